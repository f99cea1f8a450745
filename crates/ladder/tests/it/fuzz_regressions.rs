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
use std::path::Path;

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

#[test]
fn child_case() {
    alba_testkit::child_case(run_case);
}

#[test]
fn every_fuzz_regression_input_passes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    alba_testkit::every_case_passes(&dir, "fuzz_regressions::child_case");
}
