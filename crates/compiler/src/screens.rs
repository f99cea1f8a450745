//! SCADA screens against a compiled program (issue 17): what a name holds for
//! a screen, and the check of every `hmi/*.json` of a project folder, for
//! `alba check` and the API alike.

use alba_diag::{Diagnostic, Files};
use alba_ir::{Access, Layout, Target};
use alba_model::DataType;
use alba_project::hmi::{self, TagKind};
use std::path::Path;

/// What `name` holds in the program of `layout`: a BOOL, a number or a
/// structure, and whether a screen may write it (not an input, not read-only).
pub fn resolver(layout: &Layout) -> impl Fn(&str) -> Result<(TagKind, bool), String> + '_ {
    move |name: &str| match layout.resolve(name) {
        Ok(Target::Value { place, access }) => {
            let kind = if place.data_type() == DataType::Bool {
                TagKind::Bool
            } else {
                TagKind::Number
            };
            Ok((kind, access == Access::ReadWrite))
        }
        Ok(_) => Ok((TagKind::Structure, false)),
        Err(e) => Err(e.to_string()),
    }
}

/// Checks every screen of the project in `dir` (`hmi/*.json`, in name
/// order) and every user symbol (`hmi/symbols/*.json`), adding their texts
/// to `files`; returns how many screens there are and the problems of all.
/// `alarms` are the ids of alarms.csv, which alarm indicators may name.
pub fn check_dir(dir: &Path, files: &mut Files, layout: &Layout, alarms: &[String]) -> (usize, Vec<Diagnostic>) {
    let json_files = |d: &Path| -> Vec<_> {
        let mut paths: Vec<_> = std::fs::read_dir(d)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.is_file() && p.extension().is_some_and(|x| x == "json"))
            .collect();
        paths.sort();
        paths
    };
    let hmi = dir.join("hmi");
    let mut paths = json_files(&hmi);
    let screens = paths.len();
    paths.extend(json_files(&hmi.join("symbols")));
    let resolve = resolver(layout);
    let mut diags = Vec::new();
    for p in &paths {
        let name = p.strip_prefix(dir).unwrap_or(p).to_string_lossy().into_owned();
        match std::fs::read_to_string(p) {
            Ok(text) => {
                let f = files.add(name, text.clone());
                diags.extend(hmi::parse(&text, f, &resolve, &|id: &str| alarms.iter().any(|a| a == id)).1);
            }
            Err(e) => diags.push(Diagnostic::unplaced(
                alba_diag::Code::Io,
                format!("cannot read {}: {e}", p.display()),
            )),
        }
    }
    (screens, diags)
}
