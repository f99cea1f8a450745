//! `GET /api/tags`, `GET|PUT /api/tags/{name}`.

use super::audit::Actor;
use super::{Body, body, field};
use crate::error::{ApiError, ApiResult};
use crate::reply::{Force, TagInfo, TagReply};
use crate::state::AppState;
use crate::tags;
use axum::Json;
use axum::extract::{Path, State};
use std::sync::Arc;

pub async fn list(State(st): State<Arc<AppState>>) -> Json<Vec<TagInfo>> {
    Json(tags::all(&st.runtime.snapshot()))
}

pub async fn get(State(st): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<Json<TagReply>> {
    tags::one(&st.runtime.snapshot(), &name)
        .map(Json)
        .ok_or_else(|| ApiError::NotFound(format!("unknown tag `{name}`")))
}

/// `GET /api/tags/{name}/uses`: where the saved programs name it ("where is
/// this tag used?"), for the studio to jump to each place.
pub async fn uses(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
) -> ApiResult<Json<Vec<crate::reply::TagUse>>> {
    let p = st.project.lock().await;
    let Some(program) = p.program.as_ref() else {
        return Err(ApiError::Invalid(
            "the project does not compile: its uses are known once it does".into(),
        ));
    };
    crate::project::uses(&p.project, program, &name)
        .map(Json)
        .map_err(ApiError::NotFound)
}

/// Audited (`write`) by the control layer: the old value is the tag's in
/// the latest snapshot before the write.
pub async fn put(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    b: Body,
) -> ApiResult<Json<Force>> {
    let j = body(b)?;
    let value = st.control.write(&actor.control(), &name, field(&j, "value")?).await?;
    Ok(Json(Force { name, value }))
}
