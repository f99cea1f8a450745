//! `alba.toml`, the project settings (SPEC §10.1).

use crate::board::{Dir, Model, PRESETS, Pin, PinMap};
use crate::codes::Code;
use crate::diag::{Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

pub const DEFAULT_SCAN_MS: u32 = 10;
pub const MAX_SCAN_MS: u32 = 60_000;
pub const DEFAULT_RETAIN_MS: u32 = 1_000;

/// `[history]`: what the historian of `alba run` keeps (docs/historian.md).
#[derive(Debug, Clone, PartialEq)]
pub struct History {
    /// Record at all.
    pub enabled: bool,
    /// Samples older than this are deleted; 0 keeps everything.
    pub retention_days: u32,
    /// A value is also stored this often when it does not change.
    pub sample_ms: u32,
    /// A REAL is stored on change only when it moved more than this.
    pub deadband: f64,
}

impl Default for History {
    fn default() -> History {
        History {
            enabled: true,
            retention_days: 30,
            sample_ms: 10_000,
            deadband: 0.0,
        }
    }
}

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
    pub history: History,
    /// `[[plant_model]]`: simulated processes on the I/O.
    pub models: Vec<crate::plant::PlantModel>,
    /// `[modbus]`: the Modbus TCP server of `alba run` (docs/protocols.md).
    pub modbus: Option<Modbus>,
    /// `[opcua]`: the OPC UA server of `alba run` (docs/protocols.md).
    pub opcua: Option<Opcua>,
    /// `[[modbus_device]]`: remote Modbus slaves polled by `alba run --io
    /// modbus` (docs/protocols.md, "Modbus master I/O").
    pub modbus_devices: Vec<ModbusDevice>,
}

/// `[[modbus_device]]`: one remote Modbus TCP slave whose data is mapped
/// into the I/O image.
#[derive(Debug, Clone, PartialEq)]
pub struct ModbusDevice {
    pub name: String,
    /// How the slave is reached.
    pub link: DeviceLink,
    pub unit: u8,
    pub poll_ms: u32,
    pub timeout_ms: u32,
    /// Further attempts of a failed transaction before the device is lost.
    pub retries: u32,
    /// Outputs are written when they change and at least this often.
    pub refresh_ms: u32,
    pub map: Vec<ModbusMapping>,
    pub span: Span,
}

/// `tcp = "host:port"` or `rtu = "/dev/ttyUSB0"` (with `baud`, 8N1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DeviceLink {
    /// `host:port` of the slave (resolved when the driver connects).
    Tcp(String),
    /// A serial port; devices on the same port share the bus.
    Rtu { port: String, baud: u32 },
}

impl DeviceLink {
    /// `host:port` or `port@baud`, for messages.
    pub fn describe(&self) -> String {
        match self {
            DeviceLink::Tcp(a) => a.clone(),
            DeviceLink::Rtu { port, baud } => format!("{port}@{baud}"),
        }
    }
}

pub const DEFAULT_POLL_MS: u32 = 100;
pub const DEFAULT_RTU_BAUD: u32 = 19_200;
pub const DEFAULT_TIMEOUT_MS: u32 = 500;
pub const DEFAULT_REFRESH_MS: u32 = 1000;

/// One `map` entry: `count` items of the remote `area` from `start`, to or
/// from the local channels from `at` on (inputs are read, outputs written).
#[derive(Debug, Clone, PartialEq)]
pub struct ModbusMapping {
    pub area: ModbusArea,
    pub start: u16,
    pub count: u16,
    /// The first local channel (`Address::DigitalIn(n)` …, never a marker).
    pub at: crate::address::Address,
    pub span: Span,
}

/// `[opcua]`: the OPC UA server (docs/protocols.md).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Opcua {
    /// Where to listen (`None`: only with `alba run --opcua`).
    pub listen: Option<std::net::SocketAddr>,
    /// `[opcua.users]`: who may log in with a user name and password, each
    /// with the argon2 hash (PHC string) of the password; never the password.
    pub users: Vec<OpcuaUser>,
}

/// One entry of `[opcua.users]`: `operator = "$argon2id$v=19$..."`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OpcuaUser {
    pub name: String,
    /// The password's argon2 hash as a PHC string (checked to parse).
    pub hash: String,
    pub span: Span,
    /// May write tags (what the HTTP API lets anyone write); `false` for
    /// the names listed in `[opcua] read_only`.
    pub write: bool,
}

/// Checks a `[opcua.users]` entry's value is an argon2 PHC hash; the error
/// says what is wrong (a plain-text password is called one).
pub fn check_password_hash(text: &str) -> Result<(), String> {
    if !text.starts_with('$') {
        return Err(
            "this is not a password hash: [opcua.users] holds argon2 hashes, never plain-text passwords".to_string(),
        );
    }
    let hash = argon2::PasswordHash::new(text).map_err(|e| format!("`{text}` is not a valid password hash ({e})"))?;
    match hash.algorithm.as_str() {
        "argon2id" | "argon2i" | "argon2d" => {}
        other => {
            return Err(format!(
                "`{other}` hashes are not accepted: use argon2 (`$argon2id$...`)"
            ));
        }
    }
    if hash.hash.is_none() || hash.salt.is_none() {
        return Err(format!("`{text}` has no salt or no hash output"));
    }
    argon2::Params::try_from(&hash).map_err(|e| format!("`{text}` has bad argon2 parameters ({e})"))?;
    Ok(())
}

/// `[modbus]`: the Modbus TCP server (docs/protocols.md).
#[derive(Debug, Clone, PartialEq)]
pub struct Modbus {
    /// Where to listen (`None`: only with `alba run --modbus`).
    pub listen: Option<std::net::SocketAddr>,
    /// Connections served at once; more are closed at once.
    pub max_connections: u32,
    /// A connection that sends no complete request for this long is closed; 0: never.
    pub idle_timeout_s: u32,
    /// Answer only this unit id (and 0 and 255); `None`: every unit id.
    pub unit_id: Option<u8>,
    /// `[modbus.tags]`: explicit addresses of tags outside OpenPLC's map.
    pub tags: Vec<ModbusTag>,
}

