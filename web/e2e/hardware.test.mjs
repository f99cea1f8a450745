// End-to-end tests of the Hardware tab (issue 33) in Chromium, against
// `alba run` on a copy of examples/start-stop (no [board] yet) with an
// engineer and a viewer, and the byte-code interpreter for the Nano running
// on the emulated board (`alba-board`: simavr paced to real time, its UART on
// a pty, as crates/cli/tests/it/download.rs runs it):
// - a viewer sees the tab with every change disabled, and the API refuses them (403);
// - the engineer chooses the Nano and its port (typed by hand), saves: the pin
//   table follows the Nano and the port is listed; Identify names the interpreter;
// - a stand-alone sketch built for the Nano with its sizes against the limits;
// - the byte code downloaded with the progress reaching 100 %, the result kept
//   after a reload, and Verify reads it back equal;
// - a record the board's memory does not keep (an EEPROM cell stuck): the job fails
//   with flag 20 in words, and the board still runs the program it had;
// - a cable pulled in the middle of a download (the board's pty closed): the job
//   says so, and the board, plugged in again, runs the program it had;
// - a pin conflict shown on its row with the code `alba check` gives, and refused
//   at save (alba.toml unchanged);
// - attach: the controller (remote-I/O) firmware on a second emulated Nano used as
//   the running PLC's I/O without restarting `alba run`: a pin pressed on the board
//   energises its contact in the ladder, the coil's pin follows, the drawing
//   lights the pins that are on; detach: the
//   board's outputs off, the simulated I/O back.
// - Upload: the sketch built and uploaded as a job with avrdude's progress; the
//   avrdude is a stand-in on alba run's PATH (tools/fake-avrdude in the test's
//   folder: no real board here), which records its command line and draws
//   avrdude's progress bars; the command line is checked as `alba export
//   arduino --upload` builds it.
// Screenshots (hardware-viewer.png, hardware-board.png, hardware-download.png,
// hardware-failed.png, hardware-conflict.png, hardware-attached.png,
// hardware-attached-ladder.png, hardware-attached-live.png, hardware-cable-pulled.png)
// in E2E_OUT.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { createInterface } from 'node:readline';
import { elementId, openBrowser, repo, startAlba } from './harness.mjs';

const USERS = [
  { name: 'eva', role: 'engineer', password: 'boards-and-pins-4410' },
  { name: 'victor', role: 'viewer', password: 'only-looking-8812' },
];
const [eva, victor] = USERS;
const albaBin = process.env.ALBA_BIN ?? join(repo, 'target/debug/alba');

let alba, b, board, work, link, ctl;

/** The interpreter for the Nano (aurora pin map) and the emulated board, on `work/link`. */
async function startBoard() {
  work = mkdtempSync(join(tmpdir(), 'alba-e2e-board-'));
  let r = spawnSync(albaBin, ['export', 'interpreter', '--board', 'nano', '--pinmap', 'aurora', '-o', work, '--build'], { encoding: 'utf8' });
  assert.equal(r.status, 0, `alba export interpreter: ${r.stderr}`);
  r = spawnSync('bash', ['-c', 'set -e; source scripts/common.sh; source scripts/avr.sh; build_board "$1"', '_', join(work, 'alba-board')], { cwd: repo, encoding: 'utf8' });
  assert.equal(r.status, 0, `build_board: ${r.stderr}`);
  link = join(work, 'link');
  board = spawn(join(work, 'alba-board'), [join(work, 'alba_interp/build/sketch.elf'), '-m', 'atmega328p', '--tty', link, '--pins', 'D12,D13', '--eeprom', join(work, 'eeprom.bin')], {
    stdio: ['pipe', 'pipe', 'ignore'],
  });
  answers = createInterface({ input: board.stdout });
  await new Promise((ok, fail) => {
    const timer = setTimeout(() => fail(new Error('alba-board did not start in 30 s')), 30_000);
    answers.once('line', (line) => {
      clearTimeout(timer);
      if (line.startsWith('ready ')) ok();
      else fail(new Error(`alba-board: ${line}`));
    });
  });
}

/** A command of the emulated board (`stuck 5`: an EEPROM cell that keeps its value) and its answer. */
let answers;
async function boardCmd(c) {
  const answer = new Promise((ok) => answers.once('line', ok));
  board.stdin.write(`${c}\n`);
  return answer;
}

