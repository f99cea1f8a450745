//! The Modbus TCP server: connections accepted on the caller's tokio
//! runtime, each then served by a thread of its own, reading the runtime's latest snapshot and sending writes to the
//! engine thread, which applies them between two scans.
//!
//! Nothing here holds a lock the engine thread takes: reads borrow the
//! published snapshot (an `Arc`), writes wait for the engine's answer on a
//! oneshot channel, so a slow or hostile client delays only itself.

use alba_control::{Actor, Control, Refused};
use alba_ir::Program;
use alba_modbus_proto::handler::{Plan, Then, plan, read};
use alba_modbus_proto::map::{Map, Scratch, Write};
use alba_modbus_proto::mbap::{self, Header, Split};
use alba_modbus_proto::pdu::{self, Exception, Request};
use alba_project::config::{ModbusArea, ModbusTag};
use alba_runtime::Handle;
use alba_settings::{IpRange, Modbus};
use std::io::{ErrorKind, Read, Write as _};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use std::time::Instant;
use tokio::net::TcpListener;
use tokio::sync::{Semaphore, watch};

/// How the server behaves (from `[modbus]`).
#[derive(Debug, Clone)]
pub struct Settings {
    pub max_connections: usize,
    /// Close a connection with no complete request for this long.
    pub idle_timeout: Option<Duration>,
    /// Answer only this unit id (and 0 and 255).
    pub unit_id: Option<u8>,
    /// `[modbus.tags]`: the project's explicit addresses (`From<&Modbus>`
    /// leaves them empty: they are not the server's settings).
    pub tags: Vec<ModbusTag>,
    /// The clients served (`None`: every client; see [`check_listen`]).
    /// Others are disconnected at once, before any request is read.
    pub allow: Option<Vec<IpRange>>,
    /// Every write function code answers exception 01 (illegal function).
    pub read_only: bool,
}

/// Why the server refuses to listen on an address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NotLoopback(pub std::net::SocketAddr);

impl std::fmt::Display for NotLoopback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "refusing to serve Modbus TCP on {}: Modbus has no authentication, so an address beyond loopback needs an allow-list of clients: add `allow = [\"192.168.1.20\", \"10.0.0.0/24\"]` (the clients' addresses or ranges) to [modbus] in alba.toml, or listen on 127.0.0.1 (docs/security.md, \"Modbus\")",
            self.0
        )
    }
}

impl std::error::Error for NotLoopback {}

/// The listen rule (docs/security.md): loopback always; any other address
/// only with an allow-list of clients.
pub fn check_listen(addr: std::net::SocketAddr, allow: Option<&[IpRange]>) -> Result<(), NotLoopback> {
    if addr.ip().to_canonical().is_loopback() || allow.is_some() {
        Ok(())
    } else {
        Err(NotLoopback(addr))
    }
}

impl Settings {
    /// Whether a client at `ip` is served.
    pub fn allows(&self, ip: std::net::IpAddr) -> bool {
        self.allow
            .as_ref()
            .is_none_or(|list| list.iter().any(|r| r.contains(ip)))
    }
}

impl From<&Modbus> for Settings {
    fn from(m: &Modbus) -> Settings {
        Settings {
            max_connections: m.max_connections as usize,
            idle_timeout: (m.idle_timeout_s > 0).then(|| Duration::from_secs(u64::from(m.idle_timeout_s))),
            unit_id: m.unit_id,
            tags: Vec::new(),
            allow: m.allow.clone(),
            read_only: m.read_only,
        }
    }
}

impl Default for Settings {
    fn default() -> Settings {
        Settings::from(&Modbus::default())
    }
}

/// Counters, for tests and status.
#[derive(Debug, Default)]
pub struct Counters {
    pub connections: AtomicU64,
    /// Connections closed at once because `max_connections` were open.
    pub refused: AtomicU64,
    /// Connections closed at once because the client is not in `allow`.
    pub denied: AtomicU64,
    pub requests: AtomicU64,
    pub exceptions: AtomicU64,
    /// Connections closed for a frame that is not Modbus TCP.
    pub invalid: AtomicU64,
    pub timeouts: AtomicU64,
}

/// A server over one runtime, writing through the control layer.
pub struct Server {
    control: Control,
    handle: Handle,
    settings: Settings,
    scratch: Scratch,
    /// The map of the program last seen (rebuilt after an online edit).
    map: Mutex<Option<(Arc<Program>, Arc<Map>)>>,
    pub counters: Counters,
}

/// A connection's copy of the map and the program it was made for.
type MapCache = Option<(Arc<Program>, Arc<Map>)>;

/// A reply never waits longer than this for the client to take it.
const WRITE_TIMEOUT: Duration = Duration::from_secs(10);

impl Server {
    /// A server whose writes go through `control`: every client is the
    /// actor `modbus:<address>` (role `operator`, `viewer` when read-only),
    /// each write checked and recorded in the audit trail before it is
    /// applied (docs/audit.md, "Modbus").
    pub fn new(control: Control, settings: Settings) -> Arc<Server> {
        Arc::new(Server {
            handle: control.runtime().clone(),
            control,
            settings,
            scratch: Scratch::default(),
            map: Mutex::new(None),
            counters: Counters::default(),
        })
    }

