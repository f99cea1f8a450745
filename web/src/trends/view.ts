// Trends: pens on up to four y axes (automatic or fixed scales), BOOL pens
// as steps on lanes of their own (axes.ts), a legend that always shows the
// latest values (the cursor's while it is over the plot), the set saved in
// the project (GET|PUT /api/trends); a live scrolling window from WebSocket values (backfilled
// from /api/history when a pen is added, the view opens or the WebSocket
// reconnects), history (zoom by dragging, wheel, pan and zoom-out buttons)
// from /api/history with a min/max band per pen, CSV export from
// /api/history.csv. The plot element carries data-points (points plotted)
// and data-last-t (time of the last live sample), data-axes (the pens of each
// y axis) and data-lanes (the on/off pens) for end-to-end tests. With a
// shared historian, pens may plot tags other nodes recorded (pens.ts): from
// their history, read again every 2 s while live. Ctrl+F6/F7/F8 set the Y
// maximum, the Y minimum and the time shown, as the 004 PID monitor's keys (ui/fkeys.ts).
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import { ApiError, api } from '../api';
import type { Ctx } from '../ctx';
import { clear, download, h } from '../dom';
import { isStructure } from '../domain';
import { can } from '../auth';
import type { History, TrendPen } from '../types';
import { type PenSpec, aboveLanes, axesInUse, clampToNow, fixedRange, fromLane, laneRange, lanesOf, lanesTop, scaleOf, timeLabels, timeSpace, toLane } from './axes';
import { PenLog, alignLogs, exportStep, historyFailure, historySamples, joinHistories, mergeBackfill, plotValue } from './history';
import { trendCsv } from './csv';
import { trendKey, windowMs, withYLimit } from '../ui/fkeys';
import { type PenRef, REMOTE_REFRESH_MS, liveTags, newPen, parsePen, penId, penKey, remotePens } from './pens';
import { dateTime, tr, when } from '../i18n';

const COLORS = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2', '#17becf', '#7f7f7f', '#bcbd22'];
const WINDOWS: [string, number][] = [
  ['30 s', 30e3],
  ['1 min', 60e3],
  ['5 min', 300e3],
  ['15 min', 900e3],
  ['1 h', 3600e3],
];
const RANGES: [string, number][] = [
  [tr('last 15 min'), 900e3],
  [tr('last 1 h'), 3600e3],
  [tr('last 8 h'), 8 * 3600e3],
  [tr('last 24 h'), 24 * 3600e3],
  [tr('last 7 days'), 7 * 24 * 3600e3],
];
const STORE_KEY = 'alba.trends.pens';
/** How far before a backfilled window to look for the value held at its start. */
const HELD_LOOKBACK_MS = 3600e3;

type Mode = { kind: 'live' } | { kind: 'range'; from: number; to: number };

export class TrendsView {
  readonly el: HTMLElement;
  private pens: TrendPen[] = [];
  /** The set was loaded from the project (then changes are saved there). */
  private loadedFromProject = false;
  private saveTimer: ReturnType<typeof setTimeout> | null = null;
  private readonly logs = new Map<string, PenLog>();
  /** Per pen (upper case): the time of the first live sample since the pen was added or the WebSocket (re)connected. */
  private readonly liveSince = new Map<string, number>();
  /** Counts WebSocket reconnections: a backfill started before one is dropped. */
  private epoch = 0;
  /** Time of the latest live sample of any pen (ms), 0 before the first. */
  private lastLiveT = 0;
  private attrs: { points: number; lastT: number; to: number } | null = null;
  private attrsFrame = 0;
  private mode: Mode = { kind: 'live' };
  private windowMs = 60e3;
  private plot: uPlot | null = null;
  private plotKey = '';
  /** The plot has the history layout (line, max, min per pen). */
  private plotHistory = false;
  /** Server clock minus local clock (ms), from the latest values message. */
  private offset = 0;
  private historyAvailable: boolean | null = null;
  private timer: ReturnType<typeof setInterval> | null = null;
  private fetchSeq = 0;
  private wheelTimer: ReturnType<typeof setTimeout> | null = null;
  private readonly plotEl = h('div', { class: 'trend-plot', 'data-testid': 'trend-plot' });
  /** Over the plot when no pen has a value in the range shown. */
  private readonly noData = h('div', { class: 'trend-nodata', 'data-testid': 'trend-nodata', hidden: true }, tr('No data in this range'));
  private readonly pensEl = h('div', { class: 'pens', 'data-testid': 'trend-pens' });
  private readonly statusEl = h('span', { class: 'trend-status', 'data-testid': 'trend-status' });
  private readonly penInput = h('input', { list: 'trend-tags', placeholder: tr('Tag to plot'), 'data-testid': 'trend-pen-input', autocomplete: 'off' });
  private readonly datalist = h('datalist', { id: 'trend-tags' });
  /** The node whose tags the pen input offers (shown with a shared historian of several nodes). */
  private readonly nodeSel = h('select', {
    'data-testid': 'trend-node',
    title: tr('The node whose recorded tags to plot (a shared historian)'),
    hidden: true,
    onchange: () => this.renderDatalist(),
  });
  /** This runtime's node id in the historian. */
  private ownNode = '';
  /** When pens of other nodes were last read. */
  private remoteAt = 0;
  private readonly resize = new ResizeObserver(() => this.fit());

