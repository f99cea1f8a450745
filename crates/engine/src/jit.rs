//! Native code for unmonitored scans, with Cranelift.
//!
//! The JIT translates the unfused executable code ([`Code`]) into one
//! machine-code function per program. Only the ops that dominate typical
//! ladder are emitted inline: contacts, coils, one-shots, branches, jumps,
//! TON, CTU/CTD, integer compares, ADD/SUB/MOV of DINTs. Each inline op
//! first tests for its rare cases (overflow, a negative preset, a counter
//! about to wrap) and hands those to the interpreter. Every other op is a
//! call to the interpreter's own `step` for that single op. So the
//! semantics stay where they are defined (`exec.rs`), and the inline fast
//! paths are checked against the interpreter by differential tests.
//!
//! Unsafe code here has one reason: running machine code we generate. The
//! code only touches memory at slot indices of a program that passed
//! `Program::verify`, in memory whose sizes `run` checks first.
#![allow(unsafe_code)]

use crate::exec::{self, Code, Mem, Sink, Stop, X};
use crate::fault::Faults;
use alba_ir::Memory;
use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{AbiParam, Block, InstBuilder, MemFlagsData, Signature, Type, Value, types};
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
    ops: *const X,
    n_ops: usize,
    src: *const u32,
    n_src: usize,
    faults: *mut Faults,
}

/// Runs one op in the interpreter on behalf of generated code.
extern "C" fn fallback(ctx: *mut JitCtx, pc: u32, rc: u32) -> u32 {
    // SAFETY: generated code calls this only from `Jit::run`, passing the
    // context `run` built from live, exclusive borrows; while this runs the
    // generated code is suspended, so these are the only references.
    let ctx = unsafe { &mut *ctx };
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

/// A program compiled to machine code.
pub struct Jit {
    module: Option<JITModule>,
    func: unsafe extern "C" fn(*mut JitCtx) -> u32,
}

impl Drop for Jit {
    fn drop(&mut self) {
        if let Some(m) = self.module.take() {
            // SAFETY: `func` points into this module and dies with `self`.
            unsafe { m.free_memory() };
        }
    }
}

impl std::fmt::Debug for Jit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Jit")
    }
}

fn err(e: impl std::fmt::Display) -> String {
    format!("native compilation failed: {e}")
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
        let mut ctx = module.make_context();
        let mut sig = module.make_signature();
        sig.params.push(AbiParam::new(ptr));
        sig.returns.push(AbiParam::new(types::I32));
        ctx.func.signature = sig.clone();
        let id = module.declare_function("alba_scan", Linkage::Local, &sig).map_err(err)?;
        let mut fctx = FunctionBuilderContext::new();
        {
            let mut fb = FunctionBuilder::new(&mut ctx.func, &mut fctx);
            let mut fallback_sig = Signature::new(module.isa().default_call_conv());
            fallback_sig.params.push(AbiParam::new(ptr));
            fallback_sig.params.push(AbiParam::new(types::I32));
            fallback_sig.params.push(AbiParam::new(types::I32));
            fallback_sig.returns.push(AbiParam::new(types::I32));
            let fallback_sig = fb.import_signature(fallback_sig);
            Gen::new(&mut fb, ptr, fallback_sig).emit(&code.ops);
            fb.seal_all_blocks();
            fb.finalize(module.target_config());
        }
        module.define_function(id, &mut ctx).map_err(err)?;
        module.clear_context(&mut ctx);
        module.finalize_definitions().map_err(err)?;
        let raw = module.get_finalized_function(id);
        // SAFETY: `raw` is the function just defined with signature
        // `fn(ptr) -> i32` in the system calling convention.
        let func = unsafe { std::mem::transmute::<*const u8, unsafe extern "C" fn(*mut JitCtx) -> u32>(raw) };
        Ok(Jit {
            module: Some(module),
            func,
        })
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
            lens: [mem.b.len(), mem.i.len(), mem.f.len(), mem.l.len(), mem.d.len(), mem.m.len()],
            now,
            ops: code.ops.as_ptr(),
            n_ops: code.ops.len(),
            src: code.src.as_ptr(),
            n_src: code.src.len(),
            faults,
        };
        // SAFETY: the function was generated from `code` (verified, with
        // memory sizes checked above) and only uses `ctx` during the call.
        let r = unsafe { (self.func)(&mut ctx) };
        match r {
            0 => Ok(()),
            pc => Err(Stop::Runaway(code.src.get(pc as usize - 1).copied().unwrap_or(0))),
        }
    }
}

/// Code generation state for one function.
struct Gen<'a, 'b> {
    fb: &'a mut FunctionBuilder<'b>,
    ptr: Type,
    fallback_sig: cranelift_codegen::ir::SigRef,
    ctx: Value,
    base: [Value; 2],
    now: Value,
    rc: Variable,
    backward: Variable,
    flags: MemFlagsData,
}

