//! Firmware in simavr (SPEC §7.5): the harness `tools/simavr/harness.c`
//! (embedded, built once into the cache) runs a built sketch on the emulated
//! MCU with the stimulus of `alba sim` turned into pin levels and ADC
//! readings through the pin map; wired I/O is read back on the pins and
//! every other value in the sketch's memory arrays, so the result is a
//! trace in `alba sim`'s form for any list of tags.
//!
//! Rows are sampled just before the next scan's deadline (`--lag`), when the
//! outputs of the scan at `t` are on the pins: the row of `t` is the state
//! after the scan at `t`, as in the simulator.

use crate::sketch::Wire;
use crate::toolchain::{cache_dir, run, temp_sibling, tool_error};
use alba_diag::{Code, Diagnostic};
use alba_ir::Place;
use alba_model::Value;
use alba_model::address::Address;
use alba_model::board::Model;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

const HARNESS: &str = include_str!("../../../tools/simavr/harness.c");
/// The pin tables `harness.c` includes.
const PINS: &str = include_str!("../../../tools/simavr/pins.h");

/// The emulated board of the controller-mode tests and of `alba sim
/// --firmware --bytecode`'s download: simavr paced to real time with UART0 on
/// a pty (`tools/simavr/board.c`).
const BOARD: &str = include_str!("../../../tools/simavr/board.c");

/// The harness binary, built from the embedded source on first use (a new
/// source gets a new binary: the name carries a hash of it).
pub fn harness() -> Result<PathBuf, Diagnostic> {
    tool("alba-simavr", "harness.c", HARNESS)
}

/// The emulated board (`alba-board`), built like the harness.
pub fn board() -> Result<PathBuf, Diagnostic> {
    tool("alba-board", "board.c", BOARD)
}

fn tool(name: &str, file: &str, source: &str) -> Result<PathBuf, Diagnostic> {
    let hash = source
        .bytes()
        .chain(PINS.bytes())
        .fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
    let dir = cache_dir();
    let bin = dir.join(format!("{name}-{hash:016x}"));
    if bin.is_file() {
        return Ok(bin);
    }
    std::fs::create_dir_all(&dir).map_err(|e| tool_error(format!("cannot create {}: {e}", dir.display())))?;
    let src_dir = temp_sibling(&dir.join(format!("{name}-src")));
    let src = src_dir.join(file);
    std::fs::create_dir_all(&src_dir)
        .and_then(|()| std::fs::write(&src, source))
        .and_then(|()| std::fs::write(src_dir.join("pins.h"), PINS))
        .map_err(|e| {
            tool_error(format!(
                "cannot write the source of {name} in {}: {e}",
                src_dir.display()
            ))
        })?;
    let flags = run(
        Command::new("pkg-config").args(["--cflags", "--libs", "simavr"]),
        "finding simavr",
    )
    .map_err(|_| tool_error("simavr's development files were not found: install simavr and libsimavr-dev (Debian)"))?;
    let tmp = temp_sibling(&bin);
    let built = run(
        Command::new("gcc")
            .args(["-O2", "-Wall", "-Wextra", "-std=gnu11", "-x", "c", "-o"])
            .arg(&tmp)
            .arg(&src)
            .args(flags.split_whitespace())
            .arg("-lelf"),
        &format!("building {name}"),
    );
    let _ = std::fs::remove_dir_all(&src_dir);
    built?;
    std::fs::rename(&tmp, &bin).map_err(|e| tool_error(format!("cannot install {name}: {e}")))?;
    Ok(bin)
}

/// A traced column: its name as given and where the value lives.
#[derive(Debug, Clone)]
pub struct Column {
    pub name: String,
    pub place: Place,
}

/// Timing of the run, as for `alba sim`.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    pub scan_ms: u64,
    pub until_ms: u64,
    pub every_ms: u64,
    /// Time 0 is the first scan's start, not the reset (the byte-code
    /// interpreter, whose setup checks its program first).
    pub from_first_scan: bool,
}

/// What the harness measured of the scans (CPU cycles of `run()`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Profile {
    pub scans: u64,
    pub min: u64,
    pub mean: u64,
    pub max: u64,
}

/// A finished run: the trace CSV (`alba sim`'s form) and the scan profile.
#[derive(Debug, Clone)]
pub struct Run {
    pub trace: String,
    pub profile: Profile,
}