/** A stand-in for avrdude in `dir`: records its arguments, draws avrdude's bars; fails on a port named `*gone*`. */
function fakeAvrdude(dir) {
  const script = `#!/bin/sh
echo "$@" > "${dir}/avrdude-args"
case "$*" in *gone*) echo "avrdude: ser_open(): can't open device" >&2; exit 1;; esac
printf 'avrdude: writing flash\n\nWriting | ' >&2
for i in $(seq 1 50); do printf '#' >&2; sleep 0.02; done
printf ' | 100%% 1.00s\n\nReading | ' >&2
for i in $(seq 1 50); do printf '#' >&2; sleep 0.01; done
printf ' | 100%% 0.50s\n\navrdude: flash verified\n' >&2
`;
  writeFileSync(join(dir, 'avrdude'), script, { mode: 0o755 });
}

before(async () => {
  await startBoard();
  fakeAvrdude(work);
  alba = await startAlba('start-stop', { users: USERS, env: { PATH: `${work}:${process.env.PATH}` } });
  b = await openBrowser();
});

after(async () => {
  await b?.close();
  await alba?.stop();
  board?.stdin.end('quit\n');
  board?.kill();
  ctl?.proc.stdin.end('quit\n');
  ctl?.proc.kill();
  if (work) rmSync(work, { recursive: true, force: true });
});

async function login(user) {
  const { page, tid } = b;
  await page.goto(alba.url);
  await tid('login-form').waitFor();
  await tid('login-user').fill(user.name);
  await tid('login-password').fill(user.password);
  await tid('login-submit').click();
  await tid('tab-hardware').waitFor();
}

async function logout() {
  await b.page.context().clearCookies();
}

const json = (method, value) => ({ method, headers: { 'content-type': 'application/json' }, body: JSON.stringify(value) });

test('a viewer sees the Hardware tab with every change disabled; the API refuses them', async () => {
  const { tid } = b;
  await login(victor);
  await tid('tab-hardware').click();
  await tid('hardware-view').waitFor();
  await tid('hw-board').locator('option').first().waitFor({ state: 'attached' });
  for (const id of ['hw-save', 'hw-build', 'hw-upload', 'hw-download', 'hw-identify', 'hw-verify', 'hw-attach']) {
    assert.equal(await tid(id).isDisabled(), true, `${id} is disabled for a viewer`);
    assert.equal(await tid(id).getAttribute('title'), 'needs the engineer role');
  }
  await b.shot('hardware-viewer');
  await alba.login(victor.name, victor.password);
  for (const [method, path, body] of [
    ['PUT', '/api/hardware/board', { board: 'nano' }],
    ['POST', '/api/hardware/build', { board: 'nano', kind: 'sketch' }],
    ['POST', '/api/hardware/download', { port: link }],
    ['POST', '/api/hardware/upload', { port: link, board: 'nano', kind: 'sketch' }],
    ['POST', '/api/hardware/attach', { port: link, mode: 'controller' }],
    ['POST', '/api/hardware/board/undo', {}],
  ]) {
    const r = await alba.api(path, json(method, body));
    assert.equal(r.status, 403, `${method} ${path}: ${JSON.stringify(r.body)}`);
  }
  assert.equal((await alba.api('/api/hardware')).status, 200);
  await logout();
});

test('the engineer chooses the Nano and its port; the table follows; Identify names the interpreter', async () => {
  const { tid } = b;
  await login(eva);
  await tid('tab-hardware').click();
  await tid('hw-board').locator('option[value="nano"]').waitFor({ state: 'attached' });
  await tid('hw-board').selectOption('nano');
  await tid('hw-port-typed').fill(link);
  await tid('hw-save').click();
  // aurora on the Nano: Start on D2, Motor on D12
  await tid('hw-row-DI:1/0').filter({ hasText: 'Start' }).waitFor();
  assert.equal(await tid('hw-pin-DI:1/0').inputValue(), 'D2');
  await tid('hw-row-DO:2/0').filter({ hasText: 'Motor' }).waitFor();
  const toml = readFileSync(join(alba.dir, 'alba.toml'), 'utf8');
  assert.match(toml, /\[board\]\s*\nmodel = "nano"/);
  assert.ok(toml.includes(`port = "${link}"`), toml);
  // the port is the project's now: listed
  await tid('hw-port-typed').fill('');
  await tid('hw-refresh').click();
  await tid('hw-ports').locator(`option[value="${link}"]`).waitFor({ state: 'attached' });
  await tid('hw-ports').selectOption(link);
  // the drawing lights the wired pins
  await tid('hw-board-pin-D12').and(b.page.locator('.hw-do')).waitFor({ state: 'attached' });
  await tid('hw-identify').click();
  await tid('hw-port-info').filter({ hasText: 'Arduino Nano with Alba\'s byte-code interpreter' }).waitFor({ timeout: 20_000 });
  await b.shot('hardware-board');
});

