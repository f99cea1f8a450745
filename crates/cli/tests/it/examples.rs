//! `alba sim` on every example matches its golden traces. A case is
//! `golden.args` (the other options of `alba sim`) with `stimulus.csv` and
//! `golden.csv`, or, for an example with several cases,
//! `golden-<case>.args` with `stimulus-<case>.csv` and `golden-<case>.csv`.
//! `ALBA_BLESS=1` rewrites the traces (review the diff).

use crate::{alba, repo, scratch};
use std::path::{Path, PathBuf};

/// The cases of an example: (case name, args, stimulus, golden) files.
fn cases(dir: &Path) -> Vec<(String, PathBuf, PathBuf, PathBuf)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).expect("example folder") {
        let name = e.expect("directory entry").file_name().to_string_lossy().to_string();
        let Some(case) = name.strip_suffix(".args").and_then(|s| s.strip_prefix("golden")) else {
            continue;
        };
        out.push((
            case.trim_start_matches('-').to_string(),
            dir.join(&name),
            dir.join(format!("stimulus{case}.csv")),
            dir.join(format!("golden{case}.csv")),
        ));
    }
    out.sort();
    out
}

/// `got` must equal the golden file (rewritten instead with `ALBA_BLESS=1`).
fn check_golden(golden: &Path, got: &str, what: &str) {
    if std::env::var_os("ALBA_BLESS").is_some() {
        std::fs::write(golden, got).expect("write the golden file");
        return;
    }
    let want = std::fs::read_to_string(golden).unwrap_or_default();
    let first = want.lines().zip(got.lines()).find(|(a, b)| a != b);
    assert!(
        got == want,
        "{what}: output differs from {}; first difference: {first:?}",
        golden.display()
    );
}