    /// The map for `program`: the connection's own copy while the program
    /// is the same (no lock per request), else the shared one.
    fn map_for(&self, program: &Arc<Program>, cache: &mut Option<(Arc<Program>, Arc<Map>)>) -> Arc<Map> {
        if let Some((p, map)) = cache.as_ref()
            && Arc::ptr_eq(p, program)
        {
            return map.clone();
        }
        let map = self.shared_map(program);
        *cache = Some((program.clone(), map.clone()));
        map
    }

    fn shared_map(&self, program: &Arc<Program>) -> Arc<Map> {
        let mut m = self.map.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((p, map)) = m.as_ref()
            && Arc::ptr_eq(p, program)
        {
            return map.clone();
        }
        // The compiler checked the entries (E106); any refused here are left out.
        let map = Arc::new(Map::build(&program.layout, &self.settings.tags).0);
        *m = Some((program.clone(), map.clone()));
        map
    }

    /// Accepts connections until `closing` turns true. Each connection is
    /// served by a thread of its own doing blocking reads and writes (the
    /// design measured fastest: docs/performance.md, "The Modbus TCP server
    /// under load"); at most `max_connections` of them.
    pub async fn serve(self: Arc<Self>, listener: TcpListener, mut closing: watch::Receiver<bool>) {
        let slots = Arc::new(Semaphore::new(self.settings.max_connections));
        let open = Arc::new(Open::default());
        loop {
            if *closing.borrow() {
                open.close_all();
                return;
            }
            let accepted = tokio::select! {
                r = listener.accept() => r,
                _ = closing.changed() => {
                    open.close_all();
                    return;
                }
            };
            let sock = match accepted {
                Ok((s, peer)) if self.settings.allows(peer.ip()) => s,
                Ok((s, _)) => {
                    // Not a client of the allow-list: closed before a byte is read.
                    self.counters.denied.fetch_add(1, Ordering::Relaxed);
                    drop(s);
                    continue;
                }
                Err(_) => {
                    // Out of file descriptors and the like: wait, do not spin.
                    tokio::time::sleep(Duration::from_millis(20)).await;
                    continue;
                }
            };
            let Ok(permit) = slots.clone().try_acquire_owned() else {
                self.counters.refused.fetch_add(1, Ordering::Relaxed);
                drop(sock);
                continue;
            };
            let Some((sock, id)) = sock
                .into_std()
                .ok()
                .filter(|s| s.set_nonblocking(false).is_ok())
                .and_then(|s| open.add(&s).map(|id| (s, id)))
            else {
                continue;
            };
            self.counters.connections.fetch_add(1, Ordering::Relaxed);
            let me = self.clone();
            let open2 = open.clone();
            let spawned = std::thread::Builder::new().name("modbus-conn".into()).spawn(move || {
                me.connection(sock);
                open2.remove(id);
                drop(permit);
            });
            if spawned.is_err() {
                open.remove(id);
            }
        }
    }

    /// Serves one connection until the client closes it, sends a frame that
    /// is not Modbus TCP, stays idle too long or the server closes.
    fn connection(&self, sock: std::net::TcpStream) {
        let Ok(peer) = sock.peer_addr() else { return };
        let role = if self.settings.read_only {
            alba_auth::Role::Viewer
        } else {
            alba_auth::Role::Operator
        };
        let actor = Actor::modbus(peer, role);
        self.converse(&actor, sock);
        // The writes coalesced into this second's rows are recorded now.
        self.control.flush(&actor);
    }

    fn converse(&self, actor: &Actor, mut sock: std::net::TcpStream) {
        let _ = sock.set_nodelay(true);
        let _ = sock.set_write_timeout(Some(WRITE_TIMEOUT));
        let idle = self.settings.idle_timeout;
        // A read returns at the idle timeout at the latest.
        if sock.set_read_timeout(idle).is_err() {
            return;
        }
        // Frames are at most 260 bytes; whole ones are answered before the next read.
        let mut buf = [0u8; 4096];
        let mut filled = 0;
        let mut out: Vec<u8> = Vec::with_capacity(4096);
        let mut deadline = idle.map(|d| Instant::now() + d);
        let mut cache = None;
        loop {
            // Every complete request in the buffer, answered in order.
            let mut pos = 0;
            let mut invalid = false;
            loop {
                match mbap::split(&buf[pos..filled]) {
                    Split::Incomplete => break,
                    Split::Invalid(_) => {
                        invalid = true;
                        break;
                    }
                    Split::Frame { header, pdu, len } => {
                        self.request(actor, header, pdu, &mut out, &mut cache);
                        pos += len;
                    }
                }
            }
            if pos > 0 {
                buf.copy_within(pos..filled, 0);
                filled -= pos;
                deadline = idle.map(|d| Instant::now() + d);
            }
            if !out.is_empty() {
                if sock.write_all(&out).is_err() {
                    return;
                }
                out.clear();
            }
            if invalid {
                self.counters.invalid.fetch_add(1, Ordering::Relaxed);
                return;
            }
            match sock.read(&mut buf[filled..]) {
                Ok(0) => return,
                Ok(n) => filled += n,
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(_) => return,
            }
            // Bytes that never make a whole request do not keep it open.
            if deadline.is_some_and(|d| Instant::now() >= d) {
                self.counters.timeouts.fetch_add(1, Ordering::Relaxed);
                return;
            }
        }
    }

