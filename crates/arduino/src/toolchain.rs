//! Building a sketch with avr-gcc against the Arduino AVR core (Debian's
//! `gcc-avr`, `avr-libc`, `arduino-core-avr`), the flash/RAM report against
//! the board's limits, and uploading with `avrdude`.
//!
//! The flags are those of `scripts/avr.sh`: Debian's gcc-avr 5.4 builds the
//! core only as gnu++11 with `-DDECIMAL_DIG=__DECIMAL_DIG__`; the core is
//! built once per board into a cache (its own warnings silenced), the sketch
//! with `-Wall -Werror`.

use alba_diag::{Code, Diagnostic};
use alba_model::board::Model;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Where the Arduino AVR core is installed (Debian's `arduino-core-avr`).
pub const AVR_CORE: &str = "/usr/share/arduino/hardware/arduino/avr";

/// RAM kept free for the stack (call frames of the scan and the runtime
/// functions, interrupt handlers): a firmware whose static RAM leaves less is
/// refused. The deepest stack of a generated sketch is well under 100 bytes.
pub const STACK_RESERVE: u32 = 256;

/// A built firmware and what it uses.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Built {
    pub elf: PathBuf,
    pub hex: PathBuf,
    /// Bytes of flash (text + data) and of static RAM (data + bss).
    pub flash: u32,
    pub ram: u32,
    pub model: Model,
}

impl Built {
    /// `uno: flash 2 474 of 32 256 bytes (7%), RAM 112 of 2 048 bytes (5%)`.
    pub fn report(&self) -> String {
        let (flash, ram) = self.model.limits();
        format!(
            "{}: flash {} of {} bytes ({}%), RAM {} of {} bytes ({}%, {} left for the stack)",
            self.model.name(),
            self.flash,
            flash,
            100 * self.flash / flash,
            self.ram,
            ram,
            100 * self.ram / ram,
            ram.saturating_sub(self.ram)
        )
    }
}

/// The cache for built cores and the simavr harness: `$ALBA_AVR_CACHE`, else
/// `$XDG_CACHE_HOME/alba/avr`, else `~/.cache/alba/avr`.
pub fn cache_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("ALBA_AVR_CACHE") {
        return PathBuf::from(d);
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("alba").join("avr")
}

fn variant(model: Model) -> &'static str {
    match model {
        Model::Uno => "standard",
        Model::Nano => "eightanaloginputs",
        Model::Mega => "mega",
    }
}

fn common_flags(model: Model) -> Vec<String> {
    vec![
        format!("-mmcu={}", model.mcu()),
        "-DF_CPU=16000000L".into(),
        "-DARDUINO=10807".into(),
        "-DARDUINO_ARCH_AVR".into(),
        "-Os".into(),
        "-Wall".into(),
        "-ffunction-sections".into(),
        "-fdata-sections".into(),
        format!("-I{AVR_CORE}/cores/arduino"),
        format!("-I{AVR_CORE}/variants/{}", variant(model)),
    ]
}

const CXX_FLAGS: &[&str] = &[
    "-std=gnu++11",
    "-DDECIMAL_DIG=__DECIMAL_DIG__",
    "-fno-exceptions",
    "-fno-threadsafe-statics",
];

pub(crate) fn tool_error(msg: impl Into<String>) -> Diagnostic {
    Diagnostic::unplaced(Code::Toolchain, msg)
}

