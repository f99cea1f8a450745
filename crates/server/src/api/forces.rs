//! `GET|DELETE /api/forces`, `PUT|DELETE /api/forces/{name}`.

use super::{Body, body, field};
use crate::error::{ApiError, ApiResult};
use crate::reply::Force;
use crate::state::AppState;
use alba_ir::Target;
use alba_runtime::json::{from_json, to_json};
use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use std::sync::Arc;

pub async fn list(State(st): State<Arc<AppState>>) -> Json<Vec<Force>> {
    let s = st.runtime.snapshot();
    Json(
        s.forces
            .iter()
            .map(|f| Force {
                name: f.name.clone(),
                value: to_json(f.value),
            })
            .collect(),
    )
}

pub async fn put(State(st): State<Arc<AppState>>, Path(name): Path<String>, b: Body) -> ApiResult<Json<Force>> {
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
    st.runtime.force(name.clone(), place, v).await?;
    Ok(Json(Force {
        name,
        value: to_json(v),
    }))
}

pub async fn delete(State(st): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<StatusCode> {
    let s = st.runtime.snapshot();
    if !s.forces.iter().any(|f| f.name.eq_ignore_ascii_case(&name)) {
        return Err(ApiError::NotFound(format!("`{name}` is not forced")));
    }
    st.runtime.unforce(Some(name)).await?;
    Ok(StatusCode::NO_CONTENT)
}

pub async fn delete_all(State(st): State<Arc<AppState>>) -> ApiResult<StatusCode> {
    st.runtime.unforce(None).await?;
    Ok(StatusCode::NO_CONTENT)
}
