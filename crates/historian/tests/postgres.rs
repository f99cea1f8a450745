//! The PostgreSQL backend against a real PostgreSQL server (Debian's `postgresql`,
//! installed by test.sh), started by these tests in a temporary directory on a loopback
//! port.

use std::path::Path;
use std::time::{Duration, Instant};

use alba_historian::{Backend, Column, Config, Error, Historian, PgConfig, PgHistorian, Sample, migrate};

use alba_testkit::pg::{PASSWORD, PgServer};

trait Historians {
    fn config(&self, node: &str, buffer: &Path) -> PgConfig;
    fn migrate(&self);
}

impl Historians for PgServer {
    fn config(&self, node: &str, buffer: &Path) -> PgConfig {
        let mut c = PgConfig::new(self.url(), node, buffer);
        c.password = Some(PgConfig::password_from_file(&self.password_file()).expect("password"));
        c.retry_interval = Duration::from_millis(100);
        c
    }

    fn migrate(&self) {
        let c = self.config("migrate", &self.dir.path().join("unused.db"));
        let report = migrate(&c).expect("migrate");
        // No TimescaleDB in the test server (Debian has none): detected, not required.
        assert!(!report.hypertable && !report.compressed, "{report:?}");
        let note = report.note.expect("why no hypertable");
        assert!(
            note.starts_with("the timescaledb extension is not installed: "),
            "{note}"
        );
        assert_eq!(
            report.partitioned,
            note.ends_with("partitioned table (30-day ranges)"),
            "{note}"
        );
    }
}

/// Sends the buffer until it is empty (the server may take a moment to accept again).
fn backfill_all(h: &PgHistorian) {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        match h.backfill() {
            Ok(0) => return,
            Ok(_) | Err(_) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(100)),
            other => panic!("back-fill did not finish: {other:?}, {:?}", h.health()),
        }
    }
}

fn samples<'a>(tag: &'a str, from: i64, n: i64, f: impl Fn(i64) -> f64) -> Vec<Sample<'a>> {
    (0..n)
        .map(|i| Sample {
            tag,
            t_ms: from + i,
            v: f(from + i),
        })
        .collect()
}

#[test]
fn migrate_is_idempotent_and_two_nodes_write_concurrently() {
    let Some(pg) = PgServer::start() else { return };
    pg.migrate();
    pg.migrate();
    let work = tempfile::tempdir().expect("tempdir");
    let writers: Vec<_> = ["line1", "line2"]
        .into_iter()
        .enumerate()
        .map(|(k, node)| {
            let h = PgHistorian::open(pg.config(node, &work.path().join(format!("{node}.db")))).expect("open");
            std::thread::spawn(move || {
                for batch in 0..40 {
                    let mut s = samples("Level", batch * 250, 250, |t| (t as f64) + k as f64 * 0.5);
                    // A tag of the same name on both nodes, and one of each node's own.
                    s.extend(samples(if k == 0 { "Pump" } else { "Valve" }, batch * 250, 250, |t| {
                        -(t as f64)
                    }));
                    assert_eq!(h.record_batch(&s).expect("record"), 500);
                }
                let health = h.health();
                assert!(health.connected && health.buffered == 0, "{health:?}");
                h
            })
        })
        .collect();
    let writers: Vec<PgHistorian> = writers.into_iter().map(|w| w.join().expect("writer")).collect();
    assert_eq!(writers[0].nodes().expect("nodes"), ["line1", "line2"]);
    for (k, h) in writers.iter().enumerate() {
        let names: Vec<String> = h.tags(None).expect("tags").into_iter().map(|t| t.name).collect();
        assert_eq!(names, ["Level", if k == 0 { "Pump" } else { "Valve" }]);
        let raw = h.raw(None, "Level", 0, 20_000, 100_000).expect("raw");
        assert_eq!(raw.len(), 10_000);
        assert!(raw.iter().all(|p| p.v == p.t_ms as f64 + k as f64 * 0.5));
        let buckets = h.query(None, "Level", 0, 9_999, 10).expect("query");
        assert_eq!(buckets.iter().map(|b| b.count).sum::<u64>(), 10_000);
    }
    // The other node's tags, read from one runtime (what the studio's trends use).
    let line1: &dyn Backend = &writers[0];
    assert_eq!(line1.node(), Some("line1"));
    assert_eq!(line1.nodes().expect("nodes"), ["line1", "line2"]);
    let names: Vec<String> = line1
        .tags(Some("line2"))
        .expect("tags")
        .into_iter()
        .map(|t| t.name)
        .collect();
    assert_eq!(names, ["Level", "Valve"]);
    assert!(line1.tags(Some("nowhere")).expect("tags").is_empty());
    let other = line1.raw(Some("line2"), "Valve", 0, 5, 10).expect("raw of line2");
    assert_eq!(other.len(), 6);
    let buckets = line1
        .query(Some("line2"), "Level", 0, 9_999, 4)
        .expect("query of line2");
    assert_eq!(buckets.iter().map(|b| b.count).sum::<u64>(), 10_000);
    assert_eq!(buckets[0].first, 0.5);
    let mut csv = Vec::new();
    let columns = [
        Column::own("Level"),
        Column {
            node: Some("line2"),
            tag: "Level",
        },
    ];
    assert_eq!(line1.export_csv(&columns, 0, 3, 1, &mut csv).expect("csv"), 4);
    assert_eq!(
        String::from_utf8_lossy(&csv),
        "Time (ms),Level,Level@line2\n0,0,0.5\n1,1,1.5\n2,2,2.5\n3,3,3.5\n"
    );
    assert!(matches!(writers[0].query(None, "Valve", 0, 10, 5), Err(Error::UnknownTag(t)) if t == "Valve"));
    // A new database is partitioned by time: one partition per 30 days that has samples.
    let far = [-1, 90 * 86_400_000, -400 * 86_400_000].map(|t| Sample {
        tag: "Far",
        t_ms: t,
        v: 1.0,
    });
    assert_eq!(writers[0].record_batch(&far).expect("record"), 3);
    assert_eq!(
        writers[0].raw(None, "Far", i64::MIN, i64::MAX, 10).expect("raw").len(),
        3
    );
    let mut client = pg
        .config("x", &work.path().join("x.db"))
        .connection()
        .expect("settings")
        .connect(postgres::NoTls)
        .expect("connect");
    let parts: Vec<String> = client
        .query(
            "SELECT c.relname::text FROM pg_inherits i JOIN pg_class c ON c.oid = i.inhrelid
             WHERE i.inhparent = 'alba_samples'::regclass ORDER BY 1",
            &[],
        )
        .expect("partitions")
        .iter()
        .map(|r| r.get(0))
        .collect();
    assert_eq!(
        parts,
        [
            "alba_samples_p0",
            "alba_samples_p3",
            "alba_samples_pm1",
            "alba_samples_pm14"
        ]
    );
}

