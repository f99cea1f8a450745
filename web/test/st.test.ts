import { describe, expect, it } from 'vitest';
import { membersOf } from '../src/domain';
import { callee, instancesOf, nameAt, complete, declarations, formatValue, highlight, inCommentOrString, indentAfter, lex, markRange, namesByLine, pouAt, tagOf, timeLiteral, wordAt } from '../src/st/parse';

const MOTOR = `(* Start/stop (* nested *) with seal-in *)
PROGRAM Main
VAR
    delay : TON;          (* the tag Main.delay *)
    starts : CTU;
    a : ARRAY[1..3] OF INT := [1, 2, 3];
    p : Point;
    i : INT;
END_VAR
Motor := (Start OR Motor) AND NOT Stop; // seal-in
delay(IN := Motor, PT := T#5s, Q => Lamp);
starts(CU := Motor, PV := 1000);
a[2] := a[i] + LIMIT(0, i, 16#FF);
p.x := REAL#1.5E3;
IF delay.Q THEN i := starts.CV; END_IF;
END_PROGRAM
TYPE Point : STRUCT x : REAL; y : REAL; END_STRUCT; END_TYPE
`;

const tags = [
  { name: 'Start', type: 'BOOL' },
  { name: 'Stop', type: 'BOOL' },
  { name: 'Motor', type: 'BOOL' },
  { name: 'Lamp', type: 'BOOL' },
  { name: 'T1', type: 'TIMER' },
  { name: 'Main.i', type: 'INT' },
];
const env = { tags, members: (t: string) => membersOf(t).map((m) => m.name) };

describe('ST highlighting', () => {
  it('colours keywords, types, functions, literals and comments, line by line', () => {
    const lines = highlight(MOTOR);
    expect(lines).toHaveLength(MOTOR.split('\n').length);
    // a nested comment is one comment
    expect(lines[0]).toEqual([{ cls: 'st-com', text: '(* Start/stop (* nested *) with seal-in *)' }]);
    expect(lines[1]).toEqual([{ cls: 'st-kw', text: 'PROGRAM' }, { cls: '', text: ' Main' }]);
    const cls = (n: number, text: string) => lines[n - 1].find((s) => s.text.includes(text))?.cls;
    expect(cls(4, 'TON')).toBe('st-type');
    expect(cls(4, '(* the tag')).toBe('st-com');
    expect(cls(10, 'AND')).toBe('st-kw');
    expect(cls(10, '// seal-in')).toBe('st-com');
    expect(cls(11, 'T#5s')).toBe('st-num');
    expect(cls(13, 'LIMIT')).toBe('st-fn');
    expect(cls(13, '16#FF')).toBe('st-num');
    expect(cls(14, 'REAL#1.5E3')).toBe('st-num');
    // the text is kept exactly
    expect(lines.map((l) => l.map((s) => s.text).join('')).join('\n')).toBe(MOTOR);
  });
  it('lexes strings, ranges, operators and typed literals', () => {
    const kinds = (s: string) => lex(s).filter((t) => t.kind !== 'space').map((t) => `${t.kind}:${t.text}`);
    expect(kinds("s := 'it$'s';")).toEqual(['ident:s', 'op::=', "string:'it$'s'", 'op:;']);
    expect(kinds('1..5:')).toEqual(['number:1', 'op:..', 'number:5', 'op::']);
    expect(kinds('x := INT#-5 ** 2;')).toEqual(['ident:x', 'op::=', 'number:INT#-5', 'op:**', 'number:2', 'op:;']);
    expect(kinds('c := Color#Red; t := TIME#-1.5s')).toContain('number:Color#Red');
    expect(kinds('t := TIME#-1.5s')).toContain('number:TIME#-1.5s');
    expect(kinds('x := INT_TO_REAL(n)')).toContain('builtin:INT_TO_REAL');
    expect(lex('(* open').map((t) => t.kind)).toEqual(['comment']);
  });
});

