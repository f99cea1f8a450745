//! The alarm log: every change of state, with time, user and comment, in
//! SQLite (`.alba/alarms.db`), durable on `kill -9` and power loss (WAL,
//! `synchronous = FULL`, as the audit trail), no event limit, a retention in
//! days, CSV export row by row.

use crate::state::{Event, Persisted};
use rusqlite::{Connection, OpenFlags, params};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

/// `PRAGMA application_id` of an alarm log: "AlbL".
const APPLICATION_ID: i64 = 0x416C_624C;
const SCHEMA_VERSION: i64 = 2;
/// Version 2: the `states` table (each alarm's state, kept across restarts).
const STATES: &str = "
CREATE TABLE states(
    alarm TEXT PRIMARY KEY,
    state TEXT NOT NULL,
    since INTEGER NOT NULL,
    active INTEGER NOT NULL,
    value REAL,
    acked_user TEXT,
    acked_comment TEXT,
    acked_t INTEGER,
    shelved_until INTEGER,
    shelved_user TEXT,
    shelved_reason TEXT,
    oos_user TEXT,
    oos_reason TEXT
);
";
const SCHEMA: &str = "
CREATE TABLE events(
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    t INTEGER NOT NULL,
    alarm TEXT NOT NULL,
    tag TEXT NOT NULL,
    from_state TEXT NOT NULL,
    to_state TEXT NOT NULL,
    value REAL,
    severity INTEGER NOT NULL,
    user_name TEXT,
    comment TEXT,
    message TEXT NOT NULL
);
CREATE INDEX events_t ON events(t);
";

/// Appends `fields` as one CSV line (RFC 4180, the audit export's formula guard).
fn csv_line(line: &mut String, fields: &[String], end: &str) {
    for (k, f) in fields.iter().enumerate() {
        if k > 0 {
            line.push(',');
        }
        alba_audit::push_field(line, f);
    }
    line.push_str(end);
}

/// The changes of state of a simulation (`alba sim --alarms`) as CSV:
/// `time_ms,alarm,tag,from,to,value,severity,message`.
pub fn write_events_csv<W: Write>(events: &[Event], mut w: W) -> std::io::Result<()> {
    w.write_all(b"time_ms,alarm,tag,from,to,value,severity,message\n")?;
    let mut line = String::new();
    for e in events {
        line.clear();
        let fields = [
            e.t_ms.to_string(),
            e.id.clone(),
            e.tag.clone(),
            e.from.name().to_string(),
            e.to.name().to_string(),
            crate::state::format_value(e.value),
            e.severity.to_string(),
            e.message.clone(),
        ];
        csv_line(&mut line, &fields, "\n");
        w.write_all(line.as_bytes())?;
    }
    Ok(())
}

/// The header of the CSV export.
pub const CSV_HEADER: &str = "id,time_ms,time_utc,alarm,tag,from,to,value,severity,user,comment,message\r\n";

