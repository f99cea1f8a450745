import { afterEach, describe, expect, it, vi } from 'vitest';
import { AlarmBanner, alarmText, band } from '../src/ui/alarms';
import type { Alarm, AlarmStats } from '../src/types';

const stats = (over: Partial<AlarmStats> = {}): AlarmStats => ({
  alarms: 3, active: 1, unacked: 1, shelved: 0, suppressed: 0, out_of_service: 0, new_10min: 1, flood: false,
  top_unacked: 'estop', top_severity: 1000, ...over,
});
const alarm = (over: Partial<Alarm> = {}): Alarm => ({
  id: 'estop', tag: 'STOP', state: 'active_unacked', severity: 1000, message: 'Emergency stop pressed', since_ms: 0,
  condition: 'rising', value: 1, active: true, acked_by: null, ack_comment: null, acked_ms: null, shelved_until_ms: null,
  reason: null, by: null, ...over,
});

afterEach(() => vi.unstubAllGlobals());

describe('the alarm banner', () => {
  it('bands severities as docs/alarms.md names them', () => {
    expect([band(1000), band(750), band(500), band(250)]).toEqual(['critical', 'high', 'medium', 'low']);
  });

  it('is hidden with nothing to acknowledge, and shows the most severe alarm otherwise', async () => {
    const list = [alarm(), alarm({ id: 'level_hi', severity: 750, message: 'Tank above 55 L', state: 'active_acked' })];
    vi.stubGlobal('fetch', vi.fn(async () => new Response(JSON.stringify(list), { status: 200 })));
    const b = new AlarmBanner(() => undefined);
    await b.update(stats({ unacked: 0, top_unacked: null, top_severity: null }));
    expect(b.el.hidden).toBe(true);
    await b.update(stats());
    expect(b.el.hidden).toBe(false);
    expect(b.el.dataset.band).toBe('critical');
    expect(b.el.querySelector('[data-testid=alarm-text]')?.textContent).toBe(`${alarmText.waiting(1)} — estop: Emergency stop pressed`);
    // One row per alarm; only the unacknowledged one can be acknowledged.
    expect(b.el.querySelectorAll('tr').length).toBe(2);
    expect((b.el.querySelector('[data-testid=alarm-ack-estop]') as HTMLButtonElement).hidden).toBe(false);
    expect((b.el.querySelector('[data-testid=alarm-ack-level_hi]') as HTMLButtonElement).hidden).toBe(true);
  });

  it('says a flood even when everything is acknowledged', async () => {
    vi.stubGlobal('fetch', vi.fn(async () => new Response('[]', { status: 200 })));
    const b = new AlarmBanner(() => undefined);
    await b.update(stats({ unacked: 0, flood: true, new_10min: 12, top_unacked: null, top_severity: null }));
    expect(b.el.hidden).toBe(false);
    expect(b.el.textContent).toContain(alarmText.flood);
  });
});

describe('the alarm sound', () => {
  it('sounds once per new alarm, by severity band, unless muted in this browser', async () => {
    vi.stubGlobal('fetch', vi.fn(async () => new Response(JSON.stringify([alarm()]), { status: 200 })));
    localStorage.removeItem('alba.alarms.muted');
    const played: string[] = [];
    const b = new AlarmBanner(() => undefined, (band) => played.push(band));
    await b.update(stats({ new_10min: 1 })); // the first summary: what was there before the page
    expect(played).toEqual([]);
    await b.update(stats({ new_10min: 2, top_severity: 750 }));
    expect(played).toEqual(['high']);
    await b.update(stats({ new_10min: 2 })); // nothing new
    expect(played).toEqual(['high']);
    const mute = b.el.querySelector('[data-testid=alarm-mute]') as HTMLButtonElement;
    // the button shows the state the sound is in
    expect([mute.textContent, mute.getAttribute('aria-pressed'), !!mute.querySelector('svg.bell:not(.muted)')]).toEqual([' Sound on', 'false', true]);
    mute.click();
    expect(b.muted).toBe(true);
    expect([mute.textContent, mute.getAttribute('aria-pressed'), !!mute.querySelector('svg.bell.muted')]).toEqual([' Muted', 'true', true]);
    expect(mute.title).toBe('New alarms are silent in this browser: click to turn the sound on');
    await b.update(stats({ new_10min: 3 }));
    expect(played).toEqual(['high']);
    localStorage.removeItem('alba.alarms.muted');
  });
});

describe('the alarm summary', () => {
  it('filters by any text of an alarm and sorts by severity, time or name', async () => {
    const { summary } = await import('../src/ui/alarmsView');
    const list = [
      alarm({ id: 'b', severity: 500, since_ms: 3, message: 'level high' }),
      alarm({ id: 'a', severity: 1000, since_ms: 1 }),
      alarm({ id: 'c', severity: 500, since_ms: 9, tag: 'Pump' }),
    ];
    expect(summary([...list], '', 'severity').map((x) => x.id)).toEqual(['a', 'c', 'b']);
    expect(summary([...list], '', 'time').map((x) => x.id)).toEqual(['c', 'b', 'a']);
    expect(summary([...list], '', 'id').map((x) => x.id)).toEqual(['a', 'b', 'c']);
    expect(summary([...list], 'PUMP', 'id').map((x) => x.id)).toEqual(['c']);
    expect(summary([...list], 'level', 'id').map((x) => x.id)).toEqual(['b']);
  });
});

describe('the PID faceplate trend', () => {
  it('scales values into the box, oldest on the left', async () => {
    const { polyline } = await import('../src/ui/faceplate');
    expect(polyline([0, 5, 10], 238, 100, 0, 10)).toBe('0.0,100.0 2.0,50.0 4.0,0.0');
    expect(polyline([3, 3], 119, 10, 3, 3)).toBe('0.0,10.0 1.0,10.0');
  });
});
