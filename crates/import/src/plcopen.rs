//! PLCopen TC6 XML v2.01 (IEC 61131-10): the project files of the OpenPLC
//! editor, Beremiz and CODESYS exports.
//!
//! Read: every `program` POU whose body is LD becomes one Alba ladder file;
//! its variables, and the configuration's global variables, become tags
//! (located ones, `%IX0.0` `%QX0.0` `%IW0` `%QW0` `%MW0` …, keep their IEC
//! address, which Alba reads directly). An LD body is a graph: each element
//! lists the elements its input is connected to. The graph is walked from
//! its sinks (coils, output variables, function blocks) in the order of
//! their execution order or drawing position; a contact is its input AND
//! its variable, several connections into one input are an OR, and the
//! standard function blocks become Alba instructions:
//!
//! | IEC | Alba |
//! |---|---|
//! | `TON` `TOF` `TP` (IN, PT → Q, ET) | `TON` `TOF` `TP` on a TIMER tag; Q = `.DN`, ET = `.ACC` |
//! | `CTU` (CU, R, PV → Q, CV) | `CTU`, R: `MOV(0,C.ACC)`; Q = `GEQ(C.ACC,PV)` |
//! | `CTD` (CD, LD, PV → Q, CV) | `CTD`, LD: `MOV(PV,C.ACC)`; Q = `LEQ(C.ACC,0)` |
//! | `CTUD` | both, QU and QD as above |
//! | `R_TRIG` `F_TRIG` | `OSR` `OSF` with two helper bits |
//! | `GT` `GE` `EQ` `NE` `LT` `LE` | compares ANDed with EN |
//! | `ADD` `SUB` `MUL` `DIV` `MOD` `MOVE` | the instruction, gated by EN, into a helper tag |
//!
//! SFC bodies become `.sfc` programs (the [`sfc`] module), ST bodies `.st`
//! programs (the [`st`] module), as do functions and function blocks with
//! ST bodies and the data types (`types.st`), before the programs.
//!
//! Everything else (functions and function blocks in other languages,
//! FBD/IL bodies, jumps, other blocks) is refused with its place; a coil
//! fed by a refused element is refused too.

mod sfc;
mod st;

use crate::circuit::{Cond, Emitter, Structs};
use crate::names::Names;
use crate::{Error, Kind, Location, Options, ProgramOut, Project, Report, TagOut};
use alba_xml::{self as xml, Elem};
use std::collections::HashMap;

/// Deepest chain of connections followed (a deeper graph is refused rather
/// than risking the stack).
const MAX_CHAIN: usize = 2000;

pub(crate) struct Ctx<'a> {
    pub file: &'a str,
    pub text: &'a str,
}

impl Ctx<'_> {
    pub fn loc(&self, e: &Elem) -> Location {
        let (l, c) = xml::line_col(self.text, e.start);
        Location::new(self.file, l, c)
    }

    pub fn loc_at(&self, offset: usize) -> Location {
        let (l, c) = xml::line_col(self.text, offset);
        Location::new(self.file, l, c)
    }
}

/// The document's root element, which must be `<name>` (`what` names the format).
pub(crate) fn parse_root(ctx: &Ctx<'_>, name: &str, what: &str) -> Result<Elem, Error> {
    let root = xml::parse(ctx.text, &crate::XML_LIMITS).map_err(|e| xml_error(ctx, e))?;
    if root.name != name {
        return Err(Error::at(
            ctx.loc(&root),
            format!("not {what}: the root element is <{}>, not <{name}>", root.name),
        ));
    }
    Ok(root)
}

fn xml_error(ctx: &Ctx<'_>, e: xml::XmlError) -> Error {
    if e.limit {
        Error::at(ctx.loc_at(e.offset), format!("refused: {}", e.message))
    } else {
        Error::at(ctx.loc_at(e.offset), format!("not well-formed XML: {}", e.message))
    }
}

/// What a variable is in Alba.
#[derive(Debug, Clone, PartialEq, Eq)]
enum VarKind {
    /// A tag of this Alba type.
    Tag(String),
    Timer,
    Counter,
    /// R_TRIG / F_TRIG instances: helper bits, no tag of their own.
    Trig,
    /// Not convertible (why).
    Refused(String),
}

#[derive(Debug, Clone)]
struct Var {
    alba: String,
    kind: VarKind,
    /// A function block instance's type (`CTU`), upper case; empty otherwise.
    fb: String,
}

/// A duration or number literal in IEC form, as an Alba literal.
fn iec_literal(s: &str) -> Option<String> {
    let t = s.trim();
    let up = t.to_ascii_uppercase();
    if let Some(rest) = up.strip_prefix("T#").or_else(|| up.strip_prefix("TIME#")) {
        return duration_ms(rest).map(|v| v.to_string());
    }
    let body = up.split_once('#').map(|(ty, v)| {
        if [
            "INT", "DINT", "SINT", "LINT", "UINT", "UDINT", "USINT", "REAL", "LREAL", "WORD", "BYTE", "DWORD",
        ]
        .contains(&ty)
        {
            v.to_string()
        } else {
            up.clone()
        }
    });
    let v = body.unwrap_or(up);
    let v = v.replace('_', "");
    if let Some((base, digits)) = v.split_once('#') {
        let radix = match base {
            "2" => 2,
            "8" => 8,
            "16" => 16,
            _ => return None,
        };
        return i64::from_str_radix(digits, radix).ok().map(|n| n.to_string());
    }
    if v.parse::<i64>().is_ok() {
        return Some(v.trim_start_matches('+').to_string());
    }
    if v.parse::<f64>().is_ok_and(f64::is_finite) && v.contains('.') {
        return Some(v);
    }
    None
}

/// ST's functions that Alba's CPT has, by their ST names (docs/ladder.md §4.7).
pub(crate) const ST_FUNCTIONS: &[(&str, &str)] = &[
    ("SQRT", "SQRT"),
    ("ABS", "ABS"),
    ("SIN", "SIN"),
    ("COS", "COS"),
    ("TAN", "TAN"),
    ("ASIN", "ASIN"),
    ("ACOS", "ACOS"),
    ("ATAN", "ATAN"),
    ("LN", "LN"),
    ("LOG", "LOG"),
    ("TRUNC", "TRN"),
];

/// An ST expression in Alba's expression language (the CPT parser's):
/// `name` maps each identifier, `functions` the functions allowed (ST name →
/// Alba name; none: functions are refused). Literals become Alba's (`T#3s`
/// is 3000 ms, `INT#5` is 5), `&` is AND; the rest is the same in both.
pub(crate) fn st_expression(
    st: &str,
    name: &dyn Fn(&str) -> Result<String, String>,
    functions: &[(&str, &str)],
) -> Result<String, String> {
    let st = st.trim().trim_end_matches(';').trim();
    if st.is_empty() {
        return Err("the expression is empty".into());
    }
    let b: Vec<char> = st.chars().collect();
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_whitespace() {
            i += 1;
        } else if c == '(' && b.get(i + 1) == Some(&'*') {
            return Err("a comment inside the expression".into());
        } else if c.is_ascii_alphanumeric() || c == '_' {
            let s = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || "_.#".contains(b[i])) {
                i += 1;
            }
            // An exponent's sign: `1.5E-3`.
            if c.is_ascii_digit()
                && matches!(b.get(i - 1), Some('e' | 'E'))
                && matches!(b.get(i), Some('+' | '-'))
                && b.get(i + 1).is_some_and(char::is_ascii_digit)
            {
                i += 1;
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
            let w: String = b[s..i].iter().collect();
            let up = w.to_ascii_uppercase();
            if b.get(i) == Some(&'(') {
                match functions.iter().find(|(f, _)| *f == up) {
                    Some((_, alba)) => out.push((*alba).to_string()),
                    None if functions.is_empty() => {
                        return Err(format!("`{w}(…)`: functions are not available in Alba's conditions"));
                    }
                    None => return Err(format!("`{w}(…)` is not a function Alba's CPT has")),
                }
            } else if ["AND", "OR", "XOR", "NOT", "MOD", "TRUE", "FALSE"].contains(&up.as_str()) {
                out.push(up);
            } else if c.is_ascii_digit() || w.contains('#') {
                let lit = if up.starts_with("T#") || up.starts_with("TIME#") {
                    duration_ms(up.split_once('#').map(|(_, r)| r).unwrap_or("")).map(|ms| ms.to_string())
                } else {
                    iec_literal(&w)
                };
                out.push(lit.ok_or_else(|| format!("`{w}` is not a literal Alba reads"))?);
            } else {
                out.push(name(&w)?);
            }
        } else {
            let two: String = b[i..(i + 2).min(b.len())].iter().collect();
            if ["<=", ">=", "<>", "**"].contains(&two.as_str()) {
                out.push(two);
                i += 2;
            } else if "+-*/<>=()".contains(c) || (c == ',' && !functions.is_empty()) {
                out.push(c.to_string());
                i += 1;
            } else if c == '&' {
                out.push("AND".into());
                i += 1;
            } else {
                return Err(format!("`{c}` in the expression"));
            }
        }
    }
    Ok(out.join(" "))
}

