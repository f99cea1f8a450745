//! What the board cannot run is refused with a precise message before any
//! build: a channel with no pin, LREAL; and, at build time, a program too
//! large for the board (E502).

use alba_arduino::sketch::{Target, control_program, generate};
use alba_model::board::{Model, PinMap};
use std::path::Path;

fn project(name: &str, tags: &str, main: &str) -> alba_ir::Program {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("refusals").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"{name}\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n"),
    )
    .expect("write");
    std::fs::write(
        dir.join("tags.csv"),
        format!("name,type,address,initial,retain,description\n{tags}"),
    )
    .expect("write");
    std::fs::write(dir.join("main.lad"), main).expect("write");
    let c = alba_load::compile_dir(&dir);
    c.program.unwrap_or_else(|| panic!("{name}: {:?}", c.diagnostics))
}

fn uno() -> Target {
    Target {
        model: Model::Uno,
        map: PinMap::preset("aurora").expect("preset"),
        active_low: false,
        scan_ms: 10,
        monitor: true,
        power_up_on: Vec::new(),
    }
}

fn messages(prog: &alba_ir::Program, t: &Target) -> Vec<String> {
    match generate(prog, "p", t) {
        Ok(_) => Vec::new(),
        Err(d) => d.iter().map(|d| format!("{}: {}", d.code, d.message)).collect(),
    }
}

#[test]
fn missing_pins_are_refused_on_the_tag_or_the_instruction() {
    let p = project(
        "pins",
        "Level,INT,AI:3/2,,,\nOut,BOOL,DO:2/0,,,\n",
        "GRT(Level,100)OTE(Out);\nXIC(Out)OTE(DO:2/7);\n",
    );
    let m = messages(&p, &uno());
    assert_eq!(
        m,
        [
            "E104: DO:2/7 is not wired: the pin map has 6 channels there (DO:2/0 to DO:2/5)",
            "E104: `Level`: AI:3/2 is pin A6, but the Arduino Uno has no pin A6 (A0-A5); A6 and A7 are on the Nano",
        ]
    );
    // The Nano has A6; channel 7 of DO is still unwired.
    let nano = Target {
        model: Model::Nano,
        ..uno()
    };
    assert_eq!(messages(&p, &nano).len(), 1);
}

#[test]
fn lreal_is_refused() {
    let p = project("lreal", "Total,LREAL,,,,\nIn,INT,AI:3/0,,,\n", "ADD(Total,In,Total);\n");
    let m = messages(&p, &uno());
    assert!(m.iter().any(|s| s.starts_with("E501: `Total` is an LREAL")), "{m:?}");
    assert!(
        m.iter()
            .any(|s| s.contains("LREAL (64-bit) arithmetic cannot run on the board")),
        "{m:?}"
    );
}

#[test]
fn plant_models_are_left_out() {
    let c = alba_load::compile_dir(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tank-plant"));
    let prog = c.program.expect("tank-plant compiles");
    let control = control_program(&prog);
    assert!(control.ops.len() < prog.ops.len());
    assert!(control.units.iter().all(|u| !u.plant));
    let s = generate(&prog, "tank-plant", &uno()).expect("sketch");
    assert!(
        !s.files[0].1.contains("plant.lad"),
        "the plant's rungs are in the sketch"
    );
}

#[test]
fn a_program_too_large_for_the_uno_is_refused() {
    if std::process::Command::new("avr-g++").arg("--version").output().is_err() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "avr-g++ is missing (CI=true)"
        );
        eprintln!("skipped: avr-g++ is missing (./test.sh installs it)");
        return;
    }
    // 300 timers with REAL math: about 90 bytes of flash and 20 of RAM each.
    let mut tags = String::from("In,BOOL,DI:1/0,,,\nOut,BOOL,DO:2/0,,,\nA,INT,AI:3/0,,,\n");
    let mut main = String::new();
    for k in 0..300 {
        tags += &format!("T{k},TIMER,,,,\nR{k},REAL,,,,\n");
        main += &format!(
            "XIC(In)TON(T{k},{},0)CPT(R{k},A*1.5+R{k}/3.0);\nXIC(T{k}.DN)GRT(R{k},{k}.5)OTE(Out);\n",
            100 + k
        );
    }
    let p = project("large", &tags, &main);
    let s = generate(&p, "large", &uno()).expect("generates");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("refusals/large-sketch");
    std::fs::create_dir_all(&dir).expect("dir");
    for (name, text) in &s.files {
        std::fs::write(dir.join(name), text).expect("write");
    }
    let err = alba_arduino::toolchain::build(&dir.join(&s.files[0].0), Model::Uno, &dir.join("build"))
        .expect_err("300 REAL timers do not fit an Uno");
    assert_eq!(err.code, alba_diag::Code::DoesNotFit, "{}", err.message);
    assert!(
        err.message.contains("the Arduino Uno has 32256 and 2048"),
        "{}",
        err.message
    );
    // The Mega takes it.
    alba_arduino::toolchain::build(&dir.join(&s.files[0].0), Model::Mega, &dir.join("build-mega"))
        .expect("fits a Mega");
}

/// A project whose one program is `main.st`.
fn st_project(name: &str, tags: &str, main: &str) -> (alba_ir::Program, alba_diag::Files) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("refusals").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"{name}\"\nscan_ms = 10\nprograms = [\"main.st\"]\n"),
    )
    .expect("write");
    std::fs::write(
        dir.join("tags.csv"),
        format!("name,type,address,initial,retain,description\n{tags}"),
    )
    .expect("write");
    std::fs::write(dir.join("main.st"), main).expect("write");
    let c = alba_load::compile_dir(&dir);
    let files = c.files().clone();
    (
        c.program.unwrap_or_else(|| panic!("{name}: {:?}", c.diagnostics)),
        files,
    )
}

#[test]
fn string_conversions_of_real_and_time_fit_the_board_and_of_lreal_are_refused_at_their_line() {
    // REAL_TO_STRING scales in REAL arithmetic, TIME_TO_STRING,
    // STRING_TO_TIME and STRING_TO_DT compute in LINT, all of which the sketch has; LREAL_TO_STRING needs 64-bit doubles.
    let (p, _) = st_project(
        "st-real-text",
        "N,INT,,,,\n",
        "PROGRAM Main\nVAR s : STRING[24]; t : TIME; d : DT; END_VAR\ns := REAL_TO_STRING(INT_TO_REAL(N) / 4.0);\ns := TIME_TO_STRING(T#1s);\nt := STRING_TO_TIME(s);\nd := STRING_TO_DT(s);\nEND_PROGRAM\n",
    );
    assert_eq!(messages(&p, &uno()), Vec::<String>::new());
    let (p, files) = st_project(
        "st-lreal-text",
        "N,INT,,,,\n",
        "PROGRAM Main\nVAR s : STRING[24]; END_VAR\nN := N + 1;\ns := LREAL_TO_STRING(INT_TO_LREAL(N));\nEND_PROGRAM\n",
    );
    let d = generate(&p, "p", &uno()).expect_err("LREAL refused");
    let shown: Vec<String> = d.iter().map(|d| d.short(&files)).collect();
    assert!(
        shown
            .iter()
            .any(|s| s.contains("main.st:4:") && s.contains("LREAL (64-bit) arithmetic cannot run on the board")),
        "{shown:?}"
    );
}
