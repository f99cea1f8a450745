/* alba-simavr: runs an Arduino firmware (ELF) on simavr's emulated ATmega328P
 * (Uno, Nano) or ATmega2560 (Mega, `-m atmega2560`) in simulated time, drives its input pins and analog inputs from a
 * stimulus and samples its pins into a trace, the way `alba sim` does for the
 * PC engine.
 *
 *   alba-simavr FIRMWARE.elf [-m atmega328p|atmega2560] --until MS --every MS --pins D13,D8 [--stimulus FILE]
 *
 * Stimulus lines: `time_ms,pin,value` (header line optional): a digital pin gets
 * 0/1, an analog pin (A0-A7, A0-A15 on the Mega) a reading 0-1023 (converted to the millivolts that
 * make analogRead return it). Trace: `time_ms,<pins>` rows at every multiple of
 * --every up to --until, each pin's level (0/1). Time is the simulated cycle
 * count at 16 MHz, never the wall clock; the cycles simulated go to stderr.
 * Exit 1 with a message on bad arguments, a bad stimulus line or a crashed CPU.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>
#include <simavr/avr_ioport.h>
#include <simavr/avr_adc.h>

#define F_CPU 16000000UL
#define MAX_PINS 32
#define MAX_STIM 100000

typedef struct { int analog; int n; } pin_t; /* D<n> or A<n> */
typedef struct { unsigned long t; pin_t pin; int value; } stim_t;

/* simavr's errors go to stderr (its default logger writes to stdout, which is
 * the trace); its warnings are left out (on the Mega it warns about every
 * analogWrite to a timer mode it does not emulate). */
static void to_stderr(struct avr_t *avr, const int level, const char *format, va_list ap) {
    (void)avr;
    if (level <= LOG_ERROR) vfprintf(stderr, format, ap);
}

static int die(const char *msg, const char *arg) {
    fprintf(stderr, "alba-simavr: %s%s\n", msg, arg ? arg : "");
    exit(1);
}

static int mega;

/* The Arduino Mega's D0-D53 then A0-A15 (D54-D69): port and bit, from the
 * core's variants/mega/pins_arduino.h. */
static const char MEGA_PORT[] = "EEEEGEHHHHBBBBJJHHDDDDAAAAAAAACCCCCCCCDGGGLLLLLLLLBBBBFFFFFFFFKKKKKKKK";
static const char MEGA_BIT[] = "0145533456456710103210012345677654321072107654321032100123456701234567";

static pin_t parse_pin(const char *s) {
    pin_t p;
    char *end;
    if ((s[0] != 'D' && s[0] != 'A') || !s[1]) die("not a pin name: ", s);
    p.analog = s[0] == 'A';
    p.n = (int)strtol(s + 1, &end, 10);
    int max = p.analog ? (mega ? 15 : 7) : (mega ? 53 : 13);
    if (*end || p.n < 0 || p.n > max) die("no such pin on this board: ", s);
    return p;
}

/* The port and bit of a digital function of a pin (A6/A7 of a 328P have none). */
static int port_of(pin_t p, char *port) {
    if (mega) {
        int i = p.analog ? 54 + p.n : p.n;
        *port = MEGA_PORT[i];
        return MEGA_BIT[i] - '0';
    }
    if (p.analog) {
        if (p.n > 5) return -1;
        *port = 'C';
        return p.n;
    }
    if (p.n < 8) { *port = 'D'; return p.n; }
    *port = 'B';
    return p.n - 8;
}

static avr_irq_t *pin_irq(avr_t *avr, pin_t p) {
    char port;
    int bit = port_of(p, &port);
    if (bit < 0) return NULL;
    return avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit);
}

