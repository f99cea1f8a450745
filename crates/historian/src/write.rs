//! The single writer: sample inserts, rollup maintenance and retention deletes.
//!
//! Rollups are maintained lazily but exactly. The `meta` row `rolled_up_to` (R) says that
//! the rollup tiers hold the aggregates of exactly the samples with `t < R`. A sample
//! stored with `t < R` (a late one) updates the tiers in its own transaction; samples with
//! `t >= R` are *pending*: the writer keeps their aggregates in memory and writes them to
//! the tiers (a *flush*, moving R past them) once they span [`FLUSH_SPAN_MS`] or are
//! numerous, on [`Writer::flush`] and when the historian is dropped. A query reads the
//! tiers below R and raw samples from R on, in one snapshot, so it sees every sample.
//!
//! The in-memory pending aggregates are trusted only while the `meta` row `generation`
//! is the one this writer last committed: every write transaction increments it, so
//! after another writer (another `Historian` on the same file) or a retention delete the
//! pending aggregates are recomputed from the samples with `t >= R`. A crash loses
//! nothing: pending samples are in the `samples` table and are rolled up by the next
//! flush.

use std::collections::{BTreeMap, HashMap};

use rusqlite::{Connection, OptionalExtension, Transaction, TransactionBehavior, params};

use crate::agg::{Agg, floor_to};
use crate::check_time;
use crate::error::{Error, Result};
use crate::schema::{COARSEST_MS, TIERS};

/// Pending samples are rolled up once they span this much time…
pub(crate) const FLUSH_SPAN_MS: i64 = 10_000;
/// …or fill this many 1-second buckets (tags × seconds).
const FLUSH_BUCKETS: usize = 20_000;

/// Aggregates keyed by (tag id, bucket start) of the finest tier.
type Buckets = BTreeMap<(i64, i64), Agg>;

/// The writing connection and what it caches.
pub(crate) struct Writer {
    conn: Connection,
    /// Tag name → id of every tag this writer has met (ids never change).
    ids: HashMap<String, i64>,
    /// The upsert statement text of each tier (prepared once, then from the cache).
    upserts: Vec<String>,
    /// Aggregates of the samples with `t >= R`, valid for the `(R, generation)` in `known`.
    pending: Buckets,
    /// The newest time in `pending`.
    pending_max_t: i64,
    known: Option<(i64, i64)>,
}

/// Reads `rolled_up_to` (R).
pub(crate) fn rolled_up_to(conn: &Connection) -> Result<i64> {
    Ok(conn
        .prepare_cached("SELECT value FROM meta WHERE key = 'rolled_up_to'")?
        .query_row([], |r| r.get(0))?)
}

fn generation(conn: &Connection) -> Result<i64> {
    Ok(conn
        .prepare_cached("SELECT value FROM meta WHERE key = 'generation'")?
        .query_row([], |r| r.get(0))?)
}

fn set_meta(conn: &Connection, key: &str, value: i64) -> Result<()> {
    conn.prepare_cached("UPDATE meta SET value = ?2 WHERE key = ?1")?
        .execute(params![key, value])?;
    Ok(())
}

fn add(map: &mut Buckets, key: (i64, i64), a: &Agg) {
    map.entry(key).and_modify(|c| c.merge(a)).or_insert(*a);
}

