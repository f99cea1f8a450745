// A client-side reader of ladder text (docs/ladder.md §2): splits a program
// into rungs, keeping each rung's exact source slice so that an edit of one
// rung replaces only its text, and parses each rung into the element tree
// with line/column positions (columns in characters, from 1, as the server).
import type { Elem, Pos } from './ast';

export interface ParseError extends Pos {
  message: string;
}

export interface RungSource {
  /** Leading blank lines, kept when the rung is replaced. */
  lead: string;
  /** The rung's own text: comment lines, the rung, a same-line comment, the line break. */
  own: string;
  comment: string[];
  /** The rung body (between the comments and the `;`). */
  body: string;
  /** The tree, or null when the rung does not parse. */
  elements: Elem[] | null;
  error: ParseError | null;
  /** First and last line of `own` (1-based). */
  startLine: number;
  endLine: number;
}

export interface ProgramDoc {
  rungs: RungSource[];
  /** Text after the last rung (comments, blank lines, an unterminated rung). */
  tail: string;
  tailError: ParseError | null;
}

/** A cursor over the code points of a text, tracking line and column. */
class Cursor {
  i = 0;
  line = 1;
  col = 1;
  constructor(readonly cs: string[]) {}
  get done(): boolean {
    return this.i >= this.cs.length;
  }
  peek(k = 0): string {
    return this.cs[this.i + k] ?? '';
  }
  next(): string {
    const c = this.cs[this.i++] ?? '';
    if (c === '\n') {
      this.line++;
      this.col = 1;
    } else this.col++;
    return c;
  }
  pos(): Pos {
    return { line: this.line, col: this.col };
  }
  save(): [number, number, number] {
    return [this.i, this.line, this.col];
  }
  restore([i, line, col]: [number, number, number]): void {
    this.i = i;
    this.line = line;
    this.col = col;
  }
}

const isSpace = (c: string) => c === ' ' || c === '\t' || c === '\r' || c === '\n' || c === '\uFEFF';

class Fail extends Error {
  constructor(readonly at: ParseError) {
    super(at.message);
  }
}

function skipSpaces(c: Cursor): void {
  while (!c.done && isSpace(c.peek())) c.next();
}

function fail(c: Cursor, message: string): never {
  throw new Fail({ message, ...c.pos() });
}

/** Parses elements until `;`, `,` or `]` (not consumed). */
function parseSeries(c: Cursor, depth: number): Elem[] {
  const out: Elem[] = [];
  for (;;) {
    skipSpaces(c);
    const ch = c.peek();
    if (ch === '' || ch === ';' || ch === ',' || ch === ']') return out;
    if (ch === '/' && c.peek(1) === '/') fail(c, 'a comment inside a rung (missing `;`?)');
    if (ch === '[') out.push(parseBranch(c, depth + 1));
    else out.push(parseInstr(c));
  }
}

function parseBranch(c: Cursor, depth: number): Elem {
  if (depth > 32) fail(c, 'branches nest more than 32 deep');
  const start = c.pos();
  c.next(); // [
  const legs: Elem[][] = [];
  for (;;) {
    const legStart = c.pos();
    const leg = parseSeries(c, depth);
    if (leg.length === 0) throw new Fail({ message: 'an empty branch leg', ...legStart });
    legs.push(leg);
    const ch = c.peek();
    if (ch === ',') {
      c.next();
      continue;
    }
    if (ch === ']') {
      c.next();
      return { kind: 'branch', legs, line: start.line, col: start.col, end: c.pos() };
    }
    fail(c, 'the `[` of this branch is not closed');
  }
}

function parseInstr(c: Cursor): Elem {
  const start = c.pos();
  let name = '';
  while (/[A-Za-z0-9_]/.test(c.peek())) name += c.next();
  if (name === '' || !/^[A-Za-z_]/.test(name)) fail(c, `unexpected \`${c.peek()}\``);
  skipSpaces(c);
  if (c.peek() !== '(') fail(c, `\`(\` expected after \`${name}\``);
  c.next();
  const operands: string[] = [];
  let cur = '';
  let depth = 0;
  for (;;) {
    const ch = c.peek();
    if (ch === '') throw new Fail({ message: `the \`(\` of \`${name.toUpperCase()}\` is not closed`, ...start });
    if (ch === ';') fail(c, `the \`(\` of \`${name.toUpperCase()}\` is not closed`);
    if (ch === '/' && c.peek(1) === '/') fail(c, 'a comment inside an instruction');
    if (ch === ']' && depth === 0) fail(c, `\`]\` inside the operands of \`${name.toUpperCase()}\``);
    c.next();
    if (depth === 0 && ch === ')') {
      operands.push(cur);
      break;
    }
    if (depth === 0 && ch === ',') {
      operands.push(cur);
      cur = '';
      continue;
    }
    if (ch === '(' || ch === '[') depth++;
    else if (ch === ')' || ch === ']') depth = Math.max(0, depth - 1);
    cur += ch;
  }
  const ops = operands.map((o) => o.replace(/\s+/g, ' ').trim());
  return {
    kind: 'instr',
    mnemonic: name.toUpperCase(),
    operands: ops.length === 1 && ops[0] === '' ? [] : ops,
    line: start.line,
    col: start.col,
    end: c.pos(),
  };
}

