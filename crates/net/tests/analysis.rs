//! The analysis on hand-computed nets, and property tests against a naive reference.

use alba_net::PtNet;
use alba_net::analysis::{
    Analysis, Bound, Control, Invariants, Options, Part, Space, Status, analyze, coverability, invariants, samples,
};
use proptest::prelude::*;
use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::atomic::{AtomicBool, Ordering};

fn run(net: &PtNet) -> Analysis {
    analyze(net, &Options::default(), &Control::none())
}

/// Invariants as sorted lists of (id, coefficient).
fn named(ids: &[String], invs: &[Vec<i64>]) -> Vec<Vec<(String, i64)>> {
    invs.iter()
        .map(|v| {
            v.iter()
                .enumerate()
                .filter(|(_, c)| **c != 0)
                .map(|(i, c)| (ids[i].clone(), *c))
                .collect()
        })
        .collect()
}

fn inv(pairs: &[(&str, i64)]) -> Vec<(String, i64)> {
    pairs.iter().map(|(s, c)| (s.to_string(), *c)).collect()
}

fn p_inv(a: &Analysis, net: &PtNet) -> Vec<Vec<(String, i64)>> {
    let mut v = named(&net.places, a.p_invariants.as_ref().expect("p-invariants"));
    v.sort();
    v
}

fn t_inv(a: &Analysis, net: &PtNet) -> Vec<Vec<(String, i64)>> {
    let mut v = named(&net.transitions, a.t_invariants.as_ref().expect("t-invariants"));
    v.sort();
    v
}

fn ids(net: &PtNet, ts: &[usize]) -> Vec<String> {
    ts.iter().map(|&t| net.transitions[t].clone()).collect()
}

fn finite(v: &[u32]) -> Option<Vec<Bound>> {
    Some(v.iter().map(|&b| Bound::Finite(b)).collect())
}

#[test]
fn philosophers_two_deadlock() {
    let net = samples::philosophers(2);
    let a = run(&net);
    assert_eq!(a.bounded, Some(true));
    assert_eq!(a.safe, Some(true));
    assert_eq!(a.states, Some(6));
    assert_eq!(a.edges, Some(8));
    assert_eq!(a.deadlocks, Some(1));
    assert_eq!(
        ids(&net, a.deadlock_trace.as_deref().unwrap_or(&[])),
        ["takeL0", "takeL1"]
    );
    assert_eq!(a.dead_transitions, Some(vec![]));
    assert_eq!(a.live, Some(false));
    assert_eq!(a.reversible, Some(false));
    let mut expected = vec![
        inv(&[("think0", 1), ("hasL0", 1), ("eat0", 1)]),
        inv(&[("think1", 1), ("hasL1", 1), ("eat1", 1)]),
        inv(&[("hasL0", 1), ("eat0", 1), ("fork0", 1), ("eat1", 1)]),
        inv(&[("eat0", 1), ("hasL1", 1), ("eat1", 1), ("fork1", 1)]),
    ];
    expected.sort();
    assert_eq!(p_inv(&a, &net), expected);
    assert_eq!(
        t_inv(&a, &net),
        vec![
            inv(&[("takeL0", 1), ("takeR0", 1), ("release0", 1)]),
            inv(&[("takeL1", 1), ("takeR1", 1), ("release1", 1)])
        ]
    );
}

#[test]
fn philosophers_five_has_one_deadlock_reached_in_five_steps() {
    let net = samples::philosophers(5);
    let a = run(&net);
    assert_eq!(a.deadlocks, Some(1));
    assert_eq!(a.deadlock_trace.as_ref().map(Vec::len), Some(5));
    assert_eq!(a.deadlock_marking.as_ref().map(|m| m.iter().sum::<u32>()), Some(5));
    assert_eq!(a.live, Some(false));
}

fn buffer() -> PtNet {
    let mut net = PtNet::new();
    let buf = net.add_place("buf", 0);
    let free = net.add_place("free", 2);
    let put = net.add_transition("put");
    net.add_pre(put, free, 1);
    net.add_post(put, buf, 1);
    let get = net.add_transition("get");
    net.add_pre(get, buf, 1);
    net.add_post(get, free, 1);
    net
}

#[test]
fn bounded_buffer() {
    let net = buffer();
    let a = run(&net);
    assert_eq!(a.bounded, Some(true));
    assert_eq!(a.safe, Some(false));
    assert_eq!(a.place_bounds, finite(&[2, 2]));
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(3), Some(4), Some(0)));
    assert_eq!(a.deadlock_trace, None);
    assert_eq!((a.live, a.reversible), (Some(true), Some(true)));
    assert_eq!(p_inv(&a, &net), vec![inv(&[("buf", 1), ("free", 1)])]);
    assert_eq!(t_inv(&a, &net), vec![inv(&[("put", 1), ("get", 1)])]);
}

#[test]
fn unbounded_producer() {
    let mut net = PtNet::new();
    let p = net.add_place("p", 1);
    let q = net.add_place("q", 0);
    let t = net.add_transition("produce");
    net.add_pre(t, p, 1);
    net.add_post(t, p, 1);
    net.add_post(t, q, 1);
    let a = run(&net);
    assert_eq!(a.bounded, Some(false));
    assert_eq!(a.safe, Some(false));
    assert_eq!(a.place_bounds, Some(vec![Bound::Finite(1), Bound::Omega]));
    assert_eq!(a.states, Some(2), "coverability nodes (1,0) and (1,ω)");
    assert_eq!((a.edges, a.deadlocks, a.reversible), (None, None, None));
    assert_eq!(a.dead_transitions, Some(vec![]));
    assert_eq!(a.live, None);
    assert_eq!(p_inv(&a, &net), vec![inv(&[("p", 1)])]);
    assert_eq!(t_inv(&a, &net), Vec::<Vec<(String, i64)>>::new());
}

#[test]
fn unbounded_with_a_dead_transition_is_not_live() {
    let mut net = PtNet::new();
    let p = net.add_place("p", 1);
    let q = net.add_place("q", 0);
    let z = net.add_place("z", 0);
    let t = net.add_transition("produce");
    net.add_pre(t, p, 1);
    net.add_post(t, p, 1);
    net.add_post(t, q, 1);
    let never = net.add_transition("never");
    net.add_pre(never, z, 1);
    let a = run(&net);
    assert_eq!(a.bounded, Some(false));
    assert_eq!(a.dead_transitions, Some(vec![never]));
    assert_eq!(a.live, Some(false));
}

#[test]
fn weighted_arcs_with_a_dead_transition() {
    let mut net = PtNet::new();
    let p = net.add_place("p", 3);
    let q = net.add_place("q", 0);
    let r = net.add_place("r", 0);
    let t1 = net.add_transition("t1");
    net.add_pre(t1, p, 2);
    net.add_post(t1, q, 1);
    let t2 = net.add_transition("t2");
    net.add_pre(t2, q, 3);
    net.add_post(t2, r, 1);
    let a = run(&net);
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(2), Some(1), Some(1)));
    assert_eq!(a.place_bounds, finite(&[3, 1, 0]));
    assert_eq!(a.safe, Some(false));
    assert_eq!(ids(&net, a.deadlock_trace.as_deref().unwrap_or(&[])), ["t1"]);
    assert_eq!(a.deadlock_marking, Some(vec![1, 1, 0]));
    assert_eq!(a.dead_transitions, Some(vec![t2]));
    assert_eq!((a.live, a.reversible), (Some(false), Some(false)));
    // -2·y_p + y_q = 0 and -3·y_q + y_r = 0.
    assert_eq!(p_inv(&a, &net), vec![inv(&[("p", 1), ("q", 2), ("r", 6)])]);
    assert!(t_inv(&a, &net).is_empty());
}

