//! Inputs that crashed (or nearly crashed) the AWL parser or checker, and
//! hand-written tricky ones, kept under `tests/fuzz_regressions/`. Each file
//! runs in a child process (this test binary, re-run with `ALBA_FUZZ_CASE`
//! set), so a stack overflow or an endless loop in one case is reported with
//! its file name instead of killing or hanging the whole run.
//!
//! Every file, whatever its extension, runs through the checks of
//! `check::awl_input` (parse, diagnostic and program spans, diagnostics
//! render) and `check::check_and_lower` (checker and lowering against a
//! small tag table, `Program::verify` when there is no diagnostic). Every
//! case must pass (a case that fails is a bug still to fix: see
//! `tests/fuzz_regressions/README.md`).

use crate::check::{awl_input, check_and_lower};
use alba_diag::Files;
use std::path::Path;

/// Runs `src` through the parser checks, then renders its diagnostics.
fn awl(src: &str) -> Result<(), String> {
    let diags = awl_input(src)?;
    let mut files = Files::new();
    files.add("main.awl", src);
    for d in &diags {
        let _ = d.short(&files);
        let _ = d.render(&files);
    }
    Ok(())
}

fn run_case(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    // Fuzz inputs are UTF-8 (the targets skip the rest); a lossy decode
    // keeps a case useful if an editor ever touches its bytes.
    let src = String::from_utf8_lossy(&bytes);
    awl(&src).and_then(|()| check_and_lower(&src).map(drop))
}

#[test]
fn child_case() {
    alba_testkit::child_case(run_case);
}

#[test]
fn every_fuzz_regression_input_passes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    alba_testkit::every_case_passes(&dir, "fuzz_regressions::child_case");
}
