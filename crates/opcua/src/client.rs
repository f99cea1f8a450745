//! Alba as an OPC UA client: the `[[opcua_server]]` entries of alba.toml
//! bind tags to variables of remote servers (docs/protocols.md, "OPC UA
//! client I/O").
//!
//! The design is the one of the Modbus master (`alba-io`): one task per
//! server owns its session; the engine thread's `read_inputs` and
//! `write_outputs` only copy shared values (a mutex held for the copy,
//! never across I/O), so a slow or dead server never delays a scan.
//!
//! - Inputs (`dir = "in"`) are monitored items of one subscription at the
//!   server's `publishing_interval_ms` (no polling); each data change is
//!   converted to the tag's type and written into the tag before the next
//!   scan. On loss an input keeps its last value.
//! - Outputs (`dir = "out"`) are written when the engine changes them, and
//!   all of them at once after every (re)connection. A value is written
//!   with the node's own type (read at connection).
//! - A server that cannot be reached, refuses the session (wrong password,
//!   untrusted certificate) or drops it is *down*: `S:IOOK` is false while
//!   any server is down (or any binding is refused, e.g. an unknown node),
//!   `S:IOERRORS` counts failed attempts, and the client reconnects with
//!   exponential back-off (250 ms doubling to 10 s) on a fresh session.
//! - Safe outputs: when `alba run` stops, every output node is written 0 /
//!   false (as the Modbus master does); a server's own logic must handle a
//!   lost client.

use alba_engine::Engine;
use alba_ir::Layout;
use alba_ir::layout::Place;
use alba_ir::symbols::Target;
use alba_model::{DataType, Value};
use alba_runtime::{Io, IoError};
use alba_settings::{Direction, OpcuaServer, SecurityMode, SecurityPolicy};
use futures::StreamExt;
use opcua::client::{
    Client, ClientBuilder, DataChangeCallback, IdentityToken, MonitoredItem, Session, SessionPollResult,
};
use opcua::crypto::SecurityPolicy as Policy;
use opcua::types::{
    AttributeId, BrowseDescription, BrowseDirection, BrowseResultMask, DataTypeId, DataValue, Identifier,
    MessageSecurityMode, MonitoredItemCreateRequest, NodeClass, NodeClassMask, NodeId, ReadValueId, ReferenceTypeId,
    StatusCode, TimestampsToReturn, Variant, WriteValue,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

const BACKOFF_FIRST: Duration = Duration::from_millis(250);
const BACKOFF_MAX: Duration = Duration::from_secs(10);

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Health of one server connection.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Status {
    /// Connected, with every binding accepted.
    pub ok: bool,
    /// A session is open (bindings may still be refused).
    pub connected: bool,
    /// Sessions opened so far.
    pub connects: u64,
    /// Failed attempts and losses.
    pub errors: u64,
    /// Why it is down or unhealthy.
    pub last_error: Option<String>,
}

/// One binding resolved against the program.
#[derive(Debug, Clone)]
struct Bound {
    tag: String,
    node: String,
    place: Place,
}

/// What one server's task is started with.
struct Conn {
    cfg: OpcuaServer,
    /// The project folder (its password file is read at each attempt).
    dir: PathBuf,
    pki: PathBuf,
    inputs: Vec<Bound>,
    outputs: Vec<Bound>,
}

#[derive(Default)]
struct OutImage {
    /// The engine's latest value of each output binding.
    values: Vec<Option<Value>>,
}

struct ConnShared {
    /// The server as configured, and the project folder (its PKI, its
    /// password file): for a browse when no session is open.
    cfg: OpcuaServer,
    dir: PathBuf,
    /// The open session, while one is (a browse uses it).
    session: Mutex<Option<Arc<Session>>>,
    status: Mutex<Status>,
    ok: AtomicBool,
    errors: AtomicU64,
    /// The latest value of each input binding.
    inputs: Mutex<Vec<Option<Value>>>,
    outputs: Mutex<OutImage>,
    dirty: tokio::sync::Notify,
}

impl ConnShared {
    fn set(&self, f: impl FnOnce(&mut Status)) {
        let mut s = lock(&self.status);
        f(&mut s);
        self.ok.store(s.ok, Ordering::Relaxed);
    }
}

/// The driver: another driver's I/O (`--io`) plus the `[[opcua_server]]`
/// bindings.
pub struct OpcuaClientIo {
    inner: Box<dyn Io>,
    name: String,
    names: Vec<String>,
    shared: Vec<Arc<ConnShared>>,
    /// Per server: the places of its inputs and outputs.
    places: Vec<(Vec<Place>, Vec<Place>)>,
    last_out: Vec<Vec<Option<Value>>>,
    stop: tokio::sync::watch::Sender<bool>,
    done: Vec<std::sync::mpsc::Receiver<()>>,
}

/// Reads a password file (first line, without its line end).
fn read_password(dir: &Path, file: &str, server: &str) -> Result<String, String> {
    let path = dir.join(file);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("[[opcua_server]] {server}: password_file {}: {e}", path.display()))?;
    Ok(text.lines().next().unwrap_or("").to_string())
}

/// The identity `server` logs in with: its user and the password file's
/// first line (read now, so a corrected file is used at the next attempt),
/// else anonymous.
fn identity(server: &OpcuaServer, dir: &Path) -> Result<IdentityToken, String> {
    match &server.user {
        Some((user, file)) => Ok(IdentityToken::new_user_name(
            user.clone(),
            read_password(dir, file, &server.name)?,
        )),
        None => Ok(IdentityToken::Anonymous),
    }
}

