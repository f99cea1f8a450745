//! Native code for unmonitored scans, with Cranelift.
//!
//! Programs are compiled rung by rung, by *shape*: the sequence of ops of a
//! rung with their slot numbers taken out. Each distinct shape becomes one
//! machine-code function that reads the slots of the rung it runs from an
//! operand table, so a program of 10 000 similar rungs is a handful of small
//! functions and a table, not megabytes of straight-line code; a scan is one
//! predictable call per rung.
//!
//! Only the ops that dominate typical ladder are emitted inline: contacts,
//! coils, one-shots, branches, jumps, TON, CTU/CTD, integer compares and
//! ADD/SUB/MOV of DINTs, with their rare cases too (a wrapped sum, a negative
//! preset, a counter wrapping to OV/UN); their faults are noted in the
//! context and flushed into `Faults` in order. Every other op is a call to
//! the interpreter's own `step` for that single op, so most semantics are
//! written once (`exec/`), and the inline ones are held to the interpreter
//! by differential tests.
//!
//! Unsafe code here has one reason: running machine code we generate. It
//! touches memory only at slot indices taken from a program that passed
//! `Program::verify`, in memory whose sizes `run` checks first.
#![allow(unsafe_code)]

use crate::exec::{self, Code, Stop, X};
use crate::fault::{FaultCode, Faults};
use crate::mem::{Mem, Sink};
use alba_ir::Memory;
use alba_ir::op::{PID_B_SLOTS, PID_F_SLOTS, PID_I_SLOTS};
use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{AbiParam, InstBuilder, MemFlagsData, SigRef, Signature, Type, Value, types};
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
    ops: *const X,
    n_ops: usize,
    src: *const u32,
    n_src: usize,
    faults: *mut Faults,
}

impl JitCtx {
    /// Moves the faults inline code noted into `faults`, in order.
    fn flush_faults(&mut self) {
        if self.fault_n == 0 {
            return;
        }
        // SAFETY: `faults` and `src` come from live borrows held by `Jit::run`.
        let (faults, src) = unsafe { (&mut *self.faults, std::slice::from_raw_parts(self.src, self.n_src)) };
        let at = |[code, pc]: [u32; 2]| {
            let code = FaultCode::from_i32(code as i32).unwrap_or(FaultCode::Overflow);
            (code, src.get(pc as usize).copied().unwrap_or(pc))
        };
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
    let (mut m, ops, src, faults) = unsafe {
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
            std::slice::from_raw_parts(ctx.src, ctx.n_src),
            &mut *ctx.faults,
        )
    };
    let Some(&op) = ops.get(pc as usize) else { return rc };
    let mut sink = Sink { faults, src };
    u32::from(exec::step(op, &mut m, &mut sink, ctx.now, pc as usize, rc != 0))
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
    let (f, i, b, faults, src) = unsafe {
        (
            std::slice::from_raw_parts_mut(f, PID_F_SLOTS as usize),
            std::slice::from_raw_parts_mut(i, PID_I_SLOTS as usize),
            std::slice::from_raw_parts_mut(b, PID_B_SLOTS as usize),
            &mut *ctx.faults,
            std::slice::from_raw_parts(ctx.src, ctx.n_src),
        )
    };
    let mut sink = Sink { faults, src };
    crate::pid::pid_on(f, i, b, rc != 0, ctx.now, &mut sink, pc as usize);
}

/// A shape function: `(ctx, operands, count)` runs `count` consecutive
/// rungs of its shape, whose operands follow each other from `operands`, and
/// returns 0 to go on after them, or `target + 1` when a JMP to rung
/// `target` is taken.
type ShapeFn = unsafe extern "C" fn(*mut JitCtx, *const u64, usize) -> u32;

/// Consecutive rungs of one shape.
struct Run {
    f: ShapeFn,
    first_rung: usize,
    rungs: usize,
    /// Where the operands of its first rung start, and how many each rung has.
    operands: usize,
    stride: usize,
}

