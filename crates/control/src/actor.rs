//! Who acts: a user with a role, or a door's own identity.

use crate::Refused;
use alba_audit::{Action, Entry};
use alba_auth::Role;

/// The door an action came through (the audit row's `via`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Via {
    /// The HTTP API and its WebSocket.
    Http,
    Mqtt,
    Opcua,
    Modbus,
}

impl Via {
    /// The stored name: `http`, `mqtt`, `opcua`, `modbus`.
    pub fn name(self) -> &'static str {
        match self {
            Via::Http => "http",
            Via::Mqtt => "mqtt",
            Via::Opcua => "opcua",
            Via::Modbus => "modbus",
        }
    }
}

impl std::fmt::Display for Via {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Who asks for an action, as its audit row names them and as the rules
/// judge them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Actor {
    /// The door.
    pub via: Via,
    /// The user's name (an HTTP session, an OPC UA user, `[mqtt] user`), or
    /// the door's identity (`modbus:<peer>`, `opcua:anonymous`); `None`: no
    /// users are configured (HTTP on loopback).
    pub user: Option<String>,
    /// What it may do.
    pub role: Role,
    /// Where from: the client's address (`ip:port`), or the broker's for MQTT.
    pub peer: Option<String>,
}

impl Actor {
    /// A user of the HTTP API (`user` `None`: no users are configured).
    pub fn http(user: Option<String>, role: Role, peer: Option<std::net::SocketAddr>) -> Actor {
        Actor {
            via: Via::Http,
            user,
            role,
            peer: peer.map(|a| a.to_string()),
        }
    }

    /// A Modbus TCP client: Modbus has no users, so the client is known by
    /// its address (`modbus:<peer>`); its role is the server's (`viewer`
    /// when `[modbus] read_only`, else `operator`).
    pub fn modbus(peer: std::net::SocketAddr, role: Role) -> Actor {
        Actor {
            via: Via::Modbus,
            user: Some(format!("modbus:{peer}")),
            role,
            peer: Some(peer.to_string()),
        }
    }

    /// An OPC UA session: its user (`opcua:<user>`, `opcua:anonymous`) and role.
    pub fn opcua(user: Option<&str>, role: Role, peer: Option<String>) -> Actor {
        Actor {
            via: Via::Opcua,
            user: Some(format!("opcua:{}", user.unwrap_or("anonymous"))),
            role,
            peer,
        }
    }

    /// The MQTT bridge: its account (`[mqtt] user`, else `mqtt`) and that
    /// account's role; the peer is the broker.
    pub fn mqtt(account: &str, role: Role, broker: String) -> Actor {
        Actor {
            via: Via::Mqtt,
            user: Some(account.to_string()),
            role,
            peer: Some(broker),
        }
    }

    /// The actor's name in messages: the user, else the door.
    pub fn name(&self) -> String {
        self.user.clone().unwrap_or_else(|| format!("{} client", self.via))
    }

    /// Refused unless the role includes `needed`, for `what` ("writing tags").
    pub fn needs(&self, needed: Role, what: &'static str) -> Result<(), Refused> {
        if self.role.allows(needed) {
            Ok(())
        } else {
            Err(Refused::Role {
                actor: self.name(),
                role: self.role,
                needed,
                what,
            })
        }
    }

    /// An audit entry of `action` by this actor, now.
    pub fn entry(&self, action: Action) -> Entry {
        Entry {
            user: self.user.clone(),
            addr: self.peer.clone(),
            via: Some(self.via.name().to_string()),
            ..Entry::new(crate::now_ms(), action)
        }
    }
}
