// The studio's data views as a new user meets them (issue 30) on a copy of
// examples/tank-plant: the trend (BOOL pens on lanes of their own, time labels
// that neither collide nor are cut off, "No data in this range", the CSV), the
// alarms (severity named, the shelving dialog, the log following the user's
// own acknowledgements), the tag table (a refused write changes no row's
// height; Delete asks in the page), the filters' placeholders, and the dates
// in Spanish. Screenshots: trend-lanes.png, alarm-log-ack.png, alarm-shelved.png,
// tags-error.png.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { out, useStudio } from './harness.mjs';

let alba, b;
useStudio('tank-plant', (s) => ({ alba, b } = s));

const json = (body) => ({ method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body) });
const force = (tag, value) => alba.api(`/api/forces/${tag}`, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });

test('the trend: a BOOL on its own lane below the level, time labels apart and inside, "no data", the CSV', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await tid('tab-trends').click();
  for (const pen of ['Nivel_L', 'Bomba1']) {
    await tid('trend-pen-input').fill(pen);
    await tid('trend-pen-add').click();
    await tid(`trend-pen-${pen}`).waitFor();
  }
  // the level on a fixed 0–60 L scale
  await tid('trend-min-Nivel_L').fill('0');
  await tid('trend-max-Nivel_L').fill('60');
  await tid('trend-max-Nivel_L').press('Enter');
  const plot = tid('trend-plot');
  await page.waitForFunction(() => document.querySelector('[data-testid="trend-plot"]')?.dataset.scales?.includes('lanes'));
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="trend-plot"]')?.dataset.points) > 2);
  assert.equal(await plot.getAttribute('data-lanes'), 'Bomba1');
  // 0 L is where the lanes end: the BOOL is below the level's scale, not inside it
  const scales = JSON.parse(await plot.getAttribute('data-scales'));
  const [lo, hi] = scales.y1;
  assert.equal(hi, 60);
  assert.ok(lo < 0, `the level's axis reaches down over the lanes: ${lo}`);
  // the lanes take the bottom 35 % of the plot: there the level's axis reads 0
  assert.ok(Math.abs(lo + (hi - lo) * 0.35) < 1e-6, JSON.stringify(scales));
  // Time labels: in the page's font, each one ends before the next begins, the last inside the canvas.
  await page.waitForTimeout(1500); // a few redraws
  const ticks = await page.evaluate(() => {
    const el = document.querySelector('[data-testid="trend-plot"]');
    const canvas = el.querySelector('canvas');
    const ctx = document.createElement('canvas').getContext('2d');
    ctx.font = '12px system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, "Noto Sans", sans-serif';
    const left = canvas.getBoundingClientRect().left - el.getBoundingClientRect().left;
    return {
      width: canvas.getBoundingClientRect().width,
      left,
      ticks: JSON.parse(el.dataset.xTicks).map(([x, label]) => ({ x, label, w: Math.max(...label.split('\n').map((l) => ctx.measureText(l).width)) })),
    };
  });
  assert.ok(ticks.ticks.length >= 2, JSON.stringify(ticks));
  for (let k = 1; k < ticks.ticks.length; k++) {
    const [a, c] = [ticks.ticks[k - 1], ticks.ticks[k]];
    assert.ok(a.x + a.w / 2 + 4 <= c.x - c.w / 2, `labels apart: ${JSON.stringify([a, c])}`);
  }
  const last = ticks.ticks[ticks.ticks.length - 1];
  assert.ok(last.x + last.w / 2 <= ticks.width, `the last label inside the canvas: ${JSON.stringify(last)} in ${ticks.width}`);
  await b.shot('trend-lanes');
  // The CSV: the absolute time first, no row before the first sample, REAL values without float noise.
  const [download] = await Promise.all([page.waitForEvent('download'), tid('trend-export-csv').click()]);
  const file = join(out, 'trend-views.csv');
  await download.saveAs(file);
  const lines = readFileSync(file, 'utf8').trim().split('\n');
  assert.match(lines[0], /^Time \(UTC[+-]\d\d:\d\d\),Time \(ms\),Nivel_L,Bomba1$/);
  assert.ok(lines.length >= 3, `rows: ${lines.length}`);
  const rows = lines.slice(1).map((l) => l.split(','));
  assert.match(rows[0][0], /^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3}$/);
  assert.equal(rows[0][1], '0');
  assert.ok(rows[0][2] !== '' || rows[0][3] !== '', `the first row has a sample: ${lines[1]}`);
  for (const r of rows) {
    if (r[2] === '') continue;
    const digits = r[2].replace(/^-/, '').replace('.', '').replace(/^0+/, '');
    assert.ok(digits.length <= 9, `a REAL in at most 9 digits: ${r[2]}`);
    assert.equal(Math.fround(Number(r[2])), Math.fround(Math.fround(Number(r[2]))));
  }
  // A range with nothing recorded says so.
  await tid('trend-range').selectOption({ label: 'last 7 days' });
  await tid('trend-pan-left').click();
  await tid('trend-pan-left').click();
  await tid('trend-nodata').waitFor();
  assert.equal(await tid('trend-nodata').textContent(), 'No data in this range');
  await tid('trend-live').click();
  await tid('trend-nodata').waitFor({ state: 'hidden' });
  assert.deepEqual(b.errors, []);
});

