//! Parser for S7-200 AWL text (SPEC §4): one instruction per line,
//! operands separated by commas, `//` and `/* */` comments, `NETWORK n` and
//! `TITLE =` lines, and the frame of STEP 7-Micro/WIN exports
//! (`ORGANIZATION_BLOCK … BEGIN … END_ORGANIZATION_BLOCK`). Mnemonics are
//! case-insensitive and any whitespace separates tokens. A bad line is
//! reported and skipped; parsing goes on, so every error is found.

use crate::ast::{Instr, Item, MNEMONICS, Mn, Operand, Program};
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_model::tags::edit_distance;

pub fn parse(text: &str, file: FileId) -> (Program, Vec<Diagnostic>) {
    let mut items = Vec::new();
    let mut diags = Vec::new();
    let sp = |a: usize, b: usize| Span::new(file, a..b);
    let mut in_block: Option<usize> = None;
    let mut skip_to: Option<&str> = None;
    let mut offset = 0;
    for raw_line in text.split_inclusive('\n') {
        let line_start = offset;
        offset += raw_line.len();
        let line = raw_line.trim_end_matches(['\n', '\r']);
        // Blank out comments, keeping every other byte where it is.
        let mut code = String::with_capacity(line.len());
        let mut rest = line;
        let mut pos = line_start;
        while !rest.is_empty() {
            if in_block.is_some() {
                match rest.find("*/") {
                    Some(i) => {
                        code.push_str(&" ".repeat(i + 2));
                        rest = &rest[i + 2..];
                        pos += i + 2;
                        in_block = None;
                    }
                    None => {
                        code.push_str(&" ".repeat(rest.len()));
                        rest = "";
                    }
                }
                continue;
            }
            // The first `//` or `/*`: searching for each one through the
            // whole rest of the line on every comment made a line of many
            // comments quadratic.
            let opener = rest
                .match_indices('/')
                .map(|(i, _)| (i, rest.as_bytes().get(i + 1)))
                .find(|(_, next)| matches!(next, Some(b'/' | b'*')));
            match opener {
                Some((l, Some(b'/'))) => {
                    code.push_str(&rest[..l]);
                    rest = "";
                }
                Some((b, _)) => {
                    code.push_str(&rest[..b]);
                    code.push_str("  ");
                    in_block = Some(pos + b);
                    rest = &rest[b + 2..];
                    pos += b + 2;
                }
                None => {
                    code.push_str(rest);
                    rest = "";
                }
            }
        }
        let trimmed = code.trim();
        if trimmed.is_empty() {
            continue;
        }
        let lead = code.len() - code.trim_start().len();
        let start = line_start + lead;
        let end = start + trimmed.len();
        let first_word = trimmed.split_whitespace().next().unwrap_or("").to_ascii_uppercase();
        let first_word = first_word.split(['=', ':']).next().unwrap_or("").to_string();
        // Inside a block Alba does not support (reported at its start).
        if let Some(end) = skip_to {
            if first_word == end {
                skip_to = None;
            }
            continue;
        }
        match first_word.as_str() {
            "ORGANIZATION_BLOCK" | "BEGIN" | "END_ORGANIZATION_BLOCK" | "TITLE" => continue,
            "SUBROUTINE_BLOCK" | "INTERRUPT_BLOCK" => {
                diags.push(Diagnostic::new(
                    Code::IlNotSupported,
                    "subroutines and interrupt routines are not supported yet",
                    sp(start, start + first_word.len()),
                    "not supported",
                ));
                skip_to = Some(if first_word.starts_with('S') {
                    "END_SUBROUTINE_BLOCK"
                } else {
                    "END_INTERRUPT_BLOCK"
                });
                continue;
            }
            "VAR" | "VAR_INPUT" | "VAR_OUTPUT" | "VAR_IN_OUT" | "VAR_TEMP" => {
                diags.push(Diagnostic::new(
                    Code::IlNotSupported,
                    "local variables are not supported yet",
                    sp(start, start + first_word.len()),
                    "not supported",
                ));
                skip_to = Some("END_VAR");
                continue;
            }
            "NETWORK" => {
                let number = trimmed[7..].split_whitespace().next().and_then(|n| n.parse().ok());
                items.push(Item::Network {
                    number,
                    span: sp(start, end),
                });
                continue;
            }
            _ => {}
        }
        match instruction(trimmed, start, file) {
            Ok(i) => items.push(Item::Instr(i)),
            Err(d) => {
                diags.push(d);
                items.push(Item::Bad);
            }
        }
    }
    if let Some(at) = in_block {
        diags.push(Diagnostic::new(
            Code::IlSyntax,
            "this `/*` comment is never closed",
            sp(at, at + 2),
            "opened here",
        ));
    }
    (Program { items }, diags)
}

