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
    /// The PID loop structure (SPEC §6, see [`PID_MEMBERS`]).
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

/// PID: REAL slots SP … DFN, DINT slots UPD ERRC FORM, BOOL slots EN … OL
/// (and hidden state after the members of each class, see `alba_ir::Pidt`).
/// Status bits are set by the instruction; the SLC 500's SP/PV/DB status
/// bits are `SPOR`, `PVOR` and `INDB` here because `SP`, `PV` and `DB` name
/// the setpoint, the process variable and the deadband.
pub const PID_MEMBERS: &[Member] = &[
    m("SP", DataType::Real, true, 0),
    m("PV", DataType::Real, false, 1),
    m("ERR", DataType::Real, false, 2),
    m("CV", DataType::Real, true, 3),
    m("KP", DataType::Real, true, 4),
    m("KI", DataType::Real, true, 5),
    m("KD", DataType::Real, true, 6),
    m("KC", DataType::Real, true, 7),
    m("TI", DataType::Real, true, 8),
    m("TD", DataType::Real, true, 9),
    m("BIAS", DataType::Real, true, 10),
    m("MAXO", DataType::Real, true, 11),
    m("MINO", DataType::Real, true, 12),
    m("MAXS", DataType::Real, true, 13),
    m("MINS", DataType::Real, true, 14),
    m("MAXI", DataType::Real, true, 15),
    m("MINI", DataType::Real, true, 16),
    m("MAXCV", DataType::Real, true, 17),
    m("MINCV", DataType::Real, true, 18),
    m("DB", DataType::Real, true, 19),
    m("DFN", DataType::Real, true, 20),
    m("UPD", DataType::Dint, true, 0),
    m("ERRC", DataType::Dint, false, 1),
    m("FORM", DataType::Dint, true, 2),
    m("EN", DataType::Bool, false, 0),
    m("DN", DataType::Bool, false, 1),
    m("UL", DataType::Bool, false, 2),
    m("LL", DataType::Bool, false, 3),
    m("SPOR", DataType::Bool, false, 4),
    m("PVOR", DataType::Bool, false, 5),
    m("INDB", DataType::Bool, false, 6),
    m("TF", DataType::Bool, false, 7),
    m("MAN", DataType::Bool, true, 8),
    m("DIRECT", DataType::Bool, true, 9),
    m("DOE", DataType::Bool, true, 10),
    m("DEP", DataType::Bool, true, 11),
    m("OL", DataType::Bool, true, 12),
    m("TM", DataType::Bool, true, 13),
    m("MINUTES", DataType::Bool, true, 14),
];

/// Default values of PID members that are not zero (a new loop limits its
/// output to 0-100 %, filters its derivative with N = 10 and updates every
/// 100 ms in timed mode).
pub const PID_DEFAULTS: &[(&str, f64)] = &[("MAXO", 100.0), ("DFN", 10.0), ("UPD", 100.0), ("OL", 1.0), ("TM", 1.0)];

/// The parameters of a PID loop that can be wrong, for the checks done
/// when a project is checked (constant initial values) and by the
/// instruction at run time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PidParams {
    pub kp: f64,
    pub ki: f64,
    pub kd: f64,
    pub kc: f64,
    pub ti: f64,
    pub td: f64,
    pub maxs: f64,
    pub mins: f64,
    pub db: f64,
    pub maxo: f64,
    pub mino: f64,
    pub dfn: f64,
    pub maxi: f64,
    pub mini: f64,
    pub maxcv: f64,
    pub mincv: f64,
    pub bias: f64,
    pub upd: f64,
    pub form: f64,
}

/// Error codes of a PID loop (`ERRC`): the SLC 500's where it has one.
pub mod pid_error {
    /// Loop update time not more than 0.
    pub const UPD: i32 = 0x11;
    /// Proportional gain (KP, or KC with DEP) below 0.
    pub const GAIN: i32 = 0x12;
    /// Integral gain or time below 0.
    pub const INTEGRAL: i32 = 0x13;
    /// Derivative gain or time below 0.
    pub const DERIVATIVE: i32 = 0x14;
    /// MINS above MAXS.
    pub const SCALE: i32 = 0x23;
    /// Deadband below 0 or above MAXS-MINS.
    pub const DEADBAND: i32 = 0x41;
    /// MAXO below 0 or above 100 %.
    pub const UPPER_LIMIT: i32 = 0x51;
    /// MINO below 0 or above 100 %, or above MAXO.
    pub const LIMITS: i32 = 0x52;
    /// A parameter is NaN or infinite (Alba's own code).
    pub const NAN: i32 = 0x70;
    /// DFN below 0 (Alba's own code).
    pub const FILTER: i32 = 0x71;
    /// FORM not 0 to 4, 11 or 12 (Alba's own code).
    pub const FORM: i32 = 0x72;
}

/// The FORM bit that selects the `004_…` programs' own arithmetic for the
/// 16-bit velocity forms (FORM 3, 4 + 8 = 11, 12): the module's 0-32767
/// scale, only a negative u(k) corrected (to 0), u(k−1) not limited to
/// MINO..MAXO (§3.3.1.1, Annex F).
pub const PID_FORM_LISTING: i32 = 8;

