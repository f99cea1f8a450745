//! IR → Arduino sketch: the control program's ops as straight-line C++ over
//! the same typed slots the engine uses, with the runtime of `alba_rt.h`
//! (timers, counters, checked arithmetic) mirroring `crates/engine/src/exec/`.
//!
//! The sketch scans every `scan_ms` on deadlines kept with `millis()` and
//! passes the *scheduled* time to the program (scan k sees k·scan_ms, as in
//! `alba sim`), so timers count exactly what the simulator counts; a late
//! scan skips the deadlines it missed (counted in `S:OVERRUNS`). Inputs are
//! read into the image before each scan and outputs written after it, through
//! the board's pin map.

use alba_diag::{Code, Diagnostic};
use alba_ir::op::{AnySlot, MarkerSlot, S7Ctr, S7Tmr};
use alba_ir::{BinOp, Cmp, Ctr, Cvt, Loc, Op, Program, Region, Tmr, UnOp, Width};
use alba_model::address::Address;
use alba_model::board::{Model, Pin, PinMap};
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// The runtime every sketch includes.
pub const RUNTIME: &str = include_str!("../runtime/alba_rt.h");
/// The monitoring link (a Modbus RTU slave serving program memory).
pub const LINK: &str = include_str!("../runtime/alba_link.h");

/// The monitoring link's serial settings.
pub const LINK_BAUD: u32 = 115_200;
pub const LINK_SLAVE: u8 = 1;
/// First word of the link's input registers (its identity).
pub const LINK_MAGIC: u16 = 0xA1BA;

/// Backward jumps allowed in one scan (as the engine's `BACKWARD_JUMP_LIMIT`).
const BACKWARD_JUMP_LIMIT: u32 = 1_000_000;

/// What the sketch is for.
#[derive(Debug, Clone)]
pub struct Target {
    pub model: Model,
    pub map: PinMap,
    pub active_low: bool,
    pub scan_ms: u32,
    /// Serve the monitoring link on the serial port (about 350 bytes of RAM).
    pub monitor: bool,
    /// Digital output pins on at power-up (until the first scan writes the
    /// outputs) and after a major fault; the others are off.
    pub power_up_on: Vec<Pin>,
}

/// A generated sketch: an Arduino IDE folder `<name>/` with `<name>.ino` and
/// `alba_rt.h`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sketch {
    pub name: String,
    /// (file name, contents), the `.ino` first.
    pub files: Vec<(String, String)>,
    /// The I/O channels wired, in the order of the image.
    pub wiring: Vec<Wire>,
    /// Identifies the program and its memory layout: the monitoring link
    /// reports it, so a host knows the board runs what it compiled.
    pub program_id: u32,
}

/// One wired I/O channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Wire {
    pub address: Address,
    pub pin: Pin,
    /// Slot in the image (bool slot for DI/DO, integer slot for AI/AO).
    pub slot: u32,
}

/// A sketch folder name: letters, digits and `_`, not starting with a digit.
pub fn sketch_name(project: &str) -> String {
    let mut s: String = project
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert_str(0, "alba_");
    }
    s
}

/// Ops of the control programs (plant models run only in simulation).
pub fn control_ops(prog: &Program) -> &[Op] {
    let end = prog
        .units
        .iter()
        .find(|u| u.plant)
        .map_or(prog.ops.len(), |u| u.first_op as usize);
    &prog.ops[..end.min(prog.ops.len())]
}

/// The program without its plant models: what a board runs.
pub fn control_program(prog: &Program) -> Program {
    let mut p = prog.clone();
    let n = control_ops(prog).len();
    p.ops.truncate(n);
    p.locs.truncate(n);
    p.units.retain(|u| !u.plant);
    p
}

