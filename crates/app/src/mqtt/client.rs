//! One MQTT client over rumqttc's two protocol versions (`[mqtt] version`):
//! 3.1.1 (`rumqttc`) and 5 (`rumqttc::v5`), behind the few calls the JSON
//! and Sparkplug sessions make. With MQTT 5 a session starts clean with a
//! session expiry of 0 (what Sparkplug 3.0 asks), JSON messages say they are
//! UTF-8 JSON (payload format indicator and content type), and the response
//! topic and correlation data of a received message are given to the caller
//! (the request/response pattern of MQTT 5).

use super::Settings;
use rumqttc::v5::mqttbytes::v5 as p5;
use rumqttc::{Event, Packet, QoS};
use std::time::Duration;

/// The MQTT protocol version of `[mqtt] version`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Version {
    V311,
    V5,
}

/// A last will: topic, payload, QoS, retained.
pub(crate) struct Will {
    pub topic: String,
    pub payload: Vec<u8>,
    pub qos: QoS,
    pub retain: bool,
}

/// The handle that queues requests (cheap to clone).
#[derive(Clone)]
pub(crate) enum Client {
    V311(rumqttc::AsyncClient),
    V5(rumqttc::v5::AsyncClient),
}

/// The connection's event loop, polled by one task.
pub(crate) enum EventLoop {
    V311(Box<rumqttc::EventLoop>),
    V5(Box<rumqttc::v5::EventLoop>),
}

/// What a poll brought.
pub(crate) enum Ev {
    /// The broker accepted the connection.
    Connected,
    /// A message on a subscribed topic; with MQTT 5 maybe a response topic
    /// and correlation data to answer to.
    Message {
        topic: String,
        payload: Vec<u8>,
        reply: Option<(String, Option<Vec<u8>>)>,
    },
    /// Our DISCONNECT went out.
    Left,
    Other,
}

/// Why a request was not queued (the queue is full, or the client is gone).
#[derive(Debug)]
pub(crate) struct Full;

impl std::fmt::Display for Full {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the client's queue is full")
    }
}

fn qos5(q: QoS) -> rumqttc::v5::mqttbytes::QoS {
    use rumqttc::v5::mqttbytes::QoS as Q5;
    match q {
        QoS::AtMostOnce => Q5::AtMostOnce,
        QoS::AtLeastOnce => Q5::AtLeastOnce,
        QoS::ExactlyOnce => Q5::ExactlyOnce,
    }
}

/// Packets received at most (commands, STATE, writes are small): 1 MiB.
const MAX_IN: usize = 1 << 20;
/// Packets sent at most: MQTT's own limit (a Sparkplug birth of a large
/// project is megabytes; rumqttc's default of 10 KiB would refuse it).
const MAX_OUT: usize = 268_435_455;

/// A client and its event loop for `set`, registering `will`.
pub(crate) fn new(set: &Settings, will: Will) -> (Client, EventLoop) {
    let keep_alive = set.keep_alive;
    match set.version {
        Version::V311 => {
            let mut o = rumqttc::MqttOptions::new(&set.client_id, &set.host, set.port);
            o.set_keep_alive(keep_alive);
            o.set_clean_session(true);
            o.set_max_packet_size(MAX_IN, MAX_OUT);
            o.set_last_will(rumqttc::LastWill::new(will.topic, will.payload, will.qos, will.retain));
            if let Some(c) = &set.credentials {
                o.set_credentials(c.user(), c.password());
            }
            if let Some(tls) = &set.tls {
                o.set_transport(rumqttc::Transport::tls_with_config(rumqttc::TlsConfiguration::Rustls(
                    tls.clone(),
                )));
            }
            let (c, mut e) = rumqttc::AsyncClient::new(o, set.queue);
            e.set_network_options(network());
            (Client::V311(c), EventLoop::V311(Box::new(e)))
        }
        Version::V5 => {
            let mut o = rumqttc::v5::MqttOptions::new(&set.client_id, &set.host, set.port);
            o.set_keep_alive(keep_alive);
            // Clean start, session expiry 0 (none given): no state kept by the broker.
            o.set_clean_start(true);
            // What the broker may send us; what we send is bounded by the broker's CONNACK.
            o.set_max_packet_size(Some(MAX_IN as u32));
            o.set_network_options(network());
            o.set_last_will(will5(will));
            if let Some(c) = &set.credentials {
                o.set_credentials(c.user(), c.password());
            }
            if let Some(tls) = &set.tls {
                o.set_transport(rumqttc::Transport::tls_with_config(rumqttc::TlsConfiguration::Rustls(
                    tls.clone(),
                )));
            }
            let (c, e) = rumqttc::v5::AsyncClient::new(o, set.queue);
            (Client::V5(c), EventLoop::V5(Box::new(e)))
        }
    }
}

/// TCP_NODELAY: a message goes out when it is queued, not when the
/// broker's (delayed, up to 40 ms) acknowledgement of the last one comes
/// back, as Nagle's algorithm would have it — a Sparkplug DDATA per scan
/// otherwise waits for it.
fn network() -> rumqttc::NetworkOptions {
    let mut n = rumqttc::NetworkOptions::new();
    n.set_tcp_nodelay(true);
    n
}

