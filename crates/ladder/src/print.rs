//! The printer: the canonical neutral text of a program.
//!
//! Canonical text has one rung per line, its comment lines (`// text`)
//! directly above, no spaces between elements and operands as parsed
//! (trimmed, inner whitespace collapsed). `print(parse(t)) == t` for every
//! canonical `t`.

use crate::ast::{Element, Program};

pub fn print(p: &Program) -> String {
    let mut out = String::new();
    for r in &p.rungs {
        for c in &r.comment {
            comment_line(&mut out, c);
        }
        elements(&mut out, &r.elements);
        out.push_str(";\n");
    }
    if let Some(c) = &p.trailing_comment {
        for line in c.split('\n') {
            comment_line(&mut out, line);
        }
    }
    out
}

fn comment_line(out: &mut String, c: &str) {
    if c.is_empty() {
        out.push_str("//\n");
    } else {
        out.push_str("// ");
        out.push_str(c);
        out.push('\n');
    }
}

/// Prints a sequence of elements (a rung body or a branch leg).
pub fn elements(out: &mut String, elems: &[Element]) {
    for e in elems {
        match e {
            Element::Instr(i) => {
                out.push_str(i.mnemonic.name());
                out.push('(');
                for (k, o) in i.operands.iter().enumerate() {
                    if k > 0 {
                        out.push(',');
                    }
                    out.push_str(&o.text);
                }
                out.push(')');
            }
            Element::Branch(b) => {
                out.push('[');
                for (k, leg) in b.legs.iter().enumerate() {
                    if k > 0 {
                        out.push(',');
                    }
                    elements(out, leg);
                }
                out.push(']');
            }
        }
    }
}
