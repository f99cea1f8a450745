//! The Modbus master driver against Alba's own Modbus TCP server as the
//! slave (a second runtime): outputs written by the master come back as
//! inputs through the slave's program, and the poll rate is measured with
//! `poll_ms = 1`. (The third-party slave, pymodbus over TCP and RTU, is
//! driven by tests/protocols/modbus_master.py from test.sh.)

use alba_diag::{FileId, Span};
use alba_io::modbus_master::ModbusMasterIo;
use alba_modbus::{Server, Settings};
use alba_model::address::Address;
use alba_project::config::{DeviceLink, ModbusArea, ModbusDevice, ModbusMapping};
use alba_runtime::{Options, Runtime, SimIo};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::net::TcpListener;
use tokio::sync::watch;

const TAGS: &str = "name,type,address,initial,retain,description\n\
Lamp0,BOOL,%QX0.0,,,\nLamp1,BOOL,%QX0.1,,,\nEcho0,BOOL,%QX0.2,,,\nEcho1,BOOL,%QX0.3,,,\nValve,INT,%QW0,,,\nSetp,INT,%MW0,,,\n";
// The slave's program: coils 2-3 echo coils 0-1 inverted, hr 1024 (%MW0) is hr 0 plus 1.
const LAD: &str = "XIO(Lamp0)OTE(Echo0);\nXIO(Lamp1)OTE(Echo1);\nADD(Valve,1,Setp);\n";
const TOML: &str = "name = \"slave\"\nscan_ms = 2\nprograms = [\"main.lad\"]\n[modbus]\n";

fn mapping(area: ModbusArea, start: u16, count: u16, at: Address) -> ModbusMapping {
    ModbusMapping {
        area,
        start,
        count,
        at,
        span: Span::new(FileId(0), 0..0),
    }
}

fn wait(what: &str, f: impl Fn() -> bool) {
    let t0 = Instant::now();
    while !f() {
        assert!(t0.elapsed() < Duration::from_secs(20), "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn master_against_albas_own_server() {
    let dir = std::env::temp_dir().join(format!("alba-io-master-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("cannot write the test project");
    for (f, t) in [("alba.toml", TOML), ("tags.csv", TAGS), ("main.lad", LAD)] {
        std::fs::write(dir.join(f), t).expect("cannot write the test project");
    }
    let c = alba_load::compile_dir(&dir);
    let program = c.program.unwrap_or_else(|| panic!("{:?}", c.diagnostics));
    let runtime = Runtime::start(Arc::new(program), Options::new(2), Box::new(SimIo)).expect("runtime");
    let server = Server::new(alba_modbus::Control::new(runtime.handle(), None), Settings::default());
    let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
    let addr = listener.local_addr().expect("address");
    let (closing, rx) = watch::channel(false);
    tokio::spawn(server.serve(listener, rx));

    let dev = ModbusDevice {
        name: "alba".into(),
        link: DeviceLink::Tcp(addr.to_string()),
        unit: 1,
        poll_ms: 1,
        timeout_ms: 500,
        retries: 1,
        refresh_ms: 1000,
        map: vec![
            mapping(ModbusArea::Coil, 0, 2, Address::DigitalOut(0)),
            mapping(ModbusArea::Coil, 2, 2, Address::DigitalIn(0)),
            mapping(ModbusArea::HoldingRegister, 0, 1, Address::AnalogOut(0)),
            mapping(ModbusArea::HoldingRegister, 1024, 1, Address::AnalogIn(0)),
        ],
        span: Span::new(FileId(0), 0..0),
    };
    let dev2 = dev.clone();
    let io = tokio::task::spawn_blocking(move || {
        let io = ModbusMasterIo::start(vec![dev]).expect("driver");
        wait("the link", || io.all_ok());
        io.set_outputs(&[true, false], &[41]);
        wait("the echo of [on, off], 42", || {
            io.inputs() == (vec![false, true], vec![42])
        });
        io.set_outputs(&[false, true], &[(-8i16) as u16]);
        wait("the echo of [off, on], -7", || {
            io.inputs() == (vec![true, false], vec![(-7i16) as u16])
        });
        // The poll rate: 2 reads a poll, writes only on change.
        let c0 = io.status()[0].1.cycles;
        let t0 = Instant::now();
        std::thread::sleep(Duration::from_secs(1));
        let rate = (io.status()[0].1.cycles - c0) as f64 / t0.elapsed().as_secs_f64();
        let last = io.status()[0].1.last_cycle;
        println!("poll_ms = 1 against Alba's Modbus server: {rate:.0} polls/s (2 requests each), last poll {last:?}");
        assert!(io.all_ok(), "{:?}", io.status());
        // A device mapping an address the slave does not have: the slave's
        // exception reply makes it unhealthy (S:IOOK false) but keeps the
        // connection, and the healthy device goes on.
        let mut bad = ModbusDevice {
            name: "bad".into(),
            map: vec![mapping(ModbusArea::InputRegister, 5000, 1, Address::AnalogIn(1))],
            ..dev2
        };
        bad.poll_ms = 5;
        let both = ModbusMasterIo::start(vec![bad]).expect("driver");
        wait("the refusal", || both.status()[0].1.errors >= 3);
        let s = &both.status()[0].1;
        assert!(!s.ok && !both.all_ok() && s.connects == 1, "{s:?}");
        assert!(
            s.last_error.as_deref().is_some_and(
                |e| e.contains("refused reading 1 input registers from 5000") && e.contains("illegal data address")
            ),
            "{s:?}"
        );
        drop(both);
        assert!(io.all_ok(), "{:?}", io.status());
        io
    })
    .await
    .expect("master");
    // The slave goes away: the device is lost, and counted.
    closing.send_replace(true);
    runtime.shutdown();
    tokio::task::spawn_blocking(move || {
        wait("the loss", || !io.all_ok());
        assert!(io.status()[0].1.errors > 0);
    })
    .await
    .expect("master");
    let _ = std::fs::remove_dir_all(&dir);
}