/// `1m30s500ms` → 90500 (IEC duration parts, `_` allowed, decimals refused).
pub(crate) fn duration_ms(s: &str) -> Option<i64> {
    let s = s.replace('_', "").to_ascii_lowercase();
    let (neg, mut rest) = match s.strip_prefix('-') {
        Some(r) => (true, r.to_string()),
        None => (false, s),
    };
    if rest.is_empty() {
        return None;
    }
    let mut total: i64 = 0;
    while !rest.is_empty() {
        let n: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
        if n.is_empty() {
            return None;
        }
        let v: i64 = n.parse().ok()?;
        rest = rest[n.len()..].to_string();
        let (mult, len) = if rest.starts_with("ms") {
            (1, 2)
        } else if rest.starts_with('d') {
            (86_400_000, 1)
        } else if rest.starts_with('h') {
            (3_600_000, 1)
        } else if rest.starts_with('m') {
            (60_000, 1)
        } else if rest.starts_with('s') {
            (1000, 1)
        } else {
            return None;
        };
        rest = rest[len..].to_string();
        total = total.checked_add(v.checked_mul(mult)?)?;
    }
    if total > i64::from(i32::MAX) {
        return None;
    }
    Some(if neg { -total } else { total })
}

/// The Alba type of an elementary IEC type, and whether it is approximated.
fn elementary(name: &str) -> Option<(&'static str, bool)> {
    Some(match name.to_ascii_uppercase().as_str() {
        "BOOL" => ("BOOL", false),
        "SINT" => ("SINT", false),
        "INT" => ("INT", false),
        "DINT" => ("DINT", false),
        "LINT" => ("LINT", false),
        "REAL" => ("REAL", false),
        "LREAL" => ("LREAL", false),
        "TIME" => ("TIME", false),
        "USINT" | "BYTE" => ("INT", true),
        "UINT" | "WORD" => ("DINT", true),
        "UDINT" | "DWORD" | "ULINT" | "LWORD" => ("LINT", true),
        _ => return None,
    })
}

struct Conv<'a> {
    ctx: Ctx<'a>,
    report: Report,
    names: Names,
    structs: Structs,
    tags: Vec<TagOut>,
    globals: HashMap<String, Var>,
}

impl Conv<'_> {
    /// Declares the variables of a `globalVars`/`localVars`/… element.
    fn declare(&mut self, list: &Elem, scope: &mut HashMap<String, Var>, owner: &str) {
        for v in list.all("variable") {
            let loc = self.ctx.loc(v);
            let Some(name) = v.attr("name") else {
                self.report.push(Kind::Refused, loc, "a variable without a name");
                continue;
            };
            let ty = v.child("type").and_then(|t| t.children.first());
            let fb = ty
                .filter(|t| t.name == "derived")
                .and_then(|t| t.attr("name"))
                .map(str::to_ascii_uppercase)
                .unwrap_or_default();
            let (kind, approx) = match ty {
                None => (VarKind::Refused("it has no type".into()), false),
                Some(t) if t.name == "derived" => match t.attr("name").map(str::to_ascii_uppercase).as_deref() {
                    Some("TON" | "TOF" | "TP") => (VarKind::Timer, false),
                    Some("CTU" | "CTD" | "CTUD") => (VarKind::Counter, false),
                    Some("R_TRIG" | "F_TRIG") => (VarKind::Trig, false),
                    Some(other) => (
                        VarKind::Refused(format!("its type `{other}` is not one Alba has")),
                        false,
                    ),
                    None => (VarKind::Refused("a derived type without a name".into()), false),
                },
                Some(t) => match elementary(&t.name) {
                    Some((a, approx)) => (VarKind::Tag(a.to_string()), approx),
                    None => (
                        VarKind::Refused(format!("its type `{}` is not one Alba has", t.name)),
                        false,
                    ),
                },
            };
            let key = name.to_ascii_lowercase();
            if let VarKind::Refused(why) = &kind {
                self.report
                    .push(Kind::Refused, loc, format!("variable `{name}` of {owner}: {why}"));
                scope.insert(
                    key,
                    Var {
                        alba: name.to_string(),
                        kind,
                        fb,
                    },
                );
                continue;
            }
            let wanted = if self.names.is_taken(name) {
                format!("{owner}_{name}")
            } else {
                name.to_string()
            };
            let (alba, why) = self.names.alba_as(&format!("{owner}\u{0}{name}"), &wanted);
            if alba != name {
                let why = why.unwrap_or_else(|| format!("`{name}` is also the name of another tag"));
                self.report
                    .push(Kind::Approximated, loc.clone(), format!("{why}: tag `{alba}`"));
            }
            if approx && let VarKind::Tag(a) = &kind {
                let t = ty.map(|t| t.name.as_str()).unwrap_or("");
                self.report.push(
                    Kind::Approximated,
                    loc.clone(),
                    format!("`{name}`: the unsigned {t} is held in a signed {a}"),
                );
            }
            let mut address = v.attr("address").unwrap_or("").trim().to_string();
            let ty_name = match &kind {
                VarKind::Tag(t) => t.clone(),
                VarKind::Timer => "TIMER".into(),
                VarKind::Counter => "COUNTER".into(),
                _ => String::new(),
            };
            if !address.is_empty() {
                match alba_model::Address::parse(&address) {
                    Ok(Some(a))
                        if a.allowed_types()
                            .iter()
                            .any(|t| t.name().eq_ignore_ascii_case(&ty_name)) =>
                    {
                        self.report
                            .push(Kind::Converted, loc.clone(), format!("`{name}` {ty_name} at {address}"));
                    }
                    _ => {
                        self.report.push(
                            Kind::Approximated,
                            loc.clone(),
                            format!(
                                "`{name}`: the address {address} is not one Alba holds a {ty_name} at; an internal tag"
                            ),
                        );
                        address.clear();
                    }
                }
            }
            let mut initial = String::new();
            if let Some(sv) = v.child("initialValue").and_then(|i| i.child("simpleValue")) {
                let raw = sv.attr("value").unwrap_or("").trim();
                let lit = if ty_name == "BOOL" {
                    match raw.to_ascii_uppercase().as_str() {
                        "TRUE" | "1" | "BOOL#TRUE" | "BOOL#1" => Some("1".to_string()),
                        "FALSE" | "0" | "BOOL#FALSE" | "BOOL#0" => Some("0".to_string()),
                        _ => None,
                    }
                } else if matches!(kind, VarKind::Tag(_)) {
                    iec_literal(raw)
                } else {
                    None
                };
                match lit {
                    Some(l) => initial = l,
                    None => self.report.push(
                        Kind::Refused,
                        self.ctx.loc(sv),
                        format!("initial value `{raw}` of `{name}` is not converted"),
                    ),
                }
            }
            let description = v
                .child("documentation")
                .map(|d| collect_text(d).split_whitespace().collect::<Vec<_>>().join(" "))
                .unwrap_or_default();
            if matches!(kind, VarKind::Tag(_) | VarKind::Timer | VarKind::Counter) {
                self.tags.push(TagOut {
                    name: alba.clone(),
                    ty: ty_name,
                    address,
                    initial,
                    description,
                });
            }
            scope.insert(key, Var { alba, kind, fb });
        }
    }
}

fn collect_text(e: &Elem) -> String {
    let mut s = e.text.clone();
    for c in &e.children {
        s.push(' ');
        s.push_str(&collect_text(c));
    }
    s
}

