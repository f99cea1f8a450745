//! `/api/history/tags`, `/api/history`, `/api/history.csv`: queries of the
//! historian that `alba run` records into (docs/historian.md).

use super::stream;
use crate::error::{ApiError, ApiResult};
use crate::reply::{Bucket, History, HistoryTag};
use crate::state::AppState;
use alba_historian::Historian;
use axum::Json;
use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use std::collections::HashMap;
use std::sync::Arc;

/// The most rows a CSV export answers with.
const MAX_CSV_ROWS: i64 = 1_000_000;
/// The most different tags (columns) of a CSV export.
pub const MAX_CSV_COLUMNS: usize = 64;
/// The most values (rows × columns) of a CSV export.
const MAX_CSV_CELLS: i64 = 10_000_000;

fn historian(st: &AppState) -> Result<Historian, ApiError> {
    st.history.clone().ok_or(ApiError::HistoryOff)
}

/// Runs a query of the historian off the async threads.
async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, alba_historian::Error> + Send + 'static,
) -> Result<T, ApiError> {
    Ok(tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ApiError::Internal(e.to_string()))??)
}

type Params = Query<HashMap<String, String>>;

fn param<'a>(q: &'a HashMap<String, String>, name: &str) -> Result<&'a str, ApiError> {
    q.get(name)
        .map(String::as_str)
        .ok_or_else(|| ApiError::Malformed(format!("the query needs `{name}`")))
}

fn int(q: &HashMap<String, String>, name: &str, default: Option<i64>) -> Result<i64, ApiError> {
    match (q.get(name), default) {
        (None, Some(d)) => Ok(d),
        (None, None) => Err(ApiError::Malformed(format!("the query needs `{name}`"))),
        (Some(v), _) => v
            .parse()
            .map_err(|_| ApiError::Malformed(format!("`{name}` must be an integer, got `{v}`"))),
    }
}

pub async fn list(State(st): State<Arc<AppState>>) -> ApiResult<Json<Vec<HistoryTag>>> {
    let h = historian(&st)?;
    let tags = blocking(move || h.tags()).await?;
    Ok(Json(
        tags.into_iter()
            .map(|t| HistoryTag {
                name: t.name,
                first_ms: t.first_ms,
                last_ms: t.last_ms,
            })
            .collect(),
    ))
}

pub async fn query(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Json<History>> {
    let h = historian(&st)?;
    let tag = param(&q, "tag")?.to_string();
    let (from, to) = (int(&q, "from", None)?, int(&q, "to", None)?);
    let points = int(&q, "points", Some(1000))?;
    let points = usize::try_from(points).map_err(|_| ApiError::Invalid("`points` must be at least 1".into()))?;
    let t = tag.clone();
    let buckets = blocking(move || h.query(&t, from, to, points)).await?;
    Ok(Json(History {
        tag,
        from,
        to,
        buckets: buckets
            .iter()
            .map(|b| Bucket(b.t_ms, b.min, b.max, b.first, b.last))
            .collect(),
    }))
}

pub async fn csv(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Response> {
    let h = historian(&st)?;
    let mut names: Vec<String> = Vec::new();
    for name in param(&q, "tags")?.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        if !names.iter().any(|n| n == name) {
            names.push(name.to_string());
        }
        if names.len() > MAX_CSV_COLUMNS {
            return Err(ApiError::Invalid(format!(
                "`tags` lists more than {MAX_CSV_COLUMNS} different tags: export them in several files"
            )));
        }
    }
    if names.is_empty() {
        return Err(ApiError::Malformed("`tags` lists no tag".into()));
    }
    let (from, to) = (int(&q, "from", None)?, int(&q, "to", None)?);
    let step = int(&q, "step", Some(1000))?;
    if step < 1 {
        return Err(ApiError::Invalid("`step` must be at least 1 ms".into()));
    }
    let rows = if to >= from { (to - from) / step + 1 } else { 0 };
    if rows > MAX_CSV_ROWS {
        return Err(ApiError::Invalid(format!(
            "{rows} rows is more than {MAX_CSV_ROWS}: choose a larger `step` or a shorter range"
        )));
    }
    let cells = rows.saturating_mul(names.len() as i64);
    if cells > MAX_CSV_CELLS {
        return Err(ApiError::Invalid(format!(
            "{rows} rows of {} tags is more than {MAX_CSV_CELLS} values: choose a larger `step`, a shorter range or fewer tags",
            names.len()
        )));
    }
    // One export at a time per permit; the others wait their turn.
    let permit = EXPORTS.acquire().await.map_err(|e| ApiError::Internal(e.to_string()))?;
    let (mut w, mut rx) = stream::channel::<alba_historian::Error>();
    tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        match h.export_csv(&refs, from, to, step, &mut w) {
            Ok(_) => {
                let _ = w.finish();
            }
            Err(e) => w.fail(e),
        }
    });
    // A failure before the first bytes (an unknown tag) is an API error.
    let first = match rx.recv().await {
        Some(Ok(bytes)) => bytes,
        Some(Err(e)) => return Err(e.into()),
        None => Bytes::new(),
    };
    Ok((
        [
            (header::CONTENT_TYPE, "text/csv; charset=utf-8"),
            (header::CONTENT_DISPOSITION, "attachment; filename=\"trend.csv\""),
        ],
        stream::body(first, rx),
    )
        .into_response())
}

/// Exports run at once (each holds a reader of the historian and a thread).
static EXPORTS: tokio::sync::Semaphore = tokio::sync::Semaphore::const_new(2);
