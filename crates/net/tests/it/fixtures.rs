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
    // Priority first (enter1 = 1, enter2 = 2), then document order.
    let order: Vec<&str> = net
        .firing_order()
        .iter()
        .map(|&i| net.transitions[i].id.as_str())
        .collect();
    assert_eq!(order, ["enter1", "enter2", "leave1", "leave2"]);
}
