use crate::Server;
use reqwest::{Method, StatusCode};
use serde_json::{Value as Json, json};

fn files(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn status_tags_members_and_addresses() {
    let s = Server::start("tank", "status").await;
    s.wait_scans(3).await;
    let st = s.get("/api/status").await;
    assert_eq!(st["project"], "tank");
    assert_eq!(st["state"], "running");
    assert_eq!(st["scan_ms"], 10);
    assert_eq!(st["programs"], json!(["main.lad"]));
    assert!(st["stats"]["max_us"].as_u64().expect("max") >= st["stats"]["min_us"].as_u64().expect("min"));

    let tags = s.get("/api/tags").await;
    let tags = tags.as_array().expect("array");
    assert_eq!(tags[0]["name"], "Bomba1");
    let ct = tags.iter().find(|t| t["name"] == "CT_STP").expect("CT_STP");
    assert_eq!(ct["type"], "COUNTER");
    assert_eq!(ct["value"]["PRE"], 2);
    let stop = tags.iter().find(|t| t["name"] == "STOP").expect("STOP");
    assert_eq!(stop["access"], "input");
    assert_eq!(stop["address"], "DI:1/0");
    assert!(
        tags.iter()
            .any(|t| t["name"] == "S:SCANTIME" && t["access"] == "readonly")
    );

    assert_eq!(s.value("CT_STP.PRE").await, 2);
    assert_eq!(s.value("S_ULT").await, 575);
    // Every address notation names the same place.
    for a in ["DI:1/0", "%IX0.0", "I0.0"] {
        assert_eq!(s.value(&a.replace('%', "%25").replace('/', "%2F")).await, false, "{a}");
    }
    let level = s.value("Nivel_L").await.as_f64().expect("real");
    assert!((level - 33.724_34).abs() < 1e-4, "{level}");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn writes_are_checked_and_bad_requests_change_nothing() {
    let s = Server::start("tank", "writes").await;
    let (code, j) = s
        .call(Method::PUT, "/api/tags/Llenar", Some(json!({"value": true})))
        .await;
    assert_eq!((code, &j), (StatusCode::OK, &json!({"name": "Llenar", "value": true})));
    let (code, _) = s
        .call(Method::PUT, "/api/tags/CT_STP.PRE", Some(json!({"value": 7})))
        .await;
    assert_eq!(code, StatusCode::OK);
    let before = s.scans().await;

    let cases: Vec<(&str, Json, StatusCode, &str)> = vec![
        ("Nope", json!({"value": 1}), StatusCode::NOT_FOUND, "unknown tag `Nope`"),
        (
            "STOP",
            json!({"value": true}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "is an input",
        ),
        (
            "DI:1%2F0",
            json!({"value": true}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "is an input",
        ),
        (
            "Llenar",
            json!({"value": "yes"}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "BOOL",
        ),
        ("Llenar", json!({"value": 2}), StatusCode::UNPROCESSABLE_ENTITY, "BOOL"),
        (
            "CT_STP.PRE",
            json!({"value": 1.5}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "`CT_STP.PRE`",
        ),
        (
            "CT_STP.PRE",
            json!({"value": 1e12}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "`CT_STP.PRE`",
        ),
        (
            "CT_STP.DN",
            json!({"value": true}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "read-only",
        ),
        (
            "CT_STP",
            json!({"value": 1}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "is a structure",
        ),
        (
            "S:SCANTIME",
            json!({"value": 1}),
            StatusCode::UNPROCESSABLE_ENTITY,
            "read-only",
        ),
        ("Llenar", json!({"val": false}), StatusCode::BAD_REQUEST, "`value`"),
    ];
    for (name, body, want, msg) in cases {
        let (code, j) = s
            .call(Method::PUT, &format!("/api/tags/{name}"), Some(body.clone()))
            .await;
        assert_eq!(code, want, "{name} {body}: {j}");
        let e = j["error"].as_str().expect("error message");
        assert!(e.contains(msg), "{name} {body}: {e}");
    }
    let (code, j) = s
        .raw(
            Method::PUT,
            "/api/tags/Llenar",
            "application/json",
            b"{\"value\": tru".to_vec(),
        )
        .await;
    assert_eq!(code, StatusCode::BAD_REQUEST, "{j}");
    assert!(
        j["error"].as_str().expect("msg").starts_with("malformed JSON body"),
        "{j}"
    );
    let (code, _) = s
        .raw(
            Method::PUT,
            "/api/tags/Llenar",
            "text/plain",
            b"{\"value\": false}".to_vec(),
        )
        .await;
    // Refused by the guard (JSON only: docs/security.md).
    assert_eq!(code, StatusCode::UNSUPPORTED_MEDIA_TYPE);
    let big = format!("{{\"value\": false, \"pad\": \"{}\"}}", "x".repeat(100_000));
    let (code, j) = s
        .raw(Method::PUT, "/api/tags/Llenar", "application/json", big.into_bytes())
        .await;
    assert_eq!(code, StatusCode::PAYLOAD_TOO_LARGE, "{j}");
    assert!(j["error"].is_string());
    let (code, j) = s.call(Method::GET, "/api/nothing/here", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND);
    assert_eq!(j["error"], "no such endpoint");

    // The engine went on and nothing was written.
    s.wait_scans(2).await;
    assert!(s.scans().await > before);
    assert_eq!(s.get("/api/status").await["state"], "running");
    assert_eq!(s.value("Llenar").await, true);
    assert_eq!(s.value("CT_STP.PRE").await, 7);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn forces_hold_inputs_and_only_io_can_be_forced() {
    let s = Server::start("tank", "forces").await;
    assert_eq!(s.value("L_RUN").await, true);
    // One press of STOP (held by a force) stops the system.
    let (code, j) = s
        .call(Method::PUT, "/api/forces/STOP", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::OK, "{j}");
    s.wait_scans(3).await;
    assert_eq!(s.value("STOP").await, true);
    assert_eq!(s.value("CT_STP.ACC").await, 1);
    assert_eq!(s.value("L_STP").await, true);
    assert_eq!(s.value("L_RUN").await, false);
    let tags = s.get("/api/tags").await;
    let stop = tags
        .as_array()
        .expect("array")
        .iter()
        .find(|t| t["name"] == "STOP")
        .cloned();
    assert_eq!(stop.expect("STOP")["forced"], true);
    // An output forced on whatever the program says.
    let (code, _) = s
        .call(Method::PUT, "/api/forces/Bomba1", Some(json!({"value": 1})))
        .await;
    assert_eq!(code, StatusCode::OK);
    s.wait_scans(2).await;
    assert_eq!(s.value("Bomba1").await, true);
    assert_eq!(
        s.get("/api/forces").await,
        json!([{"name": "STOP", "value": true}, {"name": "Bomba1", "value": true}])
    );

    let (code, j) = s
        .call(Method::PUT, "/api/forces/Llenar", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        j["error"].as_str().expect("msg").contains("only I/O can be forced"),
        "{j}"
    );
    let (code, _) = s
        .call(Method::PUT, "/api/forces/Nope", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::NOT_FOUND);
    let (code, _) = s
        .call(Method::PUT, "/api/forces/S_ULT", Some(json!({"value": 99999})))
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);

    let (code, _) = s.call(Method::DELETE, "/api/forces/STOP", None).await;
    assert_eq!(code, StatusCode::NO_CONTENT);
    let (code, _) = s.call(Method::DELETE, "/api/forces/STOP", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND);
    let (code, _) = s.call(Method::DELETE, "/api/forces", None).await;
    assert_eq!(code, StatusCode::NO_CONTENT);
    s.wait_scans(2).await;
    assert_eq!(s.get("/api/forces").await, json!([]));
    assert_eq!(s.value("STOP").await, false, "the input is the I/O's again");
    assert_eq!(s.value("Bomba1").await, false, "the output is the program's again");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn run_and_stop() {
    let s = Server::start("tank", "runstop").await;
    let (code, j) = s.call(Method::POST, "/api/stop", None).await;
    assert_eq!(code, StatusCode::OK);
    assert_eq!(j["state"], "stopped");
    assert_eq!(s.value("L_RUN").await, false, "outputs off when stopped");
    let n = s.scans().await;
    tokio::time::sleep(std::time::Duration::from_millis(100)).await;
    assert_eq!(s.scans().await, n, "no scan while stopped");
    let (code, j) = s.call(Method::POST, "/api/run", None).await;
    assert_eq!(code, StatusCode::OK);
    assert_eq!(j["state"], "running");
    s.wait_scans(2).await;
    assert_eq!(s.value("L_RUN").await, true);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn programs_are_checked_saved_atomically_and_applied_online() {
    let s = Server::start("tank", "programs").await;
    assert_eq!(
        s.get("/api/programs").await,
        json!([{"name": "main.lad", "language": "ladder", "plant": false}])
    );
    let p = s.get("/api/programs/main.lad").await;
    let text = p["text"].as_str().expect("text").to_string();
    let rungs = p["rungs"].as_array().expect("rungs");
    assert_eq!(rungs.len(), 11);
    let r8 = &rungs[7];
    assert_eq!(
        r8["comment"][0],
        "Rung 8: pump B1 and its LED while filling is requested and the system is not stopped"
    );
    let kinds: Vec<&str> = r8["elements"]
        .as_array()
        .expect("elements")
        .iter()
        .map(|e| e["kind"].as_str().expect("kind"))
        .collect();
    assert_eq!(kinds, ["instr", "instr", "branch"]);
    assert_eq!(r8["elements"][2]["legs"][1][0]["operands"], json!(["L_FILL"]));
    assert!(r8["elements"][0]["id"].is_u64());
    let (code, _) = s.call(Method::GET, "/api/programs/nope.lad", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND);

    let file = s.dir.join("main.lad");
    let on_disk = std::fs::read_to_string(&file).expect("read");
    let listing = files(&s.dir);

    // Invalid text: located diagnostics; nothing saved, nothing applied.
    let bad = text.replace("OTE(L_RUN)", "OTE(L_RUM)");
    for (m, path) in [
        (Method::POST, "/api/check/main.lad"),
        (Method::PUT, "/api/programs/main.lad"),
    ] {
        let (code, j) = s.call(m, path, Some(json!({"text": bad, "online": true}))).await;
        assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
        assert_eq!(j["error"], "1 error");
        let d = &j["diagnostics"][0];
        assert_eq!(
            (d["code"].as_str(), d["line"].as_u64(), d["col"].as_u64()),
            (Some("E301"), Some(10), Some(15)),
            "{d}"
        );
        assert_eq!(d["file"], "main.lad");
    }
    let (code, j) = s
        .call(
            Method::PUT,
            "/api/programs/main.lad",
            Some(json!({"text": "XIC(", "online": true})),
        )
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let (code, _) = s
        .call(Method::PUT, "/api/programs/main.lad", Some(json!({"txt": text})))
        .await;
    assert_eq!(code, StatusCode::BAD_REQUEST);
    let (code, _) = s
        .call(Method::PUT, "/api/programs/main.lad", Some(json!({"text": 5})))
        .await;
    assert_eq!(code, StatusCode::BAD_REQUEST);
    let (code, _) = s
        .call(Method::PUT, "/api/programs/other.lad", Some(json!({"text": text})))
        .await;
    assert_eq!(code, StatusCode::NOT_FOUND);
    assert_eq!(std::fs::read_to_string(&file).expect("read"), on_disk);
    assert_eq!(files(&s.dir), listing, "no temporary file left behind");
    assert_eq!(s.get("/api/programs/main.lad").await["text"], text.as_str());

    // A valid check saves nothing.
    let extra = format!("{text}// Rung 12: added online\nXIC(Llenar)OTE(L_FILL);\n");
    let (code, j) = s
        .call(Method::POST, "/api/check/main.lad", Some(json!({"text": extra})))
        .await;
    assert_eq!(code, StatusCode::OK, "{j}");
    assert_eq!(j["rungs"].as_array().expect("rungs").len(), 12);
    assert_eq!(std::fs::read_to_string(&file).expect("read"), on_disk);

    // State to keep across the online edit: a written bit, a written preset, a counted press.
    for (tag, v) in [("Llenar", json!(true)), ("CT_STP.PRE", json!(5))] {
        let (code, _) = s
            .call(Method::PUT, &format!("/api/tags/{tag}"), Some(json!({"value": v})))
            .await;
        assert_eq!(code, StatusCode::OK);
    }
    s.call(Method::PUT, "/api/forces/STOP", Some(json!({"value": true})))
        .await;
    s.wait_scans(2).await;
    s.call(Method::DELETE, "/api/forces/STOP", None).await;
    s.wait_scans(2).await;
    assert_eq!(s.value("CT_STP.ACC").await, 1);
    let scans = s.scans().await;

    let (code, j) = s
        .call(
            Method::PUT,
            "/api/programs/main.lad",
            Some(json!({"text": extra, "online": true})),
        )
        .await;
    assert_eq!(
        (code, &j),
        (StatusCode::OK, &json!({"diagnostics": [], "applied": true}))
    );
    assert_eq!(std::fs::read_to_string(&file).expect("read"), extra);
    assert_eq!(files(&s.dir), listing, "no temporary file left behind");
    assert!(s.scans().await >= scans, "the scan count goes on");
    assert_eq!(s.get("/api/status").await["state"], "running");
    assert_eq!(s.value("Llenar").await, true);
    assert_eq!(s.value("CT_STP.PRE").await, 5);
    assert_eq!(s.value("CT_STP.ACC").await, 1);
    let p = s.get("/api/programs/main.lad").await;
    assert_eq!(p["rungs"].as_array().expect("rungs").len(), 12);
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn tags_csv_round_trip_and_validation() {
    let s = Server::start("tank", "tagscsv").await;
    let res = s.http.get(s.url("/api/tags.csv")).send().await.expect("get");
    assert!(
        res.headers()["content-type"]
            .to_str()
            .expect("ct")
            .starts_with("text/csv")
    );
    let text = res.text().await.expect("text");
    let file = s.dir.join("tags.csv");
    assert_eq!(text, std::fs::read_to_string(&file).expect("read"));

    let bad = format!("{text}Extra,FLOAT,,,,a tag of no known type\n");
    let (code, j) = s.raw(Method::PUT, "/api/tags.csv", "text/csv", bad.into_bytes()).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    let d = &j["diagnostics"][0];
    assert_eq!(
        (d["file"].as_str(), d["line"].as_u64()),
        (Some("tags.csv"), Some(19)),
        "{d}"
    );
    assert_eq!(std::fs::read_to_string(&file).expect("read"), text);

    s.call(Method::PUT, "/api/tags/Llenar", Some(json!({"value": true})))
        .await;
    let good = format!("{text}Extra,DINT,,42,,added from the tag table\n");
    let (code, j) = s
        .raw(Method::PUT, "/api/tags.csv", "text/csv", good.clone().into_bytes())
        .await;
    assert_eq!(code, StatusCode::OK, "{j}");
    assert_eq!(std::fs::read_to_string(&file).expect("read"), good);
    assert_eq!(s.value("Extra").await, 42);
    assert_eq!(s.value("Llenar").await, true, "values of unchanged tags are kept");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn instruction_palette_has_the_eight_groups_in_order_then_pid() {
    let s = Server::start("tank", "palette").await;
    let list = s.get("/api/instructions").await;
    let mut groups: Vec<String> = Vec::new();
    for i in list.as_array().expect("array") {
        let g = i["group"].as_str().expect("group").to_string();
        if groups.last() != Some(&g) {
            groups.push(g);
        }
    }
    assert_eq!(
        groups,
        [
            "bit", "timer", "counter", "compare", "math", "move", "trig", "flow", "special"
        ]
    );
    let pid = list
        .as_array()
        .expect("array")
        .iter()
        .find(|i| i["mnemonic"] == "PID")
        .cloned();
    assert_eq!(pid.expect("PID")["args"], json!(["pid", "num_in", "num_out"]));
    let ton = list
        .as_array()
        .expect("array")
        .iter()
        .find(|i| i["mnemonic"] == "TON")
        .cloned();
    assert_eq!(ton.expect("TON")["args"], json!(["timer", "preset", "accum"]));
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pid_members_over_the_api_and_a_plant_in_real_time() {
    let s = Server::start("pid-level", "pid").await;
    let tags = s.get("/api/tags").await;
    let lp = tags
        .as_array()
        .expect("array")
        .iter()
        .find(|t| t["name"] == "Loop")
        .expect("Loop")
        .clone();
    assert_eq!(lp["type"], "PID");
    assert_eq!(lp["value"]["UPD"], 250);
    assert!((lp["value"]["KP"].as_f64().expect("KP") - 7.14).abs() < 1e-5);
    // Set a higher level; the simulated tank (a [[plant_model]]) follows in real time.
    let (code, _) = s
        .call(Method::PUT, "/api/tags/Loop.SP", Some(json!({"value": 3.0})))
        .await;
    assert_eq!(code, StatusCode::OK);
    for (name, body) in [("Loop.PV", json!({"value": 1.0})), ("Loop", json!({"value": 1}))] {
        let (code, j) = s.call(Method::PUT, &format!("/api/tags/{name}"), Some(body)).await;
        assert!(code.is_client_error(), "{name}: {code} {j}");
    }
    let start = s.value("Level").await.as_f64().expect("level");
    let mut level = start;
    for _ in 0..100 {
        tokio::time::sleep(std::time::Duration::from_millis(50)).await;
        level = s.value("Level").await.as_f64().expect("level");
        if level > 2000.0 {
            break;
        }
    }
    assert!(level > 2000.0, "the level rose from {start} to only {level}");
    assert_eq!(s.value("Loop.SP").await, 3.0);
    s.stop().await;
}

/// A Petri-mode net's places are DINT tags `<net>.<place>`: listed, read and
/// written (an operator putting a token back) like any tag.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn net_markings_are_tags_an_operator_can_write() {
    let s = Server::start("petri-resource", "net-markings").await;
    s.wait_scans(3).await;
    assert_eq!(
        s.get("/api/programs").await,
        json!([
            {"name": "main.lad", "language": "ladder", "plant": false},
            {"name": "cell.pnml", "language": "net", "plant": false}
        ])
    );
    let p = s.get("/api/programs/cell.pnml").await;
    assert!(p["text"].as_str().expect("text").contains("<pnml"));
    let tags = s.get("/api/tags").await;
    let robot = tags
        .as_array()
        .expect("array")
        .iter()
        .find(|t| t["name"] == "cell.robot")
        .expect("the marking of place robot is listed");
    assert_eq!(
        (&robot["type"], &robot["access"], &robot["value"]),
        (&json!("DINT"), &json!("readwrite"), &json!(1))
    );
    let (code, j) = s
        .call(Method::PUT, "/api/tags/cell.done", Some(json!({"value": 5})))
        .await;
    assert_eq!((code, &j), (StatusCode::OK, &json!({"name": "cell.done", "value": 5})));
    s.wait_scans(2).await;
    assert_eq!(s.value("cell.done").await, 5, "no transition consumes from done");
    assert_eq!(s.value("cell.robot").await, 1);
    s.stop().await;
}

/// `POST /api/nets/{name}/analysis`: JSON lines ending with the same object
/// as `alba analyze --json` for a net of the project, by file name or net
/// name, bounded; a GET costs nothing (405).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_nets_analysis_is_served() {
    let s = crate::Server::start("petri-resource", "nets-analysis").await;
    let (code, lines) = crate::nets::analysis(&s, "cell", json!({})).await;
    assert_eq!(code, 200, "{lines:?}");
    let last = lines.last().expect("a result line");
    assert_eq!(last["timed_out"], false);
    let by_name = &last["result"];
    let (_, lines) = crate::nets::analysis(&s, "cell.pnml", json!({})).await;
    let by_file = &lines.last().expect("a result line")["result"];
    for key in [
        "places",
        "transitions",
        "bounded",
        "safe",
        "place_bounds",
        "states",
        "edges",
        "deadlocks",
        "dead_transitions",
        "live",
        "reversible",
        "p_invariants",
        "t_invariants",
    ] {
        assert!(by_name.get(key).is_some(), "{key} in {by_name}");
        assert_eq!(by_name[key], by_file[key], "{key}");
    }
    // `done` counts finished parts without bound: Karp–Miller's ω.
    assert_eq!(by_name["bounded"], false);
    assert_eq!(by_name["place_bounds"]["done"], "omega");
    assert_eq!(by_name["state_space"], "coverability");
    assert_eq!(by_name["status"]["state_space"], "complete");
    assert_eq!(by_name["status"]["p_invariants"], "complete");
    let (code, lines) = crate::nets::analysis(&s, "cell", json!({"max_states": 2, "invariants": "flows"})).await;
    let j = &lines.last().expect("a result line")["result"];
    assert_eq!(
        (code.as_u16(), j["state_space"].as_str()),
        (200, Some("incomplete")),
        "{j}"
    );
    assert_eq!(j["status"]["p_invariants"], "skipped: not requested");
    for bad in [
        json!({"max_states": 0}),
        json!({"time_limit_s": 121}),
        json!({"invariants": "all"}),
    ] {
        let (code, _) = s.call(Method::POST, "/api/nets/cell/analysis", Some(bad.clone())).await;
        assert_eq!(code, 422, "{bad}");
    }
    let (code, _) = s
        .call(Method::POST, "/api/nets/cell/analysis", Some(json!({"depth": 3})))
        .await;
    assert_eq!(code, 400);
    let (code, _) = s
        .call(Method::POST, "/api/nets/main.lad/analysis", Some(json!({})))
        .await;
    assert_eq!(code, 404, "a ladder program is not a net");
    // What an <img> or a link could trigger costs nothing.
    let (code, _) = s.call(Method::GET, "/api/nets/cell/analysis", None).await;
    assert_eq!(code, 405);
    s.stop().await;
}

/// Issue 15's validation gaps: a negative timer preset is refused (it would
/// fault every scan), and a tags.csv over the limit gets the JSON error shape.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_negative_timer_preset_and_an_oversized_tags_csv_are_refused_as_json() {
    let s = Server::start("tank-plant", "validation-gaps").await;
    let (code, j) = s
        .call(Method::PUT, "/api/tags/Away.PRE", Some(json!({"value": -5})))
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert!(
        j["error"].as_str().is_some_and(|e| e.contains("cannot be negative")),
        "{j}"
    );
    let (code, j) = s
        .call(Method::PUT, "/api/tags/Away.PRE", Some(json!({"value": 2500})))
        .await;
    assert_eq!(code, StatusCode::OK, "a positive preset is fine: {j}");
    // A counter's preset may be negative (CTD counts below zero).
    let (code, j) = s
        .call(Method::PUT, "/api/tags/CT_STP.PRE", Some(json!({"value": -2})))
        .await;
    assert_eq!(code, StatusCode::OK, "{j}");
    let big = vec![b'a'; 2 * 1024 * 1024];
    let (code, j) = s.raw(Method::PUT, "/api/tags.csv", "text/csv", big).await;
    assert_eq!(code, StatusCode::PAYLOAD_TOO_LARGE);
    assert!(j["error"].is_string(), "the JSON error shape: {j}");
    s.stop().await;
}

/// The binary carries the studio: a plain `cargo build` builds web/ first
/// when it is stale (crates/server/build.rs, ADR 0013), and `/` serves it
/// with its scripts.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_studio_is_embedded_and_served() {
    let s = Server::start("tank", "studio-embedded").await;
    let res = s.http.get(s.url("/")).send().await.expect("GET /");
    assert_eq!(res.status(), StatusCode::OK);
    let html = res.text().await.expect("text");
    assert!(html.contains("<title>Alba studio</title>"), "{html}");
    let script = html
        .split("src=\"./")
        .nth(1)
        .and_then(|r| r.split('"').next())
        .expect("a script");
    let js = s.http.get(s.url(&format!("/{script}"))).send().await.expect("script");
    assert_eq!(js.status(), StatusCode::OK);
    // One type, the file's: a second `application/octet-stream` beside it
    // makes Chromium refuse the script under `nosniff` (a blank studio).
    let types: Vec<&str> = js
        .headers()
        .get_all("content-type")
        .iter()
        .filter_map(|v| v.to_str().ok())
        .collect();
    assert_eq!(types, ["text/javascript; charset=utf-8"]);
    let raw = js.bytes().await.expect("js");
    assert!(raw.len() > 10_000, "the bundle, not a placeholder");
    // Compressed for a client that accepts it (SPEC §10.6): the build's own
    // brotli and gzip copies, with `Vary` for caches; identity otherwise.
    for (accept, coding, magic) in [
        ("gzip", Some("gzip"), Some(&[0x1f_u8, 0x8b][..])),
        ("gzip, deflate, br, zstd", Some("br"), None),
        ("br;q=0, gzip;q=0.8", Some("gzip"), Some(&[0x1f, 0x8b][..])),
        ("identity", None, None),
    ] {
        for path in [format!("/{script}"), "/".to_string()] {
            let res = s
                .http
                .get(s.url(&path))
                .header("accept-encoding", accept)
                .send()
                .await
                .expect("GET");
            assert_eq!(res.status(), StatusCode::OK);
            let h = res.headers().clone();
            assert_eq!(
                h.get("content-encoding").and_then(|v| v.to_str().ok()),
                coding,
                "{path} for {accept:?}"
            );
            assert_eq!(
                h.get("vary").and_then(|v| v.to_str().ok()),
                Some("Accept-Encoding"),
                "{path}"
            );
            let body = res.bytes().await.expect("body");
            if let Some(m) = magic {
                assert!(body.starts_with(m), "{path}: a gzip stream");
            }
            if coding.is_some() && path != "/" {
                assert!(
                    body.len() * 2 < raw.len(),
                    "{path}: {} of {} bytes",
                    body.len(),
                    raw.len()
                );
            } else if path != "/" {
                assert_eq!(body, raw);
            }
        }
    }
    s.stop().await;
}

/// "Where is this tag used?": every place the programs name it, through
/// members, alias addresses and expressions, with rung, element id and
/// whether it is written there.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_uses_of_a_tag_are_listed_with_their_places() {
    let s = Server::start("tank-plant", "uses").await;
    let uses = s.get("/api/tags/Llenar/uses").await;
    let got: Vec<(String, u64, bool)> = uses
        .as_array()
        .expect("array")
        .iter()
        .map(|u| {
            (
                u["instruction"].as_str().expect("text").to_string(),
                u["rung"].as_u64().expect("rung"),
                u["write"].as_bool().expect("write"),
            )
        })
        .collect();
    assert_eq!(
        got,
        [
            ("OTL(Llenar)".to_string(), 5, true),
            ("OTU(Llenar)".to_string(), 6, true),
            ("XIC(Llenar)".to_string(), 7, false),
        ]
    );
    let first = &uses[0];
    assert_eq!(
        (first["program"].as_str(), first["line"].as_u64(), first["col"].as_u64()),
        (Some("main.lad"), Some(12), Some(18))
    );
    // The id is the element's in the program view.
    let program = s.get("/api/programs/main.lad").await;
    assert!(
        program.to_string().contains(&format!("\"id\":{}", first["id"])),
        "{first}"
    );
    // A structure: every member's uses (CTU, XIC(CT_STP.DN), RES, EQU on .ACC).
    assert_eq!(s.get("/api/tags/CT_STP/uses").await.as_array().map(Vec::len), Some(4));
    // Inside an expression, in the plant program.
    let vol = s.get("/api/tags/Vol_L/uses").await;
    assert!(
        vol.as_array()
            .expect("array")
            .iter()
            .any(|u| u["program"] == "plant.lad"
                && u["instruction"].as_str().is_some_and(|t| t.starts_with("CPT(S_ULT,"))),
        "{vol}"
    );
    let (code, j) = s.call(Method::GET, "/api/tags/Nope/uses", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND, "{j}");
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn autotune_runs_the_relay_experiment_on_a_copy_and_leaves_the_plc_alone() {
    let s = Server::start("pid-level", "autotune").await;
    let sp = s.value("Loop.SP").await;
    let (code, j) = s
        .call(
            Method::POST,
            "/api/pid/Loop/autotune",
            Some(json!({"sp": 4.0, "amplitude": 10, "bias": 30})),
        )
        .await;
    assert_eq!(code, StatusCode::OK, "{j}");
    let (ku, pu) = (j["ku"].as_f64().expect("ku"), j["pu"].as_f64().expect("pu"));
    assert!(ku > 0.0 && pu > 0.0, "{j}");
    let rules = j["rules"].as_array().expect("rules");
    assert_eq!(rules.len(), 5, "{j}");
    // Ziegler–Nichols PI: Kc = 0.45 Ku, Ti = Pu / 1.2, KI = Kc / Ti.
    let zn = rules.iter().find(|r| r["rule"] == "Ziegler-Nichols PI").expect("ZN PI");
    assert!((zn["kc"].as_f64().expect("kc") - 0.45 * ku).abs() < 1e-9, "{j}");
    assert!(
        (zn["ki"].as_f64().expect("ki") - 0.45 * ku / (pu / 1.2)).abs() < 1e-9,
        "{j}"
    );
    // With its defaults (the loop's SP, a relay around its CV now) on the
    // example at rest: it oscillates (a bias of 50 % never crossed the SP).
    let cv = s.value("Loop.CV").await.as_f64().expect("CV");
    let (code, j) = s.call(Method::POST, "/api/pid/Loop/autotune", Some(json!({}))).await;
    assert_eq!(code, StatusCode::OK, "{j}");
    assert!(
        (j["bias"].as_f64().expect("bias") - cv).abs() < 1.0,
        "around the CV of {cv}: {j}"
    );
    assert!(j["ku"].as_f64().expect("ku") > 0.0, "{j}");
    // The running loop was not touched.
    assert_eq!(s.value("Loop.SP").await, sp);
    assert_eq!(s.value("Loop.MAN").await, json!(false));
    for (path, body, want) in [
        ("/api/pid/Level/autotune", json!({}), StatusCode::UNPROCESSABLE_ENTITY),
        ("/api/pid/Nope/autotune", json!({}), StatusCode::NOT_FOUND),
        (
            "/api/pid/Loop/autotune",
            json!({"amplitude": 0}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            "/api/pid/Loop/autotune",
            json!({"bias": 101}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        ("/api/pid/Loop/autotune", json!({"gain": 1}), StatusCode::BAD_REQUEST),
    ] {
        let (code, j) = s.call(Method::POST, path, Some(body)).await;
        assert_eq!(code, want, "{path}: {j}");
    }
    s.stop().await;
}
