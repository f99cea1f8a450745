//! AuroraLD Studio project folders (the thesis of `../shared/seeds/000_…`,
//! SPEC §3.3): a folder named after the project holding
//!
//! - `main.ara` — the project's name, time and date and the rail (§3.14,
//!   Fig. 205, Fig. 209);
//! - `tags.pl` — the program tags: name, variable, address, value,
//!   description (§3.6, Figs. 181–188);
//! - `instructions.pl` — the ladder: the counter of each of the 40
//!   instruction kinds, then the attributes of every instruction, kind after
//!   kind (§3.14, Figs. 206–211; the attributes of each class in §3.4);
//! - `trends.pl` — the trend environment: sample time, scales and up to 9
//!   pens (§3.18);
//! - `*.pcs` — SCADA screens (§3.19, §3.24).
//!
//! Every file is text, one value a line, in a fixed order ("se guardan en un
//! orden específico", §3.14): the readers here follow that order field by
//! field and refuse, with its line, the first value that does not fit. Where
//! the seed shows the order (main.ara, the instruction counters, XIC's 12
//! attributes, CTU's load) it is followed exactly; where it only lists a
//! class's attributes, they are read in the order listed. The layouts are in
//! docs/interchange.md, "AuroraLD", with each decision the seed leaves open.

mod ladder;
mod pcs;

use crate::names::Names;
use crate::{Error, Kind, Location, Options, PenOut, Project, Report, TagOut, TrendsOut};
use std::collections::HashMap;
use std::fs;
use std::path::Path;

pub const MAIN: &str = "main.ara";
pub const TAGS: &str = "tags.pl";
pub const INSTRUCTIONS: &str = "instructions.pl";
pub const TRENDS: &str = "trends.pl";
/// The first line of every main.ara (Fig. 205).
pub const MAIN_HEADER: &str = "//PROJECT NAME";

/// Screens read from one folder, at most.
const MAX_SCREENS: usize = 64;
/// One `.pcs` screen, at most (AuroraLD's are a few KB: at most 200 elements
/// of a few lines each).
pub const MAX_SCREEN_BYTES: u64 = 1024 * 1024;
/// The whole folder, at most: every file read, together.
pub const MAX_FOLDER_BYTES: u64 = 64 * 1024 * 1024;
/// AuroraLD's tag table holds 100 rows (Fig. 182, `num_tags = 100`).
const MAX_TAGS: i64 = 100;
/// The trend environment's pens (§3.18: "hasta un máximo de 9 variables").
const TREND_PENS: usize = 9;

/// The text files of an AuroraLD project folder.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Folder {
    pub main: Option<String>,
    pub tags: Option<String>,
    pub instructions: Option<String>,
    pub trends: Option<String>,
    /// `(file name, text)` of every `.pcs` screen, by name.
    pub screens: Vec<(String, String)>,
}

