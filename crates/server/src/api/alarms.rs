//! Alarms (docs/alarms.md, SPEC §10.5): `GET /api/alarms` (the alarms not
//! in `normal`; `?all=true` for every alarm), the operator's actions
//! (acknowledge, shelve, unshelve; out of service for an engineer), done by
//! the control layer (`Control::alarm_act`: the role, the audit row, the
//! alarm log before the change is kept), and
//! `GET /api/alarms/log.csv?from&to` (streamed).

use super::audit::Actor;
use super::{Body, body, stream};
use crate::error::{ApiError, ApiResult};
use crate::reply::{AlarmReply, AlarmStats};
use crate::state::AppState;
use alba_control::alarms::{Alarm, Request};
use axum::Json;
use axum::body::Bytes;
use axum::extract::{Path, Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde_json::Value;
use std::collections::HashMap;
use std::sync::Arc;

/// The most rows one `GET /api/alarms/log.csv` writes.
pub const MAX_CSV_ROWS: u64 = 1_000_000;

fn reply(a: Alarm) -> AlarmReply {
    let (acked_by, ack_comment, acked_ms) = match a.acked {
        Some((u, c, t)) => (Some(u), Some(c), Some(t)),
        None => (None, None, None),
    };
    let (shelved_until_ms, mut by, mut reason) = match a.shelved {
        Some((t, u, r)) => (Some(t), Some(u), Some(r)),
        None => (None, None, None),
    };
    if let Some((u, r)) = a.out_of_service {
        by = Some(u);
        reason = Some(r);
    }
    AlarmReply {
        id: a.def.id,
        tag: a.def.tag,
        state: a.state.name().to_string(),
        severity: a.def.severity,
        message: a.def.message,
        since_ms: a.since_ms,
        condition: a.def.condition.to_string(),
        value: if a.value.is_finite() { a.value } else { 0.0 },
        active: a.active,
        acked_by,
        ack_comment,
        acked_ms,
        shelved_until_ms,
        reason,
        by,
    }
}

/// `GET /api/alarms[?all=true]`: most severe first, then oldest.
pub async fn list(
    State(st): State<Arc<AppState>>,
    Query(q): Query<HashMap<String, String>>,
) -> ApiResult<Json<Vec<AlarmReply>>> {
    if let Some(k) = q.keys().find(|k| k.as_str() != "all") {
        return Err(ApiError::Malformed(format!(
            "unknown query parameter `{k}` (only `all`)"
        )));
    }
    let all = match q.get("all").map(String::as_str) {
        None | Some("false") => false,
        Some("true") => true,
        Some(v) => return Err(ApiError::Malformed(format!("`all` is true or false, not `{v}`"))),
    };
    let list = st.control.alarms().map(|h| h.list(all)).unwrap_or_default();
    Ok(Json(list.into_iter().map(reply).collect()))
}

/// `GET /api/alarms/stats`.
pub async fn stats(State(st): State<Arc<AppState>>) -> Json<AlarmStats> {
    Json(stats_of(&st))
}

/// The alarm summary (also sent on the WebSocket).
pub fn stats_of(st: &AppState) -> AlarmStats {
    let s = st.control.alarm_stats();
    let (top_unacked, top_severity) = s.top_unacked.map_or((None, None), |(id, sev)| (Some(id), Some(sev)));
    AlarmStats {
        alarms: s.alarms,
        active: s.active,
        unacked: s.unacked,
        shelved: s.shelved,
        suppressed: s.suppressed,
        out_of_service: s.out_of_service,
        new_10min: s.new_in_window,
        flood: s.flood,
        top_unacked,
        top_severity,
    }
}

fn text(j: &Value, name: &str) -> ApiResult<String> {
    match j.get(name) {
        None | Some(Value::Null) => Ok(String::new()),
        Some(Value::String(s)) => Ok(s.clone()),
        Some(_) => Err(ApiError::Malformed(format!("`{name}` must be a string"))),
    }
}

/// Applies `req` to alarm `id` through the control layer (its role check
/// and audit row); the alarm after it.
async fn act(st: Arc<AppState>, actor: Actor, id: String, req: Request) -> ApiResult<Json<AlarmReply>> {
    Ok(Json(reply(st.control.alarm_act(&actor.control(), &id, req).await?)))
}

/// `POST /api/alarms/{id}/ack` `{"comment": "..."}` (operator or above).
pub async fn ack(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(id): Path<String>,
    b: Body,
) -> ApiResult<Json<AlarmReply>> {
    let j = body(b)?;
    let comment = text(&j, "comment")?;
    act(st, actor, id, Request::Ack { comment }).await
}

/// `POST /api/alarms/{id}/shelve` `{"minutes": n, "reason": "..."}`.
pub async fn shelve(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(id): Path<String>,
    b: Body,
) -> ApiResult<Json<AlarmReply>> {
    let j = body(b)?;
    let minutes = j
        .get("minutes")
        .and_then(Value::as_u64)
        .and_then(|m| u32::try_from(m).ok())
        .ok_or_else(|| ApiError::Malformed("the body needs `minutes`, a whole number".into()))?;
    let reason = text(&j, "reason")?;
    act(st, actor, id, Request::Shelve { minutes, reason }).await
}

/// `POST /api/alarms/{id}/unshelve` `{}`.
pub async fn unshelve(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(id): Path<String>,
    b: Body,
) -> ApiResult<Json<AlarmReply>> {
    body(b)?;
    act(st, actor, id, Request::Unshelve).await
}

/// `POST /api/alarms/{id}/out_of_service` `{"on": bool, "reason": "..."}` (engineer).
pub async fn out_of_service(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(id): Path<String>,
    b: Body,
) -> ApiResult<Json<AlarmReply>> {
    let j = body(b)?;
    let on = j
        .get("on")
        .and_then(Value::as_bool)
        .ok_or_else(|| ApiError::Malformed("the body needs `on`, true or false".into()))?;
    let reason = text(&j, "reason")?;
    act(st, actor, id, Request::OutOfService { on, reason }).await
}

/// `GET /api/alarms/log.csv?from&to&limit` (Unix ms): every change of state.
pub async fn log_csv(State(st): State<Arc<AppState>>, Query(q): Query<HashMap<String, String>>) -> ApiResult<Response> {
    if let Some(k) = q.keys().find(|k| !["from", "to", "limit"].contains(&k.as_str())) {
        return Err(ApiError::Malformed(format!(
            "unknown query parameter `{k}` (one of: from, to, limit)"
        )));
    }
    let int = |name: &str| -> ApiResult<Option<i64>> {
        q.get(name)
            .map(|v| {
                v.parse()
                    .map_err(|_| ApiError::Malformed(format!("`{name}` must be an integer, got `{v}`")))
            })
            .transpose()
    };
    let (from, to) = (int("from")?, int("to")?);
    let limit = match int("limit")? {
        None => MAX_CSV_ROWS,
        Some(n) if n >= 0 => u64::try_from(n).unwrap_or(0).min(MAX_CSV_ROWS),
        Some(n) => return Err(ApiError::Invalid(format!("`limit` must be at least 0, got {n}"))),
    };
    let log = st
        .control
        .alarms()
        .and_then(|h| h.log().cloned())
        .ok_or_else(|| ApiError::NotFound("this project keeps no alarm log (no alarms.csv)".into()))?;
    let (mut w, rx) = stream::channel::<alba_control::alarms::LogError>();
    tokio::task::spawn_blocking(move || match log.export_csv(from, to, limit, &mut w) {
        Ok(_) => {
            let _ = w.finish();
        }
        Err(e) => w.fail(e),
    });
    Ok((
        [
            (header::CONTENT_TYPE, "text/csv; charset=utf-8"),
            (header::CONTENT_DISPOSITION, "attachment; filename=\"alarms.csv\""),
        ],
        stream::body(Bytes::new(), rx),
    )
        .into_response())
}
