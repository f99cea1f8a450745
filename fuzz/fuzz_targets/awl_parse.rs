//! AWL (S7-200 Instruction List) parser: never panics, every diagnostic
//! span lies inside the input on character boundaries (and renders), and
//! every span of the parsed program covers what it claims.
#![no_main]

use alba_diag::Files;
use libfuzzer_sys::fuzz_target;

#[path = "../../crates/il/tests/it/check.rs"]
mod check;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    match check::awl_input(src) {
        Ok(diags) => {
            let mut files = Files::new();
            files.add("main.awl", src);
            for d in &diags {
                let _ = d.short(&files);
                let _ = d.render(&files);
            }
        }
        Err(e) => panic!("{e}\ninput: {src:?}"),
    }
});
