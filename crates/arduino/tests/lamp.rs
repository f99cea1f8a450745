//! The interpreter firmware's lamp test as the 8051 PLC thesis describes it
//! (`002_…` §4.1.6; issue 34, point 7), on an emulated Nano in simavr: DI
//! channel 0 held at power-up walks each output of the pin map in turn for
//! about 2 s, says on the serial port that it works, lights all the outputs
//! together for as long, then lights each output while the input of its
//! channel is on — with no program in EEPROM and with one (which does not
//! run meanwhile). Released at power-up, the program runs and no lamp is
//! tested.
//!
//! Needs avr-gcc, the Arduino AVR core and simavr (`./test.sh` installs
//! them); without them the tests say so and pass, except under `CI=true`.

use alba_arduino::sketch::{Target, control_program};
use alba_arduino::{simavr, toolchain};
use alba_model::board::{Model, PinMap};
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
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

fn nano() -> Target {
    Target {
        model: Model::Nano,
        map: PinMap::preset("aurora").expect("preset"),
        active_low: false,
        scan_ms: 10,
        monitor: true,
        power_up_on: Vec::new(),
    }
}

/// The aurora map's outputs in channel order: DO (digital) then AO (PWM).
const OUTPUTS: [&str; 10] = ["D12", "D13", "A0", "A1", "A2", "A3", "D6", "D9", "D10", "D11"];

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lamp").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("work dir");
    d
}

/// The EEPROM image of start-stop for `t`, as a download leaves it (slot 0).
fn start_stop_eeprom(t: &Target, dir: &Path) -> PathBuf {
    let c = alba_load::compile_dir(&root().join("examples/start-stop"));
    let prog = control_program(&c.program.expect("start-stop compiles"));
    let bc = alba_arduino::bytecode::encode(&prog, "start-stop", t).unwrap_or_else(|d| panic!("{d:?}"));
    let ee = dir.join("eeprom.bin");
    std::fs::write(&ee, &bc.bytes).expect("write");
    ee
}

/// Runs the interpreter (its EEPROM from `eeprom`) for `until_ms` with the
/// inputs `inputs`, every output of the map sampled each 100 ms, the serial
/// lines kept.
fn run(eeprom: Option<&Path>, inputs: &[(u64, &str, i32)], until_ms: u64) -> simavr::Watched {
    let t = nano();
    let (built, _) = alba_arduino::interp::firmware(&t).unwrap_or_else(|d| panic!("{}", d.message));
    let pins = OUTPUTS
        .iter()
        .map(|p| {
            if p.starts_with('A') || ["D12", "D13"].contains(p) {
                p.to_string()
            } else {
                format!("{p}:pwm")
            }
        })
        .collect();
    let watch = simavr::Watch {
        pins,
        until_ms,
        every_ms: 100,
        inputs: inputs.iter().map(|(t, p, v)| (*t, p.to_string(), *v)).collect(),
        serial: true,
        ..simavr::Watch::default()
    };
    simavr::run_watched(&built.elf, t.model, eeprom, &watch).unwrap_or_else(|d| panic!("{}", d.message))
}

/// The rows of the trace: time, then per output whether it is on.
fn rows(trace: &str) -> Vec<(u64, Vec<bool>)> {
    trace
        .lines()
        .skip(1)
        .map(|l| {
            let mut f = l.split(',');
            let t = f.next().and_then(|t| t.parse().ok()).expect("time");
            (t, f.map(|v| v != "0").collect())
        })
        .collect()
}

/// The outputs on at `t` (the row sampled at `t`).
fn on_at(rows: &[(u64, Vec<bool>)], t: u64) -> Vec<&'static str> {
    let (_, on) = rows
        .iter()
        .find(|(at, _)| *at == t)
        .unwrap_or_else(|| panic!("no row at {t}"));
    OUTPUTS.iter().zip(on).filter(|(_, on)| **on).map(|(p, _)| *p).collect()
}

