// Generated from crates/server/src/reply.rs by `UPDATE_BINDINGS=1 cargo test -p alba-server`: do not edit.

/** Any JSON value. */
export type Json = null | boolean | number | string | Json[] | { [k: string]: Json };

export type Stats = { last_us: number, min_us: number, max_us: number, mean_us: number, jitter_us: number, overruns: number, };

export type RunState = "running" | "stopped" | "faulted";

export type Status = { project: string, state: RunState, fault: string | null, scan_ms: number, scans: number, time_ms: number, stats: Stats, minor_faults: number, io: string, programs: Array<string>, clients: number, };

export type Access = "readwrite" | "input" | "readonly";

export type TagInfo = { name: string, type: string, address: string | null, description: string, retain: boolean, access: Access, 
/**
 * A value, or an object of a structure's members.
 */
value: Json, 
/**
 * The forced value, `null` if not forced.
 */
forced: Json, };

export type TagValue = { name: string, type: string, access: Access, value: Json, forced: Json, };

export type TagReply = TagInfo | TagValue;

export type Force = { name: string, value: Json, };

export type Language = "ladder" | "il";

export type ProgramRef = { name: string, language: Language, plant: boolean, };

export type Diagnostic = { code: string, severity: string, message: string, file: string | null, line: number | null, col: number | null, end_line: number | null, end_col: number | null, help: string | null, };

export type InstrJson = { 
/**
 * The id of the compiled element (power flow), if compiled.
 */
id: number | null, mnemonic: string, operands: Array<string>, line: number, col: number, };

export type BranchJson = { id: number | null, line: number, col: number, legs: Array<Array<ElementJson>>, };

export type ElementJson = { "kind": "instr" } & InstrJson | { "kind": "branch" } & BranchJson;

export type RungJson = { number: number, comment: Array<string>, line: number, elements: Array<ElementJson>, };

export type IlLine = { line: number, id: number | null, };

export type Program = { name: string, language: Language, plant: boolean, text: string, diagnostics: Array<Diagnostic>, 
/**
 * Ladder programs.
 */
rungs?: Array<RungJson>, 
/**
 * IL programs.
 */
lines?: Array<IlLine>, };

export type Checked = { 
/**
 * Always empty (a program that does not compile is an error reply).
 */
diagnostics: Array<Diagnostic>, rungs?: Array<RungJson>, lines?: Array<IlLine>, };

export type Saved = { diagnostics: Array<Diagnostic>, applied: boolean, };

export type Instruction = { mnemonic: string, group: string, output: boolean, args: Array<string>, doc: string, };

export type HistoryTag = { name: string, first_ms: number, last_ms: number, };

export type Bucket = [number, number | null, number | null, number | null, number | null];

export type History = { tag: string, from: number, to: number, buckets: Array<Bucket>, };

export type ErrorReply = { error: string, diagnostics?: Array<Diagnostic>, };

export type PowerMsg = { type: 'power', scan: number, program: string, on: Array<number>, };

export type ErrorMsg = { type: 'error', error: string, };

export type StatusMsg = { type: 'status', project: string, state: RunState, fault: string | null, scan_ms: number, scans: number, time_ms: number, stats: Stats, minor_faults: number, io: string, programs: Array<string>, clients: number, };
