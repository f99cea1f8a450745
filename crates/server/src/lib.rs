//! The studio's server: the API of docs/api.md over the real-time runtime,
//! and the embedded browser studio.
//!
//! Handlers never touch program memory: they read the runtime's latest
//! snapshot and send requests the engine thread applies between scans.
//! Project edits (program text, tags.csv) are serialised by one lock,
//! compiled in full before anything is saved, saved atomically, and applied
//! online by swapping the program between two scans.

mod assets;
mod domain;
mod history;
pub mod project;
pub mod tags;
mod ws;

use alba_ir::{Access, Target};
use alba_runtime::json::{from_json, to_json};
use alba_runtime::{Handle, Snapshot};
use axum::Router;
use axum::body::Bytes;
use axum::extract::rejection::JsonRejection;
use axum::extract::{DefaultBodyLimit, Path, State};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post, put};
use serde_json::{Value as Json, json};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Body limits (docs/api.md).
const SMALL_BODY: usize = 64 * 1024;
const FILE_BODY: usize = 1024 * 1024;

/// What every handler shares.
pub struct AppState {
    pub runtime: Handle,
    /// The project's name and scan period (fixed while it runs).
    pub name: String,
    pub scan_ms: u32,
    /// The project as last saved; edits hold this lock from check to apply.
    pub project: tokio::sync::Mutex<project::Compiled>,
    pub io: String,
    pub clients: AtomicUsize,
    /// Set when the server shuts down: WebSocket clients close.
    pub closing: tokio::sync::watch::Sender<bool>,
    /// `None` when history is off.
    pub history: Option<alba_historian::Historian>,
}

impl AppState {
    pub fn new(
        runtime: Handle,
        compiled: project::Compiled,
        io: &str,
        history: Option<alba_historian::Historian>,
    ) -> Arc<AppState> {
        let project = &compiled.project;
        Arc::new(AppState {
            runtime,
            name: project.config.as_ref().map(|c| c.name.clone()).unwrap_or_default(),
            scan_ms: project.scan_ms(),
            project: tokio::sync::Mutex::new(compiled),
            io: io.to_string(),
            clients: AtomicUsize::new(0),
            closing: tokio::sync::watch::Sender::new(false),
            history,
        })
    }
}

/// An API error: a status and `{"error": message, ...}`.
pub struct ApiError(StatusCode, Json);

impl ApiError {
    fn new(code: StatusCode, msg: impl Into<String>) -> ApiError {
        ApiError(code, json!({"error": msg.into()}))
    }
    fn bad(msg: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::BAD_REQUEST, msg)
    }
    fn unprocessable(msg: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::UNPROCESSABLE_ENTITY, msg)
    }
    fn not_found(msg: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::NOT_FOUND, msg)
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.0, axum::Json(self.1)).into_response()
    }
}

type ApiResult = Result<Response, ApiError>;

fn ok(j: Json) -> ApiResult {
    Ok(axum::Json(j).into_response())
}

/// A JSON body, with malformed input and oversized bodies as API errors.
fn body(b: Result<axum::Json<Json>, JsonRejection>) -> Result<Json, ApiError> {
    match b {
        Ok(axum::Json(j)) => Ok(j),
        Err(JsonRejection::BytesRejection(e)) if e.status() == StatusCode::PAYLOAD_TOO_LARGE => Err(ApiError::new(
            StatusCode::PAYLOAD_TOO_LARGE,
            "the request body is too large",
        )),
        Err(e) => Err(ApiError::bad(format!("malformed JSON body: {}", e.body_text()))),
    }
}

fn field<'a>(j: &'a Json, name: &str) -> Result<&'a Json, ApiError> {
    j.get(name)
        .ok_or_else(|| ApiError::bad(format!("the body needs a `{name}` field")))
}

/// The program text of a check or save request.
fn text_field(j: &Json) -> Result<&str, ApiError> {
    field(j, "text")?
        .as_str()
        .ok_or_else(|| ApiError::bad("`text` must be a string"))
}

/// `GET /api/status` body.
pub fn status_json(s: &Snapshot, state: &AppState) -> Json {
    let st = s.stats;
    json!({
        "project": state.name,
        "state": s.state.name(),
        "fault": s.fault,
        "scan_ms": state.scan_ms,
        "scans": s.scans,
        "time_ms": s.clock_ms,
        "stats": {
            "last_us": st.last_us, "min_us": st.min_us, "max_us": st.max_us, "mean_us": st.mean_us,
            "jitter_us": st.jitter_us, "overruns": st.overruns,
        },
        "minor_faults": s.minor_faults,
        "io": state.io,
        "programs": s.program.units.iter().map(|u| u.name.clone()).collect::<Vec<_>>(),
        "clients": state.clients.load(Ordering::Relaxed),
    })
}

