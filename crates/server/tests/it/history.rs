use crate::Server;
use reqwest::{Method, StatusCode};
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_tag_is_recorded_and_queried_downsampled() {
    let s = Server::start("tank-plant", "history").await;
    let t0 = s.get("/api/status").await;
    assert_eq!(t0["state"], "running");
    // The plant fills the tank: the level rises for the first 20 s.
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let tags = s.get("/api/history/tags").await;
    let level = tags
        .as_array()
        .expect("array")
        .iter()
        .find(|t| t["name"] == "Nivel_L")
        .cloned()
        .expect("Nivel_L recorded");
    let (first, last) = (
        level["first_ms"].as_i64().expect("ms"),
        level["last_ms"].as_i64().expect("ms"),
    );
    assert!(last - first >= 500, "{level}");
    assert!(
        tags.as_array()
            .expect("array")
            .iter()
            .any(|t| t["name"] == "CT_STP.ACC"),
        "members too"
    );

    let q = s
        .get(&format!("/api/history?tag=Nivel_L&from={first}&to={last}&points=10"))
        .await;
    let b = q["buckets"].as_array().expect("buckets");
    assert!(!b.is_empty() && b.len() <= 10, "{q}");
    for w in b.windows(2) {
        assert!(w[0][0].as_i64() < w[1][0].as_i64(), "buckets in time order: {q}");
    }
    let num = |v: &serde_json::Value| v.as_f64().expect("number");
    for x in b {
        let (min, max, f, l) = (num(&x[1]), num(&x[2]), num(&x[3]), num(&x[4]));
        assert!(
            min <= f && f <= max && min <= l && l <= max && (0.0..=60.0).contains(&min),
            "{x}"
        );
    }
    assert!(
        num(&b[b.len() - 1][4]) > num(&b[0][3]),
        "the level rises while B1 fills: {q}"
    );

    // The embedded store holds this runtime only: its node is the project's name.
    assert_eq!(
        s.get("/api/history/nodes").await,
        serde_json::json!({"node": "tank-plant", "shared": false, "nodes": ["tank-plant"]})
    );
    let own = s
        .get(&format!(
            "/api/history?tag=Nivel_L&from={first}&to={last}&points=10&node=tank-plant"
        ))
        .await;
    assert_eq!(own["node"], "tank-plant");
    assert_eq!(own["buckets"], q["buckets"], "naming this node is the same query");
    let raw = s
        .get(&format!("/api/history/raw?tag=Nivel_L&from={first}&to={last}&limit=3"))
        .await;
    let points = raw["points"].as_array().expect("points");
    assert_eq!(points.len(), 3, "{raw}");
    assert_eq!(points[0][0].as_i64(), Some(first));
    assert_eq!(raw["more"], true);
    assert_eq!(
        num(&points[0][1]),
        num(&b[0][3]),
        "the first sample is the first bucket's first"
    );

    let res = s
        .http
        .get(s.url(&format!(
            "/api/history.csv?tags=Nivel_L,Bomba1@tank-plant&from={first}&to={last}&step=100"
        )))
        .send()
        .await
        .expect("csv");
    assert_eq!(res.status(), StatusCode::OK);
    let text = res.text().await.expect("text");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("Time (ms),Nivel_L,Bomba1"));
    let first: Vec<&str> = lines.next().expect("a row").split(',').collect();
    assert_eq!(first[0], "0", "times relative to `from`");
    // B1 fills the tank for its first 20 s: the rows after the first (which may
    // hold the memory before the first scan, B1 still off) show it on. (Not only
    // the last row: on a loaded machine the recorder may skip snapshots.)
    assert!(
        text.lines().skip(2).any(|l| l.ends_with(",1")),
        "B1 recorded on while it fills the tank:\n{text}"
    );
    assert!(text.lines().count() >= 6);

    let bad: [(&str, StatusCode, &str); 12] = [
        (
            "/api/history?tag=Nivel_L&from=0&to=1&node=line-9",
            StatusCode::NOT_FOUND,
            "no history for node `line-9`",
        ),
        (
            "/api/history/tags?node=line-9",
            StatusCode::NOT_FOUND,
            "no history for node `line-9`",
        ),
        (
            "/api/history.csv?tags=Nivel_L@line-9&from=0&to=1",
            StatusCode::NOT_FOUND,
            "no history for node `line-9`",
        ),
        (
            "/api/history/raw?tag=Nivel_L&from=0&to=1&limit=0",
            StatusCode::UNPROCESSABLE_ENTITY,
            "`limit` must be 1 to 100000",
        ),
        ("/api/history?from=0&to=1", StatusCode::BAD_REQUEST, "`tag`"),
        (
            "/api/history?tag=Nivel_L&from=x&to=1",
            StatusCode::BAD_REQUEST,
            "`from` must be an integer",
        ),
        (
            "/api/history?tag=Nope&from=0&to=1",
            StatusCode::NOT_FOUND,
            "no history for `Nope`",
        ),
        (
            "/api/history?tag=Nivel_L&from=0&to=1&points=0",
            StatusCode::UNPROCESSABLE_ENTITY,
            "points",
        ),
        ("/api/history.csv?tags=&from=0&to=1", StatusCode::BAD_REQUEST, "no tag"),
        (
            "/api/history.csv?tags=Nivel_L&from=0&to=100000000&step=1",
            StatusCode::UNPROCESSABLE_ENTITY,
            "rows",
        ),
        // Issue 31: `to - from` overflowed and this passed as one row (10 M were streamed).
        (
            "/api/history.csv?tags=Nivel_L&from=-9223372036854775808&to=9223372036854775807&step=1801439851",
            StatusCode::UNPROCESSABLE_ENTITY,
            "rows",
        ),
        (
            "/api/history.csv?tags=Nivel_L&from=0&to=1&step=0",
            StatusCode::UNPROCESSABLE_ENTITY,
            "`step`",
        ),
    ];
    for (path, want, msg) in bad {
        let (code, j) = s.call(Method::GET, path, None).await;
        assert_eq!(code, want, "{path}: {j}");
        assert!(j["error"].as_str().expect("error").contains(msg), "{path}: {j}");
    }
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn history_can_be_turned_off() {
    let dir = crate::copy_example("start-stop", "nohistory");
    let toml = std::fs::read_to_string(dir.join("alba.toml")).expect("toml");
    std::fs::write(dir.join("alba.toml"), format!("{toml}\n[history]\nenabled = false\n")).expect("write");
    let s = Server::start_in(dir).await;
    let (code, j) = s.call(Method::GET, "/api/history/tags", None).await;
    assert_eq!(code, StatusCode::NOT_FOUND);
    assert!(j["error"].as_str().expect("msg").contains("history is off"));
    assert!(!s.dir.join(".alba/history.db").exists());
    s.stop().await;
}
