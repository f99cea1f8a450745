// A long press on a touch screen opens the menu a right-click opens (issue 30, item 6).
import { afterEach, describe, expect, it, vi } from 'vitest';
import { LONG_PRESS_MS, installLongPress } from '../src/ui/longpress';

/** A touch event at x, y (happy-dom's TouchEvent takes no touch list). */
function touch(type: string, target: Element, x: number, y: number, fingers = 1): Event {
  const e = new Event(type, { bubbles: true, cancelable: true });
  const list = type === 'touchend' ? [] : Array.from({ length: fingers }, () => ({ clientX: x, clientY: y }));
  Object.defineProperty(e, 'touches', { value: list });
  target.dispatchEvent(e);
  return e;
}

afterEach(() => {
  vi.useRealTimers();
  document.body.replaceChildren();
});

describe('the long press', () => {
  it('sends the element a contextmenu at the finger after half a second, and the tap that ends it clicks nothing', () => {
    vi.useFakeTimers();
    const off = installLongPress();
    const el = document.createElement('div');
    document.body.append(el);
    const menus: [number, number][] = [];
    el.addEventListener('contextmenu', (e) => menus.push([e.clientX, e.clientY]));
    touch('touchstart', el, 40, 60);
    vi.advanceTimersByTime(LONG_PRESS_MS - 10);
    expect(menus).toEqual([]);
    vi.advanceTimersByTime(10);
    expect(menus).toEqual([[40, 60]]);
    expect(touch('touchend', el, 40, 60).defaultPrevented).toBe(true);
    // a short tap is a tap
    touch('touchstart', el, 40, 60);
    vi.advanceTimersByTime(200);
    expect(touch('touchend', el, 40, 60).defaultPrevented).toBe(false);
    vi.advanceTimersByTime(LONG_PRESS_MS);
    expect(menus.length).toBe(1);
    // a finger that moves scrolls; two fingers zoom
    touch('touchstart', el, 40, 60);
    touch('touchmove', el, 40, 90);
    touch('touchstart', el, 40, 60, 2);
    vi.advanceTimersByTime(LONG_PRESS_MS * 2);
    expect(menus.length).toBe(1);
    off();
    touch('touchstart', el, 40, 60);
    vi.advanceTimersByTime(LONG_PRESS_MS * 2);
    expect(menus.length).toBe(1);
  });
});
