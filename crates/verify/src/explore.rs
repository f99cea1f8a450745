//! Deciding properties over every input sequence (ADR 0015).
//!
//! The transition relation is one scan of the engine itself: a state is the
//! program memory at the end of a scan; its successors are the scans that
//! follow with every combination of input values. A breadth-first search
//! over the states reachable from the first scan decides each property:
//! a violating state gives the shortest counterexample, an exhausted search
//! proves it. What would make the state space infinite without changing any
//! behaviour is abstracted, exactly:
//!
//! * a timer's clock of last update is kept as its age relative to the end
//!   of the scan, set to 0 where the timer's next execution cannot read it,
//!   and capped at the preset (a larger age makes the same next scan);
//! * a counter that only counts up (or only down), whose value nobody else
//!   reads, is capped at its preset (beyond it, `DN` is all that shows);
//! * branch temporaries, rewritten before they are read in every scan, are
//!   cleared;
//! * the clock bits (`SM0.4`, `SM0.5`) keep the time modulo their period, and
//!   `SM0.6` the parity of the scan count, only when something reads them.
//!
//! The search stops with `unknown` when its budget of states or depth runs
//! out, or when something cannot be enumerated (a numeric input without a
//! `[domain]`, a PID loop). Every counterexample is replayed through the
//! engine as `alba sim` replays it before `refuted` is answered.

use crate::expr::{Cond, Evaluator, Probes};
use crate::props::{Kind, Properties, Property};
use crate::slots::writes;
use alba_engine::Engine;
use alba_engine::sim::Stimulus;
use alba_ir::op::{AnySlot, S7Ctr, S7Tmr};
use alba_ir::{Ctr, Layout, Memory, Op, Place, Program, Tmr};
use alba_model::address::Address;
use alba_model::{DataType, Value};
use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::Arc;
use std::time::Instant;

/// The largest k that k-induction tries before the explicit search, by default.
pub const INDUCTION_K: u32 = 3;

/// Limits of one search.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Distinct states stored.
    pub max_states: usize,
    /// Scans from the start.
    pub max_depth: u32,
    /// Wall-clock seconds per property.
    pub max_seconds: u64,
    /// Bytes the stored states and the frontier may take (estimated).
    pub max_bytes: usize,
    /// The largest k that k-induction tries on an invariant before the
    /// explicit search (0: the explicit search alone).
    pub induction_k: u32,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget {
            max_states: 2_000_000,
            max_depth: 1_000_000,
            max_seconds: 60,
            max_bytes: 1 << 30,
            induction_k: INDUCTION_K,
        }
    }
}

/// The answer for one property.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    Proved,
    Refuted,
    Unknown(String),
}

/// A run: the input values of every scan, scan k at k·scan_ms.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// The inputs chosen (those the property depends on), as a stimulus names them.
    pub inputs: Vec<String>,
    pub scans: Vec<Vec<Value>>,
}

/// How a verdict was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The explicit-state search on the engine.
    Explicit,
    /// k-induction with the SAT solver (induct.rs), with this k.
    Induction(u32),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    pub name: String,
    pub outcome: Outcome,
    pub method: Method,
    /// SAT queries made (k-induction, tried first on invariants).
    pub sat_calls: u32,
    /// Refuted: the violating run. Reachable and proved: the witness.
    pub run: Option<Run>,
    /// Scans of the run, or the depth the search reached.
    pub depth: u32,
    pub states: usize,
    pub millis: u128,
}

/// An input the search chooses on every scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// As a stimulus names it.
    pub name: String,
    pub place: Place,
    pub values: Vec<Value>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TKind {
    /// Only reset (RES) so far: nothing reads its clock.
    Reset,
    Ton,
    Tof,
    Rto,
    Tp,
    Mixed,
}

