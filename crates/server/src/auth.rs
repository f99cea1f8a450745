//! Who makes a request: the identity the session layer attaches to every
//! request (docs/security.md, "Sessions and roles").
//!
//! Handlers and the audit trail take a [`Who`] as an extractor:
//! `async fn put(who: Who, …)`. The session layer inserts it into the
//! request's extensions before any handler runs.

use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use std::net::SocketAddr;

/// Placeholder until `alba_auth::Role` exists (the `users` part):
/// viewer < operator < engineer < admin, each including the one before.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    Viewer,
    Operator,
    Engineer,
    Admin,
}

/// The identity of a request: the logged-in user (`None` when no users
/// are configured and the request acts with full rights on loopback), its
/// role, and the client's address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Who {
    pub user: Option<String>,
    pub role: Role,
    pub addr: SocketAddr,
}

impl<S: Send + Sync> FromRequestParts<S> for Who {
    type Rejection = crate::ApiError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Who, Self::Rejection> {
        parts
            .extensions
            .get::<Who>()
            .cloned()
            .ok_or_else(|| crate::ApiError::Internal("the request has no identity (no session layer)".into()))
    }
}
