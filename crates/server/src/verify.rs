//! The project's proofs and test tables as the API shows them
//! (`POST /api/verify`, `POST /api/tests`; docs/api.md "Verify and test",
//! docs/verify.md "In the studio").
//!
//! This crate does not know `alba-verify`: alba-app implements [`Verifier`]
//! over it on the saved project and sets it in `AppState::verifier` before
//! serving. Unset: both routes answer 404. Both calls take seconds of CPU:
//! the handlers run them one at a time per project (the permit the net
//! analysis uses, `429` while one runs), on their own thread at the lowest
//! priority, each property within [`PROPERTY_SECONDS`].

use crate::reply::{Diagnostic, TestsReply, VerifyReply};

/// Wall-clock seconds one property may take.
pub const PROPERTY_SECONDS: u64 = 60;

/// Why a request failed.
#[derive(Debug, Clone)]
pub enum VerifyError {
    /// The project, properties.toml or a table does not check (`422` with the diagnostics).
    DoesNotCheck(Vec<Diagnostic>),
    /// Nothing to run: no properties.toml, no tests folder, no such property (`404`).
    NotFound(String),
    /// The machine failed (`500`).
    Failed(String),
}

/// The proofs and tests of `alba run`'s project, as saved.
pub trait Verifier: Send + Sync {
    /// Decides the properties of properties.toml (only `only` if given),
    /// each within `seconds`, replaying every counterexample and witness.
    fn verify(&self, only: Option<&str>, seconds: u64) -> Result<VerifyReply, VerifyError>;
    /// Runs every `tests/*.test.csv`, with coverage.
    fn tests(&self) -> Result<TestsReply, VerifyError>;
}
