//! The tag table, `tags.csv` (SPEC §2.1, §10.1).

use crate::Invalid;
use crate::address::{Address, Area};
use crate::csv;
use crate::types::{DataType, PID_DEFAULTS, PidParams};
use crate::value::Value;
use alba_diag::Code;
use alba_diag::{Diagnostic, FileId, Span};
use std::collections::HashMap;

/// The header Alba writes; reading accepts any order and leaving out the
/// optional columns.
pub const HEADER: &str = "name,type,address,initial,retain,description";
const COLUMNS: [&str; 6] = ["name", "type", "address", "initial", "retain", "description"];

/// Longest tag name accepted.
pub const MAX_NAME_LEN: usize = 64;

/// Words that cannot name a tag because operands or expressions use them.
const RESERVED: &[&str] = &["TRUE", "FALSE", "MOD", "AND", "OR", "XOR", "NOT", "PI", "E"];

#[derive(Debug, Clone, PartialEq)]
pub struct Tag {
    pub name: String,
    pub ty: DataType,
    pub address: Option<Address>,
    /// The address as written (kept for display and round trips).
    pub address_text: Option<String>,
    /// `None` means the type's zero.
    pub initial: Option<Value>,
    /// Initial values of structure members (PID tags: `KP=5;UPD=640`), by
    /// canonical member name.
    pub members: Vec<(String, Value)>,
    pub retain: bool,
    pub description: String,
    /// Where the tag's name is declared.
    pub span: Span,
}

impl Tag {
    /// Inputs are written by I/O drivers (or a stimulus), never by programs.
    pub fn is_input(&self) -> bool {
        self.address.as_ref().is_some_and(Address::is_input)
    }
}

/// All tags of a project, looked up case-insensitively.
#[derive(Debug, Clone, Default)]
pub struct TagTable {
    tags: Vec<Tag>,
    index: HashMap<String, usize>,
}

/// Is `s` a valid identifier (letters, digits, `_`, not starting with a digit)?
pub fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Parses `MEMBER=value;MEMBER=value` for the writable members of a
/// structure type.
pub fn parse_members(text: &str, ty: DataType) -> Result<Vec<(String, Value)>, Invalid> {
    members_text(text, ty).map_err(Invalid::Members)
}

fn members_text(text: &str, ty: DataType) -> Result<Vec<(String, Value)>, String> {
    let mut out: Vec<(String, Value)> = Vec::new();
    let mut timed = Vec::new();
    for item in text.split(';').map(str::trim).filter(|s| !s.is_empty()) {
        let Some((name, value)) = item.split_once('=') else {
            return Err(format!("`{item}` is not MEMBER=value"));
        };
        let name = name.trim();
        let Some(m) = ty.member(name) else {
            let all: Vec<&str> = ty.members().iter().filter(|m| m.writable).map(|m| m.name).collect();
            return Err(format!(
                "{ty} has no member `{name}` (writable members: {})",
                all.join(" ")
            ));
        };
        if !m.writable {
            return Err(format!("{ty} member {} is a status set by the instruction", m.name));
        }
        if out.iter().any(|(n, _)| n == m.name) {
            return Err(format!("member {} is given twice", m.name));
        }
        let v = match with_unit(ty, m.name, value.trim()) {
            Some(Ok(secs)) => {
                timed.push(out.len());
                Value::Real(secs as f32)
            }
            Some(Err(e)) => return Err(format!("bad value for {}: {e}", m.name)),
            None => Value::parse(value.trim(), m.ty).map_err(|e| format!("bad value for {}: {e}", m.name))?,
        };
        out.push((m.name.to_string(), v));
    }
    // TI and TD given with a unit are in seconds so far; a loop with
    // MINUTES holds them in minutes.
    let minutes = out.iter().any(|(n, v)| n == "MINUTES" && v.as_f64() != 0.0);
    if minutes {
        for k in timed {
            out[k].1 = Value::Real((out[k].1.as_f64() / 60.0) as f32);
        }
    }
    Ok(out)
}

