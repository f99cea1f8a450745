//! Instruction List: Siemens S7-200 AWL programs (SPEC §4), parsed with
//! located diagnostics and lowered to the Alba IR with the semantics of a
//! real S7-200.

pub mod ast;
pub mod lower;
pub mod parse;

pub use ast::Program;
pub use lower::{Shared, compile, uses};
pub use parse::parse;
