//! `alba bench --realtime`: how late the engine thread wakes up, measured
//! the way `cyclictest` does: a thread with the engine's scheduling
//! (`alba_runtime::realtime`, the settings of `[runtime]`) waits for
//! deadlines every period with the engine's own primitive (a channel
//! receive with a timeout) and records how late each wake-up is. Run at
//! 1 ms and 10 ms, with the machine idle and with one busy thread per CPU at
//! normal priority (what HTTP, protocol and historian work look like to the
//! scheduler), at normal priority and at SCHED_FIFO. Prints p50, p99, p99.9
//! and max lateness and the deadlines missed (a wake-up later than a period).

use alba_runtime::realtime::Realtime;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Lateness of each wake-up (ns) over `secs` at `period`.
fn measure(period: Duration, secs: f64, rt: Realtime) -> (Vec<u64>, Vec<String>) {
    std::thread::scope(|s| {
        s.spawn(|| {
            let warnings = rt.apply();
            let (_tx, rx) = std::sync::mpsc::channel::<()>();
            let n = (secs / period.as_secs_f64()).ceil() as usize;
            let mut late = Vec::with_capacity(n);
            let mut deadline = Instant::now() + period;
            for _ in 0..n {
                let wait = deadline.saturating_duration_since(Instant::now());
                let _ = rx.recv_timeout(wait);
                let now = Instant::now();
                late.push(now.saturating_duration_since(deadline).as_nanos() as u64);
                deadline += period;
                if now > deadline {
                    // Missed ones are skipped, as the engine does.
                    let missed = (now - deadline).as_nanos() / period.as_nanos() + 1;
                    deadline += period * missed as u32;
                }
            }
            (late, warnings)
        })
        .join()
        .unwrap_or_default()
    })
}

/// One busy thread per CPU at normal priority until `stop`.
fn hogs(stop: &Arc<AtomicBool>) -> Vec<std::thread::JoinHandle<()>> {
    let cpus = std::thread::available_parallelism().map_or(2, |n| n.get());
    (0..cpus)
        .map(|_| {
            let stop = stop.clone();
            std::thread::spawn(move || {
                let mut x = 0u64;
                while !stop.load(Ordering::Relaxed) {
                    for i in 0..10_000u64 {
                        x = x.wrapping_mul(6364136223846793005).wrapping_add(i);
                    }
                    std::hint::black_box(x);
                }
            })
        })
        .collect()
}

fn pct(sorted: &[u64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i] as f64 / 1000.0
}

pub fn run(secs: f64, priority: u8, cpu: Option<usize>) -> ExitCode {
    if !(0.1..=3600.0).contains(&secs) || priority == 0 || priority > 99 {
        eprintln!("error: --seconds 0.1 to 3600; --priority 1 to 99");
        return ExitCode::FAILURE;
    }
    println!("alba bench --realtime: wake-up lateness of a thread scheduled as the engine's, {secs} s per row");
    println!(
        "(load \"cpu\": {} busy threads at normal priority)\n",
        std::thread::available_parallelism().map_or(2, |n| n.get())
    );
    println!(
        "{:>7} {:>5} {:<30} {:>8} {:>8} {:>8} {:>9} {:>9} {:>7}",
        "period", "load", "scheduling", "wakeups", "p50 µs", "p99 µs", "p99.9 µs", "max µs", "missed"
    );
    let mut warned = false;
    for period_ms in [1u64, 10] {
        for load in ["idle", "cpu"] {
            for fifo in [false, true] {
                let rt = Realtime {
                    priority: if fifo { priority } else { 0 },
                    cpu,
                    lock_memory: fifo,
                };
                let stop = Arc::new(AtomicBool::new(false));
                let threads = if load == "cpu" { hogs(&stop) } else { Vec::new() };
                let period = Duration::from_millis(period_ms);
                let (mut late, warnings) = measure(period, secs, rt);
                stop.store(true, Ordering::Relaxed);
                threads.into_iter().for_each(|t| {
                    let _ = t.join();
                });
                if !warnings.is_empty() && !warned {
                    warned = true;
                    warnings.iter().for_each(|w| eprintln!("warning: {w}"));
                }
                let missed = late.iter().filter(|&&l| l >= period.as_nanos() as u64).count();
                late.sort_unstable();
                let sched = if warnings.iter().any(|w| w.contains("SCHED_FIFO")) {
                    "normal (FIFO refused)".to_string()
                } else {
                    rt.describe()
                };
                println!(
                    "{:>5} ms {load:>5} {sched:<30} {:>8} {:>8.1} {:>8.1} {:>9.1} {:>9.1} {missed:>7}",
                    period_ms,
                    late.len(),
                    pct(&late, 0.5),
                    pct(&late, 0.99),
                    pct(&late, 0.999),
                    pct(&late, 1.0)
                );
            }
        }
    }
    ExitCode::SUCCESS
}
