//! `[runtime]`: how `alba run` treats its own data (docs/reliability.md).

use super::setting::int_setting;
use alba_diag::{Diagnostic, FileId};
use serde::Deserialize;
use toml::Spanned;

/// What `alba run` does when the retain file cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OnRetainError {
    /// Start from the previous save or the initial values, keep the bad file
    /// aside and report it (`S:RETAINLOST`, `/api/status`).
    #[default]
    Start,
    /// Refuse to start until someone fixes or removes the file.
    Refuse,
}

/// `[runtime]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Runtime {
    pub on_retain_error: OnRetainError,
    /// SCHED_FIFO priority of the engine thread, 1 to 99; 0: normal.
    pub priority: u8,
    /// The CPU the engine thread runs on.
    pub cpu: Option<u32>,
    /// Lock the process's memory in RAM (`mlockall`).
    pub lock_memory: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawRuntime {
    on_retain_error: Option<OnRetainError>,
    priority: Option<Spanned<i64>>,
    cpu: Option<Spanned<i64>>,
    lock_memory: Option<bool>,
}

pub(super) fn runtime(r: RawRuntime, file: FileId, diags: &mut Vec<Diagnostic>) -> Runtime {
    Runtime {
        on_retain_error: r.on_retain_error.unwrap_or_default(),
        priority: int_setting("priority", r.priority, 0..=99, 0, "(0: normal scheduling)", file, diags) as u8,
        cpu: r
            .cpu
            .map(|c| int_setting("cpu", Some(c), 0..=1023, 0, "(a CPU number)", file, diags)),
        lock_memory: r.lock_memory.unwrap_or(false),
    }
}
