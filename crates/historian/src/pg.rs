//! The shared historian on PostgreSQL: several runtimes write into the same table, each
//! under its own node id, through batched multi-row inserts that also maintain rollup
//! tiers (10 s, 10 min); while the database is unreachable the samples go to a bounded
//! local SQLite buffer and are back-filled in order on recovery. The downsampled query
//! fills the SQLite backend's bucket grid from the rollups, so its answers are the same and
//! its cost does not grow with the samples stored. The table is a TimescaleDB hypertable
//! (compressed) when the server has the extension, partitioned by time otherwise; TLS with
//! a CA file (tls.rs). See `docs/historian.md`.

use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use postgres::{Client, GenericClient, NoTls};
use rusqlite::{Connection, params};

use crate::agg::{Agg, ceil_to, floor_to};
use crate::backend::{Backend, Column};
use crate::csv;
use crate::error::{Error, Result, pg_message};
use crate::tls::Rustls;
use crate::{Bucket, MAX_POINTS, Point, Sample, TagRange, check_time, clamp_range, query};

/// The samples one INSERT (and one back-fill step) carries at most.
const BATCH: usize = 10_000;
/// The schema `migrate` makes: 1 was the samples alone, 2 adds the rollups.
const SCHEMA_VERSION: i32 = 2;
/// The rollup tiers kept in PostgreSQL, finest first: the table and its bucket width. Both
/// widths are widths of the SQLite backend's tiers, so a query takes the SQLite backend's
/// bucket grid and fills it exactly from the coarsest of these that divides its width.
const PG_TIERS: [(&str, i64); 2] = [("alba_rollup_10s", 10_000), ("alba_rollup_10m", 600_000)];

/// `floor(col / w) * w` for any sign (PostgreSQL's `%` keeps the dividend's sign).
fn floor_sql(col: &str, w: i64) -> String {
    format!("{col} - (({col} % {w}) + {w}) % {w}")
}

/// The statements that add the samples `source` selects (columns node, tag, t, v; each
/// new to the table) to every rollup tier, merging with the rows there: a CTE list
/// `a0 … aN` and the upserts, as one statement.
fn rollup_sql(source: &str) -> String {
    let merge = "ON CONFLICT (node, tag, t) DO UPDATE SET
                     lo = least(r.lo, excluded.lo), hi = greatest(r.hi, excluded.hi),
                     first = CASE WHEN excluded.first_t < r.first_t THEN excluded.first ELSE r.first END,
                     first_t = least(r.first_t, excluded.first_t),
                     last = CASE WHEN excluded.last_t > r.last_t THEN excluded.last ELSE r.last END,
                     last_t = greatest(r.last_t, excluded.last_t),
                     n = r.n + excluded.n";
    let (t0, w0) = PG_TIERS[0];
    let mut sql = format!(
        "WITH src AS ({source}),
         a0 AS (SELECT node, tag, {} AS b, min(v) AS lo, max(v) AS hi,
                       min(t) AS first_t, (array_agg(v ORDER BY t))[1] AS first,
                       max(t) AS last_t, (array_agg(v ORDER BY t DESC))[1] AS last, count(*) AS n
                FROM src GROUP BY 1, 2, 3)",
        floor_sql("t", w0)
    );
    for (k, (_, w)) in PG_TIERS.iter().enumerate().skip(1) {
        sql.push_str(&format!(
            ", a{k} AS (SELECT node, tag, {} AS b, min(lo) AS lo, max(hi) AS hi,
                           min(first_t) AS first_t, (array_agg(first ORDER BY first_t))[1] AS first,
                           max(last_t) AS last_t, (array_agg(last ORDER BY last_t DESC))[1] AS last,
                           sum(n)::bigint AS n
                    FROM a{} GROUP BY 1, 2, 3)",
            floor_sql("b", *w),
            k - 1
        ));
    }
    for (k, (table, _)) in PG_TIERS.iter().enumerate().skip(1) {
        sql.push_str(&format!(
            ", u{k} AS (INSERT INTO {table} AS r SELECT * FROM a{k} {merge})"
        ));
    }
    sql.push_str(&format!(" INSERT INTO {t0} AS r SELECT * FROM a0 {merge}"));
    sql
}
/// The default bound of the local buffer: 10 M samples (about 400 MB of SQLite).
pub const DEFAULT_BUFFER_SAMPLES: u64 = 10_000_000;

/// Settings of a PostgreSQL historian.
#[derive(Clone)]
pub struct PgConfig {
    /// Where and as whom to connect: a `postgres://user@host:port/db` URL or a
    /// `host=… user=… dbname=…` string. Better without the password (see `password`).
    pub url: String,
    /// The password (read from a secret file by [`PgConfig::password_from_file`]); never
    /// printed.
    pub password: Option<String>,
    /// This runtime's node id: its rows carry it, and its queries read only its rows.
    pub node: String,
    /// The local buffer (an SQLite file, created if missing) for samples that could not
    /// be sent.
    pub buffer_path: PathBuf,
    /// The most samples the buffer holds; beyond it the oldest are dropped and counted.
    pub buffer_max_samples: u64,
    /// How long a connection attempt may take.
    pub connect_timeout: Duration,
    /// How long to wait after a failed attempt before trying the database again (writes
    /// meanwhile go straight to the buffer).
    pub retry_interval: Duration,
    /// TLS: the CA certificates (PEM) the server's certificate must chain to; the server's
    /// host name or address must be in it. Set, connections are encrypted or refused.
    pub ca_file: Option<PathBuf>,
    /// TLS: a client certificate and its key (PEM) for servers that ask for one.
    pub client_cert: Option<(PathBuf, PathBuf)>,
}

