//! Minor faults (SPEC §2.4): what a program did wrong, where, and when.
//! They never stop the engine; the program keeps running with the defined
//! result the interpreter chose.

use std::fmt;

/// Codes of minor faults, as stored in `S:FAULTCODE`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(i32)]
pub enum FaultCode {
    /// Integer overflow (the result wrapped), or a float out of the target range.
    Overflow = 1,
    /// Division or modulo by zero (the result saturated, or 0 for 0/0 and MOD).
    DivZero = 2,
    /// A floating-point result was not a number (it became 0).
    Nan = 3,
    /// A value outside the domain of a conversion (BCD).
    Range = 4,
    /// A timer preset below zero (the timer used 0).
    NegativePreset = 5,
    /// A PID loop parameter is invalid (the loop's ERRC says which; the
    /// output holds).
    PidParameter = 6,
}

impl FaultCode {
    pub fn from_i32(code: i32) -> Option<FaultCode> {
        [
            FaultCode::Overflow,
            FaultCode::DivZero,
            FaultCode::Nan,
            FaultCode::Range,
            FaultCode::NegativePreset,
            FaultCode::PidParameter,
        ]
        .into_iter()
        .find(|c| *c as i32 == code)
    }

    pub fn describe(self) -> &'static str {
        match self {
            FaultCode::Overflow => "arithmetic overflow",
            FaultCode::DivZero => "division by zero",
            FaultCode::Nan => "invalid floating-point result (NaN)",
            FaultCode::Range => "value out of range for the conversion",
            FaultCode::NegativePreset => "negative timer preset",
            FaultCode::PidParameter => "invalid PID parameter (see the loop's ERRC)",
        }
    }
}

impl fmt::Display for FaultCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.describe())
    }
}

/// One recorded fault: what, at which op (see `Program::locs`), in which scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fault {
    pub code: FaultCode,
    pub pc: u32,
    pub scan: u64,
}

/// Faults since the last start: a count, the first and the last.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Faults {
    pub count: u64,
    pub first: Option<Fault>,
    pub last: Option<Fault>,
    pub(crate) scan: u64,
}

impl Faults {
    #[cold]
    pub(crate) fn record(&mut self, code: FaultCode, pc: u32) {
        let f = Fault {
            code,
            pc,
            scan: self.scan,
        };
        self.count += 1;
        self.first.get_or_insert(f);
        self.last = Some(f);
    }

    /// Adds `n` faults of which only the first and the last are known.
    #[cold]
    pub(crate) fn absorb(&mut self, n: u64, first: (FaultCode, u32), last: (FaultCode, u32)) {
        if n == 0 {
            return;
        }
        self.record(first.0, first.1);
        if n > 1 {
            self.count += n - 2;
            self.record(last.0, last.1);
        }
    }
}
