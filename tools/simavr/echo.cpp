// Harness test sketch (tools/simavr/test.sh): D13 = D2, D12 = !D2,
// D6 = analogRead(A4) / 4 as PWM, D8 toggles every 100 ms of millis().
#include <Arduino.h>

static unsigned long last;

void setup() {
    pinMode(2, INPUT);
    pinMode(13, OUTPUT);
    pinMode(12, OUTPUT);
    pinMode(8, OUTPUT);
    pinMode(6, OUTPUT);
    last = 0;
}

void loop() {
    GPIOR0 = 1;  // scan profile (the harness counts cycles between 1 and 0)
    int in = digitalRead(2);
    digitalWrite(13, in);
    digitalWrite(12, !in);
    analogWrite(6, analogRead(A4) / 4);
    // last += 100 (not last = now): millis() skips a value every 42 ms or so
    if (millis() - last >= 100) {
        last += 100;
        digitalWrite(8, !digitalRead(8));
    }
    GPIOR0 = 0;
}
