//! `alba demo`: the studio on the tank with its simulated plant
//! (examples/tank-plant), in a project folder of the user's.

use std::net::SocketAddr;
use std::path::Path;
use std::process::ExitCode;

const FILES: &[(&str, &str)] = &[
    ("alba.toml", include_str!("../../../examples/tank-plant/alba.toml")),
    ("tags.csv", include_str!("../../../examples/tank-plant/tags.csv")),
    ("main.lad", include_str!("../../../examples/tank-plant/main.lad")),
    ("plant.lad", include_str!("../../../examples/tank-plant/plant.lad")),
    ("README.md", include_str!("../../../examples/tank-plant/README.md")),
    ("alarms.csv", include_str!("../../../examples/tank-plant/alarms.csv")),
    (
        "hmi/tank.json",
        include_str!("../../../examples/tank-plant/hmi/tank.json"),
    ),
];

/// Writes the demo project into `dir` unless it holds one already (edits
/// made in the studio are kept between runs), then runs it.
pub fn run(dir: &Path, addr: SocketAddr, native: bool) -> ExitCode {
    let fresh = !dir.join("alba.toml").exists();
    if fresh {
        if dir.exists() && std::fs::read_dir(dir).map_or(true, |mut d| d.next().is_some()) {
            eprintln!(
                "error: {} exists and is neither empty nor an Alba project; choose another folder with --dir",
                dir.display()
            );
            return ExitCode::FAILURE;
        }
        if let Err(e) = std::fs::create_dir_all(dir) {
            eprintln!("error: cannot create {}: {e}", dir.display());
            return ExitCode::FAILURE;
        }
        for (file, text) in FILES {
            let path = dir.join(file);
            if let Some(parent) = path.parent()
                && let Err(e) = std::fs::create_dir_all(parent)
            {
                eprintln!("error: cannot create {}: {e}", parent.display());
                return ExitCode::FAILURE;
            }
            if let Err(e) = alba_model::fsutil::write_atomic(&path, |w| w.write_all(text.as_bytes())) {
                eprintln!("error: cannot write {}: {e}", path.display());
                return ExitCode::FAILURE;
            }
        }
    }
    let banner = format!(
        "The tank of AuroraLD with a simulated plant, {} in {} (edits are saved there). \
         Its operator screen is in the Screens tab, its alarms in the Alarms tab.",
        if fresh { "written" } else { "as last saved" },
        dir.display()
    );
    let opts = alba_app::Options {
        addr,
        io: "sim".into(),
        native,
        modbus: None,
        opcua: None,
        mqtt: None,
        tls: alba_app::tls::Tls::Auto,
        scan_log: None,
        quiet: false,
    };
    crate::run::run(dir, opts, Some(&banner))
}
