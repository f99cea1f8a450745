//! Reading: tag ranges, raw samples, min/max downsampling over the rollup tiers and the
//! columns of a CSV export.

use rusqlite::{Connection, OptionalExtension, params};

use crate::agg::{Agg, ceil_div, ceil_to, floor_to};
use crate::error::{Error, Result};
use crate::schema::TIERS;
use crate::write::rolled_up_to;
use crate::{Bucket, Point, TagRange};

/// The bucket grid of a downsampled query: bucket `i` covers `[origin + i·width,
/// origin + (i+1)·width)` intersected with the query range, and is computed from the
/// rollup tier `level` (1-based index into `TIERS`) and finer ones, or from raw samples
/// when `level` is 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Plan {
    pub origin: i64,
    pub width: i64,
    pub level: usize,
}

/// The width of level `level`'s buckets (1 ms for raw samples).
pub(crate) fn level_ms(level: usize) -> i64 {
    if level == 0 { 1 } else { TIERS[level - 1].ms }
}

/// Chooses the grid for `points` buckets over `[from, to]` (`from <= to`, `points >= 1`).
///
/// The ideal grid starts at `from` with width `ceil(span / points)`. Reading a tier of
/// width `B` needs bucket edges on multiples of `B`: the grid then starts at `from`
/// rounded down to `B`, its width is rounded up to a multiple of `B`, and so it may hold
/// fewer buckets than the ideal one. The coarsest tier that still gives at least 3/4 of
/// the ideal number of buckets is taken (raw samples always qualify).
pub(crate) fn plan(from: i64, to: i64, points: i64) -> Plan {
    let span = to - from + 1;
    let ideal_width = ceil_div(span, points);
    let ideal_count = ceil_div(span, ideal_width);
    for level in (1..=TIERS.len()).rev() {
        let b = level_ms(level);
        let origin = floor_to(from, b);
        let width = ceil_div(ceil_div(to - origin + 1, points), b) * b;
        let count = (to - origin) / width + 1;
        if 4 * count >= 3 * ideal_count {
            return Plan { origin, width, level };
        }
    }
    Plan {
        origin: from,
        width: ideal_width,
        level: 0,
    }
}

/// Feeds `sink` the aggregates covering exactly the samples of `tag` in `[lo, hi]`, in
/// time order, each with its start time: whole rollup rows of level `level` where they
/// fit inside the range, the uncovered edges from finer levels, down to raw samples.
/// Every piece lies inside one bucket of level `level`.
fn cover(conn: &Connection, tag: i64, lo: i64, hi: i64, level: usize, sink: &mut dyn FnMut(i64, Agg)) -> Result<()> {
    if lo > hi {
        return Ok(());
    }
    if level == 0 {
        let mut stmt =
            conn.prepare_cached("SELECT t, v FROM samples WHERE tag = ?1 AND t >= ?2 AND t <= ?3 ORDER BY t")?;
        let mut rows = stmt.query(params![tag, lo, hi])?;
        while let Some(row) = rows.next()? {
            let t: i64 = row.get(0)?;
            sink(t, Agg::one(t, row.get(1)?));
        }
        return Ok(());
    }
    let b = level_ms(level);
    let start = ceil_to(lo, b);
    let end = floor_to(hi + 1, b);
    if start >= end {
        return cover(conn, tag, lo, hi, level - 1, sink);
    }
    cover(conn, tag, lo, start - 1, level - 1, sink)?;
    {
        let mut stmt = conn.prepare_cached(&format!(
            "SELECT t, min, max, first_t, first, last_t, last, n FROM {}
             WHERE tag = ?1 AND t >= ?2 AND t < ?3 ORDER BY t",
            TIERS[level - 1].table
        ))?;
        let mut rows = stmt.query(params![tag, start, end])?;
        while let Some(row) = rows.next()? {
            let n: i64 = row.get(7)?;
            sink(
                row.get(0)?,
                Agg {
                    min: row.get(1)?,
                    max: row.get(2)?,
                    first_t: row.get(3)?,
                    first: row.get(4)?,
                    last_t: row.get(5)?,
                    last: row.get(6)?,
                    n: u64::try_from(n).unwrap_or(0),
                },
            );
        }
    }
    cover(conn, tag, end, hi, level - 1, sink)
}

/// Like [`cover`], for any range: the rollup tiers hold only the samples before
/// `rolled_up_to` (see write.rs); the newer ones are read raw.
fn cover_all(
    conn: &Connection,
    tag: i64,
    lo: i64,
    hi: i64,
    level: usize,
    sink: &mut dyn FnMut(i64, Agg),
) -> Result<()> {
    let r = rolled_up_to(conn)?;
    cover(conn, tag, lo, hi.min(r - 1), level, sink)?;
    cover(conn, tag, lo.max(r), hi, 0, sink)
}

/// The id of tag `name`.
pub(crate) fn tag_id(conn: &Connection, name: &str) -> Result<i64> {
    conn.prepare_cached("SELECT id FROM tags WHERE name = ?1")?
        .query_row([name], |r| r.get(0))
        .optional()?
        .ok_or_else(|| Error::UnknownTag(name.to_owned()))
}