/// `line:col` of a byte offset in `text` (1-based).
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

impl OpcuaClientIo {
    /// Resolves every binding against `layout` (an unknown or read-only tag
    /// is an error located in alba.toml), reads the password files, and
    /// starts one task per server on `rt`.
    pub fn start(
        inner: Box<dyn Io>,
        servers: &[OpcuaServer],
        layout: &Layout,
        dir: &Path,
        rt: &tokio::runtime::Handle,
    ) -> Result<OpcuaClientIo, String> {
        let toml = std::fs::read_to_string(dir.join("alba.toml")).unwrap_or_default();
        let mut conns = Vec::new();
        for s in servers {
            let mut inputs = Vec::new();
            let mut outputs = Vec::new();
            for b in &s.bindings {
                let (line, col) = line_col(&toml, b.span.start as usize);
                let place = match layout.resolve(&b.tag) {
                    Ok(Target::Value { place, access }) => {
                        if b.dir == Direction::In && access != alba_ir::Access::ReadWrite {
                            return Err(format!(
                                "alba.toml:{line}:{col}: [[opcua_server]] {}: tag `{}` cannot be written, so it cannot be an input",
                                s.name, b.tag
                            ));
                        }
                        place
                    }
                    Ok(_) => {
                        return Err(format!(
                            "alba.toml:{line}:{col}: [[opcua_server]] {}: `{}` is not a value (bind a member, like `{}.ACC`)",
                            s.name, b.tag, b.tag
                        ));
                    }
                    Err(e) => {
                        return Err(format!(
                            "alba.toml:{line}:{col}: [[opcua_server]] {}: `{}`: {e}",
                            s.name, b.tag
                        ));
                    }
                };
                let bound = Bound {
                    tag: b.tag.clone(),
                    node: b.node.clone(),
                    place,
                };
                match b.dir {
                    Direction::In => inputs.push(bound),
                    Direction::Out => outputs.push(bound),
                }
            }
            // A missing password file stops `alba run` here.
            identity(s, dir)?;
            conns.push(Conn {
                cfg: s.clone(),
                dir: dir.to_path_buf(),
                pki: dir.join(&s.pki_dir),
                inputs,
                outputs,
            });
        }
        let (stop, closing) = tokio::sync::watch::channel(false);
        let names: Vec<String> = servers.iter().map(|s| s.name.clone()).collect();
        let name = format!("{} + opcua ({})", inner.name(), names.join(", "));
        let mut shared = Vec::new();
        let mut places = Vec::new();
        let mut last_out = Vec::new();
        let mut done = Vec::new();
        for c in conns {
            let sh = Arc::new(ConnShared {
                cfg: c.cfg.clone(),
                dir: dir.to_path_buf(),
                session: Mutex::new(None),
                status: Mutex::new(Status {
                    last_error: Some("not connected yet".into()),
                    ..Status::default()
                }),
                ok: AtomicBool::new(false),
                errors: AtomicU64::new(0),
                inputs: Mutex::new(vec![None; c.inputs.len()]),
                outputs: Mutex::new(OutImage {
                    values: vec![None; c.outputs.len()],
                }),
                dirty: tokio::sync::Notify::new(),
            });
            places.push((
                c.inputs.iter().map(|b| b.place).collect(),
                c.outputs.iter().map(|b| b.place).collect(),
            ));
            last_out.push(vec![None; c.outputs.len()]);
            let (tx, rx) = std::sync::mpsc::channel();
            done.push(rx);
            let (s2, closing) = (sh.clone(), closing.clone());
            rt.spawn(async move {
                run_conn(c, s2, closing).await;
                let _ = tx.send(());
            });
            shared.push(sh);
        }
        Ok(OpcuaClientIo {
            inner,
            name,
            names,
            shared,
            places,
            last_out,
            stop,
            done,
        })
    }

    /// Each server's name and health.
    pub fn status(&self) -> Vec<(String, Status)> {
        self.names
            .iter()
            .zip(&self.shared)
            .map(|(n, s)| (n.clone(), lock(&s.status).clone()))
            .collect()
    }

    /// A handle on the servers' health that outlives the driver being moved
    /// into the runtime.
    pub fn monitor(&self) -> Monitor {
        Monitor {
            names: self.names.clone(),
            shared: self.shared.clone(),
        }
    }
}

/// Each server's health, for status pages and tests, and browsing its
/// address space (the studio's tag picker).
#[derive(Clone)]
pub struct Monitor {
    names: Vec<String>,
    shared: Vec<Arc<ConnShared>>,
}

/// Why a browse failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BrowseError {
    /// No `[[opcua_server]]` of this name.
    UnknownServer(String),
    /// The text is not a node id (`ns=2;s=Tank`, `nsu=urn:x;i=5`, `i=85`).
    BadNode(String),
    /// The server cannot be reached, refused the session or the browse.
    Server(String),
}

impl std::fmt::Display for BrowseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BrowseError::UnknownServer(n) => write!(f, "no [[opcua_server]] named `{n}` in alba.toml"),
            BrowseError::BadNode(n) => write!(
                f,
                "`{n}` is not a node id (like `i=85`, `ns=2;s=Tank.Level` or `nsu=urn:plant;s=Tank.Level`)"
            ),
            BrowseError::Server(m) => f.write_str(m),
        }
    }
}

