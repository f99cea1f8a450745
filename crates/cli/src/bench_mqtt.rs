//! `alba bench --mqtt`: tag changes published by one runtime through a real
//! broker, measured by a subscriber (numbers printed, never asserted).
//!
//! Each row runs `alba run` itself (alba-app, in this process, native code)
//! on a generated project of N DINT tags that all change every scan
//! (`ADD(V_i,1,V_i)`), with `[mqtt]` pointing at the broker, and a
//! subscriber (rumqttc, QoS 0, in its own thread) counting what arrives on
//! `alba/bench/tags/#` (JSON: one message per change) or the node's DDATA
//! (Sparkplug B: one message per snapshot carrying every change). For each
//! row it prints the changes offered (N × scans per second), the messages
//! Alba handed to its client and the changes the subscriber received per
//! second, the end-to-end latency from the snapshot that made the change
//! (its `ts`, ms since 1970) to its arrival (p50/p99/max, to 1 ms), what the
//! client's queue coalesced, and the engine's longest scan, its jitter
//! (largest lateness of a scan start) and missed deadlines, beside the same
//! project without MQTT.
//!
//! The broker is Mosquitto started on a free loopback port in a temporary
//! directory (`mosquitto` on PATH or in /usr/sbin), or `--broker HOST:PORT`.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

const SCAN_MS: u32 = 10;

#[derive(Clone, Copy, PartialEq)]
enum Mode {
    Json(u8),
    Sparkplug,
    /// The same project without MQTT: the engine's numbers to compare.
    Off,
}

impl Mode {
    fn label(self) -> String {
        match self {
            Mode::Json(q) => format!("JSON QoS {q}"),
            Mode::Sparkplug => "Sparkplug".into(),
            Mode::Off => "no MQTT".into(),
        }
    }
}

/// A Mosquitto of our own, stopped when dropped.
struct Broker {
    child: Option<std::process::Child>,
    addr: String,
    dir: Option<PathBuf>,
}