describe('ST problem places', () => {
  const line = highlight('count := Motr + 1; (* c *)')[0];
  const bad = (spans: ReturnType<typeof markRange>) => spans.filter((s) => s.cls.includes('st-bad')).map((s) => s.text).join('');
  it('underlines the columns of a problem, splitting spans and keeping their colours', () => {
    const m = markRange(line, 10, 14);
    expect(bad(m)).toBe('Motr');
    expect(m.map((s) => s.text).join('')).toBe('count := Motr + 1; (* c *)');
    expect(bad(markRange(line, 17, 21))).toBe('1; (');
    expect(markRange(line, 17, 21).find((s) => s.text === '(')?.cls).toBe('st-com st-bad');
  });
  it('marks to the end of the line without an end, and one column for an empty range', () => {
    expect(bad(markRange(line, 20, null))).toBe('(* c *)');
    expect(bad(markRange(line, 1, 1))).toBe('c');
    expect(bad(markRange(line, 99, 100))).toBe(')');
    expect(bad(markRange([], 1, 2))).toBe('');
  });
});

describe('ST declarations', () => {
  it('finds POUs, their variables and TYPE structures', () => {
    const d = declarations(MOTOR);
    expect(d.pous.map((p) => [p.kind, p.name, p.from, p.to])).toEqual([['PROGRAM', 'Main', 2, 16]]);
    expect(d.pous[0].vars.map((v) => [v.name, v.type, v.of, v.line])).toEqual([
      ['delay', 'TON', null, 4],
      ['starts', 'CTU', null, 5],
      ['a', 'ARRAY', 'INT', 6],
      ['p', 'Point', null, 7],
      ['i', 'INT', null, 8],
    ]);
    expect(d.structs.get('POINT')?.map((v) => v.name)).toEqual(['x', 'y']);
    expect(pouAt(d, 10)?.name).toBe('Main');
    expect(pouAt(d, 17)).toBeNull();
  });
  it('reads several names per line, FUNCTION_BLOCKs, globals and enumerations', () => {
    const d = declarations(`VAR_GLOBAL g : INT; END_VAR
TYPE Color : (Red, Green := 5); END_TYPE
FUNCTION_BLOCK Count
VAR_INPUT up, down : BOOL; END_VAR
VAR_OUTPUT n : DINT; END_VAR
VAR_IN_OUT x : INT; END_VAR
END_FUNCTION_BLOCK`);
    expect(d.globals.map((v) => v.name)).toEqual(['g']);
    expect(d.enums.get('COLOR')).toEqual(['Red', 'Green']);
    expect(d.pous[0].vars.map((v) => `${v.section} ${v.name}:${v.type}`)).toEqual(['VAR_INPUT up:BOOL', 'VAR_INPUT down:BOOL', 'VAR_OUTPUT n:DINT', 'VAR_IN_OUT x:INT']);
  });
});

