//! `alba analyze NET.pnml [--json] [--max-states N]`: the analysis of the net's underlying
//! place/transition net (docs/nets.md, section "analysis"; SPEC §10.5).

use alba_diag::{Files, render_all};
use alba_net::PtNet;
use alba_net::analysis::{Analysis, Bound, Options, Space, analyze, to_json};
use std::path::Path;
use std::process::ExitCode;

/// Runs the command.
pub fn run(path: &Path, as_json: bool, max_states: Option<usize>) -> ExitCode {
    let text = match std::fs::read(path) {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(t) => t,
            Err(_) => {
                eprintln!("error: {}: the file is not UTF-8 text", path.display());
                return ExitCode::FAILURE;
            }
        },
        Err(e) => {
            eprintln!("error: cannot read {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
    };
    let mut files = Files::default();
    let file = files.add(path.display().to_string(), text.clone());
    let (net, diags) = alba_net::load(file, &text);
    let (warnings, errors): (Vec<_>, Vec<_>) = diags.into_iter().partition(alba_net::is_warning);
    for w in &warnings {
        eprint!("{}", w.render_warning(&files));
    }
    let net = match net {
        Some(n) if errors.is_empty() => n,
        _ => {
            eprint!("{}", render_all(&errors, &files));
            return ExitCode::FAILURE;
        }
    };
    let pt = PtNet::from_net(&net);
    let mut options = Options::default();
    if let Some(n) = max_states {
        options.max_states = n;
    }
    let a = analyze(&pt, &options, &|| false);
    if let Some(msg) = &a.stopped {
        eprintln!("warning: {msg}");
    }
    if as_json {
        println!("{}", to_json(&pt, &a));
    } else {
        print!("{}", report(&net.id, path, &pt, &a));
    }
    ExitCode::SUCCESS
}

fn yes(b: Option<bool>) -> &'static str {
    match b {
        Some(true) => "yes",
        Some(false) => "no",
        None => "unknown",
    }
}

fn report(id: &str, path: &Path, pt: &PtNet, a: &Analysis) -> String {
    let mut s = String::new();
    let mut line = |l: String| {
        s.push_str(&l);
        s.push('\n');
    };
    line(format!(
        "net {id} ({}): {} places, {} transitions",
        path.display(),
        a.places,
        a.transitions
    ));
    for n in &a.notes {
        line(format!("note: {n}"));
    }
    match a.space {
        Space::Reachability => line(format!(
            "state space: reachability graph, {} states, {} edges, {} strongly connected components ({:.3} s)",
            a.states.unwrap_or(0),
            a.edges.unwrap_or(0),
            a.components.unwrap_or(0),
            (a.explore_time + a.scc_time).as_secs_f64()
        )),
        Space::Coverability => line(format!(
            "state space: Karp–Miller coverability graph, {} nodes ({:.3} s)",
            a.states.unwrap_or(0),
            a.explore_time.as_secs_f64()
        )),
        Space::Incomplete => line(format!(
            "state space: incomplete — {}",
            a.stopped.as_deref().unwrap_or("")
        )),
    }
    line(format!("bounded: {}, safe: {}", yes(a.bounded), yes(a.safe)));
    if let Some(b) = &a.place_bounds {
        let list: Vec<String> = b
            .iter()
            .enumerate()
            .map(|(i, v)| match v {
                Bound::Finite(n) => format!("{} ≤ {n}", pt.places[i]),
                Bound::Omega => format!("{} unbounded (ω)", pt.places[i]),
            })
            .collect();
        line(format!("place bounds: {}", list.join(", ")));
    }
    match a.deadlocks {
        Some(0) => line("deadlocks: none".into()),
        Some(n) => {
            line(format!("deadlocks: {n} dead marking{}", if n == 1 { "" } else { "s" }));
            if let Some(t) = &a.deadlock_trace {
                let seq: Vec<&str> = t.iter().map(|&i| pt.transitions[i].as_str()).collect();
                line(format!(
                    "  shortest firing sequence to one: {}",
                    if seq.is_empty() {
                        "(the initial marking)".to_string()
                    } else {
                        seq.join(" ")
                    }
                ));
            }
            if let Some(m) = &a.deadlock_marking {
                let marked: Vec<String> = m
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| **v > 0)
                    .map(|(i, v)| {
                        if *v == 1 {
                            pt.places[i].clone()
                        } else {
                            format!("{}×{v}", pt.places[i])
                        }
                    })
                    .collect();
                line(format!(
                    "  dead marking: {}",
                    if marked.is_empty() {
                        "(empty)".to_string()
                    } else {
                        marked.join(", ")
                    }
                ));
            }
        }
        None => line("deadlocks: unknown".into()),
    }
    match &a.dead_transitions {
        Some(d) if d.is_empty() => line("dead transitions: none".into()),
        Some(d) => {
            let names: Vec<&str> = d.iter().map(|&t| pt.transitions[t].as_str()).collect();
            line(format!("dead transitions: {}", names.join(", ")));
        }
        None => line("dead transitions: unknown".into()),
    }
    line(format!("live (L4): {}", yes(a.live)));
    line(format!("reversible: {}", yes(a.reversible)));
    let sum = |y: &[i64], ids: &[String]| -> String {
        y.iter()
            .enumerate()
            .filter(|(_, c)| **c != 0)
            .map(|(i, &c)| {
                if c == 1 {
                    ids[i].clone()
                } else {
                    format!("{c}·{}", ids[i])
                }
            })
            .collect::<Vec<_>>()
            .join(" + ")
    };
    match &a.p_invariants {
        Ok(v) => {
            line(format!("P-invariants ({}):", v.len()));
            for y in v {
                let w: i64 = y.iter().zip(&pt.initial).map(|(c, &m)| c * i64::from(m)).sum();
                line(format!("  {} = {w}", sum(y, &pt.places)));
            }
        }
        Err(e) => line(format!("P-invariants: not computed ({e})")),
    }
    match &a.t_invariants {
        Ok(v) => {
            line(format!("T-invariants ({}):", v.len()));
            for x in v {
                line(format!("  {}", sum(x, &pt.transitions)));
            }
        }
        Err(e) => line(format!("T-invariants: not computed ({e})")),
    }
    s
}
