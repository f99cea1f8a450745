// The screen designer (issue 17, item 2). The palette holds the element
// types the server accepts and the user's own symbols (click, or drag onto
// the screen). On the canvas: click selects (a group as a whole), Shift+click
// adds, a rubber band selects what it touches; dragging moves the selection
// on a 10-unit grid (Alt: free). Toolbar and keys: undo/redo (Ctrl+Z,
// Ctrl+Y), copy/cut/paste/duplicate (Ctrl+C/X/V/D), Delete, select all
// (Ctrl+A), nudge (arrows; Shift: 1 unit), group (Ctrl+G) and ungroup
// (Ctrl+Shift+G), bring to front / send to back (Ctrl+] / Ctrl+[), align
// and distribute, zoom (Ctrl+wheel, + / - / 0 to fit) and pan (scroll, or drag
// with the middle button or Space held). The property panel edits one
// element: place, size, rotation, label, the tag it shows, any number of
// animations, the widget's action (tag pickers list the program's tags and
// members, and mark a name that is not one). Every change is checked by the
// server a moment later (POST /api/screens/{name}/check, issue 30, item 18):
// its located problems are listed and drawn on their elements, and go as soon
// as they are fixed. Save (Ctrl+S) is a PUT of the screen, with the same
// problems when refused. The screen's JSON is the model: every change is a
// new version.
//
// Issue 35: a selected polygon or line shows a handle per vertex (drag; Alt
// free; double-click an edge to insert; right-click or Delete to remove), and
// Draw polygon / Draw line take a vertex per click (double-click or Enter
// ends) — vertices.ts. Upload image PUTs a file to /api/assets and shows it.
// Several selected elements share a form of what they have in common
// (multi.ts). Rulers with guides to snap to (guides.ts) and the cursor's x/y
// in the status line. A symbol whose tags share a first name is a template:
// its instances are rebuilt when it changes (templates.ts).
import { ApiError, api } from '../api';
import { can } from '../auth';
import type { Diagnostic } from '../types';
import type { Ctx } from '../ctx';
import { add, clear, dragScroll, h, rubberBand, s } from '../dom';
import { domain, membersOf } from '../domain';
import { tr } from '../i18n';
import {
  type Align, GRID, align, animationDefaults, copies, distribute, elementOf, freshId, group, newElement, overlaps, restack,
  snap, symbolOf, ungroup, withGroups,
} from './edit';
import { type Element, type Screen, drawElement, place } from './render';
import { animationForm, animationPreview, paramForm, propsOf } from './animform';
import { type Pt, MAX_POINTS, edges, fromPoints, hasVertices, insertVertex, pointsOf, removeVertex, setPoints } from './vertices';
import { commonParams, commonValues, setAll } from './multi';
import { type Instance, instancesOf, instantiate, isPrefix, prefixOf, rebuild, rebuildAll } from './templates';
import { type Guides, loadGuides, saveGuides, snapPoint, snapToGuides, ticks } from './guides';

// What a screen may hold comes from the server (GET /api/domain `screens`), not re-typed here.
const types = () => domain().screens.elements;
const animationKinds = () => domain().screens.animations.map((a) => a.kind);
const actions = () => ['', ...domain().screens.actions];
const DRAG_TYPE = 'application/x-alba-element';
const SYMBOL_TYPE = 'application/x-alba-symbol';
/** The rulers' breadth, in screen units (drawn left of and above the screen). */
const RULER = 24;
const ZOOMS = [0.25, 0.33, 0.5, 0.67, 0.75, 0.9, 1, 1.25, 1.5, 2, 3, 4];

export class Designer {
  readonly el: HTMLElement;
  private screen: Screen;
  private undoStack: string[] = [];
  private redoStack: string[] = [];
  private sel = new Set<string>();
  private clipboard: Element[] = [];
  private zoom = 1;
  /** Problems of the last check or refused save, by element id. */
  private errors = new Map<string, string>();
  private checkTimer: ReturnType<typeof setTimeout> | null = null;
  /** Counts checks and saves: an answer to an older one is dropped. */
  private checkSeq = 0;
  private screens: string[] = [];
  /** The project's images (GET /api/assets), offered in an image's form. */
  private assets: string[] = [];
  private readonly canvas = h('div', { class: 'hmi-canvas', 'data-testid': 'hmi-canvas', tabindex: '0' });
  private readonly props = h('div', { class: 'hmi-props', 'data-testid': 'hmi-props' });
  private readonly problems = h('ul', { class: 'problems', 'data-testid': 'hmi-problems' });
  private readonly mine = h('div', { class: 'hmi-symbols', 'data-testid': 'hmi-my-symbols' });
  private readonly zoomLabel = h('span', { class: 'hmi-zoom', 'data-testid': 'hmi-zoom' });
  private readonly status = h('span', { class: 'hmi-status', 'data-testid': 'hmi-status' });
  private readonly upload = h('input', { type: 'file', accept: 'image/png,image/jpeg,image/gif,.png,.jpg,.jpeg,.gif', hidden: true, 'data-testid': 'hmi-upload-file' });
  private svg: SVGSVGElement | null = null;
  private space = false;
  /** The vertex of the selected polygon or line last grabbed (Delete removes it). */
  private vertex: number | null = null;
  /** A polygon or a line being drawn by its vertices (screen units). */
  private drawing: { type: string; pts: Pt[] } | null = null;
  /** Rulers shown (with the guides, which elements snap to); remembered in the browser. */
  private rulers = localStorage.getItem('alba.hmi.rulers') === '1';
  /** Where the rulers are pinned while the screen is scrolled (screen units; `pinRulers`). */
  private rulerAt = { x: 0, y: 0 };
  private guides: Guides;

