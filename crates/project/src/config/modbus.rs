//! `[modbus.tags]`: explicit Modbus addresses of tags, and the Modbus areas.

use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::Deserialize;
use serde_spanned::Spanned;

/// Why a text is not a Modbus address ([`ModbusArea::parse_any`],
/// [`ModbusArea::parse_address`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AddressError {
    #[error("`{0}` is not a Modbus address: expected an area (coil, di, ir, hr) and a number, like `hr 8192`")]
    NoArea(String),
    #[error("`{text}`: expected a number from 0 to 65535 after `{}`", area.key())]
    NoNumber { text: String, area: ModbusArea },
    #[error("`{0}`: Modbus addresses go from 0 to 65535")]
    TooBig(String),
    #[error("`{text}` is inside OpenPLC's map ({} 0 to {}, which the I/O image and markers use)", area.key(), area.first_free() - 1)]
    InsideOpenPlcMap { text: String, area: ModbusArea },
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
    pub fn parse_any(text: &str) -> Result<(ModbusArea, u16), AddressError> {
        let t = text.trim();
        let split = t.find(|c: char| c.is_ascii_digit()).unwrap_or(t.len());
        let (area, num) = t.split_at(split);
        let area = area.trim().trim_end_matches(':').trim().to_ascii_lowercase();
        let area = match area.as_str() {
            "coil" | "co" => ModbusArea::Coil,
            "di" => ModbusArea::DiscreteInput,
            "ir" => ModbusArea::InputRegister,
            "hr" => ModbusArea::HoldingRegister,
            _ => return Err(AddressError::NoArea(t.to_string())),
        };
        let n: u32 = match num.parse() {
            Ok(n) if num.bytes().all(|b| b.is_ascii_digit()) => n,
            _ => {
                return Err(AddressError::NoNumber {
                    text: t.to_string(),
                    area,
                });
            }
        };
        if n > 65535 {
            return Err(AddressError::TooBig(t.to_string()));
        }
        Ok((area, n as u16))
    }

    /// [`Self::parse_any`], refused inside OpenPLC's map (`[modbus.tags]`).
    pub fn parse_address(text: &str) -> Result<(ModbusArea, u16), AddressError> {
        let t = text.trim();
        let (area, n) = Self::parse_any(t)?;
        let n = u32::from(n);
        if n < area.first_free() {
            return Err(AddressError::InsideOpenPlcMap {
                text: t.to_string(),
                area,
            });
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

/// `[modbus]` as the project reads it: only `[modbus.tags]` (the server's
/// keys are `alba-settings`').
#[derive(Deserialize)]
pub(super) struct RawModbusTags {
    #[serde(default)]
    tags: std::collections::BTreeMap<Spanned<String>, Spanned<String>>,
}

/// Validates `[modbus.tags]`.
pub(super) fn tags(m: RawModbusTags, file: FileId, diags: &mut Vec<Diagnostic>) -> Vec<ModbusTag> {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
    let mut out = Vec::new();
    for (name, addr) in m.tags {
        match ModbusArea::parse_address(addr.get_ref()) {
            Ok((area, start)) => out.push(ModbusTag {
                name: name.get_ref().trim().to_string(),
                name_span: sp(name.span()),
                area,
                start,
                span: sp(addr.span()),
            }),
            Err(msg) => diags.push(
                Diagnostic::new(Code::ConfigField, msg.to_string(), sp(addr.span()), "in [modbus.tags]").with_help(
                    "explicit addresses lie after OpenPLC's map: coil/di from 8192, ir from 1024, hr from 8192",
                ),
            ),
        }
    }
    out.sort_by_key(|t| t.name_span.start);
    out
}
