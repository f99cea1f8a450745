import { describe, expect, it } from 'vitest';
import { G, layoutRung, measure, powered, type PlacedInstr, type Wire } from '../src/ladder/layout';
import { parseBody } from '../src/ladder/parse';
import type { Elem } from '../src/ladder/ast';

const tree = (t: string): Elem[] => parseBody(t).elements!;
const withIds = (els: Elem[]): Elem[] => {
  let n = 0;
  const go = (es: Elem[]): void =>
    es.forEach((e) => {
      e.id = n++;
      if (e.kind === 'branch') e.legs.forEach(go);
    });
  go(els);
  return els;
};
const vertical = (ws: Wire[]) => ws.filter((w) => w.x1 === w.x2);

describe('element sizes', () => {
  it('contacts and coils are one cell; boxes are wider and grow with their operands', () => {
    const c = measure(tree('XIC(A)')[0]);
    expect(c).toEqual({ w: G.contactW, asc: G.contactAsc, desc: G.contactDesc });
    const coil = measure(tree('OTE(A)')[0]);
    expect(coil.w).toBe(G.contactW);
    const long = measure(tree('XIC(A_very_long_tag_name_indeed)')[0]);
    expect(long.w).toBeGreaterThan(G.contactW);
    const ton = measure(tree('TON(T1,5000,0)')[0]);
    const scp = measure(tree('SCP(S_ULT,0,1023,0.0,1.5,Nivel_m)')[0]);
    expect(ton.w).toBeGreaterThanOrEqual(G.boxMinW);
    expect(scp.asc + scp.desc - (ton.asc + ton.desc)).toBe(3 * G.boxRow);
    const cpt = measure(tree(`CPT(X,${'A+'.repeat(200)}B)`)[0]);
    expect(cpt.w).toBe(G.boxMaxW);
  });
});

describe('rung layout', () => {
  it('puts a series side by side on one wire, from the left rail to the right rail', () => {
    const l = layoutRung(tree('XIC(A)XIO(B)OTE(C)'), 0, 500);
    const items = l.items as PlacedInstr[];
    expect(items.map((i) => i.x)).toEqual([G.gap, 2 * G.gap + G.contactW, 3 * G.gap + 2 * G.contactW]);
    expect(items.map((i) => i.shape)).toEqual(['contact', 'contact', 'coil']);
    expect(new Set(items.map((i) => i.wire))).toEqual(new Set([l.wire]));
    expect(l.rail).toBe(500);
    const last = l.wires[l.wires.length - 1];
    expect([last.x1, last.x2]).toEqual([3 * G.gap + 3 * G.contactW, 500]);
    expect(l.wires.every((w) => w.y1 === l.wire && w.y2 === l.wire)).toBe(true);
  });

  it('widens the rail for a long rung and leaves room for comment lines', () => {
    const a = layoutRung(tree('XIC(A)OTE(B)'), 0, 10);
    const b = layoutRung(tree('XIC(A)OTE(B)'), 2, 10);
    expect(a.rail).toBe(2 * (G.gap + G.contactW) + G.tail);
    expect(b.wire - a.wire).toBe(2 * G.commentLine);
    expect(b.height - a.height).toBe(2 * G.commentLine);
  });

  it('stacks branch legs below one another, joined by vertical rails at both ends', () => {
    const l = layoutRung(tree('XIC(A)[XIC(B)XIC(C),XIC(D),XIO(E)]OTE(F)'));
    const br = l.items.find((i) => i.kind === 'branch')!;
    const legs = l.items.filter((i) => i.kind === 'instr' && i.path.length === 3) as PlacedInstr[];
    expect(legs.map((i) => i.path.join('.'))).toEqual(['1.0.0', '1.0.1', '1.1.0', '1.2.0']);
    const ys = [...new Set(legs.map((i) => i.wire))];
    expect(ys).toHaveLength(3);
    expect(ys[0]).toBe(l.wire);
    expect(ys[1] - ys[0]).toBe(G.contactDesc + G.legGap + G.contactAsc);
    expect(ys[2] - ys[1]).toBe(ys[1] - ys[0]);
    // the branch is as wide as its widest leg plus a gap
    expect(br.w).toBe(2 * (G.gap + G.contactW) + G.gap);
    // vertical rails: 2 segments on the left at br.x, 2 on the right at br.x + br.w
    const v = vertical(l.wires);
    expect(v.filter((w) => w.x1 === br.x).map((w) => [w.y1, w.y2])).toEqual([[ys[0], ys[1]], [ys[1], ys[2]]]);
    expect(v.filter((w) => w.x1 === br.x + br.w).map((w) => [w.y1, w.y2])).toEqual([[ys[0], ys[1]], [ys[1], ys[2]]]);
    // short legs get a wire to the right rail
    const ext = l.wires.filter((w) => w.y1 === ys[1] && w.y2 === ys[1] && w.x2 === br.x + br.w);
    expect(ext).toHaveLength(1);
    // the coil after the branch starts after it
    const coil = l.items.find((i) => i.path.join('.') === '2')!;
    expect(coil.x).toBe(br.x + br.w + G.gap);
    expect(l.height).toBe(ys[2] + G.contactDesc + G.bottom);
  });

  it('nests branches', () => {
    const l = layoutRung(tree('[XIC(A),XIC(B)[XIC(C),XIC(D)]]OTE(E)'));
    const inner = l.items.find((i) => i.kind === 'branch' && i.path.length === 3)!;
    const outer = l.items.find((i) => i.kind === 'branch' && i.path.length === 1)!;
    expect(inner.wire).toBeGreaterThan(outer.wire);
    expect(inner.x + inner.w).toBeLessThanOrEqual(outer.x + outer.w);
    const d = l.items.find((i) => i.path.join('.') === '0.1.1.1.0')!;
    expect(d.wire).toBeGreaterThan(inner.wire);
  });
});

describe('power flow on wires', () => {
  it('feeds each wire from the element before it, legs from the branch input, the right rail from the legs below', () => {
    // ids: XIC(A)=0, branch=1, XIC(B)=2, XIC(C)=3, XIC(D)=4, OTE(E)=5
    const l = layoutRung(withIds(tree('XIC(A)[XIC(B),XIC(C),XIC(D)]OTE(E)')));
    expect(l.wires[0].src).toEqual(['rail']);
    const br = l.items.find((i) => i.kind === 'branch')!;
    const right = vertical(l.wires).filter((w) => w.x1 === br.x + br.w);
    expect(right.map((w) => w.src)).toEqual([[3, 4], [4]]);
    const left = vertical(l.wires).filter((w) => w.x1 === br.x);
    expect(left.map((w) => w.src)).toEqual([[0], [0]]);
    expect(l.wires[l.wires.length - 1].src).toEqual([5]);
    const on = new Set([0, 1, 4]);
    expect(right.map((w) => powered(w, on, true))).toEqual([true, true]);
    expect(right.map((w) => powered(w, new Set([0, 1, 3]), true))).toEqual([true, false]);
    expect(powered(l.wires[0], on, false)).toBe(false);
  });

  it('leaves wires unpowered when the ids are unknown', () => {
    const l = layoutRung(tree('XIC(A)OTE(B)'));
    expect(l.wires.slice(1).every((w) => w.src.length === 0)).toBe(true);
  });
});
