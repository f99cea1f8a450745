//! The Alba audit trail: an append-only log of who changed what.
//!
//! One SQLite file (`<project>/.alba/audit.db`, WAL journal with `synchronous = FULL`:
//! a row whose write returned survives `kill -9` and power loss, see `schema.rs`) holds
//! one row per action: when (Unix ms, passed in by the caller), who (user name, or none
//! when no users are configured, and the client's address), what ([`Action`], with a
//! stable name), on what (a tag, program, user…), the old and new values (JSON text) and
//! a detail (a program diff summary). Rows are never changed, except that a row written
//! *before* its action ([`Audit::begin`], outcome `pending`) gets the action's outcome
//! once ([`Audit::finish`]); a trigger in the file refuses every other update. Rows are
//! deleted only by retention ([`Audit::apply_retention`]).
//!
//! "No acknowledged action without its row": a caller that performs an action writes the
//! row first with [`Audit::begin`] and refuses the action if that fails, then performs
//! it and records the outcome with [`Audit::finish`]. A row left `pending` means the
//! process ended between the two (the action may or may not have taken effect).
//!
//! [`Audit`] is cheap to clone and `Send + Sync`; every call blocks on SQLite (a commit
//! waits for an fsync), so async code calls it from `spawn_blocking`. See docs/audit.md.

mod action;
mod csv;
mod diff;
mod error;
mod journal;
mod schema;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use rusqlite::types::Value;
use rusqlite::{Connection, OptionalExtension, params, params_from_iter};

pub use action::Action;
pub use csv::{CSV_HEADER, format_utc, push_field};
pub use diff::{DiffSummary, diff};
pub use error::{Error, Result};
pub use journal::JOURNAL_BYTES;

/// Times must lie within ±`MAX_TIME_MS` (about ±285 000 years around 1970).
pub const MAX_TIME_MS: i64 = 1 << 53;
/// The most rows one [`Audit::query`] returns (larger limits are capped).
pub const MAX_PAGE: usize = 1000;
/// Text fields longer than this many bytes are cut (on a character boundary) and end
/// with `…`.
pub const MAX_FIELD: usize = 16 * 1024;

/// Settings of an audit log.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Config {
    /// Rows older than this many days are deleted by [`Audit::apply_retention`]; `None`
    /// keeps everything.
    pub retention_days: Option<u32>,
}

/// One action to record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// When (Unix ms).
    pub t_ms: i64,
    /// Who: the user's name; `None` when no users are configured.
    pub user: Option<String>,
    /// The client's address (`ip:port`).
    pub addr: Option<String>,
    /// What.
    pub action: Action,
    /// On what: a tag, program, file or user; `None` for the PLC itself (run, stop) or
    /// every force (unforce all).
    pub target: Option<String>,
    /// The value before, as JSON text.
    pub old: Option<String>,
    /// The value after, as JSON text.
    pub new: Option<String>,
    /// Free text: a program diff summary, a reason.
    pub detail: Option<String>,
    /// The door the action came through: `http`, `mqtt`, `opcua`, `modbus`
    /// (`None`: not said, as in rows of schema version 1).
    pub via: Option<String>,
}

impl Entry {
    /// An entry of `action` at `t_ms` with every other field empty.
    pub fn new(t_ms: i64, action: Action) -> Entry {
        Entry {
            t_ms,
            user: None,
            addr: None,
            action,
            target: None,
            old: None,
            new: None,
            detail: None,
            via: None,
        }
    }
}

/// What came of an action.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Written before the action and never finished: the process ended in between.
    Pending,
    /// Done.
    Ok,
    /// Refused or failed, with the reason.
    Failed(String),
}

impl Outcome {
    /// The stored name: `pending`, `ok` or `failed`.
    pub fn name(&self) -> &'static str {
        match self {
            Outcome::Pending => "pending",
            Outcome::Ok => "ok",
            Outcome::Failed(_) => "failed",
        }
    }

    fn error(&self) -> Option<&str> {
        match self {
            Outcome::Failed(e) => Some(e),
            _ => None,
        }
    }
}

