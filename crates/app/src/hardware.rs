//! The project's hardware (issue 33; docs/arduino.md "From the studio"):
//! the board and pin map of alba.toml, the machine's serial ports, firmware
//! builds with their sizes, byte-code downloads as jobs with progress.
//!
//! The command line and the studio share this code: `alba export`,
//! `alba download` (crates/cli) and `/api/hardware` (alba-server's
//! [`Hardware`] trait, implemented here by [`Service`]) choose the board
//! with [`target`] and download with [`download`].

use alba_arduino::sketch::{self, Target};
use alba_arduino::{bytecode, interp, toolchain};
use alba_compiler::Compiled;
use alba_control::audit::{Action, Entry};
use alba_control::{Actor, Control, json_text};
use alba_diag::{Code, Diagnostic, Files};
use alba_io::download::{BoardState, DownloadError, Link};
use alba_model::address::Address;
use alba_model::board::{Dir, Model, PRESETS, PinMap};
use alba_model::fsutil;
use alba_server::hardware::{Acting, AttachMode, BoardChange, Hardware, HardwareError};
use alba_server::project::diagnostics_json;
use alba_server::reply::{
    Attachment, BoardIdentity, BoardModel, BoardPin, BuildSizes, HardwareJob, HardwareView, JobState, PinProblem,
    PinRow, SerialPortInfo, Verified,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// What a download is told to say when it fails after the board was reached.
pub const STILL_OLD: &str = "the board still runs the previous program";

/// Jobs kept for the studio (newest first).
const KEPT_JOBS: usize = 20;

fn bad(msg: String) -> Diagnostic {
    Diagnostic::unplaced(Code::BadArgument, msg)
}

/// The board to build for: `board` and `pinmap` (the command line's
/// `--board`, `--pinmap`, the studio's choice) over `[board]` of alba.toml.
pub fn target(c: &Compiled, board: Option<&str>, pinmap: Option<&str>, monitor: bool) -> Result<Target, Diagnostic> {
    let cfg = c.project.config.as_ref();
    let saved = cfg.and_then(|c| c.board.as_ref());
    let model = match (board, saved) {
        (Some(name), _) => {
            Model::parse(name).ok_or_else(|| bad(format!("--board {name}: the boards are uno, nano and mega")))?
        }
        (None, Some(b)) => b.model,
        (None, None) => {
            return Err(bad(
                "no board: give --board uno|nano|mega or a [board] section in alba.toml".into(),
            ));
        }
    };
    let map = match (pinmap, saved) {
        (Some(p), _) => {
            PinMap::preset(p).ok_or_else(|| bad(format!("--pinmap {p}: the presets are {}", PRESETS.join(", "))))?
        }
        (None, Some(b)) => b.map.clone(),
        (None, None) => PinMap::preset("aurora").ok_or_else(|| bad("the aurora preset is missing".into()))?,
    };
    Ok(Target {
        model,
        map,
        active_low: saved.is_some_and(|b| b.active_low),
        scan_ms: c.project.scan_ms(),
        monitor,
        power_up_on: saved.map_or_else(Vec::new, |b| b.power_up_on.clone()),
    })
}

/// The project's name as firmware is named after it.
pub fn project_name(c: &Compiled) -> String {
    c.project
        .config
        .as_ref()
        .map_or("alba", |c| c.name.as_str())
        .to_string()
}

/// A download that did not happen or did not finish.
#[derive(Debug)]
pub enum DownloadFailure {
    /// The project does not compile, or cannot run on the board: nothing was sent.
    Project(Vec<Diagnostic>),
    /// The board is not the one the program is for (its interpreter says
    /// so): nothing was sent.
    NotOnBoard(String),
    /// The link or the board failed: the board keeps its program.
    Link(DownloadError),
}

/// A download done.
#[derive(Debug, Clone)]
pub struct Downloaded {
    pub bytes: usize,
    pub checksum: u16,
    pub retries: usize,
    pub ms: u128,
    /// Read back equal (when asked).
    pub verified: bool,
}

/// Asks the board on `port` who it is, encodes the project's byte code for
/// the board (`board`, `pinmap` over `[board]`; with neither, the board the
/// interpreter says it is, aurora pin map), checks that the board is the
/// one the program is for, and downloads (`alba download`, the studio's
/// Download). `go(done, total)` after each record; `false` cancels (the
/// board drops what it received and runs its program on).
pub fn download(
    c: &Compiled,
    board: Option<&str>,
    pinmap: Option<&str>,
    port: &str,
    verify: bool,
    go: impl FnMut(usize, usize) -> bool,
) -> Result<Downloaded, DownloadFailure> {
    let Some(program) = &c.program else {
        return Err(DownloadFailure::Project(c.diagnostics.clone()));
    };
    let saved = c.project.config.as_ref().is_some_and(|c| c.board.is_some());
    let mut link = Link::open(port).map_err(DownloadFailure::Link)?;
    // Who is there, before anything is written.
    let id = link.identify().map_err(DownloadFailure::Link)?;
    // Without a board given or in alba.toml, the board the interpreter says it is.
    let board = board.or((!saved).then_some(id.model.as_str()));
    let t = target(c, board, pinmap, true).map_err(|d| DownloadFailure::Project(vec![d]))?;
    let prog = sketch::control_program(program);
    let bc = bytecode::encode(&prog, &project_name(c), &t).map_err(DownloadFailure::Project)?;
    if let Some(why) = id.refuses(&t, bc.bytes.len()) {
        return Err(DownloadFailure::NotOnBoard(why));
    }
    let started = Instant::now();
    let checksum = link.download_until(&bc.bytes, go).map_err(DownloadFailure::Link)?;
    let ms = started.elapsed().as_millis();
    if verify {
        let back = link.read(0, bc.bytes.len()).map_err(DownloadFailure::Link)?;
        if back != bc.bytes {
            let at = back
                .iter()
                .zip(&bc.bytes)
                .position(|(a, b)| a != b)
                .unwrap_or(back.len());
            return Err(DownloadFailure::Link(DownloadError::Verify(at)));
        }
    }
    Ok(Downloaded {
        bytes: bc.bytes.len(),
        checksum,
        retries: link.retries,
        ms,
        verified: verify,
    })
}

/// The machine's serial ports: USB serial adapters (`/dev/ttyUSB*`,
/// `/dev/ttyACM*`) with what sysfs and `/dev/serial/by-id` say of them;
/// `extra` (the project's port, ports typed by hand) first.
pub fn ports(extra: &[(String, String)]) -> Vec<SerialPortInfo> {
    let mut out: Vec<SerialPortInfo> = Vec::new();
    for (path, why) in extra {
        if out.iter().any(|p| &p.path == path) {
            continue;
        }
        let there = Path::new(path).exists();
        out.push(SerialPortInfo {
            path: path.clone(),
            description: if there {
                why.clone()
            } else {
                format!("{why} (not present now)")
            },
        });
    }
    // /dev/serial/by-id names, by the device they point to.
    let mut by_id: Vec<(PathBuf, String)> = Vec::new();
    if let Ok(rd) = std::fs::read_dir("/dev/serial/by-id") {
        for e in rd.flatten() {
            if let Ok(dev) = std::fs::canonicalize(e.path()) {
                by_id.push((dev, e.file_name().to_string_lossy().into_owned()));
            }
        }
    }
    let mut found: Vec<String> = std::fs::read_dir("/dev")
        .map(|rd| {
            rd.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with("ttyUSB") || n.starts_with("ttyACM"))
                .collect()
        })
        .unwrap_or_default();
    found.sort();
    for name in found {
        let path = format!("/dev/{name}");
        if out.iter().any(|p| p.path == path) {
            continue;
        }
        let mut words = usb_words(&name);
        if let Some((_, id)) = by_id.iter().find(|(d, _)| d == Path::new(&path)) {
            words.push(format!("({id})"));
        }
        if words.is_empty() {
            words.push(if name.starts_with("ttyACM") {
                "USB modem (CDC ACM)".to_string()
            } else {
                "USB serial adapter".to_string()
            });
        }
        out.push(SerialPortInfo {
            path,
            description: words.join(" "),
        });
    }
    out
}

