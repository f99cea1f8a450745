//! `--io modbus`: Alba as a Modbus master, TCP or RTU. Every
//! `[[modbus_device]]` of alba.toml is a remote slave whose coils, discrete
//! inputs and registers are mapped onto the I/O image (docs/protocols.md,
//! "Modbus master I/O"). RTU devices on one serial port share it: each
//! transaction takes the port's mutex (link threads only, never the engine).
//!
//! The design is the one of the Arduino driver (`arduino.rs`): one link thread per device
//! owns its TCP connection and polls at the device's period; the engine
//! thread's `read_inputs`/`write_outputs` only copy shared images (a mutex
//! held for the copy, never across I/O), so a slow or dead slave never
//! delays a scan.
//!
//! - Requests are coalesced: the mapped items of one area that are
//!   contiguous on the slave are read (FC 1 2 3 4) or written (FC 15 16)
//!   in one request, split at the function codes' limits.
//! - Outputs are written when the engine changed them and every
//!   `refresh_ms` anyway, and at once after a (re)connection.
//! - A transaction without a valid answer within `timeout_ms` is retried
//!   `retries` times; then the device is lost: `S:IOOK` goes false (it is
//!   true only while every device answers), `S:IOERRORS` counts every failed
//!   attempt, the connection is closed and reopened with exponential
//!   back-off (`timeout_ms` up to 5 s). Inputs of a lost device keep their
//!   last values.
//! - Safe outputs: a master cannot set the outputs of a slave it cannot
//!   reach; the slave's own communication watchdog must do that. What the
//!   driver does: it writes every mapped output of a device as 0/off when
//!   it stops (`alba run` ends), and after a recovery it writes the
//!   engine's current outputs before anything else.

use crate::error::Error;
use crate::link::{Outputs, Stop, load_inputs, lock};
use crate::serial::{Port, RtuError, rtu_exchange};
use alba_engine::Engine;
use alba_modbus_proto::mbap::{self, Header};
use alba_modbus_proto::pdu::{self, FrameError, Request, Response};
use alba_model::address::Address;
use alba_project::config::{DeviceLink, ModbusArea, ModbusDevice};
use alba_runtime::IoError;
use std::io::{Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use alba_modbus_proto::pdu::{MAX_READ_BITS, MAX_READ_REGS, MAX_WRITE_BITS, MAX_WRITE_REGS};

/// One request's worth of contiguous remote items and the local channel of
/// each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Block {
    pub area: ModbusArea,
    /// Written (an output) or read.
    pub write: bool,
    pub addr: u16,
    /// `locals[k]` is the local channel of remote item `addr + k`.
    pub locals: Vec<u32>,
}

impl Block {
    fn limit(area: ModbusArea, write: bool) -> u16 {
        match (area.is_bits(), write) {
            (true, false) => MAX_READ_BITS,
            (false, false) => MAX_READ_REGS,
            (true, true) => MAX_WRITE_BITS,
            (false, true) => MAX_WRITE_REGS,
        }
    }

    fn read_request(&self) -> Request<'static> {
        let (start, count) = (self.addr, self.locals.len() as u16);
        match self.area {
            ModbusArea::Coil => Request::ReadCoils { start, count },
            ModbusArea::DiscreteInput => Request::ReadDiscreteInputs { start, count },
            ModbusArea::HoldingRegister => Request::ReadHoldingRegisters { start, count },
            ModbusArea::InputRegister => Request::ReadInputRegisters { start, count },
        }
    }
}

