// End-to-end test of the Verify & Test page (issue 37, point 3) in Chromium,
// against `alba run` on a copy of examples/start-stop whose properties.toml
// holds one property that is proved (Stop wins) and one that is refuted (the
// lamp never lights: it does, 5 s after Start):
// - Run properties lists both with their result; the refuted one opens its
//   counterexample as a replay on the violating scan, marked, with the lamp's
//   coil energised on the ladder and Lamp = 1;
// - the step buttons and the slider move through the scans: one scan before,
//   the lamp is off and its coil unpowered; the first scan is scan 1;
// - a reachable property's witness opens the same way, its last scan "reached";
// - Run tests runs the example's stop-wins table (run-and-stop removed): it
//   passes, and the coverage overlay marks the lamp's coil as never powered
//   (the motor never runs in that table); unticked, the marks go.
// - on a copy of examples/state-net-batch (a state net and a ladder), a
//   refuted property's counterexample draws the net with the net's own view:
//   the token where the scan has it, moving as the slider steps back, the
//   transition that fired in a scan marked.
// Screenshots (verify-counterexample.png, verify-coverage.png,
// verify-net-counterexample.png, verify-net-firing.png) in E2E_OUT.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { rmSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { elementId, useStudio } from './harness.mjs';

const eva = { name: 'eva', role: 'engineer', password: 'proofs-and-tables-5521' };
const PROPERTIES = `[[property]]
name = "stop wins"
never = "Stop AND Motor"

[[property]]
name = "the lamp never lights"
never = "Lamp"

[[property]]
name = "the lamp lights"
reachable = "Lamp"
`;

let alba, b;
useStudio('start-stop', (c) => ({ alba, b } = c), {
  users: [eva],
  prepare: (dir) => {
    writeFileSync(join(dir, 'properties.toml'), PROPERTIES);
    rmSync(join(dir, 'tests/run-and-stop.test.csv'));
  },
});

const NET_PROPERTIES = `[[property]]
name = "the mixer never runs"
never = "Mixer"
`;
let netAlba, nb;
useStudio('state-net-batch', (c) => ({ alba: netAlba, b: nb } = c), {
  users: [eva],
  prepare: (dir) => writeFileSync(join(dir, 'properties.toml'), NET_PROPERTIES),
});

async function login(alba, b) {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('login-form').waitFor();
  await tid('login-user').fill(eva.name);
  await tid('login-password').fill(eva.password);
  await tid('login-submit').click();
  await tid('tab-verify').waitFor();
}

const on = (id) => b.page.locator(`[data-testid="verify-ladder"] [data-testid="el-${id}"]`).getAttribute('data-on');

