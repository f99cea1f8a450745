//! `alba import` and `alba export plcopen` (issue 21) from the command line:
//! a real LDmicro file becomes a project that checks and simulates; an
//! existing project is not overwritten without --force; a malformed file is
//! refused with its place and nothing is written; a project exported to
//! PLCopen XML imports back and behaves the same.

use crate::{alba, repo, scratch};
use std::path::Path;

fn fixture(path: &str) -> String {
    repo()
        .join("crates/import/tests/fixtures")
        .join(path)
        .to_string_lossy()
        .into_owned()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn an_ldmicro_file_becomes_a_project_that_checks_and_runs() {
    let d = scratch("import-ldmicro");
    let o = alba(
        &d,
        &[
            "import",
            &fixture("ldmicro/traffic.ld"),
            "-o",
            "traffic",
            "--board",
            "uno",
        ],
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("imported") && err.contains("(ldmicro)"), "{err}");
    assert!(
        err.contains("traffic.ld:"),
        "the report names places in the source: {err}"
    );
    let toml = std::fs::read_to_string(d.join("traffic/alba.toml")).expect("alba.toml");
    assert!(toml.contains("[board]") && toml.contains("uno"), "{toml}");
    let o = alba(&d, &["check", "traffic"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = alba(&d, &["sim", "traffic", "--until", "100"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("time_ms,"));

    // Not over an existing project without --force, which replaces its files.
    let before = std::fs::read_to_string(d.join("traffic/tags.csv")).expect("tags.csv");
    let o = alba(&d, &["import", &fixture("ldmicro/blink.ld"), "-o", "traffic"]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.contains("error[E701]") && err.contains("--force"), "{err}");
    assert_eq!(
        std::fs::read_to_string(d.join("traffic/tags.csv")).expect("tags.csv"),
        before
    );
    let o = alba(
        &d,
        &["import", &fixture("ldmicro/blink.ld"), "-o", "traffic", "--force"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(
        std::fs::read_to_string(d.join("traffic/tags.csv")).expect("tags.csv"),
        before
    );
}

#[test]
fn a_malformed_file_is_refused_at_its_place_and_nothing_is_written() {
    let d = scratch("import-malformed");
    std::fs::write(
        d.join("bad.ld"),
        "LDmicro0.1\n\nIO LIST\nEND\n\nPROGRAM\nRUNG\n    FROB Xa\nEND\n",
    )
    .expect("write");
    let o = alba(&d, &["import", "bad.ld", "-o", "out"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("error[E701]") && err.contains("bad.ld:8:"), "{err}");
    assert!(
        !d.join("out").exists(),
        "a failed import wrote {}",
        d.join("out").display()
    );
    // Leftovers of the staging folder neither.
    let left: Vec<_> = std::fs::read_dir(&d)
        .expect("dir")
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(left, vec![std::ffi::OsString::from("bad.ld")]);
    let o = alba(&d, &["import", "bad.ld", "-o", "out", "--format", "cobol"]);
    assert!(stderr(&o).contains("error[E404]"), "{}", stderr(&o));
}

#[test]
fn a_project_exported_to_plcopen_imports_back_and_traces_the_same() {
    let d = scratch("import-plcopen");
    let start_stop = repo().join("examples/start-stop");
    let o = alba(
        &d,
        &["export", "plcopen", &start_stop.to_string_lossy(), "-o", "plc.xml"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let xml = std::fs::read_to_string(d.join("plc.xml")).expect("plc.xml");
    assert!(xml.contains("http://www.plcopen.org/xml/tc6_0201"), "{xml}");
    let o = alba(&d, &["import", "plc.xml", "-o", "back"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("(plcopen)"));
    let stim = d.join("stim.csv");
    std::fs::write(
        &stim,
        "time_ms,tag,value\n100,Start,1\n200,Start,0\n6000,Stop,1\n6100,Stop,0\n",
    )
    .expect("stim");
    let trace = |p: &Path| {
        let o = alba(
            &d,
            &[
                "sim",
                &p.to_string_lossy(),
                "--until",
                "7000",
                "--every",
                "100",
                "--stimulus",
                "stim.csv",
                "--tags",
                "Motor,Lamp",
            ],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let original = trace(&start_stop);
    assert!(original.contains(",1,"), "the stimulus starts the motor: {original}");
    assert_eq!(trace(&d.join("back")), original);
}

#[test]
fn an_aurorald_folder_becomes_a_project_with_its_screen_alarms_and_trend() {
    let d = scratch("import-aurora");
    let o = alba(&d, &["import", &fixture("aurora/planta"), "-o", "planta"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("(aurora)") && err.contains("instructions.pl:"), "{err}");
    for f in [
        "alba.toml",
        "tags.csv",
        "main.lad",
        "hmi/planta.json",
        "alarms.csv",
        "trends.json",
    ] {
        assert!(d.join("planta").join(f).is_file(), "{f} missing");
    }
    // `alba check` accepts it, screen and alarms included.
    let o = alba(&d, &["check", "planta"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("2 alarms") && err.contains("1 screen"), "{err}");
    let o = alba(&d, &["sim", "planta", "--until", "100"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Its main.ara alone names the folder too; a folder is never L5X.
    let o = alba(&d, &["import", &fixture("aurora/planta/main.ara"), "-o", "again"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = alba(&d, &["import", &fixture("aurora/planta"), "-o", "x", "--format", "l5x"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("only AuroraLD projects (--format aurora) are folders"),
        "{}",
        stderr(&o)
    );
    assert!(!d.join("x").exists());
}
