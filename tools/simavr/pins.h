/* Pins of the Arduino boards on simavr, shared by the harness (harness.c) and
 * the remote-I/O board (board.c): pin names, port bits, PWM duty, ADC readings.
 * Single-translation-unit helpers (static): include once per program. */
#ifndef ALBA_SIMAVR_PINS_H
#define ALBA_SIMAVR_PINS_H

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sim_avr.h>
#include <sim_elf.h>
#include <sim_irq.h>
#include <sim_io.h>
#include <avr_ioport.h>
#include <avr_adc.h>

#define MAX_PINS 64

/* pwm: sample the analogWrite duty; drive: sample whether the firmware drives the pin. */
typedef struct { int analog, n, pwm, drive; } pin_t;

static int mega;
static avr_t *avr;

static inline void die(const char *msg, const char *arg) {
    fprintf(stderr, "alba-simavr: %s%s\n", msg, arg ? arg : "");
    exit(1);
}

/* simavr logs to stdout by default; errors go to stderr, the rest is dropped
 * (Arduino's phase-correct PWM modes are not emulated and warn on every write). */
static inline void logger(avr_t *a, const int level, const char *fmt, va_list ap) {
    (void)a;
    if (level <= LOG_ERROR) vfprintf(stderr, fmt, ap);
}

/* simavr's default sleep callback usleep()s to keep real time: not here. */
static inline void no_sleep(avr_t *a, avr_cycle_count_t how_long) { (void)a; (void)how_long; }

/* Arduino Mega D0-D69 (A0-A15 = D54-D69): port letter and bit, from the core's
 * variants/mega/pins_arduino.h digital_pin_to_port_PGM / _bit_mask_PGM. */
static const char MEGA_PORT[] = "EEEEGEHHHHBBBBJJHHDDDDAAAAAAAACCCCCCCCDGGGLLLLLLLLBBBBFFFFFFFFKKKKKKKK";
static const char MEGA_BIT[] = "0145533456456710103210012345677654321072107654321032100123456701234567";

/* PWM: for each digital pin, "timer channel" (0 = none), from digital_pin_to_timer_PGM. */
static inline const char *pwm_of(int d) {
    static const char *uno[14] = {0, 0, 0, "2B", 0, "0B", "0A", 0, 0, "1A", "1B", "2A", 0, 0};
    static const char *mg[14] = {0, 0, "3B", "3C", "0B", "3A", "4A", "4B", "4C", "2B", "2A", "1A", "1B", "0A"};
    if (mega) {
        if (d < 14) return mg[d];
        if (d == 44) return "5C";
        if (d == 45) return "5B";
        if (d == 46) return "5A";
        return 0;
    }
    return d < 14 ? uno[d] : 0;
}

static inline pin_t parse_pin(const char *s) {
    pin_t p = {0, 0, 0, 0};
    char *end;
    if ((s[0] != 'D' && s[0] != 'A') || s[1] < '0' || s[1] > '9') die("not a pin name: ", s);
    p.analog = s[0] == 'A';
    p.n = (int)strtol(s + 1, &end, 10);
    if (!strcmp(end, ":pwm")) {
        p.pwm = 1;
        if (p.analog || !pwm_of(p.n)) die("not a PWM pin: ", s);
    } else if (!strcmp(end, ":drive")) p.drive = 1;
    else if (*end) die("not a pin name: ", s);
    int max = p.analog ? (mega ? 15 : 7) : (mega ? 53 : 13);
    if (p.n > max) die("no such pin on this MCU: ", s);
    return p;
}

/* Port and bit of a pin's digital function; -1 for the 328P's A6/A7 (ADC only). */
static inline int port_of(pin_t p, char *port) {
    if (mega) {
        int i = p.analog ? 54 + p.n : p.n;
        *port = MEGA_PORT[i];
        return MEGA_BIT[i] - '0';
    }
    if (p.analog) { *port = 'C'; return p.n > 5 ? -1 : p.n; }
    if (p.n < 8) { *port = 'D'; return p.n; }
    *port = 'B';
    return p.n - 8;
}

