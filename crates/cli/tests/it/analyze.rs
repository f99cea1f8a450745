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

/// The instances of the contest corpus (`crates/net/tests/mcc/corpus.tar.xz`, licences in
/// its README) named in `names`, each written to a folder of `dir` as the contest lays
/// them out (`model.pnml`, the formula files, `oracle.out`).
fn corpus_instances(dir: &std::path::Path, names: &[&str]) {
    for (instance, files) in alba_testkit::mcc::instances() {
        if names.contains(&instance.as_str()) {
            std::fs::create_dir_all(dir.join(&instance)).expect("dir");
            for (file, data) in files {
                std::fs::write(dir.join(&instance).join(file), data).expect("write");
            }
        }
    }
}

/// `--symbolic`: the contest's `Philosophers-PT-000100` (5·10^47 states) counted by the
/// decision diagrams, the explicit exploration skipped; `Kanban-PT-00005` with a
/// memory budget too small for its 2.5 M markings falls back on them without the flag;
/// an unbounded net is refused.
#[test]
fn analyze_symbolic_counts_what_the_explicit_exploration_cannot_hold() {
    let dir = super::scratch("analyze-symbolic");
    corpus_instances(&dir, &["Philosophers-PT-000100", "Kanban-PT-00005"]);
    let big = dir.join("Philosophers-PT-000100");
    let out = alba(
        &repo(),
        &[
            "analyze",
            big.to_str().expect("utf-8"),
            "--json",
            "--symbolic",
            "--invariants",
            "flows",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let states = "515377520732011331036461129765621272702107522001";
    assert_eq!(v["symbolic"]["status"], "complete");
    assert_eq!(v["symbolic"]["states"], states);
    assert_eq!(
        v["symbolic"]["edges"],
        "40084918279156436858391421203992765654608362822300"
    );
    assert!(v["symbolic"]["nodes"].as_u64().unwrap_or(0) > 0);
    assert_eq!(v["status"]["state_space"], "skipped: budget");
    assert_eq!(v["status"]["symbolic"], "complete");
    assert_eq!(v["states"], Value::Null, "more than a u64");
    assert_eq!(v["bounded"], true);
    assert_eq!(v["max_tokens_per_marking"], 200);
    // Decided on the diagrams: the contest's two deadlocks (all left forks or all right
    // ones), hence neither live nor reversible; a trace to one found by chaining (the
    // breadth-first layers exceed their budget), at least one firing per fork taken.
    assert_eq!(v["deadlocks"], 2);
    assert_eq!(v["dead_transitions"], serde_json::json!([]));
    assert_eq!(v["live"], false);
    assert_eq!(v["reversible"], false);
    assert_eq!(v["status"]["symbolic_facts"], "complete");
    let trace = v["deadlock_trace"].as_array().expect("a trace");
    assert!(trace.len() >= 100, "{trace:?}");
    assert!(v["deadlock_marking"].is_object(), "{}", v["deadlock_marking"]);
    assert!(
        v["notes"].to_string().contains("not always a shortest one"),
        "{}",
        v["notes"]
    );
    let out = alba(
        &repo(),
        &[
            "analyze",
            big.to_str().expect("utf-8"),
            "--symbolic",
            "--invariants",
            "flows",
        ],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(&format!("symbolic (decision diagrams): {states} states")),
        "{text}"
    );
    assert!(text.contains("come from the symbolic engine"), "{text}");
    assert!(text.contains("  firing sequence to one: "), "{text}");
    let kanban = dir.join("Kanban-PT-00005");
    let out = alba(
        &repo(),
        &[
            "analyze",
            kanban.to_str().expect("utf-8"),
            "--json",
            "--memory",
            "4M",
            "--invariants",
            "flows",
        ],
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["status"]["state_space"], "partial");
    assert_eq!(v["status"]["symbolic"], "complete");
    assert_eq!(v["states"], 2_546_432);
    assert_eq!(v["edges"], 24_460_016);
    assert_eq!(v["status"]["symbolic_facts"], "complete");
    assert_eq!(
        (&v["deadlocks"], &v["live"], &v["reversible"]),
        (
            &serde_json::json!(0),
            &serde_json::json!(true),
            &serde_json::json!(true)
        )
    );
    let unbounded = dir.join("grow.pnml");
    std::fs::write(
        &unbounded,
        r#"<pnml><net id="g" type="http://www.pnml.org/version-2009/grammar/ptnet"><page id="pg">
<place id="p"/><transition id="t"/><arc id="a" source="t" target="p"/></page></net></pnml>"#,
    )
    .expect("write");
    let out = alba(
        &repo(),
        &["analyze", unbounded.to_str().expect("utf-8"), "--json", "--symbolic"],
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["status"]["symbolic"], "skipped: unbounded", "{v}");
    assert_eq!(v["symbolic"]["states"], Value::Null);
}

/// `FORMULA <id> <value>` pairs of a contest output.
fn formula_lines(text: &str) -> Vec<(String, String)> {
    text.lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            if w.next() != Some("FORMULA") {
                return None;
            }
            Some((w.next()?.to_string(), w.next()?.to_string()))
        })
        .collect()
}