/// The whole sequence, checked on the serial lines and on the pins.
fn check_lamp_test(w: &simavr::Watched, what: &str) {
    let lines: Vec<&str> = w.serial.iter().map(|(_, l)| l.as_str()).collect();
    let mut want = vec!["lamp test".to_string()];
    want.extend(OUTPUTS.iter().map(|p| format!("lamp {p}")));
    want.extend(
        [
            "lamp test: the serial port works",
            "lamp all",
            "lamp inputs",
            "input D2 1",
            "input D3 1",
            "input D2 0",
            "input D3 0",
            "input D4 1",
        ]
        .map(str::to_string),
    );
    assert_eq!(lines, want, "{what}: the serial port");
    let at = |line: &str| w.serial.iter().find(|(_, l)| l == line).map(|(t, _)| *t).expect(line);
    let rows = rows(&w.trace);
    // each output on alone for about 2 s, in channel order
    for (k, p) in OUTPUTS.iter().enumerate() {
        let from = at(&format!("lamp {p}"));
        let next = if k + 1 < OUTPUTS.len() {
            at(&format!("lamp {}", OUTPUTS[k + 1]))
        } else {
            at("lamp test: the serial port works")
        };
        assert!(
            (1990..=2100).contains(&(next - from)),
            "{what}: {p} on for {} ms",
            next - from
        );
        for t in (from / 100 + 1..next / 100).map(|k| k * 100) {
            assert_eq!(on_at(&rows, t), [*p], "{what}: at {t} ms only {p} is on");
        }
    }
    // then all together for about 2 s, then all off
    let (all, inputs) = (at("lamp all"), at("lamp inputs"));
    assert!(
        (1990..=2100).contains(&(inputs - all)),
        "{what}: all on for {} ms",
        inputs - all
    );
    for t in (all / 100 + 1..inputs / 100).map(|k| k * 100) {
        assert_eq!(on_at(&rows, t), OUTPUTS, "{what}: at {t} ms all are on");
    }
    // each input lights the output of its channel: DI 0 (D2, still held) DO 0 (D12), …
    assert_eq!(on_at(&rows, 23_200), ["D12", "D13"], "{what}: D2 and D3 on");
    assert_eq!(on_at(&rows, 23_700), ["D13"], "{what}: D2 released");
    assert_eq!(on_at(&rows, 24_200), ["A0"], "{what}: D4 on, D3 off");
    assert_eq!(w.scan_starts, 0, "{what}: no program runs during the lamp test");
}

/// The lamp test's inputs: DI 0 (D2) held from the reset; once the outputs
/// are tested (about 22 s), D3 on, D2 released, D3 off and D4 on.
const HELD: [(u64, &str, i32); 5] = [
    (0, "D2", 1),
    (23_000, "D3", 1),
    (23_500, "D2", 0),
    (24_000, "D3", 0),
    (24_000, "D4", 1),
];

#[test]
fn the_lamp_test_runs_with_no_program() {
    if !tools_present() {
        return;
    }
    check_lamp_test(&run(None, &HELD, 25_000), "no program");
}

#[test]
fn the_lamp_test_runs_before_a_program_which_waits_for_the_reset() {
    if !tools_present() {
        return;
    }
    let dir = work_dir("with-program");
    let ee = start_stop_eeprom(&nano(), &dir);
    check_lamp_test(&run(Some(&ee), &HELD, 25_000), "start-stop in EEPROM");
}

#[test]
fn released_at_power_up_the_program_runs_and_no_lamp_is_tested() {
    if !tools_present() {
        return;
    }
    let dir = work_dir("released");
    let ee = start_stop_eeprom(&nano(), &dir);
    // Start (D2) pressed after the power-up: start-stop seals the motor (D12) in.
    let w = run(Some(&ee), &[(500, "D2", 1), (700, "D2", 0)], 1500);
    assert!(w.serial.is_empty(), "{:?}", w.serial);
    assert!(w.scan_starts > 0, "the program runs");
    let trace = rows(&w.trace);
    assert_eq!(on_at(&trace, 300), Vec::<&str>::new());
    assert_eq!(on_at(&trace, 1000), ["D12"], "the motor runs");
    // No program and no input held: no lamp, no output driven, the LED blinks.
    let w = run(None, &[], 1500);
    assert!(w.serial.is_empty(), "{:?}", w.serial);
    assert_eq!(w.scan_starts, 0);
    assert!(rows(&w.trace).iter().all(|(_, on)| !on[0]), "D12 stays off");
}
