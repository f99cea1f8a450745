//! The language of a request (issue 34 point 11): the `language` middleware
//! reads `Accept-Language` and serves the request inside a task-local, which
//! [`crate::project::diagnostic_json`] reads to word diagnostics and
//! [`worded`] to word the error reply's `error`. A leaf module: it depends on
//! nothing of the server.

use axum::extract::Request;
use axum::middleware::Next;
use axum::response::Response;

tokio::task_local! {
    /// The language of the request being served (issue 34 point 11).
    static LANG: alba_compiler::diag::Lang;
}

/// The language of the request this task serves: its `Accept-Language`
/// (English without one, or outside a request).
pub fn request_lang() -> alba_compiler::diag::Lang {
    LANG.try_with(|l| *l).unwrap_or_default()
}

/// Serves the request in the language of its `Accept-Language` header: the
/// diagnostics of its answer ([`crate::project::diagnostic_json`]) are
/// worded in it. Answers say `Vary: Accept-Language`.
pub async fn language(req: Request, next: Next) -> Response {
    let lang = req
        .headers()
        .get(axum::http::header::ACCEPT_LANGUAGE)
        .and_then(|v| v.to_str().ok())
        .map_or(
            alba_compiler::diag::Lang::En,
            alba_compiler::diag::Lang::from_accept_language,
        );
    let mut res = LANG.scope(lang, next.run(req)).await;
    res.headers_mut().append(
        axum::http::header::VARY,
        axum::http::HeaderValue::from_static("accept-language"),
    );
    res
}

/// An error reply's text in the language of the request: in Spanish by the
/// diagnostics' catalogue (`alba_diag::es::error`: the API's errors, and the
/// diagnostic messages an error echoes), else as the server wrote it.
pub fn worded(text: String) -> String {
    match request_lang() {
        alba_compiler::diag::Lang::Es => alba_compiler::diag::es::error(&text).unwrap_or(text),
        alba_compiler::diag::Lang::En => text,
    }
}

/// A label or note in `lang`: in Spanish by the phrase book
/// (`alba_diag::es::phrase`), else as written.
pub fn phrased(lang: alba_compiler::diag::Lang, text: &str) -> String {
    match lang {
        alba_compiler::diag::Lang::Es => alba_compiler::diag::es::phrase(text).unwrap_or_else(|| text.to_string()),
        alba_compiler::diag::Lang::En => text.to_string(),
    }
}
