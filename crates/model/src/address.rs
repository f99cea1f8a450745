//! Addresses of the I/O image and the marker memory (SPEC §2.2).
//!
//! Four notations name one image: AuroraLD (`DI:1/5`), IEC 61131-3
//! (`%IX0.5`), S7-200 (`I0.5`) and the SLC 500's files (`I:0/5`, `N7:2`;
//! see [`crate::slc`]). [`Address::parse`] normalises them all.

use crate::Invalid;
use crate::types::DataType;
use std::fmt;

/// The SLC 500's file addresses (`N7:2`, `T4:0.ACC`), parsed beside the others.
pub mod slc;

/// Digital channels per direction (`%IX0.0`..`%IX1023.7`, Modbus coils 0..8191).
pub const MAX_DIGITAL: u32 = 8192;
/// Analog channels per direction (`%IW0`..`%IW1023`).
pub const MAX_ANALOG: u32 = 1024;
/// Bytes of marker memory (`%MD1023` ends at byte 4095).
pub const MARKER_BYTES: u32 = 4096;

/// How a marker address reads the byte-addressed marker memory. Multi-byte
/// values are big-endian, as on a real S7-200.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MarkerWidth {
    Bit(u8),
    Byte,
    Word,
    DWord,
}

/// A normalised address.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Address {
    DigitalIn(u32),
    DigitalOut(u32),
    AnalogIn(u32),
    AnalogOut(u32),
    /// Marker memory at byte offset `byte`.
    Marker {
        byte: u32,
        width: MarkerWidth,
    },
}

/// The area an address lies in, for overlap checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Area {
    DigitalIn,
    DigitalOut,
    AnalogIn,
    AnalogOut,
    Marker,
}

impl Address {
    /// Parses any notation of SPEC §2.2, case-insensitively. `Ok(None)` means
    /// the text does not look like an address at all (it may be a tag name);
    /// `Err` means it looks like one but is wrong, with the reason.
    pub fn parse(text: &str) -> Result<Option<Address>, Invalid> {
        Self::parse_text(text).map_err(Invalid::Address)
    }

    fn parse_text(text: &str) -> Result<Option<Address>, String> {
        let s = text.trim().to_ascii_uppercase();
        if let Some(rest) = s.strip_prefix('%') {
            return parse_iec(rest, text).map(Some);
        }
        // SLC 500 files; a timer or counter element is no address (it names a structure).
        match slc::parse(&s, text)? {
            Some(slc::Slc::Address(a, _)) => return Ok(Some(a)),
            Some(slc::Slc::Struct(..)) => return Ok(None),
            None => {}
        }
        if let Some((area, rest)) = s.split_once(':') {
            if let Some(slash) = rest.split_once('/') {
                return parse_aurora(area, slash, text).map(Some);
            }
            return Ok(None);
        }
        parse_s7(&s, text)
    }

    pub fn area(&self) -> Area {
        match self {
            Address::DigitalIn(_) => Area::DigitalIn,
            Address::DigitalOut(_) => Area::DigitalOut,
            Address::AnalogIn(_) => Area::AnalogIn,
            Address::AnalogOut(_) => Area::AnalogOut,
            Address::Marker { .. } => Area::Marker,
        }
    }

    /// Bits covered in its area: `[start, end)`.
    pub fn footprint(&self) -> (u32, u32) {
        match *self {
            Address::DigitalIn(n) | Address::DigitalOut(n) | Address::AnalogIn(n) | Address::AnalogOut(n) => (n, n + 1),
            Address::Marker { byte, width } => {
                let start = byte * 8;
                match width {
                    MarkerWidth::Bit(b) => (start + b as u32, start + b as u32 + 1),
                    MarkerWidth::Byte => (start, start + 8),
                    MarkerWidth::Word => (start, start + 16),
                    MarkerWidth::DWord => (start, start + 32),
                }
            }
        }
    }

    pub fn overlaps(&self, other: &Address) -> bool {
        if self.area() != other.area() {
            return false;
        }
        let (a0, a1) = self.footprint();
        let (b0, b1) = other.footprint();
        a0 < b1 && b0 < a1
    }

