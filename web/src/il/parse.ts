// Pure helpers for Instruction List (S7-200 AWL) text: comments, the mnemonic
// and operands of each line, and the power flow of the server's line → id map.

export interface IlLine {
  /** 1-based line number. */
  line: number;
  /** The line without its comments (trimmed). */
  code: string;
  /** Upper-case mnemonic, or null for a blank, comment-only or frame line. */
  mnemonic: string | null;
  /** Operands as written (double quotes of symbols removed), constants left out. */
  operands: string[];
}

/** Lines of the program frame that are not instructions (NETWORK, TITLE, BEGIN…). */
const FRAME = /^(NETWORK|TITLE|BEGIN|END_\w+|ORGANIZATION_BLOCK|SUBROUTINE_BLOCK|INTERRUPT_BLOCK|VAR\w*|END_VAR)\b/i;

/**
 * Removes the comments of one line: `//` to the end and `/* … *\/` (which may
 * start or end on another line: `inBlock` tells whether the line starts inside
 * one). Quoted symbols are kept as they are.
 */
export function stripComments(text: string, inBlock = false): { code: string; inBlock: boolean } {
  let out = '';
  let i = 0;
  let quoted = false;
  while (i < text.length) {
    if (inBlock) {
      const end = text.indexOf('*/', i);
      if (end < 0) return { code: out, inBlock: true };
      i = end + 2;
      inBlock = false;
      out += ' ';
      continue;
    }
    const c = text[i];
    if (c === '"') quoted = !quoted;
    else if (!quoted && c === '/' && text[i + 1] === '/') break;
    else if (!quoted && c === '/' && text[i + 1] === '*') {
      inBlock = true;
      i += 2;
      continue;
    }
    out += c;
    i++;
  }
  return { code: out, inBlock };
}

/** A constant rather than a place: 5, -3, 1.5, 16#FF, T#5s. */
export function isConstant(tok: string): boolean {
  return /^[+-]?\d/.test(tok) || tok.includes('#');
}

/** Splits code (no comments) into tokens on whitespace and commas; "quoted symbols" stay one token (quotes removed). */
export function tokens(code: string): { text: string; quoted: boolean }[] {
  const out: { text: string; quoted: boolean }[] = [];
  let i = 0;
  while (i < code.length) {
    const c = code[i];
    if (c === ',' || /\s/.test(c)) {
      i++;
    } else if (c === '"') {
      const end = code.indexOf('"', i + 1);
      const stop = end < 0 ? code.length : end;
      out.push({ text: code.slice(i + 1, stop), quoted: true });
      i = stop + 1;
    } else {
      let j = i;
      while (j < code.length && code[j] !== ',' && code[j] !== '"' && !/\s/.test(code[j])) j++;
      out.push({ text: code.slice(i, j), quoted: false });
      i = j;
    }
  }
  return out;
}

/** The mnemonic and the operands (places: tag names, addresses) of one line of code without comments. */
export function ilOperands(code: string): { mnemonic: string | null; operands: string[] } {
  const code2 = code.trim();
  if (code2 === '' || FRAME.test(code2)) return { mnemonic: null, operands: [] };
  const [first, ...rest] = tokens(code2);
  if (!first || first.quoted) return { mnemonic: null, operands: [] };
  return {
    mnemonic: first.text.toUpperCase(),
    operands: rest.filter((t) => t.quoted || !isConstant(t.text)).map((t) => t.text).filter((t) => t !== ''),
  };
}

/** Every line of a program, with its mnemonic and operands. */
export function parseIl(text: string): IlLine[] {
  const out: IlLine[] = [];
  let inBlock = false;
  text.split('\n').forEach((raw, k) => {
    const r = stripComments(raw.replace(/\r$/, ''), inBlock);
    inBlock = r.inBlock;
    const { mnemonic, operands } = ilOperands(r.code);
    out.push({ line: k + 1, code: r.code.trim(), mnemonic, operands });
  });
  return out;
}

/** Which instruction lines are energised: `lines` from GET /api/programs (line → id), `on` from `power.on`. */
export function powerByLine(lines: { line: number; id: number | null }[], on: Iterable<number>): Map<number, boolean> {
  const set = on instanceof Set ? (on as Set<number>) : new Set(on);
  const out = new Map<number, boolean>();
  for (const l of lines) out.set(l.line, (out.get(l.line) ?? false) || (l.id !== null && set.has(l.id)));
  return out;
}