  constructor(private readonly ctx: Ctx) {
    try {
      const saved = JSON.parse(localStorage.getItem(STORE_KEY) ?? '[]');
      // Older studios kept bare names.
      if (Array.isArray(saved)) this.pens = saved.map((p) => (typeof p === 'string' ? newPen({ tag: p }) : p)).filter((p) => typeof p?.tag === 'string');
    } catch {
      /* ignore */
    }
    this.penInput.addEventListener('keydown', (e) => e.key === 'Enter' && this.addPen(this.penInput.value));
    // the 004 monitor's keys while the trends are shown: Ctrl+F6 Y max, Ctrl+F7 Y min, Ctrl+F8 the time shown
    document.addEventListener('keydown', (e) => {
      const a = trendKey(e);
      if (!a || !this.el.isConnected || this.el.offsetParent === null) return;
      e.preventDefault();
      this.onFunctionKey(a);
    });
    const windowSel = h(
      'select',
      { 'data-testid': 'trend-window', onchange: (e: Event) => this.setWindow(Number((e.target as HTMLSelectElement).value)) },
      WINDOWS.map(([l, ms]) => h('option', { value: ms, selected: ms === this.windowMs }, l)),
    );
    const rangeSel = h(
      'select',
      {
        'data-testid': 'trend-range',
        onchange: (e: Event) => {
          const sel = e.target as HTMLSelectElement;
          const ms = Number(sel.value);
          sel.value = '';
          if (ms) {
            const now = this.now();
            this.setRange(now - ms, now);
          }
        },
      },
      h('option', { value: '' }, tr('History…')),
      RANGES.map(([l, ms]) => h('option', { value: ms }, l)),
    );
    this.el = h(
      'section',
      { class: 'trends-view', 'data-testid': 'trends-view' },
      h(
        'div',
        { class: 'toolbar' },
        this.nodeSel,
        this.penInput,
        this.datalist,
        h('button', { 'data-testid': 'trend-pen-add', onclick: () => this.addPen(this.penInput.value) }, `+ ${tr('Pen')}`),
        h('span', { class: 'seg' },
          h('button', { 'data-testid': 'trend-live', onclick: () => this.setLive() }, `● ${tr('Live')}`),
          ` ${tr('window')} `, windowSel),
        h('span', { class: 'seg' },
          rangeSel,
          h('button', { 'data-testid': 'trend-pan-left', title: tr('Earlier'), onclick: () => this.pan(-0.5) }, '◀'),
          h('button', { 'data-testid': 'trend-pan-right', title: tr('Later'), onclick: () => this.pan(0.5) }, '▶'),
          h('button', { 'data-testid': 'trend-zoom-out', title: tr('Zoom out'), onclick: () => this.zoom(2) }, '−'),
          h('button', { 'data-testid': 'trend-zoom-in', title: tr('Zoom in'), onclick: () => this.zoom(0.5) }, '+')),
        h('button', { 'data-testid': 'trend-export-csv', onclick: () => void this.exportCsv() }, tr('Export CSV')),
        this.statusEl,
      ),
      this.pensEl,
      h('div', { class: 'trend-plot-wrap' }, this.plotEl, this.noData),
      h('p', { class: 'hint' }, tr('Drag across the plot to zoom into the history; the wheel zooms, ◀ ▶ pan, Live returns to the scrolling view.')),
    );
    ctx.live.onRaw((m) => {
      if (m.type !== 'values') return;
      this.offset = m.t_ms - Date.now();
      for (const [name, v] of Object.entries(m.values)) {
        const k = name.toUpperCase();
        const log = this.logs.get(k);
        if (!log) continue;
        log.push(m.t_ms, plotValue(v));
        if (!this.liveSince.has(k)) this.liveSince.set(k, m.t_ms);
        if (m.t_ms > this.lastLiveT) this.lastLiveT = m.t_ms;
      }
    });
    let prev = ctx.live.state;
    ctx.live.onState((st) => {
      if (st === 'connected' && prev === 'reconnecting') {
        // the gap while disconnected: live data starts again with the next message
        this.epoch++;
        this.liveSince.clear();
        this.backfill(this.pens);
      }
      prev = st;
    });
    this.syncSubscription();
  }

