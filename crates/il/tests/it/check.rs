//! Checks shared by the integration tests and the cargo-fuzz targets
//! (`fuzz/fuzz_targets/awl_*.rs` include this file with `#[path]`, so it
//! must depend on nothing but `alba_il`, `alba_ir`, `alba_diag` and `alba_model`).
//!
//! - [`diag_spans`]: every span of every diagnostic lies inside the input,
//!   on character boundaries, in the right file.
//! - [`ast_spans`]: every span of a parsed program lies inside the input and
//!   covers the text it claims (a name span the mnemonic as written, an
//!   operand span the operand, a network span its `NETWORK` line).
//! - [`awl_input`]: the parser on one input (the `awl_parse` target).
//! - [`check_and_lower`]: parser, checker and lowering against [`TAGS`],
//!   then the IR's own verification (the `awl_check` target).

#![allow(dead_code)]

use alba_diag::{Diagnostic, FileId, Span};
use alba_il::Program;
use alba_il::ast::{Item, Mn};

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
    let mut a = at.saturating_sub(12).min(src.len());
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
/// claims to cover. The parser reads each line on its own, so this holds
/// for the lines it kept even when it reported others.
pub fn ast_spans(src: &str, file: FileId, p: &Program) -> Result<(), String> {
    let mut prev_end = 0;
    for (n, item) in p.items.iter().enumerate() {
        let at = format!("item {n}");
        let sp = match item {
            Item::Network { span, .. } => *span,
            Item::Instr(i) => i.span,
            Item::Bad => continue,
        };
        span_in(src, file, sp, &at)?;
        if (sp.start as usize) < prev_end {
            return Err(format!("{at}: span starts before the previous item ends"));
        }
        prev_end = sp.end as usize;
        let whole = &src[sp.range()];
        if whole.trim() != whole || whole.is_empty() {
            return Err(format!("{at}: span covers {whole:?}"));
        }
        let Item::Instr(i) = item else {
            if !whole.get(..7).is_some_and(|w| w.eq_ignore_ascii_case("NETWORK")) {
                return Err(format!("{at}: network span covers {whole:?}"));
            }
            continue;
        };
        span_in(src, file, i.name_span, &format!("{at} name"))?;
        let name = &src[i.name_span.range()];
        if i.name_span.start != i.span.start || name != i.name || Mn::parse(name) != Some(i.mn) {
            return Err(format!(
                "{at}: name span covers {name:?}, the name is {:?} ({:?})",
                i.name, i.mn
            ));
        }
        let mut end = i.name_span.end;
        for (o, op) in i.operands.iter().enumerate() {
            let at = format!("{at} operand {o}");
            span_in(src, file, op.span, &at)?;
            if op.span.start < end || op.span.end > i.span.end {
                return Err(format!(
                    "{at}: outside its instruction, or before the operand before it"
                ));
            }
            end = op.span.end;
            let raw = &src[op.span.range()];
            // A block comment inside a quoted symbol is blanked in the text.
            let commented = raw.contains("/*") || raw.contains("*/");
            if raw.trim() != raw || raw.is_empty() || (!commented && raw.trim_matches('"') != op.text) {
                return Err(format!("{at}: span covers {raw:?}, text is {:?}", op.text));
            }
        }
        if end != i.span.end {
            return Err(format!(
                "{at}: the instruction span {whole:?} does not end with its last operand"
            ));
        }
    }
    Ok(())
}

/// The parser on one input, as the `awl_parse` fuzz target runs it: no
/// panic; every diagnostic span inside the input on character boundaries;
/// every span of the program right. Returns the diagnostics (for file
/// `FileId(0)`) so the caller can render them.
pub fn awl_input(src: &str) -> Result<Vec<Diagnostic>, String> {
    let file = FileId(0);
    let (prog, diags) = alba_il::parse(src, file);
    diag_spans(src, file, &diags)?;
    ast_spans(src, file, &prog)?;
    Ok(diags)
}

/// A small tag table with every type and address style an AWL program may
/// name, for checking random programs (`awl_check` fuzz target, regression
/// inputs). `Tmr` and `Ctr` are Logix timers and counters, which AWL refuses.
pub const TAGS: &str = "name,type,address,initial,retain,description\n\
Start,BOOL,I0.0,,,\nStop,BOOL,%IX0.1,,,\nMotor,BOOL,Q0.0,,,\nLamp,BOOL,DO:2/1,,,\n\
Flag,BOOL,,,,\nHeld,BOOL,,1,1,\nBit,BOOL,M2.1,,,\n\
Small,SINT,MB3,,,\nW,INT,MW4,,,\nN,INT,,100,,\nLevel,INT,AIW0,,,\nValve,INT,AQW2,,,\n\
D,DINT,MD8,,,\nCount,DINT,,-7,,\nR,REAL,MD12,,,\nRatio,REAL,,1.5,,\n\
Big,LINT,,,,\nWide,LREAL,,,,\nTm,TIME,,T#2s,,\nTmr,TIMER,,,,\nCtr,COUNTER,,,,\n";

/// Parses `src` as `main.awl` and, whatever the parser said, checks and
/// lowers it against [`TAGS`] as the compiler does (`uses`, then the layout,
/// then `compile`); every diagnostic span must lie inside the input and
/// every diagnostic must render. Without diagnostics, the finished program
/// must pass `Program::verify`. Returns all the diagnostics.
pub fn check_and_lower(src: &str) -> Result<Vec<Diagnostic>, String> {
    let mut files = alba_diag::Files::new();
    let tf = files.add("tags.csv", TAGS);
    let lf = files.add("main.awl", src);
    let (tags, td) = alba_model::TagTable::parse(TAGS, tf);
    if !td.is_empty() {
        return Err(format!("the test tag table has errors: {td:?}"));
    }
    let (ast, diags) = alba_il::parse(src, lf);
    diag_spans(src, lf, &diags)?;
    let uses = alba_il::uses(&ast);
    let mut b = alba_ir::Builder::new(alba_ir::Layout::new(&tags, &uses));
    let cd = alba_il::compile(&ast, "main.awl", &mut b, &mut alba_il::Shared::default());
    diag_spans(src, lf, &cd).map_err(|e| format!("checker: {e}"))?;
    let all: Vec<_> = diags.into_iter().chain(cd).collect();
    let _ = alba_diag::render_all(&all, &files);
    if all.is_empty() {
        let program = b.finish(files);
        program
            .verify()
            .map_err(|e| format!("the lowered program fails verification: {e}"))?;
    }
    Ok(all)
}
