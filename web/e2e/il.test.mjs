// End-to-end test of the Instruction List view on examples/festo-station
// (station.awl, S7-200 AWL, against its ladder plant model).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('festo-station', (s) => ({ alba, b } = s));

test('an AWL program is shown with live logic results and values, and edited as text', async () => {
  const { page, tid } = b;
  const program = await alba.json('/api/programs/station.awl');
  assert.equal(program.language, 'il');
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await tid('tab-program-station.awl').click();
  for (const { line } of program.lines.slice(0, 5)) await tid(`il-line-${line}`).waitFor();
  // Running: some instruction lines have a true logic result, and a value is shown.
  await page.locator('[data-testid^="il-line-"][data-on="true"]').first().waitFor();
  const ldPlatform = program.text.split('\n').findIndex((l) => l.startsWith('LD    I0.1')) + 1;
  await page.locator(`[data-testid="il-line-${ldPlatform}"] [data-tag]`).first().waitFor();
  await b.shot('il-monitor');

  // A text edit with an error is listed and not saved; a good one is saved.
  const file = join(alba.dir, 'station.awl');
  const saved = readFileSync(file, 'utf8');
  await tid('view-text').click();
  await tid('editor-text').fill(saved.replace('LD    I0.1        // platform at position 1', 'LD    I9.9.9      // platform at position 1'));
  await tid('btn-compile').click();
  await tid('diagnostic-0').waitFor();
  await tid('btn-save').click();
  await tid('toast-error').first().waitFor();
  assert.equal(readFileSync(file, 'utf8'), saved, 'nothing saved');
  const edited = saved.replace('// platform at position 1', '// platform down (position 1)');
  await tid('editor-text').fill(edited);
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="il-station.awl"]')?.getAttribute('data-dirty') === 'false');
  assert.equal(readFileSync(file, 'utf8'), edited);
  assert.equal((await alba.json('/api/status')).state, 'running');
  assert.deepEqual(b.errors, [], 'no error in the page');
});
