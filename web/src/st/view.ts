// The tab of a Structured Text program (docs/st.md "In the studio"): one text
// editor — a text area over a highlighted copy of the text (keywords, types,
// literals, comments) — with completion of names (Ctrl+Space, or as a name is
// typed), the server's problems on their lines as you type, and, beside each
// line, the live values of the names it uses (as CODESYS shows them online):
// a PROGRAM's variable `v` is the tag `<program>.v`, FB outputs the members of
// their TIMER/COUNTER, globals their tags. A watch list keeps names to follow,
// with the tag menu (write, force) on each. Loading, checking, saving online
// and the problems list are the shared ProgramEditor's.
import type { Ctx } from '../ctx';
import { clear, h } from '../dom';
import { membersOf } from '../domain';
import { ProgramEditor, problemTip } from '../editor/program';
import type { Json } from '../types';
import { closeMenu, showMenu } from '../ui/menu';
import { tagMenuItems } from '../ui/tagActions';
import { tr } from '../i18n';
import { type Completion, type Decls, type Tok, complete, declarations, formatValue, highlight, inCommentOrString, indentAfter, instancesOf, lex, markRange, nameAt, namesByLine, pouAt, tagOf, wordAt } from './parse';

/** A name shown with its value: where it is drawn and the tag it reads. */
interface Shown {
  el: HTMLElement;
  tag: string;
  type: string | null;
}

const WATCH_KEY = 'alba.st.watch.';
/** Characters from which typing repaints after a pause (about 300 lines). */
const LONG_TEXT = 12_000;

export class StView {
  readonly el: HTMLElement;
  private readonly ed: ProgramEditor;
  private decls: Decls = declarations('');
  private toks: Tok[] = [];
  private paintTimer: ReturnType<typeof setTimeout> | null = null;
  private active = false;
  private unlisten: (() => void)[] = [];
  /** One store watcher per tag shown (inline or in the watch list), by canonical name. */
  private watchers = new Map<string, () => void>();
  private values = new Map<string, Json>();
  private shown: Shown[] = [];
  /** The value box of each line (index: line - 1) in the layer above the text. */
  private valueBoxes: HTMLElement[] = [];
  /** The instance whose values a FUNCTION_BLOCK's body shows, by the FB's upper-case name. */
  private instance = new Map<string, string>();
  private watchList: string[] = [];
  private renderTimer: ReturnType<typeof setTimeout> | null = null;
  private readonly overlay = h('div', { class: 'st-overlay', 'aria-hidden': 'true', 'data-testid': 'st-overlay' });
  /** Above the text area: the values and problem messages at the end of the lines (the text in it is invisible), clickable. */
  private readonly valuesLayer = h('div', { class: 'st-overlay st-values-layer', 'data-testid': 'st-values' });
  private readonly stack: HTMLElement;
  private readonly popup = h('ul', { class: 'st-complete', 'data-testid': 'st-complete', hidden: true });
  private items: Completion[] = [];
  private itemFrom = 0;
  private selected = 0;
  private readonly watchEl = h('ul', { class: 'st-watch', 'data-testid': 'st-watch' });
  private readonly watchInput = h('input', {
    class: 'st-watch-add',
    'data-testid': 'st-watch-add',
    placeholder: tr('Add a variable or tag'),
    spellcheck: 'false',
  });
  private charW = 0;

