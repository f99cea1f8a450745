// The tab of a net program (.pnml, issue 20): an SVG editor of states,
// transitions and arcs, the live view of the running net (tokens on places,
// enabled transitions and firings from the monitored power flow of each
// transition's "enabled" and "fired" elements, timers, counters, operator
// widgets, a history of firings and marking changes; single step with F6),
// and the analysis of GET /api/nets/{name}/analysis
// (boundedness, deadlocks with their firing sequence replayed on the canvas,
// dead transitions, invariants).
//
// The PNML text is the model, as the ladder's text is: the canvas is drawn
// from its parse (pnml.ts), an edit (edit.ts) changes a copy of the net and
// writes it back as PNML, so undo/redo, the server's check (POST /api/check,
// debounced), Save (PUT /api/programs online, between scans) and the
// problems list are the shared ProgramEditor's; a problem's line:column is
// put on the element whose text holds it.
import { type AnalysisProgress, api } from '../api';
import { can, gate, why } from '../auth';
import type { Ctx } from '../ctx';
import { ZoomPan, grid } from '../canvas';
import { add, clear, fmt, h, rubberBand, s } from '../dom';
import { membersOf } from '../domain';
import { type Problem, ProgramEditor, problemTip } from '../editor/program';
import { clockTime, tr } from '../i18n';
import { openOpcuaBrowser } from '../ui/opcuaBrowse';
import type { Json, ServerMsg } from '../types';
import { highlight } from './code';
import {
  type Clip, GRID, addPlace, addTransition, arcProblem, connect, copy, findNode, freshId, moveNodes, paste, remove, rename, snap,
} from './edit';
import { PLACE_R, type Pt, TEXT, TRANS_H, TRANS_W, type Box, fitGuard, overlaps, placeBox, positions, routes, textBox, transitionBox } from './geom';
import { ARC_KINDS, type Arc, type Net, PLACE_KINDS, type Place, type Transition, type Widget, type Span, TRANSITION_KINDS, WIDGET_KINDS, loadPnml, savePnml } from './pnml';
import { ButtonLatch, DISPLAY_FORMATS, DISPLAY_MODES, LABEL_ALIGNS, STYLE_KEYS, displayText, labelLook, plotRange } from './widgets';
import { type Analysis, type Marking, enabled, initialMarking, markingTag, netName, replay } from './sim';
import { lineCol, offsetOf } from './xml';

/** A glyph inside a place or beside a transition, per kind. */
const GLYPH: Record<string, string> = {
  counter: 'C', expression: 'ƒ', variable: 'V', input: 'I', output: 'O', stop: '■', end: '⊗', condition: '?', timer: 'Δt',
};
/** Properties a kind has (docs/nets.md "Elements"), shown as fields. */
const KIND_PROPS: Record<string, string[]> = {
  state: ['value'], counter: ['load', 'direction'], input: ['source'], output: ['target', 'source'], variable: ['mode', 'source', 'target', 'value', 'initial'], timer: ['delay'],
};
/** A widget's box at `c`: 120 wide (a label as wide as its caption, in 11 px type), 50 high for a plot, else 28. */
function widgetBox(w: Widget, c: Pt): { x: number; y: number; w: number; h: number } {
  const wide = w.kind === 'label' ? Math.max(120, Math.ceil((w.text ?? '').length * 6.2) + 12) : 120;
  return { x: c.x, y: c.y, w: wide, h: w.kind === 'plot' ? 50 : 28 };
}
let uid = 0;
/** What Ctrl+C or Ctrl+X took, shared by every net tab (paste into another net). */
let clipboard: Clip | null = null;

interface Replay {
  markings: Marking[];
  fired: string[];
  step: number;
}

export class NetView {
  readonly el: HTMLElement;
  private readonly ed: ProgramEditor;
  private readonly id = ++uid;
  private net: Net | null = null;
  /** The saved version's net: what runs, and what the live view subscribes to. */
  private savedNet: Net | null = null;
  private spans = new Map<string, Span>();
  private parseError: { message: string; offset: number } | null = null;
  private at = new Map<string, Pt>();
  private sel = new Set<string>();
  private snapOn = true;
  private mode: 'graphic' | 'text' = 'graphic';
  private arcTool = false;
  private linkFrom: string | null = null;
  private mouse: Pt | null = null;
  private drag: { ids: string[]; dx: number; dy: number } | null = null;
  private lastDown: { id: string; t: number } | null = null;
  private active = false;
  private unlisten: (() => void)[] = [];
  private analysis: Analysis | null = null;
  private analysisError: string | null = null;
  private analysing = false;
  /** The running analysis's progress and its cancellation. */
  private analysisProgress: AnalysisProgress | null = null;
  private analysisAbort: AbortController | null = null;
  private analysisTimedOut = false;
  private replayState: Replay | null = null;
  /** A scan of a counterexample replayed by the Verify & Test page: its values and energised elements ({@link showScan}). */
  private scanShown: { value: (tag: string) => Json | undefined; on: ReadonlySet<number> } | null = null;
  private lit = new Set<string>();
  private history: { scan: number; t: number; fired: string[]; changes: string[] }[] = [];
  /** Each transition's monitored elements in the running program (GET /api/programs, `transitions`). */
  private monitored = new Map<string, { enabled: number | null; fired: number | null }>();
  private lastMarking = new Map<string, number>();
  private plots = new Map<string, number[]>();
  /** Each Button's latch (a double-click holds it at true: widgets.ts), by widget id. */
  private latches = new Map<string, ButtonLatch>();
  /** The Buttons' writes, one after the other: a double-click's press, release and latch
   * must reach the runtime in that order, or the release's false can land last. */
  private buttonWrites: Promise<unknown> = Promise.resolve();
  /** Analyse counts with decision diagrams first (the toolbar's check box). */
  private symbolic = false;
  private svg: SVGSVGElement | null = null;
  /** The drawn group of each node and widget, by id. */
  private groups = new Map<string, SVGGElement>();
  private readonly canvas = h('div', { class: 'net-canvas', 'data-testid': 'net-canvas', tabindex: '0' });
  private readonly propsEl = h('div', { class: 'props net-props', 'data-testid': 'net-props' });
  private readonly analysisEl = h('div', { class: 'net-analysis', 'data-testid': 'net-analysis' });
  private readonly historyEl = h('ol', { class: 'net-history', 'data-testid': 'net-history' });
  private readonly zp = new ZoomPan(this.canvas, 'net', tr('Fit the net in the window (0)'));
  private readonly liveEl = h('span', { class: 'net-live-state', 'data-testid': 'net-live-state' });
  private readonly datalists = h('div', { hidden: true });
  /** The palette's buttons by kind, with their own tooltip. */
  private readonly kindButtons = new Map<string, [HTMLButtonElement, string]>();

  constructor(
    private readonly ctx: Ctx,
    readonly program: string,
  ) {
    this.ed = new ProgramEditor(ctx, program, {
      loaded: (p) => {
        const l = loadPnml(p.text);
        this.savedNet = l.net;
        this.monitored = new Map((p.transitions ?? []).map((t) => [t.id, { enabled: t.enabled, fired: t.fired }]));
        this.history = [];
        this.lastMarking.clear();
        if (this.active) this.subscribe();
      },
      textChanged: (fromTextArea) => this.textChanged(fromTextArea),
      changed: () => this.render(),
    });
    const modeBtn = (m: 'graphic' | 'text', label: string) => h('button', { class: 'mode', 'data-testid': `view-${m}`, onclick: () => this.setMode(m) }, label);
    const tool = (label: string, testid: string, title: string, action: () => void, gateAs: 'edit' | 'runstop' | null = 'edit') => {
      const b = h('button', { class: 'small', 'data-testid': testid, title }, label);
      b.onclick = () => {
        action();
        if (this.mode === 'graphic') this.canvas.focus();
      };
      if (gateAs) gate(b, gateAs);
      return b;
    };
    const palette = h('div', { class: 'net-palette', 'data-testid': 'net-palette' });
    this.el = h(
      'section',
      { class: 'ladder-view net-view', 'data-testid': `net-${program}` },
      h('div', { class: 'toolbar' },
        h('span', { class: 'seg' }, modeBtn('graphic', tr('Graphic')), modeBtn('text', tr('Text'))),
        h('span', { class: 'seg' },
          tool('↶', 'net-undo', tr('Undo (Ctrl+Z)'), () => this.ed.undo()),
          tool('↷', 'net-redo', tr('Redo (Ctrl+Y)'), () => this.ed.redo()),
          tool(`↗ ${tr('Arc')}`, 'net-tool-arc', tr('Draw arcs: click the start, then the end (or double-click the start)'), () => this.setArcTool(!this.arcTool)),
          tool(`✕ ${tr('Delete')}`, 'net-delete', tr('Delete the selection (Del)'), () => this.deleteSelection())),
        h('span', { class: 'seg' },
          this.zp.tools,
          h('label', { class: 'net-snap', title: tr('Snap to the grid while dragging (Alt: free)') },
            h('input', { type: 'checkbox', checked: true, 'data-testid': 'net-snap', onchange: (e: Event) => (this.snapOn = (e.target as HTMLInputElement).checked) }), ` ${tr('Grid')}`)),
        h('span', { class: 'seg' },
          tool(`▶ ${tr('Run')}`, 'net-run', tr('Run the PLC (F5)'), () => this.runStop('run'), 'runstop'),
          tool(`■ ${tr('Stop')}`, 'net-stop', tr('Stop the PLC (Shift+F5)'), () => this.runStop('stop'), 'runstop'),
          tool(`⇥ ${tr('Single step')}`, 'net-step', tr('Run one scan while the PLC is stopped (F6)'), () => void this.singleStep(), 'runstop'),
          tool(tr('Reset marking'), 'net-reset', tr('Write the initial marking to every place of the net, at one scan boundary'), () => void this.resetMarking(), 'runstop'),
          this.liveEl),
        h('span', { class: 'seg' },
          tool(tr('Analyse'), 'net-analyse', tr('Reachability, deadlocks, dead transitions and invariants of the saved net'), () => void this.analyse(), 'edit'),
          h('label', { class: 'net-snap', title: tr('Count the states with decision diagrams first: exact for state spaces far too big to list (alba analyze --symbolic)') },
            h('input', { type: 'checkbox', 'data-testid': 'net-analyse-symbolic', onchange: (e: Event) => (this.symbolic = (e.target as HTMLInputElement).checked) }), ` ${tr('Decision diagrams')}`)),
        this.ed.stateEl),
      h('div', { class: 'ladder-body' },
        palette,
        h('div', { class: 'ladder-main' }, this.canvas, this.ed.textBox),
        h('aside', { class: 'ladder-side net-side' },
          this.propsEl,
          h('h3', null, tr('Analysis')), this.analysisEl,
          h('h3', null, tr('Problems')), this.ed.problemsEl,
          h('h3', null, tr('Firings and marking changes')), this.historyEl,
          this.datalists)),
    );
    this.ed.section = this.el;
    this.palette(palette);
    this.canvas.addEventListener('keydown', (e) => this.onKey(e));
    this.el.addEventListener('keydown', (e) => this.onFunctionKey(e));
    this.setMode('graphic');
  }

