//! Recipes (docs/api.md, "Recipes"): saved as CSV or JSON into
//! `recipes/<name>.csv`, applied at one scan boundary through the control
//! layer, refused with the first bad row named and nothing written.

use crate::{Server, copy_example};
use reqwest::{Method, StatusCode};
use serde_json::{Value as Json, json};

/// The tank with three tags its program leaves alone.
async fn tank(test: &str) -> Server {
    let dir = copy_example("tank", test);
    let mut tags = std::fs::read_to_string(dir.join("tags.csv")).expect("tags.csv");
    tags.push_str("Setpoint,INT,,100,,recipe test\nRatio,REAL,,,,recipe test\nMode,BOOL,,,,recipe test\n");
    std::fs::write(dir.join("tags.csv"), tags).expect("tags.csv");
    Server::start_in(dir).await
}

async fn values(s: &Server) -> (Json, Json, Json) {
    (s.value("Setpoint").await, s.value("Ratio").await, s.value("Mode").await)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_recipe_is_saved_read_back_and_applied_under_audit() {
    let s = tank("recipes-apply").await;
    let (c, j) = s
        .call(
            Method::PUT,
            "/api/recipes/batch-A",
            Some(json!({"Setpoint": 250, "Ratio": 0.75, "Mode": true})),
        )
        .await;
    assert_eq!(c, StatusCode::OK, "{j}");
    let file = std::fs::read_to_string(s.dir.join("recipes/batch-A.csv")).expect("saved");
    assert_eq!(file, "tag,value\nMode,true\nRatio,0.75\nSetpoint,250\n");
    // CSV, in its own order.
    let (c, j) = s
        .raw(
            Method::PUT,
            "/api/recipes/batch_B",
            "text/csv",
            b"tag,value\nSetpoint,-3\nMode,false\n".to_vec(),
        )
        .await;
    assert_eq!(c, StatusCode::OK, "{j}");
    assert_eq!(s.get("/api/recipes").await, json!(["batch-A", "batch_B"]));
    let text = s
        .http
        .get(s.url("/api/recipes/batch_B"))
        .send()
        .await
        .expect("get")
        .text()
        .await
        .expect("body");
    assert_eq!(text, r#"{"Setpoint":-3,"Mode":false}"#);

    assert_eq!(values(&s).await, (json!(100), json!(0.0), json!(false)));
    let (c, j) = s.call(Method::POST, "/api/recipes/batch-A/apply", None).await;
    assert_eq!(c, StatusCode::OK, "{j}");
    assert_eq!(j["written"], json!(3));
    assert_eq!(values(&s).await, (json!(250), json!(0.75), json!(true)));

    let rows = s.get("/api/audit").await["rows"].as_array().expect("rows").clone();
    let writes: Vec<&Json> = rows.iter().filter(|r| r["action"] == "write").collect();
    assert_eq!(writes.len(), 3, "{rows:?}");
    assert!(
        writes
            .iter()
            .all(|r| r["detail"] == "recipe batch-A" && r["outcome"] == "ok")
    );
    let saves: Vec<&Json> = rows.iter().filter(|r| r["action"] == "save_recipe").collect();
    assert_eq!(saves.len(), 2, "{rows:?}");
    assert!(saves.iter().any(|r| r["target"] == "recipes/batch_B.csv"));
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_recipe_with_a_bad_row_is_refused_and_writes_nothing() {
    let s = tank("recipes-refused").await;
    let before = values(&s).await;
    for (csv, row, tag) in [
        ("Setpoint,7\nNoSuchTag,1\n", 2, "NoSuchTag"),
        ("Setpoint,7\nRatio,1.5\nSTOP,true\n", 3, "STOP"),
        ("Mode,true\nSetpoint,40000\n", 2, "Setpoint"),
        ("Setpoint,7\nMode,\"yes\"\n", 2, "Mode"),
        ("Setpoint,7\nNivel_L,1\nCT_STP,3\n", 3, "CT_STP"),
    ] {
        let (c, j) = s
            .raw(Method::PUT, "/api/recipes/bad", "text/csv", csv.as_bytes().to_vec())
            .await;
        assert_eq!(c, StatusCode::OK, "saved as written: {j}");
        let (c, j) = s.call(Method::POST, "/api/recipes/bad/apply", None).await;
        assert_eq!(c, StatusCode::UNPROCESSABLE_ENTITY, "{csv}: {j}");
        let e = j["error"].as_str().expect("error");
        assert!(e.contains(&format!("row {row} (`{tag}`)")), "{csv}: {e}");
        assert!(e.contains("nothing written"), "{e}");
        assert_eq!(values(&s).await, before, "{csv}: nothing written");
    }
    let rows = s.get("/api/audit").await["rows"].as_array().expect("rows").clone();
    assert!(rows.iter().all(|r| r["action"] != "write"), "{rows:?}");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn malformed_recipes_and_names_are_400_and_missing_ones_404() {
    let s = tank("recipes-malformed").await;
    for (ctype, body) in [
        ("application/json", "[1, 2]"),
        ("application/json", r#"{"Setpoint": [1]}"#),
        ("application/json", r#"{"Setpoint": 1, "Setpoint": 2}"#),
        ("text/csv", "Setpoint\n"),
        ("text/csv", "bad tag,1\n"),
    ] {
        let (c, j) = s
            .raw(Method::PUT, "/api/recipes/r", ctype, body.as_bytes().to_vec())
            .await;
        assert_eq!(c, StatusCode::BAD_REQUEST, "{body}: {j}");
    }
    assert!(!s.dir.join("recipes/r.csv").exists());
    let (c, _) = s
        .call(Method::PUT, "/api/recipes/..%2Fx", Some(json!({"Mode": true})))
        .await;
    assert_eq!(c, StatusCode::BAD_REQUEST);
    // Edited by hand into something that does not read: 422 with the line, nothing written.
    std::fs::create_dir_all(s.dir.join("recipes")).expect("recipes/");
    std::fs::write(s.dir.join("recipes/hand.csv"), "tag,value\nSetpoint,9\nMode\n").expect("hand.csv");
    for (m, path) in [
        (Method::GET, "/api/recipes/hand"),
        (Method::POST, "/api/recipes/hand/apply"),
    ] {
        let (c, j) = s.call(m, path, None).await;
        assert_eq!(c, StatusCode::UNPROCESSABLE_ENTITY, "{path}: {j}");
        assert!(j["error"].as_str().expect("error").contains("line 3"), "{j}");
    }
    assert_eq!(s.value("Setpoint").await, json!(100));
    let (c, _) = s.call(Method::GET, "/api/recipes/none", None).await;
    assert_eq!(c, StatusCode::NOT_FOUND);
    let (c, _) = s.call(Method::POST, "/api/recipes/none/apply", None).await;
    assert_eq!(c, StatusCode::NOT_FOUND);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_recipe_is_captured_from_the_current_values() {
    let s = tank("recipes-capture").await;
    for (tag, v) in [("Setpoint", json!(321)), ("Mode", json!(true))] {
        let (c, j) = s
            .call(Method::PUT, &format!("/api/tags/{tag}"), Some(json!({"value": v})))
            .await;
        assert_eq!(c, StatusCode::OK, "{j}");
    }
    let (c, j) = s
        .call(
            Method::POST,
            "/api/recipes/now/capture",
            Some(json!({"tags": ["Setpoint", "Mode", "Ratio"]})),
        )
        .await;
    assert_eq!(c, StatusCode::OK, "{j}");
    assert_eq!(j["values"], json!({"Setpoint": 321, "Mode": true, "Ratio": 0.0}));
    let file = std::fs::read_to_string(s.dir.join("recipes/now.csv")).expect("saved");
    assert_eq!(file, "tag,value\nSetpoint,321\nMode,true\nRatio,0.0\n");
    // Again from the recipe's own tags, after a change.
    s.call(Method::PUT, "/api/tags/Setpoint", Some(json!({"value": 5})))
        .await;
    let (c, j) = s.call(Method::POST, "/api/recipes/now/capture", None).await;
    assert_eq!(c, StatusCode::OK, "{j}");
    assert_eq!(j["values"]["Setpoint"], json!(5));
    // A tag that is not there: 422 naming it, nothing saved.
    let (c, j) = s
        .call(
            Method::POST,
            "/api/recipes/other/capture",
            Some(json!({"tags": ["Mode", "Nope"]})),
        )
        .await;
    assert_eq!(c, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert!(j["error"].as_str().expect("error").contains("row 2 (`Nope`)"), "{j}");
    assert!(!s.dir.join("recipes/other.csv").exists());
    s.stop().await;
}
