//! Checking the contest's examinations ([`super::formula`]) on the fly: a breadth-first
//! exploration that evaluates every undecided property at each new marking and stops
//! as soon as all are decided, with a shortest witness or counterexample (BFS parents).
//!
//! With [`CheckOptions::stubborn`], reachability questions (EF φ, AG φ, deadlock) explore
//! a reduced graph: at each marking only a stubborn set of transitions is fired, the
//! closure of the "changers" of every undecided property (transitions of which any
//! firing sequence changing the property's value fires one, [`Pred::changers`]) under
//! two rules: an enabled transition in the set brings in every transition its firing
//! could disable (inputs or read arcs on a place it empties, inhibitor arcs on a place it
//! fills); a disabled one brings in the transitions that can remove one reason it is
//! disabled (the producers of a place short of tokens, the consumers of an inhibitor
//! place too full). Then a firing sequence from the marking to a marking satisfying φ
//! can be reordered to start with a transition of the set, one step shorter (Schmidt,
//! "Stubborn sets for standard properties", 1999): every marking the question asks for
//! stays reachable, and no "ignoring" proviso is needed because the set holds the
//! changers. Bounds need every marking: with an `UpperBounds` property the whole graph
//! is explored.
//!
//! Before exploring, [`answer`] slices the net and applies the structural reductions of
//! [`reduce`] (with [`CheckOptions::reduce`]).

mod lp;
pub mod reduce;

use super::formula::{Index, Property, Query};
use super::{Control, Part, Progress};
use crate::PtNet;

/// What [`check`] may do.
#[derive(Clone, Copy, Debug)]
pub struct CheckOptions {
    /// Largest number of markings stored.
    pub max_states: usize,
    /// Stubborn-set reduction for reachability questions.
    pub stubborn: bool,
    /// Slicing ([`super::formula::slice`], [`answer`]): the properties together on the
    /// union of their slices when it has at most three quarters of the places, else each
    /// alone on its slice when that has at most a quarter.
    pub slice: bool,
    /// Structural reductions ([`reduce`]) before each exploration of [`answer`].
    pub reduce: bool,
}

impl Default for CheckOptions {
    fn default() -> CheckOptions {
        CheckOptions {
            max_states: 10_000_000,
            stubborn: true,
            slice: true,
            reduce: true,
        }
    }
}

/// A property's answer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The formula holds.
    True,
    /// It does not.
    False,
    /// The bound of an `UpperBounds` property.
    Bound(u64),
    /// Not decided (limit, cancellation, unbounded net, overflow): why.
    Unknown(&'static str),
}

/// The answer to one property.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Answer {
    /// The property's id.
    pub id: String,
    /// The verdict.
    pub verdict: Verdict,
    /// The contest's technique names of how it was found.
    pub techniques: Vec<&'static str>,
    /// A shortest firing sequence (transition numbers) from the initial marking to a
    /// witness (EF φ true) or a counterexample (AG φ false).
    pub trace: Option<Vec<usize>>,
}

impl std::fmt::Display for Answer {
    /// The contest's output line: `FORMULA <id> TRUE|FALSE|<n> TECHNIQUES …`; an undecided
    /// property `FORMULA <id> CANNOT_COMPUTE`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = match &self.verdict {
            Verdict::True => "TRUE".to_string(),
            Verdict::False => "FALSE".to_string(),
            Verdict::Bound(n) => n.to_string(),
            Verdict::Unknown(_) => return write!(f, "FORMULA {} CANNOT_COMPUTE", self.id),
        };
        write!(f, "FORMULA {} {v} TECHNIQUES {}", self.id, self.techniques.join(" "))
    }
}

impl Answer {
    /// The trace with the transitions' ids.
    pub fn trace_ids<'n>(&self, net: &'n PtNet) -> Option<Vec<&'n str>> {
        self.trace
            .as_ref()
            .map(|t| t.iter().map(|&i| net.transitions[i].as_str()).collect())
    }
}

