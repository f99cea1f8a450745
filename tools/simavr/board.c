/* alba-board: an Arduino running a firmware in simavr, paced to real time,
 * with its serial port (UART0) on a pseudo-terminal: an emulated remote-I/O
 * board for `alba run --io arduino:PORT` (controller mode, SPEC 7.2).
 *
 *   alba-board FIRMWARE.elf [-m atmega328p|atmega2560] [-f HZ] --tty LINK
 *              --pins D12,D13,D6:pwm [--eeprom FILE] [--hold PIN]
 *
 * With --eeprom, the EEPROM starts from FILE when it exists and is written to
 * it at the end: a power cycle that keeps what the firmware stored. With
 * --hold, that digital input is high from the reset on (a button held at
 * power-up) until a `set` releases it.
 *
 * LINK becomes a symbolic link to the pty's slave (/dev/pts/N), as udev's
 * /dev/serial/by-id links are; the host opens LINK. The pty is raw (no echo,
 * no line editing) whatever the host does.
 *
 * Control on stdin, one command a line, one answer line on stdout each:
 *   set PIN VALUE   drive an input: D pins 0/1, A pins the reading 0-1023 -> `ok`
 *   get             the --pins, sampled now (level, or `:pwm` duty) -> `pins V1 V2 ...`
 *   unplug          close the pty and remove LINK (the host sees the port vanish) -> `ok`
 *   plug            a new pty, LINK points at it -> `ok /dev/pts/M`
 *   time            simulated milliseconds since the start -> `time MS`
 *   stuck ADDR      the EEPROM byte at ADDR (decimal) keeps its value whatever the
 *                   firmware writes: a worn cell, for write-verify failures -> `ok`
 *   stuck off       the EEPROM works again -> `ok`
 *   quit            (or end of input) exit
 * At start, once the pty exists: `ready /dev/pts/N`. Errors: `error TEXT`.
 *
 * Time: the CPU runs at most 1 ms of simulated time between two services of
 * the pty and stdin, and never ahead of the wall clock. On a loaded machine
 * it falls behind and then lags rather than racing to catch up, so the
 * firmware never runs faster than real time (everything, the UART included,
 * is just slower).
 * Bytes from the host enter the UART at its baud rate (simavr's receive
 * FIFO paces them); bytes the firmware sends go to the pty as written.
 */
#define _GNU_SOURCE
#include "pins.h"
#include <avr_eeprom.h>
#include <avr_uart.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <time.h>

DEFINE_FIFO(uint16_t, uart_fifo);

static const char *tty_link;
static const char *eeprom_file;
static const char *hold_pin;
static int master = -1, slave_keep = -1;
static avr_uart_t *uart;
static FILE *ctl;

/* Host -> board bytes not yet in the UART. */
static unsigned char rxq[4096];
static size_t rxq_len;
/* Board -> host bytes not yet written to the pty. */
static unsigned char txq[4096];
static size_t txq_len;

static uint64_t now_us(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

static void uart_out(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq; (void)param;
    if (master < 0) return; /* unplugged: the bytes are lost, as on a cable pulled */
    if (txq_len < sizeof txq) txq[txq_len++] = (unsigned char)value;
}

static int plug(void) {
    master = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (master < 0 || grantpt(master) || unlockpt(master)) return -1;
    const char *name = ptsname(master);
    if (!name) return -1;
    /* Raw, and held open so the master never reads EIO between two host opens. */
    slave_keep = open(name, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (slave_keep < 0) return -1;
    struct termios t;
    if (tcgetattr(slave_keep, &t) == 0) {
        cfmakeraw(&t);
        cfsetspeed(&t, B115200);
        tcsetattr(slave_keep, TCSANOW, &t);
    }
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", tty_link);
    unlink(tmp);
    if (symlink(name, tmp) || rename(tmp, tty_link)) return -1;
    rxq_len = txq_len = 0;
    return 0;
}

static void unplug(void) {
    unlink(tty_link);
    if (slave_keep >= 0) close(slave_keep);
    if (master >= 0) close(master);
    master = slave_keep = -1;
    rxq_len = txq_len = 0;
}

static void pump_pty(void) {
    if (master < 0) return;
    if (rxq_len < sizeof rxq) {
        ssize_t n = read(master, rxq + rxq_len, sizeof rxq - rxq_len);
        if (n > 0) rxq_len += (size_t)n;
    }
    /* Into the UART while its FIFO has room and the receiver is on. */
    size_t fed = 0;
    while (fed < rxq_len && avr_regbit_get(avr, uart->rxen) && !uart_fifo_isfull(&uart->input)) {
        avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT), rxq[fed++]);
    }
    if (fed) {
        memmove(rxq, rxq + fed, rxq_len - fed);
        rxq_len -= fed;
    }
    if (txq_len) {
        ssize_t n = write(master, txq, txq_len);
        if (n > 0) {
            memmove(txq, txq + n, txq_len - (size_t)n);
            txq_len -= (size_t)n;
        } else if (n < 0 && errno != EAGAIN) {
            txq_len = 0;
        }
    }
}

