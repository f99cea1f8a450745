import { describe, expect, it } from 'vitest';
import { TagCache } from '../src/ctx';
import { domain, instruction, membersOf } from '../src/domain';
import { operandLabels, operandTags, shapeOf, titleOf } from '../src/ladder/ast';
import { boxRows, boxStatusBits, layoutRung } from '../src/ladder/layout';
import { parseProgram } from '../src/ladder/parse';
import { renderRung } from '../src/ladder/render';
import { ValueStore } from '../src/live/client';
import { tableRows } from '../src/tags/view';
import type { Json, TagInfo } from '../src/types';

// Tags as GET /api/tags lists them: `notations` are what alba_ladder::domain::notations gives.
const tag = (name: string, type: string, address: string | null = null, notations: string[] = []): TagInfo => ({
  name,
  type,
  address,
  notations,
  description: '',
  retain: false,
  access: address?.startsWith('DI') || address?.startsWith('AI') ? 'input' : 'readwrite',
  value: null,
  forced: null,
});
const TAGS: TagInfo[] = [
  tag('Lamp', 'BOOL', 'DI:1/1', ['DI:1/1', '%IX0.1', '%I0.1', 'I0.1']),
  tag('Valve', 'BOOL', 'DO:2/10', ['DO:2/10', '%QX1.2', '%Q1.2', 'Q1.2']),
  tag('Key', 'BOOL', 'DI:1/15', ['DI:1/15', '%IX1.7', '%I1.7', 'I1.7']),
  tag('Level', 'INT', 'AI:3/3', ['AI:3/3', '%IW3', 'AIW6', 'AIN3']),
  tag('Drive', 'INT', 'AO:4/2', ['AO:4/2', '%QW2', 'AQW4']),
  tag('Flag', 'BOOL', 'M0.4', ['M0.4', '%MX0.4', '%M0.4']),
  tag('Word', 'INT', 'MW4', ['MW4', '%MW2']),
  tag('Odd', 'INT', 'MW3', ['MW3']),
  tag('Delay', 'TIMER'),
  tag('Loop', 'PID'),
  tag('Out', 'REAL'),
];

