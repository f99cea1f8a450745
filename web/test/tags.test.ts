import { describe, expect, it } from 'vitest';
import { csvField, lineOfDefs, parseCsv, parseTagsCsv, tagsCsv, validateDef, type TagDef } from '../src/tags/csv';
import { matches, tableRows } from '../src/tags/view';
import type { TagInfo } from '../src/types';

const TANK = `name,type,address,initial,retain,description
Bomba1,BOOL,DO:2/0,,,pump B1 (fills the tank)
S_ULT,INT,AI:3/0,575,,ultrasonic level sensor S1 (raw 0 = empty and 1023 = full)
CT_STP,COUNTER,,,,STOP presses (ACC = 1 while stopped)
`;

const def = (o: Partial<TagDef>): TagDef => ({ name: '', type: 'BOOL', address: '', initial: '', retain: '', description: '', ...o });

describe('CSV', () => {
  it('reads quotes, doubled quotes, commas and line breaks in fields, CRLF, blank lines', () => {
    const rows = parseCsv('a,b\r\n\r\n"x, y","say ""hi""" \r\n"two\nlines",  z  \n');
    expect(rows).toEqual([['a', 'b'], ['x, y', 'say "hi"'], ['two\nlines', 'z']]);
  });

  it('quotes only the fields that need it', () => {
    expect(['plain', 'a,b', 'q"', 'l\nb', ' pad'].map(csvField)).toEqual(['plain', '"a,b"', '"q"""', '"l\nb"', '" pad"']);
  });

  it('round-trips the example tag table exactly', () => {
    expect(tagsCsv(parseTagsCsv(TANK))).toBe(TANK);
  });

  it('keeps the column order of the file and adds a column a definition needs', () => {
    const f = parseTagsCsv('type,name\nBOOL,A\n');
    expect(f.columns).toEqual(['type', 'name']);
    expect(tagsCsv(f)).toBe('type,name\nBOOL,A\n');
    f.defs.push(def({ name: 'B', type: 'DINT', description: 'has, comma' }));
    expect(tagsCsv(f)).toBe('type,name,description\nBOOL,A,\nDINT,B,"has, comma"\n');
  });

  it('gives each definition its line in the written file', () => {
    const f = parseTagsCsv(TANK);
    expect(lineOfDefs(f)).toEqual([2, 3, 4]);
    f.defs[0].description = 'two\nlines';
    expect(lineOfDefs(f)).toEqual([2, 4, 5]);
  });

  it('validates names and types before sending', () => {
    const others = parseTagsCsv(TANK).defs;
    expect(validateDef(def({ name: 'New_1' }), others)).toBeNull();
    expect(validateDef(def({ name: '' }), others)).toMatch(/needs a name/);
    expect(validateDef(def({ name: '1x' }), others)).toMatch(/digit/);
    expect(validateDef(def({ name: 'bomba1' }), others)).toMatch(/already/);
    expect(validateDef(def({ name: 'MOD' }), others)).toMatch(/reserved/);
    expect(validateDef(def({ name: 'X', type: 'WORD' }), others)).toMatch(/Unknown type/);
    expect(validateDef(def({ name: 'X', type: 'PID' }), others)).toBeNull();
  });
});

describe('tag table rows', () => {
  const tags: TagInfo[] = [
    { name: 'Start', type: 'BOOL', address: 'DI:1/0', notations: ['DI:1/0', '%IX0.0', '%I0.0', 'I0.0'], description: 'start button', retain: false, access: 'input', value: false, forced: null },
    { name: 'Delay', type: 'TIMER', address: null, notations: [], description: '', retain: false, access: 'readwrite', value: {}, forced: null },
    { name: 'S:FS', type: 'BOOL', address: null, notations: [], description: 'first scan', retain: false, access: 'readonly', value: false, forced: null },
  ];

  it('lists structure members after their tag, with their access', () => {
    const rows = tableRows(tags);
    expect(rows.map((r) => r.name)).toEqual(['Start', 'Delay', 'Delay.PRE', 'Delay.ACC', 'Delay.EN', 'Delay.TT', 'Delay.DN', 'S:FS']);
    expect(rows.find((r) => r.name === 'Delay.ACC')!.access).toBe('readwrite');
    expect(rows.find((r) => r.name === 'Delay.DN')!.access).toBe('readonly');
    expect(rows[0].io).toBe(true);
    expect(rows[rows.length - 1].io).toBe(false);
  });

  it('filters on every word in name, type, address and description', () => {
    const rows = tableRows(tags);
    expect(rows.filter((r) => matches(r, 'di:1')).map((r) => r.name)).toEqual(['Start']);
    expect(rows.filter((r) => matches(r, 'delay dn')).map((r) => r.name)).toEqual(['Delay.DN']);
    expect(rows.filter((r) => matches(r, '')).length).toBe(rows.length);
  });
});
