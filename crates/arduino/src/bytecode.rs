//! Byte code (issue 19, SPEC §7.4): the IR of a control program serialised
//! for an interpreter on an 8-bit board, so that a new program is a download
//! and not a reflash. The format is documented byte by byte in
//! docs/bytecode.md; in short, little-endian throughout:
//!
//! * a 24-byte header: magic `ALBC`, format version, operand widths, the
//!   board id (the board model, pin map and output polarity the program was
//!   compiled for), the program id (the sketch's: program, layout and pin
//!   map), the scan period, the body's length and its CRC-32;
//! * the body: the memory sizes, the I/O regions, the system slots, the
//!   non-zero initial values, the wiring (pin of each I/O channel), then the
//!   ops — a 1-byte opcode, a sub-op byte where the op has one, and slot
//!   numbers of 1 byte when the area has at most 256 slots (2 otherwise);
//!   jumps are relative byte offsets.
//!
//! [`decode`] is the reference decoder: it checks everything (magic,
//! version, CRC, bounds, every slot against the sizes, jumps onto rung
//! starts) and rebuilds a [`Program`] that the engine runs — the host's
//! byte-code interpreter is the engine itself on the decoded program, so the
//! semantics stay in one place and every byte-code consumer is tested
//! against it. [`decode_for`] adds what one board's interpreter checks (its
//! board id, its memory, its pin map, the ops it has): the firmware refuses
//! exactly what `decode_for` refuses.

use crate::sketch::{self, Target, Wire};
use alba_diag::{Code, Diagnostic};
use alba_ir::layout::{Counts, Region, System};
use alba_ir::op::{MarkerSlot, S7Ctr, S7Tmr};
use alba_ir::{
    B, BinOp, Cmp, Ctr, Cvt, D, F, I, L, Layout, Loc, Memory, Op, Pidt, Program, TimeBase, Tmr, UnOp, Width,
};
use alba_model::address::Address;
use alba_model::board::{Model, Pin};

pub const MAGIC: [u8; 4] = *b"ALBC";
pub const VERSION: u8 = 3;
pub const HEADER_LEN: usize = 24;

/// A program as byte code, with what its header says.
#[derive(Debug, Clone, PartialEq)]
pub struct Bytecode {
    pub bytes: Vec<u8>,
    pub program_id: u32,
    /// Bytes of ops (the rest is header, memory description and initial values).
    pub code_len: usize,
    pub ops: usize,
}

/// What [`decode`] found: the program the engine runs, and the board's wiring.
#[derive(Debug, Clone)]
pub struct Decoded {
    pub program: Program,
    pub board_id: u16,
    pub program_id: u32,
    pub scan_ms: u16,
    pub wiring: Vec<(Address, u8, u32)>,
}

/// Why byte code was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    #[error("not Alba byte code (magic {0:02x?})")]
    Magic([u8; 4]),
    #[error("byte code format {0}; this version reads {VERSION}")]
    Version(u8),
    #[error("truncated: {0}")]
    Truncated(&'static str),
    #[error("the body's CRC-32 is {found:08x}, the header says {want:08x}")]
    Crc { want: u32, found: u32 },
    #[error("at byte {at}: {what}")]
    Bad { at: usize, what: String },
    /// Well formed, but not for this board's interpreter.
    #[error("{0}")]
    Board(String),
}

// Opcodes. One byte each; the order is the format's (never renumber).
const RUNG: u8 = 0x01;
const NOP: u8 = 0x02;
const AFI: u8 = 0x03;
const XIC: u8 = 0x04;
const XIO: u8 = 0x05;
const OTE: u8 = 0x06;
const OTL: u8 = 0x07;
const OTU: u8 = 0x08;
const ONS: u8 = 0x09;
const OSR: u8 = 0x0a;
const OSF: u8 = 0x0b;
const BR_OPEN: u8 = 0x0c;
const BR_NEXT: u8 = 0x0d;
const BR_CLOSE: u8 = 0x0e;
const JMP: u8 = 0x0f;
const TON: u8 = 0x10;
const TOF: u8 = 0x11;
const RTO: u8 = 0x12;
const TP: u8 = 0x13;
const CTU: u8 = 0x14;
const CTD: u8 = 0x15;
const RES_T: u8 = 0x16;
const RES_C: u8 = 0x17;
const CMP_I: u8 = 0x18;
const CMP_F: u8 = 0x19;
const CMP_L: u8 = 0x1a;
const CMP_D: u8 = 0x1b;
const LIM_I: u8 = 0x1c;
const LIM_F: u8 = 0x1d;
const LIM_L: u8 = 0x1e;
const LIM_D: u8 = 0x1f;
const MEQ_I: u8 = 0x20;
const MEQ_L: u8 = 0x21;
const BIN_I: u8 = 0x22;
const BIN_F: u8 = 0x23;
const BIN_L: u8 = 0x24;
const BIN_D: u8 = 0x25;
const UN_I: u8 = 0x26;
const UN_F: u8 = 0x27;
const UN_L: u8 = 0x28;
const UN_D: u8 = 0x29;
const CVT: u8 = 0x2a;
const NARROW: u8 = 0x2b;
const COPY_I: u8 = 0x2c;
const LD_BIT: u8 = 0x2d;
const ST_BIT: u8 = 0x2e;
const LD_M: u8 = 0x2f;
const ST_M: u8 = 0x30;
const LD: u8 = 0x31;
const LDN: u8 = 0x32;
const OR: u8 = 0x33;
const ORN: u8 = 0x34;
const NOT: u8 = 0x35;
const TRUE: u8 = 0x36;
const ED: u8 = 0x37;
const COPY_B: u8 = 0x38;
const S7_TON: u8 = 0x39;
const S7_TONR: u8 = 0x3a;
const S7_TOF: u8 = 0x3b;
const S7_RES_T: u8 = 0x3c;
const S7_CTU: u8 = 0x3d;
const S7_CTD: u8 = 0x3e;
const S7_CTUD: u8 = 0x3f;
const S7_RES_C: u8 = 0x40;
const PID: u8 = 0x41;

