//! Normal-mode nets (the source's token flow, docs/nets.md "Normal mode")
//! lowered onto the one IR.
//!
//! Every element — place or transition — holds at most one token; its
//! marking is the DINT tag `<net>.<id>` (0 or 1). In its turn the net works
//! on the marking it had at the start of the turn:
//!
//! - a marked **place** does its action (a Counter counts, End ends the net)
//!   and passes its token along every outgoing arc (a place with none keeps
//!   it; Stop absorbs it);
//! - a marked **transition** passes its token to every output place when it
//!   may: a plain Transition at once, a Condition (or any transition with a
//!   `<guard>`) while its guard is true, a Timer once it has held the token
//!   for its delay (an engine TON, `<net>.<id>.timer`);
//! - the new marking is written at the end of the turn, so a token moves one
//!   element per scan; two tokens reaching one element merge; End clears
//!   every marking; the first scan after a start loads the initial marking.
//!
//! Only existing ops are used, so every engine mode and the Arduino export
//! run these nets too.

use crate::petri::{
    check_number, drives, emit_drives, guards, lower_assign, lower_guard, marking_tag, net_name, net_tag,
};
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_ir::{BinOp, Builder, Cmp, I, Op, Place, Target, Tmr};
use alba_model::{DataType, TagTable, Value};
use alba_net::{ArcKind, ElementKind, Net};
use std::collections::HashMap;

/// The TIMER of a Timer transition.
pub fn timer_tag(net: &str, id: &str) -> String {
    format!("{net}.{id}.timer")
}

/// The REAL variable of an Expression place (its direct assignments).
pub fn value_tag(net: &str, id: &str) -> String {
    format!("{net}.{id}.value")
}

/// The DINT count of a Counter place.
pub fn count_tag(net: &str, id: &str) -> String {
    format!("{net}.{id}.count")
}

/// The tags a normal-mode net adds after the places' markings: markings of
/// its transitions, the timers of Timer transitions, the counts of Counter
/// places (a name already taken is E623).
pub fn extra_tags(net: &Net, name: &str, tags: &mut TagTable, diags: &mut Vec<Diagnostic>) {
    let mut add = |tag: String, ty: DataType, initial: Option<Value>, span: Span, what: String| {
        if let Some(t) = tags.get(&tag) {
            diags.push(
                Diagnostic::new(
                    Code::NetTagClash,
                    format!("{what} is the tag `{tag}`, which already exists"),
                    span,
                    "element",
                )
                .with_note(t.span, "declared here")
                .with_help("rename the element or the tag (or the net's file)"),
            );
            return;
        }
        tags.push(net_tag(tag, ty, initial, what, span));
    };
    for t in &net.transitions {
        add(
            marking_tag(name, &t.id),
            DataType::Dint,
            Some(Value::Dint(0)),
            t.span,
            format!("the token of transition {} of net {name}", t.id),
        );
        if t.kind == ElementKind::Timer {
            add(
                timer_tag(name, &t.id),
                DataType::Timer,
                None,
                t.span,
                format!("the timer of transition {} of net {name}", t.id),
            );
        }
    }
    for p in &net.places {
        if matches!(
            p.kind,
            ElementKind::Expression | ElementKind::Input | ElementKind::Variable
        ) {
            let initial = p
                .props
                .get("initial")
                .and_then(|v| v.trim().parse::<f32>().ok())
                .unwrap_or(0.0);
            add(
                value_tag(name, &p.id),
                DataType::Real,
                Some(Value::Real(initial)),
                p.span,
                format!("the variable of expression {} of net {name}", p.id),
            );
        }
        if p.kind == ElementKind::Counter {
            let load = p
                .props
                .get("load")
                .and_then(|v| v.trim().parse::<i32>().ok())
                .unwrap_or(0);
            add(
                count_tag(name, &p.id),
                DataType::Dint,
                Some(Value::Dint(load)),
                p.span,
                format!("the count of counter {} of net {name}", p.id),
            );
        }
    }
}

/// The props each kind takes.
fn known_props(kind: ElementKind) -> &'static [&'static str] {
    match kind {
        ElementKind::Timer => &["delay"],
        ElementKind::Counter => &["load", "direction"],
        ElementKind::Input => &["source"],
        ElementKind::Output => &["source", "target"],
        ElementKind::Variable => &["mode", "source", "target", "value", "initial"],
        // the number its `<tag>` holds while it has the token (1 for a BOOL tag)
        ElementKind::State => &["value"],
        _ => &[],
    }
}