/// A PID's `TI` or `TD` given with its unit: `TI=0.1min` (minutes per
/// repeat, the SLC 500's), `TD=0.6 s` (seconds): the value in seconds.
/// `None` when there is no unit or the member is not TI or TD (a plain
/// number is in the loop's unit: seconds, or minutes with `MINUTES`).
fn with_unit(ty: DataType, member: &str, value: &str) -> Option<Result<f64, String>> {
    if ty != DataType::Pid || !(member == "TI" || member == "TD") {
        return None;
    }
    let lower = value.to_ascii_lowercase();
    let (num, per) = if let Some(n) = lower.strip_suffix("min") {
        (n, 60.0)
    } else {
        (lower.strip_suffix('s')?, 1.0)
    };
    Some(match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v * per),
        _ => Err(format!("`{value}` is not a time (a number and `min` or `s`)")),
    })
}

/// Why `name` cannot be a tag name, if it cannot.
pub fn check_tag_name(name: &str) -> Result<(), Invalid> {
    tag_name_text(name).map_err(Invalid::TagName)
}

fn tag_name_text(name: &str) -> Result<(), String> {
    if name.is_empty() {
        return Err("the tag name is empty".into());
    }
    if !is_identifier(name) {
        return Err(format!(
            "`{name}` is not a valid tag name: use letters, digits and `_`, not starting with a digit"
        ));
    }
    if name.len() > MAX_NAME_LEN {
        return Err(format!("`{name}` is longer than {MAX_NAME_LEN} characters"));
    }
    if RESERVED.iter().any(|r| r.eq_ignore_ascii_case(name)) {
        return Err(format!("`{name}` is a reserved word"));
    }
    if !matches!(Address::parse(name), Ok(None)) {
        return Err(format!("`{name}` reads as an address; choose another name"));
    }
    Ok(())
}

impl TagTable {
    pub fn new() -> TagTable {
        TagTable::default()
    }

    pub fn iter(&self) -> impl Iterator<Item = &Tag> {
        self.tags.iter()
    }

    pub fn len(&self) -> usize {
        self.tags.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tags.is_empty()
    }

    pub fn get(&self, name: &str) -> Option<&Tag> {
        self.index.get(&name.to_ascii_lowercase()).map(|&i| &self.tags[i])
    }

    /// Position of a tag in declaration order.
    pub fn position(&self, name: &str) -> Option<usize> {
        self.index.get(&name.to_ascii_lowercase()).copied()
    }

    /// Adds a tag; the caller has checked the name is free.
    pub fn push(&mut self, tag: Tag) {
        self.index.insert(tag.name.to_ascii_lowercase(), self.tags.len());
        self.tags.push(tag);
    }

    /// The closest tag name to `name`, for "did you mean" hints.
    pub fn suggest(&self, name: &str) -> Option<&str> {
        let lower = name.to_ascii_lowercase();
        self.tags
            .iter()
            .map(|t| (edit_distance(&lower, &t.name.to_ascii_lowercase()), t.name.as_str()))
            .filter(|(d, _)| *d <= 2.max(lower.len() / 4))
            .min_by_key(|(d, _)| *d)
            .map(|(_, n)| n)
    }

