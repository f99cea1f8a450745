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

use crate::reply::Diagnostic;
use serde::Serialize;
use ts_rs::TS;

/// Wall-clock seconds one property may take.
pub const PROPERTY_SECONDS: u64 = 60;
/// How long `POST /api/verify` and `POST /api/tests` may take (the
/// request timeout when it is longer).
pub const VERIFY_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(600);

/// One row of a counterexample or witness stimulus (`time_ms,tag,value`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct StimulusRow {
    pub time_ms: u64,
    pub tag: String,
    pub value: String,
}

/// One scan of a replay.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct ReplayScan {
    pub time_ms: u64,
    /// Parallel to [`Replay::tags`].
    pub values: Vec<String>,
    /// Program elements (the power-flow ids of `/api/ws`) energised at the end of the scan.
    pub on: Vec<u32>,
}

/// A counterexample (or witness) replayed through the engine as `alba sim` replays it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct Replay {
    /// The stimulus file's rows.
    pub rows: Vec<StimulusRow>,
    /// The scan (0-based) where the property fails (a witness: holds).
    pub violating_scan: u32,
    pub tags: Vec<String>,
    pub scans: Vec<ReplayScan>,
}

/// `POST /api/verify`: one property's answer.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct PropertyResult {
    pub name: String,
    /// `proved`, `refuted` or `unknown`.
    pub result: String,
    /// Scans of the counterexample or witness, else the depth searched.
    pub depth: u32,
    pub states: u64,
    pub millis: u64,
    /// Why `unknown`.
    pub reason: Option<String>,
    /// A refuted property's counterexample.
    pub counterexample: Option<Replay>,
    /// A `reachable` property's witness.
    pub witness: Option<Replay>,
}

/// `POST /api/verify`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct VerifyReply {
    pub scan_ms: u32,
    pub properties: Vec<PropertyResult>,
}

/// `POST /api/tests`: one table's result.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct TestCaseResult {
    pub name: String,
    /// `tests/<name>.test.csv`.
    pub file: String,
    /// `passed`, `failed` or `error`.
    pub result: String,
    /// Cells checked (passed tables).
    pub checks: u64,
    /// The first wrong cell (failed) or the error, in words.
    pub message: Option<String>,
    /// The failing cell's line in the table.
    pub line: Option<u64>,
    pub scans: u64,
    pub millis: u64,
}

/// Coverage of one program by all the tables together.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct ProgramCoverage {
    pub program: String,
    /// Its elements (power-flow ids), and those that ever carried power.
    pub elements: Vec<u32>,
    pub powered: Vec<u32>,
    /// Elements that always had power (never switched off).
    pub always: Vec<u32>,
}

/// `POST /api/tests`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, TS)]
pub struct TestsReply {
    pub tests: Vec<TestCaseResult>,
    pub passed: u64,
    pub failed: u64,
    pub rungs: u64,
    pub rungs_powered: u64,
    pub branches: u64,
    pub branches_powered: u64,
    pub instructions: u64,
    pub switched: u64,
    /// Rungs never powered and instructions never switched, as `alba test` prints them.
    pub rungs_never: Vec<String>,
    pub never_switched: Vec<String>,
    pub coverage: Vec<ProgramCoverage>,
}

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

/// The declarations of this file's replies for web/src/api.gen.ts.
pub fn typescript(cfg: &ts_rs::Config) -> String {
    let mut out = String::new();
    macro_rules! decl {
        ($($t:ty),* $(,)?) => {
            $(
                out.push_str("\nexport ");
                out.push_str(&<$t as TS>::decl(cfg));
                out.push('\n');
            )*
        };
    }
    decl!(
        StimulusRow,
        ReplayScan,
        Replay,
        PropertyResult,
        VerifyReply,
        TestCaseResult,
        ProgramCoverage,
        TestsReply
    );
    out
}