/// `1a86:7523 QinHeng USB Serial` from sysfs, for tty `name`.
fn usb_words(name: &str) -> Vec<String> {
    let Ok(mut dir) = std::fs::canonicalize(format!("/sys/class/tty/{name}/device")) else {
        return Vec::new();
    };
    for _ in 0..6 {
        if dir.join("idVendor").is_file() {
            let read = |f: &str| {
                std::fs::read_to_string(dir.join(f))
                    .ok()
                    .map(|s| s.trim().to_string())
                    .filter(|s| !s.is_empty())
            };
            let mut w = Vec::new();
            if let (Some(v), Some(p)) = (read("idVendor"), read("idProduct")) {
                w.push(format!("{v}:{p}"));
            }
            w.extend(read("manufacturer"));
            w.extend(read("product"));
            return w;
        }
        if !dir.pop() {
            break;
        }
    }
    Vec::new()
}

/// Every board with its limits and pins (the studio's board chooser and drawing).
pub fn boards() -> Vec<BoardModel> {
    Model::ALL
        .iter()
        .map(|m| {
            let (flash_max, ram_max) = m.limits();
            BoardModel {
                name: m.name().into(),
                title: m.title().into(),
                flash_max,
                ram_max,
                pins: m
                    .all_pins()
                    .into_iter()
                    .map(|p| BoardPin {
                        pin: p.to_string(),
                        caps: m.caps(p).into_iter().map(str::to_string).collect(),
                    })
                    .collect(),
            }
        })
        .collect()
}

/// The pin map as a table: each channel's pin, the tags at its address,
/// and its problem (a pin on two channels: E102; a channel the program's
/// tags use that the map does not wire or the board cannot serve: E501).
pub fn pin_table(c: &Compiled, model: Model, map: &PinMap) -> Vec<PinRow> {
    let tags_at = |a: Address| -> Vec<String> {
        c.project
            .tags
            .iter()
            .filter(|t| t.address == Some(a))
            .map(|t| t.name.clone())
            .collect()
    };
    let address = |dir: Dir, n: u32| match dir {
        Dir::DigitalIn => Address::DigitalIn(n),
        Dir::DigitalOut => Address::DigitalOut(n),
        Dir::AnalogIn => Address::AnalogIn(n),
        Dir::AnalogOut => Address::AnalogOut(n),
    };
    let all: Vec<_> = Dir::ALL.iter().flat_map(|d| map.pins(*d).iter().copied()).collect();
    let mut rows = Vec::new();
    for dir in Dir::ALL {
        let pins = map.pins(dir);
        for (n, pin) in pins.iter().enumerate() {
            let a = address(dir, n as u32);
            let problem = if all.iter().filter(|p| *p == pin).count() > 1 {
                Some(PinProblem {
                    code: Code::ConfigField.to_string(),
                    message: format!("pin {pin} is wired to two channels"),
                })
            } else {
                match map.pin_of(model, a) {
                    Some(Err(why)) => Some(PinProblem {
                        code: Code::NotOnBoard.to_string(),
                        message: why,
                    }),
                    _ => None,
                }
            };
            rows.push(PinRow {
                dir: dir.key().into(),
                channel: n as u32,
                address: dir.address(n),
                pin: Some(pin.to_string()),
                tags: tags_at(a),
                problem,
            });
        }
        // Channels the tags use beyond the map.
        let mut beyond: Vec<u32> = c
            .project
            .tags
            .iter()
            .filter_map(|t| match (t.address, dir) {
                (Some(Address::DigitalIn(n)), Dir::DigitalIn)
                | (Some(Address::DigitalOut(n)), Dir::DigitalOut)
                | (Some(Address::AnalogIn(n)), Dir::AnalogIn)
                | (Some(Address::AnalogOut(n)), Dir::AnalogOut) => Some(n),
                _ => None,
            })
            .filter(|n| *n as usize >= pins.len())
            .collect();
        beyond.sort_unstable();
        beyond.dedup();
        for n in beyond {
            let a = address(dir, n);
            let why = match map.pin_of(model, a) {
                Some(Err(why)) => why,
                _ => format!("{} is not wired", dir.address(n as usize)),
            };
            rows.push(PinRow {
                dir: dir.key().into(),
                channel: n,
                address: dir.address(n as usize),
                pin: None,
                tags: tags_at(a),
                problem: Some(PinProblem {
                    code: Code::NotOnBoard.to_string(),
                    message: why,
                }),
            });
        }
    }
    rows
}

