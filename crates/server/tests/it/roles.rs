//! Sessions and roles (docs/api.md, "Sessions and roles"): every route ×
//! every role → status, the WebSocket handshake included; sessions that
//! expire, logout, login back-off; no users → loopback clients only.

use crate::{Server, copy_example};
use alba_auth::{Role, Users};
use alba_runtime::{Options, Runtime, SimIo};
use alba_server::auth::{Auth, Limits, ManualClock};
use reqwest::header::{AUTHORIZATION, COOKIE, RETRY_AFTER, SET_COOKIE};
use reqwest::{Method, StatusCode};
use serde_json::{Value as Json, json};
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;

const PASSWORD: &str = "a long test password 7";
const IDLE: Duration = Duration::from_secs(30 * 60);
const MAX: Duration = Duration::from_secs(12 * 3600);

/// users.toml with one user per role, named after it.
fn add_users(dir: &Path) {
    let mut users = Users::default();
    for r in Role::ALL {
        users.add(r.as_str(), r, PASSWORD).expect("add user");
    }
    users.save(dir).expect("save users.toml");
}

/// The server's state over the tank in `dir`, with `auth`.
fn state(dir: &Path, auth: Auth) -> (Arc<alba_server::AppState>, Runtime) {
    let compiled = alba_server::project::load(dir);
    let program = compiled.program.clone().expect("the example compiles");
    let mut ro = Options::new(compiled.project.scan_ms());
    ro.native = false;
    let runtime = Runtime::start(Arc::new(program), ro, Box::new(SimIo)).expect("runtime");
    (
        alba_server::AppState::new(
            runtime.handle(),
            compiled,
            "sim",
            None,
            None,
            auth,
            &alba_settings::Http::default(),
        ),
        runtime,
    )
}

/// The server over the tank with a user per role, on `clock`.
async fn serve(test: &str, clock: Arc<ManualClock>) -> (Server, Runtime) {
    let dir = copy_example("tank", test);
    add_users(&dir);
    let users = Users::load(&dir).expect("users.toml");
    let auth = Auth::new(Arc::new(users), Limits { idle: IDLE, max: MAX })
        .with_clock(clock)
        .reloading_from(&dir);
    let (state, runtime) = state(&dir, auth);
    (Server::serve_state(state, dir).await, runtime)
}

/// Logs in; the token of the reply (checked against the cookie).
async fn login(s: &Server, user: &str, password: &str) -> (StatusCode, Json) {
    let res = s
        .http
        .post(s.url("/api/login"))
        .json(&json!({"user": user, "password": password}))
        .send()
        .await
        .expect("login");
    let code = res.status();
    let cookie = res
        .headers()
        .get(SET_COOKIE)
        .map(|v| v.to_str().expect("cookie").to_string());
    let j: Json = res.json().await.expect("json");
    if code == StatusCode::OK {
        let token = j["token"].as_str().expect("token");
        assert_eq!(
            cookie.as_deref(),
            Some(format!("alba_session={token}; HttpOnly; SameSite=Strict; Path=/").as_str())
        );
    }
    (code, j)
}

async fn token(s: &Server, user: &str) -> String {
    let (code, j) = login(s, user, PASSWORD).await;
    assert_eq!(code, StatusCode::OK, "{j}");
    assert_eq!((&j["user"], &j["role"]), (&json!(user), &json!(user)));
    j["token"].as_str().expect("token").to_string()
}

/// How a request authenticates.
#[derive(Debug, Clone)]
enum Caller {
    Nobody,
    Bearer(String),
    Cookie(String),
}

async fn call(s: &Server, who: &Caller, method: Method, path: &str, body: Option<&Body>) -> (StatusCode, Json) {
    let method_changes = !matches!(method, Method::GET | Method::HEAD);
    let mut req = s.http.request(method, s.url(path));
    req = match who {
        Caller::Nobody => req,
        Caller::Bearer(t) => req.header(AUTHORIZATION, format!("Bearer {t}")),
        Caller::Cookie(t) => req.header(COOKIE, format!("alba_session={t}")),
    };
    req = match body {
        Some(Body::Json(j)) => req.json(j),
        Some(Body::Text(t)) => req.header("content-type", "text/csv").body(t.clone()),
        Some(Body::Svg(t)) => req.header("content-type", "image/svg+xml").body(t.clone()),
        // State-changing requests carry JSON, even an empty object.
        None if method_changes => req.json(&json!({})),
        None => req,
    };
    let res = req.send().await.expect("request");
    let code = res.status();
    let text = res.text().await.expect("body");
    (code, serde_json::from_str(&text).unwrap_or(Json::Null))
}

