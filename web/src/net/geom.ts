// The net editor's geometry, pure: where each node is (its <position>, or a
// layered layout for nodes that have none — files written by hand or by
// tools without graphics — which is not saved until the node is moved), node
// boxes, and arc routes: a straight line when it crosses no other node, else
// the cheapest of a few orthogonal detours that cross none, clipped to the
// node outlines; a place and a transition joined both ways get two parallel
// lines instead of one on top of the other.
import { position } from './edit';
import type { Net } from './pnml';

export const PLACE_R = 20;
export const TRANS_W = 12;
export const TRANS_H = 40;

export interface Pt {
  x: number;
  y: number;
}
export interface Box {
  x: number;
  y: number;
  w: number;
  h: number;
}

/** Where every node and widget is: its own position, or one of a layout by layers from the marked places. */
export function positions(net: Net): Map<string, Pt> {
  const out = new Map<string, Pt>();
  const nodes = [...net.places, ...net.transitions];
  for (const n of nodes) {
    const p = position(n.extra);
    if (p) out.set(n.id, p);
  }
  for (const w of net.widgets) if (w.x !== null && w.y !== null) out.set(w.id, { x: w.x, y: w.y });
  const missing = nodes.filter((n) => !out.has(n.id));
  if (missing.length) {
    // breadth first from the initially marked places (else the first node): column = distance
    const next = new Map<string, string[]>();
    for (const a of net.arcs) next.set(a.source, [...(next.get(a.source) ?? []), a.target]);
    const layer = new Map<string, number>();
    const starts = net.places.filter((p) => p.initial > 0).map((p) => p.id);
    const queue = starts.length ? starts : nodes.length ? [nodes[0].id] : [];
    for (const s of queue) layer.set(s, 0);
    for (let k = 0; k < queue.length || layer.size < nodes.length; k++) {
      if (k >= queue.length) {
        const n = nodes.find((x) => !layer.has(x.id))!;
        layer.set(n.id, 0);
        queue.push(n.id);
      }
      const id = queue[k];
      for (const t of next.get(id) ?? [])
        if (!layer.has(t)) {
          layer.set(t, layer.get(id)! + 1);
          queue.push(t);
        }
    }
    const below = Math.max(0, ...[...out.values()].map((p) => p.y + 80));
    const rows = new Map<number, number>();
    for (const n of missing) {
      const l = layer.get(n.id) ?? 0;
      const r = rows.get(l) ?? 0;
      rows.set(l, r + 1);
      out.set(n.id, { x: 60 + l * 90, y: below + 60 + r * 90 });
    }
  }
  let wy = Math.max(0, ...[...out.values()].map((p) => p.y)) + 80;
  for (const w of net.widgets)
    if (!out.has(w.id)) {
      out.set(w.id, { x: 40, y: wy });
      wy += 50;
    }
  return out;
}

export function placeBox(c: Pt): Box {
  return { x: c.x - PLACE_R, y: c.y - PLACE_R, w: 2 * PLACE_R, h: 2 * PLACE_R };
}
export function transitionBox(c: Pt): Box {
  return { x: c.x - TRANS_W / 2, y: c.y - TRANS_H / 2, w: TRANS_W, h: TRANS_H };
}

/** Whether segment a–b passes through box (shrunk by 1 so touching does not count). */
export function segmentHitsBox(a: Pt, b: Pt, box: Box): boolean {
  const x0 = box.x + 1;
  const y0 = box.y + 1;
  const x1 = box.x + box.w - 1;
  const y1 = box.y + box.h - 1;
  // Liang–Barsky clipping
  let t0 = 0;
  let t1 = 1;
  const dx = b.x - a.x;
  const dy = b.y - a.y;
  for (const [p, q] of [[-dx, a.x - x0], [dx, x1 - a.x], [-dy, a.y - y0], [dy, y1 - a.y]] as const) {
    if (p === 0) {
      if (q < 0) return false;
    } else {
      const r = q / p;
      if (p < 0) t0 = Math.max(t0, r);
      else t1 = Math.min(t1, r);
      if (t0 > t1) return false;
    }
  }
  return true;
}

/** The point where the ray from the centre `c` towards `to` leaves the node's outline. */
export function clip(c: Pt, to: Pt, kind: 'place' | 'transition'): Pt {
  const dx = to.x - c.x;
  const dy = to.y - c.y;
  const len = Math.hypot(dx, dy) || 1;
  if (kind === 'place') return { x: c.x + (dx / len) * PLACE_R, y: c.y + (dy / len) * PLACE_R };
  const sx = dx === 0 ? Infinity : TRANS_W / 2 / Math.abs(dx);
  const sy = dy === 0 ? Infinity : TRANS_H / 2 / Math.abs(dy);
  const s = Math.min(sx, sy);
  return { x: c.x + dx * s, y: c.y + dy * s };
}

const length = (pts: Pt[]) => pts.slice(1).reduce((sum, p, k) => sum + Math.abs(p.x - pts[k].x) + Math.abs(p.y - pts[k].y), 0);

/**
 * The route of an arc between two node centres: the polyline's points, first
 * and last on the node outlines. `obstacles` are the boxes of the other
 * nodes; `offset` shifts a straight line sideways (two arcs between the same
 * nodes, one each way).
 */