impl std::fmt::Debug for PgConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PgConfig")
            .field("node", &self.node)
            .field("buffer_path", &self.buffer_path)
            .field("buffer_max_samples", &self.buffer_max_samples)
            .finish_non_exhaustive()
    }
}

impl PgConfig {
    /// Settings with the defaults: a buffer of [`DEFAULT_BUFFER_SAMPLES`], 5 s to connect,
    /// 2 s between attempts.
    pub fn new(url: impl Into<String>, node: impl Into<String>, buffer_path: impl Into<PathBuf>) -> PgConfig {
        PgConfig {
            url: url.into(),
            password: None,
            node: node.into(),
            buffer_path: buffer_path.into(),
            buffer_max_samples: DEFAULT_BUFFER_SAMPLES,
            connect_timeout: Duration::from_secs(5),
            retry_interval: Duration::from_secs(2),
            ca_file: None,
            client_cert: None,
        }
    }

    /// Reads the password from a secret file (its first line; the file's content is never
    /// put into an error).
    pub fn password_from_file(path: &Path) -> Result<String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::InvalidArgument(format!("{}: cannot read the password file: {e}", path.display())))?;
        let line = text.lines().next().unwrap_or("").trim_end_matches('\r');
        if line.is_empty() {
            return Err(Error::InvalidArgument(format!(
                "{}: the password file is empty",
                path.display()
            )));
        }
        Ok(line.to_owned())
    }

    /// The connection settings, with the password and timeout applied.
    pub fn connection(&self) -> Result<postgres::Config> {
        // The parser's message never quotes the string (which may hold a password).
        let mut c =
            postgres::Config::from_str(&self.url).map_err(|e| Error::InvalidArgument(format!("historian url: {e}")))?;
        if let Some(p) = &self.password {
            c.password(p);
        }
        c.connect_timeout(self.connect_timeout);
        c.application_name("alba-historian");
        match (&self.ca_file, c.get_ssl_mode()) {
            (Some(_), _) => {
                c.ssl_mode(postgres::config::SslMode::Require);
            }
            (None, postgres::config::SslMode::Require) => {
                return Err(Error::InvalidArgument(
                    "historian url: sslmode=require needs the CA file of the server's certificate (ca_file)".into(),
                ));
            }
            // Without a CA, no TLS: `prefer` is plain text.
            (None, _) => {
                c.ssl_mode(postgres::config::SslMode::Disable);
            }
        }
        Ok(c)
    }

    /// How to connect: plain, or TLS with `ca_file` (and `client_cert`).
    fn link(&self) -> Result<Link> {
        Ok(match &self.ca_file {
            None => Link::Plain,
            Some(ca) => Link::Tls(Rustls::new(
                ca,
                self.client_cert.as_ref().map(|(c, k)| (c.as_path(), k.as_path())),
            )?),
        })
    }
}

/// How connections are made.
#[derive(Clone)]
enum Link {
    Plain,
    Tls(Rustls),
}

impl Link {
    fn connect(&self, c: &postgres::Config) -> std::result::Result<Client, postgres::Error> {
        match self {
            Link::Plain => c.connect(NoTls),
            Link::Tls(t) => c.connect(t.clone()),
        }
    }
}

/// What [`migrate`] did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MigrateReport {
    /// The samples table is a TimescaleDB hypertable.
    pub hypertable: bool,
    /// Its chunks older than 7 days are compressed (TimescaleDB).
    pub compressed: bool,
    /// Without TimescaleDB: the samples table is partitioned by time (30-day ranges). A
    /// table made by an earlier version stays as it was.
    pub partitioned: bool,
    /// Why it is not one, when the extension was not usable.
    pub note: Option<String>,
}

