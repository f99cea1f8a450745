//! SFC bodies of PLCopen TC6 XML programs onto Alba's SFC (docs/nets.md
//! "SFC"): the chart is written in IEC 61131-3's textual form, a `.sfc`
//! program, one step or transition a line.
//!
//! A TC6 SFC body is a graph like an LD body: each element lists the
//! elements its input is connected to. Steps and transitions alternate,
//! joined directly or through the four connectors: a selection divergence
//! (a step into several transitions) and convergence (several transitions
//! into a step), a simultaneous divergence (a transition into several steps)
//! and convergence (several steps into a transition); a jump step is a
//! transition's way back to a named step. A transition's `FROM` list is
//! found by walking its input back to steps, its `TO` list by walking
//! forward from it to steps and jumps. Action blocks hang on a step's
//! action point; each action is a qualifier, a duration and a BOOL variable
//! (an action of the POU with an ST body is an `ACTION` block of the chart,
//! the `st` module).

use super::{Ctx, Var, VarKind, collect_text, connections};
use crate::{Error, Kind, Location, ProgramOut, Report};
use alba_xml::Elem;
use std::collections::HashMap;

/// Connectors followed in a row, at most (a longer chain is refused).
const MAX_WALK: usize = 1000;

/// The qualifiers of IEC 61131-3 and whether they take a duration.
const QUALIFIERS: &[(&str, bool)] = &[
    ("N", false),
    ("S", false),
    ("R", false),
    ("P", false),
    ("P1", false),
    ("P0", false),
    ("L", true),
    ("D", true),
    ("SD", true),
    ("DS", true),
    ("SL", true),
];

struct Chart<'a> {
    elems: HashMap<String, &'a Elem>,
    /// localId → the elements connected to it (its readers).
    readers: HashMap<String, Vec<&'a Elem>>,
    /// Step localId → its Alba name.
    steps: HashMap<String, String>,
    /// Step name (IEC, lower case) → its Alba name.
    by_name: HashMap<String, String>,
    /// The `.sfc` file's stem: the prefix of the step tags.
    stem: String,
    scope: &'a HashMap<String, Var>,
}

fn inputs(e: &Elem) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for p in e.all("connectionPointIn") {
        v.extend(connections(Some(p)).into_iter().map(|(id, _)| id));
    }
    v
}

