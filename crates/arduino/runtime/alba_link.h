// Alba monitoring link: a Modbus RTU slave on the board's serial port, served
// between scans (never during one), so the studio can watch and write the
// program's memory while the board runs it (docs/arduino.md, "Monitoring link").
//
// The sketch defines ALBA_LINK_SLAVE and ALBA_LINK_BAUD, then the four
// callbacks below, each returning 0 or a Modbus exception code.
//
// Replies never wait for the serial transmit buffer (64 bytes): a request
// reads at most 24 registers or 256 bits, else exception 3, so a reply of the
// link can never delay a scan.
#ifndef ALBA_LINK_H
#define ALBA_LINK_H

#include <Arduino.h>

static uint8_t link_read_bit(uint8_t fc, uint16_t at, bool *v);
static uint8_t link_read_reg(uint8_t fc, uint16_t at, uint16_t *v);
static uint8_t link_write_bits(uint16_t at, uint16_t n, const uint8_t *packed);
static uint8_t link_write_regs(uint16_t at, uint16_t n, const uint8_t *be);

#define ALBA_LINK_MAX_REGS 24
#define ALBA_LINK_MAX_BITS 256

// 3.5 characters of silence end a frame: 1750 us above 19200 baud (Modbus
// over serial line, 2.5.1.1).
static const uint32_t alba_link_t35_us = ALBA_LINK_BAUD > 19200UL ? 1750UL : 38500000UL / ALBA_LINK_BAUD;

static uint8_t alba_link_frame[9 + 2 * ALBA_LINK_MAX_REGS];
static uint8_t alba_link_len;
static bool alba_link_overflow;
static uint32_t alba_link_last_us;
static uint8_t alba_link_out[5 + 2 * ALBA_LINK_MAX_REGS];

static uint16_t alba_crc16(const uint8_t *p, uint8_t n) {
    uint16_t crc = 0xFFFF;
    while (n--) {
        crc ^= *p++;
        for (uint8_t k = 0; k < 8; k++) crc = (crc & 1) ? (crc >> 1) ^ 0xA001 : crc >> 1;
    }
    return crc;
}

static void alba_link_send(uint8_t n) {
    uint16_t c = alba_crc16(alba_link_out, n);
    alba_link_out[n] = (uint8_t)(c & 0xFF);
    alba_link_out[n + 1] = (uint8_t)(c >> 8);
    Serial.write(alba_link_out, n + 2);
}

static uint16_t alba_link_be16(uint8_t at) {
    return (uint16_t)((uint16_t)alba_link_frame[at] << 8 | alba_link_frame[at + 1]);
}

// Answers the frame in alba_link_frame (CRC checked); exception codes as Modbus.
static uint8_t alba_link_handle(void) {
    const uint8_t *f = alba_link_frame;
    uint8_t n = alba_link_len, fc = f[1];
    alba_link_out[0] = f[0];
    alba_link_out[1] = fc;
    switch (fc) {
    case 1:
    case 2: {
        if (n != 8) return 3;
        uint16_t start = alba_link_be16(2), qty = alba_link_be16(4);
        if (qty < 1 || qty > ALBA_LINK_MAX_BITS) return 3;
        uint8_t bytes = (uint8_t)((qty + 7) / 8);
        if (bytes > 2 * ALBA_LINK_MAX_REGS) return 3;
        alba_link_out[2] = bytes;
        for (uint8_t i = 0; i < bytes; i++) alba_link_out[3 + i] = 0;
        for (uint16_t i = 0; i < qty; i++) {
            bool v = false;
            uint8_t e = link_read_bit(fc, start + i, &v);
            if (e) return e;
            if (v) alba_link_out[3 + i / 8] |= (uint8_t)(1 << (i % 8));
        }
        alba_link_send(3 + bytes);
        return 0;
    }
    case 3:
    case 4: {
        if (n != 8) return 3;
        uint16_t start = alba_link_be16(2), qty = alba_link_be16(4);
        if (qty < 1 || qty > ALBA_LINK_MAX_REGS) return 3;
        alba_link_out[2] = (uint8_t)(2 * qty);
        for (uint8_t i = 0; i < qty; i++) {
            uint16_t v = 0;
            uint8_t e = link_read_reg(fc, start + i, &v);
            if (e) return e;
            alba_link_out[3 + 2 * i] = (uint8_t)(v >> 8);
            alba_link_out[4 + 2 * i] = (uint8_t)(v & 0xFF);
        }
        alba_link_send(3 + 2 * qty);
        return 0;
    }
    case 5:
    case 6: {
        if (n != 8) return 3;
        uint16_t at = alba_link_be16(2), v = alba_link_be16(4);
        uint8_t e;
        if (fc == 5) {
            if (v != 0xFF00 && v != 0x0000) return 3;
            uint8_t bit = v ? 1 : 0;
            e = link_write_bits(at, 1, &bit);
        } else {
            e = link_write_regs(at, 1, &f[4]);
        }
        if (e) return e;
        for (uint8_t i = 2; i < 6; i++) alba_link_out[i] = f[i];
        alba_link_send(6);
        return 0;
    }
    case 15:
    case 16: {
        if (n < 9) return 3;
        uint16_t at = alba_link_be16(2), qty = alba_link_be16(4);
        uint8_t bytes = f[6];
        uint16_t want = fc == 15 ? (qty + 7) / 8 : 2 * qty;
        if (qty < 1 || bytes != want || n != 9 + bytes) return 3;
        uint8_t e = fc == 15 ? link_write_bits(at, qty, &f[7]) : link_write_regs(at, qty, &f[7]);
        if (e) return e;
        for (uint8_t i = 2; i < 6; i++) alba_link_out[i] = f[i];
        alba_link_send(6);
        return 0;
    }
    default:
        return 1;
    }
}

// A byte of a frame, as it arrives.
static void alba_link_byte(uint8_t c) {
    if (alba_link_len < sizeof alba_link_frame) alba_link_frame[alba_link_len++] = c;
    else alba_link_overflow = true;
    alba_link_last_us = micros();
}

// Answers the frame received once 3.5 characters of silence have ended it.
static void alba_link_end(void) {
    if (alba_link_len == 0 || micros() - alba_link_last_us < alba_link_t35_us) return;
    uint8_t n = alba_link_len;
    // A frame too long for the buffer, for another slave or with a bad CRC
    // is ignored, as Modbus asks.
    bool whole = !alba_link_overflow && n >= 4 && alba_link_frame[0] == ALBA_LINK_SLAVE &&
                 alba_crc16(alba_link_frame, n - 2) == (uint16_t)(alba_link_frame[n - 2] | (uint16_t)alba_link_frame[n - 1] << 8);
    if (whole) {
        uint8_t e = alba_link_handle();
        if (e) {
            alba_link_out[0] = ALBA_LINK_SLAVE;
            alba_link_out[1] = alba_link_frame[1] | 0x80;
            alba_link_out[2] = e;
            alba_link_send(3);
        }
    }
    alba_link_len = 0;
    alba_link_overflow = false;
}

// Call between scans: takes the bytes that arrived and answers a complete frame.
static __attribute__((unused)) void alba_link_poll(void) {
    while (Serial.available() > 0) alba_link_byte((uint8_t)Serial.read());
    alba_link_end();
}

#endif
