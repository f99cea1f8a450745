// The designer's operations on a screen (issue 17, item 2), as pure functions
// on the screen's JSON so they are tested without a browser: new elements
// and copies with fresh ids, groups, alignment, distribution, layers, and the
// element a server problem is about.
import type { Element, Screen } from './render';

export const GRID = 10;
export const snap = (v: number, grid = GRID): number => Math.round(v / grid) * grid;

/** The default size of a new element of `type`. */
const SIZES: Record<string, [number, number]> = {
  tank: [120, 200], bottle: [80, 140], pipe: [100, 20], line: [100, 10], text: [160, 30], button: [120, 36], switch: [120, 36],
  slider: [160, 30], input: [100, 30], output: [100, 30], meter: [40, 160], trend: [300, 160], building: [120, 100],
  transmission_tower: [80, 160], cooling_tower: [100, 120], wind_turbine: [100, 160], plc: [120, 80], faceplate: [220, 150],
};

/** An id of the form `<base><n>` not used in `screen` (nor in `taken`). */
export function freshId(screen: Screen, base: string, taken: Set<string> = new Set()): string {
  const used = new Set([...screen.elements.map((e) => e.id), ...taken]);
  let n = 1;
  while (used.has(`${base}${n}`)) n++;
  return `${base}${n}`;
}

/** A new element of `type` centred near (x, y). */
export function newElement(screen: Screen, type: string, x: number, y: number): Element {
  const [w, h] = SIZES[type] ?? [60, 60];
  return { id: freshId(screen, type), type, x: snap(x - w / 2), y: snap(y - h / 2), w, h, props: {}, animations: [] };
}

/**
 * Copies of `els` for `screen`, moved by (dx, dy): fresh ids (the type's
 * base name), and fresh group names so a pasted group is a new group.
 */
export function copies(screen: Screen, els: Element[], dx: number, dy: number): Element[] {
  const taken = new Set<string>();
  const groups = new Map<string, string>();
  const groupNames = new Set(screen.elements.map((e) => e.group).filter(Boolean));
  return els.map((e) => {
    const c = structuredClone(e);
    c.id = freshId(screen, e.type, taken);
    taken.add(c.id);
    c.x += dx;
    c.y += dy;
    if (e.group) {
      if (!groups.has(e.group)) {
        let n = 1;
        while (groupNames.has(`g${n}`) || [...groups.values()].includes(`g${n}`)) n++;
        groups.set(e.group, `g${n}`);
      }
      c.group = groups.get(e.group);
    }
    return c;
  });
}

/** `ids` and every element sharing a group with one of them. */
export function withGroups(screen: Screen, ids: Iterable<string>): Set<string> {
  const out = new Set(ids);
  const groups = new Set(screen.elements.filter((e) => out.has(e.id) && e.group).map((e) => e.group));
  for (const e of screen.elements) if (e.group && groups.has(e.group)) out.add(e.id);
  return out;
}

/** Puts the elements `ids` in one new group; its name. */
export function group(screen: Screen, ids: Set<string>): string {
  const names = new Set(screen.elements.map((e) => e.group));
  let n = 1;
  while (names.has(`g${n}`)) n++;
  for (const e of screen.elements) if (ids.has(e.id)) e.group = `g${n}`;
  return `g${n}`;
}

/** Ungrouped, a template's instance becomes plain copies (its `template`, `prefix` and `part` go too). */
export function ungroup(screen: Screen, ids: Set<string>): void {
  for (const e of screen.elements)
    if (ids.has(e.id)) {
      delete e.group;
      unmark(e);
    }
}

/** Without the marks of a template's instance. */
function unmark(e: Element): void {
  if (e.props && typeof e.props.template === 'string') {
    const { template: _t, prefix: _p, part: _r, ...rest } = e.props;
    e.props = rest;
  }
}

export type Align = 'left' | 'center' | 'right' | 'top' | 'middle' | 'bottom';

/** Aligns `els` on the edge or centre of their common box. */
export function align(els: Element[], how: Align): void {
  if (els.length < 2) return;
  const left = Math.min(...els.map((e) => e.x));
  const right = Math.max(...els.map((e) => e.x + e.w));
  const top = Math.min(...els.map((e) => e.y));
  const bottom = Math.max(...els.map((e) => e.y + e.h));
  for (const e of els) {
    if (how === 'left') e.x = left;
    else if (how === 'right') e.x = right - e.w;
    else if (how === 'center') e.x = (left + right) / 2 - e.w / 2;
    else if (how === 'top') e.y = top;
    else if (how === 'bottom') e.y = bottom - e.h;
    else e.y = (top + bottom) / 2 - e.h / 2;
  }
}

/** Spreads `els` so the gaps between them are equal; the first and last stay. */
export function distribute(els: Element[], axis: 'h' | 'v'): void {
  if (els.length < 3) return;
  const [pos, size] = axis === 'h' ? (['x', 'w'] as const) : (['y', 'h'] as const);
  const sorted = [...els].sort((a, b) => a[pos] - b[pos]);
  const first = sorted[0];
  const last = sorted[sorted.length - 1];
  const total = sorted.reduce((sum, e) => sum + e[size], 0);
  const gap = (last[pos] + last[size] - first[pos] - total) / (sorted.length - 1);
  let at = first[pos];
  for (const e of sorted) {
    e[pos] = Math.round(at * 100) / 100;
    at += e[size] + gap;
  }
}

/** Moves the elements `ids` to the top (drawn last) or the bottom, keeping their order. */
export function restack(screen: Screen, ids: Set<string>, to: 'front' | 'back'): void {
  const moved = screen.elements.filter((e) => ids.has(e.id));
  const rest = screen.elements.filter((e) => !ids.has(e.id));
  screen.elements = to === 'front' ? [...rest, ...moved] : [...moved, ...rest];
}

/** The element a screen problem is about: the server's messages start with "`id`: ". */
export function elementOf(message: string): string | null {
  return /^`([^`]+)`:/.exec(message)?.[1] ?? null;
}

/** Whether boxes a and b overlap. */
export function overlaps(a: { x: number; y: number; w: number; h: number }, b: { x: number; y: number; w: number; h: number }): boolean {
  return a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h;
}

/** A user symbol made of `els`: a screen holding them, moved to its origin. */
export function symbolOf(els: Element[]): Screen {
  const x0 = Math.min(...els.map((e) => e.x));
  const y0 = Math.min(...els.map((e) => e.y));
  const w = Math.max(...els.map((e) => e.x + e.w)) - x0;
  const h = Math.max(...els.map((e) => e.y + e.h)) - y0;
  const elements = els.map((e) => {
    const c = structuredClone(e);
    c.x -= x0;
    c.y -= y0;
    delete c.group;
    unmark(c);
    return c;
  });
  return { schema: 1, title: '', width: Math.max(1, w), height: Math.max(1, h), elements };
}

/** The default parameters of a new animation of `kind`. */
export function animationDefaults(kind: string): Record<string, unknown> {
  switch (kind) {
    case 'blink':
      return { on_ms: 500, off_ms: 500 };
    case 'move':
      return { min: 0, max: 100, dx: 100, dy: 0 };
    case 'rotate':
      return { speed: 1 };
    case 'color':
      return { on: '#2e7d32', off: '#9ea3a8' };
    case 'fill':
      return { min: 0, max: 100, direction: 'up' };
    default:
      return {};
  }
}
