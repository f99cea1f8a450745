//! `alba export arduino`: the sketch folder of a project, the wiring table,
//! the board from the command line or `[board]`, and refusals with codes.
//! (Builds and behaviour: crates/arduino's differential tests and test.sh.)

use crate::{alba, scratch};

#[test]
fn export_writes_the_sketch_folder_and_the_wiring() {
    let d = scratch("export");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/start-stop");
    let o = alba(
        &d,
        &[
            "export",
            "arduino",
            &root.to_string_lossy(),
            "--board",
            "uno",
            "-o",
            "out",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("for the Arduino Uno (scan 10 ms), wired:"), "{err}");
    assert!(
        err.contains("in  DI:1/0   D2    Start") && err.contains("out DO:2/1   D13   Lamp"),
        "{err}"
    );
    let ino = std::fs::read_to_string(d.join("out/start_stop/start_stop.ino")).expect("sketch");
    let golden = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../arduino/tests/golden/start_stop.ino"),
    )
    .expect("golden");
    assert_eq!(
        ino, golden,
        "the CLI writes the sketch the generator's golden test reviews"
    );
    for f in ["alba_rt.h", "alba_link.h"] {
        assert!(d.join("out/start_stop").join(f).is_file(), "{f}");
    }
    // Without the monitoring link there is no alba_link.h and no Serial.
    let o = alba(
        &d,
        &[
            "export",
            "arduino",
            &root.to_string_lossy(),
            "--board",
            "nano",
            "--no-monitor",
            "-o",
            "plain",
        ],
    );
    assert!(o.status.success());
    let ino = std::fs::read_to_string(d.join("plain/start_stop/start_stop.ino")).expect("sketch");
    assert!(!ino.contains("Serial") && !d.join("plain/start_stop/alba_link.h").exists());
}

#[test]
fn export_refusals_have_codes() {
    let d = scratch("export-refusals");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let run = |args: &[&str]| {
        let o = alba(&d, args);
        (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let start_stop = root.join("start-stop").to_string_lossy().into_owned();
    let (code, err) = run(&["export", "arduino", &start_stop, "-o", "x"]);
    assert_eq!(code, Some(1));
    assert!(
        err.contains("error[E404]: no board: give --board uno|nano|mega"),
        "{err}"
    );
    let (_, err) = run(&["export", "arduino", &start_stop, "--board", "due", "-o", "x"]);
    assert!(
        err.contains("error[E404]: --board due: the boards are uno, nano and mega"),
        "{err}"
    );
    let (_, err) = run(&[
        "export",
        "arduino",
        &start_stop,
        "--board",
        "uno",
        "--pinmap",
        "x",
        "-o",
        "x",
    ]);
    assert!(
        err.contains("error[E404]: --pinmap x: the presets are aurora, s7, openplc"),
        "{err}"
    );
    let pid = root.join("pid-gp1").to_string_lossy().into_owned();
    let (code, err) = run(&["export", "arduino", &pid, "--board", "uno", "-o", "x"]);
    assert_eq!(code, Some(1));
    assert!(
        err.contains("error[E501]: PID does not run on the board yet") && err.contains("main.lad:2:1"),
        "{err}"
    );
    assert!(!d.join("x").exists(), "nothing written for a refused program");
}

#[test]
fn export_bytecode_writes_intel_hex_or_bytes_that_decode_to_the_control_program() {
    let d = scratch("export-bytecode");
    let root = crate::repo().join("examples/tank-plant");
    let project = root.to_string_lossy();
    for out in ["tank.hex", "tank.bin"] {
        let o = alba(&d, &["export", "bytecode", &project, "--board", "uno", "-o", out]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(err.contains("bytes of byte code for the Arduino Uno"), "{err}");
    }
    let hex = std::fs::read_to_string(d.join("tank.hex")).expect("hex");
    let bin = std::fs::read(d.join("tank.bin")).expect("bin");
    assert_eq!(alba_arduino::ihex::read(&hex, 1024).expect("reads"), bin);
    let decoded = alba_arduino::bytecode::decode(&bin).expect("decodes");
    let program = alba_load::compile_dir(&root).program.expect("compiles");
    assert_eq!(decoded.program.ops, alba_arduino::sketch::control_program(&program).ops);
    // A project the board cannot hold is refused as the sketch export refuses it, nothing written.
    let o = alba(&d, &["export", "bytecode", &project, "--board", "atari", "-o", "x.hex"]);
    assert!(!o.status.success());
    assert!(!d.join("x.hex").exists());
}

/// SPEC §10.5's interface for issue 19: `alba sim --firmware --bytecode
/// --board B` downloads the byte code into the interpreter on the emulated
/// board (with `alba download`'s protocol, through its serial port), runs it
/// in simavr, and prints `alba sim`'s trace — on the Uno, the Nano and the
/// Mega, an example each with its own stimulus and golden options. The
/// interpreter is built once per board and then taken from the cache.
#[test]
fn sim_firmware_bytecode_gives_the_simulators_trace() {
    let d = scratch("sim-bytecode");
    let mut elf_of = std::collections::HashMap::new();
    for (example, board) in [
        ("start-stop", "uno"),
        ("traffic-light", "nano"),
        ("tank", "mega"),
        ("start-stop", "uno"),
    ] {
        let root = crate::repo().join("examples").join(example);
        let golden = std::fs::read_to_string(root.join("golden.args")).expect("golden.args");
        let mut args: Vec<String> = vec!["sim".into(), root.to_string_lossy().into_owned()];
        args.extend(golden.split_whitespace().map(String::from));
        args.extend([
            "--stimulus".into(),
            root.join("stimulus.csv").to_string_lossy().into_owned(),
        ]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let engine = alba(&d, &args);
        assert!(engine.status.success(), "{example}");
        let mut fw_args = args.clone();
        fw_args.extend(["--firmware", "--bytecode", "--board", board]);
        let fw = alba(&d, &fw_args);
        let err = String::from_utf8_lossy(&fw.stderr);
        assert!(fw.status.success(), "{example} on the {board}: {err}");
        assert_eq!(
            String::from_utf8_lossy(&fw.stdout),
            String::from_utf8_lossy(&engine.stdout),
            "{example} on the {board}"
        );
        assert!(String::from_utf8_lossy(&fw.stdout).lines().count() > 20, "{example}");
        // The interpreter firmware: where it is, and whether it came from the cache.
        let line = err
            .lines()
            .find(|l| l.starts_with("interpreter firmware for the "))
            .unwrap_or_else(|| panic!("{err}"));
        let elf = line
            .split(": ")
            .nth(1)
            .and_then(|r| r.split(" (").next())
            .expect("path");
        match elf_of.insert(board, elf.to_string()) {
            Some(first) => {
                assert_eq!(first, elf, "the same firmware for the same board");
                assert!(line.ends_with("(cached)"), "built again: {line}");
            }
            None => assert!(line.contains(&format!("interp-{board}-")), "{line}"),
        }
    }
    // --bytecode needs --firmware.
    let project = crate::repo().join("examples/start-stop");
    let o = alba(&d, &["sim", &project.to_string_lossy(), "--until", "10", "--bytecode"]);
    assert!(!o.status.success());
}
