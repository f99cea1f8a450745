// Draws a SCADA screen (hmi/<name>.json, docs/file-formats.md "Screens") as
// SVG and animates it from live values (issue 17). Symbols follow ISA-101:
// greys for equipment, colour only for state. Each element is a group in its
// own box (0,0)–(w,h), translated and rotated into place; animations change
// attributes of that group or of its parts marked `data-part`, and only when
// the value that drives them changes.
import { fmt, s } from '../dom';
import type { Json } from '../types';

export interface Animation {
  kind: string;
  tag: string;
  [param: string]: Json | undefined;
}

export interface Element {
  id: string;
  type: string;
  x: number;
  y: number;
  w: number;
  h: number;
  rotation?: number;
  props?: Record<string, Json>;
  animations?: Animation[];
  action?: { kind: string; tag?: string | null; value?: Json; min?: number | null; max?: number | null; screen?: string | null } | null;
}

export interface Screen {
  schema: number;
  title?: string;
  width: number;
  height: number;
  background?: string | null;
  elements: Element[];
}

const GREY = '#9ea3a8';
const DARK = '#5f6368';
const LIGHT = '#e4e6e8';
const ON = '#2e7d32';

/** The symbol of an element type, in its box: the parts animations reach are marked `data-part`. */
export function symbol(e: Element): SVGElement[] {
  const { w, h } = e;
  const p = e.props ?? {};
  const label = typeof p.label === 'string' ? p.label : '';
  const stroke = { stroke: DARK, 'stroke-width': 1.5 };
  const body = (attrs: Record<string, unknown>) => ({ fill: LIGHT, ...stroke, ...attrs });
  const text = (t: string, y = h / 2, size = 13) =>
    s('text', { x: w / 2, y, 'text-anchor': 'middle', 'dominant-baseline': 'middle', 'font-size': size, fill: '#202124', 'data-part': 'text' }, t);
  switch (e.type) {
    case 'text':
      return [text(label || String(p.text ?? ''), h / 2, Number(p.size ?? 14))];
    case 'output':
    case 'input':
      return [s('rect', body({ width: w, height: h, rx: 3, fill: '#fff' })), text('…')];
    case 'rectangle':
      return [s('rect', body({ width: w, height: h, 'data-part': 'fill' }))];
    case 'circle':
      return [s('ellipse', body({ cx: w / 2, cy: h / 2, rx: w / 2, ry: h / 2, 'data-part': 'fill' }))];
    case 'line':
      return [s('line', { x1: 0, y1: h / 2, x2: w, y2: h / 2, ...stroke, 'stroke-width': 3, 'data-part': 'fill' })];
    case 'polygon':
      return [s('polygon', body({ points: `${w / 2},0 ${w},${h} 0,${h}`, 'data-part': 'fill' }))];
    case 'arc':
      return [s('path', { d: `M 0 ${h} A ${w / 2} ${h} 0 0 1 ${w} ${h}`, fill: 'none', ...stroke, 'stroke-width': 3, 'data-part': 'fill' })];
    case 'button':
    case 'switch':
      return [s('rect', body({ width: w, height: h, rx: 6, fill: '#f1f3f4', 'data-part': 'fill' })), text(label || e.type)];
    case 'slider':
      return [
        s('rect', body({ y: h / 2 - 3, width: w, height: 6, rx: 3 })),
        s('circle', { cx: 0, cy: h / 2, r: Math.min(10, h / 2), fill: DARK, 'data-part': 'knob' }),
      ];
    case 'led':
    case 'alarm':
      return [s('circle', { cx: w / 2, cy: h / 2, r: Math.min(w, h) / 2 - 1, fill: GREY, ...stroke, 'data-part': 'fill' })];
    case 'tank':
    case 'bottle': {
      const r = Math.min(w / 2, h / 8);
      return [
        s('rect', { width: w, height: h, rx: r, fill: '#fff', ...stroke }),
        s('rect', { x: 2, y: h - 2, width: w - 4, height: 0, fill: '#4a90c2', 'data-part': 'level' }),
        s('rect', { width: w, height: h, rx: r, fill: 'none', ...stroke }),
        text(label, h + 14, 12),
      ];
    }
    case 'pump':
    case 'motor':
    case 'fan':
    case 'wind_turbine': {
      const r = Math.min(w, h) / 2 - 2;
      const blades = [0, 120, 240].map((a) =>
        s('path', { d: `M 0 0 L ${r * 0.9} -${r * 0.18} L ${r * 0.9} ${r * 0.18} Z`, fill: DARK, transform: `rotate(${a})` }),
      );
      return [
        s('circle', { cx: w / 2, cy: h / 2, r, fill: LIGHT, ...stroke, 'data-part': 'fill' }),
        s('g', { transform: `translate(${w / 2},${h / 2})` }, s('g', { 'data-part': 'rotor' }, blades)),
        text(label, h + 14, 12),
      ];
    }
    case 'pipe':
      return [s('rect', { y: h / 2 - 6, width: w, height: 12, fill: GREY, 'data-part': 'fill' })];
    case 'valve':
      return [
        s('polygon', body({ points: `0,0 ${w / 2},${h / 2} 0,${h}`, 'data-part': 'fill' })),
        s('polygon', body({ points: `${w},0 ${w / 2},${h / 2} ${w},${h}`, 'data-part': 'fill2' })),
      ];
    case 'meter':
      return [
        s('rect', body({ width: w, height: h, fill: '#fff' })),
        s('rect', { x: 2, y: h - 2, width: w - 4, height: 0, fill: '#4a90c2', 'data-part': 'level' }),
        text('…', -8, 12),
      ];
    case 'clock':
      return [s('circle', body({ cx: w / 2, cy: h / 2, r: Math.min(w, h) / 2 - 1 })), text(new Date().toLocaleTimeString(), h / 2, 11)];
    case 'image':
      return typeof p.src === 'string' ? [s('image', { href: p.src, width: w, height: h })] : [s('rect', body({ width: w, height: h }))];
    default:
      // equipment drawn as a labelled box: cooling tower, PLC, building, transmission tower, safety sign, trend …
      return [s('rect', body({ width: w, height: h, rx: 4, 'data-part': 'fill' })), text(label || e.type.replace(/_/g, ' '), h / 2, 11)];
  }
}

