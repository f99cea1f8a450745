//! A symbolic state-space engine: the reachable markings of a bounded place/transition
//! net as a multi-valued decision diagram (MDD), built by saturation, counted exactly.
//!
//! - **Diagram**: quasi-reduced MDD, one level per place (every path visits every level),
//!   sparse edges `(tokens, child)` sorted by token count, so a place's domain is
//!   whatever counts occur and no bound is needed in advance. Two terminals: `0` (the
//!   empty set, at every level) and `1` (the set of the empty suffix). A unique table makes
//!   equal nodes one node; the union, the relational product and the saturation have
//!   their operation caches. Nodes are never freed: the node budget bounds them.
//! - **Variable order**: the FORCE heuristic (Aloul, Markov, Sakallah 2003): starting
//!   from the places' order in the file, each transition pulls its places towards their
//!   centre of gravity, a few rounds, keeping the order with the smallest total span of
//!   the transitions (the file's order when it is already the best). Level 0 (the root)
//!   is the first place of that order. A smaller span is not always faster, so that
//!   order and the file's run at once on two threads ([`explore`]).
//! - **Saturation** (Ciardo, Lüttgen, Siminiceanu 2001): each transition belongs to the
//!   topmost level it reads or writes; a node is saturated when its sub-diagram is
//!   closed under the transitions of its level and below. Nodes are saturated bottom-up,
//!   and the image of a transition below its top level is saturated as it is built.
//!   Inputs, read arcs and inhibitor arcs are tests on their place's level.
//! - **Results**: the exact number of reachable markings and of firings (edges of the
//!   reachability graph: for each transition, the markings that enable it), as
//!   arbitrary-precision integers ([`Count`]; the contest has counts beyond 10^47), each
//!   place's bound and the most tokens in one marking; when asked ([`Limits::facts`]),
//!   deadlocks (with a trace to one, a shortest one when the breadth-first layers fit),
//!   dead transitions, liveness and reversibility ([`Facts`]).
//! - **Limits**: a node budget, a memory budget (the nodes, the unique table and the
//!   caches), a time budget and the cancellation flag: the engine stops with a reason,
//!   never runs out of memory. An unbounded net never saturates: the callers refuse
//!   those the explicit exploration found unbounded, and the budget stops the others.

use crate::PtNet;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A non-negative integer of any size (little-endian 64-bit limbs, no leading zero limb).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Count(Vec<u64>);

impl Count {
    /// `n`.
    pub fn from_u64(n: u64) -> Count {
        Count(if n == 0 { Vec::new() } else { vec![n] })
    }

    /// `self += o`.
    pub fn add(&mut self, o: &Count) {
        if self.0.len() < o.0.len() {
            self.0.resize(o.0.len(), 0);
        }
        let mut carry = false;
        for i in 0..self.0.len() {
            let b = o.0.get(i).copied().unwrap_or(0);
            if b == 0 && !carry && i >= o.0.len() {
                break;
            }
            let (s1, c1) = self.0[i].overflowing_add(b);
            let (s2, c2) = s1.overflowing_add(u64::from(carry));
            self.0[i] = s2;
            carry = c1 || c2;
        }
        if carry {
            self.0.push(1);
        }
    }

    /// The value when it fits in a `u64`.
    pub fn to_u64(&self) -> Option<u64> {
        match self.0.as_slice() {
            [] => Some(0),
            [n] => Some(*n),
            _ => None,
        }
    }
}

impl std::fmt::Display for Count {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const BASE: u64 = 10_000_000_000_000_000_000; // 10^19
        let mut limbs = self.0.clone();
        let mut parts = Vec::new();
        while !limbs.is_empty() {
            let mut rem = 0u128;
            for l in limbs.iter_mut().rev() {
                let cur = (rem << 64) | u128::from(*l);
                *l = (cur / u128::from(BASE)) as u64;
                rem = cur % u128::from(BASE);
            }
            while limbs.last() == Some(&0) {
                limbs.pop();
            }
            parts.push(rem as u64);
        }
        match parts.split_last() {
            None => write!(f, "0"),
            Some((top, rest)) => {
                write!(f, "{top}")?;
                for p in rest.iter().rev() {
                    write!(f, "{p:019}")?;
                }
                Ok(())
            }
        }
    }
}

/// The FxHash mixing step (fast, good enough for node ids and edge lists).
#[derive(Default, Clone, Copy)]
struct Fx(u64);

impl Hasher for Fx {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u32(&mut self, n: u32) {
        self.write_u64(u64::from(n));
    }
    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type FxMap<K, V> = HashMap<K, V, BuildHasherDefault<Fx>>;

/// Limits of [`explore`].
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Largest number of nodes created.
    pub max_nodes: usize,
    /// Bytes the nodes, the unique tables and the caches may use (both orders together).
    pub memory: usize,
    /// Time budget.
    pub time: Duration,
    /// Whether to decide the [`Facts`] too (within the same budgets).
    pub facts: bool,
    /// Whether the trace to a deadlock is looked for by breadth-first layers first (a
    /// shortest one when they fit in their budget), or by chaining at once (one trace,
    /// not always a shortest; see [`Facts::deadlock_trace`]).
    pub shortest_trace: bool,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_nodes: 1 << 28,
            memory: super::DEFAULT_MEMORY,
            time: Duration::from_secs(600),
            facts: false,
            shortest_trace: true,
        }
    }
}

/// Why the engine stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// [`Limits::max_nodes`].
    Nodes,
    /// [`Limits::memory`].
    Memory,
    /// [`Limits::time`].
    Time,
    /// The cancellation flag.
    Cancelled,
    /// A place would hold more than 2^32-1 tokens.
    Overflow,
    /// The other order's run completed first; never returned by [`explore`].
    Beaten,
}

impl Stop {
    /// The reason in words.
    pub fn reason(self) -> &'static str {
        match self {
            Stop::Nodes => "node budget",
            Stop::Memory => "memory budget",
            Stop::Time => "time budget",
            Stop::Cancelled => "cancelled",
            Stop::Overflow => "a place count exceeds 2^32-1",
            Stop::Beaten => "the other order completed first",
        }
    }
}

/// What the engine found.
#[derive(Clone, Debug)]
pub struct Symbolic {
    /// Reachable markings.
    pub states: Count,
    /// Firings: the edges of the reachability graph (for each transition, the markings
    /// that enable it).
    pub firings: Count,
    /// Bound per place.
    pub place_bounds: Vec<u32>,
    /// Most tokens in one reachable marking.
    pub max_tokens: u64,
    /// Nodes of the final diagram (terminals included).
    pub final_nodes: usize,
    /// The variable order: places from the root down.
    pub order: Vec<usize>,
    /// Deadlocks, dead transitions, liveness and reversibility, when asked
    /// ([`Limits::facts`]).
    pub facts: Option<Facts>,
}

