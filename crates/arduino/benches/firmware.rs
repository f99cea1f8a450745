//! `cargo bench -p alba-arduino`: what the examples cost on an Arduino Uno
//! (flash, RAM, CPU cycles per scan on the emulated 16 MHz ATmega328P, from
//! simavr), and the largest generated ladder program that still fits an Uno,
//! for two kinds of rung; then the same examples as byte code run by the
//! interpreter firmware (issue 19): cycles per scan against the compiled
//! sketch, byte-code size, the largest programs whose byte code fits each
//! board, and the download time. Needs avr-gcc, arduino-core-avr and simavr.

use alba_arduino::simavr::{self, Column, Timing};
use alba_arduino::sketch::{Target, control_program, generate};
use alba_arduino::toolchain::{self, Built};
use alba_ir::Place;
use alba_model::address::Address;
use alba_model::board::{Model, PinMap};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn work(name: &str) -> PathBuf {
    let d = root().join("target/avr/bench").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("work dir");
    d
}

fn uno(scan_ms: u32) -> Target {
    Target {
        model: Model::Uno,
        map: PinMap::preset("aurora").expect("preset"),
        active_low: false,
        scan_ms,
        monitor: true,
        power_up_on: Vec::new(),
    }
}

/// Builds a project folder for the Uno; `Err` with the message when it does not fit.
fn build(dir: &Path, name: &str) -> Result<(alba_ir::Program, alba_arduino::Sketch, Built), String> {
    let c = alba_load::compile_dir(dir);
    let prog = control_program(&c.program.ok_or_else(|| format!("{name} does not compile"))?);
    let scan = c.project.scan_ms();
    let s = generate(&prog, name, &uno(scan)).map_err(|d| format!("{d:?}"))?;
    let out = work(&format!("{name}-sketch"));
    for (f, text) in &s.files {
        std::fs::write(out.join(f), text).expect("write");
    }
    let b = toolchain::build(&out.join(&s.files[0].0), Model::Uno, &out.join("build")).map_err(|d| d.message)?;
    Ok((prog, s, b))
}

fn project(name: &str, tags: &str, lad: &str) -> PathBuf {
    let dir = work(name);
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
    std::fs::write(dir.join("main.lad"), lad).expect("write");
    dir
}

/// A logic rung: two contacts in parallel, one in series, two coils.
fn logic(n: usize) -> (String, String) {
    let mut tags = String::from("In,BOOL,DI:1/0,,,\nOut,BOOL,DO:2/0,,,\n");
    let mut lad = String::new();
    for i in 0..n {
        tags += &format!("A_{i},BOOL,,,,\nQ_{i},BOOL,,,,\n");
        let prev = if i == 0 {
            "In".to_string()
        } else {
            format!("Q_{}", i - 1)
        };
        lad += &format!("[XIC({prev}),XIC(A_{i})]XIO(Out)OTE(Q_{i})OTE(A_{i});\n");
    }
    lad += &format!("XIC(Q_{})OTE(Out);\n", n.max(1) - 1);
    (tags, lad)
}

/// A timer rung (`alba bench`'s): a TON, a CTU, a compare and an ADD.
fn timers(n: usize) -> (String, String) {
    let mut tags = String::from("In,BOOL,DI:1/0,,,\nOut,BOOL,DO:2/0,,,\n");
    let mut lad = String::new();
    for i in 0..n {
        tags += &format!("T_{i},TIMER,,,,\nC_{i},COUNTER,,,,\nV_{i},DINT,,,,\n");
        lad += &format!(
            "[XIO(T_{i}.DN),XIC(In)]TON(T_{i},{},0)CTU(C_{i},1000,0)GRT(C_{i}.ACC,{})ADD(V_{i},1,V_{i})OTE(Out);\n",
            5 + i % 7,
            i % 5
        );
    }
    (tags, lad)
}

/// The largest n for which `make(n)` fits an Uno (binary search).
fn largest(kind: &str, make: fn(usize) -> (String, String)) {
    let fits = |n: usize| {
        let (tags, lad) = make(n);
        build(&project(&format!("{kind}-{n}"), &tags, &lad), &format!("{kind}_{n}")).map(|(_, _, b)| b)
    };
    let (mut lo, mut hi) = (1usize, 2usize);
    let mut best = fits(lo).expect("one rung fits");
    while let Ok(b) = fits(hi) {
        best = b;
        lo = hi;
        hi *= 2;
    }
    let mut why = String::new();
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        match fits(mid) {
            Ok(b) => {
                best = b;
                lo = mid;
            }
            Err(e) => {
                why = e;
                hi = mid;
            }
        }
    }
    if why.is_empty() {
        why = fits(hi).err().unwrap_or_default();
    }
    println!(
        "largest {kind} program that fits an Uno: {lo} rungs ({})",
        best.report()
    );
    println!("  with {hi}: {why}");
}

