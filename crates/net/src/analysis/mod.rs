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
//! - P- and T-invariants: [`invariants`] (Farkas), independent of the state space.

pub mod bench;
pub mod coverability;
pub mod invariants;
mod json;
pub mod reachability;
pub mod samples;

pub use json::to_json;

use crate::PtNet;
use std::time::{Duration, Instant};

/// Limits of the analysis.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Largest number of states (or coverability nodes) explored.
    pub max_states: usize,
    /// Largest number of intermediate rows in the Farkas algorithm.
    pub max_invariant_rows: usize,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            max_states: 10_000_000,
            max_invariant_rows: invariants::MAX_ROWS,
        }
    }
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
    /// Reachable markings (bounded) or coverability nodes (unbounded).
    pub states: Option<u64>,
    /// Edges of the reachability graph (`None` when unbounded).
    pub edges: Option<u64>,
    /// Number of dead markings (`None` when unbounded).
    pub deadlocks: Option<u64>,
    /// A shortest firing sequence (transition indices) to a dead marking.
    pub deadlock_trace: Option<Vec<usize>>,
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
    /// Minimal semi-positive P-invariants (coefficient per place).
    pub p_invariants: Result<Vec<Vec<i64>>, invariants::InvariantError>,
    /// Minimal semi-positive T-invariants (coefficient per transition).
    pub t_invariants: Result<Vec<Vec<i64>>, invariants::InvariantError>,
    /// Why the state-space analysis is incomplete, when it is.
    pub stopped: Option<String>,
    /// Notes on what the result means (guards ignored, inhibitor arcs …).
    pub notes: Vec<String>,
    /// Bytes used by the state-space data structures.
    pub memory_bytes: usize,
    /// Time to build the state space.
    pub explore_time: Duration,
    /// Time of the SCC pass (liveness, reversibility).
    pub scc_time: Duration,
    /// Time of the invariant computation.
    pub invariant_time: Duration,
}

/// Analyses `net` within `options`; `cancel` is polled and stops the exploration when true.
pub fn analyze(net: &PtNet, options: &Options, cancel: &dyn Fn() -> bool) -> Analysis {
    let np = net.places.len();
    let nt = net.transitions.len();
    let mut a = Analysis {
        places: np,
        transitions: nt,
        space: Space::Incomplete,
        bounded: None,
        safe: None,
        place_bounds: None,
        states: None,
        edges: None,
        deadlocks: None,
        deadlock_trace: None,
        deadlock_marking: None,
        dead_transitions: None,
        live: None,
        reversible: None,
        components: None,
        p_invariants: Ok(Vec::new()),
        t_invariants: Ok(Vec::new()),
        stopped: None,
        notes: vec![
            "guards, priorities and tags are ignored: this is the analysis of the underlying place/transition net"
                .into(),
        ],
        memory_bytes: 0,
        explore_time: Duration::ZERO,
        scc_time: Duration::ZERO,
        invariant_time: Duration::ZERO,
    };
    if net.has_inhibitors() {
        a.notes.push(
            "inhibitor arcs: unboundedness is concluded only from growth of places without inhibitor arcs; \
             otherwise the boundedness is reported unknown"
                .into(),
        );
    }
    let inv_start = Instant::now();
    a.p_invariants = invariants::p_invariants(net, options.max_invariant_rows);
    a.t_invariants = invariants::t_invariants(net, options.max_invariant_rows);
    a.invariant_time = inv_start.elapsed();
    let start = Instant::now();
    match reachability::explore(net, options.max_states, cancel) {
        reachability::Explored::Graph(g) => {
            a.explore_time = start.elapsed();
            a.space = Space::Reachability;
            a.bounded = Some(true);
            a.safe = Some(g.max.iter().all(|&m| m <= 1));
            a.place_bounds = Some(g.max.iter().map(|&m| Bound::Finite(m)).collect());
            a.states = Some(g.store.len() as u64);
            a.edges = Some(g.edges);
            a.deadlocks = Some(g.deadlocks);
            if let Some(d) = g.first_deadlock {
                a.deadlock_trace = Some(g.trace(d));
                let mut words = vec![0u64; g.store.layout.bytes.div_ceil(8) + 1];
                let mut m = vec![0u32; np];
                g.store.marking(d as usize, &mut words, &mut m);
                a.deadlock_marking = Some(m);
            }
            a.dead_transitions = Some((0..nt).filter(|&t| !g.fired[t]).collect());
            let scc = Instant::now();
            let c = reachability::components(net, &g);
            a.scc_time = scc.elapsed();
            a.live = Some(c.live);
            a.reversible = Some(c.reversible);
            a.components = Some(c.count as u64);
            // Tarjan's per-state word and two bit sets on top of the graph.
            a.memory_bytes = g.bytes_used() + g.store.len() * 4 + g.store.len() / 4;
        }
        reachability::Explored::Unbounded => match coverability::coverability(net, options.max_states, cancel) {
            coverability::Coverability::Graph {
                nodes,
                edges: _,
                enabled,
            } => {
                a.explore_time = start.elapsed();
                a.space = Space::Coverability;
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
                a.stopped = Some(format!(
                    "the net is unbounded and its coverability graph has more than {} nodes (--max-states)",
                    options.max_states
                ));
            }
            coverability::Coverability::InhibitorOmega(p) => {
                a.stopped = Some(format!(
                    "place {} would be unbounded but an inhibitor arc reads it: the coverability graph would not be sound, boundedness unknown",
                    net.places[p]
                ));
            }
        },
        reachability::Explored::Limit => {
            a.stopped = Some(if cancel() {
                "interrupted".to_string()
            } else {
                format!(
                    "stopped after {} states (--max-states): the state space is incomplete",
                    options.max_states
                )
            });
        }
        reachability::Explored::Overflow => {
            a.stopped = Some("a place count exceeds 2^32-1: boundedness unknown".into());
        }
    }
    a
}
