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
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
export const repo = resolve(here, '../..');
export const out = resolve(process.env.E2E_OUT ?? join(here, 'out'));
mkdirSync(out, { recursive: true });

/** Starts `alba run` on a copy of examples/<name>; resolves once it serves. */
export async function startAlba(example) {
  const dir = mkdtempSync(join(tmpdir(), `alba-e2e-${example}-`));
  cpSync(join(repo, 'examples', example), dir, { recursive: true });
  const bin = process.env.ALBA_BIN ?? join(repo, 'target/debug/alba');
  const proc = spawn(bin, ['run', dir, '--http', '127.0.0.1:0'], { stdio: ['ignore', 'pipe', 'inherit'] });
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
  const api = async (path, init) => {
    const res = await fetch(new URL(path, url), init);
    const text = await res.text();
    return { status: res.status, body: text ? JSON.parse(text) : null };
  };
  return {
    url,
    dir,
    api,
    json: async (path) => (await api(path)).body,
    async stop() {
      proc.kill('SIGTERM');
      await new Promise((ok) => (proc.exitCode !== null ? ok() : proc.on('exit', ok)));
      rmSync(dir, { recursive: true, force: true });
    },
  };
}

/** A headless Chromium with a fresh profile, and one page. */
export async function openBrowser() {
  const profile = mkdtempSync(join(tmpdir(), 'alba-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    headless: true,
    acceptDownloads: true,
    args: [
      '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
    ],
    viewport: { width: 1400, height: 900 },
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
