//! `alba.toml`, the project settings (SPEC §10.1): one module per table,
//! each with its types, its raw (serde) form and its checks; this module
//! holds the top level and [`Config::parse`].

mod board;
mod history;
mod http;
mod ladder;
mod modbus;
mod modbus_device;
mod mqtt;
mod opcua;
mod opcua_server;
mod plant;
mod retention;
mod runtime;
mod session;
mod setting;
#[cfg(test)]
mod tests;

pub use board::Board;
pub use history::{DEFAULT_BUFFER_MAX_SAMPLES, History, HistoryBackend, OnDamage};
pub use http::{Http, parse_origin, split_authority};
pub use ladder::LadderDialect;
pub use modbus::{DEFAULT_MODBUS_CONNECTIONS, DEFAULT_MODBUS_IDLE_S, IpRange, Modbus, ModbusArea, ModbusTag};
pub use modbus_device::{
    DEFAULT_POLL_MS, DEFAULT_REFRESH_MS, DEFAULT_RTU_BAUD, DEFAULT_TIMEOUT_MS, DeviceLink, ModbusDevice, ModbusMapping,
};
pub use mqtt::{Mqtt, MqttVersion, Sparkplug, is_host_port};
pub use opcua::{Opcua, OpcuaUser, check_password_hash};
pub use opcua_server::{
    DEFAULT_CLIENT_PKI, DEFAULT_PUBLISHING_INTERVAL_MS, Direction, OpcuaBinding, OpcuaServer, SecurityMode,
    SecurityPolicy, is_node_id,
};
pub use retention::{Alarms, Audit, Retention};
pub use runtime::{OnRetainError, Runtime};
pub use session::{DEFAULT_IDLE_MINUTES, DEFAULT_MAX_HOURS, Session};

use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use setting::int_setting;
use toml::Spanned;

pub const DEFAULT_SCAN_MS: u32 = 10;
pub const MAX_SCAN_MS: u32 = 60_000;
pub const DEFAULT_RETAIN_MS: u32 = 1_000;

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
    /// How often `alba run` saves retentive data (also on stop).
    pub retain_ms: u32,
    /// `[runtime]`: what to do with a retain file that cannot be used.
    pub runtime: Runtime,
    pub history: History,
    /// `[audit]`: the audit trail's retention (docs/audit.md).
    pub audit: Audit,
    /// `[alarms]`: the alarm log's retention (docs/alarms.md).
    pub alarms: Alarms,
    /// `[[plant_model]]`: simulated processes on the I/O.
    pub models: Vec<alba_model::plant::PlantModel>,
    /// `[modbus]`: the Modbus TCP server of `alba run` (docs/protocols.md).
    pub modbus: Option<Modbus>,
    /// `[opcua]`: the OPC UA server of `alba run` (docs/protocols.md).
    pub opcua: Option<Opcua>,
    /// `[[modbus_device]]`: remote Modbus slaves polled by `alba run --io
    /// modbus` (docs/protocols.md, "Modbus master I/O").
    pub modbus_devices: Vec<ModbusDevice>,
    /// `[[opcua_server]]`: remote OPC UA servers bound to tags (`alba run`
    /// connects to them; docs/protocols.md, "OPC UA client I/O").
    pub opcua_servers: Vec<OpcuaServer>,
    /// `[http]`: the studio's listener (docs/security.md).
    pub http: Http,
    /// `[session]`: how long a login to the HTTP API lasts.
    pub session: Session,
    /// `[mqtt]`: the MQTT client of `alba run` (docs/scale-out.md).
    pub mqtt: Option<Mqtt>,
    /// `[ladder] dialect`: Logix's semantics or AuroraLD's (docs/ladder.md).
    pub ladder_dialect: LadderDialect,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    name: Spanned<String>,
    #[serde(default)]
    description: String,
    scan_ms: Option<Spanned<i64>>,
    programs: Spanned<Vec<Spanned<String>>>,
    #[serde(default)]
    plant: Vec<Spanned<String>>,
    board: Option<board::RawBoard>,
    retain_ms: Option<Spanned<i64>>,
    runtime: Option<runtime::RawRuntime>,
    history: Option<history::RawHistory>,
    audit: Option<retention::RawRetention>,
    alarms: Option<retention::RawRetention>,
    #[serde(default)]
    plant_model: Vec<plant::RawPlant>,
    modbus: Option<modbus::RawModbus>,
    opcua: Option<opcua::RawOpcua>,
    #[serde(default)]
    modbus_device: Vec<Spanned<modbus_device::RawDevice>>,
    #[serde(default)]
    opcua_server: Vec<Spanned<opcua_server::RawServer>>,
    http: Option<http::RawHttp>,
    session: Option<session::RawSession>,
    mqtt: Option<mqtt::RawMqtt>,
    ladder: Option<ladder::RawLadder>,
}

