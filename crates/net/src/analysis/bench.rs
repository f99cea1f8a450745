//! The analysis benchmark shared by `cargo bench -p alba-net` and `alba bench
//! --nets` (docs/performance.md "Net analysis"): the complete analysis of
//! generated nets, with states/s and bytes/state. Prints, never asserts.

use super::{Control, Options, Part, Progress, analyze, invariants, samples};
use crate::PtNet;
use std::fmt::Write;
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// User CPU seconds of this process so far (all threads), from `/proc/self/stat`.
fn user_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command (which may hold spaces): state is the first.
    let rest = &s[s.rfind(')')? + 2..];
    let ticks: f64 = rest.split_whitespace().nth(11)?.parse().ok()?;
    Some(ticks / 100.0)
}

fn peak_rss_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The report of one net's complete analysis.
pub fn report(name: &str, net: &PtNet) -> String {
    measure(name, net, super::default_threads()).0
}

/// The report of one net's complete analysis on `threads` threads, and its number of
/// states.
pub fn measure(name: &str, net: &PtNet, threads: usize) -> (String, u64) {
    let t = Instant::now();
    let cpu0 = user_seconds().unwrap_or(0.0);
    // User CPU time when the SCC pass starts: the exploration's.
    let explored_cpu = Mutex::new(None);
    let progress = |p: &Progress| {
        if p.part == Part::Components
            && let Ok(mut c) = explored_cpu.lock()
        {
            c.get_or_insert(user_seconds().unwrap_or(0.0));
        }
    };
    let control = Control {
        cancel: &AtomicBool::new(false),
        progress: &progress,
    };
    let a = analyze(
        net,
        &Options {
            threads,
            ..Options::default()
        },
        &control,
    );
    let total = t.elapsed();
    let cpu = user_seconds().unwrap_or(0.0) - cpu0;
    let explore_cpu = explored_cpu.lock().ok().and_then(|c| *c).map_or(cpu, |c| c - cpu0);
    let states = a.states.unwrap_or(0);
    let secs = a.explore_time.as_secs_f64().max(1e-9);
    let report = format!(
        "{name}: {states} states, {} edges, {} deadlocks, live {:?}, reversible {:?}, {} P-inv ({}), {} T-inv ({})\n  \
         {threads} thread(s): explore {:.3} s ({:.2} M states/s; {:.3} s user CPU, {:.2} M states per CPU-second), scc {:.3} s, \
         invariants {:.3} s, total {:.3} s ({:.3} s user CPU); {:.1} bytes/state, peak RSS {} MiB\n",
        a.edges.unwrap_or(0),
        a.deadlocks.unwrap_or(0),
        a.live,
        a.reversible,
        a.p_invariants.as_ref().map_or(0, |v| v.len()),
        a.status.p_invariants,
        a.t_invariants.as_ref().map_or(0, |v| v.len()),
        a.status.t_invariants,
        secs,
        states as f64 / secs / 1e6,
        explore_cpu,
        states as f64 / explore_cpu.max(1e-9) / 1e6,
        a.scc_time.as_secs_f64(),
        a.invariant_time.as_secs_f64(),
        total.as_secs_f64(),
        cpu,
        a.memory_bytes as f64 / states.max(1) as f64,
        peak_rss_kib().unwrap_or(0) / 1024,
    );
    (report, states)
}

/// Every net of the benchmark (`quick`: smaller ones, for a smoke run).
pub fn run(quick: bool) -> String {
    let mut out = String::new();
    let nets: Vec<(&str, PtNet)> = if quick {
        vec![
            ("cycles 9x3", samples::cycles(9, 3)),
            ("philosophers 6", samples::philosophers(6)),
            ("kanban 2", samples::kanban(2)),
        ]
    } else {
        vec![
            ("cycles 13x3", samples::cycles(13, 3)),
            ("philosophers 10", samples::philosophers(10)),
            ("philosophers 12", samples::philosophers(12)),
            ("kanban 5", samples::kanban(5)),
        ]
    };
    for (name, net) in &nets {
        out.push_str(&report(name, net));
    }
    let t = Instant::now();
    let net = samples::cycles(25, 4);
    let p = invariants::p_invariants(&net, invariants::Budget::rows(200_000)).map(|v| v.len());
    let tt = invariants::t_invariants(&net, invariants::Budget::rows(200_000)).map(|v| v.len());
    let _ = writeln!(
        out,
        "invariants on 100 places (25 4-cycles): {p:?} P, {tt:?} T in {:.3} s",
        t.elapsed().as_secs_f64()
    );
    out
}