impl Monitor {
    pub fn status(&self) -> Vec<(String, Status)> {
        self.names
            .iter()
            .zip(&self.shared)
            .map(|(n, s)| (n.clone(), lock(&s.status).clone()))
            .collect()
    }

    /// Each server's name and endpoint, in alba.toml's order.
    pub fn servers(&self) -> Vec<(String, String)> {
        self.shared
            .iter()
            .map(|s| (s.cfg.name.clone(), s.cfg.endpoint.clone()))
            .collect()
    }

    /// The children of `node` on server `name` (exact name): on its open
    /// session, else on a session opened for this browse (as `alba run`
    /// opens one: same security, user and PKI). Errors say which server
    /// and why, never the password.
    pub async fn browse(&self, name: &str, node: &str) -> Result<Vec<Child>, BrowseError> {
        let sh = self
            .shared
            .iter()
            .find(|s| s.cfg.name == name)
            .ok_or_else(|| BrowseError::UnknownServer(name.to_string()))?;
        if !is_node_id(node) {
            return Err(BrowseError::BadNode(node.to_string()));
        }
        let live = lock(&sh.session).clone();
        let r = match live {
            Some(session) => browse(&session, node).await,
            None => browse_server(&sh.cfg, &sh.dir, node).await,
        };
        r.map_err(|e| BrowseError::Server(format!("OPC UA server {name} ({}): {e}", sh.cfg.endpoint)))
    }
}

impl Drop for OpcuaClientIo {
    fn drop(&mut self) {
        self.stop.send_replace(true);
        // Give the tasks a moment to write the safe outputs and close.
        let deadline = std::time::Instant::now() + Duration::from_secs(3);
        for d in &self.done {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            let _ = d.recv_timeout(left);
        }
    }
}

impl Io for OpcuaClientIo {
    fn name(&self) -> &str {
        &self.name
    }

    fn read_inputs(&mut self, engine: &mut Engine) -> Result<(), IoError> {
        // The inner driver sets its own status (or leaves it healthy).
        engine.set_io_status(true, 0);
        self.inner.read_inputs(engine)?;
        let (mut ok, mut errors) = engine.io_status();
        for (sh, (inputs, _)) in self.shared.iter().zip(&self.places) {
            ok &= sh.ok.load(Ordering::Relaxed);
            errors = errors.saturating_add(sh.errors.load(Ordering::Relaxed).min(i32::MAX as u64) as i32);
            let values = lock(&sh.inputs).clone();
            for (place, v) in inputs.iter().zip(values) {
                if let Some(v) = v {
                    engine.write(*place, v);
                }
            }
        }
        engine.set_io_status(ok, errors);
        Ok(())
    }

    fn write_outputs(&mut self, engine: &Engine) -> Result<(), IoError> {
        self.inner.write_outputs(engine)?;
        for ((sh, (_, outputs)), last) in self.shared.iter().zip(&self.places).zip(&mut self.last_out) {
            let mut changed = false;
            for (place, l) in outputs.iter().zip(last.iter_mut()) {
                let v = Some(engine.read(*place));
                if *l != v {
                    *l = v;
                    changed = true;
                }
            }
            if changed {
                lock(&sh.outputs).values.clone_from(last);
                sh.dirty.notify_one();
            }
        }
        Ok(())
    }

    fn runs_program(&self) -> bool {
        self.inner.runs_program()
    }

    fn write_remote(&mut self, place: Place, value: Value) -> Option<Result<(), IoError>> {
        self.inner.write_remote(place, value)
    }
}

/// A number read from a variant.
#[derive(Clone, Copy)]
enum Num {
    I(i64),
    F(f64),
}

fn num(v: &Variant) -> Option<Num> {
    Some(match v {
        Variant::Boolean(b) => Num::I(i64::from(*b)),
        Variant::SByte(x) => Num::I(i64::from(*x)),
        Variant::Byte(x) => Num::I(i64::from(*x)),
        Variant::Int16(x) => Num::I(i64::from(*x)),
        Variant::UInt16(x) => Num::I(i64::from(*x)),
        Variant::Int32(x) => Num::I(i64::from(*x)),
        Variant::UInt32(x) => Num::I(i64::from(*x)),
        Variant::Int64(x) => Num::I(*x),
        Variant::UInt64(x) => Num::I(i64::try_from(*x).unwrap_or(i64::MAX)),
        Variant::Float(x) if x.is_finite() => Num::F(f64::from(*x)),
        Variant::Double(x) if x.is_finite() => Num::F(*x),
        _ => return None,
    })
}

fn value_num(v: Value) -> Num {
    match v {
        Value::Bool(b) => Num::I(i64::from(b)),
        Value::Sint(x) => Num::I(i64::from(x)),
        Value::Int(x) => Num::I(i64::from(x)),
        Value::Dint(x) | Value::Time(x) => Num::I(i64::from(x)),
        Value::Lint(x) => Num::I(x),
        Value::Real(x) => Num::F(f64::from(x)),
        Value::Lreal(x) => Num::F(x),
    }
}

fn as_i64(n: Num) -> i64 {
    match n {
        Num::I(i) => i,
        // Saturating, rounded to nearest.
        Num::F(f) => f.round() as i64,
    }
}