    /// Answers one request onto `out`.
    fn request(&self, actor: &Actor, h: Header, pdu: &[u8], out: &mut Vec<u8>, cache: &mut MapCache) {
        self.counters.requests.fetch_add(1, Ordering::Relaxed);
        let fc = pdu.first().copied().unwrap_or(0);
        let at = mbap::begin(out, h);
        out.push(fc);
        let result = match self.settings.unit_id {
            Some(u) if h.unit != u && h.unit != 0 && h.unit != 255 => Err(Exception::GatewayTargetFailed),
            // Read-only: refused by its function code, before its data is looked at.
            _ if self.settings.read_only && pdu::is_write_function(fc) => Err(Exception::IllegalFunction),
            _ => match pdu::parse(pdu) {
                Ok(req) => self.answer(actor, req, out, cache),
                Err(e) => Err(e),
            },
        };
        match result {
            Ok(()) => mbap::end(out, at),
            Err(e) => {
                self.counters.exceptions.fetch_add(1, Ordering::Relaxed);
                mbap::exception(out, at, h, fc, e);
            }
        }
    }

    /// The data of the reply to `req` (after the function code).
    fn answer(
        &self,
        actor: &Actor,
        req: Request<'_>,
        out: &mut Vec<u8>,
        cache: &mut MapCache,
    ) -> Result<(), Exception> {
        let snap = self.handle.snapshot();
        let map = self.map_for(&snap.program, cache);
        let Plan::Write { writes, then } = plan(req, &map, &snap.memory, &self.scratch, out)? else {
            return Ok(());
        };
        self.apply(actor, writes)?;
        match then {
            Then::Echo(echo) => {
                out.extend_from_slice(&echo);
                Ok(())
            }
            Then::ReadRegs { start, count } => {
                // The read sees the write: the engine published before answering.
                let snap = self.handle.snapshot();
                let map = self.map_for(&snap.program, cache);
                read(
                    &map,
                    &snap.memory,
                    &self.scratch,
                    ModbusArea::HoldingRegister,
                    start,
                    count,
                    out,
                )
            }
        }
    }

    /// Applies checked writes: engine places at the next scan boundary (all
    /// of them at the same one), Modbus-only storage at once.
    fn apply(&self, actor: &Actor, writes: Vec<Write>) -> Result<(), Exception> {
        let engine: Vec<_> = writes
            .iter()
            .filter_map(|w| match *w {
                Write::Engine(p, v) => Some((p, v)),
                _ => None,
            })
            .collect();
        if !engine.is_empty() {
            self.control
                .write_places_blocking(actor, engine)
                .map_err(|e| exception(&e))?;
        }
        for w in &writes {
            self.scratch.apply(w);
        }
        Ok(())
    }
}

/// The exception that answers a refusal of the control layer (the one
/// place where Modbus meets its rules; docs/protocols.md).
pub fn exception(r: &Refused) -> Exception {
    match r {
        Refused::UnknownTag(_)
        | Refused::NotWritable(_)
        | Refused::NotForceable(_)
        | Refused::NotForced(_)
        | Refused::UnknownAlarm(_) => Exception::IllegalDataAddress,
        Refused::WrongType(_) | Refused::OutOfRange(_) => Exception::IllegalDataValue,
        Refused::Role { .. } => Exception::IllegalFunction,
        Refused::Runtime(alba_runtime::Error::Busy) => Exception::ServerDeviceBusy,
        Refused::AuditUnavailable(_)
        | Refused::Runtime(_)
        | Refused::NotApplied(_)
        | Refused::Alarm(_)
        | Refused::Internal(_) => Exception::ServerDeviceFailure,
    }
}

/// The open connections, so that closing the server closes them (their
/// threads are blocked in a read).
#[derive(Default)]
struct Open {
    next: AtomicU64,
    socks: Mutex<Vec<(u64, std::net::TcpStream)>>,
}

impl Open {
    fn add(&self, s: &std::net::TcpStream) -> Option<u64> {
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        let clone = s.try_clone().ok()?;
        self.socks.lock().unwrap_or_else(|e| e.into_inner()).push((id, clone));
        Some(id)
    }

    fn remove(&self, id: u64) {
        self.socks
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .retain(|(i, _)| *i != id);
    }

    fn close_all(&self) {
        for (_, s) in self.socks.lock().unwrap_or_else(|e| e.into_inner()).drain(..) {
            let _ = s.shutdown(std::net::Shutdown::Both);
        }
    }
}
