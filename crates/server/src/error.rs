//! API errors and the one function that maps them to HTTP statuses (the
//! table of docs/api.md, "Errors").

use crate::project::EditError;
use crate::reply::ErrorReply;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};

/// Why a request failed. The body is always `{"error": message}` (with
/// `diagnostics` for an edit that does not compile), both in the request's
/// language (`Accept-Language`, [`crate::lang`]).
#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    /// The request itself is malformed: bad JSON, a missing field, a bad query.
    #[error("{0}")]
    Malformed(String),
    /// No such tag, program, force or endpoint.
    #[error("{0}")]
    NotFound(String),
    /// A value or request the target refuses (wrong type, out of range, read-only).
    #[error("{0}")]
    Invalid(String),
    #[error("the request body is too large")]
    TooLarge,
    /// A request to the runtime.
    #[error(transparent)]
    Runtime(#[from] alba_control::runtime::Error),
    /// Checking, saving or applying a project edit.
    #[error(transparent)]
    Edit(#[from] EditError),
    /// A query of the historian.
    #[error("{}", history_message(.0))]
    History(#[from] alba_control::history::Error),
    /// History is off for this project.
    #[error("history is off for this project (`[history] enabled = false` in alba.toml)")]
    HistoryOff,
    /// The audit row of a state-changing request could not be written: the action was
    /// not performed (docs/audit.md, "No acknowledged action without its row").
    #[error("not done: the audit trail cannot be written ({0})")]
    AuditWrite(alba_control::audit::Error),
    /// A query or export of the audit trail.
    #[error("{}", audit_message(.0))]
    Audit(alba_control::audit::Error),
    /// The server runs without an audit trail (only when embedded without one).
    #[error("this server keeps no audit trail")]
    AuditOff,
    /// No session, or one that ended, where the route needs one; a failed login.
    #[error("{0}")]
    Unauthorized(String),
    /// The session's role is too small for the route, or (no users) a
    /// client that is not on loopback.
    #[error("{0}")]
    Forbidden(String),
    /// Too many failed logins for this user or client address: retry after the duration.
    #[error("too many failed logins: try again in {} s", retry_after_s(.0))]
    TooManyAttempts(std::time::Duration),
    /// An alarm action refused, or its log row not written.
    #[error(transparent)]
    Alarm(#[from] alba_control::alarms::HubError),
    /// A remote server `alba run` is a client of (`[[opcua_server]]`) cannot
    /// be reached or refused the request.
    #[error("{0}")]
    Upstream(String),
    /// A resource that serves one request at a time is taken (a net analysis).
    #[error("{0}")]
    Busy(String),
    /// The request does not fit the state it finds (a board already
    /// attached, none to detach).
    #[error("{0}")]
    Conflict(String),
    /// A fault of the server (a task that did not finish).
    #[error("{0}")]
    Internal(String),
    /// The answer took longer than `[http] request_timeout_s`.
    #[error("the request took longer than {} s: try again, or raise [http] request_timeout_s", .0.as_secs())]
    TimedOut(std::time::Duration),
}

/// The control layer's refusals, as the API has always answered them: an
/// unknown tag, alarm or force 404, a role too small 403, a value or tag
/// refused 422, an audit row not written 500 (docs/api.md, "Errors").
impl From<alba_control::Refused> for ApiError {
    fn from(r: alba_control::Refused) -> ApiError {
        use alba_control::Refused as R;
        match r {
            R::UnknownTag(m) | R::NotForced(m) | R::UnknownAlarm(m) => ApiError::NotFound(m),
            R::NotWritable(m) | R::WrongType(m) | R::OutOfRange(m) | R::NotForceable(m) => ApiError::Invalid(m),
            e @ R::Role { .. } => ApiError::Forbidden(e.to_string()),
            R::AuditUnavailable(e) => ApiError::AuditWrite(e),
            R::Runtime(e) => ApiError::Runtime(e),
            R::NotApplied(e) => ApiError::Edit(EditError::NotApplied(e)),
            R::Alarm(e) => ApiError::Alarm(e),
            R::Internal(m) => ApiError::Internal(m),
        }
    }
}

/// The HTTP status of an error: the only place where errors meet statuses.
pub fn status(e: &ApiError) -> StatusCode {
    use alba_control::history::Error as H;
    use alba_control::runtime::Error as R;
    match e {
        ApiError::Malformed(_) => StatusCode::BAD_REQUEST,
        ApiError::NotFound(_) | ApiError::HistoryOff | ApiError::AuditOff => StatusCode::NOT_FOUND,
        ApiError::Invalid(_) => StatusCode::UNPROCESSABLE_ENTITY,
        ApiError::TooLarge => StatusCode::PAYLOAD_TOO_LARGE,
        ApiError::TimedOut(_) => StatusCode::SERVICE_UNAVAILABLE,
        ApiError::Upstream(_) => StatusCode::BAD_GATEWAY,
        ApiError::Unauthorized(_) => StatusCode::UNAUTHORIZED,
        ApiError::Forbidden(_) => StatusCode::FORBIDDEN,
        ApiError::TooManyAttempts(_) | ApiError::Busy(_) => StatusCode::TOO_MANY_REQUESTS,
        ApiError::Conflict(_) => StatusCode::CONFLICT,
        ApiError::Runtime(r) | ApiError::Edit(EditError::NotApplied(r)) => match r {
            R::Stopped | R::Io { .. } | R::Busy => StatusCode::SERVICE_UNAVAILABLE,
            R::Attached { .. } | R::Running | R::Faulted(_) => StatusCode::CONFLICT,
            R::Rejected(_) => StatusCode::UNPROCESSABLE_ENTITY,
        },
        ApiError::Edit(EditError::UnknownProgram(_) | EditError::NoTagsFile) => StatusCode::NOT_FOUND,
        ApiError::Edit(EditError::DoesNotCompile { .. }) => StatusCode::UNPROCESSABLE_ENTITY,
        ApiError::Edit(EditError::Save { .. }) | ApiError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
        ApiError::AuditWrite(_) => StatusCode::INTERNAL_SERVER_ERROR,
        ApiError::Audit(a) => match a {
            alba_control::audit::Error::InvalidArgument(_) => StatusCode::UNPROCESSABLE_ENTITY,
            _ => StatusCode::INTERNAL_SERVER_ERROR,
        },
        ApiError::Alarm(a) => match a {
            alba_control::alarms::HubError::Action(alba_control::alarms::ActionError::Unknown(_)) => {
                StatusCode::NOT_FOUND
            }
            alba_control::alarms::HubError::Action(alba_control::alarms::ActionError::Invalid(_)) => {
                StatusCode::UNPROCESSABLE_ENTITY
            }
            alba_control::alarms::HubError::Action(_) => StatusCode::CONFLICT,
            alba_control::alarms::HubError::Log(_) => StatusCode::INTERNAL_SERVER_ERROR,
        },
        ApiError::History(h) => match h {
            H::UnknownTag(_) | H::UnknownNode(_) => StatusCode::NOT_FOUND,
            // The shared database cannot be reached (not a statement it refused).
            H::Postgres(e) if e.as_db_error().is_none() => StatusCode::SERVICE_UNAVAILABLE,
            H::InvalidArgument(_) => StatusCode::UNPROCESSABLE_ENTITY,
            _ => StatusCode::INTERNAL_SERVER_ERROR,
        },
    }
}

/// Whole seconds to wait, rounded up (`Retry-After`).
fn retry_after_s(d: &std::time::Duration) -> u64 {
    d.as_secs() + u64::from(d.subsec_nanos() > 0)
}

fn history_message(e: &alba_control::history::Error) -> String {
    match e {
        alba_control::history::Error::UnknownTag(t) => format!("no history for `{t}`"),
        alba_control::history::Error::UnknownNode(n) => format!("no history for node `{n}`"),
        alba_control::history::Error::InvalidArgument(m) => m.clone(),
        e => e.to_string(),
    }
}

fn audit_message(e: &alba_control::audit::Error) -> String {
    match e {
        alba_control::audit::Error::InvalidArgument(m) => m.clone(),
        e => e.to_string(),
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let diagnostics = match &self {
            ApiError::Edit(EditError::DoesNotCompile { diagnostics }) => Some(diagnostics.clone()),
            _ => None,
        };
        let body = ErrorReply {
            error: crate::lang::worded(self.to_string()),
            diagnostics,
        };
        let mut headers = axum::http::HeaderMap::new();
        match &self {
            ApiError::Unauthorized(_) => {
                headers.insert(
                    axum::http::header::WWW_AUTHENTICATE,
                    axum::http::HeaderValue::from_static("Bearer realm=\"alba\""),
                );
            }
            ApiError::TooManyAttempts(d) => {
                headers.insert(
                    axum::http::header::RETRY_AFTER,
                    axum::http::HeaderValue::from(retry_after_s(d)),
                );
            }
            _ => {}
        }
        (status(&self), headers, axum::Json(body)).into_response()
    }
}

pub type ApiResult<T> = Result<T, ApiError>;

#[cfg(test)]
mod tests {
    use super::*;
    use alba_control::runtime::Error as R;

    /// The cases the API tests cannot provoke with a simulated project.
    #[test]
    fn statuses_of_runtime_edit_and_history_errors() {
        let io = R::Io {
            io: "board:x".into(),
            source: alba_control::runtime::IoError::LinkStopped,
        };
        let cases = [
            (ApiError::Runtime(io.clone()), StatusCode::SERVICE_UNAVAILABLE),
            (
                ApiError::Edit(EditError::NotApplied(io)),
                StatusCode::SERVICE_UNAVAILABLE,
            ),
            (
                ApiError::Runtime(R::Rejected("no".into())),
                StatusCode::UNPROCESSABLE_ENTITY,
            ),
            (
                ApiError::Edit(EditError::NotApplied(R::Stopped)),
                StatusCode::SERVICE_UNAVAILABLE,
            ),
            (ApiError::Edit(EditError::NoTagsFile), StatusCode::NOT_FOUND),
            (
                ApiError::Edit(EditError::Save {
                    path: "main.lad".into(),
                    source: std::io::Error::other("disk full"),
                }),
                StatusCode::INTERNAL_SERVER_ERROR,
            ),
            (
                ApiError::History(alba_control::history::Error::UnknownTag("X".into())),
                StatusCode::NOT_FOUND,
            ),
            (
                ApiError::History(alba_control::history::Error::InvalidArgument("points".into())),
                StatusCode::UNPROCESSABLE_ENTITY,
            ),
            (ApiError::HistoryOff, StatusCode::NOT_FOUND),
            (
                ApiError::AuditWrite(alba_control::audit::Error::Io(std::io::Error::other("disk full"))),
                StatusCode::INTERNAL_SERVER_ERROR,
            ),
            (
                ApiError::Audit(alba_control::audit::Error::InvalidArgument("limit".into())),
                StatusCode::UNPROCESSABLE_ENTITY,
            ),
            (ApiError::AuditOff, StatusCode::NOT_FOUND),
            (ApiError::Upstream("cannot connect".into()), StatusCode::BAD_GATEWAY),
            (ApiError::Runtime(R::Running), StatusCode::CONFLICT),
            (ApiError::Runtime(R::Faulted("watchdog".into())), StatusCode::CONFLICT),
        ];
        for (e, want) in cases {
            assert_eq!(status(&e), want, "{e}");
        }
    }

    /// The session errors' statuses and headers (end to end: tests/it/roles.rs).
    #[test]
    fn session_errors_carry_their_headers() {
        use axum::http::header::{RETRY_AFTER, WWW_AUTHENTICATE};
        let r = ApiError::TooManyAttempts(std::time::Duration::from_millis(1200)).into_response();
        assert_eq!(r.status(), StatusCode::TOO_MANY_REQUESTS);
        assert_eq!(
            r.headers().get(RETRY_AFTER).map(|v| v.as_bytes()),
            Some(&b"2"[..]),
            "rounded up"
        );
        let r = ApiError::Unauthorized("log in".into()).into_response();
        assert_eq!(r.status(), StatusCode::UNAUTHORIZED);
        assert!(r.headers().contains_key(WWW_AUTHENTICATE));
        let r = ApiError::Forbidden("no".into()).into_response();
        assert_eq!(r.status(), StatusCode::FORBIDDEN);
        assert!(!r.headers().contains_key(WWW_AUTHENTICATE));
    }
}