#[derive(Debug, Clone, Copy)]
struct TimerAbs {
    t: Tmr,
    kind: TKind,
    /// Something else writes its PRE or ACC: ages are not capped.
    cap: bool,
    /// Milliseconds per unit of ACC (its time base; 1 for TP).
    unit: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum S7Kind {
    /// Only reset so far.
    Reset,
    On,
    Of,
    Mixed,
}

#[derive(Debug, Clone, Copy)]
struct S7TimerAbs {
    t: S7Tmr,
    kind: S7Kind,
    /// TON/TONR whose count nothing else touches: past PT only the bit
    /// shows, so the count is capped at PT (and its pending ms dropped).
    cap: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dir {
    Up,
    Down,
}

/// How a counter's value is capped.
#[derive(Debug, Clone, Copy)]
enum CounterAbs {
    Logix { acc: usize, pre: usize, dir: Dir },
    S7Up { cv: usize, pv: usize },
}

/// A program made ready for the search.
#[derive(Clone)]
pub struct Model {
    program: Arc<Program>,
    scan_ms: u64,
    pub inputs: Vec<Input>,
    timers: Vec<TimerAbs>,
    s7timers: Vec<S7TimerAbs>,
    counters: Vec<CounterAbs>,
    /// Bool slots cleared in a state (branch temporaries).
    temps: Vec<usize>,
    /// The time is kept modulo this (1: not at all).
    period: u64,
    parity: bool,
    /// Why nothing can be decided, if so.
    blocked: Option<String>,
    /// What makes `blocked`, with the slots it is about: only a property
    /// that depends on them is blocked.
    blockers: Vec<(Vec<AnySlot>, String)>,
    plants: bool,
    /// Slots outside the property's cone of influence, put back to their
    /// initial value in every state (see [`Model::reduced`]).
    outside: Vec<AnySlot>,
    /// The properties' expressions, lowered (expr.rs).
    probes: Probes,
}

/// Every slot an op reads or writes, each one (not only the ends of a timer's range).
fn touches(op: &Op) -> Vec<AnySlot> {
    let mut v = op.slots();
    v.extend(writes(op));
    v
}

fn place_slot(p: Place) -> Option<AnySlot> {
    Some(match p {
        Place::Bool(b) => AnySlot::B(b.0),
        Place::Int(i, _) => AnySlot::I(i.0),
        Place::Real(f) => AnySlot::F(f.0),
        Place::Lint(l) => AnySlot::L(l.0),
        Place::Lreal(d) => AnySlot::D(d.0),
        _ => return None,
    })
}

/// Slots an op overwrites whatever their value before (without reading it).
fn kills(op: &Op) -> Vec<AnySlot> {
    use AnySlot as S;
    match *op {
        Op::Ote(b) | Op::LdBit { dst: b, .. } | Op::CopyB(_, b) => vec![S::B(b.0)],
        Op::BrOpen { save, acc } => vec![S::B(save.0), S::B(acc.0)],
        Op::CopyI(_, d) => vec![S::I(d.0)],
        Op::LdM { slot, .. } => match slot {
            alba_ir::op::MarkerSlot::Real(f) => vec![S::F(f.0)],
            alba_ir::op::MarkerSlot::Byte(i) | alba_ir::op::MarkerSlot::Word(i) | alba_ir::op::MarkerSlot::DWord(i) => {
                vec![S::I(i.0)]
            }
        },
        _ => vec![],
    }
}

/// A slot as nodes of the influence graph: marker memory byte by byte.
fn nodes(s: AnySlot) -> Vec<AnySlot> {
    match s {
        AnySlot::M(at, n) => (at..at.saturating_add(n)).map(|b| AnySlot::M(b, 1)).collect(),
        s => vec![s],
    }
}

fn place_nodes(p: Place) -> Vec<AnySlot> {
    match p {
        Place::MBit { byte, .. } | Place::MByte(byte) => vec![AnySlot::M(byte, 1)],
        Place::MWord(at) => nodes(AnySlot::M(at, 2)),
        Place::MDword(at, _) | Place::MReal(at) => nodes(AnySlot::M(at, 4)),
        p => place_slot(p).into_iter().collect(),
    }
}

/// Does an op other than `own` touch `s`?
fn touched_elsewhere(prog: &Program, s: AnySlot, own: &dyn Fn(&Op) -> bool) -> bool {
    prog.ops.iter().any(|op| !own(op) && touches(op).contains(&s))
}

impl Model {
    /// Prepares `program` for the search of `props` at `scan_ms`.
    pub fn new(program: Arc<Program>, scan_ms: u64, props: &Properties) -> Model {
        let prog = &*program;
        let layout = &prog.layout;
        let mut prop_slots = HashSet::new();
        for p in &props.properties {
            kind_reads(&p.kind, &mut prop_slots);
        }
        for a in &props.assumes {
            prop_slots.extend(a.reads().iter().copied());
        }
        let mut written = HashSet::new();
        let mut referenced = HashSet::new();
        for op in &prog.ops {
            written.extend(writes(op));
            referenced.extend(touches(op));
        }
        referenced.extend(prop_slots.iter().copied());
        let mut blockers: Vec<(Vec<AnySlot>, String)> = Vec::new();
        let mut inputs = Vec::new();
        let domain_of = |p: Place| props.domains.iter().find(|d| d.place == p);
        let name_of = |_p: Place, addr: Address| -> String {
            layout
                .tags
                .iter()
                .find(|t| t.address == Some(addr))
                .map_or_else(|| addr.to_string(), |t| t.name.clone())
        };
        // Digital inputs the programs read and never write.
        for n in 0..layout.di.len {
            let b = layout.di.base + n;
            let s = AnySlot::B(b);
            if referenced.contains(&s) && !written.contains(&s) {
                let place = Place::Bool(alba_ir::B(b));
                let values = match domain_of(place) {
                    Some(d) => d.values.clone(),
                    None => vec![Value::Bool(false), Value::Bool(true)],
                };
                inputs.push(Input {
                    name: name_of(place, Address::DigitalIn(n)),
                    place,
                    values,
                });
            }
        }
        // Analog inputs, and the measurements of plant models: numeric, so
        // only over a declared domain.
        let mut numeric: Vec<(Place, String)> = Vec::new();
        for n in 0..layout.ai.len {
            let i = layout.ai.base + n;
            let s = AnySlot::I(i);
            if referenced.contains(&s) && !written.contains(&s) {
                let ty = layout
                    .tags
                    .iter()
                    .find(|t| t.address == Some(Address::AnalogIn(n)))
                    .map_or(DataType::Int, |t| t.ty);
                let place = Place::Int(alba_ir::I(i), ty);
                numeric.push((place, name_of(place, Address::AnalogIn(n))));
            }
        }
        for plant in &prog.plants {
            if !inputs.iter().any(|i| i.place == plant.output) && !numeric.iter().any(|(p, _)| *p == plant.output) {
                let name = prop_name(layout, plant.output);
                if plant.output.data_type() == DataType::Bool {
                    inputs.push(Input {
                        name,
                        place: plant.output,
                        values: vec![Value::Bool(false), Value::Bool(true)],
                    });
                } else {
                    numeric.push((plant.output, name));
                }
            }
        }
        for (place, name) in numeric {
            match domain_of(place) {
                Some(d) => inputs.push(Input {
                    name,
                    place,
                    values: d.values.clone(),
                }),
                None => blockers.push((
                    place_nodes(place),
                    format!(
                        "the input `{name}` is {}: list the values to explore under [domain] in properties.toml",
                        place.data_type().with_article()
                    ),
                )),
            }
        }
        // Other places given a domain (internal tags a stimulus sets).
        for d in &props.domains {
            if !inputs.iter().any(|i| i.place == d.place) {
                inputs.push(Input {
                    name: d.name.clone(),
                    place: d.place,
                    values: d.values.clone(),
                });
            }
        }
        for op in &prog.ops {
            if matches!(op, Op::Pid(_)) {
                blockers.push((
                    writes(op),
                    "the property depends on a PID loop, whose REAL state the search does not enumerate".into(),
                ));
            }
        }
        let blocked = blockers.first().map(|(_, why)| why.clone());
        // Timers.
        let mut tmap: HashMap<u32, TimerAbs> = HashMap::new();
        let mut s7map: HashMap<u32, S7TimerAbs> = HashMap::new();
        for op in &prog.ops {
            let (t, k, unit) = match *op {
                Op::Ton(t, b) => (t, TKind::Ton, b.ms()),
                Op::Tof(t, b) => (t, TKind::Tof, b.ms()),
                Op::Rto(t, b) => (t, TKind::Rto, b.ms()),
                Op::Tp(t) => (t, TKind::Tp, 1),
                Op::ResT(t) => {
                    tmap.entry(t.i.0).or_insert(TimerAbs {
                        t,
                        kind: TKind::Reset,
                        cap: false,
                        unit: 1,
                    });
                    continue;
                }
                Op::S7Ton(t) | Op::S7Tonr(t) | Op::S7Tof(t) => {
                    let k = if matches!(op, Op::S7Tof(_)) {
                        S7Kind::Of
                    } else {
                        S7Kind::On
                    };
                    let e = s7map.entry(t.i.0).or_insert(S7TimerAbs { t, kind: k, cap: false });
                    if e.kind == S7Kind::Reset {
                        e.kind = k;
                    } else if e.kind != k {
                        e.kind = S7Kind::Mixed;
                    }
                    continue;
                }
                Op::S7ResT(t) => {
                    s7map.entry(t.i.0).or_insert(S7TimerAbs {
                        t,
                        kind: S7Kind::Reset,
                        cap: false,
                    });
                    continue;
                }
                _ => continue,
            };
            let e = tmap.entry(t.i.0).or_insert(TimerAbs {
                t,
                kind: k,
                cap: true,
                unit,
            });
            // (the largest unit: a larger cap only merges fewer states)
            e.unit = e.unit.max(unit);
            if e.kind == TKind::Reset {
                e.kind = k;
            } else if e.kind != k {
                e.kind = TKind::Mixed;
            }
        }
        let mut timers: Vec<TimerAbs> = tmap.into_values().collect();
        timers.sort_by_key(|t| t.t.i.0);
        for ta in &mut timers {
            let t = ta.t;
            let own = |op: &Op| matches!(op, Op::Ton(x, _) | Op::Tof(x, _) | Op::Rto(x, _) | Op::Tp(x) | Op::ResT(x) if *x == t);
            let others_write = prog.ops.iter().any(|op| {
                !own(op)
                    && writes(op)
                        .iter()
                        .any(|s| matches!(s, AnySlot::I(x) if *x == t.i.0 || *x == t.i.0 + 1))
            });
            ta.cap = !matches!(ta.kind, TKind::Mixed | TKind::Reset) && !others_write;
        }
        let mut s7timers: Vec<S7TimerAbs> = s7map.into_values().collect();
        s7timers.sort_by_key(|t| t.t.i.0);
        for st in &mut s7timers {
            let t = st.t;
            let own = |op: &Op| matches!(op, Op::S7Ton(x) | Op::S7Tonr(x) | Op::S7Tof(x) | Op::S7ResT(x) if *x == t);
            let private = [AnySlot::I(t.i.0), AnySlot::I(t.i.0 + 1)];
            st.cap = st.kind == S7Kind::On
                && !private
                    .iter()
                    .any(|s| prop_slots.contains(s) || touched_elsewhere(prog, *s, &own));
        }
        // Counters.
        let mut counters = Vec::new();
        let mut seen: HashSet<u32> = HashSet::new();
        for op in &prog.ops {
            match *op {
                Op::Ctu(c) | Op::Ctd(c) | Op::ResC(c) if seen.insert(c.i.0) => {
                    if let Some(a) = logix_counter(prog, c, &prop_slots) {
                        counters.push(a);
                    }
                }
                Op::S7Ctu(c) | Op::S7Ctd(c) | Op::S7Ctud(c) | Op::S7ResC(c) if seen.insert(c.i.0) => {
                    if let Some(a) = s7_counter(prog, c, &prop_slots) {
                        counters.push(a);
                    }
                }
                _ => {}
            }
        }
        let mut temps = Vec::new();
        for op in &prog.ops {
            if let Op::BrOpen { save, acc } | Op::BrNext { save, acc } = *op {
                temps.push(save.0 as usize);
                temps.push(acc.0 as usize);
            }
        }
        temps.sort_unstable();
        temps.dedup();
        let sys = layout.system;
        let reads = |b: alba_ir::B| referenced.contains(&AnySlot::B(b.0));
        let period = if reads(sys.clock_60s) {
            60_000
        } else if reads(sys.clock_1s) {
            1_000
        } else {
            1
        };
        let parity = reads(sys.scan_toggle);
        let plants = !prog.plants.is_empty();
        Model {
            scan_ms: scan_ms.max(1),
            inputs,
            timers,
            s7timers,
            counters,
            temps,
            period,
            parity,
            blocked,
            blockers,
            plants,
            outside: Vec::new(),
            probes: props.probes.clone(),
            program,
        }
    }

