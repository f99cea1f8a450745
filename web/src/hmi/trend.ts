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

/** One trend element of a running screen: its samples and its drawing. */
export class ScreenTrend {
  private samples: Sample[] = [];
  /** When the first live value came (history is the truth before it). */
  private liveSince = Infinity;
  readonly windowMs: number;

  constructor(
    private readonly g: SVGGElement,
    private readonly props: Record<string, Json> | undefined,
  ) {
    this.windowMs = windowMs(props);
  }

  /** A live value at `t`. */
  push(t: number, v: number | null): void {
    if (this.liveSince === Infinity) this.liveSince = t;
    const last = this.samples[this.samples.length - 1];
    if (last && t <= last[0]) this.samples[this.samples.length - 1] = [last[0], v];
    else this.samples.push([t, v]);
  }

  /** The window's history (sorted): kept before the first live value. */
  seed(history: Sample[]): void {
    this.samples = [...history.filter(([t]) => t < this.liveSince), ...this.samples.filter(([t]) => t >= this.liveSince)];
  }

  /** Draws the window ending at `now`; forgets what is older than the window (keeping the value held at its start). */
  draw(now: number): void {
    const from = now - this.windowMs;
    let k = 0;
    while (k + 1 < this.samples.length && this.samples[k + 1][0] <= from) k++;
    if (k > 0) this.samples = this.samples.slice(k);
    const pen = this.g.querySelector('[data-part="line"]');
    if (!pen) return;
    const box = (pen.getAttribute('data-box') ?? '0,0,100,100').split(',').map(Number) as [number, number, number, number];
    const shown = this.samples.filter(([t], i) => t > from || i === 0).map(([, v]) => v).filter((v): v is number => v !== null);
    const scale = trendScale(shown, this.props);
    pen.setAttribute('points', trendPoints(this.samples, from, now, box, scale));
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
