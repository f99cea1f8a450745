//! `alba verify` and `alba test` (SPEC §10.6, docs/verify.md).
//!
//! * [`props`] reads `properties.toml`; [`expr`] lowers its expressions
//!   (Alba's expression language) onto the IR, a probe program the engine
//!   runs after each scan.
//! * [`explore`] decides each property over every input sequence by an
//!   explicit-state search whose transition is one scan of the engine itself
//!   (one semantics), with time and counters abstracted only where exact
//!   (ADR 0015); an invariant is first tried by k-induction with a SAT solver
//!   over the IR's Boolean part, soundly abstracted ([`induct`]).
//! * [`project`] does it for a project folder (what `alba verify` runs).
//! * [`trace`] replays a counterexample scan by scan (values, power flow) for
//!   the studio's time slider.
//! * [`table`] runs `tests/*.test.csv` tables on the engine, with rung and
//!   instruction coverage from the engine's power flow and JUnit XML.

mod error;
pub mod explore;
pub mod expr;
pub mod induct;
pub mod project;
pub mod props;
mod slots;
pub mod table;
pub mod trace;

pub use error::{ReplayError, TestsError};
