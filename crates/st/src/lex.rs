//! The lexer: ST text to tokens with byte spans. Comments `(* *)` (nested),
//! `/* */` and `//`; pragmas `{…}` skipped with an E223 each (Alba runs none);
//! identifiers and keywords are case-insensitive; typed
//! and based literals (`T#1h2m`, `16#FF`, `DINT#5`) are single tokens.

use alba_diag::{Code, Diagnostic, FileId, Span};

#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// An identifier or keyword, as written.
    Ident(String),
    /// A number literal as written (`12`, `1_000`, `16#FF`, `1.5e3`).
    Number(String),
    /// `PREFIX#rest` (`T#5s`, `DINT#5`, `BOOL#TRUE`, `Color#Red`).
    Typed(String, String),
    /// A character string (`'abc'`, or `"abc"` for WSTRING), unescaped.
    Str(String, bool),
    /// Punctuation and operators: `:= => + - * / ** = <> < > <= >= ( ) [ ] , ; : . .. & ^`.
    Punct(&'static str),
    Eof,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    pub tok: Tok,
    pub start: usize,
    pub end: usize,
}

const PUNCTS: [&str; 22] = [
    ":=", "=>", "**", "<>", "<=", ">=", "..", "+", "-", "*", "/", "=", "<", ">", "(", ")", "[", "]", ",", ";", ":", ".",
];
const MORE: [&str; 2] = ["&", "^"];

/// Tokens of `text`, ending with `Eof`, and the lexical errors found.
pub fn lex(text: &str, file: FileId) -> (Vec<Token>, Vec<Diagnostic>) {
    let b = text.as_bytes();
    let mut toks = Vec::new();
    let mut diags = Vec::new();
    let mut i = 0;
    let err = |diags: &mut Vec<Diagnostic>, a: usize, z: usize, msg: String| {
        diags.push(Diagnostic::new(Code::StSyntax, msg, Span::new(file, a..z), "here"));
    };
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let start = i;
        if c == b'(' && b.get(i + 1) == Some(&b'*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == b'(' && b.get(i + 1) == Some(&b'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b')') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            if depth != 0 {
                err(
                    &mut diags,
                    start,
                    start + 2,
                    "this comment `(*` is never closed by `*)`".into(),
                );
            }
            continue;
        }
        if c == b'/' && b.get(i + 1) == Some(&b'*') {
            match text[i + 2..].find("*/") {
                Some(k) => i = i + 2 + k + 2,
                None => {
                    err(
                        &mut diags,
                        start,
                        start + 2,
                        "this comment `/*` is never closed by `*/`".into(),
                    );
                    i = b.len();
                }
            }
            continue;
        }
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        if c == b'{' {
            // A pragma: what it means is the implementation's; OpenPLC's and
            // Beremiz's (matiec) are C code pasted into the generated C.
            match text[i + 1..].find('}') {
                Some(k) => {
                    i = i + 1 + k + 1;
                    diags.push(
                        Diagnostic::new(
                            Code::StNotSupported,
                            "a pragma `{…}` is not run: OpenPLC and Beremiz paste its text into their generated C code, and Alba runs no C code".to_string(),
                            Span::new(file, start..i),
                            "pragma",
                        )
                        .with_help("write what it does in ST, or leave it out"),
                    );
                }
                None => {
                    err(
                        &mut diags,
                        start,
                        start + 1,
                        "this pragma `{` is never closed by `}`".into(),
                    );
                    i = b.len();
                }
            }
            continue;
        }
        let tok = if c == b'%' && b.get(i + 1).is_some_and(u8::is_ascii_alphabetic) {
            // A directly represented variable (`%IX0.1`, `%MW4`): a name
            // that resolves as an address.
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_alphanumeric() || (b[i] == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)))
            {
                i += 1;
            }
            Tok::Ident(text[start..i].to_string())
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            let word = &text[start..i];
            if b.get(i) == Some(&b'#') {
                i += 1;
                let date = [
                    "D",
                    "DATE",
                    "DT",
                    "DATE_AND_TIME",
                    "TOD",
                    "TIME_OF_DAY",
                    "LDATE",
                    "LDT",
                    "LTOD",
                ]
                .iter()
                .any(|d| d.eq_ignore_ascii_case(word));
                let rest = typed_rest(b, &mut i, date);
                Tok::Typed(word.to_string(), text[rest..i].to_string())
            } else {
                Tok::Ident(word.to_string())
            }
        } else if c.is_ascii_digit() {
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'_') {
                i += 1;
            }
            if b.get(i) == Some(&b'#') {
                i += 1;
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
            } else {
                if b.get(i) == Some(&b'.') && b.get(i + 1).is_some_and(u8::is_ascii_digit) {
                    i += 1;
                    while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'_') {
                        i += 1;
                    }
                }
                if matches!(b.get(i), Some(b'e' | b'E')) {
                    let mut k = i + 1;
                    if matches!(b.get(k), Some(b'+' | b'-')) {
                        k += 1;
                    }
                    if b.get(k).is_some_and(u8::is_ascii_digit) {
                        i = k;
                        while i < b.len() && b[i].is_ascii_digit() {
                            i += 1;
                        }
                    }
                }
            }
            Tok::Number(text[start..i].to_string())
        } else if c == b'\'' || c == b'"' {
            i += 1;
            let mut s = String::new();
            let mut closed = false;
            while i < b.len() {
                let ch = b[i];
                if ch == c {
                    i += 1;
                    closed = true;
                    break;
                }
                if ch == b'\n' {
                    break;
                }
                if ch == b'$' && i + 1 < b.len() {
                    let e = b[i + 1];
                    let rep = match e.to_ascii_uppercase() {
                        b'N' | b'L' => Some('\n'),
                        b'R' => Some('\r'),
                        b'T' => Some('\t'),
                        b'$' => Some('$'),
                        b'\'' => Some('\''),
                        b'"' => Some('"'),
                        _ => None,
                    };
                    if let Some(r) = rep {
                        s.push(r);
                        i += 2;
                        continue;
                    }
                    if e.eq_ignore_ascii_case(&b'P') {
                        s.push('\u{c}');
                        i += 2;
                        continue;
                    }
                    // `$hh` in a STRING (ASCII), `$hhhh` in a WSTRING.
                    let digits = if c == b'"' { 4 } else { 2 };
                    let hex = text
                        .get(i + 1..i + 1 + digits)
                        .filter(|h| h.bytes().all(|x| x.is_ascii_hexdigit()));
                    if let Some(h) = hex {
                        let code = u32::from_str_radix(h, 16).unwrap_or(0);
                        match char::from_u32(code).filter(|_| c == b'"' || code < 0x80) {
                            Some(ch) => s.push(ch),
                            None => err(
                                &mut diags,
                                i,
                                i + 1 + digits,
                                if c == b'"' {
                                    format!("`${h}` is not a character (a UTF-16 surrogate)")
                                } else {
                                    format!(
                                        "`${h}`: a STRING escape is an ASCII code ($00 to $7F); use a WSTRING for others"
                                    )
                                },
                            ),
                        }
                        i += 1 + digits;
                        continue;
                    }
                }
                let len = utf8_len(ch);
                s.push_str(text.get(i..i + len).unwrap_or(""));
                i += len;
            }
            if !closed {
                err(&mut diags, start, i, "this string is not closed on its line".into());
            }
            Tok::Str(s, c == b'"')
        } else {
            let rest = &text[i..];
            match PUNCTS.iter().chain(MORE.iter()).find(|p| rest.starts_with(**p)) {
                Some(p) => {
                    i += p.len();
                    Tok::Punct(p)
                }
                None => {
                    let len = utf8_len(c);
                    let ch = text.get(i..i + len).unwrap_or("?");
                    err(&mut diags, start, i + len, format!("unexpected character `{ch}`"));
                    i += len;
                    continue;
                }
            }
        };
        toks.push(Token { tok, start, end: i });
    }
    toks.push(Token {
        tok: Tok::Eof,
        start: b.len(),
        end: b.len(),
    });
    (toks, diags)
}

