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
    /// Where the samples go: the embedded SQLite file (default) or a shared
    /// PostgreSQL database.
    pub backend: HistoryBackend,
    /// PostgreSQL: `postgres://user@host:port/db` (or `host=… user=…`),
    /// without the password.
    pub url: Option<String>,
    /// PostgreSQL: a file holding the password (never in alba.toml, never
    /// echoed).
    pub password_file: Option<String>,
    /// PostgreSQL: this runtime's node id in the shared tables; default the
    /// project's name.
    pub node: Option<String>,
    /// PostgreSQL: the local buffer (`.alba/history-buffer.db`) holds at most
    /// this many samples while the database is unreachable; beyond it the
    /// oldest are dropped and counted.
    pub buffer_max_samples: u32,
    /// PostgreSQL over TLS: the CA certificates (PEM, relative to the
    /// project) the server's certificate must chain to.
    pub ca_file: Option<String>,
    /// PostgreSQL over TLS: a client certificate and its key (PEM), both or
    /// neither.
    pub client_cert: Option<String>,
    pub client_key: Option<String>,
}

/// Where `alba run` records (`[history] backend`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HistoryBackend {
    /// `.alba/history.db` in the project.
    #[default]
    Sqlite,
    /// A shared PostgreSQL (TimescaleDB when installed) database.
    Postgres,
}

/// The default `[history] buffer_max_samples`.
pub const DEFAULT_BUFFER_MAX_SAMPLES: u32 = 10_000_000;

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
            backend: HistoryBackend::Sqlite,
            url: None,
            password_file: None,
            node: None,
            buffer_max_samples: DEFAULT_BUFFER_MAX_SAMPLES,
            ca_file: None,
            client_cert: None,
            client_key: None,
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
    backend: Option<Spanned<HistoryBackend>>,
    url: Option<Spanned<String>>,
    password_file: Option<String>,
    node: Option<Spanned<String>>,
    buffer_max_samples: Option<Spanned<i64>>,
    ca_file: Option<String>,
    client_cert: Option<Spanned<String>>,
    client_key: Option<Spanned<String>>,
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
    history.buffer_max_samples = int(
        "buffer_max_samples",
        h.buffer_max_samples,
        1..=u32::MAX,
        history.buffer_max_samples,
        "samples",
    );
    history.password_file = h.password_file;
    history.ca_file = h.ca_file;
    match (h.client_cert, h.client_key) {
        (Some(c), Some(k)) => {
            if history.ca_file.is_none() {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    "client_cert without ca_file",
                    sp(c.span()),
                    "a client certificate is for TLS: add ca_file = \"…\" (the CA of the database's certificate)",
                ));
            }
            history.client_cert = Some(c.into_inner());
            history.client_key = Some(k.into_inner());
        }
        (Some(one), None) | (None, Some(one)) => diags.push(Diagnostic::new(
            Code::ConfigField,
            "client_cert and client_key go together",
            sp(one.span()),
            "give both the certificate and its key, or neither",
        )),
        (None, None) => {}
    }
    if let Some(node) = h.node {
        if node.get_ref().trim().is_empty() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "node is empty",
                sp(node.span()),
                "expected this runtime's id in the shared historian",
            ));
        } else {
            history.node = Some(node.into_inner());
        }
    }
    if let Some(url) = h.url {
        // The message never quotes the URL: it may hold a password.
        if url_has_password(url.get_ref()) {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "url holds a password",
                sp(url.span()),
                "put the password in the file `password_file` names, not in alba.toml",
            ));
        }
        history.url = Some(url.into_inner());
    }
    if let Some(b) = h.backend {
        history.backend = *b.get_ref();
        if history.backend == HistoryBackend::Postgres && history.url.is_none() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "backend = \"postgres\" needs a url",
                sp(b.span()),
                "add url = \"postgres://user@host:5432/db\" to [history]",
            ));
        }
    }
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

/// A `postgres://user:password@…` URL or a `password=…` key.
fn url_has_password(url: &str) -> bool {
    if url.contains("password=") {
        return true;
    }
    let rest = url
        .strip_prefix("postgres://")
        .or_else(|| url.strip_prefix("postgresql://"));
    rest.and_then(|r| r.split('/').next())
        .and_then(|authority| authority.rsplit_once('@'))
        .is_some_and(|(user, _)| user.contains(':'))
}
