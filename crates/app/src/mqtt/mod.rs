//! The MQTT client of `alba run` (docs/scale-out.md, SPEC §10.5): every tag
//! (or those `[mqtt] tags` lists) published on change, retained, as
//! `{"value", "ts"}` on `<prefix>/tags/<Tag>`; writes taken from
//! `<prefix>/set/<Tag>` with the HTTP API's rules and audit rows, refusals
//! answered on `<prefix>/error`; `<prefix>/status` is `online` while
//! connected and `offline` (the last will) when not.
//!
//! Nothing here can slow the scan: the publisher reads the runtime's
//! snapshot channel like the WebSocket clients (it skips snapshots when
//! behind), and hands messages to the client's bounded queue without
//! waiting (`try_publish`): a full queue (a slow or absent broker) leaves the
//! change to a later snapshot and counts the miss. The event loop reconnects
//! with exponential back-off and jitter (100 ms doubling to 30 s), and
//! republishes every tag on each connection (a restarted broker may have
//! lost its retained messages).
//!
//! Also here: `publish_interval_ms` and `deadband` ([`pause`], [`worth`]),
//! the broker account (`user` from users.toml or `username`, the password
//! file, [`Credentials`]), the writes' role check and audit ([`write`]),
//! and the link's counters for `/api/status` ([`Stats`], [`Link`]). The
//! protocol versions 3.1.1 and 5 are behind [`client`]; Sparkplug B is
//! [`sparkplug`], a sub-module (a mode of this bridge).

pub(crate) mod client;
pub(crate) mod sparkplug;

use crate::Service;
use alba_model::Value;
use alba_runtime::json::to_json;
pub(crate) use client::goodbye;
use client::{Client, Ev, Version, Will};
use rumqttc::QoS;
use serde_json::{Value as Json, json};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::Duration;

/// What `alba run` resolved for the client.
pub(crate) struct Settings {
    pub host: String,
    pub port: u16,
    prefix: String,
    pub client_id: String,
    /// `[mqtt] version`: 3.1.1 or 5.
    pub version: Version,
    pub qos: QoS,
    pub keep_alive: Duration,
    pub tags: Vec<String>,
    /// `[mqtt] publish_interval_ms` and `deadband`.
    pub interval: Duration,
    pub deadband: f64,
    /// The broker account: its name and password file (read at every
    /// connection attempt, so a corrected file is used without a restart).
    pub credentials: Option<Credentials>,
    /// Who writes from MQTT: the audit's user and the role checked.
    actor: (String, alba_auth::Role),
    pub queue: usize,
    pub writes: bool,
    /// TLS to the broker, when `[mqtt] ca_file` is set.
    pub tls: Option<Arc<rustls::ClientConfig>>,
    /// Sparkplug B instead of JSON.
    pub sparkplug: Option<sparkplug::SpSettings>,
}

