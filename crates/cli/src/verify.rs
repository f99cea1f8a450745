//! `alba verify` and `alba test` (SPEC §10.6, docs/verify.md), over `alba-verify`.

use crate::report;
use alba_diag::{Code, Diagnostic, Files};
use alba_model::fsutil;
use alba_verify::project;
use alba_verify::table::{self, TestResult};
use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

/// What `alba verify` was asked.
pub struct VerifyArgs {
    pub json: bool,
    pub options: project::Options,
}

fn code(n: u8) -> ExitCode {
    ExitCode::from(n)
}

pub fn verify(dir: &Path, a: VerifyArgs) -> ExitCode {
    let json = a.json;
    let mut print = |r: &project::Report, scan_ms: u64| {
        if json {
            return;
        }
        let until = u64::from(r.depth.saturating_sub(1)) * scan_ms;
        if r.method == "k-induction" {
            println!(
                "{:<8} {}  (k-induction, k = {}, {} SAT calls, {} ms)",
                r.result, r.name, r.depth, r.sat_calls, r.millis
            );
        } else {
            println!(
                "{:<8} {}  ({} states, depth {} scans, {} ms)",
                r.result, r.name, r.states, r.depth, r.millis
            );
        }
        if let Some(why) = &r.reason {
            println!("         {why}");
        }
        for (what, f) in [("counterexample", &r.counterexample), ("witness", &r.witness)] {
            if let Some(f) = f {
                println!(
                    "         {what}: {f} (alba sim {} --stimulus {f} --until {until})",
                    dir.display()
                );
            }
        }
    };
    match project::verify(dir, &a.options, &mut print) {
        Err(f) => {
            report(&f.diagnostics, &f.files, false);
            code(2)
        }
        Ok(reports) => {
            if json {
                println!("{}", serde_json::json!({ "properties": reports }));
            }
            code(project::exit_status(&reports))
        }
    }
}

pub fn test(dir: &Path, junit: Option<&Path>) -> ExitCode {
    let c = alba_load::compile_dir(dir);
    let Some(program) = c.program else {
        report(&c.diagnostics, &c.project.files, false);
        return code(2);
    };
    let scan_ms = c.project.scan_ms() as u64;
    let program = Arc::new(program);
    let (cases, cov) = match table::run_dir(dir, &program, scan_ms) {
        Ok(r) => r,
        Err(msg) => {
            report(&[Diagnostic::unplaced(Code::Io, msg.to_string())], &Files::new(), false);
            return code(2);
        }
    };
    let mut failed = 0;
    for t in &cases {
        match &t.result {
            TestResult::Passed { checks } => {
                println!("ok     {}  ({checks} checks, {} scans)", t.name, t.scans)
            }
            TestResult::Failed(m) => {
                failed += 1;
                println!("FAILED {}  {}: {}", t.name, t.file, table::describe(m));
            }
            TestResult::Error(e) => {
                failed += 1;
                println!("ERROR  {}  {e}", t.name);
            }
        }
    }
    println!("{} passed, {failed} failed", cases.len() - failed);
    print!("{}", cov.report(&program));
    if let Some(path) = junit {
        let name = c.project.config.as_ref().map_or_else(
            || {
                dir.file_name()
                    .map_or("project".into(), |n| n.to_string_lossy().into_owned())
            },
            |cfg| cfg.name.clone(),
        );
        let xml = table::junit(&name, &cases);
        if let Err(e) = fsutil::write_atomic(path, |w| w.write_all(xml.as_bytes())) {
            eprintln!("error[{}]: cannot write {}: {e}", Code::Io, path.display());
            return code(2);
        }
    }
    if failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
