//! Loads a project folder and compiles every program in it, in the order of
//! `alba.toml`, into one IR program over one layout.

use alba_ir::{Builder, Program};
use alba_model::{Code, Diagnostic, Files, Language, Project};
use std::path::Path;

/// A project and what compiling it gave.
pub struct Compiled {
    pub project: Project,
    /// `Some` when there were no errors.
    pub program: Option<Program>,
    /// Every problem found, in file order.
    pub diagnostics: Vec<Diagnostic>,
}

impl Compiled {
    pub fn files(&self) -> &Files {
        &self.project.files
    }
}

/// Loads and compiles the project in `dir`, reporting every problem of every file.
pub fn compile_dir(dir: &Path) -> Compiled {
    let (project, mut diagnostics) = Project::load(dir);
    let in_tags = |d: &Diagnostic| d.primary.as_ref().map(|l| l.span.file) == project.tags_file;
    let tags_ok = project.tags_file.is_some() && !diagnostics.iter().any(in_tags);
    let (program, mut program_diags) = compile(&project);
    if !tags_ok {
        // With rows of tags.csv refused, "unknown tag" errors may only echo
        // them: report the table's errors and the rest, not the echoes.
        program_diags.retain(|d| d.code != Code::UnknownTag);
    }
    diagnostics.extend(program_diags);
    // In file order, then by place, so a reader meets them top to bottom.
    diagnostics.sort_by_key(|d| d.primary.as_ref().map(|l| (l.span.file, l.span.start)));
    let program = if diagnostics.is_empty() { program } else { None };
    Compiled {
        project,
        program,
        diagnostics,
    }
}

/// Compiles the programs of a loaded project.
pub fn compile(project: &Project) -> (Option<Program>, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let mut ladders = Vec::new();
    for src in &project.programs {
        match src.language {
            Language::Ladder => {
                let (ast, d) = alba_ladder::parse(project.files.text(src.file), src.file);
                diags.extend(d);
                ladders.push((src.name.as_str(), src.file, ast));
            }
        }
    }
    let asts: Vec<&alba_ladder::Program> = ladders.iter().map(|(_, _, a)| a).collect();
    let layout = alba_ladder::layout_for(&project.tags, &asts);
    let mut b = Builder::new(layout);
    let mut presets = alba_ladder::Presets::default();
    for (name, file, ast) in &ladders {
        let src = project.files.text(*file);
        diags.extend(alba_ladder::compile(ast, src, name, &mut b, &mut presets));
    }
    if !diags.is_empty() {
        return (None, diags);
    }
    (Some(b.finish(project.files.clone())), diags)
}
