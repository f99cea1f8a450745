//! Integration tests of the AWL front end: the fuzz regression corpus, run
//! through the parser and the checker with the checks the cargo-fuzz
//! targets use (`check.rs`).

mod check;
mod fuzz_regressions;
