//! SCADA screens (issue 17, SPEC §8): `hmi/<screen>.json` in the project, one
//! screen per file, versioned by `schema`. Parsing checks everything a screen
//! can get wrong — the JSON, the schema, every element's type and geometry,
//! every animation's kind, tag and parameters, every write action — and
//! reports each problem as `E141` at its place in the file (line and column
//! of the offending value), so the designer can put it on the element.
//!
//! Tags are checked through the caller's `resolve` (the running program's
//! layout), which says what a name holds.

use alba_diag::{Code, Diagnostic, FileId, Span};
use serde::{Deserialize, Serialize};
use serde_json::Value as Json;
use std::collections::HashMap;

/// The schema this version writes and reads.
pub const SCHEMA: u32 = 1;

/// AuroraLD's 30 elements (SPEC §8) and the PID faceplate of `004_…`, by the
/// names screens use.
pub const ELEMENT_TYPES: &[(&str, &str)] = &[
    ("text", "a static or live text"),
    ("input", "an input box that writes a number or a BOOL"),
    ("output", "an output box showing a value"),
    ("rectangle", "a rectangle"),
    ("circle", "a circle or ellipse"),
    ("button", "a momentary push button"),
    ("switch", "a latching switch"),
    ("line", "a line"),
    ("polygon", "a polygon"),
    ("slider", "a slider that writes a number"),
    ("led", "an indicator lamp"),
    ("arc", "an arc"),
    ("wind_turbine", "a wind turbine"),
    ("fan", "a fan"),
    ("cooling_tower", "a cooling tower"),
    ("plc", "a PLC"),
    ("clock", "a clock"),
    ("image", "an image"),
    ("bottle", "a bottle"),
    ("motor", "a motor"),
    ("pump", "a pump"),
    ("tank", "a tank or silo"),
    ("pipe", "a pipe"),
    ("valve", "a valve"),
    ("building", "a building"),
    ("transmission_tower", "a transmission tower"),
    ("safety_sign", "a safety sign"),
    ("meter", "a bar or circular meter"),
    ("alarm", "an alarm indicator"),
    ("trend", "a trend graph"),
    (
        "faceplate",
        "a PID loop's faceplate (SP, PV, CV; opens the full faceplate)",
    ),
];

/// What an animation parameter holds: what the screen check accepts and the
/// designer's form shows (a number field with its unit and range, a check
/// box, a colour picker, a choice, or the colour intervals).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamKind {
    Number {
        min: f64,
        max: f64,
        unit: &'static str,
    },
    Bool,
    Color,
    Choice(&'static [&'static str]),
    Intervals,
    /// Free text of at most `max_len` characters.
    Text {
        max_len: usize,
    },
    /// A tag's name (a value, not a structure).
    Tag,
    /// Up to `max` points `[x, y]` in the element's box.
    Points {
        max: usize,
    },
    /// Up to `max` pens `{tag, color}` (a trend's): each a value tag and,
    /// optionally, a colour.
    Pens {
        max: usize,
    },
}

/// The most pens a trend element draws.
pub const MAX_TREND_PENS: usize = 3;

/// A parameter of an animation besides `tag`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    pub name: &'static str,
    pub kind: ParamKind,
    /// What it does, for the designer's form.
    pub help: &'static str,
    /// Still read, no longer offered by the form (`blink`'s `period_ms`).
    pub legacy: bool,
}

const fn p(name: &'static str, kind: ParamKind, help: &'static str) -> Param {
    Param {
        name,
        kind,
        help,
        legacy: false,
    }
}

const ANY: f64 = 1e12;
const fn number(unit: &'static str) -> ParamKind {
    ParamKind::Number {
        min: -ANY,
        max: ANY,
        unit,
    }
}
const MS: ParamKind = ParamKind::Number {
    min: 10.0,
    max: 600_000.0,
    unit: "ms",
};
const WHEN: Param = p(
    "when",
    ParamKind::Bool,
    "active while the tag is on (off: while it is off, or outside min–max)",
);
const LO: Param = p("min", number(""), "the tag's value at the start of the range");
const HI: Param = p("max", number(""), "the tag's value at the end of the range");
const RANGE_LO: Param = p(
    "min",
    number(""),
    "a number tag: active from this value (digital when neither min nor max is set)",
);
const RANGE_HI: Param = p("max", number(""), "a number tag: active up to this value");