test('a stand-alone sketch for the Nano is built with its sizes against the limits', async () => {
  const { tid } = b;
  await tid('hw-kind').selectOption('sketch');
  await tid('hw-build').click();
  await tid('hw-flash').filter({ hasText: 'of 32256 bytes' }).waitFor({ timeout: 300_000 });
  await tid('hw-ram').filter({ hasText: 'of 2048 bytes' }).waitFor();
  const used = Number((await tid('hw-flash').textContent()).match(/(\d+) of 32256/)[1]);
  assert.ok(used > 1000 && used < 32256, `flash used: ${used}`);
});

test('Upload builds the sketch and runs avrdude as `alba export arduino --upload` does, its progress a job', async () => {
  const { page, tid } = b;
  await tid('hw-kind').selectOption('sketch');
  await tid('hw-upload').click();
  const seen = new Set();
  for (let i = 0; i < 2400; i++) {
    seen.add(Number(await tid('hw-progress').getAttribute('value')));
    const state = await tid('hw-job').getAttribute('data-state');
    if (state === 'done' || state === 'failed') break;
    await page.waitForTimeout(50);
  }
  assert.equal(await tid('hw-job').getAttribute('data-state'), 'done', await tid('hw-job').textContent());
  await tid('hw-job-message').filter({ hasText: /uploaded the stand-alone sketch to .*nano: flash \d+ of 32256 bytes/ }).waitFor();
  assert.ok([...seen].some((p) => p > 10 && p < 100), `the bar moved with avrdude's: ${[...seen]}`);
  const args = readFileSync(join(work, 'avrdude-args'), 'utf8').trim();
  assert.match(args, new RegExp(`^-p m328p -c arduino -P ${link} -b 57600 -D -U flash:w:.*sketch\\.hex:i$`));
  // avrdude failing: the job fails with its words
  await tid('hw-port-typed').fill(join(work, 'gone'));
  await tid('hw-upload').click();
  await tid('hw-job').and(page.locator('[data-state="failed"]')).waitFor({ timeout: 120_000 });
  await tid('hw-job-message').filter({ hasText: "not uploaded: avrdude failed (exit status: 1): avrdude: ser_open(): can't open device" }).waitFor();
  await tid('hw-port-typed').fill('');
});

test('the byte code goes to the board with the progress reaching 100 %, the result kept after a reload', async () => {
  const { page, tid } = b;
  await tid('hw-download').click();
  const seen = new Set();
  // the bar moves while records go
  for (let i = 0; i < 1200; i++) {
    seen.add(Number(await tid('hw-progress').getAttribute('value')));
    const state = await tid('hw-job').getAttribute('data-state');
    if (state === 'done' || state === 'failed') break;
    await page.waitForTimeout(50);
  }
  assert.equal(await tid('hw-job').getAttribute('data-state'), 'done', await tid('hw-job').textContent());
  assert.equal(Number(await tid('hw-progress').getAttribute('value')), 100);
  await tid('hw-job-message').filter({ hasText: /verified: the board runs the new program/ }).waitFor();
  await b.shot('hardware-download');
  await page.reload();
  await tid('tab-hardware').click();
  await tid('hw-job').filter({ hasText: '100 %' }).waitFor();
  await tid('hw-job-message').filter({ hasText: /verified/ }).waitFor();
  // the board runs it: it says so, and Verify reads it back equal
  await tid('hw-identify').click();
  await tid('hw-port-info').filter({ hasText: 'it runs a program' }).waitFor({ timeout: 20_000 });
  await tid('hw-verify').click();
  await tid('hw-verify-result').and(b.page.locator('[data-same="true"]')).filter({ hasText: "verified: the board holds the project's program" }).waitFor({ timeout: 20_000 });
});

