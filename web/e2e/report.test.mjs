// End-to-end test of the shift report (issue 35, point 7) in Chromium, on
// examples/tank-plant: an alarm raised (the emergency stop forced on), then
// the report of the shift downloaded from the Alarms tab as XLSX and opened
// in the test (e2e/xlsx.mjs: the zip and its sheets read with node:zlib):
// the summary counts the annunciation, Top 10 names the alarm, the
// priority sheet has its 80/15/5 % targets; the PDF is a PDF.
// Screenshot: report-download.png.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { openBrowser, startAlba } from './harness.mjs';
import { readXlsx } from './xlsx.mjs';

let alba;
before(async () => {
  alba = await startAlba('tank-plant');
});
after(async () => {
  await alba?.stop();
});

test('the shift report is downloaded from the studio and opened: its sheets and cells', async () => {
  const force = (value) => alba.api('/api/forces/STOP', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });
  assert.equal((await force(true)).status, 200);
  for (let i = 0; i < 50 && !(await alba.json('/api/alarms')).some((a) => a.id === 'estop' && a.state !== 'normal'); i++) await new Promise((ok) => setTimeout(ok, 100));
  assert.ok((await alba.json('/api/alarms')).some((a) => a.id === 'estop' && a.state !== 'normal'), 'the emergency stop alarm is raised');
  const b = await openBrowser({ viewport: { width: 1400, height: 900 } });
  const { page, tid } = b;
  try {
    await page.goto(`${alba.url}#/alarms`);
    await tid('alarms-view').waitFor();
    await tid('alarms-page').selectOption('log');
    await tid('alarm-log').waitFor();
    // the range: the last hour up to now (the log's default is "now")
    const from = new Date(Date.now() - 3600_000);
    const local = new Date(from.getTime() - from.getTimezoneOffset() * 60_000).toISOString().slice(0, 16);
    await tid('alarm-log-from').fill(local);
    await b.shot('report-download');
    const [xlsx] = await Promise.all([page.waitForEvent('download'), tid('alarm-log-report-xlsx').click()]);
    assert.equal(xlsx.suggestedFilename(), 'shift-report.xlsx');
    const book = readXlsx(readFileSync(await xlsx.path()));
    assert.deepEqual(book.map((s) => s.name), ['Summary', 'Per 10 min', 'Floods', 'Top 10', 'Standing', 'Chattering', 'Priorities', 'Trends']);
    const summary = book[0].cells;
    assert.match(summary.A1, /^Shift report: /);
    const row = (label) => Object.entries(summary).find(([ref, v]) => ref.startsWith('A') && v === label)?.[0].slice(1);
    const annunciations = summary[`B${row('Alarms (annunciations)')}`];
    assert.ok(typeof annunciations === 'number' && annunciations >= 1, `the alarm is counted: ${annunciations}`);
    const fromMs = summary[`B${row('From (Unix ms)')}`];
    assert.ok(Math.abs(fromMs - from.getTime()) < 60_000, `the range asked: ${fromMs} vs ${from.getTime()}`);
    const top = book.find((s) => s.name === 'Top 10').cells;
    assert.deepEqual([top.A1, top.B1, top.C1], ['Rank', 'Alarm', 'Alarms']);
    assert.ok(Object.values(top).includes('estop'), `Top 10 names estop: ${JSON.stringify(top)}`);
    const prio = book.find((s) => s.name === 'Priorities').cells;
    const targets = Object.entries(prio).filter(([ref]) => ref.startsWith('D') && ref !== 'D1').map(([, v]) => v);
    assert.ok([80, 15, 5].every((t) => targets.includes(t)), `80/15/5 % targets: ${targets}`);
    // and the PDF of the same range
    const [pdf] = await Promise.all([page.waitForEvent('download'), tid('alarm-log-report-pdf').click()]);
    assert.equal(pdf.suggestedFilename(), 'shift-report.pdf');
    const bytes = readFileSync(await pdf.path());
    assert.equal(bytes.subarray(0, 5).toString(), '%PDF-');
    assert.match(bytes.subarray(-1024).toString('latin1'), /%%EOF\s*$/);
  } finally {
    await b.close();
    await force(false).catch(() => undefined);
  }
});
