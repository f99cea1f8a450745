//! Studio 5000 `.L5X` exports: controller and program tags, aliases to I/O,
//! and RLL routines, whose rungs are already in Rockwell's neutral text —
//! the text Alba's ladder reads — so a rung is kept as written, with its
//! operands renamed (program tags, aliases, I/O) and `?` presets filled from
//! the tag data.
//!
//! I/O (documented in docs/interchange.md): digital points `Mod:S:I.Data.B` and
//! `Mod:S:I.Data[W].B` become `DI` channels and `Mod:S:O.Data.B` `DO`
//! channels; every (module, slot, word) used gets a block of 32 channels, in
//! the order module, slot, word. Analog `Mod:S:I.ChNData` become `AI`
//! channels and `Mod:S:O.ChNData` `AO` channels, 16 a slot. With one
//! digital input module in slot 1, `Local:1:I.Data.0` is `DI:1/0`; with one
//! output module, `Local:2:O.Data.0` is `DO:2/0`.
//!
//! A `JSR` without parameters at the end of a rung is inlined: the called
//! routine's rungs in place, behind a `JMP` over them while the rung is false.
//!
//! A tag of a user-defined type is a tag per member (`Tag.Member` →
//! `Tag_Member`); the BIT members Studio 5000 packs into a hidden SINT are
//! marker bits over a marker byte, so the SINT and its bits stay one value.
//! Empty branch legs (wires) are written out where Alba's ladder can say
//! the same without them.
//!
//! Refused, with their place: arrays (Alba has no arrays), other structured
//! types, produced/consumed tags, JSR with parameters, SBR/RET, recursion,
//! routines never called, non-RLL routines, rungs with instructions Alba
//! does not have.

use crate::names::Names;
use crate::plcopen::Ctx;
use crate::{Error, Kind, Location, Options, ProgramOut, Project, Report, TagOut};
use alba_xml::Elem;
use std::collections::{BTreeMap, HashMap};

/// Alba's ladder instructions (docs/ladder.md §4.2).
const ALBA_INSTRUCTIONS: &[&str] = &[
    "XIC", "XIO", "OTE", "OTL", "OTU", "ONS", "OSR", "OSF", "TON", "TOF", "RTO", "TP", "CTU", "CTD", "RES", "LIM",
    "EQU", "NEQ", "LES", "GRT", "LEQ", "GEQ", "MEQ", "ADD", "SUB", "MUL", "DIV", "MOD", "XPY", "SQR", "NEG", "ABS",
    "LN", "LOG", "CPT", "SCP", "MOV", "CLR", "AND", "OR", "XOR", "NOT", "SIN", "COS", "TAN", "ASN", "ACS", "ATN",
    "DEG", "RAD", "JMP", "LBL", "AFI", "NOP", "TOD", "FRD",
];

/// Functions inside CPT expressions (left as they are).
const CPT_FUNCTIONS: &[&str] = &[
    "SQRT", "SQR", "ABS", "LN", "LOG", "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN", "ASN", "ACS", "ATN", "DEG", "RAD",
    "ROUND", "ATAN2", "TRN", "FRD", "TOD", "NOT",
];

#[derive(Debug, Clone)]
enum Sym {
    /// An Alba tag: the name, and for TIMER/COUNTER the PRE and ACC data.
    Tag { alba: String, data: Option<(i64, i64)> },
    /// An alias: the operand text it stands for.
    Alias(String),
    /// A tag of a user-defined type: its members by lower-case name.
    Struct(HashMap<String, Sym>),
    /// Refused (why).
    Refused(String),
}

/// User-defined types nested deeper are refused.
const MAX_UDT_DEPTH: usize = 8;

/// Members of user-defined types read for one tag, and in one project
/// (each a tag or a refusal): nested types multiply (ten members of ten
/// members … eight deep), so hostile input is capped.
const MAX_TAG_MEMBERS: usize = 10_000;
const MAX_MEMBERS: usize = 200_000;

/// Marker bytes for the BIT members of user-defined types (docs/file-formats.md §4.2).
const MARKER_BYTES: usize = 4096;

#[derive(Default)]
struct Io {
    /// (module, slot, word) → first channel.
    di: BTreeMap<(String, u32, u32), usize>,
    r#do: BTreeMap<(String, u32, u32), usize>,
    ai: BTreeMap<(String, u32), usize>,
    ao: BTreeMap<(String, u32), usize>,
}

/// A parsed I/O point: `Local:1:I.Data.0` and friends.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Point {
    Digital {
        output: bool,
        module: String,
        slot: u32,
        word: u32,
        bit: u32,
    },
    Analog {
        output: bool,
        module: String,
        slot: u32,
        ch: u32,
    },
}

fn parse_point(s: &str) -> Option<Point> {
    let mut parts = s.trim().splitn(3, ':');
    let module = parts.next()?.to_string();
    let slot: u32 = parts.next()?.parse().ok()?;
    let rest = parts.next()?;
    let (dir, member) = rest.split_once('.')?;
    let output = match dir.to_ascii_uppercase().as_str() {
        "I" => false,
        "O" => true,
        _ => return None,
    };
    let up = member.to_ascii_uppercase();
    if let Some(r) = up.strip_prefix("DATA") {
        // .Data.B or .Data[W].B
        let (word, bit) = if let Some(r) = r.strip_prefix('[') {
            let (w, b) = r.split_once("].")?;
            (w.parse().ok()?, b.parse().ok()?)
        } else {
            (0, r.strip_prefix('.')?.parse().ok()?)
        };
        if bit > 31 || word > 255 {
            return None;
        }
        return Some(Point::Digital {
            output,
            module,
            slot,
            word,
            bit,
        });
    }
    if let Some(r) = up.strip_prefix("CH") {
        let ch: String = r.chars().take_while(|c| c.is_ascii_digit()).collect();
        let tail = &r[ch.len()..];
        if (tail == "DATA" || tail == "DATA.") && !ch.is_empty() {
            let ch: u32 = ch.parse().ok()?;
            if ch < 16 {
                return Some(Point::Analog {
                    output,
                    module,
                    slot,
                    ch,
                });
            }
        }
    }
    None
}

impl Io {
    fn collect(&mut self, p: &Point) {
        match p {
            Point::Digital {
                output,
                module,
                slot,
                word,
                ..
            } => {
                let m = if *output { &mut self.r#do } else { &mut self.di };
                m.insert((module.to_ascii_lowercase(), *slot, *word), 0);
            }
            Point::Analog {
                output, module, slot, ..
            } => {
                let m = if *output { &mut self.ao } else { &mut self.ai };
                m.insert((module.to_ascii_lowercase(), *slot), 0);
            }
        }
    }

    fn number(&mut self) {
        for (i, v) in self.di.values_mut().enumerate() {
            *v = i * 32;
        }
        for (i, v) in self.r#do.values_mut().enumerate() {
            *v = i * 32;
        }
        for (i, v) in self.ai.values_mut().enumerate() {
            *v = i * 16;
        }
        for (i, v) in self.ao.values_mut().enumerate() {
            *v = i * 16;
        }
    }

