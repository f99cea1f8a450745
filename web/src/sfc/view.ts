// The tab of an SFC program (.sfc, IEC 61131-3 textual form): the chart drawn
// from the text in the IEC graphical form — steps (the initial one doubled),
// transitions with their conditions, simultaneous divergences and
// convergences as double lines, a transition back to an earlier step as a
// jump arrow, and each step's action blocks (qualifier, action, time) — with
// the running chart live: active steps (`<sfc>.<step>.X`) lit with their
// action blocks (an action row is lit by its step's activity, not by its
// tag, which other steps may drive too) and their elapsed time (`.T`). The text is the model: it is
// edited in the text view (a click on an element goes to its line) through
// the shared ProgramEditor (check, online save, undo, problems, which are also
// drawn on the step or transition whose text holds them). The canvas is the
// net editor's (canvas.ts): zoom (− + Fit, the keys + − 0, Ctrl+wheel), pan
// (the middle button, or Space held), the grid; the chart's layout follows
// the text, so nodes are not dragged (docs/nets.md, "The chart in the studio").
import { ZoomPan, grid } from '../canvas';
import type { Ctx } from '../ctx';
import { add, clear, fmt, h, s } from '../dom';
import { ProgramEditor, problemTip } from '../editor/program';
import { tr } from '../i18n';
import { netName } from '../net/sim';
import { gate, why } from '../auth';
import { membersOf } from '../domain';
import { type Chart, addAction, addJoin, addLink, addParallel, addStepAfter, elementAtLine, layoutSfc, parseSfc, removeElement, setAction, setCondition } from './parse';

const QUALIFIERS = ['N', 'S', 'R', 'L', 'D', 'P', 'P1', 'P0', 'SD', 'DS', 'SL'];
/** A time literal of the language (not a word to translate). */
const TIME_EXAMPLE = 'T#1s';

const STEP_W = 90;
const STEP_H = 34;

export class SfcView {
  readonly el: HTMLElement;
  private readonly ed: ProgramEditor;
  private chart: Chart = { steps: [], transitions: [] };
  private mode: 'chart' | 'text' = 'chart';
  private active = false;
  private unlisten: (() => void)[] = [];
  private readonly canvas = h('div', { class: 'net-canvas sfc-canvas', 'data-testid': 'sfc-canvas', tabindex: '0' });
  private readonly liveEl = h('span', { class: 'net-live-state', 'data-testid': 'sfc-live-state' });
  private groups = new Map<string, SVGGElement>();
  /** The selected element: `step:<name>` or `tr:<name>`. */
  private sel: string | null = null;
  private readonly propsEl = h('div', { class: 'props net-props', 'data-testid': 'sfc-props' });
  /** Drawing with the mouse: the next click on a step ends a link from a step or a join into a transition. */
  private pending: { kind: 'link' | 'join'; from: string } | null = null;
  private readonly hintEl = h('span', { class: 'hint sfc-hint', 'data-testid': 'sfc-hint' });
  private readonly zp = new ZoomPan(this.canvas, 'sfc', tr('Fit the chart in the window (0)'));
  /** A scan of a counterexample replayed by the Verify & Test page: its values ({@link showScan}). */
  private scanShown: ((tag: string) => unknown) | null = null;