describe('ST names and tags', () => {
  const d = declarations(MOTOR);
  const known = new Set(['START', 'STOP', 'MOTOR', 'LAMP', 'MAIN.DELAY.DN', 'MAIN.DELAY.ACC', 'MAIN.STARTS.ACC', 'MAIN.STARTS.DN', 'MAIN.A[2]', 'MAIN.I', 'MAIN.P.X']);
  const tag = (n: string) => (known.has(n.toUpperCase()) ? n : null);
  const names = namesByLine(MOTOR);
  const texts = (n: number) => (names.get(n) ?? []).map((r) => r.text);

  it('lists the names each code line uses, not formal parameters, functions nor declarations', () => {
    expect(texts(4)).toEqual([]);
    expect(texts(10)).toEqual(['Motor', 'Start', 'Stop']);
    expect(texts(11)).toEqual(['delay', 'Motor', 'Lamp']);
    expect(texts(12)).toEqual(['starts', 'Motor']);
    // a constant index is part of the name, a computed one is not
    expect(texts(13)).toEqual(['a[2]', 'a', 'i']);
    expect(texts(14)).toEqual(['p.x']);
    expect(texts(15)).toEqual(['delay.Q', 'i', 'starts.CV']);
    expect(names.get(10)?.[1].col).toBe('Motor := ('.length);
  });
  it('maps names to the tags of docs/st.md', () => {
    const main = d.pous[0];
    const of = (n: string) => tagOf(n, main, d, tag);
    expect(of('Motor')).toEqual({ tag: 'Motor', type: null });
    expect(of('delay.Q')).toEqual({ tag: 'Main.delay.DN', type: 'BOOL' });
    expect(of('delay')).toEqual({ tag: 'Main.delay.ACC', type: 'TIME' });
    expect(of('starts.CV')).toEqual({ tag: 'Main.starts.ACC', type: 'INT' });
    expect(of('a[2]')).toEqual({ tag: 'Main.a[2]', type: 'INT' });
    expect(of('i')).toEqual({ tag: 'Main.i', type: 'INT' });
    expect(of('p.x')).toEqual({ tag: 'Main.p.x', type: null });
    expect(of('delay.XX')).toBeNull();
    expect(of('Nothing')).toBeNull();
  });
  it('gives no tag to the locals of FUNCTION_BLOCKs without an instance nor to VAR_IN_OUT', () => {
    const src = 'FUNCTION_BLOCK F\nVAR n : INT; END_VAR\nVAR_EXTERNAL Motor : BOOL; END_VAR\nn := n + 1;\nEND_FUNCTION_BLOCK\nPROGRAM P\nVAR_IN_OUT r : INT; END_VAR\nr := 1;\nEND_PROGRAM\n';
    const dd = declarations(src);
    const all = (n: string) => n;
    expect(tagOf('n', dd.pous[0], dd, all)).toBeNull();
    expect(tagOf('n', dd.pous[0], dd, all, 'P.f1')).toEqual({ tag: 'P.f1.n', type: 'INT' });
    expect(tagOf('Motor', dd.pous[0], dd, all)).toEqual({ tag: 'Motor', type: 'BOOL' });
    expect(tagOf('r', dd.pous[1], dd, all)).toBeNull();
  });
  it("lists a FUNCTION_BLOCK's instances, nested ones too", () => {
    const src = `VAR_GLOBAL g : Count; END_VAR
FUNCTION_BLOCK Count
VAR n : INT; END_VAR
END_FUNCTION_BLOCK
FUNCTION_BLOCK Pair
VAR a, b : Count; t : TON; END_VAR
END_FUNCTION_BLOCK
PROGRAM Main
VAR c1 : Count; p : Pair; END_VAR
VAR_IN_OUT io : Count; END_VAR
END_PROGRAM`;
    const dd = declarations(src);
    expect(instancesOf(dd, 'count')).toEqual(['g', 'Main.p.a', 'Main.p.b', 'Main.c1']);
    expect(instancesOf(dd, 'Pair')).toEqual(['Main.p']);
    expect(instancesOf(dd, 'Nothing')).toEqual([]);
  });
});

