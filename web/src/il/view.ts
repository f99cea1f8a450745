// The tab of an Instruction List (S7-200 AWL) program: the text with line
// numbers, each instruction line lit by its power flow (the logic result after
// it) and the live values of its operands; a text mode to edit, check and save.
// Like the ladder view, ids (power-flow keys) belong to the running program and
// are shown only while the text is the saved one. Loading, checking, saving
// and the problems list are the shared ProgramEditor's.
import type { Ctx, TagRef } from '../ctx';
import { clear, fmt, h } from '../dom';
import { ProgramEditor, problemTip } from '../editor/program';
import type { Json } from '../types';
import { closeMenu, showMenu } from '../ui/menu';
import { tagMenuItems } from '../ui/tagActions';
import { type IlLine, parseIl, powerByLine } from './parse';
import { tr } from '../i18n';

interface LineView {
  row: HTMLElement;
  line: number;
}

export class IlView {
  readonly el: HTMLElement;
  private readonly ed: ProgramEditor;
  private parsed: IlLine[] = [];
  private lines: { line: number; id: number | null }[] = [];
  private mode: 'monitor' | 'text' = 'monitor';
  private active = false;
  private unlisten: (() => void)[] = [];
  private unwatch: (() => void)[] = [];
  private rows: LineView[] = [];
  private readonly linesEl = h('div', { class: 'il-lines', 'data-testid': 'il-lines' });

  constructor(
    private readonly ctx: Ctx,
    readonly program: string,
  ) {
    this.ed = new ProgramEditor(ctx, program, {
      loaded: (p) => (this.lines = p.lines ?? []),
      textChanged: (fromTextArea) => {
        this.parsed = parseIl(this.ed.text);
        if (fromTextArea) this.renderSide();
        else this.render();
      },
      changed: () => this.render(),
    });
    this.linesEl.addEventListener('contextmenu', (e) => this.onContextMenu(e));
    const modeBtn = (m: 'monitor' | 'text', label: string) =>
      h('button', { class: 'mode', 'data-testid': `view-${m}`, onclick: () => this.setMode(m) }, label);
    this.el = h(
      'section',
      { class: 'ladder-view il-view', 'data-testid': `il-${program}` },
      h('div', { class: 'toolbar' }, h('span', { class: 'seg' }, modeBtn('monitor', tr('Monitor')), modeBtn('text', tr('Text'))), this.ed.stateEl),
      h(
        'div',
        { class: 'ladder-body' },
        h('div', { class: 'ladder-main' }, this.linesEl, this.ed.textBox),
        h('aside', { class: 'ladder-side' }, h('h3', null, tr('Problems')), this.ed.problemsEl),
      ),
    );
    this.ed.section = this.el;
    this.setMode('monitor');
  }

  /** Loads the program from the server (the running version). */
  load(): Promise<void> {
    return this.ed.load();
  }

  show(): void {
    this.active = true;
    this.unlisten.push(
      ...this.ed.watch(() => this.paintPower()),
      this.ctx.live.onState(() => this.paintPower()),
      this.ctx.tags.onChange(() => this.render()),
    );
    this.ctx.live.monitor('il', [this.program]);
    this.render();
  }

  hide(): void {
    this.active = false;
    this.unlisten.forEach((f) => f());
    this.unlisten = [];
    this.ctx.live.monitor('il', null);
    this.ctx.live.subscribe('il', null);
    closeMenu();
  }

  get dirty(): boolean {
    return this.ed.dirty;
  }

  /** POST /api/check with the current text; updates the problems. */
  check(): Promise<boolean> {
    return this.ed.check();
  }

  /** PUT /api/programs/{name} online; reloads the running version on success. */
  save(): Promise<boolean> {
    return this.ed.save();
  }

  // ---- rendering ----------------------------------------------------------

  private setMode(m: 'monitor' | 'text'): void {
    this.mode = m;
    this.el.dataset.mode = m;
    this.el.querySelectorAll('button.mode').forEach((b) => b.classList.toggle('active', (b as HTMLElement).dataset.testid === `view-${m}`));
    if (m === 'text') this.ed.textEl.value = this.ed.text;
    else this.render();
  }

