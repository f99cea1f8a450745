// The language as the server describes it (GET /api/domain, docs/api.md),
// built from the Rust definitions (crates/ladder/src/domain.rs): data types
// and the members of structures, the instruction table with operand labels
// and titles, and what fits each kind of operand. The studio fetches it once
// at start (main.ts → setDomain); every module reads it from here instead of
// keeping its own copy. Unit tests set it from test/fixtures/domain.json, a
// copy of the reply that the server's tests keep equal to it.

export interface MemberInfo {
  name: string;
  type: string;
  /** Programs and the API may write it (else the instruction sets it). */
  writable: boolean;
}

export interface TypeInfo {
  name: string;
  kind: 'bool' | 'integer' | 'real' | 'structure';
  /** Members of a structure, in order (empty for elementary types). */
  members: MemberInfo[];
}

export interface GroupInfo {
  name: string;
  title: string;
}

/** A kind of operand and the tags that fit it. */
export interface ArgInfo {
  name: string;
  doc: string;
  /** Types of the tags and members that fit; empty when only literals or labels do. */
  types: string[];
  /** Only writable tags and members fit. */
  writable: boolean;
  /** Members of structures fit too (`T1.DN`, `T1.PRE`). */
  members: boolean;
  /** The operand names one tag, member or address (not a label, expression or literal-only place). */
  tag: boolean;
}

export interface InstructionInfo {
  mnemonic: string;
  group: string;
  /** Output instructions may end a rung; inputs are conditions. */
  output: boolean;
  shape: 'contact' | 'coil' | 'box';
  /** One argument kind (an ArgInfo name) per operand. */
  args: string[];
  /** One label per operand. */
  labels: string[];
  title: string;
  doc: string;
  /** Status bits of the structure in the first operand, shown in the box header. */
  bits: string[];
  /** Per operand, the live value shown beside it: null none, '' the operand's own value, else that member of the first operand. */
  shows: (string | null)[];
}

export interface Domain {
  types: TypeInfo[];
  groups: GroupInfo[];
  args: ArgInfo[];
  instructions: InstructionInfo[];
}

let current: Domain = { types: [], groups: [], args: [], instructions: [] };
let byMnemonic = new Map<string, InstructionInfo>();
let byType = new Map<string, TypeInfo>();
let byArg = new Map<string, ArgInfo>();

/** Uses `d` from now on (once at start; tests set their fixture). */
export function setDomain(d: Domain): void {
  current = d;
  byMnemonic = new Map(d.instructions.map((i) => [i.mnemonic.toUpperCase(), i]));
  byType = new Map(d.types.map((t) => [t.name.toUpperCase(), t]));
  byArg = new Map(d.args.map((a) => [a.name, a]));
}

export function domain(): Domain {
  return current;
}

/** An instruction by mnemonic (any case); undefined for one the server does not know. */
export function instruction(mnemonic: string): InstructionInfo | undefined {
  return byMnemonic.get(mnemonic.toUpperCase());
}

export function typeInfo(name: string): TypeInfo | undefined {
  return byType.get(name.toUpperCase());
}

/** Members of a structure type (empty for elementary or unknown types). */
export function membersOf(type: string): MemberInfo[] {
  return typeInfo(type)?.members ?? [];
}

export function isStructure(type: string): boolean {
  return typeInfo(type)?.kind === 'structure';
}

export function argInfo(kind: string): ArgInfo | undefined {
  return byArg.get(kind);
}
