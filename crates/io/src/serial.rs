//! The serial line to a board: how to reach it (the options of `--io
//! arduino:` and `board:`), its channel counts, opening the port, and
//! Modbus RTU transactions over it (framed by `alba_modbus_proto::rtu`),
//! which the Modbus master's RTU devices use too.

use crate::error::Error;
use crate::firmware::{BAUD, Link};
use alba_modbus_proto::pdu::{FrameError, Request, Response};
use alba_modbus_proto::rtu;
use alba_model::board::{Dir, PinMap};
use alba_runtime::IoError;
use std::io::{Read, Write};
use std::time::{Duration, Instant};

/// Channels of each direction on the board.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counts {
    pub di: usize,
    pub r#do: usize,
    pub ai: usize,
    pub ao: usize,
}

impl Counts {
    pub fn of(map: &PinMap) -> Counts {
        Counts {
            di: map.pins(Dir::DigitalIn).len(),
            r#do: map.pins(Dir::DigitalOut).len(),
            ai: map.pins(Dir::AnalogIn).len(),
            ao: map.pins(Dir::AnalogOut).len(),
        }
    }
}

/// How to reach the board.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// Serial device (`/dev/ttyUSB0`, `/dev/serial/by-id/…`, `COM3`).
    pub port: String,
    pub link: Link,
    pub baud: u32,
    /// Modbus slave id.
    pub slave: u8,
    /// How long an answer may take (Modbus), or the longest gap between two
    /// lines of the board (AuroraLD).
    pub timeout: Duration,
    /// Further attempts of a failed Modbus transaction.
    pub retries: u32,
    /// Wait after opening the port: opening asserts DTR, which resets an
    /// Uno or Nano into its bootloader for a second or two.
    pub reset_delay: Duration,
    /// First and largest wait between two attempts to reopen the port.
    pub backoff_min: Duration,
    pub backoff_max: Duration,
    /// Failed cycles in a row after which the port is closed and reopened.
    pub reopen_after: u32,
    pub counts: Counts,
}

impl Config {
    pub fn new(port: &str, counts: Counts) -> Config {
        Config {
            port: port.to_string(),
            link: Link::Modbus,
            baud: BAUD,
            slave: 1,
            timeout: Duration::from_millis(100),
            retries: 2,
            reset_delay: Duration::from_millis(2000),
            backoff_min: Duration::from_millis(100),
            backoff_max: Duration::from_millis(3000),
            reopen_after: 3,
            counts,
        }
    }

    /// Parses what follows `arduino:` in `--io`: the port, then options
    /// `link=modbus|aurora`, `slave=N`, `baud=N`, `timeout_ms=N`,
    /// `retries=N`, `reset_ms=N`, `backoff_ms=N`, `backoff_max_ms=N`.
    pub fn parse(spec: &str, counts: Counts) -> Result<Config, Error> {
        let mut parts = spec.split(',');
        let port = parts.next().unwrap_or("").trim();
        if port.is_empty() {
            return Err(Error::Options(
                "--io arduino:<serial port>[,link=modbus|aurora,…]: the port is missing".into(),
            ));
        }
        let mut c = Config::new(port, counts);
        for opt in parts {
            let (k, v) = opt
                .split_once('=')
                .ok_or_else(|| Error::Options(format!("--io arduino: `{opt}` is not option=value")))?;
            let (k, v) = (k.trim(), v.trim());
            let num = || {
                v.parse::<u64>()
                    .map_err(|_| Error::Options(format!("--io arduino: {k}={v}: not a whole number")))
            };
            match k {
                "link" => {
                    c.link = Link::parse(v)
                        .ok_or_else(|| Error::Options(format!("--io arduino: unknown link `{v}` (modbus, aurora)")))?
                }
                "slave" => {
                    c.slave = match num()? {
                        n @ 1..=247 => n as u8,
                        _ => return Err(Error::Options(format!("--io arduino: slave={v}: a slave id is 1-247"))),
                    }
                }
                "baud" => c.baud = num()?.clamp(1, 4_000_000) as u32,
                "timeout_ms" => c.timeout = Duration::from_millis(num()?.max(1)),
                "retries" => c.retries = num()?.min(100) as u32,
                "reset_ms" => c.reset_delay = Duration::from_millis(num()?),
                "backoff_ms" => c.backoff_min = Duration::from_millis(num()?.max(1)),
                "backoff_max_ms" => c.backoff_max = Duration::from_millis(num()?.max(1)),
                _ => {
                    return Err(Error::Options(format!(
                        "--io arduino: unknown option `{k}` (link, slave, baud, timeout_ms, retries, reset_ms, backoff_ms, backoff_max_ms)"
                    )));
                }
            }
        }
        c.backoff_max = c.backoff_max.max(c.backoff_min);
        Ok(c)
    }
}

