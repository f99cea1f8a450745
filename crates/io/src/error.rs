//! The errors of opening an I/O driver.

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