describe('ST completion', () => {
  const at = (src: string) => complete(src.replace('|', ''), src.indexOf('|'), env);
  const labels = (src: string) => at(src).items.map((c) => c.label);

  it('offers variables and tags for a word being typed', () => {
    const src = MOTOR.replace('IF delay.Q', 'IF Sta| delay.Q');
    expect(labels(src)).toEqual(['starts', 'Start']);
    expect(at(src).from).toBe(src.indexOf('Sta|'));
    expect(labels(MOTOR.replace('p.x :=', 'LI| p.x :='))).toEqual(['LIMIT', 'LINT']);
    expect(labels(MOTOR.replace('p.x :=', 'de| p.x :='))).toContain('delay');
  });
  it('offers the members of standard FBs, STRUCTs, user FBs and domain structures', () => {
    expect(labels(MOTOR.replace('IF delay.Q', 'IF delay.|'))).toEqual(['IN', 'PT', 'Q', 'ET']);
    expect(labels(MOTOR.replace('IF delay.Q', 'IF starts.C|'))).toEqual(['CU', 'CV']);
    expect(labels(MOTOR.replace('p.x :=', 'p.|'))).toEqual(['x', 'y']);
    expect(labels(MOTOR.replace('p.x :=', 'T1.D|'))).toEqual(['DN']);
    const fb = 'FUNCTION_BLOCK Count\nVAR_OUTPUT n : DINT; END_VAR\nVAR_TEMP t : INT; END_VAR\nEND_FUNCTION_BLOCK\nPROGRAM P\nVAR c : Count; END_VAR\nc.|\nEND_PROGRAM';
    expect(labels(fb)).toEqual(['n']);
  });
  it("offers an instance's parameters inside its call", () => {
    const src = MOTOR.replace('PT := T#5s', 'P| := T#5s');
    expect(labels(src)[0]).toBe('PT');
    expect(at(src).items[0].kind).toBe('parameter');
    expect(labels(MOTOR.replace('starts(CU := Motor', 'starts(|'))).toEqual(['CU', 'R', 'PV', 'Q', 'CV', 'delay', 'starts', 'a', 'p', 'i', 'Start', 'Stop', 'Motor', 'Lamp', 'T1']);
    expect(callee('delay(IN := (a + b), P', 23)).toBe('delay');
    expect(callee('x := LIMIT(0, ', 14)).toBe('LIMIT');
    expect(callee('x := 1; y := ', 13)).toBeNull();
  });
  it('finds the whole name around the caret', () => {
    const src = 'IF delay.Q THEN a[2] := 1; END_IF;';
    expect(nameAt(src, src.indexOf('delay') + 2)).toBe('delay.Q');
    expect(nameAt(src, src.indexOf('.Q') + 2)).toBe('delay.Q');
    expect(nameAt(src, src.indexOf('a[2]'))).toBe('a[2]');
    expect(nameAt(src, src.indexOf(':='))).toBeNull();
    expect(nameAt(src, src.indexOf('1;'))).toBeNull();
  });
  it('finds the word and its base before the caret', () => {
    expect(wordAt('x := a.b.cd', 11)).toEqual({ base: 'a.b', prefix: 'cd', from: 9 });
    expect(wordAt('x := ab', 7)).toEqual({ base: null, prefix: 'ab', from: 5 });
  });
});

describe('ST completion places', () => {
  it('knows comments and strings, where nothing is completed', () => {
    const src = "x := ab; (* cd *) s := 'ef'; // gh";
    const toks = lex(src);
    const at = (w: string) => inCommentOrString(toks, src.indexOf(w) + w.length);
    expect(at('ab')).toBe(false);
    expect(at('cd')).toBe(true);
    expect(at('ef')).toBe(true);
    expect(at('gh')).toBe(true);
    expect(at('s :=')).toBe(false);
    expect(inCommentOrString(toks, 0)).toBe(false);
  });
});

describe('ST indentation', () => {
  it('keeps the indentation, one step more after a line that opens a block', () => {
    expect(indentAfter('    x := 1;')).toBe('    ');
    expect(indentAfter('IF a THEN')).toBe('    ');
    expect(indentAfter('  IF a THEN (* then *)')).toBe('      ');
    expect(indentAfter('FOR i := 1 TO 3 DO')).toBe('    ');
    expect(indentAfter('VAR')).toBe('    ');
    expect(indentAfter('VAR x : INT; END_VAR')).toBe('');
    expect(indentAfter('PROGRAM Main')).toBe('');
    expect(indentAfter('VAR_INPUT RETAIN')).toBe('    ');
    expect(indentAfter('\tCASE s OF')).toBe('\t    ');
    expect(indentAfter('x := 1; // THEN')).toBe('');
  });
});

describe('ST values', () => {
  it('writes values as ST literals', () => {
    expect(formatValue(true, 'BOOL')).toBe('TRUE');
    expect(formatValue(false, null)).toBe('FALSE');
    expect(formatValue(1500, 'TIME')).toBe('T#1s500ms');
    expect(formatValue(3, 'INT')).toBe('3');
    expect(formatValue(1 / 3, 'REAL')).toBe('0.333333');
    expect(formatValue(null, 'INT')).toBe('…');
    expect(timeLiteral(0)).toBe('T#0ms');
    expect(timeLiteral(3723004)).toBe('T#1h2m3s4ms');
    expect(timeLiteral(-250)).toBe('T#-250ms');
  });
});
