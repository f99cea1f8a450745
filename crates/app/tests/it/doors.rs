//! One set of rules behind every door (issue 32): the same refusals from
//! the HTTP API, MQTT, OPC UA and Modbus TCP, each in its own protocol,
//! and every accepted write in the audit trail with its door and peer.
//!
//! Real clients: reqwest for HTTP, rumqttc through a real Mosquitto,
//! async-opcua's client, Modbus TCP frames on a socket (as
//! crates/modbus/tests do).

use super::{PASSWORD, add_role_users, free_port, options, serve};
use opcua::client::{ClientBuilder, IdentityToken, Session};
use opcua::crypto::SecurityPolicy;
use opcua::types::{AttributeId, DataValue, MessageSecurityMode, NodeId, StatusCode, Variant, WriteValue};
use serde_json::{Value as Json, json};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};

const TAGS: &str = "name,type,address,initial,retain,description\n\
Start,BOOL,%IX0.0,,,\nMotor,BOOL,%QX0.0,,,\nSpeed,INT,,,,\nDelay,TIMER,,,,\n";
const LAD: &str = "XIC(Start)OTE(Motor);\nXIC(Motor)TON(Delay,50,0);\n";

/// The project: Speed and Delay.PRE on holding registers, Start on a
/// discrete input; `viewer`: every door's actor may only read (users with
/// a viewer for HTTP, OPC UA anonymous beside users, `[mqtt] user` a
/// viewer, Modbus read-only).
fn project(test: &str, name: &str, viewer: bool) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-app-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let mqtt_user = if viewer {
        "user = \"viewer\"\npassword_file = \"mqtt.pw\"\n"
    } else {
        ""
    };
    let toml = format!(
        "name = \"{name}\"\nscan_ms = 5\nprograms = [\"main.lad\"]\n\
         [modbus]\nread_only = {viewer}\n[modbus.tags]\nSpeed = \"hr 8192\"\n\"Delay.PRE\" = \"hr 8300\"\nStart = \"di 9000\"\n\
         [mqtt]\n{mqtt_user}"
    );
    std::fs::write(dir.join("alba.toml"), toml).expect("alba.toml");
    std::fs::write(dir.join("tags.csv"), TAGS).expect("tags.csv");
    std::fs::write(dir.join("main.lad"), LAD).expect("main.lad");
    if viewer {
        std::fs::write(dir.join("mqtt.pw"), PASSWORD).expect("mqtt.pw");
        add_role_users(&dir);
    }
    dir
}

struct Plc {
    /// The project's name: its MQTT prefix is `alba/<name>`.
    name: &'static str,
    http: std::net::SocketAddr,
    modbus: std::net::SocketAddr,
    opcua: std::net::SocketAddr,
    client: reqwest::Client,
    /// The bearer token of `admin` (users) or none (no users: loopback has full rights).
    admin: Option<String>,
    /// The bearer token of `viewer`.
    viewer: Option<String>,
    stop: Option<(tokio::sync::oneshot::Sender<()>, tokio::task::JoinHandle<()>)>,
    dir: PathBuf,
}

impl Plc {
    async fn start(test: &str, name: &'static str, viewer: bool, broker: &str) -> Plc {
        let dir = project(test, name, viewer);
        let mut o = options("sim");
        o.quiet = true;
        let modbus: std::net::SocketAddr = format!("127.0.0.1:{}", free_port()).parse().expect("addr");
        let opcua: std::net::SocketAddr = format!("127.0.0.1:{}", free_port()).parse().expect("addr");
        o.modbus = Some(modbus);
        o.opcua = Some(opcua);
        o.mqtt = Some(broker.to_string());
        let (http, stop, task) = serve(&dir, o).await;
        let mut plc = Plc {
            name,
            http,
            modbus,
            opcua,
            client: reqwest::Client::new(),
            admin: None,
            viewer: None,
            stop: Some((stop, task)),
            dir,
        };
        if viewer {
            plc.admin = Some(plc.login("admin").await);
            plc.viewer = Some(plc.login("viewer").await);
        }
        plc
    }

    async fn login(&self, user: &str) -> String {
        crate::login(&self.client, self.http, user).await
    }

