//! What every handler shares: the runtime's handle, the project as last
//! saved (edits hold its lock from check to apply), and the hooks other
//! services of `alba run` subscribe to.

use crate::project::Compiled;
use alba_ir::Program;
use std::sync::Arc;
use std::sync::atomic::AtomicUsize;
use tokio::sync::{broadcast, watch};

/// A project edit the server saved: the file, the program it compiles to,
/// and whether it was applied online (the runtime then runs `program`).
#[derive(Debug, Clone)]
pub struct Edited {
    pub file: String,
    pub program: Arc<Program>,
    pub applied: bool,
}

pub struct AppState {
    pub runtime: alba_control::runtime::Handle,
    /// The rules for operating the PLC, shared with the other doors (MQTT,
    /// OPC UA, Modbus): writes, forces, run/stop, alarm actions and online
    /// edits go through here, and it holds the audit trail and the alarms
    /// (crates/control).
    pub control: alba_control::Control,
    /// The project's name and scan period (fixed while it runs).
    pub name: String,
    pub scan_ms: u32,
    /// The project as last saved; edits hold this lock from check to apply.
    pub project: tokio::sync::Mutex<Compiled>,
    /// The I/O driver, as `GET /api/status` names it.
    pub io: String,
    /// WebSocket clients connected.
    pub clients: AtomicUsize,
    /// Values subscribed by all live clients together (capped: `crate::ws`).
    pub subscribed: AtomicUsize,
    /// Set when the server shuts down: WebSocket clients close.
    pub closing: watch::Sender<bool>,
    /// The store `alba run` records into (SQLite or the shared PostgreSQL);
    /// `None` when history is off.
    pub history: Option<Arc<dyn alba_control::history::Backend>>,
    /// Every saved edit ("program replaced"), for services that follow the program.
    pub edits: broadcast::Sender<Edited>,
    /// What the browser-attack guard lets in (`[http]` of alba.toml).
    pub guard: crate::guard::Guard,
    /// Users, sessions, login back-off (`crate::auth`).
    pub auth: crate::auth::Auth,
    /// The client connections to remote servers (`[[opcua_server]]`), set by
    /// alba-app before serving; unset: none (`connections: []`).
    pub connections: std::sync::OnceLock<Arc<dyn crate::connections::Connections>>,
    /// The board, its ports, firmware builds and downloads (`/api/hardware`),
    /// set by alba-app before serving; unset: `/api/hardware` answers 404.
    pub hardware: std::sync::OnceLock<Arc<dyn crate::hardware::Hardware>>,
    /// The project's proofs and test tables (`/api/verify`, `/api/tests`),
    /// set by alba-app before serving; unset: those routes answer 404.
    pub verifier: std::sync::OnceLock<Arc<dyn crate::verify::Verifier>>,
    /// The studio is served over HTTPS (set by alba-app before serving;
    /// session cookies are then `Secure`).
    pub https: std::sync::atomic::AtomicBool,
    /// Live clients at most (`[http] max_ws_clients`).
    pub max_ws_clients: usize,
    /// How long a request may take (`[http] request_timeout_s`).
    pub request_timeout: std::time::Duration,
    /// One net analysis at a time (`POST /api/nets/{name}/analysis`): its
    /// thread holds the permit until it has stopped.
    pub analysis: Arc<tokio::sync::Semaphore>,
}

impl AppState {
    pub fn new(
        runtime: alba_control::runtime::Handle,
        compiled: Compiled,
        io: &str,
        history: Option<Arc<dyn alba_control::history::Backend>>,
        audit: Option<alba_control::audit::Audit>,
        auth: crate::auth::Auth,
        http: &alba_settings::Http,
    ) -> Arc<AppState> {
        // The audit trail (docs/audit.md): every state-changing request writes
        // its row there before it acts. `alba run` always opens one; `None`
        // (tests, embedders) records nothing.
        let project = &compiled.project;
        let guard = crate::guard::Guard::new(http);
        Arc::new(AppState {
            control: alba_control::Control::new(runtime.clone(), audit),
            runtime,
            name: project.config.as_ref().map(|c| c.name.clone()).unwrap_or_default(),
            scan_ms: project.scan_ms(),
            project: tokio::sync::Mutex::new(compiled),
            io: io.to_string(),
            clients: AtomicUsize::new(0),
            subscribed: AtomicUsize::new(0),
            closing: watch::Sender::new(false),
            history,
            edits: broadcast::Sender::new(16),
            guard,
            auth,
            connections: std::sync::OnceLock::new(),
            hardware: std::sync::OnceLock::new(),
            verifier: std::sync::OnceLock::new(),
            https: std::sync::atomic::AtomicBool::new(false),
            max_ws_clients: http.max_ws_clients as usize,
            request_timeout: std::time::Duration::from_secs(u64::from(http.request_timeout_s)),
            analysis: Arc::new(tokio::sync::Semaphore::new(1)),
        })
    }

    /// Saved edits from now on (a receiver that falls 16 edits behind
    /// skips the oldest).
    pub fn subscribe_edits(&self) -> broadcast::Receiver<Edited> {
        self.edits.subscribe()
    }

    /// Turns true when the server shuts down.
    pub fn closing(&self) -> watch::Receiver<bool> {
        self.closing.subscribe()
    }
}