impl Chart<'_> {
    /// The steps a transition's input comes from.
    fn sources(&self, ids: &[String], depth: usize, out: &mut Vec<String>) -> Result<(), String> {
        if depth > MAX_WALK {
            return Err(format!("connectors chained deeper than {MAX_WALK}"));
        }
        for id in ids {
            let Some(e) = self.elems.get(id) else {
                return Err(format!("a connection to element {id}, which does not exist"));
            };
            match e.name.as_str() {
                "step" => out.push(self.steps.get(id).cloned().unwrap_or_default()),
                "selectionDivergence" | "simultaneousConvergence" => self.sources(&inputs(e), depth + 1, out)?,
                other => return Err(format!("its input comes from a <{other}>, not from a step")),
            }
        }
        Ok(())
    }

    /// The steps a transition leads to.
    fn targets(&self, id: &str, depth: usize, out: &mut Vec<String>) -> Result<(), String> {
        if depth > MAX_WALK {
            return Err(format!("connectors chained deeper than {MAX_WALK}"));
        }
        for r in self.readers.get(id).map(Vec::as_slice).unwrap_or_default() {
            let rid = r.attr("localId").unwrap_or("");
            match r.name.as_str() {
                "step" => out.push(self.steps.get(rid).cloned().unwrap_or_default()),
                "jumpStep" => {
                    let target = r.attr("targetName").unwrap_or("").trim();
                    match self.by_name.get(&target.to_ascii_lowercase()) {
                        Some(s) => out.push(s.clone()),
                        None => return Err(format!("it jumps to `{target}`, which is not a step of the chart")),
                    }
                }
                "selectionConvergence" | "simultaneousDivergence" => self.targets(rid, depth + 1, out)?,
                "transition" => return Err("it leads to another transition, not to a step".into()),
                _ => {}
            }
        }
        Ok(())
    }

    /// An identifier of a condition as Alba names it.
    fn name(&self, id: &str) -> Result<String, String> {
        if let Some((step, member)) = id.split_once('.')
            && let Some(s) = self.by_name.get(&step.to_ascii_lowercase())
        {
            return match member.to_ascii_uppercase().as_str() {
                m @ ("X" | "T") => Ok(format!("{}.{s}.{m}", self.stem)),
                _ => Err(format!("`{id}`: a step has X and T")),
            };
        }
        if let Some(v) = self.scope.get(&id.to_ascii_lowercase()) {
            return match &v.kind {
                VarKind::Tag(_) => Ok(v.alba.clone()),
                VarKind::Refused(why) => Err(format!("`{id}` was refused ({why})")),
                _ => Err(format!("`{id}` is a function block instance, not a value")),
            };
        }
        if let Some((inst, member)) = id.split_once('.')
            && let Some(v) = self.scope.get(&inst.to_ascii_lowercase())
        {
            return match (&v.kind, member.to_ascii_uppercase().as_str()) {
                (VarKind::Timer, "Q") => Ok(format!("{}.DN", v.alba)),
                (VarKind::Timer, "ET") => Ok(format!("{}.ACC", v.alba)),
                (VarKind::Timer, "PT") => Ok(format!("{}.PRE", v.alba)),
                (VarKind::Counter, "CV") => Ok(format!("{}.ACC", v.alba)),
                (VarKind::Counter, "PV") => Ok(format!("{}.PRE", v.alba)),
                _ => Err(format!("`{id}` has no Alba equivalent in a condition")),
            };
        }
        Err(format!("`{id}` is neither a variable nor a step"))
    }

    /// An ST expression as an Alba condition (docs/nets.md "Guards":
    /// no functions).
    fn condition(&self, st: &str) -> Result<String, String> {
        super::st_expression(st, &|w| self.name(w), &[])
    }

    /// An inline ST condition the nets' language cannot say (a function, say)
    /// kept in ST, for `: <condition> END_TRANSITION`: when it is one ST
    /// expression on one line that names no step (`Step.X`) and no variable
    /// the chart renamed. `None` otherwise.
    fn st_condition(&self, st: &str) -> Option<String> {
        let one_line = st.split_whitespace().collect::<Vec<_>>().join(" ");
        if st.contains("//") || st.contains('.') || one_line.to_ascii_uppercase().contains("END_TRANSITION") {
            return None;
        }
        if self.scope.iter().any(|(k, v)| !v.alba.eq_ignore_ascii_case(k)) {
            return None;
        }
        let text = format!("PROGRAM c c := {one_line}; END_PROGRAM");
        let (file, diags) = alba_compiler::st::parse(&text, alba_diag::FileId(0));
        let one = file.pous.first().is_some_and(|p| p.body.len() == 1);
        (diags.is_empty() && one).then_some(one_line)
    }
}

/// The text of an inline ST body (`<inline><ST><xhtml:p>…`).
fn st_text(e: &Elem) -> Option<String> {
    let st = e.child("ST")?;
    Some(collect_text(st))
}

