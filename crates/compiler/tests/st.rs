//! Structured Text in a project (SPEC §10.6): `.st` files beside Ladder and
//! AWL, run in the order of `alba.toml` in one scan, sharing the tags of
//! tags.csv by name; errors located in the `.st` file.

use alba_diag::Code;
use alba_engine::Engine;
use alba_ir::{Place, Target};
use alba_load::compile_dir;
use alba_model::Value;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn project(name: &str, tags: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-st-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch project");
    let programs: Vec<String> = files.iter().map(|(f, _)| format!("\"{f}\"")).collect();
    let toml = format!("name = \"{name}\"\nprograms = [{}]\n", programs.join(", "));
    std::fs::write(dir.join("alba.toml"), toml).expect("scratch project");
    std::fs::write(dir.join("tags.csv"), format!("name,type,address\n{tags}")).expect("scratch project");
    for (f, text) in files {
        std::fs::write(dir.join(f), text).expect("scratch project");
    }
    dir
}

fn place(e: &Engine, name: &str) -> Place {
    match e.program().layout.resolve(name) {
        Ok(Target::Value { place, .. }) => place,
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn st_runs_in_file_order_with_ladder_and_awl_on_shared_tags() {
    let dir = project(
        "mixed",
        "A,DINT,\nB,DINT,\nC,DINT,\nD,DINT,\nGo,BOOL,DI:1/0\n",
        &[
            ("first.lad", "XIC(Go)ADD(A,1,A);\n"),
            (
                "second.st",
                "PROGRAM Second\nVAR n : DINT; END_VAR\nn := n + 1;\nB := A * 10 + n;\nEND_PROGRAM\n\
                 PROGRAM Third\nC := B + 1;\nEND_PROGRAM\n",
            ),
            ("fourth.awl", "LD SM0.0\nMOVD C, D\n"),
        ],
    );
    let c = compile_dir(&dir);
    let prog = c
        .program
        .unwrap_or_else(|| panic!("{}", alba_diag::render_all(&c.diagnostics, &c.project.files)));
    let units: Vec<&str> = prog.units.iter().map(|u| u.name.as_str()).collect();
    assert_eq!(units, ["first.lad", "second.st", "fourth.awl"]);
    let mut e = Engine::new(Arc::new(prog)).expect("verifies");
    let go = place(&e, "Go");
    e.write(go, Value::Bool(true));
    for k in 0..3 {
        e.scan(k * 10).expect("scan");
    }
    // Each program sees what the ones before it wrote in the same scan.
    assert_eq!(e.read(place(&e, "A")), Value::Dint(3));
    assert_eq!(e.read(place(&e, "B")), Value::Dint(33));
    assert_eq!(e.read(place(&e, "C")), Value::Dint(34));
    assert_eq!(e.read(place(&e, "D")), Value::Dint(34));
    assert_eq!(e.read(place(&e, "Second.n")), Value::Dint(3));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn st_errors_are_located_in_the_st_file_and_stop_the_project() {
    let dir = project(
        "errors",
        "Level,REAL,\n",
        &[(
            "main.st",
            "PROGRAM Main\nVAR x : INT; END_VAR\nx := Levle;\nx := Level;\nEND_PROGRAM\n",
        )],
    );
    let c = compile_dir(&dir);
    assert!(c.program.is_none());
    let text = alba_diag::render_all(&c.diagnostics, &c.project.files);
    assert!(text.contains("main.st:3:6"), "{text}");
    assert!(text.contains("did you mean `Level`?"), "{text}");
    assert!(c.diagnostics.iter().any(|d| d.code == Code::StType), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_st_example_compiles() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/st-motor");
    let c = compile_dir(&dir);
    assert!(
        c.diagnostics.is_empty(),
        "{}",
        alba_diag::render_all(&c.diagnostics, &c.project.files)
    );
    let prog = c.program.expect("compiles");
    assert!(matches!(prog.layout.resolve("Main.delay"), Ok(Target::Timer(_))));
}

/// `tests/projects/st-library`: the PROGRAM of `main.st` calls a FUNCTION
/// and a FUNCTION_BLOCK of `lib.st` and uses its TYPEs (the other `.st`
/// files of a project are its library). Its trace (`golden.csv`, as `alba
/// sim` writes it with `golden.args`; `ALBA_BLESS=1` rewrites it) is the
/// same in the fused, monitored and native engine.
#[test]
fn a_program_calls_the_pous_of_another_st_file() {
    use alba_engine::sim::{self, SimOptions, Stimulus};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/projects/st-library");
    let c = compile_dir(&dir);
    let prog = c
        .program
        .unwrap_or_else(|| panic!("{}", alba_diag::render_all(&c.diagnostics, &c.project.files)));
    let args = std::fs::read_to_string(dir.join("golden.args")).expect("golden.args");
    let arg = |k: &str| {
        let mut it = args.split_whitespace().skip_while(|a| *a != k);
        it.nth(1).unwrap_or_else(|| panic!("golden.args: {k}")).to_string()
    };
    let mut files = alba_diag::Files::new();
    let f = files.add(
        "stimulus.csv",
        std::fs::read_to_string(dir.join("stimulus.csv")).expect("stimulus"),
    );
    let stim = Stimulus::parse(files.text(f), f, &prog.layout).expect("stimulus");
    let cols = sim::columns(&arg("--tags"), &prog.layout).expect("columns");
    let golden = dir.join("golden.csv");
    let want = std::fs::read_to_string(&golden).unwrap_or_default();
    for mode in ["fused", "monitored", "native"] {
        let mut e = Engine::new(Arc::new(prog.clone())).expect("verifies");
        match mode {
            "monitored" => e.set_monitor(true),
            "native" => e.compile_native().expect("native code"),
            _ => {}
        }
        let mut out = Vec::new();
        let opt = SimOptions {
            scan_ms: 10,
            until_ms: arg("--until").parse().expect("--until"),
            every_ms: arg("--every").parse().expect("--every"),
        };
        sim::run(&mut e, &stim, &cols, opt, &mut out).expect("runs");
        let got = String::from_utf8(out).expect("utf-8");
        if std::env::var_os("ALBA_BLESS").is_some() {
            std::fs::write(&golden, &got).expect("write golden");
            return;
        }
        assert_eq!(
            want,
            got,
            "{mode}: {} differs (ALBA_BLESS=1 to accept)",
            golden.display()
        );
    }
}

#[test]
fn a_pou_declared_in_two_st_files_is_an_error_in_the_later_one() {
    let dir = project(
        "dup",
        "N,INT,\n",
        &[
            (
                "a.st",
                "FUNCTION Twice : INT\nVAR_INPUT x : INT; END_VAR\nTwice := x * 2;\nEND_FUNCTION\n",
            ),
            (
                "b.st",
                "FUNCTION Twice : INT\nVAR_INPUT x : INT; END_VAR\nTwice := x + x;\nEND_FUNCTION\n\
                 PROGRAM Main\nN := Twice(3);\nEND_PROGRAM\n",
            ),
        ],
    );
    let c = compile_dir(&dir);
    assert!(c.program.is_none());
    let text = alba_diag::render_all(&c.diagnostics, &c.project.files);
    assert_eq!(c.diagnostics.len(), 1, "{text}");
    assert!(text.contains("`Twice` is declared in another file too"), "{text}");
    assert!(text.contains("b.st:1:10"), "{text}");
    assert!(text.contains("a.st:1:10"), "the note names the other file: {text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unknown_pou_of_the_library_is_located_with_did_you_mean() {
    let dir = project(
        "unknown-pou",
        "In,BOOL,\nN,INT,\n",
        &[
            (
                "lib.st",
                "FUNCTION_BLOCK Counter\nVAR_INPUT up : BOOL; END_VAR\nVAR_OUTPUT n : INT; END_VAR\n\
                 IF up THEN n := n + 1; END_IF;\nEND_FUNCTION_BLOCK\n",
            ),
            (
                "main.st",
                "PROGRAM Main\nVAR c : Countr; END_VAR\nc(up := In);\nN := c.n;\nEND_PROGRAM\n",
            ),
        ],
    );
    let c = compile_dir(&dir);
    assert!(c.program.is_none());
    let text = alba_diag::render_all(&c.diagnostics, &c.project.files);
    assert!(text.contains("main.st:2:9"), "{text}");
    assert!(text.contains("did you mean `Counter`?"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_errors_of_sfc_actions_and_conditions_in_st_are_located_in_the_chart() {
    let chart = "INITIAL_STEP Idle: Count(N); END_STEP\n\
                 STEP Run: END_STEP\n\
                 ACTION Count:\n    Levle := Level + 1;\n    Level := Twice(Level, 2);\nEND_ACTION\n\
                 TRANSITION FROM Idle TO Run := Level > 3; END_TRANSITION\n\
                 TRANSITION FROM Run TO Idle : Twice(Lvel) > 4 END_TRANSITION\n";
    let dir = project(
        "sfc-st-errors",
        "Level,INT,\n",
        &[
            ("chart.sfc", chart),
            (
                "lib.st",
                "FUNCTION Twice : INT\nVAR_INPUT x : INT; END_VAR\nTwice := x * 2;\nEND_FUNCTION\n",
            ),
        ],
    );
    let c = compile_dir(&dir);
    assert!(c.program.is_none());
    let text = alba_diag::render_all(&c.diagnostics, &c.project.files);
    // The unknown name with "did you mean", and a call of the library's
    // FUNCTION with one argument too many, each at its line of the chart.
    assert!(text.contains("chart.sfc:4:5"), "{text}");
    assert!(text.contains("did you mean `Level`?"), "{text}");
    assert!(text.contains("chart.sfc:5:"), "{text}");
    // A condition in ST: the unknown name at its place in the transition.
    assert!(text.contains("chart.sfc:8:37"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
    // Without END_ACTION: a syntax error of the chart.
    let dir = project(
        "sfc-st-unended",
        "Level,INT,\n",
        &[(
            "chart.sfc",
            "INITIAL_STEP Idle: Count(N); END_STEP\nACTION Count:\n    Level := 1;\n",
        )],
    );
    let c = compile_dir(&dir);
    let text = alba_diag::render_all(&c.diagnostics, &c.project.files);
    assert!(text.contains("the action is not ended by END_ACTION"), "{text}");
    assert!(c.diagnostics.iter().any(|d| d.code == Code::SfcSyntax), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two PROGRAMs of one name in two files would share their variables' tags:
/// refused at the later one, with a note at the first.
#[test]
fn programs_of_one_name_in_two_files_clash_on_their_variables() {
    let dir = project(
        "dup-prog",
        "N,INT,\n",
        &[
            ("a.st", "PROGRAM Main\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n"),
            ("b.st", "PROGRAM Main\nVAR x : INT; END_VAR\nx := 2;\nEND_PROGRAM\n"),
        ],
    );
    let c = compile_dir(&dir);
    assert!(c.program.is_none());
    let text = alba_diag::render_all(&c.diagnostics, &c.project.files);
    assert!(text.contains("the variable's tag `Main.x` already exists"), "{text}");
    assert!(text.contains("b.st:2:5") && text.contains("a.st:2:5"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `tests/projects/oscat-basic`: 17 OSCAT BASIC functions, unchanged (README
/// there: origin and licence), called from `main.st` with the examples of
/// their documentation; every engine mode gives the documented results.
#[test]
fn oscat_basic_functions_give_their_documented_results() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/projects/oscat-basic");
    let c = compile_dir(&dir);
    let prog = c
        .program
        .unwrap_or_else(|| panic!("{}", alba_diag::render_all(&c.diagnostics, &c.project.files)));
    let want: &[(&str, Value)] = &[
        ("even4", Value::Bool(true)),
        ("even7", Value::Bool(false)),
        ("fib10", Value::Dint(55)),
        ("fib46", Value::Dint(1_836_311_903)),
        ("fib47", Value::Dint(-1)),
        ("binom5_2", Value::Dint(10)),
        ("binom10_3", Value::Dint(120)),
        ("ceil_314", Value::Int(4)),
        ("ceil_m314", Value::Int(-3)),
        ("floor_314", Value::Int(3)),
        ("floor_m314", Value::Int(-4)),
        ("sgn_m35", Value::Int(-1)),
        ("sgn_0", Value::Int(0)),
        ("max3", Value::Real(5.0)),
        ("min3", Value::Real(1.0)),
        ("mid3", Value::Real(3.0)),
        ("hypot34", Value::Real(5.0)),
        ("modr55_25", Value::Real(0.5)),
        ("modr_x_0", Value::Real(0.0)),
        ("window_in", Value::Bool(true)),
        ("window_edge", Value::Bool(false)),
        ("inc1_seq[1]", Value::Int(1)),
        ("inc1_seq[2]", Value::Int(2)),
        ("inc1_seq[3]", Value::Int(0)),
        ("inc1_seq[4]", Value::Int(1)),
        ("cmp_same", Value::Bool(true)),
        ("cmp_differ", Value::Bool(false)),
    ];
    for mode in ["fused", "monitored", "native"] {
        let mut e = Engine::new(Arc::new(prog.clone())).expect("verifies");
        match mode {
            "monitored" => e.set_monitor(true),
            "native" => e.compile_native().expect("native code"),
            _ => {}
        }
        e.scan(0).expect("scan");
        for (name, v) in want {
            assert_eq!(e.read(place(&e, &format!("Main.{name}"))), *v, "{name} ({mode})");
        }
        // Within REAL's precision: DEG(π) is 180, EXP10(3) is 1000.
        let real = |e: &Engine, n: &str| match e.read(place(e, &format!("Main.{n}"))) {
            Value::Real(x) => x,
            other => panic!("{n}: {other:?}"),
        };
        assert!((real(&e, "deg_pi") - 180.0).abs() < 1e-3, "{mode}");
        assert!((real(&e, "exp10_3") - 1000.0).abs() < 1e-3, "{mode}");
    }
}