/// The wire of an image slot.
fn wire_of(wiring: &[Wire], place: Place) -> Option<&Wire> {
    wiring.iter().find(|w| match (w.address, place) {
        (Address::DigitalIn(_) | Address::DigitalOut(_), Place::Bool(b)) => w.slot == b.0,
        (Address::AnalogIn(_) | Address::AnalogOut(_), Place::Int(i, _)) => w.slot == i.0,
        _ => false,
    })
}

/// Runs the firmware `elf` for `model` in simavr with stimulus rows
/// `(time_ms, place, value)` (inputs wired to pins) and returns the trace
/// of `cols` (wired I/O read on the pins, everything else in the firmware's
/// memory). Until the stimulus sets it, an input pin
/// holds its tag's initial value from `init` (what the simulator starts with).
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    elf: &Path,
    model: Model,
    wiring: &[Wire],
    active_low: bool,
    init: &alba_ir::Memory,
    stimulus: &[(u64, Place, Value)],
    cols: &[Column],
    timing: Timing,
) -> Result<Run, Vec<Diagnostic>> {
    simulate_eeprom(elf, model, wiring, active_low, init, stimulus, cols, timing, None)
}

/// As [`simulate`], the MCU's EEPROM starting from the image `eeprom`.
#[allow(clippy::too_many_arguments)]
pub fn simulate_eeprom(
    elf: &Path,
    model: Model,
    wiring: &[Wire],
    active_low: bool,
    init: &alba_ir::Memory,
    stimulus: &[(u64, Place, Value)],
    cols: &[Column],
    timing: Timing,
    eeprom: Option<&Path>,
) -> Result<Run, Vec<Diagnostic>> {
    let mut diags = Vec::new();
    let mut stim = String::from("time_ms,pin,value\n");
    // The value given to each input, echoed in its column (what the scan read).
    let mut given: Vec<(u64, Address, i64)> = Vec::new();
    let initial = wiring.iter().filter_map(|w| match w.address {
        Address::DigitalIn(_) => init
            .b
            .get(w.slot as usize)
            .map(|b| (0, Place::Bool(alba_ir::B(w.slot)), Value::Bool(*b))),
        Address::AnalogIn(_) => init.i.get(w.slot as usize).map(|v| {
            (
                0,
                Place::Int(alba_ir::I(w.slot), alba_model::DataType::Dint),
                Value::Dint(*v),
            )
        }),
        _ => None,
    });
    let rows: Vec<(u64, Place, Value)> = initial.chain(stimulus.iter().copied()).collect();
    for (t, place, value) in &rows {
        let Some(w) =
            wire_of(wiring, *place).filter(|w| matches!(w.address, Address::DigitalIn(_) | Address::AnalogIn(_)))
        else {
            diags.push(Diagnostic::unplaced(
                Code::StimulusTarget,
                format!("the stimulus sets {value} at {t} ms on something that is not an input wired to a pin; firmware runs take only DI and AI inputs"),
            ));
            continue;
        };
        let v = match (w.address, value) {
            (Address::DigitalIn(_), Value::Bool(b)) => i64::from(*b),
            (Address::AnalogIn(_), Value::Sint(v)) => i64::from(*v),
            (Address::AnalogIn(_), Value::Int(v)) => i64::from(*v),
            (Address::AnalogIn(_), Value::Dint(v)) => i64::from(*v),
            _ => -1,
        };
        if matches!(w.address, Address::AnalogIn(_)) && !(0..=1023).contains(&v) {
            diags.push(Diagnostic::unplaced(
                Code::StimulusTarget,
                format!(
                    "{} reads {value} at {t} ms, but an analog input of the board reads 0 to 1023",
                    w.address
                ),
            ));
            continue;
        }
        // A row applies before the first scan at or after its time: on the
        // board, at that scan's deadline (millis() lags real time by up to a
        // millisecond, so a change just after a deadline could otherwise
        // reach the scan of that deadline).
        let at = t.div_ceil(timing.scan_ms.max(1)) * timing.scan_ms.max(1);
        given.push((at, w.address, v));
        let _ = writeln!(stim, "{at},{},{v}", w.pin);
    }
    // Wired I/O is read on the pins; everything else in the firmware's memory.
    let mut pins = Vec::new();
    for c in cols {
        match wire_of(wiring, c.place) {
            Some(w) if matches!(w.address, Address::AnalogOut(_)) => pins.push(format!("{}:pwm", w.pin)),
            Some(w) => pins.push(w.pin.to_string()),
            None if matches!(c.place, Place::Lreal(_)) => diags.push(Diagnostic::unplaced(
                Code::TraceName,
                format!("`{}` is an LREAL, which the board has not", c.name),
            )),
            None => {}
        }
    }
    if !diags.is_empty() {
        return Err(diags);
    }
    let regions = if pins.len() < cols.len() {
        memory_regions(elf, init).map_err(|d| vec![d])?
    } else {
        Vec::new()
    };
    let mem_arg: Vec<String> = regions.iter().map(|r| format!("{}:{}", r.1, r.2)).collect();
    let harness = harness().map_err(|d| vec![d])?;
    let work = temp_sibling(&elf.with_file_name("simavr"));
    std::fs::create_dir_all(&work).map_err(|e| vec![tool_error(format!("cannot create {}: {e}", work.display()))])?;
    let stim_file = work.join("stimulus.csv");
    let trace_file = work.join("trace.csv");
    let result = (|| {
        std::fs::write(&stim_file, &stim).map_err(|e| tool_error(format!("cannot write the stimulus: {e}")))?;
        let lag_us = (timing.scan_ms * 1000).saturating_sub(10);
        let out = Command::new(&harness)
            .arg(elf)
            .args(["-m", model.mcu(), "--until", &timing.until_ms.to_string()])
            .args(["--every", &timing.every_ms.to_string(), "--lag", &lag_us.to_string()])
            .args(timing.from_first_scan.then_some("--from-first-scan"))
            .args(
                eeprom
                    .map(|e| ["--eeprom".as_ref(), e.as_os_str()])
                    .into_iter()
                    .flatten(),
            )
            .args(["--pins", &pins.join(",")])
            .args(["--mem", &mem_arg.join(",")])
            .arg("--stimulus")
            .arg(&stim_file)
            .arg("-o")
            .arg(&trace_file)
            .output()
            .map_err(|e| tool_error(format!("cannot run the simavr harness: {e}")))?;
        let log = String::from_utf8_lossy(&out.stderr).into_owned();
        if !out.status.success() {
            return Err(tool_error(format!(
                "the firmware run in simavr failed:\n{}",
                log.trim_end()
            )));
        }
        let text =
            std::fs::read_to_string(&trace_file).map_err(|e| tool_error(format!("cannot read the pin trace: {e}")))?;
        Ok((text, profile(&log)))
    })();
    let _ = std::fs::remove_dir_all(&work);
    let (pin_trace, profile) = result.map_err(|d| vec![d])?;
    let trace = tag_trace(&pin_trace, wiring, active_low, &given, cols, &regions, init).map_err(|d| vec![d])?;
    Ok(Run { trace, profile })
}