impl Folder {
    /// Reads the folder `dir`: main.ara first, which must be one (nothing
    /// else is read otherwise), then the other files, each within
    /// [`crate::MAX_INPUT_BYTES`] (a screen within [`MAX_SCREEN_BYTES`]) and
    /// all together within [`MAX_FOLDER_BYTES`], checked on their sizes
    /// before any is read.
    pub fn read(dir: &Path) -> Result<Folder, Error> {
        let entries = fs::read_dir(dir).map_err(|e| Error::plain(format!("cannot read {}: {e}", dir.display())))?;
        let mut names: Vec<String> = entries
            .flatten()
            .filter(|e| e.path().is_file())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let find = |want: &str| names.iter().find(|n| n.eq_ignore_ascii_case(want)).cloned();
        let Some(main) = find(MAIN) else {
            return Err(Error::plain(format!(
                "{} is not an AuroraLD project folder: it has no {MAIN}",
                dir.display()
            )));
        };
        let main = crate::read_input(&dir.join(main))?;
        read_main(&main, &mut Report::default())?;
        let others: Vec<Option<String>> = [TAGS, INSTRUCTIONS, TRENDS].iter().map(|f| find(f)).collect();
        let pcs: Vec<&String> = names
            .iter()
            .filter(|n| n.to_ascii_lowercase().ends_with(".pcs"))
            .collect();
        if pcs.len() > MAX_SCREENS {
            return Err(Error::plain(format!(
                "{} holds {} .pcs screens; at most {MAX_SCREENS} are read",
                dir.display(),
                pcs.len()
            )));
        }
        let mut total = main.len() as u64;
        for n in others.iter().flatten().chain(pcs.iter().copied()) {
            let path = dir.join(n);
            let len = fs::metadata(&path).map_or(0, |m| m.len());
            let is_screen = !others.iter().flatten().any(|o| o == n);
            if is_screen && len > MAX_SCREEN_BYTES {
                return Err(Error::plain(format!(
                    "{} is {len} bytes; screens above {} KiB are refused",
                    path.display(),
                    MAX_SCREEN_BYTES / 1024
                )));
            }
            total = total.saturating_add(len);
        }
        if total > MAX_FOLDER_BYTES {
            return Err(Error::plain(format!(
                "{} holds {total} bytes of project files; at most {} MiB are read",
                dir.display(),
                MAX_FOLDER_BYTES / (1024 * 1024)
            )));
        }
        let read = |name: &Option<String>| -> Result<Option<String>, Error> {
            name.as_ref().map(|n| crate::read_input(&dir.join(n))).transpose()
        };
        let mut folder = Folder {
            main: Some(main),
            tags: read(&others[0])?,
            instructions: read(&others[1])?,
            trends: read(&others[2])?,
            screens: Vec::new(),
        };
        let mut read_so_far: u64 = [&folder.main, &folder.tags, &folder.instructions, &folder.trends]
            .iter()
            .filter_map(|t| t.as_ref())
            .map(|t| t.len() as u64)
            .sum();
        for n in pcs {
            let text = crate::read_input_within(&dir.join(n), MAX_SCREEN_BYTES)?;
            read_so_far += text.len() as u64;
            if read_so_far > MAX_FOLDER_BYTES {
                return Err(Error::plain(format!(
                    "{} holds more than {} MiB of project files",
                    dir.display(),
                    MAX_FOLDER_BYTES / (1024 * 1024)
                )));
            }
            folder.screens.push((n.clone(), text));
        }
        Ok(folder)
    }

    /// The folder as one text, each file after a line `==> name <==` (the
    /// form `head` prints; the fuzz targets read it back with [`Folder::split`]).
    pub fn join(&self) -> String {
        let mut s = String::new();
        let mut add = |name: &str, text: &Option<String>| {
            if let Some(t) = text {
                s.push_str(&format!("==> {name} <==\n{t}"));
                if !t.ends_with('\n') {
                    s.push('\n');
                }
            }
        };
        add(MAIN, &self.main);
        add(TAGS, &self.tags);
        add(INSTRUCTIONS, &self.instructions);
        add(TRENDS, &self.trends);
        for (n, t) in &self.screens {
            add(n, &Some(t.clone()));
        }
        s
    }

    /// The inverse of [`Folder::join`]: text before the first `==>` line is
    /// ignored, unknown names are ignored, a repeated name keeps the last.
    pub fn split(text: &str) -> Folder {
        let mut f = Folder::default();
        let mut cur: Option<(String, String)> = None;
        let put = |f: &mut Folder, (name, text): (String, String)| match name.as_str() {
            MAIN => f.main = Some(text),
            TAGS => f.tags = Some(text),
            INSTRUCTIONS => f.instructions = Some(text),
            TRENDS => f.trends = Some(text),
            n if n.ends_with(".pcs") => match f.screens.iter().position(|(m, _)| *m == name) {
                Some(k) => f.screens[k].1 = text,
                None if f.screens.len() < MAX_SCREENS => f.screens.push((name, text)),
                None => {}
            },
            _ => {}
        };
        for line in text.split_inclusive('\n') {
            let head = line
                .trim_end()
                .strip_prefix("==> ")
                .and_then(|l| l.strip_suffix(" <=="));
            match head {
                Some(name) => {
                    if let Some(c) = cur.take() {
                        put(&mut f, c);
                    }
                    cur = Some((name.to_string(), String::new()));
                }
                None => {
                    if let Some((_, t)) = &mut cur {
                        t.push_str(line);
                    }
                }
            }
        }
        if let Some(c) = cur {
            put(&mut f, c);
        }
        f
    }
}

