//! Inputs found by fuzzing (`fuzz/`, targets `tags_csv` and `alba_toml`)
//! or written as tricky seeds, kept under `tests/fuzz_regressions/`.
//! `.csv` files run through `TagTable::parse`, `.toml` files through
//! `Config::parse`, anything else through both. For each: no panic, every
//! diagnostic span inside the input on character boundaries, and every
//! diagnostic renders. Each file runs in a child process (this test binary
//! re-run with `ALBA_FUZZ_CASE` set), so a stack overflow or an endless loop
//! is reported with the file's name. Every case must pass; one that fails is
//! a bug still to fix (see `tests/fuzz_regressions/README.md`).

use alba_model::config::Config;
use alba_model::{Diagnostic, FileId, Files, TagTable};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const ENV: &str = "ALBA_FUZZ_CASE";
const TIME_LIMIT: Duration = Duration::from_secs(20);

fn spans(src: &str, file: FileId, diags: &[Diagnostic]) -> Result<(), String> {
    for d in diags {
        for l in d.primary.iter().chain(&d.secondary) {
            let (s, e) = (l.span.start as usize, l.span.end as usize);
            let what = format!("diagnostic {} `{}`", d.code, d.message);
            if l.span.file != file {
                return Err(format!("{what}: span in file {:?}, not {file:?}", l.span.file));
            }
            if s > e || e > src.len() {
                return Err(format!("{what}: span {s}..{e} outside the input (len {})", src.len()));
            }
            if !src.is_char_boundary(s) || !src.is_char_boundary(e) {
                return Err(format!("{what}: span {s}..{e} is not on character boundaries"));
            }
        }
    }
    Ok(())
}

fn render(src: &str, name: &str, diags: &[Diagnostic]) {
    let mut files = Files::new();
    files.add(name, src);
    for d in diags {
        let _ = d.short(&files);
        let _ = d.render(&files);
    }
}

fn tags(src: &str) -> Result<(), String> {
    let (_, diags) = TagTable::parse(src, FileId(0));
    spans(src, FileId(0), &diags)?;
    render(src, "tags.csv", &diags);
    Ok(())
}

fn toml(src: &str) -> Result<(), String> {
    let (_, diags) = Config::parse(src, FileId(0));
    if !diags.is_empty() {
        spans(src, FileId(0), &diags)?;
        render(src, "alba.toml", &diags);
    }
    Ok(())
}

fn run_case(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let src = String::from_utf8_lossy(&bytes);
    match path.extension().and_then(|e| e.to_str()) {
        Some("csv") => tags(&src),
        Some("toml") => toml(&src),
        _ => tags(&src).and_then(|()| toml(&src)),
    }
}

/// The child side: does nothing unless `ALBA_FUZZ_CASE` names a file.
#[test]
fn child_case() {
    if let Ok(path) = std::env::var(ENV)
        && let Err(e) = run_case(Path::new(&path))
    {
        panic!("{e}");
    }
}

fn cases(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.file_name().is_some_and(|n| n != "README.md"))
        .collect();
    v.sort();
    v
}

fn in_child(path: &Path) -> Result<(), String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .args([
            "fuzz_regressions::child_case",
            "--exact",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(ENV, path)
        .env("RUST_BACKTRACE", "0")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {TIME_LIMIT:?} (endless loop?)"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    if status.success() {
        return Ok(());
    }
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut stderr);
    }
    let msg: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("note:"))
        .take(6)
        .collect();
    Err(format!("{status}: {}", msg.join("\n    ")))
}

#[test]
fn every_fuzz_regression_input_passes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let cases = cases(&dir);
    assert!(!cases.is_empty(), "no inputs in {}", dir.display());
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|p| {
            in_child(p)
                .err()
                .map(|e| format!("{}: {e}", p.file_name().unwrap_or_default().to_string_lossy()))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} fuzz regression inputs fail:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
