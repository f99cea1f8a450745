// Prints the element tree back to the ladder text of docs/ladder.md.
import type { Elem, Rung } from './ast';

export function printElements(elems: Elem[]): string {
  return elems
    .map((e) =>
      e.kind === 'instr'
        ? `${e.mnemonic.toUpperCase()}(${e.operands.map((o) => o.trim()).join(',')})`
        : `[${e.legs.map(printElements).join(',')}]`,
    )
    .join('');
}

/** One rung: its comment lines, then the rung on one line, ended by `;` (no final newline). */
export function printRung(r: Rung): string {
  const comment = r.comment.map((c) => (c.trim() === '' ? '//' : `// ${c.trim()}`));
  return [...comment, `${printElements(r.elements)};`].join('\n');
}

export function printProgram(rungs: Rung[]): string {
  return rungs.map((r) => printRung(r) + '\n').join('');
}
