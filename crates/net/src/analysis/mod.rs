//! Analysis of the underlying place/transition net ([`PtNet`]): guards, priorities and
//! tags are ignored.
//!
//! - Bounded nets: the full reachability graph ([`reachability`]) gives states, edges,
//!   per-place bounds, safeness, dead markings with a shortest firing sequence to one,
//!   dead transitions, liveness (L4: every terminal strongly connected component enables
//!   every transition) and reversibility (the initial marking is in the only terminal
//!   component).
//! - Unbounded nets: the Karp–Miller coverability graph ([`coverability`]) gives the
//!   per-place bounds (`ω` for unbounded places) and the dead transitions; deadlocks,
//!   edges and reversibility are then unknown (`None`), and liveness is `false` when a
//!   transition is dead and unknown otherwise.
//! - Inhibitor arcs: see [`reachability`] and [`coverability`]; when soundness cannot be
//!   guaranteed the boundedness is reported unknown rather than guessed.
//! - P- and T-invariants: [`invariants`]: a basis of the flows (polynomial, always) and
//!   the minimal semi-positive invariants (Farkas, exponential at worst) under a work
//!   budget of their own.
//!
//! - Beyond explicit states: the symbolic engine ([`symbolic`], decision diagrams)
//!   counts the reachable markings and firings exactly and finds the bounds, when asked
//!   ([`SymbolicMode::Always`]) or when the explicit exploration stops at its memory
//!   budget or its 2^27 states ([`SymbolicMode::Auto`]); its count then stands for the
//!   state space's (a note says so), and its [`symbolic::Facts`] (deadlocks and a
//!   firing sequence to one, a shortest one when its breadth-first layers fit, dead
//!   transitions, liveness, reversibility) for the explicit graph's.
//!
//! No part blocks another: the state space and its facts come first, then the flows,
//! then the minimal invariants, and each part reports a [`Status`] (`complete`,
//! `partial`, `skipped: …`). A [`Control`] carries a cancellation flag, polled by every
//! part, and a progress callback; [`Options::memory`] bounds the state space's memory.

pub mod bench;
pub mod coverability;
pub mod formula;
pub mod invariants;
mod json;
pub mod reachability;
pub mod samples;
pub mod stubborn;
pub mod symbolic;

pub use json::to_json;

use crate::PtNet;
use invariants::{Budget, InvariantError};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Which invariants are computed besides the flows' basis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Invariants {
    /// The basis of the P- and T-flows only.
    Flows,
    /// Also the minimal semi-positive invariants, within [`Options::invariant_work`].
    Minimal,
}

/// When the symbolic engine ([`symbolic`]) runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SymbolicMode {
    /// When the explicit exploration stops at its memory budget or its 2^27 states (not
    /// at `max_states`), on nets without inhibitor arcs.
    Auto,
    /// Always (`alba analyze --symbolic`): first, after a probe of the explicit
    /// exploration ([`PROBE_STATES`]); the explicit one is then skipped when the count
    /// shows it cannot fit.
    Always,
    /// Never.
    Off,
}

/// States the explicit probe of [`SymbolicMode::Always`] explores before the symbolic
/// engine runs (small nets are then done explicitly, unbounded ones refused).
pub const PROBE_STATES: usize = 1 << 16;

/// Limits of the analysis.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Largest number of states (or coverability nodes) explored.
    pub max_states: usize,
    /// Bytes the state space may use (markings, index, the SCC pass).
    pub memory: usize,
    /// Which invariants.
    pub invariants: Invariants,
    /// Work units of the minimal invariants (each of P and T).
    pub invariant_work: u64,
    /// Largest number of intermediate rows in the Farkas algorithm.
    pub max_invariant_rows: usize,
    /// When the symbolic engine runs (its memory budget is [`Options::memory`]).
    pub symbolic: SymbolicMode,
    /// The symbolic engine's time budget.
    pub symbolic_time: Duration,
    /// Threads of the explicit exploration and of the SCC pass's reversibility check
    /// (the results do not depend on it).
    pub threads: usize,
}

/// The default number of threads: the available parallelism, at most 2.
pub fn default_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get().min(2))
}

