//! The property the fuzz targets (`fuzz/fuzz_targets/import_*.rs`) and the
//! mutation test (`tests/fuzz.rs`) check on any input: no panic; an error
//! names a place inside the input; a success is a project whose every file
//! is there and whose rungs all come from somewhere.
//!
//! An AuroraLD folder is fuzzed as one text, its files each after a line
//! `==> name <==` ([`crate::aurora::Folder::join`]).

use crate::aurora::Folder;
use crate::{Format, Location, Options};
use std::path::Path;

/// Converts `data` as `format` and checks the result; `Err` says what is
/// wrong (a panic inside is the other failure).
pub fn check(format: Format, data: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(data);
    let name = match format {
        Format::Ldmicro => "fuzz.ld",
        Format::Plcopen => "fuzz.xml",
        Format::L5x => "fuzz.L5X",
        Format::Aurora => return check_folder(&Folder::split(&text)),
    };
    let opts = Options {
        format: Some(format),
        board: if format == Format::Ldmicro {
            Some("uno".into())
        } else {
            None
        },
        force: false,
    };
    let lines = text.split('\n').count() as u32;
    match crate::convert(Path::new(name), &text, &opts) {
        Err(e) => {
            if let Some(l) = &e.location
                && (l.file != name || l.line == 0 || l.line > lines || l.col == 0)
            {
                return Err(format!("error outside the input ({lines} lines): {e}"));
            }
            Ok(())
        }
        Ok((project, report)) => {
            if project.programs.is_empty() {
                return Err("a project without programs".into());
            }
            for e in &report.entries {
                let l = &e.location;
                if l.file == name && (l.line == 0 || l.line > lines) {
                    return Err(format!("report entry outside the input ({lines} lines): {e}"));
                }
            }
            let files = project.files();
            if !files.iter().any(|(f, _)| f == "alba.toml") || !files.iter().any(|(f, _)| f == "tags.csv") {
                return Err("alba.toml or tags.csv missing".into());
            }
            Ok(())
        }
    }
}

/// [`check`] for an AuroraLD folder: every place is inside one of its files.
fn check_folder(folder: &Folder) -> Result<(), String> {
    let lines = |file: &str| -> Option<u32> {
        let text = match file {
            crate::aurora::MAIN => folder.main.as_ref(),
            crate::aurora::TAGS => folder.tags.as_ref(),
            crate::aurora::INSTRUCTIONS => folder.instructions.as_ref(),
            crate::aurora::TRENDS => folder.trends.as_ref(),
            f => folder.screens.iter().find(|(n, _)| n == f).map(|(_, t)| t),
        }?;
        Some(text.split('\n').count() as u32)
    };
    let inside = |l: &Location| lines(&l.file).is_some_and(|n| l.line >= 1 && l.line <= n && l.col >= 1);
    match crate::convert_folder("fuzz", folder, &Options::default()) {
        Err(e) => match &e.location {
            Some(l) if !inside(l) => Err(format!("error outside the input: {e}")),
            _ => Ok(()),
        },
        Ok((project, report)) => {
            if project.programs.is_empty() {
                return Err("a project without programs".into());
            }
            for e in &report.entries {
                // tags.csv rows the check drops are placed at the tags file's first line.
                if !inside(&e.location) && e.location.line != 1 {
                    return Err(format!("report entry outside the input: {e}"));
                }
            }
            Ok(())
        }
    }
}
