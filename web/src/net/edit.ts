// The net editor's operations, as pure functions on the model (issue 20): new
// states and transitions with fresh ids, arcs (checked as the server checks
// them), moves on a grid, deletion, copy and paste. The view records each
// change for undo as the PNML text before it (ProgramEditor's stacks).
import { type Arc, type Extra, type Graphics, type Net, type Place, type Transition, noExtra } from './pnml';

export const GRID = 10;
export const snap = (v: number, grid = GRID): number => Math.round(v / grid) * grid;

export type NodeKind = 'place' | 'transition';

export function nodeKind(net: Net, id: string): NodeKind | null {
  if (net.places.some((p) => p.id === id)) return 'place';
  if (net.transitions.some((t) => t.id === id)) return 'transition';
  return null;
}

export function findNode(net: Net, id: string): Place | Transition | undefined {
  return net.places.find((p) => p.id === id) ?? net.transitions.find((t) => t.id === id);
}

/** Every id of the document (one id space: nodes, arcs, widgets, the page). */
export function usedIds(net: Net): Set<string> {
  return new Set([net.pageId, ...net.places.map((p) => p.id), ...net.transitions.map((t) => t.id), ...net.arcs.map((a) => a.id), ...net.widgets.map((w) => w.id)]);
}

/** `<base><n>` not used in `net` nor in `taken`, from `<base>1` (or `<base>0`). */
export function freshId(net: Net, base: string, taken: Set<string> = new Set(), from = 1): string {
  const used = usedIds(net);
  let n = from;
  while (used.has(`${base}${n}`) || taken.has(`${base}${n}`)) n++;
  return `${base}${n}`;
}

/** Sets a node's position, keeping the rest of its graphics (the <position> is replaced inside). */
export function setPosition(extra: Extra, x: number, y: number): void {
  const g: Graphics | null = extra.graphics;
  if (g?.raw) {
    const at = `x="${x}" y="${y}"`;
    const pos = /<((?:[\w.-]+:)?position)\b[^>]*?(\/?)>/;
    if (pos.test(g.raw)) {
      extra.graphics = { x, y, raw: g.raw.replace(pos, (_m, name: string, slash: string) => `<${name} ${at}${slash}>`) };
      return;
    }
    const open = /^<((?:[\w.-]+:)?)graphics\b[^>]*?>/.exec(g.raw);
    if (open && !open[0].endsWith('/>')) {
      extra.graphics = { x, y, raw: `${open[0]}<${open[1]}position ${at}/>${g.raw.slice(open[0].length)}` };
      return;
    }
  }
  // written as the server writes a position, so that reading it back gives the same model
  extra.graphics = { x, y, raw: `<graphics><position x="${x}" y="${y}"/></graphics>` };
}

export function position(extra: Extra): { x: number; y: number } | null {
  const g = extra.graphics;
  return g && g.x !== null && g.y !== null ? { x: g.x, y: g.y } : null;
}

/** A new place of `kind` at (x, y) snapped; its id (S1, S2 … for states, E1 … for expressions, P1 … otherwise). */
export function addPlace(net: Net, x: number, y: number, kind = 'state', grid = GRID): Place {
  const base = kind === 'state' ? (net.mode === 'normal' ? 'S' : 'P') : kind === 'expression' ? 'E' : kind.slice(0, 1).toUpperCase() + kind.slice(1);
  const p: Place = { id: freshId(net, base, new Set(), kind === 'state' && net.mode === 'normal' ? 0 : 1), name: null, initial: 0, tag: null, kind, props: {}, script: null, albaExtra: [], extra: noExtra() };
  if (kind === 'expression') p.script = '';
  setPosition(p.extra, snap(x, grid), snap(y, grid));
  net.places.push(p);
  return p;
}

/** A new transition of `kind` at (x, y) snapped (T1 …, C1 … for conditions). */
export function addTransition(net: Net, x: number, y: number, kind = 'transition', grid = GRID): Transition {
  const base = kind === 'condition' ? 'C' : kind === 'timer' ? 'Timer' : 'T';
  const t: Transition = { id: freshId(net, base), name: null, guard: null, priority: null, kind, props: {}, albaExtra: [], extra: noExtra() };
  if (kind === 'timer') t.props.delay = 'T#1s';
  setPosition(t.extra, snap(x, grid), snap(y, grid));
  net.transitions.push(t);
  return t;
}

/** Why an arc from `source` to `target` cannot be drawn, or null (the server's E604 rules). */
export function arcProblem(net: Net, source: string, target: string, kind = 'normal'): 'unknown' | 'same' | 'direction' | 'twice' | null {
  const s = nodeKind(net, source);
  const t = nodeKind(net, target);
  if (!s || !t) return 'unknown';
  if (s === t) return 'same';
  if (kind !== 'normal' && s !== 'place') return 'direction';
  if (net.arcs.some((a) => a.source === source && a.target === target)) return 'twice';
  return null;
}

