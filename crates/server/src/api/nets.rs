//! `GET /api/nets/{name}/analysis[?max_states=N]`: the analysis of a net of
//! the project (docs/nets.md "Analysis"), the same JSON object as `alba
//! analyze --json`. `{name}` is the program as listed (`line.pnml`) or the
//! net's name (`line`). The exploration runs off the async executor and is
//! bounded (by default 1 000 000 states, at most 10 000 000), so a request
//! cannot run for ever.

use crate::error::{ApiError, ApiResult};
use crate::state::AppState;
use alba_compiler::net;
use alba_compiler::petri::net_name;
use alba_compiler::project::Language;
use axum::Json;
use axum::extract::{Path, Query, State};
use net::PtNet;
use net::analysis::{Options, analyze, to_json};
use serde_json::Value;
use std::collections::HashMap;
use std::sync::Arc;

/// States explored unless `max_states` says otherwise, and the most it may say.
pub const DEFAULT_MAX_STATES: usize = 1_000_000;
pub const MAX_STATES: usize = 10_000_000;

pub async fn analysis(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    Query(q): Query<HashMap<String, String>>,
) -> ApiResult<Json<Value>> {
    if let Some(k) = q.keys().find(|k| k.as_str() != "max_states") {
        return Err(ApiError::Malformed(format!(
            "unknown query parameter `{k}` (only `max_states`)"
        )));
    }
    let max_states = match q.get("max_states") {
        None => DEFAULT_MAX_STATES,
        Some(v) => match v.parse::<usize>() {
            Ok(n @ 1..=MAX_STATES) => n,
            _ => {
                return Err(ApiError::Invalid(format!(
                    "`max_states` is 1 to {MAX_STATES}, not `{v}`"
                )));
            }
        },
    };
    let (file, text) = {
        let p = st.project.lock().await;
        let src = p
            .project
            .programs
            .iter()
            .filter(|s| s.language == Language::Net)
            .find(|s| s.name.eq_ignore_ascii_case(&name) || net_name(&s.name).eq_ignore_ascii_case(&name))
            .ok_or_else(|| ApiError::NotFound(format!("no net `{name}` in the project")))?;
        (src.file, p.project.files.text(src.file).to_string())
    };
    let json = tokio::task::spawn_blocking(move || -> Result<Value, String> {
        let (net, diags) = net::load(file, &text);
        let errors: Vec<_> = diags.iter().filter(|d| !net::is_warning(d)).collect();
        let net = match net {
            Some(n) if errors.is_empty() => n,
            _ => {
                let first = errors
                    .first()
                    .map_or_else(|| "it does not load".to_string(), |d| d.message.clone());
                return Err(format!("the net does not load: {first}"));
            }
        };
        let pt = PtNet::from_net(&net);
        let options = Options {
            max_states,
            ..Options::default()
        };
        Ok(to_json(&pt, &analyze(&pt, &options, &|| false)))
    })
    .await
    .map_err(|e| ApiError::Internal(e.to_string()))?
    .map_err(ApiError::Invalid)?;
    Ok(Json(json))
}
