// The message catalogue (issue 16): every message the studio shows has its
// Spanish, Spanish keeps no message the code dropped, and no visible string
// bypasses `tr`.
import { readFileSync, readdirSync, statSync } from 'node:fs';
import { join } from 'node:path';
import { afterEach, describe, expect, it } from 'vitest';
import { chooseLanguage, clockTime, dateOnly, dateTime, minuteTime, tr, useBrowserLanguage, useLanguage, when } from '../src/i18n';
import { es } from '../src/i18n.es';

const SRC = join(__dirname, '../src');

function sources(dir = SRC): string[] {
  return readdirSync(dir).flatMap((n) => {
    const p = join(dir, n);
    if (statSync(p).isDirectory()) return sources(p);
    return n.endsWith('.ts') && !n.startsWith('i18n') && n !== 'api.gen.ts' ? [p] : [];
  });
}

/** The messages the code asks for: the literal first argument of every `tr(…)`. */
function messages(): Map<string, string> {
  const out = new Map<string, string>();
  for (const f of sources()) {
    const text = readFileSync(f, 'utf8');
    for (const m of text.matchAll(/\btr\(\s*'((?:[^'\\]|\\.)*)'/g)) out.set(m[1].replace(/\\'/g, "'"), f);
  }
  return out;
}

/** A string literal as people would read it: lower-case letters with a capital or a space. */
const prose = (lit: string) => {
  const s = lit.replace(/\$\{[^}]*\}/g, '').trim(); // the words around a template's values
  return /[a-z]/.test(s) && (/^[A-Z]/.test(s) || / /.test(s));
};

describe('the English/Spanish catalogue', () => {
  afterEach(() => useLanguage('en'));

  it('has a Spanish message for every message of the code, and no other', () => {
    const used = messages();
    expect(used.size).toBeGreaterThan(150);
    const missing = [...used.keys()].filter((m) => !(m in es));
    expect(missing, 'messages without Spanish (src/i18n.es.ts)').toEqual([]);
    const stale = Object.keys(es).filter((m) => !used.has(m));
    expect(stale, 'Spanish for messages the code no longer uses').toEqual([]);
    for (const [m, s] of Object.entries(es)) {
      expect(s.trim(), m).not.toBe('');
      // the same placeholders, in any order
      const names = (t: string) => [...t.matchAll(/\{(\w+)\}/g)].map((x) => x[1]).sort();
      expect(names(s), m).toEqual(names(m));
    }
  });

  it('passes messages only as literals (so that this test sees them all)', () => {
    for (const f of sources()) {
      const bad = [...readFileSync(f, 'utf8').matchAll(/\btr\(\s*([^'\s])/g)].map((m) => m[0]);
      expect(bad, f).toEqual([]);
    }
  });

  it('finds no visible string that bypasses tr', () => {
    const rules: [RegExp, string][] = [
      [/\b(title|placeholder|'aria-label'):\s*(['`])((?:(?!\2).)*)\2/g, 'attribute'],
      [/\bnotify\(\s*(['`])((?:(?!\1).)*)\1/g, 'notification'],
      // a text child: a literal argument after a comma, in a line that builds elements
      [/,\s*'([^'\n]*)'\s*(?=[,)])/g, 'text'],
    ];
    const allowed = new Set(['Alba', 'F1', 'F0']);
    const found: string[] = [];
    for (const f of sources()) {
      readFileSync(f, 'utf8')
        .split('\n')
        .forEach((line, n) => {
          if (/^\s*(\/\/|\*|\/\*)/.test(line)) return;
          for (const [re, kind] of rules) {
            if (kind === 'text' && !/\bh\(|\bs\(|modeBtn\(|tool\(|field\(/.test(line)) continue;
            for (const m of line.matchAll(re)) {
              const lit = m[m.length - 1];
              if (prose(lit) && !allowed.has(lit)) found.push(`${f.slice(SRC.length + 1)}:${n + 1}: ${kind} '${lit}'`);
            }
          }
        });
    }
    expect(found).toEqual([]);
  });

  it('speaks Spanish when asked, English by default, and fills placeholders', () => {
    expect(chooseLanguage(null, 'es-AR')).toBe('es');
    expect(chooseLanguage(null, 'en-GB')).toBe('en');
    expect(chooseLanguage('en', 'es-ES')).toBe('en');
    expect(chooseLanguage('xx', undefined)).toBe('en');
    expect(tr('{n} forces active', { n: 3 })).toBe('3 forces active');
    useLanguage('es');
    expect(tr('Run')).toBe('Ejecutar');
    expect(tr('{n} forces active', { n: 3 })).toBe('3 forzados activos');
    expect(tr('a message nobody translated')).toBe('a message nobody translated');
  });

  it('says the language in <html lang>', () => {
    useLanguage('es');
    expect(document.documentElement.lang).toBe('es');
    useLanguage('en');
    expect(document.documentElement.lang).toBe('en');
  });
});

describe('dates and times, one format per language (issue 30, item 12)', () => {
  afterEach(() => {
    useLanguage('en');
    useBrowserLanguage('en-US');
  });
  const t = new Date(2026, 5, 12, 16, 54, 7).getTime();
  const morning = new Date(2026, 5, 12, 6, 4, 7).getTime();

  it('Spanish: dd/mm/yyyy and 24 h, whatever the browser', () => {
    useLanguage('es');
    for (const browser of ['en-US', 'es-ES', 'de-DE']) {
      useBrowserLanguage(browser);
      expect(dateTime(t)).toBe('12/06/2026, 16:54:07');
      expect(clockTime(morning)).toBe('06:04:07');
      expect(minuteTime(t)).toBe('16:54');
      expect(dateOnly(t)).toBe('12/06/2026');
    }
  });

  it('English: the US order and clock only in an en-US browser, else day/month and 24 h', () => {
    useBrowserLanguage('en-US');
    expect(dateTime(t)).toBe('06/12/2026, 4:54:07 PM');
    expect(clockTime(t)).toBe('4:54:07 PM');
    for (const browser of ['en-GB', 'es-ES', 'en', '']) {
      useBrowserLanguage(browser);
      expect(dateTime(t), browser).toBe('12/06/2026, 16:54:07');
      expect(clockTime(morning), browser).toBe('06:04:07');
    }
  });

  it('says the date only when it is not today', () => {
    useBrowserLanguage('en-GB');
    expect(when(t, t + 3600e3)).toBe('16:54:07');
    expect(when(t, t + 86400e3)).toBe('12/06/2026, 16:54:07');
  });
});
