//! `alba historian migrate`: creates the shared historian's schema in the PostgreSQL
//! database that `[history]` of alba.toml names; `alba historian --mqtt HOST:PORT`: the
//! service that consumes the runtimes' MQTT messages into the historian
//! (docs/historian.md).

use alba_diag::{Files, render_all};
use alba_project::config::Config;
use alba_settings::{HistoryBackend, Settings};
use clap::Subcommand;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `alba historian`: a subcommand, or the service that consumes the broker's messages.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct HistorianArgs {
    #[command(subcommand)]
    cmd: Option<HistorianCmd>,
    #[command(flatten)]
    service: ServiceArgs,
}

#[derive(Subcommand)]
pub enum HistorianCmd {
    /// Create (or check) the tables of `[history] backend = "postgres"` in its database:
    /// a TimescaleDB hypertable when the extension is installed, a plain table otherwise.
    Migrate {
        /// The project folder (with alba.toml).
        project: PathBuf,
    },
}

/// `alba historian --mqtt HOST:PORT …`: the runtimes' tag messages (JSON and Sparkplug B)
/// from the broker into the historian, each under its node id (docs/historian.md).
#[derive(clap::Args)]
pub struct ServiceArgs {
    /// The MQTT broker to consume from.
    #[arg(long, value_name = "HOST:PORT")]
    mqtt: Option<String>,
    /// The PostgreSQL database to write into (`host=… user=… dbname=…` or a
    /// postgres:// URL, without the password); its schema is made by `migrate`.
    #[arg(long, value_name = "URL", conflicts_with = "sqlite")]
    postgres: Option<String>,
    /// The database password: the first line of this file.
    #[arg(long, value_name = "FILE", requires = "postgres")]
    password_file: Option<PathBuf>,
    /// TLS to the database: the CA certificates (PEM) its certificate must chain to.
    #[arg(long, value_name = "FILE", requires = "postgres")]
    ca_file: Option<PathBuf>,
    /// TLS: a client certificate (PEM), with --client-key.
    #[arg(long, value_name = "FILE", requires_all = ["client_key", "ca_file"])]
    client_cert: Option<PathBuf>,
    /// TLS: the client certificate's key (PEM).
    #[arg(long, value_name = "FILE", requires = "client_cert")]
    client_key: Option<PathBuf>,
    /// The local buffer for samples while the database is unreachable.
    #[arg(
        long,
        value_name = "FILE",
        default_value = "historian-buffer.db",
        requires = "postgres"
    )]
    buffer: PathBuf,
    /// The most samples the buffer holds (beyond them the oldest are dropped and counted).
    #[arg(long, value_name = "N", default_value_t = alba_historian::DEFAULT_BUFFER_SAMPLES)]
    buffer_max_samples: u64,
    /// Instead of PostgreSQL: a folder of SQLite history files, one per node.
    #[arg(long, value_name = "DIR")]
    sqlite: Option<PathBuf>,
    /// JSON topic prefixes to consume (`<prefix>/tags/#`, repeatable); the levels `+`
    /// matches name the node.
    #[arg(long = "json", value_name = "PREFIX", default_value = "alba/+")]
    json: Vec<String>,
    /// Consume no JSON topics.
    #[arg(long, conflicts_with = "json")]
    no_json: bool,
    /// Consume no Sparkplug B (`spBv1.0/#`).
    #[arg(long)]
    no_sparkplug: bool,
    /// Publish the Sparkplug `STATE` of a primary host with this id.
    #[arg(long, value_name = "ID")]
    primary_host: Option<String>,
    /// The MQTT client id (the broker keeps its session while the service is away).
    #[arg(long, value_name = "ID", default_value = "alba-historian")]
    client_id: String,
    /// The broker user name (with --mqtt-password-file).
    #[arg(long, value_name = "USER", requires = "mqtt_password_file")]
    mqtt_user: Option<String>,
    /// The broker password: the first line of this file.
    #[arg(long, value_name = "FILE", requires = "mqtt_user")]
    mqtt_password_file: Option<PathBuf>,
    /// TLS to the broker: the CA certificates (PEM) its certificate must chain to.
    #[arg(long, value_name = "FILE")]
    mqtt_ca_file: Option<PathBuf>,
    /// TLS to the broker: a client certificate (PEM), with --mqtt-client-key.
    #[arg(long, value_name = "FILE", requires_all = ["mqtt_client_key", "mqtt_ca_file"])]
    mqtt_client_cert: Option<PathBuf>,
    /// TLS to the broker: the client certificate's key (PEM).
    #[arg(long, value_name = "FILE", requires = "mqtt_client_cert")]
    mqtt_client_key: Option<PathBuf>,
}

