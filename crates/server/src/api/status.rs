//! `GET /api/status`, `POST /api/run`, `POST /api/stop`, `POST /api/step`.

use super::audit::{Actor, audited, audited_safety, json_text};
use crate::error::ApiResult;
use crate::reply::{Problem, RunState, Stats, Status};
use crate::state::AppState;
use alba_audit::{Action, Entry};
use alba_runtime::Snapshot;
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

/// The audit entry of run/stop: the state before and the one asked for.
fn entry(st: &AppState, actor: &Actor, action: Action, to: RunState) -> Entry {
    let before = RunState::from(st.runtime.snapshot().state);
    let text = |s: RunState| serde_json::to_value(s).map(|v| json_text(&v)).ok();
    Entry {
        old: text(before),
        new: text(to),
        ..actor.entry(action)
    }
}

/// Audited (`run`).
pub async fn run(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<Status>> {
    let e = entry(&st, &actor, Action::Run, RunState::Running);
    audited(&st, e, async { Ok(st.runtime.run().await?) }).await?;
    Ok(get(State(st)).await)
}

/// Audited (`stop`), and never refused for want of its audit row (a full
/// disk): see `audited_safety`.
pub async fn stop(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<Status>> {
    let e = entry(&st, &actor, Action::Stop, RunState::Stopped);
    audited_safety(&st, e, async { Ok(st.runtime.stop().await?) }).await?;
    Ok(get(State(st)).await)
}

/// Audited (`step`): while stopped, one scan (inputs, program, outputs,
/// snapshot) and the status after it; `409` while running or faulted.
pub async fn step(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<Status>> {
    let before = st.runtime.snapshot().scans;
    let e = Entry {
        old: Some(before.to_string()),
        new: Some(before.saturating_add(1).to_string()),
        detail: Some("one scan".to_string()),
        ..actor.entry(Action::Step)
    };
    audited(&st, e, async { Ok(st.runtime.step().await?) }).await?;
    Ok(get(State(st)).await)
}
