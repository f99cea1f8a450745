// The studio's words in English and Spanish (issue 16, docs/i18n.md). Every
// visible string goes through `tr('English text', {args})`: English is the
// message itself (gettext-style), `es` maps each message to its Spanish; `{name}`
// placeholders take `args`. The language is chosen once per page load: the one
// the user picked (remembered), else the browser's (Spanish for any `es-*`).
// test/i18n.test.ts fails when a message has no Spanish, when Spanish keeps a
// message the code no longer uses, and when a visible string bypasses `tr`.
import { es } from './i18n.es';

export type Lang = 'en' | 'es';
export const LANGUAGES: [Lang, string][] = [
  ['en', 'English'],
  ['es', 'Español'],
];
const KEY = 'alba.lang';

/** The language to use: the stored choice, else the browser's. */
export function chooseLanguage(stored: string | null, browser: string | undefined): Lang {
  if (stored === 'en' || stored === 'es') return stored;
  return browser?.toLowerCase().startsWith('es') ? 'es' : 'en';
}

function initial(): Lang {
  try {
    return chooseLanguage(localStorage.getItem(KEY), navigator.language);
  } catch {
    return 'en';
  }
}

let current: Lang = initial();
showLanguage();

/** `<html lang>` says the language in use (screen readers, hyphenation, the browser's translation offer). */
function showLanguage(): void {
  if (typeof document !== 'undefined') document.documentElement.lang = current;
}

export function language(): Lang {
  return current;
}

/**
 * Dates and times for people (docs/i18n.md, "Dates and times"): Spanish is
 * es-ES (dd/mm/yyyy, 24 h); English is en-US (m/d/yyyy, 12 h) only in a
 * browser whose language is en-US, else en-GB (dd/mm/yyyy, 24 h).
 */
export function locale(): string {
  if (current === 'es') return 'es-ES';
  return browserLanguage().toLowerCase() === 'en-us' ? 'en-US' : 'en-GB';
}

let browserLanguage = (): string => (typeof navigator === 'undefined' ? '' : navigator.language ?? '');

/** For tests: the browser's language. */
export function useBrowserLanguage(l: string): void {
  browserLanguage = () => l;
}

/** Remembers `l` and reloads the page in it (every view is built in one language). */
export function setLanguage(l: Lang): void {
  localStorage.setItem(KEY, l);
  location.reload();
}

/** For tests: switch without a reload. */
export function useLanguage(l: Lang): void {
  current = l;
  showLanguage();
}

/** `msg` in the current language, with `{name}` replaced from `args`. */
export function tr(msg: string, args?: Record<string, string | number>): string {
  const s = (current === 'es' ? es[msg] : undefined) ?? msg;
  return args ? s.replace(/\{(\w+)\}/g, (all, k: string) => (k in args ? String(args[k]) : all)) : s;
}

const formats = new Map<string, Intl.DateTimeFormat>();
function format(kind: 'time' | 'minute' | 'date' | 'datetime'): Intl.DateTimeFormat {
  const key = `${locale()} ${kind}`;
  let f = formats.get(key);
  if (!f) {
    const date = { day: '2-digit', month: '2-digit', year: 'numeric' } as const;
    // 24 h clocks as on a panel (06:04:07); the US its own (6:04:07 AM)
    const hour = locale() === 'en-US' ? 'numeric' : '2-digit';
    const time = { hour, minute: '2-digit', second: '2-digit' } as const;
    const opts: Intl.DateTimeFormatOptions =
      kind === 'time' ? time : kind === 'minute' ? { hour, minute: '2-digit' } : kind === 'date' ? date : { ...date, ...time };
    f = new Intl.DateTimeFormat(locale(), opts);
    formats.set(key, f);
  }
  return f;
}

/** A time of day for people: `16:54:07` (`4:54:07 PM` in en-US). */
export function clockTime(ms: number): string {
  return format('time').format(ms);
}

/** A time of day to the minute: `16:54`. */
export function minuteTime(ms: number): string {
  return format('minute').format(ms);
}

/** A date: `12/06/2026` (`06/12/2026` in en-US). */
export function dateOnly(ms: number): string {
  return format('date').format(ms);
}

/** A date and a time of day: `12/06/2026, 16:54:07`. */
export function dateTime(ms: number): string {
  return format('datetime').format(ms);
}

/** A moment for a list: the time of day when it is on the day of `now`, else the date and the time. */
export function when(ms: number, now = Date.now()): string {
  return dateOnly(ms) === dateOnly(now) ? clockTime(ms) : dateTime(ms);
}
