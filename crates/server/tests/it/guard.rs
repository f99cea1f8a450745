//! The browser-attack guard (crate::guard, docs/security.md): each refusal,
//! against a running PLC, and what stays allowed.

use crate::{Server, copy_example};
use futures_util::StreamExt;
use reqwest::{Method, StatusCode};
use serde_json::Value as Json;
use std::time::{Duration, Instant};
use tokio_tungstenite::tungstenite;
use tungstenite::client::IntoClientRequest;

impl Server {
    /// A request with the given headers and body; the status, the headers
    /// and the JSON answer.
    async fn send(
        &self,
        method: Method,
        path: &str,
        headers: &[(&str, &str)],
        body: &str,
    ) -> (StatusCode, reqwest::header::HeaderMap, Json) {
        let mut req = self.http.request(method, self.url(path)).body(body.to_string());
        for (k, v) in headers {
            req = req.header(*k, *v);
        }
        let res = req.send().await.expect("request");
        let (status, h) = (res.status(), res.headers().clone());
        let text = res.text().await.expect("body");
        (status, h, serde_json::from_str(&text).unwrap_or(Json::Null))
    }

    async fn state(&self) -> Json {
        self.get("/api/status").await["state"].clone()
    }

    /// The studio's origin.
    fn origin(&self) -> String {
        format!("http://{}", self.addr)
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_foreign_page_cannot_stop_the_plc() {
    let s = Server::start("tank", "guard-stop").await;
    let evil = [("origin", "http://evil.example")];
    // The attack of issue 13: a cross-origin "simple" request, no preflight.
    for (ctype, body) in [
        ("text/plain", "{}"),
        ("application/x-www-form-urlencoded", "a=b"),
        ("multipart/form-data; boundary=x", "--x--"),
    ] {
        for origin in [&evil[..], &[("origin", "null")][..], &[][..]] {
            let mut h = vec![("content-type", ctype)];
            h.extend_from_slice(origin);
            let (code, _, j) = s.send(Method::POST, "/api/stop", &h, body).await;
            assert!(
                code == StatusCode::FORBIDDEN || code == StatusCode::UNSUPPORTED_MEDIA_TYPE,
                "{ctype} {origin:?}: {code} {j}"
            );
            assert!(j["error"].is_string(), "{j}");
        }
    }
    // Without a content type (a bodyless fetch of another page, or a sloppy script).
    let (code, _, j) = s.send(Method::POST, "/api/stop", &[], "").await;
    assert_eq!(code, StatusCode::UNSUPPORTED_MEDIA_TYPE, "{j}");
    assert!(j["error"].as_str().expect("error").contains("application/json"), "{j}");
    // JSON from a foreign origin (the browser would preflight it; a non-browser may not).
    for origin in ["http://evil.example", "null", "http://localhost:1"] {
        let h = [("content-type", "application/json"), ("origin", origin)];
        let (code, _, j) = s.send(Method::POST, "/api/stop", &h, "").await;
        assert_eq!(code, StatusCode::FORBIDDEN, "{origin}: {j}");
    }
    let h = [("content-type", "application/json"), ("sec-fetch-site", "cross-site")];
    assert_eq!(s.send(Method::POST, "/api/stop", &h, "").await.0, StatusCode::FORBIDDEN);
    // Writes and forces alike.
    let h = [("content-type", "text/plain"), ("origin", "http://evil.example")];
    let (code, _, _) = s.send(Method::PUT, "/api/tags/Llenar", &h, r#"{"value":true}"#).await;
    assert_eq!(code, StatusCode::FORBIDDEN);
    assert_eq!(s.state().await, "running", "nothing stopped the PLC");

    // The studio itself: same origin, JSON.
    let own = s.origin();
    let h = [("content-type", "application/json"), ("origin", own.as_str())];
    let (code, _, j) = s.send(Method::POST, "/api/stop", &h, "").await;
    assert_eq!((code, j["state"].clone()), (StatusCode::OK, "stopped".into()));
    // A script: JSON without Origin.
    let (code, _, j) = s
        .send(Method::POST, "/api/run", &[("content-type", "application/json")], "")
        .await;
    assert_eq!((code, j["state"].clone()), (StatusCode::OK, "running".into()));
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn foreign_host_names_are_refused() {
    let dir = copy_example("tank", "guard-host");
    let toml = std::fs::read_to_string(dir.join("alba.toml")).expect("toml");
    std::fs::write(
        dir.join("alba.toml"),
        format!(
            "{toml}\n[http]\nallowed_hosts = [\"plc1.plant.example\"]\nallowed_origins = [\"https://scada.example\"]\n"
        ),
    )
    .expect("write");
    let s = Server::start_in(dir).await;
    let port = s.addr.port();
    // DNS rebinding: evil.example resolves to 127.0.0.1, the browser sends its name.
    for host in [
        "evil.example".to_string(),
        format!("evil.example:{port}"),
        format!("localhost.evil.example:{port}"),
    ] {
        for path in ["/", "/api/status"] {
            let (code, h, j) = s.send(Method::GET, path, &[("host", &host)], "").await;
            assert_eq!(code, StatusCode::MISDIRECTED_REQUEST, "{host} {path}: {j}");
            assert!(j["error"].as_str().expect("error").contains("allowed_hosts"), "{j}");
            assert!(
                h.contains_key("content-security-policy"),
                "refusals carry the headers too"
            );
        }
        let origin = format!("http://{host}");
        let hs = [
            ("host", host.as_str()),
            ("origin", origin.as_str()),
            ("content-type", "application/json"),
        ];
        let (code, _, _) = s.send(Method::POST, "/api/stop", &hs, "").await;
        assert_eq!(code, StatusCode::MISDIRECTED_REQUEST, "{host}");
    }
    assert_eq!(s.state().await, "running");
    for host in [
        format!("localhost:{port}"),
        format!("127.0.0.1:{port}"),
        format!("[::1]:{port}"),
        format!("plc1.plant.example:{port}"),
        "PLC1.Plant.Example".to_string(),
    ] {
        let (code, _, j) = s.send(Method::GET, "/api/status", &[("host", &host)], "").await;
        assert_eq!(code, StatusCode::OK, "{host}: {j}");
    }
    // An allowed name, from its own origin or an allowed one.
    let host = format!("plc1.plant.example:{port}");
    for origin in [format!("http://{host}"), "https://scada.example".to_string()] {
        let hs = [
            ("host", host.as_str()),
            ("origin", origin.as_str()),
            ("content-type", "application/json"),
        ];
        let (code, _, j) = s.send(Method::POST, "/api/run", &hs, "").await;
        assert_eq!(code, StatusCode::OK, "{origin}: {j}");
    }
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_websocket_needs_the_studios_origin() {
    let s = Server::start("tank", "guard-ws").await;
    let handshake = |origin: Option<&str>| {
        let mut req = format!("ws://{}/api/ws", s.addr)
            .into_client_request()
            .expect("request");
        if let Some(o) = origin {
            req.headers_mut().insert("origin", o.parse().expect("origin"));
        }
        tokio_tungstenite::connect_async(req)
    };
    for origin in [
        None,
        Some("null"),
        Some("http://evil.example"),
        Some("http://127.0.0.1:1"),
    ] {
        match handshake(origin).await {
            Err(tungstenite::Error::Http(res)) => assert_eq!(res.status(), StatusCode::FORBIDDEN, "{origin:?}"),
            Err(e) => panic!("{origin:?}: {e}"),
            Ok(_) => panic!("{origin:?}: the WebSocket was opened"),
        }
    }
    let own = s.origin();
    let (mut ws, res) = handshake(Some(&own)).await.expect("same origin");
    assert_eq!(res.status(), StatusCode::SWITCHING_PROTOCOLS);
    use futures_util::SinkExt;
    ws.send(tungstenite::Message::Text(r#"{"subscribe":["Llenar"]}"#.into()))
        .await
        .expect("send");
    let m = tokio::time::timeout(Duration::from_secs(5), ws.next())
        .await
        .expect("a message");
    assert!(matches!(m, Some(Ok(tungstenite::Message::Text(_)))), "{m:?}");
    drop(ws);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_answer_carries_the_security_headers() {
    let s = Server::start("tank", "guard-headers").await;
    for (method, path) in [
        (Method::GET, "/"),
        (Method::GET, "/index.html"),
        (Method::GET, "/api/status"),
        (Method::GET, "/api/nope"),
        (Method::POST, "/api/stop"),
    ] {
        let (_, h, _) = s.send(method.clone(), path, &[], "").await;
        let get = |k: &str| h.get(k).and_then(|v| v.to_str().ok()).unwrap_or("").to_string();
        let csp = get("content-security-policy");
        for part in [
            "default-src 'self'",
            "frame-ancestors 'none'",
            "script-src 'self'",
            "object-src 'none'",
        ] {
            assert!(csp.contains(part), "{method} {path}: {csp}");
        }
        assert!(csp.contains(&format!("ws://{}", s.addr)), "{csp}");
        assert_eq!(get("x-content-type-options"), "nosniff", "{path}");
        assert_eq!(get("x-frame-options"), "DENY", "{path}");
        assert_eq!(get("referrer-policy"), "no-referrer", "{path}");
    }
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn history_csv_is_bounded_and_streamed() {
    let s = Server::start("tank-plant", "guard-csv").await;
    // Until the recorder has written the level.
    for _ in 0..500 {
        let tags = s.get("/api/history/tags").await;
        if tags
            .as_array()
            .is_some_and(|a| a.iter().any(|t| t["name"] == "Nivel_L"))
        {
            break;
        }
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    // 300 different columns: refused at once, before any query.
    let names: Vec<String> = (0..300).map(|i| format!("T{i}")).collect();
    let t = Instant::now();
    let path = format!(
        "/api/history.csv?tags={}&from=0&to=1000000000&step=1000",
        names.join(",")
    );
    let (code, j) = s.call(Method::GET, &path, None).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert!(j["error"].as_str().expect("error").contains("more than 64"), "{j}");
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
    // The issue's 300 repeats of one tag: one column.
    let path = format!(
        "/api/history.csv?tags={}&from=0&to=10000&step=1000",
        ["Nivel_L"; 300].join(",")
    );
    let res = s.http.get(s.url(&path)).send().await.expect("csv");
    assert_eq!(res.status(), StatusCode::OK);
    let text = res.text().await.expect("text");
    assert_eq!(text.lines().next(), Some("Time (ms),Nivel_L"));
    assert_eq!(text.lines().count(), 12);
    // Too many values in all (rows × columns).
    let path = format!(
        "/api/history.csv?tags={}&from=0&to=999999&step=1",
        names[..20].join(",")
    );
    let (code, j) = s.call(Method::GET, &path, None).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(j["error"].as_str().expect("error").contains("values"), "{j}");
    // An unknown tag is still an API error, not a cut answer.
    let (code, j) = s
        .call(Method::GET, "/api/history.csv?tags=Nivel_L,Nope&from=0&to=10", None)
        .await;
    assert_eq!(code, StatusCode::NOT_FOUND, "{j}");

    // The largest legal export of one tag comes in pieces, with no length announced.
    let path = "/api/history.csv?tags=Nivel_L&from=0&to=999999&step=1";
    let res = s.http.get(s.url(path)).send().await.expect("csv");
    assert_eq!(res.status(), StatusCode::OK);
    assert!(res.content_length().is_none(), "streamed, not built whole");
    let (mut pieces, mut bytes, mut lines) = (0, 0, 0);
    let mut stream = res.bytes_stream();
    while let Some(piece) = stream.next().await {
        let piece = piece.expect("piece");
        pieces += 1;
        bytes += piece.len();
        lines += piece.iter().filter(|b| **b == b'\n').count();
    }
    assert_eq!(lines, 1_000_001, "a header and a million rows");
    assert!(pieces > 10, "{pieces} pieces of {bytes} bytes");
    s.stop().await;
}
