//! The operations of the IR.
//!
//! A program is a flat list of [`Op`]s over typed slots, evaluated with one
//! boolean register, the *rung condition* `rc`:
//!
//! * rung logic (`Rung`, contacts, coils, branches) reads and writes `rc`;
//! * compares are input instructions: `rc &= a <op> b`;
//! * data operations (`Bin*`, `Un*`, `Cvt`, `Narrow`) act only while `rc` is
//!   true, like Logix output instructions;
//! * timers and counters run on every execution and read `rc`;
//! * marker loads/stores move values between the byte-addressed marker
//!   memory and temporary slots, unconditionally.
//!
//! Branches keep their state in ordinary (temporary) bool slots, so the only
//! dynamic state of an evaluation is `rc` and the program counter: a bounded,
//! heap-free model that an 8-bit microcontroller runs as easily as a PC.

/// A BOOL slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct B(pub u32);
/// A 32-bit integer slot (SINT, INT, DINT, TIME; narrower types are kept in
/// range by [`Op::Narrow`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct I(pub u32);
/// A REAL (f32) slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct F(pub u32);
/// A LINT (i64) slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct L(pub u32);
/// An LREAL (f64) slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct D(pub u32);

/// A TIMER: integer slots `i` = PRE, `i+1` = ACC, `i+2` = start/last time
/// (hidden, wrapping milliseconds); bool slots `b` = EN, `b+1` = TT, `b+2` = DN.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Tmr {
    pub i: I,
    pub b: B,
}

/// A timer's time base (AuroraLD Table 7, the SLC 500's TON/TOF/RTO): the
/// unit in which `ACC` and `PRE` count. Clock time not yet making a whole
/// unit is kept (the timer's last update moves by whole units only), so no
/// time is lost between scans. IEC and Logix timers are [`TimeBase::Ms`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum TimeBase {
    /// 0.001 s
    #[default]
    Ms,
    /// 0.01 s
    Cs,
    /// 0.1 s
    Ds,
    /// 1 s
    S,
    /// 60 s
    Min,
}

impl TimeBase {
    /// Every base, in the order of their codes (byte code, docs).
    pub const ALL: [TimeBase; 5] = [TimeBase::Ms, TimeBase::Cs, TimeBase::Ds, TimeBase::S, TimeBase::Min];

    /// Milliseconds in one unit.
    pub const fn ms(self) -> u32 {
        match self {
            TimeBase::Ms => 1,
            TimeBase::Cs => 10,
            TimeBase::Ds => 100,
            TimeBase::S => 1000,
            TimeBase::Min => 60_000,
        }
    }

    /// The unit's name as the ladder text writes it (`ms cs ds s min`).
    pub const fn name(self) -> &'static str {
        match self {
            TimeBase::Ms => "ms",
            TimeBase::Cs => "cs",
            TimeBase::Ds => "ds",
            TimeBase::S => "s",
            TimeBase::Min => "min",
        }
    }

    /// The base named `ms`, `cs`, `ds`, `s` or `min` (any case), or given in
    /// seconds as AuroraLD and the SLC 500 write it (`0.001`, `0.01`, `0.1`,
    /// `1.0`, `60`).
    pub fn parse(text: &str) -> Option<TimeBase> {
        let t = text.trim();
        if let Some(b) = TimeBase::ALL.into_iter().find(|b| b.name().eq_ignore_ascii_case(t)) {
            return Some(b);
        }
        let secs: f64 = t.parse().ok()?;
        TimeBase::from_seconds(secs)
    }

    /// The base of this many seconds, if it is one of Table 7's.
    pub fn from_seconds(secs: f64) -> Option<TimeBase> {
        TimeBase::ALL
            .into_iter()
            .find(|b| (f64::from(b.ms()) / 1000.0 - secs).abs() < 1e-9)
    }

    /// The base's code in the byte code (its index in [`TimeBase::ALL`]).
    pub fn code(self) -> u8 {
        self as u8
    }

    pub fn from_code(code: u8) -> Option<TimeBase> {
        TimeBase::ALL.get(usize::from(code)).copied()
    }
}

