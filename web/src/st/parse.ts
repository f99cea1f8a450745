// Pure helpers for Structured Text (IEC 61131-3) in the studio: a lexer for
// highlighting (keywords, types, literals, comments), the declarations of a
// file (POUs and their variables, TYPE structures, VAR_GLOBAL), the names each
// line reads or writes and the tag each one is (docs/st.md "Names and tags"),
// and the candidates to complete a name. The server's compiler (crates/st)
// stays the judge: these only find what to colour, show and offer.

export type TokKind = 'comment' | 'string' | 'number' | 'keyword' | 'type' | 'builtin' | 'ident' | 'op' | 'space';

export interface Tok {
  kind: TokKind;
  text: string;
  /** Offset in the text. */
  start: number;
  /** 1-based line of the first character. */
  line: number;
}

export const KEYWORDS = new Set(
  (
    'PROGRAM END_PROGRAM FUNCTION END_FUNCTION FUNCTION_BLOCK END_FUNCTION_BLOCK VAR VAR_INPUT VAR_OUTPUT ' +
    'VAR_IN_OUT VAR_TEMP VAR_GLOBAL VAR_EXTERNAL END_VAR RETAIN NON_RETAIN CONSTANT TYPE END_TYPE STRUCT ' +
    'END_STRUCT ARRAY OF IF THEN ELSIF ELSE END_IF CASE END_CASE FOR TO BY DO END_FOR WHILE END_WHILE REPEAT ' +
    'UNTIL END_REPEAT EXIT RETURN AND OR XOR NOT MOD TRUE FALSE'
  ).split(' '),
);

export const TYPES = new Set(
  (
    'BOOL BYTE WORD DWORD LWORD SINT INT DINT LINT USINT UINT UDINT ULINT REAL LREAL TIME LTIME DATE ' +
    'TIME_OF_DAY TOD DATE_AND_TIME DT STRING WSTRING'
  ).split(' '),
);

/** The standard function blocks: inputs and outputs as the standard names them. */
export const STANDARD_FBS: Record<string, { inputs: string[]; outputs: string[] }> = {
  TON: { inputs: ['IN', 'PT'], outputs: ['Q', 'ET'] },
  TOF: { inputs: ['IN', 'PT'], outputs: ['Q', 'ET'] },
  TP: { inputs: ['IN', 'PT'], outputs: ['Q', 'ET'] },
  CTU: { inputs: ['CU', 'R', 'PV'], outputs: ['Q', 'CV'] },
  CTD: { inputs: ['CD', 'LD', 'PV'], outputs: ['Q', 'CV'] },
  CTUD: { inputs: ['CU', 'CD', 'R', 'LD', 'PV'], outputs: ['QU', 'QD', 'CV'] },
  R_TRIG: { inputs: ['CLK'], outputs: ['Q'] },
  F_TRIG: { inputs: ['CLK'], outputs: ['Q'] },
  SR: { inputs: ['S1', 'R'], outputs: ['Q1'] },
  RS: { inputs: ['S', 'R1'], outputs: ['Q1'] },
};

/** The standard functions (the `*_TO_*` conversions are recognised by their shape). */
export const FUNCTIONS = new Set(
  (
    'ABS SQRT LN LOG EXP SIN COS TAN ASIN ACOS ATAN EXPT MOVE TRUNC SHL SHR ROL ROR SEL MUX LIMIT MAX MIN ' +
    'LEN LEFT RIGHT MID CONCAT INSERT DELETE REPLACE FIND'
  ).split(' '),
);

const isConversion = (w: string) => /^[A-Z_]+_TO_[A-Z_]+$/.test(w);

/** What an identifier is to the highlighter. */
export function wordKind(word: string): TokKind {
  const w = word.toUpperCase();
  if (KEYWORDS.has(w)) return 'keyword';
  if (TYPES.has(w) || w in STANDARD_FBS) return 'type';
  if (FUNCTIONS.has(w) || isConversion(w)) return 'builtin';
  return 'ident';
}

const IDENT_START = /[A-Za-z_]/;
const IDENT = /[A-Za-z0-9_]/;

