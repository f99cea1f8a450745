// Rulers and guides of the SCADA designer (issue 35, point 3): the ticks a
// ruler shows for a length, and the nudge that brings a moving selection's
// edge or centre onto a guide near it. Guides are the designer's own (kept
// per screen in the browser), not part of the screen's file.

/** Vertical guides at x (`v`) and horizontal ones at y (`h`), in screen units. */
export interface Guides {
  v: number[];
  h: number[];
}

/** A ruler's ticks along `length`: every 10 units, longer every 50, labelled every 100. */
export function ticks(length: number): { at: number; size: 'small' | 'mid' | 'big' }[] {
  const out: { at: number; size: 'small' | 'mid' | 'big' }[] = [];
  for (let at = 0; at <= length; at += 10) out.push({ at, size: at % 100 === 0 ? 'big' : at % 50 === 0 ? 'mid' : 'small' });
  return out;
}

/**
 * The shift along one axis that puts the nearest of a box's lines (`from`,
 * its centre, `to`) on a guide within `tol`; 0 when none is near.
 */
export function snapAxis(from: number, to: number, guides: number[], tol: number): number {
  let best = 0;
  let d = tol + 1e-9;
  for (const g of guides)
    for (const line of [from, (from + to) / 2, to]) {
      const dk = g - line;
      if (Math.abs(dk) < d) [best, d] = [dk, Math.abs(dk)];
    }
  return best;
}

/** The shift (dx, dy) that snaps the box `b` to the guides near it. */
export function snapToGuides(b: { x: number; y: number; w: number; h: number }, guides: Guides, tol: number): [number, number] {
  return [snapAxis(b.x, b.x + b.w, guides.v, tol), snapAxis(b.y, b.y + b.h, guides.h, tol)];
}

/** The guides kept for the screen `name` (none when nothing is kept or it is not readable). */
export function loadGuides(name: string): Guides {
  try {
    const g = JSON.parse(localStorage.getItem(`alba.hmi.guides.${name}`) ?? 'null');
    const nums = (a: unknown) => (Array.isArray(a) ? a.filter((x): x is number => typeof x === 'number' && Number.isFinite(x)) : []);
    return { v: nums(g?.v), h: nums(g?.h) };
  } catch {
    return { v: [], h: [] };
  }
}

export function saveGuides(name: string, g: Guides): void {
  try {
    localStorage.setItem(`alba.hmi.guides.${name}`, JSON.stringify(g));
  } catch {
    /* a browser that keeps nothing: the guides last as long as the page */
  }
}

/** A point (a vertex dragged or drawn) onto the guides near it. */
export function snapPoint(x: number, y: number, guides: Guides, tol: number): [number, number] {
  return [x + snapAxis(x, x, guides.v, tol), y + snapAxis(y, y, guides.h, tol)];
}
