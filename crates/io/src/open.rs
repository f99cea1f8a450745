//! `--io`: the driver a string names, built for a project.

use crate::error::Error;
use crate::{arduino, attach, modbus_master};
use alba_ir::Program;
use alba_model::config::{Config, DEFAULT_SCAN_MS};

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
