//! Alarms (docs/alarms.md, SPEC §10.5): `GET /api/alarms` (the alarms not
//! in `normal`; `?all=true` for every alarm), the operator's actions
//! (acknowledge, shelve, unshelve; out of service for an engineer), each
//! under its audit row and logged in the alarm log before it is kept, and
//! `GET /api/alarms/log.csv?from&to` (streamed).

use super::audit::{Actor, audited, json_text, now_ms};
use super::{Body, body, stream};
use crate::error::{ApiError, ApiResult};
use crate::reply::{AlarmReply, AlarmStats};
use crate::state::AppState;
use alba_alarms::{Alarm, Hub, Request};
use alba_audit::{Action, Entry};
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
    let list = st.alarms.get().map(|h| h.list(all)).unwrap_or_default();
    Ok(Json(list.into_iter().map(reply).collect()))
}

/// `GET /api/alarms/stats`.
pub async fn stats(State(st): State<Arc<AppState>>) -> Json<AlarmStats> {
    Json(stats_of(&st))
}

/// The alarm summary (also sent on the WebSocket).
pub fn stats_of(st: &AppState) -> AlarmStats {
    let s = st
        .alarms
        .get()
        .map(|h| h.stats(now_ms()))
        .unwrap_or(alba_alarms::Stats {
            alarms: 0,
            active: 0,
            unacked: 0,
            shelved: 0,
            suppressed: 0,
            out_of_service: 0,
            new_in_window: 0,
            flood: false,
            top_unacked: None,
        });
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

fn hub(st: &AppState, id: &str) -> ApiResult<Arc<Hub>> {
    st.alarms
        .get()
        .cloned()
        .ok_or_else(|| ApiError::NotFound(format!("no alarm `{id}` (the project has no alarms.csv)")))
}

fn text(j: &Value, name: &str) -> ApiResult<String> {
    match j.get(name) {
        None | Some(Value::Null) => Ok(String::new()),
        Some(Value::String(s)) => Ok(s.clone()),
        Some(_) => Err(ApiError::Malformed(format!("`{name}` must be a string"))),
    }
}

/// Applies `req` to alarm `id` under the audit row `entry` (its target set
/// here). Without users, the actor is `local`.
async fn act(st: Arc<AppState>, actor: Actor, id: String, req: Request, entry: Entry) -> ApiResult<Json<AlarmReply>> {
    let h = hub(&st, &id)?;
    let user = actor.user.unwrap_or_else(|| "local".into());
    let entry = Entry {
        target: Some(id.clone()),
        ..entry
    };
    let hub2 = h.clone();
    let id2 = id.clone();
    audited(&st, entry, async move {
        tokio::task::spawn_blocking(move || hub2.act(&id2, &req, &user, now_ms()))
            .await
            .map_err(|e| ApiError::Internal(e.to_string()))?
            .map_err(ApiError::from)
    })
    .await?;
    let a = h
        .list(true)
        .into_iter()
        .find(|a| a.def.id.eq_ignore_ascii_case(&id))
        .ok_or_else(|| ApiError::NotFound(format!("no alarm `{id}`")))?;
    Ok(Json(reply(a)))
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
    let entry = Entry {
        detail: (!comment.is_empty()).then(|| comment.clone()),
        ..actor.entry(Action::AlarmAck)
    };
    act(st, actor, id, Request::Ack { comment }, entry).await
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
    let entry = Entry {
        detail: Some(format!("{minutes} min: {reason}")),
        ..actor.entry(Action::AlarmShelve)
    };
    act(st, actor, id, Request::Shelve { minutes, reason }, entry).await
}

/// `POST /api/alarms/{id}/unshelve` `{}`.
pub async fn unshelve(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(id): Path<String>,
    b: Body,
) -> ApiResult<Json<AlarmReply>> {
    body(b)?;
    let entry = actor.entry(Action::AlarmUnshelve);
    act(st, actor, id, Request::Unshelve, entry).await
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
    let entry = Entry {
        new: Some(json_text(&Value::Bool(on))),
        detail: (!reason.is_empty()).then(|| reason.clone()),
        ..actor.entry(Action::AlarmOutOfService)
    };
    act(st, actor, id, Request::OutOfService { on, reason }, entry).await
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
        .alarms
        .get()
        .and_then(|h| h.log().cloned())
        .ok_or_else(|| ApiError::NotFound("this project keeps no alarm log (no alarms.csv)".into()))?;
    let (mut w, rx) = stream::channel::<alba_alarms::LogError>();
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
