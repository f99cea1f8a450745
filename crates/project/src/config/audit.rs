//! `[audit]`: how long the audit trail of `alba run` keeps its rows.

use super::setting::int_setting;
use alba_diag::{Diagnostic, FileId};
use serde::Deserialize;
use toml::Spanned;

/// `[audit]`: the audit trail (docs/audit.md). It is always on: only its
/// retention is a setting.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Audit {
    /// Rows older than this many days are deleted (at start and daily); 0 keeps
    /// everything.
    pub retention_days: u32,
}

impl Default for Audit {
    fn default() -> Audit {
        Audit { retention_days: 365 }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawAudit {
    retention_days: Option<Spanned<i64>>,
}

/// Validates `[audit]`: the defaults, with what the table sets.
pub(super) fn audit(a: RawAudit, file: FileId, diags: &mut Vec<Diagnostic>) -> Audit {
    let default = Audit::default();
    Audit {
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
