import { describe, expect, it } from 'vitest';
import { type Elem, strip, walk } from '../src/ladder/ast';
import { parseBody, parseProgram, joinProgram } from '../src/ladder/parse';
import { printElements, printProgram, printRung } from '../src/ladder/print';
import { addLeg, insert, move, newInstr, remove, setInstr, wrapInBranch } from '../src/ladder/edit';
import { FIXTURES } from './fixtures';

const positions = (els: Elem[]) => {
  const out: string[] = [];
  walk(els, (e, p) => out.push(`${p.join('.')}@${e.line}:${e.col}`));
  return out;
};

describe('printer against the examples (server rungs JSON)', () => {
  for (const f of FIXTURES) {
    it(`${f.example}: every rung prints back to its source text`, () => {
      const doc = parseProgram(f.text);
      expect(doc.rungs.length).toBe(f.rungs.length);
      f.rungs.forEach((r, i) => {
        const own = doc.rungs[i].own.replace(/\r?\n$/, '');
        expect(printRung({ comment: r.comment, elements: r.elements })).toBe(own);
      });
    });
  }

  it('prints a whole program with one rung per line', () => {
    const f = FIXTURES.find((x) => x.example === 'start-stop')!;
    expect(printProgram(f.rungs)).toBe(f.text);
  });

  it('prints nested branches and operand-less instructions', () => {
    const els: Elem[] = [
      { kind: 'instr', mnemonic: 'xic', operands: ['A'] },
      {
        kind: 'branch',
        legs: [
          [{ kind: 'instr', mnemonic: 'OTE', operands: ['X'] }],
          [{ kind: 'branch', legs: [[{ kind: 'instr', mnemonic: 'AFI', operands: [] }], [{ kind: 'instr', mnemonic: 'NOP', operands: [] }]] }],
        ],
      },
    ];
    expect(printElements(els)).toBe('XIC(A)[OTE(X),[AFI(),NOP()]]');
  });
});

describe('client parser agrees with the server', () => {
  for (const f of FIXTURES) {
    it(`${f.example}: same trees, comments and positions`, () => {
      const doc = parseProgram(f.text);
      expect(doc.rungs.map((r) => r.error)).toEqual(f.rungs.map(() => null));
      doc.rungs.forEach((r, i) => {
        expect(strip(r.elements!)).toEqual(strip(f.rungs[i].elements));
        expect(r.comment).toEqual(f.rungs[i].comment);
        expect(positions(r.elements!)).toEqual(positions(f.rungs[i].elements));
      });
    });
    it(`${f.example}: text is kept exactly and print → parse round-trips`, () => {
      const doc = parseProgram(f.text);
      expect(joinProgram(doc)).toBe(f.text);
      const again = parseProgram(printProgram(f.rungs));
      expect(again.rungs.map((r) => strip(r.elements!))).toEqual(f.rungs.map((r) => strip(r.elements)));
    });
  }

  it('keeps blank lines, a same-line comment and trailing comments', () => {
    const text = '\n\n// a\nXIC(A)OTE(B); // b\n\nXIC(C)\n  OTE(D);\n// end\n';
    const doc = parseProgram(text);
    expect(doc.rungs).toHaveLength(2);
    expect(doc.rungs[0].comment).toEqual(['a', 'b']);
    expect(doc.rungs[0].lead).toBe('\n\n');
    expect(doc.rungs[1].comment).toEqual([]);
    expect(doc.rungs[1].elements![1]).toMatchObject({ mnemonic: 'OTE', line: 7, col: 3 });
    expect(doc.tail).toBe('// end\n');
    expect(joinProgram(doc)).toBe(text);
  });

  it('splits operands at the top level only and normalises spaces', () => {
    const { elements } = parseBody('CPT( X , ATAN2(A,B) *  2 )');
    expect(elements).toEqual([{ kind: 'instr', mnemonic: 'CPT', operands: ['X', 'ATAN2(A,B) * 2'], line: 1, col: 1, end: { line: 1, col: 27 } }]);
  });

  it('counts columns in characters, not UTF-16 units', () => {
    const doc = parseProgram('// 𝄞 clef\nXIC(A)OTE(B);\n');
    expect(doc.rungs[0].comment).toEqual(['𝄞 clef']);
    const { elements } = parseBody('XIC(A)OTE(B)', { line: 1, col: 3 });
    expect(elements![1]).toMatchObject({ col: 9 });
  });

  it('reports a broken rung with its place and keeps the others', () => {
    const doc = parseProgram('XIC(A)OTE(B);\nXIC(A OTE(B);\n[XIC(A),]OTE(B);\nXIC(C)OTE(D);\n');
    expect(doc.rungs).toHaveLength(4);
    expect(doc.rungs[1].elements).toBeNull();
    expect(doc.rungs[1].error).toMatchObject({ line: 2, col: 1 });
    expect(doc.rungs[1].error!.message).toContain('not closed');
    expect(doc.rungs[2].error).toMatchObject({ message: 'an empty branch leg', line: 3, col: 9 });
    expect(doc.rungs[3].elements).toHaveLength(2);
  });

  it('refuses a `]` inside operands, as the server does', () => {
    const { error } = parseBody('[XIC(Start,XIC(Motor)]XIO(Stop)OTE(Motor)');
    expect(error).toMatchObject({ line: 1, col: 22 });
    expect(error!.message).toContain('`]` inside the operands of `XIC`');
  });

  it('reports an unterminated last rung', () => {
    const doc = parseProgram('XIC(A)OTE(B);\nXIC(C)OTE(D)\n');
    expect(doc.rungs).toHaveLength(1);
    expect(doc.tailError?.message).toContain('no `;`');
    expect(joinProgram(doc)).toBe('XIC(A)OTE(B);\nXIC(C)OTE(D)\n');
  });
});

