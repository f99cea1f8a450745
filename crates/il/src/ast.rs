//! The AWL program as parsed: networks and instructions, with the S7-200
//! instruction table.

use alba_diag::Span;
use alba_ir::Cmp;
use alba_ir::op::BinOp;

#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    pub items: Vec<Item>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// `NETWORK n`: a new network starts (its logic stack empty).
    Network {
        number: Option<u32>,
        span: Span,
    },
    Instr(Instr),
    /// A line that was reported and dropped: the logic stack of its network
    /// is unknown from here on.
    Bad,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Instr {
    pub mn: Mn,
    /// The mnemonic as written.
    pub name: String,
    pub operands: Vec<Operand>,
    /// The whole instruction (without its comment).
    pub span: Span,
    pub name_span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Operand {
    pub text: String,
    pub span: Span,
}

/// Data width of an instruction family: byte, word (INT), double word
/// (DINT), real.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Ty {
    B,
    W,
    D,
    R,
}

impl Ty {
    pub fn name(self) -> &'static str {
        match self {
            Ty::B => "a byte",
            Ty::W => "a word (INT)",
            Ty::D => "a double word (DINT)",
            Ty::R => "a REAL",
        }
    }
}

/// How a compare combines with the stack: push (LD), AND, OR.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum How {
    Load,
    And,
    Or,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TimerKind {
    Ton,
    Tonr,
    Tof,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CounterKind {
    Ctu,
    Ctd,
    Ctud,
}

impl TimerKind {
    pub fn name(self) -> &'static str {
        match self {
            TimerKind::Ton => "TON",
            TimerKind::Tonr => "TONR",
            TimerKind::Tof => "TOF",
        }
    }
}

impl CounterKind {
    pub fn name(self) -> &'static str {
        match self {
            CounterKind::Ctu => "CTU",
            CounterKind::Ctd => "CTD",
            CounterKind::Ctud => "CTUD",
        }
    }
}

/// An S7-200 instruction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mn {
    /// LD / LDN.
    Load {
        neg: bool,
    },
    /// A / AN.
    And {
        neg: bool,
    },
    /// O / ON.
    Or {
        neg: bool,
    },
    Not,
    /// `=`.
    Out,
    /// S bit, N.
    Set,
    /// R bit, N (also timers and counters).
    Reset,
    Eu,
    Ed,
    Ald,
    Old,
    Lps,
    Lrd,
    Lpp,
    Lds,
    Cmp {
        how: How,
        ty: Ty,
        op: Cmp,
    },
    /// `+I IN1, OUT`: OUT = OUT op IN1.
    Math {
        op: BinOp,
        ty: Ty,
    },
    /// INCW / DECW…: OUT = OUT ± 1.
    Inc {
        ty: Ty,
        down: bool,
    },
    Mov {
        ty: Ty,
    },
    Timer(TimerKind),
    Counter(CounterKind),
    For,
    Next,
    Jmp,
    Lbl,
    Nop,
}

fn ty_of(c: char) -> Option<Ty> {
    Some(match c {
        'B' => Ty::B,
        'W' => Ty::W,
        'D' => Ty::D,
        'R' => Ty::R,
        _ => return None,
    })
}

impl Mn {
    /// Parses a mnemonic, case-insensitively. The immediate forms (`LDI`,
    /// `=I`, `SI`…) are the plain ones: in Alba the I/O image is the field.
    pub fn parse(name: &str) -> Option<Mn> {
        let u = name.to_ascii_uppercase();
        let plain = match u.as_str() {
            "LDI" | "LDNI" | "AI" | "ANI" | "OI" | "ONI" | "=I" | "SI" | "RI" => &u[..u.len() - 1],
            _ => u.as_str(),
        };
        Some(match plain {
            "LD" => Mn::Load { neg: false },
            "LDN" => Mn::Load { neg: true },
            "A" => Mn::And { neg: false },
            "AN" => Mn::And { neg: true },
            "O" => Mn::Or { neg: false },
            "ON" => Mn::Or { neg: true },
            "NOT" => Mn::Not,
            "=" => Mn::Out,
            "S" => Mn::Set,
            "R" => Mn::Reset,
            "EU" => Mn::Eu,
            "ED" => Mn::Ed,
            "ALD" => Mn::Ald,
            "OLD" => Mn::Old,
            "LPS" => Mn::Lps,
            "LRD" => Mn::Lrd,
            "LPP" => Mn::Lpp,
            "LDS" => Mn::Lds,
            "INCB" | "INCW" | "INCD" | "DECB" | "DECW" | "DECD" => Mn::Inc {
                ty: ty_of(plain.chars().last()?)?,
                down: plain.starts_with("DEC"),
            },
            "MOVB" | "MOVW" | "MOVD" | "MOVR" => Mn::Mov {
                ty: ty_of(plain.chars().last()?)?,
            },
            "TON" => Mn::Timer(TimerKind::Ton),
            "TONR" => Mn::Timer(TimerKind::Tonr),
            "TOF" | "TOFF" => Mn::Timer(TimerKind::Tof),
            "CTU" => Mn::Counter(CounterKind::Ctu),
            "CTD" => Mn::Counter(CounterKind::Ctd),
            "CTUD" => Mn::Counter(CounterKind::Ctud),
            "FOR" => Mn::For,
            "NEXT" => Mn::Next,
            "JMP" => Mn::Jmp,
            "LBL" => Mn::Lbl,
            "NOP" => Mn::Nop,
            _ => return Mn::parse_family(plain),
        })
    }

