//! State nets and Petri nets: the model ([`Net`]) and its file format, PNML
//! (ISO/IEC 15909-2, `ptnet` grammar of 2009), loaded with located
//! diagnostics (codes E601–E608) and saved back without losing graphics or
//! other tools' data. See docs/nets.md, section "pnml".
//!
//! [`PtNet`] is the underlying place/transition net and [`analysis`] its analysis
//! (reachability, coverability, invariants; docs/nets.md, section "analysis").

pub mod analysis;
pub mod colored;
pub mod model;
pub mod pnml;
pub mod ptnet;
pub mod script;
pub mod sfc;

pub use colored::load_for_analysis;
pub use model::*;
pub use pnml::{MAX_FILE_BYTES, MAX_MARKING, MAX_WEIGHT, is_warning, load, save};
pub use ptnet::PtNet;

/// Deepest element nesting accepted in a PNML file.
pub const MAX_DEPTH: usize = 64;
/// Most elements in one PNML file: the element tree of a hostile file of
/// tiny elements then stays under about 200 MB; a net of 100 000 nodes with
/// graphics stays well below.
pub const MAX_ELEMENTS: usize = 1_000_000;

/// What a PNML document may hold (a doctype is skipped: no entity is resolved).
pub(crate) const XML_LIMITS: alba_xml::Limits = alba_xml::Limits {
    max_depth: MAX_DEPTH,
    max_elements: MAX_ELEMENTS,
    refuse_doctype: false,
};
