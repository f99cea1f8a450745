//! The firmware as a Modbus RTU slave, on its own: driven by a third-party
//! master (mbpoll, on libmodbus) for every function code it serves, and by
//! hand-made frames for what a well-behaved master never sends.

use crate::emu::Emu;
use crate::{PINS, serial, tmp, wait};
use alba_io::firmware::Link;
use alba_modbus_proto::pdu::{Request, Response};
use alba_modbus_proto::rtu::{self, crc16, with_crc};
use std::io::{Read, Write};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// mbpoll's output (stdout and stderr) for one request.
fn mbpoll(tty: &Path, args: &str) -> String {
    let out = Command::new("mbpoll")
        .args([
            "-m", "rtu", "-b", "115200", "-P", "none", "-a", "1", "-0", "-1", "-o", "0.5",
        ])
        .args(args.split_whitespace())
        .arg(tty)
        .output()
        .expect("mbpoll (Debian package mbpoll; need_avr installs it)");
    let mut s = String::from_utf8_lossy(&out.stdout).into_owned();
    s.push_str(&String::from_utf8_lossy(&out.stderr));
    s
}

fn mbpoll_write(tty: &Path, args: &str, values: &str) -> String {
    let out = Command::new("mbpoll")
        .args([
            "-m", "rtu", "-b", "115200", "-P", "none", "-a", "1", "-0", "-1", "-o", "0.5",
        ])
        .args(args.split_whitespace())
        .arg(tty)
        .args(values.split_whitespace())
        .output()
        .expect("mbpoll");
    let mut s = String::from_utf8_lossy(&out.stdout).into_owned();
    s.push_str(&String::from_utf8_lossy(&out.stderr));
    assert!(s.contains("Written"), "mbpoll {args} {values}: {s}");
    s
}

/// The values mbpoll printed, `[n]: v` lines.
fn values(out: &str) -> Vec<i64> {
    out.lines()
        .filter_map(|l| l.trim().strip_prefix('[')?.split_once("]:"))
        .map(|(_, v)| v.trim().parse().expect("a value"))
        .collect()
}

#[test]
#[ignore = "needs avr-gcc, simavr and mbpoll: run by test.sh's Arduino step"]
fn a_third_party_master_reads_and_writes_every_table() {
    let _g = serial();
    let dir = tmp("mbpoll");
    let tty = dir.join("board.tty");
    let mut board = Emu::start(Link::Modbus, &tty, PINS);
    for (pin, v) in [("D2", 1), ("D5", 1), ("D8", 1), ("A4", 1000), ("A7", 99)] {
        board.set(pin, v);
    }
    // FC 2 and 4.
    assert_eq!(values(&mbpoll(&tty, "-t 1 -r 0 -c 6")), [1, 0, 0, 1, 0, 1]);
    assert_eq!(values(&mbpoll(&tty, "-t 3 -r 0 -c 4")), [1000, 0, 0, 99]);
    assert_eq!(values(&mbpoll(&tty, "-t 3 -r 3 -c 1")), [99]);
    // FC 15 and 16, then FC 1 and 3 read them back (300 clamps to 255). The
    // board's watchdog turns them off 500 ms after the last request, so
    // each check follows its write at once.
    mbpoll_write(&tty, "-t 0 -r 0", "1 0 1 1 0 1");
    assert_eq!(&board.get()[..6], [1, 0, 1, 1, 0, 1]);
    assert_eq!(values(&mbpoll(&tty, "-t 0 -r 0 -c 6")), [1, 0, 1, 1, 0, 1]);
    mbpoll_write(&tty, "-t 4 -r 0", "300 5 6 7");
    assert_eq!(&board.get()[6..], [255, 5, 6, 7]);
    assert_eq!(values(&mbpoll(&tty, "-t 4 -r 0 -c 4")), [255, 5, 6, 7]);
    // FC 5 and 6 (one value).
    mbpoll_write(&tty, "-t 0 -r 2", "0");
    assert_eq!(board.get()[2], 0);
    mbpoll_write(&tty, "-t 4 -r 1", "77");
    assert_eq!(board.get()[7], 77);
    // Exceptions: past the last channel (2), an unsupported function (1: FC 17).
    assert!(mbpoll(&tty, "-t 3 -r 0 -c 5").contains("Illegal data address"));
    assert!(mbpoll(&tty, "-t 0 -r 6 -c 1").contains("Illegal data address"));
    assert!(mbpoll(&tty, "-t 1 -r 2 -c 5").contains("Illegal data address"));
    assert!(mbpoll(&tty, "-u").contains("Illegal function"));
    // Another slave id: no answer.
    let other = Command::new("mbpoll")
        .args([
            "-m", "rtu", "-b", "115200", "-P", "none", "-a", "2", "-0", "-1", "-o", "0.2", "-t", "1",
        ])
        .arg(&tty)
        .output()
        .expect("mbpoll");
    assert!(
        String::from_utf8_lossy(&other.stderr).contains("timed out"),
        "{other:?}"
    );
    // Then the watchdog: no request for 500 ms, every output off.
    wait("the watchdog", 5, || board.get().iter().all(|v| *v == 0));
}

