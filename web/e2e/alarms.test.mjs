// End-to-end test of the alarm banner (docs/alarms.md) on the demo's
// examples/tank-plant, whose alarms.csv has an emergency-stop alarm on the
// rising edge of STOP: forcing STOP raises it; the banner appears on every
// page with the alarm; acknowledging it from the list hides the banner, and
// the acknowledgement is in the alarm log.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('tank-plant', (s) => ({ alba, b } = s));

test('an alarm shows in the banner on every page and is acknowledged from it', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  assert.equal(await tid('alarm-banner').isHidden(), true, 'no alarm waits at start');
  const r = await alba.api('/api/forces/STOP', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value: true }) });
  assert.equal(r.status, 200, JSON.stringify(r.body));
  await tid('alarm-banner').waitFor();
  await page.waitForFunction(() => document.querySelector('[data-testid=alarm-text]')?.textContent?.includes('estop'));
  assert.match(await tid('alarm-text').textContent(), /1 alarm to acknowledge — estop: Emergency stop pressed/);
  assert.equal(await tid('alarm-banner').getAttribute('data-band'), 'critical');
  // On another page too.
  await tid('tab-tags').click();
  assert.equal(await tid('alarm-banner').isVisible(), true);
  await tid('alarm-toggle').click();
  await tid('alarm-row-estop').waitFor();
  await b.shot('alarm-banner');
  await tid('alarm-ack-estop').click();
  await tid('alarm-banner').waitFor({ state: 'hidden' });
  const csv = (await alba.api('/api/alarms/log.csv')).body;
  assert.match(String(csv), /,estop,STOP,(active_unacked|cleared_unacked),(active_acked|normal),/);
  assert.deepEqual(b.errors, []);
});

test('the alarm summary: filter, sort, acknowledge the page, shelve, the log', async () => {
  const { page, tid } = b;
  const force = (tag, value) => alba.api(`/api/forces/${tag}`, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });
  // A second emergency stop (a new rising edge) and the level alarm's tag driven low.
  await force('STOP', false);
  // The alarm service samples the published scans and may skip some: it must have seen
  // STOP low before the new rising edge, or forcing it high again raises nothing.
  const estopValue = async () => (await alba.json('/api/alarms?all=true')).find((a) => a.id === 'estop')?.value;
  for (let i = 0; i < 100 && (await estopValue()) !== 0; i++) await page.waitForTimeout(50);
  assert.equal(await estopValue(), 0, 'the alarm service saw STOP low');
  await force('STOP', true);
  await tid('tab-alarms').click();
  await tid('alarms-row-estop').waitFor();
  // The store alarms are normal: not listed; estop is, unacknowledged.
  assert.equal(await tid('alarms-row-store_fail').count(), 0);
  await tid('alarms-filter').fill('nothing matches this');
  await tid('alarms-row-estop').waitFor({ state: 'detached' });
  await tid('alarms-filter').fill('emergency');
  await tid('alarms-row-estop').waitFor();
  // Shelve it for 5 minutes with a reason, from the page's dialog; then unshelve.
  await tid('alarms-shelve-estop').click();
  await tid('shelve-minutes').fill('5');
  await tid('shelve-reason').fill('maintenance on P1');
  await tid('shelve-ok').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="alarms-row-estop"]')?.textContent.includes('shelved'));
  const shelved = (await alba.json('/api/alarms')).find((a) => a.id === 'estop');
  assert.equal(shelved.state, 'shelved');
  assert.equal(shelved.reason, 'maintenance on P1');
  await b.shot('alarm-summary');
  await tid('alarms-shelve-estop').click(); // unshelve
  await page.waitForFunction(() => !document.querySelector('[data-testid="alarms-row-estop"]')?.textContent.includes('shelved'));
  // Acknowledge the page: nothing waits any more.
  await tid('alarms-ack-page').click();
  for (let i = 0; i < 50 && (await alba.json('/api/alarms')).some((a) => a.state.endsWith('_unacked')); i++) await page.waitForTimeout(100);
  assert.equal((await alba.json('/api/alarms')).filter((a) => a.state.endsWith('_unacked')).length, 0);
  // The counts of the summary.
  assert.match(await tid('alarms-stats').textContent(), /\d+ active, 0 to acknowledge, 0 shelved; \d+ new in 10 minutes/);
  // The log page: every transition, filtered; the range as CSV.
  await tid('alarms-page').selectOption('log');
  await tid('alarm-log-table').locator('tbody tr').first().waitFor();
  await tid('alarm-log-filter').fill('maintenance');
  await page.waitForFunction(() => document.querySelectorAll('[data-testid="alarm-log-table"] tbody tr').length >= 1);
  const shelvedRows = await tid('alarm-log-table').locator('tbody tr').allTextContents();
  assert.ok(shelvedRows.length >= 1 && shelvedRows.every((r) => r.includes('estop') && r.includes('maintenance on P1')), shelvedRows.join('\n'));
  await tid('alarm-log-filter').fill('');
  assert.match(await tid('alarm-log-count').textContent(), /^\d+ events$/);
  await b.shot('alarm-log');
  const [download] = await Promise.all([page.waitForEvent('download'), tid('alarm-log-export').click()]);
  assert.equal(download.suggestedFilename(), 'alarms.csv');
  await force('STOP', false);
  assert.deepEqual(b.errors, []);
});
