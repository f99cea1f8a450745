//! `GET|DELETE /api/forces`, `PUT|DELETE /api/forces/{name}`: the control
//! layer forces and removes forces (its rules, its audit rows); these
//! handlers only translate.

use super::audit::Actor;
use super::{Body, body, field};
use crate::error::ApiResult;
use crate::reply::Force;
use crate::state::AppState;
use alba_control::runtime::json::to_json;
use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use std::sync::Arc;

/// The forces in effect in `s`.
pub fn of(s: &alba_control::runtime::Snapshot) -> Vec<Force> {
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

/// Audited (`force`): the old value is the former force, else the live value.
pub async fn put(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    b: Body,
) -> ApiResult<Json<Force>> {
    let j = body(b)?;
    let v = st.control.force(&actor.control(), &name, field(&j, "value")?).await?;
    Ok(Json(Force {
        name,
        value: to_json(v),
    }))
}

/// Audited (`unforce`): the old value is the forced one.
pub async fn delete(State(st): State<Arc<AppState>>, actor: Actor, Path(name): Path<String>) -> ApiResult<StatusCode> {
    st.control.unforce(&actor.control(), Some(&name)).await?;
    Ok(StatusCode::NO_CONTENT)
}

/// Audited (`unforce` without a target): the old value is an object of
/// every force.
pub async fn delete_all(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<StatusCode> {
    st.control.unforce(&actor.control(), None).await?;
    Ok(StatusCode::NO_CONTENT)
}
