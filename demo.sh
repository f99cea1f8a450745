#!/usr/bin/env bash
# First command of the README: build Alba (studio included) and start the
# studio on the tank example with its simulated plant. Open the URL it prints;
# Ctrl-C stops it. Options are passed to `alba demo` (e.g. --http 127.0.0.1:9000).
set -euo pipefail
cd "$(dirname "$0")"
source scripts/common.sh
need_rust
build_web
echo "Building alba (release)..." >&2
cargo build --release --locked -q -p alba-cli
ALBA="${CARGO_TARGET_DIR:-target}/release/alba"
exec "$ALBA" demo "$@"
