// The designer's animation forms and previews (issue 35, points 2 and 3).
// Each parameter gets the field its kind asks for, from the API's domain
// (`screens.animations`, made from `alba_project::hmi::ANIMATIONS`): a number
// with its unit and range, yes/no, a colour picker, a choice, or up to four
// colour intervals. A field left empty removes the parameter (its default).
// The move and rotate previews draw, in the element's own box, where a move
// ends and the path a rotation follows about its anchor (AuroraLD's
// "previsualización", `000_…` §3.22.3–4).
import type { ParamInfo } from '../api.gen';
import { h, s } from '../dom';
import { domain } from '../domain';
import { tr } from '../i18n';
import type { Json } from '../types';
import type { Animation, Element } from './render';

/** The parameters of an animation `kind`, as the domain lists them. */
export function paramsOf(kind: string): ParamInfo[] {
  return domain().screens.animations.find((a) => a.kind === kind)?.params ?? [];
}

/** The own properties of an element `type`, as the domain lists them. */
export function propsOf(type: string): ParamInfo[] {
  return domain().screens.properties.find((a) => a.kind === type)?.params ?? [];
}

const finite = (x: number | null) => (x !== null && Math.abs(x) < 1e12 ? x : undefined);

/**
 * The form of one animation's parameters: `set(name, value)` with `undefined`
 * to remove one. Legacy parameters are shown only when the file has them.
 */
export function animationForm(a: Animation, testid: string, set: (name: string, v: Json | undefined) => void): HTMLElement {
  return paramForm(paramsOf(a.kind), a, testid, set);
}

/** The form of `params` for the values `values` (an animation, or an element's props). */
export function paramForm(params: ParamInfo[], values: Record<string, Json | undefined>, testid: string, set: (name: string, v: Json | undefined) => void): HTMLElement {
  const rows = params
    .filter((p) => !p.legacy || values[p.name] !== undefined)
    .map((p) => {
      const id = `${testid}-${p.name}`;
      const label = p.unit ? `${p.name} (${p.unit})` : p.name;
      return h('label', { title: p.help, class: `hmi-param hmi-param-${p.kind}` }, h('span', null, label), field(p, values[p.name], id, (v) => set(p.name, v)));
    });
  return h('div', { class: 'hmi-params', 'data-testid': testid }, rows);
}

/** Points as the form writes them: `x,y` pairs separated by spaces (SVG's own notation). */
export function parsePoints(text: string): [number, number][] | null {
  const pairs = text.trim().split(/\s+/).filter(Boolean);
  const out: [number, number][] = [];
  for (const p of pairs) {
    const xy = p.split(',').map(Number);
    if (xy.length !== 2 || !xy.every(Number.isFinite)) return null;
    out.push([xy[0], xy[1]]);
  }
  return out;
}

