//! The storage backends behind one API: the embedded SQLite [`Historian`](crate::Historian)
//! (the default) and the shared PostgreSQL [`PgHistorian`](crate::PgHistorian).

use std::io::Write;

use crate::{Bucket, Error, Historian, Point, Result, Sample, TagRange};

/// One column of a CSV export: a tag of this runtime (`node: None`) or of another node of
/// a shared store.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column<'a> {
    /// The node whose tag it is; `None`: this runtime's.
    pub node: Option<&'a str>,
    /// The tag's name.
    pub tag: &'a str,
}

impl<'a> Column<'a> {
    /// A tag of this runtime.
    pub fn own(tag: &'a str) -> Column<'a> {
        Column { node: None, tag }
    }

    /// The column's header: the tag, or `Tag@node` for another node's.
    pub fn header(&self) -> String {
        match self.node {
            Some(node) => format!("{}@{node}", self.tag),
            None => self.tag.to_owned(),
        }
    }
}

/// What `alba run` records into and the studio's trends read from, whatever the store.
///
/// Every backend gives the same answers on the same data: the same tags, raw samples and
/// downsampled buckets (see [`Historian::query`] for the bucket grid). Reads name a node:
/// `None` is this runtime's; a shared store ([`Backend::node`] is `Some`) also answers for
/// the other nodes writing into it, a store of one runtime gives [`Error::UnknownNode`].
pub trait Backend: Send + Sync {
    /// A short name for logs and health: `sqlite` or `postgres`.
    fn kind(&self) -> &'static str;
    /// This runtime's node id in a shared store; `None` for a store of its own.
    fn node(&self) -> Option<&str>;
    /// The nodes that have samples in a shared store, by id (empty for a store of its own).
    fn nodes(&self) -> Result<Vec<String>>;
    /// Stores samples of any tags and times (see [`Historian::record_batch`]). Returns how
    /// many were accepted.
    fn record_batch(&self, samples: &[Sample<'_>]) -> Result<usize>;
    /// Every tag of `node` that has samples, by name, with the span they cover.
    fn tags(&self, node: Option<&str>) -> Result<Vec<TagRange>>;
    /// The downsampled samples of `node`'s `tag` in `[from_ms, to_ms]`, at most `points`
    /// buckets.
    fn query(&self, node: Option<&str>, tag: &str, from_ms: i64, to_ms: i64, points: usize) -> Result<Vec<Bucket>>;
    /// The samples of `node`'s `tag` in `[from_ms, to_ms]`, oldest first, at most `limit`.
    fn raw(&self, node: Option<&str>, tag: &str, from_ms: i64, to_ms: i64, limit: usize) -> Result<Vec<Point>>;
    /// Writes `columns` as CSV with sample-and-hold (see [`Historian::export_csv`]); the
    /// header names another node's tag `Tag@node`. Returns the number of data rows.
    fn export_csv(
        &self,
        columns: &[Column<'_>],
        from_ms: i64,
        to_ms: i64,
        step_ms: i64,
        out: &mut dyn Write,
    ) -> Result<u64>;
    /// Makes what was accepted durable where the backend can (rollups, back-fill).
    fn flush(&self) -> Result<()>;
}

/// The SQLite store holds one runtime's samples: another node is unknown to it.
fn own(node: Option<&str>) -> Result<()> {
    match node {
        None => Ok(()),
        Some(n) => Err(Error::UnknownNode(n.to_owned())),
    }
}

impl Backend for Historian {
    fn kind(&self) -> &'static str {
        "sqlite"
    }

    fn node(&self) -> Option<&str> {
        None
    }

    fn nodes(&self) -> Result<Vec<String>> {
        Ok(Vec::new())
    }

    fn record_batch(&self, samples: &[Sample<'_>]) -> Result<usize> {
        Historian::record_batch(self, samples)
    }

    fn tags(&self, node: Option<&str>) -> Result<Vec<TagRange>> {
        own(node)?;
        Historian::tags(self)
    }

    fn query(&self, node: Option<&str>, tag: &str, from_ms: i64, to_ms: i64, points: usize) -> Result<Vec<Bucket>> {
        own(node)?;
        Historian::query(self, tag, from_ms, to_ms, points)
    }

    fn raw(&self, node: Option<&str>, tag: &str, from_ms: i64, to_ms: i64, limit: usize) -> Result<Vec<Point>> {
        own(node)?;
        Historian::raw(self, tag, from_ms, to_ms, limit)
    }

    fn export_csv(
        &self,
        columns: &[Column<'_>],
        from_ms: i64,
        to_ms: i64,
        step_ms: i64,
        out: &mut dyn Write,
    ) -> Result<u64> {
        let mut tags = Vec::with_capacity(columns.len());
        for c in columns {
            own(c.node)?;
            tags.push(c.tag);
        }
        Historian::export_csv(self, &tags, from_ms, to_ms, step_ms, out)
    }

    fn flush(&self) -> Result<()> {
        Historian::flush(self)
    }
}
