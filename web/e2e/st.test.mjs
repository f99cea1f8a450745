// End-to-end test of the Structured Text view on examples/st-motor (main.st):
// write an ST program in the studio, see an error on its line, fix it with the
// completion of names, save online, and see the values beside the lines
// change while the timer runs (issue 36, docs/st.md "In the studio"); then a
// FUNCTION_BLOCK's body with the values of one instance, then another.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { useStudio } from './harness.mjs';

let alba, b;
useStudio('st-motor', (s) => ({ alba, b } = s));

const PROGRAM = `PROGRAM Main
VAR
    delay : TON;
    starts : CTU;
    count : INT;
END_VAR
Motor := (Start OR Motor) AND NOT Stop;
delay(IN := Motor, PT := T#5s, Q => Lamp);
starts(CU := Motor, PV := 1000);
count := Motr;
END_PROGRAM
`;

test('an ST program is written with completion, checked as typed, saved online and shows live values inline', async () => {
  const { page, tid } = b;
  const program = await alba.json('/api/programs/main.st');
  assert.equal(program.language, 'st');
  await page.goto(alba.url);
  await tid('status-conn').filter({ hasText: /^connected$/ }).waitFor();
  await tid('tab-program-main.st').click();
  await tid('st-main.st').waitFor();
  // the saved program: highlighted, with the values of its names beside the lines
  const motorLine = program.text.split('\n').findIndex((l) => l.startsWith('Motor :=')) + 1;
  await page.waitForFunction((n) => /^Motor = (TRUE|FALSE)$/.test(document.querySelector(`[data-testid="st-val-${n}-Motor"]`)?.textContent ?? ''), motorLine);
  assert.ok(await page.locator('.st-overlay .st-kw', { hasText: 'PROGRAM' }).count());
  assert.ok(await page.locator('.st-overlay .st-type', { hasText: 'TON' }).count());

  // A program with an unknown name: the server's check marks its line as it is typed.
  const file = join(alba.dir, 'main.st');
  const saved = readFileSync(file, 'utf8');
  await tid('editor-text').fill(PROGRAM);
  await tid('st-error-10').waitFor();
  await tid('line-error-10').waitFor();
  assert.match(await tid('st-error-10').textContent(), /E222: unknown name `Motr` \(did you mean `Motor`\?\)/);
  assert.match(await tid('edit-state').textContent(), /1 problem/);
  assert.equal(await page.locator('.st-line[data-line="10"] .st-bad').textContent(), 'Motr', 'the unknown name underlined');
  await b.shot('st-error');

  // Fix it by typing, with the completion: `sta` offers `starts` (a variable) and `Start` (a tag), `starts.C` its members CU, CV.
  const at = PROGRAM.indexOf('Motr;') + 'Motr'.length;
  await tid('editor-text').evaluate((t, at) => t.setSelectionRange(at, at), at);
  for (let k = 0; k < 4; k++) await page.keyboard.press('Backspace');
  await page.keyboard.type('sta');
  await tid('st-complete-starts').waitFor();
  await tid('st-complete-Start').waitFor();
  await b.shot('st-complete');
  await page.keyboard.press('Enter');
  await page.keyboard.type('.C');
  await tid('st-complete-CV').waitFor();
  await tid('st-complete-CU').waitFor();
  await page.keyboard.press('ArrowDown');
  await page.keyboard.press('Enter');
  const fixed = PROGRAM.replace('count := Motr;', 'count := starts.CV;');
  assert.equal(await tid('editor-text').inputValue(), fixed);
  await tid('st-error-10').waitFor({ state: 'detached' });
  await page.waitForFunction(() => !document.querySelector('[data-testid^="line-error-"]'));

  // Saved online: the program runs on, the file holds the new text.
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="st-main.st"]')?.getAttribute('data-dirty') === 'false');
  assert.equal(readFileSync(file, 'utf8'), fixed);
  assert.notEqual(fixed, saved);
  assert.equal((await alba.json('/api/status')).state, 'running');
  // the new variable's value is shown beside its line
  await page.waitForFunction(() => /^count = 0$/.test(document.querySelector('[data-testid="st-val-10-count"]')?.textContent ?? ''));

  // Watch names: typed, or from a value's menu beside its line.
  await tid('st-watch-add').fill('Start');
  await tid('st-watch-add').press('Enter');
  await tid('st-watch-add').fill('delay.ET');
  await tid('st-watch-add').press('Enter');
  await tid('st-val-10-count').click({ button: 'right' });
  await tid('menu-watch').click();
  await tid('st-watch-count').waitFor();
  // Force from the code: Start's value beside its line → Force ON. The motor runs, the
  // timer's ET and the counter change beside their lines.
  await tid('st-val-7-Start').click({ button: 'right' });
  await tid('menu-force-on').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="st-watch-Start"] .st-val')?.textContent === 'TRUE');
  await page.waitForFunction(() => /^count = 1$/.test(document.querySelector('[data-testid="st-val-10-count"]')?.textContent ?? ''));
  await page.waitForFunction(() => document.querySelector('[data-testid="st-val-7-Motor"]')?.textContent === 'Motor = TRUE');
  const et = async () => (await tid('st-val-8-delay').textContent()).replace(/^delay = /, '');
  await page.waitForFunction(() => /T#\d*s?\d+ms|T#\ds/.test(document.querySelector('[data-testid="st-val-8-delay"]')?.textContent ?? ''));
  const first = await et();
  await page.waitForTimeout(600);
  const second = await et();
  assert.match(first, /^T#/);
  assert.notEqual(first, second, 'the timer runs');
  assert.match(await page.locator('[data-testid="st-watch-delay.ET"] .st-val').textContent(), /^T#/);
  await b.shot('st-view');
  // after 5 s the lamp lights: Q => Lamp shown TRUE on the call's line
  await page.waitForFunction(() => document.querySelector('[data-testid="st-val-8-Lamp"]')?.textContent === 'Lamp = TRUE', null, { timeout: 10_000 });
  // An online edit keeps the FB instances' state: the counter stays at 1 (its CU edge is
  // past), the timer stays done (the lamp stays on; reset, it would be off for 5 s).
  await tid('editor-text').fill(fixed.replace('PV := 1000', 'PV := 999'));
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="st-main.st"]')?.getAttribute('data-dirty') === 'false');
  assert.match(readFileSync(file, 'utf8'), /PV := 999/);
  await page.waitForTimeout(500);
  assert.equal(await tid('st-val-10-count').textContent(), 'count = 1');
  assert.equal(await tid('st-val-8-Lamp').textContent(), 'Lamp = TRUE');
  assert.deepEqual(b.errors, [], 'no error in the page');
});

