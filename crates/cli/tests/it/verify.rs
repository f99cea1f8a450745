//! `alba verify` and `alba test` through the binary (SPEC §10.6): the JSON,
//! the exit codes, counterexamples replayed by `alba sim`, JUnit XML.

use crate::{alba, repo, scratch};
use quick_xml::events::Event;
use std::path::Path;

const MOTOR_TAGS: &str = "name,type,address,initial,retain,description
FwdBtn,BOOL,DI:1/0,,,
RevBtn,BOOL,DI:1/1,,,
Stop,BOOL,DI:1/2,,,
Fwd,BOOL,DO:2/0,,,
Rev,BOOL,DO:2/1,,,
Run,TIMER,,,,
";

fn project(dir: &Path, lad: &str, props: &str) {
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"m\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
    )
    .expect("write the project");
    std::fs::write(dir.join("tags.csv"), MOTOR_TAGS).expect("write the project");
    std::fs::write(dir.join("main.lad"), lad).expect("write the project");
    std::fs::write(dir.join("properties.toml"), props).expect("write the project");
}

const PROPS: &str = r#"
[[property]]
name = "never both directions"
mutex = ["Fwd", "Rev"]

[[property]]
name = "stop wins"
never = "Stop AND (Fwd OR Rev)"

[[property]]
name = "forward is reachable"
reachable = "Fwd AND Run.DN"
"#;

/// Forward then reverse, each rung interlocked by the other (and a timer
/// counting forward running time).
const GOOD: &str = "\
[XIC(FwdBtn),XIC(Fwd)]XIO(Stop)XIO(Rev)OTE(Fwd);
[XIC(RevBtn),XIC(Rev)]XIO(Stop)XIO(Fwd)OTE(Rev);
XIC(Fwd)TON(Run,300,0);
";
/// The same with the reverse rung's interlock contact missing.
const BAD: &str = "\
[XIC(FwdBtn),XIC(Fwd)]XIO(Stop)XIO(Rev)OTE(Fwd);
[XIC(RevBtn),XIC(Rev)]XIO(Stop)OTE(Rev);
XIC(Fwd)TON(Run,300,0);
";

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

