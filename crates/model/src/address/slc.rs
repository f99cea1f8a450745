//! SLC 500 file addressing (`004_…`; docs/addresses.md): `I:1/0`, `O:0/3`,
//! `B3:0/1`, `B3/17`, `N7:2`, `F8:0`, `T4:0.ACC`, `C5:1.DN`.
//!
//! Inputs and outputs are the digital images, one 16-bit word per slot:
//! `I:e/b` is digital input 16·e + b. The data files B3, N7, F8, N9 and N10
//! are fixed ranges of the marker memory, words big-endian as every marker
//! word (so `B3:0` is `MW0` and `B3:0/0` is its least significant bit,
//! `M1.0`). Timer and counter files (`T4:0`, `C5:1`) are not addresses: they
//! name TIMER and COUNTER structures the layout makes for the programs that
//! use them (see [`SlcStruct`]).

use crate::Invalid;
use crate::address::{Address, MarkerWidth};
use crate::types::DataType;

/// Elements per data file (the SLC 500's limit: 0 to 255).
pub const FILE_ELEMENTS: u32 = 256;

/// The data files Alba maps, with their first marker byte: `(letter, file,
/// first byte, bytes per element)`.
pub const DATA_FILES: [(char, u32, u32, u32); 5] = [
    ('B', 3, 0, 2),
    ('N', 7, 512, 2),
    ('F', 8, 1024, 4),
    ('N', 9, 2048, 2),
    ('N', 10, 2560, 2),
];

/// An SLC 500 timer (`T`) or counter (`C`) file element: `T4:0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SlcStruct {
    pub counter: bool,
    pub file: u8,
    pub element: u8,
}

impl SlcStruct {
    pub fn ty(self) -> DataType {
        if self.counter {
            DataType::Counter
        } else {
            DataType::Timer
        }
    }
}

impl std::fmt::Display for SlcStruct {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let l = if self.counter { 'C' } else { 'T' };
        write!(f, "{l}{}:{}", self.file, self.element)
    }
}

/// What an SLC 500 address names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Slc {
    /// An I/O channel or marker range; `ty` is its type without a tag (REAL
    /// for F files).
    Address(Address, DataType),
    /// A timer or counter element, with the member after the dot (`ACC`).
    Struct(SlcStruct, Option<String>),
}

fn number(s: &str, what: &str, original: &str) -> Result<u32, String> {
    if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) || s.len() > 5 {
        return Err(format!("`{original}`: expected a number for the {what}"));
    }
    s.parse()
        .map_err(|_| format!("`{original}`: expected a number for the {what}"))
}

/// A file letter and number (`N7`), if the text is shaped like one.
fn file_of(s: &str) -> Option<(char, &str)> {
    let mut chars = s.chars();
    let letter = chars.next()?;
    let digits = chars.as_str();
    (matches!(letter, 'B' | 'N' | 'F' | 'T' | 'C') && !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()))
        .then_some((letter, digits))
}

/// Parses an SLC 500 address (upper-cased `s`, `original` for messages).
/// `Ok(None)`: not SLC-shaped.
pub fn parse(s: &str, original: &str) -> Result<Option<Slc>, Invalid> {
    parse_text(s, original).map_err(Invalid::Address)
}

fn parse_text(s: &str, original: &str) -> Result<Option<Slc>, String> {
    // `B3/17`: a bit of the file counted from its start.
    if !s.contains(':') {
        let Some((file, bit)) = s.split_once('/') else {
            return Ok(None);
        };
        let Some(('B', f)) = file_of(file) else { return Ok(None) };
        let bit = number(bit, "bit", original)?;
        if bit >= FILE_ELEMENTS * 16 {
            return Err(format!(
                "`{original}`: a bit file has {} bits (B{f}/0 to B{f}/{})",
                FILE_ELEMENTS * 16,
                FILE_ELEMENTS * 16 - 1
            ));
        }
        return data(original, 'B', f, bit / 16, Some(bit % 16)).map(Some);
    }
    let Some((area, rest)) = s.split_once(':') else {
        return Ok(None);
    };
    if area == "I" || area == "O" {
        return io(area == "I", rest, original).map(Some);
    }
    let Some((letter, f)) = file_of(area) else {
        return Ok(None);
    };
    if matches!(letter, 'T' | 'C') {
        let (elem, member) = match rest.split_once('.') {
            Some((e, m)) => (e, Some(m.to_string())),
            None => (rest, None),
        };
        if member.as_deref().is_some_and(|m| m.contains(['.', '/'])) || elem.contains('/') {
            return Err(format!(
                "`{original}`: a {} element is {letter}{f}:e or {letter}{f}:e.MEMBER (like {letter}{f}:0.{})",
                if letter == 'T' { "timer" } else { "counter" },
                if letter == 'T' { "ACC" } else { "DN" }
            ));
        }
        let file = number(f, "file number", original)?;
        if file > 255 {
            return Err(format!("`{original}`: file numbers go from 0 to 255"));
        }
        let element = number(elem, "element", original)?;
        if element >= FILE_ELEMENTS {
            return Err(format!("`{original}`: elements go from 0 to {}", FILE_ELEMENTS - 1));
        }
        let st = SlcStruct {
            counter: letter == 'C',
            file: file as u8,
            element: element as u8,
        };
        return Ok(Some(Slc::Struct(st, member)));
    }
    let (elem, bit) = match rest.split_once('/') {
        Some((e, b)) => (e, Some(number(b, "bit", original)?)),
        None => (rest, None),
    };
    let elem = number(elem, "element", original)?;
    data(original, letter, f, elem, bit).map(Some)
}

