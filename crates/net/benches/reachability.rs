//! Reachability benchmark: `cargo bench -p alba-net` (release). Prints states/s and
//! bytes/state for generated nets (`alba_net::analysis::bench`, also `alba bench --nets`)
//! and for the Model Checking Contest's `Kanban-PT-00005` (2 546 432 states),
//! `FMS-PT-00005` (2 895 018) and `RobotManipulation-PT-00010` (20 030 010) from the
//! test corpus (tests/mcc), each checked against the contest's state count. `--quick`
//! leaves out the 20 M-state model.

#[path = "../tests/mcc/corpus.rs"]
mod corpus;

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    print!("{}", alba_net::analysis::bench::run(quick));
    let mut names = vec!["Kanban-PT-00005", "FMS-PT-00005"];
    if !quick {
        names.push("RobotManipulation-PT-00010");
    }
    let all = corpus::load();
    for name in names {
        let Some(i) = all.iter().find(|i| i.name == name) else {
            println!("{name}: not in the corpus");
            continue;
        };
        let net = corpus::net(i);
        let (report, states) = alba_net::analysis::bench::measure(name, &net);
        let want = i.state_space("STATES");
        print!("{report}");
        if Some(states) != want {
            println!("  MISMATCH: the contest says {want:?} states");
        }
    }
}