/// One LD body being converted.
struct Body<'b, 'e> {
    elems: HashMap<String, &'b Elem>,
    vars: &'b HashMap<String, Var>,
    memo: HashMap<(String, String), Result<Out, String>>,
    visiting: Vec<String>,
    /// Blocks emitted (or refused), by localId: a later reader of a refused
    /// block's output is refused too.
    emitted_blocks: HashMap<String, Result<(), String>>,
    e: Emitter<'e>,
    pou: String,
    structs: Structs,
    /// Instance → the helper bit holding an R_TRIG/F_TRIG's Q.
    trig_q: HashMap<String, String>,
    /// Notes for the report: (kind, byte offset, message).
    notes: Vec<(Kind, usize, String)>,
    /// Helper tags holding block results: (name, type, what).
    data_helpers: Vec<(String, String, String)>,
    /// Block localId → the helper holding its OUT.
    block_out_data: HashMap<String, String>,
    /// A function block's OUT whose only reader is an output variable:
    /// block localId → that variable's localId (the result goes straight in).
    sole_out: HashMap<String, String>,
    /// Output variables written by their block directly.
    handled: Vec<String>,
    /// TIME converts to numbers in milliseconds (CODESYS), not in seconds
    /// (matiec: OpenPLC, Beremiz).
    ms_time: bool,
}

/// The functions computing an OUT (besides the conversions).
const FUNCTIONS: &[&str] = &["ADD", "SUB", "MUL", "DIV", "MOD", "MOVE"];

/// A type conversion function `X_TO_Y`: the Alba types of X and Y.
struct Conversion {
    from: &'static str,
    to: &'static str,
    /// An unsigned IEC type held in a wider signed Alba type.
    unsigned: bool,
}

fn conversion(ty: &str) -> Option<Conversion> {
    let (from, to) = ty.split_once("_TO_")?;
    let (f, fu) = elementary(from)?;
    let (t, tu) = elementary(to)?;
    Some(Conversion {
        from: f,
        to: t,
        unsigned: fu || tu,
    })
}

/// Width rank of an Alba integer type (0 for the others).
fn int_rank(t: &str) -> u8 {
    match t {
        "SINT" => 1,
        "INT" => 2,
        "DINT" => 3,
        "LINT" => 4,
        _ => 0,
    }
}

impl Conversion {
    fn real(t: &str) -> bool {
        t == "REAL" || t == "LREAL"
    }

    /// Why the conversion is not converted, if it is not.
    fn refused(&self) -> Option<&'static str> {
        if self.from == "BOOL" || self.to == "BOOL" {
            Some("conversions from and to BOOL are not converted")
        } else if self.to == "TIME" {
            Some("conversions to TIME are not converted")
        } else {
            None
        }
    }

    /// The Alba instruction writing `src` converted into `dest`.
    fn text(&self, src: &str, dest: &str, ms_time: bool) -> String {
        match (self.from, ms_time) {
            ("TIME", false) if Self::real(self.to) => format!("CPT({dest},{src}/1000.0)"),
            ("TIME", false) => format!("DIV({src},1000,{dest})"),
            _ => format!("MOV({src},{dest})"),
        }
    }

    /// What Alba does differently, if anything.
    fn note(&self, ms_time: bool) -> Option<String> {
        let mut why = Vec::new();
        if self.unsigned {
            why.push("the unsigned value is held in a signed Alba type".to_string());
        }
        if self.from == "TIME" {
            why.push(if ms_time {
                "TIME in milliseconds, as CODESYS converts it (OpenPLC and Beremiz give seconds)".to_string()
            } else {
                "TIME in seconds, as OpenPLC and Beremiz (matiec) convert it (CODESYS gives milliseconds)".to_string()
            });
        } else if Self::real(self.from) && int_rank(self.to) > 0 {
            why.push(
                "Alba rounds halves to even and saturates out of range (IEC leaves both to the implementation)".into(),
            );
        } else if int_rank(self.to) > 0 && int_rank(self.to) < int_rank(self.from) {
            why.push("out of range, Alba keeps the low bits (IEC leaves it to the implementation)".into());
        } else if self.from == "LREAL" && self.to == "REAL" {
            why.push("out of the REAL range, Alba saturates".into());
        }
        (!why.is_empty()).then(|| why.join("; "))
    }
}

/// What an element output carries.
#[derive(Debug, Clone)]
enum Out {
    Power(Cond),
    /// A number: Alba operand text.
    Data(String),
    /// An ST expression in an input variable, as an Alba CPT expression.
    Expr(String),
}

fn connections(point: Option<&Elem>) -> Vec<(String, String)> {
    point
        .map(|p| {
            p.all("connection")
                .filter_map(|c| {
                    c.attr("refLocalId")
                        .map(|r| (r.to_string(), c.attr("formalParameter").unwrap_or("").to_string()))
                })
                .collect()
        })
        .unwrap_or_default()
}

/// The connections into a block's input `param`.
fn block_input(b: &Elem, param: &str) -> Option<Vec<(String, String)>> {
    let vars = b.child("inputVariables")?;
    let v = vars
        .all("variable")
        .find(|v| v.attr("formalParameter").is_some_and(|p| p.eq_ignore_ascii_case(param)))?;
    let c = connections(v.child("connectionPointIn"));
    if c.is_empty() { None } else { Some(c) }
}

impl Body<'_, '_> {
    fn var(&self, name: &str) -> Option<&Var> {
        self.vars.get(&name.trim().to_ascii_lowercase())
    }

    /// A variable or literal as an Alba operand (number or bit).
    fn operand(&self, expr: &str) -> Result<(String, bool), String> {
        let t = expr.trim();
        if let Some(v) = self.var(t) {
            return match &v.kind {
                VarKind::Tag(ty) => Ok((v.alba.clone(), ty == "BOOL")),
                VarKind::Timer => Ok((format!("{}.ACC", v.alba), false)),
                VarKind::Counter => Ok((format!("{}.ACC", v.alba), false)),
                VarKind::Trig => Err(format!("`{t}` is an R_TRIG/F_TRIG instance, not a value")),
                VarKind::Refused(why) => Err(format!("variable `{t}` was refused ({why})")),
            };
        }
        if let Some((inst, member)) = t.split_once('.')
            && let Some(v) = self.var(inst)
        {
            let m = member.to_ascii_uppercase();
            return match (&v.kind, m.as_str()) {
                (VarKind::Timer, "Q") => Ok((format!("{}.DN", v.alba), true)),
                (VarKind::Timer, "ET") => Ok((format!("{}.ACC", v.alba), false)),
                (VarKind::Timer, "PT") => Ok((format!("{}.PRE", v.alba), false)),
                (VarKind::Counter, "CV") => Ok((format!("{}.ACC", v.alba), false)),
                (VarKind::Counter, "PV") => Ok((format!("{}.PRE", v.alba), false)),
                // CV >= PV, as of the counter's last call: Alba's DN.
                (VarKind::Counter, "Q") if v.fb == "CTU" => Ok((format!("{}.DN", v.alba), true)),
                (VarKind::Counter, "QU") if v.fb == "CTUD" => Ok((format!("{}.DN", v.alba), true)),
                _ => Err(format!("`{t}` has no Alba equivalent")),
            };
        }
        match t.to_ascii_uppercase().as_str() {
            "TRUE" => return Ok(("1".into(), true)),
            "FALSE" => return Ok(("0".into(), true)),
            _ => {}
        }
        iec_literal(t)
            .map(|l| (l, false))
            .ok_or_else(|| format!("`{t}` is neither a variable of {} nor a literal", self.pou))
    }

    /// The power flowing into a connection point (OR of its connections).
    fn power_in(&mut self, conns: &[(String, String)]) -> Result<Cond, String> {
        if conns.is_empty() {
            return Ok(self.e.open());
        }
        let mut cs = Vec::new();
        for (id, param) in conns {
            match self.out(id, param)? {
                Out::Power(c) => cs.push(c),
                // TRUE and FALSE; a BOOL variable comes as a power flow.
                Out::Data(d) if d == "1" => cs.push(self.e.rail()),
                Out::Data(d) if d == "0" => cs.push(self.e.open()),
                Out::Data(d) => return Err(format!("`{d}`, a number, wired into a power input")),
                Out::Expr(_) => return Err("an expression wired into a power input".into()),
            }
        }
        Ok(self.e.or(&cs))
    }