/// A program compiled to machine code.
pub struct Jit {
    module: Option<JITModule>,
    runs: Vec<Run>,
    /// The run of each rung.
    run_of: Vec<u32>,
    /// The op where each rung starts.
    starts: Vec<u32>,
    operands: std::cell::RefCell<Operands>,
    /// Distinct shapes compiled.
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
            self.run_of.len(),
            self.runs.len(),
            self.shapes
        )
    }
}

fn err(e: impl std::fmt::Display) -> String {
    format!("native compilation failed: {e}")
}

/// An operand of a rung: a slot (whose address goes in the table) or a
/// number (an op index for the interpreter, a rung index for a jump).
#[derive(Debug, Clone, Copy)]
enum Operand {
    Bool(u32),
    Int(u32),
    Float(u32),
    Number(u32),
}

/// The operands of every rung, and their values for the memory they were
/// last resolved against (slot addresses are absolute, so generated code
/// needs no base registers).
#[derive(Debug, Default)]
struct Operands {
    items: Vec<Operand>,
    values: Vec<u64>,
    /// Addresses of the bool, integer and REAL arrays `values` was made for.
    bases: (usize, usize, usize),
}

impl Operands {
    fn push(&mut self, o: Operand) {
        self.items.push(o);
    }

    fn extend<const N: usize>(&mut self, os: [Operand; N]) {
        self.items.extend(os);
    }

    fn len(&self) -> usize {
        self.items.len()
    }

    /// Resolves slot operands against memory at these addresses.
    fn rebase(&mut self, b: *mut bool, i: *mut i32, f: *mut f32) {
        let bases = (b as usize, i as usize, f as usize);
        if self.bases == bases && self.values.len() == self.items.len() {
            return;
        }
        self.values = self
            .items
            .iter()
            .map(|o| match *o {
                Operand::Bool(s) => (bases.0 + s as usize) as u64,
                Operand::Int(s) => (bases.1 + 4 * s as usize) as u64,
                Operand::Float(s) => (bases.2 + 4 * s as usize) as u64,
                Operand::Number(n) => u64::from(n),
            })
            .collect();
        self.bases = bases;
    }
}

