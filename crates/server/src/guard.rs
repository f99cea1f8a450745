//! Browser attacks (docs/security.md, "Browser attacks and transport"):
//! one middleware in front of every route, the studio's files included.
//!
//! - `Host` must name this server: `localhost`, an IP literal, or a name of
//!   `[http] allowed_hosts` (DNS rebinding: a foreign name resolving to us).
//!   An IP literal cannot be a rebinding: the browser's origin is then that
//!   address, i.e. this server itself.
//! - State-changing requests (every method but GET, HEAD, OPTIONS) and the
//!   WebSocket handshake with an `Origin` must come from the studio's own
//!   origin (the `Origin` authority equals `Host`) or one of `[http]
//!   allowed_origins`; `null` is refused. A state-changing request without
//!   `Origin` (curl, scripts) is let through, since browsers always send one
//!   on such requests; the WebSocket handshake needs one.
//! - State-changing requests carry `Content-Type: application/json` (even
//!   when bodyless, as `POST /api/stop`): a page of another origin can only
//!   send that after a CORS preflight, which this server never approves.
//!   `PUT /api/tags.csv` and `PUT /api/recipes/{name}` may send `text/csv`,
//!   `PUT /api/assets/{name}` an image type or `application/octet-stream`
//!   (none CORS-safelisted either).
//! - Every answer carries CSP, `X-Content-Type-Options`, `X-Frame-Options`
//!   and `Referrer-Policy`.

use alba_settings::{Http, parse_origin, split_authority};
use axum::http::{HeaderMap, HeaderValue, Method, StatusCode, header};

/// What the guard lets in, from `[http]`.
#[derive(Debug, Clone, Default)]
pub struct Guard {
    /// Lowercase host names accepted besides `localhost` and IP literals.
    hosts: Vec<String>,
    /// Lowercase `scheme://host[:port]` accepted besides the request's own.
    origins: Vec<String>,
}

/// Why a request is refused: its status and message.
#[derive(Debug, PartialEq, Eq)]
pub struct Refusal(pub StatusCode, pub String);

impl Guard {
    pub fn new(http: &Http) -> Guard {
        Guard {
            hosts: http.allowed_hosts.clone(),
            origins: http.allowed_origins.clone(),
        }
    }

    /// Whether `host` (a `Host` header value) names this server.
    fn host_ok(&self, host: &str) -> bool {
        let Some((name, _)) = split_authority(host) else {
            return false;
        };
        let name = name.to_ascii_lowercase();
        name == "localhost"
            || name.parse::<std::net::Ipv4Addr>().is_ok()
            || (name.starts_with('[') && name[1..name.len() - 1].parse::<std::net::Ipv6Addr>().is_ok())
            || self.hosts.contains(&name)
    }

