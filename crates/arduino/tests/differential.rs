//! Differential tests (SPEC §7.5): the generated firmware, built with avr-gcc
//! and run on an emulated ATmega in simavr, gives the same trace as the
//! engine (`alba sim`) for the same program and stimulus: every example, with
//! its own stimulus where that drives only wired inputs and with a random
//! one, and a set of random ladder programs. Analog outputs are compared as
//! the PWM duty the board can show (the value clamped to 0–255), the one
//! documented difference.
//!
//! Needs avr-gcc, the Arduino AVR core and simavr (`./test.sh` installs
//! them); without them the tests say so and pass, except under `CI=true`.

mod common;

use alba_arduino::simavr::{self, Column, Timing};
use alba_arduino::sketch::{Target, Wire, control_program, generate};
use alba_arduino::toolchain;
use alba_diag::FileId;
use alba_engine::Engine;
use alba_engine::sim::{self, SimOptions, Stimulus};
use alba_ir::{Layout, Place, Program};
use alba_model::Value;
use alba_model::address::Address;
use alba_model::board::{Model, PinMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

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

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("firmware").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("work dir");
    d
}

struct Case {
    name: String,
    prog: Program,
    scan_ms: u64,
}

fn example(name: &str) -> Case {
    let c = alba_compiler::compile_dir(&root().join("examples").join(name));
    let prog = c.program.unwrap_or_else(|| panic!("{name} does not compile"));
    let scan_ms = c.project.config.as_ref().map_or(10, |c| u64::from(c.scan_ms));
    Case {
        name: name.into(),
        prog,
        scan_ms,
    }
}

/// Every wired I/O channel as a traced column, named by its address.
fn io_columns(wiring: &[Wire], layout: &Layout) -> Vec<Column> {
    wiring
        .iter()
        .map(|w| {
            let place = match w.address {
                Address::DigitalIn(_) | Address::DigitalOut(_) => Place::Bool(alba_ir::B(w.slot)),
                _ => Place::Int(alba_ir::I(w.slot), alba_model::DataType::Int),
            };
            let name = layout
                .tags
                .iter()
                .find(|t| t.address == Some(w.address))
                .map_or_else(|| w.address.to_string(), |t| t.name.clone());
            Column { name, place }
        })
        .collect()
}

/// A deterministic pseudo-random generator (xorshift64*).
/// Random input changes over `until` ms: digital inputs toggled and analog
/// readings set at random milliseconds (not only scan times).
fn random_stimulus(wiring: &[Wire], layout: &Layout, until: u64, seed: u64) -> String {
    let mut rng = common::Rng(seed | 1);
    let inputs: Vec<&Wire> = wiring
        .iter()
        .filter(|w| matches!(w.address, Address::DigitalIn(_) | Address::AnalogIn(_)))
        .collect();
    let mut rows = Vec::new();
    let mut t = 0;
    let mut state = vec![false; inputs.len()];
    while !inputs.is_empty() {
        t += 1 + rng.below(400);
        if t > until {
            break;
        }
        let k = rng.below(inputs.len() as u64) as usize;
        let w = inputs[k];
        let name = layout
            .tags
            .iter()
            .find(|tag| tag.address == Some(w.address))
            .map_or_else(|| w.address.to_string(), |tag| tag.name.clone());
        let v = match w.address {
            Address::DigitalIn(_) => {
                state[k] = !state[k];
                u64::from(state[k])
            }
            _ => rng.below(1024),
        };
        rows.push(format!("{t},{name},{v}\n"));
    }
    format!("time_ms,tag,value\n{}", rows.concat())
}

