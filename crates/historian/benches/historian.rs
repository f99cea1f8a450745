//! `cargo bench -p alba-historian --bench historian [-- --quick]`: the
//! historian benchmark (`alba_historian::bench`, also `alba bench --historian`).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    alba_historian::bench::run(std::env::args().any(|a| a == "--quick"))
}
