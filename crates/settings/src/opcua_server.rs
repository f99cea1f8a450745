//! `[[opcua_server]]`: remote OPC UA servers whose variables are bound to
//! tags (Alba as an OPC UA client, docs/protocols.md "OPC UA client I/O").

use super::setting::int_setting;
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

/// The security policies the client offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SecurityPolicy {
    None,
    Basic256Sha256,
    Aes128Sha256RsaOaep,
    Aes256Sha256RsaPss,
}

impl SecurityPolicy {
    pub const ALL: [(&'static str, SecurityPolicy); 4] = [
        ("None", SecurityPolicy::None),
        ("Basic256Sha256", SecurityPolicy::Basic256Sha256),
        ("Aes128_Sha256_RsaOaep", SecurityPolicy::Aes128Sha256RsaOaep),
        ("Aes256_Sha256_RsaPss", SecurityPolicy::Aes256Sha256RsaPss),
    ];

    /// The name used in alba.toml (the policy URI's last part).
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(_, p)| *p == self).map_or("None", |(n, _)| n)
    }
}

/// `security_mode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SecurityMode {
    None,
    Sign,
    SignAndEncrypt,
}

/// Which way a binding's value goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// The node's value feeds the tag (a monitored item).
    In,
    /// The tag's value is written to the node when it changes.
    Out,
}

/// One `bind` entry: a tag and a node id (`ns=2;s=Tank.Level`, `i=…`,
/// `nsu=urn:…;s=…`).
#[derive(Debug, Clone, PartialEq)]
pub struct OpcuaBinding {
    pub tag: String,
    pub node: String,
    pub dir: Direction,
    pub span: Span,
}

/// `[[opcua_server]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct OpcuaServer {
    pub name: String,
    /// `opc.tcp://host:port/path`.
    pub endpoint: String,
    pub policy: SecurityPolicy,
    pub mode: SecurityMode,
    /// User name and the file (relative to the project) holding the password.
    pub user: Option<(String, String)>,
    /// The client's PKI folder (own certificate, trusted/ and rejected/
    /// server certificates), relative to the project; default `.alba/pki-client`.
    pub pki_dir: String,
    pub publishing_interval_ms: u32,
    pub bindings: Vec<OpcuaBinding>,
    pub span: Span,
}