  constructor(
    private readonly ctx: Ctx,
    readonly name: string,
    screen: Screen,
    private readonly done: () => void,
  ) {
    this.screen = structuredClone(screen);
    this.guides = loadGuides(name);
    const palette = h('div', { class: 'hmi-palette', 'data-testid': 'hmi-palette' },
      types().map(([t, what]) =>
        h('button', {
          class: 'small', 'data-testid': `hmi-add-${t}`, draggable: 'true', title: what,
          ondragstart: (e: DragEvent) => e.dataTransfer?.setData(DRAG_TYPE, t),
          onclick: () => this.add(t, this.screen.width / 2, this.screen.height / 2),
        }, t.replace(/_/g, ' '))),
      h('h4', null, tr('My symbols')), this.mine);
    const button = (testid: string, label: string, title: string, f: () => void) => {
      const b = h('button', { class: 'small', 'data-testid': `hmi-${testid}`, title }, label);
      b.onclick = () => {
        f();
        this.canvas.focus();
      };
      return b;
    };
    const aligns: [Align, string, string][] = [
      ['left', '⇤', tr('Align left edges')], ['center', '↔', tr('Align centres horizontally')], ['right', '⇥', tr('Align right edges')],
      ['top', '⤒', tr('Align top edges')], ['middle', '↕', tr('Align centres vertically')], ['bottom', '⤓', tr('Align bottom edges')],
    ];
    this.el = h('div', { class: 'hmi-designer', 'data-testid': 'hmi-designer' },
      h('div', { class: 'toolbar' },
        h('strong', null, name),
        button('undo', '↶', tr('Undo (Ctrl+Z)'), () => this.undo()),
        button('redo', '↷', tr('Redo (Ctrl+Y)'), () => this.redo()),
        h('span', { class: 'sep' }),
        aligns.map(([how, label, title]) => button(`align-${how}`, label, title, () => this.onSelection((els) => align(els, how), 2))),
        button('distribute-h', '⋯', tr('Distribute horizontally'), () => this.onSelection((els) => distribute(els, 'h'), 3)),
        button('distribute-v', '⋮', tr('Distribute vertically'), () => this.onSelection((els) => distribute(els, 'v'), 3)),
        h('span', { class: 'sep' }),
        button('group', tr('Group'), tr('Group (Ctrl+G)'), () => this.group()),
        button('ungroup', tr('Ungroup'), tr('Ungroup (Ctrl+Shift+G)'), () => this.ungroup()),
        button('front', tr('To front'), tr('Bring to front (Ctrl+])'), () => this.restack('front')),
        button('back', tr('To back'), tr('Send to back (Ctrl+[)'), () => this.restack('back')),
        button('save-symbol', tr('Save as symbol'), tr('Save the selection as a symbol of your own'), () => void this.saveSymbol()),
        h('span', { class: 'sep' }),
        button('draw-polygon', tr('Draw polygon'), tr('Click each vertex, double-click or Enter to finish (Escape: cancel)'), () => this.startDrawing('polygon')),
        button('draw-line', tr('Draw line'), tr('Click each point, double-click or Enter to finish (Escape: cancel)'), () => this.startDrawing('line')),
        button('upload-image', tr('Upload image'), tr('Upload a PNG, JPEG or GIF into the project and show it (on the selected image, or a new one)'), () => this.upload.click()),
        this.upload,
        h('span', { class: 'sep' }),
        button('rulers', tr('Rulers'), tr('Rulers and guides: drag a guide out of a ruler, back onto it to remove it'), () => {
          this.rulers = !this.rulers;
          localStorage.setItem('alba.hmi.rulers', this.rulers ? '1' : '0');
          this.render();
          this.fit();
        }),
        button('zoom-out', '−', tr('Zoom out (-)'), () => this.zoomBy(-1)),
        this.zoomLabel,
        button('zoom-in', '+', tr('Zoom in (+)'), () => this.zoomBy(1)),
        button('zoom-fit', tr('Fit'), tr('Fit the screen in the window (0)'), () => this.fit()),
        h('span', { class: 'sep' }),
        button('save', tr('Save'), tr('Save (Ctrl+S)'), () => void this.save()),
        button('close', tr('Close'), tr('Back to the running screen'), () => this.done())),
      h('div', { class: 'hmi-designer-body' }, palette, this.canvas, h('aside', null, this.props, h('h3', null, tr('Problems')), this.problems)),
      h('div', { class: 'hmi-statusline' }, this.status));
    this.upload.addEventListener('change', () => {
      const f = this.upload.files?.[0];
      this.upload.value = '';
      if (f) void this.uploadImage(f);
    });
    this.canvas.addEventListener('pointermove', (e) => {
      if (!this.svg) return;
      const p = this.toScreen(e.clientX, e.clientY);
      this.status.textContent = `x ${Math.round(p.x)}  y ${Math.round(p.y)}`;
    });
    this.el.querySelector('[data-testid="hmi-save"]')?.classList.add('primary');
    this.canvas.addEventListener('dragover', (e) => {
      if (e.dataTransfer?.types.includes(DRAG_TYPE) || e.dataTransfer?.types.includes(SYMBOL_TYPE)) e.preventDefault();
    });
    this.canvas.addEventListener('drop', (e) => {
      if (!this.svg) return;
      const p = this.toScreen(e.clientX, e.clientY);
      const t = e.dataTransfer?.getData(DRAG_TYPE);
      const sym = e.dataTransfer?.getData(SYMBOL_TYPE);
      if (t) this.add(t, p.x, p.y);
      else if (sym) void this.insertSymbol(sym, p.x, p.y);
      else return;
      e.preventDefault();
    });
    this.canvas.addEventListener('scroll', () => this.pinRulers(), { passive: true });
    this.canvas.addEventListener('keydown', (e) => this.onKey(e));
    this.canvas.addEventListener('keyup', (e) => e.key === ' ' && (this.space = false));
    this.canvas.addEventListener('wheel', (e) => {
      if (!e.ctrlKey) return;
      e.preventDefault();
      this.zoomBy(e.deltaY < 0 ? 1 : -1);
    }, { passive: false });
    this.canvas.addEventListener('pointerdown', (e) => this.maybePan(e), true);
    this.render();
    requestAnimationFrame(() => this.fit());
    void this.loadLists();
  }

  /** The screen as it is now (for tests and Save). */
  get current(): Screen {
    return this.screen;
  }

  /** The selected ids, in drawing order. */
  get selection(): string[] {
    return this.screen.elements.filter((e) => this.sel.has(e.id)).map((e) => e.id);
  }

  private async loadLists(): Promise<void> {
    const [screens, symbols, assets] = await Promise.all([api.screens().catch(() => []), api.symbols().catch(() => []), api.assets().catch(() => [])]);
    this.screens = screens;
    this.assets = assets;
    clear(this.mine);
    if (symbols.length === 0) this.mine.append(h('p', { class: 'hint' }, tr('Select elements, then Save as symbol.')));
    for (const n of symbols)
      this.mine.append(h('div', { class: 'hmi-symbol-row' },
        h('button', {
          class: 'small', 'data-testid': `hmi-symbol-${n}`, draggable: 'true',
          ondragstart: (e: DragEvent) => e.dataTransfer?.setData(SYMBOL_TYPE, n),
          onclick: () => void this.insertSymbol(n, this.screen.width / 2, this.screen.height / 2),
        }, n),
        h('button', {
          class: 'small', 'data-testid': `hmi-instance-${n}`, title: tr('Insert as an instance of this template: its tags under a prefix of your own, updated when the template changes'),
          onclick: () => void this.insertInstance(n),
        }, `+ ${tr('instance')}`)));
    this.renderProps();
    await this.refreshInstances();
  }

  private change(f: (s: Screen) => void): void {
    this.undoStack.push(JSON.stringify(this.screen));
    this.redoStack = [];
    f(this.screen);
    this.render();
    this.scheduleCheck();
  }

  /** Checks the screen on the server a moment after the last change (nothing is saved). */
  private scheduleCheck(): void {
    if (!can('edit')) return;
    if (this.checkTimer) clearTimeout(this.checkTimer);
    this.checkTimer = setTimeout(() => {
      this.checkTimer = null;
      void this.check();
    }, 400);
  }

  private async check(): Promise<void> {
    const seq = ++this.checkSeq;
    try {
      await api.checkScreen(this.name, this.screen);
      if (seq === this.checkSeq) this.showProblems([]);
    } catch (e) {
      // the problems of a refused screen; another failure (the link) leaves the list as it was
      if (seq === this.checkSeq && e instanceof ApiError && e.status === 422) this.showProblems(problemsOf(e));
    }
  }

  /** Lists `ds` and marks their elements (on the drawing and in the property panel), in place. */
  private showProblems(ds: Pick<Diagnostic, 'line' | 'col' | 'message'>[]): void {
    this.errors.clear();
    clear(this.problems);
    ds.forEach((d, k) => {
      const id = elementOf(d.message);
      if (id && !this.errors.has(id)) this.errors.set(id, d.message);
      const li = h('li', { class: 'problem', 'data-testid': `hmi-problem-${k}` }, d.line === null ? d.message : `${d.line}:${d.col} ${d.message}`);
      // the element alone, even in a group, to fix it
      if (id)
        li.onclick = () => {
          this.sel = new Set([id]);
          this.render();
        };
      this.problems.append(li);
    });
    this.paintErrors();
  }

