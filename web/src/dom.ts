// A tiny hyperscript helper: h('div', {class: 'x', onclick: f}, child, …).

type Attrs = Record<string, unknown>;
export type Child = Node | string | number | null | undefined | false | Child[];

function append(el: Element, c: Child): void {
  if (c === null || c === undefined || c === false) return;
  if (Array.isArray(c)) c.forEach((x) => append(el, x));
  else el.append(c instanceof Node ? c : document.createTextNode(String(c)));
}

function setAttrs(el: Element, attrs: Attrs | null | undefined): void {
  if (!attrs) return;
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith('on') && typeof v === 'function') {
      el.addEventListener(k.slice(2).toLowerCase(), v as EventListener);
    } else if (k === 'style' && typeof v === 'object') {
      Object.assign((el as HTMLElement).style, v);
    } else if (k === 'value' && 'value' in el) {
      (el as HTMLInputElement).value = String(v);
    } else if (k === 'checked' && 'checked' in el) {
      (el as HTMLInputElement).checked = Boolean(v);
    } else {
      el.setAttribute(k, v === true ? '' : String(v));
    }
  }
}

export function h<K extends keyof HTMLElementTagNameMap>(tag: K, attrs?: Attrs | null, ...children: Child[]): HTMLElementTagNameMap[K] {
  const el = document.createElement(tag);
  setAttrs(el, attrs);
  children.forEach((c) => append(el, c));
  return el;
}

const SVG_NS = 'http://www.w3.org/2000/svg';

export function s<K extends keyof SVGElementTagNameMap>(tag: K, attrs?: Attrs | null, ...children: Child[]): SVGElementTagNameMap[K] {
  const el = document.createElementNS(SVG_NS, tag);
  setAttrs(el, attrs);
  children.forEach((c) => append(el, c));
  return el;
}

/** Appends children (nested arrays, null and false allowed). */
export function add(el: Element, ...children: Child[]): void {
  children.forEach((c) => append(el, c));
}

export function clear(el: Element): void {
  el.replaceChildren();
}

/** Formats a live value for display. */
export function fmt(v: unknown): string {
  if (v === undefined) return '…';
  if (v === null) return '—';
  if (typeof v === 'boolean') return v ? '1' : '0';
  if (typeof v === 'number') {
    if (Number.isInteger(v)) return String(v);
    const a = Math.abs(v);
    return a !== 0 && (a >= 1e6 || a < 1e-3) ? v.toExponential(3) : String(Number(v.toFixed(4)));
  }
  if (typeof v === 'object') return JSON.stringify(v);
  return String(v);
}

/** Triggers the download of a URL (same origin) or of text. */
export function download(filename: string, urlOrText: string, isText = false): void {
  const href = isText ? URL.createObjectURL(new Blob([urlOrText], { type: 'text/csv' })) : urlOrText;
  const a = h('a', { href, download: filename, style: { display: 'none' } });
  document.body.append(a);
  a.click();
  a.remove();
  if (isText) setTimeout(() => URL.revokeObjectURL(href), 1000);
}

/** Pans `canvas` by its scroll position while the pointer of `e` drags it (until released). */
export function dragScroll(canvas: HTMLElement, e: PointerEvent): void {
  e.preventDefault();
  e.stopPropagation();
  const [sx, sy, x0, y0] = [canvas.scrollLeft, canvas.scrollTop, e.clientX, e.clientY];
  const move = (m: PointerEvent) => {
    canvas.scrollLeft = sx - (m.clientX - x0);
    canvas.scrollTop = sy - (m.clientY - y0);
  };
  const up = () => {
    window.removeEventListener('pointermove', move);
    window.removeEventListener('pointerup', up);
  };
  window.addEventListener('pointermove', move);
  window.addEventListener('pointerup', up);
}

/** A rectangle in SVG coordinates. */
export interface Box {
  x: number;
  y: number;
  w: number;
  h: number;
}

/**
 * A rubber band: `band` (an SVG rect, already in the drawing) follows the pointer from
 * `a` while it drags; `done` gets the box when it is released. `toSvg` turns client
 * coordinates into the drawing's.
 */
export function rubberBand(
  band: SVGRectElement,
  a: { x: number; y: number },
  toSvg: (cx: number, cy: number) => { x: number; y: number },
  done: (box: Box) => void,
): void {
  let box: Box = { x: a.x, y: a.y, w: 0, h: 0 };
  const move = (m: PointerEvent) => {
    const b = toSvg(m.clientX, m.clientY);
    box = { x: Math.min(a.x, b.x), y: Math.min(a.y, b.y), w: Math.abs(b.x - a.x), h: Math.abs(b.y - a.y) };
    band.setAttribute('x', String(box.x));
    band.setAttribute('y', String(box.y));
    band.setAttribute('width', String(box.w));
    band.setAttribute('height', String(box.h));
  };
  const up = () => {
    window.removeEventListener('pointermove', move);
    window.removeEventListener('pointerup', up);
    done(box);
  };
  window.addEventListener('pointermove', move);
  window.addEventListener('pointerup', up);
}

/** A search box as wide as its placeholder (which it never cuts off, issue 30, item 23). */
export function searchBox(placeholder: string, testid: string): HTMLInputElement {
  // about 0.56 em a character in the UI's sans-serif, and room for the padding and the clear button
  return h('input', { type: 'search', placeholder, class: 'search', style: { width: `${(placeholder.length * 0.56 + 2.6).toFixed(1)}em` }, 'data-testid': testid });
}