/// The firmware's static variables as (name, data-space address, bytes),
/// from the ELF's symbols (`avr-nm -S`); C++ statics keep their mangled
/// names (`_ZL1B` for `static bool B[…]`).
pub fn symbols(elf: &Path) -> Result<Vec<(String, u32, u32)>, Diagnostic> {
    let nm = run(
        Command::new("avr-nm").arg("-S").arg(elf),
        "reading the firmware's symbols",
    )?;
    Ok(nm
        .lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let (addr, size, name) = match f.len() {
                4 => (f[0], f[1], f[3]),
                3 => (f[0], "0", f[2]),
                _ => return None,
            };
            // Data-space addresses carry avr-gcc's 0x800000 offset.
            let addr = u32::from_str_radix(addr, 16).ok()?;
            (addr & 0xFF_0000 == 0x80_0000)
                .then(|| Some((name.to_string(), addr & 0xFFFF, u32::from_str_radix(size, 16).ok()?)))?
        })
        .collect())
}

/// What [`run_watched`] samples and watches: `pins` (`D12`, `D6:pwm`,
/// `D13:drive`) and the memory regions `mem` (data-space address, bytes)
/// every `every_ms` to `until_ms` from the reset; the stores the firmware
/// must not make: into `forbid` once the first scan has started, and at any
/// time between `free_ram` and the stack pointer. `inputs` drive pins
/// (`(ms, "D2", 1)`, in time order; at 0, from the reset on), and with
/// `serial` the lines the firmware sends on its serial port are kept.
#[derive(Debug, Clone, Default)]
pub struct Watch {
    pub pins: Vec<String>,
    pub mem: Vec<(u32, u32)>,
    pub until_ms: u64,
    pub every_ms: u64,
    pub forbid: Vec<(u32, u32)>,
    pub free_ram: Option<u32>,
    pub inputs: Vec<(u64, String, i32)>,
    pub serial: bool,
}