/// Runs `alba sim` on an example with a stimulus and options, returning the trace.
pub fn simulate(dir: &Path, stimulus: &Path, args_text: &str, trace: &Path) -> String {
    let mut args = vec![
        "sim".to_string(),
        dir.display().to_string(),
        "--stimulus".into(),
        stimulus.display().to_string(),
        "--trace".into(),
        trace.display().to_string(),
    ];
    args.extend(args_text.split_whitespace().map(str::to_string));
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = alba(dir, &argv);
    assert!(
        out.status.success(),
        "{}: {}",
        dir.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read_to_string(trace).expect("alba sim wrote the trace")
}

#[test]
fn every_example_matches_its_golden_traces() {
    let root = repo().join("examples");
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    dirs.sort();
    let out_dir = scratch("examples");
    let mut checked = 0;
    for dir in &dirs {
        let name = dir.file_name().unwrap().to_string_lossy().to_string();
        for (case, args, stimulus, golden) in cases(dir) {
            let trace = out_dir.join(format!("{name}-{case}.csv"));
            let got = simulate(dir, &stimulus, &std::fs::read_to_string(&args).unwrap(), &trace);
            check_golden(&golden, &got, &format!("{name} {case}"));
            checked += 1;
        }
    }
    assert!(
        checked >= 7,
        "expected at least 7 golden traces of examples, found {checked}"
    );
}

#[test]
fn every_example_checks_clean() {
    for e in std::fs::read_dir(repo().join("examples")).unwrap() {
        let dir = e.unwrap().path();
        if !dir.join("alba.toml").exists() {
            continue;
        }
        let out = alba(&repo(), &["check", &dir.display().to_string()]);
        assert!(
            out.status.success(),
            "{}: {}",
            dir.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// The IR of every example, as `alba check --ir` prints it, against
/// `tests/ir/<example>.ir`: a change in lowering shows up here for review.
#[test]
fn every_example_lowers_to_its_golden_ir() {
    let golden_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/ir");
    let mut checked = 0;
    for e in std::fs::read_dir(repo().join("examples")).unwrap() {
        let dir = e.unwrap().path();
        if !dir.join("alba.toml").exists() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().to_string();
        let out = alba(&repo().join("examples"), &["check", &name, "--ir"]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let got = String::from_utf8(out.stdout).unwrap();
        check_golden(&golden_dir.join(format!("{name}.ir")), &got, &name);
        checked += 1;
    }
    assert!(checked >= 4);
}

/// The Festo program as published (`source-original.awl`) passes a bad part
/// on after a good one; the repaired `station.awl` rejects it.
#[test]
fn festo_station_source_program_shows_the_repaired_bug() {
    let example = repo().join("examples/festo-station");
    let dir = scratch("festo-original");
    for f in ["tags.csv", "plant.lad", "stimulus-good-then-bad.csv"] {
        std::fs::copy(example.join(f), dir.join(f)).unwrap();
    }
    let toml = "name = \"original\"\nprograms = [\"main.awl\"]\nplant = [\"plant.lad\"]\n";
    std::fs::write(dir.join("alba.toml"), toml).unwrap();
    std::fs::copy(example.join("source-original.awl"), dir.join("main.awl")).unwrap();
    let last_row = |trace: &str| trace.lines().last().unwrap_or_default().to_string();
    let args = "--until 14000 --every 100 --tags Measured,Delivered,Rejected";
    let stimulus = dir.join("stimulus-good-then-bad.csv");
    let original = simulate(&dir, &stimulus, args, &dir.join("original.csv"));
    assert_eq!(
        last_row(&original),
        "14000,228,2,0",
        "the source passes the 228 part on"
    );
    let repaired = simulate(&example, &stimulus, args, &dir.join("repaired.csv"));
    assert_eq!(last_row(&repaired), "14000,228,1,1", "station.awl rejects it");
}

/// The demo runs the tank's own program, unchanged, against its plant.
#[test]
fn tank_plant_runs_the_tank_program() {
    let read = |p: &str| std::fs::read_to_string(repo().join(p)).expect("read");
    assert_eq!(read("examples/tank-plant/main.lad"), read("examples/tank/main.lad"));
    let tags = read("examples/tank/tags.csv").replace("S_ULT,INT,AI:3/0,575,", "S_ULT,INT,AI:3/0,,");
    assert!(read("examples/tank-plant/tags.csv").starts_with(&tags));
}

/// An alarm means an abnormal situation (issue 30, point 2): the demo's plant
/// runs its normal cycle for 15 minutes of virtual time without one, while a
/// stop (the consumer drains the tank with pump B1 off) raises the low-level
/// alarm — so the limits are outside normal operation, not out of reach.
#[test]
fn the_demo_raises_no_alarm_in_normal_operation_and_one_when_stopped() {
    let dir = scratch("demo-alarms");
    let example = repo().join("examples/tank-plant");
    let events = |name: &str, stimulus: Option<&str>| {
        let out_file = dir.join(name);
        let mut args = vec![
            "sim".to_string(),
            example.display().to_string(),
            "--until".into(),
            "900000".into(),
            "--every".into(),
            "60000".into(),
            "--tags".into(),
            "Nivel_L".into(),
            "--alarms".into(),
            out_file.display().to_string(),
        ];
        if let Some(s) = stimulus {
            let f = dir.join(format!("{name}.stimulus.csv"));
            std::fs::write(&f, s).expect("stimulus");
            args.extend(["--stimulus".into(), f.display().to_string()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = crate::alba(&dir, &args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        std::fs::read_to_string(out_file).expect("events")
    };
    let normal = events("normal.csv", None);
    assert_eq!(
        normal.lines().count(),
        1,
        "no alarm in 15 minutes of normal operation:\n{normal}"
    );
    let stopped = events("stopped.csv", Some("time_ms,tag,value\n60000,STOP,1\n60200,STOP,0\n"));
    let activations: Vec<&str> = stopped
        .lines()
        .filter(|l| l.contains(",normal,active_unacked,"))
        .map(|l| l.split(',').nth(1).unwrap_or_default())
        .collect();
    assert_eq!(activations, ["estop", "level_lo"], "{stopped}");
}