/// Each kind's array holds 200 objects: instructions (`new NO[200]`, Fig. 67; 200 rungs,
/// Fig. 61) and a screen's elements of each type.
pub(crate) const MAX_EACH: i64 = 200;

/// A text file read one value a line.
pub(crate) struct Reader<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    pos: usize,
}

impl<'a> Reader<'a> {
    pub fn new(file: &'a str, text: &'a str) -> Reader<'a> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines: Vec<&str> = text.split('\n').map(|l| l.strip_suffix('\r').unwrap_or(l)).collect();
        if lines.last() == Some(&"") {
            lines.pop();
        }
        Reader { file, lines, pos: 0 }
    }

    fn loc_of(&self, i: usize) -> Location {
        Location::new(self.file, u32::try_from(i + 1).unwrap_or(u32::MAX), 1)
    }

    /// The place of the next line (the last line once all are read).
    pub fn loc(&self) -> Location {
        self.loc_of(self.pos.min(self.lines.len().saturating_sub(1)))
    }

    /// The next line, or an error saying that `what` is missing.
    pub fn next(&mut self, what: &dyn Fn() -> String) -> Result<(&'a str, Location), Error> {
        match self.lines.get(self.pos) {
            Some(l) => {
                let loc = self.loc_of(self.pos);
                self.pos += 1;
                Ok((l, loc))
            }
            None => Err(Error::at(
                self.loc(),
                format!("{} ends here: {} is missing", self.file, what()),
            )),
        }
    }

    /// Only blank lines may follow what was read.
    pub fn finish(&self, after: &str) -> Result<(), Error> {
        if let Some(k) = (self.pos..self.lines.len()).find(|&k| !self.lines[k].trim().is_empty()) {
            return Err(Error::at(
                self.loc_of(k),
                format!(
                    "`{}` follows {after}: {} has more lines than its counters announce",
                    clip(self.lines[k]),
                    self.file
                ),
            ));
        }
        Ok(())
    }

    /// Reads how many of something follow: 0 to [`MAX_EACH`], else the error
    /// `too_many(n)` at the count.
    pub fn count(&mut self, what: &dyn Fn() -> String, too_many: &dyn Fn(i64) -> String) -> Result<i64, Error> {
        let (v, loc) = self.value(F::Int, what)?;
        let n = match v {
            Val::I(n) => n,
            _ => 0,
        };
        if !(0..=MAX_EACH).contains(&n) {
            return Err(Error::at(loc, too_many(n)));
        }
        Ok(n)
    }

    /// Reads one value of `kind`, `what` naming it in messages.
    pub fn value(&mut self, kind: F, what: &dyn Fn() -> String) -> Result<(Val, Location), Error> {
        let (text, loc) = self.next(what)?;
        let t = text.trim();
        let bad = |expected: &str| {
            Error::at(
                loc.clone(),
                format!("`{}` is not {expected}: it should be {}", clip(t), what()),
            )
        };
        let v = match kind {
            F::Str => Val::S(text.trim_end().to_string()),
            F::Int => Val::I(t.parse::<i64>().map_err(|_| bad("an integer"))?),
            F::Float => {
                let v = t
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad("a number"))?;
                Val::F(v)
            }
            F::Bool => match t.to_ascii_lowercase().as_str() {
                "true" | "1" => Val::B(true),
                "false" | "0" => Val::B(false),
                _ => return Err(bad("`true` or `false`")),
            },
            F::Color => {
                let h = t.strip_prefix('#').unwrap_or(t);
                if !(h.len() == 6 || h.len() == 8) || !h.bytes().all(|b| b.is_ascii_hexdigit()) {
                    return Err(bad("a colour (hexadecimal ARGB, as Processing's hex() writes it)"));
                }
                Val::C(format!("#{}", h[h.len() - 6..].to_ascii_lowercase()))
            }
        };
        Ok((v, loc))
    }

    /// Reads a record of `layout` (`what` names it in messages: `XIC 3`).
    pub fn record(&mut self, what: &str, layout: &[(&'static str, F)]) -> Result<Rec, Error> {
        let loc = self.loc();
        let mut fields = Vec::with_capacity(layout.len());
        for &(name, kind) in layout {
            let (v, l) = self.value(kind, &|| format!("the `{name}` of {what}"))?;
            fields.push((name, v, l));
        }
        Ok(Rec {
            what: what.to_string(),
            loc,
            fields,
        })
    }
}

/// Text shown in a message, cut at 60 characters.
pub(crate) fn clip(s: &str) -> String {
    if s.chars().count() > 60 {
        format!("{}…", s.chars().take(60).collect::<String>())
    } else {
        s.to_string()
    }
}

/// The kind of a saved value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum F {
    Str,
    Int,
    Float,
    Bool,
    /// A Processing colour, `hex()` of its ARGB.
    Color,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Val {
    S(String),
    I(i64),
    F(f64),
    B(bool),
    /// `#rrggbb`.
    C(String),
}

/// One saved object: its fields by name.
#[derive(Debug, Clone)]
pub(crate) struct Rec {
    /// `XIC 3`, `led 0`.
    pub what: String,
    pub loc: Location,
    fields: Vec<(&'static str, Val, Location)>,
}

impl Rec {
    fn get(&self, k: &str) -> Option<&Val> {
        self.fields.iter().find(|(n, _, _)| *n == k).map(|(_, v, _)| v)
    }

    pub fn s(&self, k: &str) -> &str {
        match self.get(k) {
            Some(Val::S(s) | Val::C(s)) => s,
            _ => "",
        }
    }

    pub fn i(&self, k: &str) -> i64 {
        match self.get(k) {
            Some(Val::I(v)) => *v,
            Some(Val::F(v)) => *v as i64,
            _ => 0,
        }
    }

    pub fn f(&self, k: &str) -> f64 {
        match self.get(k) {
            Some(Val::F(v)) => *v,
            Some(Val::I(v)) => *v as f64,
            _ => 0.0,
        }
    }

    /// Where field `k` is (the record's first line if there is no such field).
    pub fn at(&self, k: &str) -> Location {
        self.fields
            .iter()
            .find(|(n, _, _)| *n == k)
            .map(|(_, _, l)| l.clone())
            .unwrap_or_else(|| self.loc.clone())
    }
}

/// The type of a program tag (§3.6, Fig. 185).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Ty {
    Int,
    Real,
    Bool,
    Timer,
    Counter,
    Pid,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s.trim().to_ascii_lowercase().as_str() {
            "int" => Ty::Int,
            "real" => Ty::Real,
            "bool" => Ty::Bool,
            "timer" => Ty::Timer,
            "counter" => Ty::Counter,
            "pid" => Ty::Pid,
            _ => return None,
        })
    }

    fn alba(self) -> &'static str {
        match self {
            // Processing's `int` is 32 bits.
            Ty::Int => "DINT",
            Ty::Real => "REAL",
            Ty::Bool => "BOOL",
            Ty::Timer => "TIMER",
            Ty::Counter => "COUNTER",
            Ty::Pid => "PID",
        }
    }
}

