//! Modbus RTU framing (the subset a remote-I/O master needs): CRC-16,
//! requests of function codes 1 2 3 4 5 6 15 16, and their responses.
//!
//! A frame is `slave, function, data…, crc_lo, crc_hi`. The master knows
//! from its request how long the answer must be ([`Request::response_len`]),
//! so it does not depend on the 3.5-character silence to find the end of a
//! response; [`decode_response`] checks everything else (CRC, slave id,
//! function, lengths, exception replies) and never panics on any input.

use std::fmt;

/// CRC-16/MODBUS (polynomial 0xA001 reflected, initial 0xFFFF).
pub fn crc16(data: &[u8]) -> u16 {
    let mut crc: u16 = 0xFFFF;
    for &b in data {
        crc ^= u16::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xA001 } else { crc >> 1 };
        }
    }
    crc
}

/// Appends the CRC (low byte first).
pub fn with_crc(mut frame: Vec<u8>) -> Vec<u8> {
    let c = crc16(&frame);
    frame.extend_from_slice(&c.to_le_bytes());
    frame
}

/// Largest RTU frame.
pub const MAX_FRAME: usize = 256;

/// A request of the master.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Request {
    /// FC 1.
    ReadCoils { addr: u16, qty: u16 },
    /// FC 2.
    ReadDiscreteInputs { addr: u16, qty: u16 },
    /// FC 3.
    ReadHoldingRegisters { addr: u16, qty: u16 },
    /// FC 4.
    ReadInputRegisters { addr: u16, qty: u16 },
    /// FC 5.
    WriteSingleCoil { addr: u16, value: bool },
    /// FC 6.
    WriteSingleRegister { addr: u16, value: u16 },
    /// FC 15.
    WriteMultipleCoils { addr: u16, values: Vec<bool> },
    /// FC 16.
    WriteMultipleRegisters { addr: u16, values: Vec<u16> },
}

/// A decoded answer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Response {
    /// FC 1, 2: as many bits as were asked for.
    Bits(Vec<bool>),
    /// FC 3, 4.
    Registers(Vec<u16>),
    /// FC 5, 6, 15, 16: the echo matched the request.
    Written,
}

/// Why a response was not accepted.
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

impl Request {
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
        }
    }

    /// The frame for `slave`, CRC included.
    pub fn encode(&self, slave: u8) -> Vec<u8> {
        let mut f = vec![slave, self.function()];
        let be = |f: &mut Vec<u8>, v: u16| f.extend_from_slice(&v.to_be_bytes());
        match self {
            Request::ReadCoils { addr, qty }
            | Request::ReadDiscreteInputs { addr, qty }
            | Request::ReadHoldingRegisters { addr, qty }
            | Request::ReadInputRegisters { addr, qty } => {
                be(&mut f, *addr);
                be(&mut f, *qty);
            }
            Request::WriteSingleCoil { addr, value } => {
                be(&mut f, *addr);
                be(&mut f, if *value { 0xFF00 } else { 0 });
            }
            Request::WriteSingleRegister { addr, value } => {
                be(&mut f, *addr);
                be(&mut f, *value);
            }
            Request::WriteMultipleCoils { addr, values } => {
                be(&mut f, *addr);
                be(&mut f, values.len() as u16);
                f.push(values.len().div_ceil(8) as u8);
                f.extend(pack_bits(values));
            }
            Request::WriteMultipleRegisters { addr, values } => {
                be(&mut f, *addr);
                be(&mut f, values.len() as u16);
                f.push((values.len() * 2) as u8);
                for v in values {
                    be(&mut f, *v);
                }
            }
        }
        with_crc(f)
    }

    /// Length of a normal answer, CRC included.
    pub fn response_len(&self) -> usize {
        match self {
            Request::ReadCoils { qty, .. } | Request::ReadDiscreteInputs { qty, .. } => {
                5 + usize::from(*qty).div_ceil(8)
            }
            Request::ReadHoldingRegisters { qty, .. } | Request::ReadInputRegisters { qty, .. } => {
                5 + 2 * usize::from(*qty)
            }
            _ => 8,
        }
    }

    /// How many bytes the answer that starts with `head` has in all: an
    /// exception is 5 bytes, anything else [`Self::response_len`]. `None`
    /// until the function byte has arrived.
    pub fn expected_len(&self, head: &[u8]) -> Option<usize> {
        let fc = *head.get(1)?;
        Some(if fc & 0x80 != 0 { 5 } else { self.response_len() })
    }
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