/// What the diagrams decide besides the counts, each fact its value or why it is
/// unknown (the budget, or cancelled):
///
/// - dead transitions: those whose enabling set meets no reachable marking;
/// - deadlocks: the reachable markings minus the union of the enabling sets;
/// - a trace to a deadlock, decided last, within a quarter of the time left and as many
///   nodes again as the rest made: a shortest one by breadth-first layers from the
///   initial marking until one meets the deadlocks, then back from a dead marking
///   through the layers (its predecessor in the layer before, marking by marking),
///   when they fit in that budget; else, with a budget of its own computed the same
///   way, one by chaining (each transition's image added to the markings reached in
///   turn, sweep after sweep, until they meet the deadlocks; then back through the
///   steps that added markings), whose sets stay close to the saturated diagrams where
///   the layers do not (`Philosophers-PT-000100`);
/// - reversibility: the markings from which the initial one is reachable, found by
///   saturation backwards (the transitions reversed) constrained to the reachable
///   markings, are all of them;
/// - liveness (L4): for every transition, the markings from which one enabling it is
///   reachable (the same backward saturation from its enabling set) are all the
///   reachable markings; a dead transition or a deadlock settles it at once, and so
///   does reversibility (then every transition that is not dead is live).
#[derive(Clone, Debug)]
pub struct Facts {
    /// Transitions enabled in no reachable marking.
    pub dead_transitions: Result<Vec<usize>, Stop>,
    /// Reachable markings enabling no transition.
    pub deadlocks: Result<Count, Stop>,
    /// A firing sequence to a dead marking and that marking (`None`: no deadlock).
    pub deadlock_trace: Result<Option<Trace>, Stop>,
    /// Whether that sequence is a shortest one (found by the breadth-first layers, not
    /// by chaining).
    pub trace_shortest: bool,
    /// Whether the initial marking is reachable from every reachable marking.
    pub reversible: Result<bool, Stop>,
    /// Whether every transition is live (L4).
    pub live: Result<bool, Stop>,
}

/// A firing sequence (transition numbers) and the marking it reaches.
pub type Trace = (Vec<usize>, Vec<u32>);

impl Facts {
    /// Their part's status: `complete` when all are decided, `partial` when some are,
    /// else skipped with the reason.
    pub fn status(&self) -> super::Status {
        let errors = [
            self.dead_transitions.as_ref().err(),
            self.deadlocks.as_ref().err(),
            self.deadlock_trace.as_ref().err(),
            self.reversible.as_ref().err(),
            self.live.as_ref().err(),
        ];
        match errors.iter().flatten().next() {
            None => super::Status::Complete,
            Some(_) if errors.iter().any(Option::is_none) => super::Status::Partial,
            Some(why) => super::Status::Skipped(match why {
                Stop::Cancelled => "cancelled",
                Stop::Overflow => "overflow",
                _ => "budget",
            }),
        }
    }

    /// Fills the analysis' facts from these (those that are decided); a note for each
    /// that is not.
    pub(super) fn adopt(self, a: &mut super::Analysis) {
        let mut unknown = Vec::new();
        let mut why =
            |what: &str, e: &Stop| unknown.push(format!("the symbolic engine did not decide {what} ({})", e.reason()));
        match self.dead_transitions {
            Ok(d) => a.dead_transitions = Some(d),
            Err(e) => why("dead transitions", &e),
        }
        match self.deadlocks {
            Ok(n) => {
                a.deadlocks = n.to_u64();
                if a.deadlocks.is_none() {
                    a.notes.push(format!("{n} dead markings (more than 2^64)"));
                }
            }
            Err(e) => why("deadlocks", &e),
        }
        match self.deadlock_trace {
            Ok(Some((trace, m))) => {
                a.deadlock_trace = Some(trace);
                a.deadlock_marking = Some(m);
                a.deadlock_trace_shortest = self.trace_shortest;
                if !self.trace_shortest {
                    a.notes.push(
                        "the firing sequence to a deadlock is not always a shortest one: the symbolic engine's \
                         breadth-first layers did not fit its budget, it was found by chaining"
                            .into(),
                    );
                }
            }
            Ok(None) => {}
            Err(e) => why("a trace to a deadlock", &e),
        }
        match self.live {
            Ok(l) => a.live = Some(l),
            Err(e) => why("liveness", &e),
        }
        match self.reversible {
            Ok(r) => a.reversible = Some(r),
            Err(e) => why("reversibility", &e),
        }
        a.notes.extend(unknown);
    }

    fn unknown(why: Stop) -> Facts {
        Facts {
            dead_transitions: Err(why),
            deadlocks: Err(why),
            deadlock_trace: Err(why),
            trace_shortest: false,
            reversible: Err(why),
            live: Err(why),
        }
    }
}

/// The outcome of [`explore`] and what it cost.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The result, or why it stopped.
    pub result: Result<Symbolic, Stop>,
    /// Nodes created (terminals included).
    pub nodes: usize,
    /// Bytes used at the end (the largest).
    pub bytes: usize,
    /// Time taken.
    pub time: Duration,
}

/// One transition's effect on one level: enabled when `need <= v < below`, then
/// `v - pre + post`.
#[derive(Clone, Copy, Debug)]
struct Act {
    need: u32,
    below: u32,
    pre: u32,
    post: u32,
}

impl Act {
    /// The value `v` of the level becomes by the firing (`act`: what it does
    /// there, none for a level it does not touch); `None` when it is not enabled
    /// on `v`.
    fn fire(act: Option<&Act>, v: u32) -> R<Option<u32>> {
        match act {
            None => Ok(Some(v)),
            Some(a) if v >= a.need && v < a.below => {
                let w = u64::from(v - a.pre) + u64::from(a.post);
                u32::try_from(w).map(Some).map_err(|_| Stop::Overflow)
            }
            Some(_) => Ok(None),
        }
    }
}

/// A transition on the levels: its actions by level, top and bottom level.
struct Event {
    acts: Vec<(usize, Act)>,
    top: usize,
    bottom: usize,
}

impl Event {
    fn act(&self, level: usize) -> Option<&Act> {
        self.acts
            .binary_search_by_key(&level, |(l, _)| *l)
            .ok()
            .map(|i| &self.acts[i].1)
    }
}

type R<T> = Result<T, Stop>;

/// The diagram store and its caches.
struct Dd<'a> {
    /// Number of levels (places); the terminals are at level `levels`.
    levels: usize,
    level: Vec<u32>,
    /// Node `i`'s edges: `edges[start[i]..start[i + 1]]`.
    start: Vec<u32>,
    edges: Vec<(u32, u32)>,
    /// Hash of a node → the last node with that hash; `next` chains the others.
    unique: FxMap<u64, u32>,
    next: Vec<u32>,
    union_cache: FxMap<(u32, u32), u32>,
    relprod_cache: FxMap<(u32, u32), u32>,
    sat_cache: FxMap<u32, u32>,
    /// The set operations of the facts: (operation, operand, operand or transition).
    op_cache: FxMap<(u8, u32, u32), u32>,
    /// Constrained saturation (node, constraint) and its relational product
    /// (node, constraint, transition).
    csat_cache: FxMap<(u32, u32), u32>,
    crel_cache: FxMap<(u32, u32, u32), u32>,
    events: Vec<Event>,
    /// Transitions by top level.
    at: Vec<Vec<u32>>,
    limits: Limits,
    started: Instant,
    cancel: &'a AtomicBool,
    ops: u64,
    /// Raised when the other order's run has completed (see [`explore`]).
    beaten: &'a AtomicBool,
    peak: usize,
}

const NONE: u32 = u32::MAX;

/// Operations between two checks of the budgets.
const CHECK: u64 = 4096;