/// Generates the sketch, or says why the program cannot run on the board
/// (each refusal located at the instruction or tag responsible).
pub fn generate(prog: &Program, project: &str, t: &Target) -> Result<Sketch, Vec<Diagnostic>> {
    let ops = control_ops(prog);
    let mut diags = Vec::new();
    let wiring = wire(prog, ops, t, &mut diags);
    let lay = &prog.layout;
    for tag in lay.tags.iter().filter(|tag| tag.ty == alba_model::DataType::Lreal) {
        diags.push(
            Diagnostic::new(
                Code::NotOnBoard,
                format!(
                    "`{}` is an LREAL, which the {} cannot hold: avr-gcc's double has 32 bits",
                    tag.name,
                    t.model.title()
                ),
                tag.span,
                "LREAL",
            )
            .with_help("use REAL (32-bit) for the board"),
        );
    }
    let mut body = String::new();
    let targets: BTreeSet<u32> = ops
        .iter()
        .filter_map(|op| if let Op::Jmp(t) = op { Some(*t) } else { None })
        .collect();
    let mut rung = u32::MAX;
    for (pc, op) in ops.iter().enumerate() {
        let loc = prog.locs.get(pc).copied().unwrap_or(Loc {
            rung: 0,
            elem: alba_ir::NO_ELEM,
        });
        if *op == Op::Rung && loc.rung != rung {
            rung = loc.rung;
            let _ = writeln!(body, "    // {}", rung_comment(prog, loc));
        }
        if targets.contains(&(pc as u32)) {
            let _ = writeln!(body, "L{pc}:");
        }
        match emit(op, pc as u32) {
            Ok(code) if code.is_empty() => {}
            Ok(code) => {
                let _ = writeln!(body, "    {code}");
            }
            Err(why) => {
                // One refusal per instruction (an LREAL ADD lowers to a conversion and an add).
                let d = located(prog, loc, Code::NotOnBoard, why);
                if !diags.contains(&d) {
                    diags.push(d);
                }
            }
        }
    }
    if !diags.is_empty() {
        return Err(diags);
    }
    let name = sketch_name(project);
    let m = &prog.init;
    let program_id = fnv1a(
        format!(
            "{body}|{}|{}|{}|{}|{}|{:?}",
            m.b.len(),
            m.i.len(),
            m.f.len(),
            m.l.len(),
            m.m.len(),
            wiring
        )
        .as_bytes(),
    );
    let ino = render(prog, &name, project, t, &wiring, &body, program_id);
    let mut files = vec![(format!("{name}.ino"), ino), ("alba_rt.h".into(), RUNTIME.into())];
    if t.monitor {
        files.push(("alba_link.h".into(), LINK.into()));
    }
    Ok(Sketch {
        files,
        name,
        wiring,
        program_id,
    })
}

pub(crate) fn fnv1a(bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .fold(0x811c_9dc5u32, |h, b| (h ^ u32::from(*b)).wrapping_mul(0x0100_0193))
}

/// Holding-register layout of the link: where each class starts (registers).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkMap {
    pub i: u32,
    pub f: u32,
    pub l: u32,
    pub m: u32,
    pub end: u32,
}

impl LinkMap {
    /// I slots (2 registers each, high word first), then F (the IEEE bits,
    /// 2 each), L (4 each), marker bytes (2 per register, first byte high).
    pub fn of(m: &alba_ir::Memory) -> LinkMap {
        let i = 0;
        let f = i + 2 * m.i.len() as u32;
        let l = f + 2 * m.f.len() as u32;
        let mm = l + 4 * m.l.len() as u32;
        LinkMap {
            i,
            f,
            l,
            m: mm,
            end: mm + (m.m.len() as u32).div_ceil(2),
        }
    }
}

fn located(prog: &Program, loc: Loc, code: Code, why: String) -> Diagnostic {
    let span = prog
        .elements
        .get(loc.elem as usize)
        .map(|e| e.span)
        .or_else(|| prog.rungs.get(loc.rung as usize).map(|r| r.span));
    match span {
        Some(s) => Diagnostic::new(code, why, s, "here"),
        None => Diagnostic::unplaced(code, why),
    }
}

fn rung_comment(prog: &Program, loc: Loc) -> String {
    let Some(r) = prog.rungs.get(loc.rung as usize) else {
        return String::new();
    };
    let unit = prog.units.get(r.unit as usize).map_or("?", |u| u.name.as_str());
    let text = prog.files.text(r.span.file).get(r.span.range()).unwrap_or("");
    let text: String = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let text: String = text.chars().take(100).collect();
    format!(
        "{unit} {} {}: {text}",
        if unit.ends_with(".awl") { "network" } else { "rung" },
        r.number + 1
    )
}

