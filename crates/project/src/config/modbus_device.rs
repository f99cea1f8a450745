//! `[[modbus_device]]`: remote Modbus slaves polled by `alba run --io modbus`.

use super::modbus::ModbusArea;
use super::setting::int_setting;
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use serde_spanned::Spanned;

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
    pub at: alba_model::address::Address,
    pub span: Span,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDevice {
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
pub(super) struct RawMapping {
    remote: Spanned<String>,
    count: Option<Spanned<i64>>,
    at: Spanned<String>,
}

/// Validates the `[[modbus_device]]` tables: settings in range, mappings
/// of a bit area onto DI/DO and a register area onto AI/AO, only coils and
/// holding registers written, no local channel fed twice.
pub(super) fn devices(raw: Vec<Spanned<RawDevice>>, file: FileId, diags: &mut Vec<Diagnostic>) -> Vec<ModbusDevice> {
    use alba_model::address::Address;
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let mut out = Vec::new();
    // Local channels already mapped: (area, index) -> device name.
    let mut taken: std::collections::HashMap<(alba_model::address::Area, u32), String> = Default::default();
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
                    diags.push(bad(msg.to_string(), m.remote.span(), "the remote address"));
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
                    diags.push(bad(msg.to_string(), m.at.span(), "the first local channel"));
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
