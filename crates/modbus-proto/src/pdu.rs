//! Modbus PDUs (function code and data), as the Modbus Application
//! Protocol v1.1b3 defines them, in both directions: a server decodes
//! requests ([`parse`]) and encodes replies ([`put_bits`],
//! [`put_registers`], [`Request::echo`], [`exception`]); a master encodes
//! requests ([`Request::encode`]) and decodes replies ([`decode_reply`]).
//! The `mbap` and `rtu` modules wrap these PDUs for TCP and serial
//! lines.
//!
//! Pure functions over byte slices; decoding never panics on any input and
//! a server's decoding does not allocate (write data stays in the receive
//! buffer).

use std::borrow::Cow;
use std::fmt;

/// Largest PDU (function code and data).
pub const MAX_PDU: usize = 253;

/// Quantity limits of the specification.
pub const MAX_READ_BITS: u16 = 2000;
pub const MAX_READ_REGS: u16 = 125;
pub const MAX_WRITE_BITS: u16 = 1968;
pub const MAX_WRITE_REGS: u16 = 123;
pub const MAX_RW_WRITE_REGS: u16 = 121;

/// The function codes that write data: 5, 6, 15, 16, 22 (Mask Write
/// Register, which this crate does not implement) and 23 (Read/Write
/// Multiple Registers). A read-only server refuses all of them.
pub const WRITE_FUNCTIONS: [u8; 6] = [5, 6, 15, 16, 22, 23];

/// Whether function code `fc` writes data ([`WRITE_FUNCTIONS`]).
pub fn is_write_function(fc: u8) -> bool {
    WRITE_FUNCTIONS.contains(&fc)
}

/// Exception codes a server answers with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exception {
    IllegalFunction = 0x01,
    IllegalDataAddress = 0x02,
    IllegalDataValue = 0x03,
    ServerDeviceFailure = 0x04,
    /// The runtime has too many requests waiting (writes from many clients
    /// at once): try again.
    ServerDeviceBusy = 0x06,
    /// The request names a unit id this server does not answer for.
    GatewayTargetFailed = 0x0B,
}

/// What an exception code means, for messages.
pub fn exception_name(code: u8) -> &'static str {
    match code {
        1 => "illegal function",
        2 => "illegal data address",
        3 => "illegal data value",
        4 => "slave device failure",
        5 => "acknowledge",
        6 => "slave device busy",
        _ => "unknown exception",
    }
}

