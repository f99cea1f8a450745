//! The Intel HEX reader (issue 19): any text gives bytes or one of the
//! source's error flags, never a panic; what it reads, written again, reads
//! back the same. The checks are `crates/arduino/tests/common/fuzz.rs`.
#![no_main]

#[path = "../../crates/arduino/tests/common/fuzz.rs"]
mod check;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = check::ihex_input(data) {
        panic!("{e}");
    }
});
