//! Inputs the fuzz target `modbus_frame` found (or that guard its corners),
//! replayed through the same harness (`alba_modbus_proto::offline`): each must be
//! answered without a panic. See `tests/fuzz_regressions/README.md`.

use alba_modbus_proto::map::Scratch;
use alba_modbus_proto::offline::{answer_stream, sample};
use std::path::Path;

#[test]
fn every_fuzz_regression_input_is_answered() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let (map, mem) = sample();
    let cases = alba_testkit::cases(&dir);
    assert!(!cases.is_empty());
    for path in cases {
        let data = std::fs::read(&path).unwrap();
        let sc = Scratch::default();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| answer_stream(&data, &map, &mem, &sc)));
        assert!(r.is_ok(), "{} panics", path.display());
    }
}
