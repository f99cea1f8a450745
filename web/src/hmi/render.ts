// Draws a SCADA screen (hmi/<name>.json, docs/file-formats.md "Screens") as
// SVG and animates it from live values (issue 17). Symbols follow ISA-101:
// greys for equipment, colour only for state. Each element is a group in its
// own box (0,0)–(w,h), translated and rotated into place; animations change
// attributes of that group or of its parts marked `data-part`, and only when
// the value that drives them changes.
import { fmt, s } from '../dom';
import { GREY, ON, symbol } from './symbols';
import type { Json } from '../types';
import { trendPens } from './trend';

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
  /** The designer's group: its elements are selected and moved together. */
  group?: string;
}

export interface Screen {
  schema: number;
  title?: string;
  width: number;
  height: number;
  background?: string | null;
  elements: Element[];
}

/**
 * The properties that name a BOOL tag of their own, and the data attribute
 * (`on`/`off`) each sets on the element for the style sheet: a bottle's cap,
 * a building's lit windows, a PLC's lamps blinking while it runs.
 */
export const PROP_TAGS: Record<string, string> = { cap_tag: 'cap', windows_tag: 'windows', run_tag: 'run' };

/** Shows the value `v` of the tag named by the property `prop` (one of `PROP_TAGS`) on `g`. */
export function showPropTag(g: SVGGElement, prop: string, v: Json): void {
  g.dataset[PROP_TAGS[prop]] = num(v) ? 'on' : 'off';
}