/// The answers as one JSON object, `{"examination": E, "formulas": [{"id", "verdict"
/// (true, false or null), "bound" (the number of an `UpperBounds` property, else null),
/// "techniques", "trace" (the transitions' ids, or null), "line" (the contest's line)}]}`:
/// `alba analyze --examination E --json` and the server's analysis (docs/nets.md).
pub fn answers_json(net: &PtNet, examination: &str, answers: &[Answer]) -> serde_json::Value {
    let list: Vec<serde_json::Value> = answers
        .iter()
        .map(|a| {
            let (verdict, bound) = match &a.verdict {
                Verdict::True => (serde_json::json!(true), serde_json::Value::Null),
                Verdict::False => (serde_json::json!(false), serde_json::Value::Null),
                Verdict::Bound(n) => (serde_json::Value::Null, serde_json::json!(n)),
                Verdict::Unknown(_) => (serde_json::Value::Null, serde_json::Value::Null),
            };
            serde_json::json!({
                "id": a.id,
                "verdict": verdict,
                "bound": bound,
                "techniques": a.techniques,
                "trace": a.trace_ids(net),
                "line": a.to_string(),
            })
        })
        .collect();
    serde_json::json!({ "examination": examination, "formulas": list })
}

/// The outcome of [`check`].
#[derive(Clone, Debug)]
pub struct Checked {
    /// One answer per property, in order.
    pub answers: Vec<Answer>,
    /// Markings stored.
    pub states: usize,
    /// Firings explored.
    pub edges: u64,
    /// Whether the stubborn-set reduction was on.
    pub reduced: bool,
}

/// The markings found, one after the other, and an open-addressing index of them
/// (state numbers, linear probing, load at most one half).
struct Seen {
    np: usize,
    markings: Vec<u32>,
    parent: Vec<(u32, u32)>,
    table: Vec<u32>,
}

const EMPTY: u32 = u32::MAX;

fn hash(m: &[u32]) -> u64 {
    let mut h: u64 = 0x243f_6a88_85a3_08d3;
    for &w in m {
        h = (h.rotate_left(5) ^ u64::from(w)).wrapping_mul(0x517c_c1b7_2722_0a95);
    }
    h ^= h >> 29;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^ (h >> 32)
}

impl Seen {
    fn new(initial: &[u32]) -> Seen {
        let mut s = Seen {
            np: initial.len(),
            markings: Vec::new(),
            parent: Vec::new(),
            table: vec![EMPTY; 1 << 10],
        };
        s.insert(initial, (u32::MAX, u32::MAX));
        s
    }

    fn len(&self) -> usize {
        self.parent.len()
    }

    fn marking(&self, i: usize) -> &[u32] {
        &self.markings[i * self.np..(i + 1) * self.np]
    }

    /// Adds `m` unless it is there; whether it was new.
    fn insert(&mut self, m: &[u32], parent: (u32, u32)) -> bool {
        let mask = self.table.len() - 1;
        let mut slot = hash(m) as usize & mask;
        loop {
            match self.table[slot] {
                EMPTY => break,
                i if self.marking(i as usize) == m => return false,
                _ => slot = (slot + 1) & mask,
            }
        }
        self.table[slot] = self.len() as u32;
        self.markings.extend_from_slice(m);
        self.parent.push(parent);
        if self.len() * 2 > self.table.len() {
            let mut table = vec![EMPTY; self.table.len() * 2];
            let mask = table.len() - 1;
            for i in 0..self.len() {
                let mut slot = hash(self.marking(i)) as usize & mask;
                while table[slot] != EMPTY {
                    slot = (slot + 1) & mask;
                }
                table[slot] = i as u32;
            }
            self.table = table;
        }
        true
    }

    fn bytes(&self) -> usize {
        self.markings.capacity() * 4 + self.parent.capacity() * 8 + self.table.len() * 4
    }

    fn trace(&self, mut i: usize) -> Vec<usize> {
        let mut out = Vec::new();
        while i != 0 {
            let (p, t) = self.parent[i];
            out.push(t as usize);
            i = p as usize;
        }
        out.reverse();
        out
    }
}

/// What [`answer_explored`] explored and removed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Explored {
    /// Markings stored, over all the explorations.
    pub states: usize,
    /// Places the structural reductions removed (over all the explorations).
    pub places_removed: usize,
    /// Transitions they removed.
    pub transitions_removed: usize,
    /// The rules they applied.
    pub applied: reduce::Applied,
}

/// Answers the properties: with [`CheckOptions::slice`], on slices where they are small
/// enough (technique `STRUCTURAL_REDUCTION`, the trace numbered in the whole net; see
/// below), the others together by one exploration of the net ([`check`]); with
/// [`CheckOptions::reduce`], each exploration on the net reduced by [`reduce::reduce`]
/// (technique `STRUCTURAL_REDUCTION` when a rule applied, the trace expanded into the
/// original transitions).
pub fn answer(net: &PtNet, props: &[Property], options: &CheckOptions, control: &Control<'_>) -> Vec<Answer> {
    answer_explored(net, props, options, control).0
}

