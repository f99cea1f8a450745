// The ladder element tree: the same shape as the API's `rungs` JSON
// (docs/api.md), so server rungs and locally parsed rungs are used alike.
// What an instruction looks like (shape, labels, title) comes from the domain.
import { type OptionalInfo, argInfo, instruction } from '../domain';

export interface Pos {
  line: number;
  col: number;
}

export interface Instr {
  kind: 'instr';
  mnemonic: string;
  operands: string[];
  /** The element id in the running program (power flow key); null/absent if unknown. */
  id?: number | null;
  line?: number;
  col?: number;
  /** Position just after the closing `)` (local parser only). */
  end?: Pos;
}

export interface Branch {
  kind: 'branch';
  legs: Elem[][];
  id?: number | null;
  line?: number;
  col?: number;
  end?: Pos;
}

export type Elem = Instr | Branch;

export interface Rung {
  comment: string[];
  elements: Elem[];
}

/** A path to an element inside a rung: [i] top level, [i, leg, j] inside branch i, … */
export type Path = number[];

/** How the diagram draws an instruction (an unknown one is a box). */
export function shapeOf(mnemonic: string): 'contact' | 'coil' | 'box' {
  return instruction(mnemonic)?.shape ?? 'box';
}

/** Operand labels shown in boxes and the properties panel: the required operands',
 * then the optional ones' (a TON's `Time base`), `Operand n` where the domain has none. */
export function operandLabels(mnemonic: string, count: number): string[] {
  const info = instruction(mnemonic);
  const l = [...(info?.labels ?? []), ...(info?.optional ?? []).map((o) => o.label)];
  return Array.from({ length: count }, (_, i) => l[i] ?? `Operand ${i + 1}`);
}

/** The optional operand at position `k` of an instruction (a TON's time base at 3), if that place is one. */
export function optionalAt(mnemonic: string, k: number): OptionalInfo | undefined {
  const info = instruction(mnemonic);
  return info ? info.optional[k - info.args.length] : undefined;
}

/** The full name for a box title ('' for an unknown instruction). */
export function titleOf(mnemonic: string): string {
  return instruction(mnemonic)?.title ?? '';
}

/** True for an operand that is a literal, `?`, a label or an expression rather than a tag. */
export function isLiteral(op: string): boolean {
  const t = op.trim();
  return t === '' || t === '?' || /^[0-9+\-.]/.test(t) || /^(T|TIME)#/i.test(t) || /^(TRUE|FALSE)$/i.test(t);
}

/** The tag names an instruction reads or writes, for live values (not labels or expressions). */
export function operandTags(i: Instr): string[] {
  const info = instruction(i.mnemonic);
  // an optional operand (a time base) is never a tag; past the table, an operand is taken as one
  const ops = info ? i.operands.filter((_, k) => !optionalAt(i.mnemonic, k) && (argInfo(info.args[k] ?? '')?.tag ?? true)) : i.operands;
  return ops.filter((o) => !isLiteral(o) && /^[A-Za-z_%][\w.:/%]*$/.test(o.trim())).map((o) => o.trim());
}

/** Visits every element with its path. */
export function walk(elems: Elem[], f: (e: Elem, path: Path) => void, prefix: Path = []): void {
  elems.forEach((e, i) => {
    const p = [...prefix, i];
    f(e, p);
    if (e.kind === 'branch') e.legs.forEach((leg, l) => walk(leg, f, [...p, l]));
  });
}

/** A copy of the tree without ids and positions (for comparisons). */
export function strip(elems: Elem[]): Elem[] {
  return elems.map((e) =>
    e.kind === 'instr'
      ? { kind: 'instr', mnemonic: e.mnemonic, operands: [...e.operands] }
      : { kind: 'branch', legs: e.legs.map(strip) },
  );
}
