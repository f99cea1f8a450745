//! The engine: owns program memory and runs scans (SPEC §2.3).

use crate::error::EngineError;
use crate::exec::{self, Code, PowerFlow, Stop};
use crate::fault::{Fault, Faults};
use alba_ir::{Memory, Place, Program};
use alba_model::Value;
use std::sync::Arc;

/// The engine stopped: a scan could not complete.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MajorFault {
    pub message: String,
    /// The op where it happened.
    pub pc: u32,
}

/// Runs a compiled program. Time is passed in by the caller for each scan;
/// inputs are written before a scan and outputs read after it.
pub struct Engine {
    prog: Arc<Program>,
    /// One executable op per canonical op, while monitoring.
    plain: Option<Code>,
    /// Fused form (unmonitored scans), unless native code runs them.
    fast: Option<Code>,
    mem: Memory,
    faults: Faults,
    first_scan: bool,
    scans: u64,
    monitor: bool,
    pf: PowerFlow,
    monitor_writes: u64,
    major: Option<MajorFault>,
    /// Duration of the last scan in ms, for `SMW22` (0 in virtual time).
    scan_time_ms: u32,
    /// `S:IOOK` and `S:IOERRORS`, as the I/O driver last reported them.
    io_ok: bool,
    io_errors: i32,
    retain_lost: bool,
    store_ok: bool,
    /// Native code for unmonitored scans, once compiled.
    #[cfg(feature = "jit")]
    native: Option<crate::jit::Jit>,
    /// The program's plant models (`[[plant_model]]`) and their state.
    plants: crate::plant::Plants,
    /// Forced places and their values (docs/cli.md "Forces"): they win over
    /// every writer — I/O, stimuli, plant models and plant programs.
    forces: Vec<(Place, Value)>,
}

/// A program made ready to run by [`Engine::prepare`].
pub struct Prepared {
    prog: Arc<Program>,
    /// The program it was prepared to follow.
    old: Arc<Program>,
    migration: alba_ir::Migration,
    init: Memory,
    plain: Code,
    fast: Option<Code>,
    #[cfg(feature = "jit")]
    native: Option<crate::jit::Jit>,
    plants: crate::plant::Plants,
    pf: PowerFlow,
}

impl Prepared {
    pub fn program(&self) -> &Arc<Program> {
        &self.prog
    }
}

/// What an engine held before a [`Engine::swap`]: dropping it frees the old
/// program's forms (milliseconds for a big one), best done off the engine's thread.
pub struct Retired {
    _mem: Memory,
    _plain: [Option<Code>; 2],
    _fast: Option<Code>,
    #[cfg(feature = "jit")]
    _native: Option<crate::jit::Jit>,
    _plants: crate::plant::Plants,
    _pf: PowerFlow,
    _prog: Arc<Program>,
}

impl Engine {
    /// Loads a program after verifying it (no op may reach outside memory).
    pub fn new(prog: Arc<Program>) -> Result<Engine, EngineError> {
        prog.verify()?;
        Ok(Engine {
            plain: None,
            fast: Some(Code::new(&prog, true)),
            mem: prog.init.clone(),
            faults: Faults::default(),
            first_scan: true,
            scans: 0,
            monitor: false,
            pf: PowerFlow::default(),
            monitor_writes: 0,
            major: None,
            scan_time_ms: 0,
            io_ok: true,
            io_errors: 0,
            retain_lost: false,
            store_ok: true,
            #[cfg(feature = "jit")]
            native: None,
            plants: crate::plant::Plants::new(&prog.plants),
            forces: Vec::new(),
            prog,
        })
    }

    pub fn program(&self) -> &Program {
        &self.prog
    }

    /// The program, shared (for snapshots that outlive an online edit).
    pub fn shared_program(&self) -> Arc<Program> {
        self.prog.clone()
    }

    pub fn memory(&self) -> &Memory {
        &self.mem
    }

    pub fn read(&self, p: Place) -> Value {
        self.mem.read(p)
    }

    /// Replaces the whole memory (attach mode: the board's memory, read over
    /// its monitoring link). Refused when the sizes are not the program's.
    pub fn load_memory(&mut self, m: &Memory) -> Result<(), EngineError> {
        let sizes = |m: &Memory| [m.b.len(), m.i.len(), m.f.len(), m.l.len(), m.d.len(), m.m.len()];
        if sizes(m) != sizes(&self.mem) {
            return Err(EngineError::MemorySizes {
                memory: sizes(m),
                program: sizes(&self.mem),
            });
        }
        self.mem.clone_from(m);
        Ok(())
    }

