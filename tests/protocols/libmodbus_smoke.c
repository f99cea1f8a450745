/* A libmodbus client against Alba's Modbus TCP server (tests/protocols).
 * Usage: libmodbus_smoke HOST PORT. Exit 0 when every check passes. */
#include <errno.h>
#include <modbus.h>
#include <stdio.h>
#include <stdlib.h>

static int failed = 0;

#define CHECK(cond, ...)                                  \
    do {                                                  \
        if (!(cond)) {                                    \
            fprintf(stderr, "FAIL line %d: ", __LINE__);  \
            fprintf(stderr, __VA_ARGS__);                 \
            fprintf(stderr, "\n");                        \
            failed++;                                     \
        }                                                 \
    } while (0)

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s HOST PORT\n", argv[0]);
        return 2;
    }
    modbus_t *ctx = modbus_new_tcp(argv[1], atoi(argv[2]));
    if (ctx == NULL || modbus_set_slave(ctx, 1) == -1 || modbus_connect(ctx) == -1) {
        fprintf(stderr, "cannot connect: %s\n", modbus_strerror(errno));
        return 1;
    }
    uint16_t regs[16];
    uint8_t bits[16];
    /* %MW0 (holding register 1024) and %MD1 (2050-2051). */
    CHECK(modbus_write_register(ctx, 1024, 4321) == 1, "write hr 1024: %s", modbus_strerror(errno));
    CHECK(modbus_read_registers(ctx, 1024, 1, regs) == 1 && regs[0] == 4321, "read hr 1024");
    uint16_t dint[2] = {0x0001, 0x0002};
    CHECK(modbus_write_registers(ctx, 2050, 2, dint) == 2, "write hr 2050-2051: %s", modbus_strerror(errno));
    CHECK(modbus_read_registers(ctx, 2050, 2, regs) == 2 && regs[0] == 1 && regs[1] == 2, "read hr 2050-2051");
    /* Coils, discrete inputs, input registers. */
    CHECK(modbus_write_bit(ctx, 1, 1) == 1, "write coil 1: %s", modbus_strerror(errno));
    CHECK(modbus_read_bits(ctx, 0, 2, bits) == 2 && bits[1] == 1, "read coils 0-1");
    uint8_t many[3] = {1, 0, 1};
    CHECK(modbus_write_bits(ctx, 200, 3, many) == 3, "write coils 200-202: %s", modbus_strerror(errno));
    CHECK(modbus_read_bits(ctx, 200, 3, bits) == 3 && bits[0] == 1 && bits[1] == 0 && bits[2] == 1, "read coils 200-202");
    CHECK(modbus_read_input_bits(ctx, 0, 8, bits) == 8, "read discrete inputs: %s", modbus_strerror(errno));
    CHECK(modbus_read_input_registers(ctx, 1024, 2, regs) == 2, "read ir 1024-1025: %s", modbus_strerror(errno));
    /* FC23. */
    uint16_t w = 99;
    CHECK(modbus_write_and_read_registers(ctx, 3000, 1, &w, 3000, 1, regs) == 1 && regs[0] == 99, "FC23");
    /* Exceptions come back as libmodbus errors. */
    CHECK(modbus_read_registers(ctx, 9000, 1, regs) == -1 && errno == EMBXILADD, "hr 9000: illegal data address");
    CHECK(modbus_write_register(ctx, 8193, 1) == -1 && errno == EMBXILADD, "half of a DINT: illegal data address");
    /* Many requests in a row on one connection. */
    int ok = 0;
    for (int i = 0; i < 2000; i++) {
        ok += modbus_read_registers(ctx, 0, 10, regs) == 10;
    }
    CHECK(ok == 2000, "%d of 2000 reads answered", ok);
    modbus_write_register(ctx, 1024, 4321);
    modbus_close(ctx);
    modbus_free(ctx);
    printf("libmodbus %s: %s\n", LIBMODBUS_VERSION_STRING, failed ? "FAILED" : "all checks passed");
    return failed ? 1 : 0;
}
