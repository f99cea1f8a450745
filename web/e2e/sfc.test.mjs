// The SFC tab (issue 20, item 2: the chart drawn from the textual SFC) on
// examples/sfc-batch: the chart in the IEC graphical form, the active step
// lit live, a forced Start moving it on, and its actions lit.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('sfc-batch', (s) => ({ alba, b } = s));

test('the SFC chart follows the running batch', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('tab-program-batch.sfc').click();
  await tid('sfc-svg').waitFor();
  assert.equal(await page.locator('.sfc-step').count(), 6);
  await page.waitForFunction(() => document.querySelector('[data-testid="sfc-step-Idle"]')?.dataset.active === 'true');
  const r = await alba.api('/api/forces/Start', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value: true }) });
  assert.equal(r.status, 200);
  await page.waitForFunction(() => document.querySelector('[data-testid="sfc-step-FillA"]')?.dataset.active === 'true');
  await page.waitForFunction(() => document.querySelector('[data-testid="sfc-action-FillA-0"]')?.classList.contains('on'));
  await b.shot('sfc-chart');
  // a transition selected: its condition in the properties; Edit in the text opens its line
  await tid('sfc-tr-t1').click();
  assert.equal(await tid('sfc-prop-condition').inputValue(), 'Start');
  await tid('sfc-goto-text').click();
  assert.equal(await tid('sfc-batch.sfc').getAttribute('data-mode'), 'text');
  assert.deepEqual(b.errors, []);
});
