//! The alarms of `alba run` (docs/alarms.md): alarms.csv resolved against
//! the program, the alarm log opened, and a thread that evaluates every
//! alarm on each published snapshot at the engine's time (anchored to the
//! wall clock at the first snapshot, so that times in the log and the API
//! are Unix ms and on-delays follow the engine clock). Online edits re-link
//! the alarms to the new program by tag name.
//!
//! Like the historian, the evaluator reads the `watch` channel of
//! snapshots: if it falls behind it skips snapshots rather than hold the
//! engine (an edge shorter than one evaluation can then be missed; a
//! `rising`/`falling` alarm on a pulse of one scan needs the evaluator to
//! keep up, which it does at ordinary scan rates).

use crate::clock::ClockGuard;
use crate::{Service, Started};
use alba_alarms::{AlarmDef, Hub, Log};
use alba_runtime::health::Health;
use std::sync::Arc;

/// The alarms of the project in `dir` resolved against `program` (none
/// without alarms.csv); errors rendered with their lines. Called before the
/// runtime starts: a bad alarms.csv stops `alba run` before anything runs.
pub(crate) fn load(dir: &std::path::Path, program: &alba_ir::Program) -> Result<Option<Vec<AlarmDef>>, String> {
    if !dir.join(alba_alarms::FILE).exists() {
        return Ok(None);
    }
    let mut files = alba_diag::Files::new();
    alba_alarms::def::load(dir, &mut files, &program.layout)
        .map(Some)
        .map_err(|d| alba_diag::render_all(&d, &files))
}

/// The problem a damaged alarm log raises (until the next start).
const DAMAGED: &str = "alarms-damaged";

/// Opens the alarm log. One that is damaged (random bytes, torn or
/// truncated pages) or not an alarm log is moved aside with its `-wal` and
/// `-shm` for a fresh one, and the problem `alarms-damaged` says so: `alba
/// run` starts (issue 31), as with a damaged history database.
fn open(dir: &std::path::Path, retention: u32, health: &Health) -> Result<Log, String> {
    let path = alba_alarms::log::project_path(dir);
    match Log::open(&path, retention) {
        Err(e) if e.is_damage() => {
            // The historian's helper: the same three files of an SQLite store.
            let to =
                alba_historian::move_aside(&path).map_err(|m| format!("{e}; and it cannot be moved aside: {m}"))?;
            health.report(
                DAMAGED,
                format!("{e}: moved to {} and a fresh alarm log started", to.display()),
            );
            Log::open(&path, retention).map_err(|e| e.to_string())
        }
        r => r.map_err(|e| e.to_string()),
    }
}

/// Opens the alarm log and starts the evaluator (`defs` from [`load`]).
/// Retention runs when the clock guard allows (`crate::clock`).
pub(crate) fn start(s: &Service<'_>, defs: Option<Vec<AlarmDef>>, guard: Arc<ClockGuard>) -> Result<Started, String> {
    let Some(defs) = defs else {
        return Ok(Started::Off);
    };
    let snapshot = s.state.runtime.snapshot();
    let retention = s.config.map(|c| c.alarms.retention_days).unwrap_or_default();
    let health = s.state.runtime.health().clone();
    let log = open(s.dir, retention, &health)?;
    if guard.allows(snapshot.unix_ms)
        && let Err(e) = log.apply_retention(snapshot.unix_ms)
    {
        eprintln!("alarms: retention: {e}");
    }
    let hub = Arc::new(Hub::new(defs, Some(log)));
    // Set once, before the server serves.
    let _ = s.state.control.set_alarms(hub.clone());
    let mut rx = s.state.runtime.subscribe();
    let rt = tokio::runtime::Handle::current();
    std::thread::spawn(move || {
        let mut program = snapshot.program.clone();
        let base = snapshot.unix_ms - snapshot.clock_ms as i64;
        let mut failing = false;
        let mut retained_day = snapshot.unix_ms / 86_400_000;
        while rt.block_on(rx.changed()).is_ok() {
            let snap = rx.borrow_and_update().clone();
            let now = base + snap.clock_ms as i64;
            if !Arc::ptr_eq(&program, &snap.program) {
                program = snap.program.clone();
                for id in hub.relink(&program.layout, now) {
                    eprintln!("alarms: `{id}` taken out of service: its tag is no longer in the program");
                }
            }
            // One line when the log starts failing and one when it recovers.
            let updated = hub.update(now, &snap.memory);
            // Damage found by anyone (an acknowledgement, an export, this
            // evaluator): the log moved it aside for a fresh one; said until
            // the next start, never a healthy store meanwhile.
            if let Some(d) = hub.log().and_then(Log::damage) {
                health.report(DAMAGED, d);
            }
            match updated {
                Err(e) if !failing => {
                    failing = true;
                    eprintln!("alarms: the alarm log cannot be written ({e}); alarms are still evaluated");
                }
                Ok(events) if failing && !events.is_empty() => {
                    failing = false;
                    eprintln!("alarms: the alarm log is written again");
                }
                _ => {}
            }
            if now / 86_400_000 != retained_day {
                retained_day = now / 86_400_000;
                if let Some(Err(e)) = hub.log().filter(|_| guard.allows(now)).map(|l| l.apply_retention(now)) {
                    eprintln!("alarms: retention: {e}");
                }
            }
        }
    });
    Ok(Started::On)
}
