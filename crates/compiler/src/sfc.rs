//! IEC 61131-3 SFC (docs/nets.md "SFC") on the one IR: the chart is a
//! 1-safe Petri-mode net (`alba_net::sfc::Sfc::to_net`, lowered by
//! `petri`), then, in the same unit and after the new marking is written:
//! each step's flag `<sfc>.<step>.X` and elapsed time `<sfc>.<step>.T`
//! (an engine TON, `<sfc>.<step>.timer`), and each action's BOOL tag as the
//! OR of its associations' terms — N: X; S/R: a latch set and reset (R
//! wins); L: X and T < t; D: X and T ≥ t; P and P1: the scan X rises; P0:
//! the scan X falls. An action written in ST (`ACTION name: … END_ACTION`)
//! drives a BOOL `<sfc>.<name>` the same way, and its body runs, lowered
//! by alba-st into the chart's unit after the actions, in the scans where
//! that BOOL is true.

use crate::petri;
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_ir::{Access, B, Builder, Cmp, I, Op, Place, Target, Tmr};
use alba_model::{DataType, TagTable, Value};
use alba_net::sfc::{Qualifier, Sfc};

pub fn x_tag(sfc: &str, step: &str) -> String {
    format!("{sfc}.{step}.X")
}

pub fn t_tag(sfc: &str, step: &str) -> String {
    format!("{sfc}.{step}.T")
}

/// The TIMER of an SD or SL association: `<sfc>.<step>.<action>.sd`.
fn assoc_timer_tag(sfc: &str, step: &str, action: &str, q: Qualifier) -> String {
    format!("{sfc}.{step}.{action}.{}", format!("{q:?}").to_ascii_lowercase())
}

fn timer_tag(sfc: &str, step: &str) -> String {
    format!("{sfc}.{step}.timer")
}

/// The BOOL an ST action's associations drive: `<sfc>.<action>`.
pub fn action_tag(sfc: &str, action: &str) -> String {
    format!("{sfc}.{action}")
}

/// The BOOL an ST condition is computed into: `<sfc>.<transition>.C`.
pub fn condition_tag(sfc: &str, transition: &str) -> String {
    format!("{sfc}.{transition}.C")
}

/// The chart's tags: each step's marking (as a net's), `.X`, `.T` and
/// timer, each ST action's BOOL and each ST condition's.
pub fn tags(sfc: &Sfc, name: &str, file: FileId, tags: &mut TagTable, diags: &mut Vec<Diagnostic>) {
    let net = sfc.to_net(name, file);
    petri::marking_tags(&net, name, tags, diags);
    for (t, nt) in sfc.transitions.iter().zip(&net.transitions).filter(|(t, _)| t.st) {
        let tag = condition_tag(name, &nt.id);
        if tags.get(&tag).is_some() {
            diags.push(Diagnostic::new(
                Code::NetTagClash,
                format!("the condition flag `{tag}` is already a tag"),
                t.condition.span,
                "condition",
            ));
            continue;
        }
        let what = format!("the ST condition of transition {} of {name}", nt.id);
        tags.push(petri::net_tag(
            tag,
            DataType::Bool,
            Some(Value::Bool(false)),
            what,
            t.condition.span,
        ));
    }
    for a in &sfc.actions {
        let tag = action_tag(name, &a.name);
        if tags.get(&tag).is_some() {
            diags.push(Diagnostic::new(
                Code::NetTagClash,
                format!("the action flag `{tag}` is already a tag"),
                a.header,
                "action",
            ));
            continue;
        }
        let what = format!("action {} of {name} is active (its ST body runs)", a.name);
        tags.push(petri::net_tag(
            tag,
            DataType::Bool,
            Some(Value::Bool(false)),
            what,
            a.header,
        ));
    }
    for s in &sfc.steps {
        // The timers of the stored-and-timed associations (SD, SL).
        for a in s
            .actions
            .iter()
            .filter(|a| matches!(a.qualifier, Qualifier::SD | Qualifier::SL))
        {
            let tag = assoc_timer_tag(name, &s.name, &a.action, a.qualifier);
            if tags.get(&tag).is_none() {
                let what = format!("times {:?} of {} in step {} of {name}", a.qualifier, a.action, s.name);
                tags.push(petri::net_tag(tag, DataType::Timer, None, what, a.span));
            }
        }
        for (tag, ty, initial, what) in [
            (
                x_tag(name, &s.name),
                DataType::Bool,
                Some(Value::Bool(s.initial)),
                "is active",
            ),
            (
                t_tag(name, &s.name),
                DataType::Time,
                Some(Value::Time(0)),
                "has been active (ms)",
            ),
            (timer_tag(name, &s.name), DataType::Timer, None, "times its activity"),
        ] {
            if tags.get(&tag).is_some() {
                diags.push(Diagnostic::new(
                    Code::NetTagClash,
                    format!("the step flag `{tag}` is already a tag"),
                    s.span,
                    "step",
                ));
                continue;
            }
            tags.push(petri::net_tag(
                tag,
                ty,
                initial,
                format!("step {} of {name} {what}", s.name),
                s.span,
            ));
        }
    }
}

