//! `alba import`: converts programs written with other tools into a complete
//! Alba project (SPEC §3.3, issue 21).
//!
//! Four formats, each with its own module:
//!
//! - [`ldmicro`]: LDmicro's text format (`LDmicro0.1` / `LDmicro0.2`), with
//!   the I/O list wired to an Arduino board's pins or to plain DI/DO tags;
//! - [`plcopen`]: PLCopen TC6 XML v2.01 LD bodies (OpenPLC editor, Beremiz);
//! - [`l5x`]: Studio 5000 `.L5X` exports (tags, RLL routines in neutral text);
//! - [`aurora`]: AuroraLD Studio project folders (`main.ara`, `tags.pl`,
//!   `instructions.pl`, `trends.pl`, `.pcs` screens).
//!
//! Every importer reads its whole input first and converts it into a
//! [`Project`] in memory together with a [`Report`] of what was converted,
//! approximated or refused, each entry with its place in the source. Only a
//! complete conversion is written, into a temporary folder beside the target
//! that is synced and renamed into place, so an error never leaves a
//! half-written project. Malformed input is an [`Error`] naming
//! `file:line:col`; nothing here panics on input.

use std::fmt;
use std::fs;
use std::path::{Path, PathBuf};

pub mod aurora;
mod circuit;
pub mod export;
#[doc(hidden)]
pub mod fuzz;
pub mod l5x;
pub mod ldmicro;
mod names;
pub mod plcopen;
mod project;
mod report;

use project::{SEQ, base_tag, stage};

pub use project::{
    AlarmOut, BoardOut, ElementOut, PenOut, ProgramOut, Project, ScreenOut, TagOut, TrendsOut, write_project,
};
pub use report::{Entry, Error, Kind, Location, Report};

/// What an imported XML document may hold: deeper nesting than PNML (PLCopen
/// bodies nest), and no doctype at all.
pub(crate) const XML_LIMITS: alba_xml::Limits = alba_xml::Limits {
    max_depth: 128,
    max_elements: 1_000_000,
    refuse_doctype: true,
};

/// The largest input file read (a hostile or mistaken multi-gigabyte file is
/// refused before it is read).
pub const MAX_INPUT_BYTES: u64 = 32 * 1024 * 1024;

/// The most rung text a conversion writes: beyond it the input is refused
/// (a small hostile file must not make a huge project).
pub(crate) const MAX_OUTPUT_BYTES: usize = 64 * 1024 * 1024;

pub use export::export_plcopen;

/// Stack of the conversion thread (see [`convert`]).
const CONVERT_STACK_BYTES: usize = 256 * 1024 * 1024;

/// The formats `alba import` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// LDmicro `.ld` text files.
    Ldmicro,
    /// PLCopen TC6 XML v2.01 (`plc.xml` of the OpenPLC editor, Beremiz).
    Plcopen,
    /// Studio 5000 `.L5X` exports.
    L5x,
    /// AuroraLD Studio project folders (or their `main.ara`).
    Aurora,
}

impl Format {
    pub const ALL: [Format; 4] = [Format::Ldmicro, Format::Plcopen, Format::L5x, Format::Aurora];

    /// The name used by `--format`.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ldmicro => "ldmicro",
            Format::Plcopen => "plcopen",
            Format::L5x => "l5x",
            Format::Aurora => "aurora",
        }
    }

    /// Parses a `--format` value (case-insensitive).
    pub fn parse(s: &str) -> Option<Format> {
        Format::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(s.trim()))
    }

    fn title(self) -> &'static str {
        match self {
            Format::Ldmicro => "LDmicro",
            Format::Plcopen => "PLCopen TC6 XML",
            Format::L5x => "Studio 5000 L5X",
            Format::Aurora => "AuroraLD Studio",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Sniffs the format from the content first, then from the extension.
pub fn detect(path: &Path, text: &str) -> Option<Format> {
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if t.starts_with("LDmicro") {
        return Some(Format::Ldmicro);
    }
    if t.starts_with(aurora::MAIN_HEADER) {
        return Some(Format::Aurora);
    }
    if t.starts_with('<') {
        let head: String = t.chars().take(4096).collect();
        if head.contains("<RSLogix5000Content") {
            return Some(Format::L5x);
        }
        if head.contains("plcopen.org/xml/tc6") || head.contains("<project") {
            return Some(Format::Plcopen);
        }
    }
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "ld" => Some(Format::Ldmicro),
        "l5x" => Some(Format::L5x),
        "xml" => Some(Format::Plcopen),
        "ara" => Some(Format::Aurora),
        _ => None,
    }
}

