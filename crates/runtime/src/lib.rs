//! The real-time runtime (SPEC §2.3): the engine on a thread of its own,
//! scanning on absolute deadlines of a monotonic clock.
//!
//! The engine thread owns program memory. Everything else talks to it
//! through a [`Handle`]: requests (writes, forces, run/stop, online edit,
//! monitoring) go through a bounded channel and are applied **between two
//! scans**; after every scan the thread publishes an immutable [`Snapshot`]
//! (memory, power flow, statistics) into a recycled buffer, without
//! allocating and without a lock ([`publish`]). A reader that is slow simply
//! sees a later snapshot: nothing it does can delay the engine.
//!
//! Each scan: apply queued requests → I/O reads the inputs → forced inputs
//! → scan → forced outputs → I/O writes the outputs → statistics → publish.
//! A deadline missed is counted as an overrun and skipped (late scans are
//! not run back to back); a scan longer than the watchdog stops the runtime
//! with a fault and the outputs in their safe state (off).

mod error;
pub mod health;
pub mod json;
mod publish;
pub mod realtime;
pub mod retain;

pub use error::{IoError, StartError};

use alba_engine::Engine;
use alba_ir::{Layout, Memory, Place, Program};
use alba_model::Value;
use health::Health;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};
use tokio::sync::{oneshot, watch};

/// How the runtime runs.
#[derive(Debug, Clone)]
pub struct Options {
    /// Scan period.
    pub scan_ms: u32,
    /// A scan longer than this stops the runtime with a fault.
    pub watchdog_ms: u32,
    /// Where retentive data is kept (`None`: not kept).
    pub retain_file: Option<PathBuf>,
    /// How often retentive data is saved while running (and on stop).
    pub retain_interval_ms: u64,
    /// What to do when the retain file cannot be used.
    pub on_retain_error: retain::OnError,
    /// Where problems with retentive data are reported (shared with the
    /// other stores of the application: the historian reports there too).
    pub health: Arc<Health>,
    /// The engine thread's scheduling (SCHED_FIFO, CPU, locked memory).
    pub realtime: realtime::Realtime,
    /// Compile the program to native code.
    pub native: bool,
    /// Start scanning at once (else wait for `run`).
    pub start_running: bool,
    /// Where every scan's start lateness is recorded (`alba bench --realtime`).
    pub scan_log: Option<Arc<ScanLog>>,
}

impl Options {
    pub fn new(scan_ms: u32) -> Options {
        Options {
            scan_ms,
            watchdog_ms: (scan_ms.saturating_mul(10)).max(500),
            retain_file: None,
            retain_interval_ms: 1000,
            on_retain_error: retain::OnError::Start,
            health: Arc::default(),
            realtime: realtime::Realtime::default(),
            native: true,
            start_running: true,
            scan_log: None,
        }
    }
}

impl Options {
    /// The same, keeping retentive data in `file`.
    pub fn with_retain(mut self, file: PathBuf) -> Options {
        self.retain_file = Some(file);
        self
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    Running,
    Stopped,
    Faulted,
}

impl RunState {
    pub fn name(self) -> &'static str {
        match self {
            RunState::Running => "running",
            RunState::Stopped => "stopped",
            RunState::Faulted => "faulted",
        }
    }
}

/// Scan statistics since the last run (µs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stats {
    pub last_us: u64,
    pub min_us: u64,
    pub max_us: u64,
    pub mean_us: u64,
    /// Largest lateness of a scan start.
    pub jitter_us: u64,
    pub overruns: u64,
    /// Scans since the last run.
    pub scans: u64,
}

impl Stats {
    fn record(&mut self, scan_us: u64, late_us: u64) {
        self.min_us = if self.scans == 0 {
            scan_us
        } else {
            self.min_us.min(scan_us)
        };
        self.max_us = self.max_us.max(scan_us);
        self.mean_us = (self.mean_us * self.scans + scan_us) / (self.scans + 1);
        self.scans += 1;
        self.last_us = scan_us;
        self.jitter_us = self.jitter_us.max(late_us);
    }

    /// As the six DINTs of the statistics tags (`S:SCANTIME` …).
    fn as_tags(&self) -> [i32; 6] {
        let c = |v: u64| v.min(i32::MAX as u64) as i32;
        [
            c(self.last_us),
            c(self.min_us),
            c(self.max_us),
            c(self.mean_us),
            c(self.jitter_us),
            c(self.overruns),
        ]
    }
}

