//! Why a replay or a test run gave no result.

/// Why a stimulus ([`crate::trace::trace`]) or a counterexample
/// ([`crate::explore::replay`]) does not replay.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReplayError {
    #[error("a replay runs at most {max} scans, not {scans}")]
    TooLong { scans: u32, max: u32 },
    /// The stimulus does not parse: where, and why.
    #[error("{0}")]
    Stimulus(String),
    #[error("the program does not load: {0}")]
    Program(alba_engine::EngineError),
    #[error("a replay in the studio sets values only; this stimulus forces")]
    Forces,
    #[error("the replay stops at {t_ms} ms with a major fault: {message}")]
    FaultAt { t_ms: u64, message: String },
    #[error("the replay stops with a major fault: {0}")]
    Fault(String),
    #[error("internal error: the counterexample does not parse: {0}")]
    Counterexample(String),
    #[error("the counterexample does not replay: an assumption fails on the way")]
    Assumption,
    #[error(
        "the counterexample found does not replay into the violation through the simulator (plant models overwrite its inputs?)"
    )]
    NoViolation,
}

/// Why a project's test tables cannot be run ([`crate::table::run_dir`]).
#[derive(Debug, thiserror::Error)]
pub enum TestsError {
    #[error("cannot read {}: {source}", path.display())]
    Unreadable {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("{} holds no *.test.csv table", .0.display())]
    NoTables(std::path::PathBuf),
}
