//! Modbus TCP framing (the MBAP header) and request PDUs, as the Modbus
//! Application Protocol v1.1b3 and Messaging on TCP/IP v1.0b define them.
//!
//! Pure functions over byte slices, with no I/O and no allocation: the
//! server and the fuzz target (`fuzz/fuzz_targets/modbus_frame.rs`) share
//! them. [`split`] cuts one ADU off the front of a buffer (several requests
//! may arrive in one TCP segment, and one request may arrive in pieces);
//! [`parse`] turns its PDU into a [`Request`] or the exception to answer.

/// Length of the MBAP header (transaction, protocol, length, unit).
pub const MBAP_LEN: usize = 7;
/// Largest PDU (function code and data).
pub const MAX_PDU: usize = 253;
/// Largest ADU.
pub const MAX_ADU: usize = MBAP_LEN + MAX_PDU;

/// Quantity limits of the specification.
pub const MAX_READ_BITS: u16 = 2000;
pub const MAX_READ_REGS: u16 = 125;
pub const MAX_WRITE_BITS: u16 = 1968;
pub const MAX_WRITE_REGS: u16 = 123;
pub const MAX_RW_WRITE_REGS: u16 = 121;

/// The MBAP fields a reply repeats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    pub transaction: u16,
    pub unit: u8,
}

/// What the front of a receive buffer holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split<'a> {
    /// The start of an ADU: more bytes are needed.
    Incomplete,
    /// One whole ADU of `len` bytes.
    Frame { header: Header, pdu: &'a [u8], len: usize },
    /// Not Modbus TCP: there is no way to find the next frame, so the
    /// connection is closed (the specification's advice).
    Invalid(&'static str),
}

/// Cuts the first ADU off `buf`.
pub fn split(buf: &[u8]) -> Split<'_> {
    if buf.len() >= 4 && (buf[2], buf[3]) != (0, 0) {
        return Split::Invalid("the protocol identifier is not 0 (not Modbus)");
    }
    if buf.len() < 6 {
        return Split::Incomplete;
    }
    let len = usize::from(u16::from_be_bytes([buf[4], buf[5]]));
    if len < 2 {
        return Split::Invalid("the length field is below 2 (a unit id and a function code)");
    }
    if len > 1 + MAX_PDU {
        return Split::Invalid("the length field is above 254");
    }
    let total = 6 + len;
    if buf.len() < total {
        return Split::Incomplete;
    }
    Split::Frame {
        header: Header {
            transaction: u16::from_be_bytes([buf[0], buf[1]]),
            unit: buf[6],
        },
        pdu: &buf[MBAP_LEN..total],
        len: total,
    }
}

/// Exception codes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exception {
    IllegalFunction = 0x01,
    IllegalDataAddress = 0x02,
    IllegalDataValue = 0x03,
    ServerDeviceFailure = 0x04,
    /// The request names a unit id this server does not answer for.
    GatewayTargetFailed = 0x0B,
}

/// A decoded request. Write data stays in the receive buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Request<'a> {
    /// FC 1.
    ReadCoils { start: u16, count: u16 },
    /// FC 2.
    ReadDiscreteInputs { start: u16, count: u16 },
    /// FC 3.
    ReadHoldingRegisters { start: u16, count: u16 },
    /// FC 4.
    ReadInputRegisters { start: u16, count: u16 },
    /// FC 5.
    WriteSingleCoil { addr: u16, value: bool },
    /// FC 6.
    WriteSingleRegister { addr: u16, value: u16 },
    /// FC 15: `count` bits packed LSB first in `bits`.
    WriteMultipleCoils { start: u16, count: u16, bits: &'a [u8] },
    /// FC 16: big-endian register values.
    WriteMultipleRegisters { start: u16, values: &'a [u8] },
    /// FC 23: the write happens before the read.
    ReadWriteRegisters {
        read_start: u16,
        read_count: u16,
        write_start: u16,
        values: &'a [u8],
    },
}

fn word(d: &[u8], at: usize) -> u16 {
    u16::from_be_bytes([d[at], d[at + 1]])
}

/// The register values of a write (big-endian pairs).
pub fn registers(values: &[u8]) -> impl Iterator<Item = u16> + '_ {
    values.chunks_exact(2).map(|p| u16::from_be_bytes([p[0], p[1]]))
}