  constructor(
    private readonly ctx: Ctx,
    readonly program: string,
  ) {
    this.ed = new ProgramEditor(ctx, program, {
      loaded: () => undefined,
      textChanged: (fromTextArea) => {
        if (fromTextArea) this.paintSoon();
        else this.paintText();
        // the names and their subscriptions follow the text after a pause while typing
        if (fromTextArea) this.scheduleValues();
        else this.renderValues();
        this.renderSide();
      },
      changed: () => {
        this.paintText();
        this.renderSide();
      },
    });
    const t = this.ed.textEl;
    t.classList.add('st-text');
    t.addEventListener('scroll', () => this.syncScroll());
    t.addEventListener('input', (e) => this.onInput(e as InputEvent));
    t.addEventListener('keydown', (e) => this.onKey(e));
    t.addEventListener('blur', () => setTimeout(() => this.closePopup(), 150));
    t.addEventListener('click', () => this.closePopup());
    this.stack = h('div', { class: 'st-stack' }, this.overlay, t, this.valuesLayer, this.popup);
    this.valuesLayer.addEventListener('contextmenu', (e) => this.onValueMenu(e));
    this.valuesLayer.addEventListener('click', (e) => this.onValueMenu(e));
    this.watchInput.addEventListener('keydown', (e) => {
      if (e.key !== 'Enter') return;
      this.addWatch(this.watchInput.value.trim());
      this.watchInput.value = '';
    });
    try {
      this.watchList = JSON.parse(localStorage.getItem(WATCH_KEY + program) ?? '[]');
    } catch {
      this.watchList = [];
    }
    this.watchEl.addEventListener('contextmenu', (e) => this.onWatchMenu(e));
    this.el = h(
      'section',
      { class: 'ladder-view st-view', 'data-testid': `st-${program}` },
      h('div', { class: 'toolbar' }, h('span', { class: 'st-hint' }, tr('Ctrl+Space completes a name')), this.ed.stateEl),
      h(
        'div',
        { class: 'ladder-body' },
        h('div', { class: 'ladder-main st-main' }, h('div', { class: 'editor-text-box st-box' }, this.ed.gutterEl, this.stack)),
        h(
          'aside',
          { class: 'ladder-side' },
          h('h3', null, tr('Problems')),
          this.ed.problemsEl,
          h('h3', null, tr('Watch')),
          this.watchInput,
          this.watchEl,
        ),
      ),
    );
    this.ed.section = this.el;
    this.ed.editedNote = tr('edited — not saved (values of the running program)');
  }

  load(): Promise<void> {
    return this.ed.load();
  }

  show(): void {
    this.active = true;
    this.unlisten.push(
      ...this.ed.watch(() => undefined),
      this.ctx.live.onState(() => this.paintLive()),
      this.ctx.tags.onChange(() => this.renderValues()),
    );
    this.renderValues();
  }

  hide(): void {
    this.active = false;
    this.unlisten.forEach((f) => f());
    this.unlisten = [];
    this.watchers.forEach((f) => f());
    this.watchers.clear();
    this.ctx.live.subscribe('st', null);
    this.closePopup();
    closeMenu();
  }

  get dirty(): boolean {
    return this.ed.dirty;
  }

  check(): Promise<boolean> {
    return this.ed.check();
  }

  /** Saves online; the new variables' tags are then known (GET /api/tags again). */
  async save(): Promise<boolean> {
    const ok = await this.ed.save();
    if (ok) await this.ctx.tags.refresh().catch(() => undefined);
    return ok;
  }

  // ---- the text ------------------------------------------------------------

  /**
   * Typed text: painted at once in a short program; in a long one (a full
   * paint takes tens of ms) after a pause, the text area showing its own
   * plain text meanwhile.
   */
  private paintSoon(): void {
    if (this.paintTimer) clearTimeout(this.paintTimer);
    this.paintTimer = null;
    if (this.ed.text.length < LONG_TEXT) {
      this.paintText();
      return;
    }
    this.el.classList.add('st-stale');
    this.paintTimer = setTimeout(() => this.paintText(), 150);
  }

  /** The highlighted copy of the text under the text area, problems marked on their lines. */
  private paintText(): void {
    if (this.paintTimer) clearTimeout(this.paintTimer);
    this.paintTimer = null;
    this.el?.classList.remove('st-stale');
    const text = this.ed.text;
    const toks = lex(text);
    this.toks = toks;
    this.decls = declarations(text, toks);
    const problems = new Map<number, string[]>();
    const places = new Map<number, [number, number | null][]>();
    for (const d of this.ed.mine()) {
      if (d.line === null) continue;
      problems.set(d.line, [...(problems.get(d.line) ?? []), problemTip(d)]);
      // the place itself, on its first line (to the end of the line when it goes on)
      const to = d.end_line === null || d.end_line === d.line ? d.end_col : null;
      places.set(d.line, [...(places.get(d.line) ?? []), [d.col ?? 1, d.col === null ? null : to]]);
    }
    clear(this.overlay);
    clear(this.valuesLayer);
    this.valueBoxes = [];
    const raw = text.split('\n');
    highlight(text, toks).forEach((line, k) => {
      const n = k + 1;
      const err = problems.get(n);
      let spans = line;
      for (const [from, to] of places.get(n) ?? []) spans = markRange(spans, from, to);
      const row = h('div', { class: `st-line${err ? ' error' : ''}`, 'data-line': String(n) });
      for (const s of spans) row.append(s.cls ? h('span', { class: s.cls }, s.text) : s.text);
      this.overlay.append(row);
      const top = h('div', { class: 'st-line', 'data-line': String(n) }, h('span', { class: 'st-ghost' }, raw[k] ?? ''));
      const box = h('span', { class: 'st-vals', 'data-testid': `st-vals-${n}` });
      this.valueBoxes[k] = box;
      top.append(box);
      if (err) top.append(h('span', { class: 'st-err', 'data-testid': `st-error-${n}`, title: err.join('\n') }, err[0]));
      this.valuesLayer.append(top);
    });
    // the values already known go back beside their (maybe moved) lines
    this.placeValues();
    this.syncScroll();
  }

