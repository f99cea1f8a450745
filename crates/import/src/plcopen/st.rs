//! ST bodies of PLCopen POUs. A `program` becomes `<program>.st`, a
//! `PROGRAM` whose `VAR` blocks are the POU's interface and whose body is
//! the `<ST>` text unchanged. Located variables (`%IX0.0`) are tags with
//! their address (alba-st refuses `AT`), the configuration's globals are
//! tags, and `externalVars` name them. A `function` or `functionBlock`
//! becomes `<name>.st`, a `FUNCTION`/`FUNCTION_BLOCK` with its interface as
//! `VAR_INPUT`/`VAR_OUTPUT`/`VAR_IN_OUT`/`VAR`/`VAR_TEMP` (the other `.st`
//! files of a project are its library, so the programs call it), and the
//! `<dataTypes>` become `types.st` (STRUCTs, enumerations, ARRAYs,
//! subranges, aliases). Variables of a type alba-st does not run, and
//! syntax errors of the body, are refused at their place in the XML; the
//! POU is then not written.

use super::{Conv, Ctx, Var, VarKind, collect_text};
use crate::{Kind, Location, ProgramOut};
use alba_xml::Elem;
use std::collections::{HashMap, HashSet};

/// Elementary types and standard FBs whose variables run on the engine
/// (docs/st.md).
const RUNS: &[&str] = &[
    "BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "BYTE", "WORD", "DWORD", "LWORD", "REAL",
    "LREAL", "TIME", "LTIME", "DATE", "TOD", "DT", "TON", "TOF", "TP", "CTU", "CTD", "CTUD", "R_TRIG", "F_TRIG", "SR",
    "RS",
];

/// The ST text of a PLCopen `<type>`'s content, or why not. `known` holds
/// the user types and function blocks of the file (lower case).
fn st_type(t: &Elem, known: &HashSet<String>) -> Result<String, String> {
    let up = t.name.to_ascii_uppercase();
    let ty = match up.as_str() {
        "DERIVED" => {
            let name = t.attr("name").ok_or("a derived type without a name")?;
            if known.contains(&name.to_ascii_lowercase()) {
                return Ok(name.to_string());
            }
            name.to_ascii_uppercase()
        }
        "ARRAY" => {
            let dims: Vec<String> = t
                .all("dimension")
                .map(|d| format!("{}..{}", d.attr("lower").unwrap_or("0"), d.attr("upper").unwrap_or("0")))
                .collect();
            let base = t
                .child("baseType")
                .and_then(|b| b.children.first())
                .ok_or("an array without a base type")?;
            return Ok(format!("ARRAY[{}] OF {}", dims.join(", "), st_type(base, known)?));
        }
        "SUBRANGESIGNED" | "SUBRANGEUNSIGNED" => {
            let r = t.child("range").ok_or("a subrange without a range")?;
            let base = t
                .child("baseType")
                .and_then(|b| b.children.first())
                .ok_or("a subrange without a base type")?;
            return Ok(format!(
                "{}({}..{})",
                st_type(base, known)?,
                r.attr("lower").unwrap_or("0"),
                r.attr("upper").unwrap_or("0")
            ));
        }
        "ENUM" => {
            let values: Vec<String> = t
                .child("values")
                .map(|v| {
                    v.all("value")
                        .filter_map(|v| {
                            let n = v.attr("name")?;
                            Some(match v.attr("value") {
                                Some(x) => format!("{n} := {x}"),
                                None => n.to_string(),
                            })
                        })
                        .collect()
                })
                .unwrap_or_default();
            if values.is_empty() {
                return Err("an enumeration without values".into());
            }
            return Ok(format!("({})", values.join(", ")));
        }
        // `<string length="n"/>`, `<wstring/>` (STRING[80] without one).
        "STRING" | "WSTRING" => {
            return Ok(match t.attr("length").map(str::trim).filter(|l| !l.is_empty()) {
                Some(n) => format!("{up}[{n}]"),
                None => up,
            });
        }
        _ => up,
    };
    if RUNS.contains(&ty.as_str()) {
        Ok(ty)
    } else {
        Err(format!("its type `{ty}` does not run in Alba's ST yet (docs/st.md)"))
    }
}

