//! Property: a net saved and loaded again is the same net (spans aside,
//! and `Graphics::raw`, which a load fills in), and load → save → load is
//! the identity.

use alba_diag::FileId;
use alba_net::*;
use proptest::prelude::*;
use std::collections::BTreeMap;

/// Text as found in names, scripts and property values: any character but
/// control characters, plus line ends and tabs, and XML's specials.
fn text() -> impl Strategy<Value = String> {
    prop_oneof![
        "([^\\p{Cc}]|\n|\t|\r){0,12}",
        Just("a < b && c > \"d\" 'e'".to_string()),
        Just(String::new()),
    ]
}

fn point() -> impl Strategy<Value = Option<Point>> {
    proptest::option::of((-1.0e6..1.0e6f64, -1.0e6..1.0e6f64).prop_map(|(x, y)| Point { x, y }))
}

fn graphics() -> impl Strategy<Value = Option<Graphics>> {
    point().prop_map(|p| p.map(|p| Graphics::at(p.x, p.y)))
}

fn foreign() -> impl Strategy<Value = Vec<String>> {
    proptest::collection::vec(
        "[a-z]{1,5}"
            .prop_map(|t| format!("<toolspecific tool=\"{t}\" version=\"2\"><x a=\"1\">y &amp; z</x></toolspecific>")),
        0..2,
    )
}

fn props() -> impl Strategy<Value = BTreeMap<String, String>> {
    proptest::collection::btree_map("[a-z]{1,6}", text(), 0..3)
}

fn extra() -> impl Strategy<Value = Extra> {
    (graphics(), foreign()).prop_map(|(graphics, toolspecific)| Extra {
        graphics,
        toolspecific,
        label_graphics: BTreeMap::new(),
    })
}

fn id() -> impl Strategy<Value = String> {
    "[A-Za-z_][A-Za-z0-9_ .:&<-]{0,6}"
}

const PLACE_KINDS: [ElementKind; 8] = [
    ElementKind::State,
    ElementKind::Counter,
    ElementKind::Expression,
    ElementKind::Variable,
    ElementKind::Input,
    ElementKind::Output,
    ElementKind::Stop,
    ElementKind::End,
];
const TRANSITION_KINDS: [ElementKind; 3] = [ElementKind::Transition, ElementKind::Condition, ElementKind::Timer];
const WIDGET_KINDS: [ElementKind; 4] = [
    ElementKind::Button,
    ElementKind::Display,
    ElementKind::Plot,
    ElementKind::Label,
];

