// End-to-end tests of a studio an operator can trust (issue 16, items 1–2),
// on examples/tank-plant, whose plant program drives the inputs FILL and S_CAP:
// a force on FILL wins over the plant in the ladder, the tag table and the API,
// and a banner on every page lists it with Remove all; Stop and Run ask first;
// a stopped PLC and a killed runtime turn every live element grey under a
// banner saying since when, until the runtime is back.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { elementId, openBrowser, startAlba } from './harness.mjs';

let alba, b;
const id = {};

before(async () => {
  alba = await startAlba('tank-plant');
  b = await openBrowser();
  const program = await alba.json('/api/programs/main.lad');
  id.fill = elementId(program, 'XIC', ['FILL']);
});

after(async () => {
  await b?.close();
  await alba?.stop();
});

const live = () => b.page.evaluate(() => document.body.dataset.live);
const waitLive = (state) => b.page.waitForFunction((s) => document.body.dataset.live === s, state, { timeout: 20_000 });

test('a force on a plant-driven input wins everywhere and the banner lists it', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await waitLive('live');
  assert.equal(await tid('forces-banner').isHidden(), true, 'no force at start');
  const r = await alba.api('/api/forces/FILL', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value: true }) });
  assert.equal(r.status, 200, JSON.stringify(r.body));
  await tid('forces-banner').waitFor();
  assert.equal(await tid('forces-text').textContent(), '1 force active');
  await tid('forces-toggle').click();
  assert.equal(await tid('forces-item-FILL').textContent(), 'FILL = true');
  // The ladder shows the forced value, scan after scan, whatever the plant's operator does.
  await tid('tab-program-main.lad').click();
  const contact = page.locator(`[data-testid="el-${id.fill}"]`);
  await page.locator(`[data-testid="el-${id.fill}"][data-on="true"]`).waitFor();
  for (let i = 0; i < 5; i++) {
    assert.equal(await contact.getAttribute('data-on'), 'true');
    assert.equal((await alba.json('/api/tags/FILL')).value, true);
    await page.waitForTimeout(300);
  }
  await tid('tab-tags').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="tag-value-FILL"]')?.textContent === '1');
  assert.equal(await tid('forces-banner').isVisible(), true, 'on every page');
  await b.shot('forces-banner');
  // Remove all asks first; Cancel keeps the force.
  await tid('forces-remove-all').click();
  await tid('confirm').waitFor();
  await tid('confirm-cancel').click();
  assert.equal((await alba.json('/api/forces')).length, 1);
  await tid('forces-remove-all').click();
  await tid('confirm-ok').click();
  await tid('forces-banner').waitFor({ state: 'hidden' });
  assert.deepEqual(await alba.json('/api/forces'), []);
  assert.deepEqual(b.errors, []);
});

test('Stop and Run ask for confirmation, and a stopped PLC looks stopped', async () => {
  const { tid } = b;
  await tid('btn-stop').click();
  await tid('confirm').waitFor();
  await tid('confirm-cancel').click();
  assert.equal((await alba.json('/api/status')).state, 'running', 'Cancel stops nothing');
  await tid('btn-stop').click();
  await tid('confirm-ok').click();
  await tid('status-state').filter({ hasText: 'stopped' }).waitFor();
  await waitLive('stopped');
  assert.match(await tid('stale-banner').textContent(), /The PLC is stopped \(since .+\)/);
  await tid('btn-run').click();
  await tid('confirm-ok').click();
  await waitLive('live');
  assert.equal(await tid('stale-banner').isHidden(), true);
  // AuroraLD's keys: Alt+2 Tags, Alt+3 Trends, Alt+1 the program; Ctrl+Shift+R stop (asks).
  const { page } = b;
  await page.keyboard.press('Alt+2');
  await page.waitForFunction(() => location.hash === '#/tags');
  await page.keyboard.press('Alt+3');
  await page.waitForFunction(() => location.hash === '#/trends');
  await page.keyboard.press('Alt+1');
  await page.waitForFunction(() => location.hash === '#/program/main.lad');
  await page.keyboard.press('Control+Shift+R');
  await tid('confirm').waitFor();
  await page.keyboard.press('Escape');
  await tid('confirm').waitFor({ state: 'detached' });
  assert.equal((await alba.json('/api/status')).state, 'running');
});

test('a killed runtime leaves no live-looking screen, and the studio recovers by itself', async () => {
  const { page, tid } = b;
  await tid('tab-program-main.lad').click();
  const powered = () => page.waitForFunction(() => document.querySelectorAll('line.wire.on').length > 0);
  await powered();
  assert.equal(await live(), 'live');
  await alba.kill();
  await waitLive('stale');
  assert.match(await tid('stale-banner').textContent(), /Not live: no data since .+; reconnecting/);
  assert.equal(await tid('status-state').textContent(), 'not live', 'no frozen "running"');
  // Every live element is drawn without colour: no green power flow.
  const filter = await page.evaluate(() => getComputedStyle(document.querySelector('main.content')).filter);
  assert.match(filter, /grayscale\(1\)/);
  await b.shot('stale-after-kill');
  await alba.restart();
  await waitLive('live');
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  assert.equal(await tid('stale-banner').isHidden(), true);
  await powered();
});

