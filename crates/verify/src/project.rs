//! `alba verify` on a project folder: compile, read properties.toml, decide
//! each property, write counterexamples and witnesses. Shared by the command
//! line and the studio (crates/app/src/verify.rs), which only present the [`Report`]s.

use crate::explore::{self, Budget, Method, Model, Outcome};
use crate::props::{self, Kind};
use alba_diag::{Code, Diagnostic, Files};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What to decide and where to write.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Counterexamples go here (default `<project>/counterexamples`).
    pub out: Option<PathBuf>,
    /// Only the property with this name.
    pub only: Option<String>,
    pub budget: Budget,
}

/// The answer for one property, as `alba verify --json` prints it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Report {
    pub name: String,
    /// `proved`, `refuted` or `unknown`.
    pub result: &'static str,
    /// A refuted property's stimulus file.
    pub counterexample: Option<String>,
    /// A reachable property's witness stimulus file.
    pub witness: Option<String>,
    /// Scans of the counterexample or witness, else the depth searched.
    pub depth: u32,
    pub states: usize,
    pub millis: u64,
    /// Why `unknown`.
    pub reason: Option<String>,
    /// `explicit` (the search on the engine) or `k-induction` (SAT, induct.rs).
    pub method: &'static str,
    /// SAT queries made (k-induction is tried first on invariants).
    pub sat_calls: u32,
}

/// Why nothing could be decided: diagnostics over these files.
pub struct Failure {
    pub diagnostics: Vec<Diagnostic>,
    pub files: Files,
}

fn fail(files: Files, d: Vec<Diagnostic>) -> Failure {
    Failure { diagnostics: d, files }
}

/// A file-name-safe form of a property's name.
fn slug(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() { "property".into() } else { s }
}

/// Decides the properties of the project in `dir`. `each` sees every report
/// as soon as it is made (with the project's scan period), for progress.
pub fn verify(dir: &Path, opt: &Options, each: &mut dyn FnMut(&Report, u64)) -> Result<Vec<Report>, Failure> {
    let c = alba_load::compile_dir(dir);
    let scan_ms = c.project.scan_ms() as u64;
    let Some(program) = c.program else {
        return Err(fail(c.project.files, c.diagnostics));
    };
    let path = dir.join("properties.toml");
    let text = alba_compiler::project::read_text(&path)
        .map_err(|msg| fail(Files::new(), vec![Diagnostic::unplaced(Code::Io, msg.to_string())]))?;
    let mut files = Files::new();
    let f = files.add(path.display().to_string(), text);
    let props = match props::parse(files.text(f), f, &program.layout) {
        Ok(p) => p,
        Err(d) => return Err(fail(files, d)),
    };
    let selected: Vec<_> = props
        .properties
        .iter()
        .filter(|p| opt.only.as_ref().is_none_or(|n| *n == p.name))
        .collect();
    if selected.is_empty() {
        let msg = match &opt.only {
            Some(n) => format!("properties.toml has no property named `{n}`"),
            None => "properties.toml has no [[property]]".to_string(),
        };
        return Err(fail(files, vec![Diagnostic::unplaced(Code::ConfigField, msg)]));
    }
    let program = Arc::new(program);
    let model = Model::new(program, scan_ms, &props);
    let out_dir = opt.out.clone().unwrap_or_else(|| dir.join("counterexamples"));
    let mut used = HashSet::new();
    let mut reports = Vec::new();
    for p in selected {
        let v = explore::decide(&model, p, &props.assumes, opt.budget);
        let mut file = None;
        if let Some(run) = &v.run {
            // Two names with one file name (`a b`, `a_b`) get -2, -3...
            let mut stem = slug(&p.name);
            let mut k = 1;
            while !used.insert(stem.clone()) {
                k += 1;
                stem = format!("{}-{k}", slug(&p.name));
            }
            let target = out_dir.join(format!("{stem}.csv"));
            let text = explore::stimulus(&model, run);
            std::fs::create_dir_all(&out_dir)
                .and_then(|()| alba_model::fsutil::write_atomic(&target, |w| w.write_all(text.as_bytes())))
                .map_err(|e| {
                    let msg = format!("cannot write {}: {e}", target.display());
                    fail(Files::new(), vec![Diagnostic::unplaced(Code::Io, msg)])
                })?;
            file = Some(target.display().to_string());
        }
        let reachable = matches!(p.kind, Kind::Reachable(_));
        let (result, reason) = match &v.outcome {
            Outcome::Proved => ("proved", None),
            Outcome::Refuted => ("refuted", None),
            Outcome::Unknown(why) => ("unknown", Some(why.clone())),
        };
        let r = Report {
            name: p.name.clone(),
            result,
            counterexample: if v.outcome == Outcome::Refuted {
                file.clone()
            } else {
                None
            },
            witness: if reachable && v.outcome == Outcome::Proved {
                file
            } else {
                None
            },
            depth: v.depth,
            states: v.states,
            millis: v.millis as u64,
            reason,
            method: match v.method {
                Method::Explicit => "explicit",
                Method::Induction(_) => "k-induction",
            },
            sat_calls: v.sat_calls,
        };
        each(&r, scan_ms);
        reports.push(r);
    }
    Ok(reports)
}

/// The exit status of `alba verify`: 0 all proved, 1 any refuted, 2 otherwise.
pub fn exit_status(reports: &[Report]) -> u8 {
    if reports.iter().any(|r| r.result == "refuted") {
        1
    } else if reports.iter().all(|r| r.result == "proved") {
        0
    } else {
        2
    }
}