impl PidParams {
    /// The algorithm without the listing bit: 0 to 4 when valid.
    pub fn base_form(&self) -> f64 {
        if self.form >= 9.0 {
            self.form - f64::from(PID_FORM_LISTING)
        } else {
            self.form
        }
    }

    /// Whether the listing bit is set (FORM 11, 12).
    pub fn listing(&self) -> bool {
        self.form >= 9.0
    }
}

impl PidParams {
    /// The first problem, as (ERRC code, member, message), or `None`.
    pub fn check(&self) -> Option<(i32, &'static str, String)> {
        use pid_error as E;
        let all = [
            ("KP", self.kp),
            ("KI", self.ki),
            ("KD", self.kd),
            ("KC", self.kc),
            ("TI", self.ti),
            ("TD", self.td),
            ("MAXS", self.maxs),
            ("MINS", self.mins),
            ("DB", self.db),
            ("MAXO", self.maxo),
            ("MINO", self.mino),
            ("DFN", self.dfn),
            ("MAXI", self.maxi),
            ("MINI", self.mini),
            ("MAXCV", self.maxcv),
            ("MINCV", self.mincv),
            ("BIAS", self.bias),
        ];
        if let Some((n, v)) = all.iter().find(|(_, v)| !v.is_finite()) {
            return Some((E::NAN, n, format!("PID parameter {n} is {v}, not a number")));
        }
        if self.upd <= 0.0 {
            return Some((
                E::UPD,
                "UPD",
                format!(
                    "PID parameter UPD = {}: the loop update time must be more than 0 ms (SLC error 11H)",
                    self.upd
                ),
            ));
        }
        for (n, v, code, what) in [
            ("KP", self.kp, E::GAIN, "a gain"),
            ("KC", self.kc, E::GAIN, "a gain"),
            ("KI", self.ki, E::INTEGRAL, "an integral gain"),
            ("TI", self.ti, E::INTEGRAL, "an integral time"),
            ("KD", self.kd, E::DERIVATIVE, "a derivative gain"),
            ("TD", self.td, E::DERIVATIVE, "a derivative time"),
        ] {
            if v < 0.0 {
                let slc = format!("{code:X}H");
                return Some((
                    code,
                    n,
                    format!("PID parameter {n} = {v}: {what} cannot be negative (SLC error {slc})"),
                ));
            }
        }
        if self.mins > self.maxs {
            return Some((
                E::SCALE,
                "MINS",
                format!(
                    "PID parameter MINS = {} is more than MAXS = {} (SLC error 23H)",
                    self.mins, self.maxs
                ),
            ));
        }
        let span = self.maxs - self.mins;
        if self.db < 0.0 || (span > 0.0 && self.db > span) {
            return Some((
                E::DEADBAND,
                "DB",
                format!(
                    "PID parameter DB = {}: the deadband must be from 0 to MAXS-MINS = {span} (SLC error 41H)",
                    self.db
                ),
            ));
        }
        // The SLC's output limits are % of CV (`004_…` §3.3.2, codes 51H, 52H).
        if !(0.0..=100.0).contains(&self.maxo) {
            return Some((
                E::UPPER_LIMIT,
                "MAXO",
                format!(
                    "PID parameter MAXO = {}: the output's upper limit must be from 0 to 100 % (SLC error 51H)",
                    self.maxo
                ),
            ));
        }
        if !(0.0..=100.0).contains(&self.mino) {
            return Some((
                E::LIMITS,
                "MINO",
                format!(
                    "PID parameter MINO = {}: the output's lower limit must be from 0 to 100 % (SLC error 52H)",
                    self.mino
                ),
            ));
        }
        if self.mino > self.maxo {
            return Some((
                E::LIMITS,
                "MINO",
                format!(
                    "PID parameter MINO = {} is more than MAXO = {} (SLC error 52H)",
                    self.mino, self.maxo
                ),
            ));
        }
        if self.dfn < 0.0 {
            return Some((
                E::FILTER,
                "DFN",
                format!(
                    "PID parameter DFN = {}: the derivative filter factor cannot be negative",
                    self.dfn
                ),
            ));
        }
        if self.base_form() == 3.0 && self.upd < 10.0 {
            return Some((
                E::FORM,
                "UPD",
                format!(
                    "PID parameter UPD = {} with FORM 3 (or 11): the 16-bit s-plane form counts T in hundredths of a second, so UPD must be 10 ms or more",
                    self.upd
                ),
            ));
        }
        let valid = (0.0..=4.0).contains(&self.form) || (11.0..=12.0).contains(&self.form);
        if !valid || self.form.fract() != 0.0 {
            return Some((
                E::FORM,
                "FORM",
                format!(
                    "PID parameter FORM = {}: the algorithm is 0 (positional), 1 or 2 (velocity, s- or z-plane) or 3 or 4 (the same with 16-bit SLC arithmetic), or 11 or 12 (3 or 4 as the 004 programs PID_CONT and PID_DISC run them)",
                    self.form
                ),
            ));
        }
        None
    }
}

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
            DataType::Pid => PID_MEMBERS,
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