/// What `import` is asked to do.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// The input's format; `None`: [`detect`] it.
    pub format: Option<Format>,
    /// An Arduino board (`uno`, `nano`, `mega`) to wire the I/O to (LDmicro),
    /// written as `[board]` in alba.toml; `None`: plain DI/DO tags.
    pub board: Option<String>,
    /// Replace the files of an existing, non-empty project folder.
    pub force: bool,
}

/// Reads an input file as text (UTF-8, or Latin-1 when it is not UTF-8, as
/// older Windows tools write), refusing files above [`MAX_INPUT_BYTES`].
pub fn read_input(input: &Path) -> Result<String, Error> {
    read_input_within(input, MAX_INPUT_BYTES)
}

/// [`read_input`] with its own bound, `max` bytes: never more is read, even
/// from a file that grows while it is read.
pub(crate) fn read_input_within(input: &Path, max: u64) -> Result<String, Error> {
    use std::io::Read;
    let cannot = |e: std::io::Error| Error::plain(format!("cannot read {}: {e}", input.display()));
    let meta = fs::metadata(input).map_err(cannot)?;
    if !meta.is_file() {
        return Err(Error::plain(format!("{} is not a file", input.display())));
    }
    let too_big = |len: u64| {
        Error::plain(format!(
            "{} is {len} bytes; files above {} are refused",
            input.display(),
            if max >= 1024 * 1024 {
                format!("{} MiB", max / (1024 * 1024))
            } else {
                format!("{max} bytes")
            }
        ))
    };
    if meta.len() > max {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::new();
    fs::File::open(input)
        .and_then(|f| f.take(max + 1).read_to_end(&mut bytes))
        .map_err(cannot)?;
    if bytes.len() as u64 > max {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    })
}

/// Converts `text` (the contents of `input`) into a project in memory. An
/// AuroraLD project is a folder: `input` is its `main.ara` (whose text is
/// `text`), and the other files are read beside it.
pub fn convert(input: &Path, text: &str, opts: &Options) -> Result<(Project, Report), Error> {
    let file = input
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| input.display().to_string());
    let format = match opts.format {
        Some(f) => f,
        None => detect(input, text).ok_or_else(|| {
            Error::at(
                Location::new(&file, 1, 1),
                "cannot tell the format: not LDmicro (`LDmicro0.1` first line), PLCopen XML (`<project>`), \
                 L5X (`<RSLogix5000Content>`) or an AuroraLD main.ara (`//PROJECT NAME`); give it with --format",
            )
        })?,
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if format == Format::Aurora {
        let dir = parent_dir(input);
        let mut folder = aurora::Folder::read(&dir)?;
        folder.main = Some(text.to_string());
        return convert_folder(&folder_name(&dir), &folder, opts);
    }
    let stem = input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "imported".to_string());
    run(format, &file, &file, || match format {
        Format::Ldmicro => ldmicro::convert(&file, &stem, text, opts),
        Format::Plcopen => plcopen::convert(&file, &stem, text, opts),
        Format::L5x => l5x::convert(&file, &stem, text, opts),
        Format::Aurora => Err(Error::plain("an AuroraLD project is a folder")),
    })
}

/// Converts an AuroraLD project folder, read into memory, named `name`.
pub fn convert_folder(name: &str, folder: &aurora::Folder, opts: &Options) -> Result<(Project, Report), Error> {
    run(Format::Aurora, name, aurora::TAGS, || {
        aurora::convert(name, folder, opts)
    })
}

/// The folder a file is in (`.` for a bare file name).
fn parent_dir(file: &Path) -> PathBuf {
    match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn folder_name(dir: &Path) -> String {
    let abs = fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    abs.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "imported".into())
}

