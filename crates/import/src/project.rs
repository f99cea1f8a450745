//! The converted project in memory ([`Project`]: tags, programs, board,
//! screens, alarms, trends) and its atomic write into a folder
//! ([`write_project`]: staged beside the target, synced, renamed).

use crate::{Error, Location};
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Distinguishes the temporary folders of conversions running at once.
pub(crate) static SEQ: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

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

    pub(crate) fn origin(&self, line: usize) -> Option<&Location> {
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
pub(crate) fn base_tag(name: &str) -> &str {
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

pub(crate) fn stage(project: &Project, tmp: &Path) -> io::Result<()> {
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