impl<'a> Dd<'a> {
    fn new(
        levels: usize,
        events: Vec<Event>,
        limits: Limits,
        started: Instant,
        cancel: &'a AtomicBool,
        beaten: &'a AtomicBool,
    ) -> Dd<'a> {
        let mut at = vec![Vec::new(); levels];
        for (t, e) in events.iter().enumerate() {
            if !e.acts.is_empty() {
                at[e.top].push(t as u32);
            }
        }
        Dd {
            levels,
            level: vec![levels as u32, levels as u32],
            start: vec![0, 0, 0],
            edges: Vec::new(),
            unique: FxMap::default(),
            next: vec![NONE, NONE],
            union_cache: FxMap::default(),
            relprod_cache: FxMap::default(),
            sat_cache: FxMap::default(),
            op_cache: FxMap::default(),
            csat_cache: FxMap::default(),
            crel_cache: FxMap::default(),
            events,
            at,
            limits,
            started,
            cancel,
            ops: 0,
            beaten,
            peak: 0,
        }
    }

    fn node_edges(&self, n: u32) -> &[(u32, u32)] {
        &self.edges[self.start[n as usize] as usize..self.start[n as usize + 1] as usize]
    }

    fn level_of(&self, n: u32) -> usize {
        self.level[n as usize] as usize
    }

    /// Bytes the nodes, the unique table and the caches will use by the next check
    /// (capacities, with the tables' control bytes; a table or vector that may fill up
    /// before then counted as doubled).
    fn bytes_soon(&self) -> usize {
        fn room(len: usize, cap: usize) -> usize {
            if len + CHECK as usize >= cap {
                2 * cap.max(CHECK as usize)
            } else {
                cap
            }
        }
        room(self.level.len(), self.level.capacity()) * 12
            + room(self.edges.len(), self.edges.capacity()) * 8
            + room(self.unique.len(), self.unique.capacity()) * 13
            + room(self.union_cache.len(), self.union_cache.capacity()) * 13
            + room(self.relprod_cache.len(), self.relprod_cache.capacity()) * 13
            + room(self.sat_cache.len(), self.sat_cache.capacity()) * 9
            + room(self.op_cache.len(), self.op_cache.capacity()) * 17
            + room(self.csat_cache.len(), self.csat_cache.capacity()) * 13
            + room(self.crel_cache.len(), self.crel_cache.capacity()) * 17
    }

    /// Bytes the nodes, the unique table and the caches use now.
    fn bytes(&self) -> usize {
        self.level.capacity() * 12
            + self.edges.capacity() * 8
            + self.unique.capacity() * 13
            + self.union_cache.capacity() * 13
            + self.relprod_cache.capacity() * 13
            + self.sat_cache.capacity() * 9
            + self.op_cache.capacity() * 17
            + self.csat_cache.capacity() * 13
            + self.crel_cache.capacity() * 17
    }

    /// Every few thousand operations: the budgets and the cancellation flag.
    fn tick(&mut self) -> R<()> {
        self.ops += 1;
        if self.ops.is_multiple_of(CHECK) {
            self.peak = self.peak.max(self.bytes());
            if self.bytes_soon() > self.limits.memory {
                return Err(Stop::Memory);
            }
            if self.cancel.load(Ordering::Relaxed) {
                return Err(Stop::Cancelled);
            }
            if self.started.elapsed() > self.limits.time {
                return Err(Stop::Time);
            }
            if self.beaten.load(Ordering::Relaxed) {
                return Err(Stop::Beaten);
            }
        }
        Ok(())
    }

    /// The node of `level` with these edges (sorted by value, no empty child).
    fn mk(&mut self, level: usize, edges: &[(u32, u32)]) -> R<u32> {
        if edges.is_empty() {
            return Ok(0);
        }
        let mut h = Fx(level as u64);
        for &(v, c) in edges {
            h.write_u64((u64::from(v) << 32) | u64::from(c));
        }
        let h = h.finish();
        let mut cand = self.unique.get(&h).copied().unwrap_or(NONE);
        while cand != NONE {
            if self.level_of(cand) == level && self.node_edges(cand) == edges {
                return Ok(cand);
            }
            cand = self.next[cand as usize];
        }
        if self.level.len() >= self.limits.max_nodes {
            return Err(Stop::Nodes);
        }
        self.tick()?;
        let need = self.edges.len() + edges.len();
        if need > self.edges.capacity() {
            // Edge lists can be long: the vector's growth is checked before it happens.
            let grown = need.max(2 * self.edges.capacity());
            if self.bytes() + (grown - self.edges.capacity()) * 8 > self.limits.memory {
                return Err(Stop::Memory);
            }
            self.edges.reserve_exact(grown - self.edges.len());
        }
        let id = self.level.len() as u32;
        self.level.push(level as u32);
        self.edges.extend_from_slice(edges);
        self.start.push(self.edges.len() as u32);
        self.next.push(self.unique.get(&h).copied().unwrap_or(NONE));
        self.unique.insert(h, id);
        if self.edges.len() >= u32::MAX as usize - 1 {
            return Err(Stop::Nodes);
        }
        Ok(id)
    }

    fn union(&mut self, a: u32, b: u32) -> R<u32> {
        if a == 0 || a == b {
            return Ok(b);
        }
        if b == 0 {
            return Ok(a);
        }
        let key = (a.min(b), a.max(b));
        if let Some(&r) = self.union_cache.get(&key) {
            return Ok(r);
        }
        self.tick()?;
        let level = self.level_of(a);
        let (ea, eb) = (self.node_edges(a).to_vec(), self.node_edges(b).to_vec());
        let mut out = Vec::with_capacity(ea.len() + eb.len());
        let (mut i, mut j) = (0, 0);
        while i < ea.len() || j < eb.len() {
            if j == eb.len() || (i < ea.len() && ea[i].0 < eb[j].0) {
                out.push(ea[i]);
                i += 1;
            } else if i == ea.len() || eb[j].0 < ea[i].0 {
                out.push(eb[j]);
                j += 1;
            } else {
                out.push((ea[i].0, self.union(ea[i].1, eb[j].1)?));
                i += 1;
                j += 1;
            }
        }
        let r = self.mk(level, &out)?;
        self.union_cache.insert(key, r);
        Ok(r)
    }

    /// The markings `n` (at the level of its top node) reaches by firing `t` once,
    /// saturated below `t`'s top level.
    fn relprod(&mut self, n: u32, t: u32) -> R<u32> {
        let level = self.level_of(n);
        if n == 0 || level > self.events[t as usize].bottom {
            return Ok(n);
        }
        if let Some(&r) = self.relprod_cache.get(&(n, t)) {
            return Ok(r);
        }
        self.tick()?;
        let act = self.events[t as usize].act(level).copied();
        let mut out = Vec::new();
        for (v, c) in self.node_edges(n).to_vec() {
            let Some(v2) = Act::fire(act.as_ref(), v)? else {
                continue;
            };
            let r = self.relprod(c, t)?;
            if r != 0 {
                out.push((v2, r));
            }
        }
        let mut r = self.mk(level, &out)?;
        if level > self.events[t as usize].top {
            r = self.fire(r, level)?;
        }
        self.relprod_cache.insert((n, t), r);
        Ok(r)
    }

    /// Closes `s` (children saturated) under the transitions of its level.
    fn fire(&mut self, mut s: u32, level: usize) -> R<u32> {
        if self.at[level].is_empty() || s == 0 {
            return Ok(s);
        }
        let events = self.at[level].clone();
        loop {
            let before = s;
            for &t in &events {
                let img = self.relprod(s, t)?;
                s = self.union(s, img)?;
            }
            if s == before {
                return Ok(s);
            }
        }
    }

    /// `n` closed under every transition of its level and below.
    fn saturate(&mut self, n: u32) -> R<u32> {
        if n < 2 {
            return Ok(n);
        }
        if let Some(&r) = self.sat_cache.get(&n) {
            return Ok(r);
        }
        let level = self.level_of(n);
        let mut out = Vec::new();
        for (v, c) in self.node_edges(n).to_vec() {
            out.push((v, self.saturate(c)?));
        }
        let s = self.mk(level, &out)?;
        let r = self.fire(s, level)?;
        self.sat_cache.insert(n, r);
        self.sat_cache.insert(r, r);
        Ok(r)
    }

    /// The nodes below `root` (itself included), children before parents.
    fn postorder(&self, root: u32) -> Vec<u32> {
        let mut seen = vec![false; self.level.len()];
        let mut out = Vec::new();
        let mut stack = vec![(root, false)];
        while let Some((n, done)) = stack.pop() {
            if done {
                out.push(n);
                continue;
            }
            if seen[n as usize] {
                continue;
            }
            seen[n as usize] = true;
            stack.push((n, true));
            for &(_, c) in self.node_edges(n) {
                if !seen[c as usize] {
                    stack.push((c, false));
                }
            }
        }
        out
    }

    /// The transitions, those of the lowest levels first (the saturation's order).
    fn bottom_up(&self) -> Vec<u32> {
        let mut ts: Vec<u32> = (0..self.events.len() as u32).collect();
        ts.sort_by_key(|&t| std::cmp::Reverse(self.events[t as usize].top));
        ts
    }

    /// The child of `n` at value `v`, or `0`.
    fn child(&self, n: u32, v: u32) -> u32 {
        let e = self.node_edges(n);
        e.binary_search_by_key(&v, |&(w, _)| w).map_or(0, |i| e[i].1)
    }

    /// `a ∩ b` (`minus`: false) or `a \ b` (true), of the same level.
    fn combine(&mut self, a: u32, b: u32, minus: bool) -> R<u32> {
        if minus {
            if a == 0 || a == b {
                return Ok(0);
            }
            if b == 0 {
                return Ok(a);
            }
        } else {
            if a == 0 || b == 0 {
                return Ok(0);
            }
            if a == b {
                return Ok(a);
            }
        }
        let key = if minus { (1, a, b) } else { (0, a.min(b), a.max(b)) };
        if let Some(&r) = self.op_cache.get(&key) {
            return Ok(r);
        }
        self.tick()?;
        let level = self.level_of(a);
        let mut out = Vec::new();
        for (v, ca) in self.node_edges(a).to_vec() {
            let cb = self.child(b, v);
            let r = if minus {
                self.combine(ca, cb, true)?
            } else if cb == 0 {
                0
            } else {
                self.combine(ca, cb, false)?
            };
            if r != 0 {
                out.push((v, r));
            }
        }
        let r = self.mk(level, &out)?;
        self.op_cache.insert(key, r);
        Ok(r)
    }

    /// The markings of `n` that enable `t` (`image`: false) or the markings firing `t`
    /// once leads to from them (true, not saturated).
    fn step(&mut self, n: u32, t: u32, image: bool) -> R<u32> {
        let level = self.level_of(n);
        if n < 2 || level > self.events[t as usize].bottom {
            return Ok(n);
        }
        let key = (2 + u8::from(image), n, t);
        if let Some(&r) = self.op_cache.get(&key) {
            return Ok(r);
        }
        self.tick()?;
        let act = self.events[t as usize].act(level).copied();
        let mut out = Vec::new();
        for (v, c) in self.node_edges(n).to_vec() {
            let v2 = match act {
                None => v,
                Some(a) if v >= a.need && v < a.below => {
                    if image {
                        let w = u64::from(v - a.pre) + u64::from(a.post);
                        u32::try_from(w).map_err(|_| Stop::Overflow)?
                    } else {
                        v
                    }
                }
                Some(_) => continue,
            };
            let r = self.step(c, t, image)?;
            if r != 0 {
                out.push((v2, r));
            }
        }
        let r = self.mk(level, &out)?;
        self.op_cache.insert(key, r);
        Ok(r)
    }

    /// `n` (markings of `c`, same level) closed under the transitions of its level and
    /// below, every marking added kept within `c` (constrained saturation, Zhao and
    /// Ciardo 2009).
    fn csat(&mut self, n: u32, c: u32) -> R<u32> {
        if n < 2 {
            return Ok(n);
        }
        if let Some(&r) = self.csat_cache.get(&(n, c)) {
            return Ok(r);
        }
        let level = self.level_of(n);
        let mut out = Vec::new();
        for (v, child) in self.node_edges(n).to_vec() {
            let cc = self.child(c, v);
            let r = self.csat(child, cc)?;
            if r != 0 {
                out.push((v, r));
            }
        }
        let s = self.mk(level, &out)?;
        let r = self.cfire(s, c, level)?;
        self.csat_cache.insert((n, c), r);
        self.csat_cache.insert((r, c), r);
        Ok(r)
    }

    /// [`Dd::fire`] within `c`.
    fn cfire(&mut self, mut s: u32, c: u32, level: usize) -> R<u32> {
        if self.at[level].is_empty() || s == 0 {
            return Ok(s);
        }
        let events = self.at[level].clone();
        loop {
            let before = s;
            for &t in &events {
                let img = self.crelprod(s, c, t)?;
                s = self.union(s, img)?;
            }
            if s == before {
                return Ok(s);
            }
        }
    }

    /// [`Dd::relprod`] within `c`: the image's markings are those of `c`.
    fn crelprod(&mut self, n: u32, c: u32, t: u32) -> R<u32> {
        if n == 0 || c == 0 {
            return Ok(0);
        }
        let level = self.level_of(n);
        if level > self.events[t as usize].bottom {
            return self.combine(n, c, false);
        }
        if let Some(&r) = self.crel_cache.get(&(n, c, t)) {
            return Ok(r);
        }
        self.tick()?;
        let act = self.events[t as usize].act(level).copied();
        let mut out = Vec::new();
        for (v, ch) in self.node_edges(n).to_vec() {
            let Some(v2) = Act::fire(act.as_ref(), v)? else {
                continue;
            };
            let cc = self.child(c, v2);
            if cc == 0 {
                continue;
            }
            let r = self.crelprod(ch, cc, t)?;
            if r != 0 {
                out.push((v2, r));
            }
        }
        let mut r = self.mk(level, &out)?;
        if level > self.events[t as usize].top {
            r = self.cfire(r, c, level)?;
        }
        self.crel_cache.insert((n, c, t), r);
        Ok(r)
    }

    /// The number of markings of `n`.
    fn count(&self, n: u32) -> Count {
        let mut count: FxMap<u32, Count> = FxMap::default();
        count.insert(0, Count::default());
        count.insert(1, Count::from_u64(1));
        for m in self.postorder(n).into_iter().filter(|&m| m > 1) {
            let mut c = Count::default();
            for &(_, child) in self.node_edges(m) {
                c.add(&count[&child]);
            }
            count.insert(m, c);
        }
        count.remove(&n).unwrap_or_default()
    }

    /// One marking of `n` (not empty), places in `order`'s numbering.
    fn pick(&self, mut n: u32, order: &[usize]) -> Vec<u32> {
        let mut m = vec![0; order.len()];
        while n > 1 {
            let Some(&(v, c)) = self.node_edges(n).first() else {
                break;
            };
            m[order[self.level_of(n)]] = v;
            n = c;
        }
        m
    }

    /// Whether marking `m` is in `n` (of the root level).
    fn contains(&self, mut n: u32, m: &[u32], order: &[usize]) -> bool {
        while n > 1 {
            n = self.child(n, m[order[self.level_of(n)]]);
        }
        n == 1
    }
}

