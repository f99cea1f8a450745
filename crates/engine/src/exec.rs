//! The interpreter: the one semantics of every IR op (SPEC §11).
//!
//! The canonical IR is lowered into [`Code`], the engine's executable form:
//! the same ops with the common ones flattened (`AddI` rather than
//! `BinI(Add, ..)`), and, for unmonitored scans, a few fused patterns that
//! replace several canonical ops (a rung that starts with a two-contact
//! branch becomes one `RungOr`). Monitored scans run the unfused form, one
//! executable op per canonical op, and record the rung condition after each
//! element; unmonitored scans run an instantiation of the same loop with no
//! recording at all.
//!
//! The Arduino generator and the byte-code firmware are tested against this
//! file. Nothing here panics on a verified program: overflow, division by
//! zero and invalid floating-point results give defined values and record a
//! minor fault.

use crate::fault::{FaultCode, Faults};
use alba_ir::op::{S7Ctr, S7Tmr};
use alba_ir::{B, BinOp, Cmp, Ctr, Cvt, F, I, L, Loc, MarkerSlot, Memory, NO_ELEM, Op, Program, Tmr, UnOp, Width};

/// Backward jumps allowed in one scan before the scan is abandoned as a
/// runaway loop (a major fault).
pub const BACKWARD_JUMP_LIMIT: u32 = 1_000_000;

/// Power flow of one scan: one bit per program element (SPEC §11).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PowerFlow {
    bits: Vec<u64>,
}

impl PowerFlow {
    pub fn new(elements: usize) -> PowerFlow {
        PowerFlow {
            bits: vec![0; elements.div_ceil(64)],
        }
    }

    /// The bits: element `e` is bit `e % 64` of word `e / 64`.
    pub fn words(&self) -> &[u64] {
        &self.bits
    }

    /// Is element `e` energised (the rung condition after it true)?
    pub fn get(&self, e: u32) -> bool {
        self.bits.get(e as usize / 64).is_some_and(|w| w >> (e % 64) & 1 == 1)
    }

    #[inline]
    fn set(&mut self, e: u32, v: bool) {
        if let Some(w) = self.bits.get_mut(e as usize / 64) {
            let mask = 1u64 << (e % 64);
            *w = (*w & !mask) | (u64::from(v) << (e % 64));
        }
    }

    fn clear(&mut self) {
        self.bits.iter_mut().for_each(|w| *w = 0);
    }
}

/// Why a scan stopped early.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// A runaway loop of backward jumps, at this canonical op.
    Runaway(u32),
    /// The memory does not have the program's layout (a bug of the caller).
    Memory,
}

/// An executable op. Slots are those of the canonical op(s) it came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum X {
    /// End of the code (a sentinel, so the loop needs no bounds test).
    End,
    Rung,
    Nop,
    Afi,
    Xic(B),
    Xio(B),
    Ote(B),
    Otl(B),
    Otu(B),
    Ons(B),
    Osr(B, B),
    Osf(B, B),
    BrOpen {
        save: B,
        acc: B,
    },
    BrNext {
        save: B,
        acc: B,
    },
    BrClose {
        acc: B,
    },
    Jmp(u32),
    Ton(Tmr),
    Tof(Tmr),
    Rto(Tmr),
    Tp(Tmr),
    Ctu(Ctr),
    Ctd(Ctr),
    ResT(Tmr),
    ResC(Ctr),
    EqI(I, I),
    NeI(I, I),
    LtI(I, I),
    GtI(I, I),
    LeI(I, I),
    GeI(I, I),
    CmpF(Cmp, F, F),
    CmpL(Cmp, L, L),
    CmpD(Cmp, alba_ir::D, alba_ir::D),
    LimI(I, I, I),
    LimF(F, F, F),
    LimL(L, L, L),
    LimD(alba_ir::D, alba_ir::D, alba_ir::D),
    MeqI(I, I, I),
    MeqL(L, L, L),
    AddI(I, I, I),
    SubI(I, I, I),
    BinI(BinOp, I, I, I),
    AddF(F, F, F),
    SubF(F, F, F),
    MulF(F, F, F),
    BinF(BinOp, F, F, F),
    BinL(BinOp, L, L, L),
    BinD(BinOp, alba_ir::D, alba_ir::D, alba_ir::D),
    MovI(I, I),
    MovF(F, F),
    UnI(UnOp, I, I),
    UnF(UnOp, F, F),
    UnL(UnOp, L, L),
    UnD(UnOp, alba_ir::D, alba_ir::D),
    Cvt(Cvt),
    Narrow(I, Width),
    CopyI(I, I),
    LdBit {
        byte: u32,
        bit: u8,
        dst: B,
    },
    StBit {
        src: B,
        byte: u32,
        bit: u8,
    },
    LdM {
        byte: u32,
        slot: MarkerSlot,
    },
    StM {
        byte: u32,
        slot: MarkerSlot,
    },
    Ld(B),
    Ldn(B),
    Or(B),
    Orn(B),
    Not,
    True,
    Ed(B),
    CopyB(B, B),
    S7Ton(S7Tmr),
    S7Tonr(S7Tmr),
    S7Tof(S7Tmr),
    S7ResT(S7Tmr),
    S7Ctu(S7Ctr),
    S7Ctd(S7Ctr),
    S7Ctud(S7Ctr),
    S7ResC(S7Ctr),
    Pid(alba_ir::Pidt),
    // Fused (unmonitored code only):
    /// `Rung; Xic/Xio(b)`: `rc = b != neg`.
    RungC {
        b: B,
        neg: bool,
    },
    /// `Rung; [X(a), X(b)]`: `rc = (a != na) | (b != nb)`.
    RungOr {
        a: B,
        b: B,
        na: bool,
        nb: bool,
    },
    /// `[X(a), X(b)]` mid-rung: `rc &= (a != na) | (b != nb)`.
    Or2 {
        a: B,
        b: B,
        na: bool,
        nb: bool,
    },
    /// `X(a); X(b)`: `rc &= (a != na) & (b != nb)`.
    And2 {
        a: B,
        b: B,
        na: bool,
        nb: bool,
    },
}

/// Executable code for one program.
#[derive(Debug, Clone)]
pub struct Code {
    pub ops: Vec<X>,
    /// The canonical op each executable op starts at (for faults and power flow).
    pub src: Vec<u32>,
    /// Memory sizes the program was verified against (b, i, f, l, d, m).
    sizes: [usize; 6],
}

fn sizes(m: &Memory) -> [usize; 6] {
    [m.b.len(), m.i.len(), m.f.len(), m.l.len(), m.d.len(), m.m.len()]
}

/// A contact op, as (bit, negated).
fn contact(op: &Op) -> Option<(B, bool)> {
    match *op {
        Op::Xic(b) => Some((b, false)),
        Op::Xio(b) => Some((b, true)),
        _ => None,
    }
}

