//! `tags.csv` parser: never panics; every diagnostic span lies inside the
//! input on character boundaries, and each diagnostic renders.
//!
//! With `ALBA_FUZZ_LENIENT_SPANS=1` a span off a character boundary is
//! tolerated (spans must still lie inside the input), to look for other
//! bugs while a known one is not fixed yet.
#![no_main]

use alba_diag::Files;
use alba_model::TagTable;
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

fn lenient() -> bool {
    static L: OnceLock<bool> = OnceLock::new();
    *L.get_or_init(|| std::env::var_os("ALBA_FUZZ_LENIENT_SPANS").is_some())
}

#[path = "../../crates/ladder/tests/it/check.rs"]
mod check;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    let mut files = Files::new();
    let f = files.add("tags.csv", src);
    let (_table, diags) = TagTable::parse(src, f);
    if let Err(e) = check::diag_spans(src, f, &diags)
        && !(lenient() && e.contains("not on character boundaries"))
    {
        panic!("{e}\ninput: {src:?}");
    }
    for d in &diags {
        let _ = d.short(&files);
        let _ = d.render(&files);
    }
});
