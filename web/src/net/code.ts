// Syntax highlighting of guards and Expression scripts (Alba's expression
// language, docs/nets.md "Guards" and "Scripts"), pure: the text cut into
// classed pieces, names known as tags told from names that are not.

export type TokenKind = 'keyword' | 'function' | 'number' | 'tag' | 'name' | 'op' | 'comment' | 'string' | 'space';

export interface Token {
  kind: TokenKind;
  text: string;
}

const KEYWORDS = new Set(['AND', 'OR', 'NOT', 'XOR', 'MOD', 'TRUE', 'FALSE', 'DEFINE', 'CONSTANT', 'CONST', 'FUNCTION']);

// The functions of a net's expressions (docs/nets.md "Expressions in nets":
// the state-net source's and CPT's), shown as such when a `(` follows.
const FUNCTIONS = new Set(
  (
    'COS COSH ARCOS ARCCOS ACOS SIN SINH ARCSIN ASIN TAN TANH ARCTAN ATAN SQRT REM ROOT POW EXP ABS LOG LN ROUND ' +
    'TRUNCATE FLOOR CEILING CEIL SIGN SQR ASN ACS ATN ATAN2 DEG RAD TRN LOG10 LOGE INT SIGNUM RND RADIANS DEGREES'
  ).split(' '),
);

/** Cuts `text` into tokens; `isTag(name)` says whether a name is a tag, member or marking of the project. */
export function highlight(text: string, isTag: (name: string) => boolean): Token[] {
  const out: Token[] = [];
  const re = /(\/\/[^\n]*|\(\*[\s\S]*?\*\))|(\s+)|(T#[\w.]+|\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)|([A-Za-z_][\w]*(?:\.[A-Za-z_][\w]*)*|S:[A-Za-z]+)|(\*\*|<=|>=|<>|==|[-+*/=<>(){};,])|("[^"]*"|'[^']*')|(.)/g;
  for (const m of text.matchAll(re)) {
    const [all, comment, space, number, name, op, str] = m;
    let kind: TokenKind = 'op';
    if (comment) kind = 'comment';
    else if (space) kind = 'space';
    else if (number) kind = 'number';
    else if (name) {
      const upper = name.toUpperCase();
      const call = /^\s*\(/.test(text.slice((m.index ?? 0) + all.length));
      kind = KEYWORDS.has(upper) ? 'keyword' : call && FUNCTIONS.has(upper) ? 'function' : isTag(name) ? 'tag' : 'name';
    }
    else if (op) kind = 'op';
    else if (str) kind = 'string';
    const last = out[out.length - 1];
    if (last && last.kind === kind && (kind === 'space' || kind === 'op')) last.text += all;
    else out.push({ kind, text: all });
  }
  return out;
}
