//! `alba download` (issue 19) to the byte-code interpreter on an emulated
//! Nano (`tools/simavr/board.c`: simavr paced to real time, its UART on a
//! pty): the program arrives, is read back equal, and runs; each of the
//! source's error flags answers a crafted record; ESC in the middle of a
//! download and a program that fails the board's checks leave the old
//! program running; a power cycle (the board stopped and started again with
//! its EEPROM) keeps the program; the lamp test walks the outputs.

use crate::{alba, repo, scratch};
use alba_io::download::Link;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::time::Duration;

struct Board {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
}

impl Board {
    fn start(dir: &Path) -> (Board, String) {
        Board::start_with(dir, &[])
    }

    fn start_with(dir: &Path, extra: &[&str]) -> (Board, String) {
        let elf = dir.join("alba_interp/build/sketch.elf");
        let mut child = Command::new(dir.join("alba-board"))
            .arg(&elf)
            .args(extra)
            .args(["-m", "atmega328p", "--tty"])
            .arg(dir.join("link"))
            .args(["--pins", "D12,D13", "--eeprom"])
            .arg(dir.join("eeprom.bin"))
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("alba-board");
        let stdin = child.stdin.take().expect("stdin");
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let mut ready = String::new();
        stdout.read_line(&mut ready).expect("ready");
        assert!(ready.starts_with("ready "), "{ready}");
        let link = dir.join("link").to_string_lossy().into_owned();
        let mut b = Board { child, stdin, stdout };
        // Past the firmware's setup (which reads the lamp-test input) before a test presses anything.
        while b.cmd("time").trim_start_matches("time ").parse::<u64>().unwrap_or(0) < 300 {
            std::thread::sleep(Duration::from_millis(20));
        }
        (b, link)
    }

    fn cmd(&mut self, c: &str) -> String {
        writeln!(self.stdin, "{c}").expect("command");
        let mut a = String::new();
        self.stdout.read_line(&mut a).expect("answer");
        a.trim().to_string()
    }

    /// Start pressed and released: the motor (D12) seals in.
    fn motor_starts(&mut self) -> bool {
        self.cmd("set D3 0");
        self.cmd("set D2 1");
        std::thread::sleep(Duration::from_millis(150));
        self.cmd("set D2 0");
        std::thread::sleep(Duration::from_millis(150));
        let on = self.cmd("get") == "pins 1 0";
        self.cmd("set D3 1");
        std::thread::sleep(Duration::from_millis(150));
        on && self.cmd("get") == "pins 0 0"
    }
}

impl Board {
    /// Power off: the board program ends and saves the EEPROM.
    fn power_off(mut self) {
        let _ = writeln!(self.stdin, "quit");
        let _ = self.child.wait();
    }
}

impl Drop for Board {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn download_to_the_interpreter_records_flags_esc_and_a_refused_program() {
    let d = scratch("download");
    let o = alba(&d, &["export", "interpreter", "--board", "nano", "-o", ".", "--build"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let st = Command::new("bash")
        .current_dir(repo())
        .args([
            "-c",
            "set -e; source scripts/common.sh; source scripts/avr.sh; build_board \"$1\"",
            "_",
        ])
        .arg(d.join("alba-board"))
        .status()
        .expect("bash");
    assert!(st.success());
    let (mut board, link) = Board::start(&d);
    let project = repo().join("examples/start-stop");
    let o = alba(
        &d,
        &[
            "download",
            &project.to_string_lossy(),
            "--port",
            &link,
            "--board",
            "nano",
            "--verify",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("downloaded 152 bytes") && err.contains("verified: the board holds the 152 bytes sent"),
        "{err}"
    );
    assert!(board.motor_starts(), "the downloaded program runs");

    let mut l = Link::open(&link).expect("link");
    // Each of the source's flags from a crafted record (none of them writes anything).
    for (rec, want) in [
        (":10000000000102030405060708090A0B0C0D0E0G78", "E01"),
        (":0100000200FD", "E02"),
        (":10000000000102030405060708090A0B0C0D0E0F79", "E04"),
        (":0000000000", "E08"),
        (":0102000000FD", "E10"),
    ] {
        assert_eq!(l.raw(rec).expect("answer"), want, "{rec}");
    }
    // ESC in the middle of a download: dropped; the old program runs on.
    let tank = alba_arduino::ihex::write(&[0x41; 64]);
    for rec in tank.lines().take(2) {
        assert_eq!(l.raw(rec).expect("answer"), "K");
    }
    assert_eq!(l.raw("\u{1b}").expect("answer"), "A");
    assert!(board.motor_starts(), "after ESC the old program runs");
    // A whole download of something that is not a program: refused at the end (flag 40).
    let junk = alba_arduino::ihex::write(&[0x41; 40]);
    let mut last = String::new();
    for rec in junk.lines() {
        last = l.raw(rec).expect("answer");
    }
    assert_eq!(last, "E40");
    assert!(board.motor_starts(), "after a refused program the old one runs");
    // Read-back still gives start-stop's byte code.
    let back = l.read(0, 4).expect("read");
    assert_eq!(back, b"ALBC");
    // A power cycle: the program is still there and runs.
    drop(l);
    board.power_off();
    let (mut board, _) = Board::start(&d);
    assert!(board.motor_starts(), "after a power cycle the program runs");
    // The lamp test: Start (D2) held at power-up walks the outputs, D12 then D13,
    // echoing each; released, the program starts.
    board.power_off();
    let (mut board, link) = Board::start_with(&d, &["--hold", "D2"]);
    let mut l = Link::open(&link).expect("link");
    let mut lines = Vec::new();
    while lines.len() < 3 {
        lines.push(l.answer(Duration::from_secs(5)).expect("lamp test line"));
    }
    assert_eq!(lines, ["lamp test", "lamp D12", "lamp D13"]);
    board.cmd("set D2 0");
    assert_eq!(l.answer(Duration::from_secs(5)).expect("end").trim(), "lamp test done");
    assert!(board.motor_starts(), "after the lamp test the program runs");
}
