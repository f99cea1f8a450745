//! What the studio's net editor needs of the server: single step
//! (`POST /api/step`), each transition's monitored "enabled" and "fired"
//! elements (`GET /api/programs/{name}`, power flow on the WebSocket) and the
//! reset of a net's marking in one step (`POST /api/nets/{name}/reset`).

use crate::Server;
use crate::ws::{connect, next, send};
use reqwest::{Method, StatusCode};
use serde_json::{Value as Json, json};
use std::collections::{BTreeSet, HashMap};

async fn audit_rows(s: &Server, action: &str) -> Vec<Json> {
    let page = s.get(&format!("/api/audit?action={action}")).await;
    page["rows"].as_array().expect("rows").clone()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn single_step_runs_one_scan_while_stopped_and_is_refused_while_running() {
    let s = Server::start("tank", "step").await;
    let (code, j) = s.call(Method::POST, "/api/step", None).await;
    assert_eq!(
        (code, j),
        (
            StatusCode::CONFLICT,
            json!({"error": "the runtime is running: stop it before stepping one scan"})
        )
    );
    let (code, j) = s.call(Method::POST, "/api/stop", None).await;
    assert_eq!((code, &j["state"]), (StatusCode::OK, &json!("stopped")));
    let n = j["scans"].as_u64().expect("scans");
    for k in 1..=3 {
        let (code, j) = s.call(Method::POST, "/api/step", None).await;
        assert_eq!(code, StatusCode::OK, "{j}");
        // Answered after the scan: the status already counts it.
        assert_eq!(j["scans"], n + k, "{j}");
        assert_eq!(j["state"], "stopped");
    }
    tokio::time::sleep(std::time::Duration::from_millis(100)).await;
    assert_eq!(s.scans().await, n + 3, "no scan between steps");
    // The program ran in those scans: the tank's run lamp follows the program.
    let (code, _) = s.call(Method::POST, "/api/run", None).await;
    assert_eq!(code, StatusCode::OK);
    // Audited as run and stop are: the refused step too.
    let rows = audit_rows(&s, "step").await;
    let outcomes: Vec<&str> = rows
        .iter()
        .rev()
        .map(|r| r["outcome"].as_str().expect("outcome"))
        .collect();
    assert_eq!(outcomes, ["failed", "ok", "ok", "ok"]);
    assert_eq!(rows[0]["old"], json!(n + 2));
    assert_eq!(rows[0]["new"], json!(n + 3));
    s.stop().await;
}

/// The energised elements of a power message, as (enabled, fired) sets of
/// transition ids.
fn lit(
    on: &Json,
    enabled: &HashMap<u64, String>,
    fired: &HashMap<u64, String>,
) -> (BTreeSet<String>, BTreeSet<String>) {
    let ids: Vec<u64> = on["on"]
        .as_array()
        .expect("on")
        .iter()
        .filter_map(Json::as_u64)
        .collect();
    let pick = |m: &HashMap<u64, String>| ids.iter().filter_map(|i| m.get(i).cloned()).collect();
    (pick(enabled), pick(fired))
}

fn set(ids: &[&str]) -> BTreeSet<String> {
    ids.iter().map(|s| s.to_string()).collect()
}

/// Each transition of a net has an "enabled" element (arcs satisfied by the
/// marking after the scan, and the guard as evaluated in it) and a "fired"
/// one (it fired in that scan), monitored like a ladder element.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn net_transitions_have_enabled_and_fired_elements() {
    let s = Server::start("petri-resource", "net-enabled").await;
    let p = s.get("/api/programs/cell.pnml").await;
    let ts = p["transitions"].as_array().expect("transitions").clone();
    let ids: Vec<&str> = ts.iter().map(|t| t["id"].as_str().expect("id")).collect();
    assert_eq!(
        ids,
        [
            "arrive1", "grab1", "loaded1", "finish1", "arrive2", "grab2", "loaded2", "finish2"
        ]
    );
    let mut enabled = HashMap::new();
    let mut fired = HashMap::new();
    for t in &ts {
        let id = t["id"].as_str().expect("id").to_string();
        enabled.insert(t["enabled"].as_u64().expect("an enabled element"), id.clone());
        fired.insert(t["fired"].as_u64().expect("a fired element"), id);
    }
    assert_eq!(enabled.len() + fired.len(), 16, "distinct elements: {ts:?}");
    // A ladder program has no transitions.
    assert!(s.get("/api/programs/main.lad").await.get("transitions").is_none());

    let (code, _) = s.call(Method::POST, "/api/stop", None).await;
    assert_eq!(code, StatusCode::OK);
    let mut ws = connect(&s).await;
    send(&mut ws, json!({"monitor": ["cell.pnml"]})).await;
    // Stopped: nothing energised.
    let m = next(&mut ws, "power", |_| true).await;
    assert_eq!(m["on"], json!([]));
    // A part at machine 1: arrive1 fires; now grab1 is enabled (wait1 and the robot).
    let (code, _) = s
        .call(Method::PUT, "/api/forces/Part1", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::OK);
    let (_, st) = s.call(Method::POST, "/api/step", None).await;
    let scan = st["scans"].clone();
    let m = next(&mut ws, "power", |j| j["scan"] == scan).await;
    assert_eq!(lit(&m, &enabled, &fired), (set(&["grab1"]), set(&["arrive1"])));
    assert_eq!(s.value("cell.wait1").await, 1);
    // grab1 fires; loaded1's arc is satisfied (load1) but its guard (Load1T.DN) is not.
    let (_, st) = s.call(Method::POST, "/api/step", None).await;
    let scan = st["scans"].clone();
    let m = next(&mut ws, "power", |j| j["scan"] == scan).await;
    assert_eq!(lit(&m, &enabled, &fired), (set(&[]), set(&["grab1"])));
    assert_eq!(s.value("cell.load1").await, 1);
    // Machine 2's part: arrive2 fires, and grab2 waits for the robot (not enabled).
    let (code, _) = s
        .call(Method::PUT, "/api/forces/Part2", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::OK);
    let (_, st) = s.call(Method::POST, "/api/step", None).await;
    let scan = st["scans"].clone();
    let m = next(&mut ws, "power", |j| j["scan"] == scan).await;
    assert_eq!(lit(&m, &enabled, &fired), (set(&[]), set(&["arrive2"])));
    assert_eq!(s.value("cell.wait2").await, 1);
    s.stop().await;
}