#[test]
fn database_stopped_loses_no_sample() {
    let Some(pg) = PgServer::start() else { return };
    pg.migrate();
    let work = tempfile::tempdir().expect("tempdir");
    let h = PgHistorian::open(pg.config("plc", &work.path().join("buffer.db"))).expect("open");
    let mut t = 0;
    let mut write = |h: &PgHistorian, batches: i64| {
        for _ in 0..batches {
            let s = samples("Flow", t, 100, |t| (t % 977) as f64);
            assert_eq!(h.record_batch(&s).expect("record"), 100);
            t += 100;
        }
    };
    write(&h, 10);
    assert!(h.health().connected);
    pg.stop();
    write(&h, 30);
    let health = h.health();
    assert!(!health.connected, "{health:?}");
    assert_eq!(health.buffered, 3_000);
    assert_eq!(health.dropped, 0);
    let err = health.last_error.expect("an error while down");
    assert!(!err.contains(PASSWORD), "the password leaked into `{err}`");
    // Back-fill is tried, and fails, while down: nothing is lost.
    assert_eq!(h.backfill().expect("backfill while down"), 3_000);
    pg.start_again();
    backfill_all(&h);
    write(&h, 10);
    let health = h.health();
    assert!(
        health.connected && health.buffered == 0 && health.dropped == 0,
        "{health:?}"
    );
    let raw = h.raw(None, "Flow", 0, i64::MAX, usize::MAX).expect("raw");
    assert_eq!(raw.len(), 5_000);
    for (i, p) in raw.iter().enumerate() {
        assert_eq!((p.t_ms, p.v), (i as i64, (i as i64 % 977) as f64));
    }
}

