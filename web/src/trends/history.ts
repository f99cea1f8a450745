// Trend data: a ring buffer of each pen's changes (live), sample-and-hold
// alignment for plotting, and history buckets → plot series.
import type { Bucket, History, Json } from '../types';

/** A number for plotting: BOOL as 0/1, null for anything else. */
export function plotValue(v: Json | undefined): number | null {
  if (typeof v === 'number') return Number.isFinite(v) ? v : null;
  if (typeof v === 'boolean') return v ? 1 : 0;
  return null;
}

/** One point of a pen: [t_ms, value] (null: no number). */
export type Sample = [number, number | null];

/** The changes of one pen, oldest first, in a fixed-size ring. */
export class PenLog {
  private t: Float64Array;
  private v: Float64Array;
  private start = 0;
  size = 0;

  constructor(readonly capacity = 20000) {
    this.t = new Float64Array(capacity);
    this.v = new Float64Array(capacity);
  }

  push(t: number, v: number | null): void {
    const val = v === null ? NaN : v;
    if (this.size > 0) {
      const last = (this.start + this.size - 1) % this.capacity;
      if (t < this.t[last]) t = this.t[last];
      if (t === this.t[last]) {
        this.v[last] = val; // same instant: the later value wins
        return;
      }
    }
    if (this.size < this.capacity) {
      const i = (this.start + this.size) % this.capacity;
      this.t[i] = t;
      this.v[i] = val;
      this.size++;
    } else {
      this.t[this.start] = t;
      this.v[this.start] = val;
      this.start = (this.start + 1) % this.capacity;
    }
  }

  at(k: number): [number, number | null] {
    const i = (this.start + k) % this.capacity;
    const v = this.v[i];
    return [this.t[i], Number.isNaN(v) ? null : v];
  }

  /** The value held at time t (the last change at or before t), or undefined before the first. */
  valueAt(t: number): number | null | undefined {
    let lo = 0;
    let hi = this.size - 1;
    let found = -1;
    while (lo <= hi) {
      const mid = (lo + hi) >> 1;
      if (this.at(mid)[0] <= t) {
        found = mid;
        lo = mid + 1;
      } else hi = mid - 1;
    }
    return found < 0 ? undefined : this.at(found)[1];
  }

  /** The newest sample, or undefined when empty. */
  last(): Sample | undefined {
    return this.size > 0 ? this.at(this.size - 1) : undefined;
  }

  /** Every sample, oldest first. */
  samples(): Sample[] {
    const out: Sample[] = [];
    for (let k = 0; k < this.size; k++) out.push(this.at(k));
    return out;
  }

  /** Replaces the content with `samples` (sorted by time; the newest kept if too many). */
  replace(samples: Sample[]): void {
    this.start = 0;
    this.size = 0;
    for (const [t, v] of samples.slice(-this.capacity)) this.push(t, v);
  }

  /** Change times within [from, to]. */
  times(from: number, to: number): number[] {
    const out: number[] = [];
    for (let k = 0; k < this.size; k++) {
      const t = this.at(k)[0];
      if (t >= from && t <= to) out.push(t);
    }
    return out;
  }
}

/**
 * Aligns several pens on one time axis for [from, to] with sample-and-hold:
 * the times are `from`, every change, and `to`; each pen's value at a time
 * is its last change before it (null before its first).
 */
export function alignLogs(logs: PenLog[], from: number, to: number): [number[], ...(number | null)[][]] {
  const ts = new Set<number>([from, to]);
  logs.forEach((l) => l.times(from, to).forEach((t) => ts.add(t)));
  const xs = [...ts].sort((a, b) => a - b);
  const ys = logs.map((l) => xs.map((t) => {
    const v = l.valueAt(t);
    return v === undefined ? null : v;
  }));
  return [xs, ...ys];
}

export interface BucketSeries {
  t: number[];
  min: (number | null)[];
  max: (number | null)[];
  first: (number | null)[];
  last: (number | null)[];
}

/** History buckets ([t, min, max, first, last]) as columns. */
export function bucketsToSeries(buckets: Bucket[]): BucketSeries {
  const s: BucketSeries = { t: [], min: [], max: [], first: [], last: [] };
  for (const b of buckets) {
    s.t.push(b[0]);
    s.min.push(b[1]);
    s.max.push(b[2]);
    s.first.push(b[3]);
    s.last.push(b[4]);
  }
  return s;
}

/**
 * Several pens' histories on one time axis: per pen three columns, the line
 * (the bucket's last value), its min and its max (a band); null where a pen
 * has no bucket at that time.
 */
