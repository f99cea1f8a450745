//! `alba new`: a runnable start/stop project (the start-stop example).

use std::path::Path;
use std::process::ExitCode;

const FILES: &[(&str, &str)] = &[
    ("alba.toml", include_str!("../../../examples/start-stop/alba.toml")),
    ("tags.csv", include_str!("../../../examples/start-stop/tags.csv")),
    ("main.lad", include_str!("../../../examples/start-stop/main.lad")),
    (
        "stimulus.csv",
        include_str!("../../../examples/start-stop/stimulus.csv"),
    ),
];

pub fn run(dir: &Path) -> ExitCode {
    if dir.exists() && std::fs::read_dir(dir).map_or(true, |mut d| d.next().is_some()) {
        eprintln!(
            "error: {} already exists and is not an empty folder; choose a new name",
            dir.display()
        );
        return ExitCode::FAILURE;
    }
    let name = dir
        .file_name()
        .map_or_else(|| "project".into(), |n| n.to_string_lossy().to_string());
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("error: cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    for (file, text) in FILES {
        let text = if *file == "alba.toml" {
            text.replace(
                "name = \"start-stop\"",
                &format!("name = {}", alba_project::config::toml_string(&name)),
            )
        } else {
            text.to_string()
        };
        if let Err(e) = alba_model::fsutil::write_atomic(&dir.join(file), |w| w.write_all(text.as_bytes())) {
            eprintln!("error: cannot write {}: {e}", dir.join(file).display());
            return ExitCode::FAILURE;
        }
    }
    let d = dir.display();
    println!("Created {d}: a start/stop motor with a lamp after 5 s.");
    println!("Check it:     alba check {d}");
    println!(
        "Simulate it:  alba sim {d} --until 10000 --every 500 --stimulus {d}/stimulus.csv --tags Start,Stop,Motor,Lamp"
    );
    ExitCode::SUCCESS
}
