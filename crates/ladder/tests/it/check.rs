//! Checks shared by the property tests and the cargo-fuzz targets
//! (`fuzz/fuzz_targets/*.rs` include this file with `#[path]`, so it must
//! depend on nothing but `alba_ladder`, `alba_diag` and `alba_model`).
//!
//! - [`ast_diff`]: structural comparison of two programs that ignores spans.
//! - [`diag_spans`]: every span of every diagnostic lies inside the input,
//!   on character boundaries, in the right file.
//! - [`ast_spans`]: every span of a parsed program lies inside the input and
//!   covers the text it claims (a name span covers the mnemonic, an operand
//!   span the operand as written, a branch span `[...]`).

#![allow(dead_code)]

use alba_diag::{Diagnostic, FileId, Span};
use alba_ladder::{Element, Instr, Program};

/// The first difference between two programs, ignoring every span, as a
/// path (`rung 2 / element 1 / leg 0 / ...`) and the two values; `None` if
/// they are equal.
pub fn ast_diff(a: &Program, b: &Program) -> Option<String> {
    if a.rungs.len() != b.rungs.len() {
        return Some(format!("number of rungs: {} vs {}", a.rungs.len(), b.rungs.len()));
    }
    for (n, (ra, rb)) in a.rungs.iter().zip(&b.rungs).enumerate() {
        if ra.comment != rb.comment {
            return Some(format!("rung {n} / comment: {:?} vs {:?}", ra.comment, rb.comment));
        }
        if let Some(d) = elements_diff(&ra.elements, &rb.elements) {
            return Some(format!("rung {n} / {d}"));
        }
    }
    if a.trailing_comment != b.trailing_comment {
        return Some(format!(
            "trailing comment: {:?} vs {:?}",
            a.trailing_comment, b.trailing_comment
        ));
    }
    if a.broken_labels != b.broken_labels {
        return Some(format!("broken labels: {:?} vs {:?}", a.broken_labels, b.broken_labels));
    }
    None
}

fn elements_diff(a: &[Element], b: &[Element]) -> Option<String> {
    if a.len() != b.len() {
        return Some(format!(
            "number of elements: {} vs {} ({} vs {})",
            a.len(),
            b.len(),
            show(a),
            show(b)
        ));
    }
    for (k, (ea, eb)) in a.iter().zip(b).enumerate() {
        match (ea, eb) {
            (Element::Instr(ia), Element::Instr(ib)) => {
                if let Some(d) = instr_diff(ia, ib) {
                    return Some(format!("element {k} / {d}"));
                }
            }
            (Element::Branch(ba), Element::Branch(bb)) => {
                if ba.legs.len() != bb.legs.len() {
                    return Some(format!(
                        "element {k} / number of legs: {} vs {}",
                        ba.legs.len(),
                        bb.legs.len()
                    ));
                }
                for (l, (la, lb)) in ba.legs.iter().zip(&bb.legs).enumerate() {
                    if let Some(d) = elements_diff(la, lb) {
                        return Some(format!("element {k} / leg {l} / {d}"));
                    }
                }
            }
            _ => {
                return Some(format!(
                    "element {k}: {} vs {}",
                    show(std::slice::from_ref(ea)),
                    show(std::slice::from_ref(eb))
                ));
            }
        }
    }
    None
}

fn instr_diff(a: &Instr, b: &Instr) -> Option<String> {
    if a.mnemonic != b.mnemonic {
        return Some(format!("mnemonic: {:?} vs {:?}", a.mnemonic, b.mnemonic));
    }
    let ta: Vec<&str> = a.operands.iter().map(|o| o.text.as_str()).collect();
    let tb: Vec<&str> = b.operands.iter().map(|o| o.text.as_str()).collect();
    (ta != tb).then(|| format!("{:?} operands: {ta:?} vs {tb:?}", a.mnemonic))
}

/// Canonical text of some elements, for messages.
fn show(e: &[Element]) -> String {
    let mut s = String::new();
    alba_ladder::print::elements(&mut s, e);
    s
}

