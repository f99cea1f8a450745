// End-to-end tests of the studio in a real browser (Debian's Chromium through
// playwright-core) against `alba run` on a copy of examples/tank-plant.
// Run by ./test.sh: `node --test e2e/`. Screenshots of the ladder monitor and
// of the trend view, the exported CSV and the latency measurement are left in
// E2E_OUT (target/e2e/ in ./test.sh) for a reviewer.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { elementId, openBrowser, out, startAlba } from './harness.mjs';

let alba, b, program;
const id = {};

before(async () => {
  alba = await startAlba('tank-plant');
  b = await openBrowser();
  program = await alba.json('/api/programs/main.lad');
  id.stop = elementId(program, 'XIC', ['STOP']);
  id.lstp = elementId(program, 'OTE', ['L_STP']);
  id.lrun = elementId(program, 'OTE', ['L_RUN']);
  id.notStopped = elementId(program, 'XIO', ['L_STP']);
  id.b1 = elementId(program, 'OTE', ['Bomba1']);
});

after(async () => {
  await b?.close();
  await alba?.stop();
});

const el = (n, on) => b.page.locator(`[data-testid="el-${n}"]${on === undefined ? '' : `[data-on="${on}"]`}`);

test('the studio loads and shows the tank program live', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  assert.equal(await tid('project-name').textContent(), 'tank-plant');
  // no users in the example: full rights, no sign-out
  assert.equal(await tid('status-user').textContent(), 'local, no users');
  assert.equal(await tid('btn-logout').isHidden(), true);
  await tid('tab-program-main.lad').click();
  for (let r = 0; r < 11; r++) await tid(`rung-${r}`).waitFor();
  assert.equal(await tid('rung-11').count(), 0, 'eleven rungs');
  // Running and not stopped: rung 5 is energised end to end.
  await el(id.notStopped, true).waitFor();
  await el(id.lrun, true).waitFor();
  await el(id.lstp, false).waitFor();
  assert.ok((await page.locator('line.wire.on').count()) > 0, 'powered wires are drawn');
  // Live values inside the boxes: the level in the SCP box moves with the plant.
  const level = page.locator('[data-testid="rung-0"] [data-tag="Nivel_L"]').first();
  const first = await level.textContent();
  await page.waitForFunction((v) => document.querySelector('[data-testid="rung-0"] [data-tag="Nivel_L"]')?.textContent !== v, first);
  assert.match(await level.textContent(), /^-?\d/);
  await tid('status-state').filter({ hasText: 'running' }).waitFor();
  await b.shot('ladder-monitor');
});

test('forcing STOP from the ladder energises L_STP and stops the pumps', async () => {
  const { page, tid } = b;
  await el(id.stop).click({ button: 'right' });
  await tid('menu-force-on').click();
  await el(id.lstp, true).waitFor();
  await el(id.notStopped, false).waitFor();
  await el(id.b1, false).waitFor();
  assert.deepEqual(await alba.json('/api/forces'), [{ name: 'STOP', value: true }]);
  await b.shot('ladder-forced');
  // Released: the press was counted once, the system stays stopped.
  await el(id.stop).click({ button: 'right' });
  await tid('menu-unforce').click();
  await page.waitForFunction(async () => (await (await fetch('/api/forces')).json()).length === 0);
  assert.equal((await alba.json('/api/tags/CT_STP.ACC')).value, 1);
  await el(id.lstp, true).waitFor();
  // A second press resumes.
  await el(id.stop).click({ button: 'right' });
  await tid('menu-force-on').click();
  await el(id.lstp, false).waitFor();
  await el(id.stop).click({ button: 'right' });
  await tid('menu-unforce').click();
  await el(id.lrun, true).waitFor();
});

test('the trend follows the level live and exports CSV', async () => {
  const { page, tid } = b;
  await tid('tab-trends').click();
  for (const pen of ['Nivel_L', 'Bomba1']) {
    if (await tid(`trend-pen-${pen}`).count()) continue;
    await tid('trend-pen-input').fill(pen);
    await tid('trend-pen-add').click();
    await tid(`trend-pen-${pen}`).waitFor();
  }
  const plot = tid('trend-plot');
  const read = async () => ({ n: Number(await plot.getAttribute('data-points')), t: Number(await plot.getAttribute('data-last-t')) });
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="trend-plot"]')?.getAttribute('data-points')) > 0);
  const before = await read();
  await page.waitForFunction((t) => Number(document.querySelector('[data-testid="trend-plot"]')?.getAttribute('data-last-t')) > t + 500, before.t);
  const later = await read();
  assert.ok(later.t > before.t && later.n > 0, `the trend moves: ${JSON.stringify([before, later])}`);
  await b.shot('trend');

  const [download] = await Promise.all([page.waitForEvent('download'), tid('trend-export-csv').click()]);
  const file = join(out, 'trend.csv');
  await download.saveAs(file);
  const lines = readFileSync(file, 'utf8').trim().split('\n');
  assert.match(lines[0], /^Time \(UTC[+-]\d\d:\d\d\),Time \(ms\),Nivel_L,Bomba1$/);
  assert.ok(lines.length >= 3, `rows: ${lines.length}`);
  const row = lines[lines.length - 1].split(',');
  assert.ok(Number.isFinite(Number(row[1])) && Number(row[2]) >= 0 && Number(row[2]) <= 60, lines[lines.length - 1]);
});

