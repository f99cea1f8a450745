//! `alarms.csv` parser (`alba_alarms::parse`) against a layout with every
//! type: never panics; every diagnostic span lies inside the input on
//! character boundaries and renders; alarm ids come out unique.
#![no_main]

use alba_diag::Files;
use alba_ir::Layout;
use alba_ir::layout::Uses;
use alba_model::TagTable;
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

#[path = "../../crates/ladder/tests/it/check.rs"]
mod check;

const TAGS: &str = "name,type,address,initial,retain,description\n\
Level,REAL,,,,\nPump,BOOL,DO:2/0,,,\nCount,DINT,,,,\nRaw,INT,AI:3/0,,,\nDelay,TIMER,,,,\nBig,LREAL,,,,\n";

fn layout() -> &'static Layout {
    static L: OnceLock<Layout> = OnceLock::new();
    L.get_or_init(|| {
        let mut files = Files::new();
        let f = files.add("tags.csv", TAGS);
        let (tags, _) = TagTable::parse(TAGS, f);
        Layout::new(&tags, &Uses::default())
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    let mut files = Files::new();
    let f = files.add("alarms.csv", src);
    let (defs, diags) = alba_alarms::parse(src, f, layout());
    if let Err(e) = check::diag_spans(src, f, &diags) {
        panic!("{e}\ninput: {src:?}");
    }
    for d in &diags {
        let _ = d.render(&files);
    }
    let mut ids: Vec<String> = defs.iter().map(|d| d.id.to_ascii_lowercase()).collect();
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), defs.len(), "duplicate ids in {src:?}");
});