  /** The red outline of each element with a problem, and the selected element's problem in the panel. */
  /** Each element's drawing by its id, found in one pass (a selector per element costs a walk of the whole screen each). */
  private drawings(): Map<string, SVGGElement> {
    const drawn = new Map<string, SVGGElement>();
    this.svg?.querySelectorAll<SVGGElement>(':scope > g.hmi-el').forEach((g) => drawn.set(g.dataset.testid!.slice('hmi-el-'.length), g));
    return drawn;
  }

  private paintErrors(): void {
    if (!this.svg) return;
    this.svg.querySelectorAll('.hmi-error-box').forEach((r) => r.remove());
    const drawn = this.drawings();
    for (const e of this.screen.elements) {
      const g = drawn.get(e.id);
      const problem = this.errors.get(e.id);
      g?.classList.toggle('hmi-error', !!problem);
      if (g && problem) g.append(s('rect', { class: 'hmi-error-box', x: -5, y: -5, width: e.w + 10, height: e.h + 10, fill: 'none', 'data-testid': `hmi-error-${e.id}` }, s('title', null, problem)));
    }
    const panel = this.props.querySelector<HTMLElement>('[data-testid="hmi-prop-error"]');
    const only = this.sel.size === 1 ? this.errors.get([...this.sel][0]) : undefined;
    if (panel) {
      panel.hidden = !only;
      panel.textContent = only ?? '';
    }
  }

  undo(): void {
    const prev = this.undoStack.pop();
    if (prev === undefined) return;
    this.redoStack.push(JSON.stringify(this.screen));
    this.screen = JSON.parse(prev);
    this.render();
    this.scheduleCheck();
  }

  redo(): void {
    const next = this.redoStack.pop();
    if (next === undefined) return;
    this.undoStack.push(JSON.stringify(this.screen));
    this.screen = JSON.parse(next);
    this.render();
    this.scheduleCheck();
  }

  add(type: string, x: number, y: number): void {
    const e = newElement(this.screen, type, x, y);
    this.change((s) => s.elements.push(e));
    this.select([e.id]);
  }

  private async insertSymbol(name: string, x: number, y: number): Promise<void> {
    let sym: Screen;
    try {
      sym = (await api.symbol(name)) as Screen;
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
      return;
    }
    const els = copies(this.screen, sym.elements, snap(x - sym.width / 2), snap(y - sym.height / 2));
    this.change((s) => {
      s.elements.push(...els);
      if (els.length > 1) group(s, new Set(els.map((e) => e.id)));
    });
    this.select(els.map((e) => e.id));
  }

  /** A template's file (a user symbol), or null with the reason told. */
  private async template(name: string): Promise<Screen | null> {
    try {
      return (await api.symbol(name)) as Screen;
    } catch (e) {
      this.ctx.notify(tr('Template {name}: {m}', { name, m: e instanceof Error ? e.message : String(e) }), 'error');
      return null;
    }
  }

  /** An instance of the template `name` in the middle of the screen, its prefix asked for. */
  private async insertInstance(name: string): Promise<void> {
    const tpl = await this.template(name);
    if (!tpl) return;
    const from = prefixOf(tpl.elements);
    if (!from) return this.ctx.notify(tr('{name} is not a template: its tags do not share a first name (Pump1 of Pump1.Running).', { name }), 'error');
    const prefix = prompt(tr('Prefix of this instance (the template uses {p}):', { p: from }), from)?.trim();
    if (!prefix) return;
    if (!isPrefix(prefix)) return this.ctx.notify(tr('{p} is not a tag name', { p: prefix }), 'error');
    const names = new Set(this.screen.elements.map((e) => e.group));
    let n = 1;
    while (names.has(`g${n}`)) n++;
    const els = instantiate(this.screen, tpl, name, prefix, snap((this.screen.width - tpl.width) / 2), snap((this.screen.height - tpl.height) / 2), `g${n}`);
    this.change((s) => s.elements.push(...els));
    this.select(els.map((e) => e.id));
    this.canvas.focus();
  }

  /** Every instance rebuilt from its template as it is now, one undoable change (told when any changed). */
  private async refreshInstances(): Promise<void> {
    const insts = instancesOf(this.screen);
    if (!insts.length) return;
    const tpls = new Map<string, Screen>();
    for (const name of new Set(insts.map((i) => i.template))) {
      const tpl = await api.symbol(name).catch(() => null);
      if (tpl) tpls.set(name, tpl as Screen);
    }
    const next = structuredClone(this.screen);
    const changed = instancesOf(next).filter((i) => tpls.has(i.template) && rebuild(next, i, tpls.get(i.template)!)).length;
    if (!changed) return;
    this.change((s) => (s.elements = next.elements));
    this.ctx.notify(tr('{n} instances updated from their templates', { n: changed }));
  }

  /** The prefix of one instance changed: rebuilt from its template. */
  private async setPrefix(inst: Instance, prefix: string): Promise<void> {
    if (!isPrefix(prefix)) return this.ctx.notify(tr('{p} is not a tag name', { p: prefix }), 'error');
    const tpl = await this.template(inst.template);
    if (!tpl) return;
    const next = structuredClone(this.screen);
    if (rebuild(next, inst, tpl, prefix)) this.change((s) => (s.elements = next.elements));
  }

  private selected(): Element[] {
    return this.screen.elements.filter((e) => this.sel.has(e.id));
  }

  select(ids: Iterable<string>, extend = false): void {
    const next = withGroups(this.screen, ids);
    this.vertex = null;
    this.sel = extend ? new Set([...this.sel, ...next]) : next;
    this.render();
  }

  /** Runs an arrangement on the selection (at least `min` elements) as one undoable change. */
  private onSelection(f: (els: Element[]) => void, min = 1): void {
    if (this.sel.size < min) {
      this.ctx.notify(tr('Select at least {n} elements.', { n: min }), 'error');
      return;
    }
    this.change(() => f(this.selected()));
  }

  private group(): void {
    if (this.sel.size < 2) return this.ctx.notify(tr('Select at least {n} elements.', { n: 2 }), 'error');
    this.change((s) => group(s, this.sel));
  }

  private ungroup(): void {
    if (this.selected().some((e) => e.group)) this.change((s) => ungroup(s, this.sel));
  }

  private restack(to: 'front' | 'back'): void {
    if (this.sel.size) this.change((s) => restack(s, this.sel, to));
  }

  private zoomBy(step: number): void {
    const k = ZOOMS.findIndex((z) => z >= this.zoom - 1e-9);
    this.setZoom(ZOOMS[Math.max(0, Math.min(ZOOMS.length - 1, (k < 0 ? ZOOMS.length - 1 : k) + step))]);
  }

  private fit(): void {
    const w = this.canvas.clientWidth - 20;
    const h = this.canvas.clientHeight - 20;
    const r = this.rulers ? RULER : 0;
    if (w > 0 && h > 0) this.setZoom(Math.max(0.1, Math.min(4, w / (this.screen.width + r), h / (this.screen.height + r))));
  }

