// The designer's operations (issue 17, item 2): ids, copies, groups,
// alignment, distribution, layers, symbols, and the element of a problem.
import { describe, expect, it } from 'vitest';
import { align, copies, distribute, elementOf, group, newElement, restack, symbolOf, ungroup, withGroups } from '../src/hmi/edit';
import type { Element, Screen } from '../src/hmi/render';

const el = (id: string, x: number, y: number, w = 20, h = 10, extra: Partial<Element> = {}): Element => ({ id, type: 'rectangle', x, y, w, h, ...extra });
const screen = (...elements: Element[]): Screen => ({ schema: 1, width: 1000, height: 600, elements });

describe('the designer on a screen', () => {
  it('gives new elements and copies fresh ids, snapped places, and new groups', () => {
    const sc = screen(el('pump1', 0, 0, 60, 60, { type: 'pump' }));
    const p = newElement(sc, 'pump', 103, 97);
    expect(p).toMatchObject({ id: 'pump2', x: 70, y: 70, w: 60, h: 60 });
    sc.elements.push(el('a', 0, 0, 10, 10, { group: 'g1' }), el('b', 20, 0, 10, 10, { group: 'g1' }));
    const c = copies(sc, sc.elements.slice(1), 20, 20);
    expect(c.map((e) => [e.id, e.x, e.y, e.group])).toEqual([['rectangle1', 20, 20, 'g2'], ['rectangle2', 40, 20, 'g2']]);
    expect(sc.elements[1].x).toBe(0);
  });

  it('selects a group as a whole, groups and ungroups', () => {
    const sc = screen(el('a', 0, 0), el('b', 0, 0), el('c', 0, 0));
    expect(group(sc, new Set(['a', 'b']))).toBe('g1');
    expect([...withGroups(sc, ['a'])].sort()).toEqual(['a', 'b']);
    expect([...withGroups(sc, ['c'])]).toEqual(['c']);
    expect(group(sc, new Set(['c']))).toBe('g2');
    ungroup(sc, new Set(['a', 'b']));
    expect([...withGroups(sc, ['a'])]).toEqual(['a']);
  });

  it('aligns edges and centres, and distributes equal gaps', () => {
    const els = [el('a', 10, 5, 20, 10), el('b', 50, 40, 40, 30), el('c', 100, 0, 10, 10)];
    align(els, 'left');
    expect(els.map((e) => e.x)).toEqual([10, 10, 10]);
    align(els, 'bottom');
    expect(els.map((e) => e.y + e.h)).toEqual([70, 70, 70]);
    align(els, 'center');
    expect(els.map((e) => e.x + e.w / 2)).toEqual([30, 30, 30]);
    align(els, 'middle');
    expect(els.map((e) => e.y + e.h / 2)).toEqual([55, 55, 55]);
    const row = [el('a', 0, 0, 10), el('c', 100, 0, 20), el('b', 30, 0, 30)];
    distribute(row, 'h');
    // total 120 wide, 60 of elements: two gaps of 30
    expect(row.map((e) => e.x)).toEqual([0, 100, 40]);
  });

  it('brings to front and sends to back, keeping the order of what moves', () => {
    const sc = screen(el('a', 0, 0), el('b', 0, 0), el('c', 0, 0), el('d', 0, 0));
    restack(sc, new Set(['a', 'c']), 'front');
    expect(sc.elements.map((e) => e.id)).toEqual(['b', 'd', 'a', 'c']);
    restack(sc, new Set(['c', 'd']), 'back');
    expect(sc.elements.map((e) => e.id)).toEqual(['d', 'c', 'b', 'a']);
  });

  it('makes a symbol of a selection at its origin, and finds the element of a problem', () => {
    const sym = symbolOf([el('a', 100, 50, 20, 10, { group: 'g1' }), el('b', 130, 70, 20, 20, { group: 'g1' })]);
    expect(sym).toMatchObject({ schema: 1, width: 50, height: 40 });
    expect(sym.elements.map((e) => [e.x, e.y, e.group])).toEqual([[0, 0, undefined], [30, 20, undefined]]);
    expect(elementOf('`pump1`: animation `rotate`: unknown tag `Bomba9`')).toBe('pump1');
    expect(elementOf('schema 2 is newer than this version reads')).toBeNull();
  });
});
