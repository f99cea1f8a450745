//! Reads an Alba project folder — `alba.toml`, `tags.csv`, `users.toml` and
//! the program files — and compiles it ([`compile_dir`]). The TOML reader
//! sits here, above the compiler (ADR 0014): `alba-project` holds the
//! project's tables with their serde forms and checks, `alba-settings` the
//! services' tables and users.toml; this crate parses the text and checks
//! both, so `alba check` reports every problem of the file.

use alba_compiler::Compiled;
use alba_diag::{Code, Diagnostic, FileId, Files, Span};
use alba_model::TagTable;
use alba_project::config::{Config, RawConfig};
use alba_project::{Language, ProgramSource, Project, read_text};
use alba_settings::{Settings, users};
use std::collections::HashSet;
use std::path::Path;

#[cfg(test)]
mod project_tests;
#[cfg(test)]
mod tests;

/// Loads and compiles the project in `dir`, reporting every problem of every file.
pub fn compile_dir(dir: &Path) -> Compiled {
    let (project, diagnostics) = load(dir);
    alba_compiler::compile_loaded(project, diagnostics)
}

/// Parses and validates `alba.toml`, reporting every problem found, in the
/// project's tables and in the services' (`alba-settings`). The config is
/// `None` only when the file could not be read as settings at all; with bad
/// values it is returned (with defaults in their place) so the rest of the
/// project is still checked.
pub fn parse(text: &str, file: FileId) -> (Option<Config>, Vec<Diagnostic>) {
    let (config, _, diags) = parse_both(text, file);
    (config, diags)
}

/// The project's tables and the services', with the problems of both.
pub fn parse_both(text: &str, file: FileId) -> (Option<Config>, Option<Settings>, Vec<Diagnostic>) {
    let raw: RawConfig = match toml::from_str(text) {
        Ok(r) => r,
        Err(e) => return (None, None, vec![alba_settings::toml_error(&e, file)]),
    };
    let (config, mut diags) = Config::check(raw, file);
    let (settings, d) = Settings::parse(text, file);
    diags.extend(d);
    (Some(config), settings, diags)
}

/// Loads `dir`, returning the project and all diagnostics.
pub fn load(dir: &Path) -> (Project, Vec<Diagnostic>) {
    let mut files = Files::new();
    let mut diags = Vec::new();
    let display = |name: &str| dir.join(name).display().to_string();

    let config = match read_text(&dir.join("alba.toml")) {
        Ok(text) => {
            let f = files.add(display("alba.toml"), text);
            let (config, settings, d) = parse_both(files.text(f), f);
            diags.extend(d);
            config.map(|c| (c, settings, f))
        }
        Err(msg) => {
            diags.push(Diagnostic::unplaced(Code::Io, msg.to_string()).with_help(
                "a project folder holds alba.toml, tags.csv and its programs; `alba new <dir>` creates one",
            ));
            None
        }
    };

    let (tags, tags_file) = match read_text(&dir.join("tags.csv")) {
        Ok(text) => {
            let f = files.add(display("tags.csv"), text);
            let (tags, d) = TagTable::parse(files.text(f), f);
            diags.extend(d);
            (tags, Some(f))
        }
        Err(msg) => {
            diags.push(Diagnostic::unplaced(Code::Io, msg.to_string()));
            (TagTable::new(), None)
        }
    };

    let mut programs = Vec::new();
    if let Some((cfg, _, _)) = &config {
        let mut seen = HashSet::new();
        let listed = cfg.programs.iter().map(|p| (p, false));
        for ((name, span), plant) in listed.chain(cfg.plant.iter().map(|p| (p, true))) {
            if let Some(d) = check_program_entry(name, *span, &mut seen) {
                diags.push(d);
                continue;
            }
            let Some(language) = Language::from_path(name) else {
                diags.push(
                    Diagnostic::new(
                        Code::ProgramFile,
                        format!("`{name}` has no known program extension"),
                        *span,
                        "unknown extension",
                    )
                    .with_help("ladder programs end in .lad, Instruction List programs in .awl, nets in .pnml, charts in .sfc, Structured Text in .st"),
                );
                continue;
            };
            match read_text(&dir.join(name)) {
                Ok(text) => {
                    let file = files.add(display(name), text);
                    programs.push(ProgramSource {
                        name: name.clone(),
                        language,
                        file,
                        plant,
                    });
                }
                Err(msg) => diags.push(Diagnostic::new(
                    Code::ProgramFile,
                    msg.to_string(),
                    *span,
                    "listed here",
                )),
            }
        }
    }
    if let Some(board) = config.as_ref().and_then(|(c, _, _)| c.board.as_ref()) {
        for tag in tags.iter() {
            let Some(Err(why)) = tag.address.and_then(|a| board.map.pin_of(board.model, a)) else {
                continue;
            };
            let why = why.split_once(' ').map_or(why.clone(), |(_, rest)| rest.to_string());
            let text = tag.address_text.as_deref().unwrap_or("");
            diags.push(
                Diagnostic::new(
                    Code::BoardPin,
                    format!("`{}` ({text}) {why}", tag.name),
                    tag.span,
                    format!("no pin on the {}", board.model.title()),
                )
                .with_help("see [board] in alba.toml and docs/file-formats.md for the pin maps"),
            );
        }
    }
    // users.toml is optional; when present it is checked with the rest.
    let users_path = dir.join(users::USERS_FILE);
    let mut has_users = false;
    let mut warnings = Vec::new();
    if users_path.exists() {
        match read_text(&users_path) {
            Ok(text) => {
                let f = files.add(display(users::USERS_FILE), text);
                let (users, d) = users::parse_users(files.text(f), f);
                has_users = !users.is_empty();
                diags.extend(d);
                warnings.extend(users::permission_warning(&users_path));
            }
            Err(msg) => diags.push(Diagnostic::unplaced(Code::Io, msg.to_string())),
        }
    }
    if let Some((_, Some(s), _)) = &config {
        let opcua_users = s.opcua.as_ref().is_some_and(|o| !o.users.is_empty());
        diags.extend(users::opcua_listen_needs_users(s, has_users || opcua_users));
        warnings.extend(users::opcua_users_warning(s));
    }
    let project = Project {
        warnings,
        dir: dir.to_path_buf(),
        files,
        config_file: config.as_ref().map(|(_, _, f)| *f),
        config: config.map(|(c, _, _)| c),
        tags,
        tags_file,
        programs,
    };
    (project, diags)
}

/// Program entries are relative paths inside the project, listed once.
fn check_program_entry(name: &str, span: Span, seen: &mut HashSet<String>) -> Option<Diagnostic> {
    use std::path::Component;
    let p = Path::new(name);
    if name.trim().is_empty()
        || p.is_absolute()
        || p.components()
            .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Some(Diagnostic::new(
            Code::ProgramFile,
            format!("`{name}` leaves the project folder"),
            span,
            "expected a path inside the project, like main.lad or programs/main.lad",
        ));
    }
    let normal: Vec<String> = p
        .components()
        .filter(|c| matches!(c, Component::Normal(_)))
        .map(|c| c.as_os_str().to_string_lossy().to_ascii_lowercase())
        .collect();
    if !seen.insert(normal.join("/")) {
        return Some(Diagnostic::new(
            Code::ProgramFile,
            format!("`{name}` is listed twice"),
            span,
            "repeated program",
        ));
    }
    None
}
