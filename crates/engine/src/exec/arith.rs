//! Arithmetic and conversions: integer ops wrap or saturate, floating-point
//! results are cleaned (NaN, ±∞), each with a minor fault.

use crate::fault::FaultCode;
use crate::mem::{Mem, rd, wr};
use alba_ir::{BinOp, Cmp, Cvt, UnOp};

#[inline]
pub(super) fn cmp<T: PartialOrd>(c: Cmp, a: T, b: T) -> bool {
    match c {
        Cmp::Eq => a == b,
        Cmp::Ne => a != b,
        Cmp::Lt => a < b,
        Cmp::Gt => a > b,
        Cmp::Le => a <= b,
        Cmp::Ge => a >= b,
    }
}

macro_rules! int_ops {
    ($bin:ident, $un:ident, $t:ty, $bcd_max:literal) => {
        /// Integer `a op b`: wraps on overflow; division by zero saturates
        /// (0/0 gives 0); each sets a fault.
        pub(super) fn $bin(op: BinOp, a: $t, b: $t) -> ($t, Option<FaultCode>) {
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
        pub(super) fn $un(op: UnOp, a: $t) -> ($t, Option<FaultCode>) {
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
        pub(super) fn $bin(op: BinOp, a: $t, b: $t) -> $t {
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

        pub(super) fn $un(op: UnOp, x: $t) -> $t {
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
        pub(super) fn $fix(v: $t, divisor_zero: bool) -> ($t, Option<FaultCode>) {
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

pub(super) fn convert(m: &mut Mem, c: Cvt) -> Option<FaultCode> {
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