pub(crate) type Port = Box<dyn serialport::SerialPort>;

pub(crate) fn open(cfg: &Config) -> Result<Port, IoError> {
    serialport::new(&cfg.port, cfg.baud)
        .data_bits(serialport::DataBits::Eight)
        .parity(serialport::Parity::None)
        .stop_bits(serialport::StopBits::One)
        .flow_control(serialport::FlowControl::None)
        // Opening raises DTR (an Uno resets); failures are ignored, as on a pty.
        .dtr_on_open(true)
        .timeout(cfg.timeout)
        .open()
        .map_err(|e| IoError::Link(format!("cannot open {}: {e}", cfg.port)))
}

/// How one RTU exchange failed.
pub(crate) enum RtuError {
    /// The port failed (the message says how): reopen it.
    Port(String),
    /// No complete answer in time.
    NoAnswer(String),
    /// An answer the codec refused, an exception reply among them.
    Answer(FrameError),
}

/// Sends `req` to `slave` and reads its answer: as many bytes as the
/// request says the answer has (no need for the 3.5-character silence).
pub(crate) fn rtu_exchange(
    port: &mut Port,
    slave: u8,
    timeout: Duration,
    req: &Request<'_>,
) -> Result<Response, RtuError> {
    let perr = |e: std::io::Error| RtuError::Port(format!("serial port: {e}"));
    let _ = port.clear(serialport::ClearBuffer::Input);
    port.write_all(&rtu::encode(slave, req)).map_err(perr)?;
    port.flush().map_err(perr)?;
    let deadline = Instant::now() + timeout;
    let mut buf = Vec::with_capacity(rtu::response_len(req));
    loop {
        let want = rtu::expected_len(req, &buf).unwrap_or(2);
        if buf.len() >= want {
            break;
        }
        let now = Instant::now();
        if now >= deadline {
            return Err(RtuError::NoAnswer(if buf.is_empty() {
                format!("no answer within {} ms", timeout.as_millis())
            } else {
                FrameError::Truncated { got: buf.len(), want }.to_string()
            }));
        }
        let _ = port.set_timeout(deadline - now);
        let mut chunk = [0u8; rtu::MAX_FRAME];
        match port.read(&mut chunk[..(want - buf.len()).min(rtu::MAX_FRAME)]) {
            Ok(0) => return Err(RtuError::Port("serial port: end of file".into())),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted) => {}
            Err(e) => return Err(perr(e)),
        }
    }
    rtu::decode_response(slave, req, &buf).map_err(RtuError::Answer)
}

/// One Modbus RTU transaction with the board, with `cfg.retries` further
/// attempts after a bad or missing answer (`on_retry` hears why; the caller
/// counts the last), the line let fall silent between them so the slave
/// sees a new frame. Errors: [`IoError::Link`] (the port failed: reopen
/// it), [`IoError::Timeout`] (no valid answer after the retries),
/// [`IoError::Refused`] (an exception reply: not retried).
pub(crate) fn transact(
    port: &mut Port,
    cfg: &Config,
    req: &Request<'_>,
    mut on_retry: impl FnMut(&IoError),
) -> Result<Response, IoError> {
    let mut attempt = 0;
    loop {
        match exchange(port, cfg, req) {
            Ok(resp) => return Ok(resp),
            Err(e @ IoError::Timeout(_)) => {
                if attempt >= cfg.retries {
                    return Err(e);
                }
                on_retry(&e);
                attempt += 1;
                quiet(port, Duration::from_millis(5))?;
            }
            Err(e) => return Err(e),
        }
    }
}

