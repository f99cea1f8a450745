//! The project behind the server: its files as last saved, compiling them
//! with an edit in place, saving edits atomically, and the JSON views of
//! programs (rungs with their element ids) and of diagnostics.

use crate::reply;
use alba_compiler::diag::{Diagnostic, FileId, Files};
use alba_compiler::project::{Language, Project};
use alba_compiler::{il as alba_il, ladder as alba_ladder};
use alba_ir::Program;
use alba_ir::model::TagTable;
use alba_ir::model::fsutil::write_atomic;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Why an edit was not checked, saved or applied.
#[derive(Debug, thiserror::Error)]
pub enum EditError {
    #[error("no program `{0}` in this project")]
    UnknownProgram(String),
    #[error("the project has no tags.csv")]
    NoTagsFile,
    /// The edited project does not compile: its diagnostics.
    #[error("{} error{}", .diagnostics.len(), if .diagnostics.len() == 1 { "" } else { "s" })]
    DoesNotCompile { diagnostics: Vec<reply::Diagnostic> },
    #[error("cannot save {}: {source}", .path.display())]
    Save { path: PathBuf, source: std::io::Error },
    /// Saved, but the runtime refused the new program.
    #[error("saved, but not applied: {0}")]
    NotApplied(alba_control::runtime::Error),
}

impl EditError {
    /// The error of a project that does not compile.
    pub fn does_not_compile(c: &Compiled) -> EditError {
        EditError::DoesNotCompile {
            diagnostics: diagnostics_json(&c.diagnostics, &c.project.files),
        }
    }
}

/// An edit to check or apply: a program's new text, or the tag table's.
pub enum Edit<'a> {
    Program { name: &'a str, text: &'a str },
    Tags(&'a str),
}

/// The project with an edit in place, compiled.
pub struct Compiled {
    pub project: Project,
    pub program: Option<Program>,
    pub diagnostics: Vec<Diagnostic>,
}

/// Loads and compiles `dir`.
pub fn load(dir: &Path) -> Compiled {
    let c = alba_load::compile_dir(dir);
    Compiled {
        project: c.project,
        program: c.program,
        diagnostics: c.diagnostics,
    }
}

/// Compiles `project` with `edit` in place (nothing is saved).
pub fn compile_with(project: &Project, edit: Option<&Edit>) -> Result<Compiled, EditError> {
    let mut p = project.clone();
    let mut diagnostics = Vec::new();
    match edit {
        Some(Edit::Program { name, text }) => {
            let file = find(&p, name)?.file;
            p.files.replace(file, *text);
        }
        Some(Edit::Tags(text)) => {
            let file = p.tags_file.ok_or(EditError::NoTagsFile)?;
            p.files.replace(file, *text);
            let (tags, d) = TagTable::parse(p.files.text(file), file);
            p.tags = tags;
            diagnostics.extend(d);
        }
        None => {}
    }
    let (program, d) = alba_compiler::compile(&p);
    diagnostics.extend(d);
    let program = if diagnostics.is_empty() { program } else { None };
    Ok(Compiled {
        project: p,
        program,
        diagnostics,
    })
}

/// The program listed as `name` (case-insensitively).
pub fn find<'a>(p: &'a Project, name: &str) -> Result<&'a alba_compiler::project::ProgramSource, EditError> {
    p.programs
        .iter()
        .find(|s| s.name.eq_ignore_ascii_case(name))
        .ok_or_else(|| EditError::UnknownProgram(name.to_string()))
}

/// Saves the edited file of `c` (the program or tags.csv) atomically.
pub fn save(c: &Compiled, edit: &Edit) -> Result<(), EditError> {
    let (rel, file) = match edit {
        Edit::Program { name, .. } => {
            let s = find(&c.project, name)?;
            (s.name.clone(), s.file)
        }
        Edit::Tags(_) => (
            "tags.csv".to_string(),
            c.project.tags_file.ok_or(EditError::NoTagsFile)?,
        ),
    };
    let path = c.project.dir.join(&rel);
    let text = c.project.files.text(file);
    write_atomic(&path, |w| w.write_all(text.as_bytes())).map_err(|source| EditError::Save { path, source })
}