  private syncScroll(): void {
    const t = this.ed.textEl;
    this.overlay.style.transform = this.valuesLayer.style.transform = `translate(${-t.scrollLeft}px, ${-t.scrollTop}px)`;
    this.closePopup();
  }

  // ---- live values ---------------------------------------------------------

  private scheduleValues(): void {
    if (this.renderTimer) clearTimeout(this.renderTimer);
    this.renderTimer = setTimeout(() => this.renderValues(), 250);
  }

  /** The tag of a name used on a line (its POU's variable, an FB member, a global). */
  private tagFor(name: string, line: number | null): { tag: string; type: string | null } | null {
    const pou = line === null ? (this.decls.pous.find((p) => p.kind === 'PROGRAM') ?? null) : pouAt(this.decls, line);
    const instance = pou?.kind === 'FUNCTION_BLOCK' ? this.instanceOf(pou.name) : null;
    return tagOf(name, pou, this.decls, (n) => this.ctx.tags.resolve(n)?.name ?? null, instance);
  }

  /** The instance shown in a FUNCTION_BLOCK's body: the one chosen, else the first. */
  private instanceOf(fb: string): string | null {
    const all = instancesOf(this.decls, fb);
    const chosen = this.instance.get(fb.toUpperCase());
    return chosen && all.includes(chosen) ? chosen : (all[0] ?? null);
  }

  /** Finds the names of every line, their tags, and follows those tags in the live store. */
  private renderValues(): void {
    if (this.renderTimer) clearTimeout(this.renderTimer);
    this.renderTimer = null;
    this.placeValues();
    if (!this.active) return;
    const tags = new Set([...this.shown.map((s) => s.tag)]);
    for (const w of this.watchList) {
      const t = this.tagFor(w, null);
      if (t) tags.add(t.tag);
    }
    for (const [tag, off] of this.watchers) {
      if (!tags.has(tag)) {
        off();
        this.watchers.delete(tag);
      }
    }
    for (const tag of tags) {
      if (this.watchers.has(tag)) continue;
      this.watchers.set(
        tag,
        this.ctx.live.store.watch(tag, (v) => {
          this.values.set(tag, v);
          this.paintValue(tag);
        }),
      );
    }
    this.ctx.live.subscribe('st', [...tags]);
  }

  /** Value elements beside each line and in the watch list (from the values known). */
  private placeValues(): void {
    this.shown = [];
    this.valueBoxes.forEach((box) => clear(box));
    // a FUNCTION_BLOCK shows one instance's values: which one, on its first line
    for (const p of this.decls.pous) {
      const inst = p.kind === 'FUNCTION_BLOCK' ? this.instanceOf(p.name) : null;
      if (inst === null) continue;
      this.valueBoxes[p.from - 1]?.append(
        h('span', { class: 'st-val-item st-instance', 'data-fb': p.name, 'data-testid': `st-instance-${p.name}`, title: tr('The instance whose values are shown') }, tr('instance'), ' ', h('b', null, inst), ' ▾'),
      );
    }
    const names = namesByLine(this.ed.text, this.toks, this.decls);
    for (const [line, refs] of names) {
      const box = this.valueBoxes[line - 1];
      if (!box) continue;
      for (const r of refs) {
        const t = this.tagFor(r.text, line);
        if (!t) continue;
        const val = h('b', { class: 'st-val' });
        box.append(h('span', { class: 'st-val-item', 'data-name': r.text, 'data-tag': t.tag, 'data-testid': `st-val-${line}-${r.text}`, title: t.tag }, `${r.text} = `, val));
        this.shown.push({ el: val, tag: t.tag, type: t.type });
      }
    }
    clear(this.watchEl);
    for (const w of this.watchList) {
      const t = this.tagFor(w, null);
      const val = h('b', { class: 'st-val' }, t ? '' : tr('no tag'));
      this.watchEl.append(
        h(
          'li',
          { 'data-name': w, 'data-tag': t?.tag ?? '', 'data-testid': `st-watch-${w}`, title: t?.tag ?? '' },
          h('span', { class: 'st-watch-name' }, w),
          val,
          h('button', { class: 'st-watch-remove', title: tr('Remove'), onclick: () => this.removeWatch(w) }, '×'),
        ),
      );
      if (t) this.shown.push({ el: val, tag: t.tag, type: t.type });
    }
    for (const s of this.shown) this.paintOne(s);
    this.paintLive();
  }

