//! STRING and WSTRING on the engine's integer slots (ADR 0017): a string of
//! at most n characters is a length slot and n character slots (codes: bytes
//! for STRING, UTF-16 units for WSTRING), every character past the length
//! being 0. The string functions are straight-line code of existing IR ops:
//! a shift by a computed number of characters is done by each power of two of
//! the number in turn (a barrel shifter), so a function on n characters costs
//! about n·log2(n) ops and no loop; nothing was added to the IR.

use super::*;

/// Longest string a declaration may give (`STRING[1024]`).
pub const MAX_STRING: i64 = 1024;
/// Characters of a `STRING` without a length.
pub const DEFAULT_STRING: i64 = 80;

/// A string value in slots: its length and its characters (zero past the
/// length). The slots of a variable or a literal are read only; the
/// functions work on copies.
#[derive(Debug, Clone)]
pub(super) struct Str {
    pub(super) len: I,
    pub(super) chars: Vec<I>,
    /// The length when it is known at compile time (a literal).
    pub(super) known: Option<usize>,
}

impl Str {
    pub(super) fn cap(&self) -> usize {
        self.chars.len()
    }
}

/// The character codes of a literal: bytes of its UTF-8 text for a STRING
/// (the lexer decoded `$` escapes), UTF-16 units for a WSTRING.
fn codes(text: &str, wide: bool) -> Vec<i32> {
    if wide {
        text.encode_utf16().map(i32::from).collect()
    } else {
        text.bytes().map(i32::from).collect()
    }
}