fn bad(msg: String, span: Span, label: &str) -> Diagnostic {
    Diagnostic::new(Code::NetElement, msg, span, label)
}

/// A Timer's delay: milliseconds (`5000`) or a duration (`T#5s`), 0 to 24 days.
fn delay(text: &str) -> Result<i32, String> {
    match Value::parse(text, DataType::Time) {
        Ok(Value::Time(ms)) if ms >= 0 => Ok(ms),
        Ok(_) => Err(format!("the delay `{text}` is negative")),
        Err(e) => Err(format!("the delay `{text}` is not a duration: {e}")),
    }
}

/// Compiles a normal-mode net as one unit (its tags are in the layout:
/// `petri::marking_tags` and [`extra_tags`]).
pub fn compile(net: &Net, file: FileId, text: &str, unit: &str, b: &mut Builder) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    let name = net_name(unit);
    let elements = net
        .places
        .iter()
        .map(|p| (p.kind, &p.props, p.span, p.id.as_str()))
        .chain(
            net.transitions
                .iter()
                .map(|t| (t.kind, &t.props, t.span, t.id.as_str())),
        );
    for (kind, props, span, id) in elements {
        for k in props.keys().filter(|k| !known_props(kind).contains(&k.as_str())) {
            diags.push(
                bad(
                    format!("a {} element has no property `{k}`", kind.as_str()),
                    span,
                    "unknown property",
                )
                .with_help(match known_props(kind) {
                    [] => format!("`{id}` takes no properties"),
                    ks => format!("`{id}` takes {}", ks.join(", ")),
                }),
            );
        }
    }
    for a in &net.arcs {
        if a.kind != ArcKind::Normal {
            diags.push(bad(
                "inhibitor and read arcs are Petri mode's: a normal-mode token just flows".into(),
                a.span,
                "arc",
            ));
        } else if a.weight != 1 {
            diags.push(bad(
                format!("a normal-mode arc passes one token; this one weighs {}", a.weight),
                a.span,
                "arc",
            ));
        }
    }
    let mut delays = vec![0; net.transitions.len()];
    for (k, t) in net.transitions.iter().enumerate() {
        match t.kind {
            ElementKind::Timer => match t.props.get("delay") {
                None => diags.push(
                    bad(format!("timer `{}` needs a delay", t.id), t.span, "timer")
                        .with_help("add `<prop name=\"delay\">T#5s</prop>` (or milliseconds)"),
                ),
                Some(d) => match delay(d) {
                    Ok(ms) => delays[k] = ms,
                    Err(m) => diags.push(bad(m, t.span, "timer")),
                },
            },
            ElementKind::Condition if t.guard.is_none() => diags.push(
                bad(format!("condition `{}` needs a `<guard>`", t.id), t.span, "condition")
                    .with_help("the condition's BOOL expression goes in `<guard>`: `<guard>Level &gt; 80</guard>`"),
            ),
            _ => {}
        }
    }
    let mut counts = HashMap::new();
    for (k, p) in net.places.iter().enumerate() {
        if p.kind != ElementKind::Counter {
            continue;
        }
        if let Some(l) = p.props.get("load")
            && l.trim().parse::<i32>().is_err()
        {
            diags.push(bad(
                format!("the counter's load `{l}` is not a DINT"),
                p.span,
                "counter",
            ));
        }
        let down = match p.props.get("direction").map(|d| d.trim().to_ascii_lowercase()) {
            None => false,
            Some(d) if d == "up" || d == "counterup" => false,
            Some(d) if d == "down" || d == "counterdown" => true,
            Some(d) => {
                diags.push(bad(
                    format!("a counter counts `up` or `down`, not `{d}`"),
                    p.span,
                    "counter",
                ));
                false
            }
        };
        counts.insert(k, down);
    }
    let mut scripts = scripts(net, &name, file, b, &mut diags);
    for (k, st) in moves(net, &name, file, b, &mut diags) {
        scripts.insert(k, st);
    }
    let drives = drives(net, &name, b, &mut diags);
    let guards = guards(net, file, text, b, &mut diags);
    // Slots.
    let int_slot = |b: &Builder, tag: String| match b.layout().resolve(&tag) {
        Ok(Target::Value {
            place: Place::Int(i, _),
            ..
        }) => Some(i),
        _ => None,
    };
    let pm: Vec<Option<I>> = net
        .places
        .iter()
        .map(|p| int_slot(b, marking_tag(&name, &p.id)))
        .collect();
    let tm: Vec<Option<I>> = net
        .transitions
        .iter()
        .map(|t| int_slot(b, marking_tag(&name, &t.id)))
        .collect();
    let timers: Vec<Option<Tmr>> = net
        .transitions
        .iter()
        .map(|t| match b.layout().resolve(&timer_tag(&name, &t.id)) {
            Ok(Target::Timer(tm)) if t.kind == ElementKind::Timer => Some(tm),
            _ => None,
        })
        .collect();
    let count_slots: HashMap<usize, I> = counts
        .keys()
        .filter_map(|&k| int_slot(b, count_tag(&name, &net.places[k].id)).map(|i| (k, i)))
        .collect();
    if !diags.is_empty() || pm.iter().chain(&tm).any(Option::is_none) || count_slots.len() != counts.len() {
        return diags;
    }
    let pm: Vec<I> = pm.into_iter().flatten().collect();
    let tm: Vec<I> = tm.into_iter().flatten().collect();
    let place_of: HashMap<&str, usize> = net.places.iter().enumerate().map(|(k, p)| (p.id.as_str(), k)).collect();
    let tr_of: HashMap<&str, usize> = net
        .transitions
        .iter()
        .enumerate()
        .map(|(k, t)| (t.id.as_str(), k))
        .collect();
    let mut p_out: Vec<Vec<usize>> = vec![Vec::new(); net.places.len()];
    let mut t_out: Vec<Vec<usize>> = vec![Vec::new(); net.transitions.len()];
    for a in &net.arcs {
        match (
            place_of.get(a.source.as_str()),
            tr_of.get(a.target.as_str()),
            tr_of.get(a.source.as_str()),
            place_of.get(a.target.as_str()),
        ) {
            (Some(&p), Some(&t), _, _) => p_out[p].push(t),
            (_, _, Some(&t), Some(&p)) => t_out[t].push(p),
            _ => {}
        }
    }

    let at_start = Span::new(file, 0..text.len().min(1));
    let first = net.places.first().map_or(at_start, |p| p.span);
    b.begin_unit(unit);
    let mark = b.mark();
    let zero = b.const_i(0);
    let one = b.const_i(1);
    let set = |b: &mut Builder, src: I, dst: I, elem: u32| {
        b.emit(Op::BinI(BinOp::Add, src, zero, dst), elem);
    };
    let mut rung = 0;
    let mut next_rung = |b: &mut Builder, span: Span| {
        b.begin_rung(rung, span);
        rung += 1;
    };
    // The first scan after a start: the initial marking, the counters' loads.
    next_rung(b, first);
    b.emit(Op::Xic(b.layout().system.first_scan), alba_ir::NO_ELEM);
    for (k, p) in net.places.iter().enumerate() {
        let init = b.const_i(i32::from(p.initial > 0));
        set(b, init, pm[k], alba_ir::NO_ELEM);
        if let Some(&c) = count_slots.get(&k) {
            let load = p
                .props
                .get("load")
                .and_then(|v| v.trim().parse::<i32>().ok())
                .unwrap_or(0);
            let load = b.const_i(load);
            set(b, load, c, alba_ir::NO_ELEM);
        }
    }
    for &m in &tm {
        set(b, zero, m, alba_ir::NO_ELEM);
    }
    // Tokens produced this turn, transitions fired, the net ended.
    next_rung(b, first);
    let p_new: Vec<I> = pm.iter().map(|_| b.temp_i()).collect();
    let t_new: Vec<I> = tm.iter().map(|_| b.temp_i()).collect();
    let fired: Vec<I> = tm.iter().map(|_| b.temp_i()).collect();
    let ended = b.temp_i();
    for &t in p_new.iter().chain(&t_new).chain(&fired).chain([&ended]) {
        b.emit(Op::CopyI(zero, t), alba_ir::NO_ELEM);
    }
    for (k, tmr) in timers.iter().enumerate() {
        if let Some(tmr) = tmr {
            let pre = b.const_i(delays[k]);
            b.emit(Op::CopyI(pre, tmr.i), alba_ir::NO_ELEM);
        }
    }
    // Places: act, then pass the token.
    for (k, p) in net.places.iter().enumerate() {
        next_rung(b, p.span);
        let elem = b.element(p.span);
        b.emit(Op::CmpI(Cmp::Gt, pm[k], zero), elem);
        if let Some(&c) = count_slots.get(&k) {
            let op = if counts[&k] { BinOp::Sub } else { BinOp::Add };
            b.emit(Op::BinI(op, c, one, c), elem);
        }
        for (dest, e) in scripts.get(&k).into_iter().flatten() {
            lower_assign(b, *dest, e, elem);
        }
        match p.kind {
            ElementKind::End => set(b, one, ended, elem),
            ElementKind::Stop => {}
            _ => {
                for &t in &p_out[k] {
                    set(b, one, t_new[t], elem);
                }
            }
        }
    }
    // Transitions: pass the token when they may.
    let mut guard_bits: Vec<Option<alba_ir::B>> = vec![None; net.transitions.len()];
    for &t in &net.firing_order() {
        let tr = &net.transitions[t];
        if let Some(tmr) = timers[t] {
            next_rung(b, tr.span);
            let elem = b.element(tr.span);
            b.emit(Op::CmpI(Cmp::Gt, tm[t], zero), elem);
            b.emit(Op::Ton(tmr, alba_ir::TimeBase::Ms), elem);
        }
        next_rung(b, tr.span);
        let elem = b.element(tr.span);
        // The guard first: its lowering loads the rung condition.
        if let Some(g) = &guards[t] {
            lower_guard(b, g, elem);
            // Kept for the transition's "enabled" element (below).
            let gb = b.temp_b();
            b.emit(Op::Ote(gb), elem);
            guard_bits[t] = Some(gb);
        }
        b.emit(Op::CmpI(Cmp::Gt, tm[t], zero), elem);
        if let Some(tmr) = timers[t] {
            b.emit(Op::Xic(alba_ir::B(tmr.b.0 + 2)), elem);
        }
        set(b, one, fired[t], elem);
        for &p in &t_out[t] {
            set(b, one, p_new[p], elem);
        }
    }
    // The new marking: what came, and what stayed (a place with no way out
    // keeps its token unless it is a Stop or an End; a transition that did not
    // fire keeps its own); nothing once the net ended.
    let end_span = net.transitions.first().map_or(first, |t| t.span);
    for (k, p) in net.places.iter().enumerate() {
        if p_out[k].is_empty() && !matches!(p.kind, ElementKind::Stop | ElementKind::End) {
            next_rung(b, end_span);
            b.emit(Op::CmpI(Cmp::Gt, pm[k], zero), alba_ir::NO_ELEM);
            set(b, one, p_new[k], alba_ir::NO_ELEM);
        }
    }
    for t in 0..tm.len() {
        next_rung(b, end_span);
        b.emit(Op::CmpI(Cmp::Gt, tm[t], zero), alba_ir::NO_ELEM);
        b.emit(Op::CmpI(Cmp::Eq, fired[t], zero), alba_ir::NO_ELEM);
        set(b, one, t_new[t], alba_ir::NO_ELEM);
    }
    next_rung(b, end_span);
    b.emit(Op::CmpI(Cmp::Gt, ended, zero), alba_ir::NO_ELEM);
    for &n in p_new.iter().chain(&t_new) {
        set(b, zero, n, alba_ir::NO_ELEM);
    }
    next_rung(b, end_span);
    for (&n, &m) in p_new.iter().zip(&pm).chain(t_new.iter().zip(&tm)) {
        b.emit(Op::CopyI(n, m), alba_ir::NO_ELEM);
    }
    emit_drives(b, net, drives, &pm, zero);
    // Monitoring: each transition's "enabled" element, on the new marking:
    // it holds the token and its guard held in this turn.
    for (t, tr) in net.transitions.iter().enumerate() {
        b.begin_rung(crate::petri::ENABLED_RUNGS + t as u32, tr.span);
        let elem = b.element(crate::petri::enabled_span(tr.span));
        b.emit(Op::True, elem);
        if let Some(gb) = guard_bits[t] {
            b.emit(Op::Xic(gb), elem);
        }
        b.emit(Op::CmpI(Cmp::Gt, tm[t], zero), elem);
    }
    b.release(mark);
    b.end_unit();
    diags
}

