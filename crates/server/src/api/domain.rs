//! `GET /api/domain`: the language as the studio needs it (types and
//! structure members, instructions with operand labels and titles, what fits
//! each operand kind), built from the Rust definitions by
//! `alba_ladder::domain`, and the role each route needs; `GET
//! /api/instructions` is its instruction table.

use crate::auth::Access;
use crate::reply::{DomainReply, RouteRole};
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
        animations: hmi::ANIMATIONS
            .iter()
            .map(|(k, ps)| (k.to_string(), ps.iter().map(|p| p.to_string()).collect()))
            .collect(),
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
