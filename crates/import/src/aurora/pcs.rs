//! `.pcs` SCADA screens (seed `000_…` §3.19, §3.24) onto Alba's screens
//! (`hmi/<name>.json`, docs/file-formats.md "Screens"), which have the same
//! 30 element types.
//!
//! A `.pcs` is saved like instructions.pl (§3.24: "se guardan en orden
//! específico y conocido"): the counter of each of the 30 element types in
//! the order of §3.19.1–3.19.30, then every element's attributes, type after
//! type, one a line, in the order of its class's main attributes (Figs.
//! 227–287; the alarm's order is Fig. 317's). Colours are Processing's
//! `hex()` of the ARGB value (Fig. 318 reads them with `unhex`). The seed
//! does not give the layout of the animations that follow some elements'
//! attributes (Fig. 318 only shows that they exist), so they are not read: a
//! file holding them does not parse, and the screen is reported as refused
//! at the first value that does not fit — the ladder, the tags and the other
//! screens are imported all the same.

use super::{F, Held, MAX_EACH, Reader, Rec, Tags, clip};
use crate::{AlarmOut, ElementOut, Error, Kind, Location, Report, ScreenOut};
use serde_json::{Map, Value, json};

use F::{Bool as B, Color as C, Float as Fl, Int as I, Str as S};

/// Vertices of a line or polygon (`new int[200]`, Figs. 241, 243).
const VERTICES: usize = 200;

/// The attributes of a class, in their saved order.
type Layout = &'static [(&'static str, F)];

