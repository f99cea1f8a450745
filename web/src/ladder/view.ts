// The ladder tab of one program: graphical editor and online monitor, text
// view, palette, operand editor with the tag picker, problems list.
//
// The program text is the model. The graphical view is derived from it by
// the client parser (parse.ts); a graphical edit re-prints only the edited
// rung (print.ts) and splices it into the text. Every change is checked by
// the server (POST /api/check) and saved with PUT /api/programs/{name}.
// Element ids (the power-flow keys) come from the running program, so
// they are shown only while the text is the saved one. Loading, checking,
// saving and the problems list are the shared ProgramEditor's.
import { api } from '../api';
import { can, gate, why } from '../auth';
import type { Ctx } from '../ctx';
import { add, clear, h } from '../dom';
import { type InstructionInfo, argInfo, domain, instruction } from '../domain';
import { type Problem, ProgramEditor, problemTip } from '../editor/program';
import type { RungJson, TagUse } from '../types';
import { closeMenu, showMenu } from '../ui/menu';
import { tagMenuItems } from '../ui/tagActions';
import { type Elem, type Instr, type Path, operandLabels, operandTags, optionalAt, shapeOf, walk } from './ast';
import { type Edited, addLeg, getAt, insert, move, newInstr, remove, setInstr, wrapInBranch } from './edit';
import { type RungLayout, layoutRung, setAnnotations } from './layout';
import { attachIds, locate } from './locate';
import { type ProgramDoc, joinProgram, parseProgram } from './parse';
import { NAV_KEYS, type NavKey, navigate } from './nav';
import { printRung } from './print';
import { type RungView, pathFromEvent, renderRung } from './render';
import { tr } from '../i18n';

const ANNOTATE_KEY = 'alba.ladder.annotate';
/** What a palette button carries when dragged. */
const DRAG_TYPE = 'application/x-alba-instruction';

/** A palette button's tooltip: the signature, what it does, and why it is disabled. */
function paletteTitle(i: InstructionInfo): string {
  const signature = `${i.mnemonic}(${i.labels.join(', ')})`;
  return `${signature} — ${i.title}: ${i.doc}${can('edit') ? '' : ` (${why('edit')})`}`;
}

/** Opens the program of a use and selects its rung: the ladder views listen for this. */
function revealUse(u: TagUse): void {
  if (u.rung === null) {
    location.hash = `#/program/${u.program}`;
    return;
  }
  pendingReveal = { program: u.program, rung: u.rung };
  const target = `#/program/${u.program}`;
  if (location.hash === target) window.dispatchEvent(new Event('alba-reveal'));
  else location.hash = target;
}

/** A use to show once its program's view is shown. */
let pendingReveal: { program: string; rung: number } | null = null;

/** Rungs cut or copied (their text, comments included), shared by every ladder tab. */
let rungClipboard: string | null = null;

interface Selection {
  rung: number;
  /** Element path ("0.1.2"), or null for the rung itself. */
  path: string | null;
}

const toPath = (p: string): Path => (p === '' ? [] : p.split('.').map(Number));

/** A rung on screen: the key of what it shows, its node, and its live view and geometry when it parses. */
interface DrawnRung {
  key: string;
  box: HTMLElement;
  view: RungView | null;
  layout: RungLayout | null;
}

export class LadderView {
  readonly el: HTMLElement;
  private readonly ed: ProgramEditor;
  private doc: ProgramDoc = { rungs: [], tail: '', tailError: null };
  private serverRungs: RungJson[] = [];
  private savedDoc: { text: string; rungs: RungJson[]; doc: ProgramDoc } | null = null;
  private sel: Selection | null = null;
  private where: 'before' | 'after' = 'after';
  private group = 'bit';
  /** The rungs on screen, in order, with what they were drawn from. */
  private drawn: DrawnRung[] = [];
  /** Bumped when every rung must be drawn again (annotations shown or hidden, tag definitions changed). */
  private drawGeneration = 0;
  /** Scroll the selection into view after the next drawing (an edit, a key, a cross-reference). */
  private revealPending = false;
  private mode: 'graphic' | 'text' = 'graphic';
  private active = false;
  private unlisten: (() => void)[] = [];
  private readonly rungsEl = h('div', { class: 'rungs', 'data-testid': 'rungs', tabindex: '0', 'data-skip-target': '', role: 'application', 'aria-label': tr('Rungs: the arrows select, Shift+F10 opens the force menu') });
  private readonly propsEl = h('div', { class: 'props', 'data-testid': 'properties' });
  private readonly paletteEl = h('div', { class: 'palette', 'data-testid': 'palette' });
  private readonly datalists = h('div', { hidden: true });
  private readonly tailEl = h('div', { class: 'rung tail', 'data-testid': 'rung-tail' }, h('pre'));
  private readonly endEl: HTMLElement;

