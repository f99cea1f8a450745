// The alarm banner on every page (docs/alarms.md): hidden while no alarm waits
// for an acknowledgement; otherwise the most severe unacknowledged alarm and
// how many there are, and a button that opens the list of alarms not in
// `normal` with an Acknowledge button each (operator and up). Driven by the
// WebSocket's `alarms` summary; the list is fetched when it changes.
import { api } from '../api';
import { gate } from '../auth';
import { clear, h } from '../dom';
import type { Alarm, AlarmStats } from '../types';
import { tr, when } from '../i18n';

/** The strings of the banner (one place; a Spanish catalogue comes later). */
export const alarmText = {
  waiting: (n: number) => (n === 1 ? tr('1 alarm to acknowledge') : tr('{n} alarms to acknowledge', { n })),
  flood: tr('alarm flood: more than 10 new alarms in 10 minutes'),
  show: tr('Alarms'),
  hide: tr('Hide'),
  ack: tr('Acknowledge'),
  none: tr('No alarms.'),
  mute: tr('Mute'),
  unmute: tr('Sound'),
  muteTitle: tr('Sound for new alarms in this browser (a tone per severity)'),
  /** The severity bands by name (the banner and the summary say these, not the number). */
  band: { critical: tr('critical'), high: tr('high'), medium: tr('medium'), low: tr('low') },
  state: {
    active_unacked: tr('active, not acknowledged'),
    active_acked: tr('active, acknowledged'),
    cleared_unacked: tr('cleared, not acknowledged'),
    shelved: tr('shelved'),
    suppressed: tr('suppressed'),
    out_of_service: tr('out of service'),
    normal: tr('normal'),
  } as Record<string, string>,
};

/** Severity band for colour: critical ≥ 1000 > high ≥ 750 > medium ≥ 500 > low. */
export function band(severity: number): 'critical' | 'high' | 'medium' | 'low' {
  return severity >= 1000 ? 'critical' : severity >= 750 ? 'high' : severity >= 500 ? 'medium' : 'low';
}

const MUTE_KEY = 'alba.alarms.muted';

/** A short tone for a new alarm: higher and repeated for more severe bands (WebAudio). */
export function tone(b: ReturnType<typeof band>): void {
  const Ctx = (globalThis as { AudioContext?: typeof AudioContext }).AudioContext;
  if (!Ctx) return;
  const ctx = new Ctx();
  const beeps = { critical: 3, high: 2, medium: 1, low: 1 }[b];
  const freq = { critical: 1046, high: 880, medium: 660, low: 523 }[b];
  for (let k = 0; k < beeps; k++) {
    const o = ctx.createOscillator();
    const g = ctx.createGain();
    o.frequency.value = freq;
    g.gain.value = 0.15;
    o.connect(g).connect(ctx.destination);
    o.start(ctx.currentTime + k * 0.25);
    o.stop(ctx.currentTime + k * 0.25 + 0.15);
  }
  setTimeout(() => void ctx.close(), beeps * 300 + 200);
}

export class AlarmBanner {
  readonly el: HTMLElement;
  private readonly text = h('span', { class: 'alarm-text', 'data-testid': 'alarm-text' });
  private readonly list = h('table', { class: 'alarm-list', 'data-testid': 'alarm-list', hidden: true });
  private readonly toggle = h('button', { class: 'small', 'data-testid': 'alarm-toggle' }, alarmText.show);
  private readonly muteBtn = h('button', { class: 'small', 'data-testid': 'alarm-mute', title: alarmText.muteTitle });
  private alarms: Alarm[] = [];
  /** New alarms in the last summary (`new_10min`), to sound only for new ones. */
  private seen: number | null = null;

  constructor(
    private readonly notify: (m: string, kind?: 'info' | 'error') => void,
    private readonly sound: (b: ReturnType<typeof band>) => void = tone,
  ) {
    this.el = h('div', { class: 'alarm-banner', 'data-testid': 'alarm-banner', role: 'alert', hidden: true }, this.text, this.muteBtn, this.toggle, this.list);
    const showMute = () => (this.muteBtn.textContent = this.muted ? alarmText.unmute : alarmText.mute);
    showMute();
    this.muteBtn.onclick = () => {
      localStorage.setItem(MUTE_KEY, this.muted ? '0' : '1');
      showMute();
    };
    this.toggle.onclick = () => {
      this.list.hidden = !this.list.hidden;
      this.toggle.textContent = this.list.hidden ? alarmText.show : alarmText.hide;
    };
  }

  /** Sound is off for this browser (remembered). */
  get muted(): boolean {
    return localStorage.getItem(MUTE_KEY) === '1';
  }

  /** A new summary: show or hide, sound for a new alarm, and fetch the list when something waits. */
  async update(s: AlarmStats): Promise<void> {
    if (this.seen !== null && s.new_10min > this.seen && s.unacked > 0 && s.top_severity !== null && !this.muted) this.sound(band(s.top_severity));
    this.seen = s.new_10min;
    this.el.hidden = s.unacked === 0 && !s.flood;
    this.el.dataset.band = s.top_severity === null ? '' : band(s.top_severity);
    if (this.el.hidden) return;
    try {
      this.alarms = await api.alarms();
    } catch (e) {
      this.notify(e instanceof Error ? e.message : String(e), 'error');
      return;
    }
    const top = this.alarms.find((a) => a.id === s.top_unacked);
    this.text.textContent = [s.unacked ? alarmText.waiting(s.unacked) : '', top ? `${top.id}: ${top.message}` : '', s.flood ? alarmText.flood : '']
      .filter(Boolean)
      .join(' — ');
    this.render();
  }

  private render(): void {
    clear(this.list);
    if (this.alarms.length === 0) {
      this.list.append(h('tr', null, h('td', null, alarmText.none)));
      return;
    }
    for (const a of this.alarms) {
      const ack = h('button', { class: 'small', 'data-testid': `alarm-ack-${a.id}`, hidden: !a.state.endsWith('unacked') }, alarmText.ack);
      gate(ack, 'ack');
      ack.onclick = async () => {
        ack.disabled = true;
        try {
          await api.ackAlarm(a.id, '');
        } catch (e) {
          this.notify(e instanceof Error ? e.message : String(e), 'error');
          ack.disabled = false;
        }
      };
      this.list.append(
        h(
          'tr',
          { 'data-testid': `alarm-row-${a.id}`, 'data-band': band(a.severity), 'data-state': a.state },
          h('td', { class: 'sev', title: tr('severity {n}', { n: a.severity }) }, alarmText.band[band(a.severity)]),
          h('td', null, a.id),
          h('td', null, a.message),
          h('td', null, alarmText.state[a.state] ?? a.state),
          h('td', null, when(a.since_ms)),
          h('td', null, ack),
        ),
      );
    }
  }
}
