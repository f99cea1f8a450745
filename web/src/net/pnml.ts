// The net model of the studio's net editor and its PNML form: the subset the
// server reads (docs/nets.md, "The PNML mapping"; crates/net/src/pnml.rs),
// written back as the server writes it (`alba_net::save`), so that a net
// saved from the studio is the file the server would save. What it does not
// understand is kept verbatim and written back: other tools' <toolspecific>
// blocks, <graphics> (a moved node gets its <position> replaced inside them),
// label graphics. Values the server would refuse (an unknown kind, an entry
// of Alba's block it does not know) are kept as written too, so that the
// server's check reports them rather than the editor dropping them.
import { type XElem, XmlError, attr, child, parseXml } from './xml';

export type Mode = 'petri' | 'normal';
export type ArcKind = 'normal' | 'inhibitor' | 'read';

export const PLACE_KINDS = ['state', 'counter', 'expression', 'variable', 'input', 'output', 'stop', 'end'] as const;
export const TRANSITION_KINDS = ['transition', 'condition', 'timer'] as const;
export const WIDGET_KINDS = ['button', 'display', 'plot', 'label'] as const;
export const ARC_KINDS: ArcKind[] = ['normal', 'inhibitor', 'read'];
export const PTNET_TYPE = 'http://www.pnml.org/version-2009/grammar/ptnet';

export interface Graphics {
  /** The parsed `<position x y>`, null when there is none. */
  x: number | null;
  y: number | null;
  /** The element as read (written back unchanged), null for one the editor wrote. */
  raw: string | null;
}

export interface Extra {
  graphics: Graphics | null;
  /** Other tools' blocks (and Alba's of another version), verbatim, in order. */
  toolspecific: string[];
  /** The `<graphics>` of the name / initialMarking / inscription labels, verbatim. */
  labelGraphics: Record<string, string>;
}

export interface Place {
  id: string;
  name: string | null;
  initial: number;
  tag: string | null;
  /** `state` unless said (kept as written when unknown). */
  kind: string;
  props: Record<string, string>;
  script: string | null;
  /** Entries of Alba's block the editor does not know, verbatim (the server reports them). */
  albaExtra: string[];
  extra: Extra;
}

export interface Transition {
  id: string;
  name: string | null;
  guard: string | null;
  priority: number | null;
  kind: string;
  props: Record<string, string>;
  albaExtra: string[];
  extra: Extra;
}

export interface Arc {
  id: string;
  source: string;
  target: string;
  weight: number;
  kind: string;
  albaExtra: string[];
  extra: Extra;
}

export interface Widget {
  id: string;
  kind: string;
  tag: string | null;
  text: string | null;
  x: number | null;
  y: number | null;
  /** The source's properties of the element (Display's `mode`, `format`, `unit`; Plot's
   * `autoscale`, `title`, `min`, `max`, `unit`; Label's colours, border, font, alignment;
   * Button's `latch`), as attributes of `<widget>`, by name (net/widgets.ts reads them). */
  style: Record<string, string>;
}

export interface Net {
  id: string;
  name: string | null;
  netType: string;
  mode: string;
  places: Place[];
  transitions: Transition[];
  arcs: Arc[];
  widgets: Widget[];
  pageId: string;
  pageName: string | null;
  pageExtra: Extra;
  extra: Extra;
  albaExtra: string[];
  namespaces: [string, string][];
}

/** Where each element is in the text it was read from (UTF-16 offsets). */
export interface Span {
  start: number;
  end: number;
  /** The guard's or script's text, when it has one. */
  text?: [number, number];
}

export interface Loaded {
  /** The net, or null when the text is not PNML the editor can show. */
  net: Net | null;
  /** Why not (with the offset of the problem). */
  error: { message: string; offset: number } | null;
  /** Element id → where it is. */
  spans: Map<string, Span>;
}

export const noExtra = (): Extra => ({ graphics: null, toolspecific: [], labelGraphics: {} });