/// The default memory budget of the state space: 2 GiB.
pub const DEFAULT_MEMORY: usize = 2 << 30;

impl Default for Options {
    fn default() -> Options {
        Options {
            max_states: usize::MAX,
            memory: DEFAULT_MEMORY,
            invariants: Invariants::Minimal,
            invariant_work: invariants::DEFAULT_WORK,
            max_invariant_rows: invariants::MAX_ROWS,
            symbolic: SymbolicMode::Auto,
            symbolic_time: Duration::from_secs(600),
            threads: default_threads(),
        }
    }
}

/// The part of the analysis running.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// Building the state space.
    StateSpace,
    /// The strongly connected components (liveness, reversibility).
    Components,
    /// The flows' basis.
    Flows,
    /// The minimal semi-positive invariants.
    Invariants,
}

impl Part {
    /// The part's name in JSON and progress reports.
    pub fn name(self) -> &'static str {
        match self {
            Part::StateSpace => "state_space",
            Part::Components => "components",
            Part::Flows => "flows",
            Part::Invariants => "invariants",
        }
    }
}

/// Where the analysis is.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// The part running.
    pub part: Part,
    /// States found (state space) or visited (components).
    pub states: u64,
    /// Bytes the state space uses.
    pub bytes: usize,
}

/// How a caller steers a running analysis.
#[derive(Clone, Copy)]
pub struct Control<'a> {
    /// Raised to stop: every part polls it and ends as `skipped: cancelled` or `partial`.
    pub cancel: &'a AtomicBool,
    /// Called as the analysis goes (every 16 384 states, and at each part's start).
    pub progress: &'a (dyn Fn(&Progress) + Sync),
}

static NEVER: AtomicBool = AtomicBool::new(false);

impl Control<'static> {
    /// Never cancelled, no progress.
    pub fn none() -> Control<'static> {
        Control {
            cancel: &NEVER,
            progress: &|_| {},
        }
    }
}

impl Control<'_> {
    /// Whether the analysis is cancelled.
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// How far a part got.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Status {
    /// Done: its results are exact.
    Complete,
    /// Stopped before the end (see [`Analysis::stopped`]); its results are unknown or a
    /// lower bound.
    Partial,
    /// Not run, or its results dropped, for this reason (`budget`, `cancelled`,
    /// `overflow`, `not requested`, `state space incomplete`).
    Skipped(&'static str),
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Status::Complete => write!(f, "complete"),
            Status::Partial => write!(f, "partial"),
            Status::Skipped(why) => write!(f, "skipped: {why}"),
        }
    }
}

/// Each part's status.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Statuses {
    /// The state space (states, edges, bounds, deadlocks, dead transitions).
    pub state_space: Status,
    /// Liveness and reversibility (the SCC pass).
    pub components: Status,
    /// The basis of the P-flows.
    pub p_flows: Status,
    /// The basis of the T-flows.
    pub t_flows: Status,
    /// The minimal semi-positive P-invariants.
    pub p_invariants: Status,
    /// The minimal semi-positive T-invariants.
    pub t_invariants: Status,
    /// The symbolic engine.
    pub symbolic: Status,
    /// Deadlocks, dead transitions, liveness and reversibility from the symbolic engine
    /// ([`symbolic::Facts`]).
    pub symbolic_facts: Status,
}

/// A place bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// At most this many tokens.
    Finite(u32),
    /// Unbounded.
    Omega,
}

/// Which state space was built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    /// The full reachability graph (the net is bounded).
    Reachability,
    /// The Karp–Miller coverability graph (the net is unbounded).
    Coverability,
    /// None completed (limit reached or unsound with inhibitor arcs).
    Incomplete,
}

/// Invariants (coefficients per place or transition), or why there are none.
pub type InvariantList = Result<Vec<Vec<i64>>, InvariantError>;

