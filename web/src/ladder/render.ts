// Draws a laid-out rung as SVG and keeps it live: power flow (data-on on
// elements, class `on` on wires) and values inside boxes. Only the nodes
// whose state changed are touched.
import { s, fmt } from '../dom';
import type { Json } from '../types';
import { instruction } from '../domain';
import { tr } from '../i18n';
import { type Elem, type Path, operandTags, titleOf } from './ast';
import { ANNOT_LINE, G, type Placed, type PlacedInstr, type RungLayout, type Src, type Wire, annotationsOf, boxColumns, boxRows, boxStatusBits, powered } from './layout';

export const GUTTER = 46;

export interface RungDecor {
  number: number;
  comment: string[];
  /** Diagnostics messages by element path ("0.1.2"); "" for the rung itself. */
  problems: Map<string, string[]>;
  selected: string | null;
  /** Tags currently forced (upper case). */
  forced: ReadonlySet<string>;
}

export interface LiveHooks {
  /** Subscribes a text node's value to a tag name; returns the unwatch. */
  watch(name: string, cb: (v: Json) => void): () => void;
}

export interface RungView {
  svg: SVGSVGElement;
  setPower(on: ReadonlySet<number>, running: boolean): void;
  dispose(): void;
}

const pathKey = (p: Path) => p.join('.');

function wireEl(w: Wire, extra = ''): SVGLineElement {
  return s('line', { class: `wire ${extra}`.trim(), x1: w.x1, y1: w.y1, x2: w.x2, y2: w.y2 });
}

function testId(el: Elem, rung: number, path: Path): string {
  return el.id === undefined || el.id === null ? `el-r${rung}-${pathKey(path)}` : `el-${el.id}`;
}

function contactSymbol(p: PlacedInstr): SVGElement[] {
  const m = p.el.mnemonic.toUpperCase();
  const cx = p.w / 2;
  const wy = p.wire - p.y;
  const out: SVGElement[] = [];
  if (p.shape === 'contact') {
    out.push(s('line', { class: 'sym', x1: cx - 7, y1: wy - 11, x2: cx - 7, y2: wy + 11 }));
    out.push(s('line', { class: 'sym', x1: cx + 7, y1: wy - 11, x2: cx + 7, y2: wy + 11 }));
    if (m === 'XIO') out.push(s('line', { class: 'sym', x1: cx - 10, y1: wy + 11, x2: cx + 10, y2: wy - 11 }));
    if (m === 'ONS') out.push(s('text', { class: 'mn', x: cx, y: wy + 24, 'text-anchor': 'middle' }, 'ONS'));
  } else {
    out.push(s('path', { class: 'sym', d: `M ${cx - 4} ${wy - 11} A 14 14 0 0 0 ${cx - 4} ${wy + 11}` }));
    out.push(s('path', { class: 'sym', d: `M ${cx + 4} ${wy - 11} A 14 14 0 0 1 ${cx + 4} ${wy + 11}` }));
    if (m !== 'OTE') out.push(s('text', { class: 'coil-letter', x: cx, y: wy + 4, 'text-anchor': 'middle' }, m === 'OTL' ? 'L' : 'U'));
  }
  return out;
}

