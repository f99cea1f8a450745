// The PID faceplate's gains in happy-dom: the gains the loop uses (KP KI KD,
// or KC TI TD with DEP), TI and TD labelled in the loop's unit (minutes with
// MINUTES, the SLC's, else seconds), and a gain typed in written as is, in
// that unit (docs/pid.md §2, SLC details).
import { afterEach, describe, expect, it, vi } from 'vitest';
import { setMe } from '../src/auth';
import type { Ctx } from '../src/ctx';
import { LiveClient } from '../src/live/client';
import { openFaceplate } from '../src/ui/faceplate';
import type { Json } from '../src/types';

function rig(values: Record<string, Json>) {
  const puts: [string, unknown][] = [];
  vi.stubGlobal('fetch', async (path: string, init: RequestInit) => {
    if (init.method === 'PUT') puts.push([decodeURIComponent(path), JSON.parse(init.body as string).value]);
    const body = path === '/api/alarms' ? [] : { name: path, value: 0 };
    return new Response(JSON.stringify(body), { status: 200, headers: { 'Content-Type': 'application/json' } });
  });
  setMe({ user: 'eve', role: 'engineer', users: true });
  const live = new LiveClient('ws://127.0.0.1:1/none');
  live.store.apply(new Map(Object.entries(values).map(([k, v]) => [`Loop.${k}`, v])));
  const ctx = { live, notify: () => {} } as unknown as Ctx;
  const box = openFaceplate(ctx, 'Loop');
  const shown = () => [...box.querySelectorAll('[data-testid="faceplate-gains"] input')].map((i) => (i as HTMLInputElement).dataset.testid?.replace('faceplate-gain-', ''));
  const unit = (m: string) => box.querySelector(`[data-testid="faceplate-unit-${m}"]`)?.textContent;
  return { box, live, puts, shown, unit };
}

afterEach(() => {
  vi.unstubAllGlobals();
  document.body.replaceChildren();
});

describe('the PID faceplate gains', () => {
  it('shows KP, KI, KD for independent gains and KC, TI, TD in the loop unit for dependent ones', () => {
    const r = rig({ DEP: false, MINUTES: false, KP: 5, KI: 0.8, KD: 0, KC: 2, TI: 6, TD: 0 });
    expect(r.shown()).toEqual(['KP', 'KI', 'KD']);
    expect(r.unit('KI')).toBe('1/s');
    r.live.store.apply(new Map([['Loop.DEP', true]]));
    expect(r.shown()).toEqual(['KC', 'TI', 'TD']);
    expect(r.unit('TI')).toBe('s');
    expect((r.box.querySelector('[data-testid="faceplate-gain-TI"]') as HTMLInputElement).value).toBe('6');
    r.live.store.apply(new Map<string, Json>([['Loop.MINUTES', true], ['Loop.TI', 0.1]]));
    expect(r.unit('TI')).toBe('min');
    expect(r.unit('TD')).toBe('min');
    expect((r.box.querySelector('[data-testid="faceplate-gain-TI"]') as HTMLInputElement).value).toBe('0.1');
  });

  it('writes a gain typed in as it is, in the unit shown', async () => {
    const r = rig({ DEP: true, MINUTES: true, KC: 2, TI: 0.1, TD: 0 });
    const ti = r.box.querySelector('[data-testid="faceplate-gain-TI"]') as HTMLInputElement;
    ti.value = '0.2';
    ti.dispatchEvent(new Event('change'));
    await vi.waitFor(() => expect(r.puts).toContainEqual(['/api/tags/Loop.TI', 0.2]));
  });
});

