//! `GET|PUT /api/trends`: the trend set saved in the project (issue 16).

use crate::Server;
use reqwest::{Method, StatusCode};
use serde_json::json;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_trend_set_is_saved_in_the_project_and_checked() {
    let s = Server::start("tank-plant", "trends").await;
    let file = s.dir.join("trends.json");
    assert_eq!(
        s.get("/api/trends").await,
        json!({"version": 1, "window_ms": 60000, "pens": []}),
        "a default without a file"
    );
    let set = json!({"version": 1, "window_ms": 300000, "pens": [
        {"tag": "Nivel_L", "axis": 1, "min": 0.0, "max": 60.0},
        {"tag": "Bomba1", "axis": 2, "min": null, "max": null},
        {"tag": "CT_STP.ACC", "axis": 2, "min": null, "max": null},
        // Another node's recorded tag (a shared historian): not one of this program's.
        {"tag": "Flow", "node": "line-2", "axis": 3, "min": null, "max": null},
        {"tag": "Nivel_L", "node": "line-2", "axis": 3, "min": null, "max": null},
    ]});
    let (code, saved) = s.call(Method::PUT, "/api/trends", Some(set.clone())).await;
    assert_eq!(code, StatusCode::OK, "{saved}");
    assert_eq!(s.get("/api/trends").await, set);
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).expect("trends.json")).expect("JSON");
    assert_eq!(on_disk, set);
    // Refused, and the file unchanged.
    let pen = |p: serde_json::Value| json!({"version": 1, "window_ms": 60000, "pens": [p]});
    let bad = [
        (
            pen(json!({"tag": "Nope", "axis": 1, "min": null, "max": null})),
            422,
            "pens[0] (Nope)",
        ),
        (
            pen(json!({"tag": "CT_STP", "axis": 1, "min": null, "max": null})),
            422,
            "a structure cannot be plotted",
        ),
        (
            pen(json!({"tag": "Nivel_L", "axis": 7, "min": null, "max": null})),
            422,
            "axis 7 is out of range",
        ),
        (
            pen(json!({"tag": "Nivel_L", "axis": 1, "min": 5.0, "max": 1.0})),
            422,
            "min 5 must be below max 1",
        ),
        (
            pen(json!({"tag": "Nivel_L", "axis": 1, "min": 5.0, "max": null})),
            422,
            "both min and max",
        ),
        (
            pen(json!({"tag": "Flow", "node": "", "axis": 1, "min": null, "max": null})),
            422,
            "pens[0] (Flow@): a pen of another node needs its tag and node",
        ),
        (
            json!({"version": 1, "window_ms": 60000, "pens": [
                {"tag": "Flow", "node": "n2", "axis": 1, "min": null, "max": null},
                {"tag": "FLOW", "node": "n2", "axis": 2, "min": null, "max": null}]}),
            422,
            "pens[1] (FLOW@n2): the tag is plotted twice",
        ),
        (json!({"version": 2, "window_ms": 60000, "pens": []}), 422, "version 2"),
        (json!({"version": 1, "window_ms": 5, "pens": []}), 422, "window_ms = 5"),
        (
            json!({"version": 1, "window_ms": 60000, "pens": [], "colour": 1}),
            400,
            "unknown field `colour`",
        ),
        (json!([1, 2]), 400, "not a trend set"),
    ];
    for (body, want, says) in bad {
        let (code, j) = s.call(Method::PUT, "/api/trends", Some(body.clone())).await;
        assert_eq!(code.as_u16(), want, "{body}: {j}");
        assert!(j["error"].as_str().is_some_and(|e| e.contains(says)), "{body}: {j}");
    }
    assert_eq!(s.get("/api/trends").await, set);
    // A damaged file is reported with its place, not replaced.
    std::fs::write(&file, "{\"version\": 1,\n \"pens\": [}").expect("write");
    let (code, j) = s.call(Method::GET, "/api/trends", None).await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        j["error"].as_str().is_some_and(|e| e.starts_with("trends.json:2:")),
        "{j}"
    );
    s.stop().await;
}
