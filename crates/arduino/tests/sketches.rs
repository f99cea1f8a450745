//! Generated sketches of the examples, as golden files (review every change:
//! they are what users upload). `ALBA_BLESS=1` rewrites them.

use alba_arduino::{Target, generate};
use alba_model::board::{Model, PinMap};
use std::path::Path;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn target(scan_ms: u32) -> Target {
    Target {
        model: Model::Uno,
        map: PinMap::preset("aurora").expect("preset"),
        active_low: false,
        scan_ms,
        monitor: true,
        power_up_on: Vec::new(),
    }
}

#[test]
fn examples_golden_sketches() {
    for ex in [
        "start-stop",
        "traffic-light",
        "star-delta",
        "tank",
        "tank-plant",
        "festo-station",
    ] {
        let c = alba_load::compile_dir(&root().join("examples").join(ex));
        let prog = c.program.unwrap_or_else(|| panic!("{ex} does not compile"));
        let cfg = c.project.config.as_ref().expect("config");
        let s = generate(&prog, &cfg.name, &target(cfg.scan_ms)).unwrap_or_else(|d| panic!("{ex}: {d:?}"));
        let golden = root()
            .join("crates/arduino/tests/golden")
            .join(format!("{}.ino", s.name));
        let ino = &s.files[0].1;
        if std::env::var_os("ALBA_BLESS").is_some() {
            std::fs::create_dir_all(golden.parent().expect("dir")).expect("mkdir");
            std::fs::write(&golden, ino).expect("write golden");
        } else {
            let want = std::fs::read_to_string(&golden).unwrap_or_default();
            assert!(
                want == *ino,
                "{ex}: the sketch differs from {} (ALBA_BLESS=1 to accept)",
                golden.display()
            );
        }
    }
}

#[test]
fn power_up_state_and_active_low() {
    let c = alba_load::compile_dir(&root().join("examples/start-stop"));
    let prog = c.program.expect("compiles");
    let mut t = target(10);
    t.power_up_on = vec![alba_model::board::Pin::D(13)];
    t.active_low = true;
    let ino = &generate(&prog, "start-stop", &t).expect("sketch").files[0].1;
    // Lamp (D13) is on at power-up and after a major fault: LOW on an active-low board.
    assert!(
        ino.contains("    digitalWrite(13, LOW);\n    pinMode(13, OUTPUT);"),
        "{ino}"
    );
    assert!(
        ino.contains("    digitalWrite(12, HIGH);\n    pinMode(12, OUTPUT);"),
        "{ino}"
    );
    let safe = &ino[ino.find("static void outputs_safe()").expect("outputs_safe")..];
    assert!(safe.contains("digitalWrite(13, LOW);") && safe.contains("digitalWrite(12, HIGH);"));
    assert!(ino.contains("digitalWrite(13, B[15] ? LOW : HIGH);"), "{ino}");
}
