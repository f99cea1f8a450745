//! I/O drivers of the runtime (the `alba_runtime::Io` seam).
//!
//! - [`modbus`]: the Modbus RTU codec (CRC-16, request and response frames)
//!   shared by the host driver and the tests.
//! - [`firmware`]: generates the remote-I/O firmware of an Arduino board
//!   (`alba firmware`): a Modbus RTU slave or the AuroraLD text link.
//! - [`arduino`]: the host driver, `alba run --io arduino:<port>`: a link
//!   thread owns the serial port and polls the board; the engine thread
//!   only exchanges the latest images with it and never waits on the port.
//! - [`modbus_master`]: `alba run --io modbus`: Alba polls the Modbus TCP
//!   slaves of `[[modbus_device]]` as its I/O.
//! - [`attach`]: `alba run --io board:<port>`: the board runs the exported
//!   sketch and the runtime mirrors its memory over the monitoring link.

pub mod arduino;
pub mod attach;
pub mod aurora;
pub mod firmware;
mod link;
pub mod modbus;
pub mod modbus_master;