/// What [`run_watched`] saw.
#[derive(Debug, Clone)]
pub struct Watched {
    /// The harness's trace: `time_ms`, then each pin, then each memory region in hex.
    pub trace: String,
    pub profile: Profile,
    /// Scans started (a runaway scan never ends, but it started).
    pub scan_starts: u64,
    /// The forbidden stores (the first 20, as the harness reports them), and how many.
    pub forbidden: Vec<String>,
    pub forbidden_count: u64,
    /// With [`Watch::serial`], each line the firmware sent: the time (ms from
    /// the reset) its end of line went out, and the line.
    pub serial: Vec<(u64, String)>,
}

/// Runs `elf` in the harness with no stimulus, its EEPROM from `eeprom`,
/// under `watch`: for tests of the firmware itself (what it runs, what it
/// stores).
pub fn run_watched(elf: &Path, model: Model, eeprom: Option<&Path>, watch: &Watch) -> Result<Watched, Diagnostic> {
    let harness = harness()?;
    let work = temp_sibling(&elf.with_file_name("watched"));
    std::fs::create_dir_all(&work).map_err(|e| tool_error(format!("cannot create {}: {e}", work.display())))?;
    let trace_file = work.join("trace.csv");
    let serial_file = work.join("serial.txt");
    let stimulus_file = work.join("stimulus.csv");
    let join = |r: &[(u32, u32)]| r.iter().map(|(a, n)| format!("{a}:{n}")).collect::<Vec<_>>().join(",");
    let mut cmd = Command::new(&harness);
    if !watch.inputs.is_empty() {
        let text: String = watch
            .inputs
            .iter()
            .map(|(t, pin, v)| format!("{t},{pin},{v}\n"))
            .collect();
        std::fs::write(&stimulus_file, text)
            .map_err(|e| tool_error(format!("cannot write {}: {e}", stimulus_file.display())))?;
        cmd.arg("--stimulus").arg(&stimulus_file);
    }
    if watch.serial {
        cmd.arg("--serial").arg(&serial_file);
    }
    let out = cmd
        .arg(elf)
        .args(["-m", model.mcu(), "--until", &watch.until_ms.to_string()])
        .args(["--every", &watch.every_ms.to_string()])
        .args(
            eeprom
                .map(|e| ["--eeprom".as_ref(), e.as_os_str()])
                .into_iter()
                .flatten(),
        )
        .args(["--pins", &watch.pins.join(","), "--mem", &join(&watch.mem)])
        .args(["--forbid", &join(&watch.forbid)])
        .args(["--free-ram", &watch.free_ram.unwrap_or(0).to_string()])
        .arg("-o")
        .arg(&trace_file)
        .output();
    let trace = std::fs::read_to_string(&trace_file);
    let serial = std::fs::read_to_string(&serial_file).unwrap_or_default();
    let _ = std::fs::remove_dir_all(&work);
    let out = out.map_err(|e| tool_error(format!("cannot run the simavr harness: {e}")))?;
    let log = String::from_utf8_lossy(&out.stderr).into_owned();
    // 3: it ran, and made forbidden stores
    if !out.status.success() && out.status.code() != Some(3) {
        return Err(tool_error(format!(
            "the firmware run in simavr failed:\n{}",
            log.trim_end()
        )));
    }
    let count = |prefix: &str| {
        log.lines()
            .find_map(|l| l.strip_prefix(prefix)?.trim().parse().ok())
            .unwrap_or(0)
    };
    Ok(Watched {
        trace: trace.map_err(|e| tool_error(format!("cannot read the pin trace: {e}")))?,
        profile: profile(&log),
        scan_starts: count("alba-simavr: scan starts "),
        forbidden: log
            .lines()
            .filter(|l| l.starts_with("alba-simavr: forbidden write "))
            .map(str::to_string)
            .collect(),
        forbidden_count: count("alba-simavr: forbidden writes "),
        serial: serial
            .lines()
            .filter_map(|l| {
                let (t, text) = l.split_once(' ')?;
                Some((t.parse().ok()?, text.to_string()))
            })
            .collect(),
    })
}