impl Writer {
    pub fn new(conn: Connection) -> Self {
        let upserts = TIERS
            .iter()
            .map(|tier| {
                format!(
                    "INSERT INTO {0}(tag, t, min, max, first_t, first, last_t, last, n)
                     VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)
                     ON CONFLICT(tag, t) DO UPDATE SET
                       min = min(min, excluded.min),
                       max = max(max, excluded.max),
                       first = CASE WHEN excluded.first_t < first_t THEN excluded.first ELSE first END,
                       first_t = min(first_t, excluded.first_t),
                       last = CASE WHEN excluded.last_t > last_t THEN excluded.last ELSE last END,
                       last_t = max(last_t, excluded.last_t),
                       n = n + excluded.n",
                    tier.table
                )
            })
            .collect();
        Writer {
            conn,
            ids: HashMap::new(),
            upserts,
            pending: Buckets::new(),
            pending_max_t: i64::MIN,
            known: None,
        }
    }

    /// Stores samples `(tag, t_ms, v)` in one transaction. NaN values are skipped, and so
    /// is a sample whose tag already has one at the same millisecond (the first one
    /// stays). Returns how many samples were stored. On error nothing is stored.
    pub fn write<'a>(&mut self, samples: impl IntoIterator<Item = (&'a str, i64, f64)>) -> Result<usize> {
        let out = self.write_inner(samples, false);
        if out.is_err() {
            self.known = None;
        }
        out
    }

    /// Rolls up every pending sample.
    pub fn flush(&mut self) -> Result<()> {
        let out = self.write_inner(std::iter::empty(), true).map(|_| ());
        if out.is_err() {
            self.known = None;
        }
        out
    }

    fn write_inner<'a>(
        &mut self,
        samples: impl IntoIterator<Item = (&'a str, i64, f64)>,
        force_flush: bool,
    ) -> Result<usize> {
        let tx = self.conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
        let r = rolled_up_to(&tx)?;
        let generation = generation(&tx)?;
        if self.known != Some((r, generation)) {
            let (pending, max_t) = pending_from_db(&tx, r)?;
            self.pending = pending;
            self.pending_max_t = max_t;
        }
        let mut new_ids: HashMap<String, i64> = HashMap::new();
        // Late samples (t < R): into the tiers now.
        let mut late = Buckets::new();
        let mut stored = 0;
        {
            let mut insert = tx.prepare_cached("INSERT OR IGNORE INTO samples(tag, t, v) VALUES(?1, ?2, ?3)")?;
            for (name, t, v) in samples {
                check_time(t)?;
                if v.is_nan() {
                    continue;
                }
                let id = match self.ids.get(name).or_else(|| new_ids.get(name)) {
                    Some(&id) => id,
                    None => {
                        let id = tag_id(&tx, name)?;
                        new_ids.insert(name.to_owned(), id);
                        id
                    }
                };
                if insert.execute(params![id, t, v])? == 0 {
                    continue;
                }
                stored += 1;
                let key = (id, floor_to(t, TIERS[0].ms));
                if t < r {
                    add(&mut late, key, &Agg::one(t, v));
                } else {
                    add(&mut self.pending, key, &Agg::one(t, v));
                    self.pending_max_t = self.pending_max_t.max(t);
                }
            }
        }
        let flush = !self.pending.is_empty()
            && (force_flush || self.pending_max_t - r >= FLUSH_SPAN_MS || self.pending.len() >= FLUSH_BUCKETS);
        if !flush && late.is_empty() && stored == 0 {
            // Nothing changed: no transaction to commit, the pending state stays valid.
            drop(tx);
            // (Tags created in it are rolled back: `new_ids` is not cached.)
            self.known = Some((r, generation));
            return Ok(0);
        }
        let mut new_r = r;
        if flush {
            for (key, a) in std::mem::take(&mut self.pending) {
                add(&mut late, key, &a);
            }
            new_r = self.pending_max_t + 1;
            self.pending_max_t = i64::MIN;
            set_meta(&tx, "rolled_up_to", new_r)?;
        }
        upsert_tiers(&tx, &self.upserts, late)?;
        set_meta(&tx, "generation", generation + 1)?;
        tx.commit()?;
        self.known = Some((new_r, generation + 1));
        // Only now: ids of tags created in a rolled-back transaction must not be cached.
        self.ids.extend(new_ids);
        Ok(stored)
    }

    /// Deletes, for one tag, the samples and rollup rows older than `cutoff` (a multiple of
    /// the coarsest tier) in the oldest chunk of at most one coarsest bucket. Returns the
    /// number of samples deleted, or `None` when the tag has nothing older than `cutoff`.
    pub fn delete_chunk(&mut self, tag: i64, cutoff: i64) -> Result<Option<u64>> {
        // Deleted samples may be pending: the pending aggregates are recomputed by the
        // next write (the generation changes).
        self.known = None;
        let tx = self.conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
        // The oldest row of any table: a rollup row's time is its bucket start, before
        // its samples.
        let mut oldest: Option<i64> = None;
        let mut tables = vec!["samples"];
        tables.extend(TIERS.iter().map(|t| t.table));
        for table in &tables {
            let t: Option<i64> = tx
                .prepare_cached(&format!("SELECT t FROM {table} WHERE tag = ?1 ORDER BY t LIMIT 1"))?
                .query_row([tag], |r| r.get(0))
                .optional()?;
            if let Some(t) = t {
                oldest = Some(oldest.map_or(t, |o| o.min(t)));
            }
        }
        let Some(oldest) = oldest.filter(|&o| o < cutoff) else {
            return Ok(None);
        };
        // Whole coarsest buckets: every tier's rows before `end` hold only samples before
        // `end`, so samples and rollups stay consistent.
        let end = (floor_to(oldest, COARSEST_MS) + COARSEST_MS).min(cutoff);
        let mut deleted = 0;
        for table in &tables {
            let n = tx
                .prepare_cached(&format!("DELETE FROM {table} WHERE tag = ?1 AND t < ?2"))?
                .execute(params![tag, end])?;
            if *table == "samples" {
                deleted = n as u64;
            }
        }
        let generation = generation(&tx)?;
        set_meta(&tx, "generation", generation + 1)?;
        tx.commit()?;
        Ok(Some(deleted))
    }

    /// Pages in use times the page size.
    pub fn used_bytes(&self) -> Result<u64> {
        let pragma =
            |name: &str| -> Result<i64> { Ok(self.conn.query_row(&format!("PRAGMA {name}"), [], |r| r.get(0))?) };
        let used = pragma("page_count")? - pragma("freelist_count")?;
        Ok(u64::try_from(used.max(0) * pragma("page_size")?).unwrap_or(0))
    }

    /// The ids of all tags.
    pub fn tag_ids(&self) -> Result<Vec<i64>> {
        let mut stmt = self.conn.prepare_cached("SELECT id FROM tags ORDER BY id")?;
        let ids = stmt
            .query_map([], |r| r.get(0))?
            .collect::<rusqlite::Result<Vec<i64>>>()?;
        Ok(ids)
    }
}

