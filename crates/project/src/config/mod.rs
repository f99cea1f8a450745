//! `alba.toml`'s project tables (SPEC §10.1): what the compiler and the
//! I/O need of the project (its name, scan time, programs, `[board]`,
//! `[ladder]`, `[[plant_model]]`, `[modbus.tags]`, `[[modbus_device]]`),
//! one module per table, each with its types, its raw (serde) form and its
//! checks. The services' tables (`[http]`, `[session]`, `[modbus]`'s server,
//! `[opcua]`, `[mqtt]`, `[history]`, …) belong to `alba-settings`; the
//! TOML reader that turns the file's text into a [`RawConfig`] is
//! `alba-load`'s (ADR 0014: no `toml` under the compiler).

mod board;
mod ladder;
mod modbus;
mod modbus_device;
mod plant;
pub mod setting;

pub use board::Board;
pub use ladder::LadderDialect;
pub use modbus::{AddressError, ModbusArea, ModbusTag};
pub use modbus_device::{
    DEFAULT_POLL_MS, DEFAULT_REFRESH_MS, DEFAULT_RTU_BAUD, DEFAULT_TIMEOUT_MS, DeviceLink, ModbusDevice, ModbusMapping,
};

use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use serde::de::IgnoredAny;
use serde_spanned::Spanned;
use setting::int_setting;

pub const DEFAULT_SCAN_MS: u32 = 10;
pub const MAX_SCAN_MS: u32 = 60_000;

/// The project's tables of `alba.toml`.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub name: String,
    pub description: String,
    pub scan_ms: u32,
    /// Program files in execution order, with where each is listed.
    pub programs: Vec<(String, Span)>,
    /// Plant-model programs, run after `programs` in simulation.
    pub plant: Vec<(String, Span)>,
    pub board: Option<Board>,
    /// `[[plant_model]]`: simulated processes on the I/O.
    pub models: Vec<alba_model::plant::PlantModel>,
    /// `[modbus.tags]`: explicit Modbus addresses of tags outside OpenPLC's
    /// map (the server itself is a service: `alba_settings::Modbus`).
    pub modbus_tags: Vec<ModbusTag>,
    /// `[[modbus_device]]`: remote Modbus slaves polled by `alba run --io
    /// modbus` (docs/protocols.md, "Modbus master I/O"): the project's I/O
    /// wiring, like `[board]`.
    pub modbus_devices: Vec<ModbusDevice>,
    /// `[ladder] dialect`: Logix's semantics or AuroraLD's (docs/ladder.md).
    pub ladder_dialect: LadderDialect,
}

/// `alba.toml` as read by serde, before its checks ([`Config::check`]). The
/// services' tables are skipped here (`alba-settings` reads them); any other
/// key is an error.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // the services' keys, skipped
pub struct RawConfig {
    name: Spanned<String>,
    #[serde(default)]
    description: String,
    scan_ms: Option<Spanned<i64>>,
    programs: Spanned<Vec<Spanned<String>>>,
    #[serde(default)]
    plant: Vec<Spanned<String>>,
    board: Option<board::RawBoard>,
    #[serde(default)]
    plant_model: Vec<plant::RawPlant>,
    modbus: Option<modbus::RawModbusTags>,
    #[serde(default)]
    modbus_device: Vec<Spanned<modbus_device::RawDevice>>,
    ladder: Option<ladder::RawLadder>,
    // The services' tables: alba-settings' (skipped, never read).
    retain_ms: Option<IgnoredAny>,
    runtime: Option<IgnoredAny>,
    history: Option<IgnoredAny>,
    audit: Option<IgnoredAny>,
    alarms: Option<IgnoredAny>,
    opcua: Option<IgnoredAny>,
    opcua_server: Option<IgnoredAny>,
    http: Option<IgnoredAny>,
    session: Option<IgnoredAny>,
    mqtt: Option<IgnoredAny>,
    reports: Option<IgnoredAny>,
}

impl Config {
    /// Checks the project's tables of a parsed `alba.toml`, reporting every
    /// problem found; with bad values the config is returned (with defaults
    /// in their place) so the rest of the project is still checked.
    pub fn check(raw: RawConfig, file: FileId) -> (Config, Vec<Diagnostic>) {
        let mut diags = Vec::new();
        let sp = |r: std::ops::Range<usize>| Span::new(file, r);
        let name = raw.name.get_ref().trim().to_string();
        if name.is_empty() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "the project name is empty",
                sp(raw.name.span()),
                "empty name",
            ));
        }
        let scan_ms = int_setting(
            "scan_ms",
            raw.scan_ms,
            1..=MAX_SCAN_MS,
            DEFAULT_SCAN_MS,
            "milliseconds",
            file,
            &mut diags,
        );
        if raw.programs.get_ref().is_empty() {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                "`programs` is empty",
                sp(raw.programs.span()),
                "expected at least one program file",
            ));
        }
        let listed = |v: Vec<Spanned<String>>| v.into_iter().map(|p| (p.get_ref().clone(), sp(p.span()))).collect();
        let programs = listed(raw.programs.into_inner());
        let plant = listed(raw.plant);
        let board = raw.board.map(|b| board::board(b, file, &mut diags));
        let ladder_dialect = raw
            .ladder
            .map_or(LadderDialect::Logix, |l| ladder::ladder(l, file, &mut diags));
        let models = raw
            .plant_model
            .into_iter()
            .filter_map(|m| m.check(file, &mut diags))
            .collect();
        let modbus_tags = raw.modbus.map_or_else(Vec::new, |m| modbus::tags(m, file, &mut diags));
        let modbus_devices = modbus_device::devices(raw.modbus_device, file, &mut diags);
        let config = Config {
            ladder_dialect,
            modbus_devices,
            models,
            name,
            description: raw.description,
            scan_ms,
            programs,
            plant,
            board,
            modbus_tags,
        };
        (config, diags)
    }
}

/// `alba.toml` read with the `toml` crate, for this crate's tests only (the
/// reader is `alba-load`'s).
#[cfg(test)]
pub(crate) fn parse_for_test(text: &str, file: FileId) -> (Option<Config>, Vec<Diagnostic>) {
    match toml::from_str::<RawConfig>(text) {
        Ok(raw) => {
            let (c, d) = Config::check(raw, file);
            (Some(c), d)
        }
        Err(e) => (
            None,
            vec![Diagnostic::new(
                Code::ConfigField,
                e.message().trim().to_string(),
                Span::new(file, e.span().unwrap_or(0..0)),
                "here",
            )],
        ),
    }
}
