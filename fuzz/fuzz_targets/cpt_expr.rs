//! CPT expression parser: never panics; an error's span lies inside the
//! expression (which starts at byte 5 of the file here) on character
//! boundaries.
#![no_main]

use alba_diag::FileId;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    let base = 5;
    if let Err((msg, sp)) = alba_ladder::expr::parse(src, FileId(0), base) {
        let (s, e) = (sp.start as usize, sp.end as usize);
        assert!(
            base <= s && s <= e && e <= base + src.len(),
            "error span {s}..{e} outside the expression (base {base}, len {}): {msg}\ninput: {src:?}",
            src.len()
        );
        assert!(
            src.is_char_boundary(s - base) && src.is_char_boundary(e - base),
            "error span {s}..{e} not on character boundaries: {msg}\ninput: {src:?}"
        );
    }
});