/// [`answer`], and what it explored and removed.
pub fn answer_explored(
    net: &PtNet,
    props: &[Property],
    options: &CheckOptions,
    control: &Control<'_>,
) -> (Vec<Answer>, Explored) {
    let mut explored = Explored::default();
    let mut answers: Vec<Option<Answer>> = vec![None; props.len()];
    // What each property reads (`None`: the whole net).
    let supports: Vec<Option<(Vec<usize>, Vec<usize>)>> = props
        .iter()
        .map(|p| {
            let (mut support, mut asked) = (Vec::new(), Vec::new());
            match &p.query {
                Query::Ef(f) | Query::Ag(f) => f.support(&mut support, &mut asked)?,
                Query::Bound(ps) => support.extend(ps),
            }
            Some((support, asked))
        })
        .collect();
    let np = net.places.len();
    let small = |s: &super::formula::Slice, num: usize, den: usize| s.net.places.len() * den <= np * num;
    let mut rest: Vec<usize> = (0..props.len()).collect();
    if options.slice {
        // All the sliceable properties together on the union of their slices when it
        // leaves out a quarter of the places; else each alone when its slice has at most
        // a quarter of them (one exploration per property costs more than a shared one).
        let sliceable: Vec<usize> = rest.iter().copied().filter(|&k| supports[k].is_some()).collect();
        let (mut places, mut asked) = (Vec::new(), Vec::new());
        for (p, t) in sliceable.iter().filter_map(|&k| supports[k].as_ref()) {
            places.extend(p);
            asked.extend(t);
        }
        let mut groups: Vec<(super::formula::Slice, Vec<usize>)> = Vec::new();
        match super::formula::slice(net, &places, &asked).filter(|s| small(s, 3, 4)) {
            Some(s) if !sliceable.is_empty() => groups.push((s, sliceable)),
            _ => {
                for &k in &sliceable {
                    if let Some((p, t)) = &supports[k]
                        && let Some(s) = super::formula::slice(net, p, t).filter(|s| small(s, 1, 4))
                    {
                        groups.push((s, vec![k]));
                    }
                }
            }
        }
        for (s, group) in groups {
            let mapped: Vec<Property> = group
                .iter()
                .map(|&k| Property {
                    id: props[k].id.clone(),
                    query: match &props[k].query {
                        Query::Ef(f) => Query::Ef(f.map(&s.place, &s.transition)),
                        Query::Ag(f) => Query::Ag(f.map(&s.place, &s.transition)),
                        Query::Bound(ps) => Query::Bound(ps.iter().map(|&q| s.place[q]).collect()),
                    },
                })
                .collect();
            for (&k, mut a) in group
                .iter()
                .zip(reduced(&s.net, &mapped, options, control, &mut explored))
            {
                if !a.techniques.contains(&"STRUCTURAL_REDUCTION") {
                    a.techniques.push("STRUCTURAL_REDUCTION");
                }
                a.trace = a.trace.map(|t| t.into_iter().map(|u| s.back[u]).collect());
                answers[k] = Some(a);
            }
            rest.retain(|k| !group.contains(k));
        }
    }
    if !rest.is_empty() {
        let group: Vec<Property> = rest.iter().map(|&k| props[k].clone()).collect();
        for (k, a) in rest
            .into_iter()
            .zip(reduced(net, &group, options, control, &mut explored))
        {
            answers[k] = Some(a);
        }
    }
    (answers.into_iter().flatten().collect(), explored)
}

/// [`check`] on the net reduced for the properties ([`CheckOptions::reduce`]), the
/// answers and traces translated back.
fn reduced(
    net: &PtNet,
    props: &[Property],
    options: &CheckOptions,
    control: &Control<'_>,
    explored: &mut Explored,
) -> Vec<Answer> {
    let Some(r) = options.reduce.then(|| reduce::reduce(net, props)).flatten() else {
        let c = check(net, props, options, control);
        explored.states += c.states;
        return c.answers;
    };
    let c = check(&r.net, &r.properties(props), options, control);
    explored.states += c.states;
    explored.places_removed += r.places_removed();
    explored.transitions_removed += r.transitions_removed();
    explored.applied += r.applied;
    c.answers
        .into_iter()
        .map(|mut a| {
            a.techniques.push("STRUCTURAL_REDUCTION");
            a.trace = a.trace.map(|t| r.trace(&t));
            a
        })
        .collect()
}

