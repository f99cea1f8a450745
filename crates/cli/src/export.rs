//! `alba export arduino` and `alba sim --firmware`: the project's control
//! program as an Arduino sketch, built, uploaded, or run in simavr.

use crate::report;
use alba_arduino::sketch::{self, Sketch, Target};
use alba_arduino::{simavr, toolchain};
use alba_compiler::Compiled;
use alba_diag::{Code, Diagnostic};
use alba_model::address::Address;
use alba_model::board::{Model, PRESETS, PinMap};
use alba_model::fsutil;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Board options of the command line; what is not given comes from `[board]`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct BoardArgs {
    /// Board: uno, nano or mega (default: `[board]` of alba.toml).
    #[arg(long, value_name = "MODEL")]
    pub board: Option<String>,
    /// Pin map preset: aurora, s7 or openplc (default: `[board]`, else aurora).
    #[arg(long, value_name = "PRESET")]
    pub pinmap: Option<String>,
    /// Leave out the monitoring link (frees about 350 bytes of RAM and the serial port).
    #[arg(long)]
    pub no_monitor: bool,
}

fn bad(msg: String) -> Diagnostic {
    Diagnostic::unplaced(Code::BadArgument, msg)
}

/// The board to build for: the command line over `[board]` (the studio's
/// code too: `alba_app::hardware::target`).
pub fn target(c: &Compiled, args: &BoardArgs) -> Result<Target, Diagnostic> {
    alba_app::hardware::target(c, args.board.as_deref(), args.pinmap.as_deref(), !args.no_monitor)
}

/// Compiles and generates, reporting any problem.
fn sketch_of(dir: &Path, args: &BoardArgs) -> Result<(Compiled, Target, alba_ir::Program, Sketch), ExitCode> {
    let c = alba_load::compile_dir(dir);
    let Some(program) = &c.program else {
        report(&c.diagnostics, c.files(), false);
        return Err(ExitCode::FAILURE);
    };
    let t = match target(&c, args) {
        Ok(t) => t,
        Err(d) => {
            report(&[d], c.files(), false);
            return Err(ExitCode::FAILURE);
        }
    };
    let prog = sketch::control_program(program);
    let name = c
        .project
        .config
        .as_ref()
        .map_or("alba", |c| c.name.as_str())
        .to_string();
    match sketch::generate(&prog, &name, &t) {
        Ok(s) => Ok((c, t, prog, s)),
        Err(d) => {
            report(&d, c.files(), false);
            Err(ExitCode::FAILURE)
        }
    }
}

fn wiring_table(s: &Sketch, prog: &alba_ir::Program) -> String {
    let mut out = String::new();
    for w in &s.wiring {
        let tag = prog
            .layout
            .tags
            .iter()
            .find(|t| t.address == Some(w.address))
            .map_or(String::new(), |t| format!("  {}", t.name));
        let dir = match w.address {
            Address::DigitalIn(_) | Address::AnalogIn(_) => "in ",
            _ => "out",
        };
        out.push_str(&format!(
            "  {dir} {:<8} {:<4}{tag}\n",
            w.address.to_string(),
            w.pin.to_string()
        ));
    }
    out
}

/// `alba export arduino`.
pub fn export(dir: &Path, args: &BoardArgs, out: &Path, build: bool, upload: Option<&str>) -> ExitCode {
    let (c, t, prog, s) = match sketch_of(dir, args) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let folder = out.join(&s.name);
    if let Err(d) = write_folder(&folder, &s.files) {
        report(&[d], c.files(), false);
        return ExitCode::FAILURE;
    }
    eprintln!(
        "wrote {} for the {} (scan {} ms), wired:\n{}",
        folder.join(&s.files[0].0).display(),
        t.model.title(),
        t.scan_ms,
        wiring_table(&s, &prog)
    );
    if !build && upload.is_none() {
        return ExitCode::SUCCESS;
    }
    build_and_upload(&folder.join(&s.files[0].0), t.model, upload)
}

/// Writes a sketch folder's files atomically.
fn write_folder(folder: &Path, files: &[(String, String)]) -> Result<(), Diagnostic> {
    for (name, text) in files {
        let path = folder.join(name);
        std::fs::create_dir_all(folder)
            .and_then(|()| fsutil::write_atomic(&path, |w| w.write_all(text.as_bytes())))
            .map_err(|e| Diagnostic::unplaced(Code::Io, format!("cannot write {}: {e}", path.display())))?;
    }
    Ok(())
}

/// The byte code of `prog` for `t`, or `None` with its refusals reported.
fn encoded(c: &Compiled, prog: &alba_ir::Program, name: &str, t: &Target) -> Option<alba_arduino::bytecode::Bytecode> {
    alba_arduino::bytecode::encode(prog, name, t)
        .map_err(|d| report(&d, c.files(), false))
        .ok()
}