/// Bit `i` of packed coil data.
pub fn bit(bits: &[u8], i: usize) -> bool {
    bits.get(i / 8).is_some_and(|b| b >> (i % 8) & 1 == 1)
}

/// Decodes a PDU. Unknown function codes are `IllegalFunction`; a PDU of
/// the wrong length, an inconsistent byte count or a quantity outside the
/// specification's limits is `IllegalDataValue`. Address ranges are checked
/// against the map by the caller (start + count past 65535 is checked here).
pub fn parse(pdu: &[u8]) -> Result<Request<'_>, Exception> {
    let Some((&fc, d)) = pdu.split_first() else {
        return Err(Exception::IllegalFunction);
    };
    let fixed = |n: usize| {
        if d.len() == n {
            Ok(())
        } else {
            Err(Exception::IllegalDataValue)
        }
    };
    let quantity = |q: u16, max: u16| {
        if (1..=max).contains(&q) {
            Ok(q)
        } else {
            Err(Exception::IllegalDataValue)
        }
    };
    let span = |start: u16, count: u16| {
        if u32::from(start) + u32::from(count) > 0x1_0000 {
            Err(Exception::IllegalDataAddress)
        } else {
            Ok(())
        }
    };
    match fc {
        1..=4 => {
            fixed(4)?;
            let start = word(d, 0);
            let max = if fc <= 2 { MAX_READ_BITS } else { MAX_READ_REGS };
            let count = quantity(word(d, 2), max)?;
            span(start, count)?;
            Ok(match fc {
                1 => Request::ReadCoils { start, count },
                2 => Request::ReadDiscreteInputs { start, count },
                3 => Request::ReadHoldingRegisters { start, count },
                _ => Request::ReadInputRegisters { start, count },
            })
        }
        5 => {
            fixed(4)?;
            let value = match word(d, 2) {
                0xFF00 => true,
                0x0000 => false,
                _ => return Err(Exception::IllegalDataValue),
            };
            Ok(Request::WriteSingleCoil {
                addr: word(d, 0),
                value,
            })
        }
        6 => {
            fixed(4)?;
            Ok(Request::WriteSingleRegister {
                addr: word(d, 0),
                value: word(d, 2),
            })
        }
        15 => {
            if d.len() < 5 {
                return Err(Exception::IllegalDataValue);
            }
            let start = word(d, 0);
            let count = quantity(word(d, 2), MAX_WRITE_BITS)?;
            let bytes = usize::from(count).div_ceil(8);
            if usize::from(d[4]) != bytes || d.len() != 5 + bytes {
                return Err(Exception::IllegalDataValue);
            }
            span(start, count)?;
            Ok(Request::WriteMultipleCoils {
                start,
                count,
                bits: &d[5..],
            })
        }
        16 => {
            if d.len() < 5 {
                return Err(Exception::IllegalDataValue);
            }
            let start = word(d, 0);
            let count = quantity(word(d, 2), MAX_WRITE_REGS)?;
            let bytes = 2 * usize::from(count);
            if usize::from(d[4]) != bytes || d.len() != 5 + bytes {
                return Err(Exception::IllegalDataValue);
            }
            span(start, count)?;
            Ok(Request::WriteMultipleRegisters { start, values: &d[5..] })
        }
        23 => {
            if d.len() < 9 {
                return Err(Exception::IllegalDataValue);
            }
            let read_start = word(d, 0);
            let read_count = quantity(word(d, 2), MAX_READ_REGS)?;
            let write_start = word(d, 4);
            let write_count = quantity(word(d, 6), MAX_RW_WRITE_REGS)?;
            let bytes = 2 * usize::from(write_count);
            if usize::from(d[8]) != bytes || d.len() != 9 + bytes {
                return Err(Exception::IllegalDataValue);
            }
            span(read_start, read_count)?;
            span(write_start, write_count)?;
            Ok(Request::ReadWriteRegisters {
                read_start,
                read_count,
                write_start,
                values: &d[9..],
            })
        }
        _ => Err(Exception::IllegalFunction),
    }
}