test('a refuted property opens its counterexample on the ladder, stepped scan by scan; tests show coverage', async () => {
  const { page, tid } = b;
  await login(alba, b);
  await alba.login(eva.name, eva.password);
  const program = await alba.json('/api/programs/main.lad');
  const lampCoil = elementId(program, 'OTE', ['Lamp']);

  await tid('tab-verify').click();
  await tid('verify-view').waitFor();
  await tid('verify-run').click();
  await tid('property-1').waitFor({ timeout: 120_000 });
  assert.equal(await tid('property-0').getAttribute('data-result'), 'proved');
  assert.equal(await tid('property-1').getAttribute('data-result'), 'refuted');
  assert.match(await tid('property-1').textContent(), /the lamp never lights/);
  // How each was decided: the interlock by k-induction, the refuted one by the search.
  assert.equal(await tid('method-0').textContent(), 'k-induction');
  assert.equal(await tid('method-1').textContent(), 'explicit');
  assert.equal(await tid('open-0').count(), 0, 'a proved property has no counterexample');

  // The counterexample opens on the violating scan.
  await tid('open-1').click();
  await tid('replay').waitFor();
  assert.equal(await tid('replay-scan').getAttribute('data-violation'), 'true');
  const last = Number(await tid('replay-slider').getAttribute('max'));
  assert.ok(last >= 500, `the lamp lights 5 s after Start: ${last + 1} scans of 10 ms`);
  assert.equal(Number(await tid('replay-slider').inputValue()), last);
  assert.equal(await tid('replay-value-Lamp').locator('td').nth(1).textContent(), '1');
  assert.equal(await on(lampCoil), 'true');
  assert.match(await tid('replay').getAttribute('class'), /violation/);
  await b.shot('verify-counterexample');

  // One scan before: the lamp is off, its coil unpowered, no violation.
  await tid('replay-prev').click();
  assert.equal(Number(await tid('replay-slider').inputValue()), last - 1);
  assert.equal(await tid('replay-scan').getAttribute('data-violation'), 'false');
  assert.equal(await tid('replay-value-Lamp').locator('td').nth(1).textContent(), '0');
  assert.equal(await on(lampCoil), 'false');

  // The first scan, then the slider half-way, then back to the violation.
  await tid('replay-first').click();
  assert.match(await tid('replay-scan').textContent(), /^scan 1 of /);
  await tid('replay-slider').fill(String(Math.floor(last / 2)));
  assert.equal(Number(await tid('replay-slider').inputValue()), Math.floor(last / 2));
  assert.match(await tid('replay-scan').textContent(), new RegExp(`^scan ${Math.floor(last / 2) + 1} of ${last + 1}`));
  assert.equal(await tid('replay-value-Motor').locator('td').nth(1).textContent(), '1', 'the motor runs while the delay times');
  await tid('replay-violation').click();
  assert.equal(await tid('replay-scan').getAttribute('data-violation'), 'true');

  // A reachable property's witness opens the same way, its last scan reached, not failing.
  assert.equal(await tid('property-2').getAttribute('data-result'), 'proved');
  await tid('open-2').click();
  assert.match(await tid('replay-scan').textContent(), /reached here$/);
  assert.doesNotMatch(await tid('replay').getAttribute('class'), /violation/);
  assert.equal(await tid('replay-value-Lamp').locator('td').nth(1).textContent(), '1');

  // The tables and the coverage overlay.
  await tid('tests-run').click();
  await tid('test-stop-wins').waitFor({ timeout: 60_000 });
  assert.equal(await tid('test-run-and-stop').count(), 0);
  assert.equal(await tid('test-stop-wins').getAttribute('data-result'), 'passed');
  assert.match(await tid('verify-coverage').textContent(), /of 3 rungs/);
  const coil = page.locator(`[data-testid="verify-ladder"] [data-testid="el-${lampCoil}"]`);
  assert.match(await coil.getAttribute('class'), /never-powered/);
  await b.shot('verify-coverage');
  await tid('coverage-toggle').uncheck();
  assert.doesNotMatch(await coil.getAttribute('class'), /never-powered/);
  assert.deepEqual(b.errors, []);
});

test('a net’s counterexample is drawn on the net: tokens and firings scan by scan', async () => {
  const { tid, page } = nb;
  await login(netAlba, nb);
  await tid('tab-verify').click();
  await tid('verify-run').click();
  await tid('property-0').waitFor({ timeout: 120_000 });
  assert.equal(await tid('property-0').getAttribute('data-result'), 'refuted');
  await tid('open-0').click();
  await tid('replay').waitFor();
  const chart = tid('verify-chart-batch.pnml');
  await chart.waitFor();
  const node = (id) => chart.locator(`[data-testid="net-node-${id}"]`);
  const tokens = async () => {
    const out = {};
    for (const id of ['idle', 'start', 'fill', 'filled', 'mix', 'mixed']) out[id] = await node(id).getAttribute('data-tokens');
    return out;
  };
  // The violating scan: the mixer runs, the token has left the place `idle` and `fill`.
  assert.equal(await tid('replay-scan').getAttribute('data-violation'), 'true');
  assert.equal(await tid('replay-value-Mixer').locator('td').nth(1).textContent(), '1');
  const atViolation = await tokens();
  assert.equal(atViolation.idle, '0', JSON.stringify(atViolation));
  assert.equal(atViolation.fill, '0', JSON.stringify(atViolation));
  assert.ok(atViolation.mix === '1' || atViolation.mixed === '1', JSON.stringify(atViolation));
  await chart.scrollIntoViewIfNeeded();
  await nb.shot('verify-net-counterexample');
  // Back to the first scan: the token waits at `idle` or has just been taken by Start.
  await tid('replay-first').click();
  const first = await tokens();
  assert.ok(first.idle === '1' || first.start === '1', JSON.stringify(first));
  assert.equal(first.mix, '0');
  // Some scan of the run fires a transition: stepping through the changes finds it marked.
  let fired = 0;
  for (let k = 0; k < 12 && fired === 0; k++) {
    await tid('replay-next-change').click();
    fired = await chart.locator('g.fired').count();
  }
  assert.ok(fired > 0, 'a firing is shown on the net');
  await chart.scrollIntoViewIfNeeded();
  await nb.shot('verify-net-firing');
  assert.deepEqual(nb.errors, []);
  void page;
});