    /// Writes a value between scans (inputs, stimuli, operator writes). A
    /// forced place keeps its forced value.
    pub fn write(&mut self, p: Place, v: Value) {
        if !self.is_forced(p) {
            self.mem.write(p, v);
        }
    }

    /// Writes even a forced place (the safe state of the outputs on a stop
    /// or a fault wins over forces; a force acts again from the next scan).
    pub fn write_over_force(&mut self, p: Place, v: Value) {
        self.mem.write(p, v);
    }

    /// Forces `p` to `v` (replacing an earlier force of `p`), visible at
    /// once. A force wins over every writer: it is applied before each scan,
    /// after each scan (so that plant programs, which run after the control
    /// programs, cannot overwrite it), after plant models step, and writes
    /// to a forced place between scans are ignored. The control programs
    /// therefore always read the forced value; a program that writes a
    /// forced place itself sees its own value until the end of the scan, as
    /// in a PLC whose forces act on the I/O image.
    pub fn force(&mut self, p: Place, v: Value) {
        self.forces.retain(|(q, _)| *q != p);
        self.forces.push((p, v));
        self.mem.write(p, v);
    }

    /// Removes the force of `p` (if any); the place keeps its value until
    /// something writes it.
    pub fn unforce(&mut self, p: Place) {
        self.forces.retain(|(q, _)| *q != p);
    }

    /// Removes every force.
    pub fn unforce_all(&mut self) {
        self.forces.clear();
    }

    pub fn is_forced(&self, p: Place) -> bool {
        self.forces.iter().any(|(q, _)| *q == p)
    }

    fn apply_forces(&mut self) {
        for &(p, v) in &self.forces {
            self.mem.write(p, v);
        }
    }

    /// Advances the plant models to `now_ms` (the simulator's clock) and
    /// writes their measurements; call it between scans, before inputs are
    /// forced or stimulated.
    pub fn step_plants(&mut self, now_ms: u64) {
        if !self.plants.is_empty() {
            self.plants.step(&mut self.mem, now_ms);
            self.apply_forces();
        }
    }

    /// `step_plants` on a real-time clock (the simulated I/O driver).
    pub fn step_plants_now(&mut self) {
        if !self.plants.is_empty() {
            self.plants.step_now(&mut self.mem);
            self.apply_forces();
        }
    }

    /// Scans run so far.
    pub fn scans(&self) -> u64 {
        self.scans
    }

    pub fn faults(&self) -> &Faults {
        &self.faults
    }

    /// "division by zero at main.lad rung 3 (4:12 `DIV(a,b,c)`)".
    pub fn describe_fault(&self, f: &Fault) -> String {
        let loc = self.prog.locs.get(f.pc as usize).copied().unwrap_or(alba_ir::Loc {
            rung: 0,
            elem: alba_ir::NO_ELEM,
        });
        format!("{} at {} (scan {})", f.code, self.prog.describe(loc), f.scan)
    }

    /// Tells the engine how long the last scan took (the real-time loop
    /// measures it), for `SMW22`.
    pub fn set_scan_time(&mut self, ms: u32) {
        self.scan_time_ms = ms;
    }

    /// Writes the scan statistics the real-time loop measures into their
    /// system tags (`S:SCANTIME` … `S:OVERRUNS`, see `alba_ir::layout::STAT_TAGS`).
    pub fn set_stats(&mut self, stats: [i32; 6]) {
        let base = self.prog.layout.system.stats.0 as usize;
        if let Some(slots) = self.mem.i.get_mut(base..base + stats.len()) {
            slots.copy_from_slice(&stats);
        }
    }

    /// The I/O link status last set by [`Engine::set_io_status`] (`S:IOOK`,
    /// `S:IOERRORS`), for a driver that combines its own with another's.
    pub fn io_status(&self) -> (bool, i32) {
        (self.io_ok, self.io_errors)
    }

    /// The I/O link status for `S:IOOK` and `S:IOERRORS` (an I/O driver
    /// calls this from `read_inputs`; visible at once and kept by scans).
    pub fn set_io_status(&mut self, ok: bool, errors: i32) {
        self.io_ok = ok;
        self.io_errors = errors;
        let sys = self.prog.layout.system;
        if let Some(b) = self.mem.b.get_mut(sys.io_ok.0 as usize) {
            *b = ok;
        }
        if let Some(i) = self.mem.i.get_mut(sys.io_errors.0 as usize) {
            *i = errors;
        }
    }

