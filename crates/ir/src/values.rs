//! Emitting value computations: what every front end needs to read an
//! operand into a slot of the right class, write a result back to any place
//! (narrowing INT/SINT, storing marker memory), and convert between classes.
//!
//! An instruction computes in one [`Class`], chosen from all its operands
//! with [`promote`] (SPEC §3.2: mixed INT/REAL arithmetic is done in REAL and
//! converted to the destination).

use crate::builder::Builder;
use crate::layout::Place;
use crate::op::{B, BinOp, Cvt, D, F, I, L, MarkerSlot, Op, UnOp, Width};
use alba_model::{DataType, Literal};

/// Arithmetic class: DINT (all integers up to 32 bits), LINT, REAL, LREAL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    I,
    L,
    F,
    D,
}

/// A readable value of one class: its slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum V {
    I(I),
    L(L),
    F(F),
    D(D),
}

/// An operand's value: a literal, or a place to read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Src {
    Lit(Literal),
    Place(Place),
}

pub fn class_of_type(t: DataType) -> Class {
    match t {
        DataType::Lreal => Class::D,
        DataType::Real => Class::F,
        DataType::Lint => Class::L,
        _ => Class::I,
    }
}

pub fn class_of_lit(l: Literal) -> Class {
    match l {
        Literal::Real(_) => Class::F,
        Literal::Int(v) | Literal::Time(v) if i32::try_from(v).is_err() => Class::L,
        _ => Class::I,
    }
}

pub fn class_of(s: Src) -> Class {
    match s {
        Src::Lit(l) => class_of_lit(l),
        Src::Place(p) => class_of_type(p.data_type()),
    }
}

/// The class of an instruction from the classes of its operands: LREAL if
/// any is LREAL (or REAL meets LINT), else REAL if any is REAL, else LINT
/// if any is LINT, else DINT.
pub fn promote(classes: impl IntoIterator<Item = Class>) -> Class {
    let (mut l, mut f, mut d) = (false, false, false);
    for c in classes {
        match c {
            Class::L => l = true,
            Class::F => f = true,
            Class::D => d = true,
            Class::I => {}
        }
    }
    if d || (f && l) {
        Class::D
    } else if f {
        Class::F
    } else if l {
        Class::L
    } else {
        Class::I
    }
}

/// The floating-point class for an instruction that computes in floats.
pub fn float_class(c: Class) -> Class {
    match c {
        Class::I | Class::F => Class::F,
        Class::L | Class::D => Class::D,
    }
}

pub fn class_name(c: Class) -> &'static str {
    match c {
        Class::I => "DINT",
        Class::L => "LINT",
        Class::F => "REAL",
        Class::D => "LREAL",
    }
}

/// The op converting `from` into `to` (`None` when both have one class).
pub fn conversion(from: V, to: V) -> Option<Cvt> {
    Some(match (from, to) {
        (V::I(a), V::F(b)) => Cvt::IF(a, b),
        (V::I(a), V::L(b)) => Cvt::IL(a, b),
        (V::I(a), V::D(b)) => Cvt::ID(a, b),
        (V::F(a), V::I(b)) => Cvt::FI(a, b),
        (V::F(a), V::L(b)) => Cvt::FL(a, b),
        (V::F(a), V::D(b)) => Cvt::FD(a, b),
        (V::L(a), V::I(b)) => Cvt::LI(a, b),
        (V::L(a), V::F(b)) => Cvt::LF(a, b),
        (V::L(a), V::D(b)) => Cvt::LD(a, b),
        (V::D(a), V::I(b)) => Cvt::DI(a, b),
        (V::D(a), V::F(b)) => Cvt::DF(a, b),
        (V::D(a), V::L(b)) => Cvt::DL(a, b),
        _ => return None,
    })
}

fn class_of_v(v: V) -> Class {
    match v {
        V::I(_) => Class::I,
        V::L(_) => Class::L,
        V::F(_) => Class::F,
        V::D(_) => Class::D,
    }
}

