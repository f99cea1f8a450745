// The symbols of screen elements (issue 17, item 3): each of the 30 element
// types as a parameterised SVG drawing in its own box (0,0)–(w,h), after
// ISA-101: flat greys for equipment, colour only for state. The parts
// animations reach are marked `data-part` (fill, fill2, level, rotor, knob,
// text; and needle, hour, minute, line for the gauges, clock and trend).
// Rotating parts sit in a group translated to their axis, so that a CSS
// spin or a `rotate(…)` on the part turns them about it.
import { s } from '../dom';
import type { Element } from './render';
import type { Json } from '../types';
import { PEN_COLORS, penPart, trendPens } from './trend';

export const GREY = '#9ea3a8';
export const DARK = '#5f6368';
export const LIGHT = '#e4e6e8';
export const ON = '#2e7d32';
/** The ink of texts and markings. */
const INK = '#202124';
/** A level (liquid or bulk) in a vessel or a meter. */
const LEVEL = '#4a90c2';
/** ISO 3864 safety yellow: a warning sign is yellow whatever its state. */
const SIGN = '#f9a800';

type Attrs = Record<string, unknown>;

/** A coordinate rounded to 1/100: short, stable SVG text. */
const n = (v: number) => Math.round(v * 100) / 100;

/** A path's `d` from commands and numbers: d('M', 0, 0, 'L', 1, 2). */
const d = (...parts: (string | number)[]) => parts.map((p) => (typeof p === 'number' ? n(p) : p)).join(' ');

/** A points list: pts([0, 0], [1, 2]). */
const pts = (...ps: [number, number][]) => ps.map(([x, y]) => `${n(x)},${n(y)}`).join(' ');

/** A point at `deg` degrees (SVG: clockwise from +x) on a circle. */
const polar = (cx: number, cy: number, r: number, deg: number): [number, number] => {
  const a = (deg * Math.PI) / 180;
  return [cx + r * Math.cos(a), cy + r * Math.sin(a)];
};

const stroke = (width = 1.5, color = DARK): Attrs => ({ stroke: color, 'stroke-width': width });
const line = (x1: number, y1: number, x2: number, y2: number, attrs: Attrs = stroke(1)) =>
  s('line', { x1: n(x1), y1: n(y1), x2: n(x2), y2: n(y2), ...attrs });
const rect = (x: number, y: number, width: number, height: number, attrs: Attrs) =>
  s('rect', { x: n(x), y: n(y), width: n(Math.max(0, width)), height: n(Math.max(0, height)), ...attrs });
const circle = (cx: number, cy: number, r: number, attrs: Attrs) => s('circle', { cx: n(cx), cy: n(cy), r: n(Math.max(0, r)), ...attrs });
/** A grey equipment surface. */
const face = (attrs: Attrs = {}): Attrs => ({ fill: LIGHT, ...stroke(), ...attrs });
/** A group placed at (x, y): the axis of what it holds. */
const at = (x: number, y: number, ...children: SVGElement[]) => s('g', { transform: `translate(${n(x)},${n(y)})` }, children);
/** A rotor: the part a `rotate` animation turns (about its group's origin). */
const rotor = (...children: SVGElement[]) => s('g', { 'data-part': 'rotor' }, children);

/**
 * Draws `draw(bw, bh)` in the largest box of (w, h) whose aspect bw/bh lies in
 * [lo, hi], centred across and standing on the bottom: a pump stays round in
 * a long box.
 */
function fitted(w: number, h: number, lo: number, hi: number, draw: (bw: number, bh: number) => SVGElement[]): SVGElement[] {
  const bw = Math.min(w, h * hi);
  const bh = Math.min(h, w / lo);
  const [ox, oy] = [(w - bw) / 2, h - bh];
  return ox || oy ? [at(ox, oy, ...draw(bw, bh))] : draw(bw, bh);
}

/** A straight bar of thickness t from (x1,y1) to (x2,y2), as a polygon (so that it takes a fill colour). */
function bar(x1: number, y1: number, x2: number, y2: number, t: number): SVGElement {
  const len = Math.hypot(x2 - x1, y2 - y1) || 1;
  const [nx, ny] = [((y1 - y2) / len) * (t / 2), ((x2 - x1) / len) * (t / 2)];
  return s('polygon', { points: pts([x1 + nx, y1 + ny], [x2 + nx, y2 + ny], [x2 - nx, y2 - ny], [x1 - nx, y1 - ny]) });
}

/**
 * A vessel: its outline `shape` (a path's d), a level clipped to it (the
 * `level` rect at x=2, y=h-2, width w-4, height 0 that `fill` animations
 * resize), and the outline drawn over the level. The clip's id depends only
 * on the geometry, so two equal ids are two equal shapes.
 */
function vessel(e: Element, shape: string, key: string): SVGElement[] {
  const { w, h } = e;
  const id = `hmi-clip-${key}-${n(w)}x${n(h)}`.replace(/[^\w-]/g, '_');
  return [
    s('clipPath', { id }, s('path', { d: shape })),
    s('path', { d: shape, fill: '#fff' }),
    s('rect', { x: 2, y: h - 2, width: w - 4, height: 0, fill: LEVEL, 'clip-path': `url(#${id})`, 'data-part': 'level' }),
    s('path', { d: shape, fill: 'none', ...stroke(), 'stroke-linejoin': 'round' }),
  ];
}

/** Tick marks on the right wall of a vessel or a bar meter, at quarters. */
const quarterTicks = (x: number, y0: number, y1: number, len: number) =>
  [0.25, 0.5, 0.75].map((f) => line(x, y1 - (y1 - y0) * f, x - len, y1 - (y1 - y0) * f, stroke(1)));

/** A round dial (clock or gauge): face, ticks from `from` over `sweep` degrees, `count` ticks, every `major`-th longer. */
function dial(cx: number, cy: number, R: number, from: number, sweep: number, count: number, major: number): SVGElement[] {
  const ticks = Array.from({ length: count }, (_, i) => {
    const a = from + (sweep * i) / (sweep === 360 ? count : count - 1);
    const long = i % major === 0;
    const [x1, y1] = polar(cx, cy, R * (long ? 0.72 : 0.8), a);
    const [x2, y2] = polar(cx, cy, R * 0.88, a);
    return line(x1, y1, x2, y2, stroke(long ? 2 : 1, long ? INK : DARK));
  });
  return [circle(cx, cy, R, { fill: '#fff', ...stroke() }), ...ticks];
}

