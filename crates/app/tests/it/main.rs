//! `alba_app::run` assembles and stops `alba run`.

mod doors;
mod hardware;
mod opcua_client;
mod store;
mod verify;

use std::path::{Path, PathBuf};
use std::time::Duration;

fn copy_example(name: &str, test: &str) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name);
    let dir = std::env::temp_dir().join(format!("alba-app-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    for e in std::fs::read_dir(&src).expect("example dir") {
        let e = e.expect("entry");
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.join(e.file_name())).expect("copy");
        }
    }
    dir
}

/// A loopback port free a moment ago (for servers that take a port, not a listener).
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .expect("bind")
        .local_addr()
        .expect("addr")
        .port()
}

/// The password of the test users (every role).
const PASSWORD: &str = "a long test password 7";

/// A user of each role in `dir`'s users.toml, named after the role, with [`PASSWORD`].
fn add_role_users(dir: &Path) {
    let mut users = alba_auth::Users::default();
    for r in alba_auth::Role::ALL {
        users.add(r.as_str(), r, PASSWORD).expect("add user");
    }
    users.save(dir).expect("users.toml");
}

/// Signs `user` in over `http`: its session token.
async fn login(client: &reqwest::Client, http: std::net::SocketAddr, user: &str) -> String {
    let j: serde_json::Value = client
        .post(format!("http://{http}/api/login"))
        .json(&serde_json::json!({"user": user, "password": PASSWORD}))
        .send()
        .await
        .expect("login")
        .json()
        .await
        .expect("login JSON");
    j["token"]
        .as_str()
        .unwrap_or_else(|| panic!("login {user}: {j}"))
        .to_string()
}