/// `I:e/b`, `I:e.0/b`, `O:e/b`: a digital channel, 16 per slot.
fn io(input: bool, rest: &str, original: &str) -> Result<Slc, String> {
    let l = if input { 'I' } else { 'O' };
    let Some((slot, bit)) = rest.split_once('/') else {
        return Err(format!(
            "`{original}`: Alba maps the bits of the SLC 500's I/O words ({l}:e/b, b from 0 to 15), not whole words; use an analog address (AI:3/n, AO:4/n) for a value"
        ));
    };
    let slot = match slot.split_once('.') {
        Some((e, "0")) => e,
        Some(_) => {
            return Err(format!(
                "`{original}`: Alba maps one 16-bit word per slot ({l}:e.0/b, or {l}:e/b)"
            ));
        }
        None => slot,
    };
    let e = number(slot, "slot", original)?;
    let b = number(bit, "bit", original)?;
    if b > 15 {
        return Err(format!("`{original}`: bits of an SLC 500 word go from 0 to 15"));
    }
    let n = e.saturating_mul(16).saturating_add(b);
    if n >= crate::address::MAX_DIGITAL {
        return Err(format!(
            "`{original}`: slots go from 0 to {} (16 channels each)",
            crate::address::MAX_DIGITAL / 16 - 1
        ));
    }
    Ok(Slc::Address(
        if input {
            Address::DigitalIn(n)
        } else {
            Address::DigitalOut(n)
        },
        DataType::Bool,
    ))
}

/// A B, N or F file element (or a bit of it).
fn data(original: &str, letter: char, f: &str, elem: u32, bit: Option<u32>) -> Result<Slc, String> {
    let file = number(f, "file number", original)?;
    let Some(&(_, _, first, size)) = DATA_FILES.iter().find(|d| d.0 == letter && d.1 == file) else {
        let known: Vec<String> = DATA_FILES.iter().map(|d| format!("{}{}", d.0, d.1)).collect();
        return Err(format!(
            "`{original}`: Alba maps the SLC 500 data files {} and the timer and counter files (T4, C5); {letter}{file} is not one of them",
            known.join(", ")
        ));
    };
    if elem >= FILE_ELEMENTS {
        return Err(format!(
            "`{original}`: elements go from 0 to {} ({letter}{file}:0 to {letter}{file}:{})",
            FILE_ELEMENTS - 1,
            FILE_ELEMENTS - 1
        ));
    }
    let byte = first + elem * size;
    match (letter, bit) {
        ('F', Some(_)) => Err(format!("`{original}`: a float (F) element has no bits")),
        ('F', None) => Ok(Slc::Address(
            Address::Marker {
                byte,
                width: MarkerWidth::DWord,
            },
            DataType::Real,
        )),
        (_, Some(b)) if b > 15 => Err(format!("`{original}`: bits of an SLC 500 word go from 0 to 15")),
        // Big-endian words: bits 0-7 are the second byte.
        (_, Some(b)) => Ok(Slc::Address(
            Address::Marker {
                byte: byte + 1 - b / 8,
                width: MarkerWidth::Bit((b % 8) as u8),
            },
            DataType::Bool,
        )),
        (_, None) => Ok(Slc::Address(
            Address::Marker {
                byte,
                width: MarkerWidth::Word,
            },
            DataType::Int,
        )),
    }
}

