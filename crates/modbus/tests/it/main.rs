//! The Modbus server over a real runtime, through raw TCP: every function
//! code, the OpenPLC map and explicit addresses, exceptions, pipelining,
//! malformed frames, the connection limit and the idle timeout. (Clients
//! written elsewhere — pymodbus, libmodbus — are driven by `tests/clients/`
//! from test.sh.)

mod security;
mod write_rate;

use alba_modbus::{Server, Settings};
use alba_modbus_proto::mbap;
use alba_runtime::{Options, Runtime, SimIo};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::watch;

pub(crate) const TAGS: &str = "name,type,address,initial,retain,description\n\
Start,BOOL,%IX0.0,,,\nMotor,BOOL,%QX0.0,,,\nLamp,BOOL,%QX1.1,,,\nLevel,INT,%IW2,,,\nValve,INT,%QW1,,,\nBig,DINT,%QW3,,,\n\
Word,INT,%MW2,,,\nRatio,REAL,%MD4,,,\nSpeed,DINT,,,,\nTemp,REAL,,,,\nBigL,LINT,,,,\nSmall,SINT,,,,\nFlag,BOOL,,,,\nDelay,TIMER,,,,\n";
const LAD: &str = "XIC(Start)OTE(Motor);\nXIC(Flag)TON(Delay,50,0);\n";
pub(crate) const TOML: &str = "name = \"mb\"\nscan_ms = 5\nprograms = [\"main.lad\"]\n[modbus]\nunit_id = 1\n[modbus.tags]\n\
Speed = \"hr 8192\"\nTemp = \"hr 8194\"\nBigL = \"hr 8196\"\nSmall = \"hr 8200\"\nFlag = \"coil 8192\"\n\
\"Delay.PRE\" = \"hr 8300\"\n\"Delay.DN\" = \"di 8192\"\n\"S:SCANMAX\" = \"ir 1024\"\nStart = \"di 9000\"\n";

pub(crate) fn project(test: &str, toml: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-modbus-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("cannot write the test project");
    std::fs::write(dir.join("alba.toml"), toml).expect("cannot write the test project");
    std::fs::write(dir.join("tags.csv"), TAGS).expect("cannot write the test project");
    std::fs::write(dir.join("main.lad"), LAD).expect("cannot write the test project");
    dir
}

struct Fixture {
    runtime: Option<Runtime>,
    server: Arc<Server>,
    addr: std::net::SocketAddr,
    closing: watch::Sender<bool>,
}

impl Drop for Fixture {
    fn drop(&mut self) {
        self.closing.send_replace(true);
        if let Some(rt) = self.runtime.take() {
            rt.shutdown();
        }
    }
}

/// The test project's program and its `[modbus]` table (with its
/// `[modbus.tags]`, which are the project's), as alba-app gives them.
pub(crate) fn compile(dir: &std::path::Path) -> (alba_ir::Program, Settings) {
    let c = alba_load::compile_dir(dir);
    let program = c.program.clone().unwrap_or_else(|| panic!("{:?}", c.diagnostics));
    let cfg = alba_settings::Settings::of(&c.project)
        .and_then(|s| s.modbus)
        .expect("the test project has [modbus]");
    let mut settings = Settings::from(&cfg);
    settings.tags = c.project.config.map(|c| c.modbus_tags).unwrap_or_default();
    (program, settings)
}

async fn start(test: &str, tweak: impl FnOnce(&mut Settings)) -> Fixture {
    let dir = project(test, TOML);
    let (program, cfg) = compile(&dir);
    let mut settings = cfg;
    tweak(&mut settings);
    let runtime = Runtime::start(Arc::new(program), Options::new(5), Box::new(SimIo)).expect("runtime");
    let server = Server::new(alba_modbus::Control::new(runtime.handle(), None), settings);
    let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
    let addr = listener.local_addr().expect("local address");
    let (closing, rx) = watch::channel(false);
    tokio::spawn(server.clone().serve(listener, rx));
    Fixture {
        runtime: Some(runtime),
        server,
        addr,
        closing,
    }
}

