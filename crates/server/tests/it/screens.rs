//! `GET /api/screens`, `GET|PUT /api/screens/{name}` (issue 17): screens
//! saved in the project, checked against the program's tags with the error
//! at its place.

use crate::Server;
use reqwest::{Method, StatusCode};
use serde_json::{Value as Json, json};

async fn put_text(s: &Server, name: &str, text: &str) -> (StatusCode, Json) {
    put_at(s, &format!("/api/screens/{name}"), text).await
}

async fn put_at(s: &Server, path: &str, text: &str) -> (StatusCode, Json) {
    let res = s
        .http
        .put(s.url(path))
        .header("content-type", "application/json")
        .body(text.to_string())
        .send()
        .await
        .expect("PUT");
    let code = res.status();
    (code, res.json().await.unwrap_or(Json::Null))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn screens_are_saved_checked_and_refused_at_their_place() {
    let s = Server::start("tank-plant", "screens").await;
    assert_eq!(s.get("/api/screens").await, json!([]));
    let screen = json!({"schema": 1, "title": "Tank", "width": 1280, "height": 720, "elements": [
        {"id": "tank", "type": "tank", "x": 100, "y": 80, "w": 120, "h": 200,
         "animations": [{"kind": "fill", "tag": "Nivel_L", "min": 0, "max": 60, "direction": "up"}]},
        {"id": "b1", "type": "pump", "x": 300, "y": 240, "w": 60, "h": 60,
         "animations": [{"kind": "rotate", "tag": "Bomba1", "speed": 1}]},
        {"id": "fill", "type": "button", "x": 300, "y": 320, "w": 80, "h": 32, "props": {"label": "Fill"},
         "action": {"kind": "momentary", "tag": "Llenar"}}
    ]});
    let (code, saved) = put_text(&s, "tank", &screen.to_string()).await;
    assert_eq!(code, StatusCode::OK, "{saved}");
    assert_eq!(s.get("/api/screens").await, json!(["tank"]));
    let back = s.get("/api/screens/tank").await;
    assert_eq!(back["elements"][0]["animations"][0]["tag"], "Nivel_L");
    assert!(s.dir.join("hmi/tank.json").exists());
    // An unknown tag: refused, the error on the element (line and column), the file unchanged.
    let bad = "{\"schema\": 1, \"width\": 800, \"height\": 600, \"elements\": [\n  {\"id\": \"t\", \"type\": \"tank\", \"x\": 0, \"y\": 0, \"w\": 10, \"h\": 10,\n   \"animations\": [{\"kind\": \"fill\", \"tag\": \"Nivel_X\"}]}]}";
    let (code, j) = put_text(&s, "tank", bad).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let d = &j["diagnostics"][0];
    assert_eq!(
        (
            d["code"].as_str(),
            d["file"].as_str(),
            d["line"].as_u64(),
            d["col"].as_u64()
        ),
        (Some("E141"), Some("tank.json"), Some(3), Some(43)),
        "{j}"
    );
    assert!(
        d["message"]
            .as_str()
            .is_some_and(|m| m.contains("unknown tag `Nivel_X`")),
        "{j}"
    );
    assert_eq!(s.get("/api/screens/tank").await, back);
    // A button on an input, an unknown element type: each said.
    let input = screen.to_string().replace("\"Llenar\"", "\"FILL\"");
    let (code, j) = put_text(&s, "tank", &input).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(j.to_string().contains("`FILL` cannot be written from a screen"), "{j}");
    let (code, j) = put_text(&s, "tank", "{not json").await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(j.to_string().contains("not a screen file"), "{j}");
    let (code, _) = put_text(&s, "bad%20name", &screen.to_string()).await;
    assert_eq!(code, StatusCode::BAD_REQUEST);
    let (code, _) = s.call(Method::GET, "/api/screens/nope", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND);
    s.stop().await;
}

async fn post_check(s: &Server, name: &str, text: &str) -> (StatusCode, Json) {
    let res = s
        .http
        .post(s.url(&format!("/api/screens/{name}/check")))
        .header("content-type", "application/json")
        .body(text.to_string())
        .send()
        .await
        .expect("POST");
    let code = res.status();
    (code, res.json().await.unwrap_or(Json::Null))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_screen_is_checked_without_being_saved() {
    let s = Server::start("tank-plant", "screen-check").await;
    let bad = "{\"schema\": 1, \"width\": 800, \"height\": 600, \"elements\": [\n  {\"id\": \"t\", \"type\": \"tank\", \"x\": 0, \"y\": 0, \"w\": 10, \"h\": 10,\n   \"animations\": [{\"kind\": \"fill\", \"tag\": \"Nivel_X\"}]}]}";
    // The problems as a save would answer them, at their place; nothing written.
    let (code, j) = post_check(&s, "draft", bad).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let d = &j["diagnostics"][0];
    assert_eq!(
        (d["code"].as_str(), d["file"].as_str(), d["line"].as_u64()),
        (Some("E141"), Some("draft.json"), Some(3)),
        "{j}"
    );
    assert!(
        d["message"]
            .as_str()
            .is_some_and(|m| m.starts_with("`t`: ") && m.contains("unknown tag `Nivel_X`")),
        "{j}"
    );
    // Fixed: the screen as it would be saved, still nothing written.
    let (code, j) = post_check(&s, "draft", &bad.replace("Nivel_X", "Nivel_L")).await;
    assert_eq!(code, StatusCode::OK, "{j}");
    assert_eq!(j["elements"][0]["animations"][0]["tag"], "Nivel_L");
    assert!(!s.dir.join("hmi/draft.json").exists());
    assert_eq!(s.get("/api/screens").await, json!([]));
    let (code, _) = post_check(&s, "bad%20name", &bad.replace("Nivel_X", "Nivel_L")).await;
    assert_eq!(code, StatusCode::BAD_REQUEST);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn symbols_are_groups_saved_and_checked_like_screens_and_alba_check_reads_them() {
    let s = Server::start("tank-plant", "symbols").await;
    assert_eq!(s.get("/api/symbols").await, json!([]));
    let sym = json!({"schema": 1, "width": 90, "height": 60, "elements": [
        {"id": "b", "type": "pump", "x": 0, "y": 0, "w": 60, "h": 60, "group": "g1",
         "animations": [{"kind": "rotate", "tag": "Bomba1", "speed": 1}]},
        {"id": "l", "type": "led", "x": 70, "y": 0, "w": 20, "h": 20, "group": "g1"}
    ]});
    let (code, saved) = put_at(&s, "/api/symbols/pump_set", &sym.to_string()).await;
    assert_eq!(code, StatusCode::OK, "{saved}");
    assert_eq!(s.get("/api/symbols").await, json!(["pump_set"]));
    assert_eq!(s.get("/api/symbols/pump_set").await["elements"][1]["group"], "g1");
    assert!(s.dir.join("hmi/symbols/pump_set.json").exists());
    // The symbols folder is not a screen.
    assert_eq!(s.get("/api/screens").await, json!([]));
    let bad = sym.to_string().replace("Bomba1", "Bomba7");
    let (code, j) = put_at(&s, "/api/symbols/pump_set", &bad).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert_eq!(j["diagnostics"][0]["file"], "pump_set.json", "{j}");
    let dir = s.dir.clone();
    // A symbol damaged on disk is found by `alba check` with its place.
    std::fs::write(dir.join("hmi/symbols/pump_set.json"), &bad).expect("write");
    let mut files = alba_compiler::diag::Files::new();
    let program = alba_load::compile_dir(&dir).program.expect("compiles");
    let (screens, diags) = alba_compiler::screens::check_dir(&dir, &mut files, &program.layout, &[]);
    assert_eq!(screens, 0);
    assert!(diags[0].message.contains("unknown tag `Bomba7`"), "{:?}", diags);
    s.stop().await;
}