/// The WebSocket handshake's status (101 when it upgrades).
async fn ws_handshake(s: &Server, who: &Caller) -> u16 {
    let mut req = format!("ws://{}/api/ws", s.addr)
        .into_client_request()
        .expect("request");
    // The studio's own origin, as a browser sends it (the guard refuses others).
    req.headers_mut()
        .insert("origin", format!("http://{}", s.addr).parse().expect("header"));
    match who {
        Caller::Nobody => {}
        Caller::Bearer(t) => {
            req.headers_mut()
                .insert("authorization", format!("Bearer {t}").parse().expect("header"));
        }
        Caller::Cookie(t) => {
            req.headers_mut()
                .insert("cookie", format!("alba_session={t}").parse().expect("header"));
        }
    }
    match tokio_tungstenite::connect_async(req).await {
        Ok((_ws, res)) => res.status().as_u16(),
        Err(tokio_tungstenite::tungstenite::Error::Http(res)) => res.status().as_u16(),
        Err(e) => panic!("handshake: {e}"),
    }
}

#[derive(Debug, Clone)]
enum Body {
    Json(Json),
    Text(String),
    Svg(String),
}

/// A row's status when allowed is the handler's, whatever it is (the
/// studio's page is 503 when the web build is not embedded; the audit
/// trail 404 in a server that keeps none): it is neither 401 nor 403.
const HANDLER: u16 = 0;

/// A route of the table: method, route as in `ROUTE_ROLES` (or the
/// router), a request to it, the role it needs (`None`: public), and the
/// status when allowed.
struct Row {
    method: Method,
    route: &'static str,
    path: String,
    body: Option<Body>,
    needs: Option<Role>,
    ok: u16,
}

