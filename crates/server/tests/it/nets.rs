//! What the studio's net editor needs of the server: single step
//! (`POST /api/step`), each transition's monitored "enabled" and "fired"
//! elements (`GET /api/programs/{name}`, power flow on the WebSocket) and the
//! reset of a net's marking in one step (`POST /api/nets/{name}/reset`),
//! and its analysis on demand (`POST /api/nets/{name}/analysis`) within
//! limits (issue 31, point 2).

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

/// A project of two nets: `loop.pnml` (Petri mode, `t` fires every scan while
/// `Go`, leaving the marking as it was) and `flow.pnml` (normal mode, a timer).
fn two_nets(test: &str) -> std::path::PathBuf {
    let dir = crate::copy_example("start-stop", test);
    for f in ["main.lad", "stimulus.csv", "golden.csv", "golden.args"] {
        let _ = std::fs::remove_file(dir.join(f));
    }
    std::fs::write(
        dir.join("tags.csv"),
        "name,type,address,initial,retain,description\nGo,BOOL,,,,\n",
    )
    .expect("tags");
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"nets\"\nscan_ms = 10\nprograms = [\"loop.pnml\", \"flow.pnml\"]\n",
    )
    .expect("toml");
    let pnml = |body: &str| {
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml"><net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">{body}</net></pnml>"#
        )
    };
    std::fs::write(
        dir.join("loop.pnml"),
        pnml(
            r#"<page id="pg"><place id="p"><initialMarking><text>1</text></initialMarking></place>
<transition id="t"><toolspecific tool="alba" version="1"><guard>Go</guard></toolspecific></transition>
<arc id="a1" source="p" target="t"/><arc id="a2" source="t" target="p"/></page>"#,
        ),
    )
    .expect("loop");
    std::fs::write(
        dir.join("flow.pnml"),
        pnml(
            r#"<toolspecific tool="alba" version="1"><mode>normal</mode></toolspecific>
<page id="pg"><place id="S0"><initialMarking><text>1</text></initialMarking></place><place id="S1"/>
<transition id="wait"><toolspecific tool="alba" version="1"><kind>timer</kind><prop name="delay">T#1h</prop></toolspecific></transition>
<arc id="a1" source="S0" target="wait"/><arc id="a2" source="wait" target="S1"/></page>"#,
        ),
    )
    .expect("flow");
    dir
}

/// A net's power flow is sent for every scan in which something is
/// energised, so a transition firing scan after scan is seen each time; in
/// normal mode a transition holding its token (a timer timing) is enabled.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn repeated_firings_are_each_sent_and_normal_mode_has_enabled_transitions() {
    let s = Server::start_in(two_nets("net-repeat")).await;
    let elems = |p: &Json| {
        let t = &p["transitions"][0];
        (
            t["enabled"].as_u64().expect("enabled"),
            t["fired"].as_u64().expect("fired"),
        )
    };
    let (loop_enabled, loop_fired) = elems(&s.get("/api/programs/loop.pnml").await);
    let (wait_enabled, wait_fired) = elems(&s.get("/api/programs/flow.pnml").await);
    assert_eq!(s.call(Method::POST, "/api/stop", None).await.0, StatusCode::OK);
    let (code, _) = s.call(Method::PUT, "/api/tags/Go", Some(json!({"value": true}))).await;
    assert_eq!(code, StatusCode::OK);
    let mut ws = connect(&s).await;
    send(&mut ws, json!({"monitor": ["loop.pnml", "flow.pnml"]})).await;
    next(&mut ws, "power", |j| j["program"] == "loop.pnml").await;
    for _ in 0..3 {
        let (_, st) = s.call(Method::POST, "/api/step", None).await;
        let scan = st["scans"].clone();
        let m = next(&mut ws, "power", |j| j["program"] == "loop.pnml" && j["scan"] == scan).await;
        assert_eq!(m["on"], json!([loop_fired, loop_enabled]), "{m}");
    }
    // The timer holds the token (the first scans passed it on from S0): enabled, not fired.
    let (_, st) = s.call(Method::POST, "/api/step", None).await;
    let scan = st["scans"].clone();
    let m = next(&mut ws, "power", |j| j["program"] == "flow.pnml" && j["scan"] == scan).await;
    let on: Vec<u64> = m["on"]
        .as_array()
        .expect("on")
        .iter()
        .filter_map(Json::as_u64)
        .collect();
    assert!(on.contains(&wait_enabled) && !on.contains(&wait_fired), "{m}");
    // Go off: `t` neither fires nor is enabled, and the message says so once.
    let (code, _) = s.call(Method::PUT, "/api/tags/Go", Some(json!({"value": false}))).await;
    assert_eq!(code, StatusCode::OK);
    let (_, st) = s.call(Method::POST, "/api/step", None).await;
    let scan = st["scans"].clone();
    let m = next(&mut ws, "power", |j| j["program"] == "loop.pnml" && j["scan"] == scan).await;
    assert_eq!(m["on"], json!([]), "{m}");
    s.stop().await;
}

