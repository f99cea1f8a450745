//! The Alba historian: an embedded time-series store for tag history.
//!
//! One SQLite file (WAL journal) holds every recorded sample of every tag, plus rollup
//! tiers of per-bucket min/max/first/last/count at 1 s, 10 s, 1 min, 10 min and 1 h. The
//! tiers hold exactly the samples older than a watermark that the writer moves forward
//! every 10 s of data (the newest samples are aggregated in memory meanwhile, and read
//! raw by queries). A downsampled query
//! ([`Historian::query`]) reads the coarsest tier that still gives the requested
//! resolution and fills the range's edges from finer tiers and raw samples, so its answer
//! is exact and its cost depends on the number of points asked for, not on the number of
//! samples stored. Retention ([`Historian::apply_retention`]) deletes old samples and
//! rollups together. Which values to store is up to the caller; [`ChangeFilter`] and
//! [`Recorder`] implement the usual on-change-with-deadband plus periodic rule.
//!
//! [`Historian`] is cheap to clone and is `Send + Sync`: one writing connection behind a
//! mutex and a small pool of reading connections, so queries run on other threads (a
//! server's `spawn_blocking`) while a recording task writes. Times are Unix milliseconds,
//! values `f64` (BOOL as 0/1; integers are exact up to 2^53). See `docs/historian.md`.
//!
//! [`Backend`] is what `alba run` records into and the studio reads, whatever the store:
//! this SQLite file or the shared [`PgHistorian`] of many nodes; [`NodeSink`] is a store of
//! many nodes' samples ([`PgHistorian`], [`SqliteNodes`]) for the broker-fed service.

mod agg;
mod backend;
pub mod bench;
mod csv;
mod error;
mod filter;
mod nodes;
mod pg;
mod query;
mod schema;
mod tls;
mod write;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use rusqlite::Connection;

pub use backend::{Backend, Column};
pub use error::{Error, Result};
pub use filter::{ChangeFilter, Filter, MAX_BUFFERED, Recorder};
pub use nodes::{NodeSink, SqliteNodes};
pub use pg::{DEFAULT_BUFFER_SAMPLES, MigrateReport, PgConfig, PgHealth, PgHistorian, migrate};
pub use tls::client_config as client_tls;

use write::Writer;

/// The most buckets one downsampled query returns (larger requests are capped).
pub const MAX_POINTS: usize = 10_000;
/// Times must lie within ±`MAX_TIME_MS` (about ±285 000 years around 1970).
pub const MAX_TIME_MS: i64 = 1 << 53;
/// The most data rows one CSV export writes.
pub const MAX_CSV_ROWS: u64 = 10_000_000;

/// Settings of a history database.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Config {
    /// Samples older than this many days are deleted by [`Historian::apply_retention`];
    /// `None` keeps everything.
    pub retention_days: Option<u32>,
    /// Reading connections kept open between queries (more are opened while needed).
    pub read_connections: usize,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            retention_days: None,
            read_connections: 4,
        }
    }
}

/// One sample to store.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<'a> {
    /// The tag's name.
    pub tag: &'a str,
    /// Unix time in milliseconds.
    pub t_ms: i64,
    /// The value.
    pub v: f64,
}

/// One stored sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Unix time in milliseconds.
    pub t_ms: i64,
    /// The value.
    pub v: f64,
}

/// A tag that has samples, and the time span they cover.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TagRange {
    /// The tag's name.
    pub name: String,
    /// The time of its oldest sample.
    pub first_ms: i64,
    /// The time of its newest sample.
    pub last_ms: i64,
}

/// The samples of one bucket of a downsampled query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bucket {
    /// The start of the bucket's time span (the query's `from` for the first bucket).
    pub t_ms: i64,
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
    /// The value of the oldest sample.
    pub first: f64,
    /// The value of the newest sample.
    pub last: f64,
    /// The number of samples.
    pub count: u64,
}

/// An open history database; clones share it.
#[derive(Clone)]
pub struct Historian {
    inner: Arc<Inner>,
}