/// An Instruction List load right after `Rung` (where `rc` is true, so it
/// is a contact): `LD a` / `LDN a`.
fn load(op: &Op) -> Option<(B, bool)> {
    match *op {
        Op::Ld(b) => Some((b, false)),
        Op::Ldn(b) => Some((b, true)),
        _ => None,
    }
}

/// `O b` / `ON b`.
fn or_with(op: &Op) -> Option<(B, bool)> {
    match *op {
        Op::Or(b) => Some((b, false)),
        Op::Orn(b) => Some((b, true)),
        _ => None,
    }
}

/// `[X(a), X(b)]` at the start of `ops`: the two contacts.
fn or2(ops: &[Op]) -> Option<(B, bool, B, bool)> {
    match ops {
        [
            Op::BrOpen { save, acc },
            c1,
            Op::BrNext { save: s2, acc: a2 },
            c2,
            Op::BrClose { acc: a3 },
            ..,
        ] if save == s2 && acc == a2 && acc == a3 => {
            let (a, na) = contact(c1)?;
            let (b, nb) = contact(c2)?;
            Some((a, na, b, nb))
        }
        _ => None,
    }
}

impl Code {
    /// Bytes of this executable form.
    pub fn bytes(&self) -> usize {
        self.ops.len() * std::mem::size_of::<X>() + self.src.len() * 4
    }

    /// Does `mem` have the sizes the program was verified against?
    pub(crate) fn fits(&self, mem: &Memory) -> bool {
        sizes(mem) == self.sizes
    }

    /// Lowers a program; `fuse` selects the fused (unmonitored) form. The
    /// program must have passed [`Program::verify`].
    pub fn new(p: &Program, fuse: bool) -> Code {
        let ops = &p.ops;
        let mut out = Vec::with_capacity(ops.len());
        let mut src = Vec::with_capacity(ops.len());
        let mut map = vec![0u32; ops.len() + 1];
        let mut i = 0;
        while i < ops.len() {
            let rest = &ops[i..];
            let (x, len) = match (fuse, rest) {
                (true, [Op::Rung, tail @ ..]) if or2(tail).is_some() => {
                    let (a, na, b, nb) = or2(tail).unwrap_or((B(0), false, B(0), false));
                    (X::RungOr { a, b, na, nb }, 6)
                }
                (true, [Op::Rung, l, o, ..]) if load(l).is_some() && or_with(o).is_some() => {
                    let (a, na) = load(l).unwrap_or((B(0), false));
                    let (b, nb) = or_with(o).unwrap_or((B(0), false));
                    (X::RungOr { a, b, na, nb }, 3)
                }
                (true, [Op::Rung, c, ..]) if contact(c).or_else(|| load(c)).is_some() => {
                    let (b, neg) = contact(c).or_else(|| load(c)).unwrap_or((B(0), false));
                    (X::RungC { b, neg }, 2)
                }
                (true, _) if or2(rest).is_some() => {
                    let (a, na, b, nb) = or2(rest).unwrap_or((B(0), false, B(0), false));
                    (X::Or2 { a, b, na, nb }, 5)
                }
                (true, [c1, c2, ..]) if contact(c1).is_some() && contact(c2).is_some() => {
                    let (a, na) = contact(c1).unwrap_or((B(0), false));
                    let (b, nb) = contact(c2).unwrap_or((B(0), false));
                    (X::And2 { a, b, na, nb }, 2)
                }
                _ => (flatten(ops[i]), 1),
            };
            map[i] = out.len() as u32;
            out.push(x);
            src.push(i as u32);
            i += len;
        }
        map[ops.len()] = out.len() as u32;
        out.push(X::End);
        src.push(ops.len() as u32);
        // Jump targets are rung starts, which always begin an executable op.
        let end = (out.len() - 1) as u32;
        for x in &mut out {
            if let X::Jmp(t) = x {
                *t = map.get(*t as usize).copied().unwrap_or(end).min(end);
            }
        }
        Code {
            ops: out,
            src,
            sizes: sizes(&p.init),
        }
    }
}

fn flatten(op: Op) -> X {
    match op {
        Op::Rung => X::Rung,
        Op::Nop => X::Nop,
        Op::Afi => X::Afi,
        Op::Xic(b) => X::Xic(b),
        Op::Xio(b) => X::Xio(b),
        Op::Ote(b) => X::Ote(b),
        Op::Otl(b) => X::Otl(b),
        Op::Otu(b) => X::Otu(b),
        Op::Ons(b) => X::Ons(b),
        Op::Osr(s, o) => X::Osr(s, o),
        Op::Osf(s, o) => X::Osf(s, o),
        Op::BrOpen { save, acc } => X::BrOpen { save, acc },
        Op::BrNext { save, acc } => X::BrNext { save, acc },
        Op::BrClose { acc } => X::BrClose { acc },
        Op::Jmp(t) => X::Jmp(t),
        Op::Ton(t) => X::Ton(t),
        Op::Tof(t) => X::Tof(t),
        Op::Rto(t) => X::Rto(t),
        Op::Tp(t) => X::Tp(t),
        Op::Ctu(c) => X::Ctu(c),
        Op::Ctd(c) => X::Ctd(c),
        Op::ResT(t) => X::ResT(t),
        Op::ResC(c) => X::ResC(c),
        Op::CmpI(c, a, b) => match c {
            Cmp::Eq => X::EqI(a, b),
            Cmp::Ne => X::NeI(a, b),
            Cmp::Lt => X::LtI(a, b),
            Cmp::Gt => X::GtI(a, b),
            Cmp::Le => X::LeI(a, b),
            Cmp::Ge => X::GeI(a, b),
        },
        Op::CmpF(c, a, b) => X::CmpF(c, a, b),
        Op::CmpL(c, a, b) => X::CmpL(c, a, b),
        Op::CmpD(c, a, b) => X::CmpD(c, a, b),
        Op::LimI(a, b, c) => X::LimI(a, b, c),
        Op::LimF(a, b, c) => X::LimF(a, b, c),
        Op::LimL(a, b, c) => X::LimL(a, b, c),
        Op::LimD(a, b, c) => X::LimD(a, b, c),
        Op::MeqI(a, b, c) => X::MeqI(a, b, c),
        Op::MeqL(a, b, c) => X::MeqL(a, b, c),
        Op::BinI(BinOp::Add, a, b, d) => X::AddI(a, b, d),
        Op::BinI(BinOp::Sub, a, b, d) => X::SubI(a, b, d),
        Op::BinI(op, a, b, d) => X::BinI(op, a, b, d),
        Op::BinF(BinOp::Add, a, b, d) => X::AddF(a, b, d),
        Op::BinF(BinOp::Sub, a, b, d) => X::SubF(a, b, d),
        Op::BinF(BinOp::Mul, a, b, d) => X::MulF(a, b, d),
        Op::BinF(op, a, b, d) => X::BinF(op, a, b, d),
        Op::BinL(op, a, b, d) => X::BinL(op, a, b, d),
        Op::BinD(op, a, b, d) => X::BinD(op, a, b, d),
        Op::UnI(UnOp::Mov, a, d) => X::MovI(a, d),
        Op::UnI(op, a, d) => X::UnI(op, a, d),
        Op::UnF(UnOp::Mov, a, d) => X::MovF(a, d),
        Op::UnF(op, a, d) => X::UnF(op, a, d),
        Op::UnL(op, a, d) => X::UnL(op, a, d),
        Op::UnD(op, a, d) => X::UnD(op, a, d),
        Op::Cvt(c) => X::Cvt(c),
        Op::Narrow(i, w) => X::Narrow(i, w),
        Op::CopyI(a, d) => X::CopyI(a, d),
        Op::LdBit { byte, bit, dst } => X::LdBit { byte, bit, dst },
        Op::StBit { src, byte, bit } => X::StBit { src, byte, bit },
        Op::LdM { byte, slot } => X::LdM { byte, slot },
        Op::StM { byte, slot } => X::StM { byte, slot },
        Op::Ld(b) => X::Ld(b),
        Op::Ldn(b) => X::Ldn(b),
        Op::Or(b) => X::Or(b),
        Op::Orn(b) => X::Orn(b),
        Op::Not => X::Not,
        Op::True => X::True,
        Op::Ed(b) => X::Ed(b),
        Op::CopyB(a, b) => X::CopyB(a, b),
        Op::S7Ton(t) => X::S7Ton(t),
        Op::S7Tonr(t) => X::S7Tonr(t),
        Op::S7Tof(t) => X::S7Tof(t),
        Op::S7ResT(t) => X::S7ResT(t),
        Op::S7Ctu(c) => X::S7Ctu(c),
        Op::S7Ctd(c) => X::S7Ctd(c),
        Op::S7Ctud(c) => X::S7Ctud(c),
        Op::S7ResC(c) => X::S7ResC(c),
        Op::Pid(p) => X::Pid(p),
    }
}