  show(): void {
    if (!this.loadedFromProject) void this.loadSet();
    this.renderPens();
    this.renderDatalist();
    this.resize.observe(this.plotEl);
    this.timer = setInterval(() => this.tick(), 250);
    this.rebuild();
    this.backfill(this.pens);
    this.loadNodes();
    if (this.historyAvailable === null) {
      api.historyTags().then(
        () => (this.historyAvailable = true),
        (e) => {
          if (e instanceof ApiError && historyFailure(e.status, e.message) === 'off') this.historyAvailable = false;
          this.renderStatus();
        },
      );
    }
  }

  hide(): void {
    if (this.timer) clearInterval(this.timer);
    this.timer = null;
    this.resize.disconnect();
  }

  /** Live: redraws, and reads the pens of other nodes again every REMOTE_REFRESH_MS. */
  private tick(): void {
    if (this.mode.kind !== 'live') return;
    const remote = remotePens(this.pens);
    if (remote.length && Date.now() - this.remoteAt >= REMOTE_REFRESH_MS) {
      this.remoteAt = Date.now();
      this.backfill(remote);
    }
    this.redraw();
  }

  /** The historian's nodes: the node picker is shown when other nodes share it. */
  private loadNodes(): void {
    api.historyNodes().then(
      (n) => {
        this.ownNode = n.node;
        const others = n.nodes.filter((x) => x !== n.node);
        const current = this.nodeSel.value;
        clear(this.nodeSel);
        this.nodeSel.append(h('option', { value: '' }, tr('this node ({node})', { node: n.node })));
        others.forEach((x) => this.nodeSel.append(h('option', { value: x, selected: x === current }, x)));
        this.nodeSel.hidden = !(n.shared && others.length > 0);
      },
      () => {
        /* no history: the picker stays hidden */
      },
    );
  }

  private now(): number {
    return Date.now() + this.offset;
  }

  /** The pens as the plot sees them (a BOOL of this runtime is a lane; another node's types are not known here). */
  private specs(): PenSpec[] {
    return this.pens.map((p) => ({ tag: penId(p), axis: p.axis, min: p.min, max: p.max, digital: !p.node && this.ctx.tags.resolve(p.tag)?.type === 'BOOL' }));
  }

  /** The project's trend set (GET /api/trends), when it has pens: every studio opens the same trend. */
  private async loadSet(): Promise<void> {
    this.loadedFromProject = true;
    try {
      const set = await api.trends();
      if (set.pens.length) {
        this.pens = set.pens;
        this.windowMs = set.window_ms;
        this.syncSubscription(false);
        this.renderPens();
        this.rebuild();
        this.backfill(this.pens);
      }
    } catch (e) {
      this.ctx.notify(tr('Trends: {m}', { m: e instanceof Error ? e.message : String(e) }), 'error');
    }
  }

  /** Saves the set in the project (PUT /api/trends) a moment after the last change; operators and up. */
  private scheduleSave(): void {
    if (!can('write')) return;
    if (this.saveTimer) clearTimeout(this.saveTimer);
    this.saveTimer = setTimeout(() => {
      api.saveTrends({ version: 1, window_ms: this.windowMs, pens: this.pens }).catch((e) =>
        this.ctx.notify(tr('Trends not saved: {m}', { m: e instanceof Error ? e.message : String(e) }), 'error'),
      );
    }, 500);
  }

  private syncSubscription(save = true): void {
    const keys = this.pens.map(penKey);
    for (const k of keys) if (!this.logs.has(k)) this.logs.set(k, new PenLog());
    for (const k of [...this.logs.keys()]) {
      if (!keys.includes(k)) {
        this.logs.delete(k);
        this.liveSince.delete(k);
      }
    }
    const live = liveTags(this.pens);
    this.ctx.live.subscribe('trends', live.length ? live : null);
    localStorage.setItem(STORE_KEY, JSON.stringify(this.pens));
    if (save) this.scheduleSave();
  }