/// The animations (SPEC §8, AuroraLD's six of `000_…` §3.22) and the
/// parameters each takes besides `tag`.
pub const ANIMATIONS: &[(&str, &[Param])] = &[
    ("visibility", &[WHEN, RANGE_LO, RANGE_HI]),
    (
        "blink",
        &[
            WHEN,
            RANGE_LO,
            RANGE_HI,
            p("on_ms", MS, "time shown in each blink (default 500)"),
            p("off_ms", MS, "time hidden in each blink (default 500)"),
            Param {
                name: "period_ms",
                kind: MS,
                help: "the whole blink, shown and hidden for half each (on_ms and off_ms win)",
                legacy: true,
            },
        ],
    ),
    (
        "move",
        &[
            LO,
            HI,
            p("dx", number("px"), "the move right at max (negative: left)"),
            p("dy", number("px"), "the move down at max (negative: up)"),
            WHEN,
        ],
    ),
    (
        "rotate",
        &[
            LO,
            HI,
            p("from", number("°"), "the angle at min (default 0)"),
            p(
                "degrees",
                number("°"),
                "the angle at max, clockwise (default 360; a meter's needle 270)",
            ),
            p(
                "speed",
                number("turns/s"),
                "spin at this speed while active instead (negative: anticlockwise)",
            ),
            p(
                "cx",
                number("px"),
                "the anchor point's x in the element's box (default its centre, or the rotor's hub)",
            ),
            p("cy", number("px"), "the anchor point's y in the element's box"),
            WHEN,
        ],
    ),
    (
        "color",
        &[
            p("on", ParamKind::Color, "the colour while the tag is on"),
            p("off", ParamKind::Color, "the colour while the tag is off"),
            p(
                "intervals",
                ParamKind::Intervals,
                "a number tag: up to 4 colours, each from its value up",
            ),
        ],
    ),
    (
        "fill",
        &[
            LO,
            HI,
            p(
                "direction",
                ParamKind::Choice(&["up", "down", "left", "right"]),
                "the way the level rises",
            ),
            p("color", ParamKind::Color, "the colour of the level"),
        ],
    ),
];

const COLOR: Param = p("color", ParamKind::Color, "the colour of its body");
const STROKE: Param = p("stroke", ParamKind::Color, "the colour of its outline");
const STROKE_W: Param = p(
    "stroke_width",
    ParamKind::Number {
        min: 0.0,
        max: 40.0,
        unit: "px",
    },
    "the width of its outline",
);
const DECIMALS: Param = p(
    "decimals",
    ParamKind::Number {
        min: 0.0,
        max: 10.0,
        unit: "",
    },
    "the figures after the point",
);
const UNIT: Param = p(
    "unit",
    ParamKind::Text { max_len: 16 },
    "the unit shown after the value",
);
const SCALE_LO: Param = p("min", number(""), "the bottom of its scale");
const SCALE_HI: Param = p("max", number(""), "the top of its scale");
const POINTS: Param = p(
    "points",
    ParamKind::Points { max: 200 },
    "its vertices [x, y] in its box (up to 200)",
);

/// The safety signs of `000_…` §3.6 (ISO 7010 shapes): a warning triangle,
/// a prohibition circle, or a mandatory/fire/exit square.
pub const SIGNS: &[&str] = &[
    "danger",
    "electrical",
    "radiation",
    "toxic",
    "flammable",
    "corrosive",
    "stop",
    "no_entry",
    "helmet",
    "fire_extinguisher",
    "exit",
];