/// The start lateness of every scan while recording, for benchmarks (`alba
/// bench --realtime`): the slots are made beforehand and the engine thread
/// fills them with atomic stores, so recording neither allocates nor locks.
/// Scans past its capacity are counted but not kept.
pub struct ScanLog {
    late_ns: Box<[std::sync::atomic::AtomicU64]>,
    /// Scans recorded (may exceed the capacity).
    scans: std::sync::atomic::AtomicUsize,
    overruns: std::sync::atomic::AtomicU64,
    recording: AtomicBool,
}

impl std::fmt::Debug for ScanLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ScanLog({} of {} scans)", self.scans(), self.late_ns.len())
    }
}

impl ScanLog {
    /// A log with room for `capacity` scans, not recording yet.
    pub fn new(capacity: usize) -> Arc<ScanLog> {
        Arc::new(ScanLog {
            late_ns: (0..capacity).map(|_| Default::default()).collect(),
            scans: Default::default(),
            overruns: Default::default(),
            recording: AtomicBool::new(false),
        })
    }

    /// Starts (or stops) recording.
    pub fn record(&self, on: bool) {
        self.recording.store(on, Ordering::Release);
    }

    /// The lateness of each scan recorded, ns, in order.
    pub fn late_ns(&self) -> Vec<u64> {
        let n = self.scans.load(Ordering::Acquire).min(self.late_ns.len());
        self.late_ns[..n].iter().map(|l| l.load(Ordering::Relaxed)).collect()
    }

    /// Deadlines missed while recording.
    pub fn overruns(&self) -> u64 {
        self.overruns.load(Ordering::Relaxed)
    }

    /// Scans recorded, kept or not.
    pub fn scans(&self) -> usize {
        self.scans.load(Ordering::Relaxed)
    }

    /// The engine thread's side (the only writer).
    fn scan(&self, late: Duration) {
        if !self.recording.load(Ordering::Acquire) {
            return;
        }
        let i = self.scans.load(Ordering::Relaxed);
        if let Some(slot) = self.late_ns.get(i) {
            slot.store(late.as_nanos() as u64, Ordering::Relaxed);
        }
        self.scans.store(i + 1, Ordering::Release);
    }

    fn missed(&self, n: u64) {
        if self.recording.load(Ordering::Acquire) {
            self.overruns.fetch_add(n, Ordering::Relaxed);
        }
    }
}

/// A forced input or output.
#[derive(Debug, Clone, PartialEq)]
pub struct Force {
    pub name: String,
    pub place: Place,
    pub value: Value,
    /// An input (it gets its prior value back when unforced).
    pub input: bool,
    /// The value before the force: an input gets it back when the force
    /// is removed (a real I/O driver overwrites it at its next read; the
    /// simulated one does not).
    pub prior: Value,
}

/// What the runtime published after a scan (or a state change).
#[derive(Debug, Clone)]
pub struct Snapshot {
    pub program: Arc<Program>,
    pub memory: Memory,
    /// Scans since the runtime started.
    pub scans: u64,
    /// Engine clock (ms since the runtime started).
    pub clock_ms: u64,
    /// Unix time of the publication, ms.
    pub unix_ms: i64,
    pub state: RunState,
    /// Why it is faulted.
    pub fault: Option<String>,
    pub stats: Stats,
    pub minor_faults: u64,
    /// Energised elements (bit e of word e / 64): see [`Snapshot::power`].
    power: Vec<u64>,
    /// `power` was computed by the scan (monitoring is on).
    monitored: bool,
    pub forces: Arc<Vec<Force>>,
}

impl Snapshot {
    pub fn read(&self, p: Place) -> Value {
        self.memory.read(p)
    }

    /// Energised elements (bit e of word e / 64), while monitoring.
    pub fn power(&self) -> Option<&[u64]> {
        self.monitored.then_some(&self.power)
    }

    pub fn energised(&self, element: u32) -> Option<bool> {
        let bits = self.power()?;
        Some(
            bits.get(element as usize / 64)
                .is_some_and(|w| w >> (element % 64) & 1 == 1),
        )
    }
}

