//! Historian benchmark: insert rates (every tag of a 10 000-tag project
//! among them), and downsampled queries over a 10-million-sample database.
//! Prints numbers; asserts nothing but that answers are complete.
//!
//! ```text
//! alba bench --historian [--quick]                               # the same, from the CLI
//! cargo bench -p alba-historian --bench historian [-- --quick]   # 10 M (1 M) samples
//! ```
//!
//! The database is built in a temporary directory (about 300 MB for 10 M samples) and
//! deleted at the end; set ALBA_HISTORIAN_BENCH_DIR to build it elsewhere.

use std::time::{Duration, Instant};

use crate::{ChangeFilter, Config, Filter, Historian, Recorder, Sample};

const RUNS: usize = 9;

/// A directory removed when dropped.
struct Scratch(std::path::PathBuf);

impl Scratch {
    fn path(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs the benchmark (1 M samples instead of 10 M when `quick`).
pub fn run(quick: bool) -> Result<(), Box<dyn std::error::Error>> {
    let total: i64 = if quick { 1_000_000 } else { 10_000_000 };
    let parent = std::env::var_os("ALBA_HISTORIAN_BENCH_DIR").map_or_else(std::env::temp_dir, Into::into);
    let dir = Scratch(parent.join(format!("alba-historian-bench-{}", std::process::id())));
    let _ = std::fs::remove_dir_all(dir.path());
    std::fs::create_dir_all(dir.path())?;
    println!("alba-historian benchmark ({} samples)", total);

    live_inserts(&dir, 100, 1_000, 0)?;
    live_inserts(&dir, 1_000, 100, 0)?;
    live_inserts(&dir, 100, 1_000, 1_000)?;
    live_inserts(&dir, 1_000, 100, 1_000)?;
    // Every tag of a 10 000-tag project recorded (issue 18): what one scan's
    // snapshot costs to record, a transaction per call and buffered.
    live_inserts(&dir, 10_000, 20, 0)?;
    live_inserts(&dir, 10_000, 20, 1_000)?;

    // One tag at 10 Hz: `total` samples, from t = 0.
    let path = dir.path().join("big.db");
    let h = Historian::open(&path, Config::default())?;
    let period = 100;
    let chunk = 36_000; // one hour of samples per transaction
    let start = Instant::now();
    let mut batch = Vec::with_capacity(chunk as usize);
    let mut i = 0;
    while i < total {
        batch.clear();
        for k in i..(i + chunk).min(total) {
            batch.push(Sample {
                tag: "Level",
                t_ms: k * period,
                v: value(k),
            });
        }
        h.record_batch(&batch)?;
        i += chunk;
    }
    let build = start.elapsed();
    let bytes =
        std::fs::metadata(&path)?.len() + std::fs::metadata(path.with_extension("db-wal")).map_or(0, |m| m.len());
    println!(
        "bulk insert (record_batch, 36 000 samples/transaction): {} samples in {:.1} s = {:.0} samples/s; file {:.0} MB = {:.1} B/sample",
        total,
        build.as_secs_f64(),
        total as f64 / build.as_secs_f64(),
        bytes as f64 / 1e6,
        bytes as f64 / total as f64
    );

    let last = (total - 1) * period;
    let hour = 3_600_000;
    let day = 24 * hour;
    let ranges: [(&str, i64, i64); 6] = [
        ("full range", 0, last),
        ("1 week", last - 7 * day, last),
        ("1 day", last / 2, last / 2 + day - 1),
        ("1 hour", last / 2 + 1_234, last / 2 + 1_234 + hour - 1),
        ("1 minute", last / 2 + 5, last / 2 + 5 + 60_000 - 1),
        ("full range (unaligned)", 777, last - 333),
    ];
    println!("downsampled query, 1000 points (median of {RUNS}; min):");
    for (name, from, to) in ranges {
        if from < 0 {
            continue;
        }
        let mut buckets = 0;
        let mut count = 0;
        let (median, min) = time(|| {
            let q = h.query("Level", from, to, 1000).map_err(|e| e.to_string())?;
            buckets = q.len();
            count = q.iter().map(|b| b.count).sum::<u64>();
            Ok(())
        })?;
        let to_stored = to.min(last);
        let expected = (to_stored / period - (from + period - 1) / period + 1) as u64;
        if count != expected {
            return Err(format!("{name}: {count} samples counted, {expected} stored").into());
        }
        println!(
            "  {name:<24} {:>9} samples -> {buckets:>4} buckets: {:>8.2} ms (min {:.2} ms)",
            count,
            ms(median),
            ms(min)
        );
    }

    // For comparison: the same full-range answer computed by SQLite from raw samples.
    {
        let conn = rusqlite::Connection::open(&path)?;
        let width = (last + 1 + 999) / 1000;
        let start = Instant::now();
        let n: i64 = conn.query_row(
            "SELECT count(*) FROM (SELECT t / ?1, min(v), max(v) FROM samples
             WHERE tag = 1 AND t BETWEEN 0 AND ?2 GROUP BY 1)",
            [width, last],
            |r| r.get(0),
        )?;
        println!(
            "  baseline: GROUP BY over raw samples, full range -> {n} buckets: {:.0} ms (once)",
            ms(start.elapsed())
        );
    }

    let mut n = 0;
    let (median, _) = time(|| {
        n = h
            .raw("Level", last / 2, last / 2 + hour - 1, usize::MAX)
            .map_err(|e| e.to_string())?
            .len();
        Ok(())
    })?;
    println!(
        "raw read of 1 hour: {n} samples in {:.2} ms = {:.0} samples/s",
        ms(median),
        n as f64 / median.as_secs_f64()
    );

    let mut rows = 0;
    let start = Instant::now();
    let mut sink = std::io::sink();
    rows += h.export_csv(&["Level"], last / 2, last / 2 + day - 1, 1_000, &mut sink)?;
    let sparse = start.elapsed();
    println!("csv export, 1 day at 1 s steps: {rows} rows in {:.0} ms", ms(sparse));
    let start = Instant::now();
    let rows = h.export_csv(&["Level"], last / 2, last / 2 + hour - 1, 100, &mut sink)?;
    println!(
        "csv export, 1 hour at 100 ms steps: {rows} rows in {:.0} ms",
        ms(start.elapsed())
    );

    let start = Instant::now();
    let deleted = h.delete_before(day)?;
    println!(
        "retention: deleted {deleted} samples (1 day) in {:.0} ms",
        ms(start.elapsed())
    );
    Ok(())
}

/// `ticks` calls of `Recorder::record` with `tags` values each, 100 ms apart, every value
/// admitted: the live path, one transaction per call or buffered for `delay_ms`.
fn live_inserts(dir: &Scratch, tags: usize, ticks: i64, delay_ms: u64) -> Result<(), Box<dyn std::error::Error>> {
    let h = Historian::open(dir.path().join(format!("live{tags}-{delay_ms}.db")), Config::default())?;
    let mut rec = Recorder::new(h, ChangeFilter::new(Filter::EVERY));
    rec.set_max_delay(delay_ms);
    let names: Vec<String> = (0..tags).map(|i| format!("Tag_{i}")).collect();
    let mut values: Vec<(&str, f64)> = names.iter().map(|n| (n.as_str(), 0.0)).collect();
    let start = Instant::now();
    let mut stored = 0;
    for tick in 0..ticks {
        for (j, v) in values.iter_mut().enumerate() {
            v.1 = value(tick * 7 + j as i64);
        }
        stored += rec.record(tick * 100, &values)?;
    }
    rec.flush()?;
    let took = start.elapsed();
    let how = if delay_ms == 0 {
        "a transaction per call".to_string()
    } else {
        format!("buffered {delay_ms} ms")
    };
    println!(
        "live insert (Recorder, {tags} tags per call, {ticks} calls, {how}): {:.0} values/s, {:.3} ms per call",
        stored as f64 / took.as_secs_f64(),
        ms(took) / ticks as f64
    );
    Ok(())
}

/// An analog-looking signal: a slow sine, a faster ripple and deterministic noise.
fn value(k: i64) -> f64 {
    let t = k as f64 / 10.0;
    let noise = ((k.wrapping_mul(6_364_136_223_846_793_005) >> 33) % 1000) as f64 / 1000.0;
    50.0 + 20.0 * (t / 600.0).sin() + 2.0 * (t / 7.0).sin() + noise
}

/// Median and minimum of `RUNS` runs of `f`, after one warm-up run.
fn time(mut f: impl FnMut() -> Result<(), String>) -> Result<(Duration, Duration), Box<dyn std::error::Error>> {
    f()?;
    let mut times = Vec::with_capacity(RUNS);
    for _ in 0..RUNS {
        let start = Instant::now();
        f()?;
        times.push(start.elapsed());
    }
    times.sort();
    Ok((times[RUNS / 2], times[0]))
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}