/// Each element type's own properties besides `label` and the shown `tag`
/// (and `alarm`, an alarm indicator's alarm id): what the designer's form
/// asks for and `alba check` checks by kind. A property the table does not
/// know is kept (for other tools) and shown only in the expert JSON.
pub const ELEMENT_PROPS: &[(&str, &[Param])] = &[
    (
        "text",
        &[
            p(
                "text",
                ParamKind::Text { max_len: 1000 },
                "the text shown (when no tag is shown)",
            ),
            p(
                "size",
                ParamKind::Number {
                    min: 4.0,
                    max: 400.0,
                    unit: "px",
                },
                "the font size",
            ),
            COLOR,
        ],
    ),
    ("input", &[DECIMALS, UNIT]),
    ("output", &[DECIMALS, UNIT]),
    ("rectangle", &[COLOR, STROKE, STROKE_W]),
    ("circle", &[COLOR, STROKE, STROKE_W]),
    ("polygon", &[POINTS, COLOR, STROKE, STROKE_W]),
    ("line", &[POINTS, STROKE, STROKE_W]),
    (
        "arc",
        &[
            p(
                "start",
                number("°"),
                "where it starts, clockwise from 12 o'clock (default -90)",
            ),
            p("end", number("°"), "where it ends (default 90)"),
            p(
                "close",
                ParamKind::Choice(&["open", "chord", "centre"]),
                "open, closed by its chord, or a pie closed through its centre",
            ),
            COLOR,
            STROKE,
            STROKE_W,
        ],
    ),
    ("button", &[COLOR]),
    (
        "switch",
        &[
            p(
                "style",
                ParamKind::Choice(&["toggle", "rocker", "rotary"]),
                "a toggle lever, a rocker or a rotary selector",
            ),
            COLOR,
        ],
    ),
    ("slider", &[]),
    ("led", &[COLOR]),
    (
        "wind_turbine",
        &[p("tower", ParamKind::Bool, "drawn on its tower (default yes)")],
    ),
    (
        "fan",
        &[p("casing", ParamKind::Bool, "drawn in its casing (default yes)")],
    ),
    ("cooling_tower", &[]),
    (
        "plc",
        &[p(
            "run_tag",
            ParamKind::Tag,
            "its RUN and I/O lamps blink while this BOOL is on",
        )],
    ),
    ("clock", &[]),
    (
        "image",
        &[
            p(
                "src",
                ParamKind::Text { max_len: 300 },
                "the image: assets/<name> of the project",
            ),
            p(
                "scale",
                ParamKind::Number {
                    min: 1.0,
                    max: 1000.0,
                    unit: "%",
                },
                "its size in percent of the box (default: fitted)",
            ),
        ],
    ),
    (
        "bottle",
        &[p("cap_tag", ParamKind::Tag, "its cap is on while this BOOL is on")],
    ),
    ("motor", &[COLOR]),
    ("pump", &[COLOR]),
    (
        "tank",
        &[p(
            "style",
            ParamKind::Choice(&["tank", "silo", "horizontal"]),
            "an upright tank, a silo with its cone, or a lying tank",
        )],
    ),
    (
        "pipe",
        &[p(
            "shape",
            ParamKind::Choice(&["straight", "elbow", "tee", "cross"]),
            "straight, an elbow, a tee or a cross (turned by the element's rotation)",
        )],
    ),
    (
        "valve",
        &[p(
            "style",
            ParamKind::Choice(&["gate", "ball", "butterfly"]),
            "a gate, a ball or a butterfly valve",
        )],
    ),
    (
        "building",
        &[p(
            "windows_tag",
            ParamKind::Tag,
            "its windows are lit while this BOOL is on",
        )],
    ),
    ("transmission_tower", &[]),
    ("safety_sign", &[p("sign", ParamKind::Choice(SIGNS), "the sign shown")]),
    (
        "meter",
        &[
            p(
                "style",
                ParamKind::Choice(&["bar", "circular"]),
                "a bar or a circular gauge",
            ),
            SCALE_LO,
            SCALE_HI,
            UNIT,
            DECIMALS,
        ],
    ),
    ("alarm", &[]),
    (
        "trend",
        &[
            SCALE_LO,
            SCALE_HI,
            p(
                "window_s",
                ParamKind::Number {
                    min: 1.0,
                    max: MAX_TREND_WINDOW_S,
                    unit: "s",
                },
                "the seconds it shows up to now (default 120)",
            ),
            p(
                "pens",
                ParamKind::Pens { max: MAX_TREND_PENS },
                "up to 3 pens, each a tag and its colour (the element's `tag` when none)",
            ),
        ],
    ),
    ("faceplate", &[]),
];

/// Write actions of widgets.
pub const ACTIONS: &[&str] = &["momentary", "toggle", "set", "input", "slider", "navigate"];

/// A screen file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Screen {
    pub schema: u32,
    #[serde(default)]
    pub title: String,
    pub width: f64,
    pub height: f64,
    #[serde(default)]
    pub background: Option<String>,
    /// Drawn in order: the last is on top.
    pub elements: Vec<Element>,
}

/// An element of a screen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Element {
    pub id: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub x: f64,
    pub y: f64,
    pub w: f64,
    pub h: f64,
    /// Degrees, clockwise.
    #[serde(default)]
    pub rotation: f64,
    /// The element's own settings (label, colours, the value a text shows …).
    #[serde(default)]
    pub props: serde_json::Map<String, Json>,
    #[serde(default)]
    pub animations: Vec<Animation>,
    #[serde(default)]
    pub action: Option<Action>,
    /// The group the element belongs to in the designer (selected and moved together).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
}

/// An animation: a kind, the tag that drives it, its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Animation {
    pub kind: String,
    pub tag: String,
    #[serde(flatten)]
    pub params: serde_json::Map<String, Json>,
}

