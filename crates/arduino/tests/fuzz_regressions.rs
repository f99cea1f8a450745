//! Inputs of the fuzz targets `bytecode_decode` (`.bin`) and `ihex_read`
//! (`.hex`) — seeds, and any input the fuzzer reported — kept under
//! `tests/fuzz_regressions/`; each runs through the target's checks
//! (`common/fuzz.rs`) in a child process (this test binary, re-run with
//! `ALBA_FUZZ_CASE` set), so a crash or a hang names its file. See
//! `tests/fuzz_regressions/README.md`.

#[path = "common/fuzz.rs"]
mod fuzz;

use std::path::Path;

fn run_case(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    match path.extension().and_then(|e| e.to_str()) {
        Some("bin") => fuzz::bytecode_input(&bytes),
        Some("hex") => fuzz::ihex_input(&bytes),
        _ => Err("a .bin (byte code) or a .hex (Intel HEX) file".into()),
    }
}

#[test]
fn child_case() {
    alba_testkit::child_case(run_case);
}

#[test]
fn every_fuzz_regression_input_passes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    alba_testkit::every_case_passes(&dir, "child_case");
}
