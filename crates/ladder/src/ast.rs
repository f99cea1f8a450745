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

/// The eight palette groups of the source (AuroraLD), plus `Special` (PID).
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
    /// The PID structure.
    Pid,
}

/// An operand an instruction may be written without: the default applies
/// when it is left out (`TON(T,5,0)` counts milliseconds, `TON(T,5,0,s)`
/// seconds). It follows the required ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Optional {
    /// A timer's time base (docs/ladder.md §4.4): `ms`, `cs`, `ds`, `s` or `min`.
    TimeBase,
}

impl Optional {
    /// The kind's name in the domain (`time_base`), beside [`Arg`]'s.
    pub fn name(self) -> &'static str {
        match self {
            Optional::TimeBase => "time_base",
        }
    }

    /// The operand's name in boxes and the properties panel.
    pub fn label(self) -> &'static str {
        match self {
            Optional::TimeBase => "Time base",
        }
    }

    /// What fits there, in words.
    pub fn doc(self) -> &'static str {
        match self {
            Optional::TimeBase => "a time base: ms, cs, ds, s or min (ms when left out)",
        }
    }

    /// The values a studio offers (any case is accepted; a time base may
    /// also be written in seconds, `0.01`, as AuroraLD does).
    pub fn choices(self) -> Vec<&'static str> {
        match self {
            Optional::TimeBase => crate::TimeBase::ALL.iter().map(|b| b.name()).collect(),
        }
    }

    /// The value that applies when the operand is left out.
    pub fn default_value(self) -> &'static str {
        match self {
            Optional::TimeBase => crate::TimeBase::default().name(),
        }
    }
}

macro_rules! instructions {
    ($($m:ident: $group:ident, $output:literal, [$($arg:ident $label:literal),*], $title:literal, $doc:literal;)*) => {
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

            /// The operand names shown in boxes and the properties panel, one per argument.
            pub fn labels(self) -> &'static [&'static str] {
                match self { $(Mnemonic::$m => &[$($label),*],)* }
            }

            /// The full name (box titles).
            pub fn title(self) -> &'static str {
                match self { $(Mnemonic::$m => $title,)* }
            }

            /// One line on what it does.
            pub fn doc(self) -> &'static str {
                match self { $(Mnemonic::$m => $doc,)* }
            }
        }
    };
}