fn as_f64(n: Num) -> f64 {
    match n {
        Num::I(i) => i as f64,
        Num::F(f) => f,
    }
}

/// A remote value as a value of the tag's type: numbers converted (clamped
/// to the type's range, reals rounded), `None` for what is not a number
/// (a string, an array, a non-finite real).
pub fn to_value(v: &Variant, t: DataType) -> Option<Value> {
    let n = num(v)?;
    let clamp = |lo: i64, hi: i64| as_i64(n).clamp(lo, hi);
    Some(match t {
        DataType::Bool => Value::Bool(as_f64(n) != 0.0),
        DataType::Sint => Value::Sint(clamp(i8::MIN.into(), i8::MAX.into()) as i8),
        DataType::Int => Value::Int(clamp(i16::MIN.into(), i16::MAX.into()) as i16),
        DataType::Time => Value::Time(clamp(i32::MIN.into(), i32::MAX.into()) as i32),
        DataType::Lint => Value::Lint(as_i64(n)),
        DataType::Real => Value::Real(as_f64(n) as f32),
        DataType::Lreal => Value::Lreal(as_f64(n)),
        _ => Value::Dint(clamp(i32::MIN.into(), i32::MAX.into()) as i32),
    })
}

/// A tag's value as a variant of the type the node has (`like`: its value
/// as read); of the tag's own type when the node's is not a number.
pub fn to_variant(v: Value, like: Option<&Variant>) -> Variant {
    let n = value_num(v);
    let i = as_i64(n);
    let f = as_f64(n);
    match like {
        Some(Variant::Boolean(_)) => Variant::Boolean(f != 0.0),
        Some(Variant::SByte(_)) => Variant::SByte(i.clamp(i8::MIN.into(), i8::MAX.into()) as i8),
        Some(Variant::Byte(_)) => Variant::Byte(i.clamp(0, u8::MAX.into()) as u8),
        Some(Variant::Int16(_)) => Variant::Int16(i.clamp(i16::MIN.into(), i16::MAX.into()) as i16),
        Some(Variant::UInt16(_)) => Variant::UInt16(i.clamp(0, u16::MAX.into()) as u16),
        Some(Variant::Int32(_)) => Variant::Int32(i.clamp(i32::MIN.into(), i32::MAX.into()) as i32),
        Some(Variant::UInt32(_)) => Variant::UInt32(i.clamp(0, u32::MAX.into()) as u32),
        Some(Variant::Int64(_)) => Variant::Int64(i),
        Some(Variant::UInt64(_)) => Variant::UInt64(i.max(0) as u64),
        Some(Variant::Float(_)) => Variant::Float(f as f32),
        Some(Variant::Double(_)) => Variant::Double(f),
        _ => crate::variant(v),
    }
}

fn zero(t: DataType) -> Value {
    match t {
        DataType::Bool => Value::Bool(false),
        DataType::Sint => Value::Sint(0),
        DataType::Int => Value::Int(0),
        DataType::Time => Value::Time(0),
        DataType::Lint => Value::Lint(0),
        DataType::Real => Value::Real(0.0),
        DataType::Lreal => Value::Lreal(0.0),
        _ => Value::Dint(0),
    }
}

fn policy(p: SecurityPolicy) -> Policy {
    match p {
        SecurityPolicy::None => Policy::None,
        SecurityPolicy::Basic256Sha256 => Policy::Basic256Sha256,
        SecurityPolicy::Aes128Sha256RsaOaep => Policy::Aes128Sha256RsaOaep,
        SecurityPolicy::Aes256Sha256RsaPss => Policy::Aes256Sha256RsaPss,
    }
}

fn mode(m: SecurityMode) -> MessageSecurityMode {
    match m {
        SecurityMode::None => MessageSecurityMode::None,
        SecurityMode::Sign => MessageSecurityMode::Sign,
        SecurityMode::SignAndEncrypt => MessageSecurityMode::SignAndEncrypt,
    }
}

/// Explains a status code a server answered a session with.
pub fn explain(code: StatusCode) -> String {
    let what = if code == StatusCode::BadIdentityTokenRejected || code == StatusCode::BadUserAccessDenied {
        " (wrong user name or password)"
    } else if code == StatusCode::BadIdentityTokenInvalid {
        " (the server does not accept this kind of login here)"
    } else if code == StatusCode::BadCertificateUntrusted {
        " (a certificate is not trusted: the server's is kept in the client's pki rejected/ folder until moved to trusted/, or the server refused ours)"
    } else if code == StatusCode::BadSecurityChecksFailed {
        " (security checks failed: a certificate refused before, still in a pki rejected/ folder — the server's or ours — or an invalid one)"
    } else if code == StatusCode::BadTcpEndpointUrlInvalid {
        " (the server offers no endpoint with this security policy and mode)"
    } else if code == StatusCode::BadNotConnected || code == StatusCode::BadCommunicationError {
        " (the server cannot be reached)"
    } else {
        ""
    };
    format!("{code}{what}")
}