    /// The model for one property: only the slots that can influence what it
    /// (and the assumptions) read are kept in a state, and only the inputs
    /// among them are enumerated. Influence is taken per rung: every slot a
    /// rung writes depends on the slots it reads before overwriting them;
    /// what jumps read is always kept. A property that depends on the fault
    /// flags keeps everything.
    pub fn reduced(&self, property: &Property, assumes: &[Cond]) -> Model {
        let prog = &*self.program;
        let layout = &prog.layout;
        let mut read = HashSet::new();
        kind_reads(&property.kind, &mut read);
        for a in assumes {
            read.extend(a.reads().iter().copied());
        }
        let mut relevant: HashSet<AnySlot> = read.into_iter().flat_map(nodes).collect();
        let sys = layout.system;
        let faults = [AnySlot::B(sys.minor_fault.0), AnySlot::I(sys.fault_code.0)];
        if faults.iter().any(|f| relevant.contains(f)) {
            return self.clone();
        }
        // Per rung: the slots whose value at the rung's start it reads (not
        // overwritten unconditionally before), and the slots it writes. A
        // `JMP` decides which rungs run: the slots its rung reads are kept
        // whatever the property, and after it nothing in its rung is sure
        // to run, so nothing there counts as overwritten.
        let mut rungs: Vec<(HashSet<AnySlot>, HashSet<AnySlot>)> = Vec::new();
        let mut killed: HashSet<AnySlot> = HashSet::new();
        let mut jumped = false;
        let mut control: Vec<usize> = Vec::new();
        for op in &prog.ops {
            if matches!(op, Op::Rung) || rungs.is_empty() {
                rungs.push((HashSet::new(), HashSet::new()));
                killed.clear();
                jumped = false;
            }
            let Some(r) = rungs.last_mut() else { continue };
            let k: Vec<AnySlot> = if jumped {
                Vec::new()
            } else {
                kills(op).into_iter().flat_map(nodes).collect()
            };
            for t in touches(op).into_iter().flat_map(nodes) {
                if !k.contains(&t) && !killed.contains(&t) {
                    r.0.insert(t);
                }
            }
            r.1.extend(writes(op).into_iter().flat_map(nodes));
            killed.extend(k);
            if matches!(op, Op::Jmp(_)) {
                jumped = true;
                control.push(rungs.len() - 1);
            }
        }
        for &c in &control {
            relevant.extend(rungs[c].0.iter().copied());
        }
        let mut grew = true;
        while grew {
            grew = false;
            for (exposed, written) in &rungs {
                if written.iter().any(|w| relevant.contains(w)) {
                    for t in exposed {
                        grew |= relevant.insert(*t);
                    }
                }
            }
        }
        // Faults set the fault flags from any computation, kept or not.
        if faults.iter().any(|f| relevant.contains(f)) {
            return self.clone();
        }
        let mut m = self.clone();
        m.blocked = self
            .blockers
            .iter()
            .find(|(slots, _)| slots.iter().any(|s| relevant.contains(s)))
            .map(|(_, why)| why.clone());
        m.inputs
            .retain(|i| place_nodes(i.place).iter().any(|s| relevant.contains(s)));
        let init = &prog.init;
        let mut outside = Vec::new();
        let keep = |s: AnySlot| relevant.contains(&s);
        outside.extend((0..init.b.len() as u32).map(AnySlot::B).filter(|s| !keep(*s)));
        outside.extend((0..init.i.len() as u32).map(AnySlot::I).filter(|s| !keep(*s)));
        outside.extend((0..init.f.len() as u32).map(AnySlot::F).filter(|s| !keep(*s)));
        outside.extend((0..init.l.len() as u32).map(AnySlot::L).filter(|s| !keep(*s)));
        outside.extend((0..init.d.len() as u32).map(AnySlot::D).filter(|s| !keep(*s)));
        outside.extend((0..init.m.len() as u32).map(|b| AnySlot::M(b, 1)).filter(|s| !keep(*s)));
        m.outside = outside;
        m
    }

