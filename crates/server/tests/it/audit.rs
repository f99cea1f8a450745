//! The audit trail through the API: a row for each kind of action with its
//! old and new values, filters and pages, the CSV export, and no action
//! performed when its row cannot be written.

use crate::Server;
use reqwest::{Method, StatusCode};
use serde_json::{Value as Json, json};

async fn rows(s: &Server, query: &str) -> Vec<Json> {
    let page = s.get(&format!("/api/audit{query}")).await;
    page["rows"].as_array().expect("rows").clone()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_action_has_its_row_with_old_and_new_values() {
    let s = Server::start("tank", "audit-rows").await;
    assert_eq!(rows(&s, "").await, Vec::<Json>::new());
    let ok = |c: StatusCode| assert!(c.is_success(), "{c}");
    ok(s.call(Method::PUT, "/api/tags/CT_STP.PRE", Some(json!({"value": 7})))
        .await
        .0);
    ok(s.call(Method::PUT, "/api/forces/STOP", Some(json!({"value": true})))
        .await
        .0);
    ok(s.call(Method::PUT, "/api/forces/STOP", Some(json!({"value": false})))
        .await
        .0);
    ok(s.call(Method::DELETE, "/api/forces/STOP", None).await.0);
    ok(s.call(Method::PUT, "/api/forces/FILL", Some(json!({"value": true})))
        .await
        .0);
    ok(s.call(Method::DELETE, "/api/forces", None).await.0);
    ok(s.call(Method::POST, "/api/stop", None).await.0);
    // Written while stopped.
    ok(s.call(Method::PUT, "/api/tags/CT_STP.PRE", Some(json!({"value": 9})))
        .await
        .0);
    ok(s.call(Method::POST, "/api/run", None).await.0);
    let text = std::fs::read_to_string(s.dir.join("main.lad")).expect("main.lad");
    let edited = format!(
        "{}\n// Rung 12: added online\nXIC(Llenar)OTE(L_FILL);\n",
        text.replace("OTE(L_STP)", "OTE(L_STP)OTE(L_STP)")
    );
    ok(s.call(
        Method::PUT,
        "/api/programs/main.lad",
        Some(json!({"text": edited, "online": true})),
    )
    .await
    .0);
    ok(
        s.call(Method::PUT, "/api/programs/main.lad", Some(json!({"text": text})))
            .await
            .0,
    );
    let tags = std::fs::read_to_string(s.dir.join("tags.csv")).expect("tags.csv");
    ok(s.raw(
        Method::PUT,
        "/api/tags.csv",
        "text/csv",
        format!("{tags}Extra,DINT,,,,added\n").into_bytes(),
    )
    .await
    .0);
    // Refused before anything is done: no row.
    let (code, _) = s
        .call(Method::PUT, "/api/tags/STOP", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);
    let (code, _) = s
        .call(Method::PUT, "/api/programs/main.lad", Some(json!({"text": "XIC("})))
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);

    let all = rows(&s, "").await;
    let seen: Vec<(String, Json, Json, Json, String)> = all
        .iter()
        .rev()
        .map(|r| {
            (
                r["action"].as_str().expect("action").to_string(),
                r["target"].clone(),
                r["old"].clone(),
                r["new"].clone(),
                r["outcome"].as_str().expect("outcome").to_string(),
            )
        })
        .collect();
    let row = |a: &str, t: Json, o: Json, n: Json, out: &str| (a.to_string(), t, o, n, out.to_string());
    assert_eq!(
        seen,
        vec![
            row("write", json!("CT_STP.PRE"), json!(2), json!(7), "ok"),
            row("force", json!("STOP"), json!(false), json!(true), "ok"),
            row("force", json!("STOP"), json!(true), json!(false), "ok"),
            row("unforce", json!("STOP"), json!(false), Json::Null, "ok"),
            row("force", json!("FILL"), json!(false), json!(true), "ok"),
            row("unforce", Json::Null, json!({"FILL": true}), Json::Null, "ok"),
            row("stop", Json::Null, json!("running"), json!("stopped"), "ok"),
            row("write", json!("CT_STP.PRE"), json!(7), json!(9), "ok"),
            row("run", Json::Null, json!("stopped"), json!("running"), "ok"),
            row("online_edit", json!("main.lad"), Json::Null, Json::Null, "ok"),
            row("save_program", json!("main.lad"), Json::Null, Json::Null, "ok"),
            row("save_tags", json!("tags.csv"), Json::Null, Json::Null, "ok"),
        ]
    );
    let by = |action: &str| {
        all.iter()
            .rev()
            .filter(|r| r["action"] == action)
            .cloned()
            .collect::<Vec<_>>()
    };
    assert_eq!(
        by("online_edit")[0]["detail"],
        "rungs: 1 added, 0 removed, 1 changed (11 → 12)"
    );
    assert_eq!(
        by("save_program")[0]["detail"],
        "rungs: 0 added, 1 removed, 1 changed (12 → 11)"
    );
    assert_eq!(
        by("save_tags")[0]["detail"],
        "rows: 1 added, 0 removed, 0 changed (18 → 19)"
    );
    // (A `failed` outcome needs a runtime that refuses a request, which a
    // simulated project does not: alba-audit's tests cover it.)
    for r in &all {
        // No users configured: no user; the client's address when the server knows it.
        assert_eq!(r["user"], Json::Null, "{r}");
        assert!(r["time_ms"].as_i64().expect("time") > 1_600_000_000_000, "{r}");
    }
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn filters_pages_and_csv_export() {
    let s = Server::start("tank", "audit-filters").await;
    for v in 1..=5 {
        let (code, _) = s
            .call(Method::PUT, "/api/tags/CT_STP.PRE", Some(json!({"value": v})))
            .await;
        assert_eq!(code, StatusCode::OK);
    }
    s.call(Method::PUT, "/api/forces/STOP", Some(json!({"value": true})))
        .await;
    s.call(Method::DELETE, "/api/forces", None).await;

    assert_eq!(rows(&s, "?action=write").await.len(), 5);
    assert_eq!(rows(&s, "?action=force,unforce").await.len(), 2);
    assert_eq!(
        rows(&s, "?target=stop").await.len(),
        1,
        "targets match case-insensitively"
    );
    assert_eq!(rows(&s, "?user=ana").await.len(), 0);
    assert_eq!(rows(&s, "?from=0&to=1").await.len(), 0);
    // Pages of 2, newest first, no row twice.
    let mut ids = Vec::new();
    let mut q = "?limit=2".to_string();
    loop {
        let page = s.get(&format!("/api/audit{q}")).await;
        let r = page["rows"].as_array().expect("rows");
        assert!(r.len() <= 2);
        ids.extend(r.iter().map(|r| r["id"].as_i64().expect("id")));
        match page["next"].as_i64() {
            Some(n) => q = format!("?limit=2&before={n}"),
            None => break,
        }
    }
    assert_eq!(ids, (1..=7).rev().collect::<Vec<i64>>());
    for (q, want) in [
        ("?action=nope", StatusCode::BAD_REQUEST),
        ("?usr=ana", StatusCode::BAD_REQUEST),
        ("?from=yesterday", StatusCode::BAD_REQUEST),
        ("?limit=0", StatusCode::UNPROCESSABLE_ENTITY),
    ] {
        let (code, j) = s.call(Method::GET, &format!("/api/audit{q}"), None).await;
        assert_eq!(code, want, "{q}: {j}");
        assert!(j["error"].is_string(), "{q}: {j}");
    }

    let res = s
        .http
        .get(s.url("/api/audit.csv?action=write&limit=3"))
        .send()
        .await
        .expect("csv");
    assert_eq!(res.status(), StatusCode::OK);
    assert_eq!(res.headers()["content-type"], "text/csv; charset=utf-8");
    let text = res.text().await.expect("text");
    let lines: Vec<&str> = text.split("\r\n").filter(|l| !l.is_empty()).collect();
    assert_eq!(lines[0], alba_audit::CSV_HEADER.trim_end());
    assert_eq!(lines.len(), 4, "{text}");
    assert!(
        lines[1].starts_with("1,") && lines[1].contains(",write,CT_STP.PRE,2,1,,ok,"),
        "{text}"
    );
    let (code, _) = s.call(Method::GET, "/api/audit.csv?before=3", None).await;
    assert_eq!(code, StatusCode::BAD_REQUEST);
    s.stop().await;
}

/// A row that cannot be written refuses the action: 500, nothing changed.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn no_action_without_its_row() {
    let s = Server::start("tank", "audit-refuse").await;
    let db = rusqlite::Connection::open(s.dir.join(".alba/audit.db")).expect("open the audit log");
    db.execute_batch("CREATE TRIGGER full BEFORE INSERT ON audit BEGIN SELECT RAISE(ABORT, 'disk full'); END;")
        .expect("make inserts fail");
    let (code, j) = s
        .call(Method::PUT, "/api/tags/CT_STP.PRE", Some(json!({"value": 7})))
        .await;
    assert_eq!(code, StatusCode::INTERNAL_SERVER_ERROR, "{j}");
    assert!(
        j["error"]
            .as_str()
            .expect("error")
            .contains("audit trail cannot be written"),
        "{j}"
    );
    assert_eq!(s.value("CT_STP.PRE").await, 2, "the write was not performed");
    // Stop makes the plant safer: it is performed all the same, its row kept
    // in the fallback journal until the log can be written (issue 31).
    let (code, _) = s.call(Method::POST, "/api/stop", None).await;
    assert_eq!(code, StatusCode::OK);
    assert_eq!(s.get("/api/status").await["state"], "stopped");
    let (code, _) = s
        .call(Method::PUT, "/api/forces/STOP", Some(json!({"value": true})))
        .await;
    assert_eq!(code, StatusCode::INTERNAL_SERVER_ERROR);
    assert_eq!(s.get("/api/forces").await, json!([]));
    let before = std::fs::read_to_string(s.dir.join("main.lad")).expect("main.lad");
    let (code, _) = s
        .call(
            Method::PUT,
            "/api/programs/main.lad",
            Some(json!({"text": format!("{before}XIC(Llenar)OTE(L_FILL);\n")})),
        )
        .await;
    assert_eq!(code, StatusCode::INTERNAL_SERVER_ERROR);
    assert_eq!(
        std::fs::read_to_string(s.dir.join("main.lad")).expect("main.lad"),
        before,
        "not saved"
    );
    db.execute_batch("DROP TRIGGER full;").expect("disk freed");
    let (code, _) = s
        .call(Method::PUT, "/api/tags/CT_STP.PRE", Some(json!({"value": 7})))
        .await;
    assert_eq!(code, StatusCode::OK);
    let all = rows(&s, "").await;
    assert_eq!(all.len(), 2, "the write, and the stop from the journal: {all:?}");
    assert!(
        all.iter()
            .any(|r| r["action"] == "stop" && r["detail"].as_str().is_some_and(|d| d.contains("audit.journal"))),
        "{all:?}"
    );
    s.stop().await;
}

