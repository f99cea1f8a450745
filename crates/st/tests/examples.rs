//! The `st-motor` example (Structured Text) against the `start-stop`
//! example (Ladder): one stimulus, the same trace of every shared signal,
//! in every engine mode; and its own golden trace (`golden.csv`, as `alba
//! sim` writes it; `ALBA_BLESS=1` rewrites it).

use alba_diag::render_all;
use alba_engine::Engine;
use alba_engine::sim::{self, SimOptions, Stimulus};
use alba_ir::{Builder, Layout, Program};
use alba_project::Language;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

/// Compiles a one-program project (Ladder or ST) the way `alba` does.
fn compile(dir: &Path) -> Program {
    let (project, diags) = alba_load::load(dir);
    assert!(diags.is_empty(), "{}", render_all(&diags, &project.files));
    let mut tags = project.tags.clone();
    let mut diags = Vec::new();
    let src = &project.programs[0];
    let text = project.files.text(src.file);
    let program = match src.language {
        Language::St => {
            let (ast, d) = alba_st::parse(text, src.file);
            diags.extend(d);
            alba_st::declare(&ast, &mut tags, &mut diags);
            let mut b = Builder::new(Layout::new(&tags, &Default::default()));
            diags.extend(alba_st::compile(&ast, &src.name, &mut b));
            b.finish(project.files.clone())
        }
        _ => {
            let (ast, d) = alba_ladder::parse(text, src.file);
            diags.extend(d);
            let mut b = Builder::new(alba_ladder::layout_for(&tags, &[&ast]));
            diags.extend(alba_ladder::compile(
                &ast,
                text,
                &src.name,
                &mut b,
                &mut Default::default(),
            ));
            b.finish(project.files.clone())
        }
    };
    assert!(diags.is_empty(), "{}", render_all(&diags, &project.files));
    program
}

fn simulate(dir: &Path, tags: &str, native: bool) -> String {
    let prog = compile(dir);
    let mut files = alba_diag::Files::new();
    let text = std::fs::read_to_string(dir.join("stimulus.csv")).expect("stimulus");
    let f = files.add("stimulus.csv", text);
    let stim = Stimulus::parse(files.text(f), f, &prog.layout).unwrap_or_else(|d| panic!("{}", render_all(&d, &files)));
    let cols = sim::columns(tags, &prog.layout).unwrap_or_else(|d| panic!("{}", d[0]));
    let mut e = Engine::new(Arc::new(prog)).expect("verifies");
    if native {
        e.compile_native().expect("native");
    }
    let mut out = Vec::new();
    let opt = SimOptions {
        scan_ms: 10,
        until_ms: 10_000,
        every_ms: 50,
    };
    sim::run(&mut e, &stim, &cols, opt, &mut out).expect("runs");
    String::from_utf8(out).expect("utf-8")
}

/// The data rows of a trace (the header names differ: `Delay` / `Main.delay`).
fn rows(trace: &str) -> Vec<&str> {
    trace.lines().skip(1).collect()
}

#[test]
fn st_and_ladder_agree_on_the_start_stop_example() {
    let lad = simulate(
        &example("start-stop"),
        "Start,Stop,Motor,Delay.ACC,Delay.DN,Lamp",
        false,
    );
    for native in [false, true] {
        let st = simulate(
            &example("st-motor"),
            "Start,Stop,Motor,Main.delay.ACC,Main.delay.DN,Lamp",
            native,
        );
        assert_eq!(rows(&lad), rows(&st), "native: {native}");
    }
    // The trace is not trivial: the motor and the lamp both switch.
    let r = rows(&lad);
    assert!(
        r.iter()
            .any(|l| l.ends_with(",1,1,1,5000,1,1") || l.contains(",1,5000,1,1")),
        "{lad}"
    );
}

#[test]
fn st_motor_golden_trace() {
    let dir = example("st-motor");
    let args = std::fs::read_to_string(dir.join("golden.args")).expect("golden.args");
    let tags = args
        .split_whitespace()
        .skip_while(|a| *a != "--tags")
        .nth(1)
        .expect("--tags");
    let got = simulate(&dir, tags, false);
    let golden = dir.join("golden.csv");
    if std::env::var_os("ALBA_BLESS").is_some() {
        std::fs::write(&golden, &got).expect("write");
        return;
    }
    let want = std::fs::read_to_string(&golden).unwrap_or_default();
    assert_eq!(want, got, "{} differs (ALBA_BLESS=1 to accept)", golden.display());
}