/// Takes the variables of a configuration's `globalVars` whose type is one
/// of the file's (`known`: an enumeration, a STRUCT, a function block) out
/// of `list`: each becomes a line of a file-level `VAR_GLOBAL` (with
/// `CONSTANT`, `RETAIN` as the list has them) in `lines`
/// (`mode : Mode_t := stopped;`), named in `globals` so the POUs'
/// `externalVars` find it; the rest is returned for the tags.
pub(super) fn user_globals(
    conv: &mut Conv<'_>,
    list: &Elem,
    known: &HashSet<String>,
    globals: &mut HashMap<String, Var>,
    lines: &mut Vec<(Location, String, String)>,
) -> Elem {
    let mut rest = list.clone();
    rest.children.retain(|v| {
        let Some(t) = v.child("type").and_then(|t| t.children.first()) else {
            return true;
        };
        let user = t.name == "derived" && t.attr("name").is_some_and(|n| known.contains(&n.to_ascii_lowercase()));
        let (Some(name), true) = (v.attr("name"), user) else {
            return true;
        };
        let loc = conv.ctx.loc(v);
        match st_type(t, known) {
            Ok(ty) => {
                let mut block = "VAR_GLOBAL".to_string();
                for (attr, word) in [("constant", " CONSTANT"), ("retain", " RETAIN")] {
                    if list.attr(attr) == Some("true") {
                        block.push_str(word);
                    }
                }
                lines.push((loc.clone(), block, format!("    {name} : {ty}{};", initial(v))));
                globals.insert(
                    name.to_ascii_lowercase(),
                    Var {
                        alba: name.to_string(),
                        kind: VarKind::Refused(format!("`{name}` is a global of the type `{ty}`, which only ST reads")),
                        fb: String::new(),
                    },
                );
                conv.report.push(
                    Kind::Converted,
                    loc,
                    format!("global `{name}` of type `{ty}`: a VAR_GLOBAL of ST"),
                );
            }
            Err(why) => conv.report.push(Kind::Refused, loc, format!("global `{name}`: {why}")),
        }
        false
    });
    rest
}

/// A variable's initial value in ST (` := …`), from its `<initialValue>`:
/// a simple value, an array value (`[1, 2, 3]`) or a structure value
/// (`(a := 1, b := 2)`).
fn initial(v: &Elem) -> String {
    fn value(e: &Elem) -> Option<String> {
        if let Some(s) = e.child("simpleValue") {
            return s.attr("value").map(|s| s.trim().to_string());
        }
        if let Some(a) = e.child("arrayValue") {
            let items: Option<Vec<String>> = a
                .all("value")
                .map(|v| {
                    let x = value(v)?;
                    Some(match v.attr("repetitionValue") {
                        Some(n) => format!("{n}({x})"),
                        None => x,
                    })
                })
                .collect();
            return Some(format!("[{}]", items?.join(", ")));
        }
        if let Some(st) = e.child("structValue") {
            let items: Option<Vec<String>> = st
                .all("value")
                .map(|v| Some(format!("{} := {}", v.attr("member")?, value(v)?)))
                .collect();
            return Some(format!("({})", items?.join(", ")));
        }
        None
    }
    v.child("initialValue")
        .and_then(value)
        .map(|s| format!(" := {s}"))
        .unwrap_or_default()
}

