//! `--io`: the driver a string names, built for a project.

use crate::error::Error;
use crate::{arduino, attach, modbus_master};
use alba_ir::Program;
use alba_project::config::{Config, DEFAULT_SCAN_MS};

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

#[cfg(test)]
mod tests {
    use super::*;

    fn example(name: &str) -> (Program, Option<Config>) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples")
            .join(name);
        let c = alba_load::compile_dir(&dir);
        let program = c.program.unwrap_or_else(|| panic!("{name}: {:?}", c.diagnostics));
        (program, c.project.config)
    }

    #[test]
    fn the_io_string_names_the_driver() {
        let (program, config) = example("start-stop");
        let open = |spec: &str| open(spec, config.as_ref(), &program);
        assert_eq!(open("sim").map(|io| io.name().to_string()).ok().as_deref(), Some("sim"));
        let e = open("can:0").err();
        assert!(matches!(&e, Some(Error::UnknownDriver(s)) if s == "can:0"), "{e:?}");
        assert!(e.is_some_and(|e| {
            e.to_string()
                .starts_with("unknown I/O driver `can:0` (available: sim, arduino:")
        }));
        assert!(matches!(open("modbus").err(), Some(Error::NoModbusDevices)));
        assert!(matches!(open("modbus").err(), Some(e) if e.to_string().contains("no [[modbus_device]]")));
        let e = open("arduino:/dev/x,speed=1").err();
        assert!(
            matches!(&e, Some(Error::Options(m)) if m.contains("unknown option `speed`")),
            "{e:?}"
        );
        assert!(matches!(open("board:").err(), Some(Error::Options(m)) if m.contains("the port is missing")));
    }
}
