//! The server's synchronous path without sockets or a runtime: a byte
//! stream in, replies out, over a fixed map and memory. The fuzz target
//! (`fuzz/fuzz_targets/modbus_frame.rs`) and the fuzz regression test run
//! it; it checks the invariants the server relies on.

use crate::handler::{Plan, Then, plan, read};
use crate::map::{Map, Scratch};
use crate::mbap::{self, Split};
use crate::pdu::{self, Exception};
use alba_ir::Memory;
use alba_project::config::ModbusArea;

/// Answers every complete request of `input` like the server does (writes
/// to program memory are planned, not applied). Returns the replies and
/// panics if an invariant breaks: a reply's length field matches its size,
/// replies repeat their request's transaction id and unit, a read returns
/// the byte count it announces.
pub fn answer_stream(input: &[u8], map: &Map, mem: &Memory, scratch: &Scratch) -> Vec<u8> {
    let mut out = Vec::new();
    let mut pos = 0;
    while let Split::Frame { header, pdu, len } = mbap::split(&input[pos..]) {
        assert!(len <= mbap::MAX_ADU && pos + len <= input.len());
        let fc = pdu[0];
        let at = mbap::begin(&mut out, header);
        out.push(fc);
        match answer(pdu, map, mem, scratch, &mut out) {
            Ok(()) => mbap::end(&mut out, at),
            Err(e) => mbap::exception(&mut out, at, header, fc, e),
        }
        let reply = &out[at..];
        assert_eq!(usize::from(u16::from_be_bytes([reply[4], reply[5]])), reply.len() - 6);
        assert_eq!(&reply[..2], &header.transaction.to_be_bytes());
        assert_eq!(reply[6], header.unit);
        assert!(reply.len() <= mbap::MAX_ADU, "reply of {} bytes", reply.len());
        pos += len;
    }
    out
}

fn answer(pdu: &[u8], map: &Map, mem: &Memory, sc: &Scratch, out: &mut Vec<u8>) -> Result<(), Exception> {
    let at = out.len();
    let Plan::Write { writes, then } = plan(pdu::parse(pdu)?, map, mem, sc, out)? else {
        // A read: its byte count is what follows it.
        assert_eq!(usize::from(out[at]), out.len() - at - 1, "a read's byte count");
        return Ok(());
    };
    for w in &writes {
        sc.apply(w);
    }
    match then {
        Then::Echo(echo) => {
            assert_eq!(echo, pdu[1..5], "a write echoes its request");
            out.extend_from_slice(&echo);
            Ok(())
        }
        Then::ReadRegs { start, count } => read(map, mem, sc, ModbusArea::HoldingRegister, start, count, out),
    }
}

/// A map with a bit of everything, for the fuzz target and its regressions:
/// I/O of every kind, markers, and explicit entries of every width.
pub fn sample() -> (Map, Memory) {
    use alba_diag::{Files, Span};
    use alba_model::TagTable;
    use alba_project::config::ModbusTag;
    let csv = "name,type,address\nI,BOOL,%IX1.3\nQ,BOOL,%QX2.1\nAi,INT,%IW5\nAo,DINT,%QW3\nW,INT,%MW10\nR,REAL,%MD7\n\
B,SINT,MB41\nX,BOOL,%MX50.1\nD,DINT,\nF,REAL,\nL,LINT,\nLr,LREAL,\nS,SINT,\nT,TIME,\nFlag,BOOL,\nTm,TIMER,\n";
    let mut files = Files::new();
    let f = files.add("tags.csv", csv);
    let (tags, _) = TagTable::parse(csv, f);
    let layout = alba_ir::Layout::new(&tags, &Default::default());
    let span = Span::new(f, 0..0);
    let tag = |name: &str, area, start| ModbusTag {
        name: name.into(),
        name_span: span,
        area,
        start,
        span,
    };
    let entries = [
        tag("D", ModbusArea::HoldingRegister, 8192),
        tag("F", ModbusArea::HoldingRegister, 8194),
        tag("L", ModbusArea::HoldingRegister, 8200),
        tag("Lr", ModbusArea::HoldingRegister, 8204),
        tag("S", ModbusArea::HoldingRegister, 65535),
        tag("T", ModbusArea::InputRegister, 1024),
        tag("Tm.PRE", ModbusArea::HoldingRegister, 9000),
        tag("Tm.DN", ModbusArea::DiscreteInput, 8192),
        tag("Flag", ModbusArea::Coil, 65535),
        tag("S:SCANMAX", ModbusArea::InputRegister, 65534),
    ];
    let (map, diags) = Map::build(&layout, &entries);
    assert!(diags.is_empty(), "{diags:?}");
    let mut mem = Memory::new(layout.counts, layout.marker_bytes);
    for (k, b) in mem.m.iter_mut().enumerate() {
        *b = k as u8;
    }
    for (k, v) in mem.i.iter_mut().enumerate() {
        *v = (k as i32) * -7919;
    }
    (map, mem)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sample_answers_a_mixed_stream() {
        let (map, mem) = sample();
        let sc = Scratch::default();
        let mut input = Vec::new();
        for (transaction, pdu) in [
            (1u16, &[3u8, 0x20, 0x00, 0, 2][..]),
            (2, &[3, 0xFF, 0xFF, 0, 1]),
            (3, &[4, 0xFF, 0xFE, 0, 2]),
            (4, &[16, 0x23, 0x28, 0, 2, 4, 0, 0, 0, 9]),
            (5, &[1, 0xFF, 0xFF, 0, 1]),
            (6, &[99]),
        ] {
            input.extend(mbap::adu(mbap::Header { transaction, unit: 1 }, pdu));
        }
        let out = answer_stream(&input, &map, &mem, &sc);
        // Six replies, the last an illegal function.
        assert_eq!(&out[out.len() - 9..], &[0, 6, 0, 0, 0, 3, 1, 0xE3, 1]);
    }
}
