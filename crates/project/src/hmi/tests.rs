//! Screen files: a good one, and malformed ones each reported at its place.

use super::*;
use alba_diag::Files;

/// Tags of a small plant: Level (REAL), Pump (BOOL, an output), Start (BOOL
/// input), T1 (TIMER) with T1.ACC, and SysTime (read-only).
fn resolve(name: &str) -> Result<(TagKind, Writable), String> {
    match name {
        "Level" | "Speed" | "T1.ACC" => Ok((TagKind::Number, true)),
        "Pump" | "Light" => Ok((TagKind::Bool, true)),
        "Start" => Ok((TagKind::Bool, false)),
        "SysTime" => Ok((TagKind::Number, false)),
        "T1" => Ok((TagKind::Structure, true)),
        _ => Err(format!("unknown tag `{name}`")),
    }
}

fn check(text: &str) -> (Option<Screen>, Vec<String>) {
    let mut files = Files::new();
    let f = files.add("hmi/main.json", text);
    let (s, d) = parse(text, f, &resolve, &|id: &str| id == "level_hi");
    (s, d.iter().map(|d| d.short(&files)).collect())
}

const GOOD: &str = r##"{
  "schema": 1,
  "title": "Tank",
  "width": 1280,
  "height": 720,
  "elements": [
    {"id": "tank", "type": "tank", "x": 100, "y": 80, "w": 120, "h": 200,
     "animations": [{"kind": "fill", "tag": "Level", "min": 0, "max": 60, "direction": "up"}]},
    {"id": "pump", "type": "pump", "x": 300, "y": 240, "w": 60, "h": 60,
     "animations": [{"kind": "rotate", "tag": "Pump", "speed": 1},
                    {"kind": "rotate", "tag": "Level", "min": 0, "max": 60, "from": -45, "degrees": 45, "cx": 0, "cy": 30, "when": true},
                    {"kind": "blink", "tag": "Level", "min": 50, "max": 60, "on_ms": 300, "off_ms": 700, "when": false},
                    {"kind": "blink", "tag": "Pump", "period_ms": 500},
                    {"kind": "visibility", "tag": "Level", "min": 5},
                    {"kind": "color", "tag": "Level", "intervals": [{"from": 0, "color": "#2e7d32"}, {"from": 55, "color": "#c62828"}]}]},
    {"id": "v1", "type": "valve", "x": 10, "y": 10, "w": 40, "h": 40, "props": {"style": "butterfly", "vendor_note": "kept"}},
    {"id": "poly", "type": "polygon", "x": 10, "y": 10, "w": 40, "h": 40, "props": {"points": [[0, 0], [40, 10], [20, 40]], "color": "orange"}},
    {"id": "b", "type": "bottle", "x": 10, "y": 10, "w": 40, "h": 40, "props": {"cap_tag": "Pump"}},
    {"id": "start", "type": "button", "x": 300, "y": 320, "w": 80, "h": 32,
     "props": {"label": "Fill"}, "action": {"kind": "momentary", "tag": "Light"}},
    {"id": "sp", "type": "slider", "x": 20, "y": 20, "w": 200, "h": 24, "action": {"kind": "slider", "tag": "Speed", "min": 0, "max": 100}},
    {"id": "next", "type": "button", "x": 20, "y": 60, "w": 80, "h": 24, "action": {"kind": "navigate", "screen": "pumps"}},
    {"id": "tr", "type": "trend", "x": 20, "y": 90, "w": 300, "h": 150,
     "props": {"label": "Level and pump", "window_s": 60, "pens": [{"tag": "Level", "color": "#1f5fa8"}, {"tag": "Pump", "color": "orange"}, {"tag": "T1.ACC"}]}}
  ]
}"##;

#[test]
fn a_good_screen_parses_without_problems() {
    let (s, d) = check(GOOD);
    assert_eq!(d, Vec::<String>::new());
    let s = s.expect("a screen");
    assert_eq!((s.elements.len(), s.elements[0].kind.as_str()), (9, "tank"));
    assert_eq!(s.elements[1].animations[0].params["speed"], 1);
    // It round-trips through the API's JSON.
    let again: Screen = serde_json::from_str(&serde_json::to_string(&s).expect("json")).expect("parse");
    assert_eq!(again, s);
    assert_eq!(ELEMENT_TYPES.len(), 31, "AuroraLD's 30 elements and the faceplate");
}

/// A screen with one element replaced by `element`.
fn with(element: &str) -> String {
    format!("{{\n\"schema\": 1,\n\"width\": 800,\n\"height\": 600,\n\"elements\": [\n{element}\n]\n}}")
}

