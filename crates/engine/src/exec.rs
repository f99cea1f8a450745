//! The interpreter: runs IR ops over program memory.
//!
//! This file holds the one semantics of every op (SPEC §11): the Arduino
//! generator and the byte-code firmware are tested against it. Nothing here
//! panics on a verified program: overflow, division by zero and invalid
//! floating-point results give defined values and record a minor fault.

use crate::fault::{FaultCode, Faults};
use alba_ir::{BinOp, Cmp, Ctr, Cvt, Loc, MarkerSlot, Memory, NO_ELEM, Op, Tmr, UnOp, Width};

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

    /// Is element `e` energised (the rung condition after it true)?
    pub fn get(&self, e: u32) -> bool {
        self.bits
            .get(e as usize / 64)
            .is_some_and(|w| w >> (e % 64) & 1 == 1)
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

/// The scan was abandoned: a runaway backward jump.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Runaway {
    pub pc: u32,
}

/// Runs `ops` once. `MON` selects the monitored variant, which records the
/// rung condition after every element in `pf`; the unmonitored variant is a
/// separate instantiation that does no such work at all.
pub(crate) fn run<const MON: bool>(
    ops: &[Op],
    locs: &[Loc],
    m: &mut Memory,
    faults: &mut Faults,
    now: u32,
    pf: &mut PowerFlow,
) -> Result<(), Runaway> {
    if MON {
        pf.clear();
    }
    let mut rc = true;
    let mut pc = 0usize;
    let mut backward = 0u32;
    while let Some(&op) = ops.get(pc) {
        let cur = pc;
        pc += 1;
        match op {
            Op::Rung => rc = true,
            Op::Nop => {}
            Op::Afi => rc = false,
            Op::Xic(b) => rc &= m.b[b.0 as usize],
            Op::Xio(b) => rc &= !m.b[b.0 as usize],
            Op::Ote(b) => m.b[b.0 as usize] = rc,
            Op::Otl(b) => {
                if rc {
                    m.b[b.0 as usize] = true;
                }
            }
            Op::Otu(b) => {
                if rc {
                    m.b[b.0 as usize] = false;
                }
            }
            Op::Ons(s) => {
                let s = s.0 as usize;
                let out = rc && !m.b[s];
                m.b[s] = rc;
                rc = out;
            }
            Op::Osr(s, o) => {
                m.b[o.0 as usize] = rc && !m.b[s.0 as usize];
                m.b[s.0 as usize] = rc;
            }
            Op::Osf(s, o) => {
                m.b[o.0 as usize] = !rc && m.b[s.0 as usize];
                m.b[s.0 as usize] = rc;
            }
            Op::BrOpen { save, acc } => {
                m.b[save.0 as usize] = rc;
                m.b[acc.0 as usize] = false;
            }
            Op::BrNext { save, acc } => {
                m.b[acc.0 as usize] |= rc;
                rc = m.b[save.0 as usize];
            }
            Op::BrClose { acc } => rc |= m.b[acc.0 as usize],
            Op::Jmp(t) => {
                if rc {
                    if MON {
                        record(locs, cur, pf, rc);
                    }
                    if (t as usize) <= cur {
                        backward += 1;
                        if backward > BACKWARD_JUMP_LIMIT {
                            return Err(Runaway { pc: cur as u32 });
                        }
                    }
                    pc = t as usize;
                    continue;
                }
            }
            Op::Ton(t) => ton(m, t, rc, now, faults, cur),
            Op::Tof(t) => tof(m, t, rc, now, faults, cur),
            Op::Rto(t) => rto(m, t, rc, now, faults, cur),
            Op::Tp(t) => tp(m, t, rc, now, faults, cur),
            Op::Ctu(c) => count(m, c, rc, true),
            Op::Ctd(c) => count(m, c, rc, false),
            Op::ResT(t) => {
                if rc {
                    m.i[t.i.0 as usize + 1] = 0;
                    m.b[t.b.0 as usize..t.b.0 as usize + 3].fill(false);
                }
            }
            Op::ResC(c) => {
                if rc {
                    m.i[c.i.0 as usize + 1] = 0;
                    m.b[c.b.0 as usize..c.b.0 as usize + 5].fill(false);
                }
            }
            Op::CmpI(c, a, b) => rc &= cmp(c, m.i[a.0 as usize], m.i[b.0 as usize]),
            Op::CmpF(c, a, b) => rc &= cmp(c, m.f[a.0 as usize], m.f[b.0 as usize]),
            Op::CmpL(c, a, b) => rc &= cmp(c, m.l[a.0 as usize], m.l[b.0 as usize]),
            Op::CmpD(c, a, b) => rc &= cmp(c, m.d[a.0 as usize], m.d[b.0 as usize]),
            Op::LimI(lo, t, hi) => {
                rc &= lim(m.i[lo.0 as usize], m.i[t.0 as usize], m.i[hi.0 as usize])
            }
            Op::LimF(lo, t, hi) => {
                rc &= lim(m.f[lo.0 as usize], m.f[t.0 as usize], m.f[hi.0 as usize])
            }
            Op::LimL(lo, t, hi) => {
                rc &= lim(m.l[lo.0 as usize], m.l[t.0 as usize], m.l[hi.0 as usize])
            }
            Op::LimD(lo, t, hi) => {
                rc &= lim(m.d[lo.0 as usize], m.d[t.0 as usize], m.d[hi.0 as usize])
            }
            Op::MeqI(s, k, c) => {
                let k = m.i[k.0 as usize];
                rc &= m.i[s.0 as usize] & k == m.i[c.0 as usize] & k;
            }
            Op::MeqL(s, k, c) => {
                let k = m.l[k.0 as usize];
                rc &= m.l[s.0 as usize] & k == m.l[c.0 as usize] & k;
            }
            Op::BinI(op, a, b, d) => {
                if rc {
                    let (v, f) = bin_i32(op, m.i[a.0 as usize], m.i[b.0 as usize]);
                    m.i[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::BinL(op, a, b, d) => {
                if rc {
                    let (v, f) = bin_i64(op, m.l[a.0 as usize], m.l[b.0 as usize]);
                    m.l[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::BinF(op, a, b, d) => {
                if rc {
                    let (x, y) = (m.f[a.0 as usize], m.f[b.0 as usize]);
                    let (v, f) = fix_f32(bin_f32(op, x, y), op == BinOp::Div && y == 0.0);
                    m.f[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::BinD(op, a, b, d) => {
                if rc {
                    let (x, y) = (m.d[a.0 as usize], m.d[b.0 as usize]);
                    let (v, f) = fix_f64(bin_f64(op, x, y), op == BinOp::Div && y == 0.0);
                    m.d[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::UnI(op, a, d) => {
                if rc {
                    let (v, f) = un_i32(op, m.i[a.0 as usize]);
                    m.i[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::UnL(op, a, d) => {
                if rc {
                    let (v, f) = un_i64(op, m.l[a.0 as usize]);
                    m.l[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::UnF(op, a, d) => {
                if rc {
                    let (v, f) = fix_f32(un_f32(op, m.f[a.0 as usize]), false);
                    m.f[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::UnD(op, a, d) => {
                if rc {
                    let (v, f) = fix_f64(un_f64(op, m.d[a.0 as usize]), false);
                    m.d[d.0 as usize] = v;
                    fault(faults, f, cur);
                }
            }
            Op::Cvt(c) => {
                if rc {
                    let f = convert(m, c);
                    fault(faults, f, cur);
                }
            }
            Op::Narrow(i, w) => {
                if rc {
                    let v = m.i[i.0 as usize];
                    let n = match w {
                        Width::W8 => v as i8 as i32,
                        Width::W16 => v as i16 as i32,
                    };
                    m.i[i.0 as usize] = n;
                    if n != v {
                        fault(faults, Some(FaultCode::Overflow), cur);
                    }
                }
            }
            Op::CopyI(a, d) => m.i[d.0 as usize] = m.i[a.0 as usize],
            Op::LdBit { byte, bit, dst } => {
                m.b[dst.0 as usize] = m.m[byte as usize] >> bit & 1 == 1;
            }
            Op::StBit { src, byte, bit } => {
                let mask = 1u8 << bit;
                let v = m.b[src.0 as usize];
                let byte = &mut m.m[byte as usize];
                *byte = if v { *byte | mask } else { *byte & !mask };
            }
            Op::LdM { byte, slot } => load_marker(m, byte as usize, slot),
            Op::StM { byte, slot } => store_marker(m, byte as usize, slot),
        }
        if MON {
            record(locs, cur, pf, rc);
        }
    }
    Ok(())
}

#[inline]
fn record(locs: &[Loc], pc: usize, pf: &mut PowerFlow, rc: bool) {
    if let Some(l) = locs.get(pc)
        && l.elem != NO_ELEM
    {
        pf.set(l.elem, rc);
    }
}

#[inline]
fn fault(faults: &mut Faults, code: Option<FaultCode>, pc: usize) {
    if let Some(code) = code {
        faults.record(code, pc as u32);
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
                _ => float_to_int(
                    un_f64(op, a as f64),
                    <$t>::MIN as f64,
                    <$t>::MAX as f64,
                    |v| v as $t,
                ),
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
                UnOp::Sqrt => x.sqrt(),
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
                    if v.is_nan() {
                        0.0
                    } else {
                        <$t>::MAX.copysign(v)
                    },
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

fn convert(m: &mut Memory, c: Cvt) -> Option<FaultCode> {
    let (imin, imax) = (i32::MIN as f64, i32::MAX as f64);
    // i64 bounds as f64: MAX rounds up to 2^63, so compare with `<`.
    let (lmin, lmax) = (i64::MIN as f64, 9_223_372_036_854_774_784.0);
    match c {
        Cvt::IF(a, d) => m.f[d.0 as usize] = m.i[a.0 as usize] as f32,
        Cvt::FI(a, d) => {
            let (v, f) = float_to_int(m.f[a.0 as usize] as f64, imin, imax, |v| v as i32);
            m.i[d.0 as usize] = v;
            return f;
        }
        Cvt::IL(a, d) => m.l[d.0 as usize] = m.i[a.0 as usize] as i64,
        Cvt::LI(a, d) => {
            let v = m.l[a.0 as usize];
            m.i[d.0 as usize] = v as i32;
            if i32::try_from(v).is_err() {
                return Some(FaultCode::Overflow);
            }
        }
        Cvt::ID(a, d) => m.d[d.0 as usize] = m.i[a.0 as usize] as f64,
        Cvt::DI(a, d) => {
            let (v, f) = float_to_int(m.d[a.0 as usize], imin, imax, |v| v as i32);
            m.i[d.0 as usize] = v;
            return f;
        }
        Cvt::LF(a, d) => m.f[d.0 as usize] = m.l[a.0 as usize] as f32,
        Cvt::FL(a, d) => {
            let (v, f) = float_to_int(m.f[a.0 as usize] as f64, lmin, lmax, |v| v as i64);
            m.l[d.0 as usize] = v;
            return f;
        }
        Cvt::LD(a, d) => m.d[d.0 as usize] = m.l[a.0 as usize] as f64,
        Cvt::DL(a, d) => {
            let (v, f) = float_to_int(m.d[a.0 as usize], lmin, lmax, |v| v as i64);
            m.l[d.0 as usize] = v;
            return f;
        }
        Cvt::FD(a, d) => m.d[d.0 as usize] = m.f[a.0 as usize] as f64,
        Cvt::DF(a, d) => {
            let (v, f) = fix_f32(m.d[a.0 as usize] as f32, false);
            m.f[d.0 as usize] = v;
            return f;
        }
    }
    None
}

fn load_marker(m: &mut Memory, at: usize, slot: MarkerSlot) {
    let mut buf = [0u8; 4];
    let n = match slot {
        MarkerSlot::Byte(_) => 1,
        MarkerSlot::Word(_) => 2,
        MarkerSlot::DWord(_) | MarkerSlot::Real(_) => 4,
    };
    if let Some(src) = m.m.get(at..at + n) {
        buf[..n].copy_from_slice(src);
    }
    match slot {
        MarkerSlot::Byte(i) => m.i[i.0 as usize] = buf[0] as i8 as i32,
        MarkerSlot::Word(i) => m.i[i.0 as usize] = i16::from_be_bytes([buf[0], buf[1]]) as i32,
        MarkerSlot::DWord(i) => m.i[i.0 as usize] = i32::from_be_bytes(buf),
        MarkerSlot::Real(f) => m.f[f.0 as usize] = f32::from_be_bytes(buf),
    }
}

fn store_marker(m: &mut Memory, at: usize, slot: MarkerSlot) {
    let bytes: ([u8; 4], usize) = match slot {
        MarkerSlot::Byte(i) => ([m.i[i.0 as usize] as u8, 0, 0, 0], 1),
        MarkerSlot::Word(i) => {
            let w = (m.i[i.0 as usize] as i16).to_be_bytes();
            ([w[0], w[1], 0, 0], 2)
        }
        MarkerSlot::DWord(i) => (m.i[i.0 as usize].to_be_bytes(), 4),
        MarkerSlot::Real(f) => (m.f[f.0 as usize].to_be_bytes(), 4),
    };
    if let Some(dst) = m.m.get_mut(at..at + bytes.1) {
        dst.copy_from_slice(&bytes.0[..bytes.1]);
    }
}

// ---- timers and counters (SPEC §3.2) ----------------------------------------

/// A timer's slots: PRE, ACC, start time; EN, TT, DN.
struct TimerSlots {
    pre: usize,
    acc: usize,
    last: usize,
    en: usize,
    tt: usize,
    dn: usize,
}

impl TimerSlots {
    #[inline]
    fn of(t: Tmr) -> TimerSlots {
        let (i, b) = (t.i.0 as usize, t.b.0 as usize);
        TimerSlots {
            pre: i,
            acc: i + 1,
            last: i + 2,
            en: b,
            tt: b + 1,
            dn: b + 2,
        }
    }
}

/// The preset, with a fault (and 0) when negative.
#[inline]
fn preset(m: &Memory, s: &TimerSlots, faults: &mut Faults, pc: usize) -> i32 {
    let pre = m.i[s.pre];
    if pre < 0 {
        faults.record(FaultCode::NegativePreset, pc as u32);
        return 0;
    }
    pre
}

/// Adds the clock time elapsed since the timer's last update to ACC.
#[inline]
fn elapse(m: &mut Memory, s: &TimerSlots, now: u32) {
    let dt = now.wrapping_sub(m.i[s.last] as u32);
    m.i[s.last] = now as i32;
    m.i[s.acc] = m.i[s.acc].saturating_add(dt.min(i32::MAX as u32) as i32);
}

fn ton(m: &mut Memory, t: Tmr, rc: bool, now: u32, faults: &mut Faults, pc: usize) {
    let s = TimerSlots::of(t);
    if rc {
        let pre = preset(m, &s, faults, pc);
        if !m.b[s.en] {
            m.b[s.en] = true;
            m.i[s.acc] = 0;
            m.i[s.last] = now as i32;
        } else if !m.b[s.dn] {
            elapse(m, &s, now);
        }
        if !m.b[s.dn] && m.i[s.acc] >= pre {
            m.b[s.dn] = true;
            m.i[s.acc] = pre;
        }
        m.b[s.tt] = !m.b[s.dn];
    } else {
        m.b[s.en] = false;
        m.b[s.tt] = false;
        m.b[s.dn] = false;
        m.i[s.acc] = 0;
    }
}

fn tof(m: &mut Memory, t: Tmr, rc: bool, now: u32, faults: &mut Faults, pc: usize) {
    let s = TimerSlots::of(t);
    if rc {
        m.b[s.en] = true;
        m.b[s.dn] = true;
        m.b[s.tt] = false;
        m.i[s.acc] = 0;
        return;
    }
    if m.b[s.en] {
        // First false scan: timing starts at 0.
        m.b[s.en] = false;
        m.b[s.tt] = true;
        m.i[s.acc] = 0;
        m.i[s.last] = now as i32;
    } else if m.b[s.tt] {
        elapse(m, &s, now);
    }
    if m.b[s.tt] {
        let pre = preset(m, &s, faults, pc);
        if m.i[s.acc] >= pre {
            m.b[s.dn] = false;
            m.b[s.tt] = false;
            m.i[s.acc] = pre;
        }
    }
}

fn rto(m: &mut Memory, t: Tmr, rc: bool, now: u32, faults: &mut Faults, pc: usize) {
    let s = TimerSlots::of(t);
    if rc {
        let pre = preset(m, &s, faults, pc);
        if !m.b[s.en] {
            // A true scan after a false one adds nothing: timing resumes now.
            m.b[s.en] = true;
            m.i[s.last] = now as i32;
        } else if !m.b[s.dn] {
            elapse(m, &s, now);
        }
        if !m.b[s.dn] && m.i[s.acc] >= pre {
            m.b[s.dn] = true;
            m.i[s.acc] = pre;
        }
        m.b[s.tt] = !m.b[s.dn];
    } else {
        m.b[s.en] = false;
        m.b[s.tt] = false;
    }
}

fn tp(m: &mut Memory, t: Tmr, rc: bool, now: u32, faults: &mut Faults, pc: usize) {
    let s = TimerSlots::of(t);
    let rising = rc && !m.b[s.en];
    if m.b[s.dn] {
        elapse(m, &s, now);
    } else if rising {
        m.b[s.dn] = true;
        m.i[s.acc] = 0;
        m.i[s.last] = now as i32;
    }
    if m.b[s.dn] {
        let pre = preset(m, &s, faults, pc);
        if m.i[s.acc] >= pre {
            m.b[s.dn] = false;
            m.i[s.acc] = pre;
        }
    }
    if !m.b[s.dn] && !rc {
        m.i[s.acc] = 0;
    }
    m.b[s.tt] = m.b[s.dn];
    m.b[s.en] = rc;
}

/// CTU (`up`) or CTD: count on the rising rung; wrap with OV/UN.
fn count(m: &mut Memory, c: Ctr, rc: bool, up: bool) {
    let (pre, acc) = (c.i.0 as usize, c.i.0 as usize + 1);
    let b = c.b.0 as usize;
    let (cu, cd, dn, ov, un) = (b, b + 1, b + 2, b + 3, b + 4);
    let edge_bit = if up { cu } else { cd };
    if rc && !m.b[edge_bit] {
        let v = m.i[acc];
        if up {
            match v.checked_add(1) {
                Some(n) => m.i[acc] = n,
                None => {
                    m.i[acc] = i32::MIN;
                    if m.b[un] {
                        m.b[un] = false
                    } else {
                        m.b[ov] = true
                    }
                }
            }
        } else {
            match v.checked_sub(1) {
                Some(n) => m.i[acc] = n,
                None => {
                    m.i[acc] = i32::MAX;
                    if m.b[ov] {
                        m.b[ov] = false
                    } else {
                        m.b[un] = true
                    }
                }
            }
        }
    }
    m.b[edge_bit] = rc;
    m.b[dn] = m.i[acc] >= m.i[pre];
}