/// One stored row.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Row {
    /// Its id: increasing in the order rows were appended, never reused.
    pub id: i64,
    /// When (Unix ms).
    pub t_ms: i64,
    /// Who (`None`: no users were configured).
    pub user: Option<String>,
    /// The client's address.
    pub addr: Option<String>,
    /// The action's stable name (see [`Action`]; a name this version does not know, from
    /// a newer one, is kept as it is).
    pub action: String,
    /// On what.
    pub target: Option<String>,
    /// The value before (JSON text).
    pub old: Option<String>,
    /// The value after (JSON text).
    pub new: Option<String>,
    /// Free text (diff summary).
    pub detail: Option<String>,
    /// The door (`http`, `mqtt`, `opcua`, `modbus`), when said.
    pub via: Option<String>,
    /// What came of it.
    pub outcome: Outcome,
}

/// Which rows a query or export takes; every field left empty matches every row.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Filter {
    /// Rows at or after this time (Unix ms).
    pub from_ms: Option<i64>,
    /// Rows at or before this time (Unix ms).
    pub to_ms: Option<i64>,
    /// Rows of this user (exactly).
    pub user: Option<String>,
    /// Rows of these actions (empty: all).
    pub actions: Vec<Action>,
    /// Rows on this target (tag names are compared ASCII case-insensitively, as Alba's
    /// names are).
    pub target: Option<String>,
}

/// One page of a query, newest first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Page {
    /// The rows, newest (highest id) first.
    pub rows: Vec<Row>,
    /// When more rows match: the `before` of the next page (the id of this page's last
    /// row).
    pub next: Option<i64>,
}

/// An open audit log; clones share it.
#[derive(Clone)]
pub struct Audit {
    inner: Arc<Inner>,
}

struct Inner {
    path: PathBuf,
    config: Config,
    writer: Mutex<Connection>,
    /// `audit.journal` beside the file, for safety actions while it cannot be
    /// written (`None` when the journal itself could not be made).
    journal: Option<Mutex<journal::Journal>>,
    /// The journal holds rows not yet moved into the file.
    journaled: std::sync::atomic::AtomicBool,
}

/// Where the row of a safety action ([`Audit::begin_safety`]) went.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Begun {
    /// Into the log, as [`Audit::begin`]: its id.
    Logged(i64),
    /// Into the fallback journal (the log could not be written): its place there.
    Journaled(u64),
    /// Nowhere (the journal failed or is full too): said on stderr, the system log.
    Nowhere,
}

impl std::fmt::Debug for Audit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Audit")
            .field("path", &self.inner.path)
            .field("config", &self.inner.config)
            .finish_non_exhaustive()
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A connection stays consistent if a holder panicked: an uncommitted transaction is
    // rolled back.
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

fn check_time(t: i64) -> Result<()> {
    if (-MAX_TIME_MS..=MAX_TIME_MS).contains(&t) {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "time {t} ms is outside ±{MAX_TIME_MS} ms"
        )))
    }
}

/// `s` cut to at most [`MAX_FIELD`] bytes.
fn bounded(s: Option<&str>) -> Option<String> {
    let s = s?;
    if s.len() <= MAX_FIELD {
        return Some(s.to_string());
    }
    let mut end = MAX_FIELD - '…'.len_utf8();
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    Some(format!("{}…", &s[..end]))
}

fn row_from(r: &rusqlite::Row<'_>) -> rusqlite::Result<Row> {
    let outcome: String = r.get(9)?;
    let error: Option<String> = r.get(10)?;
    Ok(Row {
        id: r.get(0)?,
        t_ms: r.get(1)?,
        user: r.get(2)?,
        addr: r.get(3)?,
        action: r.get(4)?,
        target: r.get(5)?,
        old: r.get(6)?,
        new: r.get(7)?,
        detail: r.get(8)?,
        via: r.get(11)?,
        outcome: match outcome.as_str() {
            "ok" => Outcome::Ok,
            "failed" => Outcome::Failed(error.unwrap_or_default()),
            _ => Outcome::Pending,
        },
    })
}