/// The client of one connection attempt (a fresh one each time: its
/// certificate store rereads `trusted/`).
fn client(pki: &Path) -> Result<Client, String> {
    ClientBuilder::new()
        .application_name("Alba")
        .application_uri("urn:alba:client")
        .product_uri("urn:alba")
        .pki_dir(pki)
        .create_sample_keypair(true)
        .trust_server_certs(false)
        .verify_server_certs(true)
        .session_retry_limit(0)
        .keep_alive_interval(Duration::from_secs(2))
        .max_failed_keep_alive_count(2)
        .request_timeout(Duration::from_secs(5))
        .session_timeout(60_000)
        .client()
        .map_err(|e| format!("OPC UA client settings: {}", e.join("; ")))
}

/// Whether `text` is a node id, `nsu=URI;` forms included (their URI is
/// resolved on a session).
pub fn is_node_id(text: &str) -> bool {
    match text.strip_prefix("nsu=") {
        Some(rest) => rest
            .split_once(';')
            .is_some_and(|(uri, id)| !uri.is_empty() && NodeId::from_str(&format!("ns=1;{id}")).is_ok()),
        None => NodeId::from_str(text).is_ok(),
    }
}

/// Parses a node id, resolving `nsu=URI;` with the session's namespace array.
async fn node_id(session: &Session, text: &str) -> Result<NodeId, String> {
    let text = match text.strip_prefix("nsu=").and_then(|r| r.split_once(';')) {
        Some((uri, rest)) => {
            let ns = session
                .get_namespace_index(uri)
                .await
                .map_err(|e| format!("namespace {uri}: {e}"))?;
            format!("ns={ns};{rest}")
        }
        None => text.to_string(),
    };
    NodeId::from_str(&text).map_err(|_| format!("`{text}` is not a node id"))
}

enum Event {
    Connected,
    Lost(StatusCode),
    Failed(StatusCode),
}

/// One server, until `closing`: connect, serve, back off, again.
async fn run_conn(c: Conn, sh: Arc<ConnShared>, mut closing: tokio::sync::watch::Receiver<bool>) {
    let mut backoff = BACKOFF_FIRST;
    loop {
        if *closing.borrow() {
            return;
        }
        match session_once(&c, &sh, &mut closing).await {
            Ok(()) => return,
            Err((msg, was_up)) => {
                sh.errors.fetch_add(1, Ordering::Relaxed);
                let mut changed = false;
                sh.set(|s| {
                    changed = s.ok || s.connected || s.last_error.as_deref() != Some(msg.as_str());
                    s.ok = false;
                    s.connected = false;
                    s.errors += 1;
                    s.last_error = Some(msg.clone());
                });
                if changed {
                    eprintln!("OPC UA client {}: {} — {msg}", c.cfg.name, c.cfg.endpoint);
                }
                if was_up {
                    backoff = BACKOFF_FIRST;
                }
            }
        }
        tokio::select! {
            _ = tokio::time::sleep(backoff) => {}
            _ = closing.changed() => {}
        }
        backoff = (backoff * 2).min(BACKOFF_MAX);
    }
}

/// One session: `Ok` when closing, else why it ended and whether it had
/// been up.
async fn session_once(
    c: &Conn,
    sh: &Arc<ConnShared>,
    closing: &mut tokio::sync::watch::Receiver<bool>,
) -> Result<(), (String, bool)> {
    let down = |m: String| (m, false);
    let mut client = client(&c.pki).map_err(down)?;
    let identity = identity(&c.cfg, &c.dir).map_err(down)?;
    let endpoint = (c.cfg.endpoint.as_str(), policy(c.cfg.policy).to_uri(), mode(c.cfg.mode));
    let (session, event_loop) = tokio::select! {
        r = client.connect_to_matching_endpoint(endpoint, identity) => r.map_err(|e| down(format!("cannot connect: {}", explain(e.status()))))?,
        _ = closing.changed() => return Ok(()),
    };
    let (ev_tx, mut ev_rx) = tokio::sync::mpsc::unbounded_channel();
    let driver = tokio::spawn(async move {
        let stream = event_loop.enter();
        futures::pin_mut!(stream);
        while let Some(r) = stream.next().await {
            let ev = match r {
                Ok(SessionPollResult::Reconnected(_)) => Event::Connected,
                Ok(SessionPollResult::ConnectionLost(c)) => Event::Lost(c),
                Ok(_) => continue,
                Err(c) => Event::Failed(c),
            };
            let end = !matches!(ev, Event::Connected);
            let _ = ev_tx.send(ev);
            if end {
                break;
            }
        }
        let _ = ev_tx.send(Event::Lost(StatusCode::BadConnectionClosed));
    });
    let r = serve(c, sh, &session, &mut ev_rx, closing).await;
    *lock(&sh.session) = None;
    if r.is_ok() {
        // Closing: the safe outputs, then a clean goodbye.
        let _ = tokio::time::timeout(Duration::from_secs(2), async {
            write_safe(c, &session).await;
            let _ = session.disconnect().await;
        })
        .await;
    }
    driver.abort();
    r
}

async fn write_safe(c: &Conn, session: &Session) {
    let mut writes = Vec::new();
    for b in &c.outputs {
        let Ok(id) = node_id(session, &b.node).await else {
            continue;
        };
        let like = read_values(session, std::slice::from_ref(&id)).await.ok();
        let like = like.as_ref().and_then(|v| v.first()).and_then(|d| d.value.as_ref());
        writes.push(write_value(id, to_variant(zero(b.place.data_type()), like)));
    }
    if !writes.is_empty() {
        let _ = session.write(&writes).await;
    }
}

