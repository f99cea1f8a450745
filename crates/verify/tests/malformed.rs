//! Bad input never panics: properties.toml and test tables, mutated at
//! random from valid files, are parsed to a value or to diagnostics whose
//! spans lie inside the input on character boundaries.

mod common;

use alba_diag::{Diagnostic, Files};
use common::*;
use proptest::prelude::*;

const PROPS: &str = r#"[[property]]
name = "never both"
mutex = ["Fwd", "Rev"]

[[property]]
name = "stop wins"
never = "Stop AND (Fwd OR Rev)"

[[property]]
name = "r"
response = { trigger = "FwdBtn", then = "Fwd", within_ms = 10 }

[[assume]]
expr = "NOT (FwdBtn AND RevBtn)"

[domain]
FwdBtn = [0, 1]
"#;

const TABLE: &str = "time_ms,FwdBtn,RevBtn,Stop,expect:Fwd,expect:Rev\n0,1,0,0,1,0\n10,0,1,,1,0\n20,,,1,0,0\n";

fn spans_ok(src: &str, diags: &[Diagnostic]) -> Result<(), String> {
    for d in diags {
        for l in d.primary.iter().chain(d.secondary.iter()) {
            let (a, b) = (l.span.start as usize, l.span.end as usize);
            if a > b || b > src.len() || !src.is_char_boundary(a) || !src.is_char_boundary(b) {
                return Err(format!("span {a}..{b} outside {} bytes: {}", src.len(), d.message));
            }
        }
    }
    Ok(())
}

/// A mutation: delete, duplicate or replace a range, or insert a piece.
fn mutate(src: &str, at: usize, len: usize, kind: u8, piece: &str) -> String {
    let chars: Vec<char> = src.chars().collect();
    let at = at % (chars.len() + 1);
    let end = (at + len).min(chars.len());
    let (a, b): (String, String) = (chars[..at].iter().collect(), chars[end..].iter().collect());
    let mid: String = chars[at..end].iter().collect();
    match kind % 4 {
        0 => format!("{a}{b}"),
        1 => format!("{a}{mid}{mid}{b}"),
        2 => format!("{a}{piece}{b}"),
        _ => format!("{a}{piece}{mid}{b}"),
    }
}

const PIECES: &[&str] = &[
    "\"",
    "[",
    "]",
    "{",
    "}",
    "=",
    ",",
    "\n",
    "é",
    "never = \"",
    "mutex = [",
    "AND",
    "((",
    "T#",
    "-1",
    "99999999999999999999",
    "expect:",
    "expect:Nope",
    ".ACC",
    "\u{0}",
    "[[property]]",
    "\\u00e9",
    "\\\"",
    "\"\"\"",
    "'",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn mutated_properties_parse_or_are_refused_in_place(
        at in 0usize..400, len in 0usize..12, kind in any::<u8>(), p in 0..PIECES.len(),
    ) {
        let prog = compile(MOTOR_TAGS, MOTOR);
        let text = mutate(PROPS, at, len, kind, PIECES[p]);
        let mut files = Files::new();
        let f = files.add("properties.toml", text.clone());
        if let Err(d) = alba_verify::props::parse(&text, f, &prog.layout) {
            prop_assert!(!d.is_empty());
            prop_assert!(spans_ok(&text, &d).is_ok(), "{:?}\n{}", spans_ok(&text, &d), text);
            for x in &d {
                let _ = x.render(&files);
            }
        }
    }

    #[test]
    fn mutated_tables_parse_or_are_refused_in_place(
        at in 0usize..120, len in 0usize..8, kind in any::<u8>(), p in 0..PIECES.len(),
    ) {
        let prog = compile(MOTOR_TAGS, MOTOR);
        let text = mutate(TABLE, at, len, kind, PIECES[p]);
        let mut files = Files::new();
        let f = files.add("t.test.csv", text.clone());
        match alba_verify::table::parse(&text, f, &prog.layout) {
            Ok(t) => {
                let mut cov = alba_verify::table::Coverage::new(&prog);
                let _ = alba_verify::table::run(&prog, SCAN_MS, &t, &mut cov);
            }
            Err(d) => {
                prop_assert!(!d.is_empty());
                prop_assert!(spans_ok(&text, &d).is_ok(), "{:?}\n{}", spans_ok(&text, &d), text);
            }
        }
    }

    #[test]
    fn any_text_is_refused_without_panic(text in "\\PC{0,80}") {
        let prog = compile(MOTOR_TAGS, MOTOR);
        let mut files = Files::new();
        let f = files.add("x", text.clone());
        if let Err(d) = alba_verify::props::parse(&text, f, &prog.layout) {
            prop_assert!(spans_ok(&text, &d).is_ok());
        }
        if let Err(d) = alba_verify::table::parse(&text, f, &prog.layout) {
            prop_assert!(spans_ok(&text, &d).is_ok());
        }
    }
}
