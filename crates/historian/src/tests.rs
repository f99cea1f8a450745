//! Unit tests of the historian as a whole (the modules test their own helpers).

use std::collections::BTreeMap;
use std::path::Path;

use proptest::prelude::*;
use proptest::test_runner::{Config as PropConfig, RngAlgorithm, TestRng, TestRunner};

use super::*;
use crate::query::plan;
use crate::schema::TIERS;

fn temp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

fn open(dir: &Path) -> Historian {
    Historian::open(dir.join("history.db"), Config::default()).expect("open history")
}

fn count_rows(path: &Path, table: &str) -> i64 {
    let c = Connection::open(path).expect("open for inspection");
    c.query_row(&format!("SELECT count(*) FROM {table}"), [], |r| r.get(0))
        .expect("count rows")
}

/// Brute-force downsampling of `samples` over `[from, to]` on the grid of `plan`.
fn brute(samples: &BTreeMap<i64, f64>, from: i64, to: i64, points: i64) -> Vec<Bucket> {
    if from > to {
        return Vec::new();
    }
    let p = plan(from, to, points);
    let mut groups: BTreeMap<i64, Vec<(i64, f64)>> = BTreeMap::new();
    for (&t, &v) in samples.range(from..=to) {
        groups
            .entry((t - p.origin).div_euclid(p.width))
            .or_default()
            .push((t, v));
    }
    groups
        .into_iter()
        .map(|(i, g)| Bucket {
            t_ms: (p.origin + i * p.width).max(from),
            min: g.iter().map(|s| s.1).fold(f64::INFINITY, f64::min),
            max: g.iter().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max),
            first: g[0].1,
            last: g[g.len() - 1].1,
            count: g.len() as u64,
        })
        .collect()
}

#[test]
fn historian_is_shareable_between_threads() {
    fn shareable<T: Send + Sync + Clone>() {}
    shareable::<Historian>();
    fn sendable<T: Send>() {}
    sendable::<Recorder>();
}

#[test]
fn round_trip_record_raw_and_tags() {
    let dir = temp();
    let h = open(dir.path());
    assert_eq!(h.record(1000, &[("A", 1.5), ("B", 1.0)]).expect("record"), 2);
    assert_eq!(h.record(1100, &[("A", -2.0)]).expect("record"), 1);
    assert_eq!(
        h.record(1200, &[("A", 9007199254740992.0), ("B", 0.0)])
            .expect("record"),
        2
    );
    let a = h.raw("A", i64::MIN, i64::MAX, usize::MAX).expect("raw");
    assert_eq!(
        a,
        vec![
            Point { t_ms: 1000, v: 1.5 },
            Point { t_ms: 1100, v: -2.0 },
            Point {
                t_ms: 1200,
                v: 9007199254740992.0
            },
        ]
    );
    assert_eq!(
        h.raw("A", 1050, 1200, 1).expect("raw"),
        vec![Point { t_ms: 1100, v: -2.0 }]
    );
    assert_eq!(
        h.tags().expect("tags"),
        vec![
            TagRange {
                name: "A".into(),
                first_ms: 1000,
                last_ms: 1200
            },
            TagRange {
                name: "B".into(),
                first_ms: 1000,
                last_ms: 1200
            },
        ]
    );
    // Reopened, the data is still there.
    drop(h);
    let h = open(dir.path());
    assert_eq!(h.raw("B", 0, 5000, 10).expect("raw").len(), 2);
    let q = h.query("B", 0, 5000, 1).expect("query");
    assert_eq!(
        q,
        vec![Bucket {
            t_ms: 0,
            min: 0.0,
            max: 1.0,
            first: 1.0,
            last: 0.0,
            count: 2
        }]
    );
}

#[test]
fn nan_is_skipped_and_duplicate_times_keep_the_first_value() {
    let dir = temp();
    let h = open(dir.path());
    assert_eq!(h.record(10, &[("A", f64::NAN), ("B", 1.0)]).expect("record"), 1);
    assert_eq!(h.record(10, &[("B", 5.0)]).expect("record"), 0);
    assert_eq!(
        h.record_batch(&[
            Sample {
                tag: "B",
                t_ms: 20,
                v: f64::INFINITY
            },
            Sample {
                tag: "B",
                t_ms: 20,
                v: 7.0
            },
        ])
        .expect("record"),
        1
    );
    assert_eq!(
        h.raw("B", 0, 100, 10).expect("raw"),
        vec![
            Point { t_ms: 10, v: 1.0 },
            Point {
                t_ms: 20,
                v: f64::INFINITY
            }
        ]
    );
    let q = h.query("B", 0, 100_000, 1).expect("query");
    assert_eq!(q.len(), 1);
    assert_eq!((q[0].min, q[0].max, q[0].count), (1.0, f64::INFINITY, 2));
    // "A" only ever had NaN: it was never recorded.
    assert_eq!(h.tags().expect("tags").len(), 1);
    assert!(matches!(h.query("A", 0, 100, 10), Err(Error::UnknownTag(_))));
}