/** The tags a screen shows or writes: what its view subscribes to, and nothing else. */
export function tagsOf(screen: Screen): string[] {
  const names = new Set<string>();
  for (const e of screen.elements) {
    for (const a of e.animations ?? []) names.add(a.tag);
    if (typeof e.props?.tag === 'string') names.add(e.props.tag);
    if (e.action?.tag) names.add(e.action.tag);
  }
  return [...names];
}

const num = (v: Json | undefined): number | null => (typeof v === 'number' ? v : typeof v === 'boolean' ? (v ? 1 : 0) : null);
const frac = (v: number, a: Animation) => {
  const lo = num(a.min) ?? 0;
  const hi = num(a.max) ?? 1;
  return Math.max(0, Math.min(1, (v - lo) / (hi - lo || 1)));
};

/** The colour of a value: on/off for a BOOL, the last interval reached for a number. */
export function colorOf(a: Animation, v: Json): string | null {
  if (Array.isArray(a.intervals)) {
    const x = num(v);
    let c: string | null = null;
    for (const i of a.intervals as { from: number; color: string }[]) if (x !== null && x >= i.from) c = i.color;
    return c;
  }
  return num(v) ? (typeof a.on === 'string' ? a.on : ON) : typeof a.off === 'string' ? a.off : GREY;
}

/**
 * Applies one animation of the element group `g` (box `e`) for value `v`.
 * Pure DOM writes on attributes; `blink` and `rotate` with `speed` are
 * driven by CSS classes, so a running pump turns without a frame loop.
 */
export function animate(g: SVGGElement, e: Element, a: Animation, v: Json): void {
  const part = (name: string) => g.querySelector(`[data-part="${name}"]`);
  const on = !!num(v);
  switch (a.kind) {
    case 'visibility':
      g.style.display = on === (a.when !== false) ? '' : 'none';
      break;
    case 'blink':
      g.classList.toggle('hmi-blink', on === (a.when !== false));
      break;
    case 'color': {
      const c = colorOf(a, v);
      if (c) g.querySelectorAll('[data-part="fill"], [data-part="fill2"]').forEach((p) => p.setAttribute('fill', c));
      break;
    }
    case 'fill': {
      const level = part('level') ?? part('fill');
      if (!level || num(v) === null) break;
      const f = frac(num(v) as number, a);
      const dir = a.direction ?? 'up';
      if (dir === 'up' || dir === 'down') {
        const h = (e.h - 4) * f;
        level.setAttribute('height', String(h));
        level.setAttribute('y', String(dir === 'up' ? e.h - 2 - h : 2));
      } else {
        const w = (e.w - 4) * f;
        level.setAttribute('width', String(w));
        level.setAttribute('x', String(dir === 'right' ? 2 : e.w - 2 - w));
      }
      if (typeof a.color === 'string') level.setAttribute('fill', a.color);
      break;
    }
    case 'move': {
      const x = num(v);
      if (x === null) break;
      const f = frac(x, a);
      g.dataset.move = `${(num(a.dx) ?? 0) * f},${(num(a.dy) ?? 0) * f}`;
      place(g, e);
      break;
    }
    case 'rotate': {
      const rotor = part('rotor') ?? g;
      if (a.speed !== undefined) {
        // turning while the value is on
        rotor.classList.toggle('hmi-spin', on);
      } else {
        const x = num(v);
        if (x !== null) rotor.setAttribute('transform', `rotate(${frac(x, a) * (num(a.degrees) ?? 360)})`);
      }
      break;
    }
  }
}

/** Puts the group at the element's place (and its `move` offset). */
export function place(g: SVGGElement, e: Element): void {
  const [dx, dy] = (g.dataset.move ?? '0,0').split(',').map(Number);
  g.setAttribute('transform', `translate(${e.x + dx},${e.y + dy}) rotate(${e.rotation ?? 0} ${e.w / 2} ${e.h / 2})`);
}

/** A text or output box's shown value. */
export function showValue(g: SVGGElement, v: Json): void {
  const t = g.querySelector('[data-part="text"]');
  if (t && t.textContent !== fmt(v)) t.textContent = fmt(v);
}

/** The element's group, drawn at its place, with its symbol. */
export function drawElement(e: Element): SVGGElement {
  const g = s('g', { class: `hmi-el hmi-${e.type}`, 'data-testid': `hmi-el-${e.id}`, 'data-type': e.type });
  g.append(...symbol(e));
  place(g, e);
  return g;
}
