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
    let screens = crate::reply::ScreenDomain {
        elements: hmi::ELEMENT_TYPES
            .iter()
            .map(|(t, d)| (t.to_string(), d.to_string()))
            .collect(),
        properties: hmi::ELEMENT_PROPS.iter().map(param_table).collect(),
        animations: hmi::ANIMATIONS.iter().map(param_table).collect(),
        actions: hmi::ACTIONS.iter().map(|a| a.to_string()).collect(),
    };
    Json(DomainReply {
        language: domain(),
        routes,
        screens,
    })
}

/// `GET /api/instructions`: the palette (every instruction, PID included).
pub async fn instructions() -> Json<Vec<InstructionInfo>> {
    Json(table())
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