  constructor(
    private readonly ctx: Ctx,
    readonly program: string,
  ) {
    this.ed = new ProgramEditor(ctx, program, {
      loaded: (p) => (this.serverRungs = p.rungs ?? []),
      textChanged: () => this.textChanged(),
      changed: () => this.render(),
    });
    this.endEl = h('div', { class: 'end-rung' },
      h('button', { 'data-testid': 'btn-rung-append', disabled: !can('edit'), title: why('edit'), onclick: () => this.addRung(true) }, `+ ${tr('rung')}`), ` (${tr('end')})`);
    this.rungsEl.addEventListener('click', (e) => this.onClick(e));
    this.rungsEl.addEventListener('contextmenu', (e) => this.onContextMenu(e));
    this.rungsEl.addEventListener('keydown', (e) => this.onKey(e));
    // Drag from the palette: dropped on an element, it goes before or after it (by the
    // side it lands on); on a rung's empty space, into that rung as a click would put it.
    this.rungsEl.addEventListener('dragover', (e) => {
      if (can('edit') && e.dataTransfer?.types.includes(DRAG_TYPE)) e.preventDefault();
    });
    this.rungsEl.addEventListener('drop', (e) => this.onDrop(e));
    const modeBtn = (m: 'graphic' | 'text', label: string) =>
      h('button', { class: 'mode', 'data-testid': `view-${m}`, onclick: () => this.setMode(m) }, label);
    // editing needs the engineer role: the edit tools are disabled otherwise, saying why
    const tool = (label: string, testid: string, title: string, action: () => void) => {
      const b = h('button', { 'data-testid': testid, title, onclick: action }, label);
      gate(b, 'edit');
      return b;
    };
    this.el = h(
      'section',
      { class: 'ladder-view', 'data-testid': `ladder-${program}` },
      h(
        'div',
        { class: 'toolbar' },
        h('span', { class: 'seg' }, modeBtn('graphic', tr('Graphic')), modeBtn('text', tr('Text')),
          h('button', { class: 'mode', 'data-testid': 'btn-annotate', title: tr('Show the address and description of each contact and coil'), onclick: () => this.toggleAnnotations() }, tr('Descriptions'))),
        h(
          'span',
          { class: 'seg' },
          h('label', { title: tr('Where the palette inserts, relative to the selected element') }, h('span', { class: 'insert-label' }, `${tr('Insert')} `),
            h('select', {
              'data-testid': 'insert-where',
              disabled: !can('edit'),
              title: why('edit'),
              onchange: (e: Event) => (this.where = (e.target as HTMLSelectElement).value as 'before' | 'after'),
            }, h('option', { value: 'after' }, tr('after')), h('option', { value: 'before' }, tr('before')))),
        ),
        h(
          'span',
          { class: 'seg' },
          tool(tr('Branch'), 'btn-branch', tr('Put the selected element in a branch, or add a leg to the selected branch'), () => this.branch()),
          tool('◀', 'btn-move-left', tr('Move the selected element left'), () => this.moveElement(-1)),
          tool('▶', 'btn-move-right', tr('Move the selected element right'), () => this.moveElement(1)),
          tool(`✕ ${tr('Delete')}`, 'btn-delete', tr('Delete the selected element (or rung)'), () => this.deleteSelected()),
        ),
        h(
          'span',
          { class: 'seg' },
          `${tr('Rung')} `,
          tool(`+ ${tr('Add')}`, 'btn-rung-add', tr('Add a rung after the selected one'), () => this.addRung()),
          tool('▲', 'btn-rung-up', tr('Move the selected rung up'), () => this.moveRung(-1)),
          tool('▼', 'btn-rung-down', tr('Move the selected rung down'), () => this.moveRung(1)),
          tool('✕', 'btn-rung-delete', tr('Delete the selected rung'), () => this.deleteRung()),
        ),
        h(
          'span',
          { class: 'seg' },
          tool('↶', 'btn-undo', tr('Undo (Ctrl+Z)'), () => this.undo()),
          tool('↷', 'btn-redo', tr('Redo (Ctrl+Y)'), () => this.redo()),
          tool(tr('Copy'), 'btn-rung-copy', tr('Copy the selected rung (Ctrl+C)'), () => this.copyRung(false)),
          tool(tr('Cut'), 'btn-rung-cut', tr('Cut the selected rung (Ctrl+X)'), () => this.copyRung(true)),
          tool(tr('Paste'), 'btn-rung-paste', tr('Paste the rung after the selected one (Ctrl+V)'), () => this.pasteRung()),
        ),
        this.ed.stateEl,
      ),
      this.paletteEl,
      h(
        'div',
        { class: 'ladder-body' },
        h('div', { class: 'ladder-main' }, this.rungsEl, this.ed.textBox),
        h('aside', { class: 'ladder-side' }, this.propsEl, h('h3', null, tr('Problems')), this.ed.problemsEl),
      ),
      this.datalists,
    );
    this.ed.section = this.el;
    this.ed.keepsPowerWhileEdited = true;
    if (localStorage.getItem(ANNOTATE_KEY) === '1') this.toggleAnnotations(true);
    this.renderPalette();
    this.setMode('graphic');
  }

