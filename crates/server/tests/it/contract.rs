//! The studio's TypeScript (web/src/api.gen.ts, re-exported by
//! web/src/types.ts) against the server's reply types: regenerate with
//! `UPDATE_BINDINGS=1 cargo test -p alba-server contract`, then the
//! studio's `npm run build` checks its code against them.

use std::path::Path;

#[test]
fn web_types_match_the_reply_types() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../web/src/api.gen.ts");
    let want = alba_server::reply::typescript();
    if std::env::var_os("UPDATE_BINDINGS").is_some() {
        std::fs::write(&file, &want).expect("write web/src/api.gen.ts");
        return;
    }
    let have = std::fs::read_to_string(&file).unwrap_or_default();
    assert!(
        have == want,
        "web/src/api.gen.ts differs from the server's reply types (crates/server/src/reply.rs): \
         run `UPDATE_BINDINGS=1 cargo test -p alba-server contract`, then `npm run build` in web/"
    );
}
