//! Checks an AWL program and lowers it to the IR, with the semantics of a
//! real S7-200 (SPEC §4).
//!
//! **The logic stack** is resolved at compile time. Its top is the IR's
//! rung condition `rc`; the eight levels below live in a ring of bool slots
//! indexed by the static depth, so nothing shifts at run time. Pushing a
//! tenth value drops the bottom one, as on the S7-200 (a program that loads
//! value after value in one network is fine); an instruction that reaches
//! for a dropped value, or for more values than were pushed, is an error
//! (`E212`). Each network (and the code after a label) starts with an
//! empty stack.

use crate::ast::{CounterKind, How, Instr, Item, Mn, Operand, Program, TimerKind, Ty};
use alba_diag::{Code, Diagnostic, Span};
use alba_ir::layout::{S7Slots, Uses};
use alba_ir::op::{S7Ctr, S7Tmr};
use alba_ir::values::{Class, Src, V};
use alba_ir::{Access, B, BinOp, Builder, Cmp, I, Op, Place, Target, UnOp};
use alba_model::address::{MARKER_BYTES, MAX_DIGITAL, MarkerWidth};
use alba_model::{Address, DataType, Literal, Value};
use std::collections::HashMap;

/// Levels of the S7-200 logic stack.
const LEVELS: usize = 9;
/// Deepest FOR nesting of the S7-200.
const MAX_LOOPS: usize = 8;

/// What all the AWL programs of a project must agree on: one kind per timer
/// and counter number, one literal PT/PV each.
#[derive(Debug, Default)]
pub struct Shared {
    timers: HashMap<u8, (TimerKind, Span)>,
    counters: HashMap<u8, (CounterKind, Span)>,
    presets: HashMap<(bool, u8), (i64, Span)>,
}

/// `T37` / `C5` as an S7 timer or counter number.
fn timer_or_counter(text: &str) -> Option<(char, u8)> {
    let mut chars = text.chars();
    let kind = chars.next()?.to_ascii_uppercase();
    let digits = chars.as_str();
    if !matches!(kind, 'T' | 'C') || digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some((kind, digits.parse().ok()?))
}

/// A constant operand such as the N of `S Q0.0, 3`.
fn constant(text: &str) -> Option<i64> {
    match Literal::parse(text) {
        Ok(Literal::Int(v)) => Some(v),
        _ => None,
    }
}

/// The `n` consecutive bit addresses from `a` (for `S`/`R` with N) that
/// exist: fewer than `n` when the range runs past the end of its area.
fn bits(a: Address, n: u32) -> Vec<Address> {
    (0..n)
        .map_while(|k| match a {
            Address::DigitalIn(c) => Some(Address::DigitalIn(c + k)).filter(|_| c + k < MAX_DIGITAL),
            Address::DigitalOut(c) => Some(Address::DigitalOut(c + k)).filter(|_| c + k < MAX_DIGITAL),
            Address::Marker {
                byte,
                width: MarkerWidth::Bit(bit),
            } => {
                let at = byte * 8 + bit as u32 + k;
                Some(Address::Marker {
                    byte: at / 8,
                    width: MarkerWidth::Bit((at % 8) as u8),
                })
                .filter(|_| at / 8 < MARKER_BYTES)
            }
            _ => None,
        })
        .collect()
}

/// Everything a program names besides tags: addresses (every bit of
/// `S`/`R` ranges too), S7 timers and counters.
pub fn uses(prog: &Program) -> Uses {
    let mut u = Uses::default();
    for item in &prog.items {
        let Item::Instr(i) = item else { continue };
        let count = |k: usize| {
            i.operands
                .get(k)
                .and_then(|o| constant(&o.text))
                .filter(|n| (1..=255).contains(n))
                .unwrap_or(1) as u32
        };
        for (k, o) in i.operands.iter().enumerate() {
            let n = if k == 0 && matches!(i.mn, Mn::Set | Mn::Reset) {
                count(1)
            } else {
                1
            };
            if let Some((kind, first)) = timer_or_counter(&o.text) {
                let set = if kind == 'T' { &mut u.timers } else { &mut u.counters };
                set.extend((first as u32..first as u32 + n).filter_map(|x| u8::try_from(x).ok()));
            } else if let Ok(Some(a)) = Address::parse(&o.text) {
                u.addresses.extend(if n > 1 { bits(a, n) } else { vec![a] });
            }
        }
    }
    u
}

/// The resolution of timer `n` used as `kind`, or why it cannot be.
fn resolution(kind: TimerKind, n: u8) -> Result<u16, String> {
    match kind {
        TimerKind::Tonr => match n {
            0 | 64 => Ok(1),
            1..=4 | 65..=68 => Ok(10),
            5..=31 | 69..=95 => Ok(100),
            _ => Err(format!("T{n} is a TON/TOF timer; TONR uses T0–T31 and T64–T95")),
        },
        TimerKind::Ton | TimerKind::Tof => match n {
            32 | 96 => Ok(1),
            33..=36 | 97..=100 => Ok(10),
            37..=63 | 101..=255 => Ok(100),
            _ => Err(format!("T{n} is a TONR timer; TON and TOF use T32–T63 and T96–T255")),
        },
    }
}

