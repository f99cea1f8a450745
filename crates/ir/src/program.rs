//! A compiled program: ops with their source locations, the layout and the
//! initial memory.

use crate::layout::Layout;
use crate::memory::Memory;
use crate::op::{AnySlot, Op};
use alba_diag::{Files, Span};
use std::fmt::Write as _;

/// No element (ops that belong to the rung, not to one instruction).
pub const NO_ELEM: u32 = u32::MAX;

/// Where an op came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Loc {
    /// Index into [`Program::rungs`].
    pub rung: u32,
    /// Index into [`Program::elements`], or [`NO_ELEM`].
    pub elem: u32,
}

/// One source element whose power flow is observable: an instruction, or a
/// branch (whose state is the OR of its legs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Element {
    pub rung: u32,
    pub span: Span,
}

/// A rung (ladder) or network (IL).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RungInfo {
    /// Index into [`Program::units`].
    pub unit: u16,
    /// 0-based number within its unit.
    pub number: u32,
    pub span: Span,
    /// Index of its first op.
    pub first_op: u32,
}

/// One program file of the project, run in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unit {
    pub name: String,
    pub first_op: u32,
    pub end_op: u32,
    /// A plant model: it runs in simulation, after the control programs,
    /// and is left out when the program drives real I/O.
    pub plant: bool,
}

#[derive(Debug, Clone)]
pub struct Program {
    pub ops: Vec<Op>,
    /// Parallel to `ops`.
    pub locs: Vec<Loc>,
    pub elements: Vec<Element>,
    pub rungs: Vec<RungInfo>,
    pub units: Vec<Unit>,
    pub layout: Layout,
    /// Memory at start: initial values, presets, constants.
    pub init: Memory,
    /// Sources, for messages that point at a rung or instruction.
    pub files: Files,
    /// Simulated processes on the I/O (`[[plant_model]]`), run by the
    /// simulator and the simulated I/O driver, not by the scan.
    pub plants: Vec<PlantSpec>,
}

/// A plant model with its signals resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct PlantSpec {
    pub model: alba_model::plant::PlantModel,
    /// Where it reads the actuator signal.
    pub input: crate::layout::Place,
    /// Where it writes the measurement.
    pub output: crate::layout::Place,
}

/// Why a program does not verify ([`Program::verify`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InvalidProgram {
    #[error("{ops} ops but {locs} locations")]
    Locations { ops: usize, locs: usize },
    #[error("the first op is not the start of a rung")]
    FirstOpNotRung,
    #[error("op {pc} ({op:?}) is not defined")]
    Undefined { pc: usize, op: Op },
    #[error("op {pc} ({op:?}) uses {slot} outside memory")]
    OutsideMemory { pc: usize, op: Op, slot: String },
    #[error("op {pc} jumps to {to}, which is not a rung start")]
    BadJump { pc: usize, to: u32 },
    #[error("op {pc} has a location outside the tables")]
    Location { pc: usize },
}

impl Program {
    /// Checks every invariant the interpreter relies on: slots in range,
    /// jumps to rung starts, one location per op. Programs built by the
    /// builder pass; this guards programs from other sources (byte code).
    pub fn verify(&self) -> Result<(), InvalidProgram> {
        if self.locs.len() != self.ops.len() {
            return Err(InvalidProgram::Locations {
                ops: self.ops.len(),
                locs: self.locs.len(),
            });
        }
        if self.ops.first().is_some_and(|op| *op != Op::Rung) {
            return Err(InvalidProgram::FirstOpNotRung);
        }
        let m = &self.init;
        for (pc, op) in self.ops.iter().enumerate() {
            if !op.is_defined() {
                return Err(InvalidProgram::Undefined { pc, op: *op });
            }
            for s in op.slots() {
                let ok = match s {
                    AnySlot::B(x) => (x as usize) < m.b.len(),
                    AnySlot::I(x) => (x as usize) < m.i.len(),
                    AnySlot::F(x) => (x as usize) < m.f.len(),
                    AnySlot::L(x) => (x as usize) < m.l.len(),
                    AnySlot::D(x) => (x as usize) < m.d.len(),
                    AnySlot::M(at, n) => (at as usize + n as usize) <= m.m.len(),
                };
                if !ok {
                    return Err(InvalidProgram::OutsideMemory {
                        pc,
                        op: *op,
                        slot: format!("{s:?}"),
                    });
                }
            }
            if let Op::Jmp(t) = op
                && !matches!(self.ops.get(*t as usize), Some(Op::Rung))
            {
                return Err(InvalidProgram::BadJump { pc, to: *t });
            }
            let loc = self.locs[pc];
            if loc.rung as usize >= self.rungs.len().max(1)
                || (loc.elem != NO_ELEM && loc.elem as usize >= self.elements.len())
            {
                return Err(InvalidProgram::Location { pc });
            }
        }
        Ok(())
    }

