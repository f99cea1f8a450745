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
    // the flood alone, not "0 alarms to acknowledge — alarm flood" (issue 30, item 23)
    expect(b.el.querySelector('[data-testid=alarm-text]')?.textContent).toBe(alarmText.flood);
  });

  it('names the severity band in its list, not the number (issue 30, item 22)', async () => {
    const list = [alarm(), alarm({ id: 'level_hi', severity: 750, state: 'active_unacked' })];
    vi.stubGlobal('fetch', vi.fn(async () => new Response(JSON.stringify(list), { status: 200 })));
    const b = new AlarmBanner(() => undefined);
    await b.update(stats({ unacked: 2 }));
    const sev = (id: string) => b.el.querySelector(`[data-testid=alarm-row-${id}] .sev`)!;
    expect(sev('estop').textContent).toBe('critical');
    expect(sev('level_hi').textContent).toBe('high');
    expect(sev('level_hi').getAttribute('title')).toBe('severity 750');
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

/** A Ctx over a LiveClient that never connects, with the toasts collected. */
async function fakeCtx() {
  const { LiveClient } = await import('../src/live/client');
  const { TagCache } = await import('../src/ctx');
  const toasts: string[] = [];
  const live = new LiveClient('ws://127.0.0.1:1/none');
  return { ctx: { live, tags: new TagCache(), notify: (m: string) => toasts.push(m) } as never, live, toasts };
}

describe('the alarm summary page (issue 30, items 14 and 22)', () => {
  afterEach(() => document.body.replaceChildren());

  it('names and colours each severity, and says until when and why an alarm is shelved', async () => {
    const until = Date.now() + 30 * 60_000;
    const list = [
      alarm({ id: 'level_hi', severity: 750, state: 'active_unacked' }),
      alarm({ id: 'pump_fail', severity: 500, state: 'shelved', shelved_until_ms: until, reason: 'maintenance on P1', by: 'ana' }),
    ];
    vi.stubGlobal('fetch', vi.fn(async (url: string) => new Response(JSON.stringify(String(url).endsWith('/stats') ? stats() : list), { status: 200 })));
    const { AlarmsView } = await import('../src/ui/alarmsView');
    const { when } = await import('../src/i18n');
    const { ctx } = await fakeCtx();
    const v = new AlarmsView(ctx);
    document.body.append(v.el);
    v.show();
    await vi.waitFor(() => expect(v.el.querySelector('[data-testid=alarms-row-level_hi]')).not.toBeNull());
    expect([...v.el.querySelectorAll('[data-testid=alarms-table] th')].map((th) => th.textContent)[0]).toBe('Severity');
    const badge = v.el.querySelector('[data-testid=alarms-row-level_hi] .sev-badge')!;
    expect(badge.textContent).toBe('high');
    expect(badge.classList.contains('band-high')).toBe(true);
    expect(v.el.querySelector('[data-testid=alarms-shelved-pump_fail]')!.textContent).toBe(`until ${when(until)} — maintenance on P1 (ana)`);
    v.hide();
  });

  it('shelves from one in-page dialog that checks the minutes and the reason, and shows the refusal', async () => {
    const posts: unknown[] = [];
    let refuse = true;
    vi.stubGlobal('fetch', vi.fn(async (url: string, init?: RequestInit) => {
      if (init?.method === 'POST') {
        posts.push(JSON.parse(String(init.body)));
        if (refuse) return new Response(JSON.stringify({ error: 'the alarm log cannot be written' }), { status: 500 });
        return new Response(JSON.stringify(alarm()), { status: 200 });
      }
      return new Response(JSON.stringify(String(url).endsWith('/stats') ? stats() : [alarm()]), { status: 200 });
    }));
    const prompt = vi.fn();
    vi.stubGlobal('prompt', prompt);
    const { AlarmsView } = await import('../src/ui/alarmsView');
    const { ctx } = await fakeCtx();
    const v = new AlarmsView(ctx);
    document.body.append(v.el);
    v.show();
    await vi.waitFor(() => expect(v.el.querySelector('[data-testid=alarms-shelve-estop]')).not.toBeNull());
    (v.el.querySelector('[data-testid=alarms-shelve-estop]') as HTMLButtonElement).click();
    const q = <T extends Element>(id: string) => document.querySelector<T & HTMLElement>(`[data-testid=${id}]`)!;
    expect(q('shelve-dialog')).not.toBeNull();
    expect(q('shelve-until').textContent).toMatch(/^until /);
    const minutes = q<HTMLInputElement>('shelve-minutes') as HTMLInputElement;
    const reason = q<HTMLInputElement>('shelve-reason') as HTMLInputElement;
    const submit = () => q('shelve-ok').click();
    // no reason: said, nothing sent
    submit();
    expect(q('shelve-error').hidden).toBe(false);
    expect(q('shelve-error').textContent).toBe('Say why the alarm is shelved.');
    // minutes out of range or not whole: said, nothing sent
    reason.value = 'maintenance on P1';
    for (const bad of ['0', '10081', '1.5', '']) {
      minutes.value = bad;
      submit();
      expect(q('shelve-error').textContent, bad).toBe('Shelve for 1 to 10080 whole minutes.');
    }
    expect(posts).toEqual([]);
    // the server's refusal stays in the dialog
    minutes.value = '5';
    submit();
    await vi.waitFor(() => expect(q('shelve-error').textContent).toBe('the alarm log cannot be written'));
    expect(q('shelve-dialog')).not.toBeNull();
    refuse = false;
    submit();
    await vi.waitFor(() => expect(document.querySelector('[data-testid=shelve-dialog]')).toBeNull());
    expect(posts).toEqual([{ minutes: 5, reason: 'maintenance on P1' }, { minutes: 5, reason: 'maintenance on P1' }]);
    expect(prompt).not.toHaveBeenCalled();
    // Escape cancels without sending
    (v.el.querySelector('[data-testid=alarms-shelve-estop]') as HTMLButtonElement).click();
    document.dispatchEvent(new KeyboardEvent('keydown', { key: 'Escape' }));
    expect(document.querySelector('[data-testid=shelve-dialog]')).toBeNull();
    expect(posts.length).toBe(2);
    v.hide();
  });
});

describe('the alarm log page (issue 30, item 5)', () => {
  afterEach(() => {
    vi.useRealTimers();
    document.body.replaceChildren();
  });

  it('ends its range now, not when the tab was opened, and follows new events', async () => {
    const urls: string[] = [];
    vi.stubGlobal('fetch', vi.fn(async (url: string) => {
      urls.push(String(url));
      return new Response('id,time_ms,time_utc,alarm,tag,from,to,value,severity,user,comment,message\n', { status: 200 });
    }));
    vi.useFakeTimers({ toFake: ['Date', 'setTimeout', 'clearTimeout'] });
    vi.setSystemTime(new Date(2026, 5, 12, 9, 0));
    const { AlarmLog } = await import('../src/ui/alarmLog');
    const { ctx } = await fakeCtx();
    const log = new AlarmLog(ctx);
    document.body.append(log.el);
    // an hour later the user acknowledges, then looks at the log
    vi.setSystemTime(new Date(2026, 5, 12, 10, 0));
    await log.load();
    const u = new URL(urls[0], 'http://x');
    expect(u.searchParams.get('to')).toBeNull();
    expect(Number(u.searchParams.get('from'))).toBe(new Date(2026, 5, 11, 9, 0).getTime());
    // a change of an alarm's state reloads the page (once for a burst)
    log.changed();
    log.changed();
    await vi.advanceTimersByTimeAsync(400);
    expect(urls.length).toBe(2);
    // an end picked by the user stops the following
    const now = log.el.querySelector<HTMLInputElement>('[data-testid=alarm-log-now]')!;
    now.checked = false;
    now.dispatchEvent(new Event('change'));
    await vi.advanceTimersByTimeAsync(0);
    expect(new URL(urls[2], 'http://x').searchParams.get('to')).not.toBeNull();
    log.changed();
    await vi.advanceTimersByTimeAsync(400);
    expect(urls.length).toBe(3);
  });
});
