/* alba-simavr: runs an Arduino firmware ELF on simavr (ATmega328P: Uno/Nano,
 * ATmega2560: Mega) in simulated time, drives inputs from a stimulus and writes
 * a trace of pins (SPEC §7.5).
 *
 *   alba-simavr FIRMWARE.elf [-m atmega328p|atmega2560] [-f HZ] --until MS --every MS
 *               [--lag US] [--from-first-scan] [--eeprom FILE] --pins D13,D12,D6:pwm,A0 [--mem ADDR:LEN,...]
 *               [--forbid ADDR:LEN,...] [--free-ram ADDR] [--stimulus FILE] [--serial FILE] [-o TRACE.csv]
 *
 * Stimulus: `time_ms,pin,value` lines (a `time_ms...` header and blank lines are
 * skipped; times never go back). Digital pin: 0/1 driven on the pin. Analog pin
 * (A0-A7, Mega A0-A15): the reading 0-1023 that analogRead returns (the
 * millivolts are ceil(value*5000/1023), which simavr scales back exactly).
 * Trace: header `time_ms,<pins>` then a row at every multiple of --every up to
 * --until: the pin's level 0/1, or for `Dn:pwm` the analogWrite duty 0-255 read
 * from the timer's compare register while its output is connected (0/255 from
 * the port otherwise), or for `Dn:drive` whether the firmware drives the pin (0
 * an input, 1 driven low, 2 driven high). At each time, inputs of that time are applied first,
 * then the row is sampled, then the CPU runs on. Time = cycles * 1000 / HZ.
 * With --lag US, the row of time t is sampled US microseconds after t (stimuli
 * up to that moment applied first): a firmware that scans at t has written its
 * outputs by then, so the row shows the outputs of the scan at t, like
 * `alba sim`'s trace.
 * With --mem, each row also holds, per region (a data-space address and a
 * length, decimal), the region's bytes in hex: a column `mADDR` (the firmware's
 * memory, for comparing every variable and not only pins). --pins may then be
 * empty.
 * Scan profile: a firmware that writes 1 to GPIOR0 when a scan starts and 0
 * when it ends (Alba's sketches do) gets its scans counted and timed in CPU
 * cycles; the count and min/mean/max cycles go to stderr as a line
 * `alba-simavr: scans N cycles min A mean B max C`.
 * The number of scans started goes to stderr too (`alba-simavr: scan starts N`):
 * a scan that never ends (a runaway loop) started all the same; and the cycle the
 * first one started at (`alba-simavr: first scan at cycle N`: the firmware's setup).
 * With --forbid ADDR:LEN,..., from the first scan on, the CPU must not store into
 * those data-space regions (decimal); with --free-ram ADDR, never between ADDR (the
 * end of the firmware's static data) and the stack pointer, where nothing lives;
 * and never outside the MCU's RAM nor into its registers by address. Each such
 * store goes to stderr as `alba-simavr: forbidden
 * write XX to ADDR at pc PC` (the first 20), their count as `alba-simavr: forbidden
 * writes N`, and the exit status is 3 (the trace is written all the same). simavr
 * sends every store of the program (ST, STD, STS, CALL's return address) through
 * avr_core_watch_write, which this program replaces (the executable's definition
 * takes the library's calls to it).
 * With --serial FILE, every line the firmware sends on its serial port (UART0)
 * goes to FILE as `MS TEXT`: the time (ms from the reset) its end of line was
 * sent, then the line (for the interpreter's lamp test).
 * Total cycles go to stderr. Exit 1 on bad arguments or a stopped CPU.
 */
#include "pins.h"
#include <avr_eeprom.h>
#include <avr_uart.h>

typedef struct { unsigned long t; pin_t pin; int value; } stim_t;

/* GPIOR0 (I/O 0x1E, data 0x3E on both MCUs): scan start (1) and end (0). */
static avr_cycle_count_t scan_start, scan_min = (avr_cycle_count_t)-1, scan_max, scan_sum;
static unsigned long scans, scan_starts;

/* With --from-first-scan, the cycle the first scan started at is the trace's
 * time 0 (a firmware whose setup takes a while: the byte-code interpreter,
 * which checks its program and schedules its scans on micros()); otherwise
 * time 0 is the reset (a sketch, whose millis() deadlines count from it). */
static avr_cycle_count_t origin, first_scan_at;
static int started, from_first_scan;
/* With --eeprom FILE, the EEPROM starts from that image (what `alba download` left). */
static const char *eeprom_file;

static void gpior0_write(avr_t *a, avr_io_addr_t addr, uint8_t v, void *param) {
    (void)param;
    a->data[addr] = v;
    if (v == 1 && !started) {
        started = 1;
        first_scan_at = a->cycle;
        if (from_first_scan) origin = a->cycle;
    }
    if (v == 1) {
        scan_start = a->cycle;
        scan_starts++;
    }
    else if (v == 0 && scan_start) {
        avr_cycle_count_t c = a->cycle - scan_start;
        scans++;
        scan_sum += c;
        if (c < scan_min) scan_min = c;
        if (c > scan_max) scan_max = c;
        scan_start = 0;
    }
}