  load(): Promise<void> {
    return this.ed.load();
  }

  show(): void {
    this.active = true;
    this.unlisten.push(
      ...this.ed.watch(() => this.paintLive()),
      this.ctx.live.onBatch(() => this.paintLive()),
      this.ctx.live.onRaw((m) => this.record(m)),
      this.ctx.live.onState(() => this.paintLive()),
      this.ctx.tags.onChange(() => this.renderProps()),
    );
    this.unlisten.push(this.mirrorRunStop());
    this.subscribe();
    this.ctx.live.monitor('net', [this.program]);
    this.render();
  }

  /**
   * The net's Run and Stop are the top bar's (issue 30, item 23): the same
   * words, tooltips (with the net's keys) and state, followed while shown.
   */
  private mirrorRunStop(): () => void {
    const pairs = (['run', 'stop'] as const).map((what) => ({
      top: document.querySelector<HTMLButtonElement>(`[data-testid="btn-${what}"]`),
      mine: this.el.querySelector<HTMLButtonElement>(`[data-testid="net-${what}"]`)!,
      key: what === 'run' ? 'F5' : tr('Shift+F5'),
    }));
    const copy = () => {
      for (const { top, mine, key } of pairs) {
        if (!top) continue;
        if (mine.textContent !== top.textContent) mine.textContent = top.textContent;
        const title = `${top.title} (${key})`;
        if (mine.title !== title) mine.title = title;
        mine.disabled = top.disabled;
      }
    };
    copy();
    const watch = new MutationObserver(copy);
    for (const { top } of pairs) if (top) watch.observe(top, { attributes: true, childList: true, characterData: true, subtree: true });
    return () => watch.disconnect();
  }

  hide(): void {
    this.active = false;
    this.unlisten.forEach((f) => f());
    this.unlisten = [];
    this.ctx.live.subscribe(`net:${this.program}`, null);
    this.ctx.live.monitor('net', null);
  }

  get dirty(): boolean {
    return this.ed.dirty;
  }

  check(): Promise<boolean> {
    return this.ed.check();
  }

  save(): Promise<boolean> {
    return this.ed.save();
  }

  /** The net being edited (for tests). */
  get current(): Net | null {
    return this.net;
  }

  // ---- the model ---------------------------------------------------------

  private textChanged(fromTextArea: boolean): void {
    const l = loadPnml(this.ed.text);
    this.parseError = l.error;
    this.spans = l.spans;
    // a text that is not PNML the editor reads is not drawn (nor edited graphically) until fixed
    this.net = l.net;
    const ids = this.net ? new Set([...this.net.places, ...this.net.transitions, ...this.net.arcs, ...this.net.widgets].map((x) => x.id)) : new Set<string>();
    this.sel = new Set([...this.sel].filter((x) => ids.has(x)));
    if (this.replayState && this.dirty) this.replayState = null;
    if (fromTextArea) this.renderSide();
    else this.render();
  }

  /** One undoable edit: `f` changes a copy of the net (false: nothing to do); the copy is written back as PNML. */
  private change(f: (net: Net) => boolean | void): boolean {
    if (!this.net || !can('edit')) return false;
    const next = structuredClone(this.net);
    if (f(next) === false) return false;
    this.ed.setText(savePnml(next));
    return true;
  }

  private subscribe(): void {
    const net = this.savedNet;
    if (!net) return this.ctx.live.subscribe(`net:${this.program}`, null);
    const names: string[] = [];
    for (const p of net.places) {
      names.push(markingTag(this.program, p.id));
      if (net.mode === 'normal') {
        if (p.kind === 'counter') names.push(`${markingTag(this.program, p.id)}.count`);
        if (['expression', 'input', 'variable'].includes(p.kind)) names.push(`${markingTag(this.program, p.id)}.value`);
      }
    }
    if (net.mode === 'normal')
      for (const t of net.transitions) {
        names.push(markingTag(this.program, t.id));
        if (t.kind === 'timer') names.push(`${markingTag(this.program, t.id)}.timer.ACC`, `${markingTag(this.program, t.id)}.timer.PRE`);
      }
    for (const w of net.widgets) if (w.tag && this.ctx.tags.resolve(w.tag)) names.push(w.tag);
    this.ctx.live.subscribe(`net:${this.program}`, names);
  }

  // ---- modes and the drawn area ------------------------------------------

  private setMode(m: 'graphic' | 'text'): void {
    this.mode = m;
    this.el.dataset.mode = m;
    this.el.querySelectorAll('.toolbar button.mode').forEach((b) => b.classList.toggle('active', (b as HTMLElement).dataset.testid === `view-${m}`));
    if (m === 'text') this.ed.textEl.value = this.ed.text;
    else this.render();
  }

  private setArcTool(on: boolean): void {
    this.arcTool = on;
    this.linkFrom = null;
    this.el.querySelector('[data-testid="net-tool-arc"]')?.classList.toggle('active', on);
    this.renderCanvas();
  }

  /** The drawn area: [x, y, w, h], at least 1200 × 700 from the origin. */
  private bounds(): [number, number, number, number] {
    const pts = [...this.at.values()];
    const x0 = Math.min(0, ...pts.map((p) => p.x - 80));
    const y0 = Math.min(0, ...pts.map((p) => p.y - 80));
    const x1 = Math.max(1200, ...pts.map((p) => p.x + 200));
    const y1 = Math.max(700, ...pts.map((p) => p.y + 120));
    return [x0, y0, x1 - x0, y1 - y0];
  }

  private toWorld(cx: number, cy: number): Pt {
    const svg = this.svg;
    if (!svg || typeof svg.createSVGPoint !== 'function') return { x: cx, y: cy };
    const pt = svg.createSVGPoint();
    if (typeof pt.matrixTransform !== 'function') return { x: cx, y: cy };
    pt.x = cx;
    pt.y = cy;
    const m = svg.getScreenCTM();
    const p = m ? pt.matrixTransform(m.inverse()) : pt;
    return { x: p.x, y: p.y };
  }

  // ---- editing -----------------------------------------------------------

  private palette(el: HTMLElement): void {
    const button = (testid: string, label: string, title: string, f: () => void) => {
      const b = h('button', { class: 'small', 'data-testid': testid, title }, label);
      b.onclick = () => {
        f();
        this.canvas.focus();
      };
      if (gate(b, 'edit')) this.kindButtons.set(testid.replace('net-add-', ''), [b, title]);
      return b;
    };
    const placeLabel: Record<string, string> = {
      state: tr('State'), counter: tr('Counter'), expression: tr('Expression'), variable: tr('Variable'), input: tr('Input'), output: tr('Output'), stop: tr('Stop'), end: tr('End'),
    };
    const transLabel: Record<string, string> = { transition: tr('Transition'), condition: tr('Condition'), timer: tr('Timer') };
    const widgetLabel: Record<string, string> = { button: tr('Button'), display: tr('Display'), plot: tr('Plot'), label: tr('Label') };
    const keys: Record<string, string> = { state: 'S', transition: 'T', expression: 'Shift+E', condition: 'Shift+C' };
    add(el,
      h('h4', null, tr('States')),
      PLACE_KINDS.map((k) => button(`net-add-${k}`, placeLabel[k], keys[k] ? `${placeLabel[k]} (${keys[k]})` : placeLabel[k], () => this.addNode('place', k))),
      h('h4', null, tr('Transitions')),
      TRANSITION_KINDS.map((k) => button(`net-add-${k}`, transLabel[k], keys[k] ? `${transLabel[k]} (${keys[k]})` : transLabel[k], () => this.addNode('transition', k))),
      h('h4', null, tr('Operator')),
      WIDGET_KINDS.map((k) => button(`net-add-${k}`, widgetLabel[k], widgetLabel[k], () => this.addWidget(k))),
      h('p', { class: 'hint' }, tr('In Petri mode only states, transitions and arcs run; the other kinds are for normal mode.')));
  }

  /** Where a new element goes: at the mouse over the canvas, else right of the selected node, else a free place. */
  private spot(): Pt {
    const one = this.sel.size === 1 ? this.at.get([...this.sel][0]) : undefined;
    let p = this.mouse ?? (one ? { x: one.x + 100, y: one.y } : { x: 60, y: 60 });
    if (!this.mouse && !one && this.at.size) {
      const last = [...this.at.values()].pop()!;
      p = { x: last.x + 100, y: last.y };
    }
    p = { x: snap(p.x), y: snap(p.y) };
    const box = (q: Pt) => ({ x: q.x - 30, y: q.y - 30, w: 60, h: 60 });
    for (let k = 0; k < 50 && [...this.at.values()].some((q) => overlaps(box(p), box(q))); k++) p = { x: p.x + 30, y: p.y };
    return p;
  }