    fn req(&self, m: reqwest::Method, path: &str, token: Option<&String>) -> reqwest::RequestBuilder {
        let r = self.client.request(m, format!("http://{}{path}", self.http));
        match token {
            Some(t) => r.bearer_auth(t),
            None => r,
        }
    }

    async fn value(&self, name: &str) -> Json {
        let j: Json = self
            .req(reqwest::Method::GET, &format!("/api/tags/{name}"), self.admin.as_ref())
            .send()
            .await
            .expect("GET tag")
            .json()
            .await
            .expect("JSON");
        j["value"].clone()
    }

    async fn audit(&self) -> Vec<Json> {
        let j: Json = self
            .req(reqwest::Method::GET, "/api/audit?action=write", self.admin.as_ref())
            .send()
            .await
            .expect("GET audit")
            .json()
            .await
            .expect("JSON");
        j["rows"].as_array().unwrap_or_else(|| panic!("{j}")).clone()
    }

    async fn stop(mut self) {
        if let Some((stop, task)) = self.stop.take() {
            let _ = stop.send(());
            tokio::time::timeout(Duration::from_secs(20), task)
                .await
                .expect("stops")
                .expect("task");
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A door's answer to a write, as its protocol says it.
async fn http_write(p: &Plc, name: &str, value: Json, viewer: bool) -> String {
    let token = if viewer { p.viewer.as_ref() } else { p.admin.as_ref() };
    let res = p
        .req(reqwest::Method::PUT, &format!("/api/tags/{name}"), token)
        .json(&json!({ "value": value }))
        .send()
        .await
        .expect("PUT");
    res.status().as_u16().to_string()
}

/// An MQTT client of the broker, subscribed to one PLC's `alba/<name>/error`.
struct Mqtt {
    prefix: String,
    client: rumqttc::AsyncClient,
    errors: tokio::sync::mpsc::UnboundedReceiver<Json>,
}

impl Mqtt {
    async fn connect(broker: &str, p: &Plc) -> Mqtt {
        let prefix = format!("alba/{}", p.name);
        let id = format!("test-{}", p.name);
        let (host, port) = broker.rsplit_once(':').expect("host:port");
        let mut o = rumqttc::MqttOptions::new(id, host, port.parse().expect("port"));
        o.set_keep_alive(Duration::from_secs(5));
        let (client, mut ev) = rumqttc::AsyncClient::new(o, 64);
        let (tx, errors) = tokio::sync::mpsc::unbounded_channel();
        let (up_tx, up) = tokio::sync::oneshot::channel();
        let mut up_tx = Some(up_tx);
        tokio::spawn(async move {
            loop {
                match ev.poll().await {
                    Ok(rumqttc::Event::Incoming(rumqttc::Packet::SubAck(_))) => {
                        if let Some(t) = up_tx.take() {
                            let _ = t.send(());
                        }
                    }
                    Ok(rumqttc::Event::Incoming(rumqttc::Packet::Publish(p))) => {
                        if let Ok(j) = serde_json::from_slice::<Json>(&p.payload) {
                            let _ = tx.send(j);
                        }
                    }
                    Ok(_) => {}
                    Err(_) => break,
                }
            }
        });
        client
            .subscribe(format!("{prefix}/error"), rumqttc::QoS::AtLeastOnce)
            .await
            .expect("subscribe");
        tokio::time::timeout(Duration::from_secs(10), up)
            .await
            .expect("subscribed")
            .expect("subscribed");
        Mqtt { prefix, client, errors }
    }

    /// Publishes `set/<name>`; the refusal on `error`, or "accepted" when
    /// none comes within 2 s.
    async fn write(&mut self, name: &str, value: Json) -> String {
        self.client
            .publish(
                format!("{}/set/{name}", self.prefix),
                rumqttc::QoS::AtLeastOnce,
                false,
                json!({ "value": value }).to_string(),
            )
            .await
            .expect("publish");
        match tokio::time::timeout(Duration::from_secs(2), self.errors.recv()).await {
            Ok(Some(e)) => {
                assert_eq!(e["tag"], name, "{e}");
                e["error"].as_str().unwrap_or_default().to_string()
            }
            _ => "accepted".into(),
        }
    }
}

/// `alba run` subscribes to `set/#` once connected: waits until a write of
/// an unknown tag is answered.
async fn mqtt_ready(m: &mut Mqtt) {
    for _ in 0..50 {
        if m.write("Nope", json!(1)).await != "accepted" {
            return;
        }
    }
    panic!("alba run never answered on MQTT");
}

async fn opcua_session(p: &Plc) -> (Arc<Session>, u16, tokio::task::JoinHandle<StatusCode>) {
    opcua_session_as(p, None).await
}

/// An OPC UA session: anonymous without security (`None`), or as a user
/// over Basic256Sha256 (the only endpoints that take passwords).
async fn opcua_session_as(p: &Plc, user: Option<&str>) -> (Arc<Session>, u16, tokio::task::JoinHandle<StatusCode>) {
    let pki = p.dir.join("client-pki");
    let mut client = ClientBuilder::new()
        .application_name("doors test")
        .application_uri("urn:alba:test")
        .pki_dir(pki)
        .create_sample_keypair(true)
        .trust_server_certs(true)
        .session_retry_limit(0)
        .request_timeout(Duration::from_secs(5))
        .client()
        .expect("OPC UA client");
    let url = format!("opc.tcp://{}/", p.opcua);
    let (policy, mode, identity) = match user {
        None => (
            SecurityPolicy::None,
            MessageSecurityMode::None,
            IdentityToken::Anonymous,
        ),
        Some(u) => (
            SecurityPolicy::Basic256Sha256,
            MessageSecurityMode::SignAndEncrypt,
            IdentityToken::new_user_name(u, PASSWORD),
        ),
    };
    let (session, event_loop) = client
        .connect_to_matching_endpoint((url.as_str(), policy.to_uri(), mode), identity)
        .await
        .expect("OPC UA connect");
    let driver = event_loop.spawn();
    tokio::time::timeout(Duration::from_secs(10), session.wait_for_connection())
        .await
        .expect("the OPC UA session opens");
    let ns = session
        .get_namespace_index(&alba_opcua::namespace_uri(p.name))
        .await
        .expect("Alba's namespace");
    (session, ns, driver)
}

async fn opcua_write(s: &Session, ns: u16, name: &str, v: Variant) -> String {
    let w = WriteValue {
        node_id: NodeId::new(ns, name.to_string()),
        attribute_id: AttributeId::Value as u32,
        value: DataValue::value_only(v),
        ..Default::default()
    };
    match s.write(&[w]).await {
        Ok(codes) => format!("{}", codes.first().copied().unwrap_or(StatusCode::BadUnexpectedError)),
        Err(e) => format!("{e}"),
    }
}

/// Sends one Modbus request; the answer: `ok`, or `exception NN`.
async fn modbus(addr: std::net::SocketAddr, pdu: &[u8]) -> (String, std::net::SocketAddr) {
    let mut s = tokio::net::TcpStream::connect(addr).await.expect("Modbus connect");
    let local = s.local_addr().expect("local address");
    let mut adu = vec![0, 7, 0, 0];
    adu.extend_from_slice(&u16::try_from(pdu.len() + 1).expect("short").to_be_bytes());
    adu.push(1);
    adu.extend_from_slice(pdu);
    s.write_all(&adu).await.expect("send");
    let mut h = [0u8; 7];
    tokio::time::timeout(Duration::from_secs(5), s.read_exact(&mut h))
        .await
        .expect("a Modbus reply")
        .expect("reply header");
    let len = usize::from(u16::from_be_bytes([h[4], h[5]])) - 1;
    let mut body = vec![0u8; len];
    s.read_exact(&mut body).await.expect("reply body");
    let answer = if body[0] & 0x80 != 0 {
        format!("exception {:02}", body[1])
    } else {
        "ok".to_string()
    };
    (answer, local)
}

/// FC16 of `regs` at `start`.
fn fc16(start: u16, regs: &[u16]) -> Vec<u8> {
    let mut p = vec![16];
    p.extend_from_slice(&start.to_be_bytes());
    p.extend_from_slice(&u16::try_from(regs.len()).expect("few").to_be_bytes());
    p.push(u8::try_from(regs.len() * 2).expect("few"));
    for r in regs {
        p.extend_from_slice(&r.to_be_bytes());
    }
    p
}

fn fc5(addr: u16, on: bool) -> Vec<u8> {
    let mut p = vec![5];
    p.extend_from_slice(&addr.to_be_bytes());
    p.extend_from_slice(&[if on { 0xFF } else { 0 }, 0]);
    p
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Refusal {
    UnknownTag,
    InputNotWritable,
    OutOfRange,
    ViewerRole,
}

/// Each door's answer to each refusal: its protocol's words for the same rule.
const EXPECTED: &[(Refusal, &str, &str, &str, &str)] = &[
    // refusal, HTTP status, MQTT error contains, OPC UA status, Modbus answer
    (
        Refusal::UnknownTag,
        "404",
        "unknown",
        "BadNodeIdUnknown",
        "exception 02",
    ),
    (
        Refusal::InputNotWritable,
        "422",
        "is an input",
        // An input's node is read-only in its access levels: async-opcua
        // refuses the write before Alba's rules see it, with that code.
        "BadUserAccessDenied",
        "exception 02",
    ),
    (
        Refusal::OutOfRange,
        "422",
        "cannot be negative",
        "BadOutOfRange",
        "exception 03",
    ),
    (
        Refusal::ViewerRole,
        "403",
        "is a viewer",
        "BadUserAccessDenied",
        "exception 01",
    ),
];

/// The refusal's write: tag and value (JSON, OPC UA variant, Modbus PDU).
fn attempt(r: Refusal) -> (&'static str, Json, Variant, Vec<u8>) {
    match r {
        Refusal::UnknownTag => ("Nope", json!(1), Variant::Int16(1), fc16(9000, &[1])),
        Refusal::InputNotWritable => ("Start", json!(true), Variant::Boolean(true), fc5(9000, true)),
        // -5 as a TIME on two registers, high word first.
        Refusal::OutOfRange => (
            "Delay.PRE",
            json!(-5),
            Variant::Int32(-5),
            fc16(8300, &[0xFFFF, 0xFFFB]),
        ),
        Refusal::ViewerRole => ("Speed", json!(5), Variant::Int16(5), fc16(8192, &[5])),
    }
}

/// The refusals × the four doors, over one PLC whose actors may write and
/// one whose actors may only read (the role refusal).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn every_door_gives_the_same_refusals_in_its_own_protocol() {
    let Some(broker) = alba_testkit::mqtt::Broker::start() else {
        return;
    };
    let writer = Plc::start("doors-refusals", "doors", false, &broker.addr()).await;
    let reader = Plc::start("doors-viewer", "doorsro", true, &broker.addr()).await;
    let mut w_mqtt = Mqtt::connect(&broker.addr(), &writer).await;
    mqtt_ready(&mut w_mqtt).await;
    let mut r_mqtt = Mqtt::connect(&broker.addr(), &reader).await;
    mqtt_ready(&mut r_mqtt).await;
    let (w_ua, w_ns, w_driver) = opcua_session(&writer).await;
    let (r_ua, r_ns, r_driver) = opcua_session(&reader).await;
    let mut got = Vec::new();
    for &(refusal, ..) in EXPECTED {
        let p = if refusal == Refusal::ViewerRole {
            &reader
        } else {
            &writer
        };
        let (ua, ns) = if refusal == Refusal::ViewerRole {
            (&r_ua, r_ns)
        } else {
            (&w_ua, w_ns)
        };
        let (name, value, variant, pdu) = attempt(refusal);
        let http = http_write(p, name, value.clone(), refusal == Refusal::ViewerRole).await;
        let mqtt = if refusal == Refusal::ViewerRole {
            &mut r_mqtt
        } else {
            &mut w_mqtt
        };
        let mqtt_answer = mqtt.write(name, value).await;
        let opcua = opcua_write(ua, ns, name, variant).await;
        let (modbus_answer, _) = modbus(p.modbus, &pdu).await;
        got.push((refusal, http, mqtt_answer, opcua, modbus_answer));
    }
    for ((refusal, http, mqtt_answer, opcua, modbus_answer), want) in got.iter().zip(EXPECTED) {
        assert_eq!(http, want.1, "{refusal:?} over HTTP");
        assert!(
            mqtt_answer.contains(want.2),
            "{refusal:?} over MQTT: `{mqtt_answer}` (wanted `{}`)",
            want.2
        );
        assert!(
            opcua.starts_with(want.3),
            "{refusal:?} over OPC UA: {opcua} (wanted {})",
            want.3
        );
        assert_eq!(modbus_answer, want.4, "{refusal:?} over Modbus");
    }
    // Nothing refused changed the PLC or left an accepted row.
    assert_eq!(writer.value("Speed").await, json!(0));
    assert_eq!(reader.value("Speed").await, json!(0));
    assert!(writer.audit().await.iter().all(|r| r["outcome"] != "ok"));
    let _ = (w_ua.disconnect().await, r_ua.disconnect().await);
    w_driver.abort();
    r_driver.abort();
    writer.stop().await;
    reader.stop().await;
}

/// An FC16 write, an OPC UA write and an MQTT `set/` write each leave a
/// row in `GET /api/audit` with their door and peer.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn writes_through_every_door_are_in_the_audit_trail() {
    let Some(broker) = alba_testkit::mqtt::Broker::start() else {
        return;
    };
    let p = Plc::start("doors-audit", "doorsaudit", false, &broker.addr()).await;
    let (answer, modbus_peer) = modbus(p.modbus, &fc16(8192, &[11])).await;
    assert_eq!(answer, "ok");
    assert_eq!(p.value("Speed").await, json!(11));
    let (ua, ns, driver) = opcua_session(&p).await;
    assert_eq!(opcua_write(&ua, ns, "Speed", Variant::Int16(22)).await, "Good");
    assert_eq!(p.value("Speed").await, json!(22));
    let mut mqtt = Mqtt::connect(&broker.addr(), &p).await;
    mqtt_ready(&mut mqtt).await;
    assert_eq!(mqtt.write("Speed", json!(33)).await, "accepted");
    let mut value = Json::Null;
    for _ in 0..50 {
        value = p.value("Speed").await;
        if value == json!(33) {
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    assert_eq!(value, json!(33), "the MQTT write");
    let rows = p.audit().await;
    let row = |via: &str| {
        rows.iter()
            .find(|r| r["via"] == via && r["target"] == "Speed" && r["outcome"] == "ok")
            .unwrap_or_else(|| panic!("no `{via}` write of Speed in {rows:#?}"))
            .clone()
    };
    let m = row("modbus");
    assert_eq!(m["new"], json!(11));
    assert_eq!(m["addr"], modbus_peer.to_string());
    assert_eq!(m["user"], format!("modbus:{modbus_peer}"));
    let o = row("opcua");
    assert_eq!(o["new"], json!(22));
    assert_eq!(o["user"], "opcua:anonymous");
    let q = row("mqtt");
    assert_eq!(q["new"], json!(33));
    assert_eq!(q["addr"], broker.addr());
    assert_eq!(q["user"], "mqtt");
    let _ = ua.disconnect().await;
    driver.abort();
    p.stop().await;
}

/// An OPC UA user's write is recorded under the user's name
/// (`opcua:<user>`) with the user's role judged by the control layer; the
/// peer stays unknown (docs/audit.md, "Why OPC UA rows have no peer").
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn an_opcua_users_write_names_the_user() {
    let Some(broker) = alba_testkit::mqtt::Broker::start() else {
        return;
    };
    let p = Plc::start("doors-ua-user", "doorsuser", true, &broker.addr()).await;
    let (ua, ns, driver) = opcua_session_as(&p, Some("operator")).await;
    assert_eq!(opcua_write(&ua, ns, "Speed", Variant::Int16(44)).await, "Good");
    assert_eq!(p.value("Speed").await, json!(44));
    let rows = p.audit().await;
    let o = rows
        .iter()
        .find(|r| r["via"] == "opcua" && r["target"] == "Speed")
        .unwrap_or_else(|| panic!("no OPC UA write of Speed in {rows:#?}"));
    assert_eq!(o["user"], "opcua:operator");
    assert_eq!(o["outcome"], "ok");
    assert_eq!(o["new"], json!(44));
    let _ = ua.disconnect().await;
    driver.abort();
    p.stop().await;
}
