//! `alarms.csv`: the alarm definitions of a project (docs/alarms.md), read
//! with located errors and resolved against the program's tags.

use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_ir::{Layout, Place, Target};
use alba_model::{DataType, csv};
use std::fmt;

/// The header of `alarms.csv` (fixed, SPEC §10.5); `suppressed_by` may follow.
pub const HEADER: [&str; 7] = ["id", "tag", "condition", "severity", "delay_ms", "deadband", "message"];
/// The optional eighth column: a BOOL tag that suppresses the alarm by design while true.
pub const SUPPRESS_COLUMN: &str = "suppressed_by";
/// Longest on-delay: one day.
pub const MAX_DELAY_MS: u64 = 86_400_000;
/// Most alarms in one project.
pub const MAX_ALARMS: usize = 10_000;

/// A comparison of an analog alarm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cmp {
    Gt,
    Ge,
    Lt,
    Le,
    Eq,
    Ne,
}

impl Cmp {
    fn as_str(self) -> &'static str {
        match self {
            Cmp::Gt => ">",
            Cmp::Ge => ">=",
            Cmp::Lt => "<",
            Cmp::Le => "<=",
            Cmp::Eq => "==",
            Cmp::Ne => "!=",
        }
    }
}

/// When an alarm is active.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Condition {
    /// The tag is true (non-zero).
    On,
    /// The tag is false (zero).
    Off,
    /// The tag went from false to true (an event: active for one evaluation).
    Rising,
    /// The tag went from true to false.
    Falling,
    /// The tag compared with a limit.
    Compare(Cmp, f64),
}

impl Condition {
    /// An edge: active for one evaluation only.
    pub fn is_edge(self) -> bool {
        matches!(self, Condition::Rising | Condition::Falling)
    }

    /// Parses `on`, `off`, `rising`, `falling`, `> X`, `>= X`, `< X`, `<= X`, `== X`, `!= X`.
    pub fn parse(text: &str) -> Result<Condition, DefError> {
        let t = text.trim();
        match t.to_ascii_lowercase().as_str() {
            "on" => return Ok(Condition::On),
            "off" => return Ok(Condition::Off),
            "rising" => return Ok(Condition::Rising),
            "falling" => return Ok(Condition::Falling),
            _ => {}
        }
        let (op, rest) = [
            (">=", Cmp::Ge),
            ("<=", Cmp::Le),
            ("==", Cmp::Eq),
            ("!=", Cmp::Ne),
            (">", Cmp::Gt),
            ("<", Cmp::Lt),
        ]
        .iter()
        .find_map(|(s, c)| t.strip_prefix(s).map(|r| (*c, r)))
        .ok_or_else(|| DefError::Condition(t.to_string()))?;
        let rest = rest.trim();
        match rest.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Condition::Compare(op, x)),
            _ => Err(DefError::Threshold {
                op: op.as_str(),
                found: rest.to_string(),
            }),
        }
    }
}

impl fmt::Display for Condition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Condition::On => f.write_str("on"),
            Condition::Off => f.write_str("off"),
            Condition::Rising => f.write_str("rising"),
            Condition::Falling => f.write_str("falling"),
            Condition::Compare(c, x) => write!(f, "{} {x}", c.as_str()),
        }
    }
}

/// Why a field of alarms.csv is refused ([`Condition::parse`], [`parse_severity`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DefError {
    #[error("`{0}` is not a condition: write on, off, rising, falling, or > >= < <= == != and a number")]
    Condition(String),
    #[error("`{op}` needs a number after it, found `{found}`")]
    Threshold { op: &'static str, found: String },
    #[error("`{0}` is not a severity: write 1 to 1000, or low, medium, high or critical")]
    Severity(String),
}

/// Parses a severity: 1–1000, or low (250), medium (500), high (750), critical (1000).
pub fn parse_severity(text: &str) -> Result<u16, DefError> {
    let t = text.trim();
    match t.to_ascii_lowercase().as_str() {
        "low" => return Ok(250),
        "medium" => return Ok(500),
        "high" => return Ok(750),
        "critical" => return Ok(1000),
        _ => {}
    }
    match t.parse::<u16>() {
        Ok(n @ 1..=1000) => Ok(n),
        _ => Err(DefError::Severity(t.to_string())),
    }
}

/// One alarm as `alarms.csv` defines it, resolved against the program.
#[derive(Debug, Clone, PartialEq)]
pub struct AlarmDef {
    pub id: String,
    /// The tag (or member, or address) as written.
    pub tag: String,
    pub place: Place,
    pub condition: Condition,
    pub severity: u16,
    pub delay_ms: u64,
    pub deadband: f64,
    pub message: String,
    /// A BOOL tag: while true the alarm is suppressed by design.
    pub suppressed_by: Option<(String, Place)>,
    /// The row, for messages.
    pub span: Span,
}

