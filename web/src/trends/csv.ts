// The trend's CSV as people read it (issue 30, item 17), made from the
// server's export (GET /api/history.csv: `Time (ms)` from the range's start,
// sample-and-hold values, an empty cell before a pen's first sample): a first
// column with the absolute local time, the rows before any pen's first sample
// left out, and REAL values in the shortest form that reads back as the same
// 32-bit float (the historian keeps them as 64-bit ones: 49.79472, not
// 49.79471969604492).
import { parseCsv } from '../ui/alarmLog';

/** `v` in the fewest digits that read back as the same f32; other numbers as they are. */
export function shortestF32(v: number): string {
  const f = Math.fround(v);
  if (f !== v || !Number.isFinite(v)) return String(v);
  for (let p = 1; p <= 9; p++) {
    const s = Number(v.toPrecision(p));
    if (Math.fround(s) === f) return String(s);
  }
  return String(v);
}

const pad = (n: number, w = 2) => String(n).padStart(w, '0');

/** A local time as spreadsheets read it: `2026-06-12 16:54:07.250`. */
export function localStamp(ms: number): string {
  const d = new Date(ms);
  return `${d.getFullYear()}-${pad(d.getMonth() + 1)}-${pad(d.getDate())} ${pad(d.getHours())}:${pad(d.getMinutes())}:${pad(d.getSeconds())}.${pad(d.getMilliseconds(), 3)}`;
}

/** The offset of local time from UTC at `ms`: `UTC+02:00`. */
export function utcOffset(ms: number): string {
  const m = -new Date(ms).getTimezoneOffset();
  return `UTC${m < 0 ? '-' : '+'}${pad(Math.floor(Math.abs(m) / 60))}:${pad(Math.abs(m) % 60)}`;
}

const field = (s: string) => (/[",\r\n]/.test(s) ? `"${s.replace(/"/g, '""')}"` : s);

/**
 * The export `text` of the range starting at `from`, for people: columns
 * `Time (UTC±hh:mm)` (local time), `Time (ms)` (from the first row kept) and the
 * pens; `real[k]` says pen k is a REAL.
 */
export function trendCsv(text: string, from: number, real: boolean[]): string {
  const [head, ...rows] = parseCsv(text).filter((r) => r.length > 1 || r[0] !== '');
  if (!head) return text;
  const first = rows.findIndex((r) => r.slice(1).some((c) => c !== ''));
  const kept = first < 0 ? [] : rows.slice(first);
  const t0 = kept.length ? from + Number(kept[0][0]) : from;
  const lines = [[`Time (${utcOffset(t0)})`, ...head].map(field).join(',')];
  for (const r of kept) {
    const t = from + Number(r[0]);
    const values = r.slice(1).map((c, k) => (c !== '' && real[k] ? shortestF32(Number(c)) : c));
    lines.push([localStamp(t), String(t - t0), ...values].map(field).join(','));
  }
  return `${lines.join('\n')}\n`;
}