pub const DEFAULT_MODBUS_CONNECTIONS: u32 = 32;
pub const DEFAULT_MODBUS_IDLE_S: u32 = 60;

impl Default for Modbus {
    fn default() -> Modbus {
        Modbus {
            listen: None,
            max_connections: DEFAULT_MODBUS_CONNECTIONS,
            idle_timeout_s: DEFAULT_MODBUS_IDLE_S,
            unit_id: None,
            tags: Vec::new(),
        }
    }
}

/// The four Modbus data areas.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ModbusArea {
    Coil,
    DiscreteInput,
    InputRegister,
    HoldingRegister,
}

impl ModbusArea {
    /// The short name used in `[modbus.tags]`.
    pub fn key(self) -> &'static str {
        match self {
            ModbusArea::Coil => "coil",
            ModbusArea::DiscreteInput => "di",
            ModbusArea::InputRegister => "ir",
            ModbusArea::HoldingRegister => "hr",
        }
    }

    /// The first number after OpenPLC's map in this area: explicit
    /// addresses start here.
    pub fn first_free(self) -> u32 {
        match self {
            ModbusArea::Coil | ModbusArea::DiscreteInput | ModbusArea::HoldingRegister => 8192,
            ModbusArea::InputRegister => 1024,
        }
    }

    /// Bits (coils, discrete inputs) or 16-bit registers.
    pub fn is_bits(self) -> bool {
        matches!(self, ModbusArea::Coil | ModbusArea::DiscreteInput)
    }

    /// Clients can write it (coils, holding registers).
    pub fn is_writable(self) -> bool {
        matches!(self, ModbusArea::Coil | ModbusArea::HoldingRegister)
    }

    /// Parses `hr 8192`, `hr8192` or `hr:8192` (area names case-insensitive;
    /// `coil`/`co`, `di`, `ir`, `hr`), any number from 0 to 65535.
    pub fn parse_any(text: &str) -> Result<(ModbusArea, u16), String> {
        let t = text.trim();
        let split = t.find(|c: char| c.is_ascii_digit()).unwrap_or(t.len());
        let (area, num) = t.split_at(split);
        let area = area.trim().trim_end_matches(':').trim().to_ascii_lowercase();
        let area = match area.as_str() {
            "coil" | "co" => ModbusArea::Coil,
            "di" => ModbusArea::DiscreteInput,
            "ir" => ModbusArea::InputRegister,
            "hr" => ModbusArea::HoldingRegister,
            _ => {
                return Err(format!(
                    "`{t}` is not a Modbus address: expected an area (coil, di, ir, hr) and a number, like `hr 8192`"
                ));
            }
        };
        let n: u32 = match num.parse() {
            Ok(n) if num.bytes().all(|b| b.is_ascii_digit()) => n,
            _ => {
                return Err(format!(
                    "`{t}`: expected a number from 0 to 65535 after `{}`",
                    area.key()
                ));
            }
        };
        if n > 65535 {
            return Err(format!("`{t}`: Modbus addresses go from 0 to 65535"));
        }
        Ok((area, n as u16))
    }

    /// [`Self::parse_any`], refused inside OpenPLC's map (`[modbus.tags]`).
    pub fn parse_address(text: &str) -> Result<(ModbusArea, u16), String> {
        let t = text.trim();
        let (area, n) = Self::parse_any(t)?;
        let n = u32::from(n);
        if n < area.first_free() {
            return Err(format!(
                "`{t}` is inside OpenPLC's map ({} 0 to {}, which the I/O image and markers use)",
                area.key(),
                area.first_free() - 1
            ));
        }
        Ok((area, n as u16))
    }
}

/// One entry of `[modbus.tags]`: `Name = "hr 8192"`.
#[derive(Debug, Clone, PartialEq)]
pub struct ModbusTag {
    /// A tag, `Tag.MEMBER` or a system tag.
    pub name: String,
    pub name_span: Span,
    pub area: ModbusArea,
    pub start: u16,
    /// Where the address is written.
    pub span: Span,
}