test('rungs are copied, pasted, undone and redone; the text view numbers its lines', async () => {
  const { page, tid } = b;
  const text = () => page.evaluate(() => document.querySelector('[data-testid="editor-text"]').value);
  const code = (t) => t.split('\n').filter((l) => l && !l.startsWith('//'));
  await tid('tab-program-main.lad').click();
  await tid('view-graphic').click();
  const before = code(await text());
  assert.equal(before.length, 11);
  // The gutter counts from 1, as the rung comments do.
  assert.equal(await page.locator('[data-testid="rung-0"] .rung-number').first().textContent(), '1');
  // Copy rung 7 ("stop filling when the tank is full") and paste it after rung 11.
  await tid('rung-6').click({ position: { x: 20, y: 10 } });
  await page.keyboard.press('Control+C');
  await tid('rung-10').click({ position: { x: 20, y: 10 } });
  await page.keyboard.press('Control+V');
  await tid('rung-11').waitFor();
  let now = code(await text());
  assert.equal(now.length, 12);
  assert.equal(now[11], before[6]);
  // Edited and not saved: the unchanged rungs keep their power flow.
  const saved = await alba.json('/api/programs/main.lad');
  await page.locator(`[data-testid="el-${elementId(saved, 'OTE', ['L_RUN'])}"][data-on="true"]`).waitFor();
  assert.match(await tid('edit-state').textContent(), /edited — not saved \(power flow on the unchanged rungs\)/);
  assert.equal(await tid('el-r11-0').getAttribute('data-on'), 'false', 'the pasted rung has no power flow yet');
  // Undo takes it away, redo puts it back; the buttons do the same.
  await page.keyboard.press('Control+Z');
  await tid('rung-11').waitFor({ state: 'detached' });
  assert.deepEqual(code(await text()), before);
  await page.keyboard.press('Control+Y');
  await tid('rung-11').waitFor();
  await tid('btn-undo').click();
  await tid('rung-11').waitFor({ state: 'detached' });
  assert.equal((await text()).split('\n').length > 0, true);
  // Cut and paste moves a rung.
  await tid('rung-0').click({ position: { x: 20, y: 10 } });
  await tid('btn-rung-cut').click();
  await tid('rung-9').click({ position: { x: 20, y: 10 } });
  await tid('btn-rung-paste').click();
  now = code(await text());
  assert.deepEqual(now, [...before.slice(1), before[0]]);
  // Addresses and descriptions under contacts and coils, on demand.
  await tid('btn-annotate').click();
  const notesOf = (tag) =>
    page.evaluate((t) => {
      const op = [...document.querySelectorAll('g.el text.operand')].find((e) => e.textContent === t);
      return [...(op?.parentElement?.querySelectorAll('[data-testid^="annotation-"]') ?? [])].map((e) => e.textContent);
    }, tag);
  await page.waitForFunction(() => document.querySelector('[data-testid^="annotation-"]'));
  assert.deepEqual(await notesOf('FILL'), ['DI:1/1', 'P2 push button: fill …']);
  await tid('btn-annotate').click();
  await page.waitForFunction(() => !document.querySelector('[data-testid^="annotation-"]'));
  assert.deepEqual(await notesOf('FILL'), []);
  // Drag and drop from the palette: XIO dropped on the left half of XIC(FILL) goes before it.
  await tid('palette-group-bit').click();
  const fillContact = page.locator('g.el', { has: page.locator('text.operand', { hasText: /^FILL$/ }) }).first();
  await tid('palette-XIO').dragTo(fillContact, { targetPosition: { x: 3, y: 30 } });
  await page.waitForFunction(() => document.querySelector('[data-testid="editor-text"]').value.includes('XIO(?)XIC(FILL)'), null, { timeout: 10_000 });
  assert.equal((await text()).split('XIO(?)').length, 2, 'one drop inserts one instruction');
  await tid('btn-undo').click();
  await page.waitForFunction(() => !document.querySelector('[data-testid="editor-text"]').value.includes('XIO(?)'));
  // The text view: line numbers, and an error marked on its line.
  await tid('view-text').click();
  const lines = (await text()).split('\n').length;
  await page.waitForFunction((n) => document.querySelector('[data-testid="line-numbers"]')?.textContent.trim().split('\n').length === n, lines);
  await tid('editor-text').fill('XIC(NoSuchTag)OTE(L_RUN);\n');
  await tid('line-error-1').waitFor();
  assert.match(await tid('line-error-1').getAttribute('title'), /E301/);
  await b.shot('text-line-numbers');
  // Back to the saved program: undo every step, then nothing is pending.
  while (await page.evaluate(() => document.querySelector('[data-testid^="ladder-"]')?.getAttribute('data-dirty') === 'true')) {
    await tid('btn-undo').click();
  }
  assert.deepEqual(code(await text()), before);
  await tid('view-graphic').click();
  assert.deepEqual(b.errors, []);
});

