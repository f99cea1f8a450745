//! The audit trail (docs/audit.md): `GET /api/audit` (a page of rows, JSON)
//! and `GET /api/audit.csv` (streamed), and the helpers every
//! state-changing handler records its action with.
//!
//! No acknowledged action without its row: a handler checks its request,
//! then [`audited`] writes the row (outcome `pending`) and only if that
//! committed performs the action, then sets the row's outcome (`ok` or
//! `failed`) and answers. If the row cannot be written the action is not
//! performed and the request fails with 500 ([`ApiError::AuditWrite`]). If
//! only the outcome cannot be set, the action stands and is acknowledged:
//! its row exists and says `pending` (logged on stderr).

use super::stream;
use crate::auth::Who;
use crate::error::{ApiError, ApiResult};
use crate::reply::{AuditOutcome, AuditPage, AuditRow};
use crate::state::AppState;
use alba_control::audit::{Action, Audit, Entry, Filter, Outcome};
use axum::Json;
use axum::body::Bytes;
use axum::extract::connect_info::ConnectInfo;
use axum::extract::{FromRequestParts, Query, State};
use axum::http::header;
use axum::http::request::Parts;
use axum::response::{IntoResponse, Response};
use serde_json::Value;
use std::collections::HashMap;
use std::convert::Infallible;
use std::net::SocketAddr;
use std::sync::Arc;

/// Rows per page of `GET /api/audit` unless `limit` says otherwise.
const DEFAULT_PAGE: usize = 100;
/// The most rows one `GET /api/audit.csv` writes.
pub const MAX_CSV_ROWS: u64 = 1_000_000;

/// Who made a request, as its audit row names them: the session layer's
/// [`Who`] (user and client address). Without a session layer (an embedder
/// that does not install it) the user is none and the address the
/// connection's, if the server was started with connect info.
/// Without a session layer the request acts with full rights, as the
/// server did before it had users.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Actor {
    pub user: Option<String>,
    pub role: crate::Role,
    pub addr: Option<SocketAddr>,
}

impl Actor {
    /// An audit entry of `action` by this actor, now (`via`: `http`).
    pub fn entry(&self, action: Action) -> Entry {
        self.control().entry(action)
    }

    /// The actor as the control layer judges it.
    pub fn control(&self) -> alba_control::Actor {
        alba_control::Actor::http(self.user.clone(), self.role, self.addr)
    }
}

impl From<&Who> for Actor {
    fn from(w: &Who) -> Actor {
        Actor {
            user: w.user.clone(),
            role: w.role,
            addr: Some(w.addr),
        }
    }
}

impl<S: Send + Sync> FromRequestParts<S> for Actor {
    type Rejection = Infallible;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Actor, Infallible> {
        if let Some(w) = parts.extensions.get::<Who>() {
            return Ok(Actor::from(w));
        }
        Ok(Actor {
            user: None,
            role: crate::Role::Admin,
            addr: parts.extensions.get::<ConnectInfo<SocketAddr>>().map(|c| c.0),
        })
    }
}

pub use alba_control::json_text;

async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> alba_control::audit::Result<T> + Send + 'static,
) -> Result<alba_control::audit::Result<T>, ApiError> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ApiError::Internal(e.to_string()))
}

/// Performs `action` under its audit row (the control layer's rule): the
/// row first (the action is not performed if it cannot be written), then
/// the action, then its outcome. For the API's own actions (saving
/// screens, trends, symbols; resetting a net); the PLC's operations are
/// the control layer's (`Control::write`, `force`, `run`, …).
pub async fn audited<T>(st: &AppState, entry: Entry, action: impl Future<Output = ApiResult<T>>) -> ApiResult<T> {
    st.control.audited(entry, action).await
}

/// Records an action already done or refused (a login, a failed login, a
/// logout): the reply must wait for it, and fail if it fails.
pub async fn record(st: &AppState, entry: Entry, outcome: Outcome) -> ApiResult<()> {
    Ok(st.control.record(entry, outcome).await?)
}

fn audit(st: &AppState) -> Result<Audit, ApiError> {
    st.control.audit().cloned().ok_or(ApiError::AuditOff)
}

type Params = Query<HashMap<String, String>>;