fn main() {
    if std::process::Command::new("avr-g++").arg("--version").output().is_err() {
        eprintln!("avr-gcc is missing: run ./test.sh once (it installs gcc-avr, arduino-core-avr, simavr)");
        std::process::exit(1);
    }
    println!("example        | flash B | RAM B (of 2048) | cycles/scan min/mean/max | mean µs at 16 MHz");
    let mut sketch_cycles = Vec::new();
    for ex in [
        "start-stop",
        "traffic-light",
        "star-delta",
        "tank",
        "tank-plant",
        "festo-station",
    ] {
        let (prog, s, b) = build(&root().join("examples").join(ex), ex).expect("example builds");
        // Every output traced, no stimulus: 2 s of scans.
        let cols: Vec<Column> = s
            .wiring
            .iter()
            .filter(|w| matches!(w.address, Address::DigitalOut(_)))
            .map(|w| Column {
                name: w.address.to_string(),
                place: Place::Bool(alba_ir::B(w.slot)),
            })
            .collect();
        let t = Timing {
            scan_ms: 10,
            until_ms: 2000,
            every_ms: 10,
            from_first_scan: false,
        };
        let run = simavr::simulate(&b.elf, Model::Uno, &s.wiring, false, &prog.init, &[], &cols, t).expect("runs");
        let p = run.profile;
        println!(
            "{ex:<14} | {:>7} | {:>15} | {:>24} | {:.1}",
            b.flash,
            b.ram,
            format!("{}/{}/{}", p.min, p.mean, p.max),
            p.mean as f64 / 16.0
        );
        sketch_cycles.push((ex, prog, s, cols, p.mean));
    }
    largest("logic", logic);
    largest("timer", timers);
    interpreter(&sketch_cycles);
}

/// The byte-code interpreter on the Uno against the compiled sketches.
fn interpreter(sketches: &[(&str, alba_ir::Program, alba_arduino::Sketch, Vec<Column>, u64)]) {
    println!("\nbyte-code interpreter on the Uno (the program in EEPROM), 2 s of scans:");
    println!("example        | byte code B (ops) | cycles/scan mean | compiled sketch | ratio");
    let mut firmware = None;
    for (ex, prog, s, cols, sketch_mean) in sketches {
        let t = uno(10);
        let bc = match alba_arduino::bytecode::encode(prog, ex, &t) {
            Ok(bc) => bc,
            Err(d) => {
                println!(
                    "{ex:<14} | refused: {}",
                    d.first().map(|d| d.message.as_str()).unwrap_or("")
                );
                continue;
            }
        };
        let out = work(&format!("{ex}-interp"));
        let files = alba_arduino::interp::generate(&t, Some(&bc.bytes));
        for (f, text) in &files {
            std::fs::write(out.join(f), text).expect("write");
        }
        let b = toolchain::build(&out.join(&files[0].0), Model::Uno, &out.join("build")).expect("builds");
        let timing = Timing {
            scan_ms: 10,
            until_ms: 2000,
            every_ms: 10,
            from_first_scan: false,
        };
        let run = simavr::simulate(&b.elf, Model::Uno, &s.wiring, false, &prog.init, &[], cols, timing).expect("runs");
        let mean = run.profile.mean;
        println!(
            "{ex:<14} | {:>17} | {mean:>16} | {sketch_mean:>15} | {:.1}×",
            format!("{} ({})", bc.bytes.len(), bc.code_len),
            mean as f64 / (*sketch_mean).max(1) as f64
        );
        firmware.get_or_insert(b);
    }
    if let Some(b) = firmware {
        println!("interpreter firmware (with its program): {}", b.report());
    }
    // The largest generated programs whose byte code fits a program slot.
    for (kind, make) in [("logic", logic as fn(usize) -> (String, String)), ("timer", timers)] {
        for model in [Model::Uno, Model::Mega] {
            let room = alba_arduino::interp::slot_size(model);
            let size = |n: usize| {
                let (tags, lad) = make(n);
                let dir = project(&format!("bc-{kind}-{n}"), &tags, &lad);
                let c = alba_load::compile_dir(&dir);
                let prog = control_program(&c.program.expect("compiles"));
                let mut t = uno(10);
                t.model = model;
                alba_arduino::bytecode::encode_program(
                    &prog,
                    10,
                    0,
                    0,
                    &generate(&prog, kind, &t).expect("sketch").wiring,
                )
                .map(|bc| bc.bytes.len())
                .unwrap_or(usize::MAX)
            };
            let (mut lo, mut hi) = (1usize, 2usize);
            while size(hi) <= room {
                lo = hi;
                hi *= 2;
            }
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                if size(mid) <= room { lo = mid } else { hi = mid }
            }
            println!(
                "largest {kind} program whose byte code fits the {}'s {room}-byte slot: {lo} rungs ({} bytes, {:.1} per rung)",
                model.title(),
                size(lo),
                size(lo) as f64 / lo as f64
            );
        }
    }
    // Download time at 115 200 baud 8N1 (11 520 characters a second): each record
    // `:LLAAAA00<data>CC\r\n` and its answer `K\n`, then the end record and `SXXXX\n`;
    // on a real ATmega328P each EEPROM byte written takes 3.3 ms (the datasheet's
    // tWD_EEPROM; simavr does not model it), bytes already equal are skipped.
    let tank = sketches.iter().find(|(ex, ..)| *ex == "tank");
    if let Some((ex, prog, ..)) = tank
        && let Ok(bc) = alba_arduino::bytecode::encode(prog, ex, &uno(10))
    {
        let text = alba_arduino::ihex::write(&bc.bytes);
        let records = text.lines().filter(|l| !l.is_empty()).count();
        let chars = text.lines().map(|l| l.len() + 2).sum::<usize>() + 2 * records + 4;
        let line_ms = chars as f64 / 11.52;
        let eeprom_ms = bc.bytes.len() as f64 * 3.3;
        println!(
            "download of {ex} ({} bytes, {records} records): {line_ms:.0} ms on the line at 115 200 baud; {:.0} ms on a real Uno writing every byte of its EEPROM (3.3 ms a byte)",
            bc.bytes.len(),
            line_ms + eeprom_ms
        );
    }
}