async fn status(State(st): State<Arc<AppState>>) -> ApiResult {
    ok(status_json(&st.runtime.snapshot(), &st))
}

async fn post_run(State(st): State<Arc<AppState>>) -> ApiResult {
    st.runtime.run().await.map_err(ApiError::unprocessable)?;
    status(State(st)).await
}

async fn post_stop(State(st): State<Arc<AppState>>) -> ApiResult {
    st.runtime.stop().await.map_err(ApiError::unprocessable)?;
    status(State(st)).await
}

async fn list_tags(State(st): State<Arc<AppState>>) -> ApiResult {
    ok(tags::all(&st.runtime.snapshot()))
}

async fn get_tag(State(st): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult {
    match tags::one(&st.runtime.snapshot(), &name) {
        Some(j) => ok(j),
        None => Err(ApiError::not_found(format!("unknown tag `{name}`"))),
    }
}

/// Resolves `name` for a write, or says why it cannot be written.
fn writable(s: &Snapshot, name: &str) -> Result<alba_ir::Place, ApiError> {
    match s.program.layout.resolve(name) {
        Err(e) => Err(ApiError::not_found(e.to_string())),
        Ok(Target::Timer(_) | Target::Counter(_)) => Err(ApiError::unprocessable(format!(
            "`{name}` is a structure: write one of its members (`{name}.PRE`, `{name}.ACC`)"
        ))),
        Ok(Target::Pid(_)) => Err(ApiError::unprocessable(format!(
            "`{name}` is a structure: write one of its members (`{name}.SP`, `{name}.KP`, `{name}.MAN`)"
        ))),
        Ok(Target::Value { place, access }) => match access {
            Access::ReadWrite => Ok(place),
            Access::Input => Err(ApiError::unprocessable(format!(
                "`{name}` is an input, written by the I/O: force it instead"
            ))),
            Access::ReadOnly | Access::Output => Err(ApiError::unprocessable(format!("`{name}` is read-only"))),
        },
    }
}

async fn put_tag(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    b: Result<axum::Json<Json>, JsonRejection>,
) -> ApiResult {
    let j = body(b)?;
    let s = st.runtime.snapshot();
    let place = writable(&s, &name)?;
    let v = from_json(field(&j, "value")?, place.data_type())
        .map_err(|e| ApiError::unprocessable(format!("`{name}`: {e}")))?;
    st.runtime.write(place, v).await.map_err(ApiError::unprocessable)?;
    ok(json!({"name": name, "value": to_json(st.runtime.snapshot().read(place))}))
}

async fn list_forces(State(st): State<Arc<AppState>>) -> ApiResult {
    let s = st.runtime.snapshot();
    ok(Json::Array(
        s.forces
            .iter()
            .map(|f| json!({"name": f.name, "value": to_json(f.value)}))
            .collect(),
    ))
}

async fn put_force(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    b: Result<axum::Json<Json>, JsonRejection>,
) -> ApiResult {
    let j = body(b)?;
    let s = st.runtime.snapshot();
    let place = match s.program.layout.resolve(&name) {
        Ok(Target::Value { place, .. }) => place,
        Ok(_) => return Err(ApiError::unprocessable(format!("`{name}` is a structure, not I/O"))),
        Err(e) => return Err(ApiError::not_found(e.to_string())),
    };
    if alba_runtime::io_kind(&s.program.layout, place).is_none() {
        return Err(ApiError::unprocessable(format!(
            "`{name}` is not an input or an output: only I/O can be forced (write internal tags instead)"
        )));
    }
    let v = from_json(field(&j, "value")?, place.data_type())
        .map_err(|e| ApiError::unprocessable(format!("`{name}`: {e}")))?;
    st.runtime
        .force(name.clone(), place, v)
        .await
        .map_err(ApiError::unprocessable)?;
    ok(json!({"name": name, "value": to_json(v)}))
}

async fn delete_force(State(st): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult {
    let s = st.runtime.snapshot();
    if !s.forces.iter().any(|f| f.name.eq_ignore_ascii_case(&name)) {
        return Err(ApiError::not_found(format!("`{name}` is not forced")));
    }
    st.runtime.unforce(Some(name)).await.map_err(ApiError::unprocessable)?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

async fn delete_forces(State(st): State<Arc<AppState>>) -> ApiResult {
    st.runtime.unforce(None).await.map_err(ApiError::unprocessable)?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

async fn list_programs(State(st): State<Arc<AppState>>) -> ApiResult {
    let p = st.project.lock().await;
    ok(Json::Array(
        p.project
            .programs
            .iter()
            .map(|s| json!({"name": s.name, "language": project::language_name(s.language), "plant": s.plant}))
            .collect(),
    ))
}

async fn get_program(State(st): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult {
    let p = st.project.lock().await;
    project::program_json(&p.project, p.program.as_ref(), &name, &p.diagnostics)
        .map(axum::Json)
        .map(IntoResponse::into_response)
        .map_err(ApiError::not_found)
}

/// Compiles the project with `edit`; `Err` with the diagnostics if it does not compile.
async fn check_edit(st: &AppState, edit: &project::Edit<'_>) -> Result<project::Compiled, ApiError> {
    let p = st.project.lock().await;
    let c = project::compile_with(&p.project, Some(edit)).map_err(ApiError::not_found)?;
    if c.program.is_none() {
        return Err(compile_error(&c));
    }
    Ok(c)
}

/// `422` with the diagnostics of a project that does not compile.
fn compile_error(c: &project::Compiled) -> ApiError {
    let n = c.diagnostics.len();
    ApiError(
        StatusCode::UNPROCESSABLE_ENTITY,
        json!({
            "error": format!("{n} error{}", if n == 1 { "" } else { "s" }),
            "diagnostics": project::diagnostics_json(&c.diagnostics, &c.project.files),
        }),
    )
}

async fn check_program(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    b: Result<axum::Json<Json>, JsonRejection>,
) -> ApiResult {
    let j = body(b)?;
    let edit = project::Edit::Program {
        name: &name,
        text: text_field(&j)?,
    };
    let c = check_edit(&st, &edit).await?;
    let view =
        project::program_json(&c.project, c.program.as_ref(), &name, &c.diagnostics).map_err(ApiError::not_found)?;
    let mut out = json!({"diagnostics": []});
    for key in ["rungs", "lines"] {
        if let Some(v) = view.get(key) {
            out[key] = v.clone();
        }
    }
    ok(out)
}

/// Saves a checked edit and, if asked while running, applies it online.
async fn apply(st: &AppState, edit: project::Edit<'_>, online: bool) -> ApiResult {
    // The lock is held from compile to swap: edits never interleave.
    let mut p = st.project.lock().await;
    let c = project::compile_with(&p.project, Some(&edit)).map_err(ApiError::not_found)?;
    let Some(program) = c.program.clone() else {
        return Err(compile_error(&c));
    };
    project::save(&c, &edit).map_err(|e| ApiError::new(StatusCode::INTERNAL_SERVER_ERROR, e))?;
    let mut applied = false;
    if online {
        st.runtime.replace(Arc::new(program)).await.map_err(|e| {
            ApiError::new(
                StatusCode::INTERNAL_SERVER_ERROR,
                format!("saved, but not applied: {e}"),
            )
        })?;
        applied = true;
    }
    *p = c;
    ok(json!({"diagnostics": [], "applied": applied}))
}

async fn put_program(
    State(st): State<Arc<AppState>>,
    Path(name): Path<String>,
    b: Result<axum::Json<Json>, JsonRejection>,
) -> ApiResult {
    let j = body(b)?;
    let online = j.get("online").and_then(Json::as_bool).unwrap_or(false);
    apply(
        &st,
        project::Edit::Program {
            name: &name,
            text: text_field(&j)?,
        },
        online,
    )
    .await
}

async fn get_tags_csv(State(st): State<Arc<AppState>>) -> ApiResult {
    let p = st.project.lock().await;
    let text = p
        .project
        .tags_file
        .map(|f| p.project.files.text(f).to_string())
        .unwrap_or_default();
    Ok(([(header::CONTENT_TYPE, "text/csv; charset=utf-8")], text).into_response())
}

async fn put_tags_csv(State(st): State<Arc<AppState>>, bytes: Bytes) -> ApiResult {
    let text = std::str::from_utf8(&bytes).map_err(|e| ApiError::bad(format!("tags.csv is not UTF-8 text: {e}")))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    apply(&st, project::Edit::Tags(text), true).await
}

async fn fallback_api() -> ApiError {
    ApiError::not_found("no such endpoint")
}

/// The router: the API under `/api`, the studio at `/`.
pub fn router(state: Arc<AppState>) -> Router {
    let files = Router::new()
        .route("/api/programs/{name}", get(get_program).put(put_program))
        .route("/api/check/{name}", post(check_program))
        .route("/api/tags.csv", get(get_tags_csv).put(put_tags_csv))
        .layer(DefaultBodyLimit::max(FILE_BODY));
    Router::new()
        .route("/api/status", get(status))
        .route("/api/run", post(post_run))
        .route("/api/stop", post(post_stop))
        .route("/api/tags", get(list_tags))
        .route("/api/tags/{name}", get(get_tag).put(put_tag))
        .route("/api/forces", get(list_forces).delete(delete_forces))
        .route("/api/forces/{name}", put(put_force).delete(delete_force))
        .route("/api/programs", get(list_programs))
        .route("/api/instructions", get(domain::instructions))
        .route("/api/domain", get(domain::get))
        .route("/api/ws", get(ws::upgrade))
        .route("/api/history/tags", get(history::list))
        .route("/api/history", get(history::query))
        .route("/api/history.csv", get(history::csv))
        .route("/api/{*rest}", axum::routing::any(fallback_api))
        .layer(DefaultBodyLimit::max(SMALL_BODY))
        .merge(files)
        .fallback(assets::serve)
        .with_state(state)
}

/// Where the OPC UA certificates of the project in `dir` live, for messages.
fn pki_dir_note(dir: &std::path::Path) -> String {
    dir.join(".alba").join("pki").display().to_string()
}

/// What `alba run` starts: the runtime for a compiled project and the
/// server in front of it.
pub struct Options {
    pub addr: std::net::SocketAddr,
    pub io: String,
    pub native: bool,
    /// Serve Modbus TCP here (else where `[modbus] listen` says, if it does).
    pub modbus: Option<std::net::SocketAddr>,
    /// Serve OPC UA here (else where `[opcua] listen` says, if it does; security None only on loopback).
    pub opcua: Option<std::net::SocketAddr>,
}

/// Runs `dir` until `shutdown` completes: loads and compiles it (its
/// diagnostics are the error), restores retentive data, starts the runtime
/// and serves the API and the studio. Calls `ready` with the bound address.
pub async fn run(
    dir: &std::path::Path,
    opts: Options,
    ready: impl FnOnce(std::net::SocketAddr),
    shutdown: impl std::future::Future<Output = ()> + Send + 'static,
) -> Result<(), RunError> {
    let compiled = project::load(dir);
    let Some(program) = compiled.program.clone() else {
        return Err(RunError::Compile(Box::new(compiled)));
    };
    let mut ro = alba_runtime::Options::new(compiled.project.scan_ms());
    ro.native = opts.native;
    ro.retain_file = Some(dir.join(".alba").join("retain.json"));
    if let Some(c) = &compiled.project.config {
        ro.retain_interval_ms = u64::from(c.retain_ms);
    }
    let io: Box<dyn alba_runtime::Io> = match opts.io.as_str() {
        "sim" => Box::new(alba_runtime::SimIo),
        arduino if arduino.starts_with("arduino:") => {
            let board = compiled.project.config.as_ref().and_then(|c| c.board.as_ref());
            alba_io::arduino::driver(arduino, board).map_err(RunError::Other)?
        }
        "modbus" => {
            let devices = compiled
                .project
                .config
                .as_ref()
                .map(|c| c.modbus_devices.as_slice())
                .unwrap_or_default();
            alba_io::modbus_master::driver(devices).map_err(RunError::Other)?
        }
        attach if attach.starts_with("board:") => {
            let board = compiled.project.config.as_ref().and_then(|c| c.board.as_ref());
            let target = alba_arduino::sketch::Target {
                model: board.map_or(alba_model::board::Model::Nano, |b| b.model),
                map: board.map_or_else(
                    || alba_model::board::PinMap::preset("aurora").unwrap_or_default(),
                    |b| b.map.clone(),
                ),
                active_low: board.is_some_and(|b| b.active_low),
                scan_ms: compiled.project.scan_ms(),
                monitor: true,
                power_up_on: board.map_or_else(Vec::new, |b| b.power_up_on.clone()),
            };
            alba_io::attach::driver(attach, &program, &target).map_err(RunError::Other)?
        }
        other => {
            return Err(RunError::Other(format!(
                "unknown I/O driver `{other}` (available: sim, arduino:<serial port>[,link=modbus|aurora,…], board:<serial port>, modbus)"
            )));
        }
    };
    let hist_cfg = compiled
        .project
        .config
        .as_ref()
        .map(|c| c.history.clone())
        .unwrap_or_default();
    let historian = if hist_cfg.enabled {
        Some(history::open(dir, &hist_cfg).map_err(RunError::Other)?)
    } else {
        None
    };
    let runtime = alba_runtime::Runtime::start(Arc::new(program), ro, io).map_err(RunError::Other)?;
    let recorder = historian.clone().map(|h| {
        history::record(
            h,
            hist_cfg,
            runtime.handle().subscribe(),
            tokio::runtime::Handle::current(),
        )
    });
    let state = AppState::new(runtime.handle(), compiled, &opts.io, historian);
    let listener = tokio::net::TcpListener::bind(opts.addr)
        .await
        .map_err(|e| RunError::Other(format!("cannot listen on {}: {e}", opts.addr)))?;
    let local = listener.local_addr().map_err(|e| RunError::Other(e.to_string()))?;
    let modbus_cfg = state_modbus(&state).await;
    if let Some(addr) = opts.modbus.or(modbus_cfg.as_ref().and_then(|m| m.listen)) {
        let l = tokio::net::TcpListener::bind(addr)
            .await
            .map_err(|e| RunError::Other(format!("cannot listen for Modbus TCP on {addr}: {e}")))?;
        let bound = l.local_addr().map_err(|e| RunError::Other(e.to_string()))?;
        let settings = modbus_cfg.as_ref().map(alba_modbus::Settings::from).unwrap_or_default();
        let server = alba_modbus::Server::new(runtime.handle(), settings);
        tokio::spawn(server.serve(l, state.closing.subscribe()));
        println!("Modbus TCP server: {bound} (OpenPLC v3 address map, docs/protocols.md)");
    }
    let opcua_cfg = {
        let p = state.project.lock().await;
        p.project
            .config
            .as_ref()
            .and_then(|c| c.opcua.as_ref())
            .and_then(|o| o.listen)
    };
    if let Some(addr) = opts.opcua.or(opcua_cfg) {
        let pki = dir.join(".alba").join("pki");
        let users = {
            let p = state.project.lock().await;
            p.project
                .config
                .as_ref()
                .and_then(|c| c.opcua.as_ref())
                .map(|o| o.users.clone())
                .unwrap_or_default()
        };
        let bound = alba_opcua::serve(
            runtime.handle(),
            &state.name,
            addr,
            pki,
            &users,
            state.closing.subscribe(),
        )
        .await
        .map_err(RunError::Other)?;
        println!(
            "OPC UA server: opc.tcp://{bound}/ (tags under Objects/Alba/{}/Tags)",
            state.name
        );
        if alba_opcua::security::is_local(bound.ip()) {
            println!(
                "  security: None (anonymous) and Basic256Sha256 with user names and passwords; client certificates trusted on first use"
            );
        } else {
            println!(
                "  security: Basic256Sha256 with user names and passwords only; unknown client certificates go to {}/rejected/",
                pki_dir_note(dir)
            );
        }
    }
    ready(local);
    let closing = state.closing.clone();
    let shutdown = async move {
        shutdown.await;
        closing.send_replace(true);
    };
    let served = axum::serve(listener, router(state))
        .with_graceful_shutdown(shutdown)
        .await
        .map_err(|e| RunError::Other(format!("server: {e}")));
    // Stops scanning and saves retentive data.
    // The recorder ends when the runtime's snapshot channel closes.
    tokio::task::spawn_blocking(move || {
        runtime.shutdown();
        if let Some(r) = recorder {
            let _ = r.join();
        }
    })
    .await
    .map_err(|e| RunError::Other(e.to_string()))?;
    served
}

/// The `[modbus]` settings of the project as loaded.
async fn state_modbus(state: &AppState) -> Option<alba_model::config::Modbus> {
    let p = state.project.lock().await;
    p.project.config.as_ref().and_then(|c| c.modbus.clone())
}

pub enum RunError {
    /// The project does not compile.
    Compile(Box<project::Compiled>),
    Other(String),
}
