#!/usr/bin/env bash
# Second command of the README: run every test of Alba.
#   formatting and lints, unit/integration/property tests of every crate
#   (golden traces in all engine modes, examples, the malformed-input corpus,
#   fuzz regressions), then a smoke run of the demo and of `alba bench`.
set -euo pipefail
cd "$(dirname "$0")"
source scripts/common.sh
need_rust
step() { printf '\n== %s\n' "$*"; }

step "format"
cargo fmt --all -- --check
step "lints"
cargo clippy --workspace --all-targets --locked -q -- -D warnings
step "tests"
cargo test --workspace --locked
step "demo and benchmark smoke runs"
cargo run -q --locked -p alba-cli -- sim examples/tank --until 2000 --every 1000 --tags Nivel_m,Nivel_L \
    | diff - <(printf 'time_ms,Nivel_m,Nivel_L\n0,0.8431085,33.72434\n1000,0.8431085,33.72434\n2000,0.8431085,33.72434\n')
cargo run -q --locked -p alba-cli -- bench --quick --sizes 100 >/dev/null
step "all tests passed"
