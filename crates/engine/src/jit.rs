//! Native code for unmonitored scans, with Cranelift.
//!
//! Programs are compiled rung by rung, by *shape*: the sequence of ops of a
//! rung with their slot numbers taken out. Consecutive rungs of one shape
//! run in one call of one machine-code function, a loop over them, so a
//! program of 10 000 similar rungs is a handful of small functions.
//!
//! How a function finds a rung's slots:
//! - **strided runs**: where every operand of a rung is the previous rung's
//!   plus the same amount (rungs on tags of their own, declared together,
//!   as generated programs and arrays of structures have them), the operands
//!   are a few *class* bases (one per memory class and change per rung) plus
//!   constant offsets. The function keeps the bases in registers and adds
//!   the changes after each rung, like compiled code walking an array of
//!   structs: no table at all. It is specific to the shape and the layout.
//! - **table runs**: otherwise, each rung's slot addresses are read from an
//!   operand table; the function is specific to the shape only.
//!
//! Only the ops that dominate typical ladder are emitted inline: contacts,
//! coils, one-shots, branches, jumps, bool copies, TON in ms (`X::Ton`; a TON in another
//! time base is `X::TonB`, left to the interpreter), CTU/CTD, integer compares and
//! ADD/SUB/MOV of DINTs, with their rare cases too (a wrapped sum, a negative
//! preset, a counter wrapping to OV/UN); their faults are noted in the
//! context and flushed into `Faults` in order. Every other op is a call to
//! the interpreter's own `step` for that single op, so most semantics are
//! written once (`exec/`), and the inline ones are held to the interpreter
//! by differential tests. Inline code branches as the interpreter does: a
//! rung's path through its instructions mostly repeats from scan to scan,
//! which branch predictors learn.
//!
//! Unsafe code here has one reason: running machine code we generate. It
//! touches memory only at slot indices taken from a program that passed
//! `Program::verify`, in memory whose sizes `run` checks first.
#![allow(unsafe_code)]

use crate::error::EngineError;
use crate::exec::{self, Code, Stop, X};
use crate::fault::{FaultCode, Faults};
use crate::mem::{Mem, Sink};
use alba_ir::op::{PID_B_SLOTS, PID_F_SLOTS, PID_I_SLOTS};
use alba_ir::{Memory, Op, Program};
use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{
    AbiParam, InstBuilder, InstructionData, MemFlagsData, Opcode, SigRef, Signature, Type, Value, ValueDef, types,
};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext, Variable};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{Linkage, Module, default_libcall_names};
use std::collections::HashMap;
use std::mem::offset_of;

/// What generated code and the fallback share during one scan.
#[repr(C)]
pub(crate) struct JitCtx {
    b: *mut bool,
    i: *mut i32,
    f: *mut f32,
    l: *mut i64,
    d: *mut f64,
    m: *mut u8,
    lens: [usize; 6],
    now: u32,
    /// The op of the last JMP taken (for runaway reports).
    last_jump: u32,
    /// Faults of inline code not yet in `faults`: how many, then the
    /// (code, op) of the first and of the last.
    fault_n: u32,
    fault_first: [u32; 2],
    fault_last: [u32; 2],
    /// Strided runs: the base of each class for the first rung of the
    /// call, and the number of rungs of the call.
    bases: [u64; MAX_CLASSES],
    count: u64,
    /// The program's canonical ops (native code's op `k` is canonical op `k`).
    ops: *const Op,
    n_ops: usize,
    faults: *mut Faults,
}

impl JitCtx {
    /// Moves the faults inline code noted into `faults`, in order.
    fn flush_faults(&mut self) {
        if self.fault_n == 0 {
            return;
        }
        // SAFETY: `faults` comes from a live borrow held by `Jit::run`.
        let faults = unsafe { &mut *self.faults };
        let at = |[code, pc]: [u32; 2]| (FaultCode::from_i32(code as i32).unwrap_or(FaultCode::Overflow), pc);
        faults.absorb(u64::from(self.fault_n), at(self.fault_first), at(self.fault_last));
        self.fault_n = 0;
    }
}

/// Runs one op in the interpreter on behalf of generated code.
extern "C" fn fallback(ctx: *mut JitCtx, pc: u32, rc: u32) -> u32 {
    // SAFETY: generated code calls this only from `Jit::run`, passing the
    // context `run` built from live, exclusive borrows; while this runs the
    // generated code is suspended, so these are the only references.
    let ctx = unsafe { &mut *ctx };
    ctx.flush_faults();
    let (mut m, ops, faults) = unsafe {
        (
            Mem {
                b: std::slice::from_raw_parts_mut(ctx.b, ctx.lens[0]),
                i: std::slice::from_raw_parts_mut(ctx.i, ctx.lens[1]),
                f: std::slice::from_raw_parts_mut(ctx.f, ctx.lens[2]),
                l: std::slice::from_raw_parts_mut(ctx.l, ctx.lens[3]),
                d: std::slice::from_raw_parts_mut(ctx.d, ctx.lens[4]),
                m: std::slice::from_raw_parts_mut(ctx.m, ctx.lens[5]),
            },
            std::slice::from_raw_parts(ctx.ops, ctx.n_ops),
            &mut *ctx.faults,
        )
    };
    let Some(&op) = ops.get(pc as usize) else { return rc };
    let mut sink = Sink { faults, src: &[] };
    u32::from(exec::step(
        exec::flatten(op),
        &mut m,
        &mut sink,
        ctx.now,
        pc as usize,
        rc != 0,
    ))
}

/// Runs a PID op on behalf of generated code, given the addresses of its
/// REAL, DINT and BOOL slot ranges (no op lookup, no dispatch: the one call
/// a PID rung makes).
extern "C" fn pid_call(ctx: *mut JitCtx, f: *mut f32, i: *mut i32, b: *mut bool, pc: u32, rc: u32) {
    // SAFETY: as for `fallback`; the three addresses are the op's slot
    // ranges in the memory `run` borrowed, in bounds after `verify` (which
    // checks each range's last slot).
    let ctx = unsafe { &mut *ctx };
    ctx.flush_faults();
    let (f, i, b, faults) = unsafe {
        (
            std::slice::from_raw_parts_mut(f, PID_F_SLOTS as usize),
            std::slice::from_raw_parts_mut(i, PID_I_SLOTS as usize),
            std::slice::from_raw_parts_mut(b, PID_B_SLOTS as usize),
            &mut *ctx.faults,
        )
    };
    let mut sink = Sink { faults, src: &[] };
    crate::pid::pid_on(f, i, b, rc != 0, ctx.now, &mut sink, pc as usize);
}

/// A shape function: `(ctx, operands, count)` runs `count` consecutive
/// rungs of its shape and returns 0 to go on after them, or `target + 1`
/// when a JMP to rung `target` is taken. A table run's function reads the
/// operands of the first of them from `operands`; a strided run's reads its
/// class bases from `ctx.bases`.
type ShapeFn = unsafe extern "C" fn(*mut JitCtx, *const u64, usize) -> u32;

