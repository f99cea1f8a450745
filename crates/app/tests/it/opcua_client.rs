//! `[[opcua_server]]` (docs/protocols.md, "OPC UA client I/O"): one `alba
//! run` serves OPC UA on loopback, another binds tags to its nodes. Read
//! (a monitored item), write on change, the server stopped (inputs held,
//! `S:IOOK` false, the health says why) and restarted (recovery, outputs
//! written again).

use super::{free_port, options, serve};
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

/// Polls `name` (up to 60 s: the first connection makes the client's certificate) until `want` holds for its value.
async fn until(addr: std::net::SocketAddr, name: &str, what: &str, want: impl Fn(&Json) -> bool) -> Json {
    let mut last = Json::Null;
    for _ in 0..600 {
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
    let (mut config, diags) = alba_settings::Settings::parse(&text, alba_diag::FileId(0));
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

/// `GET /api/status` of `addr` as `token` (none when empty: a project without users).
async fn status(http: &reqwest::Client, addr: std::net::SocketAddr, token: &str) -> Json {
    let req = http.get(format!("http://{addr}/api/status"));
    let req = if token.is_empty() { req } else { req.bearer_auth(token) };
    req.send().await.expect("GET status").json().await.expect("JSON")
}

/// Polls the first connection of `/api/status` (up to 60 s) until `want` holds.
async fn until_conn(
    http: &reqwest::Client,
    addr: std::net::SocketAddr,
    token: &str,
    what: &str,
    want: impl Fn(&Json) -> bool,
) -> Json {
    let mut last = Json::Null;
    for _ in 0..600 {
        last = status(http, addr, token).await["connections"][0].clone();
        if want(&last) {
            return last;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!("the connection never became {what} (last {last})");
}

/// `GET /api/opcua/{server}/browse[?node=…]` as `token`: status and body.
async fn browse(
    http: &reqwest::Client,
    addr: std::net::SocketAddr,
    token: &str,
    server: &str,
    node: Option<&str>,
) -> (reqwest::StatusCode, Json) {
    let mut req = http
        .get(format!("http://{addr}/api/opcua/{server}/browse"))
        .bearer_auth(token);
    if let Some(n) = node {
        req = req.query(&[("node", n)]);
    }
    let res = req.send().await.expect("GET browse");
    let code = res.status();
    (code, res.json().await.expect("JSON"))
}

/// The child of a browse reply whose browse name is `name`.
fn child<'a>(reply: &'a Json, name: &str) -> &'a Json {
    reply["children"]
        .as_array()
        .and_then(|c| c.iter().find(|x| x["browse_name"] == name))
        .unwrap_or_else(|| panic!("no child {name} in {reply}"))
}

/// The API of the client connections (docs/api.md): each connection's
/// health in `/api/status` through a stop and a restart of the remote
/// server, and browsing it from the studio's tag picker (engineers only).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn status_shows_each_connections_health_and_browse_walks_the_remote_address_space() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/protocols/plant");
    let server_dir = copy_dir(&fixture, "opcua-health-srv");
    let port = free_port();
    let mut sopts = options("sim");
    sopts.opcua = Some(format!("127.0.0.1:{port}").parse().expect("addr"));
    let (_, sstop, stask) = serve(&server_dir, sopts).await;

    let client_dir = std::env::temp_dir().join(format!("alba-app-opcua-health-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&client_dir);
    std::fs::create_dir_all(&client_dir).expect("dir");
    let endpoint = format!("opc.tcp://127.0.0.1:{port}/");
    std::fs::write(
        client_dir.join("alba.toml"),
        format!(
            "name = \"opcua-health\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n\n\
             [[opcua_server]]\nname = \"plant\"\nendpoint = \"{endpoint}\"\npublishing_interval_ms = 50\n\
             bind = [{{ tag = \"ScansIn\", node = \"nsu=urn:alba:modbus-plant;s=Scans\", dir = \"in\" }}]\n"
        ),
    )
    .expect("toml");
    std::fs::write(
        client_dir.join("tags.csv"),
        "name,type,address,initial,retain,description\nScansIn,DINT,,,,\nCopy,DINT,,,,\n",
    )
    .expect("tags");
    std::fs::write(client_dir.join("main.lad"), "ADD(ScansIn,0,Copy);\n").expect("program");
    let mut users = alba_auth::Users::default();
    let password = "a long test password 7";
    users.add("eng", alba_auth::Role::Engineer, password).expect("engineer");
    users.add("view", alba_auth::Role::Viewer, password).expect("viewer");
    users.save(&client_dir).expect("users.toml");
    let (caddr, cstop, ctask) = serve(&client_dir, options("sim")).await;
    let http = reqwest::Client::new();
    let login = |user: &'static str| {
        let http = http.clone();
        async move {
            let j: Json = http
                .post(format!("http://{caddr}/api/login"))
                .json(&serde_json::json!({"user": user, "password": password}))
                .send()
                .await
                .expect("login")
                .json()
                .await
                .expect("JSON");
            j["token"].as_str().expect("token").to_string()
        }
    };
    let (eng, view) = (login("eng").await, login("view").await);

    // Connected: the status says so, its other fields as before.
    let c = until_conn(&http, caddr, &view, "ok", |c| c["ok"] == true).await;
    assert_eq!(c["name"], "plant");
    assert_eq!(c["protocol"], "opcua");
    assert_eq!(c["endpoint"], endpoint.as_str());
    assert_eq!(
        (&c["connected"], &c["connects"], &c["last_error"]),
        (&Json::Bool(true), &serde_json::json!(1), &Json::Null),
        "{c}"
    );
    let s = status(&http, caddr, &view).await;
    assert_eq!(s["project"], "opcua-health");
    assert_eq!(s["connections"].as_array().map(Vec::len), Some(1), "{s}");
    assert!(
        s["state"].is_string() && s["stats"].is_object() && s["forces"].is_array(),
        "{s}"
    );

    // Browse from the Objects folder (the default) down to a variable.
    let (code, objects) = browse(&http, caddr, &eng, "plant", None).await;
    assert_eq!(code, reqwest::StatusCode::OK, "{objects}");
    assert_eq!(
        (&objects["server"], &objects["node"]),
        (&serde_json::json!("plant"), &serde_json::json!("i=85"))
    );
    assert_eq!(child(&objects, "Server")["node"], "i=2253");
    let alba = child(&objects, "Alba");
    assert_eq!(alba["class"], "Object");
    assert_eq!(alba["node_uri"], "nsu=urn:alba:modbus-plant;s=Alba");
    let mut at = alba["node_uri"].as_str().expect("node").to_string();
    for name in ["modbus-plant", "Tags"] {
        let (code, r) = browse(&http, caddr, &eng, "plant", Some(&at)).await;
        assert_eq!(code, reqwest::StatusCode::OK, "{r}");
        at = child(&r, name)["node"].as_str().expect("node").to_string();
    }
    let (code, tags) = browse(&http, caddr, &eng, "plant", Some(&at)).await;
    assert_eq!(code, reqwest::StatusCode::OK, "{tags}");
    let speed = child(&tags, "Speed");
    assert_eq!(speed["class"], "Variable");
    assert_eq!(speed["data_type"], "Int32");
    assert_eq!(speed["node_uri"], "nsu=urn:alba:modbus-plant;s=Speed");
    assert!(
        speed["node"]
            .as_str()
            .is_some_and(|n| n.starts_with("ns=") && n.ends_with(";s=Speed")),
        "{speed}"
    );
    assert_eq!(child(&tags, "Temp")["data_type"], "Float");
    // Refusals: an unknown server, a node that is not a node id, a viewer.
    let (code, r) = browse(&http, caddr, &eng, "nope", None).await;
    assert_eq!(code, reqwest::StatusCode::NOT_FOUND, "{r}");
    assert!(r["error"].as_str().is_some_and(|e| e.contains("`nope`")), "{r}");
    let (code, r) = browse(&http, caddr, &eng, "plant", Some("not a node")).await;
    assert_eq!(code, reqwest::StatusCode::BAD_REQUEST, "{r}");
    let (code, r) = browse(&http, caddr, &view, "plant", None).await;
    assert_eq!(code, reqwest::StatusCode::FORBIDDEN, "{r}");

    // The remote server stops: not ok, why, and browsing says it cannot reach it.
    stop(sstop, stask).await;
    let c = until_conn(&http, caddr, &view, "not ok", |c| c["ok"] == false).await;
    assert_eq!(c["connected"], false, "{c}");
    assert!(c["last_error"].as_str().is_some_and(|e| !e.is_empty()), "{c}");
    assert!(c["errors"].as_u64().unwrap_or(0) >= 1, "{c}");
    let (code, r) = browse(&http, caddr, &eng, "plant", None).await;
    assert_eq!(code, reqwest::StatusCode::BAD_GATEWAY, "{r}");
    let e = r["error"].as_str().unwrap_or_default();
    assert!(e.contains("plant") && e.contains(&endpoint), "{r}");

    // It comes back: ok again, on a new session.
    let mut sopts = options("sim");
    sopts.opcua = Some(format!("127.0.0.1:{port}").parse().expect("addr"));
    let (_, sstop, stask) = serve(&server_dir, sopts).await;
    let c = until_conn(&http, caddr, &view, "ok again", |c| c["ok"] == true).await;
    assert!(c["connects"].as_u64().unwrap_or(0) >= 2, "{c}");
    assert_eq!(c["last_error"], Json::Null, "{c}");
    let (code, r) = browse(&http, caddr, &eng, "plant", None).await;
    assert_eq!(code, reqwest::StatusCode::OK, "{r}");

    stop(cstop, ctask).await;
    stop(sstop, stask).await;
    let _ = std::fs::remove_dir_all(&server_dir);
    let _ = std::fs::remove_dir_all(&client_dir);
}

/// The one `.der` file of `dir` (waits up to 60 s for it to appear).
async fn one_cert(dir: &Path) -> PathBuf {
    for _ in 0..600 {
        let found: Vec<PathBuf> = std::fs::read_dir(dir)
            .map(|d| d.flatten().map(|e| e.path()).collect())
            .unwrap_or_default();
        if let [one] = found.as_slice() {
            return one.clone();
        }
        assert!(
            found.len() < 2,
            "one certificate expected in {}: {found:?}",
            dir.display()
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!("no certificate appeared in {}", dir.display());
}

/// Moves the certificate that landed in `pki/rejected/` to `pki/trusted/`.
async fn trust(pki: &Path) {
    let rejected = one_cert(&pki.join("rejected")).await;
    let name = rejected.file_name().expect("name");
    std::fs::create_dir_all(pki.join("trusted")).expect("trusted/");
    std::fs::rename(&rejected, pki.join("trusted").join(name)).expect("trust");
}

/// Security against Alba's own server where other machines reach it (bound
/// to 0.0.0.0: Basic256Sha256 only, a user required, unknown client
/// certificates refused): each refusal in turn — the client's certificate
/// by the server, the server's by the client, a wrong password — is
/// `S:IOOK` false with the reason in `/api/status`, and each is corrected
/// while both keep running (a certificate moved to `trusted/`, the password
/// file fixed) until values flow.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn albas_own_secure_server_refuses_untrusted_certificates_and_a_wrong_password_until_corrected() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/protocols/plant");
    let server_dir = copy_dir(&fixture, "opcua-sec-srv");
    let password = "a long test password 7";
    let mut users = alba_auth::Users::default();
    users.add("op", alba_auth::Role::Operator, password).expect("operator");
    users.save(&server_dir).expect("users.toml");
    let port = free_port();
    let mut sopts = options("sim");
    sopts.opcua = Some(format!("0.0.0.0:{port}").parse().expect("addr"));
    let (_, sstop, stask) = serve(&server_dir, sopts).await;

    let client_dir = std::env::temp_dir().join(format!("alba-app-opcua-sec-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&client_dir);
    std::fs::create_dir_all(&client_dir).expect("dir");
    std::fs::write(
        client_dir.join("alba.toml"),
        format!(
            "name = \"opcua-secure\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n\n\
             [[opcua_server]]\nname = \"plant\"\nendpoint = \"opc.tcp://127.0.0.1:{port}/\"\n\
             security_policy = \"Basic256Sha256\"\nsecurity_mode = \"SignAndEncrypt\"\n\
             user = \"op\"\npassword_file = \"plant-password.txt\"\npublishing_interval_ms = 50\n\
             bind = [{{ tag = \"ScansIn\", node = \"nsu=urn:alba:modbus-plant;s=Scans\", dir = \"in\" }}]\n"
        ),
    )
    .expect("toml");
    let wrong = "not the password";
    std::fs::write(client_dir.join("plant-password.txt"), format!("{wrong}\n")).expect("password");
    std::fs::write(
        client_dir.join("tags.csv"),
        "name,type,address,initial,retain,description\nScansIn,DINT,,,,\nCopy,DINT,,,,\n",
    )
    .expect("tags");
    std::fs::write(client_dir.join("main.lad"), "ADD(ScansIn,0,Copy);\n").expect("program");
    let (caddr, cstop, ctask) = serve(&client_dir, options("sim")).await;
    let http = reqwest::Client::new();
    let down_for = |why: &'static str| {
        let http = http.clone();
        async move {
            let c = until_conn(&http, caddr, "", why, |c| {
                c["last_error"].as_str().is_some_and(|e| e.contains(why))
            })
            .await;
            assert_eq!(
                (&c["ok"], &c["connected"]),
                (&Json::Bool(false), &Json::Bool(false)),
                "{c}"
            );
            assert_eq!(tag(caddr, "S:IOOK").await, Json::Bool(false), "{c}");
            assert!(
                !c.to_string().contains(password) && !c.to_string().contains(wrong),
                "{c}"
            );
            c
        }
    };

    // 1. The server does not know the client's certificate: refused
    //    (`BadCertificateUntrusted` the first time, then
    //    `BadSecurityChecksFailed` while it stays in the server's
    //    pki/rejected/) until an administrator trusts it.
    let server_pki = server_dir.join(".alba/pki");
    down_for("BadSecurityChecksFailed").await;
    trust(&server_pki).await;

    // 2. The client does not know the server's certificate: refused, kept
    //    in the client's pki-client/rejected/.
    let client_pki = client_dir.join(".alba/pki-client");
    down_for("BadCertificateUntrusted").await;
    trust(&client_pki).await;

    // 3. Both certificates trusted, the password is wrong.
    down_for("wrong user name or password").await;
    assert_eq!(tag(caddr, "ScansIn").await, Json::from(0), "nothing read yet");

    // Corrected: the next attempt (no restart) logs in and values flow.
    std::fs::write(client_dir.join("plant-password.txt"), format!("{password}\n")).expect("password");
    let c = until_conn(&http, caddr, "", "ok", |c| c["ok"] == true).await;
    assert_eq!(
        (&c["connected"], &c["last_error"]),
        (&Json::Bool(true), &Json::Null),
        "{c}"
    );
    assert!(c["errors"].as_u64().unwrap_or(0) >= 3, "each refusal counted: {c}");
    until(caddr, "S:IOOK", "true", |v| *v == Json::Bool(true)).await;
    let first = until(caddr, "ScansIn", "> 0", |v| v.as_i64().unwrap_or(0) > 0).await;
    until(caddr, "ScansIn", "moving", |v| v.as_i64() > first.as_i64()).await;

    stop(cstop, ctask).await;
    stop(sstop, stask).await;
    let _ = std::fs::remove_dir_all(&server_dir);
    let _ = std::fs::remove_dir_all(&client_dir);
}
