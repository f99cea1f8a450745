//! PNML loader: never panics, every diagnostic is located inside the input
//! on character boundaries (and renders), an error whenever no net comes
//! back, and a loaded net survives load → save → load unchanged. The checks
//! are those of the regression test (`crates/net/tests/it/check.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../../crates/net/tests/it/check.rs"]
mod check;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(e) = check::pnml_input(src) {
        panic!("{e}\ninput: {src:?}");
    }
});