/// Answers the properties by one exploration (see the module's text).
pub fn check(net: &PtNet, props: &[Property], options: &CheckOptions, control: &Control<'_>) -> Checked {
    let np = net.places.len();
    let nt = net.transitions.len();
    let has_bounds = props.iter().any(|p| matches!(p.query, Query::Bound(_)));
    let reduced = options.stubborn && !has_bounds;
    let technique: Vec<&'static str> = if reduced {
        vec!["EXPLICIT", "PARTIAL_ORDER"]
    } else {
        vec!["EXPLICIT"]
    };
    let mut verdicts: Vec<Option<Verdict>> = vec![None; props.len()];
    let mut traces: Vec<Option<Vec<usize>>> = vec![None; props.len()];
    let mut bounds = vec![0u64; props.len()];
    let ix = Index::new(net);
    let mut seen = Seen::new(&net.initial);
    let mut edges = 0u64;
    let mut stop: Option<&'static str> = None;
    let mut open = props.len();
    let mut m = vec![0u32; np];
    let mut set: Vec<usize> = Vec::new();
    let mut work: Vec<usize> = Vec::new();
    let mut in_set = vec![false; nt];
    let mut s = 0usize;
    while s < seen.len() && (open > 0 || has_bounds) {
        if s & 0x3fff == 0 {
            // Progress first: a caller over its budget cancels from the callback, and the
            // exploration stops now rather than 16 384 markings later (a reduced net may
            // be done by then).
            (control.progress)(&Progress {
                part: Part::StateSpace,
                states: seen.len() as u64,
                bytes: seen.bytes(),
            });
            if control.cancelled() {
                stop = Some("cancelled");
                break;
            }
        }
        m.copy_from_slice(seen.marking(s));
        // The properties at this marking.
        for (k, p) in props.iter().enumerate() {
            match &p.query {
                Query::Bound(ps) => {
                    bounds[k] = bounds[k].max(ps.iter().map(|&q| u64::from(m[q])).sum());
                }
                Query::Ef(f) | Query::Ag(f) if verdicts[k].is_none() => {
                    let ef = matches!(p.query, Query::Ef(_));
                    if f.eval(net, &m) == ef {
                        verdicts[k] = Some(if ef { Verdict::True } else { Verdict::False });
                        traces[k] = Some(seen.trace(s));
                        open -= 1;
                    }
                }
                _ => {}
            }
        }
        if open == 0 && !has_bounds {
            break;
        }
        // The transitions to fire.
        set.clear();
        if reduced {
            work.clear();
            for (k, p) in props.iter().enumerate() {
                match &p.query {
                    Query::Ef(f) if verdicts[k].is_none() => f.changers(net, &ix, &m, true, &mut work),
                    Query::Ag(f) if verdicts[k].is_none() => f.changers(net, &ix, &m, false, &mut work),
                    _ => {}
                }
            }
            while let Some(t) = work.pop() {
                if in_set[t] {
                    continue;
                }
                in_set[t] = true;
                set.push(t);
                if net.enabled(&m, t) {
                    work.extend(ix.disables[t].iter().filter(|&&u| !in_set[u]));
                } else {
                    ix.scapegoat(net, &m, t, &mut work);
                }
            }
            for &t in &set {
                in_set[t] = false;
            }
            set.retain(|&t| net.enabled(&m, t));
            set.sort_unstable();
        } else {
            set.extend((0..nt).filter(|&t| net.enabled(&m, t)));
        }
        for &t in &set {
            let Some(next) = net.fire(&m, t) else {
                stop = Some("a place holds more than 2^32 - 1 tokens");
                break;
            };
            edges += 1;
            if seen.insert(&next, (s as u32, t as u32)) && seen.len() > options.max_states.min(1 << 31) {
                stop = Some("state limit");
                break;
            }
        }
        if stop.is_some() {
            break;
        }
        s += 1;
    }
    let complete = stop.is_none();
    let answers = props
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let verdict = match (&p.query, verdicts[k].take()) {
                (_, Some(v)) => v,
                (Query::Bound(_), None) if complete => Verdict::Bound(bounds[k]),
                (Query::Ef(_), None) if complete => Verdict::False,
                (Query::Ag(_), None) if complete => Verdict::True,
                _ => Verdict::Unknown(stop.unwrap_or("not explored")),
            };
            Answer {
                id: p.id.clone(),
                verdict,
                techniques: technique.clone(),
                trace: traces[k].take(),
            }
        })
        .collect();
    Checked {
        answers,
        states: seen.len(),
        edges,
        reduced,
    }
}

#[cfg(test)]
mod tests {
    use super::super::formula::{IntExpr, Pred, deadlock_property};
    use super::*;

