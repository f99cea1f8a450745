// The Alarms tab (issue 17, item 7): the alarm summary — every alarm not in
// `normal`, filtered by text, sorted by severity, time or name — with
// acknowledge (one, or every unacknowledged alarm shown), shelve (minutes and
// a reason) and unshelve, and the log as CSV for a time range. Refreshed on
// every `alarms` summary of the WebSocket.
import { api } from '../api';
import { can, gate } from '../auth';
import type { Ctx } from '../ctx';
import { clear, download, h } from '../dom';
import { clockTime, tr } from '../i18n';
import type { Alarm } from '../types';
import { alarmText, band } from './alarms';

type SortKey = 'severity' | 'time' | 'id';

/** The alarms shown: those matching `filter` (id, tag, message, state), sorted. */
export function summary(alarms: Alarm[], filter: string, sort: SortKey): Alarm[] {
  const f = filter.trim().toLowerCase();
  const shown = alarms.filter((a) => !f || `${a.id} ${a.tag} ${a.message} ${a.state}`.toLowerCase().includes(f));
  const by: Record<SortKey, (a: Alarm, b: Alarm) => number> = {
    severity: (a, b) => b.severity - a.severity || b.since_ms - a.since_ms,
    time: (a, b) => b.since_ms - a.since_ms,
    id: (a, b) => a.id.localeCompare(b.id),
  };
  return shown.sort(by[sort]);
}

export class AlarmsView {
  readonly el: HTMLElement;
  private alarms: Alarm[] = [];
  private readonly filter = h('input', { type: 'search', placeholder: tr('Filter by id, tag, message, state'), 'data-testid': 'alarms-filter' });
  private readonly sort = h('select', { 'data-testid': 'alarms-sort' },
    h('option', { value: 'severity' }, tr('most severe first')),
    h('option', { value: 'time' }, tr('newest first')),
    h('option', { value: 'id' }, tr('by name')));
  private readonly body = h('tbody');
  private unlisten: (() => void) | null = null;

  constructor(private readonly ctx: Ctx) {
    const ackPage = h('button', { 'data-testid': 'alarms-ack-page', title: tr('Acknowledge every unacknowledged alarm shown') }, tr('Acknowledge page'));
    ackPage.onclick = () => void this.ackShown();
    gate(ackPage, 'ack');
    const log = h('button', { 'data-testid': 'alarms-log', title: tr('The alarm log of the last 24 hours, as CSV') }, tr('Log (CSV)'));
    log.onclick = () => void this.exportLog();
    this.filter.addEventListener('input', () => this.render());
    this.sort.addEventListener('change', () => this.render());
    this.el = h('section', { class: 'alarms-view', 'data-testid': 'alarms-view' },
      h('div', { class: 'toolbar' }, this.filter, this.sort, ackPage, log),
      h('table', { class: 'tags alarm-summary', 'data-testid': 'alarms-table' },
        h('thead', null, h('tr', null, [tr('Alarm'), tr('Tag'), tr('Message'), tr('State'), tr('Since'), ''].map((c) => h('th', null, c)))),
        this.body));
  }

  show(): void {
    void this.refresh();
    this.unlisten = this.ctx.live.onBatch((b) => b.alarms && void this.refresh());
  }

  hide(): void {
    this.unlisten?.();
    this.unlisten = null;
  }

  private async refresh(): Promise<void> {
    try {
      this.alarms = await api.alarms();
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
      return;
    }
    this.render();
  }

  private shown(): Alarm[] {
    return summary([...this.alarms], this.filter.value, this.sort.value as SortKey);
  }

  private async act(f: () => Promise<unknown>): Promise<void> {
    try {
      await f();
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
    }
    await this.refresh();
  }

  private async ackShown(): Promise<void> {
    const todo = this.shown().filter((a) => a.state === 'active_unacked' || a.state === 'cleared_unacked');
    await this.act(async () => {
      for (const a of todo) await api.ackAlarm(a.id, '');
    });
  }

  private async exportLog(): Promise<void> {
    const to = Date.now();
    try {
      download('alarms.csv', await api.text(`/api/alarms/log.csv?from=${to - 86_400_000}&to=${to}`), true);
    } catch (e) {
      this.ctx.notify(e instanceof Error ? e.message : String(e), 'error');
    }
  }

  private render(): void {
    clear(this.body);
    const rows = this.shown();
    if (rows.length === 0) this.body.append(h('tr', null, h('td', { colspan: 6, class: 'hint' }, alarmText.none)));
    for (const a of rows) {
      const unacked = a.state === 'active_unacked' || a.state === 'cleared_unacked';
      const ack = h('button', { class: 'small', 'data-testid': `alarms-ack-${a.id}`, hidden: !unacked }, alarmText.ack);
      ack.onclick = () => void this.act(() => api.ackAlarm(a.id, ''));
      gate(ack, 'ack');
      const shelved = a.state === 'shelved';
      const shelve = h('button', { class: 'small', 'data-testid': `alarms-shelve-${a.id}` }, shelved ? tr('Unshelve') : tr('Shelve'));
      shelve.onclick = () => {
        if (shelved) return void this.act(() => api.unshelveAlarm(a.id));
        const minutes = Number(prompt(tr('Shelve {id} for how many minutes?', { id: a.id }), '60'));
        const reason = prompt(tr('Why?'), '') ?? '';
        if (Number.isFinite(minutes) && minutes > 0) void this.act(() => api.shelveAlarm(a.id, minutes, reason));
      };
      gate(shelve, 'ack');
      this.body.append(
        h('tr', { 'data-testid': `alarms-row-${a.id}`, 'data-band': band(a.severity), class: `band-${band(a.severity)}` },
          h('td', null, a.id),
          h('td', null, a.tag),
          h('td', null, a.message),
          h('td', null, alarmText.state[a.state] ?? a.state),
          h('td', null, clockTime(a.since_ms)),
          h('td', null, ack, ' ', can('ack') || shelved ? shelve : null)),
      );
    }
  }
}
