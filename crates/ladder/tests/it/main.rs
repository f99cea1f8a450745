//! Integration tests of the ladder front end: property tests of the parser
//! and printer (round trip on random ASTs, printer ∘ parser identity on
//! canonical text, normalisation of non-canonical text, robustness on
//! arbitrary input) and the fuzz regression corpus.
//!
//! Case counts default to a few hundred per property; set `PROPTEST_CASES`
//! to run more (`PROPTEST_CASES=20000 cargo test -p alba-ladder --test it`).

mod check;
mod fuzz_regressions;
mod normalise;
mod robustness;
mod roundtrip;
mod strategies;
mod time_base;
