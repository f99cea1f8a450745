//! `alba import` of Plcopen input: never panics; an error names a place inside
//! the input; a success is a checked project (`alba_import::fuzz::check`,
//! shared with crates/import/tests/fuzz.rs).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = alba_import::fuzz::check(alba_import::Format::Plcopen, data) {
        panic!("{e}\ninput: {:?}", String::from_utf8_lossy(data));
    }
});
