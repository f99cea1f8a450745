//! `[[opcua_server]]` (docs/protocols.md, "OPC UA client I/O"): one `alba
//! run` serves OPC UA on loopback, another binds tags to its nodes. Read
//! (a monitored item), write on change, the server stopped (inputs held,
//! `S:IOOK` false, the health says why) and restarted (recovery, outputs
//! written again).

use super::{options, serve};
use serde_json::Value as Json;
use std::path::{Path, PathBuf};
use std::time::Duration;

fn copy_dir(src: &Path, test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-app-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    for e in std::fs::read_dir(src).expect("fixture dir") {
        let e = e.expect("entry");
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.join(e.file_name())).expect("copy");
        }
    }
    dir
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .expect("bind")
        .local_addr()
        .expect("addr")
        .port()
}

async fn tag(addr: std::net::SocketAddr, name: &str) -> Json {
    let v: Json = reqwest::get(format!("http://{addr}/api/tags/{name}"))
        .await
        .expect("GET tag")
        .json()
        .await
        .expect("JSON");
    v["value"].clone()
}

async fn put(addr: std::net::SocketAddr, name: &str, value: Json) {
    let res = reqwest::Client::new()
        .put(format!("http://{addr}/api/tags/{name}"))
        .json(&serde_json::json!({ "value": value }))
        .send()
        .await
        .expect("PUT tag");
    assert_eq!(res.status(), reqwest::StatusCode::OK, "PUT {name}");
}

/// Polls `name` (up to 20 s) until `want` holds for its value.
async fn until(addr: std::net::SocketAddr, name: &str, what: &str, want: impl Fn(&Json) -> bool) -> Json {
    let mut last = Json::Null;
    for _ in 0..200 {
        last = tag(addr, name).await;
        if want(&last) {
            return last;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!("{name} never became {what} (last {last})");
}

async fn stop(stop: tokio::sync::oneshot::Sender<()>, task: tokio::task::JoinHandle<()>) {
    let _ = stop.send(());
    tokio::time::timeout(Duration::from_secs(20), task)
        .await
        .expect("stops")
        .expect("task");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn binds_tags_to_albas_own_opcua_server_and_recovers_from_its_restart() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/protocols/plant");
    let server_dir = copy_dir(&fixture, "opcua-srv");
    let port = free_port();
    let mut sopts = options("sim");
    sopts.opcua = Some(format!("127.0.0.1:{port}").parse().expect("addr"));
    let (saddr, sstop, stask) = serve(&server_dir, sopts).await;

    let client_dir = std::env::temp_dir().join(format!("alba-app-opcua-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&client_dir);
    std::fs::create_dir_all(&client_dir).expect("dir");
    let ns = "nsu=urn:alba:modbus-plant;s=";
    std::fs::write(
        client_dir.join("alba.toml"),
        format!(
            "name = \"opcua-client\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n\n\
             [[opcua_server]]\nname = \"plant\"\nendpoint = \"opc.tcp://127.0.0.1:{port}/\"\npublishing_interval_ms = 50\n\
             bind = [\n  {{ tag = \"ScansIn\", node = \"{ns}Scans\", dir = \"in\" }},\n  {{ tag = \"TempIn\", node = \"{ns}Temp\", dir = \"in\" }},\n  \
             {{ tag = \"SpeedOut\", node = \"{ns}Speed\", dir = \"out\" }},\n]\n"
        ),
    )
    .expect("toml");
    std::fs::write(
        client_dir.join("tags.csv"),
        "name,type,address,initial,retain,description\nScansIn,DINT,,,,\nTempIn,LREAL,,,,\nSpeedOut,DINT,,,,\nCopy,DINT,,,,\n",
    )
    .expect("tags");
    std::fs::write(client_dir.join("main.lad"), "ADD(ScansIn,0,Copy);\n").expect("program");
    let (caddr, cstop, ctask) = serve(&client_dir, options("sim")).await;

    // Browse (the tag picker's source): the Tags folder lists the server's tags.
    let text = std::fs::read_to_string(client_dir.join("alba.toml")).expect("toml");
    let (mut config, diags) = alba_project::config::Config::parse(&text, alba_diag::FileId(0));
    assert!(diags.is_empty(), "{diags:?}");
    let server = config.take().expect("config").opcua_servers.remove(0);
    let children = alba_opcua::client::browse_server(
        &server,
        &client_dir,
        "nsu=urn:alba:modbus-plant;s=Alba/modbus-plant/Tags",
    )
    .await
    .expect("browse");
    let names: Vec<&str> = children.iter().map(|c| c.browse_name.as_str()).collect();
    assert!(names.contains(&"Scans") && names.contains(&"Delay"), "{names:?}");
    assert!(
        children
            .iter()
            .any(|c| c.node.ends_with("s=Speed") && c.class == "Variable"),
        "{children:?}"
    );

    // Read through the subscription: the server's scan counter moves here.
    until(caddr, "S:IOOK", "true", |v| *v == Json::Bool(true)).await;
    let first = until(caddr, "ScansIn", "> 0", |v| v.as_i64().unwrap_or(0) > 0).await;
    until(caddr, "ScansIn", "moving", |v| v.as_i64() > first.as_i64()).await;
    // A REAL on the server feeds an LREAL here (converted).
    put(saddr, "Temp", serde_json::json!(21.5)).await;
    until(caddr, "TempIn", "21.5", |v| v.as_f64() == Some(21.5)).await;
    // Write on change: the client's output reaches the server's node.
    put(caddr, "SpeedOut", serde_json::json!(1234)).await;
    until(saddr, "Speed", "1234", |v| v.as_i64() == Some(1234)).await;
    put(caddr, "SpeedOut", serde_json::json!(77)).await;
    until(saddr, "Speed", "77", |v| v.as_i64() == Some(77)).await;

    // The server goes away: the link is down, the inputs hold their values.
    stop(sstop, stask).await;
    until(caddr, "S:IOOK", "false", |v| *v == Json::Bool(false)).await;
    let held = tag(caddr, "ScansIn").await;
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(tag(caddr, "ScansIn").await, held, "an input keeps its last value");
    let errors = tag(caddr, "S:IOERRORS").await;
    assert!(
        errors.as_i64().unwrap_or(0) >= 1,
        "S:IOERRORS counts the loss: {errors}"
    );

    // It comes back (Speed starts at 0 there): recovery, and the output is written again.
    let mut sopts = options("sim");
    sopts.opcua = Some(format!("127.0.0.1:{port}").parse().expect("addr"));
    let (saddr, sstop, stask) = serve(&server_dir, sopts).await;
    until(caddr, "S:IOOK", "true again", |v| *v == Json::Bool(true)).await;
    until(saddr, "Speed", "77 again", |v| v.as_i64() == Some(77)).await;
    let before = tag(caddr, "ScansIn").await;
    until(caddr, "ScansIn", "moving again", |v| v != &before).await;

    stop(cstop, ctask).await;
    // Stopping the client wrote the safe value (0) to its output.
    until(saddr, "Speed", "0 (safe)", |v| v.as_i64() == Some(0)).await;
    stop(sstop, stask).await;
    let _ = std::fs::remove_dir_all(&server_dir);
    let _ = std::fs::remove_dir_all(&client_dir);
}
