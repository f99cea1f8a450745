//! `[mqtt]`: the MQTT client of `alba run` (docs/scale-out.md).

use super::setting::int_setting;
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

/// `[mqtt]`: publish tags to a broker and take writes from it.
#[derive(Debug, Clone, PartialEq)]
pub struct Mqtt {
    /// `host:port` of the broker (`alba run --mqtt` overrides it).
    pub broker: Option<String>,
    /// The MQTT protocol version: 3.1.1 (default) or 5.
    pub version: MqttVersion,
    /// Default `alba-<project name>`.
    pub client_id: Option<String>,
    /// Default `alba/<project name>`.
    pub topic_prefix: Option<String>,
    /// 0, 1 (default) or 2.
    pub qos: u8,
    pub keep_alive_s: u32,
    /// Tags (and members) to publish; empty: every tag.
    pub tags: Vec<String>,
    /// Changes are published at most this often (ms; 0: every snapshot).
    pub publish_interval_ms: u32,
    /// A REAL or LREAL is published when it moved more than this from the
    /// value last published (0: any change).
    pub deadband: f64,
    /// A broker account that is not a project user (audited as `mqtt`).
    pub username: Option<String>,
    /// A user of the project's users.toml: Alba logs in to the broker as
    /// this name, and writes from MQTT act with its role and name.
    pub user: Option<String>,
    /// A file holding the broker password (never in alba.toml, never echoed).
    pub password_file: Option<String>,
    /// Messages waiting for the broker at most; more are dropped (counted).
    pub queue: u32,
    /// Take writes from `<prefix>/set/<Tag>` (default true; the broker's ACL
    /// decides who may publish there).
    pub writes: bool,
    /// TLS to the broker: the CA that signed its certificate (PEM).
    pub ca_file: Option<String>,
    /// Mutual TLS: this client's certificate and key (PEM).
    pub client_cert: Option<String>,
    pub client_key: Option<String>,
    /// Sparkplug B instead of JSON: group, edge node and device ids.
    pub sparkplug: Option<Sparkplug>,
}

/// `[mqtt] version`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MqttVersion {
    /// `"3.1.1"` (or `4`, its protocol level).
    #[default]
    V311,
    /// `5` (or `"5"`, `"5.0"`).
    V5,
}

/// `[mqtt.sparkplug]`: publish as a Sparkplug B edge node.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sparkplug {
    /// Default `alba`.
    pub group_id: String,
    /// Default: the project's name.
    pub edge_node_id: Option<String>,
    /// The device that holds the tags `devices` does not place; default `plc`.
    pub device_id: String,
    /// Devices of their own: device id → the tags (and members) it holds.
    pub devices: Vec<(String, Vec<String>)>,
    /// The Sparkplug host id of the primary host application: publish only
    /// while its `STATE` says online, buffering on disk meanwhile.
    pub primary_host_id: Option<String>,
    /// Records (one per snapshot with changes) the store-and-forward buffer
    /// holds at most; past it the oldest are dropped (counted).
    pub buffer_max: u32,
}

pub const DEFAULT_BUFFER_MAX: u32 = 1_000_000;

pub const DEFAULT_KEEP_ALIVE_S: u32 = 30;
pub const DEFAULT_QUEUE: u32 = 10_000;