/// One job of the service.
struct Job {
    view: HardwareJob,
    /// Asked to stop: the download drops at the next record.
    cancel: Arc<AtomicBool>,
}

/// The hardware service of `alba run` for the project in `dir`.
pub struct Service {
    dir: PathBuf,
    jobs: Mutex<Vec<Arc<Mutex<Job>>>>,
    /// Ports typed by hand this session.
    typed: Mutex<Vec<String>>,
    /// One build at a time (avr-gcc takes the machine's cores).
    building: Arc<Mutex<()>>,
    next: AtomicU64,
    /// The I/O driver `alba run` was started with (`--io`).
    io: String,
    /// The board attached as the PLC's I/O, with the project's own I/O it displaced.
    attached: Mutex<Option<Attached>>,
    /// One attach or detach at a time.
    attaching: tokio::sync::Mutex<()>,
    /// `[board]` before each save of this run, newest last (Undo).
    undo: Mutex<Vec<Option<toml_edit::Item>>>,
}

/// A board attached (`POST /api/hardware/attach`).
struct Attached {
    view: Attachment,
    /// The project's own I/O, put back at detach.
    own: Box<dyn alba_runtime::Io>,
}

/// Drops a displaced I/O driver off the async workers (its link thread is joined).
fn retire(io: Box<dyn alba_runtime::Io>) {
    let _ = std::thread::Builder::new()
        .name("alba-retire".into())
        .spawn(move || drop(io));
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn does_not_build(ds: &[Diagnostic], files: &Files) -> HardwareError {
    HardwareError::DoesNotBuild(diagnostics_json(ds, files))
}

fn model_of(board: &str) -> Result<Model, HardwareError> {
    Model::parse(board)
        .ok_or_else(|| HardwareError::Malformed(format!("unknown board `{board}`: the boards are uno, nano and mega")))
}

/// A port path as typed: a device or pty path, not an option or an empty word.
fn port_path(port: &str) -> Result<String, HardwareError> {
    let p = port.trim();
    if p.is_empty() || p.starts_with('-') || p.contains('\0') {
        return Err(HardwareError::Malformed(format!(
            "`{port}` is not a serial port path (as /dev/ttyUSB0)"
        )));
    }
    Ok(p.to_string())
}

/// Board saves that can be undone (the newest).
const KEPT_UNDO: usize = 20;

/// Writes `doc` into `path` atomically once it checks as `alba check` reads
/// alba.toml: refused, nothing saved, on any problem.
fn save_checked(path: &Path, doc: &toml_edit::DocumentMut) -> Result<(), HardwareError> {
    let new = doc.to_string();
    let mut files = Files::new();
    // Checked as `alba check` reads alba.toml: refused, nothing saved, on any problem.
    let f = files.add(path.display().to_string(), new.clone());
    let (_, diags) = alba_load::parse(files.text(f), f);
    if !diags.is_empty() {
        return Err(does_not_build(&diags, &files));
    }
    fsutil::write_atomic(path, |w| w.write_all(new.as_bytes()))
        .map_err(|e| HardwareError::Failed(format!("cannot save {}: {e}", path.display())))
}

/// The outcome of a download in words.
pub fn failure_words(f: &DownloadFailure, files: &Files) -> String {
    match f {
        DownloadFailure::Project(ds) => {
            let first = ds.first().map(|d| d.short(files)).unwrap_or_default();
            format!(
                "not downloaded: the project cannot go to the board ({} problem{}: {first}); nothing was sent",
                ds.len(),
                if ds.len() == 1 { "" } else { "s" }
            )
        }
        DownloadFailure::NotOnBoard(why) => format!("not downloaded: {why}; nothing was sent"),
        DownloadFailure::Link(e @ DownloadError::Open { .. }) => format!("{e}; nothing was sent"),
        DownloadFailure::Link(e @ DownloadError::Rejected) => e.to_string(),
        DownloadFailure::Link(e) => format!("{e}: {STILL_OLD}"),
    }
}

/// A firmware kind the studio builds and uploads.
fn kind_of(kind: &str) -> Result<(), HardwareError> {
    if matches!(kind, "sketch" | "interpreter" | "controller") {
        Ok(())
    } else {
        Err(HardwareError::Malformed(format!(
            "unknown kind `{kind}`: build a `sketch`, the `interpreter` or the `controller` firmware"
        )))
    }
}

fn kind_words(kind: &str) -> &'static str {
    match kind {
        "sketch" => "stand-alone sketch",
        "interpreter" => "byte-code interpreter",
        _ => "controller (remote-I/O) firmware",
    }
}