    /// Bytes of program representation (ops and locations).
    pub fn code_bytes(&self) -> usize {
        self.ops.len() * (std::mem::size_of::<Op>() + std::mem::size_of::<Loc>())
    }

    /// A readable listing, one op per line, for golden tests and debugging.
    pub fn dump(&self) -> String {
        let mut out = String::new();
        for (pc, op) in self.ops.iter().enumerate() {
            let loc = self.locs[pc];
            if let Some(u) = self.units.iter().find(|u| u.first_op as usize == pc) {
                let _ = writeln!(out, "; program {}", u.name);
            }
            if matches!(op, Op::Rung) {
                let r = &self.rungs[loc.rung as usize];
                let _ = writeln!(out, "; rung {}", r.number);
            }
            let elem = if loc.elem == NO_ELEM {
                "-".to_string()
            } else {
                format!("e{}", loc.elem)
            };
            let _ = writeln!(out, "{pc:04} {elem:>4}  {op:?}");
        }
        out
    }

    /// "main.lad rung 3 (line 7)" for a location, for fault reports.
    pub fn describe(&self, loc: Loc) -> String {
        let Some(rung) = self.rungs.get(loc.rung as usize) else {
            return "unknown place".into();
        };
        let unit = self.units.get(rung.unit as usize).map_or("?", |u| u.name.as_str());
        let span = match self.elements.get(loc.elem as usize) {
            Some(e) => e.span,
            None => rung.span,
        };
        let (line, col) = self.files.line_col(span.file, span.start as usize);
        let what = self.files.text(span.file).get(span.range()).unwrap_or("");
        let what: String = what.chars().take(40).collect();
        format!("{unit} rung {} ({line}:{col} `{what}`)", rung.number)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::op::{B, I, TimeBase, Tmr};
    use crate::{Builder, Layout};
    use alba_diag::{FileId, Span};
    use alba_model::TagTable;

    /// A one-rung program: `Xic(b0) Ote(b1)` over a layout with a timer.
    fn program() -> Program {
        let mut files = Files::new();
        let f = files.add("tags.csv", "name,type\nT,TIMER\n");
        let (tags, _) = TagTable::parse(files.text(f), f);
        let mut b = Builder::new(Layout::new(&tags, &crate::layout::Uses::default()));
        b.begin_unit("main.lad");
        b.begin_rung(0, Span::new(FileId(0), 0..0));
        let e = b.element(Span::new(FileId(0), 0..0));
        b.emit(Op::Xic(B(0)), e);
        b.emit(Op::Ote(B(1)), e);
        b.finish(files)
    }

    #[test]
    fn verify_accepts_what_the_builder_makes() {
        assert_eq!(program().verify(), Ok(()));
    }

    #[test]
    fn verify_refuses_what_the_engine_must_never_run() {
        type Breakage = fn(&mut Program);
        let cases: [(&str, Breakage); 6] = [
            ("outside memory", |p| p.ops[1] = Op::Xic(B(1_000))),
            ("not a rung start", |p| p.ops[2] = Op::Jmp(1)),
            ("first op", |p| p.ops.swap(0, 1)),
            ("outside memory", |p| {
                p.ops[1] = Op::Ton(
                    Tmr {
                        i: I(u32::MAX),
                        b: B(0),
                    },
                    TimeBase::Ms,
                )
            }),
            ("not defined", |p| {
                p.ops[1] = Op::LdBit {
                    byte: 0,
                    bit: 8,
                    dst: B(0),
                }
            }),
            ("locations", |p| {
                p.locs.pop();
            }),
        ];
        for (want, break_it) in cases {
            let mut p = program();
            break_it(&mut p);
            let e = p.verify().unwrap_err().to_string();
            assert!(e.contains(want), "expected `{want}` in `{e}`");
        }
    }
}