  private setZoom(z: number): void {
    this.zoom = Math.round(z * 100) / 100;
    if (this.svg) {
      const r = this.rulers ? RULER : 0;
      this.svg.setAttribute('width', String((this.screen.width + r) * this.zoom));
      this.svg.setAttribute('height', String((this.screen.height + r) * this.zoom));
    }
    this.zoomLabel.textContent = `${Math.round(this.zoom * 100)} %`;
    this.pinRulers();
  }

  /**
   * Keeps the rulers at the canvas's top and left edges when the screen is
   * scrolled under them: each is moved by what is scrolled out of view (in
   * screen units), so they stay where the eye looks for them.
   */
  private pinRulers(): void {
    if (!this.svg || !this.rulers) return;
    const z = Math.max(this.zoom, 0.1);
    const c = this.canvas.getBoundingClientRect();
    const v = this.svg.getBoundingClientRect();
    this.rulerAt = { x: Math.max(0, c.left + this.canvas.clientLeft - v.left) / z, y: Math.max(0, c.top + this.canvas.clientTop - v.top) / z };
    this.svg.querySelector('[data-testid="hmi-ruler-top"]')?.setAttribute('transform', `translate(0 ${this.rulerAt.y})`);
    this.svg.querySelector('[data-testid="hmi-ruler-left"]')?.setAttribute('transform', `translate(${this.rulerAt.x} 0)`);
  }

  /** Panning: the middle button, or the left one with Space held, drags the canvas's scroll. */
  private maybePan(e: PointerEvent): void {
    if (e.button !== 1 && !(e.button === 0 && this.space)) return;
    dragScroll(this.canvas, e);
  }

  private toScreen(cx: number, cy: number): { x: number; y: number } {
    const pt = this.svg!.createSVGPoint();
    pt.x = cx;
    pt.y = cy;
    const m = this.svg!.getScreenCTM();
    const p = m ? pt.matrixTransform(m.inverse()) : pt;
    return { x: p.x, y: p.y };
  }

  private paste(els: Element[], offset: number): void {
    if (!els.length) return;
    const pasted = copies(this.screen, els, offset, offset);
    this.change((s) => s.elements.push(...pasted));
    this.select(pasted.map((e) => e.id));
  }

  private onKey(e: KeyboardEvent): void {
    if ((e.target as HTMLElement).closest('input,select,textarea')) return;
    const mod = e.ctrlKey || e.metaKey;
    const k = e.key.toLowerCase();
    const arrows: Record<string, [number, number]> = { arrowleft: [-1, 0], arrowright: [1, 0], arrowup: [0, -1], arrowdown: [0, 1] };
    if (this.drawing && (e.key === 'Enter' || e.key === 'Escape')) {
      if (e.key === 'Enter') this.finishDrawing();
      else this.stopDrawing();
      e.preventDefault();
      return;
    }
    const one = this.selected();
    if (e.key === ' ') this.space = true;
    else if ((e.key === 'Delete' || e.key === 'Backspace') && this.vertex !== null && one.length === 1 && hasVertices(one[0].type)) this.removeVertexAt(one[0], this.vertex);
    else if (mod && (k === 'y' || (k === 'z' && e.shiftKey))) this.redo();
    else if (mod && k === 'z') this.undo();
    else if (mod && k === 's') void this.save();
    else if (mod && k === 'a') this.select(this.screen.elements.map((x) => x.id));
    else if (mod && (k === 'c' || k === 'x') && this.sel.size) {
      this.clipboard = structuredClone(this.selected());
      if (k === 'x') this.change((s) => (s.elements = s.elements.filter((x) => !this.sel.has(x.id))));
    } else if (mod && k === 'v') this.paste(this.clipboard, GRID * 2);
    else if (mod && k === 'd') this.paste(this.selected(), GRID * 2);
    else if (mod && k === 'g') e.shiftKey ? this.ungroup() : this.group();
    else if (mod && e.key === ']') this.restack('front');
    else if (mod && e.key === '[') this.restack('back');
    else if (!mod && (e.key === '+' || e.key === '=')) this.zoomBy(1);
    else if (!mod && e.key === '-') this.zoomBy(-1);
    else if (!mod && e.key === '0') this.fit();
    else if (e.key === 'Escape') this.vertex !== null ? ((this.vertex = null), this.render()) : this.select([]);
    else if ((e.key === 'Delete' || e.key === 'Backspace') && this.sel.size) {
      this.change((s) => (s.elements = s.elements.filter((x) => !this.sel.has(x.id))));
      this.sel.clear();
      this.render();
    } else if (arrows[k] && this.sel.size) {
      const step = e.shiftKey ? 1 : GRID;
      this.change(() => this.selected().forEach((x) => ((x.x += arrows[k][0] * step), (x.y += arrows[k][1] * step))));
    } else return;
    e.preventDefault();
  }

  private render(): void {
    const r = this.rulers ? RULER : 0;
    const svg = s('svg', { class: 'hmi-design', viewBox: `${-r} ${-r} ${this.screen.width + r} ${this.screen.height + r}`, 'data-testid': 'hmi-design-svg' });
    const bg = s('rect', { width: this.screen.width, height: this.screen.height, fill: this.screen.background ?? '#f4f5f6', 'data-testid': 'hmi-background' });
    svg.append(bg);
    for (const e of this.screen.elements) svg.append(this.drawOne(e));
    bg.addEventListener('pointerdown', (ev) => this.startBand(ev));
    this.svg = svg;
    if (this.rulers) this.rulerLayer(svg);
    if (this.drawing) this.drawingLayer(svg);
    clear(this.canvas);
    this.canvas.append(svg);
    this.setZoom(this.zoom);
    this.renderProps();
    this.paintErrors();
  }

  /** One element as the designer shows it: its selection box, its animations' preview, its vertices' handles. */
  private drawOne(e: Element): SVGGElement {
    const g = drawElement(e);
    if (this.sel.has(e.id)) {
      g.classList.add('selected');
      g.append(s('rect', { class: 'hmi-selected', x: -3, y: -3, width: e.w + 6, height: e.h + 6, fill: 'none' }));
      // where its move ends and the path its rotation follows (one element selected)
      const preview = this.sel.size === 1 ? animationPreview(e, !g.querySelector('[data-part="rotor"], [data-part="needle"]')) : null;
      if (preview) g.append(preview);
      if (this.sel.size === 1 && hasVertices(e.type) && !this.drawing) this.vertexHandles(g, e);
    }
    g.addEventListener('pointerdown', (ev) => this.startDrag(ev, e));
    return g;
  }

  /** Draws `e` again in place (while a vertex is dragged). */
  private redraw(e: Element): void {
    const old = this.svg?.querySelector(`[data-testid="hmi-el-${CSS.escape(e.id)}"]`);
    old?.replaceWith(this.drawOne(e));
  }

  /** A point of the page in `g`'s own frame (the element's box, turned with it). */
  private local(g: SVGGraphicsElement, cx: number, cy: number, m = g.getScreenCTM()?.inverse()): Pt {
    const pt = this.svg!.createSVGPoint();
    pt.x = cx;
    pt.y = cy;
    const p = m ? pt.matrixTransform(m) : pt;
    return [p.x, p.y];
  }