#[derive(Debug, thiserror::Error)]
pub enum LogError {
    #[error("alarm log {path}: {reason}")]
    NotALog { path: PathBuf, reason: String },
    #[error("alarm log: {0}")]
    Sql(#[from] rusqlite::Error),
    #[error("alarm log: {0}")]
    Io(#[from] std::io::Error),
}

impl LogError {
    /// The file is damaged or not an alarm log: what is moved aside for a
    /// fresh log (issue 31), as opposed to a full disk or a missing folder.
    pub fn is_damage(&self) -> bool {
        match self {
            LogError::NotALog { .. } => true,
            LogError::Sql(e) => matches!(
                e.sqlite_error_code(),
                Some(rusqlite::ErrorCode::DatabaseCorrupt | rusqlite::ErrorCode::NotADatabase)
            ),
            LogError::Io(_) => false,
        }
    }
}

/// An open alarm log; clones share it.
#[derive(Clone)]
pub struct Log {
    path: PathBuf,
    conn: Arc<Mutex<Connection>>,
    retention_days: Option<u32>,
    /// Damage found while in use and what was done about it (the file was
    /// moved aside for a fresh one), for the status to show.
    damaged: Arc<Mutex<Option<String>>>,
}

impl std::fmt::Debug for Log {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Log").field("path", &self.path).finish_non_exhaustive()
    }
}

/// The alarm log of the project in `dir`.
pub fn project_path(dir: &Path) -> PathBuf {
    dir.join(".alba").join("alarms.db")
}

/// A connection to the log at `path` (created if new); a file of another
/// kind, damaged (checked page by page: `quick_check`) or of a newer schema
/// is refused.
fn connect(path: &Path) -> Result<Connection, LogError> {
    let not = |reason: String| LogError::NotALog {
        path: path.to_path_buf(),
        reason,
    };
    let conn = Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_CREATE | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(|e| not(e.to_string()))?;
    conn.busy_timeout(Duration::from_secs(10))?;
    let mode: String = conn
        .query_row("PRAGMA journal_mode = WAL", [], |r| r.get(0))
        .map_err(|e| not(format!("not an SQLite database, or damaged ({e})")))?;
    if !mode.eq_ignore_ascii_case("wal") {
        return Err(not(format!("SQLite did not take the WAL journal (`{mode}`)")));
    }
    conn.execute_batch("PRAGMA synchronous = FULL;")?;
    let refused = |r: alba_sqlite::Refusal| match r {
        alba_sqlite::Refusal::Sqlite(e) => LogError::from(e),
        alba_sqlite::Refusal::Not(reason) => not(reason),
    };
    let kind = alba_sqlite::Kind {
        application_id: APPLICATION_ID,
        version: SCHEMA_VERSION,
        create: &format!("{SCHEMA} {STATES}"),
    };
    if alba_sqlite::identify(&conn, &kind).map_err(refused)? == alba_sqlite::Found::Version(1) {
        alba_sqlite::migrate(&conn, STATES, SCHEMA_VERSION)?;
    }
    alba_sqlite::quick_check(&conn).map_err(refused)?;
    Ok(conn)
}

/// [`Log::append`] on `conn`.
fn append_on(conn: &mut Connection, events: &[Event], states: &[Persisted]) -> Result<(), LogError> {
    let tx = conn.transaction()?;
    {
        let mut stmt = tx.prepare_cached(
            "INSERT INTO events(t, alarm, tag, from_state, to_state, value, severity, user_name, comment, message)
                 VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
        )?;
        for e in events {
            stmt.execute(params![
                e.t_ms,
                e.id,
                e.tag,
                e.from.name(),
                e.to.name(),
                e.value.is_finite().then_some(e.value),
                e.severity,
                e.user,
                e.comment,
                e.message,
            ])?;
        }
        let mut stmt = tx.prepare_cached(
            "INSERT OR REPLACE INTO states(alarm, state, since, active, value, acked_user, acked_comment,
                 acked_t, shelved_until, shelved_user, shelved_reason, oos_user, oos_reason)
                 VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13)",
        )?;
        for p in states {
            let (acked_user, acked_comment, acked_t) = match &p.acked {
                Some((u, c, t)) => (Some(u), Some(c), Some(t)),
                None => (None, None, None),
            };
            let (until, shelved_user, shelved_reason) = match &p.shelved {
                Some((t, u, r)) => (Some(t), Some(u), Some(r)),
                None => (None, None, None),
            };
            let (oos_user, oos_reason) = match &p.out_of_service {
                Some((u, r)) => (Some(u), Some(r)),
                None => (None, None),
            };
            stmt.execute(params![
                p.id,
                p.state.name(),
                p.since_ms,
                p.active,
                p.value.is_finite().then_some(p.value),
                acked_user,
                acked_comment,
                acked_t,
                until,
                shelved_user,
                shelved_reason,
                oos_user,
                oos_reason,
            ])?;
        }
    }
    tx.commit()?;
    Ok(())
}

/// [`Log::load_states`] on `conn`.
fn load_states_on(conn: &Connection) -> Result<Vec<Persisted>, LogError> {
    let mut stmt = conn.prepare(
        "SELECT alarm, state, since, active, value, acked_user, acked_comment, acked_t,
                    shelved_until, shelved_user, shelved_reason, oos_user, oos_reason FROM states",
    )?;
    let mut rows = stmt.query([])?;
    let mut out = Vec::new();
    while let Some(r) = rows.next()? {
        let state: String = r.get(1)?;
        let Ok(state) = state.parse() else { continue };
        let text = |i: usize| -> rusqlite::Result<String> { Ok(r.get::<_, Option<String>>(i)?.unwrap_or_default()) };
        out.push(Persisted {
            id: r.get(0)?,
            state,
            since_ms: r.get(2)?,
            active: r.get(3)?,
            value: r.get::<_, Option<f64>>(4)?.unwrap_or(f64::NAN),
            acked: match r.get::<_, Option<i64>>(7)? {
                Some(t) => Some((text(5)?, text(6)?, t)),
                None => None,
            },
            shelved: match r.get::<_, Option<i64>>(8)? {
                Some(t) => Some((t, text(9)?, text(10)?)),
                None => None,
            },
            out_of_service: match r.get::<_, Option<String>>(11)? {
                Some(u) => Some((u, text(12)?)),
                None => None,
            },
        });
    }
    Ok(out)
}