/// Every I/O channel the program or a tag uses, with its pin; refusals for
/// channels the map does not wire to a usable pin.
fn wire(prog: &Program, ops: &[Op], t: &Target, diags: &mut Vec<Diagnostic>) -> Vec<Wire> {
    let lay = &prog.layout;
    let mut used: BTreeSet<(u8, u32)> = BTreeSet::new();
    let mut first_use: std::collections::BTreeMap<(u8, u32), usize> = Default::default();
    let region = |r: Region, x: u32| (r.base..r.base + r.len).contains(&x).then(|| x - r.base);
    for (pc, op) in ops.iter().enumerate() {
        for s in op.slots() {
            let key = match s {
                AnySlot::B(x) => region(lay.di, x)
                    .map(|n| (0, n))
                    .or_else(|| region(lay.dout, x).map(|n| (1, n))),
                AnySlot::I(x) => region(lay.ai, x)
                    .map(|n| (2, n))
                    .or_else(|| region(lay.ao, x).map(|n| (3, n))),
                _ => None,
            };
            if let Some(k) = key {
                used.insert(k);
                first_use.entry(k).or_insert(pc);
            }
        }
    }
    let mut tag_of = std::collections::BTreeMap::new();
    for (idx, tag) in lay.tags.iter().enumerate() {
        let key = match tag.address {
            Some(Address::DigitalIn(n)) => (0, n),
            Some(Address::DigitalOut(n)) => (1, n),
            Some(Address::AnalogIn(n)) => (2, n),
            Some(Address::AnalogOut(n)) => (3, n),
            _ => continue,
        };
        used.insert(key);
        tag_of.insert(key, idx);
    }
    let mut out = Vec::new();
    for (dir, n) in used {
        let (address, base) = match dir {
            0 => (Address::DigitalIn(n), lay.di.base),
            1 => (Address::DigitalOut(n), lay.dout.base),
            2 => (Address::AnalogIn(n), lay.ai.base),
            _ => (Address::AnalogOut(n), lay.ao.base),
        };
        match t.map.pin_of(t.model, address) {
            Some(Ok(pin)) => out.push(Wire {
                address,
                pin,
                slot: base + n,
            }),
            Some(Err(why)) => {
                // The tag's own E104 is reported when the project loads with a
                // [board]; here the board may come from the command line.
                let d = if let Some(tag) = tag_of.get(&(dir, n)).and_then(|&idx| lay.tags.iter().nth(idx)) {
                    Diagnostic::new(Code::BoardPin, format!("`{}`: {why}", tag.name), tag.span, "no pin")
                } else {
                    let pc = first_use.get(&(dir, n)).copied().unwrap_or(0);
                    let loc = prog.locs.get(pc).copied().unwrap_or(Loc {
                        rung: 0,
                        elem: alba_ir::NO_ELEM,
                    });
                    located(prog, loc, Code::BoardPin, why)
                };
                diags.push(
                    d.with_help("wire the channel in [board] (di, do, ai, ao) or use another; see docs/arduino.md"),
                );
            }
            None => {}
        }
    }
    out
}

fn cmp(c: Cmp) -> &'static str {
    match c {
        Cmp::Eq => "==",
        Cmp::Ne => "!=",
        Cmp::Lt => "<",
        Cmp::Gt => ">",
        Cmp::Le => "<=",
        Cmp::Ge => ">=",
    }
}

fn tmr(t: &Tmr) -> String {
    format!("&I[{}], &B[{}]", t.i.0, t.b.0)
}

fn ctr(c: &Ctr) -> String {
    format!("&I[{}], &B[{}]", c.i.0, c.b.0)
}

fn s7t(t: &S7Tmr) -> String {
    format!("&I[{}], &B[{}]", t.i.0, t.b.0)
}

fn s7c(c: &S7Ctr) -> String {
    format!("&I[{}], &B[{}]", c.i.0, c.b.0)
}

const LREAL: &str = "LREAL (64-bit) arithmetic cannot run on the board: avr-gcc's double has 32 bits";

/// An integer operation for array `a` (`I` or `L`) of C type `ty`.
fn bin_int(op: BinOp, arr: &str, a: u32, b: u32, d: u32, pc: u32) -> Result<String, String> {
    let (x, y) = (format!("{arr}[{a}]"), format!("{arr}[{b}]"));
    let e = match op {
        BinOp::Add => format!("alba_add({x}, {y}, {pc})"),
        BinOp::Sub => format!("alba_sub({x}, {y}, {pc})"),
        BinOp::Mul => format!("alba_mul({x}, {y}, {pc})"),
        BinOp::Div => format!("alba_div({x}, {y}, {pc})"),
        BinOp::Mod => format!("alba_mod({x}, {y}, {pc})"),
        BinOp::And => format!("{x} & {y}"),
        BinOp::Or => format!("{x} | {y}"),
        BinOp::Xor => format!("{x} ^ {y}"),
        BinOp::Cmp(c) => format!("{x} {} {y} ? 1 : 0", cmp(c)),
        BinOp::Pow | BinOp::Atan2 => {
            return Err("integer ** and ATAN2 are computed in 64-bit floating point, which the board lacks".into());
        }
    };
    Ok(format!("if (rc) {arr}[{d}] = {e};"))
}

fn un_int(op: UnOp, arr: &str, a: u32, d: u32, pc: u32, bcd_max: &str) -> Result<String, String> {
    let x = format!("{arr}[{a}]");
    let e = match op {
        UnOp::Mov => x,
        UnOp::Neg => format!("alba_neg({x}, {pc})"),
        UnOp::Abs => format!("alba_abs({x}, {pc})"),
        UnOp::Not => format!("~{x}"),
        UnOp::Frd => format!("alba_frd({x}, {pc})"),
        UnOp::Tod => format!("alba_tod({x}, {bcd_max}, {pc})"),
        _ => {
            return Err(format!(
                "{op:?} of an integer is computed in 64-bit floating point, which the board lacks"
            ));
        }
    };
    Ok(format!("if (rc) {arr}[{d}] = {e};"))
}