/** The tags a screen shows or writes: what its view subscribes to, and nothing else. */
export function tagsOf(screen: Screen): string[] {
  const names = new Set<string>();
  for (const e of screen.elements) {
    for (const a of e.animations ?? []) names.add(a.tag);
    if (typeof e.props?.tag === 'string') names.add(e.props.tag);
    // a trend's pens (the three it draws)
    if (e.type === 'trend') for (const pen of trendPens(e.props)) names.add(pen.tag);
    for (const prop of Object.keys(PROP_TAGS)) if (typeof e.props?.[prop] === 'string') names.add(e.props[prop] as string);
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

/** The blink's shown and hidden times in ms (`on_ms`, `off_ms`; the older `period_ms` half each; 500 each). */
export function blinkTimes(a: Animation): [number, number] {
  const period = num(a.period_ms);
  const half = period !== null && period > 0 ? period / 2 : 500;
  const ms = (x: Json | undefined) => (num(x) !== null && (num(x) as number) > 0 ? (num(x) as number) : half);
  return [ms(a.on_ms), ms(a.off_ms)];
}

/**
 * Whether a visibility or blink animation acts for the value `v` (AuroraLD's
 * digital or analog condition): a number inside `min`–`max` when either is
 * set, else the tag on; `when: false` turns it round.
 */
export function active(a: Animation, v: Json): boolean {
  const lo = num(a.min);
  const hi = num(a.max);
  const on = (lo !== null || hi !== null) && typeof v === 'number' ? v >= (lo ?? -Infinity) && v <= (hi ?? Infinity) : !!num(v);
  return on === (a.when !== false);
}

/** The child `tag` of `g` marked `data-part=part`, made with `attrs` (or removed when `attrs` is null). */
function smil(g: Element_, tag: 'animate' | 'animateTransform', part: string, attrs: Record<string, string> | null): void {
  let x = [...g.children].find((c) => c.tagName === tag && c.getAttribute('data-part') === part);
  if (!attrs) return x?.remove();
  if (!x) g.append((x = s(tag, { 'data-part': part, repeatCount: 'indefinite' })));
  for (const [k, v] of Object.entries(attrs)) if (x.getAttribute(k) !== v) x.setAttribute(k, v);
}
type Element_ = globalThis.Element;

/**
 * Applies one animation of the element group `g` (box `e`) for value `v`.
 * Pure DOM writes on attributes; a blink and a spin are SVG animations
 * (`<animate>`, `<animateTransform>`) with the element's own times, so they
 * run without a frame loop and add to the element's placement.
 */
export function animate(g: SVGGElement, e: Element, a: Animation, v: Json): void {
  const part = (name: string) => g.querySelector(`[data-part="${name}"]`);
  const on = !!num(v);
  switch (a.kind) {
    case 'visibility':
      g.style.display = active(a, v) ? '' : 'none';
      break;
    case 'blink': {
      const blinking = active(a, v);
      g.classList.toggle('hmi-blinking', blinking);
      const [shown, hidden] = blinkTimes(a);
      smil(g, 'animate', 'blink', blinking
        ? { attributeName: 'opacity', values: '1;0.15', keyTimes: `0;${+(shown / (shown + hidden)).toFixed(4)}`, calcMode: 'discrete', dur: `${shown + hidden}ms` }
        : null);
      break;
    }
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
        level.setAttribute('x', '2');
        level.setAttribute('width', String(Math.max(0, e.w - 4)));
      } else {
        const w = (e.w - 4) * f;
        level.setAttribute('width', String(w));
        level.setAttribute('x', String(dir === 'right' ? 2 : e.w - 2 - w));
        level.setAttribute('y', '2');
        level.setAttribute('height', String(Math.max(0, e.h - 4)));
      }
      if (typeof a.color === 'string') level.setAttribute('fill', a.color);
      break;
    }
    case 'move': {
      const x = num(v);
      if (x === null) break;
      const f = a.when === false ? 1 - frac(x, a) : frac(x, a);
      g.dataset.move = `${(num(a.dx) ?? 0) * f},${(num(a.dy) ?? 0) * f}`;
      place(g, e);
      break;
    }
    case 'rotate': {
      // with an anchor point the whole element turns about it (AuroraLD's
      // anchor); else a machine's rotor or a gauge's needle about its hub, or
      // the whole element about its centre
      const anchored = num(a.cx) !== null || num(a.cy) !== null;
      const needle = anchored ? null : part('needle');
      const rotor = anchored ? null : part('rotor') ?? needle;
      const [ax, ay] = rotor ? [0, 0] : [num(a.cx) ?? e.w / 2, num(a.cy) ?? e.h / 2];
      if (a.speed !== undefined) {
        // turning while active, `speed` turns a second
        const turns = num(a.speed) ?? 1;
        const spinning = on === (a.when !== false) && turns !== 0;
        const target = rotor ?? g;
        target.classList.toggle('hmi-spin', spinning);
        smil(target, 'animateTransform', 'spin', spinning
          ? { attributeName: 'transform', type: 'rotate', additive: 'sum', from: `0 ${ax} ${ay}`, to: `${turns < 0 ? -360 : 360} ${ax} ${ay}`, dur: `${+(1 / Math.abs(turns)).toFixed(4)}s` }
          : null);
      } else {
        const x = num(v);
        if (x === null) break;
        const f = a.when === false ? 1 - frac(x, a) : frac(x, a);
        const from = num(a.from) ?? 0;
        const angle = +(from + f * ((num(a.degrees) ?? (needle ? 270 : 360)) - from)).toFixed(3);
        if (rotor) rotor.setAttribute('transform', `rotate(${angle})`);
        else {
          g.dataset.rotate = `${angle} ${ax} ${ay}`;
          place(g, e);
        }
      }
      break;
    }
  }
}

/** Puts the group at the element's place (with its `move` offset and its `rotate` about an anchor). */
export function place(g: SVGGElement, e: Element): void {
  const [dx, dy] = (g.dataset.move ?? '0,0').split(',').map(Number);
  const turned = g.dataset.rotate ? ` rotate(${g.dataset.rotate})` : '';
  g.setAttribute('transform', `translate(${e.x + dx},${e.y + dy}) rotate(${e.rotation ?? 0} ${e.w / 2} ${e.h / 2})${turned}`);
}

/**
 * An element's shown value (`props.tag`): the figures of a text, output box
 * or meter (with `props.decimals` when set). A trend element draws its
 * window of values instead (trend.ts).
 */
