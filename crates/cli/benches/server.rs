//! Load on the studio's server: `alba run` (release) with 10 000 DINT tags
//! that all change every 10 ms scan, watched by 0, 1 and 10 WebSocket
//! clients subscribed to every tag. Prints, per phase: CPU of the `alba`
//! process (% of one core), bytes/s and messages/s received, engine → client
//! latency (publication time in the message to receipt), and the scan
//! statistics (mean/max µs, overruns) of the engine meanwhile.
//!
//! `cargo bench -p alba-cli --bench server` (`ALBA_BENCH_SECS=3` for a short run).

use futures_util::{SinkExt, StreamExt};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tokio_tungstenite::tungstenite::Message;

const TAGS: usize = 10_000;

fn project() -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench-server");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let mut lad = String::new();
    for i in 0..TAGS {
        tags.push_str(&format!("T{i},DINT,,{i},,\n"));
        lad.push_str(&format!("ADD(T{i},1,T{i});\n"));
    }
    let toml = "name = \"load\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n";
    for (f, t) in [("alba.toml", toml.to_string()), ("tags.csv", tags), ("main.lad", lad)] {
        std::fs::write(dir.join(f), t).expect("write");
    }
    dir
}

fn http(addr: &str, method: &str, path: &str) -> serde_json::Value {
    let mut s = TcpStream::connect(addr).expect("connect");
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
    )
    .expect("send");
    let mut text = String::new();
    s.read_to_string(&mut text).expect("answer");
    let body = text.split("\r\n\r\n").nth(1).unwrap_or("null");
    serde_json::from_str(body).unwrap_or(serde_json::Value::Null)
}

/// utime + stime of `pid`, in seconds.
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    // Fields after the command name (which is in parentheses).
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 =
        f.get(11).and_then(|v| v.parse().ok()).unwrap_or(0.0) + f.get(12).and_then(|v| v.parse().ok()).unwrap_or(0.0);
    ticks / 100.0
}

fn unix_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

#[derive(Default)]
struct Seen {
    bytes: u64,
    messages: u64,
    values: u64,
    latency_ms: Vec<i64>,
}

async fn client(addr: String, until: Instant) -> Seen {
    let (mut ws, _) = tokio_tungstenite::connect_async(format!("ws://{addr}/api/ws"))
        .await
        .expect("ws");
    ws.send(Message::Text("{\"subscribe\":\"*\"}".into()))
        .await
        .expect("send");
    let mut seen = Seen::default();
    let mut first = true;
    while let Ok(Some(Ok(m))) = tokio::time::timeout_at(until.into(), ws.next()).await {
        let Message::Text(t) = m else { continue };
        let t = t.as_str();
        if !t.starts_with("{\"type\":\"values\"") {
            continue;
        }
        seen.bytes += t.len() as u64;
        seen.messages += 1;
        // Every value is `"name":v`; 4 more colons in the envelope.
        seen.values += t.bytes().filter(|b| *b == b':').count().saturating_sub(4) as u64;
        if first {
            // The first message carries every value at once: not a latency sample.
            first = false;
            continue;
        }
        if let Some(i) = t.find("\"t_ms\":") {
            let digits: String = t[i + 7..].chars().take_while(char::is_ascii_digit).collect();
            if let Ok(sent) = digits.parse::<i64>() {
                seen.latency_ms.push(unix_ms() - sent);
            }
        }
    }
    seen
}

fn pct(v: &mut [i64], p: f64) -> i64 {
    if v.is_empty() {
        return -1;
    }
    v.sort_unstable();
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let secs: u64 = std::env::var("ALBA_BENCH_SECS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    let dir = project();
    let mut child = Command::new(env!("CARGO_BIN_EXE_alba"))
        .args(["run", ".", "--http", "127.0.0.1:0"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .spawn()
        .expect("alba run");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("banner");
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|s| s.split('/').next())
        .expect("address")
        .to_string();
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .expect("runtime");
    println!("server load: {TAGS} DINT tags changing every 10 ms scan, {secs} s per phase, `alba run` in release");
    println!(
        "{:>7} {:>7} {:>10} {:>11} {:>12} {:>8} {:>8} {:>9} {:>8} {:>9}",
        "clients", "CPU %", "MB/s", "msgs/s/cl", "values/s/cl", "p50 ms", "p99 ms", "scan µs", "max µs", "overruns"
    );
    // Warm up (page faults, first allocations) before measuring.
    std::thread::sleep(Duration::from_secs(1));
    for clients in [0usize, 1, 10] {
        // Restart scanning: statistics from zero.
        http(&addr, "POST", "/api/stop");
        http(&addr, "POST", "/api/run");
        let cpu0 = cpu_seconds(child.id());
        let t0 = Instant::now();
        let until = t0 + Duration::from_secs(secs);
        let seen: Vec<Seen> = rt.block_on(async {
            let tasks: Vec<_> = (0..clients)
                .map(|_| tokio::spawn(client(addr.clone(), until)))
                .collect();
            tokio::time::sleep_until(until.into()).await;
            let mut out = Vec::new();
            for t in tasks {
                out.push(t.await.expect("client"));
            }
            out
        });
        let wall = t0.elapsed().as_secs_f64();
        let cpu = (cpu_seconds(child.id()) - cpu0) / wall * 100.0;
        let status = http(&addr, "GET", "/api/status");
        let st = &status["stats"];
        let bytes: u64 = seen.iter().map(|s| s.bytes).sum();
        let msgs: u64 = seen.iter().map(|s| s.messages).sum();
        let values: u64 = seen.iter().map(|s| s.values).sum();
        let mut lat: Vec<i64> = seen.iter().flat_map(|s| s.latency_ms.iter().copied()).collect();
        let per = |x: u64| {
            if clients == 0 {
                0.0
            } else {
                x as f64 / clients as f64 / wall
            }
        };
        println!(
            "{:>7} {:>7.1} {:>10.1} {:>11.1} {:>12.0} {:>8} {:>8} {:>9} {:>8} {:>9}",
            clients,
            cpu,
            bytes as f64 / wall / 1e6,
            per(msgs),
            per(values),
            pct(&mut lat, 0.5),
            pct(&mut lat, 0.99),
            st["mean_us"].as_u64().unwrap_or(0),
            st["max_us"].as_u64().unwrap_or(0),
            st["overruns"].as_u64().unwrap_or(0)
        );
    }
    let _ = child.kill();
    let _ = child.wait();
}
