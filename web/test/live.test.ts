import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { Coalescer, backoffDelay, emptyBatch, merge, unionSubscription, type Batch } from '../src/live/coalesce';
import { LiveClient, ValueStore } from '../src/live/client';
import type { ServerMsg, Status } from '../src/types';

const status = { project: 'tank', state: 'running', fault: null, scan_ms: 10, scans: 5, time_ms: 50, stats: { last_us: 1, min_us: 1, max_us: 9, mean_us: 2, jitter_us: 0, overruns: 0 }, minor_faults: 0, io: 'sim', programs: ['main.lad'], clients: 1, store_ok: true, retain_lost: false, problems: [], forces: [], connections: [] } satisfies Status as Status;

describe('coalescing', () => {
  it('merges messages: latest value per name, latest power per program, latest status, all errors', () => {
    const b = emptyBatch();
    merge(b, { type: 'values', scan: 1, t_ms: 100, values: { A: 1, B: true } });
    merge(b, { type: 'values', scan: 2, t_ms: 110, values: { A: 2 } });
    merge(b, { type: 'power', scan: 2, program: 'main.lad', on: [0, 1] });
    merge(b, { type: 'power', scan: 3, program: 'main.lad', on: [1] });
    merge(b, { type: 'power', scan: 3, program: 'other.lad', on: [] });
    merge(b, { type: 'status', ...status });
    merge(b, { type: 'error', error: 'unknown tags: X' });
    expect(Object.fromEntries(b.values)).toEqual({ A: 2, B: true });
    expect(b.t_ms).toBe(110);
    expect(Object.fromEntries(b.power)).toEqual({ 'main.lad': [1], 'other.lad': [] });
    expect(b.status).toEqual(status);
    expect(b.status).not.toHaveProperty('type');
    expect(b.errors).toEqual(['unknown tags: X']);
  });

  it('flushes once per scheduled frame however many messages arrive', () => {
    const frames: (() => void)[] = [];
    const flushed: Batch[] = [];
    const c = new Coalescer((b) => flushed.push(b), (cb) => frames.push(cb));
    for (let k = 0; k < 50; k++) c.push({ type: 'values', scan: k, t_ms: k, values: { N: k } });
    expect(frames).toHaveLength(1);
    expect(flushed).toHaveLength(0);
    frames.shift()!();
    expect(flushed).toHaveLength(1);
    expect(flushed[0].values.get('N')).toBe(49);
    c.push({ type: 'values', scan: 51, t_ms: 51, values: { N: 51 } });
    expect(frames).toHaveLength(1);
    frames.shift()!();
    expect(flushed.map((b) => b.values.get('N'))).toEqual([49, 51]);
  });

  it('backs off exponentially up to 8 s, with jitter', () => {
    expect([0, 1, 2, 3, 10].map((a) => backoffDelay(a, () => 0.5))).toEqual([250, 500, 1000, 2000, 8000]);
    expect(backoffDelay(0, () => 0)).toBe(200);
    expect(backoffDelay(0, () => 1)).toBe(300);
  });

  it('unites subscriptions: "*" wins, names are deduplicated and sorted', () => {
    expect(unionSubscription([['B', 'A'], ['A', 'C']])).toEqual(['A', 'B', 'C']);
    expect(unionSubscription([['A'], '*'])).toBe('*');
    expect(unionSubscription([])).toEqual([]);
  });
});

describe('value store', () => {
  it('notifies watchers of their name only, case-insensitively, and stops after unwatch', () => {
    const s = new ValueStore();
    const seen: unknown[] = [];
    const off = s.watch('Delay.ACC', (v) => seen.push(v));
    s.apply(new Map([['DELAY.ACC', 5], ['Other', 1]]));
    s.apply(new Map([['Delay.ACC', 6]]));
    off();
    s.apply(new Map([['Delay.ACC', 7]]));
    expect(seen).toEqual([5, 6]);
    const late: unknown[] = [];
    s.watch('delay.acc', (v) => late.push(v));
    expect(late).toEqual([7]);
  });
});

