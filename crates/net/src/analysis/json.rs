//! The analysis as JSON: the object `alba analyze --json` prints and
//! `GET /api/nets/{name}/analysis` answers (SPEC §10.5's keys plus extras,
//! docs/nets.md "JSON"), places and transitions named by their PNML ids.

use super::{Analysis, Bound, Space, Status};
use crate::PtNet;
use serde_json::{Map, Value, json};

fn bound_json(b: Bound) -> Value {
    match b {
        Bound::Finite(n) => json!(n),
        Bound::Omega => json!("omega"),
    }
}

fn invariants_json(ids: &[String], invs: &[Vec<i64>]) -> Value {
    Value::Array(
        invs.iter()
            .map(|y| {
                let mut m = Map::new();
                for (i, &c) in y.iter().enumerate() {
                    if c != 0 {
                        m.insert(ids[i].clone(), json!(c));
                    }
                }
                Value::Object(m)
            })
            .collect(),
    )
}

/// The `--json` object: the keys of SPEC §10.5 plus extras.
pub fn to_json(pt: &PtNet, a: &Analysis) -> Value {
    let names = |ts: &[usize]| -> Value { Value::Array(ts.iter().map(|&t| json!(pt.transitions[t])).collect()) };
    let place_bounds = a.place_bounds.as_ref().map(|b| {
        let mut m = Map::new();
        for (i, &v) in b.iter().enumerate() {
            m.insert(pt.places[i].clone(), bound_json(v));
        }
        Value::Object(m)
    });
    let mut o = Map::new();
    o.insert("places".into(), json!(a.places));
    o.insert("transitions".into(), json!(a.transitions));
    o.insert("bounded".into(), json!(a.bounded));
    o.insert("safe".into(), json!(a.safe));
    o.insert("place_bounds".into(), place_bounds.unwrap_or(Value::Null));
    o.insert("states".into(), json!(a.states));
    o.insert("edges".into(), json!(a.edges));
    o.insert("deadlocks".into(), json!(a.deadlocks));
    o.insert(
        "dead_transitions".into(),
        a.dead_transitions.as_deref().map_or(Value::Null, names),
    );
    o.insert("live".into(), json!(a.live));
    o.insert("reversible".into(), json!(a.reversible));
    let inv = |r: &super::InvariantList, ids: &[String]| match r {
        Ok(v) => invariants_json(ids, v),
        Err(_) => Value::Null,
    };
    o.insert("p_invariants".into(), inv(&a.p_invariants, &pt.places));
    o.insert("t_invariants".into(), inv(&a.t_invariants, &pt.transitions));
    // Extras.
    o.insert("p_flows".into(), inv(&a.p_flows, &pt.places));
    o.insert("t_flows".into(), inv(&a.t_flows, &pt.transitions));
    o.insert("max_tokens_per_marking".into(), json!(a.max_tokens));
    o.insert("memory_bytes".into(), json!(a.memory_bytes));
    let st = &a.status;
    o.insert(
        "status".into(),
        json!({
            "state_space": st.state_space.to_string(),
            "components": st.components.to_string(),
            "p_flows": st.p_flows.to_string(),
            "t_flows": st.t_flows.to_string(),
            "p_invariants": st.p_invariants.to_string(),
            "t_invariants": st.t_invariants.to_string(),
            "symbolic": st.symbolic.to_string(),
            "symbolic_facts": st.symbolic_facts.to_string(),
        }),
    );
    let sym = &a.symbolic;
    o.insert(
        "symbolic".into(),
        json!({
            "status": st.symbolic.to_string(),
            "states": sym.result.as_ref().map(|s| s.states.to_string()),
            "edges": sym.result.as_ref().map(|s| s.firings.to_string()),
            "deadlocks": sym.result.as_ref().and_then(|s| s.facts.as_ref()?.deadlocks.as_ref().ok()).map(ToString::to_string),
            "nodes": sym.nodes,
            "memory_bytes": sym.bytes,
            "seconds": sym.time.as_secs_f64(),
        }),
    );
    o.insert(
        "deadlock_trace".into(),
        a.deadlock_trace.as_deref().map_or(Value::Null, names),
    );
    o.insert(
        "deadlock_marking".into(),
        a.deadlock_marking.as_ref().map_or(Value::Null, |m| {
            Value::Object(
                m.iter()
                    .enumerate()
                    .filter(|(_, v)| **v > 0)
                    .map(|(i, v)| (pt.places[i].clone(), json!(v)))
                    .collect(),
            )
        }),
    );
    o.insert(
        "state_space".into(),
        json!(match a.space {
            Space::Reachability => "reachability",
            Space::Coverability => "coverability",
            Space::Incomplete => "incomplete",
        }),
    );
    o.insert("strongly_connected_components".into(), json!(a.components));
    o.insert("stopped".into(), json!(a.stopped));
    let mut errors = Vec::new();
    for (what, r, s) in [
        ("P-flows", &a.p_flows, &st.p_flows),
        ("T-flows", &a.t_flows, &st.t_flows),
        ("minimal P-invariants", &a.p_invariants, &st.p_invariants),
        ("minimal T-invariants", &a.t_invariants, &st.t_invariants),
    ] {
        if let (Err(e), Status::Skipped(why)) = (r, s)
            && *why != "not requested"
        {
            errors.push(format!("{what} not computed: {e}"));
        }
    }
    let notes: Vec<String> = a.notes.iter().cloned().chain(errors).collect();
    o.insert("notes".into(), json!(notes));
    o.insert(
        "timings_ms".into(),
        json!({
            "explore": a.explore_time.as_secs_f64() * 1e3,
            "scc": a.scc_time.as_secs_f64() * 1e3,
            "invariants": a.invariant_time.as_secs_f64() * 1e3,
        }),
    );
    Value::Object(o)
}
