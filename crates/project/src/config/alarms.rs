//! `[alarms]`: how long the alarm log keeps its events.

use super::setting::int_setting;
use alba_diag::{Diagnostic, FileId};
use serde::Deserialize;
use toml::Spanned;

/// `[alarms]`: the alarm log (docs/alarms.md); alarms themselves are in
/// alarms.csv.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Alarms {
    /// Events older than this many days are deleted (at start and daily); 0 keeps
    /// everything.
    pub retention_days: u32,
}

impl Default for Alarms {
    fn default() -> Alarms {
        Alarms { retention_days: 365 }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawAlarms {
    retention_days: Option<Spanned<i64>>,
}

/// Validates `[alarms]`: the defaults, with what the table sets.
pub(super) fn alarms(a: RawAlarms, file: FileId, diags: &mut Vec<Diagnostic>) -> Alarms {
    let default = Alarms::default();
    Alarms {
        retention_days: int_setting(
            "retention_days",
            a.retention_days,
            0..=36_500,
            default.retention_days,
            "days",
            file,
            diags,
        ),
    }
}