/// The SLC 500 notation of an address, where it has one: digital channels
/// and the marker bytes of the data files.
pub fn notation(a: Address) -> Option<String> {
    match a {
        Address::DigitalIn(n) => Some(format!("I:{}/{}", n / 16, n % 16)),
        Address::DigitalOut(n) => Some(format!("O:{}/{}", n / 16, n % 16)),
        Address::AnalogIn(_) | Address::AnalogOut(_) => None,
        Address::Marker { byte, width } => {
            let &(l, f, first, _) = DATA_FILES
                .iter()
                .find(|d| (d.2..d.2 + FILE_ELEMENTS * d.3).contains(&byte))?;
            let off = byte - first;
            match (l, width) {
                ('F', MarkerWidth::DWord) if off % 4 == 0 => Some(format!("F{f}:{}", off / 4)),
                ('B' | 'N', MarkerWidth::Word) if off % 2 == 0 => Some(format!("{l}{f}:{}", off / 2)),
                ('B' | 'N', MarkerWidth::Bit(b)) => {
                    let b = u32::from(b) + if off % 2 == 0 { 8 } else { 0 };
                    Some(format!("{l}{f}:{}/{b}", off / 2))
                }
                _ => None,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Slc {
        parse(&s.to_ascii_uppercase(), s).unwrap().unwrap()
    }
    fn addr(s: &str) -> (Address, DataType) {
        match p(s) {
            Slc::Address(a, t) => (a, t),
            other => panic!("{s}: {other:?}"),
        }
    }

    #[test]
    fn each_file_type_maps_onto_alba_memory() {
        assert_eq!(addr("I:1/0"), (Address::DigitalIn(16), DataType::Bool));
        assert_eq!(addr("i:0.0/15"), (Address::DigitalIn(15), DataType::Bool));
        assert_eq!(addr("O:0/3"), (Address::DigitalOut(3), DataType::Bool));
        let m = |byte, width| Address::Marker { byte, width };
        assert_eq!(addr("B3:0/1"), (m(1, MarkerWidth::Bit(1)), DataType::Bool));
        assert_eq!(addr("B3:0/9"), (m(0, MarkerWidth::Bit(1)), DataType::Bool));
        assert_eq!(addr("B3/17"), addr("B3:1/1"));
        assert_eq!(addr("B3:2"), (m(4, MarkerWidth::Word), DataType::Int));
        assert_eq!(addr("N7:2"), (m(516, MarkerWidth::Word), DataType::Int));
        assert_eq!(addr("N9:1"), (m(2050, MarkerWidth::Word), DataType::Int));
        assert_eq!(addr("N10:22"), (m(2604, MarkerWidth::Word), DataType::Int));
        assert_eq!(addr("F8:0"), (m(1024, MarkerWidth::DWord), DataType::Real));
        assert_eq!(addr("F8:255"), (m(2044, MarkerWidth::DWord), DataType::Real));
        let st = |counter, file, element| SlcStruct { counter, file, element };
        assert_eq!(p("T4:0.ACC"), Slc::Struct(st(false, 4, 0), Some("ACC".into())));
        assert_eq!(p("C5:1.DN"), Slc::Struct(st(true, 5, 1), Some("DN".into())));
        assert_eq!(p("T4:7"), Slc::Struct(st(false, 4, 7), None));
        assert_eq!(st(true, 5, 1).to_string(), "C5:1");
    }

    #[test]
    fn the_files_do_not_overlap_and_fit_the_marker_memory() {
        let mut ranges: Vec<(u32, u32)> = DATA_FILES.iter().map(|d| (d.2, d.2 + FILE_ELEMENTS * d.3)).collect();
        ranges.sort();
        for w in ranges.windows(2) {
            assert!(w[0].1 <= w[1].0, "{w:?}");
        }
        assert!(ranges.iter().all(|r| r.1 <= crate::address::MARKER_BYTES));
    }

    #[test]
    fn notation_reparses_to_the_same_address() {
        for s in [
            "I:1/0", "O:0/3", "I:3/15", "B3:0/1", "B3:0/9", "B3:4", "N7:2", "F8:3", "N9:0", "N10:22",
        ] {
            let (a, _) = addr(s);
            let n = notation(a).unwrap_or_else(|| panic!("{s} has no notation"));
            assert_eq!(addr(&n).0, a, "{s} → {n}");
        }
        assert_eq!(notation(Address::AnalogIn(0)), None);
        assert_eq!(
            notation(Address::Marker {
                byte: 3100,
                width: MarkerWidth::Word
            }),
            None
        );
    }

    #[test]
    fn bad_addresses_are_explained() {
        for (s, needle) in [
            ("N7:256", "0 to 255"),
            ("N12:0", "N12 is not one of them"),
            ("B3:0/16", "0 to 15"),
            ("B3/4096", "4096 bits"),
            ("F8:0/1", "no bits"),
            ("I:1", "not whole words"),
            ("I:1.1/0", "one 16-bit word per slot"),
            ("O:0/16", "0 to 15"),
            ("I:512/0", "slots go from 0 to 511"),
            ("N7:x", "number for the element"),
            ("T4:0.ACC.X", "T4:e.MEMBER"),
            ("T4:256", "0 to 255"),
            ("T300:0", "0 to 255"),
        ] {
            let e = parse(&s.to_ascii_uppercase(), s).unwrap_err();
            assert!(e.to_string().contains(needle), "{s}: {e}");
        }
    }

    #[test]
    fn other_text_is_not_slc() {
        for s in [
            "Start", "B3", "N7", "T4", "DI:1/0", "%IX0.0", "Delay.DN", "X:1/0", "T37",
        ] {
            assert_eq!(parse(&s.to_ascii_uppercase(), s), Ok(None), "{s}");
        }
    }
}
