// The Alarms tab (issue 17, item 7): the alarm summary — every alarm not in
// `normal`, with its severity named and coloured, filtered by text, sorted by
// severity, time or name — with acknowledge (one, or every unacknowledged
// alarm shown), shelve (a dialog: minutes and a reason; the row then says
// until when and why) and unshelve, the counts and the flood state of the
// standard's guidance, and the log page (alarmLog.ts). Refreshed on every
// `alarms` summary of the WebSocket, and so is the log while it follows now.
import { api } from '../api';
import { can, gate } from '../auth';
import type { Ctx } from '../ctx';
import { add, clear, h, searchBox } from '../dom';
import { tr, when } from '../i18n';
import type { Alarm } from '../types';
import { AlarmLog } from './alarmLog';
import { alarmText, band } from './alarms';
import { shelveDialog } from './shelve';

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
  private readonly filter = searchBox(tr('Filter by id, tag, message, state'), 'alarms-filter');
  private readonly sort = h('select', { 'data-testid': 'alarms-sort' },
    h('option', { value: 'severity' }, tr('most severe first')),
    h('option', { value: 'time' }, tr('newest first')),
    h('option', { value: 'id' }, tr('by name')));
  private readonly body = h('tbody');
  private readonly stats = h('span', { class: 'alarm-stats', 'data-testid': 'alarms-stats' });
  private unlisten: (() => void) | null = null;
  private readonly log: AlarmLog;

  constructor(private readonly ctx: Ctx) {
    const ackPage = h('button', { 'data-testid': 'alarms-ack-page', title: tr('Acknowledge every unacknowledged alarm shown') }, tr('Acknowledge page'));
    ackPage.onclick = () => void this.ackShown();
    gate(ackPage, 'ack');
    const log = (this.log = new AlarmLog(ctx));
    log.el.hidden = true;
    const summaryPart = h('div', { class: 'alarm-summary-part' });
    const page = h('select', { 'data-testid': 'alarms-page' }, h('option', { value: 'summary' }, tr('Summary')), h('option', { value: 'log' }, tr('Log')));
    page.onchange = () => {
      log.el.hidden = page.value !== 'log';
      summaryPart.hidden = page.value === 'log';
      if (page.value === 'log') void log.load();
    };
    this.filter.addEventListener('input', () => this.render());
    this.sort.addEventListener('change', () => this.render());
    add(summaryPart,
      h('div', { class: 'toolbar' }, this.filter, this.sort, ackPage, this.stats),
      h('table', { class: 'tags alarm-summary', 'data-testid': 'alarms-table' },
        h('thead', null, h('tr', null, [tr('Severity'), tr('Alarm'), tr('Tag'), tr('Message'), tr('State'), tr('Since'), ''].map((c) => h('th', null, c)))),
        this.body));
    this.el = h('section', { class: 'alarms-view', 'data-testid': 'alarms-view' }, h('div', { class: 'toolbar' }, page), summaryPart, log.el);
  }

  show(): void {
    void this.refresh();
    this.unlisten = this.ctx.live.onBatch((b) => {
      if (!b.alarms) return;
      void this.refresh();
      this.log.changed();
    });
  }

  hide(): void {
    this.unlisten?.();
    this.unlisten = null;
  }

  private async refresh(): Promise<void> {
    try {
      const [alarms, st] = await Promise.all([api.alarms(), api.alarmStats()]);
      this.alarms = alarms;
      this.stats.textContent = tr('{active} active, {unacked} to acknowledge, {shelved} shelved; {n} new in 10 minutes', { active: st.active, unacked: st.unacked, shelved: st.shelved, n: st.new_10min });
      this.stats.classList.toggle('flood', st.flood);
      if (st.flood) this.stats.textContent += ` — ${alarmText.flood}`;
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

  private render(): void {
    clear(this.body);
    const rows = this.shown();
    if (rows.length === 0) this.body.append(h('tr', null, h('td', { colspan: 7, class: 'hint' }, alarmText.none)));
    for (const a of rows) {
      const unacked = a.state === 'active_unacked' || a.state === 'cleared_unacked';
      const ack = h('button', { class: 'small', 'data-testid': `alarms-ack-${a.id}`, hidden: !unacked }, alarmText.ack);
      ack.onclick = () => void this.act(() => api.ackAlarm(a.id, ''));
      gate(ack, 'ack');
      const shelved = a.state === 'shelved';
      const shelve = h('button', { class: 'small', 'data-testid': `alarms-shelve-${a.id}` }, shelved ? tr('Unshelve') : tr('Shelve'));
      shelve.onclick = async () => {
        if (shelved) return void this.act(() => api.unshelveAlarm(a.id));
        const done = await shelveDialog(a, async (minutes, reason) => {
          try {
            await api.shelveAlarm(a.id, minutes, reason);
            return null;
          } catch (e) {
            return e instanceof Error ? e.message : String(e);
          }
        });
        if (done) await this.refresh();
      };
      gate(shelve, 'ack');
      const b = band(a.severity);
      // a shelved alarm says until when, why, and who shelved it
      const shelving = shelved
        ? h('div', { class: 'shelving', 'data-testid': `alarms-shelved-${a.id}` },
            a.shelved_until_ms !== null ? tr('until {time}', { time: when(a.shelved_until_ms) }) : null,
            a.reason ? ` — ${a.reason}` : null,
            a.by ? ` (${a.by})` : null)
        : null;
      this.body.append(
        h('tr', { 'data-testid': `alarms-row-${a.id}`, 'data-band': b, class: `band-${b}` },
          h('td', { class: 'sev' }, h('span', { class: `sev-badge band-${b}`, title: tr('severity {n}', { n: a.severity }) }, alarmText.band[b])),
          h('td', null, a.id),
          h('td', null, a.tag),
          h('td', null, a.message),
          h('td', null, alarmText.state[a.state] ?? a.state, shelving),
          h('td', null, when(a.since_ms)),
          h('td', null, ack, ' ', can('ack') || shelved ? shelve : null)),
      );
    }
  }
}
