// What the Ladder and IL tabs share about editing one program: the text (saved
// and edited), the text area, loading the running version, checking with the
// server (debounced, POST /api/check), saving online (PUT /api/programs),
// the problems list, the edit-state line, reloading after a reconnection
// and the power flow of the running program. A view owns one ProgramEditor
// and draws the program its own way through the hooks.
import { ApiError, api } from '../api';
import { can, why } from '../auth';
import type { Ctx } from '../ctx';
import { clear, h } from '../dom';
import type { Diagnostic, Program } from '../types';
import { tr } from '../i18n';

export interface EditorHooks {
  /** A version was loaded from the server (before its text is set). */
  loaded(p: Program): void;
  /** The text changed (loaded, typed in the text area, or set by the view). */
  textChanged(fromTextArea: boolean): void;
  /** The problems or the checking state changed: redraw. */
  changed(): void;
}

/** A line of the problems list. */
export interface Problem {
  code: string;
  line: number | null;
  col: number | null;
  text: string;
}

/** `E301: message (help)`, for tooltips on elements and lines. */
export function problemTip(d: Diagnostic): string {
  return `${d.code ? d.code + ': ' : ''}${d.message}${d.help ? ` (${d.help})` : ''}`;
}

export class ProgramEditor {
  savedText = '';
  text = '';
  /** The problems shown: the saved version's, or the last check's while edited. */
  diagnostics: Diagnostic[] = [];
  private savedDiagnostics: Diagnostic[] = [];
  private checking = false;
  private checkTimer: ReturnType<typeof setTimeout> | null = null;
  /** Energised element ids of the running program. */
  on = new Set<number>();
  readonly textEl = h('textarea', { class: 'editor-text', 'data-testid': 'editor-text', spellcheck: 'false', wrap: 'off' });
  /** Line numbers beside the text (errors cite line:column), problem lines marked. */
  readonly gutterEl = h('pre', { class: 'line-numbers', 'aria-hidden': 'true', 'data-testid': 'line-numbers' });
  /** The text area with its line numbers: what a view shows in text mode. */
  readonly textBox = h('div', { class: 'editor-text-box' }, this.gutterEl, this.textEl);
  private gutterKey = '';
  /** Texts to go back to (newest last) and forward to: every edit, graphic or typed. */
  private undoStack: string[] = [];
  private redoStack: string[] = [];
  private lastTyped = 0;
  readonly problemsEl = h('ul', { class: 'problems', 'data-testid': 'diagnostics' });
  readonly stateEl = h('span', { class: 'edit-state', 'data-testid': 'edit-state' });
  /** The view's section (gets `data-dirty`). */
  section: HTMLElement | null = null;

  constructor(
    private readonly ctx: Ctx,
    readonly program: string,
    private readonly hooks: EditorHooks,
  ) {
    this.textEl.addEventListener('input', () => this.setText(this.textEl.value, true));
    this.textEl.addEventListener('scroll', () => (this.gutterEl.scrollTop = this.textEl.scrollTop));
    // editing, checking and saving need the engineer role: read-only text otherwise
    if (!can('edit')) {
      this.textEl.readOnly = true;
      this.textEl.title = why('edit') ?? '';
    }
  }

  get dirty(): boolean {
    return this.text !== this.savedText;
  }

  /** Loads the program from the server (the running version). */
  async load(): Promise<void> {
    const p = await api.program(this.program);
    this.savedText = p.text;
    this.savedDiagnostics = p.diagnostics;
    this.diagnostics = p.diagnostics;
    this.hooks.loaded(p);
    this.undoStack = [];
    this.redoStack = [];
    this.setText(p.text, false, false, false);
  }

  /** Undoes the last edit (a graphic edit, or a burst of typing); false when there is none. */
  undo(): boolean {
    const t = this.undoStack.pop();
    if (t === undefined) return false;
    this.redoStack.push(this.text);
    this.setText(t, false, true, false);
    return true;
  }

  redo(): boolean {
    const t = this.redoStack.pop();
    if (t === undefined) return false;
    this.undoStack.push(this.text);
    this.setText(t, false, true, false);
    return true;
  }

  get canUndo(): boolean {
    return this.undoStack.length > 0;
  }

  get canRedo(): boolean {
    return this.redoStack.length > 0;
  }

  /**
   * Sets the program text; an edited text is checked after a pause. An edit
   * is recorded for undo (`record`); typing in the text area is one step per
   * burst (a pause of a second starts a new one).
   */
  setText(text: string, fromTextArea = false, check = true, record = true): void {
    if (record && text !== this.text) {
      const now = Date.now();
      if (!fromTextArea || now - this.lastTyped > 1000) this.undoStack.push(this.text);
      if (this.undoStack.length > 200) this.undoStack.shift();
      this.redoStack = [];
      this.lastTyped = fromTextArea ? now : 0;
    }
    this.text = text;
    if (!fromTextArea && this.textEl.value !== text) this.textEl.value = text;
    if (check && this.dirty) this.scheduleCheck();
    if (!this.dirty) this.diagnostics = this.savedDiagnostics;
    this.renderGutter();
    this.hooks.textChanged(fromTextArea);
  }

  /** One number per line of the text; a line with a problem is marked, its messages in the tooltip. */
  renderGutter(): void {
    const lines = this.text.split('\n').length;
    const bad = new Map<number, string[]>();
    for (const d of this.mine()) if (d.line !== null) bad.set(d.line, [...(bad.get(d.line) ?? []), problemTip(d)]);
    const key = `${lines}|${JSON.stringify([...bad])}`;
    if (key === this.gutterKey) return;
    this.gutterKey = key;
    clear(this.gutterEl);
    for (let n = 1; n <= lines; n++) {
      const why = bad.get(n);
      this.gutterEl.append(why ? h('span', { class: 'err', title: why.join('\n'), 'data-testid': `line-error-${n}` }, String(n)) : String(n), '\n');
    }
    this.gutterEl.scrollTop = this.textEl.scrollTop;
  }