/// Builds the firmware `kind` of the project in `dir` for `model` with
/// avr-gcc: the project's stand-alone sketch (`alba export arduino`), the
/// byte-code interpreter for its pin map (`alba export interpreter`), or the
/// controller firmware for it (`alba firmware`, Modbus RTU).
fn firmware(dir: &Path, model: Model, kind: &str) -> Result<toolchain::Built, HardwareError> {
    let c = alba_load::compile_dir(dir);
    let files = c.project.files.clone();
    let toolchain_error = |d: Diagnostic| {
        if d.code == Code::Toolchain {
            HardwareError::Failed(d.message)
        } else {
            does_not_build(&[d], &files)
        }
    };
    let studio = |name: &str| {
        toolchain::cache_dir()
            .join("studio")
            .join(format!("{name}-{}-{}", model.name(), std::process::id()))
            .join(name)
    };
    match kind {
        "sketch" => {
            let Some(program) = &c.program else {
                return Err(does_not_build(&c.diagnostics, &files));
            };
            let t = target(&c, Some(model.name()), None, true).map_err(|d| does_not_build(&[d], &files))?;
            let prog = sketch::control_program(program);
            let s = sketch::generate(&prog, &project_name(&c), &t).map_err(|d| does_not_build(&d, &files))?;
            let folder = studio(&s.name);
            for (name, text) in &s.files {
                let p = folder.join(name);
                std::fs::create_dir_all(&folder)
                    .and_then(|()| fsutil::write_atomic(&p, |w| w.write_all(text.as_bytes())))
                    .map_err(|e| HardwareError::Failed(format!("cannot write {}: {e}", p.display())))?;
            }
            toolchain::build(&folder.join(&s.files[0].0), model, &folder.join("build")).map_err(toolchain_error)
        }
        "interpreter" => {
            if c.project.config.is_none() {
                return Err(does_not_build(&c.diagnostics, &files));
            }
            let t = target(&c, Some(model.name()), None, true).map_err(|d| does_not_build(&[d], &files))?;
            Ok(interp::firmware(&t).map_err(toolchain_error)?.0)
        }
        _ => {
            let t = target(&c, Some(model.name()), None, false).map_err(|d| does_not_build(&[d], &files))?;
            let pinmap = c
                .project
                .config
                .as_ref()
                .and_then(|c| c.board.as_ref())
                .map_or_else(|| "aurora".to_string(), |b| b.pinmap.clone());
            let mut spec = alba_io::firmware::Spec::new(model, &pinmap, t.map.clone(), alba_io::firmware::Link::Modbus);
            spec.active_low = t.active_low;
            let name = format!(
                "{}_io",
                project_name(&c).replace(|ch: char| !ch.is_ascii_alphanumeric(), "_")
            );
            let folder = studio(&name);
            let sketch = alba_io::firmware::write(&spec, &folder)
                .map_err(|e| HardwareError::Failed(format!("cannot write the controller firmware: {e}")))?;
            toolchain::build(&sketch, model, &folder.join("build")).map_err(toolchain_error)
        }
    }
}

/// Uploads `built` to the board on `port` with avrdude, as `alba export
/// arduino --upload` does ([`toolchain::upload_command`]), reading its
/// progress bars: writing takes the job from 10 to 90 %, verifying to 100 %.
/// `cancel` kills avrdude (the board keeps what its bootloader had written:
/// upload again).
fn avrdude(
    built: &toolchain::Built,
    port: &str,
    cancel: &AtomicBool,
    mut progress: impl FnMut(u8),
) -> Result<(), HardwareError> {
    use std::io::Read;
    let mut cmd = toolchain::upload_command(built, port);
    cmd.stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped());
    let mut child = cmd.spawn().map_err(|e| {
        HardwareError::Failed(if e.kind() == std::io::ErrorKind::NotFound {
            "avrdude was not found: install it (Debian package avrdude)".to_string()
        } else {
            format!("cannot run avrdude: {e}")
        })
    })?;
    let Some(mut err) = child.stderr.take() else {
        let _ = child.kill();
        return Err(HardwareError::Failed("avrdude's output cannot be read".into()));
    };
    let mut text = String::new();
    let (mut phase, mut hashes) = (0u8, 0u32);
    let mut buf = [0u8; 256];
    loop {
        if cancel.load(Ordering::Relaxed) {
            let _ = child.kill();
            let _ = child.wait();
            return Err(HardwareError::Failed(
                "cancelled: avrdude stopped; the board may hold part of the firmware: upload again".into(),
            ));
        }
        let n = match err.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => n,
        };
        for &b in &buf[..n] {
            text.push(char::from(b));
            if text.ends_with("Writing") {
                (phase, hashes) = (1, 0);
            } else if text.ends_with("Reading") && phase == 1 {
                (phase, hashes) = (2, 0);
            } else if b == b'#' && phase > 0 {
                hashes = (hashes + 1).min(50);
                progress(match phase {
                    1 => 10 + (hashes * 80 / 50) as u8,
                    _ => 90 + (hashes * 10 / 50) as u8,
                });
            }
        }
    }
    let status = child
        .wait()
        .map_err(|e| HardwareError::Failed(format!("avrdude: {e}")))?;
    if status.success() {
        return Ok(());
    }
    let last: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.contains('#'))
        .collect();
    let tail = last[last.len().saturating_sub(3)..].join(" / ");
    Err(HardwareError::Port(format!("avrdude failed ({status}): {tail}")))
}

impl Service {
    pub fn new(dir: &Path) -> Service {
        Service {
            dir: dir.to_path_buf(),
            jobs: Mutex::new(Vec::new()),
            typed: Mutex::new(Vec::new()),
            building: Arc::new(Mutex::new(())),
            next: AtomicU64::new(1),
            io: "sim".into(),
            attached: Mutex::new(None),
            attaching: tokio::sync::Mutex::new(()),
            undo: Mutex::new(Vec::new()),
        }
    }

