// The alarm log page (issue 17, item 7): every change of state of every alarm
// from the persistent log (GET /api/alarms/log.csv) for a time range, with a
// filter on alarm, tag, state, user and comment, and the range exported as
// CSV. The CSV the server streams is the one format; the page parses it. The
// range ends "now" unless the user picks an end (issue 30, item 5): then the
// page follows every change of an alarm's state, the user's own
// acknowledgements and shelvings included.
import { api } from '../api';
import type { Ctx } from '../ctx';
import { clear, download, h, searchBox } from '../dom';
import { dateTime, tr } from '../i18n';
import { alarmText } from './alarms';

/** Rows shown at most (the export has them all). */
const SHOWN = 2000;

/** The records of an RFC 4180 text (quoted fields, doubled quotes, CRLF or LF). */
export function parseCsv(text: string): string[][] {
  const rows: string[][] = [];
  let row: string[] = [];
  let field = '';
  let quoted = false;
  for (let i = 0; i < text.length; i++) {
    const c = text[i];
    if (quoted) {
      if (c === '"' && text[i + 1] === '"') (field += '"'), i++;
      else if (c === '"') quoted = false;
      else field += c;
    } else if (c === '"') quoted = true;
    else if (c === ',') row.push(field), (field = '');
    else if (c === '\n' || c === '\r') {
      if (c === '\r' && text[i + 1] === '\n') i++;
      row.push(field);
      rows.push(row);
      (row = []), (field = '');
    } else field += c;
  }
  if (field !== '' || row.length) rows.push([...row, field]);
  return rows;
}

/** The log's records as objects by column name, those matching `filter` (alarm, tag, states, user, comment, message). */
export function logRows(csv: string, filter: string): Record<string, string>[] {
  const [head, ...records] = parseCsv(csv);
  if (!head) return [];
  const f = filter.trim().toLowerCase();
  return records
    .map((r) => Object.fromEntries(head.map((k, i) => [k, r[i] ?? ''])))
    .filter((r) => !f || [r.alarm, r.tag, r.from, r.to, r.user, r.comment, r.message].join(' ').toLowerCase().includes(f));
}

/**
 * The shift report of the range (GET /api/reports/shift.xlsx or .pdf): from the
 * start, to the end or now; null without a start or with an end before it.
 */
export function reportUrl(ext: 'xlsx' | 'pdf', from: number, to: number): string | null {
  if (!Number.isFinite(from) || !Number.isFinite(to) || to < from) return null;
  return `/api/reports/shift.${ext}?from=${Math.floor(from)}&to=${Math.ceil(to)}`;
}

const local = (ms: number) => {
  const d = new Date(ms - new Date(ms).getTimezoneOffset() * 60_000);
  return d.toISOString().slice(0, 16);
};

/** A state as the summary names it (the log keeps the API's names). */
const state = (s: string) => alarmText.state[s as keyof typeof alarmText.state] ?? s;

export class AlarmLog {
  readonly el: HTMLElement;
  private readonly from = h('input', { type: 'datetime-local', 'data-testid': 'alarm-log-from' });
  private readonly to = h('input', { type: 'datetime-local', 'data-testid': 'alarm-log-to', hidden: true });
  /** The range ends now, and the page follows new events. */
  private readonly now = h('input', { type: 'checkbox', checked: true, 'data-testid': 'alarm-log-now' });
  private reloadTimer: ReturnType<typeof setTimeout> | null = null;
  private readonly filter = searchBox(tr('Filter by alarm, tag, state, user, comment'), 'alarm-log-filter');
  private readonly count = h('span', { class: 'hint', 'data-testid': 'alarm-log-count' });
  private readonly body = h('tbody');
  private csv = '';

  constructor(private readonly ctx: Ctx) {
    this.from.value = local(Date.now() - 86_400_000);
    this.now.addEventListener('change', () => {
      this.to.hidden = this.now.checked;
      if (!this.now.checked && !this.to.value) this.to.value = local(Date.now() + 60_000);
      void this.load();
    });
    const load = h('button', { 'data-testid': 'alarm-log-load' }, tr('Show'));
    load.onclick = () => void this.load();
    const exp = h('button', { 'data-testid': 'alarm-log-export', title: tr('The whole range as CSV') }, tr('Export CSV'));
    exp.onclick = () => void this.export();
    const report = (ext: 'xlsx' | 'pdf', label: string) => {
      const a = h('a', { class: 'button', 'data-testid': `alarm-log-report-${ext}`, download: `shift-report.${ext}`, title: tr('Alarm KPIs (EEMUA 191) and trend statistics of the range') }, label);
      // The range as it is when clicked (the end "now" moves).
      a.addEventListener('click', (ev) => {
        const ms = (i: HTMLInputElement) => (i.value ? new Date(i.value).getTime() : NaN);
        const url = reportUrl(ext, ms(this.from), this.now.checked ? Date.now() : ms(this.to));
        if (url) a.href = url;
        else {
          ev.preventDefault();
          this.ctx.notify(tr('Choose a start before the end of the range'), 'error');
        }
      });
      return a;
    };
    this.filter.addEventListener('input', () => this.render());
    this.el = h('section', { class: 'alarm-log', 'data-testid': 'alarm-log' },
      h('div', { class: 'toolbar' }, h('label', null, tr('From'), ' ', this.from), h('label', null, tr('To'), ' ', this.to), h('label', { title: tr('The range ends now and the page shows new events as they happen') }, this.now, tr('now')), load, this.filter, exp, report('xlsx', tr('Shift report (XLSX)')), report('pdf', tr('Shift report (PDF)')), this.count),
      h('table', { class: 'tags', 'data-testid': 'alarm-log-table' },
        h('thead', null, h('tr', null, [tr('Time'), tr('Alarm'), tr('Tag'), tr('From'), tr('To'), tr('Value'), tr('User'), tr('Comment')].map((c) => h('th', null, c)))),
        this.body));
  }

  private range(): string {
    const ms = (i: HTMLInputElement) => (i.value ? new Date(i.value).getTime() : NaN);
    const [a, b] = [ms(this.from), this.now.checked ? NaN : ms(this.to)];
    return [Number.isFinite(a) ? `from=${a}` : '', Number.isFinite(b) ? `to=${b}` : ''].filter(Boolean).join('&');
  }

  /** An alarm changed state: shown at once while the page follows now (a burst of changes reads once). */
  changed(): void {
    if (this.el.hidden || !this.now.checked || this.reloadTimer) return;
    this.reloadTimer = setTimeout(() => {
      this.reloadTimer = null;
      void this.load();
    }, 300);
  }

  async load(): Promise<void> {
    try {
      this.csv = await api.text(`/api/alarms/log.csv?${this.range()}`);
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
      return;
    }
    this.render();
  }

  private async export(): Promise<void> {
    try {
      download('alarms.csv', await api.text(`/api/alarms/log.csv?${this.range()}`), true);
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
    }
  }

  private render(): void {
    clear(this.body);
    const rows = logRows(this.csv, this.filter.value).reverse();
    this.count.textContent = rows.length > SHOWN ? tr('newest {n} of {m} events', { n: SHOWN, m: rows.length }) : tr('{n} events', { n: rows.length });
    for (const r of rows.slice(0, SHOWN))
      this.body.append(h('tr', { 'data-testid': `alarm-log-row-${r.id}` },
        [dateTime(Number(r.time_ms)), r.alarm, r.tag, state(r.from), state(r.to), r.value, r.user, r.comment].map((c) => h('td', null, c))));
  }
}