/// What `edit` changes in `project` (before the edit), for the audit
/// trail: `rungs: 1 added, 0 removed, 2 changed (12 → 13)` for a ladder
/// program (a rung's comment counts, its layout does not), `lines: …` for
/// IL, `rows: …` for tags.csv.
pub fn edit_summary(project: &Project, edit: &Edit) -> Result<String, EditError> {
    let (file, new, language) = match edit {
        Edit::Program { name, text } => {
            let s = find(project, name)?;
            (s.file, *text, Some(s.language))
        }
        Edit::Tags(text) => (project.tags_file.ok_or(EditError::NoTagsFile)?, *text, None),
    };
    let old = project.files.text(file);
    let (unit, old, new) = match language {
        Some(Language::Ladder) => ("rungs", rungs(old, file), rungs(new, file)),
        Some(Language::Il | Language::Net | Language::Sfc | Language::St) => ("lines", lines(old), lines(new)),
        None => ("rows", lines(old), lines(new)),
    };
    let d = alba_control::audit::diff(&old, &new);
    Ok(format!("{unit}: {d} ({} → {})", old.len(), new.len()))
}

/// Each rung of a ladder text: its comment and its text with whitespace
/// runs made one space.
fn rungs(text: &str, file: FileId) -> Vec<String> {
    let (ast, _) = alba_ladder::parse(text, file);
    ast.rungs
        .iter()
        .map(|r| {
            let body = text.get(r.span.start as usize..r.span.end as usize).unwrap_or_default();
            let body: Vec<&str> = body.split_whitespace().collect();
            format!("{}\n{}", r.comment.join("\n"), body.join(" "))
        })
        .collect()
}

/// The non-blank lines of a text, without trailing white space.
fn lines(text: &str) -> Vec<String> {
    text.lines()
        .map(str::trim_end)
        .filter(|l| !l.is_empty())
        .map(str::to_string)
        .collect()
}

pub fn language(l: Language) -> reply::Language {
    match l {
        Language::Ladder => reply::Language::Ladder,
        Language::Il => reply::Language::Il,
        Language::Net => reply::Language::Net,
        Language::Sfc => reply::Language::Sfc,
        Language::St => reply::Language::St,
    }
}

/// A diagnostic as the API shows it (docs/api.md).
/// Worded in the request's language (`Accept-Language`, [`crate::lang`]).
pub fn diagnostic_json(d: &Diagnostic, files: &Files) -> reply::Diagnostic {
    let lang = crate::lang::request_lang();
    let localized;
    let d = if lang == alba_compiler::diag::Lang::En {
        d
    } else {
        localized = d.localized(lang);
        &localized
    };
    let place = d.primary.as_ref().map(|l| {
        let s = l.span;
        let (line, col) = files.line_col(s.file, s.start as usize);
        let (end_line, end_col) = files.line_col(s.file, s.end as usize);
        let name = files.name(s.file);
        let file = Path::new(name)
            .file_name()
            .map_or(name.to_string(), |f| f.to_string_lossy().to_string());
        (file, line, col, end_line, end_col)
    });
    reply::Diagnostic {
        code: d.code.to_string(),
        severity: "error".into(),
        message: d.message.clone(),
        file: place.as_ref().map(|p| p.0.clone()),
        line: place.as_ref().map(|p| p.1),
        col: place.as_ref().map(|p| p.2),
        end_line: place.as_ref().map(|p| p.3),
        end_col: place.as_ref().map(|p| p.4),
        help: d.help.clone(),
    }
}

pub fn diagnostics_json(ds: &[Diagnostic], files: &Files) -> Vec<reply::Diagnostic> {
    ds.iter().map(|d| diagnostic_json(d, files)).collect()
}

/// Element ids of the compiled program by the span of their source.
fn element_ids(program: Option<&Program>, file: FileId) -> HashMap<(u32, u32), u32> {
    program.map_or_else(HashMap::new, |p| {
        p.elements
            .iter()
            .enumerate()
            .filter(|(_, e)| e.span.file == file)
            .map(|(id, e)| ((e.span.start, e.span.end), id as u32))
            .collect()
    })
}

