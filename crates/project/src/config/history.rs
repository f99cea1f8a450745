//! `[history]`: what the historian of `alba run` keeps.

use super::setting::int_setting;
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

/// `[history]`: what the historian of `alba run` keeps (docs/historian.md).
#[derive(Debug, Clone, PartialEq)]
pub struct History {
    /// Record at all.
    pub enabled: bool,
    /// Samples older than this are deleted; 0 keeps everything.
    pub retention_days: u32,
    /// A value is also stored this often when it does not change.
    pub sample_ms: u32,
    /// A REAL is stored on change only when it moved more than this.
    pub deadband: f64,
    /// The database is kept under this size, oldest samples deleted first;
    /// 0: no cap.
    pub max_mb: u32,
    /// Recording pauses while the disk holding the database has less free
    /// space than this (retain and project saves go on: they are small).
    pub min_free_mb: u32,
    /// What to do with a damaged or foreign history database at start.
    pub on_damage: OnDamage,
}

/// What `alba run` does with a history database it cannot use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OnDamage {
    /// Move it aside (`history.db.damaged-<ms>`) and record into a fresh one.
    #[default]
    Fresh,
    /// Refuse to start.
    Refuse,
}

impl Default for History {
    fn default() -> History {
        History {
            enabled: true,
            retention_days: 30,
            sample_ms: 10_000,
            deadband: 0.0,
            max_mb: 2048,
            min_free_mb: 256,
            on_damage: OnDamage::Fresh,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawHistory {
    enabled: Option<bool>,
    retention_days: Option<Spanned<i64>>,
    sample_ms: Option<Spanned<i64>>,
    deadband: Option<Spanned<f64>>,
    max_mb: Option<Spanned<i64>>,
    min_free_mb: Option<Spanned<i64>>,
    on_damage: Option<OnDamage>,
}

/// Validates `[history]`: the defaults, with what the table sets.
pub(super) fn history(h: RawHistory, file: FileId, diags: &mut Vec<Diagnostic>) -> History {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let mut int =
        |key: &str, v: Option<Spanned<i64>>, range: std::ops::RangeInclusive<u32>, default: u32, unit: &str| {
            int_setting(key, v, range, default, unit, file, diags)
        };
    let mut history = History::default();
    history.enabled = h.enabled.unwrap_or(true);
    history.retention_days = int(
        "retention_days",
        h.retention_days,
        0..=36_500,
        history.retention_days,
        "days",
    );
    history.sample_ms = int(
        "sample_ms",
        h.sample_ms,
        10..=86_400_000,
        history.sample_ms,
        "milliseconds",
    );
    history.max_mb = int("max_mb", h.max_mb, 0..=16_777_216, history.max_mb, "MB");
    history.min_free_mb = int("min_free_mb", h.min_free_mb, 0..=16_777_216, history.min_free_mb, "MB");
    history.on_damage = h.on_damage.unwrap_or_default();
    if let Some(d) = h.deadband {
        if d.get_ref().is_finite() && *d.get_ref() >= 0.0 {
            history.deadband = *d.get_ref();
        } else {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("deadband = {} is out of range", d.get_ref()),
                sp(d.span()),
                "expected a number ≥ 0",
            ));
        }
    }
    history
}