/** Draws one rung; `gutter` holds the rung number left of the rail. */
export function renderRung(l: RungLayout, decor: RungDecor, live: LiveHooks | null): RungView {
  const width = GUTTER + l.width + 12;
  const svg = s('svg', {
    class: 'rung-svg',
    width,
    height: l.height,
    viewBox: `0 0 ${width} ${l.height}`,
    'data-testid': `rung-svg-${decor.number}`,
  });
  const root = s('g', { transform: `translate(${GUTTER},0)` });
  svg.append(root);
  const unwatch: (() => void)[] = [];
  const wires: { el: SVGElement; w: Wire; on: boolean }[] = [];
  const elems: { el: SVGElement; id: number; on: boolean }[] = [];
  const addWire = (w: Wire, parent: SVGElement = root) => {
    const el = wireEl(w);
    parent.append(el);
    wires.push({ el, w, on: false });
  };

  // rails, number, comment
  const leftRail = s('line', { class: 'rail left', x1: 0, y1: 0, x2: 0, y2: l.height });
  root.append(leftRail, s('line', { class: 'rail', x1: l.rail, y1: 0, x2: l.rail, y2: l.height }));
  root.append(s('text', { class: 'rung-number', x: -8, y: l.wire + 4, 'text-anchor': 'end' }, String(decor.number + 1)));
  decor.comment.forEach((c, k) => {
    root.append(s('text', { class: 'comment', x: 8, y: G.top + (k + 1) * G.commentLine - 4 }, c));
  });
  const rungProblems = decor.problems.get('');
  if (rungProblems) {
    root.append(
      s('rect', { class: 'rung-error', x: 2, y: 2, width: l.rail - 4, height: l.height - 4 }, s('title', null, rungProblems.join('\n'))),
    );
  }

  for (const w of l.wires) addWire(w);

  for (const p of l.items) {
    const key = pathKey(p.path);
    const problems = decor.problems.get(key);
    const cls = ['el', `el-${p.kind === 'instr' ? p.shape : 'branch'}`, decor.selected === key ? 'selected' : '', problems ? 'error' : '']
      .filter(Boolean)
      .join(' ');
    const g = s('g', {
      class: cls,
      transform: `translate(${p.x},${p.y})`,
      'data-testid': testId(p.el, decor.number, p.path),
      'data-path': key,
      'data-on': 'false',
    });
    if (p.el.id !== undefined && p.el.id !== null) elems.push({ el: g, id: p.el.id, on: false });
    if (p.kind === 'branch') {
      // a thin hit area along the branch's left rail, and an outline when selected or in error
      g.append(s('rect', { class: 'hit branch-hit', x: -5, y: p.wire - p.y - 6, width: 10, height: p.h - (p.wire - p.y) + 6 - G.contactDesc }));
      g.append(s('rect', { class: 'outline', x: -4, y: 2, width: p.w + 8, height: p.h - 4, rx: 4 }));
    } else {
      drawInstr(p, g, decor, live, unwatch, (w) => addWire(w, g));
    }
    if (problems) g.append(s('title', null, problems.join('\n')));
    root.append(g);
  }

  let lastRunning: boolean | null = null;
  return {
    svg,
    setPower(on, running) {
      if (running !== lastRunning) {
        leftRail.classList.toggle('on', running);
        lastRunning = running;
      }
      for (const e of elems) {
        const v = running && on.has(e.id);
        if (v !== e.on) {
          e.on = v;
          e.el.setAttribute('data-on', String(v));
        }
      }
      for (const w of wires) {
        const v = powered(w.w, on, running);
        if (v !== w.on) {
          w.on = v;
          w.el.classList.toggle('on', v);
        }
      }
    },
    dispose() {
      unwatch.forEach((f) => f());
    },
  };
}