#[test]
fn full_buffer_drops_the_oldest_and_counts_them() {
    let Some(pg) = PgServer::start() else { return };
    pg.migrate();
    let work = tempfile::tempdir().expect("tempdir");
    let mut config = pg.config("plc", &work.path().join("buffer.db"));
    config.buffer_max_samples = 250;
    let h = PgHistorian::open(config.clone()).expect("open");
    pg.stop();
    for k in 0..4 {
        h.record_batch(&samples("T", k * 100, 100, |t| t as f64))
            .expect("record");
    }
    let health = h.health();
    assert_eq!((health.buffered, health.dropped), (250, 150));
    // The buffer and its counter survive a restart of the runtime.
    drop(h);
    let h = PgHistorian::open(config).expect("reopen");
    assert_eq!((h.health().buffered, h.health().dropped), (250, 150));
    pg.start_again();
    backfill_all(&h);
    let raw = h.raw(None, "T", 0, 1_000, 1_000).expect("raw");
    assert_eq!(
        raw.iter().map(|p| p.t_ms).collect::<Vec<_>>(),
        (150..400).collect::<Vec<_>>()
    );
}

#[test]
fn samples_of_many_nodes_and_buffers_of_earlier_versions_are_back_filled() {
    let Some(pg) = PgServer::start() else { return };
    pg.migrate();
    let work = tempfile::tempdir().expect("tempdir");
    let path = work.path().join("buffer.db");
    // A buffer written before samples carried their node: this historian's samples.
    {
        let c = rusqlite::Connection::open(&path).expect("old buffer");
        c.execute_batch(
            "CREATE TABLE buffered (seq INTEGER PRIMARY KEY AUTOINCREMENT,
                                    tag TEXT NOT NULL, t INTEGER NOT NULL, v REAL NOT NULL);
             INSERT INTO buffered (tag, t, v) VALUES ('Old', 1, 1.5), ('Old', 2, 2.5);",
        )
        .expect("old rows");
    }
    pg.stop();
    let h = PgHistorian::open(pg.config("service", &path)).expect("open");
    assert_eq!(h.health().buffered, 2);
    for (node, v) in [("line-1", 1.0), ("Plant/edge/PLC", 2.0)] {
        assert_eq!(h.record_for(node, &samples("T", 10, 5, |_| v)).expect("record"), 5);
    }
    assert!(h.record_for("", &samples("T", 0, 1, |_| 0.0)).is_err());
    assert_eq!(h.health().buffered, 12);
    pg.start_again();
    backfill_all(&h);
    assert_eq!(h.nodes().expect("nodes"), ["Plant/edge/PLC", "line-1", "service"]);
    let old = h.raw_node("service", "Old", 0, 10, 10).expect("raw");
    assert_eq!(
        old.iter().map(|p| (p.t_ms, p.v)).collect::<Vec<_>>(),
        [(1, 1.5), (2, 2.5)]
    );
    for (node, v) in [("line-1", 1.0), ("Plant/edge/PLC", 2.0)] {
        let raw = h.raw_node(node, "T", 0, 100, 100).expect("raw");
        assert_eq!(raw.len(), 5);
        assert!(raw.iter().all(|p| p.v == v), "{node}: {raw:?}");
    }
    // Connected: straight into the table, under each node.
    assert_eq!(
        h.record_for("line-1", &samples("T", 20, 3, |_| 9.0)).expect("record"),
        3
    );
    assert_eq!(h.raw_node("line-1", "T", 20, 30, 10).expect("raw").len(), 3);
}

#[test]
fn wrong_password_is_reported_without_echoing_it() {
    let Some(pg) = PgServer::start() else { return };
    pg.migrate();
    let work = tempfile::tempdir().expect("tempdir");
    let mut config = pg.config("plc", &work.path().join("buffer.db"));
    let wrong = "not-the-password-1234";
    config.password = Some(wrong.into());
    let h = PgHistorian::open(config).expect("open (the database may be down)");
    h.record_batch(&samples("T", 0, 10, |t| t as f64)).expect("buffered");
    let health = h.health();
    assert_eq!(health.buffered, 10);
    let err = health.last_error.expect("an authentication error");
    assert!(err.contains("password"), "{err}");
    assert!(!err.contains(wrong) && !err.contains(PASSWORD), "{err}");
    // A missing or empty password file is a precise error.
    let empty = work.path().join("empty");
    std::fs::write(&empty, "").expect("write");
    let e = PgConfig::password_from_file(&empty).expect_err("empty file");
    assert!(e.to_string().contains("is empty"), "{e}");
}

/// A deterministic, irregular signal: several tags, uneven gaps, repeated values.
fn signal(n: usize) -> Vec<(String, i64, f64)> {
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut out = Vec::with_capacity(n);
    let mut t = [1_700_000_000_000i64; 3];
    for _ in 0..n {
        let k = (next() % 3) as usize;
        t[k] += 1 + (next() % 2_000) as i64;
        let v = ((next() % 20_001) as f64 - 10_000.0) / 8.0;
        out.push((["Temp", "Level", "Speed"][k].to_owned(), t[k], v));
    }
    out
}

