//! Every fixture imports, loads and compiles with zero errors through the
//! workspace's own compiler, and matches its golden project.

use alba_import::{Format, Kind, Options};
use std::fs;
use std::path::{Path, PathBuf};

fn fixtures(dir: &str) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(dir);
    let mut v: Vec<PathBuf> = fs::read_dir(&root)
        .expect("fixtures folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e != "md"))
        .collect();
    v.sort();
    v
}

/// Imports `input` with `opts` and checks the project with alba-compiler.
fn import_and_check(input: &Path, opts: &Options) -> (alba_import::Report, tempfile::TempDir) {
    let tmp = tempfile::tempdir().expect("temp dir");
    let out = tmp.path().join("project");
    let report = alba_import::import(input, &out, opts).unwrap_or_else(|e| panic!("{}: {e}", input.display()));
    let c = alba_load::compile_dir(&out);
    if c.program.is_none() || !c.diagnostics.is_empty() {
        let mut msg = String::new();
        for d in &c.diagnostics {
            msg.push_str(&d.short(c.files()));
            msg.push('\n');
        }
        for (f, _) in [("alba.toml", 0), ("tags.csv", 0), ("main.lad", 0)] {
            msg.push_str(&format!(
                "--- {f}\n{}\n",
                fs::read_to_string(out.join(f)).unwrap_or_default()
            ));
        }
        panic!("{} does not compile:\n{msg}", input.display());
    }
    (report, tmp)
}

/// Every file under `dir`, by its path relative to `dir` (`hmi/x.json`).
fn tree(dir: &Path, rel: &str, out: &mut Vec<(String, String)>) {
    for e in fs::read_dir(dir.join(rel)).expect("project").flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let path = if rel.is_empty() { name } else { format!("{rel}/{name}") };
        if e.path().is_dir() {
            tree(dir, &path, out);
        } else {
            out.push((path, fs::read_to_string(e.path()).expect("read")));
        }
    }
}

/// Compares the generated files with tests/golden/<format>/<fixture>/, or
/// writes them there with ALBA_BLESS=1.
fn golden(format: &str, input: &Path, project: &Path, report: &alba_import::Report) {
    let stem = input.file_stem().and_then(|s| s.to_str()).unwrap_or("x");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format)
        .join(stem);
    let mut files: Vec<(String, String)> = Vec::new();
    tree(project, "", &mut files);
    let text = report.render().replace(
        &format!("{}:", input.file_name().and_then(|s| s.to_str()).unwrap_or("")),
        "",
    );
    files.push(("report.txt".into(), text));
    files.sort();
    if std::env::var_os("ALBA_BLESS").is_some() {
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("golden dir");
        for (n, t) in &files {
            if let Some(parent) = dir.join(n).parent() {
                fs::create_dir_all(parent).expect("golden dir");
            }
            fs::write(dir.join(n), t).expect("write golden");
        }
        return;
    }
    let mut want_files = Vec::new();
    tree(&dir, "", &mut want_files);
    want_files.sort();
    let names = |v: &[(String, String)]| v.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(
        names(&files),
        names(&want_files),
        "{}: the files differ from {}",
        input.display(),
        dir.display()
    );
    for (n, t) in &files {
        let want = fs::read_to_string(dir.join(n))
            .unwrap_or_else(|_| panic!("no golden {}/{n}; run with ALBA_BLESS=1", dir.display()));
        assert_eq!(
            t,
            &want,
            "{} differs from its golden {}/{n}",
            input.display(),
            dir.display()
        );
    }
}

fn run_all(format: &str, fmt: Format, board: Option<&str>) -> (usize, usize) {
    let mut rungs = 0;
    let mut n = 0;
    for f in fixtures(format) {
        let opts = Options {
            format: Some(fmt),
            board: board.map(str::to_string),
            force: false,
        };
        let (report, tmp) = import_and_check(&f, &opts);
        assert_eq!(report.format, Some(fmt));
        golden(
            &format!("{format}{}", board.map(|b| format!("-{b}")).unwrap_or_default()),
            &f,
            &tmp.path().join("project"),
            &report,
        );
        rungs += report.rungs;
        n += 1;
    }
    (n, rungs)
}

#[test]
fn ldmicro_fixtures_import_and_compile() {
    let (n, rungs) = run_all("ldmicro", Format::Ldmicro, None);
    assert!(n >= 10, "{n} fixtures");
    assert!(rungs > 50, "{rungs} rungs");
}

#[test]
fn ldmicro_fixtures_on_an_uno() {
    run_all("ldmicro", Format::Ldmicro, Some("uno"));
}

#[test]
fn ldmicro_fixtures_on_a_mega() {
    run_all("ldmicro", Format::Ldmicro, Some("mega"));
}

#[test]
fn ldmicro_master_relay_is_refused_with_its_place() {
    let f = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/ldmicro/MasterRelay-Test.ld");
    let (report, _tmp) = import_and_check(&f, &Options::default());
    let refused: Vec<String> = report
        .entries
        .iter()
        .filter(|e| e.kind == Kind::Refused)
        .map(|e| e.to_string())
        .collect();
    assert_eq!(
        refused.first().map(String::as_str),
        Some(
            "MasterRelay-Test.ld:20:3: refused: LDmicro's MASTER_RELAY has no Alba conversion (the rungs it governs run unconditioned): the rung of line 18 is left out"
        )
    );
}

#[test]
fn plcopen_fixtures_import_and_compile() {
    let (n, rungs) = run_all("plcopen", Format::Plcopen, None);
    assert!(n >= 2, "{n} fixtures");
    assert!(rungs >= 20, "{rungs} rungs");
}

#[test]
fn l5x_fixtures_import_and_compile() {
    let (n, rungs) = run_all("l5x", Format::L5x, None);
    assert!(n >= 2, "{n} fixtures");
    assert!(rungs >= 8, "{rungs} rungs");
}

/// The AuroraLD fixture folders (`tests/fixtures/aurora/<project>/`).
fn aurora_folders() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/aurora");
    let mut v: Vec<PathBuf> = fs::read_dir(&root)
        .expect("fixtures folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    v.sort();
    v
}

#[test]
fn aurora_folders_import_and_check() {
    let mut n = 0;
    for dir in aurora_folders() {
        let opts = Options::default();
        let (report, tmp) = import_and_check(&dir, &opts);
        assert_eq!(report.format, Some(Format::Aurora));
        let out = tmp.path().join("project");
        // What `alba check` checks beyond the programs: alarms.csv and the screens.
        let c = alba_load::compile_dir(&out);
        let program = c.program.as_ref().expect("compiled");
        let mut files = c.project.files.clone();
        let alarms = alba_alarms::def::load(&out, &mut files, &program.layout)
            .unwrap_or_else(|d| panic!("alarms.csv: {}", d.iter().map(|d| d.short(&files)).collect::<String>()));
        let ids: Vec<String> = alarms.into_iter().map(|a| a.id).collect();
        let (screens, bad) = alba_compiler::screens::check_dir(&out, &mut files, &program.layout, &ids);
        assert!(
            bad.is_empty(),
            "{}",
            bad.iter().map(|d| d.short(&files)).collect::<String>()
        );
        assert!(screens >= 1, "{}: no screen", dir.display());
        golden("aurora", &dir, &out, &report);
        n += 1;
    }
    assert!(n >= 1);
}
