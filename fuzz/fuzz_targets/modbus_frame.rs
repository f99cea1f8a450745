//! The Modbus TCP decoder and map: any byte stream is cut into frames,
//! each answered (reads, planned writes, exceptions) over a sample map with
//! every kind of entry, without a panic; every reply is well formed (see
//! `alba_modbus_proto::offline::answer_stream`).
#![no_main]

use alba_modbus_proto::map::Scratch;
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

static SAMPLE: OnceLock<(alba_modbus_proto::Map, alba_ir::Memory)> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let (map, mem) = SAMPLE.get_or_init(alba_modbus_proto::offline::sample);
    let scratch = Scratch::default();
    let _ = alba_modbus_proto::offline::answer_stream(data, map, mem, &scratch);
});