fn mutex() -> PtNet {
    let mut net = PtNet::new();
    let idle1 = net.add_place("idle1", 1);
    let busy1 = net.add_place("busy1", 0);
    let res = net.add_place("res", 1);
    let idle2 = net.add_place("idle2", 1);
    let busy2 = net.add_place("busy2", 0);
    for (idle, busy, n) in [(idle1, busy1, 1), (idle2, busy2, 2)] {
        let enter = net.add_transition(&format!("enter{n}"));
        net.add_pre(enter, idle, 1);
        net.add_pre(enter, res, 1);
        net.add_post(enter, busy, 1);
        let leave = net.add_transition(&format!("leave{n}"));
        net.add_pre(leave, busy, 1);
        net.add_post(leave, idle, 1);
        net.add_post(leave, res, 1);
    }
    net
}

#[test]
fn mutex_is_safe_live_reversible() {
    let net = mutex();
    let a = run(&net);
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(3), Some(4), Some(0)));
    assert_eq!(
        (a.bounded, a.safe, a.live, a.reversible),
        (Some(true), Some(true), Some(true), Some(true))
    );
    let mut expected = vec![
        inv(&[("idle1", 1), ("busy1", 1)]),
        inv(&[("busy1", 1), ("res", 1), ("busy2", 1)]),
        inv(&[("idle2", 1), ("busy2", 1)]),
    ];
    expected.sort();
    assert_eq!(p_inv(&a, &net), expected);
    assert_eq!(
        t_inv(&a, &net),
        vec![
            inv(&[("enter1", 1), ("leave1", 1)]),
            inv(&[("enter2", 1), ("leave2", 1)])
        ]
    );
}

#[test]
fn invariants_needing_negative_intermediate_coefficients() {
    // t1: p1 → p2 + p3; t2: p2 + p3 → 2·p4. Eliminating t1 gives rows p1+p2 and p1+p3
    // whose t2 entry is -1; each must then combine with 2·p4's row. An implementation
    // that drops rows with negative entries loses both invariants.
    let mut net = PtNet::new();
    let p1 = net.add_place("p1", 1);
    let p2 = net.add_place("p2", 0);
    let p3 = net.add_place("p3", 0);
    let p4 = net.add_place("p4", 0);
    let t1 = net.add_transition("t1");
    net.add_pre(t1, p1, 1);
    net.add_post(t1, p2, 1);
    net.add_post(t1, p3, 1);
    let t2 = net.add_transition("t2");
    net.add_pre(t2, p2, 1);
    net.add_pre(t2, p3, 1);
    net.add_post(t2, p4, 2);
    let a = run(&net);
    assert_eq!(
        p_inv(&a, &net),
        vec![
            inv(&[("p1", 2), ("p2", 2), ("p4", 1)]),
            inv(&[("p1", 2), ("p3", 2), ("p4", 1)])
        ]
    );
    assert_eq!((a.states, a.deadlocks), (Some(3), Some(1)));
}

#[test]
fn invariant_with_a_negative_column_cancelled_later() {
    // The classic case where PIPE's variant loses an invariant: y = p1 + p2 + p3
    // with C = [[-1, 1], [1, -2], [0, 1]] — the combination p1 + p2 of column t1 leaves
    // -1 in column t2, cancelled only by p3.
    let mut net = PtNet::new();
    let p1 = net.add_place("p1", 1);
    let p2 = net.add_place("p2", 0);
    let p3 = net.add_place("p3", 0);
    let t1 = net.add_transition("t1");
    net.add_pre(t1, p1, 1);
    net.add_post(t1, p2, 1);
    let t2 = net.add_transition("t2");
    net.add_pre(t2, p2, 2);
    net.add_post(t2, p1, 1);
    net.add_post(t2, p3, 1);
    let a = run(&net);
    assert_eq!(p_inv(&a, &net), vec![inv(&[("p1", 1), ("p2", 1), ("p3", 1)])]);
}

#[test]
fn reversible_cycle() {
    let net = samples::cycles(1, 3);
    let a = run(&net);
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(3), Some(3), Some(0)));
    assert_eq!((a.safe, a.live, a.reversible), (Some(true), Some(true), Some(true)));
    assert_eq!(a.components, Some(1));
    assert_eq!(p_inv(&a, &net), vec![inv(&[("c0p0", 1), ("c0p1", 1), ("c0p2", 1)])]);
    assert_eq!(t_inv(&a, &net), vec![inv(&[("c0t0", 1), ("c0t1", 1), ("c0t2", 1)])]);
}

#[test]
fn non_live_without_deadlock() {
    // t0 fires once (p0 → p1), then t1/t2 cycle between p1 and p2 for ever.
    let mut net = PtNet::new();
    let p0 = net.add_place("p0", 1);
    let p1 = net.add_place("p1", 0);
    let p2 = net.add_place("p2", 0);
    let t0 = net.add_transition("t0");
    net.add_pre(t0, p0, 1);
    net.add_post(t0, p1, 1);
    let t1 = net.add_transition("t1");
    net.add_pre(t1, p1, 1);
    net.add_post(t1, p2, 1);
    let t2 = net.add_transition("t2");
    net.add_pre(t2, p2, 1);
    net.add_post(t2, p1, 1);
    let a = run(&net);
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(3), Some(3), Some(0)));
    assert_eq!(a.dead_transitions, Some(vec![]));
    assert_eq!((a.live, a.reversible), (Some(false), Some(false)));
    assert_eq!(a.components, Some(2));
    assert_eq!(p_inv(&a, &net), vec![inv(&[("p0", 1), ("p1", 1), ("p2", 1)])]);
    assert_eq!(t_inv(&a, &net), vec![inv(&[("t1", 1), ("t2", 1)])]);
}

#[test]
fn inhibitor_arc_bounds_a_source_transition() {
    // add has no input and an inhibitor arc of weight 3 from cnt: cnt counts to 3.
    let mut net = PtNet::new();
    let cnt = net.add_place("cnt", 0);
    let add = net.add_transition("add");
    net.add_post(add, cnt, 1);
    net.add_inhibitor(add, cnt, 3);
    let a = run(&net);
    assert_eq!(a.bounded, Some(true));
    assert_eq!(a.place_bounds, finite(&[3]));
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(4), Some(3), Some(1)));
    assert_eq!(
        ids(&net, a.deadlock_trace.as_deref().unwrap_or(&[])),
        ["add", "add", "add"]
    );
    assert!(a.notes.iter().any(|n| n.contains("inhibitor")));
}

#[test]
fn inhibitor_from_another_place_keeps_karp_miller_sound() {
    let mut net = PtNet::new();
    let cnt = net.add_place("cnt", 0);
    let stop = net.add_place("stop", 0);
    let add = net.add_transition("add");
    net.add_post(add, cnt, 1);
    net.add_inhibitor(add, stop, 1);
    let a = run(&net);
    assert_eq!(a.bounded, Some(false));
    assert_eq!(a.place_bounds, Some(vec![Bound::Omega, Bound::Finite(0)]));
}

