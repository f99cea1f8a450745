//! Compiles every program of a loaded project, in the order of `alba.toml`,
//! into one IR program over one layout (`alba_load::compile_dir` loads the
//! folder first: the TOML reader is not under the compiler, ADR 0014).

use alba_diag::{Code, Diagnostic, Files};
use alba_ir::layout::Uses;
use alba_ir::{Builder, Layout, Program};
use alba_project::{Language, Project};

pub mod normal;
pub mod petri;
pub mod screens;
pub mod sfc;

/// The crates of the compiler's public API — project loading, diagnostics and
/// the front ends (for views of a program's structure) — so that a user of
/// the compiler (the studio's API) names one crate for the path from a
/// folder to a program.
pub use alba_diag as diag;
pub use alba_il as il;
pub use alba_ladder as ladder;
pub use alba_net as net;
pub use alba_project as project;
pub use alba_st as st;

/// A net's tags: its places' marking (petri.rs), and in normal mode its
/// transitions' and timers' (normal.rs).
fn net_tags(net: &alba_net::Net, name: &str, tags: &mut alba_model::TagTable, diags: &mut Vec<Diagnostic>) {
    petri::marking_tags(net, name, tags, diags);
    if net.mode == alba_net::Mode::Normal {
        normal::extra_tags(net, name, tags, diags);
    }
}

/// Compiles a net as one unit, by its mode: the source's normal semantics
/// (normal.rs, one token per element) or Petri's (petri.rs).
fn compile_net(
    net: &alba_net::Net,
    file: alba_diag::FileId,
    text: &str,
    unit: &str,
    b: &mut Builder,
) -> Vec<Diagnostic> {
    if net.mode == alba_net::Mode::Normal {
        normal::compile(net, file, text, unit, b)
    } else {
        petri::compile(net, file, text, unit, b)
    }
}

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

/// Compiles a loaded project (`alba_load::compile_dir` loads a folder and
/// calls this), reporting every problem of every file: `diagnostics` are the
/// loader's.
pub fn compile_loaded(project: Project, mut diagnostics: Vec<Diagnostic>) -> Compiled {
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

enum Ast {
    Ladder(alba_ladder::Program),
    Il(alba_il::Program),
    /// `None` when the file could not be loaded (the loader reported why).
    Net(Option<Box<alba_net::Net>>),
    /// `None` when the chart could not be parsed.
    Sfc(Option<Box<alba_net::sfc::Sfc>>),
    St(alba_st::File),
}

/// The `.st` files of `all` but `file`: its library.
fn others<'a>(all: &[&'a alba_st::File], file: &alba_st::File) -> Vec<&'a alba_st::File> {
    all.iter().copied().filter(|f| !std::ptr::eq(*f, file)).collect()
}