  /** Addresses and descriptions under contacts and coils: on or off for every ladder view (remembered). */
  private toggleAnnotations(on = localStorage.getItem(ANNOTATE_KEY) !== '1'): void {
    localStorage.setItem(ANNOTATE_KEY, on ? '1' : '0');
    setAnnotations(
      on
        ? (operand) => {
            const t = this.ctx.tags.resolve(operand)?.tag;
            return t ? [t.address ?? '', t.description] : [];
          }
        : null,
    );
    this.el.querySelector('[data-testid="btn-annotate"]')?.classList.toggle('active', on);
    this.drawGeneration++;
    this.render();
  }

  /** Loads the program from the server (the running version). */
  load(): Promise<void> {
    return this.ed.load();
  }

  show(): void {
    this.active = true;
    const reveal = () => {
      const p = pendingReveal;
      if (!p || p.program !== this.program) return;
      pendingReveal = null;
      // once the program is loaded (a view just made loads it)
      const go = () => (this.doc.rungs.length > p.rung ? this.reveal(p.rung) : setTimeout(go, 50));
      go();
    };
    window.addEventListener('alba-reveal', reveal);
    this.unlisten.push(() => window.removeEventListener('alba-reveal', reveal));
    reveal();
    this.unlisten.push(
      ...this.ed.watch(() => this.paintPower()),
      this.ctx.tags.onChange(() => {
        this.renderDatalists();
        // the addresses and descriptions under the elements come from the definitions
        if (localStorage.getItem(ANNOTATE_KEY) === '1') this.drawGeneration++;
        this.render();
      }),
    );
    this.ctx.live.monitor(`ladder`, [this.program]);
    this.subscribe();
    this.renderDatalists();
  }

  hide(): void {
    this.active = false;
    this.unlisten.forEach((f) => f());
    this.unlisten = [];
    this.ctx.live.monitor('ladder', null);
    this.ctx.live.subscribe('ladder', null);
    closeMenu();
  }

  get dirty(): boolean {
    return this.ed.dirty;
  }

  // ---- text and checking -------------------------------------------------

  /** Sets the text (an edit of the view); selects `select` if given. */
  private setText(text: string, select: Selection | null): void {
    if (!can('edit')) return;
    if (select !== null) {
      this.sel = select;
      this.revealPending = true;
    }
    this.ed.setText(text);
  }

  private textChanged(): void {
    this.doc = parseProgram(this.ed.text);
    if (!this.dirty) attachIds(this.doc, this.serverRungs);
    else this.keepIdsOfUnchangedRungs();
    if (this.sel && this.sel.rung >= this.doc.rungs.length) this.sel = null;
    this.render();
    if (this.active) this.subscribe();
  }

  /**
   * While the text is edited, a rung whose instructions are those of a rung of
   * the running program (same text, comments aside; matched in order) keeps
   * that rung's element ids, so its power flow stays on screen; edited and new
   * rungs have none until the edit is saved.
   */
  private keepIdsOfUnchangedRungs(): void {
    // the running program's rungs with their ids: parsed once per saved version, not per keystroke
    if (this.savedDoc?.text !== this.ed.savedText || this.savedDoc.rungs !== this.serverRungs) {
      const doc = parseProgram(this.ed.savedText);
      attachIds(doc, this.serverRungs);
      this.savedDoc = { text: this.ed.savedText, rungs: this.serverRungs, doc };
    }
    const saved = this.savedDoc.doc;
    const key = (body: string) => body.replace(/\s+/g, '');
    const pool = new Map<string, Elem[][]>();
    for (const r of saved.rungs) if (r.elements) pool.set(key(r.body), [...(pool.get(key(r.body)) ?? []), r.elements]);
    for (const r of this.doc.rungs) {
      const from = r.elements ? pool.get(key(r.body))?.shift() : undefined;
      if (!from || !r.elements) continue;
      const ids: (number | null | undefined)[] = [];
      walk(from, (e) => ids.push(e.id));
      let k = 0;
      walk(r.elements, (e) => (e.id = ids[k++] ?? null));
    }
  }

  /** POST /api/check with the current text; updates the problems. */
  check(): Promise<boolean> {
    return this.ed.check();
  }

  /** PUT /api/programs/{name} online; reloads the running version on success. */
  save(): Promise<boolean> {
    return this.ed.save();
  }

  private subscribe(): void {
    const names = new Set<string>();
    for (const r of this.doc.rungs) {
      if (!r.elements) continue;
      walk(r.elements, (e) => {
        if (e.kind !== 'instr') return;
        for (const op of operandTags(e)) {
          const ref = this.ctx.tags.resolve(op);
          if (ref) names.add(op);
        }
      });
    }
    this.ctx.live.subscribe('ladder', [...names]);
  }

  // ---- rendering ----------------------------------------------------------

