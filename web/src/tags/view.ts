// The tag table: live values, writes, forces, definitions (tags.csv) with
// add/edit/delete, CSV import and export.
import { ApiError, api } from '../api';
import { type Action, gate } from '../auth';
import type { Ctx } from '../ctx';
import { clear, fmt, h, searchBox } from '../dom';
import type { Diagnostic, Json, TagInfo } from '../types';
import { domain, isStructure, membersOf } from '../domain';
import { showMenu } from '../ui/menu';
import { parseValue, tagMenuItems } from '../ui/tagActions';
import { type TagDef, type TagsFile, lineOfDefs, parseTagsCsv, tagsCsv, validateDef } from './csv';
import { tr } from '../i18n';
import { confirmAction } from '../ui/confirm';
import { openFaceplate } from '../ui/faceplate';
import { openOpcuaBrowser } from '../ui/opcuaBrowse';

interface Row {
  name: string;
  type: string;
  access: 'readwrite' | 'input' | 'readonly';
  io: boolean;
  tag: TagInfo | null;
  member: boolean;
  search: string;
}

/** The rows of the table: each tag, then the members of structures (TIMER, COUNTER, PID). */
export function tableRows(tags: TagInfo[]): Row[] {
  const rows: Row[] = [];
  for (const t of tags) {
    const io = !!t.address && t.access !== 'readonly';
    const search = `${t.name} ${t.type} ${t.address ?? ''} ${t.description}`.toLowerCase();
    rows.push({ name: t.name, type: t.type, access: t.access, io, tag: t, member: false, search });
    for (const m of membersOf(t.type)) {
      rows.push({
        name: `${t.name}.${m.name}`,
        type: m.type,
        access: m.writable ? 'readwrite' : 'readonly',
        io: false,
        tag: null,
        member: true,
        search: `${t.name}.${m.name} ${search}`.toLowerCase(),
      });
    }
  }
  return rows;
}

export function matches(row: { search: string }, filter: string): boolean {
  const words = filter.toLowerCase().split(/\s+/).filter(Boolean);
  return words.every((w) => row.search.includes(w));
}

/** Disables `el` when the role may not do `action` (with the reason as its tooltip). */
function gated<E extends HTMLElement & { disabled: boolean }>(el: E, action: Action): E {
  gate(el, action);
  return el;
}

export class TagsView {
  readonly el: HTMLElement;
  private readonly body = h('tbody');
  private readonly filterEl = searchBox(tr('Filter by name, type, address, description'), 'tag-filter');
  private readonly formEl = h('div', { class: 'tag-form', hidden: true, 'data-testid': 'tag-form' });
  private readonly diagEl = h('ul', { class: 'problems', 'data-testid': 'tags-diagnostics' });
  private rows: { row: Row; tr: HTMLTableRowElement }[] = [];
  private unwatch: (() => void)[] = [];
  private unlisten: (() => void)[] = [];
  private file: TagsFile | null = null;