pub(crate) const CMPS: [Cmp; 6] = [Cmp::Eq, Cmp::Ne, Cmp::Lt, Cmp::Gt, Cmp::Le, Cmp::Ge];
pub(crate) const BINS: [BinOp; 10] = [
    BinOp::Add,
    BinOp::Sub,
    BinOp::Mul,
    BinOp::Div,
    BinOp::Mod,
    BinOp::Pow,
    BinOp::Atan2,
    BinOp::And,
    BinOp::Or,
    BinOp::Xor,
];
pub(crate) const UNS: [UnOp; 19] = [
    UnOp::Mov,
    UnOp::Neg,
    UnOp::Abs,
    UnOp::Not,
    UnOp::Frd,
    UnOp::Tod,
    UnOp::Sqrt,
    UnOp::Ln,
    UnOp::Log,
    UnOp::Sin,
    UnOp::Cos,
    UnOp::Tan,
    UnOp::Asin,
    UnOp::Acos,
    UnOp::Atan,
    UnOp::Deg,
    UnOp::Rad,
    UnOp::Trunc,
    UnOp::Round,
];

fn bin_code(op: BinOp) -> u8 {
    match op {
        // A compare as a math op (CPT's `=`, `<` …): 0x10 + the compare.
        BinOp::Cmp(c) => 0x10 + cmp_code(c),
        op => BINS.iter().position(|b| *b == op).unwrap_or(0) as u8,
    }
}

fn cmp_code(c: Cmp) -> u8 {
    CMPS.iter().position(|x| *x == c).unwrap_or(0) as u8
}

/// Operand widths: 1 byte per slot number when the area has at most 256
/// slots, else 2 (flag bit set). Areas: b, i, f, l, d, markers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Widths(u8);

impl Widths {
    fn of(c: &Counts, marker_bytes: u32) -> Widths {
        let sizes = [c.b, c.i, c.f, c.l, c.d, marker_bytes];
        Widths(
            sizes
                .iter()
                .enumerate()
                .fold(0, |w, (k, n)| if *n > 256 { w | 1 << k } else { w }),
        )
    }
    fn wide(self, area: usize) -> bool {
        self.0 & (1 << area) != 0
    }
}

const AREA_B: usize = 0;
const AREA_I: usize = 1;
const AREA_F: usize = 2;
const AREA_L: usize = 3;
const AREA_D: usize = 4;
const AREA_M: usize = 5;

struct Writer {
    out: Vec<u8>,
    w: Widths,
}

impl Writer {
    fn u8(&mut self, v: u8) {
        self.out.push(v);
    }
    fn u16(&mut self, v: u16) {
        self.out.extend(v.to_le_bytes());
    }
    fn u32(&mut self, v: u32) {
        self.out.extend(v.to_le_bytes());
    }
    fn slot(&mut self, area: usize, v: u32) {
        if self.w.wide(area) {
            self.u16(v as u16);
        } else {
            self.u8(v as u8);
        }
    }
}

/// Encodes the control program of `prog` for `t`'s board, or says why it
/// cannot run there (the sketch export's refusals, located, and the
/// format's own limits).
pub fn encode(prog: &Program, project: &str, t: &Target) -> Result<Bytecode, Vec<Diagnostic>> {
    // What the board cannot run, and the wiring and id, as the export decides them.
    let s = sketch::generate(prog, project, t)?;
    let p = sketch::control_program(prog);
    // And what the board's interpreter cannot hold.
    if capacity(t.model).l == 0 {
        let lints: Vec<Diagnostic> = p
            .layout
            .tags
            .iter()
            .filter(|tag| tag.ty == alba_model::DataType::Lint)
            .map(|tag| {
                Diagnostic::new(
                    Code::NotOnBoard,
                    format!(
                        "`{}` is a LINT: the byte-code interpreter on the {} holds no 64-bit integers (the Mega's does, and so does the compiled sketch)",
                        tag.name,
                        t.model.title()
                    ),
                    tag.span,
                    "LINT",
                )
            })
            .collect();
        if !lints.is_empty() {
            return Err(lints);
        }
    }
    let bc = encode_program(&p, t.scan_ms, board_id(t), s.program_id, &s.wiring)
        .map_err(|m| vec![Diagnostic::unplaced(Code::NotOnBoard, m)])?;
    let room = slot_size(t.model);
    if bc.bytes.len() > room {
        return Err(vec![Diagnostic::unplaced(
            Code::NotOnBoard,
            format!(
                "the byte code is {} bytes; the interpreter on the {} holds {room} (half its EEPROM: a download never overwrites the running program): use the Mega, or the compiled sketch (alba export arduino)",
                bc.bytes.len(),
                t.model.title()
            ),
        )]);
    }
    // What the board's interpreter would refuse (its memory, its ops) is refused here.
    decode_for(&bc.bytes, t).map_err(|e| {
        vec![
            Diagnostic::unplaced(
                Code::NotOnBoard,
                format!(
                    "the interpreter on the {} cannot run this program: {e}",
                    t.model.title()
                ),
            )
            .with_help("use the Mega, or the compiled sketch (alba export arduino)"),
        ]
    })?;
    Ok(bc)
}

/// The board id of header bytes 6-7: a hash of what an interpreter firmware
/// is built for — the board model, the pin map and the output polarity. A
/// board refuses byte code with another id (it was compiled for other pins).
pub fn board_id(t: &Target) -> u16 {
    let m = &t.map;
    let h = sketch::fnv1a(
        format!(
            "{}|{:?}|{:?}|{:?}|{:?}|{}",
            t.model.name(),
            m.di,
            m.r#do,
            m.ai,
            m.ao,
            t.active_low
        )
        .as_bytes(),
    );
    (h >> 16) as u16 ^ h as u16
}

/// Channels of each kind an interpreter wires (it keeps a wire's channel in 6 bits).
pub const MAX_CHANNELS: u32 = 64;

/// The pin byte of channel `ch` of wiring kind `kind` (0 DI, 1 DO, 2 AI,
/// 3 AO) on `t`'s board, or `None` when the pin map wires no usable pin there
/// (or the channel is past [`MAX_CHANNELS`]).
pub(crate) fn map_pin(t: &Target, kind: u8, ch: u32) -> Option<u8> {
    if ch >= MAX_CHANNELS {
        return None;
    }
    let address = match kind {
        0 => Address::DigitalIn(ch),
        1 => Address::DigitalOut(ch),
        2 => Address::AnalogIn(ch),
        3 => Address::AnalogOut(ch),
        _ => return None,
    };
    match t.map.pin_of(t.model, address) {
        Some(Ok(p)) => Some(pin_number(p)),
        _ => None,
    }
}