    /// The same, for `alba run --io <spec>`.
    pub fn with_io(mut self, spec: &str) -> Service {
        self.io = spec.to_string();
        self
    }

    /// Refused while the board on `port` is attached: one user of a port at a time.
    fn not_attached(&self, port: &str) -> Result<(), HardwareError> {
        match lock(&self.attached).as_ref() {
            Some(a) if a.view.port == port => Err(HardwareError::Busy(format!(
                "the board on {port} is attached as the PLC's I/O: detach it first"
            ))),
            _ => Ok(()),
        }
    }

    fn remember(&self, port: &str) {
        let mut t = lock(&self.typed);
        if !t.iter().any(|p| p == port) {
            t.push(port.to_string());
        }
    }

    /// A port no job is using, remembered as typed.
    fn free_port(&self, port: &str) -> Result<String, HardwareError> {
        let port = port_path(port)?;
        self.not_attached(&port)?;
        if let Some(j) = lock(&self.jobs).iter().find(|j| {
            let j = lock(j);
            j.view.port == port && j.view.state == JobState::Running
        }) {
            return Err(HardwareError::Busy(format!(
                "job {} is downloading to {port}",
                lock(j).view.id
            )));
        }
        self.remember(&port);
        Ok(port)
    }

    fn compile(&self) -> Compiled {
        alba_load::compile_dir(&self.dir)
    }

    fn start_job_of(&self, kind: &str, port: &str) -> Result<Arc<Mutex<Job>>, HardwareError> {
        self.not_attached(port)?;
        let mut jobs = lock(&self.jobs);
        if let Some(j) = jobs.iter().find(|j| {
            let j = lock(j);
            j.view.port == port && j.view.state == JobState::Running
        }) {
            let j = lock(j);
            return Err(HardwareError::Busy(format!(
                "job {} ({}) is using {port}: one job per port at a time",
                j.view.id, j.view.kind
            )));
        }
        let id = self.next.fetch_add(1, Ordering::Relaxed).to_string();
        let job = Arc::new(Mutex::new(Job {
            view: HardwareJob {
                id,
                kind: kind.into(),
                port: port.into(),
                state: JobState::Running,
                progress: 0,
                message: "compiling the project".into(),
                started_ms: alba_server::now_ms(),
            },
            cancel: Arc::new(AtomicBool::new(false)),
        }));
        jobs.insert(0, job.clone());
        jobs.truncate(KEPT_JOBS);
        Ok(job)
    }

    /// Runs `work` as a job of `kind` on `port` in its own thread and returns
    /// the job's id: `work` reports progress through `set(progress, message)`,
    /// watches `cancel`, and ends with the final message (done) or the failure
    /// in words (failed).
    fn spawn_job<F>(&self, kind: &str, port: &str, work: F) -> Result<String, HardwareError>
    where
        F: FnOnce(&dyn Fn(Option<u8>, String), &AtomicBool) -> Result<String, String> + Send + 'static,
    {
        let job = self.start_job_of(kind, port)?;
        self.remember(port);
        let (id, cancel) = {
            let j = lock(&job);
            (j.view.id.clone(), j.cancel.clone())
        };
        let spawned = std::thread::Builder::new()
            .name(format!("alba-{kind}-{id}"))
            .spawn(move || {
                let set = |progress: Option<u8>, message: String| {
                    let mut j = lock(&job);
                    if let Some(p) = progress {
                        j.view.progress = p;
                    }
                    j.view.message = message;
                };
                let result = work(&set, &cancel);
                let mut j = lock(&job);
                match result {
                    Ok(message) => {
                        j.view.state = JobState::Done;
                        j.view.progress = 100;
                        j.view.message = message;
                    }
                    Err(message) => {
                        j.view.state = JobState::Failed;
                        j.view.message = message;
                    }
                }
            });
        match spawned {
            Ok(_) => Ok(id),
            Err(e) => Err(HardwareError::Failed(format!("cannot start the {kind}: {e}"))),
        }
    }
}

impl Hardware for Service {
    fn view(&self) -> Result<HardwareView, HardwareError> {
        let c = self.compile();
        let board = c.project.config.as_ref().and_then(|c| c.board.as_ref());
        let mut extra = Vec::new();
        if let Some(p) = board.and_then(|b| b.port.clone()) {
            extra.push((p, "the project's port (alba.toml [board] port)".to_string()));
        }
        for p in lock(&self.typed).iter() {
            extra.push((p.clone(), "typed by hand".to_string()));
        }
        let pins = match board {
            Some(b) => pin_table(&c, b.model, &b.map),
            None => Vec::new(),
        };
        Ok(HardwareView {
            board: board.map(|b| b.model.name().to_string()),
            pinmap: board.map_or_else(|| "aurora".to_string(), |b| b.pinmap.clone()),
            active_low: board.is_some_and(|b| b.active_low),
            port: board.and_then(|b| b.port.clone()),
            ports: ports(&extra),
            boards: boards(),
            presets: PRESETS.iter().map(|p| p.to_string()).collect(),
            pins,
            diagnostics: diagnostics_json(&c.diagnostics, &c.project.files),
            jobs: lock(&self.jobs).iter().map(|j| lock(j).view.clone()).collect(),
            attached: lock(&self.attached).as_ref().map(|a| a.view.clone()),
            io: self.io.clone(),
            undo: lock(&self.undo).len() as u32,
        })
    }

