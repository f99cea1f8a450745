//! The other commands: new, check, explain.

use crate::{alba, scratch};

#[test]
fn new_creates_a_project_that_checks_and_runs() {
    let dir = scratch("new");
    let proj = dir.join("my-plant");
    let out = alba(&dir, &["new", "my-plant"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let toml = std::fs::read_to_string(proj.join("alba.toml")).unwrap();
    assert!(toml.contains("name = \"my-plant\""), "{toml}");
    let out = alba(&dir, &["check", "my-plant"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = alba(
        &dir,
        &[
            "sim",
            "my-plant",
            "--until",
            "1500",
            "--every",
            "500",
            "--stimulus",
            "my-plant/stimulus.csv",
            "--tags",
            "Start,Motor",
        ],
    );
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "time_ms,Start,Motor\n0,0,0\n500,0,0\n1000,1,1\n1500,0,1\n"
    );
    // A second `new` into the same folder refuses instead of overwriting.
    let out = alba(&dir, &["new", "my-plant"]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn explain_prints_a_code_and_refuses_unknown_ones() {
    let dir = scratch("explain");
    let out = alba(&dir, &["explain", "E301"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("E301: unknown tag"));
    let out = alba(&dir, &["explain", "E999"]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn check_reports_every_error_of_a_file() {
    let dir = scratch("check-all");
    std::fs::write(dir.join("alba.toml"), "name = \"x\"\nprograms = [\"main.lad\"]\n").unwrap();
    std::fs::write(dir.join("tags.csv"), "name,type\nA,BOOL\nN,DINT\nT,TIMER\n").unwrap();
    std::fs::write(
        dir.join("main.lad"),
        "XIC(A)OTE(Missing);\nXIC(A)XYZ(A);\nXIC(N)OTE(A);\nXIC(A)TON(N,10,0);\nXIC(A;\nXIC(A);\nXIC(A)JMP(Nowhere);\n",
    )
    .unwrap();
    let out = alba(&dir, &["check", ".", "--short"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    for want in [
        "./main.lad:1:11: error[E301]",
        "./main.lad:2:7: error[E201]",
        "./main.lad:3:5: error[E303]",
        "./main.lad:4:11: error[E303]",
        "./main.lad:5:4: error[E202]",
        "./main.lad:6:1: error[E308]",
        "./main.lad:7:11: error[E306]",
        "7 errors",
    ] {
        assert!(err.contains(want), "missing `{want}` in:\n{err}");
    }
}