/// `[board]`: the Arduino board and its wiring (SPEC §7.1, docs/file-formats.md).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Board {
    pub model: Model,
    /// The preset the map started from.
    pub pinmap: String,
    /// The preset with the directions `[board]` lists replaced.
    pub map: PinMap,
    /// Outputs are on when the pin is low.
    pub active_low: bool,
    /// Digital output pins that are on at power-up (and in the remote-I/O
    /// firmware's safe state); every other output is off.
    pub power_up_on: Vec<Pin>,
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
    board: Option<RawBoard>,
    retain_ms: Option<Spanned<i64>>,
    history: Option<RawHistory>,
    #[serde(default)]
    plant_model: Vec<crate::plant::RawPlant>,
    modbus: Option<RawModbus>,
    opcua: Option<RawOpcua>,
    #[serde(default)]
    modbus_device: Vec<Spanned<RawDevice>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDevice {
    name: Spanned<String>,
    tcp: Option<Spanned<String>>,
    rtu: Option<Spanned<String>>,
    baud: Option<Spanned<i64>>,
    unit: Option<Spanned<i64>>,
    poll_ms: Option<Spanned<i64>>,
    timeout_ms: Option<Spanned<i64>>,
    retries: Option<Spanned<i64>>,
    refresh_ms: Option<Spanned<i64>>,
    #[serde(default)]
    map: Vec<Spanned<RawMapping>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMapping {
    remote: Spanned<String>,
    count: Option<Spanned<i64>>,
    at: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOpcua {
    listen: Option<Spanned<String>>,
    #[serde(default)]
    users: std::collections::BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default)]
    read_only: Vec<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModbus {
    listen: Option<Spanned<String>>,
    max_connections: Option<Spanned<i64>>,
    idle_timeout_s: Option<Spanned<i64>>,
    unit_id: Option<Spanned<i64>>,
    #[serde(default)]
    tags: std::collections::BTreeMap<Spanned<String>, Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHistory {
    enabled: Option<bool>,
    retention_days: Option<Spanned<i64>>,
    sample_ms: Option<Spanned<i64>>,
    deadband: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBoard {
    model: Spanned<String>,
    pinmap: Option<Spanned<String>>,
    di: Option<Spanned<Vec<Spanned<String>>>>,
    r#do: Option<Spanned<Vec<Spanned<String>>>>,
    ai: Option<Spanned<Vec<Spanned<String>>>>,
    ao: Option<Spanned<Vec<Spanned<String>>>>,
    #[serde(default)]
    active_low: bool,
    power_up_on: Option<Vec<Spanned<String>>>,
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
                let code =
                    if msg.contains("missing field") || msg.contains("unknown field") || msg.contains("invalid type") {
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
        let mut history = History::default();
        if let Some(h) = raw.history {
            history.enabled = h.enabled.unwrap_or(true);
            history.retention_days = int(
                "retention_days",
                h.retention_days,
                0..=36_500,
                history.retention_days,
                "days",
            );
            history.sample_ms = int(
                "sample_ms",
                h.sample_ms,
                10..=86_400_000,
                history.sample_ms,
                "milliseconds",
            );
            if let Some(d) = h.deadband {
                if d.get_ref().is_finite() && *d.get_ref() >= 0.0 {
                    history.deadband = *d.get_ref();
                } else {
                    diags.push(Diagnostic::new(
                        Code::ConfigField,
                        format!("deadband = {} is out of range", d.get_ref()),
                        sp(d.span()),
                        "expected a number ≥ 0",
                    ));
                }
            }
        }
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
        let board = raw.board.map(|b| {
            let model = Model::parse(b.model.get_ref()).unwrap_or_else(|| {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("unknown board `{}`", b.model.get_ref()),
                    sp(b.model.span()),
                    format!(
                        "expected one of {}",
                        Model::ALL.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
                    ),
                ));
                Model::Uno
            });
            let (pinmap, mut map) = match &b.pinmap {
                Some(p) => match PinMap::preset(p.get_ref()) {
                    Some(m) => (p.get_ref().to_ascii_lowercase(), m),
                    None => {
                        diags.push(Diagnostic::new(
                            Code::ConfigField,
                            format!("unknown pin map `{}`", p.get_ref()),
                            sp(p.span()),
                            format!("expected one of {}", PRESETS.join(", ")),
                        ));
                        ("aurora".to_string(), PinMap::preset("aurora").unwrap_or_default())
                    }
                },
                None => ("aurora".to_string(), PinMap::preset("aurora").unwrap_or_default()),
            };
            for (dir, list) in [
                (Dir::DigitalIn, b.di),
                (Dir::DigitalOut, b.r#do),
                (Dir::AnalogIn, b.ai),
                (Dir::AnalogOut, b.ao),
            ] {
                let Some(list) = list else { continue };
                let mut pins = Vec::new();
                for item in list.into_inner() {
                    let pin = Pin::parse(item.get_ref());
                    match pin.map(|p| (p, model.refuses(p, dir))) {
                        Some((p, None)) if !pins.contains(&p) => pins.push(p),
                        Some((p, None)) => diags.push(Diagnostic::new(
                            Code::ConfigField,
                            format!("pin {p} is wired twice"),
                            sp(item.span()),
                            "a pin serves one channel",
                        )),
                        Some((_, Some(why))) => diags.push(Diagnostic::new(
                            Code::ConfigField,
                            why,
                            sp(item.span()),
                            format!("not a pin for `{}`", dir.key()),
                        )),
                        None => diags.push(Diagnostic::new(
                            Code::ConfigField,
                            format!("`{}` is not a pin name", item.get_ref()),
                            sp(item.span()),
                            "expected D<n> or A<n>, as the Arduino IDE names pins",
                        )),
                    }
                }
                *map.pins_mut(dir) = pins;
            }
            if let Some(p) = map.shared() {
                diags.push(
                    Diagnostic::new(
                        Code::ConfigField,
                        format!("pin {p} is wired to two channels"),
                        sp(b.model.span()),
                        "in this board's pin map",
                    )
                    .with_help("list the pins of each direction (`di`, `do`, `ai`, `ao`) so that no pin appears twice"),
                );
            }
            let mut power_up_on = Vec::new();
            for item in b.power_up_on.unwrap_or_default() {
                match Pin::parse(item.get_ref()) {
                    Some(p) if map.pins(Dir::DigitalOut).contains(&p) => power_up_on.push(p),
                    Some(p) => diags.push(Diagnostic::new(
                        Code::ConfigField,
                        format!("pin {p} is not a digital output of this board's pin map"),
                        sp(item.span()),
                        "not in `do`",
                    )),
                    None => diags.push(Diagnostic::new(
                        Code::ConfigField,
                        format!("`{}` is not a pin name", item.get_ref()),
                        sp(item.span()),
                        "expected D<n> or A<n>, as the Arduino IDE names pins",
                    )),
                }
            }
            Board {
                model,
                pinmap,
                map,
                active_low: b.active_low,
                power_up_on,
            }
        });
        let models = raw
            .plant_model
            .into_iter()
            .filter_map(|m| m.check(file, &mut diags))
            .collect();
        let modbus = raw.modbus.map(|m| modbus(m, file, &mut diags));
        let opcua = raw.opcua.map(|o| opcua(o, file, &mut diags));
        let modbus_devices = devices(raw.modbus_device, file, &mut diags);
        let config = Config {
            modbus_devices,
            models,
            name,
            description: raw.description,
            scan_ms,
            programs,
            plant,
            board,
            retain_ms,
            history,
            modbus,
            opcua,
        };
        (Some(config), diags)
    }
}

/// An integer setting within `range`, or `default` with a located E102.
fn int_setting(
    key: &str,
    v: Option<Spanned<i64>>,
    range: std::ops::RangeInclusive<u32>,
    default: u32,
    unit: &str,
    file: FileId,
    diags: &mut Vec<Diagnostic>,
) -> u32 {
    let Some(s) = v else { return default };
    match u32::try_from(*s.get_ref()) {
        Ok(v) if range.contains(&v) => v,
        _ => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("{key} = {} is out of range", s.get_ref()),
                Span::new(file, s.span()),
                format!("expected {} to {} {unit}", range.start(), range.end()),
            ));
            default
        }
    }
}

