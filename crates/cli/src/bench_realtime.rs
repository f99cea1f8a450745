//! `alba bench --realtime`: how steadily the real engine thread scans, the
//! way `cyclictest` measures a kernel: the start lateness of every scan
//! (scan start − its deadline) of `alba run` itself, run in this process on
//! a generated project of 1 000 rungs (the `alba bench` rung, native code),
//! at periods of 1 ms and 10 ms, with the engine at normal priority and at
//! SCHED_FIFO (`[runtime] priority`, `lock_memory`, `cpu`), and each of
//! those idle and under real protocol load generated here, on loopback:
//!
//! - 4 Modbus TCP clients sending FC3 × 10 registers back to back,
//! - 2 HTTP clients requesting `GET /api/status` back to back (a connection each),
//! - 20 WebSocket clients subscribed to 100 tags each, half of them also
//!   monitoring the ladder's power flow,
//! - an OPC UA session subscribed to 100 variables (10 ms sampling, 100 ms publishing),
//! - the historian recording every tag of the project.
//!
//! The Modbus, OPC UA and HTTP servers run in both cases (idle: nobody
//! connects; the historian is off). Prints, per row, p50 / p99 / p99.9 / max
//! lateness, the deadlines missed (overruns) and the load actually served.
//! The engine's lateness is recorded by the runtime itself
//! (`alba_runtime::ScanLog`: preallocated, atomic stores, no lock).

use crate::bench_modbus;
use alba_runtime::ScanLog;
use alba_runtime::realtime::Realtime;
use futures_util::{SinkExt, StreamExt};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;

const RUNGS: usize = 1000;
const MODBUS_CLIENTS: usize = 4;
const HTTP_CLIENTS: usize = 2;
const WS_CLIENTS: usize = 20;
/// Tags per WebSocket client and variables of the OPC UA subscription.
const WATCHED: usize = 100;
const PROJECT: &str = "rt-bench";

pub fn run(secs: f64, priority: u8, cpu: Option<usize>) -> ExitCode {
    if !(0.1..=3600.0).contains(&secs) || priority == 0 || priority > 99 {
        eprintln!("error: --seconds 0.1 to 3600; --priority 1 to 99");
        return ExitCode::FAILURE;
    }
    let dir = std::env::temp_dir().join(format!("alba-bench-realtime-{}", std::process::id()));
    let r = measure_all(&dir, secs, priority, cpu);
    let _ = std::fs::remove_dir_all(&dir);
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn measure_all(dir: &Path, secs: f64, priority: u8, cpu: Option<usize>) -> Result<(), String> {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let (tags, lad) = crate::bench::generate(RUNGS);
    for (f, text) in [("tags.csv", tags), ("main.lad", lad)] {
        std::fs::write(dir.join(f), text).map_err(|e| e.to_string())?;
    }
    println!(
        "alba bench --realtime: start lateness of every scan of `alba run` ({RUNGS} generated rungs, native code), {secs} s per row"
    );
    println!(
        "load \"protocols\": {MODBUS_CLIENTS} Modbus TCP clients (FC3 x 10, back to back), {HTTP_CLIENTS} HTTP clients \
         (GET /api/status), {WS_CLIENTS} WebSocket clients ({WATCHED} tags each, half monitoring power flow), \
         an OPC UA subscription ({WATCHED} variables), the historian recording every tag; all in this process, on loopback\n"
    );
    println!(
        "{:>7} {:>9} {:<32} {:>6} {:>8} {:>8} {:>9} {:>9} {:>8}  served during the row",
        "period", "load", "engine thread", "scans", "p50 µs", "p99 µs", "p99.9 µs", "max µs", "overruns"
    );
    for period_ms in [1u32, 10] {
        for loaded in [false, true] {
            for fifo in [false, true] {
                let rt = Realtime {
                    priority: if fifo { priority } else { 0 },
                    cpu,
                    lock_memory: fifo,
                };
                let row = row(dir, period_ms, loaded, rt, secs)?;
                if fifo {
                    alba_runtime::realtime::unlock_memory();
                }
                let mut late = row.late_ns;
                late.sort_unstable();
                println!(
                    "{:>4} ms {:>9} {:<32} {:>6} {:>8.1} {:>8.1} {:>9.1} {:>9.1} {:>8}  {}",
                    period_ms,
                    if loaded { "protocols" } else { "idle" },
                    row.sched,
                    late.len(),
                    pct(&late, 0.5),
                    pct(&late, 0.99),
                    pct(&late, 0.999),
                    pct(&late, 1.0),
                    row.overruns,
                    row.served
                );
            }
        }
    }
    Ok(())
}

/// What one row measured.
struct Row {
    late_ns: Vec<u64>,
    overruns: u64,
    /// The engine thread's scheduling as the kernel reports it.
    sched: String,
    /// The load served, for the reader.
    served: String,
}

fn alba_toml(period_ms: u32, history: bool, rt: Realtime) -> String {
    let mut t = format!("name = \"{PROJECT}\"\nscan_ms = {period_ms}\nprograms = [\"main.lad\"]\n\n[runtime]\n");
    if rt.priority > 0 {
        t.push_str(&format!("priority = {}\n", rt.priority));
    }
    if let Some(c) = rt.cpu {
        t.push_str(&format!("cpu = {c}\n"));
    }
    t.push_str(&format!(
        "lock_memory = {}\n\n[history]\nenabled = {history}\n\n[modbus]\nmax_connections = 64\n\n[modbus.tags]\n",
        rt.lock_memory
    ));
    for k in 0..5 {
        t.push_str(&format!("V_{k} = \"hr {}\"\n", 8192 + 2 * k));
    }
    t
}

/// A loopback port free right now.
fn free_port() -> Result<SocketAddr, String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    l.local_addr().map_err(|e| e.to_string())
}