/// An online edit of a net (docs/nets.md, "Marking tags") keeps the marking
/// of every place whose id did not change — even when its initial marking
/// changed — and starts a new or renamed place from its initial marking;
/// the next scan runs on from the kept marking.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_online_edit_keeps_the_markings_of_unchanged_places() {
    let s = Server::start("petri-resource", "net-online").await;
    assert_eq!(s.call(Method::POST, "/api/stop", None).await.0, StatusCode::OK);
    for part in ["Part1", "Part2"] {
        let (code, _) = s
            .call(
                Method::PUT,
                &format!("/api/forces/{part}"),
                Some(json!({"value": true})),
            )
            .await;
        assert_eq!(code, StatusCode::OK);
    }
    // Both parts arrive; machine 1 takes the robot, machine 2 waits for it.
    for _ in 0..2 {
        assert_eq!(s.call(Method::POST, "/api/step", None).await.0, StatusCode::OK);
    }
    let (code, _) = s
        .call(Method::PUT, "/api/tags/cell.done", Some(json!({"value": 4})))
        .await;
    assert_eq!(code, StatusCode::OK);
    let before = [
        ("cell.robot", 0),
        ("cell.idle1", 0),
        ("cell.load1", 1),
        ("cell.idle2", 0),
        ("cell.wait2", 1),
        ("cell.done", 4),
    ];
    for (tag, v) in before {
        assert_eq!(s.value(tag).await, json!(v), "{tag} before the edit");
    }

    // The edit: `done` starts at 7 now, `wait2` is renamed `queue2`, a new
    // place `spare` holds 3 tokens, and a guard changes.
    let text = s.get("/api/programs/cell.pnml").await["text"]
        .as_str()
        .expect("text")
        .replace(
            r#"<place id="done"><name><text>parts finished</text></name></place>"#,
            r#"<place id="done"><name><text>parts finished</text></name><initialMarking><text>7</text></initialMarking></place>
      <place id="spare"><initialMarking><text>3</text></initialMarking></place>"#,
        )
        .replace(r#""wait2""#, r#""queue2""#)
        .replace("<guard>Part2</guard>", "<guard>Part2 AND NOT Part1</guard>");
    assert!(text.contains("queue2") && text.contains("spare") && text.contains("AND NOT Part1"));
    let scans = s.scans().await;
    let (code, j) = s
        .call(
            Method::PUT,
            "/api/programs/cell.pnml",
            Some(json!({"text": text, "online": true})),
        )
        .await;
    assert_eq!(code, StatusCode::OK, "{j}");
    assert_eq!(s.scans().await, scans, "applied between scans, no scan run by it");

    let after = [
        ("cell.robot", 0),
        ("cell.idle1", 0),
        ("cell.load1", 1),
        ("cell.idle2", 0),
        ("cell.done", 4),
        ("cell.queue2", 0),
        ("cell.spare", 3),
    ];
    for (tag, v) in after {
        assert_eq!(s.value(tag).await, json!(v), "{tag} after the edit");
    }
    let (code, _) = s.call(Method::GET, "/api/tags/cell.wait2", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND, "the old place's tag is gone");
    // The net runs on from the kept marking: machine 1 still loads (its
    // timer not done), the robot still taken.
    assert_eq!(s.call(Method::POST, "/api/step", None).await.0, StatusCode::OK);
    for (tag, v) in [
        ("cell.robot", 0),
        ("cell.load1", 1),
        ("cell.done", 4),
        ("cell.spare", 3),
    ] {
        assert_eq!(s.value(tag).await, json!(v), "{tag} after a scan");
    }
    // A reset now loads the new initial marking.
    let (code, _) = s.call(Method::POST, "/api/nets/cell/reset", None).await;
    assert_eq!(code, StatusCode::OK);
    for (tag, v) in [
        ("cell.robot", 1),
        ("cell.load1", 0),
        ("cell.done", 7),
        ("cell.spare", 3),
    ] {
        assert_eq!(s.value(tag).await, json!(v), "{tag} after a reset");
    }
    s.stop().await;
}