/// Checks and decodes the answer `frame` of `slave` to `req`.
pub fn decode_response(slave: u8, req: &Request, frame: &[u8]) -> Result<Response, FrameError> {
    if frame.len() < 5 {
        return Err(FrameError::Truncated {
            got: frame.len(),
            want: req.expected_len(frame).unwrap_or(5),
        });
    }
    let (body, crc) = frame.split_at(frame.len() - 2);
    let got = u16::from_le_bytes([crc[0], crc[1]]);
    let want = crc16(body);
    if got != want {
        return Err(FrameError::BadCrc { got, want });
    }
    if body[0] != slave {
        return Err(FrameError::WrongSlave(body[0]));
    }
    let fc = body[1];
    if fc == req.function() | 0x80 {
        if frame.len() != 5 {
            return Err(FrameError::Malformed(format!(
                "exception reply of {} bytes",
                frame.len()
            )));
        }
        return Err(FrameError::Exception(body[2]));
    }
    if fc != req.function() {
        return Err(FrameError::WrongFunction(fc));
    }
    if frame.len() != req.response_len() {
        return Err(FrameError::Malformed(format!(
            "{} bytes, expected {}",
            frame.len(),
            req.response_len()
        )));
    }
    let data = &body[2..];
    let be = |i: usize| u16::from_be_bytes([data[i], data[i + 1]]);
    match req {
        Request::ReadCoils { qty, .. } | Request::ReadDiscreteInputs { qty, .. } => {
            let n = usize::from(*qty);
            if usize::from(data[0]) != n.div_ceil(8) {
                return Err(FrameError::Malformed(format!("byte count {}", data[0])));
            }
            Ok(Response::Bits(
                (0..n).map(|i| data[1 + i / 8] >> (i % 8) & 1 == 1).collect(),
            ))
        }
        Request::ReadHoldingRegisters { qty, .. } | Request::ReadInputRegisters { qty, .. } => {
            let n = usize::from(*qty);
            if usize::from(data[0]) != 2 * n {
                return Err(FrameError::Malformed(format!("byte count {}", data[0])));
            }
            Ok(Response::Registers((0..n).map(|i| be(1 + 2 * i)).collect()))
        }
        _ => {
            // The answer echoes the request's first four data bytes.
            let sent = req.encode(slave);
            if data[..4] != sent[2..6] {
                return Err(FrameError::Malformed("the echo differs from the request".into()));
            }
            Ok(Response::Written)
        }
    }
}

