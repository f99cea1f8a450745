//! I/O drivers of the runtime (the `alba_runtime::Io` seam).
//!
//! - [`open`]: the driver an `--io` string names (`sim`, `arduino:…`,
//!   `board:…`, `modbus`), for `alba run`.
//! - [`firmware`]: generates the remote-I/O firmware of an Arduino board
//!   (`alba firmware`): a Modbus RTU slave or the AuroraLD text link.
//! - [`serial`]: the serial line to a board: its options, channel counts,
//!   and Modbus RTU transactions (framed by `alba_modbus_proto::rtu`).
//! - [`arduino`]: the host driver, `alba run --io arduino:<port>`: a link
//!   thread owns the serial port and polls the board (Modbus RTU, or the
//!   AuroraLD text link of [`aurora`]); the engine thread only exchanges
//!   the latest images with it and never waits on the port.
//! - [`modbus_master`]: `alba run --io modbus`: Alba polls the Modbus TCP
//!   and RTU slaves of `[[modbus_device]]` as its I/O.
//! - [`attach`]: `alba run --io board:<port>`: the board runs the exported
//!   sketch and the runtime mirrors its memory over the monitoring link.
//!
//! Every Modbus frame is encoded and decoded by `alba-modbus-proto`.

pub mod arduino;
pub mod attach;
pub mod aurora;
pub mod download;
mod error;
pub mod firmware;
mod link;
pub mod modbus_master;
mod open;
pub mod serial;

pub use error::Error;
pub use open::open;