fn write_value(node_id: NodeId, v: Variant) -> WriteValue {
    WriteValue {
        node_id,
        attribute_id: AttributeId::Value as u32,
        value: DataValue::value_only(v),
        ..Default::default()
    }
}

async fn read_values(session: &Session, ids: &[NodeId]) -> Result<Vec<DataValue>, String> {
    let reads: Vec<ReadValueId> = ids.iter().map(|id| ReadValueId::from(id.clone())).collect();
    session
        .read(&reads, TimestampsToReturn::Neither, 0.0)
        .await
        .map_err(|e| format!("read: {}", explain(e.status())))
}

/// Runs a connected session: the subscription, the outputs, then waits.
async fn serve(
    c: &Conn,
    sh: &Arc<ConnShared>,
    session: &Arc<Session>,
    ev: &mut tokio::sync::mpsc::UnboundedReceiver<Event>,
    closing: &mut tokio::sync::watch::Receiver<bool>,
) -> Result<(), (String, bool)> {
    // Wait for the session to open (or fail: a refused login, an untrusted certificate).
    tokio::select! {
        e = ev.recv() => match e {
            Some(Event::Connected) => {}
            Some(Event::Failed(code)) | Some(Event::Lost(code)) => {
                return Err((format!("session refused: {}", explain(code)), false));
            }
            None => return Err(("session ended".into(), false)),
        },
        _ = closing.changed() => return Ok(()),
    }
    // Browses use this session while it is open.
    *lock(&sh.session) = Some(session.clone());
    let up = |m: String| (m, true);
    let mut problems: Vec<String> = Vec::new();
    // Inputs: one subscription, a monitored item per node.
    let mut in_ids: Vec<Option<NodeId>> = Vec::new();
    for b in &c.inputs {
        match node_id(session, &b.node).await {
            Ok(id) => in_ids.push(Some(id)),
            Err(e) => {
                problems.push(format!("input {}: {e}", b.tag));
                in_ids.push(None);
            }
        }
    }
    if in_ids.iter().any(Option::is_some) {
        let mut by_node: HashMap<NodeId, Vec<(usize, DataType)>> = HashMap::new();
        for (k, id) in in_ids.iter().enumerate() {
            if let (Some(id), Some(b)) = (id, c.inputs.get(k)) {
                by_node.entry(id.clone()).or_default().push((k, b.place.data_type()));
            }
        }
        let target = sh.clone();
        let callback = DataChangeCallback::new(move |dv: DataValue, item: &MonitoredItem| {
            let Some(slots) = by_node.get(&item.item_to_monitor().node_id) else {
                return;
            };
            let good = dv.status.is_none_or(|s| s.is_good());
            let Some(v) = dv.value.as_ref().filter(|_| good) else {
                return; // a bad sample: the input keeps its value
            };
            let mut inputs = lock(&target.inputs);
            for (k, t) in slots {
                if let (Some(slot), Some(x)) = (inputs.get_mut(*k), to_value(v, *t)) {
                    *slot = Some(x);
                }
            }
        });
        let interval = Duration::from_millis(u64::from(c.cfg.publishing_interval_ms));
        let sub = session
            .create_subscription(interval, 60, 10, 0, 0, true, callback)
            .await
            .map_err(|e| up(format!("cannot create the subscription: {}", explain(e.status()))))?;
        let items: Vec<MonitoredItemCreateRequest> = in_ids
            .iter()
            .flatten()
            .map(|id| {
                let mut r = MonitoredItemCreateRequest::from(id.clone());
                r.requested_parameters.sampling_interval = interval.as_secs_f64() * 1000.0;
                r.requested_parameters.queue_size = 1;
                r
            })
            .collect();
        let created = session
            .create_monitored_items(sub, TimestampsToReturn::Neither, items)
            .await
            .map_err(|e| up(format!("cannot monitor the inputs: {}", explain(e.status()))))?;
        let named = c.inputs.iter().zip(&in_ids).filter(|(_, id)| id.is_some());
        for ((b, _), r) in named.zip(&created) {
            if !r.result.status_code.is_good() {
                problems.push(format!("input {} ({}): {}", b.tag, b.node, r.result.status_code));
            }
        }
    }
    // Outputs: their nodes' types, then every current value.
    let mut outs: Vec<Option<(NodeId, Option<Variant>)>> = Vec::new();
    for b in &c.outputs {
        match node_id(session, &b.node).await {
            Ok(id) => {
                let read = read_values(session, std::slice::from_ref(&id)).await.map_err(up)?;
                let dv = read.into_iter().next().unwrap_or_default();
                match dv.status {
                    Some(s) if !s.is_good() => {
                        problems.push(format!("output {} ({}): {s}", b.tag, b.node));
                        outs.push(None);
                    }
                    _ => outs.push(Some((id, dv.value))),
                }
            }
            Err(e) => {
                problems.push(format!("output {}: {e}", b.tag));
                outs.push(None);
            }
        }
    }
    sh.set(|s| {
        s.connected = true;
        s.connects += 1;
        s.ok = problems.is_empty();
        s.last_error = if problems.is_empty() {
            None
        } else {
            Some(problems.join("; "))
        };
    });
    if problems.is_empty() {
        eprintln!("OPC UA client {}: connected to {}", c.cfg.name, c.cfg.endpoint);
    } else {
        eprintln!(
            "OPC UA client {}: connected to {}, with refused bindings: {}",
            c.cfg.name,
            c.cfg.endpoint,
            problems.join("; ")
        );
    }
    // After a (re)connection every output is written.
    let mut sent: Vec<Option<Value>> = vec![None; c.outputs.len()];
    let mut write_errors: Vec<Option<String>> = vec![None; c.outputs.len()];
    loop {
        let now = lock(&sh.outputs).values.clone();
        let mut writes = Vec::new();
        let mut which = Vec::new();
        for (k, v) in now.iter().enumerate() {
            if let (Some(v), Some(Some((id, like)))) = (v, outs.get(k))
                && sent.get(k) != Some(&Some(*v))
            {
                writes.push(write_value(id.clone(), to_variant(*v, like.as_ref())));
                which.push((k, *v));
            }
        }
        if !writes.is_empty() {
            let codes = session
                .write(&writes)
                .await
                .map_err(|e| up(format!("write: {}", explain(e.status()))))?;
            for ((k, v), code) in which.iter().zip(codes) {
                if let Some(s) = sent.get_mut(*k) {
                    *s = Some(*v);
                }
                let b = &c.outputs[*k];
                let err = (!code.is_good()).then(|| format!("output {} ({}): {code}", b.tag, b.node));
                if let Some(e) = write_errors.get_mut(*k) {
                    *e = err;
                }
            }
            let all: Vec<String> = problems
                .iter()
                .cloned()
                .chain(write_errors.iter().flatten().cloned())
                .collect();
            sh.set(|s| {
                s.ok = all.is_empty();
                s.last_error = (!all.is_empty()).then(|| all.join("; "));
            });
        }
        tokio::select! {
            _ = sh.dirty.notified() => {}
            e = ev.recv() => {
                let code = match e {
                    Some(Event::Lost(c)) | Some(Event::Failed(c)) => c,
                    _ => StatusCode::BadConnectionClosed,
                };
                return Err(up(format!("connection lost: {}", explain(code))));
            }
            _ = closing.changed() => return Ok(()),
        }
    }
}