/// The engine's trace, with analog outputs clamped to the PWM duty range.
fn engine_trace(prog: &Program, stim: &Stimulus, cols: &[Column], timing: Timing, wiring: &[Wire]) -> String {
    let mut engine = Engine::new(Arc::new(prog.clone())).expect("engine");
    let ecols: Vec<sim::Column> = cols
        .iter()
        .map(|c| sim::Column {
            name: c.name.clone(),
            place: c.place,
        })
        .collect();
    let mut out = Vec::new();
    sim::run(
        &mut engine,
        stim,
        &ecols,
        SimOptions {
            scan_ms: timing.scan_ms,
            until_ms: timing.until_ms,
            every_ms: timing.every_ms,
        },
        &mut out,
    )
    .expect("engine run");
    let text = String::from_utf8(out).expect("utf-8");
    let ao: Vec<bool> = cols
        .iter()
        .map(|c| {
            wiring.iter().any(|w| {
                matches!(w.address, Address::AnalogOut(_))
                    && Place::Int(alba_ir::I(w.slot), alba_model::DataType::Int) == c.place
            })
        })
        .collect();
    let mut lines = text.lines();
    let mut res = format!("{}\n", lines.next().unwrap_or(""));
    for line in lines {
        let mut f: Vec<String> = line.split(',').map(str::to_string).collect();
        for (k, is_ao) in ao.iter().enumerate() {
            if *is_ao && let Ok(v) = f[k + 1].parse::<i64>() {
                f[k + 1] = v.clamp(0, 255).to_string();
            }
        }
        res.push_str(&f.join(","));
        res.push('\n');
    }
    res
}

/// Builds the case's firmware for `model`, runs both sides, and compares.
fn check(case: &Case, model: Model, stimulus: Option<&str>, until: u64, every: u64, seed: u64) -> simavr::Profile {
    check_as(case, model, stimulus, until, every, seed, false)
}

/// As `check`; with `bytecode`, the firmware is the byte-code interpreter
/// with the case's byte code in its EEPROM instead of the compiled sketch.
fn check_as(
    case: &Case,
    model: Model,
    stimulus: Option<&str>,
    until: u64,
    every: u64,
    seed: u64,
    bytecode: bool,
) -> simavr::Profile {
    let target = aurora(model, case.scan_ms as u32);
    let prog = control_program(&case.prog);
    let sketch = generate(&prog, &case.name, &target).unwrap_or_else(|d| panic!("{}: {d:?}", case.name));
    let kind = if bytecode { "bytecode" } else { "sketch" };
    let dir = work_dir(&format!("{}-{}-{seed}-{kind}", case.name, model.name()));
    let files = if bytecode {
        let bc = alba_arduino::bytecode::encode(&prog, &case.name, &target).unwrap_or_else(|d| panic!("{d:?}"));
        alba_arduino::interp::generate(&target, Some(&bc.bytes))
    } else {
        sketch.files.clone()
    };
    for (name, text) in &files {
        std::fs::write(dir.join(name), text).expect("write sketch");
    }
    let built = toolchain::build(&dir.join(&files[0].0), model, &dir.join("build"))
        .unwrap_or_else(|d| panic!("{}: {}", case.name, d.message));
    let layout = &prog.layout;
    let stim_text = stimulus.map_or_else(|| random_stimulus(&sketch.wiring, layout, until, seed), str::to_string);
    let stim =
        Stimulus::parse(&stim_text, FileId(0), layout).unwrap_or_else(|d| panic!("{}: stimulus {d:?}", case.name));
    // Every I/O channel from its pin, every tag and member and the fault
    // flags from the firmware's memory.
    let mut cols = io_columns(&sketch.wiring, layout);
    for c in sim::all_columns(layout) {
        cols.push(Column {
            name: c.name,
            place: c.place,
        });
    }
    for name in ["S:FS", "S:MINOR", "S:FAULTCODE", "SM0.5", "SM0.6"] {
        if let Ok(alba_ir::Target::Value { place, .. }) = layout.resolve(name) {
            cols.push(Column {
                name: name.into(),
                place,
            });
        }
    }
    let timing = Timing {
        scan_ms: case.scan_ms,
        until_ms: until,
        every_ms: every,
        from_first_scan: bytecode,
    };
    let want = engine_trace(&prog, &stim, &cols, timing, &sketch.wiring);
    let rows: Vec<(u64, Place, Value)> = stim.writes().expect("the differential cases force nothing");
    let run = simavr::simulate(
        &built.elf,
        model,
        &sketch.wiring,
        false,
        &prog.init,
        &rows,
        &cols,
        timing,
    )
    .unwrap_or_else(|d| panic!("{}: {d:?}", case.name));
    if run.trace != want {
        std::fs::write(dir.join("engine.csv"), &want).expect("write");
        std::fs::write(dir.join("firmware.csv"), &run.trace).expect("write");
        std::fs::write(dir.join("stimulus.csv"), &stim_text).expect("write");
        let names: Vec<&str> = want.lines().next().unwrap_or("").split(',').collect();
        let first = want
            .lines()
            .zip(run.trace.lines())
            .find(|(a, b)| a != b)
            .map(|(a, b)| {
                let cols: Vec<String> = a
                    .split(',')
                    .zip(b.split(','))
                    .zip(&names)
                    .filter(|((x, y), _)| x != y)
                    .map(|((x, y), n)| format!("{n}: engine {x}, firmware {y}"))
                    .collect();
                format!("at {} ms: {}", a.split(',').next().unwrap_or("?"), cols.join("; "))
            })
            .unwrap_or_else(|| "different lengths".into());
        panic!(
            "{} on the {} ({kind}): the firmware's trace differs from the engine's (files in {}):\n{first}",
            case.name,
            model.title(),
            dir.display()
        );
    }
    assert!(run.profile.scans > 0, "{}: no scan profile", case.name);
    eprintln!(
        "{} ({}): {} | {} scans, cycles per scan min {} mean {} max {} ({:.1} µs mean at 16 MHz)",
        case.name,
        model.name(),
        built.report(),
        run.profile.scans,
        run.profile.min,
        run.profile.mean,
        run.profile.max,
        run.profile.mean as f64 / 16.0
    );
    run.profile
}

