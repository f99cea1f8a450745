//! The historian of `alba run`: a thread that records every tag from the
//! runtime's snapshots (docs/historian.md) into the embedded SQLite file or
//! the shared PostgreSQL database; the server's `/api/history` endpoints
//! query what it wrote (through `alba_historian::Backend`).
//!
//! It never blocks anything else and never fails quietly (docs/reliability.md):
//! a damaged or foreign database is moved aside for a fresh one (at start or
//! when damage shows while recording), the database is kept under
//! `[history] max_mb` by deleting the oldest hours, recording pauses while the
//! disk has less than `min_free_mb` free, and every failure is a problem in
//! the runtime's [`Health`] (`/api/status`, `S:STOREOK`) until it clears.
//!
//! The recorder takes snapshots from the same `watch` channel as the
//! WebSocket clients: when writing falls behind (10 000 tags changing every
//! scan is more than SQLite takes), it skips snapshots instead of queueing
//! them, and the engine never waits for it.

use alba_historian::{ChangeFilter, Filter, Historian, PgConfig, PgHistorian, Recorder, Sample};
use alba_model::DataType;
use alba_runtime::Snapshot;
use alba_runtime::health::Health;
use alba_server::tags;
use alba_settings::OnDamage;
use std::sync::Arc;
use tokio::sync::watch;

/// Buffered values are written at least this often (ms of record time).
const FLUSH_MS: u64 = 250;
/// Retention runs this often.
const RETENTION_EVERY_MS: i64 = 3_600_000;
/// The size cap and the free-space floor are checked this often.
const CHECK_EVERY_MS: i64 = 1_000;

/// Opens the project's history database. One that is damaged or not a
/// history database is moved aside for a fresh one (reported in `health`),
/// unless `[history] on_damage = "refuse"`.
pub fn open(dir: &std::path::Path, cfg: &alba_settings::History, health: &Health) -> Result<Historian, String> {
    let path = dir.join(".alba").join("history.db");
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    }
    let config = alba_historian::Config {
        retention_days: (cfg.retention_days > 0).then_some(cfg.retention_days),
        ..Default::default()
    };
    match Historian::open(&path, config.clone()) {
        Err(e) if e.is_damage() && cfg.on_damage == OnDamage::Fresh => {
            let to =
                alba_historian::move_aside(&path).map_err(|m| format!("{e}; and it cannot be moved aside: {m}"))?;
            health.report(
                "history-damaged",
                format!("{e}: moved to {} and recording into a fresh database", to.display()),
            );
            Historian::open(&path, config).map_err(|e| e.to_string())
        }
        Err(e) if e.is_damage() => Err(format!(
            "{e} ([history] on_damage = \"refuse\": move or remove the file to start)"
        )),
        r => r.map_err(|e| e.to_string()),
    }
}

/// The time of the newest sample, for the clock guard.
pub fn newest(h: &Historian) -> Option<i64> {
    h.tags().ok()?.iter().map(|t| t.last_ms).max()
}

/// Free bytes for an unprivileged writer on the filesystem holding `path`.
fn free_bytes(path: &std::path::Path) -> Option<u64> {
    let s = rustix::fs::statvfs(path).ok()?;
    Some(s.f_bavail.saturating_mul(s.f_frsize))
}

/// The tags recorded for the program of the latest snapshot (rebuilt after
/// an online edit, REALs with their own filter: the deadband), and the time
/// last recorded.
struct Tracked {
    program: Option<Arc<alba_ir::Program>>,
    places: Vec<(String, alba_ir::Place)>,
    last_t: i64,
}

impl Default for Tracked {
    fn default() -> Tracked {
        Tracked {
            program: None,
            places: Vec::new(),
            last_t: i64::MIN,
        }
    }
}

impl Tracked {
    /// Follows `s`'s program; false for a second snapshot in the same
    /// millisecond (the start's, then the first scan's, on a busy machine):
    /// the store keeps one value per tag and time, and the filter would
    /// believe the second one stored. It is recorded with the next snapshot.
    fn follow(&mut self, s: &Snapshot, filter: &mut ChangeFilter, real: Filter) -> bool {
        if !self.program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &s.program)) {
            self.places = tags::every_value(&s.program.layout);
            for (name, place) in &self.places {
                if matches!(place.data_type(), DataType::Real | DataType::Lreal) {
                    filter.set_filter(name, real);
                }
            }
            self.program = Some(s.program.clone());
        }
        if s.unix_ms == self.last_t {
            return false;
        }
        self.last_t = s.unix_ms;
        true
    }
}

