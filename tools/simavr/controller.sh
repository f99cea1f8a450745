#!/usr/bin/env bash
# Controller mode (docs/arduino.md, SPEC 7.2), checked without hardware:
#  - `alba firmware` generates the remote-I/O firmware for uno, nano and mega with
#    both links (Modbus RTU, AuroraLD), and each builds with -Wall -Werror and fits;
#  - the host driver runs end to end against the firmware in simavr through a
#    pseudo-terminal (tools/simavr/board.c): inputs reach the program, outputs the
#    pins; unplug/replug; fault injection (bad CRC, truncated frames, silence,
#    garbage) with the outputs in the safe state during the loss and recovery after.
# Prints flash/RAM per board and the measured round trip, cycle rate and recovery
# times. Used by ./test.sh (after need_avr).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cd "$here/../.."
source scripts/common.sh
source scripts/avr.sh
need_avr
out=target/avr/firmware
mkdir -p "$out"
# ./test.sh passes the binary its `cargo test --workspace` built (ALBA); run
# alone, this builds it. Cargo runs with --workspace so that features unify as
# in `cargo test --workspace` and nothing already built is compiled again.
if [ -z "${ALBA:-}" ]; then
    cargo build -q --locked --workspace --bin alba
    ALBA="$(cd "${CARGO_TARGET_DIR:-target}" && pwd)/debug/alba"
fi
alba="$ALBA"
for link in modbus aurora; do
    for bm in uno:openplc nano:aurora mega:aurora; do
        b=${bm%%:*} map=${bm##*:}
        printf '%s link, ' "$link"
        "$alba" firmware --board "$b" --pinmap "$map" --link "$link" -o "$out/$link-$b" --build 2>&1 >/dev/null | tail -1
    done
done
cargo test -q --locked --workspace --test board -- --ignored --nocapture 2>&1 \
    | grep -v -e '^$' -e '^running' -e '^test result' -e '^nano: flash'