fn class(ty: Ty) -> Class {
    if ty == Ty::R { Class::F } else { Class::I }
}

/// Compiles one AWL program into `b` as a unit named `name`.
pub fn compile(prog: &Program, name: &str, b: &mut Builder, shared: &mut Shared) -> Vec<Diagnostic> {
    let mut c = Compiler {
        ring: [B(0); LEVELS - 1],
        b,
        shared,
        diags: Vec::new(),
        d: 0,
        lost: 0,
        poisoned: false,
        network: 0,
        open: false,
        labels: HashMap::new(),
        jumps: Vec::new(),
        loops: Vec::new(),
    };
    c.b.begin_unit(name);
    let unit_mark = c.b.mark();
    for slot in c.ring.iter_mut() {
        *slot = c.b.temp_b();
    }
    for item in &prog.items {
        match item {
            Item::Network { number, span } => {
                // An unnumbered network follows the one before (`NETWORK
                // 4294967295` then `NETWORK` stays at the last number).
                c.network = number.unwrap_or(c.network.saturating_add(1));
                c.new_rung(*span);
                c.poisoned = false;
            }
            Item::Instr(i) => {
                if i.mn == Mn::Lbl {
                    c.label(i);
                    c.poisoned = false;
                    continue;
                }
                if !c.open {
                    c.network = c.network.max(1);
                    c.new_rung(i.span);
                }
                let elem = c.b.element(i.span);
                let mark = c.b.mark();
                let (errors, open) = (c.diags.len(), c.loops.len());
                c.instr(i, elem);
                if i.mn == Mn::For && c.loops.len() == open {
                    c.loops.push(None);
                }
                c.b.release(mark);
                // After an error the stack is unknown: no echoes of it.
                c.poisoned |= c.diags.len() > errors;
            }
            Item::Bad => c.poisoned = true,
        }
    }
    for l in std::mem::take(&mut c.loops).into_iter().flatten() {
        c.err(Code::LoopStructure, "this FOR has no NEXT", l.span, "loop not closed");
    }
    for (at, label, span) in std::mem::take(&mut c.jumps) {
        match c.labels.get(&label) {
            Some(&(target, _)) => c.b.patch_jump(at, target),
            None => c.err(
                Code::MissingLabel,
                format!("no LBL {label} in this program"),
                span,
                "unknown label",
            ),
        }
    }
    c.b.release(unit_mark);
    c.b.end_unit();
    c.diags
}

struct Loop {
    indx: Place,
    /// The enable of the FOR, on top of the stack again after NEXT.
    enable: B,
    fin: Src,
    /// The op where the body starts (a rung start).
    body: u32,
    /// Values on the stack at the FOR (the enable on top).
    depth: usize,
    exits: Vec<u32>,
    span: Span,
}

struct Compiler<'a> {
    b: &'a mut Builder,
    shared: &'a mut Shared,
    diags: Vec<Diagnostic>,
    /// The logic stack below the top (see the module comment).
    ring: [B; LEVELS - 1],
    /// Values on the logic stack.
    d: usize,
    /// Positions below this one were pushed off the bottom of the stack.
    lost: usize,
    /// An instruction of this network was in error, so the stack depth is
    /// unknown: stack errors are not reported.
    poisoned: bool,
    network: u32,
    /// A rung (network) is open.
    open: bool,
    labels: HashMap<u32, (u32, Span)>,
    jumps: Vec<(u32, u32, Span)>,
    /// Open FOR loops, innermost last; `None` for a FOR in error (its NEXT
    /// closes it quietly).
    loops: Vec<Option<Loop>>,
}