fn row(dir: &Path, period_ms: u32, loaded: bool, rt: Realtime, secs: f64) -> Result<Row, String> {
    std::fs::write(dir.join("alba.toml"), alba_toml(period_ms, loaded, rt)).map_err(|e| e.to_string())?;
    // Each row records into a history of its own.
    for f in ["history.db", "history.db-wal", "history.db-shm"] {
        let _ = std::fs::remove_file(dir.join(".alba").join(f));
    }
    let (modbus, opcua) = (free_port()?, free_port()?);
    let scans = (secs * 1000.0 / f64::from(period_ms)).ceil() as usize;
    let log = ScanLog::new(2 * scans + 1000);
    let opts = alba_app::Options {
        addr: "127.0.0.1:0".parse().map_err(|e| format!("{e}"))?,
        io: "sim".into(),
        native: true,
        modbus: Some(modbus),
        opcua: Some(opcua),
        mqtt: None,
        tls: alba_app::tls::Tls::Never,
        scan_log: Some(log.clone()),
        quiet: true,
    };
    let server = Server::start(dir.to_path_buf(), opts)?;
    let r = (|| {
        // Warm-up: first scans, page faults, the clients' connections (the
        // OPC UA session's subscription takes longest); shorter for short rows.
        let warm = |ms: f64| Duration::from_secs_f64((ms / 1000.0).min(secs));
        std::thread::sleep(warm(300.0));
        let load = loaded.then(|| Load::start(server.http, modbus, opcua));
        std::thread::sleep(warm(if loaded { 700.0 } else { 200.0 }));
        let measuring = load.as_ref().map(|l| l.measuring.clone());
        let t0 = Instant::now();
        log.record(true);
        if let Some(m) = &measuring {
            m.store(true, Ordering::Relaxed);
        }
        std::thread::sleep(Duration::from_secs_f64(secs));
        log.record(false);
        if let Some(m) = &measuring {
            m.store(false, Ordering::Relaxed);
        }
        let wall = t0.elapsed().as_secs_f64();
        let sched = engine_scheduling();
        let served = match load {
            Some(l) => l.stop(wall)?,
            None => "-".into(),
        };
        Ok::<_, String>(Row {
            late_ns: log.late_ns(),
            overruns: log.overruns(),
            sched,
            served,
        })
    })();
    server.stop()?;
    r
}

/// `alba run` of the project on a tokio runtime of its own, as the command runs it.
struct Server {
    http: SocketAddr,
    stop: tokio::sync::oneshot::Sender<()>,
    thread: std::thread::JoinHandle<Result<(), String>>,
}