test('a rung edited online is applied between scans and keeps the state', async () => {
  const { page, tid } = b;
  const file = join(alba.dir, 'main.lad');
  // State to keep: a written preset and the latched fill request.
  await alba.api('/api/tags/CT_STP.PRE', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: '{"value": 3}' });
  const scans = (await alba.json('/api/status')).scans;

  await tid('tab-program-main.lad').click();
  await tid('view-text').click();
  const editor = tid('editor-text');
  const text = await editor.inputValue();
  assert.ok(text.includes('GEQ(Nivel_L,60.0)OTU(Llenar);'));
  await editor.fill(text.replace('GEQ(Nivel_L,60.0)', 'GEQ(Nivel_L,50.0)'));
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
  await tid('toast-info').first().waitFor();
  assert.ok(readFileSync(file, 'utf8').includes('GEQ(Nivel_L,50.0)OTU(Llenar);'), 'saved to the project file');
  assert.equal((await alba.json('/api/programs/main.lad')).text, readFileSync(file, 'utf8'));
  assert.equal((await alba.json('/api/tags/CT_STP.PRE')).value, 3, 'state kept across the online edit');
  const st = await alba.json('/api/status');
  assert.equal(st.state, 'running');
  assert.ok(st.scans > scans);
  await tid('view-graphic').click();
  await page.locator('[data-testid="rung-6"]', { hasText: '50.0' }).waitFor();
  // Monitoring resumes on the new program.
  await page.locator('[data-testid="rung-4"] [data-on="true"]').first().waitFor();

  // An invalid edit is shown on the element and saves nothing.
  const saved = readFileSync(file, 'utf8');
  await tid('view-text').click();
  await editor.fill(saved.replace('OTE(L_RUN)', 'OTE(L_RUM)'));
  await tid('btn-compile').click();
  await tid('diagnostics').filter({ hasText: 'L_RUM' }).waitFor();
  await tid('btn-save').click();
  await tid('toast-error').first().waitFor();
  await tid('view-graphic').click();
  await page.locator('[data-testid="rung-4"] .error').first().waitFor();
  await b.shot('ladder-error');
  assert.equal(readFileSync(file, 'utf8'), saved, 'the file is unchanged');
  await tid('view-text').click();
  await editor.fill(saved);
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
});

test('graphical editing: palette, tag picker, branch, rung move, saved online', async () => {
  const { page, tid } = b;
  const text = async () => {
    await tid('view-text').click();
    const t = await tid('editor-text').inputValue();
    await tid('view-graphic').click();
    return t;
  };
  const rungText = (t, start) => t.split('\n').find((l) => l.startsWith(start));
  const fill = elementId(await alba.json('/api/programs/main.lad'), 'XIC', ['FILL']);
  await tid('tab-program-main.lad').click();
  await tid('view-graphic').click();
  await el(fill).click();
  await tid('palette-group-bit').click();
  await tid('palette-XIC').click();
  await tid('operand-0').fill('S_REC');
  await tid('operand-0').press('Enter');
  await tid('btn-branch').click();
  await tid('operand-0').fill('S_CAP');
  await tid('operand-0').press('Enter');
  const edited = rungText(await text(), 'XIC(FILL)');
  assert.equal(edited, 'XIC(FILL)[XIC(S_REC),XIC(S_CAP)]XIO(L_STP)GRT(Nivel_L,10.0)XIO(Bomba1)XIC(S_REC)XIO(S_CAP)OTL(Descargar);');
  // The last rung moves up one place.
  await tid('rung-10').click({ position: { x: 20, y: 10 } });
  await tid('btn-rung-up').click();
  const lines = (await text()).split('\n').filter((l) => l && !l.startsWith('//'));
  assert.equal(lines[9], 'XIC(S_CAP)OTU(Descargar);');
  assert.equal(lines[10], 'XIC(Descargar)XIO(L_STP)[OTE(Bomba2),OTE(L_REFILL)];');
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'false');
  const saved = await alba.json('/api/programs/main.lad');
  assert.equal(rungText(saved.text, 'XIC(FILL)'), edited);
  assert.equal(saved.diagnostics.length, 0);
  // Monitoring resumes: the rung of L_RUN is energised in the new program.
  await el(elementId(saved, 'OTE', ['L_RUN']), true).waitFor();
  await tid('rung-8').scrollIntoViewIfNeeded();
  await b.shot('ladder-edited');
});