/// What a widget does when used: write `tag`, or go to `screen`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Action {
    pub kind: String,
    #[serde(default)]
    pub tag: Option<String>,
    #[serde(default)]
    pub value: Option<Json>,
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
    #[serde(default)]
    pub screen: Option<String>,
}

/// What a tag name stands for, as the caller's program sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TagKind {
    Bool,
    Number,
    /// A TIMER, COUNTER or PID: its members are tags, it is not.
    Structure,
}

/// Whether a tag (or member) can be written from a screen.
pub type Writable = bool;

/// What the caller's program says a name holds, or why it does not know it.
pub type Resolve<'a> = dyn Fn(&str) -> Result<(TagKind, Writable), String> + 'a;

/// The byte offset of every value of a JSON text, by its JSON pointer
/// (`/elements/3/animations/0/tag`): where to put a diagnostic.
fn offsets(text: &str) -> HashMap<String, usize> {
    struct Scan<'a> {
        b: &'a [u8],
        i: usize,
        out: HashMap<String, usize>,
    }
    impl Scan<'_> {
        fn ws(&mut self) {
            while self.i < self.b.len() && self.b[self.i].is_ascii_whitespace() {
                self.i += 1;
            }
        }
        fn string(&mut self) -> String {
            let start = self.i + 1;
            self.i += 1;
            while self.i < self.b.len() && self.b[self.i] != b'"' {
                if self.b[self.i] == b'\\' {
                    self.i += 1;
                }
                self.i += 1;
            }
            let s = String::from_utf8_lossy(&self.b[start.min(self.b.len())..self.i.min(self.b.len())]).into_owned();
            self.i += 1;
            s
        }
        fn value(&mut self, path: &str, depth: usize) {
            self.ws();
            self.out.insert(path.to_string(), self.i);
            if depth > 64 {
                return;
            }
            match self.b.get(self.i) {
                Some(b'{') => {
                    self.i += 1;
                    loop {
                        self.ws();
                        match self.b.get(self.i) {
                            Some(b'"') => {
                                let key = self.string();
                                self.ws();
                                if self.b.get(self.i) == Some(&b':') {
                                    self.i += 1;
                                }
                                let p = format!("{path}/{}", key.replace('~', "~0").replace('/', "~1"));
                                self.value(&p, depth + 1);
                                self.ws();
                                if self.b.get(self.i) == Some(&b',') {
                                    self.i += 1;
                                }
                            }
                            Some(b'}') => {
                                self.i += 1;
                                return;
                            }
                            _ => return,
                        }
                    }
                }
                Some(b'[') => {
                    self.i += 1;
                    let mut k = 0;
                    loop {
                        self.ws();
                        match self.b.get(self.i) {
                            Some(b']') => {
                                self.i += 1;
                                return;
                            }
                            None => return,
                            _ => {
                                self.value(&format!("{path}/{k}"), depth + 1);
                                k += 1;
                                self.ws();
                                if self.b.get(self.i) == Some(&b',') {
                                    self.i += 1;
                                }
                            }
                        }
                    }
                }
                Some(b'"') => {
                    self.string();
                }
                Some(_) => {
                    while self.i < self.b.len() && !matches!(self.b[self.i], b',' | b'}' | b']') {
                        self.i += 1;
                    }
                }
                None => {}
            }
        }
    }
    let mut s = Scan {
        b: text.as_bytes(),
        i: 0,
        out: HashMap::new(),
    };
    s.value("", 0);
    s.out
}

