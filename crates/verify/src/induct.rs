//! A second back end: k-induction with a SAT solver (batsat) over the
//! Boolean part of the IR, abstracted soundly (ADR 0015).
//!
//! One scan is executed symbolically, op by op, on the program's BOOL
//! slots: contacts, coils, latches, one-shots, branches and the
//! instruction-list stack ops are encoded exactly as the interpreter runs
//! them (crates/engine/src/exec/step.rs). Everything else is *havocked*: a
//! comparison leaves `rc` AND a fresh variable, a timer, counter or PID
//! gives every BOOL it writes a fresh value, marker bits read fresh, and
//! numbers are not tracked at all. The property's expressions are the probe
//! program's ops (expr.rs), executed the same way after the scan. The
//! abstraction has every run of the program and more, so:
//!
//! * *base*: no abstract run of `k` scans from the initial memory violates
//!   the property (nor breaks an assumption before);
//! * *step*: no abstract run of `k + 1` end-of-scan states, the property
//!   holding on the first `k`, violates it on the last;
//!
//! both unsatisfiable prove it for every run. A satisfiable query may be
//! spurious (a havocked value): then this back end answers nothing and the
//! explicit search decides. Jumps are not encoded (nothing is answered for a
//! program that jumps).

use crate::expr::Cond;
use crate::props::{Kind, Property};
use alba_ir::op::AnySlot;
use alba_ir::{B, Memory, Op, Program};
use batsat::{BasicSolver, Lit, SolverInterface, lbool};
use std::time::Instant;

/// A signal: a constant or a solver literal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sig {
    C(bool),
    L(Lit),
}

impl std::ops::Not for Sig {
    type Output = Sig;
    fn not(self) -> Sig {
        match self {
            Sig::C(b) => Sig::C(!b),
            Sig::L(l) => Sig::L(!l),
        }
    }
}

/// The solver and the gates built on it (Tseitin, with constants folded).
struct Cnf {
    s: BasicSolver,
    calls: u32,
}

impl Cnf {
    fn new() -> Cnf {
        Cnf {
            s: BasicSolver::default(),
            calls: 0,
        }
    }

    fn fresh(&mut self) -> Sig {
        Sig::L(Lit::new(self.s.new_var_default(), true))
    }

    fn clause(&mut self, lits: &[Sig]) {
        let mut c = Vec::with_capacity(lits.len());
        for l in lits {
            match *l {
                Sig::C(true) => return,
                Sig::C(false) => {}
                Sig::L(l) => c.push(l),
            }
        }
        self.s.add_clause_reuse(&mut c);
    }

    fn and(&mut self, a: Sig, b: Sig) -> Sig {
        match (a, b) {
            (Sig::C(false), _) | (_, Sig::C(false)) => Sig::C(false),
            (Sig::C(true), x) | (x, Sig::C(true)) => x,
            _ if a == b => a,
            _ if a == !b => Sig::C(false),
            _ => {
                let x = self.fresh();
                self.clause(&[!x, a]);
                self.clause(&[!x, b]);
                self.clause(&[x, !a, !b]);
                x
            }
        }
    }

    fn or(&mut self, a: Sig, b: Sig) -> Sig {
        let n = self.and(!a, !b);
        !n
    }

    /// Is `goal` (with every clause so far) satisfiable?
    fn sat(&mut self, goal: Sig) -> bool {
        self.calls += 1;
        match goal {
            Sig::C(b) => b && self.s.is_ok(),
            Sig::L(l) => self.s.solve_limited(&[l]) == lbool::TRUE,
        }
    }
}

/// Why this back end answers nothing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NoProof {
    /// The program has a construct it does not encode.
    Unsupported(&'static str),
    /// The base or the step is satisfiable up to this `k` (perhaps only in
    /// the abstraction), after this many SAT calls.
    NotInductive { k: u32, sat_calls: u32 },
    /// The property is not an invariant (`response`, `reachable`).
    NotAnInvariant,
}

/// A proof: the `k` it took and the SAT calls made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Proof {
    pub k: u32,
    pub sat_calls: u32,
    pub vars: u32,
}

/// What the symbolic scan needs of the model.
pub struct Setup<'a> {
    pub program: &'a Program,
    pub probes: &'a Program,
    pub init: &'a Memory,
    /// BOOL slots the search writes before every scan (inputs).
    pub inputs: Vec<B>,
}

struct Machine<'a> {
    setup: &'a Setup<'a>,
    /// BOOL slots that nothing writes: they keep their initial value.
    fixed: Vec<bool>,
    cnf: Cnf,
}

