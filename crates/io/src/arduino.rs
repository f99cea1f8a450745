//! `--io arduino:<port>[,option=value…]`: an Arduino running the
//! remote-I/O firmware of [`crate::firmware`] is the I/O of the runtime
//! (controller mode, SPEC §7.2).
//!
//! A link thread owns the serial port. It polls the board as fast as the
//! link allows and keeps two small images in shared memory: the latest
//! inputs it read and the latest outputs the engine wrote. The engine
//! thread's `read_inputs`/`write_outputs` only copy those images (a mutex
//! held for the copy, never across I/O), so a slow, silent or unplugged
//! board never delays a scan.
//!
//! Link loss (no valid answer after the retries, or the port gone): the
//! status tag `S:IOOK` goes false and `S:IOERRORS` counts; the inputs keep
//! their last value; the board's own watchdog puts its outputs in the safe
//! state (off) when it hears no valid request for its watchdog time. The
//! thread reopens the port with exponential back-off until the board
//! answers again, then writes the current outputs at once.

use crate::aurora;
use crate::error::Error;
use crate::firmware::Link;
use crate::link::{Outputs, Stop, load_inputs, lock};
use crate::serial::{Port, open, transact};
use alba_engine::Engine;
use alba_modbus_proto::pdu::{Request, Response};
use alba_model::board::PinMap;
use alba_runtime::IoError;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub use crate::serial::{Config, Counts};

/// What the link thread reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Status {
    /// The last cycle reached the board and back.
    pub ok: bool,
    /// Failed attempts (timeouts, bad frames, port errors) so far.
    pub errors: u64,
    /// Complete cycles (inputs read and outputs written).
    pub cycles: u64,
    /// Times the port was (re)opened.
    pub opens: u64,
    pub last_error: Option<String>,
    /// Duration of the last complete cycle.
    pub last_cycle: Option<Duration>,
}

#[derive(Default)]
struct Inputs {
    di: Vec<bool>,
    ai: Vec<u16>,
    /// At least one cycle has delivered inputs.
    valid: bool,
}

struct Shared {
    inputs: Mutex<Inputs>,
    outputs: Mutex<Outputs>,
    status: Mutex<Status>,
    ok: AtomicBool,
    errors: AtomicU64,
    stop: Stop,
}

impl Shared {
    fn fail(&self, why: &IoError) {
        self.ok.store(false, Ordering::Relaxed);
        self.errors.fetch_add(1, Ordering::Relaxed);
        let mut s = lock(&self.status);
        s.ok = false;
        s.errors += 1;
        s.last_error = Some(why.to_string());
    }

    /// An attempt failed but the link may still hold (a retry follows).
    fn count_error(&self, why: &IoError) {
        self.errors.fetch_add(1, Ordering::Relaxed);
        let mut s = lock(&self.status);
        s.errors += 1;
        s.last_error = Some(why.to_string());
    }
}

/// The driver: `alba_runtime::Io` for an Arduino remote-I/O board.
pub struct ArduinoIo {
    name: String,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
    /// Scratch copies of the input image (no allocation per scan).
    di: Vec<bool>,
    ai: Vec<u16>,
}