/// Parses and checks a screen file. The screen is `None` when the file is not
/// one at all (bad JSON, missing fields, a newer schema); with other problems
/// it is returned with every problem listed.
pub fn parse(
    text: &str,
    file: FileId,
    resolve: &Resolve<'_>,
    alarm: &dyn Fn(&str) -> bool,
) -> (Option<Screen>, Vec<Diagnostic>) {
    let at = offsets(text);
    let span_of = |pointer: &str| {
        // the value itself, else its nearest enclosing value
        let mut p = pointer.to_string();
        loop {
            if let Some(&o) = at.get(&p) {
                return Span::new(file, o..o + 1);
            }
            match p.rfind('/') {
                Some(i) => p.truncate(i),
                None => return Span::new(file, 0..0),
            }
        }
    };
    let diag =
        |pointer: &str, msg: String, label: &str| Diagnostic::new(Code::ScreenFile, msg, span_of(pointer), label);
    let screen: Screen = match serde_json::from_str(text) {
        Ok(s) => s,
        Err(e) => {
            // serde_json says where, in lines and columns
            let line_start: usize = text
                .split_inclusive('\n')
                .take(e.line().saturating_sub(1))
                .map(str::len)
                .sum();
            let o = (line_start + e.column().saturating_sub(1)).min(text.len());
            return (
                None,
                vec![Diagnostic::new(
                    Code::ScreenFile,
                    // (the place is the span's; the message without serde's own "at line … column …")
                    format!(
                        "not a screen file: {}",
                        e.to_string().split(" at line ").next().unwrap_or_default()
                    ),
                    Span::new(file, o..o),
                    "here",
                )],
            );
        }
    };
    let mut d = Vec::new();
    if screen.schema != SCHEMA {
        d.push(diag(
            "/schema",
            format!(
                "schema {} is not supported (this version reads {SCHEMA})",
                screen.schema
            ),
            "schema",
        ));
        return (None, d);
    }
    for (key, v) in [("width", screen.width), ("height", screen.height)] {
        if !(v.is_finite() && (1.0..=20_000.0).contains(&v)) {
            d.push(diag(
                &format!("/{key}"),
                format!("{key} = {v} is out of range (1 to 20000)"),
                "out of range",
            ));
        }
    }
    let mut ids: HashMap<&str, usize> = HashMap::new();
    for (k, e) in screen.elements.iter().enumerate() {
        let here = format!("/elements/{k}");
        if e.id.trim().is_empty() {
            d.push(diag(&format!("{here}/id"), "an element needs an `id`".into(), "empty"));
        } else if let Some(first) = ids.insert(&e.id, k) {
            d.push(diag(
                &format!("{here}/id"),
                format!("id `{}` is already element {first}'s", e.id),
                "duplicate",
            ));
        }
        if !ELEMENT_TYPES.iter().any(|(t, _)| *t == e.kind) {
            d.push(
                diag(
                    &format!("{here}/type"),
                    format!("`{}` is not an element type", e.kind),
                    "unknown type",
                )
                .with_help(format!(
                    "one of: {}",
                    ELEMENT_TYPES.iter().map(|(t, _)| *t).collect::<Vec<_>>().join(", ")
                )),
            );
        }
        for (key, v) in [("x", e.x), ("y", e.y), ("w", e.w), ("h", e.h), ("rotation", e.rotation)] {
            if !v.is_finite() {
                d.push(diag(
                    &format!("{here}/{key}"),
                    format!("{key} is not a number"),
                    "not finite",
                ));
            }
        }
        if e.w <= 0.0 || e.h <= 0.0 {
            d.push(diag(
                &format!("{here}/w"),
                format!("element `{}` has no size ({} × {})", e.id, e.w, e.h),
                "size",
            ));
        }
        // Problems of the shown tag, animations and actions name their element.
        let from = d.len();
        check_shown(e, &here, resolve, &diag, &mut d);
        check_alarm_ref(e, &here, alarm, &diag, &mut d);
        check_props(e, &here, resolve, &diag, &mut d);
        for (n, a) in e.animations.iter().enumerate() {
            check_animation(a, &format!("{here}/animations/{n}"), resolve, &diag, &mut d);
        }
        if let Some(a) = &e.action {
            check_action(a, &format!("{here}/action"), resolve, &diag, &mut d);
        }
        for x in &mut d[from..] {
            x.message = format!("`{}`: {}", e.id, x.message);
        }
    }
    check_instances(&screen, &diag, &mut d);
    (Some(screen), d)
}

/// A template's instance (docs/file-formats.md, "Templates"): its elements carry
/// `template` (a symbol's name), `prefix` (a tag name or a path of them) and
/// `part`, are in one group, and every element of that group agrees on the
/// template and the prefix. Whether the symbol exists is the designer's (a
/// screen never depends on a symbol file); the instance's tags are checked as
/// any others.
fn check_instances(screen: &Screen, diag: &Diag<'_>, d: &mut Vec<Diagnostic>) {
    let name_ok = |s: &str| {
        !s.is_empty() && s.len() <= 64 && s.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-'))
    };
    let path_ok = |s: &str| {
        s.split('.').all(|p| {
            p.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && p.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        })
    };
    let mut first: HashMap<&str, (usize, Option<&Json>, Option<&Json>)> = HashMap::new();
    for (k, e) in screen.elements.iter().enumerate() {
        let here = format!("/elements/{k}/props");
        let (template, prefix) = (e.props.get("template"), e.props.get("prefix"));
        if let Some(g) = &e.group {
            let (n, t0, p0) = *first.entry(g.as_str()).or_insert((k, template, prefix));
            if n != k && (t0 != template || p0 != prefix) {
                d.push(diag(
                    &here,
                    format!(
                        "`{}`: its `template`/`prefix` differ from `{}`'s in group `{g}` (an instance's elements agree)",
                        e.id, screen.elements[n].id
                    ),
                    "instance",
                ));
            }
        }
        let Some(template) = template else { continue };
        let mut bad =
            |key: &str, msg: String| d.push(diag(&format!("{here}/{key}"), format!("`{}`: {msg}", e.id), key));
        if !template.as_str().is_some_and(name_ok) {
            bad(
                "template",
                "`template` is a symbol's name (letters, digits, `_` and `-`)".into(),
            );
        }
        if !prefix.and_then(Json::as_str).is_some_and(path_ok) {
            bad(
                "prefix",
                "an instance's `prefix` is a tag name (`Pump2`, `Area1.Pump2`)".into(),
            );
        }
        if !e.props.get("part").is_some_and(Json::is_string) {
            bad(
                "part",
                "an instance's `part` is the id of the template's element it copies".into(),
            );
        }
        if e.group.is_none() {
            bad("template", "an instance's elements are in a group of their own".into());
        }
    }
}