/// `POST /api/nets/{name}/analysis` with `body`: the status and the JSON
/// lines of the answer (or the error object).
pub async fn analysis(s: &Server, net: &str, body: Json) -> (StatusCode, Vec<Json>) {
    let res = s
        .http
        .post(s.url(&format!("/api/nets/{net}/analysis")))
        .json(&body)
        .send()
        .await
        .expect("request");
    let code = res.status();
    let text = res.text().await.expect("body");
    let lines = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|_| json!({"text": l})))
        .collect();
    (code, lines)
}

/// A Petri-mode net of `k` independent 3-place cycles (3^k states).
fn cycles_pnml(k: usize) -> String {
    let mut s = String::from(
        "<pnml xmlns=\"http://www.pnml.org/version-2009/grammar/pnml\"><net id=\"big\" \
         type=\"http://www.pnml.org/version-2009/grammar/ptnet\"><page id=\"g\">",
    );
    for c in 0..k {
        for i in 0..3 {
            let m = if i == 0 {
                "<initialMarking><text>1</text></initialMarking>"
            } else {
                ""
            };
            s.push_str(&format!(
                "<place id=\"c{c}p{i}\">{m}</place><transition id=\"c{c}t{i}\"/>"
            ));
            s.push_str(&format!(
                "<arc id=\"c{c}a{i}\" source=\"c{c}p{i}\" target=\"c{c}t{i}\"/>\
                 <arc id=\"c{c}b{i}\" source=\"c{c}t{i}\" target=\"c{c}p{}\"/>",
                (i + 1) % 3
            ));
        }
    }
    s.push_str("</page></net></pnml>");
    s
}

/// The scheduling policy and nice value of this process's thread named
/// `name` (SCHED_BATCH is 3), if one runs.
fn thread_policy(name: &str) -> Option<(u32, i32)> {
    for e in std::fs::read_dir("/proc/self/task").ok()?.flatten() {
        let comm = std::fs::read_to_string(e.path().join("comm")).unwrap_or_default();
        if comm.trim() == name {
            let stat = std::fs::read_to_string(e.path().join("stat")).ok()?;
            // Fields after the parenthesised name (field 3 on): nice is 19, policy 41.
            let f: Vec<&str> = stat[stat.rfind(')')? + 2..].split_whitespace().collect();
            return Some((f.get(41 - 3)?.parse().ok()?, f.get(19 - 3)?.parse().ok()?));
        }
    }
    None
}

/// The petri-resource example with `big.pnml`, `n` independent cycles of
/// three places (3^n states), added to its programs; the server on it.
async fn with_big_net(test: &str, n: usize) -> Server {
    let dir = crate::copy_example("petri-resource", test);
    std::fs::write(dir.join("big.pnml"), cycles_pnml(n)).expect("big net");
    let toml = std::fs::read_to_string(dir.join("alba.toml")).expect("toml");
    std::fs::write(
        dir.join("alba.toml"),
        toml.replace("\"cell.pnml\"]", "\"cell.pnml\", \"big.pnml\"]"),
    )
    .expect("toml");
    Server::start_in(dir).await
}

/// Issue 31, point 2: one analysis at a time (429 for the next), on a
/// least-priority thread, stopped when the client goes away — the engine scans on.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn one_analysis_at_a_time_stopped_when_the_client_leaves() {
    let s = with_big_net("net-analysis-busy", 15).await;
    // 3^15 = 14 million states: far more than a test lets it run.
    let res = s
        .http
        .post(s.url("/api/nets/big/analysis"))
        .json(&json!({"max_states": 10_000_000}))
        .send()
        .await
        .expect("request");
    assert_eq!(res.status(), StatusCode::OK);
    assert_eq!(
        res.headers().get("content-type").and_then(|v| v.to_str().ok()),
        Some("application/x-ndjson")
    );
    let mut body = res.bytes_stream();
    use futures_util::StreamExt;
    let mut text = String::new();
    while !text.contains('\n') {
        let chunk = body.next().await.expect("a progress line").expect("bytes");
        text.push_str(&String::from_utf8_lossy(&chunk));
    }
    let first: Json = serde_json::from_str(text.lines().next().expect("line")).expect("JSON");
    assert_eq!(first["progress"]["part"], "state_space", "{first}");
    assert!(first["progress"]["states"].as_u64().expect("states") > 0);
    assert_eq!(thread_policy("net-analysis"), Some((3, 19)), "SCHED_BATCH, nice 19");
    // A second one, on any net of the project, waits its turn.
    let (code, j) = s.call(Method::POST, "/api/nets/cell/analysis", Some(json!({}))).await;
    assert_eq!(code, StatusCode::TOO_MANY_REQUESTS, "{j}");
    assert!(j["error"].as_str().expect("error").contains("running"), "{j}");
    let scans = s.scans().await;
    // The client leaves: the analysis stops and the next one runs.
    drop(body);
    let mut tries = 0;
    let code = loop {
        let (code, _) = analysis(&s, "cell", json!({})).await;
        if code != StatusCode::TOO_MANY_REQUESTS || tries == 300 {
            break code;
        }
        tries += 1;
        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
    };
    assert_eq!(code, StatusCode::OK);
    for _ in 0..100 {
        if thread_policy("net-analysis").is_none() {
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(10)).await;
    }
    assert_eq!(thread_policy("net-analysis"), None, "the thread has ended");
    assert!(s.scans().await > scans, "the engine scanned on");
    s.stop().await;
}

