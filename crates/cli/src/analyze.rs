//! `alba analyze NET.pnml [--json] [--max-states N] [--memory SIZE] [--invariants
//! flows|minimal] [--invariant-budget N] [--symbolic] [--threads N]`: the analysis of the
//! net's underlying place/transition net (docs/nets.md, section "analysis"; SPEC §10.5).
//! With `--examination E [--formulas FILE.xml] [--trace]`: the Model Checking Contest's
//! examination E instead, in the contest's output form (docs/nets.md, "Contest
//! examinations").

use alba_diag::{Files, render_all};
use alba_net::PtNet;
use alba_net::analysis::formula::{self, Property};
use alba_net::analysis::stubborn::{self, CheckOptions, Verdict};
use alba_net::analysis::{
    Analysis, Bound, Control, Invariants, Options, Space, Status, SymbolicMode, analyze, to_json,
};
use alba_net::colored::Unfolding;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

/// `--invariants`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum InvariantsArg {
    /// A basis of the P- and T-flows.
    Flows,
    /// The basis and the minimal semi-positive invariants.
    Minimal,
}

/// `--examination`: the contest's names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Examination {
    /// The largest token sum of each formula's places (`<place-bound>`).
    #[value(name = "UpperBounds")]
    UpperBounds,
    /// EF/AG formulas over token counts.
    #[value(name = "ReachabilityCardinality")]
    ReachabilityCardinality,
    /// EF/AG formulas over fireability.
    #[value(name = "ReachabilityFireability")]
    ReachabilityFireability,
    /// Whether a dead marking is reachable (no formula file).
    #[value(name = "ReachabilityDeadlock")]
    ReachabilityDeadlock,
}

impl Examination {
    fn name(self) -> &'static str {
        match self {
            Examination::UpperBounds => "UpperBounds",
            Examination::ReachabilityCardinality => "ReachabilityCardinality",
            Examination::ReachabilityFireability => "ReachabilityFireability",
            Examination::ReachabilityDeadlock => "ReachabilityDeadlock",
        }
    }
}

/// `--examination`, `--formulas`, `--trace`.
pub struct Contest {
    /// The examination.
    pub examination: Examination,
    /// Its formula file, if not the one beside the model.
    pub formulas: Option<PathBuf>,
    /// Print the traces.
    pub trace: bool,
}

/// The command's limits.
pub struct Limits {
    /// `--max-states`.
    pub max_states: Option<usize>,
    /// `--memory`.
    pub memory: Option<usize>,
    /// `--invariants`.
    pub invariants: InvariantsArg,
    /// `--invariant-budget`.
    pub invariant_budget: Option<u64>,
    /// `--symbolic`.
    pub symbolic: bool,
    /// `--threads`.
    pub threads: Option<usize>,
}

/// A size: bytes, or a number with K, M or G (powers of 1 024, an optional `B` or `iB`).
pub fn parse_size(s: &str) -> Result<usize, String> {
    let t = s.trim();
    let upper = t.to_ascii_uppercase();
    let body = upper.trim_end_matches("IB").trim_end_matches('B');
    let (digits, shift) = match body.chars().last() {
        Some('K') => (&body[..body.len() - 1], 10),
        Some('M') => (&body[..body.len() - 1], 20),
        Some('G') => (&body[..body.len() - 1], 30),
        Some('T') => (&body[..body.len() - 1], 40),
        _ => (body, 0),
    };
    digits
        .trim()
        .parse::<usize>()
        .ok()
        .and_then(|n| n.checked_mul(1usize << shift))
        .filter(|&n| n > 0)
        .ok_or_else(|| format!("`{s}` is not a size (bytes, or a number with K, M or G)"))
}

/// Three quarters of the memory available (`MemAvailable`), or the library's default.
fn default_memory() -> usize {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
            line.split_whitespace().nth(1)?.parse::<usize>().ok()
        })
        .map_or(alba_net::analysis::DEFAULT_MEMORY, |kib| kib / 4 * 3 * 1024)
}

/// A file as UTF-8 text, or the error line.
fn read_text(path: &Path) -> Result<String, String> {
    match std::fs::read(path) {
        Ok(bytes) => String::from_utf8(bytes).map_err(|_| format!("{}: the file is not UTF-8 text", path.display())),
        Err(e) => Err(format!("cannot read {}: {e}", path.display())),
    }
}

