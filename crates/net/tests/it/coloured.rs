//! Coloured nets (symmetric nets, `alba_net::colored`): hand-computed unfoldings, the
//! budgets, and the editor's loader refusing them. The contest's models are checked in
//! `tests/mcc` (`coloured_models_unfold_to_their_pt_twins_answers`).

use alba_diag::{Code, FileId};
use alba_net::analysis::{Control, Options, analyze};
use alba_net::colored::{Budget, Unfolding, unfold};
use alba_net::{Net, PtNet, load, load_for_analysis};

const SYMMETRIC: &str = "http://www.pnml.org/version-2009/grammar/symmetricnet";

fn one(c: &str) -> String {
    format!(
        "<numberof><subterm><numberconstant value=\"1\"><positive/></numberconstant></subterm><subterm>{c}</subterm></numberof>"
    )
}

/// A token going round a cycle of three colours, stopped before the last by the guard
/// `x < 2`.
fn ring() -> String {
    let x = "<variable refvariable=\"x\"/>";
    format!(
        r#"<?xml version="1.0"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
<net id="ring" type="{SYMMETRIC}"><page id="g">
<place id="P"><type><structure><usersort declaration="Z"/></structure></type>
<hlinitialMarking><structure>{}</structure></hlinitialMarking></place>
<transition id="t"><condition><structure><lessthan><subterm>{x}</subterm><subterm><useroperator declaration="z2"/></subterm></lessthan></structure></condition></transition>
<arc id="a1" source="P" target="t"><hlinscription><structure>{x}</structure></hlinscription></arc>
<arc id="a2" source="t" target="P"><hlinscription><structure>{}</structure></hlinscription></arc>
</page>
<declaration><structure><declarations>
<namedsort id="Z" name="Z"><cyclicenumeration><feconstant id="z0" name="0"/><feconstant id="z1" name="1"/><feconstant id="z2" name="2"/></cyclicenumeration></namedsort>
<variabledecl id="x" name="x"><usersort declaration="Z"/></variabledecl>
</declarations></structure></declaration></net></pnml>"#,
        one("<useroperator declaration=\"z0\"/>"),
        one(&format!("<successor><subterm>{x}</subterm></successor>")),
    )
}

fn arcs(net: &Net) -> Vec<(String, String, u32)> {
    let mut v: Vec<_> = net
        .arcs
        .iter()
        .map(|a| (a.source.clone(), a.target.clone(), a.weight))
        .collect();
    v.sort();
    v
}

fn ids<T>(v: &[T], id: impl Fn(&T) -> &str) -> Vec<String> {
    v.iter().map(|x| id(x).to_string()).collect()
}

#[test]
fn a_ring_unfolds_to_a_place_per_colour_and_a_transition_per_binding() {
    let (net, u) = unfold(FileId(0), &ring(), &Budget::default()).expect("unfolds");
    assert_eq!(ids(&net.places, |p| &p.id), ["P_0", "P_1", "P_2"]);
    assert_eq!(net.places.iter().map(|p| p.initial).collect::<Vec<_>>(), [1, 0, 0]);
    // The guard x < 2 leaves t_2 out.
    assert_eq!(ids(&net.transitions, |t| &t.id), ["t_0", "t_1"]);
    assert_eq!(
        arcs(&net),
        [
            ("P_0".into(), "t_0".into(), 1),
            ("P_1".into(), "t_1".into(), 1),
            ("t_0".into(), "P_1".into(), 1),
            ("t_1".into(), "P_2".into(), 1),
        ]
    );
    assert_eq!(
        u,
        Unfolding {
            coloured_places: 1,
            coloured_transitions: 1,
            bindings: 3,
            places: vec![("P".into(), 0..3)],
            transitions: vec![("t".into(), 0..2)],
        }
    );
    let a = analyze(&PtNet::from_net(&net), &Options::default(), &Control::none());
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(3), Some(2), Some(1)));
}

