//! Parser for Rockwell neutral text (SPEC §3.1).
//!
//! ```text
//! program  := { comment | rung }
//! rung     := { element } ";"
//! element  := instr | branch
//! instr    := NAME "(" [ operand { "," operand } ] ")"
//! branch   := "[" leg { "," leg } "]"
//! leg      := element { element }
//! comment  := "//" text to end of line
//! ```
//! Whitespace may appear between any two tokens. An operand is the raw text
//! up to the next `,` or `)` outside parentheses (so `CPT(x,ATAN2(a,b))`
//! works); its meaning is checked later. A syntax error drops its rung and
//! parsing resumes after the next `;`, so one pass reports every error.

use crate::ast::{Branch, Element, Instr, Mnemonic, Operand, Program, Rung};
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_model::tags::edit_distance;

/// Parses a ladder program. Rungs with errors are left out of the result
/// and reported.
pub fn parse(text: &str, file: FileId) -> (Program, Vec<Diagnostic>) {
    let mut p = Parser {
        src: text,
        pos: 0,
        file,
        diags: Vec::new(),
        broken_labels: Vec::new(),
        last_end: 0,
        open: Vec::new(),
    };
    let mut rungs = Vec::new();
    let mut comment = Vec::new();
    loop {
        p.skip_ws();
        if p.pos >= p.src.len() {
            break;
        }
        if p.src[p.pos..].starts_with("//") {
            comment.push(p.line_comment());
            continue;
        }
        if let Some(r) = p.rung(std::mem::take(&mut comment)) {
            rungs.push(r);
        }
    }
    let trailing_comment = (!comment.is_empty()).then(|| comment.join("\n"));
    let program = Program {
        rungs,
        trailing_comment,
        broken_labels: p.broken_labels,
    };
    (program, p.diags)
}

struct Parser<'a> {
    src: &'a str,
    pos: usize,
    file: FileId,
    diags: Vec<Diagnostic>,
    broken_labels: Vec<String>,
    /// End of the last instruction or branch parsed.
    last_end: usize,
    /// Where the branches open around the current position start.
    open: Vec<usize>,
}

/// Deepest branch nesting accepted (a bound on recursion, far beyond what
/// any editor draws).
pub const MAX_BRANCH_DEPTH: usize = 32;

/// A syntax error was reported; the rung is abandoned.
struct Abandon;