/// The slave's side, for tests and fakes: the answer to `req` with the
/// given bits or registers (ignored for writes).
pub fn encode_response(slave: u8, req: &Request, bits: &[bool], regs: &[u16]) -> Vec<u8> {
    let fc = req.function();
    let mut f = vec![slave, fc];
    match req {
        Request::ReadCoils { .. } | Request::ReadDiscreteInputs { .. } => {
            let p = pack_bits(bits);
            f.push(p.len() as u8);
            f.extend(p);
        }
        Request::ReadHoldingRegisters { .. } | Request::ReadInputRegisters { .. } => {
            f.push((regs.len() * 2) as u8);
            for r in regs {
                f.extend_from_slice(&r.to_be_bytes());
            }
        }
        _ => {
            let sent = req.encode(slave);
            f.extend_from_slice(&sent[2..6]);
        }
    }
    with_crc(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn crc_of_known_frames() {
        // Read holding registers 0..1 of slave 1: 01 03 00 00 00 01 84 0A.
        assert_eq!(
            Request::ReadHoldingRegisters { addr: 0, qty: 1 }.encode(1),
            [0x01, 0x03, 0x00, 0x00, 0x00, 0x01, 0x84, 0x0A]
        );
        // Modbus spec example: slave 0x11, read coils 0x13 x 0x25 → CRC 0E84.
        assert_eq!(
            Request::ReadCoils { addr: 0x13, qty: 0x25 }.encode(0x11),
            [0x11, 0x01, 0x00, 0x13, 0x00, 0x25, 0x0E, 0x84]
        );
        assert_eq!(crc16(b"123456789"), 0x4B37);
    }

    #[test]
    fn multiple_writes_are_framed() {
        let r = Request::WriteMultipleCoils {
            addr: 0x13,
            values: vec![true, false, true, true, false, false, true, true, true, false],
        };
        let f = r.encode(0x11);
        assert_eq!(&f[..9], [0x11, 0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01]);
        let r = Request::WriteMultipleRegisters {
            addr: 1,
            values: vec![0x000A, 0x0102],
        };
        assert_eq!(&r.encode(0x11)[..11], [0x11, 0x10, 0, 1, 0, 2, 4, 0, 0x0A, 1, 2]);
    }

    #[test]
    fn answers_are_checked() {
        let req = Request::ReadDiscreteInputs { addr: 0, qty: 6 };
        let ok = encode_response(1, &req, &[true, false, false, true, true, false], &[]);
        assert_eq!(
            decode_response(1, &req, &ok),
            Ok(Response::Bits(vec![true, false, false, true, true, false]))
        );
        let mut bad = ok.clone();
        bad[3] ^= 0x40;
        assert!(matches!(decode_response(1, &req, &bad), Err(FrameError::BadCrc { .. })));
        assert_eq!(decode_response(2, &req, &ok), Err(FrameError::WrongSlave(1)));
        assert!(matches!(
            decode_response(1, &req, &ok[..4]),
            Err(FrameError::Truncated { got: 4, want: 6 })
        ));
        let exc = with_crc(vec![1, 0x82, 2]);
        assert_eq!(req.expected_len(&exc), Some(5));
        assert_eq!(decode_response(1, &req, &exc), Err(FrameError::Exception(2)));
        assert_eq!(
            FrameError::Exception(2).to_string(),
            "exception 2 (illegal data address)"
        );
        let w = Request::WriteSingleCoil { addr: 3, value: true };
        assert_eq!(decode_response(1, &w, &w.encode(1)), Ok(Response::Written));
        let other = Request::WriteSingleCoil { addr: 4, value: true }.encode(1);
        assert!(matches!(decode_response(1, &w, &other), Err(FrameError::Malformed(_))));
        let regs = Request::ReadInputRegisters { addr: 0, qty: 2 };
        let wrong_count = with_crc(vec![1, 4, 3, 0, 1, 0, 2]);
        assert!(matches!(
            decode_response(1, &regs, &wrong_count),
            Err(FrameError::Malformed(_))
        ));
    }

    fn request() -> impl Strategy<Value = Request> {
        prop_oneof![
            (any::<u16>(), 1u16..=2000).prop_map(|(addr, qty)| Request::ReadCoils { addr, qty }),
            (any::<u16>(), 1u16..=2000).prop_map(|(addr, qty)| Request::ReadDiscreteInputs { addr, qty }),
            (any::<u16>(), 1u16..=125).prop_map(|(addr, qty)| Request::ReadHoldingRegisters { addr, qty }),
            (any::<u16>(), 1u16..=125).prop_map(|(addr, qty)| Request::ReadInputRegisters { addr, qty }),
            (any::<u16>(), any::<bool>()).prop_map(|(addr, value)| Request::WriteSingleCoil { addr, value }),
            (any::<u16>(), any::<u16>()).prop_map(|(addr, value)| Request::WriteSingleRegister { addr, value }),
            (any::<u16>(), prop::collection::vec(any::<bool>(), 1..100))
                .prop_map(|(addr, values)| Request::WriteMultipleCoils { addr, values }),
            (any::<u16>(), prop::collection::vec(any::<u16>(), 1..60))
                .prop_map(|(addr, values)| Request::WriteMultipleRegisters { addr, values }),
        ]
    }

    proptest! {
        /// Whatever bytes arrive, the decoder answers without panicking, and
        /// accepts a frame only when its CRC is right.
        #[test]
        fn decoder_never_panics(req in request(), bytes in prop::collection::vec(any::<u8>(), 0..300), slave in any::<u8>()) {
            if decode_response(slave, &req, &bytes).is_ok() {
                let n = bytes.len();
                prop_assert_eq!(crc16(&bytes[..n - 2]).to_le_bytes(), [bytes[n - 2], bytes[n - 1]]);
            }
            let _ = req.expected_len(&bytes);
        }

        /// A correct answer decodes to what was sent; any single corrupted
        /// byte or any truncation is refused.
        #[test]
        fn answers_round_trip(req in request(), seed in any::<u64>(), flip in any::<(usize, u8)>(), cut in any::<usize>()) {
            let (bits, regs): (Vec<bool>, Vec<u16>) = match &req {
                Request::ReadCoils { qty, .. } | Request::ReadDiscreteInputs { qty, .. } =>
                    ((0..*qty).map(|i| (seed >> (i % 64)) & 1 == 1).collect(), vec![]),
                Request::ReadHoldingRegisters { qty, .. } | Request::ReadInputRegisters { qty, .. } =>
                    (vec![], (0..*qty).map(|i| (seed as u16).wrapping_mul(i + 1)).collect()),
                _ => (vec![], vec![]),
            };
            let f = encode_response(7, &req, &bits, &regs);
            prop_assert_eq!(f.len(), req.response_len());
            let expect = match &req {
                Request::ReadCoils { .. } | Request::ReadDiscreteInputs { .. } => Response::Bits(bits),
                Request::ReadHoldingRegisters { .. } | Request::ReadInputRegisters { .. } => Response::Registers(regs),
                _ => Response::Written,
            };
            prop_assert_eq!(decode_response(7, &req, &f), Ok(expect));
            let mut g = f.clone();
            let (at, x) = (flip.0 % g.len(), flip.1.max(1));
            g[at] ^= x;
            prop_assert!(decode_response(7, &req, &g).is_err());
            let cut = cut % f.len();
            prop_assert!(decode_response(7, &req, &f[..cut]).is_err());
        }
    }
}