fn will5(w: Will) -> p5::LastWill {
    p5::LastWill::new(w.topic, w.payload, qos5(w.qos), w.retain, None)
}

/// MQTT 5 properties of a JSON message: UTF-8, `application/json`.
fn json_properties() -> p5::PublishProperties {
    p5::PublishProperties {
        payload_format_indicator: Some(1),
        content_type: Some("application/json".into()),
        ..Default::default()
    }
}

impl Client {
    /// Queues a message without waiting.
    pub fn try_publish(&self, topic: impl Into<String>, qos: QoS, retain: bool, payload: Vec<u8>) -> Result<(), Full> {
        match self {
            Client::V311(c) => c.try_publish(topic, qos, retain, payload).map_err(|_| Full),
            Client::V5(c) => c.try_publish(topic, qos5(qos), retain, payload).map_err(|_| Full),
        }
    }

    /// Queues a JSON message (with MQTT 5: its format and content type said),
    /// and the correlation data of a request it answers.
    pub fn try_publish_json(
        &self,
        topic: impl Into<String>,
        qos: QoS,
        retain: bool,
        payload: String,
        correlation: Option<Vec<u8>>,
    ) -> Result<(), Full> {
        match self {
            Client::V311(c) => c.try_publish(topic, qos, retain, payload).map_err(|_| Full),
            Client::V5(c) => {
                let props = p5::PublishProperties {
                    correlation_data: correlation.map(Into::into),
                    ..json_properties()
                };
                c.try_publish_with_properties(topic, qos5(qos), retain, payload, props)
                    .map_err(|_| Full)
            }
        }
    }

    pub fn try_subscribe(&self, topic: impl Into<String>, qos: QoS) -> Result<(), Full> {
        match self {
            Client::V311(c) => c.try_subscribe(topic, qos).map_err(|_| Full),
            Client::V5(c) => c.try_subscribe(topic, qos5(qos)).map_err(|_| Full),
        }
    }

    pub fn try_disconnect(&self) -> Result<(), Full> {
        match self {
            Client::V311(c) => c.try_disconnect().map_err(|_| Full),
            Client::V5(c) => c.try_disconnect().map_err(|_| Full),
        }
    }
}

impl EventLoop {
    /// The next event; an error is the connection failing or ending (poll
    /// again to reconnect).
    pub async fn poll(&mut self) -> Result<Ev, String> {
        match self {
            EventLoop::V311(e) => match e.poll().await.map_err(|e| e.to_string())? {
                Event::Incoming(Packet::ConnAck(_)) => Ok(Ev::Connected),
                Event::Incoming(Packet::Publish(p)) => Ok(Ev::Message {
                    topic: p.topic,
                    payload: p.payload.to_vec(),
                    reply: None,
                }),
                Event::Outgoing(rumqttc::Outgoing::Disconnect) => Ok(Ev::Left),
                _ => Ok(Ev::Other),
            },
            EventLoop::V5(e) => match e.poll().await.map_err(|e| e.to_string())? {
                rumqttc::v5::Event::Incoming(p5::Packet::ConnAck(_)) => Ok(Ev::Connected),
                rumqttc::v5::Event::Incoming(p5::Packet::Publish(p)) => {
                    let reply = p.properties.and_then(|props| {
                        let topic = props.response_topic?;
                        Some((topic, props.correlation_data.map(|c| c.to_vec())))
                    });
                    Ok(Ev::Message {
                        topic: String::from_utf8_lossy(&p.topic).into_owned(),
                        payload: p.payload.to_vec(),
                        reply,
                    })
                }
                rumqttc::v5::Event::Outgoing(rumqttc::Outgoing::Disconnect) => Ok(Ev::Left),
                _ => Ok(Ev::Other),
            },
        }
    }

    /// Before a reconnection: the next connection's will and password, and
    /// nothing of the old session sent again.
    pub fn renew(&mut self, will: Option<Will>, credentials: Option<(&str, &str)>) {
        match self {
            EventLoop::V311(e) => {
                if let Some(w) = will {
                    e.mqtt_options
                        .set_last_will(rumqttc::LastWill::new(w.topic, w.payload, w.qos, w.retain));
                }
                if let Some((u, p)) = credentials {
                    e.mqtt_options.set_credentials(u, p);
                }
                e.clean();
                e.pending.clear();
            }
            EventLoop::V5(e) => {
                if let Some(w) = will {
                    e.options.set_last_will(will5(w));
                }
                if let Some((u, p)) = credentials {
                    e.options.set_credentials(u, p);
                }
                e.clean();
                e.pending.clear();
            }
        }
    }
}

/// Publishes `payload` on `topic` (the will's message, sent by hand on a
/// clean stop) and disconnects, within half a second.
pub(crate) async fn goodbye(c: &Client, mut eventloop: EventLoop, topic: String, retain: bool, payload: Vec<u8>) {
    let _ = c.try_publish(topic, QoS::AtLeastOnce, retain, payload);
    let _ = tokio::time::timeout(Duration::from_millis(500), async {
        let _ = c.try_disconnect();
        while let Ok(ev) = eventloop.poll().await {
            if matches!(ev, Ev::Left) {
                break;
            }
        }
    })
    .await;
}