/// The statements of every Expression place: (destination, expression),
/// checked (E631). Errors point at the place, with the script's line:col.
fn scripts(
    net: &Net,
    name: &str,
    file: FileId,
    b: &mut Builder,
    diags: &mut Vec<Diagnostic>,
) -> HashMap<usize, Vec<(Place, alba_ladder::expr::Expr)>> {
    use alba_ladder::expr::{self, Expr};
    let mut out = HashMap::new();
    for (k, p) in net
        .places
        .iter()
        .enumerate()
        .filter(|(_, p)| p.kind == ElementKind::Expression)
    {
        let Some(text) = &p.script else {
            diags.push(
                Diagnostic::new(
                    Code::NetScript,
                    format!("expression `{}` has no `<script>`", p.id),
                    p.span,
                    "expression",
                )
                .with_help("give it a script: `<script>function{ Level * 2 }</script>`"),
            );
            continue;
        };
        let at = |offset: usize, msg: String| {
            let (l, c) = alba_net::script::line_col(text, offset);
            Diagnostic::new(
                Code::NetScript,
                format!("script of `{}`, line {l} col {c}: {msg}", p.id),
                p.span,
                "expression",
            )
        };
        let script = match alba_net::script::parse(text) {
            Ok(s) => s,
            Err(errors) => {
                diags.extend(errors.into_iter().map(|e| at(e.offset, e.message)));
                continue;
            }
        };
        for (n, off) in &script.defines {
            if let Err(e) = b.layout().resolve(n) {
                diags.push(at(*off, format!("`{n}` is defined but {e}")));
            }
        }
        let constants: HashMap<String, f64> = script
            .constants
            .iter()
            .map(|(n, v, _)| (n.to_ascii_lowercase(), *v))
            .collect();
        // Constants become literals; other names stay tags.
        fn subst(e: Expr, c: &HashMap<String, f64>) -> Expr {
            match e {
                Expr::Name(n, sp) => match c.get(&n.to_ascii_lowercase()) {
                    Some(v) => Expr::Lit(alba_model::Literal::Real(*v), sp),
                    None => Expr::Name(n, sp),
                },
                Expr::Neg(a) => Expr::Neg(Box::new(subst(*a, c))),
                Expr::Not(a, sp) => Expr::Not(Box::new(subst(*a, c)), sp),
                Expr::Bin(op, a, d, sp) => Expr::Bin(op, Box::new(subst(*a, c)), Box::new(subst(*d, c)), sp),
                Expr::Call(f, args, sp) => Expr::Call(f, args.into_iter().map(|a| subst(a, c)).collect(), sp),
                other => other,
            }
        }
        let own = value_tag(name, &p.id);
        let mut stmts = Vec::new();
        for st in &script.statements {
            let e = match expr::parse_net(&st.expr, file, 0) {
                Ok(e) => subst(e, &constants),
                Err((msg, sp)) => {
                    diags.push(at(st.offset + sp.start as usize, msg));
                    continue;
                }
            };
            let mut local = Vec::new();
            let numeric = check_number(b, &e, &mut local);
            if !local.is_empty() || !numeric {
                let why = local
                    .first()
                    .map_or_else(|| "a BOOL, not a number".to_string(), |d| d.message.clone());
                diags.push(at(st.offset, format!("`{}`: {why}", st.expr)));
                continue;
            }
            let (target, off) = st
                .target
                .as_ref()
                .map_or((own.as_str(), st.offset), |(t, o)| (t.as_str(), *o));
            match b.layout().resolve(target) {
                Ok(Target::Value { place, access })
                    if access == alba_ir::Access::ReadWrite && place.data_type() != DataType::Bool =>
                {
                    stmts.push((place, e));
                }
                Ok(Target::Value { place, .. }) if place.data_type() == DataType::Bool => {
                    diags.push(at(off, format!("`{target}` is a BOOL: a script assigns numbers")));
                }
                Ok(Target::Value { access, .. }) => {
                    diags.push(at(
                        off,
                        format!("`{target}` cannot be written: {}", access.why_not_writable()),
                    ));
                }
                Ok(_) => diags.push(at(off, format!("`{target}` is a structure; name a member"))),
                Err(e) => diags.push(at(off, e.to_string())),
            }
        }
        out.insert(k, stmts);
    }
    out
}

