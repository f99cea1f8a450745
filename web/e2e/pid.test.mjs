// End-to-end test of the PID instruction in the ladder view, on
// examples/pid-level (PID(Loop,Level,Pump) against a simulated tank): the box
// is drawn with its operand labels and live values, and PID is in the palette
// (group "special") with its labels and the PID tags in the tag picker.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { elementId, openBrowser, startAlba } from './harness.mjs';

let alba, b;

before(async () => {
  alba = await startAlba('pid-level');
  b = await openBrowser();
});

after(async () => {
  await b?.close();
  await alba?.stop();
});

test('a PID box is drawn live, and PID is in the palette with its operand labels', async () => {
  const { page, tid } = b;
  const program = await alba.json('/api/programs/main.lad');
  const pid = elementId(program, 'PID', ['Loop', 'Level', 'Pump']);
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await tid('tab-program-main.lad').click();
  const box = page.locator(`[data-testid="el-${pid}"]`);
  await box.waitFor();
  assert.ok((await box.getAttribute('class')).includes('el-box'));
  assert.deepEqual(await box.locator('text.label').allTextContents(), ['PID', 'Process Var', 'Control Var']);
  assert.deepEqual(await box.locator('text.bit').allTextContents(), ['EN', 'DN', 'MAN']);
  // The rung is true: EN lit, and the process and control values shown.
  await box.locator('[data-bit="EN"].bit-on').waitFor();
  await page.waitForFunction((id) => /^-?\d/.test(document.querySelector(`[data-testid="el-${id}"] [data-tag="Pump"]`)?.textContent ?? ''), pid);
  await b.shot('ladder-pid');

  // The palette: PID in the "special" group, inserted with three operands.
  await tid('btn-rung-append').click();
  await tid('palette-group-special').click();
  await tid('palette-PID').click();
  const fields = tid('properties').locator('.operand-field > span');
  await fields.first().waitFor();
  assert.deepEqual(await fields.allTextContents(), ['PID — a PID tag', 'Process Var — a number (tag or literal)', 'Control Var — a numeric tag to write']);
  const list = await tid('operand-0').getAttribute('list');
  assert.deepEqual(await page.locator(`datalist[id="${list}"] option`).evaluateAll((os) => os.map((o) => o.value)), ['Loop']);
  await tid('view-text').click();
  // a new rung is NOP(); an output goes last
  assert.match(await tid('editor-text').inputValue(), /^NOP\(\)PID\(\?,\?,\?\);$/m);
  await tid('view-graphic').click();
  await tid('el-r1-1').filter({ has: page.locator('text.mn', { hasText: 'PID' }) }).waitFor();
  assert.deepEqual(b.errors, [], 'no error in the page');
});