describe('the domain from the server', () => {
  it('has exactly the fields domain.ts declares (the fixture is the server reply)', () => {
    const keys = (o: object) => Object.keys(o).sort();
    const d = domain();
    expect(keys(d)).toEqual(['args', 'groups', 'instructions', 'routes', 'screens', 'types']);
    expect(keys(d.screens)).toEqual(['actions', 'animations', 'elements', 'properties']);
    for (const t of d.types) {
      expect(keys(t)).toEqual(['kind', 'members', 'name']);
      expect(['bool', 'integer', 'real', 'structure']).toContain(t.kind);
      for (const m of t.members) expect(keys(m)).toEqual(['name', 'type', 'writable']);
    }
    for (const g of d.groups) expect(keys(g)).toEqual(['name', 'title']);
    for (const a of d.args) expect(keys(a)).toEqual(['doc', 'members', 'name', 'tag', 'types', 'writable']);
    for (const i of d.instructions) {
      expect(keys(i)).toEqual(['args', 'bits', 'doc', 'group', 'labels', 'mnemonic', 'optional', 'output', 'shape', 'shows', 'title']);
      for (const o of i.optional) expect(keys(o)).toEqual(['choices', 'default', 'doc', 'label', 'name']);
      expect(['contact', 'coil', 'box']).toContain(i.shape);
    }
  });

  it('has the palette groups in order, PID back in the last one', () => {
    expect(domain().groups.map((g) => g.name)).toEqual(['bit', 'timer', 'counter', 'compare', 'math', 'move', 'trig', 'flow', 'special']);
    const pid = instruction('pid')!;
    expect(pid.group).toBe('special');
    expect(pid.args).toEqual(['pid', 'num_in', 'num_out']);
    expect(domain().instructions.filter((i) => i.group === 'special').map((i) => i.mnemonic)).toEqual(['PID']);
  });

  it('draws contacts and coils for the one-bit instructions, boxes for the rest', () => {
    const shapes = domain().instructions.map((i) => [i.mnemonic, shapeOf(i.mnemonic)]);
    expect(shapes.filter(([, s]) => s === 'contact').map(([m]) => m)).toEqual(['XIC', 'XIO', 'ONS']);
    expect(shapes.filter(([, s]) => s === 'coil').map(([m]) => m)).toEqual(['OTE', 'OTL', 'OTU']);
    expect(shapeOf('xic')).toBe('contact');
    expect(shapeOf('FOO')).toBe('box');
  });

  it('labels every operand and titles every instruction', () => {
    expect(operandLabels('TOF', 3)).toEqual(['Timer', 'Preset', 'Accum']);
    expect(operandLabels('CTD', 3)).toEqual(['Counter', 'Preset', 'Accum']);
    expect(operandLabels('OSF', 2)).toEqual(['Storage Bit', 'Output Bit']);
    expect(operandLabels('NEG', 2)).toEqual(['Source', 'Dest']);
    expect(operandLabels('GEQ', 2)).toEqual(['Source A', 'Source B']);
    expect(operandLabels('SCP', 6)).toEqual(['Input', 'Input Min', 'Input Max', 'Scaled Min', 'Scaled Max', 'Output']);
    expect(operandLabels('PID', 3)).toEqual(['PID', 'Process Var', 'Control Var']);
    expect(operandLabels('FOO', 2)).toEqual(['Operand 1', 'Operand 2']);
    expect(titleOf('XPY')).toBe('X to the Power of Y');
    for (const i of domain().instructions) expect(i.labels.length, i.mnemonic).toBe(i.args.length);
  });

  it('knows which operands name tags (not labels, expressions or accumulators)', () => {
    const i = (mnemonic: string, operands: string[]) => ({ kind: 'instr' as const, mnemonic, operands });
    expect(operandTags(i('JMP', ['Skip']))).toEqual([]);
    expect(operandTags(i('CPT', ['Out', 'Level*2']))).toEqual(['Out']);
    expect(operandTags(i('TON', ['Delay', 'Pre', '0']))).toEqual(['Delay', 'Pre']);
    expect(operandTags(i('PID', ['Loop', 'Level', 'Out']))).toEqual(['Loop', 'Level', 'Out']);
  });

  it('gives structures their members, PID included', () => {
    expect(membersOf('TIMER').map((m) => m.name)).toEqual(['PRE', 'ACC', 'EN', 'TT', 'DN']);
    expect(membersOf('COUNTER').map((m) => m.name)).toEqual(['PRE', 'ACC', 'CU', 'CD', 'DN', 'OV', 'UN']);
    expect(membersOf('PID').find((m) => m.name === 'SP')).toEqual({ name: 'SP', type: 'REAL', writable: true });
    expect(membersOf('DINT')).toEqual([]);
    const rows = tableRows([tag('Loop', 'PID')]);
    expect(rows.find((r) => r.name === 'Loop.ERRC')).toMatchObject({ type: 'DINT', access: 'readonly' });
    expect(rows.find((r) => r.name === 'Loop.MAN')).toMatchObject({ type: 'BOOL', access: 'readwrite' });
  });
});