fn adu(transaction: u16, unit: u8, pdu: &[u8]) -> Vec<u8> {
    mbap::adu(mbap::Header { transaction, unit }, pdu)
}

/// Reads one reply: (transaction, unit, pdu).
async fn reply(s: &mut TcpStream) -> (u16, u8, Vec<u8>) {
    let mut h = [0u8; 7];
    tokio::time::timeout(Duration::from_secs(5), s.read_exact(&mut h))
        .await
        .expect("no reply")
        .expect("connection closed");
    assert_eq!(&h[2..4], &[0, 0]);
    let len = u16::from_be_bytes([h[4], h[5]]) as usize;
    let mut pdu = vec![0u8; len - 1];
    s.read_exact(&mut pdu).await.expect("reply body");
    (u16::from_be_bytes([h[0], h[1]]), h[6], pdu)
}

async fn ask(s: &mut TcpStream, pdu: &[u8]) -> Vec<u8> {
    s.write_all(&adu(7, 1, pdu)).await.expect("send");
    let (tid, unit, p) = reply(s).await;
    assert_eq!((tid, unit), (7, 1));
    p
}

fn regs(pdu: &[u8]) -> Vec<u16> {
    assert_eq!(pdu[1] as usize, pdu.len() - 2, "{pdu:?}");
    pdu[2..].chunks(2).map(|c| u16::from_be_bytes([c[0], c[1]])).collect()
}