    fn address(&self, p: &Point) -> Option<String> {
        Some(match p {
            Point::Digital {
                output,
                module,
                slot,
                word,
                bit,
            } => {
                let m = if *output { &self.r#do } else { &self.di };
                let base = m.get(&(module.to_ascii_lowercase(), *slot, *word))?;
                let n = base + *bit as usize;
                if *output {
                    format!("DO:2/{n}")
                } else {
                    format!("DI:1/{n}")
                }
            }
            Point::Analog {
                output,
                module,
                slot,
                ch,
            } => {
                let m = if *output { &self.ao } else { &self.ai };
                let base = m.get(&(module.to_ascii_lowercase(), *slot))?;
                let n = base + *ch as usize;
                if *output {
                    format!("AO:4/{n}")
                } else {
                    format!("AI:3/{n}")
                }
            }
        })
    }
}

fn cdata(e: Option<&Elem>) -> String {
    e.map(|e| e.text.trim().to_string()).unwrap_or_default()
}

/// Bits of a Logix integer type.
fn int_bits(ty: &str) -> Option<u32> {
    match ty {
        "SINT" => Some(8),
        "INT" => Some(16),
        "DINT" => Some(32),
        "LINT" => Some(64),
        _ => None,
    }
}

/// A value as Studio 5000 writes it in decorated data, in the radix of its
/// tag (`8#00_000_002_322`, `16#ff`, `2#0000_0001`, `'$00AB'`, `1.5e+002`),
/// as Alba's literal for the type `ty`: a based or ASCII value is the
/// two's complement of the type's bits (`16#ff` of a SINT is -1).
fn logix_value(v: &str, ty: &str) -> Option<String> {
    let v = v.trim();
    if ty == "BOOL" {
        return matches!(v, "0" | "1").then(|| v.to_string());
    }
    if ty == "REAL" || ty == "LREAL" {
        let f: f64 = v.parse().ok()?;
        return f.is_finite().then(|| format!("{f:?}"));
    }
    let bits = int_bits(ty)?;
    let raw: u64 = if let Some(ascii) = v.strip_prefix('\'').and_then(|a| a.strip_suffix('\'')) {
        // Characters, most significant byte first; `$hh`, `$$`, `$'` and
        // IEC's `$L` `$N` `$P` `$R` `$T` escapes.
        let mut n: u64 = 0;
        let mut chars = ascii.chars();
        let mut count = 0;
        while let Some(c) = chars.next() {
            let byte = if c == '$' {
                match chars.next()? {
                    '$' => b'$',
                    '\'' => b'\'',
                    'L' | 'l' | 'N' | 'n' => b'\n',
                    'P' | 'p' => 0x0c,
                    'R' | 'r' => b'\r',
                    'T' | 't' => b'\t',
                    h1 => {
                        let h2 = chars.next()?;
                        if !h1.is_ascii_hexdigit() || !h2.is_ascii_hexdigit() {
                            return None;
                        }
                        u8::from_str_radix(&format!("{h1}{h2}"), 16).ok()?
                    }
                }
            } else if c.is_ascii() {
                c as u8
            } else {
                return None;
            };
            count += 1;
            if count * 8 > bits {
                return None;
            }
            n = (n << 8) | u64::from(byte);
        }
        n
    } else if let Some((base, digits)) = v.split_once('#') {
        let radix = match base {
            "2" => 2,
            "8" => 8,
            "16" => 16,
            "10" => 10,
            _ => return None,
        };
        let digits: String = digits.chars().filter(|c| *c != '_').collect();
        let n = u64::from_str_radix(&digits, radix).ok()?;
        if bits < 64 && n >> bits != 0 {
            return None;
        }
        n
    } else {
        let n: i64 = v.parse().ok()?;
        let (lo, hi) = if bits == 64 {
            (i64::MIN, i64::MAX)
        } else {
            (-(1i64 << (bits - 1)), (1i64 << (bits - 1)) - 1)
        };
        return (lo..=hi).contains(&n).then(|| n.to_string());
    };
    // Sign-extend the `bits` low bits.
    let shift = 64 - bits;
    Some((((raw << shift) as i64) >> shift).to_string())
}

/// PRE and ACC of a TIMER/COUNTER value: an element holding its decorated
/// `DataValueMember`s (a `Structure` or a `StructureMember`).
fn pre_acc(s: &Elem) -> Option<(i64, i64)> {
    let get = |n: &str| {
        s.all("DataValueMember")
            .find(|m| m.attr("Name").is_some_and(|x| x.eq_ignore_ascii_case(n)))
            .and_then(|m| m.attr("Value"))
            .and_then(|v| logix_value(v, "DINT"))
            .and_then(|v| v.parse::<i64>().ok())
    };
    Some((get("PRE")?, get("ACC")?))
}

/// PRE and ACC of a TIMER/COUNTER tag's data (decorated or L5K).
fn struct_data(tag: &Elem) -> Option<(i64, i64)> {
    for d in tag.all("Data") {
        match d.attr("Format") {
            Some("Decorated") => {
                if let Some(pa) = d.child("Structure").and_then(pre_acc) {
                    return Some(pa);
                }
            }
            Some("L5K") => {
                let t = d.text.trim().trim_start_matches('[').trim_end_matches(']').to_string();
                let v: Vec<i64> = t.split(',').filter_map(|x| x.trim().parse().ok()).collect();
                if v.len() >= 3 {
                    return Some((v[1], v[2]));
                }
            }
            _ => {}
        }
    }
    None
}

/// The initial value of a scalar tag of type `ty`: `Ok(None)` when its data
/// is absent or zero, `Err(text)` when the data is there but not readable.
fn scalar_data(tag: &Elem, ty: &str) -> Result<Option<String>, String> {
    // L5K data is decimal whatever the tag's radix; decorated data is in
    // the radix.
    let mut seen = None;
    for d in tag.all("Data") {
        let text = match d.attr("Format") {
            Some("L5K") => d.text.trim().to_string(),
            Some("Decorated") => match d.child("DataValue").and_then(|v| v.attr("Value")) {
                Some(v) => v.trim().to_string(),
                None => continue,
            },
            _ => continue,
        };
        match logix_value(&text, ty) {
            Some(v) => return Ok(nonzero(v)),
            None => seen = Some(text),
        }
    }
    seen.map_or(Ok(None), Err)
}

/// `None` for a zero value (tags.csv leaves it out).
fn nonzero(v: String) -> Option<String> {
    (v != "0" && v != "0.0").then_some(v)
}

struct Conv<'a> {
    ctx: Ctx<'a>,
    report: Report,
    names: Names,
    tags: Vec<TagOut>,
    io: Io,
    /// Tags aliased to I/O points, declared once the I/O is numbered.
    io_tags: Vec<(usize, Point)>,
    /// The controller's user-defined types by lower-case name.
    udts: HashMap<String, &'a Elem>,
    /// The next free marker byte.
    next_marker: usize,
    /// Members read so far, in the project and for the tag being declared
    /// (see [`MAX_MEMBERS`]).
    members: usize,
    tag_members: usize,
}

