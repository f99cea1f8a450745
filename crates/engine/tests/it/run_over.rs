//! `Engine::run_over`: a program's ops run once over another memory, with
//! none of a scan's bookkeeping (how `alba verify` evaluates its properties).

use crate::util::compile_text;
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

#[test]
fn run_over_sees_the_memory_as_given_and_flags_no_fault() {
    let tags = "name,type,address\nQ,BOOL,DO:2/0\nX,DINT,\nZero,DINT,\nY,DINT,\n";
    let p = Arc::new(compile_text(tags, "XIC(S:FS)OTE(Q);\nDIV(X,Zero,Y);\n").unwrap());
    let sys = p.layout.system;
    // A scan: its first-scan bit, and the division's fault flagged in S:MINOR.
    let mut e = Engine::new(p.clone()).unwrap();
    e.scan(0).unwrap();
    e.scan(10).unwrap();
    let mut m = e.memory().clone();
    assert!(m.b[sys.minor_fault.0 as usize], "the scan flags its fault");
    assert_eq!(e.read(place(&p, "Q")), Value::Bool(false));
    // Over a memory that says "first scan" and "no fault": the ops see the
    // first-scan bit as given, and the fault is not flagged.
    m.b[sys.first_scan.0 as usize] = true;
    m.b[sys.minor_fault.0 as usize] = false;
    let mut probe = Engine::new(p.clone()).unwrap();
    let out = probe.run_over(&m, 20).unwrap();
    assert_eq!(out.read(place(&p, "Q")), Value::Bool(true));
    assert!(!out.b[sys.minor_fault.0 as usize]);
    assert_eq!(probe.scans(), 0);
    // A memory larger than the program's is refused.
    let mut big = m.clone();
    big.b.push(false);
    assert!(probe.run_over(&big, 0).is_err());
}