/// A tag of tags.pl, as Alba names it.
#[derive(Debug, Clone)]
pub(crate) struct Sym {
    pub alba: String,
    pub ty: Ty,
}

/// The program tags by their AuroraLD name (case-sensitive, as AuroraLD
/// compares them with `String.equals`).
#[derive(Debug, Default)]
pub(crate) struct Tags {
    pub map: HashMap<String, Sym>,
}

/// What a tag reference holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Held {
    Bit,
    Number,
    Structure(Ty),
}

impl Tags {
    /// The Alba operand of an AuroraLD tag reference (`Motor`, `T1.DN`,
    /// `C1.ACC`), and what it holds.
    pub fn resolve(&self, name: &str) -> Result<(String, Held), String> {
        let name = name.trim();
        if name.is_empty() || name == "?" {
            return Err("no tag is assigned (`?`)".into());
        }
        if let Some(s) = self.map.get(name) {
            let held = match s.ty {
                Ty::Bool => Held::Bit,
                Ty::Int | Ty::Real => Held::Number,
                t => Held::Structure(t),
            };
            return Ok((s.alba.clone(), held));
        }
        if let Some((base, member)) = name.rsplit_once('.')
            && let Some(s) = self.map.get(base)
        {
            let m = member.to_ascii_uppercase();
            return match (s.ty, m.as_str()) {
                (Ty::Timer | Ty::Counter, "DN" | "EN") => Ok((format!("{}.{m}", s.alba), Held::Bit)),
                (Ty::Timer | Ty::Counter, "ACC" | "PRE") => Ok((format!("{}.{m}", s.alba), Held::Number)),
                _ => Err(format!("`{name}`: `{base}` has no member `{member}`")),
            };
        }
        Err(format!("`{name}` is not a tag of {TAGS}"))
    }
}