instructions! {
    XIC: Bit, false, [BitIn "Bit"], "Examine If Closed", "examine if closed: passes the rung when the bit is 1";
    XIO: Bit, false, [BitIn "Bit"], "Examine If Open", "examine if open: passes the rung when the bit is 0";
    OTE: Bit, true, [BitOut "Bit"], "Output Energize", "output energise: bit = rung";
    OTL: Bit, true, [BitOut "Bit"], "Output Latch", "output latch: sets the bit while the rung is true";
    OTU: Bit, true, [BitOut "Bit"], "Output Unlatch", "output unlatch: clears the bit while the rung is true";
    ONS: Bit, false, [BitOut "Storage Bit"], "One Shot", "one shot: passes one scan on a rising rung (storage bit)";
    OSR: Bit, true, [BitOut "Storage Bit", BitOut "Output Bit"], "One Shot Rising", "one shot rising: output bit true for one scan on a rising rung";
    OSF: Bit, true, [BitOut "Storage Bit", BitOut "Output Bit"], "One Shot Falling", "one shot falling: output bit true for one scan on a falling rung";
    TON: Timer, true, [Timer "Timer", Preset "Preset", Accum "Accum"], "Timer On Delay", "on-delay timer (ms; a 4th operand gives another time base: cs ds s min)";
    TOF: Timer, true, [Timer "Timer", Preset "Preset", Accum "Accum"], "Timer Off Delay", "off-delay timer (ms; a 4th operand gives another time base: cs ds s min)";
    RTO: Timer, true, [Timer "Timer", Preset "Preset", Accum "Accum"], "Retentive Timer On", "retentive on-delay timer (ms; a 4th operand gives another time base: cs ds s min), cleared by RES";
    TP: Timer, true, [Timer "Timer", Preset "Preset", Accum "Accum"], "Pulse Timer", "pulse timer: DN for PRE ms from a rising rung";
    CTU: Counter, true, [Counter "Counter", Preset "Preset", Accum "Accum"], "Count Up", "count up on a rising rung";
    CTD: Counter, true, [Counter "Counter", Preset "Preset", Accum "Accum"], "Count Down", "count down on a rising rung";
    RES: Counter, true, [TimerOrCounter "Structure"], "Reset", "reset a timer or counter";
    LIM: Compare, false, [NumIn "Low Limit", NumIn "Test", NumIn "High Limit"], "Limit Test", "limit test: low <= test <= high (wraps when low > high)";
    EQU: Compare, false, [NumIn "Source A", NumIn "Source B"], "Equal", "equal";
    NEQ: Compare, false, [NumIn "Source A", NumIn "Source B"], "Not Equal", "not equal";
    LES: Compare, false, [NumIn "Source A", NumIn "Source B"], "Less Than", "less than";
    GRT: Compare, false, [NumIn "Source A", NumIn "Source B"], "Greater Than", "greater than";
    LEQ: Compare, false, [NumIn "Source A", NumIn "Source B"], "Less Than or Equal", "less than or equal";
    GEQ: Compare, false, [NumIn "Source A", NumIn "Source B"], "Greater Than or Equal", "greater than or equal";
    MEQ: Compare, false, [NumIn "Source", NumIn "Mask", NumIn "Compare"], "Masked Equal", "masked equal: (src AND mask) = (compare AND mask)";
    ADD: Math, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Add", "dest = a + b";
    SUB: Math, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Subtract", "dest = a - b";
    MUL: Math, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Multiply", "dest = a * b";
    DIV: Math, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Divide", "dest = a / b";
    MOD: Math, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Modulo", "dest = a modulo b (sign of a)";
    SQR: Math, true, [NumIn "Source", NumOut "Dest"], "Square Root", "dest = square root of src";
    NEG: Math, true, [NumIn "Source", NumOut "Dest"], "Negate", "dest = -src";
    ABS: Math, true, [NumIn "Source", NumOut "Dest"], "Absolute Value", "dest = |src|";
    XPY: Math, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "X to the Power of Y", "dest = a to the power b";
    LN: Math, true, [NumIn "Source", NumOut "Dest"], "Natural Log", "dest = natural logarithm of src";
    LOG: Math, true, [NumIn "Source", NumOut "Dest"], "Log Base 10", "dest = base-10 logarithm of src";
    CPT: Math, true, [NumOut "Dest", Expr "Expression"], "Compute", "compute: dest = expression";
    SCP: Math, true, [NumIn "Input", NumIn "Input Min", NumIn "Input Max", NumIn "Scaled Min", NumIn "Scaled Max", NumOut "Output"], "Scale with Parameters", "scale with parameters: (in-inMin)*((scMax-scMin)/(inMax-inMin))+scMin";
    MOV: MoveLogic, true, [NumIn "Source", NumOut "Dest"], "Move", "dest = src";
    CLR: MoveLogic, true, [NumOut "Dest"], "Clear", "dest = 0";
    AND: MoveLogic, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Bitwise AND", "bitwise and";
    OR: MoveLogic, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Bitwise OR", "bitwise or";
    XOR: MoveLogic, true, [NumIn "Source A", NumIn "Source B", NumOut "Dest"], "Bitwise XOR", "bitwise exclusive or";
    NOT: MoveLogic, true, [NumIn "Source", NumOut "Dest"], "Bitwise NOT", "bitwise complement";
    SIN: Trig, true, [NumIn "Source", NumOut "Dest"], "Sine", "sine (radians)";
    COS: Trig, true, [NumIn "Source", NumOut "Dest"], "Cosine", "cosine (radians)";
    TAN: Trig, true, [NumIn "Source", NumOut "Dest"], "Tangent", "tangent (radians)";
    ASN: Trig, true, [NumIn "Source", NumOut "Dest"], "Arc Sine", "arc sine (radians)";
    ACS: Trig, true, [NumIn "Source", NumOut "Dest"], "Arc Cosine", "arc cosine (radians)";
    ATN: Trig, true, [NumIn "Source", NumOut "Dest"], "Arc Tangent", "arc tangent (radians)";
    DEG: Trig, true, [NumIn "Source", NumOut "Dest"], "Radians to Degrees", "radians to degrees";
    RAD: Trig, true, [NumIn "Source", NumOut "Dest"], "Degrees to Radians", "degrees to radians";
    JMP: Flow, true, [Label "Label"], "Jump to Label", "jump to the rung with LBL(label) while the rung is true";
    LBL: Flow, false, [Label "Label"], "Label", "label: the target of JMP, first instruction of its rung";
    AFI: Flow, false, [], "Always False", "always false";
    NOP: Flow, true, [], "No Operation", "no operation";
    PID: Special, true, [Pid "PID", NumIn "Process Var", NumOut "Control Var"], "PID Loop", "PID loop: drives the control output from the process value (docs/pid.md)";
}

impl Mnemonic {
    /// The operands that may follow [`Mnemonic::args`], in order (a TON's
    /// time base); the checker accepts each one left out.
    pub fn optional(self) -> &'static [Optional] {
        match self {
            Mnemonic::TON | Mnemonic::TOF | Mnemonic::RTO => &[Optional::TimeBase],
            _ => &[],
        }
    }

    pub fn parse(name: &str) -> Option<Mnemonic> {
        Mnemonic::ALL
            .iter()
            .copied()
            .find(|m| m.name().eq_ignore_ascii_case(name))
    }
}