    /// The runtime's store health for `S:RETAINLOST` and `S:STOREOK`
    /// (visible at once and kept by scans).
    pub fn set_store_status(&mut self, retain_lost: bool, store_ok: bool) {
        self.retain_lost = retain_lost;
        self.store_ok = store_ok;
        let sys = self.prog.layout.system;
        for (slot, v) in [(sys.retain_lost, retain_lost), (sys.store_ok, store_ok)] {
            if let Some(b) = self.mem.b.get_mut(slot.0 as usize) {
                *b = v;
            }
        }
    }

    /// Prepares a new start after a stop: the next scan is a first scan
    /// again and a major fault is cleared; memory is kept.
    pub fn restart(&mut self) {
        self.first_scan = true;
        self.major = None;
    }

    /// The major fault that stopped the engine, if any.
    pub fn major_fault(&self) -> Option<&MajorFault> {
        self.major.as_ref()
    }

    /// Online edit: runs `prog` from the next scan, with the memory migrated
    /// (every tag that exists in both programs with the same name and type
    /// keeps its value, timers and counters included; see
    /// `Memory::migrate`). Fails, changing nothing, if `prog` does not verify
    /// or native code for it cannot be built. Forces are dropped (their
    /// places may have moved): the caller forces again by name.
    ///
    /// All of this on the caller's thread; [`Engine::prepare`] does the
    /// costly part elsewhere and [`Engine::swap`] the rest.
    pub fn replace(&mut self, prog: Arc<Program>) -> Result<(), EngineError> {
        let p = Engine::prepare(prog, &self.prog, self.native_on())?;
        drop(self.swap(p));
        Ok(())
    }

    /// Whether native code runs this engine's unmonitored scans.
    pub fn native_on(&self) -> bool {
        #[cfg(feature = "jit")]
        return self.native.is_some();
        #[cfg(not(feature = "jit"))]
        false
    }

    /// The costly part of an online edit from `old` to `prog`, for any
    /// thread (issue 31: a 50 000-rung edit compiled native code between two
    /// scans, a 52–81 ms gap): verifying, building the executable forms
    /// (native code when `native`, else the fused form; the plain one for
    /// monitoring), working out the memory's migration and copying the new
    /// initial memory. [`Engine::swap`] then only copies values.
    pub fn prepare(prog: Arc<Program>, old: &Arc<Program>, native: bool) -> Result<Prepared, EngineError> {
        prog.verify()?;
        #[cfg(feature = "jit")]
        let native = if native {
            Some(crate::jit::Jit::compile(&prog)?)
        } else {
            None
        };
        #[cfg(feature = "jit")]
        let fast = native.is_none().then(|| Code::new(&prog, true));
        #[cfg(not(feature = "jit"))]
        let fast = {
            let _ = native;
            Some(Code::new(&prog, true))
        };
        Ok(Prepared {
            migration: alba_ir::Migration::new(&old.layout, &prog.layout),
            old: old.clone(),
            init: prog.init.clone(),
            plain: Code::new(&prog, false),
            fast,
            #[cfg(feature = "jit")]
            native,
            plants: crate::plant::Plants::new(&prog.plants),
            pf: PowerFlow::new(prog.elements.len()),
            prog,
        })
    }

    /// Runs a prepared program from the next scan: the values migrated, the
    /// prepared forms put in place. Costs copies only, unless the engine no
    /// longer runs the program `p` was prepared from (then the migration is
    /// worked out again here). Returns what the engine held before, to be
    /// dropped off the engine's thread.
    pub fn swap(&mut self, p: Prepared) -> Retired {
        let Prepared {
            prog,
            old,
            migration,
            mut init,
            plain,
            fast,
            #[cfg(feature = "jit")]
            native,
            plants,
            pf,
        } = p;
        let migration = if Arc::ptr_eq(&old, &self.prog) {
            migration
        } else {
            alba_ir::Migration::new(&self.prog.layout, &prog.layout)
        };
        migration.apply(&self.mem, &mut init);
        // What is not used is dropped with the retired parts, not here.
        let (plain, spare_plain) = if self.monitor {
            (Some(plain), None)
        } else {
            (None, Some(plain))
        };
        let plants = if self.plants.specs() != prog.plants {
            std::mem::replace(&mut self.plants, plants)
        } else {
            plants
        };
        let retired = Retired {
            _mem: std::mem::replace(&mut self.mem, init),
            _plain: [std::mem::replace(&mut self.plain, plain), spare_plain],
            _fast: std::mem::replace(&mut self.fast, fast),
            #[cfg(feature = "jit")]
            _native: std::mem::replace(&mut self.native, native),
            _plants: plants,
            _pf: std::mem::replace(&mut self.pf, if self.monitor { pf } else { PowerFlow::default() }),
            _prog: std::mem::replace(&mut self.prog, prog),
        };
        self.faults = Faults::default();
        self.forces.clear();
        retired
    }

