//! A loaded project folder: `alba.toml`'s project tables, `tags.csv` and
//! the program files (read by `alba_load::load`).

use crate::config::Config;
use alba_diag::{Diagnostic, FileId, Files};
use alba_model::TagTable;
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
    /// The file `alba.toml` was read from (`None` if it could not be read):
    /// `alba-settings` reads the services' tables from its text.
    pub config_file: Option<FileId>,
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
}

/// Why a file of the project could not be read as text.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("cannot read {}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("cannot read {}: not UTF-8 text (invalid byte at offset {offset})", path.display())]
    NotUtf8 { path: PathBuf, offset: usize },
}

/// Reads a text file of the project: UTF-8, with a leading byte-order mark
/// (as Notepad writes) dropped so columns count from the first real character.
pub fn read_text(path: &Path) -> Result<String, ReadError> {
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut text = String::from_utf8(bytes).map_err(|e| ReadError::NotUtf8 {
        path: path.to_path_buf(),
        offset: e.utf8_error().valid_up_to(),
    })?;
    if text.starts_with('\u{feff}') {
        text.drain(..3);
    }
    Ok(text)
}