/** The symbol of an element type, in its box: the parts animations reach are marked `data-part`. */
export function symbol(e: Element): SVGElement[] {
  const { w, h } = e;
  const p = e.props ?? {};
  const label = typeof p.label === 'string' ? p.label : '';
  const text = (t: string, y = h / 2, size = 13) =>
    s('text', { x: n(w / 2), y: n(y), 'text-anchor': 'middle', 'dominant-baseline': 'middle', 'font-size': n(size), fill: INK, 'data-part': 'text' }, t);
  /** The name under an equipment symbol. */
  const name = () => text(label, h + 14, 12);
  const m = Math.min(w, h);
  switch (e.type) {
    // ——— basic shapes and controls (unchanged parts) ———
    case 'text': {
      const t = text(label || String(p.text ?? ''), h / 2, Number(p.size ?? 14));
      if (typeof p.color === 'string') t.setAttribute('fill', p.color);
      return [t];
    }
    case 'output':
    case 'input':
      return [s('rect', face({ width: w, height: h, rx: 3, fill: '#fff' })), text('…')];
    case 'rectangle':
      return [s('rect', painted(p, face({ width: w, height: h, 'data-part': 'fill' })))];
    case 'circle':
      return [s('ellipse', painted(p, face({ cx: n(w / 2), cy: n(h / 2), rx: n(w / 2), ry: n(h / 2), 'data-part': 'fill' })))];
    case 'line': {
      const ps = points(p);
      const attrs = painted(p, { fill: 'none', ...stroke(3), 'stroke-linecap': 'round', 'stroke-linejoin': 'round', 'data-part': 'fill' }, 'stroke');
      return [ps ? s('polyline', { points: pts(...ps), ...attrs }) : line(0, h / 2, w, h / 2, attrs)];
    }
    case 'polygon':
      return [s('polygon', painted(p, face({ points: pts(...(points(p) ?? [[w / 2, 0], [w, h], [0, h]])), 'stroke-linejoin': 'round', 'data-part': 'fill' })))];
    case 'arc':
      return [arc(w, h, p)];
    case 'button':
      return [s('rect', painted(p, face({ width: w, height: h, rx: 6, fill: '#f1f3f4', 'data-part': 'fill' }))), text(label || e.type)];
    case 'switch':
      return switchOf(w, h, p, text(label || e.type));
    case 'slider':
      return [
        s('rect', face({ y: n(h / 2 - 3), width: w, height: 6, rx: 3 })),
        circle(0, h / 2, Math.min(10, h / 2), { fill: DARK, 'data-part': 'knob' }),
      ];
    case 'image':
      if (typeof p.src !== 'string') return imagePlaceholder(w, h);
      else {
        // scaled by percent about the box's centre (the seed's file dialog); else fitted
        const k = typeof p.scale === 'number' ? p.scale / 100 : 1;
        // a project's image (`assets/<name>`) is served by the API, whatever page shows it
        const href = p.src.startsWith('assets/') ? `/api/${p.src}` : p.src;
        return [s('image', { href, x: n((w - w * k) / 2), y: n((h - h * k) / 2), width: n(w * k), height: n(h * k), 'data-part': 'image' })];
      }
    // ——— indicators ———
    case 'led':
      return led(w, h, p);
    case 'alarm':
      return fitted(w, h, 0.8, 1.25, alarm);
    case 'clock':
      return clock(w, h, m);
    case 'meter':
      return p.style === 'circular' ? gauge(w, h, m, text) : barMeter(w, h, text);
    case 'trend': {
      // its title stays; the value it shows is drawn as the pen
      const title = text(label, -8, 12);
      title.setAttribute('data-part', 'title');
      return [...trend(w, h, p), title];
    }
    case 'faceplate':
      return faceplate(w, h, label || (typeof p.tag === 'string' ? p.tag : ''));
    case 'safety_sign':
      return [...safetySign(w, h, typeof p.sign === 'string' ? p.sign : 'danger'), name()];
    // ——— rotating equipment ———
    case 'wind_turbine':
      return [...windTurbine(w, h, p.tower !== false), name()];
    case 'fan':
      return [...fan(w, h, m, p.casing !== false), name()];
    case 'motor':
      return [...bodyColour(fitted(w, h, 1, 2, motor), p), name()];
    case 'pump':
      return [...bodyColour(fitted(w, h, 0.8, 1.4, pump), p), name()];
    // ——— process equipment ———
    case 'tank':
      return [...tank(e), name()];
    case 'bottle':
      return [...bottle(e), name()];
    case 'pipe':
      return pipe(w, h, typeof p.shape === 'string' ? p.shape : 'straight');
    case 'valve':
      return valve(w, h, typeof p.style === 'string' ? p.style : 'gate');
    case 'cooling_tower':
      return [...coolingTower(w, h, m), name()];
    // ——— plant and site ———
    case 'plc':
      return [...plc(w, h), name()];
    case 'building':
      return [...building(w, h), name()];
    case 'transmission_tower':
      return [...transmissionTower(w, h, m), name()];
    default:
      // a type this studio does not know yet: a labelled box
      return [s('rect', face({ width: w, height: h, rx: 4, 'data-part': 'fill' })), text(label || e.type.replace(/_/g, ' '), h / 2, 11)];
  }
}

/** The element's own `color`, `stroke` and `stroke_width` over `attrs` (a line's colour is its `stroke`). */
function painted(p: Record<string, unknown>, attrs: Attrs, colourOf: 'fill' | 'stroke' = 'fill'): Attrs {
  const out = { ...attrs };
  if (typeof p.color === 'string') out[colourOf] = p.color;
  if (typeof p.stroke === 'string') out.stroke = p.stroke;
  if (typeof p.stroke_width === 'number') out['stroke-width'] = p.stroke_width;
  return out;
}

/** An equipment symbol's body (its `fill` parts) in the element's own `color`. */
function bodyColour(els: SVGElement[], p: Record<string, unknown>): SVGElement[] {
  if (typeof p.color === 'string') for (const e of els) [e, ...e.querySelectorAll('[data-part="fill"]')].forEach((x) => x.getAttribute('data-part') === 'fill' && x.setAttribute('fill', p.color as string));
  return els;
}

/** `props.points`, the vertices of a polygon or a polyline (at least two), or null. */
function points(p: Record<string, unknown>): [number, number][] | null {
  const v = p.points;
  if (!Array.isArray(v) || v.length < 2) return null;
  const ok = v.every((xy) => Array.isArray(xy) && xy.length === 2 && xy.every((c) => typeof c === 'number'));
  return ok ? (v as [number, number][]) : null;
}

/** An arc in its box from `start` to `end` (degrees clockwise from 12 o'clock), open, closed by its chord or through its centre. */
function arc(w: number, h: number, p: Record<string, unknown>): SVGElement {
  const [start, end] = [typeof p.start === 'number' ? p.start : -90, typeof p.end === 'number' ? p.end : 90];
  const [rx, ry, cx, cy] = [w / 2 - 1, h / 2 - 1, w / 2, h / 2];
  const at = (deg: number): [number, number] => [cx + rx * Math.sin((deg * Math.PI) / 180), cy - ry * Math.cos((deg * Math.PI) / 180)];
  const sweep = Math.max(-359.9, Math.min(359.9, end - start));
  const [x0, y0] = at(start);
  const [x1, y1] = at(start + sweep);
  const close = p.close === 'chord' ? ' Z' : p.close === 'centre' ? ` L ${n(cx)} ${n(cy)} Z` : '';
  const path = `${d('M', x0, y0, 'A', rx, ry, 0, Math.abs(sweep) > 180 ? 1 : 0, sweep > 0 ? 1 : 0, x1, y1)}${close}`;
  return s('path', painted(p, { d: path, fill: close ? LIGHT : 'none', ...stroke(3), 'stroke-linejoin': 'round', 'data-part': 'fill' }, close ? 'fill' : 'stroke'));
}

