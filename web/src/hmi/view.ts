// The Screens tab (issue 17): the project's SCADA screens at run time. One
// WebSocket subscription to the tags the shown screen uses (not all tags);
// animations follow the values; widgets write through the tag API (their
// role checked like everywhere); full screen for an operator's shift. A
// stale link greys the screen like every view (live/freshness.ts).
import { ApiError, api } from '../api';
import { can, gate, why } from '../auth';
import type { Ctx } from '../ctx';
import { clear, h, s } from '../dom';
import { tr } from '../i18n';
import type { Json } from '../types';
import { openFaceplate } from '../ui/faceplate';
import { Designer } from './designer';
import { ScreenTrend, trendPens } from './trend';
import { historySamples, plotValue } from '../trends/history';
import { type Element, PROP_TAGS, type Screen, animate, drawElement, showAlarm, showLoop, showPropTag, showValue, tagsOf, tick } from './render';

export class ScreensView {
  readonly el: HTMLElement;
  private readonly picker = h('select', { 'data-testid': 'hmi-screen' });
  private readonly stage = h('div', { class: 'hmi-stage', 'data-testid': 'hmi-stage' });
  private unwatch: (() => void)[] = [];
  private name = '';

  constructor(private readonly ctx: Ctx) {
    this.picker.onchange = () => void this.open(this.picker.value);
    const full = h('button', { 'data-testid': 'hmi-fullscreen', title: tr('Show the screen on the whole display') }, tr('Full screen'));
    full.onclick = () => this.fullScreen(true);
    const edit = h('button', { 'data-testid': 'hmi-edit' }, tr('Edit'));
    edit.onclick = () => void this.design(this.name);
    const create = h('button', { 'data-testid': 'hmi-new' }, `+ ${tr('New screen')}`);
    create.onclick = () => {
      const name = prompt(tr('Name of the new screen (letters, digits, _ and -):'))?.trim();
      if (name) void this.design(name, { schema: 1, width: 1000, height: 600, elements: [] });
    };
    gate(edit, 'edit');
    gate(create, 'edit');
    this.el = h('section', { class: 'hmi-view', 'data-testid': 'hmi-view' }, h('div', { class: 'toolbar' }, this.picker, full, edit, create), this.stage);
  }

  show(): void {
    void this.load();
  }

  hide(): void {
    this.fullScreen(false);
    this.stop();
  }

  /** Leaves full screen: its own button, Escape, or the browser's way out. */
  private readonly exitButton = h('button', { class: 'hmi-exit', 'data-testid': 'hmi-exit-fullscreen', title: tr('Leave full screen (Escape)') }, `✕ ${tr('Exit full screen')}`);
  private readonly onFullscreenChange = () => {
    if (!document.fullscreenElement) this.fullScreen(false);
  };
  private readonly onEscape = (e: KeyboardEvent) => {
    if (e.key === 'Escape') this.fullScreen(false);
  };

  /**
   * Full screen for an operator's shift: the whole page goes full screen
   * (where the browser allows it; a phone without the Fullscreen API still gets
   * the layout) and shows the screen under the banners — alarms, with Mute,
   * forces, "Not live" — with a button to leave. The top bar, the tabs, this
   * toolbar and the status bar step aside (body.kiosk in the style sheet).
   */
  private fullScreen(on: boolean): void {
    if (on === document.body.classList.contains('kiosk')) return;
    document.body.classList.toggle('kiosk', on);
    if (on) {
      this.exitButton.onclick = () => this.fullScreen(false);
      this.el.append(this.exitButton);
      document.addEventListener('fullscreenchange', this.onFullscreenChange);
      document.addEventListener('keydown', this.onEscape);
      void document.documentElement.requestFullscreen?.().catch(() => undefined);
      this.exitButton.focus();
    } else {
      this.exitButton.remove();
      document.removeEventListener('fullscreenchange', this.onFullscreenChange);
      document.removeEventListener('keydown', this.onEscape);
      if (document.fullscreenElement) void document.exitFullscreen?.().catch(() => undefined);
    }
  }

  private stop(): void {
    this.unwatch.forEach((f) => f());
    this.unwatch = [];
    this.ctx.live.subscribe('hmi', null);
  }

  private async load(): Promise<void> {
    let names: string[];
    try {
      names = (await api.screens()) as string[];
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
      return;
    }
    clear(this.picker);
    names.forEach((n) => this.picker.append(h('option', { value: n, selected: n === this.name }, n)));
    if (names.length === 0) {
      clear(this.stage);
      this.stage.append(h('p', { class: 'hint' }, tr('No screens in this project (hmi/*.json).')));
      return;
    }
    await this.open(names.includes(this.name) ? this.name : names[0]);
  }