/// Converts an AuroraLD project folder named `name`.
pub fn convert(name: &str, folder: &Folder, opts: &Options) -> Result<(Project, Report), Error> {
    let mut report = Report::default();
    let Some(main) = &folder.main else {
        return Err(Error::plain(format!(
            "{name} is not an AuroraLD project folder: it has no {MAIN}"
        )));
    };
    let (prg_name, description) = read_main(main, &mut report)?;
    let Some(tags_text) = &folder.tags else {
        return Err(Error::plain(format!(
            "{name}: {TAGS} is missing (every AuroraLD project has one, §3.14)"
        )));
    };
    let Some(instr_text) = &folder.instructions else {
        return Err(Error::plain(format!(
            "{name}: {INSTRUCTIONS} is missing (every AuroraLD project has one, §3.14)"
        )));
    };
    let mut names = Names::new();
    let (tags, tag_rows) = read_tags(tags_text, &mut names, &mut report)?;
    let rows = ladder::read(instr_text)?;
    let program = ladder::convert(&rows, &tags, &mut report)?;
    // trends.pl and the screens are imported where they parse: a file
    // that does not is reported and left out, the rest stays.
    let trends = match &folder.trends {
        None => None,
        Some(t) => {
            let mut r = Report::default();
            match read_trends(t, &tags, &mut r) {
                Ok(t) => {
                    report.entries.append(&mut r.entries);
                    Some(t)
                }
                Err(e) => {
                    let at = e.location.clone().unwrap_or_else(|| Location::new(TRENDS, 1, 1));
                    report.push(Kind::Refused, at, format!("{TRENDS} not imported: {}", e.message));
                    None
                }
            }
        }
    };
    let mut screens = Vec::new();
    let mut alarms = Vec::new();
    for (file, text) in &folder.screens {
        let (screen, mut a) = pcs::convert(file, text, &tags, &alarms, &mut report)?;
        screens.extend(screen);
        alarms.append(&mut a);
    }
    let board = match &opts.board {
        None => None,
        Some(b) => Some(board(b, &tag_rows)?),
    };
    let rank = |f: &str| match f {
        MAIN => 0,
        TAGS => 1,
        INSTRUCTIONS => 2,
        TRENDS => 3,
        _ => 4,
    };
    report.entries.sort_by(|a, b| {
        (rank(&a.location.file), &a.location.file, a.location.line).cmp(&(
            rank(&b.location.file),
            &b.location.file,
            b.location.line,
        ))
    });
    let project = Project {
        name: if prg_name.trim().is_empty() {
            name.to_string()
        } else {
            prg_name
        },
        description,
        scan_ms: ladder::SCAN_MS,
        board,
        tags: tag_rows,
        programs: vec![program],
        screens,
        alarms,
        trends,
    };
    Ok((project, report))
}