/** A new arc; null when it may not be drawn (see arcProblem). */
export function connect(net: Net, source: string, target: string, weight = 1, kind = 'normal'): Arc | null {
  if (arcProblem(net, source, target, kind)) return null;
  const a: Arc = { id: freshId(net, 'a'), source, target, weight, kind, albaExtra: [], extra: noExtra() };
  net.arcs.push(a);
  return a;
}

/** Moves nodes by (dx, dy); `at` gives the current position of a node that has none yet. */
export function moveNodes(net: Net, ids: Iterable<string>, dx: number, dy: number, at: (id: string) => { x: number; y: number }): void {
  for (const id of ids) {
    const n = findNode(net, id);
    if (n) {
      const p = position(n.extra) ?? at(id);
      setPosition(n.extra, p.x + dx, p.y + dy);
      continue;
    }
    const w = net.widgets.find((x) => x.id === id);
    if (w) {
      const p = w.x !== null && w.y !== null ? { x: w.x, y: w.y } : at(id);
      w.x = p.x + dx;
      w.y = p.y + dy;
    }
  }
}

/** Removes nodes, arcs and widgets by id; the arcs of a removed node go with it. */
export function remove(net: Net, ids: Set<string>): void {
  net.places = net.places.filter((p) => !ids.has(p.id));
  net.transitions = net.transitions.filter((t) => !ids.has(t.id));
  net.widgets = net.widgets.filter((w) => !ids.has(w.id));
  net.arcs = net.arcs.filter((a) => !ids.has(a.id) && !ids.has(a.source) && !ids.has(a.target));
}

/** What Ctrl+C keeps: the selected nodes and widgets, and the arcs between selected nodes. */
export interface Clip {
  places: Place[];
  transitions: Transition[];
  arcs: Arc[];
  widgets: Net['widgets'];
}

export function copy(net: Net, ids: Set<string>): Clip {
  return structuredClone({
    places: net.places.filter((p) => ids.has(p.id)),
    transitions: net.transitions.filter((t) => ids.has(t.id)),
    arcs: net.arcs.filter((a) => ids.has(a.source) && ids.has(a.target)),
    widgets: net.widgets.filter((w) => ids.has(w.id)),
  });
}

/** Pastes a copy moved by (dx, dy) with fresh ids (same base names); the new ids. */
export function paste(net: Net, clip: Clip, dx: number, dy: number, at: (id: string) => { x: number; y: number }): string[] {
  const c = structuredClone(clip);
  const taken = new Set<string>();
  const ids = new Map<string, string>();
  const fresh = (id: string) => {
    const base = /^(.*?)(\d*)$/.exec(id)![1] || 'n';
    const n = freshId(net, base, taken);
    taken.add(n);
    ids.set(id, n);
    return n;
  };
  for (const p of c.places) {
    const q = position(p.extra) ?? at(p.id);
    p.id = fresh(p.id);
    setPosition(p.extra, q.x + dx, q.y + dy);
  }
  for (const t of c.transitions) {
    const q = position(t.extra) ?? at(t.id);
    t.id = fresh(t.id);
    setPosition(t.extra, q.x + dx, q.y + dy);
  }
  for (const w of c.widgets) {
    w.id = fresh(w.id);
    if (w.x !== null && w.y !== null) {
      w.x += dx;
      w.y += dy;
    }
  }
  for (const a of c.arcs) {
    a.id = fresh(a.id);
    a.source = ids.get(a.source)!;
    a.target = ids.get(a.target)!;
  }
  net.places.push(...c.places);
  net.transitions.push(...c.transitions);
  net.arcs.push(...c.arcs);
  net.widgets.push(...c.widgets);
  return [...c.places, ...c.transitions, ...c.widgets].map((x) => x.id);
}

/**
 * Renames a node (its arcs follow); null when done, else why not. Marking tags
 * are named after ids (`<net>.<id>`): a renamed place starts from its initial
 * marking after an online edit.
 */
export function rename(net: Net, from: string, to: string): string | null {
  if (from === to) return null;
  if (!/^[A-Za-z_][\w]*$/.test(to)) return 'ident';
  if (usedIds(net).has(to)) return 'taken';
  const n = findNode(net, from);
  if (!n) return 'unknown';
  n.id = to;
  for (const a of net.arcs) {
    if (a.source === from) a.source = to;
    if (a.target === from) a.target = to;
  }
  return null;
}