fn un_f(op: UnOp, x: &str) -> String {
    match op {
        UnOp::Mov => x.to_string(),
        UnOp::Neg => format!("-{x}"),
        UnOp::Abs => format!("fabsf({x})"),
        UnOp::Sqrt => format!("sqrtf(fabsf({x}))"),
        UnOp::Ln => format!("logf({x})"),
        UnOp::Log => format!("log10f({x})"),
        UnOp::Sin => format!("sinf({x})"),
        UnOp::Cos => format!("cosf({x})"),
        UnOp::Tan => format!("tanf({x})"),
        UnOp::Asin => format!("asinf({x})"),
        UnOp::Acos => format!("acosf({x})"),
        UnOp::Atan => format!("atanf({x})"),
        // Rust's f32::to_degrees / to_radians constants.
        UnOp::Deg => format!("{x} * 57.2957795130823208767981548141051703f"),
        UnOp::Rad => format!("{x} * (3.14159265358979323846264338327950288f / 180.0f)"),
        UnOp::Trunc => format!("truncf({x})"),
        UnOp::Round => format!("alba_round_even({x})"),
        UnOp::Not | UnOp::Frd | UnOp::Tod => x.to_string(),
    }
}

/// C++ for one op (empty for ops that do nothing), or why the board cannot run it.
pub(crate) fn emit(op: &Op, pc: u32) -> Result<String, String> {
    Ok(match *op {
        Op::Rung | Op::True => "rc = 1;".into(),
        Op::Nop => String::new(),
        Op::Afi => "rc = 0;".into(),
        Op::Xic(b) => format!("rc &= B[{}];", b.0),
        Op::Xio(b) => format!("rc &= !B[{}];", b.0),
        Op::Ote(b) => format!("B[{}] = rc;", b.0),
        Op::Otl(b) => format!("if (rc) B[{}] = 1;", b.0),
        Op::Otu(b) => format!("if (rc) B[{}] = 0;", b.0),
        Op::Ons(s) => format!("{{ bool o = rc && !B[{0}]; B[{0}] = rc; rc = o; }}", s.0),
        Op::Osr(s, o) => format!("B[{1}] = rc && !B[{0}]; B[{0}] = rc;", s.0, o.0),
        Op::Osf(s, o) => format!("B[{1}] = !rc && B[{0}]; B[{0}] = rc;", s.0, o.0),
        Op::BrOpen { save, acc } => format!("B[{}] = rc; B[{}] = 0;", save.0, acc.0),
        Op::BrNext { save, acc } => format!("B[{}] |= rc; rc = B[{}];", acc.0, save.0),
        Op::BrClose { acc } => format!("rc |= B[{}];", acc.0),
        Op::Jmp(t) if t <= pc => format!("if (rc) {{ if (++back > {BACKWARD_JUMP_LIMIT}UL) return {pc}; goto L{t}; }}"),
        Op::Jmp(t) => format!("if (rc) goto L{t};"),
        Op::Ton(t, base) => format!("alba_ton({}, rc, now, {}UL, {pc});", tmr(&t), base.ms()),
        Op::Tof(t, base) => format!("alba_tof({}, rc, now, {}UL, {pc});", tmr(&t), base.ms()),
        Op::Rto(t, base) => format!("alba_rto({}, rc, now, {}UL, {pc});", tmr(&t), base.ms()),
        Op::Tp(t) => format!("alba_tp({}, rc, now, {pc});", tmr(&t)),
        Op::Ctu(c) => format!("alba_count({}, rc, true);", ctr(&c)),
        Op::Ctd(c) => format!("alba_count({}, rc, false);", ctr(&c)),
        Op::ResT(t) => format!("if (rc) alba_res_t({});", tmr(&t)),
        Op::ResC(c) => format!("if (rc) alba_res_c({});", ctr(&c)),
        Op::CmpI(c, a, b) => format!("rc &= I[{}] {} I[{}];", a.0, cmp(c), b.0),
        Op::CmpF(c, a, b) => format!("rc &= F[{}] {} F[{}];", a.0, cmp(c), b.0),
        Op::CmpL(c, a, b) => format!("rc &= L[{}] {} L[{}];", a.0, cmp(c), b.0),
        Op::LimI(lo, x, hi) => format!("rc &= alba_lim(I[{}], I[{}], I[{}]);", lo.0, x.0, hi.0),
        Op::LimF(lo, x, hi) => format!("rc &= alba_lim(F[{}], F[{}], F[{}]);", lo.0, x.0, hi.0),
        Op::LimL(lo, x, hi) => format!("rc &= alba_lim(L[{}], L[{}], L[{}]);", lo.0, x.0, hi.0),
        Op::MeqI(s, k, c) => format!("rc &= (I[{0}] & I[{1}]) == (I[{2}] & I[{1}]);", s.0, k.0, c.0),
        Op::MeqL(s, k, c) => format!("rc &= (L[{0}] & L[{1}]) == (L[{2}] & L[{1}]);", s.0, k.0, c.0),
        Op::BinI(o, a, b, d) => bin_int(o, "I", a.0, b.0, d.0, pc)?,
        Op::BinL(o, a, b, d) => bin_int(o, "L", a.0, b.0, d.0, pc)?,
        Op::BinF(o, a, b, d) => {
            let (x, y) = (format!("F[{}]", a.0), format!("F[{}]", b.0));
            let (e, dz) = match o {
                BinOp::Add => (format!("{x} + {y}"), "false".to_string()),
                BinOp::Sub => (format!("{x} - {y}"), "false".into()),
                BinOp::Mul => (format!("{x} * {y}"), "false".into()),
                BinOp::Div => (format!("{x} / {y}"), format!("{y} == 0.0f")),
                BinOp::Mod => (format!("fmodf({x}, {y})"), format!("{y} == 0.0f")),
                BinOp::Pow => (format!("powf({x}, {y})"), "false".into()),
                BinOp::Atan2 => (format!("atan2f({x}, {y})"), "false".into()),
                BinOp::Cmp(c) => (format!("{x} {} {y} ? 1.0f : 0.0f", cmp(c)), "false".into()),
                BinOp::And | BinOp::Or | BinOp::Xor => return Err("bitwise operation on a REAL".into()),
            };
            format!("if (rc) F[{}] = alba_fix({e}, {dz}, {pc});", d.0)
        }
        Op::UnI(o, a, d) => un_int(o, "I", a.0, d.0, pc, "9999999L")?,
        Op::UnL(o, a, d) => un_int(o, "L", a.0, d.0, pc, "999999999999999LL")?,
        Op::UnF(UnOp::Mov, a, d) => format!("if (rc) F[{}] = F[{}];", d.0, a.0),
        Op::UnF(o, a, d) => format!(
            "if (rc) F[{}] = alba_fix({}, false, {pc});",
            d.0,
            un_f(o, &format!("F[{}]", a.0))
        ),
        Op::Cvt(c) => match c {
            Cvt::IF(a, d) => format!("if (rc) F[{}] = (float)I[{}];", d.0, a.0),
            Cvt::FI(a, d) => format!("if (rc) I[{}] = alba_f2i(F[{}], {pc});", d.0, a.0),
            Cvt::IL(a, d) => format!("if (rc) L[{}] = (int64_t)I[{}];", d.0, a.0),
            Cvt::LI(a, d) => format!(
                "if (rc) {{ int64_t v = L[{1}]; I[{0}] = (int32_t)v; if (v < INT32_MIN || v > INT32_MAX) alba_fault(ALBA_OVERFLOW, {pc}); }}",
                d.0, a.0
            ),
            Cvt::LF(a, d) => format!("if (rc) F[{}] = (float)L[{}];", d.0, a.0),
            Cvt::FL(a, d) => format!("if (rc) L[{}] = alba_f2l(F[{}], {pc});", d.0, a.0),
            Cvt::ID(..) | Cvt::DI(..) | Cvt::LD(..) | Cvt::DL(..) | Cvt::FD(..) | Cvt::DF(..) => {
                return Err(LREAL.into());
            }
        },
        Op::Narrow(i, w) => {
            let ty = match w {
                Width::W8 => "int8_t",
                Width::W16 => "int16_t",
            };
            format!(
                "if (rc) {{ int32_t v = I[{0}]; int32_t n = ({ty})v; I[{0}] = n; if (n != v) alba_fault(ALBA_OVERFLOW, {pc}); }}",
                i.0
            )
        }
        Op::CopyI(a, d) => format!("I[{}] = I[{}];", d.0, a.0),
        Op::LdBit { byte, bit, dst } => format!("B[{}] = (M[{byte}] >> {}) & 1;", dst.0, bit & 7),
        Op::StBit { src, byte, bit } => format!(
            "if (B[{}]) M[{byte}] |= {m}; else M[{byte}] &= (uint8_t)~{m};",
            src.0,
            m = 1u8 << (bit & 7)
        ),
        Op::LdM { byte, slot } => match slot {
            MarkerSlot::Byte(i) => format!("I[{}] = (int8_t)M[{byte}];", i.0),
            MarkerSlot::Word(i) => format!("I[{}] = alba_ld_word(&M[{byte}]);", i.0),
            MarkerSlot::DWord(i) => format!("I[{}] = alba_ld_dword(&M[{byte}]);", i.0),
            MarkerSlot::Real(f) => format!("F[{}] = alba_ld_real(&M[{byte}], {pc});", f.0),
        },
        Op::StM { byte, slot } => match slot {
            MarkerSlot::Byte(i) => format!("M[{byte}] = (uint8_t)I[{}];", i.0),
            MarkerSlot::Word(i) => format!("alba_st_word(&M[{byte}], I[{}]);", i.0),
            MarkerSlot::DWord(i) => format!("alba_st_dword(&M[{byte}], I[{}]);", i.0),
            MarkerSlot::Real(f) => format!("alba_st_real(&M[{byte}], F[{}]);", f.0),
        },
        Op::Ld(b) => format!("rc = B[{}];", b.0),
        Op::Ldn(b) => format!("rc = !B[{}];", b.0),
        Op::Or(b) => format!("rc |= B[{}];", b.0),
        Op::Orn(b) => format!("rc |= !B[{}];", b.0),
        Op::Not => "rc = !rc;".into(),
        Op::Ed(s) => format!("{{ bool o = !rc && B[{0}]; B[{0}] = rc; rc = o; }}", s.0),
        Op::CopyB(a, d) => format!("B[{}] = B[{}];", d.0, a.0),
        Op::S7Ton(t) => format!("alba_s7_timer({}, rc, now, {}, 0);", s7t(&t), t.res.max(1)),
        Op::S7Tonr(t) => format!("alba_s7_timer({}, rc, now, {}, 1);", s7t(&t), t.res.max(1)),
        Op::S7Tof(t) => format!("alba_s7_timer({}, rc, now, {}, 2);", s7t(&t), t.res.max(1)),
        Op::S7ResT(t) => format!("if (rc) alba_s7_res_t({});", s7t(&t)),
        Op::S7Ctu(c) => format!("alba_s7_counter({}, rc, 0);", s7c(&c)),
        Op::S7Ctd(c) => format!("alba_s7_counter({}, rc, 1);", s7c(&c)),
        Op::S7Ctud(c) => format!("alba_s7_counter({}, rc, 2);", s7c(&c)),
        Op::S7ResC(c) => format!("if (rc) alba_s7_res_c({});", s7c(&c)),
        Op::CmpD(..) | Op::LimD(..) | Op::BinD(..) | Op::UnD(..) => return Err(LREAL.into()),
        Op::Pid(_) => {
            return Err(
                "PID does not run on the board yet: run the loop on the PC with the board as remote I/O (controller mode)"
                    .into(),
            );
        }
    })
}