/// Creates the schema (idempotent; several nodes may run it at once): the `alba_samples`
/// table keyed by (node, tag, t), made a TimescaleDB hypertable of 1-day chunks when the
/// extension is installed on the server (plain table otherwise).
pub fn migrate(config: &PgConfig) -> Result<MigrateReport> {
    let mut client = config.link()?.connect(&config.connection()?)?;
    // TimescaleDB when the server has it: detected, never required.
    let available = client
        .query_opt("SELECT 1 FROM pg_available_extensions WHERE name = 'timescaledb'", &[])?
        .is_some();
    let mut note = None;
    let timescale = if !available {
        note = Some("the timescaledb extension is not installed".to_owned());
        false
    } else if let Err(e) = client.batch_execute("CREATE EXTENSION IF NOT EXISTS timescaledb") {
        note = Some(format!("timescaledb is installed but not usable ({})", pg_message(&e)));
        false
    } else {
        true
    };
    let mut tx = client.transaction()?;
    // One migration at a time, whatever the number of nodes starting together.
    tx.execute("SELECT pg_advisory_xact_lock(6710886401)", &[])?;
    let existed = tx
        .query_opt("SELECT to_regclass('alba_samples')::text", &[])?
        .and_then(|r| r.get::<_, Option<String>>(0))
        .is_some();
    // Without TimescaleDB: ranges of PARTITION_MS, made as samples arrive (`ensure_partitions`).
    let partition = if existed || timescale {
        ""
    } else {
        "PARTITION BY RANGE (t)"
    };
    tx.batch_execute(&format!(
        "CREATE TABLE IF NOT EXISTS alba_schema (version integer NOT NULL);
         CREATE TABLE IF NOT EXISTS alba_samples (
             node text NOT NULL,
             tag text NOT NULL,
             t bigint NOT NULL,
             v double precision NOT NULL,
             PRIMARY KEY (node, tag, t)
         ) {partition};"
    ))?;
    let version: Option<i32> = tx.query_opt("SELECT version FROM alba_schema", &[])?.map(|r| r.get(0));
    if version.is_some_and(|v| v > SCHEMA_VERSION) {
        return Err(Error::InvalidArgument(format!(
            "the database has historian schema version {}; this Alba knows version {SCHEMA_VERSION}",
            version.unwrap_or_default()
        )));
    }
    for (table, _) in PG_TIERS {
        tx.batch_execute(&format!(
            "CREATE TABLE IF NOT EXISTS {table} (
                 node text NOT NULL, tag text NOT NULL, t bigint NOT NULL,
                 lo double precision NOT NULL, hi double precision NOT NULL,
                 first_t bigint NOT NULL, first double precision NOT NULL,
                 last_t bigint NOT NULL, last double precision NOT NULL,
                 n bigint NOT NULL,
                 PRIMARY KEY (node, tag, t))"
        ))?;
    }
    match version {
        None => {
            tx.execute(
                &format!("INSERT INTO alba_schema (version) VALUES ({SCHEMA_VERSION})"),
                &[],
            )?;
        }
        Some(1) => {
            // Version 1 had no rollups: made from the samples stored so far.
            tx.batch_execute(&format!(
                "{};
                 UPDATE alba_schema SET version = {SCHEMA_VERSION};",
                rollup_sql("SELECT node, tag, t, v FROM alba_samples")
            ))?;
        }
        Some(_) => {}
    }
    let partitioned = is_partitioned(&mut tx)?;
    tx.commit()?;
    let mut report = MigrateReport {
        hypertable: false,
        compressed: false,
        partitioned,
        note: None,
    };
    if timescale {
        match client.batch_execute(HYPERTABLE) {
            Ok(()) => {
                report.hypertable = true;
                match client.batch_execute(COMPRESSION) {
                    Ok(()) => report.compressed = true,
                    Err(e) => note = Some(format!("compression not enabled ({})", pg_message(&e))),
                }
            }
            Err(e) => note = Some(format!("not a hypertable ({})", pg_message(&e))),
        }
    }
    let layout = match (report.hypertable, report.partitioned) {
        (true, _) => "hypertable",
        (false, true) => "partitioned table (30-day ranges)",
        (false, false) => "plain table",
    };
    report.note = note.map(|n| format!("{n}: {layout}"));
    Ok(report)
}

/// `alba_samples` made a hypertable of 1-day chunks (the samples already there moved in).
const HYPERTABLE: &str = "SELECT create_hypertable('alba_samples', 't', chunk_time_interval => 86400000::bigint,
                                                  if_not_exists => true, migrate_data => true);";

/// Chunks older than 7 days compressed, by node and tag in time order (integer times:
/// TimescaleDB learns "now" in milliseconds from `alba_now_ms`).
const COMPRESSION: &str = "CREATE OR REPLACE FUNCTION alba_now_ms() RETURNS bigint LANGUAGE sql STABLE
                               AS $$ SELECT (extract(epoch FROM now()) * 1000)::bigint $$;
                           SELECT set_integer_now_func('alba_samples', 'alba_now_ms', replace_if_exists => true);
                           ALTER TABLE alba_samples SET (timescaledb.compress,
                               timescaledb.compress_segmentby = 'node, tag',
                               timescaledb.compress_orderby = 't');
                           SELECT add_compression_policy('alba_samples', 604800000::bigint, if_not_exists => true);";

/// The width of a partition of `alba_samples` without TimescaleDB: 30 days.
const PARTITION_MS: i64 = 30 * 86_400_000;

/// `alba_samples` is a partitioned table.
fn is_partitioned(c: &mut impl GenericClient) -> std::result::Result<bool, postgres::Error> {
    Ok(c.query_opt(
        "SELECT 1 FROM pg_partitioned_table WHERE partrelid = to_regclass('alba_samples')",
        &[],
    )?
    .is_some())
}

/// The partitions this writer knows to exist (or that the table is not partitioned).
#[derive(Default)]
struct Partitions {
    /// `None` until checked on a connection.
    partitioned: Option<bool>,
    made: std::collections::HashSet<i64>,
}

