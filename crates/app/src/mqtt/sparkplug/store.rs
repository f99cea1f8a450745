//! The store-and-forward buffer of a Sparkplug edge node with a primary host
//! (docs/scale-out.md "Store and forward"): while the node is not born — the
//! host is offline, or the broker cannot be reached — each snapshot's
//! changed values are one record in `.alba/sparkplug-buffer.db` (SQLite, WAL),
//! in order; once the host is back they are sent as historical DDATA and
//! removed. A restart keeps them: they go out after the next birth.
//!
//! Bounded: past `max` records the oldest are deleted (the newest data is
//! worth the most to a plant's operators), and each deleted record counts in
//! `dropped`. A record that cannot be written (a full disk) counts too.

use rusqlite::{Connection, params};
use std::path::Path;

pub(crate) struct Store {
    db: Connection,
    max: u64,
    len: u64,
}

impl Store {
    pub fn open(path: &Path, max: u64) -> Result<Store, String> {
        let err = |e: rusqlite::Error| format!("store-and-forward buffer {}: {e}", path.display());
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
        }
        let db = Connection::open(path).map_err(err)?;
        // WAL with NORMAL: a commit is durable against a crash of Alba (what a
        // `kill -9` is) without an fsync per record; a power loss may cost the
        // last records, never the file.
        db.pragma_update(None, "journal_mode", "WAL").map_err(err)?;
        db.pragma_update(None, "synchronous", "NORMAL").map_err(err)?;
        db.execute_batch(
            "CREATE TABLE IF NOT EXISTS record (
                 id INTEGER PRIMARY KEY AUTOINCREMENT,
                 device TEXT NOT NULL,
                 payload BLOB NOT NULL
             )",
        )
        .map_err(err)?;
        let len: i64 = db
            .query_row("SELECT COUNT(*) FROM record", [], |r| r.get(0))
            .map_err(err)?;
        Ok(Store {
            db,
            max,
            len: len as u64,
        })
    }

    /// Records waiting.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Appends a record; returns how many records were dropped (the oldest,
    /// past the bound, or this one if it could not be written).
    pub fn push(&mut self, device: &str, payload: &[u8]) -> Result<u64, (u64, String)> {
        self.db
            .execute(
                "INSERT INTO record (device, payload) VALUES (?1, ?2)",
                params![device, payload],
            )
            .map_err(|e| (1, e.to_string()))?;
        self.len += 1;
        if self.len <= self.max {
            return Ok(0);
        }
        let over = self.len - self.max;
        self.db
            .execute(
                "DELETE FROM record WHERE id IN (SELECT id FROM record ORDER BY id LIMIT ?1)",
                params![over as i64],
            )
            .map_err(|e| (0, e.to_string()))?;
        self.len = self.max;
        Ok(over)
    }

    /// The oldest `n` records, each with its id for [`Store::remove_through`].
    pub fn oldest(&self, n: usize) -> Result<Vec<(i64, String, Vec<u8>)>, String> {
        let mut q = self
            .db
            .prepare_cached("SELECT id, device, payload FROM record ORDER BY id LIMIT ?1")
            .map_err(|e| e.to_string())?;
        q.query_map(params![n as i64], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))
            .and_then(|rows| rows.collect())
            .map_err(|e| e.to_string())
    }

    /// Removes the records up to `id` (sent, or unreadable).
    pub fn remove_through(&mut self, id: i64) -> Result<(), String> {
        let n = self
            .db
            .execute("DELETE FROM record WHERE id <= ?1", params![id])
            .map_err(|e| e.to_string())?;
        self.len = self.len.saturating_sub(n as u64);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("alba-spb-store-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d.join("buffer.db")
    }

    #[test]
    fn records_come_back_in_order_and_survive_a_reopen() {
        let path = tmp("order");
        let mut s = Store::open(&path, 100).expect("open");
        for k in 0..10u8 {
            assert_eq!(s.push("plc", &[k]), Ok(0));
        }
        drop(s);
        let mut s = Store::open(&path, 100).expect("reopen");
        assert_eq!(s.len(), 10);
        let mut got = Vec::new();
        loop {
            let batch = s.oldest(3).expect("oldest");
            let Some(&(last, _, _)) = batch.last() else { break };
            assert!(batch.iter().all(|(_, d, _)| d == "plc"));
            got.extend(batch.iter().map(|(_, _, p)| p[0]));
            s.remove_through(last).expect("remove");
        }
        assert_eq!(got, (0..10).collect::<Vec<u8>>());
        assert_eq!(s.len(), 0);
        // Ids are never used again: what comes after the replay sorts after it.
        s.push("plc", &[99]).expect("push");
        assert!(s.oldest(1).expect("oldest")[0].0 > 10);
    }

    #[test]
    fn past_the_bound_the_oldest_are_dropped_and_counted() {
        let mut s = Store::open(&tmp("bound"), 5).expect("open");
        let dropped: u64 = (0..12u8).map(|k| s.push("d", &[k]).expect("push")).sum();
        assert_eq!((dropped, s.len()), (7, 5));
        assert_eq!(s.oldest(1).expect("oldest")[0].2, vec![7]);
    }
}