/// The FORCE order (see the module's documentation): places from the root down.
pub fn variable_order(net: &PtNet) -> Vec<usize> {
    let np = net.places.len();
    let touched: Vec<Vec<usize>> = (0..net.transitions.len())
        .map(|t| {
            let mut ps: Vec<usize> = net.pre[t]
                .iter()
                .chain(&net.post[t])
                .chain(&net.reads[t])
                .chain(&net.inhibitors[t])
                .map(|&(p, _)| p)
                .collect();
            ps.sort_unstable();
            ps.dedup();
            ps
        })
        .filter(|ps| !ps.is_empty())
        .collect();
    let span = |order: &[usize]| -> u64 {
        let mut rank = vec![0usize; np];
        for (i, &p) in order.iter().enumerate() {
            rank[p] = i;
        }
        touched
            .iter()
            .map(|ps| {
                let (lo, hi) = ps
                    .iter()
                    .fold((usize::MAX, 0), |(lo, hi), &p| (lo.min(rank[p]), hi.max(rank[p])));
                (hi - lo) as u64
            })
            .sum()
    };
    let mut order: Vec<usize> = (0..np).collect();
    let mut best = (span(&order), order.clone());
    let mut pos: Vec<f64> = (0..np).map(|p| p as f64).collect();
    for _ in 0..(20 + np.ilog2().pow(2) as usize).min(200) {
        let cog: Vec<f64> = touched
            .iter()
            .map(|ps| ps.iter().map(|&p| pos[p]).sum::<f64>() / ps.len() as f64)
            .collect();
        let mut sum = vec![(0.0f64, 0usize); np];
        for (ps, &c) in touched.iter().zip(&cog) {
            for &p in ps {
                sum[p].0 += c;
                sum[p].1 += 1;
            }
        }
        let target: Vec<f64> = (0..np)
            .map(|p| {
                if sum[p].1 == 0 {
                    pos[p]
                } else {
                    sum[p].0 / sum[p].1 as f64
                }
            })
            .collect();
        order.sort_by(|&a, &b| target[a].total_cmp(&target[b]).then(a.cmp(&b)));
        for (i, &p) in order.iter().enumerate() {
            pos[p] = i as f64;
        }
        let s = span(&order);
        if s < best.0 {
            best = (s, order.clone());
        }
    }
    best.1
}