/// Encodes `p` as it is (its plant models too, if any): the host's form,
/// and the part of [`encode`] after the board's checks.
pub fn encode_program(
    p: &Program,
    scan_ms: u32,
    board_id: u16,
    program_id: u32,
    wiring: &[Wire],
) -> Result<Bytecode, String> {
    let lay = &p.layout;
    let c = lay.counts;
    let limit = |what: &str, n: u32| {
        if n > u32::from(u16::MAX) {
            Err(format!("{n} {what}: byte code holds at most 65 535"))
        } else {
            Ok(())
        }
    };
    for (what, n) in [
        ("bool slots", c.b),
        ("integer slots", c.i),
        ("REAL slots", c.f),
        ("LINT slots", c.l),
        ("LREAL slots", c.d),
        ("marker bytes", lay.marker_bytes),
    ] {
        limit(what, n)?;
    }
    let scan_ms = u16::try_from(scan_ms).map_err(|_| format!("scan period {scan_ms} ms: at most 65 535"))?;
    let w = Widths::of(&c, lay.marker_bytes);
    let mut body = Writer { out: Vec::new(), w };
    // Memory sizes and I/O regions.
    for n in [c.b, c.i, c.f, c.l, c.d, lay.marker_bytes] {
        body.u16(n as u16);
    }
    for r in [lay.di, lay.dout, lay.ai, lay.ao] {
        body.u16(r.base as u16);
        body.u16(r.len as u16);
    }
    // System slots, in the order of `System`'s fields.
    let s = lay.system;
    for b in [
        s.first_scan,
        s.minor_fault,
        s.always_on,
        s.clock_60s,
        s.clock_1s,
        s.scan_toggle,
        s.io_ok,
        s.retain_lost,
        s.store_ok,
    ] {
        body.u16(b.0 as u16);
    }
    for i in [s.fault_code, s.scan_time, s.stats, s.io_errors] {
        body.u16(i.0 as u16);
    }
    // Initial values that are not zero: (area, slot, value) runs per area.
    let init = &p.init;
    let trues: Vec<u32> = (0..init.b.len() as u32).filter(|k| init.b[*k as usize]).collect();
    body.u16(trues.len() as u16);
    for k in trues {
        body.u16(k as u16);
    }
    let nz = |n: usize, zero: &dyn Fn(usize) -> bool| (0..n).filter(|k| !zero(*k)).collect::<Vec<_>>();
    let ints = nz(init.i.len(), &|k| init.i[k] == 0);
    body.u16(ints.len() as u16);
    for k in ints {
        body.u16(k as u16);
        body.u32(init.i[k] as u32);
    }
    let reals = nz(init.f.len(), &|k| init.f[k].to_bits() == 0);
    body.u16(reals.len() as u16);
    for k in reals {
        body.u16(k as u16);
        body.u32(init.f[k].to_bits());
    }
    let lints = nz(init.l.len(), &|k| init.l[k] == 0);
    body.u16(lints.len() as u16);
    for k in lints {
        body.u16(k as u16);
        body.out.extend(init.l[k].to_le_bytes());
    }
    let lreals = nz(init.d.len(), &|k| init.d[k].to_bits() == 0);
    body.u16(lreals.len() as u16);
    for k in lreals {
        body.u16(k as u16);
        body.out.extend(init.d[k].to_bits().to_le_bytes());
    }
    let marks = nz(init.m.len(), &|k| init.m[k] == 0);
    body.u16(marks.len() as u16);
    for k in marks {
        body.u16(k as u16);
        body.u8(init.m[k]);
    }
    // Wiring: kind (0 DI, 1 DO, 2 AI, 3 AO), channel, pin, slot.
    body.u16(wiring.len() as u16);
    for wire in wiring {
        let (kind, n) = match wire.address {
            Address::DigitalIn(n) => (0, n),
            Address::DigitalOut(n) => (1, n),
            Address::AnalogIn(n) => (2, n),
            Address::AnalogOut(n) => (3, n),
            Address::Marker { .. } => return Err("a marker cannot be wired".into()),
        };
        body.u8(kind);
        body.u16(n as u16);
        body.u8(pin_number(wire.pin));
        body.u16(wire.slot as u16);
    }
    // Ops: first their byte offsets (for relative jumps), then the bytes.
    body.u16(u16::try_from(p.ops.len()).map_err(|_| format!("{} ops: at most 65 535", p.ops.len()))?);
    let code_start = body.out.len();
    let mut sizes = Vec::with_capacity(p.ops.len());
    for op in &p.ops {
        let mut probe = Writer { out: Vec::new(), w };
        op_bytes(&mut probe, op, 0);
        sizes.push(probe.out.len());
    }
    let mut at = Vec::with_capacity(sizes.len() + 1);
    let mut sum = 0usize;
    for n in &sizes {
        at.push(sum);
        sum += n;
    }
    at.push(sum);
    for (pc, op) in p.ops.iter().enumerate() {
        let rel = match op {
            Op::Jmp(t) => {
                let to = *at.get(*t as usize).ok_or("a jump outside the program")? as i64;
                let from = at[pc + 1] as i64;
                i16::try_from(to - from).map_err(|_| "a jump farther than 32 KB".to_string())?
            }
            _ => 0,
        };
        op_bytes(&mut body, op, rel);
    }
    let code_len = body.out.len() - code_start;
    let mut bytes = Vec::with_capacity(HEADER_LEN + body.out.len());
    bytes.extend(MAGIC);
    bytes.push(VERSION);
    bytes.push(w.0);
    bytes.extend(board_id.to_le_bytes());
    bytes.extend(program_id.to_le_bytes());
    bytes.extend(scan_ms.to_le_bytes());
    bytes.extend([0, 0]);
    bytes.extend((body.out.len() as u32).to_le_bytes());
    bytes.extend(crc32fast::hash(&body.out).to_le_bytes());
    debug_assert_eq!(bytes.len(), HEADER_LEN);
    bytes.extend(body.out);
    Ok(Bytecode {
        bytes,
        program_id,
        code_len,
        ops: p.ops.len(),
    })
}

/// A pin in one byte: digital pin n as n, analog pin An as 0x80 + n.
fn pin_number(p: Pin) -> u8 {
    match p {
        Pin::D(n) => n,
        Pin::A(n) => 0x80 | n,
    }
}