/// The 30 types: AuroraLD's class, Alba's type, the attributes.
#[rustfmt::skip]
const TYPES: [(&str, &str, Layout); 30] = [
    ("HMI_TEXT", "text", &[("x", I), ("y", I), ("col", C), ("size", I), ("texto", S), ("layer", I), ("num", I)]),
    ("HMI_IN", "input", &[("x", I), ("y", I), ("col_txt", C), ("col_bg", C), ("size", Fl), ("txt", S), ("layer", I), ("num", I), ("wr", Fl), ("hr", Fl), ("tag", S), ("row_tag", I)]),
    ("HMI_OUT", "output", &[("x", I), ("y", I), ("col_txt", C), ("col_rect", C), ("size", Fl), ("layer", I), ("num", I), ("wr", Fl), ("hr", Fl), ("obox_decimal", I), ("obox_int", I), ("tag", S), ("row_tag", I)]),
    ("HMI_RECT", "rectangle", &[("x", I), ("y", I), ("col_rect", C), ("rect_stroke", C), ("layer", I), ("num", I), ("wr", Fl), ("hr", Fl)]),
    ("HMI_CIRC", "circle", &[("x", I), ("y", I), ("col_circ", C), ("circ_stroke", C), ("layer", I), ("num", I), ("wr", Fl), ("hr", Fl)]),
    ("HMI_BUTTON", "button", &[("x", I), ("y", I), ("col_txt", C), ("col_button", C), ("texto", S), ("layer", I), ("num", I), ("tag", S), ("row_tag", I)]),
    ("HMI_SWITCH", "switch", &[("x", I), ("y", I), ("col_switch_on", C), ("col_switch_off", C), ("layer", I), ("num", I), ("switch_type", I), ("tag", S), ("row_tag", I)]),
    // x[200] and y[200] come first (read apart), then these.
    ("HMI_LINE", "line", &[("vx_num", I), ("x1", I), ("y1", I), ("col_line", C), ("line_stroke", Fl), ("layer", I), ("num", I)]),
    ("HMI_POLYGON", "polygon", &[("vx_num", I), ("col_pol", C), ("pol_stroke", C), ("layer", I), ("num", I)]),
    ("HMI_SLIDER", "slider", &[("x", I), ("y", I), ("min_s", Fl), ("max_s", Fl), ("slider_result", Fl), ("fill_slider", C), ("layer", I), ("num", I), ("tag", S), ("row_tag", I)]),
    ("HMI_LED", "led", &[("x", I), ("y", I), ("col_led", C), ("layer", I), ("num", I), ("led_size", Fl), ("tag", S), ("row_tag", I)]),
    ("HMI_ARC", "arc", &[("x", I), ("y", I), ("col_arc", C), ("arc_stroke", C), ("layer", I), ("num", I), ("r", Fl), ("arc_ang1", Fl), ("arc_ang2", Fl)]),
    ("HMI_WIND", "wind_turbine", &[("x", I), ("y", I), ("col_blade", C), ("col_tower", C), ("layer", I), ("num", I), ("com_wind", B), ("tag", S), ("row_tag", I)]),
    ("HMI_FAN", "fan", &[("x", I), ("y", I), ("col_blade", C), ("col_bg", C), ("layer", I), ("num", I), ("com_fan", B), ("tag", S), ("row_tag", I)]),
    ("HMI_COOL", "cooling_tower", &[("x", I), ("y", I), ("col_cool", C), ("layer", I), ("num", I), ("cool_size", Fl)]),
    ("HMI_PLC", "plc", &[("x", I), ("y", I), ("col_plc", C), ("layer", I), ("num", I)]),
    ("HMI_TIME", "clock", &[("x", I), ("y", I), ("col_text", C), ("col_bg", C), ("size", Fl), ("layer", I), ("num", I), ("wr", Fl), ("hr", Fl)]),
    ("HMI_BOTTLE", "bottle", &[("x", I), ("y", I), ("col_bottle", C), ("col_fill", C), ("layer", I), ("num", I), ("min", Fl), ("max", Fl), ("tag", S), ("tag2", S), ("row_tag", I), ("row_tag2", I)]),
    ("HMI_MOTOR", "motor", &[("x", I), ("y", I), ("col_motor_on", C), ("col_motor_off", C), ("layer", I), ("num", I), ("motor_type", I), ("tag", S), ("row_tag", I)]),
    ("HMI_PUMP", "pump", &[("x", I), ("y", I), ("col_fluid", C), ("col_blade", C), ("col_pump", C), ("layer", I), ("num", I), ("dr", Fl), ("tag", S), ("row_tag", I)]),
    ("HMI_TANK", "tank", &[("x", I), ("y", I), ("col_tank", C), ("col_fluid", C), ("layer", I), ("num", I), ("tank_type", I), ("mint", Fl), ("maxt", Fl), ("tag", S), ("row_tag", I)]),
    ("HMI_PIPE", "pipe", &[("x", I), ("y", I), ("col_pipe", C), ("col_fluid", C), ("layer", I), ("num", I), ("lr", Fl), ("dr", Fl), ("pipe_type", I), ("pipe_angle", I), ("tag", S), ("row_tag", I)]),
    ("HMI_VALVE", "valve", &[("x", I), ("y", I), ("col_pipe", C), ("col_fluid", C), ("col_valve", C), ("layer", I), ("num", I), ("dr", Fl), ("valve_type", I), ("valve_angle", I), ("tag", S), ("row_tag", I)]),
    ("HMI_BUILD", "building", &[("x", I), ("y", I), ("col_build", C), ("col_light", C), ("layer", I), ("num", I), ("build_type", B), ("tag", S), ("row_tag", I)]),
    ("HMI_POWER", "transmission_tower", &[("x", I), ("y", I), ("layer", I), ("num", I), ("col_power", C)]),
    ("HMI_SIGNS", "safety_sign", &[("x", I), ("y", I), ("layer", I), ("num", I), ("size", Fl), ("sign_type", I)]),
    ("HMI_METER", "meter", &[("x", I), ("y", I), ("col_value", C), ("layer", I), ("num", I), ("meter_type", I), ("value", Fl), ("meter_value", Fl), ("minm", Fl), ("maxm", Fl), ("unit", S), ("parameter", S), ("tag", S), ("row_tag", I)]),
    ("HMI_ALARM", "alarm", &[("x", I), ("y", I), ("layer", I), ("num", I), ("row_tag", I), ("alarm_sound", I), ("alarm_action", I), ("tag", S), ("alarm_type", I)]),
    ("HMI_GRAPH", "trend", &[("x", I), ("y", I), ("layer", I), ("num", I), ("wr", Fl), ("hr", Fl), ("col_bg", C), ("col_l1", C), ("col_l2", C), ("col_l3", C), ("tag1", S), ("tag2", S), ("tag3", S), ("row_tag1", I), ("row_tag2", I), ("row_tag3", I), ("window_size", I), ("trend_title", S)]),
    ("HMI_IMAGE", "image", &[("x", I), ("y", I), ("layer", I), ("num", I), ("wr", Fl), ("hr", Fl), ("image_file", S), ("image_percentage", Fl)]),
];