  private paintOne(s: Shown): void {
    const v = this.values.get(s.tag);
    const type = s.type ?? this.ctx.tags.resolve(s.tag)?.type ?? null;
    s.el.textContent = formatValue(v, type);
    s.el.classList.toggle('bool-on', v === true);
    s.el.classList.toggle('forced', this.ctx.tags.forced.has(s.tag.toUpperCase()));
  }

  private paintValue(tag: string): void {
    for (const s of this.shown) if (s.tag === tag) this.paintOne(s);
  }

  /** Values are live while the program runs and the connection is up (dimmed otherwise). */
  private paintLive(): void {
    this.el.dataset.live = String(this.ed.live);
  }

  private addWatch(name: string): void {
    if (!name || this.watchList.some((w) => w.toUpperCase() === name.toUpperCase())) return;
    this.watchList.push(name);
    this.saveWatch();
  }

  private removeWatch(name: string): void {
    this.watchList = this.watchList.filter((w) => w !== name);
    this.saveWatch();
  }

  private saveWatch(): void {
    try {
      localStorage.setItem(WATCH_KEY + this.program, JSON.stringify(this.watchList));
    } catch {
      // private browsing: the list lasts as long as the page
    }
    this.renderValues();
  }

  /** A click on a value beside a line: the tag menu (write, force) and *Watch*. */
  private onValueMenu(e: MouseEvent): void {
    const chip = (e.target as Element).closest('.st-instance') as HTMLElement | null;
    const fb = chip?.dataset.fb;
    if (fb) {
      e.preventDefault();
      const shown = this.instanceOf(fb);
      showMenu(
        e.clientX,
        e.clientY,
        fb,
        instancesOf(this.decls, fb).map((inst) => ({
          label: inst,
          testid: `menu-instance-${inst}`,
          disabled: inst === shown,
          action: () => {
            this.instance.set(fb.toUpperCase(), inst);
            this.renderValues();
          },
        })),
      );
      return;
    }
    const item = (e.target as Element).closest('.st-val-item') as HTMLElement | null;
    const tag = item?.dataset.tag;
    const name = item?.dataset.name;
    if (!tag || !name) return;
    e.preventDefault();
    showMenu(e.clientX, e.clientY, `${name} (${tag})`, [
      ...tagMenuItems(this.ctx, tag),
      { label: tr('Watch'), testid: 'menu-watch', disabled: this.watchList.includes(name), action: () => this.addWatch(name) },
    ]);
  }

  /** The tag menu of the name at the caret, under it. */
  private nameMenu(): void {
    const t = this.ed.textEl;
    const name = nameAt(t.value, t.selectionStart);
    const line = t.value.slice(0, t.selectionStart).split('\n').length;
    const ref = name ? this.tagFor(name, line) : null;
    if (!name || !ref) {
      this.ctx.notify(name ? tr('{name} has no tag', { name }) : tr('No name at the caret'), 'error');
      return;
    }
    const r = t.getBoundingClientRect();
    const col = t.selectionStart - t.value.lastIndexOf('\n', t.selectionStart - 1) - 1;
    const lineH = parseFloat(getComputedStyle(t).lineHeight) || 19.5;
    const x = r.left + 14 + col * (this.charW || 7.8) - t.scrollLeft;
    const y = r.top + 10 + line * lineH - t.scrollTop;
    showMenu(
      x,
      y,
      `${name} (${ref.tag})`,
      [...tagMenuItems(this.ctx, ref.tag), { label: tr('Watch'), testid: 'menu-watch', disabled: this.watchList.includes(name), action: () => this.addWatch(name) }],
      t,
    );
  }

  private onWatchMenu(e: MouseEvent): void {
    const li = (e.target as Element).closest('li') as HTMLElement | null;
    const tag = li?.dataset.tag;
    if (!tag) return;
    e.preventDefault();
    showMenu(e.clientX, e.clientY, li!.dataset.name ?? tag, tagMenuItems(this.ctx, tag));
  }

  // ---- completion ----------------------------------------------------------

  private onInput(e: InputEvent): void {
    const typed = e.data ?? '';
    if (e.inputType === 'insertText' && /^[A-Za-z0-9_.]$/.test(typed)) this.openPopup(false);
    else this.closePopup();
  }

