//! `POST /api/login`, `POST /api/logout`, `GET /api/me` (docs/api.md,
//! "Sessions"); the sessions themselves are `crate::auth`.

use super::{Body, body, field};
use crate::auth::{Who, token};
use crate::error::ApiError;
use crate::reply::{Login, Me};
use crate::state::AppState;
use axum::Json;
use axum::extract::{ConnectInfo, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};
use std::net::SocketAddr;
use std::sync::Arc;

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
    let s = st.auth.login(user, password, addr).await?;
    let cookie = st.auth.cookie(&s.token);
    let reply = Login {
        token: s.token,
        user: s.user,
        role: s.role.into(),
    };
    Ok(([(header::SET_COOKIE, cookie)], Json(reply)).into_response())
}

/// Ends the request's session (if any) and clears the cookie: 204.
pub async fn logout(State(st): State<Arc<AppState>>, headers: HeaderMap) -> Response {
    if let Some(t) = token(&headers) {
        st.auth.logout(&t);
    }
    (StatusCode::NO_CONTENT, [(header::SET_COOKIE, st.auth.cleared_cookie())]).into_response()
}

/// Who the request acts as.
pub async fn me(State(st): State<Arc<AppState>>, who: Who) -> Json<Me> {
    Json(Me {
        user: who.user,
        role: who.role.into(),
        users: st.auth.has_users(),
    })
}