  private addPen(name: string): void {
    const want = parsePen(name, this.nodeSel.value, this.ownNode);
    if (!want.tag) return;
    if (want.node) {
      // Another node's tag: one it recorded (its program is not this one).
      const node = want.node;
      api.historyTags(node).then(
        (tags) => {
          const t = tags.find((x) => x.name.toUpperCase() === want.tag.toUpperCase());
          if (t) this.insertPen({ tag: t.name, node });
          else this.ctx.notify(tr('{name}: node {node} recorded no such tag', { name: want.tag, node }), 'error');
        },
        (e) => this.ctx.notify(tr('history: {m}', { m: e instanceof Error ? e.message : String(e) }), 'error'),
      );
      return;
    }
    const ref = this.ctx.tags.resolve(want.tag);
    if (!ref || isStructure(ref.type)) {
      this.ctx.notify(tr('{name}: not a tag or member that can be plotted (pick a BOOL or a number)', { name: want.tag }), 'error');
      return;
    }
    this.insertPen({ tag: ref.name });
  }

  private insertPen(ref: PenRef): void {
    const added = !this.pens.some((p) => penKey(p) === penKey(ref));
    if (added) this.pens.push(newPen(ref));
    this.penInput.value = '';
    this.syncSubscription();
    this.renderPens();
    this.rebuild();
    if (added) this.backfill([ref]);
  }

  private removePen(id: string): void {
    this.pens = this.pens.filter((p) => penId(p) !== id);
    this.syncSubscription();
    this.renderPens();
    this.rebuild();
  }

  /** Changes a pen's axis or scale, and redraws. */
  private setPen(id: string, change: Partial<TrendPen>): void {
    this.pens = this.pens.map((p) => (penId(p) === id ? { ...p, ...change } : p));
    this.syncSubscription();
    this.rebuild();
  }

  private renderPens(): void {
    clear(this.pensEl);
    const specs = this.specs();
    this.pens.forEach((pen, k) => {
      const p = penId(pen);
      const num = (which: 'min' | 'max') =>
        h('input', {
          type: 'number',
          class: 'scale',
          step: 'any',
          placeholder: which === 'min' ? tr('min') : tr('max'),
          title: tr('A fixed scale for this axis (both min and max); empty: automatic'),
          value: pen[which] ?? '',
          'data-testid': `trend-${which}-${p}`,
          onchange: () => {
            const [lo, hi] = [readNum(this.pensEl, `trend-min-${p}`), readNum(this.pensEl, `trend-max-${p}`)];
            this.setPen(p, lo !== null && hi !== null && lo < hi ? { min: lo, max: hi } : { min: null, max: null });
          },
        });
      const controls = specs[k].digital
        ? h('span', { class: 'hint' }, tr('on/off lane'))
        : h('span', null,
            h('select', { 'data-testid': `trend-axis-${p}`, title: tr('The y axis this pen shares (1, 3 left; 2, 4 right)'), onchange: (e: Event) => this.setPen(p, { axis: Number((e.target as HTMLSelectElement).value) }) },
              [1, 2, 3, 4].map((a) => h('option', { value: a, selected: a === pen.axis }, tr('axis {n}', { n: a })))),
            num('min'), num('max'));
      this.pensEl.append(
        h('span', { class: 'pen', 'data-testid': `trend-pen-${p}`, style: { borderColor: COLORS[k % COLORS.length] } },
          h('span', { class: 'swatch', style: { background: COLORS[k % COLORS.length] } }),
          p,
          controls,
          h('button', { class: 'small', title: tr('Remove {name}', { name: p }), 'data-testid': `trend-pen-remove-${p}`, onclick: () => this.removePen(p) }, '×')),
      );
    });
    if (this.pens.length === 0) this.pensEl.append(h('span', { class: 'hint' }, tr('No pens: add a tag to plot.')));
  }

  /** The tags the pen input offers: this runtime's, or those the picked node recorded. */
  private renderDatalist(): void {
    const node = this.nodeSel.value;
    const fill = (names: string[]) => {
      if (this.nodeSel.value !== node) return; // picked another meanwhile
      clear(this.datalist);
      [...new Set(names)].forEach((n) => this.datalist.append(h('option', { value: n })));
    };
    if (!node) fill([...this.ctx.tags.choices('num_in'), ...this.ctx.tags.choices('bit_in')]);
    else api.historyTags(node).then((tags) => fill(tags.map((t) => t.name)), () => fill([]));
  }

