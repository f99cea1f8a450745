//! The property the fuzz targets (`fuzz/fuzz_targets/import_*.rs`) and the
//! mutation test (`tests/fuzz.rs`) check on any input: no panic; an error
//! names a place inside the input; a success is a project whose every file
//! is there and whose rungs all come from somewhere.

use crate::{Format, Options};
use std::path::Path;

/// Converts `data` as `format` and checks the result; `Err` says what is
/// wrong (a panic inside is the other failure).
pub fn check(format: Format, data: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(data);
    let name = match format {
        Format::Ldmicro => "fuzz.ld",
        Format::Plcopen => "fuzz.xml",
        Format::L5x => "fuzz.L5X",
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
