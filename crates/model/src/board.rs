//! Arduino boards and pin maps (SPEC §7.1): which pin each I/O channel of
//! the image is wired to, and what each board has.

use crate::address::Address;
use std::fmt;

/// A board Alba builds firmware for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    Uno,
    Nano,
    Mega,
}

impl Model {
    pub const ALL: &'static [Model] = &[Model::Uno, Model::Nano, Model::Mega];

    pub fn parse(s: &str) -> Option<Model> {
        Model::ALL.iter().copied().find(|m| m.name().eq_ignore_ascii_case(s))
    }

    pub fn name(self) -> &'static str {
        match self {
            Model::Uno => "uno",
            Model::Nano => "nano",
            Model::Mega => "mega",
        }
    }

    /// As users write it in messages.
    pub fn title(self) -> &'static str {
        match self {
            Model::Uno => "Arduino Uno",
            Model::Nano => "Arduino Nano",
            Model::Mega => "Arduino Mega 2560",
        }
    }

    pub fn mcu(self) -> &'static str {
        match self {
            Model::Uno | Model::Nano => "atmega328p",
            Model::Mega => "atmega2560",
        }
    }

    /// Flash bytes a sketch may use (the bootloader takes the rest) and RAM bytes.
    pub fn limits(self) -> (u32, u32) {
        match self {
            Model::Uno | Model::Nano => (32_256, 2_048),
            Model::Mega => (253_952, 8_192),
        }
    }

    fn digital_pins(self) -> u8 {
        match self {
            Model::Uno | Model::Nano => 14,
            Model::Mega => 54,
        }
    }

    fn analog_pins(self) -> u8 {
        match self {
            Model::Uno => 6,
            Model::Nano => 8,
            Model::Mega => 16,
        }
    }

    /// Analog pins that can only be read by the ADC (the Nano's A6 and A7).
    fn analog_only(self, n: u8) -> bool {
        self == Model::Nano && n >= 6
    }

    fn pwm(self, d: u8) -> bool {
        match self {
            Model::Uno | Model::Nano => matches!(d, 3 | 5 | 6 | 9 | 10 | 11),
            Model::Mega => (2..=13).contains(&d) || (44..=46).contains(&d),
        }
    }

    /// Every pin of the board, digital then analog (`D0`…, `A0`…).
    pub fn all_pins(self) -> Vec<Pin> {
        (0..self.digital_pins())
            .map(Pin::D)
            .chain((0..self.analog_pins()).map(Pin::A))
            .collect()
    }

    /// What `pin` can do on this board: the directions of `[board]` it may
    /// serve (`di`, `do`, `ai`, `ao`), or `serial` for D0/D1 (the link to the PC).
    pub fn caps(self, pin: Pin) -> Vec<&'static str> {
        if matches!(pin, Pin::D(0 | 1)) {
            return vec!["serial"];
        }
        Dir::ALL
            .iter()
            .filter(|d| self.refuses(pin, **d).is_none())
            .map(|d| d.key())
            .collect()
    }

    /// Why `pin` cannot serve `dir` on this board, if it cannot.
    pub fn refuses(self, pin: Pin, dir: Dir) -> Option<String> {
        let board = self.title();
        match pin {
            Pin::D(n) if n >= self.digital_pins() => Some(format!(
                "the {board} has no pin {pin} (D0-D{})",
                self.digital_pins() - 1
            )),
            Pin::A(n) if n >= self.analog_pins() => Some(format!(
                "the {board} has no pin {pin} (A0-A{}){}",
                self.analog_pins() - 1,
                if n < 8 { "; A6 and A7 are on the Nano" } else { "" }
            )),
            Pin::D(0 | 1) => Some(format!("{pin} is the serial link (RX/TX) to the PC")),
            Pin::D(n) if dir == Dir::AnalogIn => Some(format!(
                "{pin} is not an analog input (D{n}); analog inputs are A0-A{}",
                self.analog_pins() - 1
            )),
            Pin::D(n) if dir == Dir::AnalogOut && !self.pwm(n) => {
                Some(format!("{pin} has no PWM, so it cannot be an analog output"))
            }
            Pin::A(_) if dir == Dir::AnalogOut => Some(format!("{pin} has no PWM, so it cannot be an analog output")),
            Pin::A(n) if matches!(dir, Dir::DigitalIn | Dir::DigitalOut) && self.analog_only(n) => {
                Some(format!("{pin} of the {board} is an analog input only"))
            }
            _ => None,
        }
    }
}

/// A pin as the Arduino IDE names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pin {
    D(u8),
    A(u8),
}

