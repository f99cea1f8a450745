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

/** Numbers and dates for people: the language's conventions. */
export function locale(): string {
  return current === 'es' ? 'es-ES' : 'en-US';
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

/** A time of day for people. */
export function clockTime(ms: number): string {
  return new Date(ms).toLocaleTimeString(locale());
}
