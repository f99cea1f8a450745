//! Alba's Modbus TCP server (SPEC §9, docs/protocols.md): the tokio
//! server over the real-time runtime — pipelined requests, a connection
//! limit, an idle timeout, reads from the latest snapshot and writes
//! applied by the engine thread between two scans.
//!
//! The protocol itself (PDU codec, MBAP framing, OpenPLC's address map and
//! the answer to each request) is `alba-modbus-proto`, without I/O; this
//! crate adds the sockets, the connections and the runtime.

pub mod server;

/// The control layer the server writes through (re-exported for its users).
pub use alba_control::Control;
pub use server::{NotLoopback, Server, Settings, check_listen, exception};
