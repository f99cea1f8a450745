//! `--io board:<port>[,option=value…]`: attach to a board that runs the
//! project's exported sketch (`alba export arduino`) and watch it live
//! through the sketch's monitoring link (a Modbus RTU slave serving the
//! program memory between scans; see `alba_arduino::sketch::LinkMap`).
//!
//! The runtime runs in attach mode (`Io::runs_program`): it does not scan;
//! each cycle loads the memory last read from the board, so the studio, the
//! API and the historian show the board's values. Operator writes go to the
//! board. A link thread owns the port (the engine thread never waits on it,
//! except for a write, which waits for the board's answer): it checks the
//! board's identity once per connection — the magic word, the memory sizes
//! and the program id must be those of the sketch this project exports —
//! then reads the whole memory in requests of at most 24 registers or 256
//! coils (what the link answers without ever delaying a scan), again and
//! again. Link loss: `S:IOOK` false, `S:IOERRORS` counts, the last values
//! stay, the port is reopened with back-off. A board running another
//! program stops the runtime with a message saying so.

use crate::error::Error;
use crate::link::{Stop, lock};
use crate::serial::{self, Config, Counts, Port, open};
use alba_arduino::sketch::{self, LINK_MAGIC, LinkMap, Target};
use alba_engine::Engine;
use alba_ir::{Memory, Place, Program};
use alba_modbus_proto::pdu::{Request, Response};
use alba_model::Value;
use alba_runtime::IoError;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

/// What the board must report to be attached to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Identity {
    pub sizes: [usize; 5],
    pub scan_ms: u16,
    pub program_id: u32,
}

impl Identity {
    /// The identity of `prog` exported for `target`.
    pub fn of(prog: &Program, target: &Target) -> Result<(Identity, LinkMap), Error> {
        let control = sketch::control_program(prog);
        let s = sketch::generate(&control, "attach", target)
            .map_err(|d| Error::NotForBoard(d.first().map_or(String::new(), |d| d.message.clone())))?;
        let m = &control.init;
        Ok((
            Identity {
                sizes: [m.b.len(), m.i.len(), m.f.len(), m.l.len(), m.m.len()],
                scan_ms: target.scan_ms.min(u32::from(u16::MAX)) as u16,
                program_id: s.program_id,
            },
            LinkMap::of(m),
        ))
    }
}

/// A write waiting for the link thread, with where to send the outcome.
type WriteReq = (Place, Value, Sender<Result<(), IoError>>);

struct Shared {
    stop: Stop,
    ok: AtomicBool,
    errors: AtomicU64,
    /// Memory read from the board, taken by the engine thread.
    memory: Mutex<Option<Memory>>,
    /// Why attaching is impossible (another program on the board).
    fatal: Mutex<Option<IoError>>,
}

pub struct AttachIo {
    name: String,
    shared: Arc<Shared>,
    writes: Sender<WriteReq>,
    thread: Option<JoinHandle<()>>,
}

impl AttachIo {
    pub fn start(cfg: Config, prog: &Program, target: &Target) -> Result<AttachIo, Error> {
        let (id, map) = Identity::of(prog, target)?;
        let shared = Arc::new(Shared {
            stop: Stop::default(),
            ok: AtomicBool::new(false),
            errors: AtomicU64::new(0),
            memory: Mutex::new(None),
            fatal: Mutex::new(None),
        });
        let (tx, rx) = mpsc::channel();
        let name = format!("board:{}", cfg.port);
        let template = prog.init.clone();
        let s = shared.clone();
        let thread = std::thread::Builder::new()
            .name("alba-attach".into())
            .spawn(move || link_thread(cfg, id, map, template, s, rx))
            .map_err(|source| Error::Thread {
                what: "the link thread",
                source,
            })?;
        Ok(AttachIo {
            name,
            shared,
            writes: tx,
            thread: Some(thread),
        })
    }
}

