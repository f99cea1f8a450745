//! The engine thread ([`Worker`]): applies the queued requests at the scan
//! boundary, runs the scans on their deadlines, publishes the snapshots; and
//! the retentive-data saver ([`Saver`]) beside it.

use super::*;
pub(crate) fn unix_ms() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

fn is_input(layout: &Layout, p: Place) -> bool {
    io_kind(layout, p) == Some(true)
}

/// The engine thread.
pub(crate) struct Worker {
    pub(crate) engine: Engine,
    pub(crate) io: Box<dyn Io>,
    pub(crate) opts: Options,
    pub(crate) state: RunState,
    pub(crate) fault: Option<String>,
    pub(crate) stats: Stats,
    pub(crate) forces: Arc<Vec<Force>>,
    pub(crate) watchers: u32,
    /// The power flow was computed by the last scan.
    pub(crate) power_fresh: bool,
    pub(crate) saver: Option<Saver>,
    /// Retentive data is saved from the next publication.
    pub(crate) save_due: bool,
    pub(crate) publisher: publish::Publisher,
    /// Zero of the engine clock.
    pub(crate) epoch: Instant,
    pub(crate) last_retain: Instant,
}

impl Worker {
    pub(crate) fn run(mut self, rx: mpsc::Receiver<(Req, Option<Reply>)>, depth: Arc<Depth>) {
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
            Req::SetIo(io, back) => self.set_io(io, back),
            Req::Shutdown => Ok(()),
        }
    }

    /// [`Handle::set_io`] on the engine's side.
    fn set_io(&mut self, io: Box<dyn Io>, back: oneshot::Sender<Box<dyn Io>>) -> Result<(), Error> {
        if io.runs_program() && !self.forces.is_empty() {
            let n = self.forces.len();
            let _ = back.send(io);
            return Err(Error::Rejected(format!(
                "{n} force(s) are on: remove them before attaching to a board that runs the program itself (it would not see them)"
            )));
        }
        // The old driver's outputs off, the program's memory kept.
        if !self.io.runs_program() {
            let kept = self.engine.memory().clone();
            self.safe_outputs();
            let _ = self.engine.load_memory(&kept);
        }
        let old = std::mem::replace(&mut self.io, io);
        self.engine.set_io_status(true, 0);
        self.power_fresh = false;
        if self.io.runs_program() && self.state != RunState::Running {
            // The board runs: the runtime mirrors it.
            self.state = RunState::Running;
            self.fault = None;
        }
        let _ = back.send(old);
        Ok(())
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
pub(crate) struct Saver {
    thread: Option<JoinHandle<()>>,
    due: Arc<AtomicBool>,
    stop: Arc<AtomicBool>,
}

impl Saver {
    pub(crate) fn start(path: PathBuf, health: Arc<Health>, latest: publish::Latest) -> Result<Saver, StartError> {
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