impl<'a> Conv<'a> {
    fn declare(&mut self, tags: &Elem, scope: &mut HashMap<String, Sym>, owner: Option<&str>) {
        for t in tags.all("Tag") {
            let loc = self.ctx.loc(t);
            let Some(name) = t.attr("Name") else {
                self.report.push(Kind::Refused, loc, "a tag without a name");
                continue;
            };
            let key = name.to_ascii_lowercase();
            let refuse = |me: &mut Self, scope: &mut HashMap<String, Sym>, why: String| {
                me.report
                    .push(Kind::Refused, loc.clone(), format!("tag `{name}`: {why}"));
                scope.insert(key.clone(), Sym::Refused(why));
            };
            let tag_type = t.attr("TagType").unwrap_or("Base");
            if tag_type == "Alias" {
                let target = t.attr("AliasFor").unwrap_or("").trim().to_string();
                if let Some(p) = parse_point(&target) {
                    self.io.collect(&p);
                    let alba = self.alba_name(name, owner, &loc);
                    self.io_tags.push((self.tags.len(), p));
                    self.tags.push(TagOut {
                        name: alba.clone(),
                        ty: String::new(),
                        address: String::new(),
                        initial: String::new(),
                        description: cdata(t.child("Description")),
                    });
                    scope.insert(key, Sym::Tag { alba, data: None });
                } else if target.contains(':') {
                    refuse(
                        self,
                        scope,
                        format!("alias for `{target}`, an I/O point Alba does not map"),
                    );
                } else {
                    scope.insert(key, Sym::Alias(target));
                }
                continue;
            }
            if tag_type != "Base" {
                refuse(self, scope, format!("{tag_type} tags are not converted"));
                continue;
            }
            if t.attr("Dimensions")
                .is_some_and(|d| !d.trim().is_empty() && d.trim() != "0")
            {
                let dims = t.attr("Dimensions").unwrap_or("");
                refuse(self, scope, format!("an array [{dims}]: Alba has no arrays"));
                continue;
            }
            let dt_raw = t.attr("DataType").unwrap_or("");
            let dt = dt_raw.to_ascii_uppercase();
            let ty = match dt.as_str() {
                "BOOL" | "SINT" | "INT" | "DINT" | "LINT" | "REAL" | "LREAL" | "TIMER" | "COUNTER" => dt.clone(),
                _ => {
                    if let Some(udt) = self.udts.get(&dt.to_ascii_lowercase()).copied() {
                        let data = t
                            .all("Data")
                            .find(|d| d.attr("Format") == Some("Decorated"))
                            .and_then(|d| d.child("Structure"));
                        let mut notes = Vec::new();
                        self.tag_members = 0;
                        let sym = self.flatten(name, owner, udt, data, &loc, 0, &mut notes);
                        let what = format!(
                            "tag `{name}` of the user-defined type `{dt_raw}`: a tag for each member (`{name}.Member` is `{name}_Member`)"
                        );
                        let what = if notes.is_empty() {
                            what
                        } else {
                            format!("{what}; {}", notes.join("; "))
                        };
                        self.report.push(Kind::Converted, loc.clone(), what);
                        scope.insert(key, sym);
                        continue;
                    }
                    refuse(self, scope, format!("data type `{dt_raw}` is not one Alba has"));
                    continue;
                }
            };
            let alba = self.alba_name(name, owner, &loc);
            let mut initial = String::new();
            let mut data = None;
            if ty == "TIMER" || ty == "COUNTER" {
                data = struct_data(t);
            } else {
                match scalar_data(t, &ty) {
                    Ok(v) => initial = v.unwrap_or_default(),
                    Err(v) => self.report.push(
                        Kind::Approximated,
                        loc.clone(),
                        format!("tag `{name}`: its value `{v}` is not a {ty}; it starts at 0"),
                    ),
                }
            }
            self.tags.push(TagOut {
                name: alba.clone(),
                ty,
                address: String::new(),
                initial,
                description: cdata(t.child("Description")),
            });
            scope.insert(key, Sym::Tag { alba, data });
        }
    }

