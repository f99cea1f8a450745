//! A man in the middle between the driver and the board: it forwards what
//! each side sends, frame by frame (a frame ends when the line falls
//! silent for two milliseconds), damaged as the current fault says.

use serialport::{SerialPort, TTYPort};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Fault {
    None,
    /// One byte of every frame changed (a CRC error in Modbus, a bad
    /// character in a text line), both ways.
    BadCrc,
    /// The last third of every frame lost, both ways.
    Truncate,
    /// Nothing gets through.
    Silence,
    /// Eight random bytes before every frame, both ways.
    Garbage,
    /// One answer of the board in three damaged.
    BadCrcSometimes,
    /// One line to the board in three with a hex digit of its data changed
    /// into another hex digit (an Intel HEX record whose checksum fails).
    BadRecordSometimes,
}

const FAULTS: [Fault; 7] = [
    Fault::None,
    Fault::BadCrc,
    Fault::Truncate,
    Fault::Silence,
    Fault::Garbage,
    Fault::BadCrcSometimes,
    Fault::BadRecordSometimes,
];

pub struct Proxy {
    fault: Arc<AtomicU8>,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
    link: PathBuf,
    _slave: TTYPort,
}

impl Proxy {
    /// Listens on a new pty named `link` and connects it to the board at `board`.
    pub fn start(board: &Path, link: &Path) -> Proxy {
        let (master, slave) = TTYPort::pair().expect("a pty pair");
        let name = slave.name().expect("the pty's name");
        let _ = std::fs::remove_file(link);
        std::os::unix::fs::symlink(&name, link).expect("symlink");
        let board = serialport::new(board.to_string_lossy(), 115_200)
            .timeout(Duration::from_millis(2))
            .open_native()
            .expect("the board's pty");
        let fault = Arc::new(AtomicU8::new(Fault::None as u8));
        let stop = Arc::new(AtomicBool::new(false));
        let mut threads = Vec::new();
        let pairs: [(TTYPort, TTYPort, bool); 2] = [
            (
                master.try_clone_native().expect("clone"),
                board.try_clone_native().expect("clone"),
                false,
            ),
            (board, master, true),
        ];
        for (from, to, answers) in pairs {
            let (fault, stop) = (fault.clone(), stop.clone());
            threads.push(std::thread::spawn(move || forward(from, to, answers, &fault, &stop)));
        }
        Proxy {
            fault,
            stop,
            threads,
            link: link.to_path_buf(),
            _slave: slave,
        }
    }

    pub fn set(&self, f: Fault) {
        self.fault.store(f as u8, Ordering::SeqCst);
    }
}

impl Drop for Proxy {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
        let _ = std::fs::remove_file(&self.link);
    }
}

fn forward(mut from: TTYPort, mut to: TTYPort, answers: bool, fault: &AtomicU8, stop: &AtomicBool) {
    let _ = from.set_timeout(Duration::from_millis(2));
    let mut frame = Vec::new();
    let mut buf = [0u8; 512];
    let mut count = 0u64;
    let mut rng = 0x2545_F491_4F6C_DD1Du64;
    while !stop.load(Ordering::SeqCst) {
        match from.read(&mut buf) {
            Ok(n) if n > 0 => {
                frame.extend_from_slice(&buf[..n]);
                continue;
            }
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            // The driver side closed its end for a moment: wait for it.
            Err(_) => std::thread::sleep(Duration::from_millis(2)),
        }
        if frame.is_empty() {
            continue;
        }
        count += 1;
        let f = FAULTS[usize::from(fault.load(Ordering::SeqCst)).min(FAULTS.len() - 1)];
        let mut out = std::mem::take(&mut frame);
        match f {
            Fault::None => {}
            Fault::BadCrc => {
                let at = out.len() / 2;
                out[at] ^= 0x40;
            }
            Fault::BadCrcSometimes => {
                if answers && count.is_multiple_of(3) {
                    let last = out.len() - 1;
                    out[last] ^= 0x01;
                }
            }
            Fault::BadRecordSometimes => {
                // `:LLAAAATTDD…`: the first data digit, 0-9 ↔ A-F stays hex.
                if !answers && count.is_multiple_of(3) && out.first() == Some(&b':') && out.len() > 11 {
                    out[9] = if out[9].is_ascii_digit() { b'A' } else { b'0' };
                }
            }
            Fault::Truncate => out.truncate(out.len() * 2 / 3),
            Fault::Silence => out.clear(),
            Fault::Garbage => {
                let mut noise: Vec<u8> = (0..8)
                    .map(|_| {
                        rng ^= rng << 13;
                        rng ^= rng >> 7;
                        rng ^= rng << 17;
                        rng as u8
                    })
                    .collect();
                noise.extend_from_slice(&out);
                out = noise;
            }
        }
        if !out.is_empty() {
            let _ = to.write_all(&out);
            let _ = to.flush();
        }
    }
}
