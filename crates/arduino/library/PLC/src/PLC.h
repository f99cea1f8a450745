// PLC.h — program an Arduino by hand in the style of the S7-200's instruction list
// (STL/AWL), as the 2014 Arduino-PLC thesis's library did (source 001, annex 10.1),
// on the runtime Alba generates for its sketches (alba_rt.h): timers and counters
// count exactly as `alba sim` and Alba's firmware count them.
//
//   #include <PLC.h>
//   PLC_TIMER(37);                 // T37: a 100 ms timer, as on the S7-200
//   void setup() { setupPLC(); }
//   void loop() {
//       scanPLC();                 // once per scan: the clock, SM0.0, SM0.1, SM0.5
//       LD(I0_0); O(Q0_0); AN(I0_1); OUT(Q0_0);   // start/stop with seal-in
//       LD(Q0_0); TON(T37, 50);                    // 5 s after the start…
//       LD(T37); OUT(Q0_1);                        // …the lamp
//   }
//
// Documented in docs/arduino.md ("PLC.h"). Build the example: File > Examples > PLC.
#ifndef PLC_h
#define PLC_h

#include <Arduino.h>
#include <stdint.h>

#include "alba_rt.h"

// ---- inputs and outputs --------------------------------------------------
// Alba's `s7` pin map (and the thesis's): I0.0–I0.5 on D2–D7, Q0.0–Q0.5 on
// D8–D13, the thesis's names X0–X5 and Y0–Y5 for the same pins. A pin number
// given to LD/A/O… is read with digitalRead, to OUT/S/R written with
// digitalWrite, when the instruction runs.
typedef uint8_t plc_pin;
const plc_pin I0_0 = 2, I0_1 = 3, I0_2 = 4, I0_3 = 5, I0_4 = 6, I0_5 = 7;
const plc_pin Q0_0 = 8, Q0_1 = 9, Q0_2 = 10, Q0_3 = 11, Q0_4 = 12, Q0_5 = 13;
const plc_pin X0 = 2, X1 = 3, X2 = 4, X3 = 5, X4 = 6, X5 = 7;
const plc_pin Y0 = 8, Y1 = 9, Y2 = 10, Y3 = 11, Y4 = 12, Y5 = 13;

// ---- timers and counters ---------------------------------------------------
// Declare the ones you use: PLC_TIMER(37) declares T37, PLC_COUNTER(5) C5. A
// timer's number gives its resolution as on the S7-200: TONR T0/T64 1 ms,
// T1–T4/T65–T68 10 ms, T5–T31/T69–T95 100 ms; TON and TOF T32/T96 1 ms,
// T33–T36/T97–T100 10 ms, T37–T63/T101–T255 100 ms.
struct PLC_Timer {
    int32_t i[4];  // CV, PT, pending ms, last update (alba_rt.h's layout)
    bool b[2];     // the timer bit, enable in the last scan
    uint16_t res;  // resolution, ms
    explicit PLC_Timer(uint8_t n)
        : i{0, 0, 0, 0}, b{false, false},
          res((n == 0 || n == 64 || n == 32 || n == 96)               ? 1
              : ((n >= 1 && n <= 4) || (n >= 65 && n <= 68) || (n >= 33 && n <= 36) || (n >= 97 && n <= 100)) ? 10
                                                                                                                     : 100) {}
    bool q() const { return b[0]; }
    int16_t value() const { return (int16_t)i[0]; }  // the current value, in units of res
};
struct PLC_Counter {
    int32_t i[2];  // CV, PV
    bool b[5];     // the counter bit, CU and CD as last seen, CU, CD
    PLC_Counter() : i{0, 0}, b{false, false, false, false, false} {}
    bool q() const { return b[0]; }
    int16_t value() const { return (int16_t)i[0]; }
};
#define PLC_TIMER(n) PLC_Timer T##n(n)
#define PLC_COUNTER(n) PLC_Counter C##n

// ---- the scan --------------------------------------------------------------
// SM0.0 always on, SM0.1 on in the first scan only, SM0.5 a 1 s clock (0.5 s on,
// 0.5 s off), as the S7-200's special memory; plc_now the scan's time in ms.
static bool SM0_0 __attribute__((unused)) = true;
static bool SM0_1 = true, SM0_5 = false;
static uint32_t plc_now;
static bool plc_started;

// The logic stack: nine levels, the top in bit 0, as on the S7-200. A tenth
// load drops the oldest value.
static uint16_t plc_stack;