/// Runs a converter and checks its project (see [`check`]); `file` names the
/// input, `tags_file` the file whose rows the tags come from.
fn run(
    format: Format,
    file: &str,
    tags_file: &str,
    job: impl FnOnce() -> Result<(Project, Report), Error> + Send,
) -> Result<(Project, Report), Error> {
    // The converters walk nested circuits and connection graphs recursively
    // (their depth is capped); a thread with a large stack makes the caps,
    // not the caller's stack size, the limit.
    let converted = std::thread::scope(|s| {
        let job = std::thread::Builder::new()
            .name("alba-import".into())
            .stack_size(CONVERT_STACK_BYTES)
            .spawn_scoped(s, || {
                let (mut project, mut report) = job()?;
                check(&mut project, &mut report, tags_file)?;
                Ok::<_, Error>((project, report))
            })
            .map_err(|e| Error::plain(format!("cannot start the conversion: {e}")))?;
        job.join()
            .map_err(|_| Error::plain(format!("the conversion of {file} failed unexpectedly")))?
    });
    let (mut project, mut report) = converted?;
    if project.name.trim().is_empty() {
        project.name = "imported".into();
    }
    if project.description.is_empty() {
        project.description = format!("imported from {file} ({}) by alba import", format.title());
    }
    report.format = Some(format);
    report.tags = project.tags.len();
    report.rungs = project.programs.iter().map(|p| count_rungs(&p.text)).sum();
    Ok((project, report))
}