impl Builder {
    pub fn temp(&mut self, c: Class) -> V {
        match c {
            Class::I => V::I(self.temp_i()),
            Class::L => V::L(self.temp_l()),
            Class::F => V::F(self.temp_f()),
            Class::D => V::D(self.temp_d()),
        }
    }

    /// Emits `ops` for element `elem`.
    pub fn post(&mut self, ops: Vec<Op>, elem: u32) {
        for op in ops {
            self.emit(op, elem);
        }
    }

    /// A bool slot holding the value of `p` (marker bits are loaded into a
    /// temporary).
    pub fn bool_in(&mut self, p: Place, elem: u32) -> B {
        match p {
            Place::Bool(b) => b,
            Place::MBit { byte, bit } => {
                let t = self.temp_b();
                self.emit(Op::LdBit { byte, bit, dst: t }, elem);
                t
            }
            _ => self.temp_b(),
        }
    }

    /// A bool slot to write for `p`, and the ops that store it back (marker
    /// bits are preloaded, so the store is right whatever the op does).
    pub fn bool_out(&mut self, p: Place, elem: u32) -> (B, Vec<Op>) {
        match p {
            Place::MBit { byte, bit } => {
                let t = self.bool_in(p, elem);
                (t, vec![Op::StBit { src: t, byte, bit }])
            }
            _ => (self.bool_in(p, elem), vec![]),
        }
    }

    /// Loads a numeric place in its own class (marker values into temporaries).
    pub fn load(&mut self, p: Place, elem: u32) -> V {
        let marker = |this: &mut Self, byte: u32, f: fn(I) -> MarkerSlot| {
            let t = this.temp_i();
            this.emit(Op::LdM { byte, slot: f(t) }, elem);
            V::I(t)
        };
        match p {
            Place::Int(i, _) => V::I(i),
            Place::Real(f) => V::F(f),
            Place::Lint(l) => V::L(l),
            Place::Lreal(d) => V::D(d),
            Place::MByte(at) => marker(self, at, MarkerSlot::Byte),
            Place::MWord(at) => marker(self, at, MarkerSlot::Word),
            Place::MDword(at, _) => marker(self, at, MarkerSlot::DWord),
            Place::MReal(at) => {
                let t = self.temp_f();
                self.emit(
                    Op::LdM {
                        byte: at,
                        slot: MarkerSlot::Real(t),
                    },
                    elem,
                );
                V::F(t)
            }
            Place::Bool(_) | Place::MBit { .. } => V::I(self.temp_i()),
        }
    }

    /// Reads an operand as a value of class `c`.
    pub fn read(&mut self, s: Src, c: Class, elem: u32) -> V {
        match s {
            Src::Lit(l) => self.constant(l, c),
            Src::Place(p) => {
                let v = self.load(p, elem);
                self.convert(v, c, elem)
            }
        }
    }

    /// A constant slot holding `l` in class `c`.
    pub fn constant(&mut self, l: Literal, c: Class) -> V {
        let (int, real) = match l {
            Literal::Int(v) | Literal::Time(v) => (v, v as f64),
            Literal::Real(r) => (r as i64, r),
            Literal::Bool(b) => (b as i64, b as i64 as f64),
        };
        match c {
            Class::I => V::I(self.const_i(int as i32)),
            Class::L => V::L(self.const_l(int)),
            Class::F => V::F(self.const_f(real as f32)),
            Class::D => V::D(self.const_d(real)),
        }
    }

    /// `v` in class `c` (a conversion into a temporary if needed).
    pub fn convert(&mut self, v: V, c: Class, elem: u32) -> V {
        if class_of_v(v) == c {
            return v;
        }
        let t = self.temp(c);
        if let Some(cvt) = conversion(v, t) {
            self.emit(Op::Cvt(cvt), elem);
        }
        t
    }