/// Reads and writes the physical I/O around each scan. The simulated I/O
/// steps the project's `[[plant_model]]`s in real time; otherwise inputs
/// are driven by the plant programs (`plant = [...]`), forces and operator
/// writes.
pub trait Io: Send {
    fn name(&self) -> &str;
    fn read_inputs(&mut self, engine: &mut Engine) -> Result<(), IoError>;
    fn write_outputs(&mut self, engine: &Engine) -> Result<(), IoError>;
    /// Attach mode: the board runs the program itself (a sketch exported
    /// with its monitoring link). `read_inputs` then loads the board's whole
    /// memory into the engine, which does not scan, and outputs are the
    /// board's own; writes go to the board through [`Io::write_remote`].
    fn runs_program(&self) -> bool {
        false
    }
    /// An operator's write, applied on the board (attach mode). `None`: the
    /// driver has no remote memory, and the write is applied locally.
    fn write_remote(&mut self, _place: Place, _value: Value) -> Option<Result<(), IoError>> {
        None
    }
}

/// `--io sim`.
pub struct SimIo;

impl Io for SimIo {
    fn name(&self) -> &str {
        "sim"
    }
    fn read_inputs(&mut self, engine: &mut Engine) -> Result<(), IoError> {
        engine.step_plants_now();
        Ok(())
    }
    fn write_outputs(&mut self, _: &Engine) -> Result<(), IoError> {
        Ok(())
    }
}

/// A request to the engine thread.
enum Req {
    Write(Place, Value),
    /// Several writes applied together, between the same two scans.
    WriteMany(Vec<(Place, Value)>),
    Force(Force),
    Unforce(Option<String>),
    Run,
    Stop,
    /// One scan while stopped.
    Step,
    /// A program prepared off the engine's thread (`Handle::replace`).
    Replace(Box<alba_engine::Prepared>),
    /// +1 / −1 watcher of power flow.
    Monitor(bool),
    Shutdown,
}

/// Why a request to the runtime was refused (see [`Handle`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Error {
    /// The engine thread has ended: nothing can be asked of it any more.
    #[error("the runtime has stopped")]
    Stopped,
    /// Attach mode: the board runs the program, so this request cannot be
    /// done here (forces, online edits and stop).
    #[error(
        "the board runs the program ({io}): forces, online edits and stop are done on a board by exporting and uploading again; writes work"
    )]
    Attached { io: String },
    /// The I/O driver could not apply an operator's write (attach mode).
    #[error("{source}")]
    Io {
        /// The driver's name.
        io: String,
        source: IoError,
    },
    /// The new program of an online edit cannot replace the running one.
    #[error("{0}")]
    Rejected(String),
    /// A single step asked for while the runtime scans on its own.
    #[error("the runtime is running: stop it before stepping one scan")]
    Running,
    /// A single step asked for while the runtime is faulted.
    #[error("the runtime is faulted ({0}): run it again before stepping")]
    Faulted(String),
    /// [`REQUEST_QUEUE`] requests already wait for the next scan boundary:
    /// this one is refused rather than queued without bound.
    #[error("the runtime is busy: {REQUEST_QUEUE} requests wait for the next scan; try again")]
    Busy,
}

/// Requests (writes, forces, run/stop, edits) that may wait for the next
/// scan boundary at once. A flood from a protocol client is refused
/// ([`Error::Busy`]: HTTP 503, Modbus exception 06) instead of growing a
/// queue that the engine thread would have to work through (issue 18).
pub const REQUEST_QUEUE: usize = 1024;

type Reply = oneshot::Sender<Result<(), Error>>;

/// How many requests wait for the engine, and the most that ever did: a
/// count taken after each request is queued and after the engine takes it
/// (issue 18: a protocol server shows by it that its load stays bounded). It
/// can be one above the true number: between the engine's receiving a
/// request and its count, one slot is free and one more request can be
/// queued and counted (the engine thread is the only taker, so never more).
#[derive(Debug, Default)]
struct Depth {
    now: std::sync::atomic::AtomicIsize,
    peak: std::sync::atomic::AtomicIsize,
}

impl Depth {
    fn queued(&self) {
        let n = self.now.fetch_add(1, Ordering::Relaxed) + 1;
        self.peak.fetch_max(n, Ordering::Relaxed);
    }

    fn taken(&self) {
        self.now.fetch_sub(1, Ordering::Relaxed);
    }
}

/// Talks to a running runtime; cheap to clone.
#[derive(Clone)]
pub struct Handle {
    tx: mpsc::SyncSender<(Req, Option<Reply>)>,
    depth: Arc<Depth>,
    latest: publish::Latest,
    snapshots: watch::Receiver<Arc<Snapshot>>,
    health: Arc<Health>,
    /// The engine runs native code (an edit is compiled to it too).
    native: bool,
}

impl Handle {
    /// The persistence problems of this runtime; the historian and other
    /// services report theirs here too.
    pub fn health(&self) -> &Arc<Health> {
        &self.health
    }