/** A switch: a toggle lever (the default), a rocker, or a rotary selector; its label under a rocker or rotary. */
function switchOf(w: number, h: number, p: Record<string, unknown>, label: SVGElement): SVGElement[] {
  const body = (attrs: Attrs) => painted(p, face(attrs));
  if (p.style === 'rocker') {
    const [bw, bh] = [Math.min(w, h * 0.7), h * 0.8];
    const [x, y] = [(w - bw) / 2, 1];
    label.setAttribute('y', String(n(h + 10)));
    return [
      rect(x, y, bw, bh, { rx: 3, fill: DARK }),
      s('path', body({ d: d('M', x + 3, y + 3, 'L', x + bw - 3, y + 3, 'L', x + bw - 3, y + bh * 0.55, 'L', x + 3, y + bh - 3, 'Z'), 'stroke-linejoin': 'round', 'data-part': 'fill' })),
      label,
    ];
  }
  if (p.style === 'rotary') {
    const R = Math.min(w, h) / 2 - 2;
    const [cx, cy] = [w / 2, h / 2];
    label.setAttribute('y', String(n(h + 10)));
    return [
      circle(cx, cy, R, body({ 'data-part': 'fill' })),
      at(cx, cy, s('g', { 'data-part': 'knob' }, rect(-R * 0.18, -R * 0.95, R * 0.36, R * 1.9, { rx: R * 0.15, fill: DARK }), line(0, -R * 0.85, 0, -R * 0.45, stroke(2, '#fff')))),
      label,
    ];
  }
  return [s('rect', body({ width: w, height: h, rx: 6, fill: '#f1f3f4', 'data-part': 'fill' })), label];
}

// ——— indicators ———

/** An image without a source: a frame with a mountain and a sun. */
function imagePlaceholder(w: number, h: number): SVGElement[] {
  return [
    s('rect', face({ width: w, height: h, 'data-part': 'fill' })),
    s('polyline', { points: pts([w * 0.1, h * 0.85], [w * 0.4, h * 0.45], [w * 0.6, h * 0.7], [w * 0.72, h * 0.58], [w * 0.9, h * 0.85]), fill: 'none', ...stroke(1.5, GREY), 'stroke-linejoin': 'round' }),
    circle(w * 0.72, h * 0.3, Math.min(w, h) * 0.08, { fill: 'none', ...stroke(1.5, GREY) }),
  ];
}

/** An indicator lamp: a grey bezel ring around the lamp (the `fill`), with a flat highlight. */
function led(w: number, h: number, p: Record<string, unknown>): SVGElement[] {
  const [cx, cy, R] = [w / 2, h / 2, Math.min(w, h) / 2 - 1];
  return [
    circle(cx, cy, R, { fill: LIGHT, ...stroke(1, GREY) }),
    circle(cx, cy, R * 0.78, { fill: typeof p.color === 'string' ? p.color : GREY, ...stroke(1.5), 'data-part': 'fill' }),
    s('ellipse', { cx: n(cx - R * 0.25), cy: n(cy - R * 0.3), rx: n(R * 0.22), ry: n(R * 0.13), fill: '#fff', opacity: 0.45, transform: `rotate(-35 ${n(cx - R * 0.25)} ${n(cy - R * 0.3)})` }),
  ];
}

/** An alarm annunciator: a bell (the `fill`) with its clapper and sound arcs either side. */
function alarm(w: number, h: number): SVGElement[] {
  const cx = w / 2;
  const bell = d(
    'M', w * 0.2, h * 0.74,
    'C', w * 0.3, h * 0.66, w * 0.29, h * 0.52, w * 0.3, h * 0.4,
    'C', w * 0.32, h * 0.16, w * 0.68, h * 0.16, w * 0.7, h * 0.4,
    'C', w * 0.71, h * 0.52, w * 0.7, h * 0.66, w * 0.8, h * 0.74, 'Z',
  );
  const wave = (x: number, dx: number, r: number) =>
    s('path', { d: d('M', x, h * (0.45 - r), 'Q', x + dx, h * 0.45, x, h * (0.45 + r)), fill: 'none', ...stroke(1.5, GREY), 'stroke-linecap': 'round' });
  return [
    circle(cx, h * 0.16, Math.min(w, h) * 0.05, face()),
    circle(cx, h * 0.84, Math.min(w, h) * 0.07, { fill: DARK }),
    s('path', { d: bell, fill: GREY, ...stroke(), 'stroke-linejoin': 'round', 'data-part': 'fill' }),
    rect(w * 0.16, h * 0.73, w * 0.68, h * 0.05, { rx: 1.5, fill: DARK }),
    wave(w * 0.18, -w * 0.08, 0.1),
    wave(w * 0.1, -w * 0.08, 0.17),
    wave(w * 0.82, w * 0.08, 0.1),
    wave(w * 0.9, w * 0.08, 0.17),
  ];
}

/**
 * An analog clock: a face with 12 hour ticks, hour and minute hands (each a
 * group turned `rotate(deg)` clockwise from 12 o'clock about the centre) set
 * to the time it is drawn, and the time in figures (`text`).
 */
function clock(w: number, h: number, m: number): SVGElement[] {
  const [cx, cy, R] = [w / 2, h / 2, m / 2 - 1];
  const now = new Date();
  const [hh, mm, ss] = [now.getHours(), now.getMinutes(), now.getSeconds()];
  const hand = (part: string, deg: number, len: number, width: number) =>
    s('g', { 'data-part': part, transform: `rotate(${n(deg)})` }, line(0, R * 0.12, 0, -len, { ...stroke(width, INK), 'stroke-linecap': 'round' }));
  const two = (v: number) => String(v).padStart(2, '0');
  return [
    ...dial(cx, cy, R, -90, 360, 12, 3),
    s('text', { x: n(cx), y: n(cy + R * 0.42), 'text-anchor': 'middle', 'dominant-baseline': 'middle', 'font-size': n(Math.max(8, R * 0.2)), fill: DARK, 'data-part': 'text' }, `${two(hh)}:${two(mm)}:${two(ss)}`),
    at(cx, cy, hand('hour', (hh % 12) * 30 + mm / 2, R * 0.5, 3), hand('minute', mm * 6 + ss / 10, R * 0.75, 2), circle(0, 0, Math.max(1.5, R * 0.06), { fill: INK })),
  ];
}

/**
 * A circular gauge: a 270° scale from bottom-left (min) clockwise to
 * bottom-right (max) with 11 ticks; the `needle` group points at the minimum,
 * so `rotate(f·270)` about the centre shows the fraction f; the value in
 * figures (`text`) under the centre.
 */
