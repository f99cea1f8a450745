// The Verify & Test page's logic (issue 37), apart from the page so that
// Vitest checks it: the replay's scan under the slider (values, what
// changed, the violation), the coverage marks of a program's elements.
// Results, replays and coverage come from the server (POST /api/verify,
// POST /api/tests), never recomputed here.
import type { ProgramCoverage, Replay } from '../api.gen';

/** A scan index within the replay (the slider's value), clamped. */
export function clampScan(r: Replay, k: number): number {
  if (r.scans.length === 0) return 0;
  return Math.min(r.scans.length - 1, Math.max(0, Math.round(Number.isFinite(k) ? k : 0)));
}

export interface ShownValue {
  tag: string;
  value: string;
  /** Different from the scan before (or set by the stimulus at this scan's time). */
  changed: boolean;
}

/** The tags' values at scan `k`, marking those that changed since the scan before. */
export function valuesAt(r: Replay, k: number): ShownValue[] {
  const i = clampScan(r, k);
  const scan = r.scans[i];
  if (!scan) return [];
  const before = i > 0 ? r.scans[i - 1] : null;
  return r.tags.map((tag, j) => ({
    tag,
    value: scan.values[j] ?? '',
    changed: before ? before.values[j] !== scan.values[j] : false,
  }));
}

/**
 * The values of scan `k` as the net and SFC views read live values: a tag's
 * value by its name (case-insensitive), a number when it is one (a BOOL is
 * 0 or 1), else its text; undefined for a tag the replay does not list.
 */
export function valueOf(r: Replay, k: number): (tag: string) => number | string | undefined {
  const values = r.scans[clampScan(r, k)]?.values ?? [];
  const at = new Map(r.tags.map((t, j) => [t.toUpperCase(), j]));
  return (tag) => {
    const j = at.get(tag.toUpperCase());
    const v = j === undefined ? undefined : values[j];
    if (v === undefined) return undefined;
    const n = Number(v);
    return v.trim() !== '' && Number.isFinite(n) ? n : v;
  };
}

/** The stimulus rows applied at scan `k` (those with a time after the scan before's, up to this scan's). */
export function rowsAt(r: Replay, k: number): Replay['rows'] {
  const i = clampScan(r, k);
  const t = r.scans[i]?.time_ms ?? 0;
  const prev = i > 0 ? r.scans[i - 1].time_ms : -1;
  return r.rows.filter((row) => row.time_ms > prev && row.time_ms <= t);
}

/** The elements energised at scan `k`. */
export function powerAt(r: Replay, k: number): Set<number> {
  return new Set(r.scans[clampScan(r, k)]?.on ?? []);
}

/** The scan the slider lands on when a replay opens: the violation. */
export function startScan(r: Replay): number {
  return clampScan(r, r.violating_scan);
}

/** Scans where the stimulus changes something (for the step buttons "previous/next change"). */
export function changeScans(r: Replay): number[] {
  const out: number[] = [];
  r.scans.forEach((_, k) => {
    if (k === 0 || valuesAt(r, k).some((v) => v.changed)) out.push(k);
  });
  return out;
}

/** The next (dir 1) or previous (dir -1) scan of `changes` from `k`; `k` when none. */
export function stepChange(changes: number[], k: number, dir: 1 | -1): number {
  if (dir > 0) return changes.find((c) => c > k) ?? k;
  return [...changes].reverse().find((c) => c < k) ?? k;
}

export interface CoverageMarks {
  /** Elements that never carried power in any table. */
  never: Set<number>;
  /** Elements that always did (never switched off). */
  always: Set<number>;
}

/** The overlay of one program's coverage. */
export function coverageMarks(c: ProgramCoverage): CoverageMarks {
  const powered = new Set(c.powered);
  return { never: new Set(c.elements.filter((e) => !powered.has(e))), always: new Set(c.always) };
}

/** Coverage as a whole percent of `part` in `all` (0 when nothing to cover). */
export function percentOf(part: number, all: number): number {
  return all > 0 ? Math.round((100 * part) / all) : 0;
}
