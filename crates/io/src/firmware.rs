//! The remote-I/O firmware of controller mode (`alba firmware`, SPEC §7.2):
//! a sketch that makes an Arduino the I/O of `alba run --io arduino:…`,
//! with the board's pin map baked in. Two links: a Modbus RTU slave
//! (default) and the AuroraLD text protocol.

use alba_model::board::{Dir, Model, Pin, PinMap};
use std::path::{Path, PathBuf};

const MODBUS_TEMPLATE: &str = include_str!("firmware/modbus.cpp");
const AURORA_TEMPLATE: &str = include_str!("firmware/aurora.cpp");

/// The serial protocol between the PC and the board.
/// Why a controller firmware cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum FirmwareError {
    /// The specification does not fit the board (the message says where).
    #[error("{0}")]
    Spec(String),
    #[error("cannot write {}: {source}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Link {
    Modbus,
    Aurora,
}

impl Link {
    pub fn parse(s: &str) -> Option<Link> {
        match s.to_ascii_lowercase().as_str() {
            "modbus" | "rtu" => Some(Link::Modbus),
            "aurora" | "aurorald" => Some(Link::Aurora),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Link::Modbus => "modbus",
            Link::Aurora => "aurora",
        }
    }
}

/// Baud rate of both links (SPEC §7.2).
pub const BAUD: u32 = 115_200;
/// The AuroraLD board id of the PLC1805.
pub const AURORA_ID: u32 = 5518;
/// Default link watchdog of the board.
pub const WATCHDOG_MS: u32 = 500;
/// The AuroraLD report period.
pub const AURORA_PERIOD_MS: u32 = 20;

/// What a firmware is generated from.
#[derive(Debug, Clone)]
pub struct Spec {
    pub model: Model,
    /// Name of the preset the map came from (for the sketch's header).
    pub pinmap: String,
    pub map: PinMap,
    pub active_low: bool,
    /// Inputs use the pin's pull-up and are on when the pin is LOW (a
    /// button or a contact to GND).
    pub pullup: bool,
    pub link: Link,
    /// Modbus slave id (1-247).
    pub slave: u8,
    /// Outputs go off when no valid request came for this long.
    pub watchdog_ms: u32,
    /// Digital output pins on at power-up and in the safe state.
    pub power_up_on: Vec<Pin>,
}

impl Spec {
    pub fn new(model: Model, pinmap: &str, map: PinMap, link: Link) -> Spec {
        Spec {
            model,
            pinmap: pinmap.to_string(),
            map,
            active_low: false,
            pullup: false,
            link,
            slave: 1,
            watchdog_ms: WATCHDOG_MS,
            power_up_on: Vec::new(),
        }
    }

    /// Every pin of the map checked against the board.
    pub fn check(&self) -> Result<(), FirmwareError> {
        self.check_text().map_err(FirmwareError::Spec)
    }

    fn check_text(&self) -> Result<(), String> {
        if !(1..=247).contains(&self.slave) {
            return Err(format!("slave id {} is not 1-247", self.slave));
        }
        if self.watchdog_ms == 0 {
            return Err("the link watchdog must be at least 1 ms".into());
        }
        for dir in Dir::ALL {
            for (n, pin) in self.map.pins(dir).iter().enumerate() {
                if let Some(why) = self.model.refuses(*pin, dir) {
                    return Err(format!("{} is pin {pin}, but {why}", dir.address(n)));
                }
            }
        }
        if let Some(p) = self.map.shared() {
            return Err(format!("pin {p} serves two channels"));
        }
        Ok(())
    }
}

/// The pin as the Arduino core names it (`13`, `A4`).
fn pin_expr(p: Pin) -> String {
    match p {
        Pin::D(n) => n.to_string(),
        Pin::A(n) => format!("A{n}"),
    }
}

