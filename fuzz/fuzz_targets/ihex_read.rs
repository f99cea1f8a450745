//! The Intel HEX reader (issue 19): any text gives bytes or one of the
//! source's error flags, never a panic; what it reads, written again, reads
//! back the same.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(bytes) = alba_arduino::ihex::read(text, 4096) {
        let again = alba_arduino::ihex::read(&alba_arduino::ihex::write(&bytes), 4096);
        assert_eq!(again.as_deref(), Ok(&bytes[..]));
    }
});
