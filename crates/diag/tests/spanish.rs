//! Every diagnostic message written in the sources has its Spanish (issue 34
//! point 11): a scan of `crates/*/src` finds each site that names a code and
//! then writes its message as a literal — `Diagnostic::new(Code::X, "…"`,
//! `err(Code::X, format!("…", …)`, `self.error(Code::X, "…"` — turns the
//! literal into its pattern (`{name}` → `{}`) and asks the Spanish catalogue
//! for it. A new message, or an English one reworded at its site, fails here
//! until `crates/diag/src/es.rs` `MESSAGES` has its template (docs/i18n.md).
//!
//! Messages that are only values (`{}: {}`) have nothing to translate and are
//! skipped; messages a site builds elsewhere than at the code (a variable
//! passed on) are caught by the CLI's Spanish run over the malformed corpus
//! (`crates/cli/tests/it/spanish.rs`).

use alba_diag::{Code, es};
use std::path::{Path, PathBuf};

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The code named by a variant's name (`UnknownTag`).
fn code_named(name: &str) -> Option<Code> {
    Code::ALL.iter().copied().find(|c| format!("{c:?}") == name)
}

/// The Rust string literal at the start of `s` (after its opening quote),
/// decoded as far as messages need: escaped quotes and backslashes, and line
/// continuations.
fn literal(s: &str) -> Option<String> {
    let mut out = String::new();
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => return Some(out),
            '\\' => match chars.next()? {
                '\n' => {
                    while chars.peek().is_some_and(|c| c.is_whitespace()) {
                        chars.next();
                    }
                }
                'n' => out.push('\n'),
                't' => out.push('\t'),
                other => out.push(other),
            },
            c => out.push(c),
        }
    }
    None
}

/// A format string's pattern: each `{…}` argument becomes `{}`, `{{` and
/// `}}` their brace.
fn pattern(fmt: &str) -> String {
    let mut out = String::new();
    let mut chars = fmt.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '{' if chars.peek() == Some(&'{') => {
                chars.next();
                out.push('{');
            }
            '}' if chars.peek() == Some(&'}') => {
                chars.next();
                out.push('}');
            }
            '{' => {
                for c in chars.by_ref() {
                    if c == '}' {
                        break;
                    }
                }
                out.push_str("{}");
            }
            c => out.push(c),
        }
    }
    out
}