  private setMode(m: 'graphic' | 'text'): void {
    this.mode = m;
    this.el.dataset.mode = m;
    this.el.querySelectorAll('button.mode').forEach((b) => b.classList.toggle('active', (b as HTMLElement).dataset.testid === `view-${m}`));
    if (m === 'text') this.ed.textEl.value = this.ed.text;
    else if (this.graphicStale) this.render();
  }

  private problemsByRung(): Map<number, Map<string, string[]>> {
    const out = new Map<number, Map<string, string[]>>();
    for (const d of this.ed.mine()) {
      if (d.line === null || d.col === null) continue;
      const at = locate(this.doc, d.line, d.col);
      if (!at) continue;
      let m = out.get(at.rung);
      if (!m) out.set(at.rung, (m = new Map()));
      const list = m.get(at.path) ?? [];
      list.push(problemTip(d));
      m.set(at.path, list);
    }
    this.doc.rungs.forEach((r, i) => {
      if (r.error) {
        let m = out.get(i);
        if (!m) out.set(i, (m = new Map()));
        if (!m.has('')) m.set('', [r.error.message]);
      }
    });
    return out;
  }

  private rendering = false;
  private graphicStale = false;

  private render(): void {
    // Removing a focused input fires blur/change, which may ask for another render.
    if (this.rendering) {
      queueMicrotask(() => this.render());
      return;
    }
    this.rendering = true;
    try {
      this.renderNow();
    } finally {
      this.rendering = false;
    }
  }

  private renderNow(): void {
    if (this.mode === 'text') {
      // the diagram is redrawn when the graphic view comes back
      this.graphicStale = true;
      this.renderProblems();
      this.ed.renderState();
      return;
    }
    this.graphicStale = false;
    // Read before anything changes: the rail follows the width the rungs have now.
    const minRail = Math.max(400, (this.rungsEl.clientWidth || 900) - 70);
    const problems = this.problemsByRung();
    const live = { watch: (n: string, cb: (v: import('../types').Json) => void) => this.ctx.live.store.watch(n, cb) };
    const forced = new Set(this.ctx.tags.forced.keys());
    // one right rail for every rung: the widest rung decides
    const layouts = this.doc.rungs.map((r) => (r.elements ? layoutRung(r.elements, r.comment.length, minRail) : null));
    const rail = Math.max(minRail, ...layouts.map((l) => l?.rail ?? 0));
    // Each rung is drawn again only when what it shows changed (its text, ids,
    // problems, selection, forces, number or the rail); the others keep their
    // nodes, so the scroll position, the pointer's target and the live values stay.
    const old = new Map(this.drawn.map((d) => [d.key, d]));
    const drawn: DrawnRung[] = this.doc.rungs.map((r, i) => {
      const selected = this.sel?.rung === i ? (this.sel.path ?? '') : null;
      const mine = problems.get(i) ?? new Map<string, string[]>();
      const ids: (number | null | undefined)[] = [];
      const uses: string[] = [];
      if (r.elements) walk(r.elements, (e) => {
        ids.push(e.id);
        if (e.kind === 'instr') uses.push(...operandTags(e).map((t) => t.toUpperCase()).filter((t) => forced.has(t)));
      });
      const key = JSON.stringify([i, r.lead + r.own, ids, [...mine], selected, uses, rail, this.drawGeneration]);
      const reuse = old.get(key);
      if (reuse) {
        old.delete(key);
        return reuse;
      }
      const box = h('div', {
        class: `rung${selected === '' ? ' selected' : ''}${problems.get(i) ? ' has-error' : ''}`,
        'data-testid': `rung-${i}`,
        'data-rung': String(i),
      });
      let view: RungView | null = null;
      let layout: RungLayout | null = null;
      if (r.elements) {
        layout = layoutRung(r.elements, r.comment.length, rail);
        view = renderRung(layout, { number: i, comment: r.comment, problems: mine, selected, forced }, live);
        box.append(view.svg);
      } else {
        box.append(
          h('div', { class: 'rung-raw' },
            h('span', { class: 'rung-number' }, String(i + 1)),
            h('pre', { title: r.error?.message ?? '' }, r.own.trimEnd()),
            h('div', { class: 'rung-raw-error' }, `${r.error?.line}:${r.error?.col} ${r.error?.message}`)),
        );
      }
      return { key, box, view, layout };
    });
    old.forEach((d) => d.view?.dispose());
    this.drawn = drawn;
    this.tailEl.hidden = !this.doc.tail.trim();
    this.tailEl.firstChild!.textContent = this.doc.tail.trimEnd();
    // Put the nodes in order, moving only what is not in place yet.
    let at = this.rungsEl.firstChild;
    for (const node of [...drawn.map((d) => d.box), this.tailEl, this.endEl]) {
      if (node === at) at = at.nextSibling;
      else this.rungsEl.insertBefore(node, at);
    }
    while (at) {
      const next = at.nextSibling;
      at.remove();
      at = next;
    }
    this.paintPower();
    this.renderProblems();
    this.renderProps();
    this.ed.renderState();
    if (this.revealPending) {
      this.revealPending = false;
      this.selectedNode()?.scrollIntoView({ block: 'nearest', inline: 'nearest' });
    }
  }