  /** The kinds that only normal mode runs (Petri mode refuses them, E620). */
  private static normalOnly(kind: string): boolean {
    return !['state', 'transition', ...WIDGET_KINDS].includes(kind);
  }

  /** Normal-mode kinds disabled in the palette of a Petri-mode net, saying why. */
  private paintPalette(): void {
    const petri = this.net?.mode === 'petri';
    for (const [kind, [b, title]] of this.kindButtons) {
      const off = petri && NetView.normalOnly(kind);
      b.disabled = off;
      b.title = off ? tr('{kind}: normal mode only (set the net’s mode with nothing selected)', { kind: title }) : title;
    }
  }

  addNode(what: 'place' | 'transition', kind: string): void {
    if (this.net?.mode === 'petri' && NetView.normalOnly(kind)) {
      this.ctx.notify(tr('{kind}: normal mode only (set the net’s mode with nothing selected)', { kind }), 'error');
      return;
    }
    const p = this.spot();
    let id = '';
    if (this.change((n) => void (id = what === 'place' ? addPlace(n, p.x, p.y, kind).id : addTransition(n, p.x, p.y, kind).id))) this.select([id]);
  }

  private addWidget(kind: string): void {
    const p = this.spot();
    let id = '';
    if (this.change((n) => {
      id = freshId(n, 'w');
      n.widgets.push({ id, kind, tag: null, text: kind === 'label' ? tr('Label') : null, x: p.x, y: p.y, style: {} });
    })) this.select([id]);
  }

  private select(ids: Iterable<string>, extend = false): void {
    this.sel = extend ? new Set([...this.sel, ...ids]) : new Set(ids);
    this.render();
  }

  private deleteSelection(): void {
    if (!this.sel.size) return;
    const ids = new Set(this.sel);
    if (this.change((n) => remove(n, ids))) this.sel.clear();
    this.render();
  }

  private link(from: string, to: string): boolean {
    if (!this.net) return false;
    const why = arcProblem(this.net, from, to);
    if (why) {
      const msg = {
        same: tr('An arc joins a state and a transition, not two of the same kind.'),
        twice: tr('These two elements are already joined that way.'),
        direction: tr('Inhibitor and read arcs go from a place to a transition.'),
        unknown: tr('An arc joins two elements of the net.'),
      }[why];
      this.ctx.notify(msg, 'error');
      return false;
    }
    let id = '';
    this.change((n) => void (id = connect(n, from, to)!.id));
    this.sel = new Set([id]);
    this.render();
    return true;
  }

  /** Arcs from every selected node to `target` (Ctrl+click), or from `source` to every selected one (Ctrl+Shift+click), as in the source. */
  private linkSelection(node: string, reverse: boolean): void {
    if (!this.net) return;
    const net = this.net;
    const pairs = [...this.sel].filter((x) => x !== node && findNode(net, x)).map((x) => (reverse ? [node, x] : [x, node]));
    const ok = pairs.filter(([a, b]) => !arcProblem(net, a, b));
    if (!ok.length) return this.ctx.notify(tr('An arc joins a state and a transition, not two of the same kind.'), 'error');
    this.change((n) => ok.forEach(([a, b]) => connect(n, a, b)));
  }

  private onFunctionKey(e: KeyboardEvent): void {
    if (e.key === 'F5') {
      e.preventDefault();
      this.runStop(e.shiftKey ? 'stop' : 'run');
    } else if (e.key === 'F6') {
      e.preventDefault();
      void this.singleStep();
    } else if (e.key === 'F4' && this.mode === 'graphic') {
      e.preventDefault();
      this.propsEl.querySelector<HTMLElement>('input,select,textarea')?.focus();
    } else if (e.key === 'F8' && this.mode === 'graphic') {
      e.preventDefault();
      this.propsEl.querySelector<HTMLElement>('[data-testid="net-prop-script"],[data-testid="net-prop-guard"]')?.focus();
    }
  }

  private onKey(e: KeyboardEvent): void {
    if ((e.target as HTMLElement).closest('input,select,textarea')) return;
    const mod = e.ctrlKey || e.metaKey;
    const k = e.key.toLowerCase();
    const arrows: Record<string, [number, number]> = { arrowleft: [-1, 0], arrowright: [1, 0], arrowup: [0, -1], arrowdown: [0, 1] };
    const at = (id: string) => this.at.get(id) ?? { x: 0, y: 0 };
    if (this.zp.key(e)) return e.preventDefault();
    if (mod && (k === 'y' || (k === 'z' && e.shiftKey))) this.ed.redo();
    else if (mod && k === 'z') this.ed.undo();
    else if (mod && k === 'a' && this.net) this.select([...this.net.places, ...this.net.transitions, ...this.net.widgets].map((x) => x.id));
    else if (mod && (k === 'c' || k === 'x') && this.sel.size && this.net) {
      clipboard = copy(this.net, this.sel);
      if (k === 'x') this.deleteSelection();
    } else if (mod && (k === 'v' || k === 'd')) {
      const clip = k === 'v' ? clipboard : this.net && copy(this.net, this.sel);
      if (!clip) return;
      let ids: string[] = [];
      if (this.change((n) => void (ids = paste(n, clip, GRID * 3, GRID * 3, at)))) this.select(ids);
    } else if (mod) return;
    else if (e.key === 'Escape') {
      this.linkFrom = null;
      if (this.arcTool) this.setArcTool(false);
      this.select([]);
    } else if (e.key === 'Delete' || e.key === 'Backspace') this.deleteSelection();
    else if (k === 's' && !e.altKey) this.addNode('place', 'state');
    else if (k === 't' && !e.altKey) this.addNode('transition', 'transition');
    else if (k === 'e' && e.shiftKey) this.addNode('place', 'expression');
    else if (k === 'c' && e.shiftKey) this.addNode('transition', 'condition');
    else if (arrows[k] && this.sel.size) {
      const step = e.shiftKey ? 1 : GRID;
      const ids = [...this.sel];
      this.change((n) => moveNodes(n, ids, arrows[k][0] * step, arrows[k][1] * step, at));
    } else return;
    e.preventDefault();
  }

  private runStop(what: 'run' | 'stop'): void {
    // the top bar's buttons: the same confirmation and state everywhere
    const b = document.querySelector<HTMLButtonElement>(`[data-testid="btn-${what}"]`);
    if (b && !b.disabled) b.click();
  }

  /** Single step (POST /api/step): one scan of the stopped PLC; refused, with the server's reason, while it runs. */
  private async singleStep(): Promise<void> {
    if (!can('runstop')) return;
    try {
      await api.step();
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
    }
  }

  /** Writes the saved net's initial marking at one scan boundary (POST /api/nets/{name}/reset). */
  private async resetMarking(): Promise<void> {
    if (!this.savedNet) return;
    try {
      await api.resetNet(this.program);
      this.ctx.notify(tr('{program}: initial marking written', { program: this.program }));
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
    }
  }

  // ---- problems on elements ----------------------------------------------

  /** The element whose text holds `offset` (the innermost one). */
  private elementAt(offset: number): string | null {
    let best: string | null = null;
    let len = Infinity;
    for (const [id, sp] of this.spans)
      if (sp.start <= offset && offset < sp.end && sp.end - sp.start < len) {
        best = id;
        len = sp.end - sp.start;
      }
    return best;
  }

  /** The server's problems by element id. */
  private problems(): Map<string, string[]> {
    const out = new Map<string, string[]>();
    for (const d of this.ed.mine()) {
      if (d.line === null) continue;
      const id = this.elementAt(offsetOf(this.ed.text, d.line, d.col ?? 1));
      if (id) out.set(id, [...(out.get(id) ?? []), problemTip(d)]);
    }
    return out;
  }

  // ---- live values -------------------------------------------------------

  /** Live for the saved text over a live connection, while the PLC runs or is stopped (single steps). */
  private get live(): boolean {
    const st = this.ctx.live.status?.state;
    return !this.ed.dirty && !!this.savedNet && this.ctx.live.state === 'connected' && (st === 'running' || st === 'stopped');
  }

  /** The transitions whose "enabled" and "fired" elements are energised in `on` (ids of the running program). */
  private powered(on: ReadonlySet<number>): { enabled: Set<string>; fired: Set<string> } {
    const enabled = new Set<string>();
    const fired = new Set<string>();
    for (const [id, e] of this.monitored) {
      if (e.enabled !== null && on.has(e.enabled)) enabled.add(id);
      if (e.fired !== null && on.has(e.fired)) fired.add(id);
    }
    return { enabled, fired };
  }

  private value(name: string): Json | undefined {
    return this.scanShown ? this.scanShown.value(name) : this.ctx.live.store.get(name);
  }

  /**
   * Shows one scan of a replayed run (the Verify & Test page's counterexample,
   * docs/verify.md): the marking from its values of the marking tags, the
   * transitions enabled and fired from its energised elements (the compiled
   * "enabled" and "fired" elements, as live), timers and counters from their tags.
   */
  showScan(value: (tag: string) => Json | undefined, on: ReadonlySet<number>): void {
    this.scanShown = { value, on };
    this.paintLive();
  }

  /** The marking shown: a replay step, the running net's, or the initial one while designing. */
  private marking(): { m: Marking; source: 'replay' | 'live' | 'initial' } {
    const net = this.net!;
    if (this.replayState) return { m: this.replayState.markings[this.replayState.step], source: 'replay' };
    if (this.live || this.scanShown) {
      const m: Marking = new Map();
      for (const n of [...net.places, ...(net.mode === 'normal' ? net.transitions : [])]) {
        const v = this.value(markingTag(this.program, n.id));
        m.set(n.id, typeof v === 'number' ? v : 0);
      }
      return { m, source: this.scanShown ? 'replay' : 'live' };
    }
    return { m: initialMarking(net), source: 'initial' };
  }

