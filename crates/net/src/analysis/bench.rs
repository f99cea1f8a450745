//! The analysis benchmark shared by `cargo bench -p alba-net` and `alba bench
//! --nets` (docs/performance.md "Net analysis"): the complete analysis of
//! generated nets, with states/s and bytes/state. Prints, never asserts.

use super::{Control, Options, analyze, invariants, samples};
use crate::PtNet;
use std::fmt::Write;
use std::time::Instant;

fn peak_rss_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The report of one net's complete analysis.
pub fn report(name: &str, net: &PtNet) -> String {
    measure(name, net).0
}

/// The report of one net's complete analysis, and its number of states.
pub fn measure(name: &str, net: &PtNet) -> (String, u64) {
    let t = Instant::now();
    let a = analyze(net, &Options::default(), &Control::none());
    let total = t.elapsed();
    let states = a.states.unwrap_or(0);
    let secs = a.explore_time.as_secs_f64().max(1e-9);
    let report = format!(
        "{name}: {states} states, {} edges, {} deadlocks, live {:?}, reversible {:?}, {} P-inv ({}), {} T-inv ({})\n  \
         explore {:.3} s ({:.2} M states/s), scc {:.3} s, invariants {:.3} s, total {:.3} s; {:.1} bytes/state, peak RSS {} MiB\n",
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
        a.scc_time.as_secs_f64(),
        a.invariant_time.as_secs_f64(),
        total.as_secs_f64(),
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