/// Strided runs have at most this many operand classes. A Ladder rung
/// needs 3–5; an ST statement group more (temporaries and shared constants
/// that stay, tags and instances moving by different amounts, the own
/// constant of a literal preset, jump targets and op numbers): 9 for
/// `alba bench --st`'s rung. Bases beyond the registers spill to the stack.
const MAX_CLASSES: usize = 12;
/// Fewer consecutive rungs of one layout share the table's generic code.
const MIN_STRIDED: usize = 4;
/// At most this many distinct strided functions per program (the rest use
/// the table), which bounds machine code and compile time for programs
/// without a regular layout.
const MAX_STRIDED_FNS: usize = 256;

/// Consecutive rungs of one shape.
#[derive(Clone, Copy)]
struct Run {
    f: ShapeFn,
    first_rung: u32,
    rungs: u32,
    /// The op where its first rung starts, and the ops of each rung.
    first_pc: u32,
    len: u32,
    /// Where its operands start in the table: `stride` per rung (a table
    /// run), or one base per class for its first rung (a strided run).
    operands: u32,
    stride: u32,
    /// Strided runs: how many classes, and where the change of each from
    /// one rung to the next starts in `Jit::deltas` (bytes, or numbers).
    classes: u32,
    deltas: u32,
}

/// A program compiled to machine code.
pub struct Jit {
    module: Option<JITModule>,
    /// Memory sizes the program was verified against.
    sizes: [usize; 6],
    /// In rung order, covering every rung.
    runs: Vec<Run>,
    rungs: usize,
    deltas: Vec<i64>,
    operands: std::cell::RefCell<Operands>,
    /// Machine-code functions: one per rung shape for table runs, one per
    /// shape and layout for strided runs.
    pub shapes: usize,
}

impl Drop for Jit {
    fn drop(&mut self) {
        if let Some(m) = self.module.take() {
            // SAFETY: the functions point into this module and die with `self`.
            unsafe { m.free_memory() };
        }
    }
}

impl std::fmt::Debug for Jit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Jit({} rungs, {} runs, {} shapes)",
            self.rungs,
            self.runs.len(),
            self.shapes
        )
    }
}

fn err(e: impl std::fmt::Display) -> EngineError {
    EngineError::Native(format!("native compilation failed: {e}"))
}

/// What an operand names: a slot of one memory class, or a number (an op
/// index for the interpreter and fault reports, a rung index for a jump).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Kind {
    Bool,
    Int,
    Float,
    Number,
}

impl Kind {
    /// Bytes per slot (1 for numbers: they are used as they are).
    fn unit(self) -> i64 {
        match self {
            Kind::Bool | Kind::Number => 1,
            Kind::Int | Kind::Float => 4,
        }
    }
}

/// An operand of a rung: a slot (whose address goes in the table) or a number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Operand {
    kind: Kind,
    n: u32,
}

/// The operands of the table runs and the class bases of the strided runs,
/// and their values for the memory they were last resolved against (slot
/// addresses are absolute, so generated code needs no memory base registers).
#[derive(Debug, Default)]
struct Operands {
    items: Vec<Operand>,
    values: Vec<u64>,
    /// Addresses of the bool, integer and REAL arrays `values` was made for.
    bases: (usize, usize, usize),
}

impl Operands {
    /// Resolves slot operands against memory at these addresses.
    fn rebase(&mut self, b: *mut bool, i: *mut i32, f: *mut f32) {
        let bases = (b as usize, i as usize, f as usize);
        if self.bases == bases && self.values.len() == self.items.len() {
            return;
        }
        self.values = self
            .items
            .iter()
            .map(|o| match o.kind {
                Kind::Bool => (bases.0 + o.n as usize) as u64,
                Kind::Int => (bases.1 + 4 * o.n as usize) as u64,
                Kind::Float => (bases.2 + 4 * o.n as usize) as u64,
                Kind::Number => u64::from(o.n),
            })
            .collect();
        self.bases = bases;
    }
}

/// The layout of the rungs of a strided run: every operand moves by the
/// same amount from one rung to the next, so the operands of a rung are a
/// few class bases (one per kind and change per rung) plus constant offsets.
/// Generated code keeps the bases in registers and adds the changes after
/// each rung: no operand table at all, like an array of structs.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct Strides {
    /// (kind, change per rung in slots or numbers) of each class.
    classes: Vec<(Kind, i64)>,
    /// (class, offset from the class base in slots or numbers) of each operand.
    at: Vec<(usize, i64)>,
}

impl Strides {
    /// The layout of rungs whose operands are `first`, then `first + delta`,
    /// …, and the class bases of the first rung; `None` if it needs too many
    /// classes or offsets too large for an instruction.
    fn new(first: &[Operand], delta: &[i64]) -> Option<(Strides, Vec<Operand>)> {
        let mut classes: Vec<(Kind, i64)> = Vec::new();
        let mut bases: Vec<Operand> = Vec::new();
        let mut of = Vec::with_capacity(first.len());
        for (o, &d) in first.iter().zip(delta) {
            let c = match classes.iter().position(|&k| k == (o.kind, d)) {
                Some(c) => c,
                None => {
                    classes.push((o.kind, d));
                    bases.push(*o);
                    classes.len() - 1
                }
            };
            bases[c].n = bases[c].n.min(o.n);
            of.push(c);
        }
        if classes.len() > MAX_CLASSES {
            return None;
        }
        let at: Vec<(usize, i64)> = first
            .iter()
            .zip(of)
            .map(|(o, c)| (c, i64::from(o.n) - i64::from(bases[c].n)))
            .collect();
        let fits = |v: i64| i32::try_from(v).is_ok();
        let ok = at.iter().all(|&(c, off)| fits(off * classes[c].0.unit()))
            && classes.iter().all(|&(k, d)| fits(d * k.unit()));
        ok.then_some((Strides { classes, at }, bases))
    }
}

/// How much each operand changes from rung `a` to rung `b` of the same shape.
fn delta(a: &[Operand], b: &[Operand]) -> Vec<i64> {
    a.iter().zip(b).map(|(x, y)| i64::from(y.n) - i64::from(x.n)).collect()
}