export function emptyNet(id: string, mode: Mode = 'normal'): Net {
  return {
    id, name: null, netType: PTNET_TYPE, mode, places: [], transitions: [], arcs: [], widgets: [],
    pageId: 'page0', pageName: null, pageExtra: noExtra(), extra: noExtra(), albaExtra: [], namespaces: [],
  };
}

const isAlba = (e: XElem) => attr(e, 'tool') === 'alba' && (attr(e, 'version') ?? '1').trim() === '1';

/** Parses a PNML document into the editor's model. */
export function loadPnml(text: string): Loaded {
  const spans = new Map<string, Span>();
  let root: XElem;
  try {
    root = parseXml(text);
  } catch (e) {
    if (e instanceof XmlError) return { net: null, error: { message: `not well-formed XML: ${e.message}`, offset: e.offset }, spans };
    throw e;
  }
  const fail = (message: string, e: XElem): Loaded => ({ net: null, error: { message, offset: e.start }, spans });
  if (root.name !== 'pnml') return fail(`the root element is <${root.name}>, not <pnml>`, root);
  const nets = root.children.filter((c) => c.name === 'net');
  if (nets.length !== 1) return fail(nets.length ? 'a second <net>: Alba reads one net per file' : 'the document has no <net>', nets[1] ?? root);
  const ne = nets[0];
  const net = emptyNet(attr(ne, 'id') ?? '', 'petri');
  net.netType = attr(ne, 'type') ?? '';
  for (const e of [root, ne]) for (const [k, v] of e.attrs) if (k.startsWith('xmlns:') && !net.namespaces.some(([n]) => n === k)) net.namespaces.push([k, v]);
  const raw = (e: XElem) => text.slice(e.start, e.end);
  const labelText = (l: XElem): string | null => {
    const t = child(l, 'text') ?? child(l, 'value');
    if (!t) return null;
    return t.name === 'value' ? (t.text.split(',').pop() ?? '') : t.text;
  };
  const int = (s: string | null, dflt: number): number => {
    if (s === null) return dflt;
    const n = Number(s.trim());
    return s.trim() !== '' && Number.isInteger(n) ? n : dflt;
  };
  const keepLabel = (l: XElem, extra: Extra) => {
    const g = child(l, 'graphics');
    if (g) extra.labelGraphics[l.name] = raw(g);
  };
  const graphics = (g: XElem): Graphics => {
    const p = child(g, 'position');
    const x = p ? Number(attr(p, 'x')?.trim() ?? 'x') : NaN;
    const y = p ? Number(attr(p, 'y')?.trim() ?? 'y') : NaN;
    const ok = Number.isFinite(x) && Number.isFinite(y);
    return { x: ok ? x : null, y: ok ? y : null, raw: raw(g) };
  };
  /** The common children of a node; returns its Alba block. */
  const common = (e: XElem, extra: Extra, label: (l: XElem) => boolean): XElem | null => {
    let alba: XElem | null = null;
    for (const c of e.children) {
      if (c.name === 'graphics') extra.graphics = graphics(c);
      else if (c.name === 'toolspecific') {
        if (isAlba(c) && !alba) alba = c;
        else extra.toolspecific.push(raw(c));
      } else label(c);
    }
    return alba;
  };
  const props = (c: XElem, into: Record<string, string>) => {
    const n = attr(c, 'name');
    if (n !== null && n.trim() !== '' && !(n in into)) into[n] = c.text;
    else return false;
    return true;
  };
  const refs = new Map<string, string>();
  const place = (e: XElem) => {
    const p: Place = { id: attr(e, 'id') ?? '', name: null, initial: 0, tag: null, kind: 'state', props: {}, script: null, albaExtra: [], extra: noExtra() };
    const span: Span = { start: e.start, end: e.end };
    const alba = common(e, p.extra, (c) => {
      if (c.name === 'name') {
        p.name = labelText(c);
        keepLabel(c, p.extra);
      } else if (c.name === 'initialMarking') {
        p.initial = int(labelText(c), 0);
        keepLabel(c, p.extra);
      }
      return true;
    });
    for (const c of alba?.children ?? []) {
      if (c.name === 'tag' && c.text.trim() !== '' && p.tag === null) p.tag = c.text.trim();
      else if (c.name === 'kind' && p.kind === 'state') p.kind = normKind(c.text, PLACE_KINDS);
      else if (c.name === 'script' && p.script === null) {
        p.script = c.text;
        if (c.textRange) span.text = c.textRange;
      } else if (!(c.name === 'prop' && props(c, p.props))) p.albaExtra.push(raw(c));
    }
    net.places.push(p);
    spans.set(p.id, span);
  };
  const transition = (e: XElem) => {
    const t: Transition = { id: attr(e, 'id') ?? '', name: null, guard: null, priority: null, kind: 'transition', props: {}, albaExtra: [], extra: noExtra() };
    const span: Span = { start: e.start, end: e.end };
    const alba = common(e, t.extra, (c) => {
      if (c.name === 'name') {
        t.name = labelText(c);
        keepLabel(c, t.extra);
      }
      return true;
    });
    for (const c of alba?.children ?? []) {
      if (c.name === 'guard' && t.guard === null && c.text.trim() !== '') {
        t.guard = c.text;
        if (c.textRange) span.text = c.textRange;
      } else if (c.name === 'priority' && t.priority === null && /^\s*[-+]?\d+\s*$/.test(c.text)) t.priority = Number(c.text.trim());
      else if (c.name === 'kind' && t.kind === 'transition') t.kind = normKind(c.text, TRANSITION_KINDS);
      else if (!(c.name === 'prop' && props(c, t.props))) t.albaExtra.push(raw(c));
    }
    net.transitions.push(t);
    spans.set(t.id, span);
  };
  const arc = (e: XElem) => {
    const a: Arc = { id: attr(e, 'id') ?? '', source: attr(e, 'source') ?? '', target: attr(e, 'target') ?? '', weight: 1, kind: 'normal', albaExtra: [], extra: noExtra() };
    const alba = common(e, a.extra, (c) => {
      if (c.name === 'inscription') {
        a.weight = int(labelText(c), 1);
        keepLabel(c, a.extra);
      } else if (c.name === 'type' && attr(c, 'value') !== null) a.kind = kindOfArc(attr(c, 'value')!);
      return true;
    });
    for (const c of alba?.children ?? []) {
      if (c.name === 'kind') a.kind = kindOfArc(c.text);
      else a.albaExtra.push(raw(c));
    }
    net.arcs.push(a);
    spans.set(a.id, { start: e.start, end: e.end });
  };
  const node = (c: XElem) => {
    if (c.name === 'place') place(c);
    else if (c.name === 'transition') transition(c);
    else if (c.name === 'arc') arc(c);
    else if (c.name === 'referencePlace' || c.name === 'referenceTransition') {
      const id = attr(c, 'id');
      const ref = attr(c, 'ref');
      if (id && ref) refs.set(id, ref);
    }
  };
  let firstPage = true;
  const page = (e: XElem) => {
    const first = firstPage;
    firstPage = false;
    if (first) net.pageId = attr(e, 'id') ?? '';
    for (const c of e.children) {
      if (c.name === 'page') page(c);
      else if (['place', 'transition', 'arc', 'referencePlace', 'referenceTransition'].includes(c.name)) node(c);
      else if (!first) continue;
      else if (c.name === 'name') {
        net.pageName = labelText(c);
        keepLabel(c, net.pageExtra);
      } else if (c.name === 'graphics') net.pageExtra.graphics = graphics(c);
      else if (c.name === 'toolspecific') net.pageExtra.toolspecific.push(raw(c));
    }
  };
  const alba = common(ne, net.extra, (c) => {
    if (c.name === 'name') {
      net.name = labelText(c);
      keepLabel(c, net.extra);
    } else if (c.name === 'page') page(c);
    else node(c);
    return true;
  });
  for (const c of alba?.children ?? []) {
    if (c.name === 'mode') net.mode = c.text.trim();
    else if (c.name === 'widget') {
      const x = attr(c, 'x');
      const y = attr(c, 'y');
      const style: Record<string, string> = {};
      for (const [k, v] of c.attrs) if (!['id', 'kind', 'tag', 'x', 'y'].includes(k)) style[k] = v;
      net.widgets.push({
        id: attr(c, 'id') ?? '', kind: attr(c, 'kind') ?? '', tag: attr(c, 'tag'), text: c.text === '' ? null : c.text,
        x: x === null ? null : Number(x), y: y === null ? null : Number(y), style,
      });
    } else net.albaExtra.push(raw(c));
  }
  // reference nodes stand for the node they name (chains followed)
  const resolve = (id: string) => {
    const seen = new Set<string>();
    while (refs.has(id) && !seen.has(id)) {
      seen.add(id);
      id = refs.get(id)!;
    }
    return id;
  };
  for (const a of net.arcs) {
    a.source = resolve(a.source);
    a.target = resolve(a.target);
  }
  return { net, error: null, spans };
}

