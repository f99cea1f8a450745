#!/usr/bin/env bash
# Builds the simavr harness and runs the AVR smoke sketch (scripts/avr-smoke.cpp)
# on an emulated ATmega328P: the trace must equal smoke-expected.csv (written by
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
build_sketch scripts/avr-smoke.cpp uno "$out/smoke"
"$out/alba-simavr" "$out/smoke/sketch.elf" --until 400 --every 50 --pins D13,D8,D12 \
    --stimulus tools/simavr/smoke-stimulus.csv >"$out/smoke-trace.csv"
diff tools/simavr/smoke-expected.csv "$out/smoke-trace.csv"
echo "simavr: the smoke sketch's trace is as expected"