/// With users: each row names the session's user; logins (both kinds) and
/// logouts have rows too.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn rows_name_the_user_and_logins_are_recorded() {
    let dir = crate::copy_example("tank", "audit-users");
    let mut users = alba_auth::Users::load(&dir).expect("no users yet");
    users
        .add("ana", alba_auth::Role::Engineer, "correct horse battery staple 42")
        .expect("add ana");
    users.save(&dir).expect("save users.toml");
    let s = start_with_users(dir).await;
    let login = |password: &'static str| {
        s.http
            .post(s.url("/api/login"))
            .json(&json!({"user": "ana", "password": password}))
            .send()
    };
    assert_eq!(
        login("wrong password, sorry").await.expect("login").status(),
        StatusCode::UNAUTHORIZED
    );
    let res = login("correct horse battery staple 42").await.expect("login");
    assert_eq!(res.status(), StatusCode::OK);
    let token = res.json::<Json>().await.expect("json")["token"]
        .as_str()
        .expect("token")
        .to_string();
    let bearer = |m: Method, path: &str| s.http.request(m, s.url(path)).bearer_auth(&token);
    let res = bearer(Method::PUT, "/api/tags/CT_STP.PRE")
        .json(&json!({"value": 4}))
        .send()
        .await
        .expect("write");
    assert_eq!(res.status(), StatusCode::OK);
    let page: Json = bearer(Method::GET, "/api/audit")
        .send()
        .await
        .expect("audit")
        .json()
        .await
        .expect("json");
    let res = bearer(Method::POST, "/api/logout")
        .json(&json!({}))
        .send()
        .await
        .expect("logout");
    assert_eq!(res.status(), StatusCode::NO_CONTENT);
    let rows: Vec<(String, Json, Json, String)> = page["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .rev()
        .map(|r| {
            assert!(r["addr"].as_str().expect("addr").starts_with("127.0.0.1:"), "{r}");
            (
                r["action"].as_str().expect("action").to_string(),
                r["user"].clone(),
                r["target"].clone(),
                r["outcome"].as_str().expect("outcome").to_string(),
            )
        })
        .collect();
    let row = |a: &str, t: &str, o: &str| (a.to_string(), json!("ana"), json!(t), o.to_string());
    assert_eq!(
        rows,
        vec![
            row("login_failed", "ana", "failed"),
            row("login", "ana", "ok"),
            row("write", "CT_STP.PRE", "ok"),
        ]
    );
    // The logout's row, read straight from the file (the session has ended).
    let log = alba_audit::Audit::open(s.dir.join(".alba/audit.db"), alba_audit::Config::default()).expect("open");
    let last = log.query(&alba_audit::Filter::default(), None, 1).expect("query").rows;
    assert_eq!(
        (last[0].action.as_str(), last[0].user.as_deref()),
        ("logout", Some("ana"))
    );
    s.stop().await;
}

/// `Server::start_in` without its wait for scans (which reads the status
/// without logging in).
async fn start_with_users(dir: std::path::PathBuf) -> Server {
    let (ready_tx, ready_rx) = tokio::sync::oneshot::channel();
    let (stop, stop_rx) = tokio::sync::oneshot::channel::<()>();
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
        let ready = move |a| {
            let _ = ready_tx.send(a);
        };
        let r = alba_app::run(&d, opts, ready, async move {
            let _ = stop_rx.await;
        })
        .await;
        assert!(r.is_ok(), "alba run failed");
    });
    let addr = ready_rx.await.expect("server started");
    Server {
        addr,
        dir,
        http: reqwest::Client::new(),
        stop: Some(stop),
        task: Some(task),
    }
}
