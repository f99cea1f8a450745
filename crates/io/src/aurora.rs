//! The AuroraLD text link (SPEC §7.2), host side: the board sends
//! `d0,…,a0,…,<id>` CR LF every 20 ms; each valid line is answered with
//! the outputs `q0,…,ao0,…` CR LF. A line is checked (field count, 0/1
//! levels, readings 0-1023, board id 5518) before it is believed.

use crate::firmware::{AURORA_ID, AURORA_PERIOD_MS};
use crate::link::Outputs;
use crate::serial::{Config, Counts};
use alba_runtime::IoError;
use std::io::{Read, Write};
use std::time::{Duration, Instant};

/// Longest line accepted.
const MAX_LINE: usize = 200;

/// Bytes received and not yet a line.
#[derive(Default)]
pub struct Reader {
    buf: Vec<u8>,
}

/// A board line that is not what the link expects (the message says why).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct BadLine(pub String);

/// Parses a board line (without its line end).
pub fn parse_line(line: &str, c: Counts) -> Result<(Vec<bool>, Vec<u16>), BadLine> {
    line_text(line, c).map_err(BadLine)
}

fn line_text(line: &str, c: Counts) -> Result<(Vec<bool>, Vec<u16>), String> {
    let fields: Vec<&str> = line.split(',').map(str::trim).collect();
    let want = c.di + c.ai + 1;
    if fields.len() != want {
        return Err(format!(
            "board line `{}` has {} fields, expected {want} ({} DI, {} AI, id)",
            line.escape_debug(),
            fields.len(),
            c.di,
            c.ai
        ));
    }
    let num = |s: &str| {
        s.parse::<u32>()
            .map_err(|_| format!("board line: `{}` is not a number", s.escape_debug()))
    };
    let mut di = Vec::with_capacity(c.di);
    for f in &fields[..c.di] {
        match num(f)? {
            0 => di.push(false),
            1 => di.push(true),
            v => return Err(format!("board line: digital input {v} is not 0 or 1")),
        }
    }
    let mut ai = Vec::with_capacity(c.ai);
    for f in &fields[c.di..c.di + c.ai] {
        match num(f)? {
            v @ 0..=1023 => ai.push(v as u16),
            v => return Err(format!("board line: analog reading {v} is not 0-1023")),
        }
    }
    let id = num(fields[want - 1])?;
    if id != AURORA_ID {
        return Err(format!(
            "board id {id}, expected {AURORA_ID} (not an AuroraLD remote-I/O board?)"
        ));
    }
    Ok((di, ai))
}

/// The line of outputs sent to the board, CR LF included.
pub fn format_outputs(r#do: &[bool], ao: &[u16]) -> String {
    let mut f: Vec<String> = r#do.iter().map(|b| u8::from(*b).to_string()).collect();
    f.extend(ao.iter().map(|v| v.to_string()));
    format!("{}\r\n", f.join(","))
}

/// Waits for the next valid line, then answers it with the outputs.
pub(crate) fn cycle(
    port: &mut Box<dyn serialport::SerialPort>,
    cfg: &Config,
    reader: &mut Reader,
    out: &Outputs,
) -> Result<(Vec<bool>, Vec<u16>), IoError> {
    let timeout = cfg.timeout.max(Duration::from_millis(3 * u64::from(AURORA_PERIOD_MS)));
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(end) = reader.buf.iter().position(|b| *b == b'\n') {
            let line: Vec<u8> = reader.buf.drain(..=end).collect();
            // A later complete line is fresher: use the last one.
            if reader.buf.contains(&b'\n') {
                continue;
            }
            let text = String::from_utf8_lossy(&line);
            let r = parse_line(text.trim_end_matches(['\r', '\n']), cfg.counts).map_err(|e| IoError::Timeout(e.0))?;
            let msg = format_outputs(&out.r#do, &out.ao);
            port.write_all(msg.as_bytes())
                .and_then(|_| port.flush())
                .map_err(|e| IoError::Link(format!("serial port: {e}")))?;
            return Ok(r);
        }
        if reader.buf.len() > MAX_LINE {
            reader.buf.clear();
            return Err(IoError::Timeout(format!("no line end in {MAX_LINE} bytes")));
        }
        let now = Instant::now();
        if now >= deadline {
            return Err(IoError::Timeout(format!(
                "no line from the board within {} ms",
                timeout.as_millis()
            )));
        }
        let _ = port.set_timeout(deadline - now);
        let mut chunk = [0u8; 128];
        match port.read(&mut chunk) {
            Ok(0) => return Err(IoError::Link("serial port: end of file".into())),
            Ok(n) => reader.buf.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
            Err(e) => return Err(IoError::Link(format!("serial port: {e}"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::serial::tests::C;

    #[test]
    fn board_lines() {
        assert_eq!(
            parse_line("1,0,0,1,0,1,1023,0,512,7,5518", C),
            Ok((vec![true, false, false, true, false, true], vec![1023, 0, 512, 7]))
        );
        assert!(
            parse_line("1,0,0,1,0,1,1023,0,512,7,5517", C)
                .unwrap_err()
                .0
                .contains("board id 5517")
        );
        assert!(
            parse_line("1,0,0,1,0,1,1023,0,512,5518", C)
                .unwrap_err()
                .0
                .contains("10 fields")
        );
        assert!(
            parse_line("1,0,2,1,0,1,1023,0,512,7,5518", C)
                .unwrap_err()
                .0
                .contains("not 0 or 1")
        );
        assert!(
            parse_line("1,0,0,1,0,1,1024,0,512,7,5518", C)
                .unwrap_err()
                .0
                .contains("not 0-1023")
        );
        assert!(
            parse_line("1,0,0,1,0,x,1023,0,512,7,5518", C)
                .unwrap_err()
                .0
                .contains("`x`")
        );
        assert!(parse_line("", C).is_err());
    }

    #[test]
    fn output_lines() {
        assert_eq!(
            format_outputs(&[true, false, false, false, false, true], &[255, 0, 12, 300]),
            "1,0,0,0,0,1,255,0,12,300\r\n"
        );
    }
}
