//! The studio's HTTP/WebSocket API (docs/api.md) over the real-time
//! runtime, and the embedded browser studio. `alba run` (crates/app)
//! builds an [`AppState`] and serves [`router`].
//!
//! Handlers never touch program memory: they read the runtime's latest
//! snapshot and send requests the engine thread applies between scans.
//! Project edits (program text, tags.csv) are serialised by one lock,
//! compiled in full before anything is saved, saved atomically, applied
//! online by swapping the program between two scans, and announced to
//! other services on [`AppState::edits`].
//!
//! Add a route: a handler in `api/<area>.rs` answering a type of
//! `reply.rs` (listed in `reply::typescript`; then `UPDATE_BINDINGS=1
//! cargo test -p alba-server contract` regenerates web/src/api.gen.ts),
//! and one `.route` line below; a route that is not a plain read gets
//! its role in [`ROUTE_ROLES`].
//!
//! Every request passes `gate::session` first: the session (cookie or
//! bearer token) and the role its route needs (docs/security.md,
//! "Sessions and roles"). The server is served with connect info
//! (`into_make_service_with_connect_info::<SocketAddr>()`): the layer
//! needs the client's address.

mod api;
mod assets;
pub mod auth;
pub mod connections;
pub mod error;
mod gate;
pub mod guard;
pub mod hardware;
mod lang;
pub mod project;
pub mod reply;
mod state;
pub mod tags;
pub mod verify;
mod ws;

pub use alba_control::now_ms;
/// The shift report as a file (`alba run`'s scheduled reports, `[reports]`).
pub use api::reports::render as render_shift_report;
pub use auth::{Role, Who};
pub use error::ApiError;
pub use state::{AppState, Edited};

use api::{
    FILE_BODY, SMALL_BODY, alarms, audit, domain, forces, history, images, nets, opcua, programs, recipes, reports,
    screens, session, status, trends,
};
use auth::Access::{Public, Role as Needs};
use axum::Router;
use axum::extract::DefaultBodyLimit;
use axum::routing::{any, get, post, put};
use std::sync::Arc;