impl Lower<'_> {
    /// Keeps a string value and gives its handle.
    pub(super) fn keep(&mut self, s: Str) -> Val {
        self.strs.push(s);
        Val::S(self.strs.len() as u32 - 1)
    }

    pub(super) fn str_of(&self, v: Val) -> Option<Str> {
        match v {
            Val::S(k) => self.strs.get(k as usize).cloned(),
            _ => None,
        }
    }

    /// A string literal: constant slots, no op.
    pub(super) fn str_literal(&mut self, text: &str, wide: bool) -> (Val, Ty) {
        let c = codes(text, wide);
        let chars = c.iter().map(|x| self.b.const_i(*x)).collect();
        let len = self.b.const_i(c.len() as i32);
        let v = self.keep(Str {
            len,
            chars,
            known: Some(c.len()),
        });
        (v, Ty::Str(wide, c.len() as u32))
    }

    /// The slots of a string variable (read without a copy).
    pub(super) fn str_loc(&self, len: I, chars: &[I]) -> Str {
        Str {
            len,
            chars: chars.to_vec(),
            known: None,
        }
    }

    /// A copy of `s` in temporaries with `cap` characters (`cap` ≥ its own).
    pub(super) fn str_copy(&mut self, s: &Str, cap: usize) -> Str {
        let zero = self.b.const_i(0);
        let len = self.b.temp_i();
        self.emit(Op::UnI(IUn::Mov, s.len, len));
        let mut chars = Vec::with_capacity(cap);
        for k in 0..cap {
            let t = self.b.temp_i();
            self.emit(Op::UnI(IUn::Mov, s.chars.get(k).copied().unwrap_or(zero), t));
            chars.push(t);
        }
        Str {
            len,
            chars,
            known: s.known,
        }
    }

    /// `v` clamped into `lo..=hi` in a new temporary.
    fn clamp(&mut self, v: I, lo: I, hi: I) -> I {
        let t = self.b.temp_i();
        self.emit(Op::UnI(IUn::Mov, v, t));
        self.emit(Op::CmpI(Cmp::Lt, t, lo));
        self.emit(Op::UnI(IUn::Mov, lo, t));
        self.emit(Op::True);
        self.emit(Op::CmpI(Cmp::Gt, t, hi));
        self.emit(Op::UnI(IUn::Mov, hi, t));
        self.emit(Op::True);
        t
    }

    /// A range fault when `v < lo` (a negative length, a position before the
    /// first character).
    fn fault_below(&mut self, v: I, lo: i32) {
        let c = self.b.const_i(lo);
        let bad = self.b.temp_b();
        self.emit(Op::CmpI(Cmp::Lt, v, c));
        self.emit(Op::Ote(bad));
        self.emit(Op::True);
        self.range_fault(bad);
    }

    /// Characters `k >= n` of the temporaries `s` set to 0, and its length `n`.
    pub(super) fn cut(&mut self, s: &mut Str, n: I) {
        let zero = self.b.const_i(0);
        for k in 0..s.cap() {
            let kc = self.b.const_i(k as i32);
            self.emit(Op::CmpI(Cmp::Ge, kc, n));
            self.emit(Op::UnI(IUn::Mov, zero, s.chars[k]));
            self.emit(Op::True);
        }
        self.emit(Op::UnI(IUn::Mov, n, s.len));
        s.known = None;
    }

    /// Moves the characters of the temporaries `s` by `by` places (0 ≤ by ≤
    /// cap) towards the start (`left`) or the end, zeros coming in: one
    /// stage per power of two.
    pub(super) fn shift(&mut self, s: &Str, by: I, left: bool) {
        let (zero, cap) = (self.b.const_i(0), s.cap());
        let mut step = 1usize;
        while step <= cap {
            let bit = self.b.const_i(step as i32);
            let t = self.b.temp_i();
            self.emit(Op::BinI(IBin::And, by, bit, t));
            self.emit(Op::CmpI(Cmp::Ne, t, zero));
            if left {
                for k in 0..cap {
                    let src = s.chars.get(k + step).copied().unwrap_or(zero);
                    self.emit(Op::UnI(IUn::Mov, src, s.chars[k]));
                }
            } else {
                for k in (0..cap).rev() {
                    let src = if k >= step { s.chars[k - step] } else { zero };
                    self.emit(Op::UnI(IUn::Mov, src, s.chars[k]));
                }
            }
            self.emit(Op::True);
            step *= 2;
        }
    }

    /// `a` followed by `b`, at most `MAX_STRING` characters.
    pub(super) fn concat(&mut self, a: &Str, b: &Str) -> Str {
        self.concat_within(a, b, a.cap() + b.cap())
    }

    /// [`Lower::concat`] when the result is known to fit `most` characters
    /// (the pieces of one string).
    fn concat_within(&mut self, a: &Str, b: &Str, most: usize) -> Str {
        let cap = most.max(a.cap()).min(MAX_STRING as usize);
        let mut r = self.str_copy(a, cap);
        let zero = self.b.const_i(0);
        match a.known {
            // After a literal, `b` goes to a known place.
            Some(off) => {
                for k in off..cap {
                    let src = b.chars.get(k - off).copied().unwrap_or(zero);
                    self.emit(Op::UnI(IUn::Mov, src, r.chars[k]));
                }
            }
            None => {
                let t = self.str_copy(b, cap);
                self.shift(&t, a.len, false);
                for k in 0..cap {
                    self.emit(Op::BinI(IBin::Add, r.chars[k], t.chars[k], r.chars[k]));
                }
            }
        }
        self.emit(Op::BinI(IBin::Add, a.len, b.len, r.len));
        let capc = self.b.const_i(cap as i32);
        self.emit(Op::CmpI(Cmp::Gt, r.len, capc));
        self.emit(Op::UnI(IUn::Mov, capc, r.len));
        self.emit(Op::True);
        r.known = a.known.zip(b.known).map(|(x, y)| (x + y).min(cap));
        r
    }

    /// The first `n` characters of `s` (0 ≤ n ≤ LEN(s)), in temporaries.
    pub(super) fn left_of(&mut self, s: &Str, n: I) -> Str {
        let mut r = self.str_copy(s, s.cap());
        self.cut(&mut r, n);
        r
    }

    /// The characters of `s` from place `from` (0-based, 0 ≤ from ≤ LEN(s)) on.
    pub(super) fn tail_of(&mut self, s: &Str, from: I) -> Str {
        let r = self.str_copy(s, s.cap());
        self.shift(&r, from, true);
        self.emit(Op::BinI(IBin::Sub, s.len, from, r.len));
        Str { known: None, ..r }
    }

    /// Stores `src` into a string variable's slots, truncated to its length.
    pub(super) fn str_store(&mut self, len: I, chars: &[I], src: &Str) {
        let zero = self.b.const_i(0);
        self.emit(Op::UnI(IUn::Mov, src.len, len));
        if src.cap() > chars.len() {
            let capc = self.b.const_i(chars.len() as i32);
            self.emit(Op::CmpI(Cmp::Gt, len, capc));
            self.emit(Op::UnI(IUn::Mov, capc, len));
            self.emit(Op::True);
        }
        for (k, d) in chars.iter().enumerate() {
            let s = src.chars.get(k).copied().unwrap_or(zero);
            if s != *d {
                self.emit(Op::UnI(IUn::Mov, s, *d));
            }
        }
    }

    /// The string argument `e` (of `f`), and whether it is a WSTRING.
    fn str_arg(&mut self, f: &str, e: &Expr, wide: Option<bool>) -> R<(Str, bool)> {
        let (v, ty) = self.eval(e, None)?;
        match (self.str_of(v), &ty) {
            (Some(s), Ty::Str(w, _)) if wide.is_none_or(|x| x == *w) => Ok((s, *w)),
            _ => Err(type_error(
                e.span,
                format!(
                    "{f} takes a {}, not {}",
                    if wide == Some(true) { "WSTRING" } else { "STRING" },
                    an(&ty)
                ),
            )),
        }
    }

    /// An integer argument (a length or a position) in an I slot.
    fn int_arg(&mut self, f: &str, e: &Expr) -> R<I> {
        let (v, ty) = self.eval(e, Some(&Ty::Int))?;
        match v {
            Val::N(V::I(x)) if ty.is_int() => Ok(x),
            _ => Err(type_error(
                e.span,
                format!("{f} takes an integer (SINT, INT, DINT) here, not {}", an(&ty)),
            )),
        }
    }

    /// The standard string functions; `None` when `up` is not one.
    pub(super) fn string_call(&mut self, up: &str, args: &[&Expr], span: Span) -> Option<R<(Val, Ty)>> {
        let known = [
            "LEN", "LEFT", "RIGHT", "MID", "CONCAT", "INSERT", "DELETE", "REPLACE", "FIND",
        ];
        if !known.contains(&up) {
            return None;
        }
        Some(self.string_fn(up, args, span))
    }

    fn string_fn(&mut self, up: &str, args: &[&Expr], span: Span) -> R<(Val, Ty)> {
        let want = match up {
            "LEN" => 1,
            "LEFT" | "RIGHT" | "FIND" => 2,
            "MID" | "INSERT" | "DELETE" => 3,
            "REPLACE" => 4,
            _ => 0,
        };
        if up == "CONCAT" {
            if args.len() < 2 {
                return Err(type_error(
                    span,
                    format!("CONCAT takes two strings or more, not {}", args.len()),
                ));
            }
        } else if args.len() != want {
            return Err(type_error(
                span,
                format!("{up} takes {want} argument(s), not {}", args.len()),
            ));
        }
        let (s, wide) = self.str_arg(up, args[0], None)?;
        let zero = self.b.const_i(0);
        let r = match up {
            "LEN" => return Ok((Val::N(V::I(s.len)), Ty::Int)),
            "CONCAT" => {
                let mut r = s;
                for a in &args[1..] {
                    let (b, _) = self.str_arg(up, a, Some(wide))?;
                    r = self.concat(&r, &b);
                }
                r
            }
            "LEFT" | "RIGHT" => {
                let l = self.int_arg(up, args[1])?;
                self.fault_below(l, 0);
                let l = self.clamp(l, zero, s.len);
                if up == "LEFT" {
                    self.left_of(&s, l)
                } else {
                    let from = self.b.temp_i();
                    self.emit(Op::BinI(IBin::Sub, s.len, l, from));
                    self.tail_of(&s, from)
                }
            }
            "MID" => {
                let (l, p) = (self.int_arg(up, args[1])?, self.int_arg(up, args[2])?);
                self.fault_below(l, 0);
                self.fault_below(p, 1);
                let from = self.place_of(p, &s);
                let rest = self.tail_of(&s, from);
                let l = self.clamp(l, zero, rest.len);
                let mut r = rest;
                self.cut(&mut r, l);
                r
            }
            "INSERT" => {
                let (b, _) = self.str_arg(up, args[1], Some(wide))?;
                let p = self.int_arg(up, args[2])?;
                self.fault_below(p, 0);
                let p = self.clamp(p, zero, s.len);
                let head = self.left_of(&s, p);
                let tail = self.tail_of(&s, p);
                let h = self.concat(&head, &b);
                self.concat_within(&h, &tail, s.cap() + b.cap())
            }
            "DELETE" | "REPLACE" => {
                let (b, at) = if up == "REPLACE" {
                    (Some(self.str_arg(up, args[1], Some(wide))?.0), 2)
                } else {
                    (None, 1)
                };
                let (l, p) = (self.int_arg(up, args[at])?, self.int_arg(up, args[at + 1])?);
                self.fault_below(l, 0);
                self.fault_below(p, 1);
                let from = self.place_of(p, &s);
                let head = self.left_of(&s, from);
                // The characters after the `l` taken out.
                let room = self.b.temp_i();
                self.emit(Op::BinI(IBin::Sub, s.len, from, room));
                let l = self.clamp(l, zero, room);
                let after = self.b.temp_i();
                self.emit(Op::BinI(IBin::Add, from, l, after));
                let tail = self.tail_of(&s, after);
                let most = s.cap() + b.as_ref().map_or(0, Str::cap);
                let h = match b {
                    Some(b) => self.concat(&head, &b),
                    None => head,
                };
                self.concat_within(&h, &tail, most)
            }
            "FIND" => {
                let (b, _) = self.str_arg(up, args[1], Some(wide))?;
                return Ok((Val::N(V::I(self.find(&s, &b))), Ty::Int));
            }
            _ => return Err(not_supported(span, format!("{up} is not supported yet"))),
        };
        let cap = r.cap() as u32;
        Ok((self.keep(r), Ty::Str(wide, cap)))
    }

    /// The 0-based place of 1-based position `p`, clamped into `0..=LEN(s)`.
    fn place_of(&mut self, p: I, s: &Str) -> I {
        let one = self.b.const_i(1);
        let t = self.b.temp_i();
        self.emit(Op::BinI(IBin::Sub, p, one, t));
        let zero = self.b.const_i(0);
        self.clamp(t, zero, s.len)
    }

    /// FIND(a, b): the position (from 1) of the first `b` in `a`, 0 if none
    /// (and for an empty `b`).
    fn find(&mut self, a: &Str, b: &Str) -> I {
        let zero = self.b.const_i(0);
        let res = self.b.temp_i();
        self.emit(Op::UnI(IUn::Mov, zero, res));
        // Places where `b` may start: LEN(a) - LEN(b) >= i.
        let room = self.b.temp_i();
        self.emit(Op::BinI(IBin::Sub, a.len, b.len, room));
        let (save, acc) = (self.b.temp_b(), self.b.temp_b());
        let bcap = b.known.unwrap_or(b.cap());
        for i in (0..a.cap()).rev() {
            let ic = self.b.const_i(i as i32);
            self.emit(Op::CmpI(Cmp::Ge, room, ic));
            self.emit(Op::CmpI(Cmp::Gt, b.len, zero));
            for j in 0..bcap.min(a.cap() - i) {
                if b.known.is_some() {
                    self.emit(Op::CmpI(Cmp::Eq, a.chars[i + j], b.chars[j]));
                } else {
                    // Past b's length, or the same character.
                    let jc = self.b.const_i(j as i32);
                    self.emit(Op::BrOpen { save, acc });
                    self.emit(Op::CmpI(Cmp::Ge, jc, b.len));
                    self.emit(Op::BrNext { save, acc });
                    self.emit(Op::CmpI(Cmp::Eq, a.chars[i + j], b.chars[j]));
                    self.emit(Op::BrClose { acc });
                }
            }
            let pos = self.b.const_i(i as i32 + 1);
            self.emit(Op::UnI(IUn::Mov, pos, res));
            self.emit(Op::True);
        }
        res
    }

    /// `a op b` on two strings (of one kind): `=`/`<>` compare length and
    /// characters, the others the first character that differs (a string
    /// before every longer string it starts).
    pub(super) fn str_compare(&mut self, c: Cmp, a: &Str, b: &Str) -> B {
        let zero = self.b.const_i(0);
        let r = self.b.temp_b();
        if matches!(c, Cmp::Eq | Cmp::Ne) {
            self.emit(Op::CmpI(Cmp::Eq, a.len, b.len));
            for k in 0..a.cap().min(b.cap()) {
                self.emit(Op::CmpI(Cmp::Eq, a.chars[k], b.chars[k]));
            }
            if c == Cmp::Ne {
                self.emit(Op::Not);
            }
            self.emit(Op::Ote(r));
            self.emit(Op::True);
            return r;
        }
        let (diff, d) = (self.b.temp_i(), self.b.temp_i());
        self.emit(Op::UnI(IUn::Mov, zero, diff));
        for k in (0..a.cap().max(b.cap())).rev() {
            let x = a.chars.get(k).copied().unwrap_or(zero);
            let y = b.chars.get(k).copied().unwrap_or(zero);
            self.emit(Op::BinI(IBin::Sub, x, y, d));
            self.emit(Op::CmpI(Cmp::Ne, d, zero));
            self.emit(Op::UnI(IUn::Mov, d, diff));
            self.emit(Op::True);
        }
        self.emit(Op::CmpI(c, diff, zero));
        self.emit(Op::Ote(r));
        self.emit(Op::True);
        r
    }

    /// Whether the LINT `x` is negative, and |x| (LINT's minimum: the engine's
    /// overflow fault), in temporaries.
    pub(super) fn abs_l(&mut self, x: alba_ir::op::L) -> (B, alba_ir::op::L) {
        let lz = self.b.const_l(0);
        let neg = self.b.temp_b();
        self.emit(Op::CmpL(Cmp::Lt, x, lz));
        self.emit(Op::Ote(neg));
        self.emit(Op::True);
        let a = self.b.temp_l();
        self.emit(Op::UnL(IUn::Mov, x, a));
        self.emit(Op::Xic(neg));
        self.emit(Op::UnL(IUn::Neg, x, a));
        self.emit(Op::True);
        (neg, a)
    }

    /// `INT_TO_STRING` and the like: the decimal text of an integer (in an I
    /// or L slot) known to have at most `digits` digits (19 for a LINT), `-`
    /// first when negative, in temporaries.
    pub(super) fn int_text(&mut self, v: V, digits: usize) -> Str {
        let x = self.b.convert(v, Class::L, self.elem);
        let V::L(x) = x else {
            return self.str_text("");
        };
        let (neg, a) = self.abs_l(x);
        // The digits right-aligned, and how many there are.
        let s = Str {
            len: self.b.temp_i(),
            chars: (0..digits + 1).map(|_| self.b.temp_i()).collect(),
            known: None,
        };
        let one = self.b.const_i(1);
        self.emit(Op::UnI(IUn::Mov, one, s.len));
        let (ten, q, dl) = (self.b.const_l(10), self.b.temp_l(), self.b.temp_l());
        let c48 = self.b.const_l(48);
        self.emit(Op::UnL(IUn::Mov, a, q));
        for k in 0..digits {
            let slot = s.chars[digits - 1 - k];
            self.emit(Op::BinL(IBin::Mod, q, ten, dl));
            self.emit(Op::BinL(IBin::Add, dl, c48, dl));
            self.emit(Op::Cvt(alba_ir::op::Cvt::LI(dl, slot)));
            self.emit(Op::BinL(IBin::Div, q, ten, q));
            if k > 0 {
                // Digit k counts when |x| ≥ 10^k.
                let p = self.b.const_l(10i64.pow(k as u32));
                let kc = self.b.const_i(k as i32 + 1);
                self.emit(Op::CmpL(Cmp::Ge, a, p));
                self.emit(Op::UnI(IUn::Mov, kc, s.len));
                self.emit(Op::True);
            }
        }
        let zero = self.b.const_i(0);
        self.emit(Op::UnI(IUn::Mov, zero, s.chars[digits]));
        // Drop the leading zeros: shift by digits - len.
        let (dc, by) = (self.b.const_i(digits as i32), self.b.temp_i());
        self.emit(Op::BinI(IBin::Sub, dc, s.len, by));
        self.shift(&s, by, true);
        // The sign: one place to the end, and `-` first.
        let (minus, nb) = (self.b.const_i(45), self.b.temp_i());
        self.emit(Op::UnI(IUn::Mov, zero, nb));
        self.emit(Op::Xic(neg));
        self.emit(Op::UnI(IUn::Mov, one, nb));
        self.emit(Op::True);
        self.shift(&s, nb, false);
        self.emit(Op::Xic(neg));
        self.emit(Op::UnI(IUn::Mov, minus, s.chars[0]));
        self.emit(Op::BinI(IBin::Add, s.len, one, s.len));
        self.emit(Op::True);
        s
    }

    /// `STRING_TO_INT` and the like: the decimal number at the start of the
    /// text (spaces first skipped, then an optional sign; it ends at the first
    /// other character), in a LINT slot; the conversion to the integer type
    /// follows.
    pub(super) fn string_to_int(&mut self, s: &Str) -> V {
        let (lz, ten) = (self.b.const_l(0), self.b.const_l(10));
        let (zero, one, two) = (self.b.const_i(0), self.b.const_i(1), self.b.const_i(2));
        let (space, minus, plus, c0, c9) = (
            self.b.const_i(32),
            self.b.const_i(45),
            self.b.const_i(43),
            self.b.const_i(48),
            self.b.const_i(57),
        );
        let v = self.b.temp_l();
        self.emit(Op::UnL(IUn::Mov, lz, v));
        // Phase 0: spaces; 1: after a sign or a digit; 2: ended.
        let (phase, neg, done) = (self.b.temp_i(), self.b.temp_b(), self.b.temp_b());
        let (ci, dl) = (self.b.temp_i(), self.b.temp_l());
        self.emit(Op::UnI(IUn::Mov, zero, phase));
        self.emit(Op::Afi);
        self.emit(Op::Ote(neg));
        self.emit(Op::True);
        for &c in &s.chars {
            // A space in phase 0 is skipped.
            self.emit(Op::CmpI(Cmp::Eq, phase, zero));
            self.emit(Op::CmpI(Cmp::Eq, c, space));
            self.emit(Op::Ote(done));
            self.emit(Op::True);
            // A sign in phase 0.
            self.emit(Op::CmpI(Cmp::Eq, phase, zero));
            self.emit(Op::CmpI(Cmp::Eq, c, minus));
            self.emit(Op::Otl(neg));
            self.emit(Op::Otl(done));
            self.emit(Op::UnI(IUn::Mov, one, phase));
            self.emit(Op::True);
            self.emit(Op::CmpI(Cmp::Eq, phase, zero));
            self.emit(Op::CmpI(Cmp::Eq, c, plus));
            self.emit(Op::Otl(done));
            self.emit(Op::UnI(IUn::Mov, one, phase));
            self.emit(Op::True);
            // A digit before the end.
            self.emit(Op::Xio(done));
            self.emit(Op::CmpI(Cmp::Lt, phase, two));
            self.emit(Op::CmpI(Cmp::Ge, c, c0));
            self.emit(Op::CmpI(Cmp::Le, c, c9));
            self.emit(Op::Otl(done));
            self.emit(Op::BinL(IBin::Mul, v, ten, v));
            self.emit(Op::BinI(IBin::Sub, c, c0, ci));
            self.emit(Op::Cvt(alba_ir::op::Cvt::IL(ci, dl)));
            self.emit(Op::BinL(IBin::Add, v, dl, v));
            self.emit(Op::UnI(IUn::Mov, one, phase));
            self.emit(Op::True);
            // Anything else ends the number.
            self.emit(Op::Xio(done));
            self.emit(Op::UnI(IUn::Mov, two, phase));
            self.emit(Op::True);
        }
        self.emit(Op::Xic(neg));
        self.emit(Op::UnL(IUn::Neg, v, v));
        self.emit(Op::True);
        V::L(v)
    }

    /// A binary operator with a string operand: the comparisons of two
    /// strings of one kind.
    pub(super) fn str_binary(&mut self, op: BinOp, a: (Val, &Ty), b: (Val, &Ty), span: Span) -> R<(Val, Ty)> {
        let c = match op {
            BinOp::Eq => Cmp::Eq,
            BinOp::Ne => Cmp::Ne,
            BinOp::Lt => Cmp::Lt,
            BinOp::Gt => Cmp::Gt,
            BinOp::Le => Cmp::Le,
            BinOp::Ge => Cmp::Ge,
            _ => {
                return Err(type_error(
                    span,
                    format!(
                        "`{}` does not take strings ({} and {}); CONCAT joins them",
                        op.text(),
                        a.1,
                        b.1
                    ),
                ));
            }
        };
        match (self.str_of(a.0), self.str_of(b.0), a.1, b.1) {
            (Some(x), Some(y), Ty::Str(w1, _), Ty::Str(w2, _)) if w1 == w2 => {
                Ok((Val::B(self.str_compare(c, &x, &y)), Ty::Bool))
            }
            _ => Err(type_error(
                span,
                format!("`{}` of {} and {}: the types differ", op.text(), a.1, b.1),
            )),
        }
    }

    /// The conversions to and from strings (`INT_TO_STRING`,
    /// `STRING_TO_DINT`, `STRING_TO_WSTRING`, …); `None` when `from`/`to`
    /// name no string.
    pub(super) fn string_conversion(&mut self, from: &str, to: &str, arg: &Expr, span: Span) -> Option<R<(Val, Ty)>> {
        let wide = |t: &str| match t {
            "STRING" => Some(false),
            "WSTRING" => Some(true),
            _ => None,
        };
        let (fw, tw) = (wide(from), wide(to));
        if fw.is_none() && tw.is_none() {
            return None;
        }
        Some(self.string_convert(from, to, fw, tw, arg, span))
    }

    fn string_convert(
        &mut self,
        from: &str,
        to: &str,
        fw: Option<bool>,
        tw: Option<bool>,
        arg: &Expr,
        span: Span,
    ) -> R<(Val, Ty)> {
        let f = format!("{from}_TO_{to}");
        match (fw, tw) {
            (Some(fw), Some(tw)) => {
                let (s, _) = self.str_arg(&f, arg, Some(fw))?;
                let r = self.str_copy(&s, s.cap());
                if fw != tw {
                    // Only ASCII keeps its meaning between UTF-8 bytes and
                    // UTF-16 units: a code above 127 becomes `?`.
                    let (max, q) = (self.b.const_i(127), self.b.const_i(63));
                    for &c in &r.chars {
                        self.emit(Op::CmpI(Cmp::Gt, c, max));
                        self.emit(Op::UnI(IUn::Mov, q, c));
                        self.emit(Op::True);
                    }
                }
                let cap = r.cap() as u32;
                Ok((self.keep(r), Ty::Str(tw, cap)))
            }
            (None, Some(tw)) => {
                let from_ty = elementary(from)
                    .filter(|t| {
                        t.is_int()
                            || t.is_bits()
                            || t.is_real()
                            || matches!(t, Ty::Bool | Ty::Time | Ty::Ltime | Ty::Date | Ty::Tod | Ty::Dt)
                    })
                    .ok_or_else(|| not_supported(span, format!("{f}: `{from}` is not an elementary type")))?;
                let (v, ty) = self.eval(arg, Some(&from_ty))?;
                if ty != from_ty {
                    return Err(type_error(
                        arg.span,
                        format!("{f} takes {}, not {}", an(&from_ty), an(&ty)),
                    ));
                }
                let s = self
                    .text_of(v, &ty)
                    .ok_or_else(|| type_error(arg.span, format!("{f} takes {}, not {}", an(&from_ty), an(&ty))))?;
                let cap = s.cap() as u32;
                Ok((self.keep(s), Ty::Str(tw, cap)))
            }
            (Some(fw), None) => {
                let to_ty = elementary(to)
                    .filter(|t| {
                        t.is_int()
                            || t.is_bits()
                            || t.is_real()
                            || matches!(t, Ty::Bool | Ty::Time | Ty::Ltime | Ty::Date | Ty::Tod | Ty::Dt)
                    })
                    .ok_or_else(|| {
                        not_supported(
                            span,
                            format!("{f}: a string converts only to numbers, bit strings, BOOL, durations and dates"),
                        )
                    })?;
                let (s, _) = self.str_arg(&f, arg, Some(fw))?;
                if to_ty == Ty::Bool {
                    return Ok((Val::B(self.string_to_bool(&s)), Ty::Bool));
                }
                if matches!(to_ty, Ty::Date | Ty::Tod | Ty::Dt) {
                    return Ok((Val::N(V::L(self.string_to_date(&s, &to_ty))), to_ty));
                }
                if matches!(to_ty, Ty::Time | Ty::Ltime) {
                    return Ok((self.string_to_time(&s, to_ty == Ty::Ltime), to_ty));
                }
                if to_ty.is_real() {
                    let v = self.string_to_real(&s, to_ty == Ty::Lreal);
                    return Ok((Val::N(v), to_ty));
                }
                let v = self.string_to_int(&s);
                Ok((self.convert(Val::N(v), &Ty::Lint, &to_ty), to_ty))
            }
            (None, None) => Err(not_supported(span, f)),
        }
    }
}
