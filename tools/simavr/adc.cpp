// Harness test sketch (tools/simavr/test.sh): the 10-bit analogRead(A0) on D0-D9 (PORTD = low
// byte, D8/D9 = bits 8/9), so the trace shows that a stimulus reading v reads v.
#include <Arduino.h>

void setup() {
    DDRD = 0xff;
    pinMode(8, OUTPUT);
    pinMode(9, OUTPUT);
}

void loop() {
    int v = analogRead(A0);
    PORTD = v & 0xff;
    digitalWrite(8, (v >> 8) & 1);
    digitalWrite(9, (v >> 9) & 1);
}