    /// The latest snapshot (an answered request's effect is in it).
    pub fn snapshot(&self) -> Arc<Snapshot> {
        self.latest.load_full()
    }

    /// A receiver that wakes at every new snapshot (coalescing: a slow
    /// reader sees the latest one). It is fed by a thread of its own, a
    /// moment after [`Handle::snapshot`] has the publication.
    pub fn subscribe(&self) -> watch::Receiver<Arc<Snapshot>> {
        self.snapshots.clone()
    }

    async fn ask(&self, req: Req) -> Result<(), Error> {
        self.send(req)?.await.map_err(|_| Error::Stopped)?
    }

    fn send(&self, req: Req) -> Result<oneshot::Receiver<Result<(), Error>>, Error> {
        let (tx, rx) = oneshot::channel();
        self.tx.try_send((req, Some(tx))).map_err(|e| match e {
            mpsc::TrySendError::Full(_) => Error::Busy,
            mpsc::TrySendError::Disconnected(_) => Error::Stopped,
        })?;
        self.depth.queued();
        Ok(rx)
    }

    /// A request that must not be lost (shutdown, monitoring counts): waits
    /// for room, which the engine makes at its next scan boundary at most.
    fn tell(&self, req: Req) {
        if self.tx.send((req, None)).is_ok() {
            self.depth.queued();
        }
    }

    /// The most requests that waited for a scan boundary at once since the
    /// runtime started: at most [`REQUEST_QUEUE`] + 1 (see `Depth`).
    pub fn queue_peak(&self) -> usize {
        self.depth.peak.load(Ordering::Relaxed).max(0) as usize
    }

    /// Writes a place at the next scan boundary; answers once applied.
    pub async fn write(&self, place: Place, value: Value) -> Result<(), Error> {
        self.ask(Req::Write(place, value)).await
    }

    /// Writes several places at the same scan boundary (no scan sees some
    /// of them without the others); answers once applied.
    pub async fn write_many(&self, writes: Vec<(Place, Value)>) -> Result<(), Error> {
        self.ask(Req::WriteMany(writes)).await
    }

    /// [`Handle::write_many`] for a thread outside any async runtime (a
    /// protocol server's connection thread): blocks until applied.
    pub fn write_many_blocking(&self, writes: Vec<(Place, Value)>) -> Result<(), Error> {
        self.send(Req::WriteMany(writes))?
            .blocking_recv()
            .map_err(|_| Error::Stopped)?
    }

    /// Forces an input or output (the caller checks it is one).
    pub async fn force(&self, name: String, place: Place, value: Value) -> Result<(), Error> {
        self.ask(Req::Force(Force {
            name,
            place,
            value,
            input: false,
            prior: value,
        }))
        .await
    }

    /// Removes the force on `name` (`None`: every force).
    pub async fn unforce(&self, name: Option<String>) -> Result<(), Error> {
        self.ask(Req::Unforce(name)).await
    }

    pub async fn run(&self) -> Result<(), Error> {
        self.ask(Req::Run).await
    }

    pub async fn stop(&self) -> Result<(), Error> {
        self.ask(Req::Stop).await
    }

    /// Single step: while stopped, runs exactly one scan (inputs read,
    /// program, outputs written, snapshot published) and answers after it.
    /// Refused while running ([`Error::Running`]) or faulted
    /// ([`Error::Faulted`]); the runtime stays stopped.
    pub async fn step(&self) -> Result<(), Error> {
        self.ask(Req::Step).await
    }

    /// Online edit: the new program runs from the next scan, memory migrated.
    /// Everything that costs (verifying, native code or the interpreter's
    /// forms, the migration's name look-ups) is done first on a thread of
    /// its own; the engine only swaps, between two scans (issue 31).
    pub async fn replace(&self, program: Arc<Program>) -> Result<(), Error> {
        let old = self.snapshot().program.clone();
        let native = self.native;
        let (tx, rx) = oneshot::channel();
        std::thread::Builder::new()
            .name("alba-prepare".into())
            .spawn(move || {
                let _ = tx.send(alba_engine::Engine::prepare(program, &old, native));
            })
            .map_err(|e| Error::Rejected(format!("cannot start a thread to prepare the edit: {e}")))?;
        let prepared = rx.await.map_err(|_| Error::Stopped)?.map_err(Error::Rejected)?;
        self.ask(Req::Replace(Box::new(prepared))).await
    }

    /// One more (or one fewer) watcher of power flow; monitoring runs while
    /// there is at least one.
    pub fn monitor(&self, on: bool) {
        self.tell(Req::Monitor(on));
    }
}

