//! `GET /api/domain`: the language as the studio needs it (types and
//! structure members, instructions with operand labels and titles, what fits
//! each operand kind), built from the Rust definitions by
//! `alba_ladder::domain`; `GET /api/instructions` is its instruction table.

use alba_compiler::ladder::domain::{Domain, InstructionInfo, domain, instructions as table};
use axum::Json;

/// `GET /api/domain`.
pub async fn get() -> Json<Domain> {
    Json(domain())
}

/// `GET /api/instructions`: the palette (every instruction, PID included).
pub async fn instructions() -> Json<Vec<InstructionInfo>> {
    Json(table())
}