/// Makes the partitions `rows` fall into, each in a transaction of its own before the
/// insert's (creating one waits for the inserts under way, which wait for nothing).
fn ensure_partitions(
    client: &mut Client,
    parts: &mut Partitions,
    rows: &[Row<'_>],
) -> std::result::Result<(), postgres::Error> {
    let partitioned = match parts.partitioned {
        Some(p) => p,
        None => *parts.partitioned.insert(is_partitioned(client)?),
    };
    if !partitioned {
        return Ok(());
    }
    let mut needed: Vec<i64> = rows
        .iter()
        .map(|r| r.2.div_euclid(PARTITION_MS))
        .filter(|p| !parts.made.contains(p))
        .collect();
    needed.sort_unstable();
    needed.dedup();
    for p in needed {
        let name = if p < 0 {
            format!("alba_samples_pm{}", -p)
        } else {
            format!("alba_samples_p{p}")
        };
        let mut tx = client.transaction()?;
        // One creator at a time (two nodes starting a new month together).
        tx.execute("SELECT pg_advisory_xact_lock(6710886402)", &[])?;
        tx.batch_execute(&format!(
            "CREATE TABLE IF NOT EXISTS {name} PARTITION OF alba_samples FOR VALUES FROM ({}) TO ({})",
            p * PARTITION_MS,
            (p + 1) * PARTITION_MS
        ))?;
        tx.commit()?;
        parts.made.insert(p);
    }
    Ok(())
}

/// The state of a PostgreSQL historian, for `alba run`'s health report.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PgHealth {
    /// The last write or back-fill reached the database.
    pub connected: bool,
    /// Samples waiting in the local buffer.
    pub buffered: u64,
    /// Samples dropped from the full buffer since it was created (oldest first).
    pub dropped: u64,
    /// The last error, if the database is not reachable.
    pub last_error: Option<String>,
}

/// A shared historian on PostgreSQL; `Send + Sync`. Its methods block: call them from a
/// thread of their own or a blocking task, not from inside an async runtime.
pub struct PgHistorian {
    config: PgConfig,
    connection: postgres::Config,
    link: Link,
    writer: Mutex<WriterState>,
    readers: Mutex<Vec<Client>>,
}

impl std::fmt::Debug for PgHistorian {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PgHistorian")
            .field("config", &self.config)
            .finish_non_exhaustive()
    }
}

struct WriterState {
    client: Option<Client>,
    partitions: Partitions,
    last_attempt: Option<Instant>,
    buffer: Buffer,
    last_error: Option<String>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A readable message for an error that made a write go to the buffer.
fn describe(e: &postgres::Error) -> String {
    match e.as_db_error() {
        Some(db) if db.code() == &postgres::error::SqlState::UNDEFINED_TABLE => {
            format!(
                "{}: the schema is missing (run `alba historian migrate`)",
                pg_message(e)
            )
        }
        _ => pg_message(e),
    }
}

impl PgHistorian {
    /// Opens the local buffer and tries the database once (it may be down: samples are
    /// then buffered until it answers). Only a bad URL or an unusable buffer file fail.
    pub fn open(config: PgConfig) -> Result<PgHistorian> {
        if config.node.is_empty() {
            return Err(Error::InvalidArgument("empty historian node id".into()));
        }
        let connection = config.connection()?;
        let link = config.link()?;
        let buffer = Buffer::open(&config.buffer_path, config.buffer_max_samples)?;
        let h = PgHistorian {
            config,
            connection,
            link,
            writer: Mutex::new(WriterState {
                client: None,
                partitions: Partitions::default(),
                last_attempt: None,
                buffer,
                last_error: None,
            }),
            readers: Mutex::new(Vec::new()),
        };
        let mut w = lock(&h.writer);
        h.ensure_client(&mut w, true);
        drop(w);
        Ok(h)
    }

    /// The node id this historian writes and reads under.
    pub fn node(&self) -> &str {
        &self.config.node
    }

    /// Connects the writer if it is not connected and an attempt is due (`now`: whatever
    /// the retry interval).
    fn ensure_client(&self, w: &mut WriterState, now: bool) -> bool {
        if w.client.as_ref().is_some_and(|c| !c.is_closed()) {
            return true;
        }
        w.client = None;
        let due = now || w.last_attempt.is_none_or(|t| t.elapsed() >= self.config.retry_interval);
        if !due {
            return false;
        }
        w.last_attempt = Some(Instant::now());
        match self.link.connect(&self.connection) {
            Ok(c) => {
                w.client = Some(c);
                true
            }
            Err(e) => {
                w.last_error = Some(describe(&e));
                false
            }
        }
    }