export function route(from: Pt, fromKind: 'place' | 'transition', to: Pt, toKind: 'place' | 'transition', obstacles: Box[], offset = 0): Pt[] {
  const hits = (pts: Pt[]) => pts.slice(1).some((p, k) => obstacles.some((b) => segmentHitsBox(pts[k], p, b)));
  const dx = to.x - from.x;
  const dy = to.y - from.y;
  const len = Math.hypot(dx, dy) || 1;
  const n = { x: (-dy / len) * offset, y: (dx / len) * offset };
  const straight = [{ x: from.x + n.x, y: from.y + n.y }, { x: to.x + n.x, y: to.y + n.y }];
  if (!hits(straight) || offset !== 0) return ends(straight, from, fromKind, to, toKind);
  // orthogonal detours: an L either way, then Z shapes through lanes beside the obstacles
  const candidates: Pt[][] = [
    [from, { x: to.x, y: from.y }, to],
    [from, { x: from.x, y: to.y }, to],
  ];
  const xs = new Set<number>([(from.x + to.x) / 2]);
  const ys = new Set<number>([(from.y + to.y) / 2]);
  // lanes beside the nodes in the way (not every node: a big net stays quick to draw)
  const blocking = obstacles.filter((b) => segmentHitsBox(from, to, b) || segmentHitsBox(from, { x: to.x, y: from.y }, b) || segmentHitsBox({ x: to.x, y: from.y }, to, b));
  for (const b of blocking) {
    xs.add(b.x - 15);
    xs.add(b.x + b.w + 15);
    ys.add(b.y - 15);
    ys.add(b.y + b.h + 15);
  }
  for (const x of xs) candidates.push([from, { x, y: from.y }, { x, y: to.y }, to]);
  for (const y of ys) candidates.push([from, { x: from.x, y }, { x: to.x, y }, to]);
  const ok = candidates.filter((c) => !hits(trimmed(c, fromKind, toKind))).sort((a, b) => length(a) - length(b));
  return ends(ok[0] ?? straight, from, fromKind, to, toKind);
}

/** The polyline with its first and last points moved onto the node outlines. */
function ends(pts: Pt[], from: Pt, fromKind: 'place' | 'transition', to: Pt, toKind: 'place' | 'transition'): Pt[] {
  const out = pts.map((p) => ({ ...p }));
  const a = clip(from, out[1], fromKind);
  const b = clip(to, out[out.length - 2], toKind);
  // a shifted straight line keeps its offset: clip from the shifted point
  if (out.length === 2 && (pts[0].x !== from.x || pts[0].y !== from.y)) {
    const d = { x: pts[0].x - from.x, y: pts[0].y - from.y };
    return [clip({ x: from.x + d.x, y: from.y + d.y }, out[1], fromKind), clip({ x: to.x + d.x, y: to.y + d.y }, out[0], toKind)];
  }
  out[0] = a;
  out[out.length - 1] = b;
  return out;
}

/** For the obstacle test: a route without its ends inside its own nodes. */
function trimmed(pts: Pt[], fromKind: 'place' | 'transition', toKind: 'place' | 'transition'): Pt[] {
  const out = pts.map((p) => ({ ...p }));
  out[0] = clip(pts[0], pts[1], fromKind);
  out[out.length - 1] = clip(pts[pts.length - 1], pts[pts.length - 2], toKind);
  return out;
}

/** The routes of every arc of the net, by arc id; without `detours` straight lines (while dragging). */
export function routes(net: Net, at: Map<string, Pt>, detours = true): Map<string, Pt[]> {
  const kind = new Map<string, 'place' | 'transition'>([
    ...net.places.map((p) => [p.id, 'place'] as const),
    ...net.transitions.map((t) => [t.id, 'transition'] as const),
  ]);
  const box = (id: string) => (kind.get(id) === 'place' ? placeBox(at.get(id)!) : transitionBox(at.get(id)!));
  const pairs = new Set(net.arcs.map((a) => `${a.source}\u0000${a.target}`));
  const out = new Map<string, Pt[]>();
  for (const a of net.arcs) {
    const f = at.get(a.source);
    const t = at.get(a.target);
    if (!f || !t || !kind.has(a.source) || !kind.has(a.target)) continue;
    const others = detours ? [...kind.keys()].filter((id) => id !== a.source && id !== a.target && at.has(id)).map(box) : [];
    const back = pairs.has(`${a.target}\u0000${a.source}`);
    out.set(a.id, route(f, kind.get(a.source)!, t, kind.get(a.target)!, others, back ? 6 : 0));
  }
  return out;
}

/** Whether two boxes overlap. */
export function overlaps(a: Box, b: Box): boolean {
  return a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h;
}

/** The text sizes of the drawing (style.css): the width of one character and the height of a line, in net units. */
export const TEXT = { label: { char: 7, size: 12 }, mono: { char: 6.1, size: 10 } };

/** The box of a text of `chars` characters whose left end is at `x` on the baseline `y`. */
export function textBox(x: number, y: number, chars: number, font: { char: number; size: number }): Box {
  return { x, y: y - font.size * 0.8, w: chars * font.char, h: font.size };
}

/**
 * A guard (or a delay) as shown beside its transition (issue 30, item 23): at
 * most `max` characters, and fewer when it would run into one of `obstacles`
 * (the nodes, their names and the guards shown before it), cut with "…" (at
 * least 4 characters are kept); the whole text stays in the tooltip.
 */
export function fitGuard(guard: string, x: number, y: number, obstacles: Box[], max = 16): string {
  const cut = (n: number) => (n >= guard.length ? guard : `${guard.slice(0, n - 1)}…`);
  for (let n = Math.min(guard.length, max); n > 4; n--) {
    const text = cut(n);
    const box = textBox(x, y, text.length, TEXT.mono);
    if (!obstacles.some((o) => overlaps({ ...box, w: box.w + 4 }, o))) return text;
  }
  return cut(Math.min(guard.length, 4));
}