  /** The history entry of `scan` (the newest, or a new one); the last 50, newest first. */
  private entryFor(scan: number, t: number): { scan: number; t: number; fired: string[]; changes: string[] } {
    if (this.history[0]?.scan === scan) return this.history[0];
    const e = { scan, t, fired: [] as string[], changes: [] as string[] };
    this.history.unshift(e);
    this.history.length = Math.min(this.history.length, 50);
    return e;
  }

  /**
   * The history: the transitions that fired in a scan (a power message of this
   * program: their "fired" elements energised) and the marking changes (a
   * values message), merged by scan.
   */
  private record(msg: ServerMsg): void {
    const net = this.savedNet;
    if (!net || !this.active) return;
    if (msg.type === 'power') {
      if (msg.program !== this.program) return;
      const fired = [...this.powered(new Set(msg.on)).fired];
      if (!fired.length) return;
      this.entryFor(msg.scan, Date.now()).fired = fired;
      return this.renderHistory();
    }
    if (msg.type !== 'values') return;
    const changes: string[] = [];
    // tag names are case-insensitive: the server may send them in its own spelling
    const values = new Map(Object.entries(msg.values).map(([k, v]) => [k.toUpperCase(), v]));
    for (const n of [...net.places, ...(net.mode === 'normal' ? net.transitions : [])]) {
      const v = values.get(markingTag(this.program, n.id).toUpperCase());
      if (typeof v !== 'number') continue;
      const was = this.lastMarking.get(n.id);
      this.lastMarking.set(n.id, v);
      if (was !== undefined && was !== v) changes.push(`${n.id} ${v > was ? '+' : '−'}${Math.abs(v - was)}`);
    }
    if (!changes.length) return;
    const e = this.entryFor(msg.scan, msg.t_ms);
    e.t = msg.t_ms;
    e.changes = changes;
    this.renderHistory();
  }

  private renderHistory(): void {
    clear(this.historyEl);
    if (!this.history.length) this.historyEl.append(h('li', { class: 'none' }, tr('None yet: the running net’s token moves are listed here.')));
    this.history.forEach((x, k) =>
      this.historyEl.append(h('li', { 'data-testid': `net-history-${k}` },
        h('span', { class: 'where' }, `#${x.scan} ${clockTime(x.t)}`), ' ',
        [x.fired.length ? tr('fired {ids}', { ids: x.fired.join(', ') }) : '', x.changes.join(' · ')].filter(Boolean).join(' — '))));
  }

  /** Tokens, enabled transitions and live values, on the drawn canvas. */
  private paintLive(): void {
    const net = this.net;
    const svg = this.svg;
    if (!net || !svg || this.mode !== 'graphic') return;
    const { m, source } = this.marking();
    svg.dataset.marking = source;
    const stopped = this.ctx.live.status?.state === 'stopped';
    this.liveEl.textContent =
      source === 'live' ? (stopped ? tr('stopped: F6 runs one scan') : tr('live')) : source === 'replay' ? tr('replay') : this.dirty ? tr('edited: initial marking shown') : tr('not running: initial marking shown');
    this.liveEl.dataset.state = source;
    // live: the runtime's own verdict (arcs and guard, after the last scan) and the transitions that fired in it;
    // a replay or the design: enabled by the arcs of the marking shown (normal mode: holding the token)
    const powered = this.scanShown ? this.powered(this.scanShown.on) : source === 'live' ? this.powered(this.ed.on) : null;
    const on = powered
      ? powered.enabled
      : net.mode === 'normal'
        ? new Set(net.transitions.filter((t) => (m.get(t.id) ?? 0) > 0).map((t) => t.id))
        : enabled(net, m);
    for (const p of net.places) {
      const g = this.groups.get(p.id);
      if (!g) continue;
      const n = m.get(p.id) ?? 0;
      g.dataset.tokens = String(n);
      const tokens = g.querySelector('.net-tokens')!;
      clear(tokens);
      if (n > 0 && n <= 4) {
        const spots = [[[0, 0]], [[-6, 0], [6, 0]], [[-6, 5], [6, 5], [0, -6]], [[-6, -6], [6, -6], [-6, 6], [6, 6]]][n - 1];
        for (const [x, y] of spots) tokens.append(s('circle', { class: 'net-token', cx: x, cy: y, r: 4.5 }));
      } else if (n !== 0) tokens.append(s('text', { class: 'net-token-count', 'text-anchor': 'middle', y: 5 }, String(n)));
      g.classList.toggle('marked', n > 0);
      const info = g.querySelector('.net-info');
      if (info) info.textContent = source === 'live' || this.scanShown ? this.infoOf(p.id, p.kind) : '';
    }
    for (const t of net.transitions) {
      const g = this.groups.get(t.id);
      if (!g) continue;
      g.classList.toggle('enabled', on.has(t.id));
      g.dataset.enabled = String(on.has(t.id));
      const fired = powered ? powered.fired.has(t.id) : this.replayState && this.replayState.step > 0 && this.replayState.fired[this.replayState.step - 1] === t.id;
      g.classList.toggle('fired', !!fired);
      // normal mode: a transition holding the token shows it (enabled or waiting for its guard)
      const tokens = g.querySelector('.net-tokens');
      if (tokens) {
        const n = m.get(t.id) ?? 0;
        g.dataset.tokens = String(n);
        g.classList.toggle('marked', n > 0);
        clear(tokens);
        if (n > 0) tokens.append(s('circle', { class: 'net-token', cx: 0, cy: 0, r: 4 }));
      }
      const info = g.querySelector('.net-info');
      if (info) info.textContent = source === 'live' || this.scanShown ? this.infoOf(t.id, t.kind) : '';
    }
    for (const w of net.widgets) {
      const g = this.groups.get(w.id);
      const v = w.tag ? this.value(w.tag) : undefined;
      const val = g?.querySelector('.net-widget-value');
      // a Display shows its value in its mode and format (net/widgets.ts); a Plot its last value
      const shown = w.kind === 'display' ? displayText(v, w.style) : w.kind === 'plot' ? displayText(v, { unit: w.style?.unit ?? '' }) : fmt(v);
      if (val) val.textContent = w.kind === 'label' ? '' : source === 'live' ? shown : '';
      g?.classList.toggle('on', v === true);
      g?.classList.toggle('latched', this.latches.get(w.id)?.latched === true);
      if (w.kind === 'plot' && g && typeof v === 'number' && source === 'live') {
        const pts = this.plots.get(w.id) ?? [];
        if (pts[pts.length - 1] !== v || pts.length < 2) pts.push(v);
        if (pts.length > 60) pts.shift();
        this.plots.set(w.id, pts);
        // the Y axis: the points' own range (autoscale), else the widget's min and max
        const { lo, hi } = plotRange(pts, w.style);
        const y = (p: number) => 44 - (Math.min(hi, Math.max(lo, p)) - lo) / (hi - lo) * 20;
        const line = g.querySelector('.net-plot-line');
        line?.setAttribute('points', pts.map((p, k) => `${4 + (k * 112) / 59},${y(p).toFixed(2)}`).join(' '));
        const scale = g.querySelector('.net-plot-scale');
        if (scale) scale.textContent = `${fmt(lo)}…${fmt(hi)}${w.style?.unit ? ` ${w.style.unit}` : ''}`;
      }
    }
  }

  private writeButton(tag: string, v: boolean): void {
    this.buttonWrites = this.buttonWrites
      .then(() => api.writeTag(tag, v))
      .catch((e) => this.ctx.notify(e.message, 'error'));
  }

  private latchOf(id: string): ButtonLatch {
    let l = this.latches.get(id);
    if (!l) this.latches.set(id, (l = new ButtonLatch()));
    return l;
  }

  /** A timer's elapsed time, a counter's count, an element's variable (normal mode). */
  private infoOf(id: string, kind: string): string {
    const tag = markingTag(this.program, id);
    if (kind === 'timer') {
      const acc = this.value(`${tag}.timer.ACC`);
      const pre = this.value(`${tag}.timer.PRE`);
      return acc === undefined ? '' : `${fmt(acc)}/${fmt(pre)} ms`;
    }
    if (kind === 'counter') return this.value(`${tag}.count`) === undefined ? '' : `= ${fmt(this.value(`${tag}.count`))}`;
    if (['expression', 'input', 'variable'].includes(kind)) return this.value(`${tag}.value`) === undefined ? '' : `= ${fmt(this.value(`${tag}.value`))}`;
    return '';
  }

  // ---- drawing -----------------------------------------------------------

  private render(): void {
    this.paintPalette();
    this.renderCanvas();
    this.renderProps();
    this.renderSide();
    this.renderAnalysis();
    this.renderHistory();
  }

  private renderSide(): void {
    const extra: Problem[] = this.parseError
      ? [{ code: '', line: lineCol(this.ed.text, this.parseError.offset)[0], col: lineCol(this.ed.text, this.parseError.offset)[1], text: this.parseError.message }]
      : [];
    this.ed.renderProblems(extra, (line, col) => this.goTo(line, col ?? 1));
    this.ed.renderState();
  }

  private goTo(line: number, col: number): void {
    if (this.mode === 'text') return this.ed.focusText(line, col);
    const id = this.elementAt(offsetOf(this.ed.text, line, col));
    if (id) this.select([id]);
    else {
      this.setMode('text');
      this.ed.focusText(line, col);
    }
  }