  /** The selected element (or rung) on screen. */
  private selectedNode(): Element | null {
    const sel = this.sel;
    if (!sel) return null;
    const box = this.drawn[sel.rung]?.box;
    return (sel.path === null ? box : box?.querySelector(`[data-path="${sel.path}"]`)) ?? null;
  }

  private paintPower(): void {
    const running = this.ed.live;
    this.drawn.forEach((d) => d.view?.setPower(this.ed.on, running));
  }

  private renderProblems(): void {
    // local syntax errors the server has not seen yet
    const local: Problem[] = [];
    if (this.dirty && this.ed.diagnostics.length === 0) {
      this.doc.rungs.forEach((r) => r.error && local.push({ text: r.error.message, line: r.error.line, col: r.error.col, code: 'syntax' }));
      if (this.doc.tailError) local.push({ text: this.doc.tailError.message, line: this.doc.tailError.line, col: this.doc.tailError.col, code: 'syntax' });
    }
    this.ed.renderProblems(local, (line, col) => {
      if (col === null) return;
      const at = locate(this.doc, line, col);
      if (at) this.select({ rung: at.rung, path: at.path === '' ? null : at.path }, true);
      if (this.mode === 'text') this.ed.focusText(line, col);
    });
  }

  private renderPalette(): void {
    clear(this.paletteEl);
    const { groups, instructions: instrs } = domain();
    add(
      this.paletteEl,
      h('div', { class: 'groups' },
        groups.map((g) =>
          h('button', {
            class: `group${g.name === this.group ? ' active' : ''}`,
            'data-testid': `palette-group-${g.name}`,
            onclick: () => {
              this.group = g.name;
              this.renderPalette();
            },
          }, g.title))),
      h('div', { class: 'items' },
        instrs.filter((i) => i.group === this.group).map((i) =>
          h('button', {
            class: 'instr',
            'data-testid': `palette-${i.mnemonic}`,
            disabled: !can('edit'),
            title: paletteTitle(i),
            draggable: can('edit') ? 'true' : 'false',
            ondragstart: (e: DragEvent) => e.dataTransfer?.setData(DRAG_TYPE, i.mnemonic),
            onclick: () => this.insertInstr(i),
          }, i.mnemonic))),
    );
  }

  private renderDatalists(): void {
    clear(this.datalists);
    const kinds = new Set(domain().instructions.flatMap((i) => i.args));
    for (const k of kinds) {
      this.datalists.append(h('datalist', { id: `tags-${this.program}-${k}` }, this.ctx.tags.choices(k).map((n) => h('option', { value: n }))));
    }
  }

  /** What the properties panel shows: drawn again only when it changes (a redraw would drop the focus and the typing in it). */
  private propsKey = '';