class FakeSocket {
  static OPEN = 1;
  static all: FakeSocket[] = [];
  readyState = 0;
  sent: string[] = [];
  onopen: (() => void) | null = null;
  onmessage: ((e: { data: string }) => void) | null = null;
  onclose: (() => void) | null = null;
  onerror: (() => void) | null = null;
  constructor(readonly url: string) {
    FakeSocket.all.push(this);
  }
  send(s: string) {
    this.sent.push(s);
  }
  close() {
    this.readyState = 3;
    this.onclose?.();
  }
  open() {
    this.readyState = 1;
    this.onopen?.();
  }
  receive(m: ServerMsg) {
    this.onmessage?.({ data: JSON.stringify(m) });
  }
}

describe('live client', () => {
  beforeEach(() => {
    FakeSocket.all = [];
    vi.stubGlobal('WebSocket', FakeSocket);
    vi.useFakeTimers();
  });
  afterEach(() => {
    vi.useRealTimers();
    vi.unstubAllGlobals();
  });

  it('sends the union of subscriptions and monitors, only when they change, and again after a reconnect', () => {
    const c = new LiveClient('ws://x/api/ws');
    const states: string[] = [];
    c.onState((s) => states.push(s));
    c.subscribe('ladder', ['Start', 'T1']);
    c.monitor('ladder', ['main.lad']);
    c.connect();
    const ws = FakeSocket.all[0];
    ws.open();
    expect(ws.sent.map((s) => JSON.parse(s))).toEqual([{ subscribe: ['Start', 'T1'] }, { monitor: ['main.lad'] }]);
    c.subscribe('trends', ['Level']);
    c.subscribe('trends', ['Level']);
    expect(ws.sent.slice(2).map((s) => JSON.parse(s))).toEqual([{ subscribe: ['Level', 'Start', 'T1'] }]);
    c.subscribe('tags', '*');
    expect(JSON.parse(ws.sent[ws.sent.length - 1])).toEqual({ subscribe: '*' });
    ws.close();
    expect(states).toEqual(['connecting', 'connected', 'reconnecting']);
    vi.advanceTimersByTime(400);
    const ws2 = FakeSocket.all[1];
    expect(ws2).toBeDefined();
    ws2.open();
    expect(ws2.sent.map((s) => JSON.parse(s))).toEqual([{ subscribe: '*' }, { monitor: ['main.lad'] }]);
    expect(states[states.length - 1]).toBe('connected');
  });

  it('dispatches raw messages at once and batches to the store and listeners per frame', () => {
    const c = new LiveClient('ws://x/api/ws');
    const raw: string[] = [];
    const batches: Batch[] = [];
    c.onRaw((m) => raw.push(m.type));
    c.onBatch((b) => batches.push(b));
    c.connect();
    const ws = FakeSocket.all[0];
    ws.open();
    ws.receive({ type: 'values', scan: 1, t_ms: 1, values: { A: 1 } });
    ws.receive({ type: 'values', scan: 2, t_ms: 2, values: { A: 2 } });
    ws.receive({ type: 'status', ...status });
    expect(raw).toEqual(['values', 'values', 'status']);
    expect(batches).toHaveLength(0);
    vi.advanceTimersByTime(100);
    expect(batches).toHaveLength(1);
    expect(c.store.get('a')).toBe(2);
    expect(c.status?.state).toBe('running');
  });
});

describe('alarms', () => {
  it('keeps the latest alarm summary of a batch', () => {
    const b = emptyBatch();
    const stats = { alarms: 3, active: 1, unacked: 1, shelved: 0, suppressed: 0, out_of_service: 0, new_10min: 1, flood: false, top_unacked: 'estop', top_severity: 1000 };
    merge(b, { type: 'alarms', ...stats, unacked: 2 });
    merge(b, { type: 'alarms', ...stats });
    expect(b.alarms).toEqual(stats);
    expect(b.alarms).not.toHaveProperty('type');
  });
});
