//! `GET /api/domain`: the language as the studio needs it (types and
//! structure members, instructions with operand labels and titles, what fits
//! each operand kind), built from the Rust definitions by
//! `alba_ladder::domain`, and the role each route needs; `GET
//! /api/instructions` is its instruction table.

use crate::auth::Access;
use crate::reply::{DomainReply, ParamInfo, ParamTable, RouteRole};
use alba_compiler::ladder::domain::{InstructionInfo, domain, instructions as table};
use axum::Json;

/// `GET /api/domain`, with the role table of [`crate::ROUTE_ROLES`].
pub async fn get() -> Json<DomainReply> {
    let routes = crate::ROUTE_ROLES
        .iter()
        .map(|(method, route, access)| RouteRole {
            method: (*method).to_string(),
            route: (*route).to_string(),
            role: match access {
                Access::Public => None,
                Access::Role(r) => Some((*r).into()),
            },
        })
        .collect();
    use alba_compiler::project::hmi;
    let mut screens = crate::reply::ScreenDomain {
        elements: hmi::ELEMENT_TYPES
            .iter()
            .map(|(t, d)| (t.to_string(), d.to_string()))
            .collect(),
        properties: hmi::ELEMENT_PROPS.iter().map(param_table).collect(),
        animations: hmi::ANIMATIONS.iter().map(param_table).collect(),
        actions: hmi::ACTIONS.iter().map(|a| a.to_string()).collect(),
    };
    let mut language = domain();
    if crate::lang::request_lang() == alba_compiler::diag::Lang::Es {
        for g in &mut language.groups {
            spanish(&mut g.title);
        }
        for a in &mut language.args {
            spanish(&mut a.doc);
        }
        language.instructions.iter_mut().for_each(spanish_instruction);
        for (_, what) in &mut screens.elements {
            spanish_owned(what);
        }
        for p in screens.properties.iter_mut().chain(&mut screens.animations) {
            for p in &mut p.params {
                spanish_owned(&mut p.help);
            }
        }
    }
    Json(DomainReply {
        language,
        routes,
        screens,
    })
}

/// `GET /api/instructions`: the palette (every instruction, PID included),
/// worded in the request's language as `/api/domain`.
pub async fn instructions() -> Json<Vec<InstructionInfo>> {
    let mut t = table();
    if crate::lang::request_lang() == alba_compiler::diag::Lang::Es {
        t.iter_mut().for_each(spanish_instruction);
    }
    Json(t)
}

/// A text the studio shows, in Spanish by `alba_diag::es::DOMAIN` (as it is
/// when the table lacks it, which `the_domain_speaks_spanish` does not let ship).
fn spanish(text: &mut &'static str) {
    if let Some(es) = alba_compiler::diag::es::domain_text(text) {
        *text = es;
    }
}

fn spanish_owned(text: &mut String) {
    if let Some(es) = alba_compiler::diag::es::domain_text(text) {
        *text = es.to_string();
    }
}

/// An instruction's title, doc and operand labels in Spanish.
fn spanish_instruction(i: &mut InstructionInfo) {
    spanish(&mut i.title);
    spanish(&mut i.doc);
    i.labels.iter_mut().for_each(spanish);
    for o in &mut i.optional {
        spanish(&mut o.label);
        spanish(&mut o.doc);
    }
}

/// An element type's or an animation's parameters.
fn param_table((kind, params): &(&str, &[alba_compiler::project::hmi::Param])) -> ParamTable {
    ParamTable {
        kind: kind.to_string(),
        params: params.iter().map(param).collect(),
    }
}

/// A parameter as the designer's form needs it.
fn param(p: &alba_compiler::project::hmi::Param) -> ParamInfo {
    use alba_compiler::project::hmi::ParamKind;
    let (kind, min, max, unit, choices) = match p.kind {
        ParamKind::Number { min, max, unit } => ("number", Some(min), Some(max), unit, &[][..]),
        ParamKind::Bool => ("bool", None, None, "", &[][..]),
        ParamKind::Color => ("color", None, None, "", &[][..]),
        ParamKind::Choice(c) => ("choice", None, None, "", c),
        ParamKind::Intervals => ("intervals", None, None, "", &[][..]),
        ParamKind::Text { max_len } => ("text", None, Some(max_len as f64), "", &[][..]),
        ParamKind::Tag => ("tag", None, None, "", &[][..]),
        ParamKind::Points { max } => ("points", None, Some(max as f64), "", &[][..]),
        ParamKind::Pens { max } => ("pens", None, Some(max as f64), "", &[][..]),
    };
    ParamInfo {
        name: p.name.to_string(),
        kind,
        min,
        max,
        unit: unit.to_string(),
        choices: choices.iter().map(|c| c.to_string()).collect(),
        help: p.help.to_string(),
        legacy: p.legacy,
    }
}