/// main.ara (Fig. 205): `//PROJECT NAME`, the name, `//TIME AND DATE`,
/// `h:m:s`, `d/m/y`, `//RAIL`, the rail's y. The name and the date are read;
/// the rail is a drawing setting.
fn read_main(text: &str, report: &mut Report) -> Result<(String, String), Error> {
    let mut r = Reader::new(MAIN, text);
    let (head, loc) = r.next(&|| format!("the first line `{MAIN_HEADER}`"))?;
    if head.trim() != MAIN_HEADER {
        return Err(Error::at(
            loc,
            format!(
                "not an AuroraLD {MAIN}: the first line is `{}`, not `{MAIN_HEADER}`",
                clip(head.trim())
            ),
        ));
    }
    let (name, name_loc) = r.next(&|| "the project's name".into())?;
    let name = name.trim().to_string();
    let mut description = String::from("imported from AuroraLD Studio by alba import");
    let expect = |r: &mut Reader<'_>, header: &str| -> Result<bool, Error> {
        match r.lines.get(r.pos) {
            None => Ok(false),
            Some(l) if l.trim() == header => {
                r.pos += 1;
                Ok(true)
            }
            Some(l) => Err(Error::at(
                r.loc(),
                format!("`{}` where main.ara has `{header}`", clip(l.trim())),
            )),
        }
    };
    if expect(&mut r, "//TIME AND DATE")? {
        let (time, _) = r.next(&|| "the time the project was saved (h:m:s)".into())?;
        let (date, _) = r.next(&|| "the date the project was saved (d/m/y)".into())?;
        description = format!(
            "imported from AuroraLD Studio by alba import (saved at {} on {})",
            time.trim(),
            date.trim()
        );
        if expect(&mut r, "//RAIL")? {
            r.value(F::Float, &|| "the rail's y (a number)".into())?;
        }
    }
    r.finish("the rail")?;
    report.push(Kind::Converted, name_loc, format!("project `{name}`"));
    Ok((name, description))
}

/// tags.pl: `ptag_counter` (the row of the last tag, −1 when there is none;
/// Fig. 182), then for each row its five columns — name, variable, address,
/// value, description (Fig. 181) — one a line.
fn read_tags(text: &str, names: &mut Names, report: &mut Report) -> Result<(Tags, Vec<TagOut>), Error> {
    const ROW: &[(&str, F)] = &[
        ("tag", F::Str),
        ("variable", F::Str),
        ("address", F::Str),
        ("value", F::Str),
        ("description", F::Str),
    ];
    let mut r = Reader::new(TAGS, text);
    let (v, loc) = r.value(F::Int, &|| {
        "`ptag_counter`, the row of the last tag (−1 for none)".into()
    })?;
    let last = match v {
        Val::I(n) => n,
        _ => -1,
    };
    if !(-1..MAX_TAGS).contains(&last) {
        return Err(Error::at(
            loc,
            format!(
                "{} tags: AuroraLD's table holds at most {MAX_TAGS} (rows 0 to 99)",
                last + 1
            ),
        ));
    }
    let mut tags = Tags::default();
    let mut out = Vec::new();
    for row in 0..=last {
        let rec = r.record(&format!("tag row {row}"), ROW)?;
        let src = rec.s("tag").trim().to_string();
        let loc = rec.loc.clone();
        if src.is_empty() {
            report.push(Kind::Refused, loc, format!("row {row} has no tag name; left out"));
            continue;
        }
        if tags.map.contains_key(&src) {
            report.push(
                Kind::Refused,
                loc,
                format!("tag `{src}` is declared twice (AuroraLD refuses the project when it compiles, §3.13); this row is left out"),
            );
            continue;
        }
        let Some(mut ty) = Ty::parse(rec.s("variable")) else {
            report.push(
                Kind::Refused,
                rec.at("variable"),
                format!(
                    "tag `{src}`: `{}` is not one of AuroraLD's variables (Int, Real, Bool, Timer, Counter, PID); left out",
                    clip(rec.s("variable"))
                ),
            );
            continue;
        };
        let (alba, why) = names.alba(&src);
        if let Some(why) = why {
            report.push(Kind::Approximated, loc.clone(), format!("{why}: tag `{alba}`"));
        }
        let addr_text = rec.s("address").trim();
        let mut address = String::new();
        let internal =
            addr_text.is_empty() || addr_text.eq_ignore_ascii_case("internal") || addr_text.eq_ignore_ascii_case("plc");
        if addr_text.eq_ignore_ascii_case("plc") {
            report.push(
                Kind::Approximated,
                rec.at("address"),
                format!("tag `{src}`: no address chosen (`PLC`, the column's placeholder): an internal tag"),
            );
        } else if !internal {
            match alba_model::Address::parse(addr_text) {
                Ok(Some(a)) if addr_text.contains(':') => {
                    use alba_model::Address as A;
                    let fits = match (ty, a) {
                        (Ty::Bool, A::DigitalIn(_) | A::DigitalOut(_)) => true,
                        (Ty::Int, A::AnalogIn(_) | A::AnalogOut(_)) => true,
                        (Ty::Real, A::AnalogIn(_) | A::AnalogOut(_)) => {
                            report.push(
                                Kind::Approximated,
                                rec.at("variable"),
                                format!(
                                    "tag `{src}`: a Real on {addr_text}; Alba holds analog channels as integers (the converter's counts), so it is a DINT"
                                ),
                            );
                            ty = Ty::Int;
                            true
                        }
                        _ => false,
                    };
                    if fits {
                        address = addr_text.to_ascii_uppercase();
                    } else {
                        report.push(
                            Kind::Approximated,
                            rec.at("address"),
                            format!(
                                "tag `{src}`: a {} cannot be on {addr_text} (§3.6, Table 10); an internal tag",
                                rec.s("variable").trim()
                            ),
                        );
                    }
                }
                _ => report.push(
                    Kind::Approximated,
                    rec.at("address"),
                    format!(
                        "tag `{src}`: `{}` is not an AuroraLD address (Internal, DI:1/n, DO:2/n, AI:3/n, AO:4/n); an internal tag",
                        clip(addr_text)
                    ),
                ),
            }
        }
        let value = rec.s("value").trim();
        let mut initial = String::new();
        let zero =
            value.is_empty() || value.parse::<f64>().is_ok_and(|v| v == 0.0) || value.eq_ignore_ascii_case("false");
        if !zero {
            let lit = match ty {
                Ty::Bool => match value.to_ascii_lowercase().as_str() {
                    "1" | "true" => Some("1".to_string()),
                    _ => None,
                },
                Ty::Int => value
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.fract() == 0.0 && v.abs() <= f64::from(i32::MAX))
                    .map(|v| (v as i64).to_string()),
                Ty::Real => value
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .map(|_| value.to_string()),
                _ => None,
            };
            match lit {
                Some(l) if address.is_empty() => initial = l,
                Some(_) => report.push(
                    Kind::Approximated,
                    rec.at("value"),
                    format!("tag `{src}`: the value {value} of an I/O tag is its last live value; not kept"),
                ),
                None => report.push(
                    Kind::Approximated,
                    rec.at("value"),
                    format!("tag `{src}`: the value `{}` is not kept", clip(value)),
                ),
            }
        }
        let shown = if address.is_empty() {
            "internal".to_string()
        } else {
            address.clone()
        };
        report.push(Kind::Converted, loc, format!("tag `{src}`: {} {shown}", ty.alba()));
        out.push(TagOut {
            name: alba.clone(),
            ty: ty.alba().to_string(),
            address,
            initial,
            description: rec.s("description").trim().to_string(),
        });
        tags.map.insert(src, Sym { alba, ty });
    }
    r.finish(&format!("the {} rows of ptag_counter", last + 1))?;
    Ok((tags, out))
}

