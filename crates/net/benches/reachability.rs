//! Reachability benchmark: `cargo bench -p alba-net` (release). Prints states/s and
//! bytes/state for 13 independent 3-place cycles (3^13 = 1 594 323 states) and the
//! dining philosophers, and the invariant time on a 100-place net.

use alba_net::analysis::{Options, analyze, samples};
use std::time::Instant;

fn peak_rss_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn run(name: &str, net: &alba_net::PtNet) {
    let t = Instant::now();
    let a = analyze(net, &Options::default(), &|| false);
    let total = t.elapsed();
    let states = a.states.unwrap_or(0);
    let secs = a.explore_time.as_secs_f64();
    println!(
        "{name}: {states} states, {} edges, {} deadlocks, live {:?}, reversible {:?}, {} P-inv, {} T-inv",
        a.edges.unwrap_or(0),
        a.deadlocks.unwrap_or(0),
        a.live,
        a.reversible,
        a.p_invariants.as_ref().map_or(0, |v| v.len()),
        a.t_invariants.as_ref().map_or(0, |v| v.len()),
    );
    println!(
        "  explore {:.3} s ({:.2} M states/s), scc {:.3} s, invariants {:.3} s, total {:.3} s; {:.1} bytes/state (data structures), peak RSS {} MiB",
        secs,
        states as f64 / secs / 1e6,
        a.scc_time.as_secs_f64(),
        a.invariant_time.as_secs_f64(),
        total.as_secs_f64(),
        a.memory_bytes as f64 / states.max(1) as f64,
        peak_rss_kib().unwrap_or(0) / 1024,
    );
}

fn main() {
    run("cycles 13x3", &samples::cycles(13, 3));
    run("philosophers 10", &samples::philosophers(10));
    run("philosophers 12", &samples::philosophers(12));
    let t = Instant::now();
    let net = samples::cycles(25, 4);
    let p = alba_net::analysis::invariants::p_invariants(&net, 200_000).map(|v| v.len());
    let tt = alba_net::analysis::invariants::t_invariants(&net, 200_000).map(|v| v.len());
    println!(
        "invariants on 100 places (25 4-cycles): {p:?} P, {tt:?} T in {:.3} s",
        t.elapsed().as_secs_f64()
    );
}
