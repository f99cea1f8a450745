//! Property expressions lowered onto the one IR.
//!
//! Every expression of properties.toml (Alba's expression language, the CPT
//! form of `alba_ladder::expr`) is typed and lowered by the compiler as a
//! net's guard is (`alba_compiler::petri::lower_condition`), one rung each,
//! into a *probe* program whose layout extends the project's: each rung
//! writes the expression's value to a BOOL of its own. After a scan, the
//! engine runs the probe program over the scan's memory
//! ([`alba_engine::Engine::run_over`]), and the property reads those BOOLs.
//! So a property's comparisons, integer overflow, division by zero and type
//! rules are the engine's and the compiler's, in one place; a probe's fault
//! never reaches the program's memory.

use alba_diag::{Code, Diagnostic, FileId, Files, Span};
use alba_engine::Engine;
use alba_ir::op::AnySlot;
use alba_ir::{B, Builder, Layout, Memory, Program};
use std::sync::Arc;

/// One expression, lowered: its value after the probe program has run is
/// the BOOL `slot`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Cond {
    slot: B,
    /// The project's slots its ops read (for the cone of influence).
    reads: Vec<AnySlot>,
}

impl Cond {
    /// Its value in `probed`, the memory [`Evaluator::run`] returned.
    pub fn holds(&self, probed: &Memory) -> bool {
        probed.b.get(self.slot.0 as usize).copied().unwrap_or(false)
    }

    /// The probe program's BOOL that holds its value.
    pub(crate) fn slot(&self) -> B {
        self.slot
    }

    /// The slots of the project's memory it reads.
    pub fn reads(&self) -> &[AnySlot] {
        &self.reads
    }
}

/// Lowers expressions into one probe program over `layout`.
pub struct Lowering<'a> {
    b: Builder,
    base: &'a Layout,
    rung: u32,
}

impl<'a> Lowering<'a> {
    pub fn new(layout: &'a Layout) -> Lowering<'a> {
        let mut b = Builder::new(layout.clone());
        b.begin_unit("properties.toml");
        Lowering {
            b,
            base: layout,
            rung: 0,
        }
    }

    /// Parses `text` (at byte `base` of `file`) and lowers it; `whole` is
    /// where a problem that has no place of its own is reported.
    pub fn add(&mut self, text: &str, file: FileId, base: usize, whole: Span) -> Result<Cond, Vec<Diagnostic>> {
        let e = alba_ladder::expr::parse(text, file, base)
            .map_err(|(message, span)| vec![Diagnostic::new(Code::Expression, message, span, "in this expression")])?;
        let mark = self.b.mark();
        let slot = self.b.state_b();
        let first = self.b.here() as usize;
        self.rung += 1;
        self.b.begin_rung(self.rung, whole);
        let elem = self.b.element(whole);
        let diags = alba_compiler::petri::lower_condition(&mut self.b, &e, whole, slot, elem, Code::Expression);
        self.b.release(mark);
        if !diags.is_empty() {
            return Err(diags);
        }
        let counts = self.base.counts;
        let mut reads = Vec::new();
        for op in &self.b.ops()[first..] {
            for s in op.slots() {
                let ours = match s {
                    AnySlot::B(x) => x < counts.b,
                    AnySlot::I(x) => x < counts.i,
                    AnySlot::F(x) => x < counts.f,
                    AnySlot::L(x) => x < counts.l,
                    AnySlot::D(x) => x < counts.d,
                    AnySlot::M(..) => true,
                };
                if ours && !reads.contains(&s) {
                    reads.push(s);
                }
            }
        }
        Ok(Cond { slot, reads })
    }

    /// The probe program.
    pub fn finish(self) -> Probes {
        Probes(Arc::new(self.b.finish(Files::new())))
    }
}

/// The probe program of a properties.toml.
#[derive(Debug, Clone)]
pub struct Probes(Arc<Program>);

impl Probes {
    pub fn program(&self) -> &Arc<Program> {
        &self.0
    }
}

/// Runs the probe program on the engine.
pub struct Evaluator(Engine);

impl Evaluator {
    pub fn new(p: &Probes) -> Result<Evaluator, alba_engine::EngineError> {
        Engine::new(p.0.clone()).map(Evaluator)
    }

    /// Evaluates every expression on `m`, the memory at the end of a scan:
    /// read each with [`Cond::holds`].
    pub fn run(&mut self, m: &Memory) -> Result<&Memory, alba_engine::EngineError> {
        self.0.run_over(m, 0)
    }
}
