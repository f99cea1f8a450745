//! Tests of the PNML loader and saver.

mod check;
mod fixtures;
mod fuzz_regressions;
mod malformed;
mod roundtrip;
