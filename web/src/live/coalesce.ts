// Coalesces WebSocket messages into one batch per animation frame, so the
// DOM is touched at most once a frame however fast the server sends.
import type { AlarmStats, Json, ServerMsg, Status } from '../types';

export interface Batch {
  /** The latest value of every name that changed, keys as sent. */
  values: Map<string, Json>;
  /** The time of the latest values message. */
  t_ms: number | null;
  /** The latest power flow of each program. */
  power: Map<string, number[]>;
  status: Status | null;
  /** The latest alarm summary (projects with alarms.csv). */
  alarms: AlarmStats | null;
  errors: string[];
}

export function emptyBatch(): Batch {
  return { values: new Map(), t_ms: null, power: new Map(), status: null, alarms: null, errors: [] };
}

/** Merges one message into a batch: later values overwrite earlier ones. */
export function merge(b: Batch, msg: ServerMsg): void {
  switch (msg.type) {
    case 'values':
      for (const [k, v] of Object.entries(msg.values)) b.values.set(k, v);
      b.t_ms = msg.t_ms;
      break;
    case 'power':
      b.power.set(msg.program, msg.on);
      break;
    case 'status': {
      const { type: _type, ...status } = msg;
      b.status = status;
      break;
    }
    case 'alarms': {
      const { type: _type, ...stats } = msg;
      b.alarms = stats;
      break;
    }
    case 'error':
      b.errors.push(msg.error);
      break;
  }
}

export type Scheduler = (cb: () => void) => void;

export const frameScheduler: Scheduler = (cb) => {
  if (typeof requestAnimationFrame === 'function' && typeof document !== 'undefined' && !document.hidden) {
    requestAnimationFrame(() => cb());
  } else {
    setTimeout(cb, 50);
  }
};

export class Coalescer {
  private pending: Batch | null = null;

  constructor(
    private readonly flush: (b: Batch) => void,
    private readonly schedule: Scheduler = frameScheduler,
  ) {}

  push(msg: ServerMsg): void {
    if (!this.pending) {
      this.pending = emptyBatch();
      this.schedule(() => {
        const b = this.pending;
        this.pending = null;
        if (b) this.flush(b);
      });
    }
    merge(this.pending, msg);
  }
}

/** Reconnection delay: exponential from 250 ms, capped at 8 s, with ±20 % jitter. */
export function backoffDelay(attempt: number, random: () => number = Math.random): number {
  const base = Math.min(8000, 250 * 2 ** Math.max(0, attempt));
  return Math.round(base * (0.8 + 0.4 * random()));
}

/** The union of several subscriptions: "*" if any wants everything, else the sorted names. */
export function unionSubscription(wants: Iterable<string[] | '*'>): string[] | '*' {
  const names = new Set<string>();
  for (const w of wants) {
    if (w === '*') return '*';
    w.forEach((n) => names.add(n));
  }
  return [...names].sort();
}
