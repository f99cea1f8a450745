//! Modbus RTU framing (serial lines): `slave, PDU…, crc_lo, crc_hi`, the
//! PDU of [`crate::pdu`] with a CRC-16.
//!
//! A master knows from its request how long the answer must be
//! ([`response_len`]), so it does not depend on the 3.5-character silence
//! to find the end of a response; [`decode_response`] checks everything
//! else (CRC, slave id, function, lengths, exception replies) and never
//! panics on any input.

use crate::pdu::{self, FrameError, Request, Response};

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

/// The frame of `req` for `slave`, CRC included.
pub fn encode(slave: u8, req: &Request<'_>) -> Vec<u8> {
    let mut f = vec![slave];
    req.encode(&mut f);
    with_crc(f)
}

/// Length of a normal answer to `req`, CRC included.
pub fn response_len(req: &Request<'_>) -> usize {
    req.reply_len() + 3
}

/// How many bytes the answer to `req` that starts with `head` has in all:
/// an exception is 5 bytes, anything else [`response_len`]. `None` until
/// the function byte has arrived.
pub fn expected_len(req: &Request<'_>, head: &[u8]) -> Option<usize> {
    let fc = *head.get(1)?;
    Some(if fc & 0x80 != 0 { 5 } else { response_len(req) })
}

/// Checks the CRC of `frame`: its slave id and PDU.
pub fn check(frame: &[u8]) -> Result<(u8, &[u8]), FrameError> {
    if frame.len() < 4 {
        return Err(FrameError::Truncated {
            got: frame.len(),
            want: 4,
        });
    }
    let (body, crc) = frame.split_at(frame.len() - 2);
    let got = u16::from_le_bytes([crc[0], crc[1]]);
    let want = crc16(body);
    if got != want {
        return Err(FrameError::BadCrc { got, want });
    }
    Ok((body[0], &body[1..]))
}

/// Checks and decodes the answer `frame` of `slave` to `req`.
pub fn decode_response(slave: u8, req: &Request<'_>, frame: &[u8]) -> Result<Response, FrameError> {
    if frame.len() < 5 {
        return Err(FrameError::Truncated {
            got: frame.len(),
            want: expected_len(req, frame).unwrap_or(5),
        });
    }
    let (from, pdu) = check(frame)?;
    if from != slave {
        return Err(FrameError::WrongSlave(from));
    }
    if pdu[0] == req.function() && frame.len() != response_len(req) {
        return Err(FrameError::Malformed(format!(
            "{} bytes, expected {}",
            frame.len(),
            response_len(req)
        )));
    }
    if pdu[0] == req.function() | 0x80 && frame.len() != 5 {
        return Err(FrameError::Malformed(format!(
            "exception reply of {} bytes",
            frame.len()
        )));
    }
    pdu::decode_reply(req, pdu)
}

/// The slave's side, for tests and fakes: the answer to `req` with the
/// given bits or registers (ignored for writes).
pub fn encode_response(slave: u8, req: &Request<'_>, bits: &[bool], regs: &[u16]) -> Vec<u8> {
    let mut f = vec![slave];
    pdu::encode_reply(req, bits, regs, &mut f);
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
            encode(1, &Request::ReadHoldingRegisters { start: 0, count: 1 }),
            [0x01, 0x03, 0x00, 0x00, 0x00, 0x01, 0x84, 0x0A]
        );
        // Modbus spec example: slave 0x11, read coils 0x13 x 0x25 → CRC 0E84.
        assert_eq!(
            encode(
                0x11,
                &Request::ReadCoils {
                    start: 0x13,
                    count: 0x25
                }
            ),
            [0x11, 0x01, 0x00, 0x13, 0x00, 0x25, 0x0E, 0x84]
        );
        assert_eq!(crc16(b"123456789"), 0x4B37);
    }

    #[test]
    fn multiple_writes_are_framed() {
        let r = Request::write_coils(0x13, &[true, false, true, true, false, false, true, true, true, false]);
        let f = encode(0x11, &r);
        assert_eq!(&f[..9], [0x11, 0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01]);
        let r = Request::write_registers(1, &[0x000A, 0x0102]);
        assert_eq!(&encode(0x11, &r)[..11], [0x11, 0x10, 0, 1, 0, 2, 4, 0, 0x0A, 1, 2]);
    }

    #[test]
    fn answers_are_checked() {
        let req = Request::ReadDiscreteInputs { start: 0, count: 6 };
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
        assert_eq!(expected_len(&req, &exc), Some(5));
        assert_eq!(decode_response(1, &req, &exc), Err(FrameError::Exception(2)));
        assert_eq!(
            FrameError::Exception(2).to_string(),
            "exception 2 (illegal data address)"
        );
        let w = Request::WriteSingleCoil { addr: 3, value: true };
        assert_eq!(decode_response(1, &w, &encode(1, &w)), Ok(Response::Written));
        let other = encode(1, &Request::WriteSingleCoil { addr: 4, value: true });
        assert!(matches!(decode_response(1, &w, &other), Err(FrameError::Malformed(_))));
        let regs = Request::ReadInputRegisters { start: 0, count: 2 };
        let wrong_count = with_crc(vec![1, 4, 3, 0, 1, 0, 2]);
        assert!(matches!(
            decode_response(1, &regs, &wrong_count),
            Err(FrameError::Malformed(_))
        ));
        assert_eq!(check(&encode(9, &w)), Ok((9, &[5u8, 0, 3, 0xFF, 0][..])));
    }

    fn request() -> impl Strategy<Value = Request<'static>> {
        prop_oneof![
            (any::<u16>(), 1u16..=2000).prop_map(|(start, count)| Request::ReadCoils { start, count }),
            (any::<u16>(), 1u16..=2000).prop_map(|(start, count)| Request::ReadDiscreteInputs { start, count }),
            (any::<u16>(), 1u16..=125).prop_map(|(start, count)| Request::ReadHoldingRegisters { start, count }),
            (any::<u16>(), 1u16..=125).prop_map(|(start, count)| Request::ReadInputRegisters { start, count }),
            (any::<u16>(), any::<bool>()).prop_map(|(addr, value)| Request::WriteSingleCoil { addr, value }),
            (any::<u16>(), any::<u16>()).prop_map(|(addr, value)| Request::WriteSingleRegister { addr, value }),
            (any::<u16>(), prop::collection::vec(any::<bool>(), 1..100))
                .prop_map(|(addr, values)| Request::write_coils(addr, &values)),
            (any::<u16>(), prop::collection::vec(any::<u16>(), 1..60))
                .prop_map(|(addr, values)| Request::write_registers(addr, &values)),
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
            let _ = expected_len(&req, &bytes);
            let _ = check(&bytes);
        }

        /// A correct answer decodes to what was sent; any single corrupted
        /// byte or any truncation is refused.
        #[test]
        fn answers_round_trip(req in request(), seed in any::<u64>(), flip in any::<(usize, u8)>(), cut in any::<usize>()) {
            let (bits, regs): (Vec<bool>, Vec<u16>) = match &req {
                Request::ReadCoils { count, .. } | Request::ReadDiscreteInputs { count, .. } =>
                    ((0..*count).map(|i| (seed >> (i % 64)) & 1 == 1).collect(), vec![]),
                Request::ReadHoldingRegisters { count, .. } | Request::ReadInputRegisters { count, .. } =>
                    (vec![], (0..*count).map(|i| (seed as u16).wrapping_mul(i + 1)).collect()),
                _ => (vec![], vec![]),
            };
            let f = encode_response(7, &req, &bits, &regs);
            prop_assert_eq!(f.len(), response_len(&req));
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