  private renderCanvas(): void {
    if (this.mode !== 'graphic') return;
    clear(this.canvas);
    this.svg = null;
    this.groups.clear();
    const net = this.net;
    if (!net) {
      this.canvas.append(h('p', { class: 'net-unreadable', 'data-testid': 'net-unreadable' }, tr('The file cannot be drawn: {m}. Fix it in the text view.', { m: this.parseError?.message ?? '' })));
      return;
    }
    const at = positions(net);
    if (this.drag) for (const id of this.drag.ids) {
      const p = at.get(id);
      if (p) at.set(id, { x: p.x + this.drag.dx, y: p.y + this.drag.dy });
    }
    this.at = at;
    const errors = this.problems();
    const a = this.analysis && !this.dirty ? this.analysis : null;
    const dead = new Set(a?.dead_transitions ?? []);
    const [x0, y0, w, hh] = this.bounds();
    const mk = `net-arrow-${this.id}`;
    const sheet = grid(`net-grid-${this.id}`, GRID * 2, { x: x0, y: y0, w, h: hh });
    const svg = s('svg', { class: 'net-svg', viewBox: `${x0} ${y0} ${w} ${hh}`, 'data-testid': 'net-svg', 'data-mode': net.mode },
      s('defs', null,
        s('marker', { id: mk, viewBox: '0 0 10 10', refX: 10, refY: 5, markerWidth: 8, markerHeight: 8, orient: 'auto-start-reverse' }, s('path', { d: 'M0,0 L10,5 L0,10 z', class: 'net-arrowhead' })),
        s('marker', { id: `${mk}-inh`, viewBox: '0 0 10 10', refX: 10, refY: 5, markerWidth: 9, markerHeight: 9, orient: 'auto' }, s('circle', { cx: 5, cy: 5, r: 4, class: 'net-inhibitor-end' })),
        sheet.pattern),
    );
    const bg = sheet.background;
    bg.dataset.testid = 'net-background';
    svg.append(bg);
    bg.addEventListener('pointerdown', (ev) => this.startBand(ev));
    svg.addEventListener('pointermove', (ev) => {
      this.mouse = this.toWorld(ev.clientX, ev.clientY);
      const preview = svg.querySelector('.net-link-preview');
      if (preview && this.mouse) {
        preview.setAttribute('x2', String(this.mouse.x));
        preview.setAttribute('y2', String(this.mouse.y));
      }
    });
    svg.addEventListener('pointerleave', () => (this.mouse = null));
    // arcs
    const r = routes(net, at, !this.drag);
    for (const arc of net.arcs) {
      const pts = r.get(arc.id);
      if (!pts) continue;
      const d = pts.map((p) => `${p.x},${p.y}`).join(' ');
      const cls = `net-arc kind-${arc.kind}${this.sel.has(arc.id) ? ' selected' : ''}${errors.has(arc.id) ? ' error' : ''}`;
      const g = s('g', { class: cls, 'data-testid': `net-arc-${arc.id}`, 'data-source': arc.source, 'data-target': arc.target },
        s('polyline', { points: d, class: 'net-arc-line', 'marker-end': arc.kind === 'inhibitor' ? `url(#${mk}-inh)` : arc.kind === 'read' ? undefined : `url(#${mk})` }),
        s('polyline', { points: d, class: 'net-arc-hit' }),
        errors.has(arc.id) ? s('title', null, errors.get(arc.id)!.join('\n')) : null);
      if (arc.weight !== 1) {
        const mid = pts[Math.floor((pts.length - 1) / 2)];
        const nxt = pts[Math.floor((pts.length - 1) / 2) + 1];
        g.append(s('text', { class: 'net-weight', x: (mid.x + nxt.x) / 2 + 4, y: (mid.y + nxt.y) / 2 - 4 }, String(arc.weight)));
      }
      g.addEventListener('pointerdown', (ev) => {
        if (ev.button !== 0) return;
        ev.stopPropagation();
        if (ev.shiftKey) this.select(this.sel.has(arc.id) ? [...this.sel].filter((x) => x !== arc.id) : [...this.sel, arc.id]);
        else this.select([arc.id]);
        this.canvas.focus();
      });
      svg.append(g);
    }
    // nodes
    const invTip = (id: string) => (this.lit.has(id) ? ' lit' : '');
    // what a guard must not run into: the nodes, their names, the widgets, and the guards drawn before it
    const taken: Box[] = [
      ...net.places.flatMap((p) => {
        const c = at.get(p.id)!;
        return [placeBox(c), textBox(c.x + PLACE_R - 6, c.y + PLACE_R + 10, (p.name ?? p.id).length, TEXT.label), ...(p.tag ? [textBox(c.x + PLACE_R - 6, c.y + PLACE_R + 22, p.tag.length + 2, TEXT.mono)] : [])];
      }),
      ...net.transitions.flatMap((t) => {
        const c = at.get(t.id)!;
        return [transitionBox(c), textBox(c.x + TRANS_W / 2 + 3, c.y - TRANS_H / 2 - 3, (t.name ?? t.id).length, TEXT.label)];
      }),
      ...net.widgets.map((wd) => widgetBox(wd, at.get(wd.id)!)),
    ];
    for (const p of net.places) {
      const c = at.get(p.id)!;
      const cls = `net-node net-place kind-${p.kind}${this.sel.has(p.id) ? ' selected' : ''}${errors.has(p.id) ? ' error' : ''}${invTip(p.id)}${this.linkFrom === p.id ? ' link-from' : ''}`;
      const g = s('g', { class: cls, transform: `translate(${c.x},${c.y})`, 'data-testid': `net-node-${p.id}`, 'data-kind': p.kind, 'data-id': p.id },
        s('circle', { r: PLACE_R + 4, class: 'net-hit' }),
        s('circle', { r: PLACE_R, class: 'net-shape' }),
        p.kind === 'end' ? s('circle', { r: PLACE_R - 4, class: 'net-shape-inner' }) : null,
        GLYPH[p.kind] ? s('text', { class: 'net-glyph', x: PLACE_R - 2, y: -PLACE_R + 4 }, GLYPH[p.kind]) : null,
        s('g', { class: 'net-tokens' }),
        // the name and lamp tag at the lower right: arcs meet the circle towards other nodes' centres
        s('text', { class: 'net-label', x: PLACE_R - 6, y: PLACE_R + 10 }, p.name ?? p.id),
        p.tag ? s('text', { class: 'net-tagname', x: PLACE_R - 6, y: PLACE_R + 22 }, `→ ${p.tag}`) : null,
        s('text', { class: 'net-info', y: -PLACE_R - 6, 'text-anchor': 'middle' }),
        a?.place_bounds && a.place_bounds[p.id] !== undefined ? s('text', { class: 'net-bound', x: -PLACE_R - 2, y: -PLACE_R + 4, 'text-anchor': 'end' }, `≤${a.place_bounds[p.id] === 'omega' ? 'ω' : a.place_bounds[p.id]}`) : null,
        errors.has(p.id) ? s('circle', { r: PLACE_R + 5, class: 'net-error-ring', 'data-testid': `net-error-${p.id}` }, s('title', null, errors.get(p.id)!.join('\n'))) : null);
      this.nodeEvents(g, p.id);
      this.groups.set(p.id, g);
      svg.append(g);
    }
    for (const t of net.transitions) {
      const c = at.get(t.id)!;
      const cls = `net-node net-transition kind-${t.kind}${this.sel.has(t.id) ? ' selected' : ''}${errors.has(t.id) ? ' error' : ''}${dead.has(t.id) ? ' dead' : ''}${invTip(t.id)}${this.linkFrom === t.id ? ' link-from' : ''}`;
      const guard = t.kind === 'timer' ? (t.props.delay ?? '') : (t.guard ?? '');
      const shown = guard && fitGuard(guard, c.x + TRANS_W / 2 + 3, c.y + TRANS_H / 2 + 11, taken);
      if (shown) taken.push(textBox(c.x + TRANS_W / 2 + 3, c.y + TRANS_H / 2 + 11, shown.length, TEXT.mono));
      const g = s('g', { class: cls, transform: `translate(${c.x},${c.y})`, 'data-testid': `net-node-${t.id}`, 'data-kind': t.kind, 'data-id': t.id, 'data-dead': dead.has(t.id) ? 'true' : undefined },
        // a grip over the bar and its labels: easier to grab than a 12-unit bar
        // the name at the top right of the bar and the guard (or delay) at the bottom right:
        // arcs meet the bar in the middle of its sides and of its ends
        s('rect', { x: -TRANS_W / 2 - 8, y: -TRANS_H / 2 - 14, width: TRANS_W + 56, height: TRANS_H + 28, class: 'net-hit' }),
        s('rect', { x: -TRANS_W / 2, y: -TRANS_H / 2, width: TRANS_W, height: TRANS_H, class: 'net-shape' }),
        GLYPH[t.kind] ? s('text', { class: 'net-glyph', x: -TRANS_W / 2 - 2, y: -TRANS_H / 2 + 8, 'text-anchor': 'end' }, GLYPH[t.kind]) : null,
        s('text', { class: 'net-label', x: TRANS_W / 2 + 3, y: -TRANS_H / 2 - 3 }, t.name ?? t.id),
        guard ? s('text', { class: 'net-guard', x: TRANS_W / 2 + 3, y: TRANS_H / 2 + 11 }, shown, s('title', null, guard)) : null,
        t.priority !== null ? s('text', { class: 'net-prio', x: -TRANS_W / 2 - 2, y: TRANS_H / 2, 'text-anchor': 'end' }, `#${t.priority}`) : null,
        s('text', { class: 'net-info', y: -TRANS_H / 2 - 17, 'text-anchor': 'middle' }),
        errors.has(t.id) ? s('rect', { x: -TRANS_W / 2 - 5, y: -TRANS_H / 2 - 5, width: TRANS_W + 10, height: TRANS_H + 10, class: 'net-error-ring', 'data-testid': `net-error-${t.id}` }, s('title', null, errors.get(t.id)!.join('\n'))) : null);
      if (net.mode === 'normal') g.append(s('g', { class: 'net-tokens' }));
      this.nodeEvents(g, t.id);
      this.groups.set(t.id, g);
      svg.append(g);
    }
    for (const wd of net.widgets) {
      const c = at.get(wd.id)!;
      const big = wd.kind === 'plot';
      const box = widgetBox(wd, c);
      const look = wd.kind === 'label' ? labelLook(wd.style) : null;
      const size = Number(wd.style?.font_size);
      const valueStyle = wd.kind === 'display' && Number.isFinite(size) && size >= 6 && size <= 72 ? { 'font-size': `${size}px` } : {};
      const anchor = look ? { left: ['start', 6], center: ['middle', box.w / 2], right: ['end', box.w - 6] }[look.align] : ['start', 6];
      const g = s('g', { class: `net-widget kind-${wd.kind}${this.sel.has(wd.id) ? ' selected' : ''}${look && !look.border ? ' no-border' : ''}`, transform: `translate(${c.x},${c.y})`, 'data-testid': `net-widget-${wd.id}`, 'data-kind': wd.kind },
        s('rect', { width: box.w, height: box.h, rx: wd.kind === 'button' ? 6 : 2, class: 'net-widget-box', style: look?.background ? `fill:${look.background}` : undefined }),
        s('text', {
          class: 'net-widget-caption', x: anchor[1], y: 12, 'text-anchor': anchor[0],
          style: look ? [look.color ? `fill:${look.color}` : '', look.font ? `font-family:${look.font}` : '', look.fontSize ? `font-size:${look.fontSize}px` : ''].filter(Boolean).join(';') || undefined : undefined,
        }, wd.kind === 'plot' && wd.style?.title ? wd.style.title : (wd.text ?? wd.tag ?? wd.kind)),
        s('text', { class: 'net-widget-value', x: 114, y: big ? 12 : 23, 'text-anchor': 'end', style: valueStyle['font-size'] ? `font-size:${valueStyle['font-size']}` : undefined }),
        big ? s('polyline', { class: 'net-plot-line', points: '' }) : null,
        big ? s('text', { class: 'net-plot-scale', x: 4, y: 48 }) : null);
      g.addEventListener('pointerdown', (ev) => {
        if (ev.button !== 0 || this.zp.space) return;
        ev.stopPropagation();
        // a button of the running net writes its tag (pressed: true, released: false; a
        // double-click latches it at true, the next press releases it: widgets.ts)
        if (wd.kind === 'button' && this.live && wd.tag && !ev.shiftKey && !this.sel.has(wd.id) && can('write')) {
          const latch = this.latchOf(wd.id);
          const write = (v: boolean | null) => {
            if (v !== null) this.writeButton(wd.tag!, v);
            g.classList.toggle('latched', latch.latched);
          };
          write(latch.press());
          const up = () => {
            window.removeEventListener('pointerup', up);
            write(latch.release());
          };
          window.addEventListener('pointerup', up);
          return;
        }
        this.startDrag(ev, wd.id);
      });
      g.addEventListener('dblclick', (ev) => {
        if (wd.kind !== 'button' || !this.live || !wd.tag || ev.shiftKey || this.sel.has(wd.id) || !can('write')) return;
        ev.stopPropagation();
        const latch = this.latchOf(wd.id);
        this.writeButton(wd.tag, latch.double() ?? true);
        g.classList.add('latched');
      });
      this.groups.set(wd.id, g);
      svg.append(g);
    }
    if (this.linkFrom && at.get(this.linkFrom)) {
      const f = at.get(this.linkFrom)!;
      const m = this.mouse ?? f;
      svg.append(s('line', { class: 'net-link-preview', x1: f.x, y1: f.y, x2: m.x, y2: m.y }));
    }
    svg.classList.toggle('arc-tool', this.arcTool);
    this.svg = svg;
    this.canvas.append(svg);
    this.zp.attach(svg, w, hh);
    this.paintLive();
  }