fn span_in(src: &str, file: FileId, sp: Span, what: &str) -> Result<(), String> {
    let (s, e) = (sp.start as usize, sp.end as usize);
    if sp.file != file {
        return Err(format!("{what}: span {s}..{e} is in file {:?}, not {file:?}", sp.file));
    }
    if s > e || e > src.len() {
        return Err(format!(
            "{what}: span {s}..{e} is outside the input (len {})",
            src.len()
        ));
    }
    if !src.is_char_boundary(s) || !src.is_char_boundary(e) {
        return Err(format!(
            "{what}: span {s}..{e} is not on character boundaries (input {:?})",
            excerpt(src, s)
        ));
    }
    Ok(())
}

fn excerpt(src: &str, at: usize) -> String {
    let mut a = at.saturating_sub(12);
    while !src.is_char_boundary(a) {
        a -= 1;
    }
    let mut b = (at + 12).min(src.len());
    while !src.is_char_boundary(b) {
        b += 1;
    }
    src[a..b].to_string()
}

/// Every label of every diagnostic points inside `src` (file `file`), with
/// `start <= end <= len` on character boundaries.
pub fn diag_spans(src: &str, file: FileId, diags: &[Diagnostic]) -> Result<(), String> {
    for d in diags {
        let labels = d.primary.iter().chain(&d.secondary);
        for l in labels {
            span_in(src, file, l.span, &format!("diagnostic {} `{}`", d.code, d.message))?;
        }
    }
    Ok(())
}

/// Every span of a parsed program lies inside `src` and covers what it
/// claims to cover.
pub fn ast_spans(src: &str, file: FileId, p: &Program) -> Result<(), String> {
    for (n, r) in p.rungs.iter().enumerate() {
        span_in(src, file, r.span, &format!("rung {n}"))?;
        let text = &src[r.span.range()];
        if !text.ends_with(';') {
            return Err(format!("rung {n}: span covers {text:?}, which does not end with `;`"));
        }
        elements_spans(src, file, &r.elements, &format!("rung {n}"))?;
        for e in &r.elements {
            let sp = e.span();
            if sp.start < r.span.start || sp.end > r.span.end {
                return Err(format!("rung {n}: an element span lies outside the rung span"));
            }
        }
    }
    Ok(())
}

