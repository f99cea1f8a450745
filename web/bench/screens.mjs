// Benchmark of the SCADA runtime view (issue 17, "Performance"; a measurement,
// not a test: it asserts nothing about time). A generated project of N DINT
// tags that all change every 100 ms scan (10 Hz), and a screen of N animated
// elements, one per tag (tank fill, LED colour, circular meter needle,
// output text, rotating pump in turn). For each N it opens the screen in
// headless Chromium and connects 19 more viewers (WebSocket clients
// subscribed to the screen's tags, as the view is), then measures for
// BENCH_SECS (default 10 s):
//   - frame times: requestAnimationFrame deltas in the page (p50/p95/p99/max);
//   - long tasks (PerformanceObserver `longtask`, over 50 ms): count and max;
//   - tag change → DOM: from the engine's publication time (`t_ms` of each
//     WebSocket message) to the DOM mutation it causes (p50/p99);
//   - the server: CPU of the `alba` process (% of one core, from /proc) and
//     the messages each extra viewer received per second.
// Prints a table and writes target/bench/screens.json.
//
//   cargo build --release -p alba-cli
//   cd web && ALBA_BIN=../target/release/alba node --experimental-websocket bench/screens.mjs
//   (BENCH_ELEMENTS=500,1000,2000 BENCH_SECS=10 are the defaults)
import { mkdirSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { openBrowser, repo, startAlba } from '../e2e/harness.mjs';

const SECS = Number(process.env.BENCH_SECS ?? 10);
const COUNTS = (process.env.BENCH_ELEMENTS ?? '500,1000,2000').split(',').map(Number);
const VIEWERS = 20;
const KINDS = ['tank', 'led', 'meter', 'output', 'pump'];

function project(dir, n) {
  for (const f of readdirSync(dir)) rmSync(join(dir, f), { recursive: true, force: true });
  let tags = 'name,type,address,initial,retain,description\nC,DINT,,,,scan counter\n';
  let lad = 'ADD(C,1,C);\n';
  const cols = Math.ceil(Math.sqrt(n * 1.25));
  const elements = [];
  for (let k = 0; k < n; k++) {
    tags += `T${k},DINT,,,,\n`;
    lad += `CPT(T${k},(C+${(k * 7) % 100}) MOD 100);\n`;
    const type = KINDS[k % KINDS.length];
    const [x, y] = [(k % cols) * 48 + 4, Math.floor(k / cols) * 48 + 4];
    const e = { id: `e${k}`, type, x, y, w: 40, h: 40, props: {}, animations: [] };
    const tag = `T${k}`;
    if (type === 'tank') e.animations.push({ kind: 'fill', tag, min: 0, max: 99, direction: 'up' });
    if (type === 'led') e.animations.push({ kind: 'color', tag, intervals: [{ from: 0, color: '#9ea3a8' }, { from: 50, color: '#2e7d32' }, { from: 80, color: '#c62828' }] });
    if (type === 'meter') Object.assign(e, { props: { style: 'circular' }, animations: [{ kind: 'rotate', tag, min: 0, max: 99 }] });
    if (type === 'output') e.props.tag = tag;
    if (type === 'pump') e.animations.push({ kind: 'rotate', tag, min: 0, max: 99, degrees: 360 });
    elements.push(e);
  }
  const screen = { schema: 1, title: `bench ${n}`, width: cols * 48 + 8, height: Math.ceil(n / cols) * 48 + 8, elements };
  writeFileSync(join(dir, 'alba.toml'), 'name = "screens-bench"\nscan_ms = 100\nprograms = ["main.lad"]\n[history]\nenabled = false\n');
  writeFileSync(join(dir, 'tags.csv'), tags);
  writeFileSync(join(dir, 'main.lad'), lad);
  mkdirSync(join(dir, 'hmi'));
  writeFileSync(join(dir, 'hmi', 'bench.json'), JSON.stringify(screen));
}

const cpuSeconds = (pid) => {
  const f = readFileSync(`/proc/${pid}/stat`, 'utf8').split(')').pop().trim().split(/\s+/);
  return (Number(f[11]) + Number(f[12])) / 100;
};
const pct = (xs, p) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? s[Math.min(s.length - 1, Math.round((s.length - 1) * p))] : NaN;
};

