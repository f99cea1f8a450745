//! The byte-code interpreter firmware (issue 19): an Arduino sketch that runs
//! the byte code of docs/bytecode.md from EEPROM. It is generated, and its
//! op cases come from the sketch export's own C++ for each op
//! (`sketch::emit`) with the slot numbers turned into the operands it reads,
//! so the board's semantics are the export's, which the differential tests
//! hold to the engine's — written once.
//!
//! At start the interpreter checks the program in EEPROM: magic, format
//! version, length, CRC-32, the memory sizes against its arrays, the wiring,
//! and every op (its opcode, each slot against the sizes, each jump onto a
//! rung start). A missing or damaged program runs nothing: the output pins
//! stay inputs (their safe state) and the LED on D13 blinks (unless the pin
//! map wires an output to D13: then no pin moves at all).

use crate::bytecode::{self, Field};
use crate::sketch::{self, RUNTIME, Target};
use alba_ir::op::{AnySlot, MarkerSlot, S7Ctr, S7Tmr};
use alba_ir::{B, BinOp, Ctr, Cvt, D, F, I, L, Op, Pidt, TimeBase, Tmr, Width};
use std::fmt::Write as _;

/// Slot numbers the op templates carry: the k-th slot field is `S + k`.
const S: u32 = 60_001;
/// The op index in a template (`pc` in the generated code).
const PC: u32 = 59_999;
/// An S7 timer's resolution in a template.
const RES: u16 = 58_000;

// The board's capacity and program slot size live with the byte code that
// must fit them (`crate::bytecode`); re-exported here, where they always were.
pub use crate::bytecode::{Capacity, capacity, slot_size};

/// Every op kind and variant, its k-th slot field numbered `S + k`.
fn templates() -> Vec<Op> {
    let (b0, b1, b2) = (B(S), B(S + 1), B(S + 2));
    let (i0, i1, i2) = (I(S), I(S + 1), I(S + 2));
    let (f0, f1, f2) = (F(S), F(S + 1), F(S + 2));
    let (l0, l1, l2) = (L(S), L(S + 1), L(S + 2));
    let (d0, d1, d2) = (D(S), D(S + 1), D(S + 2));
    let tmr = Tmr { i: i0, b: b1 };
    let ctr = Ctr { i: i0, b: b1 };
    let s7t = S7Tmr { i: i0, b: b1, res: RES };
    let s7c = S7Ctr { i: i0, b: b1 };
    let mut out = vec![
        Op::Rung,
        Op::Nop,
        Op::Afi,
        Op::Not,
        Op::True,
        Op::Xic(b0),
        Op::Xio(b0),
        Op::Ote(b0),
        Op::Otl(b0),
        Op::Otu(b0),
        Op::Ons(b0),
        Op::Ld(b0),
        Op::Ldn(b0),
        Op::Or(b0),
        Op::Orn(b0),
        Op::Ed(b0),
        Op::Osr(b0, b1),
        Op::Osf(b0, b1),
        Op::CopyB(b0, b1),
        Op::BrOpen { save: b0, acc: b1 },
        Op::BrNext { save: b0, acc: b1 },
        Op::BrClose { acc: b0 },
        Op::Tp(tmr),
        Op::ResT(tmr),
        Op::Ctu(ctr),
        Op::Ctd(ctr),
        Op::ResC(ctr),
        Op::LimI(i0, i1, i2),
        Op::LimF(f0, f1, f2),
        Op::LimL(l0, l1, l2),
        Op::LimD(d0, d1, d2),
        Op::MeqI(i0, i1, i2),
        Op::MeqL(l0, l1, l2),
        Op::Narrow(i0, Width::W8),
        Op::Narrow(i0, Width::W16),
        Op::CopyI(i0, i1),
        Op::S7Ton(s7t),
        Op::S7Tonr(s7t),
        Op::S7Tof(s7t),
        Op::S7ResT(s7t),
        Op::S7Ctu(s7c),
        Op::S7Ctd(s7c),
        Op::S7Ctud(s7c),
        Op::S7ResC(s7c),
        Op::Pid(Pidt { f: f0, i: i1, b: b2 }),
    ];
    for slot in [
        MarkerSlot::Byte(I(S + 1)),
        MarkerSlot::Word(I(S + 1)),
        MarkerSlot::DWord(I(S + 1)),
        MarkerSlot::Real(F(S + 1)),
    ] {
        out.push(Op::LdM { byte: S, slot });
        out.push(Op::StM { byte: S, slot });
    }
    // every variant in the format's order (bytecode's own tables)
    for base in TimeBase::ALL {
        out.extend([Op::Ton(tmr, base), Op::Tof(tmr, base), Op::Rto(tmr, base)]);
    }
    for c in bytecode::CMPS {
        out.extend([
            Op::CmpI(c, i0, i1),
            Op::CmpF(c, f0, f1),
            Op::CmpL(c, l0, l1),
            Op::CmpD(c, d0, d1),
        ]);
    }
    for o in bytecode::BINS.into_iter().chain(bytecode::CMPS.map(BinOp::Cmp)) {
        out.extend([
            Op::BinI(o, i0, i1, i2),
            Op::BinF(o, f0, f1, f2),
            Op::BinL(o, l0, l1, l2),
            Op::BinD(o, d0, d1, d2),
        ]);
    }
    for o in bytecode::UNS {
        out.extend([
            Op::UnI(o, i0, i1),
            Op::UnF(o, f0, f1),
            Op::UnL(o, l0, l1),
            Op::UnD(o, d0, d1),
        ]);
    }
    out.extend(
        [
            Cvt::IF(i0, f1),
            Cvt::FI(f0, i1),
            Cvt::IL(i0, l1),
            Cvt::LI(l0, i1),
            Cvt::ID(i0, d1),
            Cvt::DI(d0, i1),
            Cvt::LF(l0, f1),
            Cvt::FL(f0, l1),
            Cvt::LD(l0, d1),
            Cvt::DL(d0, l1),
            Cvt::FD(f0, d1),
            Cvt::DF(d0, f1),
        ]
        .map(Op::Cvt),
    );
    out
}

