//! Intel HEX (issue 19): how byte code travels to a board, as the 8051 PLC of
//! `002_…` received its program — data records (type 00) of up to 16 bytes
//! and an end-of-file record (type 01), each with its checksum (the two's
//! complement of the sum of its bytes). The reader reports a bad record with
//! the source's error flags, which the board's loader answers with too.

use std::fmt::Write as _;

/// Bytes per data record.
pub const RECORD_BYTES: usize = 16;

/// The source's error flags (a board answers a rejected record with one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum HexError {
    #[error("line {line}: a character that is not hexadecimal (flag 01)")]
    NotHex { line: usize },
    #[error("line {line}: record type {kind:02X} is not data (00) or end of file (01) (flag 02)")]
    RecordType { line: usize, kind: u8 },
    #[error("line {line}: checksum {found:02X}, the record's bytes sum to {want:02X} (flag 04)")]
    Checksum { line: usize, want: u8, found: u8 },
    #[error("line {line}: no data (an empty or short record, or none before the end) (flag 08)")]
    NoData { line: usize },
    #[error("line {line}: data past {limit} bytes (flag 10)")]
    Overflow { line: usize, limit: usize },
}

impl HexError {
    /// The flag byte the board answers with.
    pub fn flag(&self) -> u8 {
        match self {
            HexError::NotHex { .. } => 0x01,
            HexError::RecordType { .. } => 0x02,
            HexError::Checksum { .. } => 0x04,
            HexError::NoData { .. } => 0x08,
            HexError::Overflow { .. } => 0x10,
        }
    }
}

fn checksum(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0u8, |s, b| s.wrapping_add(*b)).wrapping_neg()
}

/// `data` as Intel HEX from address 0: 16-byte data records, then the end record.
pub fn write(data: &[u8]) -> String {
    let mut out = String::new();
    for (k, chunk) in data.chunks(RECORD_BYTES).enumerate() {
        let at = (k * RECORD_BYTES) as u16;
        let mut rec = vec![chunk.len() as u8, (at >> 8) as u8, at as u8, 0x00];
        rec.extend_from_slice(chunk);
        rec.push(checksum(&rec));
        out.push(':');
        for b in rec {
            let _ = write!(out, "{b:02X}");
        }
        out.push_str("\r\n");
    }
    out.push_str(":00000001FF\r\n");
    out
}

/// One record: (type, address, data), checked.
pub fn record(line: &str, n: usize) -> Result<(u8, u16, Vec<u8>), HexError> {
    let hex = line.trim_end().strip_prefix(':').ok_or(HexError::NotHex { line: n })?;
    if hex.len() % 2 != 0 || !hex.bytes().all(|c| c.is_ascii_hexdigit()) {
        return Err(HexError::NotHex { line: n });
    }
    let bytes: Vec<u8> = (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or(0))
        .collect();
    if bytes.len() < 5 || bytes.len() != 5 + bytes[0] as usize {
        return Err(HexError::NoData { line: n });
    }
    let (body, sum) = bytes.split_at(bytes.len() - 1);
    if checksum(body) != sum[0] {
        return Err(HexError::Checksum {
            line: n,
            want: checksum(body),
            found: sum[0],
        });
    }
    let kind = bytes[3];
    if kind > 1 {
        return Err(HexError::RecordType { line: n, kind });
    }
    Ok((kind, u16::from_be_bytes([bytes[1], bytes[2]]), body[4..].to_vec()))
}

/// The bytes of an Intel HEX text (at most `limit`), each record checked.
pub fn read(text: &str, limit: usize) -> Result<Vec<u8>, HexError> {
    let mut out = Vec::new();
    let mut lines = 0;
    for (k, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        lines = k + 1;
        let (kind, at, data) = record(line, k + 1)?;
        if kind == 1 {
            return if out.is_empty() {
                Err(HexError::NoData { line: k + 1 })
            } else {
                Ok(out)
            };
        }
        let end = at as usize + data.len();
        if end > limit {
            return Err(HexError::Overflow { line: k + 1, limit });
        }
        if out.len() < end {
            out.resize(end, 0xFF);
        }
        out[at as usize..end].copy_from_slice(&data);
    }
    Err(HexError::NoData { line: lines + 1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_checks_every_record() {
        let data: Vec<u8> = (0..=40u8).collect();
        let text = write(&data);
        assert!(
            text.starts_with(":10000000000102030405060708090A0B0C0D0E0F78\r\n"),
            "{text}"
        );
        assert!(text.ends_with(":00000001FF\r\n"));
        assert_eq!(read(&text, 1024), Ok(data));
        // Each of the source's flags from a crafted record.
        let cases = [
            (":10000000000102030405060708090A0B0C0D0E0G78", 0x01),
            (":0100000200FD", 0x02),
            (":10000000000102030405060708090A0B0C0D0E0F79", 0x04),
            (":0000000000", 0x08),
            (":0100FF000000", 0x10),
        ];
        for (rec, flag) in cases {
            let err = read(&format!("{rec}\r\n:00000001FF\r\n"), 64).expect_err(rec);
            assert_eq!(err.flag(), flag, "{rec}: {err}");
        }
        assert_eq!(
            read(":00000001FF\r\n", 8).map_err(|e| e.flag()),
            Err(0x08),
            "no data before the end"
        );
        assert_eq!(
            read(":0100000000FF\r\n", 8).map_err(|e| e.flag()),
            Err(0x08),
            "no end record"
        );
    }
}
