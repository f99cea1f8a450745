// Geometry of a rung: where every element, wire and branch rail goes.
// Pure (no DOM), so sizes and branch geometry are unit-tested.
//
// A series of elements shares one horizontal wire; every element is
// measured as a width, an ascent (above its wire) and a descent (below).
// A branch stacks its legs; the first leg's wire is the branch's wire, and
// vertical rails join the legs on the left (fed by the branch's input) and
// on the right (each segment fed by the legs below it).
import { instruction } from '../domain';
import { type Branch, type Elem, type Instr, type Path, operandLabels, shapeOf } from './ast';

export const G = {
  /** Wire before each element. */
  gap: 14,
  /** Space between two legs of a branch. */
  legGap: 8,
  /** Monospace text: width of a character at the 12 px font. */
  charW: 7.3,
  contactW: 84,
  contactAsc: 36,
  contactDesc: 16,
  boxMinW: 150,
  boxMaxW: 360,
  boxTop: 8,
  boxHeader: 16,
  boxRow: 16,
  commentLine: 16,
  top: 10,
  bottom: 14,
  /** Wire from the last element to the right rail, at least. */
  tail: 30,
} as const;

/** A source of power for a wire: the rail, or an element id. */
export type Src = 'rail' | number;

export interface Wire {
  x1: number;
  y1: number;
  x2: number;
  y2: number;
  /** Powered when any source is on; empty means never known (no ids). */
  src: Src[];
}

export interface PlacedInstr {
  kind: 'instr';
  el: Instr;
  path: Path;
  shape: 'contact' | 'coil' | 'box';
  x: number;
  y: number;
  w: number;
  h: number;
  /** Absolute y of the wire through the element. */
  wire: number;
  /** The power entering the element. */
  input: Src[];
}

export interface PlacedBranch {
  kind: 'branch';
  el: Branch;
  path: Path;
  x: number;
  y: number;
  w: number;
  h: number;
  wire: number;
  input: Src[];
}

export type Placed = PlacedInstr | PlacedBranch;

export interface RungLayout {
  width: number;
  height: number;
  /** y of the main wire. */
  wire: number;
  /** x of the right rail. */
  rail: number;
  items: Placed[];
  wires: Wire[];
}

interface Size {
  w: number;
  asc: number;
  desc: number;
}

function textW(t: string): number {
  return Array.from(t).length * G.charW;
}

/** The rows of a box: [label, operand] pairs (timers and counters, compares, math …). */
export function boxRows(i: Instr): [string, string][] {
  const labels = operandLabels(i.mnemonic, i.operands.length);
  return i.operands.map((o, k) => [labels[k], o]);
}

/** Status bits of the structure operand shown in the box header (timers, counters, PID). */
export function boxStatusBits(i: Instr): string[] {
  return instruction(i.mnemonic)?.bits ?? [];
}

/** Columns of a box, relative to its frame: label, operand, live value. */
export interface BoxColumns {
  /** x of the operand column. */
  operandX: number;
  /** Characters of operand text that fit. */
  operandChars: number;
  /** x of the right edge of the value column (values are right-aligned). */
  valueRight: number;
  /** Width of the frame. */
  frameW: number;
}

const VALUE_W = 64;

export function boxColumns(i: Instr): BoxColumns {
  const rows = boxRows(i);
  const labelW = Math.max(0, ...rows.map(([l]) => textW(l)));
  const operandW = Math.max(textW('?'), ...rows.map(([, o]) => textW(o)));
  const operandX = 6 + labelW + 8;
  const want = operandX + operandW + 10 + VALUE_W + 6;
  const title = textW(i.mnemonic) + 12;
  const frameW = Math.ceil(Math.min(G.boxMaxW - 16, Math.max(G.boxMinW - 16, want + 1, title)));
  const operandChars = Math.max(4, Math.floor((frameW - operandX - 10 - VALUE_W - 6) / G.charW));
  return { operandX, operandChars, valueRight: frameW - 6, frameW };
}

/** Lines shown under a contact or coil (its tag's address and description), or none. */
let annotate: ((operand: string) => string[]) | null = null;
/** A line of annotation under an element. */
export const ANNOT_LINE = 12;
/** The longest annotation shown, in characters (longer ones end with `…`). */
const ANNOT_CHARS = 22;

/** Shows (or, with null, hides) the address and description under every contact and coil. */
export function setAnnotations(f: ((operand: string) => string[]) | null): void {
  annotate = f;
}

/** The annotation lines of an operand, shortened. */
export function annotationsOf(operand: string): string[] {
  return (annotate?.(operand) ?? []).filter(Boolean).map((l) => (l.length > ANNOT_CHARS ? `${l.slice(0, ANNOT_CHARS - 1)}…` : l));
}

