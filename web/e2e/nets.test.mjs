// The net editor (issue 20) on a copy of examples/state-net-batch with an
// empty normal-mode net `draw.pnml` added: draw three states, a timer and a
// condition bound to a tag, undo/redo, a bad guard shown on its transition
// and not saved, save online, watch the token move when the tag changes and
// the lamp of the last state light, then analyse the net and replay the
// firing sequence to its deadlock on the canvas.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { appendFileSync, readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { useStudio } from './harness.mjs';

const EMPTY = `<?xml version="1.0" encoding="UTF-8"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
  <net id="draw" type="http://www.pnml.org/version-2009/grammar/ptnet">
    <toolspecific tool="alba" version="1"><mode>normal</mode></toolspecific>
    <page id="page0"/>
  </net>
</pnml>
`;

let alba, b;
useStudio('state-net-batch', (s) => ({ alba, b } = s), {
  prepare: (dir) => {
    writeFileSync(join(dir, 'draw.pnml'), EMPTY);
    const toml = readFileSync(join(dir, 'alba.toml'), 'utf8').replace('programs = ["batch.pnml", "main.lad"]', 'programs = ["batch.pnml", "main.lad", "draw.pnml"]');
    writeFileSync(join(dir, 'alba.toml'), toml);
    appendFileSync(join(dir, 'tags.csv'), 'Go,BOOL,,,,operator go-ahead (the condition of draw.pnml)\nLamp2,BOOL,,,,on while draw.pnml is in its last state\n');
  },
});

test('the example net drawn live: the token waits at its condition, then runs through the timers', async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}#/program/batch.pnml`);
  await tid('net-batch.pnml').waitFor();
  assert.equal(await page.locator('[data-testid="net-svg"] .net-node').count(), 10);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-live-state"]')?.textContent === 'live');
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-start"]')?.dataset.enabled === 'true');
  const force = (value) => alba.api('/api/forces/Start', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });
  assert.equal((await force(true)).status, 200);
  // the fill timer holds the token and shows its elapsed time
  await page.waitForFunction(() => /\d+\/2000 ms/.test(document.querySelector('[data-testid="net-node-filled"] .net-info')?.textContent ?? ''));
  await b.shot('net-batch-live');
  await alba.api('/api/forces/Start', { method: 'DELETE', headers: { 'content-type': 'application/json' } });
  await tid('net-history-0').waitFor();
  assert.deepEqual(b.errors, []);
});