/// The results. `None` means unknown (see [`Analysis::stopped`]) or not applicable.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// Number of places.
    pub places: usize,
    /// Number of transitions.
    pub transitions: usize,
    /// The state space built.
    pub space: Space,
    /// Whether the net is bounded.
    pub bounded: Option<bool>,
    /// Whether every place holds at most one token.
    pub safe: Option<bool>,
    /// Bound per place.
    pub place_bounds: Option<Vec<Bound>>,
    /// Largest number of tokens in one reachable marking (bounded nets).
    pub max_tokens: Option<u64>,
    /// Reachable markings (bounded) or coverability nodes (unbounded).
    pub states: Option<u64>,
    /// Edges of the reachability graph (`None` when unbounded).
    pub edges: Option<u64>,
    /// Number of dead markings (`None` when unbounded).
    pub deadlocks: Option<u64>,
    /// A firing sequence (transition indices) to a dead marking.
    pub deadlock_trace: Option<Vec<usize>>,
    /// Whether that sequence is a shortest one: the explicit engine's always are, the
    /// symbolic engine's when its breadth-first layers fit (else a note says so).
    pub deadlock_trace_shortest: bool,
    /// The dead marking it reaches.
    pub deadlock_marking: Option<Vec<u32>>,
    /// Transitions never enabled in any reachable marking.
    pub dead_transitions: Option<Vec<usize>>,
    /// Liveness (L4).
    pub live: Option<bool>,
    /// Whether the initial marking is reachable from every reachable marking.
    pub reversible: Option<bool>,
    /// Strongly connected components of the reachability graph.
    pub components: Option<u64>,
    /// A basis of the P-flows (coefficients of any sign, per place).
    pub p_flows: InvariantList,
    /// A basis of the T-flows (per transition).
    pub t_flows: InvariantList,
    /// Minimal semi-positive P-invariants (coefficient per place).
    pub p_invariants: InvariantList,
    /// Minimal semi-positive T-invariants (coefficient per transition).
    pub t_invariants: InvariantList,
    /// Each part's status.
    pub status: Statuses,
    /// Why the state-space analysis is incomplete, when it is.
    pub stopped: Option<String>,
    /// Notes on what the result means (guards ignored, inhibitor arcs …).
    pub notes: Vec<String>,
    /// Bytes used by the state-space data structures (the largest at any time).
    pub memory_bytes: usize,
    /// Time to build the state space.
    pub explore_time: Duration,
    /// Time of the SCC pass (liveness, reversibility).
    pub scc_time: Duration,
    /// Time of the invariant computation (flows and minimal invariants).
    pub invariant_time: Duration,
    /// What the symbolic engine found and cost (see [`Statuses::symbolic`]).
    pub symbolic: SymbolicReport,
}

/// The symbolic engine's part of the analysis.
#[derive(Clone, Debug, Default)]
pub struct SymbolicReport {
    /// Its results when it completed.
    pub result: Option<symbolic::Symbolic>,
    /// Decision-diagram nodes made.
    pub nodes: usize,
    /// Bytes its tables used.
    pub bytes: usize,
    /// Time it took.
    pub time: Duration,
}

/// The status of an invariant part from its result.
fn invariant_status(r: &InvariantList) -> Status {
    match r {
        Ok(_) => Status::Complete,
        Err(InvariantError::Overflow) => Status::Skipped("overflow"),
        Err(InvariantError::Cancelled) => Status::Skipped("cancelled"),
        Err(InvariantError::Budget(_) | InvariantError::TooManyRows(_)) => Status::Skipped("budget"),
    }
}

