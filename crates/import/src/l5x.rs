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
//! Refused, with their place: arrays (Alba has no arrays), user-defined and
//! other structured types, produced/consumed tags, JSR with parameters,
//! SBR/RET, recursion, routines never called, non-RLL routines, rungs with
//! instructions Alba does not have.

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
    /// Refused (why).
    Refused(String),
}

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

/// PRE and ACC of a TIMER/COUNTER tag's data (decorated or L5K).
fn struct_data(tag: &Elem) -> Option<(i64, i64)> {
    for d in tag.all("Data") {
        match d.attr("Format") {
            Some("Decorated") => {
                if let Some(s) = d.child("Structure") {
                    let get = |n: &str| {
                        s.all("DataValueMember")
                            .find(|m| m.attr("Name").is_some_and(|x| x.eq_ignore_ascii_case(n)))
                            .and_then(|m| m.attr("Value"))
                            .and_then(|v| v.trim().parse::<i64>().ok())
                    };
                    if let (Some(p), Some(a)) = (get("PRE"), get("ACC")) {
                        return Some((p, a));
                    }
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

fn scalar_data(tag: &Elem) -> Option<String> {
    for d in tag.all("Data") {
        match d.attr("Format") {
            Some("Decorated") => {
                if let Some(v) = d.child("DataValue").and_then(|v| v.attr("Value")) {
                    return Some(v.trim().to_string());
                }
            }
            Some("L5K") => return Some(d.text.trim().to_string()),
            _ => {}
        }
    }
    None
}

struct Conv<'a> {
    ctx: Ctx<'a>,
    report: Report,
    names: Names,
    tags: Vec<TagOut>,
    io: Io,
    /// Tags aliased to I/O points, declared once the I/O is numbered.
    io_tags: Vec<(usize, Point)>,
}

impl Conv<'_> {
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
                    refuse(self, scope, format!("data type `{dt_raw}` is not one Alba has"));
                    continue;
                }
            };
            let alba = self.alba_name(name, owner, &loc);
            let mut initial = String::new();
            let mut data = None;
            if ty == "TIMER" || ty == "COUNTER" {
                data = struct_data(t);
            } else if let Some(v) = scalar_data(t) {
                let ok = match ty.as_str() {
                    "BOOL" => v == "0" || v == "1",
                    "REAL" | "LREAL" => v.parse::<f64>().is_ok_and(f64::is_finite),
                    _ => v.parse::<i64>().is_ok(),
                };
                if ok && v != "0" && v != "0.0" && v != "0.00000000e+000" {
                    initial = if ty.contains("REAL") {
                        let f: f64 = v.parse().unwrap_or(0.0);
                        format!("{f:?}")
                    } else {
                        v
                    };
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
    match scope.get(&head.to_ascii_lowercase()) {
        Some(Sym::Tag { alba, .. }) => Ok(format!("{alba}{rest}")),
        Some(Sym::Alias(target)) => {
            let t = operand(target, scope, io, depth + 1)?;
            Ok(format!("{t}{rest}"))
        }
        Some(Sym::Refused(why)) => Err(format!("`{head}` was refused ({why})")),
        // Not a tag: CPT words (MOD, AND …) or a label; left as written.
        None => Ok(tok.to_string()),
    }
}

/// `TON(T,?,?)` with the data of tag T → `TON(T,5000,0)`.
fn fill_presets(text: &str, scope: &HashMap<String, Sym>) -> String {
    let mut out = String::new();
    let mut rest = text;
    let by_alba: HashMap<String, (i64, i64)> = scope
        .values()
        .filter_map(|s| match s {
            Sym::Tag { alba, data: Some(d) } => Some((alba.to_ascii_lowercase(), *d)),
            _ => None,
        })
        .collect();
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
            if sub.attr("Type") != Some("RLL") {
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
        // context program: the exported routine is the one to import.
        let target = routines
            .iter()
            .find(|r| r.attr("Use") == Some("Target"))
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
        if r.attr("Type") != Some("RLL") {
            conv.report.push(
                Kind::Refused,
                conv.ctx.loc(r),
                format!(
                    "routine `{main}` of `{pname}` is {}; only RLL (ladder) is imported",
                    r.attr("Type").unwrap_or("?")
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