  constructor(private readonly ctx: Ctx) {
    this.filterEl.addEventListener('input', () => this.applyFilter());
    // a right-click, or a long press on a touch screen, on a row: its force and write menu (as in the ladder)
    this.body.addEventListener('contextmenu', (e) => {
      const row = this.rows.find((r) => r.tr.contains(e.target as Node))?.row;
      const items = row ? tagMenuItems(this.ctx, row.name) : [];
      if (!row || items.length === 0) return;
      e.preventDefault();
      showMenu(e.clientX, e.clientY, row.name, items, e.target instanceof HTMLElement && e.target.matches('button, input') ? e.target : null);
    });
    const importInput = h('input', { type: 'file', accept: '.csv,text/csv', 'data-testid': 'tags-import', hidden: true });
    importInput.addEventListener('change', async () => {
      const f = importInput.files?.[0];
      importInput.value = '';
      if (f) await this.putCsv(await f.text(), tr('Imported {name}', { name: f.name }));
    });
    this.el = h(
      'section',
      { class: 'tags-view', 'data-testid': 'tags-view' },
      h(
        'div',
        { class: 'toolbar' },
        this.filterEl,
        gated(h('button', { 'data-testid': 'tag-add', onclick: () => void this.openForm(null) }, `+ ${tr('New tag')}`), 'tags'),
        gated(h('button', { 'data-testid': 'tags-import-button', onclick: () => importInput.click() }, tr('Import CSV…')), 'tags'),
        importInput,
        h('a', { class: 'button', href: '/api/tags.csv', download: 'tags.csv', 'data-testid': 'tags-export' }, tr('Export CSV')),
      ),
      this.formEl,
      this.diagEl,
      h(
        'div',
        { class: 'table-wrap', tabindex: '-1', 'data-skip-target': '' },
        h(
          'table',
          { class: 'tags', 'data-testid': 'tag-table' },
          h('thead', null, h('tr', null, [tr('Name'), tr('Type'), tr('Address'), tr('Value'), tr('Force'), tr('Description'), ''].map((c) => h('th', null, c)))),
          this.body,
        ),
      ),
    );
  }

  show(): void {
    this.ctx.live.subscribe('tags', '*');
    this.unlisten.push(this.ctx.tags.onChange(() => this.render()));
    this.render();
    void this.ctx.tags.refresh().catch((e) => this.ctx.notify(String(e), 'error'));
  }

  hide(): void {
    this.ctx.live.subscribe('tags', null);
    this.unlisten.forEach((f) => f());
    this.unlisten = [];
  }

  private applyFilter(): void {
    const f = this.filterEl.value;
    for (const { row, tr } of this.rows) tr.hidden = !matches(row, f);
  }

  private render(): void {
    const focused = this.focusMark();
    this.unwatch.forEach((f) => f());
    this.unwatch = [];
    clear(this.body);
    this.rows = tableRows(this.ctx.tags.list).map((row) => ({ row, tr: this.renderRow(row) }));
    this.rows.forEach(({ tr }) => this.body.append(tr));
    this.applyFilter();
    if (focused) this.refocus(focused);
  }

  /** The focused control of the table (its test id and row), to give the focus back once the rows are drawn again. */
  private focusMark(): { testid: string; row: number } | null {
    const a = document.activeElement as HTMLElement | null;
    const tr = a?.closest('tr');
    if (!a?.dataset.testid || !tr || !this.body.contains(tr)) return null;
    return { testid: a.dataset.testid, row: this.rows.findIndex((r) => r.tr === tr) };
  }

  /**
   * After a force, a write or a change of definitions the focus stays on the
   * same control; when it is gone or disabled (Unforce once unforced, a
   * deleted row), on the next control of its row, or of the row now in its place.
   */
  private refocus(m: { testid: string; row: number }): void {
    const usable = (e: Element | null): e is HTMLElement => !!e && !(e as HTMLButtonElement).disabled && !(e as HTMLElement).closest('[hidden]');
    const same = this.body.querySelector(`[data-testid="${CSS.escape(m.testid)}"]`);
    if (usable(same)) return same.focus();
    const tr = same?.closest('tr') ?? this.rows[Math.min(m.row, this.rows.length - 1)]?.tr;
    const next = [...(tr?.querySelectorAll<HTMLElement>('button, input') ?? [])].find(usable);
    (next ?? this.filterEl).focus();
  }