/// The sketch's source text.
pub fn generate(spec: &Spec) -> Result<String, FirmwareError> {
    spec.check()?;
    let template = match spec.link {
        Link::Modbus => MODBUS_TEMPLATE,
        Link::Aurora => AURORA_TEMPLATE,
    };
    let pins = |d: Dir| {
        spec.map
            .pins(d)
            .iter()
            .map(|p| pin_expr(*p))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let n = |d: Dir| spec.map.pins(d).len();
    let last = |d: Dir| match n(d) {
        0 => "(none)".to_string(),
        k => (k - 1).to_string(),
    };
    let subs: Vec<(&str, String)> = vec![
        ("@TITLE@", spec.model.title().to_string()),
        ("@PINMAP@", spec.pinmap.clone()),
        ("@BAUD@", BAUD.to_string()),
        ("@SLAVE@", spec.slave.to_string()),
        ("@WATCHDOG_MS@", spec.watchdog_ms.to_string()),
        ("@PERIOD_MS@", AURORA_PERIOD_MS.to_string()),
        ("@BOARD_ID@", AURORA_ID.to_string()),
        ("@ACTIVE_LOW@", u8::from(spec.active_low).to_string()),
        ("@PULLUP@", u8::from(spec.pullup).to_string()),
        (
            "@PULLUP_NOTE@",
            if spec.pullup { ", pull-up: on = LOW" } else { "" }.to_string(),
        ),
        (
            "@ACTIVE_NOTE@",
            if spec.active_low { ", active low: on = LOW" } else { "" }.to_string(),
        ),
        ("@N_DI@", n(Dir::DigitalIn).to_string()),
        ("@N_DO@", n(Dir::DigitalOut).to_string()),
        ("@N_AI@", n(Dir::AnalogIn).to_string()),
        ("@N_AO@", n(Dir::AnalogOut).to_string()),
        ("@LAST_DI@", last(Dir::DigitalIn)),
        ("@LAST_DO@", last(Dir::DigitalOut)),
        ("@LAST_AI@", last(Dir::AnalogIn)),
        ("@LAST_AO@", last(Dir::AnalogOut)),
        ("@DI_PINS@", pins(Dir::DigitalIn)),
        ("@DO_PINS@", pins(Dir::DigitalOut)),
        (
            "@DO_POWER_UP@",
            spec.map
                .pins(Dir::DigitalOut)
                .iter()
                .map(|p| if spec.power_up_on.contains(p) { "1" } else { "0" })
                .collect::<Vec<_>>()
                .join(", "),
        ),
        ("@AI_PINS@", pins(Dir::AnalogIn)),
        ("@AO_PINS@", pins(Dir::AnalogOut)),
    ];
    let mut out = template.to_string();
    for (k, v) in subs {
        out = out.replace(k, &v);
    }
    debug_assert!(!out.contains('@'), "a template placeholder was left");
    Ok(out)
}

/// Writes the sketch into `dir` as `<dir name>.ino` (the Arduino IDE opens
/// a sketch folder whose name is the sketch's), creating `dir`.
pub fn write(spec: &Spec, dir: &Path) -> Result<PathBuf, FirmwareError> {
    let text = generate(spec)?;
    let failed = |path: &Path, source| FirmwareError::Write {
        path: path.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(|e| failed(dir, e))?;
    let stem = dir
        .canonicalize()
        .ok()
        .and_then(|d| d.file_name().map(|s| s.to_string_lossy().into_owned()))
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "alba_remote_io".to_string());
    let path = dir.join(format!("{stem}.ino"));
    let tmp = dir.join(format!(".{stem}.ino.tmp"));
    std::fs::write(&tmp, text).map_err(|e| failed(&tmp, e))?;
    std::fs::rename(&tmp, &path).map_err(|e| failed(&path, e))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn golden(name: &str, text: &str) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(name);
        if std::env::var_os("ALBA_BLESS").is_some() {
            std::fs::create_dir_all(path.parent().expect("dir")).expect("mkdir");
            std::fs::write(&path, text).expect("bless");
        }
        let want = std::fs::read_to_string(&path).expect("golden");
        assert!(
            want == text,
            "{name} differs from its golden file (ALBA_BLESS=1 to re-bless)"
        );
    }

    #[test]
    fn modbus_sketch_for_the_aurora_nano() {
        let map = PinMap::preset("aurora").expect("preset");
        let text = generate(&Spec::new(Model::Nano, "aurora", map, Link::Modbus)).expect("sketch");
        assert!(text.contains("static const uint8_t DI_PIN[N_DI + 1] = {2, 3, 4, 5, 7, 8};"));
        assert!(text.contains("static const uint8_t AI_PIN[N_AI + 1] = {A4, A5, A6, A7};"));
        golden("modbus-nano-aurora.ino", &text);
    }

    #[test]
    fn aurora_sketch_active_low() {
        let map = PinMap::preset("aurora").expect("preset");
        let mut spec = Spec::new(Model::Nano, "aurora", map, Link::Aurora);
        spec.active_low = true;
        spec.power_up_on = vec![Pin::D(13), Pin::A(2)];
        let text = generate(&spec).expect("sketch");
        assert!(text.contains("#define ALBA_ACTIVE_LOW 1"));
        // DO pins D12 D13 A0 A1 A2 A3: D13 and A2 power up on.
        assert!(text.contains("DO_POWER_UP[N_DO + 1] = {0, 1, 0, 0, 1, 0};"), "{text}");
        golden("aurora-nano-aurora-active-low.ino", &text);
    }

    #[test]
    fn pins_the_board_lacks_are_refused() {
        let map = PinMap::preset("aurora").expect("preset");
        let e = generate(&Spec::new(Model::Uno, "aurora", map.clone(), Link::Modbus)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "AI:3/2 is pin A6, but the Arduino Uno has no pin A6 (A0-A5); A6 and A7 are on the Nano"
        );
        let mut s = Spec::new(Model::Nano, "aurora", map, Link::Modbus);
        s.slave = 0;
        assert_eq!(generate(&s).unwrap_err().to_string(), "slave id 0 is not 1-247");
    }
}