/// An example's own stimulus and trace period, if its stimulus drives only wired inputs.
fn own_stimulus(name: &str) -> Option<(String, u64, u64)> {
    let dir = root().join("examples").join(name);
    let stim = std::fs::read_to_string(dir.join("stimulus.csv")).ok()?;
    let args = std::fs::read_to_string(dir.join("golden.args")).ok()?;
    let words: Vec<&str> = args.split_whitespace().collect();
    let arg = |k: &str| {
        words
            .iter()
            .position(|w| *w == k)
            .and_then(|i| words.get(i + 1)?.parse().ok())
    };
    Some((stim, arg("--until")?, arg("--every")?))
}

/// The examples the board runs (the PID ones are refused, E501).
const BOARD_EXAMPLES: [&str; 9] = [
    "start-stop",
    "traffic-light",
    "star-delta",
    "tank",
    "tank-plant",
    "festo-station",
    // A Petri-mode net with a ladder program: nets use only ops the sketch translates.
    "petri-resource",
    // A normal-mode state net (timers, a counter, conditions, an end) with a ladder program.
    "state-net-batch",
    // An SFC chart (steps, qualifiers, timed actions) with a ladder program.
    "sfc-batch",
];

#[test]
fn examples_run_the_same_on_the_uno() {
    if !tools_present() {
        return;
    }
    for name in BOARD_EXAMPLES {
        let case = example(name);
        if let Some((stim, until, every)) =
            own_stimulus(name).filter(|_| !name.contains("plant") && name != "festo-station")
        {
            check(&case, Model::Uno, Some(&stim), until, every, 0);
        }
        check(&case, Model::Uno, None, 8000, case.scan_ms, 7);
    }
}

#[test]
fn the_mega_runs_the_same() {
    if !tools_present() {
        return;
    }
    let case = example("tank");
    check(&case, Model::Mega, None, 5000, 10, 11);
}

/// A random ladder program (common::random_ladder) compiled.
fn random_program(seed: u64) -> Case {
    let (tags, rungs) = common::random_ladder(seed);
    let dir = work_dir(&format!("random-src-{seed}"));
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"random-{seed}\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n"),
    )
    .expect("write");
    std::fs::write(dir.join("tags.csv"), tags).expect("write");
    std::fs::write(dir.join("main.lad"), &rungs).expect("write");
    let c = alba_compiler::compile_dir(&dir);
    let prog = c
        .program
        .unwrap_or_else(|| panic!("random program {seed} does not compile: {:?}\n{rungs}", c.diagnostics));
    Case {
        name: format!("random-{seed}"),
        prog,
        scan_ms: 10,
    }
}