  /** A handle per vertex (drag; right-click or Delete removes) and the edges (double-click inserts a vertex). */
  private vertexHandles(g: SVGGElement, e: Element): void {
    const pts = pointsOf(e);
    const z = Math.max(this.zoom, 0.1);
    edges(pts, e.type === 'polygon').forEach(([a, b], k) => {
      const seg = s('line', { class: 'hmi-edge', x1: a[0], y1: a[1], x2: b[0], y2: b[1], 'stroke-width': 10 / z, 'data-testid': `hmi-edge-${k}` });
      seg.addEventListener('dblclick', (ev) => {
        ev.stopPropagation();
        const [x, y] = this.snapLocal(e, this.local(g, ev.clientX, ev.clientY), ev.altKey);
        const next = insertVertex(pts, k, [x, y]);
        if (!next) return this.ctx.notify(tr('At most {n} vertices.', { n: MAX_POINTS }), 'error');
        this.change(() => setPoints(e, next));
        this.vertex = k + 1;
        this.render();
      });
      g.append(seg);
    });
    pts.forEach(([x, y], k) => {
      const c = s('circle', { class: `hmi-vertex${this.vertex === k ? ' active' : ''}`, cx: x, cy: y, r: 5 / z, 'stroke-width': 1.5 / z, 'data-testid': `hmi-vertex-${k}` });
      c.addEventListener('pointerdown', (ev) => this.dragVertex(ev, g, e, k));
      c.addEventListener('contextmenu', (ev) => {
        ev.preventDefault();
        ev.stopPropagation();
        this.removeVertexAt(e, k);
      });
      g.append(c);
    });
  }

  /** A point of `e`'s box on the screen's grid and guides (Alt: free); a turned element's points snap in its box. */
  private snapLocal(e: Element, [x, y]: Pt, free: boolean): Pt {
    const grid = free ? 1 : GRID;
    if (e.rotation) return [snap(x, grid), snap(y, grid)];
    const [sx, sy] = this.onGuides(snap(e.x + x, grid), snap(e.y + y, grid), free);
    return [sx - e.x, sy - e.y];
  }

  /** A screen point onto a guide near it (rulers shown, Alt not held). */
  private onGuides(x: number, y: number, free: boolean): Pt {
    return this.rulers && !free ? snapPoint(x, y, this.guides, 6 / Math.max(this.zoom, 0.1)) : [x, y];
  }

  private removeVertexAt(e: Element, k: number): void {
    const next = removeVertex(pointsOf(e), k, e.type);
    if (!next) return this.ctx.notify(e.type === 'polygon' ? tr('A polygon keeps at least 3 vertices.') : tr('A line keeps at least 2 points.'), 'error');
    this.vertex = null;
    this.change(() => setPoints(e, next));
  }

  /** Dragging a vertex: the element's points (and box) follow, one undoable change. */
  private dragVertex(ev: PointerEvent, g: SVGGElement, e: Element, k: number): void {
    if (ev.button !== 0) return;
    ev.stopPropagation();
    ev.preventDefault();
    this.vertex = k;
    this.canvas.focus();
    const before = JSON.stringify(this.screen);
    const m = g.getScreenCTM()?.inverse();
    const pts = pointsOf(e);
    const box = { x: e.x, y: e.y, w: e.w, h: e.h };
    let moved = false;
    const move = (mv: PointerEvent) => {
      Object.assign(e, box);
      const next = pts.slice();
      next[k] = this.snapLocal(e, this.local(g, mv.clientX, mv.clientY, m), mv.altKey);
      if (next[k][0] === pts[k][0] && next[k][1] === pts[k][1] && !moved) return;
      setPoints(e, next);
      moved = true;
      this.redraw(e);
    };
    const up = () => {
      window.removeEventListener('pointermove', move);
      window.removeEventListener('pointerup', up);
      if (moved) {
        this.undoStack.push(before);
        this.redoStack = [];
        this.scheduleCheck();
      }
      this.render();
    };
    window.addEventListener('pointermove', move);
    window.addEventListener('pointerup', up);
  }

  /** The rulers above and left of the screen (a guide is dragged out of one) and the guides across it. */
  private rulerLayer(svg: SVGSVGElement): void {
    const { width: W, height: H } = this.screen;
    const z = Math.max(this.zoom, 0.1);
    const len = { small: RULER * 0.2, mid: RULER * 0.4, big: RULER * 0.65 };
    const top = s('g', { class: 'hmi-ruler', 'data-testid': 'hmi-ruler-top' }, s('rect', { x: -RULER, y: -RULER, width: W + RULER, height: RULER }));
    for (const t of ticks(W)) {
      top.append(s('line', { x1: t.at, x2: t.at, y1: -len[t.size], y2: 0 }));
      if (t.size === 'big') top.append(s('text', { x: t.at + 2, y: -RULER + 9 }, String(t.at)));
    }
    const left = s('g', { class: 'hmi-ruler', 'data-testid': 'hmi-ruler-left' }, s('rect', { x: -RULER, y: 0, width: RULER, height: H }));
    for (const t of ticks(H)) {
      left.append(s('line', { y1: t.at, y2: t.at, x1: -len[t.size], x2: 0 }));
      if (t.size === 'big') left.append(s('text', { x: -RULER + 1, y: t.at + 9 }, String(t.at)));
    }
    top.addEventListener('pointerdown', (ev) => this.dragGuide(ev, 'h', null));
    left.addEventListener('pointerdown', (ev) => this.dragGuide(ev, 'v', null));
    svg.append(top, left);
    (['v', 'h'] as const).forEach((axis) => this.guides[axis].forEach((at, k) => svg.append(this.guideLine(axis, at, k, z))));
  }

  private guideLine(axis: 'v' | 'h', at: number, k: number, z: number): SVGGElement {
    const { width: W, height: H } = this.screen;
    const ends = axis === 'v' ? { x1: at, x2: at, y1: -RULER, y2: H } : { y1: at, y2: at, x1: -RULER, x2: W };
    const g = s('g', { class: 'hmi-guide', 'data-testid': `hmi-guide-${axis}-${k}`, 'data-at': at },
      s('line', { ...ends, class: 'hmi-guide-hit', 'stroke-width': 8 / z }), s('line', { ...ends, class: 'hmi-guide-line' }));
    g.addEventListener('pointerdown', (ev) => this.dragGuide(ev, axis, k));
    return g;
  }

  /** Drags guide `k` (or a new one out of a ruler) on the grid (Alt: free); dropped onto a ruler, it goes. */
  private dragGuide(ev: PointerEvent, axis: 'v' | 'h', k: number | null): void {
    if (ev.button !== 0 || this.space || !this.svg) return;
    ev.stopPropagation();
    ev.preventDefault();
    const list = this.guides[axis];
    const at = (m: PointerEvent) => {
      const p = this.toScreen(m.clientX, m.clientY);
      return snap(axis === 'v' ? p.x : p.y, m.altKey ? 1 : GRID);
    };
    const n = k ?? list.push(at(ev)) - 1;
    let line = this.svg.querySelector<SVGGElement>(`[data-testid="hmi-guide-${axis}-${n}"]`);
    if (!line) this.svg.append((line = this.guideLine(axis, list[n], n, Math.max(this.zoom, 0.1))));
    const move = (m: PointerEvent) => {
      list[n] = at(m);
      line!.replaceWith((line = this.guideLine(axis, list[n], n, Math.max(this.zoom, 0.1))));
      this.status.textContent = `${axis === 'v' ? 'x' : 'y'} ${list[n]}`;
    };
    const up = () => {
      window.removeEventListener('pointermove', move);
      window.removeEventListener('pointerup', up);
      // dropped onto its ruler (where it is pinned) or off the screen: it goes
      if (list[n] <= (axis === 'v' ? this.rulerAt.x : this.rulerAt.y) || list[n] >= (axis === 'v' ? this.screen.width : this.screen.height)) list.splice(n, 1);
      saveGuides(this.name, this.guides);
      this.render();
    };
    window.addEventListener('pointermove', move);
    window.addEventListener('pointerup', up);
  }