fn settings(s: &Service<'_>, cli: Option<&str>) -> Result<Option<Settings>, String> {
    let cfg = s.config.and_then(|c| c.mqtt.clone());
    let Some(broker) = cli
        .map(str::to_string)
        .or_else(|| cfg.as_ref().and_then(|c| c.broker.clone()))
    else {
        return Ok(None);
    };
    if !alba_settings::is_host_port(&broker) {
        return Err(format!("--mqtt {broker}: expected host:port, like 127.0.0.1:1883"));
    }
    let (host, port) = broker.rsplit_once(':').unwrap_or((&broker, "1883"));
    let port = port.parse::<u16>().map_err(|_| format!("--mqtt {broker}: bad port"))?;
    let cfg = cfg.unwrap_or_default();
    let name = &s.state.name;
    let (credentials, actor) = match (&cfg.user, &cfg.username, &cfg.password_file) {
        // A project user: it must exist, and writes act as it.
        (Some(u), _, Some(f)) => {
            let role = s
                .users
                .role(u)
                .ok_or_else(|| format!("[mqtt] user = \"{u}\" is not a user of users.toml (see `alba user list`)"))?;
            (Some(Credentials::read(u, s.dir.join(f))?), (u.clone(), role))
        }
        (None, Some(u), Some(f)) => (
            Some(Credentials::read(u, s.dir.join(f))?),
            ("mqtt".to_string(), alba_auth::Role::Operator),
        ),
        _ => (None, ("mqtt".to_string(), alba_auth::Role::Operator)),
    };
    Ok(Some(Settings {
        host: host.trim_start_matches('[').trim_end_matches(']').to_string(),
        port,
        prefix: cfg.topic_prefix.clone().unwrap_or_else(|| format!("alba/{name}")),
        client_id: cfg.client_id.clone().unwrap_or_else(|| format!("alba-{name}")),
        version: match cfg.version {
            alba_settings::MqttVersion::V311 => Version::V311,
            alba_settings::MqttVersion::V5 => Version::V5,
        },
        qos: match cfg.qos {
            0 => QoS::AtMostOnce,
            2 => QoS::ExactlyOnce,
            _ => QoS::AtLeastOnce,
        },
        keep_alive: Duration::from_secs(u64::from(cfg.keep_alive_s)),
        tags: cfg.tags.clone(),
        interval: Duration::from_millis(u64::from(cfg.publish_interval_ms)),
        deadband: cfg.deadband,
        credentials,
        actor,
        queue: cfg.queue as usize,
        writes: cfg.writes,
        tls: tls(s.dir, &cfg)?,
        sparkplug: cfg.sparkplug.as_ref().map(|sp| sparkplug::SpSettings {
            group: sp.group_id.clone(),
            node: sp
                .edge_node_id
                .clone()
                .unwrap_or_else(|| name.replace(['/', '+', '#'], "_")),
            device: sp.device_id.clone(),
            devices: sp.devices.clone(),
            primary_host: sp.primary_host_id.clone(),
            buffer_max: u64::from(sp.buffer_max),
        }),
    }))
}

/// A broker account: the name, and the password read from its file.
#[derive(Clone)]
pub(crate) struct Credentials {
    user: String,
    file: std::path::PathBuf,
    password: String,
}

impl Credentials {
    /// Reads the password file: its first line, without the line end. The
    /// error names the file, never its content. A file others may read is
    /// said on the console (once, at start).
    fn read(user: &str, file: std::path::PathBuf) -> Result<Credentials, String> {
        let password = read_secret(&file)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            if let Ok(m) = std::fs::metadata(&file)
                && m.permissions().mode() & 0o077 != 0
            {
                eprintln!(
                    "mqtt: warning: {} may be read by other users of this machine (chmod 600 it)",
                    file.display()
                );
            }
        }
        Ok(Credentials {
            user: user.to_string(),
            file,
            password,
        })
    }

    pub fn user(&self) -> &str {
        &self.user
    }

    pub fn password(&self) -> &str {
        &self.password
    }

    /// The password file read again before a reconnection: a corrected
    /// file is used at once; an unreadable one keeps the last password.
    pub(crate) fn refresh(&mut self) -> (&str, &str) {
        match read_secret(&self.file) {
            Ok(p) => self.password = p,
            Err(e) => eprintln!("mqtt: {e}; trying with the password read before"),
        }
        (&self.user, &self.password)
    }
}

fn read_secret(file: &std::path::Path) -> Result<String, String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("[mqtt] password_file {}: {e}", file.display()))?;
    Ok(text.lines().next().unwrap_or("").to_string())
}

/// The TLS client configuration of `[mqtt] ca_file` (and, for mutual TLS,
/// `client_cert` + `client_key`): only that CA is trusted, as a plant's
/// broker has its own; paths are relative to the project.
fn tls(dir: &std::path::Path, cfg: &alba_settings::Mqtt) -> Result<Option<Arc<rustls::ClientConfig>>, String> {
    let Some(ca) = &cfg.ca_file else { return Ok(None) };
    let client = cfg.client_cert.as_ref().zip(cfg.client_key.as_ref());
    let client = client.map(|(c, k)| (dir.join(c), dir.join(k)));
    alba_historian::client_tls(&dir.join(ca), client.as_ref().map(|(c, k)| (c.as_path(), k.as_path())))
        .map(Some)
        .map_err(|e| format!("[mqtt] {e}"))
}