/// The shape of an op: the op with every slot number zeroed, or `None` for
/// ops left to the interpreter. Its operands go to `out`. Branch ops need
/// none: their state lives in registers.
/// A jump to the rung right after its own (`rung + 1`) is `X::Jmp(1)`: it
/// skips the rest of the rung inside the function, which goes on with the
/// next rung of its run (an ST `IF` without `ELSE` in a rung of statements).
fn shape(op: X, pc: usize, rung: u32, rung_of: &HashMap<u32, u32>, n_rungs: u32, out: &mut Vec<Operand>) -> Option<X> {
    use alba_ir::{B, Ctr, I, Tmr};
    let (b0, i0) = (B(0), I(0));
    let bo = |b: B| Operand {
        kind: Kind::Bool,
        n: b.0,
    };
    let io = |i: I| Operand {
        kind: Kind::Int,
        n: i.0,
    };
    let fo = |f: alba_ir::F| Operand {
        kind: Kind::Float,
        n: f.0,
    };
    let num = |n: u32| Operand { kind: Kind::Number, n };
    let pc = num(pc as u32);
    let s = match op {
        X::Rung | X::Nop | X::Afi | X::End | X::Not | X::True => op,
        X::Xic(b)
        | X::Xio(b)
        | X::Ote(b)
        | X::Otl(b)
        | X::Otu(b)
        | X::Ons(b)
        | X::Ld(b)
        | X::Ldn(b)
        | X::Or(b)
        | X::Orn(b) => {
            out.push(bo(b));
            match op {
                X::Xic(_) => X::Xic(b0),
                X::Xio(_) => X::Xio(b0),
                X::Ote(_) => X::Ote(b0),
                X::Otl(_) => X::Otl(b0),
                X::Otu(_) => X::Otu(b0),
                X::Ld(_) => X::Ld(b0),
                X::Ldn(_) => X::Ldn(b0),
                X::Or(_) => X::Or(b0),
                X::Orn(_) => X::Orn(b0),
                _ => X::Ons(b0),
            }
        }
        X::Osr(s, o) | X::Osf(s, o) => {
            out.extend([bo(s), bo(o)]);
            if matches!(op, X::Osr(..)) {
                X::Osr(b0, b0)
            } else {
                X::Osf(b0, b0)
            }
        }
        X::BrOpen { .. } => X::BrOpen { save: b0, acc: b0 },
        X::BrNext { .. } => X::BrNext { save: b0, acc: b0 },
        X::BrClose { .. } => X::BrClose { acc: b0 },
        X::Jmp(t) => {
            // A target that is no rung start (never, after `Code::new`) ends the scan.
            let target = rung_of.get(&t).copied().unwrap_or(n_rungs);
            out.extend([num(target), pc]);
            X::Jmp(u32::from(target == rung + 1))
        }
        X::Ton(t) => {
            out.extend([io(t.i), bo(t.b), pc]);
            X::Ton(Tmr { i: i0, b: b0 })
        }
        X::Ctu(c) | X::Ctd(c) => {
            out.extend([io(c.i), bo(c.b)]);
            let z = Ctr { i: i0, b: b0 };
            if matches!(op, X::Ctu(_)) { X::Ctu(z) } else { X::Ctd(z) }
        }
        X::EqI(a, b) | X::NeI(a, b) | X::LtI(a, b) | X::GtI(a, b) | X::LeI(a, b) | X::GeI(a, b) => {
            out.extend([io(a), io(b)]);
            match op {
                X::EqI(..) => X::EqI(i0, i0),
                X::NeI(..) => X::NeI(i0, i0),
                X::LtI(..) => X::LtI(i0, i0),
                X::GtI(..) => X::GtI(i0, i0),
                X::LeI(..) => X::LeI(i0, i0),
                _ => X::GeI(i0, i0),
            }
        }
        X::AddI(a, b, d) | X::SubI(a, b, d) => {
            out.extend([io(a), io(b), io(d), pc]);
            if matches!(op, X::AddI(..)) {
                X::AddI(i0, i0, i0)
            } else {
                X::SubI(i0, i0, i0)
            }
        }
        // A REAL move (the PID's PV in and CV out, MOV of REALs): bits copied, as `exec`.
        X::MovF(a, d) => {
            out.extend([fo(a), fo(d)]);
            X::MovF(alba_ir::F(0), alba_ir::F(0))
        }
        X::Pid(p) => {
            out.extend([fo(p.f), io(p.i), bo(p.b), pc]);
            X::Pid(alba_ir::Pidt {
                f: alba_ir::F(0),
                i: i0,
                b: b0,
            })
        }
        X::CopyB(a, d) => {
            out.extend([bo(a), bo(d)]);
            X::CopyB(b0, b0)
        }
        X::MovI(a, d) | X::CopyI(a, d) => {
            out.extend([io(a), io(d)]);
            if matches!(op, X::MovI(..)) {
                X::MovI(i0, i0)
            } else {
                X::CopyI(i0, i0)
            }
        }
        _ => {
            out.push(pc);
            return None;
        }
    };
    Some(s)
}

/// A rung's shape and operands.
struct RungCode {
    start: usize,
    key: Vec<Option<X>>,
    operands: Vec<Operand>,
}

impl Jit {
    /// Compiles a verified program. Fails on hosts Cranelift does not support.
    pub fn compile(prog: &Program) -> Result<Jit, EngineError> {
        Jit::compile_with(prog, None)
    }