  constructor(
    private readonly ctx: Ctx,
    readonly program: string,
  ) {
    this.ed = new ProgramEditor(ctx, program, {
      loaded: () => undefined,
      textChanged: (fromTextArea) => {
        this.chart = parseSfc(this.ed.text);
        if (fromTextArea) this.renderSide();
        else this.render();
      },
      changed: () => this.render(),
    });
    const modeBtn = (m: 'chart' | 'text', label: string) => h('button', { class: 'mode', 'data-testid': `view-${m}`, onclick: () => this.setMode(m) }, label);
    this.el = h('section', { class: 'ladder-view net-view sfc-view', 'data-testid': `sfc-${program}` },
      h('div', { class: 'toolbar' },
        h('span', { class: 'seg' }, modeBtn('chart', tr('Chart')), modeBtn('text', tr('Text'))),
        h('span', { class: 'seg' },
          this.tool(`+ ${tr('Step')}`, 'sfc-add-step', tr('A new step after the selected one, and a transition to it (a second way out of a step is a selective divergence)'), () => this.addStep()),
          this.tool(`+ ${tr('Parallel')}`, 'sfc-add-parallel', tr('A new step activated together with the others by the selected transition (simultaneous divergence)'), () => this.addParallel()),
          this.tool(`${tr('Link')} →`, 'sfc-link', tr('A new transition from the selected step to the step you click next (a jump back, or a selective convergence)'), () => this.startPending('link')),
          this.tool(`${tr('Join')} ⇉`, 'sfc-join', tr('The step you click next also feeds the selected transition (simultaneous convergence)'), () => this.startPending('join')),
          this.tool(`✕ ${tr('Delete')}`, 'sfc-delete', tr('Delete the selected step (and the transitions left without a step) or transition'), () => this.deleteSelected())),
        this.zp.tools,
        this.hintEl,
        h('span', { class: 'seg' }, this.liveEl),
        this.ed.stateEl),
      h('div', { class: 'ladder-body' },
        h('div', { class: 'ladder-main' }, this.canvas, this.ed.textBox),
        h('aside', { class: 'ladder-side' },
          this.propsEl,
          h('h3', null, tr('Problems')), this.ed.problemsEl)));
    this.ed.section = this.el;
    this.el.addEventListener('keydown', (e) => {
      if (e.key === 'Escape' && this.pending) this.cancelPending();
    });
    this.canvas.addEventListener('keydown', (e) => this.onKey(e));
    this.setMode('chart');
  }

  load(): Promise<void> {
    return this.ed.load();
  }

  show(): void {
    this.active = true;
    this.unlisten.push(...this.ed.watch(() => this.paintLive()), this.ctx.live.onBatch(() => this.paintLive()), this.ctx.live.onState(() => this.paintLive()));
    this.subscribe();
    this.render();
  }

