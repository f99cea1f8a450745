#!/usr/bin/env bash
# Builds the simavr harness (alba-simavr, harness.c) and checks it on two sketches:
#  - echo.cpp built for uno, nano and mega (-Wall -Werror): its trace in simavr
#    must equal echo-expected.csv, written by hand from the sketch (D13 = D2 and
#    D12 = !D2 one sample after D2 changes, D8 toggles just after every 100 ms of
#    simulated time, D6's PWM duty is analogRead(A4)/4, 255 being a plain HIGH);
#  - adc.cpp on uno: every reading 0-1023 given for A0 is what analogRead returns.
# Exits non-zero on any mismatch. Used by ./test.sh.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cd "$here/../.."
source scripts/common.sh
source scripts/avr.sh
need_avr
out=target/avr/simavr
mkdir -p "$out"
build_harness "$out/alba-simavr"

for board in uno:atmega328p nano:atmega328p mega:atmega2560; do
    b=${board%%:*} mcu=${board##*:}
    build_sketch "$here/echo.cpp" "$b" "$out/echo-$b"
    "$out/alba-simavr" "$out/echo-$b/sketch.elf" -m "$mcu" --until 400 --every 10 \
        --pins D13,D12,D8,D6:pwm --stimulus "$here/echo-stimulus.csv" -o "$out/echo-$b.csv" 2>"$out/echo-$b.log"
    grep -q "^alba-simavr: scans [1-9][0-9]* cycles min [1-9]" "$out/echo-$b.log" \
        || { cat "$out/echo-$b.log"; echo "no scan profile from echo.cpp" >&2; exit 1; }
    diff "$here/echo-expected.csv" "$out/echo-$b.csv"
    echo "simavr ($b): echo.cpp's trace is as expected"
done

build_sketch "$here/adc.cpp" uno "$out/adc-uno"
for v in $(seq 0 1023); do echo "$((v + 1)),A0,$v"; done >"$out/adc-stimulus.csv"
"$out/alba-simavr" "$out/adc-uno/sketch.elf" --until 1025 --every 1 \
    --pins D0,D1,D2,D3,D4,D5,D6,D7,D8,D9 --stimulus "$out/adc-stimulus.csv" -o "$out/adc-uno.csv"
# The row at t shows the reading given at t-1 (the value t-2).
awk -F, 'NR > 2 && $1 >= 2 {
    v = 0; for (i = 2; i <= 11; i++) v += $i * 2 ^ (i - 2)
    if (v != $1 - 2) { bad++; if (bad <= 5) print "t=" $1 ": read " v ", expected " ($1 - 2) > "/dev/stderr" }
} END { exit bad > 0 }' "$out/adc-uno.csv"
echo "simavr (uno): analogRead returns each stimulus reading 0-1023 exactly"