  private renderStatus(text?: string): void {
    let s: string;
    if (text) s = text;
    else if (this.mode.kind === 'live') s = tr('live, last {window}', { window: WINDOWS.find(([, ms]) => ms === this.windowMs)?.[0] ?? '' });
    else s = `${dateTime(this.mode.from)} – ${when(this.mode.to, this.mode.from)}`;
    if (this.historyAvailable === false) s += ` · ${tr('history not available on this server (live buffer only)')}`;
    this.statusEl.textContent = s;
  }

  /** Ctrl+F6/F7: one bound of the first axis's scale (its other bound kept); Ctrl+F8: the live window. */
  private onFunctionKey(a: 'y-max' | 'y-min' | 'window'): void {
    if (a === 'window') {
      const ms = windowMs(window.prompt(tr('Time shown, in seconds (Ctrl+F8)'), String(this.windowMs / 1000)) ?? '');
      if (ms !== null) this.setWindow(ms);
      return;
    }
    const specs = this.specs();
    const mine = this.pens.filter((_, k) => scaleOf(specs[k]) === 'y1');
    if (!mine.length) return;
    const sc = this.plot?.scales.y1;
    const shown: [number, number] = [sc?.min ?? 0, sc?.max ?? 100];
    const which = a === 'y-max' ? 'max' : 'min';
    const text = window.prompt(a === 'y-max' ? tr('Y maximum (Ctrl+F6)') : tr('Y minimum (Ctrl+F7)'), String(which === 'max' ? shown[1] : shown[0]));
    if (text === null) return;
    const changed = withYLimit(mine, which, Number(text.trim().replace(',', '.')), shown);
    if (!changed) return this.ctx.notify(tr('Not a scale: the minimum must be below the maximum'), 'error');
    this.pens = this.pens.map((p) => changed.find((c) => penId(c) === penId(p)) ?? p);
    this.renderPens();
    this.rebuild();
    this.scheduleSave();
  }

  private setWindow(ms: number): void {
    const longer = ms > this.windowMs;
    this.windowMs = ms;
    this.setLive();
    this.scheduleSave();
    if (longer) this.backfill(this.pens);
  }

  private setLive(): void {
    this.mode = { kind: 'live' };
    this.rebuild();
  }

  private range(): [number, number] {
    if (this.mode.kind === 'range') return [this.mode.from, this.mode.to];
    const now = this.now();
    return [now - this.windowMs, now];
  }

  private setRange(from: number, to: number): void {
    if (!(to > from)) return;
    this.mode = { kind: 'range', from, to };
    this.rebuild();
  }

  private pan(f: number): void {
    const [a, b] = this.range();
    const d = (b - a) * f;
    this.setRange(...clampToNow(a + d, b + d, this.now()));
  }

  private zoom(f: number, center?: number): void {
    const [a, b] = this.range();
    const c = center ?? (a + b) / 2;
    // Zooming out of the live window shows more of the past, never empty future.
    this.setRange(...clampToNow(c - (c - a) * f, c + (b - c) * f, this.now()));
  }

  // ---- plotting ---------------------------------------------------------------

  private fit(): void {
    if (!this.plot) return;
    const w = Math.max(300, this.plotEl.clientWidth);
    this.plot.setSize({ width: w, height: this.height() });
  }

  private height(): number {
    return Math.max(260, Math.min(520, window.innerHeight - 260));
  }

  /** (Re)creates the plot for the current pens and mode, and fills it. */
  private rebuild(): void {
    this.renderStatus();
    const history = this.mode.kind === 'range' && this.historyAvailable !== false;
    const key = `${history}:${JSON.stringify(this.specs())}`;
    if (key !== this.plotKey || !this.plot) {
      this.plot?.destroy();
      this.plot = null;
      clear(this.plotEl);
      this.plotKey = key;
      this.plotHistory = history;
      if (this.pens.length) this.plot = this.makePlot(history);
      else this.markPlot(0, 0);
      this.noData.hidden = true;
    }
    if (history) void this.fetchHistory();
    else this.redraw();
  }

