// Syntax highlighting of guards and Expression scripts (Alba's expression
// language, docs/nets.md "Guards" and "Scripts"), pure: the text cut into
// classed pieces, names known as tags told from names that are not.

export type TokenKind = 'keyword' | 'number' | 'tag' | 'name' | 'op' | 'comment' | 'string' | 'space';

export interface Token {
  kind: TokenKind;
  text: string;
}

const KEYWORDS = new Set(['AND', 'OR', 'NOT', 'XOR', 'MOD', 'TRUE', 'FALSE', 'DEFINE', 'CONSTANT', 'CONST', 'FUNCTION']);

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
    else if (name) kind = KEYWORDS.has(name.toUpperCase()) ? 'keyword' : isTag(name) ? 'tag' : 'name';
    else if (op) kind = 'op';
    else if (str) kind = 'string';
    const last = out[out.length - 1];
    if (last && last.kind === kind && (kind === 'space' || kind === 'op')) last.text += all;
    else out.push({ kind, text: all });
  }
  return out;
}
