//! `alba analyze` (SPEC §10.5).

use super::{alba, repo};
use serde_json::Value;

#[test]
fn analyze_json_has_the_fixed_keys_and_hand_computed_values() {
    let out = alba(
        &repo(),
        &["analyze", "crates/cli/tests/fixtures/philosophers2.pnml", "--json"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.trim().lines().count(), 1, "one object: {text}");
    let v: Value = serde_json::from_str(&text).expect("JSON");
    for key in [
        "places",
        "transitions",
        "bounded",
        "safe",
        "place_bounds",
        "states",
        "edges",
        "deadlocks",
        "dead_transitions",
        "live",
        "reversible",
        "p_invariants",
        "t_invariants",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["places"], 8);
    assert_eq!(v["transitions"], 6);
    assert_eq!(v["bounded"], true);
    assert_eq!(v["safe"], true);
    assert_eq!(v["place_bounds"]["fork0"], 1);
    assert_eq!(v["states"], 6);
    assert_eq!(v["edges"], 8);
    assert_eq!(v["deadlocks"], 1);
    assert_eq!(v["deadlock_trace"], serde_json::json!(["takeL0", "takeL1"]));
    assert_eq!(v["dead_transitions"], serde_json::json!([]));
    assert_eq!(v["live"], false);
    assert_eq!(v["reversible"], false);
    let p = v["p_invariants"].as_array().expect("list");
    assert_eq!(p.len(), 4);
    assert!(p.contains(&serde_json::json!({"think0": 1, "hasL0": 1, "eat0": 1})));
    assert!(p.contains(&serde_json::json!({"hasL0": 1, "eat0": 1, "fork0": 1, "eat1": 1})));
    let t = v["t_invariants"].as_array().expect("list");
    assert!(t.contains(&serde_json::json!({"takeL1": 1, "takeR1": 1, "release1": 1})));
}

#[test]
fn analyze_report_and_errors() {
    let out = alba(&repo(), &["analyze", "crates/cli/tests/fixtures/philosophers2.pnml"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("shortest firing sequence to one: takeL0 takeL1"),
        "{text}"
    );
    assert!(text.contains("guards, priorities and tags are ignored"), "{text}");
    let dir = std::env::temp_dir().join(format!("alba-analyze-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let bad = dir.join("bad.pnml");
    std::fs::write(&bad, "<pnml><net").expect("write");
    let out = alba(&repo(), &["analyze", bad.to_str().expect("utf-8"), "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("E601") && err.contains("bad.pnml:1:"), "{err}");
    let out = alba(
        &repo(),
        &[
            "analyze",
            "crates/cli/tests/fixtures/philosophers2.pnml",
            "--json",
            "--max-states",
            "3",
        ],
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["bounded"], Value::Null);
    assert!(String::from_utf8_lossy(&out.stderr).contains("--max-states"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Each part's status, the flows' basis, `--invariants flows` and `--memory`.
#[test]
fn analyze_reports_each_parts_status_and_takes_a_memory_budget() {
    let net = "crates/cli/tests/fixtures/philosophers2.pnml";
    let out = alba(&repo(), &["analyze", net, "--json"]);
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    for part in [
        "state_space",
        "components",
        "p_flows",
        "t_flows",
        "p_invariants",
        "t_invariants",
    ] {
        assert_eq!(v["status"][part], "complete", "{part}");
    }
    assert_eq!(v["p_flows"].as_array().map(Vec::len), Some(4));
    assert_eq!(v["max_tokens_per_marking"], 4);
    let out = alba(
        &repo(),
        &["analyze", net, "--json", "--invariants", "flows", "--memory", "64M"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["p_invariants"], Value::Null);
    assert_eq!(v["status"]["p_invariants"], "skipped: not requested");
    assert_eq!(v["states"], 6);
    let out = alba(&repo(), &["analyze", net, "--memory", "lots"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("is not a size"));
}
