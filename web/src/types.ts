// The JSON shapes of docs/api.md.

export type Json = null | boolean | number | string | Json[] | { [k: string]: Json };

export interface Stats {
  last_us: number;
  min_us: number;
  max_us: number;
  mean_us: number;
  jitter_us: number;
  overruns: number;
}

export interface Status {
  project: string;
  state: 'running' | 'stopped' | 'faulted';
  fault: string | null;
  scan_ms: number;
  scans: number;
  time_ms: number;
  stats: Stats;
  minor_faults: number;
  io: string;
  programs: string[];
  clients: number;
}

export type Access = 'readwrite' | 'input' | 'readonly';

export interface TagInfo {
  name: string;
  type: string;
  address: string | null;
  /** Every notation of the address (AuroraLD, IEC, S7), upper case; empty without one. */
  notations: string[];
  description: string;
  retain: boolean;
  access: Access;
  value: Json;
  forced: Json;
}

export interface Force {
  name: string;
  value: Json;
}

export interface ProgramRef {
  name: string;
  language: 'ladder' | 'il';
  plant: boolean;
}

export interface Diagnostic {
  code: string;
  severity: string;
  message: string;
  file: string | null;
  line: number | null;
  col: number | null;
  end_line: number | null;
  end_col: number | null;
  help: string | null;
}

export interface InstrJson {
  kind: 'instr';
  id: number | null;
  mnemonic: string;
  operands: string[];
  line: number;
  col: number;
}

export interface BranchJson {
  kind: 'branch';
  id: number | null;
  line: number;
  col: number;
  legs: ElementJson[][];
}

export type ElementJson = InstrJson | BranchJson;

export interface RungJson {
  number: number;
  comment: string[];
  line: number;
  elements: ElementJson[];
}

export interface Program {
  name: string;
  language: 'ladder' | 'il';
  plant: boolean;
  text: string;
  diagnostics: Diagnostic[];
  rungs?: RungJson[];
  lines?: { line: number; id: number | null }[];
}

/** One history bucket: [t_ms, min, max, first, last]. */
export type Bucket = [number, number | null, number | null, number | null, number | null];

export interface History {
  tag: string;
  from: number;
  to: number;
  buckets: Bucket[];
}

// WebSocket messages (server → client).
export interface ValuesMsg {
  type: 'values';
  scan: number;
  t_ms: number;
  values: Record<string, Json>;
}
export interface PowerMsg {
  type: 'power';
  scan: number;
  program: string;
  on: number[];
}
export type StatusMsg = Status & { type: 'status' };
export interface ErrorMsg {
  type: 'error';
  error: string;
}
export type ServerMsg = ValuesMsg | PowerMsg | StatusMsg | ErrorMsg;