/// The shape of an op: the op with every slot number zeroed, or `None` for
/// ops left to the interpreter. Its operands go to the table. Branch ops
/// need none: their state lives in registers.
fn shape(op: X, pc: usize, rung_of: &HashMap<u32, u32>, table: &mut Operands) -> Option<X> {
    use alba_ir::{B, Ctr, I, Tmr};
    let (b0, i0) = (B(0), I(0));
    let out = table;
    let bo = |b: B| Operand::Bool(b.0);
    let io = |i: I| Operand::Int(i.0);
    let fo = |f: alba_ir::F| Operand::Float(f.0);
    let pc = Operand::Number(pc as u32);
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
            out.extend([Operand::Number(rung_of.get(&t).copied().unwrap_or(u32::MAX)), pc]);
            X::Jmp(0)
        }
        X::Ton(t) => {
            out.extend([io(t.i), bo(t.b), pc]);
            X::Ton(Tmr { i: i0, b: b0 })
        }
        X::Ctu(c) | X::Ctd(c) => {
            out.extend([io(c.i), bo(c.b), pc]);
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

impl Jit {
    /// Compiles unfused code. Fails on hosts Cranelift does not support.
    pub fn compile(code: &Code) -> Result<Jit, String> {
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

        let mut sig = module.make_signature();
        sig.params.push(AbiParam::new(ptr));
        sig.params.push(AbiParam::new(ptr));
        sig.params.push(AbiParam::new(ptr));
        sig.returns.push(AbiParam::new(types::I32));
        let mut shapes: HashMap<Vec<Option<X>>, cranelift_module::FuncId> = HashMap::new();
        let mut runs: Vec<(cranelift_module::FuncId, usize, usize, usize, usize)> = Vec::new();
        let mut run_of = Vec::with_capacity(starts.len());
        let mut operands = Operands::default();
        let mut ctx = module.make_context();
        let mut fctx = FunctionBuilderContext::new();
        for (r, &start) in starts.iter().enumerate() {
            let end = starts.get(r + 1).copied().unwrap_or(code.ops.len());
            let offset = operands.len();
            let key: Vec<Option<X>> = (start..end)
                .map(|pc| shape(code.ops[pc], pc, &rung_of, &mut operands))
                .collect();
            let stride = operands.len() - offset;
            let id = match shapes.get(&key) {
                Some(&id) => id,
                None => {
                    let id = module
                        .declare_function(&format!("alba_shape_{}", shapes.len()), Linkage::Local, &sig)
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
                        Gen::new(&mut fb, ptr, fallback_sig, pid_sig).emit(&key, stride);
                        fb.seal_all_blocks();
                        fb.finalize(module.target_config());
                    }
                    module.define_function(id, &mut ctx).map_err(err)?;
                    module.clear_context(&mut ctx);
                    shapes.insert(key, id);
                    id
                }
            };
            match runs.last_mut() {
                Some((rid, _, count, _, rstride)) if *rid == id && *rstride == stride => *count += 1,
                _ => runs.push((id, r, 1, offset, stride)),
            }
            run_of.push((runs.len() - 1) as u32);
        }
        module.finalize_definitions().map_err(err)?;
        let runs = runs
            .into_iter()
            .map(|(id, first_rung, rungs, operands, stride)| {
                let raw = module.get_finalized_function(id);
                // SAFETY: `raw` is a function defined above with signature
                // `fn(ptr, ptr, ptr) -> i32` in the system calling convention.
                let f = unsafe { std::mem::transmute::<*const u8, ShapeFn>(raw) };
                Run {
                    f,
                    first_rung,
                    rungs,
                    operands,
                    stride,
                }
            })
            .collect();
        Ok(Jit {
            module: Some(module),
            runs,
            run_of,
            starts: starts.iter().map(|&s| s as u32).collect(),
            operands: std::cell::RefCell::new(operands),
            shapes: shapes.len(),
        })
    }

    /// Bytes of the operand table and the run index.
    pub fn table_bytes(&self) -> usize {
        let t = self.operands.borrow();
        t.items.len() * std::mem::size_of::<Operand>()
            + t.values.len() * 8
            + self.run_of.len() * 4
            + self.starts.len() * 4
            + self.runs.len() * std::mem::size_of::<Run>()
    }

    /// Runs one scan of the compiled code over `mem`.
    pub(crate) fn run(&self, code: &Code, mem: &mut Memory, faults: &mut Faults, now: u32) -> Result<(), Stop> {
        if !code.fits(mem) {
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
            ops: code.ops.as_ptr(),
            n_ops: code.ops.len(),
            src: code.src.as_ptr(),
            n_src: code.src.len(),
            faults,
        };
        let mut table = self.operands.borrow_mut();
        table.rebase(ctx.b, ctx.i, ctx.f);
        let mut r = 0usize;
        let mut backward = 0u32;
        while let Some(&run) = self.run_of.get(r) {
            let run = &self.runs[run as usize];
            let skip = r - run.first_rung;
            let operands = table.values[run.operands + skip * run.stride..].as_ptr();
            // SAFETY: `run.f` was generated for the shape of these rungs,
            // whose operands follow from `operands`, `stride` per rung; it
            // uses `ctx` only during the call.
            let next = unsafe { (run.f)(&mut ctx, operands, run.rungs - skip) };
            ctx.flush_faults();
            if next == 0 {
                r = run.first_rung + run.rungs;
                continue;
            }
            let target = next as usize - 1;
            let from = self.starts.partition_point(|&s| s <= ctx.last_jump).saturating_sub(1);
            if target <= from {
                backward += 1;
                if backward > exec::BACKWARD_JUMP_LIMIT {
                    let pc = ctx.last_jump as usize;
                    return Err(Stop::Runaway(code.src.get(pc).copied().unwrap_or(0)));
                }
            }
            r = target;
        }
        Ok(())
    }
}