/// The declaration of a memory array with its initial values (none for an
/// empty class: C++ has no zero-length arrays, and no op can name it).
fn array<T: std::fmt::Display>(decl: &str, v: &[T]) -> String {
    if v.is_empty() {
        return String::new();
    }
    let mut s = format!("static {decl}[{}] __attribute__((unused)) = {{", v.len());
    for (k, x) in v.iter().enumerate() {
        if k > 0 {
            s.push_str(if k % 16 == 0 { ",\n    " } else { ", " });
        }
        s.push_str(&x.to_string());
    }
    s.push_str("};\n");
    s
}

fn float_lit(v: f32) -> String {
    if v.is_nan() {
        return "0.0f".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "3.40282347e+38f" } else { "-3.40282347e+38f" }.into();
    }
    // Shortest round-trip decimal, in exponent form so it is always a float literal.
    format!("{v:e}f")
}

/// The monitoring link's callbacks over this program's memory.
fn link_code(m: &alba_ir::Memory, program_id: u32) -> String {
    let map = LinkMap::of(m);
    let mut bytes = String::new();
    let mut wbytes = String::new();
    // Byte `k` (0 = most significant) of the big-endian register file.
    let mut class = |arr: &str, slots: usize, width: u32, base: u32, conv: &str| {
        if slots == 0 {
            return;
        }
        let (lo, hi) = (2 * base, 2 * base + width * slots as u32);
        let _ = writeln!(
            bytes,
            "    if (at >= {lo}UL && at < {hi}UL) {{ uint32_t k = at - {lo}UL; {conv} x; memcpy(&x, &{arr}[k / {width}], {width}); return (uint8_t)(x >> (8 * ({width} - 1 - k % {width}))); }}"
        );
        let _ = writeln!(
            wbytes,
            "    if (at >= {lo}UL && at < {hi}UL) {{ uint32_t k = at - {lo}UL; {conv} x; memcpy(&x, &{arr}[k / {width}], {width}); uint8_t sh = 8 * ({width} - 1 - k % {width}); x = (x & ~(({conv})0xFF << sh)) | (({conv})v << sh); memcpy(&{arr}[k / {width}], &x, {width}); return true; }}"
        );
    };
    class("I", m.i.len(), 4, map.i, "uint32_t");
    class("F", m.f.len(), 4, map.f, "uint32_t");
    class("L", m.l.len(), 8, map.l, "uint64_t");
    if !m.m.is_empty() {
        let (lo, hi) = (2 * map.m, 2 * map.m + m.m.len() as u32);
        let _ = writeln!(bytes, "    if (at >= {lo}UL && at < {hi}UL) return M[at - {lo}UL];");
        let _ = writeln!(
            wbytes,
            "    if (at >= {lo}UL && at < {hi}UL) {{ M[at - {lo}UL] = v; return true; }}"
        );
    }
    format!(
        r#"
// ---- monitoring link (docs/arduino.md): Modbus RTU slave {slave}, {baud} 8N1 ----
// coils 0-{last_b}: the BOOL slots; holding registers 0-{last_h}: the I, F, L and M slots
// as a big-endian register file (I from {hi}, F from {hf}, L from {hl}, M from {hm});
// input registers 0-11: identity and state.
#define ALBA_LINK_SLAVE {slave}
#define ALBA_LINK_BAUD {baud}UL
#include "alba_link.h"
#include <string.h>

static uint8_t mem_byte(uint32_t at) {{
{bytes}    return 0;
}}

static bool set_mem_byte(uint32_t at, uint8_t v) {{
{wbytes}    (void)v;
    return false;
}}

static uint8_t link_read_bit(uint8_t fc, uint16_t at, bool *v) {{
    if (fc != 1 || at >= sizeof B) return 2;
    *v = B[at];
    return 0;
}}

static uint8_t link_read_reg(uint8_t fc, uint16_t at, uint16_t *v) {{
    if (fc == 4) {{
        const uint16_t info[12] = {{0x{magic:04X}, 1, sizeof B, {ni}, {nf}, {nl}, {nm}, SCAN_MS,
            0x{id_hi:04X}, 0x{id_lo:04X}, (uint16_t)(scans >> 16), (uint16_t)scans}};
        if (at < 12) *v = info[at];
        else if (at == 12) *v = major ? 1 : 0;
        else if (at == 13) *v = (uint16_t)(overruns > 0xFFFF ? 0xFFFF : overruns);
        else return 2;
        return 0;
    }}
    if (at >= {end}) return 2;
    *v = (uint16_t)mem_byte(2UL * at) << 8 | mem_byte(2UL * at + 1);
    return 0;
}}

static uint8_t link_write_bits(uint16_t at, uint16_t n, const uint8_t *packed) {{
    if ((uint32_t)at + n > sizeof B) return 2;
    for (uint16_t k = 0; k < n; k++) B[at + k] = (packed[k / 8] >> (k % 8)) & 1;
    return 0;
}}

static uint8_t link_write_regs(uint16_t at, uint16_t n, const uint8_t *be) {{
    if ((uint32_t)at + n > {end}) return 2;
    for (uint16_t k = 0; k < 2 * n; k++)
        if (!set_mem_byte(2UL * at + k, be[k])) return 2;
    return 0;
}}
"#,
        slave = LINK_SLAVE,
        baud = LINK_BAUD,
        last_b = m.b.len().saturating_sub(1),
        last_h = map.end.saturating_sub(1),
        hi = map.i,
        hf = map.f,
        hl = map.l,
        hm = map.m,
        magic = LINK_MAGIC,
        ni = m.i.len(),
        nf = m.f.len(),
        nl = m.l.len(),
        nm = m.m.len(),
        id_hi = program_id >> 16,
        id_lo = program_id & 0xFFFF,
        end = map.end,
    )
}