  private makePlot(history: boolean): uPlot {
    const specs = this.specs();
    const lanes = lanesOf(specs);
    const nLanes = lanes.filter((l) => l >= 0).length;
    const analog = axesInUse(specs);
    const series: uPlot.Series[] = [{ label: tr('Time'), value: (_u, v) => (v === null ? '--' : dateTime(v)) }];
    const bands: uPlot.Band[] = [];
    specs.forEach((p, k) => {
      const color = COLORS[k % COLORS.length];
      const scale = scaleOf(p);
      // BOOLs are steps in history too; the legend shows 0/1, not the lane's coordinate.
      const value = p.digital ? (_u: uPlot, v: number | null) => (v === null ? '--' : String(fromLane(v))) : undefined;
      const stepped = p.digital || !history;
      series.push({ label: p.tag, scale, stroke: color, width: 1.5, spanGaps: history, paths: stepped ? uPlot.paths.stepped!({ align: 1 }) : undefined, points: { show: false }, value });
      if (history && !p.digital) {
        const i = series.length;
        series.push({ label: `${p.tag} max`, scale, stroke: 'transparent', width: 0, points: { show: false }, spanGaps: true });
        series.push({ label: `${p.tag} min`, scale, stroke: 'transparent', width: 0, points: { show: false }, spanGaps: true });
        bands.push({ series: [i, i + 1], fill: `${color}33` });
      }
    });
    const scales: uPlot.Scales = { x: { time: true } };
    // times in the language's format, ticks far enough apart for their labels
    const axes: uPlot.Axis[] = [{
      space: timeSpace(),
      values: (u, splits, _a, _s, incr) => {
        const labels = timeLabels(splits, incr);
        // the ticks as drawn (CSS px from the canvas' left, label), for tests
        const left = u.bbox.left / (window.devicePixelRatio || 1);
        this.plotEl.dataset.xTicks = JSON.stringify(splits.map((t, k) => [Math.round(left + u.valToPos(t, 'x')), labels[k]]));
        return labels;
      },
      size: 48,
    }];
    const withLanes = nLanes > 0;
    // an analog axis labels only its part of the plot, above the lanes
    const aboveTheLanes = (u: uPlot, splits: number[], axisIdx: number) => {
      const sc = u.scales[u.axes[axisIdx].scale ?? ''];
      const top = sc?.min !== undefined && sc.max !== undefined ? lanesTop(sc.min, sc.max) : -Infinity;
      return splits.map((v) => (v >= top - 1e-9 * Math.abs(top) ? v : null));
    };
    analog.forEach((key, n) => {
      const fixed = fixedRange(specs, key);
      scales[key] = fixed
        ? { auto: false, range: aboveLanes(fixed[0], fixed[1], withLanes) }
        : {
            auto: true,
            range: (_u, lo, hi) => {
              const [a, b] = lo === null || hi === null ? [0, 1] : uPlot.rangeNum(lo, hi, 0.1, true);
              return aboveLanes(a ?? 0, b ?? 1, withLanes);
            },
          };
      const pensHere = specs.filter((p) => scaleOf(p) === key).map((p) => p.tag).join(', ');
      const axis: uPlot.Axis = { scale: key, side: n % 2 === 0 ? 3 : 1, grid: { show: n === 0 }, label: pensHere, labelSize: 18, size: 64 };
      if (withLanes) Object.assign(axis, { filter: aboveTheLanes, grid: { show: n === 0, filter: aboveTheLanes }, ticks: { filter: aboveTheLanes } });
      axes.push(axis);
    });
    if (withLanes) {
      // the on/off pens' own axis: their names beside their lanes
      const names = specs.filter((p) => p.digital).map((p) => p.tag);
      scales.lanes = { auto: false, range: laneRange(nLanes, analog.length > 0) };
      axes.push({
        scale: 'lanes',
        side: 3,
        grid: { show: false },
        ticks: { show: false },
        splits: () => names.map((_, k) => k + 0.5),
        values: () => names,
        size: Math.min(140, 16 + 7 * Math.max(...names.map((x) => x.length))),
      });
    }
    // What the canvas shows, for tests and screen readers: the y axes with their pens, and the lanes.
    this.plotEl.dataset.axes = analog.map((key) => specs.filter((p) => scaleOf(p) === key).map((p) => p.tag).join(',')).join('|');
    this.plotEl.dataset.lanes = specs.filter((p) => p.digital).map((p) => p.tag).join(',');
    const opts: uPlot.Options = {
      width: Math.max(300, this.plotEl.clientWidth),
      height: this.height(),
      ms: 1,
      series,
      bands,
      scales,
      axes,
      legend: { live: true },
      // room for the last time label at the right edge, unless an axis is there
      padding: [null, analog.length >= 2 ? null : timeSpace() / 2, null, null],
      cursor: { drag: { x: true, y: false, setScale: false } },
      hooks: {
        draw: [
          // the scales as drawn ({key: [min, max]}), for tests
          (u) => {
            const scales = Object.fromEntries([...analog, ...(withLanes ? ['lanes'] : [])].map((k) => [k, [u.scales[k].min, u.scales[k].max]]));
            const text = JSON.stringify(scales);
            if (this.plotEl.dataset.scales !== text) this.plotEl.dataset.scales = text;
          },
          // the line between the analog pens and the lanes
          ...(withLanes && analog.length ? [(u: uPlot) => lanesLine(u, nLanes)] : []),
        ],
        setSelect: [
          (u) => {
            if (u.select.width < 5) return;
            const from = u.posToVal(u.select.left, 'x');
            const to = u.posToVal(u.select.left + u.select.width, 'x');
            u.setSelect({ left: 0, top: 0, width: 0, height: 0 }, false);
            this.setRange(from, to);
          },
        ],
      },
    };
    const u = new uPlot(opts, [[]], this.plotEl);
    u.over.addEventListener('wheel', (e) => {
      e.preventDefault();
      const [a, b] = this.range();
      const center = u.posToVal(e.offsetX, 'x');
      const f = e.deltaY > 0 ? 1.25 : 0.8;
      const na = center - (center - a) * f;
      const nb = center + (b - center) * f;
      this.mode = { kind: 'range', from: na, to: nb };
      this.renderStatus();
      // show the buffer at once, fetch the history when the wheel rests
      this.drawBuffer(na, nb);
      if (this.wheelTimer) clearTimeout(this.wheelTimer);
      this.wheelTimer = setTimeout(() => this.rebuild(), 250);
    }, { passive: false });
    return u;
  }

