//! The slots an IR op writes, for the search's abstractions (explore.rs)
//! and the SAT back end's havoc (induct.rs).

use alba_ir::Op;
use alba_ir::op::AnySlot;

/// Slots an op writes (conservatively: a timer, counter or PID writes all of its own).
pub fn writes(op: &Op) -> Vec<AnySlot> {
    use AnySlot as S;
    match *op {
        Op::Ote(b) | Op::Otl(b) | Op::Otu(b) | Op::Ons(b) | Op::Ed(b) => vec![S::B(b.0)],
        Op::Osr(a, b) | Op::Osf(a, b) => vec![S::B(a.0), S::B(b.0)],
        Op::BrOpen { save, acc } | Op::BrNext { save, acc } => vec![S::B(save.0), S::B(acc.0)],
        Op::BrClose { acc } => vec![S::B(acc.0)],
        Op::CopyB(_, d) => vec![S::B(d.0)],
        Op::LdBit { dst, .. } => vec![S::B(dst.0)],
        Op::StBit { byte, .. } => vec![S::M(byte, 1)],
        Op::StM { byte, slot } => vec![match slot {
            alba_ir::op::MarkerSlot::Byte(_) => S::M(byte, 1),
            alba_ir::op::MarkerSlot::Word(_) => S::M(byte, 2),
            _ => S::M(byte, 4),
        }],
        Op::LdM { slot, .. } => vec![match slot {
            alba_ir::op::MarkerSlot::Real(f) => S::F(f.0),
            alba_ir::op::MarkerSlot::Byte(i) | alba_ir::op::MarkerSlot::Word(i) | alba_ir::op::MarkerSlot::DWord(i) => {
                S::I(i.0)
            }
        }],
        Op::BinI(_, _, _, d) | Op::UnI(_, _, d) | Op::CopyI(_, d) | Op::Narrow(d, _) => vec![S::I(d.0)],
        Op::BinF(_, _, _, d) | Op::UnF(_, _, d) => vec![S::F(d.0)],
        Op::BinL(_, _, _, d) | Op::UnL(_, _, d) => vec![S::L(d.0)],
        Op::BinD(_, _, _, d) | Op::UnD(_, _, d) => vec![S::D(d.0)],
        Op::Cvt(c) => {
            use alba_ir::op::Cvt::*;
            vec![match c {
                FI(_, d) | LI(_, d) | DI(_, d) => S::I(d.0),
                IF(_, d) | LF(_, d) | DF(_, d) => S::F(d.0),
                IL(_, d) | FL(_, d) | DL(_, d) => S::L(d.0),
                ID(_, d) | LD(_, d) | FD(_, d) => S::D(d.0),
            }]
        }
        Op::Ton(t, _) | Op::Tof(t, _) | Op::Rto(t, _) | Op::Tp(t) | Op::ResT(t) => {
            let mut v: Vec<AnySlot> = (0..3).map(|k| S::I(t.i.0 + k)).collect();
            v.extend((0..3).map(|k| S::B(t.b.0 + k)));
            v
        }
        Op::Ctu(c) | Op::Ctd(c) | Op::ResC(c) => {
            let mut v: Vec<AnySlot> = (0..2).map(|k| S::I(c.i.0 + k)).collect();
            v.extend((0..5).map(|k| S::B(c.b.0 + k)));
            v
        }
        Op::S7Ton(t) | Op::S7Tonr(t) | Op::S7Tof(t) | Op::S7ResT(t) => {
            let mut v: Vec<AnySlot> = (0..4).map(|k| S::I(t.i.0 + k)).collect();
            v.extend((0..2).map(|k| S::B(t.b.0 + k)));
            v
        }
        Op::S7Ctu(c) | Op::S7Ctd(c) | Op::S7Ctud(c) | Op::S7ResC(c) => {
            let mut v: Vec<AnySlot> = (0..2).map(|k| S::I(c.i.0 + k)).collect();
            v.extend((0..5).map(|k| S::B(c.b.0 + k)));
            v
        }
        Op::Pid(p) => {
            let mut v: Vec<AnySlot> = (0..alba_ir::op::PID_F_SLOTS).map(|k| S::F(p.f.0 + k)).collect();
            v.extend((0..alba_ir::op::PID_I_SLOTS).map(|k| S::I(p.i.0 + k)));
            v.extend((0..alba_ir::op::PID_B_SLOTS).map(|k| S::B(p.b.0 + k)));
            v
        }
        _ => vec![],
    }
}
