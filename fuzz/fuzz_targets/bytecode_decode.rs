//! The byte-code decoder (issue 19): any bytes are refused with a reason or
//! decoded into a program that passes `Program::verify`; the header's CRC is
//! recomputed first, so the fuzzer reaches the body's decoder and not only
//! the checksum. Never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    if bytes.len() >= alba_arduino::bytecode::HEADER_LEN {
        let crc = crc32fast::hash(&bytes[alba_arduino::bytecode::HEADER_LEN..]);
        bytes[20..24].copy_from_slice(&crc.to_le_bytes());
        let len = (bytes.len() - alba_arduino::bytecode::HEADER_LEN) as u32;
        bytes[16..20].copy_from_slice(&len.to_le_bytes());
    }
    if let Ok(d) = alba_arduino::bytecode::decode(&bytes) {
        assert!(d.program.verify().is_ok());
    }
});