/// Starts a reply in `out`: the MBAP header with a length to be set by
/// [`end`]. Returns where the reply starts.
pub fn begin(out: &mut Vec<u8>, h: Header, fc: u8) -> usize {
    let at = out.len();
    let t = h.transaction.to_be_bytes();
    out.extend_from_slice(&[t[0], t[1], 0, 0, 0, 0, h.unit, fc]);
    at
}

/// Sets the length field of the reply started at `at`.
pub fn end(out: &mut [u8], at: usize) {
    let len = (out.len() - at - 6) as u16;
    out[at + 4..at + 6].copy_from_slice(&len.to_be_bytes());
}

/// Replaces whatever follows `at` by an exception reply.
pub fn exception(out: &mut Vec<u8>, at: usize, h: Header, fc: u8, e: Exception) {
    out.truncate(at);
    begin(out, h, fc | 0x80);
    out.push(e as u8);
    end(out, at);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adu(tid: u16, unit: u8, pdu: &[u8]) -> Vec<u8> {
        let mut v = tid.to_be_bytes().to_vec();
        v.extend_from_slice(&[0, 0]);
        v.extend_from_slice(&((pdu.len() + 1) as u16).to_be_bytes());
        v.push(unit);
        v.extend_from_slice(pdu);
        v
    }

    #[test]
    fn split_finds_pipelined_and_partial_frames() {
        let mut buf = adu(1, 1, &[3, 0, 0, 0, 10]);
        buf.extend(adu(2, 1, &[1, 0, 5, 0, 1]));
        let Split::Frame { header, pdu, len } = split(&buf) else {
            panic!("{:?}", split(&buf))
        };
        assert_eq!(
            (header.transaction, header.unit, pdu, len),
            (1, 1, &[3u8, 0, 0, 0, 10][..], 12)
        );
        let rest = &buf[len..];
        assert!(matches!(
            split(rest),
            Split::Frame {
                header: Header { transaction: 2, .. },
                ..
            }
        ));
        for cut in 0..rest.len() {
            assert_eq!(split(&rest[..cut]), Split::Incomplete, "cut at {cut}");
        }
    }

    #[test]
    fn split_refuses_what_is_not_modbus() {
        assert!(matches!(split(b"GET / HTTP/1.1\r\n"), Split::Invalid(_)));
        assert!(matches!(split(&[0, 1, 0, 0, 0, 1, 1]), Split::Invalid(_)));
        assert!(matches!(split(&[0, 1, 0, 0, 0, 255, 1]), Split::Invalid(_)));
        assert!(matches!(split(&[0, 1, 0, 0, 0, 0]), Split::Invalid(_)));
        // The largest legal frame is accepted.
        let big = adu(9, 0, &[0x10; MAX_PDU]);
        assert!(matches!(split(&big), Split::Frame { len: MAX_ADU, .. }));
    }

    #[test]
    fn requests_decode_and_bad_ones_get_their_exception() {
        use Exception::*;
        assert_eq!(
            parse(&[3, 0, 1, 0, 10]),
            Ok(Request::ReadHoldingRegisters { start: 1, count: 10 })
        );
        assert_eq!(
            parse(&[1, 0, 0, 0x07, 0xD0]),
            Ok(Request::ReadCoils { start: 0, count: 2000 })
        );
        assert_eq!(parse(&[1, 0, 0, 0x07, 0xD1]), Err(IllegalDataValue));
        assert_eq!(parse(&[3, 0, 0, 0, 0]), Err(IllegalDataValue));
        assert_eq!(parse(&[3, 0, 0, 0, 126]), Err(IllegalDataValue));
        assert_eq!(parse(&[3, 0xFF, 0xFF, 0, 2]), Err(IllegalDataAddress));
        assert_eq!(
            parse(&[3, 0xFF, 0xFF, 0, 1]),
            Ok(Request::ReadHoldingRegisters { start: 65535, count: 1 })
        );
        assert_eq!(parse(&[3, 0, 0, 0]), Err(IllegalDataValue));
        assert_eq!(parse(&[3, 0, 0, 0, 1, 0]), Err(IllegalDataValue));
        assert_eq!(
            parse(&[5, 0, 7, 0xFF, 0]),
            Ok(Request::WriteSingleCoil { addr: 7, value: true })
        );
        assert_eq!(
            parse(&[5, 0, 7, 0, 0]),
            Ok(Request::WriteSingleCoil { addr: 7, value: false })
        );
        assert_eq!(parse(&[5, 0, 7, 0, 1]), Err(IllegalDataValue));
        assert_eq!(
            parse(&[6, 0, 7, 0x12, 0x34]),
            Ok(Request::WriteSingleRegister { addr: 7, value: 0x1234 })
        );
        assert_eq!(
            parse(&[15, 0, 0, 0, 10, 2, 0xFF, 0x03]),
            Ok(Request::WriteMultipleCoils {
                start: 0,
                count: 10,
                bits: &[0xFF, 0x03]
            })
        );
        // Byte count not matching the quantity, or the data.
        assert_eq!(parse(&[15, 0, 0, 0, 10, 1, 0xFF]), Err(IllegalDataValue));
        assert_eq!(parse(&[15, 0, 0, 0, 10, 2, 0xFF]), Err(IllegalDataValue));
        assert_eq!(
            parse(&[16, 0, 4, 0, 2, 4, 0, 1, 0, 2]),
            Ok(Request::WriteMultipleRegisters {
                start: 4,
                values: &[0, 1, 0, 2]
            })
        );
        assert_eq!(parse(&[16, 0, 4, 0, 2, 3, 0, 1, 0]), Err(IllegalDataValue));
        assert_eq!(parse(&[16, 0, 4, 0, 124, 248]), Err(IllegalDataValue));
        assert_eq!(
            parse(&[23, 0, 0, 0, 2, 0, 9, 0, 1, 2, 0xAB, 0xCD]),
            Ok(Request::ReadWriteRegisters {
                read_start: 0,
                read_count: 2,
                write_start: 9,
                values: &[0xAB, 0xCD]
            })
        );
        assert_eq!(parse(&[23, 0, 0, 0, 2, 0, 9, 0, 1, 2, 0xAB]), Err(IllegalDataValue));
        for fc in [0u8, 7, 8, 17, 22, 24, 43, 0x41, 0x80, 0xFF] {
            assert_eq!(parse(&[fc, 0, 0, 0, 1]), Err(IllegalFunction), "fc {fc}");
        }
        assert_eq!(parse(&[]), Err(IllegalFunction));
    }

    #[test]
    fn replies_have_their_length() {
        let h = Header {
            transaction: 0x0102,
            unit: 7,
        };
        let mut out = vec![9, 9];
        let at = begin(&mut out, h, 3);
        out.extend_from_slice(&[2, 0xAB, 0xCD]);
        end(&mut out, at);
        assert_eq!(out, [9, 9, 1, 2, 0, 0, 0, 5, 7, 3, 2, 0xAB, 0xCD]);
        exception(&mut out, at, h, 3, Exception::IllegalDataAddress);
        assert_eq!(out, [9, 9, 1, 2, 0, 0, 0, 3, 7, 0x83, 2]);
        assert_eq!(registers(&[0x12, 0x34, 0, 1]).collect::<Vec<_>>(), [0x1234, 1]);
        assert!(bit(&[0b10], 1) && !bit(&[0b10], 0) && !bit(&[], 3));
    }
}
