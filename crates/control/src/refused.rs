//! Why an action was not done: one error for every door, mapped once by each.

use alba_auth::Role;

/// Why `Control` did not act. Each door maps it once: HTTP
/// (`alba-server`'s `ApiError`), OPC UA (a status code), Modbus (an
/// exception code), MQTT (the `<prefix>/error` message).
#[derive(Debug, thiserror::Error)]
pub enum Refused {
    /// No such tag.
    #[error("{0}")]
    UnknownTag(String),
    /// An input, a read-only tag or member, a structure.
    #[error("{0}")]
    NotWritable(String),
    /// A value of another kind than the tag's type takes.
    #[error("{0}")]
    WrongType(String),
    /// A value of the right kind that the tag cannot hold.
    #[error("{0}")]
    OutOfRange(String),
    /// A tag that cannot be forced (a structure, internal memory: only I/O is forced).
    #[error("{0}")]
    NotForceable(String),
    /// Removing the force of a tag that is not forced.
    #[error("{0}")]
    NotForced(String),
    /// No such alarm (or the project has none).
    #[error("{0}")]
    UnknownAlarm(String),
    /// The alarm refused the action (already acknowledged, not shelved…)
    /// or its alarm-log row could not be written.
    #[error(transparent)]
    Alarm(alba_alarms::HubError),
    /// The actor's role is too small.
    #[error("user {actor} is a {role}: {what} needs the {needed} role (users.toml)")]
    Role {
        actor: String,
        role: Role,
        needed: Role,
        what: &'static str,
    },
    /// The audit row could not be written: the action was not performed
    /// (docs/audit.md, "No acknowledged action without its row").
    #[error("not done: the audit trail cannot be written ({0})")]
    AuditUnavailable(alba_audit::Error),
    /// The runtime refused or could not apply it (stopped, busy, faulted).
    #[error(transparent)]
    Runtime(#[from] alba_runtime::Error),
    /// An online edit saved whose program the runtime did not take.
    #[error("saved, but not applied: {0}")]
    NotApplied(alba_runtime::Error),
    /// A fault of the layer itself (a task that did not finish).
    #[error("{0}")]
    Internal(String),
}

/// A refusal of one of several writes done together
/// ([`crate::Control::write_rows`]): which one (0-based; `None` when the
/// refusal concerns them all: the audit trail, the runtime) and why.
#[derive(Debug, thiserror::Error)]
#[error("{refused}")]
pub struct RowRefused {
    pub row: Option<usize>,
    pub refused: Refused,
}

impl From<Refused> for RowRefused {
    fn from(refused: Refused) -> RowRefused {
        RowRefused { row: None, refused }
    }
}