describe('tree edits', () => {
  const rung = () => parseBody('XIC(A)[XIC(B),XIC(C)]OTE(D)').elements!;
  const text = (els: Elem[]) => printElements(els);

  it('inserts before and after, at any depth', () => {
    const r = rung();
    expect(text(insert(r, [0], newInstr('XIO', 1), 'after').elements)).toBe('XIC(A)XIO(?)[XIC(B),XIC(C)]OTE(D)');
    const e = insert(r, [1, 1, 0], newInstr('XIO', 1), 'before');
    expect(text(e.elements)).toBe('XIC(A)[XIC(B),XIO(?)XIC(C)]OTE(D)');
    expect(e.select).toEqual([1, 1, 0]);
    expect(text(r)).toBe('XIC(A)[XIC(B),XIC(C)]OTE(D)'); // unchanged input
    expect(text(insert([], null, newInstr('NOP', 0), 'after').elements)).toBe('NOP()');
  });

  it('removes, dropping an emptied leg and unwrapping a one-leg branch', () => {
    expect(text(remove(rung(), [0]).elements)).toBe('[XIC(B),XIC(C)]OTE(D)');
    expect(text(remove(rung(), [1, 0, 0]).elements)).toBe('XIC(A)XIC(C)OTE(D)');
    const three = parseBody('[XIC(A),XIC(B),XIC(C)]OTE(D)').elements!;
    expect(text(remove(three, [0, 1, 0]).elements)).toBe('[XIC(A),XIC(C)]OTE(D)');
  });

  it('moves within a series and not past its ends', () => {
    expect(text(move(rung(), [0], 1).elements)).toBe('[XIC(B),XIC(C)]XIC(A)OTE(D)');
    expect(move(rung(), [0], -1).select).toEqual([0]);
    expect(text(move(rung(), [2], -1).select ? move(rung(), [2], -1).elements : [])).toBe('XIC(A)OTE(D)[XIC(B),XIC(C)]');
  });

  it('wraps in a branch, adds a leg, sets operands', () => {
    const w = wrapInBranch(rung(), [0], newInstr('XIC', 1));
    expect(text(w.elements)).toBe('[XIC(A),XIC(?)][XIC(B),XIC(C)]OTE(D)');
    expect(w.select).toEqual([0, 1, 0]);
    expect(text(addLeg(rung(), [1], newInstr('XIO', 1)).elements)).toBe('XIC(A)[XIC(B),XIC(C),XIO(?)]OTE(D)');
    expect(text(setInstr(rung(), [2], ['Lamp'], 'OTL').elements)).toBe('XIC(A)[XIC(B),XIC(C)]OTL(Lamp)');
  });
});
