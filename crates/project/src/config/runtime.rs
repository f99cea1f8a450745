//! `[runtime]`: how `alba run` treats its own data (docs/reliability.md).

use serde::Deserialize;

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
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawRuntime {
    on_retain_error: Option<OnRetainError>,
}

pub(super) fn runtime(r: RawRuntime) -> Runtime {
    Runtime {
        on_retain_error: r.on_retain_error.unwrap_or_default(),
    }
}