#[test]
fn downsampled_queries_equal_the_sqlite_backend() {
    let Some(pg) = PgServer::start() else { return };
    pg.migrate();
    let work = tempfile::tempdir().expect("tempdir");
    let sqlite = Historian::open(work.path().join("history.db"), Config::default()).expect("sqlite");
    let postgres = PgHistorian::open(pg.config("plc", &work.path().join("buffer.db"))).expect("postgres");
    let data = signal(60_000);
    let backends: [&dyn Backend; 2] = [&sqlite, &postgres];
    // Out of order (later chunks first, so rollup buckets merge late samples), and one
    // chunk twice (its duplicates ignored, not counted again).
    let chunks: Vec<&[(String, i64, f64)]> = data.chunks(5_000).collect();
    let order = (0..chunks.len())
        .filter(|k| k % 2 == 1)
        .chain((0..chunks.len()).filter(|k| k % 2 == 0))
        .chain([3]);
    for chunk in order.map(|k| chunks[k]) {
        let s: Vec<Sample<'_>> = chunk
            .iter()
            .map(|(tag, t, v)| Sample { tag, t_ms: *t, v: *v })
            .collect();
        for b in backends {
            b.record_batch(&s).expect("record");
        }
    }
    for b in backends {
        b.flush().expect("flush");
    }
    assert_eq!(
        Backend::tags(&sqlite, None).expect("tags"),
        Backend::tags(&postgres, None).expect("tags")
    );
    let start = 1_700_000_000_000i64;
    let end = data.iter().map(|d| d.1).max().unwrap_or(start);
    let mut compared = 0;
    for tag in ["Temp", "Level", "Speed"] {
        for (from, to) in [
            (start, end),
            (start - 5_000, end + 5_000),
            (start + 123_457, start + 7_654_321),
            (start + 3_600_000 - 1, start + 3 * 3_600_000 + 1),
            (start + 1_000, start + 1_200),
        ] {
            for points in [1, 7, 100, 1_000, 4_000] {
                let a = Backend::query(&sqlite, None, tag, from, to, points).expect("sqlite query");
                let b = Backend::query(&postgres, None, tag, from, to, points).expect("postgres query");
                assert_eq!(a, b, "{tag} [{from}, {to}] in {points} points");
                compared += a.len();
            }
        }
        let a = Backend::raw(&sqlite, None, tag, start, start + 2_000_000, 500).expect("raw");
        assert_eq!(
            a,
            Backend::raw(&postgres, None, tag, start, start + 2_000_000, 500).expect("raw")
        );
    }
    assert!(compared > 10_000, "the comparison covered {compared} buckets");
    // CSV exports: streamed columns (few samples per row) and looked-up ones (many).
    let columns = [Column::own("Temp"), Column::own("Level"), Column::own("Speed")];
    for (from, to, step) in [
        (start - 10_000, start + 3_000_000, 1_000),
        (start, end, 600_000),
        (start + 77, start + 5_000_077, 250_000),
    ] {
        let mut a = Vec::new();
        let mut b = Vec::new();
        let rows = Backend::export_csv(&sqlite, &columns, from, to, step, &mut a).expect("sqlite csv");
        assert_eq!(
            Backend::export_csv(&postgres, &columns, from, to, step, &mut b).expect("postgres csv"),
            rows
        );
        assert_eq!(
            String::from_utf8_lossy(&a),
            String::from_utf8_lossy(&b),
            "[{from}, {to}] by {step}"
        );
        assert!(rows > 20);
    }
    let other = [Column {
        node: Some("elsewhere"),
        tag: "Temp",
    }];
    assert!(matches!(
        Backend::export_csv(&sqlite, &other, 0, 10, 1, &mut Vec::new()),
        Err(Error::UnknownNode(n)) if n == "elsewhere"
    ));
    assert!(matches!(
        Backend::export_csv(&postgres, &other, 0, 10, 1, &mut Vec::new()),
        Err(Error::UnknownTag(_))
    ));
    for b in backends {
        assert!(matches!(b.query(None, "Nope", 0, 1, 1), Err(Error::UnknownTag(_))));
        assert!(matches!(b.query(None, "Temp", 0, 1, 0), Err(Error::InvalidArgument(_))));
    }
}

