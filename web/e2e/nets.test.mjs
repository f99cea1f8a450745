// The net editor (issue 20) on a copy of examples/state-net-batch with an
// empty normal-mode net `draw.pnml` added: draw three states, a timer and a
// condition bound to a tag, undo/redo, a bad guard shown on its transition
// and not saved, save online, watch the token move when the tag changes and
// the lamp of the last state light, then analyse the net and replay the
// firing sequence to its deadlock on the canvas; stopped, reset the marking and
// single-step the net with F6, the runtime's enabled transitions highlighted.
// A big net's analysis shows its progress and is cancelled (issue 38).
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

/** A Petri-mode net of `k` independent 3-place cycles: 3^k states. */
function cycles(k) {
  let body = '';
  for (let c = 0; c < k; c++) {
    for (let i = 0; i < 3; i++) {
      body += `<place id="c${c}p${i}">${i === 0 ? '<initialMarking><text>1</text></initialMarking>' : ''}</place><transition id="c${c}t${i}"/>`;
      body += `<arc id="c${c}a${i}" source="c${c}p${i}" target="c${c}t${i}"/><arc id="c${c}b${i}" source="c${c}t${i}" target="c${c}p${(i + 1) % 3}"/>`;
    }
  }
  return `<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml"><net id="big" type="http://www.pnml.org/version-2009/grammar/ptnet"><page id="g">${body}</page></net></pnml>\n`;
}

let alba, b;

/** Waits (up to 10 s) until the tag `name` has the value `v` on the server. */
async function tagIs(name, v) {
  for (let k = 0; k < 500; k++) {
    if ((await alba.json(`/api/tags/${name}`)).value === v) return;
    await new Promise((r) => setTimeout(r, 20));
  }
  assert.fail(`${name} never became ${v}`);
}
useStudio('state-net-batch', (s) => ({ alba, b } = s), {
  prepare: (dir) => {
    writeFileSync(join(dir, 'draw.pnml'), EMPTY);
    writeFileSync(join(dir, 'big.pnml'), cycles(15));
    writeFileSync(join(dir, 'huge.pnml'), cycles(150));
    const toml = readFileSync(join(dir, 'alba.toml'), 'utf8').replace('programs = ["batch.pnml", "main.lad"]', 'programs = ["batch.pnml", "main.lad", "draw.pnml", "big.pnml", "huge.pnml"]');
    writeFileSync(join(dir, 'alba.toml'), toml);
    appendFileSync(join(dir, 'tags.csv'), 'Go,BOOL,,,,operator go-ahead (the condition of draw.pnml)\nLamp2,BOOL,,,,on while draw.pnml is in its last state\n');
  },
});

test('the example net drawn live: the token waits at its condition, then runs through the timers', async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}#/program/batch.pnml`);
  await tid('net-batch.pnml').waitFor();
  // the view is there before its net is drawn: wait for the drawing, then count
  await tid('net-node-start').waitFor();
  assert.equal(await page.locator('[data-testid="net-svg"] .net-node').count(), 10);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-live-state"]')?.textContent === 'live');
  // the token waits at `start`, which is not enabled: its guard (Start) is false, as the runtime says
  await tagIs('batch.start', 1);
  assert.equal(await tid('net-node-start').getAttribute('data-enabled'), 'false');
  const force = (value) => alba.api('/api/forces/Start', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value }) });
  assert.equal((await force(true)).status, 200);
  // the fill timer holds the token, shows its elapsed time, and is enabled (it waits only for its delay)
  await page.waitForFunction(() => /\d+\/2000 ms/.test(document.querySelector('[data-testid="net-node-filled"] .net-info')?.textContent ?? ''));
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-filled"]')?.dataset.enabled === 'true');
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
  // the condition holds the token but is not enabled while its guard (Go) is false
  await tagIs('draw.C1', 1);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-S1"]')?.dataset.tokens === '0');
  assert.equal(await tid('net-node-C1').getAttribute('data-enabled'), 'false');
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
  // F6 steps one scan only while the PLC is stopped: refused, with the server's reason, while it runs.
  await tid('net-canvas').focus();
  await page.keyboard.press('F6');
  await tid('toast-error').filter({ hasText: 'stop it before stepping' }).waitFor();
  // The analysis of the saved net: bounded, one deadlock (the last state), replayed step by step.
  await tid('net-analyse').click();
  await tid('net-an-bounded').filter({ hasText: 'yes' }).waitFor();
  assert.equal(await tid('net-an-deadlocks').textContent(), '1');
  assert.deepEqual(await tid('net-trace').locator('li').allTextContents(), ['Timer1', 'C1']);
  // Each part of the analysis says how far it got.
  for (const part of ['state_space', 'components', 'p_flows', 't_flows', 'p_invariants', 't_invariants']) {
    assert.equal(await tid(`net-an-status-${part}`).textContent(), 'complete', part);
  }
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
  // Stopped, the live view stays on the PLC's marking; F6 runs one scan at a time.
  await page.waitForFunction(() => document.querySelector('[data-testid="net-live-state"]')?.textContent === 'stopped: F6 runs one scan');
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-S0"]')?.dataset.tokens === '1');
  assert.equal((await alba.api('/api/tags/Go', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value: false }) })).status, 200);
  const scans = async () => (await alba.json('/api/status')).scans;
  const stepped = async (before) => {
    for (let k = 0; k < 100 && (await scans()) === before; k++) await new Promise((r) => setTimeout(r, 20));
    assert.equal(await scans(), before + 1, 'one scan per F6');
  };
  const enabledIds = () => page.evaluate(() => [...document.querySelectorAll('[data-testid="net-svg"] .net-transition')].filter((g) => g.dataset.enabled === 'true').map((g) => g.dataset.id));
  await tid('net-canvas').focus();
  // Scan 1: S0 passes its token to the timer, which holds it: enabled (it only waits for its delay).
  let n = await scans();
  await page.keyboard.press('F6');
  await stepped(n);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-S0"]')?.dataset.tokens === '0');
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-Timer1"]')?.dataset.enabled === 'true');
  assert.deepEqual(await enabledIds(), ['Timer1']);
  // The toolbar's button does the same: the timer starts; 300 ms later a step finds it done and it fires.
  n = await scans();
  await tid('net-step').click();
  await stepped(n);
  await new Promise((r) => setTimeout(r, 400));
  n = await scans();
  await page.keyboard.press('F6');
  await stepped(n);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-S1"]')?.dataset.tokens === '1');
  await page.waitForFunction(() => /fired Timer1/.test(document.querySelector('[data-testid="net-history-0"]')?.textContent ?? ''));
  // the history follows each message, the drawing the next batch of them (an animation frame later)
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-Timer1"]')?.classList.contains('fired'));
  // The condition holds the token but its guard (Go) is false: not enabled — the runtime says so, not the arcs.
  n = await scans();
  await page.keyboard.press('F6');
  await stepped(n);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-S1"]')?.dataset.tokens === '0');
  assert.equal(await tid('net-node-C1').getAttribute('data-tokens'), '1', 'the token is drawn on the condition');
  assert.deepEqual(await enabledIds(), []);
  await b.shot('net-step-guard-false');
  // Go: the next step fires C1 and the token reaches S2.
  assert.equal((await alba.api('/api/tags/Go', { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ value: true }) })).status, 200);
  n = await scans();
  await page.keyboard.press('F6');
  await stepped(n);
  await page.waitForFunction(() => document.querySelector('[data-testid="net-node-S2"]')?.dataset.tokens === '1');
  await page.waitForFunction(() => /fired C1/.test(document.querySelector('[data-testid="net-history-0"]')?.textContent ?? ''));
  assert.equal((await alba.json('/api/status')).state, 'stopped');
  await b.shot('net-step');
  assert.deepEqual(b.errors, []);
});