fn net() -> impl Strategy<Value = Net> {
    let places = proptest::collection::vec(
        (
            id(),
            proptest::option::of(text()),
            0..=MAX_MARKING,
            proptest::option::of("[A-Za-z_][A-Za-z0-9_.]{0,8}"),
            proptest::sample::select(PLACE_KINDS.to_vec()),
            props(),
            proptest::option::of(text()),
            extra(),
        ),
        0..6,
    );
    let transitions = proptest::collection::vec(
        (
            id(),
            proptest::option::of(text()),
            proptest::option::of("[A-Za-z(][^\\p{Cc}]{0,12}"),
            proptest::option::of(any::<i32>()),
            proptest::sample::select(TRANSITION_KINDS.to_vec()),
            props(),
            extra(),
        ),
        0..6,
    );
    let arcs = proptest::collection::vec(
        (
            any::<bool>(),
            any::<usize>(),
            any::<usize>(),
            1..=MAX_WEIGHT,
            0..3u8,
            extra(),
        ),
        0..12,
    );
    let widgets = proptest::collection::vec(
        (
            proptest::sample::select(WIDGET_KINDS.to_vec()),
            proptest::option::of(text()),
            proptest::option::of("[^\\p{Cc}]{1,8}"),
            point(),
        ),
        0..3,
    );
    (
        id(),
        proptest::option::of(text()),
        any::<bool>(),
        places,
        transitions,
        arcs,
        widgets,
        id(),
        extra(),
        (proptest::option::of(text()), extra()),
    )
        .prop_map(
            |(nid, name, normal, places, transitions, arcs, widgets, page, extra, (page_name, page_extra))| {
                let mut net = Net::new(format!("n{nid}"));
                net.name = name;
                net.mode = if normal { Mode::Normal } else { Mode::Petri };
                net.page_id = format!("g{page}");
                net.extra = extra;
                net.page_name = page_name;
                net.page_extra = page_extra;
                for (i, (id, name, initial, tag, kind, props, script, extra)) in places.into_iter().enumerate() {
                    let mut p = Place::new(format!("p{i}{id}"), initial);
                    p.name = name;
                    p.tag = tag;
                    p.kind = kind;
                    p.props = props;
                    p.script = script;
                    p.extra = extra;
                    net.places.push(p);
                }
                for (i, (id, name, guard, priority, kind, props, extra)) in transitions.into_iter().enumerate() {
                    let mut t = Transition::new(format!("t{i}{id}"));
                    t.name = name;
                    t.guard = guard.map(|text| Guard { text, span: no_span() });
                    t.priority = priority;
                    t.kind = kind;
                    t.props = props;
                    t.extra = extra;
                    net.transitions.push(t);
                }
                let (np, nt) = (net.places.len(), net.transitions.len());
                if np > 0 && nt > 0 {
                    let mut seen = std::collections::HashSet::new();
                    for (i, (to_t, pi, ti, weight, kind, extra)) in arcs.into_iter().enumerate() {
                        let (p, t) = (net.places[pi % np].id.clone(), net.transitions[ti % nt].id.clone());
                        let kind = match (to_t, kind) {
                            (true, 1) => ArcKind::Inhibitor,
                            (true, 2) => ArcKind::Read,
                            _ => ArcKind::Normal,
                        };
                        let (s, d) = if to_t { (p, t) } else { (t, p) };
                        if !seen.insert((s.clone(), d.clone())) {
                            continue;
                        }
                        let mut a = Arc::new(format!("a{i}"), s, d, weight);
                        a.kind = kind;
                        a.extra = extra;
                        net.arcs.push(a);
                    }
                }
                for (i, (kind, tag, text, position)) in widgets.into_iter().enumerate() {
                    net.widgets.push(Widget {
                        id: format!("w{i}"),
                        kind,
                        tag,
                        text,
                        position,
                        style: Default::default(),
                    });
                }
                net
            },
        )
}

fn forget_raw(net: &mut Net) {
    let all = std::iter::once(&mut net.extra)
        .chain(std::iter::once(&mut net.page_extra))
        .chain(net.places.iter_mut().map(|p| &mut p.extra))
        .chain(net.transitions.iter_mut().map(|t| &mut t.extra))
        .chain(net.arcs.iter_mut().map(|a| &mut a.extra));
    for e in all {
        if let Some(g) = &mut e.graphics {
            g.raw = None;
        }
    }
}

fn reload(text: &str) -> Net {
    let (net, diags) = load(FileId(0), text);
    assert!(diags.is_empty(), "{text}\n{diags:#?}");
    let mut net = net.expect("a net");
    net.clear_spans();
    net
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn save_then_load_gives_the_net_back(net in net()) {
        let saved = save(&net);
        let mut once = reload(&saved);
        let again = reload(&save(&once));
        prop_assert_eq!(&once, &again, "load → save → load is not the identity:\n{}", saved);
        forget_raw(&mut once);
        prop_assert_eq!(&once, &net, "saved:\n{}", saved);
    }

    #[test]
    fn arbitrary_bytes_never_panic(text in "(<|>|/|=|\"|pnml|net|page|place|arc|transition|id|text|&|[a-z]| ){0,200}") {
        let (net, diags) = load(FileId(0), &text);
        prop_assert!(net.is_some() || diags.iter().any(|d| !is_warning(d)));
        for d in &diags {
            let p = d.primary.as_ref().expect("located");
            prop_assert!(p.span.range().end <= text.len());
        }
    }
}
