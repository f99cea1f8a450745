// How pens share the plot (issue 16, item 4): analog pens on up to four y
// axes (1, 3 left; 2, 4 right), each automatic or fixed (min/max); BOOL pens
// as steps on lanes of their own along the bottom of the plot, whatever
// their axis says, with an axis of their own (their names) — the analog axes
// keep the part above the lanes (issue 30, item 16); the time axis' labels
// in the language's format, spaced so that they do not collide; and the time
// range kept out of the future.
import { clockTime, dateOnly, minuteTime } from '../i18n';

/** A pen as the plot sees it. */
export interface PenSpec {
  tag: string;
  /** 1 to 4: pens with the same number share a y axis. */
  axis: number;
  min: number | null;
  max: number | null;
  /** A BOOL: drawn on a lane. */
  digital: boolean;
}

/** The lanes take this share of the plot's height when analog pens share it. */
export const LANE_SHARE = 0.35;

/** The uPlot scale of a pen: `y1`…`y4`, or `lanes` for a BOOL. */
export function scaleOf(p: PenSpec): string {
  return p.digital ? 'lanes' : `y${Math.min(4, Math.max(1, Math.round(p.axis)))}`;
}

/** The lane (0 = bottom) of each digital pen, by pen index; -1 for analog pens. */
export function lanesOf(pens: PenSpec[]): number[] {
  let next = 0;
  return pens.map((p) => (p.digital ? next++ : -1));
}

/** A BOOL's 0/1 drawn inside its lane: 15 % and 85 % of the lane's height. */
export function toLane(lane: number, v: number | null): number | null {
  if (v === null || Number.isNaN(v)) return null;
  return lane + 0.15 + 0.7 * (v ? 1 : 0);
}

/** The value a lane position stands for (the legend shows 0/1, not the lane's coordinate). */
export function fromLane(y: number | null): number | null {
  if (y === null || Number.isNaN(y)) return null;
  return y - Math.floor(y) > 0.5 ? 1 : 0;
}

/** The range of the lanes' scale: alone they fill the plot; beside analog pens, the bottom share. */
export function laneRange(lanes: number, withAnalog: boolean): [number, number] {
  const n = Math.max(1, lanes);
  return [0, withAnalog ? n / LANE_SHARE : n];
}

/**
 * An analog scale's range `[lo, hi]` stretched down so that its pens keep the
 * part of the plot above the lanes (the lanes take the bottom LANE_SHARE).
 */
export function aboveLanes(lo: number, hi: number, withLanes: boolean): [number, number] {
  if (!withLanes) return [lo, hi];
  return [lo - ((hi - lo) * LANE_SHARE) / (1 - LANE_SHARE), hi];
}

/** The lowest value an analog axis of range `[min, max]` labels beside lanes: the top of the lanes. */
export function lanesTop(min: number, max: number): number {
  return min + (max - min) * LANE_SHARE;
}

/** The fixed range of an axis: the first pen on it with both min and max set; null: automatic. */
export function fixedRange(pens: PenSpec[], scale: string): [number, number] | null {
  const p = pens.find((q) => !q.digital && scaleOf(q) === scale && q.min !== null && q.max !== null && q.min < q.max);
  return p ? [p.min as number, p.max as number] : null;
}

/** The analog axes in use, in order (`y1` first): where to draw axes. */
export function axesInUse(pens: PenSpec[]): string[] {
  return [...new Set(pens.filter((p) => !p.digital).map(scaleOf))].sort();
}

/** A range shifted back so that it does not end after `now` (zooming out of live shows the past, not empty future). */
export function clampToNow(from: number, to: number, now: number): [number, number] {
  return to > now ? [from - (to - now), now] : [from, to];
}

const MINUTE = 60e3;
const DAY = 86400e3;

/**
 * The time axis' labels for ticks `splits` (ms) `incr` apart: the time of day
 * (to the second when ticks are less than a minute apart or not on whole
 * minutes), and the date below the first one and wherever the day changes;
 * ticks a day or more apart show the date only.
 */
export function timeLabels(splits: number[], incr: number): string[] {
  if (incr >= DAY) return splits.map((t) => dateOnly(t));
  const seconds = incr < MINUTE || splits.some((t) => t % MINUTE !== 0);
  let day = '';
  return splits.map((t) => {
    const time = seconds ? clockTime(t) : minuteTime(t);
    const d = dateOnly(t);
    const label = d !== day ? `${time}\n${d}` : time;
    day = d;
    return label;
  });
}

/** The widest time label (in characters) and so the least space (CSS px) between two time ticks. */
export function timeSpace(charPx = 7): number {
  const widest = Math.max(clockTime(Date.UTC(2000, 0, 1, 22, 58, 58)).length, dateOnly(Date.UTC(2000, 11, 28)).length);
  return widest * charPx + 24;
}