/// The role each route needs (method, route as written in [`router`]):
/// the one place where routes meet roles (docs/api.md, "Roles"). A route
/// not listed needs `viewer` for GET (and HEAD) and `admin` for anything
/// else; paths outside `/api` (the studio's files) are public.
pub const ROUTE_ROLES: &[(&str, &str, auth::Access)] = &[
    ("POST", "/api/login", Public),
    ("POST", "/api/logout", Public),
    ("PUT", "/api/tags/{name}", Needs(Role::Operator)),
    ("POST", "/api/run", Needs(Role::Engineer)),
    ("POST", "/api/stop", Needs(Role::Engineer)),
    ("POST", "/api/step", Needs(Role::Engineer)),
    ("POST", "/api/nets/{name}/reset", Needs(Role::Engineer)),
    // Seconds of CPU and up to ANALYSIS_MEMORY: for those who edit nets.
    ("POST", "/api/nets/{name}/analysis", Needs(Role::Engineer)),
    ("DELETE", "/api/forces", Needs(Role::Engineer)),
    ("PUT", "/api/forces/{name}", Needs(Role::Engineer)),
    ("DELETE", "/api/forces/{name}", Needs(Role::Engineer)),
    ("PUT", "/api/programs/{name}", Needs(Role::Engineer)),
    ("POST", "/api/check/{name}", Needs(Role::Engineer)),
    ("PUT", "/api/tags.csv", Needs(Role::Engineer)),
    ("POST", "/api/alarms/{id}/ack", Needs(Role::Operator)),
    ("POST", "/api/alarms/{id}/shelve", Needs(Role::Operator)),
    ("POST", "/api/alarms/{id}/unshelve", Needs(Role::Operator)),
    ("POST", "/api/alarms/{id}/out_of_service", Needs(Role::Engineer)),
    ("PUT", "/api/trends", Needs(Role::Operator)),
    ("PUT", "/api/screens/{name}", Needs(Role::Engineer)),
    ("POST", "/api/screens/{name}/check", Needs(Role::Engineer)),
    ("PUT", "/api/symbols/{name}", Needs(Role::Engineer)),
    ("POST", "/api/pid/{name}/autotune", Needs(Role::Engineer)),
    ("GET", "/api/audit", Needs(Role::Engineer)),
    ("GET", "/api/audit.csv", Needs(Role::Engineer)),
    // Browsing opens sessions on a remote server as `alba run`'s client: for
    // those who bind tags to it.
    ("GET", "/api/opcua/{server}/browse", Needs(Role::Engineer)),
    // The board: alba.toml's [board], firmware builds, the serial ports.
    ("PUT", "/api/hardware/board", Needs(Role::Engineer)),
    ("POST", "/api/hardware/board/undo", Needs(Role::Engineer)),
    ("POST", "/api/hardware/build", Needs(Role::Engineer)),
    ("POST", "/api/hardware/download", Needs(Role::Engineer)),
    ("POST", "/api/hardware/upload", Needs(Role::Engineer)),
    ("POST", "/api/hardware/identify", Needs(Role::Engineer)),
    ("POST", "/api/hardware/verify", Needs(Role::Engineer)),
    ("POST", "/api/hardware/jobs/{id}/cancel", Needs(Role::Engineer)),
    ("POST", "/api/hardware/attach", Needs(Role::Engineer)),
    ("POST", "/api/hardware/detach", Needs(Role::Engineer)),
    // Proofs and test tables: seconds of CPU, like a net analysis.
    ("POST", "/api/verify", Needs(Role::Engineer)),
    ("POST", "/api/tests", Needs(Role::Engineer)),
    // Images of the screens (hmi/assets/).
    ("PUT", "/api/assets/{name}", Needs(Role::Engineer)),
    // Recipes: saved by those who edit the project, applied by operators.
    ("PUT", "/api/recipes/{name}", Needs(Role::Engineer)),
    ("POST", "/api/recipes/{name}/apply", Needs(Role::Operator)),
    ("POST", "/api/recipes/{name}/capture", Needs(Role::Engineer)),
    // Unknown endpoints: 404 for anyone logged in.
    ("*", "/api/{*rest}", Needs(Role::Viewer)),
];