/// Program memory as slices for one scan. Every slot index used with it
/// comes from a program that passed `Program::verify` against memory of
/// exactly these sizes (checked at the start of [`run`]).
pub(crate) struct Mem<'a> {
    pub(crate) b: &'a mut [bool],
    pub(crate) i: &'a mut [i32],
    pub(crate) f: &'a mut [f32],
    pub(crate) l: &'a mut [i64],
    pub(crate) d: &'a mut [f64],
    pub(crate) m: &'a mut [u8],
}

/// Reads a slot without a bounds check.
macro_rules! rd {
    ($s:expr, $x:expr) => {{
        let i = $x as usize;
        debug_assert!(i < $s.len());
        // SAFETY: `i` is a slot of a verified program and `run` checked that
        // the memory has the sizes it was verified against.
        #[allow(unsafe_code)]
        unsafe {
            *$s.get_unchecked(i)
        }
    }};
}

/// Writes a slot without a bounds check.
macro_rules! wr {
    ($s:expr, $x:expr, $v:expr) => {{
        let i = $x as usize;
        let v = $v;
        debug_assert!(i < $s.len());
        // SAFETY: as for `rd!`.
        #[allow(unsafe_code)]
        unsafe {
            *$s.get_unchecked_mut(i) = v;
        }
    }};
}

/// Where faults go, with the map back to canonical ops.
pub(crate) struct Sink<'a> {
    pub(crate) faults: &'a mut Faults,
    pub(crate) src: &'a [u32],
}

impl Sink<'_> {
    #[cold]
    #[inline(never)]
    pub(crate) fn fault(&mut self, code: FaultCode, pc: usize) {
        let canonical = self.src.get(pc).copied().unwrap_or(pc as u32);
        self.faults.record(code, canonical);
    }

    #[inline(always)]
    fn check(&mut self, code: Option<FaultCode>, pc: usize) {
        if let Some(c) = code {
            self.fault(c, pc);
        }
    }
}

/// Runs `code` once. `MON` selects the monitored instantiation, which
/// records the rung condition after every element in `pf` (use it with
/// unfused code, whose ops map one to one onto canonical ops).
pub(crate) fn run<const MON: bool>(
    code: &Code,
    locs: &[Loc],
    mem: &mut Memory,
    faults: &mut Faults,
    now: u32,
    pf: &mut PowerFlow,
) -> Result<(), Stop> {
    if !code.fits(mem) {
        return Err(Stop::Memory);
    }
    if MON {
        pf.clear();
    }
    let m = &mut Mem {
        b: &mut mem.b,
        i: &mut mem.i,
        f: &mut mem.f,
        l: &mut mem.l,
        d: &mut mem.d,
        m: &mut mem.m,
    };
    let sink = &mut Sink { faults, src: &code.src };
    let ops = &code.ops[..];
    let mut rc = true;
    let mut pc = 0usize;
    let mut backward = 0u32;
    loop {
        debug_assert!(pc < ops.len());
        // SAFETY: `pc` starts at 0 and only moves to the next op or to a jump
        // target; `Code::new` ends the code with `End`, which leaves the
        // loop, and clamps every jump target to it, so `pc < ops.len()`.
        #[allow(unsafe_code)]
        let op = unsafe { *ops.get_unchecked(pc) };
        let cur = pc;
        pc += 1;
        match op {
            X::End => break,
            X::Jmp(t) => {
                if rc {
                    if MON {
                        record(locs, code, cur, pf, rc);
                    }
                    if (t as usize) <= cur {
                        backward += 1;
                        if backward > BACKWARD_JUMP_LIMIT {
                            return Err(Stop::Runaway(code.src.get(cur).copied().unwrap_or(0)));
                        }
                    }
                    pc = t as usize;
                    continue;
                }
            }
            _ => rc = step(op, m, sink, now, cur, rc),
        }
        if MON {
            record(locs, code, cur, pf, rc);
        }
    }
    Ok(())
}