function gauge(w: number, h: number, m: number, text: (t: string, y?: number, size?: number) => SVGElement): SVGElement[] {
  const [cx, cy, R] = [w / 2, h / 2, m / 2 - 1];
  const r = R * 0.88;
  const [x0, y0] = polar(cx, cy, r, 135);
  const [x1, y1] = polar(cx, cy, r, 405);
  const [tx, ty] = polar(0, 0, R * 0.78, 135);
  const [bx, by] = polar(0, 0, R * 0.045, 45);
  const [kx, ky] = polar(0, 0, R * 0.14, 315);
  return [
    ...dial(cx, cy, R, 135, 270, 11, 5),
    s('path', { d: d('M', x0, y0, 'A', r, r, 0, 1, 1, x1, y1), fill: 'none', ...stroke(1.5) }),
    text('…', cy + R * 0.5, Math.max(9, R * 0.22)),
    at(cx, cy,
      s('g', { 'data-part': 'needle' }, s('polygon', { points: pts([tx, ty], [bx, by], [kx, ky], [-bx, -by]), fill: INK })),
      circle(0, 0, Math.max(2, R * 0.07), { fill: DARK })),
  ];
}

/** A bar meter: a frame, the `level` bar that `fill` animations resize, quarter ticks, the value (`text`) above. */
function barMeter(w: number, h: number, text: (t: string, y?: number, size?: number) => SVGElement): SVGElement[] {
  return [
    s('rect', face({ width: w, height: h, fill: '#fff' })),
    s('rect', { x: 2, y: h - 2, width: w - 4, height: 0, fill: LEVEL, 'data-part': 'level' }),
    ...quarterTicks(w, 0, h, Math.min(w * 0.25, 10)),
    text('…', -8, 12),
  ];
}

/**
 * A trend: a framed plot area (the `fill`) with a light grid, two axes and an
 * empty pen `line`, the title (`text`) above; the scale's ends (`y-min`,
 * `y-max`: `props.min`/`max` until values come) left of the y axis and the
 * window's start and end times (`x-from`, `x-to`) below the time axis.
 */
function trend(w: number, h: number, p: Record<string, unknown>): SVGElement[] {
  const font = 9;
  const [x0, y0, x1, y1] = [Math.max(6, Math.min(34, w * 0.16)), Math.max(6, h * 0.06), w - Math.max(6, w * 0.04), h - Math.max(font + 6, h * 0.1)];
  const grid = stroke(1, LIGHT);
  const label = (part: string, x: number, y: number, anchor: string, t: unknown) =>
    s('text', { x: n(x), y: n(y), 'text-anchor': anchor, 'dominant-baseline': 'middle', 'font-size': font, fill: DARK, 'data-part': part }, typeof t === 'number' ? String(t) : '');
  return [
    s('rect', face({ width: w, height: h, rx: 2, fill: '#fff', 'data-part': 'fill' })),
    ...[1, 2, 3].map((i) => line(x0 + ((x1 - x0) * i) / 4, y0, x0 + ((x1 - x0) * i) / 4, y1, grid)),
    ...[1, 2, 3].map((i) => line(x0, y0 + ((y1 - y0) * i) / 4, x1, y0 + ((y1 - y0) * i) / 4, grid)),
    s('polyline', { points: pts([x0, y0], [x0, y1], [x1, y1]), fill: 'none', ...stroke(1.5) }),
    label('y-max', x0 - 3, y0, 'end', p.max),
    label('y-min', x0 - 3, y1, 'end', p.min),
    label('x-from', x0, y1 + font / 2 + 3, 'start', null),
    label('x-to', x1, y1 + font / 2 + 3, 'end', null),
    ...penLines(p, [x0, y0, x1, y1], font),
  ];
}

/**
 * A trend's pens (trend.ts `trendPens`: `props.pens`, up to three, else the
 * one pen of its `tag`): an empty line each (`line`, `line-2`, `line-3`) in
 * its colour; with more than one, a legend of their tags top right.
 */
function penLines(p: Record<string, unknown>, box: [number, number, number, number], font: number): SVGElement[] {
  const [x0, y0, x1, y1] = box;
  const pens = trendPens(p as Record<string, Json>);
  const shown = pens.length ? pens : [{ tag: '', color: PEN_COLORS[0] }];
  const lines = shown.map((pen, k) =>
    s('polyline', { points: '', fill: 'none', ...stroke(1.5, pen.color), 'stroke-linejoin': 'round', 'data-part': penPart(k), 'data-box': [x0, y0, x1, y1].map(n).join(',') }));
  const legend =
    pens.length > 1
      ? pens.map((pen, k) => s('text', { x: n(x1 - 3), y: n(y0 + font * (k + 0.9)), 'text-anchor': 'end', 'font-size': font, fill: pen.color, 'data-part': `pen-${k + 1}` }, pen.tag))
      : [];
  return [...lines, ...legend];
}

/**
 * A PID loop's faceplate on a screen: the loop's name, a bar and the figures
 * of SP, PV and CV (`bar-SP`, `val-SP` …: the view fills them from the
 * loop's members), and its mode (`mode`). Clicking it opens the full faceplate.
 */
function faceplate(w: number, h: number, name: string): SVGElement[] {
  const row = (h - 34) / 3;
  const label = (t: string, x: number, y: number, attrs: Attrs = {}) =>
    s('text', { x: n(x), y: n(y), 'dominant-baseline': 'middle', 'font-size': n(Math.max(9, Math.min(13, row * 0.45))), fill: INK, ...attrs }, t);
  const colours: Record<string, string> = { SP: '#1f77b4', PV: '#2ca02c', CV: '#ff7f0e' };
  const bars = ['SP', 'PV', 'CV'].map((m, k) => {
    const y = 22 + k * row + row / 2;
    const [x0, x1] = [w * 0.14, w * 0.62];
    return [
      label(m, 6, y),
      s('rect', { x: n(x0), y: n(y - row * 0.2), width: n(x1 - x0), height: n(row * 0.4), fill: '#fff', ...stroke(1) }),
      s('rect', { x: n(x0), y: n(y - row * 0.2), width: 0, height: n(row * 0.4), fill: colours[m], 'data-part': `bar-${m}`, 'data-width': n(x1 - x0) }),
      label('…', w - 6, y, { 'text-anchor': 'end', 'data-part': `val-${m}` }),
    ];
  });
  return [
    s('rect', face({ width: w, height: h, rx: 4, fill: '#fff', 'data-part': 'fill' })),
    label(name, 6, 11, { 'font-weight': 'bold' }),
    label('', w - 6, 11, { 'text-anchor': 'end', 'data-part': 'mode' }),
    ...bars.flat(),
  ];
}

/** An ISO 7010 general warning sign: a yellow triangle (the `fill`) with a black border and "!". */
/** The shape of each sign (ISO 7010): warning triangle, prohibition circle, mandatory (blue) or safe/fire square. */
const SIGN_SHAPE: Record<string, 'warning' | 'prohibition' | 'mandatory' | 'fire' | 'safe'> = {
  danger: 'warning', electrical: 'warning', radiation: 'warning', toxic: 'warning', flammable: 'warning', corrosive: 'warning',
  stop: 'prohibition', no_entry: 'prohibition', helmet: 'mandatory', fire_extinguisher: 'fire', exit: 'safe',
};