#[test]
fn invalid_arguments_are_errors() {
    let dir = temp();
    let h = open(dir.path());
    h.record(0, &[("A", 1.0)]).expect("record");
    assert!(matches!(h.query("A", 0, 10, 0), Err(Error::InvalidArgument(_))));
    assert!(matches!(
        h.record(MAX_TIME_MS + 1, &[("A", 1.0)]),
        Err(Error::InvalidArgument(_))
    ));
    assert!(matches!(
        h.record(5, &[("A", 2.0), ("", 1.0)]),
        Err(Error::InvalidArgument(_))
    ));
    // The failed batch stored nothing.
    assert_eq!(h.raw("A", 0, 10, 10).expect("raw").len(), 1);
    let mut out = Vec::new();
    assert!(matches!(
        h.export_csv(&["A"], 0, 10, 0, &mut out),
        Err(Error::InvalidArgument(_))
    ));
    assert!(matches!(
        h.export_csv(&["A"], 0, i64::MAX, 1, &mut out),
        Err(Error::InvalidArgument(_))
    ));
}

#[test]
fn unknown_tag_is_an_error() {
    let dir = temp();
    let h = open(dir.path());
    h.record(0, &[("A", 1.0)]).expect("record");
    assert!(matches!(h.query("Nope", 0, 10, 10), Err(Error::UnknownTag(t)) if t == "Nope"));
    assert!(matches!(h.raw("Nope", 0, 10, 10), Err(Error::UnknownTag(_))));
    let mut out = Vec::new();
    assert!(matches!(
        h.export_csv(&["A", "Nope"], 0, 10, 1, &mut out),
        Err(Error::UnknownTag(_))
    ));
    assert!(out.is_empty(), "nothing written before the error");
}

#[test]
fn empty_ranges_give_nothing() {
    let dir = temp();
    let h = open(dir.path());
    h.record(5_000, &[("A", 1.0)]).expect("record");
    assert!(h.query("A", 10, 5, 100).expect("query").is_empty());
    assert!(h.query("A", 0, 4_999, 100).expect("query").is_empty());
    assert!(h.query("A", 5_001, 10_000_000, 100).expect("query").is_empty());
    assert!(h.raw("A", 10, 5, 100).expect("raw").is_empty());
    assert!(h.raw("A", 5_000, 5_000, 0).expect("raw").is_empty());
    let mut out = Vec::new();
    assert_eq!(h.export_csv(&["A"], 10, 5, 1, &mut out).expect("csv"), 0);
    assert_eq!(String::from_utf8(out).expect("utf8"), "Time (ms),A\n");
}

#[test]
fn boundary_times_are_included_and_tier_edges_are_exact() {
    let dir = temp();
    let h = open(dir.path());
    let hour = 3_600_000;
    // Samples on and around hour, minute and second edges, negative times included.
    let times = [
        -hour - 1,
        -hour,
        -1,
        0,
        1,
        999,
        1_000,
        59_999,
        60_000,
        hour - 1,
        hour,
        hour + 1,
        2 * hour - 1,
        2 * hour,
    ];
    let samples: Vec<Sample> = times
        .iter()
        .enumerate()
        .map(|(i, &t)| Sample {
            tag: "A",
            t_ms: t,
            v: i as f64,
        })
        .collect();
    h.record_batch(&samples).expect("record");
    let all: BTreeMap<i64, f64> = samples.iter().map(|s| (s.t_ms, s.v)).collect();
    for &from in &times {
        for &to in &times {
            for points in [1, 2, 3, 7, 1000] {
                let got = h.query("A", from, to, points).expect("query");
                assert_eq!(got, brute(&all, from, to, points as i64), "[{from}, {to}] {points}");
            }
            let raw = h.raw("A", from, to, 100).expect("raw");
            let want = if from > to { 0 } else { all.range(from..=to).count() };
            assert_eq!(raw.len(), want, "raw [{from}, {to}]");
        }
    }
    // A range that is exactly one hour bucket uses the coarsest tier and includes both ends.
    let q = h.query("A", hour, 2 * hour - 1, 1).expect("query");
    assert_eq!(q.len(), 1);
    assert_eq!((q[0].t_ms, q[0].count, q[0].first, q[0].last), (hour, 3, 10.0, 12.0));
}

