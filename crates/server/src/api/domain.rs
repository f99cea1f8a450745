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
    Json(DomainReply {
        language: domain(),
        routes,
    })
}

/// `GET /api/instructions`: the palette (every instruction, PID included).
pub async fn instructions() -> Json<Vec<InstructionInfo>> {
    Json(table())
}
