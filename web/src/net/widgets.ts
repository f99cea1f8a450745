// The operator elements of a net's live view as OPCSM defines them (the 003_… seed,
// §2.2.3.13–16): what a Display shows for a value (its mode and number format), the
// range a Plot draws, how a Label looks, and a Button that latches on a double-click.
// Their properties are the `style` of a widget (attributes of `<widget>` in the PNML's
// Alba block); every function here is pure, so the view and the tests share it.
import type { Json } from '../types';

/** Display modes: `binary` (ON/OFF), `multivalue` (a text per value), `numerical` (a number and its unit). */
export const DISPLAY_MODES = ['numerical', 'binary', 'multivalue'] as const;
/** Number formats of the numerical mode (the source's "Num. Type"). */
export const DISPLAY_FORMATS = [
  'decimal', 'integer', 'engineering', 'binary8', 'binary16', 'binary32', 'binary64', 'binary128', 'binary256', 'hex', 'time', 'string',
] as const;
export const LABEL_ALIGNS = ['left', 'center', 'right'] as const;

/** The style keys each kind of widget offers in the properties panel, in order. */
export const STYLE_KEYS: Record<string, string[]> = {
  display: ['mode', 'format', 'decimals', 'unit', 'states', 'font_size'],
  plot: ['autoscale', 'title', 'min', 'max', 'unit'],
  label: ['color', 'background', 'show_background', 'border', 'font', 'font_size', 'align'],
  button: [],
};

const num = (v: Json | undefined): number | null => {
  if (typeof v === 'number') return v;
  if (typeof v === 'boolean') return v ? 1 : 0;
  if (typeof v === 'string' && v.trim() !== '' && Number.isFinite(Number(v))) return Number(v);
  return null;
};

/** `v` in two's complement on `bits` bits, grouped by 4 digits from the right. */
function binary(v: number, bits: number): string {
  const n = BigInt.asUintN(bits, BigInt(Math.trunc(v)));
  const digits = n.toString(2).padStart(bits, '0');
  return digits.replace(/\B(?=(\d{4})+$)/g, ' ');
}

/** Engineering notation: a mantissa in [1, 1000) and an exponent that is a multiple of 3. */
function engineering(v: number, decimals: number): string {
  if (v === 0) return (0).toFixed(decimals);
  const exp = Math.floor(Math.log10(Math.abs(v)) / 3) * 3;
  let m = v / 10 ** exp;
  let e = exp;
  // rounding may reach 1000 (999.9996 with 3 decimals): one step up
  if (Math.abs(Number(m.toFixed(decimals))) >= 1000) {
    m /= 1000;
    e += 3;
  }
  return e === 0 ? m.toFixed(decimals) : `${m.toFixed(decimals)}e${e}`;
}

/** A duration in milliseconds as `h:mm:ss.mmm` (the hours left out when zero, a sign kept). */
function duration(ms: number): string {
  const sign = ms < 0 ? '-' : '';
  let t = Math.round(Math.abs(ms));
  const milli = t % 1000;
  t = Math.floor(t / 1000);
  const s = t % 60;
  t = Math.floor(t / 60);
  const m = t % 60;
  const h = Math.floor(t / 60);
  const pad = (x: number, n = 2) => String(x).padStart(n, '0');
  return `${sign}${h ? `${h}:${pad(m)}` : String(m)}:${pad(s)}.${pad(milli, 3)}`;
}

/** The number `v` in `format` (decimal unless said; `decimals` for decimal and engineering). */
export function formatNumber(v: Json | undefined, format = 'decimal', decimals: number | null = null): string {
  if (format === 'string') return v === null || v === undefined ? '' : typeof v === 'object' ? JSON.stringify(v) : String(v);
  const n = num(v);
  if (n === null) return v === null || v === undefined ? '' : String(v);
  const bits = /^binary(8|16|32|64|128|256)$/.exec(format);
  if (bits) return binary(n, Number(bits[1]));
  switch (format) {
    case 'integer':
      return String(Math.round(n));
    case 'engineering':
      return engineering(n, decimals ?? 3);
    case 'hex': {
      const x = BigInt.asUintN(n < 0 ? 32 : 64, BigInt(Math.trunc(n)));
      return `16#${x.toString(16).toUpperCase()}`;
    }
    case 'time':
      return duration(n);
    default:
      return decimals === null ? String(n) : n.toFixed(decimals);
  }
}