#[test]
fn random_ladder_programs_run_the_same() {
    if !tools_present() {
        return;
    }
    std::thread::scope(|s| {
        for half in 0..2u64 {
            s.spawn(move || {
                for seed in (1..=12u64).filter(|k| k % 2 == half) {
                    check(&random_program(seed), Model::Uno, None, 4000, 10, seed);
                }
            });
        }
    });
}

/// `model` with the aurora pin map and the monitoring link.
fn aurora(model: Model, scan_ms: u32) -> Target {
    Target {
        model,
        map: PinMap::preset("aurora").expect("preset"),
        active_low: false,
        scan_ms,
        monitor: true,
        power_up_on: Vec::new(),
    }
}

/// The Uno when the case's byte code fits its program slot, else the Mega.
fn board_for(case: &Case) -> Model {
    let uno = aurora(Model::Uno, case.scan_ms as u32);
    let fits = alba_arduino::bytecode::encode(&control_program(&case.prog), &case.name, &uno).is_ok();
    if fits { Model::Uno } else { Model::Mega }
}

#[test]
fn the_bytecode_interpreter_runs_the_examples_and_random_programs_as_the_engine() {
    if !tools_present() {
        return;
    }
    // Every example the sketch's differential runs (AWL and nets included), on the Uno
    // when its byte code fits the Uno's program slot, else on the Mega.
    for name in BOARD_EXAMPLES {
        let case = example(name);
        check_as(&case, board_for(&case), None, 6000, case.scan_ms, 5, true);
    }
    check_as(&example("tank"), Model::Mega, None, 3000, 10, 6, true);
    std::thread::scope(|s| {
        for half in 0..2u64 {
            s.spawn(move || {
                for seed in (1..=12u64).filter(|k| k % 2 == half) {
                    // on the Uno when its byte code fits the Uno's program slot, else on the Mega
                    let case = random_program(seed);
                    check_as(&case, board_for(&case), None, 3000, 10, seed, true);
                }
            });
        }
    });
}

/// A damaged program in EEPROM (a flipped byte: the CRC fails; or an operand
/// out of memory, re-signed: the op check fails) runs nothing: no scan, every
/// output off, no memory written.
#[test]
fn the_interpreter_runs_no_damaged_program() {
    if !tools_present() {
        return;
    }
    let case = example("start-stop");
    let target = aurora(Model::Uno, 10);
    let prog = control_program(&case.prog);
    let sketch = generate(&prog, &case.name, &target).expect("sketch");
    let good = alba_arduino::bytecode::encode(&prog, &case.name, &target)
        .expect("encodes")
        .bytes;
    let mut flipped = good.clone();
    let last = flipped.len() - 1;
    flipped[last] ^= 0x01;
    // The last op is OTE(Lamp): its slot made 250, past the 30 BOOL slots, and re-signed.
    let mut outside = good.clone();
    outside[last] = 250;
    let crc = crc32fast::hash(&outside[24..]);
    outside[20..24].copy_from_slice(&crc.to_le_bytes());
    assert!(
        alba_arduino::bytecode::decode(&outside).is_err(),
        "the host refuses it too"
    );
    for (what, bytes) in [("flipped", flipped), ("outside", outside)] {
        let dir = work_dir(&format!("damaged-{what}"));
        let files = alba_arduino::interp::generate(&target, Some(&bytes));
        for (name, text) in &files {
            std::fs::write(dir.join(name), text).expect("write");
        }
        let built = toolchain::build(&dir.join(&files[0].0), Model::Uno, &dir.join("build")).expect("builds");
        let cols = io_columns(&sketch.wiring, &prog.layout);
        let timing = Timing {
            scan_ms: 10,
            until_ms: 500,
            every_ms: 50,
            from_first_scan: true,
        };
        let run = simavr::simulate(
            &built.elf,
            Model::Uno,
            &sketch.wiring,
            false,
            &prog.init,
            &[],
            &cols,
            timing,
        )
        .expect("runs");
        assert_eq!(run.profile.scans, 0, "{what}: a damaged program ran");
        for line in run.trace.lines().skip(1) {
            assert!(line.split(',').skip(1).all(|v| v == "0"), "{what}: {line}");
        }
    }
}
