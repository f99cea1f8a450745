// Smoke test of the AVR toolchain (./test.sh): the Arduino core and a sketch that
// uses digital, analog and PWM I/O and millis() build for uno, nano and mega with -Wall -Werror,
// and (tools/simavr/test.sh) runs in simavr as tools/simavr/smoke-expected.csv says.
static unsigned long last;
void setup() {
    pinMode(2, INPUT);
    pinMode(13, OUTPUT);
    pinMode(8, OUTPUT);
    pinMode(12, OUTPUT);
}
void loop() {
    digitalWrite(13, digitalRead(2));
    analogWrite(6, analogRead(A4) / 4);
    digitalWrite(12, analogRead(A4) >= 512);
    if (millis() - last >= 100) {
        last += 100;
        digitalWrite(8, !digitalRead(8));
    }
}