/// A child of a browsed node.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Child {
    /// Its node id as the server answers it (`ns=2;s=Tank.Level`, `i=2253`).
    pub node: String,
    /// The same with the namespace's URI instead of its index
    /// (`nsu=urn:plant;s=Tank.Level`): what a binding should say, since a
    /// server may renumber its namespaces. `None` in namespace 0 (or when
    /// the namespace array cannot be read).
    pub node_uri: Option<String>,
    pub browse_name: String,
    pub display_name: String,
    /// `Object`, `Variable`, `Method`, …
    pub class: String,
    /// A variable's data type: a built-in type's name (`Double`, `Int32`,
    /// `Boolean`), else the type's node id; `None` for other classes (or
    /// when it cannot be read).
    pub data_type: Option<String>,
}

/// The name of a data type node (`Double`), or its id when not built in.
fn type_name(id: &NodeId) -> String {
    match (&id.identifier, id.namespace) {
        (Identifier::Numeric(n), 0) => match DataTypeId::try_from(*n) {
            Ok(t) => format!("{t:?}"),
            Err(_) => id.to_string(),
        },
        _ => id.to_string(),
    }
}

/// The children of `node` (hierarchical references, forward) on an open
/// session: what a tag picker shows, variables with their data type.
pub async fn browse(session: &Session, node: &str) -> Result<Vec<Child>, String> {
    let id = node_id(session, node).await?;
    let desc = BrowseDescription {
        node_id: id,
        browse_direction: BrowseDirection::Forward,
        reference_type_id: ReferenceTypeId::HierarchicalReferences.into(),
        include_subtypes: true,
        node_class_mask: NodeClassMask::all().bits(),
        result_mask: BrowseResultMask::All as u32,
    };
    let results = session
        .browse(&[desc], 1000, None)
        .await
        .map_err(|e| format!("browse: {}", explain(e.status())))?;
    let Some(r) = results.into_iter().next() else {
        return Ok(Vec::new());
    };
    if !r.status_code.is_good() {
        return Err(format!("browse {node}: {}", explain(r.status_code)));
    }
    let mut refs = r.references.unwrap_or_default();
    // More than a page: the rest (each page up to 1000; at most 20 pages,
    // the server's continuation point released when there are more).
    let mut next = r.continuation_point;
    let mut pages = 1;
    while !next.is_null_or_empty() {
        if pages == 20 {
            let _ = session.browse_next(true, &[next]).await;
            break;
        }
        pages += 1;
        let more = session
            .browse_next(false, &[next])
            .await
            .map_err(|e| format!("browse {node}: {}", explain(e.status())))?;
        let Some(m) = more.into_iter().next() else {
            break;
        };
        refs.extend(m.references.unwrap_or_default());
        next = m.continuation_point;
    }
    // Index → URI, for the `nsu=` form (best effort: one read).
    let uris: HashMap<u16, String> = match session.read_namespace_array().await {
        Ok(map) => map.known_namespaces().iter().map(|(u, i)| (*i, u.clone())).collect(),
        Err(_) => HashMap::new(),
    };
    // The variables' data types (best effort: one read for all).
    let vars: Vec<NodeId> = refs
        .iter()
        .filter(|x| x.node_class == NodeClass::Variable && x.node_id.server_index == 0)
        .map(|x| x.node_id.node_id.clone())
        .collect();
    let mut types: HashMap<NodeId, String> = HashMap::new();
    if !vars.is_empty() {
        let reads: Vec<ReadValueId> = vars
            .iter()
            .map(|id| ReadValueId {
                node_id: id.clone(),
                attribute_id: AttributeId::DataType as u32,
                ..Default::default()
            })
            .collect();
        if let Ok(values) = session.read(&reads, TimestampsToReturn::Neither, 0.0).await {
            for (id, dv) in vars.iter().zip(values) {
                if let Some(Variant::NodeId(t)) = dv.value {
                    types.insert(id.clone(), type_name(&t));
                }
            }
        }
    }
    Ok(refs
        .into_iter()
        .map(|x| {
            let id = x.node_id.node_id;
            let node_uri = uris
                .get(&id.namespace)
                .filter(|_| id.namespace != 0)
                .map(|u| format!("nsu={u};{}", id.identifier));
            Child {
                node: id.to_string(),
                node_uri,
                browse_name: x.browse_name.name.to_string(),
                display_name: x.display_name.text.to_string(),
                class: format!("{:?}", x.node_class),
                data_type: types.get(&id).cloned(),
            }
        })
        .collect())
}

