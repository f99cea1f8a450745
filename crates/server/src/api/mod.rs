//! The handlers of `/api`, one file per area. Each handler parses its
//! request here, answers with a type of `crate::reply` and fails with an
//! [`ApiError`] (statuses: `crate::error::status`).

pub mod alarms;
pub mod audit;
pub mod domain;
pub mod forces;
pub mod hardware;
pub mod history;
pub mod images;
pub mod nets;
pub mod opcua;
pub mod pid;
pub mod programs;
pub mod recipes;
pub mod reports;
pub mod screens;
pub mod session;
pub mod status;
pub mod stream;
pub mod tags;
pub mod trends;
pub mod verify;

use crate::error::ApiError;
use axum::extract::rejection::JsonRejection;
use axum::http::StatusCode;
use serde_json::Value as Json;

/// Body limits (docs/api.md).
pub const SMALL_BODY: usize = 64 * 1024;
pub const FILE_BODY: usize = 1024 * 1024;

/// A JSON body as the extractor gives it.
pub type Body = Result<axum::Json<Json>, JsonRejection>;

/// A JSON body, with malformed input and oversized bodies as API errors.
pub fn body(b: Body) -> Result<Json, ApiError> {
    match b {
        Ok(axum::Json(j)) => Ok(j),
        Err(JsonRejection::BytesRejection(e)) if e.status() == StatusCode::PAYLOAD_TOO_LARGE => Err(ApiError::TooLarge),
        Err(e) => Err(ApiError::Malformed(format!("malformed JSON body: {}", e.body_text()))),
    }
}

/// A whole-file body (tags.csv, a screen) as UTF-8 text; a body over the
/// limit is answered in the JSON error shape, as everywhere.
pub fn text_body(
    b: Result<axum::body::Bytes, axum::extract::rejection::BytesRejection>,
    what: &str,
) -> Result<String, ApiError> {
    let bytes = b.map_err(|e| {
        if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
            ApiError::TooLarge
        } else {
            ApiError::Malformed(e.body_text())
        }
    })?;
    String::from_utf8(bytes.to_vec()).map_err(|e| ApiError::Malformed(format!("{what} is not UTF-8 text: {e}")))
}

pub fn field<'a>(j: &'a Json, name: &str) -> Result<&'a Json, ApiError> {
    j.get(name)
        .ok_or_else(|| ApiError::Malformed(format!("the body needs a `{name}` field")))
}

/// Any other path under `/api`.
pub async fn fallback() -> ApiError {
    ApiError::NotFound("no such endpoint".into())
}