/// The action of a transition on level `l`, added when new.
fn act_at(acts: &mut Vec<(usize, Act)>, l: usize) -> &mut Act {
    let i = match acts.iter().position(|(q, _)| *q == l) {
        Some(i) => i,
        None => {
            let free = Act {
                need: 0,
                below: u32::MAX,
                pre: 0,
                post: 0,
            };
            acts.push((l, free));
            acts.len() - 1
        }
    };
    &mut acts[i].1
}

/// The transitions on the levels of `order`.
fn events(net: &PtNet, order: &[usize]) -> Vec<Event> {
    let mut level = vec![0usize; order.len()];
    for (l, &p) in order.iter().enumerate() {
        level[p] = l;
    }
    (0..net.transitions.len())
        .map(|t| {
            let mut acts: Vec<(usize, Act)> = Vec::new();
            for &(p, w) in &net.pre[t] {
                let a = act_at(&mut acts, level[p]);
                a.pre = a.pre.saturating_add(w);
                a.need = a.need.max(a.pre);
            }
            for &(p, w) in &net.reads[t] {
                let a = act_at(&mut acts, level[p]);
                a.need = a.need.max(w);
            }
            for &(p, w) in &net.inhibitors[t] {
                let a = act_at(&mut acts, level[p]);
                a.below = a.below.min(w);
            }
            for &(p, w) in &net.post[t] {
                let a = act_at(&mut acts, level[p]);
                a.post = a.post.saturating_add(w);
            }
            acts.sort_by_key(|(l, _)| *l);
            Event {
                top: acts.first().map_or(0, |(l, _)| *l),
                bottom: acts.last().map_or(0, |(l, _)| *l),
                acts,
            }
        })
        .collect()
}

/// The transitions reversed: `t⁻¹` fires from `m'` to `m` when `t` fires from `m` to
/// `m'` (inputs and outputs swapped, the tests on `m` moved onto `m'`).
fn reversed(events: &[Event]) -> Vec<Event> {
    events
        .iter()
        .map(|e| Event {
            acts: e
                .acts
                .iter()
                .map(|&(l, a)| {
                    // m = m' - post + pre: m >= need when m' >= need - pre + post (need >= pre),
                    // m < below when m' < below - pre + post.
                    let shift = |x: u32| (u64::from(x) + u64::from(a.post)).saturating_sub(u64::from(a.pre));
                    let clamp = |x: u64| u32::try_from(x).unwrap_or(u32::MAX);
                    let below = if a.below == u32::MAX {
                        u32::MAX
                    } else {
                        clamp(shift(a.below))
                    };
                    let act = Act {
                        need: clamp(shift(a.need)),
                        below,
                        pre: a.post,
                        post: a.pre,
                    };
                    (l, act)
                })
                .collect(),
            top: e.top,
            bottom: e.bottom,
        })
        .collect()
}