  private nodeEvents(g: SVGGElement, id: string): void {
    g.addEventListener('pointerdown', (ev) => {
      if (ev.button !== 0 || this.zp.space) return;
      ev.stopPropagation();
      this.canvas.focus();
      // a double click (told here: the first click redraws the node, so no dblclick event
      // would reach the new one) starts an arc from the node, as in the source
      const now = Date.now();
      const double = this.lastDown?.id === id && now - this.lastDown.t < 400;
      this.lastDown = { id, t: now };
      if (double && !this.linkFrom && !ev.shiftKey && !ev.ctrlKey && can('edit')) {
        this.linkFrom = id;
        this.renderCanvas();
        return;
      }
      if (this.linkFrom && this.linkFrom !== id) {
        const from = this.linkFrom;
        this.linkFrom = null;
        if (!this.link(from, id) && this.arcTool) this.linkFrom = from;
        if (this.arcTool) this.renderCanvas();
        return;
      }
      if (this.arcTool && can('edit')) {
        this.linkFrom = id;
        this.renderCanvas();
        return;
      }
      if ((ev.ctrlKey || ev.metaKey) && this.sel.size && !this.sel.has(id) && can('edit')) return this.linkSelection(id, ev.shiftKey);
      if (ev.shiftKey) return this.select(this.sel.has(id) ? [...this.sel].filter((x) => x !== id) : [...this.sel, id]);
      this.startDrag(ev, id);
    });
  }

  /** Dragging a node moves the selection, snapped to the grid (Alt or Grid off: free); one undoable step. */
  private startDrag(ev: PointerEvent, id: string): void {
    if (!this.sel.has(id)) this.select([id]);
    if (!can('edit')) return;
    const start = this.toWorld(ev.clientX, ev.clientY);
    const ids = [...this.sel].filter((x) => this.at.has(x));
    const from = this.at.get(id)!;
    const move = (m: PointerEvent) => {
      const p = this.toWorld(m.clientX, m.clientY);
      const grid = m.altKey || !this.snapOn ? 1 : GRID;
      const dx = snap(from.x + p.x - start.x, grid) - from.x;
      const dy = snap(from.y + p.y - start.y, grid) - from.y;
      if (this.drag && this.drag.dx === dx && this.drag.dy === dy) return;
      if (!this.drag && dx === 0 && dy === 0) return;
      this.drag = { ids, dx: 0, dy: 0 };
      this.drag.dx = dx;
      this.drag.dy = dy;
      this.renderCanvas();
    };
    const up = () => {
      window.removeEventListener('pointermove', move);
      window.removeEventListener('pointerup', up);
      const d = this.drag;
      this.drag = null;
      if (d && (d.dx || d.dy)) {
        const at = new Map(this.at);
        for (const x of d.ids) {
          const p = at.get(x)!;
          at.set(x, { x: p.x - d.dx, y: p.y - d.dy });
        }
        this.change((n) => moveNodes(n, d.ids, d.dx, d.dy, (x) => at.get(x)!));
      }
    };
    window.addEventListener('pointermove', move);
    window.addEventListener('pointerup', up);
  }

  /** A rubber band from an empty place selects the nodes it touches (Shift: adds); a click there cancels a link. */
  private startBand(ev: PointerEvent): void {
    if (ev.button !== 0 || this.zp.space) return;
    this.canvas.focus();
    if (this.linkFrom) {
      this.linkFrom = null;
      this.renderCanvas();
      return;
    }
    const a = this.toWorld(ev.clientX, ev.clientY);
    const band = s('rect', { class: 'net-band', x: a.x, y: a.y, width: 0, height: 0, 'data-testid': 'net-band' });
    this.svg?.append(band);
    rubberBand(band, a, (cx, cy) => this.toWorld(cx, cy), (box) => {
      const net = this.net;
      if (!net) return;
      const hit: string[] = [];
      if (box.w + box.h > 2) {
        for (const p of net.places) if (overlaps(placeBox(this.at.get(p.id)!), box)) hit.push(p.id);
        for (const t of net.transitions) if (overlaps(transitionBox(this.at.get(t.id)!), box)) hit.push(t.id);
        for (const w of net.widgets) if (overlaps(widgetBox(w, this.at.get(w.id)!), box)) hit.push(w.id);
        // the arcs between selected nodes come along (a whole diagram selected)
        const nodes = new Set(hit);
        for (const arc of net.arcs) if (nodes.has(arc.source) && nodes.has(arc.target)) hit.push(arc.id);
      }
      this.select(hit, ev.shiftKey);
    });
  }

  // ---- properties --------------------------------------------------------

  private tagNames(filter?: (type: string, writable: boolean) => boolean): string[] {
    const out: string[] = [];
    for (const t of this.ctx.tags.list) {
      if (!filter || filter(t.type, t.access === 'readwrite')) out.push(t.name);
      for (const m of membersOf(t.type)) if (!filter || filter(m.type, m.writable)) out.push(`${t.name}.${m.name}`);
    }
    return out;
  }

