// A small XML reader for PNML files, with source offsets: the studio's net
// editor needs the exact text of what it does not understand (other tools'
// blocks, graphics) to write it back verbatim, and the offsets of the nodes
// to put the server's line:column problems on the element they concern.
// Like the server's reader (crates/net/src/xml.rs): local names (prefix
// dropped; `xmlns:*` attributes keep theirs), XML's five entities and
// character references, CDATA, comments, processing instructions and a
// DOCTYPE skipped.

export interface XElem {
  /** Local name (prefix dropped). */
  name: string;
  attrs: [string, string][];
  children: XElem[];
  /** Character data directly inside, entities resolved. */
  text: string;
  /** Offsets (UTF-16 units) of the first and last piece of character data. */
  textRange: [number, number] | null;
  /** Offset of `<`. */
  start: number;
  /** Just after the start tag's `>`. */
  startEnd: number;
  /** Just after the end tag (or the empty tag). */
  end: number;
}

export class XmlError extends Error {
  constructor(
    message: string,
    readonly offset: number,
  ) {
    super(message);
  }
}

export const attr = (e: XElem, name: string): string | null => e.attrs.find(([k]) => k === name)?.[1] ?? null;
export const child = (e: XElem, name: string): XElem | null => e.children.find((c) => c.name === name) ?? null;

const local = (n: string) => n.slice(n.lastIndexOf(':') + 1);
const ENTITIES: Record<string, string> = { amp: '&', lt: '<', gt: '>', quot: '"', apos: "'" };

function entity(text: string, at: number): [string, number] {
  const semi = text.indexOf(';', at);
  if (semi < 0 || semi - at > 12) throw new XmlError('an `&` that starts no reference (write `&amp;`)', at);
  const name = text.slice(at + 1, semi);
  if (name.startsWith('#')) {
    const code = name[1] === 'x' ? parseInt(name.slice(2), 16) : parseInt(name.slice(1), 10);
    if (!Number.isFinite(code) || code < 0 || code > 0x10ffff) throw new XmlError('a character reference that is not a character', at);
    return [String.fromCodePoint(code), semi + 1];
  }
  const v = ENTITIES[name];
  if (v === undefined) throw new XmlError(`unknown entity \`&${name};\` (only XML's five are defined)`, at);
  return [v, semi + 1];
}

/** Resolves the references of a piece of text. */
function unescape(text: string, from: number, to: number): string {
  let out = '';
  let k = from;
  while (k < to) {
    const amp = text.indexOf('&', k);
    if (amp < 0 || amp >= to) {
      out += text.slice(k, to);
      break;
    }
    out += text.slice(k, amp);
    const [v, next] = entity(text, amp);
    out += v;
    k = next;
  }
  return out;
}

const NAME = /[A-Za-z_:][-\w.:]*/y;

