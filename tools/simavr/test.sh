#!/usr/bin/env bash
# Builds the simavr harness and runs the AVR smoke sketch (scripts/avr-smoke.cpp)
# on an emulated ATmega328P (Uno) and ATmega2560 (Mega): the trace must equal smoke-expected.csv (written by
# hand from the sketch: D13 follows D2, D8 toggles every 100 ms of simulated
# time, D12 is on from an A4 reading of 512, off at 511). Used by ./test.sh.
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/common.sh
source scripts/avr.sh
need_avr
out=target/avr/simavr
mkdir -p "$out"
gcc -O2 -Wall -Wextra -Werror -o "$out/alba-simavr" tools/simavr/harness.c -lsimavr -lelf
for board in uno:atmega328p mega:atmega2560; do
    build_sketch scripts/avr-smoke.cpp "${board%%:*}" "$out/smoke-${board%%:*}"
    "$out/alba-simavr" "$out/smoke-${board%%:*}/sketch.elf" -m "${board##*:}" --until 400 --every 50 \
        --pins D13,D8,D12 --stimulus tools/simavr/smoke-stimulus.csv >"$out/smoke-${board%%:*}.csv"
    diff tools/simavr/smoke-expected.csv "$out/smoke-${board%%:*}.csv"
    echo "simavr (${board##*:}): the smoke sketch's trace is as expected"
done