/** What a Display shows for `v` under its `style`: its mode, format and unit. */
export function displayText(v: Json | undefined, style: Record<string, string> = {}): string {
  if (v === undefined || v === null) return '';
  const mode = style.mode ?? 'numerical';
  if (mode === 'binary') return num(v) ? 'ON' : 'OFF';
  if (mode === 'multivalue') {
    // `states` = "0:Stopped;1:Running;2:Fault": the text of the value, else the value
    const n = num(v);
    for (const part of (style.states ?? '').split(';')) {
      const at = part.indexOf(':');
      if (at > 0 && n !== null && Number(part.slice(0, at)) === n) return part.slice(at + 1).trim();
    }
    return formatNumber(v);
  }
  const decimals = style.decimals !== undefined && style.decimals !== '' ? Math.max(0, Math.min(10, Math.floor(Number(style.decimals)) || 0)) : null;
  const text = typeof v === 'boolean' && !style.format ? (v ? '1' : '0') : formatNumber(v, style.format ?? 'decimal', decimals);
  return style.unit ? `${text} ${style.unit}` : text;
}

const truthy = (s: string | undefined, dflt: boolean) => (s === undefined || s === '' ? dflt : !['false', '0', 'no', 'off'].includes(s.toLowerCase()));

/** The Y range a Plot draws `points` in: their own with `autoscale` (the default), else
 * `min`–`max` (a missing bound from the points); never empty. */
export function plotRange(points: number[], style: Record<string, string> = {}): { lo: number; hi: number } {
  const auto = truthy(style.autoscale, true);
  const own = points.length ? { lo: Math.min(...points), hi: Math.max(...points) } : { lo: 0, hi: 1 };
  const bound = (k: string) => (style[k] !== undefined && style[k] !== '' && Number.isFinite(Number(style[k])) ? Number(style[k]) : null);
  let lo = auto ? own.lo : (bound('min') ?? own.lo);
  let hi = auto ? own.hi : (bound('max') ?? own.hi);
  if (hi < lo) [lo, hi] = [hi, lo];
  if (hi === lo) hi = lo + 1;
  return { lo, hi };
}

/** A Label's look: text and background colours, border, font and alignment. */
export function labelLook(style: Record<string, string> = {}): {
  color: string | null;
  background: string | null;
  border: boolean;
  font: string | null;
  fontSize: number | null;
  align: 'left' | 'center' | 'right';
} {
  const colour = (c: string | undefined) => (c && /^(#[0-9a-fA-F]{3,8}|[a-zA-Z]+)$/.test(c.trim()) ? c.trim() : null);
  const size = Number(style.font_size);
  const align = (LABEL_ALIGNS as readonly string[]).includes(style.align ?? '') ? (style.align as 'left' | 'center' | 'right') : 'left';
  return {
    color: colour(style.color),
    background: truthy(style.show_background, true) ? colour(style.background) : null,
    border: truthy(style.border, true),
    font: style.font?.trim() ? style.font.trim() : null,
    fontSize: Number.isFinite(size) && size >= 6 && size <= 72 ? size : null,
    align,
  };
}

/** A Button of the running net (the source's cButtonOSM): 1 while pressed, 0 when
 * released; a double-click latches it at 1 without holding it, the next press releases
 * it. Each method returns the value to write, or null for none. */
export class ButtonLatch {
  latched = false;
  private pressed = false;

  press(): boolean | null {
    if (this.latched) {
      // a press on a latched button releases it
      this.latched = false;
      this.pressed = false;
      return false;
    }
    this.pressed = true;
    return true;
  }

  release(): boolean | null {
    if (!this.pressed || this.latched) return null;
    this.pressed = false;
    return false;
  }

  /** The second click of a double-click (its press and release already seen). */
  double(): boolean | null {
    this.latched = true;
    this.pressed = false;
    return true;
  }
}