/// Converts the SFC body `sfc` of program `pou` (named `pname`) into
/// `<stem>.sfc`; `None` when nothing of the chart can run.
pub(super) fn convert(
    ctx: &Ctx<'_>,
    pou: &Elem,
    sfc: &Elem,
    pname: &str,
    scope: &HashMap<String, Var>,
    report: &mut Report,
) -> Result<Option<ProgramOut>, Error> {
    let stem = crate::names::file_stem(pname);
    let mut elems: HashMap<String, &Elem> = HashMap::new();
    for el in &sfc.children {
        if let Some(id) = el.attr("localId")
            && elems.insert(id.to_string(), el).is_some()
        {
            return Err(Error::at(
                ctx.loc(el),
                format!("localId {id} is used twice in `{pname}`"),
            ));
        }
    }
    let mut readers: HashMap<String, Vec<&Elem>> = HashMap::new();
    for el in &sfc.children {
        for id in inputs(el) {
            readers.entry(id).or_default().push(el);
        }
    }
    let pos = |e: &Elem| -> (i64, i64) {
        let p = e.child("position");
        let g = |k: &str| {
            p.and_then(|p| p.attr(k))
                .and_then(|s| s.parse::<f64>().ok())
                .unwrap_or(0.0) as i64
        };
        (g("y"), g("x"))
    };
    // Steps: their names as Alba step names (identifiers, unique).
    let mut chart = Chart {
        elems,
        readers,
        steps: HashMap::new(),
        by_name: HashMap::new(),
        stem: stem.clone(),
        scope,
    };
    let mut step_elems: Vec<&Elem> = sfc.all("step").collect();
    step_elems.sort_by_key(|e| pos(e));
    let mut taken: Vec<String> = Vec::new();
    for s in &step_elems {
        let name = s.attr("name").unwrap_or("").trim();
        let mut alba: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' })
            .collect();
        if alba.is_empty() || alba.starts_with(|c: char| c.is_ascii_digit()) {
            alba = format!("S_{alba}");
        }
        let base = alba.clone();
        let mut k = 2;
        while taken.iter().any(|t| t.eq_ignore_ascii_case(&alba)) {
            alba = format!("{base}_{k}");
            k += 1;
        }
        if alba != name {
            report.push(
                Kind::Approximated,
                ctx.loc(s),
                format!("step `{name}` of `{pname}` is step `{alba}` in Alba"),
            );
        }
        taken.push(alba.clone());
        if let Some(id) = s.attr("localId") {
            chart.steps.insert(id.to_string(), alba.clone());
        }
        chart.by_name.insert(name.to_ascii_lowercase(), alba);
    }
    for el in &sfc.children {
        if matches!(
            el.name.as_str(),
            "macroStep" | "connector" | "continuation" | "block" | "leftPowerRail"
        ) {
            report.push(
                Kind::Refused,
                ctx.loc(el),
                format!("<{}> in the SFC of `{pname}` is not converted", el.name),
            );
        }
    }
    let mut prog = ProgramOut::new(format!("{stem}.sfc"));
    prog.line(
        &format!("(* {pname}: imported from PLCopen TC6 XML by alba import *)"),
        None,
    );
    // Actions of each step, from its action blocks and output variables.
    let mut lines: Vec<(Location, String)> = Vec::new();
    let mut initials = 0;
    for s in &step_elems {
        let id = s.attr("localId").unwrap_or("");
        // By its localId, else (a file that leaves it out) by its name.
        let alba = chart
            .steps
            .get(id)
            .or_else(|| {
                chart
                    .by_name
                    .get(&s.attr("name").unwrap_or("").trim().to_ascii_lowercase())
            })
            .cloned()
            .unwrap_or_default();
        let mut assoc: Vec<String> = Vec::new();
        for r in chart.readers.get(id).map(Vec::as_slice).unwrap_or_default() {
            match r.name.as_str() {
                "actionBlock" => {
                    for (k, a) in r.all("action").enumerate() {
                        match action(&chart, pou, (r, k), a) {
                            Ok(text) => assoc.push(text),
                            Err(why) => report.push(
                                Kind::Refused,
                                ctx.loc(a),
                                format!("an action of step `{alba}`: {why}; left out"),
                            ),
                        }
                    }
                }
                "outVariable" => {
                    let expr = r
                        .child("expression")
                        .map(|x| x.text.trim().to_string())
                        .unwrap_or_default();
                    let negated = r.attr("negated") == Some("true");
                    match (negated, chart.scope.get(&expr.to_ascii_lowercase())) {
                        (false, Some(Var { alba, kind: VarKind::Tag(t), .. })) if t == "BOOL" => {
                            assoc.push(format!("{alba}(N);"));
                        }
                        _ => report.push(
                            Kind::Refused,
                            ctx.loc(r),
                            format!("the output variable `{expr}` of step `{alba}` is not a BOOL driven by the step (negated or not a BOOL); left out"),
                        ),
                    }
                }
                _ => {}
            }
        }
        let initial = s.attr("initialStep") == Some("true");
        initials += usize::from(initial);
        let kw = if initial { "INITIAL_STEP" } else { "STEP" };
        let body = if assoc.is_empty() {
            String::new()
        } else {
            format!(" {}", assoc.join(" "))
        };
        lines.push((ctx.loc(s), format!("{kw} {alba}:{body} END_STEP")));
        report.push(Kind::Converted, ctx.loc(s), format!("step `{alba}` of `{pname}`"));
    }
    if initials != 1 {
        report.push(
            Kind::Refused,
            ctx.loc(sfc),
            format!("the SFC of `{pname}` has {initials} initial steps (IEC: exactly one); not converted"),
        );
        return Ok(None);
    }
    let mut trans: Vec<&Elem> = sfc.all("transition").collect();
    trans.sort_by_key(|e| pos(e));
    for t in trans {
        let id = t.attr("localId").unwrap_or("");
        let loc = ctx.loc(t);
        match transition(&chart, pou, t, id) {
            Ok(text) => {
                report.push(Kind::Converted, loc.clone(), format!("transition {id} of `{pname}`"));
                lines.push((loc, text));
            }
            Err(why) => {
                report.push(
                    Kind::Refused,
                    loc.clone(),
                    format!("transition {id} of `{pname}`: {why}; left out"),
                );
                lines.push((loc, format!("// REFUSED by alba import: transition {id} ({why})")));
            }
        }
    }
    for (loc, text) in &lines {
        prog.line(text, Some(loc));
    }
    Ok(Some(prog))
}

