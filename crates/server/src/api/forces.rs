//! `GET|DELETE /api/forces`, `PUT|DELETE /api/forces/{name}`.

use super::audit::{Actor, audited, audited_safety, json_text};
use super::{Body, body, field};
use crate::error::{ApiError, ApiResult};
use crate::reply::Force;
use crate::state::AppState;
use alba_audit::{Action, Entry};
use alba_ir::Target;
use alba_runtime::json::{from_json, to_json};
use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use std::sync::Arc;

/// The forces in effect in `s`.
pub fn of(s: &alba_runtime::Snapshot) -> Vec<Force> {
    s.forces
        .iter()
        .map(|f| Force {
            name: f.name.clone(),
            value: to_json(f.value),
        })
        .collect()
}

pub async fn list(State(st): State<Arc<AppState>>) -> Json<Vec<Force>> {
    Json(of(&st.runtime.snapshot()))
}

/// The forced value of `name` in `s`, if it is forced.
fn forced(s: &alba_runtime::Snapshot, name: &str) -> Option<alba_ir::model::Value> {
    s.forces
        .iter()
        .find(|f| f.name.eq_ignore_ascii_case(name))
        .map(|f| f.value)
}

/// Audited (`force`): the old value is the former force, else the live value.
pub async fn put(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    b: Body,
) -> ApiResult<Json<Force>> {
    let j = body(b)?;
    let s = st.runtime.snapshot();
    let place = match s.program.layout.resolve(&name) {
        Ok(Target::Value { place, .. }) => place,
        Ok(_) => return Err(ApiError::Invalid(format!("`{name}` is a structure, not I/O"))),
        Err(e) => return Err(ApiError::NotFound(e.to_string())),
    };
    if alba_runtime::io_kind(&s.program.layout, place).is_none() {
        return Err(ApiError::Invalid(format!(
            "`{name}` is not an input or an output: only I/O can be forced (write internal tags instead)"
        )));
    }
    let v =
        from_json(field(&j, "value")?, place.data_type()).map_err(|e| ApiError::Invalid(format!("`{name}`: {e}")))?;
    let entry = Entry {
        target: Some(name.clone()),
        old: Some(json_text(&to_json(forced(&s, &name).unwrap_or_else(|| s.read(place))))),
        new: Some(json_text(&to_json(v))),
        ..actor.entry(Action::Force)
    };
    audited(&st, entry, async {
        Ok(st.runtime.force(name.clone(), place, v).await?)
    })
    .await?;
    Ok(Json(Force {
        name,
        value: to_json(v),
    }))
}

/// Audited (`unforce`): the old value is the forced one.
pub async fn delete(State(st): State<Arc<AppState>>, actor: Actor, Path(name): Path<String>) -> ApiResult<StatusCode> {
    let s = st.runtime.snapshot();
    let Some(value) = forced(&s, &name) else {
        return Err(ApiError::NotFound(format!("`{name}` is not forced")));
    };
    let entry = Entry {
        target: Some(name.clone()),
        old: Some(json_text(&to_json(value))),
        ..actor.entry(Action::Unforce)
    };
    audited_safety(&st, entry, async { Ok(st.runtime.unforce(Some(name)).await?) }).await?;
    Ok(StatusCode::NO_CONTENT)
}

/// Audited (`unforce` without a target): the old value is an object of
/// every force.
pub async fn delete_all(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<StatusCode> {
    let s = st.runtime.snapshot();
    let all: serde_json::Map<String, serde_json::Value> =
        s.forces.iter().map(|f| (f.name.clone(), to_json(f.value))).collect();
    let entry = Entry {
        old: Some(json_text(&serde_json::Value::Object(all))),
        ..actor.entry(Action::Unforce)
    };
    audited_safety(&st, entry, async { Ok(st.runtime.unforce(None).await?) }).await?;
    Ok(StatusCode::NO_CONTENT)
}