    /// Input combinations per scan.
    pub fn combinations(&self) -> u64 {
        self.inputs
            .iter()
            .fold(1u64, |n, i| n.saturating_mul(i.values.len() as u64))
    }

    fn assign(&self, mut k: u64, out: &mut Vec<Value>) {
        out.clear();
        for i in &self.inputs {
            let n = i.values.len() as u64;
            out.push(i.values[(k % n) as usize]);
            k /= n;
        }
    }

    /// Puts the state's clock of last update back as absolute times, for a scan
    /// following one at `prev`.
    fn denormalize(&self, m: &mut Memory, prev: u64) {
        for ta in &self.timers {
            let at = ta.t.i.0 as usize + 2;
            m.i[at] = (prev as u32).wrapping_sub(m.i[at] as u32) as i32;
        }
        for s in &self.s7timers {
            let at = s.t.i.0 as usize + 3;
            m.i[at] = (prev as u32).wrapping_sub(m.i[at] as u32) as i32;
        }
    }

    /// Makes the memory after a scan at `now` a state (see the module's doc).
    fn normalize(&self, m: &mut Memory, now: u64) {
        for ta in &self.timers {
            let (i, b) = (ta.t.i.0 as usize, ta.t.b.0 as usize);
            let (en, tt, dn) = (m.b[b], m.b[b + 1], m.b[b + 2]);
            let relevant = match ta.kind {
                TKind::Ton | TKind::Rto => en && !dn,
                TKind::Tof => tt,
                TKind::Tp => dn,
                TKind::Mixed => true,
                TKind::Reset => false,
            };
            let mut age = (now as u32).wrapping_sub(m.i[i + 2] as u32);
            if !relevant {
                age = 0;
            } else if ta.cap {
                // ACC counts whole units of the time base: the age at which it reaches PRE
                let units = m.i[i].max(0) as i64 + (-(m.i[i + 1] as i64)).max(0);
                let cap = (units * ta.unit as i64).min(u32::MAX as i64) as u32;
                age = age.min(cap);
            }
            m.i[i + 2] = age as i32;
        }
        for s in &self.s7timers {
            let (i, b) = (s.t.i.0 as usize, s.t.b.0 as usize);
            let (bit, en) = (m.b[b], m.b[b + 1]);
            let relevant = match s.kind {
                S7Kind::On => en,
                S7Kind::Of => !en && bit,
                S7Kind::Mixed => true,
                S7Kind::Reset => false,
            };
            let age = if relevant {
                (now as u32).wrapping_sub(m.i[i + 3] as u32)
            } else {
                0
            };
            m.i[i + 3] = age as i32;
            let pt = m.i[i + 1].max(0);
            if s.cap && m.i[i] >= pt {
                m.i[i] = pt;
                m.i[i + 2] = 0;
            }
        }
        for c in &self.counters {
            match *c {
                CounterAbs::Logix { acc, pre, dir } => {
                    let p = m.i[pre];
                    match dir {
                        Dir::Up if m.i[acc] > p => m.i[acc] = p,
                        Dir::Down if m.i[acc] < p.saturating_sub(1) => m.i[acc] = p.saturating_sub(1),
                        _ => {}
                    }
                }
                CounterAbs::S7Up { cv, pv } => {
                    let p = m.i[pv].max(0);
                    if m.i[cv] > p {
                        m.i[cv] = p;
                    }
                }
            }
        }
        for &t in &self.temps {
            m.b[t] = false;
        }
        let init = &self.program.init;
        for s in &self.outside {
            match *s {
                AnySlot::B(x) => m.b[x as usize] = init.b[x as usize],
                AnySlot::I(x) => m.i[x as usize] = init.i[x as usize],
                AnySlot::F(x) => m.f[x as usize] = init.f[x as usize],
                AnySlot::L(x) => m.l[x as usize] = init.l[x as usize],
                AnySlot::D(x) => m.d[x as usize] = init.d[x as usize],
                AnySlot::M(x, _) => m.m[x as usize] = init.m[x as usize],
            }
        }
    }
}

fn prop_name(layout: &Layout, p: Place) -> String {
    for t in layout.tags.iter() {
        if let Ok(alba_ir::Target::Value { place, .. }) = layout.resolve(&t.name)
            && place == p
        {
            return t.name.clone();
        }
    }
    format!("{p:?}")
}

fn logix_counter(prog: &Program, c: Ctr, prop_slots: &HashSet<AnySlot>) -> Option<CounterAbs> {
    let own = |op: &Op| matches!(op, Op::Ctu(x) | Op::Ctd(x) | Op::ResC(x) if *x == c);
    let up = prog.ops.iter().any(|op| matches!(op, Op::Ctu(x) if *x == c));
    let down = prog.ops.iter().any(|op| matches!(op, Op::Ctd(x) if *x == c));
    let private = [
        AnySlot::I(c.i.0),
        AnySlot::I(c.i.0 + 1),
        AnySlot::B(c.b.0 + 3),
        AnySlot::B(c.b.0 + 4),
    ];
    if private
        .iter()
        .any(|s| prop_slots.contains(s) || touched_elsewhere(prog, *s, &own))
    {
        return None;
    }
    let dir = match (up, down) {
        (true, false) => Dir::Up,
        (false, true) => Dir::Down,
        _ => return None,
    };
    Some(CounterAbs::Logix {
        acc: c.i.0 as usize + 1,
        pre: c.i.0 as usize,
        dir,
    })
}

fn s7_counter(prog: &Program, c: S7Ctr, prop_slots: &HashSet<AnySlot>) -> Option<CounterAbs> {
    let own = |op: &Op| matches!(op, Op::S7Ctu(x) | Op::S7Ctd(x) | Op::S7Ctud(x) | Op::S7ResC(x) if *x == c);
    let only_up = prog
        .ops
        .iter()
        .all(|op| !matches!(op, Op::S7Ctd(x) | Op::S7Ctud(x) if *x == c));
    let private = [AnySlot::I(c.i.0), AnySlot::I(c.i.0 + 1)];
    if !only_up
        || private
            .iter()
            .any(|s| prop_slots.contains(s) || touched_elsewhere(prog, *s, &own))
    {
        return None;
    }
    Some(CounterAbs::S7Up {
        cv: c.i.0 as usize,
        pv: c.i.0 as usize + 1,
    })
}

/// The project's slots a property's expressions read.
fn kind_reads(k: &Kind, out: &mut HashSet<AnySlot>) {
    let conds: Vec<&Cond> = match k {
        Kind::Never(e) | Kind::Always(e) | Kind::Reachable(e) => vec![e],
        Kind::Mutex(es) => es.iter().collect(),
        Kind::Response { trigger, then, .. } => vec![trigger, then],
    };
    for c in conds {
        out.extend(c.reads().iter().copied());
    }
}

/// The property's monitor: `Some(scans since the oldest unanswered trigger)`.
type Pending = Option<u32>;

enum Check {
    Fine(Pending),
    Violated,
    Witness,
}

/// Checks the property on `probed`, the memory at the end of a scan with
/// the expressions evaluated ([`Evaluator::run`]).
fn check(k: &Kind, probed: &Memory, pending: Pending, scan_ms: u64) -> Check {
    let t = |e: &Cond| e.holds(probed);
    match k {
        Kind::Never(e) if t(e) => Check::Violated,
        Kind::Always(e) if !t(e) => Check::Violated,
        Kind::Mutex(es) if es.iter().filter(|e| t(e)).count() > 1 => Check::Violated,
        Kind::Reachable(e) if t(e) => Check::Witness,
        Kind::Response {
            trigger,
            then,
            within_ms,
        } => {
            match pending {
                // The deadline passes at this scan: answered now is too late.
                Some(c) if u64::from(c + 1) * scan_ms > *within_ms => Check::Violated,
                Some(_) if t(then) => Check::Fine(None),
                Some(c) => Check::Fine(Some(c + 1)),
                None if t(trigger) && !t(then) => Check::Fine(Some(0)),
                None => Check::Fine(None),
            }
        }
        _ => Check::Fine(None),
    }
}

struct Node {
    parent: u32,
    combo: u64,
}

struct Frontier {
    node: u32,
    mem: Memory,
    /// Time of the scan that made this state, modulo the model's period.
    phase: u64,
    scans_odd: bool,
    pending: Pending,
    depth: u32,
}

fn key(m: &Memory, phase: u64, odd: bool, pending: Pending, out: &mut Vec<u8>) {
    out.clear();
    let mut byte = 0u8;
    for (k, &b) in m.b.iter().enumerate() {
        byte |= (b as u8) << (k % 8);
        if k % 8 == 7 {
            out.push(byte);
            byte = 0;
        }
    }
    out.push(byte);
    for v in &m.i {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in &m.f {
        out.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    for v in &m.l {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in &m.d {
        out.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    out.extend_from_slice(&m.m);
    out.extend_from_slice(&phase.to_le_bytes());
    out.push(odd as u8);
    out.extend_from_slice(&pending.map_or(u32::MAX, |c| c).to_le_bytes());
}

/// Decides `property` (under `assumes`) on the model.
pub fn decide(model: &Model, property: &Property, assumes: &[Cond], budget: Budget) -> Verdict {
    let started = Instant::now();
    // An invariant is first tried by k-induction (induct.rs): a proof there is
    // a proof; anything else leaves it to the explicit search.
    let setup = crate::induct::Setup {
        program: &model.program,
        probes: model.probes.program(),
        init: &model.program.init,
        inputs: model
            .inputs
            .iter()
            .filter_map(|i| match i.place {
                Place::Bool(b) => Some(b),
                _ => None,
            })
            .collect(),
    };
    let mut sat_calls = 0;
    match crate::induct::prove(&setup, property, assumes, budget.induction_k, budget.max_seconds) {
        Ok(proof) => {
            return Verdict {
                name: property.name.clone(),
                outcome: Outcome::Proved,
                method: Method::Induction(proof.k),
                sat_calls: proof.sat_calls,
                run: None,
                depth: proof.k,
                states: 0,
                millis: started.elapsed().as_millis(),
            };
        }
        Err(crate::induct::NoProof::NotInductive { sat_calls: n, .. }) => sat_calls = n,
        Err(_) => {}
    }
    let reduced = model.reduced(property, assumes);
    let model = &reduced;
    let mut verdict = Verdict {
        name: property.name.clone(),
        outcome: Outcome::Unknown(String::new()),
        method: Method::Explicit,
        sat_calls,
        run: None,
        depth: 0,
        states: 0,
        millis: 0,
    };
    let finish = |mut v: Verdict| {
        v.millis = started.elapsed().as_millis();
        v
    };
    if let Some(why) = &model.blocked {
        verdict.outcome = Outcome::Unknown(why.clone());
        return finish(verdict);
    }
    let combos = model.combinations();
    if combos > 1 << 20 {
        verdict.outcome = Outcome::Unknown(format!(
            "{} inputs give {combos} input combinations per scan, more than the search enumerates (2^20)",
            model.inputs.len()
        ));
        return finish(verdict);
    }
    let (mut engine, mut probes) =
        match Engine::new(model.program.clone()).and_then(|e| Evaluator::new(&model.probes).map(|p| (e, p))) {
            Ok(e) => e,
            Err(e) => {
                verdict.outcome = Outcome::Unknown(format!("the program does not load: {e}"));
                return finish(verdict);
            }
        };
    let scan_ms = model.scan_ms;
    let period = model.period;
    // Far from 0 so that ages never reach before it.
    let base = period * (1 + (1u64 << 33) / period);
    let mut nodes: Vec<Node> = vec![Node {
        parent: u32::MAX,
        combo: 0,
    }];
    let mut seen: HashSet<Box<[u8]>> = HashSet::new();
    let mut queue: VecDeque<Frontier> = VecDeque::new();
    let mut values = Vec::new();
    let mut kbuf = Vec::new();
    let init = model.program.init.clone();
    let memory_bytes = init.size_bytes();
    let state_bytes = {
        let mut k = Vec::new();
        key(&init, 0, false, None, &mut k);
        k.len()
    };
    // The root: no scan yet. Its successors are first scans at t = 0.
    let mut expand = |from: Option<&Frontier>,
                      nodes: &mut Vec<Node>,
                      queue: &mut VecDeque<Frontier>,
                      seen: &mut HashSet<Box<[u8]>>,
                      engine: &mut Engine|
     -> Result<Option<(u32, bool)>, String> {
        let (prev_abs, now_abs, odd, pending, depth, parent) = match from {
            None => (0, 0, false, None, 0, 0),
            Some(f) => {
                let prev = base + f.phase;
                (prev, prev + scan_ms, f.scans_odd, f.pending, f.depth, f.node)
            }
        };
        let mut start = match from {
            None => init.clone(),
            Some(f) => f.mem.clone(),
        };
        if from.is_some() {
            model.denormalize(&mut start, prev_abs);
        }
        for k in 0..combos {
            if model.parity && ((engine.scans() % 2 == 1) != odd) {
                let _ = engine.load_memory(&init);
                engine.restart();
                let _ = engine.scan(0);
            }
            engine.load_memory(&start).map_err(|e| format!("internal error: {e}"))?;
            if from.is_none() {
                engine.restart();
            }
            model.assign(k, &mut values);
            for (inp, v) in model.inputs.iter().zip(&values) {
                engine.write(inp.place, *v);
            }
            if let Err(m) = engine.scan(now_abs) {
                return Err(format!("a scan stops with a major fault: {}", m.message));
            }
            let probed = probes
                .run(engine.memory())
                .map_err(|e| format!("internal error: {e}"))?;
            if assumes.iter().any(|a| !a.holds(probed)) {
                continue;
            }
            let id = nodes.len() as u32;
            let outcome = check(&property.kind, probed, pending, scan_ms);
            let mut m = engine.memory().clone();
            let pend = match outcome {
                Check::Violated => {
                    nodes.push(Node { parent, combo: k });
                    return Ok(Some((id, false)));
                }
                Check::Witness => {
                    nodes.push(Node { parent, combo: k });
                    return Ok(Some((id, true)));
                }
                Check::Fine(p) => p,
            };
            model.normalize(&mut m, now_abs);
            let phase = now_abs % period;
            key(&m, phase, model.parity && !odd, pend, &mut kbuf);
            if seen.contains(kbuf.as_slice()) {
                continue;
            }
            seen.insert(kbuf.clone().into_boxed_slice());
            nodes.push(Node { parent, combo: k });
            queue.push_back(Frontier {
                node: id,
                mem: m,
                phase,
                scans_odd: !odd,
                pending: pend,
                depth: depth + 1,
            });
        }
        Ok(None)
    };
    let mut result = expand(None, &mut nodes, &mut queue, &mut seen, &mut engine);
    let mut depth = 1;
    loop {
        match result {
            Err(why) => {
                verdict.outcome = Outcome::Unknown(why);
                verdict.depth = depth;
                verdict.states = seen.len();
                return finish(verdict);
            }
            Ok(Some((id, witness))) => {
                let run = trace(&nodes, id, model);
                verdict.depth = run.scans.len() as u32;
                verdict.states = seen.len();
                verdict.outcome = if witness {
                    Outcome::Proved
                } else {
                    match replay(model, property, assumes, &run) {
                        Ok(()) => Outcome::Refuted,
                        Err(why) => Outcome::Unknown(why.to_string()),
                    }
                };
                verdict.run = Some(run);
                return finish(verdict);
            }
            Ok(None) => {}
        }
        let Some(f) = queue.pop_front() else { break };
        depth = depth.max(f.depth);
        // Each stored state is its key; each waiting one also its memory.
        let bytes = seen.len() * (state_bytes + 48) + queue.len() * (memory_bytes + 200) + nodes.len() * 16;
        if seen.len() > budget.max_states
            || f.depth >= budget.max_depth
            || started.elapsed().as_secs() >= budget.max_seconds
            || bytes > budget.max_bytes
        {
            verdict.outcome = Outcome::Unknown(format!(
                "the search stopped at its budget ({} states, depth {} scans, {} s, {} MB) without finding a violation",
                seen.len(),
                f.depth,
                started.elapsed().as_secs(),
                bytes >> 20
            ));
            verdict.depth = f.depth;
            verdict.states = seen.len();
            return finish(verdict);
        }
        result = expand(Some(&f), &mut nodes, &mut queue, &mut seen, &mut engine);
    }
    verdict.states = seen.len();
    verdict.depth = depth;
    verdict.outcome = match property.kind {
        Kind::Reachable(_) => Outcome::Refuted,
        _ => Outcome::Proved,
    };
    finish(verdict)
}

fn trace(nodes: &[Node], mut id: u32, model: &Model) -> Run {
    let mut combos = Vec::new();
    while id != 0 {
        let n = &nodes[id as usize];
        combos.push(n.combo);
        id = n.parent;
    }
    combos.reverse();
    let scans = combos
        .into_iter()
        .map(|k| {
            let mut v = Vec::new();
            model.assign(k, &mut v);
            v
        })
        .collect();
    Run {
        inputs: model.inputs.iter().map(|i| i.name.clone()).collect(),
        scans,
    }
}

/// The run as a stimulus (`time_ms,tag,value`): every input at 0, then each
/// change at its scan (every input at every scan when plant models, which
/// write their measurements each scan, are present).
pub fn stimulus(model: &Model, run: &Run) -> String {
    let mut out = String::from("time_ms,tag,value\n");
    let mut last: Option<&Vec<Value>> = None;
    for (k, scan) in run.scans.iter().enumerate() {
        let t = k as u64 * model.scan_ms;
        for (j, (name, v)) in run.inputs.iter().zip(scan).enumerate() {
            if model.plants || last.is_none_or(|l| l[j] != *v) {
                out.push_str(&format!("{t},{},{v}\n", csv_field(name)));
            }
        }
        last = Some(scan);
    }
    out
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Replays the run's stimulus as `alba sim` does (plant models stepped,
/// rows applied, one scan every scan period) and checks it ends in the
/// violation.
pub fn replay(model: &Model, property: &Property, assumes: &[Cond], run: &Run) -> Result<(), crate::ReplayError> {
    let text = stimulus(model, run);
    let mut files = alba_diag::Files::new();
    let f = files.add("counterexample.csv".to_string(), text);
    let stim = Stimulus::parse(files.text(f), f, &model.program.layout)
        .map_err(|d| crate::ReplayError::Counterexample(d[0].message.clone()))?;
    let mut engine = Engine::new(model.program.clone()).map_err(crate::ReplayError::Program)?;
    let mut probes = Evaluator::new(&model.probes).map_err(crate::ReplayError::Program)?;
    let mut next = 0;
    let mut pending = None;
    for k in 0..run.scans.len() as u64 {
        let t = k * model.scan_ms;
        engine.step_plants(t);
        while let Some(r) = stim.rows.get(next).filter(|r| r.time_ms <= t) {
            if let alba_engine::sim::Action::Set(v) = r.action {
                engine.write(r.place, v);
            }
            next += 1;
        }
        engine.scan(t).map_err(|m| crate::ReplayError::Fault(m.message))?;
        let m = probes.run(engine.memory()).map_err(crate::ReplayError::Program)?;
        if assumes.iter().any(|a| !a.holds(m)) {
            return Err(crate::ReplayError::Assumption);
        }
        match check(&property.kind, m, pending, model.scan_ms) {
            Check::Violated => return Ok(()),
            Check::Witness => return Ok(()),
            Check::Fine(p) => pending = p,
        }
    }
    Err(crate::ReplayError::NoViolation)
}
