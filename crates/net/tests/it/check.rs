//! The checks every PNML input must pass, shared by the fuzz target
//! `pnml_load` (through `#[path]`) and the regression test: `load` never
//! panics; every diagnostic is located inside the input on character
//! boundaries and renders (the unfolding of a coloured net's too); a loaded net saves and loads back to itself
//! (load → save → load is the identity, spans aside) without errors, and
//! saving it again gives the same text.

use alba_diag::{Diagnostic, FileId, Files};
use alba_net::{is_warning, load, save};

/// Every diagnostic is located inside `src` on character boundaries and renders.
fn located(src: &str, diags: &[Diagnostic]) -> Result<(), String> {
    let mut files = Files::new();
    files.add("net.pnml", src);
    for d in diags {
        let Some(p) = &d.primary else {
            return Err(format!("unlocated diagnostic: {}", d.message));
        };
        let r = p.span.range();
        if r.start > r.end || r.end > src.len() || !src.is_char_boundary(r.start) || !src.is_char_boundary(r.end) {
            return Err(format!(
                "span {r:?} outside the input or off a character boundary: {}",
                d.message
            ));
        }
        let _ = d.short(&files);
        let _ = d.render(&files);
    }
    Ok(())
}

pub fn pnml_input(src: &str) -> Result<Vec<Diagnostic>, String> {
    let (net, diags) = load(FileId(0), src);
    located(src, &diags)?;
    // A coloured net: the unfolding never panics, and its error is located too.
    if alba_net::colored::is_symmetric(src) {
        let (unfolded, d, _) = alba_net::load_for_analysis(FileId(0), src);
        located(src, &d)?;
        if unfolded.is_none() == d.is_empty() {
            return Err("an unfolding and an error, or neither".into());
        }
    }
    let errors = diags.iter().any(|d| !is_warning(d));
    match (&net, errors) {
        (Some(_), true) => return Err("a net despite errors".into()),
        (None, false) => return Err("no net and no error".into()),
        _ => {}
    }
    if let Some(mut net) = net {
        let saved = save(&net);
        let (again, d2) = load(FileId(0), &saved);
        if let Some(d) = d2.iter().find(|d| !is_warning(d)) {
            return Err(format!("the saved net does not load: {}\n{saved}", d.message));
        }
        let Some(mut again) = again else {
            return Err("the saved net does not load".into());
        };
        net.clear_spans();
        again.clear_spans();
        if net != again {
            return Err(format!("load → save → load changed the net\n{net:#?}\n{again:#?}"));
        }
        if save(&again) != saved {
            return Err("saving twice gives two texts".into());
        }
    }
    Ok(diags)
}
