// The SFC tab (issue 20, item 2: the chart drawn from the textual SFC) on
// examples/sfc-batch: the chart in the IEC graphical form, the active step
// lit live, a forced Start moving it on, and its actions lit; divergences,
// convergences and jumps drawn with the mouse, saved online.
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
  // Action rows follow their step (issue 30, item 19): Busy is latched by FillA, yet Done's Busy(R) is not lit.
  await page.waitForFunction(async () => (await (await fetch('/api/tags/Busy')).json()).value === true);
  await page.waitForTimeout(300);
  assert.equal(await tid('sfc-action-FillA-1').getAttribute('class'), 'sfc-action on');
  assert.equal(await tid('sfc-action-Done-0').getAttribute('class'), 'sfc-action');
  assert.equal(await tid('sfc-action-Mix-0').getAttribute('class'), 'sfc-action');
  await b.shot('sfc-chart');
  // a transition selected: its condition in the properties; Edit in the text opens its line
  await tid('sfc-tr-t1').click();
  assert.equal(await tid('sfc-prop-condition').inputValue(), 'Start');
  await tid('sfc-goto-text').click();
  assert.equal(await tid('sfc-batch.sfc').getAttribute('data-mode'), 'text');
  assert.deepEqual(b.errors, []);
});

test('divergences, convergences and jumps are drawn with the mouse and saved online', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('tab-program-batch.sfc').click();
  await tid('sfc-svg').waitFor();
  // a simultaneous divergence: FillA's transition activates a new step S1 beside FillB
  await tid('sfc-tr-t2').click();
  await tid('sfc-add-parallel').click();
  await tid('sfc-step-S1').waitFor();
  assert.ok((await page.locator('.sfc-double').count()) >= 2, 'double lines for the divergence');
  // a simultaneous convergence: FillB's transition waits for S1 too
  await tid('sfc-tr-t3').click();
  await tid('sfc-join').click();
  assert.match(await tid('sfc-hint').textContent(), /Click the step/);
  await tid('sfc-step-S1').click();
  // a jump: a new transition from Empty back to FillA
  await tid('sfc-step-Empty').click();
  await tid('sfc-link').click();
  await tid('sfc-step-FillA').click();
  await tid('sfc-jump-t7-FillA').waitFor();
  await b.shot('sfc-drawn');
  await tid('btn-save').click();
  await tid('toast-info').filter({ hasText: 'batch.sfc saved and applied online' }).waitFor();
  const { text } = await alba.json('/api/programs/batch.sfc');
  assert.match(text, /TRANSITION FROM FillA TO \(FillB, S1\) := Level >= 400; END_TRANSITION/);
  assert.match(text, /TRANSITION FROM \(FillB, S1\) TO Mix := Level >= 800; END_TRANSITION/);
  assert.match(text, /TRANSITION FROM Empty TO FillA := FALSE; END_TRANSITION/);
  // Delete takes the parallel step out of both transitions again
  await tid('sfc-step-S1').click();
  await tid('sfc-delete').click();
  await tid('sfc-step-S1').waitFor({ state: 'detached' });
  assert.deepEqual(b.errors, []);
});