/// One instruction line (comments removed, trimmed), starting at `start`.
fn instruction(line: &str, start: usize, file: FileId) -> Result<Instr, Diagnostic> {
    let sp = |a: usize, b: usize| Span::new(file, start + a..start + b);
    let name_len = line.find(char::is_whitespace).unwrap_or(line.len());
    let name = &line[..name_len];
    let Some(mn) = Mn::parse(name) else {
        let mut d = Diagnostic::new(
            Code::UnknownMnemonic,
            format!("unknown instruction `{name}`"),
            sp(0, name_len),
            "not an S7-200 instruction Alba knows",
        );
        if let Some(s) = suggest(name) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        return Err(d);
    };
    let mut operands = Vec::new();
    let rest = &line[name_len..];
    if !rest.trim().is_empty() {
        let mut field_start = name_len;
        let mut quoted = false;
        let bytes = line.as_bytes();
        for i in name_len..=line.len() {
            let c = bytes.get(i).copied();
            if c == Some(b'"') {
                quoted = !quoted;
            }
            if (c == Some(b',') && !quoted) || c.is_none() {
                let raw = &line[field_start..i];
                let text = raw.trim();
                if text.is_empty() {
                    let at = field_start + (raw.len() - raw.trim_start().len());
                    return Err(Diagnostic::new(
                        Code::IlSyntax,
                        format!("empty operand in `{name}`"),
                        sp(at, (at + 1).min(line.len()).max(at)),
                        "expected an operand here",
                    ));
                }
                if text.contains(char::is_whitespace) && !text.starts_with('"') {
                    // Point at the second word, where a comma was expected.
                    let first = text.find(char::is_whitespace).unwrap_or(0);
                    let second = first + (text[first..].len() - text[first..].trim_start().len());
                    let at = field_start + raw.find(text).unwrap_or(0) + second;
                    let len = text[second..].find([' ', '\t']).unwrap_or(text.len() - second);
                    return Err(Diagnostic::new(
                        Code::IlSyntax,
                        format!("`{text}` is not one operand: operands are separated by commas"),
                        sp(at, at + len),
                        "expected `,` before this",
                    ));
                }
                let lead = raw.len() - raw.trim_start().len();
                operands.push(Operand {
                    text: text.trim_matches('"').to_string(),
                    span: sp(field_start + lead, field_start + lead + text.len()),
                });
                field_start = i + 1;
            }
        }
        if quoted {
            return Err(Diagnostic::new(
                Code::IlSyntax,
                "a quoted symbol is not closed",
                sp(name_len, line.len()),
                "expected a closing `\"`",
            ));
        }
    }
    Ok(Instr {
        mn,
        name: name.to_string(),
        operands,
        span: sp(0, line.len()),
        name_span: sp(0, name_len),
    })
}

