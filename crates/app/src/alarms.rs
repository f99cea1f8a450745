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

use crate::{Service, Started};
use alba_alarms::{AlarmDef, Hub, Log};
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

/// Opens the alarm log and starts the evaluator (`defs` from [`load`]).
pub(crate) fn start(s: &Service<'_>, defs: Option<Vec<AlarmDef>>) -> Result<Started, String> {
    let Some(defs) = defs else {
        return Ok(Started::Off);
    };
    let snapshot = s.state.runtime.snapshot();
    let retention = s.config.map(|c| c.alarms.retention_days).unwrap_or_default();
    let log = Log::open(&alba_alarms::log::project_path(s.dir), retention).map_err(|e| e.to_string())?;
    if let Err(e) = log.apply_retention(snapshot.unix_ms) {
        eprintln!("alarms: retention: {e}");
    }
    let hub = Arc::new(Hub::new(defs, Some(log)));
    // Set once, before the server serves.
    let _ = s.state.alarms.set(hub.clone());
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
            match hub.update(now, &snap.memory) {
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
                if let Some(Err(e)) = hub.log().map(|l| l.apply_retention(now)) {
                    eprintln!("alarms: retention: {e}");
                }
            }
        }
    });
    Ok(Started::On)
}
