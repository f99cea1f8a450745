// Pure edits of a rung's element tree. Each returns a new tree (the input is
// not changed) and the path of the element to select afterwards.
import type { Elem, Instr, Path } from './ast';

export interface Edited {
  elements: Elem[];
  select: Path | null;
}

function clone(elems: Elem[]): Elem[] {
  return elems.map((e) =>
    e.kind === 'instr'
      ? { kind: 'instr', mnemonic: e.mnemonic, operands: [...e.operands] }
      : { kind: 'branch', legs: e.legs.map(clone) },
  );
}

/** The series holding the element at `path` and its index there. */
function seriesAt(root: Elem[], path: Path): { list: Elem[]; index: number } {
  let list = root;
  for (let k = 0; k + 1 < path.length; k += 2) {
    const b = list[path[k]];
    if (!b || b.kind !== 'branch') throw new Error(`no branch at ${path.slice(0, k + 1)}`);
    const leg = b.legs[path[k + 1]];
    if (!leg) throw new Error(`no leg at ${path.slice(0, k + 2)}`);
    list = leg;
  }
  const index = path[path.length - 1];
  if (index === undefined || index < 0 || index > list.length) throw new Error(`bad path ${path}`);
  return { list, index };
}

export function getAt(root: Elem[], path: Path): Elem | undefined {
  try {
    const { list, index } = seriesAt(root, path);
    return list[index];
  } catch {
    return undefined;
  }
}

/** A new instruction with `?` placeholders for its operands. */
export function newInstr(mnemonic: string, argCount: number): Instr {
  return { kind: 'instr', mnemonic, operands: Array.from({ length: argCount }, () => '?') };
}

/** Inserts `el` before or after the element at `path`; an empty path appends to the rung. */
export function insert(root: Elem[], path: Path | null, el: Elem, where: 'before' | 'after'): Edited {
  const elements = clone(root);
  if (!path || path.length === 0) {
    if (where === 'before') {
      elements.unshift(clone([el])[0]);
      return { elements, select: [0] };
    }
    elements.push(clone([el])[0]);
    return { elements, select: [elements.length - 1] };
  }
  const { list, index } = seriesAt(elements, path);
  const at = where === 'before' ? index : index + 1;
  list.splice(at, 0, clone([el])[0]);
  return { elements, select: [...path.slice(0, -1), at] };
}

/** Removes the element at `path`; an emptied leg goes, and a branch left with one leg is unwrapped. */
export function remove(root: Elem[], path: Path): Edited {
  const elements = clone(root);
  const { list, index } = seriesAt(elements, path);
  list.splice(index, 1);
  if (path.length >= 3 && list.length === 0) {
    const branchPath = path.slice(0, -2);
    const { list: outer, index: bi } = seriesAt(elements, branchPath);
    const b = outer[bi];
    if (b.kind === 'branch') {
      b.legs.splice(path[path.length - 2], 1);
      if (b.legs.length === 1) outer.splice(bi, 1, ...b.legs[0]);
      else if (b.legs.length === 0) outer.splice(bi, 1);
    }
    return { elements, select: null };
  }
  const select = list.length === 0 ? null : [...path.slice(0, -1), Math.min(index, list.length - 1)];
  return { elements, select };
}

/** Moves the element at `path` by `delta` places within its series. */
export function move(root: Elem[], path: Path, delta: number): Edited {
  const elements = clone(root);
  const { list, index } = seriesAt(elements, path);
  const to = index + delta;
  if (to < 0 || to >= list.length) return { elements, select: path };
  const [el] = list.splice(index, 1);
  list.splice(to, 0, el);
  return { elements, select: [...path.slice(0, -1), to] };
}

/** Puts the element at `path` in a branch whose second leg is `other`. */
export function wrapInBranch(root: Elem[], path: Path, other: Elem): Edited {
  const elements = clone(root);
  const { list, index } = seriesAt(elements, path);
  list[index] = { kind: 'branch', legs: [[list[index]], clone([other])] };
  return { elements, select: [...path, 1, 0] };
}

/** Adds a leg holding `el` to the branch at `path`. */
export function addLeg(root: Elem[], path: Path, el: Elem): Edited {
  const elements = clone(root);
  const { list, index } = seriesAt(elements, path);
  const b = list[index];
  if (b.kind !== 'branch') throw new Error('not a branch');
  b.legs.push(clone([el]));
  return { elements, select: [...path, b.legs.length - 1, 0] };
}

/** Replaces the operands (and optionally the mnemonic) of the instruction at `path`. */
export function setInstr(root: Elem[], path: Path, operands: string[], mnemonic?: string): Edited {
  const elements = clone(root);
  const { list, index } = seriesAt(elements, path);
  const e = list[index];
  if (e.kind !== 'instr') throw new Error('not an instruction');
  list[index] = { kind: 'instr', mnemonic: mnemonic ?? e.mnemonic, operands: [...operands] };
  return { elements, select: path };
}