/// The min/max downsampling of `tag` over `[from, to]` in at most `points` buckets.
pub(crate) fn downsample(conn: &Connection, tag: i64, from: i64, to: i64, points: i64) -> Result<Vec<Bucket>> {
    if from > to {
        return Ok(Vec::new());
    }
    let plan = plan(from, to, points);
    buckets(plan, from, |sink| cover_all(conn, tag, from, to, plan.level, sink))
}

/// The buckets of `plan` (for a query from `from`) from the aggregates `feed` gives the
/// sink, in time order, each inside one bucket.
pub(crate) fn buckets(
    plan: Plan,
    from: i64,
    feed: impl FnOnce(&mut dyn FnMut(i64, Agg)) -> Result<()>,
) -> Result<Vec<Bucket>> {
    let mut out: Vec<Bucket> = Vec::new();
    let mut current: Option<(i64, Agg)> = None;
    let push = |out: &mut Vec<Bucket>, index: i64, a: Agg| {
        out.push(Bucket {
            t_ms: (plan.origin + index * plan.width).max(from),
            min: a.min,
            max: a.max,
            first: a.first,
            last: a.last,
            count: a.n,
        });
    };
    feed(&mut |start, piece| {
        let index = (start - plan.origin).div_euclid(plan.width);
        match &mut current {
            Some((i, a)) if *i == index => a.merge(&piece),
            _ => {
                if let Some((i, a)) = current.take() {
                    push(&mut out, i, a);
                }
                current = Some((index, piece));
            }
        }
    })?;
    if let Some((i, a)) = current {
        push(&mut out, i, a);
    }
    Ok(out)
}

/// The number of samples of `tag` in `[from, to]`, from the coarsest rollups.
fn count(conn: &Connection, tag: i64, from: i64, to: i64) -> Result<u64> {
    let mut n = 0;
    cover_all(conn, tag, from, to, TIERS.len(), &mut |_, a| n += a.n)?;
    Ok(n)
}

/// Raw samples of `tag` in `[from, to]`, oldest first, at most `limit`.
pub(crate) fn raw(conn: &Connection, tag: i64, from: i64, to: i64, limit: i64) -> Result<Vec<Point>> {
    let mut stmt =
        conn.prepare_cached("SELECT t, v FROM samples WHERE tag = ?1 AND t >= ?2 AND t <= ?3 ORDER BY t LIMIT ?4")?;
    let points = stmt
        .query_map(params![tag, from, to, limit], |r| {
            Ok(Point {
                t_ms: r.get(0)?,
                v: r.get(1)?,
            })
        })?
        .collect::<rusqlite::Result<Vec<_>>>()?;
    Ok(points)
}

/// Every tag that has samples, with the time of its first and last one, by name.
pub(crate) fn tags(conn: &Connection) -> Result<Vec<TagRange>> {
    let mut stmt = conn.prepare_cached(
        "SELECT name,
                (SELECT t FROM samples WHERE tag = tags.id ORDER BY t ASC LIMIT 1),
                (SELECT t FROM samples WHERE tag = tags.id ORDER BY t DESC LIMIT 1)
         FROM tags ORDER BY name",
    )?;
    let mut rows = stmt.query([])?;
    let mut out = Vec::new();
    while let Some(row) = rows.next()? {
        let first: Option<i64> = row.get(1)?;
        let last: Option<i64> = row.get(2)?;
        if let (Some(first_ms), Some(last_ms)) = (first, last) {
            out.push(TagRange {
                name: row.get(0)?,
                first_ms,
                last_ms,
            });
        }
    }
    Ok(out)
}

/// The last sample of `tag` at or before `t`.
fn value_at(conn: &Connection, tag: i64, t: i64) -> Result<Option<f64>> {
    Ok(conn
        .prepare_cached("SELECT v FROM samples WHERE tag = ?1 AND t <= ?2 ORDER BY t DESC LIMIT 1")?
        .query_row(params![tag, t], |r| r.get(0))
        .optional()?)
}

/// The columns of a CSV export, read in one transaction.
pub(crate) struct CsvSource<'c> {
    pub conn: &'c Connection,
    pub ids: Vec<i64>,
}

impl crate::csv::Source for CsvSource<'_> {
    fn count(&mut self, c: usize, from: i64, to: i64) -> Result<u64> {
        count(self.conn, self.ids[c], from, to)
    }

    fn values_at(&mut self, c: usize, times: &[i64]) -> Result<Vec<Option<f64>>> {
        times.iter().map(|&t| value_at(self.conn, self.ids[c], t)).collect()
    }

    fn after(&mut self, c: usize, after: i64, to: i64, limit: i64) -> Result<Vec<(i64, f64)>> {
        let mut stmt = self
            .conn
            .prepare_cached("SELECT t, v FROM samples WHERE tag = ?1 AND t > ?2 AND t <= ?3 ORDER BY t LIMIT ?4")?;
        let rows = stmt
            .query_map(params![self.ids[c], after, to, limit], |r| Ok((r.get(0)?, r.get(1)?)))?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        Ok(rows)
    }
}