/* A digital input driven from outside stays at its level even when the
 * firmware writes its port (simavr re-raises the internal pull-up of every
 * input pin on each PORT write, which would undo the drive): the driven pins
 * are the port's "external" pins. */
static uint8_t ext_mask[128], ext_value[128];

static void drive(pin_t p, int v) {
    set_input(p, v);
    if (p.analog) return;
    char port;
    int bit = port_of(p, &port);
    if (bit < 0) return;
    unsigned char k = (unsigned char)port & 127;
    ext_mask[k] |= (uint8_t)(1 << bit);
    if (v) ext_value[k] |= (uint8_t)(1 << bit);
    else ext_value[k] &= (uint8_t)~(1 << bit);
    avr_ioport_external_t e = {.name = (unsigned long)port & 127, .mask = ext_mask[k], .value = ext_value[k]};
    avr_ioctl(avr, AVR_IOCTL_IOPORT_SET_EXTERNAL(port), &e);
}

/* The EEPROM (simavr's own buffer) and the cell `stuck` holds at `stuck_value`. */
static uint8_t *eeprom;
static uint32_t ee_size;
static long stuck = -1;
static uint8_t stuck_value;

static pin_t pins[MAX_PINS];
static int npins;
static char cmd[256];
static size_t cmd_len;
static unsigned long freq = 16000000UL;

/* One command; returns 0 to quit. */
static int command(char *line) {
    char *arg = strchr(line, ' ');
    if (arg) *arg++ = 0;
    if (!strcmp(line, "set") && arg) {
        char name[32];
        int v;
        if (sscanf(arg, "%31s %d", name, &v) != 2) {
            fprintf(ctl, "error set PIN VALUE\n");
            return 1;
        }
        pin_t p = parse_pin(name);
        if ((p.analog && (v < 0 || v > 1023)) || (!p.analog && v != 0 && v != 1)) {
            fprintf(ctl, "error value out of range\n");
            return 1;
        }
        drive(p, v);
        fprintf(ctl, "ok\n");
    } else if (!strcmp(line, "get")) {
        fprintf(ctl, "pins");
        for (int i = 0; i < npins; i++) fprintf(ctl, " %d", sample(pins[i]));
        fprintf(ctl, "\n");
    } else if (!strcmp(line, "unplug")) {
        unplug();
        fprintf(ctl, "ok\n");
    } else if (!strcmp(line, "plug")) {
        if (master >= 0) unplug();
        if (plug()) fprintf(ctl, "error cannot make a pty: %s\n", strerror(errno));
        else fprintf(ctl, "ok %s\n", ptsname(master));
    } else if (!strcmp(line, "stuck") && arg) {
        char *end;
        long at = strtol(arg, &end, 10);
        if (!strcmp(arg, "off")) {
            stuck = -1;
            fprintf(ctl, "ok\n");
        } else if (*end || at < 0 || (uint32_t)at >= ee_size || !eeprom) {
            fprintf(ctl, "error stuck ADDR (0-%u) or stuck off\n", (unsigned)ee_size - 1);
        } else {
            stuck = at;
            stuck_value = eeprom[at];
            fprintf(ctl, "ok\n");
        }
    } else if (!strcmp(line, "time")) {
        fprintf(ctl, "time %llu\n", (unsigned long long)(avr->cycle * 1000 / freq));
    } else if (!strcmp(line, "quit")) {
        return 0;
    } else {
        fprintf(ctl, "error unknown command `%s`\n", line);
    }
    return 1;
}

/* Reads stdin without blocking; returns 0 at its end or on `quit`. */
static int pump_stdin(void) {
    struct pollfd pfd = {0, POLLIN, 0};
    while (poll(&pfd, 1, 0) > 0) {
        char c;
        ssize_t n = read(0, &c, 1);
        if (n <= 0) return 0;
        if (c == '\n') {
            cmd[cmd_len] = 0;
            cmd_len = 0;
            int go = command(cmd);
            fflush(ctl);
            if (!go) return 0;
        } else if (cmd_len + 1 < sizeof cmd) {
            cmd[cmd_len++] = c;
        }
    }
    return 1;
}