    /// Inputs are written by the I/O driver only, never by programs.
    pub fn is_input(&self) -> bool {
        matches!(self, Address::DigitalIn(_) | Address::AnalogIn(_))
    }

    /// The types a tag on this address may have.
    pub fn allowed_types(&self) -> &'static [DataType] {
        match self {
            Address::DigitalIn(_) | Address::DigitalOut(_) => &[DataType::Bool],
            Address::AnalogIn(_) | Address::AnalogOut(_) => &[DataType::Int, DataType::Dint],
            Address::Marker { width, .. } => match width {
                MarkerWidth::Bit(_) => &[DataType::Bool],
                MarkerWidth::Byte => &[DataType::Sint],
                MarkerWidth::Word => &[DataType::Int],
                MarkerWidth::DWord => &[DataType::Dint, DataType::Real, DataType::Time],
            },
        }
    }

    /// The type an address has when used without a tag.
    pub fn natural_type(&self) -> DataType {
        self.allowed_types()[0]
    }
}

fn num(s: &str, what: &str, original: &str) -> Result<u32, String> {
    if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) || s.len() > 6 {
        return Err(format!("`{original}`: expected a number for the {what}"));
    }
    s.parse()
        .map_err(|_| format!("`{original}`: expected a number for the {what}"))
}

fn bit_of(s: &str, original: &str) -> Result<(u32, u8), String> {
    let (b, i) = s
        .split_once('.')
        .ok_or_else(|| format!("`{original}`: expected byte.bit, like 0.3"))?;
    let byte = num(b, "byte", original)?;
    let bit = num(i, "bit", original)?;
    if bit > 7 {
        return Err(format!("`{original}`: bit numbers go from 0 to 7"));
    }
    Ok((byte, bit as u8))
}

fn check_digital(n: u32, original: &str) -> Result<u32, String> {
    if n >= MAX_DIGITAL {
        return Err(format!(
            "`{original}`: digital channels go from 0 to {}",
            MAX_DIGITAL - 1
        ));
    }
    Ok(n)
}

fn check_analog(n: u32, original: &str) -> Result<u32, String> {
    if n >= MAX_ANALOG {
        return Err(format!("`{original}`: analog channels go from 0 to {}", MAX_ANALOG - 1));
    }
    Ok(n)
}

fn marker(byte: u32, width: MarkerWidth, original: &str) -> Result<Address, String> {
    let a = Address::Marker { byte, width };
    if a.footprint().1 > MARKER_BYTES * 8 {
        return Err(format!(
            "`{original}`: marker memory has {MARKER_BYTES} bytes (0 to {})",
            MARKER_BYTES - 1
        ));
    }
    Ok(a)
}

fn parse_aurora(area: &str, (slot, n): (&str, &str), original: &str) -> Result<Address, String> {
    let expected_slot = match area {
        "DI" => "1",
        "DO" => "2",
        "AI" => "3",
        "AO" => "4",
        _ => {
            return Err(format!(
                "`{original}`: unknown area `{area}`; AuroraLD addresses are DI:1/n, DO:2/n, AI:3/n or AO:4/n"
            ));
        }
    };
    if slot != expected_slot {
        return Err(format!(
            "`{original}`: {area} addresses use slot {expected_slot} ({area}:{expected_slot}/n)"
        ));
    }
    let n = num(n, "channel", original)?;
    Ok(match area {
        "DI" => Address::DigitalIn(check_digital(n, original)?),
        "DO" => Address::DigitalOut(check_digital(n, original)?),
        "AI" => Address::AnalogIn(check_analog(n, original)?),
        _ => Address::AnalogOut(check_analog(n, original)?),
    })
}