struct Inner {
    path: PathBuf,
    config: Config,
    writer: Mutex<Writer>,
    readers: Mutex<Vec<Connection>>,
}

impl std::fmt::Debug for Historian {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Historian")
            .field("path", &self.inner.path)
            .field("config", &self.inner.config)
            .finish_non_exhaustive()
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // The data behind these locks stays consistent if a holder panicked: a transaction
    // that did not commit is rolled back when dropped.
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

pub(crate) fn check_time(t: i64) -> Result<()> {
    if (-MAX_TIME_MS..=MAX_TIME_MS).contains(&t) {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "time {t} ms is outside ±{MAX_TIME_MS} ms"
        )))
    }
}

/// A query range clamped to the times that can be stored (which does not change answers).
fn clamp_range(from: i64, to: i64) -> (i64, i64) {
    (
        from.clamp(-MAX_TIME_MS, MAX_TIME_MS),
        to.clamp(-MAX_TIME_MS, MAX_TIME_MS),
    )
}

/// The data rows of a CSV export of `[from_ms, to_ms]` every `step_ms`, counted on the
/// range as the export clamps it (the same count the export checks), without overflow for
/// any `i64`s; `None` when `step_ms` is below 1 ms. Callers that cap an export's size
/// (the HTTP API) count with this and nothing else.
pub fn csv_rows(from_ms: i64, to_ms: i64, step_ms: i64) -> Option<u64> {
    if step_ms < 1 {
        return None;
    }
    let (from, to) = clamp_range(from_ms, to_ms);
    if from > to {
        return Some(0);
    }
    // Within ±2^53 the difference fits in an i64 and the quotient plus one in a u64.
    Some(((to - from) / step_ms) as u64 + 1)
}

/// A reading connection borrowed from the pool; returned to it on drop.
struct Reader<'h> {
    conn: Option<Connection>,
    inner: &'h Inner,
}

impl Reader<'_> {
    fn conn(&mut self) -> Result<&mut Connection> {
        match self.conn.as_mut() {
            Some(c) => Ok(c),
            None => Err(Error::InvalidArgument("reader used after release".into())),
        }
    }
}

impl Drop for Reader<'_> {
    fn drop(&mut self) {
        if let Some(conn) = self.conn.take() {
            let mut pool = lock(&self.inner.readers);
            if pool.len() < self.inner.config.read_connections {
                pool.push(conn);
            }
        }
    }
}

impl Historian {
    /// Opens the history database at `path`, creating it if missing.
    ///
    /// A file that is not SQLite, is corrupt, belongs to another application or has a
    /// newer schema gives [`Error::NotHistory`]; one that cannot be opened at all,
    /// [`Error::Open`].
    pub fn open(path: impl AsRef<Path>, config: Config) -> Result<Historian> {
        let path = path.as_ref().to_path_buf();
        let writer = Writer::new(schema::open_writer(&path)?);
        Ok(Historian {
            inner: Arc::new(Inner {
                path,
                config,
                writer: Mutex::new(writer),
                readers: Mutex::new(Vec::new()),
            }),
        })
    }

    /// The database file.
    pub fn path(&self) -> &Path {
        &self.inner.path
    }

    /// The settings it was opened with.
    pub fn config(&self) -> &Config {
        &self.inner.config
    }