#[test]
fn unbounded_inhibitor_place_is_reported_unknown() {
    // grow fills `a` for ever; `a` inhibits `use`. Karp–Miller would be unsound on `a`,
    // so the exploration runs to the limit and the boundedness stays unknown.
    let mut net = PtNet::new();
    let a_place = net.add_place("a", 0);
    let b = net.add_place("b", 1);
    let grow = net.add_transition("grow");
    net.add_post(grow, a_place, 1);
    let use_ = net.add_transition("use");
    net.add_pre(use_, b, 1);
    net.add_inhibitor(use_, a_place, 1);
    let a = analyze(
        &net,
        &Options {
            max_states: 100,
            ..Options::default()
        },
        &Control::none(),
    );
    assert_eq!(a.bounded, None);
    assert!(a.stopped.as_deref().unwrap_or("").contains("100"), "{:?}", a.stopped);
    assert_eq!(a.states, None);
}

#[test]
fn read_arc_net() {
    // t1: a → b while flag is marked (read arc); t2: b → a; t3 consumes flag.
    let mut net = PtNet::new();
    let flag = net.add_place("flag", 1);
    let pa = net.add_place("a", 1);
    let pb = net.add_place("b", 0);
    let t1 = net.add_transition("t1");
    net.add_pre(t1, pa, 1);
    net.add_post(t1, pb, 1);
    net.add_read(t1, flag, 1);
    let t2 = net.add_transition("t2");
    net.add_pre(t2, pb, 1);
    net.add_post(t2, pa, 1);
    let t3 = net.add_transition("t3");
    net.add_pre(t3, flag, 1);
    let a = run(&net);
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(4), Some(5), Some(1)));
    assert_eq!(ids(&net, a.deadlock_trace.as_deref().unwrap_or(&[])), ["t3"]);
    assert_eq!(a.deadlock_marking, Some(vec![0, 1, 0]));
    assert_eq!((a.safe, a.live, a.reversible), (Some(true), Some(false), Some(false)));
    assert_eq!(p_inv(&a, &net), vec![inv(&[("a", 1), ("b", 1)])]);
    assert_eq!(t_inv(&a, &net), vec![inv(&[("t1", 1), ("t2", 1)])]);
}

#[test]
fn max_states_stops_with_a_message() {
    let net = samples::cycles(4, 3);
    let a = analyze(
        &net,
        &Options {
            max_states: 10,
            ..Options::default()
        },
        &Control::none(),
    );
    assert_eq!(a.bounded, None);
    assert!(a.stopped.as_deref().unwrap_or("").contains("--max-states"));
}

#[test]
fn wide_places_restart_with_more_bits() {
    // 300 tokens move one by one: the packed field must widen past 8 bits.
    let mut net = PtNet::new();
    let a_place = net.add_place("a", 300);
    let b = net.add_place("b", 0);
    let t = net.add_transition("t");
    net.add_pre(t, a_place, 1);
    net.add_post(t, b, 1);
    let a = run(&net);
    assert_eq!(a.states, Some(301));
    assert_eq!(a.place_bounds, finite(&[300, 300]));
    assert_eq!(a.deadlock_marking, Some(vec![0, 300]));
}

#[test]
fn nine_cycles_full_count() {
    // The benchmark runs 13 cycles (1 594 323 states); 9 keep debug test runs short.
    let net = samples::cycles(9, 3);
    let a = run(&net);
    assert_eq!(a.states, Some(19_683));
    assert_eq!(a.edges, Some(19_683 * 9));
    assert_eq!((a.deadlocks, a.live, a.reversible), (Some(0), Some(true), Some(true)));
    assert_eq!(a.p_invariants.as_ref().map(Vec::len), Ok(9));
}

// ---- property tests ----

/// A naive reference: BFS over `Vec<u32>` markings; `None` past `limit` states.
/// Reachable markings and, per state, its (transition, successor) pairs.
type Reference = (Vec<Vec<u32>>, Vec<Vec<(usize, usize)>>);

fn naive(net: &PtNet, limit: usize) -> Option<Reference> {
    let mut index: HashMap<Vec<u32>, usize> = HashMap::new();
    let mut states = vec![net.initial.clone()];
    index.insert(net.initial.clone(), 0);
    let mut succ: Vec<Vec<(usize, usize)>> = Vec::new();
    let mut queue = VecDeque::from([0usize]);
    while let Some(s) = queue.pop_front() {
        let m = states[s].clone();
        let mut out = Vec::new();
        for t in 0..net.transitions.len() {
            if net.enabled(&m, t) {
                let n = net.fire(&m, t)?;
                let id = match index.get(&n) {
                    Some(&i) => i,
                    None => {
                        states.push(n.clone());
                        index.insert(n, states.len() - 1);
                        queue.push_back(states.len() - 1);
                        if states.len() > limit {
                            return None;
                        }
                        states.len() - 1
                    }
                };
                out.push((t, id));
            }
        }
        if succ.len() <= s {
            succ.resize(s + 1, Vec::new());
        }
        succ[s] = out;
    }
    succ.resize(states.len(), Vec::new());
    Some((states, succ))
}

fn reach_from(succ: &[Vec<(usize, usize)>], s: usize) -> HashSet<usize> {
    let mut seen = HashSet::from([s]);
    let mut stack = vec![s];
    while let Some(v) = stack.pop() {
        for &(_, w) in &succ[v] {
            if seen.insert(w) {
                stack.push(w);
            }
        }
    }
    seen
}

prop_compose! {
    fn small_net()(np in 1usize..5, nt in 1usize..5)
        (init in prop::collection::vec(0u32..3, np),
         arcs in prop::collection::vec((0..np, 0..nt, 0u32..3, 0u32..3, 0u32..8), 0..12),
         np in Just(np), nt in Just(nt)) -> PtNet {
        let mut net = PtNet::new();
        for (i, &m) in init.iter().enumerate() { net.add_place(&format!("p{i}"), m); }
        for i in 0..nt { net.add_transition(&format!("t{i}")); }
        for (p, t, pre, post, kind) in arcs {
            if pre > 0 { net.add_pre(t, p, pre); }
            if post > 0 { net.add_post(t, p, post); }
            // Now and then a read or inhibitor arc.
            match kind { 6 => net.add_read(t, p, 1), 7 => net.add_inhibitor(t, p, 2), _ => {} }
        }
        let _ = np;
        net
    }
}

fn satisfies(y: &[i64], a: &[Vec<i64>], cols: usize) -> bool {
    (0..cols).all(|j| y.iter().zip(a).map(|(c, row)| c * row[j]).sum::<i64>() == 0)
}

fn support(y: &[i64]) -> Vec<usize> {
    (0..y.len()).filter(|&i| y[i] != 0).collect()
}

/// All semi-positive solutions with coefficients 0..=3, brute force.
fn brute_invariants(a: &[Vec<i64>], cols: usize) -> Vec<Vec<i64>> {
    let n = a.len();
    let mut out = Vec::new();
    let mut y = vec![0i64; n];
    loop {
        if y.iter().any(|&c| c != 0) && satisfies(&y, a, cols) {
            out.push(y.clone());
        }
        let mut i = 0;
        loop {
            if i == n {
                return out;
            }
            y[i] += 1;
            if y[i] <= 3 {
                break;
            }
            y[i] = 0;
            i += 1;
        }
    }
}

