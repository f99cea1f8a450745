//! Inputs found by the fuzz targets `import_ldmicro`, `import_plcopen`,
//! `import_l5x` and `import_aurora`, or written to guard the importers'
//! corners, kept under `tests/fuzz_regressions/`: each runs through
//! `alba_import::fuzz::check` (what the targets check) as the format its
//! extension names (`.ld`, `.xml`, `.L5X`, `.aurora`: an AuroraLD folder as
//! one text, each file after `==> name <==`), in a child process, so a
//! stack overflow or a hang is reported with the file's name. See
//! `tests/fuzz_regressions/README.md`.

use alba_import::Format;
use std::path::Path;

fn run_case(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let format = match ext.to_ascii_lowercase().as_str() {
        "ld" => Format::Ldmicro,
        "xml" => Format::Plcopen,
        "l5x" => Format::L5x,
        "aurora" => Format::Aurora,
        _ => {
            return Err(format!(
                "`.{ext}`: not an extension of a format (.ld .xml .L5X .aurora)"
            ));
        }
    };
    alba_import::fuzz::check(format, &bytes)
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
