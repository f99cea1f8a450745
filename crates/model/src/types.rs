//! Data types of tags (SPEC §2.1) and the members of structures.

use std::fmt;

/// The type of a tag or of a structure member.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataType {
    Bool,
    /// 8-bit signed.
    Sint,
    /// 16-bit signed.
    Int,
    /// 32-bit signed.
    Dint,
    /// 64-bit signed.
    Lint,
    /// 32-bit IEEE float.
    Real,
    /// 64-bit IEEE float.
    Lreal,
    /// Duration in milliseconds, 32-bit signed.
    Time,
    Timer,
    Counter,
    /// Reserved for the PID instruction.
    Pid,
}

/// Members of a structure type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Member {
    pub name: &'static str,
    pub ty: DataType,
    /// Programs, the API and stimuli may write it (PRE and ACC); status bits
    /// are set by the instruction only.
    pub writable: bool,
    /// Position within the structure's slots of that member's storage class
    /// (integers and booleans are counted separately).
    pub index: u8,
}

const fn m(name: &'static str, ty: DataType, writable: bool, index: u8) -> Member {
    Member {
        name,
        ty,
        writable,
        index,
    }
}

/// TIMER: integer slots PRE ACC (and a hidden start time), bool slots EN TT DN.
pub const TIMER_MEMBERS: &[Member] = &[
    m("PRE", DataType::Dint, true, 0),
    m("ACC", DataType::Dint, true, 1),
    m("EN", DataType::Bool, false, 0),
    m("TT", DataType::Bool, false, 1),
    m("DN", DataType::Bool, false, 2),
];

/// COUNTER: integer slots PRE ACC, bool slots CU CD DN OV UN.
pub const COUNTER_MEMBERS: &[Member] = &[
    m("PRE", DataType::Dint, true, 0),
    m("ACC", DataType::Dint, true, 1),
    m("CU", DataType::Bool, false, 0),
    m("CD", DataType::Bool, false, 1),
    m("DN", DataType::Bool, false, 2),
    m("OV", DataType::Bool, false, 3),
    m("UN", DataType::Bool, false, 4),
];

impl DataType {
    pub const ALL: &'static [DataType] = &[
        DataType::Bool,
        DataType::Sint,
        DataType::Int,
        DataType::Dint,
        DataType::Lint,
        DataType::Real,
        DataType::Lreal,
        DataType::Time,
        DataType::Timer,
        DataType::Counter,
        DataType::Pid,
    ];

    pub fn name(self) -> &'static str {
        match self {
            DataType::Bool => "BOOL",
            DataType::Sint => "SINT",
            DataType::Int => "INT",
            DataType::Dint => "DINT",
            DataType::Lint => "LINT",
            DataType::Real => "REAL",
            DataType::Lreal => "LREAL",
            DataType::Time => "TIME",
            DataType::Timer => "TIMER",
            DataType::Counter => "COUNTER",
            DataType::Pid => "PID",
        }
    }

    /// "a BOOL", "an INT": the name with its article.
    pub fn with_article(self) -> String {
        let n = self.name();
        let article = if n.starts_with(['A', 'E', 'I', 'O', 'U']) {
            "an"
        } else {
            "a"
        };
        format!("{article} {n}")
    }

    /// Parses a type name, case-insensitively.
    pub fn parse(s: &str) -> Option<DataType> {
        DataType::ALL
            .iter()
            .copied()
            .find(|t| t.name().eq_ignore_ascii_case(s.trim()))
    }

    pub fn is_struct(self) -> bool {
        matches!(self, DataType::Timer | DataType::Counter | DataType::Pid)
    }

    pub fn is_integer(self) -> bool {
        matches!(
            self,
            DataType::Sint | DataType::Int | DataType::Dint | DataType::Lint | DataType::Time
        )
    }

    pub fn is_real(self) -> bool {
        matches!(self, DataType::Real | DataType::Lreal)
    }

    pub fn is_numeric(self) -> bool {
        self.is_integer() || self.is_real()
    }

    /// Members of a structure (empty for elementary types).
    pub fn members(self) -> &'static [Member] {
        match self {
            DataType::Timer => TIMER_MEMBERS,
            DataType::Counter => COUNTER_MEMBERS,
            _ => &[],
        }
    }

    pub fn member(self, name: &str) -> Option<&'static Member> {
        self.members().iter().find(|m| m.name.eq_ignore_ascii_case(name))
    }

    /// Inclusive range of an integer type.
    pub fn int_range(self) -> Option<(i64, i64)> {
        match self {
            DataType::Sint => Some((i8::MIN as i64, i8::MAX as i64)),
            DataType::Int => Some((i16::MIN as i64, i16::MAX as i64)),
            DataType::Dint | DataType::Time => Some((i32::MIN as i64, i32::MAX as i64)),
            DataType::Lint => Some((i64::MIN, i64::MAX)),
            _ => None,
        }
    }
}

impl fmt::Display for DataType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_is_case_insensitive_and_total_over_names() {
        for t in DataType::ALL {
            assert_eq!(DataType::parse(&t.name().to_lowercase()), Some(*t));
        }
        assert_eq!(DataType::parse("WORD"), None);
    }

    #[test]
    fn members_resolve_case_insensitively() {
        assert_eq!(DataType::Timer.member("dn").map(|m| m.index), Some(2));
        assert_eq!(DataType::Counter.member("UN").map(|m| m.ty), Some(DataType::Bool));
        assert!(DataType::Timer.member("CU").is_none());
        assert!(DataType::Dint.members().is_empty());
    }
}
