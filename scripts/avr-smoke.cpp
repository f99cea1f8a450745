// Smoke test of the AVR toolchain (./test.sh): the Arduino core and a sketch that
// uses digital, analog and PWM I/O and millis() build for uno, nano and mega with -Wall -Werror.
static unsigned long last;
void setup() {
    pinMode(2, INPUT);
    pinMode(13, OUTPUT);
    pinMode(8, OUTPUT);
}
void loop() {
    digitalWrite(13, digitalRead(2));
    analogWrite(6, analogRead(A4) / 4);
    if (millis() - last >= 100) {
        last += 100;
        digitalWrite(8, !digitalRead(8));
    }
}