fn row(method: Method, route: &'static str, path: &str, body: Option<Body>, needs: Option<Role>, ok: u16) -> Row {
    Row {
        method,
        route,
        path: path.to_string(),
        body,
        needs,
        ok,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_route_answers_each_role_as_the_table_says() {
    let clock = Arc::new(ManualClock::new());
    let (s, runtime) = serve("roles", clock).await;
    let mut callers = vec![
        ("nobody", None, Caller::Nobody),
        ("bad token", None, Caller::Bearer("0".repeat(64))),
        ("bad cookie", None, Caller::Cookie("0".repeat(64))),
    ];
    for r in Role::ALL {
        let t = token(&s, r.as_str()).await;
        // Bearer for some roles, cookie for the others: both carry a session.
        let c = if r >= Role::Engineer {
            Caller::Cookie(t)
        } else {
            Caller::Bearer(t)
        };
        callers.push((r.as_str(), Some(r), c));
    }
    let (_, prog) = call(&s, &callers[6].2, Method::GET, "/api/programs/main.lad", None).await;
    let text = prog["text"].as_str().expect("program text").to_string();
    let (_, csv) = {
        let res = s
            .http
            .get(s.url("/api/tags.csv"))
            .header(AUTHORIZATION, "Bearer ".to_string() + &token(&s, "viewer").await)
            .send()
            .await
            .expect("tags.csv");
        (res.status(), res.text().await.expect("csv"))
    };
    // A recipe for those who may read or apply it before an engineer saves one.
    std::fs::create_dir_all(s.dir.join("recipes")).expect("recipes/");
    std::fs::write(s.dir.join("recipes/r1.csv"), "tag,value\nLlenar,true\n").expect("r1.csv");
    let v = Some(Role::Viewer);
    let o = Some(Role::Operator);
    let e = Some(Role::Engineer);
    let j = |j: Json| Some(Body::Json(j));
    let rows = vec![
        row(Method::GET, "/api/me", "/api/me", None, v, 200),
        row(Method::GET, "/api/status", "/api/status", None, v, 200),
        row(Method::HEAD, "/api/status", "/api/status", None, v, 200),
        row(Method::GET, "/api/tags", "/api/tags", None, v, 200),
        row(Method::GET, "/api/tags/{name}", "/api/tags/Llenar", None, v, 200),
        row(
            Method::PUT,
            "/api/tags/{name}",
            "/api/tags/Llenar",
            j(json!({"value": true})),
            o,
            200,
        ),
        // An input stays the handler's refusal for those allowed to write.
        row(
            Method::PUT,
            "/api/tags/{name}",
            "/api/tags/STOP",
            j(json!({"value": true})),
            o,
            422,
        ),
        row(Method::GET, "/api/forces", "/api/forces", None, v, 200),
        row(
            Method::PUT,
            "/api/forces/{name}",
            "/api/forces/STOP",
            j(json!({"value": true})),
            e,
            200,
        ),
        row(Method::DELETE, "/api/forces/{name}", "/api/forces/STOP", None, e, 204),
        row(Method::DELETE, "/api/forces", "/api/forces", None, e, 204),
        row(Method::GET, "/api/programs", "/api/programs", None, v, 200),
        row(
            Method::GET,
            "/api/programs/{name}",
            "/api/programs/main.lad",
            None,
            v,
            200,
        ),
        row(
            Method::PUT,
            "/api/programs/{name}",
            "/api/programs/main.lad",
            j(json!({"text": text})),
            e,
            200,
        ),
        row(
            Method::POST,
            "/api/check/{name}",
            "/api/check/main.lad",
            j(json!({"text": text})),
            e,
            200,
        ),
        row(Method::GET, "/api/tags.csv", "/api/tags.csv", None, v, 200),
        row(
            Method::PUT,
            "/api/tags.csv",
            "/api/tags.csv",
            Some(Body::Text(csv.clone())),
            e,
            200,
        ),
        row(Method::GET, "/api/trends", "/api/trends", None, v, 200),
        row(Method::GET, "/api/screens", "/api/screens", None, v, 200),
        row(Method::GET, "/api/screens/{name}", "/api/screens/none", None, v, 404),
        row(
            Method::PUT,
            "/api/screens/{name}",
            "/api/screens/main",
            j(json!({"schema": 1, "width": 100, "height": 100, "elements": []})),
            e,
            200,
        ),
        row(
            Method::POST,
            "/api/screens/{name}/check",
            "/api/screens/main/check",
            j(json!({"schema": 1, "width": 100, "height": 100, "elements": []})),
            e,
            200,
        ),
        row(Method::GET, "/api/symbols", "/api/symbols", None, v, 200),
        row(
            Method::PUT,
            "/api/recipes/{name}",
            "/api/recipes/r1",
            Some(Body::Text("tag,value\nLlenar,true\n".into())),
            e,
            200,
        ),
        row(Method::GET, "/api/recipes", "/api/recipes", None, v, 200),
        row(
            Method::GET,
            "/api/reports/shift.xlsx",
            "/api/reports/shift.xlsx?from=0&to=600000",
            None,
            v,
            200,
        ),
        row(
            Method::GET,
            "/api/reports/shift.pdf",
            "/api/reports/shift.pdf?from=0&to=600000",
            None,
            v,
            200,
        ),
        row(
            Method::PUT,
            "/api/assets/{name}",
            "/api/assets/a.svg",
            Some(Body::Svg("<svg xmlns=\"http://www.w3.org/2000/svg\"/>".into())),
            e,
            200,
        ),
        row(Method::GET, "/api/assets", "/api/assets", None, v, 200),
        row(Method::GET, "/api/assets/{name}", "/api/assets/none.png", None, v, 404),
        row(Method::GET, "/api/recipes/{name}", "/api/recipes/r1", None, v, 200),
        row(
            Method::POST,
            "/api/recipes/{name}/capture",
            "/api/recipes/r2/capture",
            j(json!({"tags": ["Llenar"]})),
            e,
            200,
        ),
        row(
            Method::POST,
            "/api/recipes/{name}/apply",
            "/api/recipes/r1/apply",
            None,
            o,
            200,
        ),
        // (the tank has no PID loop: a well-formed request for a number is 422)
        row(
            Method::POST,
            "/api/pid/{name}/autotune",
            "/api/pid/Nivel_L/autotune",
            j(json!({})),
            e,
            422,
        ),
        row(Method::GET, "/api/symbols/{name}", "/api/symbols/none", None, v, 404),
        row(
            Method::PUT,
            "/api/symbols/{name}",
            "/api/symbols/mine",
            j(json!({"schema": 1, "width": 10, "height": 10, "elements": [
                {"id": "a", "type": "led", "x": 0, "y": 0, "w": 10, "h": 10}]})),
            e,
            200,
        ),
        row(
            Method::PUT,
            "/api/trends",
            "/api/trends",
            j(
                json!({"version": 1, "window_ms": 60000, "pens": [{"tag": "Nivel_L", "axis": 1, "min": null, "max": null}]}),
            ),
            Some(Role::Operator),
            200,
        ),
        row(Method::GET, "/api/instructions", "/api/instructions", None, v, 200),
        row(Method::GET, "/api/domain", "/api/domain", None, v, 200),
        // History is off in this server: the handler's 404 for those allowed.
        row(Method::GET, "/api/history/nodes", "/api/history/nodes", None, v, 404),
        row(Method::GET, "/api/history/tags", "/api/history/tags", None, v, 404),
        row(
            Method::GET,
            "/api/history/raw",
            "/api/history/raw?tag=Nivel_L&from=0&to=1",
            None,
            v,
            404,
        ),
        row(Method::GET, "/api/history", "/api/history?tag=Nivel_L", None, v, 404),
        row(
            Method::GET,
            "/api/history.csv",
            "/api/history.csv?tags=Nivel_L",
            None,
            v,
            404,
        ),
        // Alarms: this server has none, so the handlers answer 404 to those allowed.
        row(Method::GET, "/api/alarms", "/api/alarms", None, v, 200),
        row(Method::GET, "/api/alarms/log.csv", "/api/alarms/log.csv", None, v, 404),
        row(Method::GET, "/api/alarms/stats", "/api/alarms/stats", None, v, 200),
        // This server's project has no net: the handler's 404.
        row(
            Method::POST,
            "/api/nets/{name}/analysis",
            "/api/nets/line/analysis",
            j(json!({})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/alarms/{id}/ack",
            "/api/alarms/hi/ack",
            j(json!({})),
            o,
            404,
        ),
        row(
            Method::POST,
            "/api/alarms/{id}/shelve",
            "/api/alarms/hi/shelve",
            j(json!({"minutes": 5, "reason": "test"})),
            o,
            404,
        ),
        row(
            Method::POST,
            "/api/alarms/{id}/unshelve",
            "/api/alarms/hi/unshelve",
            j(json!({})),
            o,
            404,
        ),
        row(
            Method::POST,
            "/api/alarms/{id}/out_of_service",
            "/api/alarms/hi/out_of_service",
            j(json!({"on": true, "reason": "test"})),
            e,
            404,
        ),
        // The audit trail (rows skipped below while this server has no such route).
        row(Method::GET, "/api/audit", "/api/audit", None, e, HANDLER),
        row(Method::GET, "/api/audit.csv", "/api/audit.csv", None, e, HANDLER),
        // This server has no [[opcua_server]]: the handler's 404.
        row(
            Method::GET,
            "/api/opcua/{server}/browse",
            "/api/opcua/plant/browse",
            None,
            e,
            404,
        ),
        row(Method::POST, "/api/stop", "/api/stop", None, e, 200),
        // While stopped: one scan.
        row(Method::POST, "/api/step", "/api/step", None, e, 200),
        row(Method::POST, "/api/run", "/api/run", None, e, 200),
        // This server's project has no net: the handler's 404.
        row(
            Method::POST,
            "/api/nets/{name}/reset",
            "/api/nets/line/reset",
            None,
            e,
            404,
        ),
        // This server has no hardware service (alba-app sets it): the handler's 404.
        row(Method::GET, "/api/hardware", "/api/hardware", None, v, 404),
        row(
            Method::POST,
            "/api/hardware/jobs/{id}/cancel",
            "/api/hardware/jobs/1/cancel",
            j(json!({})),
            e,
            404,
        ),
        // No verification service either (alba-app sets it): the handler's 404.
        row(Method::POST, "/api/verify", "/api/verify", j(json!({})), e, 404),
        row(Method::POST, "/api/tests", "/api/tests", j(json!({})), e, 404),
        row(
            Method::POST,
            "/api/hardware/verify",
            "/api/hardware/verify",
            j(json!({"port": "/dev/null"})),
            e,
            404,
        ),
        row(
            Method::PUT,
            "/api/hardware/board",
            "/api/hardware/board",
            j(json!({"board": "uno"})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/hardware/build",
            "/api/hardware/build",
            j(json!({"board": "uno", "kind": "sketch"})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/hardware/download",
            "/api/hardware/download",
            j(json!({"port": "/dev/null"})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/hardware/identify",
            "/api/hardware/identify",
            j(json!({"port": "/dev/null"})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/hardware/attach",
            "/api/hardware/attach",
            j(json!({"port": "/dev/null", "mode": "controller"})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/hardware/detach",
            "/api/hardware/detach",
            j(json!({})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/hardware/upload",
            "/api/hardware/upload",
            j(json!({"port": "/dev/null", "board": "uno", "kind": "sketch"})),
            e,
            404,
        ),
        row(
            Method::POST,
            "/api/hardware/board/undo",
            "/api/hardware/board/undo",
            j(json!({})),
            e,
            404,
        ),
        row(
            Method::GET,
            "/api/hardware/jobs/{id}",
            "/api/hardware/jobs/1",
            None,
            v,
            404,
        ),
        row(Method::GET, "/api/{*rest}", "/api/nothing-here", None, v, 404),
        row(Method::POST, "/api/{*rest}", "/api/nothing-here", j(json!({})), v, 404),
        // A method a route does not have: closed to all but admin, then 405.
        row(
            Method::DELETE,
            "/api/status",
            "/api/status",
            None,
            Some(Role::Admin),
            405,
        ),
        // Public: the login (a body without a password here), the studio's files.
        row(
            Method::POST,
            "/api/login",
            "/api/login",
            j(json!({"user": "viewer"})),
            None,
            400,
        ),
        row(Method::GET, "/", "/", None, None, HANDLER),
    ];
    // Every route of the role table is exercised (except those of parts not in this server).
    for (m, route, _) in alba_server::ROUTE_ROLES {
        let tested = rows
            .iter()
            .any(|r| r.route == *route && (*m == "*" || r.method.as_str() == *m));
        assert!(tested || *route == "/api/logout", "{m} {route} has no row");
    }
    // The audit trail is another part's: without its routes, its rows would test the fallback.
    let (code, j) = call(&s, &callers[6].2, Method::GET, "/api/audit", None).await;
    let audit_served = !(code == StatusCode::NOT_FOUND && j["error"] == "no such endpoint");
    let rows: Vec<Row> = rows
        .into_iter()
        .filter(|r| audit_served || !r.route.starts_with("/api/audit"))
        .collect();
    let mut failures = Vec::new();
    // Each caller runs the whole table (a force set, then removed; stop, then run).
    for (name, role, who) in &callers {
        for r in &rows {
            let (code, body) = call(&s, who, r.method.clone(), &r.path, r.body.as_ref()).await;
            let want = match (r.needs, role) {
                (None, _) => r.ok,
                (Some(_), None) => 401,
                (Some(n), Some(have)) if *have < n => 403,
                (Some(_), Some(_)) => r.ok,
            };
            let good = if want == HANDLER {
                !matches!(code.as_u16(), 401 | 403)
            } else {
                code.as_u16() == want
            };
            if !good {
                failures.push(format!(
                    "{} {} as {name}: {code} (want {want}) {body}",
                    r.method, r.path
                ));
            }
            if matches!(want, 401 | 403) && r.method != Method::HEAD {
                assert!(body["error"].is_string(), "{} {} as {name}: {body}", r.method, r.path);
            }
        }
    }
    // The WebSocket: viewers and up.
    for (name, role, who) in &callers {
        let code = ws_handshake(&s, who).await;
        let want = if role.is_some() { 101 } else { 401 };
        if code != want {
            failures.push(format!("ws as {name}: {code} (want {want})"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    s.stop().await;
    drop(runtime);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sessions_expire_idle_and_at_their_age_and_logout_ends_them() {
    let clock = Arc::new(ManualClock::new());
    let (s, runtime) = serve("expiry", clock.clone()).await;
    let me = |t: &str| Caller::Bearer(t.to_string());
    let t = token(&s, "operator").await;
    let (code, j) = call(&s, &me(&t), Method::GET, "/api/me", None).await;
    assert_eq!(
        (code, j),
        (
            StatusCode::OK,
            json!({"user": "operator", "role": "operator", "users": true})
        )
    );

    // Idle: a request within the idle time keeps it; past it, 401.
    clock.advance(IDLE - Duration::from_secs(1));
    assert_eq!(
        call(&s, &me(&t), Method::GET, "/api/status", None).await.0,
        StatusCode::OK
    );
    clock.advance(IDLE - Duration::from_secs(1));
    assert_eq!(
        call(&s, &me(&t), Method::GET, "/api/status", None).await.0,
        StatusCode::OK
    );
    clock.advance(IDLE);
    let (code, j) = call(&s, &me(&t), Method::GET, "/api/status", None).await;
    assert_eq!(code, StatusCode::UNAUTHORIZED, "{j}");
    assert!(j["error"].as_str().expect("error").contains("log in again"), "{j}");

    // Absolute: used every 20 minutes, it still ends 12 h after the login.
    let t = token(&s, "operator").await;
    let mut alive = Duration::ZERO;
    while alive + Duration::from_secs(20 * 60) < MAX {
        clock.advance(Duration::from_secs(20 * 60));
        alive += Duration::from_secs(20 * 60);
        assert_eq!(
            call(&s, &me(&t), Method::GET, "/api/me", None).await.0,
            StatusCode::OK,
            "{alive:?}"
        );
    }
    clock.advance(MAX - alive);
    assert_eq!(
        call(&s, &me(&t), Method::GET, "/api/me", None).await.0,
        StatusCode::UNAUTHORIZED
    );

    // Logout: 204, the cookie cleared, the token dead (cookie and bearer alike).
    let t = token(&s, "engineer").await;
    let res = s
        .http
        .post(s.url("/api/logout"))
        .header(COOKIE, format!("alba_session={t}"))
        .json(&json!({}))
        .send()
        .await
        .expect("logout");
    assert_eq!(res.status(), StatusCode::NO_CONTENT);
    let cleared = res
        .headers()
        .get(SET_COOKIE)
        .expect("set-cookie")
        .to_str()
        .expect("ascii");
    assert!(
        cleared.starts_with("alba_session=;") && cleared.contains("Max-Age=0"),
        "{cleared}"
    );
    for who in [Caller::Cookie(t.clone()), Caller::Bearer(t.clone())] {
        assert_eq!(
            call(&s, &who, Method::GET, "/api/me", None).await.0,
            StatusCode::UNAUTHORIZED
        );
        assert_eq!(ws_handshake(&s, &who).await, 401);
    }
    // Logging out twice, or without a session, is harmless.
    assert_eq!(
        call(&s, &me(&t), Method::POST, "/api/logout", None).await.0,
        StatusCode::NO_CONTENT
    );
    assert_eq!(
        call(&s, &Caller::Nobody, Method::POST, "/api/logout", None).await.0,
        StatusCode::NO_CONTENT
    );
    s.stop().await;
    drop(runtime);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn failed_logins_back_off_with_429_and_retry_after() {
    let clock = Arc::new(ManualClock::new());
    let (s, runtime) = serve("backoff", clock.clone()).await;
    // Unknown user and wrong password: the same answer.
    let (c1, j1) = login(&s, "nobody", PASSWORD).await;
    let (c2, j2) = login(&s, "operator", "not the password").await;
    assert_eq!((c1, &j1), (StatusCode::UNAUTHORIZED, &j2));
    assert_eq!(c2, StatusCode::UNAUTHORIZED);
    let mut held = None;
    for _ in 0..10 {
        let res = s
            .http
            .post(s.url("/api/login"))
            .json(&json!({"user": "operator", "password": "not the password"}))
            .send()
            .await
            .expect("login");
        if res.status() == StatusCode::TOO_MANY_REQUESTS {
            held = Some(res);
            break;
        }
        assert_eq!(res.status(), StatusCode::UNAUTHORIZED);
    }
    let res = held.expect("429 after a few failures");
    let wait: u64 = res
        .headers()
        .get(RETRY_AFTER)
        .expect("Retry-After")
        .to_str()
        .expect("ascii")
        .parse()
        .expect("seconds");
    assert!(wait >= 1, "{wait}");
    let j: Json = res.json().await.expect("json");
    assert!(
        j["error"].as_str().expect("error").contains("too many failed logins"),
        "{j}"
    );
    // Even the right password waits (from this address, for this user)...
    assert_eq!(login(&s, "operator", PASSWORD).await.0, StatusCode::TOO_MANY_REQUESTS);
    // ...and passes once the wait is over.
    clock.advance(Duration::from_secs(wait));
    assert_eq!(login(&s, "operator", PASSWORD).await.0, StatusCode::OK);
    s.stop().await;
    drop(runtime);
}

/// A refusal's `error` is in the request's language (issue 34 point 11):
/// 401 and 403 in Spanish for `Accept-Language: es`, English without it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn refusals_speak_the_requests_language() {
    let (s, runtime) = serve("roles-es", Arc::new(ManualClock::new())).await;
    let viewer = token(&s, "viewer").await;
    let ask = |lang: Option<&'static str>, bearer: Option<String>| {
        let mut req = s.http.put(s.url("/api/tags/Llenar")).json(&json!({"value": true}));
        if let Some(l) = lang {
            req = req.header("accept-language", l);
        }
        if let Some(t) = bearer {
            req = req.header(AUTHORIZATION, format!("Bearer {t}"));
        }
        async move {
            let res = req.send().await.expect("request");
            let code = res.status();
            let j: Json = res.json().await.expect("json");
            (code, j["error"].as_str().unwrap_or_default().to_string())
        }
    };
    let (code, e) = ask(Some("es-ES,es;q=0.9"), Some(viewer.clone())).await;
    assert_eq!(code, StatusCode::FORBIDDEN, "{e}");
    assert_eq!(e, "esto necesita el rol operator; usted es viewer");
    let (code, e) = ask(None, Some(viewer)).await;
    assert_eq!(code, StatusCode::FORBIDDEN, "{e}");
    assert_eq!(e, "this needs the role operator; you are viewer");
    let (code, e) = ask(Some("es"), None).await;
    assert_eq!(code, StatusCode::UNAUTHORIZED, "{e}");
    assert_eq!(e, "inicie sesión primero (POST /api/login)");
    let res = s
        .http
        .post(s.url("/api/login"))
        .header("accept-language", "es")
        .json(&json!({"user": "nobody", "password": PASSWORD}))
        .send()
        .await
        .expect("login");
    let j: Json = res.json().await.expect("json");
    assert_eq!(j["error"], "usuario desconocido o contraseña incorrecta");
    s.stop().await;
    drop(runtime);
}

/// Without users: loopback clients act as admin, with no user name; login
/// is refused.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_users_loopback_clients_have_full_rights() {
    let s = Server::start("tank", "nousers").await;
    assert_eq!(
        s.get("/api/me").await,
        json!({"user": null, "role": "admin", "users": false})
    );
    let (code, j) = s
        .call(Method::POST, "/api/login", Some(json!({"user": "a", "password": "b"})))
        .await;
    assert_eq!(code, StatusCode::UNPROCESSABLE_ENTITY, "{j}");
    assert!(j["error"].as_str().expect("error").contains("no users"), "{j}");
    assert_eq!(s.call(Method::POST, "/api/stop", None).await.0, StatusCode::OK);
    s.stop().await;
}

/// A request from `peer`, as the server sees it (the client address
/// comes from the connection).
async fn from(app: &axum::Router, peer: [u8; 4], path: &str, bearer: Option<&str>) -> StatusCode {
    use tower::ServiceExt;
    let mut req = axum::http::Request::get(path)
        .header("host", "127.0.0.1")
        .extension(axum::extract::ConnectInfo(std::net::SocketAddr::from((peer, 40000))));
    if let Some(t) = bearer {
        req = req.header("authorization", format!("Bearer {t}"));
    }
    let res = app
        .clone()
        .oneshot(req.body(axum::body::Body::empty()).expect("request"))
        .await
        .expect("answer");
    StatusCode::from_u16(res.status().as_u16()).expect("status")
}

/// Without users only loopback clients are served, even by a server
/// started on another address despite the rule of `alba run`; with users,
/// a session is what counts, from anywhere.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_users_remote_clients_are_refused() {
    let dir = copy_example("tank", "remote");
    let (st, runtime) = state(&dir, Auth::open());
    let app = alba_server::router(st);
    assert_eq!(from(&app, [127, 0, 0, 1], "/api/status", None).await, StatusCode::OK);
    assert_eq!(
        from(&app, [10, 0, 0, 5], "/api/status", None).await,
        StatusCode::FORBIDDEN
    );
    assert_eq!(from(&app, [10, 0, 0, 5], "/api/ws", None).await, StatusCode::FORBIDDEN);
    drop(runtime);

    add_users(&dir);
    let users = Users::load(&dir).expect("users.toml");
    let auth = Auth::new(Arc::new(users), Limits { idle: IDLE, max: MAX });
    let t = auth
        .login("viewer", PASSWORD, std::net::SocketAddr::from(([10, 0, 0, 5], 1)))
        .await
        .expect("login")
        .token;
    let (st, runtime) = state(&dir, auth);
    let app = alba_server::router(st);
    assert_eq!(
        from(&app, [127, 0, 0, 1], "/api/status", None).await,
        StatusCode::UNAUTHORIZED
    );
    assert_eq!(from(&app, [10, 0, 0, 5], "/api/status", Some(&t)).await, StatusCode::OK);
    drop(runtime);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Waits for the server to close `ws` (1008, "session ended").
async fn closed_for_session<S>(ws: &mut S)
where
    S: futures_util::Stream<
            Item = Result<tokio_tungstenite::tungstenite::Message, tokio_tungstenite::tungstenite::Error>,
        > + Unpin,
{
    use futures_util::StreamExt;
    use tokio_tungstenite::tungstenite::Message;
    let deadline = tokio::time::Instant::now() + Duration::from_secs(10);
    loop {
        let m = tokio::time::timeout_at(deadline, ws.next())
            .await
            .expect("closed within 10 s");
        match m {
            Some(Ok(Message::Close(Some(f)))) => {
                assert_eq!(u16::from(f.code), 1008);
                assert!(f.reason.contains("session ended"), "{}", f.reason);
                return;
            }
            Some(Ok(Message::Close(None))) | None | Some(Err(_)) => panic!("closed without a reason"),
            Some(Ok(_)) => {}
        }
    }
}

/// A WebSocket lives as long as its session: logout or expiry closes it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_websocket_closes_when_its_session_ends() {
    use futures_util::SinkExt;
    let clock = Arc::new(ManualClock::new());
    let (s, runtime) = serve("wsend", clock.clone()).await;
    let open = |t: &str| {
        let mut req = format!("ws://{}/api/ws", s.addr)
            .into_client_request()
            .expect("request");
        req.headers_mut()
            .insert("origin", format!("http://{}", s.addr).parse().expect("header"));
        req.headers_mut()
            .insert("authorization", format!("Bearer {t}").parse().expect("header"));
        req
    };
    // Logout.
    let t = token(&s, "viewer").await;
    let (mut ws, _) = tokio_tungstenite::connect_async(open(&t)).await.expect("connect");
    ws.send(tokio_tungstenite::tungstenite::Message::Text(
        r#"{"subscribe": "*"}"#.into(),
    ))
    .await
    .expect("subscribe");
    assert_eq!(
        call(&s, &Caller::Bearer(t), Method::POST, "/api/logout", None).await.0,
        StatusCode::NO_CONTENT
    );
    closed_for_session(&mut ws).await;
    // Idle expiry: streaming values is not activity.
    let t = token(&s, "viewer").await;
    let (mut ws, _) = tokio_tungstenite::connect_async(open(&t)).await.expect("connect");
    ws.send(tokio_tungstenite::tungstenite::Message::Text(
        r#"{"subscribe": "*"}"#.into(),
    ))
    .await
    .expect("subscribe");
    clock.advance(IDLE);
    closed_for_session(&mut ws).await;
    s.stop().await;
    drop(runtime);
}

/// Over HTTPS (`AppState::https`, set by the TLS setup) the session
/// cookie, and the one that clears it, are `Secure`.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cookies_are_secure_over_https() {
    use tower::ServiceExt;
    let dir = copy_example("tank", "secure");
    add_users(&dir);
    let users = Users::load(&dir).expect("users.toml");
    let (st, runtime) = state(&dir, Auth::new(Arc::new(users), Limits { idle: IDLE, max: MAX }));
    st.https.store(true, std::sync::atomic::Ordering::Relaxed);
    let app = alba_server::router(st);
    let post = |path: &str, body: Json| {
        axum::http::Request::post(path)
            .header("host", "127.0.0.1")
            .header("content-type", "application/json")
            .extension(axum::extract::ConnectInfo(std::net::SocketAddr::from((
                [127, 0, 0, 1],
                40000,
            ))))
            .body(axum::body::Body::from(body.to_string()))
            .expect("request")
    };
    let res = app
        .clone()
        .oneshot(post("/api/login", json!({"user": "viewer", "password": PASSWORD})))
        .await
        .expect("login");
    assert_eq!(res.status().as_u16(), 200);
    let cookie = res
        .headers()
        .get("set-cookie")
        .expect("cookie")
        .to_str()
        .expect("ascii");
    assert!(
        cookie.starts_with("alba_session=") && cookie.ends_with("; HttpOnly; SameSite=Strict; Path=/; Secure"),
        "{cookie}"
    );
    let res = app.oneshot(post("/api/logout", json!({}))).await.expect("logout");
    assert_eq!(res.status().as_u16(), 204);
    let cleared = res
        .headers()
        .get("set-cookie")
        .expect("cookie")
        .to_str()
        .expect("ascii");
    assert!(
        cleared.contains("Max-Age=0") && cleared.ends_with("; Secure"),
        "{cleared}"
    );
    drop(runtime);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `alba user …` while the server runs: within a second, a new user can
/// log in, a removed user's session ends, a changed role applies.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn user_changes_apply_to_a_running_server() {
    let clock = Arc::new(ManualClock::new());
    let (s, runtime) = serve("reload", clock.clone()).await;
    let op = Caller::Bearer(token(&s, "operator").await);
    let viewer = Caller::Bearer(token(&s, "viewer").await);
    let stop = |who: &Caller| {
        let who = who.clone();
        let s = &s;
        async move { call(s, &who, Method::POST, "/api/stop", None).await.0 }
    };
    assert_eq!(stop(&viewer).await, StatusCode::FORBIDDEN);
    let mut users = Users::load(&s.dir).expect("users");
    users.remove("operator").expect("remove");
    users.set_role("viewer", Role::Engineer).expect("role");
    users.add("newbie", Role::Operator, PASSWORD).expect("add");
    users.save(&s.dir).expect("save");
    clock.advance(Duration::from_secs(2));
    let (code, j) = call(&s, &op, Method::GET, "/api/me", None).await;
    assert_eq!(code, StatusCode::UNAUTHORIZED, "a removed user's session ends: {j}");
    assert_eq!(login(&s, "operator", PASSWORD).await.0, StatusCode::UNAUTHORIZED);
    assert_eq!(
        stop(&viewer).await,
        StatusCode::OK,
        "the new role applies to the open session"
    );
    let (code, j) = call(&s, &viewer, Method::GET, "/api/me", None).await;
    assert_eq!((code, &j["role"]), (StatusCode::OK, &json!("engineer")));
    let (code, j) = login(&s, "newbie", PASSWORD).await;
    assert_eq!((code, &j["role"]), (StatusCode::OK, &json!("operator")), "{j}");
    // A users.toml that does not load leaves the store as it was.
    std::fs::write(s.dir.join("users.toml"), "[users.broken\n").expect("write");
    clock.advance(Duration::from_secs(2));
    let (code, j) = call(&s, &viewer, Method::GET, "/api/me", None).await;
    assert_eq!(
        (code, j),
        (
            StatusCode::OK,
            json!({"user": "viewer", "role": "engineer", "users": true})
        )
    );
    assert_eq!(
        call(&s, &Caller::Nobody, Method::GET, "/api/status", None).await.0,
        StatusCode::UNAUTHORIZED,
        "never an empty store (which would open loopback)"
    );
    s.stop().await;
    drop(runtime);
}
