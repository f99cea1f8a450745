//! `alba.toml` parser: never panics; every diagnostic span lies inside the
//! input on character boundaries, and each diagnostic renders.
#![no_main]

use alba_diag::Files;
// The reader of alba.toml is alba-load's (ADR 0014): both its project and services' tables.
use libfuzzer_sys::fuzz_target;

#[path = "../../crates/ladder/tests/it/check.rs"]
mod check;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    let mut files = Files::new();
    let f = files.add("alba.toml", src);
    let (_config, _settings, diags) = alba_load::parse_both(src, f);
    if let Err(e) = check::diag_spans(src, f, &diags) {
        panic!("{e}\ninput: {src:?}");
    }
    for d in &diags {
        let _ = d.short(&files);
        let _ = d.render(&files);
    }
});
