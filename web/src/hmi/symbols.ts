// The symbols of screen elements (issue 17, item 3): each of the 30 element
// types as a parameterised SVG drawing in its own box (0,0)–(w,h), after
// ISA-101: greys for equipment, colour only for state. The parts animations
// reach are marked `data-part` (fill, fill2, level, rotor, knob, text).
import { s } from '../dom';
import type { Element } from './render';

export const GREY = '#9ea3a8';
export const DARK = '#5f6368';
export const LIGHT = '#e4e6e8';
export const ON = '#2e7d32';

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