/// An `IP:PORT` setting, or a diagnostic.
fn listen(l: &Spanned<String>, file: FileId, diags: &mut Vec<Diagnostic>) -> Option<std::net::SocketAddr> {
    match l.get_ref().parse::<std::net::SocketAddr>() {
        Ok(a) => Some(a),
        Err(_) => {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("listen = \"{}\" is not an address and port", l.get_ref()),
                Span::new(file, l.span()),
                "expected IP:PORT, like \"127.0.0.1:5020\"",
            ));
            None
        }
    }
}

/// Validates the `[[modbus_device]]` tables: settings in range, mappings
/// of a bit area onto DI/DO and a register area onto AI/AO, only coils and
/// holding registers written, no local channel fed twice.
fn devices(raw: Vec<Spanned<RawDevice>>, file: FileId, diags: &mut Vec<Diagnostic>) -> Vec<ModbusDevice> {
    use crate::address::Address;
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let mut out = Vec::new();
    // Local channels already mapped: (area, index) -> device name.
    let mut taken: std::collections::HashMap<(crate::address::Area, u32), String> = Default::default();
    for d in raw {
        let span = sp(d.span());
        let d = d.into_inner();
        let mut int =
            |key: &str, v: Option<Spanned<i64>>, range: std::ops::RangeInclusive<u32>, default: u32, unit: &str| {
                int_setting(key, v, range, default, unit, file, diags)
            };
        let unit = int("unit", d.unit, 0..=255, 1, "(a unit id)") as u8;
        let poll_ms = int("poll_ms", d.poll_ms, 1..=3_600_000, DEFAULT_POLL_MS, "milliseconds");
        let timeout_ms = int(
            "timeout_ms",
            d.timeout_ms,
            1..=60_000,
            DEFAULT_TIMEOUT_MS,
            "milliseconds",
        );
        let retries = int("retries", d.retries, 0..=10, 1, "retries");
        let refresh_ms = int(
            "refresh_ms",
            d.refresh_ms,
            1..=3_600_000,
            DEFAULT_REFRESH_MS,
            "milliseconds",
        );
        let baud = int("baud", d.baud.clone(), 300..=4_000_000, DEFAULT_RTU_BAUD, "bits/s");
        let name = d.name.get_ref().trim().to_string();
        if name.is_empty() || out.iter().any(|o: &ModbusDevice| o.name == name) {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                if name.is_empty() {
                    "the device name is empty".to_string()
                } else {
                    format!("two Modbus devices are named `{name}`")
                },
                sp(d.name.span()),
                "a device needs a name of its own",
            ));
        }
        let link = match (&d.tcp, &d.rtu) {
            (Some(t), None) => {
                let tcp = t.get_ref().trim().to_string();
                let port_ok = tcp
                    .rsplit_once(':')
                    .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok_and(|p| p > 0));
                if !port_ok {
                    diags.push(Diagnostic::new(
                        Code::ConfigField,
                        format!("tcp = \"{tcp}\" is not a host and port"),
                        sp(t.span()),
                        "expected HOST:PORT, like \"192.168.1.20:502\"",
                    ));
                }
                if let Some(b) = &d.baud {
                    diags.push(Diagnostic::new(
                        Code::ConfigField,
                        "`baud` is a setting of serial (rtu) devices",
                        sp(b.span()),
                        "not with tcp",
                    ));
                }
                DeviceLink::Tcp(tcp)
            }
            (None, Some(r)) if !r.get_ref().trim().is_empty() => DeviceLink::Rtu {
                port: r.get_ref().trim().to_string(),
                baud,
            },
            (t, r) => {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    format!("device `{name}` needs exactly one of `tcp` and `rtu`"),
                    sp(t.as_ref().or(r.as_ref()).map_or(d.name.span(), |x| x.span())),
                    "tcp = \"HOST:PORT\" or rtu = \"/dev/ttyUSB0\"",
                ));
                DeviceLink::Tcp(String::new())
            }
        };
        let mut map = Vec::new();
        for m in d.map {
            let mspan = sp(m.span());
            let m = m.into_inner();
            let bad = |msg: String, at: std::ops::Range<usize>, label: &str| {
                Diagnostic::new(Code::ConfigField, msg, sp(at), label.to_string())
            };
            let (area, start) = match ModbusArea::parse_any(m.remote.get_ref()) {
                Ok(a) => a,
                Err(msg) => {
                    diags.push(bad(msg, m.remote.span(), "the remote address"));
                    continue;
                }
            };
            let count = match &m.count {
                None => 1,
                Some(c) => match u16::try_from(*c.get_ref()) {
                    Ok(n) if n >= 1 && u32::from(start) + u32::from(n) <= 65_536 => n,
                    _ => {
                        diags.push(bad(
                            format!("count = {} is out of range", c.get_ref()),
                            c.span(),
                            &format!("expected 1 to {} (the area ends at 65535)", 65_536 - u32::from(start)),
                        ));
                        continue;
                    }
                },
            };
            let at = match Address::parse(m.at.get_ref()) {
                Ok(Some(a)) if !matches!(a, Address::Marker { .. }) => a,
                Ok(_) => {
                    diags.push(bad(
                        format!("`{}` is not an I/O channel", m.at.get_ref()),
                        m.at.span(),
                        "expected the first local channel, like \"DI:1/0\", \"DO:2/0\", \"AI:3/0\" or \"AO:4/0\"",
                    ));
                    continue;
                }
                Err(msg) => {
                    diags.push(bad(msg, m.at.span(), "the first local channel"));
                    continue;
                }
            };
            let output = matches!(at, Address::DigitalOut(_) | Address::AnalogOut(_));
            let bits = matches!(at, Address::DigitalIn(_) | Address::DigitalOut(_));
            if bits != area.is_bits() {
                diags.push(bad(
                    format!(
                        "{} `{}` cannot feed `{}`",
                        if area.is_bits() { "bits" } else { "registers" },
                        m.remote.get_ref(),
                        m.at.get_ref()
                    ),
                    m.at.span(),
                    "coils and discrete inputs map onto DI/DO, input and holding registers onto AI/AO",
                ));
                continue;
            }
            if output && !area.is_writable() {
                diags.push(bad(
                    format!("`{}` cannot be written", m.remote.get_ref()),
                    m.remote.span(),
                    "outputs are written to coils (DO) or holding registers (AO)",
                ));
                continue;
            }
            let (first, _) = at.footprint();
            if let Some(owner) = (0..u32::from(count)).find_map(|k| taken.get(&(at.area(), first + k))) {
                diags.push(bad(
                    format!(
                        "channels from `{}` are already mapped by device `{owner}`",
                        m.at.get_ref()
                    ),
                    m.at.span(),
                    "a local channel has one source",
                ));
                continue;
            }
            for k in 0..u32::from(count) {
                taken.insert((at.area(), first + k), name.clone());
            }
            map.push(ModbusMapping {
                area,
                start,
                count,
                at,
                span: mspan,
            });
        }
        out.push(ModbusDevice {
            name,
            link,
            unit,
            poll_ms,
            timeout_ms,
            retries,
            refresh_ms,
            map,
            span,
        });
    }
    out
}