static inline bool plc_top() { return plc_stack & 1u; }
static inline void plc_set_top(bool v) { plc_stack = (uint16_t)((plc_stack & ~1u) | (v ? 1u : 0u)); }
static inline void plc_push(bool v) { plc_stack = (uint16_t)(((plc_stack << 1) | (v ? 1u : 0u)) & 0x1FFu); }
static inline bool plc_read(plc_pin p) { return digitalRead(p) == HIGH; }

// Pins of the s7 map: inputs, outputs low.
static inline void setupPLC() {
    for (plc_pin p = I0_0; p <= I0_5; p++) pinMode(p, INPUT);
    for (plc_pin p = Q0_0; p <= Q0_5; p++) {
        pinMode(p, OUTPUT);
        digitalWrite(p, LOW);
    }
}

// Call first in loop(): the scan's clock and special bits; the stack starts empty.
static inline void scanPLC() {
    plc_now = millis();
    SM0_1 = !plc_started;
    plc_started = true;
    SM0_5 = (plc_now % 1000u) < 500u;
    plc_stack = 0;
}

// ---- bit logic ---------------------------------------------------------------
// LD pushes a value, A and O combine it with the top, N negates it first.
static inline void LD(bool v) { plc_push(v); }
static inline void LD(plc_pin p) { plc_push(plc_read(p)); }
static inline void LD(const PLC_Timer &t) { plc_push(t.q()); }
static inline void LD(const PLC_Counter &c) { plc_push(c.q()); }
static inline void LDN(bool v) { plc_push(!v); }
static inline void LDN(plc_pin p) { plc_push(!plc_read(p)); }
static inline void LDN(const PLC_Timer &t) { plc_push(!t.q()); }
static inline void LDN(const PLC_Counter &c) { plc_push(!c.q()); }
static inline void A(bool v) { plc_set_top(plc_top() && v); }
static inline void A(plc_pin p) { A(plc_read(p)); }
static inline void A(const PLC_Timer &t) { A(t.q()); }
static inline void A(const PLC_Counter &c) { A(c.q()); }
static inline void AN(bool v) { A(!v); }
static inline void AN(plc_pin p) { A(!plc_read(p)); }
static inline void AN(const PLC_Timer &t) { A(!t.q()); }
static inline void AN(const PLC_Counter &c) { A(!c.q()); }
static inline void O(bool v) { plc_set_top(plc_top() || v); }
static inline void O(plc_pin p) { O(plc_read(p)); }
static inline void O(const PLC_Timer &t) { O(t.q()); }
static inline void O(const PLC_Counter &c) { O(c.q()); }
static inline void ON(bool v) { O(!v); }
static inline void ON(plc_pin p) { O(!plc_read(p)); }
static inline void ON(const PLC_Timer &t) { O(!t.q()); }
static inline void ON(const PLC_Counter &c) { O(!c.q()); }
static inline void NOT() { plc_set_top(!plc_top()); }

// The stack: ALD/OLD combine the two top levels, LPS pushes a copy of the top,
// LRD copies the second level to the top, LPP pops, LDS n pushes level n.
static inline void ALD() {
    bool a = plc_stack & 1u, b = plc_stack & 2u;
    plc_stack = (uint16_t)((plc_stack >> 1) & ~1u) | (a && b ? 1u : 0u);
}
static inline void OLD() {
    bool a = plc_stack & 1u, b = plc_stack & 2u;
    plc_stack = (uint16_t)((plc_stack >> 1) & ~1u) | (a || b ? 1u : 0u);
}
static inline void LPS() { plc_push(plc_top()); }
static inline void LRD() { plc_set_top(plc_stack & 2u); }
static inline void LPP() { plc_stack >>= 1; }
static inline void LDS(uint8_t n) { plc_push(n < 9 && (plc_stack >> n) & 1u); }

// Edges: EU is on for one scan when the top rises, ED when it falls; `last`
// is the instruction's memory (a bool of its own per EU/ED).
static inline void EU(bool &last) {
    bool v = plc_top();
    plc_set_top(v && !last);
    last = v;
}
static inline void ED(bool &last) {
    bool v = plc_top();
    plc_set_top(!v && last);
    last = v;
}

// ---- outputs -----------------------------------------------------------------
// OUT is the S7-200's `=`: the top to a pin or a bit. S and R set and reset
// while the top is on (n bits from the one given, as `S Q0.0, 2`).
static inline void OUT(plc_pin p) { digitalWrite(p, plc_top() ? HIGH : LOW); }
static inline void OUT(bool &m) { m = plc_top(); }
static inline void S(plc_pin p, uint8_t n = 1) {
    if (plc_top())
        for (uint8_t k = 0; k < n; k++) digitalWrite(p + k, HIGH);
}
static inline void R(plc_pin p, uint8_t n = 1) {
    if (plc_top())
        for (uint8_t k = 0; k < n; k++) digitalWrite(p + k, LOW);
}
static inline void S(bool &m) {
    if (plc_top()) m = true;
}
static inline void R(bool &m) {
    if (plc_top()) m = false;
}
static inline void R(PLC_Timer &t) {
    if (plc_top()) alba_s7_res_t(t.i, t.b);
}
static inline void R(PLC_Counter &c) {
    if (plc_top()) alba_s7_res_c(c.i, c.b);
}

