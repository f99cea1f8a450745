//! The checks of the fuzz targets `bytecode_decode` and `ihex_read`
//! (`fuzz/`), shared with the regression test (`tests/fuzz_regressions.rs`),
//! which replays the inputs of `tests/fuzz_regressions/` through them.
#![allow(dead_code)] // (each fuzz target uses one of the two checks)

use alba_arduino::bytecode::{self, HEADER_LEN};
use alba_arduino::ihex;
use alba_arduino::sketch::Target;
use alba_model::board::{Model, PinMap};

/// The boards whose interpreter checks are fuzzed: the Uno and the Mega, aurora map.
fn boards() -> Vec<Target> {
    [Model::Uno, Model::Mega]
        .into_iter()
        .filter_map(|model| {
            Some(Target {
                model,
                map: PinMap::preset("aurora")?,
                active_low: false,
                scan_ms: 10,
                monitor: true,
                power_up_on: Vec::new(),
            })
        })
        .collect()
}

/// Any bytes as byte code, the header's body length and CRC made good first
/// (so that the body's decoder is reached, not only the checksum): `decode`
/// refuses with a reason, or gives a program that passes `Program::verify`.
/// With the header's board id made a board's, `decode_for` that board
/// accepts only what `decode` accepts, and never panics on the board's
/// checks (memory, pins, ops).
pub fn bytecode_input(data: &[u8]) -> Result<(), String> {
    let mut bytes = data.to_vec();
    if bytes.len() >= HEADER_LEN {
        let len = (bytes.len() - HEADER_LEN) as u32;
        bytes[16..20].copy_from_slice(&len.to_le_bytes());
        let crc = crc32fast::hash(&bytes[HEADER_LEN..]);
        bytes[20..24].copy_from_slice(&crc.to_le_bytes());
    }
    let decoded = match bytecode::decode(&bytes) {
        Ok(d) => {
            d.program
                .verify()
                .map_err(|e| format!("decoded, but the program does not verify: {e}"))?;
            true
        }
        Err(e) if e.to_string().is_empty() => return Err("refused without a reason".into()),
        Err(_) => false,
    };
    for t in boards() {
        if bytes.len() >= 8 {
            bytes[6..8].copy_from_slice(&bytecode::board_id(&t).to_le_bytes());
        }
        if bytecode::decode_for(&bytes, &t).is_ok() && !decoded {
            return Err(format!("the {} accepts what decode refuses", t.model.title()));
        }
    }
    Ok(())
}

/// Any text as Intel HEX: bytes or one of the source's error flags; what it
/// reads, written again, reads back the same. (Not UTF-8: nothing to check.)
pub fn ihex_input(data: &[u8]) -> Result<(), String> {
    let Ok(text) = std::str::from_utf8(data) else {
        return Ok(());
    };
    if let Ok(bytes) = ihex::read(text, 4096) {
        let again = ihex::read(&ihex::write(&bytes), 4096);
        if again.as_deref() != Ok(&bytes[..]) {
            return Err(format!("read {} bytes, written and read again: {again:?}", bytes.len()));
        }
    }
    Ok(())
}