type Diag<'a> = dyn Fn(&str, String, &str) -> Diagnostic + 'a;

fn check_animation(a: &Animation, here: &str, resolve: &Resolve<'_>, diag: &Diag<'_>, d: &mut Vec<Diagnostic>) {
    let Some((_, params)) = ANIMATIONS.iter().find(|(k, _)| *k == a.kind) else {
        d.push(
            diag(
                &format!("{here}/kind"),
                format!("`{}` is not an animation", a.kind),
                "unknown animation",
            )
            .with_help("one of: visibility, blink, move, rotate, color, fill"),
        );
        return;
    };
    match resolve(&a.tag) {
        Err(e) => d.push(diag(
            &format!("{here}/tag"),
            format!("animation `{}`: {e}", a.kind),
            "unknown tag",
        )),
        Ok((TagKind::Structure, _)) => d.push(diag(
            &format!("{here}/tag"),
            format!("`{}` is a structure: animate one of its members", a.tag),
            "structure",
        )),
        Ok(_) => {}
    }
    for (key, value) in &a.params {
        let at = format!("{here}/{key}");
        let Some(param) = params.iter().find(|p| p.name == key) else {
            let names: Vec<&str> = params.iter().filter(|p| !p.legacy).map(|p| p.name).collect();
            d.push(diag(
                &at,
                format!(
                    "`{key}` is not a parameter of `{}` (it takes: {})",
                    a.kind,
                    names.join(", ")
                ),
                "unknown parameter",
            ));
            continue;
        };
        if let Some(problem) = param_problem(param, value, resolve) {
            d.push(diag(&at, problem, key));
        }
    }
    let num = |k: &str| a.params.get(k).and_then(Json::as_f64);
    if let (Some(lo), Some(hi)) = (num("min"), num("max"))
        && lo >= hi
    {
        d.push(diag(
            &format!("{here}/max"),
            format!("max {hi} must be above min {lo}"),
            "range",
        ));
    }
}

