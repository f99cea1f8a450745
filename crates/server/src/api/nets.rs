//! `GET /api/nets/{name}/analysis[?max_states=N]`: the analysis of a net of
//! the project (docs/nets.md "Analysis"), the same JSON object as `alba
//! analyze --json`. `{name}` is the program as listed (`line.pnml`) or the
//! net's name (`line`). The exploration runs off the async executor and is
//! bounded (by default 1 000 000 states, at most 10 000 000), so a request
//! cannot run for ever.
//!
//! `POST /api/nets/{name}/reset`: writes the net's initial marking at one
//! scan boundary (docs/nets.md "Live view").

use super::audit::{Actor, audited, json_text};
use crate::error::{ApiError, ApiResult};
use crate::reply::{MarkingValue, NetReset};
use crate::state::AppState;
use alba_audit::{Action, Entry};
use alba_compiler::diag::FileId;
use alba_compiler::net;
use alba_compiler::petri::net_name;
use alba_compiler::project::Language;
use alba_ir::Target;
use alba_ir::model::Value as PlcValue;
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
    let (_, file, text) = find(&st, &name).await?;
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

/// The net program `name` names (as listed, or the net's name): its listed
/// name, file and saved text.
async fn find(st: &AppState, name: &str) -> ApiResult<(String, FileId, String)> {
    let p = st.project.lock().await;
    let src = p
        .project
        .programs
        .iter()
        .filter(|s| s.language == Language::Net)
        .find(|s| s.name.eq_ignore_ascii_case(name) || net_name(&s.name).eq_ignore_ascii_case(name))
        .ok_or_else(|| ApiError::NotFound(format!("no net `{name}` in the project")))?;
    Ok((src.name.clone(), src.file, p.project.files.text(src.file).to_string()))
}

/// The initial marking of a net: (marking tag, value) for each place, and in
/// normal mode each transition (0), as the net's first scan loads it.
fn initial_marking(program: &str, net: &net::Net) -> Vec<(String, i32)> {
    let name = net_name(program);
    let tag = |id: &str| alba_compiler::petri::marking_tag(&name, id);
    let normal = net.mode == net::Mode::Normal;
    let mut out: Vec<(String, i32)> = net
        .places
        .iter()
        .map(|p| {
            let m = i32::try_from(p.initial).unwrap_or(i32::MAX);
            (tag(&p.id), if normal { m.min(1) } else { m })
        })
        .collect();
    if normal {
        out.extend(net.transitions.iter().map(|t| (tag(&t.id), 0)));
    }
    out
}

/// Audited (`reset_marking`, target the program, new the marking): every
/// marking tag of the saved net gets its initial value, all at one scan
/// boundary. `422` when the net does not load or the running program has not
/// got its marking tags (the net saved but not applied).
pub async fn reset(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    actor: Actor,
) -> ApiResult<Json<NetReset>> {
    let (program, file, text) = find(&st, &name).await?;
    let (net, diags) = net::load(file, &text);
    let Some(net) = net.filter(|_| diags.iter().all(net::is_warning)) else {
        let first = diags
            .iter()
            .find(|d| !net::is_warning(d))
            .map_or_else(|| "it does not load".to_string(), |d| d.message.clone());
        return Err(ApiError::Invalid(format!("the net does not load: {first}")));
    };
    let marking = initial_marking(&program, &net);
    let snap = st.runtime.snapshot();
    let mut writes = Vec::with_capacity(marking.len());
    for (tag, v) in &marking {
        match snap.program.layout.resolve(tag) {
            Ok(Target::Value { place, .. }) => writes.push((place, PlcValue::Dint(*v))),
            _ => {
                return Err(ApiError::Invalid(format!(
                    "the running program has no marking tag `{tag}`: save the net and apply it online first"
                )));
            }
        }
    }
    let reply = NetReset {
        program: program.clone(),
        marking: marking
            .into_iter()
            .map(|(tag, value)| MarkingValue { tag, value })
            .collect(),
    };
    let e = Entry {
        target: Some(program),
        new: serde_json::to_value(&reply.marking).ok().map(|v| json_text(&v)),
        ..actor.entry(Action::ResetMarking)
    };
    audited(&st, e, async { Ok(st.runtime.write_many(writes).await?) }).await?;
    Ok(Json(reply))
}