/// The time limit stops the analysis: its last line says so, and the state
/// space is reported partial.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_analysis_stops_at_its_time_limit() {
    let s = with_big_net("net-analysis-time", 15).await;
    let (code, lines) = analysis(&s, "big", json!({"max_states": 10_000_000, "time_limit_s": 1})).await;
    assert_eq!(code, StatusCode::OK);
    let last = lines.last().expect("a line");
    assert_eq!(last["timed_out"], true, "{last}");
    let r = &last["result"];
    assert_eq!(r["status"]["state_space"], "partial", "{r}");
    assert_eq!(r["state_space"], "incomplete");
    assert!(
        r["stopped"].as_str().expect("stopped").starts_with("cancelled after"),
        "{r}"
    );
    s.stop().await;
}

/// `"symbolic": true` counts with decision diagrams first: 3^25 states, far more than
/// the explicit exploration may hold, counted exactly, and decides their deadlocks,
/// liveness and reversibility; `"symbolic"` must be a boolean.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_analysis_counts_with_decision_diagrams_on_request() {
    let s = with_big_net("net-analysis-symbolic", 25).await;
    let (code, lines) = analysis(&s, "big", json!({"symbolic": true})).await;
    assert_eq!(code, StatusCode::OK);
    let r = &lines.last().expect("a line")["result"];
    assert_eq!(r["symbolic"]["status"], "complete", "{r}");
    assert_eq!(r["symbolic"]["states"], "847288609443", "{r}");
    assert_eq!(r["states"], 847_288_609_443u64, "{r}");
    assert_eq!(r["status"]["state_space"], "skipped: budget", "{r}");
    // Its deadlocks, liveness and reversibility are decided on the diagrams too.
    assert_eq!(r["status"]["symbolic_facts"], "complete", "{r}");
    assert_eq!(
        (&r["deadlocks"], &r["live"], &r["reversible"], &r["dead_transitions"]),
        (&json!(0), &json!(true), &json!(true), &json!([])),
        "{r}"
    );
    // Without it, the explicit exploration stops at its cap and nothing is counted.
    let (_, lines) = analysis(&s, "big", json!({"max_states": 1000})).await;
    let r = &lines.last().expect("a line")["result"];
    assert_eq!(r["status"]["symbolic"], "skipped: not requested", "{r}");
    let (code, j) = s
        .call(Method::POST, "/api/nets/big/analysis", Some(json!({"symbolic": "yes"})))
        .await;
    assert_eq!(code, StatusCode::BAD_REQUEST, "{j}");
    s.stop().await;
}