#[test]
fn a_version_1_schema_gets_its_rollups() {
    let Some(pg) = PgServer::start() else { return };
    let c = pg.config("plc", &pg.dir.path().join("unused.db"));
    let mut client = c
        .connection()
        .expect("settings")
        .connect(postgres::NoTls)
        .expect("connect");
    client
        .batch_execute(
            "CREATE TABLE alba_schema (version integer NOT NULL);
             INSERT INTO alba_schema VALUES (1);
             CREATE TABLE alba_samples (node text NOT NULL, tag text NOT NULL, t bigint NOT NULL,
                                        v double precision NOT NULL, PRIMARY KEY (node, tag, t));
             INSERT INTO alba_samples
                 SELECT 'plc', 'Wave', t, sin(t / 7000.0) FROM generate_series(-3600000, 7200000, 1000) t;",
        )
        .expect("a version 1 database");
    pg.migrate();
    let version: i32 = client
        .query_one("SELECT version FROM alba_schema", &[])
        .expect("version")
        .get(0);
    assert_eq!(version, 2);
    let work = tempfile::tempdir().expect("tempdir");
    let sqlite = Historian::open(work.path().join("h.db"), Config::default()).expect("sqlite");
    let wave: Vec<Sample<'_>> = (-3_600..=7_200)
        .map(|k| Sample {
            tag: "Wave",
            t_ms: k * 1_000,
            v: (k as f64 * 1_000.0 / 7_000.0).sin(),
        })
        .collect();
    sqlite.record_batch(&wave).expect("record");
    let h = PgHistorian::open(pg.config("plc", &work.path().join("b.db"))).expect("open");
    for (from, to, points) in [
        (-3_600_000, 7_200_000, 300),
        (-1_000_001, 5_000_003, 17),
        (0, 7_200_000, 1),
    ] {
        let a = sqlite.query("Wave", from, to, points).expect("sqlite");
        let b = h.query_node("plc", "Wave", from, to, points).expect("postgres");
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            // sin() of SQL and of Rust may differ in the last bit: compare the rest exactly.
            assert_eq!((x.t_ms, x.count), (y.t_ms, y.count));
            for (p, q) in [(x.min, y.min), (x.max, y.max), (x.first, y.first), (x.last, y.last)] {
                assert!((p - q).abs() < 1e-12, "{x:?} {y:?}");
            }
        }
    }
}

#[test]
fn tls_with_the_servers_ca_only() {
    let Some(pg) = PgServer::start() else { return };
    let ca = pg.enable_tls();
    let work = tempfile::tempdir().expect("tempdir");
    let mut c = pg.config("plc", &work.path().join("buffer.db"));
    c.ca_file = Some(ca);
    migrate(&c).expect("migrate over TLS");
    let h = PgHistorian::open(c.clone()).expect("open");
    assert_eq!(
        h.record_batch(&samples("T", 0, 100, |t| t as f64)).expect("record"),
        100
    );
    assert!(h.health().connected, "{:?}", h.health());
    assert_eq!(h.raw(None, "T", 0, 1_000, 1_000).expect("raw over TLS").len(), 100);
    // Without TLS the server refuses (hostnossl … reject): the samples wait in the buffer.
    let plain = PgHistorian::open(pg.config("plain", &work.path().join("plain.db"))).expect("open");
    plain.record_batch(&samples("T", 0, 5, |t| t as f64)).expect("buffered");
    let err = plain.health().last_error.expect("refused");
    assert!(err.contains("no encryption"), "{err}");
    // A certificate from another CA is refused by the client.
    let other = work.path().join("other-ca.pem");
    let key = rcgen::KeyPair::generate().expect("key");
    let mut params = rcgen::CertificateParams::new(Vec::<String>::new()).expect("params");
    params.is_ca = rcgen::IsCa::Ca(rcgen::BasicConstraints::Unconstrained);
    std::fs::write(&other, params.self_signed(&key).expect("CA").pem()).expect("other CA");
    let mut wrong = c.clone();
    wrong.ca_file = Some(other);
    wrong.buffer_path = work.path().join("wrong.db");
    let h = PgHistorian::open(wrong).expect("open");
    h.record_batch(&samples("T", 0, 5, |t| t as f64)).expect("buffered");
    let err = h.health().last_error.expect("refused");
    assert!(err.to_lowercase().contains("certificate"), "{err}");
    // sslmode=require without a CA file: a precise error, at once.
    let mut require = pg.config("plc", &work.path().join("r.db"));
    require.url.push_str(" sslmode=require");
    let e = PgHistorian::open(require).expect_err("needs a CA");
    assert!(e.to_string().contains("sslmode=require needs the CA file"), "{e}");
    let missing = PgConfig {
        ca_file: Some(work.path().join("nope.pem")),
        ..c
    };
    assert!(PgHistorian::open(missing).is_err());
}
