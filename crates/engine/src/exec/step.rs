//! [`step`]: what each executable op does.

use super::arith::{
    bin_f32, bin_f64, bin_i32, bin_i64, cmp, convert, fix_f32, fix_f64, un_f32, un_f64, un_i32, un_i64,
};
use super::code::X;
use super::markers::{load_marker, store_marker};
use super::timers::{S7Count, S7Kind, count, rto, s7_counter, s7_timer, tof, ton, tp};
use crate::fault::FaultCode;
use crate::mem::{Mem, Sink, rd, wr};
use crate::pid;
use alba_ir::{BinOp, Width};

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
        X::Ton(t) => ton(m, t, 1, rc, now, sink, cur),
        X::TonB(t, base) => ton(m, t, base, rc, now, sink, cur),
        X::Tof(t, base) => tof(m, t, base, rc, now, sink, cur),
        X::Rto(t, base) => rto(m, t, base, rc, now, sink, cur),
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
        X::Pid(p) => pid::pid(m, p, rc, now, sink, cur),
        X::RungC { b, neg } => rc = rd!(m.b, b.0) != neg,
        X::RungOr { a, b, na, nb } => rc = (rd!(m.b, a.0) != na) | (rd!(m.b, b.0) != nb),
        X::Or2 { a, b, na, nb } => rc &= (rd!(m.b, a.0) != na) | (rd!(m.b, b.0) != nb),
        X::And2 { a, b, na, nb } => rc &= (rd!(m.b, a.0) != na) & (rd!(m.b, b.0) != nb),
    }
    rc
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