/** A safety sign of `SIGNS` (`000_…` §3.6): its shape and colour by category, and its pictogram. */
function safetySign(w: number, h: number, sign: string): SVGElement[] {
  const shape = SIGN_SHAPE[sign] ?? 'warning';
  const m = Math.min(w, h);
  const sw = Math.max(2, m * 0.07);
  const [cx, cy] = [w / 2, h / 2];
  if (shape === 'warning') {
    const side = Math.min(w, h / 0.866) - sw - 2;
    const th = side * 0.866;
    const top = (h - th) / 2;
    const [px, py, ps] = [cx, top + th * 0.62, side * 0.3];
    return [
      s('polygon', { points: pts([cx, top], [cx + side / 2, top + th], [cx - side / 2, top + th]), fill: SIGN, ...stroke(sw, INK), 'stroke-linejoin': 'round', 'data-part': 'fill' }),
      ...pictogram(sign, px, py, ps),
    ];
  }
  const R = m / 2 - sw / 2 - 1;
  if (shape === 'prohibition') {
    return [
      circle(cx, cy, R, { fill: '#fff', ...stroke(sw, '#c62828'), 'data-part': 'fill' }),
      ...pictogram(sign, cx, cy, R * 0.9),
      line(cx - R * 0.7, cy - R * 0.7, cx + R * 0.7, cy + R * 0.7, stroke(sw, '#c62828')),
    ];
  }
  const colour = shape === 'mandatory' ? '#1565c0' : shape === 'fire' ? '#c62828' : '#2e7d32';
  const body = shape === 'mandatory' ? circle(cx, cy, R, { fill: colour, 'data-part': 'fill' }) : rect(cx - R, cy - R, R * 2, R * 2, { rx: 2, fill: colour, 'data-part': 'fill' });
  return [body, ...pictogram(sign, cx, cy, R * 0.9)];
}

/** The pictogram of a sign centred at (x, y), about `r` across. */
function pictogram(sign: string, x: number, y: number, r: number): SVGElement[] {
  const ink = { fill: INK };
  const white = { fill: '#fff' };
  switch (sign) {
    case 'electrical':
      return [s('polygon', { points: pts([x + r * 0.1, y - r * 0.6], [x - r * 0.3, y + r * 0.05], [x, y + r * 0.05], [x - r * 0.1, y + r * 0.6], [x + r * 0.3, y - r * 0.05], [x, y - r * 0.05]), ...ink })];
    case 'radiation':
      return [circle(x, y, r * 0.1, ink), ...[0, 120, 240].map((a) => s('path', { d: d('M', x, y, 'L', ...polar(x, y, r * 0.5, a - 30), 'A', r * 0.5, r * 0.5, 0, 0, 1, ...polar(x, y, r * 0.5, a + 30), 'Z'), ...ink }))];
    case 'toxic':
      return [circle(x, y - r * 0.15, r * 0.3, ink), line(x - r * 0.4, y + r * 0.1, x + r * 0.4, y + r * 0.5, stroke(r * 0.1, INK)), line(x + r * 0.4, y + r * 0.1, x - r * 0.4, y + r * 0.5, stroke(r * 0.1, INK))];
    case 'flammable':
      return [s('path', { d: d('M', x, y - r * 0.55, 'C', x + r * 0.5, y - r * 0.1, x + r * 0.3, y + r * 0.45, x, y + r * 0.45, 'C', x - r * 0.35, y + r * 0.45, x - r * 0.45, y, x, y - r * 0.55, 'Z'), ...ink })];
    case 'corrosive':
      return [rect(x - r * 0.5, y + r * 0.2, r * 0.4, r * 0.25, ink), rect(x + r * 0.1, y + r * 0.2, r * 0.4, r * 0.25, ink), circle(x - r * 0.3, y - r * 0.1, r * 0.08, ink), circle(x + r * 0.3, y - r * 0.1, r * 0.08, ink)];
    case 'stop':
      return [circle(x, y, r * 0.35, ink)];
    case 'no_entry':
      return [circle(x, y - r * 0.45, r * 0.14, ink), rect(x - r * 0.12, y - r * 0.28, r * 0.24, r * 0.7, ink)];
    case 'helmet':
      return [s('path', { d: d('M', x - r * 0.6, y + r * 0.2, 'A', r * 0.6, r * 0.6, 0, 0, 1, x + r * 0.6, y + r * 0.2, 'Z'), ...white }), rect(x - r * 0.7, y + r * 0.2, r * 1.4, r * 0.12, white)];
    case 'fire_extinguisher':
      return [rect(x - r * 0.2, y - r * 0.3, r * 0.4, r * 0.9, { rx: r * 0.1, ...white }), line(x, y - r * 0.3, x + r * 0.3, y - r * 0.55, stroke(r * 0.08, '#fff'))];
    case 'exit':
      return [circle(x + r * 0.1, y - r * 0.5, r * 0.12, white), s('polyline', { points: pts([x - r * 0.4, y + r * 0.5], [x - r * 0.05, y + r * 0.05], [x + r * 0.35, y + r * 0.5]), fill: 'none', ...stroke(r * 0.14, '#fff') }), line(x - r * 0.05, y - r * 0.3, x - r * 0.05, y + r * 0.05, stroke(r * 0.14, '#fff'))];
    default:
      // danger: the exclamation mark
      return [s('polygon', { points: pts([x - r * 0.08, y - r * 0.55], [x + r * 0.08, y - r * 0.55], [x + r * 0.05, y + r * 0.2], [x - r * 0.05, y + r * 0.2]), ...ink }), circle(x, y + r * 0.4, r * 0.08, ink)];
  }
}
function windTurbine(w: number, h: number, tower: boolean): SVGElement[] {
  const R = Math.max(4, Math.min(w / 2, h * 0.4) - 2);
  const [hx, hy] = [w / 2, R + 2];
  const [t0, t1] = [Math.max(1.5, w * 0.025), Math.max(3, w * 0.05)];
  const b = R * 0.085;
  const blade = (deg: number) =>
    s('path', { d: d('M', 0, -b, 'L', R * 0.22, -b * 2, 'Q', R * 0.7, -b * 1.1, R, 0, 'Q', R * 0.6, b * 0.6, 0, b, 'Z'), transform: `rotate(${deg})`, ...face({ 'stroke-width': 1, 'stroke-linejoin': 'round' }) });
  return [
    ...(tower ? [s('polygon', face({ points: pts([hx - t0, hy], [hx + t0, hy], [hx + t1, h], [hx - t1, h]), 'stroke-linejoin': 'round', 'data-part': 'tower' })), line(hx - t1 * 3, h, hx + t1 * 3, h, stroke(2))] : []),
    rect(hx - R * 0.16, hy - R * 0.1, R * 0.32, R * 0.2, face({ rx: 2, 'data-part': 'fill' })),
    at(hx, hy, rotor(blade(-90), blade(30), blade(150), circle(0, 0, R * 0.09, { fill: DARK }))),
  ];
}

