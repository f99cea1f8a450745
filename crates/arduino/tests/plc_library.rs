//! `PLC.h`, the Arduino library for programming by hand in the S7-200's style
//! (issue 34 point 8, source 001): its example sketch built with avr-gcc for
//! an Uno and run in simavr against a stimulus, each output checked; and the
//! library's copy of the runtime is the runtime Alba generates.
//!
//! Needs avr-gcc, the Arduino AVR core and simavr (`./test.sh` installs
//! them); without them the tests say so and pass, except under `CI=true`.

use alba_arduino::{simavr, toolchain};
use alba_model::board::Model;
use std::path::{Path, PathBuf};

fn library() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("library/PLC")
}

fn tools_present() -> bool {
    let ok = ["avr-g++", "pkg-config"]
        .iter()
        .all(|t| std::process::Command::new(t).arg("--version").output().is_ok())
        && Path::new(toolchain::AVR_CORE).is_dir()
        && Path::new("/usr/include/simavr/sim_avr.h").is_file();
    if !ok {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "avr-gcc, arduino-core-avr or simavr is missing (CI=true: install them, see scripts/avr.sh)"
        );
        eprintln!("skipped: avr-gcc, arduino-core-avr or simavr is missing (./test.sh installs them)");
    }
    ok
}

#[test]
fn the_library_carries_the_runtime_alba_generates() {
    let generated = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("runtime/alba_rt.h"))
        .expect("runtime/alba_rt.h");
    let published = std::fs::read_to_string(library().join("src/alba_rt.h")).expect("library/PLC/src/alba_rt.h");
    assert!(
        generated == published,
        "library/PLC/src/alba_rt.h differs from runtime/alba_rt.h: copy it (cp crates/arduino/runtime/alba_rt.h crates/arduino/library/PLC/src/)"
    );
    let props = std::fs::read_to_string(library().join("library.properties")).expect("library.properties");
    for key in ["name=PLC", "version=", "architectures=avr", "includes=PLC.h"] {
        assert!(props.contains(key), "library.properties lacks {key}");
    }
}

/// The outputs Q0.0–Q0.3 (D8–D11) at `t`.
fn outputs_at(trace: &str, t: u64) -> [bool; 4] {
    let row = trace
        .lines()
        .skip(1)
        .find(|l| l.split(',').next().and_then(|v| v.parse::<u64>().ok()) == Some(t))
        .unwrap_or_else(|| panic!("no row at {t} in\n{trace}"));
    let v: Vec<bool> = row.split(',').skip(1).map(|v| v != "0").collect();
    [v[0], v[1], v[2], v[3]]
}

#[test]
fn the_example_sketch_runs_in_simavr() {
    if !tools_present() {
        return;
    }
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("plc-library");
    let _ = std::fs::remove_dir_all(&out);
    let sketch = library().join("examples/ArranqueParo/ArranqueParo.ino");
    let built = toolchain::build_with(&sketch, Model::Uno, &out, &[&library().join("src")])
        .unwrap_or_else(|d| panic!("{}", d.message));
    // I0.0 (D2) start, I0.1 (D3) stop, I0.2 (D4) the counter's reset: three starts.
    let inputs = [
        (500, "D2", 1),
        (700, "D2", 0),
        (3500, "D3", 1),
        (3700, "D3", 0),
        (4500, "D2", 1),
        (4700, "D2", 0),
        (5500, "D3", 1),
        (5700, "D3", 0),
        (6500, "D2", 1),
        (6700, "D2", 0),
        (7500, "D4", 1),
        (7700, "D4", 0),
    ];
    let watch = simavr::Watch {
        pins: ["D8", "D9", "D10", "D11"].map(str::to_string).to_vec(),
        until_ms: 9000,
        every_ms: 100,
        inputs: inputs.iter().map(|(t, p, v)| (*t, p.to_string(), *v)).collect(),
        ..simavr::Watch::default()
    };
    let w = simavr::run_watched(&built.elf, Model::Uno, None, &watch).unwrap_or_else(|d| panic!("{}", d.message));
    let q = |t| outputs_at(&w.trace, t);
    // before the start: all off
    assert_eq!(q(400), [false; 4], "{}", w.trace);
    // started and sealed in; the lamp not yet (T37 counts 2 s)
    assert!(q(800)[0] && q(2400)[0] && !q(2400)[1], "{}", w.trace);
    // 2 s after the start, the lamp
    assert!(q(2600)[1] && q(3400)[1], "{}", w.trace);
    // the 1 s blinker (SM0.5) while the motor runs: on half the time
    let blinks: Vec<bool> = (8..35).map(|k| q(k * 100)[3]).collect();
    let on = blinks.iter().filter(|b| **b).count();
    assert!((11..=16).contains(&on), "SM0.5 on {on} of 27 samples: {blinks:?}");
    // stop: motor and lamp off, T37 reset
    assert_eq!(q(3800), [false; 4], "{}", w.trace);
    // second start: no count output yet; the third: C0 reaches 3
    assert!(q(4800)[0] && !q(4800)[2], "{}", w.trace);
    assert!(q(6800)[0] && q(6800)[2], "{}", w.trace);
    // I0.2 resets C0 (the motor keeps running)
    assert!(q(7800)[0] && !q(7800)[2], "{}", w.trace);
    // the lamp 2 s after the third start (6.5 s), not before
    assert!(!q(8400)[1] && q(8700)[1], "{}", w.trace);
}
