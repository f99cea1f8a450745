//! The conversions between strings and REAL, LREAL, TIME, LTIME, DATE, TOD,
//! DT and BOOL (docs/st.md "Strings"), as straight-line code of existing IR
//! ops on the string layout of ADR 0017: the text is built from pieces (digits of an
//! integer, literals, runs of zeros) with `cut`, `shift` and `concat`, and a
//! number is read with one pass of compares over the characters.

use super::*;
use alba_ir::op::{D, F, L};

/// A floating-point value in the slot class of its type: REAL in F slots
/// (the board has them), LREAL in D slots.
#[derive(Clone, Copy)]
enum Fp {
    F(F),
    D(D),
}

impl Lower<'_> {
    /// The ASCII `text` as a string value (constant slots, no op).
    pub(super) fn str_text(&mut self, text: &str) -> Str {
        let chars = text.bytes().map(|x| self.b.const_i(i32::from(x))).collect();
        Str {
            len: self.b.const_i(text.len() as i32),
            chars,
            known: Some(text.len()),
        }
    }

    /// `s` cut to `n` characters when `b` is set (0 otherwise), in temporaries.
    fn keep_if(&mut self, s: &Str, b: B, n: I) -> Str {
        let mut r = self.str_copy(s, s.cap());
        let (zero, k) = (self.b.const_i(0), self.b.temp_i());
        self.emit(Op::UnI(IUn::Mov, zero, k));
        self.emit(Op::Xic(b));
        self.emit(Op::UnI(IUn::Mov, n, k));
        self.emit(Op::True);
        self.cut(&mut r, k);
        r
    }

    /// `a` when `b` is set, else `c` (both kept), in temporaries.
    fn str_choose(&mut self, b: B, a: &Str, c: &Str) -> Str {
        let cap = a.cap().max(c.cap());
        let r = self.str_copy(c, cap);
        let zero = self.b.const_i(0);
        self.emit(Op::Xic(b));
        self.emit(Op::UnI(IUn::Mov, a.len, r.len));
        for (k, &d) in r.chars.iter().enumerate() {
            self.emit(Op::UnI(IUn::Mov, a.chars.get(k).copied().unwrap_or(zero), d));
        }
        self.emit(Op::True);
        Str { known: None, ..r }
    }

    /// `n` zeros (0 ≤ n ≤ most).
    fn zeros(&mut self, n: I, most: usize) -> Str {
        let z = self.str_text(&"0".repeat(most));
        let mut r = self.str_copy(&z, most);
        self.cut(&mut r, n);
        r
    }

    /// `d = max(a, lo)` for a constant `lo`, in a new temporary.
    fn at_least(&mut self, a: I, lo: i32) -> I {
        let (t, c) = (self.b.temp_i(), self.b.const_i(lo));
        self.emit(Op::UnI(IUn::Mov, a, t));
        self.emit(Op::CmpI(Cmp::Lt, t, c));
        self.emit(Op::UnI(IUn::Mov, c, t));
        self.emit(Op::True);
        t
    }

    fn fp_const(&mut self, like: Fp, v: f64) -> Fp {
        match like {
            Fp::F(_) => Fp::F(self.b.const_f(v as f32)),
            Fp::D(_) => Fp::D(self.b.const_d(v)),
        }
    }

    fn fp_temp(&mut self, like: Fp) -> Fp {
        match like {
            Fp::F(_) => Fp::F(self.b.temp_f()),
            Fp::D(_) => Fp::D(self.b.temp_d()),
        }
    }

    fn fp_cmp(&mut self, c: Cmp, a: Fp, b: Fp) {
        match (a, b) {
            (Fp::F(a), Fp::F(b)) => self.emit(Op::CmpF(c, a, b)),
            (Fp::D(a), Fp::D(b)) => self.emit(Op::CmpD(c, a, b)),
            _ => 0,
        };
    }

    fn fp_bin(&mut self, op: IBin, a: Fp, b: Fp, d: Fp) {
        match (a, b, d) {
            (Fp::F(a), Fp::F(b), Fp::F(d)) => self.emit(Op::BinF(op, a, b, d)),
            (Fp::D(a), Fp::D(b), Fp::D(d)) => self.emit(Op::BinD(op, a, b, d)),
            _ => 0,
        };
    }

    fn fp_un(&mut self, op: IUn, a: Fp, d: Fp) {
        match (a, d) {
            (Fp::F(a), Fp::F(d)) => self.emit(Op::UnF(op, a, d)),
            (Fp::D(a), Fp::D(d)) => self.emit(Op::UnD(op, a, d)),
            _ => 0,
        };
    }

    /// `REAL_TO_STRING`, `LREAL_TO_STRING`: the value rounded to 7 (REAL)
    /// or 15 (LREAL) significant digits, without trailing zeros, written as
    /// an ST literal: `-` first when negative, a point and at least one digit
    /// after it (`12.5`, `100.0`, `0.001`), and an exponent (`1.5E20`,
    /// `2.0E-7`) when the exponent is below -5 or reaches the digits; 0 is
    /// `0.0`.
    fn real_text(&mut self, x: Fp) -> Str {
        let (digits, top): (usize, u32) = match x {
            Fp::F(_) => (7, 32),
            Fp::D(_) => (15, 256),
        };
        let (zero_f, neg, is_zero) = (self.fp_const(x, 0.0), self.b.temp_b(), self.b.temp_b());
        self.fp_cmp(Cmp::Lt, x, zero_f);
        self.emit(Op::Ote(neg));
        self.emit(Op::True);
        self.fp_cmp(Cmp::Eq, x, zero_f);
        self.emit(Op::Ote(is_zero));
        self.emit(Op::True);
        // s = |x| scaled into [1, 10) by powers of ten, e the exponent.
        let s = self.fp_temp(x);
        self.fp_un(IUn::Abs, x, s);
        let e = self.b.temp_i();
        let zero = self.b.const_i(0);
        self.emit(Op::UnI(IUn::Mov, zero, e));
        self.emit(Op::Xic(is_zero));
        let one_f = self.fp_const(x, 1.0);
        self.fp_un(IUn::Mov, one_f, s);
        self.emit(Op::True);
        let mut k = top;
        while k >= 1 {
            let (p, kc) = (self.fp_const(x, 10f64.powi(k as i32)), self.b.const_i(k as i32));
            self.fp_cmp(Cmp::Ge, s, p);
            self.fp_bin(IBin::Div, s, p, s);
            self.emit(Op::BinI(IBin::Add, e, kc, e));
            self.emit(Op::True);
            k /= 2;
        }
        let mut k = top;
        while k >= 1 {
            let low = self.fp_const(x, 10f64.powi(1 - k as i32));
            let (p, kc) = (self.fp_const(x, 10f64.powi(k as i32)), self.b.const_i(k as i32));
            self.fp_cmp(Cmp::Lt, s, low);
            self.fp_bin(IBin::Mul, s, p, s);
            self.emit(Op::BinI(IBin::Sub, e, kc, e));
            self.emit(Op::True);
            k /= 2;
        }
        // m: the digits as an integer of exactly `digits` digits.
        let scale = self.fp_const(x, 10f64.powi(digits as i32 - 1));
        let sm = self.fp_temp(x);
        self.fp_bin(IBin::Mul, s, scale, sm);
        let m = self.b.temp_l();
        match sm {
            Fp::F(f) => self.emit(Op::Cvt(alba_ir::op::Cvt::FL(f, m))),
            Fp::D(d) => self.emit(Op::Cvt(alba_ir::op::Cvt::DL(d, m))),
        };
        let (full, ten, one) = (
            self.b.const_l(10i64.pow(digits as u32)),
            self.b.const_l(10),
            self.b.const_i(1),
        );
        self.emit(Op::CmpL(Cmp::Ge, m, full));
        self.emit(Op::BinL(IBin::Div, m, ten, m));
        self.emit(Op::BinI(IBin::Add, e, one, e));
        self.emit(Op::True);
        // n: the significant digits, trailing zeros left out.
        let (n, r, lz) = (self.b.temp_i(), self.b.temp_l(), self.b.const_l(0));
        let dc = self.b.const_i(digits as i32);
        self.emit(Op::UnI(IUn::Mov, dc, n));
        for j in 1..digits {
            let (p, nj) = (self.b.const_l(10i64.pow(j as u32)), self.b.const_i((digits - j) as i32));
            self.emit(Op::BinL(IBin::Mod, m, p, r));
            self.emit(Op::CmpL(Cmp::Eq, r, lz));
            self.emit(Op::UnI(IUn::Mov, nj, n));
            self.emit(Op::True);
        }
        let all = self.int_text(V::L(m), digits);
        let sig = self.left_of(&all, n);
        // With an exponent when e < -5 or e ≥ digits.
        let sci = self.b.temp_b();
        let (lo, hi) = (self.b.const_i(-5), self.b.const_i(digits as i32));
        self.emit(Op::CmpI(Cmp::Lt, e, lo));
        self.emit(Op::Ote(sci));
        self.emit(Op::True);
        self.emit(Op::CmpI(Cmp::Ge, e, hi));
        self.emit(Op::Otl(sci));
        self.emit(Op::True);
        // The digits are z1 zeros, sig, z2 zeros, the point after p of them:
        // z1 = max(0, -e), p = max(1, e + 1) without an exponent; z1 = 0,
        // p = 1 with one; z2 = max(0, p + 1 - z1 - n).
        let ne = self.b.temp_i();
        self.emit(Op::UnI(IUn::Neg, e, ne));
        let z1 = self.at_least(ne, 0);
        let e1 = self.b.temp_i();
        self.emit(Op::BinI(IBin::Add, e, one, e1));
        let p = self.at_least(e1, 1);
        self.emit(Op::Xic(sci));
        self.emit(Op::UnI(IUn::Mov, zero, z1));
        self.emit(Op::UnI(IUn::Mov, one, p));
        self.emit(Op::True);
        let z2 = self.b.temp_i();
        self.emit(Op::BinI(IBin::Add, p, one, z2));
        self.emit(Op::BinI(IBin::Sub, z2, z1, z2));
        self.emit(Op::BinI(IBin::Sub, z2, n, z2));
        let z2 = self.at_least(z2, 0);
        let lead = self.zeros(z1, 5);
        let trail = self.zeros(z2, digits);
        let g = self.concat(&lead, &sig);
        let g = self.concat(&g, &trail);
        let head = self.left_of(&g, p);
        let tail = self.tail_of(&g, p);
        let dot = self.str_text(".");
        let t = self.concat(&head, &dot);
        let t = self.concat(&t, &tail);
        // The exponent, kept only with sci.
        let et = self.int_text(V::I(e), 3);
        let big_e = self.str_text("E");
        let ex = self.concat(&big_e, &et);
        let ex = self.keep_if(&ex, sci, ex.len);
        let t = self.concat(&t, &ex);
        // The sign.
        let minus = self.str_text("-");
        let sign = self.keep_if(&minus, neg, one);
        let t = self.concat(&sign, &t);
        let z = self.str_text("0.0");
        self.str_choose(is_zero, &z, &t)
    }

    /// `TIME_TO_STRING` (milliseconds in an I slot) and `LTIME_TO_STRING`
    /// (nanoseconds in an L slot): the literal as CODESYS writes it, `T#`
    /// (`LTIME#`) and every unit that is not 0 from days down
    /// (`T#1d2h3m4s5ms`, `T#-1s500ms`, `LTIME#1ms2us3ns`); 0 is `T#0ms`
    /// (`LTIME#0ns`).
    fn time_text(&mut self, v: V, long: bool) -> Str {
        // (unit, its count of the smallest one, most digits of its part)
        let units: &[(&str, i64, usize)] = if long {
            &[
                ("d", 86_400_000_000_000, 6),
                ("h", 3_600_000_000_000, 2),
                ("m", 60_000_000_000, 2),
                ("s", 1_000_000_000, 2),
                ("ms", 1_000_000, 3),
                ("us", 1_000, 3),
                ("ns", 1, 3),
            ]
        } else {
            &[
                ("d", 86_400_000, 2),
                ("h", 3_600_000, 2),
                ("m", 60_000, 2),
                ("s", 1_000, 2),
                ("ms", 1, 3),
            ]
        };
        let x = self.b.convert(v, Class::L, self.elem);
        let V::L(x) = x else {
            return self.str_text("");
        };
        let (neg, a) = self.abs_l(x);
        let lz = self.b.const_l(0);
        let mut text = self.str_text(if long { "LTIME#" } else { "T#" });
        let minus = self.str_text("-");
        let one = self.b.const_i(1);
        let sign = self.keep_if(&minus, neg, one);
        text = self.concat(&text, &sign);
        let mut above: Option<i64> = None;
        for &(unit, per, width) in units {
            let part = self.b.temp_l();
            let c = self.b.const_l(per);
            self.emit(Op::BinL(IBin::Div, a, c, part));
            if let Some(up) = above {
                let m = self.b.const_l(up / per);
                self.emit(Op::BinL(IBin::Mod, part, m, part));
            }
            above = Some(per);
            let nz = self.b.temp_b();
            self.emit(Op::CmpL(Cmp::Ne, part, lz));
            self.emit(Op::Ote(nz));
            self.emit(Op::True);
            let digits = self.int_text(V::L(part), width);
            let u = self.str_text(unit);
            let piece = self.concat(&digits, &u);
            let piece = self.keep_if(&piece, nz, piece.len);
            text = self.concat(&text, &piece);
        }
        // Nothing but the prefix (and no sign): 0 of the smallest unit.
        let (is_zero, smallest) = (self.b.temp_b(), units[units.len() - 1].0);
        self.emit(Op::CmpL(Cmp::Eq, a, lz));
        self.emit(Op::Ote(is_zero));
        self.emit(Op::True);
        let z = self.str_text(&format!("{}0{smallest}", if long { "LTIME#" } else { "T#" }));
        self.str_choose(is_zero, &z, &text)
    }

    /// The decimal text of `v` (0 ≤ v < 10^width) with leading zeros to
    /// `width` digits.
    fn padded(&mut self, v: L, width: usize) -> Str {
        let t = self.int_text(V::L(v), width);
        let (w, k) = (self.b.const_i(width as i32), self.b.temp_i());
        self.emit(Op::BinI(IBin::Sub, w, t.len, k));
        let z = self.zeros(k, width);
        self.concat(&z, &t)
    }

    /// `floor(x / d)` and `x - floor(x / d) * d` for a constant `d > 0`.
    fn floor_div(&mut self, x: L, d: i64) -> (L, L) {
        let (dc, lz, one) = (self.b.const_l(d), self.b.const_l(0), self.b.const_l(1));
        let (q, r) = (self.b.temp_l(), self.b.temp_l());
        self.emit(Op::BinL(IBin::Div, x, dc, q));
        self.emit(Op::BinL(IBin::Mod, x, dc, r));
        self.emit(Op::CmpL(Cmp::Lt, r, lz));
        self.emit(Op::BinL(IBin::Sub, q, one, q));
        self.emit(Op::BinL(IBin::Add, r, dc, r));
        self.emit(Op::True);
        (q, r)
    }

    /// `YYYY-MM-DD` of a count of days since 1970-01-01 (proleptic
    /// Gregorian calendar; H. Hinnant's `civil_from_days`, all divisions of
    /// non-negative numbers once `era` is floored).
    fn date_part(&mut self, days: L) -> Str {
        let c = |l: &mut Self, v: i64| l.b.const_l(v);
        let z = self.b.temp_l();
        let shift = c(self, 719_468);
        self.emit(Op::BinL(IBin::Add, days, shift, z));
        let (era, doe) = self.floor_div(z, 146_097);
        let t = self.b.temp_l();
        let yoe = self.b.temp_l();
        // yoe = (doe - doe/1460 + doe/36524 - doe/146096) / 365
        self.emit(Op::UnL(IUn::Mov, doe, yoe));
        for (k, add) in [(1460, false), (36_524, true), (146_096, false)] {
            let kc = c(self, k);
            self.emit(Op::BinL(IBin::Div, doe, kc, t));
            self.emit(Op::BinL(if add { IBin::Add } else { IBin::Sub }, yoe, t, yoe));
        }
        let c365 = c(self, 365);
        self.emit(Op::BinL(IBin::Div, yoe, c365, yoe));
        let y = self.b.temp_l();
        let c400 = c(self, 400);
        self.emit(Op::BinL(IBin::Mul, era, c400, y));
        self.emit(Op::BinL(IBin::Add, y, yoe, y));
        // doy = doe - (365*yoe + yoe/4 - yoe/100)
        let doy = self.b.temp_l();
        self.emit(Op::BinL(IBin::Mul, yoe, c365, t));
        self.emit(Op::BinL(IBin::Sub, doe, t, doy));
        for (k, add) in [(4, false), (100, true)] {
            let kc = c(self, k);
            self.emit(Op::BinL(IBin::Div, yoe, kc, t));
            self.emit(Op::BinL(if add { IBin::Add } else { IBin::Sub }, doy, t, doy));
        }
        // mp = (5*doy + 2)/153; d = doy - (153*mp + 2)/5 + 1; m = mp < 10 ? mp + 3 : mp - 9
        let (c5, c2, c153, c1) = (c(self, 5), c(self, 2), c(self, 153), c(self, 1));
        let (mp, d, m) = (self.b.temp_l(), self.b.temp_l(), self.b.temp_l());
        self.emit(Op::BinL(IBin::Mul, doy, c5, mp));
        self.emit(Op::BinL(IBin::Add, mp, c2, mp));
        self.emit(Op::BinL(IBin::Div, mp, c153, mp));
        self.emit(Op::BinL(IBin::Mul, mp, c153, t));
        self.emit(Op::BinL(IBin::Add, t, c2, t));
        self.emit(Op::BinL(IBin::Div, t, c5, t));
        self.emit(Op::BinL(IBin::Sub, doy, t, d));
        self.emit(Op::BinL(IBin::Add, d, c1, d));
        let (c3, c9, c10) = (c(self, 3), c(self, 9), c(self, 10));
        self.emit(Op::BinL(IBin::Add, mp, c3, m));
        self.emit(Op::CmpL(Cmp::Ge, mp, c10));
        self.emit(Op::BinL(IBin::Sub, mp, c9, m));
        self.emit(Op::True);
        self.emit(Op::CmpL(Cmp::Le, m, c2));
        self.emit(Op::BinL(IBin::Add, y, c1, y));
        self.emit(Op::True);
        let year = self.int_text(V::L(y), 9);
        let (mm, dd) = (self.padded(m, 2), self.padded(d, 2));
        let dash = self.str_text("-");
        let t1 = self.concat(&year, &dash);
        let t1 = self.concat(&t1, &mm);
        let t1 = self.concat(&t1, &dash);
        self.concat(&t1, &dd)
    }

    /// `hh:mm:ss` and `.f` (the milliseconds without trailing zeros, none
    /// when 0) of a count of milliseconds since midnight (0 or more).
    fn time_of_day_part(&mut self, ms: L) -> Str {
        let c = |l: &mut Self, v: i64| l.b.const_l(v);
        let (h, mi, s, f) = (self.b.temp_l(), self.b.temp_l(), self.b.temp_l(), self.b.temp_l());
        let (c3600k, c60k, c1k, c60) = (c(self, 3_600_000), c(self, 60_000), c(self, 1000), c(self, 60));
        self.emit(Op::BinL(IBin::Div, ms, c3600k, h));
        self.emit(Op::BinL(IBin::Div, ms, c60k, mi));
        self.emit(Op::BinL(IBin::Mod, mi, c60, mi));
        self.emit(Op::BinL(IBin::Div, ms, c1k, s));
        self.emit(Op::BinL(IBin::Mod, s, c60, s));
        self.emit(Op::BinL(IBin::Mod, ms, c1k, f));
        let colon = self.str_text(":");
        let (hh, mm, ss) = (self.padded(h, 2), self.padded(mi, 2), self.padded(s, 2));
        let t = self.concat(&hh, &colon);
        let t = self.concat(&t, &mm);
        let t = self.concat(&t, &colon);
        let t = self.concat(&t, &ss);
        // The fraction: 3 digits less its trailing zeros, after a point.
        let (n, r, lz) = (self.b.temp_i(), self.b.temp_l(), self.b.const_l(0));
        let three = self.b.const_i(3);
        self.emit(Op::UnI(IUn::Mov, three, n));
        for (p, digits) in [(10, 2), (100, 1)] {
            let (pc, dc) = (c(self, p), self.b.const_i(digits));
            self.emit(Op::BinL(IBin::Mod, f, pc, r));
            self.emit(Op::CmpL(Cmp::Eq, r, lz));
            self.emit(Op::UnI(IUn::Mov, dc, n));
            self.emit(Op::True);
        }
        let digits = self.padded(f, 3);
        let digits = self.left_of(&digits, n);
        let point = self.str_text(".");
        let frac = self.concat(&point, &digits);
        let (some, one) = (self.b.temp_b(), self.b.const_i(1));
        self.emit(Op::CmpL(Cmp::Ne, f, lz));
        self.emit(Op::Ote(some));
        self.emit(Op::True);
        let len = self.b.temp_i();
        self.emit(Op::BinI(IBin::Add, n, one, len));
        let frac = self.keep_if(&frac, some, len);
        self.concat(&t, &frac)
    }

    /// `DATE_TO_STRING` (`D#2024-01-31`), `TOD_TO_STRING`
    /// (`TOD#12:30:15.5`), `DT_TO_STRING` (`DT#2024-01-31-12:30:00`) of
    /// their milliseconds.
    fn date_text(&mut self, x: L, ty: &Ty) -> Str {
        let (prefix, date, tod) = match ty {
            Ty::Date => ("D#", true, false),
            Ty::Tod => ("TOD#", false, true),
            _ => ("DT#", true, true),
        };
        let mut text = self.str_text(prefix);
        let (days, rem) = if date {
            self.floor_div(x, 86_400_000)
        } else {
            (self.b.const_l(0), x)
        };
        if date {
            let d = self.date_part(days);
            text = self.concat(&text, &d);
        }
        if date && tod {
            let dash = self.str_text("-");
            text = self.concat(&text, &dash);
        }
        if tod {
            let t = self.time_of_day_part(rem);
            text = self.concat(&text, &t);
        }
        text
    }

    /// `BOOL_TO_STRING`: `TRUE` or `FALSE`.
    fn bool_text(&mut self, b: B) -> Str {
        let (t, f) = (self.str_text("TRUE"), self.str_text("FALSE"));
        self.str_choose(b, &t, &f)
    }

    /// A value of type `from` (REAL, LREAL, TIME, LTIME, DATE, TOD, DT, BOOL,
    /// an integer or a bit string) as its text; `None` for other types.
    pub(super) fn text_of(&mut self, v: Val, from: &Ty) -> Option<Str> {
        Some(match (v, from) {
            (Val::B(b), Ty::Bool) => self.bool_text(b),
            (Val::N(V::F(f)), Ty::Real) => self.real_text(Fp::F(f)),
            (Val::N(V::D(d)), Ty::Lreal) => self.real_text(Fp::D(d)),
            (Val::N(x), Ty::Time) => self.time_text(x, false),
            (Val::N(x), Ty::Ltime) => self.time_text(x, true),
            (Val::N(V::L(x)), t @ (Ty::Date | Ty::Tod | Ty::Dt)) => self.date_text(x, t),
            (Val::N(x), t) if t.is_int() || t.is_bits() => self.int_text(x, 19),
            _ => return None,
        })
    }

    /// `STRING_TO_BOOL`: TRUE when the text is `TRUE` in any case or the
    /// number at its start (as `STRING_TO_INT` reads it) is not 0.
    pub(super) fn string_to_bool(&mut self, s: &Str) -> B {
        let up = self.str_copy(s, s.cap());
        let (a, z, d) = (self.b.const_i(97), self.b.const_i(122), self.b.const_i(32));
        for &c in &up.chars {
            self.emit(Op::CmpI(Cmp::Ge, c, a));
            self.emit(Op::CmpI(Cmp::Le, c, z));
            self.emit(Op::BinI(IBin::Sub, c, d, c));
            self.emit(Op::True);
        }
        let t = self.str_text("TRUE");
        let word = self.str_compare(Cmp::Eq, &up, &t);
        let r = self.b.temp_b();
        self.emit(Op::Ld(word));
        self.emit(Op::Ote(r));
        self.emit(Op::True);
        if let V::L(n) = self.string_to_int(s) {
            let lz = self.b.const_l(0);
            self.emit(Op::CmpL(Cmp::Ne, n, lz));
            self.emit(Op::Otl(r));
            self.emit(Op::True);
        }
        r
    }

    /// The rungs of a literal's prefix for one character, read in phase
    /// `at[0]`: spaces, then letters (and `_` when `under`), which set
    /// `prefix`, and its `#`, which moves to phase `at[1]`; once a prefix
    /// began, any other character moves to `at[2]` (the reading ends).
    fn prefix_rungs(&mut self, r: Reading, at: [I; 3], prefix: B, under: bool) {
        let c = |l: &mut Self, v: u8| l.b.const_i(i32::from(v));
        let (space, hash, la, lz, us) = (
            c(self, b' '),
            c(self, b'#'),
            c(self, b'a'),
            c(self, b'z'),
            c(self, b'_'),
        );
        self.emit(Op::Xio(r.done));
        self.emit(Op::Xio(prefix));
        self.emit(Op::CmpI(Cmp::Eq, r.phase, at[0]));
        self.emit(Op::CmpI(Cmp::Eq, r.ch, space));
        self.emit(Op::Otl(r.done));
        self.emit(Op::True);
        self.emit(Op::Xio(r.done));
        self.emit(Op::CmpI(Cmp::Eq, r.phase, at[0]));
        self.emit(Op::CmpI(Cmp::Ge, r.lc, la));
        self.emit(Op::CmpI(Cmp::Le, r.lc, lz));
        self.emit(Op::Otl(prefix));
        self.emit(Op::Otl(r.done));
        self.emit(Op::True);
        let marks = if under {
            vec![(us, at[0]), (hash, at[1])]
        } else {
            vec![(hash, at[1])]
        };
        for (mark, next) in marks {
            self.emit(Op::Xio(r.done));
            self.emit(Op::Xic(prefix));
            self.emit(Op::CmpI(Cmp::Eq, r.phase, at[0]));
            self.emit(Op::CmpI(Cmp::Eq, r.ch, mark));
            self.emit(Op::UnI(IUn::Mov, next, r.phase));
            self.emit(Op::Otl(r.done));
            self.emit(Op::True);
        }
        self.emit(Op::Xio(r.done));
        self.emit(Op::Xic(prefix));
        self.emit(Op::CmpI(Cmp::Eq, r.phase, at[0]));
        self.emit(Op::UnI(IUn::Mov, at[2], r.phase));
        self.emit(Op::Otl(r.done));
        self.emit(Op::True);
    }

    /// The rung of a digit of a fraction, read in phase `at` (`dl` its
    /// value): of the fraction `frac` / `scale`, the first three digits count
    /// (`fd` those so far), the others are read.
    fn fraction_rung(&mut self, r: Reading, dl: L, at: I, [frac, scale]: [L; 2], fd: I) {
        let (c0, c9, one, three) = (
            self.b.const_i(48),
            self.b.const_i(57),
            self.b.const_i(1),
            self.b.const_i(3),
        );
        let tenl = self.b.const_l(10);
        self.emit(Op::Xio(r.done));
        self.emit(Op::CmpI(Cmp::Ge, r.ch, c0));
        self.emit(Op::CmpI(Cmp::Le, r.ch, c9));
        self.emit(Op::CmpI(Cmp::Eq, r.phase, at));
        self.emit(Op::Otl(r.done));
        self.emit(Op::CmpI(Cmp::Lt, fd, three));
        self.emit(Op::BinL(IBin::Mul, frac, tenl, frac));
        self.emit(Op::BinL(IBin::Add, frac, dl, frac));
        self.emit(Op::BinL(IBin::Mul, scale, tenl, scale));
        self.emit(Op::BinI(IBin::Add, fd, one, fd));
        self.emit(Op::True);
    }

    /// `STRING_TO_TIME`, `STRING_TO_LTIME`: a duration literal, as
    /// `TIME_TO_STRING` writes it and more: spaces first skipped, an optional
    /// prefix (letters and `#`: `T#`, `TIME#`, `LT#`, `LTIME#`, any case), an
    /// optional sign, then groups of a number (`_` between digits and groups
    /// allowed, an optional fraction of which the first three digits count)
    /// and its unit `d` `h` `m` `s` `ms` `us` `ns` (any case), in any order:
    /// `'T#1h30m'`, `'-1.5s'`, `'ltime#2us3ns'`, `'TIME#6d_3h'`. Reading ends at
    /// the first other character; the groups read by then count (`'5s!'` is
    /// 5 s, `'abc'` and a number without its unit 0). Computed in LINT
    /// nanoseconds: an LTIME, or for a TIME the milliseconds (truncated; too
    /// large a value is the engine's overflow fault, as for `STRING_TO_DINT`).
    pub(super) fn string_to_time(&mut self, s: &Str, long: bool) -> Val {
        let ci = |l: &mut Self, v: i32| l.b.const_i(v);
        let cl = |l: &mut Self, v: i64| l.b.const_l(v);
        let letter = |l: &mut Self, c: u8| l.b.const_i(i32::from(c));
        let ph: Vec<I> = (0..5).map(|k| ci(self, k)).collect();
        let (zl, onel, tenl) = (cl(self, 0), cl(self, 1), cl(self, 10));
        let (c0, c9) = (ci(self, 48), ci(self, 57));
        // (`c | 32` is the lower case of a letter, and leaves digits and signs as they are)
        let (space, minus, plus, under, point) = (ci(self, 32), ci(self, 45), ci(self, 43), ci(self, 95), ci(self, 46));
        let ls = letter(self, b's');
        // Phase 0: spaces and the prefix; 1: a group may start; 2: its digits;
        // 3: its fraction; 4: ended.
        let (phase, fd, lc, d) = (self.b.temp_i(), self.b.temp_i(), self.b.temp_i(), self.b.temp_i());
        let [num, frac, scale, total, part, dl, unit] = [(); 7].map(|_| self.b.temp_l());
        let [neg, prefix, grouped, done, pm, pu, pn, go] = [(); 8].map(|_| self.b.temp_b());
        for t in [num, frac, total] {
            self.emit(Op::UnL(IUn::Mov, zl, t));
        }
        self.emit(Op::UnL(IUn::Mov, onel, scale));
        self.emit(Op::UnI(IUn::Mov, ph[0], phase));
        self.emit(Op::UnI(IUn::Mov, ph[0], fd));
        self.emit(Op::Afi);
        for b in [neg, prefix, grouped, pm, pu, pn] {
            self.emit(Op::Ote(b));
        }
        self.emit(Op::True);
        // When `go` is set: adds the group read (`num.frac` of `unit`
        // nanoseconds) and starts the next group; `go` is cleared.
        let apply = |l: &mut Self| {
            l.emit(Op::Xic(go));
            l.emit(Op::BinL(IBin::Mul, num, unit, part));
            l.emit(Op::BinL(IBin::Add, total, part, total));
            l.emit(Op::BinL(IBin::Mul, frac, unit, part));
            l.emit(Op::BinL(IBin::Div, part, scale, part));
            l.emit(Op::BinL(IBin::Add, total, part, total));
            l.emit(Op::UnL(IUn::Mov, zl, num));
            l.emit(Op::UnL(IUn::Mov, zl, frac));
            l.emit(Op::UnL(IUn::Mov, onel, scale));
            l.emit(Op::UnI(IUn::Mov, ph[0], fd));
            l.emit(Op::UnI(IUn::Mov, ph[1], phase));
            l.emit(Op::Otl(grouped));
            l.emit(Op::Otu(go));
            l.emit(Op::True);
        };
        // On the rung so far: the unit is `u` nanoseconds, `go`, and the
        // character is read when `consume`.
        let take = |l: &mut Self, u: i64, consume: bool| {
            let u = cl(l, u);
            l.emit(Op::UnL(IUn::Mov, u, unit));
            l.emit(Op::Otl(go));
            if consume {
                l.emit(Op::Otl(done));
            }
            l.emit(Op::True);
        };
        self.emit(Op::Afi);
        self.emit(Op::Ote(go));
        self.emit(Op::True);
        for &ch in &s.chars {
            self.emit(Op::BinI(IBin::Or, ch, space, lc));
            self.emit(Op::CmpI(Cmp::Eq, phase, ph[4]));
            self.emit(Op::Ote(done));
            self.emit(Op::True);
            // A pending `m` is `ms` or else minutes (and this character is
            // read on); a pending `u` or `n` needs its `s`.
            self.emit(Op::Xio(done));
            self.emit(Op::Xic(pm));
            self.emit(Op::CmpI(Cmp::Eq, lc, ls));
            take(self, 1_000_000, true);
            self.emit(Op::Xio(done));
            self.emit(Op::Xic(pm));
            take(self, 60_000_000_000, false);
            for (flag, u) in [(pu, 1_000), (pn, 1)] {
                self.emit(Op::Xio(done));
                self.emit(Op::Xic(flag));
                self.emit(Op::CmpI(Cmp::Eq, lc, ls));
                take(self, u, true);
                self.emit(Op::Xio(done));
                self.emit(Op::Xic(flag));
                self.emit(Op::UnI(IUn::Mov, ph[4], phase));
                self.emit(Op::Otl(done));
                self.emit(Op::True);
            }
            self.emit(Op::Afi);
            for f in [pm, pu, pn] {
                self.emit(Op::Ote(f));
            }
            self.emit(Op::True);
            apply(self);
            // Phase 0: spaces, then the prefix's letters and its `#`.
            let reading = Reading { ch, lc, phase, done };
            self.prefix_rungs(reading, [ph[0], ph[1], ph[4]], prefix, false);
            // A sign before the first group.
            for (sign, flag) in [(minus, Some(neg)), (plus, None)] {
                self.emit(Op::Xio(done));
                self.emit(Op::Xio(grouped));
                self.emit(Op::CmpI(Cmp::Le, phase, ph[1]));
                self.emit(Op::CmpI(Cmp::Eq, ch, sign));
                if let Some(f) = flag {
                    self.emit(Op::Otl(f));
                }
                self.emit(Op::UnI(IUn::Mov, ph[1], phase));
                self.emit(Op::Otl(done));
                self.emit(Op::True);
            }
            // A digit: of the number (phases 0–2), of its fraction (3; the
            // fourth and later are read but do not count).
            self.emit(Op::BinI(IBin::Sub, ch, c0, d));
            self.emit(Op::Cvt(alba_ir::op::Cvt::IL(d, dl)));
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Ge, ch, c0));
            self.emit(Op::CmpI(Cmp::Le, ch, c9));
            self.emit(Op::CmpI(Cmp::Le, phase, ph[2]));
            self.emit(Op::BinL(IBin::Mul, num, tenl, num));
            self.emit(Op::BinL(IBin::Add, num, dl, num));
            self.emit(Op::UnI(IUn::Mov, ph[2], phase));
            self.emit(Op::Otl(done));
            self.emit(Op::True);
            self.fraction_rung(reading, dl, ph[3], [frac, scale], fd);
            // `_` between digits or groups, the point after digits.
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Ge, phase, ph[2]));
            self.emit(Op::CmpI(Cmp::Eq, ch, under));
            self.emit(Op::Otl(done));
            self.emit(Op::True);
            self.emit(Op::Xio(done));
            self.emit(Op::Xic(grouped));
            self.emit(Op::CmpI(Cmp::Eq, phase, ph[1]));
            self.emit(Op::CmpI(Cmp::Eq, ch, under));
            self.emit(Op::Otl(done));
            self.emit(Op::True);
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Eq, phase, ph[2]));
            self.emit(Op::CmpI(Cmp::Eq, ch, point));
            self.emit(Op::UnI(IUn::Mov, ph[3], phase));
            self.emit(Op::Otl(done));
            self.emit(Op::True);
            // A unit after a number: `d`, `h`, `s` at once; `m`, `u`, `n` wait
            // for the next character.
            for (c, u) in [
                (b'd', 86_400_000_000_000),
                (b'h', 3_600_000_000_000),
                (b's', 1_000_000_000),
            ] {
                let c = letter(self, c);
                self.emit(Op::Xio(done));
                self.emit(Op::CmpI(Cmp::Ge, phase, ph[2]));
                self.emit(Op::CmpI(Cmp::Eq, lc, c));
                take(self, u, true);
            }
            apply(self);
            for (c, flag) in [(b'm', pm), (b'u', pu), (b'n', pn)] {
                let c = letter(self, c);
                self.emit(Op::Xio(done));
                self.emit(Op::CmpI(Cmp::Ge, phase, ph[2]));
                self.emit(Op::CmpI(Cmp::Eq, lc, c));
                self.emit(Op::Otl(flag));
                self.emit(Op::Otl(done));
                self.emit(Op::True);
            }
            // Anything else ends the reading.
            self.emit(Op::Xio(done));
            self.emit(Op::UnI(IUn::Mov, ph[4], phase));
            self.emit(Op::True);
        }
        // A last `m` is minutes.
        self.emit(Op::Xic(pm));
        take(self, 60_000_000_000, false);
        apply(self);
        self.emit(Op::Xic(neg));
        self.emit(Op::UnL(IUn::Neg, total, total));
        self.emit(Op::True);
        if long {
            return Val::N(V::L(total));
        }
        let ms = cl(self, 1_000_000);
        self.emit(Op::BinL(IBin::Div, total, ms, total));
        self.convert(Val::N(V::L(total)), &Ty::Lint, &Ty::Dint)
    }

    /// `STRING_TO_DATE`, `STRING_TO_TOD`, `STRING_TO_DT`: a date or time-of-day
    /// literal, as `DATE_TO_STRING` and its kin write it and more: spaces first
    /// skipped, an optional prefix (letters, `_` and `#`: `D#`, `DATE#`, `TOD#`,
    /// `TIME_OF_DAY#`, `DT#`, `DATE_AND_TIME#`, any case), then the fields
    /// `YYYY-MM-DD` (a DATE), `hh:mm[:ss[.fff]]` (a TOD) or both joined by `-`
    /// (a DT), with `_` allowed between digits; of the seconds' fraction the
    /// first three digits count. Reading ends at the first other character. A
    /// text whose fields are missing or out of range (month 13, 30 February,
    /// hour 24) is 0: `D#1970-01-01`, `TOD#00:00:00`, `DT#1970-01-01-00:00:00`,
    /// as `STRING_TO_INT` reads `'abc'` as 0. Computed in LINT milliseconds
    /// (ADR 0017).
    pub(super) fn string_to_date(&mut self, s: &Str, ty: &Ty) -> L {
        let ci = |l: &mut Self, v: i32| l.b.const_i(v);
        let cl = |l: &mut Self, v: i64| l.b.const_l(v);
        let (date, tod) = match ty {
            Ty::Date => (true, false),
            Ty::Tod => (false, true),
            _ => (true, true),
        };
        // The separators after each field but the last, and the field the
        // reading must have reached.
        let mut seps: Vec<u8> = Vec::new();
        if date {
            seps.extend(b"--");
        }
        if date && tod {
            seps.push(b'-');
        }
        if tod {
            seps.extend(b"::");
        }
        let fields = seps.len() + 1;
        let least = match (date, tod) {
            (true, false) => 2,
            (false, true) => 1,
            _ => 4,
        };
        let ph: Vec<I> = (0..4).map(|k| ci(self, k)).collect();
        let at: Vec<I> = (0..fields as i32).map(|k| ci(self, k)).collect();
        let (zl, onel, tenl) = (cl(self, 0), cl(self, 1), cl(self, 10));
        let (zero, one) = (ci(self, 0), ci(self, 1));
        let (space, under, point, c0, c9) = (ci(self, 32), ci(self, 95), ci(self, 46), ci(self, 48), ci(self, 57));
        // Phase 0: spaces and the prefix; 1: the fields; 2: the fraction; 3: ended.
        let (phase, f, nd, fd, lc, d) = [(); 6].map(|_| self.b.temp_i()).into();
        let acc: Vec<L> = (0..fields).map(|_| self.b.temp_l()).collect();
        let [frac, scale, dl] = [(); 3].map(|_| self.b.temp_l());
        let [prefix, done, bad] = [(); 3].map(|_| self.b.temp_b());
        for &a in acc.iter().chain([&frac]) {
            self.emit(Op::UnL(IUn::Mov, zl, a));
        }
        self.emit(Op::UnL(IUn::Mov, onel, scale));
        for i in [phase, f, nd, fd] {
            self.emit(Op::UnI(IUn::Mov, zero, i));
        }
        self.emit(Op::Afi);
        self.emit(Op::Ote(prefix));
        self.emit(Op::True);
        for &ch in &s.chars {
            self.emit(Op::BinI(IBin::Or, ch, space, lc));
            self.emit(Op::CmpI(Cmp::Eq, phase, ph[3]));
            self.emit(Op::Ote(done));
            self.emit(Op::True);
            // Phase 0: spaces, then the prefix's letters and `_`, and its `#`;
            // a prefix without its `#` ends the reading.
            let reading = Reading { ch, lc, phase, done };
            self.prefix_rungs(reading, [ph[0], ph[1], ph[3]], prefix, true);
            // A digit: of the current field (phases 0 and 1), or of the
            // fraction (2; the fourth and later are read but do not count).
            self.emit(Op::BinI(IBin::Sub, ch, c0, d));
            self.emit(Op::Cvt(alba_ir::op::Cvt::IL(d, dl)));
            for (k, &a) in acc.iter().enumerate() {
                self.emit(Op::Xio(done));
                self.emit(Op::CmpI(Cmp::Ge, ch, c0));
                self.emit(Op::CmpI(Cmp::Le, ch, c9));
                self.emit(Op::CmpI(Cmp::Le, phase, ph[1]));
                self.emit(Op::CmpI(Cmp::Eq, f, at[k]));
                self.emit(Op::BinL(IBin::Mul, a, tenl, a));
                self.emit(Op::BinL(IBin::Add, a, dl, a));
                self.emit(Op::True);
            }
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Ge, ch, c0));
            self.emit(Op::CmpI(Cmp::Le, ch, c9));
            self.emit(Op::CmpI(Cmp::Le, phase, ph[1]));
            self.emit(Op::UnI(IUn::Mov, ph[1], phase));
            self.emit(Op::BinI(IBin::Add, nd, one, nd));
            self.emit(Op::Otl(done));
            self.emit(Op::True);
            self.fraction_rung(reading, dl, ph[2], [frac, scale], fd);
            // `_` after a digit; a field's separator after its digits; the
            // point after the seconds' digits.
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Ge, phase, ph[1]));
            self.emit(Op::CmpI(Cmp::Gt, nd, zero));
            self.emit(Op::CmpI(Cmp::Eq, ch, under));
            self.emit(Op::Otl(done));
            self.emit(Op::True);
            for (k, &sep) in seps.iter().enumerate() {
                let c = ci(self, i32::from(sep));
                self.emit(Op::Xio(done));
                self.emit(Op::CmpI(Cmp::Eq, phase, ph[1]));
                self.emit(Op::CmpI(Cmp::Gt, nd, zero));
                self.emit(Op::CmpI(Cmp::Eq, f, at[k]));
                self.emit(Op::CmpI(Cmp::Eq, ch, c));
                self.emit(Op::UnI(IUn::Mov, at[k + 1], f));
                self.emit(Op::UnI(IUn::Mov, zero, nd));
                self.emit(Op::Otl(done));
                self.emit(Op::True);
            }
            if tod {
                self.emit(Op::Xio(done));
                self.emit(Op::CmpI(Cmp::Eq, phase, ph[1]));
                self.emit(Op::CmpI(Cmp::Gt, nd, zero));
                self.emit(Op::CmpI(Cmp::Eq, f, at[fields - 1]));
                self.emit(Op::CmpI(Cmp::Eq, ch, point));
                self.emit(Op::UnI(IUn::Mov, ph[2], phase));
                self.emit(Op::Otl(done));
                self.emit(Op::True);
            }
            // Anything else ends the reading.
            self.emit(Op::Xio(done));
            self.emit(Op::UnI(IUn::Mov, ph[3], phase));
            self.emit(Op::True);
        }
        // Fields missing: the last one read has no digit, or the reading
        // stopped before the least field.
        self.emit(Op::Afi);
        self.emit(Op::Ote(bad));
        self.emit(Op::True);
        let least = ci(self, least);
        self.emit(Op::CmpI(Cmp::Lt, f, least));
        self.emit(Op::Otl(bad));
        self.emit(Op::True);
        self.emit(Op::CmpI(Cmp::Eq, nd, zero));
        self.emit(Op::Otl(bad));
        self.emit(Op::True);
        let out_of = |l: &mut Self, v: L, lo: i64, hi: L| {
            let lo = cl(l, lo);
            l.emit(Op::CmpL(Cmp::Lt, v, lo));
            l.emit(Op::Otl(bad));
            l.emit(Op::True);
            l.emit(Op::CmpL(Cmp::Gt, v, hi));
            l.emit(Op::Otl(bad));
            l.emit(Op::True);
        };
        let total = self.b.temp_l();
        self.emit(Op::UnL(IUn::Mov, zl, total));
        let t = self.b.temp_l();
        if date {
            let (y, m, dd) = (acc[0], acc[1], acc[2]);
            let c12 = cl(self, 12);
            out_of(self, m, 1, c12);
            // The days of month `m` of year `y`.
            let dim = self.b.temp_l();
            let c31 = cl(self, 31);
            self.emit(Op::UnL(IUn::Mov, c31, dim));
            let c30 = cl(self, 30);
            for month in [4, 6, 9, 11] {
                let mc = cl(self, month);
                self.emit(Op::CmpL(Cmp::Eq, m, mc));
                self.emit(Op::UnL(IUn::Mov, c30, dim));
                self.emit(Op::True);
            }
            let leap = self.b.temp_b();
            self.emit(Op::Afi);
            self.emit(Op::Ote(leap));
            self.emit(Op::True);
            let (c4, c100, c400) = (cl(self, 4), cl(self, 100), cl(self, 400));
            let (r4, r100, r400) = (self.b.temp_l(), self.b.temp_l(), self.b.temp_l());
            self.emit(Op::BinL(IBin::Mod, y, c4, r4));
            self.emit(Op::BinL(IBin::Mod, y, c100, r100));
            self.emit(Op::BinL(IBin::Mod, y, c400, r400));
            self.emit(Op::CmpL(Cmp::Eq, r4, zl));
            self.emit(Op::CmpL(Cmp::Ne, r100, zl));
            self.emit(Op::Otl(leap));
            self.emit(Op::True);
            self.emit(Op::CmpL(Cmp::Eq, r400, zl));
            self.emit(Op::Otl(leap));
            self.emit(Op::True);
            let (c2, c28) = (cl(self, 2), cl(self, 28));
            self.emit(Op::CmpL(Cmp::Eq, m, c2));
            self.emit(Op::UnL(IUn::Mov, c28, dim));
            self.emit(Op::Xic(leap));
            self.emit(Op::BinL(IBin::Add, dim, onel, dim));
            self.emit(Op::True);
            out_of(self, dd, 1, dim);
            // H. Hinnant's `days_from_civil` (as `dates::days_from_civil`).
            let yy = self.b.temp_l();
            self.emit(Op::UnL(IUn::Mov, y, yy));
            self.emit(Op::CmpL(Cmp::Le, m, c2));
            self.emit(Op::BinL(IBin::Sub, yy, onel, yy));
            self.emit(Op::True);
            let (era, yoe) = self.floor_div(yy, 400);
            let (c9l, c153, c5, c365) = (cl(self, 9), cl(self, 153), cl(self, 5), cl(self, 365));
            let doy = self.b.temp_l();
            self.emit(Op::BinL(IBin::Add, m, c9l, doy));
            self.emit(Op::BinL(IBin::Mod, doy, c12, doy));
            self.emit(Op::BinL(IBin::Mul, doy, c153, doy));
            self.emit(Op::BinL(IBin::Add, doy, c2, doy));
            self.emit(Op::BinL(IBin::Div, doy, c5, doy));
            self.emit(Op::BinL(IBin::Add, doy, dd, doy));
            self.emit(Op::BinL(IBin::Sub, doy, onel, doy));
            let days = self.b.temp_l();
            self.emit(Op::BinL(IBin::Mul, yoe, c365, days));
            self.emit(Op::BinL(IBin::Div, yoe, c4, t));
            self.emit(Op::BinL(IBin::Add, days, t, days));
            self.emit(Op::BinL(IBin::Div, yoe, c100, t));
            self.emit(Op::BinL(IBin::Sub, days, t, days));
            self.emit(Op::BinL(IBin::Add, days, doy, days));
            let (c146097, c719468, cday) = (cl(self, 146_097), cl(self, 719_468), cl(self, 86_400_000));
            self.emit(Op::BinL(IBin::Mul, era, c146097, t));
            self.emit(Op::BinL(IBin::Add, days, t, days));
            self.emit(Op::BinL(IBin::Sub, days, c719468, days));
            self.emit(Op::BinL(IBin::Mul, days, cday, total));
        }
        if tod {
            let (h, mi, sec) = (acc[fields - 3], acc[fields - 2], acc[fields - 1]);
            let (c23, c59) = (cl(self, 23), cl(self, 59));
            out_of(self, h, 0, c23);
            out_of(self, mi, 0, c59);
            out_of(self, sec, 0, c59);
            for (v, ms) in [(h, 3_600_000), (mi, 60_000), (sec, 1000)] {
                let msc = cl(self, ms);
                self.emit(Op::BinL(IBin::Mul, v, msc, t));
                self.emit(Op::BinL(IBin::Add, total, t, total));
            }
            let c1000 = cl(self, 1000);
            self.emit(Op::BinL(IBin::Mul, frac, c1000, t));
            self.emit(Op::BinL(IBin::Div, t, scale, t));
            self.emit(Op::BinL(IBin::Add, total, t, total));
        }
        self.emit(Op::Xic(bad));
        self.emit(Op::UnL(IUn::Mov, zl, total));
        self.emit(Op::True);
        total
    }

    /// `STRING_TO_REAL`, `STRING_TO_LREAL`: the number at the start of the
    /// text (spaces first skipped, an optional sign, digits with an optional
    /// `.` and fraction, an optional exponent `E`/`e` with its sign); it ends
    /// at the first other character (`'1.5E3x'` is 1500.0, `'abc'` 0.0).
    /// Read into an LREAL when `wide_fp`, else a REAL.
    pub(super) fn string_to_real(&mut self, s: &Str, wide_fp: bool) -> V {
        let like = if wide_fp {
            Fp::D(self.b.temp_d())
        } else {
            Fp::F(self.b.temp_f())
        };
        let (zero_f, ten_f) = (self.fp_const(like, 0.0), self.fp_const(like, 10.0));
        let c = |l: &mut Self, v: i32| l.b.const_i(v);
        let (zero, one) = (c(self, 0), c(self, 1));
        let (space, minus, plus, point, c0, c9, ue, le) = (
            c(self, 32),
            c(self, 45),
            c(self, 43),
            c(self, 46),
            c(self, 48),
            c(self, 57),
            c(self, 69),
            c(self, 101),
        );
        let ph: Vec<I> = (0..6).map(|k| c(self, k)).collect();
        let v = self.fp_temp(like);
        self.fp_un(IUn::Mov, zero_f, v);
        // Phase 0: spaces; 1: integer digits; 2: fraction digits; 3: after
        // `E`; 4: exponent digits; 5: ended.
        let (phase, fd, ex) = (self.b.temp_i(), self.b.temp_i(), self.b.temp_i());
        let (neg, eneg, seen, done) = (self.b.temp_b(), self.b.temp_b(), self.b.temp_b(), self.b.temp_b());
        for t in [phase, fd, ex] {
            self.emit(Op::UnI(IUn::Mov, zero, t));
        }
        self.emit(Op::Afi);
        for b in [neg, eneg, seen] {
            self.emit(Op::Ote(b));
        }
        self.emit(Op::True);
        let (ci, dv) = (self.b.temp_i(), self.fp_temp(like));
        let most_ex = c(self, 1000);
        for &ch in &s.chars {
            // A space in phase 0 is skipped.
            self.emit(Op::CmpI(Cmp::Eq, phase, ph[0]));
            self.emit(Op::CmpI(Cmp::Eq, ch, space));
            self.emit(Op::Ote(done));
            self.emit(Op::True);
            // A sign in phase 0 (of the number) or 3 (of the exponent).
            for (at, sign, flag, next) in [
                (0, minus, Some(neg), 1),
                (0, plus, None, 1),
                (3, minus, Some(eneg), 4),
                (3, plus, None, 4),
            ] {
                self.emit(Op::Xio(done));
                self.emit(Op::CmpI(Cmp::Eq, phase, ph[at]));
                self.emit(Op::CmpI(Cmp::Eq, ch, sign));
                if let Some(f) = flag {
                    self.emit(Op::Otl(f));
                }
                self.emit(Op::Otl(done));
                self.emit(Op::UnI(IUn::Mov, ph[next], phase));
                self.emit(Op::True);
            }
            // A digit: of the number in phases 0–2, of the exponent in 3–4.
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Ge, ch, c0));
            self.emit(Op::CmpI(Cmp::Le, ch, c9));
            self.emit(Op::CmpI(Cmp::Le, phase, ph[2]));
            self.emit(Op::Otl(done));
            self.emit(Op::Otl(seen));
            self.emit(Op::BinI(IBin::Sub, ch, c0, ci));
            match dv {
                Fp::F(f) => self.emit(Op::Cvt(alba_ir::op::Cvt::IF(ci, f))),
                Fp::D(d) => self.emit(Op::Cvt(alba_ir::op::Cvt::ID(ci, d))),
            };
            self.fp_bin(IBin::Mul, v, ten_f, v);
            self.fp_bin(IBin::Add, v, dv, v);
            self.emit(Op::CmpI(Cmp::Eq, phase, ph[2]));
            self.emit(Op::BinI(IBin::Add, fd, one, fd));
            self.emit(Op::True);
            self.emit(Op::CmpI(Cmp::Lt, phase, ph[2]));
            self.emit(Op::CmpI(Cmp::Ge, ch, c0));
            self.emit(Op::CmpI(Cmp::Le, ch, c9));
            self.emit(Op::Xic(done));
            self.emit(Op::UnI(IUn::Mov, ph[1], phase));
            self.emit(Op::True);
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Ge, ch, c0));
            self.emit(Op::CmpI(Cmp::Le, ch, c9));
            self.emit(Op::CmpI(Cmp::Ge, phase, ph[3]));
            self.emit(Op::CmpI(Cmp::Le, phase, ph[4]));
            self.emit(Op::Otl(done));
            self.emit(Op::UnI(IUn::Mov, ph[4], phase));
            self.emit(Op::CmpI(Cmp::Lt, ex, most_ex));
            let ten = c(self, 10);
            self.emit(Op::BinI(IBin::Mul, ex, ten, ex));
            self.emit(Op::BinI(IBin::Sub, ch, c0, ci));
            self.emit(Op::BinI(IBin::Add, ex, ci, ex));
            self.emit(Op::True);
            // The point after the integer digits (or none).
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Le, phase, ph[1]));
            self.emit(Op::CmpI(Cmp::Eq, ch, point));
            self.emit(Op::Otl(done));
            self.emit(Op::UnI(IUn::Mov, ph[2], phase));
            self.emit(Op::True);
            // `E` after digits.
            for letter in [ue, le] {
                self.emit(Op::Xio(done));
                self.emit(Op::Xic(seen));
                self.emit(Op::CmpI(Cmp::Ge, phase, ph[1]));
                self.emit(Op::CmpI(Cmp::Le, phase, ph[2]));
                self.emit(Op::CmpI(Cmp::Eq, ch, letter));
                self.emit(Op::Otl(done));
                self.emit(Op::UnI(IUn::Mov, ph[3], phase));
                self.emit(Op::True);
            }
            // Anything else ends the number.
            self.emit(Op::Xio(done));
            self.emit(Op::UnI(IUn::Mov, ph[5], phase));
            self.emit(Op::True);
        }
        // The power of ten: ±exponent − fraction digits, one stage per bit.
        let p = self.b.temp_i();
        self.emit(Op::UnI(IUn::Mov, ex, p));
        self.emit(Op::Xic(eneg));
        self.emit(Op::UnI(IUn::Neg, ex, p));
        self.emit(Op::True);
        self.emit(Op::BinI(IBin::Sub, p, fd, p));
        let (down, ap) = (self.b.temp_b(), self.b.temp_i());
        self.emit(Op::CmpI(Cmp::Lt, p, zero));
        self.emit(Op::Ote(down));
        self.emit(Op::True);
        self.emit(Op::UnI(IUn::Abs, p, ap));
        let (top, most) = if wide_fp { (256, 511) } else { (32, 63) };
        let most = c(self, most);
        self.emit(Op::CmpI(Cmp::Gt, ap, most));
        self.emit(Op::UnI(IUn::Mov, most, ap));
        self.emit(Op::True);
        // 10^|p| as the product of its bits' powers (exact up to 10^22), then
        // one division or multiplication.
        let (bit, pw) = (self.b.temp_i(), self.fp_temp(like));
        let one_f = self.fp_const(like, 1.0);
        self.fp_un(IUn::Mov, one_f, pw);
        let mut k = top;
        while k >= 1 {
            let (kc, pk) = (c(self, k), self.fp_const(like, 10f64.powi(k)));
            self.emit(Op::BinI(IBin::And, ap, kc, bit));
            self.emit(Op::CmpI(Cmp::Ne, bit, zero));
            self.fp_bin(IBin::Mul, pw, pk, pw);
            self.emit(Op::True);
            k /= 2;
        }
        self.emit(Op::Xic(down));
        self.fp_bin(IBin::Div, v, pw, v);
        self.emit(Op::True);
        self.emit(Op::Xio(down));
        self.fp_cmp(Cmp::Ne, v, zero_f);
        self.fp_bin(IBin::Mul, v, pw, v);
        self.emit(Op::True);
        self.emit(Op::Xic(neg));
        self.fp_un(IUn::Neg, v, v);
        self.emit(Op::True);
        match v {
            Fp::F(f) => V::F(f),
            Fp::D(d) => V::D(d),
        }
    }
}

/// The slots of a literal's reading, one character at a time: the character,
/// its lower case (`c | 32`), the phase, and whether the character is read.
#[derive(Clone, Copy)]
struct Reading {
    ch: I,
    lc: I,
    phase: I,
    done: B,
}