/// An action tag and its associations: (step index, qualifier, time ms).
struct Action {
    key: String,
    place: Place,
    span: Span,
    assoc: Vec<(usize, Qualifier, Option<i64>, Option<Tmr>)>,
}

/// The ST actions of a chart as one ST file: a PROGRAM per action whose
/// body is `IF <sfc>.<action> THEN <body> END_IF`, every span in the
/// `.sfc` file (each is parsed from a text of the file's length where only
/// the header, now `PROGRAM <action>`, and the body are kept).
fn st_actions(sfc: &Sfc, name: &str, file: FileId, text: &str, diags: &mut Vec<Diagnostic>) -> alba_st::File {
    use alba_st::ast::{Expr, ExprKind, Ident, Stmt, StmtKind};
    let mut out = alba_st::File {
        pous: Vec::new(),
        types: Vec::new(),
        globals: Vec::new(),
    };
    for a in &sfc.actions {
        let (h, body) = (a.header.start as usize, a.body.start as usize..a.body.end as usize);
        // `ACTION <name>:` is at least as long as `PROGRAM <name>`.
        let header = format!("PROGRAM {}", a.name);
        let mut synth = " ".repeat(h);
        synth.push_str(&header);
        synth.push_str(&" ".repeat((body.start - h).saturating_sub(header.len())));
        synth.push_str(text.get(body.clone()).unwrap_or(""));
        synth.push_str("\nEND_PROGRAM\n");
        let (parsed, d) = alba_st::parse(&synth, file);
        // What the parser reports after the body is at END_ACTION.
        diags.extend(d.into_iter().map(|mut d| {
            if let Some(l) = d.primary.as_mut()
                && l.span.start as usize > body.end
            {
                l.span = Span::new(file, body.end..body.end + 10);
            }
            d
        }));
        for mut p in parsed.pous {
            let gate = Expr {
                kind: ExprKind::Name(Ident {
                    name: action_tag(name, &a.name),
                    span: a.header,
                }),
                span: a.header,
            };
            let stmts = std::mem::take(&mut p.body);
            p.body = vec![Stmt {
                kind: StmtKind::If {
                    arms: vec![(gate, stmts)],
                    els: None,
                },
                span: a.header,
            }];
            out.pous.push(p);
        }
    }
    out
}

