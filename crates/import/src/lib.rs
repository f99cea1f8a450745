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
use std::io::{self, Write};
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

/// A place in an input file (line and column from 1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub file: String,
    pub line: u32,
    pub col: u32,
}

impl Location {
    pub fn new(file: &str, line: u32, col: u32) -> Location {
        Location {
            file: file.to_string(),
            line,
            col,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.col)
    }
}

/// How a construct of the source came across.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Converted with the same behaviour.
    Converted,
    /// Converted, but the behaviour differs in a documented way.
    Approximated,
    /// Not converted (the message says what was left out).
    Refused,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Converted => "converted",
            Kind::Approximated => "approximated",
            Kind::Refused => "refused",
        }
    }
}

/// One line of the report.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Entry {
    pub kind: Kind,
    pub location: Location,
    pub message: String,
}

impl fmt::Display for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}: {}", self.location, self.kind.name(), self.message)
    }
}

/// What was converted, approximated and refused, in source order.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Report {
    pub entries: Vec<Entry>,
    /// The format that was read.
    pub format: Option<Format>,
    /// Rungs written into the Alba programs.
    pub rungs: usize,
    /// Tags written into tags.csv.
    pub tags: usize,
}

impl Report {
    pub(crate) fn push(&mut self, kind: Kind, location: Location, message: impl Into<String>) {
        self.entries.push(Entry {
            kind,
            location,
            message: message.into(),
        });
    }

    pub fn count(&self, kind: Kind) -> usize {
        self.entries.iter().filter(|e| e.kind == kind).count()
    }

    /// The report as text, one entry a line.
    pub fn render(&self) -> String {
        let mut s = String::new();
        for e in &self.entries {
            s.push_str(&e.to_string());
            s.push('\n');
        }
        s
    }
}

/// Why an import failed. Nothing was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    /// The place in the input, when the input is at fault.
    pub location: Option<Location>,
    pub message: String,
}

impl Error {
    pub(crate) fn at(location: Location, message: impl Into<String>) -> Error {
        Error {
            location: Some(location),
            message: message.into(),
        }
    }

    pub(crate) fn plain(message: impl Into<String>) -> Error {
        Error {
            location: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.location {
            Some(l) => write!(f, "{l}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for Error {}

/// A tag of the generated tags.csv.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TagOut {
    pub name: String,
    pub ty: String,
    pub address: String,
    pub initial: String,
    pub description: String,
}

/// A generated program file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProgramOut {
    /// Relative to the project folder (`main.lad`).
    pub file: String,
    pub text: String,
    /// Where the lines come from: (line index from 0, place in the source).
    pub origins: Vec<(usize, Location)>,
    lines: usize,
}

impl ProgramOut {
    pub(crate) fn new(file: String) -> ProgramOut {
        ProgramOut {
            file,
            text: String::new(),
            origins: Vec::new(),
            lines: 0,
        }
    }

    /// Appends one line (a rung or a `//` comment) from `origin`.
    pub(crate) fn line(&mut self, text: &str, origin: Option<&Location>) {
        if let Some(o) = origin {
            self.origins.push((self.lines, o.clone()));
        }
        self.lines += 1;
        self.text.push_str(text);
        self.text.push('\n');
    }

    fn origin(&self, line: usize) -> Option<&Location> {
        self.origins.iter().find(|(l, _)| *l == line).map(|(_, o)| o)
    }
}

/// The `[board]` table of alba.toml: the model and every direction's pins.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BoardOut {
    pub model: String,
    pub di: Vec<String>,
    pub r#do: Vec<String>,
    pub ai: Vec<String>,
    pub ao: Vec<String>,
}

/// A converted project, before it is written.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Project {
    pub name: String,
    pub description: String,
    pub scan_ms: u32,
    pub board: Option<BoardOut>,
    pub tags: Vec<TagOut>,
    pub programs: Vec<ProgramOut>,
    /// SCADA screens (`hmi/<name>.json`).
    pub screens: Vec<ScreenOut>,
    /// Alarms (`alarms.csv`).
    pub alarms: Vec<AlarmOut>,
    /// The studio's trend set (`trends.json`).
    pub trends: Option<TrendsOut>,
}

/// A SCADA screen of the project (the format of docs/file-formats.md, "Screens").
#[derive(Debug, Clone, PartialEq)]
pub struct ScreenOut {
    /// Relative to the project folder (`hmi/main.json`).
    pub file: String,
    pub title: String,
    pub width: u32,
    pub height: u32,
    pub elements: Vec<ElementOut>,
}

/// An element of a screen: its JSON object and where it comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementOut {
    pub id: String,
    pub json: serde_json::Value,
    pub origin: Location,
}