/// The message literal at the start of `rest` (an argument list), if any:
/// `"…"`, `&format!("…"`, `format!("…"`.
fn message_at(rest: &str) -> Option<String> {
    let mut rest = rest.trim_start();
    rest = rest.strip_prefix('&').unwrap_or(rest);
    if let Some(r) = rest.strip_prefix("format!(") {
        rest = r.trim_start();
    }
    literal(rest.strip_prefix('"')?).map(|l| pattern(&l))
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The top-level arguments of a call whose text starts after its `(`.
fn arguments(rest: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let (mut depth, mut start, mut in_str, mut escaped) = (0i32, 0, false, false);
    for (i, c) in rest.char_indices() {
        if in_str {
            match c {
                _ if escaped => escaped = false,
                '\\' => escaped = true,
                '"' => in_str = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => in_str = true,
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' if depth == 0 => {
                out.push(&rest[start..i]);
                return out;
            }
            ')' | ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                out.push(&rest[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out
}

/// The helpers of a file that build a diagnostic of one fixed code from a
/// message they are given (`fn bad(msg: String) -> Diagnostic {
/// Diagnostic::unplaced(Code::BadArgument, msg) }`): (name, position of the
/// message among the arguments, code).
fn helpers(text: &str) -> Vec<(String, usize, Code)> {
    let mut out = Vec::new();
    for (at, _) in text.match_indices("fn ") {
        if text[..at].chars().next_back().is_some_and(is_ident) {
            continue;
        }
        let rest = &text[at + 3..];
        let name_len = rest.find(|c: char| !is_ident(c)).unwrap_or(rest.len());
        let name = &rest[..name_len];
        let Some(params) = rest[name_len..].strip_prefix('(') else {
            continue;
        };
        let params: Vec<&str> = arguments(params)
            .into_iter()
            .map(str::trim)
            .filter(|p| !p.is_empty() && !p.ends_with("self"))
            .collect();
        if params.iter().any(|p| p.contains(": Code")) {
            continue;
        }
        let Some(position) = params
            .iter()
            .position(|p| p.starts_with("msg:") || p.starts_with("message:"))
        else {
            continue;
        };
        // The body: up to the function's closing brace at its indentation.
        let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
        let indent = &text[line_start..at];
        let body = rest.split(&format!("\n{indent}}}")).next().unwrap_or("");
        let mut codes: Vec<Code> = body
            .match_indices("Code::")
            .filter_map(|(i, _)| {
                let r = &body[i + 6..];
                code_named(&r[..r.find(|c: char| !is_ident(c)).unwrap_or(r.len())])
            })
            .collect();
        codes.dedup();
        if let [code] = codes[..] {
            out.push((name.to_string(), position, code));
        }
    }
    out
}

/// Each `(code, message pattern)` written in `text` (its `#[cfg(test)]`
/// part left out): after the code itself, or as the first argument of a
/// helper of the file that fixes the code ([`helpers`]).
fn sites(text: &str) -> Vec<(Code, String)> {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    let mut out = Vec::new();
    for (name, position, code) in helpers(text) {
        let call = format!("{name}(");
        for (at, _) in text.match_indices(&call) {
            let before = &text[..at];
            if before.chars().next_back().is_some_and(is_ident) || before.ends_with("fn ") {
                continue;
            }
            let args = arguments(&text[at + call.len()..]);
            if let Some(p) = args.get(position).and_then(|a| message_at(a)) {
                out.push((code, p));
            }
        }
    }
    for (at, _) in text.match_indices("Code::") {
        if text[..at]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_')
        {
            continue; // StatusCode::…
        }
        let rest = &text[at + 6..];
        let name_len = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        let Some(code) = code_named(&rest[..name_len]) else {
            continue;
        };
        let rest = rest[name_len..].trim_start();
        let Some(rest) = rest.strip_prefix(',') else { continue };
        if let Some(p) = message_at(rest) {
            out.push((code, p));
        }
    }
    out
}

#[test]
fn every_message_written_at_its_code_has_its_spanish() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for e in std::fs::read_dir(&crates).expect("the crates folder").flatten() {
        if e.file_name() != "diag" {
            sources(&e.path().join("src"), &mut files);
        }
    }
    files.sort();
    let mut count = 0;
    let mut missing = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        for (code, pat) in sites(&text) {
            // Only values: nothing to translate.
            if !pat.replace("{}", "").chars().any(|c| c.is_ascii_alphabetic()) {
                continue;
            }
            count += 1;
            if es::message(code, &pat).is_none() {
                let f = f.strip_prefix(&crates).unwrap_or(f).display();
                missing.push(format!("{f}: ({code:?}, \"{pat}\", \"…\")"));
            }
        }
    }
    assert!(
        count > 200,
        "the scan found only {count} messages: is it still reading the sources?"
    );
    println!("{count} messages written at their code");
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "{} of {count} messages have no Spanish template in crates/diag/src/es.rs MESSAGES:\n{}",
        missing.len(),
        missing.join("\n")
    );
}

#[test]
fn the_scan_reads_sites_as_written() {
    let src = r#"
        let d = Diagnostic::new(Code::UnknownTag, format!("unknown tag `{name}`"), span, "here");
        e.error(Code::PnmlNumber, "a <position> needs decimal `x` and `y`", s, "bad");
        (StatusCode::FORBIDDEN, "no");
        err(Code::BadLiteral, &format!("{v:?} does not fit {{DINT}}"));
        #[cfg(test)]
        Diagnostic::unplaced(Code::Io, "in a test");
    "#;
    assert_eq!(
        sites(src),
        vec![
            (Code::UnknownTag, "unknown tag `{}`".to_string()),
            (Code::PnmlNumber, "a <position> needs decimal `x` and `y`".to_string()),
            (Code::BadLiteral, "{} does not fit {DINT}".to_string()),
        ]
    );
    let helper = r#"
fn bad(msg: String, span: Span) -> Diagnostic {
    Diagnostic::new(Code::NetElement, msg, span, "here")
}
fn other() {
    d.push(bad(format!("a Timer needs a `{what}`"), span));
    bad(msg, span);
}
"#;
    assert_eq!(helpers(helper), vec![("bad".to_string(), 0, Code::NetElement)]);
    let later = "fn push(d: &mut Vec<Diagnostic>, msg: String) { d.push(Diagnostic::unplaced(Code::AlarmFile, msg)) }\nfn f() { push(&mut d, format!(\"`{id}`, (a, b)\")); }";
    assert_eq!(sites(later), vec![(Code::AlarmFile, "`{}`, (a, b)".to_string())]);
    assert_eq!(
        sites(helper),
        vec![(Code::NetElement, "a Timer needs a `{}`".to_string())]
    );
    assert_eq!(literal("a \\\"b\\\" \\\n    c\" rest"), Some("a \"b\" c".to_string()));
}