/// A request. Write data is kept as it travels (coils packed LSB first,
/// registers big-endian): borrowed from the receive buffer when decoded,
/// owned when a master builds it ([`Request::write_coils`],
/// [`Request::write_registers`]).
#[derive(Debug, Clone, PartialEq, Eq)]
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
    WriteMultipleCoils {
        start: u16,
        count: u16,
        bits: Cow<'a, [u8]>,
    },
    /// FC 16: big-endian register values.
    WriteMultipleRegisters { start: u16, values: Cow<'a, [u8]> },
    /// FC 23: the write happens before the read.
    ReadWriteRegisters {
        read_start: u16,
        read_count: u16,
        write_start: u16,
        values: Cow<'a, [u8]>,
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

/// Bits packed LSB first, as Modbus sends them.
pub fn pack_bits(bits: &[bool]) -> Vec<u8> {
    let mut out = vec![0u8; bits.len().div_ceil(8)];
    for (i, b) in bits.iter().enumerate() {
        if *b {
            out[i / 8] |= 1 << (i % 8);
        }
    }
    out
}

impl Request<'_> {
    /// FC 15 writing `values` from `start`.
    pub fn write_coils(start: u16, values: &[bool]) -> Request<'static> {
        Request::WriteMultipleCoils {
            start,
            count: values.len() as u16,
            bits: Cow::Owned(pack_bits(values)),
        }
    }

    /// FC 16 writing `values` from `start`.
    pub fn write_registers(start: u16, values: &[u16]) -> Request<'static> {
        Request::WriteMultipleRegisters {
            start,
            values: Cow::Owned(values.iter().flat_map(|v| v.to_be_bytes()).collect()),
        }
    }

    pub fn function(&self) -> u8 {
        match self {
            Request::ReadCoils { .. } => 1,
            Request::ReadDiscreteInputs { .. } => 2,
            Request::ReadHoldingRegisters { .. } => 3,
            Request::ReadInputRegisters { .. } => 4,
            Request::WriteSingleCoil { .. } => 5,
            Request::WriteSingleRegister { .. } => 6,
            Request::WriteMultipleCoils { .. } => 15,
            Request::WriteMultipleRegisters { .. } => 16,
            Request::ReadWriteRegisters { .. } => 23,
        }
    }

    /// How many coils or registers it reads or writes (FC 23: reads).
    pub fn count(&self) -> u16 {
        match self {
            Request::ReadCoils { count, .. }
            | Request::ReadDiscreteInputs { count, .. }
            | Request::ReadHoldingRegisters { count, .. }
            | Request::ReadInputRegisters { count, .. }
            | Request::WriteMultipleCoils { count, .. }
            | Request::ReadWriteRegisters { read_count: count, .. } => *count,
            Request::WriteSingleCoil { .. } | Request::WriteSingleRegister { .. } => 1,
            Request::WriteMultipleRegisters { values, .. } => (values.len() / 2) as u16,
        }
    }

    /// What the reply to a write repeats of it (its first four data bytes:
    /// the address and the value or quantity); `None` for a read.
    pub fn echo(&self) -> Option<[u8; 4]> {
        let pair = |a: u16, b: u16| {
            let (a, b) = (a.to_be_bytes(), b.to_be_bytes());
            Some([a[0], a[1], b[0], b[1]])
        };
        match *self {
            Request::WriteSingleCoil { addr, value } => pair(addr, if value { 0xFF00 } else { 0 }),
            Request::WriteSingleRegister { addr, value } => pair(addr, value),
            Request::WriteMultipleCoils { start, count, .. } => pair(start, count),
            Request::WriteMultipleRegisters { start, .. } => pair(start, self.count()),
            _ => None,
        }
    }

    /// Appends the PDU (function code and data).
    pub fn encode(&self, out: &mut Vec<u8>) {
        out.push(self.function());
        let be = |out: &mut Vec<u8>, v: u16| out.extend_from_slice(&v.to_be_bytes());
        match self {
            Request::ReadCoils { start, count }
            | Request::ReadDiscreteInputs { start, count }
            | Request::ReadHoldingRegisters { start, count }
            | Request::ReadInputRegisters { start, count } => {
                be(out, *start);
                be(out, *count);
            }
            Request::WriteSingleCoil { .. } | Request::WriteSingleRegister { .. } => {
                out.extend_from_slice(&self.echo().unwrap_or_default());
            }
            Request::WriteMultipleCoils { bits, .. } => {
                out.extend_from_slice(&self.echo().unwrap_or_default());
                out.push(bits.len() as u8);
                out.extend_from_slice(bits);
            }
            Request::WriteMultipleRegisters { values, .. } => {
                out.extend_from_slice(&self.echo().unwrap_or_default());
                out.push(values.len() as u8);
                out.extend_from_slice(values);
            }
            Request::ReadWriteRegisters {
                read_start,
                read_count,
                write_start,
                values,
            } => {
                be(out, *read_start);
                be(out, *read_count);
                be(out, *write_start);
                be(out, (values.len() / 2) as u16);
                out.push(values.len() as u8);
                out.extend_from_slice(values);
            }
        }
    }

    /// Length of the PDU of a normal reply.
    pub fn reply_len(&self) -> usize {
        let n = usize::from(self.count());
        match self {
            Request::ReadCoils { .. } | Request::ReadDiscreteInputs { .. } => 2 + n.div_ceil(8),
            Request::ReadHoldingRegisters { .. }
            | Request::ReadInputRegisters { .. }
            | Request::ReadWriteRegisters { .. } => 2 + 2 * n,
            _ => 5,
        }
    }
}