    /// Stores samples (same rules as [`crate::Historian::record_batch`]: NaN skipped, a
    /// second value at the same time of a tag ignored). With the database unreachable, or
    /// samples still waiting in the buffer, they are appended to the buffer (so that they
    /// reach the database in order) and a back-fill is tried when due. Returns how many
    /// were accepted; only invalid samples or a failing buffer file give an error.
    pub fn record_batch(&self, samples: &[Sample<'_>]) -> Result<usize> {
        self.record_for(&self.config.node, samples)
    }

    /// Stores samples under another node's id, as [`record_batch`](Self::record_batch)
    /// does under this one's: what a service consuming several runtimes' messages
    /// (`alba historian --mqtt`) writes.
    pub fn record_for(&self, node: &str, samples: &[Sample<'_>]) -> Result<usize> {
        if node.is_empty() {
            return Err(Error::InvalidArgument("empty historian node id".into()));
        }
        let mut rows = Vec::with_capacity(samples.len());
        for s in samples {
            if s.tag.is_empty() {
                return Err(Error::InvalidArgument("empty tag name".into()));
            }
            check_time(s.t_ms)?;
            if !s.v.is_nan() {
                rows.push((node, s.tag, s.t_ms, s.v));
            }
        }
        if rows.is_empty() {
            return Ok(0);
        }
        let mut guard = lock(&self.writer);
        let w = &mut *guard;
        if w.buffer.len == 0
            && self.ensure_client(w, false)
            && let Some(client) = w.client.as_mut()
        {
            let partitions = &mut w.partitions;
            match ensure_partitions(client, partitions, &rows).and_then(|()| insert(client, &rows)) {
                Ok(()) => {
                    w.last_error = None;
                    return Ok(rows.len());
                }
                Err(e) => {
                    w.last_error = Some(describe(&e));
                    w.client = None;
                    w.partitions = Partitions::default();
                    w.last_attempt = Some(Instant::now());
                }
            }
        }
        w.buffer.append(&rows)?;
        self.backfill_locked(w, false)?;
        Ok(rows.len())
    }

    /// Sends the buffered samples to the database now (connecting if needed, whatever
    /// the retry interval), oldest first. Returns how many are still waiting: 0 when the
    /// buffer is empty, more when the database is unreachable again.
    pub fn backfill(&self) -> Result<u64> {
        let mut w = lock(&self.writer);
        self.backfill_locked(&mut w, true)
    }

    fn backfill_locked(&self, w: &mut WriterState, now: bool) -> Result<u64> {
        while w.buffer.len > 0 {
            if !self.ensure_client(w, now) {
                break;
            }
            let (last_seq, rows) = w.buffer.oldest(BATCH)?;
            let refs: Vec<Row<'_>> = rows
                .iter()
                .map(|(node, tag, t, v)| (node.as_deref().unwrap_or(&self.config.node), tag.as_str(), *t, *v))
                .collect();
            let Some(client) = w.client.as_mut() else { break };
            let partitions = &mut w.partitions;
            match ensure_partitions(client, partitions, &refs).and_then(|()| insert(client, &refs)) {
                Ok(()) => {
                    w.last_error = None;
                    // Removed after the insert committed: a crash in between sends these
                    // again, and the database ignores the duplicates.
                    w.buffer.remove_through(last_seq)?;
                }
                Err(e) => {
                    w.last_error = Some(describe(&e));
                    w.client = None;
                    w.partitions = Partitions::default();
                    w.last_attempt = Some(Instant::now());
                    break;
                }
            }
        }
        Ok(w.buffer.len)
    }

    /// The connection state and the buffer's counters.
    pub fn health(&self) -> PgHealth {
        let w = lock(&self.writer);
        PgHealth {
            connected: w.client.as_ref().is_some_and(|c| !c.is_closed()) && w.last_error.is_none(),
            buffered: w.buffer.len,
            dropped: w.buffer.dropped,
            last_error: w.last_error.clone(),
        }
    }

    /// Runs `f` on a reading connection from the pool (opened when none is free; one
    /// that failed is not kept).
    fn read<T>(&self, f: impl FnOnce(&mut Client) -> Result<T>) -> Result<T> {
        let pooled = lock(&self.readers).pop();
        let mut client = match pooled {
            Some(c) if !c.is_closed() => c,
            _ => self.link.connect(&self.connection)?,
        };
        let out = f(&mut client);
        if !client.is_closed() {
            let mut pool = lock(&self.readers);
            if pool.len() < READERS {
                pool.push(client);
                return out;
            }
        }
        close(vec![client]);
        out
    }

    /// The nodes that have samples in the database, by id.
    pub fn nodes(&self) -> Result<Vec<String>> {
        self.read(|c| {
            // One index probe per node (a loose index scan), not a scan of every sample.
            let rows = c.query(
                "WITH RECURSIVE n AS (
                     (SELECT node FROM alba_samples ORDER BY node LIMIT 1)
                     UNION ALL
                     SELECT (SELECT node FROM alba_samples WHERE node > n.node ORDER BY node LIMIT 1)
                     FROM n WHERE n.node IS NOT NULL)
                 SELECT node FROM n WHERE node IS NOT NULL",
                &[],
            )?;
            let mut out: Vec<String> = rows.iter().map(|r| r.get(0)).collect();
            out.sort_by(|a, b| a.as_bytes().cmp(b.as_bytes()));
            Ok(out)
        })
    }

    /// The tags of `node` (none for a node without samples), as [`Backend::tags`] gives
    /// them.
    pub fn tags_of(&self, node: &str) -> Result<Vec<TagRange>> {
        self.read(|c| {
            // One index probe per tag (a loose index scan), not a scan of every sample.
            let rows = c.query(
                "WITH RECURSIVE n AS (
                     (SELECT tag FROM alba_samples WHERE node = $1 ORDER BY tag LIMIT 1)
                     UNION ALL
                     SELECT (SELECT tag FROM alba_samples WHERE node = $1 AND tag > n.tag
                             ORDER BY tag LIMIT 1)
                     FROM n WHERE n.tag IS NOT NULL)
                 SELECT n.tag,
                        (SELECT t FROM alba_samples WHERE node = $1 AND tag = n.tag ORDER BY t ASC LIMIT 1),
                        (SELECT t FROM alba_samples WHERE node = $1 AND tag = n.tag ORDER BY t DESC LIMIT 1)
                 FROM n WHERE n.tag IS NOT NULL",
                &[&node],
            )?;
            let mut out: Vec<TagRange> = rows
                .iter()
                .map(|r| TagRange {
                    name: r.get(0),
                    first_ms: r.get(1),
                    last_ms: r.get(2),
                })
                .collect();
            // By name in byte order, as the SQLite backend sorts them.
            out.sort_by(|a, b| a.name.as_bytes().cmp(b.name.as_bytes()));
            Ok(out)
        })
    }