/// `types.st`: one `TYPE … END_TYPE` with every `<dataType>` of the file;
/// `None` when there are none or one is refused (each refusal is in the
/// report; the POUs that use it then do not check and are left out).
pub(super) fn data_types(
    conv: &mut Conv<'_>,
    types: &Elem,
    known: &HashSet<String>,
    file: String,
) -> Option<ProgramOut> {
    let ctx = Ctx {
        file: conv.ctx.file,
        text: conv.ctx.text,
    };
    let mut lines: Vec<(String, Location)> = Vec::new();
    for d in types
        .child("dataTypes")
        .map(|d| d.all("dataType").collect::<Vec<_>>())
        .unwrap_or_default()
    {
        let loc = ctx.loc(d);
        let Some(name) = d.attr("name") else { continue };
        let Some(base) = d.child("baseType").and_then(|b| b.children.first()) else {
            conv.report
                .push(Kind::Refused, loc, format!("data type `{name}` has no base type"));
            continue;
        };
        let init = initial(d);
        if base.name == "struct" {
            lines.push((format!("    {name} : STRUCT"), loc.clone()));
            for m in base.all("variable") {
                let mname = m.attr("name").unwrap_or("");
                match m
                    .child("type")
                    .and_then(|t| t.children.first())
                    .map(|t| st_type(t, known))
                {
                    Some(Ok(t)) => lines.push((format!("        {mname} : {t}{};", initial(m)), ctx.loc(m))),
                    Some(Err(why)) => {
                        conv.report.push(
                            Kind::Refused,
                            ctx.loc(m),
                            format!("member `{mname}` of data type `{name}`: {why}"),
                        );
                        return None;
                    }
                    None => {
                        conv.report.push(
                            Kind::Refused,
                            ctx.loc(m),
                            format!("member `{mname}` of data type `{name}` has no type"),
                        );
                        return None;
                    }
                }
            }
            lines.push(("    END_STRUCT;".into(), loc.clone()));
        } else {
            match st_type(base, known) {
                Ok(t) => lines.push((format!("    {name} : {t}{init};"), loc.clone())),
                Err(why) => {
                    conv.report
                        .push(Kind::Refused, loc, format!("data type `{name}`: {why}"));
                    return None;
                }
            }
        }
        conv.report
            .push(Kind::Converted, ctx.loc(d), format!("data type `{name}`"));
    }
    if lines.is_empty() {
        return None;
    }
    let mut prog = ProgramOut::new(file);
    let first = lines[0].1.clone();
    prog.line("TYPE", Some(&first));
    for (l, o) in &lines {
        prog.line(l, Some(o));
    }
    prog.line("END_TYPE", Some(&first));
    Some(prog)
}