  private renderProps(): void {
    clear(this.propsEl);
    clear(this.datalists);
    const net = this.net;
    if (!net) return;
    const all = this.tagNames();
    const known = new Set(all.map((x) => x.toUpperCase()));
    const lists = `net-tags-${this.id}`;
    this.datalists.append(
      h('datalist', { id: lists }, all.map((n) => h('option', { value: n }))),
      h('datalist', { id: `${lists}-bool` }, this.tagNames((type, w) => type === 'BOOL' && w).map((n) => h('option', { value: n }))));
    const editable = can('edit');
    const field = (label: string, testid: string, value: string | number, set: (v: string) => void, attrs: Record<string, unknown> = {}) => {
      const input = h('input', { value: String(value), 'data-testid': `net-prop-${testid}`, disabled: !editable, title: why('edit'), ...attrs });
      input.addEventListener('change', () => set(input.value));
      input.addEventListener('keydown', (e) => e.key === 'Enter' && input.blur());
      return h('label', null, h('span', null, label), input);
    };
    const select = (label: string, testid: string, value: string, options: readonly string[], set: (v: string) => void) => {
      const sel = h('select', { 'data-testid': `net-prop-${testid}`, disabled: !editable, title: why('edit') },
        [...(options.includes(value) ? [] : [value]), ...options].map((o) => h('option', { value: o, selected: o === value }, o)));
      sel.onchange = () => set(sel.value);
      return h('label', null, h('span', null, label), sel);
    };
    /** A tag picker: a name that is not a tag, member or marking of the project is marked. */
    const tagField = (label: string, testid: string, value: string, set: (v: string) => void, list = lists) => {
      const l = field(label, testid, value, set, { list, placeholder: tr('Search tags…'), autocomplete: 'off' });
      const input = l.querySelector('input')!;
      const mark = () => {
        const bad = input.value !== '' && !known.has(input.value.toUpperCase());
        input.classList.toggle('invalid', bad);
        input.title = bad ? tr('{name} is not a tag of the running program', { name: input.value }) : '';
      };
      input.addEventListener('input', mark);
      mark();
      return l;
    };
    /** A guard or script: the text, and below it the text highlighted (tags, keywords, numbers, names that are not tags). */
    const code = (label: string, testid: string, value: string, multiline: boolean, set: (v: string) => void) => {
      const isTag = (n: string) => known.has(n.toUpperCase()) || n.toUpperCase().startsWith(`${netName(this.program).toUpperCase()}.`);
      const pre = h('pre', { class: 'net-code', 'data-testid': `net-prop-${testid}-hl` });
      const paint = (t: string) => {
        clear(pre);
        for (const tok of highlight(t, isTag)) pre.append(tok.kind === 'space' || tok.kind === 'op' ? tok.text : h('span', { class: `hl-${tok.kind}` }, tok.text));
      };
      const input = multiline
        ? h('textarea', { 'data-testid': `net-prop-${testid}`, rows: 6, spellcheck: 'false', disabled: !editable, title: why('edit') })
        : h('input', { 'data-testid': `net-prop-${testid}`, list: lists, spellcheck: 'false', autocomplete: 'off', disabled: !editable, title: why('edit') });
      input.value = value;
      input.addEventListener('input', () => paint(input.value));
      input.addEventListener('change', () => set(input.value));
      input.addEventListener('keydown', (e) => {
        const k = e as KeyboardEvent;
        if (k.key === 'Enter' && (!multiline || k.ctrlKey)) {
          k.preventDefault();
          input.blur();
        }
      });
      paint(value);
      return h('label', { class: 'net-code-field' }, h('span', null, label), input, pre);
    };
    const errors = this.problems();
    const problemList = (id: string) =>
      errors.has(id) ? h('ul', { class: 'inline-error', 'data-testid': 'net-prop-error' }, errors.get(id)!.map((m) => h('li', null, m))) : null;
    const sel = [...this.sel];
    if (sel.length === 0) {
      add(this.propsEl,
        h('h3', null, tr('Net')),
        field(tr('Name'), 'net-name', net.name ?? '', (v) => this.change((n) => void (n.name = v === '' ? null : v))),
        select(tr('Mode'), 'mode', net.mode, ['petri', 'normal'], (v) => this.change((n) => void (n.mode = v))),
        h('p', { class: 'hint' }, tr('S state, T transition, Shift+E expression, Shift+C condition; double-click an element, then click another, to draw an arc. Del deletes, Ctrl+Z/Y undo and redo, Ctrl+C/V copy and paste, F5 run, Shift+F5 stop, F6 one scan.')));
      return;
    }
    if (sel.length > 1) {
      this.propsEl.append(h('h3', null, tr('{n} elements selected', { n: sel.length })), h('p', { class: 'hint' }, tr('Move, copy or delete them together; Ctrl+click another element to draw an arc from each of them to it.')));
      return;
    }
    const id = sel[0];
    const ren = (v: string) => {
      let why: string | null = null;
      this.change((n) => (why = rename(n, id, v)) === null);
      if (why) this.ctx.notify(why === 'taken' ? tr('{id} is already used in this net.', { id: v }) : tr('An id is a letter or _ followed by letters, digits or _.'), 'error');
      else this.sel = new Set([v]);
    };
    const p = net.places.find((x) => x.id === id);
    const t = net.transitions.find((x) => x.id === id);
    const arc = net.arcs.find((x) => x.id === id);
    const wd = net.widgets.find((x) => x.id === id);
    const withP = <T>(f: (n: Net) => T | undefined, g: (x: T) => void) => this.change((n) => {
      const x = f(n);
      if (x === undefined) return false;
      g(x);
      return true;
    });
    /** The OPC UA servers of alba.toml ([[opcua_server]]), as the status lists them. */
    const opcua = () => (this.ctx.live.status?.connections ?? []).filter((c) => c.protocol === 'opcua');
    /**
     * A tag picker of an element's I/O (`source` read, `target` written) with
     * "Browse OPC UA…" when the project has OPC UA servers: the picked node's
     * binding line for alba.toml, for the tag in the field (docs/nets.md, "Editor").
     */
    const ioField = (k: string, value: string, set: (v: string) => void) => {
      const l = tagField(k, `prop-${k}`, value, set);
      if (opcua().length === 0) return l;
      const input = l.querySelector('input')!;
      const btn = h('button', { class: 'small', type: 'button', 'data-testid': `net-browse-opcua-${k}`, title: tr('Pick a variable of an OPC UA server: its node id and the binding line for alba.toml') }, tr('Browse OPC UA…'));
      gate(btn, 'browse');
      btn.onclick = (e) => {
        e.preventDefault();
        void openOpcuaBrowser({ connections: opcua(), tag: input.value.trim(), dir: k === 'target' ? 'out' : 'in', notify: (m, kind) => this.ctx.notify(m, kind) });
      };
      l.append(btn);
      return l;
    };
    const propFields = (kind: string, props: Record<string, string>, set: (k: string, v: string) => void) =>
      [...new Set([...(KIND_PROPS[kind] ?? []), ...Object.keys(props)])].map((k) =>
        ['source', 'target'].includes(k)
          ? ioField(k, props[k] ?? '', (v) => set(k, v))
          : field(k, `prop-${k}`, props[k] ?? '', (v) => set(k, v)));
    if (p) {
      const P = (g: (x: Place) => void) => withP((n) => n.places.find((x) => x.id === id), g);
      add(this.propsEl,
        h('h3', null, `${p.id} `, h('small', null, `(${p.kind})`)),
        problemList(id),
        field(tr('Id'), 'id', p.id, ren),
        field(tr('Name'), 'name', p.name ?? '', (v) => P((x) => (x.name = v === '' ? null : v))),
        select(tr('Kind'), 'kind', p.kind, PLACE_KINDS, (v) => P((x) => (x.kind = v))),
        field(net.mode === 'normal' ? tr('Initial token') : tr('Initial marking'), 'initial', p.initial, (v) => P((x) => (x.initial = Math.max(0, Math.floor(Number(v) || 0)))), { type: 'number', min: 0 }),
        tagField(tr('Lamp tag (BOOL, on while marked)'), 'tag', p.tag ?? '', (v) => P((x) => (x.tag = v.trim() === '' ? null : v.trim())), `${lists}-bool`),
        propFields(p.kind, p.props, (k, v) => P((x) => (v === '' ? delete x.props[k] : (x.props[k] = v)))),
        p.kind === 'expression' || p.script !== null
          ? code(tr('Script (F8; Ctrl+Enter applies)'), 'script', p.script ?? '', true, (v) => P((x) => (x.script = v)))
          : null,
        h('p', { class: 'hint' }, tr('Marking tag: {tag}', { tag: markingTag(this.program, p.id) })));
    } else if (t) {
      const T = (g: (x: Transition) => void) => withP((n) => n.transitions.find((x) => x.id === id), g);
      add(this.propsEl,
        h('h3', null, `${t.id} `, h('small', null, `(${t.kind})`)),
        problemList(id),
        field(tr('Id'), 'id', t.id, ren),
        field(tr('Name'), 'name', t.name ?? '', (v) => T((x) => (x.name = v === '' ? null : v))),
        select(tr('Kind'), 'kind', t.kind, TRANSITION_KINDS, (v) => T((x) => {
          x.kind = v;
          if (v === 'timer' && !x.props.delay) x.props.delay = 'T#1s';
        })),
        code(tr('Guard (a BOOL expression; empty: always)'), 'guard', t.guard ?? '', false, (v) => T((x) => (x.guard = v.trim() === '' ? null : v))),
        field(tr('Priority (lower first; empty: document order)'), 'priority', t.priority ?? '', (v) => T((x) => (x.priority = v.trim() === '' || !Number.isInteger(Number(v)) ? null : Number(v))), { type: 'number' }),
        propFields(t.kind, t.props, (k, v) => T((x) => (v === '' ? delete x.props[k] : (x.props[k] = v)))));
    } else if (arc) {
      const A = (g: (x: Arc) => void) => withP((n) => n.arcs.find((x) => x.id === id), g);
      add(this.propsEl,
        h('h3', null, `${arc.id} `, h('small', null, `${arc.source} → ${arc.target}`)),
        problemList(id),
        field(tr('Weight'), 'weight', arc.weight, (v) => A((x) => (x.weight = Math.max(1, Math.floor(Number(v) || 1)))), { type: 'number', min: 1 }),
        select(tr('Kind'), 'arc-kind', arc.kind, ARC_KINDS, (v) => A((x) => (x.kind = v))));
    } else if (wd) {
      const W = (g: (x: Widget) => void) => withP((n) => n.widgets.find((x) => x.id === id), g);
      add(this.propsEl,
        h('h3', null, `${wd.id} `, h('small', null, `(${wd.kind})`)),
        select(tr('Kind'), 'widget-kind', wd.kind, WIDGET_KINDS, (v) => W((x) => (x.kind = v))),
        tagField(tr('Tag'), 'widget-tag', wd.tag ?? '', (v) => W((x) => (x.tag = v.trim() === '' ? null : v.trim()))),
        field(tr('Caption'), 'widget-text', wd.text ?? '', (v) => W((x) => (x.text = v === '' ? null : v))),
        // the source's properties of the element (net/widgets.ts), kept as attributes of <widget>
        [...new Set([...(STYLE_KEYS[wd.kind] ?? []), ...Object.keys(wd.style ?? {})])].map((k) => {
          const setStyle = (v: string) => W((x) => {
            x.style = { ...(x.style ?? {}) };
            if (v.trim() === '') delete x.style[k];
            else x.style[k] = v.trim();
          });
          const choices: Record<string, readonly string[]> = {
            mode: ['', ...DISPLAY_MODES], format: ['', ...DISPLAY_FORMATS], align: ['', ...LABEL_ALIGNS],
            autoscale: ['', 'true', 'false'], show_background: ['', 'true', 'false'], border: ['', 'true', 'false'],
          };
          return choices[k] ? select(k, `widget-style-${k}`, wd.style?.[k] ?? '', choices[k], setStyle) : field(k, `widget-style-${k}`, wd.style?.[k] ?? '', setStyle);
        }));
    }
  }

