//! The functions of expressions (CPT's, and the state-net source's in nets'
//! guards and scripts), lowered onto the IR's existing operations: the
//! engine, its native code, the Arduino export and the byte code run them
//! without an operation of their own, so they agree by construction.
//!
//! Functions the IR has no operation for are compositions that do not touch
//! the rung condition (compares give 1 or 0 as values, `BinOp::Cmp`), so
//! they lower inside a CPT as inside a guard. Their results follow Alba's
//! floating-point rules: a result that is not a number is 0 with a minor
//! fault, ±∞ is ±MAX with a minor fault (docs/ladder.md "CPT").

use crate::expr::Func;
use alba_ir::values::{Class, V};
use alba_ir::{BinOp, Builder, Cmp, UnOp};
use alba_model::Literal;

struct Emit<'a> {
    b: &'a mut Builder,
    c: Class,
    elem: u32,
}

impl Emit<'_> {
    fn k(&mut self, v: f64) -> V {
        self.b.constant(Literal::Real(v), self.c)
    }
    fn un(&mut self, op: UnOp, a: V) -> V {
        let t = self.b.temp(self.c);
        self.b.un(op, a, t, self.elem);
        t
    }
    fn bin(&mut self, op: BinOp, x: V, y: V) -> V {
        let t = self.b.temp(self.c);
        self.b.bin(op, x, y, t, self.elem);
        t
    }
    fn cmp(&mut self, c: Cmp, x: V, y: V) -> V {
        self.bin(BinOp::Cmp(c), x, y)
    }
    /// e ** x.
    fn exp(&mut self, x: V) -> V {
        let e = self.k(std::f64::consts::E);
        self.bin(BinOp::Pow, e, x)
    }
    /// 1, 0 or -1.
    fn sign(&mut self, x: V) -> V {
        let zero = self.k(0.0);
        let pos = self.cmp(Cmp::Gt, x, zero);
        let neg = self.cmp(Cmp::Lt, x, zero);
        self.bin(BinOp::Sub, pos, neg)
    }
    /// e**(x - ln 2) ± e**(-x - ln 2): cosh and sinh, without overflowing
    /// before the result does.
    fn half_exps(&mut self, x: V) -> (V, V) {
        let ln2 = self.k(std::f64::consts::LN_2);
        let a = self.bin(BinOp::Sub, x, ln2);
        let p = self.exp(a);
        let nx = self.un(UnOp::Neg, x);
        let a = self.bin(BinOp::Sub, nx, ln2);
        let n = self.exp(a);
        (p, n)
    }
}