function field(p: ParamInfo, v: Json | undefined, id: string, set: (v: Json | undefined) => void): HTMLElement {
  switch (p.kind) {
    case 'number': {
      const input = h('input', { type: 'number', step: 'any', min: finite(p.min), max: finite(p.max), value: typeof v === 'number' ? v : '', placeholder: tr('default'), 'data-testid': id });
      input.addEventListener('change', () => {
        const x = input.valueAsNumber;
        if (input.value === '') set(undefined);
        else if (Number.isFinite(x)) set(x);
      });
      return input;
    }
    case 'bool': {
      const sel = h('select', { 'data-testid': id },
        h('option', { value: '', selected: v === undefined }, tr('default')),
        h('option', { value: 'true', selected: v === true }, tr('yes')),
        h('option', { value: 'false', selected: v === false }, tr('no')));
      sel.onchange = () => set(sel.value === '' ? undefined : sel.value === 'true');
      return sel;
    }
    case 'choice': {
      const sel = h('select', { 'data-testid': id }, h('option', { value: '', selected: v === undefined }, tr('default')), p.choices.map((c) => h('option', { value: c, selected: v === c }, c)));
      sel.onchange = () => set(sel.value || undefined);
      return sel;
    }
    case 'color':
      return colorField(typeof v === 'string' ? v : undefined, id, set);
    case 'intervals':
      return intervalsField(Array.isArray(v) ? (v as { from: number; color: string }[]) : [], id, set);
    case 'text':
    case 'tag': {
      const attrs = p.kind === 'tag' ? { list: 'hmi-tags', placeholder: tr('Search tags…'), autocomplete: 'off' } : { maxlength: finite(p.max) };
      const input = h('input', { value: typeof v === 'string' ? v : '', 'data-testid': id, ...attrs });
      input.addEventListener('change', () => set(input.value === '' ? undefined : input.value));
      return input;
    }
    case 'points': {
      const shown = Array.isArray(v) ? (v as number[][]).map((xy) => xy.join(',')).join(' ') : '';
      const area = h('textarea', { rows: 2, 'data-testid': id, placeholder: '0,0 40,10 20,40' }, shown);
      area.addEventListener('change', () => {
        const pts = parsePoints(area.value);
        area.classList.toggle('invalid', pts === null);
        if (pts) set(pts.length ? pts : undefined);
      });
      return area;
    }
    case 'pens': {
      // a trend's pens: one "tag colour" per line, at most `max` (the colour may be left out)
      const shown = Array.isArray(v) ? (v as { tag?: string; color?: string }[]).map((p) => [p.tag ?? '', p.color ?? ''].join(' ').trim()).join('\n') : '';
      const area = h('textarea', { rows: 3, 'data-testid': id, placeholder: tr('a tag and its colour, one pen a line') }, shown);
      area.addEventListener('change', () => {
        const pens = parsePens(area.value, finite(p.max) ?? 3);
        area.classList.toggle('invalid', pens === null);
        if (pens) set(pens.length ? pens : undefined);
      });
      return area;
    }
  }
}

/** A trend's pens from "tag colour" lines; null when there are more than `max`. */
export function parsePens(text: string, max: number): { tag: string; color?: string }[] | null {
  const pens = text
    .split(/\n/)
    .map((line) => line.trim().split(/\s+/))
    .filter(([tag]) => tag)
    .map(([tag, color]) => (color ? { tag, color } : { tag }));
  return pens.length <= max ? pens : null;
}

/** A colour: a swatch that opens the browser's picker and the text (a name or #rgb), either sets it; empty removes it. */
function colorField(v: string | undefined, id: string, set: (v: Json | undefined) => void): HTMLElement {
  const hex = v && /^#[0-9a-f]{6}$/i.test(v) ? v : '#9ea3a8';
  const swatch = h('input', { type: 'color', value: hex, 'data-testid': `${id}-swatch`, title: tr('Choose a colour') });
  const text = h('input', { value: v ?? '', placeholder: tr('default'), 'data-testid': id, size: 8 });
  swatch.addEventListener('change', () => set(swatch.value));
  text.addEventListener('change', () => set(text.value.trim() || undefined));
  return h('span', { class: 'hmi-color' }, swatch, text);
}

/** Up to four intervals, each a colour from its value up. */
function intervalsField(list: { from: number; color: string }[], id: string, set: (v: Json | undefined) => void): HTMLElement {
  const put = (next: { from: number; color: string }[]) => set(next.length ? next : undefined);
  const rows = list.map((iv, n) => {
    const from = h('input', { type: 'number', step: 'any', value: iv.from, 'data-testid': `${id}-${n}-from`, title: tr('from this value up') });
    from.addEventListener('change', () => Number.isFinite(from.valueAsNumber) && put(list.map((x, k) => (k === n ? { ...x, from: from.valueAsNumber } : x))));
    const colour = colorField(iv.color, `${id}-${n}-color`, (c) => put(list.map((x, k) => (k === n ? { ...x, color: typeof c === 'string' ? c : '#9ea3a8' } : x))));
    const remove = h('button', { type: 'button', class: 'small', 'data-testid': `${id}-${n}-remove`, title: tr('Remove this interval') }, '✕');
    remove.onclick = () => put(list.filter((_, k) => k !== n));
    return h('div', { class: 'hmi-interval' }, from, colour, remove);
  });
  const more = h('button', { type: 'button', class: 'small', 'data-testid': `${id}-add`, disabled: list.length >= 4 }, `+ ${tr('interval')}`);
  more.onclick = () => put([...list, { from: list.length ? list[list.length - 1].from + 10 : 0, color: '#9ea3a8' }]);
  return h('div', { class: 'hmi-intervals' }, rows, more);
}