/// `GET /api/programs/{name}`: the text, its diagnostics and its structure
/// (rungs of elements for ladder, instruction lines for IL) with the ids
/// of the compiled program's elements.
pub fn program_json(
    project: &Project,
    program: Option<&Program>,
    name: &str,
    diags: &[Diagnostic],
) -> Result<reply::Program, EditError> {
    let src = find(project, name)?;
    let files = &project.files;
    let text = files.text(src.file);
    let ids = element_ids(program, src.file);
    let id_of = |s: alba_compiler::diag::Span| ids.get(&(s.start, s.end)).copied();
    let lc = |s: alba_compiler::diag::Span| files.line_col(src.file, s.start as usize);
    let mut out = reply::Program {
        name: src.name.clone(),
        language: language(src.language),
        plant: src.plant,
        text: text.to_string(),
        diagnostics: diags
            .iter()
            .filter(|d| d.primary.as_ref().is_some_and(|l| l.span.file == src.file))
            .map(|d| diagnostic_json(d, files))
            .collect(),
        rungs: None,
        lines: None,
        transitions: None,
    };
    match src.language {
        Language::Ladder => {
            let (ast, _) = alba_ladder::parse(text, src.file);
            let rungs = ast
                .rungs
                .iter()
                .enumerate()
                .map(|(n, r)| reply::RungJson {
                    number: n,
                    comment: r.comment.clone(),
                    line: lc(r.elements.first().map_or(r.span, |e| e.span())).0,
                    elements: elements_json(&r.elements, &id_of, &lc),
                })
                .collect();
            out.rungs = Some(rungs);
        }
        Language::Il => {
            let (ast, _) = alba_il::parse(text, src.file);
            let lines = ast
                .items
                .iter()
                .filter_map(|i| match i {
                    alba_il::ast::Item::Instr(i) => Some(reply::IlLine {
                        line: lc(i.span).0,
                        id: id_of(i.span),
                    }),
                    _ => None,
                })
                .collect();
            out.lines = Some(lines);
        }
        // A net's structure is its PNML: the studio reads it; the server
        // adds each transition's monitored elements (found by span).
        Language::Net => {
            let (net, _) = alba_compiler::net::load(src.file, text);
            out.transitions = net.map(|net| {
                net.transitions
                    .iter()
                    .map(|t| {
                        let e = alba_compiler::petri::enabled_span(t.span);
                        reply::NetTransition {
                            id: t.id.clone(),
                            enabled: ids.get(&(e.start, e.end)).copied(),
                            fired: id_of(t.span),
                        }
                    })
                    .collect()
            });
        }
        Language::Sfc | Language::St => {}
    }
    Ok(out)
}

fn elements_json(
    elems: &[alba_ladder::Element],
    id_of: &dyn Fn(alba_compiler::diag::Span) -> Option<u32>,
    lc: &dyn Fn(alba_compiler::diag::Span) -> (usize, usize),
) -> Vec<reply::ElementJson> {
    elems
        .iter()
        .map(|e| {
            let (line, col) = lc(e.span());
            match e {
                alba_ladder::Element::Instr(i) => reply::ElementJson::Instr(reply::InstrJson {
                    id: id_of(i.span),
                    mnemonic: i.mnemonic.name().to_string(),
                    operands: i.operands.iter().map(|o| o.text.clone()).collect(),
                    line,
                    col,
                }),
                alba_ladder::Element::Branch(b) => reply::ElementJson::Branch(reply::BranchJson {
                    id: id_of(b.span),
                    line,
                    col,
                    legs: b.legs.iter().map(|l| elements_json(l, id_of, lc)).collect(),
                }),
            }
        })
        .collect()
}

/// The element ids of each program unit (for monitoring by program).
pub fn unit_elements(p: &Program) -> Vec<std::ops::Range<u32>> {
    // (first, end) of each unit; (MAX, 0) for a unit with no element.
    let mut ranges = vec![(u32::MAX, 0); p.units.len()];
    for (id, e) in p.elements.iter().enumerate() {
        let unit = p.rungs.get(e.rung as usize).map_or(0, |r| r.unit as usize);
        if let Some(r) = ranges.get_mut(unit) {
            r.0 = r.0.min(id as u32);
            r.1 = r.1.max(id as u32 + 1);
        }
    }
    ranges
        .into_iter()
        .map(|(start, end)| if start > end { 0..0 } else { start..end })
        .collect()
}