impl Server {
    fn start(dir: PathBuf, opts: alba_app::Options) -> Result<Server, String> {
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let (stop, stop_rx) = tokio::sync::oneshot::channel::<()>();
        let thread = std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_multi_thread()
                .worker_threads(2)
                .enable_all()
                .build()
                .map_err(|e| e.to_string())?;
            let r = rt.block_on(alba_app::run(
                &dir,
                opts,
                move |a| {
                    let _ = ready_tx.send(a);
                },
                async {
                    let _ = stop_rx.await;
                },
            ));
            match r {
                Ok(()) => Ok(()),
                Err(alba_app::RunError::Other(m)) => Err(m),
                Err(alba_app::RunError::Compile(_)) => Err("the generated project does not compile".into()),
            }
        });
        match ready_rx.recv_timeout(Duration::from_secs(60)) {
            Ok(http) => Ok(Server { http, stop, thread }),
            Err(_) => Err(match thread.join() {
                Ok(Err(e)) => format!("alba run: {e}"),
                _ => "alba run did not start".into(),
            }),
        }
    }

    fn stop(self) -> Result<(), String> {
        let _ = self.stop.send(());
        match self.thread.join() {
            Ok(r) => r.map_err(|e| format!("alba run: {e}")),
            Err(_) => Err("alba run panicked".into()),
        }
    }
}

/// The policy and priority of the thread named `alba-engine`, from /proc.
fn engine_scheduling() -> String {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return "unknown (no /proc)".into();
    };
    for t in tasks.flatten() {
        let comm = std::fs::read_to_string(t.path().join("comm")).unwrap_or_default();
        if comm.trim() != "alba-engine" {
            continue;
        }
        let stat = std::fs::read_to_string(t.path().join("stat")).unwrap_or_default();
        // Fields after the command name: state is field 3; rt_priority 40, policy 41.
        let f: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
        let field = |n: usize| f.get(n - 3).and_then(|v| v.parse::<u64>().ok());
        let locked = std::fs::read_to_string("/proc/self/status")
            .unwrap_or_default()
            .lines()
            .find_map(|l| l.strip_prefix("VmLck:").map(|v| v.trim() != "0 kB"))
            .unwrap_or(false);
        let mut s = match (field(41), field(40)) {
            (Some(1), Some(p)) => format!("SCHED_FIFO {p}"),
            (Some(0), _) => "normal".to_string(),
            (Some(p), _) => format!("policy {p}"),
            _ => "unknown".to_string(),
        };
        if locked {
            s.push_str(", memory locked");
        }
        return s;
    }
    "not found".into()
}

fn pct(sorted: &[u64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i] as f64 / 1000.0
}

/// The protocol clients of a loaded row.
struct Load {
    stop: Arc<AtomicBool>,
    /// Counting (the measurement window).
    measuring: Arc<AtomicBool>,
    modbus: Vec<std::thread::JoinHandle<bench_modbus::Tally>>,
    http: Vec<std::thread::JoinHandle<(u64, u64)>>,
    /// WebSocket messages and OPC UA values received while measuring.
    ws: Arc<AtomicU64>,
    opcua: Arc<AtomicU64>,
    clients: std::thread::JoinHandle<Vec<String>>,
}

impl Load {
    fn start(http: SocketAddr, modbus: SocketAddr, opcua: SocketAddr) -> Load {
        let stop = Arc::new(AtomicBool::new(false));
        let measuring = Arc::new(AtomicBool::new(false));
        let modbus = (0..MODBUS_CLIENTS)
            .map(|_| {
                let (stop, measuring) = (stop.clone(), measuring.clone());
                std::thread::spawn(move || bench_modbus::client(modbus, 8192, &stop, &measuring))
            })
            .collect();
        let http_threads = (0..HTTP_CLIENTS)
            .map(|_| {
                let (stop, measuring) = (stop.clone(), measuring.clone());
                std::thread::spawn(move || http_client(http, &stop, &measuring))
            })
            .collect();
        let (ws, ua) = (Arc::new(AtomicU64::new(0)), Arc::new(AtomicU64::new(0)));
        let clients = {
            let (stop, measuring, ws, ua) = (stop.clone(), measuring.clone(), ws.clone(), ua.clone());
            std::thread::spawn(move || async_clients(http, opcua, &stop, &measuring, &ws, &ua))
        };
        Load {
            stop,
            measuring,
            modbus,
            http: http_threads,
            ws,
            opcua: ua,
            clients,
        }
    }