/// Products, tuples, `all`, `subtract`, `add`, a dot place without inscriptions,
/// `predecessor` on an integer range (cyclic), `and`/`or`/`not`/`inequality`/
/// `equality`/`greaterthanorequal`, `finiteintrangeconstant`, `booleanconstant`.
#[test]
fn products_ranges_and_guards_unfold_as_computed_by_hand() {
    let (x, y) = ("<variable refvariable=\"x\"/>", "<variable refvariable=\"y\"/>");
    let tuple = |a: &str, b: &str| format!("<tuple><subterm>{a}</subterm><subterm>{b}</subterm></tuple>");
    let one_n = "<finiteintrangeconstant value=\"1\"><finiteintrange start=\"1\" end=\"3\"/></finiteintrangeconstant>";
    let two = |c: &str| {
        format!(
            "<numberof><subterm><numberconstant value=\"2\"><positive/></numberconstant></subterm><subterm>{c}</subterm></numberof>"
        )
    };
    let text = format!(
        r#"<pnml><net id="grid" type="{SYMMETRIC}"><page id="g">
<place id="Q"><type><structure><usersort declaration="NN"/></structure></type>
<hlinitialMarking><structure><subtract><subterm><all><usersort declaration="NN"/></all></subterm><subterm>{}</subterm></subtract></structure></hlinitialMarking></place>
<place id="D"><type><structure><dot/></structure></type><hlinitialMarking><structure><dotconstant/></structure></hlinitialMarking></place>
<transition id="u"><condition><structure><and>
<subterm><inequality><subterm>{x}</subterm><subterm>{y}</subterm></inequality></subterm>
<subterm><not><subterm><equality><subterm>{x}</subterm><subterm><predecessor><subterm>{y}</subterm></predecessor></subterm></equality></subterm></not></subterm>
<subterm><or><subterm><greaterthanorequal><subterm>{x}</subterm><subterm>{one_n}</subterm></greaterthanorequal></subterm><subterm><booleanconstant value="false"/></subterm></or></subterm>
</and></structure></condition></transition>
<arc id="a1" source="Q" target="u"><hlinscription><structure>{}</structure></hlinscription></arc>
<arc id="a2" source="D" target="u"/>
<arc id="a3" source="u" target="Q"><hlinscription><structure><add><subterm>{}</subterm><subterm>{}</subterm></add></structure></hlinscription></arc>
</page>
<declaration><structure><declarations>
<namedsort id="NN" name="NN"><productsort><usersort declaration="N"/><usersort declaration="N"/></productsort></namedsort>
<namedsort id="N" name="N"><finiteintrange start="1" end="3"/></namedsort>
<variabledecl id="x" name="x"><usersort declaration="N"/></variabledecl>
<variabledecl id="y" name="y"><usersort declaration="N"/></variabledecl>
</declarations></structure></declaration></net></pnml>"#,
        one(&tuple(one_n, one_n)),
        one(&tuple(x, y)),
        two(&tuple(y, x)),
        one(&tuple(x, x)),
    );
    let (net, u) = unfold(FileId(0), &text, &Budget::default()).expect("unfolds");
    assert_eq!(
        ids(&net.places, |p| &p.id),
        [
            "Q_1_1", "Q_1_2", "Q_1_3", "Q_2_1", "Q_2_2", "Q_2_3", "Q_3_1", "Q_3_2", "Q_3_3", "D"
        ]
    );
    // all − (1,1).
    assert_eq!(
        net.places.iter().map(|p| p.initial).collect::<Vec<_>>(),
        [0, 1, 1, 1, 1, 1, 1, 1, 1, 1]
    );
    // x ≠ y and x ≠ y − 1 (cyclic: the predecessor of 1 is 3): (1,3), (2,1), (3,2).
    assert_eq!(ids(&net.transitions, |t| &t.id), ["u_1_3", "u_2_1", "u_3_2"]);
    assert_eq!(u.bindings, 9);
    let of = |t: &str| -> Vec<(String, String, u32)> {
        arcs(&net).into_iter().filter(|(s, d, _)| s == t || d == t).collect()
    };
    assert_eq!(
        of("u_2_1"),
        [
            ("D".into(), "u_2_1".into(), 1),
            ("Q_2_1".into(), "u_2_1".into(), 1),
            ("u_2_1".into(), "Q_1_2".into(), 2),
            ("u_2_1".into(), "Q_2_2".into(), 1),
        ]
    );
    // One dot token: one of the three fires, then nothing.
    let a = analyze(&PtNet::from_net(&net), &Options::default(), &Control::none());
    assert_eq!((a.states, a.edges, a.deadlocks), (Some(4), Some(3), Some(3)));
}

#[test]
fn an_unfolding_over_the_budget_is_refused_with_the_budget_named() {
    let small = Budget {
        elements: 4,
        bindings: 1_000,
    };
    let e = unfold(FileId(0), &ring(), &small).expect_err("over budget");
    assert_eq!(e.code, Code::PnmlLimit);
    assert!(
        e.message.contains("more than 4 places, transitions and arcs"),
        "{}",
        e.message
    );
    assert!(e.primary.is_some() && e.help.is_some());
    let few = Budget {
        elements: 1_000,
        bindings: 2,
    };
    let e = unfold(FileId(0), &ring(), &few).expect_err("over budget");
    assert_eq!(e.code, Code::PnmlLimit);
    assert!(
        e.message
            .contains("unfolding `t` needs 3 bindings of its variables; Alba tries at most 2 in a net"),
        "{}",
        e.message
    );
}

