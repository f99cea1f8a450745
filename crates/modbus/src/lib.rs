//! Alba's Modbus TCP server (SPEC §9, docs/protocols.md).
//!
//! - [`frame`]: the MBAP codec and request decoder (pure; fuzzed).
//! - [`map`]: OpenPLC v3's address map plus explicit `[modbus.tags]`
//!   addresses, over a snapshot of program memory.
//! - [`server`]: the tokio server: pipelined requests, a connection limit,
//!   an idle timeout, reads from the latest snapshot and writes applied by
//!   the engine thread between two scans.
//!
//! The codec is Alba's own rather than `tokio-modbus`'s server. What the
//! issue asks of the server is mostly framing policy: which malformed input
//! gets which exception reply and which closes the connection, several
//! requests in one segment answered in order, a connection limit, an idle
//! timeout that a trickling client cannot reset, reads straight from the
//! engine's snapshot with no per-request allocation. Owning the ~250 lines
//! of MBAP/PDU code puts every one of those decisions in one place, under
//! unit tests and a fuzz target (`fuzz/`), with no extra dependency.

pub mod frame;
pub mod map;
pub mod offline;
pub mod server;

pub use map::Map;
pub use server::{Server, Settings};