/** Parses one rung body (the text before its `;`, positions from `at`). */
export function parseBody(body: string, at: Pos = { line: 1, col: 1 }): { elements: Elem[] | null; error: ParseError | null } {
  const c = new Cursor(Array.from(body));
  c.line = at.line;
  c.col = at.col;
  try {
    const els = parseSeries(c, 0);
    skipSpaces(c);
    if (!c.done) fail(c, c.peek() === ']' ? 'a `]` without its `[`' : c.peek() === ',' ? 'a `,` outside a branch' : `unexpected \`${c.peek()}\``);
    return { elements: els, error: null };
  } catch (e) {
    if (e instanceof Fail) return { elements: null, error: e.at };
    throw e;
  }
}

/** Splits a program into rungs (each with its comment and its exact text) and parses each. */
export function parseProgram(text: string): ProgramDoc {
  const c = new Cursor(Array.from(text));
  const rungs: RungSource[] = [];
  let chunkStart = 0;
  for (;;) {
    // Leading blank lines.
    const leadStart = c.i;
    let lineStart = c.save();
    for (;;) {
      const s = c.save();
      while (c.peek() === ' ' || c.peek() === '\t' || c.peek() === '\r' || c.peek() === '\uFEFF') c.next();
      if (c.peek() === '\n') {
        c.next();
        lineStart = c.save();
      } else {
        c.restore(s);
        break;
      }
    }
    c.restore(lineStart);
    const lead = c.cs.slice(leadStart, c.i).join('');
    const ownStart = c.i;
    const startLine = c.line;
    // Comment lines (and blank lines between them) before the rung.
    const comment: string[] = [];
    for (;;) {
      skipSpaces(c);
      if (c.peek() === '/' && c.peek(1) === '/') {
        c.next();
        c.next();
        let t = '';
        while (!c.done && c.peek() !== '\n') t += c.next();
        comment.push(t.replace(/\r$/, '').trim());
      } else break;
    }
    if (c.done) {
      return { rungs, tail: c.cs.slice(chunkStart).join(''), tailError: null };
    }
    // The body, up to the `;` at the end of the rung (not inside operands).
    const bodyPos = c.pos();
    const bodyStart = c.i;
    let depth = 0;
    while (!c.done) {
      const ch = c.peek();
      if (ch === '/' && c.peek(1) === '/') {
        while (!c.done && c.peek() !== '\n') c.next();
        continue;
      }
      if (ch === '(') depth++;
      else if (ch === ')') depth = Math.max(0, depth - 1);
      else if (ch === ';') break;
      c.next();
    }
    if (c.done) {
      const body = c.cs.slice(bodyStart).join('');
      return {
        rungs,
        tail: c.cs.slice(chunkStart).join(''),
        tailError: body.trim() ? { message: 'the last rung has no `;`', ...c.pos() } : null,
      };
    }
    const body = c.cs.slice(bodyStart, c.i).join('');
    c.next(); // ;
    // The rest of the line: a same-line comment joins the rung's comment.
    const s = c.save();
    while (c.peek() === ' ' || c.peek() === '\t' || c.peek() === '\r') c.next();
    if (c.peek() === '/' && c.peek(1) === '/') {
      c.next();
      c.next();
      let t = '';
      while (!c.done && c.peek() !== '\n') t += c.next();
      comment.push(t.replace(/\r$/, '').trim());
    } else if (c.peek() !== '\n' && !c.done) {
      c.restore(s); // another rung on the same line
    }
    const endLine = c.line;
    if (c.peek() === '\n') c.next();
    const { elements, error } = parseBody(body, bodyPos);
    rungs.push({
      lead,
      own: c.cs.slice(ownStart, c.i).join(''),
      comment,
      body,
      elements,
      error,
      startLine,
      endLine,
    });
    chunkStart = c.i;
  }
}

/** The program text again: every rung's lead and own text, then the tail. */
export function joinProgram(doc: { rungs: { lead: string; own: string }[]; tail: string }): string {
  return doc.rungs.map((r) => r.lead + r.own).join('') + doc.tail;
}