/// Converts the ST body `st` of `pou` (named `pname`, of PLCopen type
/// `kind`: `program`, `function` or `functionBlock`); `known` holds the
/// user types and function blocks of the file (lower case). `None` when
/// something in it is refused (each refusal is in the report).
pub(super) fn convert(
    conv: &mut Conv<'_>,
    pou: &Elem,
    st: &Elem,
    (pname, kind): (&str, &str),
    known: &HashSet<String>,
    scope: &mut HashMap<String, Var>,
) -> Option<ProgramOut> {
    let (keyword, end) = match kind {
        "function" => ("FUNCTION", "END_FUNCTION"),
        "functionBlock" => ("FUNCTION_BLOCK", "END_FUNCTION_BLOCK"),
        _ => ("PROGRAM", "END_PROGRAM"),
    };
    let program = keyword == "PROGRAM";
    let ctx = Ctx {
        file: conv.ctx.file,
        text: conv.ctx.text,
    };
    let mut ok = true;
    let mut decls = String::new();
    if let Some(iface) = pou.child("interface") {
        for list in &iface.children {
            let kw = match (list.name.as_str(), program) {
                ("localVars", _) | ("inputVars" | "outputVars" | "inOutVars", true) => "VAR",
                ("inputVars", false) => "VAR_INPUT",
                ("outputVars", false) => "VAR_OUTPUT",
                ("inOutVars", false) => "VAR_IN_OUT",
                ("tempVars", _) => "VAR_TEMP",
                ("globalVars", _) => "VAR_GLOBAL",
                // Those of the file's types (the others are tags, named as they are).
                ("externalVars", _) => "VAR_EXTERNAL",
                _ => continue,
            };
            let mut block = String::new();
            let mut located = list.clone();
            located
                .children
                .retain(|v| v.name == "variable" && v.attr("address").is_some() && kw != "VAR_EXTERNAL");
            if !program {
                for v in &located.children {
                    conv.report.push(
                        Kind::Refused,
                        ctx.loc(v),
                        format!(
                            "variable `{}` of {keyword} `{pname}` has an address: only a program's variables may",
                            v.attr("name").unwrap_or("")
                        ),
                    );
                    ok = false;
                }
            } else if !located.children.is_empty() {
                conv.declare(&located, scope, pname);
                for v in &located.children {
                    let name = v.attr("name").unwrap_or("");
                    if let Some(var) = scope.get(&name.to_ascii_lowercase())
                        && var.alba != name
                    {
                        conv.report.push(
                            Kind::Refused,
                            ctx.loc(v),
                            format!(
                                "located variable `{name}` of `{pname}` had to be renamed `{}`",
                                var.alba
                            ),
                        );
                        ok = false;
                    }
                }
            }
            let of_file_type = |v: &Elem| {
                v.child("type")
                    .and_then(|t| t.child("derived"))
                    .and_then(|d| d.attr("name"))
                    .is_some_and(|n| known.contains(&n.to_ascii_lowercase()))
            };
            for v in list
                .all("variable")
                .filter(|v| v.attr("address").is_none() && (kw != "VAR_EXTERNAL" || of_file_type(v)))
            {
                let name = v.attr("name").unwrap_or("");
                let ty = v.child("type").and_then(|t| t.children.first());
                let ty = match ty.map(|t| st_type(t, known)) {
                    Some(Ok(t)) => t,
                    Some(Err(why)) => {
                        conv.report.push(
                            Kind::Refused,
                            ctx.loc(v),
                            format!("variable `{name}` of `{pname}`: {why}"),
                        );
                        ok = false;
                        continue;
                    }
                    None => {
                        conv.report.push(
                            Kind::Refused,
                            ctx.loc(v),
                            format!("variable `{name}` of `{pname}` has no type"),
                        );
                        ok = false;
                        continue;
                    }
                };
                let init = initial(v);
                block.push_str(&format!("    {name} : {ty}{init};\n"));
            }
            if program && !block.is_empty() && matches!(list.name.as_str(), "inputVars" | "outputVars" | "inOutVars") {
                conv.report.push(
                    Kind::Approximated,
                    ctx.loc(list),
                    format!(
                        "the {} of program `{pname}` are its variables (VAR): nothing passes a program parameters in Alba",
                        list.name
                    ),
                );
            }
            if !block.is_empty() {
                let retain = if list.attr("retain") == Some("true") {
                    " RETAIN"
                } else {
                    ""
                };
                let constant = if list.attr("constant") == Some("true") {
                    " CONSTANT"
                } else {
                    ""
                };
                decls.push_str(&format!("{kw}{retain}{constant}\n{block}END_VAR\n"));
            }
        }
    }
    let ret = match (kind, pou.child("interface").and_then(|i| i.child("returnType"))) {
        ("function", Some(r)) => match r.children.first().map(|t| st_type(t, known)) {
            Some(Ok(t)) => format!(" : {t}"),
            Some(Err(why)) => {
                conv.report
                    .push(Kind::Refused, ctx.loc(r), format!("the result of `{pname}`: {why}"));
                ok = false;
                String::new()
            }
            None => String::new(),
        },
        ("function", None) => {
            conv.report.push(
                Kind::Refused,
                ctx.loc(pou),
                format!("function `{pname}` has no returnType"),
            );
            ok = false;
            String::new()
        }
        _ => String::new(),
    };
    let (body, body_at) = st_body(&ctx, st);
    let body = body.as_str();
    let head = format!("{keyword} {pname}{ret}\n{decls}");
    let text = format!("{head}{body}\n{end}\n");
    // Syntax errors, located in the XML (the body is the CDATA verbatim).
    let (_, diags) = alba_compiler::st::parse(&text, alba_diag::FileId(0));
    for d in &diags {
        let loc = match (d.primary.as_ref(), body_at) {
            (Some(l), Some(at)) if l.span.start as usize >= head.len() => {
                ctx.loc_at(at + (l.span.start as usize - head.len()).min(body.len()))
            }
            _ => ctx.loc(st),
        };
        conv.report.push(
            Kind::Refused,
            loc,
            format!("ST of `{pname}`: {}: {}", d.code, d.message),
        );
        ok = false;
    }
    if !ok {
        return None;
    }
    let what = match keyword {
        "PROGRAM" => String::new(),
        k => format!("{} ", k.to_ascii_lowercase().replace('_', " ")),
    };
    conv.report
        .push(Kind::Converted, ctx.loc(st), format!("ST body of {what}`{pname}`"));
    let mut prog = ProgramOut::new(format!("{}.st", crate::names::file_stem(pname)));
    // Each line's place: the POU for the header, the XML line of the CDATA
    // for the body.
    let pou_loc: Location = ctx.loc(pou);
    let head_lines = head.lines().count();
    let starts: Vec<usize> = std::iter::once(0)
        .chain(body.match_indices('\n').map(|(k, _)| k + 1))
        .collect();
    for (i, l) in text.lines().enumerate() {
        let origin = match (body_at, i.checked_sub(head_lines).and_then(|k| starts.get(k))) {
            (Some(o), Some(s)) if i < head_lines + body.lines().count() => ctx.loc_at(o + s),
            _ => pou_loc.clone(),
        };
        prog.line(l, Some(&origin));
    }
    Some(prog)
}

