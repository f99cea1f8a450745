/* alba-simavr: runs an Arduino firmware ELF on simavr (ATmega328P: Uno/Nano,
 * ATmega2560: Mega) in simulated time, drives inputs from a stimulus and writes
 * a trace of pins (SPEC §7.5).
 *
 *   alba-simavr FIRMWARE.elf [-m atmega328p|atmega2560] [-f HZ] --until MS --every MS
 *               [--lag US] --pins D13,D12,D6:pwm,A0 [--stimulus FILE] [-o TRACE.csv]
 *
 * Stimulus: `time_ms,pin,value` lines (a `time_ms...` header and blank lines are
 * skipped; times never go back). Digital pin: 0/1 driven on the pin. Analog pin
 * (A0-A7, Mega A0-A15): the reading 0-1023 that analogRead returns (the
 * millivolts are ceil(value*5000/1023), which simavr scales back exactly).
 * Trace: header `time_ms,<pins>` then a row at every multiple of --every up to
 * --until: the pin's level 0/1, or for `Dn:pwm` the analogWrite duty 0-255 read
 * from the timer's compare register while its output is connected (0/255 from
 * the port otherwise). At each time, inputs of that time are applied first,
 * then the row is sampled, then the CPU runs on. Time = cycles * 1000 / HZ.
 * With --lag US, the row of time t is sampled US microseconds after t (stimuli
 * up to that moment applied first): a firmware that scans at t has written its
 * outputs by then, so the row shows the outputs of the scan at t, like
 * `alba sim`'s trace.
 * Scan profile: a firmware that writes 1 to GPIOR0 when a scan starts and 0
 * when it ends (Alba's sketches do) gets its scans counted and timed in CPU
 * cycles; the count and min/mean/max cycles go to stderr as a line
 * `alba-simavr: scans N cycles min A mean B max C`.
 * Total cycles go to stderr. Exit 1 on bad arguments or a stopped CPU.
 */
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

typedef struct { int analog, n, pwm; } pin_t;
typedef struct { unsigned long t; pin_t pin; int value; } stim_t;

static int mega;
static avr_t *avr;

static void die(const char *msg, const char *arg) {
    fprintf(stderr, "alba-simavr: %s%s\n", msg, arg ? arg : "");
    exit(1);
}

/* simavr logs to stdout by default; errors go to stderr, the rest is dropped
 * (Arduino's phase-correct PWM modes are not emulated and warn on every write). */
static void logger(avr_t *a, const int level, const char *fmt, va_list ap) {
    (void)a;
    if (level <= LOG_ERROR) vfprintf(stderr, fmt, ap);
}

/* simavr's default sleep callback usleep()s to keep real time: not here. */
static void no_sleep(avr_t *a, avr_cycle_count_t how_long) { (void)a; (void)how_long; }

/* Arduino Mega D0-D69 (A0-A15 = D54-D69): port letter and bit, from the core's
 * variants/mega/pins_arduino.h digital_pin_to_port_PGM / _bit_mask_PGM. */
static const char MEGA_PORT[] = "EEEEGEHHHHBBBBJJHHDDDDAAAAAAAACCCCCCCCDGGGLLLLLLLLBBBBFFFFFFFFKKKKKKKK";
static const char MEGA_BIT[] = "0145533456456710103210012345677654321072107654321032100123456701234567";