    /// Turns power-flow monitoring on or off (SPEC §11). While off, scans
    /// run an instantiation of the interpreter without any recording.
    pub fn set_monitor(&mut self, on: bool) {
        self.monitor = on;
        self.pf = if on {
            PowerFlow::new(self.prog.elements.len())
        } else {
            PowerFlow::default()
        };
        if !on {
            self.plain = None;
        } else if self.plain.is_none() {
            self.plain = Some(Code::new(&self.prog, false));
        }
    }

    /// Bytes the engine holds for its program: memory, the IR with its
    /// locations, the executable forms it keeps (the fused form unless native
    /// code runs, the unfused one while monitoring) and, if compiled, native
    /// code's operand table and runs (machine code itself is shared by rung
    /// shapes and small).
    pub fn footprint(&self) -> usize {
        let forms = [&self.plain, &self.fast]
            .iter()
            .filter_map(|c| c.as_ref())
            .map(|c| c.bytes())
            .sum::<usize>();
        let mut bytes = self.mem.size_bytes() + self.prog.code_bytes() + forms;
        #[cfg(feature = "jit")]
        if let Some(n) = &self.native {
            bytes += n.table_bytes();
        }
        bytes
    }

    /// Compiles the program to machine code for unmonitored scans (see
    /// `jit.rs`). Monitored scans keep using the interpreter. Fails, and
    /// leaves the interpreter in charge, where native code is unavailable.
    pub fn compile_native(&mut self) -> Result<(), EngineError> {
        #[cfg(feature = "jit")]
        {
            self.native = Some(crate::jit::Jit::compile(&self.prog)?);
            self.fast = None;
            Ok(())
        }
        #[cfg(not(feature = "jit"))]
        Err(EngineError::NoNativeCompiler)
    }

    /// The Cranelift IR and machine code native code would run for this
    /// program (for profiling: `alba bench --listing`).
    pub fn native_listing(&self) -> Result<String, EngineError> {
        #[cfg(feature = "jit")]
        {
            let mut out = String::new();
            crate::jit::Jit::compile_with(&self.prog, Some(&mut out))?;
            Ok(out)
        }
        #[cfg(not(feature = "jit"))]
        Err(EngineError::NoNativeCompiler)
    }

    /// How native code runs the program, once compiled: (rungs, rungs in
    /// strided runs, machine-code functions).
    pub fn native_layout(&self) -> Option<(usize, usize, usize)> {
        #[cfg(feature = "jit")]
        if let Some(n) = &self.native {
            return Some((n.rungs(), n.strided_rungs(), n.shapes));
        }
        None
    }

    /// Power flow of the last scan, while monitoring.
    pub fn power_flow(&self) -> Option<&PowerFlow> {
        self.monitor.then_some(&self.pf)
    }

    /// Scans that recorded power flow (for tests that check monitoring costs
    /// nothing when off).
    pub fn monitored_scans(&self) -> u64 {
        self.monitor_writes
    }

    /// An unmonitored scan: native code if compiled, else fused code.
    fn run_unmonitored(&mut self, now: u32) -> Result<(), Stop> {
        #[cfg(feature = "jit")]
        if let Some(native) = &self.native {
            return native.run(&self.prog, &mut self.mem, &mut self.faults, now);
        }
        let fast = self.fast.get_or_insert_with(|| Code::new(&self.prog, true));
        exec::run::<false>(
            fast,
            &self.prog.locs,
            &mut self.mem,
            &mut self.faults,
            now,
            &mut self.pf,
        )
    }