    /// Compiles, and with `listing` appends the Cranelift IR and the machine
    /// code (after register allocation) of every function to it.
    pub fn compile_with(prog: &Program, mut listing: Option<&mut String>) -> Result<Jit, EngineError> {
        // Unfused code: one executable op per canonical op.
        let code = &Code::new(prog, false);
        let mut flags = settings::builder();
        flags.set("opt_level", "speed").map_err(err)?;
        flags.set("use_colocated_libcalls", "false").map_err(err)?;
        flags.set("is_pic", "false").map_err(err)?;
        let isa = cranelift_native::builder()
            .map_err(err)?
            .finish(settings::Flags::new(flags))
            .map_err(err)?;
        let ptr = isa.pointer_type();
        let mut module = JITModule::new(JITBuilder::with_isa(isa, default_libcall_names()));

        // Rungs start at `Rung` ops (jump targets are always rung starts).
        let starts: Vec<usize> = (0..code.ops.len()).filter(|&pc| code.ops[pc] == X::Rung).collect();
        let rung_of: HashMap<u32, u32> = starts
            .iter()
            .enumerate()
            .map(|(r, &pc)| (pc as u32, r as u32))
            .collect();
        let n_rungs = starts.len() as u32;
        let rungs: Vec<RungCode> = starts
            .iter()
            .enumerate()
            .map(|(r, &start)| {
                // The last rung ends before the final `End` (which does nothing).
                let end = starts.get(r + 1).copied().unwrap_or(code.ops.len() - 1);
                let mut operands = Vec::new();
                let key = (start..end)
                    .map(|pc| shape(code.ops[pc], pc, r as u32, &rung_of, n_rungs, &mut operands))
                    .collect();
                RungCode { start, key, operands }
            })
            .collect();

        let mut sig = module.make_signature();
        sig.params.push(AbiParam::new(ptr));
        sig.params.push(AbiParam::new(ptr));
        sig.params.push(AbiParam::new(ptr));
        sig.returns.push(AbiParam::new(types::I32));
        let mut fns: HashMap<(Vec<Option<X>>, Option<Strides>), cranelift_module::FuncId> = HashMap::new();
        let mut strided_fns = 0;
        let mut runs: Vec<(cranelift_module::FuncId, Run)> = Vec::new();
        let mut operands = Operands::default();
        let mut deltas = Vec::new();
        let mut ctx = module.make_context();
        let mut fctx = FunctionBuilderContext::new();
        let mut r = 0;
        while r < rungs.len() {
            // The longest sequence of rungs of this shape whose operands all
            // move by the same amount from one rung to the next.
            let first = &rungs[r];
            let mut end = r + 1;
            let mut step: Option<Vec<i64>> = None;
            while let Some(next) = rungs.get(end)
                && next.key == first.key
            {
                let d = delta(&rungs[end - 1].operands, &next.operands);
                if step.as_ref().is_some_and(|s| *s != d) {
                    break;
                }
                step = Some(d);
                end += 1;
            }
            let strided = match &step {
                Some(step) if end - r >= MIN_STRIDED => Strides::new(&first.operands, step),
                _ => None,
            };
            let strided = strided.filter(|(s, _)| {
                strided_fns < MAX_STRIDED_FNS || fns.contains_key(&(first.key.clone(), Some(s.clone())))
            });
            // A short sequence settles only its first rung here (the next
            // may start a strided run).
            let end = if strided.is_some() || end - r >= MIN_STRIDED {
                end
            } else {
                r + 1
            };
            let (strides, bases) = match strided {
                Some((s, b)) => (Some(s), b),
                None => (None, Vec::new()),
            };
            let fkey = (first.key.clone(), strides);
            let id = match fns.get(&fkey) {
                Some(&id) => id,
                None => {
                    let id = module
                        .declare_function(&format!("alba_shape_{}", fns.len()), Linkage::Local, &sig)
                        .map_err(err)?;
                    ctx.func.signature = sig.clone();
                    {
                        let mut fb = FunctionBuilder::new(&mut ctx.func, &mut fctx);
                        let mut fallback_sig = Signature::new(module.isa().default_call_conv());
                        fallback_sig.params.push(AbiParam::new(ptr));
                        fallback_sig.params.push(AbiParam::new(types::I32));
                        fallback_sig.params.push(AbiParam::new(types::I32));
                        fallback_sig.returns.push(AbiParam::new(types::I32));
                        let fallback_sig = fb.import_signature(fallback_sig);
                        let mut pid_sig = Signature::new(module.isa().default_call_conv());
                        pid_sig.params.extend([AbiParam::new(ptr); 4]);
                        pid_sig.params.extend([AbiParam::new(types::I32); 2]);
                        let pid_sig = fb.import_signature(pid_sig);
                        let access = fkey.1.clone();
                        Gen::new(&mut fb, ptr, fallback_sig, pid_sig, access).emit(&fkey.0, first.operands.len());
                        fb.seal_all_blocks();
                        fb.finalize(module.target_config());
                    }
                    if let Some(out) = listing.as_deref_mut() {
                        ctx.set_disasm(true);
                        let rungs = match &fkey.1 {
                            Some(_) => format!("rungs {}-{}, strided", r, end - 1),
                            None => format!("rung {r}, operand table"),
                        };
                        out.push_str(&format!("; function {} ({rungs})\n{}\n", fns.len(), ctx.func.display()));
                    }
                    module.define_function(id, &mut ctx).map_err(err)?;
                    if let Some(out) = listing.as_deref_mut() {
                        let vcode = ctx.compiled_code().and_then(|c| c.vcode.as_deref()).unwrap_or("");
                        out.push_str(&format!("; machine code\n{vcode}\n"));
                    }
                    module.clear_context(&mut ctx);
                    strided_fns += usize::from(fkey.1.is_some());
                    fns.insert(fkey.clone(), id);
                    id
                }
            };
            let run = Run {
                f: empty_shape,
                first_rung: r as u32,
                rungs: (end - r) as u32,
                first_pc: first.start as u32,
                len: first.key.len() as u32,
                operands: operands.items.len() as u32,
                stride: first.operands.len() as u32,
                classes: 0,
                deltas: deltas.len() as u32,
            };
            match &fkey.1 {
                Some(s) => {
                    operands.items.extend(bases);
                    deltas.extend(s.classes.iter().map(|&(k, d)| d * k.unit()));
                    runs.push((
                        id,
                        Run {
                            stride: 0,
                            classes: s.classes.len() as u32,
                            ..run
                        },
                    ));
                }
                None => {
                    for rung in &rungs[r..end] {
                        operands.items.extend(&rung.operands);
                    }
                    match runs.last_mut() {
                        Some((rid, last)) if *rid == id && last.classes == 0 => last.rungs += run.rungs,
                        _ => runs.push((id, run)),
                    }
                }
            }
            r = end;
        }
        module.finalize_definitions().map_err(err)?;
        let runs = runs
            .into_iter()
            .map(|(id, run)| {
                let raw = module.get_finalized_function(id);
                // SAFETY: `raw` is a function defined above with signature
                // `fn(ptr, ptr, ptr) -> i32` in the system calling convention.
                let f = unsafe { std::mem::transmute::<*const u8, ShapeFn>(raw) };
                Run { f, ..run }
            })
            .collect();
        Ok(Jit {
            module: Some(module),
            sizes: exec::sizes(&prog.init),
            runs,
            rungs: rungs.len(),
            deltas,
            operands: std::cell::RefCell::new(operands),
            shapes: fns.len(),
        })
    }

    /// Rungs compiled.
    pub fn rungs(&self) -> usize {
        self.rungs
    }

    /// Rungs in strided runs (operands at constant offsets from a few bases).
    pub fn strided_rungs(&self) -> usize {
        self.runs
            .iter()
            .filter(|r| r.classes > 0)
            .map(|r| r.rungs as usize)
            .sum()
    }

    /// Bytes of the operand table and the runs.
    pub fn table_bytes(&self) -> usize {
        let t = self.operands.borrow();
        t.items.len() * std::mem::size_of::<Operand>()
            + t.values.len() * 8
            + self.deltas.len() * 8
            + self.runs.len() * std::mem::size_of::<Run>()
    }

    /// Runs one scan of the compiled code over `mem`.
    pub(crate) fn run(&self, prog: &Program, mem: &mut Memory, faults: &mut Faults, now: u32) -> Result<(), Stop> {
        if exec::sizes(mem) != self.sizes {
            return Err(Stop::Memory);
        }
        let mut ctx = JitCtx {
            b: mem.b.as_mut_ptr(),
            i: mem.i.as_mut_ptr(),
            f: mem.f.as_mut_ptr(),
            l: mem.l.as_mut_ptr(),
            d: mem.d.as_mut_ptr(),
            m: mem.m.as_mut_ptr(),
            lens: [
                mem.b.len(),
                mem.i.len(),
                mem.f.len(),
                mem.l.len(),
                mem.d.len(),
                mem.m.len(),
            ],
            now,
            last_jump: 0,
            fault_n: 0,
            fault_first: [0; 2],
            fault_last: [0; 2],
            bases: [0; MAX_CLASSES],
            count: 0,
            ops: prog.ops.as_ptr(),
            n_ops: prog.ops.len(),
            faults,
        };
        let mut table = self.operands.borrow_mut();
        table.rebase(ctx.b, ctx.i, ctx.f);
        let (mut ri, mut r) = (0usize, 0usize);
        let mut backward = 0u32;
        while let Some(run) = self.runs.get(ri) {
            let skip = r - run.first_rung as usize;
            let at = run.operands as usize;
            let count = run.rungs as usize - skip;
            let operands = if run.classes == 0 {
                table.values[at + skip * run.stride as usize..].as_ptr()
            } else {
                // The class bases of rung `skip` of the run (0 but after a jump).
                let n = run.classes as usize;
                let deltas = &self.deltas[run.deltas as usize..][..n];
                for ((b, v), d) in ctx.bases.iter_mut().zip(&table.values[at..at + n]).zip(deltas) {
                    *b = v.wrapping_add(d.wrapping_mul(skip as i64) as u64);
                }
                ctx.count = count as u64;
                ctx.bases.as_ptr()
            };
            // SAFETY: `run.f` was generated for the shape and layout of these
            // rungs, whose operands `operands` gives; it uses `ctx` only
            // during the call.
            let next = unsafe { (run.f)(&mut ctx, operands, count) };
            ctx.flush_faults();
            if next == 0 {
                ri += 1;
                r = (run.first_rung + run.rungs) as usize;
                continue;
            }
            let target = next as usize - 1;
            if target >= self.rungs {
                break;
            }
            let from = self.rung_at(ctx.last_jump);
            if target <= from {
                backward += 1;
                if backward > exec::BACKWARD_JUMP_LIMIT {
                    return Err(Stop::Runaway(ctx.last_jump));
                }
            }
            r = target;
            ri = self.runs.partition_point(|x| x.first_rung as usize <= target) - 1;
        }
        Ok(())
    }