test('trends: two axes, on/off pens as steps on lanes, a live legend, the set saved in the project, a forced value', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  const r = await alba.api('/api/forces/FILL', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value: true }) });
  assert.equal(r.status, 200);
  await tid('tab-trends').click();
  for (const pen of ['Nivel_L', 'Cont_L', 'Bomba1', 'FILL']) {
    await tid('trend-pen-input').fill(pen);
    await tid('trend-pen-add').click();
    await tid(`trend-pen-${pen}`).waitFor();
  }
  // Cont_L (0–10 L) on its own axis beside the tank's 0–60 L; on/off pens have lanes, not axes.
  await tid('trend-axis-Cont_L').selectOption('2');
  assert.equal(await tid('trend-axis-Bomba1').count(), 0);
  await tid('trend-min-Nivel_L').fill('0');
  await tid('trend-max-Nivel_L').fill('60');
  await tid('trend-max-Nivel_L').press('Tab');
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="trend-plot"]')?.getAttribute('data-points')) > 2);
  // Two y axes are drawn (plus time), each labelled with its pens; two lanes.
  await page.waitForFunction(() => document.querySelector('[data-testid="trend-plot"]')?.dataset.axes === 'Nivel_L|Cont_L');
  assert.equal(await tid('trend-plot').getAttribute('data-lanes'), 'Bomba1,FILL');
  // The legend shows the latest values without hovering; the forced FILL is 1.
  const legend = async (name) =>
    page.evaluate((n) => {
      const row = [...document.querySelectorAll('[data-testid="trend-plot"] .u-legend .u-series')].find((r) => r.textContent.includes(n));
      return row?.querySelector('.u-value')?.textContent;
    }, name);
  await page.waitForFunction(() => [...document.querySelectorAll('[data-testid="trend-plot"] .u-legend .u-value')].every((v) => v.textContent !== '--'));
  assert.equal(await legend('FILL'), '1');
  assert.match(await legend('Nivel_L'), /^\d/);
  await b.shot('trends-axes-lanes');
  // Zooming out of live shows the past: the range still ends now.
  await tid('trend-zoom-out').click();
  const to = Number(await tid('trend-plot').getAttribute('data-to'));
  const status = await alba.json('/api/status');
  assert.ok(to <= Date.now() + 1000, `the range ends in the future: ${to}`);
  assert.ok(status.state === 'running');
  // The set is the project's: trends.json holds the pens, axes and scales.
  let set;
  for (let i = 0; i < 100 && (set = await alba.json('/api/trends')).pens.length < 4; i++) await page.waitForTimeout(100);
  assert.deepEqual(set.pens.map((p) => [p.tag, p.axis, p.min, p.max]), [['Nivel_L', 1, 0, 60], ['Cont_L', 2, null, null], ['Bomba1', 1, null, null], ['FILL', 1, null, null]]);
  await alba.api('/api/forces', { method: 'DELETE', headers: { 'content-type': 'application/json' } });
  assert.deepEqual(b.errors, []);
});

test('where is this tag used: the list, and a click lands on the rung', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('tab-program-main.lad').click();
  const program = await alba.json('/api/programs/main.lad');
  await page.locator(`[data-testid="el-${elementId(program, 'XIC', ['Llenar'])}"]`).click();
  await tid('uses-Llenar').click();
  await tid('use-2').waitFor();
  const items = await tid('uses-list').locator('li').allTextContents();
  assert.deepEqual(items, [
    'Llenar: 3 uses',
    'main.lad rung 6 · 12:18 OTL(Llenar) writes',
    'main.lad rung 7 · 14:18 OTU(Llenar) writes',
    'main.lad rung 8 · 16:1 XIC(Llenar)',
  ]);
  await tid('use-0').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="rung-5"]')?.classList.contains('selected'));
  // From another tab: the program opens on the rung.
  await tid('tab-tags').click();
  await tid('tab-program-main.lad').click();
  await page.locator(`[data-testid="el-${elementId(program, 'XIC', ['Llenar'])}"]`).click();
  await tid('uses-Llenar').click();
  await tid('use-1').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="rung-6"]')?.classList.contains('selected'));
  assert.deepEqual(b.errors, []);
});
