// A screen's trend element (issue 30, item 4): the last `props.window_s`
// seconds of its tag (120 when unset), filled from the historian when the
// screen opens and then from live values, drawn as a sample-and-hold line up
// to now — a steady value is a steady line — on `props.min`–`props.max` or
// the range of what it shows, with the scale's ends and the window's start
// and end times as axis labels (the language's time format).
import { clockTime } from '../i18n';
import type { Json } from '../types';
import type { Sample } from '../trends/history';

export const DEFAULT_WINDOW_S = 120;
/** The most pens a trend element draws (alba-project's MAX_TREND_PENS). */
export const MAX_PENS = 3;
/** The pens' colours when `props.pens` gives none: blue, orange, green (first is the single pen's). */
export const PEN_COLORS = ['#1f5fa8', '#e8710a', '#2e7d32'];

export interface Pen {
  tag: string;
  color: string;
}

/**
 * A trend element's pens: `props.pens` (up to three `{tag, color}`, a missing
 * colour by its place), else the element's `tag` as the one pen; none when it
 * has neither.
 */
export function trendPens(props: Record<string, Json> | undefined): Pen[] {
  const list = Array.isArray(props?.pens) ? (props.pens as Json[]) : [];
  const pens = list
    .filter((p): p is Record<string, Json> => !!p && typeof p === 'object' && !Array.isArray(p) && typeof p.tag === 'string' && p.tag !== '')
    .slice(0, MAX_PENS)
    .map((p, k) => ({ tag: p.tag as string, color: typeof p.color === 'string' && p.color ? p.color : PEN_COLORS[k] }));
  if (pens.length) return pens;
  return typeof props?.tag === 'string' && props.tag ? [{ tag: props.tag, color: PEN_COLORS[0] }] : [];
}

/** The SVG part a pen draws into: `line` for the first (as a single-pen trend), `line-2`, `line-3`. */
export const penPart = (k: number) => (k === 0 ? 'line' : `line-${k + 1}`);
/** The longest window: a day. */
export const MAX_WINDOW_S = 86_400;

/** The element's time window in ms: `props.window_s` when it is a number of seconds in range, else the default. */
export function windowMs(props: Record<string, Json> | undefined): number {
  const s = props?.window_s;
  return (typeof s === 'number' && s > 0 && s <= MAX_WINDOW_S ? s : DEFAULT_WINDOW_S) * 1000;
}

/** A scale value as a short label: at most 4 significant digits. */
export function scaleLabel(v: number): string {
  return String(Number(v.toPrecision(4)));
}

/** The value held at `t`: the last sample at or before it (undefined before the first). */
function heldAt(samples: Sample[], t: number): number | null | undefined {
  let v: number | null | undefined;
  for (const [st, sv] of samples) {
    if (st > t) break;
    v = sv;
  }
  return v;
}

/**
 * The scale: `props.min`–`props.max` when both are set (min < max), else the
 * range of the values shown, widened by a tenth (a steady value sits in the
 * middle of a scale of ±10 %, or ±1 around zero).
 */
export function trendScale(values: number[], props: Record<string, Json> | undefined): [number, number] {
  const [pmin, pmax] = [props?.min, props?.max];
  if (typeof pmin === 'number' && typeof pmax === 'number' && pmin < pmax) return [pmin, pmax];
  if (values.length === 0) return [0, 1];
  let [lo, hi] = [Math.min(...values), Math.max(...values)];
  if (typeof pmin === 'number') lo = pmin;
  if (typeof pmax === 'number') hi = pmax;
  if (lo === hi) {
    const d = lo === 0 ? 1 : Math.abs(lo) * 0.1;
    return [lo - d, hi + d];
  }
  const pad = (hi - lo) * 0.05;
  return [typeof pmin === 'number' ? lo : lo - pad, typeof pmax === 'number' ? hi : hi + pad];
}

/**
 * The polyline points of `samples` over [from, to] in the box (x0, y0)–(x1, y1):
 * steps (a value held until the next), from the value held at `from` (or the
 * first sample) to `to`; a gap (null) is bridged.
 */
export function trendPoints(samples: Sample[], from: number, to: number, box: [number, number, number, number], [lo, hi]: [number, number]): string {
  const [x0, y0, x1, y1] = box;
  const x = (t: number) => (x0 + ((x1 - x0) * (t - from)) / (to - from || 1)).toFixed(1);
  const y = (v: number) => (y1 - ((Math.max(lo, Math.min(hi, v)) - lo) / (hi - lo || 1)) * (y1 - y0)).toFixed(1);
  const pts: string[] = [];
  let held = heldAt(samples, from);
  if (held !== undefined && held !== null) pts.push(`${x(from)},${y(held)}`);
  for (const [t, v] of samples) {
    if (t <= from || t > to) continue;
    if (held !== undefined && held !== null && v !== null) pts.push(`${x(t)},${y(held)}`);
    if (v !== null) pts.push(`${x(t)},${y(v)}`);
    held = v;
  }
  if (held !== undefined && held !== null) pts.push(`${x(to)},${y(held)}`);
  return pts.join(' ');
}

/** One trend element of a running screen: each pen's samples, and the drawing (one scale for all pens). */
export class ScreenTrend {
  private samples: Sample[][];
  /** When each pen's first live value came (history is the truth before it). */
  private liveSince: number[];
  readonly windowMs: number;

  constructor(
    private readonly g: SVGGElement,
    private readonly props: Record<string, Json> | undefined,
    readonly pens = 1,
  ) {
    this.windowMs = windowMs(props);
    this.samples = Array.from({ length: pens }, () => []);
    this.liveSince = Array.from({ length: pens }, () => Infinity);
  }

  /** A live value of pen `k` at `t`. */
  push(t: number, v: number | null, k = 0): void {
    if (this.liveSince[k] === Infinity) this.liveSince[k] = t;
    const samples = this.samples[k];
    const last = samples[samples.length - 1];
    if (last && t <= last[0]) samples[samples.length - 1] = [last[0], v];
    else samples.push([t, v]);
  }

  /** Pen `k`'s history over the window (sorted): kept before its first live value. */
  seed(history: Sample[], k = 0): void {
    const since = this.liveSince[k];
    this.samples[k] = [...history.filter(([t]) => t < since), ...this.samples[k].filter(([t]) => t >= since)];
  }

  /** Draws the window ending at `now`; forgets what is older than the window (keeping the value held at its start). */
  draw(now: number): void {
    const from = now - this.windowMs;
    this.samples = this.samples.map((samples) => {
      let k = 0;
      while (k + 1 < samples.length && samples[k + 1][0] <= from) k++;
      return k > 0 ? samples.slice(k) : samples;
    });
    const first = this.g.querySelector('[data-part="line"]');
    if (!first) return;
    const box = (first.getAttribute('data-box') ?? '0,0,100,100').split(',').map(Number) as [number, number, number, number];
    const shown = this.samples.flatMap((samples) => samples.filter(([t], i) => t > from || i === 0).map(([, v]) => v).filter((v): v is number => v !== null));
    const scale = trendScale(shown, this.props);
    this.samples.forEach((samples, k) => this.g.querySelector(`[data-part="${penPart(k)}"]`)?.setAttribute('points', trendPoints(samples, from, now, box, scale)));
    const label = (part: string, text: string) => {
      const el = this.g.querySelector(`[data-part="${part}"]`);
      if (el && el.textContent !== text) el.textContent = text;
    };
    label('y-min', scaleLabel(scale[0]));
    label('y-max', scaleLabel(scale[1]));
    label('x-from', clockTime(from));
    label('x-to', clockTime(now));
  }
}