/// Code generation for one rung shape.
struct Gen<'a, 'b> {
    fb: &'a mut FunctionBuilder<'b>,
    ptr: Type,
    fallback_sig: SigRef,
    pid_sig: SigRef,
    ctx: Value,
    /// Operands of the rung being generated, and the next one to read.
    operands: Variable,
    next: i32,
    now: Value,
    rc: Variable,
    /// Open branches: (rung state at the branch, OR of the legs so far).
    branches: Vec<(Variable, Variable)>,
    flags: MemFlagsData,
}

impl<'a, 'b> Gen<'a, 'b> {
    fn new(fb: &'a mut FunctionBuilder<'b>, ptr: Type, fallback_sig: SigRef, pid_sig: SigRef) -> Self {
        let entry = fb.create_block();
        fb.append_block_params_for_function_params(entry);
        fb.switch_to_block(entry);
        let ctx = fb.block_params(entry)[0];
        let flags = MemFlagsData::trusted();
        let now = fb.ins().load(types::I32, flags, ctx, offset_of!(JitCtx, now) as i32);
        let rc = fb.declare_var(types::I8);
        let one = fb.ins().iconst(types::I8, 1);
        fb.def_var(rc, one);
        let operands = fb.declare_var(ptr);
        Gen {
            fb,
            ptr,
            fallback_sig,
            pid_sig,
            ctx,
            operands,
            next: 0,
            now,
            rc,
            branches: Vec::new(),
            flags,
        }
    }

    /// The next operand (a byte offset, an op index or a rung index).
    fn operand(&mut self) -> Value {
        let base = self.fb.use_var(self.operands);
        let v = self.fb.ins().load(types::I64, self.flags, base, self.next * 8);
        self.next += 1;
        v
    }

    /// The next operand as a 32-bit number.
    fn operand32(&mut self) -> Value {
        let v = self.operand();
        self.fb.ins().ireduce(types::I32, v)
    }

    /// Address of the bool slot named by the next operand.
    fn b_addr(&mut self) -> Value {
        self.operand()
    }

    /// Address of the integer slot named by the next operand.
    fn i_addr(&mut self) -> Value {
        self.operand()
    }