    /// The rung holding op `pc`.
    fn rung_at(&self, pc: u32) -> usize {
        let ri = self.runs.partition_point(|x| x.first_pc <= pc).saturating_sub(1);
        self.runs
            .get(ri)
            .map_or(0, |x| (x.first_rung + (pc - x.first_pc) / x.len.max(1)) as usize)
    }
}

/// A placeholder until the module is finalized.
unsafe extern "C" fn empty_shape(_: *mut JitCtx, _: *const u64, _: usize) -> u32 {
    0
}

/// Code generation for one rung shape.
struct Gen<'a, 'b> {
    fb: &'a mut FunctionBuilder<'b>,
    ptr: Type,
    fallback_sig: SigRef,
    pid_sig: SigRef,
    ctx: Value,
    /// Rungs left to run, counting the current one.
    left: Variable,
    /// Table runs: where the current rung's operands start.
    table: Variable,
    /// Strided runs: the layout, and each slot class's base for the current rung.
    strides: Option<Strides>,
    class_bases: Vec<Option<Variable>>,
    /// The next operand of the rung to read.
    next: usize,
    /// The scan's clock.
    now: Value,
    rc: Variable,
    /// Open branches: (rung state at the branch, OR of the legs so far).
    branches: Vec<(Variable, Variable)>,
    flags: MemFlagsData,
    /// Where the current rung ends (a jump to the next rung goes there).
    rung_end: Option<cranelift_codegen::ir::Block>,
}

/// A slot's address: a base and a constant offset in bytes.
#[derive(Clone, Copy)]
struct Addr {
    base: Value,
    off: i32,
}

/// A number operand of the rung, computed only where it is used (in cold
/// paths mostly: fault reports).
#[derive(Clone, Copy)]
struct Num(usize);

impl<'a, 'b> Gen<'a, 'b> {
    fn new(
        fb: &'a mut FunctionBuilder<'b>,
        ptr: Type,
        fallback_sig: SigRef,
        pid_sig: SigRef,
        strides: Option<Strides>,
    ) -> Self {
        let entry = fb.create_block();
        fb.append_block_params_for_function_params(entry);
        fb.switch_to_block(entry);
        let params = fb.block_params(entry).to_vec();
        let (ctx, param, count) = (params[0], params[1], params[2]);
        let flags = MemFlagsData::trusted();
        let rc = fb.declare_var(types::I8);
        let one = fb.ins().iconst(types::I8, 1);
        fb.def_var(rc, one);
        let table = fb.declare_var(ptr);
        fb.def_var(table, param);
        let left = fb.declare_var(ptr);
        fb.def_var(left, count);
        let now = fb.ins().load(types::I32, flags, ctx, offset_of!(JitCtx, now) as i32);
        // Slot classes keep their base in a register (numbers are computed
        // from the context where used).
        let class_bases = match &strides {
            Some(s) => (s.classes.iter().enumerate())
                .map(|(c, &(kind, _))| {
                    (kind != Kind::Number).then(|| {
                        let v = fb.declare_var(ptr);
                        let at = (offset_of!(JitCtx, bases) + c * 8) as i32;
                        let base = fb.ins().load(types::I64, flags, ctx, at);
                        fb.def_var(v, base);
                        v
                    })
                })
                .collect(),
            None => Vec::new(),
        };
        Gen {
            fb,
            ptr,
            fallback_sig,
            pid_sig,
            ctx,
            left,
            table,
            strides,
            class_bases,
            next: 0,
            now,
            rc,
            branches: Vec::new(),
            flags,
            rung_end: None,
        }
    }

    /// The address of the slot named by the next operand.
    fn slot(&mut self) -> Addr {
        let j = self.next;
        self.next += 1;
        match &self.strides {
            None => {
                let table = self.fb.use_var(self.table);
                let base = self.fb.ins().load(types::I64, self.flags, table, (j * 8) as i32);
                Addr { base, off: 0 }
            }
            Some(s) => {
                let (c, off) = s.at[j];
                let off = (off * s.classes[c].0.unit()) as i32;
                let base = match self.class_bases[c] {
                    Some(v) => self.fb.use_var(v),
                    None => self.ctx_base(c),
                };
                Addr { base, off }
            }
        }
    }

    /// The next operand, a number.
    fn number(&mut self) -> Num {
        self.next += 1;
        Num(self.next - 1)
    }

    /// The value of a number operand, as a 32-bit integer.
    fn num(&mut self, Num(j): Num) -> Value {
        let v = match &self.strides {
            None => {
                let table = self.fb.use_var(self.table);
                self.fb.ins().load(types::I64, self.flags, table, (j * 8) as i32)
            }
            Some(s) => {
                // The class base for the first rung of the call, plus the
                // offset, plus the change per rung times the rungs done.
                let (c, off) = s.at[j];
                let step = s.classes[c].1;
                let base = self.ctx_base(c);
                let left = self.fb.use_var(self.left);
                let count = self
                    .fb
                    .ins()
                    .load(self.ptr, self.flags, self.ctx, offset_of!(JitCtx, count) as i32);
                let done = self.fb.ins().isub(count, left);
                let moved = self.fb.ins().imul_imm_s(done, step);
                let v = self.fb.ins().iadd(base, moved);
                self.fb.ins().iadd_imm_s(v, off)
            }
        };
        self.fb.ins().ireduce(types::I32, v)
    }

    /// The base of class `c` for the first rung of the call.
    fn ctx_base(&mut self, c: usize) -> Value {
        let at = (offset_of!(JitCtx, bases) + c * 8) as i32;
        self.fb.ins().load(self.ptr, self.flags, self.ctx, at)
    }

    /// The scan's clock.
    fn now(&mut self) -> Value {
        self.now
    }

    /// A slot's address as one value (for calls).
    fn addr_value(&mut self, a: Addr) -> Value {
        if a.off == 0 {
            a.base
        } else {
            self.fb.ins().iadd_imm_s(a.base, i64::from(a.off))
        }
    }