/// Reads `alarms.csv` and resolves its tags in `layout`. Every problem is
/// reported (code E140), each at its field; alarms with an error are left out.
pub fn parse(text: &str, file: FileId, layout: &Layout) -> (Vec<AlarmDef>, Vec<Diagnostic>) {
    let sp = |r: &std::ops::Range<usize>| Span::new(file, r.clone());
    let (records, errors) = csv::read(text);
    let mut diags: Vec<Diagnostic> = errors
        .iter()
        .map(|e| Diagnostic::new(Code::AlarmFile, e.message.clone(), sp(&e.span), "here"))
        .collect();
    let mut records = records.into_iter();
    let Some(header) = records.next() else {
        diags.push(
            Diagnostic::new(
                Code::AlarmFile,
                "alarms.csv is empty",
                Span::new(file, 0..0),
                "no header",
            )
            .with_help(format!("the first line is the header `{}`", HEADER.join(","))),
        );
        return (Vec::new(), diags);
    };
    let names: Vec<String> = header
        .fields
        .iter()
        .map(|f| f.text.trim().to_ascii_lowercase())
        .collect();
    let with_suppress = names.len() == 8 && names[7] == SUPPRESS_COLUMN;
    if names[..names.len().min(7)] != HEADER[..] || !(names.len() == 7 || with_suppress) {
        diags.push(
            Diagnostic::new(
                Code::AlarmFile,
                format!("the header of alarms.csv must be `{}`", HEADER.join(",")),
                sp(&header.span),
                "header",
            )
            .with_help(format!(
                "write that header on the first line (an eighth column `{SUPPRESS_COLUMN}` may follow)"
            )),
        );
        return (Vec::new(), diags);
    }
    let columns = names.len();
    let mut defs: Vec<AlarmDef> = Vec::new();
    // Every id seen (also of rows with errors), for "used twice".
    let mut ids: Vec<(String, Span)> = Vec::new();
    for r in records {
        if r.fields.len() != columns {
            let at = r.fields.get(columns).map_or(r.end(), |f| f.span.clone());
            push(
                &mut diags,
                file,
                format!("an alarm row has {columns} fields, this one has {}", r.fields.len()),
                &at,
                "wrong number of fields",
            );
            continue;
        }
        if defs.len() >= MAX_ALARMS {
            push(
                &mut diags,
                file,
                format!("more than {MAX_ALARMS} alarms"),
                &r.span,
                "too many",
            );
            break;
        }
        let f = &r.fields;
        let before = diags.len();
        let id = f[0].text.trim().to_string();
        let id_ok = !id.is_empty()
            && id.len() <= 64
            && id
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
        if !id_ok {
            diags.push(
                Diagnostic::new(
                    Code::AlarmFile,
                    format!("`{id}` is not an alarm id"),
                    sp(&f[0].span),
                    "id",
                )
                .with_help("an id is 1 to 64 letters, digits, `_`, `-` or `.` (it appears in URLs)"),
            );
        } else if let Some((_, first)) = ids.iter().find(|(i, _)| i.eq_ignore_ascii_case(&id)) {
            diags.push(
                Diagnostic::new(
                    Code::AlarmFile,
                    format!("the alarm id `{id}` is used twice"),
                    sp(&f[0].span),
                    "again",
                )
                .with_note(*first, "first here"),
            );
        } else {
            ids.push((id.clone(), sp(&f[0].span)));
        }
        let tag = f[1].text.trim().to_string();
        let place = resolve(layout, &tag, sp(&f[1].span), &mut diags);
        let condition = Condition::parse(&f[2].text)
            .map_err(|m| {
                diags.push(Diagnostic::new(
                    Code::AlarmFile,
                    m.to_string(),
                    sp(&f[2].span),
                    "condition",
                ))
            })
            .ok();
        let severity = parse_severity(&f[3].text)
            .map_err(|m| {
                diags.push(Diagnostic::new(
                    Code::AlarmFile,
                    m.to_string(),
                    sp(&f[3].span),
                    "severity",
                ))
            })
            .ok();
        let delay_text = f[4].text.trim();
        let delay_ms = if delay_text.is_empty() {
            Some(0)
        } else {
            match delay_text.parse::<u64>() {
                Ok(d) if d <= MAX_DELAY_MS => Some(d),
                _ => {
                    diags.push(Diagnostic::new(
                        Code::AlarmFile,
                        format!("`{delay_text}` is not an on-delay: write 0 to {MAX_DELAY_MS} milliseconds"),
                        sp(&f[4].span),
                        "delay_ms",
                    ));
                    None
                }
            }
        };
        let db_text = f[5].text.trim();
        let deadband = if db_text.is_empty() {
            Some(0.0)
        } else {
            match db_text.parse::<f64>() {
                Ok(d) if d.is_finite() && d >= 0.0 => Some(d),
                _ => {
                    diags.push(Diagnostic::new(
                        Code::AlarmFile,
                        format!("`{db_text}` is not a deadband: write a number ≥ 0"),
                        sp(&f[5].span),
                        "deadband",
                    ));
                    None
                }
            }
        };
        let message = f[6].text.trim().to_string();
        if message.is_empty() {
            push(
                &mut diags,
                file,
                "an alarm needs a message (what the operator reads)".into(),
                &f[6].span,
                "message",
            );
        }
        if let (Some(c), Some(p)) = (condition, place) {
            let digital = p.data_type() == DataType::Bool;
            match c {
                Condition::Compare(..) if digital => diags.push(Diagnostic::new(
                    Code::AlarmFile,
                    format!("`{tag}` is a BOOL: compare numbers, or use on, off, rising or falling"),
                    sp(&f[2].span),
                    "comparison of a BOOL",
                )),
                Condition::On | Condition::Off | Condition::Rising | Condition::Falling
                    if deadband.is_some_and(|d| d > 0.0) =>
                {
                    push(
                        &mut diags,
                        file,
                        format!("a deadband applies to comparisons, not to `{c}`"),
                        &f[5].span,
                        "deadband",
                    );
                }
                _ => {}
            }
            if c.is_edge() && delay_ms.is_some_and(|d| d > 0) {
                push(
                    &mut diags,
                    file,
                    format!("`{c}` is an edge (an instant): it takes no on-delay"),
                    &f[4].span,
                    "delay_ms",
                );
            }
        }
        let suppressed_by = if with_suppress && !f[7].text.trim().is_empty() {
            let name = f[7].text.trim().to_string();
            match resolve(layout, &name, sp(&f[7].span), &mut diags) {
                Some(p) if p.data_type() == DataType::Bool => Some(Some((name, p))),
                Some(_) => {
                    push(
                        &mut diags,
                        file,
                        format!("`{name}` is not a BOOL"),
                        &f[7].span,
                        "suppressed_by",
                    );
                    None
                }
                None => None,
            }
        } else {
            Some(None)
        };
        if diags.len() != before {
            continue;
        }
        if let (Some(place), Some(condition), Some(severity), Some(delay_ms), Some(deadband), Some(suppressed_by)) =
            (place, condition, severity, delay_ms, deadband, suppressed_by)
        {
            defs.push(AlarmDef {
                id,
                tag,
                place,
                condition,
                severity,
                delay_ms,
                deadband,
                message,
                suppressed_by,
                span: sp(&r.span),
            });
        }
    }
    diags.sort_by_key(|d| d.primary.as_ref().map(|l| l.span.start));
    (defs, diags)
}