/// The ST conditions of a chart as one ST file: a PROGRAM per condition
/// assigning it to its flag `<sfc>.<transition>.C`, every span in the
/// `.sfc` file (as for [`st_actions`], the text before the condition
/// becomes `PROGRAM c c:=`).
fn st_conditions(sfc: &Sfc, name: &str, file: FileId, text: &str, diags: &mut Vec<Diagnostic>) -> alba_st::File {
    use alba_st::ast::{Expr, ExprKind, Ident, StmtKind};
    let mut out = alba_st::File {
        pous: Vec::new(),
        types: Vec::new(),
        globals: Vec::new(),
    };
    let net = sfc.to_net(name, file);
    for (t, nt) in sfc.transitions.iter().zip(&net.transitions).filter(|(t, _)| t.st) {
        let (h, cond) = (
            t.span.start as usize,
            t.condition.span.start as usize..t.condition.span.end as usize,
        );
        // `TRANSITION FROM a TO b :` is longer than this.
        let header = "PROGRAM c c:=";
        let mut synth = " ".repeat(h);
        synth.push_str(header);
        synth.push_str(&" ".repeat((cond.start - h).saturating_sub(header.len())));
        synth.push_str(text.get(cond.clone()).unwrap_or(""));
        synth.push_str(";\nEND_PROGRAM\n");
        let (parsed, d) = alba_st::parse(&synth, file);
        let at_end = Span::new(file, cond.end..cond.end);
        let errors = d.len();
        diags.extend(d.into_iter().map(|mut d| {
            if let Some(l) = d.primary.as_mut()
                && (l.span.start as usize >= cond.end || (l.span.start as usize) < cond.start)
            {
                l.span = at_end;
            }
            d
        }));
        if errors > 0 {
            continue;
        }
        for mut p in parsed.pous {
            match p.body.as_mut_slice() {
                [s] if matches!(s.kind, StmtKind::Assign(..)) => {
                    if let StmtKind::Assign(target, _) = &mut s.kind {
                        *target = Expr {
                            kind: ExprKind::Name(Ident {
                                name: condition_tag(name, &nt.id),
                                span: t.condition.span,
                            }),
                            span: t.condition.span,
                        };
                    }
                    out.pous.push(p);
                }
                _ => diags.push(Diagnostic::new(
                    Code::SfcSyntax,
                    "a condition in ST is one expression",
                    t.condition.span,
                    "condition",
                )),
            }
        }
    }
    out
}

