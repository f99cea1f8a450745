//! `/api/history/tags`, `/api/history`, `/api/history.csv`: queries of the
//! historian that `alba run` records into (docs/historian.md).

use crate::error::{ApiError, ApiResult};
use crate::reply::{Bucket, History, HistoryTag};
use crate::state::AppState;
use alba_historian::Historian;
use axum::Json;
use axum::extract::{Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use std::collections::HashMap;
use std::sync::Arc;

/// The most rows a CSV export answers with.
const MAX_CSV_ROWS: i64 = 1_000_000;

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
    let names: Vec<String> = param(&q, "tags")?
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    if names.is_empty() {
        return Err(ApiError::Malformed("`tags` lists no tag".into()));
    }
    let (from, to) = (int(&q, "from", None)?, int(&q, "to", None)?);
    let step = int(&q, "step", Some(1000))?;
    if step < 1 {
        return Err(ApiError::Invalid("`step` must be at least 1 ms".into()));
    }
    if to >= from && (to - from) / step >= MAX_CSV_ROWS {
        return Err(ApiError::Invalid(format!(
            "{} rows is more than {MAX_CSV_ROWS}: choose a larger `step` or a shorter range",
            (to - from) / step + 1
        )));
    }
    let text = blocking(move || {
        let mut out = Vec::new();
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        h.export_csv(&refs, from, to, step, &mut out)?;
        Ok(out)
    })
    .await?;
    Ok((
        [
            (header::CONTENT_TYPE, "text/csv; charset=utf-8"),
            (header::CONTENT_DISPOSITION, "attachment; filename=\"trend.csv\""),
        ],
        text,
    )
        .into_response())
}
