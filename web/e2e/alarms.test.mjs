// End-to-end test of the alarm banner (docs/alarms.md) on the demo's
// examples/tank-plant, whose alarms.csv has an emergency-stop alarm on the
// rising edge of STOP: forcing STOP raises it; the banner appears on every
// page with the alarm; acknowledging it from the list hides the banner, and
// the acknowledgement is in the alarm log.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, startAlba } from './harness.mjs';

let alba, b;

before(async () => {
  alba = await startAlba('tank-plant');
  b = await openBrowser();
});

after(async () => {
  await b?.close();
  await alba?.stop();
});

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
