//! `alba verify` and `alba test` (SPEC §10.6, docs/verify.md), over `alba-verify`.

use crate::report;
use alba_diag::{Code, Diagnostic, Files};
use alba_model::fsutil;
use alba_verify::explore::{self, Budget, Model, Outcome};
use alba_verify::table::{self, TestResult};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

/// What `alba verify` was asked.
pub struct VerifyArgs<'a> {
    pub json: bool,
    /// Where counterexamples go (default `<project>/counterexamples`).
    pub out: Option<&'a Path>,
    pub only: Option<&'a str>,
    pub budget: Budget,
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

fn code(n: u8) -> ExitCode {
    ExitCode::from(n)
}

pub fn verify(dir: &Path, a: VerifyArgs) -> ExitCode {
    let c = alba_compiler::compile_dir(dir);
    let Some(program) = c.program else {
        report(&c.diagnostics, &c.project.files, false);
        return code(2);
    };
    let scan_ms = c.project.scan_ms() as u64;
    let path = dir.join("properties.toml");
    let text = match alba_project::read_text(&path) {
        Ok(t) => t,
        Err(msg) => {
            report(&[Diagnostic::unplaced(Code::Io, msg)], &Files::new(), false);
            return code(2);
        }
    };
    let mut files = Files::new();
    let f = files.add(path.display().to_string(), text);
    let props = match alba_verify::props::parse(files.text(f), f, &program.layout) {
        Ok(p) => p,
        Err(d) => {
            report(&d, &files, false);
            return code(2);
        }
    };
    let selected: Vec<_> = props
        .properties
        .iter()
        .filter(|p| a.only.is_none_or(|n| n == p.name))
        .collect();
    if selected.is_empty() {
        let msg = match a.only {
            Some(n) => format!("properties.toml has no property named `{n}`"),
            None => "properties.toml has no [[property]]".to_string(),
        };
        report(&[Diagnostic::unplaced(Code::ConfigField, msg)], &files, false);
        return code(2);
    }
    let program = Arc::new(program);
    let model = Model::new(program.clone(), scan_ms, &props);
    let out_dir: PathBuf = a.out.map_or_else(|| dir.join("counterexamples"), Path::to_path_buf);
    let mut rows = Vec::new();
    let (mut refuted, mut unknown) = (false, false);
    let mut used = std::collections::HashSet::new();
    for p in selected {
        let v = explore::decide(&model, p, &props.assumes, a.budget);
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
            let written = std::fs::create_dir_all(&out_dir)
                .and_then(|()| fsutil::write_atomic(&target, |w| w.write_all(text.as_bytes())));
            if let Err(e) = written {
                eprintln!("error[{}]: cannot write {}: {e}", Code::Io, target.display());
                return code(2);
            }
            file = Some(target.display().to_string());
        }
        let (result, reason) = match &v.outcome {
            Outcome::Proved => ("proved", None),
            Outcome::Refuted => ("refuted", None),
            Outcome::Unknown(why) => ("unknown", Some(why.clone())),
        };
        refuted |= v.outcome == Outcome::Refuted;
        unknown |= matches!(v.outcome, Outcome::Unknown(_));
        let reachable = matches!(p.kind, alba_verify::props::Kind::Reachable(_));
        let (counterexample, witness) = match (&v.outcome, reachable) {
            (Outcome::Refuted, _) => (file.clone(), None),
            (Outcome::Proved, true) => (None, file.clone()),
            _ => (None, None),
        };
        if !a.json {
            let until = v.depth.saturating_sub(1) as u64 * scan_ms;
            println!(
                "{result:<8} {}  ({} states, depth {} scans, {} ms)",
                p.name, v.states, v.depth, v.millis
            );
            if let Some(r) = &reason {
                println!("         {r}");
            }
            if let Some(f) = &counterexample {
                println!(
                    "         counterexample: {f} (alba sim {} --stimulus {f} --until {until})",
                    dir.display()
                );
            }
            if let Some(f) = &witness {
                println!(
                    "         witness: {f} (alba sim {} --stimulus {f} --until {until})",
                    dir.display()
                );
            }
        }
        rows.push(serde_json::json!({
            "name": p.name,
            "result": result,
            "counterexample": counterexample,
            "witness": witness,
            "depth": v.depth,
            "states": v.states,
            "millis": v.millis as u64,
            "reason": reason,
        }));
    }
    if a.json {
        println!("{}", serde_json::json!({ "properties": rows }));
    }
    if refuted {
        code(1)
    } else if unknown {
        code(2)
    } else {
        ExitCode::SUCCESS
    }
}

pub fn test(dir: &Path, junit: Option<&Path>) -> ExitCode {
    let c = alba_compiler::compile_dir(dir);
    let Some(program) = c.program else {
        report(&c.diagnostics, &c.project.files, false);
        return code(2);
    };
    let scan_ms = c.project.scan_ms() as u64;
    let program = Arc::new(program);
    let (cases, cov) = match table::run_dir(dir, &program, scan_ms) {
        Ok(r) => r,
        Err(msg) => {
            report(&[Diagnostic::unplaced(Code::Io, msg)], &Files::new(), false);
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
