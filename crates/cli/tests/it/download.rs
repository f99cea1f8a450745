//! `alba download` (issue 19) to the byte-code interpreter on an emulated
//! Nano (`tools/simavr/board.c`: simavr paced to real time, its UART on a
//! pty): the program arrives, is read back equal, and runs; each of the
//! source's error flags answers a crafted record; ESC in the middle of a
//! download and a program that fails the board's checks leave the old
//! program running; a power cycle (the board stopped and started again with
//! its EEPROM) keeps the program; the lamp test walks the outputs until a reset.

use crate::{alba, repo, scratch};
use alba_io::download::{BoardState, DownloadError, Link};
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
    /// The interpreter of `dir/alba_interp` on an emulated Nano (Motor D12, Lamp D13).
    fn start(dir: &Path) -> (Board, String) {
        Board::start_with(dir, &[])
    }

    fn start_with(dir: &Path, extra: &[&str]) -> (Board, String) {
        Board::run(dir, &dir.join("alba_interp/build/sketch.elf"), "D12,D13", extra)
    }

    /// `elf` on an emulated Nano sampling `pins`, its EEPROM in `dir/eeprom.bin`.
    fn run(dir: &Path, elf: &Path, pins: &str, extra: &[&str]) -> (Board, String) {
        let mut child = Command::new(dir.join("alba-board"))
            .arg(elf)
            .args(extra)
            .args(["-m", "atmega328p", "--tty"])
            .arg(dir.join("link"))
            .args(["--pins", pins, "--eeprom"])
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
        let t0 = b.time();
        b.wait(300 - t0.min(300));
        (b, link)
    }

    fn cmd(&mut self, c: &str) -> String {
        writeln!(self.stdin, "{c}").expect("command");
        let mut a = String::new();
        self.stdout.read_line(&mut a).expect("answer");
        a.trim().to_string()
    }

    /// The board's simulated time, ms.
    fn time(&mut self) -> u64 {
        self.cmd("time").trim_start_matches("time ").parse().expect("time")
    }

    /// Waits until `ms` of the board's time have passed (it runs at most at real
    /// time, slower on a busy machine: the board's time, not the wall clock's).
    fn wait(&mut self, ms: u64) {
        let until = self.time() + ms;
        while self.time() < until {
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Start pressed and released: the motor (D12) seals in; then Stop stops it.
    fn motor_starts(&mut self) -> bool {
        let on = self.motor_on();
        self.cmd("set D3 1");
        self.wait(60);
        on && self.cmd("get") == "pins 0 0"
    }

    /// Start pressed and released: whether the motor (D12) sealed in.
    fn motor_on(&mut self) -> bool {
        self.cmd("set D3 0");
        self.cmd("set D2 1");
        self.wait(60);
        self.cmd("set D2 0");
        self.wait(60);
        self.cmd("get") == "pins 1 0"
    }

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

/// Builds the emulated board program into `dir/alba-board`.
fn build_board(dir: &Path) {
    let st = Command::new("bash")
        .current_dir(repo())
        .args([
            "-c",
            "set -e; source scripts/common.sh; source scripts/avr.sh; build_board \"$1\"",
            "_",
        ])
        .arg(dir.join("alba-board"))
        .status()
        .expect("bash");
    assert!(st.success());
}

/// `alba export bytecode` of `project` for the Nano: its bytes.
fn byte_code(d: &Path, project: &str) -> Vec<u8> {
    let o = alba(
        d,
        &["export", "bytecode", project, "--board", "nano", "-o", "program.bin"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read(d.join("program.bin")).expect("byte code")
}

#[test]
fn download_to_the_interpreter_records_flags_esc_and_a_refused_program() {
    let d = scratch("download");
    let o = alba(&d, &["export", "interpreter", "--board", "nano", "-o", ".", "--build"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    build_board(&d);
    let (mut board, link) = Board::start(&d);
    let project = repo().join("examples/start-stop");
    let project = project.to_string_lossy();
    let good = byte_code(&d, &project);
    let o = alba(
        &d,
        &["download", &project, "--port", &link, "--board", "nano", "--verify"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("downloaded 153 bytes") && err.contains("verified: the board holds the 153 bytes sent"),
        "{err}"
    );
    assert!(board.motor_starts(), "the downloaded program runs");

    // The board says what it is; a download for another board or pin map is refused
    // before anything is written.
    for (args, want) in [
        (
            ["--board", "uno", "--pinmap", "aurora"],
            "the board is an Arduino Nano (its interpreter says so), and the program is for the Arduino Uno: give --board nano",
        ),
        (
            ["--board", "nano", "--pinmap", "s7"],
            "the board's interpreter was built for another pin map",
        ),
    ] {
        let mut a = vec!["download", &project, "--port", &link];
        a.extend(args);
        let o = alba(&d, &a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains("not downloaded to") && err.contains(want),
            "{err}"
        );
    }
    // `--read`: the running program, to a file or as Intel HEX on standard output.
    let o = alba(&d, &["download", "--port", &link, "--read", "back.bin"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("read 153 bytes of the running program slot of the Arduino Nano")
            && err.contains("(running it)")
            && err.contains("CRC good"),
        "{err}"
    );
    assert_eq!(std::fs::read(d.join("back.bin")).expect("read back"), good);
    let o = alba(&d, &["download", "--port", &link, "--read", "-"]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).expect("hex");
    assert_eq!(alba_arduino::ihex::read(&text, 4096).as_deref(), Ok(&good[..]));

    let mut l = Link::open(&link).expect("link");
    let id = l.identify().expect("identity");
    assert_eq!(
        (id.model.as_str(), id.slot, id.state),
        ("nano", 511, BoardState::Running)
    );
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
    // 20: a byte that the EEPROM does not keep (the emulated cell 5 of the other slot,
    // where the next download goes, holds its value whatever is written).
    assert_eq!(board.cmd("stuck 5"), "ok");
    assert_eq!(
        l.raw(":10000000000102030405060708090A0B0C0D0E0F78").expect("answer"),
        "E20"
    );
    drop(l);
    let o = alba(&d, &["download", &project, "--port", &link, "--board", "nano"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && err.contains("record 1 was refused 3 times: the memory did not keep what was written (20)"),
        "{err}"
    );
    assert_eq!(board.cmd("stuck off"), "ok");
    assert!(
        board.motor_starts(),
        "after a write-verify failure the old program runs"
    );

    let mut l = Link::open(&link).expect("link");
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
    // A program whose whole-program CRC is wrong (every record good): refused at the end;
    // the running program stops with its outputs safe (the sealed-in motor drops out) and
    // starts again, and it is still the one in the board.
    assert!(board.motor_on(), "the motor runs");
    let mut corrupt = good.clone();
    corrupt[20] ^= 0x01;
    assert!(matches!(l.download(&corrupt, |_, _| {}), Err(DownloadError::Rejected)));
    board.wait(30);
    assert_eq!(
        board.cmd("get"),
        "pins 0 0",
        "the outputs are safe after a refused program"
    );
    assert!(board.motor_starts(), "the old program runs again");
    assert_eq!(l.read(0, good.len()).expect("read"), good, "the old program is kept");
    // A power cycle: the program is still there and runs.
    drop(l);
    board.power_off();
    let (mut board, _) = Board::start(&d);
    assert!(board.motor_starts(), "after a power cycle the program runs");
    // The lamp test (crates/arduino/tests/lamp.rs has all of it): Start (D2) held at
    // power-up walks the pin map's outputs, D12 then D13 2 s later, echoing each; the
    // program waits for a power-up with D2 released, and then runs.
    board.power_off();
    let (board, link) = Board::start_with(&d, &["--hold", "D2"]);
    let mut l = Link::open(&link).expect("link");
    let mut lines = Vec::new();
    while lines.len() < 3 {
        lines.push(l.answer(Duration::from_secs(10)).expect("lamp test line"));
    }
    assert_eq!(lines, ["lamp test", "lamp D12", "lamp D13"]);
    drop(l);
    board.power_off();
    let (mut board, _) = Board::start(&d);
    assert!(board.motor_starts(), "after the lamp test and a reset the program runs");
}

/// The levels of D13 (the third pin of `get`) sampled every 25 ms of the board's time for `ms`.
fn led_levels(board: &mut Board, ms: u64) -> Vec<char> {
    let mut out = Vec::new();
    for _ in 0..ms / 25 {
        board.wait(25);
        let pins = board.cmd("get");
        out.push(pins.chars().last().unwrap_or('?'));
    }
    out
}

/// The error lamp: a board with no program, or with a damaged one, drives no
/// output and blinks its LED on D13 (the project's pin map leaves D13 free:
/// Lamp on D11, and the analog outputs on D6, D9, D10), and says so; a
/// program that checks stops the blinking.
#[test]
fn a_missing_or_damaged_program_blinks_the_error_led_with_the_outputs_safe() {
    let d = scratch("download-led");
    let project = d.join("start-stop-d11");
    std::fs::create_dir_all(&project).expect("dir");
    for f in ["main.lad", "tags.csv"] {
        std::fs::copy(repo().join("examples/start-stop").join(f), project.join(f)).expect("copy");
    }
    std::fs::write(
        project.join("alba.toml"),
        "name = \"start-stop-d11\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n\n[board]\nmodel = \"nano\"\npinmap = \"aurora\"\ndo = [\"D12\", \"D11\"]\nao = [\"D6\", \"D9\", \"D10\"]\n",
    )
    .expect("write");
    let project = project.to_string_lossy();
    let o = alba(&d, &["export", "interpreter", &project, "-o", ".", "--build"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    build_board(&d);
    let elf = d.join("alba_interp/build/sketch.elf");
    // Motor and Lamp: driven or not (0 an input); D13: the LED's level.
    let pins = "D12:drive,D11:drive,D13";
    let (mut board, link) = Board::run(&d, &elf, pins, &[]);
    let blinks = |levels: &[char]| levels.contains(&'0') && levels.contains(&'1');
    // No program yet (an erased EEPROM).
    let levels = led_levels(&mut board, 1200);
    assert!(blinks(&levels), "the LED blinks with no program: {levels:?}");
    assert!(board.cmd("get").starts_with("pins 0 0 "), "no output driven");
    let id = Link::open(&link).expect("link").identify().expect("identity");
    assert_eq!(id.state, BoardState::NoProgram);
    // A program that checks: the LED goes dark and the program drives its outputs.
    let o = alba(&d, &["download", &project, "--port", &link]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    board.wait(50);
    let levels = led_levels(&mut board, 600);
    assert!(levels.iter().all(|l| *l == '0'), "the LED is off: {levels:?}");
    assert!(
        board.cmd("get").starts_with("pins 1 1 "),
        "Motor and Lamp are outputs, off"
    );
    // A damaged program (a byte of the running slot's body changed while the power
    // was off): at power-up it checks no more; no output driven, the LED blinks.
    board.power_off();
    let mut ee = std::fs::read(d.join("eeprom.bin")).expect("eeprom");
    assert_eq!(ee[1023], 1, "the download went to the second slot");
    assert_eq!(&ee[511..515], b"ALBC");
    ee[511 + 40] ^= 0x20;
    std::fs::write(d.join("eeprom.bin"), &ee).expect("write");
    let (mut board, link) = Board::run(&d, &elf, pins, &[]);
    let levels = led_levels(&mut board, 1200);
    assert!(blinks(&levels), "the LED blinks with a damaged program: {levels:?}");
    assert!(board.cmd("get").starts_with("pins 0 0 "), "no output driven");
    let o = alba(&d, &["download", "--port", &link, "--read", "damaged.bin"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success() && err.contains("no program that checks") && err.contains("CRC-32"),
        "{err}"
    );
}
