//! `POST /api/verify` and `POST /api/tests` (docs/api.md "Verify and test"):
//! the saved project's properties decided and its test tables run. The work
//! is alba-app's ([`crate::verify::Verifier`]); here: the request, one run
//! at a time per project (`429`), a thread of its own at the lowest priority.

use super::nets::lowest_priority;
use crate::error::{ApiError, ApiResult};
use crate::project::EditError;
use crate::reply::{TestsReply, VerifyReply};
use crate::state::AppState;
use crate::verify::{PROPERTY_SECONDS, Verifier, VerifyError};
use axum::Json;
use axum::body::Bytes;
use axum::extract::State;
use serde::Deserialize;
use std::sync::Arc;

impl From<VerifyError> for ApiError {
    fn from(e: VerifyError) -> ApiError {
        match e {
            VerifyError::DoesNotCheck(diagnostics) => ApiError::Edit(EditError::DoesNotCompile { diagnostics }),
            VerifyError::NotFound(m) => ApiError::NotFound(m),
            VerifyError::Failed(m) => ApiError::Internal(m),
        }
    }
}

/// `POST /api/verify`'s body (optional).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Request {
    /// Only the property with this name.
    property: Option<String>,
    /// Seconds per property, 1 to [`PROPERTY_SECONDS`] (the default).
    time_limit_s: Option<u64>,
}

fn service(st: &AppState) -> ApiResult<Arc<dyn Verifier>> {
    st.verifier
        .get()
        .cloned()
        .ok_or_else(|| ApiError::NotFound("this server has no verification service".into()))
}

/// Runs `f` on a thread of its own at the lowest priority, holding the
/// project's analysis permit until it has ended.
async fn exclusive<T: Send + 'static>(
    st: &AppState,
    f: impl FnOnce() -> Result<T, VerifyError> + Send + 'static,
) -> ApiResult<T> {
    let permit = st.analysis.clone().try_acquire_owned().map_err(|_| {
        ApiError::Busy("a verification, test run or analysis of this project is running: wait for it to end".into())
    })?;
    let (tx, rx) = tokio::sync::oneshot::channel();
    std::thread::Builder::new()
        .name("verify".into())
        .spawn(move || {
            lowest_priority();
            let r = f();
            drop(permit);
            let _ = tx.send(r);
        })
        .map_err(|e| ApiError::Internal(format!("cannot start the verification: {e}")))?;
    rx.await
        .map_err(|_| ApiError::Internal("the verification stopped".into()))?
        .map_err(ApiError::from)
}

/// `POST /api/verify` `{"property"?, "time_limit_s"?}`.
pub async fn verify(State(st): State<Arc<AppState>>, body: Bytes) -> ApiResult<Json<VerifyReply>> {
    let req: Request = if body.iter().all(u8::is_ascii_whitespace) {
        Request::default()
    } else {
        serde_json::from_slice(&body).map_err(|e| ApiError::Malformed(format!("the verify request: {e}")))?
    };
    let seconds = match req.time_limit_s {
        None => PROPERTY_SECONDS,
        Some(n @ 1..=PROPERTY_SECONDS) => n,
        Some(n) => {
            return Err(ApiError::Invalid(format!(
                "`time_limit_s` is 1 to {PROPERTY_SECONDS}, not `{n}`"
            )));
        }
    };
    let v = service(&st)?;
    Ok(Json(
        exclusive(&st, move || v.verify(req.property.as_deref(), seconds)).await?,
    ))
}

/// `POST /api/tests`.
pub async fn tests(State(st): State<Arc<AppState>>) -> ApiResult<Json<TestsReply>> {
    let v = service(&st)?;
    Ok(Json(exclusive(&st, move || v.tests()).await?))
}
