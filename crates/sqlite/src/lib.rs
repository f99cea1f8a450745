//! Alba's SQLite files — the audit trail (`.alba/audit.db`), the history
//! (`history.db`) and the alarm log (`alarms.db`) — are each known by
//! `PRAGMA application_id` and versioned by `PRAGMA user_version`. Opening
//! one is the same steps for all three, done here once:
//!
//! 1. [`identify`]: an empty file is created with its schema (one
//!    transaction: the tables, the application id, the version); a file of
//!    another application or of a newer schema is refused with the reason; an
//!    older version is migrated by the caller's steps.
//! 2. [`quick_check`]: torn or truncated pages show only when read, so the
//!    whole file is checked once at open (a few ms per MB).
//! 3. [`move_aside`]: a file refused as damaged is renamed with its `-wal`
//!    and `-shm` to `<name>.damaged-<unix ms>` (kept to be examined) so that
//!    a fresh one can take its place.
//!
//! Each store maps a [`Refusal`] into its own error (`NotAudit`,
//! `NotHistory`, the alarm log's `NotLog`).

use rusqlite::Connection;
use std::path::{Path, PathBuf};

/// What a store's file must be.
pub struct Kind<'a> {
    /// `PRAGMA application_id` of the store.
    pub application_id: i64,
    /// The schema version this program writes.
    pub version: i64,
    /// The SQL that creates the schema of `version` on an empty file (run in
    /// the creating transaction, before the identity is set).
    pub create: &'a str,
}

/// Why a file is not opened as the store.
#[derive(Debug)]
pub enum Refusal {
    /// SQLite failed (I/O, locked, not a database): the error.
    Sqlite(rusqlite::Error),
    /// The file is not this store, is of a newer schema, or is damaged: why.
    Not(String),
}

impl From<rusqlite::Error> for Refusal {
    fn from(e: rusqlite::Error) -> Refusal {
        Refusal::Sqlite(e)
    }
}

/// What [`identify`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Found {
    /// The file was empty: the schema of `kind.version` was created.
    Created,
    /// The store, at this version (at most `kind.version`; the caller
    /// migrates an older one).
    Version(i64),
}

/// Knows the file on `conn` by its identity: creates the store on an empty
/// file, refuses another application's file or a newer schema.
pub fn identify(conn: &Connection, kind: &Kind<'_>) -> Result<Found, Refusal> {
    let get = |sql: &str| -> Result<i64, rusqlite::Error> { conn.query_row(sql, [], |r| r.get(0)) };
    let app_id = get("PRAGMA application_id")?;
    let version = get("PRAGMA user_version")?;
    let objects = get("SELECT count(*) FROM sqlite_master")?;
    if app_id == 0 && version == 0 && objects == 0 {
        conn.execute_batch(&format!(
            "BEGIN IMMEDIATE; {} PRAGMA application_id = {}; PRAGMA user_version = {}; COMMIT;",
            kind.create, kind.application_id, kind.version
        ))?;
        return Ok(Found::Created);
    }
    if app_id != kind.application_id {
        return Err(Refusal::Not(format!(
            "an SQLite database of another application (application_id {app_id:#x})"
        )));
    }
    if version > kind.version {
        return Err(Refusal::Not(format!(
            "schema version {version} is newer than this program supports ({})",
            kind.version
        )));
    }
    Ok(Found::Version(version))
}

/// Runs `sql` (a migration step) and sets the schema version to `to`, in one
/// transaction.
pub fn migrate(conn: &Connection, sql: &str, to: i64) -> Result<(), rusqlite::Error> {
    conn.execute_batch(&format!("BEGIN IMMEDIATE; {sql} PRAGMA user_version = {to}; COMMIT;"))
}

/// Reads the whole file once (`PRAGMA quick_check`): damage is found at
/// open, not by the first write that needs the damaged page.
pub fn quick_check(conn: &Connection) -> Result<(), Refusal> {
    let check: String = conn.query_row("PRAGMA quick_check(1)", [], |r| r.get(0))?;
    if check == "ok" {
        Ok(())
    } else {
        Err(Refusal::Not(format!("the database is damaged ({check})")))
    }
}

/// Moves the database `path` and its `-wal` and `-shm` files aside to
/// `<name>.damaged-<unix ms>` (and its `-wal`, `-shm`), so that a fresh
/// database can take its place and the old one can still be examined.
/// Returns the new path of the database.
pub fn move_aside(path: &Path) -> std::io::Result<PathBuf> {
    let ms = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis());
    let with = |p: &Path, suffix: &str| {
        let mut name = p.file_name().map(|n| n.to_os_string()).unwrap_or_default();
        name.push(suffix);
        p.with_file_name(name)
    };
    let to = with(path, &format!(".damaged-{ms}"));
    std::fs::rename(path, &to)?;
    for side in ["-wal", "-shm"] {
        match std::fs::rename(with(path, side), with(&to, side)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    Ok(to)
}

#[cfg(test)]
mod tests {
    use super::*;

    const KIND: Kind<'static> = Kind {
        application_id: 0x1234,
        version: 2,
        create: "CREATE TABLE t(x);",
    };

    fn conn(dir: &Path) -> Connection {
        Connection::open(dir.join("x.db")).expect("open")
    }

    #[test]
    fn an_empty_file_is_created_then_known() {
        let dir = tempfile::tempdir().expect("dir");
        assert_eq!(identify(&conn(dir.path()), &KIND).expect("create"), Found::Created);
        let c = conn(dir.path());
        assert_eq!(identify(&c, &KIND).expect("known"), Found::Version(2));
        c.execute_batch("INSERT INTO t VALUES (1)")
            .expect("the schema was created");
        quick_check(&c).expect("sound");
    }

    #[test]
    fn another_application_or_a_newer_schema_is_refused() {
        let dir = tempfile::tempdir().expect("dir");
        let c = conn(dir.path());
        c.execute_batch("CREATE TABLE u(y); PRAGMA application_id = 7;")
            .expect("foreign");
        match identify(&c, &KIND) {
            Err(Refusal::Not(m)) => assert!(m.contains("another application (application_id 0x7)"), "{m}"),
            other => panic!("{other:?}"),
        }
        c.execute_batch("PRAGMA application_id = 4660; PRAGMA user_version = 3;")
            .expect("newer");
        match identify(&c, &KIND) {
            Err(Refusal::Not(m)) => assert!(m.contains("schema version 3 is newer"), "{m}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_older_version_is_found_and_migrated() {
        let dir = tempfile::tempdir().expect("dir");
        let c = conn(dir.path());
        c.execute_batch("CREATE TABLE t(x); PRAGMA application_id = 4660; PRAGMA user_version = 1;")
            .expect("v1");
        assert_eq!(identify(&c, &KIND).expect("v1"), Found::Version(1));
        migrate(&c, "ALTER TABLE t ADD COLUMN y;", 2).expect("migrate");
        assert_eq!(identify(&c, &KIND).expect("v2"), Found::Version(2));
    }

    #[test]
    fn a_file_moved_aside_takes_its_journal_files_along() {
        let dir = tempfile::tempdir().expect("dir");
        let db = dir.path().join("x.db");
        std::fs::write(&db, b"garbage").expect("db");
        std::fs::write(dir.path().join("x.db-wal"), b"w").expect("wal");
        let to = move_aside(&db).expect("aside");
        assert!(!db.exists() && to.exists());
        assert!(to.to_string_lossy().contains("x.db.damaged-"));
        let mut wal = to.into_os_string();
        wal.push("-wal");
        assert!(PathBuf::from(wal).exists());
        assert!(!dir.path().join("x.db-wal").exists());
    }
}
