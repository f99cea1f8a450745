// End-to-end test of recipes (issue 35, point 6) in Chromium, on
// examples/tank-plant with an engineer and an operator:
// - the engineer writes two recipes in the Recipes tab (a good one and one
//   with a negative timer preset, out of range) and a third naming an input (read-only to a write);
// - the operator cannot save, applies the good one after a confirmation
//   that lists its tags (cancelled first: nothing written), and every value
//   is written, with an audit row per value under the recipe's name (that
//   they land at one scan boundary is the control layer's write_rows, tested
//   in crates/control);
// - the bad ones are refused with the row named, nothing written.
// Screenshots: recipes-edit.png, recipes-applied.png, recipes-refused.png.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, startAlba } from './harness.mjs';

const olga = { name: 'olga', role: 'operator', password: 'pumps-and-valves-7731' };
const eric = { name: 'eric', role: 'engineer', password: 'ladder-and-logic-4412' };

let alba;
let b;
before(async () => {
  alba = await startAlba('tank-plant', { users: [olga, eric] });
  await alba.login(eric.name, eric.password);
  b = await openBrowser({ viewport: { width: 1400, height: 900 } });
});
after(async () => {
  await b?.close();
  await alba?.stop();
});

async function login(who) {
  const { tid } = b;
  await tid('login-form').waitFor();
  await tid('login-user').fill(who.name);
  await tid('login-password').fill(who.password);
  await tid('login-submit').click();
  await tid('status-user').filter({ hasText: `${who.name} (${who.role})` }).waitFor();
}

const PRESETS = ['CT_STP.PRE', 'Away.PRE', 'Back.PRE'];
const values = async () => Object.fromEntries(await Promise.all(PRESETS.map(async (t) => [t, (await alba.json(`/api/tags/${t}`)).value])));

async function write(name, csv) {
  const { tid } = b;
  await tid('recipes-list').selectOption('');
  await tid('recipes-name').fill(name);
  await tid('recipes-text').fill(csv);
  await tid('recipes-save').click();
  await tid('recipes-note').filter({ hasText: 'Saved' }).waitFor();
  await b.page.waitForFunction((n) => [...document.querySelectorAll('[data-testid="recipes-list"] option')].some((o) => o.value === n), name);
  await tid('recipes-note').evaluate((el) => (el.textContent = ''));
}

test('an engineer writes recipes; an operator applies one with confirmation, the bad ones are refused with nothing written', async () => {
  const { page, tid } = b;
  // the confirmation answered as each step says (not the harness's accept-all)
  page.removeAllListeners('dialog');
  await page.goto(`${alba.url}#/recipes`);
  await login(eric);
  await tid('recipes-view').waitFor();
  await write('batch-a', 'tag,value\nCT_STP.PRE,4\nAway.PRE,3500\nBack.PRE,2500\n');
  await write('batch-bad', 'tag,value\nCT_STP.PRE,9\nAway.PRE,-5\nBack.PRE,9000\n');
  await write('batch-input', 'tag,value\nAway.PRE,9100\nS_REC,true\n');
  // edited: the good one read back, changed and saved again
  await tid('recipes-list').selectOption('batch-a');
  await page.waitForFunction(() => document.querySelector('[data-testid="recipes-text"]').value.includes('Back.PRE,2500'));
  await tid('recipes-text').fill('tag,value\nCT_STP.PRE,5\nAway.PRE,3500\nBack.PRE,2500\n');
  await tid('recipes-save').click();
  await tid('recipes-note').filter({ hasText: 'Saved' }).waitFor();
  const saved = (await alba.api('/api/recipes/batch-a', { headers: { accept: 'application/json' } })).body;
  assert.equal(JSON.stringify(saved).includes('"CT_STP.PRE":5'), true, `saved as edited: ${JSON.stringify(saved)}`);
  await b.shot('recipes-edit');
  await tid('btn-logout').click();

  // the operator
  await login(olga);
  await page.evaluate(() => (location.hash = '#/recipes'));
  await tid('recipes-view').waitFor();
  assert.equal(await tid('recipes-save').isDisabled(), true, 'an operator does not save');
  assert.equal(await tid('recipes-apply').isDisabled(), false, 'an operator applies');
  const before = await values();
  assert.notDeepEqual(before, { 'CT_STP.PRE': 5, 'Away.PRE': 3500, 'Back.PRE': 2500 });
  await tid('recipes-list').selectOption('batch-a');
  await page.waitForFunction(() => document.querySelector('[data-testid="recipes-text"]').value.includes('CT_STP.PRE,5'));

  // the confirmation names what is written; cancelled, nothing is
  let asked = '';
  page.once('dialog', (d) => {
    asked = d.message();
    void d.dismiss();
  });
  await tid('recipes-apply').click();
  for (let i = 0; i < 20 && !asked; i++) await page.waitForTimeout(50);
  assert.equal(asked, 'Apply recipe batch-a? 3 values are written at once: CT_STP.PRE, Away.PRE, Back.PRE');
  await page.waitForTimeout(300);
  assert.deepEqual(await values(), before, 'cancelled: nothing written');

  // confirmed: all three, each audited with the recipe's name
  const audit = async () => (await alba.json('/api/audit?limit=1000'))?.rows ?? [];
  page.once('dialog', (d) => void d.accept());
  await tid('recipes-apply').click();
  await tid('recipes-note').filter({ hasText: 'Applied: 3 values written' }).waitFor();
  assert.deepEqual(await values(), { 'CT_STP.PRE': 5, 'Away.PRE': 3500, 'Back.PRE': 2500 });
  const rows = (await audit()).filter((r) => r.detail === 'recipe batch-a');
  assert.equal(rows.length, 3, `a row per value: ${JSON.stringify(rows)}`);
  assert.deepEqual(rows.map((r) => r.user), ['olga', 'olga', 'olga'], 'by the operator');
  assert.deepEqual(rows.map((r) => r.target).sort(), [...PRESETS].sort());
  await b.shot('recipes-applied');

  // the bad ones: refused with their row named, nothing written
  for (const [name, says] of [
    ['batch-bad', /recipe `batch-bad` not applied, nothing written: row 2 \(`Away\.PRE`\)/],
    ['batch-input', /recipe `batch-input` not applied, nothing written: row 2 \(`S_REC`\)/],
  ]) {
    await tid('recipes-list').selectOption(name);
    await page.waitForFunction((n) => document.querySelector('[data-testid="recipes-name"]').value === n, name);
    page.once('dialog', (d) => void d.accept());
    await tid('recipes-apply').click();
    await tid('toast-error').filter({ hasText: says }).waitFor();
    // the previous apply's "Applied" does not stay beside Apply
    assert.equal(await tid('recipes-note').textContent(), 'Not applied: nothing written', `${name}: the status line`);
    assert.deepEqual(await values(), { 'CT_STP.PRE': 5, 'Away.PRE': 3500, 'Back.PRE': 2500 }, `${name}: nothing written`);
    if (name === 'batch-bad') await b.shot('recipes-refused');
  }
  assert.equal((await audit()).filter((r) => /batch-(bad|input)/.test(r.detail ?? '') && r.action === 'write').length, 0, 'nothing audited as written');
});