/// A row of alarms.csv (docs/alarms.md).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AlarmOut {
    pub id: String,
    pub tag: String,
    pub condition: String,
    pub severity: String,
    pub message: String,
    pub origin: Location,
}

/// trends.json (docs/api.md, "Trends"): the live window and the pens.
#[derive(Debug, Clone, PartialEq)]
pub struct TrendsOut {
    pub window_ms: u64,
    pub pens: Vec<PenOut>,
}

/// A pen of trends.json: a tag or member, on axis 1, with a fixed scale or none.
#[derive(Debug, Clone, PartialEq)]
pub struct PenOut {
    pub tag: String,
    pub scale: Option<(f64, f64)>,
}

impl ScreenOut {
    fn json(&self) -> String {
        let screen = serde_json::json!({
            "schema": 1,
            "title": self.title,
            "width": self.width,
            "height": self.height,
            "elements": self.elements.iter().map(|e| e.json.clone()).collect::<Vec<_>>(),
        });
        serde_json::to_string_pretty(&screen).unwrap_or_default() + "\n"
    }
}

impl Project {
    /// alba.toml.
    pub fn alba_toml(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!("name = {}\n", toml_str(&self.name)));
        s.push_str(&format!("description = {}\n", toml_str(&self.description)));
        s.push_str(&format!("scan_ms = {}\n", self.scan_ms));
        let progs: Vec<String> = self.programs.iter().map(|p| toml_str(&p.file)).collect();
        s.push_str(&format!("programs = [{}]\n", progs.join(", ")));
        if let Some(b) = &self.board {
            s.push_str("\n[board]\n");
            s.push_str(&format!("model = {}\n", toml_str(&b.model)));
            for (key, pins) in [("di", &b.di), ("do", &b.r#do), ("ai", &b.ai), ("ao", &b.ao)] {
                let pins: Vec<String> = pins.iter().map(|p| toml_str(p)).collect();
                s.push_str(&format!("{key} = [{}]\n", pins.join(", ")));
            }
        }
        s
    }

    /// tags.csv.
    pub fn tags_csv(&self) -> String {
        let mut s = String::from("name,type,address,initial,retain,description\n");
        for t in &self.tags {
            let fields = [
                csv_field(&t.name),
                csv_field(&t.ty),
                csv_field(&t.address),
                csv_field(&t.initial),
                String::new(),
                csv_field(&t.description),
            ];
            s.push_str(&fields.join(","));
            s.push('\n');
        }
        s
    }

    /// Every file of the project: (relative path, contents).
    pub fn files(&self) -> Vec<(String, String)> {
        let mut v = vec![
            ("alba.toml".to_string(), self.alba_toml()),
            ("tags.csv".to_string(), self.tags_csv()),
        ];
        for p in &self.programs {
            v.push((p.file.clone(), p.text.clone()));
        }
        for sc in &self.screens {
            v.push((sc.file.clone(), sc.json()));
        }
        if !self.alarms.is_empty() {
            let mut a = String::from("id,tag,condition,severity,delay_ms,deadband,message\n");
            for r in &self.alarms {
                let fields = [
                    csv_field(&r.id),
                    csv_field(&r.tag),
                    csv_field(&r.condition),
                    csv_field(&r.severity),
                    "0".into(),
                    "0".into(),
                    csv_field(&r.message),
                ];
                a.push_str(&fields.join(","));
                a.push('\n');
            }
            v.push(("alarms.csv".into(), a));
        }
        if let Some(t) = &self.trends {
            let pens: Vec<serde_json::Value> = t
                .pens
                .iter()
                .map(|p| {
                    let (min, max) = match p.scale {
                        Some((a, b)) => (serde_json::json!(a), serde_json::json!(b)),
                        None => (serde_json::Value::Null, serde_json::Value::Null),
                    };
                    serde_json::json!({"tag": p.tag, "axis": 1, "min": min, "max": max})
                })
                .collect();
            let set = serde_json::json!({"version": 1, "window_ms": t.window_ms, "pens": pens});
            v.push((
                "trends.json".into(),
                serde_json::to_string_pretty(&set).unwrap_or_default() + "\n",
            ));
        }
        v
    }
}

