// The status bar: run state, scan times, overruns, store problems
// (retentive data lost, history not recorded, disk below its floor), the
// health of each client connection to a remote server ([[opcua_server]]),
// the studio's connection, the user and role, and the logout.
import { type Me, whoLabel } from '../auth';
import type { ConnState } from '../live/client';
import { h } from '../dom';
import type { Connection, QueueCounters, Status } from '../types';
import { tr } from '../i18n';

/** The strings of the status bar that are not field values. */
const text = {
  signOut: tr('Sign out'),
  signOutTitle: tr('End the session'),
  storeProblems: (n: number) => (n === 1 ? tr('1 storage problem') : tr('{n} storage problems', { n })),
  retainLost: tr('retentive data lost'),
  notLive: tr('not live'),
  state: { running: tr('running'), stopped: tr('stopped'), faulted: tr('faulted') } as Record<string, string>,
  remoteOk: (c: Connection) => tr('{name}: connected to {endpoint}', { name: c.name, endpoint: c.endpoint }),
  remoteRefused: (c: Connection, error: string) =>
    tr('{name}: connected to {endpoint}, but: {error}', { name: c.name, endpoint: c.endpoint, error }),
  remoteDown: (c: Connection, error: string) => tr('{name}: {endpoint} is down: {error}', { name: c.name, endpoint: c.endpoint, error }),
  queue: (q: QueueCounters) =>
    tr('{published} published, {coalesced} coalesced, {dropped} dropped', {
      published: q.published,
      coalesced: q.coalesced,
      dropped: q.dropped,
    }),
  buffered: (q: QueueCounters) => tr('{buffered} buffered, {replayed} replayed', { buffered: q.buffered, replayed: q.replayed }),
  conn: { connecting: tr('connecting'), connected: tr('connected'), reconnecting: tr('reconnecting') } as Record<string, string>,
};

export class StatusBar {
  readonly el: HTMLElement;
  private readonly fields: Record<string, Text> = {};
  private readonly spans: Record<string, HTMLElement> = {};
  private lastState = '';
  private notLive = false;
  private readonly conns = h('span', { class: 'status-item conns', 'data-testid': 'status-connections', hidden: true });
  private connsKey = '';
  private readonly logoutBtn = h('button', { class: 'small link', 'data-testid': 'btn-logout', title: text.signOutTitle, hidden: true }, text.signOut);

  constructor() {
    const field = (key: string, label: string, title?: string) => {
      const t = document.createTextNode('—');
      this.fields[key] = t;
      const span = h('span', { class: `field ${key}`, 'data-testid': `status-${key}` }, t);
      this.spans[key] = span;
      return h('span', { class: 'status-item', title }, label ? h('span', { class: 'label' }, label) : null, span);
    };
    this.el = h(
      'footer',
      { class: 'statusbar', 'data-testid': 'statusbar' },
      field('state', '', tr('The state of the PLC (not live: the runtime does not answer)')),
      field('scan-last', tr('scan'), tr('How long the last scan took')),
      field('scan-max', tr('max'), tr('The longest scan since the start')),
      field('overruns', tr('overruns'), tr('Scans that took longer than the scan period')),
      field('scans', tr('scans'), tr('Scans since the start')),
      field('fault', ''),
      field('store', ''),
      this.conns,
      h('span', { class: 'spacer' }),
      field('user', '', tr('Who uses the studio, and their role')),
      this.logoutBtn,
      field('conn', '', tr('The studio’s connection to the runtime')),
    );
  }

  private set(key: string, text: string): void {
    const t = this.fields[key];
    if (t.data !== text) t.data = text;
  }

  status(s: Status): void {
    this.lastState = s.state;
    this.showState();
    this.set('scan-last', `${s.stats.last_us} µs`);
    this.set('scan-max', `${s.stats.max_us} µs`);
    this.set('overruns', String(s.stats.overruns));
    this.set('scans', String(s.scans));
    this.set('fault', s.fault ?? '');
    this.spans.fault.hidden = !s.fault;
    // Store problems: a count, each message in the tooltip (and for
    // screen readers); hidden while all is well.
    const problems = s.problems ?? [];
    const label = [problems.length ? text.storeProblems(problems.length) : '', s.retain_lost ? text.retainLost : '']
      .filter(Boolean)
      .join(' · ');
    this.set('store', label);
    this.spans.store.hidden = !label;
    this.spans.store.title = problems.map((p) => p.message).join('\n');
    this.spans.store.setAttribute('role', label ? 'alert' : 'none');
    this.connections(s.connections ?? []);
  }

  /**
   * Each remote server: its name, green (ok), amber (bindings refused, or
   * data held back) or red (down), why in the tooltip; the broker's
   * tooltip also counts what its queue published, coalesced and dropped.
   */
  private connections(list: Connection[]): void {
    const key = JSON.stringify(list.map((c) => [c.name, c.ok, c.connected, c.last_error, c.endpoint, c.queue]));
    if (key === this.connsKey) return;
    this.connsKey = key;
    this.conns.replaceChildren(
      ...list.map((c) => {
        const health = c.ok ? 'ok' : c.connected ? 'refused' : 'down';
        const error = c.last_error ?? '';
        const lines = [health === 'ok' ? text.remoteOk(c) : health === 'refused' ? text.remoteRefused(c, error) : text.remoteDown(c, error)];
        if (c.queue) {
          lines.push(text.queue(c.queue));
          if (c.queue.buffered || c.queue.replayed) lines.push(text.buffered(c.queue));
        }
        const title = lines.join('\n');
        return h('span', { class: 'remote', 'data-testid': `status-remote-${c.name}`, 'data-health': health, title, 'aria-label': title }, c.name);
      }),
    );
    this.conns.hidden = list.length === 0;
  }

  /** While the data is stale the run state is unknown: the field says so instead of a frozen "running". */
  stale(on: boolean): void {
    this.notLive = on;
    this.showState();
  }

  private showState(): void {
    const state = this.notLive ? text.notLive : (text.state[this.lastState] ?? this.lastState);
    this.set('state', state);
    this.spans.state.dataset.state = this.notLive ? 'stale' : this.lastState;
  }

  /** The user and role ("alice (operator)", or "local, no users"); sign-out only with users. */
  user(me: Me): void {
    this.set('user', whoLabel(me));
    this.spans.user.dataset.role = me.role;
    this.logoutBtn.hidden = !me.users;
  }

  onLogout(f: () => void): void {
    this.logoutBtn.onclick = f;
  }

  conn(c: ConnState): void {
    this.set('conn', text.conn[c] ?? c);
    this.spans.conn.dataset.conn = c;
  }
}
