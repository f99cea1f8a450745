//! PostgreSQL historian benchmark: ingest from 10 concurrent writers, and downsampled
//! queries over a 10-million-sample tag, against a real PostgreSQL started in a temporary
//! directory (alba-testkit, Debian's `postgresql`). Prints numbers; asserts nothing but
//! that answers are complete.
//!
//!     cargo bench -p alba-historian --bench postgres              # 10 M samples per phase
//!     cargo bench -p alba-historian --bench postgres -- --quick   # 1 M
//!
//! Phase 1: 10 writers, each a node of its own (`node0`…`node9`), each one tag at 10 Hz
//! in batches of 10 000 samples (what `alba run` sends every 250 ms from 4 000 changes a
//! second). Phase 2: 10 writers fill one tag of one node, each a tenth of its time span,
//! so that the query has 10 M samples of one tag.

use std::time::{Duration, Instant};

use alba_historian::{PgConfig, PgHistorian, Sample, migrate};
use alba_testkit::pg::PgServer;

const RUNS: usize = 9;
const WRITERS: i64 = 10;
const PERIOD_MS: i64 = 100;

fn median(mut d: Vec<Duration>) -> Duration {
    d.sort();
    d[d.len() / 2]
}

fn config(pg: &PgServer, node: &str) -> PgConfig {
    let mut c = PgConfig::new(pg.url(), node, pg.dir.path().join(format!("buffer-{node}.db")));
    c.password = Some(PgConfig::password_from_file(&pg.password_file()).expect("password"));
    c
}

/// `WRITERS` threads, writer `k` under `node(k)` the samples `k * per ..` of tag `Level`.
fn ingest(pg: &PgServer, total: i64, node: impl Fn(i64) -> String) -> f64 {
    let per = total / WRITERS;
    let writers: Vec<PgHistorian> = (0..WRITERS)
        .map(|k| PgHistorian::open(config(pg, &node(k))).expect("open"))
        .collect();
    let start = Instant::now();
    std::thread::scope(|s| {
        for (k, h) in writers.iter().enumerate() {
            s.spawn(move || {
                let first = k as i64 * per;
                let mut i = first;
                while i < first + per {
                    let n = (first + per - i).min(10_000);
                    let batch: Vec<Sample<'_>> = (i..i + n)
                        .map(|j| Sample {
                            tag: "Level",
                            t_ms: j * PERIOD_MS,
                            v: ((j as f64) / 3_000.0).sin() * 50.0 + (j % 7) as f64,
                        })
                        .collect();
                    h.record_batch(&batch).expect("record");
                    i += n;
                }
                assert_eq!(h.health().buffered, 0, "everything reached the database");
            });
        }
    });
    let secs = start.elapsed().as_secs_f64();
    total as f64 / secs
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let total: i64 = if quick { 1_000_000 } else { 10_000_000 };
    let Some(pg) = PgServer::start() else {
        eprintln!("PostgreSQL is not installed: nothing measured");
        return;
    };
    let report = migrate(&config(&pg, "migrate")).expect("migrate");
    println!(
        "alba-historian PostgreSQL benchmark ({total} samples per phase; hypertable: {})",
        report.hypertable
    );

    let rate = ingest(&pg, total, |k| format!("node{k}"));
    println!("ingest, {WRITERS} writers (nodes), {total} samples: {rate:.0} samples/s");
    let rate = ingest(&pg, total, |_| "long".to_owned());
    println!("ingest, {WRITERS} writers into one tag, {total} samples: {rate:.0} samples/s");

    let mut client = config(&pg, "long")
        .connection()
        .expect("settings")
        .connect(postgres::NoTls)
        .expect("connect");
    let h = PgHistorian::open(config(&pg, "long")).expect("open");
    let last = total * PERIOD_MS - 1;
    let hour = 3_600_000;
    for (what, from, to) in [
        ("full range", 0, last),
        ("1 week", last / 4, last / 4 + 7 * 24 * hour - 1),
        ("1 day", last / 2, last / 2 + 24 * hour - 1),
        ("1 hour", last / 2, last / 2 + hour - 1),
        ("1 minute", last / 2, last / 2 + 60_000 - 1),
    ] {
        let to = to.min(last);
        let _ = h.query_node("long", "Level", from, to, 1_000).expect("warm-up");
        let mut times = Vec::with_capacity(RUNS);
        let mut buckets = Vec::new();
        for _ in 0..RUNS {
            let start = Instant::now();
            buckets = h.query_node("long", "Level", from, to, 1_000).expect("query");
            times.push(start.elapsed());
        }
        let samples: u64 = buckets.iter().map(|b| b.count).sum();
        let expected = to / PERIOD_MS - (from + PERIOD_MS - 1) / PERIOD_MS + 1;
        assert_eq!(samples as i64, expected, "{what}: every sample counted");
        println!(
            "query, {what} ({samples} samples -> {} buckets): {:.2} ms",
            buckets.len(),
            median(times).as_secs_f64() * 1e3
        );
    }
    // For comparison: the aggregation over the raw samples that the rollups replace.
    let start = Instant::now();
    let rows = client
        .query(
            "SELECT t / 1000000, min(v), max(v), count(*) FROM alba_samples
             WHERE node = 'long' AND tag = 'Level' GROUP BY 1",
            &[],
        )
        .expect("group by");
    println!(
        "for comparison: SQL GROUP BY min/max over the raw samples, full range ({} groups): {:.0} ms",
        rows.len(),
        start.elapsed().as_secs_f64() * 1e3
    );
    let size: i64 = client
        .query_one(
            // Every table: the samples' partitions (or the one table) and the rollups.
            "SELECT sum(pg_total_relation_size(oid))::bigint FROM pg_class
             WHERE relkind = 'r' AND relname LIKE 'alba\\_%'",
            &[],
        )
        .expect("size")
        .get(0);
    println!(
        "database size: {} MB = {:.1} B/sample",
        size >> 20,
        size as f64 / (2 * total) as f64
    );
}