/// Emits `f(args)` computed in class `c` (the arguments already in `c`)
/// and returns the temporary holding the result. Acts while the rung
/// condition is true, like every data operation, and leaves it unchanged.
pub fn call(b: &mut Builder, f: Func, args: &[V], c: Class, elem: u32) -> V {
    let mut e = Emit { b, c, elem };
    let float = matches!(c, Class::F | Class::D);
    let x = args[0];
    let y = args.get(1).copied().unwrap_or(x);
    let simple = |op| Some(op);
    let op = match f {
        Func::Sqrt => simple(UnOp::Sqrt),
        Func::Abs => simple(UnOp::Abs),
        Func::Sin => simple(UnOp::Sin),
        Func::Cos => simple(UnOp::Cos),
        Func::Tan => simple(UnOp::Tan),
        Func::Asn => simple(UnOp::Asin),
        Func::Acs => simple(UnOp::Acos),
        Func::Atn => simple(UnOp::Atan),
        Func::Ln => simple(UnOp::Ln),
        Func::Log => simple(UnOp::Log),
        Func::Deg => simple(UnOp::Deg),
        Func::Rad => simple(UnOp::Rad),
        Func::Frd => simple(UnOp::Frd),
        Func::Tod => simple(UnOp::Tod),
        Func::Trn if float => simple(UnOp::Trunc),
        Func::Round if float => simple(UnOp::Round),
        // An integer is already whole.
        Func::Trn | Func::Round | Func::Floor | Func::Ceil | Func::RoundAway if !float => simple(UnOp::Mov),
        _ => None,
    };
    if let Some(op) = op {
        return e.un(op, x);
    }
    match f {
        Func::Atan2 => e.bin(BinOp::Atan2, x, y),
        Func::Pow => e.bin(BinOp::Pow, x, y),
        Func::Root => {
            let one = e.k(1.0);
            let inv = e.bin(BinOp::Div, one, y);
            e.bin(BinOp::Pow, x, inv)
        }
        Func::Exp => e.exp(x),
        Func::Cosh => {
            let (p, n) = e.half_exps(x);
            e.bin(BinOp::Add, p, n)
        }
        Func::Sinh => {
            let (p, n) = e.half_exps(x);
            e.bin(BinOp::Sub, p, n)
        }
        Func::Tanh => {
            // sign(x)·(1 - 2/(e**(2m) + 1)), m = min(|x|, 20): tanh(20) is 1
            // to within an LREAL, and e**40 does not overflow.
            let s = e.sign(x);
            let a = e.un(UnOp::Abs, x);
            let cap = e.k(20.0);
            let over = e.cmp(Cmp::Gt, a, cap);
            let excess = e.bin(BinOp::Sub, a, cap);
            let cut = e.bin(BinOp::Mul, over, excess);
            let m = e.bin(BinOp::Sub, a, cut);
            let m2 = e.bin(BinOp::Add, m, m);
            let p = e.exp(m2);
            let one = e.k(1.0);
            let two = e.k(2.0);
            let d = e.bin(BinOp::Add, p, one);
            let q = e.bin(BinOp::Div, two, d);
            let t = e.bin(BinOp::Sub, one, q);
            e.bin(BinOp::Mul, s, t)
        }
        Func::Floor => {
            let t = e.un(UnOp::Trunc, x);
            let below = e.cmp(Cmp::Lt, x, t);
            e.bin(BinOp::Sub, t, below)
        }
        Func::Ceil => {
            let t = e.un(UnOp::Trunc, x);
            let above = e.cmp(Cmp::Gt, x, t);
            e.bin(BinOp::Add, t, above)
        }
        Func::Sign => e.sign(x),
        Func::Rem => {
            // r = fmod(a, b) (exact); the IEEE remainder is r, or r - sign(r)·|b|
            // when |r| > |b|/2 or, at |r| = |b|/2, when the quotient is odd.
            let r = e.bin(BinOp::Mod, x, y);
            let ab = e.un(UnOp::Abs, y);
            let half = e.k(0.5);
            let h = e.bin(BinOp::Mul, ab, half);
            let ar = e.un(UnOp::Abs, r);
            let over = e.cmp(Cmp::Gt, ar, h);
            let tie = e.cmp(Cmp::Eq, ar, h);
            let whole = e.bin(BinOp::Sub, x, r);
            let q = e.bin(BinOp::Div, whole, y);
            let two = e.k(2.0);
            let odd = e.bin(BinOp::Mod, q, two);
            let odd = e.un(UnOp::Abs, odd);
            let tie_odd = e.bin(BinOp::Mul, tie, odd);
            let flip = e.bin(BinOp::Add, over, tie_odd);
            let s = e.sign(r);
            let step = e.bin(BinOp::Mul, s, ab);
            let step = e.bin(BinOp::Mul, flip, step);
            e.bin(BinOp::Sub, r, step)
        }
        Func::LogB => {
            let n = e.un(UnOp::Ln, x);
            let d = e.un(UnOp::Ln, y);
            e.bin(BinOp::Div, n, d)
        }
        Func::SqrtStrict => {
            // sqrt(x)·p + ln(2p - 1), p = (x >= 0): ln(-1) is not a number,
            // which gives 0 and the minor fault.
            let zero = e.k(0.0);
            let p = e.cmp(Cmp::Ge, x, zero);
            let one = e.k(1.0);
            let p2 = e.bin(BinOp::Add, p, p);
            let q = e.bin(BinOp::Sub, p2, one);
            let n = e.un(UnOp::Ln, q);
            let s = e.un(UnOp::Sqrt, x);
            let s = e.bin(BinOp::Mul, s, p);
            e.bin(BinOp::Add, s, n)
        }
        Func::SqrtZero => {
            // sqrt(|x|)·(x >= 0): 0 for a negative, without a fault.
            let zero = e.k(0.0);
            let p = e.cmp(Cmp::Ge, x, zero);
            let s = e.un(UnOp::Sqrt, x);
            e.bin(BinOp::Mul, s, p)
        }
        Func::RoundAway => {
            // Round half to even, except at a tie: t + 2(x - t), away from 0.
            let r = e.un(UnOp::Round, x);
            let t = e.un(UnOp::Trunc, x);
            let d = e.bin(BinOp::Sub, x, t);
            let ad = e.un(UnOp::Abs, d);
            let half = e.k(0.5);
            let tie = e.cmp(Cmp::Eq, ad, half);
            let away = e.bin(BinOp::Add, t, d);
            let away = e.bin(BinOp::Add, away, d);
            let diff = e.bin(BinOp::Sub, away, r);
            let fix = e.bin(BinOp::Mul, tie, diff);
            e.bin(BinOp::Add, r, fix)
        }
        Func::Rnd => {
            // Park and Miller's minimal standard generator (s = 16807·s mod
            // 2^31-1) in DINT by Schrage's method, which never overflows; its
            // state is a slot of this call's own, seeded from the slot number.
            // u = (s mod 2^24) / 2^24 is exact in a REAL, in [0, 1).
            let b = &mut *e.b;
            let seed = 1 + (b.layout().counts.i % 1_000_000) as i32;
            let s = b.state_i(seed);
            let k = |b: &mut Builder, v: i32| V::I(b.const_i(v));
            let ti = |b: &mut Builder| V::I(b.temp_i());
            let (sv, q, r, a, m) = (V::I(s), k(b, 127_773), k(b, 2836), k(b, 16_807), k(b, 2_147_483_647));
            let hi = ti(b);
            b.bin(BinOp::Div, sv, q, hi, elem);
            let lo = ti(b);
            b.bin(BinOp::Mod, sv, q, lo, elem);
            let p1 = ti(b);
            b.bin(BinOp::Mul, a, lo, p1, elem);
            let p2 = ti(b);
            b.bin(BinOp::Mul, r, hi, p2, elem);
            let t = ti(b);
            b.bin(BinOp::Sub, p1, p2, t, elem);
            let zero = k(b, 0);
            let neg = ti(b);
            b.bin(BinOp::Cmp(Cmp::Le), t, zero, neg, elem);
            let wrap = ti(b);
            b.bin(BinOp::Mul, neg, m, wrap, elem);
            b.bin(BinOp::Add, t, wrap, sv, elem);
            let two24 = k(b, 1 << 24);
            let low = ti(b);
            b.bin(BinOp::Mod, sv, two24, low, elem);
            let low = b.convert(low, c, elem);
            let scale = e.k(f64::from(1u32 << 24));
            let u = e.bin(BinOp::Div, low, scale);
            let span = e.bin(BinOp::Sub, y, x);
            let off = e.bin(BinOp::Mul, span, u);
            e.bin(BinOp::Add, x, off)
        }
        // Handled above.
        _ => e.un(UnOp::Mov, x),
    }
}