/// The C++ that reads `fields` into `s0…`, `x0…` (bytes) and `w0…` (words).
fn reads(fields: &[Field], first_slot: usize, first_byte: usize) -> String {
    let (mut s, mut x, mut w) = (first_slot, first_byte, 0);
    let mut out = String::new();
    for f in fields {
        match f {
            Field::Slot(area, _) => {
                let _ = write!(out, "uint16_t s{s} = rd_slot({area}); ");
                s += 1;
            }
            Field::Byte(_) => {
                let _ = write!(out, "uint8_t x{x} = rd8(); (void)x{x}; ");
                x += 1;
            }
            Field::Word(_) => {
                let _ = write!(out, "uint16_t w{w} = rd16(); (void)w{w}; ");
                w += 1;
            }
        }
    }
    out
}

/// How far each slot field of a template reaches (`Op::slots`, with their
/// extents): the field's slot plus this must fit in its area.
fn extents(op: &Op, fields: &[Field]) -> Vec<u32> {
    fields
        .iter()
        .map(|f| {
            let Field::Slot(area, base) = *f else { return 0 };
            op.slots()
                .into_iter()
                .filter_map(|slot| {
                    let (a, v, n) = match slot {
                        AnySlot::B(v) => (0, v, 1),
                        AnySlot::I(v) => (1, v, 1),
                        AnySlot::F(v) => (2, v, 1),
                        AnySlot::L(v) => (3, v, 1),
                        AnySlot::D(v) => (4, v, 1),
                        AnySlot::M(v, n) => (5, v, n),
                    };
                    // the slot belongs to the last field of its area at or below it
                    let owner = fields
                        .iter()
                        .filter_map(|g| match *g {
                            Field::Slot(ga, x) if ga == a && x <= v => Some(x),
                            _ => None,
                        })
                        .max()?;
                    (a == area && owner == base).then(|| v - base + n)
                })
                .max()
                .unwrap_or(1)
        })
        .collect()
}

/// The op's C++ from the export with the template's numbers as operands.
fn body(op: &Op) -> Option<String> {
    let mut code = sketch::emit(op, PC).ok()?;
    for k in 0..3 {
        code = code.replace(&(S + k).to_string(), &format!("s{k}"));
    }
    Some(
        code.replace(&PC.to_string(), "pc")
            .replace(&RES.to_string(), "(w0 ? w0 : 1)"),
    )
}

/// The ops the interpreter runs on a board of capacity `cap`: those the
/// engine defines and the export translates (no LINT op where it holds no
/// LINT).
fn runs(op: &Op, cap: Capacity) -> Option<String> {
    if !op.is_defined() || (cap.l == 0 && op.slots().iter().any(|s| matches!(s, AnySlot::L(_)))) {
        return None;
    }
    body(op)
}

/// The `switch` of the interpreter (`run`), the layout table the checker
/// walks (`LAYOUT`: per op and variant, its opcode, its variant byte or 0xFF,
/// its field count, then per field a kind-and-area byte and an extent), and
/// per opcode the offset of its first entry there (`FIRST`, 0xFFFF for none).
fn cases(cap: Capacity) -> (String, String, String) {
    // Opcode → its variants (templates with their fields).
    type Variants = Vec<(Op, Vec<Field>)>;
    let mut groups: Vec<(u8, Variants)> = Vec::new();
    for op in templates() {
        let (code, fields) = bytecode::fields(&op, 0);
        match groups.iter_mut().find(|(c, _)| *c == code) {
            Some((_, v)) => v.push((op, fields)),
            None => groups.push((code, vec![(op, fields)])),
        }
    }
    let (mut run, mut layout) = (String::new(), String::new());
    let mut first: Vec<Option<usize>> = vec![None; 0x42];
    let mut at = 0usize;
    // (the checker checks the slots before a variant byte with the variant's extents)
    let mut entry = |code: u8, sel: Option<u8>, op: &Op, fields: &[Field]| {
        first[code as usize].get_or_insert(at);
        at += 3 + 2 * fields.len();
        let _ = write!(
            layout,
            "    0x{code:02x}, 0x{:02x}, {},",
            sel.unwrap_or(0xFF),
            fields.len()
        );
        let ext = extents(op, fields);
        for (f, ext) in fields.iter().zip(ext) {
            let _ = match f {
                Field::Slot(area, _) => write!(layout, " {area}, {ext},"),
                Field::Byte(_) => write!(layout, " 0x40, 0,"),
                Field::Word(_) => write!(layout, " 0x80, 0,"),
            };
        }
        layout.push('\n');
    };
    for (code, ops) in groups {
        if ops.len() == 1 {
            let (op, fields) = &ops[0];
            let Some(b) = runs(op, cap) else { continue };
            let r = reads(fields, 0, 0);
            let _ = writeln!(run, "        case 0x{code:02x}: {{ {r}{b} break; }}");
            entry(code, None, op, fields);
            continue;
        }
        // Variants told apart by their first byte field; the fields before it are common.
        let sel = ops[0].1.iter().position(|f| matches!(f, Field::Byte(_))).unwrap_or(0);
        let head = reads(&ops[0].1[..=sel], 0, 0);
        let slots_before = ops[0].1[..sel].iter().filter(|f| matches!(f, Field::Slot(..))).count();
        let mut rv = String::new();
        for (op, fields) in &ops {
            let Field::Byte(v) = fields[sel] else { continue };
            let Some(b) = runs(op, cap) else { continue };
            let r = reads(&fields[sel + 1..], slots_before, 1);
            let _ = writeln!(rv, "            case {v}: {{ {r}{b} break; }}");
            entry(code, Some(v), op, fields);
        }
        let _ = writeln!(
            run,
            "        case 0x{code:02x}: {{ {head}\n            switch (x0) {{\n{rv}            default: return 0xFFFF;\n            }}\n            break;\n        }}"
        );
    }
    let first = first
        .iter()
        .map(|e| e.map_or("0xFFFF".to_string(), |e| e.to_string()))
        .collect::<Vec<_>>()
        .join(", ");
    (run, layout, first)
}

