//! The Model Checking Contest corpus (`crates/net/tests/mcc/corpus.tar.xz`,
//! licences in the README beside it), read for the tests of every crate that
//! uses it: one directory per instance with `model.pnml`, the contest's
//! formula files and `oracle.out`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The corpus in the repository.
pub fn corpus_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../net/tests/mcc/corpus.tar.xz")
}

/// The coloured (symmetric net) instances beside it: `col.tar.xz`.
pub fn coloured_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../net/tests/mcc/col.tar.xz")
}

/// Every instance's files by name (`Kanban-PT-00005` → `model.pnml` → bytes).
pub fn instances() -> BTreeMap<String, BTreeMap<String, Vec<u8>>> {
    instances_in(&corpus_path())
}

/// Every instance of an archive laid out like the corpus (`col.tar.xz` too).
pub fn instances_in(archive: &Path) -> BTreeMap<String, BTreeMap<String, Vec<u8>>> {
    let xz = std::fs::read(archive).unwrap_or_else(|e| panic!("{}: {e}", archive.display()));
    let mut tar = Vec::new();
    lzma_rs::xz_decompress(&mut &xz[..], &mut tar).expect("xz");
    let mut by_name: BTreeMap<String, BTreeMap<String, Vec<u8>>> = BTreeMap::new();
    // ustar: 512-byte headers (name at 0, octal size at 124, type at 156), data padded to 512.
    let mut at = 0;
    while at + 512 <= tar.len() && tar[at] != 0 {
        let header = &tar[at..at + 512];
        let name = String::from_utf8_lossy(&header[..100])
            .trim_end_matches('\0')
            .to_string();
        let size_text = String::from_utf8_lossy(&header[124..136]);
        let size = usize::from_str_radix(size_text.trim_matches(|c: char| c == '\0' || c == ' '), 8).expect("size");
        let data = tar[at + 512..at + 512 + size].to_vec();
        at += 512 + size.div_ceil(512) * 512;
        if header[156] != b'0' && header[156] != 0 {
            continue;
        }
        let parts: Vec<&str> = name.trim_start_matches("./").split('/').collect();
        if let [instance, file] = parts[..] {
            by_name
                .entry(instance.to_string())
                .or_default()
                .insert(file.to_string(), data);
        }
    }
    by_name
}