/// `s` as a TOML string (quoted and escaped), for writing alba.toml.
pub fn toml_string(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

impl Config {
    /// Parses and validates `alba.toml`, reporting every problem found. The
    /// config is `None` only when the file could not be read as settings at
    /// all; with bad values it is returned (with defaults in their place) so
    /// the rest of the project is still checked.
    pub fn parse(text: &str, file: FileId) -> (Option<Config>, Vec<Diagnostic>) {
        let raw: RawConfig = match toml::from_str(text) {
            Ok(r) => r,
            Err(e) => {
                let span = Span::new(file, e.span().unwrap_or(0..0));
                let msg = e.message().trim().to_string();
                let code = if msg.contains("missing field")
                    || msg.contains("unknown field")
                    || msg.contains("unknown variant")
                    || msg.contains("invalid type")
                {
                    Code::ConfigField
                } else {
                    Code::TomlSyntax
                };
                let mut d = Diagnostic::new(code, format!("alba.toml: {msg}"), span, "here");
                if msg.contains("missing field") {
                    d = d.with_help(
                        "the minimal alba.toml is: name = \"tank\"  scan_ms = 10  programs = [\"main.lad\"]",
                    );
                }
                return (None, vec![d]);
            }
        };
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
        // An integer setting within `range`, or the default with a diagnostic.
        let mut int =
            |key: &str, v: Option<Spanned<i64>>, range: std::ops::RangeInclusive<u32>, default: u32, unit: &str| {
                int_setting(key, v, range, default, unit, file, &mut diags)
            };
        let scan_ms = int("scan_ms", raw.scan_ms, 1..=MAX_SCAN_MS, DEFAULT_SCAN_MS, "milliseconds");
        let retain_ms = int(
            "retain_ms",
            raw.retain_ms,
            10..=3_600_000,
            DEFAULT_RETAIN_MS,
            "milliseconds",
        );
        let history = raw
            .history
            .map_or_else(History::default, |h| history::history(h, file, &mut diags));
        let audit = raw
            .audit
            .map_or_else(Retention::default, |a| retention::retention(a, file, &mut diags));
        let alarms = raw
            .alarms
            .map_or_else(Retention::default, |a| retention::retention(a, file, &mut diags));
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
        let modbus = raw.modbus.map(|m| modbus::modbus(m, file, &mut diags));
        let opcua = raw.opcua.map(|o| opcua::opcua(o, file, &mut diags));
        let modbus_devices = modbus_device::devices(raw.modbus_device, file, &mut diags);
        let opcua_servers = opcua_server::servers(raw.opcua_server, file, &mut diags);
        let http = raw.http.map(|h| http::http(h, file, &mut diags)).unwrap_or_default();
        let session = raw
            .session
            .map_or_else(Session::default, |s| session::session(s, file, &mut diags));
        let mqtt = raw.mqtt.map(|m| mqtt::mqtt(m, file, &mut diags));
        let config = Config {
            mqtt,
            ladder_dialect,
            modbus_devices,
            opcua_servers,
            session,
            models,
            name,
            description: raw.description,
            scan_ms,
            programs,
            plant,
            board,
            retain_ms,
            runtime: raw
                .runtime
                .map(|r| runtime::runtime(r, file, &mut diags))
                .unwrap_or_default(),
            history,
            audit,
            alarms,
            modbus,
            opcua,
            http,
        };
        (Some(config), diags)
    }
}
