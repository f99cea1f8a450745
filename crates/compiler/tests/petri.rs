//! Petri-mode nets in a project: marking tags in the layout and the E62x
//! diagnostics, located in the .pnml file.

use alba_diag::Code;
use alba_ir::{Place, Target};
use alba_load::compile_dir;
use std::path::PathBuf;

/// A project folder with `tags.csv`, one net `line.pnml` and `extra` files.
fn project(name: &str, tags: &str, net: &str, extra: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-petri-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch project");
    let mut programs = vec!["\"line.pnml\"".to_string()];
    programs.extend(extra.iter().map(|(f, _)| format!("\"{f}\"")));
    let toml = format!("name = \"{name}\"\nprograms = [{}]\n", programs.join(", "));
    std::fs::write(dir.join("alba.toml"), toml).expect("scratch project");
    std::fs::write(
        dir.join("tags.csv"),
        format!("name,type,address,initial,retain,description\n{tags}"),
    )
    .expect("scratch project");
    std::fs::write(dir.join("line.pnml"), net).expect("scratch project");
    for (f, text) in extra {
        let path = dir.join(f);
        std::fs::create_dir_all(path.parent().expect("a parent")).expect("scratch project");
        std::fs::write(path, text).expect("scratch project");
    }
    dir
}

fn net(body: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<pnml xmlns=\"http://www.pnml.org/version-2009/grammar/pnml\">\n<net id=\"n\" type=\"http://www.pnml.org/version-2009/grammar/ptnet\">\n<page id=\"pg\">\n{body}\n</page>\n</net>\n</pnml>\n"
    )
}

const CYCLE: &str = r#"<place id="filling"><initialMarking><text>2</text></initialMarking></place>
<place id="empty"/>
<transition id="t1"/>
<arc id="a1" source="filling" target="t1"/>
<arc id="a2" source="t1" target="empty"/>"#;

fn place_tag(tag: &str) -> String {
    format!(
        r#"<place id="p"><initialMarking><text>1</text></initialMarking><toolspecific tool="alba" version="1"><tag>{tag}</tag></toolspecific></place>
<transition id="t"/>
<arc id="a" source="p" target="t"/>"#
    )
}

fn guard(g: &str) -> String {
    format!(
        r#"<place id="p"><initialMarking><text>1</text></initialMarking></place>
<transition id="t"><toolspecific tool="alba" version="1"><guard>{g}</guard></toolspecific></transition>
<arc id="a" source="p" target="t"/>"#
    )
}

const TAGS: &str =
    "Start,BOOL,DI:1/0,,,an input\nLevel,DINT,,,,a number\nLamp,BOOL,,,,a lamp\nDelay,TIMER,,,,a timer\n";

/// The codes, file names and lines of the diagnostics of a project.
fn errors(dir: &std::path::Path) -> Vec<(Code, String, usize)> {
    let c = compile_dir(dir);
    assert!(c.program.is_none(), "expected errors");
    c.diagnostics
        .iter()
        .map(|d| {
            let span = d.primary.as_ref().expect("located").span;
            let path = std::path::Path::new(c.files().name(span.file));
            let name = path.file_name().unwrap_or_default().to_string_lossy().to_string();
            (d.code, name, c.files().line_col(span.file, span.start as usize).0)
        })
        .collect()
}

#[test]
fn each_place_is_a_dint_tag_named_net_dot_place_with_its_initial_marking() {
    let dir = project("marking", TAGS, &net(CYCLE), &[]);
    let c = compile_dir(&dir);
    assert!(c.diagnostics.is_empty(), "{:?}", c.diagnostics);
    let program = c.program.expect("compiles");
    let layout = &program.layout;
    // After the tags of tags.csv, so that theirs keep their slots.
    let names: Vec<&str> = layout.tags.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["Start", "Level", "Lamp", "Delay", "line.filling", "line.empty"]);
    let Ok(Target::Value {
        place: Place::Int(slot, ty),
        access,
    }) = layout.resolve("LINE.Filling")
    else {
        panic!("line.filling does not resolve to an integer slot");
    };
    assert_eq!(ty, alba_model::DataType::Dint);
    assert_eq!(access, alba_ir::Access::ReadWrite, "an operator may write a marking");
    assert_eq!(program.init.i[slot.0 as usize], 2);
    assert!(layout.tags.get("line.filling").is_some_and(|t| !t.retain));
    // Members of other tags still resolve.
    assert!(matches!(layout.resolve("Delay.DN"), Ok(Target::Value { .. })));
}