/// Executes one op other than `End` and `Jmp`, returning the new rung
/// condition. The interpreter loop and the JIT's fallback both call it.
#[inline(always)]
pub(crate) fn step(op: X, m: &mut Mem, sink: &mut Sink, now: u32, cur: usize, mut rc: bool) -> bool {
    match op {
        X::End | X::Jmp(_) => {}
        X::Rung => rc = true,
        X::Nop => {}
        X::Afi => rc = false,
        X::Xic(b) => rc &= rd!(m.b, b.0),
        X::Xio(b) => rc &= !rd!(m.b, b.0),
        X::Ote(b) => wr!(m.b, b.0, rc),
        X::Otl(b) => {
            if rc {
                wr!(m.b, b.0, true);
            }
        }
        X::Otu(b) => {
            if rc {
                wr!(m.b, b.0, false);
            }
        }
        X::Ons(s) => {
            let out = rc && !rd!(m.b, s.0);
            wr!(m.b, s.0, rc);
            rc = out;
        }
        X::Osr(s, o) => {
            wr!(m.b, o.0, rc && !rd!(m.b, s.0));
            wr!(m.b, s.0, rc);
        }
        X::Osf(s, o) => {
            wr!(m.b, o.0, !rc && rd!(m.b, s.0));
            wr!(m.b, s.0, rc);
        }
        X::BrOpen { save, acc } => {
            wr!(m.b, save.0, rc);
            wr!(m.b, acc.0, false);
        }
        X::BrNext { save, acc } => {
            wr!(m.b, acc.0, rd!(m.b, acc.0) | rc);
            rc = rd!(m.b, save.0);
        }
        X::BrClose { acc } => rc |= rd!(m.b, acc.0),
        X::Ton(t) => ton(m, t, rc, now, sink, cur),
        X::Tof(t) => tof(m, t, rc, now, sink, cur),
        X::Rto(t) => rto(m, t, rc, now, sink, cur),
        X::Tp(t) => tp(m, t, rc, now, sink, cur),
        X::Ctu(c) => count(m, c, rc, true),
        X::Ctd(c) => count(m, c, rc, false),
        X::ResT(t) => {
            if rc {
                wr!(m.i, t.i.0 + 1, 0);
                for k in 0..3 {
                    wr!(m.b, t.b.0 + k, false);
                }
            }
        }
        X::ResC(c) => {
            if rc {
                wr!(m.i, c.i.0 + 1, 0);
                for k in 0..5 {
                    wr!(m.b, c.b.0 + k, false);
                }
            }
        }
        X::EqI(a, b) => rc &= rd!(m.i, a.0) == rd!(m.i, b.0),
        X::NeI(a, b) => rc &= rd!(m.i, a.0) != rd!(m.i, b.0),
        X::LtI(a, b) => rc &= rd!(m.i, a.0) < rd!(m.i, b.0),
        X::GtI(a, b) => rc &= rd!(m.i, a.0) > rd!(m.i, b.0),
        X::LeI(a, b) => rc &= rd!(m.i, a.0) <= rd!(m.i, b.0),
        X::GeI(a, b) => rc &= rd!(m.i, a.0) >= rd!(m.i, b.0),
        X::CmpF(c, a, b) => rc &= cmp(c, rd!(m.f, a.0), rd!(m.f, b.0)),
        X::CmpL(c, a, b) => rc &= cmp(c, rd!(m.l, a.0), rd!(m.l, b.0)),
        X::CmpD(c, a, b) => rc &= cmp(c, rd!(m.d, a.0), rd!(m.d, b.0)),
        X::LimI(lo, t, hi) => rc &= lim(rd!(m.i, lo.0), rd!(m.i, t.0), rd!(m.i, hi.0)),
        X::LimF(lo, t, hi) => rc &= lim(rd!(m.f, lo.0), rd!(m.f, t.0), rd!(m.f, hi.0)),
        X::LimL(lo, t, hi) => rc &= lim(rd!(m.l, lo.0), rd!(m.l, t.0), rd!(m.l, hi.0)),
        X::LimD(lo, t, hi) => rc &= lim(rd!(m.d, lo.0), rd!(m.d, t.0), rd!(m.d, hi.0)),
        X::MeqI(s, k, c) => {
            let k = rd!(m.i, k.0);
            rc &= rd!(m.i, s.0) & k == rd!(m.i, c.0) & k;
        }
        X::MeqL(s, k, c) => {
            let k = rd!(m.l, k.0);
            rc &= rd!(m.l, s.0) & k == rd!(m.l, c.0) & k;
        }
        X::AddI(a, b, d) => {
            if rc {
                let (v, o) = rd!(m.i, a.0).overflowing_add(rd!(m.i, b.0));
                wr!(m.i, d.0, v);
                if o {
                    sink.fault(FaultCode::Overflow, cur);
                }
            }
        }
        X::SubI(a, b, d) => {
            if rc {
                let (v, o) = rd!(m.i, a.0).overflowing_sub(rd!(m.i, b.0));
                wr!(m.i, d.0, v);
                if o {
                    sink.fault(FaultCode::Overflow, cur);
                }
            }
        }
        X::BinI(op, a, b, d) => {
            if rc {
                let (v, f) = bin_i32(op, rd!(m.i, a.0), rd!(m.i, b.0));
                wr!(m.i, d.0, v);
                sink.check(f, cur);
            }
        }
        X::AddF(a, b, d) => {
            if rc {
                let (v, f) = fix_f32(rd!(m.f, a.0) + rd!(m.f, b.0), false);
                wr!(m.f, d.0, v);
                sink.check(f, cur);
            }
        }
        X::SubF(a, b, d) => {
            if rc {
                let (v, f) = fix_f32(rd!(m.f, a.0) - rd!(m.f, b.0), false);
                wr!(m.f, d.0, v);
                sink.check(f, cur);
            }
        }
        X::MulF(a, b, d) => {
            if rc {
                let (v, f) = fix_f32(rd!(m.f, a.0) * rd!(m.f, b.0), false);
                wr!(m.f, d.0, v);
                sink.check(f, cur);
            }
        }
        X::BinF(op, a, b, d) => {
            if rc {
                let (x, y) = (rd!(m.f, a.0), rd!(m.f, b.0));
                let (v, f) = fix_f32(bin_f32(op, x, y), matches!(op, BinOp::Div | BinOp::Mod) && y == 0.0);
                wr!(m.f, d.0, v);
                sink.check(f, cur);
            }
        }
        X::BinL(op, a, b, d) => {
            if rc {
                let (v, f) = bin_i64(op, rd!(m.l, a.0), rd!(m.l, b.0));
                wr!(m.l, d.0, v);
                sink.check(f, cur);
            }
        }
        X::BinD(op, a, b, d) => {
            if rc {
                let (x, y) = (rd!(m.d, a.0), rd!(m.d, b.0));
                let (v, f) = fix_f64(bin_f64(op, x, y), matches!(op, BinOp::Div | BinOp::Mod) && y == 0.0);
                wr!(m.d, d.0, v);
                sink.check(f, cur);
            }
        }
        X::MovI(a, d) => {
            if rc {
                wr!(m.i, d.0, rd!(m.i, a.0));
            }
        }
        X::MovF(a, d) => {
            if rc {
                wr!(m.f, d.0, rd!(m.f, a.0));
            }
        }
        X::UnI(op, a, d) => {
            if rc {
                let (v, f) = un_i32(op, rd!(m.i, a.0));
                wr!(m.i, d.0, v);
                sink.check(f, cur);
            }
        }
        X::UnL(op, a, d) => {
            if rc {
                let (v, f) = un_i64(op, rd!(m.l, a.0));
                wr!(m.l, d.0, v);
                sink.check(f, cur);
            }
        }
        X::UnF(op, a, d) => {
            if rc {
                let (v, f) = fix_f32(un_f32(op, rd!(m.f, a.0)), false);
                wr!(m.f, d.0, v);
                sink.check(f, cur);
            }
        }
        X::UnD(op, a, d) => {
            if rc {
                let (v, f) = fix_f64(un_f64(op, rd!(m.d, a.0)), false);
                wr!(m.d, d.0, v);
                sink.check(f, cur);
            }
        }
        X::Cvt(c) => {
            if rc {
                let f = convert(m, c);
                sink.check(f, cur);
            }
        }
        X::Narrow(i, w) => {
            if rc {
                let v = rd!(m.i, i.0);
                let n = match w {
                    Width::W8 => v as i8 as i32,
                    Width::W16 => v as i16 as i32,
                };
                wr!(m.i, i.0, n);
                if n != v {
                    sink.fault(FaultCode::Overflow, cur);
                }
            }
        }
        X::CopyI(a, d) => wr!(m.i, d.0, rd!(m.i, a.0)),
        X::LdBit { byte, bit, dst } => wr!(m.b, dst.0, rd!(m.m, byte) >> (bit & 7) & 1 == 1),
        X::StBit { src, byte, bit } => {
            let mask = 1u8 << (bit & 7);
            let old = rd!(m.m, byte);
            wr!(m.m, byte, if rd!(m.b, src.0) { old | mask } else { old & !mask });
        }
        X::LdM { byte, slot } => {
            let f = load_marker(m, byte as usize, slot);
            sink.check(f, cur);
        }
        X::StM { byte, slot } => store_marker(m, byte as usize, slot),
        X::Ld(b) => rc = rd!(m.b, b.0),
        X::Ldn(b) => rc = !rd!(m.b, b.0),
        X::Or(b) => rc |= rd!(m.b, b.0),
        X::Orn(b) => rc |= !rd!(m.b, b.0),
        X::Not => rc = !rc,
        X::True => rc = true,
        X::Ed(s) => {
            let out = !rc && rd!(m.b, s.0);
            wr!(m.b, s.0, rc);
            rc = out;
        }
        X::CopyB(a, d) => wr!(m.b, d.0, rd!(m.b, a.0)),
        X::S7Ton(t) => s7_timer(m, t, rc, now, S7Kind::Ton),
        X::S7Tonr(t) => s7_timer(m, t, rc, now, S7Kind::Tonr),
        X::S7Tof(t) => s7_timer(m, t, rc, now, S7Kind::Tof),
        X::S7ResT(t) => {
            if rc {
                wr!(m.i, t.i.0, 0);
                wr!(m.i, t.i.0 + 2, 0);
                wr!(m.b, t.b.0, false);
            }
        }
        X::S7Ctu(c) => s7_counter(m, c, rc, S7Count::Up),
        X::S7Ctd(c) => s7_counter(m, c, rc, S7Count::Down),
        X::S7Ctud(c) => s7_counter(m, c, rc, S7Count::UpDown),
        X::S7ResC(c) => {
            if rc {
                wr!(m.i, c.i.0, 0);
                wr!(m.b, c.b.0, false);
            }
        }
        X::Pid(p) => crate::pid::pid(m, p, rc, now, sink, cur),
        X::RungC { b, neg } => rc = rd!(m.b, b.0) != neg,
        X::RungOr { a, b, na, nb } => rc = (rd!(m.b, a.0) != na) | (rd!(m.b, b.0) != nb),
        X::Or2 { a, b, na, nb } => rc &= (rd!(m.b, a.0) != na) | (rd!(m.b, b.0) != nb),
        X::And2 { a, b, na, nb } => rc &= (rd!(m.b, a.0) != na) & (rd!(m.b, b.0) != nb),
    }
    rc
}