export function showValue(g: SVGGElement, v: Json, props: Record<string, Json> = {}): void {
  const t = g.querySelector('[data-part="text"]');
  const figures = typeof v === 'number' && typeof props.decimals === 'number' ? v.toFixed(Math.max(0, Math.min(10, props.decimals))) : fmt(v);
  const shown = typeof props.unit === 'string' && props.unit ? `${figures} ${props.unit}` : figures;
  if (t && t.textContent !== shown) t.textContent = shown;
}

/**
 * A faceplate element from its loop's members (`get('SP')` …): SP and PV
 * bars on the PV's scale (MINS–MAXS, 0–100 when unset), CV in % (MINO–MAXO),
 * the figures, and the mode.
 */
export function showLoop(g: SVGGElement, get: (member: string) => Json | undefined): void {
  const v = (m: string) => num(get(m) as Json) ?? 0;
  const scale = (lo: number, hi: number): [number, number] => (hi > lo ? [lo, hi] : [0, 100]);
  const scales: Record<string, [number, number]> = { SP: scale(v('MINS'), v('MAXS')), PV: scale(v('MINS'), v('MAXS')), CV: scale(v('MINO'), v('MAXO')) };
  for (const m of ['SP', 'PV', 'CV']) {
    const bar = g.querySelector(`[data-part="bar-${m}"]`);
    const [lo, hi] = scales[m];
    const f = Math.max(0, Math.min(1, (v(m) - lo) / (hi - lo)));
    bar?.setAttribute('width', (Number(bar.getAttribute('data-width') ?? 0) * f).toFixed(1));
    const t = g.querySelector(`[data-part="val-${m}"]`);
    if (t) t.textContent = get(m) === undefined ? '…' : v(m).toFixed(2);
  }
  const mode = g.querySelector('[data-part="mode"]');
  if (mode) mode.textContent = get('MAN') === true ? 'MAN' : get('MAN') === false ? 'AUTO' : '';
}

/** The colour and blinking of an alarm indicator for its alarm's state (ISA-18.2 / ISA-101: unacknowledged blinks). */
export const ALARM_LOOK: Record<string, [string, boolean]> = {
  normal: ['#9ea3a8', false],
  active_unacked: ['#c62828', true],
  active_acked: ['#c62828', false],
  cleared_unacked: ['#f9a825', true],
  shelved: ['#6d4c9f', false],
  suppressed: ['#6d4c9f', false],
  out_of_service: ['#6d4c9f', false],
};

/** An alarm indicator (`props.alarm`, an alarm id) showing its alarm's state (`normal` when not listed). */
export function showAlarm(g: SVGGElement, state: string): void {
  const [colour, blink] = ALARM_LOOK[state] ?? ALARM_LOOK.normal;
  g.querySelectorAll('[data-part="fill"]').forEach((p) => p.setAttribute('fill', colour));
  g.classList.toggle('hmi-blink', blink);
  g.dataset.state = state;
}

/** Sets a clock element's hands and figures to `now`. */
export function tick(g: SVGGElement, now: Date): void {
  const [hh, mm, ss] = [now.getHours(), now.getMinutes(), now.getSeconds()];
  g.querySelector('[data-part="hour"]')?.setAttribute('transform', `rotate(${(hh % 12) * 30 + mm / 2})`);
  g.querySelector('[data-part="minute"]')?.setAttribute('transform', `rotate(${mm * 6 + ss / 10})`);
  const t = g.querySelector('[data-part="text"]');
  if (t) t.textContent = [hh, mm, ss].map((x) => String(x).padStart(2, '0')).join(':');
}

/** The element's group, drawn at its place, with its symbol. */
export function drawElement(e: Element): SVGGElement {
  const g = s('g', { class: `hmi-el hmi-${e.type}`, 'data-testid': `hmi-el-${e.id}`, 'data-type': e.type });
  g.append(...symbol(e));
  place(g, e);
  return g;
}
