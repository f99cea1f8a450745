//! `[modbus]`: the Modbus TCP server of `alba run` (its `[modbus.tags]` are
//! the project's: `alba_project::config::ModbusTag`).

use super::setting::{int_setting, listen};
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

/// `[modbus]`: the Modbus TCP server (docs/protocols.md).
#[derive(Debug, Clone, PartialEq)]
pub struct Modbus {
    /// Where to listen (`None`: only with `alba run --modbus`).
    pub listen: Option<std::net::SocketAddr>,
    /// Connections served at once; more are closed at once.
    pub max_connections: u32,
    /// A connection that sends no complete request for this long is closed; 0: never.
    pub idle_timeout_s: u32,
    /// Answer only this unit id (and 0 and 255); `None`: every unit id.
    pub unit_id: Option<u8>,
    /// `allow`: the client addresses served (`None`: every client of a
    /// loopback listener; a listener beyond loopback needs the list).
    pub allow: Option<Vec<IpRange>>,
    /// `read_only`: every write function code answers exception 01.
    pub read_only: bool,
}

/// Why a text is not an address or a CIDR range ([`IpRange::parse`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum IpRangeError {
    #[error("`{0}` is not an IP address or a CIDR range (like \"192.168.1.20\" or \"10.0.0.0/24\")")]
    NotAnAddress(String),
    #[error("`{text}`: the prefix length of an IPv{} range goes from 0 to {max}", if *max == 32 { 4 } else { 6 })]
    Prefix { text: String, max: u8 },
    #[error("`{text}` has bits set after its /{} prefix: the range is `{range}`", range.prefix)]
    HostBits { text: String, range: IpRange },
}

/// One entry of `[modbus] allow`: an address (`"192.168.1.20"`, `"::1"`)
/// or a CIDR range (`"10.0.0.0/24"`, `"fd00::/8"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IpRange {
    /// The network address (host bits cleared).
    pub net: std::net::IpAddr,
    /// Leading bits that must match (32 or 128: one address).
    pub prefix: u8,
}

impl IpRange {
    /// Parses `ADDR` or `ADDR/PREFIX`. A range whose address has host
    /// bits set (`10.0.0.5/24`) is refused: it is most likely a typo.
    pub fn parse(text: &str) -> Result<IpRange, IpRangeError> {
        let t = text.trim();
        let (a, p) = match t.split_once('/') {
            Some((a, p)) => (a, Some(p)),
            None => (t, None),
        };
        let addr: std::net::IpAddr = a.parse().map_err(|_| IpRangeError::NotAnAddress(t.to_string()))?;
        let max: u8 = if addr.is_ipv4() { 32 } else { 128 };
        let prefix = match p {
            None => max,
            Some(p) => match p.parse::<u8>() {
                Ok(n) if n <= max && p.bytes().all(|b| b.is_ascii_digit()) => n,
                _ => {
                    return Err(IpRangeError::Prefix {
                        text: t.to_string(),
                        max,
                    });
                }
            },
        };
        let r = IpRange { net: addr, prefix };
        if r.masked(addr) != addr {
            return Err(IpRangeError::HostBits {
                text: t.to_string(),
                range: IpRange {
                    net: r.masked(addr),
                    prefix,
                },
            });
        }
        Ok(r)
    }

    /// `ip` with the bits after the prefix cleared.
    fn masked(&self, ip: std::net::IpAddr) -> std::net::IpAddr {
        use std::net::IpAddr;
        match ip {
            IpAddr::V4(a) => {
                let m = u32::MAX.checked_shl(32 - u32::from(self.prefix)).unwrap_or(0);
                IpAddr::V4((u32::from(a) & m).into())
            }
            IpAddr::V6(a) => {
                let m = u128::MAX.checked_shl(128 - u32::from(self.prefix)).unwrap_or(0);
                IpAddr::V6((u128::from(a) & m).into())
            }
        }
    }

    /// Whether `ip` is in the range (an IPv4 client seen on an IPv6
    /// socket, `::ffff:a.b.c.d`, counts as its IPv4 address).
    pub fn contains(&self, ip: std::net::IpAddr) -> bool {
        let ip = ip.to_canonical();
        ip.is_ipv4() == self.net.is_ipv4() && self.masked(ip) == self.net
    }
}

