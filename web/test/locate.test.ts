import { describe, expect, it } from 'vitest';
import { parseProgram } from '../src/ladder/parse';
import { attachIds, locate } from '../src/ladder/locate';
import { FIXTURES } from './fixtures';

describe('ids and diagnostics by position', () => {
  it('attaches the server ids to the parsed tree', () => {
    const f = FIXTURES.find((x) => x.example === 'tank')!;
    const doc = parseProgram(f.text);
    expect(attachIds(doc, f.rungs)).toBe(34);
    const br = doc.rungs[7].elements![2];
    expect(br.kind === 'branch' && br.id).toBe(17);
    expect(br.kind === 'branch' && br.legs[1][0].id).toBe(19);
  });

  it('finds the innermost element at a diagnostic, or the rung', () => {
    const doc = parseProgram('// c\nXIC(Strat)[OTE(A),\n  OTE(B)];\n\nXIC(A OTE(B);\n');
    expect(locate(doc, 2, 5)).toEqual({ rung: 0, path: '0' });
    expect(locate(doc, 2, 11)).toEqual({ rung: 0, path: '1' });
    expect(locate(doc, 2, 12)).toEqual({ rung: 0, path: '1.0.0' });
    expect(locate(doc, 3, 3)).toEqual({ rung: 0, path: '1.1.0' });
    expect(locate(doc, 1, 1)).toEqual({ rung: 0, path: '' });
    expect(locate(doc, 5, 4)).toEqual({ rung: 1, path: '' });
    expect(locate(doc, 9, 1)).toBeNull();
  });
});