    /// Runs the program's ops once over `base`, the memory of another
    /// program whose layout this one extends (the slots after `base`'s are
    /// this program's own: temporaries, constants, results): `base` is
    /// copied in, the ops run, and the memory is returned. None of a scan's
    /// bookkeeping happens (system bits, scan count, forces, fault flags),
    /// so `base` is seen as it is. `alba verify` evaluates its properties so
    /// (they are lowered onto the IR, docs/verify.md).
    pub fn run_over(&mut self, base: &Memory, now_ms: u64) -> Result<&Memory, EngineError> {
        let fits = base.b.len() <= self.mem.b.len()
            && base.i.len() <= self.mem.i.len()
            && base.f.len() <= self.mem.f.len()
            && base.l.len() <= self.mem.l.len()
            && base.d.len() <= self.mem.d.len()
            && base.m.len() == self.mem.m.len();
        if !fits {
            let sizes = |m: &Memory| [m.b.len(), m.i.len(), m.f.len(), m.l.len(), m.d.len(), m.m.len()];
            return Err(EngineError::MemorySizes {
                memory: sizes(base),
                program: sizes(&self.mem),
            });
        }
        self.mem.b[..base.b.len()].copy_from_slice(&base.b);
        self.mem.i[..base.i.len()].copy_from_slice(&base.i);
        self.mem.f[..base.f.len()].copy_from_slice(&base.f);
        self.mem.l[..base.l.len()].copy_from_slice(&base.l);
        self.mem.d[..base.d.len()].copy_from_slice(&base.d);
        self.mem.m.copy_from_slice(&base.m);
        match self.run_unmonitored(now_ms as u32) {
            Ok(()) => Ok(&self.mem),
            Err(Stop::Runaway(_)) => Err(EngineError::Runaway),
            Err(Stop::Memory) => Err(EngineError::MemorySizes {
                memory: [0; 6],
                program: [0; 6],
            }),
        }
    }

    /// Runs one scan at time `now_ms` (milliseconds on the caller's clock).
    pub fn scan(&mut self, now_ms: u64) -> Result<(), MajorFault> {
        if let Some(m) = &self.major {
            return Err(m.clone());
        }
        let sys = self.prog.layout.system;
        let b = &mut self.mem.b;
        b[sys.first_scan.0 as usize] = self.first_scan;
        b[sys.always_on.0 as usize] = true;
        // From the full 64-bit time: no wrap after 65.5 s (or 49 days).
        b[sys.clock_60s.0 as usize] = (now_ms / 30_000) % 2 == 1;
        b[sys.clock_1s.0 as usize] = (now_ms / 500) % 2 == 1;
        b[sys.scan_toggle.0 as usize] = self.scans % 2 == 1;
        self.mem.i[sys.scan_time.0 as usize] = self.scan_time_ms.min(i16::MAX as u32) as i32;
        b[sys.io_ok.0 as usize] = self.io_ok;
        self.mem.i[sys.io_errors.0 as usize] = self.io_errors;
        b[sys.retain_lost.0 as usize] = self.retain_lost;
        b[sys.store_ok.0 as usize] = self.store_ok;
        self.faults.scan = self.scans;
        let before = self.faults.count;
        self.apply_forces();
        let now = now_ms as u32; // wrapping milliseconds, like millis()
        let r = if self.monitor {
            self.monitor_writes += 1;
            let plain = self.plain.get_or_insert_with(|| Code::new(&self.prog, false));
            exec::run::<true>(
                plain,
                &self.prog.locs,
                &mut self.mem,
                &mut self.faults,
                now,
                &mut self.pf,
            )
        } else {
            self.run_unmonitored(now)
        };
        self.apply_forces();
        self.first_scan = false;
        self.scans += 1;
        if self.faults.count != before
            && let Some(last) = self.faults.last
        {
            self.mem.b[sys.minor_fault.0 as usize] = true;
            self.mem.i[sys.fault_code.0 as usize] = last.code as i32;
        }
        match r {
            Ok(()) => {}
            Err(Stop::Runaway(pc)) => {
                let loc = self.prog.locs[pc as usize];
                let m = MajorFault {
                    message: format!(
                        "scan abandoned: more than {} backward jumps at {}",
                        exec::BACKWARD_JUMP_LIMIT,
                        self.prog.describe(loc)
                    ),
                    pc,
                };
                self.major = Some(m.clone());
                return Err(m);
            }
            Err(Stop::Memory) => {
                let m = MajorFault {
                    message: "internal error: memory does not match the program layout".into(),
                    pc: 0,
                };
                self.major = Some(m.clone());
                return Err(m);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// The runtime moves the engine onto its own thread.
    #[test]
    fn engine_is_send() {
        fn send<T: Send>() {}
        send::<super::Engine>();
    }
}