#[test]
fn a_marking_tag_may_not_clash_with_a_tag() {
    // A tags.csv name cannot have a dot; a second net can clash.
    let dir = project("clash", TAGS, &net(CYCLE), &[("sub/line.pnml", &net(CYCLE))]);
    let e = errors(&dir);
    assert!(
        e.iter()
            .any(|(c, f, _)| *c == Code::NetTagClash && f.ends_with("line.pnml")),
        "{e:?}"
    );
    // A net named like a TIMER tag may not shadow its members.
    let tags = format!("{TAGS}line,TIMER,,,,a timer named like the net\n");
    let dn = net(r#"<place id="DN"/><place id="other"/>"#);
    let dir = project("member", &tags, &dn, &[]);
    assert_eq!(errors(&dir), [(Code::NetTagClash, "line.pnml".to_string(), 5)]);
}

#[test]
fn place_tags_must_be_writable_bools() {
    for (name, tag) in [
        ("unknown", "Lampp"),
        ("dint", "Level"),
        ("input", "Start"),
        ("timer", "Delay"),
        ("status", "Delay.DN"),
        ("system", "S:FS"),
    ] {
        let dir = project(&format!("tag-{name}"), TAGS, &net(&place_tag(tag)), &[]);
        let e = errors(&dir);
        assert_eq!(e, [(Code::NetPlaceTag, "line.pnml".to_string(), 5)], "{name}");
    }
    let dir = project("tag-ok", TAGS, &net(&place_tag("Lamp")), &[]);
    assert!(compile_dir(&dir).program.is_some());
}

#[test]
fn guards_are_bool_expressions_over_known_tags() {
    for (name, g) in [
        ("unknown", "Startt"),
        ("number", "Level + 1"),
        ("not-number", "NOT Level"),
        ("and-number", "Start AND Level"),
        ("timer", "Delay"),
        ("syntax", "Start AND"),
        ("unknown-function", "cosine(Level) &gt; 2"),
        ("function-of-bool", "abs(Start) &gt; 2"),
        ("function-arity", "rem(Level) &gt; 2"),
        ("bool-arith", "Start + 1 &gt; 0"),
    ] {
        let dir = project(&format!("guard-{name}"), TAGS, &net(&guard(g)), &[]);
        let e = errors(&dir);
        assert!(
            !e.is_empty()
                && e.iter()
                    .all(|(c, f, l)| *c == Code::NetGuard && f == "line.pnml" && *l == 6),
            "{name}: {e:?}"
        );
    }
    for g in [
        "Start",
        "NOT Start AND (Level &gt;= 3 OR Level * 2 = 7)",
        "Delay.DN XOR Lamp",
        "Level / 0 &lt; 1.5",
        "TRUE",
        "false OR Lamp = FALSE",
        // The state-net source's functions and operators (issue 34).
        "ABS(Level) &gt; 2",
        "cos(Level) &gt; 0.5 &amp; (Level % 2 == 0) | sqrt(Level) : 2 != 1",
    ] {
        let dir = project("guard-ok", TAGS, &net(&guard(g)), &[]);
        let c = compile_dir(&dir);
        assert!(c.program.is_some(), "{g}: {:?}", c.diagnostics);
    }
}

#[test]
fn the_state_net_kinds_run_in_normal_mode_only() {
    let timer = net(
        r#"<place id="p"/><transition id="t"><toolspecific tool="alba" version="1"><kind>timer</kind></toolspecific></transition>"#,
    );
    let dir = project("kind", TAGS, &timer, &[]);
    assert_eq!(errors(&dir), [(Code::NetMode, "line.pnml".to_string(), 5)]);
}

fn normal(body: &str) -> String {
    net(body).replace(
        "<page id=\"pg\">",
        "<toolspecific tool=\"alba\" version=\"1\"><mode>normal</mode></toolspecific>\n<page id=\"pg\">",
    )
}

#[test]
fn normal_mode_gives_every_element_a_token_tag_and_timers_and_counts_their_own() {
    let body = r#"<place id="s"><initialMarking><text>1</text></initialMarking></place>
<place id="c"><toolspecific tool="alba" version="1"><kind>counter</kind><prop name="load">7</prop></toolspecific></place>
<transition id="t"><toolspecific tool="alba" version="1"><kind>timer</kind><prop name="delay">T#2s</prop></toolspecific></transition>
<transition id="back"/>
<arc id="a1" source="s" target="t"/>
<arc id="a2" source="t" target="c"/>
<arc id="a3" source="c" target="back"/>
<arc id="a4" source="back" target="s"/>"#;
    let dir = project(
        "normal-tags",
        TAGS,
        &normal(body),
        &[("main.lad", "XIC(line.t.timer.DN)OTE(Lamp);\n")],
    );
    let c = compile_dir(&dir);
    assert!(c.diagnostics.is_empty(), "{:?}", c.diagnostics);
    let program = c.program.expect("compiles");
    let names: Vec<&str> = program.layout.tags.iter().map(|t| t.name.as_str()).skip(4).collect();
    assert_eq!(
        names,
        [
            "line.s",
            "line.c",
            "line.t",
            "line.t.timer",
            "line.back",
            "line.c.count"
        ]
    );
    for member in ["line.t.timer.ACC", "line.t.timer.DN", "line.c.count", "line.back"] {
        assert!(
            matches!(program.layout.resolve(member), Ok(Target::Value { .. })),
            "{member}"
        );
    }
}

#[test]
fn normal_mode_elements_are_checked() {
    let cases = [
        // A condition without its guard.
        (
            r#"<place id="p"/><transition id="t"><toolspecific tool="alba" version="1"><kind>condition</kind></toolspecific></transition>"#,
            Code::NetElement,
            6,
        ),
        // A timer without a delay, and with a bad one.
        (
            r#"<place id="p"/><transition id="t"><toolspecific tool="alba" version="1"><kind>timer</kind></toolspecific></transition>"#,
            Code::NetElement,
            6,
        ),
        (
            r#"<place id="p"/><transition id="t"><toolspecific tool="alba" version="1"><kind>timer</kind><prop name="delay">soon</prop></toolspecific></transition>"#,
            Code::NetElement,
            6,
        ),
        // A counter counting sideways, a property a kind does not take.
        (
            r#"<place id="p"><toolspecific tool="alba" version="1"><kind>counter</kind><prop name="direction">sideways</prop></toolspecific></place>"#,
            Code::NetElement,
            6,
        ),
        (
            r#"<place id="p"><toolspecific tool="alba" version="1"><prop name="colour">red</prop></toolspecific></place>"#,
            Code::NetElement,
            6,
        ),
        // Petri mode's arcs.
        (
            r#"<place id="p"/><transition id="t"/>
<arc id="a" source="p" target="t"><toolspecific tool="alba" version="1"><kind>inhibitor</kind></toolspecific></arc>"#,
            Code::NetElement,
            7,
        ),
        (
            r#"<place id="p"/><transition id="t"/>
<arc id="a" source="p" target="t"><inscription><text>2</text></inscription></arc>"#,
            Code::NetElement,
            7,
        ),
        // An expression without its script.
        (
            r#"<place id="p"><toolspecific tool="alba" version="1"><kind>expression</kind></toolspecific></place>"#,
            Code::NetScript,
            6,
        ),
    ];
    for (k, (body, code, line)) in cases.iter().enumerate() {
        let dir = project(&format!("normal-bad-{k}"), TAGS, &normal(body), &[]);
        assert_eq!(
            errors(&dir),
            [(*code, "line.pnml".to_string(), *line)],
            "case {k}: {body}"
        );
    }
}

#[test]
fn a_ladder_program_reads_and_writes_marking_tags() {
    let lad = "XIC(Start)MOV(5,line.empty);\nGRT(line.filling,1)OTE(Lamp);\n";
    let dir = project("ladder", TAGS, &net(CYCLE), &[("main.lad", lad)]);
    let c = compile_dir(&dir);
    assert!(c.diagnostics.is_empty(), "{:?}", c.diagnostics);
}