  private renderProps(): void {
    const sel = this.sel;
    const rungNow = sel ? this.doc.rungs[sel.rung] : undefined;
    const key = JSON.stringify([sel, rungNow?.lead, rungNow?.own]);
    if (key === this.propsKey) return;
    this.propsKey = key;
    clear(this.propsEl);
    if (!sel) {
      this.propsEl.append(h('p', { class: 'hint' }, tr('Click an element to select it, right-click to force or toggle its tag. Choose an instruction in the palette to insert it after (or before) the selection.')));
      return;
    }
    const rung = this.doc.rungs[sel.rung];
    if (!rung) return;
    if (sel.path === null) {
      const ta = h('textarea', { class: 'comment-input', 'data-testid': 'rung-comment-input', rows: '3', readonly: !can('edit'), title: why('edit') });
      ta.value = rung.comment.join('\n');
      this.propsEl.append(
        h('h3', null, tr('Rung {n}', { n: sel.rung + 1 })),
        h('label', null, tr('Comment')),
        ta,
        h('button', { 'data-testid': 'rung-comment-apply', disabled: !can('edit'), title: why('edit'), onclick: () => this.setComment(sel.rung, ta.value) }, tr('Apply comment')),
      );
      return;
    }
    const el = rung.elements && getAt(rung.elements, toPath(sel.path));
    if (!el) return;
    if (el.kind === 'branch') {
      this.propsEl.append(h('h3', null, tr('Branch ({n} legs)', { n: el.legs.length })), h('p', { class: 'hint' }, tr('“Branch” adds a leg.')));
      return;
    }
    const info = instruction(el.mnemonic);
    // the operands written, then the first optional one left out (a TON's time base), offered at its default
    const shown = info && el.operands.length >= info.args.length && optionalAt(el.mnemonic, el.operands.length) ? el.operands.length + 1 : el.operands.length;
    const labels = operandLabels(el.mnemonic, shown);
    const same = domain().instructions.filter((i) => info && i.args.join() === info.args.join());
    const apply = () => {
      const values = fields.map((f) => f.value);
      // an optional operand set back to its default is left out (`TON(T,5,0)`)
      while (values.length > (info?.args.length ?? 0) && values[values.length - 1] === '' && optionalAt(el.mnemonic, values.length - 1)) values.pop();
      this.setOperands(sel, values);
    };
    const fields: (HTMLInputElement | HTMLSelectElement)[] = Array.from({ length: shown }, (_, k) => {
      const op = el.operands[k] ?? '';
      const opt = optionalAt(el.mnemonic, k);
      if (opt) {
        // a choice, never a tag: the default (left out) first, then the domain's choices,
        // and a spelling the checker also takes (`0.01`) kept as written
        const choices = opt.choices.includes(op.trim()) || op.trim() === '' ? opt.choices : [...opt.choices, op.trim()];
        const select = h('select', { 'data-testid': `operand-${k}`, disabled: !can('edit'), title: why('edit'), onchange: apply },
          h('option', { value: '' }, tr('{value} (default)', { value: opt.default })),
          choices.map((c) => h('option', { value: c }, c)));
        select.value = op.trim();
        return select;
      }
      const input = h('input', {
        'data-testid': `operand-${k}`,
        value: op,
        list: info ? `tags-${this.program}-${info.args[k]}` : undefined,
        autocomplete: 'off',
        spellcheck: 'false',
        readonly: !can('edit'),
        title: why('edit'),
      });
      input.addEventListener('change', apply);
      input.addEventListener('keydown', (e) => {
        if (e.key === 'Enter') input.dispatchEvent(new Event('change'));
      });
      return input;
    });
    add(
      this.propsEl,
      h('h3', null, `${el.mnemonic}`, info ? h('small', null, ` ${info.doc}`) : null),
      same.length > 1
        ? h('label', null, `${tr('Instruction')} `,
            h('select', {
              'data-testid': 'mnemonic-select',
              disabled: !can('edit'),
              title: why('edit'),
              onchange: (e: Event) => this.setOperands(sel, el.operands, (e.target as HTMLSelectElement).value),
            }, same.map((i) => h('option', { value: i.mnemonic, selected: i.mnemonic === el.mnemonic.toUpperCase() }, i.mnemonic))))
        : null,
      // The label, then what fits in words (`a BOOL tag to write`), not the kind's internal name.
      fields.map((field, k) => {
        const doc = info ? (optionalAt(el.mnemonic, k)?.doc ?? argInfo(info.args[k] ?? '')?.doc ?? '') : '';
        return h('label', { class: 'operand-field' }, h('span', { title: doc }, labels[k], doc ? h('small', null, ` — ${doc}`) : null), field);
      }),
      this.usesPanel(operandTags(el).filter((t) => this.ctx.tags.resolve(t))),
    );
  }

  /** "Where used": a button per tag of the selected instruction; the list links to each place. */
  private usesPanel(tags: string[]): HTMLElement | null {
    if (tags.length === 0) return null;
    const list = h('ul', { class: 'uses', 'data-testid': 'uses-list' });
    const show = async (tag: string) => {
      clear(list);
      let uses;
      try {
        uses = await api.uses(tag);
      } catch (e) {
        this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
        return;
      }
      list.append(h('li', { class: 'hint' }, uses.length === 1 ? tr('{tag}: 1 use', { tag }) : tr('{tag}: {n} uses', { tag, n: uses.length })));
      uses.forEach((u, k) =>
        list.append(
          h('li', null,
            h('a', { href: `#/program/${u.program}`, 'data-testid': `use-${k}`, onclick: (e: Event) => { e.preventDefault(); revealUse(u); } },
              `${u.program}${u.rung === null ? '' : ` ${tr('rung')} ${u.rung + 1}`} · ${u.line}:${u.col}`),
            ' ', h('code', null, u.instruction), u.write ? h('span', { class: 'writes' }, ` ${tr('writes')}`) : null),
        ),
      );
    };
    return h('div', { class: 'uses-panel' },
      h('span', { class: 'label' }, `${tr('Where used')}: `),
      tags.map((t) => h('button', { class: 'small', 'data-testid': `uses-${t}`, onclick: () => void show(t) }, t)),
      list);
  }

  /** Selects rung `rung` (from 0) and scrolls to it (a cross-reference landed here). */
  reveal(rung: number): void {
    this.setMode('graphic');
    this.select({ rung, path: null }, true);
  }

  // ---- selection and events ----------------------------------------------

  /** Selects; with `scroll`, the selection is scrolled into view (a click leaves the view where it is). */
  private select(sel: Selection | null, scroll = false): void {
    this.sel = sel;
    this.revealPending = scroll;
    this.render();
  }

  private targetOf(e: Event): Selection | null {
    const rungEl = (e.target as Element).closest?.('[data-rung]');
    if (!rungEl) return null;
    const rung = Number(rungEl.getAttribute('data-rung'));
    return { rung, path: pathFromEvent(e) };
  }

