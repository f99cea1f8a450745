//! `GET /api/tags`, `GET|PUT /api/tags/{name}`.

use super::audit::{Actor, audited, json_text};
use super::{Body, body, field};
use crate::error::{ApiError, ApiResult};
use crate::reply::{Force, TagInfo, TagReply};
use crate::state::AppState;
use crate::tags;
use alba_ir::{Access, Target};
use alba_runtime::Snapshot;
use alba_runtime::json::{from_json, to_json};
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

/// Resolves `name` for a write, or says why it cannot be written.
fn writable(s: &Snapshot, name: &str) -> Result<alba_ir::Place, ApiError> {
    match s.program.layout.resolve(name) {
        Err(e) => Err(ApiError::NotFound(e.to_string())),
        Ok(Target::Timer(_) | Target::Counter(_)) => Err(ApiError::Invalid(format!(
            "`{name}` is a structure: write one of its members (`{name}.PRE`, `{name}.ACC`)"
        ))),
        Ok(Target::Pid(_)) => Err(ApiError::Invalid(format!(
            "`{name}` is a structure: write one of its members (`{name}.SP`, `{name}.KP`, `{name}.MAN`)"
        ))),
        Ok(Target::Value { place, access }) => match access {
            Access::ReadWrite => Ok(place),
            Access::Input => Err(ApiError::Invalid(format!(
                "`{name}` is an input, written by the I/O: force it instead"
            ))),
            Access::ReadOnly | Access::Output => Err(ApiError::Invalid(format!("`{name}` is read-only"))),
        },
    }
}

/// Audited (`write`): the old value is the tag's in the latest snapshot
/// before the write.
pub async fn put(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    b: Body,
) -> ApiResult<Json<Force>> {
    let j = body(b)?;
    let value = write_tag(&st, actor.entry(alba_audit::Action::Write), &name, field(&j, "value")?).await?;
    Ok(Json(Force { name, value }))
}

/// Writes `name` = `value` (JSON) with the API's rules (inputs, read-only
/// members and structures refused; the value checked against the type)
/// under the audit row `entry` (its target, old and new values are filled
/// here); the value the tag then holds. `PUT /api/tags/{name}` and the MQTT
/// `set` topic (alba-app) both write through here.
pub async fn write_tag(
    st: &AppState,
    entry: alba_audit::Entry,
    name: &str,
    value: &serde_json::Value,
) -> ApiResult<serde_json::Value> {
    let s = st.runtime.snapshot();
    let place = writable(&s, name)?;
    let v = from_json(value, place.data_type()).map_err(|e| ApiError::Invalid(format!("`{name}`: {e}")))?;
    // A timer's preset is a duration: never negative (the instruction would
    // fault on it every scan).
    if let Some((base, member)) = name.rsplit_once('.')
        && member.eq_ignore_ascii_case("PRE")
        && matches!(s.program.layout.resolve(base), Ok(Target::Timer(_)))
        && v.as_i64() < 0
    {
        return Err(ApiError::Invalid(format!(
            "`{name}` is a timer's preset: it cannot be negative"
        )));
    }
    let entry = alba_audit::Entry {
        target: Some(name.to_string()),
        old: Some(json_text(&to_json(s.read(place)))),
        new: Some(json_text(&to_json(v))),
        ..entry
    };
    audited(st, entry, async { Ok(st.runtime.write(place, v).await?) }).await?;
    Ok(to_json(st.runtime.snapshot().read(place)))
}
