//! `GET /api/status`, `POST /api/run`, `POST /api/stop`, `POST /api/step`.

use super::audit::Actor;
use crate::error::ApiResult;
use crate::reply::{Problem, Stats, Status};
use crate::state::AppState;
use alba_control::runtime::Snapshot;
use axum::Json;
use axum::extract::State;
use std::sync::Arc;
use std::sync::atomic::Ordering;

/// The status of the runtime behind `state` as of snapshot `s`.
pub fn status_of(s: &Snapshot, state: &AppState) -> Status {
    let st = s.stats;
    let health = state.runtime.health();
    Status {
        project: state.name.clone(),
        state: s.state.into(),
        fault: s.fault.clone(),
        scan_ms: state.scan_ms,
        scans: s.scans,
        time_ms: s.clock_ms,
        stats: Stats {
            last_us: st.last_us,
            min_us: st.min_us,
            max_us: st.max_us,
            mean_us: st.mean_us,
            jitter_us: st.jitter_us,
            overruns: st.overruns,
        },
        minor_faults: s.minor_faults,
        io: state.io.clone(),
        programs: s.program.units.iter().map(|u| u.name.clone()).collect(),
        clients: state.clients.load(Ordering::Relaxed),
        store_ok: health.ok(),
        retain_lost: health.retain_lost(),
        problems: health
            .problems()
            .into_iter()
            .map(|p| Problem {
                source: p.source.to_string(),
                message: p.message,
                since_unix_ms: p.since_unix_ms,
            })
            .chain(state.auth.alerts().into_iter().map(|(user, n, since)| Problem {
                source: "login".into(),
                message: format!(
                    "{n} failed logins for user `{user}`, each within 15 minutes of the last: someone may be \
                     guessing its password (the guessing addresses are held back, the user is not)"
                ),
                since_unix_ms: since,
            }))
            .collect(),
        forces: super::forces::of(s),
        connections: state.connections.get().map(|c| c.status()).unwrap_or_default(),
    }
}

pub async fn get(State(st): State<Arc<AppState>>) -> Json<Status> {
    Json(status_of(&st.runtime.snapshot(), &st))
}

/// Audited (`run`).
pub async fn run(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<Status>> {
    st.control.run(&actor.control()).await?;
    Ok(get(State(st)).await)
}

/// Audited (`stop`), and never refused for want of its audit row (a full
/// disk): see `Control::audited_safety`.
pub async fn stop(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<Status>> {
    st.control.stop(&actor.control()).await?;
    Ok(get(State(st)).await)
}

/// Audited (`step`): while stopped, one scan (inputs, program, outputs,
/// snapshot) and the status after it; `409` while running or faulted.
pub async fn step(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<Status>> {
    st.control.step(&actor.control()).await?;
    Ok(get(State(st)).await)
}
