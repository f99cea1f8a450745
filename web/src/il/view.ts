// The tab of an Instruction List (S7-200 AWL) program: the text with line
// numbers, each instruction line lit by its power flow (the logic result after
// it) and the live values of its operands; a text mode to edit, check and save.
// Like the ladder view, ids (power-flow keys) belong to the running program and
// are shown only while the text is the saved one.
import { ApiError, api } from '../api';
import type { Ctx, TagRef } from '../ctx';
import { clear, fmt, h } from '../dom';
import type { Diagnostic, Json } from '../types';
import { closeMenu, showMenu } from '../ui/menu';
import { tagMenuItems } from '../ui/tagActions';
import { type IlLine, parseIl, powerByLine } from './parse';

interface LineView {
  row: HTMLElement;
  line: number;
}

export class IlView {
  readonly el: HTMLElement;
  private savedText = '';
  private text = '';
  private parsed: IlLine[] = [];
  private lines: { line: number; id: number | null }[] = [];
  private diagnostics: Diagnostic[] = [];
  private savedDiagnostics: Diagnostic[] = [];
  private checking = false;
  private on = new Set<number>();
  private mode: 'monitor' | 'text' = 'monitor';
  private checkTimer: ReturnType<typeof setTimeout> | null = null;
  private active = false;
  private wasDisconnected = false;
  private unlisten: (() => void)[] = [];
  private unwatch: (() => void)[] = [];
  private rows: LineView[] = [];
  private readonly linesEl = h('div', { class: 'il-lines', 'data-testid': 'il-lines' });
  private readonly textEl = h('textarea', { class: 'editor-text', 'data-testid': 'editor-text', spellcheck: 'false', wrap: 'off' });
  private readonly problemsEl = h('ul', { class: 'problems', 'data-testid': 'diagnostics' });
  private readonly stateEl = h('span', { class: 'edit-state', 'data-testid': 'edit-state' });

  constructor(
    private readonly ctx: Ctx,
    readonly program: string,
  ) {
    this.textEl.addEventListener('input', () => this.setText(this.textEl.value, true));
    this.linesEl.addEventListener('contextmenu', (e) => this.onContextMenu(e));
    const modeBtn = (m: 'monitor' | 'text', label: string) =>
      h('button', { class: 'mode', 'data-testid': `view-${m}`, onclick: () => this.setMode(m) }, label);
    this.el = h(
      'section',
      { class: 'ladder-view il-view', 'data-testid': `il-${program}` },
      h('div', { class: 'toolbar' }, h('span', { class: 'seg' }, modeBtn('monitor', 'Monitor'), modeBtn('text', 'Text')), this.stateEl),
      h(
        'div',
        { class: 'ladder-body' },
        h('div', { class: 'ladder-main' }, this.linesEl, this.textEl),
        h('aside', { class: 'ladder-side' }, h('h3', null, 'Problems'), this.problemsEl),
      ),
    );
    this.setMode('monitor');
  }

  /** Loads the program from the server (the running version). */
  async load(): Promise<void> {
    const p = await api.program(this.program);
    this.savedText = p.text;
    this.lines = p.lines ?? [];
    this.savedDiagnostics = p.diagnostics;
    this.diagnostics = p.diagnostics;
    this.setText(p.text, false, false);
  }