const PARAMS: [&str; 7] = ["from", "to", "user", "action", "target", "before", "limit"];

fn int(q: &HashMap<String, String>, name: &str) -> Result<Option<i64>, ApiError> {
    q.get(name)
        .map(|v| {
            v.parse()
                .map_err(|_| ApiError::Malformed(format!("`{name}` must be an integer, got `{v}`")))
        })
        .transpose()
}

/// The filter of a query string (docs/api.md); unknown parameters are
/// refused, so that a misspelt filter does not silently match every row.
fn filter(q: &HashMap<String, String>) -> Result<Filter, ApiError> {
    if let Some(k) = q.keys().find(|k| !PARAMS.contains(&k.as_str())) {
        return Err(ApiError::Malformed(format!(
            "unknown query parameter `{k}` (one of: {})",
            PARAMS.join(", ")
        )));
    }
    let text = |name: &str| q.get(name).filter(|v| !v.is_empty()).cloned();
    let actions = match q.get("action") {
        None => Vec::new(),
        Some(list) => list
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<Action>().map_err(|e| ApiError::Malformed(e.to_string())))
            .collect::<Result<_, _>>()?,
    };
    Ok(Filter {
        from_ms: int(q, "from")?,
        to_ms: int(q, "to")?,
        user: text("user"),
        actions,
        target: text("target"),
    })
}

fn row_json(r: alba_control::audit::Row) -> AuditRow {
    let json = |s: Option<String>| match s {
        None => Value::Null,
        Some(t) => serde_json::from_str(&t).unwrap_or(Value::String(t)),
    };
    let (outcome, error) = match r.outcome {
        Outcome::Pending => (AuditOutcome::Pending, None),
        Outcome::Ok => (AuditOutcome::Ok, None),
        Outcome::Failed(e) => (AuditOutcome::Failed, Some(e)),
    };
    AuditRow {
        id: r.id,
        time_ms: r.t_ms,
        user: r.user,
        addr: r.addr,
        action: r.action,
        target: r.target,
        old: json(r.old),
        new: json(r.new),
        detail: r.detail,
        outcome,
        error,
        via: r.via,
    }
}

/// `GET /api/audit?from&to&user&action&target&before&limit`.
pub async fn list(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Json<AuditPage>> {
    let a = audit(&st)?;
    let f = filter(&q)?;
    let before = int(&q, "before")?;
    let limit = match int(&q, "limit")? {
        None => DEFAULT_PAGE,
        Some(n) if n >= 1 => usize::try_from(n).unwrap_or(usize::MAX),
        Some(n) => return Err(ApiError::Invalid(format!("`limit` must be at least 1, got {n}"))),
    };
    let page = blocking(move || a.query(&f, before, limit))
        .await?
        .map_err(ApiError::Audit)?;
    Ok(Json(AuditPage {
        rows: page.rows.into_iter().map(row_json).collect(),
        next: page.next,
    }))
}

/// `GET /api/audit.csv?from&to&user&action&target&limit`: oldest first, at
/// most `limit` (and [`MAX_CSV_ROWS`]) rows, streamed: the server holds a
/// few chunks of it at a time, however many rows match.
pub async fn csv(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Response> {
    let a = audit(&st)?;
    let f = filter(&q)?;
    if q.contains_key("before") {
        return Err(ApiError::Malformed(
            "`before` pages `/api/audit`; filter the export by time".into(),
        ));
    }
    let limit = match int(&q, "limit")? {
        None => MAX_CSV_ROWS,
        Some(n) if n >= 0 => u64::try_from(n).unwrap_or(0).min(MAX_CSV_ROWS),
        Some(n) => return Err(ApiError::Invalid(format!("`limit` must be at least 0, got {n}"))),
    };
    let (mut w, rx) = stream::channel::<alba_control::audit::Error>();
    tokio::task::spawn_blocking(move || match a.export_csv(&f, limit, &mut w) {
        Ok(_) => {
            let _ = w.finish();
        }
        Err(e) => w.fail(e),
    });
    Ok((
        [
            (header::CONTENT_TYPE, "text/csv; charset=utf-8"),
            (header::CONTENT_DISPOSITION, "attachment; filename=\"audit.csv\""),
        ],
        stream::body(Bytes::new(), rx),
    )
        .into_response())
}