test('draw a net, a refused guard, save, run it live, analyse and replay its deadlock', async () => {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('tab-program-draw.pnml').click();
  const view = tid('net-draw.pnml');
  await view.waitFor();
  await tid('net-svg').waitFor();
  const nodes = () => page.locator('[data-testid="net-svg"] .net-node');
  const arcs = () => page.locator('[data-testid="net-svg"] .net-arc');
  const setField = async (testid, value) => {
    await tid(testid).fill(value);
    await tid(testid).press('Enter');
  };
  // Three states, a timer and a condition from the palette: each goes right of the one before.
  for (const k of ['state', 'timer', 'state', 'condition', 'state']) await tid(`net-add-${k}`).click();
  assert.equal(await nodes().count(), 5);
  for (const id of ['S0', 'Timer1', 'S1', 'C1', 'S2']) await tid(`net-node-${id}`).waitFor();
  // Arcs with the arc tool: a click on the start, one on the end.
  await tid('net-tool-arc').click();
  for (const [a, z] of [['S0', 'Timer1'], ['Timer1', 'S1'], ['S1', 'C1'], ['C1', 'S2']]) {
    await tid(`net-node-${a}`).click();
    await tid(`net-node-${z}`).click();
  }
  await page.keyboard.press('Escape');
  assert.equal(await arcs().count(), 4);
  // An arc between two states is refused, saying why.
  await tid('net-tool-arc').click();
  await tid('net-node-S0').click();
  await tid('net-node-S1').click();
  await tid('toast-error').filter({ hasText: 'not two of the same kind' }).waitFor();
  await page.keyboard.press('Escape');
  assert.equal(await arcs().count(), 4);
  // Undo takes back the last arc, redo puts it back.
  await tid('net-canvas').focus();
  await page.keyboard.press('Control+z');
  assert.equal(await arcs().count(), 3);
  await page.keyboard.press('Control+y');
  assert.equal(await arcs().count(), 4);
  // Properties: the first state holds the token, the timer waits 300 ms, the last state lights Lamp2.
  await tid('net-node-S0').click();
  await setField('net-prop-initial', '1');
  await tid('net-node-Timer1').click();
  await setField('net-prop-prop-delay', 'T#300ms');
  await tid('net-node-S2').click();
  await setField('net-prop-tag', 'Lamp2');
  // The condition on a mistyped tag: the server's check puts it on the transition.
  await tid('net-node-C1').click();
  await setField('net-prop-guard', 'Goo');
  await tid('diagnostics').locator('li', { hasText: 'Goo' }).waitFor();
  await tid('net-error-C1').waitFor();
  assert.match(await tid('net-error-C1').locator('title').textContent(), /Goo/);
  assert.match(await tid('net-prop-error').textContent(), /Goo/);
  await b.shot('net-editor-error');
  // Save is refused: nothing saved.
  await tid('btn-save').click();
  await tid('toast-error').filter({ hasText: 'not saved' }).waitFor();
  assert.doesNotMatch((await alba.json('/api/programs/draw.pnml')).text, /place/);
  // Fixed, saved and applied online.
  await tid('net-node-C1').click();
  await setField('net-prop-guard', 'Go');
  await page.waitForFunction(() => !document.querySelector('[data-testid="net-error-C1"]'));
  await tid('btn-save').click();
  await tid('toast-info').filter({ hasText: 'draw.pnml saved and applied online' }).waitFor();
  const saved = (await alba.json('/api/programs/draw.pnml')).text;
  assert.match(saved, /<guard>Go<\/guard>/);
  assert.match(saved, /<position x="60" y="60"\/>/, 'positions are saved');
  // Live: the token leaves S0 through the timer and waits at the condition until Go.
  await page.waitForFunction(() => document.querySelector('[data-testid="net-live-state"]')?.textContent === 'live');
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-C1"]')?.dataset.enabled === 'true');
  assert.equal(await tid('net-node-S2').getAttribute('data-tokens'), '0');
  assert.equal((await alba.json('/api/tags/Lamp2')).value, false);
  await b.shot('net-live-waiting');
  const w = await alba.api('/api/tags/Go', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value: true }) });
  assert.equal(w.status, 200);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-S2"]')?.dataset.tokens === '1');
  assert.equal(await tid('net-node-C1').getAttribute('data-enabled'), 'false');
  assert.equal((await alba.json('/api/tags/Lamp2')).value, true, 'the last state lights its lamp');
  await tid('net-history-0').waitFor();
  await b.shot('net-live');
  // The analysis of the saved net: bounded, one deadlock (the last state), replayed step by step.
  await tid('net-analyse').click();
  await tid('net-an-bounded').filter({ hasText: 'yes' }).waitFor();
  assert.equal(await tid('net-an-deadlocks').textContent(), '1');
  assert.deepEqual(await tid('net-trace').locator('li').allTextContents(), ['Timer1', 'C1']);
  await tid('net-replay').click();
  await page.waitForFunction(() => document.querySelector('[data-testid="net-live-state"]')?.textContent === 'replay');
  assert.equal(await tid('net-node-S0').getAttribute('data-tokens'), '1');
  await tid('net-replay-next').click();
  assert.equal(await tid('net-node-S1').getAttribute('data-tokens'), '1');
  assert.match(await tid('net-node-Timer1').getAttribute('class'), /fired/);
  await tid('net-replay-next').click();
  assert.equal(await tid('net-node-S2').getAttribute('data-tokens'), '1');
  await tid('net-replay-dead').waitFor();
  await b.shot('net-analysis-replay');
  await tid('net-replay-close').click();
  // The place invariant S0 + S1 + S2 lights its places on hover.
  await tid('net-an-pinv-0').hover();
  assert.match(await tid('net-node-S1').getAttribute('class'), /\blit\b/);
  // Stopped, the initial marking written back (engineer): the token is in S0 again.
  await tid('net-stop').click();
  await tid('confirm-ok').click();
  await tid('status-state').filter({ hasText: 'stopped' }).waitFor();
  await tid('net-reset').click();
  await tid('toast-info').filter({ hasText: 'initial marking written' }).waitFor();
  assert.equal((await alba.json('/api/tags/draw.S0')).value, 1);
  assert.equal((await alba.json('/api/tags/draw.S2')).value, 0);
  assert.deepEqual(b.errors, []);
});
