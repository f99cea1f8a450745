// The drawing canvas the graphical editors share (the net editor, the SFC
// chart): an SVG drawing in a scrolling element, zoomed in steps (the
// toolbar's − / + / Fit, the keys + − 0, Ctrl+wheel), panned with the middle
// button or with Space held (dragScroll), over a grid that fills the
// window whatever the drawing's size and zoom (no grey strip beside a small
// drawing, issue 30, item 23).
import { dragScroll, h, s } from './dom';
import { tr } from './i18n';

export const ZOOMS = [0.25, 0.33, 0.5, 0.67, 0.75, 0.9, 1, 1.25, 1.5, 2, 3];

export class ZoomPan {
  zoom = 1;
  /** Space is held: a left-button drag pans (editors leave their own gestures alone then). */
  space = false;
  /** The toolbar's "− 100 % + Fit", test ids `<prefix>-zoom-out`, `-zoom`, `-zoom-in`, `-zoom-fit`. */
  readonly tools: HTMLElement;
  private readonly label: HTMLElement;
  private svg: SVGSVGElement | null = null;
  private size = { w: 0, h: 0 };
  /** The drawing's top left corner (its viewBox origin). */
  private origin = { x: 0, y: 0 };

  constructor(
    private readonly canvas: HTMLElement,
    prefix: string,
    fitTitle: string,
  ) {
    this.label = h('span', { class: 'net-zoom', 'data-testid': `${prefix}-zoom` });
    const tool = (label: string, testid: string, title: string, f: () => void) =>
      h('button', { class: 'small', 'data-testid': `${prefix}-${testid}`, title, onclick: () => (f(), canvas.focus()) }, label);
    this.tools = h('span', { class: 'seg' },
      tool('−', 'zoom-out', tr('Zoom out (-)'), () => this.zoomBy(-1)),
      this.label,
      tool('+', 'zoom-in', tr('Zoom in (+)'), () => this.zoomBy(1)),
      tool(tr('Fit'), 'zoom-fit', fitTitle, () => this.fit()));
    canvas.addEventListener('wheel', (e) => {
      if (!e.ctrlKey) return;
      e.preventDefault();
      this.zoomBy(e.deltaY < 0 ? 1 : -1);
    }, { passive: false });
    canvas.addEventListener('pointerdown', (e) => {
      if (e.button === 1 || (e.button === 0 && this.space)) dragScroll(canvas, e);
    }, true);
    canvas.addEventListener('keyup', (e) => e.key === ' ' && (this.space = false));
    if (typeof ResizeObserver !== 'undefined') new ResizeObserver(() => this.set(this.zoom)).observe(canvas);
    this.set(1);
  }

  /** The drawing now shown, `w` × `h` units at zoom 1. */
  attach(svg: SVGSVGElement, w: number, h: number): void {
    this.svg = svg;
    this.size = { w, h };
    const [x, y] = (svg.getAttribute('viewBox') ?? '0 0').split(/\s+/).map(Number);
    this.origin = { x: x || 0, y: y || 0 };
    this.set(this.zoom);
  }

  /** One step of ZOOMS in (+1) or out (−1); from a zoom between two steps (after Fit), the nearer one that way. */
  zoomBy(step: number): void {
    const k = ZOOMS.findIndex((z) => z >= this.zoom - 1e-9);
    const at = k < 0 ? ZOOMS.length : k;
    const on = Math.abs((ZOOMS[at] ?? Infinity) - this.zoom) < 1e-9;
    this.set(ZOOMS[Math.max(0, Math.min(ZOOMS.length - 1, step > 0 && !on ? at : at + step))]);
  }

  /** The whole drawing in the window (25 % to 200 %). */
  fit(): void {
    const w = this.canvas.clientWidth - 20;
    const hh = this.canvas.clientHeight - 20;
    if (w > 0 && hh > 0 && this.size.w > 0 && this.size.h > 0) this.set(Math.max(0.25, Math.min(2, w / this.size.w, hh / this.size.h)));
  }

  set(z: number): void {
    this.zoom = Math.round(z * 100) / 100;
    this.label.textContent = `${Math.round(this.zoom * 100)} %`;
    const svg = this.svg;
    if (!svg) return;
    // the sheet reaches the window's edges: the drawing, or more of the grid
    const pw = Math.max(this.size.w * this.zoom, Math.floor(this.canvas.clientWidth));
    const ph = Math.max(this.size.h * this.zoom, Math.floor(this.canvas.clientHeight));
    const [w, h] = [pw / this.zoom, ph / this.zoom];
    svg.setAttribute('viewBox', `${this.origin.x} ${this.origin.y} ${w} ${h}`);
    svg.setAttribute('width', String(pw));
    svg.setAttribute('height', String(ph));
    const bg = svg.querySelector(':scope > rect.net-bg');
    bg?.setAttribute('width', String(w));
    bg?.setAttribute('height', String(h));
  }

  /** The keys of the canvas: + (or =), −, 0, and Space held; true when `e` was one of them. */
  key(e: KeyboardEvent): boolean {
    if (e.ctrlKey || e.metaKey || e.altKey) return false;
    if (e.key === ' ') this.space = true;
    else if (e.key === '+' || e.key === '=') this.zoomBy(1);
    else if (e.key === '-') this.zoomBy(-1);
    else if (e.key === '0') this.fit();
    else return false;
    return true;
  }
}

/** A grid of `step` units under the drawing: its pattern (for the `defs`) and the background rectangle filled with it. */
export function grid(id: string, step: number, box: { x: number; y: number; w: number; h: number }): { pattern: SVGPatternElement; background: SVGRectElement } {
  return {
    pattern: s('pattern', { id, width: step, height: step, patternUnits: 'userSpaceOnUse' }, s('path', { d: `M ${step} 0 L 0 0 0 ${step}`, class: 'net-grid-line' })),
    background: s('rect', { x: box.x, y: box.y, width: box.w, height: box.h, fill: `url(#${id})`, class: 'net-bg' }),
  };
}
