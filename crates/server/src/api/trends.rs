//! `GET|PUT /api/trends`: the studio's trend set (pens, axes, scales, live
//! window), kept in the project as `trends.json` so that every studio opens
//! the same trend, saved atomically and checked like every project file.

use super::audit::{Actor, audited, json_text};
use super::{Body, body};
use crate::error::{ApiError, ApiResult};
use crate::reply::{TrendPen, TrendSet};
use crate::state::AppState;
use alba_control::audit::Action;
use alba_ir::Target;
use axum::Json;
use axum::extract::State;
use std::sync::Arc;

const FILE: &str = "trends.json";
const MAX_PENS: usize = 32;

fn default_set() -> TrendSet {
    TrendSet {
        version: 1,
        window_ms: 60_000,
        pens: Vec::new(),
    }
}

/// The problems of `set` against the running program's tags (empty: valid).
fn check(set: &TrendSet, layout: &alba_ir::Layout) -> Vec<String> {
    let mut e = Vec::new();
    if set.version != 1 {
        e.push(format!("version {} is not supported (1 is)", set.version));
    }
    if !(1_000..=7 * 86_400_000).contains(&set.window_ms) {
        e.push(format!(
            "window_ms = {} is out of range (1000 to 604800000)",
            set.window_ms
        ));
    }
    if set.pens.len() > MAX_PENS {
        e.push(format!("{} pens: at most {MAX_PENS}", set.pens.len()));
    }
    for (
        k,
        TrendPen {
            tag,
            node,
            axis,
            min,
            max,
        },
    ) in set.pens.iter().enumerate()
    {
        let at = match node {
            Some(n) => format!("pens[{k}] ({tag}@{n})"),
            None => format!("pens[{k}] ({tag})"),
        };
        match node {
            // Another node's tag: its program is not this one (its history tells what it recorded).
            Some(n) if n.is_empty() || tag.is_empty() => {
                e.push(format!("{at}: a pen of another node needs its tag and node"))
            }
            Some(_) => {}
            None => match layout.resolve(tag) {
                Ok(Target::Value { .. }) => {}
                Ok(_) => e.push(format!("{at}: a structure cannot be plotted: pick a member")),
                Err(err) => e.push(format!("{at}: {err}")),
            },
        }
        if !(1..=4).contains(axis) {
            e.push(format!("{at}: axis {axis} is out of range (1 to 4)"));
        }
        match (min, max) {
            (Some(a), Some(b)) if !(a.is_finite() && b.is_finite() && a < b) => {
                e.push(format!("{at}: min {a} must be below max {b}"))
            }
            (Some(_), None) | (None, Some(_)) => e.push(format!("{at}: give both min and max, or neither")),
            _ => {}
        }
        if set.pens[..k]
            .iter()
            .any(|p| p.tag.eq_ignore_ascii_case(tag) && p.node == *node)
        {
            e.push(format!("{at}: the tag is plotted twice"));
        }
    }
    e
}

/// The saved set: the default when there is none; a damaged file is an
/// error with its line and column (it is not replaced behind the user's back).
pub async fn get(State(st): State<Arc<AppState>>) -> ApiResult<Json<TrendSet>> {
    let path = st.project.lock().await.project.dir.join(FILE);
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Json(default_set())),
        Err(e) => return Err(ApiError::Internal(format!("cannot read {FILE}: {e}"))),
    };
    let set: TrendSet = serde_json::from_str(&text)
        .map_err(|e| ApiError::Invalid(format!("{FILE}:{}:{}: {e}", e.line(), e.column())))?;
    Ok(Json(set))
}

/// Audited (`save_trends`): checked against the running program's tags, then
/// written atomically.
pub async fn put(State(st): State<Arc<AppState>>, actor: Actor, b: Body) -> ApiResult<Json<TrendSet>> {
    let j = body(b)?;
    let set: TrendSet = serde_json::from_value(j).map_err(|e| ApiError::Malformed(format!("not a trend set: {e}")))?;
    let problems = check(&set, &st.runtime.snapshot().program.layout);
    if !problems.is_empty() {
        return Err(ApiError::Invalid(problems.join("; ")));
    }
    let path = st.project.lock().await.project.dir.join(FILE);
    let pens: Vec<String> = set
        .pens
        .iter()
        .map(|p| match &p.node {
            Some(n) => format!("{}@{n}", p.tag),
            None => p.tag.clone(),
        })
        .collect();
    let entry = alba_control::audit::Entry {
        target: Some(FILE.into()),
        new: Some(json_text(&serde_json::json!(pens))),
        ..actor.entry(Action::SaveTrends)
    };
    let text = serde_json::to_string_pretty(&set).map_err(|e| ApiError::Internal(e.to_string()))?;
    audited(&st, entry, async {
        alba_ir::model::fsutil::write_atomic(&path, |w| {
            w.write_all(text.as_bytes())?;
            w.write_all(b"\n")
        })
        .map_err(|e| ApiError::Internal(format!("cannot save {FILE}: {e}")))
    })
    .await?;
    Ok(Json(set))
}
