//! The one intermediate representation of Alba (SPEC §11).
//!
//! Ladder, IL (and later state nets) compile to a [`Program`]: a flat list
//! of [`Op`]s over typed slots laid out by [`Layout`], each op tagged with
//! the rung and element it came from. The engine interprets it, the Arduino
//! generator translates it and the byte code serialises it.

pub mod builder;
pub mod layout;
pub mod memory;
pub mod op;
pub mod program;
pub mod symbols;
pub mod values;

/// The data model whose types the IR's public API speaks of (a layout's
/// tags, their data types and values), so that a user of the IR names one
/// crate for both.
pub use alba_model as model;

pub use builder::{Builder, TempMark};
pub use layout::{Counts, Layout, Place, Region, TagSlot};
pub use memory::{Memory, Migration};
pub use op::{B, BinOp, Cmp, Ctr, Cvt, D, F, I, L, MarkerSlot, Op, Pidt, TimeBase, Tmr, UnOp, Width};
pub use program::{Element, InvalidProgram, Loc, NO_ELEM, PlantSpec, Program, RungInfo, Unit};
pub use symbols::{Access, ResolveError, Target};
