import { describe, expect, it } from 'vitest';
import {
  PenLog,
  alignLogs,
  bucketsToSeries,
  exportStep,
  historyFailure,
  historySamples,
  joinHistories,
  mergeBackfill,
  plotValue,
  type Sample,
} from '../src/trends/history';
import type { Bucket } from '../src/types';

describe('pen log (ring buffer)', () => {
  it('keeps the newest samples when full and answers sample-and-hold', () => {
    const l = new PenLog(3);
    [1, 2, 3, 4].forEach((t) => l.push(t * 10, t));
    expect(l.size).toBe(3);
    expect(l.at(0)).toEqual([20, 2]);
    expect(l.valueAt(15)).toBeUndefined();
    expect(l.valueAt(20)).toBe(2);
    expect(l.valueAt(35)).toBe(3);
    expect(l.valueAt(1000)).toBe(4);
  });

  it('merges samples at the same instant and never goes back in time', () => {
    const l = new PenLog(10);
    l.push(10, 1);
    l.push(10, 2);
    l.push(5, 3);
    expect(l.size).toBe(1);
    expect(l.at(0)).toEqual([10, 3]);
    l.push(11, null);
    expect(l.valueAt(12)).toBeNull();
  });

  it('aligns pens on the union of their change times, holding values', () => {
    const a = new PenLog();
    const b = new PenLog();
    a.push(0, 1);
    a.push(30, 2);
    b.push(20, 5);
    const [xs, ya, yb] = alignLogs([a, b], 10, 40);
    expect(xs).toEqual([10, 20, 30, 40]);
    expect(ya).toEqual([1, 1, 2, 2]);
    expect(yb).toEqual([null, 5, 5, 5]);
  });

  it('plots booleans as 0/1 and drops non-numbers', () => {
    expect([true, false, 2.5, null, 'x', { a: 1 }].map((v) => plotValue(v))).toEqual([1, 0, 2.5, null, null, null]);
  });
});

describe('history buckets', () => {
  const buckets: Bucket[] = [
    [1000, 1, 5, 2, 4],
    [2000, 0, 3, 3, 0],
  ];

  it('turns buckets into columns', () => {
    expect(bucketsToSeries(buckets)).toEqual({ t: [1000, 2000], min: [1, 0], max: [5, 3], first: [2, 3], last: [4, 0] });
  });

  it('joins pens with different buckets on one axis with gaps', () => {
    const j = joinHistories([
      { node: 'n', tag: 'A', from: 0, to: 3000, buckets },
      { node: 'n', tag: 'B', from: 0, to: 3000, buckets: [[1500, 7, 9, 7, 8], [2000, 1, 1, 1, 1]] },
    ]);
    expect(j.xs).toEqual([1000, 1500, 2000]);
    expect(j.pens[0]).toEqual({ line: [4, null, 0], min: [1, null, 0], max: [5, null, 3] });
    expect(j.pens[1]).toEqual({ line: [null, 8, 1], min: [null, 7, 1], max: [null, 9, 1] });
  });

  it('chooses an export step of about 2000 rows, at least 10 ms', () => {
    expect(exportStep(0, 1000)).toBe(10);
    expect(exportStep(0, 3_600_000)).toBe(1800);
  });
});

/** Times strictly increase (sorted, no two samples at one time). */
function strictlyIncreasing(xs: Sample[]): boolean {
  return xs.every((s, i) => i === 0 || s[0] > xs[i - 1][0]);
}

