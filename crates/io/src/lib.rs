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
pub mod firmware;
mod link;
pub mod modbus_master;
pub mod serial;

use alba_ir::Program;
use alba_model::config::{Config, DEFAULT_SCAN_MS};

/// Why an I/O driver cannot be opened.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// `--io` names no driver.
    #[error(
        "unknown I/O driver `{0}` (available: sim, arduino:<serial port>[,link=modbus|aurora,…], board:<serial port>, modbus)"
    )]
    UnknownDriver(String),
    /// The driver's options are wrong (the message names the option).
    #[error("{0}")]
    Options(String),
    /// `--io modbus` with no slave to poll.
    #[error("--io modbus: alba.toml has no [[modbus_device]] (see docs/protocols.md, \"Modbus master I/O\")")]
    NoModbusDevices,
    /// `--io board:`: the program cannot be exported to the board.
    #[error("this project cannot run on the board: {0}")]
    NotForBoard(String),
    /// The driver's link thread could not be started.
    #[error("cannot start {what}: {source}")]
    Thread {
        what: &'static str,
        #[source]
        source: std::io::Error,
    },
}

/// The I/O an `--io` string names, for `program` of the project configured
/// by `config` (its `[board]`, `[[modbus_device]]` and `scan_ms`):
///
/// - `sim`: the simulated I/O of the runtime;
/// - `arduino:<serial port>[,option=value…]`: a remote-I/O board ([`arduino`]);
/// - `board:<serial port>[,option=value…]`: a board running the exported
///   sketch ([`attach`]);
/// - `modbus`: the `[[modbus_device]]` slaves ([`modbus_master`]).
///
/// Drivers that own a link start its thread here; a board or slave that is
/// not reachable yet is a status (`S:IOOK`), not an error.
pub fn open(spec: &str, config: Option<&Config>, program: &Program) -> Result<Box<dyn alba_runtime::Io>, Error> {
    let board = config.and_then(|c| c.board.as_ref());
    match spec {
        "sim" => Ok(Box::new(alba_runtime::SimIo)),
        "modbus" => modbus_master::driver(config.map(|c| c.modbus_devices.as_slice()).unwrap_or_default()),
        s if s.starts_with("arduino:") => arduino::driver(s, board),
        s if s.starts_with("board:") => {
            let target = alba_arduino::sketch::Target {
                model: board.map_or(alba_model::board::Model::Nano, |b| b.model),
                map: board.map_or_else(
                    || alba_model::board::PinMap::preset("aurora").unwrap_or_default(),
                    |b| b.map.clone(),
                ),
                active_low: board.is_some_and(|b| b.active_low),
                scan_ms: config.map_or(DEFAULT_SCAN_MS, |c| c.scan_ms),
                monitor: true,
                power_up_on: board.map_or_else(Vec::new, |b| b.power_up_on.clone()),
            };
            attach::driver(s, program, &target)
        }
        other => Err(Error::UnknownDriver(other.to_string())),
    }
}
