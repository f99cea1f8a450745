//! Stores that take samples under any node id: what a service consuming several
//! runtimes' messages (`alba historian --mqtt`) writes into. The PostgreSQL historian
//! keeps every node in its table; [`SqliteNodes`] keeps one SQLite history file per node.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::{Config, Error, Historian, PgHistorian, Result, Sample, lock};

/// A store of many nodes' samples.
pub trait NodeSink: Send + Sync {
    /// `postgres` or `sqlite`.
    fn kind(&self) -> &'static str;
    /// Stores `samples` under `node` (the rules of [`Historian::record_batch`]). Returns
    /// how many were accepted: stored, or buffered to be sent later.
    fn record_for(&self, node: &str, samples: &[Sample<'_>]) -> Result<usize>;
    /// Makes what was accepted durable where the store can (rollups, back-fill).
    fn flush(&self) -> Result<()>;
    /// What is wrong now, if anything (an unreachable database, a full buffer).
    fn problem(&self) -> Option<String>;
}

impl NodeSink for PgHistorian {
    fn kind(&self) -> &'static str {
        "postgres"
    }

    fn record_for(&self, node: &str, samples: &[Sample<'_>]) -> Result<usize> {
        PgHistorian::record_for(self, node, samples)
    }

    fn flush(&self) -> Result<()> {
        self.backfill().map(|_| ())
    }

    fn problem(&self) -> Option<String> {
        let h = self.health();
        let dropped = if h.dropped > 0 {
            format!(", {} dropped (the buffer was full)", h.dropped)
        } else {
            String::new()
        };
        h.last_error
            .map(|e| format!("database unreachable ({e}): {} samples buffered{dropped}", h.buffered))
    }
}

/// One SQLite history file per node in a folder: `<dir>/<node>.db`, the node id
/// percent-encoded where it is not a letter, digit, `-`, `_` or an inner `.` (so
/// `Plant/line-1` is `Plant%2Fline-1.db`). Each file is an ordinary history database.
pub struct SqliteNodes {
    dir: PathBuf,
    config: Config,
    open: Mutex<HashMap<String, Historian>>,
}

impl SqliteNodes {
    /// The folder `dir` (created if missing); files open with `config`.
    pub fn open(dir: impl AsRef<Path>, config: Config) -> Result<SqliteNodes> {
        let dir = dir.as_ref().to_path_buf();
        std::fs::create_dir_all(&dir).map_err(|e| Error::InvalidArgument(format!("{}: {e}", dir.display())))?;
        Ok(SqliteNodes {
            dir,
            config,
            open: Mutex::new(HashMap::new()),
        })
    }

    /// The history file of `node`.
    pub fn path_of(&self, node: &str) -> PathBuf {
        let mut name = String::new();
        for (i, b) in node.bytes().enumerate() {
            if b.is_ascii_alphanumeric() || b == b'-' || b == b'_' || (b == b'.' && i > 0) {
                name.push(char::from(b));
            } else {
                name.push_str(&format!("%{b:02X}"));
            }
        }
        self.dir.join(format!("{name}.db"))
    }

    /// The history of `node` (its file created on first use).
    pub fn historian(&self, node: &str) -> Result<Historian> {
        if node.is_empty() {
            return Err(Error::InvalidArgument("empty historian node id".into()));
        }
        let mut open = lock(&self.open);
        if let Some(h) = open.get(node) {
            return Ok(h.clone());
        }
        let h = Historian::open(self.path_of(node), self.config.clone())?;
        open.insert(node.to_owned(), h.clone());
        Ok(h)
    }

    /// The nodes that have a file, by id.
    pub fn nodes(&self) -> Result<Vec<String>> {
        let mut out = Vec::new();
        for e in std::fs::read_dir(&self.dir)? {
            let name = e?.file_name();
            if let Some(stem) = name.to_str().and_then(|n| n.strip_suffix(".db"))
                && let Some(node) = decode(stem)
            {
                out.push(node);
            }
        }
        out.sort_by(|a, b| a.as_bytes().cmp(b.as_bytes()));
        Ok(out)
    }
}

/// The node id of a file name made by [`SqliteNodes::path_of`].
fn decode(stem: &str) -> Option<String> {
    let b = stem.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = std::str::from_utf8(b.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok().filter(|s| !s.is_empty())
}

impl NodeSink for SqliteNodes {
    fn kind(&self) -> &'static str {
        "sqlite"
    }

    fn record_for(&self, node: &str, samples: &[Sample<'_>]) -> Result<usize> {
        self.historian(node)?.record_batch(samples)
    }

    fn flush(&self) -> Result<()> {
        let open: Vec<Historian> = lock(&self.open).values().cloned().collect();
        open.iter().try_for_each(Historian::flush)
    }

    fn problem(&self) -> Option<String> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_file_per_node_with_reversible_names() {
        let dir = tempfile::tempdir().expect("tempdir");
        let store = SqliteNodes::open(dir.path().join("nodes"), Config::default()).expect("open");
        for node in ["line-1", "Plant/edge 7/PLC", ".hidden", "ñandú"] {
            let s = [Sample {
                tag: "Level",
                t_ms: 1,
                v: 2.5,
            }];
            assert_eq!(store.record_for(node, &s).expect("record"), 1);
        }
        assert_eq!(
            store.path_of("Plant/edge 7/PLC").file_name().and_then(|n| n.to_str()),
            Some("Plant%2Fedge%207%2FPLC.db")
        );
        assert_eq!(
            store.path_of("..").file_name().and_then(|n| n.to_str()),
            Some("%2E..db")
        );
        assert_eq!(
            store.nodes().expect("nodes"),
            [".hidden", "Plant/edge 7/PLC", "line-1", "ñandú"]
        );
        let h = store.historian("Plant/edge 7/PLC").expect("historian");
        assert_eq!(h.raw("Level", 0, 10, 10).expect("raw").len(), 1);
        assert!(store.record_for("", &[]).is_err());
        store.flush().expect("flush");
    }
}