/// `Action(Q[, T#t]);` of the `k`-th `<action>` of an action block.
fn action(chart: &Chart<'_>, pou: &Elem, (block, k): (&Elem, usize), a: &Elem) -> Result<String, String> {
    let q = a.attr("qualifier").unwrap_or("N").trim().to_ascii_uppercase();
    let Some(&(q, timed)) = QUALIFIERS.iter().find(|(n, _)| *n == q) else {
        return Err(format!("`{q}` is not a qualifier of IEC 61131-3"));
    };
    let time = match (timed, a.attr("duration").map(str::trim).filter(|d| !d.is_empty())) {
        (true, Some(d)) => {
            let up = d.to_ascii_uppercase();
            let ms = up
                .strip_prefix("T#")
                .or_else(|| up.strip_prefix("TIME#"))
                .and_then(super::duration_ms)
                .filter(|ms| *ms >= 0)
                .ok_or_else(|| format!("the duration `{d}` is not a literal time (a variable is not converted)"))?;
            format!(", T#{ms}ms")
        }
        (true, None) => return Err(format!("the qualifier {q} needs a duration")),
        (false, Some(d)) => return Err(format!("the qualifier {q} takes no duration (`{d}`)")),
        (false, None) => String::new(),
    };
    if let Some(inline) = a.child("inline") {
        // An inline ST body is an action of the chart (st::declare_actions).
        let name = super::st::inline_action_name(block, k);
        return match chart.scope.get(&name.to_ascii_lowercase()) {
            Some(v) if inline.child("ST").is_some() => Ok(format!("{}({q}{time});", v.alba)),
            _ if inline.child("ST").is_some() => Err(format!("its ST body `{name}` is not converted")),
            _ => Err("an inline action body in LD, FBD or IL; only ST bodies are converted".into()),
        };
    }
    let name = a
        .child("reference")
        .and_then(|r| r.attr("name"))
        .map(str::trim)
        .ok_or("an action without a reference")?;
    if let Some(v) = chart.scope.get(&name.to_ascii_lowercase()) {
        return match &v.kind {
            VarKind::Tag(t) if t == "BOOL" => Ok(format!("{}({q}{time});", v.alba)),
            _ => Err(format!("`{name}` is not a BOOL variable")),
        };
    }
    let named = pou.child("actions").is_some_and(|acts| {
        acts.all("action")
            .any(|x| x.attr("name").is_some_and(|n| n.eq_ignore_ascii_case(name)))
    });
    if named {
        return Err(format!(
            "`{name}` is an action whose body is not ST; only ST action bodies are converted (or write a BOOL and a program that runs while it is true)"
        ));
    }
    Err(format!(
        "`{name}` is neither a BOOL variable nor an action of the program"
    ))
}