/// One saved element.
struct Saved {
    ty: usize,
    rec: Rec,
    /// The vertices of a line or polygon.
    points: Vec<(f64, f64)>,
}

fn read(file: &str, text: &str) -> Result<Vec<Saved>, Error> {
    let mut r = Reader::new(file, text);
    let mut counts = Vec::new();
    for (class, _, _) in TYPES {
        counts.push(r.count(&|| format!("the number of {class} elements"), &|n| {
            format!("{n} {class}: a screen holds 0 to {MAX_EACH} of each element")
        })?);
    }
    let mut out = Vec::new();
    for (ty, ((class, _, layout), n)) in TYPES.iter().zip(counts).enumerate() {
        for k in 0..n {
            let what = format!("{class} {k}");
            let mut points = Vec::new();
            if matches!(*class, "HMI_LINE" | "HMI_POLYGON") {
                let mut xs = Vec::with_capacity(VERTICES);
                for axis in ["x", "y"] {
                    for v in 0..VERTICES {
                        let (val, _) = r.value(F::Int, &|| format!("{axis}[{v}] of {what}"))?;
                        xs.push(if let super::Val::I(n) = val { n as f64 } else { 0.0 });
                    }
                }
                let (x, y) = xs.split_at(VERTICES);
                points = x.iter().copied().zip(y.iter().copied()).collect();
            }
            let rec = r.record(&what, layout)?;
            if !points.is_empty() {
                let n = rec.i("vx_num");
                if !(0..=VERTICES as i64).contains(&n) {
                    return Err(Error::at(
                        rec.at("vx_num"),
                        format!("{what} has {n} vertices: 0 to {VERTICES}"),
                    ));
                }
                points.truncate(n as usize);
            }
            out.push(Saved { ty, rec, points });
        }
    }
    r.finish("the attributes of the last element")?;
    Ok(out)
}

/// `hmi/<name>.json` of a `.pcs` file name (letters, digits, `_`, `-`).
fn screen_name(file: &str) -> String {
    let stem = file.rsplit_once('.').map(|(s, _)| s).unwrap_or(file);
    let s: String = stem
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
        .collect();
    if s.is_empty() { "screen".into() } else { s }
}

