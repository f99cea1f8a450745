//! Modbus TCP framing: the MBAP header (Messaging on TCP/IP v1.0b) around
//! a PDU of [`crate::pdu`].
//!
//! [`split`] cuts one ADU off the front of a receive buffer (several
//! requests may arrive in one TCP segment, and one may arrive in pieces);
//! [`begin`] and [`end`] frame what is written between them; [`exception`]
//! replaces a reply under construction by an exception reply.

use crate::pdu::{self, Exception, MAX_PDU, Request};

/// Length of the MBAP header (transaction, protocol, length, unit).
pub const MBAP_LEN: usize = 7;
/// Largest ADU.
pub const MAX_ADU: usize = MBAP_LEN + MAX_PDU;

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

/// The length of the ADU at the front of `buf` once its header says it
/// (`Ok(None)` before), or why `buf` is not Modbus TCP.
pub fn adu_len(buf: &[u8]) -> Result<Option<usize>, &'static str> {
    if buf.len() >= 4 && (buf[2], buf[3]) != (0, 0) {
        return Err("the protocol identifier is not 0 (not Modbus)");
    }
    if buf.len() < 6 {
        return Ok(None);
    }
    let len = usize::from(u16::from_be_bytes([buf[4], buf[5]]));
    if len < 2 {
        return Err("the length field is below 2 (a unit id and a function code)");
    }
    if len > 1 + MAX_PDU {
        return Err("the length field is above 254");
    }
    Ok(Some(6 + len))
}

/// Cuts the first ADU off `buf`.
pub fn split(buf: &[u8]) -> Split<'_> {
    match adu_len(buf) {
        Err(why) => Split::Invalid(why),
        Ok(Some(total)) if buf.len() >= total => Split::Frame {
            header: Header {
                transaction: u16::from_be_bytes([buf[0], buf[1]]),
                unit: buf[6],
            },
            pdu: &buf[MBAP_LEN..total],
            len: total,
        },
        Ok(_) => Split::Incomplete,
    }
}

/// Starts an ADU in `out`: the MBAP header with a length to be set by
/// [`end`]. Returns where the ADU starts.
pub fn begin(out: &mut Vec<u8>, h: Header) -> usize {
    let at = out.len();
    let t = h.transaction.to_be_bytes();
    out.extend_from_slice(&[t[0], t[1], 0, 0, 0, 0, h.unit]);
    at
}

/// Sets the length field of the ADU started at `at`.
pub fn end(out: &mut [u8], at: usize) {
    let len = (out.len() - at - 6) as u16;
    out[at + 4..at + 6].copy_from_slice(&len.to_be_bytes());
}

/// Replaces whatever follows `at` by an exception reply.
pub fn exception(out: &mut Vec<u8>, at: usize, h: Header, fc: u8, e: Exception) {
    out.truncate(at);
    begin(out, h);
    pdu::exception(out, fc, e);
    end(out, at);
}

/// The ADU of a PDU.
pub fn adu(h: Header, pdu: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(MBAP_LEN + pdu.len());
    let at = begin(&mut out, h);
    out.extend_from_slice(pdu);
    end(&mut out, at);
    out
}

/// The ADU of a request (a master's side).
pub fn request(h: Header, req: &Request<'_>) -> Vec<u8> {
    let mut out = Vec::with_capacity(MBAP_LEN + 8);
    let at = begin(&mut out, h);
    req.encode(&mut out);
    end(&mut out, at);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adu_of(transaction: u16, unit: u8, pdu: &[u8]) -> Vec<u8> {
        adu(Header { transaction, unit }, pdu)
    }

    #[test]
    fn split_finds_pipelined_and_partial_frames() {
        let mut buf = adu_of(1, 1, &[3, 0, 0, 0, 10]);
        assert_eq!(buf, [0, 1, 0, 0, 0, 6, 1, 3, 0, 0, 0, 10]);
        buf.extend(adu_of(2, 1, &[1, 0, 5, 0, 1]));
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
        let big = adu_of(9, 0, &[0x10; MAX_PDU]);
        assert!(matches!(split(&big), Split::Frame { len: MAX_ADU, .. }));
    }

    #[test]
    fn replies_have_their_length() {
        let h = Header {
            transaction: 0x0102,
            unit: 7,
        };
        let mut out = vec![9, 9];
        let at = begin(&mut out, h);
        out.extend_from_slice(&[3, 2, 0xAB, 0xCD]);
        end(&mut out, at);
        assert_eq!(out, [9, 9, 1, 2, 0, 0, 0, 5, 7, 3, 2, 0xAB, 0xCD]);
        exception(&mut out, at, h, 3, Exception::IllegalDataAddress);
        assert_eq!(out, [9, 9, 1, 2, 0, 0, 0, 3, 7, 0x83, 2]);
        let r = request(h, &Request::ReadCoils { start: 5, count: 1 });
        assert_eq!(r, [1, 2, 0, 0, 0, 6, 7, 1, 0, 5, 0, 1]);
    }
}