    /// The members of a tag (`path`, `Tag` or `Tag.Member`) of the
    /// user-defined type `udt` as tags, `data` its decorated value. A BIT
    /// member is a bit of a SINT member (Studio 5000 packs BOOLs so): that
    /// SINT gets a marker byte and its BIT members the marker bits over it,
    /// so writing either changes the other, as in Logix.
    #[allow(clippy::too_many_arguments)]
    fn flatten(
        &mut self,
        path: &str,
        owner: Option<&str>,
        udt: &'a Elem,
        data: Option<&Elem>,
        loc: &Location,
        depth: usize,
        notes: &mut Vec<String>,
    ) -> Sym {
        let members: Vec<&Elem> = udt
            .child("Members")
            .map(|m| m.all("Member").collect())
            .unwrap_or_default();
        let name_of = |m: &Elem| m.attr("Name").unwrap_or("").to_string();
        let ty_of = |m: &Elem| m.attr("DataType").unwrap_or("").to_ascii_uppercase();
        // SINT members holding BIT members → their marker byte.
        let mut hosts: HashMap<String, Result<usize, String>> = HashMap::new();
        for m in members.iter().filter(|m| ty_of(m) == "BIT") {
            let target = m.attr("Target").unwrap_or("").to_ascii_lowercase();
            if hosts.contains_key(&target) {
                continue;
            }
            let host = members.iter().find(|h| name_of(h).eq_ignore_ascii_case(&target));
            let r = match host.map(|h| ty_of(h)) {
                Some(t) if t == "SINT" => {
                    if self.next_marker < MARKER_BYTES {
                        self.next_marker += 1;
                        Ok(self.next_marker - 1)
                    } else {
                        Err(format!("the {MARKER_BYTES} marker bytes are used up"))
                    }
                }
                Some(t) => Err(format!("BIT members on a {t}, not a SINT")),
                None => Err(format!("BIT members on `{target}`, which is not a member")),
            };
            hosts.insert(target, r);
        }
        let mut map = HashMap::new();
        for m in members {
            if self.tag_members >= MAX_TAG_MEMBERS || self.members >= MAX_MEMBERS {
                // Said once, where it happened (the callers stop quietly).
                if self.tag_members <= MAX_TAG_MEMBERS {
                    let why = if self.members >= MAX_MEMBERS {
                        format!("more than {MAX_MEMBERS} members of user-defined types in the project")
                    } else {
                        format!("more than {MAX_TAG_MEMBERS} members in one tag")
                    };
                    self.report.push(
                        Kind::Refused,
                        loc.clone(),
                        format!("`{path}`: {why}; the rest are left out"),
                    );
                    self.tag_members = MAX_TAG_MEMBERS + 1;
                }
                break;
            }
            self.members += 1;
            self.tag_members += 1;
            let mname = name_of(m);
            let key = mname.to_ascii_lowercase();
            let mpath = format!("{path}.{mname}");
            let mty = ty_of(m);
            let value = data.and_then(|d| {
                d.children
                    .iter()
                    .find(|c| c.attr("Name").is_some_and(|n| n.eq_ignore_ascii_case(&mname)))
            });
            let refused = |me: &mut Self, why: String| {
                me.report
                    .push(Kind::Refused, loc.clone(), format!("member `{mpath}`: {why}"));
                Sym::Refused(why)
            };
            let sym = if m
                .attr("Dimension")
                .is_some_and(|d| d.trim() != "0" && !d.trim().is_empty())
            {
                refused(self, "an array (Alba has no arrays)".into())
            } else if let Some(host) = hosts.get(&key) {
                match host {
                    Ok(k) => {
                        notes.push(format!("`{mpath}` is the marker byte %MB{k}, its BIT members its bits"));
                        Sym::Tag {
                            alba: format!("%MB{k}"),
                            data: None,
                        }
                    }
                    Err(why) => refused(self, why.clone()),
                }
            } else if mty == "BIT" {
                let target = m.attr("Target").unwrap_or("").to_ascii_lowercase();
                let bit = m.attr("BitNumber").and_then(|b| b.trim().parse::<u8>().ok());
                match (hosts.get(&target), bit) {
                    (Some(Ok(k)), Some(b)) if b < 8 => {
                        let initial = value
                            .and_then(|v| v.attr("Value"))
                            .and_then(|v| logix_value(v, "BOOL"))
                            .and_then(nonzero)
                            .unwrap_or_default();
                        let alba = self.member_tag(&mpath, owner, loc, "BOOL", &format!("%MX{k}.{b}"), initial, m);
                        Sym::Tag { alba, data: None }
                    }
                    (Some(Err(why)), _) => refused(self, why.clone()),
                    _ => refused(self, "a BIT member without a bit 0…7 of a SINT member".into()),
                }
            } else if matches!(
                mty.as_str(),
                "BOOL" | "SINT" | "INT" | "DINT" | "LINT" | "REAL" | "LREAL" | "TIMER" | "COUNTER"
            ) {
                let (initial, data) = if mty == "TIMER" || mty == "COUNTER" {
                    (String::new(), value.and_then(pre_acc))
                } else {
                    let v = value
                        .and_then(|v| v.attr("Value"))
                        .and_then(|v| logix_value(v, &mty))
                        .and_then(nonzero)
                        .unwrap_or_default();
                    (v, None)
                };
                let alba = self.member_tag(&mpath, owner, loc, &mty, "", initial, m);
                Sym::Tag { alba, data }
            } else if let Some(sub) = self.udts.get(&mty.to_ascii_lowercase()).copied() {
                if depth + 1 >= MAX_UDT_DEPTH {
                    refused(self, format!("user-defined types nested deeper than {MAX_UDT_DEPTH}"))
                } else {
                    self.flatten(&mpath, owner, sub, value, loc, depth + 1, notes)
                }
            } else {
                refused(
                    self,
                    format!("data type `{}` is not one Alba has", m.attr("DataType").unwrap_or("")),
                )
            };
            map.insert(key, sym);
        }
        Sym::Struct(map)
    }

    /// Declares the tag of member `path` (`Tag.Member`): `Tag_Member`.
    #[allow(clippy::too_many_arguments)]
    fn member_tag(
        &mut self,
        path: &str,
        owner: Option<&str>,
        loc: &Location,
        ty: &str,
        address: &str,
        initial: String,
        member: &Elem,
    ) -> String {
        let flat = path.replace('.', "_");
        // The dotted path keys it: a tag really named `Tag_Member` is another.
        let key = format!("{}\u{0}{path}", owner.unwrap_or(""));
        let wanted = match owner {
            Some(o) if self.names.is_taken(&flat) => format!("{o}_{flat}"),
            _ => flat.clone(),
        };
        let (alba, why) = self.names.alba_as(&key, &wanted);
        if alba != flat {
            let why = why.unwrap_or_else(|| format!("`{flat}` is also another tag"));
            self.report.push(
                Kind::Approximated,
                loc.clone(),
                format!("{why}: member `{path}` is tag `{alba}`"),
            );
        }
        let description = match cdata(member.child("Description")) {
            d if d.is_empty() => format!("member {path}"),
            d => d,
        };
        self.tags.push(TagOut {
            name: alba.clone(),
            ty: ty.to_string(),
            address: address.to_string(),
            initial,
            description,
        });
        alba
    }

    fn alba_name(&mut self, name: &str, owner: Option<&str>, loc: &Location) -> String {
        let key = format!("{}\u{0}{name}", owner.unwrap_or(""));
        let wanted = match owner {
            Some(o) if self.names.is_taken(name) => format!("{o}_{name}"),
            _ => name.to_string(),
        };
        let (alba, why) = self.names.alba_as(&key, &wanted);
        if alba != name {
            let why = why.unwrap_or_else(|| format!("`{name}` is also a controller or another program's tag"));
            self.report
                .push(Kind::Approximated, loc.clone(), format!("{why}: tag `{alba}`"));
        }
        alba
    }
}