/// One field of an encoded op after its opcode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Field {
    /// A slot number of an area (1 or 2 bytes by the area's width).
    Slot(usize, u32),
    Byte(u8),
    Word(u16),
}

/// An op as its opcode and fields, in the order they are written (`rel`: a
/// jump's offset from the next op). The one description of the encoding:
/// the writer and the interpreter's generator both read it.
pub(crate) fn fields(op: &Op, rel: i16) -> (u8, Vec<Field>) {
    use Field::{Byte, Slot, Word};
    let b = |x: B| Slot(AREA_B, x.0);
    let i = |x: I| Slot(AREA_I, x.0);
    let f = |x: F| Slot(AREA_F, x.0);
    let l = |x: L| Slot(AREA_L, x.0);
    let d = |x: D| Slot(AREA_D, x.0);
    let m = |x: u32| Slot(AREA_M, x);
    match *op {
        Op::Rung => (RUNG, vec![]),
        Op::Nop => (NOP, vec![]),
        Op::Afi => (AFI, vec![]),
        Op::Not => (NOT, vec![]),
        Op::True => (TRUE, vec![]),
        Op::Xic(x) => (XIC, vec![b(x)]),
        Op::Xio(x) => (XIO, vec![b(x)]),
        Op::Ote(x) => (OTE, vec![b(x)]),
        Op::Otl(x) => (OTL, vec![b(x)]),
        Op::Otu(x) => (OTU, vec![b(x)]),
        Op::Ons(x) => (ONS, vec![b(x)]),
        Op::Ld(x) => (LD, vec![b(x)]),
        Op::Ldn(x) => (LDN, vec![b(x)]),
        Op::Or(x) => (OR, vec![b(x)]),
        Op::Orn(x) => (ORN, vec![b(x)]),
        Op::Ed(x) => (ED, vec![b(x)]),
        Op::Osr(x, y) => (OSR, vec![b(x), b(y)]),
        Op::Osf(x, y) => (OSF, vec![b(x), b(y)]),
        Op::CopyB(x, y) => (COPY_B, vec![b(x), b(y)]),
        Op::BrOpen { save, acc } => (BR_OPEN, vec![b(save), b(acc)]),
        Op::BrNext { save, acc } => (BR_NEXT, vec![b(save), b(acc)]),
        Op::BrClose { acc } => (BR_CLOSE, vec![b(acc)]),
        Op::Jmp(_) => (JMP, vec![Word(rel as u16)]),
        Op::Ton(t, tb) => (TON, vec![Byte(tb.code()), i(t.i), b(t.b)]),
        Op::Tof(t, tb) => (TOF, vec![Byte(tb.code()), i(t.i), b(t.b)]),
        Op::Rto(t, tb) => (RTO, vec![Byte(tb.code()), i(t.i), b(t.b)]),
        Op::Tp(t) => (TP, vec![i(t.i), b(t.b)]),
        Op::ResT(t) => (RES_T, vec![i(t.i), b(t.b)]),
        Op::Ctu(c) => (CTU, vec![i(c.i), b(c.b)]),
        Op::Ctd(c) => (CTD, vec![i(c.i), b(c.b)]),
        Op::ResC(c) => (RES_C, vec![i(c.i), b(c.b)]),
        Op::CmpI(c, x, y) => (CMP_I, vec![Byte(cmp_code(c)), i(x), i(y)]),
        Op::CmpF(c, x, y) => (CMP_F, vec![Byte(cmp_code(c)), f(x), f(y)]),
        Op::CmpL(c, x, y) => (CMP_L, vec![Byte(cmp_code(c)), l(x), l(y)]),
        Op::CmpD(c, x, y) => (CMP_D, vec![Byte(cmp_code(c)), d(x), d(y)]),
        Op::LimI(x, y, z) => (LIM_I, vec![i(x), i(y), i(z)]),
        Op::LimF(x, y, z) => (LIM_F, vec![f(x), f(y), f(z)]),
        Op::LimL(x, y, z) => (LIM_L, vec![l(x), l(y), l(z)]),
        Op::LimD(x, y, z) => (LIM_D, vec![d(x), d(y), d(z)]),
        Op::MeqI(x, y, z) => (MEQ_I, vec![i(x), i(y), i(z)]),
        Op::MeqL(x, y, z) => (MEQ_L, vec![l(x), l(y), l(z)]),
        Op::BinI(o, x, y, z) => (BIN_I, vec![Byte(bin_code(o)), i(x), i(y), i(z)]),
        Op::BinF(o, x, y, z) => (BIN_F, vec![Byte(bin_code(o)), f(x), f(y), f(z)]),
        Op::BinL(o, x, y, z) => (BIN_L, vec![Byte(bin_code(o)), l(x), l(y), l(z)]),
        Op::BinD(o, x, y, z) => (BIN_D, vec![Byte(bin_code(o)), d(x), d(y), d(z)]),
        Op::UnI(o, x, y) => (UN_I, vec![Byte(un_code(o)), i(x), i(y)]),
        Op::UnF(o, x, y) => (UN_F, vec![Byte(un_code(o)), f(x), f(y)]),
        Op::UnL(o, x, y) => (UN_L, vec![Byte(un_code(o)), l(x), l(y)]),
        Op::UnD(o, x, y) => (UN_D, vec![Byte(un_code(o)), d(x), d(y)]),
        Op::Cvt(c) => (
            CVT,
            match c {
                Cvt::IF(x, y) => vec![Byte(0), i(x), f(y)],
                Cvt::FI(x, y) => vec![Byte(1), f(x), i(y)],
                Cvt::IL(x, y) => vec![Byte(2), i(x), l(y)],
                Cvt::LI(x, y) => vec![Byte(3), l(x), i(y)],
                Cvt::ID(x, y) => vec![Byte(4), i(x), d(y)],
                Cvt::DI(x, y) => vec![Byte(5), d(x), i(y)],
                Cvt::LF(x, y) => vec![Byte(6), l(x), f(y)],
                Cvt::FL(x, y) => vec![Byte(7), f(x), l(y)],
                Cvt::LD(x, y) => vec![Byte(8), l(x), d(y)],
                Cvt::DL(x, y) => vec![Byte(9), d(x), l(y)],
                Cvt::FD(x, y) => vec![Byte(10), f(x), d(y)],
                Cvt::DF(x, y) => vec![Byte(11), d(x), f(y)],
            },
        ),
        Op::Narrow(x, width) => (
            NARROW,
            vec![
                Byte(match width {
                    Width::W8 => 8,
                    Width::W16 => 16,
                }),
                i(x),
            ],
        ),
        Op::CopyI(x, y) => (COPY_I, vec![i(x), i(y)]),
        Op::LdBit { byte, bit, dst } => (LD_BIT, vec![m(byte), Byte(bit), b(dst)]),
        Op::StBit { src, byte, bit } => (ST_BIT, vec![m(byte), Byte(bit), b(src)]),
        Op::LdM { byte, slot } | Op::StM { byte, slot } => (
            if matches!(op, Op::LdM { .. }) { LD_M } else { ST_M },
            match slot {
                MarkerSlot::Byte(x) => vec![m(byte), Byte(1), i(x)],
                MarkerSlot::Word(x) => vec![m(byte), Byte(2), i(x)],
                MarkerSlot::DWord(x) => vec![m(byte), Byte(4), i(x)],
                MarkerSlot::Real(x) => vec![m(byte), Byte(0x84), f(x)],
            },
        ),
        Op::S7Ton(t) => (S7_TON, vec![i(t.i), b(t.b), Word(t.res)]),
        Op::S7Tonr(t) => (S7_TONR, vec![i(t.i), b(t.b), Word(t.res)]),
        Op::S7Tof(t) => (S7_TOF, vec![i(t.i), b(t.b), Word(t.res)]),
        Op::S7ResT(t) => (S7_RES_T, vec![i(t.i), b(t.b), Word(t.res)]),
        Op::S7Ctu(c) => (S7_CTU, vec![i(c.i), b(c.b)]),
        Op::S7Ctd(c) => (S7_CTD, vec![i(c.i), b(c.b)]),
        Op::S7Ctud(c) => (S7_CTUD, vec![i(c.i), b(c.b)]),
        Op::S7ResC(c) => (S7_RES_C, vec![i(c.i), b(c.b)]),
        Op::Pid(p) => (PID, vec![f(p.f), i(p.i), b(p.b)]),
    }
}