/// `alba export bytecode`: the board's checks as for a sketch, then the byte
/// code, written atomically as Intel HEX (`.hex`) or raw bytes.
pub fn bytecode(dir: &Path, args: &BoardArgs, out: &Path) -> ExitCode {
    let (c, t, prog, s) = match sketch_of(dir, args) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let Some(bc) = encoded(&c, &prog, &s.name, &t) else {
        return ExitCode::FAILURE;
    };
    let hex = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("hex"));
    let bytes = if hex {
        alba_arduino::ihex::write(&bc.bytes).into_bytes()
    } else {
        bc.bytes.clone()
    };
    if let Err(e) = fsutil::write_atomic(out, |w| w.write_all(&bytes)) {
        report(
            &[Diagnostic::unplaced(
                Code::Io,
                format!("cannot write {}: {e}", out.display()),
            )],
            c.files(),
            false,
        );
        return ExitCode::FAILURE;
    }
    eprintln!(
        "wrote {}: {} bytes of byte code for the {} ({} ops in {} bytes, program id {:08x}){}",
        out.display(),
        bc.bytes.len(),
        t.model.title(),
        bc.ops,
        bc.code_len,
        bc.program_id,
        if hex { ", as Intel HEX" } else { "" }
    );
    ExitCode::SUCCESS
}

/// Downloads `bytes` with `alba download`'s protocol into the interpreter
/// `elf` running on the emulated board (simavr paced to real time, its serial
/// port on a pty); returns the EEPROM image it leaves.
fn download_emulated(elf: &Path, model: Model, dir: &Path, bytes: &[u8]) -> Result<PathBuf, Vec<Diagnostic>> {
    use std::io::{BufRead, Write};
    let io = |m: String| vec![Diagnostic::unplaced(Code::Io, m)];
    let board = simavr::board().map_err(|d| vec![d])?;
    let (ee, link) = (dir.join("eeprom.bin"), dir.join("link"));
    let _ = std::fs::remove_file(&ee);
    let mut child = std::process::Command::new(board)
        .arg(elf)
        .args(["-m", model.mcu(), "--tty"])
        .arg(&link)
        .args(["--pins", "D13", "--eeprom"])
        .arg(&ee)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .map_err(|e| io(format!("cannot start the emulated board: {e}")))?;
    let result = (|| {
        let mut ready = String::new();
        let out = child
            .stdout
            .take()
            .ok_or_else(|| io("the emulated board has no output".into()))?;
        std::io::BufReader::new(out)
            .read_line(&mut ready)
            .map_err(|e| io(e.to_string()))?;
        if !ready.starts_with("ready ") {
            return Err(io(format!("the emulated board did not start: {ready}")));
        }
        let mut l = alba_io::download::Link::open(&link.to_string_lossy()).map_err(|e| io(e.to_string()))?;
        l.download(bytes, |_, _| {}).map_err(|e| io(format!("download: {e}")))?;
        Ok(())
    })();
    if let Some(mut stdin) = child.stdin.take() {
        let _ = writeln!(stdin, "quit");
    }
    let _ = child.wait();
    result?;
    Ok(ee)
}

/// The board an interpreter is for: a project's `[board]` under the command
/// line's options, or `--board` and `--pinmap` alone (outputs active high);
/// a problem is reported.
fn interpreter_target(project: Option<&Path>, args: &BoardArgs) -> Result<Target, ExitCode> {
    let refuse = |d: Diagnostic, files: &alba_diag::Files| {
        report(&[d], files, false);
        ExitCode::FAILURE
    };
    if let Some(dir) = project {
        let c = alba_load::compile_dir(dir);
        if c.project.config.is_none() {
            report(&c.diagnostics, c.files(), false);
            return Err(ExitCode::FAILURE);
        }
        return target(&c, args).map_err(|d| refuse(d, c.files()));
    }
    let files = alba_diag::Files::new();
    let model = match args.board.as_deref().map(Model::parse) {
        Some(Some(m)) => m,
        _ => {
            return Err(refuse(
                bad("give --board uno|nano|mega, or a project with a [board] section".into()),
                &files,
            ));
        }
    };
    let Some(map) = PinMap::preset(args.pinmap.as_deref().unwrap_or("aurora")) else {
        return Err(refuse(
            bad(format!("--pinmap: the presets are {}", PRESETS.join(", "))),
            &files,
        ));
    };
    Ok(Target {
        model,
        map,
        active_low: false,
        scan_ms: 10,
        monitor: true,
        power_up_on: Vec::new(),
    })
}