  private renderRow(row: Row): HTMLTableRowElement {
    const t = row.tag;
    const valueText = document.createTextNode('…');
    const valueSpan = h('span', { class: 'value', 'data-testid': `tag-value-${row.name}` }, valueText);
    const valueCell = h('td', { class: 'value-cell' }, valueSpan);
    const errorEl = h('div', { class: 'inline-error', 'data-testid': `tag-error-${row.name}`, hidden: true });
    const structured = isStructure(row.type);
    if (!structured) {
      this.unwatch.push(
        this.ctx.live.store.watch(row.name, (v) => {
          const s = fmt(v);
          if (valueText.data !== s) valueText.data = s;
          valueSpan.classList.toggle('bool-on', v === true);
        }),
      );
    } else valueText.data = '';
    const showError = (msg: string | null) => {
      errorEl.hidden = msg === null;
      errorEl.textContent = msg ?? '';
    };
    const write = async (value: Json) => {
      try {
        await api.writeTag(row.name, value);
        showError(null);
        return true;
      } catch (e) {
        showError(e instanceof ApiError ? e.message : String(e));
        return false;
      }
    };
    if (!structured && row.access === 'readwrite' && !row.io) {
      if (row.type === 'BOOL') {
        valueCell.append(
          gated(h('button', { class: 'small', 'data-testid': `tag-toggle-${row.name}`, onclick: () => void write(!(this.ctx.live.store.get(row.name) === true)) }, tr('Toggle')), 'write'),
        );
      } else {
        const edit = () => {
          const input = h('input', { class: 'value-input', 'data-testid': `tag-input-${row.name}`, value: fmt(this.ctx.live.store.get(row.name)) });
          const done = () => {
            const back = input === document.activeElement;
            input.remove();
            valueSpan.hidden = false;
            if (back) editBtn.focus();
          };
          input.addEventListener('keydown', async (e) => {
            if (e.key === 'Enter') {
              if (await write(parseValue(row.type, input.value))) done();
            } else if (e.key === 'Escape') {
              showError(null);
              done();
            }
          });
          input.addEventListener('blur', () => setTimeout(() => input.isConnected && errorEl.hidden && done(), 150));
          valueSpan.hidden = true;
          valueCell.prepend(input);
          input.focus();
          input.select();
        };
        const editBtn = gated(h('button', { class: 'small', title: tr('Edit the value'), 'data-testid': `tag-edit-value-${row.name}`, onclick: edit }, '✎'), 'write');
        valueCell.append(editBtn);
      }
    }
    valueCell.append(errorEl);

    const forceCell = h('td', { class: 'force-cell' });
    if (row.io) {
      const forced = this.ctx.tags.forced.get(row.name.toUpperCase());
      const isForced = forced !== undefined;
      const force = async (v: Json | null) => {
        try {
          if (v === null) await api.unforce(row.name);
          else await api.force(row.name, v);
          showError(null);
          await this.ctx.tags.refreshForces();
        } catch (e) {
          showError(e instanceof ApiError ? e.message : String(e));
        }
      };
      if (isForced) forceCell.append(h('span', { class: 'forced', 'data-testid': `tag-forced-${row.name}` }, `F=${fmt(forced)}`), ' ');
      if (row.type === 'BOOL') {
        forceCell.append(
          gated(h('button', { class: 'small', title: tr('Force to 1 (on)'), 'data-testid': `force-on-${row.name}`, onclick: () => void force(true) }, 'F1'), 'force'),
          gated(h('button', { class: 'small', title: tr('Force to 0 (off)'), 'data-testid': `force-off-${row.name}`, onclick: () => void force(false) }, 'F0'), 'force'),
        );
      } else {
        const input = gated(h('input', { class: 'force-input', 'data-testid': `force-value-${row.name}`, placeholder: tr('value'), size: 6 }), 'force');
        forceCell.append(input, gated(h('button', { class: 'small', 'data-testid': `force-apply-${row.name}`, onclick: () => void force(parseValue(row.type, input.value)) }, tr('Force')), 'force'));
      }
      forceCell.append(gated(h('button', { class: 'small', 'data-testid': `unforce-${row.name}`, disabled: !isForced, onclick: () => void force(null) }, tr('Unforce')), 'force'));
    }

    const actions = h('td', { class: 'actions' });
    if (row.type === 'PID' && !row.member) {
      actions.append(h('button', { class: 'small', 'data-testid': `tag-faceplate-${row.name}`, onclick: () => openFaceplate(this.ctx, row.name) }, tr('Faceplate')), ' ');
    }
    if (t && t.access !== 'readonly' && !t.name.includes(':')) {
      actions.append(
        gated(h('button', { class: 'small', 'data-testid': `tag-def-edit-${row.name}`, onclick: () => void this.openForm(row.name) }, tr('Edit')), 'tags'),
        gated(h('button', { class: 'small danger', 'data-testid': `tag-def-delete-${row.name}`, onclick: () => void this.deleteDef(row.name) }, tr('Delete')), 'tags'),
      );
    }
    return h(
      'tr',
      { class: `${row.member ? 'member' : ''} access-${row.access}`, 'data-testid': `tag-row-${row.name}` },
      h('td', { class: 'name' }, row.name),
      h('td', null, row.type),
      h('td', null, t?.address ?? ''),
      valueCell,
      forceCell,
      h('td', { class: 'desc', title: t?.description || undefined }, t?.description ?? ''),
      actions,
    );
  }