pub fn run(args: HistorianArgs) -> ExitCode {
    let result = match args.cmd {
        Some(HistorianCmd::Migrate { project }) => migrate(&project),
        None => serve(args.service),
    };
    match result {
        Ok(msg) => {
            println!("{msg}");
            ExitCode::SUCCESS
        }
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}

/// The first line of a secret file (never printed).
fn secret(path: &Path) -> Result<String, String> {
    alba_historian::PgConfig::password_from_file(path).map_err(|e| e.to_string())
}

fn serve(a: ServiceArgs) -> Result<String, String> {
    let Some(broker) = a.mqtt else {
        return Err("give --mqtt HOST:PORT to consume a broker's messages, or a subcommand (see --help)".into());
    };
    if !alba_settings::is_host_port(&broker) {
        return Err(format!("--mqtt {broker}: expected host:port, like 127.0.0.1:1883"));
    }
    let (host, port) = broker.rsplit_once(':').unwrap_or((&broker, "1883"));
    let port = port.parse::<u16>().map_err(|_| format!("--mqtt {broker}: bad port"))?;
    let credentials = match (a.mqtt_user, a.mqtt_password_file) {
        (Some(u), Some(f)) => Some((u, secret(&f)?)),
        _ => None,
    };
    let tls = match &a.mqtt_ca_file {
        Some(ca) => Some(
            alba_historian::client_tls(ca, a.mqtt_client_cert.as_deref().zip(a.mqtt_client_key.as_deref()))
                .map_err(|e| format!("--mqtt-ca-file: {e}"))?,
        ),
        None => None,
    };
    let opts = alba_app::ingest::IngestOptions {
        host: host.trim_start_matches('[').trim_end_matches(']').to_string(),
        port,
        client_id: a.client_id,
        credentials,
        tls,
        json: if a.no_json { Vec::new() } else { a.json },
        sparkplug: !a.no_sparkplug,
        primary_host: a.primary_host,
    };
    if opts.json.is_empty() && !opts.sparkplug {
        return Err("--no-json and --no-sparkplug: nothing to consume".into());
    }
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start: {e}"))?;
    let store: std::sync::Arc<dyn alba_historian::NodeSink> = match (a.postgres, a.sqlite) {
        (Some(url), None) => {
            let mut pg = alba_historian::PgConfig::new(url, "alba-historian", a.buffer);
            pg.buffer_max_samples = a.buffer_max_samples;
            if pg.connection().map_err(|e| e.to_string())?.get_password().is_some() {
                return Err("--postgres holds a password: put it in the file --password-file names".into());
            }
            if let Some(f) = &a.password_file {
                pg.password = Some(secret(f)?);
            }
            pg.ca_file = a.ca_file;
            pg.client_cert = a.client_cert.zip(a.client_key);
            // The schema, if the database answers now (else the samples wait in the buffer).
            match alba_historian::migrate(&pg) {
                Ok(_) => {}
                Err(e) => eprintln!("historian: schema not checked ({e}); buffering until the database answers"),
            }
            std::sync::Arc::new(alba_historian::PgHistorian::open(pg).map_err(|e| e.to_string())?)
        }
        (None, Some(dir)) => std::sync::Arc::new(
            alba_historian::SqliteNodes::open(dir, alba_historian::Config::default()).map_err(|e| e.to_string())?,
        ),
        _ => return Err("say where to write: --postgres URL (with --password-file) or --sqlite DIR".into()),
    };
    let counters = rt.block_on(alba_app::ingest::ingest(store, opts, crate::run::shutdown_signal()))?;
    use std::sync::atomic::Ordering::Relaxed;
    Ok(format!(
        "historian: stopped after {} messages, {} samples stored, {} ignored, {} rebirths asked for",
        counters.messages.load(Relaxed),
        counters.samples.load(Relaxed),
        counters.ignored.load(Relaxed),
        counters.rebirths.load(Relaxed)
    ))
}

/// alba.toml alone (the programs need not compile to migrate).
fn config(dir: &Path) -> Result<(Config, Settings), String> {
    let path = dir.join("alba.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut files = Files::new();
    let f = files.add(path.display().to_string(), text);
    let (config, settings, diags) = alba_load::parse_both(files.text(f), f);
    match (config, settings) {
        (Some(c), Some(s)) if diags.is_empty() => Ok((c, s)),
        _ => Err(format!("alba.toml has errors:\n{}", render_all(&diags, &files))),
    }
}

fn migrate(dir: &Path) -> Result<String, String> {
    let (config, settings) = config(dir)?;
    if settings.history.backend != HistoryBackend::Postgres {
        return Err(format!(
            "{}: [history] backend is not \"postgres\" (the embedded SQLite historian needs no migration)",
            dir.join("alba.toml").display()
        ));
    }
    let pg = alba_app::pg_config(dir, &config.name, &settings.history)?;
    let report = alba_historian::migrate(&pg).map_err(|e| e.to_string())?;
    Ok(match (report.hypertable, report.note) {
        (_, Some(note)) => format!("historian schema ready: {note}"),
        (true, None) => {
            "historian schema ready: alba_samples is a TimescaleDB hypertable, chunks compressed after 7 days"
                .to_owned()
        }
        (false, None) => "historian schema ready".to_owned(),
    })
}