/// Analyses `net` within `options`, steered by `control`: the state space and its facts
/// first, then the flows' basis, then (when asked) the minimal invariants.
pub fn analyze(net: &PtNet, options: &Options, control: &Control<'_>) -> Analysis {
    let np = net.places.len();
    let nt = net.transitions.len();
    let skipped = Status::Skipped("not requested");
    let mut a = Analysis {
        places: np,
        transitions: nt,
        space: Space::Incomplete,
        bounded: None,
        safe: None,
        place_bounds: None,
        max_tokens: None,
        states: None,
        edges: None,
        deadlocks: None,
        deadlock_trace: None,
        deadlock_trace_shortest: true,
        deadlock_marking: None,
        dead_transitions: None,
        live: None,
        reversible: None,
        components: None,
        p_flows: Err(InvariantError::Cancelled),
        t_flows: Err(InvariantError::Cancelled),
        p_invariants: Err(InvariantError::Cancelled),
        t_invariants: Err(InvariantError::Cancelled),
        status: Statuses {
            state_space: Status::Partial,
            components: Status::Skipped("state space incomplete"),
            p_flows: skipped.clone(),
            t_flows: skipped.clone(),
            p_invariants: skipped.clone(),
            t_invariants: skipped.clone(),
            symbolic_facts: skipped.clone(),
            symbolic: skipped,
        },
        stopped: None,
        notes: vec![
            "guards, priorities and tags are ignored: this is the analysis of the underlying place/transition net"
                .into(),
        ],
        memory_bytes: 0,
        explore_time: Duration::ZERO,
        scc_time: Duration::ZERO,
        invariant_time: Duration::ZERO,
        symbolic: SymbolicReport::default(),
    };
    if net.has_inhibitors() {
        a.notes.push(
            "inhibitor arcs: unboundedness is concluded only from growth of places without inhibitor arcs; \
             otherwise the boundedness is reported unknown"
                .into(),
        );
    }
    state_space(net, options, control, &mut a);
    let progress = |part| {
        (control.progress)(&Progress {
            part,
            states: a.states.unwrap_or(0),
            bytes: a.memory_bytes,
        })
    };
    let inv_start = Instant::now();
    progress(Part::Flows);
    a.p_flows = invariants::p_flows(net, control.cancel);
    a.t_flows = invariants::t_flows(net, control.cancel);
    a.status.p_flows = invariant_status(&a.p_flows);
    a.status.t_flows = invariant_status(&a.t_flows);
    if options.invariants == Invariants::Minimal {
        progress(Part::Invariants);
        let budget = Budget {
            work: options.invariant_work,
            max_rows: options.max_invariant_rows,
            cancel: control.cancel,
        };
        a.p_invariants = invariants::p_invariants(net, budget);
        a.t_invariants = invariants::t_invariants(net, budget);
        a.status.p_invariants = invariant_status(&a.p_invariants);
        a.status.t_invariants = invariant_status(&a.t_invariants);
    }
    a.invariant_time = inv_start.elapsed();
    a
}

/// The state space and the facts that come from it: explicitly, symbolically, or both
/// (see [`SymbolicMode`]).
fn state_space(net: &PtNet, options: &Options, control: &Control<'_>, a: &mut Analysis) {
    let start = Instant::now();
    let limits = reachability::Limits {
        max_states: options.max_states,
        memory: options.memory,
    };
    let capacity = options.max_states.min(reachability::MAX_STATES);
    let at_budget = |e: &reachability::Explored| match e {
        reachability::Explored::Limit { why, .. } => {
            *why == reachability::Stop::Memory
                || (*why == reachability::Stop::States && options.max_states > reachability::MAX_STATES)
        }
        _ => false,
    };
    let mut explored = None;
    if options.symbolic == SymbolicMode::Always {
        let probe = reachability::explore_threads(
            net,
            &reachability::Limits {
                max_states: capacity.min(PROBE_STATES),
                ..limits
            },
            options.threads,
            control,
        );
        let larger = matches!(probe, reachability::Explored::Limit { why, .. }
            if why == reachability::Stop::Memory || (why == reachability::Stop::States && capacity > PROBE_STATES));
        if larger {
            run_symbolic(net, options, control, a);
            if let Some(s) = &a.symbolic.result {
                let n = &s.states;
                // The explicit store needs at least the packed marking per state.
                let bits: u64 = s
                    .place_bounds
                    .iter()
                    .map(|v| u64::from(32 - v.leading_zeros()).max(1))
                    .sum();
                let bytes = bits.div_ceil(8).max(1);
                let fits = n
                    .to_u64()
                    .is_some_and(|n| n <= capacity as u64 && n.saturating_mul(bytes) <= options.memory as u64);
                if !fits {
                    a.explore_time = start.elapsed();
                    a.status.state_space = Status::Skipped("budget");
                    a.stopped = Some(format!(
                        "the explicit exploration was skipped: the symbolic engine counted {n} states, more than it can hold \
                         ({capacity} states, --max-states, or {} MiB at {bytes} bytes a state at least, --memory)",
                        options.memory >> 20
                    ));
                    adopt_symbolic(a);
                    return;
                }
            }
        } else {
            explored = Some(probe);
        }
    }
    let explored = explored.unwrap_or_else(|| reachability::explore_threads(net, &limits, options.threads, control));
    let fallback = options.symbolic == SymbolicMode::Always
        || (options.symbolic == SymbolicMode::Auto && at_budget(&explored) && !net.has_inhibitors());
    explicit(net, explored, options, control, start, a);
    if a.bounded == Some(false) {
        a.status.symbolic = Status::Skipped("unbounded");
    } else if fallback && a.status.symbolic == Status::Skipped("not requested") {
        run_symbolic(net, options, control, a);
    }
    adopt_symbolic(a);
}