/// The client's counters (JSON and Sparkplug).
#[derive(Default)]
pub(crate) struct Stats {
    pub connected: AtomicBool,
    /// Connections made (ConnAck received) since `alba run` started.
    pub connects: AtomicU64,
    /// Connections lost.
    pub errors: AtomicU64,
    /// JSON: set on each new connection: republish everything.
    republish: AtomicBool,
    /// Messages handed to the client's queue (tag values, DDATA).
    pub published: AtomicU64,
    /// Changes the full queue could not take (sent later, coalesced).
    pub deferred: AtomicU64,
    /// Sparkplug's store and forward: records waiting in the buffer, sent
    /// from it, and lost (the oldest past the bound, unreadable, or metrics
    /// the current birth does not have).
    pub buffered: AtomicU64,
    pub replayed: AtomicU64,
    pub dropped: AtomicU64,
    /// Records the buffer could not write (a full disk); said once.
    pub store_errors: AtomicU64,
    /// Why the last connection failed or ended (cleared on a connection).
    pub last_error: Mutex<Option<String>>,
    /// Connected but holding data back, and why (Sparkplug: the primary
    /// host is offline).
    pub held: Mutex<Option<String>>,
}

impl Stats {
    pub fn set(slot: &Mutex<Option<String>>, v: Option<String>) {
        *slot.lock().unwrap_or_else(PoisonError::into_inner) = v;
    }

    /// A connection acknowledged: counted, and the last error cleared.
    pub fn connected_now(&self) {
        self.connected.store(true, Ordering::Relaxed);
        self.connects.fetch_add(1, Ordering::Relaxed);
        Self::set(&self.last_error, None);
    }

    /// A connection failed or ended with `e`: counted and kept as the last error.
    pub fn failed(&self, e: &dyn std::fmt::Display) {
        self.errors.fetch_add(1, Ordering::Relaxed);
        Self::set(&self.last_error, Some(e.to_string()));
    }

    fn get(slot: &Mutex<Option<String>>) -> Option<String> {
        slot.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }
}

/// The broker link as `GET /api/status` shows it (`connections`, name `mqtt`).
pub(crate) struct Link {
    stats: Arc<Stats>,
    protocol: &'static str,
    endpoint: String,
    capacity: u64,
}

impl alba_server::connections::Connections for Link {
    fn status(&self) -> Vec<alba_server::reply::Connection> {
        let s = &self.stats;
        let n = |c: &AtomicU64| c.load(Ordering::Relaxed);
        let connected = s.connected.load(Ordering::Relaxed);
        let held = Stats::get(&s.held);
        vec![alba_server::reply::Connection {
            name: "mqtt".into(),
            protocol: self.protocol.into(),
            endpoint: self.endpoint.clone(),
            ok: connected && held.is_none(),
            connected,
            connects: n(&s.connects),
            errors: n(&s.errors),
            last_error: if connected { held } else { Stats::get(&s.last_error) },
            queue: Some(alba_server::reply::QueueCounters {
                published: n(&s.published),
                coalesced: n(&s.deferred),
                dropped: n(&s.dropped),
                buffered: n(&s.buffered),
                replayed: n(&s.replayed),
                capacity: self.capacity,
            }),
        }]
    }

    fn browse<'a>(&'a self, server: &'a str, _node: &'a str) -> alba_server::connections::Browsing<'a> {
        Box::pin(async move { Err(alba_server::connections::BrowseError::UnknownServer(server.to_string())) })
    }
}

