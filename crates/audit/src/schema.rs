//! The database layout, the connection settings (durability) and the checks that refuse
//! files that are not audit logs.
//!
//! Durability: the log uses the WAL journal with `synchronous = FULL`. In WAL mode a
//! commit appends the transaction to the `-wal` file; with `FULL` SQLite fsyncs that
//! file before the commit returns, so a row whose `INSERT` returned survives both a
//! `kill -9` of the process and a power loss (with `NORMAL`, the default of the
//! historian, it survives `kill -9` but the last commits may be lost on power loss).
//! The rollback journal (`DELETE`) with `FULL` is as durable but needs two or three
//! fsyncs per commit (journal, database, directory) and makes readers and the writer
//! wait for each other; in WAL a commit is one fsync and a query or a long CSV export
//! never holds up the writer.

use std::path::Path;
use std::time::Duration;

use rusqlite::{Connection, ErrorCode, OpenFlags};

use crate::error::{Error, Result};

/// `PRAGMA application_id` of an audit log: "AlbA".
pub(crate) const APPLICATION_ID: i64 = 0x416C_6241;
/// `PRAGMA user_version`: the schema version this code writes and reads.
pub(crate) const SCHEMA_VERSION: i64 = 2;

const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

/// The columns, in the order every `SELECT` of rows uses (see `row_from`).
pub(crate) const COLUMNS: &str =
    "id, t, user_name, addr, action, target, old_value, new_value, detail, outcome, error, via";

/// `AUTOINCREMENT`: ids are never reused, even after retention deleted the newest rows,
/// so an id names one row forever and orders rows as they were appended. The trigger
/// makes rows append-only in the file itself: the one change allowed is setting the
/// outcome of a `pending` row.
const SCHEMA: &str = "
CREATE TABLE audit(
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    t INTEGER NOT NULL,
    user_name TEXT,
    addr TEXT,
    action TEXT NOT NULL,
    target TEXT,
    old_value TEXT,
    new_value TEXT,
    detail TEXT,
    outcome TEXT NOT NULL CHECK (outcome IN ('pending', 'ok', 'failed')),
    error TEXT,
    via TEXT
);
CREATE INDEX audit_t ON audit(t);
";

/// Rows append-only (version 2: `via` too).
const TRIGGER: &str = "
CREATE TRIGGER audit_append_only BEFORE UPDATE ON audit
WHEN OLD.outcome <> 'pending'
  OR NEW.id IS NOT OLD.id OR NEW.t IS NOT OLD.t OR NEW.user_name IS NOT OLD.user_name
  OR NEW.addr IS NOT OLD.addr OR NEW.action IS NOT OLD.action OR NEW.target IS NOT OLD.target
  OR NEW.old_value IS NOT OLD.old_value OR NEW.new_value IS NOT OLD.new_value
  OR NEW.detail IS NOT OLD.detail OR NEW.via IS NOT OLD.via
BEGIN
    SELECT RAISE(ABORT, 'audit rows are append-only: only the outcome of a pending row may be set');
END;
";

/// Version 1 to 2: the door a row's action came through (`via`: `http`,
/// `mqtt`, `opcua`, `modbus`); rows of version 1 keep it empty.
const MIGRATE_1_2: &str = "
ALTER TABLE audit ADD COLUMN via TEXT;
DROP TRIGGER audit_append_only;
";

fn open_error(path: &Path, e: rusqlite::Error) -> Error {
    match e.sqlite_error_code() {
        Some(ErrorCode::NotADatabase) => Error::NotAudit {
            path: path.to_path_buf(),
            reason: "the file is not an SQLite database (or its header is damaged)".into(),
        },
        Some(ErrorCode::DatabaseCorrupt) => Error::NotAudit {
            path: path.to_path_buf(),
            reason: format!("the database is corrupt ({e})"),
        },
        _ => Error::Open {
            path: path.to_path_buf(),
            source: e,
        },
    }
}

/// Opens (creating it if needed) the writing connection: WAL, `synchronous = FULL`,
/// schema created on an empty file, identity and version checked otherwise.
pub(crate) fn open_writer(path: &Path) -> Result<Connection> {
    let conn = Connection::open(path).map_err(|e| open_error(path, e))?;
    let mode = setup(&conn, true).map_err(|e| open_error(path, e))?;
    if !mode.eq_ignore_ascii_case("wal") {
        return Err(Error::NotAudit {
            path: path.to_path_buf(),
            reason: format!("SQLite did not take the WAL journal (it answered `{mode}`)"),
        });
    }
    let refused = |r: alba_sqlite::Refusal| match r {
        alba_sqlite::Refusal::Sqlite(e) => open_error(path, e),
        alba_sqlite::Refusal::Not(reason) => Error::NotAudit {
            path: path.to_path_buf(),
            reason,
        },
    };
    let kind = alba_sqlite::Kind {
        application_id: APPLICATION_ID,
        version: SCHEMA_VERSION,
        create: &format!("{SCHEMA} {TRIGGER}"),
    };
    match alba_sqlite::identify(&conn, &kind).map_err(refused)? {
        alba_sqlite::Found::Created => return Ok(conn),
        alba_sqlite::Found::Version(1) => {
            alba_sqlite::migrate(&conn, &format!("{MIGRATE_1_2} {TRIGGER}"), SCHEMA_VERSION)
                .map_err(|e| open_error(path, e))?;
        }
        alba_sqlite::Found::Version(_) => {}
    }
    // Torn or truncated pages show only when read: the whole file is checked
    // once here, so damage is found at start, not by the first action that
    // needs its row.
    alba_sqlite::quick_check(&conn).map_err(refused)?;
    conn.prepare(&format!("SELECT {COLUMNS} FROM audit LIMIT 0"))
        .map_err(|e| match open_error(path, e) {
            Error::Open { source, .. } => Error::NotAudit {
                path: path.to_path_buf(),
                reason: format!("table `audit` is missing or damaged ({source})"),
            },
            other => other,
        })?;
    Ok(conn)
}

/// Opens a reading connection on a log the writer has opened (and so set to WAL).
pub(crate) fn open_reader(path: &Path) -> Result<Connection> {
    let flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX | OpenFlags::SQLITE_OPEN_URI;
    let conn = Connection::open_with_flags(path, flags).map_err(|e| open_error(path, e))?;
    setup(&conn, false).map_err(|e| open_error(path, e))?;
    conn.execute_batch("PRAGMA query_only = ON;")?;
    Ok(conn)
}

/// Connection settings; the journal mode the file has (the writer sets WAL).
fn setup(conn: &Connection, writer: bool) -> rusqlite::Result<String> {
    conn.busy_timeout(BUSY_TIMEOUT)?;
    conn.set_prepared_statement_cache_capacity(16);
    // Answers with a row; persistent in the file once set.
    let sql = if writer {
        "PRAGMA journal_mode = WAL"
    } else {
        "PRAGMA journal_mode"
    };
    let mode: String = conn.query_row(sql, [], |r| r.get(0))?;
    conn.execute_batch("PRAGMA synchronous = FULL; PRAGMA temp_store = MEMORY;")?;
    Ok(mode)
}