impl Drop for Writer {
    fn drop(&mut self) {
        // Best effort: pending samples are stored anyway and rolled up by the next writer.
        let _ = self.flush();
    }
}

/// Adds the finest-tier aggregates `finest` to every tier.
fn upsert_tiers(tx: &Transaction<'_>, upserts: &[String], finest: Buckets) -> Result<()> {
    if finest.is_empty() {
        return Ok(());
    }
    let mut level = finest;
    for (i, tier) in TIERS.iter().enumerate() {
        if i > 0 {
            let mut coarser = Buckets::new();
            for ((tag, t), a) in level {
                add(&mut coarser, (tag, floor_to(t, tier.ms)), &a);
            }
            level = coarser;
        }
        let mut upsert = tx.prepare_cached(&upserts[i])?;
        for (&(tag, t), a) in &level {
            upsert.execute(params![
                tag,
                t,
                a.min,
                a.max,
                a.first_t,
                a.first,
                a.last_t,
                a.last,
                i64::try_from(a.n).unwrap_or(i64::MAX)
            ])?;
        }
    }
    Ok(())
}

/// The aggregates of the samples with `t >= r`, and their newest time.
fn pending_from_db(conn: &Connection, r: i64) -> Result<(Buckets, i64)> {
    let mut pending = Buckets::new();
    let mut max_t = i64::MIN;
    let ids = conn
        .prepare_cached("SELECT id FROM tags")?
        .query_map([], |row| row.get(0))?
        .collect::<rusqlite::Result<Vec<i64>>>()?;
    let mut stmt = conn.prepare_cached("SELECT t, v FROM samples WHERE tag = ?1 AND t >= ?2")?;
    for id in ids {
        let mut rows = stmt.query(params![id, r])?;
        while let Some(row) = rows.next()? {
            let t: i64 = row.get(0)?;
            add(&mut pending, (id, floor_to(t, TIERS[0].ms)), &Agg::one(t, row.get(1)?));
            max_t = max_t.max(t);
        }
    }
    Ok((pending, max_t))
}

/// The id of tag `name`, created if new.
fn tag_id(conn: &Connection, name: &str) -> Result<i64> {
    if name.is_empty() {
        return Err(Error::InvalidArgument("empty tag name".into()));
    }
    conn.prepare_cached("INSERT INTO tags(name) VALUES(?1) ON CONFLICT(name) DO NOTHING")?
        .execute([name])?;
    let id = conn
        .prepare_cached("SELECT id FROM tags WHERE name = ?1")?
        .query_row([name], |r| r.get(0))?;
    Ok(id)
}