fn profile(log: &str) -> Profile {
    log.lines()
        .find_map(|l| {
            let rest = l.strip_prefix("alba-simavr: scans ")?;
            let n: Vec<u64> = rest.split_whitespace().filter_map(|w| w.parse().ok()).collect();
            (n.len() == 4).then(|| Profile {
                scans: n[0],
                min: n[1],
                mean: n[2],
                max: n[3],
            })
        })
        .unwrap_or_default()
}

/// The pin trace as tag values: outputs through active-low, analog outputs as
/// duty, inputs as the value last given.
/// The firmware's memory arrays (`B`, `I`, `F`, `L`, `M` of the sketch, or
/// of the byte-code interpreter) as (class, data-space address, bytes), from
/// the ELF's symbols, checked to hold the program's memory.
fn memory_regions(elf: &Path, init: &alba_ir::Memory) -> Result<Vec<(char, u32, u32)>, Diagnostic> {
    let syms = symbols(elf)?;
    let want = [
        ('B', init.b.len()),
        ('I', 4 * init.i.len()),
        ('F', 4 * init.f.len()),
        ('L', 8 * init.l.len()),
        ('M', init.m.len()),
    ];
    let mut out = Vec::new();
    for (class, size) in want.into_iter().filter(|w| w.1 > 0) {
        let name = format!("_ZL1{class}");
        match syms.iter().find(|s| s.0 == name) {
            // (the byte-code interpreter's arrays are larger than the program: its first `size` bytes)
            Some((_, addr, len)) if *len as usize >= size => out.push((class, *addr, size as u32)),
            _ => {
                return Err(tool_error(format!(
                    "the firmware has no memory array {class} of {size} bytes: is it an Alba sketch of this program?"
                )));
            }
        }
    }
    Ok(out)
}

/// A memory image from the harness's hex dumps (AVR: little-endian).
fn memory_of(dumps: &[&str], regions: &[(char, u32, u32)], init: &alba_ir::Memory) -> Option<alba_ir::Memory> {
    let mut m = init.clone();
    for (hex, (class, _, _)) in dumps.iter().zip(regions) {
        let bytes: Vec<u8> = (0..hex.len() / 2)
            .map(|k| u8::from_str_radix(hex.get(2 * k..2 * k + 2)?, 16).ok())
            .collect::<Option<_>>()?;
        match class {
            'B' => m.b = bytes.iter().map(|b| *b != 0).collect(),
            'I' => {
                m.i = bytes
                    .chunks(4)
                    .map(|c| i32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect()
            }
            'F' => {
                m.f = bytes
                    .chunks(4)
                    .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect()
            }
            'L' => {
                m.l = bytes
                    .chunks(8)
                    .map(|c| i64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
                    .collect()
            }
            _ => m.m = bytes,
        }
    }
    Some(m)
}

fn tag_trace(
    pin_trace: &str,
    wiring: &[Wire],
    active_low: bool,
    given: &[(u64, Address, i64)],
    cols: &[Column],
    regions: &[(char, u32, u32)],
    init: &alba_ir::Memory,
) -> Result<String, Diagnostic> {
    let mut out = String::from("time_ms");
    for c in cols {
        out.push(',');
        out.push_str(&c.name);
    }
    out.push('\n');
    for line in pin_trace.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let bad = || tool_error(format!("the harness wrote a malformed row: `{line}`"));
        let npins = fields.len().checked_sub(1 + regions.len()).ok_or_else(bad)?;
        let mem = if regions.is_empty() {
            None
        } else {
            Some(memory_of(&fields[1 + npins..], regions, init).ok_or_else(bad)?)
        };
        let t: u64 = fields[0].parse().map_err(|_| bad())?;
        out.push_str(fields[0]);
        let mut pin_fields = fields[1..1 + npins].iter();
        for c in cols {
            let Some(w) = wire_of(wiring, c.place) else {
                let m = mem.as_ref().ok_or_else(bad)?;
                let _ = write!(out, ",{}", m.read(c.place));
                continue;
            };
            let v: i64 = pin_fields.next().ok_or_else(bad)?.parse().map_err(|_| bad())?;
            let v = match w.address {
                Address::DigitalOut(_) => v ^ i64::from(active_low),
                Address::DigitalIn(_) | Address::AnalogIn(_) => given
                    .iter()
                    .rev()
                    .find(|(at, a, _)| *at <= t && *a == w.address)
                    .map_or(0, |a| a.2),
                _ => v,
            };
            let _ = write!(out, ",{v}");
        }
        out.push('\n');
    }
    Ok(out)
}
