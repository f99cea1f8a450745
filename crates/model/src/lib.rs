//! Alba's core model: diagnostics, data types, values, addresses, the tag
//! table and project files. Every other crate builds on these.

pub mod address;
pub mod board;
pub mod codes;
pub mod config;
pub mod csv;
pub mod diag;
pub mod fsutil;
pub mod plant;
pub mod project;
pub mod tags;
pub mod types;
pub mod value;

pub use address::Address;
pub use codes::Code;
pub use diag::{Diagnostic, FileId, Files, Span};
pub use project::{Language, Project};
pub use tags::{Tag, TagTable};
pub use types::DataType;
pub use value::{Literal, Value};
