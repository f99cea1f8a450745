//! The Model Checking Contest fixtures (`tests/mcc/corpus.tar.xz`, README.md beside
//! it): one directory per instance with `model.pnml`, the contest's formula files and
//! `oracle.out`, the expected answers. Shared by the tests and the benchmark.

use std::collections::BTreeMap;

/// One instance of the corpus.
pub struct Instance {
    /// `Kanban-PT-00005`.
    pub name: String,
    /// Its files by name (`model.pnml`, `UpperBounds.xml`, `oracle.out` …).
    pub files: BTreeMap<String, Vec<u8>>,
}

impl Instance {
    /// A file as text.
    pub fn text(&self, file: &str) -> Option<String> {
        self.files.get(file).map(|b| String::from_utf8_lossy(b).into_owned())
    }

    /// `STATE_SPACE <what> <n>` of the oracle (`STATES`, `TRANSITIONS`,
    /// `MAX_TOKEN_IN_PLACE`, `MAX_TOKEN_PER_MARKING`); `None` when unknown or infinite.
    pub fn state_space(&self, what: &str) -> Option<u64> {
        let oracle = self.text("oracle.out")?;
        oracle.lines().find_map(|l| {
            let mut w = l.split_whitespace();
            (w.next() == Some("STATE_SPACE") && w.next() == Some(what))
                .then(|| w.next()?.parse().ok())
                .flatten()
        })
    }
}

/// Every instance of the corpus, by name.
pub fn load() -> Vec<Instance> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/mcc/corpus.tar.xz");
    let xz = std::fs::read(&path).expect("tests/mcc/corpus.tar.xz");
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
        .into_iter()
        .map(|(name, files)| Instance { name, files })
        .collect()
}

/// The place/transition net of an instance.
pub fn net(i: &Instance) -> alba_net::PtNet {
    let text = i.text("model.pnml").expect("model.pnml");
    let (net, diags) = alba_net::load(alba_diag::FileId(0), &text);
    let errors: Vec<_> = diags.iter().filter(|d| !alba_net::is_warning(d)).collect();
    assert!(errors.is_empty(), "{}: {errors:?}", i.name);
    alba_net::PtNet::from_net(&net.expect("a net"))
}
