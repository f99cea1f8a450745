//! The application layer: assembles `alba run`.
//!
//! [`run`] loads and compiles the project, opens its I/O driver and its
//! historian, starts the runtime, then the services in front of it — the
//! HTTP/WebSocket API (alba-server) with its audit trail, the historian's recorder, the alarms, the scheduled shift reports, the MQTT client, the Modbus
//! TCP and OPC UA servers — and stops them all on one shutdown signal
//! (`AppState::closing`), the runtime last (retentive data saved).
//!
//! Add a service: a file beside `modbus.rs` with a `start(&Service, …)`
//! that spawns it on `state.closing()` (and, to follow online edits,
//! `state.subscribe_edits()`), and one line in [`run`] calling it.

mod alarms;
mod audit;
mod clock;
mod connections;
mod edits;
pub mod hardware;
mod history;
pub use history::pg_config;
pub mod ingest;
mod limits;
mod lock;
mod modbus;
mod mqtt;
mod opcua;
mod reports;
pub mod serve;
pub mod tls;
mod users;
pub mod verify;

use alba_server::AppState;
use alba_server::project::{self, Compiled};
use alba_settings::Settings;
use std::net::SocketAddr;
use std::path::Path;
use std::sync::Arc;

/// What `alba run` starts, from its command line.
pub struct Options {
    pub addr: SocketAddr,
    /// The I/O driver (`--io`): `sim`, `arduino:…`, `board:…`, `modbus`.
    pub io: String,
    pub native: bool,
    /// Serve Modbus TCP here (else where `[modbus] listen` says, if it does).
    pub modbus: Option<SocketAddr>,
    /// Serve OPC UA here (else where `[opcua] listen` says, if it does; security None only on loopback).
    pub opcua: Option<SocketAddr>,
    /// Publish to this MQTT broker (`host:port`; else where `[mqtt] broker` says, if it does).
    pub mqtt: Option<String>,
    /// HTTPS or plain HTTP for the studio (`tls::Tls::Auto`: HTTPS beyond loopback).
    pub tls: tls::Tls,
    /// Record every scan's start lateness here (`alba bench --realtime`).
    pub scan_log: Option<Arc<alba_runtime::ScanLog>>,
    /// Print no banners for the servers started (a benchmark embedding `alba run`).
    pub quiet: bool,
}

pub enum RunError {
    /// The project does not compile.
    Compile(Box<Compiled>),
    Other(String),
}

/// What a service of `alba run` is started with: the project folder, the
/// services' settings as loaded (`alba-settings`), and the server's state (the runtime's handle,
/// the shutdown signal `closing()`, saved edits `subscribe_edits()`).
pub(crate) struct Service<'a> {
    pub dir: &'a Path,
    pub config: Option<&'a Settings>,
    /// `[modbus.tags]`: the project's explicit Modbus addresses.
    pub modbus_tags: &'a [alba_project::config::ModbusTag],
    pub state: &'a Arc<AppState>,
    /// The project's users as loaded at start (users.toml and the
    /// deprecated `[opcua.users]`).
    pub users: &'a Arc<alba_auth::Users>,
    /// Print no banners ([`Options::quiet`]).
    pub quiet: bool,
}

impl Service<'_> {
    /// A line of a server's banner on stdout, unless quiet.
    pub fn say(&self, line: std::fmt::Arguments<'_>) {
        if !self.quiet {
            println!("{line}");
        }
    }
}

/// Whether a service was started (its configuration may leave it off).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Started {
    On,
    Off,
}