fn parse_iec(rest: &str, original: &str) -> Result<Address, String> {
    let mut chars = rest.chars();
    let area = chars
        .next()
        .ok_or_else(|| format!("`{original}`: expected I, Q or M after %"))?;
    let tail = chars.as_str();
    let (size, n) = match tail.chars().next() {
        Some(c @ ('X' | 'B' | 'W' | 'D')) => (c, &tail[1..]),
        Some(c) if c.is_ascii_digit() => ('X', tail),
        _ => {
            return Err(format!("`{original}`: expected a size X, B, W or D after %{area}"));
        }
    };
    match (area, size) {
        ('I', 'X') => {
            let (b, i) = bit_of(n, original)?;
            check_digital(b.saturating_mul(8).saturating_add(i as u32), original).map(Address::DigitalIn)
        }
        ('Q', 'X') => {
            let (b, i) = bit_of(n, original)?;
            check_digital(b.saturating_mul(8).saturating_add(i as u32), original).map(Address::DigitalOut)
        }
        ('I', 'W') => check_analog(num(n, "word", original)?, original).map(Address::AnalogIn),
        ('Q', 'W') => check_analog(num(n, "word", original)?, original).map(Address::AnalogOut),
        ('M', 'X') => {
            let (b, i) = bit_of(n, original)?;
            marker(b, MarkerWidth::Bit(i), original)
        }
        ('M', 'B') => marker(num(n, "byte", original)?, MarkerWidth::Byte, original),
        ('M', 'W') => marker(num(n, "word", original)?.saturating_mul(2), MarkerWidth::Word, original),
        ('M', 'D') => marker(
            num(n, "double word", original)?.saturating_mul(4),
            MarkerWidth::DWord,
            original,
        ),
        ('I' | 'Q' | 'M', _) => Err(format!("`{original}`: %{area}{size} is not an address Alba knows")),
        _ => Err(format!("`{original}`: IEC addresses start with %I, %Q or %M")),
    }
}

/// S7-200 notation; `Ok(None)` when the text is not S7-shaped.
fn parse_s7(s: &str, original: &str) -> Result<Option<Address>, String> {
    let starts_num = |t: &str| t.bytes().next().is_some_and(|b| b.is_ascii_digit());
    let all_num = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit() || b == b'.');
    let addr = if let Some(n) = s.strip_prefix("AIW").filter(|t| all_num(t)) {
        let w = num(n, "word", original)?;
        if w % 2 != 0 {
            return Err(format!("`{original}`: S7 analog words are even (AIW0, AIW2, ...)"));
        }
        Address::AnalogIn(check_analog(w / 2, original)?)
    } else if let Some(n) = s.strip_prefix("AQW").filter(|t| all_num(t)) {
        let w = num(n, "word", original)?;
        if w % 2 != 0 {
            return Err(format!("`{original}`: S7 analog words are even (AQW0, AQW2, ...)"));
        }
        Address::AnalogOut(check_analog(w / 2, original)?)
    } else if let Some(n) = s.strip_prefix("AIN").filter(|t| all_num(t)) {
        Address::AnalogIn(check_analog(num(n, "channel", original)?, original)?)
    } else if let Some(n) = s.strip_prefix("MB").filter(|t| all_num(t)) {
        marker(num(n, "byte", original)?, MarkerWidth::Byte, original)?
    } else if let Some(n) = s.strip_prefix("MW").filter(|t| all_num(t)) {
        marker(num(n, "byte", original)?, MarkerWidth::Word, original)?
    } else if let Some(n) = s.strip_prefix("MD").filter(|t| all_num(t)) {
        marker(num(n, "byte", original)?, MarkerWidth::DWord, original)?
    } else if let Some((area, n)) = s.split_at_checked(1).filter(|(_, t)| starts_num(t) && all_num(t)) {
        if !n.contains('.') {
            // `M1`, `Q5`: not S7 (bits need byte.bit), so free for tag names.
            return Ok(None);
        }
        match area {
            "I" => {
                let (b, i) = bit_of(n, original)?;
                Address::DigitalIn(check_digital(b.saturating_mul(8).saturating_add(i as u32), original)?)
            }
            "Q" => {
                let (b, i) = bit_of(n, original)?;
                Address::DigitalOut(check_digital(b.saturating_mul(8).saturating_add(i as u32), original)?)
            }
            "M" => {
                let (b, i) = bit_of(n, original)?;
                marker(b, MarkerWidth::Bit(i), original)?
            }
            _ => return Ok(None),
        }
    } else {
        return Ok(None);
    };
    Ok(Some(addr))
}

