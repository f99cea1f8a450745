// The optional 4th operand of TON/TOF/RTO in the ladder editor (issue 34, point 3;
// docs/ladder.md §4.4) on a copy of examples/plc8051-pulse-relay: the properties panel
// offers "Time base" with its choices, never a tag; choosing one writes it, choosing the
// default leaves it out again, and the box shows a "Time base" row.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { elementId, useStudio } from './harness.mjs';

let alba, b;
useStudio('plc8051-pulse-relay', (s) => ({ alba, b } = s));

test('a TON’s time base is chosen in the properties panel', async () => {
  const { page, tid } = b;
  const text = async () => {
    await tid('view-text').click();
    const t = await tid('editor-text').inputValue();
    await tid('view-graphic').click();
    return t;
  };
  await page.goto(alba.url);
  await tid('tab-program-main.lad').click();
  await tid('view-graphic').click();
  const ton = elementId(await alba.json('/api/programs/main.lad'), 'TON', ['T_On', '1500', '0']);
  await page.locator(`[data-testid="el-${ton}"]`).click();
  const base = tid('operand-3');
  assert.equal(await base.evaluate((e) => e.tagName), 'SELECT');
  assert.equal(await base.inputValue(), '');
  assert.deepEqual(await base.locator('option').allTextContents(), ['ms (default)', 'ms', 'cs', 'ds', 's', 'min']);
  await base.selectOption('ds');
  assert.match(await text(), /TON\(T_On,1500,0,ds\);/);
  // the box has a Time base row; the base is no tag, so no "Where used" for it
  await page.waitForFunction(() => [...document.querySelectorAll('text.label')].some((t) => t.textContent === 'Time base'));
  assert.equal(await tid('uses-ds').count(), 0);
  await b.shot('ladder-time-base');
  await tid('operand-3').selectOption('');
  assert.match(await text(), /TON\(T_On,1500,0\);/);
  assert.deepEqual(b.errors, []);
});