impl ArduinoIo {
    /// Starts the link thread (it opens the port itself, so a board that is
    /// not plugged in yet is not an error: the link comes up when it is).
    pub fn start(cfg: Config) -> Result<ArduinoIo, Error> {
        let shared = Arc::new(Shared {
            inputs: Mutex::new(Inputs::default()),
            outputs: Mutex::new(Outputs::new(cfg.counts.r#do, cfg.counts.ao)),
            status: Mutex::new(Status::default()),
            ok: AtomicBool::new(false),
            errors: AtomicU64::new(0),
            stop: Stop::default(),
        });
        let name = format!("arduino:{} ({})", cfg.port, cfg.link.name());
        let counts = cfg.counts;
        let s = shared.clone();
        let thread = std::thread::Builder::new()
            .name("alba-io-arduino".into())
            .spawn(move || link_thread(cfg, s))
            .map_err(|source| Error::Thread {
                what: "the I/O link thread",
                source,
            })?;
        Ok(ArduinoIo {
            name,
            shared,
            thread: Some(thread),
            di: Vec::with_capacity(counts.di),
            ai: Vec::with_capacity(counts.ai),
        })
    }

    pub fn status(&self) -> Status {
        lock(&self.shared.status).clone()
    }

    /// The latest input image: DI levels and AI readings (empty before the
    /// first complete cycle).
    pub fn inputs(&self) -> (Vec<bool>, Vec<u16>) {
        let i = lock(&self.shared.inputs);
        (i.di.clone(), i.ai.clone())
    }

    /// Sets the outputs the link writes (what `write_outputs` does from an
    /// engine), for tools and tests that drive the board without a program.
    pub fn set_outputs(&self, r#do: &[bool], ao: &[u16]) {
        lock(&self.shared.outputs).set(r#do, ao);
    }
}

impl Drop for ArduinoIo {
    fn drop(&mut self) {
        self.shared.stop.request();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl alba_runtime::Io for ArduinoIo {
    fn name(&self) -> &str {
        &self.name
    }

    fn read_inputs(&mut self, engine: &mut Engine) -> Result<(), IoError> {
        let errors = self.shared.errors.load(Ordering::Relaxed).min(i32::MAX as u64) as i32;
        engine.set_io_status(self.shared.ok.load(Ordering::Relaxed), errors);
        {
            // Only a copy under the lock: the link thread never holds it
            // across I/O either.
            let i = lock(&self.shared.inputs);
            if !i.valid {
                return Ok(());
            }
            self.di.clone_from(&i.di);
            self.ai.clone_from(&i.ai);
        }
        load_inputs(
            engine,
            self.di.iter().copied().enumerate(),
            self.ai
                .iter()
                .map(|v| i16::try_from(*v).unwrap_or(i16::MAX))
                .enumerate(),
        );
        Ok(())
    }

    fn write_outputs(&mut self, engine: &Engine) -> Result<(), IoError> {
        lock(&self.shared.outputs).copy_from(engine, |v| v.clamp(0, i32::from(u16::MAX)) as u16);
        Ok(())
    }
}

/// Tells the user on stderr when the link comes up or goes down (not at
/// every error: those are counted in `S:IOERRORS`).
struct Announcer {
    name: String,
    up: Option<bool>,
}

impl Announcer {
    fn up(&mut self) {
        if self.up != Some(true) {
            eprintln!("I/O {}: link up", self.name);
            self.up = Some(true);
        }
    }

    fn down(&mut self, why: &IoError) {
        if self.up != Some(false) {
            let what = if self.up.is_none() { "no link yet" } else { "link lost" };
            eprintln!("I/O {}: {what} ({why}); retrying", self.name);
            self.up = Some(false);
        }
    }
}

fn link_thread(cfg: Config, shared: Arc<Shared>) {
    let mut say = Announcer {
        name: format!("arduino:{}", cfg.port),
        up: None,
    };
    let mut backoff = cfg.backoff_min;
    while !shared.stop.stopping() {
        let mut port = match open(&cfg) {
            Ok(p) => p,
            Err(e) => {
                say.down(&e);
                shared.fail(&e);
                shared.stop.sleep(backoff);
                backoff = (backoff * 2).min(cfg.backoff_max);
                continue;
            }
        };
        lock(&shared.status).opens += 1;
        shared.stop.sleep(cfg.reset_delay);
        let _ = port.clear(serialport::ClearBuffer::All);
        let mut failed = 0u32;
        let mut session = match cfg.link {
            Link::Modbus => Session::Modbus,
            Link::Aurora => Session::Aurora(aurora::Reader::default()),
        };
        while !shared.stop.stopping() {
            let t0 = Instant::now();
            let outputs = lock(&shared.outputs).clone();
            let r = match &mut session {
                Session::Modbus => modbus_cycle(&mut port, &cfg, &shared, &outputs),
                Session::Aurora(reader) => aurora::cycle(&mut port, &cfg, reader, &outputs),
            };
            match r {
                Ok((di, ai)) => {
                    {
                        let mut i = lock(&shared.inputs);
                        i.di = di;
                        i.ai = ai;
                        i.valid = true;
                    }
                    shared.ok.store(true, Ordering::Relaxed);
                    let mut s = lock(&shared.status);
                    s.ok = true;
                    s.cycles += 1;
                    s.last_cycle = Some(t0.elapsed());
                    failed = 0;
                    backoff = cfg.backoff_min;
                    drop(s);
                    say.up();
                }
                Err(e) if e.is_link_down() => {
                    say.down(&e);
                    shared.fail(&e);
                    break;
                }
                Err(e) => {
                    say.down(&e);
                    shared.fail(&e);
                    failed += 1;
                    if failed >= cfg.reopen_after {
                        break;
                    }
                }
            }
        }
        if shared.stop.stopping() && failed == 0 {
            // A last write of the outputs the engine left (off, after a
            // stop), so the board does not wait for its watchdog.
            let outputs = lock(&shared.outputs).clone();
            let _ = match &mut session {
                Session::Modbus => modbus_cycle(&mut port, &cfg, &shared, &outputs).map(|_| ()),
                Session::Aurora(reader) => aurora::cycle(&mut port, &cfg, reader, &outputs).map(|_| ()),
            };
        }
        drop(port);
        if !shared.stop.stopping() {
            shared.stop.sleep(backoff);
            backoff = (backoff * 2).min(cfg.backoff_max);
        }
    }
}

enum Session {
    Modbus,
    Aurora(aurora::Reader),
}

/// One Modbus cycle: read DI and AI, write DO and AO.
fn modbus_cycle(
    port: &mut Port,
    cfg: &Config,
    shared: &Shared,
    out: &Outputs,
) -> Result<(Vec<bool>, Vec<u16>), IoError> {
    let c = cfg.counts;
    let mut di = Vec::new();
    let mut ai = Vec::new();
    if c.di > 0 {
        let req = Request::ReadDiscreteInputs {
            start: 0,
            count: c.di as u16,
        };
        if let Response::Bits(b) = transact(port, cfg, &req, |e| shared.count_error(e))? {
            di = b;
        }
    }
    if c.ai > 0 {
        let req = Request::ReadInputRegisters {
            start: 0,
            count: c.ai as u16,
        };
        if let Response::Registers(r) = transact(port, cfg, &req, |e| shared.count_error(e))? {
            ai = r;
        }
    }
    if c.r#do > 0 {
        let req = Request::write_coils(0, &out.r#do);
        transact(port, cfg, &req, |e| shared.count_error(e))?;
    }
    if c.ao > 0 {
        let req = Request::write_registers(0, &out.ao);
        transact(port, cfg, &req, |e| shared.count_error(e))?;
    }
    if c == Counts::default() {
        // Nothing to exchange: do not spin.
        std::thread::sleep(cfg.timeout);
    }
    Ok((di, ai))
}

/// The driver for `--io arduino:<port>[,options]` (`spec` is the whole
/// option). The board's channels come from the project's `[board]`; a
/// project without one is taken to be wired as the AuroraLD PLC1805 (the
/// `aurora` map on a Nano: 6 DI, 6 DO, 4 AI, 4 AO).
pub fn driver(spec: &str, board: Option<&alba_project::config::Board>) -> Result<Box<dyn alba_runtime::Io>, Error> {
    let rest = spec
        .strip_prefix("arduino:")
        .ok_or_else(|| Error::Options(format!("`{spec}` is not arduino:<serial port>[,options]")))?;
    let counts = match board {
        Some(b) => Counts::of(&b.map),
        None => Counts::of(&PinMap::preset("aurora").unwrap_or_default()),
    };
    let cfg = Config::parse(rest, counts)?;
    Ok(Box::new(ArduinoIo::start(cfg)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::serial::tests::C;

    #[test]
    fn only_arduino_specs() {
        assert!(driver("sim", None).is_err());
    }

    /// A port that does not exist: the driver reports the loss through its
    /// status and keeps trying; the engine side never waits.
    #[test]
    fn missing_port_is_a_status_not_a_failure() {
        let mut cfg = Config::parse("/nonexistent/alba-tty,backoff_ms=5,backoff_max_ms=20", C).expect("config");
        cfg.reset_delay = Duration::ZERO;
        let io = ArduinoIo::start(cfg).expect("driver");
        let t0 = Instant::now();
        while io.status().errors < 3 {
            assert!(t0.elapsed() < Duration::from_secs(5), "no retries");
            std::thread::sleep(Duration::from_millis(5));
        }
        let s = io.status();
        assert!(!s.ok && s.opens == 0);
        assert!(
            s.last_error
                .as_deref()
                .is_some_and(|e| e.contains("cannot open /nonexistent/alba-tty"))
        );
        assert_eq!(io.inputs(), (vec![], vec![]));
    }
}