impl Drop for Broker {
    fn drop(&mut self) {
        if let Some(c) = self.child.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
        if let Some(d) = &self.dir {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}

fn free_port() -> Result<u16, String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    l.local_addr().map(|a| a.port()).map_err(|e| e.to_string())
}

fn temp_dir(what: &str) -> Result<PathBuf, String> {
    let nanos = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos());
    let d = std::env::temp_dir().join(format!("alba-bench-mqtt-{what}-{}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&d).map_err(|e| format!("cannot create {}: {e}", d.display()))?;
    Ok(d)
}

fn mosquitto() -> Result<Broker, String> {
    let exe = ["/usr/sbin/mosquitto", "/usr/local/sbin/mosquitto"]
        .into_iter()
        .map(PathBuf::from)
        .find(|p| p.exists())
        .unwrap_or_else(|| PathBuf::from("mosquitto"));
    let dir = temp_dir("broker")?;
    let port = free_port()?;
    let conf = dir.join("mosquitto.conf");
    // No limit on the messages queued for the subscriber: the bench counts
    // what Alba sends, not what a queue bound would drop. TCP_NODELAY on the
    // broker's side too (Mosquitto's default is Nagle's algorithm).
    std::fs::write(
        &conf,
        format!(
            "listener {port} 127.0.0.1\nallow_anonymous true\npersistence false\nmax_queued_messages 0\nset_tcp_nodelay true\n"
        ),
    )
    .map_err(|e| e.to_string())?;
    let child = std::process::Command::new(&exe)
        .arg("-c")
        .arg(&conf)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .map_err(|e| {
            format!(
                "cannot start {}: {e} (install Mosquitto: apt-get install mosquitto; or give --broker HOST:PORT)",
                exe.display()
            )
        })?;
    let broker = Broker {
        child: Some(child),
        addr: format!("127.0.0.1:{port}"),
        dir: Some(dir),
    };
    let deadline = Instant::now() + Duration::from_secs(10);
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        if Instant::now() > deadline {
            return Err("mosquitto did not start listening".into());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    Ok(broker)
}

/// A project of `n` DINT tags that all change every scan.
fn project(dir: &Path, n: usize, mode: Mode, broker: &str) -> Result<(), String> {
    let mut toml =
        format!("name = \"bench\"\nscan_ms = {SCAN_MS}\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n");
    match mode {
        Mode::Json(q) => toml.push_str(&format!("[mqtt]\nbroker = \"{broker}\"\nqos = {q}\nwrites = false\n")),
        Mode::Sparkplug => toml.push_str(&format!(
            "[mqtt]\nbroker = \"{broker}\"\nwrites = false\n[mqtt.sparkplug]\ngroup_id = \"bench\"\nedge_node_id = \"node\"\n"
        )),
        Mode::Off => {}
    }
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let mut lad = String::new();
    for i in 0..n {
        tags.push_str(&format!("V_{i},DINT,,,,\n"));
        lad.push_str(&format!("ADD(V_{i},1,V_{i});\n"));
    }
    for (f, text) in [("alba.toml", toml), ("tags.csv", tags), ("main.lad", lad)] {
        std::fs::write(dir.join(f), text).map_err(|e| format!("cannot write {f}: {e}"))?;
    }
    Ok(())
}

/// `alba run` of `dir` in this process; stopped by the returned sender.
struct Running {
    addr: SocketAddr,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Running {
    fn start(dir: &Path) -> Result<Running, String> {
        let (tx, rx) = tokio::sync::oneshot::channel::<()>();
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let dir = dir.to_path_buf();
        let thread = std::thread::spawn(move || {
            let Ok(rt) = tokio::runtime::Builder::new_multi_thread()
                .worker_threads(2)
                .enable_all()
                .build()
            else {
                return;
            };
            let opts = alba_app::Options {
                addr: SocketAddr::from(([127, 0, 0, 1], 0)),
                io: "sim".into(),
                native: true,
                modbus: None,
                opcua: None,
                mqtt: None,
                tls: alba_app::tls::Tls::Never,
                scan_log: None,
                quiet: true,
            };
            let ready = ready_tx.clone();
            let result = rt.block_on(alba_app::run(
                &dir,
                opts,
                move |a| {
                    let _ = ready.send(Ok(a));
                },
                async move {
                    let _ = rx.await;
                },
            ));
            if let Err(e) = result {
                let msg = match e {
                    alba_app::RunError::Compile(_) => "the generated project does not compile".to_string(),
                    alba_app::RunError::Other(m) => m,
                };
                let _ = ready_tx.send(Err(msg));
            }
        });
        let addr = ready_rx
            .recv_timeout(Duration::from_secs(120))
            .map_err(|_| "alba run did not start".to_string())??;
        Ok(Running {
            addr,
            stop: Some(tx),
            thread: Some(thread),
        })
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        if let Some(s) = self.stop.take() {
            let _ = s.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// One HTTP/1.1 request to the studio's API; the JSON body.
fn http(addr: SocketAddr, method: &str, path: &str) -> Result<serde_json::Value, String> {
    let mut s = TcpStream::connect(addr).map_err(|e| e.to_string())?;
    s.set_read_timeout(Some(Duration::from_secs(10)))
        .map_err(|e| e.to_string())?;
    let body = if method == "GET" { "" } else { "{}" };
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )
    .map_err(|e| e.to_string())?;
    let mut reply = String::new();
    s.read_to_string(&mut reply).map_err(|e| e.to_string())?;
    let (head, body) = reply.split_once("\r\n\r\n").ok_or("no HTTP reply")?;
    let body = if head.to_ascii_lowercase().contains("transfer-encoding: chunked") {
        dechunk(body)
    } else {
        body.to_string()
    };
    serde_json::from_str(&body).map_err(|e| format!("{method} {path}: {e}"))
}

fn dechunk(mut s: &str) -> String {
    let mut out = String::new();
    while let Some((size, rest)) = s.split_once("\r\n") {
        let Ok(n) = usize::from_str_radix(size.trim(), 16) else {
            break;
        };
        if n == 0 || rest.len() < n {
            break;
        }
        out.push_str(&rest[..n]);
        s = rest[n..].trim_start_matches("\r\n");
    }
    out
}

/// What the subscriber saw while measuring.
#[derive(Default)]
struct Seen {
    messages: AtomicU64,
    changes: AtomicU64,
    /// Latencies in µs (arrival − the snapshot's time).
    lat_us: Mutex<Vec<u32>>,
}

fn now_us() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as i64)
}

/// `"ts":<digits>` of a JSON tag message.
fn json_ts(p: &[u8]) -> Option<i64> {
    let s = std::str::from_utf8(p).ok()?;
    let rest = &s[s.find("\"ts\":")? + 5..];
    let end = rest.find(|c: char| !c.is_ascii_digit()).unwrap_or(rest.len());
    rest[..end].parse().ok()
}

/// A subscriber on `topic` in its own thread, counting while `measure` is set.
fn subscriber(
    broker: &str,
    topic: String,
    sparkplug: bool,
    measure: Arc<AtomicBool>,
    stop: Arc<AtomicBool>,
    seen: Arc<Seen>,
) -> Result<std::thread::JoinHandle<()>, String> {
    let (host, port) = broker.rsplit_once(':').ok_or("--broker: expected HOST:PORT")?;
    let port: u16 = port.parse().map_err(|_| "--broker: bad port")?;
    let host = host.to_string();
    Ok(std::thread::spawn(move || {
        let Ok(rt) = tokio::runtime::Builder::new_current_thread().enable_all().build() else {
            return;
        };
        rt.block_on(async move {
            let mut o = rumqttc::MqttOptions::new(format!("bench-sub-{}", std::process::id()), host, port);
            o.set_keep_alive(Duration::from_secs(30));
            o.set_max_packet_size(268_435_455, 1 << 20);
            let (client, mut ev) = rumqttc::AsyncClient::new(o, 100);
            let _ = client.subscribe(topic, rumqttc::QoS::AtMostOnce).await;
            while !stop.load(Ordering::Relaxed) {
                let Ok(Ok(e)) = tokio::time::timeout(Duration::from_millis(100), ev.poll()).await else {
                    continue;
                };
                let rumqttc::Event::Incoming(rumqttc::Packet::Publish(p)) = e else {
                    continue;
                };
                if !measure.load(Ordering::Relaxed) {
                    continue;
                }
                let (changes, ts) = if sparkplug {
                    match alba_sparkplug::decode_payload(&p.payload) {
                        Ok(d) => (d.metrics.len() as u64, d.timestamp.map(|t| t as i64)),
                        Err(_) => continue,
                    }
                } else {
                    (1, json_ts(&p.payload))
                };
                seen.messages.fetch_add(1, Ordering::Relaxed);
                seen.changes.fetch_add(changes, Ordering::Relaxed);
                if let Some(ts) = ts {
                    let us = (now_us() - ts * 1000).clamp(0, i64::from(u32::MAX)) as u32;
                    if let Ok(mut l) = seen.lat_us.lock() {
                        l.push(us);
                    }
                }
            }
        });
    }))
}

fn pct_ms(sorted: &[u32], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    f64::from(sorted[i]) / 1000.0
}

/// One row: `n` tags in `mode` for `secs`.
fn row(n: usize, mode: Mode, secs: f64, broker: &str) -> Result<(), String> {
    let dir = temp_dir("project")?;
    project(&dir, n, mode, broker)?;
    let measure = Arc::new(AtomicBool::new(false));
    let stop = Arc::new(AtomicBool::new(false));
    let seen = Arc::new(Seen::default());
    let sub = match mode {
        Mode::Off => None,
        Mode::Json(_) => Some(subscriber(
            broker,
            "alba/bench/tags/#".into(),
            false,
            measure.clone(),
            stop.clone(),
            seen.clone(),
        )?),
        Mode::Sparkplug => Some(subscriber(
            broker,
            "spBv1.0/bench/DDATA/#".into(),
            true,
            measure.clone(),
            stop.clone(),
            seen.clone(),
        )?),
    };
    let result = (|| {
        let alba = Running::start(&dir)?;
        // Warm-up: connected, born, the first (retained) burst past.
        std::thread::sleep(Duration::from_secs(2));
        let queue = |s: &serde_json::Value| -> (u64, u64) {
            let q = s["connections"]
                .as_array()
                .and_then(|c| c.iter().find(|c| c["name"] == "mqtt"))
                .map(|c| c["queue"].clone())
                .unwrap_or_default();
            (
                q["published"].as_u64().unwrap_or(0),
                q["coalesced"].as_u64().unwrap_or(0),
            )
        };
        // The scan statistics start again with a run.
        http(alba.addr, "POST", "/api/stop")?;
        http(alba.addr, "POST", "/api/run")?;
        let before = http(alba.addr, "GET", "/api/status")?;
        measure.store(true, Ordering::Relaxed);
        let t0 = Instant::now();
        std::thread::sleep(Duration::from_secs_f64(secs));
        measure.store(false, Ordering::Relaxed);
        let elapsed = t0.elapsed().as_secs_f64();
        let after = http(alba.addr, "GET", "/api/status")?;
        let ((p0, c0), (p1, c1)) = (queue(&before), queue(&after));
        let stats = &after["stats"];
        let scans = after["scans"].as_u64().unwrap_or(0) - before["scans"].as_u64().unwrap_or(0);
        let offered = n as f64 * scans as f64 / elapsed;
        let mut lat = seen.lat_us.lock().map(|l| l.clone()).unwrap_or_default();
        lat.sort_unstable();
        let num = |v: &serde_json::Value| v.as_u64().unwrap_or(0);
        if mode == Mode::Off {
            println!(
                "{:<12} {n:>6} {offered:>12.0} {:>10} {:>12} {:>7} {:>7} {:>7} {:>10} {:>9} {:>9} {:>8}",
                mode.label(),
                "-",
                "-",
                "-",
                "-",
                "-",
                "-",
                num(&stats["max_us"]),
                num(&stats["jitter_us"]),
                num(&stats["overruns"]),
            );
        } else {
            println!(
                "{:<12} {n:>6} {offered:>12.0} {:>10.0} {:>12.0} {:>7.1} {:>7.1} {:>7.1} {:>10} {:>9} {:>9} {:>8}",
                mode.label(),
                (p1 - p0) as f64 / elapsed,
                seen.changes.load(Ordering::Relaxed) as f64 / elapsed,
                pct_ms(&lat, 0.5),
                pct_ms(&lat, 0.99),
                pct_ms(&lat, 1.0),
                c1 - c0,
                num(&stats["max_us"]),
                num(&stats["jitter_us"]),
                num(&stats["overruns"]),
            );
        }
        drop(alba);
        Ok::<(), String>(())
    })();
    stop.store(true, Ordering::Relaxed);
    if let Some(s) = sub {
        let _ = s.join();
    }
    let _ = std::fs::remove_dir_all(&dir);
    result
}

pub fn run(tags: &[usize], secs: f64, broker: Option<String>) -> ExitCode {
    if tags.is_empty() || tags.contains(&0) || !(0.5..=3600.0).contains(&secs) {
        eprintln!("error: --tags takes counts of 1 or more; --seconds 0.5 to 3600");
        return ExitCode::FAILURE;
    }
    let own = match &broker {
        Some(_) => None,
        None => match mosquitto() {
            Ok(b) => Some(b),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        },
    };
    let addr = broker.unwrap_or_else(|| own.as_ref().map(|b| b.addr.clone()).unwrap_or_default());
    println!(
        "alba bench --mqtt: N DINT tags all changing every {SCAN_MS} ms scan, published by alba run (in this process) to {addr}{}; \
         a QoS 0 subscriber counts what arrives; {secs} s per row",
        if own.is_some() {
            " (Mosquitto started for the bench)"
        } else {
            ""
        }
    );
    println!("latency: from the snapshot's time (ms since 1970) to arrival, to 1 ms\n");
    println!(
        "{:<12} {:>6} {:>12} {:>10} {:>12} {:>7} {:>7} {:>7} {:>10} {:>9} {:>9} {:>8}",
        "mode",
        "tags",
        "offered ch/s",
        "sent msg/s",
        "received ch/s",
        "p50 ms",
        "p99 ms",
        "max ms",
        "coalesced",
        "scan max µs",
        "jitter µs",
        "overruns"
    );
    for &n in tags {
        for mode in [Mode::Off, Mode::Json(0), Mode::Json(1), Mode::Sparkplug] {
            if let Err(e) = row(n, mode, secs, &addr) {
                eprintln!("error: {} with {n} tags: {e}", mode.label());
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