fn utf8_len(first: u8) -> usize {
    match first {
        0xF0..=0xFF => 4,
        0xE0..=0xEF => 3,
        0xC0..=0xDF => 2,
        _ => 1,
    }
}

/// Whether the value so far is a decimal number ending in its exponent's
/// `E` (`REAL#2.5E` of `REAL#2.5E-8`), so a sign may follow.
fn signed_exponent(v: &[u8]) -> bool {
    v.len() >= 2
        && matches!(v[v.len() - 1], b'e' | b'E')
        && v[v.len() - 2].is_ascii_digit()
        && v.iter()
            .all(|c| c.is_ascii_digit() || matches!(c, b'.' | b'_' | b'e' | b'E'))
}

/// The value part of a typed literal: an optional sign, then letters,
/// digits, `_`, `#` (`DINT#16#FF`), for dates and times of day (`date`)
/// `:` and `-`, `.` before a digit (`T#1.5s`) and the sign of an exponent
/// (`LREAL#1.5E-8`). Returns where it starts.
fn typed_rest(b: &[u8], i: &mut usize, date: bool) -> usize {
    if matches!(b.get(*i), Some(b'+' | b'-')) {
        *i += 1;
    }
    let start = *i;
    while let Some(&c) = b.get(*i) {
        let ok = c.is_ascii_alphanumeric()
            || matches!(c, b'_' | b'#')
            || (date && c == b':')
            || (date && c == b'-' && *i > start && b.get(*i + 1).is_some_and(u8::is_ascii_digit))
            || (c == b'.' && b.get(*i + 1).is_some_and(u8::is_ascii_digit))
            || (matches!(c, b'+' | b'-')
                && signed_exponent(&b[start..*i])
                && b.get(*i + 1).is_some_and(u8::is_ascii_digit));
        if !ok {
            break;
        }
        *i += 1;
    }
    // The sign belongs to the value.
    if start > 0 && matches!(b.get(start - 1), Some(b'+' | b'-')) && b.get(start - 2) == Some(&b'#') {
        start - 1
    } else {
        start
    }
}