/// Decodes a request PDU. Unknown function codes are `IllegalFunction`; a
/// PDU of the wrong length, an inconsistent byte count or a quantity
/// outside the specification's limits is `IllegalDataValue`. Address ranges
/// are checked against the map by the caller (start + count past 65535 is
/// checked here).
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
    // A write of `count` items whose data (`bytes` of it, after a byte
    // count at `at`) ends the PDU.
    let data = |at: usize, bytes: usize| {
        if d.len() <= at || usize::from(d[at]) != bytes || d.len() != at + 1 + bytes {
            Err(Exception::IllegalDataValue)
        } else {
            Ok(Cow::Borrowed(&d[at + 1..]))
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
        15 | 16 => {
            if d.len() < 5 {
                return Err(Exception::IllegalDataValue);
            }
            let start = word(d, 0);
            let (max, bytes): (u16, fn(u16) -> usize) = if fc == 15 {
                (MAX_WRITE_BITS, |n| usize::from(n).div_ceil(8))
            } else {
                (MAX_WRITE_REGS, |n| 2 * usize::from(n))
            };
            let count = quantity(word(d, 2), max)?;
            let payload = data(4, bytes(count))?;
            span(start, count)?;
            Ok(if fc == 15 {
                Request::WriteMultipleCoils {
                    start,
                    count,
                    bits: payload,
                }
            } else {
                Request::WriteMultipleRegisters { start, values: payload }
            })
        }
        23 => {
            if d.len() < 9 {
                return Err(Exception::IllegalDataValue);
            }
            let read_start = word(d, 0);
            let read_count = quantity(word(d, 2), MAX_READ_REGS)?;
            let write_start = word(d, 4);
            let write_count = quantity(word(d, 6), MAX_RW_WRITE_REGS)?;
            let values = data(8, 2 * usize::from(write_count))?;
            span(read_start, read_count)?;
            span(write_start, write_count)?;
            Ok(Request::ReadWriteRegisters {
                read_start,
                read_count,
                write_start,
                values,
            })
        }
        _ => Err(Exception::IllegalFunction),
    }
}

/// A read reply's data: the byte count, then `count` bits packed LSB first
/// (bit `i` from `bit(i)`). Stops at the first error.
pub fn put_bits<E>(out: &mut Vec<u8>, count: u16, mut bit: impl FnMut(u16) -> Result<bool, E>) -> Result<(), E> {
    out.push(count.div_ceil(8) as u8);
    let mut byte = 0u8;
    for i in 0..count {
        if bit(i)? {
            byte |= 1 << (i % 8);
        }
        if i % 8 == 7 {
            out.push(byte);
            byte = 0;
        }
    }
    if !count.is_multiple_of(8) {
        out.push(byte);
    }
    Ok(())
}

/// A read reply's data: the byte count, then `count` registers big-endian
/// (register `i` from `reg(i)`). Stops at the first error.
pub fn put_registers<E>(out: &mut Vec<u8>, count: u16, mut reg: impl FnMut(u16) -> Result<u16, E>) -> Result<(), E> {
    out.push((2 * count) as u8);
    for i in 0..count {
        out.extend_from_slice(&reg(i)?.to_be_bytes());
    }
    Ok(())
}

/// Appends the exception reply to function `fc`.
pub fn exception(out: &mut Vec<u8>, fc: u8, e: Exception) {
    out.extend_from_slice(&[fc | 0x80, e as u8]);
}

/// The reply PDU to `req` with the given bits or registers (for reads;
/// ignored for writes): a slave's side, for tests and fakes.
pub fn encode_reply(req: &Request<'_>, bits: &[bool], regs: &[u16], out: &mut Vec<u8>) {
    out.push(req.function());
    match req {
        Request::ReadCoils { .. } | Request::ReadDiscreteInputs { .. } => {
            let _ = put_bits(out, bits.len() as u16, |i| Ok::<_, ()>(bits[usize::from(i)]));
        }
        Request::ReadHoldingRegisters { .. }
        | Request::ReadInputRegisters { .. }
        | Request::ReadWriteRegisters { .. } => {
            let _ = put_registers(out, regs.len() as u16, |i| Ok::<_, ()>(regs[usize::from(i)]));
        }
        _ => out.extend_from_slice(&req.echo().unwrap_or_default()),
    }
}

