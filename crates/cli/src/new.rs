//! `alba new`: a runnable start/stop project (the start-stop example), or
//! with `--net` a state net in normal mode (the state-net-batch example).

use std::path::Path;
use std::process::ExitCode;

/// A starting project: its files and what `alba new` says about it.
struct Template {
    files: &'static [(&'static str, &'static str)],
    /// The example's `name = "…"` line in alba.toml, replaced by the folder's name.
    name_line: &'static str,
    what: &'static str,
    sim: &'static str,
}

const LADDER: Template = Template {
    files: FILES,
    name_line: "name = \"start-stop\"",
    what: "a start/stop motor with a lamp after 5 s",
    sim: "--until 10000 --every 500 --stimulus {d}/stimulus.csv --tags Start,Stop,Motor,Lamp",
};

const NET: Template = Template {
    files: NET_FILES,
    name_line: "name = \"state-net-batch\"",
    what: "a batch machine as a state net in normal mode (batch.pnml) with a ladder program",
    sim: "--until 22000 --every 500 --stimulus {d}/stimulus.csv --tags Start,Ready,Valve,Mixer,batch.batches.count,AllDone",
};

const NET_FILES: &[(&str, &str)] = &[
    ("alba.toml", include_str!("../../../examples/state-net-batch/alba.toml")),
    ("tags.csv", include_str!("../../../examples/state-net-batch/tags.csv")),
    (
        "batch.pnml",
        include_str!("../../../examples/state-net-batch/batch.pnml"),
    ),
    ("main.lad", include_str!("../../../examples/state-net-batch/main.lad")),
    (
        "stimulus.csv",
        include_str!("../../../examples/state-net-batch/stimulus.csv"),
    ),
];

const FILES: &[(&str, &str)] = &[
    ("alba.toml", include_str!("../../../examples/start-stop/alba.toml")),
    ("tags.csv", include_str!("../../../examples/start-stop/tags.csv")),
    ("main.lad", include_str!("../../../examples/start-stop/main.lad")),
    (
        "stimulus.csv",
        include_str!("../../../examples/start-stop/stimulus.csv"),
    ),
];

pub fn run(dir: &Path, net: bool) -> ExitCode {
    let t = if net { &NET } else { &LADDER };
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
    for (file, text) in t.files {
        let text = if *file == "alba.toml" {
            text.replace(t.name_line, &format!("name = {}", alba_settings::toml_string(&name)))
        } else {
            text.to_string()
        };
        if let Err(e) = alba_model::fsutil::write_atomic(&dir.join(file), |w| w.write_all(text.as_bytes())) {
            eprintln!("error: cannot write {}: {e}", dir.join(file).display());
            return ExitCode::FAILURE;
        }
    }
    let d = dir.display();
    println!("Created {d}: {}.", t.what);
    println!("Check it:     alba check {d}");
    println!("Simulate it:  alba sim {d} {}", t.sim.replace("{d}", &d.to_string()));
    ExitCode::SUCCESS
}
