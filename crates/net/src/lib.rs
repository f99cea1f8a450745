//! State nets and Petri nets: the model ([`Net`]) and its file format, PNML
//! (ISO/IEC 15909-2, `ptnet` grammar of 2009), loaded with located
//! diagnostics (codes E601–E608) and saved back without losing graphics or
//! other tools' data. See docs/nets.md, section "pnml".
//!
//! [`PtNet`] is the underlying place/transition net and [`analysis`] its analysis
//! (reachability, coverability, invariants; docs/nets.md, section "analysis").

pub mod analysis;
pub mod model;
pub mod pnml;
pub mod ptnet;
pub mod script;
pub mod sfc;
mod xml;

pub use model::*;
pub use pnml::{MAX_FILE_BYTES, MAX_MARKING, MAX_WEIGHT, is_warning, load, save};
pub use ptnet::PtNet;
pub use xml::{MAX_DEPTH, MAX_ELEMENTS};
