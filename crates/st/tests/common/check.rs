//! What the `st_check` fuzz target (fuzz/) and the mutation test hold for
//! any text: parsing, declaring, lowering never panic; every diagnostic
//! span lies inside the input on character boundaries and renders; a text
//! with no diagnostic gives a program that passes `Program::verify`.

use alba_diag::{Files, render_all};
use alba_ir::{Builder, Layout};
use alba_model::TagTable;

/// Tags of every type and address style, shared as globals by the input.
pub const TAGS: &str = "name,type,address\nStart,BOOL,DI:1/0\nMotor,BOOL,DO:2/0\nLevel,REAL,\nCount,DINT,\nSmall,INT,\nT1,TIMER,\nW,DINT,MD4\nFlag,BOOL,M0.1\n";

pub fn check_and_lower(src: &str) -> Result<(), String> {
    let mut files = Files::new();
    let tf = files.add("tags.csv", TAGS);
    let sf = files.add("main.st", src);
    let (mut tags, d0) = TagTable::parse(files.text(tf), tf);
    if !d0.is_empty() {
        return Err(format!("the tag table is refused: {}", render_all(&d0, &files)));
    }
    let (ast, mut diags) = alba_st::parse(files.text(sf), sf);
    let _ = alba_st::ast::dump(&ast);
    alba_st::declare(&ast, &mut tags, &mut diags);
    let mut b = Builder::new(Layout::new(&tags, &Default::default()));
    diags.extend(alba_st::compile(&ast, "main.st", &mut b));
    for d in &diags {
        for l in d.primary.iter().chain(d.secondary.iter()) {
            let r = l.span.range();
            let text = files.text(l.span.file);
            if r.start > r.end || r.end > text.len() || !text.is_char_boundary(r.start) || !text.is_char_boundary(r.end)
            {
                return Err(format!(
                    "span {r:?} outside the input or between characters: {}",
                    d.message
                ));
            }
        }
    }
    let _ = render_all(&diags, &files);
    if diags.is_empty() {
        let p = b.finish(files);
        p.verify().map_err(|e| format!("the program does not verify: {e}"))?;
    }
    Ok(())
}