    fn reader(&self) -> Result<Reader<'_>> {
        let pooled = lock(&self.inner.readers).pop();
        let conn = match pooled {
            Some(c) => c,
            None => schema::open_reader(&self.inner.path)?,
        };
        Ok(Reader {
            conn: Some(conn),
            inner: &self.inner,
        })
    }

    /// Runs `f` in a read transaction: one consistent snapshot of the database.
    fn read<T>(&self, f: impl FnOnce(&Connection) -> Result<T>) -> Result<T> {
        let mut reader = self.reader()?;
        let tx = reader.conn()?.transaction()?;
        let out = f(&tx)?;
        tx.finish()?;
        Ok(out)
    }

    pub(crate) fn write<'a>(&self, samples: impl IntoIterator<Item = (&'a str, i64, f64)>) -> Result<usize> {
        lock(&self.inner.writer).write(samples)
    }

    /// Stores `values` (tag name, value) at `t_ms` in one transaction, with no filtering
    /// (see [`Recorder`] for that). NaN values are skipped, and so is a value for a tag
    /// that already has one at `t_ms`. Returns how many were stored; on error none is.
    pub fn record(&self, t_ms: i64, values: &[(&str, f64)]) -> Result<usize> {
        self.write(values.iter().map(|&(name, v)| (name, t_ms, v)))
    }

    /// Stores samples of any tags and times in one transaction: for bulk imports and
    /// buffered writers (one transaction per call; larger batches write faster). Same
    /// rules as [`record`](Self::record).
    pub fn record_batch(&self, samples: &[Sample<'_>]) -> Result<usize> {
        self.write(samples.iter().map(|s| (s.tag, s.t_ms, s.v)))
    }

    /// Writes the rollups of the recent samples that are still kept in memory (see
    /// `docs/historian.md`). Never needed for correct answers; done anyway when the last
    /// clone of the historian is dropped.
    pub fn flush(&self) -> Result<()> {
        lock(&self.inner.writer).flush()
    }

    /// Every tag that has samples, by name, with the span they cover.
    pub fn tags(&self) -> Result<Vec<TagRange>> {
        self.read(query::tags)
    }

    /// The samples of `tag` in `[from_ms, to_ms]` (both included) reduced to at most
    /// `points` buckets (capped at [`MAX_POINTS`]) of min/max/first/last/count, oldest
    /// first; buckets without samples are left out. The buckets have equal widths of at
    /// least `(to - from + 1) / points` ms, are aligned so that they can be read from the
    /// rollup tiers, and are at least 3/4 as many as requested when the range holds that
    /// many milliseconds. An empty or reversed range gives no bucket.
    pub fn query(&self, tag: &str, from_ms: i64, to_ms: i64, points: usize) -> Result<Vec<Bucket>> {
        if points == 0 {
            return Err(Error::InvalidArgument("points must be at least 1".into()));
        }
        let points = points.min(MAX_POINTS) as i64;
        let (from, to) = clamp_range(from_ms, to_ms);
        self.read(|c| {
            let id = query::tag_id(c, tag)?;
            query::downsample(c, id, from, to, points)
        })
    }

    /// The samples of `tag` in `[from_ms, to_ms]` (both included), oldest first, at most
    /// `limit` of them.
    pub fn raw(&self, tag: &str, from_ms: i64, to_ms: i64, limit: usize) -> Result<Vec<Point>> {
        let (from, to) = clamp_range(from_ms, to_ms);
        let limit = i64::try_from(limit).unwrap_or(i64::MAX);
        self.read(|c| {
            let id = query::tag_id(c, tag)?;
            query::raw(c, id, from, to, limit)
        })
    }

    /// Writes `tags` as CSV: a header `Time (ms),TagA,TagB`, then one row for each time
    /// `from_ms + k·step_ms` up to `to_ms`, with the time relative to `from_ms` and, for
    /// each tag, its value at that time held from its last sample at or before it (an
    /// empty cell before the tag's first sample). Returns the number of data rows. An
    /// unknown tag fails before anything is written.
    pub fn export_csv<W: Write>(
        &self,
        tags: &[&str],
        from_ms: i64,
        to_ms: i64,
        step_ms: i64,
        writer: W,
    ) -> Result<u64> {
        let (from, to) = clamp_range(from_ms, to_ms);
        let mut writer = std::io::BufWriter::new(writer);
        let headers: Vec<String> = tags.iter().map(|t| (*t).to_owned()).collect();
        self.read(|conn| {
            csv::rows(from, to, step_ms)?;
            let ids = tags
                .iter()
                .map(|n| query::tag_id(conn, n))
                .collect::<Result<Vec<_>>>()?;
            let mut src = query::CsvSource { conn, ids };
            csv::write(&mut src, &headers, from, to, step_ms, &mut writer)
        })
    }

    /// The retention cut-off for time `now_ms`: samples before it are to be deleted. It is
    /// `now_ms` less the retention days, rounded down to the hour. `None` without
    /// retention.
    pub fn retention_cutoff(&self, now_ms: i64) -> Option<i64> {
        let days = i64::from(self.inner.config.retention_days?);
        let cutoff = now_ms
            .clamp(-MAX_TIME_MS, MAX_TIME_MS)
            .saturating_sub(days * 86_400_000);
        Some(agg::floor_to(cutoff, schema::COARSEST_MS))
    }

    /// Deletes the samples and rollups older than
    /// [`retention_cutoff`](Self::retention_cutoff): to be called periodically (say
    /// hourly, from a blocking task). It works in transactions of at most one hour of one tag, releasing the
    /// writer between them so that recording goes on. Returns the number of samples
    /// deleted. The file does not shrink: SQLite reuses the freed pages.
    pub fn apply_retention(&self, now_ms: i64) -> Result<u64> {
        let Some(cutoff) = self.retention_cutoff(now_ms) else {
            return Ok(0);
        };
        self.delete_before(cutoff)
    }

    /// Deletes the samples and rollups older than `cutoff_ms` rounded down to the hour,
    /// whatever the retention setting. Returns the number of samples deleted.
    pub fn delete_before(&self, cutoff_ms: i64) -> Result<u64> {
        let cutoff = agg::floor_to(cutoff_ms.clamp(-MAX_TIME_MS, MAX_TIME_MS), schema::COARSEST_MS);
        let ids = lock(&self.inner.writer).tag_ids()?;
        let mut deleted = 0;
        for id in ids {
            while let Some(n) = lock(&self.inner.writer).delete_chunk(id, cutoff)? {
                deleted += n;
            }
        }
        Ok(deleted)
    }

    /// The bytes the stored data takes: the file's pages less its free ones (SQLite reuses
    /// free pages, so the file stays about this size while [`enforce_cap`](Self::enforce_cap)
    /// holds it down).
    pub fn used_bytes(&self) -> Result<u64> {
        lock(&self.inner.writer).used_bytes()
    }

    /// Deletes the oldest samples and rollups, one hour at a time, until the data takes at
    /// most `max_bytes` (or only the newest hour is left). Returns the number of samples
    /// deleted.
    pub fn enforce_cap(&self, max_bytes: u64) -> Result<u64> {
        let mut deleted = 0;
        while self.used_bytes()? > max_bytes {
            let oldest = self.read(query::tags)?.iter().map(|t| t.first_ms).min();
            let Some(oldest) = oldest else { break };
            let n = self.delete_before(agg::floor_to(oldest, schema::COARSEST_MS) + schema::COARSEST_MS)?;
            if n == 0 {
                break;
            }
            deleted += n;
        }
        Ok(deleted)
    }

    /// The database turned out damaged while in use ([`Error::is_damage`]): it is closed,
    /// moved aside with [`move_aside`], and a fresh one is created in its place. Returns
    /// where the old one went. Queries running meanwhile may fail.
    pub fn replace_damaged(&self) -> Result<PathBuf> {
        let path = &self.inner.path;
        let mut writer = lock(&self.inner.writer);
        // Close every connection to the old file before its files move (SQLite deletes
        // the `-wal` file by name when the last one closes).
        *writer = Writer::new(Connection::open_in_memory()?);
        lock(&self.inner.readers).clear();
        let to = move_aside(path)?;
        *writer = Writer::new(schema::open_writer(path)?);
        Ok(to)
    }
}

/// Moves the database `path` and its `-wal` and `-shm` files aside to
/// `<name>.damaged-<unix ms>` (`alba_sqlite::move_aside`, shared with the
/// audit trail and the alarm log).
pub use alba_sqlite::move_aside;

#[cfg(test)]
mod tests;
