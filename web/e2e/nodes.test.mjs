// Trends from another node (issue 22): two `alba run` record into one real
// PostgreSQL (Debian's postgresql, which test.sh installs; a cluster of its own
// in a temporary directory on a free loopback port, as crates/testkit/src/pg.rs
// starts it), each under its own node id; the studio of `line-1` picks the node
// `line-2` beside the pen input and plots its level from the shared history.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { appendFileSync, existsSync, mkdtempSync, readdirSync, rmSync, writeFileSync, chmodSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { openBrowser, repo, startAlba } from './harness.mjs';

const albaBin = process.env.ALBA_BIN ?? join(repo, 'target/debug/alba');

function pgBin() {
  const base = '/usr/lib/postgresql';
  if (!existsSync(base)) return null;
  const v = readdirSync(base)
    .filter((d) => existsSync(join(base, d, 'bin/pg_ctl')))
    .sort((a, b) => Number(a) - Number(b));
  return v.length ? join(base, v.at(-1), 'bin') : null;
}

const freePort = () =>
  new Promise((ok) => {
    const s = createServer().listen(0, '127.0.0.1', () => {
      const { port } = s.address();
      s.close(() => ok(port));
    });
  });

/** A PostgreSQL server of its own; `null` (skipped) when none is installed outside CI. */
async function startPostgres() {
  const bin = pgBin();
  if (!bin) {
    if (process.env.CI === 'true') throw new Error('PostgreSQL is not installed: apt-get install -y postgresql (test.sh does)');
    return null;
  }
  const dir = mkdtempSync(join(tmpdir(), 'alba-e2e-pg-'));
  chmodSync(dir, 0o755);
  const pw = join(dir, 'pw');
  writeFileSync(pw, 'e2e-historian-pw\n');
  const root = process.getuid?.() === 0;
  if (root) spawnSync('chown', ['-R', 'postgres:', dir]);
  const run = (tool, args) => {
    const exe = join(bin, tool);
    const r = root ? spawnSync('runuser', ['-u', 'postgres', '--', exe, ...args]) : spawnSync(exe, args);
    if (r.status !== 0) throw new Error(`${tool} failed: ${r.stdout}${r.stderr}`);
  };
  const data = join(dir, 'data');
  const port = await freePort();
  run('initdb', ['-D', data, '-U', 'alba', '--auth=scram-sha-256', '--pwfile', pw, '-E', 'UTF8', '--locale=C']);
  run('pg_ctl', ['-D', data, '-l', join(dir, 'log'), '-w', '-t', '120', '-o', `-p ${port} -k ${dir} -c listen_addresses=127.0.0.1`, 'start']);
  return {
    pw,
    url: `host=127.0.0.1 port=${port} user=alba dbname=postgres`,
    stop() {
      try {
        run('pg_ctl', ['-D', data, '-m', 'immediate', 'stop']);
      } finally {
        rmSync(dir, { recursive: true, force: true });
      }
    },
  };
}

let pg = null;
let line1 = null;
let line2 = null;
let b = null;

before(async () => {
  pg = await startPostgres();
  if (!pg) return;
  const history = (node) => (dir) => {
    appendFileSync(join(dir, 'alba.toml'), `\n[history]\nbackend = "postgres"\nurl = "${pg.url}"\npassword_file = "${pg.pw}"\nnode = "${node}"\n`);
    const r = spawnSync(albaBin, ['historian', 'migrate', dir]);
    if (r.status !== 0) throw new Error(`alba historian migrate: ${r.stderr}`);
  };
  line2 = await startAlba('tank-plant', { prepare: history('line-2') });
  line1 = await startAlba('tank', { prepare: history('line-1') });
  b = await openBrowser();
});

after(async () => {
  await b?.close();
  await line1?.stop();
  await line2?.stop();
  pg?.stop();
});

test("the trends plot another node's tag from the shared historian", async (t) => {
  if (!pg) return t.skip('PostgreSQL is not installed');
  // line-2 has recorded its level.
  for (let i = 0; ; i++) {
    const n = await line1.json('/api/history/nodes');
    const tags = await line1.json('/api/history/tags?node=line-2');
    if (n?.nodes?.includes('line-2') && Array.isArray(tags) && tags.some((x) => x.name === 'Nivel_L')) break;
    if (i > 300) throw new Error(`line-2 never recorded: ${JSON.stringify(n)}`);
    await new Promise((ok) => setTimeout(ok, 200));
  }
  assert.deepEqual(await line1.json('/api/history/nodes'), { node: 'line-1', shared: true, nodes: ['line-1', 'line-2'] });
  const { page, tid } = b;
  await page.goto(line1.url);
  await tid('tab-trends').click();
  const picker = tid('trend-node');
  await picker.waitFor({ state: 'visible' });
  await picker.selectOption('line-2');
  // The input offers what line-2 recorded (tank has no Nivel_L of its own).
  await page.waitForFunction(() => [...document.querySelectorAll('#trend-tags option')].some((o) => o.value === 'Nivel_L'));
  await tid('trend-pen-input').fill('Nivel_L');
  await tid('trend-pen-add').click();
  await tid('trend-pen-Nivel_L@line-2').waitFor();
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="trend-plot"]')?.getAttribute('data-points')) > 1);
  // Typed as Tag@node too; a tag line-2 did not record is refused with a notice.
  await picker.selectOption('');
  await tid('trend-pen-input').fill('Nope@line-2');
  await tid('trend-pen-add').click();
  await page.getByText('node line-2 recorded no such tag').waitFor();
  // The set is the project's, with the node.
  for (let i = 0; ; i++) {
    const set = await line1.json('/api/trends');
    if (set.pens.some((p) => p.tag === 'Nivel_L' && p.node === 'line-2')) break;
    if (i > 100) throw new Error(`not saved: ${JSON.stringify(set)}`);
    await new Promise((ok) => setTimeout(ok, 100));
  }
  await b.shot('trend-other-node');
  assert.deepEqual(b.errors, []);
});
