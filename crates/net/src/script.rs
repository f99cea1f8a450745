//! The script of an Expression element (the source's code editor programs,
//! `003_…` §2.2.3.5 and §4.5.4; docs/nets.md "Scripts"): sections
//! `define{…}` (the names the function uses), `constant{…}` (or `const{…}`:
//! `name = number`, comma- or line-separated) and `function{…}` (statements
//! separated by `;` or line ends), and `//` comments. A statement is
//! `target = expression` or a bare expression, whose value goes to the
//! element's own variable (the source's "direct assignment"). Expressions
//! are Alba's expression language (the guards' and CPT's); this module only
//! splits the sections and statements and keeps where each one starts
//! (byte offsets in the script text), so errors point at the script's
//! line:col. No I/O.

/// A parsed script.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Script {
    /// `define{a, b}`: names and their offsets.
    pub defines: Vec<(String, usize)>,
    /// `constant{k = 2.5}`: name, value, offset.
    pub constants: Vec<(String, f64, usize)>,
    pub statements: Vec<Statement>,
}

/// One statement of `function{…}`.
#[derive(Debug, Clone, PartialEq)]
pub struct Statement {
    /// `target =` (name and offset), or `None` for a direct assignment.
    pub target: Option<(String, usize)>,
    /// The expression's text and its offset in the script.
    pub expr: String,
    pub offset: usize,
}

/// A problem in a script: what, and the byte offset where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScriptError {
    pub message: String,
    pub offset: usize,
}

/// The longest script read (characters of a source's code editor).
pub const MAX_SCRIPT: usize = 64 * 1024;

/// Line and column (both from 1) of byte `offset` in `text` (an offset
/// inside a character counts as that character's).
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut at = offset.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

fn err(message: impl Into<String>, offset: usize) -> ScriptError {
    ScriptError {
        message: message.into(),
        offset,
    }
}

fn is_ident(s: &str) -> bool {
    let mut c = s.chars();
    c.next().is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && s.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '.')
}

/// The text with `//` comments blanked (offsets kept).
fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        match line.find("//") {
            Some(k) => {
                out.push_str(&line[..k]);
                // One space per byte, so that offsets stay the text's.
                for c in line[k..].chars() {
                    if c == '\n' {
                        out.push('\n');
                    } else {
                        out.extend(std::iter::repeat_n(' ', c.len_utf8()));
                    }
                }
            }
            None => out.push_str(line),
        }
    }
    out
}

/// Items of a section body split at `seps`, trimmed, with their offsets
/// (relative to `base`); empty items are skipped.
fn items(body: &str, base: usize, seps: &[char]) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (k, c) in body.char_indices().chain([(body.len(), ';')]) {
        if seps.contains(&c) || k == body.len() {
            let raw = &body[start..k];
            let lead = raw.len() - raw.trim_start().len();
            let t = raw.trim();
            if !t.is_empty() {
                out.push((t.to_string(), base + start + lead));
            }
            start = k + c.len_utf8();
        }
    }
    out
}