#[inline]
fn record(locs: &[Loc], code: &Code, pc: usize, pf: &mut PowerFlow, rc: bool) {
    let canonical = code.src.get(pc).copied().unwrap_or(u32::MAX) as usize;
    if let Some(l) = locs.get(canonical)
        && l.elem != NO_ELEM
    {
        pf.set(l.elem, rc);
    }
}

#[inline]
fn cmp<T: PartialOrd>(c: Cmp, a: T, b: T) -> bool {
    match c {
        Cmp::Eq => a == b,
        Cmp::Ne => a != b,
        Cmp::Lt => a < b,
        Cmp::Gt => a > b,
        Cmp::Le => a <= b,
        Cmp::Ge => a >= b,
    }
}

/// LIM: `low <= test <= high`, or outside-the-band when `low > high` (Logix).
#[inline]
fn lim<T: PartialOrd>(lo: T, t: T, hi: T) -> bool {
    if lo <= hi {
        lo <= t && t <= hi
    } else {
        t >= lo || t <= hi
    }
}

macro_rules! int_ops {
    ($bin:ident, $un:ident, $t:ty, $bcd_max:literal) => {
        /// Integer `a op b`: wraps on overflow; division by zero saturates
        /// (0/0 gives 0); each sets a fault.
        fn $bin(op: BinOp, a: $t, b: $t) -> ($t, Option<FaultCode>) {
            let ovf = |r: Option<$t>, w: $t| match r {
                Some(v) => (v, None),
                None => (w, Some(FaultCode::Overflow)),
            };
            match op {
                BinOp::Add => ovf(a.checked_add(b), a.wrapping_add(b)),
                BinOp::Sub => ovf(a.checked_sub(b), a.wrapping_sub(b)),
                BinOp::Mul => ovf(a.checked_mul(b), a.wrapping_mul(b)),
                BinOp::Div if b == 0 => {
                    let v = if a > 0 {
                        <$t>::MAX
                    } else if a < 0 {
                        <$t>::MIN
                    } else {
                        0
                    };
                    (v, Some(FaultCode::DivZero))
                }
                BinOp::Div => ovf(a.checked_div(b), a.wrapping_div(b)),
                BinOp::Mod if b == 0 => (0, Some(FaultCode::DivZero)),
                BinOp::Mod => (a.wrapping_rem(b), None),
                BinOp::And => (a & b, None),
                BinOp::Or => (a | b, None),
                BinOp::Xor => (a ^ b, None),
                BinOp::Cmp(c) => (cmp(c, a, b) as $t, None),
                // Not produced by the compilers (they compute these in
                // floating point); defined anyway.
                BinOp::Pow | BinOp::Atan2 => float_to_int(
                    bin_f64(op, a as f64, b as f64),
                    <$t>::MIN as f64,
                    <$t>::MAX as f64,
                    |v| v as $t,
                ),
            }
        }

        /// Integer `op a`.
        fn $un(op: UnOp, a: $t) -> ($t, Option<FaultCode>) {
            let ovf = |r: Option<$t>, w: $t| match r {
                Some(v) => (v, None),
                None => (w, Some(FaultCode::Overflow)),
            };
            match op {
                UnOp::Mov => (a, None),
                UnOp::Neg => ovf(a.checked_neg(), a.wrapping_neg()),
                UnOp::Abs => ovf(a.checked_abs(), a.wrapping_abs()),
                UnOp::Not => (!a, None),
                UnOp::Frd => {
                    // BCD to binary; a nibble above 9 is a range fault.
                    if a < 0 {
                        return (0, Some(FaultCode::Range));
                    }
                    let (mut v, mut mul, mut x): ($t, $t, $t) = (0, 1, a);
                    while x > 0 {
                        let digit = x & 0xF;
                        if digit > 9 {
                            return (0, Some(FaultCode::Range));
                        }
                        v += digit * mul;
                        mul = mul.saturating_mul(10);
                        x >>= 4;
                    }
                    (v, None)
                }
                UnOp::Tod => {
                    if !(0..=$bcd_max).contains(&a) {
                        return (0, Some(FaultCode::Range));
                    }
                    let (mut v, mut shift, mut x): ($t, u32, $t) = (0, 0, a);
                    while x > 0 {
                        v |= (x % 10) << shift;
                        shift += 4;
                        x /= 10;
                    }
                    (v, None)
                }
                _ => float_to_int(un_f64(op, a as f64), <$t>::MIN as f64, <$t>::MAX as f64, |v| {
                    v as $t
                }),
            }
        }
    };
}
int_ops!(bin_i32, un_i32, i32, 9_999_999);
int_ops!(bin_i64, un_i64, i64, 999_999_999_999_999);