  // ---- definitions (tags.csv) --------------------------------------------------

  private async loadFile(): Promise<TagsFile> {
    this.file = parseTagsCsv(await api.tagsCsv());
    return this.file;
  }

  /**
   * "Browse OPC UA…" when the project has [[opcua_server]] entries: a node's
   * binding line for alba.toml, for the tag being edited (docs/protocols.md, "Browse").
   */
  private browseButton(tag: () => string): HTMLButtonElement | null {
    const servers = () => (this.ctx.live.status?.connections ?? []).filter((c) => c.protocol === 'opcua');
    if (servers().length === 0) return null;
    const b = h('button', { 'data-testid': 'tag-form-browse-opcua', title: tr('Pick a variable of an OPC UA server: its node id and the binding line for alba.toml') }, tr('Browse OPC UA…'));
    b.onclick = () => void openOpcuaBrowser({ connections: servers(), tag: tag(), dir: 'in', notify: (m, k) => this.ctx.notify(m, k) });
    return gated(b, 'browse');
  }

  /** The test id of the button that opened the form: the focus goes back to it when the form closes. */
  private formOpener = '';

  private async openForm(name: string | null): Promise<void> {
    this.formOpener = (document.activeElement as HTMLElement | null)?.dataset.testid ?? '';
    const file = await this.loadFile();
    const idx = name === null ? -1 : file.defs.findIndex((d) => d.name.toUpperCase() === name.toUpperCase());
    const def: TagDef = idx >= 0 ? { ...file.defs[idx] } : { name: '', type: 'BOOL', address: '', initial: '', retain: '', description: '' };
    const field = (k: keyof TagDef, label: string, input: HTMLInputElement | HTMLSelectElement) => {
      input.setAttribute('data-testid', `tag-form-${k}`);
      return h('label', null, h('span', null, label), input);
    };
    const nameIn = h('input', { value: def.name, autocomplete: 'off' });
    const typeIn = h('select', null, domain().types.map(({ name: t }) => h('option', { value: t, selected: t === def.type.toUpperCase() }, t)));
    const addrIn = h('input', { value: def.address, placeholder: tr('internal, or DI:1/0, %QX0.1, AI:3/0…') });
    const initIn = h('input', { value: def.initial });
    const retainIn = h('input', { type: 'checkbox', checked: /^(1|true|yes)$/i.test(def.retain) });
    const descIn = h('input', { value: def.description, size: 40 });
    const err = h('div', { class: 'inline-error', 'data-testid': 'tag-form-error', hidden: true });
    const save = async () => {
      const nd: TagDef = {
        name: nameIn.value.trim(),
        type: typeIn.value,
        address: addrIn.value.trim(),
        initial: initIn.value.trim(),
        retain: retainIn.checked ? '1' : '',
        description: descIn.value,
      };
      const others = file.defs.filter((_, k) => k !== idx);
      const problem = validateDef(nd, others);
      if (problem) {
        err.hidden = false;
        err.textContent = problem;
        return;
      }
      const defs = [...file.defs];
      if (idx >= 0) defs[idx] = nd;
      else defs.push(nd);
      const next = { columns: file.columns, defs };
      if (await this.putCsv(tagsCsv(next), idx >= 0 ? tr('Tag {name} changed', { name: nd.name }) : tr('Tag {name} added', { name: nd.name }), next)) this.closeForm();
    };
    clear(this.formEl);
    this.formEl.append(
      h('h3', null, idx >= 0 ? tr('Edit {name}', { name: def.name }) : tr('New tag')),
      h('div', { class: 'fields' },
        field('name', tr('Name'), nameIn),
        field('type', tr('Type'), typeIn),
        field('address', tr('Address'), addrIn),
        field('initial', tr('Initial'), initIn),
        field('retain', tr('Retain'), retainIn),
        field('description', tr('Description'), descIn)),
      err,
      h('div', { class: 'buttons' },
        h('button', { class: 'primary', 'data-testid': 'tag-form-save', onclick: () => void save() }, tr('Save to tags.csv')),
        h('button', { 'data-testid': 'tag-form-cancel', onclick: () => this.closeForm() }, tr('Cancel')),
        this.browseButton(() => nameIn.value.trim())),
    );
    this.formEl.hidden = false;
    nameIn.focus();
  }

