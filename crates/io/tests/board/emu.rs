//! The emulated board: `tools/simavr/board.c` running the generated firmware.

use alba_io::firmware::{self, Link, Spec};
use alba_model::board::{Model, PinMap};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::Mutex;

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| repo().join("target"), PathBuf::from)
}

/// The board program alone (`tools/simavr/board.c`), built once.
pub fn board_program() -> PathBuf {
    built(Link::Modbus, false, false).0
}

/// The board program and a firmware ELF.
type Built = (PathBuf, PathBuf);

/// Builds (once per firmware) the board program and the firmware for a
/// Nano with the aurora map; returns (board program, firmware ELF).
fn built(link: Link, active_low: bool, pullup: bool) -> Built {
    type Key = (Link, bool, bool);
    static BUILT: Mutex<Vec<(Key, Built)>> = Mutex::new(Vec::new());
    let mut done = BUILT.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, r)) = done.iter().find(|(k, _)| *k == (link, active_low, pullup)) {
        return r.clone();
    }
    let out = target_dir().join("avr").join("ctl");
    let bin = out.join("alba-board");
    let map = PinMap::preset("aurora").expect("preset");
    let mut spec = Spec::new(Model::Nano, "aurora", map, link);
    spec.active_low = active_low;
    spec.pullup = pullup;
    let name = format!(
        "remote_io_{}{}{}",
        link.name(),
        if active_low { "_low" } else { "" },
        if pullup { "_pullup" } else { "" }
    );
    let sketch = firmware::write(&spec, &out.join(&name)).expect("firmware");
    let build = out.join(format!("build-{name}"));
    let st = Command::new("bash")
        .current_dir(repo())
        .args([
            "-c",
            "set -e; source scripts/common.sh; source scripts/avr.sh; build_board \"$1\"; build_sketch \"$2\" nano \"$3\"",
            "_",
        ])
        .arg(&bin)
        .arg(&sketch)
        .arg(&build)
        .status()
        .expect("bash");
    assert!(st.success(), "building the board or the {name} firmware failed");
    let r = (bin, build.join("sketch.elf"));
    done.push(((link, active_low, pullup), r.clone()));
    r
}

pub struct Emu {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
}

impl Emu {
    /// Starts the board with `tty` as its port's name and `pins` sampled by `get`.
    pub fn start(link: Link, tty: &Path, pins: &str) -> Emu {
        Emu::start_with(link, false, false, tty, pins)
    }

    /// The same, with a firmware whose outputs are active low, or whose
    /// inputs use their pull-up (on = LOW).
    pub fn start_with(link: Link, active_low: bool, pullup: bool, tty: &Path, pins: &str) -> Emu {
        let (bin, elf) = built(link, active_low, pullup);
        Emu::run(&bin, &elf, tty, pins)
    }

    /// Starts the board program `bin` on the firmware `elf` (a Nano).
    pub fn run(bin: &Path, elf: &Path, tty: &Path, pins: &str) -> Emu {
        let mut child = Command::new(bin)
            .arg(elf)
            .arg("--tty")
            .arg(tty)
            .args(["--pins", pins])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("alba-board");
        let stdin = child.stdin.take().expect("stdin");
        let stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let mut e = Emu { child, stdin, stdout };
        let ready = e.line();
        assert!(ready.starts_with("ready /dev/"), "alba-board said `{ready}`");
        e
    }

    fn line(&mut self) -> String {
        let mut s = String::new();
        self.stdout.read_line(&mut s).expect("alba-board's answer");
        assert!(!s.is_empty(), "alba-board ended");
        s.trim_end().to_string()
    }

    pub fn cmd(&mut self, c: &str) -> String {
        writeln!(self.stdin, "{c}").expect("alba-board's stdin");
        self.stdin.flush().expect("flush");
        let r = self.line();
        assert!(!r.starts_with("error"), "`{c}`: {r}");
        r
    }

    pub fn set(&mut self, pin: &str, v: i32) {
        self.cmd(&format!("set {pin} {v}"));
    }

    /// The sampled pins, in the order given at start.
    pub fn get(&mut self) -> Vec<i32> {
        let r = self.cmd("get");
        r.split_whitespace()
            .skip(1)
            .map(|v| v.parse().expect("a pin value"))
            .collect()
    }

    pub fn unplug(&mut self) {
        self.cmd("unplug");
    }

    pub fn plug(&mut self) {
        self.cmd("plug");
    }
}

impl Drop for Emu {
    fn drop(&mut self) {
        let _ = writeln!(self.stdin, "quit");
        let _ = self.stdin.flush();
        for _ in 0..100 {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
