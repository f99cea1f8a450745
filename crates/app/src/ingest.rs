//! `alba historian --mqtt`: a small service that consumes the tag messages of many
//! runtimes from an MQTT broker into the historian (docs/historian.md "A historian
//! fed from the broker"), so that the runtimes need no database credentials.
//!
//! - JSON (`alba run --mqtt`): `<prefix>/tags/<Tag>` with `{"value", "ts"}`; the node
//!   is what the `+` levels of the prefix matched (`alba/+` → `alba/line1` is `line1`).
//! - Sparkplug B (`spBv1.0/#`): births name each metric and its alias, data messages
//!   send aliases; device metrics go under the node `<group>/<edge node>/<device>`,
//!   node metrics under `<group>/<edge node>` (`bdSeq` and `Node Control/…` are not
//!   recorded). A data message with an alias it has no birth for, or a gap in `seq`,
//!   asks the edge node for a rebirth (NCMD `Node Control/Rebirth`), at most every 5 s.
//!   `--primary-host ID` publishes the Sparkplug `STATE` of a primary host.
//!
//! Delivery is at least once into the store: QoS 1 subscriptions in a persistent session
//! (the broker keeps what arrives while the service is away), each message acknowledged
//! only once its samples are stored or buffered (a sample stored twice is ignored). The
//! event loop reconnects with exponential back-off and jitter; while the store is slower
//! than the broker, at most `QUEUE` messages wait in memory and the broker holds the rest.

use crate::mqtt::backoff;
use alba_historian::{NodeSink, Sample};
use alba_sparkplug::proto::{Metric, Payload, metric};
use prost::Message as _;
use rumqttc::{AsyncClient, Event, LastWill, MqttOptions, Packet, Publish, QoS};
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Messages waiting between the broker and the store.
const QUEUE: usize = 10_000;
/// The most samples one write to the store carries.
const BATCH: usize = 10_000;
/// The least time between two rebirth requests to one edge node.
const REBIRTH_EVERY: Duration = Duration::from_secs(5);

/// What `alba historian --mqtt` was told.
#[derive(Debug, Clone)]
pub struct IngestOptions {
    pub host: String,
    pub port: u16,
    /// The MQTT client id: the broker keeps this session's messages while it is away.
    pub client_id: String,
    /// User name and password for the broker.
    pub credentials: Option<(String, String)>,
    /// TLS to the broker (`alba_historian::client_tls`: its CA, a client certificate).
    pub tls: Option<Arc<rustls::ClientConfig>>,
    /// JSON topic prefixes: `<prefix>/tags/#` is consumed; `+` levels name the node.
    pub json: Vec<String>,
    /// Consume Sparkplug B (`spBv1.0/#`).
    pub sparkplug: bool,
    /// Publish `spBv1.0/STATE/<id>` as a Sparkplug primary host.
    pub primary_host: Option<String>,
}

/// Counters, printed when the service stops.
#[derive(Debug, Default)]
pub struct Counters {
    pub messages: AtomicU64,
    pub samples: AtomicU64,
    /// Messages or metrics that are not tag samples (a string, a malformed payload).
    pub ignored: AtomicU64,
    pub rebirths: AtomicU64,
}

/// A received sample: node, tag, time, value.
pub type Received = (String, String, i64, f64);

/// A message's samples, and the message to acknowledge once they are stored.
struct Item {
    publish: Publish,
    samples: Vec<Received>,
}

fn now_ms() -> i64 {
    alba_server::now_ms()
}

/// The node and tag of a JSON topic under `prefix` (`alba/+`): the levels the `+`s
/// matched (or the prefix's last level when it has none), and what follows `/tags/`.
pub fn json_topic(prefix: &str, topic: &str) -> Option<(String, String)> {
    let want: Vec<&str> = prefix.split('/').collect();
    let got: Vec<&str> = topic.split('/').collect();
    if got.len() < want.len() + 2 || got[want.len()] != "tags" {
        return None;
    }
    let mut node = Vec::new();
    for (w, g) in want.iter().zip(&got) {
        match *w {
            "+" => node.push(*g),
            w if w == *g => {}
            _ => return None,
        }
    }
    let node = if node.is_empty() {
        want.last().copied().unwrap_or_default().to_owned()
    } else {
        node.join("/")
    };
    let tag = got[want.len() + 1..].join("/");
    (!node.is_empty() && !tag.is_empty()).then_some((node, tag))
}

