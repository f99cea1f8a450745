//! Attach mode end to end: the start-stop example exported with its
//! monitoring link (`alba export arduino`), built with avr-gcc, runs on an
//! emulated Nano (`tools/simavr/board.c`); the runtime attaches to it over
//! the pty and mirrors its memory, and an operator's write reaches the
//! board's program.

use crate::emu::{self, Emu};
use crate::proxy::{Fault, Proxy};
use crate::{place, tmp, value, wait};
use alba_arduino::sketch::{self, Target};
use alba_io::arduino::{Config, Counts};
use alba_io::attach::AttachIo;
use alba_io::download::Link;
use alba_model::Value;
use alba_model::board::{Model, PinMap};
use alba_runtime::{Options, RunState, Runtime};
use std::sync::Arc;
use std::time::Duration;

fn target() -> Target {
    Target {
        model: Model::Nano,
        map: PinMap::preset("aurora").expect("preset"),
        active_low: false,
        scan_ms: 10,
        monitor: true,
        power_up_on: Vec::new(),
    }
}

fn example(name: &str) -> Arc<alba_ir::Program> {
    let c = alba_load::compile_dir(&emu::repo().join("examples").join(name));
    Arc::new(c.program.unwrap_or_else(|| panic!("{name}: {:?}", c.diagnostics)))
}

fn config(tty: &std::path::Path) -> Config {
    let mut c = Config::new(&tty.to_string_lossy(), Counts::default());
    c.reset_delay = Duration::ZERO;
    c.backoff_min = Duration::from_millis(50);
    c.backoff_max = Duration::from_millis(400);
    c.timeout = Duration::from_millis(200);
    c
}

fn options() -> Options {
    let mut o = Options::new(20);
    o.native = false;
    o
}

/// Builds `files` (a sketch folder's files) for the Nano into `dir`.
fn build(dir: &std::path::Path, files: &[(String, String)]) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).expect("mkdir");
    for (name, text) in files {
        std::fs::write(dir.join(name), text).expect("write");
    }
    let built = alba_arduino::toolchain::build(&dir.join(&files[0].0), Model::Nano, &dir.join("build"))
        .unwrap_or_else(|d| panic!("{}", d.message));
    println!("{}: {}", files[0].0, built.report());
    built.elf
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn the_studio_watches_and_writes_a_running_board() {
    let _g = crate::serial();
    let dir = tmp("attach");
    let prog = example("start-stop");
    let s = sketch::generate(&sketch::control_program(&prog), "start-stop", &target()).expect("sketch");
    let elf = build(&dir.join(&s.name), &s.files);
    // Motor on D12, Lamp on D13 (aurora); Start on D2, Stop on D3.
    let tty = dir.join("board.tty");
    let board = Emu::run(&emu::board_program(), &elf, &tty, "D12,D13");
    watch_and_write(board, &tty, prog);
}

/// The same with the byte-code interpreter (issue 19): its firmware, built
/// once, gets the program by `alba download`'s protocol — over a line that
/// damages a record now and then, which the board refuses (E04) and the
/// host sends again — then serves the link on the same serial port.
#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn the_studio_watches_and_writes_a_board_running_byte_code() {
    let _g = crate::serial();
    let dir = tmp("attach-bytecode");
    let prog = example("start-stop");
    let elf = build(
        &dir.join("alba_interp"),
        &alba_arduino::interp::generate(&target(), None),
    );
    let tty = dir.join("board.tty");
    let board = Emu::run(&emu::board_program(), &elf, &tty, "D12,D13");
    let bc = alba_arduino::bytecode::encode(&prog, "start-stop", &target()).expect("byte code");
    {
        let proxy = Proxy::start(&tty, &dir.join("proxy.tty"));
        proxy.set(Fault::BadRecordSometimes);
        let mut link = Link::open(&dir.join("proxy.tty").to_string_lossy()).expect("port");
        let sum = link.download(&bc.bytes, |_, _| {}).expect("download over a noisy line");
        let host = bc.bytes.iter().fold(0u16, |s, b| s.wrapping_add(u16::from(*b)));
        assert_eq!(sum, host, "the board's checksum of the download");
        assert!(link.retries > 0, "no record was damaged and sent again");
        println!(
            "download over a line damaging one line in three: {} records sent again",
            link.retries
        );
        proxy.set(Fault::None);
        assert_eq!(link.read(0, bc.bytes.len()).expect("read-back"), bc.bytes);
    }
    watch_and_write(board, &tty, prog);
}

/// Attach to `board` (running start-stop on the aurora pins): another
/// program is refused; the mirror follows the pins; a written preset
/// reaches the board's program; forces are refused.
fn watch_and_write(mut board: Emu, tty: &std::path::Path, prog: Arc<alba_ir::Program>) {
    // Another program's identity is refused, with the reason.
    let other = example("traffic-light");
    let io = AttachIo::start(config(tty), &other, &target()).expect("driver");
    let rt = Runtime::start(other, options(), Box::new(io)).expect("runtime");
    let mut rx = rt.handle().subscribe();
    wait("the refusal", 10, || rx.borrow_and_update().state == RunState::Faulted);
    let why = rx.borrow().fault.clone().unwrap_or_default();
    assert!(why.contains("runs another program"), "{why}");
    rt.shutdown();

    let io = AttachIo::start(config(tty), &prog, &target()).expect("driver");
    let rt = Runtime::start(prog.clone(), options(), Box::new(io)).expect("runtime");
    let h = rt.handle();
    let snap = || h.snapshot();
    wait("the link", 10, || value(&snap(), "S:IOOK") == Value::Bool(true));
    // The board's program runs: Start on D2 seals the motor in; the mirror shows it.
    board.set("D2", 1);
    wait("Motor on the pin", 5, || board.get()[0] == 1);
    board.set("D2", 0);
    let t0 = std::time::Instant::now();
    wait("Motor and the delay timer in the mirrored memory", 5, || {
        let s = snap();
        value(&s, "Motor") == Value::Bool(true) && matches!(value(&s, "Delay.ACC"), Value::Dint(v) if v > 0)
    });
    println!(
        "attach: the board's state reached the runtime {} ms after the pin",
        t0.elapsed().as_millis()
    );
    assert_eq!(value(&snap(), "Lamp"), Value::Bool(false), "the lamp waits 5 s");
    // The operator shortens the lamp delay on the board: the lamp lights.
    let rtk = tokio::runtime::Builder::new_current_thread().build().expect("tokio");
    rtk.block_on(h.write(place(&rt, "Delay.PRE"), Value::Dint(200)))
        .expect("write on the board");
    wait("Lamp on the pin after the written preset", 5, || board.get()[1] == 1);
    wait("the written preset read back", 5, || {
        value(&snap(), "Delay.PRE") == Value::Dint(200)
    });
    // Forces are refused in attach mode.
    let err = rtk
        .block_on(h.force("Start".into(), place(&rt, "Start"), Value::Bool(true)))
        .expect_err("no forces on a board");
    assert!(matches!(err, alba_runtime::Error::Attached { .. }), "{err}");
    assert!(err.to_string().contains("the board runs the program"), "{err}");
    // Stop on D3 stops the motor on the board; the mirror follows.
    board.set("D3", 1);
    wait("Motor off in the mirror", 5, || {
        value(&snap(), "Motor") == Value::Bool(false)
    });
    assert_eq!(board.get()[0], 0);
    rt.shutdown();
}