/// Discards what arrives until `gap` passes without a byte (bounded).
pub(crate) fn quiet(port: &mut Port, gap: Duration) -> Result<(), IoError> {
    let _ = port.set_timeout(gap);
    let mut buf = [0u8; 64];
    let until = Instant::now() + Duration::from_millis(200);
    while Instant::now() < until {
        match port.read(&mut buf) {
            Ok(0) => return Err(IoError::Link("serial port: end of file".into())),
            Ok(_) => continue,
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => break,
            Err(e) => return Err(IoError::Link(format!("serial port: {e}"))),
        }
    }
    Ok(())
}

fn exchange(port: &mut Port, cfg: &Config, req: &Request<'_>) -> Result<Response, IoError> {
    rtu_exchange(port, cfg.slave, cfg.timeout, req).map_err(|e| match e {
        RtuError::Port(m) => IoError::Link(m),
        RtuError::NoAnswer(m) => IoError::Timeout(m),
        RtuError::Answer(e @ FrameError::Exception(_)) => IoError::Refused(format!(
            "the board refused {}: {e} (does its firmware have the pin map of alba.toml?)",
            describe(req)
        )),
        RtuError::Answer(e) => IoError::Timeout(e.to_string()),
    })
}

fn describe(req: &Request<'_>) -> String {
    let n = req.count();
    match req {
        Request::ReadDiscreteInputs { .. } => format!("reading {n} digital inputs"),
        Request::ReadInputRegisters { .. } => format!("reading {n} analog inputs"),
        Request::WriteMultipleCoils { .. } => format!("writing {n} digital outputs"),
        Request::WriteMultipleRegisters { .. } => format!("writing {n} analog outputs"),
        other => format!("function {}", other.function()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The channels of the `aurora` map on a Nano.
    pub(crate) const C: Counts = Counts {
        di: 6,
        r#do: 6,
        ai: 4,
        ao: 4,
    };

    #[test]
    fn io_options() {
        let c = Config::parse("/dev/ttyUSB0", C).expect("config");
        assert_eq!(
            (c.port.as_str(), c.link, c.slave, c.baud),
            ("/dev/ttyUSB0", Link::Modbus, 1, 115_200)
        );
        assert_eq!(c.reset_delay, Duration::from_millis(2000));
        let c = Config::parse("COM3,link=aurora,reset_ms=0,timeout_ms=50,retries=5,slave=7", C).expect("config");
        assert_eq!((c.link, c.slave, c.retries), (Link::Aurora, 7, 5));
        assert_eq!((c.reset_delay, c.timeout), (Duration::ZERO, Duration::from_millis(50)));
        assert!(
            Config::parse("", C)
                .unwrap_err()
                .to_string()
                .contains("the port is missing")
        );
        assert!(
            Config::parse("/dev/x,link=can", C)
                .unwrap_err()
                .to_string()
                .contains("unknown link `can`")
        );
        assert!(
            Config::parse("/dev/x,slave=0", C)
                .unwrap_err()
                .to_string()
                .contains("1-247")
        );
        assert!(
            Config::parse("/dev/x,speed=9600", C)
                .unwrap_err()
                .to_string()
                .contains("unknown option `speed`")
        );
        assert!(
            Config::parse("/dev/x,retries", C)
                .unwrap_err()
                .to_string()
                .contains("not option=value")
        );
        assert!(
            Config::parse("/dev/x,retries=-1", C)
                .unwrap_err()
                .to_string()
                .contains("not a whole number")
        );
    }
}