/// The blocks of a device: its mappings sorted by area, direction and
/// address, merged where they touch, split at the function code limits.
pub fn plan(dev: &ModbusDevice) -> Vec<Block> {
    let mut items: Vec<(ModbusArea, bool, u16, u32)> = Vec::new();
    for m in &dev.map {
        let write = matches!(m.at, Address::DigitalOut(_) | Address::AnalogOut(_));
        let (first, _) = m.at.footprint();
        for k in 0..m.count {
            items.push((m.area, write, m.start + k, first + u32::from(k)));
        }
    }
    items.sort();
    // A remote item mapped twice (read into two channels) is read once per
    // mapping: keep both by allowing duplicates to start a new block.
    let mut blocks: Vec<Block> = Vec::new();
    for (area, write, addr, local) in items {
        if let Some(b) = blocks.last_mut()
            && b.area == area
            && b.write == write
            && u32::from(b.addr) + b.locals.len() as u32 == u32::from(addr)
            && b.locals.len() < usize::from(Block::limit(area, write))
        {
            b.locals.push(local);
            continue;
        }
        blocks.push(Block {
            area,
            write,
            addr,
            locals: vec![local],
        });
    }
    blocks
}

/// Health of one device.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Status {
    pub ok: bool,
    pub errors: u64,
    /// Complete polls (every block read and every due write done).
    pub cycles: u64,
    pub connects: u64,
    pub last_error: Option<String>,
    /// Duration of the last complete poll.
    pub last_cycle: Option<Duration>,
}

#[derive(Default)]
struct Image {
    di: Vec<bool>,
    ai: Vec<u16>,
    /// Channels some device has delivered at least once.
    di_known: Vec<bool>,
    ai_known: Vec<bool>,
}

struct DeviceShared {
    status: Mutex<Status>,
    ok: AtomicBool,
    errors: AtomicU64,
}

struct Shared {
    inputs: Mutex<Image>,
    outputs: Mutex<Outputs>,
    devices: Vec<DeviceShared>,
    stop: Stop,
}

/// The driver: `alba_runtime::Io` over the `[[modbus_device]]` slaves.
pub struct ModbusMasterIo {
    name: String,
    names: Vec<String>,
    shared: Arc<Shared>,
    threads: Vec<JoinHandle<()>>,
    di: Vec<bool>,
    ai: Vec<u16>,
    di_known: Vec<bool>,
    ai_known: Vec<bool>,
}

fn image_sizes(devices: &[ModbusDevice]) -> [usize; 4] {
    let mut n = [0usize; 4];
    for m in devices.iter().flat_map(|d| &d.map) {
        let (first, _) = m.at.footprint();
        let end = first as usize + usize::from(m.count);
        let i = match m.at {
            Address::DigitalIn(_) => 0,
            Address::DigitalOut(_) => 1,
            Address::AnalogIn(_) => 2,
            Address::AnalogOut(_) => 3,
            Address::Marker { .. } => continue,
        };
        n[i] = n[i].max(end);
    }
    n
}

impl ModbusMasterIo {
    /// Starts one link thread per device (they connect themselves: a slave
    /// that is not up yet is a status, not an error).
    pub fn start(devices: Vec<ModbusDevice>) -> Result<ModbusMasterIo, Error> {
        if devices.is_empty() {
            return Err(Error::NoModbusDevices);
        }
        let [ndi, ndo, nai, nao] = image_sizes(&devices);
        let shared = Arc::new(Shared {
            inputs: Mutex::new(Image {
                di: vec![false; ndi],
                ai: vec![0; nai],
                di_known: vec![false; ndi],
                ai_known: vec![false; nai],
            }),
            outputs: Mutex::new(Outputs::new(ndo, nao)),
            devices: devices
                .iter()
                .map(|_| DeviceShared {
                    status: Mutex::new(Status::default()),
                    ok: AtomicBool::new(false),
                    errors: AtomicU64::new(0),
                })
                .collect(),
            stop: Stop::default(),
        });
        let names: Vec<String> = devices.iter().map(|d| d.name.clone()).collect();
        let name = format!("modbus ({})", names.join(", "));
        let mut threads = Vec::new();
        // Devices on one serial port share it (one transaction at a time).
        let mut buses: std::collections::HashMap<String, Arc<Mutex<Option<Port>>>> = Default::default();
        for (i, dev) in devices.into_iter().enumerate() {
            let s = shared.clone();
            let bus = match &dev.link {
                DeviceLink::Rtu { port, .. } => Some(buses.entry(port.clone()).or_default().clone()),
                DeviceLink::Tcp(_) => None,
            };
            let t = std::thread::Builder::new()
                .name(format!("alba-io-modbus-{i}"))
                .spawn(move || link_thread(dev, i, s, bus))
                .map_err(|source| Error::Thread {
                    what: "a Modbus link thread",
                    source,
                })?;
            threads.push(t);
        }
        Ok(ModbusMasterIo {
            name,
            names,
            shared,
            threads,
            di: Vec::with_capacity(ndi),
            ai: Vec::with_capacity(nai),
            di_known: Vec::with_capacity(ndi),
            ai_known: Vec::with_capacity(nai),
        })
    }

