//! `alba download` (issue 19): byte code to a board running the interpreter
//! firmware, over its serial port, as Intel HEX records (docs/bytecode.md,
//! "Download"). The board answers each record with a line — `K` written, or
//! `E` and the source's error flag — and the end record with `S` and the
//! 16-bit sum of the data bytes once the new program has checked; a rejected
//! record is sent again (three times at most). ESC first, so a download the
//! board was in the middle of is dropped.

use alba_arduino::sketch::Target;
use alba_arduino::{bytecode, ihex};
use alba_model::board::Model;
use std::io::{Read, Write};
use std::time::{Duration, Instant};

/// The serial speed of the download.
pub const BAUD: u32 = 115_200;
/// Attempts per record.
const TRIES: usize = 3;

/// Why a download failed.
#[derive(Debug, thiserror::Error)]
pub enum DownloadError {
    #[error("cannot open {port}: {source}{}", open_hint(source))]
    Open { port: String, source: serialport::Error },
    #[error("the board on {0} does not answer (is it running Alba's byte-code interpreter at 115 200 baud?)")]
    NoAnswer(String),
    #[error(
        "the board on {0} does not say what it is (its interpreter is older than this Alba: flash it again, alba export interpreter --upload)"
    )]
    NoIdentity(String),
    #[error("record {record} was refused {TRIES} times: {why}")]
    Refused { record: usize, why: String },
    #[error("the board refused the program: it does not pass the board's checks (flag 40); the old program runs on")]
    Rejected,
    #[error("the board's checksum of the download is {board:04X}, the program's is {host:04X}")]
    Checksum { board: u16, host: u16 },
    #[error("read-back differs from what was sent at byte {0}")]
    Verify(usize),
    #[error("cancelled after record {done} of {total} (the board dropped the records it had)")]
    Cancelled { done: usize, total: usize },
    /// The link went in the middle of a download (a cable pulled, the board
    /// reset or gone): the board drops a half download at its next `ESC` or
    /// reset and keeps the program it had.
    #[error("the link to the board was lost at record {record} of {total} (cable pulled or board reset?): {why}")]
    Lost { record: usize, total: usize, why: String },
    #[error("serial port: {0}")]
    Io(#[from] std::io::Error),
    #[error("unexpected answer `{0}`")]
    Answer(String),
}

/// What to do about a port that does not open: busy, gone, not allowed.
fn open_hint(e: &serialport::Error) -> &'static str {
    use serialport::ErrorKind as K;
    match e.kind() {
        // EBUSY: another program holds the port (TIOCEXCL).
        K::NoDevice => {
            " (another program has the port open — the Arduino IDE's serial monitor, a terminal, `alba run --io` — close it)"
        }
        K::Io(std::io::ErrorKind::PermissionDenied) => {
            " (add the user that runs alba to the `dialout` group, then log in again)"
        }
        K::Io(std::io::ErrorKind::NotFound) => " (no such port: is the board plugged in? list the ports again)",
        _ => "",
    }
}

/// What a board says of itself (the `I` line, docs/bytecode.md "Download").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Identity {
    /// The byte-code format its interpreter reads.
    pub version: u8,
    /// Its board id (board, pin map, polarity: `alba_arduino::bytecode::board_id`).
    pub board_id: u16,
    /// Bytes of a program slot.
    pub slot: u16,
    pub state: BoardState,
    /// `uno`, `nano` or `mega`.
    pub model: String,
}

/// What a board is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoardState {
    /// A program checks and runs.
    Running,
    /// No program that checks (none yet, or a damaged one): outputs safe, error LED.
    NoProgram,
    /// The program stopped on a major fault (outputs safe).
    Faulted,
}

impl Identity {
    /// `I02268D01FFRnano` → the identity.
    pub fn parse(line: &str) -> Option<Identity> {
        let rest = line.strip_prefix('I')?;
        let hex = |from: usize, to: usize| u16::from_str_radix(rest.get(from..to)?, 16).ok();
        let state = match rest.get(10..11)? {
            "R" => BoardState::Running,
            "N" => BoardState::NoProgram,
            "F" => BoardState::Faulted,
            _ => return None,
        };
        Some(Identity {
            version: u8::try_from(hex(0, 2)?).ok()?,
            board_id: hex(2, 6)?,
            slot: hex(6, 10)?,
            state,
            model: rest.get(11..)?.to_string(),
        })
    }
}