test('alarms: severity named, shelving in a dialog with its reason shown, the log following the user\'s acknowledgement', async () => {
  const { page, tid } = b;
  await force('STOP', true);
  await tid('alarm-banner').waitFor();
  await tid('alarm-toggle').click();
  await tid('alarm-row-estop').waitFor();
  assert.equal(await page.locator('[data-testid="alarm-row-estop"] .sev').textContent(), 'critical');
  await tid('alarm-toggle').click();
  await tid('tab-alarms').click();
  await tid('alarms-row-estop').waitFor();
  assert.equal(await page.locator('[data-testid="alarms-table"] th').first().textContent(), 'Severity');
  const badge = page.locator('[data-testid="alarms-row-estop"] .sev-badge');
  assert.equal(await badge.textContent(), 'critical');
  assert.equal(await badge.evaluate((e) => getComputedStyle(e).backgroundColor), 'rgb(183, 28, 28)');
  // The log page, left open: the user's acknowledgement appears by itself.
  await tid('alarms-page').selectOption('log');
  await tid('alarm-log-table').locator('tbody tr').first().waitFor();
  assert.equal(await tid('alarm-log-now').isChecked(), true);
  assert.equal(await tid('alarm-log-to').isHidden(), true, 'the end is now: no date to pick');
  const acked = page.locator('[data-testid="alarm-log-table"] tbody tr', { hasText: 'seen at the panel' });
  assert.equal(await acked.count(), 0);
  const r = await alba.api('/api/alarms/estop/ack', json({ comment: 'seen at the panel' }));
  assert.equal(r.status, 200, JSON.stringify(r.body));
  await acked.first().waitFor();
  assert.match(await acked.first().textContent(), /estop.*not acknowledged.*local/);
  // the time in the language's format (English in an en-US browser: m/d/yyyy, h:mm:ss AM/PM)
  assert.match(await acked.first().locator('td').first().textContent(), /^\d\d\/\d\d\/\d{4}, \d{1,2}:\d\d:\d\d\s[AP]M$/);
  await b.shot('alarm-log-ack');
  // Shelving: one dialog, its checks said, then the row says until when and why.
  await tid('alarms-page').selectOption('summary');
  // a second press of the emergency stop raises it again
  await force('STOP', false);
  await page.waitForTimeout(300);
  await force('STOP', true);
  // (an edge alarm: active for a moment, then cleared and waiting for its acknowledgement)
  await page.locator('[data-testid="alarms-row-estop"]', { hasText: 'cleared, not acknowledged' }).waitFor();
  await tid('alarms-shelve-estop').click();
  await tid('shelve-dialog').waitFor();
  await tid('shelve-ok').click();
  assert.equal(await tid('shelve-error').textContent(), 'Say why the alarm is shelved.');
  await tid('shelve-reason').fill('maintenance on P1');
  await tid('shelve-minutes').fill('0');
  await tid('shelve-ok').click();
  assert.equal(await tid('shelve-error').textContent(), 'Shelve for 1 to 10080 whole minutes.');
  await tid('shelve-minutes').fill('30');
  // (30 minutes on may be tomorrow: then the date comes first)
  assert.match(await tid('shelve-until').textContent(), /^until (\d\d\/\d\d\/\d{4}, )?\d{1,2}:\d\d:\d\d\s[AP]M$/);
  await tid('shelve-reason').press('Enter');
  await tid('shelve-dialog').waitFor({ state: 'detached' });
  await tid('alarms-shelved-estop').waitFor();
  assert.match(await tid('alarms-shelved-estop').textContent(), /^until (\d\d\/\d\d\/\d{4}, )?\d{1,2}:\d\d:\d\d\s[AP]M — maintenance on P1 \(local\)$/);
  const shelved = (await alba.json('/api/alarms')).find((a) => a.id === 'estop');
  assert.equal(shelved.reason, 'maintenance on P1');
  await b.shot('alarm-shelved');
  await tid('alarms-shelve-estop').click(); // unshelve
  await tid('alarms-shelved-estop').waitFor({ state: 'detached' });
  await alba.api('/api/forces/STOP', { method: 'DELETE' });
  assert.deepEqual(b.errors, []);
});

