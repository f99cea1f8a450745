// The language as the server describes it (GET /api/domain, docs/api.md; its
// types are generated from the Rust ones into api.gen.ts),
// built from the Rust definitions (crates/ladder/src/domain.rs): data types
// and the members of structures, the instruction table with operand labels
// and titles, and what fits each kind of operand. The studio fetches it once
// at start (main.ts → setDomain); every module reads it from here instead of
// keeping its own copy. Unit tests set it from test/fixtures/domain.json, a
// copy of the reply that the server's tests keep equal to it.

import type { ArgInfo, DomainReply, GroupInfo, InstructionInfo, MemberInfo, OptionalInfo, RouteRole, TypeInfo } from './api.gen';

/** GET /api/domain: the language, and the role each route needs. */
export type Domain = DomainReply;
export type { ArgInfo, GroupInfo, InstructionInfo, MemberInfo, OptionalInfo, RouteRole, TypeInfo };

let current: Domain = { types: [], groups: [], args: [], instructions: [], routes: [], screens: { elements: [], properties: [], animations: [], actions: [] } };
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
