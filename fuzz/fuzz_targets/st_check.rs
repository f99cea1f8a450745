//! Structured Text: any input is parsed, its variables declared as tags,
//! and its PROGRAMs checked and lowered to the IR against a small tag
//! table, without panicking; every diagnostic span lies inside the input
//! and renders; a text without diagnostics passes `Program::verify`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../../crates/st/tests/common/check.rs"]
mod check;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(e) = check::check_and_lower(src) {
        panic!("{e}\ninput: {src:?}");
    }
});