    fn ld8(&mut self, addr: Value, off: i32) -> Value {
        self.fb.ins().load(types::I8, self.flags, addr, off)
    }
    fn st8(&mut self, addr: Value, off: i32, v: Value) {
        self.fb.ins().store(self.flags, v, addr, off);
    }
    fn ld32(&mut self, addr: Value, off: i32) -> Value {
        self.fb.ins().load(types::I32, self.flags, addr, off * 4)
    }
    fn st32(&mut self, addr: Value, off: i32, v: Value) {
        self.fb.ins().store(self.flags, v, addr, off * 4);
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
    fn not(&mut self, v: Value) -> Value {
        self.fb.ins().bxor_imm_u(v, 1)
    }
    fn and(&mut self, a: Value, b: Value) -> Value {
        self.fb.ins().band(a, b)
    }
    fn or(&mut self, a: Value, b: Value) -> Value {
        self.fb.ins().bor(a, b)
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
    fn fault_if(&mut self, cond: Value, code: FaultCode, pc: Value) {
        let cold = self.fb.create_block();
        let join = self.fb.create_block();
        self.fb.ins().brif(cond, cold, &[], join, &[]);
        self.fb.set_cold_block(cold);
        self.fb.switch_to_block(cold);
        let f = self.flags;
        let n = self
            .fb
            .ins()
            .load(types::I32, f, self.ctx, offset_of!(JitCtx, fault_n) as i32);
        let code = self.c32(code as i64);
        let first = self.fb.create_block();
        let rest = self.fb.create_block();
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
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(join);
    }

    /// The function: a loop over `count` rungs of this shape.
    fn emit(mut self, shape: &[Option<X>], stride: usize) {
        let entry = self.fb.current_block().unwrap_or_else(|| self.fb.create_block());
        let params = self.fb.block_params(entry).to_vec();
        let (first, count) = (params[1], params[2]);
        let left = self.fb.declare_var(self.ptr);
        self.fb.def_var(self.operands, first);
        self.fb.def_var(left, count);
        let head = self.fb.create_block();
        let body = self.fb.create_block();
        let done = self.fb.create_block();
        self.fb.ins().jump(head, &[]);
        self.fb.switch_to_block(head);
        let n = self.fb.use_var(left);
        self.fb.ins().brif(n, body, &[], done, &[]);
        self.fb.switch_to_block(body);
        self.next = 0;
        for op in shape {
            match op {
                Some(op) => self.op(*op),
                None => {
                    let pc = self.operand32();
                    self.call_fallback(pc);
                }
            }
        }
        let base = self.fb.use_var(self.operands);
        let following = self.fb.ins().iadd_imm_s(base, (stride * 8) as i64);
        self.fb.def_var(self.operands, following);
        let n = self.fb.use_var(left);
        let n1 = self.fb.ins().iadd_imm_s(n, -1);
        self.fb.def_var(left, n1);
        self.fb.ins().jump(head, &[]);
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
                let a = self.b_addr();
                let v = self.ld8(a, 0);
                let v = if matches!(op, X::Xio(_)) { self.not(v) } else { v };
                self.and_rc(v);
            }
            X::Ote(_) => {
                let a = self.b_addr();
                let rc = self.rc();
                self.st8(a, 0, rc);
            }
            // The logic stack of Instruction List.
            X::Ld(_) | X::Ldn(_) | X::Or(_) | X::Orn(_) => {
                let a = self.b_addr();
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
                let a = self.b_addr();
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
                let a = self.b_addr();
                let sv = self.ld8(a, 0);
                let rc = self.rc();
                let nsv = self.not(sv);
                let out = self.and(rc, nsv);
                self.st8(a, 0, rc);
                self.set_rc(out);
            }
            X::Osr(..) | X::Osf(..) => {
                let s = self.b_addr();
                let o = self.b_addr();
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
            X::Jmp(_) => {
                let target = self.operand32();
                let pc = self.operand32();
                let rc = self.rc();
                self.when(rc, |g| {
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
                let a = self.i_addr();
                let b = self.i_addr();
                let x = self.ld32(a, 0);
                let y = self.ld32(b, 0);
                let c = self.fb.ins().icmp(cc, x, y);
                self.and_rc(c);
            }
            X::AddI(..) | X::SubI(..) => {
                let a = self.i_addr();
                let b = self.i_addr();
                let d = self.i_addr();
                let pc = self.operand32();
                let rc = self.rc();
                // Without a branch on the rung (shared by every rung of the
                // shape, it would mispredict): keep the old value when false.
                let x = self.ld32(a, 0);
                let y = self.ld32(b, 0);
                let old = self.ld32(d, 0);
                let (v, of) = if matches!(op, X::AddI(..)) {
                    self.fb.ins().sadd_overflow(x, y)
                } else {
                    self.fb.ins().ssub_overflow(x, y)
                };
                // Wrapped, with an overflow fault (as `exec`).
                let v = self.fb.ins().select(rc, v, old);
                self.st32(d, 0, v);
                let fault = self.and(rc, of);
                self.fault_if(fault, FaultCode::Overflow, pc);
            }
            X::MovI(..) => {
                let a = self.i_addr();
                let d = self.i_addr();
                let rc = self.rc();
                let v = self.ld32(a, 0);
                let old = self.ld32(d, 0);
                let v = self.fb.ins().select(rc, v, old);
                self.st32(d, 0, v);
            }
            X::CopyI(..) => {
                let a = self.i_addr();
                let d = self.i_addr();
                let v = self.ld32(a, 0);
                self.st32(d, 0, v);
            }
            X::MovF(..) => {
                // 32 bits moved as an integer: the same bits as the interpreter's copy.
                let a = self.i_addr();
                let d = self.i_addr();
                let rc = self.rc();
                let v = self.ld32(a, 0);
                let old = self.ld32(d, 0);
                let v = self.fb.ins().select(rc, v, old);
                self.st32(d, 0, v);
            }
            X::Pid(_) => {
                // One direct call; the rung condition is unchanged.
                let (f, i, b) = (self.operand(), self.operand(), self.operand());
                let pc = self.operand32();
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

    /// TON, as `exec/timers.rs`'s `ton`, without branches: every field is loaded once,
    /// computed for both rung states and stored once. A negative preset on a
    /// true rung counts as 0, with a fault.
    fn ton(&mut self) {
        let iv = self.i_addr();
        let bv = self.b_addr();
        let pc = self.operand32();
        let rc = self.rc();
        let pre = self.ld32(iv, 0);
        let zero = self.c32(0);
        let negative = self.fb.ins().icmp_imm_s(IntCC::SignedLessThan, pre, 0);
        let bad = self.and(rc, negative);
        self.fault_if(bad, FaultCode::NegativePreset, pc);
        let pre = self.fb.ins().smax(pre, zero);
        let en = self.ld8(bv, 0);
        let dn = self.ld8(bv, 2);
        let acc = self.ld32(iv, 1);
        let last = self.ld32(iv, 2);
        let first = self.not(en);
        let ndn = self.not(dn);
        let timing = self.and(en, ndn);
        // ACC + time since the last update, saturating.
        let dt = self.fb.ins().isub(self.now, last);
        let max = self.c32(i32::MAX as i64);
        let dt = self.fb.ins().umin(dt, max);
        let (sum, of) = self.fb.ins().sadd_overflow(acc, dt);
        let advanced = self.fb.ins().select(of, max, sum);
        let acc1 = self.fb.ins().select(timing, advanced, acc);
        let acc1 = self.fb.ins().select(first, zero, acc1);
        let moved = self.or(first, timing);
        let last1 = self.fb.ins().select(moved, self.now, last);
        let reached = self.fb.ins().icmp(IntCC::SignedGreaterThanOrEqual, acc1, pre);
        let done = self.and(ndn, reached);
        let acc2 = self.fb.ins().select(done, pre, acc1);
        let dn1 = self.or(dn, done);
        // Rung false: everything cleared, LAST kept.
        let acc_out = self.fb.ins().select(rc, acc2, zero);
        let last_out = self.fb.ins().select(rc, last1, last);
        let dn_out = self.and(rc, dn1);
        let ndn1 = self.not(dn1);
        let tt_out = self.and(rc, ndn1);
        self.st8(bv, 0, rc);
        self.st8(bv, 1, tt_out);
        self.st8(bv, 2, dn_out);
        self.st32(iv, 1, acc_out);
        self.st32(iv, 2, last_out);
    }

    /// CTU / CTD, as `exec/timers.rs`'s `count`: count on the rising rung; a wrap past
    /// the 32-bit range sets OV (up) or UN (down), or clears the other one.
    fn count(&mut self, up: bool) {
        let iv = self.i_addr();
        let bv = self.b_addr();
        let _pc = self.operand32();
        let (edge_o, dn_o) = (if up { 0 } else { 1 }, 2);
        let (set_o, clear_o) = if up { (3, 4) } else { (4, 3) };
        let rc = self.rc();
        let edge = self.ld8(bv, edge_o);
        let nedge = self.not(edge);
        let rising = self.and(rc, nedge);
        let acc = self.ld32(iv, 1);
        let step = if up { 1 } else { -1 };
        let next = self.fb.ins().iadd_imm_s(acc, step);
        let acc1 = self.fb.ins().select(rising, next, acc);
        self.st32(iv, 1, acc1);
        let limit = if up { i32::MAX as i64 } else { i32::MIN as i64 };
        let at_limit = self.fb.ins().icmp_imm_s(IntCC::Equal, acc, limit);
        let wraps = self.and(rising, at_limit);
        self.when(wraps, |g| {
            let clear = g.ld8(bv, clear_o);
            let set = g.ld8(bv, set_o);
            let nclear = g.not(clear);
            let set1 = g.or(set, nclear);
            g.st8(bv, set_o, set1);
            let zero = g.c8(0);
            g.st8(bv, clear_o, zero);
        });
        self.st8(bv, edge_o, rc);
        let pre = self.ld32(iv, 0);
        let dn = self.fb.ins().icmp(IntCC::SignedGreaterThanOrEqual, acc1, pre);
        self.st8(bv, dn_o, dn);
    }
}