/// Compiles the programs of a loaded project: the control programs in the
/// order of `alba.toml`, then the plant models.
pub fn compile(project: &Project) -> (Option<Program>, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let mut uses = Uses::default();
    let mut asts = Vec::new();
    for src in &project.programs {
        let text = project.files.text(src.file);
        let ast = match src.language {
            Language::Ladder => {
                let (ast, d) = alba_ladder::parse(text, src.file);
                diags.extend(d);
                uses.addresses.extend(alba_ladder::addresses(&ast));
                uses.slc.extend(alba_ladder::slc_structs(&ast));
                Ast::Ladder(ast)
            }
            Language::Il => {
                let (ast, d) = alba_il::parse(text, src.file);
                diags.extend(d);
                let u = alba_il::uses(&ast);
                uses.addresses.extend(u.addresses);
                uses.timers.extend(u.timers);
                uses.counters.extend(u.counters);
                Ast::Il(ast)
            }
            Language::Net => {
                // Warnings (an element of another tool skipped) do not stop
                // the net; `alba check` of the file shows them.
                let (net, d) = alba_net::load(src.file, text);
                diags.extend(d.into_iter().filter(|d| !alba_net::is_warning(d)));
                if let Some(net) = &net {
                    uses.addresses.extend(petri::addresses(net, src.file));
                }
                Ast::Net(net.map(Box::new))
            }
            Language::Sfc => match alba_net::sfc::parse(src.file, text) {
                Ok(sfc) => {
                    let net = sfc.to_net(&petri::net_name(&src.name), src.file);
                    uses.addresses.extend(petri::addresses(&net, src.file));
                    Ast::Sfc(Some(Box::new(sfc)))
                }
                Err(d) => {
                    diags.extend(d);
                    Ast::Sfc(None)
                }
            },
            Language::St => {
                let (ast, d) = alba_st::parse(text, src.file);
                diags.extend(d);
                Ast::St(ast)
            }
        };
        asts.push((src, ast));
    }
    // The FUNCTIONs, FUNCTION_BLOCKs and TYPEs of every `.st` file are known
    // in the others: each file's library is the other `.st` files.
    let st_files: Vec<&alba_st::File> = asts
        .iter()
        .filter_map(|(_, a)| if let Ast::St(f) = a { Some(f) } else { None })
        .collect();
    // Each place's marking is a DINT tag `<net>.<place>`, after the tags of
    // tags.csv so that theirs do not move.
    let mut tags = project.tags.clone();
    for (src, ast) in &asts {
        match ast {
            Ast::Net(Some(net)) => net_tags(net, &petri::net_name(&src.name), &mut tags, &mut diags),
            Ast::Sfc(Some(sfc)) => sfc::tags(sfc, &petri::net_name(&src.name), src.file, &mut tags, &mut diags),
            Ast::St(file) => alba_st::declare_with(file, &others(&st_files, file), &mut tags, &mut diags),
            _ => {}
        }
    }
    let mut b = Builder::new(Layout::new(&tags, &uses));
    let mut presets = alba_ladder::Presets::default();
    let dialect = match project.config.as_ref().map(|c| c.ladder_dialect) {
        Some(alba_project::config::LadderDialect::AuroraLd) => alba_ladder::Dialect::AuroraLd,
        _ => alba_ladder::Dialect::Logix,
    };
    let mut shared = alba_il::Shared::default();
    for (src, ast) in &asts {
        if src.plant {
            b.begin_plant();
        }
        let text = project.files.text(src.file);
        diags.extend(match ast {
            Ast::Ladder(ast) => alba_ladder::compile_in(ast, text, &src.name, &mut b, &mut presets, dialect),
            Ast::Il(ast) => alba_il::compile(ast, &src.name, &mut b, &mut shared),
            Ast::Net(Some(net)) => compile_net(net, src.file, text, &src.name, &mut b),
            Ast::Net(None) | Ast::Sfc(None) => Vec::new(),
            Ast::Sfc(Some(sfc)) => sfc::compile(sfc, src.file, text, &src.name, &st_files, &mut b),
            Ast::St(file) => alba_st::compile_with(file, &others(&st_files, file), &src.name, &mut b),
        });
    }
    if let Some(cfg) = &project.config {
        for m in &cfg.models {
            if let Some(spec) = resolve_plant(&b, m, &mut diags) {
                b.add_plant(spec);
            }
        }
    }
    // `[modbus.tags]` names resolve against the layout the programs use.
    if let Some(tags) = project.config.as_ref().map(|c| &c.modbus_tags)
        && !tags.is_empty()
    {
        let mut layout = b.layout().clone();
        layout.plant = false;
        diags.extend(alba_modbus_proto::Map::build(&layout, tags).1);
    }
    // A FUNCTION_BLOCK of one `.st` file called from another is checked in
    // both: its errors are reported once.
    let mut seen = std::collections::HashSet::new();
    diags.retain(|d| seen.insert((d.code, d.message.clone(), d.primary.as_ref().map(|l| l.span))));
    if !diags.is_empty() {
        return (None, diags);
    }
    (Some(b.finish(project.files.clone())), diags)
}

/// Resolves the signals of a plant model: the input may be any number; the
/// output must be a number the model may write (an input, or an internal tag).
fn resolve_plant(
    b: &Builder,
    m: &alba_model::plant::PlantModel,
    diags: &mut Vec<Diagnostic>,
) -> Option<alba_ir::PlantSpec> {
    use alba_ir::{Access, Target};
    let layout = b.layout();
    let mut place = |(name, span): &(String, alba_diag::Span), output: bool| {
        let bad = |msg: String| Diagnostic::new(Code::PlantModel, msg, *span, "plant signal");
        match layout.resolve(name) {
            Ok(Target::Value { place, access }) if place.data_type().is_numeric() => {
                if output && (access == Access::ReadOnly || layout.is_output(place)) {
                    diags.push(bad(format!(
                        "a plant model cannot write `{name}`: it is {}",
                        if access == Access::ReadOnly {
                            "read-only"
                        } else {
                            "an output of the program"
                        }
                    )));
                    None
                } else {
                    Some(place)
                }
            }
            Ok(Target::Value { place, .. }) => {
                diags.push(bad(format!(
                    "`{name}` is {}, not a number",
                    place.data_type().with_article()
                )));
                None
            }
            Ok(_) => {
                diags.push(bad(format!("`{name}` is a structure; name a member")));
                None
            }
            Err(e) => {
                diags.push(bad(e.to_string()));
                None
            }
        }
    };
    let input = place(&m.input, false);
    let output = place(&m.output, true);
    Some(alba_ir::PlantSpec {
        model: m.clone(),
        input: input?,
        output: output?,
    })
}