/// The bytes of one op (`rel`: a jump's offset from the next op).
fn op_bytes(w: &mut Writer, op: &Op, rel: i16) {
    let (code, fields) = fields(op, rel);
    w.u8(code);
    for f in fields {
        match f {
            Field::Slot(area, v) => w.slot(area, v),
            Field::Byte(v) => w.u8(v),
            Field::Word(v) => w.u16(v),
        }
    }
}

fn un_code(o: UnOp) -> u8 {
    UNS.iter().position(|u| *u == o).unwrap_or(0) as u8
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
    w: Widths,
    /// Where the body starts in the whole byte code (for messages).
    base: usize,
}

impl Reader<'_> {
    fn bad(&self, what: impl Into<String>) -> DecodeError {
        DecodeError::Bad {
            at: self.base + self.at,
            what: what.into(),
        }
    }
    fn take(&mut self, n: usize) -> Result<&[u8], DecodeError> {
        let s = self
            .b
            .get(self.at..self.at + n)
            .ok_or_else(|| self.bad("the body ends inside a field"))?;
        self.at += n;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, DecodeError> {
        Ok(self.take(1)?[0])
    }
    fn u16(&mut self) -> Result<u16, DecodeError> {
        let s = self.take(2)?;
        Ok(u16::from_le_bytes([s[0], s[1]]))
    }
    fn u32(&mut self) -> Result<u32, DecodeError> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn u64(&mut self) -> Result<u64, DecodeError> {
        let s = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(s);
        Ok(u64::from_le_bytes(a))
    }
    fn slot(&mut self, area: usize) -> Result<u32, DecodeError> {
        Ok(if self.w.wide(area) {
            u32::from(self.u16()?)
        } else {
            u32::from(self.u8()?)
        })
    }
    fn b(&mut self) -> Result<B, DecodeError> {
        Ok(B(self.slot(AREA_B)?))
    }
    fn i(&mut self) -> Result<I, DecodeError> {
        Ok(I(self.slot(AREA_I)?))
    }
    fn f(&mut self) -> Result<F, DecodeError> {
        Ok(F(self.slot(AREA_F)?))
    }
    fn l(&mut self) -> Result<L, DecodeError> {
        Ok(L(self.slot(AREA_L)?))
    }
    fn d(&mut self) -> Result<D, DecodeError> {
        Ok(D(self.slot(AREA_D)?))
    }
    fn m(&mut self) -> Result<u32, DecodeError> {
        self.slot(AREA_M)
    }
    fn cmp(&mut self) -> Result<Cmp, DecodeError> {
        let c = self.u8()?;
        CMPS.get(c as usize)
            .copied()
            .ok_or_else(|| self.bad(format!("compare {c} is not defined")))
    }
    fn bin(&mut self) -> Result<BinOp, DecodeError> {
        let c = self.u8()?;
        match c {
            0x10..=0x15 => Ok(BinOp::Cmp(CMPS[(c - 0x10) as usize])),
            _ => BINS
                .get(c as usize)
                .copied()
                .ok_or_else(|| self.bad(format!("math op {c} is not defined"))),
        }
    }
    fn un(&mut self) -> Result<UnOp, DecodeError> {
        let c = self.u8()?;
        UNS.get(c as usize)
            .copied()
            .ok_or_else(|| self.bad(format!("function {c} is not defined")))
    }

    fn time_base(&mut self) -> Result<TimeBase, DecodeError> {
        let c = self.u8()?;
        TimeBase::from_code(c).ok_or_else(|| self.bad(format!("time base {c} is not defined")))
    }

    /// One op; a jump's relative offset is returned beside it.
    fn op(&mut self) -> Result<(Op, Option<i16>), DecodeError> {
        let code = self.u8()?;
        let tmr = |r: &mut Self| -> Result<Tmr, DecodeError> { Ok(Tmr { i: r.i()?, b: r.b()? }) };
        let ctr = |r: &mut Self| -> Result<Ctr, DecodeError> { Ok(Ctr { i: r.i()?, b: r.b()? }) };
        let op = match code {
            RUNG => Op::Rung,
            NOP => Op::Nop,
            AFI => Op::Afi,
            NOT => Op::Not,
            TRUE => Op::True,
            XIC => Op::Xic(self.b()?),
            XIO => Op::Xio(self.b()?),
            OTE => Op::Ote(self.b()?),
            OTL => Op::Otl(self.b()?),
            OTU => Op::Otu(self.b()?),
            ONS => Op::Ons(self.b()?),
            LD => Op::Ld(self.b()?),
            LDN => Op::Ldn(self.b()?),
            OR => Op::Or(self.b()?),
            ORN => Op::Orn(self.b()?),
            ED => Op::Ed(self.b()?),
            OSR => Op::Osr(self.b()?, self.b()?),
            OSF => Op::Osf(self.b()?, self.b()?),
            COPY_B => Op::CopyB(self.b()?, self.b()?),
            BR_OPEN => Op::BrOpen {
                save: self.b()?,
                acc: self.b()?,
            },
            BR_NEXT => Op::BrNext {
                save: self.b()?,
                acc: self.b()?,
            },
            BR_CLOSE => Op::BrClose { acc: self.b()? },
            JMP => return Ok((Op::Jmp(0), Some(self.u16()? as i16))),
            TON => {
                let tb = self.time_base()?;
                Op::Ton(tmr(self)?, tb)
            }
            TOF => {
                let tb = self.time_base()?;
                Op::Tof(tmr(self)?, tb)
            }
            RTO => {
                let tb = self.time_base()?;
                Op::Rto(tmr(self)?, tb)
            }
            TP => Op::Tp(tmr(self)?),
            RES_T => Op::ResT(tmr(self)?),
            CTU => Op::Ctu(ctr(self)?),
            CTD => Op::Ctd(ctr(self)?),
            RES_C => Op::ResC(ctr(self)?),
            CMP_I => Op::CmpI(self.cmp()?, self.i()?, self.i()?),
            CMP_F => Op::CmpF(self.cmp()?, self.f()?, self.f()?),
            CMP_L => Op::CmpL(self.cmp()?, self.l()?, self.l()?),
            CMP_D => Op::CmpD(self.cmp()?, self.d()?, self.d()?),
            LIM_I => Op::LimI(self.i()?, self.i()?, self.i()?),
            LIM_F => Op::LimF(self.f()?, self.f()?, self.f()?),
            LIM_L => Op::LimL(self.l()?, self.l()?, self.l()?),
            LIM_D => Op::LimD(self.d()?, self.d()?, self.d()?),
            MEQ_I => Op::MeqI(self.i()?, self.i()?, self.i()?),
            MEQ_L => Op::MeqL(self.l()?, self.l()?, self.l()?),
            BIN_I => Op::BinI(self.bin()?, self.i()?, self.i()?, self.i()?),
            BIN_F => Op::BinF(self.bin()?, self.f()?, self.f()?, self.f()?),
            BIN_L => Op::BinL(self.bin()?, self.l()?, self.l()?, self.l()?),
            BIN_D => Op::BinD(self.bin()?, self.d()?, self.d()?, self.d()?),
            UN_I => Op::UnI(self.un()?, self.i()?, self.i()?),
            UN_F => Op::UnF(self.un()?, self.f()?, self.f()?),
            UN_L => Op::UnL(self.un()?, self.l()?, self.l()?),
            UN_D => Op::UnD(self.un()?, self.d()?, self.d()?),
            CVT => {
                let k = self.u8()?;
                Op::Cvt(match k {
                    0 => Cvt::IF(self.i()?, self.f()?),
                    1 => Cvt::FI(self.f()?, self.i()?),
                    2 => Cvt::IL(self.i()?, self.l()?),
                    3 => Cvt::LI(self.l()?, self.i()?),
                    4 => Cvt::ID(self.i()?, self.d()?),
                    5 => Cvt::DI(self.d()?, self.i()?),
                    6 => Cvt::LF(self.l()?, self.f()?),
                    7 => Cvt::FL(self.f()?, self.l()?),
                    8 => Cvt::LD(self.l()?, self.d()?),
                    9 => Cvt::DL(self.d()?, self.l()?),
                    10 => Cvt::FD(self.f()?, self.d()?),
                    11 => Cvt::DF(self.d()?, self.f()?),
                    _ => return Err(self.bad(format!("conversion {k} is not defined"))),
                })
            }
            NARROW => {
                let width = match self.u8()? {
                    8 => Width::W8,
                    16 => Width::W16,
                    n => return Err(self.bad(format!("width {n} is not 8 or 16"))),
                };
                Op::Narrow(self.i()?, width)
            }
            COPY_I => Op::CopyI(self.i()?, self.i()?),
            LD_BIT | ST_BIT => {
                let byte = self.m()?;
                let bit = self.u8()?;
                let b = self.b()?;
                if code == LD_BIT {
                    Op::LdBit { byte, bit, dst: b }
                } else {
                    Op::StBit { src: b, byte, bit }
                }
            }
            LD_M | ST_M => {
                let byte = self.m()?;
                let slot = match self.u8()? {
                    1 => MarkerSlot::Byte(self.i()?),
                    2 => MarkerSlot::Word(self.i()?),
                    4 => MarkerSlot::DWord(self.i()?),
                    0x84 => MarkerSlot::Real(self.f()?),
                    k => return Err(self.bad(format!("marker size {k} is not defined"))),
                };
                if code == LD_M {
                    Op::LdM { byte, slot }
                } else {
                    Op::StM { byte, slot }
                }
            }
            S7_TON | S7_TONR | S7_TOF | S7_RES_T => {
                let t = S7Tmr {
                    i: self.i()?,
                    b: self.b()?,
                    res: self.u16()?,
                };
                match code {
                    S7_TON => Op::S7Ton(t),
                    S7_TONR => Op::S7Tonr(t),
                    S7_TOF => Op::S7Tof(t),
                    _ => Op::S7ResT(t),
                }
            }
            S7_CTU | S7_CTD | S7_CTUD | S7_RES_C => {
                let c = S7Ctr {
                    i: self.i()?,
                    b: self.b()?,
                };
                match code {
                    S7_CTU => Op::S7Ctu(c),
                    S7_CTD => Op::S7Ctd(c),
                    S7_CTUD => Op::S7Ctud(c),
                    _ => Op::S7ResC(c),
                }
            }
            PID => Op::Pid(Pidt {
                f: self.f()?,
                i: self.i()?,
                b: self.b()?,
            }),
            other => return Err(self.bad(format!("opcode 0x{other:02x} is not defined"))),
        };
        Ok((op, None))
    }
}