/** Splits ST text into tokens (every character in one token; comments may span lines). */
export function lex(text: string): Tok[] {
  const out: Tok[] = [];
  let i = 0;
  let line = 1;
  const push = (kind: TokKind, end: number) => {
    const t = text.slice(i, end);
    out.push({ kind, text: t, start: i, line });
    for (const c of t) if (c === '\n') line++;
    i = end;
  };
  while (i < text.length) {
    const c = text[i];
    const d = text[i + 1];
    if (/\s/.test(c)) {
      let j = i + 1;
      while (j < text.length && /\s/.test(text[j])) j++;
      push('space', j);
    } else if (c === '(' && d === '*') {
      // nested (* … *)
      let depth = 0;
      let j = i;
      while (j < text.length) {
        if (text[j] === '(' && text[j + 1] === '*') {
          depth++;
          j += 2;
        } else if (text[j] === '*' && text[j + 1] === ')') {
          depth--;
          j += 2;
          if (depth === 0) break;
        } else j++;
      }
      push('comment', Math.min(j, text.length));
    } else if (c === '/' && d === '*') {
      const end = text.indexOf('*/', i + 2);
      push('comment', end < 0 ? text.length : end + 2);
    } else if (c === '/' && d === '/') {
      const end = text.indexOf('\n', i);
      push('comment', end < 0 ? text.length : end);
    } else if (c === '{') {
      // a pragma: shown as a comment
      const end = text.indexOf('}', i);
      push('comment', end < 0 ? text.length : end + 1);
    } else if (c === "'" || c === '"') {
      let j = i + 1;
      while (j < text.length && text[j] !== c && text[j] !== '\n') j += text[j] === '$' ? 2 : 1;
      push('string', Math.min(j + 1, text.length));
    } else if (/\d/.test(c)) {
      let j = i;
      while (j < text.length && /[0-9_.eE]/.test(text[j])) {
        // 1.5E+3: a sign only right after the exponent
        j++;
        if ((text[j - 1] === 'e' || text[j - 1] === 'E') && /[+-]/.test(text[j] ?? '')) j++;
      }
      // 16#FF, 2#1010
      if (text[j] === '#') {
        j++;
        while (j < text.length && /[0-9A-Fa-f_]/.test(text[j])) j++;
      }
      // `1..5` (a range) is two numbers: do not eat the dots
      const dots = text.slice(i, j).indexOf('..');
      push('number', dots >= 0 ? i + dots : j);
    } else if (IDENT_START.test(c)) {
      let j = i + 1;
      while (j < text.length && IDENT.test(text[j])) j++;
      if (text[j] === '#') {
        // typed literals: T#1h2m, DINT#5, INT#-5, DT#2020-01-01-12:00, Color#Red
        j++;
        if (/[+-]/.test(text[j] ?? '')) j++;
        while (j < text.length && /[A-Za-z0-9_.:#-]/.test(text[j])) {
          if (text[j] === '-' && !/^D/i.test(text.slice(i))) break;
          j++;
        }
        push('number', j);
      } else {
        push(wordKind(text.slice(i, j)), j);
      }
    } else {
      const two = text.slice(i, i + 2);
      push('op', [':=', '=>', '<=', '>=', '<>', '**', '..'].includes(two) ? i + 2 : i + 1);
    }
  }
  return out;
}

export interface Span {
  /** `st-kw`, `st-type`, `st-fn`, `st-num`, `st-str`, `st-com`, or '' for plain text. */
  cls: string;
  text: string;
}

const CLASS: Record<TokKind, string> = {
  comment: 'st-com',
  string: 'st-str',
  number: 'st-num',
  keyword: 'st-kw',
  type: 'st-type',
  builtin: 'st-fn',
  ident: '',
  op: '',
  space: '',
};

/** The text cut into coloured spans, line by line (one array per line of the text). */
export function highlight(text: string, toks: Tok[] = lex(text)): Span[][] {
  const lines: Span[][] = [[]];
  for (const t of toks) {
    const cls = t.kind === 'keyword' && /^(TRUE|FALSE)$/i.test(t.text) ? 'st-num' : CLASS[t.kind];
    t.text.split('\n').forEach((part, k) => {
      if (k > 0) lines.push([]);
      if (part === '') return;
      const cur = lines[lines.length - 1];
      const last = cur[cur.length - 1];
      if (last && last.cls === cls) last.text += part;
      else cur.push({ cls, text: part });
    });
  }
  return lines;
}

/**
 * Marks columns `from`..`to` (1-based, `to` exclusive) of a line's spans with
 * ` st-bad` (a problem's place), splitting spans at the edges; `to` null or
 * past the end marks to the end of the line, a range before the first
 * character one column.
 */
export function markRange(spans: Span[], from: number, to: number | null): Span[] {
  const len = spans.reduce((n, s) => n + s.text.length, 0);
  let a = Math.max(0, from - 1);
  let b = to === null || to - 1 > len ? len : Math.max(a, to - 1);
  if (b === a) b = a + 1;
  if (a >= len) {
    a = Math.max(0, len - 1);
    b = len;
  }
  const out: Span[] = [];
  let at = 0;
  for (const s of spans) {
    const end = at + s.text.length;
    const cut = [at, Math.min(Math.max(a, at), end), Math.min(Math.max(b, at), end), end];
    for (let k = 0; k < 3; k++) {
      const part = s.text.slice(cut[k] - at, cut[k + 1] - at);
      if (part) out.push({ cls: k === 1 ? `${s.cls} st-bad`.trim() : s.cls, text: part });
    }
    at = end;
  }
  return out;
}

// ---- declarations ----------------------------------------------------------

export interface VarDecl {
  name: string;
  /** The type as written, upper case for the elementary and standard ones (`TON`, `ARRAY`, `Point`). */
  type: string;
  /** For an ARRAY: the element type. */
  of: string | null;
  section: string;
  line: number;
}

export interface Pou {
  kind: 'PROGRAM' | 'FUNCTION' | 'FUNCTION_BLOCK';
  name: string;
  /** First and last line (END_…), 1-based. */
  from: number;
  to: number;
  vars: VarDecl[];
  /** Lines inside VAR blocks (declarations, not code). */
  declLines: Set<number>;
}

export interface Decls {
  pous: Pou[];
  /** VAR_GLOBAL at file level. */
  globals: VarDecl[];
  /** STRUCT types by upper-case name: their members. */
  structs: Map<string, VarDecl[]>;
  /** Enumeration types by upper-case name: their values. */
  enums: Map<string, string[]>;
}

/** The tokens without spaces and comments. */
export function code(toks: Tok[]): Tok[] {
  return toks.filter((t) => t.kind !== 'space' && t.kind !== 'comment');
}

const up = (t: Tok | undefined) => (t ? t.text.toUpperCase() : '');

/** Reads `a, b : T …;` declarations from `k` up to `end` (END_VAR / END_STRUCT); returns them and where it stopped. */
function readVars(ts: Tok[], k: number, end: string, section: string): { vars: VarDecl[]; k: number } {
  const vars: VarDecl[] = [];
  while (k < ts.length && up(ts[k]) !== end) {
    const names: Tok[] = [];
    while (k < ts.length && ts[k].kind === 'ident') {
      names.push(ts[k++]);
      if (ts[k]?.text === ',') k++;
      else break;
    }
    // `x AT %IX0.0 : BOOL`
    if (up(ts[k]) === 'AT') k += 2;
    if (names.length && ts[k]?.text === ':') {
      k++;
      let type = ts[k]?.text ?? '';
      let of: string | null = null;
      if (up(ts[k]) === 'ARRAY') {
        let j = k;
        while (j < ts.length && up(ts[j]) !== 'OF' && ts[j].text !== ';') j++;
        of = up(ts[j]) === 'OF' ? (ts[j + 1]?.text ?? null) : null;
        type = 'ARRAY';
      }
      const norm = (s: string) => (wordKind(s) === 'type' ? s.toUpperCase() : s);
      for (const n of names) vars.push({ name: n.text, type: norm(type), of: of && norm(of), section, line: n.line });
    }
    // to the end of the declaration (a nested STRUCT … END_STRUCT counts as one)
    let depth = 0;
    while (k < ts.length) {
      const w = up(ts[k]);
      if (w === 'STRUCT') depth++;
      else if (w === 'END_STRUCT') depth--;
      else if (depth <= 0 && (w === end || (depth === 0 && ts[k].text === ';'))) break;
      k++;
    }
    if (ts[k]?.text === ';') k++;
  }
  return { vars, k };
}

/** The POUs, globals and types declared in a file. */
export function declarations(text: string, toks: Tok[] = lex(text)): Decls {
  const ts = code(toks);
  const out: Decls = { pous: [], globals: [], structs: new Map(), enums: new Map() };
  let pou: Pou | null = null;
  let k = 0;
  while (k < ts.length) {
    const w = up(ts[k]);
    if (w === 'PROGRAM' || w === 'FUNCTION' || w === 'FUNCTION_BLOCK') {
      pou = { kind: w, name: ts[k + 1]?.kind === 'ident' ? ts[k + 1].text : '', from: ts[k].line, to: ts[k].line, vars: [], declLines: new Set() };
      out.pous.push(pou);
      k += 2;
    } else if (/^END_(PROGRAM|FUNCTION|FUNCTION_BLOCK)$/.test(w)) {
      if (pou) pou.to = ts[k].line;
      pou = null;
      k++;
    } else if (w.startsWith('VAR')) {
      const from = ts[k].line;
      k++;
      while (['RETAIN', 'NON_RETAIN', 'CONSTANT'].includes(up(ts[k]))) k++;
      const r = readVars(ts, k, 'END_VAR', w);
      k = r.k + 1;
      const to = ts[r.k]?.line ?? from;
      if (pou) {
        pou.vars.push(...r.vars);
        for (let n = from; n <= to; n++) pou.declLines.add(n);
      } else out.globals.push(...r.vars);
    } else if (w === 'TYPE') {
      k++;
      while (k < ts.length && up(ts[k]) !== 'END_TYPE') {
        const name = ts[k];
        if (name.kind === 'ident' && ts[k + 1]?.text === ':') {
          k += 2;
          if (up(ts[k]) === 'STRUCT') {
            const r = readVars(ts, k + 1, 'END_STRUCT', 'STRUCT');
            out.structs.set(name.text.toUpperCase(), r.vars);
            k = r.k + 1;
          } else if (ts[k]?.text === '(') {
            const values: string[] = [];
            while (k < ts.length && ts[k].text !== ')') {
              if (ts[k].kind === 'ident') values.push(ts[k].text);
              k++;
            }
            out.enums.set(name.text.toUpperCase(), values);
          }
        }
        while (k < ts.length && ts[k].text !== ';' && up(ts[k]) !== 'END_TYPE') k++;
        if (ts[k]?.text === ';') k++;
      }
      k++;
    } else k++;
  }
  return out;
}

/** The POU a line is in. */
export function pouAt(d: Decls, line: number): Pou | null {
  return d.pous.find((p) => line >= p.from && line <= p.to) ?? null;
}

// ---- names and tags --------------------------------------------------------

/** The member of the engine structure (TIMER, COUNTER) or the BOOL tag an FB output or input is. */
const FB_MEMBER: Record<string, Record<string, string>> = {
  TIMER: { Q: 'DN', ET: 'ACC', IN: 'EN', PT: 'PRE', '': 'ACC' },
  CTU: { CV: 'ACC', PV: 'PRE', Q: 'DN', CU: 'CU', '': 'ACC' },
  CTD: { CV: 'ACC', PV: 'PRE', CD: 'CD', '': 'ACC' },
  CTUD: { CV: 'ACC', PV: 'PRE', CU: 'CU', CD: 'CD', '': 'ACC' },
  R_TRIG: { Q: 'Q', '': 'Q' },
  F_TRIG: { Q: 'Q', '': 'Q' },
  SR: { Q1: 'Q1', '': 'Q1' },
  RS: { Q1: 'Q1', '': 'Q1' },
};

function fbMembers(type: string): Record<string, string> | null {
  const t = type.toUpperCase();
  return t === 'TON' || t === 'TOF' || t === 'TP' ? FB_MEMBER.TIMER : (FB_MEMBER[t] ?? null);
}

/** A name as written in the code (`delay.Q`, `Main.a[2]`, `Motor`) and where. */
export interface NameRef {
  text: string;
  line: number;
  /** 0-based column in the line. */
  col: number;
}

/**
 * The names each code line reads or writes: identifiers with their members
 * and constant indexes (`p.x`, `a[2]`), not keywords, types, functions,
 * formal parameters (`IN :=`) nor names in declarations. An index that is not
 * a constant ends the name (`a[i]` is `a`, and `i`).
 */
export function namesByLine(text: string, toks: Tok[] = lex(text), d: Decls = declarations(text, toks)): Map<number, NameRef[]> {
  const ts = code(toks);
  const out = new Map<number, NameRef[]>();
  const lineStart: number[] = [0];
  for (let i = 0; i < text.length; i++) if (text[i] === '\n') lineStart.push(i + 1);
  let k = 0;
  while (k < ts.length) {
    const t = ts[k];
    const pou = pouAt(d, t.line);
    if (t.kind !== 'ident' || !pou || pou.declLines.has(t.line) || t.line === pou.from) {
      k++;
      continue;
    }
    const prev = ts[k - 1]?.text;
    // a member after a name already taken (`x.y` with `x` cut off by a non-constant index)
    if (prev === '.') {
      k++;
      continue;
    }
    let name = t.text;
    let j = k + 1;
    for (;;) {
      if (ts[j]?.text === '.' && ts[j + 1]?.kind === 'ident') {
        name += `.${ts[j + 1].text}`;
        j += 2;
      } else if (ts[j]?.text === '[') {
        // only constant indexes: [1], [0, 2]
        const idx: string[] = [];
        let m = j + 1;
        while (ts[m]?.kind === 'number' || (ts[m]?.text === '-' && ts[m + 1]?.kind === 'number')) {
          if (ts[m].text === '-') {
            idx.push(`-${ts[m + 1].text}`);
            m += 2;
          } else idx.push(ts[m++].text);
          if (ts[m]?.text === ',') m++;
          else break;
        }
        if (idx.length && ts[m]?.text === ']') {
          name += `[${idx.join(',')}]`;
          j = m + 1;
        } else break;
      } else break;
    }
    const next = ts[j]?.text;
    const formal = (prev === '(' || prev === ',') && (next === ':=' || next === '=>');
    const isVar = pou.vars.some((v) => v.name.toUpperCase() === t.text.toUpperCase());
    // a call of a function or of a POU (not of an instance: `delay(…)` is a variable)
    const call = next === '(' && !isVar && !name.includes('.');
    if (!formal && !call) {
      const col = t.start - lineStart[t.line - 1];
      const list = out.get(t.line) ?? [];
      if (!list.some((r) => r.text.toUpperCase() === name.toUpperCase())) list.push({ text: name, line: t.line, col });
      out.set(t.line, list);
    }
    k = j;
  }
  return out;
}

/** A name's tag and its ST type, when the declarations tell it (TIME shows as `T#…`). */
export interface TagOfName {
  tag: string;
  type: string | null;
}

/** The ST type of a standard FB's member (ET/PT: TIME). */
function fbMemberType(member: string, fbType: string): string {
  const m = member.toUpperCase();
  if (m === 'ET' || m === 'PT' || (m === '' && /^(TON|TOF|TP)$/i.test(fbType))) return 'TIME';
  if (m === 'CV' || m === 'PV' || m === '') return /^(R_TRIG|F_TRIG|SR|RS)$/i.test(fbType) ? 'BOOL' : 'INT';
  return 'BOOL';
}

/**
 * The tag a name of the code is, in its POU (docs/st.md "Names and tags"):
 * a PROGRAM's variable `v` is `<program>.v`, a member of a standard FB
 * instance the member of its TIMER/COUNTER (`delay.Q` → `Main.delay.DN`,
 * a bare instance its ET/CV), a global (VAR_GLOBAL, VAR_EXTERNAL, a tag of
 * tags.csv) its own name; a FUNCTION_BLOCK's variable the one of
 * `instance` (`Main.c1.n`). `tag` says whether a tag exists and gives its
 * canonical name; null for names with no tag (FUNCTION locals, FUNCTION_BLOCK
 * locals with no instance, VAR_IN_OUT, values of enumerations, unknown names).
 */
export function tagOf(name: string, pou: Pou | null, d: Decls, tag: (name: string) => string | null, instance: string | null = null): TagOfName | null {
  const parts = name.split('.');
  const head = parts[0].replace(/\[.*$/, '').toUpperCase();
  const found = (t: string | null, type: string | null) => (t ? { tag: t, type } : null);
  const v = pou?.vars.find((x) => x.name.toUpperCase() === head) ?? d.globals.find((x) => x.name.toUpperCase() === head);
  if (v) {
    const local = pou?.vars.includes(v) ?? false;
    const global = !local || v.section === 'VAR_GLOBAL' || v.section === 'VAR_EXTERNAL';
    if (!global && v.section === 'VAR_IN_OUT') return null;
    let base: string;
    if (global) base = parts[0];
    else if (pou!.kind === 'PROGRAM') base = `${pou!.name}.${parts[0]}`;
    // a FUNCTION_BLOCK's variable: the one of the instance shown
    else if (pou!.kind === 'FUNCTION_BLOCK' && instance) base = `${instance}.${parts[0]}`;
    else return null;
    const fb = fbMembers(v.type);
    if (fb) {
      const member = parts[1] ?? '';
      const m = fb[member.toUpperCase()];
      if (m === undefined || parts.length > 2) return null;
      return found(tag(`${base}.${m}`), fbMemberType(member, v.type));
    }
    const elem = parts[0].includes('[') && v.of ? v.of : v.type;
    return found(tag([base, ...parts.slice(1)].join('.')), parts.length === 1 ? elem : null);
  }
  if ([...d.enums.values()].some((vals) => vals.some((x) => x.toUpperCase() === head))) return null;
  return found(tag(name), null);
}

/**
 * The instances of a FUNCTION_BLOCK, as tag prefixes: PROGRAM variables
 * (`Main.c1`), globals (`g1`) and instances inside other FBs' instances
 * (`Main.p.a`). Arrays of instances are left out.
 */
export function instancesOf(d: Decls, fb: string, depth = 0): string[] {
  const want = fb.toUpperCase();
  const out: string[] = [];
  for (const v of d.globals) if (v.type.toUpperCase() === want) out.push(v.name);
  for (const p of d.pous) {
    const of = p.vars.filter((v) => v.type.toUpperCase() === want && v.section !== 'VAR_IN_OUT' && v.section !== 'VAR_TEMP');
    if (p.kind === 'PROGRAM') {
      for (const v of of) out.push(v.section === 'VAR_GLOBAL' ? v.name : `${p.name}.${v.name}`);
    } else if (p.kind === 'FUNCTION_BLOCK' && of.length && depth < 8 && p.name.toUpperCase() !== want) {
      for (const outer of instancesOf(d, p.name, depth + 1)) for (const v of of) out.push(`${outer}.${v.name}`);
    }
  }
  return out;
}

// ---- completion ------------------------------------------------------------

export interface Completion {
  label: string;
  /** What it is: `variable`, `tag`, `member`, `keyword`, `type`, `function`. */
  kind: string;
  detail: string;
}

/** The word being typed before `caret`: the path before the last dot and the part after it. */
export function wordAt(text: string, caret: number): { base: string | null; prefix: string; from: number } {
  let i = caret;
  while (i > 0 && IDENT.test(text[i - 1])) i--;
  const prefix = text.slice(i, caret);
  if (text[i - 1] !== '.') return { base: null, prefix, from: i };
  let j = i - 1;
  while (j > 0 && /[A-Za-z0-9_.[\]]/.test(text[j - 1])) j--;
  return { base: text.slice(j, i - 1), prefix, from: i };
}

export interface CompletionEnv {
  /** Tags of tags.csv (and the server's tag list): name and type. */
  tags: { name: string; type: string }[];
  /** Members of a structure type of the domain (TIMER, COUNTER…). */
  members(type: string): string[];
}

/** The members a name with this declared type has (an FB's, a STRUCT's, a domain structure's). */
function membersOfType(type: string, d: Decls, env: CompletionEnv): Completion[] {
  const t = type.toUpperCase();
  const fb = STANDARD_FBS[t];
  if (fb) return [...fb.inputs.map((m) => ({ label: m, kind: 'member', detail: `${t} input` })), ...fb.outputs.map((m) => ({ label: m, kind: 'member', detail: `${t} output` }))];
  const user = d.pous.find((p) => p.kind === 'FUNCTION_BLOCK' && p.name.toUpperCase() === t);
  if (user) return user.vars.filter((v) => v.section !== 'VAR_TEMP').map((v) => ({ label: v.name, kind: 'member', detail: `${v.type} (${v.section})` }));
  const st = d.structs.get(t);
  if (st) return st.map((v) => ({ label: v.name, kind: 'member', detail: v.type }));
  return env.members(type).map((m) => ({ label: m, kind: 'member', detail: type }));
}

/** The type of a dotted path in a POU (variables, their members, tags). */
function typeOfPath(path: string, pou: Pou | null, d: Decls, env: CompletionEnv): string | null {
  const parts = path.split('.').map((p) => p.replace(/\[.*$/, ''));
  const head = parts[0].toUpperCase();
  const v = pou?.vars.find((x) => x.name.toUpperCase() === head) ?? d.globals.find((x) => x.name.toUpperCase() === head);
  let type: string | null = v ? (path.split('.')[0].includes('[') && v.of ? v.of : v.type) : (env.tags.find((t) => t.name.toUpperCase() === head)?.type ?? null);
  for (const m of parts.slice(1)) {
    if (!type) return null;
    const t: string = type.toUpperCase();
    const user = d.pous.find((p) => p.kind === 'FUNCTION_BLOCK' && p.name.toUpperCase() === t);
    const fields = user?.vars ?? d.structs.get(t);
    const f = fields?.find((x) => x.name.toUpperCase() === m.toUpperCase());
    type = f ? f.type : null;
  }
  return type;
}

/**
 * What can be typed at `caret`: after `x.`, the members of x's type; else the
 * POU's variables, the globals and tags, the POUs and types of the file, the
 * standard functions and FBs, and keywords; those that start with what is
 * typed (any case), best first.
 */
export function complete(text: string, caret: number, env: CompletionEnv, d: Decls = declarations(text)): { from: number; items: Completion[] } {
  const { base, prefix, from } = wordAt(text, caret);
  const line = text.slice(0, caret).split('\n').length;
  const pou = pouAt(d, line);
  const p = prefix.toUpperCase();
  const fits = (c: Completion) => c.label.toUpperCase().startsWith(p);
  if (base !== null) {
    const type = typeOfPath(base, pou, d, env);
    return { from, items: type ? membersOfType(type, d, env).filter(fits) : [] };
  }
  const all: Completion[] = [];
  const seen = new Set<string>();
  // in the parentheses of an instance's call: its parameters first
  const inCall = callee(text, from);
  const callType = inCall ? typeOfPath(inCall, pou, d, env) : null;
  const params = callType ? membersOfType(callType, d, env).map((c) => ({ ...c, kind: 'parameter' })) : [];
  const add = (c: Completion) => {
    const k = c.label.toUpperCase();
    if (seen.has(k) || k === p) return;
    seen.add(k);
    if (fits(c)) all.push(c);
  };
  params.forEach(add);
  for (const v of pou?.vars ?? []) add({ label: v.name, kind: 'variable', detail: v.type === 'ARRAY' ? `ARRAY OF ${v.of}` : v.type });
  for (const v of d.globals) add({ label: v.name, kind: 'variable', detail: v.type });
  for (const t of env.tags) if (!t.name.includes('.')) add({ label: t.name, kind: 'tag', detail: t.type });
  for (const x of d.pous) if (x.kind !== 'PROGRAM') add({ label: x.name, kind: 'type', detail: x.kind });
  for (const n of [...d.structs.keys(), ...d.enums.keys()]) add({ label: n, kind: 'type', detail: 'TYPE' });
  for (const f of FUNCTIONS) add({ label: f, kind: 'function', detail: '' });
  for (const f of Object.keys(STANDARD_FBS)) add({ label: f, kind: 'type', detail: 'FUNCTION_BLOCK' });
  for (const t of TYPES) add({ label: t, kind: 'type', detail: '' });
  for (const k of KEYWORDS) add({ label: k, kind: 'keyword', detail: '' });
  return { from, items: p === '' ? all.filter((c) => c.kind === 'parameter' || c.kind === 'variable' || c.kind === 'tag') : all };
}

/**
 * The name called by the parentheses that are open at `at` in its statement
 * (`delay(IN := x, |` → `delay`), or null outside a call.
 */
export function callee(text: string, at: number): string | null {
  let depth = 0;
  for (let i = at - 1; i >= 0; i--) {
    const c = text[i];
    if (c === ';') return null;
    if (c === ')') depth++;
    else if (c === '(') {
      if (text[i + 1] === '*') continue;
      if (depth > 0) {
        depth--;
        continue;
      }
      const m = /([A-Za-z_][A-Za-z0-9_.[\]]*)\s*$/.exec(text.slice(Math.max(0, i - 200), i));
      return m ? m[1] : null;
    }
  }
  return null;
}

/**
 * The indentation of a new line after `line`: the same as it has, one step
 * (4 spaces) more after a line that opens a block (`THEN`, `ELSE`, `DO`,
 * `REPEAT`, `OF`, `VAR…`, `STRUCT`; not a POU's first line: bodies are
 * written flush, as in the examples), comments ignored.
 */
export function indentAfter(line: string): string {
  const own = /^[ \t]*/.exec(line)?.[0] ?? '';
  const code = highlight(line)[0]
    .filter((s) => s.cls !== 'st-com')
    .map((s) => s.text)
    .join('')
    .trim();
  const opens =
    /\b(THEN|ELSE|DO|REPEAT|OF|STRUCT)$/i.test(code) ||
    (/^VAR\w*\b/i.test(code) && !/\bEND_VAR;?$/i.test(code));
  return opens ? own + '    ' : own;
}

/** The whole dotted name around `caret` (`delay.Q`, `a[2]`), or null off a name. */
export function nameAt(text: string, caret: number): string | null {
  const part = /[A-Za-z0-9_.[\]]/;
  let a = caret;
  let b = caret;
  while (a > 0 && part.test(text[a - 1])) a--;
  while (b < text.length && part.test(text[b])) b++;
  const name = text.slice(a, b).replace(/^[.\]]+|[.[]+$/g, '');
  return IDENT_START.test(name[0] ?? '') ? name : null;
}

/** Whether the character before `at` is inside a comment or a string (no completion there). */
export function inCommentOrString(toks: Tok[], at: number): boolean {
  let lo = 0;
  let hi = toks.length - 1;
  while (lo <= hi) {
    const mid = (lo + hi) >> 1;
    const t = toks[mid];
    if (at - 1 < t.start) hi = mid - 1;
    else if (at - 1 >= t.start + t.text.length) lo = mid + 1;
    else return t.kind === 'comment' || t.kind === 'string';
  }
  return false;
}

// ---- values ----------------------------------------------------------------

/** A value as ST writes it: TIME in ms as `T#…`, booleans TRUE/FALSE, REAL shortened. */
export function formatValue(v: unknown, type: string | null): string {
  if (v === null || v === undefined) return '…';
  if (typeof v === 'boolean') return v ? 'TRUE' : 'FALSE';
  if (typeof v === 'number' && type?.toUpperCase() === 'TIME') return timeLiteral(v);
  if (typeof v === 'number' && !Number.isInteger(v)) return String(Number(v.toPrecision(6)));
  if (typeof v === 'string') return `'${v}'`;
  if (typeof v === 'object') return JSON.stringify(v);
  return String(v);
}

/** Milliseconds as a TIME literal: 0 → T#0ms, 1500 → T#1s500ms, 3723000 → T#1h2m3s. */
export function timeLiteral(ms: number): string {
  if (ms === 0) return 'T#0ms';
  const sign = ms < 0 ? '-' : '';
  let rest = Math.abs(Math.round(ms));
  const parts: string[] = [];
  for (const [unit, n] of [
    ['d', 86_400_000],
    ['h', 3_600_000],
    ['m', 60_000],
    ['s', 1000],
    ['ms', 1],
  ] as const) {
    const q = Math.floor(rest / n);
    rest -= q * n;
    if (q) parts.push(`${q}${unit}`);
  }
  return `T#${sign}${parts.join('')}`;
}