    /// The downsampled samples of `node`'s `tag`, as [`Backend::query`] gives them.
    pub fn query_node(&self, node: &str, tag: &str, from_ms: i64, to_ms: i64, points: usize) -> Result<Vec<Bucket>> {
        if points == 0 {
            return Err(Error::InvalidArgument("points must be at least 1".into()));
        }
        let points = points.min(MAX_POINTS) as i64;
        let (from, to) = clamp_range(from_ms, to_ms);
        self.read(|c| {
            exists(c, node, tag)?;
            if from > to {
                return Ok(Vec::new());
            }
            // The SQLite backend's bucket grid, filled from this database's rollups.
            let plan = query::plan(from, to, points);
            let level = tier_for(query::level_ms(plan.level));
            query::buckets(plan, from, |sink| cover(c, node, tag, from, to, level, sink))
        })
    }

    /// The raw samples of `node`'s `tag`, as [`Backend::raw`] gives them.
    pub fn raw_node(&self, node: &str, tag: &str, from_ms: i64, to_ms: i64, limit: usize) -> Result<Vec<Point>> {
        let (from, to) = clamp_range(from_ms, to_ms);
        let limit = i64::try_from(limit).unwrap_or(i64::MAX);
        self.read(|c| {
            exists(c, node, tag)?;
            let rows = c.query(
                "SELECT t, v FROM alba_samples WHERE node = $1 AND tag = $2 AND t >= $3 AND t <= $4
                 ORDER BY t LIMIT $5",
                &[&node, &tag, &from, &to, &limit],
            )?;
            Ok(rows
                .iter()
                .map(|r| Point {
                    t_ms: r.get(0),
                    v: r.get(1),
                })
                .collect())
        })
    }

    /// Writes `columns` (tags of this node or of others) as CSV, as
    /// [`crate::Historian::export_csv`] does, from one snapshot of the database.
    pub fn export_csv(
        &self,
        columns: &[Column<'_>],
        from_ms: i64,
        to_ms: i64,
        step_ms: i64,
        out: &mut dyn std::io::Write,
    ) -> Result<u64> {
        let (from, to) = clamp_range(from_ms, to_ms);
        csv::rows(from, to, step_ms)?;
        let headers: Vec<String> = columns.iter().map(Column::header).collect();
        let cols: Vec<(String, String)> = columns
            .iter()
            .map(|c| (c.node.unwrap_or(&self.config.node).to_owned(), c.tag.to_owned()))
            .collect();
        let mut out = std::io::BufWriter::new(out);
        self.read(|c| {
            let mut tx = c
                .build_transaction()
                .isolation_level(postgres::IsolationLevel::RepeatableRead)
                .read_only(true)
                .start()?;
            for (node, tag) in &cols {
                exists(&mut tx, node, tag)?;
            }
            let rows = csv::write(&mut PgCsv { tx: &mut tx, cols }, &headers, from, to, step_ms, &mut out)?;
            tx.commit()?;
            Ok(rows)
        })
    }
}

/// The reading connections kept open between queries.
const READERS: usize = 4;

/// Closes connections. The synchronous client says goodbye on a runtime of its own, which
/// cannot run on a thread of an async runtime: there it is done on a thread of its own.
fn close(clients: Vec<Client>) {
    if clients.is_empty() {
        return;
    }
    if tokio::runtime::Handle::try_current().is_ok() {
        std::thread::spawn(move || drop(clients));
    } else {
        drop(clients);
    }
}

impl Drop for PgHistorian {
    fn drop(&mut self) {
        let mut clients = std::mem::take(&mut *lock(&self.readers));
        clients.extend(lock(&self.writer).client.take());
        close(clients);
    }
}

/// The columns of a CSV export, read in one transaction.
struct PgCsv<'t, 'c> {
    tx: &'t mut postgres::Transaction<'c>,
    /// Node and tag of each column.
    cols: Vec<(String, String)>,
}

impl csv::Source for PgCsv<'_, '_> {
    fn count(&mut self, c: usize, from: i64, to: i64) -> Result<u64> {
        let (node, tag) = &self.cols[c];
        let mut n = 0;
        cover(self.tx, node, tag, from, to, PG_TIERS.len(), &mut |_, a| n += a.n)?;
        Ok(n)
    }

    fn values_at(&mut self, c: usize, times: &[i64]) -> Result<Vec<Option<f64>>> {
        let (node, tag) = &self.cols[c];
        // One index probe per time, on the server: one round trip per block of rows.
        let rows = self.tx.query(
            "SELECT (SELECT v FROM alba_samples s WHERE s.node = $1 AND s.tag = $2 AND s.t <= g.t
                     ORDER BY s.t DESC LIMIT 1)
             FROM unnest($3::int8[]) WITH ORDINALITY AS g(t, i) ORDER BY g.i",
            &[node, tag, &times],
        )?;
        Ok(rows.iter().map(|r| r.get(0)).collect())
    }