function drawInstr(
  p: PlacedInstr,
  g: SVGElement,
  decor: RungDecor,
  live: LiveHooks | null,
  unwatch: (() => void)[],
  addWire: (w: Wire) => void,
): void {
  const i = p.el;
  const wy = p.wire - p.y;
  const out: Src[] = i.id === undefined || i.id === null ? [] : [i.id];
  g.append(s('rect', { class: 'hit', x: 0, y: 0, width: p.w, height: p.h }));
  g.append(s('rect', { class: 'outline', x: 1, y: 1, width: p.w - 2, height: p.h - 2, rx: 4 }));
  if (p.shape !== 'box') {
    const cx = p.w / 2;
    addWire({ x1: 0, y1: wy, x2: cx - 7, y2: wy, src: p.input });
    addWire({ x1: cx + 7, y1: wy, x2: p.w, y2: wy, src: out });
    g.append(...contactSymbol(p));
    const name = i.operands[0] ?? '';
    const forced = decor.forced.has(name.toUpperCase());
    g.append(s('text', { class: 'operand', x: cx, y: wy - 16, 'text-anchor': 'middle' }, name));
    if (forced) g.append(s('text', { class: 'forced-badge', x: p.w - 4, y: wy + 26, 'text-anchor': 'end' }, 'F'));
    if (i.operands.length > 1) {
      g.append(s('text', { class: 'operand small', x: cx, y: wy + 26, 'text-anchor': 'middle' }, i.operands.slice(1).join(', ')));
    }
    annotationsOf(name).forEach((line, k) =>
      g.append(s('text', { class: 'annotation', x: cx, y: wy + 30 + k * ANNOT_LINE, 'text-anchor': 'middle', 'data-testid': `annotation-${k}` }, line)),
    );
    return;
  }
  // function box
  const bx = 8;
  const cols = boxColumns(i);
  const bw = cols.frameW;
  const top = G.boxTop;
  const rows = boxRows(i);
  const bh = G.boxHeader + Math.max(1, rows.length) * G.boxRow + 6;
  addWire({ x1: 0, y1: wy, x2: bx, y2: wy, src: p.input });
  addWire({ x1: bx + bw, y1: wy, x2: p.w, y2: wy, src: out });
  g.append(s('rect', { class: 'box', x: bx, y: top, width: bw, height: bh, rx: 2 }));
  const m = i.mnemonic.toUpperCase();
  g.append(s('text', { class: 'mn', x: bx + 6, y: top + 12 }, m));
  const bits = boxStatusBits(i);
  const titleX = bx + 6 + m.length * G.charW + 8;
  const title = titleOf(m);
  const titleRoom = bw - (titleX - bx) - 6 - bits.length * 24;
  if (title && title.length * 5.6 <= titleRoom) g.append(s('text', { class: 'title', x: titleX, y: top + 12 }, title));
  const base = i.operands[0]?.trim() ?? '';
  bits.forEach((b, k) => {
    const t = s('text', { class: 'bit', x: bx + bw - 6 - (bits.length - 1 - k) * 24, y: top + 12, 'text-anchor': 'end', 'data-bit': b }, b);
    g.append(t);
    if (live && base) unwatch.push(live.watch(`${base}.${b}`, (v) => t.classList.toggle('bit-on', v === true)));
  });
  g.append(s('line', { class: 'box-sep', x1: bx, y1: top + G.boxHeader, x2: bx + bw, y2: top + G.boxHeader }));
  const tags = new Set(operandTags(i));
  const shows = instruction(m)?.shows;
  rows.forEach(([label, op], k) => {
    const y = top + G.boxHeader + (k + 1) * G.boxRow - 4;
    g.append(s('text', { class: 'label', x: bx + 6, y }, label));
    const shown = Array.from(op).length > cols.operandChars ? Array.from(op).slice(0, cols.operandChars - 1).join('') + '…' : op;
    // live value (the domain's `shows`): a timer's or counter's Preset and Accum rows
    // show the member's value in place of the literal (one number a row, as the
    // literal is only where it starts), structure operands nothing, other operands
    // their tag's value beside the name
    const show = shows && k < shows.length ? shows[k] : '';
    if (show && base && live) {
      const member = `${base}.${show}`;
      const node = document.createTextNode(shown);
      const tip = s('title', null, tr('{member} now; {literal} in the program', { member, literal: op }));
      const t = s('text', { class: 'operand', x: bx + cols.operandX, y }, s('tspan', { 'data-tag': member }, node), tip);
      g.append(t);
      unwatch.push(live.watch(member, (v) => {
        const text = fmt(v);
        if (node.data !== text) node.data = text;
        t.setAttribute('class', 'operand val');
      }));
      return;
    }
    g.append(s('text', { class: 'operand', x: bx + cols.operandX, y }, shown, shown !== op ? s('title', null, op) : null));
    const watchName = show === '' && tags.has(op.trim()) ? op.trim() : null;
    if (watchName && live) {
      const node = document.createTextNode('…');
      g.append(s('text', { class: 'val', x: bx + cols.valueRight, y, 'text-anchor': 'end', 'data-tag': watchName }, node));
      unwatch.push(live.watch(watchName, (v) => {
        const t = fmt(v);
        if (node.data !== t) node.data = t;
      }));
    }
  });
}

/** The placed item under an SVG event target, by its data-path. */
export function pathFromEvent(ev: Event): string | null {
  const t = (ev.target as Element | null)?.closest?.('[data-path]');
  return t ? t.getAttribute('data-path') : null;
}

export type { Placed };