/// The [`Facts`] of the reachable markings `reach` (saturated, root level), within
/// `dd`'s budgets; the trace last, with budgets of its own.
fn facts(net: &PtNet, dd: &mut Dd<'_>, reach: u32, order: &[usize]) -> Facts {
    // The saturation's caches are done with.
    dd.relprod_cache = FxMap::default();
    dd.sat_cache = FxMap::default();
    let nt = dd.events.len() as u32;
    let en: Vec<u32> = match (0..nt).map(|t| dd.step(reach, t, false)).collect::<R<_>>() {
        Ok(v) => v,
        Err(why) => return Facts::unknown(why),
    };
    let dead_transitions: Vec<usize> = (0..nt as usize).filter(|&t| en[t] == 0).collect();
    // Their union in the saturation's order, the transitions of the lowest levels first:
    // the partial unions stay local (half the nodes on `Philosophers-PT-000100`).
    let dead = dd
        .bottom_up()
        .into_iter()
        .try_fold(0, |any, t| dd.union(any, en[t as usize]))
        .and_then(|any| dd.combine(reach, any, true));
    let dead = match dead {
        Ok(d) => d,
        Err(why) => {
            return Facts {
                dead_transitions: Ok(dead_transitions),
                ..Facts::unknown(why)
            };
        }
    };
    let deadlocks = dd.count(dead);
    // Backwards: the transitions reversed, every marking kept within `reach`.
    let backward = reversed(&dd.events);
    let forward = std::mem::replace(&mut dd.events, backward);
    let reversible = (|| {
        let init = initial(net, dd, order)?;
        Ok(dd.csat(init, reach)? == reach)
    })();
    let live = if nt == 0 {
        Ok(true)
    } else if !dead_transitions.is_empty() || dead != 0 {
        Ok(false)
    } else {
        match reversible {
            Ok(true) => Ok(true),
            Err(Stop::Cancelled) => Err(Stop::Cancelled),
            _ => en
                .iter()
                .try_fold(true, |live, &e| Ok(live && dd.csat(e, reach)? == reach)),
        }
    };
    dd.events = forward;
    // The backward saturations' caches are done with.
    dd.csat_cache = FxMap::default();
    dd.crel_cache = FxMap::default();
    // The trace last, with budgets of its own ([`trace`]).
    let mut trace_shortest = false;
    let deadlock_trace = if dead == 0 {
        Ok(None)
    } else if live == Err(Stop::Cancelled) {
        Err(Stop::Cancelled)
    } else {
        trace(net, dd, dead, order).map(|(t, shortest)| {
            trace_shortest = shortest;
            Some(t)
        })
    };
    Facts {
        dead_transitions: Ok(dead_transitions),
        deadlocks: Ok(deadlocks),
        deadlock_trace,
        trace_shortest,
        reversible,
        live,
    }
}

/// A firing sequence from the initial marking to one of `dead` and the marking it
/// reaches, and whether it is a shortest one: by breadth-first layers ([`shortest`])
/// when they fit in their budget, else by chaining ([`chained`]) with a budget of its
/// own (or at once: [`Limits::shortest_trace`]). Each budget is a quarter of the time
/// left and as many nodes again as made so far (at least 2^20): breadth-first layers
/// can be much larger than the saturated diagrams.
fn trace(net: &PtNet, dd: &mut Dd<'_>, dead: u32, order: &[usize]) -> R<(Trace, bool)> {
    fn within<T>(dd: &mut Dd<'_>, run: impl FnOnce(&mut Dd<'_>) -> R<T>) -> R<T> {
        let limits = dd.limits;
        let elapsed = dd.started.elapsed();
        dd.limits.time = elapsed + limits.time.saturating_sub(elapsed) / 4;
        dd.limits.max_nodes = limits.max_nodes.min(dd.level.len() + dd.level.len().max(1 << 20));
        let r = run(dd);
        dd.limits = limits;
        r
    }
    if dd.limits.shortest_trace {
        match within(dd, |dd| shortest(net, dd, dead, order)) {
            Err(Stop::Nodes | Stop::Time | Stop::Memory) => {
                // The layers' caches are done with.
                dd.union_cache = FxMap::default();
                dd.op_cache = FxMap::default();
            }
            done => return Ok((done?, true)),
        }
    }
    Ok((within(dd, |dd| chained(net, dd, dead, order))?, false))
}

/// The initial marking's diagram.
fn initial(net: &PtNet, dd: &mut Dd<'_>, order: &[usize]) -> R<u32> {
    let mut init = 1;
    for l in (0..dd.levels).rev() {
        init = dd.mk(l, &[(net.initial[order[l]], init)])?;
    }
    Ok(init)
}

/// The marking from which firing `t` leads to `m`, when `t` is enabled there and it is
/// in `set`.
fn before(net: &PtNet, dd: &Dd<'_>, m: &[u32], t: usize, set: u32, order: &[usize]) -> Option<Vec<u32>> {
    let mut prev = m.to_vec();
    for &(p, w) in &net.post[t] {
        prev[p] = prev[p].checked_sub(w)?;
    }
    for &(p, w) in &net.pre[t] {
        prev[p] = prev[p].checked_add(w)?;
    }
    (net.enabled(&prev, t) && dd.contains(set, &prev, order)).then_some(prev)
}

/// A shortest firing sequence from the initial marking to one of `dead` and the marking
/// it reaches: breadth-first layers until one meets `dead`, then back through them.
fn shortest(net: &PtNet, dd: &mut Dd<'_>, dead: u32, order: &[usize]) -> R<Trace> {
    let init = initial(net, dd, order)?;
    let nt = dd.events.len() as u32;
    let mut layers = vec![init];
    let mut seen = init;
    let mut frontier = init;
    let mut hit = dd.combine(frontier, dead, false)?;
    while hit == 0 {
        let mut next = 0;
        for t in 0..nt {
            let img = dd.step(frontier, t, true)?;
            next = dd.union(next, img)?;
        }
        frontier = dd.combine(next, seen, true)?;
        if frontier == 0 {
            // Every dead marking is reachable: not reached here.
            return Err(Stop::Nodes);
        }
        seen = dd.union(seen, frontier)?;
        layers.push(frontier);
        hit = dd.combine(frontier, dead, false)?;
    }
    let end = dd.pick(hit, order);
    let mut m = end.clone();
    let mut seq = Vec::new();
    for &layer in layers.iter().rev().skip(1) {
        dd.tick()?;
        let step = (0..net.transitions.len()).find_map(|t| Some((t, before(net, dd, &m, t, layer, order)?)));
        let Some((t, prev)) = step else {
            return Err(Stop::Nodes);
        };
        seq.push(t);
        m = prev;
    }
    seq.reverse();
    Ok((seq, end))
}

/// A firing sequence from the initial marking to one of `dead`, not always a shortest
/// one, and the marking it reaches, by chaining: the set of markings reached grows by
/// each transition's image in turn (the transitions of the lowest levels first, as in
/// the saturation), sweep after sweep until it meets `dead`; a sweep goes as deep as a
/// breadth-first layer at least, and the sets stay close to the saturated diagrams.
/// Each step that grew the set is kept (its transition and the set before it); from
/// a dead marking of the last set, back through the steps: a marking not in the set
/// before a step was reached by that step's transition, from the one marking it
/// comes from.
fn chained(net: &PtNet, dd: &mut Dd<'_>, dead: u32, order: &[usize]) -> R<Trace> {
    let mut set = initial(net, dd, order)?;
    let sweep = dd.bottom_up();
    let mut steps: Vec<(u32, u32)> = Vec::new();
    let mut hit = dd.combine(set, dead, false)?;
    while hit == 0 {
        let swept = set;
        for &t in &sweep {
            let img = dd.step(set, t, true)?;
            let grown = dd.union(set, img)?;
            if grown != set {
                steps.push((t, set));
                set = grown;
            }
        }
        if set == swept {
            // Every dead marking is reachable: not reached here.
            return Err(Stop::Nodes);
        }
        hit = dd.combine(set, dead, false)?;
    }
    let end = dd.pick(hit, order);
    let mut m = end.clone();
    let mut seq = Vec::new();
    for &(t, prior) in steps.iter().rev() {
        dd.tick()?;
        if dd.contains(prior, &m, order) {
            continue;
        }
        let Some(prev) = before(net, dd, &m, t as usize, prior, order) else {
            return Err(Stop::Nodes);
        };
        seq.push(t as usize);
        m = prev;
    }
    seq.reverse();
    Ok((seq, end))
}