/// Parses a script. Every problem is reported.
pub fn parse(text: &str) -> Result<Script, Vec<ScriptError>> {
    if text.len() > MAX_SCRIPT {
        return Err(vec![err(format!("a script is at most {MAX_SCRIPT} bytes"), 0)]);
    }
    let clean = strip_comments(text);
    let mut script = Script::default();
    let mut errors = Vec::new();
    let mut pos = 0;
    let mut seen_function = false;
    while pos < clean.len() {
        let rest = &clean[pos..];
        let skip = rest.len() - rest.trim_start().len();
        pos += skip;
        if pos >= clean.len() {
            break;
        }
        let rest = &clean[pos..];
        let word_len = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        let word = &rest[..word_len];
        let kind = match word {
            "define" => 0,
            "constant" | "const" => 1,
            "function" => 2,
            _ => {
                errors.push(err(
                    format!(
                        "expected a section `define{{…}}`, `constant{{…}}` or `function{{…}}`, found `{}`",
                        rest.chars().take(20).collect::<String>().trim()
                    ),
                    pos,
                ));
                return Err(errors);
            }
        };
        let after = pos + word_len;
        let open = clean[after..].find(|c: char| !c.is_whitespace()).map(|k| after + k);
        let Some(open) = open.filter(|&o| clean[o..].starts_with('{')) else {
            errors.push(err(format!("`{word}` is followed by `{{`"), after));
            return Err(errors);
        };
        let Some(close) = clean[open + 1..].find('}').map(|k| open + 1 + k) else {
            errors.push(err(format!("the `{word}` section has no closing `}}`"), open));
            return Err(errors);
        };
        let body = &clean[open + 1..close];
        match kind {
            0 => {
                for (name, at) in items(body, open + 1, &[',', '\n', ';']) {
                    if is_ident(&name) {
                        script.defines.push((name, at));
                    } else {
                        errors.push(err(format!("`{name}` is not a name"), at));
                    }
                }
            }
            1 => {
                for (item, at) in items(body, open + 1, &[',', '\n', ';']) {
                    let Some((n, v)) = item.split_once('=') else {
                        errors.push(err(format!("a constant is `name = number`, not `{item}`"), at));
                        continue;
                    };
                    let (n, v) = (n.trim(), v.trim());
                    match v.parse::<f64>() {
                        Ok(x) if x.is_finite() && is_ident(n) => script.constants.push((n.to_string(), x, at)),
                        Ok(_) if !is_ident(n) => errors.push(err(format!("`{n}` is not a name"), at)),
                        _ => errors.push(err(format!("the constant `{n}` is `{v}`, not a number"), at)),
                    }
                }
            }
            _ => {
                if seen_function {
                    errors.push(err("a script has one `function` section", pos));
                }
                seen_function = true;
                for (stmt, at) in items(body, open + 1, &[';', '\n']) {
                    // `a = b`, not `a == b`, `a <= b`, `a >= b`, `a <> b`.
                    let eq = stmt.char_indices().find(|&(k, c)| {
                        c == '=' && !stmt[k + 1..].starts_with('=') && !stmt[..k].ends_with(['<', '>', '=', '!'])
                    });
                    match eq {
                        Some((k, _)) if is_ident(stmt[..k].trim()) => {
                            let rhs = &stmt[k + 1..];
                            let lead = rhs.len() - rhs.trim_start().len();
                            if rhs.trim().is_empty() {
                                errors.push(err("nothing after `=`", at + k));
                                continue;
                            }
                            script.statements.push(Statement {
                                target: Some((stmt[..k].trim().to_string(), at)),
                                expr: rhs.trim().to_string(),
                                offset: at + k + 1 + lead,
                            });
                        }
                        Some((k, _)) => errors.push(err(format!("`{}` cannot be assigned", stmt[..k].trim()), at)),
                        None => script.statements.push(Statement {
                            target: None,
                            expr: stmt,
                            offset: at,
                        }),
                    }
                }
            }
        }
        pos = close + 1;
    }
    if !seen_function && errors.is_empty() {
        errors.push(err("a script needs a `function{…}` section", 0));
    }
    if errors.is_empty() { Ok(script) } else { Err(errors) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sources_samples_parse() {
        let s = parse(
            "//\n//Expression testing. Code sample 2.\n//\ndefine{v0, v10}\nfunction\n{\n    v0 + 2;\n    v0 * 2;\n    v10 = v0;\n    cos(v10);\n}\n",
        )
        .expect("parses");
        assert_eq!(
            s.defines.iter().map(|d| d.0.as_str()).collect::<Vec<_>>(),
            ["v0", "v10"]
        );
        let stmts: Vec<(Option<&str>, &str)> = s
            .statements
            .iter()
            .map(|t| (t.target.as_ref().map(|x| x.0.as_str()), t.expr.as_str()))
            .collect();
        assert_eq!(
            stmts,
            [
                (None, "v0 + 2"),
                (None, "v0 * 2"),
                (Some("v10"), "v0"),
                (None, "cos(v10)")
            ]
        );
        let text = "define\n{\n    v1,v2,v3\n}\nconst\n{\n    total=12.78\n}\nfunction\n{\n  v2 = cos(v1)*total;\n  v3 = v2 + v1;\n}\n";
        let s = parse(text).expect("parses");
        assert_eq!(
            s.constants,
            [("total".to_string(), 12.78, text.find("total").unwrap_or(0))]
        );
        let v3 = &s.statements[1];
        assert_eq!(
            &text[v3.offset..v3.offset + v3.expr.len()],
            "v2 + v1",
            "offsets point into the text"
        );
        assert_eq!(line_col(text, v3.offset), (12, 8));
        // Comparisons are expressions, not assignments.
        let s = parse("function{ a >= 2; b <= 3; c == 4 }").expect("parses");
        assert!(s.statements.iter().all(|t| t.target.is_none()));
    }

    /// Found by `cargo fuzz run net_script`: a comment holding a multi-byte
    /// character shifted every later offset (fuzz/regressions/net_script/).
    #[test]
    fn comments_with_multibyte_characters_keep_offsets() {
        let text = "// señal ñ\nfunction{ x = 1; ñ }";
        let s = parse(text).expect("parses");
        let st = &s.statements[0];
        assert_eq!(&text[st.offset..st.offset + st.expr.len()], "1");
        let bad = parse("// ñ\nfuntion").expect_err("bad section");
        assert_eq!(bad[0].offset, text.find('\n').map_or(0, |_| "// ñ\n".len()));
        for e in parse("//\u{e9}\u{e9}\n{").expect_err("bad").iter() {
            let _ = line_col("//\u{e9}\u{e9}\n{", e.offset);
        }
    }

    /// The input `cargo fuzz run net_script` crashed on (kept in
    /// tests/fuzz_regressions/), checked as the fuzz target checks.
    #[test]
    fn the_fuzz_regression_is_fixed() {
        let bytes = include_bytes!("../tests/fuzz_regressions/script-crash-f4fa55f7");
        let text = std::str::from_utf8(bytes).expect("UTF-8");
        match parse(text) {
            Ok(s) => assert!(
                s.statements
                    .iter()
                    .all(|t| text.get(t.offset..t.offset + t.expr.len()).is_some())
            ),
            Err(e) => e.iter().for_each(|x| {
                assert!(x.offset <= text.len());
                let _ = line_col(text, x.offset);
            }),
        }
    }

    #[test]
    fn errors_are_located() {
        for (text, want, at) in [
            ("", "needs a `function", 0),
            ("funtion{a}", "expected a section", 0),
            ("function a", "is followed by `{`", 8),
            ("function{ a = 1", "no closing", 8),
            ("define{ 2x }", "`2x` is not a name", 8),
            ("constant{ k = lots }", "not a number", 10),
            ("const{ k }", "`name = number`", 7),
            ("function{ a = }", "nothing after", 12),
            ("function{ a+b = 2 }", "cannot be assigned", 10),
            ("function{a} function{b}", "one `function`", 12),
        ] {
            let e = parse(text).expect_err(text);
            assert!(e[0].message.contains(want) && e[0].offset == at, "{text:?}: {e:?}");
        }
    }
}

#[cfg(test)]
mod props {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Any text: a script or located errors, never a panic.
        #[test]
        fn any_text_parses_or_is_refused_with_offsets_inside(text in "[a-z{}=;,/ \n0-9.+*()<>]{0,120}") {
            match parse(&text) {
                Ok(s) => for st in &s.statements {
                    prop_assert_eq!(text.get(st.offset..st.offset + st.expr.len()), Some(st.expr.as_str()));
                },
                Err(e) => for x in &e {
                    prop_assert!(x.offset <= text.len());
                },
            }
        }
    }
}