describe('operands and the tag cache', () => {
  const cache = new TagCache();
  cache.set(TAGS);

  it('finds the tag on an address written in any notation', () => {
    const on = (op: string) => cache.resolve(op)?.name ?? null;
    expect(on('Ain3')).toBe('Level');
    expect(on('AIW6')).toBe('Level');
    expect(on('%iw3')).toBe('Level');
    expect(on('I0.1')).toBe('Lamp');
    expect(on('q1.2')).toBe('Valve');
    expect(on('%IX1.7')).toBe('Key');
    expect(on('%QW2')).toBe('Drive');
    expect(on('%MX0.4')).toBe('Flag');
    // IEC %MWn is the n-th word, S7 MWn starts at byte n
    expect(on('%MW2')).toBe('Word');
    expect(on('MW3')).toBe('Odd');
    expect(on('DI:1/01')).toBe('Lamp');
    expect(on('AIW3')).toBeNull();
    expect(on('%MW3')).toBeNull();
  });

  it('resolves members with their type and access', () => {
    expect(cache.resolve('delay.dn')).toMatchObject({ name: 'Delay.DN', type: 'BOOL', access: 'readonly' });
    expect(cache.resolve('Delay.PRE')).toMatchObject({ type: 'DINT', access: 'readwrite' });
    expect(cache.resolve('Loop.CV')).toMatchObject({ name: 'Loop.CV', type: 'REAL', access: 'readwrite' });
    expect(cache.resolve('Loop.NOPE')).toBeNull();
  });

  it('offers the tags that fit each operand kind', () => {
    expect(cache.choices('pid')).toEqual(['Loop']);
    expect(cache.choices('timer')).toEqual(['Delay']);
    expect(cache.choices('timer_or_counter')).toEqual(['Delay']);
    const bitIn = cache.choices('bit_in');
    expect(bitIn).toEqual(expect.arrayContaining(['Lamp', 'Delay.DN', 'Loop.MAN', 'Loop.UL']));
    const bitOut = cache.choices('bit_out');
    expect(bitOut).toContain('Loop.MAN');
    expect(bitOut).not.toContain('Lamp');
    expect(bitOut).not.toContain('Delay.DN');
    const numOut = cache.choices('num_out');
    expect(numOut).toEqual(expect.arrayContaining(['Drive', 'Out', 'Delay.PRE', 'Delay.ACC', 'Loop.SP']));
    expect(numOut).not.toContain('Level');
    expect(numOut).not.toContain('Loop.PV');
    expect(cache.choices('num_in')).toContain('Level');
    expect(cache.choices('preset')).not.toContain('Out');
    expect(cache.choices('label')).toEqual([]);
  });
});

describe('a PID box', () => {
  it('shows its operands with their labels, the live PV and CV, and its status bits', () => {
    const doc = parseProgram('XIC(Lamp)PID(Loop,Level,Out);\n');
    const pid = doc.rungs[0].elements![1];
    expect(pid.kind === 'instr' && boxRows(pid)).toEqual([['PID', 'Loop'], ['Process Var', 'Level'], ['Control Var', 'Out']]);
    expect(pid.kind === 'instr' && boxStatusBits(pid)).toEqual(['EN', 'DN', 'MAN']);
    const store = new ValueStore();
    const v = renderRung(layoutRung(doc.rungs[0].elements!, 0, 600), { number: 0, comment: [], problems: new Map(), selected: null, forced: new Set() }, store);
    document.body.append(v.svg);
    const box = v.svg.querySelector('[data-testid="el-r0-1"]')!;
    expect(box.classList.contains('el-box')).toBe(true);
    expect([...box.querySelectorAll('text.label')].map((t) => t.textContent)).toEqual(['PID', 'Process Var', 'Control Var']);
    expect([...box.querySelectorAll('[data-tag]')].map((t) => t.getAttribute('data-tag'))).toEqual(['Level', 'Out']);
    store.apply(new Map<string, Json>([['Level', 412], ['Out', 55.5], ['Loop.MAN', true]]));
    expect(box.querySelector('[data-tag="Out"]')!.textContent).toBe('55.5');
    expect(box.querySelector('[data-bit="MAN"]')!.classList.contains('bit-on')).toBe(true);
    v.dispose();
    v.svg.remove();
  });
});

describe('the tag cache', () => {
  it('tells its listeners when more than the values changed, not otherwise', () => {
    const tags = new TagCache();
    let heard = 0;
    tags.onChange(() => heard++);
    const tag = (value: number, description = '') => ({ name: 'Level', type: 'REAL', address: null, notations: [], description, retain: false, access: 'readwrite' as const, value, forced: null });
    tags.set([tag(1)]);
    // a refresh that only brings new values redraws nothing (a long press keeps its row)
    tags.set([tag(2)]);
    expect([heard, tags.get('level')?.value]).toEqual([1, 2]);
    tags.set([tag(2, 'the tank')]);
    tags.set([tag(2, 'the tank')], [{ name: 'Level', value: 5 }]);
    expect(heard).toBe(3);
  });
});