    /// Checks a request's method, path and headers; `Err` says why it is refused.
    pub fn admit(&self, method: &Method, path: &str, headers: &HeaderMap) -> Result<(), Refusal> {
        let text = |name: header::HeaderName| headers.get(name).map(|v| v.to_str().unwrap_or("\u{fffd}"));
        let Some(host) = text(header::HOST) else {
            return Err(Refusal(
                StatusCode::BAD_REQUEST,
                "the request has no `Host` header".into(),
            ));
        };
        if !self.host_ok(host) {
            return Err(Refusal(
                StatusCode::MISDIRECTED_REQUEST,
                format!(
                    "`Host: {host}` is not a name of this server: add it to `[http] allowed_hosts` in alba.toml to reach the studio by that name"
                ),
            ));
        }
        let websocket = path == "/api/ws"
            || headers
                .get(header::UPGRADE)
                .is_some_and(|v| v.as_bytes().eq_ignore_ascii_case(b"websocket"));
        let changes = !websocket && !matches!(*method, Method::GET | Method::HEAD | Method::OPTIONS);
        if !(websocket || changes) {
            return Ok(());
        }
        match text(header::ORIGIN) {
            Some(origin) => self.origin_ok(origin, host)?,
            None if websocket => {
                return Err(Refusal(
                    StatusCode::FORBIDDEN,
                    "the WebSocket handshake needs an `Origin` header".into(),
                ));
            }
            // Browsers send `Origin` on every such request; this one is not
            // from a browser, unless it says it is from another site.
            None => {
                if let Some(site) = text(header::HeaderName::from_static("sec-fetch-site"))
                    && !matches!(site, "same-origin" | "none")
                {
                    return Err(Refusal(
                        StatusCode::FORBIDDEN,
                        format!("a `{site}` request may not change anything"),
                    ));
                }
            }
        }
        if changes {
            let ctype = text(header::CONTENT_TYPE).unwrap_or("");
            let media = ctype.split(';').next().unwrap_or("").trim().to_ascii_lowercase();
            let put = *method == Method::PUT;
            let csv = put && media == "text/csv" && (path == "/api/tags.csv" || path.starts_with("/api/recipes/"));
            // None of these is CORS-safelisted: another origin needs a preflight.
            let image = put
                && path.starts_with("/api/assets/")
                && matches!(
                    media.as_str(),
                    "image/png" | "image/jpeg" | "image/gif" | "image/svg+xml" | "application/octet-stream"
                );
            if media != "application/json" && !csv && !image {
                let what = if ctype.is_empty() {
                    "it has none".to_string()
                } else {
                    format!("not `{ctype}`")
                };
                return Err(Refusal(
                    StatusCode::UNSUPPORTED_MEDIA_TYPE,
                    format!("a {method} request must be sent as `Content-Type: application/json` ({what})"),
                ));
            }
        }
        Ok(())
    }

    /// Whether `origin` is the request's own (its authority is `host`) or allowed.
    fn origin_ok(&self, origin: &str, host: &str) -> Result<(), Refusal> {
        let refuse = || {
            Err(Refusal(
                StatusCode::FORBIDDEN,
                format!(
                    "requests from `{origin}` are refused: only the studio's own origin and `[http] allowed_origins` may change anything or open the WebSocket"
                ),
            ))
        };
        let Some(o) = parse_origin(origin) else {
            return refuse();
        };
        let authority = o.split_once("://").map_or("", |(_, a)| a);
        if authority.eq_ignore_ascii_case(host) || self.origins.contains(&o) {
            Ok(())
        } else {
            refuse()
        }
    }
}