macro_rules! float_ops {
    ($bin:ident, $un:ident, $fix:ident, $t:ty) => {
        /// Floating-point `a op b` in the type's own precision, so REAL
        /// results match a 32-bit target bit for bit.
        #[inline]
        fn $bin(op: BinOp, a: $t, b: $t) -> $t {
            match op {
                BinOp::Add => a + b,
                BinOp::Sub => a - b,
                BinOp::Mul => a * b,
                BinOp::Div => a / b,
                BinOp::Mod => a % b,
                BinOp::Pow => a.powf(b),
                BinOp::Atan2 => a.atan2(b),
                BinOp::Cmp(c) => cmp(c, a, b) as u8 as $t,
                // Bitwise operations on reals are refused by `verify`.
                BinOp::And | BinOp::Or | BinOp::Xor => a,
            }
        }

        fn $un(op: UnOp, x: $t) -> $t {
            match op {
                UnOp::Mov => x,
                UnOp::Neg => -x,
                UnOp::Abs => x.abs(),
                // Of the absolute value, as Logix SQR and SQRT do.
                UnOp::Sqrt => x.abs().sqrt(),
                UnOp::Ln => x.ln(),
                UnOp::Log => x.log10(),
                UnOp::Sin => x.sin(),
                UnOp::Cos => x.cos(),
                UnOp::Tan => x.tan(),
                UnOp::Asin => x.asin(),
                UnOp::Acos => x.acos(),
                UnOp::Atan => x.atan(),
                UnOp::Deg => x.to_degrees(),
                UnOp::Rad => x.to_radians(),
                UnOp::Trunc => x.trunc(),
                UnOp::Round => x.round_ties_even(),
                // Integer-only operations are refused by `verify`.
                UnOp::Not | UnOp::Frd | UnOp::Tod => x,
            }
        }

        /// NaN becomes 0 and ±∞ becomes ±MAX, each with a fault.
        #[inline]
        fn $fix(v: $t, divisor_zero: bool) -> ($t, Option<FaultCode>) {
            if v.is_finite() {
                (v, None)
            } else if divisor_zero {
                (
                    if v.is_nan() { 0.0 } else { <$t>::MAX.copysign(v) },
                    Some(FaultCode::DivZero),
                )
            } else if v.is_nan() {
                (0.0, Some(FaultCode::Nan))
            } else {
                (<$t>::MAX.copysign(v), Some(FaultCode::Overflow))
            }
        }
    };
}
float_ops!(bin_f32, un_f32, fix_f32, f32);
float_ops!(bin_f64, un_f64, fix_f64, f64);

/// Float to integer: round half to even; NaN gives 0 and out-of-range
/// values saturate, with a fault.
#[inline]
fn float_to_int<T>(v: f64, lo: f64, hi: f64, cast: impl Fn(f64) -> T) -> (T, Option<FaultCode>) {
    if v.is_nan() {
        return (cast(0.0), Some(FaultCode::Nan));
    }
    let r = v.round_ties_even();
    if r < lo || r > hi {
        return (cast(r.clamp(lo, hi)), Some(FaultCode::Overflow));
    }
    (cast(r), None)
}

fn convert(m: &mut Mem, c: Cvt) -> Option<FaultCode> {
    let (imin, imax) = (i32::MIN as f64, i32::MAX as f64);
    // The largest f64 below 2^63 (i64::MAX itself rounds up to 2^63).
    let (lmin, lmax) = (i64::MIN as f64, 9_223_372_036_854_774_784.0);
    match c {
        Cvt::IF(a, d) => wr!(m.f, d.0, rd!(m.i, a.0) as f32),
        Cvt::FI(a, d) => {
            let (v, f) = float_to_int(rd!(m.f, a.0) as f64, imin, imax, |v| v as i32);
            wr!(m.i, d.0, v);
            return f;
        }
        Cvt::IL(a, d) => wr!(m.l, d.0, rd!(m.i, a.0) as i64),
        Cvt::LI(a, d) => {
            let v = rd!(m.l, a.0);
            wr!(m.i, d.0, v as i32);
            if i32::try_from(v).is_err() {
                return Some(FaultCode::Overflow);
            }
        }
        Cvt::ID(a, d) => wr!(m.d, d.0, rd!(m.i, a.0) as f64),
        Cvt::DI(a, d) => {
            let (v, f) = float_to_int(rd!(m.d, a.0), imin, imax, |v| v as i32);
            wr!(m.i, d.0, v);
            return f;
        }
        Cvt::LF(a, d) => wr!(m.f, d.0, rd!(m.l, a.0) as f32),
        Cvt::FL(a, d) => {
            let (v, f) = float_to_int(rd!(m.f, a.0) as f64, lmin, lmax, |v| v as i64);
            wr!(m.l, d.0, v);
            return f;
        }
        Cvt::LD(a, d) => wr!(m.d, d.0, rd!(m.l, a.0) as f64),
        Cvt::DL(a, d) => {
            let (v, f) = float_to_int(rd!(m.d, a.0), lmin, lmax, |v| v as i64);
            wr!(m.l, d.0, v);
            return f;
        }
        Cvt::FD(a, d) => wr!(m.d, d.0, rd!(m.f, a.0) as f64),
        Cvt::DF(a, d) => {
            let (v, f) = fix_f32(rd!(m.d, a.0) as f32, false);
            wr!(m.f, d.0, v);
            return f;
        }
    }
    None
}

fn marker_width(slot: MarkerSlot) -> usize {
    match slot {
        MarkerSlot::Byte(_) => 1,
        MarkerSlot::Word(_) => 2,
        MarkerSlot::DWord(_) | MarkerSlot::Real(_) => 4,
    }
}