    fn save_board(&self, change: &BoardChange) -> Result<HardwareView, HardwareError> {
        let model = model_of(&change.board)?;
        if PinMap::preset(&change.pinmap).is_none() {
            return Err(HardwareError::Malformed(format!(
                "unknown pin map `{}`: the presets are {}",
                change.pinmap,
                PRESETS.join(", ")
            )));
        }
        let path = self.dir.join("alba.toml");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| HardwareError::Failed(format!("cannot read {}: {e}", path.display())))?;
        let mut doc: toml_edit::DocumentMut = text
            .parse()
            .map_err(|e| HardwareError::Failed(format!("{} does not parse: {e}", path.display())))?;
        // What Undo puts back: `[board]` as it was (`None`: there was none).
        let before = doc.get("board").cloned();
        if !doc.contains_key("board") {
            doc["board"] = toml_edit::table();
        }
        // `[board]` or `board = { … }`: changed where it is, as it is written.
        let b = doc["board"]
            .as_table_like_mut()
            .ok_or_else(|| HardwareError::Failed("`board` in alba.toml is not a table".into()))?;
        b.insert("model", toml_edit::value(model.name()));
        b.insert("pinmap", toml_edit::value(change.pinmap.to_ascii_lowercase()));
        for (key, pins) in [
            ("di", &change.di),
            ("do", &change.r#do),
            ("ai", &change.ai),
            ("ao", &change.ao),
        ] {
            match pins {
                Some(list) => {
                    let list: toml_edit::Array = list.iter().map(|p| p.trim().to_ascii_uppercase()).collect();
                    b.insert(key, toml_edit::value(list));
                }
                None => {
                    b.remove(key);
                }
            }
        }
        match &change.port {
            Some(p) => {
                b.insert("port", toml_edit::value(port_path(p)?));
            }
            None => {
                b.remove("port");
            }
        }
        save_checked(&path, &doc)?;
        let mut undo = lock(&self.undo);
        undo.push(before);
        let extra = undo.len().saturating_sub(KEPT_UNDO);
        undo.drain(..extra);
        drop(undo);
        self.view()
    }