test("a big net's analysis shows its progress and is cancelled; the next one runs", async () => {
  const { page, tid } = b;
  await page.goto(`${alba.url}#/program/huge.pnml`);
  await tid('net-huge.pnml').waitFor();
  await tid('net-analyse').click();
  // 3^150 states, 150 successors each: the million states the studio explores take
  // seconds (3^15's took less than one), and the progress line counts them meanwhile.
  await tid('net-analysis-progress').filter({ hasText: /state space: [\d,.\s]+ states/ }).waitFor({ timeout: 30_000 });
  await b.shot('net-analysis-progress');
  await tid('net-analysis-cancel').click();
  await tid('net-analysis-error').filter({ hasText: 'Analysis cancelled.' }).waitFor();
  // The server stopped it: another analysis runs (429 until the cancelled one has stopped).
  await page.goto(`${alba.url}#/program/batch.pnml`);
  await tid('net-batch.pnml').waitFor();
  for (let k = 0; ; k++) {
    await tid('net-analyse').click();
    await page.waitForFunction(() => document.querySelector('[data-testid="net-an-status-state_space"], [data-testid="net-analysis-error"]'));
    if (await tid('net-an-status-state_space').count()) break;
    assert.match(await tid('net-analysis-error').textContent(), /analysis of this project is running/);
    assert.ok(k < 150, 'the cancelled analysis never stopped');
    await new Promise((r) => setTimeout(r, 200));
  }
  assert.equal(await tid('net-an-status-state_space').textContent(), 'complete');
  assert.equal(await tid('net-an-status-symbolic').count(), 0, 'decision diagrams only when they ran');
  // With decision diagrams, the big net's 3^15 states are counted exactly, at once.
  await page.goto(`${alba.url}#/program/big.pnml`);
  await tid('net-big.pnml').waitFor();
  await tid('net-analyse-symbolic').check();
  await tid('net-analyse').click();
  await tid('net-an-status-symbolic').filter({ hasText: 'complete' }).waitFor({ timeout: 60_000 });
  assert.equal(await tid('net-an-space').textContent(), '14348907 states, counted with decision diagrams');
  // and its deadlocks, liveness and reversibility decided on the diagrams
  assert.equal(await tid('net-an-status-symbolic_facts').textContent(), 'complete');
  assert.equal(await tid('net-an-deadlocks').textContent(), '0');
  assert.equal(await tid('net-an-live').textContent(), 'yes');
  assert.equal(await tid('net-an-reversible').textContent(), 'yes');
  assert.equal(await tid('net-an-dead').textContent(), 'none');
  // The toasts of the steps before (4–8 s each) would cover the lower rows of the shot.
  await page.waitForFunction(() => !document.querySelector('[data-testid="toasts"] .toast'), null, { timeout: 15_000 });
  await b.shot('net-analysis-symbolic');
  assert.deepEqual(b.errors, []);
});
