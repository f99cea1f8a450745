//! The ladder syntax tree and the instruction table (SPEC §3.2).

use alba_diag::Span;

/// A ladder program: rungs in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    pub rungs: Vec<Rung>,
    /// Comment lines after the last rung (kept so nothing is lost).
    pub trailing_comment: Option<String>,
    /// Labels set in rungs that were dropped for syntax errors, so a JMP to
    /// them does not report a second, misleading error.
    pub broken_labels: Vec<String>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Rung {
    /// The `//` lines directly above the rung, without the `//` (one entry per line).
    pub comment: Vec<String>,
    pub elements: Vec<Element>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Element {
    Instr(Instr),
    Branch(Branch),
}

impl Element {
    pub fn span(&self) -> Span {
        match self {
            Element::Instr(i) => i.span,
            Element::Branch(b) => b.span,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Instr {
    pub mnemonic: Mnemonic,
    pub operands: Vec<Operand>,
    pub span: Span,
    pub name_span: Span,
}

/// An operand as written (whitespace trimmed and collapsed). Its meaning
/// (tag, member, address, literal, expression) is decided by the checker,
/// which knows what the instruction expects there.
#[derive(Debug, Clone, PartialEq)]
pub struct Operand {
    pub text: String,
    pub span: Span,
}

/// `[leg, leg, ...]`: every leg starts from the rung state at the branch;
/// the state after it is the OR of the legs.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    pub legs: Vec<Vec<Element>>,
    pub span: Span,
}

/// The eight palette groups of the source (AuroraLD), plus the reserved PID.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Group {
    Bit,
    Timer,
    Counter,
    Compare,
    Math,
    MoveLogic,
    Trig,
    Flow,
    Special,
}

/// What an operand position expects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Arg {
    /// A BOOL to read (contact).
    BitIn,
    /// A BOOL to write (coil, one-shot storage).
    BitOut,
    Timer,
    Counter,
    /// RES: a TIMER or COUNTER.
    TimerOrCounter,
    /// Timer/counter preset: a literal (the initial PRE), `?`, or an integer tag read on every execution.
    Preset,
    /// Timer/counter accumulator: a literal (the initial ACC) or `?`.
    Accum,
    /// A number to read: tag, member, address or literal.
    NumIn,
    /// A number to write.
    NumOut,
    Label,
    /// A CPT expression.
    Expr,
    /// The PID structure (reserved).
    Pid,
}

macro_rules! instructions {
    ($($m:ident: $group:ident, $output:literal, [$($arg:ident),*], $doc:literal;)*) => {
        /// A ladder instruction.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Mnemonic { $($m,)* }

        impl Mnemonic {
            pub const ALL: &'static [Mnemonic] = &[$(Mnemonic::$m,)*];

            pub fn name(self) -> &'static str {
                match self { $(Mnemonic::$m => stringify!($m),)* }
            }

            pub fn group(self) -> Group {
                match self { $(Mnemonic::$m => Group::$group,)* }
            }

            /// Output instructions may end a rung; inputs are conditions.
            pub fn is_output(self) -> bool {
                match self { $(Mnemonic::$m => $output,)* }
            }

            pub fn args(self) -> &'static [Arg] {
                match self { $(Mnemonic::$m => &[$(Arg::$arg),*],)* }
            }

            /// One line on what it does.
            pub fn doc(self) -> &'static str {
                match self { $(Mnemonic::$m => $doc,)* }
            }
        }
    };
}