    fn undo_board(&self) -> Result<HardwareView, HardwareError> {
        let mut undo = lock(&self.undo);
        let Some(before) = undo.last().cloned() else {
            return Err(HardwareError::Conflict(
                "no board save to undo (since alba run started)".into(),
            ));
        };
        let path = self.dir.join("alba.toml");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| HardwareError::Failed(format!("cannot read {}: {e}", path.display())))?;
        let mut doc: toml_edit::DocumentMut = text
            .parse()
            .map_err(|e| HardwareError::Failed(format!("{} does not parse: {e}", path.display())))?;
        // Only `[board]` goes back: the rest of alba.toml stays as it is now.
        match before {
            Some(item) => doc["board"] = item,
            None => {
                doc.remove("board");
            }
        }
        save_checked(&path, &doc)?;
        undo.pop();
        drop(undo);
        self.view()
    }

    fn build(&self, board: &str, kind: &str) -> Result<BuildSizes, HardwareError> {
        let model = model_of(board)?;
        kind_of(kind)?;
        let built = {
            let _one = lock(&self.building);
            firmware(&self.dir, model, kind)?
        };
        let (flash_max, ram_max) = model.limits();
        Ok(BuildSizes {
            board: model.name().into(),
            kind: kind.into(),
            flash_bytes: built.flash,
            ram_bytes: built.ram,
            flash_max,
            ram_max,
            report: built.report(),
        })
    }

    fn upload(&self, port: &str, board: &str, kind: &str) -> Result<String, HardwareError> {
        let model = model_of(board)?;
        kind_of(kind)?;
        let port = port_path(port)?;
        let (dir, building, kind) = (self.dir.clone(), self.building.clone(), kind.to_string());
        self.spawn_job("upload", &port.clone(), move |set, cancel| {
            set(
                Some(0),
                format!(
                    "building the {} for the {} with avr-gcc",
                    kind_words(&kind),
                    model.title()
                ),
            );
            let built = {
                let _one = lock(&building);
                firmware(&dir, model, &kind)
            };
            built
                .and_then(|b| {
                    set(Some(10), format!("uploading with avrdude ({})", b.report()));
                    avrdude(&b, &port, cancel, |p| {
                        set(Some(p), format!("uploading with avrdude: {p} %"))
                    })
                    .map(|()| b)
                })
                .map(|b| format!("uploaded the {} to {port}: {}", kind_words(&kind), b.report()))
                .map_err(|e| format!("not uploaded: {e}"))
        })
    }

    fn download(&self, port: &str) -> Result<String, HardwareError> {
        let port = port_path(port)?;
        let dir = self.dir.clone();
        self.spawn_job("download", &port.clone(), move |set, cancel| {
            let c = alba_load::compile_dir(&dir);
            set(None, format!("asking the board on {port} what it is"));
            let result = download(&c, None, None, &port, true, |done, total| {
                let pct = (done * 100 / total.max(1)).min(100) as u8;
                set(Some(pct), format!("downloading: record {done} of {total}"));
                !cancel.load(Ordering::Relaxed)
            });
            match result {
                Ok(d) => Ok(format!(
                    "downloaded {} bytes to {port} in {} ms, checksum {:04X}{}, verified: the board runs the new program",
                    d.bytes,
                    d.ms,
                    d.checksum,
                    match d.retries {
                        0 => String::new(),
                        n => format!(" ({n} record(s) sent again after line errors)"),
                    }
                )),
                Err(f) => Err(failure_words(&f, c.files())),
            }
        })
    }

    fn cancel(&self, id: &str) -> Option<HardwareJob> {
        let jobs = lock(&self.jobs);
        let job = jobs.iter().find(|j| lock(j).view.id == id)?;
        let j = lock(job);
        if j.view.state == JobState::Running {
            j.cancel.store(true, Ordering::Relaxed);
        }
        Some(j.view.clone())
    }

    fn job(&self, id: &str) -> Option<HardwareJob> {
        lock(&self.jobs)
            .iter()
            .map(|j| lock(j).view.clone())
            .find(|j| j.id == id)
    }

    fn identify(&self, port: &str) -> Result<BoardIdentity, HardwareError> {
        let port = self.free_port(port)?;
        let mut link = Link::open(&port).map_err(|e| HardwareError::Port(e.to_string()))?;
        let unknown = |why: String| BoardIdentity {
            port: port.clone(),
            known: false,
            board: None,
            format: None,
            board_id: None,
            state: None,
            program: None,
            message: format!("unknown device: {why}"),
        };
        let id = match link.identify() {
            Ok(id) => id,
            Err(e) => return Ok(unknown(e.to_string())),
        };
        let head = link.read(0, bytecode::HEADER_LEN).ok();
        let program = head
            .filter(|h| h[..4] == bytecode::MAGIC)
            .map(|h| format!("{:08x}", u32::from_le_bytes([h[8], h[9], h[10], h[11]])));
        let state = match id.state {
            BoardState::Running => "running",
            BoardState::NoProgram => "no_program",
            BoardState::Faulted => "faulted",
        };
        let doing = match id.state {
            BoardState::Running => "runs a program",
            BoardState::NoProgram => "has no program that checks (outputs safe)",
            BoardState::Faulted => "stopped on a major fault",
        };
        Ok(BoardIdentity {
            message: format!(
                "an {} with Alba's byte-code interpreter (format {}, board id {:04x}): it {doing}{}",
                id.title(),
                id.version,
                id.board_id,
                program.as_ref().map_or(String::new(), |p| format!(", program id {p}"))
            ),
            port: port.clone(),
            known: true,
            board: Some(id.model.clone()),
            format: Some(id.version),
            board_id: Some(format!("{:04x}", id.board_id)),
            state: Some(state.into()),
            program,
        })
    }

    fn verify(&self, port: &str) -> Result<Verified, HardwareError> {
        let port = self.free_port(port)?;
        let c = self.compile();
        let Some(program) = &c.program else {
            return Err(does_not_build(&c.diagnostics, c.files()));
        };
        let mut link = Link::open(&port).map_err(|e| HardwareError::Port(e.to_string()))?;
        let id = match link.identify() {
            Ok(id) => id,
            Err(e) => {
                return Ok(Verified {
                    port,
                    same: false,
                    bytes: 0,
                    message: format!("not verified: {e}"),
                });
            }
        };
        let saved = c.project.config.as_ref().is_some_and(|c| c.board.is_some());
        let t = target(&c, (!saved).then_some(id.model.as_str()), None, true)
            .map_err(|d| does_not_build(&[d], c.files()))?;
        let prog = sketch::control_program(program);
        let bc = bytecode::encode(&prog, &project_name(&c), &t).map_err(|d| does_not_build(&d, c.files()))?;
        let read = link.read(0, bc.bytes.len().min(usize::from(id.slot)));
        let back = match read {
            Ok(b) => b,
            Err(e) => {
                return Ok(Verified {
                    port,
                    same: false,
                    bytes: bc.bytes.len() as u32,
                    message: format!("not verified: {e}"),
                });
            }
        };
        let same = back == bc.bytes;
        let id_of = |b: &[u8]| {
            (b.len() >= bytecode::HEADER_LEN && b[..4] == bytecode::MAGIC)
                .then(|| format!("{:08x}", u32::from_le_bytes([b[8], b[9], b[10], b[11]])))
        };
        let message = if same {
            format!(
                "verified: the board holds the project's program ({} bytes, program id {:08x})",
                bc.bytes.len(),
                bc.program_id
            )
        } else {
            let at = back
                .iter()
                .zip(&bc.bytes)
                .position(|(a, b)| a != b)
                .unwrap_or(back.len());
            format!(
                "the board's program differs from the project's at byte {at} (the board's program id {}, the project's {:08x}): download it",
                id_of(&back).unwrap_or_else(|| "none".into()),
                bc.program_id
            )
        };
        Ok(Verified {
            port,
            same,
            bytes: bc.bytes.len() as u32,
            message,
        })
    }

    fn attach<'a>(&'a self, control: &'a Control, actor: &'a Actor, port: &'a str, mode: AttachMode) -> Acting<'a> {
        Box::pin(async move {
            let _one = self.attaching.lock().await;
            if let Some(a) = lock(&self.attached).as_ref() {
                return Err(HardwareError::Conflict(format!(
                    "the board on {} is attached ({}): detach it first",
                    a.view.port, a.view.mode
                )));
            }
            let port = self.free_port(port)?;
            if self.io.split([':', ',']).any(|w| w == port) {
                return Err(HardwareError::Conflict(format!(
                    "{port} is the project's own I/O already (alba run --io {})",
                    self.io
                )));
            }
            let spec = match mode {
                AttachMode::Controller => format!("arduino:{port}"),
                AttachMode::Monitor => format!("board:{port}"),
            };
            let words = match mode {
                AttachMode::Controller => "the board's pins are the PLC's inputs and outputs (controller firmware)",
                AttachMode::Monitor => "the board runs the project's sketch, watched through its monitoring link",
            };
            let entry = Entry {
                target: Some(port.clone()),
                old: Some(json_text(&serde_json::Value::String(self.io.clone()))),
                new: Some(json_text(&serde_json::Value::String(spec.clone()))),
                detail: Some(mode.name().to_string()),
                ..actor.entry(Action::Attach)
            };
            // The running program (online edits included) and the project's [board].
            let program = control.runtime().snapshot().program.clone();
            let (dir, at, driver) = (self.dir.clone(), port.clone(), spec.clone());
            let open = async move {
                tokio::task::spawn_blocking(move || {
                    if !Path::new(&at).exists() {
                        return Err(HardwareError::Port(format!(
                            "{at}: no such serial port (is the board plugged in?)"
                        )));
                    }
                    let c = alba_load::compile_dir(&dir);
                    alba_io::open(&driver, c.project.config.as_ref(), &program)
                        .map_err(|e| HardwareError::Failed(format!("cannot attach {at}: {e}")))
                })
                .await
                .map_err(|e| HardwareError::Failed(format!("hardware: {e}")))?
            };
            let own = control.attach(actor, entry, open).await?;
            *lock(&self.attached) = Some(Attached {
                view: Attachment {
                    port: port.clone(),
                    mode: mode.name().into(),
                    io: spec,
                    since_ms: alba_server::now_ms(),
                    message: format!("attached to {port}: {words}"),
                },
                own,
            });
            Ok(())
        })
    }

    fn detach<'a>(&'a self, control: &'a Control, actor: &'a Actor) -> Acting<'a> {
        Box::pin(async move {
            let _one = self.attaching.lock().await;
            let taken = lock(&self.attached).take();
            let Some(a) = taken else {
                return Err(HardwareError::Conflict("no board is attached".into()));
            };
            let entry = Entry {
                target: Some(a.view.port.clone()),
                old: Some(json_text(&serde_json::Value::String(a.view.io.clone()))),
                new: Some(json_text(&serde_json::Value::String(self.io.clone()))),
                detail: Some(a.view.mode.clone()),
                ..actor.entry(Action::Detach)
            };
            match control.detach(actor, entry, a.own).await {
                Ok(board) => {
                    retire(board);
                    Ok(())
                }
                // Not allowed: still attached.
                Err((r, Some(own))) => {
                    *lock(&self.attached) = Some(Attached { view: a.view, own });
                    Err(r.into())
                }
                // The runtime did not take it (it has ended, or is flooded):
                // the project's own I/O went with the refusal.
                Err((r, None)) => Err(r.into()),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_job_per_port_at_a_time() {
        let s = Service::new(Path::new("/nonexistent"));
        let a = s.start_job_of("download", "/dev/ttyUSB0").expect("first");
        let Err(HardwareError::Busy(m)) = s.start_job_of("download", "/dev/ttyUSB0") else {
            panic!("a second job on the same port");
        };
        assert!(m.contains("one job per port"), "{m}");
        // Another port is free; the first, once its job ends, too.
        s.start_job_of("download", "/dev/ttyUSB1").expect("another port");
        lock(&a).view.state = JobState::Failed;
        s.start_job_of("download", "/dev/ttyUSB0").expect("after the job ended");
        assert_eq!(lock(&s.jobs).len(), 3);
    }

    #[test]
    fn board_is_saved_where_and_as_it_is_written() {
        let dir = std::env::temp_dir().join(format!("alba-hw-inline-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let toml =
            "# keep me\nname = \"x\"\nprograms = [\"main.lad\"]\nboard = { model = \"uno\", active_low = true }\n";
        std::fs::write(dir.join("alba.toml"), toml).expect("alba.toml");
        let s = Service::new(&dir);
        let change = BoardChange {
            board: "nano".into(),
            pinmap: "s7".into(),
            r#do: Some(vec!["D8".into(), " d9 ".into()]),
            ..BoardChange::default()
        };
        // The view afterwards compiles a project without main.lad: the save itself is what counts.
        let _ = s.save_board(&change);
        let saved = std::fs::read_to_string(dir.join("alba.toml")).expect("saved");
        assert!(saved.starts_with("# keep me\n"), "{saved}");
        assert!(
            saved.contains("board = { model = \"nano\", active_low = true"),
            "{saved}"
        );
        let mut files = Files::new();
        let f = files.add("alba.toml", saved.clone());
        let (cfg, d) = alba_load::parse(files.text(f), f);
        assert!(d.is_empty(), "{d:?}");
        let b = cfg.and_then(|c| c.board).expect("board");
        assert_eq!((b.model, b.pinmap.as_str(), b.active_low), (Model::Nano, "s7", true));
        assert_eq!(b.map.r#do, [alba_model::board::Pin::D(8), alba_model::board::Pin::D(9)]);
        // A pin the Nano does not have: refused with E102, nothing saved.
        let bad = BoardChange {
            board: "nano".into(),
            pinmap: "s7".into(),
            di: Some(vec!["D20".into()]),
            ..BoardChange::default()
        };
        let Err(HardwareError::DoesNotBuild(d)) = s.save_board(&bad) else {
            panic!("a pin the board lacks");
        };
        assert_eq!(d[0].code, "E102", "{d:?}");
        assert!(d[0].message.contains("D20"), "{d:?}");
        assert_eq!(std::fs::read_to_string(dir.join("alba.toml")).expect("kept"), saved);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn port_paths_and_failures_in_words() {
        assert!(port_path(" /dev/ttyACM0 ").is_ok());
        for bad in ["", "  ", "--help"] {
            assert!(matches!(port_path(bad), Err(HardwareError::Malformed(_))), "{bad:?}");
        }
        let files = Files::new();
        let refused = DownloadFailure::Link(DownloadError::Refused {
            record: 3,
            why: alba_io::download::flag_meaning(0x04).into(),
        });
        assert_eq!(
            failure_words(&refused, &files),
            format!("record 3 was refused 3 times: a bad checksum (04): {STILL_OLD}")
        );
        let rejected = failure_words(&DownloadFailure::Link(DownloadError::Rejected), &files);
        assert!(
            rejected.contains("flag 40") && rejected.contains("old program runs on"),
            "{rejected}"
        );
        let elsewhere = failure_words(
            &DownloadFailure::NotOnBoard("the board is an Arduino Uno".into()),
            &files,
        );
        assert!(elsewhere.ends_with("nothing was sent"), "{elsewhere}");
    }
}