/** Parses a whole document into its root element; an XmlError at the first problem. */
export function parseXml(text: string): XElem {
  const stack: XElem[] = [];
  let root: XElem | null = null;
  let k = 0;
  const addText = (s: string, from: number, to: number) => {
    const top = stack[stack.length - 1];
    if (!top) {
      if (s.trim() !== '') throw new XmlError('text outside the root element', from);
      return;
    }
    top.text += s;
    top.textRange = top.textRange ? [top.textRange[0], to] : [from, to];
  };
  const skip = (close: string, what: string) => {
    const end = text.indexOf(close, k);
    if (end < 0) throw new XmlError(`${what} never ends`, k);
    k = end + close.length;
  };
  while (k < text.length) {
    const lt = text.indexOf('<', k);
    if (lt < 0) {
      addText(unescape(text, k, text.length), k, text.length);
      break;
    }
    if (lt > k) addText(unescape(text, k, lt), k, lt);
    k = lt;
    if (text.startsWith('<!--', k)) skip('-->', 'a comment');
    else if (text.startsWith('<![CDATA[', k)) {
      const end = text.indexOf(']]>', k);
      if (end < 0) throw new XmlError('a CDATA section never ends', k);
      if (!stack.length) throw new XmlError('CDATA outside the root element', k);
      addText(text.slice(k + 9, end), k, end + 3);
      k = end + 3;
    } else if (text.startsWith('<?', k)) skip('?>', 'a processing instruction');
    else if (text.startsWith('<!DOCTYPE', k)) {
      // an internal subset in brackets may hold '>'
      let depth = 0;
      let j = k;
      for (; j < text.length; j++) {
        if (text[j] === '[') depth++;
        else if (text[j] === ']') depth--;
        else if (text[j] === '>' && depth <= 0) break;
      }
      k = j + 1;
    } else if (text.startsWith('</', k)) {
      NAME.lastIndex = k + 2;
      const m = NAME.exec(text);
      const gt = text.indexOf('>', k);
      if (!m || gt < 0) throw new XmlError('a malformed end tag', k);
      const el = stack.pop();
      if (!el) throw new XmlError('an end tag without a start tag', k);
      if (local(m[0]) !== el.name || text.slice(NAME.lastIndex, gt).trim() !== '') throw new XmlError(`</${m[0]}> closes <${el.name}>`, k);
      el.end = gt + 1;
      k = gt + 1;
      const top = stack[stack.length - 1];
      if (top) top.children.push(el);
      else root = el;
    } else {
      NAME.lastIndex = k + 1;
      const m = NAME.exec(text);
      if (!m) throw new XmlError('a `<` that starts no tag (write `&lt;`)', k);
      if (root && !stack.length) throw new XmlError('a second root element: a document has one', k);
      const el: XElem = { name: local(m[0]), attrs: [], children: [], text: '', textRange: null, start: k, startEnd: 0, end: 0 };
      let j = NAME.lastIndex;
      for (;;) {
        while (/\s/.test(text[j] ?? '')) j++;
        if (j >= text.length) throw new XmlError(`<${m[0]}> is never closed`, k);
        if (text[j] === '>' || text.startsWith('/>', j)) break;
        NAME.lastIndex = j;
        const a = NAME.exec(text);
        if (!a) throw new XmlError('bad attribute', j);
        j = NAME.lastIndex;
        while (/\s/.test(text[j] ?? '')) j++;
        if (text[j] !== '=') throw new XmlError(`bad attribute: \`${a[0]}\` has no value`, j);
        j++;
        while (/\s/.test(text[j] ?? '')) j++;
        const q = text[j];
        if (q !== '"' && q !== "'") throw new XmlError('bad attribute: a value not in quotes', j);
        const close = text.indexOf(q, j + 1);
        if (close < 0) throw new XmlError('bad attribute: a value never closed', j);
        if (text.slice(j + 1, close).includes('<')) throw new XmlError('bad attribute value: `<`', j);
        const key = a[0].startsWith('xmlns') ? a[0] : local(a[0]);
        el.attrs.push([key, unescape(text, j + 1, close)]);
        j = close + 1;
      }
      const empty = text[j] === '/';
      k = j + (empty ? 2 : 1);
      el.startEnd = k;
      if (empty) {
        el.end = k;
        const top = stack[stack.length - 1];
        if (top) top.children.push(el);
        else root = el;
      } else {
        if (stack.length >= 64) throw new XmlError('elements nested deeper than 64 levels', el.start);
        stack.push(el);
      }
    }
  }
  const open = stack[stack.length - 1];
  if (open) throw new XmlError(`<${open.name}> is never closed`, open.start);
  if (!root) throw new XmlError('no root element: the file is empty', 0);
  return root;
}

/** The 1-based line and column (characters) of an offset. */
export function lineCol(text: string, offset: number): [number, number] {
  let line = 1;
  let start = 0;
  for (let k = 0; k < offset && k < text.length; k++)
    if (text[k] === '\n') {
      line++;
      start = k + 1;
    }
  return [line, [...text.slice(start, offset)].length + 1];
}

/** The offset of a 1-based line and column (characters). */
export function offsetOf(text: string, line: number, col: number): number {
  let k = 0;
  for (let l = 1; l < line; l++) {
    const nl = text.indexOf('\n', k);
    if (nl < 0) return text.length;
    k = nl + 1;
  }
  // columns count characters: step over surrogate pairs
  for (let c = 1; c < col && k < text.length && text[k] !== '\n'; c++) k += text.codePointAt(k)! > 0xffff ? 2 : 1;
  return k;
}
