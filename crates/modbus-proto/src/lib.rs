//! Alba's Modbus protocol, without I/O (SPEC §9, docs/protocols.md): pure
//! functions over byte slices and program memory, shared by the Modbus TCP
//! server (`alba-modbus`), the Modbus master and Arduino drivers
//! (`alba-io`), the compiler's check of `[modbus.tags]` and the fuzz
//! target (`fuzz/fuzz_targets/modbus_frame.rs`).
//!
//! - [`pdu`]: the PDU codec in both directions: requests decoded and
//!   encoded, replies encoded and decoded, exceptions. Adding a function
//!   code starts here.
//! - [`mbap`]: Modbus TCP framing (the MBAP header).
//! - [`rtu`]: Modbus RTU framing (serial lines) with its CRC-16.
//! - [`map`]: OpenPLC v3's address map plus explicit `[modbus.tags]`
//!   addresses, over a snapshot of program memory.
//! - [`handler`]: the server's answer to a decoded request (reads from
//!   memory, writes checked and planned).
//! - [`offline`]: a byte stream answered like the server does, without
//!   sockets: the fuzz target's harness and its sample map.
//!
//! The codec is Alba's own rather than `tokio-modbus`'s. What the server
//! needs is mostly framing policy: which malformed input gets which
//! exception reply and which closes the connection, several requests in one
//! segment answered in order, reads straight from the engine's snapshot with
//! no per-request allocation. Owning the PDU and MBAP code puts every one of
//! those decisions in one place, under unit tests and a fuzz target, with no
//! extra dependency.

pub mod handler;
pub mod map;
pub mod mbap;
pub mod offline;
pub mod pdu;
pub mod rtu;

pub use map::Map;
pub use pdu::{Exception, FrameError, Request, Response};
