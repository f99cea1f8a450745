// The screen designer (issue 17, item 2; a first version): a palette of the
// 30 element types (click, or drag onto the screen), elements moved by
// dragging on a 10-unit grid, a property panel (place and size, label, the
// tag an output shows, one animation, the widget's action) with tag pickers,
// undo/redo of every change (Ctrl+Z, Ctrl+Y), copy/paste (Ctrl+C, Ctrl+V),
// Delete, and Save (PUT /api/screens/{name}: the server's located errors are
// listed). The screen itself is the model: every change is a new version of
// its JSON.
import { ApiError, api } from '../api';
import type { Ctx } from '../ctx';
import { add, clear, h, s } from '../dom';
import { domain } from '../domain';
import { tr } from '../i18n';
import { type Element, type Screen, drawElement } from './render';

// What a screen may hold comes from the server (GET /api/domain `screens`), not re-typed here.
const types = () => domain().screens.elements;
const animations = () => ['', ...domain().screens.animations.map(([k]) => k)];
const actions = () => ['', ...domain().screens.actions];
const GRID = 10;
const DRAG_TYPE = 'application/x-alba-element';

const snap = (v: number) => Math.round(v / GRID) * GRID;

/** A new element of `type` centred near (x, y), with an id not used yet. */
export function newElement(screen: Screen, type: string, x: number, y: number): Element {
  const size: Record<string, [number, number]> = { tank: [120, 200], bottle: [80, 140], pipe: [100, 20], line: [100, 10], text: [160, 30], button: [120, 36], switch: [120, 36], slider: [160, 30] };
  const [w, h] = size[type] ?? [60, 60];
  let n = 1;
  while (screen.elements.some((e) => e.id === `${type}${n}`)) n++;
  return { id: `${type}${n}`, type, x: snap(x - w / 2), y: snap(y - h / 2), w, h, props: {}, animations: [] };
}

export class Designer {
  readonly el: HTMLElement;
  private screen: Screen;
  private undoStack: string[] = [];
  private redoStack: string[] = [];
  private sel: string | null = null;
  private clipboard: Element | null = null;
  private readonly canvas = h('div', { class: 'hmi-canvas', 'data-testid': 'hmi-canvas', tabindex: '0' });
  private readonly props = h('div', { class: 'hmi-props', 'data-testid': 'hmi-props' });
  private readonly problems = h('ul', { class: 'problems', 'data-testid': 'hmi-problems' });
  private svg: SVGSVGElement | null = null;

  constructor(
    private readonly ctx: Ctx,
    readonly name: string,
    screen: Screen,
    private readonly done: () => void,
  ) {
    this.screen = structuredClone(screen);
    const palette = h('div', { class: 'hmi-palette', 'data-testid': 'hmi-palette' },
      types().map(([t, what]) =>
        h('button', {
          class: 'small', 'data-testid': `hmi-add-${t}`, draggable: 'true', title: what,
          ondragstart: (e: DragEvent) => e.dataTransfer?.setData(DRAG_TYPE, t),
          onclick: () => this.add(t, this.screen.width / 2, this.screen.height / 2),
        }, t.replace(/_/g, ' '))));
    const save = h('button', { class: 'primary', 'data-testid': 'hmi-save' }, tr('Save'));
    save.onclick = () => void this.save();
    const close = h('button', { 'data-testid': 'hmi-close' }, tr('Close'));
    close.onclick = () => this.done();
    const undo = h('button', { 'data-testid': 'hmi-undo', title: tr('Undo (Ctrl+Z)') }, '↶');
    undo.onclick = () => this.undo();
    const redo = h('button', { 'data-testid': 'hmi-redo', title: tr('Redo (Ctrl+Y)') }, '↷');
    redo.onclick = () => this.redo();
    this.el = h('div', { class: 'hmi-designer', 'data-testid': 'hmi-designer' },
      h('div', { class: 'toolbar' }, h('strong', null, name), undo, redo, save, close),
      h('div', { class: 'hmi-designer-body' }, palette, this.canvas, h('aside', null, this.props, h('h3', null, tr('Problems')), this.problems)));
    this.canvas.addEventListener('dragover', (e) => e.dataTransfer?.types.includes(DRAG_TYPE) && e.preventDefault());
    this.canvas.addEventListener('drop', (e) => {
      const t = e.dataTransfer?.getData(DRAG_TYPE);
      if (!t || !this.svg) return;
      e.preventDefault();
      const p = this.toScreen(e.clientX, e.clientY);
      this.add(t, p.x, p.y);
    });
    this.canvas.addEventListener('keydown', (e) => this.onKey(e));
    this.render();
  }