    /// Parses `tags.csv`. Returns every valid row, and a diagnostic for each
    /// invalid one (all problems of the file, not only the first).
    pub fn parse(text: &str, file: FileId) -> (TagTable, Vec<Diagnostic>) {
        let mut table = TagTable::new();
        let mut diags = Vec::new();
        let span = |r: &std::ops::Range<usize>| Span::new(file, r.clone());
        let (records, errors) = csv::read(text);
        for e in errors {
            diags.push(Diagnostic::new(
                Code::CsvSyntax,
                e.message.clone(),
                span(&e.span),
                "here",
            ));
        }
        let mut records = records.into_iter();
        let Some(header) = records.next() else {
            if diags.is_empty() {
                diags.push(
                    Diagnostic::new(
                        Code::CsvHeader,
                        "tags.csv is empty",
                        Span::new(file, 0..0),
                        "expected a header here",
                    )
                    .with_help(format!("start the file with `{HEADER}`")),
                );
            }
            return (table, diags);
        };
        // Map each column to its field position.
        let mut cols: [Option<usize>; 6] = [None; 6];
        for (i, f) in header.fields.iter().enumerate() {
            let name = f.text.trim().to_ascii_lowercase();
            match COLUMNS.iter().position(|c| *c == name) {
                Some(c) if cols[c].is_none() => cols[c] = Some(i),
                Some(_) => diags.push(Diagnostic::new(
                    Code::CsvHeader,
                    format!("column `{name}` appears twice in the header"),
                    span(&f.span),
                    "repeated column",
                )),
                None => diags.push(
                    Diagnostic::new(
                        Code::CsvHeader,
                        format!("unknown column `{}` in the header", f.text.trim()),
                        span(&f.span),
                        "not a tags.csv column",
                    )
                    .with_help(format!("the columns are {HEADER}")),
                ),
            }
        }
        let (Some(c_name), Some(c_type)) = (cols[0], cols[1]) else {
            diags.push(
                Diagnostic::new(
                    Code::CsvHeader,
                    "the header of tags.csv needs the columns `name` and `type`",
                    span(&header.span),
                    "header",
                )
                .with_help(format!("start the file with `{HEADER}`")),
            );
            return (table, diags);
        };
        let width = header.fields.len();
        let mut io_owner: HashMap<(Area, u32), usize> = HashMap::new();
        let mut marker_owner: HashMap<u32, usize> = HashMap::new();
        for rec in records {
            if rec.fields.len() > width {
                let extra = &rec.fields[width];
                diags.push(
                    Diagnostic::new(
                        Code::CsvSyntax,
                        format!("this row has {} fields but the header has {width}", rec.fields.len()),
                        span(&extra.span),
                        "extra field",
                    )
                    .with_help("a description with commas must be in double quotes"),
                );
                continue;
            }
            let field = |c: Option<usize>| c.and_then(|i| rec.fields.get(i));
            let text = |c: Option<usize>| field(c).map_or("", |f| f.text.trim());
            let fspan = |c: Option<usize>| field(c).map_or(span(&rec.end()), |f| span(&f.span));
            let mut ok = true;

            let name = text(Some(c_name)).to_string();
            let name_span = fspan(Some(c_name));
            if let Err(msg) = check_tag_name(&name) {
                diags.push(Diagnostic::new(Code::BadTagName, msg, name_span, "tag name"));
                ok = false;
            } else if let Some(prev) = table.get(&name) {
                diags.push(
                    Diagnostic::new(
                        Code::DuplicateTag,
                        format!("tag `{name}` is declared twice"),
                        name_span,
                        "second declaration",
                    )
                    .with_note(prev.span, format!("`{}` first declared here", prev.name))
                    .with_help("tag names are case-insensitive"),
                );
                ok = false;
            }

            let type_text = text(Some(c_type));
            let ty = match DataType::parse(type_text) {
                Some(t) => Some(t),
                None => {
                    let found = if type_text.is_empty() {
                        "nothing".to_string()
                    } else {
                        format!("`{type_text}`")
                    };
                    diags.push(
                        Diagnostic::new(
                            Code::UnknownType,
                            format!("unknown type {found}"),
                            fspan(Some(c_type)),
                            "expected a data type",
                        )
                        .with_help("types are BOOL SINT INT DINT LINT REAL LREAL TIME TIMER COUNTER PID"),
                    );
                    None
                }
            };

            let addr_text = text(cols[2]);
            let addr_span = fspan(cols[2]);
            let address = if addr_text.is_empty() || addr_text.eq_ignore_ascii_case("internal") {
                None
            } else {
                match Address::parse(addr_text) {
                    Ok(Some(a)) => Some(a),
                    Ok(None)
                        if matches!(
                            crate::address::slc::parse(&addr_text.to_ascii_uppercase(), addr_text),
                            Ok(Some(crate::address::slc::Slc::Struct(..)))
                        ) =>
                    {
                        diags.push(
                            Diagnostic::new(
                                Code::BadAddress,
                                format!(
                                    "`{addr_text}` is an SLC 500 timer or counter, a structure rather than an address"
                                ),
                                addr_span,
                                "not an address",
                            )
                            .with_help("name it in a program (TON(T4:0,10,0,s), XIC(C5:1.DN)), or declare a TIMER or COUNTER tag without an address"),
                        );
                        ok = false;
                        None
                    }
                    Ok(None) => {
                        diags.push(
                            Diagnostic::new(
                                Code::BadAddress,
                                format!("`{addr_text}` is not an address"),
                                addr_span,
                                "expected an address",
                            )
                            .with_help("for example DI:1/0, %QX0.1, I0.2, AIW0, MW10; leave empty for an internal tag"),
                        );
                        ok = false;
                        None
                    }
                    Err(msg) => {
                        diags.push(Diagnostic::new(Code::BadAddress, msg, addr_span, "bad address"));
                        ok = false;
                        None
                    }
                }
            };
            if let (Some(t), Some(a)) = (ty, address.as_ref())
                && (t.is_struct() || !a.allowed_types().contains(&t))
            {
                let allowed: Vec<_> = a.allowed_types().iter().map(|t| t.name()).collect();
                diags.push(
                    Diagnostic::new(
                        Code::TypeAddressMismatch,
                        format!("a {t} tag cannot be on {addr_text}"),
                        addr_span,
                        format!("this address holds {}", allowed.join(" or ")),
                    )
                    .with_note(fspan(Some(c_type)), "type declared here"),
                );
                ok = false;
            }
            if let Some(a) = address {
                let (start, end) = a.footprint();
                let owner = if a.area() == Area::Marker {
                    (start..end).find_map(|b| marker_owner.get(&b).copied())
                } else {
                    io_owner.get(&(a.area(), start)).copied()
                };
                if let Some(i) = owner {
                    let prev: &Tag = &table.tags[i];
                    diags.push(
                        Diagnostic::new(
                            Code::AddressUsedTwice,
                            format!(
                                "address {addr_text} is already used by `{}` ({})",
                                prev.name,
                                prev.address_text.as_deref().unwrap_or("")
                            ),
                            addr_span,
                            "used twice",
                        )
                        .with_note(prev.span, "first user"),
                    );
                    ok = false;
                }
            }

            let init_text = text(cols[3]);
            let mut members = Vec::new();
            if ty == Some(DataType::Pid) && !init_text.is_empty() {
                match parse_members(init_text, DataType::Pid) {
                    Ok(m) => {
                        if let Some((_, _, msg)) = pid_params(&m).check() {
                            diags.push(
                                Diagnostic::new(Code::PidParameter, msg, fspan(cols[3]), "invalid loop parameter")
                                    .with_help("the PID section of docs/ladder.md lists the members and their ranges"),
                            );
                            ok = false;
                        }
                        members = m;
                    }
                    Err(msg) => {
                        diags.push(
                            Diagnostic::new(Code::PidParameter, msg, fspan(cols[3]), "bad PID parameter list")
                                .with_help("write MEMBER=value pairs separated by `;`, e.g. `KP=5;KI=0.8;UPD=640`"),
                        );
                        ok = false;
                    }
                }
            }
            let initial = match ty {
                Some(DataType::Pid) => None,
                Some(t) if !init_text.is_empty() => match Value::parse(init_text, t) {
                    Ok(v) => Some(v),
                    Err(msg) => {
                        diags.push(Diagnostic::new(
                            Code::BadInitialValue,
                            format!("bad initial value for `{name}`: {msg}"),
                            fspan(cols[3]),
                            format!("expected {} value", t.with_article()),
                        ));
                        ok = false;
                        None
                    }
                },
                _ => None,
            };

            let retain_text = text(cols[4]).to_ascii_lowercase();
            let retain = match retain_text.as_str() {
                "" | "0" | "false" | "no" => false,
                "1" | "true" | "yes" => true,
                _ => {
                    diags.push(Diagnostic::new(
                        Code::BadRetain,
                        format!("`{}` is not a retain flag", text(cols[4])),
                        fspan(cols[4]),
                        "expected 0, 1, true, false, yes or no",
                    ));
                    ok = false;
                    false
                }
            };

            let (Some(ty), true) = (ty, ok) else { continue };
            let idx = table.tags.len();
            if let Some(a) = address {
                let (start, end) = a.footprint();
                if a.area() == Area::Marker {
                    for b in start..end {
                        marker_owner.insert(b, idx);
                    }
                } else {
                    io_owner.insert((a.area(), start), idx);
                }
            }
            table.push(Tag {
                name,
                ty,
                address,
                address_text: address.map(|_| addr_text.to_string()),
                initial,
                members,
                retain,
                description: text(cols[5]).to_string(),
                span: name_span,
            });
        }
        (table, diags)
    }