instructions! {
    XIC: Bit, false, [BitIn], "examine if closed: passes the rung when the bit is 1";
    XIO: Bit, false, [BitIn], "examine if open: passes the rung when the bit is 0";
    OTE: Bit, true, [BitOut], "output energise: bit = rung";
    OTL: Bit, true, [BitOut], "output latch: sets the bit while the rung is true";
    OTU: Bit, true, [BitOut], "output unlatch: clears the bit while the rung is true";
    ONS: Bit, false, [BitOut], "one shot: passes one scan on a rising rung (storage bit)";
    OSR: Bit, true, [BitOut, BitOut], "one shot rising: output bit true for one scan on a rising rung";
    OSF: Bit, true, [BitOut, BitOut], "one shot falling: output bit true for one scan on a falling rung";
    TON: Timer, true, [Timer, Preset, Accum], "on-delay timer (ms)";
    TOF: Timer, true, [Timer, Preset, Accum], "off-delay timer (ms)";
    RTO: Timer, true, [Timer, Preset, Accum], "retentive on-delay timer (ms), cleared by RES";
    TP: Timer, true, [Timer, Preset, Accum], "pulse timer: DN for PRE ms from a rising rung";
    CTU: Counter, true, [Counter, Preset, Accum], "count up on a rising rung";
    CTD: Counter, true, [Counter, Preset, Accum], "count down on a rising rung";
    RES: Counter, true, [TimerOrCounter], "reset a timer or counter";
    LIM: Compare, false, [NumIn, NumIn, NumIn], "limit test: low <= test <= high (wraps when low > high)";
    EQU: Compare, false, [NumIn, NumIn], "equal";
    NEQ: Compare, false, [NumIn, NumIn], "not equal";
    LES: Compare, false, [NumIn, NumIn], "less than";
    GRT: Compare, false, [NumIn, NumIn], "greater than";
    LEQ: Compare, false, [NumIn, NumIn], "less than or equal";
    GEQ: Compare, false, [NumIn, NumIn], "greater than or equal";
    MEQ: Compare, false, [NumIn, NumIn, NumIn], "masked equal: (src AND mask) = (compare AND mask)";
    ADD: Math, true, [NumIn, NumIn, NumOut], "dest = a + b";
    SUB: Math, true, [NumIn, NumIn, NumOut], "dest = a - b";
    MUL: Math, true, [NumIn, NumIn, NumOut], "dest = a * b";
    DIV: Math, true, [NumIn, NumIn, NumOut], "dest = a / b";
    MOD: Math, true, [NumIn, NumIn, NumOut], "dest = a modulo b (sign of a)";
    SQR: Math, true, [NumIn, NumOut], "dest = square root of src";
    NEG: Math, true, [NumIn, NumOut], "dest = -src";
    ABS: Math, true, [NumIn, NumOut], "dest = |src|";
    XPY: Math, true, [NumIn, NumIn, NumOut], "dest = a to the power b";
    LN: Math, true, [NumIn, NumOut], "dest = natural logarithm of src";
    LOG: Math, true, [NumIn, NumOut], "dest = base-10 logarithm of src";
    CPT: Math, true, [NumOut, Expr], "compute: dest = expression";
    SCP: Math, true, [NumIn, NumIn, NumIn, NumIn, NumIn, NumOut], "scale with parameters: (in-inMin)*((scMax-scMin)/(inMax-inMin))+scMin";
    MOV: MoveLogic, true, [NumIn, NumOut], "dest = src";
    CLR: MoveLogic, true, [NumOut], "dest = 0";
    AND: MoveLogic, true, [NumIn, NumIn, NumOut], "bitwise and";
    OR: MoveLogic, true, [NumIn, NumIn, NumOut], "bitwise or";
    XOR: MoveLogic, true, [NumIn, NumIn, NumOut], "bitwise exclusive or";
    NOT: MoveLogic, true, [NumIn, NumOut], "bitwise complement";
    SIN: Trig, true, [NumIn, NumOut], "sine (radians)";
    COS: Trig, true, [NumIn, NumOut], "cosine (radians)";
    TAN: Trig, true, [NumIn, NumOut], "tangent (radians)";
    ASN: Trig, true, [NumIn, NumOut], "arc sine (radians)";
    ACS: Trig, true, [NumIn, NumOut], "arc cosine (radians)";
    ATN: Trig, true, [NumIn, NumOut], "arc tangent (radians)";
    DEG: Trig, true, [NumIn, NumOut], "radians to degrees";
    RAD: Trig, true, [NumIn, NumOut], "degrees to radians";
    JMP: Flow, true, [Label], "jump to the rung with LBL(label) while the rung is true";
    LBL: Flow, false, [Label], "label: the target of JMP, first instruction of its rung";
    AFI: Flow, false, [], "always false";
    NOP: Flow, true, [], "no operation";
    PID: Special, true, [Pid, NumIn, NumOut], "PID loop (reserved)";
}

impl Mnemonic {
    pub fn parse(name: &str) -> Option<Mnemonic> {
        Mnemonic::ALL
            .iter()
            .copied()
            .find(|m| m.name().eq_ignore_ascii_case(name))
    }
}
