//! Bit strings on the engine's signed slots: masks, AND/OR/XOR, shifts and
//! rotations by constant and computed amounts (existing IR ops only).

use super::*;

pub(super) fn vclass(v: V) -> Class {
    match v {
        V::I(_) => Class::I,
        V::F(_) => Class::F,
        V::L(_) => Class::L,
        V::D(_) => Class::D,
    }
}

impl Lower<'_> {
    /// `x` (of class I or L) with only its low `w` bits, in a new slot.
    pub(super) fn wrap_bits(&mut self, x: V, w: u32) -> V {
        let c = vclass(x);
        let t = self.b.temp(c);
        if w >= 64 {
            self.b.un(IUn::Mov, x, t, self.elem);
        } else {
            let m = self.b.constant(alba_model::Literal::Int((1i64 << w) - 1), c);
            self.b.bin(IBin::And, x, m, t, self.elem);
        }
        t
    }

    pub(super) fn int_const(&mut self, v: i64, c: Class) -> V {
        self.b.constant(alba_model::Literal::Int(v), c)
    }

    /// The mask of bit `bit` of a value of `ty` in class `c` (a signed
    /// type's sign bit sign-extended, so setting it stays in range).
    pub(super) fn bit_mask(&mut self, ty: &Ty, bit: u32, c: Class) -> V {
        let w = match ty {
            Ty::Sint => 8,
            Ty::Int => 16,
            Ty::Dint => 32,
            _ => 64,
        };
        let m = if bit + 1 == w && w < 64 {
            -(1i64 << bit)
        } else {
            1i64 << bit
        };
        self.int_const(m, c)
    }

    /// `AND`, `OR`, `XOR` of two bit strings.
    pub(super) fn bitwise(&mut self, op: BinOp, (x, ta): (V, &Ty), (y, tb): (V, &Ty), span: Span) -> R<(Val, Ty)> {
        let ty = if widens(ta, tb) { tb.clone() } else { ta.clone() };
        if !(ta.is_bits() && tb.is_bits() && widens(ta, &ty) && widens(tb, &ty)) {
            return Err(type_error(
                span,
                format!(
                    "{} takes BOOL operands or bit strings (BYTE … LWORD) of one type, not {ta} and {tb}",
                    op.text()
                ),
            ));
        }
        let c = ty.class();
        let x = self.b.convert(x, c, self.elem);
        let y = self.b.convert(y, c, self.elem);
        let t = self.b.temp(c);
        let iop = match op {
            BinOp::And => IBin::And,
            BinOp::Or => IBin::Or,
            _ => IBin::Xor,
        };
        self.b.bin(iop, x, y, t, self.elem);
        Ok((Val::N(t), ty))
    }

    /// `SHL`/`SHR`/`ROL`/`ROR` of a `w`-bit string by a constant.
    pub(super) fn shift_const(&mut self, f: &str, x: V, s: u32, w: u32) -> V {
        match f {
            "SHL" => self.shl(x, s, w),
            "SHR" => self.shr(x, s, w),
            "ROL" => self.rol(x, s % w, w),
            _ => self.rol(x, (w - s % w) % w, w),
        }
    }

    /// `x` shifted left by `s` within `w` bits (values of fewer than 64 bits
    /// are never negative; LWORD's top bit is the sign of its slot).
    pub(super) fn shl(&mut self, x: V, s: u32, w: u32) -> V {
        let c = vclass(x);
        let t = self.b.temp(c);
        if s >= w {
            let z = self.int_const(0, c);
            self.b.un(IUn::Mov, z, t, self.elem);
            return t;
        }
        if s == 0 {
            self.b.un(IUn::Mov, x, t, self.elem);
            return t;
        }
        let keep = w - s;
        let p = self.int_const(1i64 << s, c);
        if w < 64 {
            let m = self.int_const((1i64 << keep) - 1, c);
            self.b.bin(IBin::And, x, m, t, self.elem);
            self.b.bin(IBin::Mul, t, p, t, self.elem);
            return t;
        }
        // 64 bits: the bits below the one reaching bit 63 move by a product;
        // that one becomes the sign.
        let m = self.int_const((1i64 << (keep - 1)) - 1, c);
        self.b.bin(IBin::And, x, m, t, self.elem);
        self.b.bin(IBin::Mul, t, p, t, self.elem);
        let top = self.int_const(1i64 << (keep - 1), c);
        let (zero, min) = (self.int_const(0, c), self.int_const(i64::MIN, c));
        let tb = self.b.temp(c);
        self.b.bin(IBin::And, x, top, tb, self.elem);
        self.cmp(Cmp::Ne, tb, zero);
        self.b.bin(IBin::Or, t, min, t, self.elem);
        self.emit(Op::True);
        t
    }

    /// `x` shifted right by `s` within `w` bits, zeros coming in.
    pub(super) fn shr(&mut self, x: V, s: u32, w: u32) -> V {
        let c = vclass(x);
        let t = self.b.temp(c);
        if s >= w {
            let z = self.int_const(0, c);
            self.b.un(IUn::Mov, z, t, self.elem);
            return t;
        }
        if s == 0 {
            self.b.un(IUn::Mov, x, t, self.elem);
            return t;
        }
        let p = self.int_const(1i64 << s, c);
        if w < 64 {
            self.b.bin(IBin::Div, x, p, t, self.elem);
            return t;
        }
        // 64 bits: without the sign, divided; the sign bit comes back at 63 - s.
        let max = self.int_const(i64::MAX, c);
        self.b.bin(IBin::And, x, max, t, self.elem);
        self.b.bin(IBin::Div, t, p, t, self.elem);
        let (zero, bit) = (self.int_const(0, c), self.int_const(1i64 << (63 - s), c));
        self.cmp(Cmp::Lt, x, zero);
        self.b.bin(IBin::Or, t, bit, t, self.elem);
        self.emit(Op::True);
        t
    }

    /// `x` rotated left by `s` (0 ≤ s < w) within `w` bits.
    pub(super) fn rol(&mut self, x: V, s: u32, w: u32) -> V {
        if s == 0 {
            return self.shl(x, 0, w);
        }
        let a = self.shl(x, s, w);
        let b = self.shr(x, w - s, w);
        let t = self.b.temp(vclass(x));
        self.b.bin(IBin::Or, a, b, t, self.elem);
        t
    }

    /// A shift or rotation by a computed amount `n`: by each power of two
    /// of its bits in turn. SHL/SHR by `n ≥ w` give 0, by `n < 0` the value
    /// unchanged; rotations take `n` modulo `w`.
    pub(super) fn shift_var(&mut self, f: &str, x: V, n: I, w: u32) -> V {
        let c = vclass(x);
        let r = self.b.temp(c);
        self.b.un(IUn::Mov, x, r, self.elem);
        let rotate = f == "ROL" || f == "ROR";
        let zero = self.b.const_i(0);
        let amount = if rotate {
            let wc = self.b.const_i(w as i32);
            let m = self.b.temp_i();
            self.emit(Op::BinI(IBin::Mod, n, wc, m));
            self.emit(Op::BinI(IBin::Add, m, wc, m));
            self.emit(Op::BinI(IBin::Mod, m, wc, m));
            m
        } else {
            n
        };
        let mut k = 1u32;
        while k < w {
            let shifted = self.shift_const(f, r, k, w);
            let bit = self.b.const_i(k as i32);
            let tb = self.b.temp_i();
            self.emit(Op::BinI(IBin::And, amount, bit, tb));
            self.emit(Op::CmpI(Cmp::Ne, tb, zero));
            self.b.un(IUn::Mov, shifted, r, self.elem);
            self.emit(Op::True);
            k *= 2;
        }
        if !rotate {
            let wc = self.b.const_i(w as i32);
            let z = self.int_const(0, c);
            self.emit(Op::CmpI(Cmp::Ge, n, wc));
            self.b.un(IUn::Mov, z, r, self.elem);
            self.emit(Op::True);
            self.emit(Op::CmpI(Cmp::Lt, n, zero));
            self.b.un(IUn::Mov, x, r, self.elem);
            self.emit(Op::True);
        }
        r
    }
}