/* PWM: for each digital pin, "timer channel" (0 = none), from digital_pin_to_timer_PGM. */
static const char *pwm_of(int d) {
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

static pin_t parse_pin(const char *s) {
    pin_t p = {0, 0, 0};
    char *end;
    if ((s[0] != 'D' && s[0] != 'A') || s[1] < '0' || s[1] > '9') die("not a pin name: ", s);
    p.analog = s[0] == 'A';
    p.n = (int)strtol(s + 1, &end, 10);
    if (!strcmp(end, ":pwm")) {
        p.pwm = 1;
        if (p.analog || !pwm_of(p.n)) die("not a PWM pin: ", s);
    } else if (*end) die("not a pin name: ", s);
    int max = p.analog ? (mega ? 15 : 7) : (mega ? 53 : 13);
    if (p.n > max) die("no such pin on this MCU: ", s);
    return p;
}

/* Port and bit of a pin's digital function; -1 for the 328P's A6/A7 (ADC only). */
static int port_of(pin_t p, char *port) {
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
static int level(pin_t p) {
    char port;
    int bit = port_of(p, &port);
    if (bit < 0) return 0;
    avr_ioport_state_t st;
    if (avr_ioctl(avr, AVR_IOCTL_IOPORT_GETSTATE(port), &st) != 0) return 0;
    return (((st.ddr >> bit) & 1) ? (st.port >> bit) : (st.pin >> bit)) & 1;
}

/* analogWrite duty: data-space addresses of TCCRnA and OCRnxL are the same on
 * both MCUs; COMnx1 is bit 7/5/3 of TCCRnA for channel A/B/C. */
static int duty(pin_t p) {
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

static void adc_started(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq; (void)param;
    union { avr_adc_mux_t mux; uint32_t v; } e = { .v = value };
    if (e.mux.kind == ADC_MUX_TEMP && e.mux.src >= 8 && e.mux.src < 16)
        adc->temp = (uint16_t)adc_mv[e.mux.src];
}

static void adc_setup(void) {
    for (avr_io_t *io = avr->io_port; io; io = io->next)
        if (!strcmp(io->kind, "adc")) adc = (avr_adc_t *)io;
    if (!adc) die("simavr has no ADC for this MCU", NULL);
    for (int i = 0; i < 64; i++)
        if (adc->muxmode[i].kind == ADC_MUX_SINGLE && adc->muxmode[i].src >= 8)
            adc->muxmode[i].kind = ADC_MUX_TEMP;
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_OUT_TRIGGER), adc_started, NULL);
}

/* GPIOR0 (I/O 0x1E, data 0x3E on both MCUs): scan start (1) and end (0). */
static avr_cycle_count_t scan_start, scan_min = (avr_cycle_count_t)-1, scan_max, scan_sum;
static unsigned long scans;

static void gpior0_write(avr_t *a, avr_io_addr_t addr, uint8_t v, void *param) {
    (void)param;
    a->data[addr] = v;
    if (v == 1) scan_start = a->cycle;
    else if (v == 0 && scan_start) {
        avr_cycle_count_t c = a->cycle - scan_start;
        scans++;
        scan_sum += c;
        if (c < scan_min) scan_min = c;
        if (c > scan_max) scan_max = c;
        scan_start = 0;
    }
}

static void apply(const stim_t *s) {
    if (s->pin.analog) {
        if (s->value < 0 || s->value > 1023) die("an analog reading is 0 to 1023", NULL);
        uint32_t mv = (uint32_t)((s->value * 5000UL + 1022) / 1023);
        adc_mv[s->pin.n] = mv;
        if (s->pin.n < 8) avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0 + s->pin.n), mv);
        return;
    }
    char port;
    int bit = port_of(s->pin, &port);
    avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit), s->value ? 1 : 0);
}