/// When the explicit state space is incomplete and the symbolic engine completed: its
/// states, firings and bounds stand for the state space's, with a note.
fn adopt_symbolic(a: &mut Analysis) {
    let Some(s) = &a.symbolic.result else {
        return;
    };
    if a.status.state_space == Status::Complete {
        return;
    }
    a.bounded = Some(true);
    a.safe = Some(s.place_bounds.iter().all(|&b| b <= 1));
    a.place_bounds = Some(s.place_bounds.iter().map(|&b| Bound::Finite(b)).collect());
    a.max_tokens = Some(s.max_tokens);
    a.states = s.states.to_u64();
    a.edges = s.firings.to_u64();
    a.notes.push(format!(
        "states ({}), edges ({}), place bounds, most tokens per marking, deadlocks, dead transitions, liveness and \
         reversibility come from the symbolic engine (decision diagrams)",
        s.states, s.firings
    ));
    if let Some(f) = s.facts.clone() {
        f.adopt(a);
    }
}

/// Runs the symbolic engine.
fn run_symbolic(net: &PtNet, options: &Options, control: &Control<'_>, a: &mut Analysis) {
    let limits = symbolic::Limits {
        memory: options.memory,
        time: options.symbolic_time,
        facts: true,
        ..symbolic::Limits::default()
    };
    let o = symbolic::explore(net, &limits, control.cancel);
    a.symbolic.nodes = o.nodes;
    a.symbolic.bytes = o.bytes;
    a.symbolic.time = o.time;
    a.memory_bytes = a.memory_bytes.max(o.bytes);
    let s = match o.result {
        Ok(s) => s,
        Err(why) => {
            a.status.symbolic = Status::Skipped(match why {
                symbolic::Stop::Cancelled => "cancelled",
                symbolic::Stop::Overflow => "overflow",
                symbolic::Stop::Nodes | symbolic::Stop::Memory | symbolic::Stop::Time | symbolic::Stop::Beaten => {
                    "budget"
                }
            });
            a.status.symbolic_facts = a.status.symbolic.clone();
            a.notes.push(format!(
                "symbolic engine stopped ({}) after {} nodes, {:.3} s",
                why.reason(),
                o.nodes,
                o.time.as_secs_f64()
            ));
            return;
        }
    };
    a.status.symbolic = Status::Complete;
    a.status.symbolic_facts = s
        .facts
        .as_ref()
        .map_or(Status::Skipped("not requested"), symbolic::Facts::status);
    a.symbolic.result = Some(s);
}

