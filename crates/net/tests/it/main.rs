//! Tests of the PNML loader and saver.

mod check;
mod coloured;
mod fixtures;
mod fuzz_regressions;
mod malformed;
mod roundtrip;