/// Checks and decodes byte code into the program the engine runs.
pub fn decode(bytes: &[u8]) -> Result<Decoded, DecodeError> {
    let h = bytes
        .get(..HEADER_LEN)
        .ok_or(DecodeError::Truncated("the header is 24 bytes"))?;
    let magic = [h[0], h[1], h[2], h[3]];
    if magic != MAGIC {
        return Err(DecodeError::Magic(magic));
    }
    if h[4] != VERSION {
        return Err(DecodeError::Version(h[4]));
    }
    let w = Widths(h[5]);
    let board_id = u16::from_le_bytes([h[6], h[7]]);
    let program_id = u32::from_le_bytes([h[8], h[9], h[10], h[11]]);
    let scan_ms = u16::from_le_bytes([h[12], h[13]]);
    let len = u32::from_le_bytes([h[16], h[17], h[18], h[19]]) as usize;
    let want = u32::from_le_bytes([h[20], h[21], h[22], h[23]]);
    let body = bytes
        .get(HEADER_LEN..HEADER_LEN.saturating_add(len))
        .ok_or(DecodeError::Truncated("the body is shorter than the header says"))?;
    let found = crc32fast::hash(body);
    if found != want {
        return Err(DecodeError::Crc { want, found });
    }
    let mut r = Reader {
        b: body,
        at: 0,
        w,
        base: HEADER_LEN,
    };
    let mut n = [0u32; 6];
    for x in &mut n {
        *x = u32::from(r.u16()?);
    }
    let counts = Counts {
        b: n[0],
        i: n[1],
        f: n[2],
        l: n[3],
        d: n[4],
    };
    if Widths::of(&counts, n[5]) != w {
        return Err(r.bad("the operand widths do not match the memory sizes"));
    }
    let mut regions = [Region::default(); 4];
    for (k, reg) in regions.iter_mut().enumerate() {
        let (base, len) = (u32::from(r.u16()?), u32::from(r.u16()?));
        let size = if k < 2 { counts.b } else { counts.i };
        if base + len > size {
            return Err(r.bad("an I/O region outside memory"));
        }
        *reg = Region { base, len };
    }
    let mut bs = [B(0); 9];
    for b in &mut bs {
        *b = r.b_wide()?;
        if b.0 >= counts.b {
            return Err(r.bad("a system bit outside memory"));
        }
    }
    let mut is = [I(0); 4];
    for (k, i) in is.iter_mut().enumerate() {
        *i = I(u32::from(r.u16()?));
        let extent = if k == 2 {
            alba_ir::layout::STAT_TAGS.len() as u32
        } else {
            1
        };
        if i.0 + extent > counts.i {
            return Err(r.bad("a system integer outside memory"));
        }
    }
    let system = System {
        first_scan: bs[0],
        minor_fault: bs[1],
        always_on: bs[2],
        clock_60s: bs[3],
        clock_1s: bs[4],
        scan_toggle: bs[5],
        io_ok: bs[6],
        retain_lost: bs[7],
        store_ok: bs[8],
        fault_code: is[0],
        scan_time: is[1],
        stats: is[2],
        io_errors: is[3],
    };
    let mut init = Memory::new(counts, n[5]);
    let slot_in = |r: &Reader, k: u16, len: usize| -> Result<usize, DecodeError> {
        if (k as usize) < len {
            Ok(k as usize)
        } else {
            Err(r.bad(format!("initial value for slot {k} outside memory ({len})")))
        }
    };
    for _ in 0..r.u16()? {
        let k = r.u16()?;
        let k = slot_in(&r, k, init.b.len())?;
        init.b[k] = true;
    }
    for _ in 0..r.u16()? {
        let k = r.u16()?;
        let k = slot_in(&r, k, init.i.len())?;
        init.i[k] = r.u32()? as i32;
    }
    for _ in 0..r.u16()? {
        let k = r.u16()?;
        let k = slot_in(&r, k, init.f.len())?;
        init.f[k] = f32::from_bits(r.u32()?);
    }
    for _ in 0..r.u16()? {
        let k = r.u16()?;
        let k = slot_in(&r, k, init.l.len())?;
        init.l[k] = r.u64()? as i64;
    }
    for _ in 0..r.u16()? {
        let k = r.u16()?;
        let k = slot_in(&r, k, init.d.len())?;
        init.d[k] = f64::from_bits(r.u64()?);
    }
    for _ in 0..r.u16()? {
        let k = r.u16()?;
        let k = slot_in(&r, k, init.m.len())?;
        init.m[k] = r.u8()?;
    }
    let mut wiring = Vec::new();
    for _ in 0..r.u16()? {
        let (kind, ch, pin, slot) = (r.u8()?, u32::from(r.u16()?), r.u8()?, u32::from(r.u16()?));
        let (address, region) = match kind {
            0 => (Address::DigitalIn(ch), regions[0]),
            1 => (Address::DigitalOut(ch), regions[1]),
            2 => (Address::AnalogIn(ch), regions[2]),
            3 => (Address::AnalogOut(ch), regions[3]),
            k => return Err(r.bad(format!("wiring kind {k} is not defined"))),
        };
        if slot != region.base + ch || ch >= region.len {
            return Err(r.bad(format!("channel {ch} wired outside its image")));
        }
        wiring.push((address, pin, slot));
    }
    let n_ops = r.u16()? as usize;
    let code_start = r.at;
    let mut ops = Vec::with_capacity(n_ops);
    let mut starts = Vec::with_capacity(n_ops + 1);
    let mut jumps = Vec::new();
    for pc in 0..n_ops {
        starts.push(r.at - code_start);
        let (op, rel) = r.op()?;
        if let Some(rel) = rel {
            jumps.push((pc, r.at - code_start, rel));
        }
        ops.push(op);
    }
    starts.push(r.at - code_start);
    if r.at != body.len() {
        return Err(r.bad(format!("{} bytes after the last op", body.len() - r.at)));
    }
    for (pc, next, rel) in jumps {
        let to = next as i64 + i64::from(rel);
        let target = usize::try_from(to)
            .ok()
            .and_then(|to| starts.binary_search(&to).ok())
            .filter(|t| *t < ops.len())
            .ok_or_else(|| DecodeError::Bad {
                at: HEADER_LEN + code_start + next - 3,
                what: format!("op {pc} jumps to byte {to}, which starts no op"),
            })?;
        ops[pc] = Op::Jmp(target as u32);
    }
    let program = rebuild(ops, init, counts, n[5], regions, system);
    program.verify().map_err(|e| DecodeError::Bad {
        at: HEADER_LEN + code_start,
        what: e.to_string(),
    })?;
    Ok(Decoded {
        program,
        board_id,
        program_id,
        scan_ms,
        wiring,
    })
}