int main(int argc, char **argv) {
    const char *elf = NULL, *pins_arg = NULL, *mcu = "atmega328p";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--tty") && more) tty_link = argv[++i];
        else if (!strcmp(a, "--pins") && more) pins_arg = argv[++i];
        else if (!strcmp(a, "-f") && more) freq = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "-m") && more) mcu = argv[++i];
        else if (!strcmp(a, "--eeprom") && more) eeprom_file = argv[++i];
        else if (!strcmp(a, "--hold") && more) hold_pin = argv[++i];
        else if (a[0] != '-' && !elf) elf = a;
        else die("unknown argument: ", a);
    }
    if (!elf || !tty_link || !freq)
        die("usage: alba-board FIRMWARE.elf [-m atmega328p|atmega2560] [-f HZ] --tty LINK [--pins D12,D6:pwm]", NULL);
    if (!strcmp(mcu, "atmega2560")) mega = 1;
    else if (strcmp(mcu, "atmega328p")) die("unknown MCU (atmega328p or atmega2560): ", mcu);
    if (pins_arg) {
        char *list = strdup(pins_arg);
        for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
            if (npins == MAX_PINS) die("too many pins", NULL);
            pins[npins++] = parse_pin(tok);
        }
    }
    /* Answers go to the original stdout; anything simavr prints to stderr. */
    ctl = fdopen(dup(1), "w");
    if (!ctl) die("cannot write to stdout", NULL);
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
    static uint8_t ee[4096];
    ee_size = mega ? 4096 : 1024;
    if (eeprom_file) {
        FILE *f = fopen(eeprom_file, "rb");
        if (f) {
            size_t n = fread(ee, 1, ee_size, f);
            fclose(f);
            if (n == ee_size) {
                avr_eeprom_desc_t d = {.ee = ee, .offset = 0, .size = ee_size};
                avr_ioctl(avr, AVR_IOCTL_EEPROM_SET, &d);
            }
        }
    }

    {
        /* (simavr 1.6 answers GET with a pointer to its EEPROM when given none,
         * and -1 even then: the pointer says whether it worked) */
        avr_eeprom_desc_t d = {.ee = NULL, .offset = 0, .size = ee_size};
        avr_ioctl(avr, AVR_IOCTL_EEPROM_GET, &d);
        eeprom = d.ee;
    }
    if (hold_pin) set_input(parse_pin(hold_pin), 1);
    for (avr_io_t *io = avr->io_port; io; io = io->next)
        if (!strcmp(io->kind, "uart") && ((avr_uart_t *)io)->name == '0') uart = (avr_uart_t *)io;
    if (!uart) die("simavr has no UART0 for this MCU", NULL);
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POOL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), uart_out, NULL);

    if (plug()) die("cannot make a pseudo-terminal: ", strerror(errno));
    fprintf(ctl, "ready %s\n", ptsname(master));
    fflush(ctl);

    uint64_t start = now_us();
    avr_cycle_count_t slice = freq / 1000;
    for (;;) {
        uint64_t now = now_us();
        avr_cycle_count_t due = (avr_cycle_count_t)((now - start) * (freq / 1000) / 1000);
        if (due > avr->cycle + 2 * slice) {
            /* Fallen behind (a busy machine): simulated time does not race to
             * catch up, it lags, so the firmware's timing is never faster
             * than real time. */
            start = now - (uint64_t)(avr->cycle * 1000 / (freq / 1000));
            due = avr->cycle;
        }
        avr_cycle_count_t stop = due < avr->cycle + slice ? due : avr->cycle + slice;
        while (avr->cycle < stop) {
            int st = avr_run(avr);
            if (st == cpu_Done || st == cpu_Crashed) die("the CPU stopped (crashed, or sleeping with interrupts off)", NULL);
            /* a write to the stuck cell is undone before the next instruction can read it back */
            if (stuck >= 0) eeprom[stuck] = stuck_value;
        }
        pump_pty();
        if (!pump_stdin()) break;
        if (avr->cycle >= due) {
            struct timespec ts = {0, 100000};
            nanosleep(&ts, NULL);
        }
    }
    unplug();
    if (eeprom_file) {
        FILE *f = fopen(eeprom_file, "wb");
        if (!f || !eeprom || fwrite(eeprom, 1, ee_size, f) != ee_size) die("cannot save the EEPROM to ", eeprom_file);
        fclose(f);
    }
    return 0;
}
