//! The diagnostics index (`docs/diagnostics.md`) agrees with the catalogue of
//! codes (`src/codes.rs`): every code has one section headed
//! `### E301 — <its exact title>` that quotes its explanation, the index table
//! lists it with the same title, and no code the catalogue does not know is
//! mentioned anywhere on the page. When this fails after a change to
//! `codes.rs`, update `docs/diagnostics.md`.

use alba_diag::Code;
use std::collections::BTreeMap;
use std::path::Path;

fn page() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/diagnostics.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// A code as written (`E301`) if `s` starts with one: `E` and three digits
/// not followed by another digit.
fn code_at(s: &str) -> Option<&str> {
    let b = s.as_bytes();
    let is_code = b.len() >= 4
        && b[0] == b'E'
        && b[1..4].iter().all(u8::is_ascii_digit)
        && !b.get(4).is_some_and(u8::is_ascii_digit);
    is_code.then(|| &s[..4])
}

/// The sections of the page: heading code → (title, lines of the section).
fn sections(text: &str) -> Vec<(String, String, Vec<&str>)> {
    let mut out: Vec<(String, String, Vec<&str>)> = Vec::new();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("### ")
            && let Some(code) = code_at(rest)
        {
            let title = rest[code.len()..]
                .strip_prefix(" — ")
                .unwrap_or_else(|| panic!("heading `{line}`: write `### {code} — <title>`"));
            out.push((code.to_string(), title.to_string(), Vec::new()));
            continue;
        }
        if line.starts_with('#') {
            // Any other heading ends the code's section.
            out.push((String::new(), String::new(), Vec::new()));
            continue;
        }
        if let Some(last) = out.last_mut() {
            last.2.push(line);
        }
    }
    out.retain(|(code, _, _)| !code.is_empty());
    out
}

/// Rows of the index table: `| [E301](#e301) | title |` or `| E301 | title |`.
fn index_rows(text: &str) -> BTreeMap<String, String> {
    let mut rows = BTreeMap::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 || !cells[0].is_empty() {
            continue;
        }
        let first = cells[1].trim_start_matches('[');
        let Some(code) = code_at(first) else { continue };
        let prev = rows.insert(code.to_string(), cells[2].to_string());
        assert!(prev.is_none(), "{code} is listed twice in the index table");
    }
    rows
}

#[test]
fn every_code_has_one_section_with_its_exact_title_and_explanation() {
    let text = page();
    let sections = sections(&text);
    let mut problems = Vec::new();
    for c in Code::ALL {
        let code = c.to_string();
        let found: Vec<_> = sections.iter().filter(|(k, _, _)| *k == code).collect();
        match found.as_slice() {
            [] => problems.push(format!("{code} has no section `### {code} — {}`", c.title())),
            [(_, title, lines)] => {
                if title != c.title() {
                    problems.push(format!(
                        "{code}: the page's title is `{title}`, codes.rs says `{}`",
                        c.title()
                    ));
                }
                let quote = format!("> {}", c.explanation());
                if !lines.iter().any(|l| l.trim_end() == quote) {
                    problems.push(format!("{code}: the section does not quote the explanation:\n{quote}"));
                }
            }
            _ => problems.push(format!("{code} has {} sections", found.len())),
        }
    }
    assert!(problems.is_empty(), "docs/diagnostics.md:\n{}", problems.join("\n"));
}

#[test]
fn the_index_table_lists_every_code_with_its_title() {
    let text = page();
    let rows = index_rows(&text);
    let mut problems = Vec::new();
    for c in Code::ALL {
        let code = c.to_string();
        match rows.get(&code) {
            None => problems.push(format!("{code} is missing from the index table")),
            Some(title) if title != c.title() => problems.push(format!(
                "{code}: the index says `{title}`, codes.rs says `{}`",
                c.title()
            )),
            Some(_) => {}
        }
    }
    assert!(problems.is_empty(), "docs/diagnostics.md:\n{}", problems.join("\n"));
}

#[test]
fn no_unknown_code_is_mentioned() {
    let text = page();
    let known: Vec<String> = Code::ALL.iter().map(Code::to_string).collect();
    let mut unknown = Vec::new();
    for (n, line) in text.lines().enumerate() {
        for (i, _) in line.match_indices('E') {
            let before = line[..i].chars().next_back();
            if before.is_some_and(|ch| ch.is_ascii_alphanumeric()) {
                continue;
            }
            if let Some(code) = code_at(&line[i..])
                && !known.iter().any(|k| k == code)
            {
                unknown.push(format!("line {}: {code}", n + 1));
            }
        }
    }
    assert!(
        unknown.is_empty(),
        "docs/diagnostics.md mentions codes that codes.rs does not have:\n{}",
        unknown.join("\n")
    );
}

#[test]
fn sections_follow_the_catalogue_order() {
    let text = page();
    let order: Vec<String> = sections(&text).into_iter().map(|(k, _, _)| k).collect();
    let want: Vec<String> = Code::ALL.iter().map(Code::to_string).collect();
    assert_eq!(
        order, want,
        "docs/diagnostics.md: the sections are not in the order of codes.rs"
    );
}
