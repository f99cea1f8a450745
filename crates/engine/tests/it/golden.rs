//! Golden traces: every folder under `tests/golden/` is a project with a
//! `stimulus.csv`, the simulation arguments in `golden.args` and the
//! expected trace in `golden.csv`. `ALBA_BLESS=1 cargo test` rewrites the
//! traces; review every change (`git diff`) before committing it.

use crate::util::{MODES, compile, simulate_in};
use std::path::{Path, PathBuf};

/// The options of `alba sim` a golden case uses.
pub struct Args {
    pub until: u64,
    pub every: Option<u64>,
    pub tags: Option<String>,
}

pub fn parse_args(text: &str) -> Args {
    let mut args = Args {
        until: 0,
        every: None,
        tags: None,
    };
    let mut it = text.split_whitespace();
    while let Some(k) = it.next() {
        let v = it.next().unwrap_or_else(|| panic!("golden.args: {k} needs a value"));
        match k {
            "--until" => args.until = v.parse().expect("--until is a number"),
            "--every" => args.every = Some(v.parse().expect("--every is a number")),
            "--tags" => args.tags = Some(v.to_string()),
            _ => panic!("golden.args: unknown option {k}"),
        }
    }
    args
}

fn cases() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("tests/golden exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("golden.args").exists())
        .collect();
    dirs.sort();
    dirs
}

#[test]
fn every_golden_trace_matches() {
    let bless = std::env::var_os("ALBA_BLESS").is_some();
    let mut failures = Vec::new();
    let cases = cases();
    assert!(cases.len() >= 10, "expected the golden cases, found {}", cases.len());
    for dir in cases {
        let args = parse_args(&std::fs::read_to_string(dir.join("golden.args")).expect("golden.args"));
        let program = compile(&dir);
        let scan_ms = alba_load::load(&dir).0.scan_ms() as u64;
        let stimulus = std::fs::read_to_string(dir.join("stimulus.csv")).unwrap_or_default();
        let times = (scan_ms, args.until, args.every.unwrap_or(scan_ms));
        let golden = dir.join("golden.csv");
        let want = std::fs::read_to_string(&golden).unwrap_or_default();
        // Every way the engine runs a program must give the golden trace.
        for mode in MODES {
            let got = simulate_in(mode, program.clone(), &stimulus, args.tags.as_deref(), times);
            if bless {
                std::fs::write(&golden, &got).expect("write golden");
                break;
            }
            if got != want {
                let diff: Vec<String> = want
                    .lines()
                    .zip(got.lines())
                    .filter(|(a, b)| a != b)
                    .take(5)
                    .map(|(a, b)| format!("  want {a}\n  got  {b}"))
                    .collect();
                failures.push(format!("{} ({mode:?}):\n{}", dir.display(), diff.join("\n")));
            }
        }
    }
    assert!(failures.is_empty(), "golden traces differ:\n{}", failures.join("\n"));
}