async function run(n) {
  const alba = await startAlba('start-stop', { prepare: (dir) => project(dir, n) });
  const b = await openBrowser();
  try {
    const { page } = b;
    await page.addInitScript(() => {
      const m = { t: 0, lat: [], frames: [], long: [] };
      window.__m = m;
      const Native = window.WebSocket;
      window.WebSocket = class extends Native {
        constructor(...a) {
          super(...a);
          this.addEventListener('message', (ev) => {
            const t = typeof ev.data === 'string' && /"t_ms":(\d+)/.exec(ev.data);
            if (t && ev.data.includes('"T')) m.t = Number(t[1]);
          });
        }
      };
      new PerformanceObserver((l) => l.getEntries().forEach((e) => m.long.push(e.duration))).observe({ type: 'longtask', buffered: true });
    });
    await page.goto(`${alba.url}#/screens`);
    await page.getByTestId('tab-screens').click();
    await page.getByTestId('hmi-screen-bench').waitFor({ timeout: 60_000 });
    const tags = Array.from({ length: n }, (_, k) => `T${k}`);
    // 19 more viewers, subscribed to the same tags.
    const viewers = Array.from({ length: VIEWERS - 1 }, () => {
      // (the server wants the studio's own Origin on a WebSocket handshake; undici's extension sets it)
      const ws = new WebSocket(`${alba.url.replace('http', 'ws')}api/ws`, { headers: { origin: alba.url.replace(/\/$/, '') } });
      const v = { ws, messages: 0 };
      ws.onopen = () => ws.send(JSON.stringify({ subscribe: tags }));
      ws.onmessage = (e) => String(e.data).startsWith('{"type":"values"') && v.messages++;
      return v;
    });
    await page.waitForTimeout(2000); // warm up
    viewers.forEach((v) => (v.messages = 0));
    await page.evaluate(() => {
      const m = window.__m;
      Object.assign(m, { lat: [], frames: [], long: [] });
      new MutationObserver(() => m.t && m.lat.push(Date.now() - m.t)).observe(document.querySelector('[data-testid="hmi-screen-bench"]'), {
        subtree: true, attributes: true, childList: true, characterData: true,
      });
      let last = performance.now();
      const frame = (t) => {
        m.frames.push(t - last);
        last = t;
        if (!m.stop) requestAnimationFrame(frame);
      };
      requestAnimationFrame(frame);
    });
    const cpu0 = cpuSeconds(alba.pid);
    const t0 = Date.now();
    await page.waitForTimeout(SECS * 1000);
    const wall = (Date.now() - t0) / 1000;
    const cpu = ((cpuSeconds(alba.pid) - cpu0) / wall) * 100;
    const m = await page.evaluate(() => ((window.__m.stop = true), window.__m));
    viewers.forEach((v) => v.ws.close());
    const status = await alba.json('/api/status');
    return {
      elements: n,
      frames: m.frames.length,
      frame_ms: { p50: pct(m.frames, 0.5), p95: pct(m.frames, 0.95), p99: pct(m.frames, 0.99), max: Math.max(...m.frames) },
      long_tasks: { count: m.long.length, max_ms: m.long.length ? Math.max(...m.long) : 0 },
      latency_ms: { samples: m.lat.length, p50: pct(m.lat, 0.5), p99: pct(m.lat, 0.99) },
      server_cpu_pct: Number(cpu.toFixed(1)),
      viewer_msgs_per_s: Number((viewers.reduce((a, v) => a + v.messages, 0) / viewers.length / wall).toFixed(1)),
      scan: status?.stats,
      errors: b.errors,
    };
  } finally {
    await b.close();
    await alba.stop();
  }
}

const results = [];
for (const n of COUNTS) {
  const r = await run(n);
  results.push(r);
  const f = (x) => (Number.isFinite(x) ? x.toFixed(1) : '—');
  console.log(
    `${n} elements: frame p50/p95/p99/max ${f(r.frame_ms.p50)}/${f(r.frame_ms.p95)}/${f(r.frame_ms.p99)}/${f(r.frame_ms.max)} ms (${r.frames} frames), ` +
      `long tasks ${r.long_tasks.count} (max ${f(r.long_tasks.max_ms)} ms), change→DOM p50/p99 ${r.latency_ms.p50}/${r.latency_ms.p99} ms, ` +
      `server CPU ${r.server_cpu_pct} % with ${VIEWERS} viewers (${r.viewer_msgs_per_s} msg/s each)${r.errors.length ? `, page errors: ${r.errors}` : ''}`,
  );
}
const outDir = join(repo, 'target', 'bench');
mkdirSync(outDir, { recursive: true });
writeFileSync(join(outDir, 'screens.json'), JSON.stringify(results, null, 2) + '\n');
