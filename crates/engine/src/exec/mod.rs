//! The interpreter: the one semantics of every IR op (SPEC §11).
//!
//! The canonical IR is lowered into [`Code`], the engine's executable form:
//! the same ops with the common ones flattened (`AddI` rather than
//! `BinI(Add, ..)`), and, for unmonitored scans, a few fused patterns that
//! replace several canonical ops (a rung that starts with a two-contact
//! branch becomes one `RungOr`). Monitored scans run the unfused form, one
//! executable op per canonical op, and record the rung condition after each
//! element; unmonitored scans run an instantiation of the same loop with no
//! recording at all.
//!
//! The Arduino generator and the byte-code firmware are tested against this
//! file. Nothing here panics on a verified program: overflow, division by
//! zero and invalid floating-point results give defined values and record a
//! minor fault.
//!
//! The modules: `code` (the executable form and fusion), `step` (what
//! each op does), `arith` (arithmetic and conversions), `markers` (marker
//! bytes), `timers` (timers and counters); program memory and the fault
//! sink are in `crate::mem`, the PID instruction in `crate::pid`.

mod arith;
mod code;
mod markers;
mod step;
mod timers;

pub use code::{Code, X};
pub(crate) use code::{flatten, sizes};
pub(crate) use step::step;

use crate::fault::Faults;
use crate::mem::{Mem, Sink};
use alba_ir::{Loc, Memory, NO_ELEM};

/// Backward jumps allowed in one scan before the scan is abandoned as a
/// runaway loop (a major fault).
pub const BACKWARD_JUMP_LIMIT: u32 = 1_000_000;

/// Power flow of one scan: one bit per program element (SPEC §11).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PowerFlow {
    bits: Vec<u64>,
}

impl PowerFlow {
    pub fn new(elements: usize) -> PowerFlow {
        PowerFlow {
            bits: vec![0; elements.div_ceil(64)],
        }
    }

    /// The bits: element `e` is bit `e % 64` of word `e / 64`.
    pub fn words(&self) -> &[u64] {
        &self.bits
    }

    /// Is element `e` energised (the rung condition after it true)?
    pub fn get(&self, e: u32) -> bool {
        self.bits.get(e as usize / 64).is_some_and(|w| w >> (e % 64) & 1 == 1)
    }

    #[inline]
    fn set(&mut self, e: u32, v: bool) {
        if let Some(w) = self.bits.get_mut(e as usize / 64) {
            let mask = 1u64 << (e % 64);
            *w = (*w & !mask) | (u64::from(v) << (e % 64));
        }
    }

    fn clear(&mut self) {
        self.bits.iter_mut().for_each(|w| *w = 0);
    }
}

/// Why a scan stopped early.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// A runaway loop of backward jumps, at this canonical op.
    Runaway(u32),
    /// The memory does not have the program's layout (a bug of the caller).
    Memory,
}

/// Runs `code` once. `MON` selects the monitored instantiation, which
/// records the rung condition after every element in `pf` (use it with
/// unfused code, whose ops map one to one onto canonical ops).
pub(crate) fn run<const MON: bool>(
    code: &Code,
    locs: &[Loc],
    mem: &mut Memory,
    faults: &mut Faults,
    now: u32,
    pf: &mut PowerFlow,
) -> Result<(), Stop> {
    if !code.fits(mem) {
        return Err(Stop::Memory);
    }
    if MON {
        pf.clear();
    }
    let m = &mut Mem {
        b: &mut mem.b,
        i: &mut mem.i,
        f: &mut mem.f,
        l: &mut mem.l,
        d: &mut mem.d,
        m: &mut mem.m,
    };
    let sink = &mut Sink { faults, src: &code.src };
    let ops = &code.ops[..];
    let mut rc = true;
    let mut pc = 0usize;
    let mut backward = 0u32;
    loop {
        debug_assert!(pc < ops.len());
        // SAFETY: `pc` starts at 0 and only moves to the next op or to a jump
        // target; `Code::new` ends the code with `End`, which leaves the
        // loop, and clamps every jump target to it, so `pc < ops.len()`.
        #[allow(unsafe_code)]
        let op = unsafe { *ops.get_unchecked(pc) };
        let cur = pc;
        pc += 1;
        match op {
            X::End => break,
            X::Jmp(t) => {
                if rc {
                    if MON {
                        record(locs, code, cur, pf, rc);
                    }
                    if (t as usize) <= cur {
                        backward += 1;
                        if backward > BACKWARD_JUMP_LIMIT {
                            return Err(Stop::Runaway(code.src.get(cur).copied().unwrap_or(cur as u32)));
                        }
                    }
                    pc = t as usize;
                    continue;
                }
            }
            _ => rc = step(op, m, sink, now, cur, rc),
        }
        if MON {
            record(locs, code, cur, pf, rc);
        }
    }
    Ok(())
}

#[inline]
fn record(locs: &[Loc], code: &Code, pc: usize, pf: &mut PowerFlow, rc: bool) {
    let canonical = code.src.get(pc).copied().unwrap_or(pc as u32) as usize;
    if let Some(l) = locs.get(canonical)
        && l.elem != NO_ELEM
    {
        pf.set(l.elem, rc);
    }
}
