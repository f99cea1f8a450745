//! The settings of Alba's services, from the same `alba.toml` as the project
//! (ADR 0014): `retain_ms` and `[runtime]`, `[history]`, `[audit]`,
//! `[alarms]`, `[modbus]` (the server; `[modbus.tags]` is the project's),
//! `[opcua]`, `[[opcua_server]]`, `[http]`, `[session]`, `[mqtt]`, `[reports]`, one
//! module per table with its types, its raw (serde) form and its checks; and
//! the user store, `users.toml` ([`users`]).
//!
//! Read by the application (`alba-app`) and the commands that start
//! services, never by the compiler: the project's tables are
//! `alba_project::config`'s, and `alba-load` checks both when it loads a
//! folder. Password hashes in `[opcua.users]` are checked for form with
//! `password-hash` only; the `argon2` verifier belongs to `alba-auth`.

mod history;
mod http;
mod modbus;
mod mqtt;
mod opcua;
mod opcua_server;
mod reports;
mod retention;
mod runtime;
mod session;
pub mod users;

pub use history::{DEFAULT_BUFFER_MAX_SAMPLES, History, HistoryBackend, OnDamage};
pub use http::{Http, parse_origin, split_authority};
pub use modbus::{DEFAULT_MODBUS_CONNECTIONS, DEFAULT_MODBUS_IDLE_S, IpRange, IpRangeError, Modbus};
pub use mqtt::{Mqtt, MqttVersion, Sparkplug, is_host_port};
pub use opcua::{HashError, Opcua, OpcuaUser, check_password_hash};
pub use opcua_server::{
    DEFAULT_CLIENT_PKI, DEFAULT_PUBLISHING_INTERVAL_MS, Direction, OpcuaBinding, OpcuaServer, SecurityMode,
    SecurityPolicy, is_node_id,
};
pub use reports::{DEFAULT_REPORTS_FOLDER, ReportFormat, Reports};
pub use retention::{Alarms, Audit, Retention};
pub use runtime::{OnRetainError, Runtime};
pub use session::{DEFAULT_IDLE_MINUTES, DEFAULT_MAX_HOURS, Session};

use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_project::config::setting;
use serde::Deserialize;
use toml::Spanned;

pub const DEFAULT_RETAIN_MS: u32 = 1_000;

/// The services' tables of `alba.toml`.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// How often `alba run` saves retentive data (also on stop).
    pub retain_ms: u32,
    /// `[runtime]`: what to do with a retain file that cannot be used.
    pub runtime: Runtime,
    pub history: History,
    /// `[audit]`: the audit trail's retention (docs/audit.md).
    pub audit: Audit,
    /// `[alarms]`: the alarm log's retention (docs/alarms.md).
    pub alarms: Alarms,
    /// `[modbus]`: the Modbus TCP server of `alba run` (docs/protocols.md).
    pub modbus: Option<Modbus>,
    /// `[opcua]`: the OPC UA server of `alba run` (docs/protocols.md).
    pub opcua: Option<Opcua>,
    /// `[[opcua_server]]`: remote OPC UA servers bound to tags (`alba run`
    /// connects to them; docs/protocols.md, "OPC UA client I/O").
    pub opcua_servers: Vec<OpcuaServer>,
    /// `[http]`: the studio's listener (docs/security.md).
    pub http: Http,
    /// `[session]`: how long a login to the HTTP API lasts.
    pub session: Session,
    /// `[mqtt]`: the MQTT client of `alba run` (docs/scale-out.md).
    pub mqtt: Option<Mqtt>,
    /// `[reports]`: the shift reports written to a folder (docs/alarms.md, "Scheduled reports").
    pub reports: Option<Reports>,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            retain_ms: DEFAULT_RETAIN_MS,
            runtime: Runtime::default(),
            history: History::default(),
            audit: Audit::default(),
            alarms: Alarms::default(),
            modbus: None,
            opcua: None,
            opcua_servers: Vec::new(),
            http: Http::default(),
            session: Session::default(),
            mqtt: None,
            reports: None,
        }
    }
}

/// The services' keys of `alba.toml`; the project's are skipped (the
/// project's reader refuses unknown keys).
#[derive(Deserialize)]
struct RawSettings {
    retain_ms: Option<Spanned<i64>>,
    runtime: Option<runtime::RawRuntime>,
    history: Option<history::RawHistory>,
    audit: Option<retention::RawRetention>,
    alarms: Option<retention::RawRetention>,
    modbus: Option<modbus::RawModbus>,
    opcua: Option<opcua::RawOpcua>,
    #[serde(default)]
    opcua_server: Vec<Spanned<opcua_server::RawServer>>,
    http: Option<http::RawHttp>,
    session: Option<session::RawSession>,
    mqtt: Option<mqtt::RawMqtt>,
    reports: Option<reports::RawReports>,
}

/// `s` as a TOML string (quoted and escaped), for writing alba.toml.
pub fn toml_string(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// A TOML file that could not be read as settings, located.
pub fn toml_error(e: &toml::de::Error, file: FileId) -> Diagnostic {
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
        d = d.with_help("the minimal alba.toml is: name = \"tank\"  scan_ms = 10  programs = [\"main.lad\"]");
    }
    d
}

impl Settings {
    /// Parses and validates the services' tables of `alba.toml`, reporting
    /// every problem found. `None` only when the file could not be read as
    /// settings at all; with bad values the settings are returned (with
    /// defaults in their place).
    pub fn parse(text: &str, file: FileId) -> (Option<Settings>, Vec<Diagnostic>) {
        let raw: RawSettings = match toml::from_str(text) {
            Ok(r) => r,
            Err(e) => return (None, vec![toml_error(&e, file)]),
        };
        let mut diags = Vec::new();
        let retain_ms = setting::int_setting(
            "retain_ms",
            raw.retain_ms,
            10..=3_600_000,
            DEFAULT_RETAIN_MS,
            "milliseconds",
            file,
            &mut diags,
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
        let modbus = raw.modbus.map(|m| modbus::modbus(m, file, &mut diags));
        let opcua = raw.opcua.map(|o| opcua::opcua(o, file, &mut diags));
        let opcua_servers = opcua_server::servers(raw.opcua_server, file, &mut diags);
        let http = raw.http.map(|h| http::http(h, file, &mut diags)).unwrap_or_default();
        let session = raw
            .session
            .map_or_else(Session::default, |s| session::session(s, file, &mut diags));
        let mqtt = raw.mqtt.map(|m| mqtt::mqtt(m, file, &mut diags));
        let reports = raw.reports.and_then(|r| reports::reports(r, file, &mut diags));
        let runtime = raw
            .runtime
            .map(|r| runtime::runtime(r, file, &mut diags))
            .unwrap_or_default();
        let settings = Settings {
            retain_ms,
            runtime,
            history,
            audit,
            alarms,
            modbus,
            opcua,
            opcua_servers,
            http,
            session,
            mqtt,
            reports,
        };
        (Some(settings), diags)
    }

    /// The settings of a loaded project, from the text of its alba.toml
    /// (`None` without one, or when it is not TOML). Their problems were
    /// reported when the project was loaded (`alba_load::load`).
    pub fn of(project: &alba_project::Project) -> Option<Settings> {
        let file = project.config_file?;
        Settings::parse(project.files.text(file), file).0
    }
}
