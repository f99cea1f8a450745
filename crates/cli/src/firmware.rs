//! `alba firmware`: the remote-I/O firmware of controller mode (SPEC §7.2).

use alba_diag::render_all;
use alba_diag::{Code, Diagnostic, Files};
use alba_io::firmware::{self, Link, Spec};
use alba_model::board::{Model, PinMap};
use std::path::Path;
use std::process::ExitCode;

pub struct Args<'a> {
    pub project: Option<&'a Path>,
    pub board: Option<&'a str>,
    pub pinmap: Option<&'a str>,
    pub link: &'a str,
    pub slave: u8,
    pub watchdog_ms: u32,
    pub active_low: bool,
    pub pullup: bool,
    pub out: &'a Path,
    /// Build with avr-gcc (and upload to this port).
    pub build: bool,
    pub upload: Option<&'a str>,
}

fn refuse(msg: String) -> ExitCode {
    eprint!(
        "{}",
        render_all(&[Diagnostic::unplaced(Code::BadArgument, msg)], &Files::new())
    );
    ExitCode::FAILURE
}

pub fn run(a: Args) -> ExitCode {
    let Some(link) = Link::parse(a.link) else {
        return refuse(format!("unknown link `{}` (modbus or aurora)", a.link));
    };
    // The project's [board], then the options on top of it.
    let (mut model, mut pinmap, mut map, mut active_low) = (None, "aurora".to_string(), None, a.active_low);
    let mut power_up_on = Vec::new();
    if let Some(dir) = a.project {
        let (project, diags) = alba_load::load(dir);
        if !diags.is_empty() {
            eprint!("{}", render_all(&diags, &project.files));
            return ExitCode::FAILURE;
        }
        match project.config.as_ref().and_then(|c| c.board.as_ref()) {
            Some(b) => {
                model = Some(b.model);
                pinmap = b.pinmap.clone();
                map = Some(b.map.clone());
                active_low |= b.active_low;
                power_up_on.clone_from(&b.power_up_on);
            }
            None if a.board.is_none() => {
                return refuse(format!(
                    "{} has no [board] in alba.toml: add one or give --board (and --pinmap)",
                    dir.display()
                ));
            }
            None => {}
        }
    }
    if let Some(b) = a.board {
        match Model::parse(b) {
            Some(m) => model = Some(m),
            None => return refuse(format!("unknown board `{b}` (uno, nano or mega)")),
        }
    }
    if let Some(p) = a.pinmap {
        match PinMap::preset(p) {
            Some(m) => {
                pinmap = p.to_ascii_lowercase();
                map = Some(m);
            }
            None => return refuse(format!("unknown pin map `{p}` (aurora, s7 or openplc)")),
        }
    }
    let Some(model) = model else {
        return refuse("which board? give --board uno|nano|mega, or a project with [board]".into());
    };
    let map = match map {
        Some(m) => m,
        None => PinMap::preset(&pinmap).unwrap_or_default(),
    };
    let mut spec = Spec::new(model, &pinmap, map, link);
    spec.slave = a.slave;
    spec.watchdog_ms = a.watchdog_ms;
    spec.active_low = active_low;
    spec.pullup = a.pullup;
    spec.power_up_on = power_up_on;
    match firmware::write(&spec, a.out) {
        Ok(path) => {
            let c = alba_io::arduino::Counts::of(&spec.map);
            let what = match link {
                Link::Modbus => format!("Modbus RTU slave {}", spec.slave),
                Link::Aurora => "AuroraLD text link".to_string(),
            };
            println!(
                "wrote {} ({what}, {} 8N1; {}, pin map {}: {} DI, {} DO, {} AI, {} AO; watchdog {} ms)",
                path.display(),
                firmware::BAUD,
                model.title(),
                spec.pinmap,
                c.di,
                c.r#do,
                c.ai,
                c.ao,
                spec.watchdog_ms
            );
            if a.build {
                return crate::export::build_and_upload(&path, model, a.upload);
            }
            ExitCode::SUCCESS
        }
        Err(e) => refuse(e.to_string()),
    }
}