#[test]
fn the_editor_refuses_a_coloured_net_and_the_analysis_unfolds_it() {
    let (net, diags) = load(FileId(0), &ring());
    assert!(net.is_none());
    assert_eq!(diags.len(), 1, "{diags:?}");
    assert_eq!(diags[0].code, Code::PnmlStructure);
    assert!(diags[0].message.contains("a coloured net (symmetric net)"));
    assert!(diags[0].help.as_deref().is_some_and(|h| h.contains("alba analyze")));
    let (net, diags, u) = load_for_analysis(FileId(0), &ring());
    assert!(diags.is_empty());
    assert_eq!(net.expect("unfolded").places.len(), 3);
    assert_eq!(u.expect("an unfolding").coloured_places, 1);
    // A place/transition net is loaded as before, without an unfolding.
    let pt = r#"<pnml><net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet"><page id="g"><place id="p"/></page></net></pnml>"#;
    let (net, diags, u) = load_for_analysis(FileId(0), pt);
    assert!(net.is_some() && diags.is_empty() && u.is_none());
}

/// A coloured model's formulas name its coloured nodes: the tokens of `P` are those of
/// `P_0`, `P_1` and `P_2` together, `t` is fireable when `t_0` or `t_1` is, the bound of
/// `P` is that of the sum; an unfolded name still reads, an unknown one is located.
#[test]
fn formulas_name_coloured_places_and_transitions() {
    use alba_net::analysis::formula::{IntExpr, Pred, Query, parse, parse_for};
    use alba_net::analysis::stubborn::{CheckOptions, answer};
    let (net, u) = unfold(FileId(0), &ring(), &Budget::default()).expect("unfolds");
    let pt = PtNet::from_net(&net);
    let text = r#"<?xml version="1.0"?>
<property-set xmlns="http://mcc.lip6.fr/">
  <property><id>R-00</id><formula><place-bound><place>P</place></place-bound></formula></property>
  <property><id>R-01</id><formula><all-paths><globally><conjunction>
    <integer-le><tokens-count><place>P</place></tokens-count><integer-constant>1</integer-constant></integer-le>
    <integer-le><integer-constant>1</integer-constant><tokens-count><place>P</place></tokens-count></integer-le>
  </conjunction></globally></all-paths></formula></property>
  <property><id>R-02</id><formula><exists-path><finally><negation><is-fireable><transition>t</transition></is-fireable></negation></finally></exists-path></formula></property>
  <property><id>R-03</id><formula><exists-path><finally><integer-le><integer-constant>1</integer-constant><tokens-count><place>P_2</place></tokens-count></integer-le></finally></exists-path></formula></property>
</property-set>"#;
    let props = parse_for(text, &pt, Some(&u)).expect("reads");
    assert_eq!(props[0].query, Query::Bound(vec![0, 1, 2]));
    let Query::Ef(Pred::Not(f)) = &props[2].query else {
        panic!("{:?}", props[2].query)
    };
    assert_eq!(**f, Pred::Fireable(vec![0, 1]));
    let Query::Ef(Pred::Le(_, IntExpr::Tokens(p2))) = &props[3].query else {
        panic!("{:?}", props[3].query)
    };
    assert_eq!(p2, &vec![2]);
    let answers: Vec<String> = answer(&pt, &props, &CheckOptions::default(), &Control::none())
        .iter()
        .map(|a| a.to_string().split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .collect();
    assert_eq!(
        answers,
        [
            "FORMULA R-00 1",
            "FORMULA R-01 TRUE",
            "FORMULA R-02 TRUE",
            "FORMULA R-03 TRUE"
        ]
    );
    // Without the unfolding, `P` is unknown: the error says where.
    let e = parse(text, &pt).expect_err("P is not a place of the unfolded net");
    assert_eq!((e.line, e.column), (3, 48), "{e}");
    assert!(e.message.contains("no place `P`"), "{e}");
    let e = parse_for(&text.replace("<transition>t<", "<transition>u<"), &pt, Some(&u)).expect_err("unknown");
    assert_eq!((e.line, e.column), (8, 80), "{e}");
    assert!(e.message.contains("no transition `u`"), "{e}");
}