/// The text of an `<ST>` element (of its `<xhtml:p>`, as Beremiz and OpenPLC
/// write it, or `<xhtml>`, as IronPLC does; else its own) without its
/// leading blank lines, and where it is in the XML.
fn st_body(ctx: &Ctx<'_>, st: &Elem) -> (String, Option<usize>) {
    let para = st.children.iter().find(|c| c.name == "p" || c.name == "xhtml");
    let body = match para {
        Some(p) => p.text.clone(),
        None if st.children.is_empty() => st.text.clone(),
        None => collect_text(st),
    };
    let body = body.trim_start_matches(['\n', '\r']).trim_end().to_string();
    let from = para.unwrap_or(st).start;
    let at = ctx.text.get(from..).and_then(|r| r.find(&body)).map(|o| o + from);
    (body, at)
}

/// An SFC action with an ST body: its name and `<ST>` element.
pub(super) struct StAction<'a> {
    name: String,
    st: &'a Elem,
}

impl StAction<'_> {
    pub(super) fn name(&self) -> &str {
        &self.name
    }
}

/// Puts each action of `pou` whose body is ST in `scope` under its own
/// name, so the chart's action blocks name it (`Fill(N);`); its body
/// becomes an `ACTION Fill: … END_ACTION` of the chart ([`action_blocks`]),
/// whose flag `<chart>.Fill` the compiler declares.
pub(super) fn declare_actions<'a>(
    conv: &mut Conv<'_>,
    pou: &'a Elem,
    pname: &str,
    scope: &mut HashMap<String, Var>,
) -> Vec<StAction<'a>> {
    // Inline ST bodies of the chart's action blocks that are on a step:
    // actions named after their block and place in it
    // ([`inline_action_name`]).
    let blocks = pou
        .child("body")
        .and_then(|b| b.child("SFC"))
        .into_iter()
        .flat_map(|sfc| sfc.all("actionBlock"))
        .filter(|b| {
            b.child("connectionPointIn")
                .and_then(|c| c.child("connection"))
                .is_some()
        });
    let inline = blocks.flat_map(|block| {
        block.all("action").enumerate().filter_map(move |(k, a)| {
            let st = a.child("inline")?.child("ST")?;
            let name = inline_action_name(block, k);
            Some((a, format!("the inline action `{name}`"), name, st))
        })
    });
    // Then the POU's named actions with an ST body.
    let named = pou
        .child("actions")
        .into_iter()
        .flat_map(|acts| acts.all("action"))
        .filter_map(|a| {
            let name = a.attr("name")?;
            let st = a.child("body")?.child("ST")?;
            Some((a, format!("action `{name}`"), name.to_string(), st))
        });
    let mut out = Vec::new();
    for (a, what, name, st) in inline.chain(named) {
        let key = name.to_ascii_lowercase();
        if scope.contains_key(&key) {
            conv.report.push(
                Kind::Refused,
                conv.ctx.loc(a),
                format!("{what} of `{pname}` has the name of a variable; left out"),
            );
            continue;
        }
        scope.insert(
            key,
            Var {
                alba: name.clone(),
                kind: VarKind::Tag("BOOL".into()),
                fb: String::new(),
            },
        );
        out.push(StAction { name, st });
    }
    out
}