/// Connects to `server` (as `alba run` would: same security, user and
/// PKI; `dir` is the project), browses `node` and disconnects.
pub async fn browse_server(server: &OpcuaServer, dir: &Path, node: &str) -> Result<Vec<Child>, String> {
    let identity = identity(server, dir)?;
    let mut client = client(&dir.join(&server.pki_dir))?;
    let endpoint = (
        server.endpoint.as_str(),
        policy(server.policy).to_uri(),
        mode(server.mode),
    );
    let (session, event_loop) = client
        .connect_to_matching_endpoint(endpoint, identity)
        .await
        .map_err(|e| format!("cannot connect: {}", explain(e.status())))?;
    // The session opens (or is refused: a wrong password, an untrusted
    // certificate) as the event loop runs: its first event says which.
    let (opened_tx, opened) = tokio::sync::oneshot::channel();
    let driver = tokio::spawn(async move {
        let stream = event_loop.enter();
        futures::pin_mut!(stream);
        let mut tx = Some(opened_tx);
        while let Some(r) = stream.next().await {
            let first = match r {
                Ok(SessionPollResult::Reconnected(_)) => Ok(()),
                Ok(SessionPollResult::ConnectionLost(c)) | Err(c) => Err(c),
                Ok(_) => continue,
            };
            let end = first.is_err();
            if let Some(t) = tx.take() {
                let _ = t.send(first);
            }
            if end {
                break;
            }
        }
    });
    let r = async {
        match tokio::time::timeout(Duration::from_secs(10), opened).await {
            Ok(Ok(Ok(()))) => browse(&session, node).await,
            Ok(Ok(Err(code))) => Err(format!("session refused: {}", explain(code))),
            Ok(Err(_)) => Err("session ended".to_string()),
            Err(_) => Err("the session did not open within 10 s".to_string()),
        }
    }
    .await;
    let _ = tokio::time::timeout(Duration::from_secs(2), session.disconnect()).await;
    driver.abort();
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remote_numbers_become_the_tags_type() {
        assert_eq!(to_value(&Variant::Double(2.6), DataType::Dint), Some(Value::Dint(3)));
        assert_eq!(
            to_value(&Variant::Int64(1 << 40), DataType::Int),
            Some(Value::Int(i16::MAX))
        );
        assert_eq!(to_value(&Variant::UInt16(7), DataType::Bool), Some(Value::Bool(true)));
        assert_eq!(to_value(&Variant::Float(1.5), DataType::Lreal), Some(Value::Lreal(1.5)));
        assert_eq!(to_value(&Variant::Double(f64::NAN), DataType::Real), None);
        assert_eq!(to_value(&Variant::from("text"), DataType::Dint), None);
    }

    #[test]
    fn tag_values_are_written_with_the_nodes_type() {
        assert_eq!(
            to_variant(Value::Dint(300), Some(&Variant::Byte(0))),
            Variant::Byte(255)
        );
        assert_eq!(
            to_variant(Value::Bool(true), Some(&Variant::Double(0.0))),
            Variant::Double(1.0)
        );
        assert_eq!(
            to_variant(Value::Real(2.5), Some(&Variant::Int32(0))),
            Variant::Int32(3)
        );
        assert_eq!(to_variant(Value::Int(-4), None), Variant::Int16(-4));
        assert_eq!(zero(DataType::Bool), Value::Bool(false));
    }

    #[test]
    fn node_ids_are_checked_before_browsing() {
        for ok in ["i=85", "ns=2;s=Tank.Level", "nsu=urn:alba:plant;s=Speed", "ns=1;i=5"] {
            assert!(is_node_id(ok), "{ok}");
        }
        for bad in ["", "not a node", "nsu=;s=x", "nsu=urn:x", "ns=x;s=y"] {
            assert!(!is_node_id(bad), "{bad}");
        }
    }

    #[test]
    fn data_types_are_named() {
        assert_eq!(type_name(&NodeId::new(0, 11u32)), "Double");
        assert_eq!(type_name(&NodeId::new(0, 1u32)), "Boolean");
        assert_eq!(type_name(&NodeId::new(2, 3001u32)), "ns=2;i=3001");
    }
}
