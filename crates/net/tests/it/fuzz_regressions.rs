//! Inputs found by the fuzz target `pnml_load` or written to guard its
//! corners, kept under `tests/fuzz_regressions/`; each runs through
//! `check::pnml_input` in a child process (this test binary, re-run with
//! `ALBA_FUZZ_CASE` set), so a stack overflow or a hang is reported with the
//! file's name. See `tests/fuzz_regressions/README.md`.

use crate::check::pnml_input;
use std::path::Path;

fn run_case(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let src = String::from_utf8_lossy(&bytes);
    pnml_input(&src).map(drop)
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

#[test]
fn fixtures_and_malformed_inputs_pass_the_fuzz_checks() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    for dir in ["fixtures", "malformed", "malformed_coloured"] {
        for p in alba_testkit::cases(&root.join(dir)) {
            if p.extension().is_some_and(|e| e == "pnml") {
                let src = std::fs::read_to_string(&p).unwrap();
                if let Err(e) = pnml_input(&src) {
                    panic!("{}: {e}", p.display());
                }
            }
        }
    }
}
