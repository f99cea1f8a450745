//! Alba's core model: data types, values, addresses, the tag table, boards
//! and plant models. Every other crate builds on these. Diagnostics are in
//! `alba-diag`; `alba.toml` and project loading in `alba-project`.

pub mod address;
pub mod board;
pub mod csv;
pub mod error;
pub mod fsutil;
pub mod plant;
pub use address::slc;
pub mod tags;
pub mod types;
pub mod value;

pub use address::Address;
pub use error::Invalid;
pub use tags::{Tag, TagTable};
pub use types::DataType;
pub use value::{Literal, Value};
