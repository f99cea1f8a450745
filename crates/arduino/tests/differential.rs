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
    /// The project's own `[board]` (model and pin map), when it has one: it
    /// runs there whatever board a test asks for.
    board: Option<(Model, PinMap)>,
}

/// Examples whose inputs are tags without an address (set from a screen or a
/// protocol): on the board they are wired to these channels — in a copy of
/// the example — so the example's own stimulus drives them on the pins.
const WIRED_FOR_THE_BOARD: &[(&str, &[(&str, &str)])] = &[("opcsm-tour", &[("Start", "DI:1/0"), ("Level", "AI:3/0")])];

fn example(name: &str) -> Case {
    let mut dir = root().join("examples").join(name);
    if let Some((_, wires)) = WIRED_FOR_THE_BOARD.iter().find(|(n, _)| *n == name) {
        // (a copy per call: tests run at once)
        static COPIES: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let n = COPIES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let copy = work_dir(&format!("{name}-wired-{n}"));
        for f in std::fs::read_dir(&dir).expect("example").flatten() {
            if f.path().is_file() {
                std::fs::copy(f.path(), copy.join(f.file_name())).expect("copy");
            }
        }
        let tags = std::fs::read_to_string(dir.join("tags.csv")).expect("tags.csv");
        let tags: Vec<String> = tags
            .lines()
            .map(|l| {
                let mut f: Vec<&str> = l.split(',').collect();
                if let Some((_, a)) = wires.iter().find(|(t, _)| f.first() == Some(t)) {
                    assert_eq!(f[2], "", "{name}: {} already has an address", f[0]);
                    f[2] = a;
                }
                f.join(",")
            })
            .collect();
        std::fs::write(copy.join("tags.csv"), tags.join("\n") + "\n").expect("write");
        dir = copy;
    }
    let c = alba_load::compile_dir(&dir);
    let prog = c.program.unwrap_or_else(|| panic!("{name} does not compile"));
    let scan_ms = c.project.config.as_ref().map_or(10, |c| u64::from(c.scan_ms));
    let board = c
        .project
        .config
        .as_ref()
        .and_then(|c| c.board.as_ref())
        .map(|b| (b.model, b.map.clone()));
    Case {
        name: name.into(),
        prog,
        scan_ms,
        board,
    }
}

/// Where `case` runs: its own `[board]`, else `model` with the aurora map.
fn target_for(case: &Case, model: Model) -> Target {
    let mut t = aurora(model, case.scan_ms as u32);
    if let Some((m, map)) = &case.board {
        t.model = *m;
        t.map = map.clone();
    }
    t
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
    let target = target_for(case, model);
    let model = target.model;
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

/// The examples the board runs (the PID ones are refused, E501): all the others.
const BOARD_EXAMPLES: [&str; 15] = [
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
    // OPCSM's elements as one state net (no ladder): its inputs wired for the board.
    "opcsm-tour",
    // Structured Text (an on-delay and a counter block) lowered to the same IR.
    "st-motor",
    // The 8051 PLC thesis's applications (002_…, chapter 6), in its own elements; the tank
    // on a Mega with twelve inputs (its [board]).
    "plc8051-latch",
    "plc8051-pulse-relay",
    "plc8051-tank",
    // The 004 source's plants without a compensator: the control program (the errors)
    // runs on the board; the plants are the host's models, so its own stimulus (the
    // set point step for the plants) is not replayed on the pins.
    "uncompensated",
];

/// Every example runs on the board (the differential tests below) or is
/// refused by the export and by the byte code, each refusal at its place.
#[test]
fn every_example_runs_on_the_board_or_is_refused_at_its_place() {
    let mut refused = Vec::new();
    for e in std::fs::read_dir(root().join("examples")).expect("examples").flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let case = example(&name);
        let t = target_for(&case, Model::Mega);
        let prog = control_program(&case.prog);
        let sketch = generate(&prog, &name, &t);
        let bc = alba_arduino::bytecode::encode(&prog, &name, &t);
        if BOARD_EXAMPLES.contains(&name.as_str()) {
            assert!(
                sketch.is_ok() && bc.is_ok(),
                "{name}: {:?} {:?}",
                sketch.err(),
                bc.err()
            );
            continue;
        }
        for d in [sketch.expect_err(&name), bc.expect_err(&name)] {
            assert!(!d.is_empty() && d.iter().all(|d| d.primary.is_some()), "{name}: {d:?}");
        }
        refused.push(name);
    }
    refused.sort();
    assert!(refused.iter().all(|n| n.starts_with("pid-")), "{refused:?}");
}