const WITH_FB = `FUNCTION_BLOCK Count
VAR_INPUT up : BOOL; END_VAR
VAR n : INT; END_VAR
IF up THEN n := n + 1; END_IF;
END_FUNCTION_BLOCK
PROGRAM Main
VAR
    delay : TON;
    starts : CTU;
    count : INT;
    c1 : Count;
    c2 : Count;
END_VAR
Motor := (Start OR Motor) AND NOT Stop;
delay(IN := Motor, PT := T#5s, Q => Lamp);
starts(CU := Motor, PV := 999);
count := starts.CV;
c1(up := Motor);
c2(up := FALSE);
END_PROGRAM
`;

test("a FUNCTION_BLOCK's body shows the values of the instance chosen", async () => {
  const { page, tid } = b;
  await tid('editor-text').fill(WITH_FB);
  await tid('btn-save').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="st-main.st"]')?.getAttribute('data-dirty') === 'false');
  // the motor runs (Start is still forced): c1 counts every scan, c2 never
  assert.match(await tid('st-instance-Count').textContent(), /Main\.c1/);
  await page.waitForFunction(() => /^n = [1-9]\d*$/.test(document.querySelector('[data-testid="st-val-4-n"]')?.textContent ?? ''));
  assert.equal(await tid('st-val-4-up').textContent(), 'up = TRUE');
  await tid('st-instance-Count').click();
  await tid('menu-instance-Main.c2').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="st-val-4-n"]')?.textContent === 'n = 0');
  assert.equal(await tid('st-val-4-up').textContent(), 'up = FALSE');
  assert.match(await tid('st-instance-Count').textContent(), /Main\.c2/);
  await b.shot('st-fb-instance');
  // from the keyboard: Alt+Enter on a name opens its menu
  const at = WITH_FB.indexOf('NOT Stop') + 5;
  await tid('editor-text').evaluate((t, at) => {
    t.focus();
    t.setSelectionRange(at, at);
  }, at);
  await page.keyboard.press('Alt+Enter');
  await tid('menu-watch').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="st-watch-Stop"] .st-val')?.textContent === 'FALSE');
  assert.equal(await tid('editor-text').inputValue(), WITH_FB, 'the text unchanged');
  assert.deepEqual(b.errors, [], 'no error in the page');
});