/// A decoded reply.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Response {
    /// FC 1, 2: as many bits as were asked for.
    Bits(Vec<bool>),
    /// FC 3, 4, 23.
    Registers(Vec<u16>),
    /// FC 5, 6, 15, 16: the echo matched the request.
    Written,
}

/// Why a reply was not accepted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FrameError {
    /// Shorter than the frame must be.
    Truncated {
        got: usize,
        want: usize,
    },
    BadCrc {
        got: u16,
        want: u16,
    },
    WrongSlave(u8),
    WrongFunction(u8),
    /// The slave answered with an exception code (1 illegal function, 2
    /// illegal data address, 3 illegal data value, 4 device failure …).
    Exception(u8),
    /// Well framed but not what the request asks for.
    Malformed(String),
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameError::Truncated { got, want } => write!(f, "truncated frame ({got} of {want} bytes)"),
            FrameError::BadCrc { got, want } => write!(f, "bad CRC ({got:04X}, expected {want:04X})"),
            FrameError::WrongSlave(s) => write!(f, "answer from slave {s}"),
            FrameError::WrongFunction(c) => write!(f, "answer with function code {c}"),
            FrameError::Exception(c) => write!(f, "exception {c} ({})", exception_name(*c)),
            FrameError::Malformed(m) => write!(f, "malformed answer: {m}"),
        }
    }
}

impl std::error::Error for FrameError {}

