//! `alba verify` and `alba test` (SPEC §10.6, docs/verify.md).
//!
//! * [`props`] reads `properties.toml`; [`expr`] evaluates its expressions
//!   (Alba's expression language, parsed by `alba-ladder`) on program memory.
//! * [`explore`] decides each property over every input sequence by an
//!   explicit-state search whose transition is one scan of the engine itself
//!   (one semantics), with time and counters abstracted only where exact
//!   (ADR 0015).
//! * [`project`] does it for a project folder (what `alba verify` runs).
//! * [`trace`] replays a counterexample scan by scan (values, power flow) for
//!   the studio's time slider.
//! * [`table`] runs `tests/*.test.csv` tables on the engine, with rung and
//!   instruction coverage from the engine's power flow and JUnit XML.

mod error;
pub mod explore;
pub mod expr;
pub mod project;
pub mod props;
pub mod table;
pub mod trace;

pub use error::{ReplayError, TestsError};