/// The explicit state space's facts (reachability graph, coverability graph, or why it
/// stopped).
fn explicit(
    net: &PtNet,
    explored: reachability::Explored,
    options: &Options,
    control: &Control<'_>,
    start: Instant,
    a: &mut Analysis,
) {
    let np = net.places.len();
    let nt = net.transitions.len();
    match explored {
        reachability::Explored::Graph(g) => {
            a.explore_time = start.elapsed();
            a.space = Space::Reachability;
            a.status.state_space = Status::Complete;
            a.bounded = Some(true);
            a.safe = Some(g.max.iter().all(|&m| m <= 1));
            a.place_bounds = Some(g.max.iter().map(|&m| Bound::Finite(m)).collect());
            a.max_tokens = Some(g.max_tokens);
            a.states = Some(g.store.len() as u64);
            a.edges = Some(g.edges);
            a.deadlocks = Some(g.deadlocks);
            if let Some(d) = g.first_deadlock {
                a.deadlock_trace = g.deadlock_trace.clone();
                let mut words = vec![0u64; g.store.layout.bytes.div_ceil(8) + 1];
                let mut m = vec![0u32; np];
                g.store.marking(d as usize, &mut words, &mut m);
                a.deadlock_marking = Some(m);
            }
            a.dead_transitions = Some((0..nt).filter(|&t| !g.fired[t]).collect());
            a.memory_bytes = g.peak_bytes;
            (control.progress)(&Progress {
                part: Part::Components,
                states: 0,
                bytes: g.bytes_used(),
            });
            let scc = Instant::now();
            let left = options.memory.saturating_sub(g.bytes_used());
            match reachability::components(net, &g, options.threads, left, control) {
                Ok((c, bytes)) => {
                    a.live = Some(c.live);
                    a.reversible = Some(c.reversible);
                    a.components = Some(c.count as u64);
                    a.status.components = Status::Complete;
                    a.memory_bytes = a.memory_bytes.max(g.bytes_used() + bytes);
                }
                Err(reachability::SccStop::Budget) => a.status.components = Status::Skipped("budget"),
                Err(reachability::SccStop::Cancelled) => a.status.components = Status::Skipped("cancelled"),
            }
            a.scc_time = scc.elapsed();
        }
        reachability::Explored::Unbounded => {
            match coverability::coverability(net, options.max_states, control.cancel) {
                coverability::Coverability::Graph {
                    nodes,
                    edges: _,
                    enabled,
                } => {
                    a.explore_time = start.elapsed();
                    a.space = Space::Coverability;
                    a.status.state_space = Status::Complete;
                    let bounds: Vec<Bound> = (0..np)
                        .map(|p| {
                            let m = nodes.iter().map(|n| n[p]).max().unwrap_or(0);
                            if m == coverability::OMEGA {
                                Bound::Omega
                            } else {
                                Bound::Finite(m)
                            }
                        })
                        .collect();
                    a.bounded = Some(false);
                    a.safe = Some(false);
                    a.place_bounds = Some(bounds);
                    a.states = Some(nodes.len() as u64);
                    let dead: Vec<usize> = (0..nt).filter(|&t| !enabled[t]).collect();
                    a.live = if dead.is_empty() { None } else { Some(false) };
                    a.status.components = if dead.is_empty() {
                        Status::Skipped("unbounded")
                    } else {
                        Status::Complete
                    };
                    a.dead_transitions = Some(dead);
                    a.memory_bytes = nodes.len() * (np * 4 + 48);
                    a.notes.push(
                        "unbounded: Karp–Miller coverability graph; states counts its nodes; edges, deadlocks and reversibility are not computed"
                            .into(),
                    );
                }
                coverability::Coverability::Limit => {
                    a.bounded = Some(false);
                    a.safe = Some(false);
                    a.stopped = Some(if control.cancelled() {
                        "cancelled".to_string()
                    } else {
                        format!(
                            "the net is unbounded and its coverability graph has more than {} nodes (--max-states)",
                            options.max_states
                        )
                    });
                }
                coverability::Coverability::InhibitorOmega(p) => {
                    a.stopped = Some(format!(
                        "place {} would be unbounded but an inhibitor arc reads it: the coverability graph would not be sound, boundedness unknown",
                        net.places[p]
                    ));
                }
            }
        }
        reachability::Explored::Limit { why, states, bytes } => {
            a.explore_time = start.elapsed();
            a.memory_bytes = bytes;
            a.stopped = Some(match why {
                reachability::Stop::Cancelled => format!("cancelled after {states} states"),
                reachability::Stop::States => format!(
                    "stopped after {} states (--max-states): the state space is incomplete",
                    options.max_states
                ),
                reachability::Stop::Memory => format!(
                    "stopped after {states} states: the state space needs more than {} MiB (--memory)",
                    options.memory >> 20
                ),
            });
        }
        reachability::Explored::Overflow => {
            a.stopped = Some("a place count exceeds 2^32-1: boundedness unknown".into());
        }
    }
}