export function measureInstr(i: Instr): Size {
  const shape = shapeOf(i.mnemonic);
  if (shape !== 'box') {
    const name = i.operands[0] ?? '';
    const notes = annotationsOf(name);
    const w = Math.max(G.contactW, textW(name) + 14, ...notes.map((l) => textW(l) * 0.85 + 10));
    return { w, asc: G.contactAsc, desc: G.contactDesc + (notes.length ? notes.length * ANNOT_LINE + 14 : 0) };
  }
  const rows = boxRows(i);
  const w = boxColumns(i).frameW + 16;
  const h = G.boxHeader + Math.max(1, rows.length) * G.boxRow + 6;
  return { w, asc: G.boxTop + G.boxHeader / 2 + 2, desc: h - (G.boxHeader / 2 + 2) + 6 };
}

function measureSeries(elems: Elem[]): Size {
  let w = 0;
  let asc = 0;
  let desc = 0;
  for (const e of elems) {
    const m = measure(e);
    w += G.gap + m.w;
    asc = Math.max(asc, m.asc);
    desc = Math.max(desc, m.desc);
  }
  return { w, asc, desc };
}

function measureBranch(b: Branch): Size {
  const legs = b.legs.map(measureSeries);
  const w = Math.max(0, ...legs.map((l) => l.w)) + G.gap;
  const asc = legs[0]?.asc ?? 0;
  let below = legs[0]?.desc ?? 0;
  for (const l of legs.slice(1)) below += G.legGap + l.asc + l.desc;
  return { w, asc, desc: below };
}

export function measure(e: Elem): Size {
  return e.kind === 'instr' ? measureInstr(e) : measureBranch(e);
}

interface Out {
  items: Placed[];
  wires: Wire[];
}

const srcOf = (e: Elem): Src[] => (e.id === undefined || e.id === null ? [] : [e.id]);

/** Places a series with its wire at `wire`, starting at `x`; returns the power source after it. */
function placeSeries(elems: Elem[], prefix: Path, x: number, wire: number, src: Src[], out: Out): { x: number; src: Src[] } {
  let cur = src;
  elems.forEach((e, i) => {
    const m = measure(e);
    out.wires.push({ x1: x, y1: wire, x2: x + G.gap, y2: wire, src: cur });
    x += G.gap;
    const path = [...prefix, i];
    if (e.kind === 'instr') {
      out.items.push({ kind: 'instr', el: e, path, shape: shapeOf(e.mnemonic), x, y: wire - m.asc, w: m.w, h: m.asc + m.desc, wire, input: cur });
    } else {
      placeBranch(e, path, x, wire, cur, m, out);
    }
    x += m.w;
    cur = srcOf(e);
  });
  return { x, src: cur };
}

function placeBranch(b: Branch, path: Path, x: number, wire: number, src: Src[], m: Size, out: Out): void {
  out.items.push({ kind: 'branch', el: b, path, x, y: wire - m.asc, w: m.w, h: m.asc + m.desc, wire, input: src });
  const legs = b.legs.map(measureSeries);
  const wires: number[] = [];
  let y = wire;
  legs.forEach((l, k) => {
    if (k > 0) y += legs[k - 1].desc + G.legGap + l.asc;
    wires.push(y);
  });
  const ends: Src[][] = [];
  b.legs.forEach((leg, k) => {
    const r = placeSeries(leg, [...path, k], x, wires[k], src, out);
    ends.push(r.src);
    if (r.x < x + m.w) out.wires.push({ x1: r.x, y1: wires[k], x2: x + m.w, y2: wires[k], src: r.src });
  });
  for (let k = 1; k < wires.length; k++) {
    // Left rail: every leg is fed by the branch's input.
    out.wires.push({ x1: x, y1: wires[k - 1], x2: x, y2: wires[k], src });
    // Right rail: the segment above leg k carries the power of legs k and below.
    const below = [...new Set(ends.slice(k).flat())];
    out.wires.push({ x1: x + m.w, y1: wires[k - 1], x2: x + m.w, y2: wires[k], src: below });
  }
}

/**
 * Lays out one rung. x = 0 is the left rail; the right rail is at
 * `minRail` or further right if the rung is wider. `commentLines` lines of
 * comment are left free at the top.
 */
export function layoutRung(elements: Elem[], commentLines = 0, minRail = 0): RungLayout {
  const m = measureSeries(elements);
  const asc = Math.max(m.asc, G.contactAsc);
  const desc = Math.max(m.desc, G.contactDesc);
  const wire = G.top + commentLines * G.commentLine + asc;
  const out: Out = { items: [], wires: [] };
  const end = placeSeries(elements, [], 0, wire, ['rail'], out);
  const rail = Math.max(minRail, end.x + G.tail);
  out.wires.push({ x1: end.x, y1: wire, x2: rail, y2: wire, src: end.src });
  return { width: rail, height: wire + desc + G.bottom, wire, rail, items: out.items, wires: out.wires };
}

/** Whether a wire is powered, given the energised ids (and whether the program runs). */
export function powered(w: Wire, on: ReadonlySet<number>, running: boolean): boolean {
  if (!running) return false;
  return w.src.some((s) => (s === 'rail' ? true : on.has(s)));
}