impl std::fmt::Display for IpRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let max = if self.net.is_ipv4() { 32 } else { 128 };
        if self.prefix == max {
            write!(f, "{}", self.net)
        } else {
            write!(f, "{}/{}", self.net, self.prefix)
        }
    }
}

pub const DEFAULT_MODBUS_CONNECTIONS: u32 = 32;
pub const DEFAULT_MODBUS_IDLE_S: u32 = 60;

impl Default for Modbus {
    fn default() -> Modbus {
        Modbus {
            listen: None,
            max_connections: DEFAULT_MODBUS_CONNECTIONS,
            idle_timeout_s: DEFAULT_MODBUS_IDLE_S,
            unit_id: None,
            allow: None,
            read_only: false,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawModbus {
    listen: Option<Spanned<String>>,
    max_connections: Option<Spanned<i64>>,
    idle_timeout_s: Option<Spanned<i64>>,
    unit_id: Option<Spanned<i64>>,
    allow: Option<Spanned<Vec<Spanned<String>>>>,
    read_only: Option<bool>,
    /// `[modbus.tags]`: the project's (`alba_project::config::ModbusTag`).
    #[allow(dead_code)]
    tags: Option<serde::de::IgnoredAny>,
}

/// Validates `[modbus]`.
pub(super) fn modbus(m: RawModbus, file: FileId, diags: &mut Vec<Diagnostic>) -> Modbus {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let addr = m.listen.as_ref().and_then(|l| listen(l, file, diags));
    let allow = m.allow.map(|a| allow(a, file, diags));
    if let (Some(a), Some(l), None) = (addr, m.listen.as_ref(), &allow)
        && !a.ip().to_canonical().is_loopback()
    {
        diags.push(
            Diagnostic::new(
                Code::ModbusClients,
                format!("listen = \"{a}\" is not a loopback address, so it needs `allow`"),
                sp(l.span()),
                "Modbus TCP has no authentication: beyond loopback, only the clients of an allow-list are served",
            )
            .with_help("add `allow = [\"192.168.1.20\", \"10.0.0.0/24\"]` (the clients' addresses or ranges) to [modbus], or listen on 127.0.0.1"),
        );
    }
    let mut int =
        |key: &str, v: Option<Spanned<i64>>, range: std::ops::RangeInclusive<u32>, default: u32, unit: &str| {
            int_setting(key, v, range, default, unit, file, diags)
        };
    let mut out = Modbus {
        listen: addr,
        allow,
        read_only: m.read_only.unwrap_or(false),
        max_connections: int(
            "max_connections",
            m.max_connections,
            1..=4096,
            DEFAULT_MODBUS_CONNECTIONS,
            "connections",
        ),
        idle_timeout_s: int(
            "idle_timeout_s",
            m.idle_timeout_s,
            0..=86_400,
            DEFAULT_MODBUS_IDLE_S,
            "seconds",
        ),
        ..Modbus::default()
    };
    if m.unit_id.is_some() {
        out.unit_id = Some(int("unit_id", m.unit_id, 0..=255, 1, "(a unit id)") as u8);
    }
    out
}

/// Validates `[modbus] allow`: every entry an address or a CIDR range, the
/// list not empty (it would let no client in). Bad entries are left out.
fn allow(list: Spanned<Vec<Spanned<String>>>, file: FileId, diags: &mut Vec<Diagnostic>) -> Vec<IpRange> {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let span = list.span();
    let entries = list.into_inner();
    if entries.is_empty() {
        diags.push(
            Diagnostic::new(
                Code::ModbusClients,
                "allow = [] lets no client in",
                sp(span),
                "in [modbus]",
            )
            .with_help(
                "list the clients' addresses or ranges, or remove `allow` to serve every client of a loopback listener",
            ),
        );
    }
    let mut out = Vec::new();
    for e in entries {
        match IpRange::parse(e.get_ref()) {
            Ok(r) => out.push(r),
            Err(msg) => diags.push(
                Diagnostic::new(Code::ModbusClients, msg.to_string(), sp(e.span()), "in [modbus] allow").with_help(
                    "an IPv4 or IPv6 address, or a range written ADDRESS/PREFIX like \"10.0.0.0/24\" or \"fd00::/8\"",
                ),
            ),
        }
    }
    out
}