  private drawBuffer(from: number, to: number): void {
    if (!this.plot || this.plotHistory) return;
    const logs = this.pens.map((p) => this.logs.get(penKey(p))!);
    const lanes = lanesOf(this.specs());
    const raw = alignLogs(logs, from, to);
    const data = raw.map((col, c) => (c === 0 || lanes[c - 1] < 0 ? col : col.map((v) => toLane(lanes[c - 1], v)))) as uPlot.AlignedData;
    this.plot.setData(data, false);
    this.plot.setScale('x', { min: from, max: to });
    this.showLatest(data[0].length);
    this.markPlot(data[0].length, to);
    this.showNoData(data);
  }

  /** "No data in this range" while no pen has a value in the columns `data` (time first). */
  private showNoData(data: ArrayLike<unknown>[]): void {
    const empty = !Array.from(data).slice(1).some((col) => Array.from(col).some((v) => v !== null && v !== undefined));
    if (this.noData.hidden !== !empty) this.noData.hidden = !empty;
  }

  /** The legend shows the latest values while the cursor is away from the plot (never `--`). */
  private showLatest(points: number): void {
    const u = this.plot;
    if (!u || points === 0) return;
    const hovering = u.cursor.left !== undefined && u.cursor.left >= 0;
    if (!hovering) u.setLegend({ idx: points - 1 }, false);
  }

  /** data-points / data-last-t / data-to on the plot element, written at most once per animation frame. */
  private markPlot(points: number, to: number): void {
    this.attrs = { points, lastT: this.lastLiveT, to };
    if (this.attrsFrame) return;
    this.attrsFrame = requestAnimationFrame(() => {
      this.attrsFrame = 0;
      const a = this.attrs;
      if (!a) return;
      this.plotEl.dataset.points = String(a.points);
      this.plotEl.dataset.lastT = String(a.lastT);
      this.plotEl.dataset.to = String(Math.round(a.to));
    });
  }

  /** The plot area's width in CSS pixels: one history bucket each. */
  private plotWidth(): number {
    const w = this.plot ? Math.round(this.plot.bbox.width / (window.devicePixelRatio || 1)) : 0;
    return Math.max(50, w || this.plotEl.clientWidth || 800);
  }

