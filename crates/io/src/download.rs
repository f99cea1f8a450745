//! `alba download` (issue 19): byte code to a board running the interpreter
//! firmware, over its serial port, as Intel HEX records (docs/bytecode.md,
//! "Download"). The board answers each record with a line — `K` written, or
//! `E` and the source's error flag — and the end record with `S` and the
//! 16-bit sum of the data bytes once the new program has checked; a rejected
//! record is sent again (three times at most). ESC first, so a download the
//! board was in the middle of is dropped.

use alba_arduino::ihex;
use std::io::{Read, Write};
use std::time::{Duration, Instant};

/// The serial speed of the download.
pub const BAUD: u32 = 115_200;
/// Attempts per record.
const TRIES: usize = 3;

/// Why a download failed.
#[derive(Debug, thiserror::Error)]
pub enum DownloadError {
    #[error("cannot open {port}: {source}")]
    Open { port: String, source: serialport::Error },
    #[error("the board on {0} does not answer (is it running Alba's byte-code interpreter at 115 200 baud?)")]
    NoAnswer(String),
    #[error("record {record} was refused {TRIES} times: {why}")]
    Refused { record: usize, why: String },
    #[error("the board refused the program: it does not pass the board's checks (flag 40); the old program runs on")]
    Rejected,
    #[error("the board's checksum of the download is {board:04X}, the program's is {host:04X}")]
    Checksum { board: u16, host: u16 },
    #[error("read-back differs from what was sent at byte {0}")]
    Verify(usize),
    #[error("serial port: {0}")]
    Io(#[from] std::io::Error),
    #[error("unexpected answer `{0}`")]
    Answer(String),
}

/// What a flag means (the source's table).
pub fn flag_meaning(flag: u8) -> &'static str {
    match flag {
        0x01 => "a character that is not hexadecimal (01)",
        0x02 => "a record type other than data or end (02)",
        0x04 => "a bad checksum (04)",
        0x08 => "no data (08)",
        0x10 => "data past the end of the program memory (10)",
        0x20 => "the memory did not keep what was written (20)",
        0x40 => "the program does not pass the board's checks (40)",
        _ => "an unknown error flag",
    }
}

/// A serial link to the board, line by line.
pub struct Link {
    port: Box<dyn serialport::SerialPort>,
    name: String,
    /// Records sent again after the board refused them (a line error).
    pub retries: usize,
}

impl Link {
    pub fn open(port: &str) -> Result<Link, DownloadError> {
        let p = serialport::new(port, BAUD)
            .timeout(Duration::from_millis(100))
            .open()
            .map_err(|source| DownloadError::Open {
                port: port.to_string(),
                source,
            })?;
        Ok(Link {
            port: p,
            name: port.to_string(),
            retries: 0,
        })
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), DownloadError> {
        self.port.write_all(bytes)?;
        self.port.flush()?;
        Ok(())
    }

    /// One answer line (without its end), waiting at most `wait`.
    pub fn answer(&mut self, wait: Duration) -> Result<String, DownloadError> {
        let start = Instant::now();
        let mut line = Vec::new();
        let mut b = [0u8; 1];
        while start.elapsed() < wait {
            match self.port.read(&mut b) {
                Ok(1) if b[0] == b'\n' => return Ok(String::from_utf8_lossy(&line).trim().to_string()),
                Ok(1) if line.len() < 4096 => line.push(b[0]),
                Ok(_) => {}
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Err(e) => return Err(e.into()),
            }
        }
        Err(DownloadError::NoAnswer(self.name.clone()))
    }

    /// Sends `bytes` as Intel HEX; `progress(done, total)` after each record.
    /// Returns the board's checksum of the download.
    pub fn download(&mut self, bytes: &[u8], mut progress: impl FnMut(usize, usize)) -> Result<u16, DownloadError> {
        // Drop any half download, and see that a board answers.
        self.send(&[0x1B])?;
        let a = self.answer(Duration::from_secs(3))?;
        if a != "A" {
            return Err(DownloadError::Answer(a));
        }
        let text = ihex::write(bytes);
        let records: Vec<&str> = text.lines().filter(|l| !l.is_empty()).collect();
        let host = bytes.iter().fold(0u16, |s, b| s.wrapping_add(u16::from(*b)));
        for (k, rec) in records.iter().enumerate() {
            let mut why = String::new();
            for attempt in 0..TRIES {
                if attempt > 0 {
                    self.retries += 1;
                }
                self.send(format!("{rec}\r\n").as_bytes())?;
                let a = self.answer(Duration::from_secs(3))?;
                if a == "K" {
                    why.clear();
                    break;
                }
                if let Some(sum) = a.strip_prefix('S') {
                    let board = u16::from_str_radix(sum, 16).map_err(|_| DownloadError::Answer(a.clone()))?;
                    progress(k + 1, records.len());
                    return if board == host {
                        Ok(board)
                    } else {
                        Err(DownloadError::Checksum { board, host })
                    };
                }
                match a.strip_prefix('E').and_then(|f| u8::from_str_radix(f, 16).ok()) {
                    Some(0x40) => return Err(DownloadError::Rejected),
                    Some(f) => why = flag_meaning(f).to_string(),
                    None => return Err(DownloadError::Answer(a)),
                }
            }
            if !why.is_empty() {
                return Err(DownloadError::Refused { record: k + 1, why });
            }
            progress(k + 1, records.len());
        }
        Err(DownloadError::Answer("no answer to the end record".into()))
    }

    /// `n` bytes of the running program from `at`.
    pub fn read(&mut self, at: u16, n: usize) -> Result<Vec<u8>, DownloadError> {
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let chunk = (n - out.len()).min(32);
            let from = at as usize + out.len();
            self.send(format!("R{from:04X}{chunk:02X}\n").as_bytes())?;
            let a = self.answer(Duration::from_secs(3))?;
            let got: Vec<u8> = (0..a.len() / 2)
                .filter_map(|k| u8::from_str_radix(a.get(2 * k..2 * k + 2)?, 16).ok())
                .collect();
            if got.len() != chunk {
                return Err(DownloadError::Answer(a));
            }
            out.extend(got);
        }
        Ok(out)
    }

    /// Sends one raw line (tests: crafted records) and returns the answer.
    pub fn raw(&mut self, line: &str) -> Result<String, DownloadError> {
        self.send(format!("{line}\r\n").as_bytes())?;
        self.answer(Duration::from_secs(3))
    }
}