/// trends.pl (§3.18, Figs. 221–223): the sample time (ms, at least 50), the
/// time axis from and to (ms), the y axis from and to, then the tags of the
/// nine pens (`graph_1` … `graph_9`; empty or `?` when unused).
fn read_trends(text: &str, tags: &Tags, report: &mut Report) -> Result<TrendsOut, Error> {
    let mut r = Reader::new(TRENDS, text);
    let num = |r: &mut Reader<'_>, what: &'static str| -> Result<(f64, Location), Error> {
        let (v, l) = r.value(F::Float, &|| what.to_string())?;
        Ok((if let Val::F(v) = v { v } else { 0.0 }, l))
    };
    let (sample, sample_loc) = num(&mut r, "the sample time in ms")?;
    let (t0, _) = num(&mut r, "the start of the time axis (ms)")?;
    let (t1, t_loc) = num(&mut r, "the end of the time axis (ms)")?;
    let (y0, _) = num(&mut r, "the bottom of the y axis")?;
    let (y1, y_loc) = num(&mut r, "the top of the y axis")?;
    let mut pens = Vec::new();
    for k in 1..=TREND_PENS {
        let (tag, loc) = r.next(&|| format!("the tag of pen graph_{k}"))?;
        let tag = tag.trim();
        if tag.is_empty() || tag == "?" {
            continue;
        }
        match tags.resolve(tag) {
            Ok((alba, Held::Bit | Held::Number)) => {
                if pens.iter().any(|p: &PenOut| p.tag.eq_ignore_ascii_case(&alba)) {
                    report.push(
                        Kind::Refused,
                        loc,
                        format!("pen graph_{k}: `{tag}` is plotted twice; left out"),
                    );
                    continue;
                }
                report.push(Kind::Converted, loc, format!("pen graph_{k}: `{tag}`"));
                pens.push(PenOut {
                    tag: alba,
                    scale: (y0 < y1).then_some((y0, y1)),
                });
            }
            Ok((_, Held::Structure(_))) => report.push(
                Kind::Refused,
                loc,
                format!("pen graph_{k}: `{tag}` is a structure; Alba plots its members (`{tag}.ACC`); left out"),
            ),
            Err(why) => report.push(Kind::Refused, loc, format!("pen graph_{k}: {why}; left out")),
        }
    }
    r.finish("the nine pens")?;
    if sample < 50.0 {
        report.push(
            Kind::Approximated,
            sample_loc.clone(),
            format!("sample time {sample} ms: AuroraLD samples every 50 ms at least (§3.18)"),
        );
    }
    report.push(
        Kind::Approximated,
        sample_loc,
        format!(
            "sample time {sample} ms: Alba's trends draw every recorded value (the historian records on change and every history.sample_ms)"
        ),
    );
    let span = t1 - t0;
    let window_ms = if (1_000.0..=604_800_000.0).contains(&span) {
        report.push(
            Kind::Converted,
            t_loc,
            format!("time axis {t0} to {t1} ms: a window of {span} ms"),
        );
        span as u64
    } else {
        let w = span.clamp(1_000.0, 604_800_000.0) as u64;
        report.push(
            Kind::Approximated,
            t_loc,
            format!("time axis {t0} to {t1} ms: Alba's window is 1 s to 7 days; {w} ms"),
        );
        w
    };
    if y0 >= y1 {
        report.push(
            Kind::Approximated,
            y_loc,
            format!("y axis {y0} to {y1}: not a range; the pens scale automatically"),
        );
    }
    Ok(TrendsOut { window_ms, pens })
}

