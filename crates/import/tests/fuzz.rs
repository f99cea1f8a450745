//! Random mutations of the real fixtures never panic: every input gives a
//! checked project or an error (the importer's and the compiler's code on
//! the way are both exercised). The AuroraLD folders are mutated as one
//! text (`Folder::join`), as the `import_aurora` fuzz target reads them.

use alba_import::{Format, Options};
use proptest::prelude::*;
use std::fs;
use std::path::{Path, PathBuf};

const TOKENS: &[&str] = &[
    "PARALLEL\n",
    "SERIES\n",
    "END\n",
    "RUNG\n",
    "TON T 100000\n",
    "CTC C 3\n",
    "OSF\n",
    "COIL Y 1 0 0\n",
    "CONTACTS X 1\n",
    "<",
    ">",
    "</",
    "/>",
    "&",
    "&amp;",
    "\"",
    "<contact localId=\"9\">",
    "refLocalId=\"1\"",
    "<block localId=\"77\" typeName=\"TON\" instanceName=\"x\">",
    "[",
    "]",
    "(",
    ")",
    ",",
    ";",
    "?",
    "XIC(",
    "JSR(",
    "Local:1:I.Data.",
    "<![CDATA[",
    "]]>",
    "\u{feff}",
    "\u{0}",
    "é",
    "==> tags.pl <==\n",
    "==> x.pcs <==\n",
    "BST\n",
    "XIC\n",
    "255\n",
    "200\n",
    "-1\n",
    "true\n",
    "NUM\n",
    "?\n",
    "T1.DN\n",
];

fn fixtures() -> Vec<(PathBuf, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let mut v = Vec::new();
    for dir in ["ldmicro", "plcopen", "l5x"] {
        let mut files: Vec<PathBuf> = fs::read_dir(root.join(dir))
            .expect("fixtures")
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e != "md"))
            .collect();
        files.sort();
        for f in files {
            let bytes = fs::read(&f).expect("read");
            v.push((f, bytes));
        }
    }
    // AuroraLD folders, each as one text (`Folder::join`).
    let mut dirs: Vec<PathBuf> = fs::read_dir(root.join("aurora"))
        .expect("fixtures")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    for d in dirs {
        let folder = alba_import::aurora::Folder::read(&d).expect("folder");
        v.push((d.with_extension("aurora"), folder.join().into_bytes()));
    }
    v
}

#[derive(Debug, Clone)]
enum Mutation {
    Byte(usize, u8),
    Delete(usize, usize),
    Duplicate(usize, usize),
    Insert(usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Byte(p, b)),
        (any::<usize>(), 1usize..200).prop_map(|(p, n)| Mutation::Delete(p, n)),
        (any::<usize>(), 1usize..200).prop_map(|(p, n)| Mutation::Duplicate(p, n)),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(p, t)| Mutation::Insert(p, t)),
    ]
}

fn apply(mut b: Vec<u8>, ms: &[Mutation]) -> Vec<u8> {
    for m in ms {
        if b.is_empty() {
            break;
        }
        match *m {
            Mutation::Byte(p, x) => {
                let i = p % b.len();
                b[i] = x;
            }
            Mutation::Delete(p, n) => {
                let i = p % b.len();
                let j = (i + n).min(b.len());
                b.drain(i..j);
            }
            Mutation::Duplicate(p, n) => {
                let i = p % b.len();
                let j = (i + n).min(b.len());
                let piece = b[i..j].to_vec();
                b.splice(i..i, piece);
            }
            Mutation::Insert(p, t) => {
                let i = p % (b.len() + 1);
                b.splice(i..i, TOKENS[t].bytes());
            }
        }
    }
    b
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_fixtures_never_panic(which in any::<usize>(), ms in prop::collection::vec(mutation(), 1..6), force_format in any::<bool>()) {
        let all = fixtures();
        let (path, bytes) = &all[which % all.len()];
        let text = String::from_utf8_lossy(&apply(bytes.clone(), &ms)).into_owned();
        let format = if force_format { alba_import::detect(path, &String::from_utf8_lossy(bytes)) } else { None };
        let opts = Options { format, board: None, force: false };
        if path.extension().is_none_or(|e| e != "aurora") {
            let _ = alba_import::convert(path, &text, &opts);
        }
        for f in Format::ALL {
            if let Err(e) = alba_import::fuzz::check(f, text.as_bytes()) {
                panic!("{f}: {e}");
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, failure_persistence: None, ..ProptestConfig::default() })]

    /// The AuroraLD folders alone (positional files: a value out of place
    /// anywhere must give a located error or a refusal, never a panic).
    #[test]
    fn mutated_aurora_folders_never_panic(which in any::<usize>(), ms in prop::collection::vec(mutation(), 1..8)) {
        let all: Vec<_> = fixtures().into_iter().filter(|(p, _)| p.extension().is_some_and(|e| e == "aurora")).collect();
        let (_, bytes) = &all[which % all.len()];
        let data = apply(bytes.clone(), &ms);
        if let Err(e) = alba_import::fuzz::check(Format::Aurora, &data) {
            panic!("{e}");
        }
    }
}
