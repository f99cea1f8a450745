// The ladder element tree: the same shape as the API's `rungs` JSON
// (docs/api.md), so server rungs and locally parsed rungs are used alike.

export interface Pos {
  line: number;
  col: number;
}

export interface Instr {
  kind: 'instr';
  mnemonic: string;
  operands: string[];
  /** The element id in the running program (power flow key); null/absent if unknown. */
  id?: number | null;
  line?: number;
  col?: number;
  /** Position just after the closing `)` (local parser only). */
  end?: Pos;
}

export interface Branch {
  kind: 'branch';
  legs: Elem[][];
  id?: number | null;
  line?: number;
  col?: number;
  end?: Pos;
}

export type Elem = Instr | Branch;

export interface Rung {
  comment: string[];
  elements: Elem[];
}

/** A path to an element inside a rung: [i] top level, [i, leg, j] inside branch i, … */
export type Path = number[];

/** Instructions drawn as contacts or coils (everything else is a box). */
const CONTACTS = new Set(['XIC', 'XIO', 'ONS']);
const COILS = new Set(['OTE', 'OTL', 'OTU']);

export function shapeOf(mnemonic: string): 'contact' | 'coil' | 'box' {
  const m = mnemonic.toUpperCase();
  if (CONTACTS.has(m)) return 'contact';
  if (COILS.has(m)) return 'coil';
  return 'box';
}

/** Operand labels shown in boxes, by mnemonic. */
const LABELS: Record<string, string[]> = {
  XIC: ['Bit'],
  ONS: ['Storage Bit'],
  TON: ['Timer', 'Preset', 'Accum'],
  CTU: ['Counter', 'Preset', 'Accum'],
  RES: ['Structure'],
  LIM: ['Low Limit', 'Test', 'High Limit'],
  EQU: ['Source A', 'Source B'],
  MEQ: ['Source', 'Mask', 'Compare'],
  ADD: ['Source A', 'Source B', 'Dest'],
  SQR: ['Source', 'Dest'],
  CPT: ['Dest', 'Expression'],
  SCP: ['Input', 'Input Min', 'Input Max', 'Scaled Min', 'Scaled Max', 'Output'],
  MOV: ['Source', 'Dest'],
  CLR: ['Dest'],
  NOT: ['Source', 'Dest'],
  OSR: ['Storage Bit', 'Output Bit'],
  JMP: ['Label'],
  PID: ['PID', 'Process Var', 'Control Var'],
};
const SAME: Record<string, string> = {
  TOF: 'TON', RTO: 'TON', TP: 'TON', CTD: 'CTU', NEQ: 'EQU', LES: 'EQU', GRT: 'EQU', LEQ: 'EQU', GEQ: 'EQU',
  SUB: 'ADD', MUL: 'ADD', DIV: 'ADD', MOD: 'ADD', XPY: 'ADD', AND: 'ADD', OR: 'ADD', XOR: 'ADD',
  NEG: 'SQR', ABS: 'SQR', LN: 'SQR', LOG: 'SQR', SIN: 'SQR', COS: 'SQR', TAN: 'SQR', ASN: 'SQR', ACS: 'SQR',
  ATN: 'SQR', DEG: 'SQR', RAD: 'SQR', OSF: 'OSR', LBL: 'JMP', XIO: 'XIC', OTE: 'XIC', OTL: 'XIC', OTU: 'XIC',
};

export function operandLabels(mnemonic: string, count: number): string[] {
  const m = mnemonic.toUpperCase();
  const l = LABELS[m] ?? LABELS[SAME[m] ?? ''] ?? [];
  return Array.from({ length: count }, (_, i) => l[i] ?? `Operand ${i + 1}`);
}

/** Full names for box titles. */
export const TITLES: Record<string, string> = {
  TON: 'Timer On Delay', TOF: 'Timer Off Delay', RTO: 'Retentive Timer On', TP: 'Pulse Timer',
  CTU: 'Count Up', CTD: 'Count Down', RES: 'Reset', LIM: 'Limit Test', EQU: 'Equal', NEQ: 'Not Equal',
  LES: 'Less Than', GRT: 'Greater Than', LEQ: 'Less Than or Equal', GEQ: 'Greater Than or Equal',
  MEQ: 'Masked Equal', ADD: 'Add', SUB: 'Subtract', MUL: 'Multiply', DIV: 'Divide', MOD: 'Modulo',
  SQR: 'Square Root', NEG: 'Negate', ABS: 'Absolute Value', XPY: 'X to the Power of Y', LN: 'Natural Log',
  LOG: 'Log Base 10', CPT: 'Compute', SCP: 'Scale with Parameters', MOV: 'Move', CLR: 'Clear',
  AND: 'Bitwise AND', OR: 'Bitwise OR', XOR: 'Bitwise XOR', NOT: 'Bitwise NOT', SIN: 'Sine', COS: 'Cosine',
  TAN: 'Tangent', ASN: 'Arc Sine', ACS: 'Arc Cosine', ATN: 'Arc Tangent', DEG: 'Radians to Degrees',
  RAD: 'Degrees to Radians', JMP: 'Jump to Label', LBL: 'Label', AFI: 'Always False', NOP: 'No Operation',
  OSR: 'One Shot Rising', OSF: 'One Shot Falling',
};

const TIMERS = new Set(['TON', 'TOF', 'RTO', 'TP']);
const COUNTERS = new Set(['CTU', 'CTD']);

export function isTimer(m: string): boolean {
  return TIMERS.has(m.toUpperCase());
}
export function isCounter(m: string): boolean {
  return COUNTERS.has(m.toUpperCase());
}

/** True for an operand that is a literal, `?`, a label or an expression rather than a tag. */
export function isLiteral(op: string): boolean {
  const t = op.trim();
  return t === '' || t === '?' || /^[0-9+\-.]/.test(t) || /^(T|TIME)#/i.test(t) || /^(TRUE|FALSE)$/i.test(t);
}

/** The tag names an instruction reads or writes, for live values (not labels or expressions). */
export function operandTags(i: Instr): string[] {
  const m = i.mnemonic.toUpperCase();
  if (m === 'JMP' || m === 'LBL') return [];
  const ops = m === 'CPT' ? i.operands.slice(0, 1) : i.operands;
  return ops.filter((o) => !isLiteral(o) && /^[A-Za-z_%][\w.:/%]*$/.test(o.trim())).map((o) => o.trim());
}

/** Visits every element with its path. */
export function walk(elems: Elem[], f: (e: Elem, path: Path) => void, prefix: Path = []): void {
  elems.forEach((e, i) => {
    const p = [...prefix, i];
    f(e, p);
    if (e.kind === 'branch') e.legs.forEach((leg, l) => walk(leg, f, [...p, l]));
  });
}

/** A copy of the tree without ids and positions (for comparisons). */
export function strip(elems: Elem[]): Elem[] {
  return elems.map((e) =>
    e.kind === 'instr'
      ? { kind: 'instr', mnemonic: e.mnemonic, operands: [...e.operands] }
      : { kind: 'branch', legs: e.legs.map(strip) },
  );
}
