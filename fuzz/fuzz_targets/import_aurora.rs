//! `alba import` of an AuroraLD project folder, fuzzed as one text with each
//! file after a line `==> name <==` (`alba_import::aurora::Folder::join`):
//! never panics; an error names a place inside one of the files; a success
//! has its report entries inside them (`alba_import::fuzz::check`, shared
//! with crates/import/tests/fuzz.rs).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = alba_import::fuzz::check(alba_import::Format::Aurora, data) {
        panic!("{e}\ninput: {:?}", String::from_utf8_lossy(data));
    }
});
