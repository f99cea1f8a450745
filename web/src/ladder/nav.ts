// Keyboard selection in the ladder (pure): where an arrow key takes the
// selection, from the rungs' geometry (layout.ts). Left and Right walk the
// elements of a rung in program order (a branch, then its legs one after the
// other), Left from the first element selects the rung itself and Right from
// the rung its first element; Up and Down go to the element above or below
// (another leg of a branch), else to the nearest element of the rung before
// or after; Home and End go to the first and last element of the rung.

/** A selectable element of a rung: its path ("0.1.2") and box, in program order. */
export interface NavItem {
  path: string;
  x: number;
  y: number;
  w: number;
  h: number;
}

export interface NavSelection {
  rung: number;
  /** null: the rung itself. */
  path: string | null;
}

export type NavKey = 'ArrowLeft' | 'ArrowRight' | 'ArrowUp' | 'ArrowDown' | 'Home' | 'End';

export const NAV_KEYS: readonly string[] = ['ArrowLeft', 'ArrowRight', 'ArrowUp', 'ArrowDown', 'Home', 'End'];

const cx = (i: NavItem) => i.x + i.w / 2;
const cy = (i: NavItem) => i.y + i.h / 2;

/**
 * The item of `items` at x: the upper one whose span holds x (the innermost:
 * an element, not the branch around it), else the one whose centre is nearest;
 * the rung itself when it has none.
 */
function nearest(rung: number, items: NavItem[] | null, x: number): NavSelection {
  if (!items?.length) return { rung, path: null };
  const over = items.filter((i) => i.x <= x && x < i.x + i.w);
  const inner = over.filter((i) => !over.some((o) => o.path.startsWith(i.path + '.'))).sort((a, b) => a.y - b.y);
  if (inner.length) return { rung, path: inner[0].path };
  let best = items[0];
  for (const i of items) if (Math.abs(cx(i) - x) < Math.abs(cx(best) - x)) best = i;
  return { rung, path: best.path };
}

/** One path inside the other (an element and a branch around it). */
const nested = (a: string, b: string) => a.startsWith(b + '.') || b.startsWith(a + '.');

/**
 * Where `key` takes the selection; `rungs[k]` lists rung k's items in program
 * order (null for a rung that does not parse). Nothing selected: the first rung.
 */
export function navigate(rungs: (NavItem[] | null)[], sel: NavSelection | null, key: NavKey): NavSelection | null {
  if (rungs.length === 0) return null;
  if (!sel || sel.rung >= rungs.length) return { rung: 0, path: null };
  const items = rungs[sel.rung] ?? [];
  const k = sel.path === null ? -1 : items.findIndex((i) => i.path === sel.path);
  const here = k >= 0 ? items[k] : null;
  const to = (rung: number, path: string | null): NavSelection => ({ rung, path });
  switch (key) {
    case 'Home':
      return items.length ? to(sel.rung, items[0].path) : sel;
    case 'End':
      return items.length ? to(sel.rung, items[items.length - 1].path) : sel;
    case 'ArrowRight':
      if (k + 1 < items.length) return to(sel.rung, items[k + 1].path);
      return sel;
    case 'ArrowLeft':
      if (k > 0) return to(sel.rung, items[k - 1].path);
      return to(sel.rung, null);
    case 'ArrowUp':
    case 'ArrowDown': {
      const down = key === 'ArrowDown';
      if (here) {
        // another leg of a branch: the nearest element across, over the same span of the rung
        const across = items.filter(
          (i) => i !== here && !nested(i.path, here.path) && (down ? cy(i) > here.y + here.h : cy(i) < here.y) && i.x < here.x + here.w && i.x + i.w > here.x,
        );
        if (across.length) {
          across.sort((a, b) => Math.abs(cy(a) - cy(here)) - Math.abs(cy(b) - cy(here)) || Math.abs(cx(a) - cx(here)) - Math.abs(cx(b) - cx(here)));
          return to(sel.rung, across[0].path);
        }
      }
      const next = sel.rung + (down ? 1 : -1);
      if (next < 0 || next >= rungs.length) return sel;
      return here ? nearest(next, rungs[next], cx(here)) : to(next, null);
    }
  }
}