impl Default for Mqtt {
    fn default() -> Mqtt {
        Mqtt {
            broker: None,
            version: MqttVersion::V311,
            client_id: None,
            topic_prefix: None,
            qos: 1,
            keep_alive_s: DEFAULT_KEEP_ALIVE_S,
            tags: Vec::new(),
            publish_interval_ms: 0,
            deadband: 0.0,
            username: None,
            user: None,
            password_file: None,
            queue: DEFAULT_QUEUE,
            writes: true,
            ca_file: None,
            client_cert: None,
            client_key: None,
            sparkplug: None,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMqtt {
    broker: Option<Spanned<String>>,
    version: Option<Spanned<RawVersion>>,
    client_id: Option<Spanned<String>>,
    topic_prefix: Option<Spanned<String>>,
    qos: Option<Spanned<i64>>,
    keep_alive_s: Option<Spanned<i64>>,
    #[serde(default)]
    tags: Vec<Spanned<String>>,
    publish_interval_ms: Option<Spanned<i64>>,
    deadband: Option<Spanned<f64>>,
    username: Option<Spanned<String>>,
    user: Option<Spanned<String>>,
    password_file: Option<Spanned<String>>,
    queue: Option<Spanned<i64>>,
    writes: Option<bool>,
    ca_file: Option<Spanned<String>>,
    client_cert: Option<Spanned<String>>,
    client_key: Option<Spanned<String>>,
    sparkplug: Option<RawSparkplug>,
}

/// `version = 5` or `version = "3.1.1"`.
#[derive(Deserialize)]
#[serde(untagged)]
enum RawVersion {
    Number(i64),
    Text(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSparkplug {
    group_id: Option<Spanned<String>>,
    edge_node_id: Option<Spanned<String>>,
    device_id: Option<Spanned<String>>,
    #[serde(default)]
    devices: std::collections::BTreeMap<Spanned<String>, Vec<Spanned<String>>>,
    primary_host_id: Option<Spanned<String>>,
    buffer_max: Option<Spanned<i64>>,
}

/// A Sparkplug id: it goes into topics, so no `/`, `+`, `#`, not empty.
fn sparkplug_id(s: &str) -> bool {
    !s.is_empty() && !s.contains(['/', '+', '#'])
}

/// Whether `s` is a `host:port` (a name or an address and a port number).
pub fn is_host_port(s: &str) -> bool {
    match s.rsplit_once(':') {
        Some((host, port)) => {
            !host.is_empty() && !host.contains(char::is_whitespace) && port.parse::<u16>().is_ok_and(|p| p > 0)
        }
        None => false,
    }
}

/// Validates `[mqtt]`.
pub(super) fn mqtt(mut m: RawMqtt, file: FileId, diags: &mut Vec<Diagnostic>) -> Mqtt {
    let buffer_max = int_setting(
        "buffer_max",
        m.sparkplug.as_mut().and_then(|sp| sp.buffer_max.take()),
        10..=100_000_000,
        DEFAULT_BUFFER_MAX,
        "records",
        file,
        diags,
    );
    let mut bad = |s: &Spanned<String>, msg: String, label: &str| {
        diags.push(Diagnostic::new(
            Code::ConfigField,
            msg,
            Span::new(file, s.span()),
            label,
        ));
    };
    if let Some(b) = &m.broker
        && !is_host_port(b.get_ref())
    {
        bad(
            b,
            format!("broker = \"{}\" is not a host and port", b.get_ref()),
            "expected \"host:port\", like \"127.0.0.1:1883\"",
        );
    }
    // Topic levels may not hold wildcards; MQTT forbids them in published topics.
    if let Some(p) = &m.topic_prefix
        && (p.get_ref().is_empty() || p.get_ref().contains(['#', '+', '\0']) || p.get_ref().ends_with('/'))
    {
        bad(
            p,
            format!("topic_prefix = \"{}\" is not a topic prefix", p.get_ref()),
            "no `#`, `+`, and no `/` at the end",
        );
    }
    if let Some(c) = &m.client_id
        && (c.get_ref().is_empty() || c.get_ref().len() > 128)
    {
        bad(c, "client_id must be 1 to 128 characters".into(), "client id");
    }
    if let (Some(_), Some(u)) = (&m.username, &m.user) {
        bad(
            u,
            "user and username are two ways to name the broker account: set one".into(),
            "`user`: a user of users.toml; `username`: any other account",
        );
    } else if m.username.is_some() != m.password_file.is_some() && m.user.is_none() {
        let at = m.username.as_ref().or(m.password_file.as_ref());
        if let Some(at) = at {
            bad(
                at,
                "username and password_file go together".into(),
                "set both, or neither",
            );
        }
    } else if let (Some(u), None) = (&m.user, &m.password_file) {
        bad(
            u,
            "user needs a password_file: the broker's password for this user".into(),
            "add password_file = \"…\"",
        );
    }
    if m.client_cert.is_some() != m.client_key.is_some() {
        if let Some(at) = m.client_cert.as_ref().or(m.client_key.as_ref()) {
            bad(
                at,
                "client_cert and client_key go together".into(),
                "set both, or neither",
            );
        }
    } else if let (Some(c), None) = (&m.client_cert, &m.ca_file) {
        bad(
            c,
            "a client certificate needs TLS: set ca_file too".into(),
            "without ca_file",
        );
    }
    let sparkplug = m.sparkplug.map(|sp| {
        for id in [&sp.group_id, &sp.edge_node_id, &sp.device_id, &sp.primary_host_id]
            .into_iter()
            .flatten()
            .chain(sp.devices.keys())
        {
            if !sparkplug_id(id.get_ref()) {
                bad(
                    id,
                    format!("\"{}\" cannot be a Sparkplug id", id.get_ref()),
                    "no `/`, `+`, `#`, not empty",
                );
            }
        }
        Sparkplug {
            group_id: sp.group_id.map_or_else(|| "alba".into(), |g| g.into_inner()),
            edge_node_id: sp.edge_node_id.map(|n| n.into_inner()),
            device_id: sp.device_id.map_or_else(|| "plc".into(), |d| d.into_inner()),
            devices: sp
                .devices
                .into_iter()
                .map(|(d, tags)| (d.into_inner(), tags.into_iter().map(Spanned::into_inner).collect()))
                .collect(),
            primary_host_id: sp.primary_host_id.map(|h| h.into_inner()),
            buffer_max,
        }
    });
    let qos = int_setting("qos", m.qos, 0..=2, 1, "", file, diags) as u8;
    let keep_alive_s = int_setting(
        "keep_alive_s",
        m.keep_alive_s,
        5..=3600,
        DEFAULT_KEEP_ALIVE_S,
        "seconds",
        file,
        diags,
    );
    let queue = int_setting("queue", m.queue, 10..=1_000_000, DEFAULT_QUEUE, "messages", file, diags);
    let publish_interval_ms = int_setting(
        "publish_interval_ms",
        m.publish_interval_ms,
        0..=3_600_000,
        0,
        "ms",
        file,
        diags,
    );
    let version = match m.version.as_ref().map(|v| (v.get_ref(), v.span())) {
        None => MqttVersion::V311,
        Some((RawVersion::Number(5), _)) => MqttVersion::V5,
        Some((RawVersion::Number(4), _)) => MqttVersion::V311,
        Some((RawVersion::Text(t), _)) if t == "5" || t == "5.0" => MqttVersion::V5,
        Some((RawVersion::Text(t), _)) if t == "3.1.1" || t == "4" => MqttVersion::V311,
        Some((v, span)) => {
            let shown = match v {
                RawVersion::Number(n) => n.to_string(),
                RawVersion::Text(t) => format!("\"{t}\""),
            };
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("version = {shown} is not an MQTT version Alba speaks"),
                Span::new(file, span),
                "expected 5 or \"3.1.1\"",
            ));
            MqttVersion::V311
        }
    };
    let deadband = match m.deadband {
        Some(d) if d.get_ref().is_finite() && *d.get_ref() >= 0.0 => *d.get_ref(),
        Some(d) => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("deadband = {} is out of range", d.get_ref()),
                Span::new(file, d.span()),
                "expected a number ≥ 0",
            ));
            0.0
        }
        None => 0.0,
    };
    Mqtt {
        broker: m.broker.map(|b| b.into_inner()),
        version,
        client_id: m.client_id.map(|c| c.into_inner()),
        topic_prefix: m.topic_prefix.map(|p| p.into_inner()),
        qos,
        keep_alive_s,
        tags: m.tags.into_iter().map(|t| t.into_inner()).collect(),
        publish_interval_ms,
        deadband,
        username: m.username.map(|u| u.into_inner()),
        user: m.user.map(|u| u.into_inner()),
        password_file: m.password_file.map(|p| p.into_inner()),
        queue,
        writes: m.writes.unwrap_or(true),
        ca_file: m.ca_file.map(|c| c.into_inner()),
        client_cert: m.client_cert.map(|c| c.into_inner()),
        client_key: m.client_key.map(|c| c.into_inner()),
        sparkplug,
    }
}
