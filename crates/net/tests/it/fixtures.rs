//! Fixtures: Alba's own form and PNML as other tools write it.

use alba_diag::FileId;
use alba_net::*;
use std::path::Path;

fn read(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Loads without errors (warnings allowed) and checks load → save → load.
pub fn load_ok(name: &str) -> (Net, Vec<alba_diag::Diagnostic>) {
    let text = read(name);
    let (net, diags) = load(FileId(0), &text);
    let net = net.unwrap_or_else(|| panic!("{name}: {diags:#?}"));
    assert!(diags.iter().all(is_warning), "{name}: {diags:#?}");
    let saved = save(&net);
    let (again, d2) = load(FileId(0), &saved);
    let mut again = again.unwrap_or_else(|| panic!("{name} saved:\n{saved}\n{d2:#?}"));
    assert!(d2.iter().all(is_warning), "{d2:#?}");
    let mut a = net.clone();
    a.clear_spans();
    again.clear_spans();
    assert_eq!(a, again, "{name}: load → save → load changed the net; saved:\n{saved}");
    // Saving twice gives the same text.
    assert_eq!(save(&again), saved);
    (net, diags)
}

#[test]
fn alba_fixture_loads_with_everything() {
    let (net, diags) = load_ok("alba_mutex.pnml");
    assert!(diags.is_empty(), "{diags:#?}");
    assert_eq!(net.id, "mutex");
    assert_eq!(net.name.as_deref(), Some("Mutex"));
    assert_eq!(net.mode, Mode::Petri);
    assert_eq!(net.page_id, "top");
    assert_eq!(net.places.len(), 5);
    assert_eq!(net.transitions.len(), 4);
    assert_eq!(net.arcs.len(), 13);
    let idle1 = net.place("idle1").unwrap();
    assert_eq!(idle1.initial, 1);
    assert_eq!(idle1.name.as_deref(), Some("Idle 1"));
    assert_eq!(
        idle1.extra.graphics.as_ref().unwrap().position,
        Some(Point { x: 50.0, y: 50.0 })
    );
    assert!(idle1.extra.label_graphics["name"].contains("offset"));
    assert_eq!(net.place("busy1").unwrap().tag.as_deref(), Some("Busy1"));
    let res = net.place("res").unwrap();
    assert_eq!(res.extra.toolspecific.len(), 1);
    assert!(res.extra.toolspecific[0].contains("tool=\"other\""));
    let enter1 = net.transition("enter1").unwrap();
    assert_eq!(enter1.guard.as_ref().unwrap().text, "Start AND NOT Stop");
    assert_eq!(enter1.priority, Some(1));
    // The guard's span covers its text in the file.
    let text = read("alba_mutex.pnml");
    let g = enter1.guard.as_ref().unwrap();
    assert_eq!(&text[g.span.range()], "Start AND NOT Stop");
    let a13 = net.arcs.iter().find(|a| a.id == "a13").unwrap();
    assert_eq!(a13.kind, ArcKind::Inhibitor);
    let a6 = net.arcs.iter().find(|a| a.id == "a6").unwrap();
    assert_eq!(
        a6.extra
            .graphics
            .as_ref()
            .unwrap()
            .raw
            .as_deref()
            .unwrap()
            .matches("<position")
            .count(),
        2
    );
    assert_eq!(net.widgets.len(), 2);
    assert_eq!(net.widgets[0].kind, ElementKind::Button);
    assert_eq!(net.widgets[0].tag.as_deref(), Some("Start"));
    // a widget's other attributes are its properties (OPCSM's), kept by name
    let style: Vec<(&str, &str)> = net.widgets[1]
        .style
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    assert_eq!(
        style,
        [
            ("align", "center"),
            ("background", "navy"),
            ("color", "#fff"),
            ("font_size", "14")
        ]
    );
    assert!(net.widgets[0].style.is_empty());
    // Priority first (enter1 = 1, enter2 = 2), then document order.
    let order: Vec<&str> = net
        .firing_order()
        .iter()
        .map(|&i| net.transitions[i].id.as_str())
        .collect();
    assert_eq!(order, ["enter1", "enter2", "leave1", "leave2"]);
}

#[test]
fn pipe_legacy_form_loads_with_warnings() {
    let (net, diags) = load_ok("pipe_producer_consumer.pnml");
    assert_eq!(net.id, "Net-One");
    assert_eq!(net.net_type, "P/T net");
    assert_eq!(net.places.len(), 4);
    assert_eq!(net.transitions.len(), 3);
    assert_eq!(net.arcs.len(), 7);
    let marks: Vec<u32> = net.places.iter().map(|p| p.initial).collect();
    assert_eq!(marks, [1, 0, 0, 2]);
    assert_eq!(net.place("P2").unwrap().name.as_deref(), Some("Buffer"));
    let w = net.arcs.iter().find(|a| a.id == "T1 to P2").unwrap();
    assert_eq!(w.weight, 2);
    let inh = net.arcs.iter().find(|a| a.id == "P3 to T2").unwrap();
    assert_eq!(inh.kind, ArcKind::Inhibitor);
    assert_eq!(
        net.transition("T0").unwrap().extra.graphics.as_ref().unwrap().position,
        Some(Point { x: 60.0, y: 180.0 })
    );
    // One warning per ignored element name and parent, located.
    let msgs: Vec<&str> = diags.iter().map(|d| d.message.as_str()).collect();
    for m in [
        "<token> in <net>",
        "<capacity> in <place>",
        "<rate> in <transition>",
        "<arcpath> in <arc>",
    ] {
        assert_eq!(msgs.iter().filter(|x| x.starts_with(m)).count(), 1, "{m}: {msgs:#?}");
    }
    assert!(diags.iter().all(|d| d.code == alba_diag::Code::PnmlIgnored));
}

#[test]
fn tina_export_loads_and_keeps_its_toolspecific() {
    let (net, diags) = load_ok("tina_philosophers.pnml");
    assert!(diags.is_empty(), "{diags:#?}");
    assert_eq!(net.places.len(), 8);
    assert_eq!(net.transitions.len(), 6);
    assert_eq!(net.arcs.len(), 20);
    assert_eq!(net.page_id, "philo2-page");
    let t = net.transition("take1a").unwrap();
    assert_eq!(t.extra.toolspecific.len(), 1);
    assert!(t.extra.toolspecific[0].starts_with("<toolspecific tool=\"Tina\""));
    assert!(t.extra.toolspecific[0].ends_with("</toolspecific>"));
    // Written back verbatim.
    assert!(save(&net).contains(&t.extra.toolspecific[0]));
}

#[test]
fn nested_pages_are_flattened_and_references_resolved() {
    let (net, diags) = load_ok("pages_references.pnml");
    assert!(diags.is_empty(), "{diags:#?}");
    assert_eq!(net.name.as_deref(), Some("Cell"));
    assert_eq!(net.page_id, "main");
    assert_eq!(net.page_name.as_deref(), Some("Main"));
    let ids: Vec<&str> = net.places.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(ids, ["parts", "loaded"]);
    let arcs: Vec<(&str, &str, u32)> = net
        .arcs
        .iter()
        .map(|a| (a.source.as_str(), a.target.as_str(), a.weight))
        .collect();
    assert_eq!(
        arcs,
        [
            ("parts", "load", 2),
            ("load", "loaded", 1),
            ("loaded", "unload", 1),
            ("unload", "parts", 2)
        ]
    );
    assert!(net.arcs[0].extra.label_graphics["inscription"].contains("offset"));
}

#[test]
fn prefixed_blocks_stay_well_formed_when_saved() {
    let (net, _) = load_ok("pages_references.pnml");
    assert_eq!(
        net.namespaces,
        [(
            "xmlns:pn".to_string(),
            "http://www.pnml.org/version-2009/grammar/pnml".to_string()
        )]
    );
    let saved = save(&net);
    assert!(
        saved.contains("xmlns:pn=\"http://www.pnml.org/version-2009/grammar/pnml\""),
        "{saved}"
    );
}

#[test]
fn nested_page_data_is_dropped_with_one_warning() {
    let text = r#"<pnml><net id="n" type="ptnet"><page id="a"><toolspecific tool="x" version="1"/>
<page id="b"><name><text>B</text></name><toolspecific tool="y" version="1"/><toolspecific tool="z" version="1"/>
<place id="p"/></page></page></net></pnml>"#;
    let (net, diags) = load(FileId(0), text);
    let net = net.unwrap();
    assert_eq!(net.page_extra.toolspecific, [r#"<toolspecific tool="x" version="1"/>"#]);
    let msgs: Vec<&str> = diags.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(
        msgs,
        [
            "the <name> of a nested page is dropped: pages are flattened into the first",
            "the <toolspecific> of a nested page is dropped: pages are flattened into the first"
        ]
    );
    assert!(diags.iter().all(is_warning));
}

/// Golden files: what `save` writes for each fixture, under `tests/saved/`
/// (`ALBA_UPDATE_GOLDEN=1` rewrites them). A change to the writer shows up
/// here as a diff to review.
#[test]
fn saved_form_of_each_fixture_is_the_golden_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let update = std::env::var_os("ALBA_UPDATE_GOLDEN").is_some();
    let mut n = 0;
    for p in alba_testkit::cases(&root.join("fixtures")) {
        if p.extension().is_none_or(|e| e != "pnml") {
            continue;
        }
        n += 1;
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let (net, _) = load_ok(&name);
        let saved = save(&net);
        let golden = root.join("saved").join(&name);
        if update {
            std::fs::write(&golden, &saved).unwrap();
        }
        let want = std::fs::read_to_string(&golden)
            .unwrap_or_else(|e| panic!("{}: {e} (ALBA_UPDATE_GOLDEN=1 writes it)", golden.display()));
        assert_eq!(
            saved, want,
            "{name}: the saved form changed (ALBA_UPDATE_GOLDEN=1 to accept)"
        );
    }
    assert!(n >= 4);
}
