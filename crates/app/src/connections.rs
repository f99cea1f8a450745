//! The API's view of `alba run`'s client connections: alba-server's
//! [`Connections`] over the OPC UA client's monitor (`[[opcua_server]]`)
//! and the MQTT client's counters, together in [`All`].

use alba_opcua::client::{BrowseError, Monitor};
use alba_server::connections::{self, Browsing, Connections};
use alba_server::reply::{BrowseNode, Connection};
use std::sync::Arc;

/// Every client connection, in this order: the OPC UA servers, the broker.
pub(crate) struct All(pub Vec<Arc<dyn Connections>>);

impl Connections for All {
    fn status(&self) -> Vec<Connection> {
        self.0.iter().flat_map(|c| c.status()).collect()
    }

    fn browse<'a>(&'a self, server: &'a str, node: &'a str) -> Browsing<'a> {
        Box::pin(async move {
            for c in &self.0 {
                match c.browse(server, node).await {
                    Err(connections::BrowseError::UnknownServer(_)) => continue,
                    r => return r,
                }
            }
            Err(connections::BrowseError::UnknownServer(server.to_string()))
        })
    }
}

pub(crate) struct OpcuaConnections(pub Monitor);

impl Connections for OpcuaConnections {
    fn status(&self) -> Vec<Connection> {
        let endpoints = self.0.servers();
        self.0
            .status()
            .into_iter()
            .zip(endpoints)
            .map(|((name, s), (_, endpoint))| Connection {
                name,
                protocol: "opcua".into(),
                endpoint,
                ok: s.ok,
                connected: s.connected,
                connects: s.connects,
                errors: s.errors,
                last_error: s.last_error,
                queue: None,
            })
            .collect()
    }

    fn browse<'a>(&'a self, server: &'a str, node: &'a str) -> Browsing<'a> {
        Box::pin(async move {
            match self.0.browse(server, node).await {
                Ok(children) => Ok(children
                    .into_iter()
                    .map(|c| BrowseNode {
                        node: c.node,
                        node_uri: c.node_uri,
                        browse_name: c.browse_name,
                        display_name: c.display_name,
                        class: c.class,
                        data_type: c.data_type,
                    })
                    .collect()),
                Err(BrowseError::UnknownServer(n)) => Err(connections::BrowseError::UnknownServer(n)),
                Err(e @ BrowseError::BadNode(_)) => Err(connections::BrowseError::BadNode(e.to_string())),
                Err(BrowseError::Server(m)) => Err(connections::BrowseError::Upstream(m)),
            }
        })
    }
}