/// Back-off after a failed connection: from 100 ms doubling to 30 s, with
/// jitter so that many runtimes do not reconnect in step (and a dead broker
/// costs no CPU). Returns the wait and the next back-off.
pub(crate) fn backoff(current: Duration) -> (Duration, Duration) {
    let jitter = u64::from(std::process::id() ^ current.subsec_nanos()) % 100;
    let wait = current + Duration::from_millis(jitter * current.as_millis() as u64 / 400);
    (wait, (current * 2).min(Duration::from_secs(30)))
}

/// Whether `new` is worth publishing after `old`, the value last published:
/// any change, and for a REAL or LREAL a move of more than `deadband`.
pub(crate) fn worth(old: Option<Value>, new: Value, deadband: f64) -> bool {
    match (old, new) {
        (None, _) => true,
        (Some(Value::Real(a)), Value::Real(b)) => moved(f64::from(a), f64::from(b), deadband),
        (Some(Value::Lreal(a)), Value::Lreal(b)) => moved(a, b, deadband),
        (Some(o), n) => o != n,
    }
}

/// Whether `b` is more than `deadband` from `a`; values that are not
/// finite move when their bits differ (a NaN after a NaN does not).
pub(crate) fn moved(a: f64, b: f64, deadband: f64) -> bool {
    if a.is_finite() && b.is_finite() {
        (b - a).abs() > deadband
    } else {
        a.to_bits() != b.to_bits()
    }
}

/// Waits `interval` (`[mqtt] publish_interval_ms`) before the publisher's
/// next pass: snapshots in between coalesce in the channel. False when
/// `alba run` is stopping.
pub(crate) async fn pause(interval: Duration, closing: &mut tokio::sync::watch::Receiver<bool>) -> bool {
    if interval.is_zero() {
        return true;
    }
    tokio::select! {
        _ = closing.wait_for(|c| *c) => false,
        _ = tokio::time::sleep(interval) => true,
    }
}

/// Whether the value `name` is the tag `tag` or one of its members (any case).
pub(crate) fn is_of(name: &str, tag: &str) -> bool {
    name.eq_ignore_ascii_case(tag)
        || (name.len() > tag.len()
            && name.as_bytes()[tag.len()] == b'.'
            && name.is_char_boundary(tag.len())
            && name[..tag.len()].eq_ignore_ascii_case(tag))
}

/// The tags a client publishes: every value of the layout, or those `tags` names (and their members).
pub(crate) fn published(layout: &alba_ir::Layout, tags: &[String]) -> Vec<(String, alba_ir::Place)> {
    let mut places = alba_server::tags::every_value(layout);
    if !tags.is_empty() {
        places.retain(|(n, _)| tags.iter().any(|t| is_of(n, t)));
    }
    places
}