/// Runs the command. `path` may be a contest instance's folder (its `model.pnml`).
pub fn run(path: &Path, as_json: bool, limits: Limits, contest: Option<Contest>) -> ExitCode {
    let model = if path.is_dir() {
        path.join("model.pnml")
    } else {
        path.to_path_buf()
    };
    let path = model.as_path();
    let text = match read_text(path) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut files = Files::default();
    let file = files.add(path.display().to_string(), text.clone());
    let started = std::time::Instant::now();
    let (net, diags, unfolding) = alba_net::load_for_analysis(file, &text);
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
    if let Some(u) = &unfolding {
        eprintln!(
            "note: a coloured net (symmetric net), unfolded: {} coloured places and {} transitions ({} bindings) became {} places and {} transitions in {:.3} s",
            u.coloured_places,
            u.coloured_transitions,
            u.bindings,
            pt.places.len(),
            pt.transitions.len(),
            started.elapsed().as_secs_f64()
        );
    }
    if let Some(c) = contest {
        return examine(path, &pt, unfolding.as_ref(), as_json, &limits, &c);
    }
    let mut options = Options {
        memory: limits.memory.unwrap_or_else(default_memory),
        invariants: match limits.invariants {
            InvariantsArg::Flows => Invariants::Flows,
            InvariantsArg::Minimal => Invariants::Minimal,
        },
        symbolic: if limits.symbolic {
            SymbolicMode::Always
        } else {
            SymbolicMode::Auto
        },
        ..Options::default()
    };
    if let Some(n) = limits.max_states {
        options.max_states = n;
    }
    if let Some(n) = limits.invariant_budget {
        options.invariant_work = n;
    }
    if let Some(n) = limits.threads {
        options.threads = n;
    }
    let a = analyze(&pt, &options, &Control::none());
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

/// `--examination`: reads the formulas, answers them ([`stubborn::answer`]) within the
/// state limit and the memory budget, prints one `FORMULA` line each (or JSON). A
/// coloured model's formulas name its coloured places and transitions (`unfolding`);
/// traces name the unfolded transitions.
fn examine(
    model: &Path,
    pt: &PtNet,
    unfolding: Option<&Unfolding>,
    as_json: bool,
    limits: &Limits,
    c: &Contest,
) -> ExitCode {
    let props: Vec<Property> = if c.examination == Examination::ReachabilityDeadlock {
        if let Some(f) = &c.formulas {
            eprintln!(
                "error: {}: ReachabilityDeadlock has no formula file (it is EF deadlock)",
                f.display()
            );
            return ExitCode::FAILURE;
        }
        vec![formula::deadlock_property()]
    } else {
        let file = c.formulas.clone().unwrap_or_else(|| {
            model
                .parent()
                .unwrap_or(Path::new("."))
                .join(format!("{}.xml", c.examination.name()))
        });
        let text = match read_text(&file) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        match formula::parse_for(&text, pt, unfolding) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("error: {}:{e}", file.display());
                return ExitCode::FAILURE;
            }
        }
    };
    let mut options = CheckOptions::default();
    if let Some(n) = limits.max_states {
        options.max_states = n;
    }
    let memory = limits.memory.unwrap_or_else(default_memory);
    // The memory budget: the exploration reports its bytes as it goes; past the budget
    // it is cancelled and the undecided formulas are CANNOT_COMPUTE.
    let cancel = AtomicBool::new(false);
    let over = AtomicBool::new(false);
    let progress = |p: &alba_net::analysis::Progress| {
        if p.bytes > memory {
            over.store(true, Ordering::Relaxed);
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let control = Control {
        cancel: &cancel,
        progress: &progress,
    };
    let answers = stubborn::answer(pt, &props, &options, &control);
    if over.load(Ordering::Relaxed) {
        eprintln!("warning: the exploration reached the memory budget ({memory} bytes, --memory)");
    }
    for a in &answers {
        if let Verdict::Unknown(why) = &a.verdict {
            let why = if *why == "state limit" {
                "the state limit (--max-states)"
            } else if *why == "cancelled" && over.load(Ordering::Relaxed) {
                "the memory budget (--memory)"
            } else {
                why
            };
            eprintln!("warning: {}: not decided: {why}", a.id);
        }
    }
    if as_json {
        println!("{}", stubborn::answers_json(pt, c.examination.name(), &answers));
    } else {
        let mut out = String::new();
        for a in &answers {
            out.push_str(&format!("{a}\n"));
            if c.trace
                && let Some(t) = a.trace_ids(pt)
            {
                let seq = if t.is_empty() {
                    "(the initial marking)".to_string()
                } else {
                    t.join(" ")
                };
                out.push_str(&format!("  trace {}: {seq}\n", a.id));
            }
        }
        print!("{out}");
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
    match (&a.status.symbolic, &a.symbolic.result) {
        (Status::Skipped("not requested"), _) => {}
        (Status::Complete, Some(s)) => line(format!(
            "symbolic (decision diagrams): {} states, {} edges ({} nodes, {} in the result, {:.3} s)",
            s.states,
            s.firings,
            a.symbolic.nodes,
            s.final_nodes,
            a.symbolic.time.as_secs_f64()
        )),
        (st, _) => line(format!(
            "symbolic (decision diagrams): {st} ({} nodes, {:.3} s)",
            a.symbolic.nodes,
            a.symbolic.time.as_secs_f64()
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
                    "  {}firing sequence to one: {}",
                    if a.deadlock_trace_shortest { "shortest " } else { "" },
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
    let st = &a.status;
    let mut out = Vec::new();
    invariant_lines(
        &mut out,
        "P-flows, a basis",
        &a.p_flows,
        &st.p_flows,
        &pt.places,
        Some(&pt.initial),
    );
    invariant_lines(
        &mut out,
        "T-flows, a basis",
        &a.t_flows,
        &st.t_flows,
        &pt.transitions,
        None,
    );
    if matches!(st.p_invariants, Status::Skipped("not requested")) {
        out.push("minimal invariants: not requested (--invariants flows)".into());
    } else {
        invariant_lines(
            &mut out,
            "P-invariants",
            &a.p_invariants,
            &st.p_invariants,
            &pt.places,
            Some(&pt.initial),
        );
        invariant_lines(
            &mut out,
            "T-invariants",
            &a.t_invariants,
            &st.t_invariants,
            &pt.transitions,
            None,
        );
    }
    out.push(format!(
        "status: state space {}, liveness/reversibility {}, P-flows {}, T-flows {}, P-invariants {}, T-invariants {}, symbolic {}, symbolic facts {}",
        st.state_space,
        st.components,
        st.p_flows,
        st.t_flows,
        st.p_invariants,
        st.t_invariants,
        st.symbolic,
        st.symbolic_facts
    ));
    for l in out {
        line(l);
    }
    s
}

/// `a - b + 2·c`: a weighted sum of ids.
fn weighted_sum(y: &[i64], ids: &[String]) -> String {
    let mut out = String::new();
    for (i, &c) in y.iter().enumerate().filter(|(_, c)| **c != 0) {
        let sign = if c < 0 { "-" } else { "+" };
        if out.is_empty() {
            if c < 0 {
                out.push('-');
            }
        } else {
            out.push_str(&format!(" {sign} "));
        }
        match c.unsigned_abs() {
            1 => out.push_str(&ids[i]),
            k => out.push_str(&format!("{k}·{}", ids[i])),
        }
    }
    out
}

/// The lines of one list of invariants (with the weighted sum of the initial marking
/// for P-invariants), or why it is missing.
fn invariant_lines(
    out: &mut Vec<String>,
    what: &str,
    r: &alba_net::analysis::InvariantList,
    status: &Status,
    ids: &[String],
    initial: Option<&[u32]>,
) {
    match r {
        Ok(v) => {
            out.push(format!("{what} ({}):", v.len()));
            for y in v {
                match initial {
                    Some(m0) => {
                        let w: i64 = y.iter().zip(m0).map(|(c, &m)| c * i64::from(m)).sum();
                        out.push(format!("  {} = {w}", weighted_sum(y, ids)));
                    }
                    None => out.push(format!("  {}", weighted_sum(y, ids))),
                }
            }
        }
        Err(e) => out.push(format!("{what}: {status} ({e})")),
    }
}