    /// Stops every client; what they were served, per second of `wall`.
    fn stop(self, wall: f64) -> Result<String, String> {
        self.stop.store(true, Ordering::Relaxed);
        let (mut modbus, mut unanswered) = (0u64, 0u64);
        for t in self.modbus {
            let t = t.join().map_err(|_| "a Modbus client panicked")?;
            modbus += t.lat_ns.len() as u64;
            unanswered += t.unanswered;
        }
        let (mut http, mut failed) = (0u64, 0u64);
        for t in self.http {
            let (ok, bad) = t.join().map_err(|_| "an HTTP client panicked")?;
            http += ok;
            failed += bad;
        }
        let problems = self
            .clients
            .join()
            .map_err(|_| "the WebSocket/OPC UA clients panicked")?;
        if let Some(p) = problems.first() {
            return Err(p.clone());
        }
        let per_s = |n: u64| n as f64 / wall;
        Ok(format!(
            "Modbus {:.0} req/s ({unanswered} unanswered), HTTP {:.0} req/s ({failed} failed), WS {:.0} msg/s, OPC UA {:.0} values/s",
            per_s(modbus),
            per_s(http),
            per_s(self.ws.load(Ordering::Relaxed)),
            per_s(self.opcua.load(Ordering::Relaxed)),
        ))
    }
}

/// `GET /api/status` again and again, a connection each; (answered 200, other).
fn http_client(addr: SocketAddr, stop: &AtomicBool, measuring: &AtomicBool) -> (u64, u64) {
    let (mut ok, mut bad) = (0, 0);
    let mut reply = Vec::with_capacity(4096);
    while !stop.load(Ordering::Relaxed) {
        reply.clear();
        let good = TcpStream::connect(addr).is_ok_and(|mut s| {
            s.write_all(format!("GET /api/status HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n").as_bytes())
                .is_ok()
                && s.read_to_end(&mut reply).is_ok()
                && reply.starts_with(b"HTTP/1.1 200")
        });
        if measuring.load(Ordering::Relaxed) {
            if good {
                ok += 1;
            } else {
                bad += 1;
            }
        }
    }
    (ok, bad)
}

/// The WebSocket and OPC UA clients on a tokio runtime of their own (not
/// the server's) until `stop`; the problems that kept any from working.
fn async_clients(
    http: SocketAddr,
    opcua: SocketAddr,
    stop: &AtomicBool,
    measuring: &Arc<AtomicBool>,
    ws: &Arc<AtomicU64>,
    ua: &Arc<AtomicU64>,
) -> Vec<String> {
    let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(rt) => rt,
        Err(e) => return vec![e.to_string()],
    };
    rt.block_on(async {
        let (done_tx, done) = tokio::sync::watch::channel(false);
        let mut tasks = tokio::task::JoinSet::new();
        for k in 0..WS_CLIENTS {
            let (done, measuring, count) = (done.clone(), measuring.clone(), ws.clone());
            tasks.spawn(async move { ws_client(http, k % 2 == 0, done, &measuring, &count).await });
        }
        {
            let (done, measuring, count) = (done.clone(), measuring.clone(), ua.clone());
            tasks.spawn(async move { opcua_client(opcua, done, &measuring, &count).await });
        }
        while !stop.load(Ordering::Relaxed) {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        done_tx.send_replace(true);
        let mut problems = Vec::new();
        while let Some(r) = tasks.join_next().await {
            match r {
                Ok(Err(e)) => problems.push(e),
                Err(e) => problems.push(e.to_string()),
                Ok(Ok(())) => {}
            }
        }
        problems
    })
}

