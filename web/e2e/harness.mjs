// Shared by the end-to-end tests: `alba run` on a scratch copy of an example,
// and Debian's Chromium driven by playwright-core.
//   ALBA_BIN  the alba binary (default ../target/debug/alba)
//   CHROMIUM  the browser (default /usr/bin/chromium)
//   E2E_OUT   where screenshots, downloads and measurements go (default e2e/out)
import { spawn } from 'node:child_process';
import { cpSync, mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createInterface } from 'node:readline';
import { after, before } from 'node:test';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
export const repo = resolve(here, '../..');
export const out = resolve(process.env.E2E_OUT ?? join(here, 'out'));
mkdirSync(out, { recursive: true });

const albaBin = () => process.env.ALBA_BIN ?? join(repo, 'target/debug/alba');

/** `alba user add <dir> <name> --role <role>`, the password on standard input. */
export async function addUser(dir, { name, role, password }) {
  const proc = spawn(albaBin(), ['user', 'add', dir, name, '--role', role], { stdio: ['pipe', 'ignore', 'pipe'] });
  let err = '';
  proc.stderr.on('data', (d) => (err += d));
  proc.stdin.end(`${password}\n`);
  const code = await new Promise((ok) => proc.on('exit', ok));
  if (code !== 0) throw new Error(`alba user add ${name} exited with ${code}: ${err}`);
}

/**
 * Starts `alba run` on a copy of examples/<name>; resolves once it serves.
 * `users` ({name, role, password}) are added to the copy first.
 */
export async function startAlba(example, { users = [], prepare = null, args = [], env = {} } = {}) {
  const dir = mkdtempSync(join(tmpdir(), `alba-e2e-${example}-`));
  cpSync(join(repo, 'examples', example), dir, { recursive: true });
  for (const u of users) await addUser(dir, u);
  await prepare?.(dir);
  let { proc, url } = await spawnAlba(dir, '127.0.0.1:0', args, env);
  // With users, `login()` gives the helpers a bearer token.
  let token = null;
  const api = async (path, init = {}) => {
    const headers = { ...(init.headers ?? {}) };
    if (token && !Object.keys(headers).some((k) => k.toLowerCase() === 'authorization')) headers.authorization = `Bearer ${token}`;
    const res = await fetch(new URL(path, url), { ...init, headers });
    const text = await res.text();
    let body = null;
    try {
      body = text ? JSON.parse(text) : null;
    } catch {
      body = text;
    }
    return { status: res.status, body };
  };
  return {
    url,
    dir,
    api,
    /** The process id of `alba run` (for CPU measurements). */
    get pid() {
      return proc.pid;
    },
    json: async (path) => (await api(path)).body,
    /** Logs the helpers in (POST /api/login; the bearer token of the reply). */
    async login(user, password) {
      const r = await api('/api/login', { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ user, password }) });
      if (r.status !== 200 || !r.body?.token) throw new Error(`login ${user}: ${r.status} ${JSON.stringify(r.body)}`);
      token = r.body.token;
    },
    /** Kills `alba run` as a crash would (SIGKILL); the project stays. */
    async kill() {
      proc.kill('SIGKILL');
      await new Promise((ok) => (proc.exitCode !== null || proc.signalCode !== null ? ok() : proc.on('exit', ok)));
    },
    /** Starts `alba run` again on the same project and address. */
    async restart() {
      ({ proc } = await spawnAlba(dir, new URL(url).host, args, env));
    },
    async stop() {
      proc.kill('SIGTERM');
      await new Promise((ok) => (proc.exitCode !== null || proc.signalCode !== null ? ok() : proc.on('exit', ok)));
      rmSync(dir, { recursive: true, force: true });
    },
  };
}

/** `alba run <dir> --http <addr> [args]` (`env` over this process's); resolves once it serves, with its URL. */
async function spawnAlba(dir, addr, args = [], env = {}) {
  const proc = spawn(albaBin(), ['run', dir, '--http', addr, ...args], { stdio: ['ignore', 'pipe', 'inherit'], env: { ...process.env, ...env } });
  const url = await new Promise((ok, fail) => {
    const timer = setTimeout(() => fail(new Error('alba run did not start in 30 s')), 30_000);
    proc.on('exit', (code) => fail(new Error(`alba run exited with ${code}`)));
    createInterface({ input: proc.stdout }).on('line', (line) => {
      const m = line.match(/http:\/\/[^/\s]+\//);
      if (m) {
        clearTimeout(timer);
        ok(m[0]);
      }
    });
  });
  return { proc, url };
}

/**
 * For a test file: `alba run` on examples/<example> and a browser, started
 * before its tests (`set` receives `{ alba, b }`) and stopped after them.
 */
export function useStudio(example, set, opts) {
  let ctx = {};
  before(async () => {
    ctx = { alba: await startAlba(example, opts), b: await openBrowser() };
    set(ctx);
  });
  after(async () => {
    await ctx.b?.close();
    await ctx.alba?.stop();
  });
}

/**
 * A headless Chromium with a fresh profile, and one page; `viewport` and
 * `hasTouch` (a phone) as Playwright takes them, `args` more switches.
 */
export async function openBrowser({ viewport = { width: 1400, height: 900 }, hasTouch = false, args = [] } = {}) {
  const profile = mkdtempSync(join(tmpdir(), 'alba-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    headless: true,
    acceptDownloads: true,
    args: [
      '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      ...args,
    ],
    viewport,
    hasTouch,
  });
  const page = context.pages()[0] ?? (await context.newPage());
  const errors = [];
  page.on('pageerror', (e) => errors.push(`pageerror: ${e.message}`));
  page.on('dialog', (d) => d.accept());
  return {
    page,
    errors,
    tid: (id) => page.getByTestId(id),
    shot: (name) => page.screenshot({ path: join(out, `${name}.png`) }),
    async close() {
      await context.close();
      rmSync(profile, { recursive: true, force: true });
    },
  };
}

/** The id of the first element of `program` with this mnemonic and operands. */
export function elementId(program, mnemonic, operands) {
  const walk = (els) => {
    for (const e of els) {
      if (e.kind === 'instr' && e.mnemonic === mnemonic && JSON.stringify(e.operands) === JSON.stringify(operands)) return e.id;
      for (const leg of e.legs ?? []) {
        const id = walk(leg);
        if (id !== undefined) return id;
      }
    }
    return undefined;
  };
  for (const r of program.rungs) {
    const id = walk(r.elements);
    if (id !== undefined) return id;
  }
  throw new Error(`no ${mnemonic}(${operands.join(',')}) in ${program.name}`);
}