#[test]
fn examples_run_the_same_on_the_uno() {
    if !tools_present() {
        return;
    }
    for name in BOARD_EXAMPLES {
        let case = example(name);
        if let Some((stim, until, every)) = own_stimulus(name)
            .filter(|_| !name.contains("plant") && !["festo-station", "uncompensated"].contains(&name))
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
    let c = alba_load::compile_dir(&dir);
    let prog = c
        .program
        .unwrap_or_else(|| panic!("random program {seed} does not compile: {:?}\n{rungs}", c.diagnostics));
    Case {
        name: format!("random-{seed}"),
        prog,
        scan_ms: 10,
        board: None,
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

/// The Uno when the case's byte code fits its program slot, else the Mega
/// (or the case's own board).
fn board_for(case: &Case) -> Model {
    if let Some((m, _)) = &case.board {
        return *m;
    }
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

/// The interpreter firmware for `t`, without a program (`interp::firmware`,
/// built once and cached): each run starts it from an EEPROM image, as a
/// board that has had a download.
struct Interpreter {
    elf: PathBuf,
    target: Target,
    /// The firmware's statics (name, address, bytes).
    syms: Vec<(String, u32, u32)>,
    dir: PathBuf,
}

/// What the board did with one program in its EEPROM.
#[derive(Debug)]
struct Verdict {
    ran: bool,
    /// Rows where an output pin was driven (it must stay an input: its safe state).
    driven: Vec<String>,
    forbidden: Vec<String>,
    /// The memory sizes the board loaded (its `N[]`), in the last row.
    sizes: [u16; 6],
}

impl Interpreter {
    fn build(t: &Target, name: &str) -> Interpreter {
        let dir = work_dir(name);
        let (built, _) = alba_arduino::interp::firmware(t).unwrap_or_else(|d| panic!("{}", d.message));
        let syms = simavr::symbols(&built.elf).expect("symbols");
        Interpreter {
            elf: built.elf,
            target: t.clone(),
            syms,
            dir,
        }
    }

    fn sym(&self, name: &str) -> (u32, u32) {
        let mangled = format!("_ZL{}{name}", name.len());
        self.syms
            .iter()
            .find(|s| s.0 == mangled || s.0 == name)
            .map(|s| (s.1, s.2))
            .unwrap_or_else(|| panic!("the interpreter has no `{name}`"))
    }

    /// Runs `bytes` as the program in slot 0 for 250 ms with every output pin of the
    /// pin map watched, and the stores the firmware must never make watched: into its
    /// free RAM at any time, and once it scans, into its memory past what the program
    /// uses (by the host's decoding, `accepted`) and into its tables of the program.
    fn run(&self, bytes: &[u8], accepted: Option<&alba_arduino::bytecode::Decoded>, case: usize) -> Verdict {
        let ee = self.dir.join(format!("eeprom-{case}.bin"));
        std::fs::write(&ee, bytes).expect("write");
        let map = &self.target.map;
        let pins: Vec<String> = map.r#do.iter().chain(&map.ao).map(|p| format!("{p}:drive")).collect();
        let mut watch = simavr::Watch {
            pins: pins.clone(),
            mem: vec![self.sym("N")],
            until_ms: 250,
            every_ms: 50,
            forbid: Vec::new(),
            free_ram: Some(self.sym("__bss_end").0),
            ..simavr::Watch::default()
        };
        if let Some(d) = accepted {
            let c = d.program.layout.counts;
            for (name, used) in [
                ("B", c.b),
                ("I", 4 * c.i),
                ("F", 4 * c.f),
                ("L", 8 * c.l),
                ("M", d.program.layout.marker_bytes),
            ] {
                let (at, len) = self.sym(name);
                if used < len {
                    watch.forbid.push((at + used, len - used));
                }
            }
            for name in [
                "N",
                "wide",
                "code_start",
                "code_end",
                "n_ops",
                "scan_period",
                "sys_b",
                "sys_i",
                "n_wires",
                "w_wire",
                "w_pin",
                "image_base",
                "prog_id",
            ] {
                watch.forbid.push(self.sym(name));
            }
        }
        let run = simavr::run_watched(&self.elf, self.target.model, Some(&ee), &watch)
            .unwrap_or_else(|d| panic!("case {case}: {}", d.message));
        let _ = std::fs::remove_file(&ee);
        let rows: Vec<&str> = run.trace.lines().skip(1).collect();
        let driven = rows
            .iter()
            .filter(|r| r.split(',').skip(1).take(pins.len()).any(|v| v != "0"))
            .map(|r| r.to_string())
            .collect();
        let hex = rows.last().and_then(|r| r.split(',').next_back()).unwrap_or("");
        let mut sizes = [0u16; 6];
        for (k, s) in sizes.iter_mut().enumerate() {
            *s = hex
                .get(4 * k..4 * k + 4)
                .and_then(|h| u16::from_str_radix(h, 16).ok())
                .map_or(0, u16::swap_bytes);
        }
        let mut forbidden = run.forbidden;
        if run.forbidden_count as usize > forbidden.len() {
            forbidden.push(format!("({} in all)", run.forbidden_count));
        }
        Verdict {
            ran: run.scan_starts > 0,
            driven,
            forbidden,
            sizes,
        }
    }

    /// The host's verdict on `bytes` and the board's agree: what the host refuses,
    /// the board never runs (no scan, every output an input); what it accepts, the
    /// board runs with the memory sizes the host decoded, and stores nothing where
    /// it must not.
    fn agrees(&self, bytes: &[u8], case: usize, what: &str) -> bool {
        let host = alba_arduino::bytecode::decode_for(bytes, &self.target);
        let v = self.run(bytes, host.as_ref().ok(), case);
        assert!(
            v.forbidden.is_empty(),
            "{what}: forbidden stores {:?} (host: {host:?})",
            v.forbidden
        );
        match &host {
            Ok(d) => {
                assert!(
                    v.ran,
                    "{what}: the host accepts it (ops {:?}), the board does not run it",
                    d.program.ops
                );
                let c = d.program.layout.counts;
                let want = [c.b, c.i, c.f, c.l, c.d, d.program.layout.marker_bytes].map(|n| n as u16);
                assert_eq!(v.sizes, want, "{what}: the memory the board loaded");
            }
            Err(e) => {
                assert!(!v.ran, "{what}: the host refuses it ({e}), the board runs it");
                assert!(
                    v.driven.is_empty(),
                    "{what}: a refused program drove outputs: {:?}",
                    v.driven
                );
            }
        }
        host.is_ok()
    }
}

/// `bytes` with its body's CRC (and length) made good again: what a tool that
/// re-signs a damaged program would send.
fn resign(mut bytes: Vec<u8>) -> Vec<u8> {
    let len = (bytes.len() - HEADER_LEN) as u32;
    bytes[16..20].copy_from_slice(&len.to_le_bytes());
    let crc = crc32fast::hash(&bytes[HEADER_LEN..]);
    bytes[20..24].copy_from_slice(&crc.to_le_bytes());
    bytes
}

const HEADER_LEN: usize = alba_arduino::bytecode::HEADER_LEN;

/// Crafted programs, each refused by the host for one reason, are refused by
/// the board too (no scan, every output an input, no stray store); among them
/// the ones an earlier firmware ran: an I/O image outside memory with a wire
/// past the BOOL area, a system integer whose extent wraps around 16 bits, a
/// jump onto a 0x01 operand inside an op, a marker bit past 7, a pin the pin
/// map does not have, another board's id. Control cases the host accepts run.
#[test]
fn the_interpreter_refuses_what_the_host_refuses() {
    if !tools_present() {
        return;
    }
    let target = aurora(Model::Uno, 10);
    let board = Interpreter::build(&target, "interp-checks");
    let case = example("start-stop");
    let prog = control_program(&case.prog);
    let good = alba_arduino::bytecode::encode(&prog, &case.name, &target)
        .expect("encodes")
        .bytes;
    let body = |at: usize| HEADER_LEN + at;
    // Body offsets (docs/bytecode.md): sizes 0-11, I/O images 12-27 (DO: base 16, length
    // 18), system bits 28-45, system integers 46-53 (statistics 50), then the initial values.
    let mut cases: Vec<(&str, Vec<u8>)> = vec![("start-stop as compiled", good.clone())];
    let mut flipped = good.clone();
    let last = flipped.len() - 1;
    flipped[last] ^= 0x01;
    cases.push(("a flipped byte (the CRC)", flipped));
    let mut v = good.clone();
    v[last] = 250;
    cases.push(("the last op's slot past the 30 BOOL slots", resign(v)));
    let mut v = good.clone();
    v[body(18)] = 250;
    cases.push(("the DO image 250 channels long (past memory)", resign(v)));
    let mut v = good.clone();
    v[body(50)..body(52)].copy_from_slice(&0xFFFFu16.to_le_bytes());
    cases.push(("the statistics at integer 65 535 (the extent wraps)", resign(v)));
    let mut v = good.clone();
    v[6] ^= 0x01;
    cases.push(("another board's id", v));
    let mut v = good.clone();
    v[4] = 1;
    cases.push(("format version 1", v));
    // The wiring: start-stop's 4 wires (kind, channel, pin, slot) after its initial values.
    let wires = (0..good.len() - 24)
        .find(|k| good[*k..].starts_with(&[4, 0, 0, 0, 0, 2, 6, 0]))
        .expect("the wiring")
        + 2;
    let mut v = good.clone();
    v[wires + 3] = 11;
    cases.push(("Start on D11, which the pin map does not have there", resign(v)));
    let mut v = good.clone();
    v[wires + 4] = 7;
    cases.push(("Start wired to another slot than its image's", resign(v)));
    // The DO image made 250 long and Motor's wire moved to channel 200, past the BOOL area.
    let mut v = good.clone();
    v[body(18)] = 250;
    let motor = wires + 12;
    v[motor + 1] = 200;
    v[motor + 4] = 14 + 200;
    cases.push(("a wire on channel 200 of an image past memory", resign(v)));
    // Hand-made programs over start-stop's memory: a jump onto an operand 0x01 of an op, a
    // marker bit past 7, and a jump onto a rung (accepted).
    let custom = |ops: Vec<alba_ir::Op>, markers: u32| {
        let mut p = prog.clone();
        p.layout.marker_bytes = markers;
        p.init.m = vec![0; markers as usize];
        p.locs = vec![p.locs[0]; ops.len()];
        p.ops = ops;
        let s = generate(&prog, &case.name, &target).expect("sketch");
        alba_arduino::bytecode::encode_program(&p, 10, alba_arduino::bytecode::board_id(&target), 1, &s.wiring)
            .expect("encodes")
            .bytes
    };
    use alba_ir::{B, Op};
    // Rung; XIC(B1) = 04 01; Rung; JMP → 3 ops on; Rung
    let jumps = custom(vec![Op::Rung, Op::Xic(B(1)), Op::Rung, Op::Jmp(4), Op::Rung], 0);
    cases.push(("a jump onto a rung", jumps.clone()));
    let mut v = jumps.clone();
    let at = v.len() - 3;
    assert_eq!(v[at - 1], 0x0f, "the jump");
    // from the end of the jump back to the operand 0x01 of XIC: 1 + 2 + 1 + 3 - 2 = 5 bytes back
    v[at..at + 2].copy_from_slice(&(-5i16).to_le_bytes());
    assert_eq!(v[v.len() - 1 - 5], 0x01);
    cases.push(("a jump onto XIC's operand 0x01", resign(v)));
    let bits = custom(
        vec![
            Op::Rung,
            Op::LdBit {
                byte: 0,
                bit: 9,
                dst: B(16),
            },
        ],
        4,
    );
    cases.push(("a marker bit 9", bits));
    let mut accepted = 0;
    for (k, (what, bytes)) in cases.iter().enumerate() {
        accepted += usize::from(board.agrees(bytes, k, what));
    }
    assert_eq!(accepted, 2, "only start-stop and the jump onto a rung are good");
}

/// A mutation campaign: valid programs of several examples with bytes changed
/// — re-signed with a good CRC or not; anywhere, in the memory description, in
/// the header or in the ops; a byte inserted or removed — each loaded into the
/// emulated Uno. Whatever the host decoder refuses the board never runs (no
/// scan, every output an input); whatever it accepts the board runs with the
/// memory the host decoded, never storing past what the program uses, into its
/// own tables or into free RAM (simavr's store hook). Deterministic seeds.
#[test]
fn mutated_programs_run_on_the_board_exactly_when_the_host_accepts_them() {
    if !tools_present() {
        return;
    }
    let target = aurora(Model::Uno, 10);
    let board = Interpreter::build(&target, "interp-mutations");
    let bases: Vec<(Vec<u8>, usize)> = BOARD_EXAMPLES
        .iter()
        .filter_map(|name| {
            let case = example(name);
            let t = aurora(Model::Uno, case.scan_ms as u32);
            let bc = alba_arduino::bytecode::encode(&control_program(&case.prog), name, &t).ok()?;
            Some((bc.bytes.clone(), bc.bytes.len() - bc.code_len))
        })
        .collect();
    assert!(bases.len() >= 4, "{} examples fit the Uno", bases.len());
    const CASES: u64 = 1000;
    let counts = std::sync::Mutex::new((0, 0));
    std::thread::scope(|s| {
        for half in 0..2u64 {
            let (board, bases, counts) = (&board, &bases, &counts);
            s.spawn(move || {
                for k in (0..CASES).filter(|k| k % 2 == half) {
                    let mut r = common::Rng(0x5eed_0000 + k);
                    let (base, code_at) = &bases[r.below(bases.len() as u64) as usize];
                    let mut v = base.clone();
                    let any = |r: &mut common::Rng, from: usize, to: usize| from + r.below((to - from) as u64) as usize;
                    let (what, sign) = match r.below(6) {
                        0 | 1 => {
                            for _ in 0..1 + r.below(3) {
                                let at = any(&mut r, HEADER_LEN, v.len());
                                v[at] = r.next() as u8;
                            }
                            ("bytes anywhere in the body", r.below(4) != 0)
                        }
                        2 => {
                            // an operand or opcode of the ops, usually to a small value
                            let at = any(&mut r, *code_at, v.len());
                            v[at] = if r.below(3) == 0 {
                                r.next() as u8
                            } else {
                                r.below(40) as u8
                            };
                            ("a byte of the ops", true)
                        }
                        3 => {
                            // a u16 of the memory description, near what it was or anything
                            let at = any(&mut r, HEADER_LEN, code_at - 1);
                            let old = u16::from_le_bytes([v[at], v[at + 1]]);
                            let new = match r.below(3) {
                                0 => old.wrapping_add(1 + r.below(8) as u16),
                                1 => old.wrapping_sub(1 + r.below(8) as u16),
                                _ => r.next() as u16,
                            };
                            v[at..at + 2].copy_from_slice(&new.to_le_bytes());
                            ("a field of the memory description", true)
                        }
                        4 => {
                            let at = any(&mut r, 4, 16);
                            v[at] = if r.below(2) == 0 {
                                v[at] ^ (1 << r.below(8))
                            } else {
                                r.next() as u8
                            };
                            ("a header byte", r.below(2) == 0)
                        }
                        _ => {
                            let at = any(&mut r, *code_at, v.len());
                            if r.below(2) == 0 {
                                v.remove(at);
                            } else {
                                v.insert(at, r.below(0x42) as u8);
                            }
                            ("a byte of the ops inserted or removed", true)
                        }
                    };
                    let v = if sign { resign(v) } else { v };
                    let what = format!(
                        "case {k}: {what}{}",
                        if sign { ", re-signed" } else { ", not re-signed" }
                    );
                    let ok = board.agrees(&v, k as usize, &what);
                    let mut c = counts.lock().expect("counts");
                    if ok { c.0 += 1 } else { c.1 += 1 }
                }
            });
        }
    });
    let (accepted, refused) = *counts.lock().expect("counts");
    eprintln!(
        "{CASES} mutated programs: {accepted} accepted and run, {refused} refused, by the host and the board alike"
    );
    assert!(
        accepted >= 20 && refused >= 100,
        "{accepted} accepted, {refused} refused"
    );
}

/// A program with timers in every time base (issue 34: ms, cs, ds, s, min),
/// on wired inputs and outputs, scanned every `scan_ms`.
fn time_base_program(scan_ms: u64) -> Case {
    let dir = work_dir(&format!("time-base-src-{scan_ms}"));
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"time-base-{scan_ms}\"\nscan_ms = {scan_ms}\nprograms = [\"main.lad\"]\n"),
    )
    .expect("write");
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    tags.push_str("Run,BOOL,DI:1/0,,,\nHold,BOOL,DI:1/1,,,\nClear,BOOL,DI:1/2,,,\n");
    for k in 0..5 {
        tags.push_str(&format!("T{k},TIMER,,,,\nL{k},BOOL,DO:2/{k},,,\n"));
    }
    std::fs::write(dir.join("tags.csv"), tags).expect("write");
    let rungs = "XIC(Run)TON(T0,150,0,ms);\n\
                 XIC(Run)TOF(T1,37,0,cs);\n\
                 XIC(Hold)RTO(T2,6,0,ds);\n\
                 XIC(Run)XIO(Hold)TON(T3,2,0,s);\n\
                 XIC(Hold)TOF(T4,1,0,min);\n\
                 XIC(Clear)RES(T2);\n\
                 XIC(T0.DN)OTE(L0);\nXIC(T1.DN)OTE(L1);\nXIC(T2.DN)OTE(L2);\nXIC(T3.DN)OTE(L3);\nXIC(T4.TT)OTE(L4);\n";
    std::fs::write(dir.join("main.lad"), rungs).expect("write");
    let c = alba_load::compile_dir(&dir);
    let prog = c
        .program
        .unwrap_or_else(|| panic!("the time-base program does not compile: {:?}", c.diagnostics));
    Case {
        name: format!("time-base-{scan_ms}"),
        prog,
        scan_ms,
        board: None,
    }
}

#[test]
fn timers_in_every_time_base_run_the_same_as_the_engine() {
    if !tools_present() {
        return;
    }
    // 7 ms scans do not divide the units: the remainders must be kept alike.
    for (scan_ms, seed) in [(7u64, 21u64), (10, 22)] {
        let case = time_base_program(scan_ms);
        check(&case, Model::Uno, None, 8000, scan_ms, seed);
        check_as(&case, Model::Uno, None, 8000, scan_ms, seed, true);
    }
}

/// The golden cases of an example, as `alba sim`'s golden test reads them:
/// (stimulus, `--until`, `--every`, `--tags`, golden trace).
fn golden_cases(name: &str) -> Vec<(String, u64, u64, Vec<String>, String)> {
    let dir = root().join("examples").join(name);
    let mut out = Vec::new();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("example")
        .flatten()
        .map(|e| e.file_name())
        .collect();
    files.sort();
    for f in files {
        let f = f.to_string_lossy();
        let Some(case) = f.strip_suffix(".args").and_then(|s| s.strip_prefix("golden")) else {
            continue;
        };
        let read = |p: String| std::fs::read_to_string(dir.join(&p)).unwrap_or_else(|e| panic!("{name}/{p}: {e}"));
        let args = read(f.to_string());
        let words: Vec<&str> = args.split_whitespace().collect();
        let arg = |k: &str| {
            words
                .iter()
                .position(|w| *w == k)
                .and_then(|i| words.get(i + 1))
                .copied()
        };
        let num = |k: &str| {
            arg(k)
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{name}{case}: {k}"))
        };
        let tags = arg("--tags").expect("--tags").split(',').map(str::to_string).collect();
        out.push((
            read(format!("stimulus{case}.csv")),
            num("--until"),
            num("--every"),
            tags,
            read(format!("golden{case}.csv")),
        ));
    }
    out
}

/// The 8051 PLC thesis's applications (issue 34, point 6) on the byte-code
/// interpreter in simavr: the program downloaded into the board's EEPROM,
/// each golden case's stimulus on its pins, and the trace of the golden's
/// tags (I/O on the pins, the rest in the interpreter's memory) equal to the
/// golden file `alba sim` is held to — latch by pulses and the pulse relay
/// on the Uno, the tank on its own Mega.
#[test]
fn the_8051_applications_give_their_golden_traces_on_the_interpreter() {
    if !tools_present() {
        return;
    }
    for name in ["plc8051-latch", "plc8051-pulse-relay", "plc8051-tank"] {
        let case = example(name);
        let target = target_for(&case, Model::Uno);
        let prog = control_program(&case.prog);
        let sketch = generate(&prog, name, &target).unwrap_or_else(|d| panic!("{name}: {d:?}"));
        let bc = alba_arduino::bytecode::encode(&prog, name, &target).unwrap_or_else(|d| panic!("{name}: {d:?}"));
        let (firmware, _) = alba_arduino::interp::firmware(&target).unwrap_or_else(|d| panic!("{}", d.message));
        let dir = work_dir(&format!("{name}-golden"));
        let ee = dir.join("eeprom.bin");
        std::fs::write(&ee, &bc.bytes).expect("write");
        let cases = golden_cases(name);
        assert!(!cases.is_empty(), "{name}: no golden case");
        for (stim_text, until, every, tags, golden) in cases {
            let layout = &prog.layout;
            let cols: Vec<Column> = tags
                .iter()
                .map(|t| match layout.resolve(t) {
                    Ok(alba_ir::Target::Value { place, .. }) => Column { name: t.clone(), place },
                    other => panic!("{name}: {t} is no value: {other:?}"),
                })
                .collect();
            let stim = Stimulus::parse(&stim_text, FileId(0), layout).unwrap_or_else(|d| panic!("{name}: {d:?}"));
            let rows = stim.writes().expect("the golden stimuli force nothing");
            let timing = Timing {
                scan_ms: case.scan_ms,
                until_ms: until,
                every_ms: every,
                from_first_scan: true,
            };
            let run = simavr::simulate_eeprom(
                &firmware.elf,
                target.model,
                &sketch.wiring,
                false,
                &prog.init,
                &rows,
                &cols,
                timing,
                Some(&ee),
            )
            .unwrap_or_else(|d| panic!("{name}: {d:?}"));
            if run.trace != golden {
                std::fs::write(dir.join("firmware.csv"), &run.trace).expect("write");
                let first = golden.lines().zip(run.trace.lines()).find(|(a, b)| a != b);
                panic!(
                    "{name} on the {}: the interpreter's trace differs from the golden (in {}): {first:?}",
                    target.model.title(),
                    dir.display()
                );
            }
            assert!(run.profile.scans > 0, "{name}: no scan");
        }
    }
}