#[test]
fn plan_gives_at_most_points_and_at_least_three_quarters() {
    let mut runner = TestRunner::new(PropConfig::with_cases(2000));
    let strategy = (-(1i64 << 40)..(1i64 << 40), 0i64..(1i64 << 36), 1i64..=10_000);
    runner
        .run(&strategy, |(from, len, points)| {
            let to = from + len;
            let p = plan(from, to, points);
            let count = (to - p.origin) / p.width + 1;
            prop_assert!(count <= points, "{p:?}: {count} > {points}");
            let span = len + 1;
            let ideal = span.min(points);
            prop_assert!(4 * count >= 3 * ideal, "{p:?}: {count} < 3/4 of {ideal}");
            prop_assert!(p.origin <= from);
            let b = if p.level == 0 { 1 } else { TIERS[p.level - 1].ms };
            prop_assert_eq!(p.origin % b, 0);
            prop_assert_eq!(p.width % b, 0);
            Ok(())
        })
        .expect("plan properties");
}

#[test]
fn downsampling_matches_brute_force() {
    let dir = temp();
    let h = open(dir.path());
    // Time steps from 1 ms to 2 h (log-uniform-ish), values with many ties.
    let step = prop_oneof![
        1i64..20,
        20i64..2_000,
        2_000i64..200_000,
        200_000i64..7_200_000,
        7_200_000i64..40_000_000
    ];
    let series = (
        -(1i64 << 33)..(1i64 << 33),
        prop::collection::vec((step, -5i32..5), 1..300),
        any::<u64>(),
        prop::collection::vec(
            (any::<u16>(), any::<u16>(), prop_oneof![1usize..8, 8usize..2_000]),
            1..12,
        ),
    );
    // A fixed seed: the same cases on every run (the level coverage below depends on it).
    let mut runner = TestRunner::new_with_rng(
        PropConfig::with_cases(96),
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let case = std::cell::Cell::new(0);
    let levels = std::cell::RefCell::new([0usize; TIERS.len() + 1]);
    runner
        .run(&series, |(start, steps, seed, queries)| {
            case.set(case.get() + 1);
            let tag = format!("T{}", case.get());
            let mut t = start;
            let mut samples: Vec<(i64, f64)> = Vec::new();
            for (dt, v) in steps {
                t += dt;
                samples.push((t, f64::from(v) * 0.5));
            }
            let all: BTreeMap<i64, f64> = samples.iter().copied().collect();
            // Insert in a scrambled order and in several transactions, so that rollup
            // rows are merged out of time order.
            let mut order: Vec<usize> = (0..samples.len()).collect();
            let mut s = seed | 1;
            for i in (1..order.len()).rev() {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                order.swap(i, (s % (i as u64 + 1)) as usize);
            }
            for chunk in order.chunks(1 + (seed % 40) as usize) {
                let batch: Vec<Sample> = chunk
                    .iter()
                    .map(|&i| Sample {
                        tag: &tag,
                        t_ms: samples[i].0,
                        v: samples[i].1,
                    })
                    .collect();
                h.record_batch(&batch).expect("record");
            }
            let first = samples[0].0;
            let last = samples[samples.len() - 1].0;
            let span = (last - first + 2) as u64;
            for (a, b, points) in queries {
                let from = first - 1 + (span * u64::from(a) / 65_536) as i64;
                let to = first - 1 + (span * u64::from(b) / 65_536) as i64;
                let got = h.query(&tag, from, to, points).expect("query");
                if from <= to {
                    let level = plan(from, to, points as i64).level;
                    levels.borrow_mut()[level] += 1;
                }
                let want = brute(&all, from, to, points as i64);
                prop_assert_eq!(got, want, "[{}, {}] {}", from, to, points);
            }
            // The whole range in one bucket counts every sample.
            let one = h.query(&tag, first, last, 1).expect("query");
            prop_assert_eq!(one.len(), 1);
            prop_assert_eq!(one[0].count, all.len() as u64);
            Ok(())
        })
        .expect("downsampling equals brute force");
    // Every tier and raw samples were exercised.
    let levels = levels.into_inner();
    assert!(levels.iter().all(|&n| n >= 5), "queries per level: {levels:?}");
}

#[test]
fn query_caps_points() {
    let dir = temp();
    let h = open(dir.path());
    let samples: Vec<Sample> = (0..30_000)
        .map(|i| Sample {
            tag: "A",
            t_ms: i,
            v: i as f64,
        })
        .collect();
    h.record_batch(&samples).expect("record");
    let q = h.query("A", 0, 29_999, 1_000_000).expect("query");
    assert_eq!(q.len(), MAX_POINTS);
    assert_eq!(q.iter().map(|b| b.count).sum::<u64>(), 30_000);
    let q = h.query("A", 0, 29_999, 30).expect("query");
    assert_eq!(q.len(), 30);
    assert!(q.iter().all(|b| b.count == 1000));
    assert_eq!(
        (q[1].t_ms, q[1].min, q[1].max, q[1].first, q[1].last),
        (1000, 1000.0, 1999.0, 1000.0, 1999.0)
    );
}

#[test]
fn retention_deletes_old_rows_from_all_tiers() {
    let dir = temp();
    let path = dir.path().join("history.db");
    let day = 86_400_000;
    let h = Historian::open(
        &path,
        Config {
            retention_days: Some(2),
            ..Config::default()
        },
    )
    .expect("open");
    // Two tags, a sample every 10 minutes for 5 days.
    let samples: Vec<Sample> = (0..5 * 144)
        .flat_map(|i| {
            let t = i * 600_000 + 123;
            [
                Sample {
                    tag: "A",
                    t_ms: t,
                    v: 1.0,
                },
                Sample {
                    tag: "B",
                    t_ms: t,
                    v: 2.0,
                },
            ]
        })
        .collect();
    h.record_batch(&samples).expect("record");
    let now = 5 * day + 30 * 60_000; // cut-off: 3 days + 30 min, rounded down to 3 days
    assert_eq!(h.retention_cutoff(now), Some(3 * day));
    let deleted = h.apply_retention(now).expect("retention");
    assert_eq!(deleted, 2 * 3 * 144);
    assert_eq!(count_rows(&path, "samples"), 2 * 2 * 144);
    for tier in &TIERS {
        let c = Connection::open(&path).expect("open");
        let old: i64 = c
            .query_row(
                &format!("SELECT count(*) FROM {} WHERE t < ?1", tier.table),
                [3 * day],
                |r| r.get(0),
            )
            .expect("count");
        assert_eq!(old, 0, "{}", tier.table);
        let n: i64 = c
            .query_row(&format!("SELECT sum(n) FROM {}", tier.table), [], |r| r.get(0))
            .expect("sum");
        assert_eq!(n, 2 * 2 * 144, "{} counts what is left", tier.table);
    }
    let tags = h.tags().expect("tags");
    assert_eq!(tags[0].first_ms, 3 * day + 123);
    let q = h.query("A", 0, 10 * day, 1).expect("query");
    assert_eq!(q[0].count, 2 * 144);
    // Again: nothing more to delete. Without retention nothing is deleted.
    assert_eq!(h.apply_retention(now).expect("retention"), 0);
    let keep = Historian::open(dir.path().join("keep.db"), Config::default()).expect("open");
    keep.record(0, &[("A", 1.0)]).expect("record");
    assert_eq!(keep.apply_retention(i64::MAX).expect("retention"), 0);
    assert_eq!(keep.raw("A", 0, 0, 1).expect("raw").len(), 1);
}

#[test]
fn csv_holds_values_between_samples() {
    let dir = temp();
    let h = open(dir.path());
    h.record(1_000, &[("A", 1.0)]).expect("record");
    h.record(1_250, &[("A", 2.5), ("B,x", 7.0)]).expect("record");
    h.record(1_500, &[("A", 3.0)]).expect("record");
    h.record(2_100, &[("B,x", -1.0)]).expect("record");
    let mut out = Vec::new();
    let rows = h.export_csv(&["A", "B,x"], 1_100, 2_100, 250, &mut out).expect("csv");
    assert_eq!(rows, 5);
    assert_eq!(
        String::from_utf8(out).expect("utf8"),
        "Time (ms),A,\"B,x\"\n0,1,\n250,2.5,7\n500,3,7\n750,3,7\n1000,3,-1\n"
    );
    // Before every sample the cells are empty; a range before A's first sample.
    let mut out = Vec::new();
    h.export_csv(&["A"], 0, 1_000, 500, &mut out).expect("csv");
    assert_eq!(String::from_utf8(out).expect("utf8"), "Time (ms),A\n0,\n500,\n1000,1\n");
}

#[test]
fn csv_lookup_and_stream_modes_agree() {
    let dir = temp();
    let h = open(dir.path());
    // Dense "A" (many samples per row: looked up), sparse "B" (streamed).
    let mut samples = Vec::new();
    for i in 0..20_000i64 {
        samples.push(Sample {
            tag: "A",
            t_ms: i * 10 + 3,
            v: (i % 97) as f64,
        });
        if i % 1_000 == 0 {
            samples.push(Sample {
                tag: "B",
                t_ms: i * 10 + 3,
                v: i as f64,
            });
        }
    }
    h.record_batch(&samples).expect("record");
    let all_a: BTreeMap<i64, f64> = samples.iter().filter(|s| s.tag == "A").map(|s| (s.t_ms, s.v)).collect();
    let all_b: BTreeMap<i64, f64> = samples.iter().filter(|s| s.tag == "B").map(|s| (s.t_ms, s.v)).collect();
    for step in [7, 1_000, 33_333] {
        let (from, to) = (-5_000, 210_000);
        let mut out = Vec::new();
        h.export_csv(&["A", "B"], from, to, step, &mut out).expect("csv");
        let mut want = String::from("Time (ms),A,B\n");
        let mut t = from;
        while t <= to {
            let a = all_a
                .range(..=t)
                .next_back()
                .map(|(_, v)| v.to_string())
                .unwrap_or_default();
            let b = all_b
                .range(..=t)
                .next_back()
                .map(|(_, v)| v.to_string())
                .unwrap_or_default();
            want.push_str(&format!("{},{a},{b}\n", t - from));
            t += step;
        }
        assert_eq!(String::from_utf8(out).expect("utf8"), want, "step {step}");
    }
}

#[test]
fn files_that_are_not_history_databases_are_refused() {
    let dir = temp();
    // Not SQLite at all.
    let garbage = dir.path().join("garbage.db");
    std::fs::write(&garbage, vec![0x5Au8; 8192]).expect("write");
    let e = Historian::open(&garbage, Config::default()).expect_err("garbage");
    assert!(matches!(e, Error::NotHistory { .. }), "{e}");
    assert!(e.to_string().contains("not an SQLite database"), "{e}");
    // Another application's SQLite database.
    let other = dir.path().join("other.db");
    Connection::open(&other)
        .expect("open")
        .execute_batch("CREATE TABLE x(a);")
        .expect("create");
    let e = Historian::open(&other, Config::default()).expect_err("other");
    assert!(e.to_string().contains("another application"), "{e}");
    // A history database whose schema page is damaged.
    let damaged = dir.path().join("damaged.db");
    {
        let h = Historian::open(&damaged, Config::default()).expect("open");
        h.record(0, &[("A", 1.0)]).expect("record");
    }
    let mut bytes = std::fs::read(&damaged).expect("read");
    for b in bytes.iter_mut().skip(100).take(3000) {
        *b = 0xA5;
    }
    std::fs::write(&damaged, &bytes).expect("write");
    let e = Historian::open(&damaged, Config::default()).expect_err("damaged");
    assert!(matches!(e, Error::NotHistory { .. }), "{e}");
    // A path that cannot be a file.
    let e = Historian::open(dir.path().join("missing/dir/h.db"), Config::default()).expect_err("missing directory");
    assert!(matches!(e, Error::Open { .. }), "{e}");
}

#[test]
fn reads_run_concurrently_with_writes() {
    let dir = temp();
    let h = open(dir.path());
    h.record(0, &[("A", 0.0)]).expect("record");
    let writer = {
        let h = h.clone();
        std::thread::spawn(move || {
            for i in 1..=400i64 {
                let batch: Vec<Sample> = (0..50)
                    .map(|j| {
                        let t = i * 50 + j;
                        Sample {
                            tag: "A",
                            t_ms: t * 100,
                            v: t as f64,
                        }
                    })
                    .collect();
                h.record_batch(&batch).expect("record");
            }
        })
    };
    let mut seen = 0;
    let mut reads = 0;
    while !writer.is_finished() || reads < 5 {
        let q = h.query("A", 0, i64::from(i32::MAX), 500).expect("query");
        let count: u64 = q.iter().map(|b| b.count).sum();
        // Each snapshot holds whole transactions: a value per time step, consistent with
        // the bucket statistics.
        assert!(count >= seen, "count went down");
        assert_eq!((count - 1) % 50, 0, "partial transaction seen");
        for b in &q {
            assert!(b.min <= b.first && b.first <= b.last && b.last <= b.max);
        }
        seen = count;
        reads += 1;
    }
    writer.join().expect("writer thread");
    let q = h.query("A", 0, i64::from(i32::MAX), 500).expect("query");
    assert_eq!(q.iter().map(|b| b.count).sum::<u64>(), 20_001);
}

#[test]
fn filter_stores_changes_beyond_deadband_and_periodically() {
    let f = Filter {
        deadband: 0.5,
        period_ms: 1_000,
    };
    assert!(f.admits(None, 0, 1.0));
    let last = Some((0, 1.0));
    assert!(!f.admits(last, 100, 1.5), "within the deadband");
    assert!(f.admits(last, 100, 1.51));
    assert!(f.admits(last, 100, 0.49));
    assert!(f.admits(last, 1_000, 1.0), "period elapsed");
    assert!(!f.admits(last, 999, 1.0));
    assert!(f.admits(last, -5, 1.0), "time went backwards");
    assert!(!f.admits(last, 100, f64::NAN));
    assert!(f.admits(last, 100, f64::INFINITY));
    assert!(!f.admits(Some((0, f64::INFINITY)), 100, f64::INFINITY));
    let on_change = Filter {
        deadband: 0.0,
        period_ms: 0,
    };
    assert!(!on_change.admits(last, 1_000_000, 1.0));
    assert!(on_change.admits(last, 1, 1.000001));
    assert!(Filter::EVERY.admits(last, 1, 1.0));

    // The deadband is measured from the last stored value, so a drift is caught.
    let mut cf = ChangeFilter::new(Filter {
        deadband: 1.0,
        period_ms: 0,
    });
    let stored: Vec<i64> = (0..30).filter(|&i| cf.admit("A", i, i as f64 * 0.3)).collect();
    assert_eq!(stored, vec![0, 4, 8, 12, 16, 20, 24, 28]);
    cf.set_filter("B", Filter::EVERY);
    assert!(cf.admit("B", 0, 1.0) && cf.admit("B", 1, 1.0));
    assert!(!cf.admit("A", 100, 8.4));
    cf.forget("A");
    assert!(cf.admit("A", 100, 8.4));
}

#[test]
fn recorder_writes_what_the_filter_admits() {
    let dir = temp();
    let h = open(dir.path());
    let mut rec = Recorder::new(
        h.clone(),
        ChangeFilter::new(Filter {
            deadband: 0.0,
            period_ms: 1_000,
        }),
    );
    let mut stored = 0;
    for i in 0..50i64 {
        // A changes every 10 steps, B never, at 100 ms steps.
        stored += rec
            .record(i * 100, &[("A", (i / 10) as f64), ("B", 3.0)])
            .expect("record");
    }
    let a: Vec<i64> = h
        .raw("A", 0, 10_000, 100)
        .expect("raw")
        .iter()
        .map(|p| p.t_ms)
        .collect();
    let b: Vec<i64> = h
        .raw("B", 0, 10_000, 100)
        .expect("raw")
        .iter()
        .map(|p| p.t_ms)
        .collect();
    assert_eq!(a, vec![0, 1000, 2000, 3000, 4000]);
    assert_eq!(b, vec![0, 1000, 2000, 3000, 4000]);
    assert_eq!(stored, 10);
    rec.filter_mut().set_filter("B", Filter::EVERY);
    assert_eq!(rec.record(5_000, &[("B", 3.0)]).expect("record"), 1);
    assert_eq!(rec.historian().path(), h.path());
}

/// Queries `tag` over many ranges and resolutions and compares with brute force.
fn assert_queries_exact(h: &Historian, tag: &str, all: &BTreeMap<i64, f64>) {
    let first = *all.keys().next().expect("samples");
    let last = *all.keys().next_back().expect("samples");
    let span = last - first + 1;
    for (a, b) in [(0, 8), (1, 7), (2, 5), (0, 1), (3, 8), (7, 8)] {
        let from = first - 1 + span * a / 8;
        let to = first + span * b / 8;
        for points in [1, 3, 50, 1000] {
            let got = h.query(tag, from, to, points).expect("query");
            assert_eq!(got, brute(all, from, to, points as i64), "[{from}, {to}] {points}");
        }
    }
}

#[test]
fn pending_samples_survive_a_crash_and_other_writers() {
    let dir = temp();
    let path = dir.path().join("history.db");
    let mut all = BTreeMap::new();
    fn put(h: &Historian, all: &mut BTreeMap<i64, f64>, range: std::ops::Range<i64>, step: i64) {
        for i in range {
            let t = i * step;
            let v = ((i * 37) % 101) as f64;
            if h.record(t, &[("A", v)]).expect("record") == 1 {
                all.insert(t, v);
            }
        }
    }
    let h = Historian::open(&path, Config::default()).expect("open");
    put(&h, &mut all, 0..5_000, 100);
    // The last seconds are still pending; the "crash" skips the flush on drop.
    std::mem::forget(h);
    let h = Historian::open(&path, Config::default()).expect("reopen");
    put(&h, &mut all, 5_000..6_000, 100);
    // A second writer on the same file, writing late and new samples.
    let other = Historian::open(&path, Config::default()).expect("second writer");
    put(&other, &mut all, 6_000..6_050, 100);
    put(&h, &mut all, 6_050..6_100, 100);
    put(&other, &mut all, 3_000..3_100, 101);
    put(&h, &mut all, 6_100..6_200, 100);
    assert_queries_exact(&h, "A", &all);
    assert_queries_exact(&other, "A", &all);
    drop(other);
    h.flush().expect("flush");
    assert_queries_exact(&h, "A", &all);
    let rolled: i64 = Connection::open(&path)
        .expect("open")
        .query_row("SELECT sum(n) FROM rollup_1h", [], |r| r.get(0))
        .expect("sum");
    assert_eq!(rolled as usize, all.len(), "after a flush the tiers hold every sample");
    // Retention cutting into samples that are pending.
    put(&h, &mut all, 6_200..6_230, 100);
    let cutoff = 3_600_000;
    h.delete_before(cutoff + 1).expect("retention");
    all.retain(|&t, _| t >= cutoff);
    put(&h, &mut all, 6_230..6_300, 100);
    assert_queries_exact(&h, "A", &all);
}

#[test]
fn recorder_buffers_up_to_the_max_delay() {
    let dir = temp();
    let h = open(dir.path());
    let mut rec = Recorder::new(h.clone(), ChangeFilter::new(Filter::EVERY));
    rec.set_max_delay(1_000);
    for i in 0..10i64 {
        assert_eq!(rec.record(i * 100, &[("A", i as f64), ("B", 1.0)]).expect("record"), 2);
    }
    assert_eq!(rec.buffered(), 20);
    assert!(matches!(h.raw("A", 0, 10_000, 100), Err(Error::UnknownTag(_))));
    // One second after the oldest buffered value: everything is written at once.
    rec.record(1_000, &[("A", 10.0)]).expect("record");
    assert_eq!(rec.buffered(), 0);
    assert_eq!(h.raw("A", 0, 10_000, 100).expect("raw").len(), 11);
    rec.record(1_100, &[("A", 11.0)]).expect("record");
    assert_eq!(rec.flush().expect("flush"), 1);
    rec.record(1_200, &[("B", 2.0)]).expect("record");
    drop(rec);
    assert_eq!(h.raw("B", 0, 10_000, 100).expect("raw").len(), 11);
}

#[test]
fn the_size_cap_deletes_the_oldest_hours_first() {
    let dir = temp();
    let h = open(dir.path());
    // 10 tags, one sample every 10 s for 48 hours.
    let names: Vec<String> = (0..10).map(|i| format!("T{i}")).collect();
    let hour = 3_600_000;
    for chunk in 0..48 {
        let samples: Vec<Sample<'_>> = (0..360)
            .flat_map(|k| {
                let t = chunk * hour + k * 10_000;
                names.iter().map(move |n| Sample {
                    tag: n,
                    t_ms: t,
                    v: (t % 977) as f64,
                })
            })
            .collect();
        h.record_batch(&samples).expect("record");
    }
    h.flush().expect("flush");
    let before = h.used_bytes().expect("size");
    let cap = before / 3;
    let deleted = h.enforce_cap(cap).expect("cap");
    assert!(
        deleted > 0 && h.used_bytes().expect("size") <= cap,
        "{before} → cap {cap}"
    );
    let ranges = h.tags().expect("tags");
    assert_eq!(ranges.len(), 10);
    for r in &ranges {
        // Whole hours went, oldest first; the newest sample stays.
        assert_eq!(r.first_ms % hour, 0, "{r:?}");
        assert!(r.first_ms >= 24 * hour, "{r:?}");
        assert_eq!(r.last_ms, 47 * hour + 359 * 10_000);
    }
    // More data keeps it under the cap once enforced again, reusing free pages.
    let len_before = std::fs::metadata(h.path()).expect("file").len();
    let samples: Vec<Sample<'_>> = (0..360)
        .flat_map(|k| {
            let t = 48 * hour + k * 10_000;
            names.iter().map(move |n| Sample {
                tag: n,
                t_ms: t,
                v: 1.0,
            })
        })
        .collect();
    h.record_batch(&samples).expect("record");
    h.enforce_cap(cap).expect("cap");
    assert!(h.used_bytes().expect("size") <= cap);
    assert!(std::fs::metadata(h.path()).expect("file").len() <= len_before);
}

#[test]
fn a_database_damaged_in_use_is_moved_aside_for_a_fresh_one() {
    let dir = temp();
    let path = dir.path().join("history.db");
    let h = open(dir.path());
    let samples: Vec<Sample<'_>> = (0..20_000)
        .map(|k| Sample {
            tag: "A",
            t_ms: k * 1000,
            v: k as f64,
        })
        .collect();
    h.record_batch(&samples).expect("record");
    h.flush().expect("flush");
    drop(h);
    // Overwrite the data pages (past the header, the schema and the tables' roots).
    {
        use std::io::{Seek, SeekFrom};
        let c = Connection::open(&path).expect("open");
        c.execute_batch("PRAGMA wal_checkpoint(TRUNCATE);").expect("checkpoint");
        drop(c);
        let mut f = std::fs::OpenOptions::new().write(true).open(&path).expect("file");
        let len = f.metadata().expect("len").len();
        f.seek(SeekFrom::Start(64 * 1024)).expect("seek");
        f.write_all(&vec![0xA5; (len - 64 * 1024) as usize]).expect("damage");
    }
    // It still opens (the header and schema are fine) …
    let h = open(dir.path());
    // … and the damage shows when its pages are read.
    match h.raw("A", 0, i64::MAX, 100_000) {
        Err(e) => assert!(e.is_damage(), "{e}"),
        Ok(p) => panic!("{} points read from damaged pages", p.len()),
    }
    let aside = h.replace_damaged().expect("replace");
    assert!(aside.to_string_lossy().contains("history.db.damaged-") && aside.exists());
    h.record(5, &[("B", 1.0)]).expect("a fresh database records");
    assert_eq!(h.tags().expect("tags").len(), 1);
    assert!(matches!(h.raw("A", 0, 10, 10), Err(Error::UnknownTag(_))));
}

/// Issue 31: `to - from` overflowed for extreme ranges, so a caller's cap on the rows of an
/// export counted 1 where the export wrote millions. The count is exact (compared in 128-bit
/// arithmetic on the clamped range) for any `i64`s and never panics.
#[test]
fn csv_rows_is_exact_for_extreme_ranges() {
    let exact = |from: i64, to: i64, step: i64| -> Option<u64> {
        if step < 1 {
            return None;
        }
        let (f, t) = (
            i128::from(from.clamp(-MAX_TIME_MS, MAX_TIME_MS)),
            i128::from(to.clamp(-MAX_TIME_MS, MAX_TIME_MS)),
        );
        Some(if f > t {
            0
        } else {
            u64::try_from((t - f) / i128::from(step) + 1).expect("fits")
        })
    };
    assert_eq!(
        csv_rows(i64::MIN, i64::MAX, 1_801_439_851),
        exact(i64::MIN, i64::MAX, 1_801_439_851)
    );
    assert!(csv_rows(i64::MIN, i64::MAX, 1_801_439_851).is_some_and(|r| r > 1_000_000));
    let edges = [
        i64::MIN,
        i64::MIN + 1,
        -MAX_TIME_MS - 1,
        -1,
        0,
        1,
        MAX_TIME_MS + 1,
        i64::MAX - 1,
        i64::MAX,
    ];
    let mut runner = TestRunner::new_with_rng(
        PropConfig::with_cases(4096),
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let time = || prop_oneof![proptest::sample::select(edges.to_vec()), any::<i64>()];
    runner
        .run(
            &(time(), time(), prop_oneof![Just(1i64), Just(i64::MAX), any::<i64>()]),
            |(from, to, step)| {
                prop_assert_eq!(csv_rows(from, to, step), exact(from, to, step));
                Ok(())
            },
        )
        .expect("csv_rows agrees with exact arithmetic");
}