#[test]
fn verify_proves_the_interlocked_starter() {
    let d = scratch("verify-good");
    project(&d, GOOD, PROPS);
    let out = alba(&d, &["verify", ".", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
    let v = json(&out);
    let props = v["properties"].as_array().expect("properties");
    assert_eq!(props.len(), 3);
    for p in props {
        assert_eq!(p["result"], "proved", "{p}");
        assert!(p["counterexample"].is_null(), "{p}");
        assert!(p["depth"].as_u64().expect("depth") > 0, "{p}");
        assert!(p["name"].is_string());
    }
    assert_eq!(props[0]["name"], "never both directions");
}

#[test]
fn verify_refutes_the_missing_interlock_and_sim_replays_it() {
    let d = scratch("verify-bad");
    project(&d, BAD, PROPS);
    let out = alba(&d, &["verify", ".", "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stdout));
    let v = json(&out);
    let p = &v["properties"][0];
    assert_eq!(p["result"], "refuted", "{p}");
    assert_eq!(v["properties"][1]["result"], "proved");
    let cex = p["counterexample"].as_str().expect("a counterexample path");
    let depth = p["depth"].as_u64().expect("depth");
    let until = (depth - 1) * 10;
    // `alba sim` replays it into the violation: both directions on at its last scan.
    let sim = alba(
        &d,
        &[
            "sim",
            ".",
            "--stimulus",
            cex,
            "--until",
            &until.to_string(),
            "--tags",
            "Fwd,Rev",
        ],
    );
    assert!(sim.status.success(), "{}", String::from_utf8_lossy(&sim.stderr));
    let trace = String::from_utf8_lossy(&sim.stdout);
    let last = trace.lines().last().expect("a row");
    assert_eq!(last, format!("{until},1,1"), "{trace}");
    // And not before it (the counterexample is the shortest).
    assert!(
        trace
            .lines()
            .skip(1)
            .take(depth as usize - 1)
            .all(|l| !l.ends_with(",1,1")),
        "{trace}"
    );
}

#[test]
fn verify_answers_unknown_with_exit_2_and_refuses_bad_files() {
    let d = scratch("verify-unknown");
    project(&d, GOOD, PROPS);
    // A budget far too small: unknown, never proved by the search (the two
    // invariants are proved by k-induction, which stores no state).
    let out = alba(&d, &["verify", ".", "--json", "--max-states", "3"]);
    assert_eq!(out.status.code(), Some(2));
    let v = json(&out);
    for p in v["properties"].as_array().unwrap() {
        if p["method"] == "k-induction" {
            assert_eq!(p["result"], "proved", "{p}");
            assert!(p["sat_calls"].as_u64().unwrap() >= 2, "{p}");
        } else {
            assert_eq!(p["result"], "unknown", "{p}");
        }
    }
    assert_eq!(v["properties"][0]["method"], "k-induction", "{v}");
    assert_eq!(v["properties"][2]["method"], "explicit", "{v}");
    // So does a memory budget too small.
    let out = alba(&d, &["verify", ".", "--json", "--max-mb", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(json(&out)["properties"][2]["reason"].as_str().unwrap().contains("MB"));
    // Text output names the reason.
    let out = alba(&d, &["verify", ".", "--max-states", "3"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("budget"));
    // A bad expression: the place and the message, exit 2.
    std::fs::write(
        d.join("properties.toml"),
        "[[property]]\nname = \"x\"\nnever = \"Fwd AND Nope\"\n",
    )
    .unwrap();
    let out = alba(&d, &["verify", "."]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("Nope") && err.contains("properties.toml:3"), "{err}");
    std::fs::remove_file(d.join("properties.toml")).unwrap();
    let out = alba(&d, &["verify", "."]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn the_examples_properties_are_proved() {
    for ex in [
        "start-stop",
        "star-delta",
        "traffic-light",
        "tank",
        "state-net-batch",
        "festo-station",
        "sfc-batch",
        "st-motor",
        "plc8051-latch",
        "plc8051-pulse-relay",
        "plc8051-tank",
    ] {
        let d = scratch(&format!("verify-example-{ex}"));
        let out_dir = d.join("cex");
        let out = alba(
            &repo(),
            &[
                "verify",
                &format!("examples/{ex}"),
                "--json",
                "--out",
                out_dir.to_str().unwrap(),
            ],
        );
        let v = json(&out);
        for p in v["properties"].as_array().expect("properties") {
            assert_eq!(p["result"], "proved", "{ex}: {p}");
        }
        assert_eq!(out.status.code(), Some(0), "{ex}");
    }
}

fn junit_cases(path: &Path) -> (Vec<String>, Vec<String>) {
    let xml = std::fs::read_to_string(path).expect("junit written");
    let mut r = quick_xml::Reader::from_str(&xml);
    let (mut cases, mut failures) = (Vec::new(), Vec::new());
    loop {
        match r.read_event().expect("well-formed JUnit XML") {
            Event::Eof => break,
            Event::Start(e) | Event::Empty(e) => {
                let attr = |k: &str| {
                    e.try_get_attribute(k)
                        .expect("attribute")
                        .map(|a| a.unescape_value().expect("value").into_owned())
                        .unwrap_or_default()
                };
                match e.name().as_ref() {
                    b"testcase" => cases.push(attr("name")),
                    b"failure" => failures.push(attr("message")),
                    _ => {}
                }
            }
            _ => {}
        }
    }
    (cases, failures)
}

#[test]
fn test_runs_tables_with_exit_codes_junit_and_coverage() {
    let d = scratch("test-tables");
    project(&d, GOOD, PROPS);
    std::fs::create_dir(d.join("tests")).unwrap();
    std::fs::write(
        d.join("tests/forward.test.csv"),
        "time_ms,FwdBtn,RevBtn,expect:Fwd,expect:Rev\n0,1,0,1,0\n10,0,1,1,0\n300,,,1,\n",
    )
    .unwrap();
    let junit = d.join("junit.xml");
    let out = alba(&d, &["test", ".", "--junit", junit.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("coverage: "), "{stdout}");
    assert_eq!(junit_cases(&junit), (vec!["forward".to_string()], vec![]));
    // A second table that fails: exit 1, the failure names its first wrong cell.
    std::fs::write(
        d.join("tests/reverse.test.csv"),
        "time_ms,RevBtn,expect:Rev,expect:Fwd\n0,1,1,0\n10,0,0,0\n",
    )
    .unwrap();
    let out = alba(&d, &["test", ".", "--junit", junit.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let (cases, failures) = junit_cases(&junit);
    assert_eq!(cases, ["forward", "reverse"]);
    assert_eq!(failures, ["line 3, t = 10 ms: expect:Rev is 1, expected 0"]);
    // No tables at all: exit 2.
    std::fs::remove_dir_all(d.join("tests")).unwrap();
    assert_eq!(alba(&d, &["test", "."]).status.code(), Some(2));
}

#[test]
fn the_examples_tables_pass() {
    for ex in [
        "start-stop",
        "star-delta",
        "plc8051-latch",
        "plc8051-pulse-relay",
        "plc8051-tank",
    ] {
        let out = alba(&repo(), &["test", &format!("examples/{ex}")]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{ex}: {}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
}