describe('the autotune panel', () => {
  it('leaves the relay centre to the loop by default (no fixed 50 %), and sends what is typed', async () => {
    const bodies: Record<string, unknown>[] = [];
    const r = rig({ DEP: false, MINUTES: false, KP: 7, KI: 1.6, KD: 0, CV: 12.16, SP: 1.52 });
    vi.stubGlobal('fetch', async (path: string, init: RequestInit) => {
      if (path.endsWith('/autotune')) bodies.push(JSON.parse(init.body as string));
      return new Response(JSON.stringify({ error: 'no' }), { status: 422, headers: { 'Content-Type': 'application/json' } });
    });
    const bias = r.box.querySelector('[data-testid="autotune-bias"]') as HTMLInputElement;
    expect(bias.value).toBe('');
    const run = r.box.querySelector('[data-testid="autotune-run"]') as HTMLButtonElement;
    run.click();
    await vi.waitFor(() => expect(bodies.length).toBe(1));
    expect(bodies[0]).toEqual({ amplitude: 10, hysteresis: 0, sp: 1.52 });
    bias.value = '30';
    await vi.waitFor(() => expect(run.disabled).toBe(false));
    run.click();
    await vi.waitFor(() => expect(bodies.length).toBe(2));
    expect(bodies[1].bias).toBe(30);
  });
});

describe('the PID faceplate at a glance (issue 30, item 23)', () => {
  it('is titled by the loop, shows its setpoint in the box, and plots % apart from the PV\'s units', async () => {
    const r = rig({ SP: 5, PV: 4.2, CV: 37, MINS: 0, MAXS: 10, MINO: 0, MAXO: 100, MAN: false });
    expect(r.box.querySelector('h2')!.textContent).toBe('Loop');
    expect(r.box.querySelector('[data-testid="faceplate-what"]')!.textContent).toBe('PID loop');
    const sp = r.box.querySelector('[data-testid="faceplate-sp-input"]') as HTMLInputElement;
    expect(sp.value).toBe('5');
    r.live.store.apply(new Map<string, Json>([['Loop.SP', 6.5]]));
    expect(sp.value).toBe('6.5');
    // two panels: SP and PV on 0–10, CV on 0–100 %
    await vi.waitFor(() => expect(r.box.querySelector('[data-part="pv-max"]')!.textContent).toBe('10'), { timeout: 2000 });
    const part = (p: string) => r.box.querySelector(`[data-part="${p}"]`)!.textContent;
    expect([part('pv-min'), part('pv-max'), part('cv-min'), part('cv-max')]).toEqual(['0', '10', '0 %', '100 %']);
    expect(r.box.querySelector('[data-testid="faceplate-trend-pv"] polyline')).not.toBeNull();
    expect(r.box.querySelectorAll('[data-testid="faceplate-trend-cv"] polyline').length).toBe(1);
  });
});

describe('the faceplate function keys (004 PID monitor)', () => {
  const key = (k: string) => document.dispatchEvent(new KeyboardEvent('keydown', { key: k, bubbles: true }));
  const parts = (box: HTMLElement) => [...box.querySelector('[data-testid="faceplate-show"]')!.children].map((c) => c.getAttribute('data-testid'));

  it('F5 shows the tank, F6 the tank and the trend, F1 the control view', () => {
    const r = rig({ MAN: false, PV: 50, MINS: 0, MAXS: 100 });
    expect(parts(r.box)).toEqual(['faceplate-trend']);
    key('F5');
    expect(parts(r.box)).toEqual(['faceplate-tank']);
    key('F6');
    expect(parts(r.box)).toEqual(['faceplate-tank', 'faceplate-trend']);
    key('F1');
    expect(parts(r.box)).toEqual(['faceplate-trend']);
  });

  it('F3 switches auto/manual and the arrows move the manual output', async () => {
    const r = rig({ MAN: false, CV: 40, MINO: 0, MAXO: 100 });
    key('F3');
    await vi.waitFor(() => expect(r.puts).toContainEqual(['/api/tags/Loop.MAN', true]));
    r.live.store.apply(new Map([['Loop.MAN', true]]));
    key('ArrowUp');
    await vi.waitFor(() => expect(r.puts).toContainEqual(['/api/tags/Loop.CV', 41]));
    // closed, the keys are the page's again
    (r.box.querySelector('[data-testid="faceplate-close"]') as HTMLButtonElement).click();
    const before = r.puts.length;
    key('F3');
    await new Promise((res) => setTimeout(res, 20));
    expect(r.puts.length).toBe(before);
  });
});