    /// `+I`, `/R`…, and compares `LDW=`, `AD<>`, `OR>=`…
    fn parse_family(u: &str) -> Option<Mn> {
        if let Some(op) = u.chars().next().and_then(|c| match c {
            '+' => Some(BinOp::Add),
            '-' => Some(BinOp::Sub),
            '*' => Some(BinOp::Mul),
            '/' => Some(BinOp::Div),
            _ => None,
        }) {
            let rest = &u[1..];
            let ty = match rest {
                "I" => Ty::W,
                "D" => Ty::D,
                "R" => Ty::R,
                _ => return None,
            };
            return Some(Mn::Math { op, ty });
        }
        let (how, rest) = if let Some(r) = u.strip_prefix("LD") {
            (How::Load, r)
        } else if let Some(r) = u.strip_prefix('A') {
            (How::And, r)
        } else if let Some(r) = u.strip_prefix('O') {
            (How::Or, r)
        } else {
            return None;
        };
        let mut chars = rest.chars();
        let ty = ty_of(chars.next()?)?;
        let op = match chars.as_str() {
            "=" | "==" => Cmp::Eq,
            "<>" => Cmp::Ne,
            "<" => Cmp::Lt,
            ">" => Cmp::Gt,
            "<=" => Cmp::Le,
            ">=" => Cmp::Ge,
            _ => return None,
        };
        Some(Mn::Cmp { how, ty, op })
    }

    /// How many operands it takes (a range for `NOP`, whose count is optional).
    pub fn operand_count(self) -> (usize, usize) {
        match self {
            Mn::Not | Mn::Eu | Mn::Ed | Mn::Ald | Mn::Old | Mn::Lps | Mn::Lrd | Mn::Lpp | Mn::Next => (0, 0),
            Mn::Nop => (0, 1),
            Mn::Load { .. }
            | Mn::And { .. }
            | Mn::Or { .. }
            | Mn::Out
            | Mn::Lds
            | Mn::Inc { .. }
            | Mn::Jmp
            | Mn::Lbl => (1, 1),
            Mn::Set | Mn::Reset | Mn::Cmp { .. } | Mn::Math { .. } | Mn::Mov { .. } | Mn::Timer(_) | Mn::Counter(_) => {
                (2, 2)
            }
            Mn::For => (3, 3),
        }
    }

    /// What its operands are, for messages: `LD bit`, `MOVW IN, OUT`.
    pub fn usage(self) -> &'static str {
        match self {
            Mn::Load { .. } | Mn::And { .. } | Mn::Or { .. } => "bit",
            Mn::Out => "bit",
            Mn::Set | Mn::Reset => "bit, N",
            Mn::Lds => "n",
            Mn::Cmp { .. } => "IN1, IN2",
            Mn::Math { .. } => "IN1, OUT",
            Mn::Inc { .. } => "OUT",
            Mn::Mov { .. } => "IN, OUT",
            Mn::Timer(_) => "Txxx, PT",
            Mn::Counter(_) => "Cxxx, PV",
            Mn::For => "INDX, INIT, FINAL",
            Mn::Jmp | Mn::Lbl => "n",
            Mn::Nop => "[N]",
            _ => "",
        }
    }
}

/// Every mnemonic, for suggestions.
pub const MNEMONICS: &[&str] = &[
    "LD", "LDN", "A", "AN", "O", "ON", "NOT", "=", "S", "R", "EU", "ED", "ALD", "OLD", "LPS", "LRD", "LPP", "LDS",
    "LDW=", "LDW<>", "LDW<", "LDW>", "LDW<=", "LDW>=", "AW=", "OW=", "LDD=", "LDR=", "+I", "-I", "*I", "/I", "+D",
    "-D", "*D", "/D", "+R", "-R", "*R", "/R", "INCW", "DECW", "INCD", "DECD", "INCB", "DECB", "MOVB", "MOVW", "MOVD",
    "MOVR", "TON", "TONR", "TOF", "CTU", "CTD", "CTUD", "FOR", "NEXT", "JMP", "LBL", "NOP",
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mnemonics_parse_case_insensitively() {
        assert_eq!(Mn::parse("ldn"), Some(Mn::Load { neg: true }));
        assert_eq!(Mn::parse("=i"), Some(Mn::Out));
        assert_eq!(Mn::parse("TOFF"), Some(Mn::Timer(TimerKind::Tof)));
        assert_eq!(
            Mn::parse("ldw<="),
            Some(Mn::Cmp {
                how: How::Load,
                ty: Ty::W,
                op: Cmp::Le
            })
        );
        assert_eq!(
            Mn::parse("OR>"),
            Some(Mn::Cmp {
                how: How::Or,
                ty: Ty::R,
                op: Cmp::Gt
            })
        );
        assert_eq!(
            Mn::parse("AD=="),
            Some(Mn::Cmp {
                how: How::And,
                ty: Ty::D,
                op: Cmp::Eq
            })
        );
        assert_eq!(
            Mn::parse("/I"),
            Some(Mn::Math {
                op: BinOp::Div,
                ty: Ty::W
            })
        );
        assert_eq!(Mn::parse("decd"), Some(Mn::Inc { ty: Ty::D, down: true }));
        for bad in ["NAND", "LDX=", "+X", "MOVQ", "LDW=<", ""] {
            assert_eq!(Mn::parse(bad), None, "{bad}");
        }
        for m in MNEMONICS {
            assert!(Mn::parse(m).is_some(), "{m}");
        }
    }
}