/// Converts one `.pcs` file. A file that does not parse is reported and
/// gives no screen; the alarms of its alarm elements are returned apart.
pub(crate) fn convert(
    file: &str,
    text: &str,
    tags: &Tags,
    taken: &[AlarmOut],
    report: &mut Report,
) -> Result<(Option<ScreenOut>, Vec<AlarmOut>), Error> {
    let saved = match read(file, text) {
        Ok(s) => s,
        Err(e) => {
            let at = e.location.clone().unwrap_or_else(|| Location::new(file, 1, 1));
            report.push(
                Kind::Refused,
                at,
                format!(
                    "screen {file} not imported: {} (docs/interchange.md, AuroraLD screens)",
                    e.message
                ),
            );
            return Ok((None, Vec::new()));
        }
    };
    let name = screen_name(file);
    let mut elements: Vec<(i64, usize, ElementOut)> = Vec::new();
    let mut alarms: Vec<AlarmOut> = Vec::new();
    let mut ids: Vec<String> = Vec::new();
    let mut fresh = |base: &str| {
        let mut id = base.to_string();
        let mut k = 2;
        while ids.contains(&id) {
            id = format!("{base}_{k}");
            k += 1;
        }
        ids.push(id.clone());
        id
    };
    for (order, s) in saved.iter().enumerate() {
        let (_, kind, _) = TYPES[s.ty];
        let rec = &s.rec;
        let loc = rec.loc.clone();
        let layer = rec.i("layer");
        let base = format!("{kind}{}", rec.i("num"));
        let mut notes = Vec::new();
        let taken_id = |id: &str| taken.iter().chain(&alarms).any(|a| a.id.eq_ignore_ascii_case(id));
        let b = match build(kind, s, tags, &name, &taken_id, &mut notes) {
            Ok(b) => b,
            Err(why) => {
                report.push(Kind::Refused, loc, format!("{}: {why}; left out", rec.what));
                continue;
            }
        };
        for (k, l, m) in notes {
            report.push(k, l, m);
        }
        if let Some(a) = b.alarm {
            alarms.push(a);
        }
        if kind == "line" {
            // Each segment of the polyline, from (x1, y1) through the vertices.
            let mut pts = vec![(rec.f("x1"), rec.f("y1"))];
            pts.extend(s.points.iter().copied());
            let thick = rec.f("line_stroke").max(1.0);
            for (k, seg) in pts.windows(2).enumerate() {
                let ((ax, ay), (bx, by)) = (seg[0], seg[1]);
                let len = (bx - ax).hypot(by - ay).max(1.0);
                let (cx, cy) = ((ax + bx) / 2.0, (ay + by) / 2.0);
                let id = fresh(&format!("{base}_{k}"));
                let el = json!({
                    "id": id, "type": "line", "x": r1(cx - len / 2.0), "y": r1(cy - thick / 2.0), "w": r1(len), "h": r1(thick),
                    "rotation": r1((by - ay).atan2(bx - ax).to_degrees()),
                });
                elements.push((
                    layer,
                    order,
                    ElementOut {
                        id,
                        json: el,
                        origin: loc.clone(),
                    },
                ));
            }
            continue;
        }
        let (ex, ey) = b.at.unwrap_or((rec.f("x"), rec.f("y")));
        let id = fresh(&base);
        let mut el = json!({"id": id, "type": kind, "x": r1(ex), "y": r1(ey), "w": r1(b.w), "h": r1(b.h)});
        if let Some(o) = el.as_object_mut() {
            if b.rotation != 0.0 {
                o.insert("rotation".into(), json!(r1(b.rotation)));
            }
            if !b.props.is_empty() {
                o.insert("props".into(), Value::Object(b.props));
            }
            if !b.anims.is_empty() {
                o.insert("animations".into(), Value::Array(b.anims));
            }
            if let Some(a) = b.action {
                o.insert("action".into(), a);
            }
        }
        elements.push((
            layer,
            order,
            ElementOut {
                id,
                json: el,
                origin: loc,
            },
        ));
    }
    // Drawn by layer, the highest on top (§3.19).
    elements.sort_by_key(|(layer, order, _)| (*layer, *order));
    let elements: Vec<ElementOut> = elements.into_iter().map(|(_, _, e)| e).collect();
    let (mut width, mut height) = (200.0f64, 150.0f64);
    for e in &elements {
        let g = |k: &str| e.json.get(k).and_then(Value::as_f64).unwrap_or(0.0);
        width = width.max(g("x") + g("w") + 20.0);
        height = height.max(g("y") + g("h") + 20.0);
    }
    if !elements.is_empty() {
        report.push(
            Kind::Approximated,
            Location::new(file, 1, 1),
            format!(
                "screen hmi/{name}.json: {} elements; their own colours are kept where an animation shows a state (LED, switch, motor, pipe, tank …); Alba draws the rest in its greys",
                elements.len()
            ),
        );
    }
    Ok((
        Some(ScreenOut {
            file: format!("hmi/{name}.json"),
            title: name,
            width: width.clamp(1.0, 20_000.0).ceil() as u32,
            height: height.clamp(1.0, 20_000.0).ceil() as u32,
            elements,
        }),
        alarms,
    ))
}