test('tag table: live values, an inline error for a bad write, forcing I/O', async () => {
  const { page, tid } = b;
  await tid('tab-tags').click();
  await tid('tag-row-Vol_L').waitFor();
  const v = await tid('tag-value-Vol_L').textContent();
  await page.waitForFunction((old) => document.querySelector('[data-testid="tag-value-Vol_L"]')?.textContent !== old, v);
  await tid('tag-edit-value-CT_STP.PRE').click();
  await tid('tag-input-CT_STP.PRE').fill('abc');
  await tid('tag-input-CT_STP.PRE').press('Enter');
  await tid('tag-error-CT_STP.PRE').waitFor();
  await tid('tag-input-CT_STP.PRE').press('Escape');
  await tid('force-on-S_REC').click();
  await tid('tag-forced-S_REC').waitFor();
  assert.deepEqual(await alba.json('/api/forces'), [{ name: 'S_REC', value: true }]);
  await tid('unforce-S_REC').click();
  await tid('tag-forced-S_REC').waitFor({ state: 'detached' });
  // A new tag: the server refuses an address already used, then accepts it without one.
  await tid('tag-add').click();
  await tid('tag-form-name').fill('Batches');
  await tid('tag-form-type').selectOption('DINT');
  await tid('tag-form-address').fill('DI:1/0');
  await tid('tag-form-save').click();
  await tid('tags-diagnostic-0').waitFor();
  assert.ok(!readFileSync(join(alba.dir, 'tags.csv'), 'utf8').includes('Batches'), 'nothing saved');
  await tid('tag-form-address').fill('');
  await tid('tag-form-save').click();
  await tid('tag-row-Batches').waitFor();
  assert.match(readFileSync(join(alba.dir, 'tags.csv'), 'utf8'), /\nBatches,DINT,/);
  assert.equal((await alba.json('/api/tags/Batches')).value, 0);
  await b.shot('tags');
  // Delete asks in the page (not the browser's confirm()), Cancel first.
  await tid('tag-def-delete-Batches').click();
  await tid('confirm').waitFor();
  assert.equal(await page.locator('#confirm-title').textContent(), 'Delete the tag Batches?');
  await tid('confirm-cancel').click();
  await tid('confirm').waitFor({ state: 'detached' });
  assert.equal(await tid('tag-row-Batches').count(), 1);
  await tid('tag-def-delete-Batches').click();
  await tid('confirm-ok').click();
  await tid('tag-row-Batches').waitFor({ state: 'detached' });
  assert.ok(!readFileSync(join(alba.dir, 'tags.csv'), 'utf8').includes('Batches'));
});

// A measurement, not a pass/fail on time: engine → DOM latency of a value that
// changes every scan (Vol_L, the plant's tank volume), from the publication time
// the server puts in each message to the change of its cell in the tag table.
test('engine to DOM latency (printed, written to latency.json)', async () => {
  const { page, tid } = b;
  // Whatever the earlier tests left (a STOP press counted, an empty tank): the
  // system running and water in the tank, so Vol_L changes on every scan.
  const put = (tag, value) =>
    alba.api(`/api/tags/${tag}`, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });
  await alba.api('/api/forces', { method: 'DELETE', headers: { 'content-type': 'application/json' } });
  assert.equal((await put('CT_STP.ACC', 0)).status < 300, true);
  assert.equal((await put('Vol_L', 30.0)).status < 300, true);
  await page.addInitScript(() => {
    const lat = { t: 0, samples: [] };
    window.__lat = lat;
    const Native = window.WebSocket;
    window.WebSocket = class extends Native {
      constructor(...a) {
        super(...a);
        this.addEventListener('message', (ev) => {
          if (typeof ev.data === 'string' && ev.data.includes('"Vol_L"')) {
            const m = ev.data.match(/"t_ms":(\d+)/);
            if (m) lat.t = Number(m[1]);
          }
        });
      }
    };
  });
  // A new document (not just a new hash), so that the init script runs.
  await page.goto(`${alba.url}?latency#/tags`);
  await tid('tag-value-Vol_L').waitFor();
  await page.evaluate(() => {
    const cell = document.querySelector('[data-testid="tag-value-Vol_L"]');
    new MutationObserver(() => window.__lat.t && window.__lat.samples.push(Date.now() - window.__lat.t)).observe(cell, {
      subtree: true, childList: true, characterData: true,
    });
  });
  await page.waitForTimeout(5000);
  const samples = (await page.evaluate(() => window.__lat.samples)).sort((x, y) => x - y);
  assert.ok(samples.length > 50, `DOM updates seen: ${samples.length}`);
  const pct = (p) => samples[Math.min(samples.length - 1, Math.round((samples.length - 1) * p))];
  const result = { samples: samples.length, p50_ms: pct(0.5), p99_ms: pct(0.99), max_ms: samples[samples.length - 1] };
  writeFileSync(join(out, 'latency.json'), JSON.stringify(result, null, 2) + '\n');
  console.log(`engine → DOM latency: ${JSON.stringify(result)}`);
  assert.deepEqual(b.errors, [], 'no error in the page');
});
