//! The script parser of normal-mode Expression elements
//! (`alba_net::script::parse`): never panics; every error offset lies inside
//! the text (or at its end); a parsed script's statements point into the
//! text at their expressions.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    match alba_net::script::parse(src) {
        Ok(s) => {
            for st in &s.statements {
                assert!(src.get(st.offset..st.offset + st.expr.len()).is_some(), "{st:?} in {src:?}");
            }
        }
        Err(errors) => {
            assert!(!errors.is_empty());
            for e in &errors {
                assert!(e.offset <= src.len(), "{e:?} in {src:?}");
                let _ = alba_net::script::line_col(src, e.offset);
            }
        }
    }
});