/// As [`decode`], and refused unless the interpreter firmware for `t`'s board
/// runs it: the board id, the program slot's size, the interpreter's memory
/// (and no LREAL, no LINT on the Uno and Nano), its number of wires, every
/// wire on the pin the board's pin map has for that channel, and every op
/// one the interpreter has (the sketch export translates it). The firmware
/// makes the same checks (`interp.rs`, `load_at`), so it runs exactly what
/// this accepts.
pub fn decode_for(bytes: &[u8], t: &Target) -> Result<Decoded, DecodeError> {
    let d = decode(bytes)?;
    let board = |m: String| Err(DecodeError::Board(m));
    let title = t.model.title();
    let want = board_id(t);
    if d.board_id != want {
        return board(format!(
            "it was compiled for another board or pin map (board id {:04x}; this {title}'s interpreter is {want:04x})",
            d.board_id
        ));
    }
    let room = slot_size(t.model);
    let len = bytes
        .len()
        .min(HEADER_LEN + u32::from_le_bytes([bytes[16], bytes[17], bytes[18], bytes[19]]) as usize);
    if len > room {
        return board(format!("{len} bytes; the {title}'s program slot holds {room}"));
    }
    let cap = capacity(t.model);
    let lay = &d.program.layout;
    for (what, n, max) in [
        ("BOOL slots", lay.counts.b, cap.b),
        ("integer slots", lay.counts.i, cap.i),
        ("REAL slots", lay.counts.f, cap.f),
        ("LINT slots", lay.counts.l, cap.l),
        ("LREAL slots", lay.counts.d, 0),
        ("marker bytes", lay.marker_bytes, cap.m),
        ("wired channels", d.wiring.len() as u32, cap.wires),
    ] {
        if n > max {
            return board(format!("{n} {what}; the {title}'s interpreter holds {max}"));
        }
    }
    for (address, pin, _) in &d.wiring {
        let (kind, ch) = match *address {
            Address::DigitalIn(n) => (0, n),
            Address::DigitalOut(n) => (1, n),
            Address::AnalogIn(n) => (2, n),
            Address::AnalogOut(n) => (3, n),
            Address::Marker { .. } => (4, 0),
        };
        if ch >= MAX_CHANNELS {
            return board(format!(
                "{address}: the interpreter wires channels 0 to {} of a kind",
                MAX_CHANNELS - 1
            ));
        }
        if map_pin(t, kind, ch) != Some(*pin) {
            return board(format!(
                "{address} is wired to pin byte 0x{pin:02x}, which is not that channel's pin on the {title}'s pin map"
            ));
        }
    }
    if let Some((pc, op)) = d
        .program
        .ops
        .iter()
        .enumerate()
        .find(|(pc, op)| !matches!(op, Op::Jmp(_)) && sketch::emit(op, *pc as u32).is_err())
    {
        return board(format!("op {pc} ({op:?}) does not run on the {title}"));
    }
    Ok(d)
}

