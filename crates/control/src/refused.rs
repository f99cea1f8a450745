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
}