fn run_small(net: &PtNet) -> Analysis {
    analyze(
        net,
        &Options {
            max_states: 5_000,
            ..Options::default()
        },
        &Control::none(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(100))]

    #[test]
    fn agrees_with_the_naive_reference(net in small_net()) {
        let a = run_small(&net);
        match naive(&net, 300) {
            Some((states, succ)) => {
                prop_assert_eq!(a.bounded, Some(true));
                prop_assert_eq!(a.states, Some(states.len() as u64));
                let edges: usize = succ.iter().map(Vec::len).sum();
                prop_assert_eq!(a.edges, Some(edges as u64));
                let dead = succ.iter().filter(|s| s.is_empty()).count();
                prop_assert_eq!(a.deadlocks, Some(dead as u64));
                // Shortest trace: its length is the BFS depth of the closest dead marking.
                if let Some(trace) = &a.deadlock_trace {
                    let mut m = net.initial.clone();
                    for &t in trace {
                        prop_assert!(net.enabled(&m, t));
                        m = net.fire(&m, t).expect("no overflow");
                    }
                    prop_assert!((0..net.transitions.len()).all(|t| !net.enabled(&m, t)));
                }
                let nt = net.transitions.len();
                let live = (0..states.len()).all(|s| {
                    let r = reach_from(&succ, s);
                    (0..nt).all(|t| r.iter().any(|&v| net.enabled(&states[v], t)))
                });
                prop_assert_eq!(a.live, Some(live));
                let reversible = (0..states.len()).all(|s| reach_from(&succ, s).contains(&0));
                prop_assert_eq!(a.reversible, Some(reversible));
                let fired: HashSet<usize> = succ.iter().flatten().map(|&(t, _)| t).collect();
                let dead_t: Vec<usize> = (0..nt).filter(|t| !fired.contains(t)).collect();
                prop_assert_eq!(a.dead_transitions.clone(), Some(dead_t));
                for p in 0..net.places.len() {
                    let max = states.iter().map(|m| m[p]).max().unwrap_or(0);
                    prop_assert_eq!(a.place_bounds.as_ref().map(|b| b[p]), Some(Bound::Finite(max)));
                }
                // Every reachable marking satisfies every P-invariant.
                for y in a.p_invariants.as_ref().expect("p-invariants") {
                    let w0: i64 = y.iter().zip(&net.initial).map(|(c, &m)| c * i64::from(m)).sum();
                    for m in &states {
                        let w: i64 = y.iter().zip(m).map(|(c, &v)| c * i64::from(v)).sum();
                        prop_assert_eq!(w, w0);
                    }
                }
                // Coverability agrees with reachability on bounded nets (without inhibitor
                // arcs: with them a bounded net may cover an ancestor, see docs/nets.md).
                if net.has_inhibitors() {
                } else if let coverability::Coverability::Graph { nodes, edges: cedges, .. } =
                    coverability::coverability(&net, 100_000, Control::none().cancel)
                {
                    let set: HashSet<Vec<u32>> = nodes.into_iter().collect();
                    let reach: HashSet<Vec<u32>> = states.iter().cloned().collect();
                    prop_assert_eq!(set, reach);
                    prop_assert_eq!(cedges, edges as u64);
                } else {
                    prop_assert!(false, "coverability failed on a bounded net");
                }
            }
            None => {
                // More than 300 states: either unbounded or unknown, never a wrong "bounded".
                if a.bounded == Some(true) {
                    prop_assert!(a.states.unwrap_or(0) > 300);
                }
            }
        }
    }

    #[test]
    fn t_invariants_return_to_the_marking(net in small_net()) {
        let a = run_small(&net);
        let Some((states, _)) = naive(&net, 500) else { return Ok(()) };
        for x in a.t_invariants.as_ref().expect("t-invariants") {
            for m in states.iter().take(50) {
                // Search an order in which the multiset x is fireable from m.
                fn search(net: &PtNet, m: &[u32], left: &mut [i64]) -> Option<Vec<u32>> {
                    if left.iter().all(|&c| c == 0) {
                        return Some(m.to_vec());
                    }
                    for t in 0..left.len() {
                        if left[t] > 0 && net.enabled(m, t) {
                            let n = net.fire(m, t)?;
                            left[t] -= 1;
                            let r = search(net, &n, left);
                            left[t] += 1;
                            if r.is_some() {
                                return r;
                            }
                        }
                    }
                    None
                }
                if x.iter().sum::<i64>() > 8 {
                    continue;
                }
                let mut left = x.clone();
                if let Some(end) = search(&net, m, &mut left) {
                    prop_assert_eq!(&end, m);
                }
            }
        }
    }

    #[test]
    fn farkas_finds_every_minimal_invariant(net in small_net()) {
        for (a, cols, found) in [
            (net.incidence(), net.transitions.len(), invariants::p_invariants(&net, invariants::Budget::rows(100_000)).expect("p")),
            (
                (0..net.transitions.len()).map(|t| net.incidence().iter().map(|r| r[t]).collect()).collect(),
                net.places.len(),
                invariants::t_invariants(&net, invariants::Budget::rows(100_000)).expect("t"),
            ),
        ] {
            let brute = brute_invariants(&a, cols);
            // Found ones are invariants, gcd 1, and of minimal support.
            for y in &found {
                prop_assert!(y.iter().all(|&c| c >= 0) && satisfies(y, &a, cols));
                let g = y.iter().fold(0i64, |g, &c| { let (mut a, mut b) = (g, c); while b != 0 { (a, b) = (b, a % b); } a });
                prop_assert_eq!(g, 1);
                let s = support(y);
                for b in &brute {
                    let sb = support(b);
                    prop_assert!(!(sb.iter().all(|i| s.contains(i)) && sb.len() < s.len()), "{:?} not minimal: {:?}", y, b);
                }
            }
            // Every minimal support among the brute-force ones is found.
            for b in &brute {
                let sb = support(b);
                // Minimal among all invariants known (brute force ones have coefficients <= 3;
                // found ones are checked invariants above).
                let minimal = brute.iter().chain(&found).all(|c| { let sc = support(c); !(sc.iter().all(|i| sb.contains(i)) && sc.len() < sb.len()) });
                if minimal {
                    prop_assert!(found.iter().any(|y| support(y) == sb), "missing invariant with support {:?}", sb);
                }
            }
        }
    }
}

/// The Kanban model of the Model Checking Contest: its published reachable
/// marking counts (the benchmark, `alba bench --nets`, runs n = 5).
#[test]
fn kanban_reaches_the_published_marking_counts() {
    for (n, states) in [(1, 160), (2, 4_600), (3, 58_400)] {
        let net = samples::kanban(n);
        assert_eq!((net.places.len(), net.transitions.len()), (16, 16));
        let a = analyze(&net, &Options::default(), &Control::none());
        assert_eq!(a.states, Some(states), "kanban {n}");
        assert_eq!((a.bounded, a.deadlocks), (Some(true), Some(0)), "kanban {n}");
    }
}