/// What is wrong with `value` for `param`, if anything.
fn param_problem(param: &Param, value: &Json, resolve: &Resolve<'_>) -> Option<String> {
    let key = param.name;
    match param.kind {
        ParamKind::Tag => match value.as_str().map(|t| (t, resolve(t))) {
            None => Some(format!("`{key}` is a tag's name (a string)")),
            Some((_, Err(err))) => Some(format!("`{key}`: {err}")),
            Some((t, Ok((TagKind::Structure, _)))) => {
                Some(format!("`{key}`: `{t}` is a structure: name one of its members"))
            }
            Some(_) => None,
        },
        ParamKind::Text { max_len } => match value.as_str() {
            Some(t) if t.chars().count() <= max_len => None,
            Some(_) => Some(format!("`{key}` is longer than {max_len} characters")),
            None => Some(format!("`{key}` is a text")),
        },
        ParamKind::Points { max } => match value.as_array() {
            Some(list) if list.len() <= max => list.iter().enumerate().find_map(|(n, pt)| {
                let ok = pt
                    .as_array()
                    .is_some_and(|xy| xy.len() == 2 && xy.iter().all(|c| c.as_f64().is_some()));
                (!ok).then(|| format!("point {n} of `{key}` is not [x, y]"))
            }),
            _ => Some(format!("`{key}` is a list of at most {max} points [x, y]")),
        },
        ParamKind::Pens { max } => match value.as_array() {
            Some(list) if list.len() <= max => list.iter().enumerate().find_map(|(n, pen)| {
                let Some(tag) = pen.get("tag").and_then(Json::as_str) else {
                    return Some(format!("pen {} of `{key}` needs its `tag` (a string)", n + 1));
                };
                if let Some(c) = pen.get("color")
                    && !c.as_str().is_some_and(is_color)
                {
                    return Some(format!("pen {} of `{key}`: {c} is not a colour", n + 1));
                }
                if let Some(other) = pen
                    .as_object()
                    .and_then(|o| o.keys().find(|k| *k != "tag" && *k != "color"))
                {
                    return Some(format!("pen {} of `{key}`: `{other}` is not tag or color", n + 1));
                }
                match resolve(tag) {
                    Err(err) => Some(format!("pen {} of `{key}`: {err}", n + 1)),
                    Ok((TagKind::Number | TagKind::Bool, _)) => None,
                    Ok(_) => Some(format!("pen {} of `{key}`: `{tag}` is not a number or a BOOL", n + 1)),
                }
            }),
            _ => Some(format!("`{key}` is a list of at most {max} pens {{tag, color}}")),
        },
        ParamKind::Number { min, max, unit } => match value.as_f64() {
            None => Some(format!("`{key}` is not a number")),
            Some(x) if x < min || x > max => Some(format!("`{key}` {x} is not from {min} to {max} {unit}")),
            Some(_) => None,
        },
        ParamKind::Bool => (!value.is_boolean()).then(|| format!("`{key}` is true or false")),
        ParamKind::Color => (!value.as_str().is_some_and(is_color))
            .then(|| format!("`{key}` {value} is not a colour (#rrggbb, #rgb, a name or rgb(…))")),
        ParamKind::Choice(choices) => (!value.as_str().is_some_and(|v| choices.contains(&v))).then(|| {
            let (last, rest) = choices.split_last().unwrap_or((&"", &[]));
            format!("{key} {value} is not {} or {last}", rest.join(", "))
        }),
        ParamKind::Intervals => match value.as_array() {
            Some(list) if list.len() <= 4 => list.iter().enumerate().find_map(|(n, i)| {
                let ok = i.get("from").and_then(Json::as_f64).is_some()
                    && i.get("color").and_then(Json::as_str).is_some_and(is_color);
                (!ok).then(|| format!("interval {n}: an interval needs `from` (a number) and `color`"))
            }),
            _ => Some("`intervals` is a list of at most 4".into()),
        },
    }
}

/// A colour the browser draws and nothing else: `#rgb`, `#rgba`, `#rrggbb`,
/// `#rrggbbaa`, a name, or `rgb(…)`/`rgba(…)`/`hsl(…)`/`hsla(…)` of numbers.
pub fn is_color(c: &str) -> bool {
    if let Some(hex) = c.strip_prefix('#') {
        return matches!(hex.len(), 3 | 4 | 6 | 8) && hex.chars().all(|ch| ch.is_ascii_hexdigit());
    }
    if !c.is_empty() && c.len() <= 32 && c.chars().all(|ch| ch.is_ascii_alphabetic()) {
        return true;
    }
    ["rgb(", "rgba(", "hsl(", "hsla("].iter().any(|f| {
        c.strip_prefix(f)
            .and_then(|r| r.strip_suffix(')'))
            .is_some_and(|args| !args.is_empty() && args.chars().all(|ch| ch.is_ascii_digit() || " ,.%/-".contains(ch)))
    })
}

/// `props.tag`, the value an element shows: a value, or for a faceplate the PID loop.
fn check_shown(e: &Element, here: &str, resolve: &Resolve<'_>, diag: &Diag<'_>, d: &mut Vec<Diagnostic>) {
    let at = format!("{here}/props/tag");
    let Some(tag) = e.props.get("tag") else {
        if e.kind == "faceplate" {
            d.push(diag(
                &format!("{here}/props"),
                "a faceplate needs the PID loop `tag` it shows".into(),
                "tag",
            ));
        }
        return;
    };
    let Some(tag) = tag.as_str() else {
        d.push(diag(&at, "`tag` is a tag's name (a string)".into(), "not a string"));
        return;
    };
    match (resolve(tag), e.kind == "faceplate") {
        (Err(err), _) => d.push(diag(&at, format!("shown tag: {err}"), "unknown tag")),
        (Ok((TagKind::Structure, _)), false) => d.push(diag(
            &at,
            format!("`{tag}` is a structure: show one of its members"),
            "structure",
        )),
        (Ok((kind, _)), true) if kind != TagKind::Structure => d.push(diag(
            &at,
            format!("a faceplate shows a PID loop; `{tag}` is a single value"),
            "not a loop",
        )),
        _ => {}
    }
}