/// The runtime: its thread and a handle to it.
pub struct Runtime {
    handle: Handle,
    thread: Option<JoinHandle<()>>,
}

impl Runtime {
    /// Starts the engine thread for `program`, restoring retentive data
    /// first. Fails if the program does not verify or the retain file is
    /// not one.
    pub fn start(program: Arc<Program>, opts: Options, io: Box<dyn Io>) -> Result<Runtime, StartError> {
        let mut engine = Engine::new(program.clone()).map_err(StartError::Program)?;
        if opts.native {
            // Where native code is unavailable the interpreter runs instead.
            let _ = engine.compile_native();
        }
        let native = engine.native_on();
        let health = opts.health.clone();
        if let Some(path) = &opts.retain_file {
            let r = retain::load(path, &program, opts.on_retain_error, |p, v| engine.write(p, v))
                .map_err(StartError::Retain)?;
            if r.lost() {
                health.set_retain_lost();
            }
            // A problem until the runtime restarts: someone must look.
            if let Some(w) = r.warning() {
                health.report("retain", w);
            }
        }
        engine.set_store_status(health.retain_lost(), health.ok());
        let (tx, rx) = mpsc::sync_channel(REQUEST_QUEUE);
        let depth = Arc::new(Depth::default());
        let worker_depth = depth.clone();
        let first = Arc::new(Snapshot {
            program: program.clone(),
            memory: engine.memory().clone(),
            scans: 0,
            clock_ms: 0,
            unix_ms: unix_ms(),
            // What readers see until the thread's first publication.
            state: if opts.start_running {
                RunState::Running
            } else {
                RunState::Stopped
            },
            fault: None,
            stats: Stats::default(),
            minor_faults: 0,
            // Room for the power flow, so that turning monitoring on
            // allocates nothing in the recycled copies.
            power: Vec::with_capacity(program.elements.len().div_ceil(64)),
            monitored: false,
            forces: Arc::new(Vec::new()),
        });
        let (publisher, latest, snap_rx) = publish::Publisher::start(first).map_err(|source| StartError::Thread {
            what: "publish",
            source,
        })?;
        let saver = match &opts.retain_file {
            Some(p) => Some(Saver::start(p.clone(), health.clone(), latest.clone())?),
            None => None,
        };
        let state = Worker {
            saver,
            save_due: false,
            engine,
            io,
            opts,
            state: RunState::Stopped,
            fault: None,
            stats: Stats::default(),
            forces: Arc::new(Vec::new()),
            watchers: 0,
            power_fresh: false,
            publisher,
            epoch: Instant::now(),
            last_retain: Instant::now(),
        };
        let thread = std::thread::Builder::new()
            .name("alba-engine".into())
            .spawn(move || state.run(rx, worker_depth))
            .map_err(|source| StartError::Thread { what: "engine", source })?;
        Ok(Runtime {
            handle: Handle {
                tx,
                depth,
                latest,
                snapshots: snap_rx,
                health,
                native,
            },
            thread: Some(thread),
        })
    }

    pub fn handle(&self) -> Handle {
        self.handle.clone()
    }