/** A fan: a round housing (`fill`) around the duct, four swept blades and the hub in the `rotor`. */
function fan(w: number, h: number, m: number, casing: boolean): SVGElement[] {
  const [cx, cy, R] = [w / 2, h / 2, m / 2 - 2];
  const r = R * 0.84;
  const blade = (deg: number) =>
    s('path', { d: d('M', 0, 0, 'C', r * 0.1, -r * 0.5, r * 0.75, -r * 0.6, r * 0.9, -r * 0.15, 'C', r * 0.65, -r * 0.02, r * 0.35, r * 0.08, 0, 0, 'Z'), transform: `rotate(${deg})`, fill: GREY, ...stroke(1), 'stroke-linejoin': 'round' });
  return [
    ...(casing ? [circle(cx, cy, R, face({ 'data-part': 'fill' })), circle(cx, cy, r, { fill: '#fff', ...stroke(1) })] : []),
    at(cx, cy, rotor(blade(0), blade(90), blade(180), blade(270), circle(0, 0, R * 0.14, { fill: DARK }))),
  ];
}

/**
 * A motor, side view: fan cowl, finned body (`fill`), terminal box on top,
 * feet on a base plate, the shaft to the right ending in a coupling disc
 * (the `rotor`, with spokes that show it turning).
 */
function motor(w: number, h: number): SVGElement[] {
  const m = Math.min(w, h);
  const [x0, x1, yt, yb] = [w * 0.14, w * 0.7, h * 0.3, h * 0.76];
  const cy = (yt + yb) / 2;
  const rc = Math.max(3, m * 0.09);
  const xc = w - rc - 1.5;
  const fins = [1, 2, 3, 4].map((i) => line(x0 + w * 0.05, yt + ((yb - yt) * i) / 5, x1 - w * 0.05, yt + ((yb - yt) * i) / 5, stroke(1)));
  return [
    rect(w * 0.03, yt + h * 0.05, x0 - w * 0.03, yb - yt - h * 0.1, face({ rx: 3 })),
    rect(x1, cy - h * 0.04, xc - x1, h * 0.08, { fill: GREY, ...stroke(1) }),
    rect(x1, yt + h * 0.06, w * 0.06, yb - yt - h * 0.12, face({ rx: 1.5 })),
    rect(w * 0.36, h * 0.18, w * 0.18, yt - h * 0.18 + 0.75, face({ rx: 1.5 })),
    rect(x0 + w * 0.05, yb, w * 0.1, h * 0.08, { fill: GREY, ...stroke(1) }),
    rect(x1 - w * 0.15, yb, w * 0.1, h * 0.08, { fill: GREY, ...stroke(1) }),
    rect(x0 - w * 0.02, yb + h * 0.08, x1 - x0 + w * 0.04, Math.max(2, h * 0.03), { fill: DARK }),
    rect(x0, yt, x1 - x0, yb - yt, face({ rx: 3, 'data-part': 'fill' })),
    ...fins,
    at(xc, cy, rotor(circle(0, 0, rc, face({ 'stroke-width': 1 })), line(-rc, 0, rc, 0, stroke(1.5)), line(0, -rc, 0, rc, stroke(1.5)))),
  ];
}

/**
 * A centrifugal pump: the round casing (`fill`) with a tangential outlet
 * nozzle to the right at the top, a flange, a base, and the impeller (six
 * backward-curved vanes) in the `rotor`.
 */
function pump(w: number, h: number): SVGElement[] {
  const R = Math.max(4, Math.min(w * 0.38, h * 0.37));
  const [cx, cy] = [Math.max(R + 2, w * 0.42), h * 0.45];
  const noz = R * 0.42;
  const vane = (deg: number) =>
    s('path', { d: d('M', R * 0.16, 0, 'C', R * 0.4, 0, R * 0.58, R * 0.12, R * 0.64, R * 0.36), transform: `rotate(${deg})`, fill: 'none', ...stroke(1.5), 'stroke-linecap': 'round' });
  return [
    s('polygon', { points: pts([cx - R * 0.5, cy + R * 0.6], [cx + R * 0.5, cy + R * 0.6], [cx + R * 0.85, h - 1], [cx - R * 0.85, h - 1]), fill: GREY, ...stroke(1.5), 'stroke-linejoin': 'round' }),
    rect(cx, cy - R, w - 1 - cx, noz, face()),
    rect(w - Math.max(3, w * 0.04) - 1, cy - R - noz * 0.2, Math.max(3, w * 0.04), noz * 1.4, { fill: DARK }),
    circle(cx, cy, R, face({ 'data-part': 'fill' })),
    at(cx, cy, rotor(...[0, 60, 120, 180, 240, 300].map(vane), circle(0, 0, R * 0.14, { fill: DARK }))),
  ];
}

// ——— process equipment ———

/** A tank with dished heads, or (`style: 'silo'`) a silo: conical roof and bottom, outlet and legs; `level` clipped to the vessel. */
function tank(e: Element): SVGElement[] {
  const { w, h } = e;
  const ticks = quarterTicks(w - 1, 0, h, Math.min(w * 0.12, 8));
  if (e.props?.style === 'silo') {
    const [rh, yc, yo, ow] = [Math.min(h * 0.1, w * 0.25), h * 0.6, h * 0.86, w * 0.18];
    const shape = d('M', 1, rh, 'L', w / 2, 1, 'L', w - 1, rh, 'L', w - 1, yc, 'L', w / 2 + ow / 2, yo, 'L', w / 2 - ow / 2, yo, 'L', 1, yc, 'Z');
    return [
      line(w * 0.1, yc, w * 0.1, h, stroke(2.5)),
      line(w * 0.9, yc, w * 0.9, h, stroke(2.5)),
      line(w * 0.1, yc + (h - yc) * 0.55, w * 0.9, yc + (h - yc) * 0.55, stroke(1)),
      rect(w / 2 - ow * 0.35, yo, ow * 0.7, h * 0.07, { fill: GREY, ...stroke(1) }),
      ...vessel(e, shape, 'silo'),
      line(1, rh, w - 1, rh, stroke(1, GREY)),
      ...quarterTicks(w - 1, rh, yc, Math.min(w * 0.12, 8)),
    ];
  }
  if (e.props?.style === 'horizontal') {
    // a lying tank on two saddles: elliptical heads left and right
    const hd = Math.max(2, Math.min(w * 0.08, h * 0.2));
    const [y0, y1] = [1, h * 0.82];
    const ry = (y1 - y0) / 2;
    const shape = d('M', hd, y0, 'L', w - hd, y0, 'A', hd - 1, ry, 0, 0, 1, w - hd, y1, 'L', hd, y1, 'A', hd - 1, ry, 0, 0, 1, hd, y0, 'Z');
    return [
      s('polygon', { points: pts([w * 0.2, y1 - 2], [w * 0.28, h], [w * 0.12, h]), fill: GREY, ...stroke(1) }),
      s('polygon', { points: pts([w * 0.8, y1 - 2], [w * 0.88, h], [w * 0.72, h]), fill: GREY, ...stroke(1) }),
      ...vessel({ ...e, h: y1 }, shape, 'htank'),
      line(hd, y0, hd, y1, stroke(1, GREY)),
      line(w - hd, y0, w - hd, y1, stroke(1, GREY)),
    ];
  }
  const hd = Math.max(2, Math.min(h * 0.08, w * 0.15));
  const rx = w / 2 - 1;
  const shape = d('M', 1, hd, 'A', rx, hd - 1, 0, 0, 1, w - 1, hd, 'L', w - 1, h - hd, 'A', rx, hd - 1, 0, 0, 1, 1, h - hd, 'Z');
  return [
    ...vessel(e, shape, 'tank'),
    line(1, hd, w - 1, hd, stroke(1, GREY)),
    line(1, h - hd, w - 1, h - hd, stroke(1, GREY)),
    ...ticks,
  ];
}