  /**
   * Seeds the live buffers of `pens` with the last window of history, so that
   * the live view is full at once; the buffer keeps what arrived live (see
   * mergeBackfill). Without history (off, unknown tag, an error) the buffer
   * stays as it is.
   */
  private backfill(pens: PenRef[]): void {
    if (this.historyAvailable === false || pens.length === 0) return;
    const to = this.now();
    const from = to - this.windowMs;
    const points = this.plotWidth();
    const epoch = this.epoch;
    for (const pen of pens) {
      const k = penKey(pen);
      const log = this.logs.get(k);
      if (!log) continue;
      // the value held at the window's start: the last one recorded in the hour before it
      const before = api.history(pen.tag, from - HELD_LOOKBACK_MS, from - 1, 1, pen.node).catch(() => null);
      Promise.all([api.history(pen.tag, from, to, points, pen.node), before]).then(
        ([hist, prior]) => {
          if (epoch !== this.epoch || this.logs.get(k) !== log) return; // removed, re-added or reconnected since
          const held = prior?.buckets[prior.buckets.length - 1]?.[4];
          const samples = historySamples(hist.buckets, hist.from, hist.to, points, held);
          log.replace(mergeBackfill(samples, log.samples(), this.liveSince.get(k) ?? Infinity));
          if (this.mode.kind === 'live') this.redraw();
        },
        (e) => {
          const kind = e instanceof ApiError ? historyFailure(e.status, e.message) : 'error';
          if (kind === 'off' && this.historyAvailable !== false) {
            this.historyAvailable = false;
            this.renderStatus();
          }
          // 'no-data': nothing recorded for this tag yet; 'error': keep the live buffer only
        },
      );
    }
  }

  /** Live (or range without history): the ring buffers. */
  private redraw(): void {
    if (!this.plot) return;
    const [from, to] = this.range();
    this.drawBuffer(from, to);
  }

  private async fetchHistory(): Promise<void> {
    if (this.mode.kind !== 'range' || !this.plot) return;
    const { from, to } = this.mode;
    const seq = ++this.fetchSeq;
    const points = this.plotWidth();
    this.renderStatus(tr('loading history…'));
    let hs: History[];
    try {
      hs = await Promise.all(
        this.pens.map((p) =>
          api.history(p.tag, from, to, points, p.node).catch((e) => {
            // a tag with nothing recorded is an empty pen, not a failure
            if (e instanceof ApiError && historyFailure(e.status, e.message) === 'no-data') return { node: p.node ?? this.ownNode, tag: p.tag, from, to, buckets: [] };
            throw e;
          }),
        ),
      );
    } catch (e) {
      if (seq !== this.fetchSeq) return;
      if (e instanceof ApiError && historyFailure(e.status, e.message) === 'off') {
        this.historyAvailable = false;
        this.rebuild(); // falls back to the live buffer
        return;
      }
      this.renderStatus(tr('history: {m}', { m: e instanceof Error ? e.message : String(e) }));
      return;
    }
    if (seq !== this.fetchSeq || !this.plot) return;
    const j = joinHistories(hs);
    const data: (number | null)[][] = [j.xs];
    const lanes = lanesOf(this.specs());
    // A BOOL's line on its lane (its band is not drawn: a step says it all).
    j.pens.forEach((p, k) => (lanes[k] >= 0 ? data.push(p.line.map((v) => toLane(lanes[k], v))) : data.push(p.line, p.max, p.min)));
    this.plot.setData(data as uPlot.AlignedData, false);
    this.plot.setScale('x', { min: from, max: to });
    this.showLatest(j.xs.length);
    this.markPlot(j.xs.length, to);
    this.showNoData(data);
    this.renderStatus();
  }

  private async exportCsv(): Promise<void> {
    if (this.pens.length === 0) {
      this.ctx.notify(tr('Add a pen first'), 'error');
      return;
    }
    const [from, to] = this.range();
    const url = api.historyCsvUrl(this.pens.map(penId), from, to, exportStep(from, to));
    const real = this.pens.map((p) => !p.node && this.ctx.tags.resolve(p.tag)?.type === 'REAL');
    try {
      const text = await api.text(url);
      download('trend.csv', trendCsv(text, Math.floor(from), real), true);
    } catch (e) {
      this.ctx.notify(tr('CSV export failed: {m}', { m: (e as Error).message }), 'error');
    }
  }
}

/** The number in the input `testid` under `root`, or null. */
function readNum(root: HTMLElement, testid: string): number | null {
  const el = root.querySelector(`[data-testid="${testid}"]`) as HTMLInputElement | null;
  const v = el?.value.trim() ?? '';
  return v === '' || !Number.isFinite(Number(v)) ? null : Number(v);
}

/** The line between the analog pens and the `lanes` lanes below them. */
function lanesLine(u: uPlot, lanes: number): void {
  const y = Math.round(u.valToPos(lanes, 'lanes', true)) + 0.5;
  u.ctx.save();
  u.ctx.strokeStyle = '#9aa3ae';
  u.ctx.lineWidth = 1;
  u.ctx.beginPath();
  u.ctx.moveTo(u.bbox.left, y);
  u.ctx.lineTo(u.bbox.left + u.bbox.width, y);
  u.ctx.stroke();
  u.ctx.restore();
}
