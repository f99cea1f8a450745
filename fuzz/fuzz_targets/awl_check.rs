//! AWL checker/lowering: any input is parsed, then checked against a small
//! tag table with every type and address style and lowered to the IR,
//! without panicking; every diagnostic span lies inside the input and
//! renders; a program without diagnostics passes `Program::verify`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../../crates/il/tests/it/check.rs"]
mod check;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(e) = check::check_and_lower(src) {
        panic!("{e}\ninput: {src:?}");
    }
});
