//! The middleware every request passes, outermost first: the
//! browser-attack guard ([`guard`], rules in `crate::guard`), the request
//! timeout ([`timeout`]), then the session and role check ([`session`],
//! rules in `crate::auth`). Kept apart from the rules they apply, so that
//! the rules do not depend on [`AppState`] (which holds them).

use crate::auth::{Access, identify, needed};
use crate::error::ApiError;
use crate::guard::{Refusal, secure};
use crate::reply::ErrorReply;
use crate::state::AppState;
use axum::extract::{ConnectInfo, MatchedPath, Request, State};
use axum::http::header;
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::net::SocketAddr;
use std::sync::Arc;

/// The guard: refuses what [`Guard::admit`](crate::guard::Guard::admit) refuses, and adds the
/// security headers to every answer.
pub async fn guard(State(st): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    let host = req.headers().get(header::HOST).cloned();
    let mut res = match st.guard.admit(req.method(), req.uri().path(), req.headers()) {
        Ok(()) => next.run(req).await,
        Err(Refusal(status, error)) => (
            status,
            axum::Json(ErrorReply {
                error: crate::lang::worded(error),
                diagnostics: None,
            }),
        )
            .into_response(),
    };
    secure(res.headers_mut(), host.as_ref());
    res
}

/// The session and role check before every route (see `crate::auth`'s doc).
pub async fn session(State(st): State<Arc<AppState>>, mut req: Request, next: Next) -> Response {
    let route = req.extensions().get::<MatchedPath>().map(|m| m.as_str().to_string());
    let access = needed(crate::ROUTE_ROLES, req.method(), route.as_deref(), req.uri().path());
    let Some(addr) = req.extensions().get::<ConnectInfo<SocketAddr>>().map(|c| c.0) else {
        return ApiError::Internal("the server does not know the client's address (serve with connect info)".into())
            .into_response();
    };
    let who = identify(&st.auth, req.headers(), addr);
    let who = match (access, who) {
        (Access::Public, Ok(w)) => w,
        (Access::Public, Err(_)) => None,
        (Access::Role(_), Err(e)) => return e.into_response(),
        (Access::Role(_), Ok(None)) if !st.auth.has_users() => {
            return ApiError::Forbidden(
                "this project has no users, so only clients on this computer (loopback) are served; add users with `alba user add`".into(),
            )
            .into_response();
        }
        (Access::Role(_), Ok(None)) => {
            return ApiError::Unauthorized("log in first (POST /api/login)".into()).into_response();
        }
        (Access::Role(needed), Ok(Some((w, key)))) => {
            if !w.role.allows(needed) {
                return ApiError::Forbidden(format!("this needs the role {needed}; you are {}", w.role))
                    .into_response();
            }
            Some((w, key))
        }
    };
    if let Some((w, key)) = who {
        req.extensions_mut().insert(w);
        if let Some(k) = key {
            req.extensions_mut().insert(k);
        }
    }
    next.run(req).await
}

/// Answers 503 when a request takes longer than `[http] request_timeout_s`, or
/// than its own bound on a route of [`crate::LONG_ROUTES`] (until its answer
/// starts: a long download streams on).
pub async fn timeout(State(st): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    let path = req.uri().path();
    let limit = crate::LONG_ROUTES
        .iter()
        .find(|(route, _)| *route == path)
        .map_or(st.request_timeout, |(_, long)| st.request_timeout.max(*long));
    match tokio::time::timeout(limit, next.run(req)).await {
        Ok(r) => r,
        Err(_) => ApiError::TimedOut(limit).into_response(),
    }
}
