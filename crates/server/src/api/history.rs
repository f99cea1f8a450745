//! `/api/history/nodes`, `/api/history/tags`, `/api/history`,
//! `/api/history/raw`, `/api/history.csv`: queries of the historian that
//! `alba run` records into, whatever its store (docs/historian.md), for this
//! runtime's tags or, with a shared store, another node's (`node=`).

use super::stream;
use crate::error::{ApiError, ApiResult};
use crate::reply::{Bucket, History, HistoryNodes, HistoryRaw, HistoryTag};
use crate::state::AppState;
use alba_control::history::{Backend, Column};
use axum::Json;
use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use std::collections::HashMap;
use std::sync::Arc;

/// The most rows a CSV export answers with.
const MAX_CSV_ROWS: u64 = 1_000_000;
/// The most different tags (columns) of a CSV export.
pub const MAX_CSV_COLUMNS: usize = 64;
/// The most values (rows × columns) of a CSV export.
const MAX_CSV_CELLS: u64 = 10_000_000;

fn historian(st: &AppState) -> Result<Arc<dyn Backend>, ApiError> {
    st.history.clone().ok_or(ApiError::HistoryOff)
}

/// This runtime's node id: the shared store's, or the project's name.
fn own_node(st: &AppState, h: &dyn Backend) -> String {
    h.node().unwrap_or(&st.name).to_owned()
}

/// The node `node` names for the store: `None` for this runtime's (none, or its own id).
fn other_node(own: &str, node: Option<&str>) -> Option<String> {
    node.filter(|n| !n.is_empty() && *n != own).map(str::to_owned)
}

/// The node a query's `node=` names for the store, and the node id to answer with.
fn queried_node(st: &AppState, h: &dyn Backend, q: &HashMap<String, String>) -> (Option<String>, String) {
    let own = own_node(st, h);
    match other_node(&own, q.get("node").map(String::as_str)) {
        Some(n) => (Some(n.clone()), n),
        None => (None, own),
    }
}

/// Runs a query of the historian off the async threads.
async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, alba_control::history::Error> + Send + 'static,
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

/// The most samples one `/api/history/raw` answers with.
pub const MAX_RAW: i64 = 100_000;

pub async fn nodes(State(st): State<Arc<AppState>>) -> ApiResult<Json<HistoryNodes>> {
    let h = historian(&st)?;
    let node = own_node(&st, h.as_ref());
    let shared = h.node().is_some();
    let store = h.clone();
    let mut nodes = blocking(move || store.nodes()).await?;
    if !nodes.contains(&node) {
        nodes.push(node.clone());
        nodes.sort_by(|a, b| a.as_bytes().cmp(b.as_bytes()));
    }
    Ok(Json(HistoryNodes { node, shared, nodes }))
}