const num = (v: Json | undefined): number | null => (typeof v === 'number' ? v : null);
const n2 = (x: number) => +x.toFixed(2);

/**
 * The preview of an element's `move` and `rotate` animations in its own box
 * (the caller places it like the element): a dashed ghost where a move ends
 * and a line to it; for a rotation of the whole element (`turnsWhole`: an
 * anchor is set, or the element has no rotor or needle), the anchor, the arc
 * its centre follows from `from` to `degrees` (a circle for a spin) and a
 * ghost at the end angle.
 */
export function animationPreview(e: Element, turnsWhole: boolean): SVGGElement | null {
  const g = s('g', { class: 'hmi-preview', 'data-testid': `hmi-preview-${e.id}` });
  const [cx, cy] = [e.w / 2, e.h / 2];
  for (const a of e.animations ?? []) {
    if (a.kind === 'move') {
      const [dx, dy] = [num(a.dx) ?? 0, num(a.dy) ?? 0];
      if (dx === 0 && dy === 0) continue;
      g.append(
        s('line', { x1: cx, y1: cy, x2: cx + dx, y2: cy + dy, 'data-part': 'move-path' }),
        s('rect', { x: dx, y: dy, width: e.w, height: e.h, 'data-part': 'move-ghost' }),
      );
    } else if (a.kind === 'rotate') {
      const anchored = num(a.cx) !== null || num(a.cy) !== null;
      if (!anchored && !turnsWhole) continue;
      const [ax, ay] = [num(a.cx) ?? cx, num(a.cy) ?? cy];
      const spin = a.speed !== undefined;
      const from = spin ? 0 : num(a.from) ?? 0;
      const to = spin ? 360 : num(a.degrees) ?? 360;
      const r = Math.hypot(cx - ax, cy - ay);
      const at = (deg: number) => {
        const t = (deg * Math.PI) / 180;
        return [ax + (cx - ax) * Math.cos(t) - (cy - ay) * Math.sin(t), ay + (cx - ax) * Math.sin(t) + (cy - ay) * Math.cos(t)];
      };
      g.append(s('path', { d: `M ${ax - 5} ${ay} H ${ax + 5} M ${ax} ${ay - 5} V ${ay + 5}`, 'data-part': 'anchor' }));
      if (r > 0.5) {
        if (Math.abs(to - from) >= 360) g.append(s('circle', { cx: ax, cy: ay, r: n2(r), 'data-part': 'rotate-path' }));
        else {
          const [x0, y0] = at(from);
          const [x1, y1] = at(to);
          const large = Math.abs(to - from) > 180 ? 1 : 0;
          g.append(s('path', { d: `M ${n2(x0)} ${n2(y0)} A ${n2(r)} ${n2(r)} 0 ${large} ${to > from ? 1 : 0} ${n2(x1)} ${n2(y1)}`, 'data-part': 'rotate-path' }));
        }
      }
      if (!spin) g.append(s('rect', { x: 0, y: 0, width: e.w, height: e.h, transform: `rotate(${to} ${ax} ${ay})`, 'data-part': 'rotate-ghost' }));
    }
  }
  return g.childElementCount ? g : null;
}