/// The router: the API under `/api`, the studio at `/`, all behind the
/// browser-attack guard, the timeout and the session check (`gate.rs`).
pub fn router(state: Arc<AppState>) -> Router {
    let files = Router::new()
        .route("/api/programs/{name}", get(programs::get).put(programs::put))
        .route("/api/check/{name}", post(programs::check))
        .route("/api/tags.csv", get(programs::get_tags_csv).put(programs::put_tags_csv))
        .route("/api/screens/{name}", get(screens::get).put(screens::put))
        .route("/api/screens/{name}/check", post(screens::check_screen))
        .route("/api/symbols/{name}", get(screens::get_symbol).put(screens::put_symbol))
        .route("/api/recipes/{name}", get(recipes::get).put(recipes::put))
        .layer(DefaultBodyLimit::max(FILE_BODY));
    let images = Router::new()
        .route("/api/assets/{name}", get(images::get).put(images::put))
        .layer(DefaultBodyLimit::max(images::ASSET_BODY));
    Router::new()
        .route("/api/login", post(session::login))
        .route("/api/logout", post(session::logout))
        .route("/api/me", get(session::me))
        .route("/api/status", get(status::get))
        .route("/api/run", post(status::run))
        .route("/api/stop", post(status::stop))
        .route("/api/step", post(status::step))
        .route("/api/tags", get(api::tags::list))
        .route("/api/tags/{name}", get(api::tags::get).put(api::tags::put))
        .route("/api/tags/{name}/uses", get(api::tags::uses))
        .route("/api/forces", get(forces::list).delete(forces::delete_all))
        .route("/api/forces/{name}", put(forces::put).delete(forces::delete))
        .route("/api/programs", get(programs::list))
        .route("/api/nets/{name}/analysis", post(nets::analysis))
        .route("/api/nets/{name}/reset", post(nets::reset))
        .route("/api/pid/{name}/autotune", post(api::pid::autotune))
        .route("/api/instructions", get(domain::instructions))
        .route("/api/domain", get(domain::get))
        .route("/api/ws", get(ws::upgrade))
        .route("/api/history/nodes", get(history::nodes))
        .route("/api/history/tags", get(history::list))
        .route("/api/history/raw", get(history::raw))
        .route("/api/history", get(history::query))
        .route("/api/history.csv", get(history::csv))
        .route("/api/alarms", get(alarms::list))
        .route("/api/alarms/log.csv", get(alarms::log_csv))
        .route("/api/alarms/stats", get(alarms::stats))
        .route("/api/alarms/{id}/ack", post(alarms::ack))
        .route("/api/alarms/{id}/shelve", post(alarms::shelve))
        .route("/api/alarms/{id}/unshelve", post(alarms::unshelve))
        .route("/api/alarms/{id}/out_of_service", post(alarms::out_of_service))
        .route("/api/trends", get(trends::get).put(trends::put))
        .route("/api/screens", get(screens::list))
        .route("/api/symbols", get(screens::list_symbols))
        .route("/api/audit", get(audit::list))
        .route("/api/audit.csv", get(audit::csv))
        .route("/api/opcua/{server}/browse", get(opcua::browse))
        .route("/api/hardware", get(api::hardware::get))
        .route("/api/hardware/board", put(api::hardware::put_board))
        .route("/api/hardware/board/undo", post(api::hardware::undo_board))
        .route("/api/hardware/build", post(api::hardware::build))
        .route("/api/hardware/download", post(api::hardware::download))
        .route("/api/hardware/upload", post(api::hardware::upload))
        .route("/api/hardware/identify", post(api::hardware::identify))
        .route("/api/hardware/verify", post(api::hardware::verify))
        .route("/api/hardware/jobs/{id}", get(api::hardware::job))
        .route("/api/hardware/jobs/{id}/cancel", post(api::hardware::cancel))
        .route("/api/hardware/attach", post(api::hardware::attach))
        .route("/api/hardware/detach", post(api::hardware::detach))
        .route("/api/verify", post(api::verify::verify))
        .route("/api/tests", post(api::verify::tests))
        .route("/api/recipes", get(recipes::list))
        .route("/api/assets", get(images::list))
        .route("/api/reports/shift.xlsx", get(reports::xlsx))
        .route("/api/reports/shift.pdf", get(reports::pdf))
        .route("/api/recipes/{name}/apply", post(recipes::apply))
        .route("/api/recipes/{name}/capture", post(recipes::capture))
        .route("/api/{*rest}", any(api::fallback))
        .layer(DefaultBodyLimit::max(SMALL_BODY))
        .merge(files)
        .merge(images)
        .fallback(assets::serve)
        .layer(axum::middleware::from_fn_with_state(state.clone(), gate::session))
        .layer(axum::middleware::from_fn_with_state(state.clone(), gate::timeout))
        .layer(axum::middleware::from_fn_with_state(state.clone(), gate::guard))
        .layer(axum::middleware::from_fn(lang::language))
        .with_state(state)
}

/// Routes whose work may outlast `[http] request_timeout_s`, and how long
/// each may take (the request timeout when that is longer): a firmware build
/// runs avr-gcc (the Arduino core too, the first time), proofs and test
/// tables run their searches and scans ([`gate::timeout`]).
pub const LONG_ROUTES: &[(&str, std::time::Duration)] = &[
    ("/api/hardware/build", std::time::Duration::from_secs(600)),
    ("/api/verify", std::time::Duration::from_secs(600)),
    ("/api/tests", std::time::Duration::from_secs(600)),
];