/// Checks the converted project with Alba's own compiler, as `alba check`
/// does. A rung Alba refuses (an instruction or operand the conversion could
/// not judge, literals that clash across programs …) is turned into a
/// comment and reported as refused at its place in the source; a tag whose
/// initial value or address is refused loses it (approximated). Repeated
/// until the project checks.
fn check(project: &mut Project, report: &mut Report, file: &str) -> Result<(), Error> {
    let whole = Location::new(file, 1, 1);
    // The first error of the last check, for the message when it never passes.
    let mut last = String::new();
    for round in 0..16 {
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let seq = SEQ.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = std::env::temp_dir().join(format!(
            "alba-import-check-{}-{stamp}-{seq}-{round}",
            std::process::id()
        ));
        let staged = stage(project, &tmp);
        let compiled = staged.map(|()| {
            let c = alba_load::compile_dir(&tmp);
            // Screens are checked against the compiled program, as `alba check` does.
            let mut screen_diags: Vec<(String, String)> = Vec::new();
            if let Some(prog) = c.program.as_ref().filter(|_| !project.screens.is_empty()) {
                let mut files = c.project.files.clone();
                let ids: Vec<String> = project.alarms.iter().map(|a| a.id.clone()).collect();
                let (_, d) = alba_compiler::screens::check_dir(&tmp, &mut files, &prog.layout, &ids);
                for d in d {
                    let name = d
                        .primary
                        .as_ref()
                        .map(|l| files.name(l.span.file).replace('\\', "/"))
                        .unwrap_or_default();
                    screen_diags.push((name, format!("error[{}]: {}", d.code, d.message)));
                }
            }
            (c, screen_diags)
        });
        let _ = fs::remove_dir_all(&tmp);
        let (c, screen_diags) =
            compiled.map_err(|e| Error::plain(format!("cannot check the converted project: {e}")))?;
        if c.diagnostics.is_empty() {
            if screen_diags.is_empty() {
                return Ok(());
            }
            drop_screen_elements(project, report, &whole, screen_diags);
            continue;
        }
        let files = c.files();
        if let Some(d) = c.diagnostics.first() {
            // Where in the project (not the staging folder) and what.
            last = match &d.primary {
                Some(l) => {
                    let name = files.name(l.span.file).replace('\\', "/");
                    let file = name.rsplit('/').next().unwrap_or(&name).to_string();
                    let (line, col) = files.line_col(l.span.file, l.span.start as usize);
                    format!("{file}:{line}:{col}: error[{}]: {}", d.code, d.message)
                }
                None => format!("error[{}]: {}", d.code, d.message),
            };
        }
        let mut rungs: Vec<(usize, usize, String)> = Vec::new();
        let mut tag_rows: Vec<(usize, String)> = Vec::new();
        for d in &c.diagnostics {
            let msg = format!("error[{}]: {}", d.code, d.message);
            let Some(l) = &d.primary else {
                return Err(Error::plain(format!("the converted project does not check: {msg}")));
            };
            let name = files.name(l.span.file).replace('\\', "/");
            let (line, _) = files.line_col(l.span.file, l.span.start as usize);
            let line = line.saturating_sub(1);
            let is = |f: &str| name == f || name.ends_with(&format!("/{f}"));
            if let Some(pi) = project.programs.iter().position(|p| is(&p.file)) {
                rungs.push((pi, line, msg));
            } else if is("tags.csv") && line >= 1 {
                tag_rows.push((line - 1, msg));
            } else {
                return Err(Error::plain(format!(
                    "the converted project does not check: {}",
                    d.short(files)
                )));
            }
        }
        let mut changed = false;
        rungs.sort();
        rungs.dedup_by(|a, b| a.0 == b.0 && a.1 == b.1);
        // An ST program is left out whole: commenting out one line of a
        // statement that spans several would change what the rest means.
        let mut st_out: Vec<usize> = Vec::new();
        // The first error of each, for the message when nothing is left.
        let mut st_first: Vec<(Location, String)> = Vec::new();
        // So is a chart whose ST action does not check.
        let in_action = |text: &str, line: usize| {
            let mut inside = false;
            for l in text.lines().take(line + 1) {
                let l = l.trim();
                if l.starts_with("ACTION ") && l.ends_with(':') {
                    inside = true;
                } else if l == "END_ACTION" {
                    inside = false;
                }
            }
            inside
        };
        for (pi, line, msg) in &rungs {
            let p = &project.programs[*pi];
            if p.file.ends_with(".st") || (p.file.ends_with(".sfc") && in_action(&p.text, *line)) {
                let loc = p.origin(*line).cloned().unwrap_or_else(|| whole.clone());
                report.push(Kind::Refused, loc.clone(), format!("`{}`: {msg}", p.file));
                if !st_out.contains(pi) {
                    st_out.push(*pi);
                    st_first.push((loc, format!("`{}` does not check in Alba ({msg})", p.file)));
                }
            }
        }
        for (pi, line, msg) in rungs {
            if st_out.contains(&pi) {
                continue;
            }
            let p = &mut project.programs[pi];
            let mut lines: Vec<String> = p.text.lines().map(str::to_string).collect();
            let Some(text) = lines.get(line).cloned() else { continue };
            if text.trim_start().starts_with("//") {
                continue;
            }
            let loc = p.origin(line).cloned().unwrap_or_else(|| whole.clone());
            report.push(
                Kind::Refused,
                loc,
                format!("`{}` does not check in Alba ({msg}); left out", text.trim()),
            );
            lines[line] = format!("// REFUSED by alba import: {} ({msg})", text.trim());
            p.text = lines.join("\n") + "\n";
            changed = true;
        }
        st_out.sort_unstable();
        for pi in st_out.into_iter().rev() {
            let p = project.programs.remove(pi);
            report.push(
                Kind::Refused,
                p.origin(0).cloned().unwrap_or_else(|| whole.clone()),
                format!("`{}` does not check in Alba; left out", p.file),
            );
            changed = true;
        }
        // What is left must run: not only ST files of FUNCTIONs, FUNCTION_BLOCKs
        // and TYPEs (a PLCopen import's library).
        let runs = |p: &ProgramOut| {
            !p.file.ends_with(".st")
                || alba_compiler::st::parse(&p.text, alba_diag::FileId(0))
                    .0
                    .pous
                    .iter()
                    .any(|u| u.kind == alba_compiler::st::ast::PouKind::Program)
        };
        if !project.programs.iter().any(runs)
            && let Some((loc, why)) = st_first.into_iter().next()
        {
            return Err(Error::at(loc, format!("nothing left to import: {why}")));
        }
        tag_rows.sort();
        tag_rows.dedup_by(|a, b| a.0 == b.0);
        for (row, msg) in tag_rows.into_iter().rev() {
            let Some(t) = project.tags.get_mut(row) else { continue };
            if !t.initial.is_empty() {
                report.push(
                    Kind::Approximated,
                    whole.clone(),
                    format!("tag `{}`: initial value `{}` dropped ({msg})", t.name, t.initial),
                );
                t.initial.clear();
            } else if !t.address.is_empty() {
                report.push(
                    Kind::Approximated,
                    whole.clone(),
                    format!("tag `{}`: address `{}` dropped ({msg})", t.name, t.address),
                );
                t.address.clear();
            } else {
                report.push(
                    Kind::Refused,
                    whole.clone(),
                    format!("tag `{}` left out ({msg})", t.name),
                );
                let gone = project.tags.remove(row).name;
                let on_it = |tag: &str| base_tag(tag).eq_ignore_ascii_case(&gone);
                for a in project.alarms.iter().filter(|a| on_it(&a.tag)) {
                    report.push(
                        Kind::Refused,
                        a.origin.clone(),
                        format!("alarm `{}` left out: its tag `{gone}` is", a.id),
                    );
                }
                project.alarms.retain(|a| !on_it(&a.tag));
                if let Some(t) = &mut project.trends {
                    t.pens.retain(|p| !on_it(&p.tag));
                }
            }
            changed = true;
        }
        if !changed {
            break;
        }
    }
    Err(Error::plain(format!(
        "the converted project does not check, even without the rungs Alba refuses: {last}"
    )))
}

