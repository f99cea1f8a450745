// Maps between the parsed text and the server's view: element ids by
// position, and diagnostics to the rung and element they point at.
import type { ElementJson, RungJson } from '../types';
import { type Elem, type Pos, walk } from './ast';
import type { ProgramDoc } from './parse';

const before = (a: Pos, b: Pos) => a.line < b.line || (a.line === b.line && a.col < b.col);

/** Copies the server's element ids onto the locally parsed trees, matching elements by line and column. */
export function attachIds(doc: ProgramDoc, rungs: RungJson[]): number {
  const ids = new Map<string, number | null>();
  const collect = (els: ElementJson[]) =>
    els.forEach((e) => {
      ids.set(`${e.line}:${e.col}`, e.id);
      if (e.kind === 'branch') e.legs.forEach(collect);
    });
  rungs.forEach((r) => collect(r.elements));
  let n = 0;
  for (const r of doc.rungs) {
    if (!r.elements) continue;
    walk(r.elements, (e) => {
      const id = ids.get(`${e.line}:${e.col}`);
      e.id = id ?? null;
      if (id !== undefined && id !== null) n++;
    });
  }
  return n;
}

export interface Place {
  rung: number;
  /** Path of the innermost element at the place, "" for the rung as a whole. */
  path: string;
}

/** The rung (and element) at a line and column of the program text; null if outside every rung. */
export function locate(doc: ProgramDoc, line: number, col: number): Place | null {
  const at = { line, col };
  const rung = doc.rungs.findIndex((r) => line >= r.startLine && line <= r.endLine);
  if (rung < 0) return null;
  const els = doc.rungs[rung].elements;
  let best = '';
  if (els) {
    walk(els, (e: Elem, p) => {
      if (e.line === undefined || e.col === undefined || !e.end) return;
      const start = { line: e.line, col: e.col };
      if (!before(at, start) && before(at, e.end)) best = p.join('.'); // inner ones come later
    });
  }
  return { rung, path: best };
}
