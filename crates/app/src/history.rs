//! The historian of `alba run`: a thread that records every tag from the
//! runtime's snapshots (docs/historian.md); the server's `/api/history`
//! endpoints query what it wrote.
//!
//! The recorder takes snapshots from the same `watch` channel as the
//! WebSocket clients: when writing falls behind (10 000 tags changing every
//! scan is more than SQLite takes), it skips snapshots instead of queueing
//! them, and the engine never waits for it.

use alba_historian::{ChangeFilter, Filter, Historian, Recorder};
use alba_model::DataType;
use alba_runtime::Snapshot;
use alba_server::tags;
use std::sync::Arc;
use tokio::sync::watch;

/// Buffered values are written at least this often (ms of record time).
const FLUSH_MS: u64 = 250;
/// Retention runs this often.
const RETENTION_EVERY_MS: i64 = 3_600_000;

/// Opens the project's history database.
pub fn open(dir: &std::path::Path, cfg: &alba_project::config::History) -> Result<Historian, String> {
    let path = dir.join(".alba").join("history.db");
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    }
    let config = alba_historian::Config {
        retention_days: (cfg.retention_days > 0).then_some(cfg.retention_days),
        ..Default::default()
    };
    Historian::open(&path, config).map_err(|e| e.to_string())
}

/// Records every snapshot `rx` publishes until the runtime stops.
pub fn record(
    h: Historian,
    cfg: alba_project::config::History,
    mut rx: watch::Receiver<Arc<Snapshot>>,
    rt: tokio::runtime::Handle,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let every = Filter {
            deadband: 0.0,
            period_ms: u64::from(cfg.sample_ms),
        };
        let mut rec = Recorder::new(h.clone(), ChangeFilter::new(every));
        rec.set_max_delay(FLUSH_MS);
        let mut program = None;
        let mut places = Vec::new();
        let mut retained_at: Option<i64> = None;
        while rt.block_on(rx.changed()).is_ok() {
            let s = rx.borrow_and_update().clone();
            if !program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &s.program)) {
                places = tags::every_value(&s.program.layout);
                for (name, place) in &places {
                    if matches!(place.data_type(), DataType::Real | DataType::Lreal) {
                        rec.filter_mut().set_filter(
                            name,
                            Filter {
                                deadband: cfg.deadband,
                                ..every
                            },
                        );
                    }
                }
                program = Some(s.program.clone());
            }
            let values: Vec<(&str, f64)> = places.iter().map(|(n, p)| (n.as_str(), s.read(*p).as_f64())).collect();
            if let Err(e) = rec.record(s.unix_ms, &values) {
                eprintln!("history: {e}");
            }
            if retained_at.is_none_or(|t| s.unix_ms.saturating_sub(t) >= RETENTION_EVERY_MS) {
                retained_at = Some(s.unix_ms);
                if let Err(e) = h.apply_retention(s.unix_ms) {
                    eprintln!("history retention: {e}");
                }
            }
        }
        if let Err(e) = rec.flush().and_then(|_| h.flush()) {
            eprintln!("history: {e}");
        }
    })
}
