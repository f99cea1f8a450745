//! `alba sim` on every example matches its golden trace. Each example has
//! `stimulus.csv`, `golden.args` (the other options of `alba sim`) and
//! `golden.csv`; `ALBA_BLESS=1` rewrites the traces (review the diff).

use crate::{alba, repo, scratch};

#[test]
fn every_example_matches_its_golden_trace() {
    let root = repo().join("examples");
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    dirs.sort();
    let bless = std::env::var_os("ALBA_BLESS").is_some();
    let out_dir = scratch("examples");
    let mut checked = 0;
    for dir in dirs.iter().filter(|d| d.join("golden.args").exists()) {
        let name = dir.file_name().unwrap().to_string_lossy().to_string();
        let trace = out_dir.join(format!("{name}.csv"));
        let args_text = std::fs::read_to_string(dir.join("golden.args")).unwrap();
        let mut args = vec![
            "sim".to_string(),
            dir.display().to_string(),
            "--stimulus".into(),
            dir.join("stimulus.csv").display().to_string(),
            "--trace".into(),
            trace.display().to_string(),
        ];
        args.extend(args_text.split_whitespace().map(str::to_string));
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = alba(&root, &argv);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let got = std::fs::read_to_string(&trace).unwrap();
        if bless {
            std::fs::write(dir.join("golden.csv"), &got).unwrap();
        } else {
            let want = std::fs::read_to_string(dir.join("golden.csv")).unwrap_or_default();
            let first = want.lines().zip(got.lines()).find(|(a, b)| a != b);
            assert!(
                got == want,
                "{name}: trace differs from golden.csv; first difference: {first:?}"
            );
        }
        checked += 1;
    }
    assert!(
        checked >= 4,
        "expected at least 4 examples with golden traces, found {checked}"
    );
}

#[test]
fn every_example_checks_clean() {
    for e in std::fs::read_dir(repo().join("examples")).unwrap() {
        let dir = e.unwrap().path();
        if !dir.join("alba.toml").exists() {
            continue;
        }
        let out = alba(&repo(), &["check", &dir.display().to_string()]);
        assert!(
            out.status.success(),
            "{}: {}",
            dir.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// The IR of every example, as `alba check --ir` prints it, against
/// `tests/ir/<example>.ir`: a change in lowering shows up here for review.
#[test]
fn every_example_lowers_to_its_golden_ir() {
    let bless = std::env::var_os("ALBA_BLESS").is_some();
    let golden_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/ir");
    let mut checked = 0;
    for e in std::fs::read_dir(repo().join("examples")).unwrap() {
        let dir = e.unwrap().path();
        if !dir.join("alba.toml").exists() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().to_string();
        let out = alba(&repo().join("examples"), &["check", &name, "--ir"]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let got = String::from_utf8(out.stdout).unwrap();
        let golden = golden_dir.join(format!("{name}.ir"));
        if bless {
            std::fs::write(&golden, &got).unwrap();
        } else {
            let want = std::fs::read_to_string(&golden).unwrap_or_default();
            let first = want.lines().zip(got.lines()).find(|(a, b)| a != b);
            assert!(
                got == want,
                "{name}: IR differs from {}; first difference: {first:?}",
                golden.display()
            );
        }
        checked += 1;
    }
    assert!(checked >= 4);
}
