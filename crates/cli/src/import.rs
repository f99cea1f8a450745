//! `alba import` and `alba export plcopen`: the command-line face of
//! `alba-import` (docs/interchange.md). The report goes to standard error, one
//! entry a line (`file:line:col: converted|approximated|refused: …`), then
//! a summary; a failed import writes nothing and exits 1 with E701.

use alba_diag::{Code, Diagnostic, Files};
use alba_import::{Format, Kind, Options};
use alba_model::fsutil;
use std::path::Path;
use std::process::ExitCode;

fn fail(code: Code, message: String) -> ExitCode {
    crate::report(&[Diagnostic::unplaced(code, message)], &Files::new(), false);
    ExitCode::FAILURE
}

pub fn run(file: &Path, out: &Path, format: Option<&str>, board: Option<String>, force: bool) -> ExitCode {
    let opts = Options {
        // clap allows only the formats' names.
        format: format.and_then(Format::parse),
        board,
        force,
    };
    let report = match alba_import::import(file, out, &opts) {
        Ok(r) => r,
        Err(e) => return fail(Code::ImportFailed, e.to_string()),
    };
    eprint!("{}", report.render());
    let format = report.format.map(|f| f.to_string()).unwrap_or_default();
    eprintln!(
        "imported {} ({format}) into {}: {} rungs, {} tags; {} converted, {} approximated, {} refused (docs/interchange.md)",
        file.display(),
        out.display(),
        report.rungs,
        report.tags,
        report.count(Kind::Converted),
        report.count(Kind::Approximated),
        report.count(Kind::Refused),
    );
    ExitCode::SUCCESS
}

pub fn export_plcopen(project: &Path, out: &Path) -> ExitCode {
    let (xml, report) = match alba_import::export::export_plcopen(project) {
        Ok(x) => x,
        Err(e) => return fail(Code::ImportFailed, e.to_string()),
    };
    if let Err(e) = fsutil::write_atomic(out, |w| w.write_all(xml.as_bytes())) {
        return fail(Code::Io, format!("cannot write {}: {e}", out.display()));
    }
    eprint!("{}", report.render());
    eprintln!(
        "wrote {} (PLCopen TC6 XML v2.01); {} refused",
        out.display(),
        report.count(Kind::Refused)
    );
    ExitCode::SUCCESS
}