/// The Variable element's modes (the source's six, §2.2.3.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum VarMode {
    /// `target = source` (also the source's WriteToTarget).
    Assignment,
    /// Nothing: the variable is a scratch value for scripts.
    Variable,
    /// `value = target`.
    WriteToMyVariable,
    /// `target = value` (a constant).
    DefineTarget,
    /// `target = initial`.
    ResetTargetValue,
}

fn var_mode(text: &str) -> Option<VarMode> {
    match text.trim().to_ascii_lowercase().replace(['_', ' '], "").as_str() {
        "assignment" | "writetotarget" => Some(VarMode::Assignment),
        "variable" => Some(VarMode::Variable),
        "writetomyvariable" => Some(VarMode::WriteToMyVariable),
        "definetarget" => Some(VarMode::DefineTarget),
        "resettargetvalue" => Some(VarMode::ResetTargetValue),
        _ => None,
    }
}

/// The moves of Input, Output and Variable places, as (destination,
/// expression) statements like a script's (E630 for what is missing or wrong).
fn moves(
    net: &Net,
    name: &str,
    file: FileId,
    b: &mut Builder,
    diags: &mut Vec<Diagnostic>,
) -> Vec<(usize, Vec<(Place, alba_ladder::expr::Expr)>)> {
    use alba_ladder::expr;
    let mut out = Vec::new();
    for (k, p) in net.places.iter().enumerate() {
        if !matches!(p.kind, ElementKind::Input | ElementKind::Output | ElementKind::Variable) {
            continue;
        }
        let own = value_tag(name, &p.id);
        let prop = |key: &str| p.props.get(key).map(|v| v.trim().to_string()).filter(|v| !v.is_empty());
        let need = |key: &str, diags: &mut Vec<Diagnostic>| {
            let v = prop(key);
            if v.is_none() {
                diags.push(bad(
                    format!("a {} element needs `{key}`", p.kind.as_str()),
                    p.span,
                    p.kind.as_str(),
                ));
            }
            v
        };
        // (destination name, source expression text)
        let mv: Option<(String, String)> = match p.kind {
            ElementKind::Input => need("source", diags).map(|s| (own.clone(), s)),
            ElementKind::Output => match (need("target", diags), prop("source")) {
                (Some(t), Some(s)) => Some((t, s)),
                (Some(_), None) => {
                    diags.push(bad(
                        "an output element needs `source` (a tag or a number)".into(),
                        p.span,
                        "output",
                    ));
                    None
                }
                _ => None,
            },
            // A Variable without a mode is the source's `Variable` mode: a scratch value.
            _ => match prop("mode").map(|m| (var_mode(&m), m)) {
                None | Some((Some(VarMode::Variable), _)) => None,
                Some((None, m)) => {
                    diags.push(
                        bad(format!("`{m}` is not a variable mode"), p.span, "variable").with_help(
                            "one of Assignment, Variable, WriteToMyVariable, WriteToTarget, DefineTarget, ResetTargetValue",
                        ),
                    );
                    None
                }
                Some((Some(VarMode::Assignment), _)) => need("target", diags).zip(need("source", diags)),
                Some((Some(VarMode::WriteToMyVariable), _)) => need("target", diags).map(|t| (own.clone(), t)),
                Some((Some(VarMode::DefineTarget), _)) => need("target", diags).zip(need("value", diags)),
                Some((Some(VarMode::ResetTargetValue), _)) => {
                    need("target", diags).map(|t| (t, prop("initial").unwrap_or_else(|| "0".into())))
                }
            },
        };
        let Some((dest, src)) = mv else { continue };
        let e = match expr::parse_net(&src, file, 0) {
            Ok(e) => e,
            Err((msg, _)) => {
                diags.push(bad(format!("`{src}`: {msg}"), p.span, p.kind.as_str()));
                continue;
            }
        };
        let mut local = Vec::new();
        if !check_number(b, &e, &mut local) {
            let why = local
                .first()
                .map_or_else(|| "a BOOL, not a number".to_string(), |d| d.message.clone());
            diags.push(bad(format!("`{src}`: {why}"), p.span, p.kind.as_str()));
            continue;
        }
        match b.layout().resolve(&dest) {
            Ok(Target::Value {
                place,
                access: alba_ir::Access::ReadWrite,
            }) if place.data_type() != DataType::Bool => {
                out.push((k, vec![(place, e)]));
            }
            Ok(Target::Value { access, place }) => diags.push(bad(
                if place.data_type() == DataType::Bool {
                    format!("`{dest}` is a BOOL: elements move numbers")
                } else {
                    format!("`{dest}` cannot be written: {}", access.why_not_writable())
                },
                p.span,
                p.kind.as_str(),
            )),
            Ok(_) => diags.push(bad(
                format!("`{dest}` is a structure; name a member"),
                p.span,
                p.kind.as_str(),
            )),
            Err(e) => diags.push(bad(e.to_string(), p.span, p.kind.as_str())),
        }
    }
    out
}