    /// The byte `off` bytes from `a`.
    fn ld8(&mut self, a: Addr, off: i32) -> Value {
        self.fb.ins().load(types::I8, self.flags, a.base, a.off + off)
    }
    fn st8(&mut self, a: Addr, off: i32, v: Value) {
        self.fb.ins().store(self.flags, v, a.base, a.off + off);
    }
    /// The 32-bit slot `off` slots from `a`.
    fn ld32(&mut self, a: Addr, off: i32) -> Value {
        self.fb.ins().load(types::I32, self.flags, a.base, a.off + off * 4)
    }
    fn st32(&mut self, a: Addr, off: i32, v: Value) {
        self.fb.ins().store(self.flags, v, a.base, a.off + off * 4);
    }
    fn rc(&mut self) -> Value {
        self.fb.use_var(self.rc)
    }
    fn set_rc(&mut self, v: Value) {
        self.fb.def_var(self.rc, v);
    }
    fn c8(&mut self, v: i64) -> Value {
        self.fb.ins().iconst(types::I8, v)
    }
    fn c32(&mut self, v: i64) -> Value {
        self.fb.ins().iconst(types::I32, v)
    }
    /// The value of a bool that is a constant (the rung condition at the
    /// start of a rung, the OR of no branch legs yet).
    fn known(&self, v: Value) -> Option<bool> {
        let ValueDef::Result(inst, _) = self.fb.func.dfg.value_def(v) else {
            return None;
        };
        match self.fb.func.dfg.insts[inst] {
            InstructionData::UnaryImm {
                opcode: Opcode::Iconst,
                imm,
            } => Some(imm.bits() != 0),
            _ => None,
        }
    }
    // Bools are 0 or 1 (memory holds Rust bools, generated code stores
    // nothing else), so a known operand decides or passes the other through;
    // Cranelift cannot assume that and would mask with 1.
    fn not(&mut self, v: Value) -> Value {
        match self.known(v) {
            Some(k) => self.c8(i64::from(!k)),
            None => self.fb.ins().bxor_imm_u(v, 1),
        }
    }
    fn and(&mut self, a: Value, b: Value) -> Value {
        match (self.known(a), self.known(b)) {
            (Some(true), _) => b,
            (_, Some(true)) => a,
            (Some(false), _) => a,
            (_, Some(false)) => b,
            _ => self.fb.ins().band(a, b),
        }
    }
    fn or(&mut self, a: Value, b: Value) -> Value {
        match (self.known(a), self.known(b)) {
            (Some(false), _) => b,
            (_, Some(false)) => a,
            (Some(true), _) => a,
            (_, Some(true)) => b,
            _ => self.fb.ins().bor(a, b),
        }
    }
    fn and_rc(&mut self, v: Value) {
        let rc = self.rc();
        let r = self.and(rc, v);
        self.set_rc(r);
    }

    /// Calls the interpreter for the op whose index is `pc`; the rung
    /// condition it returns becomes the current one.
    fn call_fallback(&mut self, pc: Value) {
        let f = self.fb.ins().iconst(self.ptr, fallback as *const () as i64);
        let rc = self.rc();
        let rc32 = self.fb.ins().uextend(types::I32, rc);
        let call = self.fb.ins().call_indirect(self.fallback_sig, f, &[self.ctx, pc, rc32]);
        let r = self.fb.inst_results(call)[0];
        let r8 = self.fb.ins().ireduce(types::I8, r);
        self.set_rc(r8);
    }

    /// `if cond { then() }` then continue.
    fn when(&mut self, cond: Value, then: impl FnOnce(&mut Self)) {
        let t = self.fb.create_block();
        let join = self.fb.create_block();
        self.fb.ins().brif(cond, t, &[], join, &[]);
        self.fb.switch_to_block(t);
        then(self);
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(join);
    }

    /// `if cond { note fault `code` at op `pc` }` (a cold path, no call).
    fn fault_if(&mut self, cond: Value, code: FaultCode, pc: Num) {
        let cold = self.fb.create_block();
        let join = self.fb.create_block();
        self.fb.ins().brif(cond, cold, &[], join, &[]);
        self.fb.set_cold_block(cold);
        self.fb.switch_to_block(cold);
        self.note_fault(code, pc);
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(join);
    }

    /// Notes fault `code` at op `pc` in the context (in a cold block).
    fn note_fault(&mut self, code: FaultCode, pc: Num) {
        let pc = self.num(pc);
        let f = self.flags;
        let n = self
            .fb
            .ins()
            .load(types::I32, f, self.ctx, offset_of!(JitCtx, fault_n) as i32);
        let code = self.c32(code as i64);
        let first = self.fb.create_block();
        let rest = self.fb.create_block();
        self.fb.set_cold_block(first);
        self.fb.set_cold_block(rest);
        self.fb.ins().brif(n, rest, &[], first, &[]);
        self.fb.switch_to_block(first);
        self.fb
            .ins()
            .store(f, code, self.ctx, offset_of!(JitCtx, fault_first) as i32);
        self.fb
            .ins()
            .store(f, pc, self.ctx, offset_of!(JitCtx, fault_first) as i32 + 4);
        self.fb.ins().jump(rest, &[]);
        self.fb.switch_to_block(rest);
        self.fb
            .ins()
            .store(f, code, self.ctx, offset_of!(JitCtx, fault_last) as i32);
        self.fb
            .ins()
            .store(f, pc, self.ctx, offset_of!(JitCtx, fault_last) as i32 + 4);
        let n1 = self.fb.ins().iadd_imm_s(n, 1);
        self.fb.ins().store(f, n1, self.ctx, offset_of!(JitCtx, fault_n) as i32);
    }

    /// `if cond { note fault `code` at op `pc`; faulted } else { normal }`.
    fn fault_if_else(&mut self, cond: Value, code: FaultCode, pc: Num, normal: Value, faulted: i64) -> Value {
        let (cold, join) = (self.fb.create_block(), self.fb.create_block());
        let v = self.fb.append_block_param(join, types::I32);
        self.fb.ins().brif(cond, cold, &[], join, &[normal.into()]);
        self.fb.set_cold_block(cold);
        self.fb.switch_to_block(cold);
        self.note_fault(code, pc);
        let faulted = self.c32(faulted);
        self.fb.ins().jump(join, &[faulted.into()]);
        self.fb.switch_to_block(join);
        v
    }

    /// The function: a loop over `count` rungs of this shape.
    /// `count` is at least 1: the test is at the bottom.
    fn emit(mut self, shape: &[Option<X>], stride: usize) {
        let body = self.fb.create_block();
        let done = self.fb.create_block();
        let rung_end = self.fb.create_block();
        self.rung_end = Some(rung_end);
        self.fb.ins().jump(body, &[]);
        self.fb.switch_to_block(body);
        self.next = 0;
        for op in shape {
            match op {
                Some(op) => self.op(*op),
                None => {
                    let pc = self.number();
                    let pc = self.num(pc);
                    self.call_fallback(pc);
                }
            }
        }
        self.fb.ins().jump(rung_end, &[]);
        self.fb.switch_to_block(rung_end);
        // The next rung's operands.
        match &self.strides {
            None => {
                let table = self.fb.use_var(self.table);
                let following = self.fb.ins().iadd_imm_s(table, (stride * 8) as i64);
                self.fb.def_var(self.table, following);
            }
            Some(s) => {
                let moves: Vec<(Variable, i64)> = (s.classes.iter().zip(&self.class_bases))
                    .filter_map(|(&(kind, step), v)| v.filter(|_| step != 0).map(|v| (v, step * kind.unit())))
                    .collect();
                for (v, step) in moves {
                    let base = self.fb.use_var(v);
                    let following = self.fb.ins().iadd_imm_s(base, step);
                    self.fb.def_var(v, following);
                }
            }
        }
        let n = self.fb.use_var(self.left);
        let n1 = self.fb.ins().iadd_imm_s(n, -1);
        self.fb.def_var(self.left, n1);
        self.fb.ins().brif(n1, body, &[], done, &[]);
        self.fb.switch_to_block(done);
        let zero = self.c32(0);
        self.fb.ins().return_(&[zero]);
    }