/// The security headers. `connect-src` names the WebSocket of the host the
/// page came from (checked by then, or refused and not a page).
pub(crate) fn secure(h: &mut HeaderMap, host: Option<&HeaderValue>) {
    let host = host
        .and_then(|h| h.to_str().ok())
        .filter(|h| split_authority(h).is_some());
    let connect = match host {
        Some(host) => format!("'self' ws://{host} wss://{host}"),
        None => "'self'".to_string(),
    };
    let csp = format!(
        "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; \
         connect-src {connect}; object-src 'none'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'"
    );
    // A handler's own policy stands (`GET /api/assets/{name}`: a stricter one).
    if let Ok(v) = HeaderValue::from_str(&csp)
        && !h.contains_key(header::CONTENT_SECURITY_POLICY)
    {
        h.insert(header::CONTENT_SECURITY_POLICY, v);
    }
    h.insert(header::X_CONTENT_TYPE_OPTIONS, HeaderValue::from_static("nosniff"));
    h.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    h.insert(header::REFERRER_POLICY, HeaderValue::from_static("no-referrer"));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(pairs: &[(&'static str, &str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.insert(*k, HeaderValue::from_str(v).expect("header"));
        }
        h
    }

    fn guard() -> Guard {
        Guard::new(&Http {
            allowed_hosts: vec!["plc1.plant.example".into()],
            allowed_origins: vec!["https://scada.example".into()],
            ..Http::default()
        })
    }

    #[test]
    fn hosts() {
        let g = guard();
        for ok in [
            "localhost",
            "LOCALHOST:8080",
            "127.0.0.1:8080",
            "[::1]:8080",
            "10.1.2.3",
            "plc1.plant.example:443",
        ] {
            assert_eq!(g.admit(&Method::GET, "/", &headers(&[("host", ok)])), Ok(()), "{ok}");
        }
        for bad in [
            "evil.example",
            "evil.example:8080",
            "localhost.evil.example",
            "127.0.0.1.nip.io",
            "",
            "a b",
        ] {
            let r = g.admit(&Method::GET, "/", &headers(&[("host", bad)]));
            assert_eq!(r.map_err(|e| e.0), Err(StatusCode::MISDIRECTED_REQUEST), "{bad}");
        }
        assert_eq!(
            g.admit(&Method::GET, "/", &HeaderMap::new()).map_err(|e| e.0),
            Err(StatusCode::BAD_REQUEST)
        );
    }

    #[test]
    fn origins_and_content_types() {
        let g = guard();
        let json = ("content-type", "application/json; charset=utf-8");
        let host = ("host", "127.0.0.1:8080");
        let post = |h: &[(&'static str, &str)]| g.admit(&Method::POST, "/api/stop", &headers(h)).map_err(|e| e.0);
        assert_eq!(post(&[host, json]), Ok(()), "no Origin: a script");
        assert_eq!(post(&[host, json, ("origin", "http://127.0.0.1:8080")]), Ok(()));
        assert_eq!(post(&[host, json, ("origin", "https://scada.example")]), Ok(()));
        for bad in [
            "http://evil.example",
            "null",
            "http://127.0.0.1:8081",
            "http://127.0.0.1:8080.evil.example",
            "https://scada.example:444",
            "nonsense",
        ] {
            assert_eq!(
                post(&[host, json, ("origin", bad)]),
                Err(StatusCode::FORBIDDEN),
                "{bad}"
            );
        }
        assert_eq!(
            post(&[host, json, ("sec-fetch-site", "cross-site")]),
            Err(StatusCode::FORBIDDEN)
        );
        for ctype in [
            "text/plain",
            "application/x-www-form-urlencoded",
            "multipart/form-data; boundary=x",
        ] {
            assert_eq!(
                post(&[host, ("content-type", ctype)]),
                Err(StatusCode::UNSUPPORTED_MEDIA_TYPE),
                "{ctype}"
            );
        }
        assert_eq!(post(&[host]), Err(StatusCode::UNSUPPORTED_MEDIA_TYPE));
        let csv = headers(&[host, ("content-type", "text/csv")]);
        assert_eq!(g.admit(&Method::PUT, "/api/tags.csv", &csv), Ok(()));
        assert!(g.admit(&Method::PUT, "/api/tags/X", &csv).is_err());
        assert!(g.admit(&Method::POST, "/api/tags.csv", &csv).is_err());
        // GETs need neither.
        let get = headers(&[host, ("origin", "http://evil.example")]);
        assert_eq!(g.admit(&Method::GET, "/api/status", &get), Ok(()));
    }

    #[test]
    fn websocket_needs_an_own_origin() {
        let g = guard();
        let ws = |origin: Option<&str>| {
            let mut h = headers(&[("host", "localhost:8080"), ("upgrade", "websocket")]);
            if let Some(o) = origin {
                h.insert("origin", HeaderValue::from_str(o).expect("origin"));
            }
            g.admit(&Method::GET, "/api/ws", &h).map_err(|e| e.0)
        };
        assert_eq!(ws(Some("http://localhost:8080")), Ok(()));
        assert_eq!(ws(Some("https://scada.example")), Ok(()));
        for bad in [
            None,
            Some("null"),
            Some("http://evil.example"),
            Some("http://localhost:9999"),
        ] {
            assert_eq!(ws(bad), Err(StatusCode::FORBIDDEN), "{bad:?}");
        }
    }
}