/// Starts the client if `--mqtt` or `[mqtt] broker` asks for one; its link
/// for `/api/status`.
pub(crate) async fn start(s: &Service<'_>, cli: Option<&str>) -> Result<Option<Arc<Link>>, String> {
    let Some(set) = settings(s, cli)? else {
        return Ok(None);
    };
    // Names to publish: each checked now, so a typo is an error at start.
    let snapshot = s.state.runtime.snapshot();
    for t in &set.tags {
        if let Err(e) = snapshot.program.layout.resolve(t) {
            return Err(format!("[mqtt] tags: {e}"));
        }
    }
    let stats = Arc::new(Stats::default());
    let link = Arc::new(Link {
        stats: stats.clone(),
        protocol: if set.sparkplug.is_some() { "sparkplug" } else { "mqtt" },
        endpoint: format!("{}:{}", set.host, set.port),
        capacity: set.queue as u64,
    });
    if set.sparkplug.is_some() {
        sparkplug::start(s, set, stats)?;
        return Ok(Some(link));
    }
    let will = Will {
        topic: format!("{}/status", set.prefix),
        payload: b"offline".to_vec(),
        qos: QoS::AtLeastOnce,
        retain: true,
    };
    let (client, mut eventloop) = client::new(&set, will);
    let set = Arc::new(set);
    println!(
        "mqtt: publishing to {}:{}{}{} under {}/",
        set.host,
        set.port,
        if set.version == Version::V5 { " (MQTT 5)" } else { "" },
        if set.tls.is_some() { " (TLS)" } else { "" },
        set.prefix
    );

    // The event loop: connection, back-off, incoming writes.
    let (st, c, sts, cfg) = (s.state.clone(), client.clone(), stats.clone(), set.clone());
    let mut closing = s.state.closing();
    let mut creds = set.credentials.clone();
    tokio::spawn(async move {
        let mut backoff = Duration::from_millis(100);
        loop {
            let ev = tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                ev = eventloop.poll() => ev,
            };
            match ev {
                Ok(Ev::Connected) => {
                    backoff = Duration::from_millis(100);
                    sts.connected_now();
                    sts.republish.store(true, Ordering::Relaxed);
                    let _ = c.try_publish(
                        format!("{}/status", cfg.prefix),
                        QoS::AtLeastOnce,
                        true,
                        b"online".to_vec(),
                    );
                    if cfg.writes {
                        let _ = c.try_subscribe(format!("{}/set/#", cfg.prefix), QoS::AtLeastOnce);
                    }
                    eprintln!("mqtt: connected to {}:{}", cfg.host, cfg.port);
                }
                Ok(Ev::Message { topic, payload, reply }) => {
                    if let Some(tag) = topic.strip_prefix(&format!("{}/set/", cfg.prefix)) {
                        set_tag(&st, &c, &cfg, tag, &payload, reply).await;
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    if sts.connected.swap(false, Ordering::Relaxed) {
                        eprintln!("mqtt: connection lost ({e}); reconnecting");
                    }
                    sts.failed(&e);
                    eventloop.renew(None, creds.as_mut().map(Credentials::refresh));
                    let (wait, next) = self::backoff(backoff);
                    backoff = next;
                    tokio::select! {
                        _ = closing.wait_for(|c| *c) => break,
                        _ = tokio::time::sleep(wait) => {}
                    }
                }
            }
        }
        // A clean goodbye: the broker would otherwise send the will.
        goodbye(
            &c,
            eventloop,
            format!("{}/status", cfg.prefix),
            true,
            b"offline".to_vec(),
        )
        .await;
    });

    // The publisher: changes of the published snapshots, at most one pass
    // per `publish_interval_ms`.
    let mut rx = s.state.runtime.subscribe();
    let mut closing = s.state.closing();
    tokio::spawn(async move {
        let mut program = None;
        // Each published value: its topic, its place, and the value last published.
        let mut places: Vec<(String, alba_ir::Place, Option<Value>)> = Vec::new();
        loop {
            tokio::select! {
                _ = closing.wait_for(|c| *c) => break,
                r = rx.changed() => if r.is_err() { break },
            }
            let snap = rx.borrow_and_update().clone();
            if !program.as_ref().is_some_and(|p| Arc::ptr_eq(p, &snap.program)) {
                // After an online edit everything goes again: the types may have changed.
                places = published(&snap.program.layout, &set.tags)
                    .into_iter()
                    .map(|(n, p)| (format!("{}/tags/{n}", set.prefix), p, None))
                    .collect();
                program = Some(snap.program.clone());
            }
            if !stats.connected.load(Ordering::Relaxed) {
                continue;
            }
            if stats.republish.swap(false, Ordering::Relaxed) {
                places.iter_mut().for_each(|(_, _, last)| *last = None);
            }
            for (topic, place, last) in &mut places {
                let v = snap.read(*place);
                if !worth(*last, v, set.deadband) {
                    continue;
                }
                let payload = format!("{{\"value\":{},\"ts\":{}}}", to_json(v), snap.unix_ms);
                match client.try_publish_json(topic.as_str(), set.qos, true, payload, None) {
                    Ok(()) => {
                        stats.published.fetch_add(1, Ordering::Relaxed);
                        *last = Some(v);
                    }
                    // The queue is full: this change goes with a later snapshot.
                    Err(_) => {
                        stats.deferred.fetch_add(1, Ordering::Relaxed);
                    }
                }
            }
            if !pause(set.interval, &mut closing).await {
                break;
            }
        }
    });
    Ok(Some(link))
}

