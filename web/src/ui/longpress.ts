// A long press on a touch screen does what a right-click does (issue 30, item 6):
// a finger held still for half a second on an element sends it a `contextmenu`
// event at that point, so every view's menu (the ladder's and the IL's force
// menu, the tag table's) opens on a phone too. Browsers that send their own
// `contextmenu` for a long press (Chrome on Android) are left to it; the tap
// that ends a long press clicks nothing.

/** How long a finger stays down before it is a long press. */
export const LONG_PRESS_MS = 500;
/** How far it may wander meanwhile (CSS pixels). */
const SLOP = 10;

/** Listens on `root` (the document: main.ts, once) for long presses; returns the uninstaller. */
export function installLongPress(root: Document | HTMLElement = document): () => void {
  let timer: ReturnType<typeof setTimeout> | null = null;
  let start: { x: number; y: number; target: Element } | null = null;
  /** A menu was opened by this press (ours or the browser's): the rest of the press is swallowed. */
  let fired = false;
  let firedAt = 0;
  const cancel = () => {
    if (timer) clearTimeout(timer);
    timer = null;
  };
  const onStart = (e: Event) => {
    const t = e as TouchEvent;
    cancel();
    fired = false;
    if (t.touches.length !== 1) return;
    const p = t.touches[0];
    start = { x: p.clientX, y: p.clientY, target: t.target as Element };
    timer = setTimeout(() => {
      timer = null;
      if (!start) return;
      fired = true;
      firedAt = Date.now();
      start.target.dispatchEvent(new MouseEvent('contextmenu', { bubbles: true, cancelable: true, clientX: start.x, clientY: start.y, button: 2 }));
    }, LONG_PRESS_MS);
  };
  const onMove = (e: Event) => {
    const p = (e as TouchEvent).touches[0];
    if (start && p && Math.hypot(p.clientX - start.x, p.clientY - start.y) > SLOP) cancel();
  };
  const onEnd = (e: Event) => {
    cancel();
    start = null;
    // no click (nor the mouse events a browser makes of a tap) after a long press
    if (fired && e.cancelable) e.preventDefault();
  };
  const onMenu = (e: Event) => {
    if (!e.isTrusted) return;
    // the browser's own long-press menu: first, ours is not needed; after ours, it is one too many
    if (timer) {
      cancel();
      fired = true;
    } else if (fired && Date.now() - firedAt < 1500) {
      e.preventDefault();
      e.stopImmediatePropagation();
    }
  };
  root.addEventListener('touchstart', onStart, { passive: true });
  root.addEventListener('touchmove', onMove, { passive: true });
  root.addEventListener('touchend', onEnd);
  root.addEventListener('touchcancel', onEnd);
  root.addEventListener('contextmenu', onMenu, true);
  return () => {
    cancel();
    root.removeEventListener('touchstart', onStart);
    root.removeEventListener('touchmove', onMove);
    root.removeEventListener('touchend', onEnd);
    root.removeEventListener('touchcancel', onEnd);
    root.removeEventListener('contextmenu', onMenu, true);
  };
}