  // ---- analysis ----------------------------------------------------------

  async analyse(): Promise<void> {
    if (this.analysing) return;
    const abort = new AbortController();
    this.analysisAbort = abort;
    this.analysing = true;
    this.analysisProgress = null;
    this.analysisError = null;
    this.analysisTimedOut = false;
    this.renderAnalysis();
    try {
      const r = await api.netAnalysis<Analysis>(this.program, this.symbolic, (p) => {
        this.analysisProgress = p;
        this.renderAnalysis();
      }, abort.signal);
      this.analysis = r.result;
      this.analysisTimedOut = r.timed_out;
    } catch (e) {
      this.analysis = null;
      this.analysisError = abort.signal.aborted ? tr('Analysis cancelled.') : e instanceof Error ? e.message : String(e);
    } finally {
      this.analysing = false;
      this.analysisAbort = null;
      this.replayState = null;
      this.render();
    }
  }

  /** Closes the analysis's connection: the server stops it. */
  private cancelAnalysis(): void {
    this.analysisAbort?.abort();
  }

  private startReplay(): void {
    const trace = this.analysis?.deadlock_trace;
    const net = this.savedNet;
    if (!trace || !net || !this.net) return;
    const r = replay(net, trace);
    this.replayState = { ...r, step: 0 };
    this.render();
  }

  private replayStep(d: number): void {
    const r = this.replayState;
    if (!r) return;
    r.step = Math.max(0, Math.min(r.fired.length, r.step + d));
    this.renderAnalysis();
    this.paintLive();
  }

  private renderAnalysis(): void {
    const el = this.analysisEl;
    clear(el);
    if (this.analysing) {
      const p = this.analysisProgress;
      const part: Record<string, string> = {
        state_space: tr('state space'), components: tr('liveness and reversibility'), flows: tr('flows'), invariants: tr('minimal invariants'),
      };
      return void el.append(
        h('p', { class: 'hint', 'data-testid': 'net-analysis-progress' }, p
          ? tr('Analysing… {part}: {n} states, {mb} MB', { part: part[p.part] ?? p.part, n: p.states.toLocaleString(), mb: (p.bytes / 1048576).toFixed(1) })
          : tr('Analysing…')),
        h('button', { class: 'small', 'data-testid': 'net-analysis-cancel', onclick: () => this.cancelAnalysis() }, tr('Cancel')));
    }
    if (this.analysisError) return void el.append(h('p', { class: 'inline-error', 'data-testid': 'net-analysis-error' }, this.analysisError));
    const a = this.analysis;
    if (!a) return void el.append(h('p', { class: 'hint' }, tr('Analyse explores the markings of the saved net: guards, priorities and tags are left out.')));
    const yes = (v: boolean | null) => (v === null ? tr('unknown') : v ? tr('yes') : tr('no'));
    const row = (label: string, testid: string, value: string) => h('tr', null, h('th', null, label), h('td', { 'data-testid': `net-an-${testid}` }, value));
    const light = (ids: string[]) => {
      this.lit = new Set(ids);
      this.renderCanvas();
    };
    const inv = (list: Record<string, number>[] | null, what: string, testid: string) =>
      list === null
        ? h('p', { class: 'hint' }, tr('not computed'))
        : list.length === 0
          ? h('p', { class: 'hint' }, tr('none'))
          : h('ul', { class: 'net-invariants' }, list.map((x, k) =>
            h('li', {
              'data-testid': `net-an-${testid}-${k}`, title: what,
              onmouseenter: () => light(Object.keys(x)), onmouseleave: () => light([]),
            }, Object.entries(x).map(([id, c]) => (c === 1 ? id : `${c}·${id}`)).join(' + '))));
    add(el,
      this.dirty ? h('p', { class: 'hint' }, tr('Of the saved version: save to analyse your changes.')) : null,
      h('table', { class: 'net-an-table' },
        row(tr('State space'), 'space', a.state_space !== 'complete' && a.symbolic?.status === 'complete'
          // not listed, but counted exactly by the decision diagrams
          ? tr('{n} states, counted with decision diagrams', { n: a.symbolic.states ?? '?' })
          : `${a.state_space ?? ''} · ${tr('{n} states', { n: a.states ?? '?' })}`),
        row(tr('Bounded'), 'bounded', yes(a.bounded)),
        row(tr('Safe'), 'safe', yes(a.safe)),
        row(tr('Deadlocks'), 'deadlocks', a.deadlocks === null ? tr('unknown') : String(a.deadlocks)),
        row(tr('Live'), 'live', yes(a.live)),
        row(tr('Reversible'), 'reversible', yes(a.reversible)),
        row(tr('Dead transitions'), 'dead', a.dead_transitions === null ? tr('unknown') : a.dead_transitions.length ? a.dead_transitions.join(', ') : tr('none'))),
      a.stopped ? h('p', { class: 'inline-error' }, a.stopped) : null,
      this.analysisTimedOut ? h('p', { class: 'inline-error', 'data-testid': 'net-analysis-timed-out' }, tr('The analysis ran out of time: what is not complete is unknown.')) : null,
      a.status ? h('table', { class: 'net-an-table net-an-status' },
        ([['state_space', tr('State space')], ['symbolic', tr('Decision diagrams')], ['symbolic_facts', tr('Deadlocks, liveness and reversibility from decision diagrams')], ['components', tr('Liveness and reversibility')], ['p_flows', tr('Place flows')], ['t_flows', tr('Transition flows')], ['p_invariants', tr('Place invariants')], ['t_invariants', tr('Transition invariants')]] as const)
          // the decision diagrams only when they ran (a fallback when the states did not fit)
          .filter(([k]) => a.status?.[k] !== undefined && !((k === 'symbolic' || k === 'symbolic_facts') && a.status[k] === 'skipped: not requested'))
          .map(([k, label]) => h('tr', null, h('th', null, label), h('td', { 'data-testid': `net-an-status-${k}`, class: a.status?.[k] === 'complete' ? '' : 'warn' }, statusText(a.status?.[k] ?? ''))))) : null);
    const trace = a.deadlock_trace;
    if (trace && trace.length >= 0 && a.deadlocks) {
      const r = this.replayState;
      add(el,
        h('h4', null, tr('Firing sequence to a deadlock')),
        h('ol', { class: 'net-trace', 'data-testid': 'net-trace' }, trace.map((t, k) => h('li', { class: r && r.step === k + 1 ? 'current' : r && k < r.step ? 'done' : '' }, t))),
        h('div', { class: 'net-replay' },
          h('button', { class: 'small', 'data-testid': 'net-replay', onclick: () => this.startReplay() }, r ? tr('Restart') : tr('Replay')),
          r ? h('button', { class: 'small', 'data-testid': 'net-replay-back', title: tr('Step back'), onclick: () => this.replayStep(-1) }, '◀') : null,
          r ? h('button', { class: 'small', 'data-testid': 'net-replay-next', title: tr('Fire the next transition'), onclick: () => this.replayStep(1) }, '▶') : null,
          r ? h('span', { 'data-testid': 'net-replay-step' }, tr('step {k} of {n}', { k: r.step, n: r.fired.length })) : null,
          r ? h('button', { class: 'small', 'data-testid': 'net-replay-close', onclick: () => ((this.replayState = null), this.render()) }, tr('Close')) : null),
        r && r.step === r.fired.length && r.fired.length < trace.length ? h('p', { class: 'inline-error' }, tr('The sequence stops here: the net changed since the analysis.')) : null,
        r && r.step === r.fired.length ? h('p', { class: 'hint', 'data-testid': 'net-replay-dead' }, tr('Dead marking: no transition is enabled.')) : null);
    }
    add(el,
      h('h4', null, tr('Place invariants')), inv(a.p_invariants, tr('Hover to highlight the places it covers'), 'pinv'),
      h('h4', null, tr('Transition invariants')), inv(a.t_invariants, tr('Hover to highlight the transitions it covers'), 'tinv'),
      (a.notes ?? []).map((n) => h('p', { class: 'hint' }, n)));
  }
}

/** A part's status (`complete`, `partial`, `skipped: budget` …) in the studio's language. */
function statusText(s: string): string {
  const reasons: Record<string, string> = {
    budget: tr('budget'), cancelled: tr('cancelled'), overflow: tr('overflow'), 'not requested': tr('not requested'),
    'state space incomplete': tr('state space incomplete'), unbounded: tr('unbounded'),
  };
  if (s === 'complete') return tr('complete');
  if (s === 'partial') return tr('partial');
  if (s.startsWith('skipped: ')) return tr('skipped: {why}', { why: reasons[s.slice(9)] ?? s.slice(9) });
  return s;
}