impl Pin {
    pub fn parse(s: &str) -> Option<Pin> {
        let s = s.trim();
        let (kind, n) = s.split_at_checked(1)?;
        let n: u8 = n.parse().ok()?;
        match kind {
            "D" | "d" => Some(Pin::D(n)),
            "A" | "a" => Some(Pin::A(n)),
            _ => None,
        }
    }
}

impl fmt::Display for Pin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Pin::D(n) => write!(f, "D{n}"),
            Pin::A(n) => write!(f, "A{n}"),
        }
    }
}

/// The four directions of the I/O image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    DigitalIn,
    DigitalOut,
    AnalogIn,
    AnalogOut,
}

impl Dir {
    pub const ALL: [Dir; 4] = [Dir::DigitalIn, Dir::DigitalOut, Dir::AnalogIn, Dir::AnalogOut];

    /// The key of this direction in `[board]`.
    pub fn key(self) -> &'static str {
        match self {
            Dir::DigitalIn => "di",
            Dir::DigitalOut => "do",
            Dir::AnalogIn => "ai",
            Dir::AnalogOut => "ao",
        }
    }

    /// Channel `n` in the AuroraLD notation.
    pub fn address(self, n: usize) -> String {
        match self {
            Dir::DigitalIn => format!("DI:1/{n}"),
            Dir::DigitalOut => format!("DO:2/{n}"),
            Dir::AnalogIn => format!("AI:3/{n}"),
            Dir::AnalogOut => format!("AO:4/{n}"),
        }
    }
}

/// Pins of the channels 0, 1, 2 … of each direction.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct PinMap {
    pub di: Vec<Pin>,
    pub r#do: Vec<Pin>,
    pub ai: Vec<Pin>,
    pub ao: Vec<Pin>,
}

pub const PRESETS: &[&str] = &["aurora", "s7", "openplc"];

impl PinMap {
    /// A preset of SPEC §7.1.
    pub fn preset(name: &str) -> Option<PinMap> {
        let d = |v: &[u8]| v.iter().map(|n| Pin::D(*n)).collect::<Vec<_>>();
        let a = |v: &[u8]| v.iter().map(|n| Pin::A(*n)).collect::<Vec<_>>();
        match name.to_ascii_lowercase().as_str() {
            // AuroraLD / PLC1805.
            "aurora" => Some(PinMap {
                di: d(&[2, 3, 4, 5, 7, 8]),
                r#do: [d(&[12, 13]), a(&[0, 1, 2, 3])].concat(),
                ai: a(&[4, 5, 6, 7]),
                ao: d(&[6, 9, 10, 11]),
            }),
            // The 2014 thesis (source 001): I0.0-I0.5, Q0.0-Q0.5, Ain0-5.
            "s7" => Some(PinMap {
                di: d(&[2, 3, 4, 5, 6, 7]),
                r#do: d(&[8, 9, 10, 11, 12, 13]),
                ai: a(&[0, 1, 2, 3, 4, 5]),
                ao: Vec::new(),
            }),
            // OpenPLC's Uno layout: %IX0.0-0.4, %QX0.0-0.3, %IW0-5, %QW0-2.
            "openplc" => Some(PinMap {
                di: d(&[2, 3, 4, 5, 6]),
                r#do: d(&[7, 8, 12, 13]),
                ai: a(&[0, 1, 2, 3, 4, 5]),
                ao: d(&[9, 10, 11]),
            }),
            _ => None,
        }
    }

    pub fn pins(&self, dir: Dir) -> &[Pin] {
        match dir {
            Dir::DigitalIn => &self.di,
            Dir::DigitalOut => &self.r#do,
            Dir::AnalogIn => &self.ai,
            Dir::AnalogOut => &self.ao,
        }
    }

    pub fn pins_mut(&mut self, dir: Dir) -> &mut Vec<Pin> {
        match dir {
            Dir::DigitalIn => &mut self.di,
            Dir::DigitalOut => &mut self.r#do,
            Dir::AnalogIn => &mut self.ai,
            Dir::AnalogOut => &mut self.ao,
        }
    }