const E: &str = r#""id": "e", "type": "tank", "x": 1, "y": 2, "w": 10, "h": 10"#;

#[test]
fn malformed_screens_are_reported_at_their_place() {
    let mut cases: Vec<(String, &str)> = vec![
        (
            "{".into(),
            "hmi/main.json:1:1: error[E141]: not a screen file: EOF while parsing an object",
        ),
        (
            "[]".into(),
            "hmi/main.json:1:2: error[E141]: not a screen file: invalid length 0",
        ),
        ("{\"schema\": 1}".into(), "missing field `width`"),
        (
            "{\"schema\": 2, \"width\": 1, \"height\": 1, \"elements\": []}".into(),
            "hmi/main.json:1:12: error[E141]: schema 2 is not supported (this version reads 1)",
        ),
        (
            "{\"schema\": 1, \"width\": 0, \"height\": 1, \"elements\": []}".into(),
            "hmi/main.json:1:24: error[E141]: width = 0 is out of range (1 to 20000)",
        ),
        (
            "{\"schema\": 1, \"width\": 10, \"height\": 1, \"elements\": [], \"zoom\": 2}".into(),
            "unknown field `zoom`",
        ),
        (
            with(r#"{"id": "e", "type": "spaceship", "x": 1, "y": 2, "w": 10, "h": 10}"#),
            "hmi/main.json:6:21: error[E141]: `spaceship` is not an element type",
        ),
        (
            with(&format!("{{{E}}},\n{{{E}}}")),
            "hmi/main.json:7:8: error[E141]: id `e` is already element 0's",
        ),
        (
            with(r#"{"id": " ", "type": "tank", "x": 1, "y": 2, "w": 10, "h": 10}"#),
            "hmi/main.json:6:8: error[E141]: an element needs an `id`",
        ),
        (
            with(r#"{"id": "e", "type": "tank", "x": 1, "y": 2, "w": 0, "h": 10}"#),
            "hmi/main.json:6:50: error[E141]: element `e` has no size (0 × 10)",
        ),
        (
            with(r#"{"id": "e", "type": "tank", "x": "left", "y": 2, "w": 1, "h": 1}"#),
            "invalid type: string \"left\", expected f64",
        ),
        (with(&format!("{{{E}, \"colour\": 1}}")), "unknown field `colour`"),
        (
            with(&format!("{{{E}, \"props\": {{\"tag\": \"Nivel\"}}}}")),
            "hmi/main.json:6:80: error[E141]: `e`: shown tag: unknown tag `Nivel`",
        ),
        (
            with(&format!("{{{E}, \"props\": {{\"tag\": 3}}}}")),
            "`e`: `tag` is a tag's name (a string)",
        ),
        (
            with(&format!("{{{E}, \"props\": {{\"tag\": \"T1\"}}}}")),
            "`e`: `T1` is a structure: show one of its members",
        ),
        (
            with(r#"{"id": "f", "type": "faceplate", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"tag": "Level"}}"#),
            "`f`: a faceplate shows a PID loop; `Level` is a single value",
        ),
        (
            with(r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"window_s": 0}}"#),
            "hmi/main.json:6:86: error[E141]: `t`: `window_s` 0 is not from 1 to 86400 s",
        ),
        (
            with(r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"window_s": "2 min"}}"#),
            "`t`: `window_s` is not a number",
        ),
        (
            with(r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"window_s": 86401}}"#),
            "`window_s` 86401 is not from 1 to 86400 s",
        ),
        (
            with(
                r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"pens": [{"tag": "Level"}, {"tag": "Pump"}, {"tag": "Speed"}, {"tag": "T1.ACC"}]}}"#,
            ),
            "`t`: `pens` is a list of at most 3 pens {tag, color}",
        ),
        (
            with(
                r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"pens": [{"tag": "Level"}, {"tag": "Nope"}]}}"#,
            ),
            "`t`: pen 2 of `pens`: unknown tag `Nope`",
        ),
        (
            with(
                r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"pens": [{"tag": "T1"}]}}"#,
            ),
            "`t`: pen 1 of `pens`: `T1` is not a number or a BOOL",
        ),
        (
            with(
                r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"pens": [{"tag": "Level", "color": "url(x)"}]}}"#,
            ),
            "`t`: pen 1 of `pens`: \"url(x)\" is not a colour",
        ),
        (
            with(
                r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"pens": [{"color": "red"}]}}"#,
            ),
            "`t`: pen 1 of `pens` needs its `tag` (a string)",
        ),
        (
            with(
                r#"{"id": "t", "type": "trend", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"pens": [{"tag": "Level", "width": 2}]}}"#,
            ),
            "`t`: pen 1 of `pens`: `width` is not tag or color",
        ),
        (
            with(&format!("{{{E}, \"props\": {{\"pens\": [{{\"tag\": \"Level\"}}]}}}}")),
            "`e`: `pens` is not a property of `tank`",
        ),
        (
            with(&format!("{{{E}, \"props\": {{\"window_s\": 60}}}}")),
            "`e`: `window_s` is not a property of `tank` (it takes: style)",
        ),
        (
            with(r#"{"id": "a", "type": "alarm", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"alarm": "level_hx"}}"#),
            "`a`: no alarm `level_hx` in alarms.csv",
        ),
        (
            with(r#"{"id": "a", "type": "led", "x": 1, "y": 2, "w": 10, "h": 10, "props": {"alarm": "level_hi"}}"#),
            "`a`: only an `alarm` element shows an alarm's state",
        ),
        (
            with(r#"{"id": "f", "type": "faceplate", "x": 1, "y": 2, "w": 10, "h": 10}"#),
            "`f`: a faceplate needs the PID loop `tag` it shows",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"spin\", \"tag\": \"Pump\"}}]}}"
            )),
            "`spin` is not an animation",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"fill\", \"tag\": \"Nope\"}}]}}"
            )),
            "hmi/main.json:6:102: error[E141]: `e`: animation `fill`: unknown tag `Nope`",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"fill\", \"tag\": \"T1\"}}]}}"
            )),
            "`T1` is a structure: animate one of its members",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"fill\", \"tag\": \"Level\", \"speed\": 3}}]}}"
            )),
            "`speed` is not a parameter of `fill` (it takes: min, max, direction, color)",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"move\", \"tag\": \"Level\", \"min\": 5, \"max\": 5}}]}}"
            )),
            "max 5 must be above min 5",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"fill\", \"tag\": \"Level\", \"direction\": \"sideways\"}}]}}"
            )),
            "direction \"sideways\" is not up, down, left or right",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"color\", \"tag\": \"Level\", \"intervals\": [{{\"from\": 0}}]}}]}}"
            )),
            "an interval needs `from` (a number) and `color`",
        ),
        (
            with(&format!(
                "{{{E}, \"animations\": [{{\"kind\": \"color\", \"tag\": \"Level\", \"intervals\": [{{}},{{}},{{}},{{}},{{}}]}}]}}"
            )),
            "`intervals` is a list of at most 4",
        ),
        (
            with(&format!("{{{E}, \"animations\": [{{\"tag\": \"Level\"}}]}}")),
            "missing field `kind`",
        ),
        (
            with(&format!(
                "{{{E}, \"action\": {{\"kind\": \"jump\", \"tag\": \"Pump\"}}}}"
            )),
            "`jump` is not an action",
        ),
        (
            with(&format!("{{{E}, \"action\": {{\"kind\": \"toggle\"}}}}")),
            "`toggle` needs the `tag` it writes",
        ),
        (
            with(&format!(
                "{{{E}, \"action\": {{\"kind\": \"toggle\", \"tag\": \"Start\"}}}}"
            )),
            "`Start` cannot be written from a screen (an input, or read-only)",
        ),
        (
            with(&format!(
                "{{{E}, \"action\": {{\"kind\": \"set\", \"tag\": \"SysTime\", \"value\": 1}}}}"
            )),
            "`SysTime` cannot be written from a screen",
        ),
        (
            with(&format!(
                "{{{E}, \"action\": {{\"kind\": \"slider\", \"tag\": \"Pump\"}}}}"
            )),
            "a slider writes a number; `Pump` is a BOOL",
        ),
        (
            with(&format!(
                "{{{E}, \"action\": {{\"kind\": \"momentary\", \"tag\": \"Level\"}}}}"
            )),
            "`momentary` writes a BOOL; `Level` is a number",
        ),
        (
            with(&format!(
                "{{{E}, \"action\": {{\"kind\": \"slider\", \"tag\": \"Speed\", \"min\": 9, \"max\": 1}}}}"
            )),
            "max 1 must be above min 9",
        ),
        (
            with(&format!("{{{E}, \"action\": {{\"kind\": \"navigate\"}}}}")),
            "`navigate` needs the `screen` to go to",
        ),
        (
            with(&format!(
                "{{{E}, \"action\": {{\"kind\": \"set\", \"tag\": \"Nope\"}}}}"
            )),
            "action `set`: unknown tag `Nope`",
        ),
    ];
    // Each parameter is checked by its kind (the table the designer's forms are made from).
    let anim = |a: &str| with(&format!("{{{E}, \"animations\": [{{\"tag\": \"Level\", {a}}}]}}"));
    cases.extend([
        (
            anim(r#""kind": "blink", "on_ms": 5"#),
            "`on_ms` 5 is not from 10 to 600000 ms",
        ),
        (anim(r#""kind": "blink", "off_ms": "fast""#), "`off_ms` is not a number"),
        (
            anim(r#""kind": "visibility", "when": "yes""#),
            "`when` is true or false",
        ),
        (
            anim(r#""kind": "color", "on": "red;}""#),
            "`on` \"red;}\" is not a colour",
        ),
        (anim(r#""kind": "color", "off": "url(#x)""#), "is not a colour"),
        (anim(r#""kind": "rotate", "cx": "middle""#), "`cx` is not a number"),
        (
            anim(r#""kind": "visibility", "min": 10, "max": 2"#),
            "max 2 must be above min 10",
        ),
    ]);
    // An element's own properties, by kind (the designer's forms are made from the same table).
    let el = |t: &str, props: &str| {
        with(&format!(
            r#"{{"id": "e", "type": "{t}", "x": 1, "y": 2, "w": 10, "h": 10, "props": {props}}}"#
        ))
    };
    cases.extend([
        (
            el("valve", r#"{"style": "globe"}"#),
            "style \"globe\" is not gate, ball or butterfly",
        ),
        (
            el("polygon", r#"{"points": [[0, 0], [5]]}"#),
            "point 1 of `points` is not [x, y]",
        ),
        (
            el("line", r#"{"points": 3}"#),
            "`points` is a list of at most 200 points [x, y]",
        ),
        (el("bottle", r#"{"cap_tag": "Nope"}"#), "`cap_tag`: unknown tag `Nope`"),
        (
            el("building", r#"{"windows_tag": "T1"}"#),
            "`windows_tag`: `T1` is a structure",
        ),
        (
            el("rectangle", r##"{"color": "#12"}"##),
            "`color` \"#12\" is not a colour",
        ),
        (el("fan", r#"{"casing": 1}"#), "`casing` is true or false"),
        (el("image", r#"{"scale": 0}"#), "`scale` 0 is not from 1 to 1000 %"),
        (
            el("safety_sign", r#"{"sign": "skull"}"#),
            "sign \"skull\" is not danger, electrical",
        ),
        (
            el("pump", r#"{"decimals": 2}"#),
            "`decimals` is not a property of `pump` (it takes: color)",
        ),
    ]);
    assert!(cases.len() >= 20);
    for (text, want) in cases {
        let (_, d) = check(&text);
        assert!(d.iter().any(|m| m.contains(want)), "{text}\nwanted: {want}\ngot: {d:?}");
        assert!(
            d.iter()
                .all(|m| m.starts_with("hmi/main.json:") && m.contains("error[E141]")),
            "{d:?}"
        );
    }
}

#[test]
fn template_instances_agree_within_their_group() {
    let inst = |id: &str, group: &str, prefix: &str| {
        format!(
            r#"{{"id": "{id}", "type": "led", "x": 1, "y": 1, "w": 10, "h": 10, "group": "{group}", "props": {{"tag": "Pump", "template": "pumpface", "prefix": "{prefix}", "part": "led1"}}}}"#
        )
    };
    // two instances, each a group of its own
    let good = with(
        &[
            inst("a", "g1", "Pump"),
            inst("b", "g1", "Pump"),
            inst("c", "g2", "T1.ACC"),
        ]
        .join(",\n"),
    );
    assert_eq!(check(&good).1, Vec::<String>::new());
    // one group, two prefixes
    let mixed = with(&[inst("a", "g1", "Pump"), inst("b", "g1", "Light")].join(",\n"));
    let d = check(&mixed).1;
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(
        d[0].contains("`b`: its `template`/`prefix` differ from `a`'s in group `g1`"),
        "{d:?}"
    );
    // a prefix that is no tag name, a template name with a slash, no part, no group
    let bad = with(
        r#"{"id": "x", "type": "led", "x": 1, "y": 1, "w": 10, "h": 10, "props": {"template": "../p", "prefix": "2 pumps"}}"#,
    );
    let d = check(&bad).1;
    assert_eq!(d.len(), 4, "{d:?}");
    for what in [
        "is a symbol's name",
        "`prefix` is a tag name",
        "`part` is the id",
        "in a group of their own",
    ] {
        assert!(d.iter().any(|m| m.contains(what)), "{what}: {d:?}");
    }
}