/// The issue's time-outs were invariant computations running before the state space
/// and with no bound on their work: here the minimal T-invariants (8^10 of them) run out
/// of their budget, reported as such, while the state space, the flows and the minimal
/// P-invariant are complete.
#[test]
fn invariants_over_budget_block_nothing() {
    let net = samples::parallel_ring(10, 8);
    let a = analyze(
        &net,
        &Options {
            invariant_work: 5_000_000,
            ..Options::default()
        },
        &Control::none(),
    );
    assert_eq!((a.space, a.states, a.edges), (Space::Reachability, Some(10), Some(80)));
    assert_eq!((a.live, a.reversible), (Some(true), Some(true)));
    assert_eq!(a.status.state_space, Status::Complete);
    assert_eq!(a.status.components, Status::Complete);
    assert_eq!(a.status.p_flows, Status::Complete);
    assert_eq!(a.status.t_flows, Status::Complete);
    assert_eq!(a.status.p_invariants, Status::Complete);
    assert_eq!(a.status.t_invariants, Status::Skipped("budget"));
    assert_eq!(a.t_invariants, Err(invariants::InvariantError::Budget(5_000_000)));
    // T-flows: 80 transitions, incidence of rank 9.
    assert_eq!(a.t_flows.as_ref().map(Vec::len), Ok(71));
    assert_eq!(a.p_invariants.as_ref().map(Vec::len), Ok(1));
    let json = alba_net::analysis::to_json(&net, &a);
    assert_eq!(json["status"]["t_invariants"], "skipped: budget");
    assert_eq!(json["status"]["state_space"], "complete");
    assert_eq!(json["t_invariants"], serde_json::Value::Null);
    // Asked for the flows only, the minimal invariants are not computed at all.
    let a = analyze(
        &net,
        &Options {
            invariants: Invariants::Flows,
            ..Options::default()
        },
        &Control::none(),
    );
    assert_eq!(a.status.t_invariants, Status::Skipped("not requested"));
}

/// The cancellation flag stops the exploration at its next poll, and every later part.
#[test]
fn cancellation_stops_every_part() {
    let net = samples::cycles(11, 3);
    let cancel = AtomicBool::new(false);
    let seen = std::sync::Mutex::new(Vec::new());
    let progress = |p: &alba_net::analysis::Progress| {
        seen.lock().expect("lock").push((p.part, p.states));
        cancel.store(true, Ordering::Relaxed);
    };
    let a = analyze(
        &net,
        &Options::default(),
        &Control {
            cancel: &cancel,
            progress: &progress,
        },
    );
    assert_eq!(a.space, Space::Incomplete);
    assert_eq!(a.states, None);
    assert!(
        a.stopped.as_deref().unwrap_or("").starts_with("cancelled after"),
        "{:?}",
        a.stopped
    );
    assert_eq!(a.status.state_space, Status::Partial);
    assert_eq!(a.status.components, Status::Skipped("state space incomplete"));
    assert_eq!(a.status.p_flows, Status::Skipped("cancelled"));
    assert_eq!(a.status.p_invariants, Status::Skipped("cancelled"));
    let seen = seen.lock().expect("lock");
    assert_eq!(seen[0], (Part::StateSpace, 1));
    assert!(seen.iter().any(|&(p, _)| p == Part::Flows), "{seen:?}");
}

/// The memory budget stops the exploration with a message naming `--memory`; the
/// invariants are still given.
#[test]
fn memory_budget_stops_the_state_space_only() {
    let net = samples::cycles(11, 3);
    let a = analyze(
        &net,
        &Options {
            memory: 1 << 20,
            ..Options::default()
        },
        &Control::none(),
    );
    assert_eq!(a.status.state_space, Status::Partial);
    let why = a.stopped.as_deref().unwrap_or("");
    assert!(why.contains("--memory") && why.contains("1 MiB"), "{why}");
    assert!(a.memory_bytes <= 1 << 20, "{}", a.memory_bytes);
    assert_eq!(a.status.p_invariants, Status::Complete);
    assert_eq!(a.p_invariants.as_ref().map(Vec::len), Ok(11));
}

/// Rank of an integer matrix (fraction-free elimination in i128).
fn rank(rows: &[Vec<i64>]) -> usize {
    let mut m: Vec<Vec<i128>> = rows
        .iter()
        .map(|r| r.iter().map(|&v| i128::from(v)).collect())
        .collect();
    let cols = m.first().map_or(0, Vec::len);
    let mut r = 0;
    for c in 0..cols {
        let Some(p) = (r..m.len()).find(|&i| m[i][c] != 0) else {
            continue;
        };
        m.swap(r, p);
        for i in 0..m.len() {
            if i != r && m[i][c] != 0 {
                let (a, b) = (m[r][c], m[i][c]);
                let pivot = m[r].clone();
                for (x, y) in m[i].iter_mut().zip(&pivot) {
                    *x = *x * a - *y * b;
                }
                let g = m[i].iter().fold(0i128, |g, &v| {
                    let (mut a, mut b) = (g.abs(), v.abs());
                    while b != 0 {
                        (a, b) = (b, a % b);
                    }
                    a
                });
                if g > 1 {
                    m[i].iter_mut().for_each(|v| *v /= g);
                }
            }
        }
        r += 1;
    }
    r
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The flows' basis: every vector a flow, independent, as many as the kernel's
    /// dimension, and spanning every minimal invariant.
    #[test]
    fn flows_are_a_basis_of_the_kernel(net in small_net()) {
        let c = net.incidence();
        let ct: Vec<Vec<i64>> = (0..net.transitions.len()).map(|t| c.iter().map(|r| r[t]).collect()).collect();
        let never = AtomicBool::new(false);
        for (a, cols, basis, minimal) in [
            (c.clone(), net.transitions.len(), invariants::p_flows(&net, &never).expect("p"),
             invariants::p_invariants(&net, invariants::Budget::rows(100_000)).expect("p")),
            (ct.clone(), net.places.len(), invariants::t_flows(&net, &never).expect("t"),
             invariants::t_invariants(&net, invariants::Budget::rows(100_000)).expect("t")),
        ] {
            for y in &basis {
                prop_assert!(satisfies(y, &a, cols), "{:?} is not a flow", y);
            }
            prop_assert_eq!(rank(&basis), basis.len());
            prop_assert_eq!(basis.len(), a.len() - rank(&a));
            for y in &minimal {
                let mut with = basis.clone();
                with.push(y.clone());
                prop_assert_eq!(rank(&with), basis.len(), "{:?} outside the span", y);
            }
        }
    }
}