/// Validates `[opcua]`: user names and password hashes, and that a
/// listen address beyond loopback has users (nobody could log in otherwise:
/// such an address serves no anonymous endpoint).
fn opcua(o: RawOpcua, file: FileId, diags: &mut Vec<Diagnostic>) -> Opcua {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let addr = o.listen.as_ref().and_then(|l| listen(l, file, diags));
    let mut users = Vec::new();
    let mut entries: Vec<_> = o.users.into_iter().collect();
    entries.sort_by_key(|(name, _)| name.span().start);
    for (name, hash) in entries {
        let n = name.get_ref();
        if n.is_empty() || n.chars().any(|c| c.is_whitespace() || c.is_control()) {
            diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("`{n}` is not a user name"),
                sp(name.span()),
                "in [opcua.users]: a user name is not empty and has no spaces",
            ));
            continue;
        }
        match check_password_hash(hash.get_ref()) {
            Ok(()) => users.push(OpcuaUser {
                name: n.clone(),
                hash: hash.get_ref().clone(),
                span: sp(name.span()),
                write: true,
            }),
            Err(msg) => diags.push(
                Diagnostic::new(
                    Code::ConfigField,
                    msg,
                    sp(hash.span()),
                    format!("the password hash of `{n}`"),
                )
                .with_help("make one with `alba hash-password` (it reads the password from stdin)"),
            ),
        }
    }
    for r in &o.read_only {
        match users.iter_mut().find(|u| u.name == *r.get_ref()) {
            Some(u) => u.write = false,
            None => diags.push(Diagnostic::new(
                Code::ConfigField,
                format!("`{}` is not in [opcua.users]", r.get_ref()),
                sp(r.span()),
                "read_only lists user names of [opcua.users]",
            )),
        }
    }
    if let (Some(a), Some(l)) = (addr, o.listen.as_ref())
        && !a.ip().is_loopback()
        && users.is_empty()
    {
        diags.push(
            Diagnostic::new(
                Code::ConfigField,
                format!("listen = \"{a}\" is not a loopback address, so it needs [opcua.users]"),
                sp(l.span()),
                "beyond loopback only Basic256Sha256 with a user name and password is served",
            )
            .with_help("add `[opcua.users]` with `name = \"<hash from alba hash-password>\"`, or listen on 127.0.0.1"),
        );
    }
    Opcua { listen: addr, users }
}

