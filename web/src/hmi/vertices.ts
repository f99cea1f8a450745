// The vertices of a polygon or a polyline (`line`) in the designer (issue 35,
// point 1), as pure functions on the element's JSON so they are tested
// without a browser: the element's points (`props.points`, in its box, or the
// shape drawn without them), moving, inserting and removing a vertex within
// the limits the server checks (a polygon keeps 3, a line 2, at most 200),
// the edge nearest a point, and an element made of points drawn on the screen.
import type { Element } from './render';

export type Pt = [number, number];

/** The most vertices a polygon or a line may have (the server's `Points { max: 200 }`). */
export const MAX_POINTS = 200;

/** Whether `type` is drawn through vertices the designer edits. */
export const hasVertices = (type: string): boolean => type === 'polygon' || type === 'line';

/** The fewest vertices an element of `type` keeps. */
export const minPoints = (type: string): number => (type === 'polygon' ? 3 : 2);

/** The element's vertices in its box: `props.points` when valid, else the shape it is drawn as without them. */
export function pointsOf(e: Element): Pt[] {
  const v = e.props?.points;
  if (Array.isArray(v) && v.length >= 2 && v.every((xy) => Array.isArray(xy) && xy.length === 2 && xy.every((c) => typeof c === 'number')))
    return (v as Pt[]).map(([x, y]) => [x, y]);
  return e.type === 'polygon' ? [[e.w / 2, 0], [e.w, e.h], [0, e.h]] : [[0, e.h / 2], [e.w, e.h / 2]];
}

/** The edges of a list of points: the segment from each to the next (and back to the first when `closed`). */
export function edges(pts: Pt[], closed: boolean): [Pt, Pt][] {
  const out: [Pt, Pt][] = [];
  for (let k = 0; k + 1 < pts.length; k++) out.push([pts[k], pts[k + 1]]);
  if (closed && pts.length > 2) out.push([pts[pts.length - 1], pts[0]]);
  return out;
}

/** The distance from `p` to the segment a–b. */
export function distToSegment(p: Pt, a: Pt, b: Pt): number {
  const [dx, dy] = [b[0] - a[0], b[1] - a[1]];
  const len2 = dx * dx + dy * dy;
  const t = len2 === 0 ? 0 : Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2));
  return Math.hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
}

/** The index of the edge nearest `p` (edge k runs from vertex k to the next). */
export function nearestEdge(pts: Pt[], p: Pt, closed: boolean): number {
  let best = 0;
  let d = Infinity;
  edges(pts, closed).forEach(([a, b], k) => {
    const dk = distToSegment(p, a, b);
    if (dk < d) [best, d] = [k, dk];
  });
  return best;
}

/** `pts` with a vertex at `p` inserted after vertex `k` (on edge k); null at the limit. */
export function insertVertex(pts: Pt[], k: number, p: Pt): Pt[] | null {
  if (pts.length >= MAX_POINTS || k < 0 || k >= pts.length) return null;
  return [...pts.slice(0, k + 1), p, ...pts.slice(k + 1)];
}

/** `pts` without vertex `k`; null when the element would have too few. */
export function removeVertex(pts: Pt[], k: number, type: string): Pt[] | null {
  if (pts.length <= minPoints(type) || k < 0 || k >= pts.length) return null;
  return pts.filter((_, i) => i !== k);
}

const round = (v: number) => Math.round(v * 100) / 100;

/**
 * Sets the element's vertices `pts` (in its box as it is now) and fits its
 * box to them, so a vertex dragged outside grows the box and the points stay
 * in it. A rotated element keeps its box (its turn is about the box's centre)
 * and its vertices are held inside it.
 */
export function setPoints(e: Element, pts: Pt[]): void {
  if (e.rotation) {
    const held = pts.map(([x, y]): Pt => [round(Math.max(0, Math.min(e.w, x))), round(Math.max(0, Math.min(e.h, y)))]);
    e.props = { ...e.props, points: held };
    return;
  }
  const xs = pts.map((p) => p[0]);
  const ys = pts.map((p) => p[1]);
  const [x0, y0] = [Math.min(...xs), Math.min(...ys)];
  e.x = round(e.x + x0);
  e.y = round(e.y + y0);
  e.w = Math.max(1, round(Math.max(...xs) - x0));
  e.h = Math.max(1, round(Math.max(...ys) - y0));
  e.props = { ...e.props, points: pts.map(([x, y]): Pt => [round(x - x0), round(y - y0)]) };
}

/** Consecutive repeats dropped (a double-click's clicks land on the same snapped point), and the closing repeat of a polygon. */
export function dedupe(pts: Pt[], closed: boolean): Pt[] {
  const out = pts.filter((p, k) => k === 0 || p[0] !== pts[k - 1][0] || p[1] !== pts[k - 1][1]);
  while (closed && out.length > 1 && out[0][0] === out[out.length - 1][0] && out[0][1] === out[out.length - 1][1]) out.pop();
  return out;
}

/** An element of `type` (polygon or line) with the id `id` through the screen points `pts`; null when too few or too many. */
export function fromPoints(id: string, type: string, pts: Pt[]): Element | null {
  const ps = dedupe(pts, type === 'polygon');
  if (ps.length < minPoints(type) || ps.length > MAX_POINTS) return null;
  const e: Element = { id, type, x: 0, y: 0, w: 1, h: 1, props: {}, animations: [] };
  setPoints(e, ps);
  return e;
}