/// The latest time a sample may carry: the end of the year 9999 (ms since 1970). A time
/// the broker brings is a publisher's word: before 1970 or after this it is ignored and
/// counted, so that no sample makes the store compute ranges past its integers.
pub const LATEST_MS: i64 = 253_402_300_799_999;

fn plausible(t: i64) -> bool {
    (0..=LATEST_MS).contains(&t)
}

/// The sample of a JSON payload `{"value": <bool or number>, "ts": <ms>}` (`ts` missing:
/// now; a `ts` that is not a time from 1970 to 9999: none).
pub fn json_sample(payload: &[u8]) -> Option<(i64, f64)> {
    let j: serde_json::Value = serde_json::from_slice(payload).ok()?;
    let v = match j.get("value")? {
        serde_json::Value::Bool(b) => f64::from(u8::from(*b)),
        serde_json::Value::Number(n) => n.as_f64()?,
        _ => return None,
    };
    let t = match j.get("ts") {
        None => now_ms(),
        Some(ts) => ts.as_i64().filter(|t| plausible(*t))?,
    };
    Some((t, v))
}

/// A Sparkplug metric's value as a number, by its data type (booleans 0/1); `None` for
/// strings, data sets and the like.
fn number(datatype: u32, v: &metric::Value) -> Option<f64> {
    use metric::Value as V;
    Some(match (datatype, v) {
        (11, V::BooleanValue(b)) => f64::from(u8::from(*b)),
        (1, V::IntValue(x)) => f64::from(*x as u8 as i8),
        (2, V::IntValue(x)) => f64::from(*x as u16 as i16),
        (3, V::IntValue(x)) => f64::from(*x as i32),
        (5..=7, V::IntValue(x)) => f64::from(*x),
        (4, V::LongValue(x)) => *x as i64 as f64,
        (8, V::LongValue(x)) => *x as f64,
        (9, V::FloatValue(x)) => f64::from(*x),
        (10, V::DoubleValue(x)) => *x,
        _ => return None,
    })
}

/// What the service knows of one edge node: its metrics' aliases from the births.
#[derive(Default)]
struct Edge {
    /// Alias → (device, metric name, data type).
    aliases: HashMap<u64, (Option<String>, String, u32)>,
    /// (device, name) → data type, for metrics sent by name without one.
    types: HashMap<(Option<String>, String), u32>,
    /// The `seq` of the last message.
    seq: Option<u64>,
    rebirth_at: Option<Instant>,
}

/// The Sparkplug side: every edge node's aliases, and the rebirths to ask for.
#[derive(Default)]
pub struct Sparkplug {
    edges: HashMap<(String, String), Edge>,
}