/// Checks and decodes the reply PDU `pdu` to `req`.
pub fn decode_reply(req: &Request<'_>, pdu: &[u8]) -> Result<Response, FrameError> {
    let Some((&fc, data)) = pdu.split_first() else {
        return Err(FrameError::Truncated { got: 0, want: 2 });
    };
    if fc == req.function() | 0x80 {
        return match data {
            [code] => Err(FrameError::Exception(*code)),
            _ => Err(FrameError::Malformed(format!("exception reply of {} bytes", pdu.len()))),
        };
    }
    if fc != req.function() {
        return Err(FrameError::WrongFunction(fc));
    }
    if pdu.len() != req.reply_len() {
        return Err(FrameError::Malformed(format!(
            "{} bytes, expected {}",
            pdu.len(),
            req.reply_len()
        )));
    }
    let n = usize::from(req.count());
    let byte_count = |want: usize| {
        if usize::from(data[0]) == want {
            Ok(())
        } else {
            Err(FrameError::Malformed(format!("byte count {}", data[0])))
        }
    };
    match req {
        Request::ReadCoils { .. } | Request::ReadDiscreteInputs { .. } => {
            byte_count(n.div_ceil(8))?;
            Ok(Response::Bits((0..n).map(|i| bit(&data[1..], i)).collect()))
        }
        Request::ReadHoldingRegisters { .. }
        | Request::ReadInputRegisters { .. }
        | Request::ReadWriteRegisters { .. } => {
            byte_count(2 * n)?;
            Ok(Response::Registers(registers(&data[1..]).collect()))
        }
        _ => {
            if req.echo().is_some_and(|e| data[..4] == e) {
                Ok(Response::Written)
            } else {
                Err(FrameError::Malformed("the echo differs from the request".into()))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(bytes: &[u8]) -> Cow<'_, [u8]> {
        Cow::Borrowed(bytes)
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
                bits: b(&[0xFF, 0x03])
            })
        );
        // Byte count not matching the quantity, or the data.
        assert_eq!(parse(&[15, 0, 0, 0, 10, 1, 0xFF]), Err(IllegalDataValue));
        assert_eq!(parse(&[15, 0, 0, 0, 10, 2, 0xFF]), Err(IllegalDataValue));
        assert_eq!(
            parse(&[16, 0, 4, 0, 2, 4, 0, 1, 0, 2]),
            Ok(Request::WriteMultipleRegisters {
                start: 4,
                values: b(&[0, 1, 0, 2])
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
                values: b(&[0xAB, 0xCD])
            })
        );
        assert_eq!(parse(&[23, 0, 0, 0, 2, 0, 9, 0, 1, 2, 0xAB]), Err(IllegalDataValue));
        for fc in [0u8, 7, 8, 17, 22, 24, 43, 0x41, 0x80, 0xFF] {
            assert_eq!(parse(&[fc, 0, 0, 0, 1]), Err(IllegalFunction), "fc {fc}");
        }
        assert_eq!(parse(&[]), Err(IllegalFunction));
    }

    #[test]
    fn requests_encode_to_what_parse_reads_back() {
        let reqs = [
            Request::ReadCoils { start: 3, count: 17 },
            Request::ReadDiscreteInputs { start: 0, count: 2000 },
            Request::ReadHoldingRegisters { start: 9, count: 125 },
            Request::ReadInputRegisters { start: 1, count: 1 },
            Request::WriteSingleCoil { addr: 7, value: true },
            Request::WriteSingleRegister { addr: 7, value: 0xBEEF },
            Request::write_coils(0x13, &[true, false, true, true, false, false, true, true, true, false]),
            Request::write_registers(1, &[0x000A, 0x0102]),
            Request::ReadWriteRegisters {
                read_start: 0,
                read_count: 2,
                write_start: 9,
                values: b(&[0xAB, 0xCD]),
            },
        ];
        for r in reqs {
            let mut pdu = Vec::new();
            r.encode(&mut pdu);
            assert_eq!(parse(&pdu), Ok(r.clone()), "{pdu:02X?}");
        }
        let mut pdu = Vec::new();
        Request::write_coils(0x13, &[true, false, true, true, false, false, true, true, true, false]).encode(&mut pdu);
        assert_eq!(pdu, [0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01]);
    }

    #[test]
    fn replies_decode_and_bad_ones_are_refused() {
        let req = Request::ReadDiscreteInputs { start: 0, count: 6 };
        let mut ok = Vec::new();
        encode_reply(&req, &[true, false, false, true, true, false], &[], &mut ok);
        assert_eq!(ok, [2, 1, 0b011001]);
        assert_eq!(
            decode_reply(&req, &ok),
            Ok(Response::Bits(vec![true, false, false, true, true, false]))
        );
        assert_eq!(decode_reply(&req, &[0x82, 2]), Err(FrameError::Exception(2)));
        assert!(matches!(
            decode_reply(&req, &[0x82, 2, 0]),
            Err(FrameError::Malformed(_))
        ));
        assert_eq!(decode_reply(&req, &[3, 1, 0]), Err(FrameError::WrongFunction(3)));
        assert!(matches!(decode_reply(&req, &[2, 2, 0]), Err(FrameError::Malformed(_))));
        assert!(decode_reply(&req, &[]).is_err());
        let w = Request::WriteSingleCoil { addr: 3, value: true };
        assert_eq!(decode_reply(&w, &[5, 0, 3, 0xFF, 0]), Ok(Response::Written));
        assert!(matches!(
            decode_reply(&w, &[5, 0, 4, 0xFF, 0]),
            Err(FrameError::Malformed(_))
        ));
        let regs = Request::ReadInputRegisters { start: 0, count: 2 };
        assert_eq!(
            decode_reply(&regs, &[4, 4, 0, 1, 0, 2]),
            Ok(Response::Registers(vec![1, 2]))
        );
        assert!(matches!(
            decode_reply(&regs, &[4, 3, 0, 1, 0, 2]),
            Err(FrameError::Malformed(_))
        ));
    }

    #[test]
    fn reply_data_and_helpers() {
        let mut out = Vec::new();
        put_bits(&mut out, 10, |i| Ok::<_, ()>(i % 3 == 0)).expect("bits");
        assert_eq!(out, [2, 0b0100_1001, 0b10]);
        out.clear();
        assert_eq!(
            put_registers(&mut out, 3, |i| if i < 2 { Ok(i + 7) } else { Err(i) }),
            Err(2)
        );
        exception(&mut out, 3, Exception::IllegalDataAddress);
        assert_eq!(&out[out.len() - 2..], [0x83, 2]);
        assert_eq!(registers(&[0x12, 0x34, 0, 1]).collect::<Vec<_>>(), [0x1234, 1]);
        assert!(bit(&[0b10], 1) && !bit(&[0b10], 0) && !bit(&[], 3));
        assert_eq!(exception_name(2), "illegal data address");
    }
}
