//! Arbitrary input never panics a parser, and every span a parser reports
//! lies inside its input, on character boundaries: the ladder parser (and
//! the diagnostics render), the CPT expression parser, `tags.csv` and
//! `alba.toml`.

use crate::check::{diag_spans, ladder_input};
use crate::strategies::{config, expr, mutate, mutation, noisy, program, soup};
use alba_diag::{Diagnostic, FileId, Files};
use alba_ladder::print;
use alba_model::TagTable;
use proptest::prelude::*;

/// Runs `src` through the ladder parser and checks it (see
/// `check::ladder_input`), then renders its diagnostics.
pub fn ladder(src: &str) -> Result<(), String> {
    let diags = ladder_input(src)?;
    render(src, "main.lad", &diags);
    Ok(())
}

fn render(src: &str, name: &str, diags: &[Diagnostic]) {
    let mut files = Files::new();
    files.add(name, src);
    for d in diags {
        let _ = d.short(&files);
        let _ = d.render(&files);
    }
}

/// The CPT parser on `src` placed at byte `base` of a file.
pub fn cpt(src: &str) -> Result<(), String> {
    let base = 7;
    if let Err((msg, sp)) = alba_ladder::expr::parse(src, FileId(0), base) {
        let (s, e) = (sp.start as usize, sp.end as usize);
        if !(base <= s && s <= e && e <= base + src.len()) {
            return Err(format!(
                "expression error span {s}..{e} outside {base}..{}: {msg}",
                base + src.len()
            ));
        }
        if !src.is_char_boundary(s - base) || !src.is_char_boundary(e - base) {
            return Err(format!(
                "expression error span {s}..{e} not on character boundaries: {msg}"
            ));
        }
    }
    Ok(())
}

/// `tags.csv`: no panic, spans inside the input, diagnostics render.
pub fn tags(src: &str) -> Result<(), String> {
    let (_, diags) = TagTable::parse(src, FileId(0));
    diag_spans(src, FileId(0), &diags)?;
    render(src, "tags.csv", &diags);
    Ok(())
}

/// `alba.toml`: no panic, spans inside the input, diagnostics render.
pub fn toml(src: &str) -> Result<(), String> {
    let (_, diags) = alba_load::parse(src, FileId(0));
    if !diags.is_empty() {
        diag_spans(src, FileId(0), &diags)?;
        render(src, "alba.toml", &diags);
    }
    Ok(())
}

fn check(what: &str, f: fn(&str) -> Result<(), String>, src: &str) -> Result<(), TestCaseError> {
    f(src).map_err(|e| TestCaseError::fail(format!("{what}: {e}\ninput: {src:?}")))
}

/// The ladder parser and the CPT parser (one property per parser family, so
/// a bug in one does not hide behind a bug in another).
fn ladder_and_cpt(src: &str) -> Result<(), TestCaseError> {
    check("ladder", ladder, src)?;
    check("cpt", cpt, src)
}

const CSV_PIECES: &[&str] = &[
    "name,type,address,initial,retain,description\n",
    "name",
    "type",
    "address",
    "initial",
    ",",
    "\"",
    "\"\"",
    "\n",
    "\r\n",
    "\r",
    " ",
    "BOOL",
    "INT",
    "DINT",
    "REAL",
    "TIME",
    "TIMER",
    "COUNTER",
    "PID",
    "DI:1/",
    "DO:2/0",
    "%MW",
    "MW",
    "M0.",
    "1",
    "-",
    "e",
    "T#",
    "16#",
    "ms",
    "9999999999",
    "é",
    "中",
    "\u{feff}",
    "\u{1F600}",
];

const TOML_PIECES: &[&str] = &[
    "name",
    "scan_ms",
    "programs",
    "description",
    "[board]",
    "model",
    "pinmap",
    " = ",
    "=",
    "\"",
    "'",
    "[",
    "]",
    ",",
    "\n",
    "\r\n",
    "#",
    "uno",
    "s7",
    "main.lad",
    "-1",
    "99999999999",
    "1e3",
    "{",
    "}",
    ".",
    "é",
    "\u{1F600}",
    "\"\"\"",
    "\\u00e9",
    "\\",
];

fn pieces(from: &'static [&'static str]) -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(from), 0..60).prop_map(|v| v.concat())
}

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn ladder_arbitrary_strings(s in any::<String>()) {
        ladder_and_cpt(&s)?;
    }

    #[test]
    fn ladder_random_mixes_of_pieces(s in soup()) {
        ladder_and_cpt(&s)?;
    }

    #[test]
    fn ladder_mutations_of_valid_programs(
        (p, seed, muts) in (program(), any::<u64>(), prop::collection::vec(mutation(), 1..6))
    ) {
        let text = if seed % 2 == 0 { print(&p) } else { noisy(&p, seed) };
        ladder_and_cpt(&mutate(&text, &muts))?;
    }

    #[test]
    fn cpt_mutations_of_valid_expressions(
        (e, muts) in (expr(), prop::collection::vec(mutation(), 1..6))
    ) {
        check("cpt", cpt, &mutate(&e, &muts))?;
    }

    #[test]
    fn tags_csv_arbitrary_strings(s in prop_oneof![any::<String>(), soup()]) {
        check("tags.csv", tags, &s)?;
    }

    #[test]
    fn tags_csv_random_mixes_of_pieces(s in pieces(CSV_PIECES)) {
        check("tags.csv", tags, &s)?;
    }

    #[test]
    fn tags_csv_mutations_of_a_valid_file(muts in prop::collection::vec(mutation(), 1..8)) {
        check("tags.csv", tags, &mutate(VALID_TAGS, &muts))?;
    }

    #[test]
    fn alba_toml_arbitrary_strings(s in prop_oneof![any::<String>(), soup()]) {
        check("alba.toml", toml, &s)?;
    }

    #[test]
    fn alba_toml_random_mixes_of_pieces(s in pieces(TOML_PIECES)) {
        check("alba.toml", toml, &s)?;
    }

    #[test]
    fn alba_toml_mutations_of_a_valid_file(muts in prop::collection::vec(mutation(), 1..8)) {
        check("alba.toml", toml, &mutate(VALID_TOML, &muts))?;
    }
}

const VALID_TAGS: &str = "name,type,address,initial,retain,description\n\
    Start,BOOL,DI:1/0,,,start\nT,TIMER,,,,\"a, \"\"b\"\"\"\nR,REAL,%MD2,-2.5e3,1,\n\
    W,INT,MW4,16#FF,,\nD,TIME,,T#1m30s,,\nC,COUNTER,,,,\nL,LREAL,,1e300,,\nS,SINT,Q0.1,-128,,\n";

const VALID_TOML: &str = "name = \"tank\"\ndescription = \"x\"\nscan_ms = 10\n\
    programs = [\"main.lad\", \"b.lad\"]\n[board]\nmodel = \"uno\"\npinmap = \"s7\"\n";