    /// The pin of an I/O address, or why there is none; `None` for markers.
    pub fn pin_of(&self, model: Model, addr: Address) -> Option<Result<Pin, String>> {
        let (dir, n) = match addr {
            Address::DigitalIn(n) => (Dir::DigitalIn, n),
            Address::DigitalOut(n) => (Dir::DigitalOut, n),
            Address::AnalogIn(n) => (Dir::AnalogIn, n),
            Address::AnalogOut(n) => (Dir::AnalogOut, n),
            Address::Marker { .. } => return None,
        };
        let pins = self.pins(dir);
        let n = n as usize;
        Some(match pins.get(n) {
            None => Err(format!(
                "{} is not wired: the pin map has {} channel{} there ({})",
                dir.address(n),
                pins.len(),
                if pins.len() == 1 { "" } else { "s" },
                if pins.is_empty() {
                    "none".to_string()
                } else {
                    format!("{} to {}", dir.address(0), dir.address(pins.len() - 1))
                }
            )),
            Some(&p) => match model.refuses(p, dir) {
                Some(why) => Err(format!("{} is pin {p}, but {why}", dir.address(n))),
                None => Ok(p),
            },
        })
    }

    /// Pins used by two channels.
    pub fn shared(&self) -> Option<Pin> {
        let all: Vec<Pin> = Dir::ALL.iter().flat_map(|d| self.pins(*d).iter().copied()).collect();
        all.iter()
            .enumerate()
            .find(|(i, p)| all[..*i].contains(p))
            .map(|(_, p)| *p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pins_and_their_capabilities() {
        assert_eq!(Model::Nano.all_pins().len(), 14 + 8);
        assert_eq!(Model::Mega.all_pins().len(), 54 + 16);
        assert_eq!(Model::Uno.caps(Pin::D(1)), ["serial"]);
        assert_eq!(Model::Uno.caps(Pin::D(3)), ["di", "do", "ao"]);
        assert_eq!(Model::Uno.caps(Pin::D(4)), ["di", "do"]);
        assert_eq!(Model::Nano.caps(Pin::A(0)), ["di", "do", "ai"]);
        assert_eq!(Model::Nano.caps(Pin::A(7)), ["ai"]);
        assert!(Model::Uno.caps(Pin::A(7)).is_empty());
    }

    #[test]
    fn presets_on_boards() {
        let aurora = PinMap::preset("Aurora").unwrap();
        assert_eq!(aurora.pin_of(Model::Nano, Address::AnalogIn(2)), Some(Ok(Pin::A(6))));
        assert_eq!(
            aurora.pin_of(Model::Uno, Address::AnalogIn(2)),
            Some(Err(
                "AI:3/2 is pin A6, but the Arduino Uno has no pin A6 (A0-A5); A6 and A7 are on the Nano".into()
            ))
        );
        assert_eq!(aurora.pin_of(Model::Uno, Address::DigitalOut(2)), Some(Ok(Pin::A(0))));
        assert_eq!(
            aurora.pin_of(Model::Uno, Address::DigitalIn(6)),
            Some(Err(
                "DI:1/6 is not wired: the pin map has 6 channels there (DI:1/0 to DI:1/5)".into()
            ))
        );
        let s7 = PinMap::preset("s7").unwrap();
        assert_eq!(
            s7.pin_of(Model::Mega, Address::AnalogOut(0)),
            Some(Err(
                "AO:4/0 is not wired: the pin map has 0 channels there (none)".into()
            ))
        );
        for p in PRESETS {
            let m = PinMap::preset(p).unwrap();
            assert_eq!(m.shared(), None, "{p}");
            for model in [Model::Nano, Model::Mega] {
                for dir in Dir::ALL {
                    for pin in m.pins(dir) {
                        assert_eq!(model.refuses(*pin, dir), None, "{p} {pin} on {model:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn pins_that_cannot_serve() {
        assert_eq!(Pin::parse("d13"), Some(Pin::D(13)));
        assert_eq!(Pin::parse("A"), None);
        assert_eq!(Pin::parse("x1"), None);
        assert!(
            Model::Uno
                .refuses(Pin::D(0), Dir::DigitalIn)
                .unwrap()
                .contains("serial")
        );
        assert!(
            Model::Uno
                .refuses(Pin::D(7), Dir::AnalogOut)
                .unwrap()
                .contains("no PWM")
        );
        assert!(
            Model::Uno
                .refuses(Pin::D(7), Dir::AnalogIn)
                .unwrap()
                .contains("not an analog input")
        );
        assert!(
            Model::Nano
                .refuses(Pin::A(7), Dir::DigitalOut)
                .unwrap()
                .contains("analog input only")
        );
        assert!(
            Model::Uno
                .refuses(Pin::D(14), Dir::DigitalOut)
                .unwrap()
                .contains("no pin D14")
        );
        assert_eq!(Model::Mega.refuses(Pin::D(45), Dir::AnalogOut), None);
        assert_eq!(Model::Mega.refuses(Pin::A(15), Dir::DigitalIn), None);
    }
}