impl Identity {
    /// The board as users name it (`Arduino Nano`).
    pub fn title(&self) -> String {
        Model::parse(&self.model).map_or_else(|| self.model.clone(), |m| m.title().to_string())
    }

    /// Why byte code of `len` bytes for `t` must not go to this board, if it
    /// must not: another board, another byte-code format, another pin map or
    /// output polarity, a program larger than the board's slot.
    pub fn refuses(&self, t: &Target, len: usize) -> Option<String> {
        if self.model != t.model.name() {
            return Some(format!(
                "the board is an {} (its interpreter says so), and the program is for the {}: give --board {}, or change [board] in alba.toml",
                self.title(),
                t.model.title(),
                self.model
            ));
        }
        if self.version != bytecode::VERSION {
            return Some(format!(
                "the board's interpreter reads byte code format {}, this Alba writes format {}: flash the interpreter again (alba export interpreter <project> --upload PORT)",
                self.version,
                bytecode::VERSION
            ));
        }
        let want = bytecode::board_id(t);
        if self.board_id != want {
            return Some(format!(
                "the board's interpreter was built for another pin map or output polarity (board id {:04x}; this program's is {want:04x}): give the --pinmap it was built with, or flash the interpreter for this project (alba export interpreter <project> --upload PORT)",
                self.board_id
            ));
        }
        if len > usize::from(self.slot) {
            return Some(format!(
                "the program is {len} bytes and the board's program slot holds {}",
                self.slot
            ));
        }
        None
    }
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
        self.download_until(bytes, |done, total| {
            progress(done, total);
            true
        })
    }

    /// As [`Link::download`]; `go(done, total)` after each record: `false`
    /// drops the download (ESC, the board's own way) and the board runs its
    /// program on ([`DownloadError::Cancelled`]).
    pub fn download_until(
        &mut self,
        bytes: &[u8],
        mut go: impl FnMut(usize, usize) -> bool,
    ) -> Result<u16, DownloadError> {
        // Drop any half download, and see that a board answers.
        self.escape()?;
        let text = ihex::write(bytes);
        let records: Vec<&str> = text.lines().filter(|l| !l.is_empty()).collect();
        let host = bytes.iter().fold(0u16, |s, b| s.wrapping_add(u16::from(*b)));
        for (k, rec) in records.iter().enumerate() {
            let mut why = String::new();
            for attempt in 0..TRIES {
                if attempt > 0 {
                    self.retries += 1;
                }
                let lost = |e: DownloadError| match e {
                    DownloadError::Io(_) | DownloadError::NoAnswer(_) => DownloadError::Lost {
                        record: k + 1,
                        total: records.len(),
                        why: e.to_string(),
                    },
                    e => e,
                };
                self.send(format!("{rec}\r\n").as_bytes()).map_err(lost)?;
                let a = self.answer(Duration::from_secs(3)).map_err(lost)?;
                if a == "K" {
                    why.clear();
                    break;
                }
                if let Some(sum) = a.strip_prefix('S') {
                    let board = u16::from_str_radix(sum, 16).map_err(|_| DownloadError::Answer(a.clone()))?;
                    // The new program runs: too late to drop it.
                    let _ = go(k + 1, records.len());
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
            if !go(k + 1, records.len()) {
                self.send(&[0x1B])?;
                let a = self.answer(Duration::from_secs(3))?;
                if a != "A" {
                    return Err(DownloadError::Answer(a));
                }
                return Err(DownloadError::Cancelled {
                    done: k + 1,
                    total: records.len(),
                });
            }
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

    /// ESC: the board drops a half download and answers `A`. Answers a
    /// broken-off exchange left in the line before it (a record's late `K`
    /// after a cable was pulled and plugged again) are skipped.
    fn escape(&mut self) -> Result<(), DownloadError> {
        self.send(&[0x1B])?;
        let until = Instant::now() + Duration::from_secs(3);
        for _ in 0..8 {
            let a = self.answer(until.saturating_duration_since(Instant::now()))?;
            if a == "A" {
                return Ok(());
            }
            if Instant::now() >= until {
                return Err(DownloadError::Answer(a));
            }
        }
        Err(DownloadError::Answer("no `A` to ESC among 8 answers".into()))
    }

    /// Asks the board who it is (after an ESC, so a half download is dropped first).
    pub fn identify(&mut self) -> Result<Identity, DownloadError> {
        self.escape()?;
        self.send(b"I\n")?;
        let a = self
            .answer(Duration::from_secs(3))
            .map_err(|_| DownloadError::NoIdentity(self.name.clone()))?;
        Identity::parse(&a).ok_or(DownloadError::Answer(a))
    }

    /// Sends one raw line (tests: crafted records) and returns the answer.
    pub fn raw(&mut self, line: &str) -> Result<String, DownloadError> {
        self.send(format!("{line}\r\n").as_bytes())?;
        self.answer(Duration::from_secs(3))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_model::board::PinMap;

    fn nano() -> Target {
        Target {
            model: Model::Nano,
            map: PinMap::preset("aurora").expect("aurora"),
            active_low: false,
            scan_ms: 10,
            monitor: true,
            power_up_on: Vec::new(),
        }
    }

    #[test]
    fn a_port_that_does_not_open_says_what_to_do() {
        use serialport::{Error, ErrorKind};
        let open = |kind| DownloadError::Open {
            port: "/dev/ttyUSB0".into(),
            source: Error::new(kind, "x"),
        };
        let busy = open(ErrorKind::NoDevice).to_string();
        assert!(
            busy.starts_with("cannot open /dev/ttyUSB0: x (another program has the port open"),
            "{busy}"
        );
        let denied = open(ErrorKind::Io(std::io::ErrorKind::PermissionDenied)).to_string();
        assert!(denied.contains("`dialout` group"), "{denied}");
        let gone = open(ErrorKind::Io(std::io::ErrorKind::NotFound)).to_string();
        assert!(gone.contains("is the board plugged in?"), "{gone}");
        assert_eq!(open(ErrorKind::Unknown).to_string(), "cannot open /dev/ttyUSB0: x");
        // A real one: a path that is not there.
        let Err(e) = Link::open("/nonexistent/tty") else {
            panic!("opened a port that is not there");
        };
        assert!(e.to_string().contains("is the board plugged in?"), "{e}");
    }

    #[test]
    fn an_identity_line_reads_and_refuses_another_board() {
        let t = nano();
        let id = format!("I{:02X}{:04X}01FFRnano", bytecode::VERSION, bytecode::board_id(&t));
        let me = Identity::parse(&id).expect("parses");
        assert_eq!(me.state, BoardState::Running);
        assert_eq!((me.slot, me.model.as_str()), (511, "nano"));
        assert_eq!(me.refuses(&t, 152), None);
        assert!(me.refuses(&t, 600).expect("too big").contains("600 bytes"));
        let mut mega = t.clone();
        mega.model = Model::Mega;
        let why = me.refuses(&mega, 152).expect("another board");
        assert!(
            why.contains("is an Arduino Nano") && why.contains("--board nano"),
            "{why}"
        );
        let mut low = t.clone();
        low.active_low = true;
        assert!(
            me.refuses(&low, 152)
                .expect("another polarity")
                .contains("another pin map")
        );
        let old = Identity {
            version: 1,
            ..me.clone()
        };
        assert!(old.refuses(&t, 152).expect("old").contains("format 1"));
        for bad in ["", "I", "I02268D01FFXnano", "IZZ268D01FFRnano", "K"] {
            assert_eq!(Identity::parse(bad), None, "{bad}");
        }
        assert_eq!(
            Identity::parse("I02268D01FFNuno").map(|i| i.state),
            Some(BoardState::NoProgram)
        );
    }
}