test('a record the board does not keep: the flag in words, and the old program still runs', async () => {
  const { tid } = b;
  const program = (await b.page.evaluate(async (port) => (await (await fetch('/api/hardware/identify', { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ port }) })).json()).program, link));
  assert.match(program, /^[0-9a-f]{8}$/);
  // another program, which the board will not take
  const lad = join(alba.dir, 'main.lad');
  const old = readFileSync(lad, 'utf8');
  writeFileSync(lad, '[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);\nXIC(Motor)OTE(Lamp);\n');
  assert.equal(await boardCmd('stuck 5'), 'ok');
  await tid('hw-download').click();
  await tid('hw-job').and(b.page.locator('[data-state="failed"]')).waitFor({ timeout: 30_000 });
  await tid('hw-job-message').filter({ hasText: 'the memory did not keep what was written (20): the board still runs the previous program' }).waitFor();
  await b.shot('hardware-failed');
  assert.equal(await boardCmd('stuck off'), 'ok');
  // Verify: the board's program is not the changed project's
  await tid('hw-verify').click();
  await tid('hw-verify-result').and(b.page.locator('[data-same="false"]')).filter({ hasText: `the board's program id ${program}` }).waitFor({ timeout: 20_000 });
  writeFileSync(lad, old);
  await tid('hw-identify').click();
  await tid('hw-port-info').filter({ hasText: `program id ${program}` }).waitFor({ timeout: 20_000 });
});

test('a cable pulled mid-download: the job ends saying so, and the board keeps its program', async () => {
  const { page, tid } = b;
  const id = async () => (await alba.api('/api/hardware/identify', json('POST', { port: link }))).body;
  await alba.login(eva.name, eva.password);
  const program = (await id()).program;
  assert.match(program, /^[0-9a-f]{8}$/);
  const lad = join(alba.dir, 'main.lad');
  const old = readFileSync(lad, 'utf8');
  writeFileSync(lad, '[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);\nXIC(Motor)OTE(Lamp);\n');
  const before = (await alba.api('/api/hardware')).body.jobs[0]?.id;
  await tid('hw-download').click();
  // the cable pulled (the pty closed) once records go
  let job = null;
  for (let i = 0; i < 4000 && !job; i++) {
    const j = (await alba.api('/api/hardware')).body.jobs[0];
    if (!j || j.id === before) continue;
    if (j.state !== 'running') assert.fail(`the download ended before the cable was pulled: ${j.message}`);
    if (j.progress > 0) job = j;
  }
  assert.ok(job, 'the records never started');
  assert.equal(await boardCmd('unplug'), 'ok');
  await tid('hw-job').and(page.locator('[data-state="failed"]')).waitFor({ timeout: 30_000 });
  await tid('hw-job-message').filter({ hasText: /^the link to the board was lost at record \d+ of \d+ \(cable pulled or board reset\?\): .*: the board still runs the previous program$/ }).waitFor();
  await b.shot('hardware-cable-pulled');
  assert.match(await boardCmd('plug'), /^ok /);
  writeFileSync(lad, old);
  await tid('hw-identify').click();
  await tid('hw-port-info').filter({ hasText: `it runs a program, program id ${program}` }).waitFor({ timeout: 20_000 });
});

test('a pin conflict is shown on its row with its code and refused at save', async () => {
  const { tid } = b;
  const before = readFileSync(join(alba.dir, 'alba.toml'), 'utf8');
  await tid('hw-pin-DO:2/1').fill('D2');
  await tid('hw-save').click();
  await tid('hw-problem-DO:2/1').filter({ hasText: 'E102' }).waitFor();
  await tid('hw-problem-DI:1/0').filter({ hasText: 'D2' }).waitFor();
  assert.equal(readFileSync(join(alba.dir, 'alba.toml'), 'utf8'), before, 'nothing saved');
  await b.shot('hardware-conflict');
  assert.deepEqual(b.errors, []);
});

/** The controller (remote-I/O) firmware for the Nano (aurora map, Modbus RTU) on a second emulated board, on `work/ctl-link`. */
async function startController() {
  const r = spawnSync(albaBin, ['firmware', '--board', 'nano', '--pinmap', 'aurora', '-o', join(work, 'ctl'), '--build'], { encoding: 'utf8' });
  assert.equal(r.status, 0, `alba firmware: ${r.stderr}`);
  const tty = join(work, 'ctl-link');
  const proc = spawn(join(work, 'alba-board'), [join(work, 'ctl/build/sketch.elf'), '-m', 'atmega328p', '--tty', tty, '--pins', 'D12,D13'], {
    stdio: ['pipe', 'pipe', 'ignore'],
  });
  const lines = createInterface({ input: proc.stdout });
  const next = () => new Promise((ok) => lines.once('line', ok));
  const ready = await Promise.race([next(), new Promise((_, fail) => setTimeout(() => fail(new Error('alba-board did not start in 30 s')), 30_000))]);
  assert.match(ready, /^ready /);
  return {
    proc,
    tty,
    async cmd(c) {
      const answer = next();
      proc.stdin.write(`${c}\n`);
      return answer;
    },
  };
}

