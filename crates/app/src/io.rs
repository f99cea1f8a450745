//! The I/O driver of `--io`.
//!
//! To move into crates/io as `alba_io::open(spec, config, program)` (same
//! shape); `run` then calls that instead.

use alba_ir::Program;
use alba_model::config::Config;
use alba_runtime::Io;

/// The driver `spec` names, set up from the project's configuration.
pub(crate) fn open(spec: &str, config: Option<&Config>, program: &Program) -> Result<Box<dyn Io>, String> {
    let board = config.and_then(|c| c.board.as_ref());
    match spec {
        "sim" => Ok(Box::new(alba_runtime::SimIo)),
        arduino if arduino.starts_with("arduino:") => alba_io::arduino::driver(arduino, board),
        "modbus" => {
            let devices = config.map(|c| c.modbus_devices.as_slice()).unwrap_or_default();
            alba_io::modbus_master::driver(devices)
        }
        attach if attach.starts_with("board:") => {
            let target = alba_arduino::sketch::Target {
                model: board.map_or(alba_model::board::Model::Nano, |b| b.model),
                map: board.map_or_else(
                    || alba_model::board::PinMap::preset("aurora").unwrap_or_default(),
                    |b| b.map.clone(),
                ),
                active_low: board.is_some_and(|b| b.active_low),
                scan_ms: config.map_or(alba_model::config::DEFAULT_SCAN_MS, |c| c.scan_ms),
                monitor: true,
                power_up_on: board.map_or_else(Vec::new, |b| b.power_up_on.clone()),
            };
            alba_io::attach::driver(attach, program, &target)
        }
        other => Err(format!(
            "unknown I/O driver `{other}` (available: sim, arduino:<serial port>[,link=modbus|aurora,…], board:<serial port>, modbus)"
        )),
    }
}