int main(int argc, char **argv) {
    const char *elf = NULL, *stim_file = NULL, *pins_arg = NULL;
    unsigned long until = 0, every = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--until") && i + 1 < argc) until = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--every") && i + 1 < argc) every = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--pins") && i + 1 < argc) pins_arg = argv[++i];
        else if (!strcmp(argv[i], "--stimulus") && i + 1 < argc) stim_file = argv[++i];
        else if (!strcmp(argv[i], "-m") && i + 1 < argc) {
            const char *m = argv[++i];
            if (!strcmp(m, "atmega2560")) mega = 1;
            else if (strcmp(m, "atmega328p")) die("unknown MCU (atmega328p or atmega2560): ", m);
        }
        else if (argv[i][0] != '-' && !elf) elf = argv[i];
        else die("unknown argument: ", argv[i]);
    }
    if (!elf || !pins_arg || !every) die("usage: alba-simavr FIRMWARE.elf --until MS --every MS --pins D13,D8 [--stimulus FILE]", NULL);

    pin_t pins[MAX_PINS];
    int npins = 0;
    char *list = strdup(pins_arg);
    for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
        if (npins == MAX_PINS) die("too many pins", NULL);
        pins[npins++] = parse_pin(tok);
    }

    static stim_t stim[MAX_STIM];
    int nstim = 0;
    if (stim_file) {
        FILE *f = fopen(stim_file, "r");
        if (!f) die("cannot read ", stim_file);
        char line[256];
        int lineno = 0;
        while (fgets(line, sizeof line, f)) {
            lineno++;
            char name[32];
            unsigned long t;
            int v;
            if (line[0] == '\n' || !strncmp(line, "time_ms", 7)) continue;
            if (sscanf(line, "%lu,%31[^,],%d", &t, name, &v) != 3 || nstim == MAX_STIM) {
                fprintf(stderr, "alba-simavr: %s:%d: expected time_ms,pin,value\n", stim_file, lineno);
                return 1;
            }
            if (nstim && t < stim[nstim - 1].t) {
                fprintf(stderr, "alba-simavr: %s:%d: times must not go back\n", stim_file, lineno);
                return 1;
            }
            stim[nstim].t = t;
            stim[nstim].pin = parse_pin(name);
            stim[nstim].value = v;
            nstim++;
        }
        fclose(f);
    }

    avr_global_logger_set(to_stderr);
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(elf, &fw) != 0) die("cannot load the firmware ", elf);
    avr_t *avr = avr_make_mcu_by_name(mega ? "atmega2560" : "atmega328p");
    if (!avr) die("simavr does not know the MCU", NULL);
    avr_init(avr);
    avr->frequency = F_CPU;
    avr->avcc = avr->vcc = avr->aref = 5000;
    avr_load_firmware(avr, &fw);

    printf("time_ms");
    for (int i = 0; i < npins; i++) printf(",%c%d", pins[i].analog ? 'A' : 'D', pins[i].n);
    printf("\n");
    int next_stim = 0;
    for (unsigned long t = 0; t <= until; t++) {
        /* Inputs of this millisecond, then run the millisecond. */
        while (next_stim < nstim && stim[next_stim].t <= t) {
            stim_t *s = &stim[next_stim++];
            if (s->pin.analog) {
                if (s->value < 0 || s->value > 1023) die("an analog reading is 0 to 1023", NULL);
                uint32_t mv = (uint32_t)((s->value * 5000UL + 1022) / 1023);
                avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0 + s->pin.n), mv);
            } else {
                avr_raise_irq(pin_irq(avr, s->pin), s->value ? 1 : 0);
            }
        }
        if (t % every == 0) {
            printf("%lu", t);
            for (int i = 0; i < npins; i++) {
                avr_irq_t *irq = pin_irq(avr, pins[i]);
                printf(",%d", irq ? (int)(irq->value & 1) : 0);
            }
            printf("\n");
        }
        avr_cycle_count_t end = (avr_cycle_count_t)(t + 1) * (F_CPU / 1000);
        while (avr->cycle < end) {
            int state = avr_run(avr);
            if (state == cpu_Done || state == cpu_Crashed) die("the CPU stopped (crashed or sleeping with interrupts off)", NULL);
        }
    }
    fprintf(stderr, "alba-simavr: %llu cycles simulated\n", (unsigned long long)avr->cycle);
    return 0;
}
