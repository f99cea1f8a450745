//! The project edit path: `GET /api/programs`, `GET|PUT
//! /api/programs/{name}`, `POST /api/check/{name}`, `GET|PUT /api/tags.csv`.
//! Edits are compiled in full before anything is saved, then the control
//! layer (`Control::edit`: the role, the audit row) has them saved
//! atomically and applied online by swapping the program between two
//! scans; they are announced on `AppState::edits`.

use super::audit::Actor;
use super::{Body, body, field};
use crate::error::{ApiError, ApiResult};
use crate::project::{self, EditError};
use crate::reply::{Checked, Program, ProgramRef, Saved};
use crate::state::{AppState, Edited};
use alba_control::audit::{Action, Entry};
use axum::Json;
use axum::body::Bytes;
use axum::extract::{Path, State};
use axum::http::header;
use axum::response::IntoResponse;
use serde_json::Value;
use std::sync::Arc;

/// The program text of a check or save request.
fn text_field(j: &Value) -> Result<&str, ApiError> {
    field(j, "text")?
        .as_str()
        .ok_or_else(|| ApiError::Malformed("`text` must be a string".into()))
}

pub async fn list(State(st): State<Arc<AppState>>) -> Json<Vec<ProgramRef>> {
    let p = st.project.lock().await;
    Json(
        p.project
            .programs
            .iter()
            .map(|s| ProgramRef {
                name: s.name.clone(),
                language: project::language(s.language),
                plant: s.plant,
            })
            .collect(),
    )
}

pub async fn get(State(st): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<Json<Program>> {
    let p = st.project.lock().await;
    Ok(Json(project::program_json(
        &p.project,
        p.program.as_ref(),
        &name,
        &p.diagnostics,
    )?))
}

/// Compiles the project with `edit`; the diagnostics if it does not compile.
/// Checks `name` with `text` in place of its program. The project is taken
/// under its lock only to be copied: the compile (seconds for a huge net)
/// runs on a blocking thread, holding up neither edits nor the async workers.
async fn check_program(st: &AppState, name: &str, text: &str) -> ApiResult<project::Compiled> {
    let current = st.project.lock().await.project.clone();
    let (name, text) = (name.to_string(), text.to_string());
    let c = tokio::task::spawn_blocking(move || {
        project::compile_with(
            &current,
            Some(&project::Edit::Program {
                name: &name,
                text: &text,
            }),
        )
    })
    .await
    .map_err(|e| ApiError::Internal(format!("check: {e}")))??;
    if c.program.is_none() {
        return Err(EditError::does_not_compile(&c).into());
    }
    Ok(c)
}

pub async fn check(State(st): State<Arc<AppState>>, Path(name): Path<String>, b: Body) -> ApiResult<Json<Checked>> {
    let j = body(b)?;
    let c = check_program(&st, &name, text_field(&j)?).await?;
    let view = project::program_json(&c.project, c.program.as_ref(), &name, &c.diagnostics)?;
    Ok(Json(Checked {
        diagnostics: Vec::new(),
        rungs: view.rungs,
        lines: view.lines,
    }))
}

/// Saves a checked edit and, if asked while running, applies it online.
/// Audited once it compiles (`save_program`, `online_edit` or `save_tags`,
/// with the diff summary as detail): the row is written before the file.
async fn apply(st: &AppState, actor: &Actor, edit: project::Edit<'_>, online: bool) -> ApiResult<Saved> {
    // The lock is held from compile to swap: edits never interleave.
    let mut p = st.project.lock().await;
    let c = project::compile_with(&p.project, Some(&edit))?;
    let Some(program) = c.program.clone() else {
        return Err(EditError::does_not_compile(&c).into());
    };
    let (action, target) = match &edit {
        project::Edit::Program { name, .. } => (
            if online {
                Action::OnlineEdit
            } else {
                Action::SaveProgram
            },
            project::find(&p.project, name)?.name.clone(),
        ),
        project::Edit::Tags(_) => (Action::SaveTags, "tags.csv".to_string()),
    };
    let entry = Entry {
        target: Some(target),
        detail: Some(project::edit_summary(&p.project, &edit)?),
        ..actor.entry(action)
    };
    let program = Arc::new(program);
    let swap = online.then(|| program.clone());
    st.control
        .edit(
            &actor.control(),
            entry,
            || Ok::<_, ApiError>(project::save(&c, &edit)?),
            swap,
        )
        .await?;
    *p = c;
    let file = match edit {
        project::Edit::Program { name, .. } => {
            project::find(&p.project, name).map_or(name.to_string(), |s| s.name.clone())
        }
        project::Edit::Tags(_) => "tags.csv".to_string(),
    };
    // Nobody listening is fine.
    let _ = st.edits.send(Edited {
        file,
        program,
        applied: online,
    });
    Ok(Saved {
        diagnostics: Vec::new(),
        applied: online,
    })
}

pub async fn put(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    b: Body,
) -> ApiResult<Json<Saved>> {
    let j = body(b)?;
    let online = j.get("online").and_then(Value::as_bool).unwrap_or(false);
    let edit = project::Edit::Program {
        name: &name,
        text: text_field(&j)?,
    };
    Ok(Json(apply(&st, &actor, edit, online).await?))
}

pub async fn get_tags_csv(State(st): State<Arc<AppState>>) -> impl IntoResponse {
    let p = st.project.lock().await;
    let text = p
        .project
        .tags_file
        .map(|f| p.project.files.text(f).to_string())
        .unwrap_or_default();
    ([(header::CONTENT_TYPE, "text/csv; charset=utf-8")], text)
}

pub async fn put_tags_csv(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    bytes: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<Json<Saved>> {
    let text = super::text_body(bytes, "tags.csv")?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    Ok(Json(apply(&st, &actor, project::Edit::Tags(text), true).await?))
}