/// Records every snapshot `rx` publishes until the runtime stops.
pub fn record(
    h: Historian,
    cfg: alba_settings::History,
    mut rx: watch::Receiver<Arc<Snapshot>>,
    health: Arc<Health>,
    guard: Arc<crate::clock::ClockGuard>,
    rt: tokio::runtime::Handle,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let max_bytes = u64::from(cfg.max_mb) << 20;
        let floor = u64::from(cfg.min_free_mb) << 20;
        let dir = h.path().parent().map(std::path::Path::to_path_buf).unwrap_or_default();
        let mut checked_at: Option<i64> = None;
        let mut paused = false;
        let every = Filter {
            deadband: 0.0,
            period_ms: u64::from(cfg.sample_ms),
        };
        let real = Filter {
            deadband: cfg.deadband,
            ..every
        };
        let mut rec = Recorder::new(h.clone(), ChangeFilter::new(every));
        rec.set_max_delay(FLUSH_MS);
        let mut tracked = Tracked::default();
        let mut retained_at: Option<i64> = None;
        while rt.block_on(rx.changed()).is_ok() {
            let s = rx.borrow_and_update().clone();
            if !tracked.follow(&s, rec.filter_mut(), real) {
                continue;
            }
            if checked_at.is_none_or(|t| s.unix_ms.saturating_sub(t) >= CHECK_EVERY_MS) {
                checked_at = Some(s.unix_ms);
                paused = check_space(&h, &dir, floor, max_bytes, &health);
            }
            if paused {
                continue;
            }
            let values: Vec<(&str, f64)> = tracked
                .places
                .iter()
                .map(|(n, p)| (n.as_str(), s.read(*p).as_f64()))
                .collect();
            match rec.record(s.unix_ms, &values) {
                // Cleared once values were written (not when they are only buffered).
                Ok(n) if n > 0 && rec.buffered() == 0 => health.clear("history"),
                Ok(_) => {}
                Err(e) => failed(&h, &e, &health),
            }
            if retained_at.is_none_or(|t| s.unix_ms.saturating_sub(t) >= RETENTION_EVERY_MS) {
                retained_at = Some(s.unix_ms);
                // Never after a clock jump nobody explained (crate::clock).
                if guard.allows(s.unix_ms)
                    && let Err(e) = h.apply_retention(s.unix_ms)
                {
                    failed(&h, &e, &health);
                }
            }
        }
        if let Err(e) = rec.flush().and_then(|_| h.flush()) {
            failed(&h, &e, &health);
        }
    })
}

/// A write or a retention pass failed: reported; a damaged database is
/// moved aside for a fresh one at once.
fn failed(h: &Historian, e: &alba_historian::Error, health: &Health) {
    if !e.is_damage() {
        let what = if e.is_disk_full() { "the disk is full: " } else { "" };
        return health.report("history", format!("history not recorded: {what}{e}"));
    }
    match h.replace_damaged() {
        Ok(to) => {
            health.report(
                "history-damaged",
                format!("{e}: moved to {} and recording into a fresh database", to.display()),
            );
            health.clear("history");
        }
        Err(e2) => health.report(
            "history",
            format!("history not recorded: {e}; replacing it failed: {e2}"),
        ),
    }
}

/// The free-space floor and the size cap; whether recording is to pause.
fn check_space(h: &Historian, dir: &std::path::Path, floor: u64, max_bytes: u64, health: &Health) -> bool {
    if max_bytes > 0 {
        match h.enforce_cap(max_bytes) {
            Ok(_) => health.clear("history-cap"),
            Err(e) => health.report("history-cap", format!("cannot keep history under its size cap: {e}")),
        }
    }
    match free_bytes(dir) {
        Some(free) if free < floor => {
            health.report(
                "history-disk",
                format!(
                    "history paused: {} MB free on the disk of {}, below [history] min_free_mb = {}",
                    free >> 20,
                    dir.display(),
                    floor >> 20
                ),
            );
            true
        }
        _ => {
            health.clear("history-disk");
            false
        }
    }
}