/// `alba export interpreter`: the byte-code interpreter's sketch folder for
/// a board and pin map (no program: any program for them is downloaded later).
pub fn interpreter(
    project: Option<&Path>,
    args: &BoardArgs,
    out: &Path,
    build: bool,
    upload: Option<&str>,
) -> ExitCode {
    let t = match interpreter_target(project, args) {
        Ok(t) => t,
        Err(code) => return code,
    };
    let folder = out.join("alba_interp");
    if let Err(d) = write_folder(&folder, &alba_arduino::interp::generate(&t, None)) {
        report(&[d], &alba_diag::Files::new(), false);
        return ExitCode::FAILURE;
    }
    eprintln!(
        "wrote {} for the {} (board id {:04x}: this pin map{})",
        folder.join("alba_interp.ino").display(),
        t.model.title(),
        alba_arduino::bytecode::board_id(&t),
        if t.active_low { ", outputs active low" } else { "" }
    );
    if !build && upload.is_none() {
        return ExitCode::SUCCESS;
    }
    build_and_upload(&folder.join("alba_interp.ino"), t.model, upload)
}

/// `alba download`: the project's byte code to a board running the
/// interpreter (the studio's Download runs the same `alba_app::hardware::download`).
pub fn download(dir: &Path, args: &BoardArgs, port: &str, verify: bool) -> ExitCode {
    use alba_app::hardware::DownloadFailure;
    let c = alba_load::compile_dir(dir);
    let mut shown = false;
    let result = alba_app::hardware::download(
        &c,
        args.board.as_deref(),
        args.pinmap.as_deref(),
        port,
        verify,
        |done, total| {
            shown = true;
            eprint!("\rdownloading: {done}/{total} records");
            true
        },
    );
    if shown {
        eprintln!();
    }
    let d = match result {
        Ok(d) => d,
        Err(DownloadFailure::Project(d)) => {
            report(&d, c.files(), false);
            return ExitCode::FAILURE;
        }
        Err(DownloadFailure::NotOnBoard(why)) => {
            report(
                &[Diagnostic::unplaced(
                    Code::NotOnBoard,
                    format!("not downloaded to {port}: {why}"),
                )],
                c.files(),
                false,
            );
            return ExitCode::FAILURE;
        }
        Err(DownloadFailure::Link(e)) => {
            report(&[Diagnostic::unplaced(Code::Io, e.to_string())], c.files(), false);
            return ExitCode::FAILURE;
        }
    };
    let retried = match d.retries {
        0 => String::new(),
        1 => " (1 record sent again after a line error)".to_string(),
        n => format!(" ({n} records sent again after line errors)"),
    };
    eprintln!(
        "downloaded {} bytes to {port} in {} ms{retried}, checksum {:04X}: the board runs the new program",
        d.bytes, d.ms, d.checksum
    );
    if d.verified {
        eprintln!("verified: the board holds the {} bytes sent", d.bytes);
    }
    ExitCode::SUCCESS
}

/// `alba download --read`: the board's running program (its header's length,
/// or the whole slot when the header is not a program's) into `out`.
pub fn read_back(port: &str, out: &Path) -> ExitCode {
    use alba_arduino::bytecode::{self, HEADER_LEN};
    use alba_io::download::BoardState;
    let files = alba_diag::Files::new();
    let fail = |d: Diagnostic| {
        report(&[d], &files, false);
        ExitCode::FAILURE
    };
    let io = |e: alba_io::download::DownloadError| Diagnostic::unplaced(Code::Io, e.to_string());
    let read = (|| {
        let mut link = alba_io::download::Link::open(port)?;
        let id = link.identify()?;
        let head = link.read(0, HEADER_LEN)?;
        let len = u32::from_le_bytes([head[16], head[17], head[18], head[19]]) as usize;
        let n = if head[..4] == bytecode::MAGIC && HEADER_LEN + len <= usize::from(id.slot) {
            HEADER_LEN + len
        } else {
            usize::from(id.slot)
        };
        let mut bytes = head;
        bytes.extend(link.read(HEADER_LEN as u16, n - HEADER_LEN)?);
        Ok((id, bytes))
    })();
    let (id, bytes) = match read {
        Ok(x) => x,
        Err(e) => return fail(io(e)),
    };
    let hex = out.as_os_str() == "-" || out.extension().is_some_and(|e| e.eq_ignore_ascii_case("hex"));
    let data = if hex {
        alba_arduino::ihex::write(&bytes).into_bytes()
    } else {
        bytes.clone()
    };
    let written = if out.as_os_str() == "-" {
        std::io::Write::write_all(&mut std::io::stdout(), &data)
    } else {
        fsutil::write_atomic(out, |w| w.write_all(&data))
    };
    if let Err(e) = written {
        return fail(Diagnostic::unplaced(
            Code::Io,
            format!("cannot write {}: {e}", out.display()),
        ));
    }
    let board = id.title();
    let state = match id.state {
        BoardState::Running => "running it",
        BoardState::NoProgram => "no program that checks: outputs safe",
        BoardState::Faulted => "stopped on a major fault",
    };
    let what = match bytecode::decode(&bytes) {
        Ok(d) => format!(
            "program id {:08x}, board id {:04x}, {} ops, CRC good",
            d.program_id,
            d.board_id,
            d.program.ops.len()
        ),
        Err(e) => format!("not a program that checks: {e}"),
    };
    eprintln!(
        "read {} bytes of the running program slot of the {board} on {port} ({state}) into {}: {what}",
        bytes.len(),
        if out.as_os_str() == "-" {
            "standard output".to_string()
        } else {
            out.display().to_string()
        }
    );
    ExitCode::SUCCESS
}