  private scheduleCheck(): void {
    if (this.checkTimer) clearTimeout(this.checkTimer);
    this.checkTimer = setTimeout(() => void this.check(), 400);
  }

  /** POST /api/check with the current text; updates the problems. */
  async check(): Promise<boolean> {
    if (this.checkTimer) clearTimeout(this.checkTimer);
    this.checkTimer = null;
    if (!can('edit')) return false;
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
      this.hooks.changed();
    }
  }

  /** PUT /api/programs/{name} online; reloads the running version on success. */
  async save(): Promise<boolean> {
    if (!can('edit')) return false;
    try {
      const r = await api.saveProgram(this.program, this.text, true);
      this.ctx.notify(r.applied ? tr('{program} saved and applied online', { program: this.program }) : tr('{program} saved', { program: this.program }));
      await this.load();
      return true;
    } catch (e) {
      if (!(e instanceof ApiError)) throw e;
      this.diagnostics = e.diagnostics;
      this.ctx.notify(tr('{program} not saved: {m}', { program: this.program, m: e.message }), 'error');
      this.hooks.changed();
      return false;
    }
  }

  /** Diagnostics of this program's file (or with no file). */
  mine(): Diagnostic[] {
    const base = this.program.split('/').pop()!.toLowerCase();
    return this.diagnostics.filter((d) => !d.file || d.file.toLowerCase() === base || d.file.toLowerCase() === this.program.toLowerCase());
  }

  /**
   * While the view is shown: the power flow of the program (`paint` on every
   * change, and on status changes), and a reload of the running version after
   * a reconnection (the server may have restarted with another program)
   * unless the text is being edited. Returns the unsubscribers.
   */
  watch(paint: () => void): (() => void)[] {
    let wasDisconnected = false;
    return [
      this.ctx.live.onBatch((b) => {
        const on = b.power.get(this.program);
        if (on) this.on = new Set(on);
        if (on || b.status) paint();
      }),
      this.ctx.live.onState((st) => {
        if (st === 'reconnecting') wasDisconnected = true;
        else if (st === 'connected' && wasDisconnected) {
          wasDisconnected = false;
          if (!this.dirty) void this.load().catch(() => undefined);
        }
      }),
    ];
  }

  /**
   * The view shows power flow on the unchanged parts while the text is edited
   * (the ladder view: unchanged rungs keep the running program's ids).
   */
  keepsPowerWhileEdited = false;

  /** The edit-state words for an edited text, when the view says its own (ST: values stay, by name). */
  editedNote: string | null = null;

  /** The running program's power flow can be shown: the program runs and the connection is live. */
  get live(): boolean {
    return this.ctx.live.status?.state === 'running' && this.ctx.live.state === 'connected';
  }

  /** Power flow is shown only for the saved text of a running program with a live connection. */
  get monitoring(): boolean {
    return !this.dirty && this.ctx.live.status?.state === 'running' && this.ctx.live.state === 'connected';
  }

  renderState(): void {
    const n = this.mine().length;
    // the whole text in the tooltip too: a narrow toolbar shortens it
    this.stateEl.textContent = this.stateEl.title = [
      !this.dirty
        ? tr('online')
        : this.editedNote !== null
          ? this.editedNote
          : this.keepsPowerWhileEdited
          ? tr('edited — not saved (power flow on the unchanged rungs)')
          : tr('edited — not saved (monitoring paused)'),
      this.checking ? tr('checking…') : '',
      n === 1 ? tr('1 problem') : n > 1 ? tr('{n} problems', { n }) : '',
    ]
      .filter(Boolean)
      .join(' · ');
    this.stateEl.className = `edit-state${this.dirty ? ' dirty' : ''}${n ? ' bad' : ''}`;
    if (this.section) this.section.dataset.dirty = String(this.dirty);
  }

  /** The problems list: this program's diagnostics, then `extra`; a click on one calls `go`. */
  renderProblems(extra: Problem[], go: (line: number, col: number | null) => void): void {
    this.renderGutter();
    clear(this.problemsEl);
    const all: Problem[] = this.mine().map((d) => ({
      text: `${d.message}${d.help ? ` — ${d.help}` : ''}`,
      line: d.line,
      col: d.col,
      code: d.code,
    }));
    all.push(...extra);
    if (all.length === 0) {
      this.problemsEl.append(h('li', { class: 'none' }, tr('No problems')));
      return;
    }
    all.forEach((d, k) =>
      this.problemsEl.append(
        h('li', { class: 'problem', 'data-testid': `diagnostic-${k}`, onclick: () => d.line !== null && go(d.line, d.col) },
          h('span', { class: 'code' }, d.code),
          ' ',
          d.line !== null ? h('span', { class: 'where' }, `${d.line}:${d.col}`) : null,
          ' ',
          d.text),
      ),
    );
  }

  /** Puts the caret of the text area at line:col (1-based). */
  focusText(line: number, col: number): void {
    const lines = this.text.split('\n');
    let off = 0;
    for (let k = 0; k < line - 1 && k < lines.length; k++) off += lines[k].length + 1;
    off += Math.max(0, col - 1);
    this.textEl.focus();
    this.textEl.setSelectionRange(off, off);
  }
}
