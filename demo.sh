#!/usr/bin/env bash
# First command of the README: build Alba and run the tank example in the
# simulator (virtual time), printing its trace. (The browser studio replaces
# this demo in a later version.)
set -euo pipefail
cd "$(dirname "$0")"
source scripts/common.sh
need_rust
echo "Building alba (release)..." >&2
cargo build --release --locked -q -p alba-cli
ALBA="${CARGO_TARGET_DIR:-target}/release/alba"
echo >&2
echo "== The tank of AuroraLD (examples/tank): 14 s of simulated time, a row every 0.5 s ==" >&2
echo "   S_ULT is the raw level (0-1023), Nivel_m/Nivel_L the scaled level; see examples/tank/README.md" >&2
echo >&2
"$ALBA" check examples/tank
table() { if command -v column >/dev/null 2>&1; then column -s, -t; else cat; fi; }
"$ALBA" sim examples/tank --stimulus examples/tank/stimulus.csv $(cat examples/tank/golden.args) | table
echo >&2
echo "Next: $ALBA new my-plant && $ALBA sim my-plant --until 10000 --every 500 --stimulus my-plant/stimulus.csv" >&2