/// `[board]` for `--board`: the model and the `aurora` preset's pins (the
/// PLC1805 wiring AuroraLD's channels come from, SPEC §7.1), as many of each
/// direction as the tags use.
fn board(model: &str, tags: &[TagOut]) -> Result<crate::BoardOut, Error> {
    use alba_model::board::{Dir, Model, PinMap};
    let m = Model::parse(model).ok_or_else(|| Error::plain(format!("unknown board `{model}`: uno, nano or mega")))?;
    let preset = PinMap::preset("aurora").unwrap_or_default();
    let mut lists: Vec<Vec<String>> = Vec::new();
    for dir in Dir::ALL {
        use alba_model::Address as A;
        let used = tags
            .iter()
            .filter_map(|t| match (dir, alba_model::Address::parse(&t.address)) {
                (Dir::DigitalIn, Ok(Some(A::DigitalIn(n))))
                | (Dir::DigitalOut, Ok(Some(A::DigitalOut(n))))
                | (Dir::AnalogIn, Ok(Some(A::AnalogIn(n))))
                | (Dir::AnalogOut, Ok(Some(A::AnalogOut(n)))) => Some(n as usize),
                _ => None,
            })
            .max();
        let pins = preset.pins(dir);
        let n = used.map(|u| u + 1).unwrap_or(0);
        if n > pins.len() {
            return Err(Error::plain(format!(
                "{} has no pin on the `aurora` wiring (it has {} {} channels)",
                dir.address(n - 1),
                pins.len(),
                dir.key().to_ascii_uppercase()
            )));
        }
        lists.push(pins[..n].iter().map(ToString::to_string).collect());
    }
    let mut it = lists.into_iter();
    let mut next = || it.next().unwrap_or_default();
    Ok(crate::BoardOut {
        model: m.name().to_string(),
        di: next(),
        r#do: next(),
        ai: next(),
        ao: next(),
    })
}