/// The `WHERE` clause and parameters of `f` (plus `id < before`).
fn where_clause(f: &Filter, before: Option<i64>) -> (String, Vec<Value>) {
    let mut conds: Vec<String> = Vec::new();
    let mut args: Vec<Value> = Vec::new();
    if let Some(from) = f.from_ms {
        conds.push("t >= ?".into());
        args.push(Value::Integer(from));
    }
    if let Some(to) = f.to_ms {
        conds.push("t <= ?".into());
        args.push(Value::Integer(to));
    }
    if let Some(u) = &f.user {
        conds.push("user_name = ?".into());
        args.push(Value::Text(u.clone()));
    }
    if !f.actions.is_empty() {
        let marks = vec!["?"; f.actions.len()].join(", ");
        conds.push(format!("action IN ({marks})"));
        args.extend(f.actions.iter().map(|a| Value::Text(a.name().to_string())));
    }
    if let Some(t) = &f.target {
        conds.push("target = ? COLLATE NOCASE".into());
        args.push(Value::Text(t.clone()));
    }
    if let Some(b) = before {
        conds.push("id < ?".into());
        args.push(Value::Integer(b));
    }
    let sql = if conds.is_empty() {
        String::new()
    } else {
        format!(" WHERE {}", conds.join(" AND "))
    };
    (sql, args)
}

/// The audit log of the project in `dir`: `<dir>/.alba/audit.db`.
pub fn project_path(dir: &Path) -> PathBuf {
    dir.join(".alba").join("audit.db")
}

