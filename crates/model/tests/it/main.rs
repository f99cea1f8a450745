//! Integration tests of the model crate: the fuzz regression corpus of the
//! `tags.csv` and `alba.toml` parsers.

mod fuzz_regressions;