const B: usize = 0;
const I: usize = 1;

impl<'a, 'b> Gen<'a, 'b> {
    fn new(fb: &'a mut FunctionBuilder<'b>, ptr: Type, fallback_sig: cranelift_codegen::ir::SigRef) -> Self {
        let entry = fb.create_block();
        fb.append_block_params_for_function_params(entry);
        fb.switch_to_block(entry);
        let ctx = fb.block_params(entry)[0];
        let flags = MemFlagsData::trusted();
        let b = fb.ins().load(ptr, flags, ctx, offset_of!(JitCtx, b) as i32);
        let i = fb.ins().load(ptr, flags, ctx, offset_of!(JitCtx, i) as i32);
        let now = fb.ins().load(types::I32, flags, ctx, offset_of!(JitCtx, now) as i32);
        let rc = fb.declare_var(types::I8);
        let backward = fb.declare_var(types::I32);
        let one = fb.ins().iconst(types::I8, 1);
        fb.def_var(rc, one);
        let zero = fb.ins().iconst(types::I32, 0);
        fb.def_var(backward, zero);
        Gen {
            fb,
            ptr,
            fallback_sig,
            ctx,
            base: [b, i],
            now,
            rc,
            backward,
            flags,
        }
    }

    fn ld_b(&mut self, slot: u32) -> Value {
        self.fb.ins().load(types::I8, self.flags, self.base[B], slot as i32)
    }
    fn st_b(&mut self, slot: u32, v: Value) {
        self.fb.ins().store(self.flags, v, self.base[B], slot as i32);
    }
    fn ld_i(&mut self, slot: u32) -> Value {
        self.fb.ins().load(types::I32, self.flags, self.base[I], (slot * 4) as i32)
    }
    fn st_i(&mut self, slot: u32, v: Value) {
        self.fb.ins().store(self.flags, v, self.base[I], (slot * 4) as i32);
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

    /// Calls the interpreter for op `pc`; the rung condition it returns
    /// becomes the current one.
    fn call_fallback(&mut self, pc: usize) {
        let f = self.fb.ins().iconst(self.ptr, fallback as *const () as i64);
        let pcv = self.c32(pc as i64);
        let rc = self.rc();
        let rc32 = self.fb.ins().uextend(types::I32, rc);
        let call = self.fb.ins().call_indirect(self.fallback_sig, f, &[self.ctx, pcv, rc32]);
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

    /// `if cond { fallback(pc) } else { fast() }` then continue.
    fn unless_rare(&mut self, rare: Value, pc: usize, fast: impl FnOnce(&mut Self)) {
        let slow = self.fb.create_block();
        let quick = self.fb.create_block();
        let join = self.fb.create_block();
        self.fb.ins().brif(rare, slow, &[], quick, &[]);
        self.fb.set_cold_block(slow);
        self.fb.switch_to_block(slow);
        self.call_fallback(pc);
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(quick);
        fast(self);
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(join);
    }

    fn emit(mut self, ops: &[X]) {
        // A block for every jump target.
        let mut targets: HashMap<u32, Block> = HashMap::new();
        for op in ops {
            if let X::Jmp(t) = op {
                let b = self.fb.create_block();
                targets.entry(*t).or_insert(b);
            }
        }
        let exit = self.fb.create_block();
        for (pc, &op) in ops.iter().enumerate() {
            if let Some(&b) = targets.get(&(pc as u32)) {
                self.fb.ins().jump(b, &[]);
                self.fb.switch_to_block(b);
            }
            self.op(pc, op, &targets, exit);
        }
        self.fb.ins().jump(exit, &[]);
        self.fb.switch_to_block(exit);
        let ok = self.c32(0);
        self.fb.ins().return_(&[ok]);
    }

    fn op(&mut self, pc: usize, op: X, targets: &HashMap<u32, Block>, exit: Block) {
        match op {
            X::End => {
                self.fb.ins().jump(exit, &[]);
                let dead = self.fb.create_block();
                self.fb.switch_to_block(dead);
            }
            X::Rung => {
                let one = self.c8(1);
                self.set_rc(one);
            }
            X::Nop => {}
            X::Afi => {
                let zero = self.c8(0);
                self.set_rc(zero);
            }
            X::Xic(b) => {
                let v = self.ld_b(b.0);
                let rc = self.rc();
                let r = self.fb.ins().band(rc, v);
                self.set_rc(r);
            }
            X::Xio(b) => {
                let v = self.ld_b(b.0);
                let nv = self.not(v);
                let rc = self.rc();
                let r = self.fb.ins().band(rc, nv);
                self.set_rc(r);
            }
            X::Ote(b) => {
                let rc = self.rc();
                self.st_b(b.0, rc);
            }
            X::Otl(b) => {
                let v = self.ld_b(b.0);
                let rc = self.rc();
                let r = self.fb.ins().bor(v, rc);
                self.st_b(b.0, r);
            }
            X::Otu(b) => {
                let v = self.ld_b(b.0);
                let rc = self.rc();
                let nrc = self.not(rc);
                let r = self.fb.ins().band(v, nrc);
                self.st_b(b.0, r);
            }
            X::Ons(s) => {
                let sv = self.ld_b(s.0);
                let rc = self.rc();
                let nsv = self.not(sv);
                let out = self.fb.ins().band(rc, nsv);
                self.st_b(s.0, rc);
                self.set_rc(out);
            }
            X::Osr(s, o) => {
                let sv = self.ld_b(s.0);
                let rc = self.rc();
                let nsv = self.not(sv);
                let out = self.fb.ins().band(rc, nsv);
                self.st_b(o.0, out);
                self.st_b(s.0, rc);
            }
            X::Osf(s, o) => {
                let sv = self.ld_b(s.0);
                let rc = self.rc();
                let nrc = self.not(rc);
                let out = self.fb.ins().band(nrc, sv);
                self.st_b(o.0, out);
                self.st_b(s.0, rc);
            }
            X::BrOpen { save, acc } => {
                let rc = self.rc();
                self.st_b(save.0, rc);
                let zero = self.c8(0);
                self.st_b(acc.0, zero);
            }
            X::BrNext { save, acc } => {
                let a = self.ld_b(acc.0);
                let rc = self.rc();
                let na = self.fb.ins().bor(a, rc);
                self.st_b(acc.0, na);
                let s = self.ld_b(save.0);
                self.set_rc(s);
            }
            X::BrClose { acc } => {
                let a = self.ld_b(acc.0);
                let rc = self.rc();
                let r = self.fb.ins().bor(rc, a);
                self.set_rc(r);
            }
            X::Jmp(t) => {
                let target = targets.get(&t).copied().unwrap_or(exit);
                let next = self.fb.create_block();
                let rc = self.rc();
                if (t as usize) <= pc {
                    // Backward: count, and stop a runaway loop.
                    let count = self.fb.create_block();
                    let runaway = self.fb.create_block();
                    self.fb.ins().brif(rc, count, &[], next, &[]);
                    self.fb.switch_to_block(count);
                    let n = self.fb.use_var(self.backward);
                    let n1 = self.fb.ins().iadd_imm_s(n, 1);
                    self.fb.def_var(self.backward, n1);
                    let over = self.fb.ins().icmp_imm_s(IntCC::UnsignedGreaterThan, n1, exec::BACKWARD_JUMP_LIMIT as i64);
                    self.fb.ins().brif(over, runaway, &[], target, &[]);
                    self.fb.set_cold_block(runaway);
                    self.fb.switch_to_block(runaway);
                    let code = self.c32(pc as i64 + 1);
                    self.fb.ins().return_(&[code]);
                } else {
                    self.fb.ins().brif(rc, target, &[], next, &[]);
                }
                self.fb.switch_to_block(next);
            }
            X::Ton(t) => self.ton(pc, t.i.0, t.b.0),
            X::Ctu(c) => self.count(pc, c.i.0, c.b.0, true),
            X::Ctd(c) => self.count(pc, c.i.0, c.b.0, false),
            X::EqI(a, b) => self.cmp_i(IntCC::Equal, a.0, b.0),
            X::NeI(a, b) => self.cmp_i(IntCC::NotEqual, a.0, b.0),
            X::LtI(a, b) => self.cmp_i(IntCC::SignedLessThan, a.0, b.0),
            X::GtI(a, b) => self.cmp_i(IntCC::SignedGreaterThan, a.0, b.0),
            X::LeI(a, b) => self.cmp_i(IntCC::SignedLessThanOrEqual, a.0, b.0),
            X::GeI(a, b) => self.cmp_i(IntCC::SignedGreaterThanOrEqual, a.0, b.0),
            X::AddI(a, b, d) | X::SubI(a, b, d) => {
                let add = matches!(op, X::AddI(..));
                let rc = self.rc();
                self.when(rc, |g| {
                    let x = g.ld_i(a.0);
                    let y = g.ld_i(b.0);
                    let (v, of) = if add { g.fb.ins().sadd_overflow(x, y) } else { g.fb.ins().ssub_overflow(x, y) };
                    g.unless_rare(of, pc, |g| g.st_i(d.0, v));
                });
            }
            X::MovI(a, d) => {
                let rc = self.rc();
                self.when(rc, |g| {
                    let v = g.ld_i(a.0);
                    g.st_i(d.0, v);
                });
            }
            X::CopyI(a, d) => {
                let v = self.ld_i(a.0);
                self.st_i(d.0, v);
            }
            // Everything else: the interpreter, one op at a time.
            _ => self.call_fallback(pc),
        }
    }

    fn cmp_i(&mut self, cc: IntCC, a: u32, b: u32) {
        let x = self.ld_i(a);
        let y = self.ld_i(b);
        let c = self.fb.ins().icmp(cc, x, y);
        let rc = self.rc();
        let r = self.fb.ins().band(rc, c);
        self.set_rc(r);
    }

    /// TON, as `exec::ton`; a negative preset goes to the interpreter.
    fn ton(&mut self, pc: usize, i: u32, b: u32) {
        let (pre_s, acc_s, last_s) = (i, i + 1, i + 2);
        let (en_s, tt_s, dn_s) = (b, b + 1, b + 2);
        let rc = self.rc();
        let on = self.fb.create_block();
        let off = self.fb.create_block();
        let join = self.fb.create_block();
        self.fb.ins().brif(rc, on, &[], off, &[]);

        self.fb.switch_to_block(off);
        let z8 = self.c8(0);
        self.st_b(en_s, z8);
        self.st_b(tt_s, z8);
        self.st_b(dn_s, z8);
        let z32 = self.c32(0);
        self.st_i(acc_s, z32);
        self.fb.ins().jump(join, &[]);

        self.fb.switch_to_block(on);
        let pre = self.ld_i(pre_s);
        let negative = self.fb.ins().icmp_imm_s(IntCC::SignedLessThan, pre, 0);
        self.unless_rare(negative, pc, |g| {
            let en = g.ld_b(en_s);
            let first = g.fb.create_block();
            let running = g.fb.create_block();
            let timing = g.fb.create_block();
            let check = g.fb.create_block();
            g.fb.ins().brif(en, running, &[], first, &[]);

            g.fb.switch_to_block(first);
            let one = g.c8(1);
            g.st_b(en_s, one);
            let z = g.c32(0);
            g.st_i(acc_s, z);
            g.st_i(last_s, g.now);
            g.fb.ins().jump(check, &[]);

            g.fb.switch_to_block(running);
            let dn = g.ld_b(dn_s);
            g.fb.ins().brif(dn, check, &[], timing, &[]);

            g.fb.switch_to_block(timing);
            let last = g.ld_i(last_s);
            let dt = g.fb.ins().isub(g.now, last);
            g.st_i(last_s, g.now);
            let max = g.c32(i32::MAX as i64);
            let dt = g.fb.ins().umin(dt, max);
            let acc = g.ld_i(acc_s);
            let (sum, of) = g.fb.ins().sadd_overflow(acc, dt);
            let acc = g.fb.ins().select(of, max, sum);
            g.st_i(acc_s, acc);
            g.fb.ins().jump(check, &[]);

            g.fb.switch_to_block(check);
            let dn = g.ld_b(dn_s);
            let acc = g.ld_i(acc_s);
            let reached = g.fb.ins().icmp(IntCC::SignedGreaterThanOrEqual, acc, pre);
            let ndn = g.not(dn);
            let set = g.fb.ins().band(ndn, reached);
            g.when(set, |g| {
                let one = g.c8(1);
                g.st_b(dn_s, one);
                g.st_i(acc_s, pre);
            });
            let dn = g.ld_b(dn_s);
            let tt = g.not(dn);
            g.st_b(tt_s, tt);
        });
        self.fb.ins().jump(join, &[]);
        self.fb.switch_to_block(join);
    }

    /// CTU / CTD, as `exec::count`; a count that would wrap goes to the interpreter.
    fn count(&mut self, pc: usize, i: u32, b: u32, up: bool) {
        let (pre_s, acc_s) = (i, i + 1);
        let edge_s = if up { b } else { b + 1 };
        let dn_s = b + 2;
        let rc = self.rc();
        let edge = self.ld_b(edge_s);
        let nedge = self.not(edge);
        let rising = self.fb.ins().band(rc, nedge);
        let acc = self.ld_i(acc_s);
        let limit = if up { i32::MAX as i64 } else { i32::MIN as i64 };
        let at_limit = self.fb.ins().icmp_imm_s(IntCC::Equal, acc, limit);
        let wraps = self.fb.ins().band(rising, at_limit);
        self.unless_rare(wraps, pc, |g| {
            let step = if up { 1 } else { -1 };
            let next = g.fb.ins().iadd_imm_s(acc, step);
            let acc = g.fb.ins().select(rising, next, acc);
            g.st_i(acc_s, acc);
            let rc = g.rc();
            g.st_b(edge_s, rc);
            let pre = g.ld_i(pre_s);
            let dn = g.fb.ins().icmp(IntCC::SignedGreaterThanOrEqual, acc, pre);
            g.st_b(dn_s, dn);
        });
    }
}
