//! Power flow (SPEC §11): the engine publishes, per scan, the rung condition
//! after every element while monitoring, and does no such work otherwise.

use crate::util::{compile_text, observable};
use alba_engine::Engine;
use alba_ir::{Place, Program, Target};
use alba_model::Value;
use std::sync::Arc;

fn place(p: &Program, name: &str) -> Place {
    match p.layout.resolve(name) {
        Ok(Target::Value { place, .. }) => place,
        other => panic!("{name}: {other:?}"),
    }
}

/// The element whose source text is `text`.
fn elem(p: &Program, text: &str) -> u32 {
    let found = p
        .elements
        .iter()
        .position(|e| p.files.text(e.span.file).get(e.span.range()) == Some(text));
    found.unwrap_or_else(|| panic!("no element `{text}`")) as u32
}

const TAGS: &str = "name,type,address\nA,BOOL,DI:1/0\nB,BOOL,DI:1/1\nC,BOOL,DI:1/2\nQ,BOOL,DO:2/0\nT,TIMER,\nX,DINT,\n";
const LAD: &str = "[XIC(A),XIC(B)]XIO(C)OTE(Q);\nXIC(Q)TON(T,100,0)GRT(X,5)OTE(B2);\n";

#[test]
fn monitored_scan_publishes_every_element() {
    let tags = format!("{TAGS}B2,BOOL,\n");
    let p = Arc::new(compile_text(&tags, LAD).unwrap());
    let mut e = Engine::new(p.clone()).unwrap();
    e.set_monitor(true);
    e.write(place(&p, "A"), Value::Bool(true));
    e.scan(0).unwrap();
    let pf = e.power_flow().expect("monitoring");
    let on = |t: &str| pf.get(elem(&p, t));
    assert!(on("XIC(A)"), "A is true");
    assert!(!on("XIC(B)"), "B is false: its leg is not energised");
    assert!(on("[XIC(A),XIC(B)]"), "the branch is the OR of its legs");
    assert!(on("XIO(C)") && on("OTE(Q)"), "the rest of the rung conducts");
    assert!(on("XIC(Q)") && on("TON(T,100,0)"), "a timer passes the rung on");
    assert!(!on("GRT(X,5)") && !on("OTE(B2)"), "X = 0 is not > 5");
    // The next scan with A off shows the change.
    e.write(place(&p, "A"), Value::Bool(false));
    e.scan(10).unwrap();
    let pf = e.power_flow().unwrap();
    assert!(!pf.get(elem(&p, "XIC(A)")) && !pf.get(elem(&p, "OTE(Q)")));
    assert_eq!(e.monitored_scans(), 2);
}

#[test]
fn unmonitored_scans_record_nothing_and_agree_with_monitored_ones() {
    let tags = format!("{TAGS}B2,BOOL,\n");
    let p = Arc::new(compile_text(&tags, LAD).unwrap());
    let mut quiet = Engine::new(p.clone()).unwrap();
    let mut watched = Engine::new(p.clone()).unwrap();
    watched.set_monitor(true);
    for k in 0..50u64 {
        let a = Value::Bool(k % 7 < 3);
        for e in [&mut quiet, &mut watched] {
            e.write(place(&p, "A"), a);
            e.scan(k * 10).unwrap();
        }
        assert_eq!(observable(&quiet), observable(&watched), "scan {k}");
    }
    assert!(quiet.power_flow().is_none());
    assert_eq!(quiet.monitored_scans(), 0, "no monitored work without monitoring");
    assert_eq!(watched.monitored_scans(), 50);
    // Turning monitoring off stops the recording.
    watched.set_monitor(false);
    watched.scan(1000).unwrap();
    assert_eq!(watched.monitored_scans(), 50);
    assert!(watched.power_flow().is_none());
}
