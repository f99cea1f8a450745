//! Structured Text (IEC 61131-3, 3rd edition, textual): a lexer and parser
//! with located, coded diagnostics, a checker, and the lowering of
//! `PROGRAM`s to the Alba IR (see docs/st.md for what is implemented and
//! every deviation from the standard).

pub mod ast;
pub mod lex;
pub mod lower;
pub mod parse;

pub use ast::File;
pub use lower::{compile, compile_in, compile_unoptimised, compile_with, declare, declare_with};
pub use parse::parse;
