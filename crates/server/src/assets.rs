//! The studio, embedded at build time from `web/dist`, which build.rs builds
//! when it is stale (ADR 0013).

use axum::http::{HeaderMap, HeaderValue, StatusCode, Uri, header};
use axum::response::{IntoResponse, Response};

include!(concat!(env!("OUT_DIR"), "/assets.rs"));

fn mime(path: &str) -> &'static str {
    match path.rsplit('.').next().unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "svg" => "image/svg+xml",
        "json" => "application/json",
        "png" => "image/png",
        "ico" => "image/x-icon",
        "woff2" => "font/woff2",
        "txt" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

fn find(path: &str) -> Option<&'static [u8]> {
    ASSETS.iter().find(|(p, _)| *p == path).map(|(_, b)| *b)
}

/// The encodings a request accepts (`Accept-Encoding`, RFC 9110 §12.5.3):
/// whether `name` has a q-value above 0, by name or by `*`.
fn accepts(headers: &HeaderMap, name: &str) -> bool {
    let mut star = false;
    for item in headers
        .get_all(header::ACCEPT_ENCODING)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
    {
        let mut parts = item.split(';');
        let coding = parts.next().unwrap_or("").trim();
        let q = parts
            .find_map(|p| p.trim().strip_prefix("q=").or_else(|| p.trim().strip_prefix("Q=")))
            .map_or(1.0, |q| q.trim().parse::<f32>().unwrap_or(0.0));
        if coding.eq_ignore_ascii_case(name) {
            return q > 0.0;
        }
        if coding == "*" {
            star = q > 0.0;
        }
    }
    star
}

/// A file of the studio as the request accepts it: the build's brotli or
/// gzip copy (`file.br`, `file.gz`, written by vite.config.ts) when there is
/// one and the client takes it, else the file itself.
fn respond(path: &str, bytes: &'static [u8], headers: &HeaderMap, cache: &'static str) -> Response {
    let mut extra: Vec<(header::HeaderName, HeaderValue)> = vec![
        (header::CONTENT_TYPE, HeaderValue::from_static(mime(path))),
        (header::CACHE_CONTROL, HeaderValue::from_static(cache)),
    ];
    let mut body = bytes;
    let packed: Vec<(&'static str, &'static [u8])> = [("br", ".br"), ("gzip", ".gz")]
        .into_iter()
        .filter_map(|(coding, ext)| Some((coding, find(&format!("{path}{ext}"))?)))
        .collect();
    if !packed.is_empty() {
        extra.push((header::VARY, HeaderValue::from_static("Accept-Encoding")));
    }
    if let Some((coding, b)) = packed.into_iter().find(|(coding, _)| accepts(headers, coding)) {
        body = b;
        extra.push((header::CONTENT_ENCODING, HeaderValue::from_static(coding)));
    }
    let mut res = body.into_response();
    // insert, not extend: extend appends, and the body's own
    // `application/octet-stream` would stay beside the file's type
    for (name, value) in extra {
        res.headers_mut().insert(name, value);
    }
    res
}

/// Serves a file of the studio; any other path gets `index.html` (the
/// studio routes in the browser).
pub async fn serve(uri: Uri, headers: HeaderMap) -> Response {
    let path = uri.path().trim_start_matches('/');
    if let Some(bytes) = find(path).filter(|_| !path.is_empty()) {
        let cache = if path.starts_with("assets/") {
            "public, max-age=31536000, immutable"
        } else {
            "no-cache"
        };
        return respond(path, bytes, &headers, cache);
    }
    match find("index.html") {
        Some(index) => respond("index.html", index, &headers, "no-cache"),
        None => (
            StatusCode::SERVICE_UNAVAILABLE,
            [(header::CONTENT_TYPE, "text/plain; charset=utf-8")],
            "The studio was not built into this binary (npm was not found when it was built): \
             install Node.js and npm, then rebuild alba (./demo.sh does both). The API is at /api.\n",
        )
            .into_response(),
    }
}

#[cfg(test)]
mod tests {
    use super::accepts;
    use axum::http::{HeaderMap, HeaderValue, header};

    fn with(v: &str) -> HeaderMap {
        let mut h = HeaderMap::new();
        h.insert(header::ACCEPT_ENCODING, HeaderValue::from_str(v).expect("header"));
        h
    }

    #[test]
    fn accept_encoding_is_read_with_its_q_values() {
        assert!(accepts(&with("gzip, deflate, br, zstd"), "br"));
        assert!(accepts(&with("gzip"), "gzip"));
        assert!(!accepts(&with("gzip"), "br"));
        assert!(!accepts(&with("br;q=0, gzip;q=0.5"), "br"));
        assert!(accepts(&with("br;q=0, gzip;q=0.5"), "gzip"));
        assert!(accepts(&with("*"), "br"));
        assert!(!accepts(&with("*;q=0"), "gzip"));
        assert!(!accepts(&with("identity"), "gzip"));
        assert!(!accepts(&HeaderMap::new(), "gzip"));
        assert!(!accepts(&with("gzip;q=x"), "gzip"), "an unreadable q-value is 0");
    }
}