  /** The screen as it is now (for tests and Save). */
  get current(): Screen {
    return this.screen;
  }

  private change(f: (s: Screen) => void): void {
    this.undoStack.push(JSON.stringify(this.screen));
    this.redoStack = [];
    f(this.screen);
    this.render();
  }

  undo(): void {
    const prev = this.undoStack.pop();
    if (prev === undefined) return;
    this.redoStack.push(JSON.stringify(this.screen));
    this.screen = JSON.parse(prev);
    this.render();
  }

  redo(): void {
    const next = this.redoStack.pop();
    if (next === undefined) return;
    this.undoStack.push(JSON.stringify(this.screen));
    this.screen = JSON.parse(next);
    this.render();
  }

  add(type: string, x: number, y: number): void {
    const e = newElement(this.screen, type, x, y);
    this.change((s) => s.elements.push(e));
    this.select(e.id);
  }

  private selected(): Element | undefined {
    return this.screen.elements.find((e) => e.id === this.sel);
  }

  private select(id: string | null): void {
    this.sel = id;
    this.render();
  }

  private toScreen(cx: number, cy: number): { x: number; y: number } {
    const pt = this.svg!.createSVGPoint();
    pt.x = cx;
    pt.y = cy;
    const m = this.svg!.getScreenCTM();
    const p = m ? pt.matrixTransform(m.inverse()) : pt;
    return { x: p.x, y: p.y };
  }

  private onKey(e: KeyboardEvent): void {
    if ((e.target as HTMLElement).closest('input,select,textarea')) return;
    const mod = e.ctrlKey || e.metaKey;
    const k = e.key.toLowerCase();
    const sel = this.selected();
    if (mod && k === 'z') this.undo();
    else if (mod && k === 'y') this.redo();
    else if (mod && k === 'c' && sel) this.clipboard = structuredClone(sel);
    else if (mod && k === 'v' && this.clipboard) {
      const copy = { ...structuredClone(this.clipboard), id: newElement(this.screen, this.clipboard.type, 0, 0).id, x: this.clipboard.x + GRID * 2, y: this.clipboard.y + GRID * 2 };
      this.change((s) => s.elements.push(copy));
      this.select(copy.id);
    } else if ((e.key === 'Delete' || e.key === 'Backspace') && sel) this.change((s) => (s.elements = s.elements.filter((x) => x !== sel)));
    else return;
    e.preventDefault();
  }

  private render(): void {
    const svg = s('svg', { class: 'hmi-screen', viewBox: `0 0 ${this.screen.width} ${this.screen.height}`, 'data-testid': 'hmi-design-svg' });
    svg.append(s('rect', { width: this.screen.width, height: this.screen.height, fill: this.screen.background ?? '#f4f5f6' }));
    for (const e of this.screen.elements) {
      const g = drawElement(e);
      if (e.id === this.sel) g.append(s('rect', { class: 'hmi-selected', x: -3, y: -3, width: e.w + 6, height: e.h + 6, fill: 'none' }));
      g.addEventListener('pointerdown', (ev) => this.startDrag(ev, e));
      svg.append(g);
    }
    svg.addEventListener('pointerdown', (ev) => ev.target === svg.firstChild && this.select(null));
    this.svg = svg;
    clear(this.canvas);
    this.canvas.append(svg);
    this.renderProps();
  }

  private startDrag(ev: PointerEvent, e: Element): void {
    ev.stopPropagation();
    if (this.sel !== e.id) this.select(e.id);
    const start = this.toScreen(ev.clientX, ev.clientY);
    const [x0, y0] = [e.x, e.y];
    let moved = false;
    const before = JSON.stringify(this.screen);
    const move = (m: PointerEvent) => {
      const p = this.toScreen(m.clientX, m.clientY);
      const el = this.selected();
      if (!el) return;
      el.x = snap(x0 + p.x - start.x);
      el.y = snap(y0 + p.y - start.y);
      moved = moved || el.x !== x0 || el.y !== y0;
      const g = this.svg?.querySelector(`[data-testid="hmi-el-${el.id}"]`);
      g?.setAttribute('transform', `translate(${el.x},${el.y}) rotate(${el.rotation ?? 0} ${el.w / 2} ${el.h / 2})`);
    };
    const up = () => {
      window.removeEventListener('pointermove', move);
      window.removeEventListener('pointerup', up);
      if (moved) {
        this.undoStack.push(before);
        this.redoStack = [];
        this.render();
      }
    };
    window.addEventListener('pointermove', move);
    window.addEventListener('pointerup', up);
  }

