//! The API of docs/api.md against a real server on a loopback port, over a
//! copy of an example project.

mod api;
mod assets;
mod audit;
mod contract;
mod domain;
mod errors;
mod guard;
mod history;
mod limits;
pub mod nets;
mod recipes;
mod reports;
mod roles;
mod scale;
mod screens;
mod trends;
mod ws;

use reqwest::{Client, Method, StatusCode};
use serde_json::{Value as Json, json};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tokio::sync::oneshot;

pub struct Server {
    pub addr: SocketAddr,
    pub dir: PathBuf,
    pub http: Client,
    stop: Option<oneshot::Sender<()>>,
    task: Option<tokio::task::JoinHandle<()>>,
}

impl Server {
    /// Serves a ready `state` (the router alone, without `alba run`'s
    /// services) on a loopback port, for tests that build the state
    /// themselves (a fake board, a manual clock).
    pub async fn serve_state(state: std::sync::Arc<alba_server::AppState>, dir: PathBuf) -> Server {
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.expect("listen");
        let addr = listener.local_addr().expect("addr");
        let (stop, stop_rx) = oneshot::channel::<()>();
        let closing = state.closing.clone();
        let task = tokio::spawn(async move {
            let app = alba_server::router(state).into_make_service_with_connect_info::<SocketAddr>();
            axum::serve(listener, app)
                .with_graceful_shutdown(async move {
                    let _ = stop_rx.await;
                    closing.send_replace(true);
                })
                .await
                .expect("serve");
        });
        Server {
            addr,
            dir,
            http: Client::new(),
            stop: Some(stop),
            task: Some(task),
        }
    }
}

/// A fresh copy of `examples/<name>` in a scratch directory named by `test`, which
/// no other test of this binary may use: tests run in parallel, and two sharing a
/// directory would delete each other's project (and meet the project lock).
pub fn copy_example(name: &str, test: &str) -> PathBuf {
    static USED: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    {
        let mut used = USED.lock().unwrap_or_else(|e| e.into_inner());
        assert!(
            !used.iter().any(|u| u == test),
            "the scratch name `{test}` is used by two tests"
        );
        used.push(test.to_string());
    }
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name);
    let dir = std::env::temp_dir().join(format!("alba-server-{test}-{}", std::process::id()));
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

impl Server {
    /// `alba run` on a copy of `examples/<example>` at an ephemeral port.
    pub async fn start(example: &str, test: &str) -> Server {
        Server::start_in(copy_example(example, test)).await
    }

    pub async fn start_in(dir: PathBuf) -> Server {
        let (ready_tx, ready_rx) = oneshot::channel();
        let (stop, stop_rx) = oneshot::channel::<()>();
        let opts = alba_app::Options {
            addr: "127.0.0.1:0".parse().expect("addr"),
            io: "sim".into(),
            native: false,
            modbus: None,
            opcua: None,
            mqtt: None,
            tls: alba_app::tls::Tls::Auto,
            scan_log: None,
            quiet: false,
        };
        let d = dir.clone();
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
            if let Err(e) = r {
                match e {
                    alba_app::RunError::Compile(c) => panic!("does not compile: {:?}", c.diagnostics),
                    alba_app::RunError::Other(m) => panic!("{m}"),
                }
            }
        });
        let addr = ready_rx.await.expect("server started");
        let s = Server {
            addr,
            dir,
            // A connection per request: `alba run` closes an idle keep-alive when a
            // newer client of its address needs the place (issue 31), and a pooled
            // client could pick that connection as it closes (IncompleteMessage).
            http: Client::builder().pool_max_idle_per_host(0).build().expect("client"),
            stop: Some(stop),
            task: Some(task),
        };
        // Tests start from a scanned program, not from its initial memory.
        s.wait_scans(2).await;
        s
    }

    pub fn url(&self, path: &str) -> String {
        format!("http://{}{path}", self.addr)
    }

    /// Sends a request with an optional JSON body; the status and the JSON
    /// answer (`null` for an empty body). State-changing requests are sent
    /// as JSON even without a body, as the guard requires (crate::guard).
    pub async fn call(&self, method: Method, path: &str, body: Option<Json>) -> (StatusCode, Json) {
        let changes = !matches!(method, Method::GET | Method::HEAD);
        let mut req = self.http.request(method, self.url(path));
        if let Some(b) = body {
            req = req.json(&b);
        } else if changes {
            req = req.header("content-type", "application/json");
        }
        let res = req.send().await.expect("request");
        Server::answer(res).await
    }

    /// Sends raw bytes as the body with a content type.
    pub async fn raw(&self, method: Method, path: &str, ctype: &str, body: Vec<u8>) -> (StatusCode, Json) {
        let res = self
            .http
            .request(method, self.url(path))
            .header("content-type", ctype)
            .body(body)
            .send()
            .await
            .expect("request");
        Server::answer(res).await
    }

    async fn answer(res: reqwest::Response) -> (StatusCode, Json) {
        let status = res.status();
        let text = res.text().await.expect("body");
        let j = if text.is_empty() {
            Json::Null
        } else {
            serde_json::from_str(&text).unwrap_or_else(|_| json!({"text": text}))
        };
        (status, j)
    }

    pub async fn get(&self, path: &str) -> Json {
        let (s, j) = self.call(Method::GET, path, None).await;
        assert_eq!(s, StatusCode::OK, "GET {path}: {j}");
        j
    }

    pub async fn value(&self, tag: &str) -> Json {
        self.get(&format!("/api/tags/{tag}")).await["value"].clone()
    }

    pub async fn scans(&self) -> u64 {
        self.get("/api/status").await["scans"].as_u64().expect("scans")
    }

    /// Waits until `scans` has advanced by `n`.
    pub async fn wait_scans(&self, n: u64) {
        let start = self.scans().await;
        for _ in 0..500 {
            if self.scans().await >= start + n {
                return;
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
        panic!("the engine does not scan");
    }

    /// Stops the server, waits for it (retentive data saved) and removes
    /// its project copy.
    pub async fn stop(mut self) {
        if let Some(s) = self.stop.take() {
            let _ = s.send(());
        }
        if let Some(t) = self.task.take() {
            tokio::time::timeout(Duration::from_secs(10), t)
                .await
                .expect("server stops within 10 s")
                .expect("server task");
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}
