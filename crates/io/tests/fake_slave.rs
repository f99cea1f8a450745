//! The host driver against a scripted Modbus slave on a pseudo-terminal
//! (no AVR tools needed): retries repair single errors without dropping
//! `S:IOOK`, an exception reply is reported as a pin-map mismatch, a silent
//! slave drops the link and a returning one restores it, with the outputs
//! written again.
#![cfg(unix)]

use alba_io::arduino::{ArduinoIo, Config, Counts};
use alba_modbus_proto::pdu::{self, Request};
use alba_modbus_proto::rtu::{self, encode_response, with_crc};
use serialport::{SerialPort, TTYPort};
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const COUNTS: Counts = Counts {
    di: 3,
    r#do: 2,
    ai: 2,
    ao: 1,
};

/// What the fake slave does.
#[derive(Default)]
struct Script {
    /// Damage the CRC of every n-th answer (0: never).
    bad_every: AtomicU32,
    /// Answer nothing.
    silent: AtomicBool,
    /// Answer every request with this exception (0: none).
    exception: AtomicU32,
    answers: AtomicU32,
    /// Last coils and registers written.
    coils: Mutex<Vec<bool>>,
    regs: Mutex<Vec<u16>>,
}

/// The request in a frame from the master (CRC checked).
fn parse(f: &[u8]) -> Option<Request<'_>> {
    let (_, p) = rtu::check(f).ok()?;
    pdu::parse(p).ok()
}

fn slave(mut port: TTYPort, s: Arc<Script>, stop: Arc<AtomicBool>) {
    let _ = port.set_timeout(Duration::from_millis(2));
    let mut frame = Vec::new();
    let mut buf = [0u8; 256];
    while !stop.load(Ordering::SeqCst) {
        match port.read(&mut buf) {
            Ok(n) if n > 0 => {
                frame.extend_from_slice(&buf[..n]);
                continue;
            }
            Ok(_) | Err(_) => {}
        }
        if frame.is_empty() {
            continue;
        }
        let f = std::mem::take(&mut frame);
        let Some(req) = parse(&f) else { continue };
        if s.silent.load(Ordering::SeqCst) {
            continue;
        }
        let mut answer = match s.exception.load(Ordering::SeqCst) {
            0 => {
                match &req {
                    Request::WriteMultipleCoils { count, bits, .. } => {
                        *s.coils.lock().expect("coils") = (0..usize::from(*count)).map(|i| pdu::bit(bits, i)).collect()
                    }
                    Request::WriteMultipleRegisters { values, .. } => {
                        *s.regs.lock().expect("regs") = pdu::registers(values).collect()
                    }
                    _ => {}
                }
                encode_response(1, &req, &[true, false, true], &[512, 1023])
            }
            code => with_crc(vec![1, req.function() | 0x80, code as u8]),
        };
        let n = s.answers.fetch_add(1, Ordering::SeqCst) + 1;
        let every = s.bad_every.load(Ordering::SeqCst);
        if every > 0 && n.is_multiple_of(every) {
            let last = answer.len() - 1;
            answer[last] ^= 0xFF;
        }
        let _ = port.write_all(&answer);
    }
}

fn wait(what: &str, mut f: impl FnMut() -> bool) {
    let t0 = Instant::now();
    while !f() {
        assert!(t0.elapsed() < Duration::from_secs(5), "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

struct Rig {
    io: ArduinoIo,
    script: Arc<Script>,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
    _slave: TTYPort,
}

impl Drop for Rig {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn rig() -> Rig {
    let (master, slave_side) = TTYPort::pair().expect("pty pair");
    let name = slave_side.name().expect("pty name");
    let script = Arc::new(Script::default());
    let stop = Arc::new(AtomicBool::new(false));
    let (s, st) = (script.clone(), stop.clone());
    let thread = std::thread::spawn(move || slave(master, s, st));
    let mut cfg = Config::parse(&format!("{name},reset_ms=0,timeout_ms=30,backoff_ms=10"), COUNTS).expect("cfg");
    cfg.backoff_max = Duration::from_millis(50);
    let io = ArduinoIo::start(cfg).expect("driver");
    Rig {
        io,
        script,
        stop,
        thread: Some(thread),
        _slave: slave_side,
    }
}

#[test]
fn a_cycle_reads_and_writes_every_direction() {
    let r = rig();
    r.io.set_outputs(&[true, false], &[200]);
    wait("a cycle", || r.io.status().cycles > 2);
    assert_eq!(r.io.inputs(), (vec![true, false, true], vec![512, 1023]));
    assert_eq!(*r.script.coils.lock().expect("coils"), [true, false]);
    assert_eq!(*r.script.regs.lock().expect("regs"), [200]);
    let s = r.io.status();
    assert!(s.ok && s.errors == 0 && s.opens == 1, "{s:?}");
}

#[test]
fn retries_repair_single_errors() {
    let r = rig();
    wait("the link", || r.io.status().ok);
    // Every other answer damaged: each request succeeds at its second attempt.
    r.script.bad_every.store(2, Ordering::SeqCst);
    let c0 = r.io.status().cycles;
    let mut dropped = false;
    wait("cycles through the errors", || {
        dropped |= !r.io.status().ok;
        r.io.status().cycles > c0 + 10
    });
    let s = r.io.status();
    assert!(!dropped, "S:IOOK dropped on an error a retry repaired");
    assert!(s.errors >= 10, "{s:?}");
    assert!(
        s.last_error.as_deref().is_some_and(|e| e.starts_with("bad CRC")),
        "{s:?}"
    );
}

#[test]
fn an_exception_is_a_pin_map_mismatch() {
    let r = rig();
    r.script.exception.store(2, Ordering::SeqCst);
    wait("errors", || r.io.status().errors >= 3);
    let s = r.io.status();
    assert!(!s.ok);
    assert_eq!(
        s.last_error.as_deref(),
        Some(
            "the board refused reading 3 digital inputs: exception 2 (illegal data address) (does its firmware have the pin map of alba.toml?)"
        )
    );
    r.script.exception.store(0, Ordering::SeqCst);
    wait("recovery", || r.io.status().ok);
}

#[test]
fn a_silent_slave_drops_the_link_and_its_return_restores_it() {
    let r = rig();
    wait("the link", || r.io.status().ok);
    r.script.silent.store(true, Ordering::SeqCst);
    wait("the loss", || !r.io.status().ok);
    let s = r.io.status();
    assert_eq!(s.last_error.as_deref(), Some("no answer within 30 ms"));
    // Inputs keep their last value.
    assert_eq!(r.io.inputs(), (vec![true, false, true], vec![512, 1023]));
    // Reopened after three failed cycles.
    wait("a reopen", || r.io.status().opens >= 2);
    r.io.set_outputs(&[false, true], &[7]);
    r.script.silent.store(false, Ordering::SeqCst);
    wait("recovery", || r.io.status().ok);
    wait("the outputs written again", || {
        let coils = r.script.coils.lock().expect("coils").clone();
        let regs = r.script.regs.lock().expect("regs").clone();
        coils == [false, true] && regs == [7]
    });
}