/// A write from MQTT through the control layer (every door's rules) with
/// its audit row (`via` `mqtt`; the user `mqtt`, or `[mqtt] user`, with
/// the broker's address): refused unless that user's role may write tags;
/// what the tag then holds, or why not (the refusal's message, answered on
/// `<prefix>/error`).
pub(crate) async fn write(st: &alba_server::AppState, set: &Settings, tag: &str, value: &Json) -> Result<Json, String> {
    let (user, role) = &set.actor;
    let actor = alba_control::Actor::mqtt(user, *role, format!("{}:{}", set.host, set.port));
    st.control.write(&actor, tag, value).await.map_err(|e| e.to_string())
}

/// A write from `<prefix>/set/<tag>` (`{"value": ...}`) through [`write`];
/// a refusal is answered on `<prefix>/error` as `{"tag", "error", "ts"}`.
/// With MQTT 5, a message with a response topic is answered there too,
/// with its correlation data: `{"tag", "value", "ts"}` (what the tag then
/// holds) or the refusal.
async fn set_tag(
    st: &alba_server::AppState,
    c: &Client,
    cfg: &Settings,
    tag: &str,
    payload: &[u8],
    reply: Option<(String, Option<Vec<u8>>)>,
) {
    let value = serde_json::from_slice::<Json>(payload)
        .map_err(|e| format!("the payload is not JSON ({e}); send {{\"value\": ...}}"))
        .and_then(|j| {
            j.get("value")
                .cloned()
                .ok_or_else(|| "the payload needs a `value` field".to_string())
        });
    let result = match value {
        Ok(v) => write(st, cfg, tag, &v).await,
        Err(e) => Err(e),
    };
    let ts = alba_server::now_ms();
    let answer = match &result {
        Ok(v) => json!({"tag": tag, "value": v, "ts": ts}),
        Err(error) => json!({"tag": tag, "error": error, "ts": ts}),
    };
    if result.is_err() {
        let _ = c.try_publish_json(
            format!("{}/error", cfg.prefix),
            QoS::AtLeastOnce,
            false,
            answer.to_string(),
            None,
        );
    }
    if let Some((topic, correlation)) = reply {
        let _ = c.try_publish_json(topic, QoS::AtLeastOnce, false, answer.to_string(), correlation);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_deadband_is_for_reals_and_measured_from_the_last_published_value() {
        let r = Value::Real;
        assert!(worth(None, r(1.0), 0.5), "a first value always goes");
        assert!(!worth(Some(r(10.0)), r(10.4), 0.5));
        assert!(worth(Some(r(10.0)), r(10.6), 0.5));
        assert!(worth(Some(Value::Lreal(1.0)), Value::Lreal(-1.0), 1.5));
        assert!(!worth(Some(r(1.0)), r(1.0), 0.0));
        assert!(worth(Some(r(1.0)), r(1.000_001), 0.0), "0: any change");
        // Integers and BOOLs: any change, whatever the deadband.
        assert!(worth(Some(Value::Dint(5)), Value::Dint(6), 100.0));
        assert!(!worth(Some(Value::Bool(true)), Value::Bool(true), 0.0));
        // Not finite: published when it changes, not again.
        assert!(worth(Some(r(1.0)), r(f32::NAN), 1e9));
        assert!(!worth(Some(r(f32::NAN)), r(f32::NAN), 0.0));
        assert!(worth(Some(r(f32::INFINITY)), r(1.0), 1e9));
    }

    #[test]
    fn a_name_is_its_tag_or_a_member() {
        assert!(is_of("Delay.ACC", "delay") && is_of("Level", "LEVEL"));
        assert!(!is_of("Delayed", "Delay") && !is_of("Dela", "Delay"));
    }
}