    /// Stops scanning, saves retentive data and ends the thread.
    pub fn shutdown(mut self) {
        self.handle.tell(Req::Shutdown);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Runtime {
    fn drop(&mut self) {
        if let Some(t) = self.thread.take() {
            self.handle.tell(Req::Shutdown);
            let _ = t.join();
        }
    }
}

fn unix_ms() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

/// Is `p` an input (`Some(true)`), an output (`Some(false)`) or neither?
/// Only I/O can be forced.
pub fn io_kind(layout: &Layout, p: Place) -> Option<bool> {
    let within = |r: alba_ir::Region, s: u32| (r.base..r.base + r.len).contains(&s);
    match p {
        Place::Bool(b) if within(layout.di, b.0) => Some(true),
        Place::Bool(b) if within(layout.dout, b.0) => Some(false),
        Place::Int(i, _) if within(layout.ai, i.0) => Some(true),
        Place::Int(i, _) if within(layout.ao, i.0) => Some(false),
        _ => None,
    }
}

fn is_input(layout: &Layout, p: Place) -> bool {
    io_kind(layout, p) == Some(true)
}

/// The engine thread.
struct Worker {
    engine: Engine,
    io: Box<dyn Io>,
    opts: Options,
    state: RunState,
    fault: Option<String>,
    stats: Stats,
    forces: Arc<Vec<Force>>,
    watchers: u32,
    /// The power flow was computed by the last scan.
    power_fresh: bool,
    saver: Option<Saver>,
    /// Retentive data is saved from the next publication.
    save_due: bool,
    publisher: publish::Publisher,
    /// Zero of the engine clock.
    epoch: Instant,
    last_retain: Instant,
}

impl Worker {
    fn run(mut self, rx: mpsc::Receiver<(Req, Option<Reply>)>, depth: Arc<Depth>) {
        for w in self.opts.realtime.apply() {
            eprintln!("warning: {w}");
        }
        if self.opts.start_running {
            self.start();
        }
        self.publish();
        let period = Duration::from_millis(u64::from(self.opts.scan_ms.max(1)));
        let mut deadline = Instant::now();
        loop {
            // Wait for the deadline (or, stopped, for a request), applying
            // requests as they come: no scan is running meanwhile.
            loop {
                let wait = if self.state == RunState::Running {
                    deadline.saturating_duration_since(Instant::now())
                } else {
                    Duration::from_millis(200)
                };
                let (req, reply) = match rx.recv_timeout(wait) {
                    Ok(r) => {
                        depth.taken();
                        r
                    }
                    Err(RecvTimeoutError::Timeout) => {
                        if self.state == RunState::Running {
                            break;
                        }
                        continue;
                    }
                    Err(RecvTimeoutError::Disconnected) => {
                        self.finish();
                        return;
                    }
                };
                if matches!(req, Req::Shutdown) {
                    self.finish();
                    return;
                }
                let was = self.state;
                let r = self.apply(req);
                if self.state == RunState::Running && was != RunState::Running {
                    deadline = Instant::now();
                }
                // Published before the answer: the caller sees its effect.
                self.publish();
                if let Some(reply) = reply {
                    let _ = reply.send(r);
                }
                if self.state == RunState::Running && Instant::now() >= deadline {
                    break;
                }
            }
            let started = Instant::now();
            let late = started.saturating_duration_since(deadline);
            if let Some(log) = &self.opts.scan_log {
                log.scan(late);
            }
            self.scan(late);
            // Next deadline; missed ones are counted and skipped.
            deadline += period;
            let now = Instant::now();
            if now > deadline {
                let missed = (now - deadline).as_nanos() / period.as_nanos() + 1;
                self.stats.overruns += missed as u64;
                if let Some(log) = &self.opts.scan_log {
                    log.missed(missed as u64);
                }
                deadline += period * missed as u32;
            }
            if self.saver.is_some() && self.last_retain.elapsed() >= Duration::from_millis(self.opts.retain_interval_ms)
            {
                self.save_retained();
            }
        }
    }

    fn clock_ms(&self) -> u64 {
        self.epoch.elapsed().as_millis() as u64
    }

    fn start(&mut self) {
        self.engine.restart();
        self.state = RunState::Running;
        self.fault = None;
        self.stats = Stats::default();
    }

    /// One scan with its I/O, forces, statistics and publication.
    fn scan(&mut self, late: Duration) {
        let t0 = Instant::now();
        if let Err(e) = self.io.read_inputs(&mut self.engine) {
            return self.halt(format!("I/O ({}): {e}", self.io.name()));
        }
        if self.io.runs_program() {
            // Attach mode: the memory just read is the board's; nothing to run.
            self.stats
                .record(t0.elapsed().as_micros() as u64, late.as_micros() as u64);
            return self.publish();
        }
        self.engine
            .set_store_status(self.opts.health.retain_lost(), self.opts.health.ok());
        // Forces are the engine's: applied before and after the scan.
        let now = self.clock_ms();
        if let Err(m) = self.engine.scan(now) {
            return self.halt(m.message);
        }
        if let Err(e) = self.io.write_outputs(&self.engine) {
            return self.halt(format!("I/O ({}): {e}", self.io.name()));
        }
        self.power_fresh = self.watchers > 0;
        let took = t0.elapsed();
        self.stats.record(took.as_micros() as u64, late.as_micros() as u64);
        self.engine.set_scan_time(took.as_millis() as u32);
        self.engine.set_stats(self.stats.as_tags());
        if took > Duration::from_millis(u64::from(self.opts.watchdog_ms)) {
            return self.halt(format!(
                "watchdog: a scan took {} ms (limit {} ms)",
                took.as_millis(),
                self.opts.watchdog_ms
            ));
        }
        self.publish();
    }

    /// Stops with a fault: outputs off.
    fn halt(&mut self, why: String) {
        self.state = RunState::Faulted;
        self.fault = Some(why);
        self.safe_outputs();
        self.save_retained();
        self.publish();
    }

    /// Outputs in their safe state: every digital output off, analog 0.
    /// (In attach mode the board keeps its outputs: it runs on its own.)
    fn safe_outputs(&mut self) {
        self.power_fresh = false;
        if self.io.runs_program() {
            return;
        }
        let l = self.engine.program().layout.clone();
        for b in l.dout.base..l.dout.base + l.dout.len {
            self.engine
                .write_over_force(Place::Bool(alba_ir::B(b)), Value::Bool(false));
        }
        for i in l.ao.base..l.ao.base + l.ao.len {
            self.engine
                .write_over_force(Place::Int(alba_ir::I(i), alba_model::DataType::Int), Value::Int(0));
        }
        let _ = self.io.write_outputs(&self.engine);
    }

    /// An operator's write through the I/O driver, if it has remote memory.
    fn write_remote(&mut self, p: Place, v: Value) -> Result<(), Error> {
        match self.io.write_remote(p, v) {
            Some(Err(source)) => Err(Error::Io {
                io: self.io.name().to_string(),
                source,
            }),
            _ => Ok(()),
        }
    }

    fn apply(&mut self, req: Req) -> Result<(), Error> {
        match req {
            Req::Write(p, v) => {
                self.write_remote(p, v)?;
                self.engine.write(p, v);
                Ok(())
            }
            Req::Force(_) | Req::Replace(_) | Req::Stop | Req::Step if self.io.runs_program() => Err(Error::Attached {
                io: self.io.name().to_string(),
            }),
            Req::WriteMany(ws) => {
                for (p, v) in ws {
                    self.write_remote(p, v)?;
                    self.engine.write(p, v);
                }
                Ok(())
            }
            Req::Force(mut f) => {
                f.input = is_input(&self.engine.program().layout, f.place);
                let mut fs = (*self.forces).clone();
                f.prior = match fs.iter().position(|x| x.place == f.place) {
                    Some(i) => fs.remove(i).prior,
                    None => self.engine.read(f.place),
                };
                fs.retain(|x| !x.name.eq_ignore_ascii_case(&f.name));
                // Visible at once, also while stopped.
                self.engine.force(f.place, f.value);
                fs.push(f);
                self.forces = Arc::new(fs);
                Ok(())
            }
            Req::Unforce(name) => {
                let (gone, kept): (Vec<Force>, Vec<Force>) = self
                    .forces
                    .iter()
                    .cloned()
                    .partition(|x| name.as_ref().is_none_or(|n| x.name.eq_ignore_ascii_case(n)));
                for f in &gone {
                    self.engine.unforce(f.place);
                    if f.input {
                        self.engine.write(f.place, f.prior);
                    }
                }
                self.forces = Arc::new(kept);
                Ok(())
            }
            Req::Run => {
                if self.state != RunState::Running {
                    self.start();
                }
                Ok(())
            }
            Req::Stop => {
                if self.state == RunState::Running {
                    self.state = RunState::Stopped;
                    self.safe_outputs();
                    self.save_retained();
                }
                Ok(())
            }
            Req::Step => match self.state {
                RunState::Running => Err(Error::Running),
                RunState::Faulted => Err(Error::Faulted(self.fault.clone().unwrap_or_default())),
                RunState::Stopped => {
                    self.scan(Duration::ZERO);
                    // A scan that faulted (watchdog, I/O) says so.
                    match (self.state, &self.fault) {
                        (RunState::Faulted, Some(f)) => Err(Error::Faulted(f.clone())),
                        _ => Ok(()),
                    }
                }
            },
            Req::Replace(p) => {
                let p = self.engine.swap(*p);
                // The old program's forms are freed elsewhere: for a big
                // program that takes milliseconds.
                let _ = std::thread::Builder::new()
                    .name("alba-retire".into())
                    .spawn(move || drop(p));
                let program = self.engine.shared_program();
                let layout = &program.layout;
                // Forces follow their names into the new layout.
                let fs = self
                    .forces
                    .iter()
                    .filter_map(|f| match layout.resolve(&f.name) {
                        Ok(alba_ir::Target::Value { place, .. }) => Some(Force {
                            place,
                            input: is_input(layout, place),
                            ..f.clone()
                        }),
                        _ => None,
                    })
                    .collect::<Vec<_>>();
                for f in &fs {
                    self.engine.force(f.place, f.value);
                }
                self.forces = Arc::new(fs);
                Ok(())
            }
            Req::Monitor(on) => {
                self.watchers = if on {
                    self.watchers + 1
                } else {
                    self.watchers.saturating_sub(1)
                };
                if on && self.watchers == 1 {
                    // No power flow until a scan has computed it.
                    self.power_fresh = false;
                }
                self.engine.set_monitor(self.watchers > 0);
                Ok(())
            }
            Req::Shutdown => Ok(()),
        }
    }

    /// Publishes the engine's state into a recycled snapshot (no allocation
    /// in steady state: the buffers keep their sizes), then has retentive
    /// data saved from it if a save is due.
    fn publish(&mut self) {
        let clock_ms = self.clock_ms();
        let Worker {
            engine,
            state,
            fault,
            stats,
            forces,
            power_fresh,
            publisher,
            ..
        } = self;
        publisher.publish(|s| {
            s.program = engine.shared_program();
            s.memory.clone_from(engine.memory());
            s.scans = engine.scans();
            s.clock_ms = clock_ms;
            s.unix_ms = unix_ms();
            s.state = *state;
            s.fault.clone_from(fault);
            s.stats = *stats;
            s.minor_faults = engine.faults().count;
            s.power.clear();
            if let Some(pf) = engine.power_flow().filter(|_| *power_fresh) {
                s.power.extend_from_slice(pf.words());
            }
            s.monitored = engine.power_flow().is_some() && *power_fresh;
            s.forces = forces.clone();
        });
        if std::mem::take(&mut self.save_due)
            && let Some(saver) = &self.saver
        {
            saver.wake();
        }
    }

    /// Has the saver thread save the retained values of the next snapshot
    /// (the file is written there, so an fsync never delays a scan, and the
    /// values are read from the snapshot, so the engine copies nothing).
    fn save_retained(&mut self) {
        self.last_retain = Instant::now();
        // In attach mode the board's memory is not this runtime's to keep.
        self.save_due = self.saver.is_some() && !self.io.runs_program();
    }

    fn finish(&mut self) {
        if self.state == RunState::Running {
            self.state = RunState::Stopped;
            self.safe_outputs();
        }
        self.save_retained();
        self.publish();
        // Joins the saver after that last save.
        self.saver = None;
    }
}

/// The thread that writes the retain file: woken by the engine, it saves the
/// retained values of the latest snapshot (atomically: an interrupted save
/// leaves the previous file).
struct Saver {
    thread: Option<JoinHandle<()>>,
    due: Arc<AtomicBool>,
    stop: Arc<AtomicBool>,
}

impl Saver {
    fn start(path: PathBuf, health: Arc<Health>, latest: publish::Latest) -> Result<Saver, StartError> {
        let due = Arc::new(AtomicBool::new(false));
        let stop = Arc::new(AtomicBool::new(false));
        let (saving, stopping) = (due.clone(), stop.clone());
        let thread = std::thread::Builder::new()
            .name("alba-retain".into())
            .spawn(move || {
                // The retained tags of the program last saved.
                let (mut program, mut names) = (None::<Arc<Program>>, Vec::new());
                loop {
                    // Read before `due`: the engine asks for its last save
                    // before it stops the thread.
                    let stop = stopping.load(Ordering::Acquire);
                    if saving.swap(false, Ordering::AcqRel) {
                        let snap = latest.load_full();
                        if program.as_ref().is_none_or(|p| !Arc::ptr_eq(p, &snap.program)) {
                            names = retain::retained(&snap.program);
                            program = Some(snap.program.clone());
                        }
                        let values: Vec<(String, Value)> =
                            names.iter().map(|(n, p)| (n.clone(), snap.read(*p))).collect();
                        if !values.is_empty() {
                            match retain::save(&path, &values, unix_ms()) {
                                Ok(()) => health.clear("retain-save"),
                                Err(e) => health.report(
                                    "retain-save",
                                    format!("cannot save retentive data to {}: {e}", path.display()),
                                ),
                            }
                        }
                    }
                    if stop {
                        return;
                    }
                    std::thread::park();
                }
            })
            .map_err(|source| StartError::Thread { what: "retain", source })?;
        Ok(Saver {
            thread: Some(thread),
            due,
            stop,
        })
    }

    fn wake(&self) {
        self.due.store(true, Ordering::Release);
        if let Some(t) = &self.thread {
            t.thread().unpark();
        }
    }
}

impl Drop for Saver {
    /// Ends the thread after the save asked for, if any.
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            let _ = t.join();
        }
    }
}
