//! Images of the screens (docs/api.md, "Assets"): uploaded into
//! `hmi/assets/`, served with their type, `nosniff` and a policy that lets
//! nothing run; SVG with scripts or external references refused; oversize 413.

use crate::Server;
use reqwest::{Method, StatusCode};
use serde_json::json;

const PNG: &[u8] = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x01\0\0\0\x01\x08\x06\0\0\0\x1f\x15\xc4\x89";
const SVG: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 4 4"><rect id="r" width="4" height="4" fill="teal"/><use href="#r"/></svg>"##;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn images_are_saved_served_and_audited() {
    let s = Server::start("tank", "assets-ok").await;
    let (c, j) = s
        .raw(Method::PUT, "/api/assets/pump.png", "image/png", PNG.to_vec())
        .await;
    assert_eq!(c, StatusCode::OK, "{j}");
    assert_eq!(j, json!({"name": "pump.png", "type": "image/png", "bytes": PNG.len()}));
    assert_eq!(std::fs::read(s.dir.join("hmi/assets/pump.png")).expect("saved"), PNG);
    let (c, j) = s
        .raw(
            Method::PUT,
            "/api/assets/tank.svg",
            "image/svg+xml",
            SVG.as_bytes().to_vec(),
        )
        .await;
    assert_eq!(c, StatusCode::OK, "{j}");
    assert_eq!(s.get("/api/assets").await, json!(["pump.png", "tank.svg"]));
    for (name, ctype, body) in [
        ("pump.png", "image/png", PNG),
        ("tank.svg", "image/svg+xml", SVG.as_bytes()),
    ] {
        let res = s
            .http
            .get(s.url(&format!("/api/assets/{name}")))
            .send()
            .await
            .expect("get");
        assert_eq!(res.status(), StatusCode::OK);
        let h = res.headers().clone();
        assert_eq!(h["content-type"], ctype);
        assert_eq!(h["x-content-type-options"], "nosniff");
        let csp = h["content-security-policy"].to_str().expect("csp");
        assert!(
            csp.starts_with("default-src 'none'") && csp.contains("sandbox"),
            "{csp}"
        );
        assert_eq!(res.bytes().await.expect("body").as_ref(), body);
    }
    let rows = s.get("/api/audit?action=save_asset").await["rows"].clone();
    let rows = rows.as_array().expect("rows");
    assert_eq!(rows.len(), 2, "{rows:?}");
    assert!(
        rows.iter()
            .any(|r| r["target"] == "hmi/assets/pump.png" && r["detail"] == format!("image/png, {} bytes", PNG.len()))
    );
    s.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_images_are_refused_and_nothing_is_saved() {
    let s = Server::start("tank", "assets-refused").await;
    let svg = |inner: &str| format!(r#"<svg xmlns="http://www.w3.org/2000/svg">{inner}</svg>"#).into_bytes();
    for (name, ctype, body, code, says) in [
        (
            "x.svg",
            "image/svg+xml",
            svg("<script>alert(1)</script>"),
            422,
            "scripts",
        ),
        (
            "x.svg",
            "image/svg+xml",
            svg(r#"<rect onclick="alert(1)"/>"#),
            422,
            "event handler",
        ),
        (
            "x.svg",
            "image/svg+xml",
            svg(r#"<image href="https://evil.example/a.png"/>"#),
            422,
            "external reference",
        ),
        (
            "x.svg",
            "image/svg+xml",
            svg(r#"<use xmlns:xlink="http://www.w3.org/1999/xlink" xlink:href="http://evil.example/s.svg#a"/>"#),
            422,
            "external reference",
        ),
        ("x.png", "image/png", b"GIF89a....".to_vec(), 422, "not a image/png"),
        (
            "x.gif",
            "application/octet-stream",
            b"<svg/>".to_vec(),
            422,
            "not a image/gif",
        ),
        (
            "x.exe",
            "application/octet-stream",
            PNG.to_vec(),
            400,
            "not an image name",
        ),
        ("..%2Fx.png", "image/png", PNG.to_vec(), 400, "not an image name"),
        ("x.png", "image/png", vec![0x89; 2 * 1024 * 1024 + 1], 413, "too large"),
    ] {
        let (c, j) = s.raw(Method::PUT, &format!("/api/assets/{name}"), ctype, body).await;
        assert_eq!(c.as_u16(), code, "{name} {says}: {j}");
        let e = j["error"].as_str().expect("error");
        assert!(e.contains(says), "{name}: {e}");
    }
    // Sent as text: refused by the guard (a type another origin may send without asking).
    let (c, _) = s
        .raw(Method::PUT, "/api/assets/y.png", "text/plain", PNG.to_vec())
        .await;
    assert_eq!(c, StatusCode::UNSUPPORTED_MEDIA_TYPE);
    assert!(!s.dir.join("hmi/assets").exists(), "nothing saved");
    let (c, _) = s.call(Method::GET, "/api/assets/none.png", None).await;
    assert_eq!(c, StatusCode::NOT_FOUND);
    let rows = s.get("/api/audit").await["rows"].clone();
    assert_eq!(rows, json!([]), "no row for a refused upload");
    s.stop().await;
}