pub const DEFAULT_PUBLISHING_INTERVAL_MS: u32 = 100;
pub const DEFAULT_CLIENT_PKI: &str = ".alba/pki-client";

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawServer {
    name: Spanned<String>,
    endpoint: Spanned<String>,
    security_policy: Option<Spanned<String>>,
    security_mode: Option<Spanned<String>>,
    user: Option<Spanned<String>>,
    password_file: Option<Spanned<String>>,
    pki_dir: Option<Spanned<String>>,
    publishing_interval_ms: Option<Spanned<i64>>,
    #[serde(default)]
    bind: Vec<Spanned<RawBinding>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBinding {
    tag: Spanned<String>,
    node: Spanned<String>,
    dir: Spanned<String>,
}

/// Whether `s` looks like an OPC UA node id: `[ns=N;|nsu=URI;]` then
/// `i=N`, `s=…`, `g=…` or `b=…`.
pub fn is_node_id(s: &str) -> bool {
    let rest = if let Some(r) = s.strip_prefix("ns=") {
        match r.split_once(';') {
            Some((n, rest)) if n.parse::<u16>().is_ok() => rest,
            _ => return false,
        }
    } else if let Some(r) = s.strip_prefix("nsu=") {
        match r.split_once(';') {
            Some((u, rest)) if !u.is_empty() => rest,
            _ => return false,
        }
    } else {
        s
    };
    match rest.split_at_checked(2) {
        Some(("i=", n)) => n.parse::<u32>().is_ok(),
        Some(("s=" | "g=" | "b=", v)) => !v.is_empty(),
        _ => false,
    }
}

/// Validates the `[[opcua_server]]` tables (tags are checked against the
/// program by `alba check`/`alba run`, which know the tags).
pub(super) fn servers(raw: Vec<Spanned<RawServer>>, file: FileId, diags: &mut Vec<Diagnostic>) -> Vec<OpcuaServer> {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let mut out: Vec<OpcuaServer> = Vec::new();
    // Tags already fed by an input binding.
    let mut fed: std::collections::HashMap<String, String> = Default::default();
    for s in raw {
        let span = sp(s.span());
        let s = s.into_inner();
        let bad = |msg: String, at: std::ops::Range<usize>, label: &str| {
            Diagnostic::new(Code::ConfigField, msg, sp(at), label.to_string())
        };
        let name = s.name.get_ref().trim().to_string();
        if name.is_empty() || out.iter().any(|o| o.name == name) {
            diags.push(bad(
                if name.is_empty() {
                    "the OPC UA server name is empty".to_string()
                } else {
                    format!("two OPC UA servers are named `{name}`")
                },
                s.name.span(),
                "a server needs a name of its own",
            ));
        }
        let endpoint = s.endpoint.get_ref().trim().to_string();
        let host_ok = endpoint
            .strip_prefix("opc.tcp://")
            .and_then(|r| r.split('/').next())
            .is_some_and(|hp| {
                !hp.is_empty()
                    && hp
                        .rsplit_once(':')
                        .is_none_or(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok_and(|p| p > 0))
            });
        if !host_ok {
            diags.push(bad(
                format!("endpoint = \"{endpoint}\" is not an OPC UA address"),
                s.endpoint.span(),
                "expected opc.tcp://HOST:PORT/…, like \"opc.tcp://192.168.1.30:4840/\"",
            ));
        }
        let policy = match &s.security_policy {
            None => SecurityPolicy::None,
            Some(p) => match SecurityPolicy::ALL.iter().find(|(n, _)| n == p.get_ref()) {
                Some((_, p)) => *p,
                None => {
                    diags.push(bad(
                        format!("security_policy = \"{}\" is not known", p.get_ref()),
                        p.span(),
                        "expected None, Basic256Sha256, Aes128_Sha256_RsaOaep or Aes256_Sha256_RsaPss",
                    ));
                    SecurityPolicy::None
                }
            },
        };
        let mode = match &s.security_mode {
            None if policy == SecurityPolicy::None => SecurityMode::None,
            None => SecurityMode::SignAndEncrypt,
            Some(m) => match m.get_ref().as_str() {
                "None" => SecurityMode::None,
                "Sign" => SecurityMode::Sign,
                "SignAndEncrypt" => SecurityMode::SignAndEncrypt,
                other => {
                    diags.push(bad(
                        format!("security_mode = \"{other}\" is not known"),
                        m.span(),
                        "expected None, Sign or SignAndEncrypt",
                    ));
                    SecurityMode::None
                }
            },
        };
        if (policy == SecurityPolicy::None) != (mode == SecurityMode::None) {
            let at = s
                .security_mode
                .as_ref()
                .or(s.security_policy.as_ref())
                .map_or(s.name.span(), |x| x.span());
            diags.push(bad(
                format!(
                    "security_policy {} does not go with security_mode {mode:?}",
                    policy.name()
                ),
                at,
                "policy None takes mode None; a secure policy takes Sign or SignAndEncrypt",
            ));
        }
        let user = match (&s.user, &s.password_file) {
            (None, None) => None,
            (Some(u), Some(f)) if !u.get_ref().is_empty() && !f.get_ref().is_empty() => {
                Some((u.get_ref().clone(), f.get_ref().clone()))
            }
            (u, f) => {
                let at = u.as_ref().or(f.as_ref()).map_or(s.name.span(), |x| x.span());
                diags.push(bad(
                    "`user` and `password_file` go together".to_string(),
                    at,
                    "a user name and the file holding its password (never the password itself)",
                ));
                None
            }
        };
        let publishing_interval_ms = int_setting(
            "publishing_interval_ms",
            s.publishing_interval_ms,
            10..=3_600_000,
            DEFAULT_PUBLISHING_INTERVAL_MS,
            "milliseconds",
            file,
            diags,
        );
        let mut bindings = Vec::new();
        for b in s.bind {
            let bspan = sp(b.span());
            let b = b.into_inner();
            let dir = match b.dir.get_ref().as_str() {
                "in" => Direction::In,
                "out" => Direction::Out,
                other => {
                    diags.push(bad(
                        format!("dir = \"{other}\" is not a direction"),
                        b.dir.span(),
                        "expected \"in\" (the node feeds the tag) or \"out\" (the tag is written to the node)",
                    ));
                    continue;
                }
            };
            let node = b.node.get_ref().trim().to_string();
            if !is_node_id(&node) {
                diags.push(bad(
                    format!("`{node}` is not a node id"),
                    b.node.span(),
                    "expected a node id like \"ns=2;s=Tank.Level\" or \"ns=3;i=1001\"",
                ));
                continue;
            }
            let tag = b.tag.get_ref().trim().to_string();
            if tag.is_empty() {
                diags.push(bad("the tag is empty".into(), b.tag.span(), "a tag of tags.csv"));
                continue;
            }
            if dir == Direction::In {
                if let Some(owner) = fed.get(&tag) {
                    diags.push(bad(
                        format!("tag `{tag}` is already fed by server `{owner}`"),
                        b.tag.span(),
                        "a tag has one source",
                    ));
                    continue;
                }
                fed.insert(tag.clone(), name.clone());
            }
            bindings.push(OpcuaBinding {
                tag,
                node,
                dir,
                span: bspan,
            });
        }
        out.push(OpcuaServer {
            name,
            endpoint,
            policy,
            mode,
            user,
            pki_dir: s
                .pki_dir
                .map_or_else(|| DEFAULT_CLIENT_PKI.to_string(), |p| p.into_inner()),
            publishing_interval_ms,
            bindings,
            span,
        });
    }
    out
}
