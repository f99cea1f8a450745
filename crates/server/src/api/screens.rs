//! `GET /api/screens`, `GET|PUT /api/screens/{name}`: the project's SCADA
//! screens (`hmi/<name>.json`, issue 17), checked against the running
//! program's tags with located errors (E141) and saved atomically;
//! `POST /api/screens/{name}/check`: the same checks, nothing saved (the
//! designer's problems, as they are made and fixed).
//! `GET /api/symbols`, `GET|PUT /api/symbols/{name}`: the user's own symbols
//! (`hmi/symbols/<name>.json`), groups of elements saved from the designer in
//! the same format and checked the same way.

use super::audit::{Actor, audited, json_text};
use crate::error::{ApiError, ApiResult};
use crate::project::{EditError, diagnostics_json};
use crate::state::AppState;
use alba_compiler::diag::Files;
use alba_compiler::project::hmi::{self, Screen};
use alba_control::audit::Action;
use axum::Json;
use axum::body::Bytes;
use axum::extract::{Path, State};
use serde_json::{Value as JsonValue, json};
use std::sync::Arc;

/// Where screens or symbols live in the project.
#[derive(Clone, Copy)]
enum Kind {
    Screen,
    Symbol,
}

impl Kind {
    fn dir(self) -> &'static str {
        match self {
            Kind::Screen => "hmi",
            Kind::Symbol => "hmi/symbols",
        }
    }
    fn what(self) -> &'static str {
        match self {
            Kind::Screen => "screen",
            Kind::Symbol => "symbol",
        }
    }
}

/// A screen's name: letters, digits, `_` and `-` (it is a file name).
fn file_of(st_dir: &std::path::Path, kind: Kind, name: &str) -> ApiResult<std::path::PathBuf> {
    let ok =
        !name.is_empty() && name.len() <= 64 && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if !ok {
        return Err(ApiError::Malformed(format!(
            "`{name}` is not a {} name (letters, digits, `_` and `-`, at most 64)",
            kind.what()
        )));
    }
    Ok(st_dir.join(kind.dir()).join(format!("{name}.json")))
}

/// Parses and checks `text` as the screen `name`; its diagnostics on refusal.
fn check(st: &AppState, kind: Kind, name: &str, text: &str) -> ApiResult<Screen> {
    let snapshot = st.runtime.snapshot();
    let mut files = Files::new();
    let f = files.add(format!("{}/{name}.json", kind.dir()), text);
    let alarm_ids: Vec<String> = st
        .control
        .alarms()
        .map(|h| h.list(true).into_iter().map(|a| a.def.id).collect())
        .unwrap_or_default();
    let (screen, diags) = hmi::parse(
        text,
        f,
        &alba_compiler::screens::resolver(&snapshot.program.layout),
        &|id: &str| alarm_ids.iter().any(|a| a == id),
    );
    match screen {
        Some(s) if diags.is_empty() => Ok(s),
        _ => Err(ApiError::Edit(EditError::DoesNotCompile {
            diagnostics: diagnostics_json(&diags, &files),
        })),
    }
}

/// The screens of the project, by name.
pub async fn list(st: State<Arc<AppState>>) -> ApiResult<Json<JsonValue>> {
    list_of(st, Kind::Screen).await
}

/// The user's symbols, by name.
pub async fn list_symbols(st: State<Arc<AppState>>) -> ApiResult<Json<JsonValue>> {
    list_of(st, Kind::Symbol).await
}

async fn list_of(State(st): State<Arc<AppState>>, kind: Kind) -> ApiResult<Json<JsonValue>> {
    let dir = st.project.lock().await.project.dir.join(kind.dir());
    let mut names: Vec<String> = match std::fs::read_dir(&dir) {
        Ok(entries) => entries
            .flatten()
            .filter(|e| e.path().is_file())
            .filter_map(|e| e.file_name().to_str()?.strip_suffix(".json").map(str::to_string))
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(ApiError::Internal(format!("cannot list {}: {e}", dir.display()))),
    };
    names.sort();
    Ok(Json(json!(names)))
}

/// One screen, checked as it is now (a tag removed since it was saved is a 422 with its place).
pub async fn get(st: State<Arc<AppState>>, name: Path<String>) -> ApiResult<Json<Screen>> {
    get_of(st, Kind::Screen, name).await
}

/// One symbol, checked like a screen.
pub async fn get_symbol(st: State<Arc<AppState>>, name: Path<String>) -> ApiResult<Json<Screen>> {
    get_of(st, Kind::Symbol, name).await
}

async fn get_of(State(st): State<Arc<AppState>>, kind: Kind, Path(name): Path<String>) -> ApiResult<Json<Screen>> {
    let path = file_of(&st.project.lock().await.project.dir, kind, &name)?;
    let text = std::fs::read_to_string(&path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => ApiError::NotFound(format!("no {} `{name}`", kind.what())),
        _ => ApiError::Internal(format!("cannot read {}: {e}", path.display())),
    })?;
    Ok(Json(check(&st, kind, &name, &text)?))
}

/// The screen of the body checked as `PUT` would, nothing saved: the screen, or `422` with the problems.
pub async fn check_screen(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    bytes: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<Json<Screen>> {
    file_of(&st.project.lock().await.project.dir, Kind::Screen, &name)?;
    let text = super::text_body(bytes, "the screen")?;
    Ok(Json(check(&st, Kind::Screen, &name, &text)?))
}

/// Audited (`save_screen`): checked, then written atomically (`hmi/` made if needed).
pub async fn put(
    st: State<Arc<AppState>>,
    actor: Actor,
    name: Path<String>,
    bytes: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<Json<Screen>> {
    put_of(st, actor, Kind::Screen, name, bytes).await
}

/// A symbol saved from the designer: audited as `save_screen` with its path.
pub async fn put_symbol(
    st: State<Arc<AppState>>,
    actor: Actor,
    name: Path<String>,
    bytes: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<Json<Screen>> {
    put_of(st, actor, Kind::Symbol, name, bytes).await
}

async fn put_of(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    kind: Kind,
    Path(name): Path<String>,
    bytes: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<Json<Screen>> {
    let text = super::text_body(bytes, &format!("the {}", kind.what()))?;
    let screen = check(&st, kind, &name, &text)?;
    let path = file_of(&st.project.lock().await.project.dir, kind, &name)?;
    let pretty = serde_json::to_string_pretty(&screen).map_err(|e| ApiError::Internal(e.to_string()))?;
    let entry = alba_control::audit::Entry {
        target: Some(format!("{}/{name}.json", kind.dir())),
        new: Some(json_text(&json!({"elements": screen.elements.len()}))),
        ..actor.entry(Action::SaveScreen)
    };
    audited(&st, entry, async {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| ApiError::Internal(format!("cannot create {}: {e}", dir.display())))?;
        }
        alba_ir::model::fsutil::write_atomic(&path, |w| {
            w.write_all(pretty.as_bytes())?;
            w.write_all(b"\n")
        })
        .map_err(|e| ApiError::Internal(format!("cannot save {}: {e}", path.display())))
    })
    .await?;
    Ok(Json(screen))
}
