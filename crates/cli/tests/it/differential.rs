//! Ladder and Instruction List agree: every folder under
//! `tests/differential/` holds one program written twice, `main.lad` and
//! `main.awl`, with one `tags.csv`, a `stimulus.csv` and `args` (the
//! `--until/--every/--tags` options of `alba sim`). Both are simulated with
//! the same stimulus and must give byte-identical traces, in which every
//! traced column changes at least once (so a broken program cannot pass by
//! doing nothing).
//!
//! Each case runs at the 10 ms scan its stimulus was written for, and once
//! more at 7 ms (tracing every scan) to catch timing that only agrees when
//! the scan period divides the timers' resolutions.

use crate::{alba, repo, scratch};
use std::path::{Path, PathBuf};

/// Fewer cases than this means the folder was not found or was emptied.
const MIN_CASES: usize = 8;

/// The scan periods every case runs at; the first is the one its stimulus
/// and `args` were written for, where the trace must also be non-trivial.
const SCANS_MS: [u32; 2] = [10, 7];

/// The two languages, by program file extension.
const LANGS: [&str; 2] = ["lad", "awl"];

struct Sim {
    trace: String,
    /// `N minor fault(s)` from the summary on stderr, if any.
    faults: Option<String>,
}

/// Writes a project of `case` for `lang` under `work` and simulates it.
fn simulate(case: &Path, lang: &str, scan_ms: u32, args: &[&str], work: &Path) -> Result<Sim, String> {
    let name = case.file_name().unwrap_or_default().to_string_lossy();
    let project = work.join(lang);
    std::fs::create_dir_all(&project).map_err(|e| format!("{}: {e}", project.display()))?;
    let program = format!("main.{lang}");
    std::fs::write(
        project.join("alba.toml"),
        format!("name = \"{name}-{lang}\"\nscan_ms = {scan_ms}\nprograms = [\"{program}\"]\n"),
    )
    .map_err(|e| e.to_string())?;
    for file in ["tags.csv", program.as_str()] {
        std::fs::copy(case.join(file), project.join(file)).map_err(|e| format!("{file}: {e}"))?;
    }
    let trace = work.join(format!("trace-{lang}.csv"));
    let (project_arg, stimulus, trace_arg) = (
        project.display().to_string(),
        case.join("stimulus.csv").display().to_string(),
        trace.display().to_string(),
    );
    let mut argv = vec!["sim", &project_arg, "--stimulus", &stimulus, "--trace", &trace_arg];
    argv.extend_from_slice(args);
    let out = alba(work, &argv);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(format!("`alba sim` failed on main.{lang}:\n{stderr}"));
    }
    let faults = stderr
        .split_once(" minor fault(s)")
        .map(|(before, _)| before.rsplit(' ').next().unwrap_or_default().to_string());
    let trace = std::fs::read_to_string(&trace).map_err(|e| format!("trace of main.{lang}: {e}"))?;
    Ok(Sim { trace, faults })
}

/// The first row where the two traces differ, for the failure message.
fn first_difference(lad: &str, awl: &str) -> String {
    let (mut l, mut a) = (lad.lines(), awl.lines());
    for row in 1.. {
        match (l.next(), a.next()) {
            (Some(x), Some(y)) if x == y => continue,
            (None, None) => break,
            (x, y) => {
                return format!(
                    "first difference at line {row}:\n      {}\n      lad: {}\n      awl: {}",
                    lad.lines().next().unwrap_or_default(),
                    x.unwrap_or("<end of trace>"),
                    y.unwrap_or("<end of trace>")
                );
            }
        }
    }
    "the traces differ".into()
}

/// The traced columns that never take a second value.
fn constant_columns(trace: &str) -> Vec<String> {
    let mut lines = trace.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    header
        .iter()
        .enumerate()
        .skip(1)
        .filter(|&(k, _)| {
            let mut values = rows.iter().map(|r| r.get(k).copied().unwrap_or_default());
            let first = values.next();
            values.all(|v| Some(v) == first)
        })
        .map(|(_, name)| name.to_string())
        .collect()
}

/// The options of `args` without `--every n` (for the extra scan period,
/// which traces every scan).
fn without_every(args: &[String]) -> Vec<&str> {
    let mut out = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--every" {
            it.next();
        } else if !a.starts_with("--every=") {
            out.push(a.as_str());
        }
    }
    out
}

/// Runs one case at every scan period; returns what went wrong.
fn check_case(case: &Path, work: &Path) -> Result<(), String> {
    for file in ["main.lad", "main.awl", "tags.csv", "stimulus.csv", "args"] {
        if !case.join(file).is_file() {
            return Err(format!("{file} is missing"));
        }
    }
    let args_text = std::fs::read_to_string(case.join("args")).map_err(|e| e.to_string())?;
    let args: Vec<String> = args_text.split_whitespace().map(str::to_string).collect();
    if !args.iter().any(|a| a == "--tags") || !args.iter().any(|a| a == "--until") {
        return Err("args must give --until and --tags".into());
    }
    for (pass, scan_ms) in SCANS_MS.into_iter().enumerate() {
        let argv: Vec<&str> = if pass == 0 {
            args.iter().map(String::as_str).collect()
        } else {
            without_every(&args)
        };
        let dir = work.join(format!("{scan_ms}ms"));
        let [lad, awl] = LANGS.map(|lang| simulate(case, lang, scan_ms, &argv, &dir));
        let (lad, awl) = (lad?, awl?);
        if lad.trace != awl.trace {
            return Err(format!(
                "at a {scan_ms} ms scan the traces differ ({}), {}",
                dir.display(),
                first_difference(&lad.trace, &awl.trace)
            ));
        }
        if lad.faults != awl.faults {
            return Err(format!(
                "at a {scan_ms} ms scan the minor faults differ: lad {:?}, awl {:?}",
                lad.faults, awl.faults
            ));
        }
        if pass == 0 {
            let constant = constant_columns(&lad.trace);
            if lad.trace.lines().count() < 3 || !constant.is_empty() {
                return Err(format!(
                    "the trace is trivial: these columns never change: {}",
                    constant.join(", ")
                ));
            }
        }
    }
    Ok(())
}

#[test]
fn ladder_and_awl_twins_give_identical_traces() {
    let root = repo().join("crates/cli/tests/differential");
    let mut cases: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap_or_else(|e| panic!("{}: {e}", root.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    cases.sort();
    let work = scratch("differential");
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|case| {
            let name = case.file_name().unwrap_or_default().to_string_lossy().to_string();
            check_case(case, &work.join(&name))
                .err()
                .map(|why| format!("  {name}: {why}"))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} differential case(s) failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
    assert!(
        cases.len() >= MIN_CASES,
        "expected at least {MIN_CASES} cases in {}, found {}",
        root.display(),
        cases.len()
    );
}