test('attach: the board is the PLC\'s I/O without a restart, the ladder\'s contacts follow its pins; detach', async () => {
  const { page, tid } = b;
  ctl = await startController();
  await page.reload();
  await tid('tab-hardware').click();
  await tid('hw-attached').filter({ hasText: 'the PLC uses its own I/O (sim)' }).waitFor();
  assert.equal(await tid('hw-detach').isHidden(), true);
  await tid('hw-port-typed').fill(ctl.tty);
  await tid('hw-attach-mode').selectOption('controller');
  await tid('hw-attach').click();
  await tid('hw-attached').and(page.locator('[data-attached="true"]')).filter({ hasText: `attached to ${ctl.tty}` }).waitFor({ timeout: 20_000 });
  assert.equal(await tid('hw-attach').isHidden(), true);
  await b.shot('hardware-attached');
  // The ladder, live from the board: Start (D2) pressed on it energises XIC(Start); Motor seals in on D12.
  const program = await alba.json('/api/programs/main.lad');
  const start = elementId(program, 'XIC', ['Start']);
  const motor = elementId(program, 'OTE', ['Motor']);
  const el = (n, on) => page.locator(`[data-testid="el-${n}"][data-on="${on}"]`);
  await tid('tab-program-main.lad').click();
  await el(start, false).waitFor();
  assert.equal(await ctl.cmd('set D2 1'), 'ok');
  await el(start, true).waitFor({ timeout: 20_000 });
  await el(motor, true).waitFor({ timeout: 20_000 });
  await b.shot('hardware-attached-ladder');
  assert.equal(await ctl.cmd('set D2 0'), 'ok');
  await el(start, false).waitFor({ timeout: 20_000 });
  let pins = '';
  for (let i = 0; i < 200 && pins !== 'pins 1 0'; i++) {
    pins = await ctl.cmd('get');
    await page.waitForTimeout(50);
  }
  assert.equal(pins, 'pins 1 0', 'Motor on the board\'s D12');
  await tid('status-state').filter({ hasText: 'running' }).waitFor();
  // The drawing lights the pins live: Motor's D12 on, Start's D2 released.
  await tid('tab-hardware').click();
  await tid('hw-board-pin-D12').and(page.locator('[data-live="on"]')).waitFor({ timeout: 20_000 });
  await tid('hw-board-pin-D2').and(page.locator('[data-live="off"]')).waitFor();
  await b.shot('hardware-attached-live');
  // Detach: the board's outputs off, its pins not read any more, the PLC running on.
  await tid('hw-detach').click();
  await tid('hw-attached').and(page.locator('[data-attached="false"]')).waitFor({ timeout: 20_000 });
  for (let i = 0; i < 200 && pins !== 'pins 0 0'; i++) {
    pins = await ctl.cmd('get');
    await page.waitForTimeout(50);
  }
  assert.equal(pins, 'pins 0 0', 'the detached board\'s outputs are off');
  assert.equal(await ctl.cmd('set D2 1'), 'ok');
  await tid('tab-program-main.lad').click();
  await page.waitForTimeout(500);
  await el(start, false).waitFor();
  await tid('status-state').filter({ hasText: 'running' }).waitFor();
  assert.deepEqual(b.errors, []);
});

test('Undo puts alba.toml\'s [board] back as it was before the save', async () => {
  const { page, tid } = b;
  const original = readFileSync(join(repo, 'examples/start-stop/alba.toml'), 'utf8');
  await page.reload();
  await tid('tab-hardware').click();
  await tid('hw-undo').and(page.locator(':enabled')).waitFor();
  await tid('hw-undo').click();
  await tid('hw-undo').and(page.locator(':disabled')).waitFor();
  assert.equal(readFileSync(join(alba.dir, 'alba.toml'), 'utf8'), original, 'the example\'s alba.toml, without [board]');
  assert.deepEqual(b.errors, []);
});