/// Builds a sketch into `build/` beside it, reports its size, and uploads it
/// when a port is given (`alba export arduino`, `alba firmware`).
pub fn build_and_upload(sketch: &Path, model: Model, upload: Option<&str>) -> ExitCode {
    let files = alba_diag::Files::new();
    let dir = sketch.parent().unwrap_or(Path::new("."));
    let built = match toolchain::build(sketch, model, &dir.join("build")) {
        Ok(b) => b,
        Err(d) => {
            report(&[d], &files, false);
            return ExitCode::FAILURE;
        }
    };
    eprintln!("built {}\n{}", built.hex.display(), built.report());
    if let Some(port) = upload {
        if let Err(d) = toolchain::upload(&built, port) {
            report(&[d], &files, false);
            return ExitCode::FAILURE;
        }
        eprintln!("uploaded to {port}");
    }
    ExitCode::SUCCESS
}

/// `alba sim --firmware`: the trace of the generated firmware in simavr.
pub fn simulate(
    dir: &Path,
    args: &BoardArgs,
    stimulus: &alba_engine::sim::Stimulus,
    cols: &[alba_engine::sim::Column],
    timing: simavr::Timing,
    bytecode: bool,
) -> Result<String, ExitCode> {
    let (c, t, prog, s) = sketch_of(dir, args)?;
    let work: PathBuf = std::env::temp_dir().join(format!("alba-firmware-{}", std::process::id()));
    let folder = work.join(&s.name);
    let result = (|| -> Result<String, Vec<Diagnostic>> {
        std::fs::create_dir_all(&folder).map_err(|e| vec![Diagnostic::unplaced(Code::Io, e.to_string())])?;
        // The sketch, or the byte-code interpreter (built once for the board, then
        // cached) and the project's byte code to download into it.
        let (built, program) = if bytecode {
            let bc = alba_arduino::bytecode::encode(&prog, &s.name, &t)?;
            let (built, cached) = alba_arduino::interp::firmware(&t).map_err(|d| vec![d])?;
            eprintln!(
                "interpreter firmware for the {}: {} ({})",
                t.model.title(),
                built.elf.display(),
                if cached { "cached" } else { "built, and cached" }
            );
            (built, Some(bc.bytes))
        } else {
            for (name, text) in &s.files {
                std::fs::write(folder.join(name), text)
                    .map_err(|e| vec![Diagnostic::unplaced(Code::Io, e.to_string())])?;
            }
            let sketch = folder.join(&s.files[0].0);
            (
                toolchain::build(&sketch, t.model, &folder.join("build")).map_err(|d| vec![d])?,
                None,
            )
        };
        let rows = stimulus.writes().map_err(|r| {
            vec![Diagnostic::unplaced(
                Code::StimulusTarget,
                format!(
                    "the stimulus forces a value at {} ms: forces are not available on the board's firmware (--firmware); write the value instead",
                    r.time_ms
                ),
            )]
        })?;
        let cols: Vec<simavr::Column> = cols
            .iter()
            .map(|c| simavr::Column {
                name: c.name.clone(),
                place: c.place,
            })
            .collect();
        // The byte code goes in as `alba download` sends it, to the same firmware on the
        // emulated board, whose EEPROM the run then starts from.
        let eeprom = match &program {
            Some(bytes) => Some(download_emulated(&built.elf, t.model, &folder, bytes)?),
            None => None,
        };
        let run = simavr::simulate_eeprom(
            &built.elf,
            t.model,
            &s.wiring,
            t.active_low,
            &prog.init,
            &rows,
            &cols,
            timing,
            eeprom.as_deref(),
        )?;
        eprintln!(
            "{} | {} scans in simavr, CPU cycles per scan min {} mean {} max {} ({:.1} µs mean at 16 MHz)",
            built.report(),
            run.profile.scans,
            run.profile.min,
            run.profile.mean,
            run.profile.max,
            run.profile.mean as f64 / 16.0
        );
        Ok(run.trace)
    })();
    let _ = std::fs::remove_dir_all(&work);
    result.map_err(|d| {
        report(&d, c.files(), false);
        ExitCode::FAILURE
    })
}