/** A bottle: cap, neck, shoulders and a body with rounded bottom corners; `level` clipped to it. */
function bottle(e: Element): SVGElement[] {
  const { w, h } = e;
  const [cx, nw, r] = [w / 2, Math.max(2, w * 0.17), Math.min(w * 0.12, h * 0.05)];
  const shape = d(
    'M', cx - nw, h * 0.1, 'L', cx - nw, h * 0.2,
    'C', cx - nw, h * 0.3, 1, h * 0.28, 1, h * 0.42,
    'L', 1, h - 1 - r, 'Q', 1, h - 1, 1 + r, h - 1,
    'L', w - 1 - r, h - 1, 'Q', w - 1, h - 1, w - 1, h - 1 - r,
    'L', w - 1, h * 0.42,
    'C', w - 1, h * 0.28, cx + nw, h * 0.3, cx + nw, h * 0.2,
    'L', cx + nw, h * 0.1, 'Z',
  );
  return [
    ...vessel(e, shape, 'bottle'),
    rect(cx - nw - 1.5, h * 0.02, nw * 2 + 3, h * 0.08, { rx: 1.5, fill: GREY, ...stroke(1), 'data-part': 'cap' }),
  ];
}

/** A horizontal pipe (`fill`) with a flange at each end. */
/**
 * A pipe: straight across its box, or an elbow (left to bottom), a tee (left,
 * right and bottom) or a cross, turned by the element's rotation to 0, 90,
 * 180 or 270°.
 */
function pipe(w: number, h: number, shape: string): SVGElement[] {
  const fh = Math.min(18, h);
  const fw = Math.min(4, w / 8);
  if (shape === 'straight' || !['elbow', 'tee', 'cross'].includes(shape)) {
    return [
      s('rect', { y: n(h / 2 - 6), width: w, height: 12, fill: GREY, 'data-part': 'fill' }),
      line(0, h / 2 - 6, w, h / 2 - 6, stroke(1)),
      line(0, h / 2 + 6, w, h / 2 + 6, stroke(1)),
      rect(0, h / 2 - fh / 2, fw, fh, { fill: DARK }),
      rect(w - fw, h / 2 - fh / 2, fw, fh, { fill: DARK }),
    ];
  }
  const [cx, cy, t] = [w / 2, h / 2, 6];
  const arms: [number, number, number, number][] = [[0, cy - t, cx + t, 2 * t]]; // left
  if (shape !== 'elbow') arms.push([cx - t, cy - t, w - cx + t, 2 * t]); // right
  arms.push([cx - t, cy - t, 2 * t, h - cy + t]); // bottom
  if (shape === 'cross') arms.push([cx - t, 0, 2 * t, cy + t]); // top
  const flanges: SVGElement[] = [rect(0, cy - fh / 2, fw, fh, { fill: DARK }), rect(cx - fh / 2, h - fw, fh, fw, { fill: DARK })];
  if (shape !== 'elbow') flanges.push(rect(w - fw, cy - fh / 2, fw, fh, { fill: DARK }));
  if (shape === 'cross') flanges.push(rect(cx - fh / 2, 0, fh, fw, { fill: DARK }));
  return [
    s('g', { 'data-part': 'fill', fill: GREY }, arms.map(([x, y, aw, ah]) => rect(x, y, aw, ah, { ...stroke(1), fill: 'inherit' }))),
    // the joint drawn over the arms' inner edges
    rect(cx - t + 0.75, cy - t + 0.75, 2 * t - 1.5, 2 * t - 1.5, { fill: GREY, 'data-part': 'fill2' }),
    ...flanges,
  ];
}
/** A valve: gate (a bonnet and handwheel), ball (a ball between the seats) or butterfly (a disc across a round body). */
function valve(w: number, h: number, style: string): SVGElement[] {
  const [yt, yb] = [h * 0.4, h - 1];
  const cy = (yt + yb) / 2;
  const ya = h * 0.22;
  if (style === 'butterfly') {
    const R = Math.min(w / 2, (yb - yt) / 2 + h * 0.1) - 1;
    return [
      line(w / 2, cy - R, w / 2, ya, stroke(2)),
      rect(w * 0.3, ya - h * 0.05, w * 0.4, h * 0.1, face({ rx: 2 })),
      line(1, cy, w / 2 - R, cy, stroke(3)),
      line(w / 2 + R, cy, w - 1, cy, stroke(3)),
      circle(w / 2, cy, R, face({ 'data-part': 'fill' })),
      line(w / 2 - R * 0.55, cy + R * 0.55, w / 2 + R * 0.55, cy - R * 0.55, { ...stroke(3), 'stroke-linecap': 'round', 'data-part': 'fill2' }),
    ];
  }
  const body = [
    s('polygon', face({ points: pts([1, yt], [w / 2, cy], [1, yb]), 'stroke-linejoin': 'round', 'data-part': 'fill' })),
    s('polygon', face({ points: pts([w - 1, yt], [w / 2, cy], [w - 1, yb]), 'stroke-linejoin': 'round', 'data-part': 'fill2' })),
  ];
  if (style === 'ball') {
    return [line(w / 2, cy, w / 2, ya, stroke(2)), rect(w * 0.35, ya - 2, w * 0.3, 4, { fill: DARK }), ...body, circle(w / 2, cy, Math.min(w, yb - yt) * 0.22, { fill: '#fff', ...stroke(1.5) })];
  }
  return [
    line(w / 2, cy, w / 2, ya, stroke(2)),
    s('path', { d: d('M', w * 0.2, ya, 'A', w * 0.3, h * 0.2, 0, 0, 1, w * 0.8, ya, 'Z'), ...face(), 'stroke-linejoin': 'round' }),
    ...body,
  ];
}
function coolingTower(w: number, h: number, m: number): SVGElement[] {
  const [yt, yb] = [h * 0.24, h * 0.9];
  const shell = d(
    'M', w * 0.1, yb, 'C', w * 0.3, h * 0.68, w * 0.3, h * 0.45, w * 0.25, yt,
    'L', w * 0.75, yt, 'C', w * 0.7, h * 0.45, w * 0.7, h * 0.68, w * 0.9, yb, 'Z',
  );
  const legs = Array.from({ length: 9 }, (_, i): [number, number] => [w * (0.1 + (0.8 * i) / 8), i % 2 ? h - 1 : yb]);
  const puff = (x: number, y: number, r: number) => circle(w * x, h * y, m * r, { fill: '#fff', ...stroke(1, GREY) });
  return [
    puff(0.42, 0.14, 0.08), puff(0.56, 0.1, 0.09), puff(0.68, 0.15, 0.065),
    s('polyline', { points: pts(...legs), fill: 'none', ...stroke(1.5), 'stroke-linejoin': 'round' }),
    line(w * 0.04, h - 1, w * 0.96, h - 1, stroke(2)),
    s('path', { d: shell, ...face(), 'stroke-linejoin': 'round', 'data-part': 'fill' }),
    s('ellipse', { cx: n(w / 2), cy: n(yt), rx: n(w * 0.25), ry: n(Math.max(1.5, h * 0.025)), fill: GREY, ...stroke(1) }),
  ];
}

