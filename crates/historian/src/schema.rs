//! The database layout: tables, rollup tiers, connection settings and the checks that
//! refuse files that are not history databases.

use std::path::Path;
use std::time::Duration;

use rusqlite::{Connection, ErrorCode, OpenFlags};

use crate::error::{Error, Result};

/// `PRAGMA application_id` of a history database: "AlbH".
pub(crate) const APPLICATION_ID: i64 = 0x416C_6248;
/// `PRAGMA user_version`: the schema version this code writes and reads.
pub(crate) const SCHEMA_VERSION: i64 = 1;

/// One rollup tier: a table of per-bucket aggregates of fixed width.
#[derive(Debug)]
pub(crate) struct Tier {
    pub table: &'static str,
    pub ms: i64,
}

/// The rollup tiers, finest first. Each width divides the next one, so a bucket of a
/// coarse tier is exactly a run of whole buckets of every finer tier (the query relies on
/// it), and the coarsest width divides every retention cut-off.
pub(crate) const TIERS: [Tier; 5] = [
    Tier {
        table: "rollup_1s",
        ms: 1_000,
    },
    Tier {
        table: "rollup_10s",
        ms: 10_000,
    },
    Tier {
        table: "rollup_1m",
        ms: 60_000,
    },
    Tier {
        table: "rollup_10m",
        ms: 600_000,
    },
    Tier {
        table: "rollup_1h",
        ms: 3_600_000,
    },
];

/// The width of the coarsest tier: retention cuts and deletes in whole multiples of it.
pub(crate) const COARSEST_MS: i64 = TIERS[TIERS.len() - 1].ms;

const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

fn schema_sql() -> String {
    let mut sql = String::from(
        "CREATE TABLE tags(id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE);
         CREATE TABLE samples(tag INTEGER NOT NULL, t INTEGER NOT NULL, v REAL NOT NULL,
                              PRIMARY KEY(tag, t)) WITHOUT ROWID;\n",
    );
    for tier in &TIERS {
        sql.push_str(&format!(
            "CREATE TABLE {}(tag INTEGER NOT NULL, t INTEGER NOT NULL,
                 min REAL NOT NULL, max REAL NOT NULL,
                 first_t INTEGER NOT NULL, first REAL NOT NULL,
                 last_t INTEGER NOT NULL, last REAL NOT NULL,
                 n INTEGER NOT NULL,
                 PRIMARY KEY(tag, t)) WITHOUT ROWID;\n",
            tier.table
        ));
    }
    // `rolled_up_to`: the rollup tiers hold exactly the samples older than it (see
    // write.rs); `generation`: incremented by every write transaction.
    sql.push_str(&format!(
        "CREATE TABLE meta(key TEXT PRIMARY KEY, value INTEGER NOT NULL) WITHOUT ROWID;
         INSERT INTO meta(key, value) VALUES('rolled_up_to', {}), ('generation', 0);\n",
        -crate::MAX_TIME_MS
    ));
    sql
}

/// Maps an SQLite error met while opening to the error the caller should see: a file that
/// is not SQLite, or is damaged, is "not a usable history database".
fn open_error(path: &Path, e: rusqlite::Error) -> Error {
    match e.sqlite_error_code() {
        Some(ErrorCode::NotADatabase) => Error::NotHistory {
            path: path.to_path_buf(),
            reason: "the file is not an SQLite database (or its header is damaged)".into(),
        },
        Some(ErrorCode::DatabaseCorrupt) => Error::NotHistory {
            path: path.to_path_buf(),
            reason: format!("the database is corrupt ({e})"),
        },
        _ => Error::Open {
            path: path.to_path_buf(),
            source: e,
        },
    }
}

/// Opens (creating it if needed) the single writing connection: WAL journal, `synchronous
/// = NORMAL`, schema created on an empty file, identity and version checked otherwise.
pub(crate) fn open_writer(path: &Path) -> Result<Connection> {
    let conn = Connection::open(path).map_err(|e| open_error(path, e))?;
    setup(&conn, 32 * 1024, true).map_err(|e| open_error(path, e))?;
    let kind = alba_sqlite::Kind {
        application_id: APPLICATION_ID,
        version: SCHEMA_VERSION,
        create: &schema_sql(),
    };
    let found = alba_sqlite::identify(&conn, &kind).map_err(|r| match r {
        alba_sqlite::Refusal::Sqlite(e) => open_error(path, e),
        alba_sqlite::Refusal::Not(reason) => Error::NotHistory {
            path: path.to_path_buf(),
            reason,
        },
    })?;
    if found == alba_sqlite::Found::Created {
        return Ok(conn);
    }
    // A damaged schema shows when the tables are compiled into statements.
    let mut tables = vec!["meta", "tags", "samples"];
    tables.extend(TIERS.iter().map(|t| t.table));
    for table in tables {
        conn.prepare(&format!("SELECT * FROM {table} LIMIT 0"))
            .map_err(|e| match open_error(path, e) {
                Error::Open { source, .. } => Error::NotHistory {
                    path: path.to_path_buf(),
                    reason: format!("table `{table}` is missing or damaged ({source})"),
                },
                other => other,
            })?;
    }
    let meta: i64 = conn
        .query_row(
            "SELECT count(*) FROM meta WHERE key IN ('rolled_up_to', 'generation')",
            [],
            |r| r.get(0),
        )
        .map_err(|e| open_error(path, e))?;
    if meta != 2 {
        return Err(Error::NotHistory {
            path: path.to_path_buf(),
            reason: "the `meta` table is incomplete".into(),
        });
    }
    Ok(conn)
}

/// Opens a reading connection on a database the writer has already opened (and so set to
/// WAL): it reads a consistent snapshot while the writer goes on committing.
pub(crate) fn open_reader(path: &Path) -> Result<Connection> {
    let flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX | OpenFlags::SQLITE_OPEN_URI;
    let conn = Connection::open_with_flags(path, flags).map_err(|e| open_error(path, e))?;
    setup(&conn, 16 * 1024, false).map_err(|e| open_error(path, e))?;
    conn.execute_batch("PRAGMA query_only = ON;")?;
    Ok(conn)
}

fn setup(conn: &Connection, cache_kib: i64, writer: bool) -> rusqlite::Result<()> {
    conn.busy_timeout(BUSY_TIMEOUT)?;
    conn.set_prepared_statement_cache_capacity(32);
    if writer {
        // Answers with a row; persistent in the file once set, so readers need not.
        let _mode: String = conn.query_row("PRAGMA journal_mode = WAL", [], |r| r.get(0))?;
    }
    conn.execute_batch(&format!(
        "PRAGMA synchronous = NORMAL; PRAGMA temp_store = MEMORY; PRAGMA cache_size = -{cache_kib};"
    ))
}
