//! `/api/hardware` (docs/api.md "Hardware"; SPEC §10.6): the board and pin
//! map, the serial ports, firmware builds, byte-code downloads as jobs.
//! The work is alba-app's ([`crate::hardware::Hardware`]); here: the
//! requests, the roles (changes need `engineer`) and the audit rows
//! (`save_board`, `download`, `upload`; `attach` and `detach` are the
//! control layer's).

use super::audit::{self, Actor};
use super::{Body, body, field};
use crate::error::{ApiError, ApiResult};
use crate::hardware::{AttachMode, BoardChange, Hardware, HardwareError};
use crate::project::EditError;
use crate::reply::{BoardIdentity, BuildSizes, HardwareJob, HardwareView, JobStarted, JobState, Verified};
use crate::state::AppState;
use alba_control::audit::{Action, Entry};
use axum::Json;
use axum::extract::{Path, State};
use serde_json::Value;
use std::sync::Arc;
use std::time::Duration;

impl From<HardwareError> for ApiError {
    fn from(e: HardwareError) -> ApiError {
        match e {
            HardwareError::Malformed(m) => ApiError::Malformed(m),
            HardwareError::NotFound(m) => ApiError::NotFound(m),
            HardwareError::DoesNotBuild(diagnostics) => ApiError::Edit(EditError::DoesNotCompile { diagnostics }),
            HardwareError::Busy(m) => ApiError::Busy(m),
            HardwareError::Port(m) => ApiError::Upstream(m),
            HardwareError::Failed(m) => ApiError::Internal(m),
            HardwareError::Refused(r) => match std::sync::Arc::try_unwrap(r) {
                Ok(r) => ApiError::from(r),
                Err(r) => ApiError::Internal(r.to_string()),
            },
            HardwareError::Conflict(m) => ApiError::Conflict(m),
        }
    }
}

fn service(st: &AppState) -> ApiResult<Arc<dyn Hardware>> {
    st.hardware
        .get()
        .cloned()
        .ok_or_else(|| ApiError::NotFound("this server has no hardware service".into()))
}

/// Runs a blocking call of the service off the async workers.
async fn blocking<T: Send + 'static>(f: impl FnOnce() -> Result<T, HardwareError> + Send + 'static) -> ApiResult<T> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ApiError::Internal(format!("hardware: {e}")))?
        .map_err(ApiError::from)
}

fn string(j: &Value, name: &str) -> ApiResult<String> {
    field(j, name)?
        .as_str()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .ok_or_else(|| ApiError::Malformed(format!("`{name}` must be a non-empty string")))
}

fn pins(j: &Value, name: &str) -> ApiResult<Option<Vec<String>>> {
    match j.get(name) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::Array(a)) => a
            .iter()
            .map(|p| {
                p.as_str()
                    .map(str::to_string)
                    .ok_or_else(|| ApiError::Malformed(format!("`{name}` must be a list of pin names")))
            })
            .collect::<ApiResult<Vec<_>>>()
            .map(Some),
        Some(_) => Err(ApiError::Malformed(format!("`{name}` must be a list of pin names"))),
    }
}

/// `GET /api/hardware`.
pub async fn get(State(st): State<Arc<AppState>>) -> ApiResult<Json<HardwareView>> {
    let hw = service(&st)?;
    Ok(Json(blocking(move || hw.view()).await?))
}

