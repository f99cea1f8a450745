//! Golden tests of the parser: every `tests/parse/*.st` printed back as
//! fully parenthesised ST (`*.st.out`), and every `tests/errors/*.st` with
//! its rendered diagnostics (`*.st.err`). `ALBA_BLESS=1` rewrites them;
//! review every change.

use alba_diag::{Files, render_all};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join(name)
}

fn sources(d: &Path) -> Vec<PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(d)
        .expect("golden folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "st"))
        .collect();
    v.sort();
    v
}

fn check(path: &Path, ext: &str, got: &str, problems: &mut Vec<String>) {
    let golden = path.with_extension(ext);
    if std::env::var_os("ALBA_BLESS").is_some() {
        std::fs::write(&golden, got).expect("write golden");
        return;
    }
    let want = std::fs::read_to_string(&golden).unwrap_or_default();
    if want != got {
        problems.push(format!("{} differs (ALBA_BLESS=1 to accept):\n{got}", golden.display()));
    }
}

#[test]
fn parse_goldens() {
    let mut problems = Vec::new();
    let cases = sources(&dir("parse"));
    assert!(cases.len() >= 4, "parse goldens missing");
    for path in cases {
        let text = std::fs::read_to_string(&path).expect("read");
        let mut files = Files::new();
        let f = files.add(path.file_name().unwrap_or_default().to_string_lossy(), text.clone());
        let (ast, diags) = alba_st::parse(&text, f);
        if !diags.is_empty() {
            problems.push(format!(
                "{}: unexpected errors\n{}",
                path.display(),
                render_all(&diags, &files)
            ));
            continue;
        }
        let dump = alba_st::ast::dump(&ast);
        // What is printed parses again to the same tree.
        let (again, d2) = alba_st::parse(&dump, f);
        if !d2.is_empty() || alba_st::ast::dump(&again) != dump {
            problems.push(format!(
                "{}: the printed tree does not parse back the same",
                path.display()
            ));
        }
        check(&path, "st.out", &dump, &mut problems);
    }
    assert!(problems.is_empty(), "{}", problems.join("\n\n"));
}

#[test]
fn error_goldens() {
    let mut problems = Vec::new();
    let cases = sources(&dir("errors"));
    assert!(cases.len() >= 4, "error goldens missing");
    for path in cases {
        let text = std::fs::read_to_string(&path).expect("read");
        let mut files = Files::new();
        let f = files.add(path.file_name().unwrap_or_default().to_string_lossy(), text.clone());
        let (_, diags) = alba_st::parse(&text, f);
        if diags.is_empty() {
            problems.push(format!("{}: no error reported", path.display()));
        }
        check(&path, "st.err", &render_all(&diags, &files), &mut problems);
    }
    assert!(problems.is_empty(), "{}", problems.join("\n\n"));
}

/// Every prefix of every golden source (an edit in progress) parses to an
/// end, with errors but without a panic or a hang.
#[test]
fn every_prefix_of_every_golden_parses_to_an_end() {
    for d in ["parse", "errors"] {
        for path in sources(&dir(d)) {
            let text = std::fs::read_to_string(&path).expect("read");
            for (cut, _) in text.char_indices() {
                let (_, diags) = alba_st::parse(&text[..cut], alba_diag::FileId(0));
                assert!(
                    diags.len() <= cut + 1,
                    "{}: {} errors for {cut} bytes",
                    path.display(),
                    diags.len()
                );
            }
        }
    }
}
