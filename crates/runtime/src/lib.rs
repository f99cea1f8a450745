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
mod worker;

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
use worker::{Saver, Worker, unix_ms};

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
    /// Another I/O driver (`Handle::set_io`); the one it displaces (or,
    /// refused, the one offered) goes back through the sender, to be
    /// dropped off the engine's thread (a driver's drop joins its link thread).
    SetIo(Box<dyn Io>, oneshot::Sender<Box<dyn Io>>),
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
        let prepared = rx
            .await
            .map_err(|_| Error::Stopped)?
            .map_err(|e| Error::Rejected(e.to_string()))?;
        self.ask(Req::Replace(Box::new(prepared))).await
    }

    /// Puts `io` in place of the runtime's I/O driver between two scans,
    /// without stopping it (attaching a board from the studio, and back:
    /// issue 33). The displaced driver first puts the outputs it drove in
    /// their safe state (off; a board that runs its own program keeps its
    /// own); the program's memory is kept, and the new driver gets the
    /// program's outputs at the next scan. `S:IOOK` is true until the new
    /// driver says otherwise. A driver that runs the program itself
    /// ([`Io::runs_program`]) puts the runtime in run (the board runs), and
    /// is refused while forces are on ([`Error::Rejected`]): the board would
    /// not see them. Returns the displaced driver: the caller keeps it (to
    /// put it back) or drops it, off any async worker (its drop may join a
    /// link thread). A refused driver is dropped on a thread of its own.
    pub async fn set_io(&self, io: Box<dyn Io>) -> Result<Box<dyn Io>, Error> {
        let (tx, rx) = oneshot::channel();
        let answer = self.ask(Req::SetIo(io, tx)).await;
        let back = rx.await.map_err(|_| Error::Stopped);
        match answer {
            Ok(()) => back,
            Err(e) => {
                if let Ok(refused) = back {
                    retire(refused);
                }
                Err(e)
            }
        }
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

/// Drops `io` on a thread of its own (its link thread may take a moment to end).
fn retire(io: Box<dyn Io>) {
    let _ = std::thread::Builder::new()
        .name("alba-retire".into())
        .spawn(move || drop(io));
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