  private renderProps(): void {
    clear(this.props);
    const e = this.selected();
    if (!e) {
      this.props.append(h('p', { class: 'hint' }, tr('Drag an element from the palette onto the screen, or click it. Select an element to set its properties.')));
      return;
    }
    const tags = this.ctx.tags.choices('').filter(Boolean);
    const list = h('datalist', { id: 'hmi-tags' }, tags.map((t) => h('option', { value: t })));
    const field = (label: string, testid: string, value: string | number, set: (v: string) => void, attrs: Record<string, unknown> = {}) => {
      const input = h('input', { value: String(value), 'data-testid': `hmi-prop-${testid}`, ...attrs });
      input.addEventListener('change', () => set(input.value));
      return h('label', null, h('span', null, label), input);
    };
    const num = (k: 'x' | 'y' | 'w' | 'h') => field(k, k, e[k], (v) => Number.isFinite(Number(v)) && this.change(() => (e[k] = Number(v))), { type: 'number' });
    const anim = e.animations?.[0];
    const kindSel = h('select', { 'data-testid': 'hmi-prop-anim-kind' }, animations().map((k) => h('option', { value: k, selected: (anim?.kind ?? '') === k }, k || '—')));
    kindSel.onchange = () =>
      this.change(() => {
        const kind = kindSel.value;
        e.animations = kind ? [{ ...(anim ?? { tag: '' }), kind, tag: anim?.tag ?? '' }] : [];
        if (kind === 'rotate' && e.animations[0]) e.animations[0].speed = 1;
        if (kind === 'fill' && e.animations[0]) Object.assign(e.animations[0], { min: 0, max: 100, direction: 'up' });
      });
    const actSel = h('select', { 'data-testid': 'hmi-prop-action-kind' }, actions().map((k) => h('option', { value: k, selected: (e.action?.kind ?? '') === k }, k || '—')));
    actSel.onchange = () => this.change(() => (e.action = actSel.value ? { kind: actSel.value, tag: e.action?.tag ?? null } : null));
    add(
      this.props,
      list,
      h('h3', null, `${e.id} (${e.type})`),
      field(tr('Label'), 'label', String(e.props?.label ?? ''), (v) => this.change(() => (e.props = { ...e.props, label: v }))),
      num('x'), num('y'), num('w'), num('h'),
      field(tr('Shows tag'), 'shows', String(e.props?.tag ?? ''), (v) =>
        this.change(() => {
          const { tag: _old, ...rest } = e.props ?? {};
          e.props = v ? { ...rest, tag: v } : rest;
        }), { list: 'hmi-tags' }),
      h('label', null, h('span', null, tr('Animation')), kindSel),
      anim ? field(tr('Animation tag'), 'anim-tag', anim.tag, (v) => this.change(() => (anim.tag = v)), { list: 'hmi-tags' }) : null,
      anim ? field(tr('Parameters (JSON)'), 'anim-params', JSON.stringify(Object.fromEntries(Object.entries(anim).filter(([k]) => k !== 'kind' && k !== 'tag'))), (v) => {
        try {
          const p = JSON.parse(v);
          this.change(() => (e.animations = [{ kind: anim.kind, tag: anim.tag, ...p }]));
        } catch {
          this.ctx.notify(tr('Parameters (JSON)') + ': JSON?', 'error');
        }
      }) : null,
      h('label', null, h('span', null, tr('Action')), actSel),
      e.action && e.action.kind !== 'navigate' ? field(tr('Action tag'), 'action-tag', e.action.tag ?? '', (v) => this.change(() => (e.action!.tag = v)), { list: 'hmi-tags' }) : null,
    );
  }

  private async save(): Promise<void> {
    clear(this.problems);
    try {
      await api.saveScreen(this.name, this.screen);
      this.ctx.notify(tr('{name} saved', { name: this.name }));
    } catch (e) {
      if (!(e instanceof ApiError)) throw e;
      const ds = e.diagnostics.length ? e.diagnostics : [{ line: null, col: null, message: e.message }];
      ds.forEach((d, k) => this.problems.append(h('li', { class: 'problem', 'data-testid': `hmi-problem-${k}` }, d.line === null ? d.message : `${d.line}:${d.col} ${d.message}`)));
      this.ctx.notify(tr('{name} not saved: {m}', { name: this.name, m: e.message }), 'error');
    }
  }
}