describe('backfill of the live buffer from history', () => {
  it('turns buckets into sample-and-hold changes within each bucket', () => {
    // grid of 100 ms; the first bucket is a partial one starting at `from`
    const b: Bucket[] = [
      [950, 1, 1, 1, 1],
      [1000, 0, 10, 2, 8], // rising: min before max
      [1100, 3, 9, 9, 3], // falling: max (= first, not repeated) before min (= last)
      [1300, 3, 3, 3, 3], // after an empty bucket; same value as held: nothing new
      [1400, 5, 5, 5, 5],
    ];
    const s = historySamples(b, 950, 1450);
    expect(s).toEqual([
      [950, 1],
      [1000, 2],
      [1025, 0],
      [1050, 10],
      [1075, 8],
      [1100, 9],
      [1150, 3],
      [1400, 5],
    ]);
    expect(strictlyIncreasing(s)).toBe(true);
    // every value lies within its bucket's min..max, at a time inside the bucket
    for (const [t, v] of s) {
      const k = b.filter((x) => x[0] <= t).length - 1;
      const end = k + 1 < b.length ? b[k + 1][0] : 1451;
      expect(t).toBeLessThan(end);
      expect(v).toBeGreaterThanOrEqual(b[k][1]!);
      expect(v).toBeLessThanOrEqual(b[k][2]!);
    }
  });

  it('keeps the last bucket within `to` and handles a single bucket', () => {
    // one bucket: its width is the ideal grid width, (to - from + 1) / points
    expect(historySamples([[1000, 1, 4, 1, 4]], 1000, 1039, 1)).toEqual([[1000, 1], [1020, 4]]);
    expect(historySamples([[1000, 1, 4, 1, 4]], 1000, 1039, 4)).toEqual([[1000, 1], [1005, 4]]);
    // the last bucket ends at `to`
    expect(historySamples([[0, 0, 0, 0, 0], [100, 0, 0, 0, 0], [200, 1, 2, 1, 2]], 0, 219)).toEqual([[0, 0], [200, 1], [210, 2]]);
    expect(historySamples([], 0, 10)).toEqual([]);
    // the value held before the window starts the line at its left edge
    expect(historySamples([[1000, 2, 2, 2, 2]], 950, 1099, 1, 7)).toEqual([[949, 7], [1000, 2]]);
    expect(historySamples([], 950, 1099, 1, 7)).toEqual([[949, 7]]);
    expect(historySamples([[950, 7, 7, 7, 7]], 950, 1099, 1, 7)).toEqual([[949, 7]]);
    // a repeated bucket time never gives two samples at one time
    const d = historySamples([[100, 1, 1, 1, 1], [100, 2, 2, 2, 2], [150, 3, 3, 3, 3]], 100, 199);
    expect(strictlyIncreasing(d)).toBe(true);
    expect(d[0]).toEqual([100, 1]);
  });

  const history: Sample[] = [
    [100, 1],
    [200, 2],
    [300, 3],
    [400, 4],
    [500, 5],
  ];

  it('puts history before the first live sample and keeps every live sample', () => {
    const live: Sample[] = [
      [350, 30],
      [450, 40],
      [600, 60],
    ];
    const m = mergeBackfill(history, live, 350);
    expect(m).toEqual([
      [100, 1],
      [200, 2],
      [300, 3],
      [350, 30],
      [450, 40],
      [600, 60],
    ]);
    expect(strictlyIncreasing(m)).toBe(true);
  });

  it('takes the whole history when no live sample came yet, and live wins at the same instant', () => {
    expect(mergeBackfill(history, [], Infinity)).toEqual(history);
    const m = mergeBackfill(history, [[300, 33]], 300);
    expect(m).toEqual([
      [100, 1],
      [200, 2],
      [300, 33],
    ]);
  });

  it('fills a reconnection gap: history replaces the old live samples it covers, older ones stay', () => {
    const live: Sample[] = [
      [50, 0], // before the history window: kept
      [150, 15], // before the disconnect, covered by history: replaced
      [250, 25],
      [450, 45], // first sample after the reconnect (cut)
      [480, 48],
    ];
    const m = mergeBackfill(history, live, 450);
    expect(m).toEqual([
      [50, 0],
      [100, 1],
      [200, 2],
      [300, 3],
      [400, 4],
      [450, 45],
      [480, 48],
    ]);
    expect(strictlyIncreasing(m)).toBe(true);
  });

  it('keeps the live buffer when history is empty or starts after it', () => {
    const live: Sample[] = [
      [10, 1],
      [20, 2],
    ];
    expect(mergeBackfill([], live, 10)).toEqual(live);
    // live since 10, history (of a longer window) from 100 on: nothing to fill before the live data
    expect(mergeBackfill(history, live, 10)).toEqual(live);
  });

  it('sorts unsorted input and never repeats a time', () => {
    const m = mergeBackfill([[300, 3], [100, 1], [100, 11], [200, 2]], [[500, 5], [400, 4]], 400);
    expect(m).toEqual([
      [100, 11],
      [200, 2],
      [300, 3],
      [400, 4],
      [500, 5],
    ]);
  });

  it('seeds a ring buffer: live pushes afterwards continue it without going back in time', () => {
    const log = new PenLog(6);
    log.push(450, 45);
    log.replace(mergeBackfill(historySamples([[0, 1, 1, 1, 1], [100, 2, 2, 2, 2], [200, 3, 3, 3, 3]], 0, 299), log.samples(), 450));
    expect(log.samples()).toEqual([
      [0, 1],
      [100, 2],
      [200, 3],
      [450, 45],
    ]);
    log.push(460, 46);
    log.push(455, 47); // late: held at 460
    expect(log.last()).toEqual([460, 47]);
    expect(log.valueAt(150)).toBe(2);
    // replace keeps the newest when there are more than the capacity
    log.replace([1, 2, 3, 4, 5, 6, 7, 8].map((t) => [t, t] as Sample));
    expect(log.size).toBe(6);
    expect(log.at(0)).toEqual([3, 3]);
  });

  it('tells history off from a tag without history', () => {
    expect(historyFailure(404, 'history is off for this project (`[history] enabled = false` in alba.toml)')).toBe('off');
    expect(historyFailure(404, 'no such endpoint')).toBe('off');
    expect(historyFailure(404, 'no history for `Level`')).toBe('no-data');
    expect(historyFailure(422, 'points must be at least 1')).toBe('error');
    expect(historyFailure(0, 'cannot reach the server: x')).toBe('error');
  });
});
