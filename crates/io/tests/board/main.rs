//! Controller mode end to end against an emulated board: the remote-I/O
//! firmware built with avr-gcc runs in simavr (`tools/simavr/board.c`,
//! paced to real time, its UART on a pseudo-terminal), and the host driver
//! talks to it through the pty — directly, or through a fault-injecting
//! proxy.
//!
//! These tests need the AVR toolchain and simavr, so they are `#[ignore]`d
//! in `cargo test --workspace`; `./test.sh` runs them in its Arduino step
//! after installing the tools (`cargo test -p alba-io --test board --
//! --ignored`). They print the measured round trip, cycle rate and
//! recovery times; they never assert a duration.

mod attach;
mod emu;
mod proxy;
mod slave;

use alba_io::arduino::{ArduinoIo, Config, Counts, Status};
use alba_io::firmware::Link;
use alba_ir::{Place, Target};
use alba_model::Value;
use alba_runtime::{Options, Runtime, Snapshot};
use emu::Emu;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// One emulated board at a time: each takes a good part of a core.
fn serial() -> MutexGuard<'static, ()> {
    static M: Mutex<()> = Mutex::new(());
    M.lock().unwrap_or_else(|p| p.into_inner())
}

/// The aurora map on a Nano: DI D2 D3 D4 D5 D7 D8, DO D12 D13 A0-A3, AI A4-A7, AO D6 D9 D10 D11.
const PINS: &str = "D12,D13,A0,A1,A2,A3,D6:pwm,D9:pwm,D10:pwm,D11:pwm";
const COUNTS: Counts = Counts {
    di: 6,
    r#do: 6,
    ai: 4,
    ao: 4,
};

fn config(port: &std::path::Path, link: Link) -> Config {
    let mut c = Config::new(&port.to_string_lossy(), COUNTS);
    c.link = link;
    // The emulated board does not reset on open.
    c.reset_delay = Duration::ZERO;
    c.backoff_min = Duration::from_millis(50);
    c.backoff_max = Duration::from_millis(400);
    c
}