  hide(): void {
    this.active = false;
    this.unlisten.forEach((f) => f());
    this.unlisten = [];
    this.ctx.live.subscribe(`sfc:${this.program}`, null);
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

  /** The canvas's keys: zoom, Delete, Escape (nothing selected), Ctrl+Z / Ctrl+Y. */
  private onKey(e: KeyboardEvent): void {
    const mod = e.ctrlKey || e.metaKey;
    const k = e.key.toLowerCase();
    if (this.zp.key(e)) return e.preventDefault();
    if (mod && (k === 'y' || (k === 'z' && e.shiftKey))) this.ed.redo();
    else if (mod && k === 'z') this.ed.undo();
    else if (mod) return;
    else if (e.key === 'Escape' && !this.pending) this.select(null);
    else if ((e.key === 'Delete' || e.key === 'Backspace') && this.sel && !why('edit')) this.deleteSelected();
    else return;
    e.preventDefault();
  }

  private tag(step: string, member: 'X' | 'T'): string {
    return `${netName(this.program)}.${step}.${member}`;
  }

  private subscribe(): void {
    if (!this.active) return;
    const saved = parseSfc(this.ed.savedText);
    this.ctx.live.subscribe(`sfc:${this.program}`, saved.steps.flatMap((st) => [this.tag(st.name, 'X'), this.tag(st.name, 'T')]));
  }

  private setMode(m: 'chart' | 'text'): void {
    this.mode = m;
    this.el.dataset.mode = m === 'chart' ? 'graphic' : 'text';
    this.el.querySelectorAll('.toolbar button.mode').forEach((b) => b.classList.toggle('active', (b as HTMLElement).dataset.testid === `view-${m}`));
    if (m === 'text') this.ed.textEl.value = this.ed.text;
    else this.render();
  }

  private render(): void {
    if (this.active) this.subscribe();
    this.renderChart();
    this.renderSide();
    this.renderProps();
  }

  private select(id: string | null): void {
    this.sel = id;
    this.render();
  }

  /** One undoable edit of the text (the model). */
  private edit(text: string): void {
    if (text !== this.ed.text) this.ed.setText(text);
  }

  private addStep(): void {
    const from = this.sel?.startsWith('step:') ? this.sel.slice(5) : this.chart.steps[this.chart.steps.length - 1]?.name;
    if (!from) {
      this.edit(`${this.ed.text}${this.ed.text.endsWith('\n') || !this.ed.text ? '' : '\n'}INITIAL_STEP Init: END_STEP\n`);
      return this.select('step:Init');
    }
    const r = addStepAfter(this.ed.text, this.chart, from);
    this.edit(r.text);
    this.select(`step:${r.step}`);
  }

  private tool(label: string, testid: string, title: string, action: () => void): HTMLButtonElement {
    const b = h('button', { class: 'small', 'data-testid': testid, title }, label);
    b.onclick = action;
    gate(b, 'edit');
    return b;
  }

  private selected(kind: 'step' | 'tr'): string | undefined {
    return this.sel?.startsWith(`${kind}:`) ? this.sel.slice(kind.length + 1) : undefined;
  }

  private say(text: string): void {
    this.hintEl.textContent = text;
  }

  private addParallel(): void {
    const t = this.chart.transitions.find((x) => x.name === this.selected('tr'));
    if (!t) return this.say(tr('Select a transition first.'));
    const r = addParallel(this.ed.text, this.chart, t);
    this.edit(r.text);
    this.select(`step:${r.step}`);
  }

  private startPending(kind: 'link' | 'join'): void {
    const from = kind === 'link' ? this.selected('step') : this.selected('tr');
    if (!from) return this.say(kind === 'link' ? tr('Select a step first.') : tr('Select a transition first.'));
    this.pending = { kind, from };
    this.el.dataset.pending = kind;
    this.say(kind === 'link' ? tr('Click the step the new transition goes to (Escape cancels).') : tr('Click the step to join into the transition (Escape cancels).'));
  }

  private cancelPending(): void {
    this.pending = null;
    delete this.el.dataset.pending;
    this.say('');
  }

  /** A click on a step while drawing a link or a join. */
  private finishPending(step: string): void {
    const p = this.pending!;
    this.cancelPending();
    if (p.kind === 'link') {
      this.edit(addLink(this.ed.text, p.from, step));
      const added = parseSfc(this.ed.text).transitions.at(-1);
      return this.select(added ? `tr:${added.name}` : null);
    }
    const t = this.chart.transitions.find((x) => x.name === p.from);
    if (t) this.edit(addJoin(this.ed.text, t, step));
    this.select(`tr:${p.from}`);
  }

  private deleteSelected(): void {
    if (!this.sel) return this.say(tr('Select a step or a transition first.'));
    this.edit(removeElement(this.ed.text, this.chart, this.sel));
    this.select(null);
  }

  private tagNames(): string[] {
    const out: string[] = [];
    for (const t of this.ctx.tags.list) {
      out.push(t.name);
      for (const m of membersOf(t.type)) out.push(`${t.name}.${m.name}`);
    }
    return out;
  }

  /** The selected step's actions or transition's condition, edited in place in the text. */
  private renderProps(): void {
    const el = this.propsEl;
    clear(el);
    const step = this.sel?.startsWith('step:') ? this.chart.steps.find((x) => `step:${x.name}` === this.sel) : undefined;
    const t = this.sel?.startsWith('tr:') ? this.chart.transitions.find((x) => `tr:${x.name}` === this.sel) : undefined;
    const list = `sfc-tags-${this.program}`;
    const editable = !why('edit');
    const toText = (line: number) => h('button', { class: 'small', 'data-testid': 'sfc-goto-text', onclick: () => this.goTo(line) }, tr('Edit in the text'));
    el.append(h('datalist', { id: list }, this.tagNames().map((n) => h('option', { value: n }))));
    if (!step && !t) {
      el.append(h('p', { class: 'hint' }, tr('Select a step to edit its actions, or a transition to edit its condition; the text view edits the rest.')));
      return;
    }
    if (t) {
      const input = h('input', { value: t.condition, list, 'data-testid': 'sfc-prop-condition', spellcheck: 'false', disabled: !editable, title: why('edit') });
      input.addEventListener('change', () => input.value.trim() && this.edit(setCondition(this.ed.text, t, input.value)));
      input.addEventListener('keydown', (e) => e.key === 'Enter' && input.blur());
      const links = [t.from, t.to].map((x) => x.join(', ')).join(' → ');
      el.append(
        h('h3', null, `${t.name} `, h('small', null, links)),
        h('label', null, h('span', null, tr('Condition (a BOOL expression)')), input),
        toText(t.line));
      return;
    }
    const st = step!;
    const row = (a: { name: string; qualifier: string; time: string | null } | null, k: number) => {
      const q = h('select', { 'data-testid': `sfc-prop-q-${k}`, disabled: !editable }, QUALIFIERS.map((x) => h('option', { value: x, selected: x === (a?.qualifier ?? 'N') }, x)));
      const name = h('input', { value: a?.name ?? '', list, 'data-testid': `sfc-prop-action-${k}`, placeholder: tr('Action (a BOOL tag)'), disabled: !editable });
      const time = h('input', { value: a?.time ?? '', 'data-testid': `sfc-prop-time-${k}`, placeholder: TIME_EXAMPLE, disabled: !editable });
      const value = () => (name.value.trim() ? { name: name.value.trim(), qualifier: q.value, time: time.value.trim() || null } : null);
      const apply = () => {
        const v = value();
        if (a) this.edit(setAction(this.ed.text, st, k, v));
        else if (v) this.edit(addAction(this.ed.text, st, v));
      };
      const btn = a
        ? h('button', { class: 'small', 'data-testid': `sfc-prop-remove-${k}`, title: tr('Remove this action'), disabled: !editable, onclick: () => this.edit(setAction(this.ed.text, st, k, null)) }, '✕')
        : h('button', { class: 'small', 'data-testid': 'sfc-prop-add', disabled: !editable, onclick: apply }, tr('Add'));
      if (a) for (const x of [q, name, time]) x.addEventListener('change', apply);
      return h('div', { class: 'sfc-action-row' }, q, name, time, btn);
    };
    add(el,
      h('h3', null, st.name, st.initial ? h('small', null, ` (${tr('initial')})`) : null),
      h('h4', null, tr('Actions')),
      st.actions.map((a, k) => row(a, k)),
      row(null, st.actions.length),
      toText(st.line));
  }

  private renderSide(): void {
    this.ed.renderProblems([], (line, col) => {
      this.setMode('text');
      this.ed.focusText(line, col ?? 1);
    });
    this.ed.renderState();
  }

  private goTo(line: number): void {
    this.setMode('text');
    this.ed.focusText(line, 1);
  }

  private renderChart(): void {
    if (this.mode !== 'chart') return;
    clear(this.canvas);
    this.groups.clear();
    const chart = this.chart;
    const { at } = layoutSfc(chart);
    const errors = new Map<string, string[]>();
    for (const d of this.ed.mine()) {
      const id = d.line === null ? null : elementAtLine(chart, d.line);
      if (id) errors.set(id, [...(errors.get(id) ?? []), problemTip(d)]);
    }
    const pts = [...at.values()];
    const w = Math.max(900, ...pts.map((p) => p.x + 420));
    const hh = Math.max(500, ...pts.map((p) => p.y + 120));
    const sheet = grid(`sfc-grid-${this.program}`, 20, { x: 0, y: 0, w, h: hh });
    const svg = s('svg', { class: 'net-svg sfc-svg', viewBox: `0 0 ${w} ${hh}`, 'data-testid': 'sfc-svg' },
      s('defs', null, sheet.pattern, s('marker', { id: `sfc-arrow-${this.program}`, viewBox: '0 0 10 10', refX: 10, refY: 5, markerWidth: 8, markerHeight: 8, orient: 'auto' }, s('path', { d: 'M0,0 L10,5 L0,10 z', class: 'net-arrowhead' }))));
    svg.append(sheet.background);
    const stepAt = (name: string) => at.get(`step:${chart.steps.find((x) => x.name.toUpperCase() === name.toUpperCase())?.name}`);
    const line = (x1: number, y1: number, x2: number, y2: number, cls = 'sfc-link') => svg.append(s('line', { x1, y1, x2, y2, class: cls }));
    // links: step → transition → steps (double lines for simultaneous divergence and convergence)
    for (const t of chart.transitions) {
      const p = at.get(`tr:${t.name}`)!;
      const from = t.from.map(stepAt).filter((x): x is { x: number; y: number } => !!x);
      const to = t.to.map((n) => ({ n, p: stepAt(n) })).filter((x): x is { n: string; p: { x: number; y: number } } => !!x.p);
      const top = p.y - 14;
      const bottom = p.y + 14;
      if (from.length > 1) {
        const xs = [...from.map((f) => f.x), p.x];
        line(Math.min(...xs) - 10, top, Math.max(...xs) + 10, top, 'sfc-double');
        line(Math.min(...xs) - 10, top + 4, Math.max(...xs) + 10, top + 4, 'sfc-double');
        for (const f of from) line(f.x, f.y + STEP_H / 2, f.x, top);
        line(p.x, top + 4, p.x, p.y);
      } else if (from[0]) {
        const f = from[0];
        svg.append(s('polyline', { points: `${f.x},${f.y + STEP_H / 2} ${f.x},${top} ${p.x},${top} ${p.x},${p.y}`, class: 'sfc-link' }));
      }
      const down = to.filter((x) => x.p.y > p.y);
      const jumps = to.filter((x) => x.p.y <= p.y);
      if (down.length > 1) {
        const xs = [...down.map((d) => d.p.x), p.x];
        line(p.x, p.y, p.x, bottom);
        line(Math.min(...xs) - 10, bottom, Math.max(...xs) + 10, bottom, 'sfc-double');
        line(Math.min(...xs) - 10, bottom + 4, Math.max(...xs) + 10, bottom + 4, 'sfc-double');
        for (const d of down) line(d.p.x, bottom + 4, d.p.x, d.p.y - STEP_H / 2);
      } else if (down[0]) {
        const d = down[0].p;
        svg.append(s('polyline', { points: `${p.x},${p.y} ${p.x},${d.y - STEP_H / 2 - 16} ${d.x},${d.y - STEP_H / 2 - 16} ${d.x},${d.y - STEP_H / 2}`, class: 'sfc-link' }));
      }
      jumps.forEach((j, k) => {
        const y = bottom + 6 + k * 16;
        svg.append(s('line', { x1: p.x, y1: p.y, x2: p.x, y2: y + 8, class: 'sfc-link', 'marker-end': `url(#sfc-arrow-${this.program})` }),
          s('text', { class: 'sfc-jump', x: p.x + 6, y: y + 8, 'data-testid': `sfc-jump-${t.name}-${j.n}` }, j.n));
      });
    }
    for (const st of chart.steps) {
      const p = at.get(`step:${st.name}`)!;
      const id = `step:${st.name}`;
      const g = s('g', { class: `sfc-step${st.initial ? ' initial' : ''}${errors.has(id) ? ' error' : ''}${this.sel === id ? ' selected' : ''}`, transform: `translate(${p.x},${p.y})`, 'data-testid': `sfc-step-${st.name}`, 'data-active': 'false' },
        s('rect', { x: -STEP_W / 2, y: -STEP_H / 2, width: STEP_W, height: STEP_H, class: 'sfc-box' }),
        st.initial ? s('rect', { x: -STEP_W / 2 + 3, y: -STEP_H / 2 + 3, width: STEP_W - 6, height: STEP_H - 6, class: 'sfc-box-inner' }) : null,
        s('text', { class: 'net-label', 'text-anchor': 'middle', y: 4 }, st.name),
        s('text', { class: 'net-info sfc-time', x: -STEP_W / 2, y: -STEP_H / 2 - 4 }),
        errors.has(id) ? s('title', null, errors.get(id)!.join('\n')) : null);
      // the action blocks: qualifier | action | time, in a row to the right
      st.actions.forEach((a, k) => {
        const y = -STEP_H / 2 + k * 22;
        if (k === 0) g.append(s('line', { x1: STEP_W / 2, y1: 0, x2: STEP_W / 2 + 16, y2: 0, class: 'sfc-link' }));
        g.append(s('g', { class: 'sfc-action', 'data-testid': `sfc-action-${st.name}-${k}`, 'data-tag': a.name },
          s('rect', { x: STEP_W / 2 + 16, y, width: 30, height: 22, class: 'sfc-qual' }),
          s('text', { x: STEP_W / 2 + 31, y: y + 15, 'text-anchor': 'middle', class: 'sfc-qual-text' }, a.qualifier),
          s('rect', { x: STEP_W / 2 + 46, y, width: 110 + (a.time ? 50 : 0), height: 22, class: 'sfc-act' }),
          s('text', { x: STEP_W / 2 + 52, y: y + 15, class: 'sfc-act-text' }, a.name),
          a.time ? s('text', { x: STEP_W / 2 + 160, y: y + 15, class: 'sfc-act-time' }, a.time) : null));
      });
      g.addEventListener('click', (e) => {
        e.stopPropagation();
        if (this.zp.space) return;
        this.canvas.focus();
        if (this.pending) this.finishPending(st.name);
        else this.select(id);
      });
      this.groups.set(id, g);
      svg.append(g);
    }
    for (const t of chart.transitions) {
      const p = at.get(`tr:${t.name}`)!;
      const id = `tr:${t.name}`;
      const g = s('g', { class: `sfc-transition${errors.has(id) ? ' error' : ''}${this.sel === id ? ' selected' : ''}`, transform: `translate(${p.x},${p.y})`, 'data-testid': `sfc-tr-${t.name}` },
        s('rect', { x: -20, y: -8, width: 40, height: 16, class: 'net-hit' }),
        s('rect', { x: -16, y: -2, width: 32, height: 4, class: 'sfc-bar' }),
        s('text', { class: 'net-guard sfc-cond', x: 22, y: 4 }, t.condition),
        t.named || t.priority !== null ? s('text', { class: 'net-prio', x: -22, y: 4, 'text-anchor': 'end' }, `${t.named ? t.name : ''}${t.priority !== null ? ` #${t.priority}` : ''}`) : null,
        errors.has(id) ? s('title', null, errors.get(id)!.join('\n')) : null);
      g.addEventListener('click', (e) => {
        e.stopPropagation();
        if (this.zp.space) return;
        this.canvas.focus();
        if (!this.pending) this.select(id);
      });
      this.groups.set(id, g);
      svg.append(g);
    }
    // a click on the empty sheet cancels a link or join being drawn, else clears the selection
    svg.addEventListener('click', () => {
      if (this.zp.space) return;
      this.canvas.focus();
      if (this.pending) this.cancelPending();
      else if (this.sel) this.select(null);
    });
    if (!chart.steps.length) this.canvas.append(h('p', { class: 'hint sfc-empty' }, tr('No steps yet: write the chart in the Text view.')));
    this.canvas.append(svg);
    this.zp.attach(svg, w, hh);
    this.paintLive();
  }

  /**
   * Shows one scan of a replayed run (the Verify & Test page's counterexample,
   * docs/verify.md): the active steps and their time from its values of the
   * steps' `.X` and `.T` tags.
   */
  showScan(value: (tag: string) => unknown): void {
    this.scanShown = value;
    this.paintLive();
  }

  /** Active steps, their time and their action blocks: from the running program's saved text only (or a replayed scan). */
  private paintLive(): void {
    const replay = this.scanShown;
    const live = this.ed.monitoring;
    this.liveEl.textContent = replay ? tr('replay') : live ? tr('live') : this.dirty ? tr('edited — not live') : tr('not running');
    this.liveEl.dataset.state = replay ? 'replay' : live ? 'live' : 'initial';
    const get = replay ?? (live ? (tag: string) => this.ctx.live.store.get(tag) : () => undefined);
    for (const st of this.chart.steps) {
      const g = this.groups.get(`step:${st.name}`);
      if (!g) continue;
      const x = get(this.tag(st.name, 'X'));
      const t = get(this.tag(st.name, 'T'));
      const on = x === true;
      g.dataset.active = String(on);
      g.classList.toggle('active', on);
      const time = g.querySelector('.sfc-time');
      if (time) time.textContent = on && typeof t === 'number' ? `${fmt(t)} ms` : '';
      g.querySelectorAll<SVGGElement>('.sfc-action').forEach((a) => a.classList.toggle('on', on));
    }
  }
}