/// The settings of `[history] backend = "postgres"` for the project in `dir` (named
/// `name`): the node id defaults to the project's name, the password file is relative to
/// the project folder, the buffer is `.alba/history-buffer.db`.
pub fn pg_config(dir: &std::path::Path, name: &str, cfg: &alba_settings::History) -> Result<PgConfig, String> {
    let url = cfg.url.clone().ok_or("[history] backend = \"postgres\" has no url")?;
    let node = cfg.node.clone().unwrap_or_else(|| name.to_owned());
    let alba = dir.join(".alba");
    std::fs::create_dir_all(&alba).map_err(|e| format!("cannot create {}: {e}", alba.display()))?;
    let mut pg = PgConfig::new(url, node, alba.join("history-buffer.db"));
    pg.buffer_max_samples = u64::from(cfg.buffer_max_samples);
    if let Some(file) = &cfg.password_file {
        pg.password = Some(PgConfig::password_from_file(&dir.join(file)).map_err(|e| e.to_string())?);
    }
    pg.ca_file = cfg.ca_file.as_ref().map(|f| dir.join(f));
    pg.client_cert = cfg
        .client_cert
        .as_ref()
        .zip(cfg.client_key.as_ref())
        .map(|(c, k)| (dir.join(c), dir.join(k)));
    pg.connection().map_err(|e| e.to_string())?;
    Ok(pg)
}

/// Records every snapshot into the shared PostgreSQL historian (docs/historian.md): the
/// same on-change/periodic filter as the SQLite recorder, one batch every `FLUSH_MS`; an
/// unreachable database is the problem `history` (samples buffered and dropped counted)
/// until the buffer is back-filled.
pub fn record_pg(
    h: Arc<PgHistorian>,
    cfg: alba_settings::History,
    mut rx: watch::Receiver<Arc<Snapshot>>,
    health: Arc<Health>,
    rt: tokio::runtime::Handle,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let every = Filter {
            deadband: 0.0,
            period_ms: u64::from(cfg.sample_ms),
        };
        let real = Filter {
            deadband: cfg.deadband,
            ..every
        };
        let mut filter = ChangeFilter::new(every);
        let mut tracked = Tracked::default();
        let mut pending: Vec<(String, i64, f64)> = Vec::new();
        let mut sent_at: Option<i64> = None;
        let send = |pending: &mut Vec<(String, i64, f64)>| {
            let batch: Vec<Sample<'_>> = pending
                .iter()
                .map(|(tag, t_ms, v)| Sample {
                    tag,
                    t_ms: *t_ms,
                    v: *v,
                })
                .collect();
            let result = h.record_batch(&batch);
            pending.clear();
            match result {
                Err(e) => health.report("history", format!("history not recorded: {e}")),
                Ok(_) => {
                    let s = h.health();
                    if s.buffered == 0 && s.last_error.is_none() {
                        health.clear("history");
                    } else {
                        // No counts in the message: a changed message is logged again.
                        let dropping = if s.dropped > 0 {
                            "; the buffer is full, oldest dropped"
                        } else {
                            ""
                        };
                        health.report(
                            "history",
                            format!(
                                "shared historian unreachable ({}): buffering in .alba/history-buffer.db{dropping}",
                                s.last_error.unwrap_or_default(),
                            ),
                        );
                    }
                }
            }
        };
        while rt.block_on(rx.changed()).is_ok() {
            let s = rx.borrow_and_update().clone();
            if !tracked.follow(&s, &mut filter, real) {
                continue;
            }
            for (name, place) in &tracked.places {
                let v = s.read(*place).as_f64();
                if filter.admit(name, s.unix_ms, v) {
                    pending.push((name.clone(), s.unix_ms, v));
                }
            }
            if sent_at.is_none_or(|t| s.unix_ms.saturating_sub(t) >= FLUSH_MS as i64) {
                sent_at = Some(s.unix_ms);
                send(&mut pending);
            }
        }
        send(&mut pending);
        if let Err(e) = h.backfill() {
            health.report("history", format!("history not back-filled: {e}"));
        }
    })
}