/// Runs `dir` until `shutdown` completes: loads and compiles it (its
/// diagnostics are the error), restores retentive data, starts the runtime
/// and every service. Calls `ready` with the bound address of the studio.
pub async fn run(
    dir: &Path,
    opts: Options,
    ready: impl FnOnce(SocketAddr),
    shutdown: impl std::future::Future<Output = ()> + Send + 'static,
) -> Result<(), RunError> {
    let compiled = project::load(dir);
    for w in &compiled.project.warnings {
        eprint!("{}", w.render_warning(&compiled.project.files));
    }
    let Some(program) = compiled.program.clone() else {
        return Err(RunError::Compile(Box::new(compiled)));
    };
    // One runtime per project: held until this function returns.
    let _lock = lock::acquire(dir).map_err(RunError::Other)?;
    let config = compiled.project.config.clone();
    let config = config.as_ref();
    // The services' tables, from the alba.toml the project was loaded from.
    let settings = alba_settings::Settings::of(&compiled.project);
    let settings = settings.as_ref();
    let alarm_defs = alarms::load(dir, &program).map_err(RunError::Other)?;
    let users = Arc::new(alba_auth::Users::load(dir).map_err(|e| RunError::Other(e.to_string()))?);
    let auth = users::auth(dir, users.clone(), settings, opts.addr).map_err(RunError::Other)?;
    let mut ro = alba_runtime::Options::new(compiled.project.scan_ms());
    ro.native = opts.native;
    ro.scan_log = opts.scan_log.clone();
    ro.retain_file = Some(dir.join(".alba").join("retain.json"));
    if let Some(c) = settings {
        ro.retain_interval_ms = u64::from(c.retain_ms);
        ro.on_retain_error = match c.runtime.on_retain_error {
            alba_settings::OnRetainError::Start => alba_runtime::retain::OnError::Start,
            alba_settings::OnRetainError::Refuse => alba_runtime::retain::OnError::Refuse,
        };
        ro.realtime = alba_runtime::realtime::Realtime {
            priority: c.runtime.priority,
            cpu: c.runtime.cpu.map(|c| c as usize),
            lock_memory: c.runtime.lock_memory,
        };
    }
    let health = ro.health.clone();
    let io = alba_io::open(&opts.io, config, &program).map_err(|e| RunError::Other(e.to_string()))?;
    // `[[opcua_server]]`: remote OPC UA variables bound to tags, beside the `--io` driver.
    let mut monitor = None;
    let io: Box<dyn alba_runtime::Io> = match settings.map(|c| c.opcua_servers.as_slice()) {
        Some(servers) if !servers.is_empty() => {
            let client = alba_opcua::client::OpcuaClientIo::start(
                io,
                servers,
                &program.layout,
                dir,
                &tokio::runtime::Handle::current(),
            )
            .map_err(RunError::Other)?;
            monitor = Some(client.monitor());
            Box::new(client)
        }
        _ => io,
    };
    let hist_cfg = settings.map(|c| c.history.clone()).unwrap_or_default();
    let use_pg = hist_cfg.enabled && hist_cfg.backend == alba_settings::HistoryBackend::Postgres;
    let pg = if use_pg {
        let name = config.map(|c| c.name.as_str()).unwrap_or_default();
        let pg = history::pg_config(dir, name, &hist_cfg).map_err(RunError::Other)?;
        // Its client blocks (it tries the database once here; an unreachable one is buffered for).
        let opened = tokio::task::spawn_blocking(move || alba_historian::PgHistorian::open(pg))
            .await
            .map_err(|e| RunError::Other(e.to_string()))?;
        Some(Arc::new(opened.map_err(|e| RunError::Other(format!("history: {e}")))?))
    } else {
        None
    };
    let historian = if hist_cfg.enabled && !use_pg {
        Some(history::open(dir, &hist_cfg, &health).map_err(RunError::Other)?)
    } else {
        None
    };
    let audit_cfg = settings.map(|c| c.audit.clone()).unwrap_or_default();
    let audit = audit::open(dir, &audit_cfg, &health).map_err(RunError::Other)?;
    // Retention only after a clock it can explain (crate::clock).
    let stores = [
        clock::Store {
            name: "audit trail",
            newest_ms: audit::newest(&audit),
            retention_days: audit.config().retention_days,
        },
        clock::Store {
            name: "history",
            newest_ms: historian.as_ref().and_then(history::newest),
            retention_days: (hist_cfg.retention_days > 0).then_some(hist_cfg.retention_days),
        },
    ];
    let guard = clock::ClockGuard::start(dir, health.clone(), audit::now_ms(), &stores);
    audit::retain(&audit, &guard).map_err(RunError::Other)?;
    let runtime =
        alba_runtime::Runtime::start(Arc::new(program), ro, io).map_err(|e| RunError::Other(e.to_string()))?;
    // The recorder ends when the runtime's snapshot channel closes.
    let recorder = if let Some(pg) = pg.clone() {
        Some(history::record_pg(
            pg,
            hist_cfg,
            runtime.handle().subscribe(),
            health.clone(),
            tokio::runtime::Handle::current(),
        ))
    } else {
        historian.clone().map(|h| {
            history::record(
                h,
                hist_cfg,
                runtime.handle().subscribe(),
                health.clone(),
                guard.clone(),
                tokio::runtime::Handle::current(),
            )
        })
    };
    let store: Option<Arc<dyn alba_historian::Backend>> = match (pg, historian) {
        (Some(pg), _) => Some(pg),
        (None, Some(h)) => Some(Arc::new(h)),
        (None, None) => None,
    };
    let http_cfg = settings.map(|c| c.http.clone()).unwrap_or_default();
    let state = AppState::new(
        runtime.handle(),
        compiled,
        &opts.io,
        store,
        Some(audit),
        auth,
        &http_cfg,
    );
    let listener = tokio::net::TcpListener::bind(opts.addr)
        .await
        .map_err(|e| RunError::Other(format!("cannot listen on {}: {e}", opts.addr)))?;
    let local = listener.local_addr().map_err(|e| RunError::Other(e.to_string()))?;
    let acceptor = if tls::https(opts.tls, local, http_cfg.insecure) {
        state.https.store(true, std::sync::atomic::Ordering::Relaxed);
        Some(tls::acceptor(dir, &http_cfg, local).map_err(RunError::Other)?)
    } else {
        None
    };

    let service = Service {
        dir,
        config: settings,
        modbus_tags: config.map_or(&[], |c| c.modbus_tags.as_slice()),
        state: &state,
        users: &users,
        quiet: opts.quiet,
    };
    modbus::start(&service, opts.modbus).await.map_err(RunError::Other)?;
    opcua::start(&service, opts.opcua).await.map_err(RunError::Other)?;
    let broker = mqtt::start(&service, opts.mqtt.as_deref())
        .await
        .map_err(RunError::Other)?;
    // The client connections in `/api/status`: the OPC UA servers, the broker.
    let mut links: Vec<Arc<dyn alba_server::connections::Connections>> = Vec::new();
    if let Some(m) = monitor {
        links.push(Arc::new(connections::OpcuaConnections(m)));
    }
    if let Some(b) = broker {
        links.push(b);
    }
    if !links.is_empty() {
        let _ = state.connections.set(Arc::new(connections::All(links)));
    }
    let _ = state
        .hardware
        .set(Arc::new(hardware::Service::new(dir).with_io(&opts.io)));
    let _ = state.verifier.set(Arc::new(verify::Service::new(dir)));
    edits::start(&service);
    audit::start(&service, guard.clone());
    alarms::start(&service, alarm_defs, guard).map_err(RunError::Other)?;
    reports::start(&service);

    ready(local);
    let closing = state.closing.clone();
    let shutdown = async move {
        shutdown.await;
        closing.send_replace(true);
    };
    // Handlers may read the client's address (`ConnectInfo<SocketAddr>`) either way.
    let router = alba_server::router(state);
    let conn_limits = serve::Limits {
        max_connections: http_cfg.max_connections,
        header_timeout: std::time::Duration::from_secs(u64::from(http_cfg.header_timeout_s)),
    };
    match acceptor {
        Some(acceptor) => {
            let listener = tls::TlsListener::new(listener, acceptor).map_err(|e| RunError::Other(e.to_string()))?;
            serve::serve(listener, router, conn_limits, shutdown).await;
        }
        None => {
            use axum::serve::ListenerExt;
            let listener = listener.tap_io(|tcp| limits::bound_send_buffer(tcp));
            serve::serve(listener, router, conn_limits, shutdown).await;
        }
    }
    // Stops scanning and saves retentive data.
    tokio::task::spawn_blocking(move || {
        runtime.shutdown();
        if let Some(r) = recorder {
            let _ = r.join();
        }
    })
    .await
    .map_err(|e| RunError::Other(e.to_string()))?;
    Ok(())
}