    fn data_in(&mut self, conns: &[(String, String)]) -> Result<String, String> {
        match conns {
            [(id, param)] => match self.out(id, param)? {
                Out::Data(d) => Ok(d),
                Out::Power(_) => Err("a power flow wired into a number input".into()),
                Out::Expr(_) => Err("an expression is converted only as the input of MOVE".into()),
            },
            [] => Err("an unconnected input".into()),
            _ => Err("several connections into a number input".into()),
        }
    }

    fn out(&mut self, id: &str, param: &str) -> Result<Out, String> {
        let key = (id.to_string(), param.to_ascii_uppercase());
        if let Some(r) = self.memo.get(&key) {
            return r.clone();
        }
        if self.visiting.iter().any(|v| v == id) {
            return Err(format!("a feedback loop through element {id}"));
        }
        if self.visiting.len() >= MAX_CHAIN {
            return Err(format!("connections chained deeper than {MAX_CHAIN} elements"));
        }
        self.visiting.push(id.to_string());
        let r = self.compute(id, param);
        self.visiting.pop();
        self.memo.insert(key, r.clone());
        r
    }

    fn compute(&mut self, id: &str, param: &str) -> Result<Out, String> {
        let Some(el) = self.elems.get(id).copied() else {
            return Err(format!("a connection to element {id}, which does not exist"));
        };
        match el.name.as_str() {
            "leftPowerRail" => Ok(Out::Power(self.e.rail())),
            "contact" => {
                let input = self.power_in(&connections(el.child("connectionPointIn")))?;
                let var = el
                    .child("variable")
                    .map(|v| v.text.trim().to_string())
                    .unwrap_or_default();
                let (op, is_bit) = self.operand(&var)?;
                if !is_bit {
                    return Err(format!("contact on `{var}`, which is not a BOOL"));
                }
                let neg = el.attr("negated") == Some("true");
                match el.attr("edge").unwrap_or("none") {
                    "none" => {
                        let frag = if neg {
                            format!("XIO({op})")
                        } else {
                            format!("XIC({op})")
                        };
                        Ok(Out::Power(self.e.and(input, &frag, std::slice::from_ref(&op))))
                    }
                    edge @ ("rising" | "falling") => {
                        let m = self.e.names().fresh(&format!("{}_edge_mem", op.replace('.', "_")));
                        let q = self.e.names().fresh(&format!("{}_edge", op.replace('.', "_")));
                        let rail = self.e.rail();
                        let mn = if edge == "rising" { "OSR" } else { "OSF" };
                        self.e.emit(
                            rail,
                            &format!("XIC({op})"),
                            &format!("{mn}({m},{q})"),
                            &[m.clone(), q.clone()],
                        );
                        self.e.helpers.push((m, format!("edge memory of {op}")));
                        self.e.helpers.push((q.clone(), format!("{edge} edge of {op}")));
                        let frag = if neg { format!("XIO({q})") } else { format!("XIC({q})") };
                        Ok(Out::Power(self.e.and(input, &frag, &[q])))
                    }
                    other => Err(format!("contact edge `{other}`")),
                }
            }
            "coil" => {
                let input = self.power_in(&connections(el.child("connectionPointIn")))?;
                self.coil(el, input)?;
                Ok(Out::Power(input))
            }
            "inVariable" | "inOutVariable" => {
                let expr = el
                    .child("expression")
                    .map(|x| x.text.trim().to_string())
                    .unwrap_or_default();
                if el.name == "inOutVariable" {
                    self.sink(el)?;
                }
                let (op, is_bit) = match self.operand(&expr) {
                    Ok(o) => o,
                    // An ST expression (`A * 2 + B`), not a lone variable.
                    Err(why) if el.name == "inVariable" && expr.contains(|c: char| "+-*/()<>=&, ".contains(c)) => {
                        let e = st_expression(&expr, &|w| self.operand(w).map(|(op, _)| op), ST_FUNCTIONS)
                            .map_err(|e| format!("{why}; as an expression: {e}"))?;
                        return Ok(Out::Expr(e));
                    }
                    Err(why) => return Err(why),
                };
                let negated = el.attr("negated") == Some("true") || el.attr("negatedOut") == Some("true");
                if is_bit && (op != "1" && op != "0") {
                    let frag = if negated {
                        format!("XIO({op})")
                    } else {
                        format!("XIC({op})")
                    };
                    Ok(Out::Power(self.e.input(&frag, std::slice::from_ref(&op))))
                } else if negated {
                    Err(format!("a negated `{expr}`"))
                } else {
                    Ok(Out::Data(op))
                }
            }
            "block" => self.block_out(el, param),
            other => Err(format!("<{other}> elements are not converted")),
        }
    }

    fn coil(&mut self, el: &Elem, input: Cond) -> Result<(), String> {
        let var = el
            .child("variable")
            .map(|v| v.text.trim().to_string())
            .unwrap_or_default();
        let (op, is_bit) = self.operand(&var)?;
        if !is_bit || op == "1" || op == "0" {
            return Err(format!("coil on `{var}`, which is not a BOOL variable"));
        }
        let w = std::slice::from_ref(&op);
        if el.attr("edge").is_some_and(|e| e != "none") {
            return Err("edge-triggered coils are not converted".into());
        }
        let negated = el.attr("negated") == Some("true");
        match el.attr("storage").unwrap_or("none") {
            "set" => self.e.emit(input, "", &format!("OTL({op})"), w),
            "reset" => self.e.emit(input, "", &format!("OTU({op})"), w),
            _ if negated => self.e.emit(input, &format!("OTL({op})"), &format!("OTU({op})"), w),
            _ => self.e.emit(input, "", &format!("OTE({op})"), w),
        }
        Ok(())
    }