pub async fn list(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Json<Vec<HistoryTag>>> {
    let h = historian(&st)?;
    let (node, _) = queried_node(&st, h.as_ref(), &q);
    let tags = blocking(move || h.tags(node.as_deref())).await?;
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
    let (node, answer) = queried_node(&st, h.as_ref(), &q);
    let tag = param(&q, "tag")?.to_string();
    let (from, to) = (int(&q, "from", None)?, int(&q, "to", None)?);
    let points = int(&q, "points", Some(1000))?;
    let points = usize::try_from(points).map_err(|_| ApiError::Invalid("`points` must be at least 1".into()))?;
    let t = tag.clone();
    let buckets = blocking(move || h.query(node.as_deref(), &t, from, to, points)).await?;
    Ok(Json(History {
        node: answer,
        tag,
        from,
        to,
        buckets: buckets
            .iter()
            .map(|b| Bucket(b.t_ms, b.min, b.max, b.first, b.last))
            .collect(),
    }))
}

pub async fn raw(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Json<HistoryRaw>> {
    let h = historian(&st)?;
    let (node, answer) = queried_node(&st, h.as_ref(), &q);
    let tag = param(&q, "tag")?.to_string();
    let (from, to) = (int(&q, "from", None)?, int(&q, "to", None)?);
    let limit = int(&q, "limit", Some(10_000))?;
    if !(1..=MAX_RAW).contains(&limit) {
        return Err(ApiError::Invalid(format!("`limit` must be 1 to {MAX_RAW}")));
    }
    let t = tag.clone();
    // One more than asked: whether the range holds more.
    let mut points = blocking(move || h.raw(node.as_deref(), &t, from, to, limit as usize + 1)).await?;
    let more = points.len() > limit as usize;
    points.truncate(limit as usize);
    Ok(Json(HistoryRaw {
        node: answer,
        tag,
        from,
        to,
        points: points.iter().map(|p| (p.t_ms, p.v)).collect(),
        more,
    }))
}

pub async fn csv(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult<Response> {
    let h = historian(&st)?;
    let own = own_node(&st, h.as_ref());
    // `Tag` of this runtime, `Tag@node` of another node.
    let mut names: Vec<(Option<String>, String)> = Vec::new();
    for name in param(&q, "tags")?.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let column = match name.rsplit_once('@') {
            Some((tag, node)) => (other_node(&own, Some(node)), tag.to_string()),
            None => (None, name.to_string()),
        };
        if !names.contains(&column) {
            names.push(column);
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
    csv_size(from, to, step, names.len())?;
    // One export at a time per permit; the others wait their turn.
    let permit = EXPORTS.acquire().await.map_err(|e| ApiError::Internal(e.to_string()))?;
    let (mut w, mut rx) = stream::channel::<alba_control::history::Error>();
    tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let columns: Vec<Column<'_>> = names
            .iter()
            .map(|(node, tag)| Column {
                node: node.as_deref(),
                tag,
            })
            .collect();
        match h.export_csv(&columns, from, to, step, &mut w) {
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

/// Checks the size of an export of `columns` tags over `[from, to]` every `step` ms
/// against the caps, counting rows as the historian will write them
/// (`alba_control::history::csv_rows`: clamped, no overflow for any `i64`s); the values it holds.
fn csv_size(from: i64, to: i64, step: i64, columns: usize) -> Result<u64, ApiError> {
    let rows = alba_control::history::csv_rows(from, to, step)
        .ok_or_else(|| ApiError::Invalid("`step` must be at least 1 ms".into()))?;
    if rows > MAX_CSV_ROWS {
        return Err(ApiError::Invalid(format!(
            "{rows} rows is more than {MAX_CSV_ROWS}: choose a larger `step` or a shorter range"
        )));
    }
    let cells = rows.saturating_mul(columns as u64);
    if cells > MAX_CSV_CELLS {
        return Err(ApiError::Invalid(format!(
            "{rows} rows of {columns} tags is more than {MAX_CSV_CELLS} values: choose a larger `step`, a shorter range or fewer tags"
        )));
    }
    Ok(cells)
}

/// Exports run at once (each holds a reader of the historian and a thread).
static EXPORTS: tokio::sync::Semaphore = tokio::sync::Semaphore::const_new(2);

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 31: `to - from` overflowed, so `from=i64::MIN&to=i64::MAX` passed the caps as
    /// one row and streamed 610 M values. Over extreme and arbitrary ranges, what is
    /// accepted is within the caps, counted exactly (128-bit arithmetic on the range the
    /// historian clamps to).
    #[test]
    fn csv_caps_hold_for_any_range() {
        let m = alba_control::history::MAX_TIME_MS;
        let exact = |from: i64, to: i64, step: i64| {
            let (f, t) = (i128::from(from.clamp(-m, m)), i128::from(to.clamp(-m, m)));
            if f > t { 0 } else { (t - f) / i128::from(step) + 1 }
        };
        assert!(csv_size(i64::MIN, i64::MAX, 1_801_439_851, 61).is_err());
        let edges = [
            i64::MIN,
            i64::MIN + 1,
            -m - 1,
            -m,
            -1,
            0,
            1,
            m,
            m + 1,
            i64::MAX - 1,
            i64::MAX,
        ];
        let mut cases: Vec<(i64, i64, i64)> = Vec::new();
        for &a in &edges {
            for &b in &edges {
                for step in [1, 2, 1000, 1_801_439_851, i64::MAX / 2, i64::MAX] {
                    cases.push((a, b, step));
                }
            }
        }
        // Arbitrary ones too (a fixed generator: the same cases every run).
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as i64
        };
        for _ in 0..20_000 {
            cases.push((next(), next(), next().unsigned_abs().max(1).min(i64::MAX as u64) as i64));
        }
        for (from, to, step) in cases {
            for columns in [1, 61, MAX_CSV_COLUMNS] {
                if let Ok(cells) = csv_size(from, to, step, columns) {
                    let rows = exact(from, to, step);
                    assert!(rows <= i128::from(MAX_CSV_ROWS), "{from} {to} {step}");
                    assert_eq!(i128::from(cells), rows * columns as i128, "{from} {to} {step}");
                    assert!(cells <= MAX_CSV_CELLS);
                }
            }
        }
    }
}