int main(int argc, char **argv) {
    const char *elf = NULL, *stim_file = NULL, *pins_arg = NULL, *out_file = NULL, *mcu = "atmega328p";
    unsigned long until = 0, every = 0, lag = 0, freq = 16000000UL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--until") && more) until = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--every") && more) every = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--lag") && more) lag = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--pins") && more) pins_arg = argv[++i];
        else if (!strcmp(a, "--stimulus") && more) stim_file = argv[++i];
        else if (!strcmp(a, "-o") && more) out_file = argv[++i];
        else if (!strcmp(a, "-f") && more) freq = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "-m") && more) mcu = argv[++i];
        else if (a[0] != '-' && !elf) elf = a;
        else die("unknown argument: ", a);
    }
    if (!elf || !pins_arg || !every || !freq)
        die("usage: alba-simavr FIRMWARE.elf [-m atmega328p|atmega2560] [-f HZ] --until MS --every MS [--lag US] "
            "--pins D13,D6:pwm,A0 [--stimulus FILE] [-o TRACE]", NULL);
    if (!strcmp(mcu, "atmega2560")) mega = 1;
    else if (strcmp(mcu, "atmega328p")) die("unknown MCU (atmega328p or atmega2560): ", mcu);

    pin_t pins[MAX_PINS];
    int npins = 0;
    char *list = strdup(pins_arg);
    for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
        if (npins == MAX_PINS) die("too many pins", NULL);
        pins[npins++] = parse_pin(tok);
    }

    stim_t *stim = NULL;
    size_t nstim = 0, cap = 0;
    if (stim_file) {
        FILE *f = fopen(stim_file, "r");
        if (!f) die("cannot read ", stim_file);
        char line[256], name[32];
        int lineno = 0;
        while (fgets(line, sizeof line, f)) {
            lineno++;
            unsigned long t;
            int v;
            if (line[0] == '\n' || line[0] == '\r' || line[0] == '#' || !strncmp(line, "time_ms", 7)) continue;
            if (sscanf(line, "%lu,%31[^,],%d", &t, name, &v) != 3) {
                fprintf(stderr, "alba-simavr: %s:%d: expected time_ms,pin,value\n", stim_file, lineno);
                return 1;
            }
            if (nstim && t < stim[nstim - 1].t) {
                fprintf(stderr, "alba-simavr: %s:%d: times must not go back\n", stim_file, lineno);
                return 1;
            }
            if (nstim == cap) stim = realloc(stim, (cap = cap ? 2 * cap : 256) * sizeof *stim);
            stim[nstim].t = t;
            stim[nstim].pin = parse_pin(name);
            stim[nstim].value = v;
            if (!stim[nstim].pin.analog && v != 0 && v != 1) die("a digital input is 0 or 1: ", name);
            nstim++;
        }
        fclose(f);
    }

    /* The trace goes to -o or to the original stdout; anything simavr prints goes to stderr. */
    FILE *trace = out_file ? fopen(out_file, "w") : fdopen(dup(1), "w");
    if (!trace) die("cannot write ", out_file);
    dup2(2, 1);

    avr_global_logger_set(logger);
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(elf, &fw) != 0) die("cannot load the firmware ", elf);
    avr = avr_make_mcu_by_name(mcu);
    if (!avr) die("simavr does not know the MCU ", mcu);
    avr_init(avr);
    avr_load_firmware(avr, &fw);
    avr->frequency = (uint32_t)freq;
    avr->vcc = avr->avcc = avr->aref = 5000;
    avr->sleep = no_sleep;
    adc_setup();
    avr_register_io_write(avr, 0x3E, gpior0_write, NULL);

    fprintf(trace, "time_ms");
    for (int i = 0; i < npins; i++)
        fprintf(trace, ",%c%d%s", pins[i].analog ? 'A' : 'D', pins[i].n, pins[i].pwm ? ":pwm" : "");
    fprintf(trace, "\n");

    size_t next = 0;
    for (unsigned long t = 0; t <= until; t += every) {
        avr_cycle_count_t target = (avr_cycle_count_t)t * freq / 1000 + (avr_cycle_count_t)lag * freq / 1000000;
        /* run up to t, stopping at each stimulus time on the way */
        for (;;) {
            avr_cycle_count_t stop = target;
            avr_cycle_count_t at = next < nstim ? (avr_cycle_count_t)stim[next].t * freq / 1000 : 0;
            int due = next < nstim && at <= target;
            if (due) stop = at;
            while (avr->cycle < stop) {
                int st = avr_run(avr);
                if (st == cpu_Done || st == cpu_Crashed) die("the CPU stopped (crashed, or sleeping with interrupts off)", NULL);
            }
            if (due) apply(&stim[next++]);
            else break;
        }
        fprintf(trace, "%lu", t);
        for (int i = 0; i < npins; i++) {
            if (pins[i].pwm) fprintf(trace, ",%d", duty(pins[i]));
            else if (pins[i].analog && port_of(pins[i], &(char){0}) < 0) fprintf(trace, ",0");
            else fprintf(trace, ",%d", level(pins[i]));
        }
        fprintf(trace, "\n");
    }
    fclose(trace);
    if (scans)
        fprintf(stderr, "alba-simavr: scans %lu cycles min %llu mean %llu max %llu\n", scans,
                (unsigned long long)scan_min, (unsigned long long)(scan_sum / scans), (unsigned long long)scan_max);
    fprintf(stderr, "alba-simavr: %llu cycles simulated (%.3f ms at %lu Hz)\n",
            (unsigned long long)avr->cycle, avr->cycle * 1000.0 / freq, freq);
    return 0;
}
