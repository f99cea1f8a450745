//! `POST /api/verify` and `POST /api/tests` (issue 37, point 3) through
//! `alba run`: examples/start-stop with one property that holds and one
//! that fails; the counterexample replayed scan by scan into the violation;
//! the tables run with coverage; a viewer refused; a broken properties.toml
//! answered 422 with its line.

use super::{add_role_users, login, options, serve};
use reqwest::StatusCode;
use serde_json::{Value as Json, json};
use std::path::{Path, PathBuf};
use std::time::Duration;

const PROPERTIES: &str = "[[property]]\nname = \"stop wins\"\nnever = \"Stop AND Motor\"\n\n\
[[property]]\nname = \"the lamp never lights\"\nnever = \"Lamp\"\n";

fn project(test: &str) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/start-stop");
    let dir = std::env::temp_dir().join(format!("alba-app-verify-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("tests")).expect("scratch dir");
    for f in [
        "alba.toml",
        "tags.csv",
        "main.lad",
        "tests/run-and-stop.test.csv",
        "tests/stop-wins.test.csv",
    ] {
        std::fs::copy(src.join(f), dir.join(f)).expect("copy");
    }
    std::fs::write(dir.join("properties.toml"), PROPERTIES).expect("properties.toml");
    add_role_users(&dir);
    dir
}

async fn post(c: &reqwest::Client, http: std::net::SocketAddr, path: &str, token: &str) -> (StatusCode, Json) {
    let r = c
        .post(format!("http://{http}{path}"))
        .bearer_auth(token)
        .json(&json!({}))
        .send()
        .await
        .expect("request");
    let s = r.status();
    (s, r.json().await.unwrap_or(Json::Null))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_studio_decides_properties_replays_counterexamples_and_runs_tables_with_coverage() {
    let dir = project("run");
    let mut o = options("sim");
    o.quiet = true;
    let (http, stop, task) = serve(&dir, o).await;
    let c = reqwest::Client::new();
    let engineer = login(&c, http, "engineer").await;
    let viewer = login(&c, http, "viewer").await;

    // Seconds of CPU: for engineers.
    for path in ["/api/verify", "/api/tests"] {
        let (s, j) = post(&c, http, path, &viewer).await;
        assert_eq!(s, StatusCode::FORBIDDEN, "{path}: {j}");
    }

    let (s, j) = post(&c, http, "/api/verify", &engineer).await;
    assert_eq!(s, StatusCode::OK, "{j}");
    assert_eq!(j["scan_ms"], 10);
    let props = j["properties"].as_array().expect("properties");
    assert_eq!(props.len(), 2);
    assert_eq!(props[0]["name"], "stop wins");
    assert_eq!(props[0]["result"], "proved", "{}", props[0]);
    assert!(props[0]["counterexample"].is_null());
    assert_eq!(props[0]["method"], "k-induction", "{}", props[0]);
    let p = &props[1];
    assert_eq!(p["result"], "refuted", "{p}");
    assert_eq!(p["method"], "explicit", "{p}");
    let cx = &p["counterexample"];
    let tags: Vec<&str> = cx["tags"]
        .as_array()
        .expect("tags")
        .iter()
        .map(|t| t.as_str().unwrap_or(""))
        .collect();
    let lamp = tags.iter().position(|t| *t == "Lamp").expect("Lamp shown");
    let scans = cx["scans"].as_array().expect("scans");
    let bad = cx["violating_scan"].as_u64().expect("violating_scan") as usize;
    assert_eq!(scans.len(), p["depth"].as_u64().expect("depth") as usize);
    assert_eq!(bad, scans.len() - 1);
    assert_eq!(cx["first_scan"], 0, "a short run keeps every scan");
    // The violation is at the violating scan and not before: the lamp lights 5 s after Start.
    assert_eq!(scans[bad]["values"][lamp], "1", "{}", scans[bad]);
    assert!(scans[..bad].iter().all(|s| s["values"][lamp] == "0"));
    assert!(scans[bad]["time_ms"].as_u64().expect("time") >= 5000);
    assert!(!scans[bad]["on"].as_array().expect("on").is_empty());
    let rows = cx["rows"].as_array().expect("rows");
    assert!(
        rows.iter().any(|r| r["tag"] == "Start" && r["value"] == "1"),
        "{rows:?}"
    );

    // One property by name; a name not there is a 422 naming it.
    let r = c
        .post(format!("http://{http}/api/verify"))
        .bearer_auth(&engineer)
        .json(&json!({"property": "stop wins", "time_limit_s": 5}))
        .send()
        .await
        .expect("verify one");
    assert_eq!(r.status(), StatusCode::OK);
    let j: Json = r.json().await.expect("JSON");
    assert_eq!(j["properties"].as_array().map(Vec::len), Some(1));
    let r = c
        .post(format!("http://{http}/api/verify"))
        .bearer_auth(&engineer)
        .json(&json!({"property": "nope"}))
        .send()
        .await
        .expect("verify nope");
    assert_eq!(r.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let j: Json = r.json().await.expect("JSON");
    assert!(j.to_string().contains("nope"), "{j}");
    let r = c
        .post(format!("http://{http}/api/verify"))
        .bearer_auth(&engineer)
        .json(&json!({"time_limit_s": 0}))
        .send()
        .await
        .expect("verify 0 s");
    assert_eq!(r.status(), StatusCode::UNPROCESSABLE_ENTITY);

    // The tables: both pass; the coverage names main.lad's elements.
    let (s, j) = post(&c, http, "/api/tests", &engineer).await;
    assert_eq!(s, StatusCode::OK, "{j}");
    assert_eq!(j["passed"], 2, "{j}");
    assert_eq!(j["failed"], 0);
    let names: Vec<&str> = j["tests"]
        .as_array()
        .expect("tests")
        .iter()
        .map(|t| t["name"].as_str().unwrap_or(""))
        .collect();
    assert_eq!(names, ["run-and-stop", "stop-wins"]);
    let cov = j["coverage"].as_array().expect("coverage");
    assert_eq!(cov.len(), 1);
    assert!(
        cov[0]["program"].as_str().expect("program").contains("main"),
        "{}",
        cov[0]
    );
    let all = cov[0]["elements"].as_array().expect("elements").len();
    let powered = cov[0]["powered"].as_array().expect("powered").len();
    // The lamp never lights in these tables (5090 ms is 10 ms short of its 5 s... after 100 ms):
    // some element is never powered, most are.
    assert!(powered > 0 && powered <= all, "{powered} of {all}");
    assert_eq!(j["rungs"], 3);

    // A table that fails names its cell.
    std::fs::write(
        dir.join("tests/wrong.test.csv"),
        "time_ms,Start,Stop,expect:Motor\n0,1,0,0\n",
    )
    .expect("write");
    let (s, j) = post(&c, http, "/api/tests", &engineer).await;
    assert_eq!(s, StatusCode::OK, "{j}");
    assert_eq!(j["failed"], 1, "{j}");
    let wrong = &j["tests"][2];
    assert_eq!(wrong["result"], "failed");
    assert_eq!(wrong["line"], 2);
    assert!(wrong["message"].as_str().expect("message").contains("Motor"), "{wrong}");

    // A broken properties.toml: 422 with the line of the problem.
    std::fs::write(
        dir.join("properties.toml"),
        "[[property]]\nname = \"x\"\nnever = \"Nope AND\"\n",
    )
    .expect("write");
    let (s, j) = post(&c, http, "/api/verify", &engineer).await;
    assert_eq!(s, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert_eq!(j["diagnostics"][0]["line"], 3, "{j}");

    let _ = stop.send(());
    tokio::time::timeout(Duration::from_secs(20), task)
        .await
        .expect("stops")
        .expect("task");
    let _ = std::fs::remove_dir_all(&dir);
}
