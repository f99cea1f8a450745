//! The error type of the audit log.

use std::path::PathBuf;

/// Everything that can go wrong opening, writing or reading an audit log.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file could not be opened or created (missing directory, permissions, …).
    #[error("{}: cannot open the audit log: {source}", path.display())]
    Open {
        /// The database file.
        path: PathBuf,
        /// What SQLite reported.
        #[source]
        source: rusqlite::Error,
    },
    /// The project's `.alba` folder could not be created.
    #[error("cannot create {}: {source}", path.display())]
    CreateDir {
        /// The folder.
        path: PathBuf,
        /// What the system reported.
        #[source]
        source: std::io::Error,
    },
    /// The file exists but is not an audit log this program can use: not SQLite,
    /// corrupt, another application's database or a newer schema version.
    #[error("{}: not a usable audit log: {reason}", path.display())]
    NotAudit {
        /// The database file.
        path: PathBuf,
        /// Why it was refused.
        reason: String,
    },
    /// An argument is out of range: a time outside ±2^53 ms, a limit of 0, an unknown
    /// action name, a row id that is not pending.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// An SQLite error while reading or writing an open log (disk full, I/O error, …).
    #[error("audit log error: {0}")]
    Sqlite(#[from] rusqlite::Error),
    /// Writing an export failed.
    #[error("export write error: {0}")]
    Io(#[from] std::io::Error),
}

impl Error {
    /// The file is damaged or not an audit log (as opposed to one that
    /// cannot be opened at all, or a full disk): what can be moved aside for
    /// a fresh log.
    pub fn is_damage(&self) -> bool {
        match self {
            Error::NotAudit { .. } => true,
            Error::Sqlite(e) | Error::Open { source: e, .. } => matches!(
                e.sqlite_error_code(),
                Some(rusqlite::ErrorCode::DatabaseCorrupt | rusqlite::ErrorCode::NotADatabase)
            ),
            _ => false,
        }
    }
}

/// The result type of the audit log.
pub type Result<T, E = Error> = std::result::Result<T, E>;
