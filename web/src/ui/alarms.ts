// The alarm banner on every page (docs/alarms.md): hidden while no alarm waits
// for an acknowledgement; otherwise the most severe unacknowledged alarm and
// how many there are, and a button that opens the list of alarms not in
// `normal` with an Acknowledge button each (operator and up). Driven by the
// WebSocket's `alarms` summary; the list is fetched when it changes.
import { api } from '../api';
import { gate } from '../auth';
import { clear, h, s } from '../dom';
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
  soundOn: tr('Sound on'),
  muted: tr('Muted'),
  soundOnTitle: tr('New alarms sound in this browser (a tone per severity): click to mute'),
  mutedTitle: tr('New alarms are silent in this browser: click to turn the sound on'),
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

/** A bell (crossed out while muted), drawn: a font may have no emoji. */
function bell(muted: boolean): SVGSVGElement {
  return s('svg', { class: `bell${muted ? ' muted' : ''}`, viewBox: '0 0 16 16', width: 13, height: 13, 'aria-hidden': 'true' },
    s('path', { d: 'M8 1.5a1 1 0 0 1 1 1v.6a4.5 4.5 0 0 1 3.5 4.4v3l1.5 2H2l1.5-2v-3A4.5 4.5 0 0 1 7 3.1v-.6a1 1 0 0 1 1-1zM6.3 13.5h3.4a1.7 1.7 0 0 1-3.4 0z' }),
    muted ? s('line', { x1: 1.5, y1: 1.5, x2: 14.5, y2: 14.5 }) : null);
}

export class AlarmBanner {
  readonly el: HTMLElement;
  private readonly text = h('span', { class: 'alarm-text', 'data-testid': 'alarm-text' });
  private readonly list = h('table', { class: 'alarm-list', 'data-testid': 'alarm-list', hidden: true });
  private readonly toggle = h('button', { class: 'small', 'data-testid': 'alarm-toggle' }, alarmText.show);
  private readonly muteBtn = h('button', { class: 'small mute', 'data-testid': 'alarm-mute' });
  private alarms: Alarm[] = [];
  /** New alarms in the last summary (`new_10min`), to sound only for new ones. */
  private seen: number | null = null;

  constructor(
    private readonly notify: (m: string, kind?: 'info' | 'error') => void,
    private readonly sound: (b: ReturnType<typeof band>) => void = tone,
  ) {
    this.el = h('div', { class: 'alarm-banner', 'data-testid': 'alarm-banner', role: 'alert', hidden: true }, this.text, this.muteBtn, this.toggle, this.list);
    // the button shows the state the sound is in (a crossed bell while muted); a click changes it
    const showMute = () => {
      const m = this.muted;
      this.muteBtn.replaceChildren(bell(m), h('span', { class: 'word' }, ` ${m ? alarmText.muted : alarmText.soundOn}`));
      this.muteBtn.title = m ? alarmText.mutedTitle : alarmText.soundOnTitle;
      this.muteBtn.setAttribute('aria-pressed', String(m));
    };
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
    this.text.title = this.text.textContent;
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