fn suggest(name: &str) -> Option<&'static str> {
    let upper = name.to_ascii_uppercase();
    // What the seed's translator wrote for AND NOT and OR NOT.
    match upper.as_str() {
        "NAND" => return Some("AN"),
        "NOR" => return Some("ON"),
        _ => {}
    }
    MNEMONICS
        .iter()
        .map(|m| (edit_distance(&upper, m), *m))
        .filter(|(d, _)| *d <= 1 || (*d == 2 && upper.len() > 3))
        .min_by_key(|(d, _)| *d)
        .map(|(_, m)| m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_diag::Files;

    fn parse_ok(text: &str) -> Program {
        let (p, d) = parse(text, FileId(0));
        assert!(d.is_empty(), "{d:?}");
        p
    }

    fn errors(text: &str) -> Vec<String> {
        let mut files = Files::new();
        let f = files.add("main.awl", text);
        parse(files.text(f), f).1.iter().map(|d| d.short(&files)).collect()
    }

    fn instrs(p: &Program) -> Vec<(String, Vec<String>)> {
        p.items
            .iter()
            .filter_map(|i| match i {
                Item::Instr(i) => Some((i.name.to_string(), i.operands.iter().map(|o| o.text.clone()).collect())),
                Item::Network { .. } | Item::Bad => None,
            })
            .collect()
    }

    #[test]
    fn plain_awl_with_comments_parses() {
        let p = parse_ok(
            "LD SM0.1 //first scan\nS Q0.0,1 //set\n/* a block\n   comment */ LDW> 215, MW3// glued comment\n  ald\n",
        );
        assert_eq!(
            instrs(&p),
            [
                ("LD".into(), vec!["SM0.1".into()]),
                ("S".into(), vec!["Q0.0".into(), "1".into()]),
                ("LDW>".into(), vec!["215".into(), "MW3".into()]),
                ("ald".into(), vec![]),
            ]
        );
    }

    #[test]
    fn the_first_comment_opener_wins() {
        let p =
            parse_ok("LD I0.0 /* a // b */ /**/ // c /* d\n= Q0.0 /*x*//*y*/ // z\nA I0.1///*\nS Q0.1, 1 /* /* */\n");
        assert_eq!(
            instrs(&p),
            [
                ("LD".into(), vec!["I0.0".into()]),
                ("=".into(), vec!["Q0.0".into()]),
                ("A".into(), vec!["I0.1".into()]),
                ("S".into(), vec!["Q0.1".into(), "1".into()]),
            ]
        );
    }

    #[test]
    fn micro_win_exports_parse() {
        let text = "ORGANIZATION_BLOCK MAIN:OB1\nTITLE=PROGRAM COMMENTS\nBEGIN\nNetwork 1 // Network Title\n// Network Comment\nLD     I0.0\n=      Q0.0\n\nNETWORK 2\nTITLE =\nLDN    \"Stop Button\"\n=      Q0.1\nEND_ORGANIZATION_BLOCK\n";
        let p = parse_ok(text);
        let networks: Vec<_> = p
            .items
            .iter()
            .filter_map(|i| match i {
                Item::Network { number, .. } => Some(*number),
                _ => None,
            })
            .collect();
        assert_eq!(networks, [Some(1), Some(2)]);
        assert_eq!(instrs(&p)[2], ("LDN".into(), vec!["Stop Button".into()]));
    }

    #[test]
    fn errors_are_located_and_every_line_is_checked() {
        assert_eq!(
            errors("LD I0.0\nNAND I0.1\n= Q0.0 Q0.1\nMOVW 5,, MW0\n/* open\n"),
            [
                "main.awl:2:1: error[E211]: unknown instruction `NAND`",
                "main.awl:3:8: error[E210]: `Q0.0 Q0.1` is not one operand: operands are separated by commas",
                "main.awl:4:8: error[E210]: empty operand in `MOVW`",
                "main.awl:5:1: error[E210]: this `/*` comment is never closed",
            ]
        );
        assert_eq!(
            errors(
                "SUBROUTINE_BLOCK SBR_0:SBR0\nVAR_INPUT\nIN1:BOOL;\nEND_VAR\nBEGIN\nLD IN1\nEND_SUBROUTINE_BLOCK\nNOR\n"
            ),
            [
                "main.awl:1:1: error[E215]: subroutines and interrupt routines are not supported yet",
                "main.awl:8:1: error[E211]: unknown instruction `NOR`"
            ]
        );
    }
}