/// `POST /api/nets/{name}/reset`: the initial marking, written at one scan
/// boundary, audited; refused for what is not a net of the running program.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_net_marking_is_reset_in_one_step() {
    let s = Server::start("petri-resource", "net-reset").await;
    let (code, _) = s.call(Method::POST, "/api/stop", None).await;
    assert_eq!(code, StatusCode::OK);
    let (code, _) = s
        .call(Method::PUT, "/api/forces/Part1", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::OK);
    for _ in 0..2 {
        assert_eq!(s.call(Method::POST, "/api/step", None).await.0, StatusCode::OK);
    }
    let (code, _) = s
        .call(Method::PUT, "/api/tags/cell.done", Some(json!({"value": 4})))
        .await;
    assert_eq!(code, StatusCode::OK);
    assert_eq!(
        (
            s.value("cell.robot").await,
            s.value("cell.idle1").await,
            s.value("cell.load1").await
        ),
        (json!(0), json!(0), json!(1))
    );
    let (code, j) = s.call(Method::POST, "/api/nets/cell/reset", None).await;
    assert_eq!(code, StatusCode::OK, "{j}");
    assert_eq!(j["program"], "cell.pnml");
    let marking = j["marking"].as_array().expect("marking");
    assert_eq!(marking.len(), 10);
    assert_eq!(marking[0], json!({"tag": "cell.robot", "value": 1}));
    let want = [
        ("cell.robot", 1),
        ("cell.idle1", 1),
        ("cell.wait1", 0),
        ("cell.load1", 0),
        ("cell.work1", 0),
        ("cell.idle2", 1),
        ("cell.done", 0),
    ];
    for (tag, v) in want {
        assert_eq!(s.value(tag).await, json!(v), "{tag}");
    }
    // By file name too; audited with the marking written.
    let (code, _) = s.call(Method::POST, "/api/nets/cell.pnml/reset", None).await;
    assert_eq!(code, StatusCode::OK);
    let rows = audit_rows(&s, "reset_marking").await;
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["target"], "cell.pnml");
    assert_eq!(rows[0]["new"][0], json!({"tag": "cell.robot", "value": 1}));
    // Not a net, no such net.
    let (code, j) = s.call(Method::POST, "/api/nets/main.lad/reset", None).await;
    assert_eq!(
        (code, j),
        (
            StatusCode::NOT_FOUND,
            json!({"error": "no net `main.lad` in the project"})
        )
    );
    let (code, _) = s.call(Method::POST, "/api/nets/nope/reset", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND);
    // Saved but not applied: the running program lacks the new place's marking.
    let text = s.get("/api/programs/cell.pnml").await["text"]
        .as_str()
        .expect("text")
        .replace(r#"<place id="done">"#, r#"<place id="extra"/><place id="done">"#);
    let (code, j) = s
        .call(
            Method::PUT,
            "/api/programs/cell.pnml",
            Some(json!({"text": text, "online": false})),
        )
        .await;
    assert_eq!(code, StatusCode::OK, "{j}");
    let (code, j) = s.call(Method::POST, "/api/nets/cell/reset", None).await;
    assert_eq!(
        (code, j),
        (
            StatusCode::UNPROCESSABLE_ENTITY,
            json!({"error": "the running program has no marking tag `cell.extra`: save the net and apply it online first"})
        )
    );
    s.stop().await;
}