/// The tag of a member (`T.DN` → `T`).
fn base_tag(name: &str) -> &str {
    name.split('.').next().unwrap_or(name)
}

fn toml_str(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn csv_field(f: &str) -> String {
    // Line breaks become spaces: a description is one line.
    let f = f.replace(['\r', '\n'], " ");
    if f.contains([',', '"']) || f.starts_with(' ') || f.ends_with(' ') {
        format!("\"{}\"", f.replace('"', "\"\""))
    } else {
        f
    }
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

/// Distinguishes the temporary folders of conversions running at once.
static SEQ: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Checks the converted project with Alba's own compiler, as `alba check`
/// does. A rung Alba refuses (an instruction or operand the conversion could
/// not judge, literals that clash across programs …) is turned into a
/// comment and reported as refused at its place in the source; a tag whose
/// initial value or address is refused loses it (approximated). Repeated
/// until the project checks.
fn check(project: &mut Project, report: &mut Report, file: &str) -> Result<(), Error> {
    let whole = Location::new(file, 1, 1);
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
            let c = alba_compiler::compile_dir(&tmp);
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
        for (pi, line, msg) in &rungs {
            let p = &project.programs[*pi];
            if p.file.ends_with(".st") {
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
        if project.programs.is_empty()
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
    Err(Error::plain(
        "the converted project does not check, even without the rungs Alba refuses",
    ))
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

/// Writes `project` into `out_dir` atomically (see [`import`]).
pub fn write_project(project: &Project, out_dir: &Path, force: bool) -> Result<(), Error> {
    let existing = match fs::read_dir(out_dir) {
        Ok(mut it) => Some(it.next().is_some()),
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => {
            return Err(Error::plain(format!("cannot use {}: {e}", out_dir.display())));
        }
    };
    if out_dir.exists() && !out_dir.is_dir() {
        return Err(Error::plain(format!(
            "{} exists and is not a folder",
            out_dir.display()
        )));
    }
    if existing == Some(true) && !force {
        return Err(Error::plain(format!(
            "{} exists and is not empty; use --force to replace its project files",
            out_dir.display()
        )));
    }
    let parent = match out_dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let base = out_dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "project".into());
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let seq = SEQ.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = parent.join(format!(".{base}.alba-import-{}-{stamp}-{seq}", std::process::id()));
    let staged = stage(project, &tmp);
    if let Err(e) = staged {
        let _ = fs::remove_dir_all(&tmp);
        return Err(Error::plain(format!("cannot write {}: {e}", tmp.display())));
    }
    let placed = match existing {
        // A new or empty folder: the staged folder takes its place whole.
        None | Some(false) => {
            if existing == Some(false) {
                let _ = fs::remove_dir(out_dir);
            }
            fs::rename(&tmp, out_dir)
        }
        // --force over an existing project: each file is renamed over its
        // old version (each rename atomic); other files stay.
        Some(true) => place_files(project, &tmp, out_dir),
    };
    let _ = sync_dir(&parent);
    match placed {
        Ok(()) => {
            let _ = fs::remove_dir_all(&tmp);
            Ok(())
        }
        Err(e) => {
            let _ = fs::remove_dir_all(&tmp);
            Err(Error::plain(format!("cannot write {}: {e}", out_dir.display())))
        }
    }
}

fn stage(project: &Project, tmp: &Path) -> io::Result<()> {
    fs::create_dir(tmp)?;
    for (rel, text) in project.files() {
        let path = tmp.join(&rel);
        if let Some(dir) = path.parent() {
            fs::create_dir_all(dir)?;
        }
        let mut f = fs::File::create(&path)?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
    }
    sync_dir(tmp)
}

fn place_files(project: &Project, tmp: &Path, out_dir: &Path) -> io::Result<()> {
    for (rel, _) in project.files() {
        let to = out_dir.join(&rel);
        if let Some(dir) = to.parent() {
            fs::create_dir_all(dir)?;
        }
        fs::rename(tmp.join(&rel), to)?;
    }
    sync_dir(out_dir)
}

fn sync_dir(dir: &Path) -> io::Result<()> {
    #[cfg(unix)]
    {
        fs::File::open(dir)?.sync_all()
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        Ok(())
    }
}
