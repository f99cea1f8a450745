//! The remote servers `alba run` is a client of (`[[opcua_server]]` of
//! alba.toml, docs/protocols.md "OPC UA client I/O"), as the API shows
//! them: each connection's health in `GET /api/status`, and browsing a
//! server's address space (`GET /api/opcua/{server}/browse`, the studio's
//! tag picker).
//!
//! This crate does not know OPC UA: alba-app implements [`Connections`]
//! over the client's monitor and sets it in `AppState::connections`
//! before serving. Unset: no connections (`connections: []`, browse 404).

use crate::reply::{BrowseNode, Connection};
use std::future::Future;
use std::pin::Pin;

/// Why a browse failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BrowseError {
    /// No server of this name (`404`).
    UnknownServer(String),
    /// The node is not a node id (`400`): the message says so.
    BadNode(String),
    /// The server cannot be reached, refused the session or the browse
    /// (`502`): the message says which server and why (never a password).
    Upstream(String),
}

/// A boxed browse in progress.
pub type Browsing<'a> = Pin<Box<dyn Future<Output = Result<Vec<BrowseNode>, BrowseError>> + Send + 'a>>;

/// The client connections of `alba run`.
pub trait Connections: Send + Sync {
    /// One entry per configured server, in alba.toml's order.
    fn status(&self) -> Vec<Connection>;
    /// The children of `node` (an OPC UA node id) on the OPC UA server named
    /// `server`.
    fn browse<'a>(&'a self, server: &'a str, node: &'a str) -> Browsing<'a>;
}