// ---- timers ------------------------------------------------------------------
// Enabled by the top of the stack (which they leave as it is); PT in units of
// the timer's resolution: TON(T37, 50) is 5 s.
static inline void TON(PLC_Timer &t, int16_t pt) {
    t.i[1] = pt;
    alba_s7_timer(t.i, t.b, plc_top(), plc_now, t.res, 0);
}
static inline void TONR(PLC_Timer &t, int16_t pt) {
    t.i[1] = pt;
    alba_s7_timer(t.i, t.b, plc_top(), plc_now, t.res, 1);
}
static inline void TOF(PLC_Timer &t, int16_t pt) {
    t.i[1] = pt;
    alba_s7_timer(t.i, t.b, plc_top(), plc_now, t.res, 2);
}

// ---- counters ----------------------------------------------------------------
// As the S7-200: CTU counts rising edges of the second level and is reset by the
// top (LD count; LD reset; CTU(C5, 3)); CTD counts down the second level, the top
// loads PV; CTUD counts up the third level and down the second, the top resets.
// The inputs are used: the first one is left on top.
static inline void plc_counter(PLC_Counter &c, int16_t pv, uint8_t kind) {
    uint8_t inputs = kind == 2 ? 3 : 2;
    c.i[1] = pv;
    if (kind == 0) c.b[3] = plc_stack & 2u;
    if (kind == 1) c.b[4] = plc_stack & 2u;
    if (kind == 2) {
        c.b[3] = plc_stack & 4u;
        c.b[4] = plc_stack & 2u;
    }
    alba_s7_counter(c.i, c.b, plc_top(), kind);
    plc_stack >>= inputs - 1;
}
static inline void CTU(PLC_Counter &c, int16_t pv) { plc_counter(c, pv, 0); }
static inline void CTD(PLC_Counter &c, int16_t pv) { plc_counter(c, pv, 1); }
static inline void CTUD(PLC_Counter &c, int16_t pv) { plc_counter(c, pv, 2); }

// ---- words -------------------------------------------------------------------
// While the top is on: MOVW moves, ADDW/SUBW/MULW/DIVW compute `out = out op in`
// (the S7-200's +I -I *I /I) with alba_rt.h's overflow and division rules.
// Compares push (LDW…) or combine with the top (AW…, OW…).
static inline void MOVW(int16_t in, int16_t &out) {
    if (plc_top()) out = in;
}
static inline int16_t plc_sat16(int32_t v) { return v > INT16_MAX ? INT16_MAX : v < INT16_MIN ? INT16_MIN : (int16_t)v; }
static inline void ADDW(int16_t in, int16_t &out) {
    if (plc_top()) out = plc_sat16(alba_add<int32_t>(out, in, 0));
}
static inline void SUBW(int16_t in, int16_t &out) {
    if (plc_top()) out = plc_sat16(alba_sub<int32_t>(out, in, 0));
}
static inline void MULW(int16_t in, int16_t &out) {
    if (plc_top()) out = plc_sat16(alba_mul<int32_t>(out, in, 0));
}
static inline void DIVW(int16_t in, int16_t &out) {
    if (plc_top()) out = plc_sat16(alba_div<int32_t>(out, in, 0));
}
static inline void LDWEQ(int16_t a, int16_t b) { plc_push(a == b); }
static inline void LDWNE(int16_t a, int16_t b) { plc_push(a != b); }
static inline void LDWLT(int16_t a, int16_t b) { plc_push(a < b); }
static inline void LDWGT(int16_t a, int16_t b) { plc_push(a > b); }
static inline void LDWLE(int16_t a, int16_t b) { plc_push(a <= b); }
static inline void LDWGE(int16_t a, int16_t b) { plc_push(a >= b); }
static inline void AWEQ(int16_t a, int16_t b) { A(a == b); }
static inline void AWLT(int16_t a, int16_t b) { A(a < b); }
static inline void AWGT(int16_t a, int16_t b) { A(a > b); }
static inline void OWEQ(int16_t a, int16_t b) { O(a == b); }
// AIW: an analog input of the s7 map (A0–A5), 0–1023.
static inline int16_t AIW(uint8_t n) { return (int16_t)analogRead(A0 + n); }

#endif