/// The interpreter sketch for `t`'s board (`.ino` and `alba_rt.h`); with
/// `program`, that byte code is in its EEPROM image (the ELF's `.eeprom`,
/// which simavr and avrdude load), as `alba download` would leave it.
pub fn generate(t: &Target, program: Option<&[u8]>) -> Vec<(String, String)> {
    let c = capacity(t.model);
    let (run, layout, first) = cases(c);
    let eeprom = match program {
        Some(p) => {
            let mut s = String::from(
                "// The program, as a download leaves it in EEPROM.\nconst uint8_t alba_program[] EEMEM __attribute__((used)) = {",
            );
            for (k, b) in p.iter().enumerate() {
                s.push_str(if k % 16 == 0 { "\n    " } else { " " });
                let _ = write!(s, "0x{b:02x},");
            }
            s.push_str("\n};\n");
            s
        }
        None => String::new(),
    };
    let lvl = |on: bool| if on != t.active_low { "HIGH" } else { "LOW" };
    let (mut map, mut map_at) = (Vec::new(), vec!["0".to_string()]);
    for (kind, dir) in alba_model::board::Dir::ALL.iter().enumerate() {
        for ch in 0..t.map.pins(*dir).len().min(bytecode::MAX_CHANNELS as usize) {
            let pin = bytecode::map_pin(t, kind as u8, ch as u32).unwrap_or(0xFF);
            map.push(format!("0x{pin:02x}"));
        }
        map_at.push(map.len().to_string());
    }
    if map.is_empty() {
        map.push("0xff".into());
    }
    // The error LED is the board's own on D13, unless the pin map wires D13 (blinking
    // an actuator is no signal, and driving an input's wire is worse): then there is none.
    let d13_wired = alba_model::board::Dir::ALL
        .iter()
        .any(|d| t.map.pins(*d).contains(&alba_model::board::Pin::D(13)));
    let (led_setup, led_blink, led_off) = if d13_wired {
        ("", "", "")
    } else {
        (
            "        pinMode(LED_BUILTIN, OUTPUT);\n",
            "        digitalWrite(LED_BUILTIN, (millis() / 250) & 1);\n",
            "    digitalWrite(LED_BUILTIN, LOW);  // no error (still an input if it never blinked)\n",
        )
    };
    let ino = format!(
        r#"// The Alba byte-code interpreter for the {board} ({mcu}), generated by Alba {version}.
// It runs the program in EEPROM (docs/bytecode.md); its op cases are the sketch export's
// C++ for each op, so it computes what an exported sketch computes.
#include <Arduino.h>
#include <avr/eeprom.h>
#include <avr/pgmspace.h>
#define ALBA_INLINE __attribute__((noinline, unused))
#include "alba_rt.h"

{eeprom}
static bool B[{cb}];
static int32_t I[{ci}];
static float F[{cf}];
static int64_t L[{cl}];
static uint8_t M[{cm}];
// Sizes the program uses, by area (B, I, F, L, D, M); what the arrays hold.
static uint16_t N[6];
static const uint16_t CAP[6] PROGMEM = {{{cb}, {ci}, {cf}, {lcap}, 0, {cm}}};
static uint8_t wide;
static uint16_t code_start, code_end, n_ops, scan_period = 10;
static {bslot} sys_b[9];
static {islot} sys_i[4];
// The wires: per wire its kind (0 DI, 1 DO, 2 AI, 3 AO) in the top 2 bits and its channel
// (below 64) under them, and its pin; its slot is its image's base + the channel.
static uint8_t n_wires, w_wire[{cw}], w_pin[{cw}];
static uint16_t image_base[4];
static uint16_t p;
static uint32_t prog_id;
static bool first_scan = true, major = false, loaded = false;

// What this firmware is built for: the header's board id (board, pin map, output
// polarity), and the pin map — per kind (DI, DO, AI, AO) the pin byte of each channel
// from MAP_AT[kind] (0xFF: a pin the board cannot use there).
#define BOARD_ID 0x{board_id:04X}
static const uint8_t MAP[] PROGMEM = {{{map}}};
static const uint8_t MAP_AT[5] PROGMEM = {{{map_at}}};

static uint8_t rd8() {{ return eeprom_read_byte((const uint8_t *)(uintptr_t)p++); }}
static __attribute__((noinline)) uint16_t rd16() {{ uint16_t v = rd8(); return v | (uint16_t)rd8() << 8; }}
static __attribute__((noinline)) uint32_t rd32() {{ uint32_t v = rd16(); return v | (uint32_t)rd16() << 16; }}
static __attribute__((noinline)) uint16_t rd_slot(uint8_t area) {{ return (wide >> area) & 1 ? rd16() : rd8(); }}

// Per op and variant the interpreter runs: opcode, variant byte (0xFF: none), field
// count, then per field its kind (0-5: a slot of that area; 0x40 a byte; 0x80 a word)
// and, for a slot, how far it reaches, grouped by opcode; FIRST: where each opcode's
// entries start (0xFFFF: an opcode it does not run). Ends with 0.
static const uint8_t LAYOUT[] PROGMEM = {{
{layout}    0
}};

static const uint16_t FIRST[] PROGMEM = {{{first}}};

// The entry of `op` (with variant `sel`, or any when `any`), or 0xFFFF.
static uint16_t entry_of(uint8_t op, uint8_t sel, bool any) {{
    if (op >= sizeof FIRST / sizeof FIRST[0]) return 0xFFFF;
    for (uint16_t e = pgm_read_word(&FIRST[op]); e != 0xFFFF && pgm_read_byte(&LAYOUT[e]) == op;
         e += 3 + 2 * pgm_read_byte(&LAYOUT[e + 2]))
        if (any || pgm_read_byte(&LAYOUT[e + 1]) == sel) return e;
    return 0xFFFF;
}}

// The op at p, read without running it (p moves past it): 1 if it is well formed (a
// known opcode and variant, each slot and its extent inside memory); with `jumps`, a
// jump must also land on a rung that starts an op inside the code.
static uint8_t op_start(uint16_t to);
static uint8_t check_op(bool jumps) {{
    uint8_t op = rd8();
    if (op == 0x0f) {{
        int16_t rel = (int16_t)rd16();
        uint16_t to = p + rel;
        return !jumps || (to >= code_start && to < code_end &&
                          eeprom_read_byte((const uint8_t *)(uintptr_t)to) == 0x01 && op_start(to));
    }}
    if (op == 0x2d || op == 0x2e) {{
        uint16_t s0 = rd_slot(5); uint8_t bit = rd8(); uint16_t s1 = rd_slot(0);
        return s0 < N[5] && bit < 8 && s1 < N[0];
    }}
    uint16_t e = entry_of(op, 0, true);
    if (e == 0xFFFF) return 0;
    bool variants = pgm_read_byte(&LAYOUT[e + 1]) != 0xFF;
    // slots read before the variant byte: checked once the variant's extents are known
    uint16_t before[2];
    uint8_t n_before = 0;
    for (uint8_t k = 0; k < pgm_read_byte(&LAYOUT[e + 2]); k++) {{
        uint8_t kind = pgm_read_byte(&LAYOUT[e + 3 + 2 * k]), ext = pgm_read_byte(&LAYOUT[e + 4 + 2 * k]);
        if (kind == 0x80) rd16();
        else if (kind == 0x40) {{
            uint8_t x = rd8();
            if (variants) {{
                // the variant byte: its own entry (the fields before it are the same kinds)
                e = entry_of(op, x, false);
                if (e == 0xFFFF) return 0;
                variants = false;
                for (uint8_t j = 0; j < n_before; j++) {{
                    uint8_t a = pgm_read_byte(&LAYOUT[e + 3 + 2 * j]);
                    if ((uint32_t)before[j] + pgm_read_byte(&LAYOUT[e + 4 + 2 * j]) > N[a]) return 0;
                }}
            }}
        }} else if (variants && n_before < 2) before[n_before++] = rd_slot(kind);
        else if ((uint32_t)rd_slot(kind) + ext > N[kind]) return 0;
    }}
    return 1;
}}

// 1 if an op starts at `to` (the ops from the first, walked again).
static uint8_t op_start(uint16_t to) {{
    uint16_t keep = p;
    p = code_start;
    while (p < to && check_op(false)) {{}}
    uint8_t at = p == to;
    p = keep;
    return at;
}}

// Every op, without running it: 1 if the code is sound — the first op starts a rung,
// every op is well formed, the last ends where the body does, and they are as many as
// the header of the ops says.
static uint8_t check_code() {{
    p = code_start;
    if (p < code_end && eeprom_read_byte((const uint8_t *)(uintptr_t)p) != 0x01) return 0;
    uint16_t n = 0;
    while (p < code_end) {{
        if (!check_op(true)) return 0;
        n++;
    }}
    return p == code_end && n == n_ops;
}}

static uint32_t crc32_eeprom(uint16_t from, uint16_t len) {{
    uint32_t c = 0xFFFFFFFFUL;
    for (uint16_t k = 0; k < len; k++) {{
        c ^= eeprom_read_byte((const uint8_t *)(uintptr_t)(from + k));
        for (uint8_t j = 0; j < 8; j++) c = (c >> 1) ^ (0xEDB88320UL & (0UL - (c & 1)));
    }}
    return ~c;
}}

// Checks and loads the program in EEPROM: 0 when there is none that can run.
// EEPROM: two program slots and, in the last byte, which one runs (0xFF, erased: the
// first). A download writes the other slot and switches only once it checks.
#define SLOT_SIZE ((E2END + 1UL - 1) / 2)
#define SELECTOR (E2END)
static uint16_t slot_base(uint8_t slot) {{ return slot == 1 ? SLOT_SIZE : 0; }}
static uint8_t active_slot() {{ return eeprom_read_byte((const uint8_t *)(uintptr_t)SELECTOR) == 1 ? 1 : 0; }}

// The widths byte a program with the sizes N must have (bit k: area k has over 256 slots).
static uint8_t widths() {{
    uint8_t w = 0;
    for (uint8_t a = 0; a < 6; a++) if (N[a] > 256) w |= 1 << a;
    return w;
}}

// The checks are those of the host's `bytecode::decode_for` for this board, one for one:
// the firmware runs exactly what the host accepts.
static uint8_t load_at(uint16_t base) {{
    p = base;
    if (rd8() != 'A' || rd8() != 'L' || rd8() != 'B' || rd8() != 'C' || rd8() != {version_byte}) return 0;
    wide = rd8();
    if (rd16() != BOARD_ID) return 0;  // compiled for another board or pin map
    prog_id = rd32();
    scan_period = rd16();
    rd16();
    uint32_t len = rd32(), crc = rd32();
    if (len > SLOT_SIZE - 24 || crc32_eeprom(base + 24, (uint16_t)len) != crc) return 0;
    code_end = base + 24 + (uint16_t)len;
    for (uint8_t a = 0; a < 6; a++) {{
        uint16_t n = rd16();
        if (n > pgm_read_word(&CAP[a])) return 0;
        N[a] = n;
    }}
    if (wide != widths()) return 0;
    // The I/O images: DI and DO in the BOOL area, AI and AO in the integer area.
    uint16_t reg[8];
    for (uint8_t k = 0; k < 8; k += 2) {{
        reg[k] = image_base[k / 2] = rd16();
        reg[k + 1] = rd16();
        if ((uint32_t)reg[k] + reg[k + 1] > N[k < 4 ? 0 : 1]) return 0;
    }}
    for (uint8_t k = 0; k < 9; k++) {{
        uint16_t s = rd16();
        if (s >= N[0]) return 0;
        sys_b[k] = s;
    }}
    for (uint8_t k = 0; k < 4; k++) {{
        uint16_t s = rd16();
        if ((uint32_t)s + (k == 2 ? {stats} : 1) > N[1]) return 0;
        sys_i[k] = s;
    }}
    for (uint16_t n = rd16(); n; n--) {{ uint16_t s = rd16(); if (s >= N[0]) return 0; B[s] = 1; }}
    for (uint16_t n = rd16(); n; n--) {{ uint16_t s = rd16(); if (s >= N[1]) return 0; I[s] = (int32_t)rd32(); }}
    for (uint16_t n = rd16(); n; n--) {{ uint16_t s = rd16(); if (s >= N[2]) return 0; uint32_t v = rd32(); memcpy(&F[s], &v, 4); }}
    for (uint16_t n = rd16(); n; n--) {{ uint16_t s = rd16(); if (s >= N[3]) return 0; uint64_t v = rd32(); v |= (uint64_t)rd32() << 32; L[s] = (int64_t)v; }}
    for (uint16_t n = rd16(); n; n--) {{ rd16(); rd32(); rd32(); return 0; }}  // LREAL: not on this board
    for (uint16_t n = rd16(); n; n--) {{ uint16_t s = rd16(); if (s >= N[5]) return 0; M[s] = rd8(); }}
    // Each wire inside its image, on the pin this board's pin map has for its channel.
    n_wires = 0;
    for (uint16_t n = rd16(); n; n--) {{
        uint8_t kind = rd8(); uint16_t ch = rd16(); uint8_t pin = rd8(); uint16_t slot = rd16();
        if (n_wires >= {cw} || kind > 3 || ch >= reg[2 * kind + 1] || slot != (uint32_t)reg[2 * kind] + ch) return 0;
        uint8_t at = pgm_read_byte(&MAP_AT[kind]), channels = pgm_read_byte(&MAP_AT[kind + 1]) - at;
        if (ch >= channels || pin == 0xFF || pgm_read_byte(&MAP[at + ch]) != pin) return 0;
        w_pin[n_wires] = pin & 0x80 ? A0 + (pin & 0x7F) : pin;
        w_wire[n_wires++] = (uint8_t)(kind << 6 | ch);
    }}
    n_ops = rd16();
    code_start = p;
    return check_code();
}}

// Loads the running slot's program into fresh memory.
static uint8_t load() {{
    memset(B, 0, sizeof B);
    memset(I, 0, sizeof I);
    memset(F, 0, sizeof F);
    memset(L, 0, sizeof L);
    memset(M, 0, sizeof M);
    return load_at(slot_base(active_slot()));
}}

// ---- download (docs/bytecode.md "Download"): Intel HEX records on the serial port,
// between scans. Each record is answered with a line: `K` (written), `E` and the
// source's error flag in hex (01 not hex, 02 record type, 04 checksum, 08 no data,
// 10 address overflow, 20 write-verify), after the end record `S` and the 16-bit
// sum of the data bytes (the new program checks and runs) or `E40` (it does not:
// the old one keeps running); ESC drops the download (`A`). `R` + 4 hex digits
// (address) + 2 (count): that many bytes of the running slot, in hex. `I`: the board's
// identity, `I`, the format version (2 hex digits), the board id (4), the program slot's
// size (4), the state (`R` a program runs, `N` none that checks, `F` stopped on a major
// fault) and the board's name.
static char line[44];  // the longest record: `:10AAAA00`, 32 hex digits of data, its checksum
static uint8_t line_len;
static uint16_t dl_sum;
static bool dl_on;
static bool reload;

static inline uint8_t w_kind(uint8_t k) {{ return w_wire[k] >> 6; }}
static inline uint16_t w_slot(uint8_t k, uint8_t kind) {{ return image_base[kind] + (w_wire[k] & 63); }}

static uint8_t hexval(char c) {{ return c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10; }}
static bool ishex(char c) {{ return (c >= '0' && c <= '9') || ((c | 0x20) >= 'a' && (c | 0x20) <= 'f'); }}
static uint8_t hexbyte(uint8_t at) {{ return hexval(line[at]) << 4 | hexval(line[at + 1]); }}

static void hex_out(uint16_t v, uint8_t digits) {{
    while (digits--) {{
        uint8_t d = (v >> (4 * digits)) & 15;
        Serial.write(d < 10 ? '0' + d : 'A' - 10 + d);
    }}
}}

static void reply_flag(uint8_t f) {{
    Serial.write('E');
    hex_out(f, 2);
    Serial.write('\n');
}}

static void outputs_safe();

static void record() {{
    if (line[0] == 'I') {{
        Serial.write('I');
        hex_out({version_byte}, 2);
        hex_out(BOARD_ID, 4);
        hex_out(SLOT_SIZE, 4);
        Serial.write(!loaded ? 'N' : major ? 'F' : 'R');
        Serial.println(F("{model}"));
        return;
    }}
    if (line[0] == 'R') {{
        // read-back of the running slot
        uint16_t at = 0; uint8_t n = 0;
        for (uint8_t k = 1; k < 5; k++) at = at << 4 | hexval(line[k]);
        n = hexbyte(5);
        uint16_t base = slot_base(active_slot());
        for (uint8_t k = 0; k < n && (uint32_t)at + k < SLOT_SIZE; k++) {{
            uint8_t b = eeprom_read_byte((const uint8_t *)(uintptr_t)(base + at + k));
            hex_out(b, 2);
        }}
        Serial.write('\n');
        return;
    }}
    if (line[0] != ':' || line_len < 11 || (line_len & 1) == 0) {{ reply_flag(line_len < 11 ? 0x08 : 0x01); return; }}
    for (uint8_t k = 1; k < line_len; k++) if (!ishex(line[k])) {{ reply_flag(0x01); return; }}
    uint8_t n = hexbyte(1), type = hexbyte(7);
    if (line_len != 11 + 2 * n) {{ reply_flag(0x08); return; }}
    uint8_t sum = 0;
    for (uint8_t k = 1; k < line_len; k += 2) sum += hexbyte(k);
    if (sum != 0) {{ reply_flag(0x04); return; }}
    if (type > 1) {{ reply_flag(0x02); return; }}
    uint8_t target = active_slot() ^ 1;
    uint16_t base = slot_base(target);
    if (!dl_on) {{ dl_on = true; dl_sum = 0; }}
    if (type == 1) {{
        dl_on = false;
        // The new slot must check before it runs. Checking it overwrites the running
        // program's tables, so that one stops first with its outputs safe; refused, the
        // old program starts again (from its initial values), as after a power cycle.
        outputs_safe();
        if (!load_at(base)) {{ loaded = false; reply_flag(0x40); reload = true; return; }}
        eeprom_update_byte((uint8_t *)(uintptr_t)SELECTOR, target);
        Serial.write('S');
        hex_out(dl_sum, 4);
        Serial.write('\n');
        reload = true;
        return;
    }}
    if (n == 0) {{ reply_flag(0x08); return; }}
    uint16_t at = (uint16_t)hexbyte(3) << 8 | hexbyte(5);
    if ((uint32_t)at + n > SLOT_SIZE) {{ reply_flag(0x10); return; }}
    for (uint8_t k = 0; k < n; k++) {{
        uint8_t b = hexbyte(9 + 2 * k);
        eeprom_update_byte((uint8_t *)(uintptr_t)(base + at + k), b);
        if (eeprom_read_byte((const uint8_t *)(uintptr_t)(base + at + k)) != b) {{ reply_flag(0x20); return; }}
        dl_sum += b;
    }}
    Serial.write('K');
    Serial.write('\n');
}}

static inline uint8_t alba_duty(int32_t v) {{ return v < 0 ? 0 : v > 255 ? 255 : (uint8_t)v; }}

static void read_inputs() {{
    for (uint8_t k = 0; k < n_wires; k++) {{
        uint8_t kind = w_kind(k);
        if (kind == 0) B[w_slot(k, 0)] = digitalRead(w_pin[k]) == HIGH;
        else if (kind == 2) I[w_slot(k, 2)] = analogRead(w_pin[k]);
    }}
}}

static void write_outputs() {{
    for (uint8_t k = 0; k < n_wires; k++) {{
        uint8_t kind = w_kind(k);
        if (kind == 1) digitalWrite(w_pin[k], B[w_slot(k, 1)] ? {on} : {off});
        else if (kind == 3) analogWrite(w_pin[k], alba_duty(I[w_slot(k, 3)]));
    }}
}}

static void outputs_safe() {{
    for (uint8_t k = 0; k < n_wires; k++) {{
        uint8_t kind = w_kind(k);
        if (kind == 1) digitalWrite(w_pin[k], {off});
        else if (kind == 3) analogWrite(w_pin[k], 0);
    }}
}}

// One scan at time `now` (ms): 0, or not 0 for a major fault (a runaway loop).
static uint16_t run(uint32_t now) {{
    bool rc = 1;
    uint32_t back = 0;
    (void)now;
    p = code_start;
    while (p < code_end) {{
        uint16_t pc = p;
        (void)pc;
        switch (rd8()) {{
{run}        case 0x0f: {{ int16_t rel = (int16_t)rd16();
            if (rc) {{ if (rel < 0 && ++back > 1000000UL) return pc ? pc : 1; p += rel; }}
            break; }}
        case 0x2d: {{ uint16_t s0 = rd_slot(5); uint8_t bit = rd8() & 7; uint16_t s1 = rd_slot(0);
            B[s1] = (M[s0] >> bit) & 1; break; }}
        case 0x2e: {{ uint16_t s0 = rd_slot(5); uint8_t bit = rd8() & 7; uint16_t s1 = rd_slot(0);
            if (B[s1]) M[s0] |= (uint8_t)(1 << bit); else M[s0] &= (uint8_t)~(1 << bit); break; }}
        default: return 0xFFFF;
        }}
    }}
    return 0;
}}

static uint32_t next_us, vnow, half_s, half_ms, scans, overruns, scan_ms;

static void scan() {{
    B[sys_b[0]] = first_scan;
    B[sys_b[2]] = 1;
    B[sys_b[3]] = (half_s / 60) & 1;
    B[sys_b[4]] = half_s & 1;
    B[sys_b[5]] = scans & 1;
    I[sys_i[2] + 5] = (int32_t)overruns;
    I[sys_i[1]] = scan_ms < 32767 ? (int32_t)scan_ms : 32767;
    alba_fault_code = 0;
    uint32_t t0 = micros();
    uint16_t stop = run(vnow);
    scan_ms = (micros() - t0) / 1000;
    first_scan = false;
    scans++;
    if (alba_fault_code) {{
        B[sys_b[1]] = 1;
        I[sys_i[0]] = alba_fault_code;
    }}
    if (stop) major = true;
}}

static void advance(uint32_t ms) {{
    next_us += ms * 1000UL;
    vnow += ms;
    half_ms += ms;
    while (half_ms >= 500) {{
        half_ms -= 500;
        half_s++;
    }}
}}

static void start() {{
    loaded = load();
    first_scan = true;
    major = false;
    scans = overruns = 0;
    vnow = half_s = half_ms = 0;
    if (!loaded) {{
{led_setup}        return;
    }}
{led_off}    B[sys_b[6]] = 1;  // S:IOOK: the pins are local
    B[sys_b[8]] = 1;  // S:STOREOK
    for (uint8_t k = 0; k < n_wires; k++) {{
        uint8_t kind = w_kind(k), pin = w_pin[k];
        if (kind == 0) pinMode(pin, INPUT);
        else if (kind == 1) {{ digitalWrite(pin, {off}); pinMode(pin, OUTPUT); }}
        else if (kind == 3) {{ analogWrite(pin, 0); pinMode(pin, OUTPUT); }}
    }}
    // Deadlines on micros(): scan k starts k periods after the first, to 4 µs.
    next_us = micros();
}}

// ---- monitoring link (docs/bytecode.md "Monitoring"): the exported sketch's Modbus RTU
// slave {slave}, {baud} 8N1, on the same serial port, so `alba run --io board:PORT`
// attaches to the board. Between frames and lines, a byte that starts neither a record
// (`:`), a read-back (`R`), ESC nor an end of line starts a link frame.
#define ALBA_LINK_SLAVE {slave}
#define ALBA_LINK_BAUD {baud}UL
#include "alba_link.h"

// Byte `at` of the link's big-endian register file (the I, F and L slots, then the
// marker bytes), or 0 past its end.
static uint8_t *mem_byte(uint32_t at) {{
    uint32_t n = 4UL * N[1];
    if (at < n) return (uint8_t *)&I[at / 4] + 3 - at % 4;
    at -= n;
    n = 4UL * N[2];
    if (at < n) return (uint8_t *)&F[at / 4] + 3 - at % 4;
    at -= n;
    n = 8UL * N[3];
    if (at < n) return (uint8_t *)&L[at / 8] + 7 - at % 8;
    at -= n;
    return at < N[5] ? &M[at] : 0;
}}

static uint16_t link_regs() {{ return 2 * N[1] + 2 * N[2] + 4 * N[3] + (N[5] + 1) / 2; }}

static uint8_t link_read_bit(uint8_t fc, uint16_t at, bool *v) {{
    if (!loaded) return 4;
    if (fc != 1 || at >= N[0]) return 2;
    *v = B[at];
    return 0;
}}

static uint8_t link_read_reg(uint8_t fc, uint16_t at, uint16_t *v) {{
    if (!loaded) return 4;
    if (fc == 4) {{
        const uint16_t info[12] = {{0x{magic:04X}, 1, N[0], N[1], N[2], N[3], N[5], scan_period,
            (uint16_t)(prog_id >> 16), (uint16_t)prog_id, (uint16_t)(scans >> 16), (uint16_t)scans}};
        if (at < 12) *v = info[at];
        else if (at == 12) *v = major ? 1 : 0;
        else if (at == 13) *v = (uint16_t)(overruns > 0xFFFF ? 0xFFFF : overruns);
        else return 2;
        return 0;
    }}
    if (at >= link_regs()) return 2;
    uint8_t *hi = mem_byte(2UL * at), *lo = mem_byte(2UL * at + 1);
    *v = (uint16_t)(hi ? *hi : 0) << 8 | (lo ? *lo : 0);
    return 0;
}}

static uint8_t link_write_bits(uint16_t at, uint16_t n, const uint8_t *packed) {{
    if (!loaded) return 4;
    if ((uint32_t)at + n > N[0]) return 2;
    for (uint16_t k = 0; k < n; k++) B[at + k] = (packed[k / 8] >> (k % 8)) & 1;
    return 0;
}}

static uint8_t link_write_regs(uint16_t at, uint16_t n, const uint8_t *be) {{
    if (!loaded) return 4;
    if ((uint32_t)at + n > link_regs()) return 2;
    for (uint16_t k = 0; k < 2 * n; k++)
        if (!mem_byte(2UL * at + k)) return 2;
    for (uint16_t k = 0; k < 2 * n; k++) *mem_byte(2UL * at + k) = be[k];
    return 0;
}}

// Bytes from the serial port, between scans: download lines or link frames.
static void serial_poll() {{
    while (Serial.available()) {{
        char c = Serial.read();
        if (line_len == 0 && (alba_link_len > 0 || (c != ':' && c != 'R' && c != 'I' && c != 0x1B && c != '\r' && c != '\n'))) {{
            alba_link_byte((uint8_t)c);
        }} else if (c == 0x1B) {{
            line_len = 0;
            dl_on = false;
            Serial.write('A');
            Serial.write('\n');
        }} else if (c == '\r' || c == '\n') {{
            if (line_len) record();
            line_len = 0;
        }} else if (line_len < sizeof line) line[line_len++] = c;
        else line_len = sizeof line;  // too long: answered as not a record at its end
    }}
    alba_link_end();
}}

// Lamp test (the 8051 PLC's, 002_… §4.1.6), with or without a program: DI channel 0 of
// the pin map held high at power-up walks every output of the pin map in turn, about 2 s
// each (`lamp D12` on the serial port); then says on the serial port that it works; then
// lights all the outputs together for as long, and turns them off; then each digital
// input lights the output of its channel (`input D3 1` on each change) until a reset with
// the input released, as the source leaves its test.
static uint8_t map_len(uint8_t kind) {{ return pgm_read_byte(&MAP_AT[kind + 1]) - pgm_read_byte(&MAP_AT[kind]); }}
// The Arduino pin of channel `ch` of `kind` (0xFF: none), as the wires' pins are read.
static uint8_t map_pin(uint8_t kind, uint8_t ch) {{
    uint8_t pin = pgm_read_byte(&MAP[pgm_read_byte(&MAP_AT[kind]) + ch]);
    return pin == 0xFF ? 0xFF : pin & 0x80 ? A0 + (pin & 0x7F) : pin;
}}

static void lamp_set(uint8_t kind, uint8_t pin, bool on) {{
    if (kind == 1) digitalWrite(pin, on ? {on} : {off});
    else analogWrite(pin, on ? 255 : 0);
}}

static void lamp_all(bool on) {{
    for (uint8_t kind = 1; kind <= 3; kind += 2)
        for (uint8_t ch = 0; ch < map_len(kind); ch++)
            if (map_pin(kind, ch) != 0xFF) lamp_set(kind, map_pin(kind, ch), on);
}}

static void lamp_name(uint8_t pin) {{
    Serial.print(pin >= A0 ? 'A' : 'D');
    Serial.print(pin >= A0 ? pin - A0 : pin);
}}

static void lamp_test() {{
    uint8_t hold = map_len(0) ? map_pin(0, 0) : 0xFF;
    if (hold == 0xFF) return;
    pinMode(hold, INPUT);
    if (digitalRead(hold) != HIGH) return;
    lamp_all(false);
    for (uint8_t kind = 1; kind <= 3; kind += 2)
        for (uint8_t ch = 0; ch < map_len(kind); ch++)
            if (map_pin(kind, ch) != 0xFF) pinMode(map_pin(kind, ch), OUTPUT);
    Serial.println(F("lamp test"));
    for (uint8_t kind = 1; kind <= 3; kind += 2)
        for (uint8_t ch = 0; ch < map_len(kind); ch++) {{
            uint8_t pin = map_pin(kind, ch);
            if (pin == 0xFF) continue;
            Serial.print(F("lamp "));
            lamp_name(pin);
            Serial.println();
            lamp_set(kind, pin, true);
            delay(2000);
            lamp_set(kind, pin, false);
        }}
    Serial.println(F("lamp test: the serial port works"));
    Serial.println(F("lamp all"));
    lamp_all(true);
    delay(2000);
    lamp_all(false);
    Serial.println(F("lamp inputs"));
    uint8_t seen[{max_ch} / 8] = {{0}};
    for (uint8_t ch = 0; ch < map_len(0); ch++)
        if (map_pin(0, ch) != 0xFF) pinMode(map_pin(0, ch), INPUT);
    for (;;) {{
        for (uint8_t ch = 0; ch < map_len(0); ch++) {{
            uint8_t pin = map_pin(0, ch);
            if (pin == 0xFF) continue;
            bool v = digitalRead(pin) == HIGH;
            if (ch < map_len(1) && map_pin(1, ch) != 0xFF) lamp_set(1, map_pin(1, ch), v);
            if (v == ((seen[ch / 8] >> (ch % 8)) & 1)) continue;
            seen[ch / 8] ^= (uint8_t)(1 << (ch % 8));
            Serial.print(F("input "));
            lamp_name(pin);
            Serial.println(v ? F(" 1") : F(" 0"));
        }}
    }}
}}

void setup() {{
    Serial.begin(ALBA_LINK_BAUD);
    // before the program: the test needs none, and once it runs only a reset ends it
    lamp_test();
    start();
}}

void loop() {{
    serial_poll();
    if (reload) {{
        // a new program, or the old one after a refused download (its outputs already safe)
        reload = false;
        start();
    }}
    if (!loaded) {{
        // No program that can run: the outputs stay inputs (safe), the error LED blinks.
{led_blink}        return;
    }}
    if (major) {{
        outputs_safe();
        return;
    }}
    uint32_t period = scan_period ? scan_period : 1;
    uint32_t late = micros() - next_us;
    if ((int32_t)late < 0) return;
    if (late >= period * 1000UL) {{
        uint32_t missed = late / (period * 1000UL);
        overruns += missed;
        advance(missed * period);
    }}
    GPIOR0 = 1;  // the scan starts (simavr's harness counts its cycles)
    read_inputs();
    scan();
    if (major) outputs_safe();
    else write_outputs();
    GPIOR0 = 0;
    advance(period);
}}
"#,
        board = t.model.title(),
        model = t.model.name(),
        mcu = t.model.mcu(),
        version = env!("CARGO_PKG_VERSION"),
        version_byte = bytecode::VERSION,
        first = first,
        board_id = bytecode::board_id(t),
        map = map.join(", "),
        map_at = map_at.join(", "),
        stats = alba_ir::layout::STAT_TAGS.len(),
        bslot = if c.b <= 256 { "uint8_t" } else { "uint16_t" },
        islot = if c.i <= 256 { "uint8_t" } else { "uint16_t" },
        cb = c.b,
        ci = c.i,
        cf = c.f,
        cl = c.l.max(1),
        lcap = c.l,
        cm = c.m.max(1),
        cw = c.wires,
        on = lvl(true),
        off = lvl(false),
        slave = sketch::LINK_SLAVE,
        baud = sketch::LINK_BAUD,
        magic = sketch::LINK_MAGIC,
        max_ch = bytecode::MAX_CHANNELS,
    );
    vec![
        ("alba_interp.ino".into(), ino),
        ("alba_rt.h".into(), RUNTIME.into()),
        ("alba_link.h".into(), sketch::LINK.into()),
    ]
}