  private onClick(e: MouseEvent): void {
    const t = this.targetOf(e);
    if (!t) return;
    this.rungsEl.focus({ preventScroll: true });
    this.select(t);
  }

  private onContextMenu(e: MouseEvent): void {
    const t = this.targetOf(e);
    if (!t || t.path === null) return;
    if (this.openMenu(t, e.clientX, e.clientY)) e.preventDefault();
  }

  /** The force/write menu of the element at `t`, at x, y; false when `t` is not an instruction. */
  private openMenu(t: Selection, x: number, y: number): boolean {
    const r = this.doc.rungs[t.rung];
    const el = r?.elements && t.path !== null ? getAt(r.elements, toPath(t.path)) : null;
    if (!el || el.kind !== 'instr') return false;
    const ops = operandTags(el);
    const single = shapeOf(el.mnemonic) !== 'box' || ops.length <= 1;
    const items = single ? (ops[0] ? tagMenuItems(this.ctx, ops[0]) : []) : ops.flatMap((o) => tagMenuItems(this.ctx, o, `-${o}`));
    showMenu(x, y, `${el.mnemonic}(${el.operands.join(',')})`, items, this.rungsEl);
    return true;
  }

  /** Arrows, Home and End move the selection (nav.ts); Shift+F10 or the menu key opens the selected element's menu. */
  private onNavKey(e: KeyboardEvent): boolean {
    if (e.ctrlKey || e.metaKey || e.altKey) return false;
    if ((e.key === 'F10' && e.shiftKey) || e.key === 'ContextMenu') {
      const node = this.selectedNode();
      if (!this.sel || !node) return false;
      const box = node.getBoundingClientRect();
      return this.openMenu(this.sel, box.left + Math.min(box.width / 2, 40), box.top + box.height / 2);
    }
    if (e.shiftKey || !NAV_KEYS.includes(e.key)) return false;
    const rungs = this.drawn.map((d) => d.layout?.items.map((i) => ({ path: i.path.join('.'), x: i.x, y: i.y, w: i.w, h: i.h })) ?? null);
    const next = navigate(rungs, this.sel, e.key as NavKey);
    if (next && (next.rung !== this.sel?.rung || next.path !== this.sel?.path)) this.select(next, true);
    return true;
  }

  private onDrop(e: DragEvent): void {
    const mnemonic = e.dataTransfer?.getData(DRAG_TYPE);
    const info = mnemonic ? domain().instructions.find((i) => i.mnemonic === mnemonic) : undefined;
    const target = this.targetOf(e);
    if (!info || !target || !can('edit')) return;
    e.preventDefault();
    const el = (e.target as Element).closest?.('g.el');
    const box = el?.getBoundingClientRect();
    const where = this.where;
    if (box && target.path !== null) this.where = e.clientX < box.left + box.width / 2 ? 'before' : 'after';
    this.sel = target;
    this.insertInstr(info);
    this.where = where;
  }

  private onKey(e: KeyboardEvent): void {
    if ((e.target as HTMLElement).closest('input,textarea,select')) return;
    if (this.onNavKey(e)) {
      e.preventDefault();
      return;
    }
    const mod = e.ctrlKey || e.metaKey;
    const key = e.key.toLowerCase();
    const shortcut: Record<string, () => void> = {
      z: () => (e.shiftKey ? this.redo() : this.undo()),
      y: () => this.redo(),
      c: () => this.copyRung(false),
      x: () => this.copyRung(true),
      v: () => this.pasteRung(),
    };
    if (mod && shortcut[key] && can('edit')) {
      e.preventDefault();
      shortcut[key]();
    } else if ((e.key === 'Delete' || e.key === 'Backspace') && can('edit')) {
      e.preventDefault();
      this.deleteSelected();
    } else if (e.key === 'Escape') this.select(null);
  }

  // ---- edits ----------------------------------------------------------------

  private chunks(): string[] {
    return this.doc.rungs.map((r) => {
      const t = r.lead + r.own;
      return t.endsWith('\n') ? t : t + '\n';
    });
  }

  private setChunks(chunks: string[], select: Selection | null): void {
    this.setText(chunks.join('') + this.doc.tail, select);
  }

  private editRung(rung: number, f: (els: Elem[]) => Edited): void {
    const r = this.doc.rungs[rung];
    if (!r || !r.elements) {
      this.ctx.notify(tr('This rung does not parse: fix it in the text view first'), 'error');
      return;
    }
    let ed: Edited;
    try {
      ed = f(r.elements);
    } catch (err) {
      this.ctx.notify(String(err), 'error');
      return;
    }
    const chunks = this.chunks();
    chunks[rung] = r.lead + printRung({ comment: r.comment, elements: ed.elements }) + '\n';
    const select = { rung, path: ed.select ? ed.select.join('.') : null };
    if (chunks.join('') + this.doc.tail === this.ed.text) {
      // nothing changed (e.g. a change event repeated on blur)
      if (this.sel?.rung !== select.rung || this.sel?.path !== select.path) this.select(select);
      return;
    }
    this.setChunks(chunks, select);
  }