/// [`Log::export_csv`] on `conn`.
fn events_on(conn: &Connection, from_ms: i64, to_ms: i64, limit: u64) -> Result<Vec<Event>, LogError> {
    let mut stmt = conn.prepare_cached(
        "SELECT t, alarm, tag, from_state, to_state, value, severity, user_name, comment, message
             FROM events WHERE t >= ?1 AND t <= ?2 ORDER BY id LIMIT ?3",
    )?;
    let mut rows = stmt.query(params![from_ms, to_ms, i64::try_from(limit).unwrap_or(i64::MAX)])?;
    let mut out = Vec::new();
    while let Some(r) = rows.next()? {
        let state = |i: usize| -> rusqlite::Result<crate::state::State> {
            let s: String = r.get(i)?;
            s.parse().map_err(|e: String| {
                rusqlite::Error::FromSqlConversionFailure(i, rusqlite::types::Type::Text, e.into())
            })
        };
        out.push(Event {
            t_ms: r.get(0)?,
            id: r.get(1)?,
            tag: r.get(2)?,
            from: state(3)?,
            to: state(4)?,
            value: r.get::<_, Option<f64>>(5)?.unwrap_or(f64::NAN),
            severity: u16::try_from(r.get::<_, i64>(6)?).unwrap_or(u16::MAX),
            user: r.get(7)?,
            comment: r.get(8)?,
            message: r.get(9)?,
        });
    }
    Ok(out)
}

fn export_on<W: Write>(
    conn: &Connection,
    from_ms: Option<i64>,
    to_ms: Option<i64>,
    limit: u64,
    writer: W,
) -> Result<u64, LogError> {
    let mut stmt = conn.prepare_cached(
        "SELECT id, t, alarm, tag, from_state, to_state, value, severity, user_name, comment, message
             FROM events WHERE t >= ?1 AND t <= ?2 ORDER BY id LIMIT ?3",
    )?;
    let mut rows = stmt.query(params![
        from_ms.unwrap_or(i64::MIN),
        to_ms.unwrap_or(i64::MAX),
        i64::try_from(limit).unwrap_or(i64::MAX)
    ])?;
    let mut out = std::io::BufWriter::new(writer);
    out.write_all(CSV_HEADER.as_bytes())?;
    let mut n = 0;
    let mut line = String::new();
    while let Some(r) = rows.next()? {
        line.clear();
        let t: i64 = r.get(1)?;
        let value: Option<f64> = r.get(6)?;
        let severity: i64 = r.get(7)?;
        let text = |i: usize| -> rusqlite::Result<String> { Ok(r.get::<_, Option<String>>(i)?.unwrap_or_default()) };
        let fields = [
            r.get::<_, i64>(0)?.to_string(),
            t.to_string(),
            alba_audit::format_utc(t),
            text(2)?,
            text(3)?,
            text(4)?,
            text(5)?,
            value.map(crate::state::format_value).unwrap_or_default(),
            severity.to_string(),
            text(8)?,
            text(9)?,
            text(10)?,
        ];
        csv_line(&mut line, &fields, "\r\n");
        out.write_all(line.as_bytes())?;
        n += 1;
    }
    out.flush()?;
    Ok(n)
}

impl Log {
    /// Opens (creating) the log at `path`; a file of another kind, corrupt or
    /// of a newer schema is refused. `retention_days` 0 keeps everything.
    pub fn open(path: &Path, retention_days: u32) -> Result<Log, LogError> {
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        Ok(Log {
            path: path.to_path_buf(),
            conn: Arc::new(Mutex::new(connect(path)?)),
            retention_days: (retention_days > 0).then_some(retention_days),
            damaged: Arc::new(Mutex::new(None)),
        })
    }