fn options(io: &str) -> alba_app::Options {
    alba_app::Options {
        addr: "127.0.0.1:0".parse().expect("addr"),
        io: io.into(),
        native: false,
        modbus: None,
        opcua: None,
        mqtt: None,
        tls: alba_app::tls::Tls::Auto,
        scan_log: None,
        quiet: false,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_unknown_io_driver_is_refused_before_anything_starts() {
    let dir = copy_example("tank", "badio");
    let r = alba_app::run(&dir, options("nope"), |_| panic!("not ready"), async {}).await;
    match r {
        Err(alba_app::RunError::Other(m)) => assert!(m.contains("unknown I/O driver `nope`"), "{m}"),
        _ => panic!("expected an error"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn one_shutdown_signal_stops_every_service() {
    let dir = copy_example("tank", "stop");
    let mut opts = options("sim");
    opts.modbus = Some("127.0.0.1:0".parse().expect("addr"));
    let (ready_tx, ready_rx) = tokio::sync::oneshot::channel();
    let (stop, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let d = dir.clone();
    let task = tokio::spawn(async move {
        alba_app::run(
            &d,
            opts,
            move |a| {
                let _ = ready_tx.send(a);
            },
            async move {
                let _ = stop_rx.await;
            },
        )
        .await
        .is_ok()
    });
    let addr = ready_rx.await.expect("ready");
    tokio::net::TcpStream::connect(addr).await.expect("the API serves");
    let _ = stop.send(());
    let ok = tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("stops within 10 s")
        .expect("task");
    assert!(ok);
    assert!(dir.join(".alba").exists(), "retentive data and history kept in .alba");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `alba run` with `opts` on `dir` until the returned sender fires; its address.
async fn serve(
    dir: &Path,
    opts: alba_app::Options,
) -> (
    std::net::SocketAddr,
    tokio::sync::oneshot::Sender<()>,
    tokio::task::JoinHandle<()>,
) {
    let (ready_tx, ready_rx) = tokio::sync::oneshot::channel();
    let (stop, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let d = dir.to_path_buf();
    let task = tokio::spawn(async move {
        let r = alba_app::run(
            &d,
            opts,
            move |a| {
                let _ = ready_tx.send(a);
            },
            async move {
                let _ = stop_rx.await;
            },
        )
        .await;
        if let Err(alba_app::RunError::Other(m)) = r {
            panic!("{m}");
        }
    });
    (ready_rx.await.expect("ready"), stop, task)
}

/// A client trusting only `cert` (PEM).
fn client_trusting(cert: &Path) -> reqwest::Client {
    let pem = std::fs::read(cert).expect("certificate");
    reqwest::Client::builder()
        .add_root_certificate(reqwest::Certificate::from_pem(&pem).expect("pem"))
        .build()
        .expect("client")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn https_with_a_self_signed_certificate_made_on_first_run() {
    let dir = copy_example("tank", "tls");
    let mut opts = options("sim");
    opts.tls = alba_app::tls::Tls::Always;
    let (addr, stop, task) = serve(&dir, opts).await;
    let (cert, key) = alba_app::tls::self_signed_paths(&dir);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&key).expect("key").permissions().mode();
        assert_eq!(mode & 0o777, 0o600, "the key is its owner's only");
    }
    let https = client_trusting(&cert);
    for host in ["localhost", "127.0.0.1"] {
        let url = format!("https://{host}:{}/api/status", addr.port());
        let res = https.get(&url).send().await.expect("HTTPS");
        assert_eq!(res.status(), reqwest::StatusCode::OK, "{url}");
        assert!(res.headers().contains_key("content-security-policy"));
    }
    // No plain HTTP on that port.
    let plain = reqwest::Client::new()
        .get(format!("http://{addr}/api/status"))
        .send()
        .await;
    assert!(
        plain.is_err() || !plain.expect("answer").status().is_success(),
        "plain HTTP refused"
    );
    // A client that does not trust the certificate refuses the server.
    let untrusting = reqwest::Client::builder().build().expect("client");
    assert!(
        untrusting
            .get(format!("https://localhost:{}/api/status", addr.port()))
            .send()
            .await
            .is_err()
    );
    let _ = stop.send(());
    tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("stops")
        .expect("task");

    // The next run keeps the certificate.
    let before = std::fs::read(&cert).expect("cert");
    let mut opts = options("sim");
    opts.tls = alba_app::tls::Tls::Always;
    let (addr, stop, task) = serve(&dir, opts).await;
    assert_eq!(std::fs::read(&cert).expect("cert"), before);
    let res = https
        .get(format!("https://localhost:{}/api/status", addr.port()))
        .send()
        .await
        .expect("HTTPS");
    assert_eq!(res.status(), reqwest::StatusCode::OK);
    let _ = stop.send(());
    tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("stops")
        .expect("task");
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn https_with_the_users_certificate() {
    let dir = copy_example("tank", "tls-own");
    let (cert, key) = (dir.join("own-cert.pem"), dir.join("own-key.pem"));
    alba_app::tls::make_self_signed(
        &cert,
        &key,
        "127.0.0.1:0".parse().expect("addr"),
        &["plc1.example".into()],
    )
    .expect("cert");
    let toml = std::fs::read_to_string(dir.join("alba.toml")).expect("toml");
    std::fs::write(
        dir.join("alba.toml"),
        format!("{toml}\n[http]\ncert = \"own-cert.pem\"\nkey = \"own-key.pem\"\n"),
    )
    .expect("write");
    let mut opts = options("sim");
    opts.tls = alba_app::tls::Tls::Always;
    let (addr, stop, task) = serve(&dir, opts).await;
    assert!(
        !alba_app::tls::self_signed_paths(&dir).0.exists(),
        "no certificate made"
    );
    let res = client_trusting(&cert)
        .get(format!("https://localhost:{}/api/status", addr.port()))
        .send()
        .await
        .expect("HTTPS with the user's certificate");
    assert_eq!(res.status(), reqwest::StatusCode::OK);
    let _ = stop.send(());
    tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("stops")
        .expect("task");
    // A missing key file is a clear error before anything is served.
    std::fs::remove_file(&key).expect("rm");
    let mut opts = options("sim");
    opts.tls = alba_app::tls::Tls::Always;
    let r = alba_app::run(&dir, opts, |_| panic!("not ready"), async {}).await;
    match r {
        Err(alba_app::RunError::Other(m)) => assert!(m.contains("own-key.pem") && m.contains("private key"), "{m}"),
        _ => panic!("expected an error"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn https_beyond_loopback_unless_explicitly_insecure() {
    use alba_app::tls::{Tls, https};
    let a = |s: &str| s.parse::<std::net::SocketAddr>().expect("addr");
    assert!(!https(Tls::Auto, a("127.0.0.1:8080"), false));
    assert!(!https(Tls::Auto, a("[::1]:8080"), false));
    assert!(https(Tls::Auto, a("0.0.0.0:8080"), false));
    assert!(https(Tls::Auto, a("192.168.1.5:8080"), false));
    assert!(!https(Tls::Auto, a("0.0.0.0:8080"), true), "[http] insecure = true");
    assert!(!https(Tls::Never, a("0.0.0.0:8080"), false), "--insecure-http");
    assert!(https(Tls::Always, a("127.0.0.1:8080"), false), "--https");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_listener_beyond_loopback_serves_https_unless_insecure_is_set() {
    let dir = copy_example("tank", "tls-any");
    // Beyond loopback the studio needs users.
    let mut users = alba_auth::Users::default();
    users
        .add("ann", alba_auth::Role::Admin, "a long test password 7")
        .expect("add");
    users.save(&dir).expect("save");
    let mut opts = options("sim");
    opts.addr = "0.0.0.0:0".parse().expect("addr");
    let (addr, stop, task) = serve(&dir, opts).await;
    let (cert, _) = alba_app::tls::self_signed_paths(&dir);
    assert!(cert.exists(), "a certificate made on first run");
    let url = format!("https://localhost:{}/api/status", addr.port());
    // Any answer of the studio (with users, 401 without a session) shows it serves HTTPS.
    let res = client_trusting(&cert).get(&url).send().await.expect("HTTPS");
    assert!(res.headers().contains_key("content-security-policy"), "{res:?}");
    let plain = reqwest::Client::new()
        .get(format!("http://127.0.0.1:{}/api/status", addr.port()))
        .send()
        .await;
    assert!(
        plain.is_err() || !plain.expect("answer").status().is_success(),
        "no plain HTTP"
    );
    let _ = stop.send(());
    tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("stops")
        .expect("task");

    // `[http] insecure = true`: plain HTTP, explicitly.
    let toml = std::fs::read_to_string(dir.join("alba.toml")).expect("toml");
    std::fs::write(dir.join("alba.toml"), format!("{toml}\n[http]\ninsecure = true\n")).expect("write");
    let mut opts = options("sim");
    opts.addr = "0.0.0.0:0".parse().expect("addr");
    let (addr, stop, task) = serve(&dir, opts).await;
    assert_eq!(alba_app::tls::scheme(&dir, alba_app::tls::Tls::Auto, addr), "http");
    let res = reqwest::Client::new()
        .get(format!("http://127.0.0.1:{}/api/status", addr.port()))
        .send()
        .await
        .expect("plain HTTP");
    assert!(res.headers().contains_key("content-security-policy"), "{res:?}");
    let _ = stop.send(());
    tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("stops")
        .expect("task");
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn handlers_know_the_clients_address_over_tls() {
    use axum::extract::ConnectInfo;
    let dir = std::env::temp_dir().join(format!("alba-app-tls-peer-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let (cert, key) = alba_app::tls::self_signed_paths(&dir);
    let any: std::net::SocketAddr = "127.0.0.1:0".parse().expect("addr");
    alba_app::tls::make_self_signed(&cert, &key, any, &[]).expect("cert");
    let acceptor = alba_app::tls::acceptor(&dir, &Default::default(), any).expect("acceptor");
    let tcp = tokio::net::TcpListener::bind(any).await.expect("bind");
    let addr = tcp.local_addr().expect("addr");
    let listener = alba_app::tls::TlsListener::new(tcp, acceptor).expect("listener");
    let router = axum::Router::new().route(
        "/",
        axum::routing::get(|ConnectInfo(peer): ConnectInfo<std::net::SocketAddr>| async move { peer.to_string() }),
    );
    let server = tokio::spawn(async move {
        let limits = alba_app::serve::Limits {
            max_connections: 16,
            header_timeout: Duration::from_secs(15),
        };
        alba_app::serve::serve(listener, router, limits, std::future::pending()).await;
    });
    let res = client_trusting(&cert)
        .get(format!("https://localhost:{}/", addr.port()))
        .send()
        .await
        .expect("HTTPS");
    let peer = res.text().await.expect("text");
    assert!(peer.starts_with("127.0.0.1:") && peer != addr.to_string(), "{peer}");
    server.abort();
    let _ = std::fs::remove_dir_all(&dir);
}

/// No users: the studio is served on loopback only; a non-loopback
/// address is refused before anything starts, with what to do instead.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_users_a_non_loopback_listener_is_refused() {
    let dir = copy_example("tank", "openhttp");
    for addr in ["0.0.0.0:0", "[::]:0"] {
        let mut opts = options("sim");
        opts.addr = addr.parse().expect("addr");
        let r = alba_app::run(&dir, opts, |_| panic!("not ready"), async {}).await;
        match r {
            Err(alba_app::RunError::Other(m)) => {
                assert!(m.contains("refusing to serve the studio"), "{m}");
                assert!(m.contains("no users") && m.contains("alba user add"), "{m}");
            }
            _ => panic!("{addr}: expected a refusal"),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// With users, any address may be served (each request then needs a session).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn with_users_a_non_loopback_listener_starts() {
    let dir = copy_example("tank", "usershttp");
    let mut users = alba_auth::Users::default();
    users
        .add("ann", alba_auth::Role::Admin, "a long test password 7")
        .expect("add");
    users.save(&dir).expect("save");
    let mut opts = options("sim");
    opts.addr = "0.0.0.0:0".parse().expect("addr");
    let (ready_tx, ready_rx) = tokio::sync::oneshot::channel();
    let (stop, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let d = dir.clone();
    let task = tokio::spawn(async move {
        alba_app::run(
            &d,
            opts,
            move |a| {
                let _ = ready_tx.send(a);
            },
            async move {
                let _ = stop_rx.await;
            },
        )
        .await
        .is_ok()
    });
    let addr = ready_rx.await.expect("ready");
    assert!(addr.ip().is_unspecified(), "{addr}");
    tokio::net::TcpStream::connect(("127.0.0.1", addr.port()))
        .await
        .expect("the API serves");
    let _ = stop.send(());
    let ok = tokio::time::timeout(Duration::from_secs(10), task)
        .await
        .expect("stops within 10 s")
        .expect("task");
    assert!(ok);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Alarms end to end (SPEC §10.5): alarms.csv evaluated on the running
/// program, `GET /api/alarms`, acknowledge, shelve, the log as CSV, the
/// audit rows.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn alarms_are_evaluated_acknowledged_shelved_and_logged() {
    let dir = std::env::temp_dir().join(format!("alba-app-alarms-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    for (f, t) in [
        (
            "alba.toml",
            "name = \"alarms\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n[history]\nenabled = false\n",
        ),
        (
            "tags.csv",
            "name,type,address,initial,retain,description\nCount,DINT,,,,\nSetpoint,DINT,,,,\n",
        ),
        ("main.lad", "ADD(Count,1,Count);\n"),
        (
            "alarms.csv",
            "id,tag,condition,severity,delay_ms,deadband,message\nbig,Count,> 20,high,0,0,Count above 20\n\
             sp,Setpoint,>= 100,medium,0,5,Setpoint high\n",
        ),
    ] {
        std::fs::write(dir.join(f), t).expect("write");
    }
    let (addr, stop, task) = serve(&dir, options("sim")).await;
    let client = reqwest::Client::new();
    let url = |p: &str| format!("http://{addr}{p}");
    let get = |p: String| {
        let c = client.clone();
        async move {
            let r = c.get(p).send().await.expect("get");
            assert!(r.status().is_success(), "{}", r.status());
            r.text().await.expect("text")
        }
    };
    let post = |p: String, body: &'static str| {
        let c = client.clone();
        async move {
            let r = c
                .request(
                    if p.contains("/api/tags/") {
                        reqwest::Method::PUT
                    } else {
                        reqwest::Method::POST
                    },
                    p,
                )
                .header("content-type", "application/json")
                .body(body)
                .send()
                .await
                .expect("send");
            (r.status().as_u16(), r.text().await.expect("text"))
        }
    };
    let until = |what: &'static str, f: fn(&str) -> bool| {
        let u = url("/api/alarms");
        async move {
            for _ in 0..200 {
                let t = get(u.clone()).await;
                if f(&t) {
                    return t;
                }
                tokio::time::sleep(Duration::from_millis(20)).await;
            }
            panic!("timed out waiting for {what}");
        }
    };
    let t = until("big active", |t| {
        t.contains("\"id\":\"big\"") && t.contains("active_unacked")
    })
    .await;
    assert!(t.contains("\"severity\":750") && t.contains("Count above 20"), "{t}");
    assert!(!t.contains("\"id\":\"sp\""), "sp is normal: {t}");
    assert_eq!(post(url("/api/tags/Setpoint"), "{\"value\": 150}").await.0, 200);
    until("sp active", |t| t.contains("\"id\":\"sp\"")).await;
    let (code, body) = post(url("/api/alarms/sp/ack"), "{\"comment\": \"seen it\"}").await;
    assert_eq!(code, 200, "{body}");
    assert!(
        body.contains("\"state\":\"active_acked\"") && body.contains("\"acked_by\":\"local\""),
        "{body}"
    );
    assert_eq!(post(url("/api/alarms/sp/ack"), "{}").await.0, 409, "acknowledged twice");
    assert_eq!(post(url("/api/alarms/nope/ack"), "{}").await.0, 404);
    assert_eq!(
        post(url("/api/alarms/big/shelve"), "{\"minutes\": 0, \"reason\": \"x\"}")
            .await
            .0,
        422
    );
    // Deadband 5: 96 keeps it active; 90 clears it (acknowledged: back to normal).
    post(url("/api/tags/Setpoint"), "{\"value\": 96}").await;
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert!(get(url("/api/alarms")).await.contains("\"id\":\"sp\""));
    post(url("/api/tags/Setpoint"), "{\"value\": 90}").await;
    until("sp normal", |t| !t.contains("\"id\":\"sp\"")).await;
    let (code, body) = post(url("/api/alarms/big/shelve"), "{\"minutes\": 5, \"reason\": \"test\"}").await;
    assert_eq!(code, 200, "{body}");
    assert!(body.contains("\"state\":\"shelved\""), "{body}");
    let stats = get(url("/api/alarms/stats")).await;
    assert!(
        stats.contains("\"alarms\":2") && stats.contains("\"shelved\":1") && stats.contains("\"flood\":false"),
        "{stats}"
    );
    let all = get(url("/api/alarms?all=true")).await;
    assert!(
        all.contains("\"id\":\"sp\",") && all.contains("\"state\":\"normal\""),
        "{all}"
    );
    let csv = get(url("/api/alarms/log.csv")).await;
    for want in [
        "id,time_ms,time_utc,alarm,tag,from,to,value,severity,user,comment,message",
        ",sp,Setpoint,active_unacked,active_acked,150,500,local,seen it,Setpoint high",
        ",sp,Setpoint,active_acked,normal,90,",
        ",big,Count,active_unacked,shelved,",
    ] {
        assert!(csv.contains(want), "{want:?} in\n{csv}");
    }
    let audit = get(url("/api/audit?action=alarm_ack,alarm_shelve")).await;
    assert!(
        audit.contains("\"target\":\"sp\"") && audit.contains("\"target\":\"big\""),
        "{audit}"
    );
    let _ = stop.send(());
    let _ = tokio::time::timeout(Duration::from_secs(10), task).await;
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_bad_alarms_csv_stops_alba_run_with_located_errors() {
    let dir = copy_example("tank", "badalarms");
    std::fs::write(
        dir.join("alarms.csv"),
        "id,tag,condition,severity,delay_ms,deadband,message\nhi,Nope,on,high,0,0,m\n",
    )
    .expect("write");
    let r = alba_app::run(&dir, options("sim"), |_| panic!("not ready"), async {}).await;
    match r {
        Err(alba_app::RunError::Other(m)) => {
            assert!(
                m.contains("E140") && m.contains("alarms.csv:2:4") && m.contains("`Nope`"),
                "{m}"
            )
        }
        _ => panic!("expected an error"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// One runtime per project: a second `alba run` on the same folder stops at
/// once with the first one's process id (issue 15); after the first stops,
/// the project runs again.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_second_run_of_the_same_project_is_refused() {
    let dir = copy_example("tank", "lock");
    let (_, stop, task) = serve(&dir, options("sim")).await;
    let r = alba_app::run(&dir, options("sim"), |_| panic!("must not start"), async {}).await;
    match r {
        Err(alba_app::RunError::Other(m)) => {
            assert!(
                m.contains("another `alba run`") && m.contains(&format!("pid {}", std::process::id())),
                "{m}"
            )
        }
        _ => panic!("expected the lock to refuse a second run"),
    }
    let _ = stop.send(());
    let _ = tokio::time::timeout(Duration::from_secs(10), task).await;
    let (_, stop, task) = serve(&dir, options("sim")).await;
    let _ = stop.send(());
    let _ = tokio::time::timeout(Duration::from_secs(10), task).await;
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 31: `.alba/lock` was followed through a symbolic link (its target
/// truncated to the pid), and deleting it let a second run start. The lock
/// is now on the project directory; the pid file is never followed.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_lock_follows_no_link_and_survives_its_file_being_deleted() {
    let dir = copy_example("tank", "locklink");
    std::fs::create_dir_all(dir.join(".alba")).expect(".alba");
    let victim = dir.join("precious.txt");
    std::fs::write(&victim, "keep me").expect("victim");
    std::os::unix::fs::symlink(&victim, dir.join(".alba/lock")).expect("symlink");
    match alba_app::run(&dir, options("sim"), |_| panic!("must not start"), async {}).await {
        Err(alba_app::RunError::Other(m)) => assert!(m.contains("not a regular file"), "{m}"),
        _ => panic!("expected a refusal"),
    }
    assert_eq!(std::fs::read_to_string(&victim).expect("victim"), "keep me");
    std::fs::remove_file(dir.join(".alba/lock")).expect("rm link");
    // Running, its lock file deleted: a second run is still refused.
    let (addr, stop, task) = serve(&dir, options("sim")).await;
    std::fs::remove_file(dir.join(".alba/lock")).expect("rm lock");
    match alba_app::run(&dir, options("sim"), |_| panic!("must not start"), async {}).await {
        Err(alba_app::RunError::Other(m)) => assert!(m.contains("another `alba run`"), "{m}"),
        _ => panic!("a second run started once .alba/lock was deleted"),
    }
    // The first one scans on.
    let scans = |addr| async move {
        let s: serde_json::Value = reqwest::get(format!("http://{addr}/api/status"))
            .await
            .expect("status")
            .json()
            .await
            .expect("json");
        s["scans"].as_u64().expect("scans")
    };
    let before = scans(addr).await;
    let mut after = before;
    for _ in 0..100 {
        after = scans(addr).await;
        if after > before {
            break;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert!(after > before, "the first run keeps scanning");
    let _ = stop.send(());
    let _ = tokio::time::timeout(Duration::from_secs(10), task).await;
    let _ = std::fs::remove_dir_all(&dir);
}