/// A COUNTER: integer slots `i` = PRE, `i+1` = ACC; bool slots `b` = CU,
/// `b+1` = CD, `b+2` = DN, `b+3` = OV, `b+4` = UN.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Ctr {
    pub i: I,
    pub b: B,
}

/// A PID loop (SPEC §6): REAL slots from `f`, DINT slots from `i`, BOOL
/// slots from `b`. The first slots of each class are the members of
/// `alba_model::types::PID_MEMBERS` in their order; hidden state follows
/// (see the `PID_*` constants). The instruction reads its raw input from
/// `f + PID_F_IN` and leaves its raw output in `f + PID_F_OUT`: the front
/// end moves the operands there and back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Pidt {
    pub f: F,
    pub i: I,
    pub b: B,
}

/// REAL members (SP … DFN).
pub const PID_F_MEMBERS: u32 = 21;
/// Hidden REAL slots, after the members.
pub const PID_F_IN: u32 = 21;
pub const PID_F_OUT: u32 = 22;
/// Integral term (%), or u(k-1) of the velocity forms.
pub const PID_F_INT: u32 = 23;
/// Previous derivative input (PV or error, %).
pub const PID_F_DPREV: u32 = 24;
/// Filtered derivative term (%).
pub const PID_F_DTERM: u32 = 25;
/// e(k-1) and e(k-2) of the velocity forms (%).
pub const PID_F_E1: u32 = 26;
pub const PID_F_E2: u32 = 27;
/// The last valid setpoint (used while SP is out of range).
pub const PID_F_SPLAST: u32 = 28;
/// The previous error, for the zero-crossing deadband.
pub const PID_F_EPREV: u32 = 29;
pub const PID_F_SLOTS: u32 = 30;
/// DINT members (UPD ERRC FORM), then hidden: clock of the next update,
/// and e(k-1), e(k-2), u(k-1) of the 16-bit forms.
pub const PID_I_MEMBERS: u32 = 3;
pub const PID_I_DUE: u32 = 3;
pub const PID_I_E1: u32 = 4;
pub const PID_I_E2: u32 = 5;
pub const PID_I_U1: u32 = 6;
pub const PID_I_SLOTS: u32 = 7;
/// BOOL members (EN … OL, TM, MINUTES), then hidden: running
/// (initialised), manual at the last execution.
pub const PID_B_MEMBERS: u32 = 15;
pub const PID_B_RUN: u32 = 15;
pub const PID_B_WASMAN: u32 = 16;
pub const PID_B_SLOTS: u32 = 17;

/// An S7-200 timer (Instruction List): integer slots `i` = current value
/// (in units of the resolution), `i+1` = PT, `i+2` = milliseconds not yet
/// counted, `i+3` = clock at the last update; bool slots `b` = timer bit,
/// `b+1` = enable at the last execution. `res` is the resolution in ms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct S7Tmr {
    pub i: I,
    pub b: B,
    pub res: u16,
}

/// An S7-200 counter: integer slots `i` = current value, `i+1` = PV; bool
/// slots `b` = counter bit, `b+1`/`b+2` = count-up/count-down input at the
/// last execution, `b+3`/`b+4` = the count-up/count-down inputs of this
/// execution (copied there from the logic stack).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct S7Ctr {
    pub i: I,
    pub b: B,
}

/// Comparison operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cmp {
    Eq,
    Ne,
    Lt,
    Gt,
    Le,
    Ge,
}

/// Two-operand operations `d = a op b`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Mod,
    /// Floating point only.
    Pow,
    /// Floating point only.
    Atan2,
    /// Integers only (bitwise).
    And,
    Or,
    Xor,
    /// Comparisons giving 1 or 0 (for CPT expressions).
    Cmp(Cmp),
}

/// One-operand operations `d = op a`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnOp {
    Mov,
    Neg,
    Abs,
    /// Integers only: bitwise complement.
    Not,
    /// Integers only: BCD to integer.
    Frd,
    /// Integers only: integer to BCD.
    Tod,
    // Floating point only:
    Sqrt,
    Ln,
    Log,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Deg,
    Rad,
    Trunc,
    Round,
}