// ——— plant and site ———

/** A PLC rack: power supply, CPU with RUN (`fill`) and ERR lamps, three I/O modules with channel lamps and terminals. */
function plc(w: number, h: number): SVGElement[] {
  const [y0, y1] = [h * 0.16, h * 0.84];
  const units = [1.2, 1.2, 1, 1, 1];
  const gap = w * 0.015;
  const inner = w * 0.92 - gap * (units.length - 1);
  const unit = inner / units.reduce((a, b) => a + b, 0);
  const r = Math.max(1, Math.min(unit * 0.1, h * 0.03));
  const lamp = (x: number, y: number, attrs: Attrs = {}) => circle(x, y, r, { fill: GREY, ...stroke(0.75), ...attrs });
  const out: SVGElement[] = [rect(1, h * 0.1, w - 2, h * 0.8, { rx: 2, fill: GREY, ...stroke(1.5) })];
  let x = w * 0.04;
  units.forEach((u, i) => {
    const mw = unit * u;
    const cx = x + mw / 2;
    out.push(rect(x, y0, mw, y1 - y0, face({ 'stroke-width': 1, rx: 1 })));
    if (i === 0) {
      // power supply: one lamp and a switch
      out.push(lamp(cx, y0 + h * 0.08), rect(cx - mw * 0.2, y0 + h * 0.2, mw * 0.4, h * 0.12, { fill: DARK }));
    } else if (i === 1) {
      // CPU: RUN and ERR lamps, a port
      out.push(lamp(cx - mw * 0.2, y0 + h * 0.08, { 'data-part': 'fill', class: 'hmi-run-lamp' }), lamp(cx + mw * 0.2, y0 + h * 0.08));
      out.push(rect(cx - mw * 0.25, y0 + h * 0.24, mw * 0.5, h * 0.1, { fill: '#fff', ...stroke(1) }));
    } else {
      // I/O: four channel lamps and a terminal block
      for (let k = 0; k < 4; k++) out.push(lamp(cx, y0 + h * (0.07 + k * 0.065), { class: `hmi-io-lamp hmi-io-lamp-${(i + k) % 3}` }));
      out.push(rect(x + mw * 0.15, y0 + (y1 - y0) * 0.55, mw * 0.7, (y1 - y0) * 0.38, { fill: DARK }));
    }
    x += mw + gap;
  });
  return out;
}

/** A building: walls (`fill`), a gable roof, windows and a door. */
function building(w: number, h: number): SVGElement[] {
  const win = (x: number, y: number) => rect(w * x, h * y, w * 0.14, h * 0.13, { fill: '#fff', ...stroke(1), 'data-part': 'window' });
  return [
    rect(w * 0.1, h * 0.38, w * 0.8, h * 0.62 - 1, face({ 'data-part': 'fill' })),
    s('polygon', { points: pts([w * 0.03, h * 0.4], [w * 0.5, h * 0.06], [w * 0.97, h * 0.4]), fill: GREY, ...stroke(1.5), 'stroke-linejoin': 'round' }),
    win(0.18, 0.48), win(0.43, 0.48), win(0.68, 0.48), win(0.18, 0.72), win(0.68, 0.72),
    rect(w * 0.42, h * 0.72, w * 0.16, h * 0.28 - 1, { fill: DARK }),
  ];
}

/**
 * A lattice transmission tower: legs, cross-arms and peak as bars in the
 * outline group (`fill`, dark), light bracing between the legs, insulators
 * hanging from the arms.
 */
function transmissionTower(w: number, h: number, m: number): SVGElement[] {
  const cx = w / 2;
  const t = Math.max(1.5, m * 0.025);
  // the left leg, top to bottom: (x, y) corners; the right one mirrors it
  const leg: [number, number][] = [[cx - w * 0.05, h * 0.08], [cx - w * 0.08, h * 0.44], [w * 0.16, h - 1]];
  const legX = (y: number) => {
    const [a, b] = y <= leg[1][1] ? [leg[0], leg[1]] : [leg[1], leg[2]];
    return a[0] + ((b[0] - a[0]) * (y - a[1])) / (b[1] - a[1]);
  };
  const mirror = (x: number) => w - x;
  const outline: SVGElement[] = [];
  for (let i = 0; i < leg.length - 1; i++) {
    outline.push(bar(leg[i][0], leg[i][1], leg[i + 1][0], leg[i + 1][1], t));
    outline.push(bar(mirror(leg[i][0]), leg[i][1], mirror(leg[i + 1][0]), leg[i + 1][1], t));
  }
  outline.push(bar(cx, h * 0.01, leg[0][0], leg[0][1], t), bar(cx, h * 0.01, mirror(leg[0][0]), leg[0][1], t));
  // cross-arms: a bottom chord at y reaching out to x, and a tie up to the leg at y - rise
  const arms: [number, number][] = [[h * 0.2, w * 0.14], [h * 0.36, w * 0.04]];
  const insulators: SVGElement[] = [];
  for (const [y, xo] of arms) {
    outline.push(bar(xo, y, mirror(xo), y, t));
    outline.push(bar(xo, y, legX(y - h * 0.06), y - h * 0.06, t * 0.7), bar(mirror(xo), y, mirror(legX(y - h * 0.06)), y - h * 0.06, t * 0.7));
    for (const x of [xo + t, mirror(xo) - t]) {
      insulators.push(line(x, y, x, y + h * 0.07, stroke(1.5, INK)), circle(x, y + h * 0.075, Math.max(1, m * 0.015), { fill: INK }));
    }
  }
  // bracing: horizontal struts and X-diagonals between levels
  const levels = [0.08, 0.2, 0.3, 0.36, 0.44, 0.58, 0.74, 1].map((f) => Math.min(h - 1, h * f));
  const brace: SVGElement[] = [];
  levels.forEach((y, i) => {
    brace.push(line(legX(y), y, mirror(legX(y)), y, stroke(0.75)));
    if (i > 0) {
      const yp = levels[i - 1];
      brace.push(line(legX(yp), yp, mirror(legX(y)), y, stroke(0.75)), line(mirror(legX(yp)), yp, legX(y), y, stroke(0.75)));
    }
  });
  return [s('g', { fill: 'none' }, brace), s('g', { fill: DARK, 'data-part': 'fill' }, outline), ...insulators];
}
