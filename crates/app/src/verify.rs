//! The studio's Verify & Test page (`POST /api/verify`, `POST /api/tests`):
//! alba-verify on the project as saved, as `alba verify` and `alba test` run
//! it, with every counterexample and witness replayed through the engine
//! scan by scan (tag values and power flow) for the page's time slider.

use alba_server::project::{diagnostics_json, unit_elements};
use alba_server::reply::{
    ProgramCoverage, PropertyResult, Replay, ReplayScan, StimulusRow, TestCaseResult, TestsReply, VerifyReply,
};
use alba_server::verify::{Verifier, VerifyError};
use alba_verify::explore::Budget;
use alba_verify::project::{self, Options};
use alba_verify::table::{self, TestResult};
use alba_verify::trace;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// The verification service of `alba run`, on the project folder.
pub struct Service {
    dir: PathBuf,
}

impl Service {
    pub fn new(dir: &Path) -> Service {
        Service { dir: dir.to_path_buf() }
    }
}

/// A fresh folder for one run's counterexample files (removed after).
fn scratch() -> PathBuf {
    static N: AtomicU64 = AtomicU64::new(0);
    std::env::temp_dir().join(format!(
        "alba-verify-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ))
}

/// Removes the scratch folder however the run ends.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn replay(program: &Arc<alba_ir::Program>, scan_ms: u64, file: &str, depth: u32) -> Result<Replay, VerifyError> {
    let text = std::fs::read_to_string(file).map_err(|e| VerifyError::Failed(format!("cannot read {file}: {e}")))?;
    let t = trace::trace(program, scan_ms, &text, depth.max(1)).map_err(|e| VerifyError::Failed(e.to_string()))?;
    Ok(Replay {
        rows: trace::rows(&text)
            .into_iter()
            .map(|(time_ms, tag, value)| StimulusRow { time_ms, tag, value })
            .collect(),
        violating_scan: (t.scans.len() as u32).saturating_sub(1),
        first_scan: t.first,
        tags: t.tags,
        scans: t
            .scans
            .into_iter()
            .map(|s| ReplayScan {
                time_ms: s.time_ms,
                values: s.values,
                on: s.on,
            })
            .collect(),
    })
}

fn compile(dir: &Path) -> Result<(Arc<alba_ir::Program>, u64), VerifyError> {
    let c = alba_load::compile_dir(dir);
    let scan_ms = c.project.scan_ms() as u64;
    match c.program {
        Some(p) => Ok((Arc::new(p), scan_ms)),
        None => Err(VerifyError::DoesNotCheck(diagnostics_json(
            &c.diagnostics,
            &c.project.files,
        ))),
    }
}

impl Verifier for Service {
    fn verify(&self, only: Option<&str>, seconds: u64) -> Result<VerifyReply, VerifyError> {
        if !self.dir.join("properties.toml").is_file() {
            return Err(VerifyError::NotFound("the project has no properties.toml".into()));
        }
        let out = Scratch(scratch());
        let options = Options {
            out: Some(out.0.clone()),
            only: only.map(str::to_string),
            budget: Budget {
                max_seconds: seconds,
                ..Budget::default()
            },
        };
        let reports = project::verify(&self.dir, &options, &mut |_, _| {})
            .map_err(|f| VerifyError::DoesNotCheck(diagnostics_json(&f.diagnostics, &f.files)))?;
        let (program, scan_ms) = compile(&self.dir)?;
        let replayed =
            |f: &Option<String>, depth| f.as_deref().map(|f| replay(&program, scan_ms, f, depth)).transpose();
        let properties = reports
            .iter()
            .map(|r| {
                Ok(PropertyResult {
                    name: r.name.clone(),
                    result: r.result.to_string(),
                    depth: r.depth,
                    states: r.states as u64,
                    millis: r.millis,
                    reason: r.reason.clone(),
                    method: r.method.to_string(),
                    counterexample: replayed(&r.counterexample, r.depth)?,
                    witness: replayed(&r.witness, r.depth)?,
                })
            })
            .collect::<Result<Vec<_>, VerifyError>>()?;
        Ok(VerifyReply {
            scan_ms: scan_ms as u32,
            properties,
        })
    }

    fn tests(&self) -> Result<TestsReply, VerifyError> {
        if !self.dir.join("tests").is_dir() {
            return Err(VerifyError::NotFound("the project has no tests folder".into()));
        }
        let (program, scan_ms) = compile(&self.dir)?;
        let (cases, cov) =
            table::run_dir(&self.dir, &program, scan_ms).map_err(|e| VerifyError::NotFound(e.to_string()))?;
        let tests: Vec<TestCaseResult> = cases
            .iter()
            .map(|c| {
                let (result, checks, message, line) = match &c.result {
                    TestResult::Passed { checks } => ("passed", *checks as u64, None, None),
                    TestResult::Failed(m) => ("failed", 0, Some(table::describe(m)), Some(m.line as u64)),
                    TestResult::Error(e) => ("error", 0, Some(e.clone()), None),
                };
                TestCaseResult {
                    name: c.name.clone(),
                    file: c.file.clone(),
                    result: result.into(),
                    checks,
                    message,
                    line,
                    scans: c.scans,
                    millis: c.millis as u64,
                }
            })
            .collect();
        let report = cov.report(&program);
        let coverage = unit_elements(&program)
            .into_iter()
            .zip(&program.units)
            .filter(|(range, _)| !range.is_empty())
            .map(|(range, unit)| {
                let of = |e: u32| cov.element(e as usize).unwrap_or((false, false));
                ProgramCoverage {
                    program: unit.name.clone(),
                    elements: range.clone().collect(),
                    powered: range.clone().filter(|&e| of(e).0).collect(),
                    always: range.filter(|&e| of(e) == (true, false)).collect(),
                }
            })
            .collect();
        let passed = tests.iter().filter(|t| t.result == "passed").count() as u64;
        Ok(TestsReply {
            passed,
            failed: tests.len() as u64 - passed,
            tests,
            rungs: report.rungs as u64,
            rungs_powered: report.rungs_powered as u64,
            branches: report.branches as u64,
            branches_powered: report.branches_powered as u64,
            instructions: report.instructions as u64,
            switched: report.switched as u64,
            rungs_never: report.rungs_never,
            never_switched: report.never_switched,
            coverage,
        })
    }
}