/// The name of the `k`-th (from 0) action of an action block when its body
/// is inline: `A<localId>_<k + 1>` (`A57_1`).
pub(super) fn inline_action_name(block: &Elem, k: usize) -> String {
    format!("A{}_{}", block.attr("localId").unwrap_or("0").trim(), k + 1)
}

/// Appends to the chart `prog` an `ACTION <name>: <body> END_ACTION` for
/// each ST action. `false` (and nothing appended) when one is refused.
pub(super) fn action_blocks(
    conv: &mut Conv<'_>,
    pou: &Elem,
    pname: &str,
    scope: &HashMap<String, Var>,
    actions: &[StAction<'_>],
    prog: &mut ProgramOut,
) -> bool {
    if actions.is_empty() {
        return true;
    }
    let ctx = Ctx {
        file: conv.ctx.file,
        text: conv.ctx.text,
    };
    let mut ok = true;
    // The bodies name the chart's variables, which are tags: by their own
    // names only if none was renamed.
    if let Some(iface) = pou.child("interface") {
        for v in iface.children.iter().flat_map(|l| l.all("variable")) {
            let name = v.attr("name").unwrap_or("");
            if let Some(var) = scope.get(&name.to_ascii_lowercase())
                && !var.alba.eq_ignore_ascii_case(name)
            {
                conv.report.push(
                    Kind::Refused,
                    ctx.loc(v),
                    format!(
                        "variable `{name}` of `{pname}` is the tag `{}`; the ST actions that name it are not converted",
                        var.alba
                    ),
                );
                ok = false;
            }
        }
    }
    let mut lines: Vec<(String, Location)> = Vec::new();
    for a in actions {
        let (body, at) = st_body(&ctx, a.st);
        let here = ctx.loc(a.st);
        lines.push((format!("ACTION {}:", a.name), here.clone()));
        let mut off = 0;
        for l in body.split('\n') {
            let loc = at.map(|o| ctx.loc_at(o + off)).unwrap_or_else(|| here.clone());
            off += l.len() + 1;
            lines.push((l.trim_end_matches('\r').to_string(), loc));
        }
        lines.push(("END_ACTION".into(), here));
    }
    // Syntax errors, at their line in the XML: the bodies parsed as
    // PROGRAMs (an ACTION's header and end are as long as a PROGRAM's).
    let text: String = lines
        .iter()
        .map(|(l, _)| match l.strip_prefix("ACTION ") {
            Some(n) => format!("PROGRAM {}\n", n.trim_end_matches(':')),
            None if l == "END_ACTION" => "END_PROGRAM\n".into(),
            None => format!("{l}\n"),
        })
        .collect();
    let (_, diags) = alba_compiler::st::parse(&text, alba_diag::FileId(0));
    for d in &diags {
        let loc = d
            .primary
            .as_ref()
            .map(|l| {
                let line = text.get(..l.span.start as usize).unwrap_or(&text).matches('\n').count();
                lines.get(line).map(|(_, o)| o.clone()).unwrap_or_else(|| ctx.loc(pou))
            })
            .unwrap_or_else(|| ctx.loc(pou));
        conv.report.push(
            Kind::Refused,
            loc,
            format!("ST actions of `{pname}`: {}: {}", d.code, d.message),
        );
        ok = false;
    }
    if !ok {
        conv.report.push(
            Kind::Refused,
            ctx.loc(pou),
            format!("the ST actions of `{pname}` are not converted"),
        );
        return false;
    }
    for a in actions {
        conv.report.push(
            Kind::Converted,
            ctx.loc(a.st),
            format!("ST action `{}` of `{pname}`: an ACTION of the chart", a.name),
        );
    }
    for (l, o) in &lines {
        prog.line(l, Some(o));
    }
    true
}