  private insertInstr(i: InstructionInfo): void {
    const sel = this.sel;
    if (!sel) {
      this.ctx.notify(tr('Select a rung or an element first'), 'error');
      return;
    }
    const el = newInstr(i.mnemonic, i.args.length);
    if (sel.path === null) {
      // on a rung: inputs go first, outputs last
      this.editRung(sel.rung, (els) => insert(els, null, el, i.output ? 'after' : 'before'));
    } else {
      this.editRung(sel.rung, (els) => insert(els, toPath(sel.path!), el, this.where));
    }
    // focus the first operand of the new instruction
    queueMicrotask(() => (this.propsEl.querySelector('[data-testid="operand-0"]') as HTMLInputElement | null)?.select());
  }

  private branch(): void {
    const sel = this.sel;
    if (!sel || sel.path === null) {
      this.ctx.notify(tr('Select an element to branch around'), 'error');
      return;
    }
    const r = this.doc.rungs[sel.rung];
    const el = r?.elements && getAt(r.elements, toPath(sel.path));
    if (!el) return;
    const output = el.kind === 'instr' && instruction(el.mnemonic)?.output;
    const leg = newInstr(output ? 'OTE' : 'XIC', 1);
    this.editRung(sel.rung, (els) => (el.kind === 'branch' ? addLeg(els, toPath(sel.path!), leg) : wrapInBranch(els, toPath(sel.path!), leg)));
  }

  private moveElement(delta: number): void {
    const sel = this.sel;
    if (!sel || sel.path === null) return;
    this.editRung(sel.rung, (els) => move(els, toPath(sel.path!), delta));
  }

  private deleteSelected(): void {
    const sel = this.sel;
    if (!sel) return;
    if (sel.path === null) this.deleteRung();
    else this.editRung(sel.rung, (els) => remove(els, toPath(sel.path!)));
  }

  private setOperands(sel: Selection, operands: string[], mnemonic?: string): void {
    if (sel.path === null) return;
    this.editRung(sel.rung, (els) => setInstr(els, toPath(sel.path!), operands, mnemonic));
  }

  private setComment(rung: number, text: string): void {
    const r = this.doc.rungs[rung];
    if (!r) return;
    const comment = text.split('\n').map((l) => l.trim()).filter((l, k, all) => l !== '' || k < all.length - 1);
    const chunks = this.chunks();
    if (r.elements) chunks[rung] = r.lead + printRung({ comment, elements: r.elements }) + '\n';
    else chunks[rung] = r.lead + [...comment.map((c) => `// ${c}`), r.body.trim() + ';'].join('\n') + '\n';
    this.setChunks(chunks, { rung, path: null });
  }

  private addRung(atEnd = false): void {
    const chunks = this.chunks();
    const at = atEnd || !this.sel ? chunks.length : this.sel.rung + 1;
    chunks.splice(at, 0, 'NOP();\n');
    this.setChunks(chunks, { rung: at, path: null });
  }

  private moveRung(delta: number): void {
    const sel = this.sel;
    if (!sel) return;
    const to = sel.rung + delta;
    const chunks = this.chunks();
    if (to < 0 || to >= chunks.length) return;
    const [c] = chunks.splice(sel.rung, 1);
    chunks.splice(to, 0, c);
    this.setChunks(chunks, { rung: to, path: null });
  }

  private undo(): void {
    if (!this.ed.undo()) this.ctx.notify(tr('Nothing to undo'));
  }

  private redo(): void {
    if (!this.ed.redo()) this.ctx.notify(tr('Nothing to redo'));
  }

  /** Copies (or cuts) the selected rung, its comment included. */
  private copyRung(cut: boolean): void {
    const sel = this.sel;
    if (!sel) {
      this.ctx.notify(tr('Select a rung first'), 'error');
      return;
    }
    rungClipboard = this.chunks()[sel.rung] ?? null;
    if (rungClipboard !== null) void navigator.clipboard?.writeText(rungClipboard).catch(() => undefined);
    if (cut) this.deleteRung();
  }

  /** Pastes the copied rung after the selected one (or at the end). */
  private pasteRung(): void {
    if (rungClipboard === null) {
      this.ctx.notify(tr('Copy a rung first'), 'error');
      return;
    }
    const chunks = this.chunks();
    const at = this.sel ? this.sel.rung + 1 : chunks.length;
    chunks.splice(at, 0, rungClipboard);
    this.setChunks(chunks, { rung: at, path: null });
  }

  private deleteRung(): void {
    const sel = this.sel;
    if (!sel) return;
    const chunks = this.chunks();
    chunks.splice(sel.rung, 1);
    this.setChunks(chunks, chunks.length ? { rung: Math.min(sel.rung, chunks.length - 1), path: null } : null);
  }

  /** The whole text, for tests and the top bar. */
  get source(): string {
    return joinProgram(this.doc);
  }
}

export type { Instr };