  /** The draw tool: each click a vertex (on the grid; Alt: free), double-click or Enter finishes. */
  private startDrawing(type: string): void {
    this.drawing = { type, pts: [] };
    this.sel.clear();
    this.vertex = null;
    this.render();
    this.status.textContent = type === 'polygon' ? tr('Click each vertex, double-click or Enter to finish (Escape: cancel)') : tr('Click each point, double-click or Enter to finish (Escape: cancel)');
  }

  private stopDrawing(): void {
    this.drawing = null;
    this.render();
  }

  private finishDrawing(): void {
    const d = this.drawing;
    if (!d) return;
    const e = fromPoints(freshId(this.screen, d.type), d.type, d.pts);
    if (!e) return this.ctx.notify(d.type === 'polygon' ? tr('A polygon keeps at least 3 vertices.') : tr('A line keeps at least 2 points.'), 'error');
    this.drawing = null;
    this.change((s) => s.elements.push(e));
    this.select([e.id]);
  }

  /** What the draw tool shows: the points so far and a segment to the pointer, over everything (clicks land on it). */
  private drawingLayer(svg: SVGSVGElement): void {
    const d = this.drawing!;
    const closed = d.type === 'polygon';
    const shape = s(closed ? 'polygon' : 'polyline', { class: 'hmi-draw-preview', 'data-testid': 'hmi-draw-preview', points: d.pts.map((p) => p.join(',')).join(' ') });
    const over = s('rect', { class: 'hmi-draw-overlay', 'data-testid': 'hmi-draw-overlay', width: this.screen.width, height: this.screen.height, fill: 'transparent' });
    const at = (ev: MouseEvent): Pt => {
      const p = this.toScreen(ev.clientX, ev.clientY);
      const grid = ev.altKey ? 1 : GRID;
      return this.onGuides(snap(p.x, grid), snap(p.y, grid), ev.altKey);
    };
    const show = (extra: Pt | null) => shape.setAttribute('points', [...d.pts, ...(extra ? [extra] : [])].map((p) => p.join(',')).join(' '));
    over.addEventListener('pointerdown', (ev) => {
      if (ev.button !== 0 || this.space) return;
      ev.stopPropagation();
      if (d.pts.length >= MAX_POINTS) return this.ctx.notify(tr('At most {n} vertices.', { n: MAX_POINTS }), 'error');
      d.pts.push(at(ev));
      show(null);
      this.canvas.focus();
    });
    over.addEventListener('pointermove', (ev) => show(at(ev)));
    over.addEventListener('dblclick', (ev) => {
      ev.stopPropagation();
      this.finishDrawing();
    });
    svg.append(shape, over);
  }

  /** Puts an image file into the project (PUT /api/assets/{name}) and shows it: on the one selected image, or on a new one. */
  private async uploadImage(f: File): Promise<void> {
    const name = f.name.replace(/[^A-Za-z0-9_.-]/g, '_').replace(/^\.+/, '').slice(-64);
    try {
      await api.putAsset(name, f);
    } catch (e) {
      return this.ctx.notify(tr('{name} not uploaded: {m}', { name, m: e instanceof Error ? e.message : String(e) }), 'error', 'hmi-upload');
    }
    const src = `assets/${name}`;
    if (!this.assets.includes(name)) this.assets = [...this.assets, name].sort();
    const [one] = this.selected();
    if (this.sel.size === 1 && one.type === 'image') {
      this.change(() => (one.props = { ...one.props, src }));
    } else {
      // its own size (at most the screen), centred
      let [w, h] = [160, 120];
      try {
        const bmp = await createImageBitmap(f);
        const k = Math.min(1, this.screen.width / bmp.width, this.screen.height / bmp.height);
        [w, h] = [Math.max(1, Math.round(bmp.width * k)), Math.max(1, Math.round(bmp.height * k))];
        bmp.close();
      } catch {
        /* not decodable here: the default box */
      }
      const e = newElement(this.screen, 'image', this.screen.width / 2, this.screen.height / 2);
      Object.assign(e, { w, h, x: snap((this.screen.width - w) / 2), y: snap((this.screen.height - h) / 2), props: { src } });
      this.change((s) => s.elements.push(e));
      this.select([e.id]);
    }
    this.ctx.notify(tr('{name} uploaded', { name }), 'info', 'hmi-upload');
  }

  /** An image's choice among the project's images (its `src`, `assets/<name>`), with a thumbnail of the one shown. */
  private assetPicker(e: Element): HTMLElement {
    const src = typeof e.props?.src === 'string' ? e.props.src : '';
    const pick = h('select', { 'data-testid': 'hmi-asset-pick' },
      h('option', { value: '', selected: !src }, this.assets.length ? tr('(choose an image)') : tr('(no images: Upload image)')),
      this.assets.map((n) => h('option', { value: `assets/${n}`, selected: src === `assets/${n}` }, n)));
    pick.onchange = () => pick.value && this.change(() => (e.props = { ...e.props, src: pick.value }));
    const thumb = src.startsWith('assets/') ? h('img', { class: 'hmi-asset-thumb', src: `/api/${src}`, alt: '', 'data-testid': 'hmi-asset-thumb' }) : null;
    return h('label', { class: 'hmi-asset' }, h('span', null, tr('Project image')), pick, thumb);
  }

  /** A rubber band from an empty place: selects every element it touches (Shift: adds). */
  private startBand(ev: PointerEvent): void {
    if (ev.button !== 0) return;
    const a = this.toScreen(ev.clientX, ev.clientY);
    const band = s('rect', { class: 'hmi-band', x: a.x, y: a.y, width: 0, height: 0, 'data-testid': 'hmi-band' });
    this.svg?.append(band);
    rubberBand(band, a, (cx, cy) => this.toScreen(cx, cy), (box) => {
      const hit = box.w + box.h > 2 ? this.screen.elements.filter((e) => overlaps(e, box)).map((e) => e.id) : [];
      this.select(hit, ev.shiftKey);
      this.canvas.focus();
    });
  }

