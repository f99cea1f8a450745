import { describe, expect, it } from 'vitest';
import { layoutRung } from '../src/ladder/layout';
import { parseProgram } from '../src/ladder/parse';
import { attachIds } from '../src/ladder/locate';
import { renderRung } from '../src/ladder/render';
import { ValueStore } from '../src/live/client';
import { FIXTURES } from './fixtures';
import type { Json } from '../src/types';

function tankRung(n: number) {
  const f = FIXTURES.find((x) => x.example === 'tank')!;
  const doc = parseProgram(f.text);
  attachIds(doc, f.rungs);
  return doc.rungs[n];
}

describe('rung SVG', () => {
  it('has an element per instruction and branch with its test id, and live values in boxes', () => {
    const r = tankRung(1); // XIC(STOP)ONS(STOP_ONS)CTU(CT_STP,2,0)
    const store = new ValueStore();
    const v = renderRung(layoutRung(r.elements!, r.comment.length, 600), { number: 1, comment: r.comment, problems: new Map(), selected: '2', forced: new Set(['STOP']) }, store);
    document.body.append(v.svg);
    const ids = [...v.svg.querySelectorAll('[data-testid^="el-"]')].map((e) => e.getAttribute('data-testid'));
    expect(ids).toEqual(['el-2', 'el-3', 'el-4']);
    expect(v.svg.querySelector('[data-testid="el-4"]')!.classList.contains('selected')).toBe(true);
    expect(v.svg.querySelector('[data-testid="el-2"] .forced-badge')).not.toBeNull();
    // Preset and Accum: one number a row, the literal until the live value comes (issue 30, item 23)
    const acc = v.svg.querySelector('[data-tag="CT_STP.ACC"]')!;
    const row = (label: string) => [...v.svg.querySelectorAll('text.label')].find((t) => t.textContent === label)!;
    const numbersIn = (label: string) => [...v.svg.querySelectorAll('text')].filter((t) => t.getAttribute('y') === row(label).getAttribute('y') && /^\d/.test(t.firstChild?.textContent ?? ''));
    expect(acc.textContent).toBe('0');
    store.apply(new Map<string, Json>([['CT_STP.ACC', 1], ['CT_STP.DN', true], ['CT_STP.PRE', 2]]));
    expect(acc.textContent).toBe('1');
    expect(numbersIn('Accum').length).toBe(1);
    expect(numbersIn('Preset').length).toBe(1);
    expect(acc.parentElement!.querySelector('title')!.textContent).toBe('CT_STP.ACC now; 0 in the program');
    expect(v.svg.querySelector('[data-bit="DN"]')!.classList.contains('bit-on')).toBe(true);
    v.dispose();
    store.apply(new Map([['CT_STP.ACC', 2]]));
    expect(acc.textContent).toBe('1');
  });

  it('marks energised elements and the wires they feed, touching only what changed', () => {
    const r = tankRung(7); // XIC(Llenar)XIO(L_STP)[OTE(Bomba1),OTE(L_FILL)]: ids 15..19
    const v = renderRung(layoutRung(r.elements!, 0, 600), { number: 7, comment: [], problems: new Map(), selected: null, forced: new Set() }, null);
    const on = (id: number) => v.svg.querySelector(`[data-testid="el-${id}"]`)!.getAttribute('data-on');
    v.setPower(new Set([15, 16, 17, 18, 19]), true);
    expect([15, 16, 17, 18, 19].map(on)).toEqual(['true', 'true', 'true', 'true', 'true']);
    const lit = v.svg.querySelectorAll('line.wire.on').length;
    expect(lit).toBeGreaterThan(5);
    v.setPower(new Set([16]), true); // Llenar false: only XIO(L_STP) true in isolation
    expect([15, 16, 17].map(on)).toEqual(['false', 'true', 'false']);
    expect(v.svg.querySelectorAll('line.wire.on').length).toBeLessThan(lit);
    v.setPower(new Set([15, 16, 17, 18, 19]), false); // stopped: nothing is energised
    expect(v.svg.querySelectorAll('[data-on="true"]').length).toBe(0);
    expect(v.svg.querySelectorAll('line.wire.on').length).toBe(0);
  });

  it('outlines elements with problems and gives them the message as tooltip', () => {
    const doc = parseProgram('XIC(Strat)OTE(B);\n');
    const r = doc.rungs[0];
    const v = renderRung(layoutRung(r.elements!), { number: 0, comment: [], problems: new Map([['0', ['E301: unknown tag `Strat`']]]), selected: null, forced: new Set() }, null);
    const el = v.svg.querySelector('[data-testid="el-r0-0"]')!;
    expect(el.classList.contains('error')).toBe(true);
    expect(el.querySelector('title')!.textContent).toContain('unknown tag');
  });
});
