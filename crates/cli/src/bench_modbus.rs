//! `alba bench --modbus`: the Modbus TCP server under load, measured with
//! one load client for every server (numbers printed, never asserted).
//!
//! The load is OpenPLC's reference measurement (issue 6): each client is a
//! thread with one blocking connection sending Read Holding Registers of 10
//! registers and waiting for the reply, as a libmodbus client does. For
//! each client count it reports requests per second, latency percentiles,
//! requests left unanswered (a wrong, short or late reply: the client then
//! reconnects), and what the engine did meanwhile: the longest scan, the
//! largest lateness of a scan start (jitter) and missed deadlines.
//!
//! By default Alba's own server runs in this process, as `alba run` runs it:
//! the engine thread scans a generated 1 000-rung program every 10 ms and
//! the server runs on a two-thread tokio runtime; the registers read are
//! five DINT tags of the program (`V_0`..`V_4` on holding registers
//! 8192-8201). `--target HOST:PORT` loads another server instead (OpenPLC,
//! say) with the same client.

use alba_project::config::{ModbusArea, ModbusTag};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

const RUNGS: usize = 1000;
const SCAN_MS: u32 = 10;

/// What one client measured.
#[derive(Default)]
pub(crate) struct Tally {
    pub(crate) lat_ns: Vec<u32>,
    pub(crate) unanswered: u64,
}

fn request(tid: u16, start: u16) -> [u8; 12] {
    let t = tid.to_be_bytes();
    let s = start.to_be_bytes();
    [t[0], t[1], 0, 0, 0, 6, 1, 3, s[0], s[1], 0, 10]
}

fn connect(addr: SocketAddr) -> Option<TcpStream> {
    let s = TcpStream::connect_timeout(&addr, Duration::from_secs(2)).ok()?;
    s.set_nodelay(true).ok()?;
    s.set_read_timeout(Some(Duration::from_secs(1))).ok()?;
    Some(s)
}

/// One client until `stop`: a request, its reply, again.
pub(crate) fn client(addr: SocketAddr, start: u16, stop: &AtomicBool, measure: &AtomicBool) -> Tally {
    let mut t = Tally::default();
    let mut sock = connect(addr);
    let mut tid: u16 = 0;
    let mut reply = [0u8; 9 + 20];
    while !stop.load(Ordering::Relaxed) {
        let Some(s) = sock.as_mut() else {
            t.unanswered += 1;
            std::thread::sleep(Duration::from_millis(10));
            sock = connect(addr);
            continue;
        };
        tid = tid.wrapping_add(1);
        let t0 = Instant::now();
        let ok = s.write_all(&request(tid, start)).is_ok()
            && s.read_exact(&mut reply).is_ok()
            && reply[..2] == tid.to_be_bytes()
            && reply[7] == 3
            && reply[8] == 20;
        let ns = t0.elapsed().as_nanos().min(u32::MAX as u128) as u32;
        if !measure.load(Ordering::Relaxed) {
            if !ok {
                sock = connect(addr);
            }
            continue;
        }
        if ok {
            t.lat_ns.push(ns);
        } else {
            t.unanswered += 1;
            sock = connect(addr);
        }
    }
    t
}

/// Runs `n` clients for `secs` (after a short warm-up); (req/s, sorted latencies, unanswered).
fn load(addr: SocketAddr, start: u16, n: usize, secs: f64) -> (f64, Vec<u32>, u64) {
    let stop = Arc::new(AtomicBool::new(false));
    let measure = Arc::new(AtomicBool::new(false));
    let threads: Vec<_> = (0..n)
        .map(|_| {
            let (stop, measure) = (stop.clone(), measure.clone());
            std::thread::spawn(move || client(addr, start, &stop, &measure))
        })
        .collect();
    std::thread::sleep(Duration::from_millis(500));
    measure.store(true, Ordering::Relaxed);
    let t0 = Instant::now();
    std::thread::sleep(Duration::from_secs_f64(secs));
    measure.store(false, Ordering::Relaxed);
    let elapsed = t0.elapsed().as_secs_f64();
    stop.store(true, Ordering::Relaxed);
    let mut lat = Vec::new();
    let mut unanswered = 0;
    for t in threads {
        if let Ok(t) = t.join() {
            lat.extend(t.lat_ns);
            unanswered += t.unanswered;
        }
    }
    lat.sort_unstable();
    (lat.len() as f64 / elapsed, lat, unanswered)
}

fn pct(sorted: &[u32], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    f64::from(sorted[i]) / 1000.0
}