    fn op(&mut self, op: X) {
        match op {
            X::Rung => {
                let one = self.c8(1);
                self.set_rc(one);
            }
            X::Nop | X::End => {}
            X::Afi => {
                let zero = self.c8(0);
                self.set_rc(zero);
            }
            X::Xic(_) | X::Xio(_) => {
                let a = self.slot();
                let v = self.ld8(a, 0);
                let v = if matches!(op, X::Xio(_)) { self.not(v) } else { v };
                self.and_rc(v);
            }
            X::Ote(_) => {
                let a = self.slot();
                let rc = self.rc();
                self.st8(a, 0, rc);
            }
            // The logic stack of Instruction List.
            X::Ld(_) | X::Ldn(_) | X::Or(_) | X::Orn(_) => {
                let a = self.slot();
                let v = self.ld8(a, 0);
                let v = if matches!(op, X::Ldn(_) | X::Orn(_)) {
                    self.not(v)
                } else {
                    v
                };
                let v = if matches!(op, X::Or(_) | X::Orn(_)) {
                    let rc = self.rc();
                    self.or(rc, v)
                } else {
                    v
                };
                self.set_rc(v);
            }
            X::Not => {
                let rc = self.rc();
                let n = self.not(rc);
                self.set_rc(n);
            }
            X::True => {
                let one = self.c8(1);
                self.set_rc(one);
            }
            X::Otl(_) | X::Otu(_) => {
                let a = self.slot();
                let v = self.ld8(a, 0);
                let rc = self.rc();
                let r = if matches!(op, X::Otl(_)) {
                    self.or(v, rc)
                } else {
                    let nrc = self.not(rc);
                    self.and(v, nrc)
                };
                self.st8(a, 0, r);
            }
            X::Ons(_) => {
                let a = self.slot();
                let sv = self.ld8(a, 0);
                let rc = self.rc();
                let nsv = self.not(sv);
                let out = self.and(rc, nsv);
                self.st8(a, 0, rc);
                self.set_rc(out);
            }
            X::Osr(..) | X::Osf(..) => {
                let s = self.slot();
                let o = self.slot();
                let sv = self.ld8(s, 0);
                let rc = self.rc();
                let out = if matches!(op, X::Osr(..)) {
                    let nsv = self.not(sv);
                    self.and(rc, nsv)
                } else {
                    let nrc = self.not(rc);
                    self.and(nrc, sv)
                };
                self.st8(o, 0, out);
                self.st8(s, 0, rc);
            }
            X::BrOpen { .. } => {
                let save = self.fb.declare_var(types::I8);
                let acc = self.fb.declare_var(types::I8);
                let rc = self.rc();
                self.fb.def_var(save, rc);
                let zero = self.c8(0);
                self.fb.def_var(acc, zero);
                self.branches.push((save, acc));
            }
            X::BrNext { .. } => {
                if let Some(&(save, acc)) = self.branches.last() {
                    let a = self.fb.use_var(acc);
                    let rc = self.rc();
                    let na = self.or(a, rc);
                    self.fb.def_var(acc, na);
                    let s = self.fb.use_var(save);
                    self.set_rc(s);
                }
            }
            X::BrClose { .. } => {
                if let Some((_, acc)) = self.branches.pop() {
                    let a = self.fb.use_var(acc);
                    let rc = self.rc();
                    let r = self.or(rc, a);
                    self.set_rc(r);
                }
            }
            X::Jmp(1) => {
                // To the next rung: the rest of this one is skipped.
                let _ = (self.number(), self.number());
                let rc = self.rc();
                let (end, go_on) = (self.rung_end, self.fb.create_block());
                if let Some(end) = end {
                    self.fb.ins().brif(rc, end, &[], go_on, &[]);
                    self.fb.switch_to_block(go_on);
                }
            }
            X::Jmp(_) => {
                let (target, pc) = (self.number(), self.number());
                let rc = self.rc();
                self.when(rc, |g| {
                    let (target, pc) = (g.num(target), g.num(pc));
                    g.fb.ins()
                        .store(g.flags, pc, g.ctx, offset_of!(JitCtx, last_jump) as i32);
                    let code = g.fb.ins().iadd_imm_s(target, 1);
                    g.fb.ins().return_(&[code]);
                    let dead = g.fb.create_block();
                    g.fb.switch_to_block(dead);
                });
            }
            X::Ton(_) => self.ton(),
            X::Ctu(_) => self.count(true),
            X::Ctd(_) => self.count(false),
            X::EqI(..) | X::NeI(..) | X::LtI(..) | X::GtI(..) | X::LeI(..) | X::GeI(..) => {
                let cc = match op {
                    X::EqI(..) => IntCC::Equal,
                    X::NeI(..) => IntCC::NotEqual,
                    X::LtI(..) => IntCC::SignedLessThan,
                    X::GtI(..) => IntCC::SignedGreaterThan,
                    X::LeI(..) => IntCC::SignedLessThanOrEqual,
                    _ => IntCC::SignedGreaterThanOrEqual,
                };
                let a = self.slot();
                let b = self.slot();
                let x = self.ld32(a, 0);
                let y = self.ld32(b, 0);
                let c = self.fb.ins().icmp(cc, x, y);
                self.and_rc(c);
            }
            X::AddI(..) | X::SubI(..) => {
                let (a, b, d) = (self.slot(), self.slot(), self.slot());
                let pc = self.number();
                let rc = self.rc();
                self.when(rc, |g| {
                    let x = g.ld32(a, 0);
                    let y = g.ld32(b, 0);
                    let (v, of) = if matches!(op, X::AddI(..)) {
                        g.fb.ins().sadd_overflow(x, y)
                    } else {
                        g.fb.ins().ssub_overflow(x, y)
                    };
                    // Wrapped, with an overflow fault (as `exec`).
                    g.st32(d, 0, v);
                    g.fault_if(of, FaultCode::Overflow, pc);
                });
            }
            // A REAL move copies 32 bits as an integer: the same bits as the interpreter's copy.
            X::MovI(..) | X::MovF(..) => {
                let (a, d) = (self.slot(), self.slot());
                let rc = self.rc();
                self.when(rc, |g| {
                    let v = g.ld32(a, 0);
                    g.st32(d, 0, v);
                });
            }
            X::CopyI(..) => {
                let (a, d) = (self.slot(), self.slot());
                let v = self.ld32(a, 0);
                self.st32(d, 0, v);
            }
            X::CopyB(..) => {
                let (a, d) = (self.slot(), self.slot());
                let v = self.ld8(a, 0);
                self.st8(d, 0, v);
            }
            X::Pid(_) => {
                // One direct call; the rung condition is unchanged.
                let (f, i, b) = (self.slot(), self.slot(), self.slot());
                let (f, i, b) = (self.addr_value(f), self.addr_value(i), self.addr_value(b));
                let pc = self.number();
                let pc = self.num(pc);
                let rc = self.rc();
                let rc32 = self.fb.ins().uextend(types::I32, rc);
                let call = self.fb.ins().iconst(self.ptr, pid_call as *const () as i64);
                self.fb
                    .ins()
                    .call_indirect(self.pid_sig, call, &[self.ctx, f, i, b, pc, rc32]);
            }
            // `shape` sends everything else to the interpreter.
            _ => {}
        }
    }

