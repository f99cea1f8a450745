// The Recipes tab (issue 35, item 6): the project's recipes
// (recipes/<name>.csv, `tag,value`), edited as CSV, saved by an engineer,
// captured from the current values, and applied by an operator after a
// confirmation that names what will be written. The server checks every
// entry first and writes all of them at one scan boundary, or none (a 422
// naming the first bad row, shown as it comes).
import { ApiError, api } from '../api';
import { gate } from '../auth';
import type { Ctx } from '../ctx';
import { clear, h } from '../dom';
import { tr } from '../i18n';

/** The tags of a recipe's CSV, in order (header, blank lines and `#` comments skipped). */
export function recipeTags(csv: string): string[] {
  const tags: string[] = [];
  for (const raw of csv.split(/\r?\n/)) {
    const line = raw.trim();
    if (!line || line.startsWith('#')) continue;
    const tag = line.split(',')[0].trim().replace(/^"|"$/g, '');
    if (!tags.length && tag.toLowerCase() === 'tag' && /,\s*"?value"?\s*$/i.test(line)) continue;
    tags.push(tag);
  }
  return tags;
}

/** A recipe's entries as its CSV (text quoted, quotes doubled). */
export function recipeCsv(entries: Record<string, unknown>): string {
  const value = (v: unknown) => (typeof v === 'string' ? `"${v.replace(/"/g, '""')}"` : String(v));
  return `tag,value\n${Object.entries(entries).map(([t, v]) => `${t},${value(v)}\n`).join('')}`;
}

/**
 * The status beside Apply after a refusal: a 422 (a bad row) wrote nothing;
 * after any other failure it is unknown what was written, so nothing is said
 * (the error is shown either way). Never the previous apply's "Applied".
 */
export function refusedNote(e: unknown): string {
  return e instanceof ApiError && e.status === 422 ? tr('Not applied: nothing written') : '';
}

/** A recipe's name as the server takes it: letters, digits, `_` and `-`, at most 64. */
export const recipeName = (name: string) => /^[A-Za-z0-9_-]{1,64}$/.test(name);

export class RecipesView {
  readonly el: HTMLElement;
  private readonly list = h('select', { 'data-testid': 'recipes-list' });
  private readonly name = h('input', { type: 'text', placeholder: tr('recipe name'), 'data-testid': 'recipes-name' });
  private readonly text = h('textarea', { rows: 16, cols: 60, spellcheck: false, 'data-testid': 'recipes-text' });
  private readonly note = h('span', { class: 'hint', 'data-testid': 'recipes-note' });

  constructor(private readonly ctx: Ctx) {
    const save = h('button', { 'data-testid': 'recipes-save' }, tr('Save'));
    save.onclick = () => void this.save();
    gate(save, 'recipe');
    const capture = h('button', { 'data-testid': 'recipes-capture', title: tr('Save the current values of these tags as the recipe') }, tr('Capture'));
    capture.onclick = () => void this.capture();
    gate(capture, 'recipe');
    const apply = h('button', { 'data-testid': 'recipes-apply', title: tr('Write every value at one scan, or none') }, tr('Apply'));
    apply.onclick = () => void this.apply();
    gate(apply, 'apply');
    this.list.onchange = () => void this.open(this.list.value);
    this.el = h('section', { class: 'recipes-view', 'data-testid': 'recipes-view' },
      h('div', { class: 'toolbar' }, this.list, this.name, save, capture, apply, this.note),
      h('p', { class: 'hint' }, tr('One tag,value pair per line.')),
      this.text);
  }

  show(): void {
    void this.refresh();
  }

  hide(): void {}

  private fail(e: unknown): void {
    this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
  }

  private async refresh(select?: string): Promise<void> {
    try {
      const names = await api.recipes();
      clear(this.list);
      this.list.append(h('option', { value: '' }, tr('(new recipe)')), ...names.map((n) => h('option', { value: n }, n)));
      const pick = select ?? this.name.value;
      if (names.includes(pick)) this.list.value = pick;
    } catch (e) {
      this.fail(e);
    }
  }

  private async open(name: string): Promise<void> {
    this.name.value = name;
    this.note.textContent = '';
    if (!name) {
      this.text.value = 'tag,value\n';
      return;
    }
    try {
      this.text.value = recipeCsv(await api.recipe(name));
    } catch (e) {
      this.fail(e);
    }
  }

  private checkedName(): string | null {
    const name = this.name.value.trim();
    if (recipeName(name)) return name;
    this.ctx.notify(tr('A recipe name is letters, digits, _ and - (at most 64)'), 'error');
    return null;
  }

  private async save(): Promise<void> {
    const name = this.checkedName();
    if (!name) return;
    try {
      await api.saveRecipe(name, this.text.value);
      this.note.textContent = tr('Saved');
      await this.refresh(name);
    } catch (e) {
      this.fail(e);
    }
  }

  private async capture(): Promise<void> {
    const name = this.checkedName();
    if (!name) return;
    try {
      await api.captureRecipe(name, recipeTags(this.text.value));
      await this.open(name);
      this.note.textContent = tr('Captured');
      await this.refresh(name);
    } catch (e) {
      this.fail(e);
    }
  }

  private async apply(): Promise<void> {
    const name = this.checkedName();
    if (!name) return;
    const tags = recipeTags(this.text.value);
    if (!confirm(tr('Apply recipe {name}? {n} values are written at once: {tags}', { name, n: tags.length, tags: tags.join(', ') }))) return;
    try {
      const r = await api.applyRecipe(name);
      this.note.textContent = tr('Applied: {n} values written', { n: r.written });
    } catch (e) {
      this.note.textContent = refusedNote(e);
      this.fail(e);
    }
  }
}
