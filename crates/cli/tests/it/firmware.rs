//! `alba firmware`: the remote-I/O sketch of controller mode, from options
//! or from a project's `[board]`, and its refusals. (The sketches' builds
//! and behaviour are checked by tools/simavr/controller.sh.)

use crate::{alba, scratch};

fn text(o: &std::process::Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn firmware_from_options_and_from_a_project() {
    let d = scratch("firmware");
    let o = alba(
        &d,
        &["firmware", "--board", "uno", "--pinmap", "openplc", "-o", "uno_io"],
    );
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(out.starts_with("wrote uno_io/uno_io.ino (Modbus RTU slave 1, 115200 8N1; Arduino Uno, pin map openplc: 5 DI, 4 DO, 6 AI, 3 AO; watchdog 500 ms)"), "{out}");
    let sketch = std::fs::read_to_string(d.join("uno_io/uno_io.ino")).expect("sketch");
    assert!(sketch.contains("static const uint8_t DO_PIN[N_DO + 1] = {7, 8, 12, 13};"));
    assert!(sketch.contains("#define ALBA_SLAVE 1"));
    assert!(sketch.contains("#define ALBA_PULLUP 0"));
    let o = alba(
        &d,
        &[
            "firmware",
            "--board",
            "nano",
            "--input-pullup",
            "--slave",
            "9",
            "-o",
            "nano_io",
        ],
    );
    assert!(o.status.success(), "{}", text(&o).1);
    let sketch = std::fs::read_to_string(d.join("nano_io/nano_io.ino")).expect("sketch");
    assert!(sketch.contains("#define ALBA_PULLUP 1") && sketch.contains("#define ALBA_SLAVE 9"));
    assert!(sketch.contains("DI channels (digitalRead, pull-up: on = LOW)"));

    std::fs::create_dir_all(d.join("plant")).expect("mkdir");
    std::fs::write(
        d.join("plant/alba.toml"),
        "name = \"plant\"\nprograms = [\"main.lad\"]\n[board]\nmodel = \"mega\"\npinmap = \"s7\"\nactive_low = true\ndo = [\"D22\", \"D23\"]\n",
    )
    .expect("toml");
    std::fs::write(
        d.join("plant/tags.csv"),
        "name,type,address,initial,retain,description\nA,BOOL,DI:1/0,,,\nB,BOOL,DO:2/1,,,\n",
    )
    .expect("tags");
    std::fs::write(d.join("plant/main.lad"), "XIC(A)OTE(B);\n").expect("lad");
    let o = alba(
        &d,
        &[
            "firmware",
            "plant",
            "--link",
            "aurora",
            "--watchdog-ms",
            "250",
            "-o",
            "out/mega_io",
        ],
    );
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        out.contains("AuroraLD text link")
            && out.contains("Arduino Mega 2560, pin map s7: 6 DI, 2 DO, 6 AI, 0 AO; watchdog 250 ms"),
        "{out}"
    );
    let sketch = std::fs::read_to_string(d.join("out/mega_io/mega_io.ino")).expect("sketch");
    assert!(sketch.contains("static const uint8_t DO_PIN[N_DO + 1] = {22, 23};"));
    assert!(sketch.contains("#define ALBA_ACTIVE_LOW 1"));
    assert!(sketch.contains("#define ALBA_WATCHDOG_MS 250UL"));
}

#[test]
fn firmware_refusals() {
    let d = scratch("firmware-refusals");
    let cases: &[(&[&str], &str)] = &[
        (
            &["firmware", "--board", "uno", "-o", "x"],
            "error[E404]: AI:3/2 is pin A6, but the Arduino Uno has no pin A6 (A0-A5); A6 and A7 are on the Nano",
        ),
        (
            &["firmware", "--board", "due", "-o", "x"],
            "unknown board `due` (uno, nano or mega)",
        ),
        (
            &["firmware", "--board", "nano", "--pinmap", "plc5", "-o", "x"],
            "unknown pin map `plc5`",
        ),
        (
            &["firmware", "--board", "nano", "--link", "can", "-o", "x"],
            "unknown link `can` (modbus or aurora)",
        ),
        (
            &["firmware", "--board", "nano", "--slave", "0", "-o", "x"],
            "slave id 0 is not 1-247",
        ),
        (&["firmware", "-o", "x"], "which board?"),
        (&["firmware", "missing-project", "-o", "x"], "missing-project"),
    ];
    for (args, want) in cases {
        let o = alba(&d, args);
        let (_, err) = text(&o);
        assert!(!o.status.success(), "{args:?}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
    assert!(!d.join("x").exists(), "nothing is written when refused");
}
