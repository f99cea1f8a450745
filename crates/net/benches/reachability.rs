//! Reachability benchmark: `cargo bench -p alba-net` (release). Prints states/s and
//! bytes/state for generated nets (`alba_net::analysis::bench`, also `alba bench --nets`)
//! and for the Model Checking Contest's `Kanban-PT-00005` (2 546 432 states),
//! `FMS-PT-00005` (2 895 018) and `RobotManipulation-PT-00010` (20 030 010) from the
//! test corpus (tests/mcc), each checked against the contest's state count. `--quick`
//! leaves out the 20 M-state model. `--symbolic [NAME…]` times the symbolic engine
//! (`alba_net::analysis::symbolic`) instead, on the same models and the corpus's
//! instances of 10^9 states and more (or on the instances named), each checked against
//! the contest's counts, then again with the facts (deadlocks and a trace to one, dead
//! transitions, liveness, reversibility). `NAME…` alone analyses just the corpus's
//! instances named; `--threads=N` sets the analysis's threads (default: the available
//! parallelism, at most 2).

#[path = "../tests/mcc/corpus.rs"]
mod corpus;

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--") || a == "--symbolic")
        .collect();
    if args.first().map(String::as_str) == Some("--symbolic") {
        symbolic(&args[1..]);
        return;
    }
    let quick = std::env::args().any(|a| a == "--quick");
    let threads = std::env::args()
        .find_map(|a| a.strip_prefix("--threads=").and_then(|n| n.parse().ok()))
        .unwrap_or_else(alba_net::analysis::default_threads);
    let mut names = vec!["Kanban-PT-00005", "FMS-PT-00005"];
    if !args.is_empty() {
        names = args.iter().map(String::as_str).collect();
    } else {
        print!("{}", alba_net::analysis::bench::run(quick));
        if !quick {
            names.push("RobotManipulation-PT-00010");
        }
    }
    let all = corpus::load();
    for i in names.into_iter().filter_map(|name| instance(&all, name)) {
        let name = i.name.as_str();
        let net = corpus::net(i);
        let (report, states) = alba_net::analysis::bench::measure(name, &net, threads);
        let want = i.state_space("STATES");
        print!("{report}");
        if Some(states) != want {
            println!("  MISMATCH: the contest says {want:?} states");
        }
    }
}

/// `--symbolic`: time, nodes and memory of the symbolic engine per instance.
fn symbolic(names: &[String]) {
    use alba_net::analysis::symbolic::{Limits, Stop, explore};
    let defaults = [
        "Kanban-PT-00005",
        "FMS-PT-00005",
        "RobotManipulation-PT-00010",
        "Kanban-PT-00050",
        "FMS-PT-00050",
        "Philosophers-PT-000100",
    ];
    let names: Vec<&str> = if names.is_empty() {
        defaults.to_vec()
    } else {
        names.iter().map(String::as_str).collect()
    };
    let all = corpus::load();
    for i in names.into_iter().filter_map(|name| instance(&all, name)) {
        let name = i.name.as_str();
        let net = corpus::net(i);
        let o = explore(&net, &Limits::default(), &std::sync::atomic::AtomicBool::new(false));
        let want = i.state_space_text("STATES").unwrap_or_default();
        match o.result {
            Ok(s) => println!(
                "{name}: {} states{} in {:.3} s, {} nodes made ({} in the result), {:.1} MiB",
                s.states,
                if s.states.to_string() == want { "" } else { " MISMATCH" },
                o.time.as_secs_f64(),
                o.nodes,
                s.final_nodes,
                o.bytes as f64 / (1 << 20) as f64
            ),
            Err(why) => {
                println!(
                    "{name}: stopped ({}) after {:.3} s, {} nodes, {:.1} MiB",
                    why.reason(),
                    o.time.as_secs_f64(),
                    o.nodes,
                    o.bytes as f64 / (1 << 20) as f64
                );
                continue;
            }
        }
        // Again with the facts: deadlocks and a trace to one, dead transitions,
        // liveness, reversibility.
        let limits = Limits {
            facts: true,
            ..Limits::default()
        };
        let o = explore(&net, &limits, &std::sync::atomic::AtomicBool::new(false));
        let Some(f) = o.result.ok().and_then(|s| s.facts) else {
            println!("  with the facts: stopped after {:.3} s", o.time.as_secs_f64());
            continue;
        };
        let shown = |r: Result<String, Stop>| r.unwrap_or_else(|why| format!("unknown ({})", why.reason()));
        println!(
            "  with the facts: {:.3} s, {} nodes made, {:.1} MiB; deadlocks {}, trace {}, dead transitions {}, live {}, reversible {}",
            o.time.as_secs_f64(),
            o.nodes,
            o.bytes as f64 / (1 << 20) as f64,
            shown(f.deadlocks.map(|c| c.to_string())),
            shown(f.deadlock_trace.map(|t| match t {
                Some((t, _)) => format!("of {} firings", t.len()),
                None => "none".into(),
            })),
            shown(f.dead_transitions.map(|d| d.len().to_string())),
            shown(f.live.map(|l| l.to_string())),
            shown(f.reversible.map(|r| r.to_string())),
        );
    }
}

/// The corpus's instance `name`, or a line saying it is not there.
fn instance<'a>(all: &'a [corpus::Instance], name: &str) -> Option<&'a corpus::Instance> {
    let found = all.iter().find(|i| i.name == name);
    if found.is_none() {
        println!("{name}: not in the corpus");
    }
    found
}
