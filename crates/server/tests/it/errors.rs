//! One test per error status of docs/api.md ("Errors"): each fails if
//! `crate::error::status` maps its case to another status.

use crate::{Server, copy_example};
use alba_runtime::{Io, IoError, Options, Runtime};
use reqwest::{Method, StatusCode};
use serde_json::json;
use std::sync::Arc;

/// An I/O driver in attach mode: the "board" runs the program.
struct Board;

impl Io for Board {
    fn name(&self) -> &str {
        "board:test"
    }
    fn read_inputs(&mut self, _: &mut alba_engine::Engine) -> Result<(), IoError> {
        Ok(())
    }
    fn write_outputs(&mut self, _: &alba_engine::Engine) -> Result<(), IoError> {
        Ok(())
    }
    fn runs_program(&self) -> bool {
        true
    }
}

/// The server over a runtime of the test's own (its I/O, its lifetime).
async fn serve(example: &str, test: &str, io: Box<dyn Io>) -> (Server, Runtime) {
    let dir = copy_example(example, test);
    let compiled = alba_server::project::load(&dir);
    let program = compiled.program.clone().expect("the example compiles");
    let mut ro = Options::new(compiled.project.scan_ms());
    ro.native = false;
    let runtime = Runtime::start(Arc::new(program), ro, io).expect("runtime");
    let state = alba_server::AppState::new(
        runtime.handle(),
        compiled,
        "test",
        None,
        None,
        alba_server::auth::Auth::open(),
        &alba_settings::Http::default(),
    );
    (Server::serve_state(state, dir).await, runtime)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_400_malformed_request() {
    let s = Server::start("tank", "e400").await;
    let (code, j) = s
        .raw(
            Method::PUT,
            "/api/tags/Llenar",
            "application/json",
            b"{\"value\"".to_vec(),
        )
        .await;
    assert_eq!(code, StatusCode::BAD_REQUEST, "{j}");
    let (code, j) = s
        .call(Method::POST, "/api/check/main.lad", Some(json!({"txt": ""})))
        .await;
    assert_eq!(code, StatusCode::BAD_REQUEST, "{j}");
    assert!(j["error"].as_str().expect("error").contains("`text`"), "{j}");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_404_unknown_tag_or_program() {
    let s = Server::start("tank", "e404").await;
    let (code, j) = s.call(Method::GET, "/api/tags/Nope", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND, "{j}");
    assert_eq!(j["error"], "unknown tag `Nope`");
    let (code, j) = s
        .call(Method::POST, "/api/check/nope.lad", Some(json!({"text": ""})))
        .await;
    assert_eq!(code, StatusCode::NOT_FOUND, "{j}");
    assert_eq!(j["error"], "no program `nope.lad` in this project");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_409_conflict_in_attach_mode() {
    let (s, runtime) = serve("tank", "e409", Box::new(Board)).await;
    for (m, path, body) in [
        (Method::PUT, "/api/forces/STOP", Some(json!({"value": true}))),
        (Method::POST, "/api/stop", None),
        (Method::POST, "/api/step", None),
    ] {
        let (code, j) = s.call(m, path, body).await;
        assert_eq!(code, StatusCode::CONFLICT, "{path}: {j}");
        assert!(
            j["error"]
                .as_str()
                .expect("error")
                .contains("the board runs the program"),
            "{j}"
        );
    }
    // An online edit is saved, not applied.
    let text = s.get("/api/programs/main.lad").await["text"].clone();
    let (code, j) = s
        .call(
            Method::PUT,
            "/api/programs/main.lad",
            Some(json!({"text": text, "online": true})),
        )
        .await;
    assert_eq!(code, StatusCode::CONFLICT, "{j}");
    assert!(
        j["error"]
            .as_str()
            .expect("error")
            .starts_with("saved, but not applied"),
        "{j}"
    );
    s.stop().await;
    runtime.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_413_body_too_large() {
    let s = Server::start("tank", "e413").await;
    let big = format!("{{\"value\": false, \"pad\": \"{}\"}}", "x".repeat(100_000));
    let (code, j) = s
        .raw(Method::PUT, "/api/tags/Llenar", "application/json", big.into_bytes())
        .await;
    assert_eq!(code, StatusCode::PAYLOAD_TOO_LARGE, "{j}");
    assert_eq!(j["error"], "the request body is too large");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_422_invalid_value_or_program() {
    let s = Server::start("tank", "e422").await;
    let (code, j) = s.call(Method::PUT, "/api/tags/Llenar", Some(json!({"value": 2}))).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let (code, j) = s
        .call(Method::POST, "/api/check/main.lad", Some(json!({"text": "XIC("})))
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert!(j["diagnostics"].as_array().is_some_and(|d| !d.is_empty()), "{j}");
    s.stop().await;
}

/// A refused program save answers in the request's language (issue 34
/// point 11): Spanish for `Accept-Language: es`, English otherwise.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_refused_save_speaks_the_requests_language() {
    let s = Server::start("tank", "e422-es").await;
    let send = |lang: Option<&'static str>| {
        let mut req = s
            .http
            .request(Method::PUT, s.url("/api/programs/main.lad"))
            .json(&json!({"text": "XIC(Strat)OTE(Llenar);\n"}));
        if let Some(l) = lang {
            req = req.header("accept-language", l);
        }
        async move {
            let res = req.send().await.expect("request");
            let vary = res.headers().get("vary").map(|v| v.to_str().unwrap_or("").to_string());
            let (code, j) = Server::answer(res).await;
            (code, j, vary.unwrap_or_default())
        }
    };
    let (code, j, vary) = send(Some("es-ES,es;q=0.9,en;q=0.8")).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let d = &j["diagnostics"][0];
    assert_eq!(d["code"], "E301", "{j}");
    assert_eq!(d["message"], "variable desconocida `Strat`", "{j}");
    assert!(vary.to_ascii_lowercase().contains("accept-language"), "{vary}");
    let (_, j, _) = send(None).await;
    assert_eq!(j["diagnostics"][0]["message"], "unknown tag `Strat`", "{j}");
    let (_, j, _) = send(Some("de, en;q=0.5")).await;
    assert_eq!(j["diagnostics"][0]["message"], "unknown tag `Strat`", "{j}");
    s.stop().await;
}

/// A request with `Accept-Language` and its answer: status, `error`.
async fn ask_in(s: &Server, lang: &str, method: Method, path: &str, body: Option<Vec<u8>>) -> (StatusCode, String) {
    let mut req = s.http.request(method, s.url(path)).header("accept-language", lang);
    if let Some(b) = body {
        req = req.header("content-type", "application/json").body(b);
    }
    let (code, j) = Server::answer(req.send().await.expect("request")).await;
    (code, j["error"].as_str().unwrap_or_default().to_string())
}

/// The top-level `error` of the common refusals in the request's language
/// (issue 34 point 11): 400, 404, 409 and 422 in Spanish for
/// `Accept-Language: es`, the same requests in English without it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn errors_speak_the_requests_language() {
    let s = Server::start("tank", "e-es").await;
    let es = "es-ES,es;q=0.9,en;q=0.8";
    let (code, e) = ask_in(&s, es, Method::GET, "/api/tags/Nope", None).await;
    assert_eq!(
        (code, e.as_str()),
        (StatusCode::NOT_FOUND, "variable desconocida `Nope`")
    );
    let check = Some(br#"{"text": ""}"#.to_vec());
    let (code, e) = ask_in(&s, es, Method::POST, "/api/check/nope.lad", check).await;
    assert_eq!(
        (code, e.as_str()),
        (
            StatusCode::NOT_FOUND,
            "no hay ningún programa `nope.lad` en este proyecto"
        )
    );
    let (code, e) = ask_in(&s, es, Method::PUT, "/api/tags/Llenar", Some(b"{\"value\"".to_vec())).await;
    assert_eq!(code, StatusCode::BAD_REQUEST, "{e}");
    assert!(
        e.starts_with("cuerpo JSON mal formado: no se pudo leer como JSON: EOF"),
        "{e}"
    );
    let (code, e) = ask_in(
        &s,
        es,
        Method::PUT,
        "/api/tags/Llenar",
        Some(br#"{"value": 2}"#.to_vec()),
    )
    .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{e}");
    assert_eq!(e, "`Llenar`: 2 está fuera del rango de BOOL (0 a 1)");
    // A program that does not compile: the count, and its diagnostics, in Spanish.
    let bad = br#"{"text": "XIC(Strat)OTE(Llenr);\n"}"#.to_vec();
    let res = s
        .http
        .put(s.url("/api/programs/main.lad"))
        .header("accept-language", es)
        .header("content-type", "application/json")
        .body(bad.clone())
        .send()
        .await
        .expect("request");
    let (code, j) = Server::answer(res).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert_eq!(j["error"], "2 errores", "{j}");
    assert_eq!(j["diagnostics"][0]["message"], "variable desconocida `Strat`", "{j}");
    // English without the header, and for a language Alba does not speak.
    let (_, e) = ask_in(&s, "de, en;q=0.5", Method::GET, "/api/tags/Nope", None).await;
    assert_eq!(e, "unknown tag `Nope`");
    let (_, e) = ask_in(&s, "en", Method::PUT, "/api/programs/main.lad", Some(bad)).await;
    assert_eq!(e, "2 errors");
    s.stop().await;
    // 409: a board that runs the program refuses a stop, in Spanish.
    let (s, runtime) = serve("tank", "e409-es", Box::new(Board)).await;
    let (code, e) = ask_in(&s, "es", Method::POST, "/api/stop", Some(b"{}".to_vec())).await;
    assert_eq!(code, StatusCode::CONFLICT, "{e}");
    assert!(e.starts_with("la placa ejecuta el programa ("), "{e}");
    s.stop().await;
    runtime.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_503_runtime_not_running() {
    let (s, runtime) = serve("tank", "e503", Box::new(alba_runtime::SimIo)).await;
    assert_eq!(s.get("/api/status").await["project"], "tank");
    runtime.shutdown();
    for (m, path, body) in [
        (Method::POST, "/api/run", None),
        (Method::POST, "/api/step", None),
        (Method::PUT, "/api/tags/Llenar", Some(json!({"value": true}))),
        (Method::DELETE, "/api/forces", None),
    ] {
        let (code, j) = s.call(m, path, body).await;
        assert_eq!(code, StatusCode::SERVICE_UNAVAILABLE, "{path}: {j}");
        assert_eq!(j["error"], "the runtime has stopped");
    }
    s.stop().await;
}

/// A remote server that cannot be reached (the hook alba-app sets for
/// `[[opcua_server]]`).
struct Unreachable;

impl alba_server::connections::Connections for Unreachable {
    fn status(&self) -> Vec<alba_server::reply::Connection> {
        vec![alba_server::reply::Connection {
            name: "plant".into(),
            protocol: "opcua".into(),
            endpoint: "opc.tcp://127.0.0.1:1/".into(),
            ok: false,
            connected: false,
            connects: 0,
            errors: 3,
            last_error: Some("cannot connect: BadNotConnected".into()),
            queue: None,
        }]
    }
    fn browse<'a>(&'a self, server: &'a str, _node: &'a str) -> alba_server::connections::Browsing<'a> {
        use alba_server::connections::BrowseError;
        Box::pin(async move {
            if server == "plant" {
                Err(BrowseError::Upstream("OPC UA server plant: cannot connect".into()))
            } else {
                Err(BrowseError::UnknownServer(server.into()))
            }
        })
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_502_remote_server_unreachable() {
    let dir = copy_example("tank", "e502");
    let compiled = alba_server::project::load(&dir);
    let program = compiled.program.clone().expect("the example compiles");
    let mut ro = Options::new(compiled.project.scan_ms());
    ro.native = false;
    let runtime = Runtime::start(Arc::new(program), ro, Box::new(alba_runtime::SimIo)).expect("runtime");
    let state = alba_server::AppState::new(
        runtime.handle(),
        compiled,
        "test",
        None,
        None,
        alba_server::auth::Auth::open(),
        &alba_settings::Http::default(),
    );
    assert!(state.connections.set(Arc::new(Unreachable)).is_ok());
    let s = Server::serve_state(state, dir).await;
    let (code, j) = s.call(Method::GET, "/api/opcua/plant/browse", None).await;
    assert_eq!(code, StatusCode::BAD_GATEWAY, "{j}");
    assert_eq!(j["error"], "OPC UA server plant: cannot connect");
    let (code, j) = s.call(Method::GET, "/api/opcua/other/browse?node=i%3D85", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND, "{j}");
    let (code, j) = s.call(Method::GET, "/api/opcua/plant/browse?nod=i%3D85", None).await;
    assert_eq!(code, StatusCode::BAD_REQUEST, "{j}");
    // The status shows the hook's connections.
    let st = s.get("/api/status").await;
    assert_eq!(
        st["connections"][0]["last_error"], "cannot connect: BadNotConnected",
        "{st}"
    );
    s.stop().await;
    drop(runtime);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_connections_the_status_lists_none_and_browse_is_404() {
    let s = Server::start("tank", "noconn").await;
    assert_eq!(s.get("/api/status").await["connections"], json!([]));
    let (code, j) = s.call(Method::GET, "/api/opcua/plant/browse", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND, "{j}");
    assert_eq!(j["error"], "no [[opcua_server]] named `plant` in alba.toml");
    s.stop().await;
}
