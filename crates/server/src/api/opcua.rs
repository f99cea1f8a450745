//! `GET /api/opcua/{server}/browse?node=<node id>`: the children of a node
//! of a remote OPC UA server `alba run` is a client of (`[[opcua_server]]`),
//! for the studio's tag picker.

use crate::connections::BrowseError;
use crate::error::{ApiError, ApiResult};
use crate::reply::OpcuaBrowse;
use crate::state::AppState;
use axum::Json;
use axum::extract::{Path, Query, State};
use std::collections::HashMap;
use std::sync::Arc;

/// The Objects folder: where a browse starts.
pub const OBJECTS: &str = "i=85";

/// Engineer (`ROUTE_ROLES`). `404` for a server not in alba.toml, `502`
/// when it cannot be reached or refuses (the message says why).
pub async fn browse(
    State(st): State<Arc<AppState>>,
    Path(server): Path<String>,
    Query(q): Query<HashMap<String, String>>,
) -> ApiResult<Json<OpcuaBrowse>> {
    let node = q
        .get("node")
        .map(|n| n.trim())
        .filter(|n| !n.is_empty())
        .unwrap_or(OBJECTS)
        .to_string();
    if let Some(k) = q.keys().find(|k| k.as_str() != "node") {
        return Err(ApiError::Malformed(format!(
            "unknown query parameter `{k}` (only `node`)"
        )));
    }
    let unknown = || ApiError::NotFound(format!("no [[opcua_server]] named `{server}` in alba.toml"));
    let Some(c) = st.connections.get() else {
        return Err(unknown());
    };
    match c.browse(&server, &node).await {
        Ok(children) => Ok(Json(OpcuaBrowse { server, node, children })),
        Err(BrowseError::UnknownServer(_)) => Err(unknown()),
        Err(BrowseError::BadNode(m)) => Err(ApiError::Malformed(m)),
        Err(BrowseError::Upstream(m)) => Err(ApiError::Upstream(m)),
    }
}
