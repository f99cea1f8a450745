//! The error type of the historian.

use std::path::PathBuf;

/// Everything that can go wrong opening, writing or reading a history database.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file could not be opened or created (missing directory, permissions, …).
    #[error("{}: cannot open history database: {source}", path.display())]
    Open {
        /// The database file.
        path: PathBuf,
        /// What SQLite reported.
        #[source]
        source: rusqlite::Error,
    },
    /// The file exists but is not a history database this program can use: not SQLite,
    /// corrupt, another application's SQLite database or a newer schema version.
    #[error("{}: not a usable history database: {reason}", path.display())]
    NotHistory {
        /// The database file.
        path: PathBuf,
        /// Why it was refused.
        reason: String,
    },
    /// A query named a tag that has never been recorded.
    #[error("unknown tag `{0}`")]
    UnknownTag(String),
    /// A query named a node that the store does not hold (the SQLite store holds only
    /// this runtime's samples).
    #[error("unknown node `{0}`")]
    UnknownNode(String),
    /// An argument is out of range: `points` of 0, a time outside ±2^53 ms, an empty tag
    /// name, a CSV step of 0 ms or an export of too many rows.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// An SQLite error while reading or writing an open database.
    #[error("history database error: {0}")]
    Sqlite(#[from] rusqlite::Error),
    /// A PostgreSQL error (connection refused or lost, a statement refused, …). Never
    /// holds the connection's password.
    #[error("postgres historian: {}", pg_message(.0))]
    Postgres(#[from] postgres::Error),
    /// Writing an export failed.
    #[error("export write error: {0}")]
    Io(#[from] std::io::Error),
}

impl Error {
    /// The database is damaged or is not a history database: it cannot be used any more
    /// and is to be moved aside ([`crate::move_aside`]).
    pub fn is_damage(&self) -> bool {
        match self {
            Error::NotHistory { .. } => true,
            Error::Sqlite(e) => matches!(
                e.sqlite_error_code(),
                Some(rusqlite::ErrorCode::DatabaseCorrupt | rusqlite::ErrorCode::NotADatabase)
            ),
            _ => false,
        }
    }

    /// The disk (or the file's size limit) is full.
    pub fn is_disk_full(&self) -> bool {
        matches!(self, Error::Sqlite(e) if e.sqlite_error_code() == Some(rusqlite::ErrorCode::DiskFull))
    }
}

/// What PostgreSQL said: the server's message and SQLSTATE, or the client's error and its
/// causes (a refused or lost connection, a timeout, …).
pub(crate) fn pg_message(e: &postgres::Error) -> String {
    if let Some(db) = e.as_db_error() {
        return format!("{}: {} (SQLSTATE {})", db.severity(), db.message(), db.code().code());
    }
    let mut out = e.to_string();
    let mut source = std::error::Error::source(e);
    while let Some(s) = source {
        out.push_str(": ");
        out.push_str(&s.to_string());
        source = s.source();
    }
    out
}

/// The result type of the historian.
pub type Result<T, E = Error> = std::result::Result<T, E>;