/// Waits until the connection is closed by the server.
async fn closed(s: &mut TcpStream) -> bool {
    let mut b = [0u8; 64];
    matches!(
        tokio::time::timeout(Duration::from_secs(5), s.read(&mut b)).await,
        Ok(Ok(0) | Err(_))
    )
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn openplc_map_reads_and_writes_every_area() {
    let f = start("map", |_| {}).await;
    let h = f.runtime.as_ref().unwrap().handle();
    let mut s = TcpStream::connect(f.addr).await.unwrap();
    // An input set by the I/O (here: a direct write) drives Motor through the program.
    let snap = h.snapshot();
    let place = |n: &str| match snap.program.layout.resolve(n).unwrap() {
        alba_ir::Target::Value { place, .. } => place,
        t => panic!("{t:?}"),
    };
    h.write(place("Start"), alba_model::Value::Bool(true)).await.unwrap();
    h.write(place("Level"), alba_model::Value::Int(-2)).await.unwrap();
    // FC2: discrete input 0 = %IX0.0; FC4: input register 2 = %IW2.
    assert_eq!(ask(&mut s, &[2, 0, 0, 0, 3]).await, [2, 1, 1]);
    assert_eq!(regs(&ask(&mut s, &[4, 0, 0, 0, 3]).await), [0, 0, 0xFFFE]);
    // FC1: coil 0 = %QX0.0 = Motor, on after a scan.
    for _ in 0..500 {
        if ask(&mut s, &[1, 0, 0, 0, 1]).await == [1, 1, 1] {
            break;
        }
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
    assert_eq!(ask(&mut s, &[1, 0, 0, 0, 1]).await, [1, 1, 1]);
    // FC5 on coil 9 = %QX1.1 = Lamp (not written by the program).
    assert_eq!(ask(&mut s, &[5, 0, 9, 0xFF, 0]).await, [5, 0, 9, 0xFF, 0]);
    assert_eq!(ask(&mut s, &[1, 0, 8, 0, 2]).await, [1, 1, 2]);
    assert_eq!(
        h.snapshot().read(place("Lamp")),
        alba_model::Value::Bool(true),
        "written at the scan boundary, before the reply"
    );
    // FC15 across the image's end (16 coils here) into Modbus-only storage.
    assert_eq!(ask(&mut s, &[15, 0, 14, 0, 4, 1, 0b1010]).await, [15, 0, 14, 0, 4]);
    assert_eq!(ask(&mut s, &[1, 0, 14, 0, 4]).await, [1, 1, 0b1010]);
    // FC6/FC3: holding register 1 = %QW1 (INT), 3 = %QW3 (DINT tag: 0..65535).
    assert_eq!(ask(&mut s, &[6, 0, 1, 0xFF, 0xFE]).await, [6, 0, 1, 0xFF, 0xFE]);
    assert_eq!(h.snapshot().read(place("Valve")), alba_model::Value::Int(-2));
    ask(&mut s, &[6, 0, 3, 0xFF, 0xFE]).await;
    assert_eq!(h.snapshot().read(place("Big")), alba_model::Value::Dint(65534));
    // FC16 on %MW2 (register 1026) and %MD4 (REAL, registers 2056-2057, high word first).
    let r = 1.5f32.to_be_bytes();
    assert_eq!(
        ask(&mut s, &[16, 0x04, 0x02, 0, 1, 2, 0x12, 0x34]).await,
        [16, 0x04, 0x02, 0, 1]
    );
    assert_eq!(h.snapshot().read(place("Word")), alba_model::Value::Int(0x1234));
    ask(&mut s, &[16, 0x08, 0x08, 0, 2, 4, r[0], r[1], r[2], r[3]]).await;
    assert_eq!(h.snapshot().read(place("Ratio")), alba_model::Value::Real(1.5));
    // The %MW and %MD windows show the same marker bytes: %MW2 is bytes 4-5 = register 2050's pair...
    // register 1024+n and 2048+n are both bytes 2n, 2n+1.
    assert_eq!(regs(&ask(&mut s, &[3, 0x04, 0x02, 0, 1]).await), [0x1234]);
    assert_eq!(regs(&ask(&mut s, &[3, 0x08, 0x02, 0, 1]).await), [0x1234]);
    assert_eq!(
        regs(&ask(&mut s, &[3, 0x04, 0x08, 0, 2]).await),
        [u16::from_be_bytes([r[0], r[1]]), u16::from_be_bytes([r[2], r[3]])]
    );
    // Modbus-only storage in %ML's range reads back what was written.
    ask(&mut s, &[6, 0x10, 0x00, 0xAB, 0xCD]).await;
    assert_eq!(regs(&ask(&mut s, &[3, 0x10, 0x00, 0, 1]).await), [0xABCD]);
    // FC23: write before read, in one request.
    assert_eq!(
        regs(&ask(&mut s, &[23, 0, 0, 0, 4, 0, 1, 0, 1, 2, 0, 42]).await),
        [0, 42, 0, 65534]
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn explicit_addresses_hold_whole_values() {
    let f = start("explicit", |_| {}).await;
    let h = f.runtime.as_ref().unwrap().handle();
    let mut s = TcpStream::connect(f.addr).await.unwrap();
    let snap = h.snapshot();
    let place = |n: &str| match snap.program.layout.resolve(n).unwrap() {
        alba_ir::Target::Value { place, .. } => place,
        t => panic!("{t:?}"),
    };
    // Speed DINT on hr 8192-8193, Temp REAL on 8194-8195, BigL LINT on 8196-8199.
    let t = (-12.25f32).to_be_bytes();
    let l = (-5_000_000_000i64).to_be_bytes();
    let mut pdu = vec![16, 0x20, 0x00, 0, 8, 16, 0xFF, 0xFF, 0xFF, 0xF6, t[0], t[1], t[2], t[3]];
    pdu.extend_from_slice(&l);
    assert_eq!(ask(&mut s, &pdu).await, [16, 0x20, 0x00, 0, 8]);
    let snap = h.snapshot();
    assert_eq!(snap.read(place("Speed")), alba_model::Value::Dint(-10));
    assert_eq!(snap.read(place("Temp")), alba_model::Value::Real(-12.25));
    assert_eq!(snap.read(place("BigL")), alba_model::Value::Lint(-5_000_000_000));
    assert_eq!(
        regs(&ask(&mut s, &[3, 0x20, 0x00, 0, 8]).await),
        [0xFFFF, 0xFFF6, 0xC144, 0, 0xFFFF, 0xFFFE, 0xD5FA, 0x0E00]
    );
    // Half of a DINT, a write past the entries, a gap: illegal data address; nothing written.
    assert_eq!(ask(&mut s, &[6, 0x20, 0x01, 0, 1]).await, [0x86, 2]);
    assert_eq!(ask(&mut s, &[16, 0x20, 0x00, 0, 1, 2, 0, 1]).await, [0x90, 2]);
    assert_eq!(ask(&mut s, &[3, 0x20, 0x09, 0, 1]).await, [0x83, 2]);
    assert_eq!(h.snapshot().read(place("Speed")), alba_model::Value::Dint(-10));
    // A SINT takes -128..127 only; a non-finite REAL is refused.
    assert_eq!(ask(&mut s, &[6, 0x20, 0x08, 0, 200]).await, [0x86, 3]);
    assert_eq!(
        ask(&mut s, &[6, 0x20, 0x08, 0xFF, 0x80]).await,
        [6, 0x20, 0x08, 0xFF, 0x80]
    );
    assert_eq!(h.snapshot().read(place("Small")), alba_model::Value::Sint(-128));
    assert_eq!(
        ask(&mut s, &[16, 0x20, 0x02, 0, 2, 4, 0x7F, 0xC0, 0, 0]).await,
        [0x90, 3]
    );
    // A BOOL tag on coil 8192 drives the timer; its preset and DN bit are mapped too.
    assert_eq!(
        ask(&mut s, &[6, 0x20, 0x6C, 0, 20]).await,
        [0x86, 2],
        "half of Delay.PRE"
    );
    assert_eq!(
        ask(&mut s, &[16, 0x20, 0x6C, 0, 2, 4, 0, 0, 0, 20]).await,
        [16, 0x20, 0x6C, 0, 2]
    );
    assert_eq!(ask(&mut s, &[5, 0x20, 0x00, 0xFF, 0]).await, [5, 0x20, 0x00, 0xFF, 0]);
    assert_eq!(h.snapshot().read(place("Flag")), alba_model::Value::Bool(true));
    for _ in 0..500 {
        if ask(&mut s, &[2, 0x20, 0x00, 0, 1]).await == [2, 1, 1] {
            break;
        }
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    assert_eq!(ask(&mut s, &[2, 0x20, 0x00, 0, 1]).await, [2, 1, 1], "Delay.DN");
    // System tags and inputs on input registers / discrete inputs.
    let before = h.snapshot().stats.max_us;
    let r = regs(&ask(&mut s, &[4, 0x04, 0x00, 0, 2]).await);
    let max = (u64::from(r[0]) << 16) | u64::from(r[1]);
    assert!(before <= max && max <= h.snapshot().stats.max_us, "S:SCANMAX {max}");
    assert_eq!(ask(&mut s, &[2, 0x23, 0x28, 0, 1]).await, [2, 1, 0], "Start on di 9000");
    // Nothing may write discrete inputs or input registers: no such function codes.
    assert_eq!(ask(&mut s, &[0x41, 0, 0]).await, [0xC1, 1]);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn exceptions_for_illegal_addresses_functions_and_values() {
    let f = start("exceptions", |_| {}).await;
    let mut s = TcpStream::connect(f.addr).await.unwrap();
    // Past OpenPLC's ranges with nothing mapped there.
    assert_eq!(ask(&mut s, &[1, 0x1F, 0xFF, 0, 3]).await, [0x81, 2]);
    assert_eq!(ask(&mut s, &[4, 0x03, 0xFF, 0, 4]).await, [0x84, 2]);
    assert_eq!(ask(&mut s, &[3, 0xFF, 0xFF, 0, 1]).await, [0x83, 2]);
    assert_eq!(ask(&mut s, &[5, 0x30, 0x00, 0xFF, 0]).await, [0x85, 2]);
    // Quantities and values.
    assert_eq!(ask(&mut s, &[3, 0, 0, 0, 0]).await, [0x83, 3]);
    assert_eq!(ask(&mut s, &[3, 0, 0, 0, 126]).await, [0x83, 3]);
    assert_eq!(ask(&mut s, &[5, 0, 0, 0x12, 0x34]).await, [0x85, 3]);
    assert_eq!(ask(&mut s, &[16, 0, 0, 0, 2, 3, 0, 0, 0]).await, [0x90, 3]);
    assert_eq!(ask(&mut s, &[3, 0, 0]).await, [0x83, 3]);
    // Functions.
    assert_eq!(ask(&mut s, &[8, 0, 0, 0, 0]).await, [0x88, 1]);
    assert_eq!(ask(&mut s, &[43, 14, 1, 0]).await, [0xAB, 1]);
    // Unit ids: 1 (configured), 0 and 255 are answered; others get 0x0B.
    for unit in [0u8, 1, 255] {
        s.write_all(&adu(9, unit, &[3, 0, 0, 0, 1])).await.unwrap();
        assert_eq!(reply(&mut s).await, (9, unit, vec![3, 2, 0, 0]));
    }
    s.write_all(&adu(9, 2, &[3, 0, 0, 0, 1])).await.unwrap();
    assert_eq!(reply(&mut s).await, (9, 2, vec![0x83, 0x0B]));
    // The connection is still good after all that.
    assert_eq!(regs(&ask(&mut s, &[3, 0, 0, 0, 1]).await), [0]);
    assert_eq!(f.server.counters.exceptions.load(Ordering::Relaxed), 12);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pipelined_and_fragmented_requests_are_answered_in_order() {
    let f = start("pipeline", |_| {}).await;
    let mut s = TcpStream::connect(f.addr).await.unwrap();
    // 50 requests in one segment, writes and reads mixed.
    let mut burst = Vec::new();
    for i in 0..50u16 {
        burst.extend(adu(i, 1, &[6, 0x04, 0x10, 0, i as u8]));
        burst.extend(adu(1000 + i, 1, &[3, 0x04, 0x10, 0, 1]));
    }
    s.write_all(&burst).await.unwrap();
    for i in 0..50u16 {
        assert_eq!(reply(&mut s).await, (i, 1, vec![6, 0x04, 0x10, 0, i as u8]));
        assert_eq!(reply(&mut s).await, (1000 + i, 1, vec![3, 2, 0, i as u8]));
    }
    // One request a byte at a time.
    for b in adu(77, 1, &[3, 0x04, 0x10, 0, 1]) {
        s.write_all(&[b]).await.unwrap();
        tokio::time::sleep(Duration::from_millis(2)).await;
    }
    assert_eq!(reply(&mut s).await, (77, 1, vec![3, 2, 0, 49]));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn malformed_frames_close_the_connection_and_the_server_keeps_serving() {
    let f = start("malformed", |_| {}).await;
    let bad: [&[u8]; 4] = [
        b"GET / HTTP/1.1\r\n\r\n",
        &[0, 1, 0, 0, 0, 1, 1],          // length 1: no function code
        &[0, 1, 0, 0, 0x01, 0x00, 1, 3], // length 256
        &[0, 1, 0, 7, 0, 6, 1, 3, 0, 0, 0, 1],
    ];
    for b in bad {
        let mut s = TcpStream::connect(f.addr).await.unwrap();
        s.write_all(b).await.unwrap();
        assert!(closed(&mut s).await, "{b:?}");
    }
    // A good request before a bad one is answered first.
    let mut s = TcpStream::connect(f.addr).await.unwrap();
    let mut two = adu(5, 1, &[3, 0, 0, 0, 1]);
    two.extend_from_slice(&[0, 6, 0xAA, 0xBB, 0, 6, 1, 3, 0, 0, 0, 1]);
    s.write_all(&two).await.unwrap();
    assert_eq!(reply(&mut s).await, (5, 1, vec![3, 2, 0, 0]));
    assert!(closed(&mut s).await);
    assert_eq!(f.server.counters.invalid.load(Ordering::Relaxed), 5);
    // Random bytes on many connections; then a normal client is served.
    let mut seed = 0x2545F4914F6CDD1Du64;
    for _ in 0..50 {
        let mut junk = vec![0u8; 300];
        for b in junk.iter_mut() {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            *b = seed as u8;
        }
        let mut s = TcpStream::connect(f.addr).await.unwrap();
        let _ = s.write_all(&junk).await;
    }
    let mut s = TcpStream::connect(f.addr).await.unwrap();
    assert_eq!(regs(&ask(&mut s, &[3, 0, 0, 0, 1]).await), [0]);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn connection_limit_and_idle_timeout() {
    let f = start("limits", |s| {
        s.max_connections = 2;
        // Long enough that a loaded machine gets both first requests in before it
        // (300 ms closed `a` before its first request once in CI).
        s.idle_timeout = Some(Duration::from_secs(2));
    })
    .await;
    let mut a = TcpStream::connect(f.addr).await.unwrap();
    let mut b = TcpStream::connect(f.addr).await.unwrap();
    assert_eq!(regs(&ask(&mut a, &[3, 0, 0, 0, 1]).await), [0]);
    assert_eq!(regs(&ask(&mut b, &[3, 0, 0, 0, 1]).await), [0]);
    // A third is closed at once.
    let mut c = TcpStream::connect(f.addr).await.unwrap();
    assert!(closed(&mut c).await);
    assert_eq!(f.server.counters.refused.load(Ordering::Relaxed), 1);
    // A half-open client (a partial frame, then silence) is closed by the
    // idle timeout, and its slot is free again.
    a.write_all(&[0, 1, 0, 0, 0, 6, 1]).await.unwrap();
    assert!(closed(&mut a).await);
    assert!(closed(&mut b).await, "idle");
    assert!(f.server.counters.timeouts.load(Ordering::Relaxed) >= 2);
    let mut d = TcpStream::connect(f.addr).await.unwrap();
    assert_eq!(regs(&ask(&mut d, &[3, 0, 0, 0, 1]).await), [0]);
}

/// A flood of Modbus clients cannot stall the scan (issue 18), asserted by
/// counting: more clients than `max_connections` are turned away, and each
/// accepted connection pipelines 600 FC16 writes and 600 FC3 reads in one
/// burst, yet the engine never has more requests waiting than there are
/// connections (a connection's thread waits for each write to be applied
/// before it reads the next request), every request is answered in order
/// without a single "busy" exception, and the engine scans on while the
/// flood is served.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_modbus_flood_is_bounded_by_the_connections_and_scans_go_on() {
    const CONNS: usize = 8;
    const WRITES: u16 = 600;
    let f = start("flood", |s| s.max_connections = CONNS).await;
    let h = f.runtime.as_ref().expect("runtime").handle();
    let mut socks = Vec::new();
    for _ in 0..CONNS {
        let mut s = TcpStream::connect(f.addr).await.unwrap();
        assert_eq!(regs(&ask(&mut s, &[3, 0x20, 0, 0, 2]).await).len(), 2, "served");
        socks.push(s);
    }
    // Beyond the limit: closed at once, nothing queued for them.
    for _ in 0..4 {
        let mut s = TcpStream::connect(f.addr).await.unwrap();
        assert!(closed(&mut s).await);
    }
    assert_eq!(f.server.counters.refused.load(Ordering::Relaxed), 4);
    let mut clients = tokio::task::JoinSet::new();
    for (c, s) in socks.into_iter().enumerate() {
        let h = h.clone();
        clients.spawn(async move {
            let (mut rd, mut wr) = s.into_split();
            let mut burst = Vec::new();
            for i in 0..WRITES {
                // Speed (DINT, hr 8192-8193) := c·100000 + i, then read back.
                let v = (c as u32 * 100_000 + u32::from(i)).to_be_bytes();
                burst.extend(adu(2 * i, 1, &[16, 0x20, 0, 0, 2, 4, v[0], v[1], v[2], v[3]]));
                burst.extend(adu(2 * i + 1, 1, &[3, 0x20, 0, 0, 2]));
            }
            let send = tokio::spawn(async move { wr.write_all(&burst).await.map(|()| wr) });
            // The scans done when the first and the last reply came.
            let mut scans = (0, 0);
            for i in 0..2 * WRITES {
                let mut hd = [0u8; 7];
                tokio::time::timeout(Duration::from_secs(30), rd.read_exact(&mut hd))
                    .await
                    .expect("no reply")
                    .expect("connection closed");
                let len = u16::from_be_bytes([hd[4], hd[5]]) as usize;
                let mut pdu = vec![0u8; len - 1];
                rd.read_exact(&mut pdu).await.expect("reply body");
                assert_eq!(u16::from_be_bytes([hd[0], hd[1]]), i, "in order");
                assert!(pdu[0] & 0x80 == 0, "connection {c}, request {i}: exception {pdu:?}");
                if i == 0 {
                    scans.0 = h.snapshot().scans;
                }
            }
            scans.1 = h.snapshot().scans;
            let _keep_open = send.await.expect("sender").expect("burst sent");
            scans
        });
    }
    let (mut first, mut last, mut served) = (u64::MAX, 0, 0);
    while let Some(r) = clients.join_next().await {
        let (a, b) = r.expect("client");
        (first, last, served) = (first.min(a), last.max(b), served + 1);
    }
    assert_eq!(served, CONNS);
    assert_eq!(f.server.counters.exceptions.load(Ordering::Relaxed), 0);
    assert!(
        (1..=CONNS).contains(&h.queue_peak()),
        "{} requests waited for the engine at once from {CONNS} connections",
        h.queue_peak()
    );
    assert!(
        last > first,
        "no scan while {} requests were served",
        2 * CONNS * WRITES as usize
    );
}

#[test]
fn bad_modbus_tags_are_reported_where_they_are_written() {
    let toml = "name = \"mb\"\nprograms = [\"main.lad\"]\n[modbus.tags]\nSped = \"hr 8192\"\n\
Speed = \"coil 8192\"\n\"S:SCANMAX\" = \"hr 8300\"\nStart = \"coil 8200\"\nTemp = \"hr 9000\"\nBigL = \"hr 9001\"\nDelay = \"hr 9100\"\n";
    let dir = project("diags", toml);
    let c = alba_load::compile_dir(&dir);
    let msgs: Vec<String> = c.diagnostics.iter().map(|d| d.short(c.files())).collect();
    let file = dir.join("alba.toml").display().to_string();
    let want: Vec<String> = [
        "4:1: error[E106]: unknown tag `Sped`",
        "5:9: error[E106]: `Speed` is a DINT: it goes on registers (`hr`, `ir`)",
        "6:15: error[E106]: `S:SCANMAX` is read-only: clients write holding registers, so put it on an input register (`ir`)",
        "7:9: error[E106]: `Start` is an input: clients write coils, so put it on a discrete input (`di`)",
        "9:8: error[E106]: `BigL` (hr 9001 to 9004) overlaps `Temp` (hr 9000 to 9001)",
        "10:1: error[E106]: `Delay` is a structure: map its members (`Delay.PRE`, `Delay.ACC`, `Delay.DN`)",
    ]
    .iter()
    .map(|m| format!("{file}:{m}"))
    .collect();
    assert_eq!(msgs, want);
}