impl Parser<'_> {
    fn span(&self, start: usize, end: usize) -> Span {
        Span::new(self.file, start..end)
    }

    fn peek(&self) -> Option<u8> {
        self.src.as_bytes().get(self.pos).copied()
    }

    fn skip_ws(&mut self) {
        while let Some(c) = self.peek() {
            if c.is_ascii_whitespace() {
                self.pos += 1;
            } else {
                break;
            }
        }
    }

    /// Reads a `//` comment (at `pos`) to the end of its line.
    fn line_comment(&mut self) -> String {
        let start = self.pos + 2;
        let end = self.src[start..].find('\n').map_or(self.src.len(), |i| start + i);
        self.pos = end;
        self.src[start..end].trim().to_string()
    }

    fn error(&mut self, code: Code, msg: impl Into<String>, start: usize, end: usize, label: &str) {
        let d = Diagnostic::new(code, msg, self.span(start, end), label);
        self.diags.push(d);
    }

    /// Span of the character at `pos` (or an empty span at the end).
    fn char_end(&self, pos: usize) -> usize {
        self.src[pos..].chars().next().map_or(pos, |c| pos + c.len_utf8())
    }

    fn rung(&mut self, mut comment: Vec<String>) -> Option<Rung> {
        let start = self.pos;
        self.last_end = start;
        self.open.clear();
        let mut ok = true;
        let elements = match self.elements(false, start, &mut ok) {
            Ok(e) => e,
            Err(Abandon) => {
                self.recover(start);
                return None;
            }
        };
        // `XIC(a)OTE(b); // note` : a comment on the rung's own last line
        // describes that rung (it is printed above it).
        let end = self.pos;
        let rest = &self.src[self.pos..];
        let spaces = rest.len() - rest.trim_start_matches([' ', '\t']).len();
        if rest[spaces..].starts_with("//") {
            self.pos += spaces;
            comment.push(self.line_comment());
        }
        if !ok {
            // Dropped for an unknown instruction: keep its labels, so JMPs to
            // them do not add a second, misleading error.
            fn labels(elems: &[Element], out: &mut Vec<String>) {
                for e in elems {
                    match e {
                        Element::Instr(i) if i.mnemonic == Mnemonic::LBL => {
                            out.extend(i.operands.first().map(|o| o.text.clone()));
                        }
                        Element::Instr(_) => {}
                        Element::Branch(b) => b.legs.iter().for_each(|l| labels(l, out)),
                    }
                }
            }
            labels(&elements, &mut self.broken_labels);
            return None;
        }
        Some(Rung {
            comment,
            elements,
            span: self.span(start, end),
        })
    }

    /// After an error: remember labels of the rung (so JMPs to them do not
    /// report a second error) and skip past the next `;`.
    fn recover(&mut self, start: usize) {
        let end = self.src[self.pos..]
            .find(';')
            .map_or(self.src.len(), |i| self.pos + i + 1);
        let text = self.src[start..end].to_ascii_uppercase();
        let mut rest = text.as_str();
        while let Some(i) = rest.find("LBL") {
            rest = &rest[i + 3..];
            let inner = rest.trim_start();
            if let Some(after) = inner.strip_prefix('(')
                && let Some(close) = after.find(')')
            {
                self.broken_labels.push(after[..close].trim().to_string());
            }
        }
        self.pos = end;
    }

    /// Elements up to `;` (top level, consumed) or `,`/`]` (in a branch, not consumed).
    fn elements(&mut self, in_branch: bool, rung_start: usize, ok: &mut bool) -> Result<Vec<Element>, Abandon> {
        let mut out = Vec::new();
        loop {
            self.skip_ws();
            if self.src[self.pos..].starts_with("//") {
                // A comment belongs above a rung; after an instruction it almost
                // always means the `;` before it was forgotten.
                let at = self.last_end;
                if at <= rung_start {
                    let d = Diagnostic::new(
                        Code::Syntax,
                        "a comment inside a rung",
                        self.span(self.pos, self.pos + 2),
                        "comment here",
                    )
                    .with_help("put the comment on its own line above the rung");
                    self.diags.push(d);
                    return Err(Abandon);
                }
                let d = Diagnostic::new(
                    Code::UnterminatedRung,
                    "a comment inside a rung: the rung before it does not end with `;`",
                    self.span(at, at),
                    "expected `;` here",
                )
                .with_help("end the rung with `;`; a comment line goes directly above the rung it describes");
                self.diags.push(d);
                return Err(Abandon);
            }
            match self.peek() {
                None if !self.open.is_empty() => {
                    let at = self.open.last().copied().unwrap_or(rung_start);
                    self.error(
                        Code::Unbalanced,
                        "this branch is never closed",
                        at,
                        at + 1,
                        "`[` without its `]`",
                    );
                    return Err(Abandon);
                }
                None => {
                    let at = self.last_end.max(rung_start);
                    let d = Diagnostic::new(
                        Code::UnterminatedRung,
                        "the last rung does not end with `;`",
                        self.span(at, at),
                        "expected `;` here",
                    )
                    .with_note(self.span(rung_start, self.char_end(rung_start)), "the rung starts here");
                    self.diags.push(d);
                    return Err(Abandon);
                }
                Some(b';') if in_branch => {
                    self.error(
                        Code::Unbalanced,
                        "the branch is not closed before `;`",
                        self.pos,
                        self.pos + 1,
                        "expected `]` before this",
                    );
                    return Err(Abandon);
                }
                Some(b';') => {
                    self.pos += 1;
                    return Ok(out);
                }
                Some(b',' | b']') if in_branch => return Ok(out),
                Some(c @ (b',' | b']' | b')')) => {
                    let what = match c {
                        b',' => "`,` outside a branch",
                        b']' => "`]` without its `[`",
                        _ => "`)` without its `(`",
                    };
                    self.error(
                        Code::Unbalanced,
                        format!("unexpected {what}"),
                        self.pos,
                        self.pos + 1,
                        "here",
                    );
                    return Err(Abandon);
                }
                Some(b'[') => out.push(Element::Branch(self.branch(rung_start, ok)?)),
                Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                    if let Some(i) = self.instr(ok)? {
                        out.push(Element::Instr(i));
                    }
                }
                Some(_) => {
                    let end = self.char_end(self.pos);
                    let ch = &self.src[self.pos..end];
                    self.error(
                        Code::Syntax,
                        format!("unexpected `{ch}`"),
                        self.pos,
                        end,
                        "expected an instruction, `[`, `,`, `]` or `;`",
                    );
                    return Err(Abandon);
                }
            }
        }
    }

    fn branch(&mut self, rung_start: usize, ok: &mut bool) -> Result<Branch, Abandon> {
        let start = self.pos;
        if self.open.len() >= MAX_BRANCH_DEPTH {
            self.error(
                Code::Unbalanced,
                format!("branches are nested more than {MAX_BRANCH_DEPTH} deep"),
                start,
                start + 1,
                "one branch too many",
            );
            return Err(Abandon);
        }
        self.open.push(start);
        let result = self.branch_legs(start, rung_start, ok);
        self.open.pop();
        result
    }

    fn branch_legs(&mut self, start: usize, rung_start: usize, ok: &mut bool) -> Result<Branch, Abandon> {
        self.pos += 1;
        let mut legs = Vec::new();
        loop {
            let leg_start = self.pos;
            let leg = self.elements(true, rung_start, ok)?;
            if leg.is_empty() {
                let at = self.pos;
                self.error(
                    Code::EmptyLeg,
                    "empty branch leg",
                    leg_start.min(at),
                    self.char_end(at),
                    "expected an instruction in this leg",
                );
                return Err(Abandon);
            }
            legs.push(leg);
            match self.peek() {
                Some(b',') => self.pos += 1,
                _ => {
                    // `]`: elements() stops only at `,` or `]` inside a branch.
                    self.pos += 1;
                    break;
                }
            }
        }
        self.last_end = self.pos;
        Ok(Branch {
            legs,
            span: self.span(start, self.pos),
        })
    }

    /// An instruction; `Ok(None)` (with `ok` cleared) for an unknown name,
    /// so the rest of the rung is still checked for syntax errors.
    fn instr(&mut self, ok: &mut bool) -> Result<Option<Instr>, Abandon> {
        let start = self.pos;
        while self.peek().is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_') {
            self.pos += 1;
        }
        let name = &self.src[start..self.pos];
        let name_span = self.span(start, self.pos);
        self.skip_ws();
        if self.peek() != Some(b'(') {
            let at = self.pos;
            self.error(
                Code::Syntax,
                format!("expected `(` after `{name}`"),
                at,
                self.char_end(at),
                "operands go in parentheses, like XIC(Start)",
            );
            return Err(Abandon);
        }
        let open = self.pos;
        self.pos += 1;
        let mut operands = Vec::new();
        let mut depth = 0usize;
        let mut op_start = self.pos;
        loop {
            match self.peek() {
                None | Some(b';') => {
                    self.error(
                        Code::Unbalanced,
                        format!("the `(` of `{name}` is not closed"),
                        open,
                        open + 1,
                        "opened here",
                    );
                    return Err(Abandon);
                }
                Some(b'(' | b'[') => depth += 1,
                Some(b')' | b']') if depth > 0 => depth -= 1,
                Some(c @ (b',' | b')')) if depth == 0 => {
                    let raw = &self.src[op_start..self.pos];
                    let closing = c == b')';
                    if !(closing && operands.is_empty() && raw.trim().is_empty()) {
                        if raw.trim().is_empty() {
                            self.error(
                                Code::Syntax,
                                format!("empty operand in `{name}`"),
                                op_start,
                                self.char_end(self.pos),
                                "expected an operand here",
                            );
                            return Err(Abandon);
                        }
                        let lead = raw.len() - raw.trim_start().len();
                        let s = op_start + lead;
                        let e = s + raw.trim().len();
                        operands.push(Operand {
                            text: collapse_ws(raw),
                            span: self.span(s, e),
                        });
                    }
                    self.pos += 1;
                    if closing {
                        break;
                    }
                    op_start = self.pos;
                    continue;
                }
                Some(b']') => {
                    self.error(
                        Code::Unbalanced,
                        format!("`]` inside the operands of `{name}`"),
                        self.pos,
                        self.pos + 1,
                        "expected `)` first",
                    );
                    return Err(Abandon);
                }
                Some(_) => {}
            }
            self.pos += 1;
        }
        let span = self.span(start, self.pos);
        self.last_end = self.pos;
        match Mnemonic::parse(name) {
            Some(mnemonic) => Ok(Some(Instr {
                mnemonic,
                operands,
                span,
                name_span,
            })),
            None => {
                let mut d = Diagnostic::new(
                    Code::UnknownInstruction,
                    format!("unknown instruction `{name}`"),
                    name_span,
                    "not an instruction",
                );
                if let Some(s) = suggest(name) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                self.diags.push(d);
                *ok = false;
                Ok(None)
            }
        }
    }
}

