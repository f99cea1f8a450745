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
        self.state_space_text(what)?.parse().ok()
    }

    /// The same as decimal text, of any size (`Philosophers-PT-000100` has 5·10^47 states).
    pub fn state_space_text(&self, what: &str) -> Option<String> {
        let oracle = self.text("oracle.out")?;
        oracle.lines().find_map(|l| {
            let mut w = l.split_whitespace();
            (w.next() == Some("STATE_SPACE") && w.next() == Some(what))
                .then(|| {
                    w.next()
                        .filter(|n| n.bytes().all(|b| b.is_ascii_digit()))
                        .map(String::from)
                })
                .flatten()
        })
    }
}

/// Every instance of the corpus, by name.
pub fn load() -> Vec<Instance> {
    alba_testkit::mcc::instances()
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