/// Validates `[modbus]`.
fn modbus(m: RawModbus, file: FileId, diags: &mut Vec<Diagnostic>) -> Modbus {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let listen = m.listen.and_then(|l| listen(&l, file, diags));
    let mut int =
        |key: &str, v: Option<Spanned<i64>>, range: std::ops::RangeInclusive<u32>, default: u32, unit: &str| {
            int_setting(key, v, range, default, unit, file, diags)
        };
    let mut out = Modbus {
        listen,
        max_connections: int(
            "max_connections",
            m.max_connections,
            1..=4096,
            DEFAULT_MODBUS_CONNECTIONS,
            "connections",
        ),
        idle_timeout_s: int(
            "idle_timeout_s",
            m.idle_timeout_s,
            0..=86_400,
            DEFAULT_MODBUS_IDLE_S,
            "seconds",
        ),
        ..Modbus::default()
    };
    if m.unit_id.is_some() {
        out.unit_id = Some(int("unit_id", m.unit_id, 0..=255, 1, "(a unit id)") as u8);
    }
    for (name, addr) in m.tags {
        match ModbusArea::parse_address(addr.get_ref()) {
            Ok((area, start)) => out.tags.push(ModbusTag {
                name: name.get_ref().trim().to_string(),
                name_span: sp(name.span()),
                area,
                start,
                span: sp(addr.span()),
            }),
            Err(msg) => diags.push(
                Diagnostic::new(Code::ConfigField, msg, sp(addr.span()), "in [modbus.tags]").with_help(
                    "explicit addresses lie after OpenPLC's map: coil/di from 8192, ir from 1024, hr from 8192",
                ),
            ),
        }
    }
    out.tags.sort_by_key(|t| t.name_span.start);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::Files;

    fn parse(text: &str) -> Result<Config, Vec<String>> {
        let mut files = Files::new();
        let f = files.add("alba.toml", text);
        match Config::parse(text, f) {
            (Some(c), d) if d.is_empty() => Ok(c),
            (_, d) => Err(d.iter().map(|d| d.short(&files)).collect()),
        }
    }

    #[test]
    fn names_with_quotes_and_backslashes_round_trip() {
        for name in ["plain", "a\\b", "say \"hi\"", "tab\there", "ñandú"] {
            let text = format!("name = {}\nprograms = [\"a.lad\"]\n", toml_string(name));
            assert_eq!(parse(&text).unwrap().name, name, "{text}");
        }
    }

    #[test]
    fn minimal_config_takes_defaults() {
        let c = parse("name = \"tank\"\nprograms = [\"main.lad\"]\n").unwrap();
        assert_eq!(c.scan_ms, 10);
        assert_eq!(c.programs[0].0, "main.lad");
        assert!(c.board.is_none());
    }

    #[test]
    fn retain_and_history_settings() {
        let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n").unwrap();
        assert_eq!((c.retain_ms, c.history.clone()), (1000, History::default()));
        let c = parse(
            "name = \"x\"\nretain_ms = 250\nprograms = [\"a.lad\"]\n[history]\nretention_days = 0\nsample_ms = 500\ndeadband = 0.5\n",
        )
        .unwrap();
        assert_eq!(c.retain_ms, 250);
        assert_eq!(
            c.history,
            History {
                enabled: true,
                retention_days: 0,
                sample_ms: 500,
                deadband: 0.5
            }
        );
        let e = parse(
            "name = \"x\"\nretain_ms = 5\nprograms = [\"a.lad\"]\n[history]\nretention_days = -1\ndeadband = -1.0\n",
        )
        .unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:2:13: error[E102]: retain_ms = 5 is out of range",
                "alba.toml:5:18: error[E102]: retention_days = -1 is out of range",
                "alba.toml:6:12: error[E102]: deadband = -1 is out of range",
            ]
        );
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[history]\nkeep = 3\n").unwrap_err();
        assert!(e[0].contains("unknown field `keep`"), "{e:?}");
    }

    #[test]
    fn modbus_devices_and_their_maps() {
        let head = "name = \"x\"\nprograms = [\"a.lad\"]\n";
        let c = parse(&format!(
            "{head}[[modbus_device]]\nname = \"rack\"\ntcp = \"10.0.0.5:502\"\nmap = [\n  {{ remote = \"di 0\", count = 8, at = \"%IX0.0\" }},\n  {{ remote = \"hr 100\", at = \"AO:4/2\" }},\n]\n"
        ))
        .unwrap();
        let d = &c.modbus_devices[0];
        assert_eq!(
            (
                d.name.as_str(),
                &d.link,
                d.unit,
                d.poll_ms,
                d.timeout_ms,
                d.retries,
                d.refresh_ms
            ),
            ("rack", &DeviceLink::Tcp("10.0.0.5:502".into()), 1, 100, 500, 1, 1000)
        );
        let m: Vec<_> = d.map.iter().map(|m| (m.area, m.start, m.count, m.at)).collect();
        assert_eq!(
            m,
            [
                (ModbusArea::DiscreteInput, 0, 8, crate::address::Address::DigitalIn(0)),
                (
                    ModbusArea::HoldingRegister,
                    100,
                    1,
                    crate::address::Address::AnalogOut(2)
                ),
            ]
        );
        let c = parse(&format!(
            "{head}[[modbus_device]]\nname = \"bus\"\nrtu = \"/dev/ttyUSB0\"\nbaud = 9600\n"
        ))
        .unwrap();
        assert_eq!(
            c.modbus_devices[0].link,
            DeviceLink::Rtu {
                port: "/dev/ttyUSB0".into(),
                baud: 9600
            }
        );
        let e = parse(&format!(
            "{head}[[modbus_device]]\nname = \"b\"\nrtu = \"/dev/x\"\ntcp = \"h:1\"\n[[modbus_device]]\nname = \"c\"\ntcp = \"h:1\"\nbaud = 9600\n"
        ))
        .unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:6:7: error[E102]: device `b` needs exactly one of `tcp` and `rtu`",
                "alba.toml:10:8: error[E102]: `baud` is a setting of serial (rtu) devices",
            ]
        );
        let e = parse(&format!(
            "{head}[[modbus_device]]\nname = \"a\"\ntcp = \"nowhere\"\npoll_ms = 0\nunit = 300\nmap = [\n  {{ remote = \"di 0\", count = 4, at = \"AI:3/0\" }},\n  {{ remote = \"ir 0\", at = \"AO:4/0\" }},\n  {{ remote = \"coil 65535\", count = 2, at = \"DO:2/0\" }},\n  {{ remote = \"coil 0\", at = \"MW0\" }},\n  {{ remote = \"zz 1\", at = \"DI:1/0\" }},\n  {{ remote = \"di 0\", count = 2, at = \"DI:1/0\" }},\n]\n[[modbus_device]]\nname = \"a\"\ntcp = \"h:1\"\nmap = [{{ remote = \"coil 4\", at = \"DI:1/1\" }}]\n"
        ))
        .unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:7:8: error[E102]: unit = 300 is out of range",
                "alba.toml:6:11: error[E102]: poll_ms = 0 is out of range",
                "alba.toml:5:7: error[E102]: tcp = \"nowhere\" is not a host and port",
                "alba.toml:9:38: error[E102]: bits `di 0` cannot feed `AI:3/0`",
                "alba.toml:10:14: error[E102]: `ir 0` cannot be written",
                "alba.toml:11:36: error[E102]: count = 2 is out of range",
                "alba.toml:12:29: error[E102]: `MW0` is not an I/O channel",
                "alba.toml:13:14: error[E102]: `zz 1` is not a Modbus address: expected an area (coil, di, ir, hr) and a number, like `hr 8192`",
                "alba.toml:17:8: error[E102]: two Modbus devices are named `a`",
                "alba.toml:19:34: error[E102]: channels from `DI:1/1` are already mapped by device `a`",
            ]
        );
    }

    #[test]
    fn boards_and_pin_maps() {
        let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"Nano\"\npinmap = \"s7\"\n").unwrap();
        let b = c.board.unwrap();
        assert_eq!((b.model, b.pinmap.as_str(), b.active_low), (Model::Nano, "s7", false));
        assert_eq!(b.map, PinMap::preset("s7").unwrap());
        // A custom list replaces one direction of the preset.
        let c = parse(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\nai = [\"A4\", \"A5\"]\nactive_low = true\n",
        )
        .unwrap();
        let b = c.board.unwrap();
        assert_eq!(b.map.ai, [Pin::A(4), Pin::A(5)]);
        assert_eq!(b.map.di, PinMap::preset("aurora").unwrap().di);
        assert!(b.active_low);
        // Outputs on at power-up: digital outputs of the map only.
        let c =
            parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\npower_up_on = [\"A0\"]\n").unwrap();
        assert_eq!(c.board.unwrap().power_up_on, [Pin::A(0)]);
        let e =
            parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\npower_up_on = [\"D2\", \"X\"]\n")
                .unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:5:16: error[E102]: pin D2 is not a digital output of this board's pin map",
                "alba.toml:5:22: error[E102]: `X` is not a pin name",
            ]
        );
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"due\"\n").unwrap_err();
        assert_eq!(e, ["alba.toml:4:9: error[E102]: unknown board `due`"]);
        let e = parse(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\nao = [\"D7\", \"Q3\", \"D9\", \"D9\"]\n",
        )
        .unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:5:7: error[E102]: D7 has no PWM, so it cannot be an analog output",
                "alba.toml:5:13: error[E102]: `Q3` is not a pin name",
                "alba.toml:5:25: error[E102]: pin D9 is wired twice",
            ]
        );
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\ndi = [\"D12\"]\n").unwrap_err();
        assert_eq!(e, ["alba.toml:4:9: error[E102]: pin D12 is wired to two channels"]);
    }

    /// A real argon2id hash of `pw` (small parameters: a test).
    fn test_hash(pw: &str) -> String {
        use argon2::password_hash::{PasswordHasher, SaltString};
        let a = argon2::Argon2::new(
            argon2::Algorithm::Argon2id,
            argon2::Version::V0x13,
            argon2::Params::new(8, 1, 1, None).unwrap(),
        );
        let salt = SaltString::encode_b64(b"alba-test-salt").unwrap();
        a.hash_password(pw.as_bytes(), &salt).unwrap().to_string()
    }

    #[test]
    fn opcua_users_hold_argon2_hashes() {
        let h = test_hash("secret");
        let c = parse(&format!(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n[opcua.users]\noperator = \"{h}\"\nadmin = \"{h}\"\n"
        ))
        .unwrap();
        let o = c.opcua.unwrap();
        assert_eq!(o.listen, Some("0.0.0.0:4840".parse().unwrap()));
        let names: Vec<_> = o.users.iter().map(|u| u.name.as_str()).collect();
        assert_eq!(names, ["operator", "admin"], "in file order");
        assert_eq!(o.users[0].hash, h);
        assert!(o.users.iter().all(|u| u.write));
        let c = parse(&format!(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nread_only = [\"viewer\"]\n[opcua.users]\noperator = \"{h}\"\nviewer = \"{h}\"\n"
        ))
        .unwrap();
        let w: Vec<_> = c
            .opcua
            .unwrap()
            .users
            .iter()
            .map(|u| (u.name.clone(), u.write))
            .collect();
        assert_eq!(w, [("operator".to_string(), true), ("viewer".to_string(), false)]);
        let e = parse(&format!(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nread_only = [\"ghost\"]\n[opcua.users]\noperator = \"{h}\"\n"
        ))
        .unwrap_err();
        assert_eq!(e, ["alba.toml:4:14: error[E102]: `ghost` is not in [opcua.users]"]);
        // Loopback needs no users.
        let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"127.0.0.2:4840\"\n").unwrap();
        assert!(c.opcua.unwrap().users.is_empty());
        // Errors, each located on the offending value.
        let e = parse(&format!(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"127.0.0.1:4840\"\n[opcua.users]\nplain = \"hunter2\"\nmd5 = \"$1$abc$def\"\n\"two words\" = \"{h}\"\nbroken = \"$argon2id$v=19$m=8,t=1,p=1$\"\nweak = \"$argon2id$v=19$m=1,t=1,p=1$YWxiYS10ZXN0LXNhbHQ$AAAAAAAAAAAAAAAAAAAAAA\"\n"
        ))
        .unwrap_err();
        assert_eq!(e.len(), 5, "{e:#?}");
        assert_eq!(
            e[0],
            "alba.toml:6:9: error[E102]: this is not a password hash: [opcua.users] holds argon2 hashes, never plain-text passwords"
        );
        assert!(e[1].starts_with("alba.toml:7:7: error[E102]: `$1$abc$def`"), "{}", e[1]);
        assert_eq!(e[2], "alba.toml:8:1: error[E102]: `two words` is not a user name");
        assert!(
            e[3].starts_with("alba.toml:9:10: error[E102]: `$argon2id$v=19$m=8,t=1,p=1$`"),
            "{}",
            e[3]
        );
        assert!(
            e[4].starts_with("alba.toml:10:8: error[E102]: `$argon2id$v=19$m=1,t=1,p=1$"),
            "{}",
            e[4]
        );
        // Beyond loopback without users nobody could log in.
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n").unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:4:10: error[E102]: listen = \"0.0.0.0:4840\" is not a loopback address, so it needs [opcua.users]"
            ]
        );
        assert!(check_password_hash(&h).is_ok());
    }

    #[test]
    fn modbus_settings_and_explicit_addresses() {
        let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n").unwrap();
        assert!(c.modbus.is_none() && c.opcua.is_none());
        let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"127.0.0.1:4840\"\n").unwrap();
        assert_eq!(c.opcua.unwrap().listen, Some("127.0.0.1:4840".parse().unwrap()));
        let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"4840\"\n").unwrap_err();
        assert_eq!(
            e,
            ["alba.toml:4:10: error[E102]: listen = \"4840\" is not an address and port"]
        );
        let c = parse(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[modbus]\nlisten = \"127.0.0.1:5020\"\nunit_id = 3\n[modbus.tags]\nSpeed = \"hr 8192\"\n\"Delay.PRE\" = \"HR:9000\"\nRunning = \"coil8192\"\n",
        )
        .unwrap();
        let m = c.modbus.unwrap();
        assert_eq!(m.listen, Some("127.0.0.1:5020".parse().unwrap()));
        assert_eq!((m.unit_id, m.max_connections, m.idle_timeout_s), (Some(3), 32, 60));
        let tags: Vec<_> = m.tags.iter().map(|t| (t.name.as_str(), t.area, t.start)).collect();
        assert_eq!(
            tags,
            [
                ("Speed", ModbusArea::HoldingRegister, 8192),
                ("Delay.PRE", ModbusArea::HoldingRegister, 9000),
                ("Running", ModbusArea::Coil, 8192),
            ]
        );
        let e = parse(
            "name = \"x\"\nprograms = [\"a.lad\"]\n[modbus]\nlisten = \"localhost\"\nmax_connections = 0\n[modbus.tags]\nA = \"hr 100\"\nB = \"xx 9000\"\nC = \"ir 70000\"\n",
        )
        .unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:4:10: error[E102]: listen = \"localhost\" is not an address and port",
                "alba.toml:5:19: error[E102]: max_connections = 0 is out of range",
                "alba.toml:7:5: error[E102]: `hr 100` is inside OpenPLC's map (hr 0 to 8191, which the I/O image and markers use)",
                "alba.toml:8:5: error[E102]: `xx 9000` is not a Modbus address: expected an area (coil, di, ir, hr) and a number, like `hr 8192`",
                "alba.toml:9:5: error[E102]: `ir 70000`: Modbus addresses go from 0 to 65535",
            ]
        );
    }

    #[test]
    fn bad_configs_are_located() {
        let e = parse("name = \"x\"\nscan_m = 5\nprograms = [\"a.lad\"]\n").unwrap_err();
        assert!(
            e[0].starts_with("alba.toml:2:1: error[E102]: alba.toml: unknown field `scan_m`"),
            "{e:?}"
        );
        let e = parse("name = \"x\"\nscan_ms = 0\nprograms = []\n").unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:2:11: error[E102]: scan_ms = 0 is out of range",
                "alba.toml:3:12: error[E102]: `programs` is empty"
            ]
        );
        let e = parse("name = \"x\nprograms = [\"a.lad\"]\n").unwrap_err();
        assert!(e[0].contains("error[E101]"), "{e:?}");
        let e = parse("programs = [\"a.lad\"]\n").unwrap_err();
        assert!(e[0].contains("missing field `name`"), "{e:?}");
        let e = parse("name = 5\nprograms = [\"a.lad\"]\n").unwrap_err();
        assert!(e[0].starts_with("alba.toml:1:8: error[E102]"), "{e:?}");
    }

    #[test]
    fn plant_models_are_checked_with_their_places() {
        let head = "name = \"p\"\nprograms = [\"a.lad\"]\n";
        let ok = format!(
            "{head}[[plant_model]]\nkind = \"first_order\"\ninput = \"AO:4/0\"\noutput = \"AI:3/0\"\ntau = 10.0\ninput_scale = [0, 10000, 0, 10]\ndead_time = 0.5\n"
        );
        let c = parse(&ok).unwrap();
        assert_eq!(c.models.len(), 1);
        assert_eq!(c.models[0].dead_time, 0.5);
        let bad = format!(
            "{head}[[plant_model]]\nkind = \"first_order\"\ninput = \"U\"\noutput = \"Y\"\ntau = -1.0\narea = 2.0\nsaturation = [5, 1]\n\n[[plant_model]]\nkind = \"third\"\ninput = \"U\"\noutput = \"Y\"\n\n[[plant_model]]\nkind = \"second_order\"\ninput = \"U\"\noutput = \"Y\"\nden = [1, 2]\n"
        );
        let e = parse(&bad).unwrap_err();
        assert_eq!(
            e,
            [
                "alba.toml:7:7: error[E105]: tau = -1 must be a number more than 0",
                "alba.toml:8:8: error[E105]: `area` is not a parameter of a first_order model",
                "alba.toml:9:14: error[E105]: saturation must be [lo, hi] with lo <= hi",
                "alba.toml:12:8: error[E105]: unknown plant model kind `third`",
                "alba.toml:20:7: error[E105]: den must be three numbers [a2, a1, a0] for gain/(a2·s² + a1·s + a0)",
            ]
        );
    }
}
