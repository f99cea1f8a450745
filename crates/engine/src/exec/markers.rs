//! Marker bytes (`MB`, `MW`, `MD`) moved to and from typed slots.

use super::arith::fix_f32;
use crate::fault::FaultCode;
use crate::mem::{Mem, rd, wr};
use alba_ir::MarkerSlot;

fn marker_width(slot: MarkerSlot) -> usize {
    match slot {
        MarkerSlot::Byte(_) => 1,
        MarkerSlot::Word(_) => 2,
        MarkerSlot::DWord(_) | MarkerSlot::Real(_) => 4,
    }
}

/// Loads a marker value into a slot. A REAL whose bits are NaN or ±∞ (MW
/// writes can make any bit pattern) is cleaned like any REAL result.
pub(super) fn load_marker(m: &mut Mem, at: usize, slot: MarkerSlot) -> Option<FaultCode> {
    let mut buf = [0u8; 4];
    let n = marker_width(slot);
    if let Some(src) = m.m.get(at..at + n) {
        buf[..n].copy_from_slice(src);
    }
    match slot {
        MarkerSlot::Byte(i) => wr!(m.i, i.0, buf[0] as i8 as i32),
        MarkerSlot::Word(i) => wr!(m.i, i.0, i16::from_be_bytes([buf[0], buf[1]]) as i32),
        MarkerSlot::DWord(i) => wr!(m.i, i.0, i32::from_be_bytes(buf)),
        MarkerSlot::Real(f) => {
            let (v, fault) = fix_f32(f32::from_be_bytes(buf), false);
            wr!(m.f, f.0, v);
            return fault;
        }
    }
    None
}

pub(super) fn store_marker(m: &mut Mem, at: usize, slot: MarkerSlot) {
    let bytes: [u8; 4] = match slot {
        MarkerSlot::Byte(i) => [rd!(m.i, i.0) as u8, 0, 0, 0],
        MarkerSlot::Word(i) => {
            let w = (rd!(m.i, i.0) as i16).to_be_bytes();
            [w[0], w[1], 0, 0]
        }
        MarkerSlot::DWord(i) => rd!(m.i, i.0).to_be_bytes(),
        MarkerSlot::Real(f) => rd!(m.f, f.0).to_be_bytes(),
    };
    let n = marker_width(slot);
    if let Some(dst) = m.m.get_mut(at..at + n) {
        dst.copy_from_slice(&bytes[..n]);
    }
}
