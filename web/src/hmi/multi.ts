// Several selected elements edited together (issue 35, point 3): the
// properties every one of them has (the same name and the same kind of
// value; the vertices, which are geometry, aside) and the values they agree
// on. A field whose elements disagree starts empty; a value set there goes
// to all of them, as one change.
import type { ParamInfo } from '../api.gen';
import type { Json } from '../types';
import type { Element } from './render';

/** What a property is, for comparing two element types' tables (its help text aside). */
const shape = (p: ParamInfo) => JSON.stringify({ ...p, help: '' });

/** The properties in every one of `tables` (one per selected element), in the first table's order. */
export function commonParams(tables: ParamInfo[][]): ParamInfo[] {
  if (tables.length === 0) return [];
  const [first, ...rest] = tables;
  return first.filter((p) => p.kind !== 'points' && rest.every((t) => t.some((q) => q.name === p.name && shape(q) === shape(p))));
}

/** For each of `params`, the value all of `els` have (absent when they disagree or none has it). */
export function commonValues(els: Element[], params: ParamInfo[]): Record<string, Json | undefined> {
  const out: Record<string, Json | undefined> = {};
  for (const p of params) {
    const vs = els.map((e) => JSON.stringify(e.props?.[p.name] ?? null));
    if (vs.every((v) => v === vs[0]) && els[0].props?.[p.name] !== undefined) out[p.name] = els[0].props?.[p.name];
  }
  return out;
}

/** Sets (or, with `undefined`, removes) the property `name` on every one of `els`. */
export function setAll(els: Element[], name: string, v: Json | undefined): void {
  for (const e of els) {
    const { [name]: _old, ...rest } = e.props ?? {};
    e.props = v === undefined ? rest : { ...rest, [name]: v };
  }
}