/// The decision diagrams' facts ([`symbolic::Facts`]) against the explicit graph's:
/// dead transitions, number of deadlocks, liveness, reversibility, and a trace to a
/// deadlock, replayed to a dead marking: a shortest one (as long as the explicit one;
/// the breadth-first layers of these small nets fit their budget), and one found by
/// chaining ([`symbolic::Limits::shortest_trace`] off), no shorter.
fn symbolic_facts_agree(net: &PtNet, a: &Analysis) -> Result<(), TestCaseError> {
    use alba_net::analysis::symbolic;
    for shortest_trace in [true, false] {
        let limits = symbolic::Limits {
            facts: true,
            shortest_trace,
            ..symbolic::Limits::default()
        };
        let s = symbolic::explore(net, &limits, &AtomicBool::new(false))
            .result
            .map_err(|e| TestCaseError::fail(e.reason()))?;
        let f = s.facts.expect("facts asked");
        prop_assert_eq!(f.dead_transitions.ok(), a.dead_transitions.clone());
        prop_assert_eq!(f.deadlocks.ok().and_then(|c| c.to_u64()), a.deadlocks);
        prop_assert_eq!(f.live.ok(), a.live);
        prop_assert_eq!(f.reversible.ok(), a.reversible);
        match f.deadlock_trace.expect("a trace or none") {
            None => prop_assert_eq!(a.deadlocks, Some(0)),
            Some((trace, end)) => {
                let mut m = net.initial.clone();
                for &t in &trace {
                    prop_assert!(net.enabled(&m, t));
                    m = net.fire(&m, t).expect("fires");
                }
                prop_assert_eq!(&m, &end);
                prop_assert!((0..net.transitions.len()).all(|t| !net.enabled(&m, t)));
                let explicit = a.deadlock_trace.as_ref().map_or(0, Vec::len);
                prop_assert_eq!(f.trace_shortest, shortest_trace);
                if shortest_trace {
                    prop_assert_eq!(trace.len(), explicit);
                } else {
                    prop_assert!(trace.len() >= explicit);
                }
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// On random bounded nets with weights, read and inhibitor arcs.
    #[test]
    fn symbolic_facts_equal_the_explicit_ones(net in small_net()) {
        let a = run_small(&net);
        if a.space == Space::Reachability {
            symbolic_facts_agree(&net, &a)?;
        }
    }
}

#[test]
fn symbolic_facts_of_the_samples_equal_the_explicit_ones() {
    for net in [
        samples::cycles(4, 3),
        samples::philosophers(5),
        samples::kanban(3),
        samples::parallel_ring(4, 3),
    ] {
        let a = analyze(&net, &Options::default(), &Control::none());
        assert_eq!(a.space, Space::Reachability);
        symbolic_facts_agree(&net, &a).expect("agree");
    }
}

mod stubborn_sets {
    //! The stubborn-set reduction of the contest examinations against the full
    //! exploration: random nets (read and inhibitor arcs included), random state formulas,
    //! the same verdict for EF φ and AG φ (where a state limit stopped neither on an
    //! unbounded net), and every trace replays to a marking that
    //! shows it.
    use super::*;
    use alba_net::analysis::formula::{IntExpr, Pred, Property, Query};
    use alba_net::analysis::stubborn::{CheckOptions, Verdict, answer, check};

    const N: usize = 8;

    prop_compose! {
        fn net5()(init in prop::collection::vec(0u32..3, N),
                  arcs in prop::collection::vec((0..N, 0..N, 0u32..3, 0u32..3, 0u32..10), 6..20)) -> PtNet {
            let mut net = PtNet::new();
            for (i, &m) in init.iter().enumerate() { net.add_place(&format!("p{i}"), m); }
            for i in 0..N { net.add_transition(&format!("t{i}")); }
            for (p, t, pre, post, kind) in arcs {
                if pre > 0 { net.add_pre(t, p, pre); }
                if post > 0 { net.add_post(t, p, post); }
                match kind { 8 => net.add_read(t, p, 1), 9 => net.add_inhibitor(t, p, 2), _ => {} }
            }
            net
        }
    }

    fn pred() -> impl Strategy<Value = Pred> {
        random_pred(N, 3, 12, 4)
    }

    /// Random predicates over `n` places and transitions: comparisons, `is-fireable`,
    /// `deadlock`, nested up to `depth` with at most `size` nodes and `width - 1` operands.
    pub(super) fn random_pred(n: usize, depth: u32, size: u32, width: usize) -> impl Strategy<Value = Pred> {
        let places = move || prop::collection::vec(0..n, 1..3);
        let leaf = prop_oneof![
            (places(), 0u64..4).prop_map(|(p, c)| Pred::Le(IntExpr::Tokens(p), IntExpr::Const(c))),
            (0u64..4, places()).prop_map(|(c, p)| Pred::Le(IntExpr::Const(c), IntExpr::Tokens(p))),
            (places(), places()).prop_map(|(a, b)| Pred::Le(IntExpr::Tokens(a), IntExpr::Tokens(b))),
            prop::collection::vec(0..n, 1..3).prop_map(Pred::Fireable),
            Just(Pred::Deadlock),
        ];
        leaf.prop_recursive(depth, size, 3, move |inner| {
            prop_oneof![
                inner.clone().prop_map(|p| Pred::Not(Box::new(p))),
                prop::collection::vec(inner.clone(), 1..width).prop_map(Pred::And),
                prop::collection::vec(inner, 1..width).prop_map(Pred::Or),
            ]
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        #[test]
        fn reduced_answers_equal_the_full_exploration(net in net5(), fs in prop::collection::vec(pred(), 1..4)) {
            let mut props = Vec::new();
            for (k, f) in fs.into_iter().enumerate() {
                props.push(Property { id: format!("ef{k}"), query: Query::Ef(f.clone()) });
                props.push(Property { id: format!("ag{k}"), query: Query::Ag(f) });
            }
            let limit = CheckOptions { max_states: 3_000, stubborn: false, slice: false, reduce: false };
            let full = check(&net, &props, &limit, &Control::none());
            let reduced = check(&net, &props, &CheckOptions { stubborn: true, ..limit }, &Control::none());
            let sliced = answer(&net, &props, &CheckOptions { stubborn: true, slice: true, ..limit }, &Control::none());
            let full_states = full.states;
            for (((p, a), b), c) in props.iter().zip(&full.answers).zip(&reduced.answers).zip(&sliced) {
                let unknown = |v: &Verdict| matches!(v, Verdict::Unknown(_));
                if !unknown(&a.verdict) && !unknown(&c.verdict) || full_states < limit.max_states {
                    prop_assert_eq!(&a.verdict, &c.verdict, "sliced {}: {:?}", p.id, p.query);
                }
                if let (Some(trace), Query::Ef(f) | Query::Ag(f)) = (&c.trace, &p.query) {
                    let mut m = net.initial.clone();
                    for &t in trace {
                        prop_assert!(net.enabled(&m, t));
                        m = net.fire(&m, t).expect("fires");
                    }
                    prop_assert_eq!(f.eval(&net, &m), c.verdict == Verdict::True);
                }
                // Where a limit left one undecided (unbounded nets), the decided ones agree.
                if !unknown(&a.verdict) && !unknown(&b.verdict) || full.states < limit.max_states {
                    prop_assert_eq!(&a.verdict, &b.verdict, "{}: {:?}", p.id, p.query);
                }
                if let (Some(trace), Query::Ef(f) | Query::Ag(f)) = (&b.trace, &p.query) {
                    let mut m = net.initial.clone();
                    for &t in trace {
                        prop_assert!(net.enabled(&m, t));
                        m = net.fire(&m, t).expect("fires");
                    }
                    prop_assert_eq!(f.eval(&net, &m), b.verdict == Verdict::True);
                }
            }
        }
    }
}

mod structural_reductions {
    //! The structural reductions of the contest examinations (`stubborn::reduce`)
    //! against the full exploration: random nets (read and inhibitor arcs included) with
    //! pieces the rules apply to (chains `a -h-> p -f-> b`, copies of places with more,
    //! as many or fewer tokens, copies of transitions), random formulas over the
    //! original places and transitions, bounds, the deadlock question: the same answers,
    //! every trace replayed in the original net to a marking showing the verdict.
    use super::*;
    use alba_net::analysis::formula::{Pred, Property, Query, deadlock_property};
    use alba_net::analysis::stubborn::reduce::{Applied, reduce};
    use alba_net::analysis::stubborn::{CheckOptions, Verdict, answer, check};
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;

    /// Places and transitions formulas may name.
    const N: usize = 6;

    type Piece = (u8, usize, usize, u32, bool);

    prop_compose! {
        fn reducible()(init in prop::collection::vec(0u32..3, N),
                       arcs in prop::collection::vec((0..N, 0..N, 0u32..3, 0u32..3, 0u32..10), 4..14),
                       pieces in prop::collection::vec((0u8..6, 0..N, 0..N, 0u32..3, any::<bool>()), 1..5)) -> PtNet {
            let mut net = PtNet::new();
            for (i, &m) in init.iter().enumerate() { net.add_place(&format!("p{i}"), m); }
            for i in 0..N { net.add_transition(&format!("t{i}")); }
            for (p, t, pre, post, kind) in arcs {
                if pre > 0 { net.add_pre(t, p, pre); }
                if post > 0 { net.add_post(t, p, post); }
                match kind { 7 => net.add_read(t, p, 1), 8 | 9 => net.add_inhibitor(t, p, 1 + kind - 8), _ => {} }
            }
            for (k, piece) in pieces.into_iter().enumerate() {
                add_piece(&mut net, k, piece);
            }
            net
        }
    }

    /// One piece: a chain from `a` to `b` (`f` free, or `h` giving only to the middle
    /// place and `f` needing another place; with `c = 2` also one from `b` to `a`
    /// through the same place, two and two); a copy of place `a` with `c - 1` tokens
    /// more; a copy of transition `a`; a place holding `a + b` with `c - 1` tokens more;
    /// a transition doing what `a` then `b` do (with `a`'s read and inhibitor arcs or
    /// without).
    fn add_piece(net: &mut PtNet, k: usize, (kind, a, b, c, flag): Piece) {
        match kind {
            0 | 1 => {
                let p = net.add_place(&format!("mid{k}"), 0);
                let h = net.add_transition(&format!("h{k}"));
                net.add_pre(h, a, 1);
                net.add_post(h, p, 1);
                let f = net.add_transition(&format!("f{k}"));
                net.add_pre(f, p, 1);
                net.add_post(f, b, 1);
                if kind == 1 {
                    // f also needs c's place; h perhaps gives elsewhere too.
                    net.add_pre(f, (a + b + c as usize) % N, 1);
                }
                if flag {
                    let x = net.add_place(&format!("x{k}"), 0);
                    net.add_post(if kind == 1 { f } else { h }, x, 1);
                }
                if c == 2 {
                    // Two and two: b -> p -> a as well.
                    let h2 = net.add_transition(&format!("h{k}'"));
                    net.add_pre(h2, b, 1);
                    net.add_post(h2, p, 1);
                    let f2 = net.add_transition(&format!("f{k}'"));
                    net.add_pre(f2, p, 1);
                    net.add_post(f2, a, 1);
                }
            }
            2 => {
                let q = net.add_place(&format!("copy{k}"), (net.initial[a] + c).saturating_sub(1));
                for t in 0..net.transitions.len() {
                    let (pre, post) = (weight(&net.pre[t], a), weight(&net.post[t], a));
                    if pre > 0 {
                        net.add_pre(t, q, pre);
                    }
                    if post > 0 {
                        net.add_post(t, q, post);
                    }
                    if flag && weight(&net.reads[t], a) > 0 {
                        net.add_read(t, q, 1);
                    }
                }
            }
            4 => {
                let m0 = (net.initial[a] + net.initial[b] + c).saturating_sub(1);
                let q = net.add_place(&format!("sum{k}"), m0);
                for t in 0..net.transitions.len() {
                    let w = |arcs: &[Vec<(usize, u32)>]| weight(&arcs[t], a) + weight(&arcs[t], b);
                    let (pre, post) = (w(&net.pre), w(&net.post));
                    if pre > 0 {
                        net.add_pre(t, q, pre);
                    }
                    if post > 0 {
                        net.add_post(t, q, post);
                    }
                    if flag && w(&net.reads) > 0 {
                        net.add_read(t, q, 1);
                    }
                }
            }
            5 => {
                let t = net.add_transition(&format!("seq{k}"));
                for q in 0..net.places.len() {
                    let (pa, qa) = (weight(&net.pre[a], q), weight(&net.post[a], q));
                    let (pb, qb) = (weight(&net.pre[b], q), weight(&net.post[b], q));
                    if pa + pb.saturating_sub(qa) > 0 {
                        net.add_pre(t, q, pa + pb.saturating_sub(qa));
                    }
                    if qb + qa.saturating_sub(pb) > 0 {
                        net.add_post(t, q, qb + qa.saturating_sub(pb));
                    }
                }
                if flag {
                    for (q, w) in net.reads[a].clone() {
                        net.add_read(t, q, w);
                    }
                    for (q, w) in net.inhibitors[a].clone() {
                        net.add_inhibitor(t, q, w);
                    }
                }
            }
            _ => {
                let t = net.add_transition(&format!("dup{k}"));
                for arcs in 0..4 {
                    let list = [&net.pre, &net.post, &net.reads, &net.inhibitors][arcs][a].clone();
                    for (p, w) in list {
                        match arcs {
                            0 => net.add_pre(t, p, w),
                            1 => net.add_post(t, p, w),
                            2 => net.add_read(t, p, w),
                            _ => net.add_inhibitor(t, p, w),
                        }
                    }
                }
            }
        }
    }

    fn weight(arcs: &[(usize, u32)], p: usize) -> u32 {
        arcs.iter().find(|a| a.0 == p).map_or(0, |a| a.1)
    }

    fn pred() -> impl Strategy<Value = Pred> {
        super::stubborn_sets::random_pred(N, 2, 8, 3)
    }

    /// The property lists asked of a net: the formulas as EF and AG, the deadlock
    /// question alone, and bounds of two places.
    fn lists(fs: Vec<Pred>, bound: Vec<usize>) -> Vec<Vec<Property>> {
        let mut props = Vec::new();
        for (k, f) in fs.into_iter().enumerate() {
            props.push(Property {
                id: format!("ef{k}"),
                query: Query::Ef(f.clone()),
            });
            props.push(Property {
                id: format!("ag{k}"),
                query: Query::Ag(f),
            });
        }
        let bound = vec![Property {
            id: "ub".into(),
            query: Query::Bound(bound),
        }];
        vec![props, vec![deadlock_property()], bound]
    }

    /// With and without the reductions: the same verdicts (where no limit stopped
    /// either), every trace a firing sequence of the original net ending where the
    /// formula has the verdict's value. The rules applied.
    fn compare(net: &PtNet, props: &[Property]) -> Result<Applied, TestCaseError> {
        let limit = CheckOptions {
            max_states: 3_000,
            stubborn: false,
            slice: false,
            reduce: false,
        };
        let full = check(net, props, &limit, &Control::none());
        for options in [
            CheckOptions { reduce: true, ..limit },
            CheckOptions {
                reduce: true,
                stubborn: true,
                slice: true,
                ..limit
            },
        ] {
            let have = answer(net, props, &options, &Control::none());
            for ((p, a), b) in props.iter().zip(&full.answers).zip(&have) {
                let unknown = |v: &Verdict| matches!(v, Verdict::Unknown(_));
                if !unknown(&a.verdict) && !unknown(&b.verdict) {
                    prop_assert_eq!(&a.verdict, &b.verdict, "{}: {:?} on {:?}", p.id, p.query, net);
                }
                if let (Some(trace), Query::Ef(f) | Query::Ag(f)) = (&b.trace, &p.query) {
                    let mut m = net.initial.clone();
                    for &t in trace {
                        prop_assert!(net.enabled(&m, t), "{:?}: {} of {:?} disabled", p.id, t, trace);
                        m = net.fire(&m, t).expect("fires");
                    }
                    prop_assert_eq!(
                        f.eval(net, &m),
                        b.verdict == Verdict::True,
                        "{}: trace {:?}",
                        p.id,
                        trace
                    );
                }
            }
        }
        Ok(reduce(net, props).map(|r| r.applied).unwrap_or_default())
    }

    fn case() -> impl Strategy<Value = (PtNet, Vec<Pred>, Vec<usize>)> {
        (
            reducible(),
            prop::collection::vec(pred(), 1..3),
            prop::collection::vec(0..N, 1..3),
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1500))]

        #[test]
        fn reductions_keep_every_answer_and_traces_replay((net, fs, bound) in case()) {
            for props in lists(fs, bound) {
                compare(&net, &props)?;
            }
        }
    }

    /// The generator exercises every rule (else the property test above would prove
    /// little): 600 cases from a fixed seed, each compared, and every rule applied many
    /// times.
    #[test]
    fn every_rule_is_exercised_and_sound_on_random_nets() {
        let mut runner = TestRunner::deterministic();
        let mut total = Applied::default();
        for _ in 0..600 {
            let (net, fs, bound) = case().new_tree(&mut runner).expect("a case").current();
            for props in lists(fs, bound) {
                match compare(&net, &props) {
                    Ok(a) => total += a,
                    Err(e) => panic!("{e}"),
                }
            }
        }
        eprintln!("{total:?}");
        for (rule, n) in [
            ("implicit places", total.implicit_places),
            ("dead transitions", total.dead_transitions),
            ("duplicate transitions", total.duplicate_transitions),
            ("redundant transitions", total.redundant_transitions),
            ("implicit places over several places", total.implicit_places_lp),
            ("pre-agglomerations", total.pre_agglomerations),
            ("post-agglomerations", total.post_agglomerations),
        ] {
            assert!(n >= 50, "{rule}: applied {n} times: {total:?}");
        }
    }
}

/// Everything the state space and the SCC pass report (no times, no bytes).
fn facts(a: &Analysis) -> String {
    format!(
        "{:?}",
        (
            (
                a.space,
                a.bounded,
                a.safe,
                &a.place_bounds,
                a.max_tokens,
                a.states,
                a.edges
            ),
            (a.deadlocks, &a.deadlock_trace, &a.deadlock_marking, &a.dead_transitions),
            (
                a.live,
                a.reversible,
                a.components,
                &a.status.state_space,
                &a.status.components
            ),
            &a.stopped,
        )
    )
}

fn on_threads(net: &PtNet, threads: usize, max_states: usize) -> Analysis {
    analyze(
        net,
        &Options {
            max_states,
            threads,
            invariants: Invariants::Flows,
            ..Options::default()
        },
        &Control::none(),
    )
}

prop_compose! {
    /// Nets large enough for BFS levels of hundreds of states (split between threads).
    fn medium_net()(np in 4usize..9, nt in 3usize..9)
        (init in prop::collection::vec(0u32..4, np),
         arcs in prop::collection::vec((0..np, 0..nt, 0u32..3, 0u32..3, 0u32..10), 4..24),
         nt in Just(nt)) -> PtNet {
        let mut net = PtNet::new();
        for (i, &m) in init.iter().enumerate() { net.add_place(&format!("p{i}"), m); }
        for i in 0..nt { net.add_transition(&format!("t{i}")); }
        for (p, t, pre, post, kind) in arcs {
            if pre > 0 { net.add_pre(t, p, pre); }
            if post > 0 { net.add_post(t, p, post); }
            match kind { 8 => net.add_read(t, p, 1), 9 => net.add_inhibitor(t, p, 3), _ => {} }
        }
        net
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(60))]

    /// The parallel exploration numbers the states as the sequential one: every result,
    /// the shortest deadlock trace included, is the same on one and on two threads.
    #[test]
    fn two_threads_find_what_one_finds(net in medium_net()) {
        let one = on_threads(&net, 1, 20_000);
        let two = on_threads(&net, 2, 20_000);
        prop_assert_eq!(facts(&one), facts(&two));
    }
}

#[test]
fn two_threads_find_what_one_finds_on_samples() {
    for net in [
        samples::philosophers(6),
        samples::kanban(2),
        samples::cycles(9, 3),
        philosophers_with_deadlock_far(),
    ] {
        let one = on_threads(&net, 1, usize::MAX);
        let two = on_threads(&net, 2, usize::MAX);
        assert_eq!(one.status.state_space, Status::Complete);
        assert_eq!(facts(&one), facts(&two));
    }
}

/// Philosophers whose deadlock is many levels deep (a counter before the table), so
/// that the trace is rebuilt through levels split between threads.
fn philosophers_with_deadlock_far() -> PtNet {
    let mut net = samples::philosophers(7);
    let go = net.add_place("go", 0);
    let count = net.add_place("count", 0);
    let tick = net.add_transition("tick");
    net.add_post(tick, count, 1);
    net.add_inhibitor(tick, count, 9);
    net.add_inhibitor(tick, go, 1);
    let start = net.add_transition("start");
    net.add_pre(start, count, 9);
    net.add_post(start, go, 1);
    for t in 0..net.transitions.len() - 2 {
        net.add_read(t, go, 1);
    }
    net
}

#[test]
fn a_field_widened_late_keeps_every_state_on_one_and_two_threads() {
    // 8 three-place cycles (6 561 markings) beside a token walking a chain of 21 places;
    // at its end `inc` counts to 3, so the counter's field widens when more than 90 000
    // states (two arena chunks) are stored: the states are re-laid on both threads.
    let mut net = samples::cycles(8, 3);
    let chain: Vec<usize> = (0..21)
        .map(|i| net.add_place(&format!("c{i}"), u32::from(i == 0)))
        .collect();
    for i in 0..20 {
        let t = net.add_transition(&format!("walk{i}"));
        net.add_pre(t, chain[i], 1);
        net.add_post(t, chain[i + 1], 1);
    }
    let count = net.add_place("count", 0);
    let inc = net.add_transition("inc");
    net.add_read(inc, chain[20], 1);
    net.add_post(inc, count, 1);
    net.add_inhibitor(inc, count, 3);
    let one = on_threads(&net, 1, usize::MAX);
    let two = on_threads(&net, 2, usize::MAX);
    assert_eq!(one.states, Some(6_561 * 24));
    assert_eq!(one.place_bounds.as_ref().map(|b| b[count]), Some(Bound::Finite(3)));
    assert_eq!(facts(&one), facts(&two));
}
