//! ST bodies of PLCopen `program` POUs: each becomes `<program>.st`, a
//! `PROGRAM` whose `VAR` blocks are the POU's interface and whose body is
//! the `<ST>` text unchanged. Located variables (`%IX0.0`) are tags with
//! their address (alba-st refuses `AT`), the configuration's globals are
//! tags, and `externalVars` name them. Variables of a type alba-st does not
//! run, and syntax errors of the body, are refused at their place in the
//! XML; the program is then not written.

use super::{Conv, Ctx, Var, VarKind, collect_text};
use crate::{Kind, Location, ProgramOut, TagOut};
use alba_xml::Elem;
use std::collections::HashMap;

/// Types whose variables run on the engine (docs/st.md).
const RUNS: &[&str] = &[
    "BOOL", "SINT", "INT", "DINT", "LINT", "REAL", "LREAL", "TIME", "TON", "TOF", "TP", "CTU", "CTD", "CTUD", "R_TRIG",
    "F_TRIG", "SR", "RS",
];

/// The ST text of a PLCopen `<type>`'s content, or why not.
fn st_type(t: &Elem) -> Result<String, String> {
    let up = t.name.to_ascii_uppercase();
    let ty = match up.as_str() {
        "DERIVED" => t
            .attr("name")
            .ok_or("a derived type without a name")?
            .to_ascii_uppercase(),
        "ARRAY" => {
            let dims: Vec<String> = t
                .all("dimension")
                .map(|d| format!("{}..{}", d.attr("lower").unwrap_or("0"), d.attr("upper").unwrap_or("0")))
                .collect();
            let base = t
                .child("baseType")
                .and_then(|b| b.children.first())
                .ok_or("an array without a base type")?;
            return Ok(format!("ARRAY[{}] OF {}", dims.join(", "), st_type(base)?));
        }
        _ => up,
    };
    if RUNS.contains(&ty.as_str()) {
        Ok(ty)
    } else {
        Err(format!("its type `{ty}` does not run in Alba's ST yet (docs/st.md)"))
    }
}

/// Converts the ST body `st` of program `pou` (named `pname`); `None` when
/// something in it is refused (each refusal is in the report).
pub(super) fn convert(
    conv: &mut Conv<'_>,
    pou: &Elem,
    st: &Elem,
    pname: &str,
    scope: &mut HashMap<String, Var>,
) -> Option<ProgramOut> {
    let ctx = Ctx {
        file: conv.ctx.file,
        text: conv.ctx.text,
    };
    let mut ok = true;
    let mut decls = String::new();
    if let Some(iface) = pou.child("interface") {
        for list in &iface.children {
            let kw = match list.name.as_str() {
                "localVars" | "inputVars" | "outputVars" | "inOutVars" => "VAR",
                "tempVars" => "VAR_TEMP",
                "globalVars" => "VAR_GLOBAL",
                _ => continue,
            };
            let mut block = String::new();
            let mut located = list.clone();
            located
                .children
                .retain(|v| v.name == "variable" && v.attr("address").is_some());
            if !located.children.is_empty() {
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
            for v in list.all("variable").filter(|v| v.attr("address").is_none()) {
                let name = v.attr("name").unwrap_or("");
                let ty = v.child("type").and_then(|t| t.children.first());
                let ty = match ty.map(st_type) {
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
                let init = v
                    .child("initialValue")
                    .and_then(|i| i.child("simpleValue"))
                    .and_then(|s| s.attr("value"))
                    .map(|s| format!(" := {}", s.trim()))
                    .unwrap_or_default();
                block.push_str(&format!("    {name} : {ty}{init};\n"));
            }
            if !block.is_empty() && matches!(list.name.as_str(), "inputVars" | "outputVars" | "inOutVars") {
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
    let (body, body_at) = st_body(&ctx, st);
    let body = body.as_str();
    let head = format!("PROGRAM {pname}\n{decls}");
    let text = format!("{head}{body}\nEND_PROGRAM\n");
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
    conv.report
        .push(Kind::Converted, ctx.loc(st), format!("ST body of `{pname}`"));
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

/// An SFC action with an ST body: its tag, name and `<ST>` element.
pub(super) struct StAction<'a> {
    tag: String,
    name: String,
    st: &'a Elem,
}

/// Declares a BOOL tag `<pou>_<action>` for each action of `pou` whose body
/// is ST, and puts it in `scope` under the action's name, so the chart's
/// action blocks drive it like a BOOL variable.
pub(super) fn declare_actions<'a>(
    conv: &mut Conv<'_>,
    pou: &'a Elem,
    pname: &str,
    scope: &mut HashMap<String, Var>,
) -> Vec<StAction<'a>> {
    let mut out = Vec::new();
    let Some(acts) = pou.child("actions") else {
        return out;
    };
    for a in acts.all("action") {
        let Some(name) = a.attr("name") else { continue };
        let Some(st) = a.child("body").and_then(|b| b.child("ST")) else {
            continue;
        };
        let key = name.to_ascii_lowercase();
        if scope.contains_key(&key) {
            conv.report.push(
                Kind::Refused,
                conv.ctx.loc(a),
                format!("action `{name}` of `{pname}` has the name of a variable; left out"),
            );
            continue;
        }
        let (tag, _) = conv
            .names
            .alba_as(&format!("{pname}\u{0}action\u{0}{name}"), &format!("{pname}_{name}"));
        conv.tags.push(TagOut {
            name: tag.clone(),
            ty: "BOOL".into(),
            address: String::new(),
            initial: String::new(),
            description: format!("alba import: action `{name}` of `{pname}` runs while true"),
        });
        scope.insert(
            key,
            Var {
                alba: tag.clone(),
                kind: VarKind::Tag("BOOL".into()),
                fb: String::new(),
            },
        );
        out.push(StAction {
            tag,
            name: name.to_string(),
            st,
        });
    }
    out
}

/// `<pou>_actions.st`: `IF <tag> THEN <body> END_IF;` for each ST action,
/// run after the chart. `None` when there are none or one is refused.
pub(super) fn actions_program(
    conv: &mut Conv<'_>,
    pou: &Elem,
    pname: &str,
    scope: &HashMap<String, Var>,
    actions: &[StAction<'_>],
) -> Option<ProgramOut> {
    if actions.is_empty() {
        return None;
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
    let prog_name = format!("{}_actions", crate::names::file_stem(pname));
    let mut lines: Vec<(String, Location)> = vec![(format!("PROGRAM {prog_name}"), ctx.loc(pou))];
    for a in actions {
        let (body, at) = st_body(&ctx, a.st);
        let here = ctx.loc(a.st);
        lines.push((format!("(* action {} *)", a.name), here.clone()));
        lines.push((format!("IF {} THEN", a.tag), here.clone()));
        let mut off = 0;
        for l in body.split('\n') {
            let loc = at.map(|o| ctx.loc_at(o + off)).unwrap_or_else(|| here.clone());
            off += l.len() + 1;
            lines.push((l.trim_end_matches('\r').to_string(), loc));
        }
        lines.push(("END_IF;".into(), here));
    }
    lines.push(("END_PROGRAM".into(), ctx.loc(pou)));
    let text: String = lines.iter().map(|(l, _)| format!("{l}\n")).collect();
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
        return None;
    }
    for a in actions {
        conv.report.push(
            Kind::Converted,
            ctx.loc(a.st),
            format!("ST action `{}` of `{pname}`: runs while `{}` is true", a.name, a.tag),
        );
    }
    let mut prog = ProgramOut::new(format!("{prog_name}.st"));
    for (l, o) in &lines {
        prog.line(l, Some(o));
    }
    Some(prog)
}
