//! `alba_app::run` assembles and stops `alba run`.

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

fn options(io: &str) -> alba_app::Options {
    alba_app::Options {
        addr: "127.0.0.1:0".parse().expect("addr"),
        io: io.into(),
        native: false,
        modbus: None,
        opcua: None,
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