/// Loads a marker value into a slot. A REAL whose bits are NaN or ±∞ (MW
/// writes can make any bit pattern) is cleaned like any REAL result.
fn load_marker(m: &mut Mem, at: usize, slot: MarkerSlot) -> Option<FaultCode> {
    let mut buf = [0u8; 4];
    let n = marker_width(slot);
    if let Some(src) = m.m.get(at..at + n) {
        buf[..n].copy_from_slice(src);
    }
    match slot {
        MarkerSlot::Byte(i) => wr!(m.i, i.0, buf[0] as i8 as i32),
        MarkerSlot::Word(i) => wr!(m.i, i.0, i16::from_be_bytes([buf[0], buf[1]]) as i32),
        MarkerSlot::DWord(i) => wr!(m.i, i.0, i32::from_be_bytes(buf)),
        MarkerSlot::Real(f) => {
            let (v, fault) = fix_f32(f32::from_be_bytes(buf), false);
            wr!(m.f, f.0, v);
            return fault;
        }
    }
    None
}

fn store_marker(m: &mut Mem, at: usize, slot: MarkerSlot) {
    let bytes: [u8; 4] = match slot {
        MarkerSlot::Byte(i) => [rd!(m.i, i.0) as u8, 0, 0, 0],
        MarkerSlot::Word(i) => {
            let w = (rd!(m.i, i.0) as i16).to_be_bytes();
            [w[0], w[1], 0, 0]
        }
        MarkerSlot::DWord(i) => rd!(m.i, i.0).to_be_bytes(),
        MarkerSlot::Real(f) => rd!(m.f, f.0).to_be_bytes(),
    };
    let n = marker_width(slot);
    if let Some(dst) = m.m.get_mut(at..at + n) {
        dst.copy_from_slice(&bytes[..n]);
    }
}

// ---- timers and counters (SPEC §3.2) ----------------------------------------
//
// A TIMER is integer slots PRE, ACC, LAST (the clock at its last update,
// wrapping milliseconds) and bool slots EN, TT, DN. Time counted is always
// clock time between scans, never a number of scans.

const PRE: u32 = 0;
const ACC: u32 = 1;
const LAST: u32 = 2;
const EN: u32 = 0;
const TT: u32 = 1;
const DN: u32 = 2;

/// The preset, with a fault (and 0) when negative.
#[inline(always)]
fn preset(m: &Mem, t: Tmr, sink: &mut Sink, pc: usize) -> i32 {
    let pre = rd!(m.i, t.i.0 + PRE);
    if pre < 0 {
        sink.fault(FaultCode::NegativePreset, pc);
        return 0;
    }
    pre
}

/// Adds the clock time elapsed since the timer's last update to ACC.
#[inline(always)]
fn elapse(m: &mut Mem, t: Tmr, now: u32) {
    let dt = now.wrapping_sub(rd!(m.i, t.i.0 + LAST) as u32);
    wr!(m.i, t.i.0 + LAST, now as i32);
    let acc = rd!(m.i, t.i.0 + ACC);
    wr!(m.i, t.i.0 + ACC, acc.saturating_add(dt.min(i32::MAX as u32) as i32));
}

/// Sets DN and stops ACC at PRE once reached (TON, RTO).
#[inline(always)]
fn done_at_preset(m: &mut Mem, t: Tmr, pre: i32) {
    if !rd!(m.b, t.b.0 + DN) && rd!(m.i, t.i.0 + ACC) >= pre {
        wr!(m.b, t.b.0 + DN, true);
        wr!(m.i, t.i.0 + ACC, pre);
    }
}

/// TON: rung true → EN; ACC from 0 on the first true scan, adding clock
/// time after; DN at PRE (ACC stops there); TT = EN ∧ ¬DN. Rung false →
/// everything 0.
#[inline(always)]
fn ton(m: &mut Mem, t: Tmr, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    if rc {
        let pre = preset(m, t, sink, pc);
        if !rd!(m.b, t.b.0 + EN) {
            wr!(m.b, t.b.0 + EN, true);
            wr!(m.i, t.i.0 + ACC, 0);
            wr!(m.i, t.i.0 + LAST, now as i32);
        } else if !rd!(m.b, t.b.0 + DN) {
            elapse(m, t, now);
        }
        done_at_preset(m, t, pre);
        wr!(m.b, t.b.0 + TT, !rd!(m.b, t.b.0 + DN));
    } else {
        wr!(m.b, t.b.0 + EN, false);
        wr!(m.b, t.b.0 + TT, false);
        wr!(m.b, t.b.0 + DN, false);
        wr!(m.i, t.i.0 + ACC, 0);
    }
}

/// TOF: rung true → EN = DN = 1, TT = 0, ACC = 0. The first false scan
/// after that starts timing from 0; at PRE, DN = TT = 0.
fn tof(m: &mut Mem, t: Tmr, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    if rc {
        wr!(m.b, t.b.0 + EN, true);
        wr!(m.b, t.b.0 + DN, true);
        wr!(m.b, t.b.0 + TT, false);
        wr!(m.i, t.i.0 + ACC, 0);
        return;
    }
    if rd!(m.b, t.b.0 + EN) {
        wr!(m.b, t.b.0 + EN, false);
        wr!(m.b, t.b.0 + TT, true);
        wr!(m.i, t.i.0 + ACC, 0);
        wr!(m.i, t.i.0 + LAST, now as i32);
    } else if rd!(m.b, t.b.0 + TT) {
        elapse(m, t, now);
    }
    if rd!(m.b, t.b.0 + TT) {
        let pre = preset(m, t, sink, pc);
        if rd!(m.i, t.i.0 + ACC) >= pre {
            wr!(m.b, t.b.0 + DN, false);
            wr!(m.b, t.b.0 + TT, false);
            wr!(m.i, t.i.0 + ACC, pre);
        }
    }
}

/// RTO: like TON, but a false rung keeps ACC and DN; a true scan after a
/// false one adds nothing (timing resumes then). Only RES clears it.
fn rto(m: &mut Mem, t: Tmr, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    if rc {
        let pre = preset(m, t, sink, pc);
        if !rd!(m.b, t.b.0 + EN) {
            wr!(m.b, t.b.0 + EN, true);
            wr!(m.i, t.i.0 + LAST, now as i32);
        } else if !rd!(m.b, t.b.0 + DN) {
            elapse(m, t, now);
        }
        done_at_preset(m, t, pre);
        wr!(m.b, t.b.0 + TT, !rd!(m.b, t.b.0 + DN));
    } else {
        wr!(m.b, t.b.0 + EN, false);
        wr!(m.b, t.b.0 + TT, false);
    }
}