  show(): void {
    this.active = true;
    this.unlisten.push(
      this.ctx.live.onBatch((b) => {
        const on = b.power.get(this.program);
        if (on) this.on = new Set(on);
        if (on || b.status) this.paintPower();
      }),
      this.ctx.live.onState((st) => {
        if (st === 'reconnecting') this.wasDisconnected = true;
        else if (st === 'connected' && this.wasDisconnected) {
          this.wasDisconnected = false;
          if (!this.dirty) void this.load().catch(() => undefined);
        }
        this.paintPower();
      }),
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
    return this.text !== this.savedText;
  }

  // ---- text and checking -------------------------------------------------

  private setText(text: string, fromTextArea = false, check = true): void {
    this.text = text;
    this.parsed = parseIl(text);
    if (!fromTextArea && this.textEl.value !== text) this.textEl.value = text;
    if (check && this.dirty) this.scheduleCheck();
    if (!this.dirty) this.diagnostics = this.savedDiagnostics;
    if (fromTextArea) this.renderSide();
    else this.render();
  }

  private scheduleCheck(): void {
    if (this.checkTimer) clearTimeout(this.checkTimer);
    this.checkTimer = setTimeout(() => void this.check(), 400);
  }

  /** POST /api/check with the current text; updates the problems. */
  async check(): Promise<boolean> {
    if (this.checkTimer) clearTimeout(this.checkTimer);
    this.checkTimer = null;
    const text = this.text;
    this.checking = true;
    this.renderState();
    try {
      await api.check(this.program, text);
      if (text === this.text) this.diagnostics = [];
      return true;
    } catch (e) {
      if (!(e instanceof ApiError)) throw e;
      if (text === this.text) {
        this.diagnostics = e.diagnostics.length
          ? e.diagnostics
          : [{ code: '', severity: 'error', message: e.message, file: null, line: null, col: null, end_line: null, end_col: null, help: null }];
      }
      return false;
    } finally {
      this.checking = false;
      this.render();
    }
  }

  /** PUT /api/programs/{name} online; reloads the running version on success. */
  async save(): Promise<boolean> {
    try {
      const r = await api.saveProgram(this.program, this.text, true);
      this.ctx.notify(r.applied ? `${this.program} saved and applied online` : `${this.program} saved`);
      await this.load();
      return true;
    } catch (e) {
      if (!(e instanceof ApiError)) throw e;
      this.diagnostics = e.diagnostics;
      this.ctx.notify(`${this.program} not saved: ${e.message}`, 'error');
      this.render();
      return false;
    }
  }

  // ---- rendering ----------------------------------------------------------

  private setMode(m: 'monitor' | 'text'): void {
    this.mode = m;
    this.el.dataset.mode = m;
    this.el.querySelectorAll('button.mode').forEach((b) => b.classList.toggle('active', (b as HTMLElement).dataset.testid === `view-${m}`));
    if (m === 'text') this.textEl.value = this.text;
    else this.render();
  }

  /** Diagnostics of this program's file (or with no file). */
  private mine(): Diagnostic[] {
    const base = this.program.split('/').pop()!.toLowerCase();
    return this.diagnostics.filter((d) => !d.file || d.file.toLowerCase() === base || d.file.toLowerCase() === this.program.toLowerCase());
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
    for (const d of this.mine()) {
      if (d.line === null) continue;
      const list = problems.get(d.line) ?? [];
      list.push(`${d.code ? d.code + ': ' : ''}${d.message}${d.help ? ` (${d.help})` : ''}`);
      problems.set(d.line, list);
    }
    const instr = new Set(this.dirty ? [] : this.lines.map((l) => l.line));
    const forced = this.ctx.tags.forced;
    const names = new Set<string>();
    const srcLines = this.text.split('\n');
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
    this.renderProblems();
    this.renderState();
  }

  private paintPower(): void {
    const running = !this.dirty && this.ctx.live.status?.state === 'running' && this.ctx.live.state === 'connected';
    const power = powerByLine(this.lines, running ? this.on : []);
    for (const r of this.rows) {
      const on = power.get(r.line) === true;
      if (r.row.dataset.on !== String(on)) r.row.dataset.on = String(on);
    }
  }

  private renderState(): void {
    const n = this.mine().length;
    this.stateEl.textContent = `${this.dirty ? 'edited — not saved (monitoring paused)' : 'online'}${this.checking ? ' · checking…' : ''}${n ? ` · ${n} problem${n > 1 ? 's' : ''}` : ''}`;
    this.stateEl.className = `edit-state${this.dirty ? ' dirty' : ''}${n ? ' bad' : ''}`;
    this.el.dataset.dirty = String(this.dirty);
  }

  private renderProblems(): void {
    clear(this.problemsEl);
    const all = this.mine();
    if (all.length === 0) {
      this.problemsEl.append(h('li', { class: 'none' }, 'No problems'));
      return;
    }
    all.forEach((d, k) =>
      this.problemsEl.append(
        h('li', { class: 'problem', 'data-testid': `diagnostic-${k}`, onclick: () => d.line !== null && this.goTo(d.line, d.col ?? 1) },
          h('span', { class: 'code' }, d.code),
          ' ',
          d.line !== null ? h('span', { class: 'where' }, `${d.line}:${d.col}`) : null,
          ' ',
          `${d.message}${d.help ? ` — ${d.help}` : ''}`),
      ),
    );
  }

  private goTo(line: number, col: number): void {
    if (this.mode === 'text') {
      const lines = this.text.split('\n');
      let off = 0;
      for (let k = 0; k < line - 1 && k < lines.length; k++) off += lines[k].length + 1;
      off += Math.max(0, col - 1);
      this.textEl.focus();
      this.textEl.setSelectionRange(off, off);
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