/// Runs a tool, turning a missing tool or a failure into an E503 with its output.
pub(crate) fn run(cmd: &mut Command, what: &str) -> Result<String, Diagnostic> {
    let prog = cmd.get_program().to_string_lossy().into_owned();
    let out = cmd.output().map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            tool_error(format!(
                "{prog} was not found: install gcc-avr, avr-libc and arduino-core-avr (Debian), or run ./test.sh once"
            ))
        } else {
            tool_error(format!("{what}: cannot run {prog}: {e}"))
        }
    })?;
    if !out.status.success() {
        let mut text = String::from_utf8_lossy(&out.stderr).into_owned();
        text.push_str(&String::from_utf8_lossy(&out.stdout));
        return Err(tool_error(format!(
            "{what} failed ({}):\n{}",
            out.status,
            text.trim_end()
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// A fresh directory next to `dst`, renamed into place when complete, so a
/// cache entry is never seen half-built (concurrent builders race harmlessly).
pub(crate) fn temp_sibling(dst: &Path) -> PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    let name = dst.file_name().map_or("x".into(), |n| n.to_string_lossy().into_owned());
    dst.with_file_name(format!(
        ".{name}.tmp-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ))
}

/// The Arduino core for a board, built once into the cache.
fn core(model: Model, cache: &Path) -> Result<PathBuf, Diagnostic> {
    let dir = cache.join(format!("core-{}", model.name()));
    let lib = dir.join("core.a");
    if lib.is_file() {
        return Ok(lib);
    }
    let src = Path::new(AVR_CORE).join("cores/arduino");
    let entries = std::fs::read_dir(&src).map_err(|e| {
        tool_error(format!(
            "the Arduino AVR core is not at {}: {e} (install arduino-core-avr)",
            src.display()
        ))
    })?;
    let tmp = temp_sibling(&dir);
    std::fs::create_dir_all(&tmp).map_err(|e| tool_error(format!("cannot create {}: {e}", tmp.display())))?;
    let mut sources: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    sources.sort();
    let mut objs = Vec::new();
    for f in sources {
        let ext = f.extension().and_then(|e| e.to_str()).unwrap_or("");
        let Some(name) = f.file_name().map(|n| n.to_string_lossy().into_owned()) else {
            continue;
        };
        let o = tmp.join(format!("{name}.o"));
        let mut cmd = match ext {
            "cpp" => {
                let mut c = Command::new("avr-g++");
                c.args(common_flags(model)).args(CXX_FLAGS).args(["-fpermissive", "-w"]);
                c
            }
            "c" => {
                let mut c = Command::new("avr-gcc");
                c.args(common_flags(model)).args(["-std=gnu11", "-w"]);
                c
            }
            "S" => {
                let mut c = Command::new("avr-gcc");
                c.args(common_flags(model)).args(["-x", "assembler-with-cpp"]);
                c
            }
            _ => continue,
        };
        cmd.arg("-c").arg(&f).arg("-o").arg(&o);
        run(&mut cmd, &format!("building the Arduino core ({name})"))?;
        objs.push(o);
    }
    run(
        Command::new("avr-gcc-ar")
            .arg("rcs")
            .arg(tmp.join("core.a"))
            .args(&objs),
        "archiving the Arduino core",
    )?;
    // Another builder may have won the race: theirs is as good as ours.
    if std::fs::rename(&tmp, &dir).is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    if lib.is_file() {
        Ok(lib)
    } else {
        Err(tool_error(format!(
            "the core was built but {} is missing",
            lib.display()
        )))
    }
}

/// Builds `sketch` (an `.ino` or `.cpp`) for a board into `out`
/// (`sketch.elf`, `sketch.hex`), with every warning an error, and checks
/// flash and RAM against the board (E502 when it does not fit).
pub fn build(sketch: &Path, model: Model, out: &Path) -> Result<Built, Diagnostic> {
    build_with(sketch, model, out, &[])
}

/// [`build`] with more folders searched for `#include <…>`: an Arduino
/// library's `src/` (the `PLC.h` library, `library/PLC/`).
pub fn build_with(sketch: &Path, model: Model, out: &Path, includes: &[&Path]) -> Result<Built, Diagnostic> {
    let cache = cache_dir();
    std::fs::create_dir_all(&cache).map_err(|e| tool_error(format!("cannot create {}: {e}", cache.display())))?;
    std::fs::create_dir_all(out).map_err(|e| tool_error(format!("cannot create {}: {e}", out.display())))?;
    let core = core(model, &cache)?;
    let obj = out.join("sketch.o");
    run(
        Command::new("avr-g++")
            .args(common_flags(model))
            .args(CXX_FLAGS)
            .args(["-Werror", "-x", "c++", "-include", "Arduino.h", "-c"])
            .args(includes.iter().map(|d| format!("-I{}", d.display())))
            .arg(sketch)
            .arg("-o")
            .arg(&obj),
        "compiling the sketch",
    )?;
    let elf = out.join("sketch.elf");
    let hex = out.join("sketch.hex");
    run(
        Command::new("avr-gcc")
            .arg(format!("-mmcu={}", model.mcu()))
            .args(["-Os", "-Wl,--gc-sections"])
            // Regions larger than any board, so a firmware that does not fit
            // still links and is measured: the check below reports it (E502)
            // with its sizes, rather than the linker's region errors.
            .args([
                "-Wl,--defsym=__TEXT_REGION_LENGTH__=0x100000",
                "-Wl,--defsym=__DATA_REGION_LENGTH__=0xff00",
                "-o",
            ])
            .arg(&elf)
            .arg(&obj)
            .arg(&core)
            .arg("-lm"),
        "linking the firmware",
    )?;
    run(
        Command::new("avr-objcopy")
            .args(["-O", "ihex", "-R", ".eeprom"])
            .arg(&elf)
            .arg(&hex),
        "writing the .hex file",
    )?;
    let built = measure(elf, hex, model)?;
    let (flash, ram) = model.limits();
    if built.flash > flash || built.ram + STACK_RESERVE > ram {
        return Err(Diagnostic::unplaced(
            Code::DoesNotFit,
            format!(
                "the firmware needs {} bytes of flash and {} bytes of RAM plus {STACK_RESERVE} for the stack; the {} has {flash} and {ram}",
                built.flash,
                built.ram,
                model.title()
            ),
        )
        .with_help("shorten the program or use fewer tags, or choose a board with more memory (mega)"));
    }
    Ok(built)
}

/// The flash and RAM a built firmware uses (`avr-size`).
pub fn measure(elf: PathBuf, hex: PathBuf, model: Model) -> Result<Built, Diagnostic> {
    let sizes = run(Command::new("avr-size").arg("-A").arg(&elf), "measuring the firmware")?;
    let section = |name: &str| -> u32 {
        sizes
            .lines()
            .find_map(|l| {
                let mut f = l.split_whitespace();
                (f.next() == Some(name)).then(|| f.next().and_then(|s| s.parse().ok()))?
            })
            .unwrap_or(0)
    };
    let (text, data, bss) = (section(".text"), section(".data"), section(".bss"));
    Ok(Built {
        elf,
        hex,
        flash: text + data,
        ram: data + bss,
        model,
    })
}

/// The avrdude command that uploads a built firmware (the Uno's bootloader
/// at 115200 baud, the Nano's at 57600; the Mega's stk500v2): [`upload`],
/// and the studio's Upload job, which reads its progress bar.
pub fn upload_command(built: &Built, port: &str) -> Command {
    let (programmer, baud, part) = match built.model {
        Model::Uno => ("arduino", "115200", "m328p"),
        Model::Nano => ("arduino", "57600", "m328p"),
        Model::Mega => ("wiring", "115200", "m2560"),
    };
    let mut cmd = Command::new("avrdude");
    cmd.args(["-p", part, "-c", programmer, "-P", port, "-b", baud, "-D", "-U"])
        .arg(format!("flash:w:{}:i", built.hex.display()));
    cmd
}

/// Uploads a built firmware with avrdude ([`upload_command`]).
pub fn upload(built: &Built, port: &str) -> Result<(), Diagnostic> {
    let mut cmd = upload_command(built, port);
    run(&mut cmd, &format!("uploading to {port}")).map(|_| ()).map_err(|d| {
        if d.message.contains("was not found") {
            tool_error("avrdude was not found: install it (Debian package avrdude)")
        } else {
            d
        }
    })
}