static void apply(const stim_t *s) { set_input(s->pin, s->value); }

/* --serial: the firmware's lines, each with the time of its end. */
static FILE *serial_out;
static unsigned long serial_freq;
static char serial_line[256];
static size_t serial_len;

static void serial_byte(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq; (void)param;
    char c = (char)value;
    if (c == '\r') return;
    if (c == '\n') {
        fprintf(serial_out, "%llu %.*s\n", (unsigned long long)(avr->cycle * 1000 / serial_freq), (int)serial_len, serial_line);
        fflush(serial_out);
        serial_len = 0;
    } else if (serial_len < sizeof serial_line) {
        serial_line[serial_len++] = c;
    }
}

static unsigned long forbid_at[MAX_PINS], forbid_len[MAX_PINS];
static int nforbid;
static unsigned long forbidden, free_ram;

static void forbidden_write(avr_t *a, unsigned long addr, uint8_t v) {
    if (forbidden++ < 20)
        fprintf(stderr, "alba-simavr: forbidden write %02x to %lu at pc 0x%x (sp %u)\n", v, addr, (unsigned)a->pc,
                (unsigned)(a->data[R_SPL] | a->data[R_SPH] << 8));
}

/* Replaces simavr's (sim_core.c): the same checks, and the watch of --forbid. */
void avr_core_watch_write(avr_t *a, uint16_t addr, uint8_t v) {
    if (addr > a->ramend) {
        forbidden_write(a, addr, v);
        addr = addr % (a->ramend + 1);
    }
    if (addr < 32) {
        forbidden_write(a, addr, v);
        a->state = cpu_Crashed;
        return;
    }
    uint16_t sp = a->data[R_SPL] | a->data[R_SPH] << 8;
    /* (a CALL stores its return address, 2 bytes or the Mega's 3, below SP before moving it) */
    if (free_ram && addr >= free_ram && addr + 3 < sp) forbidden_write(a, addr, v);
    if (started)
        for (int i = 0; i < nforbid; i++)
            if (addr >= forbid_at[i] && addr < forbid_at[i] + forbid_len[i]) forbidden_write(a, addr, v);
    a->data[addr] = v;
}