/// Rewrites the operands of one rung. Errors are refusals of the rung.
fn rewrite(text: &str, scope: &HashMap<String, Sym>, io: &Io) -> Result<String, String> {
    let mut out = String::with_capacity(text.len());
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    // The instruction whose operands we are in, and the operand index.
    let mut stack: Vec<(String, usize)> = Vec::new();
    while i < chars.len() {
        let c = chars[i];
        if c.is_ascii_digit() {
            // A number or a based/duration literal.
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || matches!(chars[i], '.' | '#' | '_')) {
                out.push(chars[i]);
                i += 1;
            }
            continue;
        }
        if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len()
                && (chars[i].is_ascii_alphanumeric() || matches!(chars[i], '_' | ':' | '.' | '[' | ']'))
            {
                i += 1;
            }
            let tok: String = chars[start..i].iter().collect();
            let next = chars[i..].iter().find(|c| !c.is_whitespace()).copied();
            if next == Some('#') {
                // T#5s, 16#FF-like literals with a letter first.
                out.push_str(&tok);
                continue;
            }
            if next == Some('(') {
                let up = tok.to_ascii_uppercase();
                let in_cpt = stack.iter().any(|(m, _)| m == "CPT");
                if up == "JSR" || up == "SBR" || up == "RET" {
                    return Err(format!(
                        "{up}: subroutines are not converted (an Alba program runs every scan)"
                    ));
                }
                if !in_cpt && !ALBA_INSTRUCTIONS.contains(&up.as_str()) {
                    return Err(format!("`{tok}` is not an Alba instruction"));
                }
                if in_cpt && !CPT_FUNCTIONS.contains(&up.as_str()) {
                    return Err(format!("`{tok}` is not a CPT function of Alba"));
                }
                out.push_str(&tok);
                // Skip spaces, then the parenthesis opens below.
                stack.push((up, 0));
                while i < chars.len() && chars[i].is_whitespace() {
                    i += 1;
                }
                if i < chars.len() {
                    out.push('(');
                    i += 1;
                }
                continue;
            }
            // An operand: a tag path, an alias, an I/O point or a system tag.
            out.push_str(&operand(&tok, scope, io, 0)?);
            continue;
        }
        match c {
            '(' => stack.push((String::new(), 0)),
            ')' => {
                stack.pop();
            }
            ',' => {
                if let Some(top) = stack.last_mut() {
                    top.1 += 1;
                }
            }
            _ => {}
        }
        out.push(c);
        i += 1;
    }
    Ok(fill_presets(&out, scope))
}

/// One element of a rung: an instruction's text (and whether it is an
/// output), or a branch of legs.
enum Part {
    Instr(String, bool),
    Branch(Vec<Vec<Part>>),
}

/// Branches nested deeper are left to Alba's parser to refuse.
const MAX_LEG_DEPTH: usize = 64;

