//! The historian of `alba run`: a thread that records every tag from the
//! runtime's snapshots (docs/historian.md), and the `/api/history` endpoints.
//!
//! The recorder takes snapshots from the same `watch` channel as the
//! WebSocket clients: when writing falls behind (10 000 tags changing every
//! scan is more than SQLite takes), it skips snapshots instead of queueing
//! them, and the engine never waits for it.

use crate::{ApiError, ApiResult, AppState, ok, tags};
use alba_historian::{ChangeFilter, Filter, Historian, Recorder};
use alba_model::{DataType, Value};
use alba_runtime::Snapshot;
use axum::extract::{Query, State};
use axum::http::header;
use axum::response::IntoResponse;
use serde_json::json;
use std::collections::HashMap;
use std::sync::Arc;
use tokio::sync::watch;

/// Buffered values are written at least this often (ms of record time).
const FLUSH_MS: u64 = 250;
/// Retention runs this often.
const RETENTION_EVERY_MS: i64 = 3_600_000;
/// The most rows a CSV export answers with.
const MAX_CSV_ROWS: i64 = 1_000_000;

fn as_f64(v: Value) -> f64 {
    match v {
        Value::Bool(b) => f64::from(u8::from(b)),
        Value::Sint(x) => f64::from(x),
        Value::Int(x) => f64::from(x),
        Value::Dint(x) => f64::from(x),
        Value::Lint(x) => x as f64,
        Value::Real(x) => f64::from(x),
        Value::Lreal(x) => x,
        Value::Time(x) => f64::from(x),
    }
}

/// Opens the project's history database.
pub fn open(dir: &std::path::Path, cfg: &alba_project::config::History) -> Result<Historian, String> {
    let path = dir.join(".alba").join("history.db");
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    }
    let config = alba_historian::Config {
        retention_days: (cfg.retention_days > 0).then_some(cfg.retention_days),
        ..Default::default()
    };
    Historian::open(&path, config).map_err(|e| e.to_string())
}

/// Records every snapshot `rx` publishes until the runtime stops.
pub fn record(
    h: Historian,
    cfg: alba_project::config::History,
    mut rx: watch::Receiver<Arc<Snapshot>>,
    rt: tokio::runtime::Handle,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let every = Filter {
            deadband: 0.0,
            period_ms: u64::from(cfg.sample_ms),
        };
        let mut rec = Recorder::new(h.clone(), ChangeFilter::new(every));
        rec.set_max_delay(FLUSH_MS);
        let mut program = None;
        let mut places = Vec::new();
        let mut retained_at: Option<i64> = None;
        while rt.block_on(rx.changed()).is_ok() {
            let s = rx.borrow_and_update().clone();
            if !program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &s.program)) {
                places = tags::every_value(&s.program.layout);
                for (name, place) in &places {
                    if matches!(place.data_type(), DataType::Real | DataType::Lreal) {
                        rec.filter_mut().set_filter(
                            name,
                            Filter {
                                deadband: cfg.deadband,
                                ..every
                            },
                        );
                    }
                }
                program = Some(s.program.clone());
            }
            let values: Vec<(&str, f64)> = places.iter().map(|(n, p)| (n.as_str(), as_f64(s.read(*p)))).collect();
            if let Err(e) = rec.record(s.unix_ms, &values) {
                eprintln!("history: {e}");
            }
            if retained_at.is_none_or(|t| s.unix_ms.saturating_sub(t) >= RETENTION_EVERY_MS) {
                retained_at = Some(s.unix_ms);
                if let Err(e) = h.apply_retention(s.unix_ms) {
                    eprintln!("history retention: {e}");
                }
            }
        }
        if let Err(e) = rec.flush().and_then(|_| h.flush()) {
            eprintln!("history: {e}");
        }
    })
}

fn historian(st: &AppState) -> Result<Historian, ApiError> {
    st.history.clone().ok_or_else(|| {
        ApiError::not_found("history is off for this project (`[history] enabled = false` in alba.toml)")
    })
}

fn from_history(e: alba_historian::Error) -> ApiError {
    match e {
        alba_historian::Error::UnknownTag(t) => ApiError::not_found(format!("no history for `{t}`")),
        alba_historian::Error::InvalidArgument(m) => ApiError::unprocessable(m),
        e => ApiError::new(axum::http::StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

/// Runs a query of the historian off the async threads.
async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, alba_historian::Error> + Send + 'static,
) -> Result<T, ApiError> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ApiError::new(axum::http::StatusCode::INTERNAL_SERVER_ERROR, e.to_string()))?
        .map_err(from_history)
}

type Params = Query<HashMap<String, String>>;

fn param<'a>(q: &'a HashMap<String, String>, name: &str) -> Result<&'a str, ApiError> {
    q.get(name)
        .map(String::as_str)
        .ok_or_else(|| ApiError::bad(format!("the query needs `{name}`")))
}

fn int(q: &HashMap<String, String>, name: &str, default: Option<i64>) -> Result<i64, ApiError> {
    match (q.get(name), default) {
        (None, Some(d)) => Ok(d),
        (None, None) => Err(ApiError::bad(format!("the query needs `{name}`"))),
        (Some(v), _) => v
            .parse()
            .map_err(|_| ApiError::bad(format!("`{name}` must be an integer, got `{v}`"))),
    }
}

pub async fn list(State(st): State<Arc<AppState>>) -> ApiResult {
    let h = historian(&st)?;
    let tags = blocking(move || h.tags()).await?;
    ok(tags
        .into_iter()
        .map(|t| json!({"name": t.name, "first_ms": t.first_ms, "last_ms": t.last_ms}))
        .collect())
}

pub async fn query(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult {
    let h = historian(&st)?;
    let tag = param(&q, "tag")?.to_string();
    let (from, to) = (int(&q, "from", None)?, int(&q, "to", None)?);
    let points = int(&q, "points", Some(1000))?;
    let points = usize::try_from(points).map_err(|_| ApiError::unprocessable("`points` must be at least 1"))?;
    let t = tag.clone();
    let buckets = blocking(move || h.query(&t, from, to, points)).await?;
    ok(json!({
        "tag": tag, "from": from, "to": to,
        "buckets": buckets.iter().map(|b| json!([b.t_ms, b.min, b.max, b.first, b.last])).collect::<Vec<_>>(),
    }))
}

pub async fn csv(State(st): State<Arc<AppState>>, Query(q): Params) -> ApiResult {
    let h = historian(&st)?;
    let names: Vec<String> = param(&q, "tags")?
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    if names.is_empty() {
        return Err(ApiError::bad("`tags` lists no tag"));
    }
    let (from, to) = (int(&q, "from", None)?, int(&q, "to", None)?);
    let step = int(&q, "step", Some(1000))?;
    if step < 1 {
        return Err(ApiError::unprocessable("`step` must be at least 1 ms"));
    }
    if to >= from && (to - from) / step >= MAX_CSV_ROWS {
        return Err(ApiError::unprocessable(format!(
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
