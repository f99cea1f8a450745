//! The byte-code decoder (issue 19): any bytes, the header's length and CRC
//! made good first so the fuzzer reaches the body's decoder and not only the
//! checksum, are refused with a reason or decoded into a program that passes
//! `Program::verify`; the board checks of `decode_for` (with the header's
//! board id made the Uno's, then the Mega's) accept nothing `decode`
//! refuses. Never a panic. The checks are `crates/arduino/tests/common/fuzz.rs`.
#![no_main]

#[path = "../../crates/arduino/tests/common/fuzz.rs"]
mod check;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = check::bytecode_input(data) {
        panic!("{e}");
    }
});
