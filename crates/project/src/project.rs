//! A project folder: `alba.toml`, `tags.csv` and the program files.

use crate::config::Config;
use alba_diag::{Code, Diagnostic, FileId, Files, Span};
use alba_model::TagTable;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// The language of a program file, from its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Language {
    /// `.lad`: Rockwell neutral text (SPEC §3.1).
    Ladder,
    /// `.awl`: Siemens S7-200 Instruction List (SPEC §4).
    Il,
    /// `.pnml`: a state net or Petri net (SPEC §5, §10.5; docs/nets.md).
    Net,
    /// `.sfc`: an IEC 61131-3 sequential function chart, textual form (docs/nets.md, SFC).
    Sfc,
    /// `.st`: IEC 61131-3 Structured Text POUs (docs/st.md).
    St,
}

impl Language {
    pub fn from_path(path: &str) -> Option<Language> {
        let ext = Path::new(path).extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "lad" => Some(Language::Ladder),
            "awl" => Some(Language::Il),
            "pnml" => Some(Language::Net),
            "sfc" => Some(Language::Sfc),
            "st" => Some(Language::St),
            _ => None,
        }
    }
}

#[derive(Debug, Clone)]
pub struct ProgramSource {
    /// As listed in `alba.toml`.
    pub name: String,
    pub language: Language,
    pub file: FileId,
    /// A plant model (listed under `plant`): it runs after the control
    /// programs, reads their outputs and writes the inputs.
    pub plant: bool,
}

/// A loaded project. Loading never stops at the first problem: what could be
/// read is here, and every problem found is in the diagnostics.
#[derive(Debug, Clone)]
pub struct Project {
    pub dir: PathBuf,
    pub files: Files,
    pub config: Option<Config>,
    pub tags: TagTable,
    /// The file the tag table was read from (`None` if it could not be read).
    pub tags_file: Option<FileId>,
    pub programs: Vec<ProgramSource>,
    /// Problems that do not stop the project (a deprecated setting): shown,
    /// never counted as errors.
    pub warnings: Vec<Diagnostic>,
}

impl Project {
    pub fn scan_ms(&self) -> u32 {
        self.config
            .as_ref()
            .map_or(crate::config::DEFAULT_SCAN_MS, |c| c.scan_ms)
    }