  private closeForm(): void {
    this.formEl.hidden = true;
    clear(this.formEl);
    const back = this.formOpener && this.el.querySelector<HTMLElement>(`[data-testid="${CSS.escape(this.formOpener)}"]`);
    (back || this.el.querySelector<HTMLElement>('[data-testid="tag-add"]'))?.focus();
  }

  private async deleteDef(name: string): Promise<void> {
    const sure = await confirmAction(
      tr('Delete the tag {name}?', { name }),
      tr('It is removed from tags.csv. If a program still uses it, nothing is saved and the problems are listed.'),
      tr('Delete'),
    );
    if (!sure) return;
    const file = await this.loadFile();
    const defs = file.defs.filter((d) => d.name.toUpperCase() !== name.toUpperCase());
    const next = { columns: file.columns, defs };
    await this.putCsv(tagsCsv(next), tr('Tag {name} deleted', { name }), next);
  }

  /** PUT /api/tags.csv; shows the diagnostics (with the row they point at) on failure. */
  private async putCsv(text: string, done: string, file?: TagsFile): Promise<boolean> {
    clear(this.diagEl);
    try {
      await api.saveTagsCsv(text);
      this.ctx.notify(done);
      await this.ctx.tags.refresh();
      return true;
    } catch (e) {
      const err = e instanceof ApiError ? e : new ApiError(0, String(e));
      const lines = file ? lineOfDefs(file) : [];
      const rowName = (d: Diagnostic) => {
        if (!file || d.line === null) return '';
        const k = lines.indexOf(d.line);
        return k >= 0 ? ` (${tr('tag {name}', { name: file.defs[k].name || '#' + (k + 1) })})` : '';
      };
      this.diagEl.append(h('li', { class: 'problem head' }, tr('tags.csv not saved: {m}', { m: err.message })));
      err.diagnostics.forEach((d, k) =>
        this.diagEl.append(
          h('li', { class: 'problem', 'data-testid': `tags-diagnostic-${k}` },
            h('span', { class: 'code' }, d.code), ' ',
            d.file ? `${d.file}:${d.line ?? ''}:${d.col ?? ''} ` : '',
            d.message, rowName(d), d.help ? ` — ${d.help}` : ''),
        ),
      );
      this.ctx.notify(tr('tags.csv not saved: {m}', { m: err.message }), 'error');
      return false;
    }
  }
}