#[allow(clippy::too_many_arguments)]
fn render(
    prog: &Program,
    name: &str,
    project: &str,
    t: &Target,
    wiring: &[Wire],
    body: &str,
    program_id: u32,
) -> String {
    let m = &prog.init;
    let sys = prog.layout.system;
    let bools: Vec<u8> = m.b.iter().map(|b| u8::from(*b)).collect();
    let memory = [
        array("bool B", &bools),
        array(
            "int32_t I",
            &m.i.iter()
                .map(|v| {
                    if *v == i32::MIN {
                        "INT32_MIN".to_string()
                    } else {
                        v.to_string()
                    }
                })
                .collect::<Vec<_>>(),
        ),
        array("float F", &m.f.iter().map(|v| float_lit(*v)).collect::<Vec<_>>()),
        array(
            "int64_t L",
            &m.l.iter()
                .map(|v| {
                    if *v == i64::MIN {
                        "INT64_MIN".to_string()
                    } else {
                        format!("{v}LL")
                    }
                })
                .collect::<Vec<_>>(),
        ),
        array("uint8_t M", &m.m),
    ]
    .concat();
    let lvl = |on: bool| if on != t.active_low { "HIGH" } else { "LOW" };
    let mut setup = String::new();
    let mut read = String::new();
    let mut write = String::new();
    let mut safe = String::new();
    for w in wiring {
        let pin = match w.pin {
            Pin::D(n) => n.to_string(),
            Pin::A(n) => format!("A{n}"),
        };
        match w.address {
            Address::DigitalIn(_) => {
                let _ = writeln!(setup, "    pinMode({pin}, INPUT);");
                let _ = writeln!(read, "    B[{}] = digitalRead({pin}) == HIGH;", w.slot);
            }
            Address::DigitalOut(_) => {
                // The power-up level first, so the pin never glitches.
                let up = lvl(t.power_up_on.contains(&w.pin));
                let _ = writeln!(setup, "    digitalWrite({pin}, {up});\n    pinMode({pin}, OUTPUT);");
                let on_off = (lvl(true), lvl(false));
                let _ = writeln!(
                    write,
                    "    digitalWrite({pin}, B[{}] ? {} : {});",
                    w.slot, on_off.0, on_off.1
                );
                let _ = writeln!(safe, "    digitalWrite({pin}, {up});");
            }
            Address::AnalogIn(_) => {
                let _ = writeln!(read, "    I[{}] = analogRead({pin});", w.slot);
            }
            Address::AnalogOut(_) => {
                let _ = writeln!(setup, "    analogWrite({pin}, 0);\n    pinMode({pin}, OUTPUT);");
                let _ = writeln!(write, "    analogWrite({pin}, alba_duty(I[{}]));", w.slot);
                let _ = writeln!(safe, "    analogWrite({pin}, 0);");
            }
            Address::Marker { .. } => {}
        }
    }
    format!(
        r#"// {name}: generated by Alba {version} from the project "{project}" for the {board}
// ({mcu}, pin map below). Do not edit: change the project and export again.
// The scan runs every {scan} ms on millis() deadlines; the program sees the scheduled
// time (scan k at k*{scan} ms), like `alba sim`. Semantics: crates/engine/src/exec/.
#include <Arduino.h>
#include "alba_rt.h"

#define SCAN_MS {scan}UL

// Program memory: typed slots, as in the engine (system slots, I/O images, tags,
// temporaries and constants).
{memory}
static inline uint8_t alba_duty(int32_t v) {{ return v < 0 ? 0 : v > 255 ? 255 : (uint8_t)v; }}

static void read_inputs() {{
{read}}}

static void write_outputs() {{
{write}}}

// The power-up state (after a major fault too).
static void outputs_safe() {{
{safe}}}

// One scan of the control program at time `now` (ms). Returns 0, or the op of a
// runaway loop of backward jumps (a major fault).
static uint16_t run(uint32_t now) {{
    bool rc = 1;
    uint32_t back = 0;
    (void)now;
    (void)back;
{body}    return 0;
}}

static bool first_scan = true, major = false;
static uint32_t next_ms, vnow, half_s, half_ms, scans, overruns, scan_ms;

static void scan() {{
    B[{fs}] = first_scan;
    B[{on}] = 1;
    B[{c60}] = (half_s / 60) & 1;
    B[{c1}] = half_s & 1;
    B[{tog}] = scans & 1;
    I[{ovr}] = (int32_t)overruns;
    I[{smw22}] = scan_ms < 32767 ? (int32_t)scan_ms : 32767;
    alba_fault_code = 0;
    uint32_t t0 = micros();
    uint16_t stop = run(vnow);
    scan_ms = (micros() - t0) / 1000;
    first_scan = false;
    scans++;
    if (alba_fault_code) {{
        B[{minor}] = 1;
        I[{code}] = alba_fault_code;
    }}
    if (stop) major = true;
}}

{link}
static void advance(uint32_t ms) {{
    next_ms += ms;
    vnow += ms;
    half_ms += ms;
    while (half_ms >= 500) {{
        half_ms -= 500;
        half_s++;
    }}
}}

void setup() {{
{setup}{serial}    next_ms = millis();
}}

void loop() {{
{poll}    if (major) {{
        outputs_safe();
        return;
    }}
    uint32_t late = millis() - next_ms;
    if ((int32_t)late < 0) return;
    if (late >= SCAN_MS) {{
        uint32_t missed = late / SCAN_MS;
        overruns += missed;
        advance(missed * SCAN_MS);
    }}
    GPIOR0 = 1;  // the scan starts (simavr's harness counts its cycles)
    read_inputs();
    scan();
    if (major) outputs_safe();
    else write_outputs();
    GPIOR0 = 0;
    advance(SCAN_MS);
}}
"#,
        version = env!("CARGO_PKG_VERSION"),
        board = t.model.title(),
        mcu = t.model.mcu(),
        scan = t.scan_ms.max(1),
        fs = sys.first_scan.0,
        on = sys.always_on.0,
        c60 = sys.clock_60s.0,
        c1 = sys.clock_1s.0,
        tog = sys.scan_toggle.0,
        minor = sys.minor_fault.0,
        code = sys.fault_code.0,
        ovr = sys.stats.0 + 5,
        smw22 = sys.scan_time.0,
        link = if t.monitor {
            link_code(m, program_id)
        } else {
            String::new()
        },
        serial = if t.monitor {
            format!("    Serial.begin({LINK_BAUD}UL);\n")
        } else {
            String::new()
        },
        poll = if t.monitor {
            "    alba_link_poll();  // between scans: the link never delays one\n"
        } else {
            ""
        },
    )
}
