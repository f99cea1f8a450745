//! `alba historian migrate`: creates the shared historian's schema in the PostgreSQL
//! database that `[history]` of alba.toml names (docs/historian.md).

use alba_diag::{Files, render_all};
use alba_project::config::{Config, HistoryBackend};
use clap::Subcommand;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Subcommand)]
pub enum HistorianCmd {
    /// Create (or check) the tables of `[history] backend = "postgres"` in its database:
    /// a TimescaleDB hypertable when the extension is installed, a plain table otherwise.
    Migrate {
        /// The project folder (with alba.toml).
        project: PathBuf,
    },
}

pub fn run(cmd: HistorianCmd) -> ExitCode {
    match cmd {
        HistorianCmd::Migrate { project } => match migrate(&project) {
            Ok(msg) => {
                println!("{msg}");
                ExitCode::SUCCESS
            }
            Err(msg) => {
                eprintln!("error: {msg}");
                ExitCode::FAILURE
            }
        },
    }
}

/// alba.toml alone (the programs need not compile to migrate).
fn config(dir: &Path) -> Result<Config, String> {
    let path = dir.join("alba.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut files = Files::new();
    let f = files.add(path.display().to_string(), text);
    let (config, diags) = Config::parse(files.text(f), f);
    match config {
        Some(c) if diags.is_empty() => Ok(c),
        _ => Err(format!("alba.toml has errors:\n{}", render_all(&diags, &files))),
    }
}

/// The settings of the project's PostgreSQL historian (the password file is relative to
/// the project folder).
pub fn pg_config(dir: &Path, config: &Config) -> Result<alba_historian::PgConfig, String> {
    let h = &config.history;
    if h.backend != HistoryBackend::Postgres {
        return Err(format!(
            "{}: [history] backend is not \"postgres\" (the embedded SQLite historian needs no migration)",
            dir.join("alba.toml").display()
        ));
    }
    let url = h.url.clone().ok_or("[history] has no url")?;
    let node = h.node.clone().unwrap_or_else(|| config.name.clone());
    let mut pg = alba_historian::PgConfig::new(url, node, dir.join(".alba").join("history-buffer.db"));
    pg.buffer_max_samples = u64::from(h.buffer_max_samples);
    if let Some(file) = &h.password_file {
        pg.password = Some(alba_historian::PgConfig::password_from_file(&dir.join(file)).map_err(|e| e.to_string())?);
    }
    Ok(pg)
}

fn migrate(dir: &Path) -> Result<String, String> {
    let config = config(dir)?;
    let pg = pg_config(dir, &config)?;
    let connection = pg.connection().map_err(|e| e.to_string())?;
    let report = alba_historian::migrate(&connection).map_err(|e| e.to_string())?;
    Ok(match (report.hypertable, report.note) {
        (true, _) => "historian schema ready: alba_samples is a TimescaleDB hypertable".to_owned(),
        (false, Some(note)) => format!("historian schema ready: {note}"),
        (false, None) => "historian schema ready (plain table)".to_owned(),
    })
}