    /// Damage found while the log was in use (torn pages read by an
    /// acknowledgement, an export…), once the file was moved aside for a
    /// fresh one: what happened, for the status. `None` while healthy.
    pub fn damage(&self) -> Option<String> {
        self.damaged.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }

    /// `r`, after moving the file aside for a fresh log if `r` says it is
    /// damaged (`conn` is the locked connection, replaced in place: every
    /// clone of the log writes the fresh file from then on).
    fn checked<T>(&self, conn: &mut Connection, r: Result<T, LogError>) -> Result<T, LogError> {
        if let Err(e) = &r
            && e.is_damage()
        {
            // Close the old file first: SQLite deletes its `-wal` by name on close.
            *conn = Connection::open_in_memory()?;
            let what = match alba_sqlite::move_aside(&self.path)
                .map_err(LogError::from)
                .and_then(|to| {
                    connect(&self.path).map(|fresh| {
                        *conn = fresh;
                        to
                    })
                }) {
                Ok(to) => format!("{e}: moved to {} and a fresh alarm log started", to.display()),
                Err(m) => format!("{e}; and no fresh log could take its place: {m}"),
            };
            *self.damaged.lock().unwrap_or_else(PoisonError::into_inner) = Some(what);
        }
        r
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Appends `events` and keeps `states` (the alarms they changed) in one
    /// transaction; returns once they are durable.
    /// A damaged file (torn pages…) is moved aside for a fresh log and the
    /// write made there ([`Log::damage`] says so).
    pub fn append(&self, events: &[Event], states: &[Persisted]) -> Result<(), LogError> {
        if events.is_empty() && states.is_empty() {
            return Ok(());
        }
        let mut conn = self.conn.lock().unwrap_or_else(PoisonError::into_inner);
        let r = append_on(&mut conn, events, states);
        match self.checked(&mut conn, r) {
            Err(e) if e.is_damage() => append_on(&mut conn, events, states),
            r => r,
        }
    }
    /// The states kept by [`Log::append`], for [`crate::Alarms::restore`]; a
    /// row that does not read back (an unknown state name) is skipped.
    pub fn load_states(&self) -> Result<Vec<Persisted>, LogError> {
        let mut conn = self.conn.lock().unwrap_or_else(PoisonError::into_inner);
        let r = load_states_on(&conn);
        self.checked(&mut conn, r)
    }
    /// Writes the events with `from_ms <= t <= to_ms`, oldest first, at most
    /// `limit`, as CSV (RFC 4180; a field a spreadsheet would run as a formula
    /// gets a leading `'`, as in the audit export). Returns the rows written.
    pub fn export_csv<W: Write>(
        &self,
        from_ms: Option<i64>,
        to_ms: Option<i64>,
        limit: u64,
        writer: W,
    ) -> Result<u64, LogError> {
        let mut conn = self.conn.lock().unwrap_or_else(PoisonError::into_inner);
        let r = export_on(&conn, from_ms, to_ms, limit, writer);
        // Damage found while reading: the export is cut, the file moved aside and said so.
        self.checked(&mut conn, r)
    }
    /// The events with `from_ms <= t <= to_ms`, oldest first, at most `limit`
    /// (the shift report's KPIs, [`crate::kpi`]).
    pub fn events(&self, from_ms: i64, to_ms: i64, limit: u64) -> Result<Vec<Event>, LogError> {
        let mut conn = self.conn.lock().unwrap_or_else(PoisonError::into_inner);
        let r = events_on(&conn, from_ms, to_ms, limit);
        self.checked(&mut conn, r)
    }

    /// Deletes events older than the retention (call at start and daily).
    pub fn apply_retention(&self, now_ms: i64) -> Result<u64, LogError> {
        let Some(days) = self.retention_days else {
            return Ok(0);
        };
        let cutoff = now_ms.saturating_sub(i64::from(days) * 86_400_000);
        let conn = self.conn.lock().unwrap_or_else(PoisonError::into_inner);
        Ok(conn.execute("DELETE FROM events WHERE t < ?1", [cutoff])? as u64)
    }

    /// Events logged (for tests and the status).
    pub fn count(&self) -> Result<u64, LogError> {
        let conn = self.conn.lock().unwrap_or_else(PoisonError::into_inner);
        Ok(conn.query_row("SELECT count(*) FROM events", [], |r| r.get::<_, i64>(0))? as u64)
    }
}