impl Sparkplug {
    /// The samples of a Sparkplug message (node, tag, time, value), and the NCMD to
    /// publish (topic, payload) when the edge node is to be reborn.
    pub fn message(
        &mut self,
        topic: &str,
        payload: &[u8],
        ignored: &AtomicU64,
    ) -> (Vec<Received>, Option<(String, Vec<u8>)>) {
        let mut out = Vec::new();
        let Some(t) = alba_sparkplug::Topic::parse(topic) else {
            return (out, None);
        };
        let kind = t.kind.as_str();
        if !matches!(kind, "NBIRTH" | "DBIRTH" | "NDATA" | "DDATA" | "NDEATH") {
            return (out, None); // commands, device deaths, STATE
        }
        let key = (t.group.clone(), t.node.clone());
        if kind == "NDEATH" {
            self.edges.remove(&key);
            return (out, None);
        }
        let Ok(p) = Payload::decode(payload) else {
            ignored.fetch_add(1, Ordering::Relaxed);
            return (out, None);
        };
        let edge = self.edges.entry(key).or_default();
        if kind == "NBIRTH" {
            *edge = Edge {
                rebirth_at: edge.rebirth_at,
                ..Edge::default()
            };
        }
        let mut reborn = false;
        // A gap in the sequence: something was lost, the aliases may be stale.
        if let (Some(seq), Some(last), false) = (p.seq, edge.seq, kind == "NBIRTH") {
            reborn |= seq != last.wrapping_add(1) % 256;
        }
        if p.seq.is_some() {
            edge.seq = p.seq;
        }
        let device = t.device.clone().filter(|_| kind.starts_with('D'));
        let node = match &device {
            Some(d) => format!("{}/{}/{d}", t.group, t.node),
            None => format!("{}/{}", t.group, t.node),
        };
        let birth = kind.ends_with("BIRTH");
        for m in &p.metrics {
            let named = m.name.clone();
            let known = m.alias.and_then(|a| edge.aliases.get(&a)).cloned();
            let (name, datatype) = match (named, known) {
                (Some(n), _) => {
                    let dt = m
                        .datatype
                        .or_else(|| edge.types.get(&(device.clone(), n.clone())).copied());
                    (n, dt)
                }
                (None, Some((_, n, dt))) => (n, m.datatype.or(Some(dt))),
                (None, None) => {
                    reborn = true; // an alias without its birth
                    continue;
                }
            };
            if birth && let Some(dt) = datatype {
                edge.types.insert((device.clone(), name.clone()), dt);
                if let Some(a) = m.alias {
                    edge.aliases.insert(a, (device.clone(), name.clone(), dt));
                }
            }
            if name == alba_sparkplug::BD_SEQ || name.starts_with("Node Control/") || m.is_null == Some(true) {
                continue;
            }
            if name.is_empty() {
                ignored.fetch_add(1, Ordering::Relaxed); // no tag to store it under
                continue;
            }
            match (datatype, &m.value) {
                (Some(dt), Some(v)) => match number(dt, v) {
                    Some(v) => {
                        let t = match m.timestamp.or(p.timestamp).map(i64::try_from) {
                            None => now_ms(),
                            Some(Ok(t)) if plausible(t) => t,
                            Some(_) => {
                                ignored.fetch_add(1, Ordering::Relaxed);
                                continue;
                            }
                        };
                        out.push((node.clone(), name.replace('/', "."), t, v));
                    }
                    None => {
                        ignored.fetch_add(1, Ordering::Relaxed);
                    }
                },
                _ => {
                    ignored.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
        let due = edge.rebirth_at.is_none_or(|at| at.elapsed() >= REBIRTH_EVERY);
        let ncmd = (reborn && due).then(|| {
            edge.rebirth_at = Some(Instant::now());
            let cmd = Payload {
                timestamp: u64::try_from(now_ms()).ok(),
                metrics: vec![Metric {
                    name: Some(alba_sparkplug::REBIRTH.into()),
                    datatype: Some(alba_sparkplug::DataType::Boolean as u32),
                    value: Some(metric::Value::BooleanValue(true)),
                    ..Default::default()
                }],
                ..Default::default()
            };
            (
                format!("{}/{}/NCMD/{}", alba_sparkplug::NAMESPACE, t.group, t.node),
                cmd.encode_to_vec(),
            )
        });
        (out, ncmd)
    }
}

/// The `STATE` message of a primary host (Sparkplug 3.0: JSON, retained).
fn state(online: bool, timestamp: i64) -> Vec<u8> {
    serde_json::json!({"online": online, "timestamp": timestamp})
        .to_string()
        .into_bytes()
}

/// Writes what the event loop received, a batch at a time, then acknowledges it.
fn writer(
    store: Arc<dyn NodeSink>,
    mut rx: tokio::sync::mpsc::Receiver<Item>,
    client: AsyncClient,
    counters: Arc<Counters>,
) {
    let mut problem: Option<String> = None;
    while let Some(first) = rx.blocking_recv() {
        let mut items = vec![first];
        let mut n = items[0].samples.len();
        while n < BATCH {
            match rx.try_recv() {
                Ok(item) => {
                    n += item.samples.len();
                    items.push(item);
                }
                Err(_) => break,
            }
        }
        let mut by_node: HashMap<&str, Vec<Sample<'_>>> = HashMap::new();
        for (node, tag, t_ms, v) in items.iter().flat_map(|i| &i.samples) {
            by_node.entry(node).or_default().push(Sample {
                tag,
                t_ms: *t_ms,
                v: *v,
            });
        }
        let mut stored = true;
        for (node, samples) in &by_node {
            match store.record_for(node, samples) {
                Ok(k) => {
                    counters.samples.fetch_add(k as u64, Ordering::Relaxed);
                }
                // Samples the store refuses (an empty tag, a time out of range) are dropped.
                Err(alba_historian::Error::InvalidArgument(e)) => {
                    eprintln!("historian: samples of {node} refused: {e}");
                    counters.ignored.fetch_add(samples.len() as u64, Ordering::Relaxed);
                }
                Err(e) => {
                    eprintln!("historian: samples of {node} not stored: {e}");
                    stored = false;
                }
            }
        }
        let now = store.problem();
        if now != problem {
            match &now {
                Some(p) => eprintln!("historian: {p}"),
                None => eprintln!("historian: the store is reachable again"),
            }
            problem = now;
        }
        // Unacknowledged, the broker sends them again after a reconnection.
        if stored {
            for item in &items {
                if let Err(e) = client.try_ack(&item.publish) {
                    eprintln!("historian: acknowledgement not sent: {e}");
                }
            }
        }
    }
    if let Err(e) = store.flush() {
        eprintln!("historian: {e}");
    }
}

/// Consumes the broker's messages into `store` until `shutdown`; then stores what was
/// received and disconnects.
pub async fn ingest(
    store: Arc<dyn NodeSink>,
    opts: IngestOptions,
    shutdown: impl std::future::Future<Output = ()>,
) -> Result<Arc<Counters>, String> {
    let mut mqtt = MqttOptions::new(&opts.client_id, &opts.host, opts.port);
    mqtt.set_keep_alive(Duration::from_secs(30));
    // The broker keeps the subscriptions and queues messages while the service is away.
    mqtt.set_clean_session(false);
    mqtt.set_manual_acks(true);
    mqtt.set_max_packet_size(16 << 20, 1 << 20);
    if let Some((u, p)) = &opts.credentials {
        mqtt.set_credentials(u, p);
    }
    if let Some(tls) = &opts.tls {
        mqtt.set_transport(rumqttc::Transport::tls_with_config(rumqttc::TlsConfiguration::Rustls(
            tls.clone(),
        )));
    }
    let born = now_ms();
    let state_topic = opts
        .primary_host
        .as_ref()
        .map(|id| format!("{}/STATE/{id}", alba_sparkplug::NAMESPACE));
    if let Some(topic) = &state_topic {
        mqtt.set_last_will(LastWill::new(topic, state(false, born), QoS::AtLeastOnce, true));
    }
    // Room for an acknowledgement of every packet id that can be in flight (65 535).
    let (client, mut eventloop) = AsyncClient::new(mqtt, 70_000);
    let counters = Arc::new(Counters::default());
    let (tx, rx) = tokio::sync::mpsc::channel::<Item>(QUEUE);
    let (done_tx, done_rx) = tokio::sync::oneshot::channel::<()>();
    {
        let (store, client, counters) = (store.clone(), client.clone(), counters.clone());
        std::thread::spawn(move || {
            writer(store, rx, client, counters);
            let _ = done_tx.send(());
        });
    }
    let mut filters: Vec<String> = opts.json.iter().map(|p| format!("{p}/tags/#")).collect();
    if opts.sparkplug {
        filters.push(format!("{}/#", alba_sparkplug::NAMESPACE));
    }
    println!(
        "historian: consuming {} from {}:{} into {}",
        filters.join(", "),
        opts.host,
        opts.port,
        store.kind()
    );
    let mut sparkplug = Sparkplug::default();
    let mut tx = Some(tx);
    let mut shutdown = std::pin::pin!(shutdown);
    let mut done = std::pin::pin!(done_rx);
    let mut connected = false;
    let mut last_failure: Option<String> = None;
    let mut wait = Duration::from_millis(100);
    loop {
        let ev = tokio::select! {
            () = &mut shutdown, if tx.is_some() => {
                // The writer stores what it has and ends; new messages stay with the broker.
                tx = None;
                continue;
            }
            _ = &mut done => break,
            ev = eventloop.poll() => ev,
        };
        match ev {
            Ok(Event::Incoming(Packet::ConnAck(_))) => {
                connected = true;
                last_failure = None;
                wait = Duration::from_millis(100);
                eprintln!("historian: connected to {}:{}", opts.host, opts.port);
                for f in &filters {
                    let _ = client.try_subscribe(f.clone(), QoS::AtLeastOnce);
                }
                if let Some(topic) = &state_topic {
                    let _ = client.try_publish(topic.clone(), QoS::AtLeastOnce, true, state(true, born));
                }
            }
            Ok(Event::Incoming(Packet::Publish(p))) => {
                let Some(tx) = &tx else { continue };
                counters.messages.fetch_add(1, Ordering::Relaxed);
                let samples = if p.topic.starts_with(alba_sparkplug::NAMESPACE) && opts.sparkplug {
                    let (samples, ncmd) = sparkplug.message(&p.topic, &p.payload, &counters.ignored);
                    if let Some((topic, payload)) = ncmd {
                        counters.rebirths.fetch_add(1, Ordering::Relaxed);
                        let _ = client.try_publish(topic, QoS::AtLeastOnce, false, payload);
                    }
                    samples
                } else {
                    let found = opts.json.iter().find_map(|prefix| json_topic(prefix, &p.topic));
                    match (found, json_sample(&p.payload)) {
                        (Some((node, tag)), Some((t, v))) => vec![(node, tag, t, v)],
                        _ => {
                            counters.ignored.fetch_add(1, Ordering::Relaxed);
                            Vec::new()
                        }
                    }
                };
                // Waits while the queue is full: the broker holds the rest meanwhile.
                if tx.send(Item { publish: p, samples }).await.is_err() {
                    break;
                }
            }
            Ok(_) => {}
            Err(e) => {
                // Said when a connection is lost and when the reason for failing to
                // connect changes (a refused certificate, a broker not listening), not
                // at every attempt.
                let why = e.to_string();
                if connected {
                    eprintln!("historian: connection to the broker lost ({why}); reconnecting");
                    connected = false;
                } else if last_failure.as_ref() != Some(&why) {
                    eprintln!(
                        "historian: cannot connect to {}:{} ({why}); retrying",
                        opts.host, opts.port
                    );
                }
                last_failure = Some(why);
                let (pause, next) = backoff(wait);
                wait = next;
                tokio::select! {
                    _ = &mut done => break,
                    () = &mut shutdown, if tx.is_some() => tx = None,
                    () = tokio::time::sleep(pause) => {}
                }
            }
        }
    }
    // A clean goodbye: the STATE of a primary host, then the acknowledgements and the
    // disconnection (within a second).
    if let Some(topic) = state_topic {
        let _ = client.try_publish(topic, QoS::AtLeastOnce, true, state(false, born));
    }
    let _ = tokio::time::timeout(Duration::from_secs(1), async {
        let _ = client.disconnect().await;
        while let Ok(ev) = eventloop.poll().await {
            if matches!(ev, Event::Outgoing(rumqttc::Outgoing::Disconnect)) {
                break;
            }
        }
    })
    .await;
    Ok(counters)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_topics_name_the_node_by_the_wildcards() {
        let t = |p: &str, t: &str| json_topic(p, t);
        assert_eq!(
            t("alba/+", "alba/line1/tags/Level"),
            Some(("line1".into(), "Level".into()))
        );
        assert_eq!(
            t("alba/+", "alba/line1/tags/Tank.ACC"),
            Some(("line1".into(), "Tank.ACC".into()))
        );
        assert_eq!(
            t("plant/+/+", "plant/a2/l3/tags/X/Y"),
            Some(("a2/l3".into(), "X/Y".into()))
        );
        assert_eq!(
            t("site/line-4", "site/line-4/tags/Flow"),
            Some(("line-4".into(), "Flow".into()))
        );
        assert_eq!(t("alba/+", "alba/line1/status"), None);
        assert_eq!(t("alba/+", "alba/line1/set/Level"), None);
        assert_eq!(t("alba/+", "alba/line1/tags"), None);
        assert_eq!(t("alba/+", "other/line1/tags/Level"), None);
        assert_eq!(json_sample(br#"{"value": true, "ts": 5}"#), Some((5, 1.0)));
        assert_eq!(json_sample(br#"{"value": -2.5, "ts": 7}"#), Some((7, -2.5)));
        assert_eq!(json_sample(br#"{"value": "text", "ts": 7}"#), None);
        assert_eq!(json_sample(b"offline"), None);
        assert!(json_sample(br#"{"value": 3}"#).is_some_and(|(t, v)| t > 0 && v == 3.0));
        // A time a publisher got wrong is no time.
        assert_eq!(json_sample(br#"{"value": 1, "ts": -1}"#), None);
        assert_eq!(json_sample(br#"{"value": 1, "ts": 253402300800000}"#), None);
        assert_eq!(json_sample(br#"{"value": 1, "ts": "soon"}"#), None);
        assert_eq!(
            json_sample(br#"{"value": 1, "ts": 253402300799999}"#),
            Some((LATEST_MS, 1.0))
        );
    }

    /// Sequence numbers and times: in range, at the edges, anything.
    fn edgy() -> impl proptest::strategy::Strategy<Value = u64> {
        use proptest::prelude::*;
        prop_oneof![
            0u64..300,
            Just(u64::MAX),
            Just(i64::MAX as u64),
            Just(LATEST_MS as u64),
            Just(LATEST_MS as u64 + 1),
            any::<u64>()
        ]
    }

    proptest::proptest! {
        /// Whatever publishers send (any seq, alias, type, value and time, or bytes that
        /// are no payload), on any topic: no panic, and every sample has a node, a tag and a
        /// time from 1970 to 9999.
        #[test]
        fn any_sparkplug_messages_never_panic_and_give_plausible_samples(
            msgs in proptest::collection::vec(
                (
                    proptest::sample::select(vec![
                        "spBv1.0/G/NBIRTH/n", "spBv1.0/G/NDATA/n", "spBv1.0/G/DBIRTH/n/d",
                        "spBv1.0/G/DDATA/n/d", "spBv1.0/G/NDEATH/n", "spBv1.0/G/NCMD/n",
                        "spBv1.0/STATE/h", "spBv1.0/G", "spBv1.0//NDATA/", "other/x",
                    ]),
                    proptest::option::of(edgy()),
                    proptest::option::of(edgy()),
                    proptest::collection::vec(
                        (
                            proptest::option::of(proptest::sample::select(vec!["A", "B/C", "bdSeq", "Node Control/Rebirth", ""])),
                            proptest::option::of(0u64..4),
                            proptest::option::of(0u32..20),
                            proptest::option::of(edgy()),
                            proptest::prelude::any::<u64>(),
                            0u8..5,
                        ),
                        0..6,
                    ),
                    proptest::collection::vec(proptest::prelude::any::<u8>(), 0..40),
                ),
                1..30,
            )
        ) {
            use metric::Value as V;
            let ignored = AtomicU64::new(0);
            let mut sp = Sparkplug::default();
            for (topic, seq, time, metrics, raw) in msgs {
                let metrics = metrics
                    .into_iter()
                    .map(|(name, alias, datatype, timestamp, x, kind)| Metric {
                        name: name.map(str::to_owned),
                        alias,
                        datatype,
                        timestamp,
                        value: Some(match kind {
                            0 => V::IntValue(x as u32),
                            1 => V::LongValue(x),
                            2 => V::FloatValue(f32::from_bits(x as u32)),
                            3 => V::DoubleValue(f64::from_bits(x)),
                            _ => V::BooleanValue(x & 1 == 1),
                        }),
                        ..Default::default()
                    })
                    .collect();
                let body = if raw.len() > 30 {
                    raw
                } else {
                    Payload { timestamp: time, metrics, seq, ..Default::default() }.encode_to_vec()
                };
                let (samples, _) = sp.message(topic, &body, &ignored);
                for (node, tag, t, _) in samples {
                    proptest::prop_assert!(!node.is_empty() && !tag.is_empty());
                    proptest::prop_assert!(plausible(t), "{t}");
                }
            }
        }
    }

    fn metric(name: Option<&str>, alias: Option<u64>, datatype: Option<u32>, v: metric::Value) -> Metric {
        Metric {
            name: name.map(str::to_owned),
            alias,
            datatype,
            timestamp: Some(1_000),
            value: Some(v),
            ..Default::default()
        }
    }

    fn payload(seq: u64, metrics: Vec<Metric>) -> Vec<u8> {
        Payload {
            timestamp: Some(900),
            metrics,
            seq: Some(seq),
            ..Default::default()
        }
        .encode_to_vec()
    }

    #[test]
    fn sparkplug_births_name_the_aliases_of_data_messages() {
        use metric::Value as V;
        let ignored = AtomicU64::new(0);
        let mut sp = Sparkplug::default();
        let nbirth = payload(
            0,
            vec![
                metric(Some("bdSeq"), None, Some(4), V::LongValue(3)),
                metric(Some("Node Control/Rebirth"), None, Some(11), V::BooleanValue(false)),
                metric(Some("Uptime"), Some(9), Some(7), V::IntValue(4_000_000_000)),
            ],
        );
        let (s, cmd) = sp.message("spBv1.0/Plant/NBIRTH/line1", &nbirth, &ignored);
        assert_eq!(s, [("Plant/line1".into(), "Uptime".into(), 1_000, 4e9)]);
        assert!(cmd.is_none());
        let dbirth = payload(
            1,
            vec![
                metric(Some("Level"), Some(0), Some(10), V::DoubleValue(2.5)),
                metric(Some("Tank/ACC"), Some(1), Some(3), V::IntValue(-5i32 as u32)),
                metric(Some("Pump"), Some(2), Some(11), V::BooleanValue(true)),
                metric(Some("Name"), Some(3), Some(12), V::StringValue("x".into())),
            ],
        );
        let (s, _) = sp.message("spBv1.0/Plant/DBIRTH/line1/PLC", &dbirth, &ignored);
        let node = "Plant/line1/PLC".to_owned();
        assert_eq!(
            s,
            [
                (node.clone(), "Level".into(), 1_000, 2.5),
                (node.clone(), "Tank.ACC".into(), 1_000, -5.0),
                (node.clone(), "Pump".into(), 1_000, 1.0),
            ]
        );
        assert_eq!(ignored.load(Ordering::Relaxed), 1, "the string");
        // By alias only, the data type from the birth when omitted.
        let ddata = payload(
            2,
            vec![
                metric(None, Some(1), None, V::IntValue(7)),
                metric(None, Some(2), Some(11), V::BooleanValue(false)),
            ],
        );
        let (s, cmd) = sp.message("spBv1.0/Plant/DDATA/line1/PLC", &ddata, &ignored);
        assert_eq!(
            s,
            [
                (node.clone(), "Tank.ACC".into(), 1_000, 7.0),
                (node.clone(), "Pump".into(), 1_000, 0.0)
            ]
        );
        assert!(cmd.is_none());
        // An unknown alias and a gap in seq: a rebirth is asked for, once per 5 s.
        let lost = payload(9, vec![metric(None, Some(77), None, V::IntValue(1))]);
        let (s, cmd) = sp.message("spBv1.0/Plant/DDATA/line1/PLC", &lost, &ignored);
        assert!(s.is_empty());
        let (topic, body) = cmd.expect("a rebirth");
        assert_eq!(topic, "spBv1.0/Plant/NCMD/line1");
        let p = Payload::decode(body.as_slice()).expect("NCMD");
        assert_eq!(p.metrics[0].name.as_deref(), Some("Node Control/Rebirth"));
        assert_eq!(p.metrics[0].value, Some(V::BooleanValue(true)));
        let (_, again) = sp.message("spBv1.0/Plant/DDATA/line1/PLC", &lost, &ignored);
        assert!(again.is_none(), "not again within 5 s");
        // A death forgets the aliases; other edge nodes keep theirs.
        sp.message("spBv1.0/Plant/NDEATH/line1", &payload(0, vec![]), &ignored);
        let (s, _) = sp.message("spBv1.0/Plant/DDATA/line1/PLC", &ddata, &ignored);
        assert!(s.is_empty());
        let (s, _) = sp.message("spBv1.0/Plant/DDATA/line1/PLC", b"\xff\xff not protobuf", &ignored);
        assert!(s.is_empty());
        assert!(sp.message("spBv1.0/STATE/host", b"{}", &ignored).0.is_empty());
    }
}