impl Drop for AttachIo {
    fn drop(&mut self) {
        self.shared.stop.request();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl alba_runtime::Io for AttachIo {
    fn name(&self) -> &str {
        &self.name
    }

    fn read_inputs(&mut self, engine: &mut Engine) -> Result<(), IoError> {
        if let Some(why) = lock(&self.shared.fatal).clone() {
            return Err(why);
        }
        if let Some(m) = lock(&self.shared.memory).take() {
            engine
                .load_memory(&m)
                .map_err(|e| IoError::MemoryMismatch(e.to_string()))?;
        }
        let errors = self.shared.errors.load(Ordering::Relaxed).min(i32::MAX as u64) as i32;
        engine.set_io_status(self.shared.ok.load(Ordering::Relaxed), errors);
        Ok(())
    }

    fn write_outputs(&mut self, _: &Engine) -> Result<(), IoError> {
        Ok(())
    }

    fn runs_program(&self) -> bool {
        true
    }

    fn write_remote(&mut self, place: Place, value: Value) -> Option<Result<(), IoError>> {
        let (tx, rx) = mpsc::channel();
        if self.writes.send((place, value, tx)).is_err() {
            return Some(Err(IoError::LinkStopped));
        }
        Some(
            rx.recv_timeout(Duration::from_secs(WRITE_CONFIRM_S))
                .unwrap_or(Err(IoError::WriteTimeout { secs: WRITE_CONFIRM_S })),
        )
    }
}

fn link_thread(
    cfg: Config,
    id: Identity,
    map: LinkMap,
    template: Memory,
    shared: Arc<Shared>,
    writes: Receiver<WriteReq>,
) {
    let mut backoff = cfg.backoff_min;
    while !shared.stop.stopping() {
        let failed = match open(&cfg) {
            Ok(mut port) => {
                shared.stop.sleep(cfg.reset_delay);
                let r = session(&mut port, &cfg, &id, map, &template, &shared, &writes);
                shared.ok.store(false, Ordering::Relaxed);
                match r {
                    Ok(()) => return,
                    Err(e) => e,
                }
            }
            Err(e) => e,
        };
        shared.errors.fetch_add(1, Ordering::Relaxed);
        // Writes cannot wait for the link to come back.
        while let Ok((_, _, reply)) = writes.try_recv() {
            let _ = reply.send(Err(IoError::NoLink(Box::new(failed.clone()))));
        }
        shared.stop.sleep(backoff);
        backoff = (backoff * 2).min(cfg.backoff_max);
    }
}

/// One connection: identify, then read and write until the link fails
/// (`Err`) or the runtime stops (`Ok`).
fn session(
    port: &mut Port,
    cfg: &Config,
    id: &Identity,
    map: LinkMap,
    template: &Memory,
    shared: &Shared,
    writes: &Receiver<WriteReq>,
) -> Result<(), IoError> {
    let info = regs(port, cfg, shared, Request::ReadInputRegisters { start: 0, count: 12 })?;
    let got = Identity {
        sizes: [info[2], info[3], info[4], info[5], info[6]].map(usize::from),
        scan_ms: info[7],
        program_id: u32::from(info[8]) << 16 | u32::from(info[9]),
    };
    if info[0] != LINK_MAGIC || info[1] != 1 {
        let why = IoError::WrongDevice(format!(
            "the device on {} is not an Alba sketch with a monitoring link (it answered {:04X} {:04X}); export with `alba export arduino` and upload",
            cfg.port, info[0], info[1]
        ));
        *lock(&shared.fatal) = Some(why.clone());
        return Err(why);
    }
    if got != *id {
        let why = IoError::WrongDevice(format!(
            "the board on {} runs another program (id {:08X}, memory {:?}, scan {} ms; this project exports id {:08X}, memory {:?}, scan {} ms): export and upload it again",
            cfg.port, got.program_id, got.sizes, got.scan_ms, id.program_id, id.sizes, id.scan_ms
        ));
        *lock(&shared.fatal) = Some(why.clone());
        return Err(why);
    }
    let mut failures = 0;
    while !shared.stop.stopping() {
        while let Ok((place, value, reply)) = writes.try_recv() {
            let r = write(port, cfg, shared, map, place, value);
            let link_down = matches!(r, Err(ref e) if e.is_link_down());
            let _ = reply.send(r.clone());
            if link_down {
                return r;
            }
        }
        match read_memory(port, cfg, shared, map, template) {
            Ok(m) => {
                failures = 0;
                *lock(&shared.memory) = Some(m);
                shared.ok.store(true, Ordering::Relaxed);
            }
            Err(e) => {
                shared.ok.store(false, Ordering::Relaxed);
                failures += 1;
                if failures >= cfg.reopen_after || e.is_link_down() {
                    return Err(e);
                }
            }
        }
    }
    Ok(())
}

fn transact(port: &mut Port, cfg: &Config, shared: &Shared, req: &Request<'_>) -> Result<Response, IoError> {
    serial::transact(port, cfg, req, |_| {
        shared.errors.fetch_add(1, Ordering::Relaxed);
    })
    .inspect_err(|e| {
        if matches!(e, IoError::Timeout(_)) {
            shared.errors.fetch_add(1, Ordering::Relaxed);
        }
    })
}

fn regs(port: &mut Port, cfg: &Config, shared: &Shared, req: Request<'_>) -> Result<Vec<u16>, IoError> {
    match transact(port, cfg, shared, &req)? {
        Response::Registers(r) => Ok(r),
        other => Err(IoError::UnexpectedAnswer(format!("{other:?}"))),
    }
}

const MAX_REGS: u16 = 24;
/// How long an operator's write waits for the board's confirmation.
const WRITE_CONFIRM_S: u64 = 3;
const MAX_BITS: u16 = 256;

/// The board's whole memory: coils for the bools, holding registers for the rest.
fn read_memory(
    port: &mut Port,
    cfg: &Config,
    shared: &Shared,
    map: LinkMap,
    template: &Memory,
) -> Result<Memory, IoError> {
    let mut m = template.clone();
    let nb = m.b.len() as u16;
    let mut at = 0u16;
    while at < nb {
        let qty = (nb - at).min(MAX_BITS);
        match transact(port, cfg, shared, &Request::ReadCoils { start: at, count: qty })? {
            Response::Bits(bits) => {
                for (k, b) in bits.into_iter().take(qty as usize).enumerate() {
                    m.b[at as usize + k] = b;
                }
            }
            other => return Err(IoError::UnexpectedAnswer(format!("{other:?}"))),
        }
        at += qty;
    }
    let mut bytes = Vec::with_capacity(2 * map.end as usize);
    let mut r = 0u16;
    let end = map.end.min(u32::from(u16::MAX)) as u16;
    while r < end {
        let qty = (end - r).min(MAX_REGS);
        for v in regs(
            port,
            cfg,
            shared,
            Request::ReadHoldingRegisters { start: r, count: qty },
        )? {
            bytes.extend_from_slice(&v.to_be_bytes());
        }
        r += qty;
    }
    let word = |at: usize, n: usize| -> Option<&[u8]> { bytes.get(at..at + n) };
    for k in 0..m.i.len() {
        if let Some(b) = word(2 * map.i as usize + 4 * k, 4) {
            m.i[k] = i32::from_be_bytes([b[0], b[1], b[2], b[3]]);
        }
    }
    for k in 0..m.f.len() {
        if let Some(b) = word(2 * map.f as usize + 4 * k, 4) {
            m.f[k] = f32::from_be_bytes([b[0], b[1], b[2], b[3]]);
        }
    }
    for k in 0..m.l.len() {
        if let Some(b) = word(2 * map.l as usize + 8 * k, 8) {
            let mut a = [0u8; 8];
            a.copy_from_slice(b);
            m.l[k] = i64::from_be_bytes(a);
        }
    }
    let mlen = m.m.len();
    if let Some(b) = word(2 * map.m as usize, mlen) {
        m.m.copy_from_slice(b);
    }
    Ok(m)
}

fn int_of(v: Value) -> Option<i64> {
    match v {
        Value::Bool(b) => Some(i64::from(b)),
        Value::Sint(x) => Some(i64::from(x)),
        Value::Int(x) => Some(i64::from(x)),
        Value::Dint(x) | Value::Time(x) => Some(i64::from(x)),
        Value::Lint(x) => Some(x),
        Value::Real(_) | Value::Lreal(_) => None,
    }
}

/// Writes bytes at byte offset `at` of the register file, reading the
/// covering registers first when the range is not register-aligned.
fn write_bytes(port: &mut Port, cfg: &Config, shared: &Shared, at: usize, data: &[u8]) -> Result<(), IoError> {
    let first = at / 2;
    let last = (at + data.len()).div_ceil(2);
    let qty = (last - first) as u16;
    let mut buf = if at.is_multiple_of(2) && data.len().is_multiple_of(2) {
        vec![0u8; 2 * qty as usize]
    } else {
        regs(
            port,
            cfg,
            shared,
            Request::ReadHoldingRegisters {
                start: first as u16,
                count: qty,
            },
        )?
        .iter()
        .flat_map(|v| v.to_be_bytes())
        .collect()
    };
    buf[at - 2 * first..at - 2 * first + data.len()].copy_from_slice(data);
    transact(
        port,
        cfg,
        shared,
        &Request::WriteMultipleRegisters {
            start: first as u16,
            values: buf.into(),
        },
    )
    .map(|_| ())
}

fn write(
    port: &mut Port,
    cfg: &Config,
    shared: &Shared,
    map: LinkMap,
    place: Place,
    value: Value,
) -> Result<(), IoError> {
    let mbase = 2 * map.m as usize;
    let bad = || IoError::DoesNotFit(format!("{value} cannot be written there"));
    match place {
        Place::Bool(b) => {
            let on = int_of(value).ok_or_else(bad)? != 0;
            transact(
                port,
                cfg,
                shared,
                &Request::WriteSingleCoil {
                    addr: b.0 as u16,
                    value: on,
                },
            )
            .map(|_| ())
        }
        Place::Int(i, _) => {
            let v = int_of(value).ok_or_else(bad)? as i32;
            write_bytes(
                port,
                cfg,
                shared,
                2 * map.i as usize + 4 * i.0 as usize,
                &v.to_be_bytes(),
            )
        }
        Place::Real(f) => {
            let Value::Real(v) = value else { return Err(bad()) };
            write_bytes(
                port,
                cfg,
                shared,
                2 * map.f as usize + 4 * f.0 as usize,
                &v.to_be_bytes(),
            )
        }
        Place::Lint(l) => {
            let v = int_of(value).ok_or_else(bad)?;
            write_bytes(
                port,
                cfg,
                shared,
                2 * map.l as usize + 8 * l.0 as usize,
                &v.to_be_bytes(),
            )
        }
        Place::MBit { byte, bit } => {
            let on = int_of(value).ok_or_else(bad)? != 0;
            let r = regs(
                port,
                cfg,
                shared,
                Request::ReadHoldingRegisters {
                    start: ((mbase + byte as usize) / 2) as u16,
                    count: 1,
                },
            )?;
            let mut b = r.first().copied().unwrap_or(0).to_be_bytes()[(mbase + byte as usize) % 2];
            b = if on { b | 1 << (bit & 7) } else { b & !(1 << (bit & 7)) };
            write_bytes(port, cfg, shared, mbase + byte as usize, &[b])
        }
        Place::MByte(byte) => write_bytes(
            port,
            cfg,
            shared,
            mbase + byte as usize,
            &[int_of(value).ok_or_else(bad)? as u8],
        ),
        Place::MWord(byte) => {
            let v = int_of(value).ok_or_else(bad)? as i16;
            write_bytes(port, cfg, shared, mbase + byte as usize, &v.to_be_bytes())
        }
        Place::MDword(byte, _) => {
            let v = int_of(value).ok_or_else(bad)? as i32;
            write_bytes(port, cfg, shared, mbase + byte as usize, &v.to_be_bytes())
        }
        Place::MReal(byte) => {
            let Value::Real(v) = value else { return Err(bad()) };
            write_bytes(port, cfg, shared, mbase + byte as usize, &v.to_be_bytes())
        }
        Place::Lreal(_) => Err(IoError::DoesNotFit("a board has no LREAL".into())),
    }
}

/// The driver for `--io board:<port>[,options]`: the options of
/// `arduino:` (`slave`, `timeout_ms`, `retries`, `reset_ms`, `backoff_ms`,
/// `backoff_max_ms`); the board and its pin map from the project's
/// `[board]` (else a Nano with the aurora map), as for the export.
pub fn driver(spec: &str, prog: &Program, target: &Target) -> Result<Box<dyn alba_runtime::Io>, Error> {
    let rest = spec
        .strip_prefix("board:")
        .ok_or_else(|| Error::Options(format!("`{spec}` is not board:<serial port>[,options]")))?;
    let cfg = Config::parse(rest, Counts::default())?;
    Ok(Box::new(AttachIo::start(cfg, prog, target)?))
}
