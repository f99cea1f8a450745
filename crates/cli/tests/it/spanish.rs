//! Every message the malformed corpus provokes has its Spanish (issue 34
//! point 11): each case of `tests/malformed/` is run as `malformed.rs` runs
//! it, and each `error[CODE]: message` (or `warning[…]`) it prints must match
//! a template of `alba_diag::es::MESSAGES` under its code; so must the
//! Structured Text error goldens (`crates/st/tests/errors/*.err`). The nets'
//! corpus is checked by alba-net's own malformed test, the messages written
//! at their code by alba-diag's source scan (docs/i18n.md, "Adding a
//! message's Spanish").

use crate::alba;
use alba_diag::{Code, es};
use std::path::Path;

/// The `(code, message)` of each diagnostic headline in `text`.
fn headlines(text: &str) -> Vec<(Code, String)> {
    let mut out = Vec::new();
    for line in text.lines() {
        for head in ["error[E", "warning[E"] {
            let Some(at) = line.find(head) else { continue };
            let rest = &line[at + head.len() - 1..];
            let Some((code, message)) = rest.split_once("]: ") else {
                continue;
            };
            if let Ok(code) = code.parse::<Code>() {
                out.push((code, message.to_string()));
            }
        }
    }
    out
}

fn untranslated(source: &str, text: &str, missing: &mut Vec<String>) -> usize {
    let found = headlines(text);
    for (code, message) in &found {
        if es::message(*code, message).is_none() {
            missing.push(format!("{source}: {code} `{message}`"));
        }
    }
    found.len()
}

#[test]
fn every_message_of_the_malformed_corpus_has_its_spanish() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed");
    let mut cases: Vec<_> = std::fs::read_dir(&root)
        .expect("tests/malformed")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|d| d.join("cmd").exists())
        .collect();
    cases.sort();
    let mut missing = Vec::new();
    let mut seen = 0;
    for dir in &cases {
        let name = dir.file_name().unwrap_or_default().to_string_lossy().to_string();
        let cmd = std::fs::read_to_string(dir.join("cmd")).unwrap_or_default();
        let args: Vec<&str> = cmd.split_whitespace().collect();
        let out = alba(dir, &args);
        seen += untranslated(&name, &String::from_utf8_lossy(&out.stderr), &mut missing);
    }
    let st = Path::new(env!("CARGO_MANIFEST_DIR")).join("../st/tests/errors");
    let mut goldens: Vec<_> = std::fs::read_dir(&st)
        .expect("crates/st/tests/errors")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "err"))
        .collect();
    goldens.sort();
    for g in &goldens {
        let name = g.file_name().unwrap_or_default().to_string_lossy().to_string();
        seen += untranslated(&name, &std::fs::read_to_string(g).unwrap_or_default(), &mut missing);
    }
    assert!(
        seen >= 150,
        "only {seen} diagnostics in the corpus: is stderr still read?"
    );
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "{} messages have no Spanish template (crates/diag/src/es.rs MESSAGES):\n{}",
        missing.len(),
        missing.join("\n")
    );
}

/// The same corpus in Spanish: `LANG=es_ES.UTF-8` turns every headline into
/// its template's Spanish, so none keeps the fall-back `título: English`.
#[test]
fn a_malformed_project_checked_in_spanish_reads_spanish() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed/lad-unknown-tag");
    let out = crate::alba_env(&dir, &["check", "."], &[("LANG", "es_ES.UTF-8")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("error[E301]: variable desconocida `"), "{err}");
    assert!(!err.contains("unknown tag"), "{err}");
}

#[test]
fn headlines_are_read_in_both_forms() {
    let text = "error[E301]: unknown tag `Strat`\n  ┌─ main.lad:2:5\nmain.lad:1:1: error[E200]: unexpected `)`\nwarning[E109]: [opcua.users] is deprecated\nerror: not ours\n";
    let h = headlines(text);
    assert_eq!(h.len(), 3, "{h:?}");
    assert_eq!(h[0], (Code::UnknownTag, "unknown tag `Strat`".to_string()));
    assert_eq!(h[1], (Code::Syntax, "unexpected `)`".to_string()));
}