  private async open(name: string): Promise<void> {
    this.stop();
    this.name = name;
    let screen: Screen;
    try {
      screen = (await api.screen(name)) as Screen;
    } catch (e) {
      clear(this.stage);
      const msg = e instanceof ApiError ? [e.message, ...e.diagnostics.map((d) => `${d.line}:${d.col} ${d.message}`)].join('\n') : String(e);
      this.stage.append(h('pre', { class: 'inline-error', 'data-testid': 'hmi-error' }, msg));
      return;
    }
    const svg = s('svg', {
      class: 'hmi-screen',
      viewBox: `0 0 ${screen.width} ${screen.height}`,
      preserveAspectRatio: 'xMidYMid meet',
      'data-testid': `hmi-screen-${name}`,
    });
    // no background of its own: the theme's ISA-101 grey (--hmi-screen, dimmer in the dark theme)
    svg.append(s('rect', { class: 'hmi-bg', width: screen.width, height: screen.height, style: `fill: ${screen.background ?? 'var(--hmi-screen, #f4f5f6)'}` }));
    const clocks: SVGGElement[] = [];
    const trends: [ScreenTrend, string[]][] = [];
    const indicators: [SVGGElement, string][] = [];
    for (const e of screen.elements) {
      const g = drawElement(e);
      svg.append(g);
      for (const a of e.animations ?? []) this.unwatch.push(this.ctx.live.store.watch(a.tag, (v) => animate(g, e, a, v)));
      for (const prop of Object.keys(PROP_TAGS)) {
        const tag = e.props?.[prop];
        if (typeof tag === 'string') this.unwatch.push(this.ctx.live.store.watch(tag, (v) => showPropTag(g, prop, v)));
      }
      const shown = e.props?.tag;
      if (e.type === 'faceplate' && typeof shown === 'string') {
        // the loop's members; a click opens the full faceplate
        const update = () => showLoop(g, (m) => this.ctx.live.store.get(`${shown}.${m}`));
        for (const m of ['SP', 'PV', 'CV', 'MAN']) this.unwatch.push(this.ctx.live.store.watch(`${shown}.${m}`, update));
        g.classList.add('hmi-widget');
        g.addEventListener('click', () => openFaceplate(this.ctx, shown));
      } else if (e.type === 'trend') {
        // its pens (props.pens, up to three), else its tag
        const pens = trendPens(e.props).map((p) => p.tag);
        if (pens.length) trends.push([new ScreenTrend(g, e.props, pens.length), pens]);
      }
      else if (typeof shown === 'string') this.unwatch.push(this.ctx.live.store.watch(shown, (v) => showValue(g, v, e.props)));
      if (e.type === 'clock') clocks.push(g);
      if (e.type === 'alarm' && typeof e.props?.alarm === 'string') indicators.push([g, e.props.alarm]);
      if (e.action) this.wire(g, e);
    }
    if (indicators.length) {
      // alarm indicators follow their alarms' states; a click goes to the alarm summary
      const refresh = async () => {
        const states = new Map((await api.alarms().catch(() => [])).map((a) => [a.id, a.state]));
        for (const [g, id] of indicators) showAlarm(g, states.get(id) ?? 'normal');
      };
      void refresh();
      this.unwatch.push(this.ctx.live.onBatch((b) => b.alarms && void refresh()));
      for (const [g] of indicators) {
        g.classList.add('hmi-widget');
        g.addEventListener('click', () => (location.hash = '#/alarms'));
      }
    }
    if (trends.length) this.startTrends(trends);
    if (clocks.length) {
      const timer = setInterval(() => clocks.forEach((g) => tick(g, new Date())), 1000);
      this.unwatch.push(() => clearInterval(timer));
    }
    // the I/O link: when S:IOOK drops the inputs hold their last values, and the screen says so
    const ioBanner = h('div', { class: 'hmi-io-down', 'data-testid': 'hmi-io-down', hidden: true }, tr('I/O link down (S:IOOK off): inputs hold their last values'));
    this.unwatch.push(this.ctx.live.store.watch('S:IOOK', (v) => {
      ioBanner.hidden = v !== false;
      svg.classList.toggle('io-down', v === false);
    }));
    clear(this.stage);
    this.stage.append(ioBanner, svg);
    this.ctx.live.subscribe('hmi', [...tagsOf(screen), 'S:IOOK']);
  }

