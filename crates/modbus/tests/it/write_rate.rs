//! Modbus write throughput with and without the audit trail (issue 32:
//! within 20 %). Numbers printed, never asserted:
//!
//! `cargo test -p alba-modbus --test it write_rate -- --ignored --nocapture`
//!
//! Each of `CLIENTS` clients has one connection and sends FC16 writes of
//! `Speed` (a DINT on holding registers 8192-8193), each waiting for its reply, for
//! `SECS` seconds; the server writes through the control layer with no
//! audit log (as before issue 32), then with one (a row per write, or
//! coalesced: docs/audit.md, "Modbus").

use super::{TAGS, TOML, compile, project};
use alba_modbus::{Control, Server};
use alba_runtime::{Options, Runtime, SimIo};
use std::io::{Read, Write};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::net::TcpListener;
use tokio::sync::watch;

const CLIENTS: usize = 4;
const SECS: u64 = 3;

fn client(addr: std::net::SocketAddr, until: Instant, k: u16) -> u64 {
    let mut s = std::net::TcpStream::connect(addr).expect("connect");
    s.set_nodelay(true).expect("nodelay");
    let mut done = 0u64;
    let mut reply = [0u8; 12];
    let mut tid: u16 = 0;
    while Instant::now() < until {
        tid = tid.wrapping_add(1);
        let t = tid.to_be_bytes();
        let v = (tid % 1000 + k).to_be_bytes();
        // Speed is a DINT: two registers, high word first.
        let req = [t[0], t[1], 0, 0, 0, 11, 1, 16, 0x20, 0x00, 0, 2, 4, 0, 0, v[0], v[1]];
        s.write_all(&req).expect("send");
        s.read_exact(&mut reply).expect("reply");
        assert_eq!(reply[7], 16, "an exception: {reply:?}");
        done += 1;
    }
    done
}

async fn rate(audited: bool) -> f64 {
    let dir = project(if audited { "rate-audit" } else { "rate-plain" }, TOML);
    let (program, cfg) = compile(&dir);
    let runtime = Runtime::start(Arc::new(program), Options::new(5), Box::new(SimIo)).expect("runtime");
    let audit = audited
        .then(|| alba_audit::Audit::open(dir.join("audit.db"), alba_audit::Config::default()).expect("audit log"));
    let server = Server::new(Control::new(runtime.handle(), audit.clone()), cfg);
    let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
    let addr = listener.local_addr().expect("addr");
    let (closing, rx) = watch::channel(false);
    tokio::spawn(server.clone().serve(listener, rx));
    let until = Instant::now() + Duration::from_secs(SECS);
    let started = Instant::now();
    let total: u64 = tokio::task::spawn_blocking(move || {
        let threads: Vec<_> = (0..CLIENTS)
            .map(|k| std::thread::spawn(move || client(addr, until, k as u16)))
            .collect();
        threads.into_iter().map(|t| t.join().expect("client")).sum()
    })
    .await
    .expect("clients");
    let secs = started.elapsed().as_secs_f64();
    closing.send_replace(true);
    runtime.shutdown();
    let rows = audit.map(|a| {
        a.query(&alba_audit::Filter::default(), None, 1)
            .expect("query")
            .rows
            .first()
            .map_or(0, |r| r.id)
    });
    let per_s = total as f64 / secs;
    println!(
        "{}: {total} FC16 writes in {secs:.1} s by {CLIENTS} clients = {per_s:.0} writes/s; audit rows: {}",
        if audited {
            "with the audit trail"
        } else {
            "without an audit trail"
        },
        rows.map_or("none".to_string(), |n| n.to_string())
    );
    let _ = std::fs::remove_dir_all(&dir);
    let _ = TAGS;
    per_s
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "a measurement: run with --ignored --nocapture"]
async fn write_rate() {
    let plain = rate(false).await;
    let audited = rate(true).await;
    println!("audited / plain = {:.2}", audited / plain);
}
