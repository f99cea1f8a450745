//! A project in a temporary folder, compiled.

#![allow(dead_code)]

use alba_diag::Files;
use alba_ir::Program;
use alba_verify::explore::{self, Budget, Model, Outcome, Verdict};
use alba_verify::props;
use std::path::Path;
use std::sync::Arc;

pub const SCAN_MS: u64 = 10;

/// Writes alba.toml, tags.csv and main.lad into `dir`.
pub fn write(dir: &Path, tags: &str, lad: &str) {
    std::fs::write(
        dir.join("alba.toml"),
        format!("name = \"t\"\nscan_ms = {SCAN_MS}\nprograms = [\"main.lad\"]\n"),
    )
    .expect("alba.toml");
    std::fs::write(
        dir.join("tags.csv"),
        format!("name,type,address,initial,retain,description\n{tags}"),
    )
    .expect("tags.csv");
    std::fs::write(dir.join("main.lad"), lad).expect("main.lad");
}

pub fn compile(tags: &str, lad: &str) -> Arc<Program> {
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), tags, lad);
    let c = alba_load::compile_dir(dir.path());
    let msgs: Vec<String> = c.diagnostics.iter().map(|d| d.message.clone()).collect();
    Arc::new(
        c.program
            .unwrap_or_else(|| panic!("the test program compiles: {msgs:?}")),
    )
}

/// Decides every property of `toml` on the program.
pub fn decide(program: &Arc<Program>, toml: &str) -> (Model, Vec<Verdict>, props::Properties) {
    decide_with(program, toml, Budget::default())
}

pub fn decide_with(program: &Arc<Program>, toml: &str, budget: Budget) -> (Model, Vec<Verdict>, props::Properties) {
    let mut files = Files::new();
    let f = files.add("properties.toml", toml.to_string());
    let p = props::parse(files.text(f), f, &program.layout).unwrap_or_else(|d| {
        panic!(
            "properties parse: {:?}",
            d.iter().map(|d| &d.message).collect::<Vec<_>>()
        )
    });
    let model = Model::new(program.clone(), SCAN_MS, &p);
    let v = p
        .properties
        .iter()
        .map(|prop| explore::decide(&model, prop, &p.assumes, budget))
        .collect();
    (model, v, p)
}

pub fn outcome(v: &Verdict) -> &'static str {
    match v.outcome {
        Outcome::Proved => "proved",
        Outcome::Refuted => "refuted",
        Outcome::Unknown(_) => "unknown",
    }
}

pub const MOTOR_TAGS: &str = "\
FwdBtn,BOOL,DI:1/0,,,
RevBtn,BOOL,DI:1/1,,,
Stop,BOOL,DI:1/2,,,
Fwd,BOOL,DO:2/0,,,
Rev,BOOL,DO:2/1,,,
";

/// Forward/reverse starter with the interlock contacts.
pub const MOTOR: &str = "\
[XIC(FwdBtn),XIC(Fwd)]XIO(Stop)XIO(Rev)OTE(Fwd);
[XIC(RevBtn),XIC(Rev)]XIO(Stop)XIO(Fwd)OTE(Rev);
";

/// The same with the reverse rung's interlock contact missing.
pub const MOTOR_NO_INTERLOCK: &str = "\
[XIC(FwdBtn),XIC(Fwd)]XIO(Stop)XIO(Rev)OTE(Fwd);
[XIC(RevBtn),XIC(Rev)]XIO(Stop)OTE(Rev);
";