test('the tag table: a refused write leaves every row its height', async () => {
  const { page, tid } = b;
  await tid('tab-tags').click();
  await tid('tag-row-CT_STP.PRE').waitFor();
  const heights = () => page.evaluate(() => [...document.querySelectorAll('[data-testid="tag-table"] tbody tr')].filter((r) => !r.hidden).map((r) => Math.round(r.getBoundingClientRect().height)));
  const widths = () => page.evaluate(() => [...document.querySelectorAll('[data-testid="tag-table"] thead th')].map((th) => Math.round(th.getBoundingClientRect().width)));
  await tid('tag-edit-value-CT_STP.PRE').click();
  await tid('tag-input-CT_STP.PRE').waitFor();
  const [h0, w0] = [await heights(), await widths()];
  await tid('tag-input-CT_STP.PRE').fill('abc');
  await tid('tag-input-CT_STP.PRE').press('Enter');
  await tid('tag-error-CT_STP.PRE').waitFor();
  assert.ok((await tid('tag-error-CT_STP.PRE').textContent()).length > 20);
  assert.deepEqual(await heights(), h0, 'no row changed height');
  assert.deepEqual(await widths(), w0, 'no column changed width');
  await b.shot('tags-error');
  await tid('tag-input-CT_STP.PRE').press('Escape');
  await tid('tag-error-CT_STP.PRE').waitFor({ state: 'hidden' });
});

test('filter boxes show their whole placeholder, in English and in Spanish', async () => {
  const { page, tid } = b;
  // (a tab's view is made on the hash change that follows the click: wait for the box)
  const cut = async (testid) => {
    await tid(testid).waitFor();
    return page.evaluate((id) => {
      const el = document.querySelector(`[data-testid="${id}"]`);
      const cs = getComputedStyle(el);
      const ctx = document.createElement('canvas').getContext('2d');
      ctx.font = `${cs.fontSize} ${cs.fontFamily}`;
      const room = el.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight) - 16; // the clear button
      return ctx.measureText(el.placeholder).width > room ? `${el.placeholder}: ${ctx.measureText(el.placeholder).width} > ${room}` : '';
    }, testid);
  };
  for (const lang of ['en', 'es']) {
    if (lang === 'es') {
      await page.evaluate(() => localStorage.setItem('alba.lang', 'es'));
      await page.reload();
      await tid('status-conn').filter({ hasText: /^conectado$/ }).waitFor();
    }
    await tid('tab-tags').click();
    assert.equal(await cut('tag-filter'), '');
    await tid('tab-alarms').click();
    assert.equal(await cut('alarms-filter'), '');
    await tid('alarms-page').selectOption('log');
    assert.equal(await cut('alarm-log-filter'), '');
    await tid('alarms-page').selectOption('summary');
  }
});

test('Spanish dates: dd/mm/yyyy and 24 h in the alarm log and the trend legend', async () => {
  const { page, tid } = b;
  // (in Spanish since the test before)
  await tid('tab-alarms').click();
  await tid('alarms-page').selectOption('log');
  await tid('alarm-log-table').locator('tbody tr').first().waitFor();
  const time = await tid('alarm-log-table').locator('tbody tr td').first().textContent();
  assert.match(time, /^\d\d\/\d\d\/\d{4}, \d\d:\d\d:\d\d$/);
  const now = new Date();
  const dd = String(now.getDate()).padStart(2, '0');
  const mm = String(now.getMonth() + 1).padStart(2, '0');
  assert.ok(time.startsWith(`${dd}/${mm}/${now.getFullYear()}`), time);
  await tid('tab-trends').click();
  await page.locator('.u-legend .u-series').first().waitFor();
  assert.match(await page.locator('.u-legend .u-series').first().textContent(), /^Hora\s*\d\d\/\d\d\/\d{4}, \d\d:\d\d:\d\d$/);
  await page.evaluate(() => localStorage.setItem('alba.lang', 'en'));
  assert.deepEqual(b.errors, []);
});