    /// Where an instruction of class `c` writes its result for `p`, and the
    /// ops that then convert, narrow and store it.
    pub fn dest(&mut self, p: Place, c: Class, elem: u32) -> (V, Vec<Op>) {
        let narrow = |i: I, ty: DataType| match ty {
            DataType::Sint => vec![Op::Narrow(i, Width::W8)],
            DataType::Int => vec![Op::Narrow(i, Width::W16)],
            _ => vec![],
        };
        let (native, mut post) = match p {
            Place::Int(i, ty) => (V::I(i), narrow(i, ty)),
            Place::Real(f) => (V::F(f), vec![]),
            Place::Lint(l) => (V::L(l), vec![]),
            Place::Lreal(d) => (V::D(d), vec![]),
            Place::MByte(at) | Place::MWord(at) | Place::MDword(at, _) | Place::MReal(at) => {
                // Preload, so the store-back is right when the rung is false.
                let v = self.load(p, elem);
                let store = match (p, v) {
                    (Place::MByte(_), V::I(t)) => vec![
                        Op::Narrow(t, Width::W8),
                        Op::StM {
                            byte: at,
                            slot: MarkerSlot::Byte(t),
                        },
                    ],
                    (Place::MWord(_), V::I(t)) => vec![
                        Op::Narrow(t, Width::W16),
                        Op::StM {
                            byte: at,
                            slot: MarkerSlot::Word(t),
                        },
                    ],
                    (Place::MDword(..), V::I(t)) => vec![Op::StM {
                        byte: at,
                        slot: MarkerSlot::DWord(t),
                    }],
                    (_, V::F(t)) => vec![Op::StM {
                        byte: at,
                        slot: MarkerSlot::Real(t),
                    }],
                    _ => vec![],
                };
                (v, store)
            }
            Place::Bool(_) | Place::MBit { .. } => (self.temp(c), vec![]),
        };
        if class_of_v(native) == c {
            return (native, post);
        }
        let t = self.temp(c);
        let Some(cvt) = conversion(t, native) else {
            return (native, post);
        };
        post.insert(0, Op::Cvt(cvt));
        (t, post)
    }

    /// `d = a op b` (all of one class).
    pub fn bin(&mut self, op: BinOp, a: V, b: V, d: V, elem: u32) {
        let op = match (a, b, d) {
            (V::I(a), V::I(b), V::I(d)) => Op::BinI(op, a, b, d),
            (V::F(a), V::F(b), V::F(d)) => Op::BinF(op, a, b, d),
            (V::L(a), V::L(b), V::L(d)) => Op::BinL(op, a, b, d),
            (V::D(a), V::D(b), V::D(d)) => Op::BinD(op, a, b, d),
            _ => return,
        };
        self.emit(op, elem);
    }

    /// `d = op a` (both of one class).
    pub fn un(&mut self, op: UnOp, a: V, d: V, elem: u32) {
        let op = match (a, d) {
            (V::I(a), V::I(d)) => Op::UnI(op, a, d),
            (V::F(a), V::F(d)) => Op::UnF(op, a, d),
            (V::L(a), V::L(d)) => Op::UnL(op, a, d),
            (V::D(a), V::D(d)) => Op::UnD(op, a, d),
            _ => return,
        };
        self.emit(op, elem);
    }

    /// `dest = op src` computed in class `c`, with the conversions,
    /// narrowing and marker stores the places need.
    pub fn unary_to(&mut self, op: UnOp, src: Src, dest: Place, c: Class, elem: u32) {
        let a = self.read(src, c, elem);
        let (d, post) = self.dest(dest, c, elem);
        self.un(op, a, d, elem);
        self.post(post, elem);
    }

    /// `dest = a op b` computed in class `c`.
    pub fn binary_to(&mut self, op: BinOp, a: Src, b: Src, dest: Place, c: Class, elem: u32) {
        let a = self.read(a, c, elem);
        let b = self.read(b, c, elem);
        let (d, post) = self.dest(dest, c, elem);
        self.bin(op, a, b, d, elem);
        self.post(post, elem);
    }
}