impl Machine<'_> {
    /// An arbitrary end-of-scan state.
    fn free_state(&mut self) -> Vec<Sig> {
        let n = self.setup.probes.layout.counts.b as usize;
        let init = &self.setup.init.b;
        (0..n)
            .map(|k| {
                if self.fixed.get(k).copied().unwrap_or(false) {
                    Sig::C(init.get(k).copied().unwrap_or(false))
                } else {
                    self.cnf.fresh()
                }
            })
            .collect()
    }

    /// The initial memory (before the first scan).
    fn init_state(&self) -> Vec<Sig> {
        let n = self.setup.probes.layout.counts.b as usize;
        (0..n)
            .map(|k| Sig::C(self.setup.init.b.get(k).copied().unwrap_or(false)))
            .collect()
    }

    /// One scan from `s` (inputs chosen freely); `first` for the first scan.
    fn scan(&mut self, s: &[Sig], first: bool) -> Result<Vec<Sig>, NoProof> {
        let mut m = s.to_vec();
        for &i in &self.setup.inputs {
            let f = self.cnf.fresh();
            set(&mut m, i, f);
        }
        let sys = self.setup.program.layout.system;
        set(&mut m, sys.first_scan, Sig::C(first));
        set(&mut m, sys.always_on, Sig::C(true));
        set(&mut m, sys.io_ok, Sig::C(true));
        set(&mut m, sys.retain_lost, Sig::C(false));
        set(&mut m, sys.store_ok, Sig::C(true));
        for b in [sys.clock_60s, sys.clock_1s, sys.scan_toggle] {
            let f = self.cnf.fresh();
            set(&mut m, b, f);
        }
        let setup = self.setup;
        self.run(&setup.program.ops, &mut m)?;
        // A fault anywhere in the scan sets S:MINOR (sticky).
        let fault = self.cnf.fresh();
        let was = get(&m, sys.minor_fault);
        let now = self.cnf.or(was, fault);
        set(&mut m, sys.minor_fault, now);
        Ok(m)
    }

    /// The expressions' values on the end-of-scan state `s`.
    fn probe(&mut self, s: &[Sig]) -> Result<Vec<Sig>, NoProof> {
        let mut m = s.to_vec();
        let setup = self.setup;
        self.run(&setup.probes.ops, &mut m)?;
        Ok(m)
    }

    fn run(&mut self, ops: &[Op], m: &mut [Sig]) -> Result<(), NoProof> {
        let mut rc = Sig::C(true);
        for op in ops {
            let c = &mut self.cnf;
            match *op {
                Op::Rung | Op::True => rc = Sig::C(true),
                Op::Nop => {}
                Op::Afi => rc = Sig::C(false),
                Op::Xic(b) => rc = c.and(rc, get(m, b)),
                Op::Xio(b) => rc = c.and(rc, !get(m, b)),
                Op::Ote(b) => set(m, b, rc),
                Op::Otl(b) => {
                    let v = c.or(get(m, b), rc);
                    set(m, b, v);
                }
                Op::Otu(b) => {
                    let v = c.and(get(m, b), !rc);
                    set(m, b, v);
                }
                Op::Ons(s) => {
                    let out = c.and(rc, !get(m, s));
                    set(m, s, rc);
                    rc = out;
                }
                Op::Osr(s, o) => {
                    let out = c.and(rc, !get(m, s));
                    set(m, o, out);
                    set(m, s, rc);
                }
                Op::Osf(s, o) => {
                    let out = c.and(!rc, get(m, s));
                    set(m, o, out);
                    set(m, s, rc);
                }
                Op::Ed(s) => {
                    let out = c.and(!rc, get(m, s));
                    set(m, s, rc);
                    rc = out;
                }
                Op::BrOpen { save, acc } => {
                    set(m, save, rc);
                    set(m, acc, Sig::C(false));
                }
                Op::BrNext { save, acc } => {
                    let v = c.or(get(m, acc), rc);
                    set(m, acc, v);
                    rc = get(m, save);
                }
                Op::BrClose { acc } => rc = c.or(rc, get(m, acc)),
                Op::Ld(b) => rc = get(m, b),
                Op::Ldn(b) => rc = !get(m, b),
                Op::Or(b) => rc = c.or(rc, get(m, b)),
                Op::Orn(b) => rc = c.or(rc, !get(m, b)),
                Op::Not => rc = !rc,
                Op::CopyB(a, d) => {
                    let v = get(m, a);
                    set(m, d, v);
                }
                Op::Jmp(_) => return Err(NoProof::Unsupported("a jump")),
                Op::CmpI(..)
                | Op::CmpF(..)
                | Op::CmpL(..)
                | Op::CmpD(..)
                | Op::LimI(..)
                | Op::LimF(..)
                | Op::LimL(..)
                | Op::LimD(..)
                | Op::MeqI(..)
                | Op::MeqL(..) => {
                    let f = c.fresh();
                    rc = c.and(rc, f);
                }
                ref other => {
                    // Numbers are not tracked; a BOOL written here (a
                    // timer's or counter's bits, a marker bit read) is havocked.
                    for s in crate::slots::writes(other) {
                        if let AnySlot::B(x) = s {
                            let f = c.fresh();
                            set(m, B(x), f);
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

fn get(m: &[Sig], b: B) -> Sig {
    m.get(b.0 as usize).copied().unwrap_or(Sig::C(false))
}

fn set(m: &mut [Sig], b: B, v: Sig) {
    if let Some(x) = m.get_mut(b.0 as usize) {
        *x = v;
    }
}

fn holds(c: &Cond, probed: &[Sig]) -> Sig {
    get(probed, c.slot())
}

/// The property's violation on a probed state.
fn bad(cnf: &mut Cnf, kind: &Kind, p: &[Sig]) -> Option<Sig> {
    Some(match kind {
        Kind::Never(e) => holds(e, p),
        Kind::Always(e) => !holds(e, p),
        Kind::Mutex(es) => {
            let mut any = Sig::C(false);
            for (i, a) in es.iter().enumerate() {
                for b in &es[i + 1..] {
                    let both = cnf.and(holds(a, p), holds(b, p));
                    any = cnf.or(any, both);
                }
            }
            any
        }
        Kind::Response { .. } | Kind::Reachable(_) => return None,
    })
}

/// Tries to prove `property` by k-induction for k = 1..=`max_k` (within `seconds`).
pub fn prove(setup: &Setup, property: &Property, assumes: &[Cond], max_k: u32, seconds: u64) -> Result<Proof, NoProof> {
    if matches!(property.kind, Kind::Response { .. } | Kind::Reachable(_)) {
        return Err(NoProof::NotAnInvariant);
    }
    let started = Instant::now();
    let prog = setup.program;
    let mut written = vec![false; setup.probes.layout.counts.b as usize];
    for op in &prog.ops {
        for s in crate::slots::writes(op) {
            if let AnySlot::B(x) = s
                && let Some(w) = written.get_mut(x as usize)
            {
                *w = true;
            }
        }
    }
    let mut fixed: Vec<bool> = written.iter().map(|w| !w).collect();
    let sys = prog.layout.system;
    let engine_written = [
        sys.first_scan,
        sys.always_on,
        sys.io_ok,
        sys.retain_lost,
        sys.store_ok,
        sys.clock_60s,
        sys.clock_1s,
        sys.scan_toggle,
        sys.minor_fault,
    ];
    for b in setup.inputs.iter().chain(&engine_written) {
        if let Some(f) = fixed.get_mut(b.0 as usize) {
            *f = false;
        }
    }
    // The probe program's own slots are written before they are read.
    let mut calls = 0;
    let mut vars = 0;
    for k in 1..=max_k {
        if started.elapsed().as_secs() >= seconds {
            break;
        }
        // Base: k scans from the initial memory.
        let mut m = Machine {
            setup,
            fixed: fixed.clone(),
            cnf: Cnf::new(),
        };
        let mut s = m.init_state();
        let mut ok = Sig::C(true);
        let mut viol = Sig::C(false);
        for i in 0..k {
            s = m.scan(&s, i == 0)?;
            let p = m.probe(&s)?;
            for a in assumes {
                ok = m.cnf.and(ok, holds(a, &p));
            }
            let b = bad(&mut m.cnf, &property.kind, &p).ok_or(NoProof::NotAnInvariant)?;
            let here = m.cnf.and(ok, b);
            viol = m.cnf.or(viol, here);
        }
        let base = m.cnf.sat(viol);
        calls += m.cnf.calls;
        vars += m.cnf.s.num_vars();
        if base {
            return Err(NoProof::NotInductive { k, sat_calls: calls });
        }
        // Step: k + 1 states, the property on the first k, not on the last.
        let mut m = Machine {
            setup,
            fixed: fixed.clone(),
            cnf: Cnf::new(),
        };
        let mut s = m.free_state();
        let mut path = Sig::C(true);
        for i in 0..=k {
            if i > 0 {
                s = m.scan(&s, false)?;
            }
            let p = m.probe(&s)?;
            for a in assumes {
                path = m.cnf.and(path, holds(a, &p));
            }
            let b = bad(&mut m.cnf, &property.kind, &p).ok_or(NoProof::NotAnInvariant)?;
            path = if i < k { m.cnf.and(path, !b) } else { m.cnf.and(path, b) };
        }
        let step = m.cnf.sat(path);
        calls += m.cnf.calls;
        vars += m.cnf.s.num_vars();
        if !step {
            return Ok(Proof {
                k,
                sat_calls: calls,
                vars,
            });
        }
    }
    Err(NoProof::NotInductive {
        k: max_k,
        sat_calls: calls,
    })
}