    /// TON, as `exec/timers.rs`'s `ton`, with the interpreter's branches (a
    /// timer's path repeats from scan to scan, so they predict well; each
    /// field is stored at most once). A negative preset on a true rung
    /// counts as 0, with a fault.
    fn ton(&mut self) {
        let (iv, bv) = (self.slot(), self.slot());
        let pc = self.number();
        let rc = self.rc();
        let (on, off, join) = (self.fb.create_block(), self.fb.create_block(), self.fb.create_block());
        self.fb.ins().brif(rc, on, &[], off, &[]);
        // Rung false: everything cleared, LAST kept. Out of line (as the
        // first true scan): the paths that repeat scan after scan fall through.
        self.fb.set_cold_block(off);
        self.fb.switch_to_block(off);
        let (zero8, zero) = (self.c8(0), self.c32(0));
        for o in [EN, TT, DN] {
            self.st8(bv, o, zero8);
        }
        self.st32(iv, ACC, zero);
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(on);
        let pre = self.ld32(iv, PRE);
        let negative = self.fb.ins().icmp_imm_s(IntCC::SignedLessThan, pre, 0);
        let pre = self.fault_if_else(negative, FaultCode::NegativePreset, pc, pre, 0);
        let en = self.ld8(bv, EN);
        let dn = self.ld8(bv, DN);
        let (first, enabled, timing, done) = (
            self.fb.create_block(),
            self.fb.create_block(),
            self.fb.create_block(),
            self.fb.create_block(),
        );
        self.fb.ins().brif(en, enabled, &[], first, &[]);
        // The first true scan: ACC from 0, done at once if PRE is 0.
        self.fb.set_cold_block(first);
        self.fb.switch_to_block(first);
        let one = self.c8(1);
        self.st8(bv, EN, one);
        let now = self.now();
        self.st32(iv, LAST, now);
        let zero = self.c32(0);
        self.st32(iv, ACC, zero);
        let at_zero = self.fb.ins().icmp_imm_s(IntCC::Equal, pre, 0);
        let dn1 = self.or(dn, at_zero);
        self.st8(bv, DN, dn1);
        let tt = self.not(dn1);
        self.st8(bv, TT, tt);
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(enabled);
        self.fb.ins().brif(dn, done, &[], timing, &[]);
        // Done: ACC stays at PRE.
        self.fb.switch_to_block(done);
        let zero8 = self.c8(0);
        self.st8(bv, TT, zero8);
        self.fb.ins().jump(join, &[]);
        // Timing: ACC + the clock time since the last update, saturating;
        // DN at PRE, ACC stopping there.
        self.fb.switch_to_block(timing);
        let acc = self.ld32(iv, ACC);
        let last = self.ld32(iv, LAST);
        let now = self.now();
        self.st32(iv, LAST, now);
        let dt = self.fb.ins().isub(now, last);
        let max = self.c32(i32::MAX as i64);
        let dt = self.fb.ins().umin(dt, max);
        // A sum past i32::MAX saturates there, which is at or past PRE.
        let (sum, of) = self.fb.ins().sadd_overflow(acc, dt);
        let at_pre = self.fb.ins().icmp(IntCC::SignedGreaterThanOrEqual, sum, pre);
        let reached = self.or(of, at_pre);
        let acc = self.fb.ins().select(reached, pre, sum);
        self.st32(iv, ACC, acc);
        self.st8(bv, DN, reached);
        let tt = self.not(reached);
        self.st8(bv, TT, tt);
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(join);
    }

    /// CTU / CTD, as `exec/timers.rs`'s `count`: count on the rising rung; a wrap past
    /// the 32-bit range sets OV (up) or UN (down), or clears the other one.
    fn count(&mut self, up: bool) {
        let (iv, bv) = (self.slot(), self.slot());
        let (edge_o, dn_o) = (if up { 0 } else { 1 }, 2);
        let (set_o, clear_o) = if up { (3, 4) } else { (4, 3) };
        let rc = self.rc();
        let edge = self.ld8(bv, edge_o);
        let nedge = self.not(edge);
        let rising = self.and(rc, nedge);
        let acc = self.ld32(iv, ACC);
        let pre = self.ld32(iv, PRE);
        let (counts, same, after) = (self.fb.create_block(), self.fb.create_block(), self.fb.create_block());
        self.fb.ins().brif(rising, counts, &[], same, &[]);
        // DN on each path (no value merged after them: fewer register moves).
        self.fb.switch_to_block(same);
        let dn = self.fb.ins().icmp(IntCC::SignedGreaterThanOrEqual, acc, pre);
        self.st8(bv, dn_o, dn);
        self.fb.ins().jump(after, &[]);
        // Counting (once per rising edge) out of line.
        self.fb.set_cold_block(counts);
        self.fb.switch_to_block(counts);
        let one = self.c32(1);
        let (next, wraps) = if up {
            self.fb.ins().sadd_overflow(acc, one)
        } else {
            self.fb.ins().ssub_overflow(acc, one)
        };
        self.st32(iv, ACC, next);
        let dn = self.fb.ins().icmp(IntCC::SignedGreaterThanOrEqual, next, pre);
        self.st8(bv, dn_o, dn);
        let wrap = self.fb.create_block();
        self.fb.ins().brif(wraps, wrap, &[], after, &[]);
        self.fb.set_cold_block(wrap);
        self.fb.switch_to_block(wrap);
        let clear = self.ld8(bv, clear_o);
        let set = self.ld8(bv, set_o);
        let nclear = self.not(clear);
        let set1 = self.or(set, nclear);
        self.st8(bv, set_o, set1);
        let zero = self.c8(0);
        self.st8(bv, clear_o, zero);
        self.fb.ins().jump(after, &[]);
        self.fb.switch_to_block(after);
        self.st8(bv, edge_o, rc);
    }
}

// The fields of a timer or counter (as in `exec/timers.rs`): integer slots
// from its `i`, bool slots from its `b`.
const PRE: i32 = 0;
const ACC: i32 = 1;
const LAST: i32 = 2;
const EN: i32 = 0;
const TT: i32 = 1;
const DN: i32 = 2;
