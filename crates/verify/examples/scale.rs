//! Measures `alba verify`'s search on a generated 100-rung program with 20
//! inputs, 10 timers and 5 counters (issue 37's performance case): five
//! stations of 20 rungs, each with 4 inputs, 2 timers and a counter, and
//! three safety properties per station. Prints states and time per property.
//!
//! `cargo run -p alba-verify --example scale [--release]`

use alba_verify::explore::{self, Budget, Model, Outcome};
use std::fmt::Write as _;
use std::sync::Arc;

fn station(k: usize, tags: &mut String, lad: &mut String, props: &mut String) {
    let n = |s: &str| format!("S{k}_{s}");
    for (j, name) in ["Start", "Stop", "Part", "Reset"].iter().enumerate() {
        let _ = writeln!(tags, "{},BOOL,DI:1/{},,,", n(name), 4 * k + j);
    }
    for (j, name) in ["Motor", "Fwd", "Rev", "Lamp"].iter().enumerate() {
        let _ = writeln!(tags, "{},BOOL,DO:2/{},,,", n(name), 4 * k + j);
    }
    for name in [
        "Run", "Dir", "Full", "Blink", "Seen", "Ons", "Ack", "Idle", "Busy", "Alarm",
    ] {
        let _ = writeln!(tags, "{},BOOL,,,,", n(name));
    }
    let _ = writeln!(
        tags,
        "{},TIMER,,,,\n{},TIMER,,,,\n{},COUNTER,,,,",
        n("Tr"),
        n("Tb"),
        n("Cp")
    );
    let rungs = [
        format!(
            "[XIC({s}),XIC({m})]XIO({st})OTE({m});",
            s = n("Start"),
            m = n("Motor"),
            st = n("Stop")
        ),
        format!("XIC({m})TON({t},2000,0);", m = n("Motor"), t = n("Tr")),
        format!("XIC({t}.DN)OTE({r});", t = n("Tr"), r = n("Run")),
        format!(
            "XIC({p})ONS({o})XIC({r})CTU({c},5,0);",
            p = n("Part"),
            o = n("Ons"),
            r = n("Run"),
            c = n("Cp")
        ),
        format!("XIC({x})RES({c});", x = n("Reset"), c = n("Cp")),
        format!("XIC({c}.DN)OTL({f});", c = n("Cp"), f = n("Full")),
        format!("XIC({x})OTU({f});", x = n("Reset"), f = n("Full")),
        format!("XIC({r})XIO({f})OTL({d});", r = n("Run"), f = n("Full"), d = n("Dir")),
        format!("XIC({f})OTU({d});", f = n("Full"), d = n("Dir")),
        format!(
            "XIC({r})XIC({d})XIO({v})OTE({w});",
            r = n("Run"),
            d = n("Dir"),
            v = n("Rev"),
            w = n("Fwd")
        ),
        format!(
            "XIC({r})XIO({d})XIO({w})XIO({st})OTE({v});",
            r = n("Run"),
            d = n("Dir"),
            v = n("Rev"),
            w = n("Fwd"),
            st = n("Stop")
        ),
        format!("XIC({f})XIO({b}.DN)TON({b},500,0);", f = n("Full"), b = n("Tb")),
        format!("XIC({b}.DN)OTE({l});", b = n("Tb"), l = n("Blink")),
        format!(
            "[XIC({l}),XIC({r})]OTE({lamp});",
            l = n("Blink"),
            r = n("Run"),
            lamp = n("Lamp")
        ),
        format!("XIC({p})OTE({s});", p = n("Part"), s = n("Seen")),
        format!("XIC({x})XIC({f})OTE({a});", x = n("Reset"), f = n("Full"), a = n("Ack")),
        format!("XIO({m})OTE({i});", m = n("Motor"), i = n("Idle")),
        format!(
            "XIC({m})XIO({i})OTE({b});",
            m = n("Motor"),
            i = n("Idle"),
            b = n("Busy")
        ),
        format!("XIC({f})XIC({w})OTE({a});", f = n("Full"), w = n("Fwd"), a = n("Alarm")),
        format!("XIC({a})OTU({d});", a = n("Alarm"), d = n("Dir")),
    ];
    for r in rungs {
        lad.push_str(&r);
        lad.push('\n');
    }
    let _ = write!(
        props,
        "[[property]]\nname = \"S{k} directions apart\"\nmutex = [\"{f}\", \"{r}\"]\n\n\
         [[property]]\nname = \"S{k} stop wins\"\nnever = \"{st} AND {m}\"\n\n\
         [[property]]\nname = \"S{k} no forward when full\"\nnever = \"{fu} AND {f} AND NOT {a}\"\n\n",
        f = n("Fwd"),
        r = n("Rev"),
        st = n("Stop"),
        m = n("Motor"),
        fu = n("Full"),
        a = n("Alarm"),
    );
}

fn main() {
    let (mut tags, mut lad, mut props) = (
        String::from("name,type,address,initial,retain,description\n"),
        String::new(),
        String::new(),
    );
    for k in 0..5 {
        station(k, &mut tags, &mut lad, &mut props);
    }
    let dir = std::env::temp_dir().join(format!("alba-verify-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"scale\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
    )
    .expect("write");
    std::fs::write(dir.join("tags.csv"), &tags).expect("write");
    std::fs::write(dir.join("main.lad"), &lad).expect("write");
    let c = alba_load::compile_dir(&dir);
    let _ = std::fs::remove_dir_all(&dir);
    let program = Arc::new(c.program.unwrap_or_else(|| panic!("compiles: {:?}", c.diagnostics)));
    let mut files = alba_diag::Files::new();
    let f = files.add("properties.toml", props);
    let p = alba_verify::props::parse(files.text(f), f, &program.layout).expect("properties");
    let model = Model::new(program.clone(), 10, &p);
    println!(
        "program: {} rungs, {} inputs, 10 timers, 5 counters",
        program.rungs.len(),
        model.inputs.len()
    );
    for prop in &p.properties {
        let v = explore::decide(&model, prop, &p.assumes, Budget::default());
        let r = match &v.outcome {
            Outcome::Proved => "proved".to_string(),
            Outcome::Refuted => "refuted".to_string(),
            Outcome::Unknown(w) => format!("unknown ({w})"),
        };
        println!(
            "{:<32} {r:<8} {:>8} states  depth {:>5}  {:>6} ms  {:?}, {} SAT calls",
            prop.name, v.states, v.depth, v.millis, v.method, v.sat_calls
        );
    }
}