/// The interpreter firmware for `t`'s board without a program, built once
/// into the cache (`toolchain::cache_dir`, keyed by the board and a hash of
/// the generated source, so a new Alba or another pin map builds anew) and
/// reused after; `true` when it came from the cache.
pub fn firmware(t: &Target) -> Result<(crate::toolchain::Built, bool), alba_diag::Diagnostic> {
    use crate::toolchain::{self, temp_sibling, tool_error};
    let files = generate(t, None);
    let hash = files
        .iter()
        .flat_map(|(name, text)| name.bytes().chain(text.bytes()))
        .fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
    let cache = toolchain::cache_dir();
    let dir = cache.join(format!("interp-{}-{hash:016x}", t.model.name()));
    let (elf, hex) = (dir.join("build/sketch.elf"), dir.join("build/sketch.hex"));
    if elf.is_file() && hex.is_file() {
        return Ok((toolchain::measure(elf, hex, t.model)?, true));
    }
    let tmp = temp_sibling(&dir);
    let io = |e: std::io::Error| tool_error(format!("cannot write the interpreter in {}: {e}", tmp.display()));
    std::fs::create_dir_all(&tmp).map_err(io)?;
    for (name, text) in &files {
        std::fs::write(tmp.join(name), text).map_err(io)?;
    }
    let result = toolchain::build(&tmp.join(&files[0].0), t.model, &tmp.join("build"));
    if let Err(d) = result {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(d);
    }
    // Another builder may have won the race: theirs is as good as ours.
    if std::fs::rename(&tmp, &dir).is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    Ok((toolchain::measure(elf, hex, t.model)?, false))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn templates_number_their_slot_fields_in_order_and_cover_every_opcode() {
        let mut codes = std::collections::BTreeSet::new();
        for op in templates() {
            let (code, fields) = bytecode::fields(&op, 0);
            codes.insert(code);
            let slots: Vec<u32> = fields
                .iter()
                .filter_map(|f| match f {
                    Field::Slot(_, v) => Some(*v),
                    _ => None,
                })
                .collect();
            let want: Vec<u32> = (0..slots.len() as u32).map(|k| S + k).collect();
            assert_eq!(slots, want, "{op:?}");
        }
        // Every opcode (0x01 to 0x41) but the jump and the marker bits, which are written by hand.
        assert_eq!(codes.len(), 0x41 - 3, "{codes:?}");
    }
}