/// Compiles the chart as one unit; its ST actions may call the FUNCTIONs
/// and FUNCTION_BLOCKs of the project's `.st` files (`library`).
pub fn compile(
    sfc: &Sfc,
    file: FileId,
    text: &str,
    unit: &str,
    library: &[&alba_st::File],
    b: &mut Builder,
) -> Vec<Diagnostic> {
    let name = petri::net_name(unit);
    let mut diags = Vec::new();
    let slot = |b: &Builder, tag: &str| b.layout().resolve(tag).ok();
    // Step flags, elapsed times, timers.
    let mut steps = Vec::new();
    for s in &sfc.steps {
        match (
            slot(b, &x_tag(&name, &s.name)),
            slot(b, &t_tag(&name, &s.name)),
            slot(b, &timer_tag(&name, &s.name)),
        ) {
            (
                Some(Target::Value {
                    place: Place::Bool(x), ..
                }),
                Some(Target::Value {
                    place: Place::Int(t, _),
                    ..
                }),
                Some(Target::Timer(tmr)),
            ) => steps.push((x, t, tmr)),
            _ => return diags, // clashes reported by `tags`
        }
    }
    // Actions: each BOOL tag once, with every association that drives it.
    let mut actions: Vec<Action> = Vec::new();
    for (k, s) in sfc.steps.iter().enumerate() {
        for a in &s.actions {
            let tag = match sfc.st_action(&a.action) {
                Some(st) => action_tag(&name, &st.name),
                None => a.action.clone(),
            };
            let place = match b.layout().resolve(&tag) {
                Ok(Target::Value {
                    place,
                    access: Access::ReadWrite,
                }) if place.data_type() == DataType::Bool => place,
                Ok(Target::Value { place, access }) => {
                    let why = if place.data_type() == DataType::Bool {
                        access.why_not_writable().to_string()
                    } else {
                        format!("it is {}, not a BOOL", place.data_type().with_article())
                    };
                    diags.push(Diagnostic::new(
                        Code::SfcAction,
                        format!("the action `{}` cannot be driven: {why}", a.action),
                        a.span,
                        "action",
                    ));
                    continue;
                }
                Ok(_) => {
                    diags.push(Diagnostic::new(
                        Code::SfcAction,
                        format!("`{}` is a structure; name a BOOL member", a.action),
                        a.span,
                        "action",
                    ));
                    continue;
                }
                Err(e) => {
                    let mut d = Diagnostic::new(Code::SfcAction, format!("action {e}"), a.span, "action");
                    if let Some(sg) = b.layout().tags.suggest(&a.action) {
                        d = d.with_help(format!("did you mean `{sg}`?"));
                    }
                    diags.push(d);
                    continue;
                }
            };
            let key = a.action.to_ascii_lowercase();
            let tmr = match b
                .layout()
                .resolve(&assoc_timer_tag(&name, &s.name, &a.action, a.qualifier))
            {
                Ok(Target::Timer(t)) => Some(t),
                _ => None,
            };
            match actions.iter_mut().find(|x| x.key == key) {
                Some(x) => x.assoc.push((k, a.qualifier, a.time_ms, tmr)),
                None => actions.push(Action {
                    key,
                    place,
                    span: a.span,
                    assoc: vec![(k, a.qualifier, a.time_ms, tmr)],
                }),
            }
        }
    }
    let st = st_actions(sfc, &name, file, text, &mut diags);
    let conds = st_conditions(sfc, &name, file, text, &mut diags);
    if !diags.is_empty() {
        return diags;
    }
    let net = sfc.to_net(&name, file);
    let max = i32::MAX;
    let mut st_diags = Vec::new();
    let st_out = &mut st_diags;
    let mut cond_diags = Vec::new();
    let cond_out = &mut cond_diags;
    // The ST conditions, each into its flag, before the chart's turn.
    let before = move |b: &mut Builder| {
        if !conds.pous.is_empty() {
            cond_out.extend(alba_st::compile_in(&conds, library, 30_000, b));
        }
    };
    diags = petri::compile_with(
        &net,
        file,
        text,
        unit,
        b,
        (before, move |b: &mut Builder, marking: &[I]| {
            let zero = b.const_i(0);
            let forever = b.const_i(max);
            let span = sfc.steps.first().map_or(Span::new(file, 0..0), |s| s.span);
            let mut rung = 10_000;
            let mut next = |b: &mut Builder, sp: Span| {
                b.begin_rung(rung, sp);
                rung += 1;
            };
            // Flags, times and the edges of X.
            let mut prev: Vec<B> = Vec::new();
            for (k, &(x, t, tmr)) in steps.iter().enumerate() {
                let sp = sfc.steps[k].span;
                next(b, sp);
                let elem = b.element(sp);
                b.emit(Op::True, elem);
                b.emit(Op::CmpI(Cmp::Gt, marking[k], zero), elem);
                b.emit(Op::Ote(x), elem);
                next(b, sp);
                b.emit(Op::CopyI(forever, tmr.i), alba_ir::NO_ELEM);
                b.emit(Op::Xic(x), alba_ir::NO_ELEM);
                b.emit(Op::Ton(tmr, alba_ir::TimeBase::Ms), alba_ir::NO_ELEM);
                b.emit(Op::CopyI(I(tmr.i.0 + 1), t), alba_ir::NO_ELEM);
                prev.push(b.state_b());
            }
            // Actions.
            for Action {
                place,
                span: asp,
                assoc,
                ..
            } in &actions
            {
                let acc = b.temp_b();
                let latch = b.state_b();
                next(b, *asp);
                b.emit(Op::Otu(acc), alba_ir::NO_ELEM);
                // SD and SL run on their own from the step's activation: a bit each.
                let runs: Vec<Option<B>> = assoc
                    .iter()
                    .map(|(_, q, _, _)| matches!(q, Qualifier::SD | Qualifier::SL).then(|| b.state_b()))
                    .collect();
                let all_runs: Vec<B> = runs.iter().flatten().copied().collect();
                let term = |b: &mut Builder, n: usize, next: &mut dyn FnMut(&mut Builder, Span)| {
                    let (k, q, t, tmr) = assoc[n];
                    let (x, tt, _): (B, I, Tmr) = steps[k];
                    let elem = b.element(sfc.steps[k].span);
                    let limit = b.const_i(i32::try_from(t.unwrap_or(0)).unwrap_or(i32::MAX));
                    match q {
                        Qualifier::N => {
                            b.emit(Op::Xic(x), elem);
                            b.emit(Op::Otl(acc), elem);
                        }
                        Qualifier::S => {
                            b.emit(Op::Xic(x), elem);
                            b.emit(Op::Otl(latch), elem);
                        }
                        Qualifier::R => {
                            b.emit(Op::Xic(x), elem);
                            b.emit(Op::Otu(latch), elem);
                            for &r in &all_runs {
                                b.emit(Op::Otu(r), elem);
                            }
                        }
                        Qualifier::L | Qualifier::D => {
                            b.emit(Op::Xic(x), elem);
                            b.emit(
                                Op::CmpI(if q == Qualifier::L { Cmp::Lt } else { Cmp::Ge }, tt, limit),
                                elem,
                            );
                            b.emit(Op::Otl(acc), elem);
                        }
                        Qualifier::DS => {
                            b.emit(Op::Xic(x), elem);
                            b.emit(Op::CmpI(Cmp::Ge, tt, limit), elem);
                            b.emit(Op::Otl(latch), elem);
                        }
                        Qualifier::SD | Qualifier::SL => {
                            let (Some(run), Some(tmr)) = (runs[n], tmr) else { return };
                            // Started by the step's activation, then timed on its own.
                            b.emit(Op::Xic(x), elem);
                            b.emit(Op::Xio(prev[k]), elem);
                            b.emit(Op::Otl(run), elem);
                            next(b, sfc.steps[k].span);
                            b.emit(Op::CopyI(limit, tmr.i), elem);
                            b.emit(Op::Xic(run), elem);
                            b.emit(Op::Ton(tmr, alba_ir::TimeBase::Ms), elem);
                            next(b, sfc.steps[k].span);
                            b.emit(Op::Xic(B(tmr.b.0 + 2)), elem);
                            b.emit(Op::Otu(run), elem);
                            if q == Qualifier::SD {
                                // The delay is over: stored until a reset.
                                b.emit(Op::Otl(latch), elem);
                            } else {
                                // Limited: on while it runs.
                                next(b, sfc.steps[k].span);
                                b.emit(Op::Xic(run), elem);
                                b.emit(Op::Otl(acc), elem);
                            }
                        }
                        Qualifier::P | Qualifier::P1 => {
                            b.emit(Op::Xic(x), elem);
                            b.emit(Op::Xio(prev[k]), elem);
                            b.emit(Op::Otl(acc), elem);
                        }
                        Qualifier::P0 => {
                            b.emit(Op::Xio(x), elem);
                            b.emit(Op::Xic(prev[k]), elem);
                            b.emit(Op::Otl(acc), elem);
                        }
                    }
                };
                // What stores first, then the resets (R wins), then the rest.
                let mut order: Vec<usize> = (0..assoc.len()).collect();
                order.sort_by_key(|&n| match assoc[n].1 {
                    Qualifier::S | Qualifier::DS | Qualifier::SD => 0,
                    Qualifier::R => 1,
                    _ => 2,
                });
                for n in order {
                    next(b, sfc.steps[assoc[n].0].span);
                    term(b, n, &mut next);
                }
                next(b, *asp);
                let elem = b.element(*asp);
                b.emit(Op::Xic(latch), elem);
                b.emit(Op::Otl(acc), elem);
                next(b, *asp);
                b.emit(Op::Xic(acc), elem);
                let (out, post) = b.bool_out(*place, elem);
                b.emit(Op::Ote(out), elem);
                b.post(post, elem);
            }
            // Remember X for the next scan's edges.
            for (k, &(x, _, _)) in steps.iter().enumerate() {
                next(b, span);
                b.emit(Op::Xic(x), alba_ir::NO_ELEM);
                b.emit(Op::Ote(prev[k]), alba_ir::NO_ELEM);
            }
            // The ST actions' bodies, each while its flag is true.
            if !st.pous.is_empty() {
                st_out.extend(alba_st::compile_in(&st, library, rung, b));
            }
        }),
    );
    diags.extend(cond_diags);
    diags.extend(st_diags);
    diags
}