/// Trims and collapses runs of whitespace to one space.
fn collapse_ws(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn suggest(name: &str) -> Option<&'static str> {
    let upper = name.to_ascii_uppercase();
    Mnemonic::ALL
        .iter()
        .map(|m| (edit_distance(&upper, m.name()), m.name()))
        .filter(|(d, _)| *d <= 1 || (*d == 2 && upper.len() > 3))
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_diag::Files;

    fn short(text: &str) -> Vec<String> {
        let mut files = Files::new();
        let f = files.add("main.lad", text);
        parse(files.text(f), f).1.iter().map(|d| d.short(&files)).collect()
    }

    #[test]
    fn a_comment_on_the_rung_line_belongs_to_that_rung() {
        let (p, d) = parse("// above\nXIC(a)OTE(b); // seal in\nXIC(c)OTE(d);\n", FileId(0));
        assert!(d.is_empty());
        assert_eq!(p.rungs[0].comment, ["above", "seal in"]);
        assert!(p.rungs[1].comment.is_empty());
        assert_eq!(crate::print(&p), "// above\n// seal in\nXIC(a)OTE(b);\nXIC(c)OTE(d);\n");
    }

    #[test]
    fn comments_inside_rungs_are_refused_where_they_are() {
        assert_eq!(
            short("XIC(a)OTE(x);\n[// c\nXIC(b),XIC(c)]OTE(d);\n"),
            ["main.lad:2:2: error[E200]: a comment inside a rung"]
        );
        assert_eq!(
            short("XIC(a)OTE(x)\n// c\nXIC(b)OTE(d);\n"),
            ["main.lad:1:13: error[E204]: a comment inside a rung: the rung before it does not end with `;`"]
        );
    }

    #[test]
    fn a_label_in_a_rung_with_an_unknown_instruction_still_counts() {
        let (p, d) = parse("XIC(A)JMP(skip);\nLBL(skip)FOO(A)OTE(B);\n", FileId(0));
        assert_eq!(d.len(), 1, "{d:?}");
        assert_eq!(p.broken_labels, ["skip"]);
    }

    #[test]
    fn an_unclosed_branch_at_the_end_points_at_its_bracket() {
        assert_eq!(
            short("XIC(a)OTE(b);\nXIC(c)[XIC(a),[XIC(b)"),
            ["main.lad:2:15: error[E202]: this branch is never closed"]
        );
        assert_eq!(
            short("XIC(a)OTE(b)"),
            ["main.lad:1:13: error[E204]: the last rung does not end with `;`"]
        );
    }
}