/// The reachable markings of `net` by saturation, within `limits`, stopped when
/// `cancel` is raised. No order suits every net (FORCE's is 10× faster than the file's
/// on `GlobalResAllocation-PT-03`, 30× slower on `BART-PT-002`): when they differ, the
/// two run at once on two threads, each with half the memory budget, and the first to
/// complete stops the other. Each thread has a large stack (the recursion goes a few
/// frames deep per place).
pub fn explore(net: &PtNet, limits: &Limits, cancel: &AtomicBool) -> Outcome {
    let started = Instant::now();
    let force = variable_order(net);
    let file: Vec<usize> = (0..net.places.len()).collect();
    let orders = if force == file { vec![file] } else { vec![force, file] };
    let share = Limits {
        memory: limits.memory / orders.len(),
        ..*limits
    };
    let done = AtomicBool::new(false);
    let run = |order: &Vec<usize>| {
        let mut dd = Dd::new(net.places.len(), events(net, order), share, started, cancel, &done);
        let result = build(net, &mut dd, order.clone()).map(|(mut s, root)| {
            let won = done
                .compare_exchange(false, true, Ordering::AcqRel, Ordering::Relaxed)
                .is_ok();
            if won && limits.facts {
                // The other order's run stops at its next check: the whole memory
                // budget is this one's.
                dd.beaten = &NOT_BEATEN;
                dd.limits.memory = limits.memory;
                s.facts = Some(facts(net, &mut dd, root, &s.order));
            }
            s
        });
        Outcome {
            result,
            nodes: dd.level.len(),
            bytes: dd.peak.max(dd.bytes()),
            time: started.elapsed(),
        }
    };
    let outcomes: Vec<Outcome> = std::thread::scope(|s| {
        let handles: Vec<_> = orders
            .iter()
            .map(|order| {
                std::thread::Builder::new()
                    .name("alba-symbolic".into())
                    .stack_size(256 << 20)
                    .spawn_scoped(s, move || run(order))
                    .ok()
            })
            .collect();
        handles.into_iter().flatten().filter_map(|h| h.join().ok()).collect()
    });
    // The completed one; else the first stop that is not "beaten".
    let bytes = outcomes.iter().map(|o| o.bytes).sum();
    let mut best = outcomes
        .into_iter()
        .min_by_key(|o| match &o.result {
            Ok(s) if s.facts.is_some() => 0,
            Ok(_) => 1,
            Err(Stop::Beaten) => 3,
            Err(_) => 2,
        })
        .unwrap_or(Outcome {
            result: Err(Stop::Memory),
            nodes: 0,
            bytes: 0,
            time: started.elapsed(),
        });
    best.bytes = bytes;
    best.time = started.elapsed();
    best
}

/// Never raised: the winning run's flag once it has completed.
static NOT_BEATEN: AtomicBool = AtomicBool::new(false);