impl Compiler<'_> {
    fn err(&mut self, code: Code, msg: impl Into<String>, span: Span, label: impl Into<String>) {
        self.diags.push(Diagnostic::new(code, msg, span, label));
    }

    /// Starts an IR rung (a network, a label, a loop body) with an empty stack.
    fn new_rung(&mut self, span: Span) -> u32 {
        let at = self.b.here();
        self.b.begin_rung(self.network.max(1) - 1, span);
        self.open = true;
        self.d = 0;
        self.lost = 0;
        at
    }

    /// The slot of stack level `k` below the top (`k` ≥ 1, checked by `need`).
    fn level(&self, k: usize) -> B {
        self.ring[(self.d - 1 - k) % self.ring.len()]
    }

    /// A push: stores the top (`rc`) in its slot, as the push buries it.
    fn push(&mut self, elem: u32) {
        if self.d >= 1 {
            let slot = self.ring[(self.d - 1) % self.ring.len()];
            self.b.emit(Op::Ote(slot), elem);
        }
        self.d += 1;
        self.lost = self.lost.max(self.d.saturating_sub(LEVELS));
    }

    /// Does the stack hold the `n` values an instruction uses? Reports if not.
    fn need(&mut self, i: &Instr, n: usize) -> bool {
        if self.d >= n && self.d - n >= self.lost {
            return true;
        }
        if self.poisoned {
            return false;
        }
        if self.d >= n {
            let d = Diagnostic::new(
                Code::LogicStack,
                format!(
                    "{} reaches {n} values down the logic stack, but more than {LEVELS} values were loaded since: the oldest fell off its bottom",
                    i.name.to_ascii_uppercase()
                ),
                i.name_span,
                "value lost",
            )
            .with_help(format!("the S7-200 logic stack has {LEVELS} levels: combine values with ALD/OLD before loading more"));
            self.diags.push(d);
            return false;
        }
        let msg = if self.d == 0 {
            format!(
                "{} needs a value on the logic stack, which is empty here",
                i.name.to_ascii_uppercase()
            )
        } else {
            format!(
                "{} needs {n} values on the logic stack, which holds {} here",
                i.name.to_ascii_uppercase(),
                self.d
            )
        };
        let d = Diagnostic::new(Code::LogicStack, msg, i.name_span, "not enough values")
            .with_help("a network starts with an empty stack: load a value first (LD, LDN, LDW=…)");
        self.diags.push(d);
        false
    }

    /// A bit operand: I, Q, M, SM, T, C, a BOOL tag or any address notation.
    fn bit(&mut self, i: &Instr, o: &Operand, write: bool) -> Option<Place> {
        if let Some((kind, n)) = timer_or_counter(&o.text) {
            let table = if kind == 'T' {
                &self.b.layout().timers
            } else {
                &self.b.layout().counters
            };
            let slots = *table.get(&n)?;
            if write {
                self.err(
                    Code::NotWritable,
                    format!(
                        "`{}` is a {} bit, set by its instruction",
                        o.text,
                        if kind == 'T' { "timer" } else { "counter" }
                    ),
                    o.span,
                    "read-only",
                );
                return None;
            }
            return Some(Place::Bool(slots.b));
        }
        let (place, access) = self.resolve(o)?;
        if place.data_type() != DataType::Bool {
            self.err(
                Code::OperandType,
                format!(
                    "{} needs a bit, `{}` is {}",
                    i.name.to_ascii_uppercase(),
                    o.text,
                    place.data_type().with_article()
                ),
                o.span,
                "expected a bit",
            );
            return None;
        }
        if write && access != Access::ReadWrite {
            self.not_writable(o, access);
            return None;
        }
        Some(place)
    }

    fn not_writable(&mut self, o: &Operand, access: Access) {
        let why = access.why_not_writable();
        self.err(
            Code::NotWritable,
            format!("`{}` cannot be written: {why}", o.text),
            o.span,
            "not writable",
        );
    }

    /// Resolves a symbol, address or system name through the layout.
    fn resolve(&mut self, o: &Operand) -> Option<(Place, Access)> {
        match self.b.layout().resolve(&o.text) {
            Ok(Target::Value { place, access }) => Some((place, access)),
            Ok(_) => {
                self.err(
                    Code::OperandType,
                    format!(
                        "`{}` is a Logix TIMER or COUNTER tag; AWL uses S7 timers (T37) and counters (C5)",
                        o.text
                    ),
                    o.span,
                    "not an S7 operand",
                );
                None
            }
            Err(e) => {
                let code = match e {
                    alba_ir::ResolveError::UnknownTag(_) => Code::UnknownTag,
                    alba_ir::ResolveError::UnknownMember { .. } => Code::UnknownMember,
                    alba_ir::ResolveError::NotAStructure { .. } => Code::OperandType,
                    _ => Code::BadAddress,
                };
                let mut d = Diagnostic::new(code, e.to_string(), o.span, "here");
                if code == Code::UnknownTag {
                    d = d.with_help(
                        "AWL operands are addresses (I0.0, Q0.1, M2.0, MW4, AIW0, T37, C5) or symbols of tags.csv",
                    );
                }
                self.diags.push(d);
                None
            }
        }
    }

    /// A value operand of width `ty`: a literal (not when `write`), a tag of
    /// that type, an address, or a timer/counter current value (words).
    fn value(&mut self, i: &Instr, o: &Operand, ty: Ty, write: bool) -> Option<Src> {
        let name = i.name.to_ascii_uppercase();
        let t = o.text.as_str();
        if t.starts_with(|c: char| c.is_ascii_digit() || matches!(c, '+' | '-' | '.'))
            || t.to_ascii_uppercase().starts_with("T#")
        {
            if write {
                self.err(
                    Code::NotWritable,
                    format!("`{t}` is a constant and cannot be written"),
                    o.span,
                    "expected an address or a tag",
                );
                return None;
            }
            let lit = match Literal::parse(t) {
                Ok(l) => l,
                Err(m) => {
                    self.err(Code::BadLiteral, m, o.span, "bad constant");
                    return None;
                }
            };
            let range = |lo: i64, hi: i64, v: i64| (lo..=hi).contains(&v);
            let ok = match (ty, lit) {
                (Ty::B, Literal::Int(v)) => range(-128, 255, v),
                (Ty::W, Literal::Int(v) | Literal::Time(v)) => range(i16::MIN as i64, i16::MAX as i64, v),
                (Ty::D, Literal::Int(v) | Literal::Time(v)) => range(i32::MIN as i64, i32::MAX as i64, v),
                (Ty::R, Literal::Int(_)) => true,
                (Ty::R, Literal::Real(v)) => v.abs() <= f32::MAX as f64,
                _ => false,
            };
            if !ok {
                self.err(
                    Code::BadLiteral,
                    format!("`{t}` does not fit {}", ty.name()),
                    o.span,
                    "out of range",
                );
                return None;
            }
            // A byte constant keeps its 8 bits: 200 is the byte 16#C8.
            let lit = match (ty, lit) {
                (Ty::B, Literal::Int(v)) => Literal::Int(v as u8 as i8 as i64),
                _ => lit,
            };
            return Some(Src::Lit(lit));
        }
        if let Some((kind, n)) = timer_or_counter(t) {
            if ty != Ty::W {
                self.err(
                    Code::OperandType,
                    format!("{name} needs {}, `{t}` is a word", ty.name()),
                    o.span,
                    "a timer or counter value is a word",
                );
                return None;
            }
            let table = if kind == 'T' {
                &self.b.layout().timers
            } else {
                &self.b.layout().counters
            };
            let slots = *table.get(&n)?;
            return Some(Src::Place(Place::Int(slots.i, DataType::Int)));
        }
        let (place, access) = self.resolve(o)?;
        let place = match (ty, place) {
            // MD holds a REAL for the real instructions.
            (Ty::R, Place::MDword(at, _)) => Place::MReal(at),
            _ => place,
        };
        let pt = place.data_type();
        let fits = match ty {
            Ty::B => pt == DataType::Sint,
            Ty::W => pt == DataType::Int,
            Ty::D => matches!(pt, DataType::Dint | DataType::Time),
            Ty::R => pt == DataType::Real,
        };
        if !fits {
            self.err(
                Code::OperandType,
                format!("{name} needs {}, `{t}` is {}", ty.name(), pt.with_article()),
                o.span,
                format!("expected {}", ty.name()),
            );
            return None;
        }
        if write && access != Access::ReadWrite {
            self.not_writable(o, access);
            return None;
        }
        Some(Src::Place(place))
    }

    /// A constant in `lo..=hi` (the N of S/R, LDS).
    fn count(&mut self, o: &Operand, lo: i64, hi: i64) -> Option<u32> {
        match constant(&o.text) {
            Some(v) if (lo..=hi).contains(&v) => Some(v as u32),
            _ => {
                self.err(
                    Code::BadLiteral,
                    format!("`{}` must be a constant from {lo} to {hi}", o.text),
                    o.span,
                    "bad count",
                );
                None
            }
        }
    }

    /// The number and slots of timer (`kind` 'T') or counter ('C') operand `o`.
    fn s7_slots(&mut self, o: &Operand, kind: char) -> Option<(u8, S7Slots)> {
        let layout = self.b.layout();
        let table = if kind == 'T' { &layout.timers } else { &layout.counters };
        match timer_or_counter(&o.text) {
            Some((k, n)) if k == kind => table.get(&n).map(|s| (n, *s)),
            _ => {
                let what = if kind == 'T' { "timer" } else { "counter" };
                self.err(
                    Code::OperandType,
                    format!("`{}` is not a {what}: {what}s are {kind}0 to {kind}255", o.text),
                    o.span,
                    format!("expected {kind}xxx"),
                );
                None
            }
        }
    }

    /// The literal PT/PV of a timer/counter as its initial value, or a word
    /// copied into it on every execution.
    fn preset(&mut self, timer: bool, n: u8, slot: I, s: Src, o: &Operand, elem: u32) {
        match s {
            Src::Lit(Literal::Int(v) | Literal::Time(v)) => {
                let key = (timer, n);
                match self.shared.presets.get(&key) {
                    Some(&(prev, span)) if prev != v => {
                        let d = Diagnostic::new(
                            Code::ConflictingPreset,
                            format!(
                                "`{}` conflicts with the value {prev} given earlier to {}{n}",
                                o.text,
                                if timer { 'T' } else { 'C' }
                            ),
                            o.span,
                            "different preset",
                        )
                        .with_note(span, "first given here");
                        self.diags.push(d);
                    }
                    Some(_) => {}
                    None => {
                        self.shared.presets.insert(key, (v, o.span));
                        self.b
                            .set_initial(Place::Int(slot, DataType::Int), Value::Int(v as i16));
                    }
                }
            }
            Src::Place(p) => {
                if let V::I(v) = self.b.load(p, elem) {
                    self.b.emit(Op::CopyI(v, slot), elem);
                }
            }
            Src::Lit(_) => {}
        }
    }

    fn label(&mut self, i: &Instr) {
        // Not checked by `instr` (labels are handled before it): `LBL 4, 5`
        // is as wrong as `LBL`.
        let [o] = i.operands.as_slice() else {
            self.err(
                Code::OperandCount,
                "LBL takes one operand, the label number",
                i.span,
                "expected LBL n",
            );
            return;
        };
        let Some(n) = self.count(o, 0, 255) else { return };
        let at = self.new_rung(i.span);
        let elem = self.b.element(i.span);
        self.b.emit(Op::Nop, elem);
        if let Some(&(_, prev)) = self.labels.get(&n) {
            let d = Diagnostic::new(
                Code::DuplicateLabel,
                format!("LBL {n} is set twice"),
                o.span,
                "second LBL",
            )
            .with_note(prev, "first set here");
            self.diags.push(d);
            return;
        }
        self.labels.insert(n, (at, o.span));
    }

    fn instr(&mut self, i: &Instr, elem: u32) {
        let (lo, hi) = i.mn.operand_count();
        if i.operands.len() < lo || i.operands.len() > hi {
            let usage = i.mn.usage();
            self.err(
                Code::OperandCount,
                format!(
                    "{} takes {} operand{}, found {}",
                    i.name.to_ascii_uppercase(),
                    hi,
                    if hi == 1 { "" } else { "s" },
                    i.operands.len()
                ),
                i.span,
                format!("expected {} {usage}", i.name.to_ascii_uppercase()),
            );
            return;
        }
        let op = |k: usize| &i.operands[k];
        match i.mn {
            Mn::Load { neg } => {
                let Some(p) = self.bit(i, op(0), false) else { return };
                let v = self.b.bool_in(p, elem);
                self.push(elem);
                self.b.emit(if neg { Op::Ldn(v) } else { Op::Ld(v) }, elem);
            }
            Mn::And { neg } | Mn::Or { neg } => {
                let Some(p) = self.bit(i, op(0), false) else { return };
                if !self.need(i, 1) {
                    return;
                }
                let v = self.b.bool_in(p, elem);
                let o = match (i.mn, neg) {
                    (Mn::And { .. }, false) => Op::Xic(v),
                    (Mn::And { .. }, true) => Op::Xio(v),
                    (_, false) => Op::Or(v),
                    (_, true) => Op::Orn(v),
                };
                self.b.emit(o, elem);
            }
            Mn::Not => {
                if self.need(i, 1) {
                    self.b.emit(Op::Not, elem);
                }
            }
            Mn::Out => {
                let Some(p) = self.bit(i, op(0), true) else { return };
                if !self.need(i, 1) {
                    return;
                }
                let (t, post) = self.b.bool_out(p, elem);
                self.b.emit(Op::Ote(t), elem);
                self.b.post(post, elem);
            }
            Mn::Set | Mn::Reset => self.set_reset(i, elem),
            Mn::Eu | Mn::Ed => {
                if self.need(i, 1) {
                    let s = self.b.state_b();
                    self.b.emit(if i.mn == Mn::Eu { Op::Ons(s) } else { Op::Ed(s) }, elem);
                }
            }
            Mn::Ald | Mn::Old => {
                if self.need(i, 2) {
                    let l = self.level(1);
                    self.b.emit(if i.mn == Mn::Ald { Op::Xic(l) } else { Op::Or(l) }, elem);
                    self.d -= 1;
                }
            }
            Mn::Lps => {
                if self.need(i, 1) {
                    self.push(elem);
                }
            }
            Mn::Lrd | Mn::Lpp => {
                if self.need(i, 2) {
                    let l = self.level(1);
                    self.b.emit(Op::Ld(l), elem);
                    if i.mn == Mn::Lpp {
                        self.d -= 1;
                    }
                }
            }
            Mn::Lds => {
                // LDS 0 duplicates the top; LDS n copies the value n below it.
                let Some(n) = self.count(op(0), 0, 8) else { return };
                if self.need(i, n as usize + 1) {
                    let l = (n > 0).then(|| self.level(n as usize));
                    self.push(elem);
                    if let Some(l) = l {
                        self.b.emit(Op::Ld(l), elem);
                    }
                }
            }
            Mn::Cmp { how, ty, op: cmp } => self.compare(i, how, ty, cmp, elem),
            Mn::Math { op: bop, ty } => {
                let (Some(in1), Some(out)) = (self.value(i, op(0), ty, false), self.value(i, op(1), ty, true)) else {
                    return;
                };
                if !self.need(i, 1) {
                    return;
                }
                let Src::Place(dest) = out else { return };
                if bop == BinOp::Div {
                    self.divide(in1, dest, class(ty), elem);
                } else {
                    // OUT = OUT op IN1 (IN2 is OUT).
                    self.b.binary_to(bop, out, in1, dest, class(ty), elem);
                }
            }
            Mn::Inc { ty, down } => {
                if ty == Ty::B {
                    self.err(
                        Code::IlNotSupported,
                        "byte increments (INCB, DECB) are not supported yet",
                        i.name_span,
                        "not supported",
                    );
                    return;
                }
                let Some(out) = self.value(i, op(0), ty, true) else {
                    return;
                };
                if !self.need(i, 1) {
                    return;
                }
                let Src::Place(dest) = out else { return };
                let one = Src::Lit(Literal::Int(1));
                let bop = if down { BinOp::Sub } else { BinOp::Add };
                self.b.binary_to(bop, out, one, dest, class(ty), elem);
            }
            Mn::Mov { ty } => {
                let (Some(src), Some(Src::Place(dest))) =
                    (self.value(i, op(0), ty, false), self.value(i, op(1), ty, true))
                else {
                    return;
                };
                if self.need(i, 1) {
                    self.b.unary_to(UnOp::Mov, src, dest, class(ty), elem);
                }
            }
            Mn::Timer(kind) => self.timer(i, kind, elem),
            Mn::Counter(kind) => self.counter(i, kind, elem),
            Mn::For => self.for_loop(i, elem),
            Mn::Next => self.next(i, elem),
            Mn::Jmp => {
                let Some(n) = self.count(op(0), 0, 255) else { return };
                if self.need(i, 1) {
                    let at = self.b.emit(Op::Jmp(0), elem);
                    self.jumps.push((at, n, op(0).span));
                }
            }
            Mn::Lbl => {}
            Mn::Nop => {
                self.b.emit(Op::Nop, elem);
            }
        }
    }

    /// OUT = OUT / IN1, leaving OUT unchanged when IN1 is 0, as the S7-200
    /// does (the engine still records the division by zero as a minor fault).
    fn divide(&mut self, in1: Src, dest: Place, c: Class, elem: u32) {
        let enable = self.b.temp_b();
        self.b.emit(Op::Ote(enable), elem);
        let a = self.b.read(Src::Place(dest), c, elem);
        let b = self.b.read(in1, c, elem);
        let q = self.b.temp(c);
        self.b.bin(BinOp::Div, a, b, q, elem);
        let zero = self.b.constant(Literal::Int(0), c);
        match (b, zero) {
            (V::I(b), V::I(z)) => self.b.emit(Op::CmpI(Cmp::Ne, b, z), elem),
            (V::F(b), V::F(z)) => self.b.emit(Op::CmpF(Cmp::Ne, b, z), elem),
            _ => return,
        };
        let (d, post) = self.b.dest(dest, c, elem);
        self.b.un(UnOp::Mov, q, d, elem);
        self.b.post(post, elem);
        self.b.emit(Op::Ld(enable), elem);
    }

    fn compare(&mut self, i: &Instr, how: How, ty: Ty, cmp: Cmp, elem: u32) {
        if ty == Ty::B {
            self.err(
                Code::IlNotSupported,
                "byte compares (LDB…) are not supported yet",
                i.name_span,
                "not supported",
            );
            return;
        }
        let (Some(a), Some(b)) = (
            self.value(i, &i.operands[0], ty, false),
            self.value(i, &i.operands[1], ty, false),
        ) else {
            return;
        };
        if how != How::Load && !self.need(i, 1) {
            return;
        }
        let c = class(ty);
        let va = self.b.read(a, c, elem);
        let vb = self.b.read(b, c, elem);
        let test = match (va, vb) {
            (V::I(x), V::I(y)) => Op::CmpI(cmp, x, y),
            (V::F(x), V::F(y)) => Op::CmpF(cmp, x, y),
            _ => return,
        };
        match how {
            How::Load => {
                self.push(elem);
                self.b.emit(Op::True, elem);
                self.b.emit(test, elem);
            }
            How::And => {
                self.b.emit(test, elem);
            }
            How::Or => {
                let t = self.b.temp_b();
                self.b.emit(Op::Ote(t), elem);
                self.b.emit(Op::True, elem);
                self.b.emit(test, elem);
                self.b.emit(Op::Or(t), elem);
            }
        }
    }

    fn set_reset(&mut self, i: &Instr, elem: u32) {
        let set = i.mn == Mn::Set;
        let (target, n) = (&i.operands[0], &i.operands[1]);
        let Some(n) = self.count(n, 1, 255) else { return };
        if !self.need(i, 1) {
            return;
        }
        if let Some((kind, first)) = timer_or_counter(&target.text) {
            if set {
                self.err(
                    Code::NotWritable,
                    format!(
                        "S cannot set `{}`: timers and counters are set by their instructions",
                        target.text
                    ),
                    target.span,
                    "use R to reset it",
                );
                return;
            }
            for k in 0..n {
                let Some(num) = u8::try_from(first as u32 + k).ok() else {
                    self.err(
                        Code::BadAddress,
                        format!("R {}, {n} runs past the last number 255", target.text),
                        target.span,
                        "too many",
                    );
                    return;
                };
                let layout = self.b.layout();
                let op = if kind == 'T' {
                    layout
                        .timers
                        .get(&num)
                        .map(|s| Op::S7ResT(S7Tmr { i: s.i, b: s.b, res: 1 }))
                } else {
                    layout.counters.get(&num).map(|s| Op::S7ResC(S7Ctr { i: s.i, b: s.b }))
                };
                if let Some(op) = op {
                    self.b.emit(op, elem);
                }
            }
            return;
        }
        let Some(first) = self.bit(i, target, true) else { return };
        let places: Vec<Place> = if n == 1 {
            vec![first]
        } else {
            let addr = match Address::parse(&target.text) {
                Ok(Some(a)) => Some(a),
                _ => self.b.layout().tags.get(&target.text).and_then(|t| t.address),
            };
            let Some(addr) = addr.filter(|a| matches!(a, Address::DigitalOut(_) | Address::Marker { .. })) else {
                self.err(
                    Code::OperandType,
                    format!("`{}` has no address, so it has no next bits for N = {n}", target.text),
                    target.span,
                    "expected a Q or M address",
                );
                return;
            };
            let layout = self.b.layout();
            let all: Vec<Option<Place>> = bits(addr, n)
                .into_iter()
                .map(|a| layout.address_place(a, DataType::Bool))
                .collect();
            if all.iter().any(Option::is_none) || all.len() != n as usize {
                let area = if matches!(addr, Address::Marker { .. }) {
                    "marker memory"
                } else {
                    "the outputs"
                };
                let d = Diagnostic::new(
                    Code::BadAddress,
                    format!(
                        "{} {}, {n} runs past the end of {area}",
                        i.name.to_ascii_uppercase(),
                        target.text
                    ),
                    i.operands[1].span,
                    "too many bits",
                );
                self.diags.push(d);
                return;
            }
            all.into_iter().flatten().collect()
        };
        for p in places {
            let (t, post) = self.b.bool_out(p, elem);
            self.b.emit(if set { Op::Otl(t) } else { Op::Otu(t) }, elem);
            self.b.post(post, elem);
        }
    }

    fn timer(&mut self, i: &Instr, kind: TimerKind, elem: u32) {
        let Some((n, slots)) = self.s7_slots(&i.operands[0], 'T') else {
            return;
        };
        let res = match resolution(kind, n) {
            Ok(r) => r,
            Err(m) => {
                self.err(Code::S7Timer, m, i.operands[0].span, "wrong timer number");
                return;
            }
        };
        if let Some(&(k, span)) = self.shared.timers.get(&n) {
            if k != kind {
                let d = Diagnostic::new(
                    Code::S7Timer,
                    format!("T{n} is used as a {} and as a {}", k.name(), kind.name()),
                    i.operands[0].span,
                    "second kind",
                )
                .with_note(span, "first used here")
                .with_help("one timer number serves one kind of timer");
                self.diags.push(d);
                return;
            }
        } else {
            self.shared.timers.insert(n, (kind, i.operands[0].span));
        }
        let Some(pt) = self.preset_time(i, n, res) else {
            return;
        };
        if let Src::Lit(Literal::Int(v)) = pt
            && v < 0
        {
            self.err(
                Code::BadLiteral,
                "a timer preset cannot be negative",
                i.operands[1].span,
                "negative",
            );
            return;
        }
        if !self.need(i, 1) {
            return;
        }
        self.preset(true, n, I(slots.i.0 + 1), pt, &i.operands[1], elem);
        let t = S7Tmr {
            i: slots.i,
            b: slots.b,
            res,
        };
        self.b.emit(
            match kind {
                TimerKind::Ton => Op::S7Ton(t),
                TimerKind::Tonr => Op::S7Tonr(t),
                TimerKind::Tof => Op::S7Tof(t),
            },
            elem,
        );
    }

    /// The PT of timer `n`: a count of its resolution, or a duration
    /// (`T#5s`) that is a whole number of them.
    fn preset_time(&mut self, i: &Instr, n: u8, res: u16) -> Option<Src> {
        let o = &i.operands[1];
        let Ok(Literal::Time(ms)) = Literal::parse(&o.text) else {
            return self.value(i, o, Ty::W, false);
        };
        let units = ms / res as i64;
        if ms % res as i64 != 0 || !(0..=i16::MAX as i64).contains(&units) {
            let d = Diagnostic::new(
                Code::BadLiteral,
                format!(
                    "`{}` is not a preset of T{n}, which counts {res} ms from 0 to 32767 times",
                    o.text
                ),
                o.span,
                "not a whole number of units",
            )
            .with_help(format!(
                "T{n} can time {res} ms to {} s",
                res as i64 * i16::MAX as i64 / 1000
            ));
            self.diags.push(d);
            return None;
        }
        Some(Src::Lit(Literal::Int(units)))
    }

    fn counter(&mut self, i: &Instr, kind: CounterKind, elem: u32) {
        let Some((n, slots)) = self.s7_slots(&i.operands[0], 'C') else {
            return;
        };
        if let Some(&(k, span)) = self.shared.counters.get(&n) {
            if k != kind {
                let d = Diagnostic::new(
                    Code::S7Timer,
                    format!("C{n} is used as a {} and as a {}", k.name(), kind.name()),
                    i.operands[0].span,
                    "second kind",
                )
                .with_note(span, "first used here")
                .with_help("one counter number serves one counter");
                self.diags.push(d);
                return;
            }
        } else {
            self.shared.counters.insert(n, (kind, i.operands[0].span));
        }
        let Some(pv) = self.value(i, &i.operands[1], Ty::W, false) else {
            return;
        };
        let inputs = if kind == CounterKind::Ctud { 3 } else { 2 };
        if !self.need(i, inputs) {
            return;
        }
        self.preset(false, n, I(slots.i.0 + 1), pv, &i.operands[1], elem);
        let c = S7Ctr { i: slots.i, b: slots.b };
        // The count inputs, from the stack levels below the top.
        match kind {
            CounterKind::Ctu => self.b.emit(Op::CopyB(self.level(1), B(c.b.0 + 3)), elem),
            CounterKind::Ctd => self.b.emit(Op::CopyB(self.level(1), B(c.b.0 + 4)), elem),
            CounterKind::Ctud => {
                self.b.emit(Op::CopyB(self.level(2), B(c.b.0 + 3)), elem);
                self.b.emit(Op::CopyB(self.level(1), B(c.b.0 + 4)), elem)
            }
        };
        self.b.emit(
            match kind {
                CounterKind::Ctu => Op::S7Ctu(c),
                CounterKind::Ctd => Op::S7Ctd(c),
                CounterKind::Ctud => Op::S7Ctud(c),
            },
            elem,
        );
        // The inputs are used: the first one is left on top.
        let first = self.level(inputs - 1);
        self.b.emit(Op::Ld(first), elem);
        self.d -= inputs - 1;
    }

    fn for_loop(&mut self, i: &Instr, elem: u32) {
        let ops = &i.operands;
        let (Some(Src::Place(indx)), Some(init), Some(fin)) = (
            self.value(i, &ops[0], Ty::W, true),
            self.value(i, &ops[1], Ty::W, false),
            self.value(i, &ops[2], Ty::W, false),
        ) else {
            return;
        };
        if !self.need(i, 1) {
            return;
        }
        if self.loops.len() >= MAX_LOOPS {
            self.err(
                Code::LoopStructure,
                format!("FOR loops nest at most {MAX_LOOPS} deep"),
                i.name_span,
                "too deep",
            );
            return;
        }
        // INDX = INIT when enabled; skip the loop when not, or when INIT > FINAL.
        self.b.unary_to(UnOp::Mov, init, indx, Class::I, elem);
        let enable = self.b.state_b();
        self.b.emit(Op::Ote(enable), elem);
        self.b.emit(Op::Not, elem);
        let skip = self.b.emit(Op::Jmp(0), elem);
        let (iv, fv) = (
            self.b.read(Src::Place(indx), Class::I, elem),
            self.b.read(fin, Class::I, elem),
        );
        self.b.emit(Op::True, elem);
        if let (V::I(x), V::I(y)) = (iv, fv) {
            self.b.emit(Op::CmpI(Cmp::Gt, x, y), elem);
        }
        let done = self.b.emit(Op::Jmp(0), elem);
        let depth = self.d;
        let body = self.new_rung(i.span);
        // The body starts with the enable (true) still on the stack.
        self.d = depth;
        self.loops.push(Some(Loop {
            indx,
            enable,
            fin,
            body,
            depth,
            exits: vec![skip, done],
            span: i.span,
        }));
    }

    fn next(&mut self, i: &Instr, elem: u32) {
        let l = match self.loops.pop() {
            Some(Some(l)) => l,
            Some(None) => return,
            None => {
                self.err(Code::LoopStructure, "NEXT without its FOR", i.name_span, "no open loop");
                return;
            }
        };
        // Again while INDX < FINAL; INDX += 1 (so it ends at FINAL + 1, and
        // a FINAL of 32767 cannot loop for ever).
        let (iv, fv) = (
            self.b.read(Src::Place(l.indx), Class::I, elem),
            self.b.read(l.fin, Class::I, elem),
        );
        self.b.emit(Op::True, elem);
        if let (V::I(x), V::I(y)) = (iv, fv) {
            self.b.emit(Op::CmpI(Cmp::Lt, x, y), elem);
        }
        let again = self.b.temp_b();
        self.b.emit(Op::Ote(again), elem);
        self.b.emit(Op::True, elem);
        let one = Src::Lit(Literal::Int(1));
        self.b
            .binary_to(BinOp::Add, Src::Place(l.indx), one, l.indx, Class::I, elem);
        self.b.emit(Op::Ld(again), elem);
        self.b.emit(Op::Jmp(l.body), elem);
        let exit = self.new_rung(i.span);
        for at in l.exits {
            self.b.patch_jump(at, exit);
        }
        // After the loop the enable is on top again.
        self.d = l.depth;
        self.b.emit(Op::Ld(l.enable), elem);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_resolution_table_is_the_s7_200_one() {
        assert_eq!(resolution(TimerKind::Tonr, 0), Ok(1));
        assert_eq!(resolution(TimerKind::Tonr, 4), Ok(10));
        assert_eq!(resolution(TimerKind::Tonr, 95), Ok(100));
        assert!(resolution(TimerKind::Tonr, 32).is_err());
        assert_eq!(resolution(TimerKind::Ton, 32), Ok(1));
        assert_eq!(resolution(TimerKind::Tof, 100), Ok(10));
        assert_eq!(resolution(TimerKind::Ton, 255), Ok(100));
        assert!(resolution(TimerKind::Ton, 31).is_err());
    }

    fn check(text: &str) -> Vec<String> {
        let (prog, mut diags) = crate::parse(text, alba_diag::FileId(0));
        let layout = alba_ir::Layout::new(&alba_model::TagTable::default(), &uses(&prog));
        let mut b = Builder::new(layout);
        diags.extend(compile(&prog, "main.awl", &mut b, &mut Shared::default()));
        diags.iter().map(|d| format!("{} {}", d.code, d.message)).collect()
    }

    #[test]
    fn a_label_takes_exactly_one_operand() {
        assert_eq!(
            check("LBL\nLBL 4, 5\n")[..2],
            [
                "E302 LBL takes one operand, the label number",
                "E302 LBL takes one operand, the label number",
            ]
        );
    }

    #[test]
    fn unnumbered_networks_after_the_last_number_do_not_overflow() {
        assert!(check("NETWORK 4294967295\nLD I0.0\n= Q0.0\nNETWORK\nLD I0.1\n= Q0.1\n").is_empty());
    }

    #[test]
    fn set_reset_ranges_walk_consecutive_bits() {
        let m = |byte, bit| Address::Marker {
            byte,
            width: MarkerWidth::Bit(bit),
        };
        assert_eq!(bits(m(0, 6), 3), [m(0, 6), m(0, 7), m(1, 0)]);
        assert_eq!(
            bits(Address::DigitalOut(2), 2),
            [Address::DigitalOut(2), Address::DigitalOut(3)]
        );
    }
}