  /** Dragging an element moves the whole selection, snapped to the grid (Alt: free). */
  private startDrag(ev: PointerEvent, e: Element): void {
    if (ev.button !== 0 || this.space) return;
    ev.stopPropagation();
    if (ev.shiftKey) {
      const ids = withGroups(this.screen, [e.id]);
      const drop = [...ids].every((id) => this.sel.has(id));
      this.sel = drop ? new Set([...this.sel].filter((id) => !ids.has(id))) : new Set([...this.sel, ...ids]);
      this.render();
      return;
    }
    if (!this.sel.has(e.id)) this.select([e.id]);
    this.canvas.focus();
    const start = this.toScreen(ev.clientX, ev.clientY);
    const moving = this.selected();
    const from = moving.map((x) => [x.x, x.y]);
    const before = JSON.stringify(this.screen);
    let moved = false;
    // What moves is drawn on a layer of its own, moved by the compositor: the
    // screen under it is not painted again at every move (issue 35's 60 fps
    // with 1 000 elements while 100 are dragged, docs/performance.md).
    // (made at the first move: a click, or the press of a double-click, hides nothing)
    const drawn = this.drawings();
    const gs = moving.map((x) => drawn.get(x.id));
    let layer: SVGSVGElement | null = null;
    let shown = [0, 0];
    const move = (m: PointerEvent) => {
      const p = this.toScreen(m.clientX, m.clientY);
      const grid = m.altKey ? 1 : GRID;
      const [ex, ey] = from[moving.indexOf(e)];
      // the grabbed element snaps; the others keep their offsets to it
      let dx = snap(ex + p.x - start.x, grid) - ex;
      let dy = snap(ey + p.y - start.y, grid) - ey;
      // then onto a guide near an edge or the centre of what moves
      if (this.rulers && !m.altKey && (this.guides.v.length || this.guides.h.length)) {
        const x0 = Math.min(...from.map((f) => f[0])) + dx;
        const y0 = Math.min(...from.map((f) => f[1])) + dy;
        const x1 = Math.max(...moving.map((x, k) => from[k][0] + x.w)) + dx;
        const y1 = Math.max(...moving.map((x, k) => from[k][1] + x.h)) + dy;
        const [sx, sy] = snapToGuides({ x: x0, y: y0, w: x1 - x0, h: y1 - y0 }, this.guides, 6 / Math.max(this.zoom, 0.1));
        dx += sx;
        dy += sy;
      }
      moving.forEach((x, k) => {
        x.x = from[k][0] + dx;
        x.y = from[k][1] + dy;
      });
      if (dx !== shown[0] || dy !== shown[1]) {
        shown = [dx, dy];
        const z = Math.max(this.zoom, 0.1);
        layer ??= this.dragLayer(gs);
        layer.style.transform = `translate(${dx * z}px, ${dy * z}px)`;
      }
      moved = moved || dx !== 0 || dy !== 0;
    };
    const up = () => {
      window.removeEventListener('pointermove', move);
      window.removeEventListener('pointerup', up);
      // the drawings take their places (no redraw of the whole screen)
      moving.forEach((x, k) => {
        const g = gs[k];
        if (g) {
          place(g, x);
          g.style.visibility = '';
        }
      });
      layer?.remove();
      if (moved) {
        this.undoStack.push(before);
        this.redoStack = [];
        this.renderProps();
        this.paintErrors();
      }
    };
    window.addEventListener('pointermove', move);
    window.addEventListener('pointerup', up);
  }

  /**
   * A layer over the screen with copies of `gs` (hidden meanwhile), placed
   * exactly over it: moved by a CSS transform while they are dragged.
   */
  private dragLayer(gs: (SVGGElement | undefined)[]): SVGSVGElement {
    const svg = this.svg!;
    const layer = s('svg', { class: 'hmi-drag-layer', viewBox: svg.getAttribute('viewBox'), width: svg.getAttribute('width'), height: svg.getAttribute('height'), 'aria-hidden': 'true' });
    const c = this.canvas.getBoundingClientRect();
    const v = svg.getBoundingClientRect();
    Object.assign(layer.style, {
      left: `${v.left - c.left - this.canvas.clientLeft + this.canvas.scrollLeft}px`,
      top: `${v.top - c.top - this.canvas.clientTop + this.canvas.scrollTop}px`,
    });
    for (const g of gs) {
      if (!g) continue;
      const copy = g.cloneNode(true) as SVGGElement;
      copy.removeAttribute('data-testid');
      layer.append(copy);
      g.style.visibility = 'hidden';
    }
    this.canvas.append(layer);
    return layer;
  }

  /** Every tag and member a screen can name. */
  private tagNames(): string[] {
    const out: string[] = [];
    for (const t of this.ctx.tags.list) {
      out.push(t.name);
      for (const m of membersOf(t.type)) out.push(`${t.name}.${m.name}`);
    }
    return out;
  }

