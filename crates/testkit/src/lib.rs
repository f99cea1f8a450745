//! Test support shared by the crates' integration tests.
//!
//! **Fuzz regressions.** A folder of inputs that crashed (or nearly crashed)
//! a parser runs one input per child process — the test binary itself, re-run
//! for one test with [`CASE_ENV`] naming the file — so a stack overflow or an
//! endless loop in one case is reported with its file name instead of
//! killing or hanging the whole run. A crate's test module holds two tests:
//!
//! ```text
//! #[test]
//! fn child_case() {
//!     alba_testkit::child_case(run_case); // does nothing in the parent run
//! }
//!
//! #[test]
//! fn every_fuzz_regression_input_passes() {
//!     alba_testkit::every_case_passes(&dir, "fuzz_regressions::child_case");
//! }
//! ```

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The variable naming the input a child runs.
pub const CASE_ENV: &str = "ALBA_FUZZ_CASE";

/// A child still running after this is taken for an endless loop (a safety
/// net against hangs, not a speed check).
const TIME_LIMIT: Duration = Duration::from_secs(20);

/// The child side: runs `run` on the file [`CASE_ENV`] names, panicking with
/// its error; does nothing when the variable is not set.
pub fn child_case(run: impl Fn(&Path) -> Result<(), String>) {
    if let Ok(path) = std::env::var(CASE_ENV)
        && let Err(e) = run(Path::new(&path))
    {
        panic!("{e}");
    }
}

/// The input files of `dir` (everything but its README), sorted.
pub fn cases(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.file_name().is_some_and(|n| n != "README.md"))
        .collect();
    v.sort();
    v
}

/// Runs one case in a child running test `child_test`; `Err` with what went wrong.
fn in_child(path: &Path, child_test: &str) -> Result<(), String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .args([child_test, "--exact", "--nocapture", "--test-threads=1"])
        .env(CASE_ENV, path)
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

/// The parent side: runs every input of `dir` in a child running the test
/// `child_test` (its path in the test binary) and fails listing those that fail.
pub fn every_case_passes(dir: &Path, child_test: &str) {
    let cases = cases(dir);
    assert!(!cases.is_empty(), "no inputs in {}", dir.display());
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|p| {
            in_child(p, child_test)
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

pub mod mcc;
pub mod mqtt;
pub mod pg;