/// Leaves out the screen elements `alba check` refuses (a message about an
/// element starts with its id in backquotes); a screen refused as a whole
/// goes with all its elements.
fn drop_screen_elements(project: &mut Project, report: &mut Report, whole: &Location, diags: Vec<(String, String)>) {
    for (file, msg) in diags {
        let Some(si) = project.screens.iter().position(|sc| file.ends_with(&sc.file)) else {
            continue;
        };
        let id = msg
            .split_once("]: `")
            .and_then(|(_, rest)| rest.split_once('`'))
            .map(|(id, _)| id.to_string());
        let screen = &mut project.screens[si];
        match id.and_then(|id| screen.elements.iter().position(|e| e.id == id)) {
            Some(ei) => {
                let e = screen.elements.remove(ei);
                report.push(
                    Kind::Refused,
                    e.origin,
                    format!("screen element `{}` left out of {} ({msg})", e.id, screen.file),
                );
            }
            None => {
                let sc = project.screens.remove(si);
                let at = sc
                    .elements
                    .first()
                    .map(|e| e.origin.clone())
                    .unwrap_or_else(|| whole.clone());
                report.push(Kind::Refused, at, format!("screen {} left out ({msg})", sc.file));
            }
        }
    }
}

/// Rungs of a generated ladder text (each ends with `;` on its own line end).
fn count_rungs(text: &str) -> usize {
    text.lines()
        .filter(|l| {
            let t = l.trim();
            !t.starts_with("//") && t.ends_with(';')
        })
        .count()
}

/// Imports `input` into the project folder `out_dir`.
///
/// Refuses an existing non-empty `out_dir` unless `opts.force`. The files
/// are written into a temporary folder beside `out_dir`, synced, then
/// renamed into place: on any error nothing is left behind.
pub fn import(input: &Path, out_dir: &Path, opts: &Options) -> Result<Report, Error> {
    let is_dir = input.is_dir();
    let main_ara = input.file_name().is_some_and(|n| n.eq_ignore_ascii_case(aurora::MAIN));
    if is_dir || (main_ara && opts.format.is_none_or(|f| f == Format::Aurora)) {
        if let Some(f) = opts.format.filter(|f| *f != Format::Aurora) {
            return Err(Error::plain(format!(
                "{} is a folder: only AuroraLD projects (--format aurora) are folders, not {f}",
                input.display()
            )));
        }
        let dir = if is_dir { input.to_path_buf() } else { parent_dir(input) };
        let folder = aurora::Folder::read(&dir)?;
        let (project, report) = convert_folder(&folder_name(&dir), &folder, opts)?;
        write_project(&project, out_dir, opts.force)?;
        return Ok(report);
    }
    let text = read_input(input)?;
    let (project, report) = convert(input, &text, opts)?;
    write_project(&project, out_dir, opts.force)?;
    Ok(report)
}