/// `props.alarm` of an alarm indicator: the id of an alarm of alarms.csv.
fn check_alarm_ref(e: &Element, here: &str, alarm: &dyn Fn(&str) -> bool, diag: &Diag<'_>, d: &mut Vec<Diagnostic>) {
    let Some(v) = e.props.get("alarm") else { return };
    let at = format!("{here}/props/alarm");
    match v.as_str() {
        None => d.push(diag(&at, "`alarm` is an alarm's id (a string)".into(), "not a string")),
        Some(id) if !alarm(id) => d.push(diag(&at, format!("no alarm `{id}` in alarms.csv"), "unknown alarm")),
        Some(_) if e.kind != "alarm" => d.push(diag(
            &at,
            "only an `alarm` element shows an alarm's state".into(),
            "not an indicator",
        )),
        Some(_) => {}
    }
}

/// The longest time window of a trend: a day, in seconds.
pub const MAX_TREND_WINDOW_S: f64 = 86_400.0;

/// An element's own properties, each by its kind (`ELEMENT_PROPS`). A
/// property of another element type is refused here (a trend's `window_s` on
/// a tank); one no element type has is kept for other tools.
fn check_props(e: &Element, here: &str, resolve: &Resolve<'_>, diag: &Diag<'_>, d: &mut Vec<Diagnostic>) {
    let own = ELEMENT_PROPS
        .iter()
        .find(|(t, _)| *t == e.kind)
        .map_or(&[][..], |(_, ps)| *ps);
    for (key, value) in &e.props {
        let at = format!("{here}/props/{key}");
        match own.iter().find(|p| p.name == key) {
            Some(param) => {
                let problem = param_problem(param, value, resolve);
                if let Some(problem) = problem {
                    d.push(diag(&at, problem, key));
                }
            }
            None if ELEMENT_PROPS.iter().any(|(_, ps)| ps.iter().any(|p| p.name == key)) => {
                let names: Vec<&str> = own.iter().map(|p| p.name).collect();
                d.push(diag(
                    &at,
                    format!(
                        "`{key}` is not a property of `{}` (it takes: {})",
                        e.kind,
                        if names.is_empty() {
                            "label".to_string()
                        } else {
                            names.join(", ")
                        }
                    ),
                    "not its property",
                ));
            }
            None => {}
        }
    }
}

fn check_action(a: &Action, here: &str, resolve: &Resolve<'_>, diag: &Diag<'_>, d: &mut Vec<Diagnostic>) {
    if !ACTIONS.contains(&a.kind.as_str()) {
        d.push(diag(
            &format!("{here}/kind"),
            format!("`{}` is not an action ({})", a.kind, ACTIONS.join(", ")),
            "unknown action",
        ));
        return;
    }
    if a.kind == "navigate" {
        if a.screen.as_deref().is_none_or(str::is_empty) {
            d.push(diag(
                &format!("{here}/screen"),
                "`navigate` needs the `screen` to go to".into(),
                "screen",
            ));
        }
        return;
    }
    let Some(tag) = &a.tag else {
        d.push(diag(here, format!("`{}` needs the `tag` it writes", a.kind), "tag"));
        return;
    };
    match resolve(tag) {
        Err(e) => d.push(diag(
            &format!("{here}/tag"),
            format!("action `{}`: {e}", a.kind),
            "unknown tag",
        )),
        Ok((_, false)) => d.push(diag(
            &format!("{here}/tag"),
            format!("`{tag}` cannot be written from a screen (an input, or read-only)"),
            "read-only",
        )),
        Ok((TagKind::Structure, _)) => d.push(diag(
            &format!("{here}/tag"),
            format!("`{tag}` is a structure"),
            "structure",
        )),
        Ok((TagKind::Bool, _)) if matches!(a.kind.as_str(), "slider") => d.push(diag(
            &format!("{here}/kind"),
            format!("a slider writes a number; `{tag}` is a BOOL"),
            "kind",
        )),
        Ok((TagKind::Number, _)) if matches!(a.kind.as_str(), "momentary" | "toggle") => d.push(diag(
            &format!("{here}/kind"),
            format!("`{}` writes a BOOL; `{tag}` is a number", a.kind),
            "kind",
        )),
        Ok(_) => {}
    }
    if let (Some(lo), Some(hi)) = (a.min, a.max)
        && lo >= hi
    {
        d.push(diag(
            &format!("{here}/max"),
            format!("max {hi} must be above min {lo}"),
            "range",
        ));
    }
}

#[cfg(test)]
mod tests;
