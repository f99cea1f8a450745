//! `[http]`: the HTTP/WebSocket listener of `alba run` (docs/security.md,
//! "Browser attacks and transport").

use super::setting::int_setting;
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

/// `[http]`: who may reach the studio and its API, and how.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Http {
    /// Extra host names accepted in the `Host` header, lowercase, without a
    /// port (`localhost` and IP literals are always accepted): the names the
    /// studio is reached by, e.g. `plc1.plant.example`.
    pub allowed_hosts: Vec<String>,
    /// Extra origins (`scheme://host[:port]`, lowercase) accepted in the
    /// `Origin` header of state-changing requests and the WebSocket, besides
    /// the studio's own origin: e.g. a SCADA page served elsewhere.
    pub allowed_origins: Vec<String>,
    /// Serve plain HTTP on a non-loopback address (else HTTPS only there).
    pub insecure: bool,
    /// The TLS certificate chain (PEM) for HTTPS, relative to the project;
    /// `None`: a self-signed one made on first run in `.alba/tls/`.
    pub cert: Option<String>,
    /// The certificate's private key (PEM), with `cert`.
    pub key: Option<String>,
    /// Open HTTP connections at most; more are answered 503 and closed.
    pub max_connections: u32,
    /// Live (WebSocket) clients at most; more are closed with code 1013.
    pub max_ws_clients: u32,
    /// A request whose answer takes longer is answered 503.
    pub request_timeout_s: u32,
    /// A connection must send a whole request head within this time of
    /// opening or of its last answer (an idle keep-alive), else it is closed.
    pub header_timeout_s: u32,
}

pub const DEFAULT_MAX_CONNECTIONS: u32 = 256;
pub const DEFAULT_MAX_WS_CLIENTS: u32 = 64;
pub const DEFAULT_REQUEST_TIMEOUT_S: u32 = 30;
pub const DEFAULT_HEADER_TIMEOUT_S: u32 = 15;

impl Default for Http {
    fn default() -> Http {
        Http {
            allowed_hosts: Vec::new(),
            allowed_origins: Vec::new(),
            insecure: false,
            cert: None,
            key: None,
            max_connections: DEFAULT_MAX_CONNECTIONS,
            max_ws_clients: DEFAULT_MAX_WS_CLIENTS,
            request_timeout_s: DEFAULT_REQUEST_TIMEOUT_S,
            header_timeout_s: DEFAULT_HEADER_TIMEOUT_S,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawHttp {
    #[serde(default)]
    allowed_hosts: Vec<Spanned<String>>,
    #[serde(default)]
    allowed_origins: Vec<Spanned<String>>,
    insecure: Option<bool>,
    cert: Option<Spanned<String>>,
    key: Option<Spanned<String>>,
    max_connections: Option<Spanned<i64>>,
    max_ws_clients: Option<Spanned<i64>>,
    request_timeout_s: Option<Spanned<i64>>,
    header_timeout_s: Option<Spanned<i64>>,
}

/// Whether `s` is a host name: letters, digits, `-`, `.` (and `_`, seen in
/// private networks), not empty.
fn is_host_name(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 253
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '.' | '_'))
}

/// `s` as an origin `scheme://host[:port]` (lowercase, `http` or
/// `https`), if it is one.
pub fn parse_origin(s: &str) -> Option<String> {
    let s = s.trim().to_ascii_lowercase();
    let rest = s.strip_prefix("http://").or_else(|| s.strip_prefix("https://"))?;
    split_authority(rest)?;
    Some(s)
}

/// `host[:port]` split into the host (an IPv6 literal keeps its brackets)
/// and the port; `None` when it is not one.
pub fn split_authority(a: &str) -> Option<(&str, Option<u16>)> {
    let (host, port) = if a.starts_with('[') {
        let end = a.find(']')?;
        let (h, p) = a.split_at(end + 1);
        h[1..end].parse::<std::net::Ipv6Addr>().ok()?;
        (h, p)
    } else {
        match a.split_once(':') {
            Some((h, _)) => (h, &a[h.len()..]),
            None => (a, ""),
        }
    };
    let port = match port {
        "" => None,
        p => Some(p.strip_prefix(':')?.parse::<u16>().ok()?),
    };
    (host.starts_with('[') || is_host_name(host)).then_some((host, port))
}

/// Validates `[http]`.
pub(super) fn http(h: RawHttp, file: FileId, diags: &mut Vec<Diagnostic>) -> Http {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let mut out = Http {
        insecure: h.insecure.unwrap_or(false),
        ..Http::default()
    };
    for name in h.allowed_hosts {
        let n = name.get_ref().trim().to_ascii_lowercase();
        if is_host_name(&n) {
            out.allowed_hosts.push(n);
        } else {
            diags.push(
                Diagnostic::new(
                    Code::ConfigField,
                    format!("`{}` is not a host name", name.get_ref()),
                    sp(name.span()),
                    "not a host name",
                )
                .with_help("`allowed_hosts` lists bare names, without scheme or port: [\"plc1.plant.example\"]"),
            );
        }
    }
    for origin in h.allowed_origins {
        match parse_origin(origin.get_ref()) {
            Some(o) => out.allowed_origins.push(o),
            None => diags.push(
                Diagnostic::new(
                    Code::ConfigField,
                    format!("`{}` is not an origin", origin.get_ref()),
                    sp(origin.span()),
                    "not an origin",
                )
                .with_help("an origin is `scheme://host[:port]`: \"https://scada.plant.example:8443\""),
            ),
        }
    }
    match (h.cert, h.key) {
        (Some(c), Some(k)) => {
            out.cert = Some(c.into_inner());
            out.key = Some(k.into_inner());
        }
        (Some(one), None) | (None, Some(one)) => diags.push(Diagnostic::new(
            Code::ConfigField,
            "`[http]` needs both `cert` and `key`, or neither",
            sp(one.span()),
            "set alone",
        )),
        (None, None) => {}
    }
    out.max_connections = int_setting(
        "max_connections",
        h.max_connections,
        4..=100_000,
        DEFAULT_MAX_CONNECTIONS,
        "connections",
        file,
        diags,
    );
    out.max_ws_clients = int_setting(
        "max_ws_clients",
        h.max_ws_clients,
        1..=10_000,
        DEFAULT_MAX_WS_CLIENTS,
        "clients",
        file,
        diags,
    );
    out.request_timeout_s = int_setting(
        "request_timeout_s",
        h.request_timeout_s,
        1..=3_600,
        DEFAULT_REQUEST_TIMEOUT_S,
        "seconds",
        file,
        diags,
    );
    out.header_timeout_s = int_setting(
        "header_timeout_s",
        h.header_timeout_s,
        1..=3_600,
        DEFAULT_HEADER_TIMEOUT_S,
        "seconds",
        file,
        diags,
    );
    out
}