/// The `TRANSITION … END_TRANSITION` line of a transition.
fn transition(chart: &Chart<'_>, pou: &Elem, t: &Elem, id: &str) -> Result<String, String> {
    let mut from = Vec::new();
    chart.sources(
        &connections(t.child("connectionPointIn"))
            .into_iter()
            .map(|(i, _)| i)
            .collect::<Vec<_>>(),
        0,
        &mut from,
    )?;
    let mut to = Vec::new();
    chart.targets(id, 0, &mut to)?;
    from.dedup();
    to.dedup();
    if from.is_empty() {
        return Err("it comes from no step".into());
    }
    if to.is_empty() {
        return Err("it leads to no step".into());
    }
    let cond = t.child("condition").ok_or("it has no condition")?;
    let mut in_st = false;
    let text = if let Some(inline) = cond.child("inline") {
        let st = st_text(inline).ok_or("its inline condition is not ST")?;
        match chart.condition(&st) {
            Ok(c) => c,
            Err(why) => {
                in_st = true;
                chart.st_condition(&st).ok_or(why)?
            }
        }
    } else if let Some(r) = cond.child("reference") {
        let name = r.attr("name").unwrap_or("").trim();
        let body = pou
            .child("transitions")
            .and_then(|ts| {
                ts.all("transition")
                    .find(|x| x.attr("name").is_some_and(|n| n.eq_ignore_ascii_case(name)))
            })
            .and_then(|x| x.child("body"))
            .ok_or_else(|| format!("its condition `{name}` is not a transition of the program"))?;
        let st = st_text(body).ok_or_else(|| format!("the body of `{name}` is not ST"))?;
        // `:= expr;` or `name := expr;`, or the bare expression.
        let expr = match st.split_once(":=") {
            Some((lhs, rhs)) if lhs.trim().is_empty() || lhs.trim().eq_ignore_ascii_case(name) => rhs,
            Some(_) => return Err(format!("the body of `{name}` is not `{name} := condition;`")),
            None => st.as_str(),
        };
        chart.condition(expr)?
    } else if let Some(cp) = cond.child("connectionPointIn") {
        let src = connections(Some(cp));
        match src.as_slice() {
            [(sid, _)] => match chart.elems.get(sid) {
                Some(v) if v.name == "inVariable" => {
                    let expr = v.child("expression").map(collect_text).unwrap_or_default();
                    let c = chart.condition(&expr)?;
                    if v.attr("negated") == Some("true") {
                        format!("NOT ({c})")
                    } else {
                        c
                    }
                }
                _ => {
                    return Err(
                        "its condition is drawn in LD/FBD; only a variable or an ST expression is converted".into(),
                    );
                }
            },
            _ => {
                return Err(
                    "its condition is drawn in LD/FBD; only a variable or an ST expression is converted".into(),
                );
            }
        }
    } else {
        return Err("its condition is empty".into());
    };
    let list = |v: &[String]| {
        if v.len() == 1 {
            v[0].clone()
        } else {
            format!("({})", v.join(", "))
        }
    };
    let head = match t.attr("priority").and_then(|p| p.trim().parse::<i32>().ok()) {
        // Not `t<k>`: Alba names the k-th unnamed transition so.
        Some(p) => format!("TRANSITION tr{id} (PRIORITY := {p})"),
        None => "TRANSITION".into(),
    };
    Ok(if in_st {
        format!("{head} FROM {} TO {} : {text} END_TRANSITION", list(&from), list(&to))
    } else {
        format!("{head} FROM {} TO {} := {text}; END_TRANSITION", list(&from), list(&to))
    })
}