/// The places a name stands for: a tag's value, or every member of a
/// structure (`Delay` → `Delay.PRE`, `Delay.ACC`, …).
fn places_of(layout: &alba_ir::Layout, name: &str) -> Vec<alba_ir::Place> {
    let upper = name.trim().to_ascii_uppercase();
    match layout.resolve(name) {
        Ok(alba_ir::Target::Value { place, .. }) => vec![place],
        Ok(_) => crate::tags::every_value(layout)
            .into_iter()
            .filter(|(n, _)| n.to_ascii_uppercase().starts_with(&format!("{upper}.")))
            .map(|(_, p)| p)
            .collect(),
        Err(_) => Vec::new(),
    }
}

/// The names an operand refers to: itself, or the identifiers of an
/// expression (`CPT(Out, Level * 2.0 + Bias)`).
fn names_in(text: &str) -> Vec<&str> {
    let mut out = vec![text.trim()];
    out.extend(
        text.split(|c: char| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | ':' | '/')))
            .filter(|t| t.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_'))
            .filter(|t| *t != text.trim()),
    );
    out
}

/// `GET /api/tags/{name}/uses`: every place a program of the project names
/// `name` (as a tag, a member, an alias address, or inside an expression),
/// in program order, with where it is and whether it writes there.
pub fn uses(project: &Project, program: &Program, name: &str) -> Result<Vec<reply::TagUse>, String> {
    let layout = &program.layout;
    let wanted = places_of(layout, name);
    if wanted.is_empty() {
        return Err(format!("`{name}` is not a tag, member or address of this program"));
    }
    let hits = |text: &str| {
        names_in(text)
            .into_iter()
            .any(|n| places_of(layout, n).iter().any(|p| wanted.contains(p)))
    };
    let files = &project.files;
    let mut out = Vec::new();
    for src in &project.programs {
        let text = files.text(src.file);
        let ids = element_ids(Some(program), src.file);
        let mut push = |span: alba_compiler::diag::Span, instr: String, rung: Option<usize>, write: bool| {
            let (line, col) = files.line_col(src.file, span.start as usize);
            out.push(reply::TagUse {
                program: src.name.clone(),
                line,
                col,
                rung,
                id: ids.get(&(span.start, span.end)).copied(),
                instruction: instr,
                write,
            });
        };
        match src.language {
            Language::Ladder => {
                let (ast, _) = alba_ladder::parse(text, src.file);
                for (n, rung) in ast.rungs.iter().enumerate() {
                    let mut stack: Vec<&alba_ladder::Element> = rung.elements.iter().rev().collect();
                    while let Some(e) = stack.pop() {
                        match e {
                            alba_ladder::Element::Instr(i) => {
                                let args = i.mnemonic.args();
                                for (k, o) in i.operands.iter().enumerate() {
                                    if hits(&o.text) {
                                        let write = matches!(
                                            args.get(k),
                                            Some(alba_ladder::Arg::BitOut | alba_ladder::Arg::NumOut)
                                        );
                                        let ops: Vec<&str> = i.operands.iter().map(|o| o.text.as_str()).collect();
                                        push(
                                            i.span,
                                            format!("{}({})", i.mnemonic.name(), ops.join(",")),
                                            Some(n),
                                            write,
                                        );
                                        break;
                                    }
                                }
                            }
                            alba_ladder::Element::Branch(b) => {
                                for leg in b.legs.iter().rev() {
                                    stack.extend(leg.iter().rev());
                                }
                            }
                        }
                    }
                }
            }
            Language::Il => {
                let (ast, _) = alba_il::parse(text, src.file);
                for item in &ast.items {
                    if let alba_il::ast::Item::Instr(i) = item
                        && i.operands.iter().any(|o| hits(&o.text))
                    {
                        let ops: Vec<&str> = i.operands.iter().map(|o| o.text.as_str()).collect();
                        push(i.span, format!("{} {}", i.name, ops.join(", ")), None, false);
                    }
                }
            }
            Language::Net | Language::Sfc | Language::St => {}
        }
    }
    Ok(out)
}