    /// An element that writes: a coil, an output variable, a block.
    fn sink(&mut self, el: &Elem) -> Result<(), String> {
        let id = el.attr("localId").unwrap_or("").to_string();
        match el.name.as_str() {
            "coil" => self.out(&id, "").map(|_| ()),
            "block" => self.run_block(el),
            "outVariable" | "inOutVariable" => {
                let conns = connections(el.child("connectionPointIn"));
                if conns.is_empty() {
                    return Ok(());
                }
                let expr = el
                    .child("expression")
                    .map(|x| x.text.trim().to_string())
                    .unwrap_or_default();
                let (op, is_bit) = self.operand(&expr)?;
                let w = std::slice::from_ref(&op);
                if is_bit {
                    let c = self.power_in(&conns)?;
                    let negated = el.attr("negated") == Some("true") || el.attr("negatedIn") == Some("true");
                    if negated {
                        self.e.emit(c, &format!("OTL({op})"), &format!("OTU({op})"), w);
                    } else {
                        self.e.emit(c, "", &format!("OTE({op})"), w);
                    }
                } else {
                    let src = self.data_in(&conns)?;
                    let id = el.attr("localId").unwrap_or("");
                    if !self.handled.iter().any(|h| h == id) {
                        let rail = self.e.rail();
                        self.e.emit(rail, "", &format!("MOV({src},{op})"), w);
                    }
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }

    fn instance(&self, b: &Elem, want: &VarKind) -> Result<String, String> {
        let ty = b.attr("typeName").unwrap_or("");
        let Some(inst) = b.attr("instanceName") else {
            return Err(format!("{ty} block without an instance name"));
        };
        match self.var(inst) {
            Some(v) if &v.kind == want => Ok(v.alba.clone()),
            Some(_) => Err(format!("instance `{inst}` is not declared as a {ty}")),
            None => Err(format!("instance `{inst}` is not declared")),
        }
    }

    fn power_of(&mut self, b: &Elem, param: &str) -> Result<Cond, String> {
        let conns = block_input(b, param).unwrap_or_default();
        let c = self.power_in(&conns)?;
        // EN, when wired, gates the block's power inputs (exactly, when it
        // is always true: wired to the rail, as OpenPLC's editor draws it).
        if let Some(en) = block_input(b, "EN") {
            let en = self.power_in(&en)?;
            if self.e.is_true(en) {
                return Ok(c);
            }
            self.notes.push((
                Kind::Approximated,
                b.start,
                format!(
                    "EN of {} `{}` is ANDed into {param}: IEC does not call a block whose EN is false (it keeps its state), Alba runs the instruction with a false rung",
                    b.attr("typeName").unwrap_or(""),
                    b.attr("instanceName").unwrap_or("")
                ),
            ));
            return Ok(self.e.and_cond(c, en));
        }
        Ok(c)
    }

    /// Emits a standard function block once; a block that was refused
    /// refuses whoever reads it later.
    fn run_block(&mut self, b: &Elem) -> Result<(), String> {
        let id = b.attr("localId").unwrap_or("").to_string();
        if let Some(r) = self.emitted_blocks.get(&id) {
            return r.clone().map_err(|why| {
                format!(
                    "it reads block {} {}, which was refused ({why})",
                    b.attr("typeName").unwrap_or(""),
                    b.attr("instanceName")
                        .map(|i| format!("`{i}`"))
                        .unwrap_or_else(|| format!("(localId {id})"))
                )
            });
        }
        // Ok while it is being emitted: a feedback loop through the block
        // reads its outputs as of the last scan.
        self.emitted_blocks.insert(id.clone(), Ok(()));
        let r = self.emit_block(b);
        self.emitted_blocks.insert(id, r.clone());
        r
    }

    fn emit_block(&mut self, b: &Elem) -> Result<(), String> {
        let ty = b.attr("typeName").unwrap_or("").to_ascii_uppercase();
        match ty.as_str() {
            "TON" | "TOF" | "TP" => {
                let t = self.instance(b, &VarKind::Timer)?;
                let input = self.power_of(b, "IN")?;
                let pt = match block_input(b, "PT") {
                    Some(c) => self.data_in(&c)?,
                    None => "?".to_string(),
                };
                let args = if pt.parse::<i64>().is_ok() {
                    let pre: i64 = pt.parse().unwrap_or(0);
                    Some(self.structs.timer(&t, pre)?)
                } else {
                    None
                };
                let args = args.unwrap_or_else(|| format!("{t},{pt},0"));
                self.e
                    .emit(input, "", &format!("{ty}({args})"), std::slice::from_ref(&t));
                Ok(())
            }
            "CTU" | "CTD" | "CTUD" => {
                let c = self.instance(b, &VarKind::Counter)?;
                let pv = match block_input(b, "PV") {
                    Some(conns) => self.data_in(&conns)?,
                    None => "0".to_string(),
                };
                let lit: Option<i64> = pv.parse().ok();
                let args = match lit {
                    Some(p) => self.structs.counter(&c, p, 0).0,
                    None => format!("{c},{pv},0"),
                };
                let w = std::slice::from_ref(&c);
                if ty == "CTU" || ty == "CTUD" {
                    let cu = self.power_of(b, "CU")?;
                    self.e.emit(cu, "", &format!("CTU({args})"), w);
                }
                if ty == "CTD" || ty == "CTUD" {
                    let cd = self.power_of(b, "CD")?;
                    self.e.emit(cd, "", &format!("CTD({args})"), w);
                    if let Some(ld) = block_input(b, "LD") {
                        let ld = self.power_in(&ld)?;
                        self.e.emit(ld, "", &format!("MOV({pv},{c}.ACC)"), w);
                    }
                }
                if (ty == "CTU" || ty == "CTUD")
                    && let Some(r) = block_input(b, "R")
                {
                    let r = self.power_in(&r)?;
                    self.e.emit(r, "", &format!("MOV(0,{c}.ACC)"), w);
                }
                Ok(())
            }
            "R_TRIG" | "F_TRIG" => {
                let inst = b.attr("instanceName").unwrap_or("trig");
                match self.var(inst).map(|v| v.kind.clone()) {
                    Some(VarKind::Trig) => {}
                    _ => return Err(format!("instance `{inst}` is not declared as an {ty}")),
                }
                let (m, q) = self.trig_bits(inst);
                if ty == "F_TRIG" {
                    self.notes.push((
                        Kind::Approximated,
                        b.start,
                        format!("F_TRIG `{inst}`: IEC's gives a pulse on the first scan when CLK is false, Alba's OSF does not"),
                    ));
                }
                let clk = self.power_of(b, "CLK")?;
                let mn = if ty == "R_TRIG" { "OSR" } else { "OSF" };
                self.e.emit(clk, "", &format!("{mn}({m},{q})"), &[m, q]);
                Ok(())
            }
            "GT" | "GE" | "EQ" | "NE" | "LT" | "LE" => Ok(()),
            t if FUNCTIONS.contains(&t) || conversion(t).is_some() => {
                let id = b.attr("localId").unwrap_or("").to_string();
                let conv = conversion(t);
                if let Some(c) = &conv
                    && let Some(why) = c.refused()
                {
                    return Err(format!("{ty}: {why}"));
                }
                let en = self.enable(b)?;
                let ins: Vec<String> = if ty == "MOVE" || conv.is_some() {
                    vec!["IN".into()]
                } else {
                    vec!["IN1".into(), "IN2".into()]
                };
                let mut ops = Vec::new();
                // MOVE of an ST expression is a CPT.
                let mut expr: Option<String> = None;
                for i in &ins {
                    let c = block_input(b, i).ok_or_else(|| format!("{ty}: input {i} is not connected"))?;
                    if ty == "MOVE"
                        && let [(sid, p)] = c.as_slice()
                        && let Out::Expr(e) = self.out(sid, p)?
                    {
                        expr = Some(e);
                        ops.push(String::new());
                        continue;
                    }
                    ops.push(self.data_in(&c)?);
                }
                let direct = self.sole_out.get(&id).cloned().and_then(|ov| {
                    let el = self.elems.get(&ov)?;
                    let expr = el.child("expression").map(|x| x.text.trim().to_string())?;
                    match self.operand(&expr) {
                        Ok((op, false)) if op.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') => {
                            Some((ov, op))
                        }
                        _ => None,
                    }
                });
                let helper = match &direct {
                    Some((ov, op)) => {
                        self.handled.push(ov.clone());
                        op.clone()
                    }
                    None => {
                        let floating = |t: &str| {
                            self.is_real(t)
                                || t.contains('.')
                                || (t.len() > 1
                                    && ST_FUNCTIONS.iter().any(|(_, f)| *f == t && *f != "ABS" && *f != "TRN"))
                        };
                        let real = ops.iter().any(|o| self.is_real(o))
                            || expr.as_deref().is_some_and(|e| e.split_whitespace().any(floating));
                        let result_ty = match &conv {
                            Some(c) => c.to,
                            None if real => "REAL",
                            None => "DINT",
                        };
                        let helper = self.e.names().fresh(&format!("{}_out", ty.to_ascii_lowercase()));
                        self.data_helpers.push((
                            helper.clone(),
                            result_ty.to_string(),
                            format!("output OUT of {ty} block {id}"),
                        ));
                        helper
                    }
                };
                let text = if let Some(e) = &expr {
                    format!("CPT({helper},{e})")
                } else if let Some(c) = &conv {
                    if let Some(note) = c.note(self.ms_time) {
                        self.notes.push((Kind::Approximated, b.start, format!("{ty}: {note}")));
                    }
                    c.text(&ops[0], &helper, self.ms_time)
                } else if ty == "MOVE" {
                    format!("MOV({},{helper})", ops[0])
                } else {
                    format!("{ty}({},{},{helper})", ops[0], ops[1])
                };
                if !self.e.is_true(en) && direct.is_none() {
                    self.notes.push((
                        Kind::Approximated,
                        b.start,
                        format!(
                            "{ty} with EN: while EN is false its OUT ({helper}) keeps the last result (IEC leaves it to the implementation)"
                        ),
                    ));
                }
                self.e.emit(en, "", &text, std::slice::from_ref(&helper));
                self.block_out_data.insert(id, helper);
                Ok(())
            }
            other => Err(format!(
                "block `{other}` is not converted (only TON TOF TP CTU CTD CTUD R_TRIG F_TRIG, GT GE EQ NE LT LE, ADD SUB MUL DIV MOD MOVE, and X_TO_Y between numbers and from TIME)"
            )),
        }
    }

    /// The power into a block's EN (the rail when EN is not wired).
    fn enable(&mut self, b: &Elem) -> Result<Cond, String> {
        match block_input(b, "EN") {
            Some(c) => self.power_in(&c),
            None => Ok(self.e.rail()),
        }
    }

    /// Whether an Alba operand is a REAL/LREAL (tag or literal).
    fn is_real(&self, op: &str) -> bool {
        if op.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+') {
            return op.contains(['.', 'e', 'E']);
        }
        if let Some((_, ty, _)) = self.data_helpers.iter().find(|(h, _, _)| h == op) {
            return ty == "REAL";
        }
        self.vars.values().any(|v| {
            v.alba.eq_ignore_ascii_case(op) && matches!(&v.kind, VarKind::Tag(t) if t == "REAL" || t == "LREAL")
        })
    }

    fn trig_bits(&mut self, inst: &str) -> (String, String) {
        let base = inst.replace(|c: char| !c.is_ascii_alphanumeric() && c != '_', "_");
        let m = self.e.names().fresh(&format!("{base}_M"));
        let q = self.e.names().fresh(&format!("{base}_Q"));
        self.e.helpers.push((m.clone(), format!("memory of {inst}")));
        self.e.helpers.push((q.clone(), format!("output Q of {inst}")));
        self.trig_q.insert(inst.to_ascii_lowercase(), q.clone());
        (m, q)
    }

    fn block_out(&mut self, b: &Elem, param: &str) -> Result<Out, String> {
        self.run_block(b)?;
        let ty = b.attr("typeName").unwrap_or("").to_ascii_uppercase();
        let p = param.to_ascii_uppercase();
        let inst = b.attr("instanceName").unwrap_or("");
        let alba = self.var(inst).map(|v| v.alba.clone()).unwrap_or_default();
        let pv = || -> Option<Vec<(String, String)>> { block_input(b, "PV") };
        match (ty.as_str(), p.as_str()) {
            ("TON" | "TOF" | "TP", "Q" | "") => {
                let dn = format!("{alba}.DN");
                Ok(Out::Power(self.e.input(&format!("XIC({dn})"), &[alba])))
            }
            ("TON" | "TOF" | "TP", "ET") => Ok(Out::Data(format!("{alba}.ACC"))),
            ("CTU", "Q" | "") | ("CTUD", "QU") => {
                let pv = match pv() {
                    Some(c) => self.data_in(&c)?,
                    None => "0".into(),
                };
                Ok(Out::Power(self.e.input(&format!("GEQ({alba}.ACC,{pv})"), &[alba])))
            }
            ("CTD", "Q" | "") | ("CTUD", "QD") => Ok(Out::Power(self.e.input(&format!("LEQ({alba}.ACC,0)"), &[alba]))),
            ("CTU" | "CTD" | "CTUD", "CV") => Ok(Out::Data(format!("{alba}.ACC"))),
            ("R_TRIG" | "F_TRIG", "Q" | "") => {
                let q = self.trig_q.get(&inst.to_ascii_lowercase()).cloned().unwrap_or_default();
                Ok(Out::Power(self.e.input(&format!("XIC({q})"), &[q])))
            }
            ("GT" | "GE" | "EQ" | "NE" | "LT" | "LE", "OUT" | "") => {
                let a = block_input(b, "IN1").ok_or_else(|| format!("{ty}: IN1 is not connected"))?;
                let c2 = block_input(b, "IN2").ok_or_else(|| format!("{ty}: IN2 is not connected"))?;
                if block_input(b, "IN3").is_some() {
                    return Err(format!("{ty} with more than two inputs"));
                }
                let a = self.data_in(&a)?;
                let c2 = self.data_in(&c2)?;
                let m = match ty.as_str() {
                    "GT" => "GRT",
                    "GE" => "GEQ",
                    "EQ" => "EQU",
                    "NE" => "NEQ",
                    "LT" => "LES",
                    _ => "LEQ",
                };
                let en = self.enable(b)?;
                let reads: Vec<String> = [&a, &c2]
                    .iter()
                    .filter(|o| o.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_'))
                    .map(|o| (*o).clone())
                    .collect();
                Ok(Out::Power(self.e.and(en, &format!("{m}({a},{c2})"), &reads)))
            }
            (t, "OUT" | "") if FUNCTIONS.contains(&t) || conversion(t).is_some() => {
                let id = b.attr("localId").unwrap_or("");
                self.block_out_data
                    .get(id)
                    .cloned()
                    .map(Out::Data)
                    .ok_or_else(|| format!("{ty} has no result"))
            }
            // No converted block can fail, so ENO is EN (IEC 61131-3: ENO is
            // false when EN is, true when the block ran without error).
            (_, "ENO") => Ok(Out::Power(self.enable(b)?)),
            (t, p) => Err(format!("output `{p}` of {t}")),
        }
    }
}

/// The `externalVars` of a POU: declared by the configuration; unknown ones
/// become tags, global from then on (so the next POU naming one shares the
/// tag, not declares it again).
fn external_vars(
    conv: &mut Conv<'_>,
    list: &Elem,
    scope: &mut HashMap<String, Var>,
    globals: &mut HashMap<String, Var>,
) {
    let mut l2 = list.clone();
    l2.children.retain(|c| {
        c.name == "variable"
            && c.attr("name")
                .is_some_and(|n| !scope.contains_key(&n.to_ascii_lowercase()))
    });
    if l2.children.is_empty() {
        return;
    }
    let mut ext = HashMap::new();
    let mut tmp = Conv {
        ctx: Ctx {
            file: conv.ctx.file,
            text: conv.ctx.text,
        },
        report: Report::default(),
        names: std::mem::take(&mut conv.names),
        structs: Structs::default(),
        tags: Vec::new(),
        globals: HashMap::new(),
    };
    tmp.declare(&l2, &mut ext, "global");
    conv.names = tmp.names;
    conv.tags.extend(tmp.tags);
    conv.report.entries.extend(tmp.report.entries);
    globals.extend(ext.clone());
    scope.extend(ext);
}

/// The tags a function or function block names through its `externalVars`.
fn external_tags(
    conv: &mut Conv<'_>,
    pou: &Elem,
    scope: &mut HashMap<String, Var>,
    globals: &mut HashMap<String, Var>,
) {
    if let Some(iface) = pou.child("interface") {
        for list in iface.all("externalVars") {
            external_vars(conv, list, scope, globals);
        }
    }
}

/// Converts a PLCopen project.
pub fn convert(file: &str, stem: &str, text: &str, _opts: &Options) -> Result<(Project, Report), Error> {
    let ctx = Ctx { file, text };
    let root = parse_root(&ctx, "project", "a PLCopen project")?;
    let ns_ok = root
        .attrs
        .iter()
        .any(|(k, v)| k.starts_with("xmlns") && v.contains("plcopen.org/xml/tc6"));
    if !ns_ok {
        return Err(Error::at(
            ctx.loc(&root),
            "not PLCopen TC6 XML: <project> lacks the namespace http://www.plcopen.org/xml/tc6_0201",
        ));
    }
    let mut conv = Conv {
        ctx,
        report: Report::default(),
        names: Names::new(),
        structs: Structs::default(),
        tags: Vec::new(),
        globals: HashMap::new(),
    };
    let name = root
        .child("contentHeader")
        .and_then(|h| h.attr("name"))
        .unwrap_or(stem)
        .to_string();

    // User types and function blocks, by which ST variables are declared.
    let types_el = root.child("types");
    let mut known: std::collections::HashSet<String> = types_el
        .and_then(|t| t.child("dataTypes"))
        .map(|d| {
            d.all("dataType")
                .filter_map(|d| d.attr("name"))
                .map(str::to_ascii_lowercase)
                .collect()
        })
        .unwrap_or_default();
    known.extend(
        types_el
            .and_then(|t| t.child("pous"))
            .into_iter()
            .flat_map(|p| p.all("pou"))
            .filter(|p| p.attr("pouType") != Some("program"))
            .filter_map(|p| p.attr("name"))
            .map(str::to_ascii_lowercase),
    );
    // Global variables and the scan period of the configurations; globals of
    // the file's types are ST (`globals.st`, one file-level VAR_GLOBAL).
    let mut global_st: Vec<(Location, String, String)> = Vec::new();
    let mut scan_ms: Option<u32> = None;
    let mut instances: Vec<String> = Vec::new();
    let mut tasks: Vec<(i64, String)> = Vec::new();
    let mut globals = HashMap::new();
    if let Some(cfgs) = root.child("instances").and_then(|i| i.child("configurations")) {
        for cfg in cfgs.all("configuration") {
            for gv in cfg.all("globalVars") {
                let gv = st::user_globals(&mut conv, gv, &known, &mut globals, &mut global_st);
                conv.declare(&gv, &mut globals, "global");
            }
            for res in cfg.all("resource") {
                for gv in res.all("globalVars") {
                    let gv = st::user_globals(&mut conv, gv, &known, &mut globals, &mut global_st);
                    conv.declare(&gv, &mut globals, "global");
                }
                for task in res.all("task") {
                    let loc = conv.ctx.loc(task);
                    if let Some(iv) = task.attr("interval") {
                        let ms = iv
                            .trim()
                            .to_ascii_uppercase()
                            .strip_prefix("T#")
                            .or_else(|| iv.trim().to_ascii_uppercase().strip_prefix("TIME#").map(|_| ""))
                            .and_then(duration_ms);
                        match ms {
                            Some(ms) if (1..=60_000).contains(&ms) && scan_ms.is_none() => {
                                scan_ms = u32::try_from(ms).ok();
                                conv.report
                                    .push(Kind::Converted, loc, format!("task interval {iv}: scan_ms = {ms}"));
                            }
                            _ => conv.report.push(
                                Kind::Approximated,
                                loc,
                                format!(
                                    "task `{}` ({iv}): Alba has one scan period",
                                    task.attr("name").unwrap_or("")
                                ),
                            ),
                        }
                    }
                    // A task of higher priority (a lower number) runs its
                    // programs first in Alba's one scan.
                    let prio = task
                        .attr("priority")
                        .and_then(|p| p.trim().parse::<i64>().ok())
                        .unwrap_or(i64::MAX);
                    for pi in task.all("pouInstance") {
                        if let Some(t) = pi.attr("typeName") {
                            tasks.push((prio, t.to_ascii_lowercase()));
                        }
                    }
                }
                tasks.sort_by_key(|(p, _)| *p);
                instances.extend(tasks.drain(..).map(|(_, t)| t));
                for pi in res.all("pouInstance") {
                    if let Some(t) = pi.attr("typeName") {
                        instances.push(t.to_ascii_lowercase());
                    }
                }
            }
        }
    }
    conv.globals = globals.clone();

    let mut programs = Vec::new();
    let pous: Vec<&Elem> = root
        .child("types")
        .and_then(|t| t.child("pous"))
        .map(|p| p.all("pou").collect())
        .unwrap_or_default();
    // Programs in the order of the tasks' instances, then the others.
    let mut ordered: Vec<&Elem> = Vec::new();
    for i in &instances {
        if let Some(p) = pous
            .iter()
            .find(|p| p.attr("name").map(str::to_ascii_lowercase).as_deref() == Some(i))
            && !ordered.iter().any(|o| std::ptr::eq(*o, *p))
        {
            ordered.push(p);
        }
    }
    for p in &pous {
        if !ordered.iter().any(|o| std::ptr::eq(*o, *p)) {
            ordered.push(p);
        }
    }
    // `types.st` and the functions and function blocks, before the programs.
    let mut library: Vec<ProgramOut> = Vec::new();
    let mut refused_programs: Vec<String> = Vec::new();
    let ms_time = root
        .child("fileHeader")
        .and_then(|h| h.attr("productName"))
        .is_some_and(|p| p.to_ascii_uppercase().contains("CODESYS"));
    for pou in ordered {
        let loc = conv.ctx.loc(pou);
        let pname = pou.attr("name").unwrap_or("").to_string();
        let kind = pou.attr("pouType").unwrap_or("");
        let body = pou.child("body");
        let lang = body.and_then(|b| {
            b.children
                .iter()
                .find(|c| c.name != "documentation" && c.name != "addData")
        });
        if kind != "program" {
            let st = lang.filter(|l| l.name == "ST");
            match st {
                Some(st) if kind == "function" || kind == "functionBlock" => {
                    let mut scope = globals.clone();
                    external_tags(&mut conv, pou, &mut scope, &mut globals);
                    if let Some(out) = st::convert(&mut conv, pou, st, (&pname, kind), &known, &mut scope) {
                        library.push(out);
                    }
                }
                _ => conv.report.push(
                    Kind::Refused,
                    loc,
                    format!(
                        "{kind} `{pname}` has a {} body: Alba imports functions and function blocks written in ST",
                        lang.map(|l| l.name.as_str()).unwrap_or("no")
                    ),
                ),
            }
            continue;
        }
        let Some(ld) = lang.filter(|l| l.name == "LD" || l.name == "SFC" || l.name == "ST") else {
            let what = lang.map(|l| l.name.clone()).unwrap_or_else(|| "no".into());
            conv.report.push(
                Kind::Refused,
                loc,
                format!("program `{pname}` has a {what} body; only LD, SFC and ST bodies are imported"),
            );
            refused_programs.push(format!("`{pname}` ({what})"));
            continue;
        };
        let is_sfc = ld.name == "SFC";
        let is_st = ld.name == "ST";
        if !is_sfc && pou.child("actions").is_some_and(|a| !a.children.is_empty()) {
            conv.report.push(
                Kind::Refused,
                loc.clone(),
                format!("the actions of program `{pname}` are not imported"),
            );
        }
        let mut scope = globals.clone();
        if let Some(iface) = pou.child("interface") {
            for list in &iface.children {
                if matches!(
                    list.name.as_str(),
                    "localVars" | "inputVars" | "outputVars" | "inOutVars" | "externalVars" | "globalVars" | "tempVars"
                ) {
                    if list.name == "externalVars" {
                        external_vars(&mut conv, list, &mut scope, &mut globals);
                    } else if !is_st {
                        conv.declare(list, &mut scope, &pname);
                    }
                }
            }
        }
        if is_st {
            let before = conv.report.entries.len();
            match st::convert(&mut conv, pou, ld, (&pname, kind), &known, &mut scope) {
                Some(prog) => programs.push(prog),
                None => {
                    // Why, by its first refusal (a syntax error at its line).
                    let first = conv.report.entries[before..]
                        .iter()
                        .find(|e| e.kind == Kind::Refused)
                        .map(|e| format!(", refused at {}:{}: {}", e.location.line, e.location.col, e.message))
                        .unwrap_or_default();
                    refused_programs.push(format!("`{pname}` (ST{first})"));
                }
            }
            continue;
        }
        if is_sfc {
            // Actions with an ST body: `ACTION … END_ACTION` blocks of the
            // chart, which runs each body while its associations hold.
            let actions = st::declare_actions(&mut conv, pou, &pname, &mut scope);
            match sfc::convert(&conv.ctx, pou, ld, &pname, &scope, &mut conv.report)? {
                Some(mut prog) => {
                    if !st::action_blocks(&mut conv, pou, &pname, &scope, &actions, &mut prog) {
                        // The associations name actions the chart no longer has.
                        for a in &actions {
                            scope.remove(&a.name().to_ascii_lowercase());
                        }
                        match sfc::convert(&conv.ctx, pou, ld, &pname, &scope, &mut Report::default())? {
                            Some(p) => prog = p,
                            None => continue,
                        }
                    }
                    programs.push(prog);
                }
                None => refused_programs.push(format!("`{pname}` (SFC)")),
            }
            continue;
        }
        let mut elems: HashMap<String, &Elem> = HashMap::new();
        for el in &ld.children {
            if let Some(id) = el.attr("localId")
                && elems.insert(id.to_string(), el).is_some()
            {
                return Err(Error::at(
                    conv.ctx.loc(el),
                    format!("localId {id} is used twice in `{pname}`"),
                ));
            }
        }
        // Sinks in execution order, else top to bottom, left to right.
        let pos = |e: &Elem| -> (i64, i64, i64) {
            let ord = e
                .attr("executionOrderId")
                .and_then(|s| s.parse::<i64>().ok())
                .unwrap_or(0);
            let p = e.child("position");
            let y = p
                .and_then(|p| p.attr("y"))
                .and_then(|s| s.parse::<f64>().ok())
                .unwrap_or(0.0) as i64;
            let x = p
                .and_then(|p| p.attr("x"))
                .and_then(|s| s.parse::<f64>().ok())
                .unwrap_or(0.0) as i64;
            (if ord > 0 { ord } else { i64::MAX }, y, x)
        };
        let mut sinks: Vec<&Elem> = ld
            .children
            .iter()
            .filter(|e| {
                matches!(
                    e.name.as_str(),
                    "coil" | "outVariable" | "inOutVariable" | "block" | "comment"
                )
            })
            .collect();
        let ordered_by_exec = sinks.iter().any(|e| pos(e).0 != i64::MAX);
        if ordered_by_exec {
            // Executed elements in their order; each comment goes before the
            // first of them drawn at or below it.
            let (comments, mut rest): (Vec<&Elem>, Vec<&Elem>) = sinks.iter().partition(|e| e.name == "comment");
            rest.sort_by_key(|e| pos(e));
            for c in comments {
                let cy = pos(c).1;
                let at = rest.iter().position(|e| pos(e).1 >= cy).unwrap_or(rest.len());
                rest.insert(at, c);
            }
            sinks = rest;
        } else {
            sinks.sort_by_key(|e| {
                let (_, y, x) = pos(e);
                (y, x)
            });
        }
        for el in &ld.children {
            if matches!(
                el.name.as_str(),
                "jump" | "label" | "return" | "connector" | "continuation"
            ) {
                conv.report.push(
                    Kind::Refused,
                    conv.ctx.loc(el),
                    format!("<{}> in `{pname}` is not converted", el.name),
                );
            }
        }
        let mut names = std::mem::take(&mut conv.names);
        let mut lines: Vec<(String, usize)> = Vec::new();
        // Readers of every block OUT, to write a function's result straight
        // into its only output variable.
        let mut readers: HashMap<String, Vec<(String, bool)>> = HashMap::new();
        for el in &ld.children {
            let mut points: Vec<&Elem> = Vec::new();
            el.descendants("connectionPointIn", &mut points);
            for pt in points {
                for (id, param) in connections(Some(pt)) {
                    if param.eq_ignore_ascii_case("OUT") {
                        readers
                            .entry(id)
                            .or_default()
                            .push((el.attr("localId").unwrap_or("").to_string(), el.name == "outVariable"));
                    }
                }
            }
        }
        let sole_out: HashMap<String, String> = readers
            .into_iter()
            .filter_map(|(id, r)| match r.as_slice() {
                [(ov, true)] => Some((id, ov.clone())),
                _ => None,
            })
            .collect();
        let mut origins: Vec<Location> = Vec::new();
        let mut refusals: Vec<(Location, String)> = Vec::new();
        {
            let mut body = Body {
                elems,
                vars: &scope,
                memo: HashMap::new(),
                visiting: Vec::new(),
                emitted_blocks: HashMap::new(),
                e: Emitter::new(&mut names, "pwr"),
                pou: pname.clone(),
                structs: std::mem::take(&mut conv.structs),
                trig_q: HashMap::new(),
                notes: Vec::new(),
                data_helpers: Vec::new(),
                block_out_data: HashMap::new(),
                sole_out,
                handled: Vec::new(),
                ms_time,
            };
            for s in &sinks {
                origins.push(conv.ctx.loc(s));
                body.e.set_origin(origins.len() - 1);
                if s.name == "comment" {
                    let t = collect_text(s);
                    for l in t.lines() {
                        let l = l.trim();
                        if !l.is_empty() {
                            body.e.comment(l);
                        }
                    }
                    continue;
                }
                if body.e.bytes() > crate::MAX_OUTPUT_BYTES {
                    return Err(Error::at(
                        conv.ctx.loc(s),
                        format!(
                            "the converted program would exceed {} MiB",
                            crate::MAX_OUTPUT_BYTES >> 20
                        ),
                    ));
                }
                if let Err(why) = body.sink(s) {
                    let what = match s.name.as_str() {
                        "coil" | "outVariable" | "inOutVariable" => format!(
                            "<{}> `{}`",
                            s.name,
                            s.child("variable")
                                .or_else(|| s.child("expression"))
                                .map(|v| v.text.trim())
                                .unwrap_or("")
                        ),
                        _ => format!("block {}", s.attr("typeName").unwrap_or("")),
                    };
                    refusals.push((conv.ctx.loc(s), format!("{what}: {why}")));
                    body.e.comment(&format!("REFUSED by alba import: {what} ({why})"));
                } else if matches!(s.name.as_str(), "block") {
                    let msg = match s.attr("instanceName") {
                        Some(i) => format!("{} `{i}`", s.attr("typeName").unwrap_or("")),
                        None => format!("{} function", s.attr("typeName").unwrap_or("")),
                    };
                    conv.report.push(Kind::Converted, conv.ctx.loc(s), msg);
                }
            }
            for (k, off, m) in std::mem::take(&mut body.notes) {
                conv.report.push(k, conv.ctx.loc_at(off), m);
            }
            conv.structs = std::mem::take(&mut body.structs);
            for (h, ty, what) in std::mem::take(&mut body.data_helpers) {
                conv.tags.push(TagOut {
                    name: h,
                    ty,
                    address: String::new(),
                    initial: String::new(),
                    description: format!("alba import: {what}"),
                });
            }
            let helpers = std::mem::take(&mut body.e.helpers);
            for (h, what) in helpers {
                conv.tags.push(TagOut {
                    name: h,
                    ty: "BOOL".into(),
                    address: String::new(),
                    initial: String::new(),
                    description: format!("alba import: {what}"),
                });
            }
            lines.extend(body.e.finish_with_origins());
        }
        conv.names = names;
        for (l, m) in refusals {
            conv.report.push(Kind::Refused, l, m);
        }
        let file_name = format!("{}.lad", crate::names::file_stem(&pname));
        let mut prog = ProgramOut::new(file_name);
        for (l, o) in lines {
            let origin = origins.get(o);
            if l.starts_with("//") {
                prog.line(&l, origin);
            } else {
                prog.line(&format!("{l};"), origin);
            }
        }
        programs.push(prog);
    }
    if !programs.is_empty() {
        if let Some(t) = types_el {
            let taken = |f: &str| library.iter().chain(&programs).any(|p| p.file.eq_ignore_ascii_case(f));
            let file = ["types.st", "data_types.st", "alba_types.st"]
                .into_iter()
                .find(|f| !taken(f))
                .unwrap_or("alba_import_types.st");
            if let Some(types) = st::data_types(&mut conv, t, &known, file.to_string()) {
                library.insert(0, types);
            }
        }
        if !global_st.is_empty() {
            let taken = |f: &str| library.iter().chain(&programs).any(|p| p.file.eq_ignore_ascii_case(f));
            let file = ["globals.st", "alba_globals.st"]
                .into_iter()
                .find(|f| !taken(f))
                .unwrap_or("alba_import_globals.st");
            let mut g = ProgramOut::new(file.to_string());
            let mut blocks: Vec<&str> = Vec::new();
            for (_, b, _) in &global_st {
                if !blocks.contains(&b.as_str()) {
                    blocks.push(b);
                }
            }
            for block in blocks {
                g.line(block, None);
                for (loc, _, line) in global_st.iter().filter(|(_, b, _)| b == block) {
                    g.line(line, Some(loc));
                }
                g.line("END_VAR", None);
            }
            // After the types it names, before the POUs.
            let at = usize::from(library.first().is_some_and(|p| p.file.ends_with("types.st")));
            library.insert(at, g);
        }
        library.append(&mut programs);
        programs = library;
    }
    if programs.is_empty() {
        let why = if refused_programs.is_empty() {
            "it has no program POU".to_string()
        } else {
            format!("its programs are {}", refused_programs.join(", "))
        };
        return Err(Error::at(
            conv.ctx.loc(&root),
            format!("nothing to import: Alba imports LD, SFC and ST bodies of programs, and {why}"),
        ));
    }
    let mut report = conv.report;
    report.entries.sort_by_key(|e| (e.location.line, e.location.col));
    Ok((
        Project {
            name,
            description: String::new(),
            scan_ms: scan_ms.unwrap_or(10),
            board: None,
            tags: conv.tags,
            programs,
            ..Project::default()
        },
        report,
    ))
}