/// An element in Alba's terms.
struct Built {
    w: f64,
    h: f64,
    /// Its box's corner, when not the saved `x`, `y`.
    at: Option<(f64, f64)>,
    rotation: f64,
    props: Map<String, Value>,
    anims: Vec<Value>,
    action: Option<Value>,
    alarm: Option<AlarmOut>,
}

type Notes = Vec<(Kind, Location, String)>;

/// Converts one saved element of Alba type `kind` (`Err`: why it is refused).
fn build(
    kind: &str,
    s: &Saved,
    tags: &Tags,
    screen: &str,
    taken: &dyn Fn(&str) -> bool,
    notes: &mut Notes,
) -> Result<Built, String> {
    let rec = &s.rec;
    let loc = rec.loc.clone();
    // The value a tag field names, if any.
    let tag = |field: &str| -> Result<Option<String>, String> {
        let t = rec.s(field).trim();
        if t.is_empty() || t == "?" {
            return Ok(None);
        }
        match tags.resolve(t) {
            Ok((alba, Held::Bit | Held::Number)) => Ok(Some(alba)),
            Ok((_, Held::Structure(_))) => Err(format!("`{t}` is a structure; a screen shows its members")),
            Err(e) => Err(e),
        }
    };
    let needed = |field: &str| -> Result<String, String> {
        tag(field)?.ok_or_else(|| format!("no tag is assigned to its `{field}` (`?`)"))
    };
    let range = |lo: f64, hi: f64| {
        if lo < hi {
            Ok(())
        } else {
            Err(format!("its range {lo} to {hi} is empty"))
        }
    };
    let wr = |d: f64| if rec.f("wr") > 0.0 { rec.f("wr") } else { d };
    let hr = |d: f64| if rec.f("hr") > 0.0 { rec.f("hr") } else { d };
    let mut b = Built {
        w: 60.0,
        h: 60.0,
        at: None,
        rotation: 0.0,
        props: Map::new(),
        anims: Vec::new(),
        action: None,
        alarm: None,
    };
    match kind {
        "text" => {
            let size = rec.f("size").max(1.0);
            let chars = rec.s("texto").chars().count().max(1) as f64;
            (b.w, b.h) = ((chars * size * 0.6).max(20.0), size * 1.5);
            b.props.insert("label".into(), json!(rec.s("texto")));
            b.props.insert("size".into(), json!(size));
        }
        "input" => {
            (b.w, b.h) = (wr(100.0), hr(30.0));
            b.action = Some(json!({"kind": "input", "tag": needed("tag")?}));
        }
        "output" => {
            (b.w, b.h) = (wr(100.0), hr(30.0));
            b.props.insert("tag".into(), json!(needed("tag")?));
            b.props
                .insert("decimals".into(), json!(rec.i("obox_decimal").clamp(0, 9)));
        }
        "rectangle" | "circle" | "clock" => (b.w, b.h) = (wr(80.0), hr(80.0)),
        "button" => {
            (b.w, b.h) = (120.0, 36.0);
            b.props.insert("label".into(), json!(rec.s("texto")));
            b.action = Some(json!({"kind": "momentary", "tag": needed("tag")?}));
        }
        "switch" => {
            (b.w, b.h) = (120.0, 36.0);
            let t = needed("tag")?;
            b.anims
                .push(json!({"kind": "color", "tag": t, "on": rec.s("col_switch_on"), "off": rec.s("col_switch_off")}));
            b.action = Some(json!({"kind": "toggle", "tag": t}));
        }
        "slider" => {
            (b.w, b.h) = (160.0, 30.0);
            let (lo, hi) = (rec.f("min_s"), rec.f("max_s"));
            range(lo, hi)?;
            b.action = Some(json!({"kind": "slider", "tag": needed("tag")?, "min": lo, "max": hi}));
        }
        "led" => {
            let d = rec.f("led_size").max(4.0);
            (b.w, b.h) = (d, d);
            b.anims
                .push(json!({"kind": "color", "tag": needed("tag")?, "on": rec.s("col_led")}));
        }
        "arc" => {
            let d = (2.0 * rec.f("r")).max(4.0);
            (b.w, b.h) = (d, d / 2.0);
            notes.push((
                Kind::Approximated,
                loc,
                format!(
                    "{}: the arc from {}° to {}° is drawn as Alba's half arc in its box",
                    rec.what,
                    rec.f("arc_ang1"),
                    rec.f("arc_ang2")
                ),
            ));
        }
        "wind_turbine" | "fan" | "pump" => {
            (b.w, b.h) = match kind {
                "wind_turbine" => (100.0, 160.0),
                "fan" => (60.0, 60.0),
                _ => (70.0, 70.0),
            };
            if let Some(t) = tag("tag")? {
                b.anims.push(json!({"kind": "rotate", "tag": t, "speed": 1}));
            }
        }
        "cooling_tower" => {
            let s = rec.f("cool_size").max(20.0);
            (b.w, b.h) = (s, s * 1.2);
        }
        "plc" => (b.w, b.h) = (120.0, 80.0),
        "transmission_tower" => (b.w, b.h) = (80.0, 160.0),
        "safety_sign" => {
            let s = rec.f("size").max(10.0);
            (b.w, b.h) = (s, s);
        }
        "bottle" => {
            (b.w, b.h) = (80.0, 140.0);
            if let Some(t) = tag("tag")? {
                let (lo, hi) = (rec.f("min"), rec.f("max"));
                range(lo, hi)?;
                b.anims.push(json!({"kind": "fill", "tag": t, "min": lo, "max": hi, "direction": "up", "color": rec.s("col_fill")}));
            }
            if tag("tag2")?.is_some() {
                notes.push((
                    Kind::Approximated,
                    rec.at("tag2"),
                    format!(
                        "{}: Alba's bottle has no cap; the cap's tag `{}` is not shown",
                        rec.what,
                        rec.s("tag2").trim()
                    ),
                ));
            }
        }
        "motor" => {
            (b.w, b.h) = (60.0, 60.0);
            // The motor's type is its angle (§3.19.19): 0, 90, 180, 270°.
            b.rotation = 90.0 * rec.i("motor_type").rem_euclid(4) as f64;
            if let Some(t) = tag("tag")? {
                b.anims.push(
                    json!({"kind": "color", "tag": t, "on": rec.s("col_motor_on"), "off": rec.s("col_motor_off")}),
                );
            }
        }
        "tank" => {
            (b.w, b.h) = (120.0, 200.0);
            if rec.i("tank_type") == 2 {
                b.props.insert("style".into(), json!("silo"));
            }
            if let Some(t) = tag("tag")? {
                let (lo, hi) = (rec.f("mint"), rec.f("maxt"));
                range(lo, hi)?;
                b.anims.push(json!({"kind": "fill", "tag": t, "min": lo, "max": hi, "direction": "up", "color": rec.s("col_fluid")}));
            }
        }
        "pipe" | "valve" => {
            let dr = rec.f("dr").max(4.0);
            let pipe = kind == "pipe";
            (b.w, b.h) = if pipe {
                (rec.f("lr").max(4.0), dr)
            } else {
                (dr * 1.2, dr * 1.6)
            };
            b.rotation = rec.i(if pipe { "pipe_angle" } else { "valve_angle" }) as f64;
            if let Some(t) = tag("tag")? {
                b.anims
                    .push(json!({"kind": "color", "tag": t, "on": rec.s("col_fluid")}));
            }
            let shape = rec.i(if pipe { "pipe_type" } else { "valve_type" });
            if shape != 0 {
                notes.push((
                    Kind::Approximated,
                    loc,
                    format!("{}: its shape {shape} is drawn as Alba's {kind}", rec.what),
                ));
            }
        }
        "building" => {
            (b.w, b.h) = (120.0, 100.0);
            if let Some(t) = tag("tag")? {
                b.anims
                    .push(json!({"kind": "color", "tag": t, "on": rec.s("col_light")}));
            }
        }
        "meter" => {
            let circular = rec.i("meter_type") == 1;
            (b.w, b.h) = if circular { (100.0, 100.0) } else { (40.0, 160.0) };
            let t = needed("tag")?;
            let (lo, hi) = (rec.f("minm"), rec.f("maxm"));
            range(lo, hi)?;
            b.props.insert("tag".into(), json!(t));
            let label = format!("{} {}", rec.s("parameter").trim(), rec.s("unit").trim());
            if !label.trim().is_empty() {
                b.props.insert("label".into(), json!(label.trim()));
            }
            if circular {
                b.props.insert("style".into(), json!("circular"));
                b.anims.push(json!({"kind": "rotate", "tag": t, "min": lo, "max": hi}));
            } else {
                b.anims
                    .push(json!({"kind": "fill", "tag": t, "min": lo, "max": hi, "direction": "up"}));
            }
        }
        "alarm" => {
            (b.w, b.h) = (24.0, 24.0);
            let t = needed("tag")?;
            if rec.i("alarm_type") != 0 {
                return Err(
                    "an analog alarm: the attributes the seed gives (Fig. 317) do not hold its intervals".into(),
                );
            }
            // The four modes in the order of §3.20.
            let (cond, what) = match rec.i("alarm_action") {
                0 => ("rising", "changes to on"),
                1 => ("falling", "changes to off"),
                2 => ("on", "is on"),
                3 => ("off", "is off"),
                n => return Err(format!("alarm action {n} is not one of AuroraLD's four (§3.20)")),
            };
            let mut id = format!("{screen}_alarm{}", rec.i("num"));
            let mut k = 2;
            while taken(&id) {
                id = format!("{screen}_alarm{}_{k}", rec.i("num"));
                k += 1;
            }
            notes.push((
                Kind::Approximated,
                rec.at("alarm_sound"),
                format!(
                    "{}: alarm `{id}` on `{t}` ({cond}) in alarms.csv; its sound {} is the studio's alarm sound",
                    rec.what,
                    rec.i("alarm_sound")
                ),
            ));
            b.props.insert("alarm".into(), json!(id));
            b.alarm = Some(AlarmOut {
                id,
                tag: t,
                condition: cond.into(),
                severity: "medium".into(),
                message: format!("{} {what} (AuroraLD alarm)", rec.s("tag").trim()),
                origin: loc,
            });
        }
        "trend" => {
            (b.w, b.h) = (wr(300.0), hr(160.0));
            b.props.insert("tag".into(), json!(needed("tag1")?));
            b.props.insert("label".into(), json!(rec.s("trend_title")));
            for f in ["tag2", "tag3"] {
                if tag(f)?.is_some() {
                    notes.push((
                        Kind::Approximated,
                        rec.at(f),
                        format!(
                            "{}: Alba's trend element draws one pen; `{}` is not drawn (add it to the studio's trend)",
                            rec.what,
                            rec.s(f).trim()
                        ),
                    ));
                }
            }
        }
        "image" => {
            return Err(format!(
                "the picture `{}` is not copied into the project",
                clip(rec.s("image_file").trim())
            ));
        }
        "polygon" => {
            if s.points.len() < 3 {
                return Err("a polygon needs 3 vertices".into());
            }
            let (x0, y0, x1, y1) = bounds(&s.points);
            notes.push((
                Kind::Approximated,
                loc,
                format!(
                    "{}: its {} vertices are drawn as Alba's polygon symbol in their box",
                    rec.what,
                    s.points.len()
                ),
            ));
            b.at = Some((x0, y0));
            (b.w, b.h) = ((x1 - x0).max(1.0), (y1 - y0).max(1.0));
        }
        "line" if s.points.is_empty() => return Err("a line without vertices".into()),
        _ => {}
    }
    Ok(b)
}

/// A coordinate to a tenth of a pixel.
fn r1(v: f64) -> f64 {
    (v * 10.0).round() / 10.0
}

fn bounds(p: &[(f64, f64)]) -> (f64, f64, f64, f64) {
    p.iter().fold(
        (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
        |(a, b, c, d), &(x, y)| (a.min(x), b.min(y), c.max(x), d.max(y)),
    )
}