    /// Writes the table in `tags.csv` form (the canonical header and order).
    pub fn to_csv(&self) -> String {
        let mut out = String::from(HEADER);
        out.push('\n');
        for t in &self.tags {
            let fields = [
                t.name.clone(),
                t.ty.name().to_string(),
                t.address_text.clone().unwrap_or_default(),
                if t.members.is_empty() {
                    t.initial.map(|v| v.to_string()).unwrap_or_default()
                } else {
                    t.members
                        .iter()
                        .map(|(m, v)| format!("{m}={v}"))
                        .collect::<Vec<_>>()
                        .join(";")
                },
                if t.retain { "1".into() } else { String::new() },
                t.description.clone(),
            ];
            let quoted: Vec<String> = fields.iter().map(|f| quote(f)).collect();
            out.push_str(&quoted.join(","));
            out.push('\n');
        }
        out
    }
}

fn quote(f: &str) -> String {
    if f.contains([',', '"', '\n', '\r']) || f.starts_with(' ') || f.ends_with(' ') {
        format!("\"{}\"", f.replace('"', "\"\""))
    } else {
        f.to_string()
    }
}

/// Levenshtein distance, for suggestions.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb)).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The parameters of a PID loop given as `MEMBER=value` pairs over the
/// defaults (kept here rather than in `types`, which `value` imports).
fn pid_params(members: &[(String, Value)]) -> PidParams {
    let get = |n: &str| {
        members
            .iter()
            .find(|(m, _)| m.eq_ignore_ascii_case(n))
            .map(|(_, v)| v.as_f64())
            .or_else(|| PID_DEFAULTS.iter().find(|(m, _)| *m == n).map(|(_, v)| *v))
            .unwrap_or(0.0)
    };
    PidParams {
        kp: get("KP"),
        ki: get("KI"),
        kd: get("KD"),
        kc: get("KC"),
        ti: get("TI"),
        td: get("TD"),
        maxs: get("MAXS"),
        mins: get("MINS"),
        db: get("DB"),
        maxo: get("MAXO"),
        mino: get("MINO"),
        dfn: get("DFN"),
        maxi: get("MAXI"),
        mini: get("MINI"),
        maxcv: get("MAXCV"),
        mincv: get("MINCV"),
        bias: get("BIAS"),
        upd: get("UPD"),
        form: get("FORM"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alba_diag::Files;

    fn parse(text: &str) -> (TagTable, Vec<Diagnostic>, Files) {
        let mut files = Files::new();
        let f = files.add("tags.csv", text);
        let (t, d) = TagTable::parse(text, f);
        (t, d, files)
    }

    #[test]
    fn spec_example_parses() {
        let (t, d, _) = parse(
            "name,type,address,initial,retain,description\n\
             Start,BOOL,DI:1/0,,,start button\n\
             Level,DINT,AI:3/0,,,raw level 0-1023\n\
             Delay,TIMER,,,,\n\
             Count,DINT,,7,,\n",
        );
        assert!(d.is_empty(), "{d:?}");
        assert_eq!(t.len(), 4);
        assert_eq!(t.get("count").unwrap().initial, Some(Value::Dint(7)));
        assert_eq!(t.get("START").unwrap().address, Some(Address::DigitalIn(0)));
        assert!(t.get("start").unwrap().is_input());
    }

    #[test]
    fn every_bad_row_is_reported_with_its_column() {
        let text = "name,type,address,initial,retain,description\n\
                    Good,BOOL,,,,\n\
                    good,BOOL,,,,\n\
                    X,WORD,,,,\n\
                    Y,BOOL,DI:9/0,,,\n\
                    Z,REAL,DI:1/1,,,\n\
                    A,INT,,99999,,\n\
                    B,BOOL,%IX0.2,,,\n\
                    C,BOOL,DI:1/2,,,\n\
                    1bad,BOOL,,,,\n\
                    D,BOOL,,,maybe,\n\
                    P,PID,,UPD=0,,\n\
                    Q,PID,,KP=1;KQ=2,,\n";
        let (t, d, files) = parse(text);
        let got: Vec<String> = d.iter().map(|d| d.short(&files)).collect();
        let expect = [
            "tags.csv:3:1: error[E114]: tag `good` is declared twice",
            "tags.csv:4:3: error[E113]: unknown type `WORD`",
            "tags.csv:5:8: error[E115]: `DI:9/0`: DI addresses use slot 1 (DI:1/n)",
            "tags.csv:6:8: error[E117]: a REAL tag cannot be on DI:1/1",
            "tags.csv:7:8: error[E118]: bad initial value for `A`: 99999 is out of range for INT (-32768 to 32767)",
            "tags.csv:9:8: error[E116]: address DI:1/2 is already used by `B` (%IX0.2)",
            "tags.csv:10:1: error[E112]: `1bad` is not a valid tag name: use letters, digits and `_`, not starting with a digit",
            "tags.csv:11:10: error[E119]: `maybe` is not a retain flag",
            "tags.csv:12:8: error[E121]: PID parameter UPD = 0: the loop update time must be more than 0 ms (SLC error 11H)",
            "tags.csv:13:8: error[E121]: PID has no member `KQ` (writable members: SP CV KP KI KD KC TI TD BIAS MAXO MINO MAXS MINS MAXI MINI MAXCV MINCV DB DFN UPD FORM MAN DIRECT DOE DEP OL TM MINUTES)",
        ];
        assert_eq!(got, expect);
        assert_eq!(t.len(), 2); // Good and B
    }

    /// TI and TD with a unit — the SLC 500's minutes (the `004_…` source's
    /// "Ti 0.1 min/rep") or seconds — are stored in the loop's unit:
    /// seconds, or minutes when MINUTES is set (before or after them); a
    /// plain number is already in the loop's unit. Other members and bad
    /// numbers take no unit.
    #[test]
    fn pid_times_may_be_given_in_minutes_or_seconds() {
        let get = |text: &str, n: &str| {
            let m = parse_members(text, DataType::Pid).expect(text);
            m.iter().find(|(k, _)| k == n).map(|(_, v)| v.as_f64()).expect(n)
        };
        let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
        assert!(near(get("KC=2;TI=0.1min;TD=0.01 MIN", "TI"), 6.0));
        assert!(near(get("KC=2;TI=0.1min;TD=0.01 MIN", "TD"), 0.6));
        assert!(near(get("KC=2;TI=0.1min", "KC"), 2.0));
        assert!(near(get("TI=6", "TI"), 6.0));
        assert!(near(get("TI=6 s", "TI"), 6.0));
        assert!(near(get("MINUTES=1;TI=0.1min", "TI"), 0.1));
        assert!(near(get("TI=0.1min;TD=1.2s;MINUTES=1", "TI"), 0.1));
        assert!(near(get("TI=0.1min;TD=1.2s;MINUTES=1", "TD"), 0.02));
        assert!(near(get("MINUTES=1;TI=0.25", "TI"), 0.25));
        assert!(near(get("MINUTES=0;TI=0.25min", "TI"), 15.0));
        for bad in ["TI=xmin", "KP=2min", "TD=min", "TI=3h", "KC=2s", "TD=s"] {
            let e = parse_members(bad, DataType::Pid).expect_err(bad);
            assert!(e.to_string().contains("bad value for"), "{bad}: {e}");
        }
    }

    #[test]
    fn overlapping_markers_are_the_same_address() {
        let (_, d, files) = parse("name,type,address\nW,INT,MW2\nB,BOOL,M3.0\nD,DINT,%MD1\n");
        let got: Vec<String> = d.iter().map(|d| d.short(&files)).collect();
        assert_eq!(
            got,
            ["tags.csv:3:8: error[E116]: address M3.0 is already used by `W` (MW2)"]
        );
    }

    #[test]
    fn slc_500_addresses_are_tag_addresses_and_their_errors_are_located() {
        let (t, d, files) = parse(
            "name,type,address\nStart,BOOL,I:1/0\nLamp,BOOL,O:0/3\nRef,INT,N7:2\nFlag,BOOL,B3:0/1\nGain,REAL,F8:0\n",
        );
        assert!(
            d.is_empty(),
            "{:?}",
            d.iter().map(|d| d.short(&files)).collect::<Vec<_>>()
        );
        assert_eq!(t.get("start").unwrap().address, Some(Address::DigitalIn(16)));
        assert!(t.get("start").unwrap().is_input());
        assert_eq!(t.get("lamp").unwrap().address, Some(Address::DigitalOut(3)));
        // B3 is MW0: a tag on B3:0/1 (M1.1) and one on MW0 share a place.
        let (_, d, files) = parse("name,type,address\nW,INT,MW0\nFlag,BOOL,B3:0/1\n");
        let got: Vec<String> = d.iter().map(|d| d.short(&files)).collect();
        assert_eq!(
            got,
            ["tags.csv:3:11: error[E116]: address B3:0/1 is already used by `W` (MW0)"]
        );
        let (_, d, files) = parse("name,type,address\nA,INT,N7:256\nB,TIMER,T4:0\nC,INT,N12:0\nD,INT,F8:0\n");
        let got: Vec<String> = d.iter().map(|d| d.short(&files)).collect();
        assert_eq!(got.len(), 4, "{got:?}");
        assert!(
            got[0].starts_with("tags.csv:2:7: error[E115]: `N7:256`: elements go from 0 to 255"),
            "{got:?}"
        );
        assert!(
            got[1].starts_with("tags.csv:3:9: error[E115]: `T4:0` is an SLC 500 timer or counter"),
            "{got:?}"
        );
        assert!(got[2].contains("N12 is not one of them"), "{got:?}");
        // F8 is REAL (a double word): an INT does not fit it.
        assert!(got[3].contains("E117"), "{got:?}");
    }

    #[test]
    fn header_may_reorder_and_omit_columns_but_not_invent_them() {
        let (t, d, _) = parse("type,name\nBOOL,A\n");
        assert!(d.is_empty());
        assert_eq!(t.get("a").unwrap().ty, DataType::Bool);
        let (_, d, files) = parse("name,type,colour\n");
        assert_eq!(
            d[0].short(&files),
            "tags.csv:1:11: error[E111]: unknown column `colour` in the header"
        );
        let (_, d, _) = parse("");
        assert_eq!(d[0].code, Code::CsvHeader);
    }

    #[test]
    fn names_that_read_as_addresses_or_keywords_are_refused() {
        for n in ["MW2", "I0.1", "Ain0", "true", "mod", "a-b", ""] {
            assert!(check_tag_name(n).is_err(), "{n}");
        }
        for n in ["M1", "Motor_1", "_x", "Q5"] {
            assert!(check_tag_name(n).is_ok(), "{n}");
        }
    }

    #[test]
    fn csv_round_trips() {
        let text = "name,type,address,initial,retain,description\nA,BOOL,DI:1/0,1,1,\"a, b\"\nT,TIMER,,,,\n";
        let (t, d, _) = parse(text);
        assert!(d.is_empty());
        assert_eq!(t.to_csv(), text);
    }

    #[test]
    fn suggestions_find_near_names() {
        let (t, _, _) = parse("name,type\nStart,BOOL\nStop,BOOL\n");
        assert_eq!(t.suggest("Strat"), Some("Start"));
        assert_eq!(t.suggest("Zzzzzz"), None);
    }
}