/** A kind as the server writes it: lower case when it is one it knows, else as written. */
function normKind(s: string, known: readonly string[]): string {
  const t = s.trim();
  return known.includes(t.toLowerCase()) ? t.toLowerCase() : t;
}

function kindOfArc(s: string): string {
  const t = s.trim();
  return t === 'test' ? 'read' : t;
}

// ---- writing -------------------------------------------------------------

/** Escapes text as the server does (`\r` as a reference, so it survives line-end normalisation). */
export function esc(s: string): string {
  return s.replace(/[&<>"'\r]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&apos;', '\r': '&#13;' })[c]!);
}

const escAttr = (s: string) => esc(s).replace(/\t/g, '&#9;').replace(/\n/g, '&#10;');

/** A number as Rust's `{}` writes an f64 (`135`, `2.5`). */
const num = (v: number) => String(v);

class W {
  out = '';
  line(depth: number, s: string): void {
    this.out += `${'  '.repeat(depth)}${s}\n`;
  }
  close(depth: number, name: string, mark: number): void {
    if (this.out.length === mark && this.out.endsWith('>\n')) this.out = `${this.out.slice(0, mark - 2)}/>\n`;
    else this.line(depth, `</${name}>`);
  }
  label(depth: number, name: string, text: string, extra: Extra): void {
    const g = extra.labelGraphics[name];
    if (g !== undefined) {
      this.line(depth, `<${name}>`);
      this.line(depth + 1, `<text>${esc(text)}</text>`);
      this.line(depth + 1, g);
      this.line(depth, `</${name}>`);
    } else this.line(depth, `<${name}><text>${esc(text)}</text></${name}>`);
  }
  extra(depth: number, extra: Extra): void {
    const g = extra.graphics;
    if (g) {
      if (g.raw !== null) this.line(depth, g.raw);
      else if (g.x !== null && g.y !== null) this.line(depth, `<graphics><position x="${num(g.x)}" y="${num(g.y)}"/></graphics>`);
    }
    for (const t of extra.toolspecific) this.line(depth, t);
  }
  alba(depth: number, body: string[]): void {
    if (!body.length) return;
    this.line(depth, '<toolspecific tool="alba" version="1">');
    for (const b of body) this.line(depth + 1, b);
    this.line(depth, '</toolspecific>');
  }
}

function propLines(props: Record<string, string>): string[] {
  // the server keeps them in a BTreeMap: sorted by name (byte order)
  return Object.keys(props)
    .sort((a, b) => (a < b ? -1 : a > b ? 1 : 0))
    .map((k) => `<prop name="${escAttr(k)}">${esc(props[k])}</prop>`);
}

/** Writes the net as PNML, as `alba_net::save` does. */
export function savePnml(net: Net): string {
  const w = new W();
  w.line(0, '<?xml version="1.0" encoding="UTF-8"?>');
  const ns = net.namespaces.filter(([k]) => k.length > 'xmlns:'.length).map(([k, v]) => ` ${escAttr(k)}="${escAttr(v)}"`).join('');
  w.line(0, `<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml"${ns}>`);
  w.line(1, `<net id="${escAttr(net.id)}" type="${escAttr(net.netType)}">`);
  if (net.name !== null) w.label(2, 'name', net.name, net.extra);
  w.extra(2, net.extra);
  const body: string[] = [];
  if (net.mode !== 'petri') body.push(`<mode>${esc(net.mode)}</mode>`);
  for (const x of net.widgets) {
    let s = `<widget id="${escAttr(x.id)}" kind="${escAttr(x.kind)}"`;
    if (x.tag !== null) s += ` tag="${escAttr(x.tag)}"`;
    if (x.x !== null && x.y !== null) s += ` x="${num(x.x)}" y="${num(x.y)}"`;
    for (const k of Object.keys(x.style ?? {}).sort()) s += ` ${k}="${escAttr(x.style[k])}"`;
    body.push(`${s}>${esc(x.text ?? '')}</widget>`);
  }
  w.alba(2, [...body, ...net.albaExtra]);
  w.line(2, `<page id="${escAttr(net.pageId)}">`);
  if (net.pageName !== null) w.label(3, 'name', net.pageName, net.pageExtra);
  w.extra(3, net.pageExtra);
  for (const p of net.places) {
    w.line(3, `<place id="${escAttr(p.id)}">`);
    const mark = w.out.length;
    if (p.name !== null) w.label(4, 'name', p.name, p.extra);
    if (p.initial !== 0 || 'initialMarking' in p.extra.labelGraphics) w.label(4, 'initialMarking', String(p.initial), p.extra);
    w.extra(4, p.extra);
    const b: string[] = [];
    if (p.tag !== null) b.push(`<tag>${esc(p.tag)}</tag>`);
    if (p.kind !== 'state') b.push(`<kind>${esc(p.kind)}</kind>`);
    b.push(...propLines(p.props));
    if (p.script !== null) b.push(`<script>${esc(p.script)}</script>`);
    w.alba(4, [...b, ...p.albaExtra]);
    w.close(3, 'place', mark);
  }
  for (const t of net.transitions) {
    w.line(3, `<transition id="${escAttr(t.id)}">`);
    const mark = w.out.length;
    if (t.name !== null) w.label(4, 'name', t.name, t.extra);
    w.extra(4, t.extra);
    const b: string[] = [];
    if (t.guard !== null) b.push(`<guard>${esc(t.guard)}</guard>`);
    if (t.priority !== null) b.push(`<priority>${t.priority}</priority>`);
    if (t.kind !== 'transition') b.push(`<kind>${esc(t.kind)}</kind>`);
    b.push(...propLines(t.props));
    w.alba(4, [...b, ...t.albaExtra]);
    w.close(3, 'transition', mark);
  }
  for (const a of net.arcs) {
    w.line(3, `<arc id="${escAttr(a.id)}" source="${escAttr(a.source)}" target="${escAttr(a.target)}">`);
    const mark = w.out.length;
    if (a.weight !== 1 || 'inscription' in a.extra.labelGraphics) w.label(4, 'inscription', String(a.weight), a.extra);
    w.extra(4, a.extra);
    w.alba(4, [...(a.kind !== 'normal' ? [`<kind>${esc(a.kind)}</kind>`] : []), ...a.albaExtra]);
    w.close(3, 'arc', mark);
  }
  w.line(2, '</page>');
  w.line(1, '</net>');
  w.line(0, '</pnml>');
  return w.out;
}
