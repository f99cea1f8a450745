//! [`Code`], the executable form: canonical ops flattened into [`X`], and
//! for unmonitored scans the fused patterns.

use alba_ir::op::{S7Ctr, S7Tmr};
use alba_ir::{B, BinOp, Cmp, Ctr, Cvt, F, I, L, MarkerSlot, Memory, Op, Program, TimeBase, Tmr, UnOp, Width};

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
    /// A TON counting milliseconds (the native code's inline one).
    Ton(Tmr),
    /// A TON counting in units of this many ms.
    TonB(Tmr, u32),
    Tof(Tmr, u32),
    Rto(Tmr, u32),
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
    /// The canonical op each executable op starts at (for faults and power
    /// flow); empty for unfused code, where op `k` is canonical op `k`.
    pub src: Vec<u32>,
    /// Memory sizes the program was verified against (b, i, f, l, d, m).
    sizes: [usize; 6],
}

/// The slot counts of a memory (b, i, f, l, d, m).
pub(crate) fn sizes(m: &Memory) -> [usize; 6] {
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
        let mut src = Vec::with_capacity(if fuse { ops.len() } else { 0 });
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
            if fuse {
                src.push(i as u32);
            }
            i += len;
        }
        map[ops.len()] = out.len() as u32;
        out.push(X::End);
        if fuse {
            src.push(ops.len() as u32);
        }
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

/// The executable op of one canonical op.
pub(crate) fn flatten(op: Op) -> X {
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
        Op::Ton(t, TimeBase::Ms) => X::Ton(t),
        Op::Ton(t, b) => X::TonB(t, b.ms()),
        Op::Tof(t, b) => X::Tof(t, b.ms()),
        Op::Rto(t, b) => X::Rto(t, b.ms()),
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
