//! `[modbus]`: the Modbus TCP server of `alba run`, with `[modbus.tags]`.

use super::setting::{int_setting, listen};
use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use toml::Spanned;

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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawModbus {
    listen: Option<Spanned<String>>,
    max_connections: Option<Spanned<i64>>,
    idle_timeout_s: Option<Spanned<i64>>,
    unit_id: Option<Spanned<i64>>,
    #[serde(default)]
    tags: std::collections::BTreeMap<Spanned<String>, Spanned<String>>,
}

/// Validates `[modbus]`.
pub(super) fn modbus(m: RawModbus, file: FileId, diags: &mut Vec<Diagnostic>) -> Modbus {
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
