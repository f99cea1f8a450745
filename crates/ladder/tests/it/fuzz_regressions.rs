//! Inputs that crashed (or nearly crashed) a parser, kept under
//! `tests/fuzz_regressions/`. Each file runs through the parsers in a child
//! process (this test binary, re-run with `ALBA_FUZZ_CASE` set), so a stack
//! overflow or an endless loop in one case is reported with its file name
//! instead of killing or hanging the whole run.
//!
//! By extension: `.lad` runs through the ladder checks of
//! `check::ladder_input` (parse, spans, round trip, diagnostics render)
//! and `check::check_and_lower` (checker and lowering against a tag table
//! with every type); `.cpt` through the CPT expression parser; `.csv` through
//! the tags.csv reader; `.toml` through the alba.toml reader; anything else
//! through every parser. Every case must pass (a case that fails is a parser bug
//! still to fix: see `tests/fuzz_regressions/README.md`).

use crate::check::check_and_lower;
use crate::robustness::{cpt, ladder, tags, toml};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const ENV: &str = "ALBA_FUZZ_CASE";
const TIME_LIMIT: Duration = Duration::from_secs(20);

fn run_case(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    // Fuzz inputs are UTF-8 (the targets skip the rest); a lossy decode
    // keeps a case useful if an editor ever touches its bytes.
    let src = String::from_utf8_lossy(&bytes);
    match path.extension().and_then(|e| e.to_str()) {
        Some("lad") => ladder(&src).and_then(|()| check_and_lower(&src).map(drop)),
        Some("cpt") => cpt(&src),
        Some("csv") => tags(&src),
        Some("toml") => toml(&src),
        _ => ladder(&src)
            .and_then(|()| cpt(&src))
            .and_then(|()| tags(&src))
            .and_then(|()| toml(&src)),
    }
}

/// The child side: does nothing unless `ALBA_FUZZ_CASE` names a file.
#[test]
fn child_case() {
    if let Ok(path) = std::env::var(ENV)
        && let Err(e) = run_case(Path::new(&path))
    {
        panic!("{e}");
    }
}

pub fn cases(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.file_name().is_some_and(|n| n != "README.md"))
        .collect();
    v.sort();
    v
}

/// Runs one case in a child process; `Err` with what went wrong.
fn in_child(path: &Path) -> Result<(), String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .args([
            "fuzz_regressions::child_case",
            "--exact",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(ENV, path)
        .env("RUST_BACKTRACE", "0")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {TIME_LIMIT:?} (endless loop?)"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    if status.success() {
        return Ok(());
    }
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut stderr);
    }
    let msg: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("note:"))
        .take(6)
        .collect();
    Err(format!("{status}: {}", msg.join("\n    ")))
}

#[test]
fn every_fuzz_regression_input_passes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let cases = cases(&dir);
    assert!(!cases.is_empty(), "no inputs in {}", dir.display());
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|p| {
            in_child(p)
                .err()
                .map(|e| format!("{}: {e}", p.file_name().unwrap_or_default().to_string_lossy()))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} fuzz regression inputs fail:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