async fn ws_client(
    http: SocketAddr,
    monitor: bool,
    mut done: tokio::sync::watch::Receiver<bool>,
    measuring: &AtomicBool,
    count: &AtomicU64,
) -> Result<(), String> {
    let mut req = format!("ws://{http}/api/ws")
        .into_client_request()
        .map_err(|e| e.to_string())?;
    let origin = format!("http://{http}").parse().map_err(|e| format!("{e}"))?;
    req.headers_mut().insert("Origin", origin);
    let (mut ws, _) = tokio_tungstenite::connect_async(req)
        .await
        .map_err(|e| format!("WebSocket: {e}"))?;
    let names: Vec<String> = (0..WATCHED).map(|i| format!("\"V_{i}\"")).collect();
    let mut hello = vec![format!("{{\"subscribe\":[{}]}}", names.join(","))];
    if monitor {
        hello.push("{\"monitor\":[\"main.lad\"]}".into());
    }
    for h in hello {
        ws.send(Message::Text(h.into()))
            .await
            .map_err(|e| format!("WebSocket: {e}"))?;
    }
    loop {
        tokio::select! {
            m = ws.next() => match m {
                Some(Ok(Message::Text(t))) => {
                    if t.as_str().starts_with("{\"type\":\"error\"") {
                        return Err(format!("WebSocket: {}", t.as_str()));
                    }
                    if measuring.load(Ordering::Relaxed) {
                        count.fetch_add(1, Ordering::Relaxed);
                    }
                }
                Some(Ok(_)) => {}
                Some(Err(e)) => return Err(format!("WebSocket: {e}")),
                None => return Err("WebSocket: closed by the server".into()),
            },
            _ = done.changed() => return Ok(()),
        }
    }
}

async fn opcua_client(
    addr: SocketAddr,
    mut done: tokio::sync::watch::Receiver<bool>,
    measuring: &Arc<AtomicBool>,
    count: &Arc<AtomicU64>,
) -> Result<(), String> {
    use opcua::client::{ClientBuilder, DataChangeCallback, IdentityToken};
    use opcua::crypto::SecurityPolicy;
    use opcua::types::{MessageSecurityMode, MonitoredItemCreateRequest, NodeId, TimestampsToReturn};
    let fail = |what: &str, e: String| format!("OPC UA {what}: {e}");
    let pki = std::env::temp_dir().join(format!("alba-bench-realtime-pki-{}", std::process::id()));
    let mut client = ClientBuilder::new()
        .application_name("alba bench")
        .application_uri("urn:alba:bench")
        .pki_dir(&pki)
        .create_sample_keypair(false)
        .trust_server_certs(true)
        .session_retry_limit(0)
        .client()
        .map_err(|e| fail("client", e.join("; ")))?;
    let url = format!("opc.tcp://{addr}/");
    let (session, event_loop) = client
        .connect_to_matching_endpoint(
            (url.as_str(), SecurityPolicy::None.to_uri(), MessageSecurityMode::None),
            IdentityToken::Anonymous,
        )
        .await
        .map_err(|e| fail("connect", e.to_string()))?;
    let events = event_loop.spawn();
    let r = async {
        if !session.wait_for_connection().await {
            return Err(fail("session", "not opened".into()));
        }
        let ns = session
            .get_namespace_index(&alba_opcua::namespace_uri(PROJECT))
            .await
            .map_err(|e| fail("namespace", e.to_string()))?;
        let (measuring, count) = (measuring.clone(), count.clone());
        let callback = DataChangeCallback::new(move |_, _| {
            if measuring.load(Ordering::Relaxed) {
                count.fetch_add(1, Ordering::Relaxed);
            }
        });
        let sub = session
            .create_subscription(Duration::from_millis(100), 60, 10, 0, 0, true, callback)
            .await
            .map_err(|e| fail("subscription", e.to_string()))?;
        let items: Vec<MonitoredItemCreateRequest> = (0..WATCHED)
            .map(|i| {
                let mut r = MonitoredItemCreateRequest::from(NodeId::new(ns, format!("V_{i}")));
                r.requested_parameters.sampling_interval = 10.0;
                r.requested_parameters.queue_size = 1;
                r
            })
            .collect();
        session
            .create_monitored_items(sub, TimestampsToReturn::Neither, items)
            .await
            .map_err(|e| fail("monitored items", e.to_string()))?;
        let _ = done.changed().await;
        Ok(())
    }
    .await;
    let _ = session.disconnect().await;
    events.abort();
    let _ = std::fs::remove_dir_all(&pki);
    r
}