/// Conversions between storage classes. Float to integer rounds half to
/// even and saturates (with a fault) when out of range; wide to narrow
/// integer wraps (with a fault) when out of range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cvt {
    IF(I, F),
    FI(F, I),
    IL(I, L),
    LI(L, I),
    ID(I, D),
    DI(D, I),
    LF(L, F),
    FL(F, L),
    LD(L, D),
    DL(D, L),
    FD(F, D),
    DF(D, F),
}

/// Width of a value kept in a 32-bit slot or in marker memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Width {
    W8,
    W16,
}

/// What a marker load/store moves (big-endian in marker memory).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MarkerSlot {
    /// MB: a signed byte into an integer slot.
    Byte(I),
    /// MW: a signed 16-bit word into an integer slot.
    Word(I),
    /// MD as DINT or TIME.
    DWord(I),
    /// MD as REAL.
    Real(F),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Op {
    /// Start of a rung: `rc = true`.
    Rung,
    /// Does nothing (NOP, LBL).
    Nop,
    /// `rc = false` (AFI).
    Afi,
    Xic(B),
    Xio(B),
    /// `b = rc`.
    Ote(B),
    /// `if rc { b = true }`.
    Otl(B),
    /// `if rc { b = false }`.
    Otu(B),
    /// One-shot: `out = rc && !s; s = rc; rc = out`.
    Ons(B),
    /// `o = rc && !s; s = rc` (rc passes on).
    Osr(B, B),
    /// `o = !rc && s; s = rc` (rc passes on).
    Osf(B, B),
    /// Branch start: `save = rc; acc = false`.
    BrOpen {
        save: B,
        acc: B,
    },
    /// Next leg: `acc |= rc; rc = save`.
    BrNext {
        save: B,
        acc: B,
    },
    /// Branch end: `rc |= acc`.
    BrClose {
        acc: B,
    },
    /// If `rc`, continue at the op with this index (the `Rung` of the label's rung).
    Jmp(u32),
    /// TON, TOF, RTO counting `ACC` in units of the time base.
    Ton(Tmr, TimeBase),
    Tof(Tmr, TimeBase),
    Rto(Tmr, TimeBase),
    /// TP (IEC): milliseconds.
    Tp(Tmr),
    Ctu(Ctr),
    Ctd(Ctr),
    /// If `rc`: clear ACC and every status bit.
    ResT(Tmr),
    ResC(Ctr),
    /// `rc &= a <cmp> b`.
    CmpI(Cmp, I, I),
    CmpF(Cmp, F, F),
    CmpL(Cmp, L, L),
    CmpD(Cmp, D, D),
    /// `rc &= lim(low, test, high)` with the Logix wrap-around rule.
    LimI(I, I, I),
    LimF(F, F, F),
    LimL(L, L, L),
    LimD(D, D, D),
    /// `rc &= (src & mask) == (cmp & mask)`.
    MeqI(I, I, I),
    MeqL(L, L, L),
    /// If `rc`: `d = a op b`.
    BinI(BinOp, I, I, I),
    BinF(BinOp, F, F, F),
    BinL(BinOp, L, L, L),
    BinD(BinOp, D, D, D),
    /// If `rc`: `d = op a`.
    UnI(UnOp, I, I),
    UnF(UnOp, F, F),
    UnL(UnOp, L, L),
    UnD(UnOp, D, D),
    /// If `rc`: convert.
    Cvt(Cvt),
    /// If `rc`: wrap the slot to 8 or 16 bits (fault if it changed).
    Narrow(I, Width),
    /// Unconditional copy (a timer's preset read from a tag on every execution).
    CopyI(I, I),
    /// Marker memory bit → bool slot.
    LdBit {
        byte: u32,
        bit: u8,
        dst: B,
    },
    /// Bool slot → marker memory bit.
    StBit {
        src: B,
        byte: u32,
        bit: u8,
    },
    /// Marker memory → slot.
    LdM {
        byte: u32,
        slot: MarkerSlot,
    },
    /// Slot → marker memory.
    StM {
        byte: u32,
        slot: MarkerSlot,
    },
    // Logic-stack operations of Instruction List:
    /// `rc = b`.
    Ld(B),
    /// `rc = !b`.
    Ldn(B),
    /// `rc |= b`.
    Or(B),
    /// `rc |= !b`.
    Orn(B),
    /// `rc = !rc`.
    Not,
    /// `rc = true`.
    True,
    /// Falling edge: `out = !rc && s; s = rc; rc = out` (ED; EU is `Ons`).
    Ed(B),
    /// Unconditional bool copy `d = s`.
    CopyB(B, B),
    /// S7-200 timers and counters (see `S7Tmr`, `S7Ctr`); `rc` is the
    /// enable (timers), the reset (CTU, CTUD) or the load input (CTD).
    S7Ton(S7Tmr),
    S7Tonr(S7Tmr),
    S7Tof(S7Tmr),
    /// If `rc`: current value, pending time and bit cleared.
    S7ResT(S7Tmr),
    S7Ctu(S7Ctr),
    S7Ctd(S7Ctr),
    S7Ctud(S7Ctr),
    /// If `rc`: current value and bit cleared.
    S7ResC(S7Ctr),
    /// The PID loop: runs on every execution and reads `rc` (see `Pidt`).
    Pid(Pidt),
}

