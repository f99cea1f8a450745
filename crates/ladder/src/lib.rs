//! Ladder in Rockwell's neutral text (SPEC §3): parser with located
//! diagnostics, canonical printer, and the checker that lowers rungs to the
//! Alba IR; `domain` describes the language (types, instructions, operand
//! kinds, address notations) for the browser studio.

pub mod ast;
pub mod domain;
pub mod expr;
pub mod funcs;
pub mod lower;
pub mod parse;
pub mod print;

/// The time base of `TON(T,pre,acc,base)` (docs/ladder.md §4.4).
pub use alba_ir::TimeBase;
pub use ast::{Arg, Branch, Element, Group, Instr, Mnemonic, Operand, Optional, Program, Rung};
pub use lower::{Dialect, Presets, addresses, compile, compile_in, layout_for, slc_structs};
pub use parse::parse;
pub use print::print;
