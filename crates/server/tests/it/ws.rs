use crate::Server;
use futures_util::{SinkExt, StreamExt};
use reqwest::Method;
use serde_json::{Value as Json, json};
use std::time::Duration;
use tokio_tungstenite::tungstenite::Message;

pub(crate) type Ws = tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// Connects as the studio does: from its own origin.
pub(crate) async fn connect(s: &Server) -> Ws {
    use tokio_tungstenite::tungstenite::client::IntoClientRequest;
    let mut req = format!("ws://{}/api/ws", s.addr)
        .into_client_request()
        .expect("request");
    let origin = format!("http://{}", s.addr).parse().expect("origin");
    req.headers_mut().insert("origin", origin);
    let (ws, _) = tokio_tungstenite::connect_async(req).await.expect("connect");
    ws
}

pub(crate) async fn send(ws: &mut Ws, j: Json) {
    ws.send(Message::Text(j.to_string().into())).await.expect("send");
}

/// The next message of `kind` that satisfies `ok`, within 5 s.
pub(crate) async fn next(ws: &mut Ws, kind: &str, ok: impl Fn(&Json) -> bool) -> Json {
    let deadline = tokio::time::Instant::now() + Duration::from_secs(5);
    loop {
        let m = tokio::time::timeout_at(deadline, ws.next())
            .await
            .unwrap_or_else(|_| panic!("no `{kind}` message in 5 s"))
            .expect("open")
            .expect("message");
        if let Message::Text(t) = m {
            let j: Json = serde_json::from_str(t.as_str()).expect("JSON message");
            if j["type"] == kind && ok(&j) {
                return j;
            }
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn values_are_streamed_on_change_only() {
    let s = Server::start("tank", "wsvalues").await;
    let mut ws = connect(&s).await;
    send(&mut ws, json!({"subscribe": ["Llenar", "CT_STP", "Nivel_L"]})).await;
    let first = next(&mut ws, "values", |_| true).await;
    let v = &first["values"];
    assert_eq!(v["Llenar"], false);
    assert_eq!(v["CT_STP.PRE"], 2);
    assert!(v["Nivel_L"].is_number());
    assert!(first["scan"].is_u64() && first["t_ms"].is_u64());

    s.call(Method::PUT, "/api/tags/Llenar", Some(json!({"value": true})))
        .await;
    let m = next(&mut ws, "values", |j| j["values"].get("Llenar").is_some()).await;
    assert_eq!(m["values"], json!({"Llenar": true}), "only what changed");

    // Status arrives periodically; errors come back as messages.
    let st = next(&mut ws, "status", |_| true).await;
    assert_eq!(st["state"], "running");
    assert_eq!(st["clients"], 1);
    send(&mut ws, json!({"subscribe": ["Nope"]})).await;
    let e = next(&mut ws, "error", |_| true).await;
    assert!(e["error"].as_str().expect("msg").contains("Nope"));
    ws.send(Message::Text("{not json".into())).await.expect("send");
    next(&mut ws, "error", |j| j["error"] == "malformed JSON command").await;
    send(&mut ws, json!({"subscribe": "*"})).await;
    let all = next(&mut ws, "values", |j| j["values"].get("S_ULT").is_some()).await;
    assert!(all["values"].get("CT_STP.ACC").is_some() && all["values"].get("S:SCANTIME").is_some());
    // The server stops although a client is connected.
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn monitoring_streams_power_flow() {
    let s = Server::start("tank", "wspower").await;
    let p = s.get("/api/programs/main.lad").await;
    // Rung 5: XIO(L_STP)OTE(L_RUN): both energised while running.
    let r5 = &p["rungs"][4]["elements"];
    let (xio, ote) = (r5[0]["id"].as_u64().expect("id"), r5[1]["id"].as_u64().expect("id"));
    let mut ws = connect(&s).await;
    send(&mut ws, json!({"monitor": ["nope.lad"]})).await;
    next(&mut ws, "error", |j| j["error"] == "unknown programs: nope.lad").await;
    send(&mut ws, json!({"monitor": ["main.lad"]})).await;
    let on = |j: &Json, id: u64| j["on"].as_array().expect("on").iter().any(|x| x.as_u64() == Some(id));
    let m = next(&mut ws, "power", |j| j["program"] == "main.lad").await;
    assert!(on(&m, xio) && on(&m, ote), "{m}");
    // STOP pressed: L_STP on, so rung 5 goes dead.
    s.call(Method::PUT, "/api/forces/STOP", Some(json!({"value": true})))
        .await;
    let m = next(&mut ws, "power", |j| !on(j, xio)).await;
    assert!(!on(&m, ote), "{m}");
    drop(ws);
    s.stop().await;
}

/// A client that stops reading is disconnected (after its send times out)
/// while the engine and the other clients go on.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_that_does_not_read_is_dropped() {
    // 5 000 tags changing every scan: megabytes per second for a client of "*".
    let dir = crate::copy_example("start-stop", "ws-unread");
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let mut lad = String::new();
    for i in 0..5000 {
        tags.push_str(&format!("T{i},DINT,,,,\n"));
        lad.push_str(&format!("ADD(T{i},1,T{i});\n"));
    }
    std::fs::write(dir.join("tags.csv"), tags).expect("write");
    std::fs::write(dir.join("main.lad"), lad).expect("write");
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"slow\"\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n",
    )
    .expect("write");
    let s = Server::start_in(dir).await;
    let mut stalled = connect(&s).await;
    send(&mut stalled, json!({"subscribe": "*"})).await;
    let mut reader = connect(&s).await;
    send(&mut reader, json!({"subscribe": ["T0"]})).await;
    next(&mut reader, "values", |_| true).await;
    let clients = |j: &Json| j["clients"].as_u64().expect("clients");
    assert_eq!(clients(&s.get("/api/status").await), 2);
    let scans = s.scans().await;
    // `stalled` is never read again: its socket buffers fill, its sends time out.
    let deadline = tokio::time::Instant::now() + Duration::from_secs(60);
    loop {
        // The reading client keeps getting values meanwhile.
        next(&mut reader, "values", |_| true).await;
        if clients(&s.get("/api/status").await) == 1 {
            break;
        }
        assert!(
            tokio::time::Instant::now() < deadline,
            "the stalled client is still connected after 60 s"
        );
    }
    let st = s.get("/api/status").await;
    assert_eq!(st["state"], "running");
    assert!(st["scans"].as_u64().expect("scans") > scans);
    drop(stalled);
    s.stop().await;
}

/// The alarm summary comes when the socket opens and again after a change
/// of an alarm's state (the demo's tank-plant has five alarms: three of
/// the process, two of the runtime's stores).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn alarm_changes_are_pushed() {
    let s = Server::start("tank-plant", "ws-alarms").await;
    let mut ws = connect(&s).await;
    let first = next(&mut ws, "alarms", |_| true).await;
    assert_eq!(first["alarms"], 5, "{first}");
    assert_eq!(first["unacked"], 0, "{first}");
    // The emergency stop's rising edge: forcing STOP on raises `estop`.
    let (code, j) = s
        .call(Method::PUT, "/api/forces/STOP", Some(json!({"value": true})))
        .await;
    assert!(code.is_success(), "{code} {j}");
    let m = next(&mut ws, "alarms", |j| j["unacked"] == 1).await;
    assert_eq!(
        (m["top_unacked"].as_str(), m["top_severity"].as_u64()),
        (Some("estop"), Some(1000)),
        "{m}"
    );
    let (code, j) = s
        .call(Method::POST, "/api/alarms/estop/ack", Some(json!({"comment": "test"})))
        .await;
    assert!(code.is_success(), "{code} {j}");
    next(&mut ws, "alarms", |j| j["unacked"] == 0).await;
    s.stop().await;
}

/// Issue 31: a `subscribe` repeating one name made the server send it once
/// per repetition on every change (64 clients: 2 GB in 15 s). Each value is
/// now sent once, however often and under whatever names it is asked for;
/// a program monitored twice sends its power flow once; the names of one
/// subscription are capped. Counted in messages and keys, not timed.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn repeated_names_are_sent_once_and_subscriptions_are_capped() {
    let s = Server::start("tank", "wsdup").await;
    let mut ws = connect(&s).await;
    let mut names: Vec<Json> = vec![json!("Llenar"); 3000];
    names.extend([json!("CT_STP"), json!("CT_STP.PRE"), json!("CT_STP")]);
    send(&mut ws, json!({ "subscribe": names })).await;
    // Read raw: a JSON parser would merge repeated keys.
    let raw = loop {
        let m = tokio::time::timeout(Duration::from_secs(5), ws.next())
            .await
            .expect("a message")
            .expect("open")
            .expect("message");
        if let Message::Text(t) = m
            && t.as_str().starts_with("{\"type\":\"values\"")
        {
            break t.as_str().to_string();
        }
    };
    assert_eq!(
        raw.matches("\"Llenar\":").count(),
        1,
        "each value once: {}",
        &raw[..raw.len().min(300)]
    );
    let first: Json = serde_json::from_str(&raw).expect("JSON");
    let keys: Vec<&String> = first["values"].as_object().expect("values").keys().collect();
    let members = keys.iter().filter(|k| k.starts_with("CT_STP.")).count();
    assert_eq!(keys.len(), 1 + members, "each value once: {keys:?}");
    assert_eq!(keys.iter().filter(|k| **k == "Llenar").count(), 1);
    s.call(Method::PUT, "/api/tags/Llenar", Some(json!({"value": true})))
        .await;
    let m = next(&mut ws, "values", |j| j["values"].get("Llenar").is_some()).await;
    assert_eq!(m["values"], json!({"Llenar": true}));

    // One program monitored 200 times: at most one power message per scan,
    // counted over the messages up to the third status message.
    send(&mut ws, json!({ "monitor": vec![json!("main.lad"); 200] })).await;
    let mut per_scan: std::collections::HashMap<u64, usize> = std::collections::HashMap::new();
    let mut statuses = 0;
    while statuses < 3 {
        let m = tokio::time::timeout(Duration::from_secs(5), ws.next())
            .await
            .expect("a message")
            .expect("open")
            .expect("message");
        let Message::Text(t) = m else { continue };
        let j: Json = serde_json::from_str(t.as_str()).expect("JSON");
        match j["type"].as_str() {
            Some("power") => *per_scan.entry(j["scan"].as_u64().expect("scan")).or_default() += 1,
            Some("status") => statuses += 1,
            _ => {}
        }
    }
    assert!(!per_scan.is_empty(), "no power flow at all");
    assert!(
        per_scan.values().all(|&n| n == 1),
        "power sent more than once per scan: {per_scan:?}"
    );

    // More names than a subscription may list: refused, nothing followed.
    let many: Vec<Json> = (0..=4096).map(|i| json!(format!("T{i}"))).collect();
    send(&mut ws, json!({ "monitor": [] })).await;
    send(&mut ws, json!({ "subscribe": many })).await;
    let e = next(&mut ws, "error", |_| true).await;
    assert!(e["error"].as_str().expect("msg").contains("at most 4096"), "{e}");
    // The PLC scanned all along.
    s.wait_scans(5).await;
    s.stop().await;
}