/// Replays a firing sequence of transition ids from the initial marking; `None` when a
/// transition is unknown or not enabled.
fn replay(pt: &alba_net::PtNet, trace: &[&str]) -> Option<Vec<u32>> {
    let mut m = pt.initial.clone();
    for id in trace {
        m = pt.fire(&m, pt.transition(id)?)?;
    }
    Some(m)
}

/// Every examination on four contest instances: each formula answered, each answer the
/// oracle's, and each trace a firing sequence of the net to a marking that is a witness
/// (EF φ true) or a counterexample (AG φ false).
#[test]
fn analyze_examinations_match_the_contest_oracles_and_traces_replay() {
    use alba_net::analysis::formula::{self, Query};
    let dir = super::scratch("analyze-examinations");
    let names = [
        "ERK-PT-000001",
        "ResAllocation-PT-R003C002",
        "Eratosthenes-PT-010",
        "TwoPhaseLocking-PT-nC00004vD",
    ];
    corpus_instances(&dir, &names);
    let mut checked = 0;
    let mut traces = 0;
    for name in names {
        let inst = dir.join(name);
        let oracle = std::fs::read_to_string(inst.join("oracle.out")).expect("oracle");
        let expected: std::collections::BTreeMap<String, String> = formula_lines(&oracle).into_iter().collect();
        let text = std::fs::read_to_string(inst.join("model.pnml")).expect("model");
        let (net, _) = alba_net::load(alba_diag::FileId(0), &text);
        let pt = alba_net::PtNet::from_net(&net.expect("net"));
        for exam in [
            "UpperBounds",
            "ReachabilityCardinality",
            "ReachabilityFireability",
            "ReachabilityDeadlock",
        ] {
            let out = alba(
                &repo(),
                &[
                    "analyze",
                    inst.to_str().expect("utf-8"),
                    "--examination",
                    exam,
                    "--json",
                ],
            );
            assert!(
                out.status.success(),
                "{name} {exam}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
            assert_eq!(v["examination"], exam);
            let props = if exam == "ReachabilityDeadlock" {
                vec![formula::deadlock_property()]
            } else {
                let f = std::fs::read_to_string(inst.join(format!("{exam}.xml"))).expect("formulas");
                formula::parse(&f, &pt).expect("parses")
            };
            let list = v["formulas"].as_array().expect("formulas");
            assert_eq!(list.len(), props.len(), "{name} {exam}");
            for (a, p) in list.iter().zip(&props) {
                assert_eq!(a["id"], p.id.as_str());
                let value = match (&a["verdict"], &a["bound"]) {
                    (Value::Bool(true), _) => "TRUE".to_string(),
                    (Value::Bool(false), _) => "FALSE".to_string(),
                    (_, Value::Number(n)) => n.to_string(),
                    _ => panic!("{name}: {} undecided", p.id),
                };
                let want = expected.get(&p.id).unwrap_or_else(|| panic!("{}: no oracle", p.id));
                assert_eq!(&value, want, "{}", p.id);
                assert!(
                    a["line"]
                        .as_str()
                        .expect("line")
                        .starts_with(&format!("FORMULA {} {value} TECHNIQUES EXPLICIT", p.id))
                );
                checked += 1;
                if let Some(t) = a["trace"].as_array() {
                    let ids: Vec<&str> = t.iter().filter_map(Value::as_str).collect();
                    let m = replay(&pt, &ids).unwrap_or_else(|| panic!("{}: trace does not replay", p.id));
                    match &p.query {
                        Query::Ef(f) => assert!(value == "TRUE" && f.eval(&pt, &m), "{}", p.id),
                        Query::Ag(f) => assert!(value == "FALSE" && !f.eval(&pt, &m), "{}", p.id),
                        Query::Bound(_) => panic!("{}: a bound has no trace", p.id),
                    }
                    traces += 1;
                }
            }
        }
    }
    assert_eq!(checked, 4 * (3 * 16 + 1), "every formula of the four instances");
    assert!(traces > 0);
}

/// The text form with `--trace` on a hand-written file over two philosophers: the
/// shortest witnesses and counterexamples, computed by hand.
#[test]
fn analyze_examination_prints_the_contest_lines_and_traces() {
    let dir = super::scratch("analyze-examination-text");
    let net = "crates/cli/tests/fixtures/philosophers2.pnml";
    let card = dir.join("card.xml");
    std::fs::write(
        &card,
        r#"<?xml version="1.0"?>
<property-set xmlns="http://mcc.lip6.fr/">
  <property><id>eats</id><description/><formula><exists-path><finally>
    <integer-le><integer-constant>1</integer-constant><tokens-count><place>eat0</place></tokens-count></integer-le>
  </finally></exists-path></formula></property>
  <property><id>both-eat</id><description/><formula><exists-path><finally><conjunction>
    <integer-le><integer-constant>1</integer-constant><tokens-count><place>eat0</place></tokens-count></integer-le>
    <integer-le><integer-constant>1</integer-constant><tokens-count><place>eat1</place></tokens-count></integer-le>
  </conjunction></finally></exists-path></formula></property>
  <property><id>fork0-kept</id><description/><formula><all-paths><globally>
    <integer-le><integer-constant>1</integer-constant><tokens-count><place>fork0</place><place>hasL0</place><place>eat0</place></tokens-count></integer-le>
  </globally></all-paths></formula></property>
  <property><id>fire</id><description/><formula><exists-path><finally>
    <is-fireable><transition>release1</transition></is-fireable>
  </finally></exists-path></formula></property>
</property-set>
"#,
    )
    .expect("write");
    let out = alba(
        &repo(),
        &[
            "analyze",
            net,
            "--examination",
            "ReachabilityCardinality",
            "--formulas",
            card.to_str().expect("utf-8"),
            "--trace",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines = formula_lines(&text);
    assert_eq!(
        lines,
        [
            ("eats", "TRUE"),
            ("both-eat", "FALSE"),
            ("fork0-kept", "FALSE"),
            ("fire", "TRUE")
        ]
        .map(|(a, b)| (a.to_string(), b.to_string()))
    );
    // eat0 needs takeL0 then takeR0; fork0 + hasL0 + eat0 counts fork0's token wherever
    // it is except in philosopher 1's right hand (eat1): takeL1 takeR1.
    assert!(text.contains("  trace eats: takeL0 takeR0\n"), "{text}");
    assert!(text.contains("  trace fork0-kept: takeL1 takeR1\n"), "{text}");
    assert!(text.contains("  trace fire: takeL1 takeR1\n"), "{text}");
    assert!(!text.contains("trace both-eat"), "no witness for a false EF: {text}");
    // Without --trace, only the FORMULA lines.
    let out = alba(&repo(), &["analyze", net, "--examination", "ReachabilityDeadlock"]);
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "FORMULA ReachabilityDeadlock TRUE TECHNIQUES EXPLICIT PARTIAL_ORDER STRUCTURAL_REDUCTION\n"
    );
    let out = alba(
        &repo(),
        &["analyze", net, "--examination", "ReachabilityDeadlock", "--trace"],
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("  trace ReachabilityDeadlock: takeL0 takeL1\n"));
    // A state limit too small to decide: CANNOT_COMPUTE, and why on stderr.
    let out = alba(
        &repo(),
        &[
            "analyze",
            net,
            "--examination",
            "ReachabilityDeadlock",
            "--max-states",
            "1",
        ],
    );
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "FORMULA ReachabilityDeadlock CANNOT_COMPUTE\n"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("--max-states"));
}

/// A malformed formula file, a missing one, an unknown place or transition: an error
/// with the file, line and column, exit 1, nothing on stdout.
#[test]
fn analyze_examination_errors_name_the_file_line_and_column() {
    let dir = super::scratch("analyze-examination-errors");
    let net = "crates/cli/tests/fixtures/philosophers2.pnml";
    let cases = [
        (
            "malformed.xml",
            "<property-set>\n  <property><id>x</id>\n</property-set>\n",
            "malformed.xml:3:",
        ),
        (
            "place.xml",
            "<property-set>\n<property><id>x</id><formula><exists-path><finally>\n  <integer-le><integer-constant>1</integer-constant><tokens-count><place>nowhere</place></tokens-count></integer-le>\n</finally></exists-path></formula></property>\n</property-set>\n",
            "place.xml:3:",
        ),
        (
            "transition.xml",
            "<property-set>\n<property><id>x</id><formula><exists-path><finally>\n\n  <is-fireable><transition>jump</transition></is-fireable>\n</finally></exists-path></formula></property>\n</property-set>\n",
            "transition.xml:4:",
        ),
        (
            "operator.xml",
            "<property-set>\n<property><id>x</id><formula><exists-path><finally><until/></finally></exists-path></formula></property>\n</property-set>\n",
            "operator.xml:2:",
        ),
    ];
    for (file, text, at) in cases {
        let path = dir.join(file);
        std::fs::write(&path, text).expect("write");
        let out = alba(
            &repo(),
            &[
                "analyze",
                net,
                "--examination",
                "ReachabilityFireability",
                "--formulas",
                path.to_str().expect("utf-8"),
            ],
        );
        assert_eq!(out.status.code(), Some(1), "{file}");
        assert!(out.stdout.is_empty(), "{file}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("error: ") && err.contains(at), "{file}: {err}");
    }
    let missing = dir.join("missing.xml");
    let out = alba(
        &repo(),
        &[
            "analyze",
            net,
            "--examination",
            "UpperBounds",
            "--formulas",
            missing.to_str().expect("utf-8"),
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read"));
    // No file beside the model: the default `<EXAMINATION>.xml` is missing too.
    let out = alba(&repo(), &["analyze", net, "--examination", "UpperBounds"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("UpperBounds.xml"));
    let out = alba(
        &repo(),
        &[
            "analyze",
            net,
            "--examination",
            "ReachabilityDeadlock",
            "--formulas",
            "x.xml",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no formula file"));
    for args in [
        &["analyze", net, "--trace"][..],
        &["analyze", net, "--examination", "CTLFireability"][..],
    ] {
        let out = alba(&repo(), args);
        assert!(!out.status.success(), "{args:?}");
    }
}

/// `--memory` bounds the examination's exploration too: past the budget the formulas are
/// CANNOT_COMPUTE (the contest's word), with the reason on stderr; with room, the
/// oracle's bounds.
#[test]
fn analyze_examination_keeps_the_memory_budget() {
    let dir = super::scratch("analyze-examination-memory");
    corpus_instances(&dir, &["Anderson-PT-04"]);
    let inst = dir.join("Anderson-PT-04");
    let inst = inst.to_str().expect("utf-8");
    let out = alba(
        &repo(),
        &["analyze", inst, "--examination", "UpperBounds", "--memory", "1K"],
    );
    assert!(out.status.success());
    let lines = formula_lines(&String::from_utf8_lossy(&out.stdout));
    assert_eq!(lines.len(), 16);
    assert!(lines.iter().all(|(_, v)| v == "CANNOT_COMPUTE"), "{lines:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("memory budget"));
    let out = alba(
        &repo(),
        &["analyze", inst, "--examination", "UpperBounds", "--memory", "256M"],
    );
    let oracle = std::fs::read_to_string(dir.join("Anderson-PT-04/oracle.out")).expect("oracle");
    let expected = formula_lines(&oracle);
    let lines = formula_lines(&String::from_utf8_lossy(&out.stdout));
    assert_eq!(lines.len(), 16);
    for l in lines {
        assert!(expected.contains(&l), "{l:?}");
    }
}

/// Issue 38, point 6: a coloured model of the contest (`crates/net/tests/mcc/col.tar.xz`)
/// is unfolded and analysed; its answers are the contest's, and the note says what the
/// unfolding made; its examinations' answers are the contest's. A symmetric net over the
/// unfolding budget is refused with E606.
#[test]
fn analyze_unfolds_a_coloured_model() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (instance, files) in alba_testkit::mcc::instances_in(&alba_testkit::mcc::coloured_path()) {
        if ["Philosophers-COL-000005", "BART-COL-002"].contains(&instance.as_str()) {
            std::fs::create_dir_all(dir.path().join(&instance)).expect("dir");
            for (file, data) in files {
                std::fs::write(dir.path().join(&instance).join(file), data).expect("write");
            }
        }
    }
    let philo = dir.path().join("Philosophers-COL-000005");
    let out = alba(&repo(), &["analyze", philo.to_str().expect("utf-8"), "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("a coloured net (symmetric net), unfolded: 5 coloured places and 5 transitions (25 bindings) became 25 places and 25 transitions"),
        "{err}"
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    // The contest's answers for Philosophers-COL-000005 (and its P/T twin).
    assert_eq!(v["states"], 243);
    assert_eq!(v["edges"], 945);
    assert_eq!(v["max_tokens_per_marking"], 10);
    assert_eq!(v["place_bounds"]["Think_1"], 1);
    // The contest's examinations: the formulas name coloured places and transitions;
    // every answer is the contest's, and a trace names the unfolded transitions.
    let oracle = std::fs::read_to_string(philo.join("oracle.out")).expect("oracle");
    let expected: std::collections::BTreeMap<String, String> = formula_lines(&oracle).into_iter().collect();
    let text = std::fs::read_to_string(philo.join("model.pnml")).expect("model");
    let (net, _, _) = alba_net::load_for_analysis(alba_diag::FileId(0), &text);
    let pt = alba_net::PtNet::from_net(&net.expect("unfolds"));
    let mut checked = 0;
    for exam in [
        "UpperBounds",
        "ReachabilityCardinality",
        "ReachabilityFireability",
        "ReachabilityDeadlock",
    ] {
        let out = alba(
            &repo(),
            &[
                "analyze",
                philo.to_str().expect("utf-8"),
                "--examination",
                exam,
                "--trace",
            ],
        );
        assert!(out.status.success(), "{exam}: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8_lossy(&out.stdout);
        let lines = formula_lines(&text);
        assert!(!lines.is_empty(), "{text}");
        for (id, value) in &lines {
            assert_eq!(expected.get(id), Some(value), "{id}");
            checked += 1;
        }
        if exam == "ReachabilityDeadlock" {
            let trace = text
                .lines()
                .find_map(|l| l.trim().strip_prefix("trace ReachabilityDeadlock: "))
                .unwrap_or_else(|| panic!("a trace: {text}"));
            let ids: Vec<&str> = trace.split_whitespace().collect();
            assert!(ids.iter().all(|t| t.contains('_')), "unfolded names: {trace}");
            let m = replay(&pt, &ids).expect("replays on the unfolded net");
            assert!((0..pt.transitions.len()).all(|t| !pt.enabled(&m, t)), "{trace}");
        }
    }
    assert_eq!(checked, 3 * 16 + 1);
    let bart = dir.path().join("BART-COL-002/model.pnml");
    let out = alba(&repo(), &["analyze", bart.to_str().expect("utf-8")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("E606"), "{err}");
    assert!(
        err.contains("bindings of its variables; Alba tries at most 20000000"),
        "{err}"
    );
}