impl Audit {
    /// Opens the audit log of the project in `dir` ([`project_path`]), creating its
    /// `.alba` folder and the file if missing: for `alba run` and for commands that
    /// change the project without a server (`alba user`). Several processes may write
    /// the same log (SQLite locks it; a writer waits up to 10 s for another).
    pub fn open_project(dir: &Path, config: Config) -> Result<Audit> {
        let path = project_path(dir);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|source| Error::CreateDir {
                path: parent.to_path_buf(),
                source,
            })?;
        }
        Audit::open(path, config)
    }

    /// Opens the audit log at `path`, creating it if missing (its folder must exist).
    ///
    /// A file that is not SQLite, is corrupt, belongs to another application or has a
    /// newer schema gives [`Error::NotAudit`]; one that cannot be opened at all,
    /// [`Error::Open`].
    pub fn open(path: impl AsRef<Path>, config: Config) -> Result<Audit> {
        let path = path.as_ref().to_path_buf();
        let writer = schema::open_writer(&path)?;
        let journal = match journal::Journal::open(&path.with_extension("journal")) {
            Ok(j) => Some(j),
            Err(e) => {
                eprintln!("warning: audit: no fallback journal beside {}: {e}", path.display());
                None
            }
        };
        let journaled = journal.as_ref().is_some_and(|j| !j.is_empty());
        let audit = Audit {
            inner: Arc::new(Inner {
                path,
                config,
                writer: Mutex::new(writer),
                journal: journal.map(Mutex::new),
                journaled: std::sync::atomic::AtomicBool::new(journaled),
            }),
        };
        if journaled && let Err(e) = audit.replay_journal() {
            eprintln!("warning: audit: the fallback journal's rows stay there for now: {e}");
        }
        Ok(audit)
    }

    /// Begins a safety action — stop, removing forces — which must happen even
    /// when the log cannot be written (a full disk): its `pending` row goes
    /// into the log if it can, else into the fallback journal, else (journal
    /// full or failing too) only to stderr. The caller then performs the
    /// action whatever this returned, and records the outcome with
    /// [`finish_safety`](Self::finish_safety). The journal's rows move into
    /// the log the next time it is written or opened.
    pub fn begin_safety(&self, e: &Entry) -> Begun {
        let error = match self.begin(e) {
            Ok(id) => return Begun::Logged(id),
            Err(err) => err,
        };
        let seq = self.inner.journal.as_ref().and_then(|j| {
            let mut j = lock(j);
            let seq = j.used();
            let t = e.t_ms.to_string();
            let fields = [
                Some("begin"),
                Some(seq.to_string()).as_deref(),
                Some(t.as_str()),
                e.user.as_deref(),
                e.addr.as_deref(),
                Some(e.action.name()),
                e.target.as_deref(),
                e.old.as_deref(),
                e.new.as_deref(),
                e.detail.as_deref(),
            ]
            .map(|f| f.map(str::to_string));
            let refs: Vec<Option<&str>> = fields.iter().map(Option::as_deref).collect();
            j.append(&journal::line(&refs)).ok().map(|()| seq)
        });
        let who = e.user.as_deref().unwrap_or("(no user)");
        let on = e.target.as_deref().unwrap_or("");
        match seq {
            Some(seq) => {
                self.inner.journaled.store(true, std::sync::atomic::Ordering::Relaxed);
                eprintln!(
                    "audit: {} cannot be written ({error}): `{}` {on} by {who} recorded in the fallback journal",
                    self.inner.path.display(),
                    e.action.name()
                );
                Begun::Journaled(seq)
            }
            None => {
                eprintln!(
                    "audit: {} cannot be written ({error}) nor its fallback journal: `{}` {on} by {who} at {} ms \
                     from {} is recorded here only",
                    self.inner.path.display(),
                    e.action.name(),
                    e.t_ms,
                    e.addr.as_deref().unwrap_or("?")
                );
                Begun::Nowhere
            }
        }
    }

    /// Records the outcome of a safety action where its row went.
    pub fn finish_safety(&self, begun: &Begun, outcome: &Outcome) -> Result<()> {
        match begun {
            Begun::Logged(id) => self.finish(*id, outcome),
            Begun::Journaled(seq) => {
                let j = self
                    .inner
                    .journal
                    .as_ref()
                    .ok_or_else(|| Error::InvalidArgument("no journal".into()))?;
                let seq = seq.to_string();
                lock(j).append(&journal::line(&[
                    Some("finish"),
                    Some(&seq),
                    Some(outcome.name()),
                    outcome.error(),
                ]))?;
                Ok(())
            }
            Begun::Nowhere => {
                eprintln!("audit: outcome of the action above: {}", outcome.name());
                Ok(())
            }
        }
    }

    /// Moves the fallback journal's rows into the log (in one transaction),
    /// each with its outcome and a detail saying where it was kept, then
    /// empties the journal. Returns how many rows moved.
    pub fn replay_journal(&self) -> Result<usize> {
        let Some(j) = self.inner.journal.as_ref() else {
            return Ok(0);
        };
        let mut j = lock(j);
        let lines = j.lines()?;
        let mut outcomes = std::collections::HashMap::new();
        for l in &lines {
            let f = journal::fields(l);
            if f.first().and_then(|x| x.as_deref()) == Some("finish") {
                let get = |i: usize| f.get(i).cloned().flatten();
                let outcome = match get(2).as_deref() {
                    Some("ok") => Outcome::Ok,
                    Some("failed") => Outcome::Failed(get(3).unwrap_or_default()),
                    _ => Outcome::Pending,
                };
                outcomes.insert(get(1).unwrap_or_default(), outcome);
            }
        }
        let conn = lock(&self.inner.writer);
        let tx = conn.unchecked_transaction()?;
        let mut moved = 0;
        for l in &lines {
            let f = journal::fields(l);
            let get = |i: usize| f.get(i).cloned().flatten();
            if get(0).as_deref() != Some("begin") {
                continue;
            }
            let Some(action) = get(5).and_then(|a| a.parse::<Action>().ok()) else {
                continue;
            };
            let detail = match get(9) {
                Some(d) => format!("{d} (kept in audit.journal while audit.db could not be written)"),
                None => "kept in audit.journal while audit.db could not be written".to_string(),
            };
            let outcome = outcomes.remove(&get(1).unwrap_or_default()).unwrap_or(Outcome::Pending);
            let e = Entry {
                t_ms: get(2).and_then(|t| t.parse().ok()).unwrap_or(0),
                user: get(3),
                addr: get(4),
                action,
                target: get(6),
                old: get(7),
                new: get(8),
                detail: Some(detail),
                via: None,
            };
            Audit::insert_on(&tx, &e, &outcome)?;
            moved += 1;
        }
        tx.commit()?;
        drop(conn);
        j.clear()?;
        self.inner.journaled.store(false, std::sync::atomic::Ordering::Relaxed);
        Ok(moved)
    }

    /// The database file.
    pub fn path(&self) -> &Path {
        &self.inner.path
    }

    /// The settings it was opened with.
    pub fn config(&self) -> &Config {
        &self.inner.config
    }

    fn insert(&self, e: &Entry, outcome: &Outcome) -> Result<i64> {
        let id = Audit::insert_on(&lock(&self.inner.writer), e, outcome)?;
        // The log can be written again: the journal's rows go in too.
        if self.inner.journaled.load(std::sync::atomic::Ordering::Relaxed)
            && let Err(err) = self.replay_journal()
        {
            eprintln!("warning: audit: the fallback journal's rows stay there for now: {err}");
        }
        Ok(id)
    }

    fn insert_on(conn: &Connection, e: &Entry, outcome: &Outcome) -> Result<i64> {
        check_time(e.t_ms)?;
        let mut stmt = conn.prepare_cached(
            "INSERT INTO audit(t, user_name, addr, action, target, old_value, new_value, detail, outcome, error, via)
             VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)",
        )?;
        stmt.execute(params![
            e.t_ms,
            bounded(e.user.as_deref()),
            bounded(e.addr.as_deref()),
            e.action.name(),
            bounded(e.target.as_deref()),
            bounded(e.old.as_deref()),
            bounded(e.new.as_deref()),
            bounded(e.detail.as_deref()),
            outcome.name(),
            bounded(outcome.error()),
            bounded(e.via.as_deref()),
        ])?;
        Ok(conn.last_insert_rowid())
    }

    /// Appends a row for an action already done (or refused): a login, a logout. Returns
    /// its id once it is committed (durable). A `Pending` outcome is the same as
    /// [`begin`](Self::begin).
    pub fn record(&self, e: &Entry, outcome: &Outcome) -> Result<i64> {
        self.insert(e, outcome)
    }

    /// Appends a `pending` row for an action about to be done, and returns its id once it
    /// is committed (durable): the caller then performs the action, and refuses it if
    /// this failed. [`finish`](Self::finish) records the outcome.
    pub fn begin(&self, e: &Entry) -> Result<i64> {
        self.insert(e, &Outcome::Pending)
    }

    /// Records the outcome of the pending row `id`. Fails with
    /// [`Error::InvalidArgument`] if there is no such row or its outcome is already set,
    /// or if `outcome` is `Pending`.
    pub fn finish(&self, id: i64, outcome: &Outcome) -> Result<()> {
        if *outcome == Outcome::Pending {
            return Err(Error::InvalidArgument(
                "an outcome cannot be set back to pending".into(),
            ));
        }
        let conn = lock(&self.inner.writer);
        let n = conn
            .prepare_cached("UPDATE audit SET outcome = ?2, error = ?3 WHERE id = ?1 AND outcome = 'pending'")?
            .execute(params![id, outcome.name(), bounded(outcome.error())])?;
        if n == 1 {
            Ok(())
        } else {
            Err(Error::InvalidArgument(format!("audit row {id} is not pending")))
        }
    }

    /// Runs `f` in a read transaction on a connection of its own.
    fn read<T>(&self, f: impl FnOnce(&Connection) -> Result<T>) -> Result<T> {
        let mut conn = schema::open_reader(&self.inner.path)?;
        let tx = conn.transaction()?;
        let out = f(&tx)?;
        tx.finish()?;
        Ok(out)
    }

    /// The row `id`, if it exists.
    pub fn get(&self, id: i64) -> Result<Option<Row>> {
        self.read(|c| {
            Ok(c.query_row(
                &format!("SELECT {} FROM audit WHERE id = ?1", schema::COLUMNS),
                [id],
                row_from,
            )
            .optional()?)
        })
    }

    /// The rows matching `filter` with an id below `before` (all when `None`), newest
    /// first, at most `limit` (capped at [`MAX_PAGE`]; 0 is refused). Page on by passing
    /// the reply's `next` as `before`: appends meanwhile do not shift pages.
    pub fn query(&self, filter: &Filter, before: Option<i64>, limit: usize) -> Result<Page> {
        if limit == 0 {
            return Err(Error::InvalidArgument("limit must be at least 1".into()));
        }
        let limit = limit.min(MAX_PAGE);
        let (cond, mut args) = where_clause(filter, before);
        // One more than asked, to know whether a next page exists.
        args.push(Value::Integer(limit as i64 + 1));
        let sql = format!("SELECT {} FROM audit{cond} ORDER BY id DESC LIMIT ?", schema::COLUMNS);
        self.read(|c| {
            let mut stmt = c.prepare(&sql)?;
            let mut rows = stmt
                .query_map(params_from_iter(args), row_from)?
                .collect::<rusqlite::Result<Vec<Row>>>()?;
            let next = if rows.len() > limit {
                rows.truncate(limit);
                rows.last().map(|r| r.id)
            } else {
                None
            };
            Ok(Page { rows, next })
        })
    }

    /// Writes the rows matching `filter`, oldest first, at most `limit` of them, as CSV
    /// (RFC 4180, see [`CSV_HEADER`] and docs/audit.md) to `writer`, row by row: the
    /// memory used does not grow with the number of rows. Returns the number of rows
    /// written.
    pub fn export_csv<W: Write>(&self, filter: &Filter, limit: u64, writer: W) -> Result<u64> {
        let (cond, mut args) = where_clause(filter, None);
        args.push(Value::Integer(i64::try_from(limit).unwrap_or(i64::MAX)));
        let sql = format!("SELECT {} FROM audit{cond} ORDER BY id LIMIT ?", schema::COLUMNS);
        let mut out = std::io::BufWriter::new(writer);
        let n = self.read(|c| {
            let mut stmt = c.prepare(&sql)?;
            let mut rows = stmt.query(params_from_iter(args))?;
            out.write_all(CSV_HEADER.as_bytes())?;
            let mut n = 0;
            let mut line = String::new();
            while let Some(r) = rows.next()? {
                line.clear();
                csv::write_row(&mut line, &row_from(r)?);
                out.write_all(line.as_bytes())?;
                n += 1;
            }
            Ok(n)
        })?;
        out.flush()?;
        Ok(n)
    }

    /// The retention cut-off for time `now_ms`: rows before it are to be deleted.
    /// `None` without retention.
    pub fn retention_cutoff(&self, now_ms: i64) -> Option<i64> {
        let days = i64::from(self.inner.config.retention_days?);
        Some(
            now_ms
                .clamp(-MAX_TIME_MS, MAX_TIME_MS)
                .saturating_sub(days * 86_400_000),
        )
    }

    /// Deletes the rows older than [`retention_cutoff`](Self::retention_cutoff): to be
    /// called at start and daily. Returns the number of rows deleted.
    pub fn apply_retention(&self, now_ms: i64) -> Result<u64> {
        match self.retention_cutoff(now_ms) {
            Some(cutoff) => self.delete_before(cutoff),
            None => Ok(0),
        }
    }

    /// Deletes the rows with a time before `cutoff_ms`, whatever the retention setting,
    /// in transactions of at most 10 000 rows (recording goes on between them). Returns
    /// the number of rows deleted. The file does not shrink: SQLite reuses the pages.
    pub fn delete_before(&self, cutoff_ms: i64) -> Result<u64> {
        let mut deleted = 0;
        loop {
            let n = lock(&self.inner.writer)
                .prepare_cached("DELETE FROM audit WHERE id IN (SELECT id FROM audit WHERE t < ?1 LIMIT 10000)")?
                .execute([cutoff_ms])?;
            deleted += n as u64;
            if n == 0 {
                return Ok(deleted);
            }
        }
    }
}

#[cfg(test)]
mod tests;