  /**
   * Trend elements: filled with their window from the historian (when it has
   * the tag), then live values; redrawn every half second, so that the line
   * moves on while a value holds.
   */
  private startTrends(trends: [ScreenTrend, string[]][]): void {
    const now = Date.now();
    for (const [trend, tag, k] of trends.flatMap(([t, tags]) => tags.map((tag, k) => [t, tag, k] as const))) {
      this.unwatch.push(this.ctx.live.store.watch(tag, (v) => trend.push(Date.now(), plotValue(v), k)));
      const from = now - trend.windowMs;
      const points = 600;
      // the value held at the window's start: the last one recorded in the hour before it
      const before = api.history(tag, from - 3600e3, from - 1, 1).catch(() => null);
      Promise.all([api.history(tag, from, now, points), before]).then(
        ([hist, prior]) => {
          const held = prior?.buckets[prior.buckets.length - 1]?.[4];
          trend.seed(historySamples(hist.buckets, hist.from, hist.to, points, held), k);
          trend.draw(Date.now());
        },
        () => undefined, // no history (off, or nothing recorded): live values only
      );
      trend.draw(now);
    }
    const timer = setInterval(() => trends.forEach(([t]) => t.draw(Date.now())), 500);
    this.unwatch.push(() => clearInterval(timer));
  }

  /** Opens the designer on `name` (its saved version, or `fresh`); back to the run view when closed. */
  private async design(name: string, fresh?: Screen): Promise<void> {
    let screen = fresh;
    if (!screen) {
      try {
        screen = (await api.screen(name)) as Screen;
      } catch (e) {
        this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
        return;
      }
    }
    this.stop();
    const d = new Designer(this.ctx, name, screen, () => {
      this.name = name;
      void this.load();
    });
    clear(this.stage);
    this.stage.append(d.el);
  }

  /** A widget: writes its tag through the API (operators and up), or goes to another screen. */
  private wire(g: SVGGElement, e: Element): void {
    const a = e.action!;
    g.classList.add('hmi-widget');
    if (a.kind === 'navigate') {
      g.addEventListener('click', () => a.screen && void this.open(a.screen).then(() => (this.picker.value = a.screen!)));
      return;
    }
    const tag = a.tag;
    if (!tag) return;
    if (!can('write')) {
      g.classList.add('disabled');
      g.append(s('title', null, why('write') ?? ''));
      return;
    }
    // pending while the write is on its way; confirmed or refused when the answer comes
    const write = async (v: Json) => {
      g.classList.remove('confirmed', 'refused');
      g.classList.add('pending');
      let outcome = 'confirmed';
      try {
        await api.writeTag(tag, v);
      } catch (err) {
        outcome = 'refused';
        this.ctx.notify(err instanceof Error ? err.message : String(err), 'error');
      } finally {
        g.classList.remove('pending');
        g.classList.add(outcome);
        setTimeout(() => g.classList.remove(outcome), 800);
      }
    };
    const [lo, hi] = [a.min ?? 0, a.max ?? 100];
    if (a.kind === 'slider') {
      // the knob follows the tag; dragging moves it, and the value is written on release
      const knob = g.querySelector('[data-part="knob"]');
      const at = (v: number) => knob?.setAttribute('cx', String(Math.max(0, Math.min(1, (v - lo) / (hi - lo || 1))) * e.w));
      this.unwatch.push(this.ctx.live.store.watch(tag, (v) => typeof v === 'number' && !g.classList.contains('dragging') && at(v)));
      const valueAt = (ev: PointerEvent) => {
        const box = g.getBoundingClientRect();
        const f = Math.max(0, Math.min(1, (ev.clientX - box.left) / (box.width || 1)));
        return Number((lo + f * (hi - lo)).toPrecision(6));
      };
      g.addEventListener('pointerdown', (ev) => {
        g.classList.add('dragging');
        g.setPointerCapture?.(ev.pointerId);
        at(valueAt(ev));
      });
      g.addEventListener('pointermove', (ev) => g.classList.contains('dragging') && at(valueAt(ev)));
      g.addEventListener('pointerup', (ev) => {
        if (!g.classList.contains('dragging')) return;
        g.classList.remove('dragging');
        void write(valueAt(ev));
      });
      return;
    }
    if (a.kind === 'momentary') {
      g.addEventListener('pointerdown', () => void write(true));
      g.addEventListener('pointerup', () => void write(false));
      g.addEventListener('pointerleave', (ev) => ev.buttons && void write(false));
    } else if (a.kind === 'toggle') {
      g.addEventListener('click', () => void write(!(this.ctx.live.store.get(tag) === true)));
    } else if (a.kind === 'set') {
      g.addEventListener('click', () => void write(a.value ?? true));
    } else {
      g.addEventListener('click', () => {
        const v = prompt(tr('New value of {name}:', { name: tag }), String(this.ctx.live.store.get(tag) ?? ''));
        const n = v === null ? NaN : Number(v);
        if (Number.isFinite(n) && (a.min == null || n >= a.min) && (a.max == null || n <= a.max)) void write(n);
        else if (v !== null && Number.isFinite(n)) this.ctx.notify(tr('{value} is outside {min} to {max}', { value: v, min: a.min ?? '−∞', max: a.max ?? '∞' }), 'error');
        else if (v !== null) this.ctx.notify(tr('{value} is not a number', { value: v }), 'error');
      });
    }
  }
}
