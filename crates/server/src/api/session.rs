//! `POST /api/login`, `POST /api/logout`, `GET /api/me` (docs/api.md,
//! "Sessions"); the sessions themselves are `crate::auth`.

use super::audit::{self, Actor};
use super::{Body, body, field};
use crate::auth::{Who, cleared_cookie, cookie, token};
use crate::error::ApiError;
use crate::reply::{Login, Me};
use crate::state::AppState;
use alba_control::audit::{Action, Entry, Outcome};
use axum::Json;
use axum::extract::{ConnectInfo, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};
use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::Ordering;

/// A string field of at most `max` bytes.
fn text<'a>(j: &'a serde_json::Value, name: &str, max: usize) -> Result<&'a str, ApiError> {
    let s = field(j, name)?
        .as_str()
        .ok_or_else(|| ApiError::Malformed(format!("`{name}` must be a string")))?;
    if s.len() > max {
        return Err(ApiError::Malformed(format!("`{name}` is longer than {max} bytes")));
    }
    Ok(s)
}

/// `{"user", "password"}` → a session: `{"token", "user", "role"}` and the
/// `alba_session` cookie.
pub async fn login(
    State(st): State<Arc<AppState>>,
    ConnectInfo(addr): ConnectInfo<SocketAddr>,
    b: Body,
) -> Result<Response, ApiError> {
    let j = body(b)?;
    let user = text(&j, "user", alba_auth::MAX_NAME_LEN)?;
    let password = text(&j, "password", alba_auth::MAX_PASSWORD_BYTES)?;
    if !st.auth.has_users() {
        return Err(ApiError::Invalid(
            "this project has no users: every request from this computer has full rights (add users with `alba user add`)"
                .into(),
        ));
    }
    // Audited (`login`, `login_failed`) before the reply; a login whose row
    // cannot be written is undone. Attempts held back by the back-off are
    // not recorded (they check nothing, and would let a flood write rows).
    let actor = Actor {
        user: Some(user.to_string()),
        role: crate::Role::Viewer,
        addr: Some(addr),
    };
    let entry = |action| Entry {
        target: Some(user.to_string()),
        ..actor.entry(action)
    };
    let s = match st.auth.login(user, password, addr).await {
        Ok(s) => s,
        Err(e @ ApiError::Unauthorized(_)) => {
            audit::record(&st, entry(Action::LoginFailed), Outcome::Failed(e.to_string())).await?;
            return Err(e);
        }
        Err(e) => return Err(e),
    };
    if let Err(e) = audit::record(&st, entry(Action::Login), Outcome::Ok).await {
        st.auth.logout(&s.token);
        return Err(e);
    }
    let cookie = cookie(&s.token, st.https.load(Ordering::Relaxed));
    let reply = Login {
        token: s.token,
        user: s.user,
        role: s.role.into(),
    };
    Ok(([(header::SET_COOKIE, cookie)], Json(reply)).into_response())
}

/// Ends the request's session (if any) and clears the cookie: 204.
/// Audited (`logout`) when it ended a live session; the row is written
/// first, and if it cannot be the session stays open (500).
pub async fn logout(
    State(st): State<Arc<AppState>>,
    ConnectInfo(addr): ConnectInfo<SocketAddr>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    if let Some(t) = token(&headers) {
        if let Some((user, _)) = st.auth.session(&t) {
            let actor = Actor {
                user: Some(user.clone()),
                role: crate::Role::Viewer,
                addr: Some(addr),
            };
            let entry = Entry {
                target: Some(user),
                ..actor.entry(Action::Logout)
            };
            audit::record(&st, entry, Outcome::Ok).await?;
        }
        st.auth.logout(&t);
    }
    Ok((
        StatusCode::NO_CONTENT,
        [(header::SET_COOKIE, cleared_cookie(st.https.load(Ordering::Relaxed)))],
    )
        .into_response())
}

/// Who the request acts as.
pub async fn me(State(st): State<Arc<AppState>>, who: Who) -> Json<Me> {
    Json(Me {
        user: who.user,
        role: who.role.into(),
        users: st.auth.has_users(),
    })
}