/// TP: a rising rung starts a pulse DN = 1 of PRE ms (ACC from 0, whatever
/// the rung does next); not retriggerable while DN; ACC = 0 once the pulse
/// has ended and the rung is false. TT follows DN; EN is the rung.
fn tp(m: &mut Mem, t: Tmr, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    let rising = rc && !rd!(m.b, t.b.0 + EN);
    if rd!(m.b, t.b.0 + DN) {
        elapse(m, t, now);
    } else if rising {
        wr!(m.b, t.b.0 + DN, true);
        wr!(m.i, t.i.0 + ACC, 0);
        wr!(m.i, t.i.0 + LAST, now as i32);
    }
    if rd!(m.b, t.b.0 + DN) {
        let pre = preset(m, t, sink, pc);
        if rd!(m.i, t.i.0 + ACC) >= pre {
            wr!(m.b, t.b.0 + DN, false);
            wr!(m.i, t.i.0 + ACC, pre);
        }
    }
    if !rd!(m.b, t.b.0 + DN) && !rc {
        wr!(m.i, t.i.0 + ACC, 0);
    }
    wr!(m.b, t.b.0 + TT, rd!(m.b, t.b.0 + DN));
    wr!(m.b, t.b.0 + EN, rc);
}

/// CTU (`up`) / CTD: count on the false→true transition of the rung (CU/CD
/// remember the last rung state); DN = ACC ≥ PRE. Wrapping past the 32-bit
/// range sets OV (up) or UN (down), or clears the opposite flag if set.
#[inline(always)]
fn count(m: &mut Mem, c: Ctr, rc: bool, up: bool) {
    let (pre, acc) = (c.i.0, c.i.0 + 1);
    let b = c.b.0;
    let (dn, ov, un) = (b + 2, b + 3, b + 4);
    let edge = if up { b } else { b + 1 };
    if rc && !rd!(m.b, edge) {
        let v = rd!(m.i, acc);
        let (next, wrapped) = if up { v.overflowing_add(1) } else { v.overflowing_sub(1) };
        wr!(m.i, acc, next);
        if wrapped {
            let (set, clear) = if up { (ov, un) } else { (un, ov) };
            if rd!(m.b, clear) {
                wr!(m.b, clear, false);
            } else {
                wr!(m.b, set, true);
            }
        }
    }
    wr!(m.b, edge, rc);
    wr!(m.b, dn, rd!(m.i, acc) >= rd!(m.i, pre));
}

// ---- S7-200 timers and counters (SPEC §4) -----------------------------------
//
// An S7 timer counts in units of its resolution (1, 10 or 100 ms); the
// milliseconds not yet making a unit are kept, so no time is lost between
// scans. Its current value is a 16-bit count: TON and TONR go on counting to
// 32767, TOF stops at PT.

#[derive(Clone, Copy, PartialEq, Eq)]
enum S7Kind {
    Ton,
    Tonr,
    Tof,
}

/// Adds the clock time since the last update to the count, up to `cap`.
#[inline]
fn s7_advance(m: &mut Mem, t: S7Tmr, now: u32, cap: i32) {
    let (cv, rem, last) = (t.i.0, t.i.0 + 2, t.i.0 + 3);
    let dt = now.wrapping_sub(rd!(m.i, last) as u32);
    wr!(m.i, last, now as i32);
    let res = u64::from(t.res.max(1));
    let total = rd!(m.i, rem).max(0) as u64 + u64::from(dt);
    let units = (total / res).min(i32::MAX as u64) as i32;
    wr!(m.i, rem, (total % res) as i32);
    wr!(m.i, cv, rd!(m.i, cv).saturating_add(units).min(cap.max(0)));
}

fn s7_timer(m: &mut Mem, t: S7Tmr, enable: bool, now: u32, kind: S7Kind) {
    let (cv, pt, rem, last) = (t.i.0, t.i.0 + 1, t.i.0 + 2, t.i.0 + 3);
    let (bit, en) = (t.b.0, t.b.0 + 1);
    let was = rd!(m.b, en);
    wr!(m.b, en, enable);
    match kind {
        S7Kind::Ton | S7Kind::Tonr => {
            if enable {
                if !was {
                    // The first enabled execution starts timing (TON from 0,
                    // TONR from where it stopped) and counts nothing yet.
                    if kind == S7Kind::Ton {
                        wr!(m.i, cv, 0);
                        wr!(m.i, rem, 0);
                    }
                    wr!(m.i, last, now as i32);
                } else {
                    s7_advance(m, t, now, i16::MAX as i32);
                }
                wr!(m.b, bit, rd!(m.i, cv) >= rd!(m.i, pt));
            } else if kind == S7Kind::Ton {
                wr!(m.i, cv, 0);
                wr!(m.i, rem, 0);
                wr!(m.b, bit, false);
            }
        }
        S7Kind::Tof => {
            if enable {
                wr!(m.b, bit, true);
                wr!(m.i, cv, 0);
                wr!(m.i, rem, 0);
                return;
            }
            if was {
                // The enable has just dropped: timing starts from 0.
                wr!(m.i, cv, 0);
                wr!(m.i, rem, 0);
                wr!(m.i, last, now as i32);
            } else if rd!(m.b, bit) {
                let p = rd!(m.i, pt);
                s7_advance(m, t, now, p);
            }
            if rd!(m.b, bit) && rd!(m.i, cv) >= rd!(m.i, pt) {
                wr!(m.b, bit, false);
            }
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum S7Count {
    Up,
    Down,
    UpDown,
}

/// CTU/CTD/CTUD. `top` is the reset input (CTU, CTUD) or the load input
/// (CTD); the count inputs were copied to `b+3` (up) and `b+4` (down).
fn s7_counter(m: &mut Mem, c: S7Ctr, top: bool, kind: S7Count) {
    let (cv, pv) = (c.i.0, c.i.0 + 1);
    let (bit, cu_was, cd_was, cu, cd) = (c.b.0, c.b.0 + 1, c.b.0 + 2, c.b.0 + 3, c.b.0 + 4);
    let up = rd!(m.b, cu) && !rd!(m.b, cu_was);
    let down = rd!(m.b, cd) && !rd!(m.b, cd_was);
    wr!(m.b, cu_was, rd!(m.b, cu));
    wr!(m.b, cd_was, rd!(m.b, cd));
    let v = rd!(m.i, cv);
    match kind {
        S7Count::Up => {
            // Stops at 32767; the reset wins.
            let v = if top {
                0
            } else if up {
                (v + 1).min(i16::MAX as i32)
            } else {
                v
            };
            wr!(m.i, cv, v);
            wr!(m.b, bit, v >= rd!(m.i, pv));
        }
        S7Count::Down => {
            if top {
                // Load: the preset, and the bit off.
                wr!(m.i, cv, rd!(m.i, pv));
                wr!(m.b, bit, false);
            } else {
                let v = if down && v > 0 { v - 1 } else { v };
                wr!(m.i, cv, v);
                wr!(m.b, bit, v == 0);
            }
        }
        S7Count::UpDown => {
            // Wraps at the ends of the 16-bit range; the reset wins.
            let mut v = v;
            if up {
                v = if v >= i16::MAX as i32 { i16::MIN as i32 } else { v + 1 };
            }
            if down {
                v = if v <= i16::MIN as i32 { i16::MAX as i32 } else { v - 1 };
            }
            if top {
                v = 0;
            }
            wr!(m.i, cv, v);
            wr!(m.b, bit, v >= rd!(m.i, pv));
        }
    }
}