/// The analysis's notes and `stopped` come in the studio's language: every one of
/// them in Spanish for `Accept-Language: es` (a note missing from the phrase book
/// would come back in English and fail this), in English otherwise.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_analysis_speaks_the_language_of_the_request() {
    // (3^25 states: the explicit exploration is skipped, the symbolic engine's notes come)
    let s = with_big_net("net-analysis-spanish", 25).await;
    for body in [json!({"max_states": 1000}), json!({"symbolic": true})] {
        let mut texts = Vec::new();
        for lang in ["en", "es"] {
            let res = s
                .http
                .post(s.url("/api/nets/big/analysis"))
                .header("accept-language", lang)
                .json(&body)
                .send()
                .await
                .expect("request");
            let text = res.text().await.expect("body");
            let last: Json = serde_json::from_str(text.lines().last().expect("a line")).expect("JSON");
            let r = &last["result"];
            let mut t: Vec<String> = r["notes"]
                .as_array()
                .expect("notes")
                .iter()
                .map(|n| n.to_string())
                .collect();
            t.push(r["stopped"].to_string());
            texts.push(t);
        }
        let (en, es) = (&texts[0], &texts[1]);
        assert_eq!(en.len(), es.len());
        for (en, es) in en.iter().zip(es) {
            if en != "null" {
                assert_ne!(en, es, "not in Spanish: {es}");
            }
        }
        if body["max_states"] == 1000 {
            assert!(
                es.iter()
                    .any(|t| t.contains("detenido tras 1000 estados (--max-states)")),
                "{es:?}"
            );
            assert!(
                es.iter().any(|t| t.contains("no se tienen en cuenta las guardas")),
                "{es:?}"
            );
        } else {
            assert!(es.iter().any(|t| t.contains("vienen del motor simbólico")), "{es:?}");
            assert!(
                es.iter().any(|t| t.contains("se omitió la exploración explícita")),
                "{es:?}"
            );
        }
    }
    s.stop().await;
}

/// A contest examination through the same streaming analysis: the last line's
/// `result` is `alba analyze --examination --json`'s object; a formula naming no
/// place of the net, an unknown examination or missing formulas are `422`.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_analysis_answers_a_contest_examination() {
    let s = with_big_net("net-analysis-examination", 2).await;
    let le = |k: u32, places: &[&str]| {
        let ps: String = places.iter().map(|p| format!("<place>{p}</place>")).collect();
        format!("<integer-le><integer-constant>{k}</integer-constant><tokens-count>{ps}</tokens-count></integer-le>")
    };
    let formulas = format!(
        "<property-set>\
         <property><id>reach</id><formula><exists-path><finally>{}</finally></exists-path></formula></property>\
         <property><id>never</id><formula><exists-path><finally>{}</finally></exists-path></formula></property>\
         <property><id>one</id><formula><all-paths><globally>{}</globally></all-paths></formula></property>\
         </property-set>",
        le(1, &["c0p2"]),
        le(2, &["c0p0", "c0p1", "c0p2"]),
        le(1, &["c1p0", "c1p1", "c1p2"]),
    );
    let (code, lines) = analysis(
        &s,
        "big",
        json!({"examination": "ReachabilityCardinality", "formulas": formulas}),
    )
    .await;
    assert_eq!(code, StatusCode::OK, "{lines:?}");
    let last = lines.last().expect("a line");
    assert_eq!(last["timed_out"], false);
    let r = &last["result"];
    assert_eq!(r["examination"], "ReachabilityCardinality");
    let f = r["formulas"].as_array().expect("formulas");
    assert_eq!(f.len(), 3);
    // Each cycle holds one token: c0p2 is reached by c0t0 c0t1; two tokens in a
    // cycle never; one token in cycle 1 always.
    assert_eq!(f[0]["verdict"], true);
    assert_eq!(f[0]["trace"], json!(["c0t0", "c0t1"]));
    assert_eq!(f[1]["verdict"], false);
    assert_eq!(f[1]["trace"], Json::Null);
    assert_eq!(f[2]["verdict"], true);
    assert!(
        f[0]["line"]
            .as_str()
            .expect("line")
            .starts_with("FORMULA reach TRUE TECHNIQUES EXPLICIT")
    );
    let (code, lines) = analysis(&s, "big", json!({"examination": "ReachabilityDeadlock"})).await;
    assert_eq!(code, StatusCode::OK);
    assert_eq!(
        lines.last().expect("a line")["result"]["formulas"][0]["line"],
        "FORMULA ReachabilityDeadlock FALSE TECHNIQUES EXPLICIT PARTIAL_ORDER STRUCTURAL_REDUCTION"
    );
    let unknown = format!(
        "<property-set>\n<property><id>x</id><formula><exists-path><finally>\n{}\n</finally></exists-path></formula></property></property-set>",
        le(1, &["nowhere"])
    );
    for (body, says) in [
        (
            json!({"examination": "ReachabilityCardinality", "formulas": unknown}),
            "line 3",
        ),
        (json!({"examination": "CTLFireability"}), "examination"),
        (json!({"examination": "UpperBounds"}), "formulas"),
        (
            json!({"examination": "ReachabilityDeadlock", "formulas": "<property-set/>"}),
            "no formula file",
        ),
    ] {
        let (code, j) = s.call(Method::POST, "/api/nets/big/analysis", Some(body)).await;
        assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
        assert!(j["error"].as_str().expect("error").contains(says), "{j}");
    }
    s.stop().await;
}
