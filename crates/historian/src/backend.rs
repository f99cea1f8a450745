//! The storage backends behind one API: the embedded SQLite [`Historian`](crate::Historian)
//! (the default) and the shared PostgreSQL [`PgHistorian`](crate::PgHistorian).

use crate::{Bucket, Historian, Point, Result, Sample, TagRange};

/// What `alba run` records into and the studio's trends read from, whatever the store.
///
/// Every backend gives the same answers on the same data: the same tags, raw samples and
/// downsampled buckets (see [`Historian::query`] for the bucket grid).
pub trait Backend: Send + Sync {
    /// A short name for logs and health: `sqlite` or `postgres`.
    fn kind(&self) -> &'static str;
    /// Stores samples of any tags and times (see [`Historian::record_batch`]). Returns how
    /// many were accepted.
    fn record_batch(&self, samples: &[Sample<'_>]) -> Result<usize>;
    /// Every tag that has samples, by name, with the span they cover.
    fn tags(&self) -> Result<Vec<TagRange>>;
    /// The downsampled samples of `tag` in `[from_ms, to_ms]`, at most `points` buckets.
    fn query(&self, tag: &str, from_ms: i64, to_ms: i64, points: usize) -> Result<Vec<Bucket>>;
    /// The samples of `tag` in `[from_ms, to_ms]`, oldest first, at most `limit`.
    fn raw(&self, tag: &str, from_ms: i64, to_ms: i64, limit: usize) -> Result<Vec<Point>>;
    /// Makes what was accepted durable where the backend can (rollups, back-fill).
    fn flush(&self) -> Result<()>;
}

impl Backend for Historian {
    fn kind(&self) -> &'static str {
        "sqlite"
    }

    fn record_batch(&self, samples: &[Sample<'_>]) -> Result<usize> {
        Historian::record_batch(self, samples)
    }

    fn tags(&self) -> Result<Vec<TagRange>> {
        Historian::tags(self)
    }

    fn query(&self, tag: &str, from_ms: i64, to_ms: i64, points: usize) -> Result<Vec<Bucket>> {
        Historian::query(self, tag, from_ms, to_ms, points)
    }

    fn raw(&self, tag: &str, from_ms: i64, to_ms: i64, limit: usize) -> Result<Vec<Point>> {
        Historian::raw(self, tag, from_ms, to_ms, limit)
    }

    fn flush(&self) -> Result<()> {
        Historian::flush(self)
    }
}