/// Waits up to `secs` for `f`, returning how long it took.
fn wait(what: &str, secs: u64, mut f: impl FnMut() -> bool) -> Duration {
    let t0 = Instant::now();
    while !f() {
        assert!(t0.elapsed() < Duration::from_secs(secs), "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
    t0.elapsed()
}

fn value(s: &Snapshot, name: &str) -> Value {
    match s.program.layout.resolve(name) {
        Ok(Target::Value { place, .. }) => s.read(place),
        other => panic!("{name}: {other:?}"),
    }
}

fn place(rt: &Runtime, name: &str) -> Place {
    match rt.handle().snapshot().program.layout.resolve(name) {
        Ok(Target::Value { place, .. }) => place,
        other => panic!("{name}: {other:?}"),
    }
}

/// A project whose logic copies inputs to outputs in ways that show every
/// direction: DO0 = DI0, DO1 = NOT DI1, DO5 = DI5, AO0 = AI0 / 4, AO3 = AI3 / 4.
fn project(dir: &std::path::Path) -> Arc<alba_ir::Program> {
    std::fs::create_dir_all(dir).expect("mkdir");
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"remote\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[board]\nmodel = \"nano\"\npinmap = \"aurora\"\n",
    )
    .expect("toml");
    std::fs::write(
        dir.join("tags.csv"),
        "name,type,address,initial,retain,description\n\
         Start,BOOL,DI:1/0,,,\nStop,BOOL,DI:1/1,,,\nLast,BOOL,DI:1/5,,,\n\
         Motor,BOOL,DO:2/0,,,\nIdle,BOOL,DO:2/1,,,\nLamp,BOOL,DO:2/5,,,\n\
         Level,INT,AI:3/0,,,\nFlow,INT,AI:3/3,,,\nValve,INT,AO:4/0,,,\nPump,INT,AO:4/3,,,\n",
    )
    .expect("tags");
    std::fs::write(
        dir.join("main.lad"),
        "XIC(Start)OTE(Motor);\nXIO(Stop)OTE(Idle);\nXIC(Last)OTE(Lamp);\nDIV(Level,4,Valve);\nDIV(Flow,4,Pump);\n",
    )
    .expect("lad");
    let c = alba_load::compile_dir(dir);
    assert!(c.diagnostics.is_empty(), "{:?}", c.diagnostics);
    Arc::new(c.program.expect("program"))
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = emu::target_dir().join("ctl-test").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("mkdir");
    d
}

fn report(what: &str, s: &Status, since: Instant, cycles0: u64) {
    let secs = since.elapsed().as_secs_f64();
    println!(
        "{what}: last cycle {:.2} ms, {:.1} cycles/s, {} errors, {} opens",
        s.last_cycle.map_or(0.0, |d| d.as_secs_f64() * 1e3),
        (s.cycles - cycles0) as f64 / secs,
        s.errors,
        s.opens
    );
}

/// Inputs on the board's pins reach the program, its outputs reach the pins.
fn end_to_end(link: Link) {
    let _g = serial();
    let dir = tmp(&format!("e2e-{}", link.name()));
    let program = project(&dir.join("project"));
    let mut board = Emu::start(link, &dir.join("board.tty"), PINS);
    let io = ArduinoIo::start(config(&dir.join("board.tty"), link)).expect("driver");
    let rt = Runtime::start(program, Options::new(10), Box::new(io)).expect("runtime");
    let snap = || rt.handle().snapshot();
    let up = wait("the link", 10, || value(&snap(), "S:IOOK") == Value::Bool(true));
    println!("{}: link up {} ms after start", link.name(), up.as_millis());

    // Idle = NOT Stop: on at once.
    wait("Idle on the pin", 5, || board.get()[1] == 1);
    let t = Instant::now();
    board.set("D2", 1);
    wait("Start in the program", 5, || {
        value(&snap(), "Start") == Value::Bool(true)
    });
    wait("Motor on its pin", 5, || board.get()[0] == 1);
    println!(
        "{}: input pin to output pin {} ms",
        link.name(),
        t.elapsed().as_millis()
    );
    board.set("D3", 1);
    board.set("D8", 1);
    wait("Idle off and Lamp on", 5, || {
        let p = board.get();
        p[1] == 0 && p[5] == 1
    });
    board.set("A4", 1000);
    board.set("A7", 99);
    wait("the analog readings", 5, || {
        let s = snap();
        value(&s, "Level") == Value::Int(1000) && value(&s, "Flow") == Value::Int(99)
    });
    wait("the PWM duties", 5, || {
        let p = board.get();
        p[6] == 250 && p[9] == 24
    });
    board.set("D2", 0);
    wait("Motor off", 5, || board.get()[0] == 0);
    let s = snap();
    assert_eq!(value(&s, "S:IOOK"), Value::Bool(true));
    println!("{}: S:IOERRORS = {:?}", link.name(), value(&s, "S:IOERRORS"));
    rt.shutdown();
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn modbus_end_to_end() {
    end_to_end(Link::Modbus);
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn aurora_end_to_end() {
    end_to_end(Link::Aurora);
}

/// Round trip and cycle rate of the bare link (no program).
#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn modbus_cycle_rate() {
    let _g = serial();
    let dir = tmp("rate");
    let _board = Emu::start(Link::Modbus, &dir.join("board.tty"), PINS);
    let io = ArduinoIo::start(config(&dir.join("board.tty"), Link::Modbus)).expect("driver");
    wait("the link", 10, || io.status().ok);
    let c0 = io.status().cycles;
    let t0 = Instant::now();
    // Every cycle's duration, sampled as the count moves.
    let mut seen = c0;
    let mut times = Vec::new();
    while t0.elapsed() < Duration::from_secs(2) {
        let s = io.status();
        if s.cycles != seen {
            seen = s.cycles;
            times.extend(s.last_cycle);
        }
        std::thread::sleep(Duration::from_micros(500));
    }
    let s = io.status();
    assert!(s.cycles > c0, "no cycle in 2 s");
    report("modbus at 115200 baud (4 transactions a cycle)", &s, t0, c0);
    times.sort();
    if !times.is_empty() {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        println!(
            "modbus cycle: min {:.2} ms, median {:.2} ms, max {:.2} ms over {} cycles (wire time alone: 6.8 ms)",
            ms(times[0]),
            ms(times[times.len() / 2]),
            ms(times[times.len() - 1]),
            times.len()
        );
    }
}

/// The board unplugged: the link drops, the board's watchdog turns its
/// outputs off, the driver retries with back-off; plugged back (a new pty
/// behind the same name), it recovers and writes the outputs again.
fn unplug_replug(link: Link) {
    let _g = serial();
    let dir = tmp(&format!("replug-{}", link.name()));
    let tty = dir.join("board.tty");
    let mut board = Emu::start(link, &tty, PINS);
    let io = ArduinoIo::start(config(&tty, link)).expect("driver");
    io.set_outputs(&[true, false, false, false, false, true], &[200, 0, 0, 7]);
    wait("outputs on the pins", 10, || {
        let p = board.get();
        p[0] == 1 && p[5] == 1 && p[6] == 200 && p[9] == 7
    });
    wait("a complete cycle", 10, || io.status().ok);
    let e0 = io.status().errors;
    board.unplug();
    let lost = Instant::now();
    let down = wait("the link to drop", 5, || !io.status().ok);
    let safe = wait("the safe state on the board", 5, || board.get().iter().all(|v| *v == 0));
    println!(
        "{}: unplugged: link down after {} ms, board outputs off after {} ms",
        link.name(),
        down.as_millis(),
        (lost.elapsed()).as_millis().min(safe.as_millis() + down.as_millis())
    );
    std::thread::sleep(Duration::from_millis(600));
    assert!(!io.status().ok);
    assert!(io.status().errors > e0);
    let opens = io.status().opens;
    board.plug();
    let back = wait("the link to recover", 10, || io.status().ok);
    wait("the outputs again", 5, || {
        let p = board.get();
        p[0] == 1 && p[5] == 1 && p[6] == 200
    });
    println!(
        "{}: replugged: link up again after {} ms (opens {} -> {})",
        link.name(),
        back.as_millis(),
        opens,
        io.status().opens
    );
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn modbus_unplug_replug() {
    unplug_replug(Link::Modbus);
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn aurora_unplug_replug() {
    unplug_replug(Link::Aurora);
}

/// Faults injected between the driver and the board, each for a while,
/// then a clean line again: no panic, the status drops and errors count,
/// the board's outputs go to the safe state while it hears nothing valid,
/// and everything recovers.
fn faults(link: Link) {
    use proxy::Fault;
    let _g = serial();
    let dir = tmp(&format!("faults-{}", link.name()));
    let mut board = Emu::start(link, &dir.join("board.tty"), PINS);
    let proxy = proxy::Proxy::start(&dir.join("board.tty"), &dir.join("proxy.tty"));
    let io = ArduinoIo::start(config(&dir.join("proxy.tty"), link)).expect("driver");
    io.set_outputs(&[true, true, false, false, false, false], &[100, 0, 0, 0]);
    wait("outputs through the proxy", 10, || {
        let p = board.get();
        p[0] == 1 && p[1] == 1 && p[6] == 100
    });
    wait("a complete cycle", 10, || io.status().ok);
    for fault in [Fault::BadCrc, Fault::Truncate, Fault::Silence, Fault::Garbage] {
        let e0 = io.status().errors;
        proxy.set(fault);
        let down = wait(&format!("the link to drop under {fault:?}"), 5, || !io.status().ok);
        let safe = wait(&format!("the safe state under {fault:?}"), 5, || {
            board.get().iter().all(|v| *v == 0)
        });
        assert!(!io.status().ok, "{fault:?}");
        proxy.set(Fault::None);
        let back = wait(&format!("recovery after {fault:?}"), 10, || io.status().ok);
        wait(&format!("the outputs after {fault:?}"), 5, || {
            let p = board.get();
            p[0] == 1 && p[1] == 1 && p[6] == 100
        });
        let s = io.status();
        println!(
            "{} {fault:?}: link down after {} ms, outputs off {} ms later, recovered {} ms after the fault ended; \
             errors +{} (last: {})",
            link.name(),
            down.as_millis(),
            safe.as_millis(),
            back.as_millis(),
            s.errors - e0,
            s.last_error.as_deref().unwrap_or("-")
        );
        assert!(s.errors > e0, "{fault:?} was not counted");
    }
    // One answer in three damaged: the retries keep the link going.
    if link == Link::Modbus {
        let s0 = io.status();
        let t0 = Instant::now();
        proxy.set(Fault::BadCrcSometimes);
        wait("cycles through the damaged answers", 30, || {
            io.status().cycles > s0.cycles + 20
        });
        let s = io.status();
        proxy.set(Fault::None);
        assert!(s.errors > s0.errors, "the damaged answers were not counted");
        report("modbus with one answer in three damaged", &s, t0, s0.cycles);
        wait("the outputs on", 5, || board.get()[0] == 1);
    }
    drop(io);
    drop(proxy);
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn modbus_fault_injection() {
    faults(Link::Modbus);
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn aurora_fault_injection() {
    faults(Link::Aurora);
}

/// `S:IOOK` and `S:IOERRORS` follow a lost board inside a running program.
#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn status_tags_follow_the_link() {
    let _g = serial();
    let dir = tmp("status");
    let program = project(&dir.join("project"));
    let tty = dir.join("board.tty");
    let mut board = Emu::start(Link::Modbus, &tty, PINS);
    let rt = Runtime::start(
        program,
        Options::new(10),
        Box::new(ArduinoIo::start(config(&tty, Link::Modbus)).expect("driver")),
    )
    .expect("runtime");
    let snap = || rt.handle().snapshot();
    board.set("D2", 1);
    wait("Motor on", 10, || board.get()[0] == 1);
    let scans0 = snap().scans;
    board.unplug();
    wait("S:IOOK off", 5, || value(&snap(), "S:IOOK") == Value::Bool(false));
    let s = snap();
    assert!(matches!(value(&s, "S:IOERRORS"), Value::Dint(n) if n > 0));
    // The inputs keep their last value; the engine keeps scanning.
    assert_eq!(value(&s, "Start"), Value::Bool(true));
    wait("scans during the loss", 5, || snap().scans > scans0 + 20);
    wait("the board's outputs off", 5, || board.get()[0] == 0);
    let _ = place(&rt, "Motor");
    board.plug();
    wait("S:IOOK on again", 10, || value(&snap(), "S:IOOK") == Value::Bool(true));
    wait("Motor on again", 5, || board.get()[0] == 1);
    rt.shutdown();
}

/// GET `path` from the server at `addr` (HTTP/1.1, connection closed), the body.
fn http_get(addr: &str, path: &str) -> String {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(addr).expect("connect");
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n").expect("request");
    let mut r = String::new();
    s.read_to_string(&mut r).expect("response");
    let (head, body) = r.split_once("\r\n\r\n").expect("a response");
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    // Chunked or not, the JSON object of a tag is found by its name.
    body.to_string()
}

/// The value in `/api/tags` of the tag `name` (as JSON text).
fn api_value(body: &str, name: &str) -> Option<String> {
    let at = body.find(&format!("\"name\":\"{name}\""))?;
    let obj_start = body[..at].rfind('{')?;
    let obj = &body[obj_start..];
    let obj = &obj[..obj.find('}')? + 1];
    let v = obj.find("\"value\":")? + "\"value\":".len();
    let rest = &obj[v..];
    let end = rest.find([',', '}'])?;
    Some(rest[..end].to_string())
}

/// The real command: `alba run PROJECT --io arduino:PORT,reset_ms=0` serves
/// the board's pins as the project's I/O; the API shows them and `S:IOOK`.
#[test]
#[ignore = "needs avr-gcc, simavr and the alba binary: run by test.sh's Arduino step"]
fn alba_run_with_the_board() {
    use std::io::BufRead;
    let _g = serial();
    let dir = tmp("alba-run");
    project(&dir.join("project"));
    let tty = dir.join("board.tty");
    let mut board = Emu::start(Link::Modbus, &tty, PINS);
    let alba = emu::target_dir().join("debug").join("alba");
    assert!(alba.exists(), "{} is missing: cargo build -p alba-cli", alba.display());
    let mut child = std::process::Command::new(&alba)
        .arg("run")
        .arg(dir.join("project"))
        .args(["--http", "127.0.0.1:0", "--io"])
        .arg(format!("arduino:{},reset_ms=0", tty.display()))
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("alba run");
    let mut out = std::io::BufReader::new(child.stdout.take().expect("stdout"));
    let mut line = String::new();
    out.read_line(&mut line).expect("banner");
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|s| s.split('/').next())
        .unwrap_or_else(|| panic!("no address in `{line}`"))
        .to_string();
    let tags = || http_get(&addr, "/api/tags");
    wait("S:IOOK in the API", 10, || {
        api_value(&tags(), "S:IOOK").as_deref() == Some("true")
    });
    board.set("D2", 1);
    board.set("A4", 400);
    wait("Start and Level in the API", 10, || {
        let t = tags();
        api_value(&t, "Start").as_deref() == Some("true") && api_value(&t, "Level").as_deref() == Some("400")
    });
    wait("Motor and Valve on the pins", 5, || {
        let p = board.get();
        p[0] == 1 && p[6] == 100
    });
    board.unplug();
    wait("S:IOOK false in the API", 10, || {
        api_value(&tags(), "S:IOOK").as_deref() == Some("false")
    });
    board.plug();
    wait("S:IOOK again", 10, || {
        api_value(&tags(), "S:IOOK").as_deref() == Some("true")
    });
    // SIGTERM: the runtime stops with its outputs off, written to the board.
    let _ = std::process::Command::new("kill").arg(child.id().to_string()).status();
    let _ = child.wait();
    let t = Instant::now();
    wait("the outputs off after the stop", 5, || board.get()[0] == 0);
    println!("alba run: outputs off {} ms after it exited", t.elapsed().as_millis());
}

/// Relay boards: with active-low outputs, off is HIGH at power-up, on is
/// LOW, and the watchdog's safe state is HIGH again. PWM is not inverted.
#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn active_low_outputs() {
    let _g = serial();
    let dir = tmp("active-low");
    let tty = dir.join("board.tty");
    let mut board = Emu::start_with(Link::Modbus, true, false, &tty, PINS);
    wait("power-up: every output off, HIGH", 5, || board.get()[..6] == [1; 6]);
    let io = ArduinoIo::start(config(&tty, Link::Modbus)).expect("driver");
    io.set_outputs(&[true, false, false, false, false, true], &[30, 0, 0, 0]);
    wait("on = LOW", 10, || board.get() == [0, 1, 1, 1, 1, 0, 30, 0, 0, 0]);
    drop(io);
    // The driver's last write leaves the outputs as they were set; the
    // watchdog then turns them off: HIGH.
    wait("the safe state, HIGH", 5, || {
        board.get() == [1, 1, 1, 1, 1, 1, 0, 0, 0, 0]
    });
}

/// Inputs with their pull-up: a contact to GND (the pin LOW) is on, on
/// both links.
#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn input_pullup() {
    let _g = serial();
    for link in [Link::Modbus, Link::Aurora] {
        let dir = tmp(&format!("pullup-{}", link.name()));
        let tty = dir.join("board.tty");
        let mut board = Emu::start_with(link, false, true, &tty, PINS);
        for pin in ["D2", "D3", "D4", "D5", "D7", "D8"] {
            board.set(pin, 1);
        }
        board.set("D3", 0);
        let io = ArduinoIo::start(config(&tty, link)).expect("driver");
        wait("the inputs", 10, || {
            io.inputs().0 == [false, true, false, false, false, false]
        });
        board.set("D3", 1);
        board.set("D8", 0);
        wait("the inputs again", 10, || {
            io.inputs().0 == [false, false, false, false, false, true]
        });
    }
}
