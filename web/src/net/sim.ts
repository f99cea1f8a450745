// What the net editor computes about markings, pure: the marking tags of a
// net (`<net>.<id>`, docs/nets.md "Marking tags"), the transitions a marking
// enables (arcs only — guards are the runtime's: the underlying
// place/transition net of the analysis, with inhibitor and read arcs), and
// firing, to replay an analysis's firing sequence on the canvas.
import type { Net } from './pnml';

export type Marking = Map<string, number>;

/** The net's name in tag names: its file name without directory and extension. */
export function netName(program: string): string {
  return program.split('/').pop()!.replace(/\.[^.]*$/, '');
}

/** The marking tag of an element (places; in normal mode transitions too). */
export const markingTag = (program: string, id: string): string => `${netName(program)}.${id}`;

export function initialMarking(net: Net): Marking {
  return new Map(net.places.map((p) => [p.id, net.mode === 'normal' ? Math.min(1, p.initial) : p.initial]));
}

/** The transitions enabled at `m` by their arcs (several arcs between one pair add their weights). */
export function enabled(net: Net, m: Marking): Set<string> {
  const need = new Map<string, { p: string; w: number; kind: string }[]>();
  for (const a of net.arcs) {
    if (!net.places.some((p) => p.id === a.source)) continue;
    need.set(a.target, [...(need.get(a.target) ?? []), { p: a.source, w: a.weight, kind: a.kind }]);
  }
  const out = new Set<string>();
  for (const t of net.transitions) {
    const sums = new Map<string, number>();
    for (const n of need.get(t.id) ?? []) sums.set(`${n.kind}\u0000${n.p}`, (sums.get(`${n.kind}\u0000${n.p}`) ?? 0) + n.w);
    let ok = true;
    for (const [k, w] of sums) {
      const [kind, p] = k.split('\u0000');
      const have = m.get(p) ?? 0;
      if (kind === 'inhibitor' ? have >= w : have < w) ok = false;
    }
    if (ok) out.add(t.id);
  }
  return out;
}

/** The marking after firing `t` at `m` (interleaving semantics; read and inhibitor arcs move nothing). */
export function fire(net: Net, m: Marking, t: string): Marking {
  const out = new Map(m);
  for (const a of net.arcs) {
    if (a.kind !== 'normal') continue;
    if (a.target === t) out.set(a.source, (out.get(a.source) ?? 0) - a.weight);
    if (a.source === t) out.set(a.target, (out.get(a.target) ?? 0) + a.weight);
  }
  return out;
}

/** The markings along a firing sequence from the initial marking: [m0, m1, …]; stops at a transition not enabled. */
export function replay(net: Net, trace: string[]): { markings: Marking[]; fired: string[] } {
  const markings = [initialMarking(net)];
  const fired: string[] = [];
  for (const t of trace) {
    const m = markings[markings.length - 1];
    if (!enabled(net, m).has(t)) break;
    markings.push(fire(net, m, t));
    fired.push(t);
  }
  return { markings, fired };
}

/** The result of POST /api/nets/{name}/analysis (docs/nets.md "JSON"). */
export interface Analysis {
  places: number;
  transitions: number;
  bounded: boolean | null;
  safe: boolean | null;
  place_bounds: Record<string, number | 'omega'> | null;
  states: number | null;
  edges: number | null;
  deadlocks: number | null;
  dead_transitions: string[] | null;
  live: boolean | null;
  reversible: boolean | null;
  p_invariants: Record<string, number>[] | null;
  t_invariants: Record<string, number>[] | null;
  deadlock_trace?: string[] | null;
  deadlock_marking?: Record<string, number> | null;
  state_space?: string;
  stopped?: string | null;
  notes?: string[];
  /** Each part's status: `complete`, `partial`, `skipped: budget` … */
  status?: Record<'state_space' | 'components' | 'p_flows' | 't_flows' | 'p_invariants' | 't_invariants', string> & { symbolic?: string; symbolic_facts?: string };
  /** The decision-diagram engine's counts (decimal: they may exceed 64 bits) and cost. */
  symbolic?: { status: string; states: string | null; edges: string | null; deadlocks?: string | null; nodes: number; memory_bytes: number; seconds: number };
  p_flows?: Record<string, number>[] | null;
  t_flows?: Record<string, number>[] | null;
}