/* Level of a pin: PORT bit when it is an output, else the PIN bit. */
static inline int level(pin_t p) {
    char port;
    int bit = port_of(p, &port);
    if (bit < 0) return 0;
    avr_ioport_state_t st;
    if (avr_ioctl(avr, AVR_IOCTL_IOPORT_GETSTATE(port), &st) != 0) return 0;
    return (((st.ddr >> bit) & 1) ? (st.port >> bit) : (st.pin >> bit)) & 1;
}

/* analogWrite duty: data-space addresses of TCCRnA and OCRnxL are the same on
 * both MCUs; COMnx1 is bit 7/5/3 of TCCRnA for channel A/B/C. */
static inline int duty(pin_t p) {
    const char *tc = pwm_of(p.n);
    static const int tccr[6] = {0x44, 0x80, 0xB0, 0x90, 0xA0, 0x120};
    static const int ocr8[2] = {0x47, 0xB3}; /* timers 0 and 2: OCRnA, OCRnB = +1 */
    int timer = tc[0] - '0', ch = tc[1] - 'A';
    if ((avr->data[tccr[timer]] >> (7 - 2 * ch)) & 1) {
        if (timer == 0) return avr->data[ocr8[0] + ch];
        if (timer == 2) return avr->data[ocr8[1] + ch];
        return avr->data[tccr[timer] + 8 + 2 * ch]; /* OCRnxL: 8-bit PWM in Arduino */
    }
    return level(p) ? 255 : 0;
}

/* ADC. simavr 1.6 keeps adc_values[8] only, so ADC8-15 (Mega A8-A15) cannot be
 * set through ADC_IRQ_ADC8+: their mux entries are turned into "temperature
 * sensor" reads whose value is set when a conversion of that channel starts. */
static avr_adc_t *adc;
static uint32_t adc_mv[16];

static inline void adc_started(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq; (void)param;
    union { avr_adc_mux_t mux; uint32_t v; } e = { .v = value };
    if (e.mux.kind == ADC_MUX_TEMP && e.mux.src >= 8 && e.mux.src < 16)
        adc->temp = (uint16_t)adc_mv[e.mux.src];
}

static inline void adc_setup(void) {
    for (avr_io_t *io = avr->io_port; io; io = io->next)
        if (!strcmp(io->kind, "adc")) adc = (avr_adc_t *)io;
    if (!adc) die("simavr has no ADC for this MCU", NULL);
    for (int i = 0; i < 64; i++)
        if (adc->muxmode[i].kind == ADC_MUX_SINGLE && adc->muxmode[i].src >= 8)
            adc->muxmode[i].kind = ADC_MUX_TEMP;
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_OUT_TRIGGER), adc_started, NULL);
}

/* Drives an input pin: D pins 0/1, A pins the reading 0-1023 analogRead returns. */
static inline void set_input(pin_t pin, int value) {
    if (pin.analog) {
        if (value < 0 || value > 1023) die("an analog reading is 0 to 1023", NULL);
        uint32_t mv = (uint32_t)((value * 5000UL + 1022) / 1023);
        adc_mv[pin.n] = mv;
        if (pin.n < 8) avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0 + pin.n), mv);
        return;
    }
    char port;
    int bit = port_of(pin, &port);
    avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit), value ? 1 : 0);
}

/* 0 when the pin is an input (the firmware does not drive it), 1 when it is an
 * output driven low, 2 driven high. */
static inline int driven(pin_t p) {
    char port;
    int bit = port_of(p, &port);
    if (bit < 0) return 0;
    avr_ioport_state_t st;
    if (avr_ioctl(avr, AVR_IOCTL_IOPORT_GETSTATE(port), &st) != 0) return 0;
    return ((st.ddr >> bit) & 1) ? 1 + ((st.port >> bit) & 1) : 0;
}

/* A pin as the trace shows it: level 0/1, the duty 0-255 of a `Dn:pwm`, or
 * whether a `Dn:drive` is driven (0 input, 1 low, 2 high). */
static inline int sample(pin_t p) {
    if (p.pwm) return duty(p);
    if (p.drive) return driven(p);
    if (p.analog && port_of(p, &(char){0}) < 0) return 0;
    return level(p);
}

#endif