export function joinHistories(hs: History[]): { xs: number[]; pens: { line: (number | null)[]; min: (number | null)[]; max: (number | null)[] }[] } {
  const xs = [...new Set(hs.flatMap((h) => h.buckets.map((b) => b[0])))].sort((a, b) => a - b);
  const index = new Map(xs.map((t, i) => [t, i]));
  const pens = hs.map((h) => {
    const line: (number | null)[] = xs.map(() => null);
    const min = [...line];
    const max = [...line];
    for (const b of h.buckets) {
      const i = index.get(b[0])!;
      line[i] = b[4];
      min[i] = b[1];
      max[i] = b[2];
    }
    return { line, min, max };
  });
  return { xs, pens };
}

/** The sample step for a CSV export of [from, to]: about `rows` rows, at least 10 ms. */
export function exportStep(from: number, to: number, rows = 2000): number {
  return Math.max(10, Math.ceil((to - from) / rows / 10) * 10);
}

/**
 * History buckets as sample-and-hold changes, for seeding a live buffer: per
 * bucket its first value at the bucket's start, its min and max (in the order
 * that follows the bucket's direction) and its last value spread over the
 * bucket's span (the API gives no time for them, and a bucket is about a pixel
 * wide), without repeating a value that is already held. Times strictly
 * increase. The buckets' span is their grid width (the smallest gap between
 * starts after the first, which may be a partial bucket beginning at `from`),
 * never beyond the next bucket or `to`. `held` is the value recorded last
 * before `from` (a tag is recorded on change and then only periodically), put
 * at `from - 1` so that the line starts at the window's left edge.
 */
export function historySamples(buckets: Bucket[], from: number, to: number, points = buckets.length, held?: number | null): Sample[] {
  const out: Sample[] = [];
  // the value held when the window starts (recorded before it), just before `from`
  if (held !== undefined) out.push([from - 1, held]);
  if (buckets.length === 0) return out;
  let width = Infinity;
  for (let i = 2; i < buckets.length; i++) width = Math.min(width, buckets[i][0] - buckets[i - 1][0]);
  if (!Number.isFinite(width) || width <= 0) width = Math.max(1, Math.ceil((to - from + 1) / Math.max(1, points)));
  const emit = (t: number, v: number | null) => {
    const prev = out[out.length - 1];
    if (prev && t <= prev[0]) return;
    if (prev && prev[1] === v) return;
    out.push([t, v]);
  };
  buckets.forEach((b, i) => {
    const [t, min, max, first, last] = b;
    const next = i + 1 < buckets.length ? buckets[i + 1][0] : to + 1;
    const end = Math.min(t + width, next, to + 1);
    const q = Math.max(0, end - t) / 4;
    const extremes = last !== null && first !== null && last < first ? [max, min] : [min, max];
    emit(t, first);
    if (q > 0) {
      emit(t + q, extremes[0]);
      emit(t + 2 * q, extremes[1]);
      emit(t + 3 * q, last);
    }
  });
  return out;
}

/**
 * Seeds a live buffer with history: the result is sorted by time with no two
 * samples at the same time. `live` is the buffer (oldest first) and `cut` the
 * time of the first live sample received since the pen was added or the
 * WebSocket (re)connected (Infinity when none came yet). History is the truth
 * from its first sample up to `cut` (it replaces live samples there, which
 * fills a disconnection's gap); live samples before the history and from
 * `cut` on are kept, so live data wins where both have a sample.
 */
export function mergeBackfill(history: Sample[], live: Sample[], cut: number): Sample[] {
  if (history.length === 0) return live.slice();
  const h0 = history[0][0];
  const parts: Sample[] = [
    ...live.filter(([t]) => t < h0),
    ...history.filter(([t]) => t < cut),
    ...live.filter(([t]) => t >= cut),
  ];
  // sort (stable) and keep the later source at equal times
  const sorted = parts.map((s, i) => [s, i] as const).sort((a, b) => a[0][0] - b[0][0] || a[1] - b[1]).map(([s]) => s);
  const out: Sample[] = [];
  for (const s of sorted) {
    if (!Number.isFinite(s[0])) continue;
    if (out.length && out[out.length - 1][0] === s[0]) out[out.length - 1] = s;
    else out.push(s);
  }
  return out;
}

/** What a failed history request means: history is off (or the server has no such endpoint), the tag has no history, or another error. */
export function historyFailure(status: number, message: string): 'off' | 'no-data' | 'error' {
  if (status !== 404) return 'error';
  if (/^no history for\b/i.test(message)) return 'no-data';
  if (/^history is off\b/i.test(message) || /^no such endpoint/i.test(message)) return 'off';
  return 'error';
}