/// Sends `frame` and returns what came back: read until `want` bytes have come
/// (at most 3 s), then 60 ms more for anything unexpected. A frame that must
/// not be answered (`want` 0) is given 400 ms: on a loaded machine simavr runs
/// slower than real time, and the next frame must not reach the board before
/// this one has been read whole, or the board takes both for one frame.
fn ask(port: &mut Box<dyn serialport::SerialPort>, frame: &[u8], want: usize) -> Vec<u8> {
    let _ = port.clear(serialport::ClearBuffer::All);
    port.write_all(frame).expect("write");
    let mut got = Vec::new();
    let wait = if want == 0 { 400 } else { 3000 };
    let mut end = Instant::now() + Duration::from_millis(wait);
    let mut complete = false;
    let mut buf = [0u8; 300];
    while Instant::now() < end {
        if let Ok(n) = port.read(&mut buf) {
            got.extend_from_slice(&buf[..n]);
        }
        if want > 0 && !complete && got.len() >= want {
            complete = true;
            end = Instant::now() + Duration::from_millis(60);
        }
    }
    got
}

#[test]
#[ignore = "needs avr-gcc and simavr: run by test.sh's Arduino step"]
fn frames_a_master_should_not_send() {
    let _g = serial();
    let dir = tmp("raw");
    let tty = dir.join("board.tty");
    let mut board = Emu::start(Link::Modbus, &tty, PINS);
    let mut port = serialport::new(tty.to_string_lossy(), 115_200)
        .timeout(Duration::from_millis(5))
        .open()
        .expect("the board's pty");
    let exc = |fc: u8, code: u8| with_crc(vec![1, fc | 0x80, code]);
    // A bad CRC: ignored, no answer.
    let mut bad = rtu::encode(1, &Request::WriteSingleCoil { addr: 0, value: true });
    bad[6] ^= 1;
    assert_eq!(ask(&mut port, &bad, 0), Vec::<u8>::new());
    assert_eq!(board.get()[0], 0);
    // FC 5 with a value that is neither FF00 nor 0000: exception 3.
    assert_eq!(ask(&mut port, &with_crc(vec![1, 5, 0, 0, 0x12, 0x34]), 5), exc(5, 3));
    // Quantity 0: exception 3; too many: 3; a length that does not match the byte count: 3.
    assert_eq!(ask(&mut port, &with_crc(vec![1, 2, 0, 0, 0, 0]), 5), exc(2, 3));
    assert_eq!(ask(&mut port, &with_crc(vec![1, 4, 0, 0, 0, 126]), 5), exc(4, 3));
    assert_eq!(
        ask(&mut port, &with_crc(vec![1, 15, 0, 0, 0, 6, 2, 0x3F]), 5),
        exc(15, 3)
    );
    assert_eq!(
        ask(&mut port, &with_crc(vec![1, 16, 0, 0, 0, 2, 4, 0, 1]), 5),
        exc(16, 3)
    );
    // A read of 3 bytes too short to be a request: exception 3 rather than a guess.
    assert_eq!(ask(&mut port, &with_crc(vec![1, 3, 0, 0, 0]), 5), exc(3, 3));
    // An unknown function: exception 1.
    assert_eq!(ask(&mut port, &with_crc(vec![1, 43, 14, 1, 0]), 5), exc(43, 1));
    // A broadcast write is carried out without an answer.
    let all_on = rtu::encode(0, &Request::write_coils(0, &[true; 6]));
    assert_eq!(ask(&mut port, &all_on, 0), Vec::<u8>::new());
    assert_eq!(&board.get()[..6], [1; 6]);
    // Two requests without the 3.5-character silence between them: each is
    // answered as soon as it is complete and its CRC checks.
    let read = Request::ReadCoils { start: 0, count: 6 };
    let mut two = rtu::encode(1, &read);
    two.extend(rtu::encode(1, &read));
    let answer = rtu::encode_response(1, &read, &[true; 6], &[]);
    assert_eq!(
        ask(&mut port, &two, 2 * answer.len()),
        [answer.clone(), answer.clone()].concat()
    );
    // A request with garbage before it is one frame with a bad CRC: no answer.
    let mut noisy = vec![0x55, 0x01];
    noisy.extend(rtu::encode(1, &read));
    assert_eq!(ask(&mut port, &noisy, 0), Vec::<u8>::new());
    // A frame longer than 256 bytes: dropped whole.
    let mut long = vec![1u8, 16, 0, 0, 0, 4, 8];
    long.resize(300, 0);
    let c = crc16(&long);
    long.extend_from_slice(&c.to_le_bytes());
    assert_eq!(ask(&mut port, &long, 0), Vec::<u8>::new());
    // And the board still answers good requests. The frames above without an
    // answer took longer than the 500 ms watchdog, so the coils may be off
    // again: write them before reading them back.
    let on = Request::write_coils(0, &[true; 6]);
    let echo = rtu::encode_response(1, &on, &[], &[]);
    assert_eq!(ask(&mut port, &rtu::encode(1, &on), echo.len()), echo);
    let got = ask(&mut port, &rtu::encode(1, &read), answer.len());
    assert_eq!(rtu::decode_response(1, &read, &got), Ok(Response::Bits(vec![true; 6])));
}