    fn after(&mut self, c: usize, after: i64, to: i64, limit: i64) -> Result<Vec<(i64, f64)>> {
        let (node, tag) = &self.cols[c];
        let rows = self.tx.query(
            "SELECT t, v FROM alba_samples WHERE node = $1 AND tag = $2 AND t > $3 AND t <= $4
             ORDER BY t LIMIT $5",
            &[node, tag, &after, &to, &limit],
        )?;
        Ok(rows.iter().map(|r| (r.get(0), r.get(1))).collect())
    }
}

/// The coarsest PostgreSQL tier (1-based, 0: raw samples) whose width divides `width`.
fn tier_for(width: i64) -> usize {
    PG_TIERS.iter().rposition(|(_, w)| width % w == 0).map_or(0, |k| k + 1)
}

/// Feeds `sink` the aggregates covering exactly the samples of `node`'s `tag` in
/// `[lo, hi]`, in time order: whole rows of tier `level` inside the range, the edges from
/// finer tiers, down to raw samples (as the SQLite backend's `cover`).
fn cover(
    c: &mut impl GenericClient,
    node: &str,
    tag: &str,
    lo: i64,
    hi: i64,
    level: usize,
    sink: &mut dyn FnMut(i64, Agg),
) -> Result<()> {
    if lo > hi {
        return Ok(());
    }
    if level == 0 {
        let rows = c.query(
            "SELECT t, v FROM alba_samples WHERE node = $1 AND tag = $2 AND t >= $3 AND t <= $4 ORDER BY t",
            &[&node, &tag, &lo, &hi],
        )?;
        for r in &rows {
            let t: i64 = r.get(0);
            sink(t, Agg::one(t, r.get(1)));
        }
        return Ok(());
    }
    let (table, b) = PG_TIERS[level - 1];
    let start = ceil_to(lo, b);
    let end = floor_to(hi + 1, b);
    if start >= end {
        return cover(c, node, tag, lo, hi, level - 1, sink);
    }
    cover(c, node, tag, lo, start - 1, level - 1, sink)?;
    let rows = c.query(
        &format!(
            "SELECT t, lo, hi, first_t, first, last_t, last, n FROM {table}
             WHERE node = $1 AND tag = $2 AND t >= $3 AND t < $4 ORDER BY t"
        ),
        &[&node, &tag, &start, &end],
    )?;
    for r in &rows {
        let n: i64 = r.get(7);
        sink(
            r.get(0),
            Agg {
                min: r.get(1),
                max: r.get(2),
                first_t: r.get(3),
                first: r.get(4),
                last_t: r.get(5),
                last: r.get(6),
                n: u64::try_from(n).unwrap_or(0),
            },
        );
    }
    cover(c, node, tag, end, hi, level - 1, sink)
}

/// [`Error::UnknownTag`] when `node` has no sample of `tag`.
fn exists(c: &mut impl GenericClient, node: &str, tag: &str) -> Result<()> {
    let found = c
        .query_opt(
            // In index order: one probe (a bitmap scan, which a partition without
            // statistics yet may get, would visit every sample of the tag).
            "SELECT 1 FROM alba_samples WHERE node = $1 AND tag = $2 ORDER BY t LIMIT 1",
            &[&node, &tag],
        )?
        .is_some();
    if found {
        Ok(())
    } else {
        Err(Error::UnknownTag(tag.to_owned()))
    }
}

/// A sample to insert: node, tag, time, value.
type Row<'a> = (&'a str, &'a str, i64, f64);

/// One multi-row INSERT per [`BATCH`] samples, in one transaction; duplicates of stored
/// (node, tag, t) are ignored.
fn insert(client: &mut Client, rows: &[Row<'_>]) -> std::result::Result<(), postgres::Error> {
    let mut tx = client.transaction()?;
    // The rollups take exactly the samples inserted (a duplicate is not counted twice).
    let stmt = tx.prepare(&rollup_sql(
        "INSERT INTO alba_samples (node, tag, t, v)
         SELECT u.node, u.tag, u.t, u.v
         FROM unnest($1::text[], $2::text[], $3::int8[], $4::float8[]) AS u(node, tag, t, v)
         ON CONFLICT DO NOTHING
         RETURNING node, tag, t, v",
    ))?;
    for chunk in rows.chunks(BATCH) {
        let nodes: Vec<&str> = chunk.iter().map(|r| r.0).collect();
        let tags: Vec<&str> = chunk.iter().map(|r| r.1).collect();
        let times: Vec<i64> = chunk.iter().map(|r| r.2).collect();
        let values: Vec<f64> = chunk.iter().map(|r| r.3).collect();
        tx.execute(&stmt, &[&nodes, &tags, &times, &values])?;
    }
    tx.commit()
}

/// A buffered sample: its node (`None`: this historian's, as buffers written before node
/// ids were kept per sample), tag, time, value.
type Owned = (Option<String>, String, i64, f64);

/// The local buffer: an SQLite file of samples in arrival order, holding at most `max`.
struct Buffer {
    conn: Connection,
    max: u64,
    len: u64,
    dropped: u64,
}

impl Buffer {
    fn open(path: &Path, max: u64) -> Result<Buffer> {
        if max == 0 {
            return Err(Error::InvalidArgument(
                "the historian buffer must hold at least 1 sample".into(),
            ));
        }
        let open_err = |source| Error::Open {
            path: path.to_path_buf(),
            source,
        };
        let conn = Connection::open(path).map_err(open_err)?;
        conn.execute_batch(
            "PRAGMA journal_mode = WAL;
             PRAGMA synchronous = NORMAL;
             CREATE TABLE IF NOT EXISTS buffered (
                 seq INTEGER PRIMARY KEY AUTOINCREMENT,
                 tag TEXT NOT NULL, t INTEGER NOT NULL, v REAL NOT NULL);
             CREATE TABLE IF NOT EXISTS counters (name TEXT PRIMARY KEY, n INTEGER NOT NULL);",
        )
        .and_then(|()| {
            // Buffers of earlier versions hold this node's samples only.
            let has_node: bool = conn.query_row(
                "SELECT count(*) FROM pragma_table_info('buffered') WHERE name = 'node'",
                [],
                |r| r.get::<_, i64>(0).map(|n| n > 0),
            )?;
            if has_node {
                Ok(())
            } else {
                conn.execute_batch("ALTER TABLE buffered ADD COLUMN node TEXT")
            }
        })
        .map_err(|e| Error::NotHistory {
            path: path.to_path_buf(),
            reason: format!("not a historian buffer: {e}"),
        })?;
        let len: i64 = conn.query_row("SELECT count(*) FROM buffered", [], |r| r.get(0))?;
        let dropped: i64 = conn.query_row(
            "SELECT coalesce(max(n), 0) FROM counters WHERE name = 'dropped'",
            [],
            |r| r.get(0),
        )?;
        Ok(Buffer {
            conn,
            max,
            len: u64::try_from(len).unwrap_or(0),
            dropped: u64::try_from(dropped).unwrap_or(0),
        })
    }

    /// Appends `rows`; beyond the bound, drops the oldest and counts them.
    fn append(&mut self, rows: &[Row<'_>]) -> Result<()> {
        let tx = self.conn.transaction()?;
        {
            let mut stmt = tx.prepare_cached("INSERT INTO buffered (node, tag, t, v) VALUES (?1, ?2, ?3, ?4)")?;
            for (node, tag, t, v) in rows {
                stmt.execute(params![node, tag, t, v])?;
            }
        }
        let len = self.len + rows.len() as u64;
        let excess = len.saturating_sub(self.max);
        if excess > 0 {
            let n = i64::try_from(excess).unwrap_or(i64::MAX);
            tx.execute(
                "DELETE FROM buffered WHERE seq IN (SELECT seq FROM buffered ORDER BY seq LIMIT ?1)",
                [n],
            )?;
            let dropped = i64::try_from(self.dropped + excess).unwrap_or(i64::MAX);
            tx.execute(
                "INSERT INTO counters (name, n) VALUES ('dropped', ?1)
                 ON CONFLICT (name) DO UPDATE SET n = excluded.n",
                [dropped],
            )?;
        }
        tx.commit()?;
        self.len = len - excess;
        self.dropped += excess;
        Ok(())
    }

    /// The oldest `n` samples and the sequence number of the last one.
    fn oldest(&self, n: usize) -> Result<(i64, Vec<Owned>)> {
        let mut stmt = self
            .conn
            .prepare_cached("SELECT seq, node, tag, t, v FROM buffered ORDER BY seq LIMIT ?1")?;
        let mut rows = stmt.query([i64::try_from(n).unwrap_or(i64::MAX)])?;
        let mut out = Vec::new();
        let mut last = 0;
        while let Some(r) = rows.next()? {
            last = r.get(0)?;
            out.push((r.get(1)?, r.get(2)?, r.get(3)?, r.get(4)?));
        }
        Ok((last, out))
    }

    fn remove_through(&mut self, seq: i64) -> Result<()> {
        self.conn.execute("DELETE FROM buffered WHERE seq <= ?1", [seq])?;
        let len: i64 = self.conn.query_row("SELECT count(*) FROM buffered", [], |r| r.get(0))?;
        self.len = u64::try_from(len).unwrap_or(0);
        Ok(())
    }
}

impl Backend for PgHistorian {
    fn kind(&self) -> &'static str {
        "postgres"
    }

    fn node(&self) -> Option<&str> {
        Some(&self.config.node)
    }

    fn nodes(&self) -> Result<Vec<String>> {
        PgHistorian::nodes(self)
    }

    fn record_batch(&self, samples: &[Sample<'_>]) -> Result<usize> {
        PgHistorian::record_batch(self, samples)
    }

    fn tags(&self, node: Option<&str>) -> Result<Vec<TagRange>> {
        self.tags_of(node.unwrap_or(&self.config.node))
    }

    fn query(&self, node: Option<&str>, tag: &str, from_ms: i64, to_ms: i64, points: usize) -> Result<Vec<Bucket>> {
        self.query_node(node.unwrap_or(&self.config.node), tag, from_ms, to_ms, points)
    }

    fn raw(&self, node: Option<&str>, tag: &str, from_ms: i64, to_ms: i64, limit: usize) -> Result<Vec<Point>> {
        self.raw_node(node.unwrap_or(&self.config.node), tag, from_ms, to_ms, limit)
    }

    fn export_csv(
        &self,
        columns: &[Column<'_>],
        from_ms: i64,
        to_ms: i64,
        step_ms: i64,
        out: &mut dyn std::io::Write,
    ) -> Result<u64> {
        PgHistorian::export_csv(self, columns, from_ms, to_ms, step_ms, out)
    }

    fn flush(&self) -> Result<()> {
        self.backfill().map(|_| ())
    }
}