  /** The tag an operand names (directly or by its address), if the server knows it. */
  private resolve(operand: string): TagRef | null {
    return this.ctx.tags.resolve(operand);
  }

  private render(): void {
    this.unwatch.forEach((f) => f());
    this.unwatch = [];
    this.rows = [];
    clear(this.linesEl);
    const problems = new Map<number, string[]>();
    for (const d of this.ed.mine()) {
      if (d.line === null) continue;
      const list = problems.get(d.line) ?? [];
      list.push(problemTip(d));
      problems.set(d.line, list);
    }
    const instr = new Set(this.dirty ? [] : this.lines.map((l) => l.line));
    const forced = this.ctx.tags.forced;
    const names = new Set<string>();
    const srcLines = this.ed.text.split('\n');
    if (srcLines.length > 1 && srcLines[srcLines.length - 1] === '') srcLines.pop();
    srcLines.forEach((src, k) => {
      const n = k + 1;
      const p = this.parsed[k];
      const err = problems.get(n);
      const values = h('span', { class: 'il-values' });
      const seen = new Set<string>();
      for (const op of p?.operands ?? []) {
        const ref = this.resolve(op);
        if (!ref || seen.has(ref.name.toUpperCase())) continue;
        seen.add(ref.name.toUpperCase());
        names.add(ref.name);
        const label = ref.name.toUpperCase() === op.toUpperCase() ? op : `${op} ${ref.name}`;
        const val = h('span', { class: 'il-value', 'data-tag': op, title: `${ref.name} (${ref.type})` }, '…');
        const isForced = forced.has(ref.name.toUpperCase());
        this.unwatch.push(
          this.ctx.live.store.watch(ref.name, (v: Json) => {
            val.textContent = fmt(v);
            val.classList.toggle('bool-on', v === true);
          }),
        );
        values.append(h('span', { class: `il-operand${isForced ? ' forced' : ''}` }, `${label}=`, val, isForced ? ' F' : null));
      }
      const isInstr = instr.has(n) || (this.dirty && p?.mnemonic !== null);
      const row = h(
        'div',
        {
          class: `il-line${isInstr ? ' instr' : ''}${err ? ' error' : ''}`,
          'data-line': String(n),
          'data-testid': isInstr ? `il-line-${n}` : undefined,
          'data-on': isInstr ? 'false' : undefined,
          title: err ? err.join('\n') : undefined,
        },
        h('span', { class: 'il-no' }, String(n)),
        h('span', { class: 'il-mark' }),
        h('span', { class: 'il-code' }, src.replace(/\r$/, '') || ' '),
        values,
      );
      if (isInstr) this.rows.push({ row, line: n });
      this.linesEl.append(row);
    });
    if (this.active) this.ctx.live.subscribe('il', [...names]);
    this.paintPower();
    this.renderSide();
  }

  private renderSide(): void {
    this.ed.renderProblems([], (line, col) => this.goTo(line, col ?? 1));
    this.ed.renderState();
  }

  private paintPower(): void {
    const power = powerByLine(this.lines, this.ed.monitoring ? this.ed.on : []);
    for (const r of this.rows) {
      const on = power.get(r.line) === true;
      if (r.row.dataset.on !== String(on)) r.row.dataset.on = String(on);
    }
  }

  private goTo(line: number, col: number): void {
    if (this.mode === 'text') {
      this.ed.focusText(line, col);
    } else {
      this.linesEl.querySelector(`[data-line="${line}"]`)?.scrollIntoView({ block: 'center' });
    }
  }

  private onContextMenu(e: MouseEvent): void {
    const row = (e.target as Element).closest('.il-line') as HTMLElement | null;
    if (!row) return;
    const p = this.parsed[Number(row.dataset.line) - 1];
    if (!p?.mnemonic) return;
    e.preventDefault();
    const ops = [...new Set(p.operands)].filter((op) => this.resolve(op));
    const several = ops.length > 1;
    const items = ops.flatMap((op) => {
      const name = this.resolve(op)?.name ?? op;
      return tagMenuItems(this.ctx, name, several ? `-${op}` : '');
    });
    showMenu(e.clientX, e.clientY, p.code, items);
  }
}