  private onKey(e: KeyboardEvent): void {
    if (e.key === ' ' && e.ctrlKey) {
      e.preventDefault();
      this.openPopup(true);
      return;
    }
    if (e.key === 'Enter' && e.altKey) {
      // Alt+Enter: the menu of the name at the caret (force, write, watch) from the keyboard
      e.preventDefault();
      this.closePopup();
      this.nameMenu();
      return;
    }
    if (this.popup.hidden) {
      if (e.key === 'Enter' && !e.ctrlKey && !e.altKey && !e.shiftKey && !e.metaKey && !this.ed.textEl.readOnly) {
        // a new line keeps the indentation, one step more after THEN, DO, VAR…
        e.preventDefault();
        const t = this.ed.textEl;
        const at = t.selectionStart;
        const line = t.value.slice(t.value.lastIndexOf('\n', at - 1) + 1, at);
        t.setRangeText(`\n${indentAfter(line)}`, at, t.selectionEnd, 'end');
        t.dispatchEvent(new Event('input'));
      }
      return;
    }
    if (e.key === 'ArrowDown' || e.key === 'ArrowUp') {
      e.preventDefault();
      const n = this.items.length;
      this.selected = (this.selected + (e.key === 'ArrowDown' ? 1 : n - 1)) % n;
      this.paintPopup();
    } else if (e.key === 'Enter' || e.key === 'Tab') {
      e.preventDefault();
      this.accept(this.selected);
    } else if (e.key === 'Escape') {
      e.preventDefault();
      this.closePopup();
    }
  }

  /** Opens the list of names for the word at the caret (`forced`: even for an empty word). */
  private openPopup(forced: boolean): void {
    const t = this.ed.textEl;
    const caret = t.selectionStart;
    if (caret !== t.selectionEnd) return this.closePopup();
    const { base, prefix } = wordAt(t.value, caret);
    if (!forced && base === null && prefix.length < 1) return this.closePopup();
    if (!forced && inCommentOrString(this.toks, caret)) return this.closePopup();
    const env = {
      tags: this.ctx.tags.list.map((x) => ({ name: x.name, type: x.type })),
      members: (type: string) => membersOf(type).map((m) => m.name),
    };
    const r = complete(t.value, caret, env, declarations(t.value));
    this.items = r.items.slice(0, 50);
    this.itemFrom = r.from;
    this.selected = 0;
    if (this.items.length === 0) return this.closePopup();
    // under the caret: monospace text, so line and column give the place
    if (!this.charW) {
      const probe = h('span', { class: 'st-probe' }, 'M'.repeat(20));
      this.overlay.append(probe);
      this.charW = probe.getBoundingClientRect().width / 20 || 7.8;
      probe.remove();
    }
    const before = t.value.slice(0, r.from).split('\n');
    const style = getComputedStyle(t);
    const lineH = parseFloat(style.lineHeight) || 19.5;
    const top = parseFloat(style.paddingTop) + before.length * lineH - t.scrollTop;
    const left = parseFloat(style.paddingLeft) + before[before.length - 1].length * this.charW - t.scrollLeft;
    this.popup.style.top = `${top}px`;
    this.popup.style.left = `${Math.max(0, left)}px`;
    this.popup.hidden = false;
    this.paintPopup();
  }

  private paintPopup(): void {
    clear(this.popup);
    this.items.forEach((c, k) => {
      const li = h(
        'li',
        { class: `${c.kind}${k === this.selected ? ' selected' : ''}`, 'data-testid': `st-complete-${c.label}` },
        h('span', { class: 'st-c-label' }, c.label),
        c.detail ? h('span', { class: 'st-c-detail' }, c.detail) : null,
      );
      // mousedown, not click: the text area keeps its focus and caret
      li.addEventListener('mousedown', (e) => {
        e.preventDefault();
        this.accept(k);
      });
      this.popup.append(li);
    });
    this.popup.children[this.selected]?.scrollIntoView({ block: 'nearest' });
  }

  private accept(k: number): void {
    const c = this.items[k];
    const t = this.ed.textEl;
    this.closePopup();
    if (!c) return;
    t.setRangeText(c.label, this.itemFrom, t.selectionStart, 'end');
    t.dispatchEvent(new Event('input'));
    t.focus();
  }

  private closePopup(): void {
    if (!this.popup.hidden) this.popup.hidden = true;
  }

  private renderSide(): void {
    this.ed.renderProblems([], (line, col) => this.ed.focusText(line, col ?? 1));
    this.ed.renderState();
  }
}