pub fn run(clients: &[usize], secs: f64, target: Option<SocketAddr>, start: Option<u16>) -> ExitCode {
    if clients.is_empty() || clients.contains(&0) || !(0.1..=3600.0).contains(&secs) {
        eprintln!("error: --clients takes counts of 1 or more; --seconds 0.1 to 3600");
        return ExitCode::FAILURE;
    }
    println!(
        "alba bench --modbus: FC3 (Read Holding Registers) x 10 registers, one blocking connection per client thread"
    );
    if let Some(addr) = target {
        println!("target: {addr} (external server)\n");
        println!(
            "{:>7} {:>10} {:>9} {:>9} {:>9} {:>10}",
            "clients", "req/s", "p50 µs", "p99 µs", "max µs", "unanswered"
        );
        for &n in clients {
            let (rate, lat, un) = load(addr, start.unwrap_or(0), n, secs);
            println!(
                "{n:>7} {rate:>10.0} {:>9.1} {:>9.1} {:>9.1} {un:>10}",
                pct(&lat, 0.5),
                pct(&lat, 0.99),
                pct(&lat, 1.0)
            );
        }
        return ExitCode::SUCCESS;
    }
    match own_server(clients, secs, start.unwrap_or(8192)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn own_server(clients: &[usize], secs: f64, start: u16) -> Result<(), String> {
    let (tags, lad) = crate::bench::generate(RUNGS);
    let program = crate::bench::compile_text(&tags, "main.lad", &lad)?;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    let runtime = alba_runtime::Runtime::start(
        program,
        alba_runtime::Options::new(SCAN_MS),
        Box::new(alba_runtime::SimIo),
    )
    .map_err(|e| e.to_string())?;
    let handle = runtime.handle();
    let tags: Vec<ModbusTag> = (0..5)
        .map(|k| ModbusTag {
            name: format!("V_{k}"),
            name_span: alba_diag::Span::new(alba_diag::FileId(0), 0..0),
            area: ModbusArea::HoldingRegister,
            start: 8192 + 2 * k as u16,
            span: alba_diag::Span::new(alba_diag::FileId(0), 0..0),
        })
        .collect();
    let settings = alba_modbus::Settings {
        max_connections: 256,
        tags,
        ..Default::default()
    };
    let server = alba_modbus::Server::new(alba_modbus::Control::new(handle.clone(), None), settings);
    let (closing, closing_rx) = tokio::sync::watch::channel(false);
    let addr = rt.block_on(async {
        let l = tokio::net::TcpListener::bind("127.0.0.1:0")
            .await
            .map_err(|e| e.to_string())?;
        let a = l.local_addr().map_err(|e| e.to_string())?;
        tokio::spawn(server.clone().serve(l, closing_rx));
        Ok::<_, String>(a)
    })?;
    println!(
        "server: Alba's, in this process on {addr}; engine: {RUNGS} generated rungs every {SCAN_MS} ms (native code); {secs} s per row\n"
    );
    println!(
        "{:>9} {:>10} {:>9} {:>9} {:>9} {:>10} {:>11} {:>10} {:>9} {:>6}",
        "clients", "req/s", "p50 µs", "p99 µs", "max µs", "unanswered", "scan max µs", "jitter µs", "overruns", "scans"
    );
    // Statistics restart with each run: stop, run, then the phase.
    let restart = |rt: &tokio::runtime::Runtime| {
        rt.block_on(async {
            let _ = handle.stop().await;
            let _ = handle.run().await;
        })
    };
    let engine_cols = |h: &alba_runtime::Handle| {
        let s = h.snapshot();
        format!(
            "{:>11} {:>10} {:>9} {:>6}",
            s.stats.max_us, s.stats.jitter_us, s.stats.overruns, s.stats.scans
        )
    };
    restart(&rt);
    std::thread::sleep(Duration::from_secs_f64(secs + 0.5));
    println!(
        "{:>9} {:>10} {:>9} {:>9} {:>9} {:>10} {}",
        "no load",
        "-",
        "-",
        "-",
        "-",
        "-",
        engine_cols(&handle)
    );
    for &n in clients {
        restart(&rt);
        let (rate, lat, un) = load(addr, start, n, secs);
        println!(
            "{n:>9} {rate:>10.0} {:>9.1} {:>9.1} {:>9.1} {un:>10} {}",
            pct(&lat, 0.5),
            pct(&lat, 0.99),
            pct(&lat, 1.0),
            engine_cols(&handle)
        );
    }
    let served = server.counters.requests.load(Ordering::Relaxed);
    println!("\nserver: {served} requests answered in all");
    closing.send_replace(true);
    drop(rt);
    runtime.shutdown();
    Ok(())
}