fn push(diags: &mut Vec<Diagnostic>, file: FileId, msg: String, span: &std::ops::Range<usize>, label: &str) {
    diags.push(Diagnostic::new(
        Code::AlarmFile,
        msg,
        Span::new(file, span.clone()),
        label,
    ));
}

fn resolve(layout: &Layout, name: &str, span: Span, diags: &mut Vec<Diagnostic>) -> Option<Place> {
    match layout.resolve(name) {
        Ok(Target::Value { place, .. }) => Some(place),
        Ok(_) => {
            diags.push(Diagnostic::new(
                Code::AlarmFile,
                format!("`{name}` is a structure; name a member (`{name}.DN`, `{name}.ACC`)"),
                span,
                "structure",
            ));
            None
        }
        Err(e) => {
            let mut d = Diagnostic::new(Code::AlarmFile, e.to_string(), span, "unknown");
            if let Some(s) = layout.tags.suggest(name) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            diags.push(d);
            None
        }
    }
}

/// Largest alarms.csv read.
pub const MAX_FILE_BYTES: u64 = 4 << 20;

/// Reads `<dir>/alarms.csv` (none: no alarms), registering it in `files` so
/// that errors render with its lines, and resolves it in `layout`.
pub fn load(
    dir: &std::path::Path,
    files: &mut alba_diag::Files,
    layout: &Layout,
) -> Result<Vec<AlarmDef>, Vec<Diagnostic>> {
    let path = dir.join(crate::FILE);
    let text = match std::fs::metadata(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Ok(m) if m.len() > MAX_FILE_BYTES => {
            return Err(vec![Diagnostic::unplaced(
                Code::AlarmFile,
                format!("{} is larger than {} MiB", path.display(), MAX_FILE_BYTES >> 20),
            )]);
        }
        _ => std::fs::read(&path)
            .map_err(|e| e.to_string())
            .and_then(|b| String::from_utf8(b).map_err(|_| "it is not UTF-8 text".to_string()))
            .map_err(|e| {
                vec![Diagnostic::unplaced(
                    Code::AlarmFile,
                    format!("cannot read {}: {e}", path.display()),
                )]
            })?,
    };
    let file = files.add(path.display().to_string(), text);
    let (defs, diags) = parse(files.text(file), file, layout);
    if diags.is_empty() { Ok(defs) } else { Err(diags) }
}
