#!/usr/bin/env bash
# Second command of the README: run every test of Alba.
#   formatting and lints; the studio's type check, unit tests (Vitest) and build;
#   unit/integration/property tests of every crate (golden traces in all engine
#   modes, examples, the malformed-input corpus, fuzz regressions, the HTTP API,
#   kill -9 of retentive data); end-to-end tests in a real browser (Chromium driven
#   by playwright-core); the AVR toolchain building for every board; smoke runs
#   of the simulator and of `alba bench`; the Modbus TCP server against pymodbus
#   and libmodbus clients, the OPC UA server against asyncua, the OPC UA client
#   ([[opcua_server]]) against asyncua's server, the Modbus master
#   (--io modbus) against pymodbus slaves over TCP and RTU, the MQTT client (JSON and
#   Sparkplug B) against Mosquitto with paho-mqtt and pysparkplug (tests/protocols/).
set -euo pipefail
cd "$(dirname "$0")"
source scripts/common.sh
need_rust
step() { printf '\n== %s\n' "$*"; }
# Every test's scratch projects, sockets and browser profiles go under one directory,
# removed when the run ends, pass or fail (std::env::temp_dir and mktemp read TMPDIR).
# Open like /tmp itself (1777): PostgreSQL and Mosquitto run as their own users and
# must reach the files the tests make for them.
scratch="$(mktemp -d "${TMPDIR:-/tmp}/alba-test.XXXXXX")"
chmod 1777 "$scratch"
trap 'rm -rf "$scratch"' EXIT
export TMPDIR="$scratch"

step "format; docs/ARCHITECTURE.md's crate table against the manifests"
cargo fmt --all -- --check
python3 scripts/check-architecture.py
step "studio: npm packages, build (with its type check), unit tests"
build_web
(cd web && npm test --silent)
step "AVR toolchain and simavr (the firmware tests of cargo test use them)"
source scripts/avr.sh
need_avr
export ALBA_AVR_CACHE="$PWD/target/avr/cache"
step "PostgreSQL and Mosquitto (the shared historian's tests start their own server and broker on loopback), libfaketime"
need_postgres
need_mosquitto
need_faketime
step "lints: clippy on every crate and target (a few minutes on a first run)"
cargo clippy --workspace --all-targets --locked -- -D warnings
step "tests: every crate's unit, integration, golden, property and fuzz-regression tests"
cargo test --workspace --locked
# `cargo test` built the `alba` binary for the CLI's integration tests; every
# step below uses that one (a separate `cargo build -p alba-cli` would unify
# features differently and rebuild dozens of crates).
TARGET="$(cd "${CARGO_TARGET_DIR:-target}" && pwd)"
ALBA="$TARGET/debug/alba"
[ -x "$ALBA" ] || { echo "error: cargo test did not leave $ALBA" >&2; exit 1; }
step "browser end-to-end tests (screenshots in target/e2e/)"
need_chromium
mkdir -p target/e2e
(cd web && ALBA_BIN="$ALBA" E2E_OUT="$PWD/../target/e2e" node --test e2e/)
step "protocols: pymodbus, libmodbus and asyncua clients against alba run --modbus --opcua; alba run --io modbus against pymodbus slaves; Mosquitto with paho-mqtt and pysparkplug against alba run --mqtt"
tests/protocols/run.sh "$ALBA"
step "Arduino: every example's sketch builds for uno, nano and mega (no warnings); the simavr harness checks itself"
# (The PID examples are refused, E501, until the PID instruction runs on the board.)
for ex in examples/*/; do
    for board in uno nano mega; do
        if out=$("$ALBA" export arduino "$ex" --board "$board" -o "target/avr/export/$board" --build 2>&1); then
            echo "$(basename "$ex") $(tail -1 <<<"$out")"
        elif grep -q '^error\[E501\]: PID does not run on the board' <<<"$out" && grep -q 'PID(' "$ex"/*.lad; then
            echo "$(basename "$ex"): refused, as it should be (PID is not on the board yet)"
            break
        elif [ "$board" != mega ] && grep -q '^model = "mega"' "$ex/alba.toml" && grep -q '^error\[E104\].* has no pin' <<<"$out"; then
            # wired in its [board] for the Mega's pins: refused on a smaller board, at the tag
            echo "$(basename "$ex"): refused on the $board, as it should be (its [board] wires Mega pins)"
        else
            echo "$out"
            exit 1
        fi
    done
done
tools/simavr/test.sh
step "Arduino controller mode: remote-I/O firmware for every board and link; the host driver against it in simavr, with faults"
ALBA="$ALBA" tools/simavr/controller.sh
step "demo and benchmark smoke runs"
"$ALBA" sim examples/tank --until 2000 --every 1000 --tags Nivel_m,Nivel_L \
    | diff - <(printf 'time_ms,Nivel_m,Nivel_L\n0,0.8431085,33.72434\n1000,0.8431085,33.72434\n2000,0.8431085,33.72434\n')
"$ALBA" bench --quick --sizes 100 >/dev/null
"$ALBA" bench --nets --quick >/dev/null
"$ALBA" bench --realtime --seconds 0.2 >/dev/null
step "all tests passed"