    /// `n` independent processes, each `idle -> busy -> done`, and a `stop` transition
    /// needing every `done`: (3^n states in full, a single path reduced to the deadlock).
    pub(super) fn processes(n: usize) -> PtNet {
        let mut net = PtNet::new();
        let stop = net.add_transition("stop");
        for i in 0..n {
            let idle = net.add_place(&format!("idle{i}"), 1);
            let busy = net.add_place(&format!("busy{i}"), 0);
            let done = net.add_place(&format!("done{i}"), 0);
            let a = net.add_transition(&format!("start{i}"));
            net.add_pre(a, idle, 1);
            net.add_post(a, busy, 1);
            let b = net.add_transition(&format!("end{i}"));
            net.add_pre(b, busy, 1);
            net.add_post(b, done, 1);
            net.add_pre(stop, done, 1);
        }
        net
    }

    fn both(net: &PtNet, props: &[Property]) -> (Checked, Checked) {
        let full = check(
            net,
            props,
            &CheckOptions {
                stubborn: false,
                ..CheckOptions::default()
            },
            &Control::none(),
        );
        let reduced = check(net, props, &CheckOptions::default(), &Control::none());
        (full, reduced)
    }

    #[test]
    fn stubborn_sets_keep_the_deadlock_and_explore_fewer_markings() {
        let net = processes(6);
        let (full, reduced) = both(&net, &[deadlock_property()]);
        assert_eq!(full.answers[0].verdict, Verdict::True);
        assert_eq!(reduced.answers[0].verdict, Verdict::True);
        // The trace leads to a dead marking.
        let trace = reduced.answers[0].trace.clone().expect("a witness");
        let mut m = net.initial.clone();
        for t in trace {
            assert!(net.enabled(&m, t));
            m = net.fire(&m, t).expect("fires");
        }
        assert!(Pred::Deadlock.eval(&net, &m));
        assert!(
            reduced.states * 10 < full.states,
            "{} vs {}",
            reduced.states,
            full.states
        );
    }

    #[test]
    fn reachability_answers_agree_with_and_without_reduction() {
        let net = processes(4);
        let busy = |i: usize| net.place(&format!("busy{i}")).expect("place");
        let done = |i: usize| net.place(&format!("done{i}")).expect("place");
        let le = |a: Vec<usize>, c: u64| Pred::Le(IntExpr::Tokens(a), IntExpr::Const(c));
        let props = vec![
            // Two busy at once: reachable.
            Property {
                id: "a".into(),
                query: Query::Ef(Pred::Not(Box::new(le(vec![busy(0), busy(1)], 1)))),
            },
            // Never three done with process 3 still idle? False: reachable.
            Property {
                id: "b".into(),
                query: Query::Ag(le(vec![done(0), done(1), done(2)], 2)),
            },
            // Process 0 never holds two tokens: true.
            Property {
                id: "c".into(),
                query: Query::Ag(Pred::And(vec![le(vec![0, busy(0), done(0)], 1), Pred::True])),
            },
            Property {
                id: "d".into(),
                query: Query::Ef(Pred::Fireable(vec![0])),
            },
        ];
        let (full, reduced) = both(&net, &props);
        let v = |c: &Checked| c.answers.iter().map(|a| a.verdict.clone()).collect::<Vec<_>>();
        assert_eq!(
            v(&full),
            vec![Verdict::True, Verdict::False, Verdict::True, Verdict::True]
        );
        assert_eq!(v(&full), v(&reduced));
        assert_eq!(
            reduced.answers[0].to_string(),
            "FORMULA a TRUE TECHNIQUES EXPLICIT PARTIAL_ORDER"
        );
    }

    #[test]
    fn bounds_explore_the_whole_graph_and_limits_leave_answers_unknown() {
        let net = processes(3);
        let props = vec![
            Property {
                id: "u".into(),
                query: Query::Bound(vec![1, 4, 7]),
            },
            deadlock_property(),
        ];
        let c = check(&net, &props, &CheckOptions::default(), &Control::none());
        assert!(!c.reduced);
        assert_eq!(c.states, 28);
        assert_eq!(c.answers[0].verdict, Verdict::Bound(3));
        assert_eq!(c.answers[0].to_string(), "FORMULA u 3 TECHNIQUES EXPLICIT");
        let c = check(
            &net,
            &props,
            &CheckOptions {
                max_states: 5,
                stubborn: false,
                slice: false,
                reduce: false,
            },
            &Control::none(),
        );
        assert_eq!(c.answers[0].verdict, Verdict::Unknown("state limit"));
        assert_eq!(c.answers[0].to_string(), "FORMULA u CANNOT_COMPUTE");
    }
}