  private renderProps(): void {
    clear(this.props);
    const els = this.selected();
    if (els.length === 0) {
      this.props.append(h('p', { class: 'hint' }, tr('Drag an element from the palette onto the screen, or click it. Select an element to set its properties.')));
      return;
    }
    if (els.length > 1) {
      const groups = new Set(els.map((e) => e.group ?? ''));
      // the properties they all have, with the values they agree on: a change goes to all, one undo step
      const params = commonParams(els.map((e) => propsOf(e.type)));
      const types = [...new Set(els.map((e) => e.type))];
      // one template instance: its template and its prefix
      const inst = instancesOf(this.screen).find((i) => groups.size === 1 && groups.has(i.group));
      if (inst) {
        const prefix = h('input', { value: inst.prefix, 'data-testid': 'hmi-instance-prefix' });
        prefix.addEventListener('change', () => void this.setPrefix(inst, prefix.value.trim()));
        this.props.append(h('h3', { 'data-testid': 'hmi-instance-of' }, tr('Instance of {name}', { name: inst.template })),
          h('label', null, h('span', null, tr('Prefix')), prefix));
      }
      this.props.append(
        h('h3', null, tr('{n} elements selected', { n: els.length })),
        h('p', { class: 'hint', 'data-testid': 'hmi-multi-types' }, types.join(', ')),
        params.length
          ? h('div', { class: 'hmi-multi' },
            h('p', { class: 'hint' }, tr('What they have in common: a value set here goes to all of them (an empty field: they differ).')),
            paramForm(params, commonValues(els, params), 'hmi-multi', (name, v) => this.change(() => setAll(els, name, v))))
          : h('p', { class: 'hint', 'data-testid': 'hmi-multi-none' }, tr('They have no property in common.')),
        h('p', { class: 'hint' }, groups.size === 1 && !groups.has('') ? tr('A group: Ungroup to edit its elements one by one.') : tr('Align, distribute, group or move them together.')));
      return;
    }
    const e = els[0];
    const known = new Set(this.tagNames());
    const list = h('datalist', { id: 'hmi-tags' }, [...known].map((t) => h('option', { value: t })));
    const field = (label: string, testid: string, value: string | number, set: (v: string) => void, attrs: Record<string, unknown> = {}) => {
      const input = h('input', { value: String(value), 'data-testid': `hmi-prop-${testid}`, ...attrs });
      input.addEventListener('change', () => set(input.value));
      return h('label', null, h('span', null, label), input);
    };
    // A tag picker: the program's tags and members to search in; a name that is not one is marked.
    const tagField = (label: string, testid: string, value: string, set: (v: string) => void) => {
      const l = field(label, testid, value, set, { list: 'hmi-tags', placeholder: tr('Search tags…'), autocomplete: 'off' });
      const input = l.querySelector('input')!;
      const mark = () => {
        const bad = input.value !== '' && !known.has(input.value);
        input.classList.toggle('invalid', bad);
        input.title = bad ? tr('{name} is not a tag of the running program', { name: input.value }) : '';
      };
      input.addEventListener('input', mark);
      mark();
      return l;
    };
    const json = (label: string, testid: string, value: unknown, set: (v: Record<string, unknown>) => void) =>
      field(label, testid, JSON.stringify(value), (v) => {
        try {
          const p = JSON.parse(v || '{}');
          if (typeof p !== 'object' || p === null || Array.isArray(p)) throw new Error();
          set(p);
        } catch {
          this.ctx.notify(tr('{what}: not a JSON object', { what: label }), 'error');
        }
      });
    const num = (k: 'x' | 'y' | 'w' | 'h' | 'rotation', label: string) =>
      field(label, k, e[k] ?? 0, (v) => Number.isFinite(Number(v)) && this.change(() => (e[k] = Number(v))), { type: 'number' });
    const { label: _l, tag: shown, ...others } = e.props ?? {};
    const anims = e.animations ?? [];
    const animRows = anims.map((a, k) => {
      const kind = h('select', { 'data-testid': `hmi-prop-anim-kind-${k}` }, animationKinds().map((x) => h('option', { value: x, selected: a.kind === x }, x)));
      kind.onchange = () => this.change(() => (anims[k] = { kind: kind.value, tag: a.tag, ...animationDefaults(kind.value) } as typeof a));
      const remove = h('button', { class: 'small', 'data-testid': `hmi-prop-anim-remove-${k}`, title: tr('Remove this animation') }, '✕');
      remove.onclick = () => this.change(() => anims.splice(k, 1));
      const { kind: _k, tag: _t, ...params } = a;
      return h('fieldset', { class: 'hmi-anim', 'data-testid': `hmi-anim-${k}` },
        h('legend', null, h('span', null, tr('Animation')), kind, remove),
        tagField(tr('Tag'), `anim-tag-${k}`, a.tag, (v) => this.change(() => (a.tag = v))),
        animationForm(a, `hmi-prop-anim-${k}`, (name, v) => this.change(() => (v === undefined ? delete a[name] : (a[name] = v)))),
        h('details', { class: 'hmi-expert' }, h('summary', null, tr('JSON (expert)')),
          json(tr('Parameters (JSON)'), `anim-params-${k}`, params, (p) => this.change(() => (anims[k] = { kind: a.kind, tag: a.tag, ...p } as typeof a)))));
    });
    const addAnim = h('select', { 'data-testid': 'hmi-prop-anim-add' }, h('option', { value: '' }, `+ ${tr('Animation')}…`), animationKinds().map((x) => h('option', { value: x }, x)));
    addAnim.onchange = () => addAnim.value && this.change(() => (e.animations = [...anims, { kind: addAnim.value, tag: '', ...animationDefaults(addAnim.value) } as (typeof anims)[0]]));
    const act = e.action;
    const actSel = h('select', { 'data-testid': 'hmi-prop-action-kind' }, actions().map((k) => h('option', { value: k, selected: (act?.kind ?? '') === k }, k || '—')));
    actSel.onchange = () => this.change(() => (e.action = actSel.value ? { kind: actSel.value, tag: actSel.value === 'navigate' ? null : act?.tag ?? null, screen: actSel.value === 'navigate' ? this.screens[0] ?? null : null } : null));
    const target = h('select', { 'data-testid': 'hmi-prop-action-screen' }, this.screens.map((n) => h('option', { value: n, selected: act?.screen === n }, n)));
    target.onchange = () => this.change(() => (e.action!.screen = target.value));
    add(
      this.props,
      list,
      h('h3', null, `${e.id} (${e.type})`, e.group ? h('small', null, ` · ${tr('group')} ${e.group}`) : null),
      h('p', { class: 'inline-error', 'data-testid': 'hmi-prop-error', hidden: true }),
      field(tr('Label'), 'label', String(e.props?.label ?? ''), (v) => this.change(() => (e.props = { ...e.props, label: v }))),
      h('div', { class: 'hmi-geom' }, num('x', 'x'), num('y', 'y'), num('w', tr('width')), num('h', tr('height')), num('rotation', tr('rotation °'))),
      tagField(tr('Shows tag'), 'shows', typeof shown === 'string' ? shown : '', (v) =>
        this.change(() => {
          const { tag: _old, ...rest } = e.props ?? {};
          e.props = v ? { ...rest, tag: v } : rest;
        })),
      paramForm(propsOf(e.type), e.props ?? {}, 'hmi-prop-el', (name, v) =>
        this.change(() => {
          const { [name]: _old, ...rest } = e.props ?? {};
          e.props = v === undefined ? rest : { ...rest, [name]: v };
        })),
      e.type === 'image' ? this.assetPicker(e) : null,
      h('details', { class: 'hmi-expert' }, h('summary', null, tr('JSON (expert)')),
        json(tr('Other properties (JSON)'), 'props', others, (p) =>
          this.change(() => (e.props = { ...p, ...(e.props?.label !== undefined ? { label: e.props.label } : {}), ...(typeof shown === 'string' ? { tag: shown } : {}) })))),
      animRows,
      h('label', null, addAnim),
      h('label', null, h('span', null, tr('Action')), actSel),
      act && act.kind !== 'navigate' ? tagField(tr('Action tag'), 'action-tag', act.tag ?? '', (v) => this.change(() => (act.tag = v))) : null,
      act?.kind === 'navigate' ? h('label', null, h('span', null, tr('Go to screen')), target) : null,
      act?.kind === 'set' ? json(tr('Value written (JSON)'), 'action-value', { value: act.value ?? true }, (p) => this.change(() => (act.value = p.value as never))) : null,
      act?.kind === 'slider' || act?.kind === 'input'
        ? h('div', { class: 'hmi-geom' },
          field(tr('min'), 'action-min', act.min ?? '', (v) => this.change(() => (act.min = v === '' ? null : Number(v))), { type: 'number' }),
          field(tr('max'), 'action-max', act.max ?? '', (v) => this.change(() => (act.max = v === '' ? null : Number(v))), { type: 'number' }))
        : null,
    );
  }

  private async saveSymbol(): Promise<void> {
    const els = this.selected();
    if (els.length === 0) return this.ctx.notify(tr('Select at least {n} elements.', { n: 1 }), 'error');
    const name = prompt(tr('Name of the symbol (letters, digits, _ and -):'))?.trim();
    if (!name) return;
    try {
      await api.saveSymbol(name, symbolOf(els));
      this.ctx.notify(tr('{name} saved', { name }));
      // the instances of it follow: on this screen, then on the other saved ones
      await this.loadLists();
      await this.updateSavedScreens(name);
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
    }
  }

  /** The instances of template `name` on the other saved screens rebuilt and those screens saved (each told if refused). */
  private async updateSavedScreens(name: string): Promise<void> {
    const tpl = (await api.symbol(name)) as Screen;
    let updated = 0;
    for (const other of this.screens.filter((n) => n !== this.name)) {
      try {
        const screen = (await api.screen(other)) as Screen;
        if (!rebuildAll(screen, name, tpl)) continue;
        await api.saveScreen(other, screen);
        updated++;
      } catch (e) {
        this.ctx.notify(tr('{name} not saved: {m}', { name: other, m: e instanceof Error ? e.message : String(e) }), 'error');
      }
    }
    if (updated) this.ctx.notify(tr('{n} saved screens updated from {name}', { n: updated, name }), 'info', 'hmi-template-screens');
  }

  private async save(): Promise<void> {
    const seq = ++this.checkSeq;
    // one toast for the outcome of the latest save: a success replaces a failure
    const key = `hmi-save-${this.name}`;
    try {
      await api.saveScreen(this.name, this.screen);
      if (seq === this.checkSeq) this.showProblems([]);
      this.ctx.notify(tr('{name} saved', { name: this.name }), 'info', key);
    } catch (e) {
      if (!(e instanceof ApiError)) throw e;
      if (seq === this.checkSeq) this.showProblems(problemsOf(e));
      this.ctx.notify(tr('{name} not saved: {m}', { name: this.name, m: e.message }), 'error', key);
    }
  }
}

/** The located problems of a refused screen (its message alone when it has none). */
function problemsOf(e: ApiError): Pick<Diagnostic, 'line' | 'col' | 'message'>[] {
  return e.diagnostics.length ? e.diagnostics : [{ line: null, col: null, message: e.message }];
}