fn elements_spans(src: &str, file: FileId, elems: &[Element], at: &str) -> Result<(), String> {
    let mut prev_end = 0;
    for (k, e) in elems.iter().enumerate() {
        let at = format!("{at} / element {k}");
        let sp = e.span();
        span_in(src, file, sp, &at)?;
        if (sp.start as usize) < prev_end {
            return Err(format!("{at}: span starts before the previous element ends"));
        }
        prev_end = sp.end as usize;
        match e {
            Element::Instr(i) => {
                span_in(src, file, i.name_span, &format!("{at} name"))?;
                let name = &src[i.name_span.range()];
                if !name.eq_ignore_ascii_case(i.mnemonic.name()) {
                    return Err(format!("{at}: name span covers {name:?}, not {}", i.mnemonic.name()));
                }
                let whole = &src[i.span.range()];
                if i.name_span.start != i.span.start || !whole.ends_with(')') {
                    return Err(format!("{at}: instruction span covers {whole:?}"));
                }
                for (o, op) in i.operands.iter().enumerate() {
                    span_in(src, file, op.span, &format!("{at} operand {o}"))?;
                    let raw = &src[op.span.range()];
                    if collapse_ws(raw) != op.text || raw.trim() != raw {
                        return Err(format!("{at} operand {o}: span covers {raw:?}, text is {:?}", op.text));
                    }
                    if op.span.start < i.span.start || op.span.end > i.span.end {
                        return Err(format!("{at} operand {o}: outside its instruction"));
                    }
                }
            }
            Element::Branch(b) => {
                let whole = &src[b.span.range()];
                if !(whole.starts_with('[') && whole.ends_with(']')) {
                    return Err(format!("{at}: branch span covers {whole:?}"));
                }
                for (l, leg) in b.legs.iter().enumerate() {
                    elements_spans(src, file, leg, &format!("{at} / leg {l}"))?;
                    for e in leg {
                        if e.span().start < b.span.start || e.span().end > b.span.end {
                            return Err(format!("{at} / leg {l}: element outside the branch"));
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

/// Trims and collapses runs of whitespace to one space, as the parser does
/// with operands.
pub fn collapse_ws(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The full check of one input, as the fuzz target runs it: parse; every
/// diagnostic span inside the input; and when the input is accepted, every
/// AST span right, and print → parse gives the same program back with no
/// diagnostics, and printing that again gives the same text. Returns the
/// diagnostics (for file `FileId(0)`) so the caller can render them.
pub fn ladder_input(src: &str) -> Result<Vec<Diagnostic>, String> {
    let file = FileId(0);
    let (prog, diags) = alba_ladder::parse(src, file);
    diag_spans(src, file, &diags)?;
    if !diags.is_empty() {
        return Ok(diags);
    }
    ast_spans(src, file, &prog)?;
    let printed = alba_ladder::print(&prog);
    let (again, d2) = alba_ladder::parse(&printed, FileId(1));
    if !d2.is_empty() {
        return Err(format!(
            "the printed text of an accepted program does not parse: {:?}\nprinted:\n{printed}",
            d2.iter().map(|d| &d.message).collect::<Vec<_>>()
        ));
    }
    if let Some(d) = ast_diff(&prog, &again) {
        return Err(format!("print → parse changed the program: {d}\nprinted:\n{printed}"));
    }
    let twice = alba_ladder::print(&again);
    if twice != printed {
        return Err(format!("print is not stable:\n{printed}\nthen\n{twice}"));
    }
    Ok(diags)
}

/// A tag table with every type and address style, for checking random
/// programs (`ladder_check` fuzz target, `.lad` regression inputs).
pub const TAGS: &str = "name,type,address,initial,retain,description\n\
I0,BOOL,DI:1/0,,,\nI1,BOOL,%IX0.1,,,\nQ0,BOOL,DO:2/0,,,\nQ1,BOOL,Q0.1,,,\n\
B0,BOOL,,,,\nB1,BOOL,,1,1,\nM0,BOOL,M2.1,,,\n\
T0,TIMER,,,,\nT1,TIMER,,,,\nC0,COUNTER,,,,\nC1,COUNTER,,,,\n\
S0,SINT,,-3,,\nN0,INT,,100,,\nW0,INT,MW0,,,\nA0,INT,AI:3/0,,,\nA1,INT,AO:4/1,,,\n\
D0,DINT,,3,,\nD1,DINT,,-7,,\nD2,DINT,%MD1,,,\nL0,LINT,,,,\n\
R0,REAL,,1.5,,\nR1,REAL,,,,\nF0,LREAL,,,,\nTm,TIME,,T#2s,,\n";

/// Parses `src` as `main.lad` and, whatever the parser said, checks and
/// lowers it against [`TAGS`]; every diagnostic span must lie inside the
/// input and every diagnostic must render. Returns all the diagnostics.
pub fn check_and_lower(src: &str) -> Result<Vec<Diagnostic>, String> {
    let mut files = alba_diag::Files::new();
    let tf = files.add("tags.csv", TAGS);
    let lf = files.add("main.lad", src);
    let (tags, td) = alba_model::TagTable::parse(TAGS, tf);
    if !td.is_empty() {
        return Err(format!("the test tag table has errors: {td:?}"));
    }
    let (ast, diags) = alba_ladder::parse(src, lf);
    diag_spans(src, lf, &diags)?;
    let layout = alba_ladder::layout_for(&tags, &[&ast]);
    let mut b = alba_ir::Builder::new(layout);
    let cd = alba_ladder::compile(&ast, src, "main.lad", &mut b, &mut alba_ladder::Presets::default());
    diag_spans(src, lf, &cd).map_err(|e| format!("checker: {e}"))?;
    let all: Vec<_> = diags.into_iter().chain(cd).collect();
    let _ = alba_diag::render_all(&all, &files);
    if all.is_empty() {
        let _ = b.finish(files);
    }
    Ok(all)
}
