//! `[board]`: the Arduino board and its wiring (pin maps in `alba_model::board`).

use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_model::board::{Dir, Model, PRESETS, Pin, PinMap};
use serde::Deserialize;
use serde_spanned::Spanned;

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
    /// The serial port the board is on (`/dev/ttyUSB0`), as the studio's
    /// Hardware tab and `alba download` offer it first.
    pub port: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBoard {
    model: Spanned<String>,
    pinmap: Option<Spanned<String>>,
    di: Option<Spanned<Vec<Spanned<String>>>>,
    r#do: Option<Spanned<Vec<Spanned<String>>>>,
    ai: Option<Spanned<Vec<Spanned<String>>>>,
    ao: Option<Spanned<Vec<Spanned<String>>>>,
    #[serde(default)]
    active_low: bool,
    power_up_on: Option<Vec<Spanned<String>>>,
    port: Option<Spanned<String>>,
}

/// Validates `[board]`: the model, the pin map and the pins it lists.
pub(super) fn board(b: RawBoard, file: FileId, diags: &mut Vec<Diagnostic>) -> Board {
    let sp = |r: std::ops::Range<usize>| Span::new(file, r);
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
        port: b.port.and_then(|p| {
            let path = p.get_ref().trim();
            if path.is_empty() {
                diags.push(Diagnostic::new(
                    Code::ConfigField,
                    "`port` is empty",
                    sp(p.span()),
                    "a serial port's path, as /dev/ttyUSB0",
                ));
                None
            } else {
                Some(path.to_string())
            }
        }),
    }
}