/// A slot of any class, for visiting every slot an op touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AnySlot {
    B(u32),
    I(u32),
    F(u32),
    L(u32),
    D(u32),
    /// A byte range of marker memory.
    M(u32, u32),
}

impl Op {
    /// Whether the op means something: a marker bit is 0-7, and a REAL or
    /// LREAL takes no bitwise operation, `NOT`, `FRD` or `TOD`
    /// ([`crate::Program::verify`] refuses the others).
    pub fn is_defined(&self) -> bool {
        !match self {
            Op::LdBit { bit, .. } | Op::StBit { bit, .. } => *bit > 7,
            Op::BinF(o, ..) | Op::BinD(o, ..) => matches!(o, BinOp::And | BinOp::Or | BinOp::Xor),
            Op::UnF(o, ..) | Op::UnD(o, ..) => matches!(o, UnOp::Not | UnOp::Frd | UnOp::Tod),
            _ => false,
        }
    }

    /// Every slot the op reads or writes (for verification at load time).
    pub fn slots(&self) -> Vec<AnySlot> {
        use AnySlot as S;
        // Saturating: a crafted slot near u32::MAX must fail verification, not overflow.
        let tmr = |t: &Tmr| {
            vec![
                S::I(t.i.0),
                S::I(t.i.0.saturating_add(2)),
                S::B(t.b.0),
                S::B(t.b.0.saturating_add(2)),
            ]
        };
        let ctr = |c: &Ctr| {
            vec![
                S::I(c.i.0),
                S::I(c.i.0.saturating_add(1)),
                S::B(c.b.0),
                S::B(c.b.0.saturating_add(4)),
            ]
        };
        let s7t = |t: &S7Tmr| {
            vec![
                S::I(t.i.0),
                S::I(t.i.0.saturating_add(3)),
                S::B(t.b.0),
                S::B(t.b.0.saturating_add(1)),
            ]
        };
        let s7c = |c: &S7Ctr| {
            vec![
                S::I(c.i.0),
                S::I(c.i.0.saturating_add(1)),
                S::B(c.b.0),
                S::B(c.b.0.saturating_add(4)),
            ]
        };
        let ms = |byte: u32, s: &MarkerSlot| match *s {
            MarkerSlot::Byte(i) => vec![S::I(i.0), S::M(byte, 1)],
            MarkerSlot::Word(i) => vec![S::I(i.0), S::M(byte, 2)],
            MarkerSlot::DWord(i) => vec![S::I(i.0), S::M(byte, 4)],
            MarkerSlot::Real(f) => vec![S::F(f.0), S::M(byte, 4)],
        };
        match self {
            Op::Rung | Op::Nop | Op::Afi | Op::Jmp(_) => vec![],
            Op::Xic(b) | Op::Xio(b) | Op::Ote(b) | Op::Otl(b) | Op::Otu(b) | Op::Ons(b) => {
                vec![S::B(b.0)]
            }
            Op::Osr(a, b) | Op::Osf(a, b) => vec![S::B(a.0), S::B(b.0)],
            Op::BrOpen { save, acc } | Op::BrNext { save, acc } => vec![S::B(save.0), S::B(acc.0)],
            Op::BrClose { acc } => vec![S::B(acc.0)],
            Op::Ton(t, _) | Op::Tof(t, _) | Op::Rto(t, _) | Op::Tp(t) | Op::ResT(t) => tmr(t),
            Op::Ctu(c) | Op::Ctd(c) | Op::ResC(c) => ctr(c),
            Op::CmpI(_, a, b) => vec![S::I(a.0), S::I(b.0)],
            Op::CmpF(_, a, b) => vec![S::F(a.0), S::F(b.0)],
            Op::CmpL(_, a, b) => vec![S::L(a.0), S::L(b.0)],
            Op::CmpD(_, a, b) => vec![S::D(a.0), S::D(b.0)],
            Op::LimI(a, b, c) | Op::MeqI(a, b, c) | Op::BinI(_, a, b, c) => {
                vec![S::I(a.0), S::I(b.0), S::I(c.0)]
            }
            Op::LimF(a, b, c) | Op::BinF(_, a, b, c) => vec![S::F(a.0), S::F(b.0), S::F(c.0)],
            Op::LimL(a, b, c) | Op::MeqL(a, b, c) | Op::BinL(_, a, b, c) => {
                vec![S::L(a.0), S::L(b.0), S::L(c.0)]
            }
            Op::LimD(a, b, c) | Op::BinD(_, a, b, c) => vec![S::D(a.0), S::D(b.0), S::D(c.0)],
            Op::UnI(_, a, d) | Op::CopyI(a, d) => vec![S::I(a.0), S::I(d.0)],
            Op::UnF(_, a, d) => vec![S::F(a.0), S::F(d.0)],
            Op::UnL(_, a, d) => vec![S::L(a.0), S::L(d.0)],
            Op::UnD(_, a, d) => vec![S::D(a.0), S::D(d.0)],
            Op::Narrow(a, _) => vec![S::I(a.0)],
            Op::Cvt(c) => match *c {
                Cvt::IF(a, b) => vec![S::I(a.0), S::F(b.0)],
                Cvt::FI(a, b) => vec![S::F(a.0), S::I(b.0)],
                Cvt::IL(a, b) => vec![S::I(a.0), S::L(b.0)],
                Cvt::LI(a, b) => vec![S::L(a.0), S::I(b.0)],
                Cvt::ID(a, b) => vec![S::I(a.0), S::D(b.0)],
                Cvt::DI(a, b) => vec![S::D(a.0), S::I(b.0)],
                Cvt::LF(a, b) => vec![S::L(a.0), S::F(b.0)],
                Cvt::FL(a, b) => vec![S::F(a.0), S::L(b.0)],
                Cvt::LD(a, b) => vec![S::L(a.0), S::D(b.0)],
                Cvt::DL(a, b) => vec![S::D(a.0), S::L(b.0)],
                Cvt::FD(a, b) => vec![S::F(a.0), S::D(b.0)],
                Cvt::DF(a, b) => vec![S::D(a.0), S::F(b.0)],
            },
            Op::LdBit { byte, dst, .. } => vec![S::B(dst.0), S::M(*byte, 1)],
            Op::StBit { src, byte, .. } => vec![S::B(src.0), S::M(*byte, 1)],
            Op::LdM { byte, slot } | Op::StM { byte, slot } => ms(*byte, slot),
            Op::Not | Op::True => vec![],
            Op::Ld(b) | Op::Ldn(b) | Op::Or(b) | Op::Orn(b) | Op::Ed(b) => vec![S::B(b.0)],
            Op::CopyB(a, b) => vec![S::B(a.0), S::B(b.0)],
            Op::S7Ton(t) | Op::S7Tonr(t) | Op::S7Tof(t) | Op::S7ResT(t) => s7t(t),
            Op::S7Ctu(c) | Op::S7Ctd(c) | Op::S7Ctud(c) | Op::S7ResC(c) => s7c(c),
            Op::Pid(p) => vec![
                S::F(p.f.0),
                S::F(p.f.0.saturating_add(PID_F_SLOTS - 1)),
                S::I(p.i.0),
                S::I(p.i.0.saturating_add(PID_I_SLOTS - 1)),
                S::B(p.b.0),
                S::B(p.b.0.saturating_add(PID_B_SLOTS - 1)),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ops_stay_small() {
        // The interpreter streams ops through the cache: keep them at 16 bytes.
        assert_eq!(std::mem::size_of::<Op>(), 16);
    }
}
