//! Online edit keeps state (SPEC §11): recompiling a changed program maps
//! unchanged tags — timers and counters with their accumulators and status
//! bits, latched bits, values — to the new layout.

use crate::util::compile_text;
use alba_engine::Engine;
use alba_ir::{Memory, Place, Program, Target};
use alba_model::Value;
use std::sync::Arc;

fn place(p: &Program, name: &str) -> Place {
    match p.layout.resolve(name) {
        Ok(Target::Value { place, .. }) => place,
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn migrated_memory_keeps_every_unchanged_tag() {
    let tags_a =
        "name,type,address,initial\nRun,BOOL,DI:1/0,\nT,TIMER,,\nC,COUNTER,,\nLatch,BOOL,,\nN,DINT,,\nGone,REAL,,\n";
    let lad_a = "XIC(Run)TON(T,1000,0);\nXIC(Run)CTU(C,10,0)OTL(Latch);\nXIC(Run)ADD(N,1,N);\n";
    let a = Arc::new(compile_text(tags_a, lad_a).unwrap());
    let mut e = Engine::new(a.clone()).unwrap();
    e.write(place(&a, "Run"), Value::Bool(true));
    for k in 0..31 {
        e.scan(k * 10).unwrap();
    }
    // A new tag first (every slot moves), one tag gone, a rung changed.
    let tags_b =
        "name,type,address,initial\nNew,DINT,,5\nRun,BOOL,DI:1/0,\nT,TIMER,,\nC,COUNTER,,\nLatch,BOOL,,\nN,DINT,,\n";
    let lad_b = "XIC(Run)TON(T,1000,0);\nXIC(Run)CTU(C,10,0)OTL(Latch);\nXIC(Run)ADD(N,2,N)MOV(N,New);\n";
    let b = Arc::new(compile_text(tags_b, lad_b).unwrap());
    let migrated = Memory::migrate(e.memory(), &a.layout, &b.layout, &b.init);
    let read = |m: &Memory, p: &Program, n: &str| m.read(place(p, n));
    for name in ["Run", "T.ACC", "T.EN", "T.TT", "C.ACC", "C.CU", "Latch", "N"] {
        assert_eq!(read(&migrated, &b, name), read(e.memory(), &a, name), "{name}");
    }
    assert_eq!(read(&migrated, &b, "T.ACC"), Value::Dint(300));
    assert_eq!(read(&migrated, &b, "C.ACC"), Value::Dint(1));
    assert_eq!(read(&migrated, &b, "N"), Value::Dint(31));
    assert_eq!(
        read(&migrated, &b, "New"),
        Value::Dint(5),
        "new tags start from their initial value"
    );
}
