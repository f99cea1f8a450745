//! Measures the two back ends on project folders (ADR 0015): each property
//! of properties.toml decided by k-induction alone (SAT, induct.rs) and by
//! the explicit search alone, with states, SAT calls and times.
//!
//! `cargo run -p alba-verify --example compare -- examples/star-delta examples/tank …`

use alba_verify::explore::{self, Budget, Method, Model, Outcome};
use alba_verify::induct::{self, NoProof, Setup};
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let seconds: u64 = std::env::var("SECONDS_PER_PROPERTY")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    println!("| example | property | k-induction | SAT calls | time | explicit | states | time |");
    println!("|---|---|---|---|---|---|---|---|");
    for dir in std::env::args().skip(1) {
        let dir = std::path::Path::new(&dir);
        let c = alba_load::compile_dir(dir);
        let scan_ms = c.project.scan_ms() as u64;
        let Some(program) = c.program else {
            eprintln!("{}: does not compile", dir.display());
            continue;
        };
        let program = Arc::new(program);
        let Ok(text) = std::fs::read_to_string(dir.join("properties.toml")) else {
            eprintln!("{}: no properties.toml", dir.display());
            continue;
        };
        let mut files = alba_diag::Files::new();
        let f = files.add("properties.toml", text);
        let Ok(props) = alba_verify::props::parse(files.text(f), f, &program.layout) else {
            eprintln!("{}: properties.toml does not parse", dir.display());
            continue;
        };
        let model = Model::new(program.clone(), scan_ms, &props);
        let name = dir
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        for p in &props.properties {
            let setup = Setup {
                program: &program,
                probes: props.probes.program(),
                init: &program.init,
                inputs: model
                    .inputs
                    .iter()
                    .filter_map(|i| match i.place {
                        alba_ir::Place::Bool(b) => Some(b),
                        _ => None,
                    })
                    .collect(),
            };
            let t = Instant::now();
            let (ind, calls) = match induct::prove(&setup, p, &props.assumes, 6, seconds) {
                Ok(proof) => (format!("proved (k = {})", proof.k), proof.sat_calls),
                Err(NoProof::NotInductive { k, sat_calls }) => (format!("no proof up to k = {k}"), sat_calls),
                Err(NoProof::NotAnInvariant) => ("not an invariant".to_string(), 0),
                Err(NoProof::Unsupported(what)) => (format!("not encoded ({what})"), 0),
            };
            let ind_ms = t.elapsed().as_millis();
            let budget = Budget {
                max_seconds: seconds,
                induction_k: 0,
                ..Budget::default()
            };
            let v = explore::decide(&model, p, &props.assumes, budget);
            debug_assert_eq!(v.method, Method::Explicit);
            let res = match &v.outcome {
                Outcome::Proved => "proved".to_string(),
                Outcome::Refuted => "refuted".to_string(),
                Outcome::Unknown(_) => "unknown (budget)".to_string(),
            };
            println!(
                "| {name} | {} | {ind} | {calls} | {ind_ms} ms | {res} | {} | {} ms |",
                p.name, v.states, v.millis
            );
        }
    }
}
