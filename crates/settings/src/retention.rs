//! `[audit]` and `[alarms]`: how long the audit trail (docs/audit.md) and the
//! alarm log (docs/alarms.md) of `alba run` keep their rows. Both are always
//! on: only their retention is a setting.

use super::setting::int_setting;
use alba_diag::{Diagnostic, FileId};
use serde::Deserialize;
use toml::Spanned;

/// A log's retention.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Retention {
    /// Rows older than this many days are deleted (at start and daily); 0 keeps
    /// everything.
    pub retention_days: u32,
}

/// `[audit]`.
pub type Audit = Retention;
/// `[alarms]` (the alarms themselves are in alarms.csv).
pub type Alarms = Retention;

impl Default for Retention {
    fn default() -> Retention {
        Retention { retention_days: 365 }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawRetention {
    retention_days: Option<Spanned<i64>>,
}

/// Validates `[audit]` or `[alarms]`: the defaults, with what the table sets.
pub(super) fn retention(a: RawRetention, file: FileId, diags: &mut Vec<Diagnostic>) -> Retention {
    let default = Retention::default();
    Retention {
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