/// Reads the elements of a leg up to `,`, `]`, `;` or the end; `None` when
/// the text is not well formed (Alba's parser reports it).
fn parse_leg(c: &[char], i: &mut usize, depth: usize) -> Option<Vec<Part>> {
    let mut leg = Vec::new();
    loop {
        while *i < c.len() && c[*i].is_whitespace() {
            *i += 1;
        }
        match c.get(*i) {
            None | Some(',' | ']' | ';') => return Some(leg),
            Some('[') => {
                if depth >= MAX_LEG_DEPTH {
                    return None;
                }
                *i += 1;
                let mut legs = vec![parse_leg(c, i, depth + 1)?];
                loop {
                    match c.get(*i) {
                        Some(',') => {
                            *i += 1;
                            legs.push(parse_leg(c, i, depth + 1)?);
                        }
                        Some(']') => {
                            *i += 1;
                            break;
                        }
                        _ => return None,
                    }
                }
                leg.push(Part::Branch(legs));
            }
            Some(_) => {
                let start = *i;
                while *i < c.len() && (c[*i].is_ascii_alphanumeric() || c[*i] == '_') {
                    *i += 1;
                }
                let name: String = c[start..*i].iter().collect();
                while *i < c.len() && c[*i].is_whitespace() {
                    *i += 1;
                }
                if name.is_empty() || c.get(*i) != Some(&'(') {
                    return None;
                }
                let mut open = 0usize;
                loop {
                    match c.get(*i)? {
                        '(' => open += 1,
                        ')' => {
                            open -= 1;
                            if open == 0 {
                                *i += 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                    *i += 1;
                }
                let output = alba_ladder::Mnemonic::parse(&name).is_none_or(|m| m.is_output());
                leg.push(Part::Instr(c[start..*i].iter().collect(), output));
            }
        }
    }
}

fn has_output(leg: &[Part]) -> bool {
    leg.iter().any(|p| match p {
        Part::Instr(_, o) => *o,
        Part::Branch(legs) => legs.iter().any(|l| has_output(l)),
    })
}

/// Takes the empty legs out of the branches of `leg`: Logix draws an empty
/// leg as a wire, which Alba's ladder has no instruction for. `tail`: the
/// value at the end of `leg` is read by nothing (it ends the rung, or a leg
/// of a branch that does, …).
fn unwire(leg: Vec<Part>, tail: bool) -> Result<Vec<Part>, String> {
    let n = leg.len();
    let mut out = Vec::new();
    for (k, p) in leg.into_iter().enumerate() {
        let Part::Branch(legs) = p else {
            out.push(p);
            continue;
        };
        let last = tail && k + 1 == n;
        let legs = legs
            .into_iter()
            .map(|l| unwire(l, last))
            .collect::<Result<Vec<_>, _>>()?;
        if !legs.iter().any(Vec::is_empty) {
            out.push(Part::Branch(legs));
        } else if !legs.iter().any(|l| has_output(l)) {
            // Conditions in parallel with a wire: always true.
        } else if last {
            // Outputs in parallel with a wire whose value nothing reads.
            let mut legs: Vec<Vec<Part>> = legs.into_iter().filter(|l| !l.is_empty()).collect();
            if legs.len() == 1 {
                out.append(&mut legs[0]);
            } else {
                out.push(Part::Branch(legs));
            }
        } else {
            return Err(
                "an empty branch leg (a wire) beside outputs, with more instructions after the branch: Alba's ladder has no always-true instruction to stand for it".into(),
            );
        }
    }
    Ok(out)
}

fn print_leg(leg: &[Part], out: &mut String) {
    for p in leg {
        match p {
            Part::Instr(t, _) => out.push_str(t),
            Part::Branch(legs) => {
                out.push('[');
                for (k, l) in legs.iter().enumerate() {
                    if k > 0 {
                        out.push(',');
                    }
                    print_leg(l, out);
                }
                out.push(']');
            }
        }
    }
}

/// A rung with empty branch legs (`XIC(A)[,XIO(B)]OTE(C);`, which Studio
/// 5000 accepts) written without them, if it has any.
fn without_empty_legs(text: &str) -> Result<Option<String>, String> {
    let squeezed: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    if !["[,", ",,", ",]", "[]"].iter().any(|p| squeezed.contains(p)) {
        return Ok(None);
    }
    let c: Vec<char> = text.chars().collect();
    let mut i = 0;
    let Some(leg) = parse_leg(&c, &mut i, 0) else {
        return Ok(None);
    };
    if c.get(i).is_some_and(|x| *x != ';') {
        return Ok(None);
    }
    let mut out = String::new();
    print_leg(&unwire(leg, true)?, &mut out);
    out.push(';');
    Ok(Some(out))
}

/// Alias chains followed (an alias of an alias …); deeper, or a cycle, is refused.
const MAX_ALIAS_CHAIN: usize = 16;

fn operand(tok: &str, scope: &HashMap<String, Sym>, io: &Io, depth: usize) -> Result<String, String> {
    if depth > MAX_ALIAS_CHAIN {
        return Err(format!(
            "`{tok}`: aliases chained more than {MAX_ALIAS_CHAIN} deep (or in a cycle)"
        ));
    }
    let up = tok.to_ascii_uppercase();
    if up.starts_with("S:") {
        return Ok(tok.to_string());
    }
    if let Some(p) = parse_point(tok) {
        return io
            .address(&p)
            .ok_or_else(|| format!("`{tok}` is an I/O point of no aliased module"));
    }
    if tok.contains(':') {
        return Err(format!("`{tok}`: an I/O or module reference Alba does not map"));
    }
    let split = tok.find(['.', '[']).unwrap_or(tok.len());
    let (head, rest) = tok.split_at(split);
    if rest.starts_with('[') {
        return Err(format!("`{tok}`: an array element (Alba has no arrays)"));
    }
    if rest.contains('[') {
        return Err(format!(
            "`{tok}`: an indirect address or an array member (Alba has neither)"
        ));
    }
    match scope.get(&head.to_ascii_lowercase()) {
        Some(Sym::Tag { alba, .. }) => Ok(format!("{alba}{rest}")),
        Some(Sym::Struct(members)) => member(tok, members, rest),
        Some(Sym::Alias(target)) => {
            let t = operand(target, scope, io, depth + 1)?;
            Ok(format!("{t}{rest}"))
        }
        Some(Sym::Refused(why)) => Err(format!("`{head}` was refused ({why})")),
        // Not a tag: CPT words (MOD, AND …) or a label; left as written.
        None => Ok(tok.to_string()),
    }
}

/// The operand `tok` = a structure tag and `rest` (`.Member.DN`): the
/// member's tag and what follows it.
fn member(tok: &str, members: &HashMap<String, Sym>, rest: &str) -> Result<String, String> {
    let mut cur = members;
    let mut segs = rest.split('.').skip(1);
    while let Some(seg) = segs.next() {
        match cur.get(&seg.to_ascii_lowercase()) {
            Some(Sym::Struct(m)) => cur = m,
            Some(Sym::Tag { alba, .. }) => {
                let tail: Vec<&str> = segs.collect();
                return Ok(if tail.is_empty() {
                    alba.clone()
                } else {
                    format!("{alba}.{}", tail.join("."))
                });
            }
            Some(Sym::Refused(why)) => return Err(format!("`{tok}`: {why}")),
            Some(Sym::Alias(_)) | None => return Err(format!("`{tok}`: `{seg}` is not a member")),
        }
    }
    Err(format!("`{tok}` is a whole structure (Alba has no structures)"))
}

/// TIMER/COUNTER data of the tags in `sym`, by lower-case Alba name.
fn timer_data(sym: &Sym, out: &mut HashMap<String, (i64, i64)>) {
    match sym {
        Sym::Tag { alba, data: Some(d) } => {
            out.insert(alba.to_ascii_lowercase(), *d);
        }
        Sym::Struct(m) => m.values().for_each(|s| timer_data(s, out)),
        _ => {}
    }
}

/// `TON(T,?,?)` with the data of tag T → `TON(T,5000,0)`.
fn fill_presets(text: &str, scope: &HashMap<String, Sym>) -> String {
    let mut out = String::new();
    let mut rest = text;
    let mut by_alba = HashMap::new();
    scope.values().for_each(|s| timer_data(s, &mut by_alba));
    while let Some(pos) = rest.find('(') {
        let head = &rest[..pos];
        let mn: String = head
            .chars()
            .rev()
            .take_while(|c| c.is_ascii_alphabetic())
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        let up = mn.to_ascii_uppercase();
        out.push_str(head);
        out.push('(');
        rest = &rest[pos + 1..];
        if matches!(up.as_str(), "TON" | "TOF" | "RTO" | "TP" | "CTU" | "CTD")
            && let Some(end) = rest.find(')')
        {
            let args: Vec<&str> = rest[..end].split(',').collect();
            if args.len() == 3
                && let Some((pre, acc)) = by_alba.get(&args[0].trim().to_ascii_lowercase())
            {
                let p = if args[1].trim() == "?" {
                    pre.to_string()
                } else {
                    args[1].to_string()
                };
                let a = if args[2].trim() == "?" {
                    acc.to_string()
                } else {
                    args[2].to_string()
                };
                out.push_str(&format!("{},{p},{a})", args[0]));
                rest = &rest[end + 1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// A routine's language; a rung export's context routine has no `Type`,
/// and its `RLLContent` says it.
fn routine_type(r: &Elem) -> &str {
    match r.attr("Type") {
        Some(t) => t,
        None if r.child("RLLContent").is_some() => "RLL",
        None => "?",
    }
}

struct RoutineJob<'a, 'p> {
    pname: &'a str,
    routines: &'a [&'a Elem],
    scope: &'a HashMap<String, Sym>,
    prog: &'p mut ProgramOut,
    /// Routines inlined at least once (lower case).
    called: &'p mut Vec<String>,
    labels: &'p mut usize,
}

/// Deepest chain of JSR inlined.
const MAX_JSR_DEPTH: usize = 16;

/// A rung that ends in `JSR(Routine)` / `JSR(Routine,0)` outside any branch:
/// the condition in front of it and the routine's name.
fn split_jsr(text: &str) -> Option<(String, String)> {
    let t = text.trim().trim_end_matches(';').trim_end();
    let up = t.to_ascii_uppercase();
    let at = up.rfind("JSR")?;
    let depth = t[..at].chars().fold(0i32, |d, c| match c {
        '[' => d + 1,
        ']' => d - 1,
        _ => d,
    });
    if depth != 0 {
        return None;
    }
    let rest = t[at + 3..].trim_start();
    let args = rest.strip_prefix('(')?.strip_suffix(')')?;
    if args.contains(['(', ')']) {
        return None;
    }
    let parts: Vec<&str> = args.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [name] | [name, "0"] if !name.is_empty() => Some((t[..at].to_string(), (*name).to_string())),
        _ => None,
    }
}

/// Writes the rungs of routine `r`, inlining each JSR without parameters: an
/// unconditional one in place, a conditional one as `cond OTE(jsr)`,
/// `XIO(jsr)JMP(end)`, the routine, `LBL(end)NOP()` — Logix does not scan a
/// routine whose JSR is false, and Alba does not execute skipped rungs.
fn emit_routine(conv: &mut Conv<'_>, job: &mut RoutineJob<'_, '_>, r: &Elem, stack: &mut Vec<String>) {
    let rname = r.attr("Name").unwrap_or("");
    stack.push(rname.to_ascii_lowercase());
    let pname = job.pname;
    let rungs: Vec<&Elem> = r
        .child("RLLContent")
        .map(|c| c.all("Rung").collect())
        .unwrap_or_default();
    for rung in rungs {
        let loc = conv.ctx.loc(rung);
        let num = rung.attr("Number").unwrap_or("?");
        for line in cdata(rung.child("Comment")).lines() {
            let l = line.trim_end();
            if l.is_empty() {
                job.prog.line("//", None);
            } else {
                job.prog.line(&format!("// {l}"), None);
            }
        }
        if rung.attr("Type").is_some_and(|t| t != "N") {
            conv.report.push(
                Kind::Refused,
                loc,
                format!(
                    "rung {num} of `{pname}`/`{rname}` is a pending edit (type {}); only normal rungs are imported",
                    rung.attr("Type").unwrap_or("")
                ),
            );
            continue;
        }
        let raw = cdata(rung.child("Text"));
        let one_line: String = raw.split_whitespace().collect::<Vec<_>>().join(" ");
        let tloc = rung.child("Text").map(|t| conv.ctx.loc(t)).unwrap_or(loc.clone());
        let refuse = |conv: &mut Conv<'_>, prog: &mut ProgramOut, why: String| {
            conv.report.push(
                Kind::Refused,
                tloc.clone(),
                format!("rung {num} of `{pname}`/`{rname}`: {why}"),
            );
            prog.line(
                &format!("// REFUSED by alba import: rung {num}: {one_line} ({why})"),
                Some(&tloc),
            );
        };
        let one_line = match without_empty_legs(&one_line) {
            Ok(None) => one_line.clone(),
            Ok(Some(t)) => {
                conv.report.push(
                    Kind::Converted,
                    tloc.clone(),
                    format!("rung {num} of `{pname}`/`{rname}`: its empty branch legs (wires) are written out: `{t}`"),
                );
                t
            }
            Err(why) => {
                refuse(conv, job.prog, why);
                continue;
            }
        };
        if let Some((cond, target)) = split_jsr(&one_line) {
            let key = target.to_ascii_lowercase();
            let Some(sub) = job
                .routines
                .iter()
                .find(|x| x.attr("Name").is_some_and(|n| n.eq_ignore_ascii_case(&target)))
            else {
                refuse(
                    conv,
                    job.prog,
                    format!("JSR to `{target}`, a routine this program does not have"),
                );
                continue;
            };
            if stack.contains(&key) {
                refuse(conv, job.prog, format!("JSR to `{target}` is recursive"));
                continue;
            }
            if stack.len() >= MAX_JSR_DEPTH {
                refuse(
                    conv,
                    job.prog,
                    format!("JSR nested deeper than {MAX_JSR_DEPTH} routines"),
                );
                continue;
            }
            if routine_type(sub) != "RLL" {
                refuse(
                    conv,
                    job.prog,
                    format!("JSR to `{target}`, which is not an RLL routine"),
                );
                continue;
            }
            let cond = match rewrite(&format!("{cond}NOP();"), job.scope, &conv.io) {
                Ok(c) => c.trim().trim_end_matches(';').trim_end_matches("NOP()").to_string(),
                Err(why) => {
                    refuse(conv, job.prog, why);
                    continue;
                }
            };
            if !job.called.contains(&key) {
                job.called.push(key);
            }
            if cond.trim().is_empty() {
                conv.report.push(
                    Kind::Converted,
                    tloc.clone(),
                    format!("JSR({target}): the routine is inlined here"),
                );
                job.prog
                    .line(&format!("// JSR({target}) inlined by alba import"), Some(&tloc));
                emit_routine(conv, job, sub, stack);
            } else {
                *job.labels += 1;
                let flag = conv.names.fresh("jsr_flag");
                let label = format!("JSR_END_{}", *job.labels);
                conv.tags.push(TagOut {
                    name: flag.clone(),
                    ty: "BOOL".into(),
                    address: String::new(),
                    initial: String::new(),
                    description: format!("alba import: the condition of JSR({target}) in {pname}"),
                });
                conv.report.push(
                    Kind::Converted,
                    tloc.clone(),
                    format!("JSR({target}): the routine is inlined, skipped by JMP({label}) while the rung is false"),
                );
                job.prog.line(&format!("{cond}OTE({flag});"), Some(&tloc));
                job.prog.line(&format!("XIO({flag})JMP({label});"), Some(&tloc));
                emit_routine(conv, job, sub, stack);
                job.prog.line(&format!("LBL({label})NOP();"), Some(&tloc));
            }
            continue;
        }
        match rewrite(&one_line, job.scope, &conv.io) {
            Ok(t) => {
                let t = t.trim().to_string();
                let t = if t.ends_with(';') { t } else { format!("{t};") };
                job.prog.line(&t, Some(&tloc));
            }
            Err(why) => refuse(conv, job.prog, why),
        }
    }
    stack.pop();
}

/// Converts an L5X export.
pub fn convert(file: &str, stem: &str, text: &str, _opts: &Options) -> Result<(Project, Report), Error> {
    let ctx = Ctx { file, text };
    let root = crate::plcopen::parse_root(&ctx, "RSLogix5000Content", "an L5X export")?;
    let Some(ctl) = root.child("Controller") else {
        return Err(Error::at(ctx.loc(&root), "<RSLogix5000Content> has no <Controller>"));
    };
    let name = ctl.attr("Name").unwrap_or(stem).to_string();
    let mut conv = Conv {
        ctx,
        report: Report::default(),
        names: Names::new(),
        tags: Vec::new(),
        io: Io::default(),
        io_tags: Vec::new(),
        udts: ctl
            .child("DataTypes")
            .map(|d| {
                d.all("DataType")
                    .filter_map(|t| Some((t.attr("Name")?.to_ascii_lowercase(), t)))
                    .collect()
            })
            .unwrap_or_default(),
        next_marker: 0,
        members: 0,
        tag_members: 0,
    };
    let mut globals: HashMap<String, Sym> = HashMap::new();
    if let Some(tags) = ctl.child("Tags") {
        conv.declare(tags, &mut globals, None);
    }
    let programs: Vec<&Elem> = ctl
        .child("Programs")
        .map(|p| p.all("Program").collect())
        .unwrap_or_default();
    let mut scopes: Vec<HashMap<String, Sym>> = Vec::new();
    for p in &programs {
        let mut scope = globals.clone();
        if let Some(tags) = p.child("Tags") {
            let owner = p.attr("Name").unwrap_or("program").to_string();
            conv.declare(tags, &mut scope, Some(&owner));
        }
        scopes.push(scope);
    }
    // I/O used directly in rungs joins the numbering too.
    let mut rung_elems: Vec<&Elem> = Vec::new();
    for p in &programs {
        p.descendants("Text", &mut rung_elems);
    }
    for t in &rung_elems {
        for tok in t
            .text
            .split(|c: char| !(c.is_ascii_alphanumeric() || matches!(c, '_' | ':' | '.' | '[' | ']')))
        {
            if let Some(p) = parse_point(tok) {
                conv.io.collect(&p);
            }
        }
    }
    conv.io.number();
    for (i, p) in std::mem::take(&mut conv.io_tags) {
        let addr = conv.io.address(&p).unwrap_or_default();
        let ty = match p {
            Point::Digital { .. } => "BOOL",
            Point::Analog { .. } => "INT",
        };
        if let Some(t) = conv.tags.get_mut(i) {
            t.ty = ty.into();
            t.address = addr;
        }
    }

    // Scan period and program order from the tasks.
    let mut scan_ms = 10u32;
    let mut order: Vec<String> = Vec::new();
    if let Some(tasks) = ctl.child("Tasks") {
        let first_rate = tasks.all("Task").find_map(|t| {
            let r = t.attr("Rate").and_then(|r| r.trim().parse::<f64>().ok())?;
            (t.attr("Type") == Some("PERIODIC") && (1.0..=60_000.0).contains(&r)).then_some(r)
        });
        if let Some(r) = first_rate {
            scan_ms = r.round() as u32;
        }
        let mut rate_set = false;
        for t in tasks.all("Task") {
            let loc = conv.ctx.loc(t);
            let ty = t.attr("Type").unwrap_or("");
            let rate = t.attr("Rate").and_then(|r| r.trim().parse::<f64>().ok());
            match (ty, rate) {
                ("PERIODIC", Some(r)) if !rate_set && (1.0..=60_000.0).contains(&r) => {
                    scan_ms = r.round() as u32;
                    rate_set = true;
                    conv.report.push(
                        Kind::Converted,
                        loc,
                        format!(
                            "periodic task `{}` every {r} ms: scan_ms = {scan_ms}",
                            t.attr("Name").unwrap_or("")
                        ),
                    );
                }
                _ => conv.report.push(
                    Kind::Approximated,
                    loc,
                    format!(
                        "task `{}` ({ty}): Alba runs every program in one periodic scan of {scan_ms} ms",
                        t.attr("Name").unwrap_or("")
                    ),
                ),
            }
            if let Some(sp) = t.child("ScheduledPrograms") {
                for s in sp.all("ScheduledProgram") {
                    if let Some(n) = s.attr("Name") {
                        order.push(n.to_ascii_lowercase());
                    }
                }
            }
        }
    }
    let mut idx: Vec<usize> = (0..programs.len()).collect();
    idx.sort_by_key(|&i| {
        let n = programs[i].attr("Name").unwrap_or("").to_ascii_lowercase();
        order.iter().position(|o| *o == n).unwrap_or(usize::MAX)
    });

    let mut outs = Vec::new();
    let mut files: Vec<String> = Vec::new();
    for i in idx {
        let p = programs[i];
        let pname = p.attr("Name").unwrap_or("program");
        let ploc = conv.ctx.loc(p);
        if !order.is_empty() && !order.contains(&pname.to_ascii_lowercase()) {
            conv.report.push(
                Kind::Approximated,
                ploc.clone(),
                format!("program `{pname}` is in no task; Alba runs it every scan"),
            );
        }
        let routines: Vec<&Elem> = p
            .child("Routines")
            .map(|r| r.all("Routine").collect())
            .unwrap_or_default();
        // A routine export (TargetType="Routine") has no main routine in its
        // context program: the exported routine is the one to import; in a
        // rung export (TargetType="Rung"), the routine of the exported rungs.
        let target = routines
            .iter()
            .find(|r| r.attr("Use") == Some("Target"))
            .or_else(|| {
                routines.iter().find(|r| {
                    r.child("RLLContent")
                        .is_some_and(|c| c.all("Rung").any(|g| g.attr("Use") == Some("Target")))
                })
            })
            .and_then(|r| r.attr("Name"));
        let main = match p.attr("MainRoutineName") {
            Some(m) if routines.iter().any(|r| r.attr("Name") == Some(m)) => m,
            _ => target.unwrap_or_else(|| p.attr("MainRoutineName").unwrap_or("")),
        };
        let Some(r) = routines.iter().find(|r| r.attr("Name") == Some(main)) else {
            conv.report.push(
                Kind::Refused,
                ploc,
                format!("program `{pname}` has no main routine `{main}`"),
            );
            continue;
        };
        if routine_type(r) != "RLL" {
            conv.report.push(
                Kind::Refused,
                conv.ctx.loc(r),
                format!(
                    "routine `{main}` of `{pname}` is {}; only RLL (ladder) is imported",
                    routine_type(r)
                ),
            );
            continue;
        }
        let mut fname = format!("{}.lad", crate::names::file_stem(pname));
        let mut n = 2;
        while files.iter().any(|f| f.eq_ignore_ascii_case(&fname)) {
            fname = format!("{}_{n}.lad", crate::names::file_stem(pname));
            n += 1;
        }
        files.push(fname.clone());
        let mut prog = ProgramOut::new(fname);
        let mut called: Vec<String> = vec![main.to_ascii_lowercase()];
        let mut labels = 0usize;
        let mut job = RoutineJob {
            pname,
            routines: &routines,
            scope: &scopes[i],
            prog: &mut prog,
            called: &mut called,
            labels: &mut labels,
        };
        emit_routine(&mut conv, &mut job, r, &mut Vec::new());
        for r in &routines {
            let rn = r.attr("Name").unwrap_or("");
            if !called.contains(&rn.to_ascii_lowercase()) {
                conv.report.push(
                    Kind::Refused,
                    conv.ctx.loc(r),
                    format!("routine `{rn}` of `{pname}` is never called by a JSR Alba inlines; not imported"),
                );
            }
        }
        outs.push(prog);
    }
    if outs.is_empty() {
        return Err(Error::at(
            conv.ctx.loc(ctl),
            "nothing to import: the controller has no program with an RLL main routine",
        ));
    }
    let mut report = conv.report;
    report.entries.sort_by_key(|e| (e.location.line, e.location.col));
    Ok((
        Project {
            name,
            description: String::new(),
            scan_ms,
            board: None,
            tags: conv.tags,
            programs: outs,
            ..Project::default()
        },
        report,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points() {
        assert_eq!(
            parse_point("Local:1:I.Data.0"),
            Some(Point::Digital {
                output: false,
                module: "Local".into(),
                slot: 1,
                word: 0,
                bit: 0
            })
        );
        assert_eq!(
            parse_point("Local:2:O.Data[1].7"),
            Some(Point::Digital {
                output: true,
                module: "Local".into(),
                slot: 2,
                word: 1,
                bit: 7
            })
        );
        assert_eq!(
            parse_point("Local:3:I.Ch2Data"),
            Some(Point::Analog {
                output: false,
                module: "Local".into(),
                slot: 3,
                ch: 2
            })
        );
        assert_eq!(parse_point("Local:1:C.Data.0"), None);
        assert_eq!(parse_point("Motor"), None);
    }
}
