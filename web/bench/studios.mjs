// Benchmark: engine → browser DOM latency with 1, 10 and 50 open studios
// (issue 18, item 4; a measurement, not a test). `alba run` on
// examples/tank-plant (Vol_L changes every 10 ms scan); K pages of one
// headless Chromium show the studio, half on the tag table and half on the
// plant.lad ladder (live values in boxes); on the first page of each kind,
// brought to front in turn, a MutationObserver records, for BENCH_SECS
// (default 10 s), the time from the
// engine's publication (`t_ms` of the WebSocket message) to the change of
// Vol_L's cell or box value. Prints p50/p99/max per view and the server's CPU;
// writes target/bench/studios.json.
//
//   cargo build --release -p alba-cli
//   cd web && ALBA_BIN=../target/release/alba node bench/studios.mjs   (BENCH_STUDIOS=1,10,50)
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { openBrowser, repo, startAlba } from '../e2e/harness.mjs';

const SECS = Number(process.env.BENCH_SECS ?? 10);
const COUNTS = (process.env.BENCH_STUDIOS ?? '1,10,50').split(',').map(Number);

const cpuSeconds = (pid) => {
  const f = readFileSync(`/proc/${pid}/stat`, 'utf8').split(')').pop().trim().split(/\s+/);
  return (Number(f[11]) + Number(f[12])) / 100;
};
const pct = (xs, p) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? s[Math.min(s.length - 1, Math.round((s.length - 1) * p))] : NaN;
};

/** Records Date.now() − t_ms of the last message carrying Vol_L at every change of `selector`. */
const instrument = () => {
  const lat = { t: 0, samples: [] };
  window.__lat = lat;
  const Native = window.WebSocket;
  window.WebSocket = class extends Native {
    constructor(...a) {
      super(...a);
      this.addEventListener('message', (ev) => {
        const m = typeof ev.data === 'string' && ev.data.includes('"Vol_L"') && /"t_ms":(\d+)/.exec(ev.data);
        if (m) lat.t = Number(m[1]);
      });
    }
  };
};

async function run(k) {
  const alba = await startAlba('tank-plant');
  const b = await openBrowser();
  try {
    const ctx = b.page.context();
    const pages = [b.page];
    for (let n = 1; n < k; n++) pages.push(await ctx.newPage());
    const views = pages.map((_, n) => (n % 2 === 0 ? 'tags' : 'program/plant.lad'));
    // one after the other: 50 studios loading at once on 2 cores time out
    for (const [n, p] of pages.entries()) {
      if (n < 2) await p.addInitScript(instrument);
      await p.goto(`${alba.url}#/${views[n]}`, { timeout: 120_000 });
    }
    const watched = [[pages[0], '[data-testid="tag-value-Vol_L"]', 'tag table']];
    if (pages[1]) watched.push([pages[1], '[data-tag="Vol_L"]', 'ladder']);
    for (const [p, sel] of watched) {
      await p.locator(sel).first().waitFor({ timeout: 60_000 });
      await p.evaluate((s) => {
        const lat = window.__lat;
        new MutationObserver(() => lat.t && lat.samples.push(Date.now() - lat.t)).observe(document.querySelector(s), { subtree: true, childList: true, characterData: true });
      }, sel);
    }
    // Each measured page in front in turn (Chromium throttles the frames of background tabs;
    // the other studios keep their subscriptions and their own updates either way).
    const out = { studios: k };
    let cpu = 0;
    for (const [p, , name] of watched) {
      await p.bringToFront();
      await p.waitForTimeout(2000);
      await p.evaluate(() => (window.__lat.samples = []));
      const cpu0 = cpuSeconds(alba.pid);
      const t0 = Date.now();
      await p.waitForTimeout(SECS * 1000);
      cpu = Math.max(cpu, ((cpuSeconds(alba.pid) - cpu0) / ((Date.now() - t0) / 1000)) * 100);
      const s = await p.evaluate(() => window.__lat.samples);
      out[name] = { samples: s.length, p50_ms: pct(s, 0.5), p99_ms: pct(s, 0.99), max_ms: s.length ? Math.max(...s) : NaN };
    }
    out.server_cpu_pct = Number(cpu.toFixed(1));
    out.status = (await alba.json('/api/status'))?.stats;
    return out;
  } finally {
    await b.close();
    await alba.stop();
  }
}

const results = [];
for (const k of COUNTS) {
  const r = await run(k);
  results.push(r);
  const v = (x) => (x ? `${x.p50_ms}/${x.p99_ms}/${x.max_ms} ms (${x.samples})` : '—');
  console.log(`${k} studios: tag table p50/p99/max ${v(r['tag table'])}, ladder ${v(r.ladder)}, server CPU ${r.server_cpu_pct} %, scan max ${r.status?.max_us} µs, overruns ${r.status?.overruns}`);
}
const outDir = join(repo, 'target', 'bench');
mkdirSync(outDir, { recursive: true });
writeFileSync(join(outDir, 'studios.json'), JSON.stringify(results, null, 2) + '\n');