/// Saturates the initial marking and reads the results off the diagram (and the root
/// of the reachable markings).
fn build(net: &PtNet, dd: &mut Dd<'_>, order: Vec<usize>) -> R<(Symbolic, u32)> {
    let init = initial(net, dd, &order)?;
    let root = dd.saturate(init)?;
    let nodes = dd.postorder(root);
    let mut count: FxMap<u32, Count> = FxMap::default();
    let mut most: FxMap<u32, u64> = FxMap::default();
    count.insert(1, Count::from_u64(1));
    most.insert(1, 0);
    let mut bounds = vec![0u32; dd.levels];
    for &n in nodes.iter().filter(|&&n| n > 1) {
        let mut c = Count::default();
        let mut m = 0u64;
        for &(v, child) in dd.node_edges(n) {
            c.add(&count[&child]);
            m = m.max(u64::from(v) + most[&child]);
        }
        let l = dd.level_of(n);
        if let Some(&(v, _)) = dd.node_edges(n).last() {
            bounds[order[l]] = bounds[order[l]].max(v);
        }
        count.insert(n, c);
        most.insert(n, m);
    }
    // Firings: for each transition, the markings that enable it.
    let mut firings = Count::default();
    for t in 0..dd.events.len() {
        if dd.events[t].acts.is_empty() {
            firings.add(&count[&root]);
            continue;
        }
        let mut enabled: FxMap<u32, Count> = FxMap::default();
        for &n in &nodes {
            dd.tick()?;
            let l = dd.level_of(n);
            if n < 2 || l > dd.events[t].bottom {
                continue;
            }
            let act = dd.events[t].act(l).copied();
            let mut c = Count::default();
            for &(v, child) in dd.node_edges(n) {
                if act.is_some_and(|a| v < a.need || v >= a.below) {
                    continue;
                }
                let below = if dd.level_of(child) > dd.events[t].bottom {
                    &count[&child]
                } else {
                    &enabled[&child]
                };
                c.add(below);
            }
            enabled.insert(n, c);
        }
        firings.add(&enabled[&root]);
    }
    let s = Symbolic {
        states: count[&root].clone(),
        firings,
        place_bounds: bounds,
        max_tokens: most[&root],
        final_nodes: nodes.len(),
        order,
        facts: None,
    };
    Ok((s, root))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::reachability::{self, Explored};
    use crate::analysis::{Control, samples};

    fn never() -> AtomicBool {
        AtomicBool::new(false)
    }

    /// The explicit engine's states, firings, bounds and most tokens.
    fn explicit(net: &PtNet) -> (u64, u64, Vec<u32>, u64) {
        let limits = reachability::Limits {
            max_states: 1 << 24,
            memory: 1 << 30,
        };
        match reachability::explore(net, &limits, &Control::none()) {
            Explored::Graph(g) => (g.store.len() as u64, g.edges, g.max.clone(), g.max_tokens),
            _ => panic!("explicit exploration incomplete"),
        }
    }

    fn symbolic(net: &PtNet) -> (u64, u64, Vec<u32>, u64) {
        let s = explore(net, &Limits::default(), &never()).result.expect("complete");
        (
            s.states.to_u64().expect("u64"),
            s.firings.to_u64().expect("u64"),
            s.place_bounds,
            s.max_tokens,
        )
    }

    #[test]
    fn counts_add_with_carries_and_print_in_decimal() {
        let mut c = Count::from_u64(u64::MAX);
        c.add(&Count::from_u64(1));
        assert_eq!(c.to_string(), "18446744073709551616");
        assert_eq!(c.to_u64(), None);
        let mut big = Count::default();
        for _ in 0..1000 {
            big.add(&c);
        }
        assert_eq!(big.to_string(), "18446744073709551616000");
        let mut sq = Count::default();
        for _ in 0..3 {
            sq.add(&big);
        }
        assert_eq!(sq.to_string(), "55340232221128654848000");
        assert_eq!(Count::default().to_string(), "0");
        assert_eq!(
            Count::from_u64(10_000_000_000_000_000_000).to_string(),
            "10000000000000000000"
        );
    }

    #[test]
    fn small_nets_agree_with_the_explicit_engine() {
        for net in [
            samples::cycles(4, 3),
            samples::philosophers(5),
            samples::kanban(3),
            samples::parallel_ring(4, 3),
        ] {
            assert_eq!(symbolic(&net), explicit(&net));
        }
    }

    #[test]
    fn read_and_inhibitor_arcs_and_weights_are_tests_on_their_level() {
        // a:3 → b by twos; c is read to move b → d; e inhibits (below 2) the move d → e.
        let mut net = PtNet::new();
        let a = net.add_place("a", 5);
        let b = net.add_place("b", 0);
        let c = net.add_place("c", 1);
        let d = net.add_place("d", 0);
        let e = net.add_place("e", 0);
        let t = net.add_transition("ab");
        net.add_pre(t, a, 2);
        net.add_post(t, b, 3);
        let u = net.add_transition("bd");
        net.add_pre(u, b, 1);
        net.add_post(u, d, 1);
        net.add_read(u, c, 1);
        let v = net.add_transition("de");
        net.add_pre(v, d, 1);
        net.add_post(v, e, 1);
        net.add_inhibitor(v, e, 2);
        let w = net.add_transition("toggle");
        net.add_pre(w, c, 1);
        let back = net.add_transition("back");
        net.add_post(back, c, 1);
        net.add_inhibitor(back, c, 1);
        assert_eq!(symbolic(&net), explicit(&net));
    }

    #[test]
    fn large_counts_are_exact() {
        // 64 independent two-state toggles: 2^64 markings, 64·2^64 firings.
        let mut net = PtNet::new();
        for i in 0..64 {
            let p = net.add_place(&format!("off{i}"), 1);
            let q = net.add_place(&format!("on{i}"), 0);
            let t = net.add_transition(&format!("up{i}"));
            net.add_pre(t, p, 1);
            net.add_post(t, q, 1);
            let t = net.add_transition(&format!("down{i}"));
            net.add_pre(t, q, 1);
            net.add_post(t, p, 1);
        }
        let s = explore(&net, &Limits::default(), &never()).result.expect("complete");
        assert_eq!(s.states.to_string(), "18446744073709551616");
        assert_eq!(s.firings.to_string(), "1180591620717411303424");
        assert_eq!(s.max_tokens, 64);
        assert!(s.final_nodes < 200, "{}", s.final_nodes);
    }

    #[test]
    fn budgets_stop_cleanly_with_their_reason() {
        let net = samples::kanban(6);
        let tiny = Limits {
            max_nodes: 50,
            ..Limits::default()
        };
        let o = explore(&net, &tiny, &never());
        assert_eq!(o.result.err(), Some(Stop::Nodes));
        assert!(o.nodes <= 50);
        let cancelled = AtomicBool::new(true);
        let o = explore(&samples::cycles(60, 6), &Limits::default(), &cancelled);
        assert_eq!(o.result.err(), Some(Stop::Cancelled));
        // An unbounded net never saturates: the memory budget stops it.
        let mut grow = PtNet::new();
        let p = grow.add_place("p", 0);
        let t = grow.add_transition("t");
        grow.add_post(t, p, 1);
        let small = Limits {
            memory: 4 << 20,
            ..Limits::default()
        };
        let o = explore(&grow, &small, &never());
        assert!(matches!(o.result, Err(Stop::Memory)), "{:?}", o.result);
        assert!(o.bytes <= 8 << 20, "{}", o.bytes);
    }

    #[test]
    fn facts_over_budget_stay_unknown_with_their_reason() {
        // One order (the file's is FORCE's): the same nodes on every run.
        let net = samples::cycles(4, 3);
        assert_eq!(variable_order(&net), (0..net.places.len()).collect::<Vec<_>>());
        let counted = explore(&net, &Limits::default(), &never());
        assert!(counted.result.as_ref().is_ok_and(|s| s.facts.is_none()));
        let tight = Limits {
            max_nodes: counted.nodes + 3,
            facts: true,
            ..Limits::default()
        };
        let s = explore(&net, &tight, &never())
            .result
            .expect("counted within the budget");
        let f = s.facts.expect("asked");
        assert_eq!(f.live, Err(Stop::Nodes));
        assert_eq!(f.status(), super::super::Status::Skipped("budget"));
        let s = explore(
            &net,
            &Limits {
                facts: true,
                ..Limits::default()
            },
            &never(),
        )
        .result
        .expect("counted");
        let f = s.facts.expect("asked");
        assert_eq!(f.status(), super::super::Status::Complete);
        assert_eq!((f.live, f.reversible, f.deadlock_trace), (Ok(true), Ok(true), Ok(None)));
    }

    #[test]
    fn a_trace_by_chaining_replays_to_the_deadlock_and_says_it_may_not_be_shortest() {
        // Philosophers who all took their left fork: the one deadlock, n firings away.
        let net = samples::philosophers(12);
        let a = crate::analysis::analyze(&net, &crate::analysis::Options::default(), &Control::none());
        let shortest = a.deadlock_trace.as_ref().map(Vec::len).expect("a deadlock");
        for shortest_trace in [true, false] {
            let limits = Limits {
                facts: true,
                shortest_trace,
                ..Limits::default()
            };
            let s = explore(&net, &limits, &never()).result.expect("counted");
            let f = s.facts.expect("asked");
            let Ok(Some((trace, end))) = f.deadlock_trace.clone() else {
                panic!("no trace: {:?}", f.deadlock_trace);
            };
            let mut m = net.initial.clone();
            for &t in &trace {
                m = net.fire(&m, t).expect("enabled");
            }
            assert_eq!(m, end);
            assert!((0..net.transitions.len()).all(|t| !net.enabled(&m, t)));
            assert_eq!(f.trace_shortest, shortest_trace);
            if shortest_trace {
                assert_eq!(trace.len(), shortest);
            } else {
                assert!(trace.len() >= shortest);
            }
            // The analysis says when it may not be a shortest one.
            let mut b = a.clone();
            f.adopt(&mut b);
            assert_eq!(b.deadlock_trace_shortest, shortest_trace);
            let noted = b.notes.iter().find(|n| n.contains("not always a shortest one"));
            assert_eq!(noted.is_some(), !shortest_trace, "{:?}", b.notes);
            // The studio shows it in Spanish too.
            assert!(noted.is_none_or(|n| alba_diag::es::phrase(n).is_some()), "{noted:?}");
        }
    }

    #[test]
    fn the_order_keeps_linked_places_together() {
        // A ring of 30 places listed in a scrambled order: FORCE brings each
        // transition's two places near each other.
        let mut net = PtNet::new();
        let n = 30;
        let ids: Vec<usize> = (0..n).map(|i| (i * 7) % n).collect();
        let mut place = vec![0; n];
        for &i in &ids {
            place[i] = net.add_place(&format!("p{i}"), u32::from(i == 0));
        }
        for i in 0..n {
            let t = net.add_transition(&format!("t{i}"));
            net.add_pre(t, place[i], 1);
            net.add_post(t, place[(i + 1) % n], 1);
        }
        let span = |order: &[usize]| -> usize {
            let mut rank = vec![0; n];
            for (r, &p) in order.iter().enumerate() {
                rank[p] = r;
            }
            (0..n).map(|i| rank[place[i]].abs_diff(rank[place[(i + 1) % n]])).sum()
        };
        let file: Vec<usize> = (0..n).collect();
        let order = variable_order(&net);
        assert!(span(&order) < span(&file) / 2, "{} vs {}", span(&order), span(&file));
        assert_eq!(symbolic(&net).0, n as u64);
    }
}