    /// Loads `dir`, returning the project and all diagnostics.
    pub fn load(dir: &Path) -> (Project, Vec<Diagnostic>) {
        let mut files = Files::new();
        let mut diags = Vec::new();
        let display = |name: &str| dir.join(name).display().to_string();

        let config = match read_text(&dir.join("alba.toml")) {
            Ok(text) => {
                let f = files.add(display("alba.toml"), text);
                let (config, d) = Config::parse(files.text(f), f);
                diags.extend(d);
                config.map(|c| (c, f))
            }
            Err(msg) => {
                diags.push(Diagnostic::unplaced(Code::Io, msg).with_help(
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
                diags.push(Diagnostic::unplaced(Code::Io, msg));
                (TagTable::new(), None)
            }
        };

        let mut programs = Vec::new();
        if let Some((cfg, _)) = &config {
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
                    Err(msg) => diags.push(Diagnostic::new(Code::ProgramFile, msg, *span, "listed here")),
                }
            }
        }
        if let Some(board) = config.as_ref().and_then(|(c, _)| c.board.as_ref()) {
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
        let users_path = dir.join(crate::users::USERS_FILE);
        let mut has_users = false;
        let mut warnings = Vec::new();
        if users_path.exists() {
            match read_text(&users_path) {
                Ok(text) => {
                    let f = files.add(display(crate::users::USERS_FILE), text);
                    let (users, d) = crate::users::parse_users(files.text(f), f);
                    has_users = !users.is_empty();
                    diags.extend(d);
                    warnings.extend(crate::users::permission_warning(&users_path));
                }
                Err(msg) => diags.push(Diagnostic::unplaced(Code::Io, msg)),
            }
        }
        if let Some((c, _)) = &config {
            let opcua_users = c.opcua.as_ref().is_some_and(|o| !o.users.is_empty());
            diags.extend(crate::users::opcua_listen_needs_users(c, has_users || opcua_users));
        }
        warnings.extend(config.as_ref().and_then(|(c, _)| crate::users::opcua_users_warning(c)));
        let project = Project {
            warnings,
            dir: dir.to_path_buf(),
            files,
            config: config.map(|(c, _)| c),
            tags,
            tags_file,
            programs,
        };
        (project, diags)
    }
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

/// Reads a text file of the project: UTF-8, with a leading byte-order mark
/// (as Notepad writes) dropped so columns count from the first real character.
pub fn read_text(path: &Path) -> Result<String, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut text = String::from_utf8(bytes).map_err(|e| {
        format!(
            "cannot read {}: not UTF-8 text (invalid byte at offset {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })?;
    if text.starts_with('\u{feff}') {
        text.drain(..3);
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("alba-model-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn loads_a_project_and_reports_missing_programs() {
        let d = tmp("load");
        std::fs::write(
            d.join("alba.toml"),
            "name = \"t\"\nprograms = [\"main.lad\", \"gone.lad\", \"x.st\", \"../up.lad\", \"main.lad\"]\n",
        )
        .unwrap();
        std::fs::write(d.join("tags.csv"), "name,type\nA,BOOL\n").unwrap();
        std::fs::write(d.join("main.lad"), "XIC(A)OTE(A);\n").unwrap();
        let (p, diags) = Project::load(&d);
        assert_eq!(p.programs.len(), 1);
        assert_eq!(p.tags.len(), 1);
        let codes: Vec<_> = diags.iter().map(|d| d.code).collect();
        assert_eq!(codes, [Code::ProgramFile; 4]);
        let short: Vec<_> = diags.iter().map(|x| x.short(&p.files)).collect();
        assert!(short[0].contains("alba.toml:2:25"), "{short:?}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn users_toml_is_checked_and_opcua_users_warned() {
        const HASH: &str = "$argon2id$v=19$m=8,t=1,p=1$YWxiYS10ZXN0LXNhbHQ$AAAAAAAAAAAAAAAAAAAAAA";
        let d = tmp("users");
        let toml = "name = \"t\"\nprograms = [\"main.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n";
        std::fs::write(d.join("alba.toml"), toml).unwrap();
        std::fs::write(d.join("tags.csv"), "name,type\nA,BOOL\n").unwrap();
        std::fs::write(d.join("main.lad"), "XIC(A)OTE(A);\n").unwrap();
        let short = |(p, diags): (Project, Vec<Diagnostic>)| -> Vec<String> {
            diags.iter().map(|x| x.short(&p.files)).collect()
        };
        // No users anywhere: a listener beyond loopback is refused.
        let e = short(Project::load(&d));
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(
            e[0].contains("alba.toml:4:10: error[E102]") && e[0].contains("needs users"),
            "{e:?}"
        );
        // A user in users.toml is enough; its errors are located.
        std::fs::write(
            d.join("users.toml"),
            format!("[users.op]\nrole = \"operator\"\npassword = \"{HASH}\"\n"),
        )
        .unwrap();
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let f = d.join("users.toml");
            std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o644)).unwrap();
            let (p, diags) = Project::load(&d);
            assert!(diags.is_empty(), "a users.toml open to others is a warning: {diags:?}");
            assert_eq!(p.warnings.len(), 1);
            assert!(p.warnings[0].render_warning(&p.files).contains("warning[E107]"));
            std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o600)).unwrap();
        }
        let (p, diags) = Project::load(&d);
        assert!(diags.is_empty() && p.warnings.is_empty(), "{diags:?}");
        std::fs::write(d.join("users.toml"), "[users.op]\nrole = \"god\"\npassword = \"x\"\n").unwrap();
        let e = short(Project::load(&d));
        assert_eq!(e.len(), 3, "{e:?}");
        assert!(e[0].contains("users.toml:2:8: error[E107]"), "{e:?}");
        // [opcua.users] still loads, with a warning that is not an error.
        std::fs::remove_file(d.join("users.toml")).unwrap();
        std::fs::write(d.join("alba.toml"), format!("{toml}[opcua.users]\nop = \"{HASH}\"\n")).unwrap();
        let (p, diags) = Project::load(&d);
        assert!(diags.is_empty(), "{diags:?}");
        assert_eq!(p.warnings.len(), 1);
        let w = p.warnings[0].render_warning(&p.files);
        assert!(w.contains("warning[E109]") && w.contains("alba user"), "{w}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn missing_folder_is_one_clear_error_per_file() {
        let (p, diags) = Project::load(Path::new("/nonexistent/alba"));
        assert!(p.config.is_none());
        assert_eq!(diags.len(), 2);
        assert!(diags[0].message.contains("cannot read /nonexistent/alba/alba.toml"));
    }
}
