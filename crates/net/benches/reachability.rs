//! Reachability benchmark: `cargo bench -p alba-net` (release). Prints states/s and
//! bytes/state for 13 independent 3-place cycles (3^13 = 1 594 323 states), the dining
//! philosophers and the Kanban model with 5 kanbans (2 546 432 states), and the invariant
//! time on a 100-place net (`alba_net::analysis::bench`, also `alba bench --nets`).

fn main() {
    print!(
        "{}",
        alba_net::analysis::bench::run(std::env::args().any(|a| a == "--quick"))
    );
}