    /// Each device's name and status.
    pub fn status(&self) -> Vec<(String, Status)> {
        self.names
            .iter()
            .zip(&self.shared.devices)
            .map(|(n, d)| (n.clone(), lock(&d.status).clone()))
            .collect()
    }

    /// Every device answers.
    pub fn all_ok(&self) -> bool {
        self.shared.devices.iter().all(|d| d.ok.load(Ordering::Relaxed))
    }

    fn errors(&self) -> u64 {
        self.shared
            .devices
            .iter()
            .map(|d| d.errors.load(Ordering::Relaxed))
            .sum()
    }

    /// The latest input image (DI levels, AI registers).
    pub fn inputs(&self) -> (Vec<bool>, Vec<u16>) {
        let i = lock(&self.shared.inputs);
        (i.di.clone(), i.ai.clone())
    }

    /// Sets the outputs (what `write_outputs` does from an engine).
    pub fn set_outputs(&self, r#do: &[bool], ao: &[u16]) {
        lock(&self.shared.outputs).set(r#do, ao);
    }
}

impl Drop for ModbusMasterIo {
    fn drop(&mut self) {
        self.shared.stop.request();
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

impl alba_runtime::Io for ModbusMasterIo {
    fn name(&self) -> &str {
        &self.name
    }

    fn read_inputs(&mut self, engine: &mut Engine) -> Result<(), IoError> {
        let errors = self.errors().min(i32::MAX as u64) as i32;
        engine.set_io_status(self.all_ok(), errors);
        {
            let i = lock(&self.shared.inputs);
            self.di.clone_from(&i.di);
            self.ai.clone_from(&i.ai);
            self.di_known.clone_from(&i.di_known);
            self.ai_known.clone_from(&i.ai_known);
        }
        let (di_known, ai_known) = (&self.di_known, &self.ai_known);
        load_inputs(
            engine,
            self.di.iter().copied().enumerate().filter(|(n, _)| di_known[*n]),
            // A register is a two's complement INT.
            self.ai
                .iter()
                .map(|v| *v as i16)
                .enumerate()
                .filter(|(n, _)| ai_known[*n]),
        );
        Ok(())
    }

    fn write_outputs(&mut self, engine: &Engine) -> Result<(), IoError> {
        lock(&self.shared.outputs).copy_from(engine, |v| {
            v.clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16 as u16
        });
        Ok(())
    }
}

/// How one device is reached: its own TCP connection (MBAP framing), or a
/// serial bus shared with the other devices on that port (RTU framing).
enum Conn {
    Tcp(TcpConn),
    Rtu(RtuConn),
}

struct TcpConn {
    stream: TcpStream,
    tid: u16,
    unit: u8,
    timeout: Duration,
}

struct RtuConn {
    bus: Arc<Mutex<Option<Port>>>,
    port: String,
    baud: u32,
    unit: u8,
    timeout: Duration,
}

impl Conn {
    fn open(dev: &ModbusDevice, bus: Option<&Arc<Mutex<Option<Port>>>>) -> Result<Conn, IoError> {
        match (&dev.link, bus) {
            (DeviceLink::Rtu { port, baud }, Some(bus)) => {
                let c = RtuConn {
                    bus: bus.clone(),
                    port: port.clone(),
                    baud: *baud,
                    unit: dev.unit,
                    timeout: Duration::from_millis(u64::from(dev.timeout_ms)),
                };
                c.ensure_open()?;
                Ok(Conn::Rtu(c))
            }
            _ => TcpConn::open(dev).map(Conn::Tcp),
        }
    }

    fn transact(&mut self, req: &Request<'_>) -> Result<Response, IoError> {
        match self {
            Conn::Tcp(c) => c.transact(req),
            Conn::Rtu(c) => c.transact(req),
        }
    }
}

impl RtuConn {
    fn ensure_open(&self) -> Result<(), IoError> {
        let mut bus = lock(&self.bus);
        if bus.is_none() {
            let p = serialport::new(&self.port, self.baud)
                .data_bits(serialport::DataBits::Eight)
                .parity(serialport::Parity::None)
                .stop_bits(serialport::StopBits::One)
                .flow_control(serialport::FlowControl::None)
                .timeout(self.timeout)
                .open()
                .map_err(|e| IoError::Link(format!("cannot open {}: {e}", self.port)))?;
            *bus = Some(p);
        }
        Ok(())
    }

    /// One RTU transaction with the bus held; a port error closes the port
    /// (the next connection attempt reopens it).
    fn transact(&mut self, req: &Request<'_>) -> Result<Response, IoError> {
        let mut bus = lock(&self.bus);
        let Some(port) = bus.as_mut() else {
            return Err(IoError::Link(format!("{} is closed", self.port)));
        };
        let r = rtu_exchange(port, self.unit, self.timeout, req).map_err(|e| match e {
            RtuError::Port(m) => IoError::Link(m),
            RtuError::NoAnswer(m) => IoError::Timeout(m),
            RtuError::Answer(e @ FrameError::Exception(_)) => {
                IoError::Refused(format!("the slave refused {}: {e}", describe(req)))
            }
            // A corrupted frame on a serial line: worth a retry.
            RtuError::Answer(e) => IoError::Timeout(format!("bad answer to {}: {e}", describe(req))),
        });
        // The silence between frames: 3.5 characters (11 bits each), at least 2 ms.
        let gap = Duration::from_micros(38_500_000 / u64::from(self.baud.max(1))).max(Duration::from_millis(2));
        std::thread::sleep(gap);
        if matches!(r, Err(IoError::Link(_))) {
            *bus = None;
        }
        r
    }
}

impl TcpConn {
    fn open(dev: &ModbusDevice) -> Result<TcpConn, IoError> {
        let timeout = Duration::from_millis(u64::from(dev.timeout_ms));
        let tcp = dev.link.describe();
        let addrs: Vec<_> = tcp
            .to_socket_addrs()
            .map_err(|e| IoError::Link(format!("cannot resolve {tcp}: {e}")))?
            .collect();
        let mut last = format!("{tcp} resolves to no address");
        for a in addrs {
            match TcpStream::connect_timeout(&a, timeout) {
                Ok(stream) => {
                    let _ = stream.set_nodelay(true);
                    return Ok(TcpConn {
                        stream,
                        tid: 0,
                        unit: dev.unit,
                        timeout,
                    });
                }
                Err(e) => last = format!("cannot connect to {tcp}: {e}"),
            }
        }
        Err(IoError::Link(last))
    }

    /// Sends `req`, waits for its answer (skipping stale answers of earlier
    /// timed-out transactions) and decodes it.
    fn transact(&mut self, req: &Request<'_>) -> Result<Response, IoError> {
        self.tid = self.tid.wrapping_add(1);
        let frame = mbap::request(
            Header {
                transaction: self.tid,
                unit: self.unit,
            },
            req,
        );
        let io = |e: std::io::Error| IoError::Link(format!("connection: {e}"));
        self.stream.write_all(&frame).map_err(io)?;
        let deadline = Instant::now() + self.timeout;
        let mut adu = Vec::with_capacity(mbap::MAX_ADU);
        loop {
            adu.resize(mbap::MBAP_LEN, 0);
            self.read_exact_by(&mut adu, deadline)?;
            let Ok(Some(len)) = mbap::adu_len(&adu) else {
                return Err(IoError::Link(format!(
                    "malformed MBAP header {:02X?} from the slave",
                    &adu[..]
                )));
            };
            adu.resize(len, 0);
            self.read_exact_by(&mut adu[mbap::MBAP_LEN..], deadline)?;
            let mbap::Split::Frame { header, pdu, .. } = mbap::split(&adu) else {
                return Err(IoError::Link("malformed MBAP frame from the slave".into()));
            };
            if header.transaction != self.tid {
                // The late answer of a transaction that timed out.
                continue;
            }
            if header.unit != self.unit {
                let e = FrameError::WrongSlave(header.unit);
                return Err(IoError::Link(format!("bad answer to {}: {e}", describe(req))));
            }
            return pdu::decode_reply(req, pdu).map_err(|e| match e {
                FrameError::Exception(_) => IoError::Refused(format!("the slave refused {}: {e}", describe(req))),
                e => IoError::Link(format!("bad answer to {}: {e}", describe(req))),
            });
        }
    }

    fn read_exact_by(&mut self, buf: &mut [u8], deadline: Instant) -> Result<(), IoError> {
        let mut got = 0;
        while got < buf.len() {
            let now = Instant::now();
            if now >= deadline {
                return Err(IoError::Timeout(format!(
                    "no answer within {} ms",
                    self.timeout.as_millis()
                )));
            }
            let _ = self.stream.set_read_timeout(Some(deadline - now));
            match self.stream.read(&mut buf[got..]) {
                Ok(0) => return Err(IoError::Link("the slave closed the connection".into())),
                Ok(n) => got += n,
                Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(IoError::Link(format!("connection: {e}"))),
            }
        }
        Ok(())
    }
}

fn describe(req: &Request<'_>) -> String {
    let n = req.count();
    match req {
        Request::ReadCoils { start, .. } => format!("reading {n} coils from {start}"),
        Request::ReadDiscreteInputs { start, .. } => format!("reading {n} discrete inputs from {start}"),
        Request::ReadHoldingRegisters { start, .. } => format!("reading {n} holding registers from {start}"),
        Request::ReadInputRegisters { start, .. } => format!("reading {n} input registers from {start}"),
        Request::WriteMultipleCoils { start, .. } => format!("writing {n} coils from {start}"),
        Request::WriteMultipleRegisters { start, .. } => format!("writing {n} holding registers from {start}"),
        other => format!("function {}", other.function()),
    }
}

/// The write request of an output block with the current values (`zero`:
/// the safe values).
fn write_request(b: &Block, out: &Outputs, zero: bool) -> Request<'static> {
    if b.area.is_bits() {
        let values: Vec<bool> = b
            .locals
            .iter()
            .map(|&l| !zero && out.r#do.get(l as usize).copied().unwrap_or(false))
            .collect();
        Request::write_coils(b.addr, &values)
    } else {
        let values: Vec<u16> = b
            .locals
            .iter()
            .map(|&l| {
                if zero {
                    0
                } else {
                    out.ao.get(l as usize).copied().unwrap_or(0)
                }
            })
            .collect();
        Request::write_registers(b.addr, &values)
    }
}

struct Device {
    dev: ModbusDevice,
    index: usize,
    shared: Arc<Shared>,
    blocks: Vec<Block>,
}

impl Device {
    fn me(&self) -> &DeviceShared {
        &self.shared.devices[self.index]
    }

    fn error(&self, why: &IoError, lost: bool) {
        let d = self.me();
        d.errors.fetch_add(1, Ordering::Relaxed);
        if lost {
            d.ok.store(false, Ordering::Relaxed);
        }
        let mut s = lock(&d.status);
        s.errors += 1;
        s.last_error = Some(why.to_string());
        if lost {
            s.ok = false;
        }
    }

    /// A transaction with retries; every failed attempt is counted.
    fn transact(&self, conn: &mut Conn, req: &Request<'_>) -> Result<Response, IoError> {
        let mut attempt = 0;
        loop {
            match conn.transact(req) {
                Ok(r) => return Ok(r),
                Err(e @ IoError::Timeout(_)) if attempt < self.dev.retries && !self.shared.stop.stopping() => {
                    self.error(&e, false);
                    attempt += 1;
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// One poll: every read block, then every output block due.
    fn poll(&self, conn: &mut Conn, written: &mut [Option<(Request<'static>, Instant)>]) -> Result<(), IoError> {
        let refresh = Duration::from_millis(u64::from(self.dev.refresh_ms));
        for (b, last) in self.blocks.iter().zip(written.iter_mut()) {
            if b.write {
                let req = write_request(b, &lock(&self.shared.outputs), false);
                let due = match last {
                    Some((prev, at)) => *prev != req || at.elapsed() >= refresh,
                    None => true,
                };
                if due {
                    self.transact(conn, &req)?;
                    *last = Some((req, Instant::now()));
                }
            } else {
                let resp = self.transact(conn, &b.read_request())?;
                let mut img = lock(&self.shared.inputs);
                let img = &mut *img;
                match resp {
                    Response::Bits(bits) => {
                        let (vals, known) = if b.area.is_bits() {
                            (&mut img.di, &mut img.di_known)
                        } else {
                            continue;
                        };
                        for (&l, v) in b.locals.iter().zip(bits) {
                            if let (Some(d), Some(k)) = (vals.get_mut(l as usize), known.get_mut(l as usize)) {
                                *d = v;
                                *k = true;
                            }
                        }
                    }
                    Response::Registers(regs) => {
                        for (&l, v) in b.locals.iter().zip(regs) {
                            if let (Some(d), Some(k)) = (img.ai.get_mut(l as usize), img.ai_known.get_mut(l as usize)) {
                                *d = v;
                                *k = true;
                            }
                        }
                    }
                    Response::Written => {}
                }
            }
        }
        Ok(())
    }
}

fn link_thread(dev: ModbusDevice, index: usize, shared: Arc<Shared>, bus: Option<Arc<Mutex<Option<Port>>>>) {
    let blocks = plan(&dev);
    let d = Device {
        dev,
        index,
        shared,
        blocks,
    };
    let period = Duration::from_millis(u64::from(d.dev.poll_ms));
    let backoff_min = Duration::from_millis(u64::from(d.dev.timeout_ms)).min(Duration::from_secs(1));
    let backoff_max = Duration::from_secs(5);
    let mut backoff = backoff_min;
    let mut up: Option<bool> = None;
    let down = |up: &mut Option<bool>, why: &IoError| {
        if *up != Some(false) {
            let what = if up.is_none() { "no link yet" } else { "link lost" };
            eprintln!("I/O modbus device {}: {what} ({why}); retrying", d.dev.name);
            *up = Some(false);
        }
    };
    while !d.shared.stop.stopping() {
        let mut conn = match Conn::open(&d.dev, bus.as_ref()) {
            Ok(c) => c,
            Err(e) => {
                d.error(&e, true);
                down(&mut up, &e);
                d.shared.stop.sleep(backoff);
                backoff = (backoff * 2).min(backoff_max);
                continue;
            }
        };
        lock(&d.me().status).connects += 1;
        // After a (re)connection every output block is written at once.
        let mut written: Vec<Option<(Request<'static>, Instant)>> = vec![None; d.blocks.len()];
        let mut next = Instant::now();
        while !d.shared.stop.stopping() {
            let t0 = Instant::now();
            match d.poll(&mut conn, &mut written) {
                Ok(()) => {
                    let me = d.me();
                    me.ok.store(true, Ordering::Relaxed);
                    let mut s = lock(&me.status);
                    s.ok = true;
                    s.cycles += 1;
                    s.last_cycle = Some(t0.elapsed());
                    drop(s);
                    backoff = backoff_min;
                    if up != Some(true) {
                        eprintln!("I/O modbus device {}: link up ({})", d.dev.name, d.dev.link.describe());
                        up = Some(true);
                    }
                }
                Err(e) => {
                    d.error(&e, true);
                    down(&mut up, &e);
                    if !matches!(e, IoError::Refused(_)) {
                        break;
                    }
                }
            }
            next += period;
            let now = Instant::now();
            if next > now {
                d.shared.stop.sleep(next - now);
            } else {
                next = now;
            }
        }
        if d.shared.stop.stopping() {
            // Leave the slave's outputs off (one attempt each).
            let out = lock(&d.shared.outputs);
            let reqs: Vec<Request<'static>> = d
                .blocks
                .iter()
                .filter(|b| b.write)
                .map(|b| write_request(b, &out, true))
                .collect();
            drop(out);
            for r in reqs {
                if conn.transact(&r).is_err() {
                    break;
                }
            }
            break;
        }
        drop(conn);
        d.shared.stop.sleep(backoff);
        backoff = (backoff * 2).min(backoff_max);
    }
}

/// The driver for `--io modbus`: the devices of alba.toml.
pub fn driver(devices: &[ModbusDevice]) -> Result<Box<dyn alba_runtime::Io>, Error> {
    Ok(Box::new(ModbusMasterIo::start(devices.to_vec())?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_diag::{FileId, Span};
    use alba_project::config::ModbusMapping;

    fn mapping(area: ModbusArea, start: u16, count: u16, at: Address) -> ModbusMapping {
        ModbusMapping {
            area,
            start,
            count,
            at,
            span: Span::new(FileId(0), 0..0),
        }
    }

    fn device(map: Vec<ModbusMapping>) -> ModbusDevice {
        ModbusDevice {
            name: "d".into(),
            link: DeviceLink::Tcp("127.0.0.1:1".into()),
            unit: 1,
            poll_ms: 10,
            timeout_ms: 50,
            retries: 0,
            refresh_ms: 1000,
            map,
            span: Span::new(FileId(0), 0..0),
        }
    }

    #[test]
    fn blocks_are_coalesced_and_split_at_the_limits() {
        let d = device(vec![
            mapping(ModbusArea::DiscreteInput, 8, 8, Address::DigitalIn(8)),
            mapping(ModbusArea::DiscreteInput, 0, 8, Address::DigitalIn(0)),
            mapping(ModbusArea::DiscreteInput, 20, 1, Address::DigitalIn(16)),
            mapping(ModbusArea::InputRegister, 0, 300, Address::AnalogIn(0)),
            mapping(ModbusArea::Coil, 0, 4, Address::DigitalOut(0)),
            mapping(ModbusArea::Coil, 0, 4, Address::DigitalIn(17)),
            mapping(ModbusArea::HoldingRegister, 10, 2, Address::AnalogOut(0)),
        ]);
        let b = plan(&d);
        let shape: Vec<_> = b.iter().map(|b| (b.area, b.write, b.addr, b.locals.len())).collect();
        assert_eq!(
            shape,
            [
                (ModbusArea::Coil, false, 0, 4),
                (ModbusArea::Coil, true, 0, 4),
                (ModbusArea::DiscreteInput, false, 0, 16),
                (ModbusArea::DiscreteInput, false, 20, 1),
                (ModbusArea::InputRegister, false, 0, 125),
                (ModbusArea::InputRegister, false, 125, 125),
                (ModbusArea::InputRegister, false, 250, 50),
                (ModbusArea::HoldingRegister, true, 10, 2),
            ]
        );
        assert_eq!(b[2].locals, (0..16).collect::<Vec<u32>>());
        assert_eq!(b[0].locals, [17, 18, 19, 20]);
    }

    #[test]
    fn no_devices_is_an_error_and_a_dead_slave_is_a_status() {
        assert!(ModbusMasterIo::start(vec![]).is_err());
        // A port nothing listens on.
        let l = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
        let addr = l.local_addr().expect("addr");
        drop(l);
        let mut d = device(vec![mapping(ModbusArea::DiscreteInput, 0, 1, Address::DigitalIn(0))]);
        d.link = DeviceLink::Tcp(addr.to_string());
        let io = ModbusMasterIo::start(vec![d]).expect("driver");
        let t0 = Instant::now();
        while io.status()[0].1.errors < 2 {
            assert!(t0.elapsed() < Duration::from_secs(10), "no retries");
            std::thread::sleep(Duration::from_millis(5));
        }
        assert!(!io.all_ok());
        assert!(
            io.status()[0]
                .1
                .last_error
                .as_deref()
                .is_some_and(|e| e.contains("cannot connect"))
        );
    }
}