/// `PUT /api/hardware/board` `{"board", "pinmap", "di"?, "do"?, "ai"?, "ao"?, "port"?}`:
/// `[board]` checked and saved atomically (audited `save_board`); 422 with
/// the diagnostics, nothing saved, when it does not check.
pub async fn put_board(State(st): State<Arc<AppState>>, actor: Actor, b: Body) -> ApiResult<Json<HardwareView>> {
    let j = body(b)?;
    let change = BoardChange {
        board: string(&j, "board")?,
        pinmap: match j.get("pinmap") {
            None | Some(Value::Null) => "aurora".into(),
            Some(_) => string(&j, "pinmap")?,
        },
        di: pins(&j, "di")?,
        r#do: pins(&j, "do")?,
        ai: pins(&j, "ai")?,
        ao: pins(&j, "ao")?,
        port: match j.get("port") {
            None | Some(Value::Null) => None,
            Some(Value::String(s)) if s.trim().is_empty() => None,
            Some(_) => Some(string(&j, "port")?),
        },
    };
    let hw = service(&st)?;
    let mut detail = format!("model = {}, pinmap = {}", change.board, change.pinmap);
    for (k, v) in [
        ("di", &change.di),
        ("do", &change.r#do),
        ("ai", &change.ai),
        ("ao", &change.ao),
    ] {
        if let Some(v) = v {
            detail.push_str(&format!(", {k} = [{}]", v.join(", ")));
        }
    }
    if let Some(p) = &change.port {
        detail.push_str(&format!(", port = {p}"));
    }
    let entry = Entry {
        target: Some("alba.toml [board]".into()),
        detail: Some(detail),
        ..actor.entry(Action::SaveBoard)
    };
    // Serialised with the other project edits.
    let _project = st.project.lock().await;
    let view = audit::audited(&st, entry, blocking(move || hw.save_board(&change))).await?;
    Ok(Json(view))
}

/// `POST /api/hardware/board/undo`: `[board]` as it was before the last
/// save (audited `save_board`, detail `undo`); `409` with nothing to undo.
pub async fn undo_board(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<HardwareView>> {
    let hw = service(&st)?;
    let entry = Entry {
        target: Some("alba.toml [board]".into()),
        detail: Some("undo: [board] as it was before the last save".into()),
        ..actor.entry(Action::SaveBoard)
    };
    let _project = st.project.lock().await;
    let view = audit::audited(&st, entry, blocking(move || hw.undo_board())).await?;
    Ok(Json(view))
}

/// `POST /api/hardware/build` `{"board", "kind": "sketch"|"interpreter"}`.
pub async fn build(State(st): State<Arc<AppState>>, b: Body) -> ApiResult<Json<BuildSizes>> {
    let j = body(b)?;
    let (board, kind) = (string(&j, "board")?, string(&j, "kind")?);
    let hw = service(&st)?;
    Ok(Json(blocking(move || hw.build(&board, &kind)).await?))
}

/// `POST /api/hardware/download` `{"port"}` → `{"job"}`: audited
/// `download`, the row's outcome set when the job ends.
pub async fn download(State(st): State<Arc<AppState>>, actor: Actor, b: Body) -> ApiResult<Json<JobStarted>> {
    let j = body(b)?;
    let port = string(&j, "port")?;
    let entry = Entry {
        target: Some(port.clone()),
        detail: Some("the project's byte code".into()),
        ..actor.entry(Action::Download)
    };
    start_job(&st, entry, move |hw| hw.download(&port)).await
}

/// `POST /api/hardware/upload` `{"port", "board", "kind": "sketch"|"interpreter"|"controller"}`
/// → `{"job"}`: the firmware built and uploaded with avrdude; audited
/// `upload`, the row's outcome set when the job ends.
pub async fn upload(State(st): State<Arc<AppState>>, actor: Actor, b: Body) -> ApiResult<Json<JobStarted>> {
    let j = body(b)?;
    let (port, board, kind) = (string(&j, "port")?, string(&j, "board")?, string(&j, "kind")?);
    let entry = Entry {
        target: Some(port.clone()),
        detail: Some(format!("{kind} for {board}")),
        ..actor.entry(Action::Upload)
    };
    start_job(&st, entry, move |hw| hw.upload(&port, &board, &kind)).await
}

/// Starts a job under its audit row `entry`, whose outcome is the job's.
async fn start_job(
    st: &Arc<AppState>,
    entry: Entry,
    start: impl FnOnce(&dyn Hardware) -> Result<String, HardwareError> + Send + 'static,
) -> ApiResult<Json<JobStarted>> {
    let hw = service(st)?;
    let row = st.control.begin(entry).await?;
    let started = {
        let hw = hw.clone();
        tokio::task::spawn_blocking(move || start(hw.as_ref()))
            .await
            .map_err(|e| HardwareError::Failed(format!("hardware: {e}")))
            .and_then(|r| r)
    };
    let job = match started {
        Ok(job) => job,
        Err(e) => {
            st.control.finish(row, &Err::<(), _>(ApiError::from(e.clone()))).await;
            return Err(e.into());
        }
    };
    // The row's outcome is the job's.
    let (st2, id) = (st.clone(), job.clone());
    tokio::spawn(async move {
        loop {
            tokio::time::sleep(Duration::from_millis(200)).await;
            let result: ApiResult<()> = match hw.job(&id) {
                None => Err(ApiError::Internal("the job was forgotten".into())),
                Some(j) if j.state == JobState::Running => continue,
                Some(j) if j.state == JobState::Done => Ok(()),
                Some(j) => Err(ApiError::Invalid(j.message)),
            };
            st2.control.finish(row, &result).await;
            break;
        }
    });
    Ok(Json(JobStarted { job }))
}

/// `GET /api/hardware/jobs/{id}`.
pub async fn job(State(st): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<Json<HardwareJob>> {
    let hw = service(&st)?;
    hw.job(&id)
        .map(Json)
        .ok_or_else(|| ApiError::NotFound(format!("no hardware job `{id}`")))
}

/// `POST /api/hardware/identify` `{"port"}`: what answers there.
pub async fn identify(State(st): State<Arc<AppState>>, b: Body) -> ApiResult<Json<BoardIdentity>> {
    let j = body(b)?;
    let port = string(&j, "port")?;
    let hw = service(&st)?;
    Ok(Json(blocking(move || hw.identify(&port)).await?))
}

/// `POST /api/hardware/verify` `{"port"}`: does the board run the project's program?
pub async fn verify(State(st): State<Arc<AppState>>, b: Body) -> ApiResult<Json<Verified>> {
    let j = body(b)?;
    let port = string(&j, "port")?;
    let hw = service(&st)?;
    Ok(Json(blocking(move || hw.verify(&port)).await?))
}

/// `POST /api/hardware/jobs/{id}/cancel`: the job asked to stop (its state
/// turns `failed`, "cancelled …", once the board has dropped the records).
pub async fn cancel(State(st): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<Json<HardwareJob>> {
    let hw = service(&st)?;
    hw.cancel(&id)
        .map(Json)
        .ok_or_else(|| ApiError::NotFound(format!("no hardware job `{id}`")))
}

/// `POST /api/hardware/attach` `{"port", "mode": "controller"|"monitor"}`:
/// the board as the running PLC's I/O, without restarting it (audited
/// `attach`, by the control layer); the view after, with `attached`.
pub async fn attach(State(st): State<Arc<AppState>>, actor: Actor, b: Body) -> ApiResult<Json<HardwareView>> {
    let j = body(b)?;
    let port = string(&j, "port")?;
    let mode = string(&j, "mode")?;
    let mode = AttachMode::parse(&mode)
        .ok_or_else(|| ApiError::Malformed(format!("`mode` is `controller` or `monitor`, not `{mode}`")))?;
    let hw = service(&st)?;
    hw.attach(&st.control, &actor.control(), &port, mode).await?;
    Ok(Json(blocking(move || hw.view()).await?))
}

/// `POST /api/hardware/detach`: the project's own I/O back (audited `detach`).
pub async fn detach(State(st): State<Arc<AppState>>, actor: Actor) -> ApiResult<Json<HardwareView>> {
    let hw = service(&st)?;
    hw.detach(&st.control, &actor.control()).await?;
    Ok(Json(blocking(move || hw.view()).await?))
}