int main(int argc, char **argv) {
    const char *elf = NULL, *stim_file = NULL, *pins_arg = "", *mem_arg = "", *forbid_arg = "", *out_file = NULL,
               *mcu = "atmega328p", *serial_file = NULL;
    unsigned long until = 0, every = 0, lag = 0, freq = 16000000UL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--until") && more) until = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--every") && more) every = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--lag") && more) lag = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--pins") && more) pins_arg = argv[++i];
        else if (!strcmp(a, "--mem") && more) mem_arg = argv[++i];
        else if (!strcmp(a, "--forbid") && more) forbid_arg = argv[++i];
        else if (!strcmp(a, "--free-ram") && more) free_ram = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--stimulus") && more) stim_file = argv[++i];
        else if (!strcmp(a, "-o") && more) out_file = argv[++i];
        else if (!strcmp(a, "--serial") && more) serial_file = argv[++i];
        else if (!strcmp(a, "-f") && more) freq = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "-m") && more) mcu = argv[++i];
        else if (!strcmp(a, "--from-first-scan")) from_first_scan = 1;
        else if (!strcmp(a, "--eeprom") && more) eeprom_file = argv[++i];
        else if (a[0] != '-' && !elf) elf = a;
        else die("unknown argument: ", a);
    }
    if (!elf || (!*pins_arg && !*mem_arg) || !every || !freq)
        die("usage: alba-simavr FIRMWARE.elf [-m atmega328p|atmega2560] [-f HZ] --until MS --every MS [--lag US] "
            "--pins D13,D6:pwm,A0 [--mem ADDR:LEN,...] [--stimulus FILE] [-o TRACE]", NULL);
    if (!strcmp(mcu, "atmega2560")) mega = 1;
    else if (strcmp(mcu, "atmega328p")) die("unknown MCU (atmega328p or atmega2560): ", mcu);

    pin_t pins[MAX_PINS];
    int npins = 0;
    char *list = strdup(pins_arg);
    for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
        if (npins == MAX_PINS) die("too many pins", NULL);
        pins[npins++] = parse_pin(tok);
    }

    unsigned long mem_at[MAX_PINS], mem_len[MAX_PINS];
    int nmem = 0;
    char *mlist = strdup(mem_arg);
    for (char *tok = strtok(mlist, ","); tok; tok = strtok(NULL, ",")) {
        char *colon;
        if (nmem == MAX_PINS) die("too many memory regions", NULL);
        mem_at[nmem] = strtoul(tok, &colon, 10);
        if (*colon != ':') die("a memory region is ADDR:LEN: ", tok);
        mem_len[nmem] = strtoul(colon + 1, NULL, 10);
        nmem++;
    }

    char *flist = strdup(forbid_arg);
    for (char *tok = strtok(flist, ","); tok; tok = strtok(NULL, ",")) {
        char *colon;
        if (nforbid == MAX_PINS) die("too many forbidden regions", NULL);
        forbid_at[nforbid] = strtoul(tok, &colon, 10);
        if (*colon != ':') die("a forbidden region is ADDR:LEN: ", tok);
        forbid_len[nforbid] = strtoul(colon + 1, NULL, 10);
        nforbid++;
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
    if (eeprom_file) {
        static uint8_t ee[4096];
        FILE *f = fopen(eeprom_file, "rb");
        if (!f) die("cannot read ", eeprom_file);
        size_t n = fread(ee, 1, sizeof ee, f);
        fclose(f);
        avr_eeprom_desc_t d = {.ee = ee, .offset = 0, .size = (uint32_t)n};
        avr_ioctl(avr, AVR_IOCTL_EEPROM_SET, &d);
    }
    avr->frequency = (uint32_t)freq;
    avr->vcc = avr->avcc = avr->aref = 5000;
    avr->sleep = no_sleep;
    adc_setup();
    avr_register_io_write(avr, 0x3E, gpior0_write, NULL);
    if (serial_file) {
        serial_out = fopen(serial_file, "w");
        if (!serial_out) die("cannot write ", serial_file);
        serial_freq = freq;
        uint32_t flags = 0;
        avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
        flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POOL_SLEEP);
        avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
        avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), serial_byte, NULL);
    }

    fprintf(trace, "time_ms");
    for (int i = 0; i < npins; i++)
        fprintf(trace, ",%c%d%s", pins[i].analog ? 'A' : 'D', pins[i].n, pins[i].pwm ? ":pwm" : pins[i].drive ? ":drive" : "");
    for (int i = 0; i < nmem; i++) {
        if (mem_at[i] + mem_len[i] > (unsigned long)avr->ramend + 1) die("a memory region is outside the MCU's RAM", NULL);
        fprintf(trace, ",m%lu", mem_at[i]);
    }
    fprintf(trace, "\n");

    /* Time 0 is the start of the first scan (the firmware's setup, such as the
     * byte-code interpreter's check of its program, takes what it takes):
     * run to it, at most 2 s, and stop before the scan reads its inputs. */
    while (from_first_scan && !started && avr->cycle < 2 * (avr_cycle_count_t)freq) {
        int st = avr_run(avr);
        if (st == cpu_Done || st == cpu_Crashed) die("the CPU stopped (crashed, or sleeping with interrupts off)", NULL);
    }
    size_t next = 0;
    for (unsigned long t = 0; t <= until; t += every) {
        avr_cycle_count_t target = origin + (avr_cycle_count_t)t * freq / 1000 + (avr_cycle_count_t)lag * freq / 1000000;
        /* run up to t, stopping at each stimulus time on the way */
        for (;;) {
            avr_cycle_count_t stop = target;
            /* from the first scan, a change at t is on the pins 50 µs before the
             * deadline of t, so the scan at t reads it however the loop polls its clock */
            avr_cycle_count_t at = next < nstim ? origin + (avr_cycle_count_t)stim[next].t * freq / 1000 : 0;
            if (from_first_scan && next < nstim && stim[next].t > 0) at -= (avr_cycle_count_t)freq / 20000;
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
        for (int i = 0; i < npins; i++) fprintf(trace, ",%d", sample(pins[i]));
        for (int i = 0; i < nmem; i++) {
            fputc(',', trace);
            for (unsigned long k = 0; k < mem_len[i]; k++) fprintf(trace, "%02x", avr->data[mem_at[i] + k]);
        }
        fprintf(trace, "\n");
    }
    fclose(trace);
    if (serial_out) {
        if (serial_len) fprintf(serial_out, "%llu %.*s\n", (unsigned long long)(avr->cycle * 1000 / freq), (int)serial_len, serial_line);
        fclose(serial_out);
    }
    if (scans)
        fprintf(stderr, "alba-simavr: scans %lu cycles min %llu mean %llu max %llu\n", scans,
                (unsigned long long)scan_min, (unsigned long long)(scan_sum / scans), (unsigned long long)scan_max);
    fprintf(stderr, "alba-simavr: scan starts %lu\n", scan_starts);
    if (started) fprintf(stderr, "alba-simavr: first scan at cycle %llu\n", (unsigned long long)first_scan_at);
    fprintf(stderr, "alba-simavr: %llu cycles simulated (%.3f ms at %lu Hz)\n",
            (unsigned long long)avr->cycle, avr->cycle * 1000.0 / freq, freq);
    if (forbidden) {
        fprintf(stderr, "alba-simavr: forbidden writes %lu\n", forbidden);
        return 3;
    }
    return 0;
}