impl Reader<'_> {
    /// A system bit: always two bytes (the table is fixed-size).
    fn b_wide(&mut self) -> Result<B, DecodeError> {
        Ok(B(u32::from(self.u16()?)))
    }
}

/// A program around decoded ops: one unit, its rungs at the `Rung` ops, no
/// sources (byte code keeps none), the memory and system slots as decoded.
fn rebuild(ops: Vec<Op>, init: Memory, counts: Counts, marker_bytes: u32, r: [Region; 4], system: System) -> Program {
    // One empty source, so that fault reports have a place to name.
    let mut files = alba_diag::Files::new();
    let nowhere = alba_diag::Span::new(files.add("<byte code>", ""), 0..0);
    let mut rungs = Vec::new();
    let mut locs = Vec::with_capacity(ops.len());
    for (pc, op) in ops.iter().enumerate() {
        if *op == Op::Rung {
            rungs.push(alba_ir::RungInfo {
                unit: 0,
                number: rungs.len() as u32,
                span: nowhere,
                first_op: pc as u32,
            });
        }
        locs.push(Loc {
            rung: rungs.len().saturating_sub(1) as u32,
            elem: alba_ir::NO_ELEM,
        });
    }
    let mut layout = Layout::new(&Default::default(), &Default::default());
    layout.system = system;
    layout.di = r[0];
    layout.dout = r[1];
    layout.ai = r[2];
    layout.ao = r[3];
    layout.counts = counts;
    layout.marker_bytes = marker_bytes;
    let n = ops.len() as u32;
    Program {
        ops,
        locs,
        elements: Vec::new(),
        rungs,
        units: vec![alba_ir::Unit {
            name: "bytecode".into(),
            first_op: 0,
            end_op: n,
            plant: false,
        }],
        layout,
        init,
        files,
        plants: Vec::new(),
    }
}

/// What the interpreter's arrays hold on each board (RAM: Uno and Nano 2 KB,
/// Mega 8 KB).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capacity {
    pub b: u32,
    pub i: u32,
    pub f: u32,
    pub l: u32,
    pub m: u32,
    pub wires: u32,
}

pub fn capacity(model: Model) -> Capacity {
    match model {
        Model::Mega => Capacity {
            b: 1024,
            i: 512,
            f: 192,
            l: 16,
            m: 256,
            wires: 96,
        },
        // No LINT on the Uno and the Nano: the 64-bit cases would not fit in their flash.
        // 20 wires: all the pins a pin map can use there (D2-D13, A0-A7), none twice.
        _ => Capacity {
            b: 256,
            i: 128,
            f: 48,
            l: 0,
            m: 64,
            wires: 20,
        },
    }
}

/// Bytes of one of the two program slots in the board's EEPROM (the last byte
/// says which slot runs): Uno and Nano 511, Mega 2 047.
pub fn slot_size(model: Model) -> usize {
    let eeprom = match model {
        Model::Mega => 4096,
        _ => 1024,
    };
    (eeprom - 1) / 2
}