/// Prints AuroraLD style for I/O and S7 byte addressing for markers (the
/// only notation that can name every marker byte).
impl fmt::Display for Address {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Address::DigitalIn(n) => write!(f, "DI:1/{n}"),
            Address::DigitalOut(n) => write!(f, "DO:2/{n}"),
            Address::AnalogIn(n) => write!(f, "AI:3/{n}"),
            Address::AnalogOut(n) => write!(f, "AO:4/{n}"),
            Address::Marker { byte, width } => match width {
                MarkerWidth::Bit(b) => write!(f, "M{byte}.{b}"),
                MarkerWidth::Byte => write!(f, "MB{byte}"),
                MarkerWidth::Word => write!(f, "MW{byte}"),
                MarkerWidth::DWord => write!(f, "MD{byte}"),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Address {
        Address::parse(s).unwrap().unwrap()
    }

    #[test]
    fn every_notation_of_a_channel_is_the_same_address() {
        assert_eq!(p("DI:1/9"), Address::DigitalIn(9));
        assert_eq!(p("%IX1.1"), Address::DigitalIn(9));
        assert_eq!(p("I1.1"), Address::DigitalIn(9));
        assert_eq!(p("do:2/3"), p("%QX0.3"));
        assert_eq!(p("Q0.3"), Address::DigitalOut(3));
        assert_eq!(p("AI:3/2"), Address::AnalogIn(2));
        assert_eq!(p("%IW2"), Address::AnalogIn(2));
        assert_eq!(p("AIW4"), Address::AnalogIn(2));
        assert_eq!(p("Ain2"), Address::AnalogIn(2));
        assert_eq!(p("AO:4/1"), p("%QW1"));
        assert_eq!(p("AQW2"), Address::AnalogOut(1));
    }

    #[test]
    fn markers_are_one_byte_addressed_memory() {
        assert_eq!(p("%MX3.1"), p("M3.1"));
        // IEC %MWn is the n-th word; S7 MWn starts at byte n.
        assert_eq!(p("%MW1"), p("MW2"));
        assert_eq!(p("%MD1"), p("MD4"));
        assert!(p("MW2").overlaps(&p("MW3")));
        assert!(!p("MW2").overlaps(&p("MW4")));
        assert!(p("MD0").overlaps(&p("M3.7")));
        assert!(!p("MW0").overlaps(&p("M2.0")));
        assert!(!p("I0.0").overlaps(&p("Q0.0")));
    }

    #[test]
    fn tag_names_are_not_addresses() {
        for s in [
            "Start", "Motor1", "I", "Q", "MBx", "AIW", "Delay.DN", "S_ULT", "M", "In1", "M1", "Q5",
        ] {
            assert_eq!(Address::parse(s), Ok(None), "{s}");
        }
    }

    #[test]
    fn malformed_addresses_are_explained() {
        for (s, needle) in [
            ("DI:2/0", "slot 1"),
            ("XX:1/0", "unknown area"),
            ("%IX0.8", "0 to 7"),
            ("AIW3", "even"),
            ("%IW1024", "0 to 1023"),
            ("%MD1024", "4096 bytes"),
            ("%KX0.0", "%I, %Q or %M"),
            ("DI:1/x", "number"),
            ("%IXa", "byte.bit"),
        ] {
            let e = Address::parse(s).unwrap_err();
            assert!(e.to_string().contains(needle), "{s}: {e}");
        }
    }

    #[test]
    fn display_reparses_to_the_same_address() {
        for s in ["DI:1/5", "%QX2.1", "AIW6", "%QW3", "M1.2", "MB7", "%MW3", "MD8"] {
            let a = p(s);
            assert_eq!(p(&a.to_string()), a);
        }
    }
}
