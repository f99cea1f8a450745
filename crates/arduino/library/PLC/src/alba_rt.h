// Alba runtime for generated sketches: the semantics of crates/engine/src/exec/,
// function by function, in C++ that avr-gcc 5.4 (gnu++11, int = 16 bits, double =
// float) and a host g++ both build. Timers count wrapping milliseconds of the scan
// clock; faults never stop a scan: they give the interpreter's defined result and
// are reported in S:MINOR / S:FAULTCODE at the end of the scan.
#ifndef ALBA_RT_H
#define ALBA_RT_H

#include <stdint.h>
#include <math.h>

// How the helpers are compiled: inline in a sketch (each op is written once), out of
// line in the byte-code interpreter (every op is a case of one switch).
#ifndef ALBA_INLINE
#define ALBA_INLINE inline
#endif

// Minor fault codes (crates/engine/src/fault.rs).
#define ALBA_OVERFLOW 1
#define ALBA_DIVZERO 2
#define ALBA_NAN 3
#define ALBA_RANGE 4
#define ALBA_NEGPRESET 5

// The last fault of this scan (0: none) and the op it happened at.
static uint8_t alba_fault_code;
static uint16_t alba_fault_pc;

static void alba_fault(uint8_t code, uint16_t pc) __attribute__((noinline, unused));
static void alba_fault(uint8_t code, uint16_t pc) {
    alba_fault_code = code;
    alba_fault_pc = pc;
}

// ---- integers -------------------------------------------------------------

template <typename T> struct alba_lim_of;
template <> struct alba_lim_of<int32_t> {
    static int32_t lowest() { return INT32_MIN; }
    static int32_t highest() { return INT32_MAX; }
};
template <> struct alba_lim_of<int64_t> {
    static int64_t lowest() { return INT64_MIN; }
    static int64_t highest() { return INT64_MAX; }
};

template <typename T> static ALBA_INLINE T alba_add(T a, T b, uint16_t pc) {
    T r;
    if (__builtin_add_overflow(a, b, &r)) alba_fault(ALBA_OVERFLOW, pc);
    return r;
}
template <typename T> static ALBA_INLINE T alba_sub(T a, T b, uint16_t pc) {
    T r;
    if (__builtin_sub_overflow(a, b, &r)) alba_fault(ALBA_OVERFLOW, pc);
    return r;
}
template <typename T> static ALBA_INLINE T alba_mul(T a, T b, uint16_t pc) {
    T r;
    if (__builtin_mul_overflow(a, b, &r)) alba_fault(ALBA_OVERFLOW, pc);
    return r;
}
// Division by zero saturates (0/0 is 0); MIN / -1 wraps to MIN; each a fault.
template <typename T> static ALBA_INLINE T alba_div(T a, T b, uint16_t pc) {
    if (b == 0) {
        alba_fault(ALBA_DIVZERO, pc);
        return a > 0 ? alba_lim_of<T>::highest() : a < 0 ? alba_lim_of<T>::lowest() : 0;
    }
    if (b == -1 && a == alba_lim_of<T>::lowest()) {
        alba_fault(ALBA_OVERFLOW, pc);
        return a;
    }
    return a / b;
}
template <typename T> static ALBA_INLINE T alba_mod(T a, T b, uint16_t pc) {
    if (b == 0) {
        alba_fault(ALBA_DIVZERO, pc);
        return 0;
    }
    if (b == -1) return 0;
    return a % b;
}
template <typename T> static ALBA_INLINE T alba_neg(T a, uint16_t pc) {
    if (a == alba_lim_of<T>::lowest()) {
        alba_fault(ALBA_OVERFLOW, pc);
        return a;
    }
    return -a;
}
template <typename T> static ALBA_INLINE T alba_abs(T a, uint16_t pc) {
    if (a == alba_lim_of<T>::lowest()) {
        alba_fault(ALBA_OVERFLOW, pc);
        return a;
    }
    return a < 0 ? -a : a;
}
// BCD to binary: a negative value or a nibble above 9 is a range fault (0).
template <typename T> static ALBA_INLINE T alba_frd(T a, uint16_t pc) {
    if (a < 0) {
        alba_fault(ALBA_RANGE, pc);
        return 0;
    }
    T v = 0, mul = 1, x = a;
    while (x > 0) {
        T digit = x & 0xF;
        if (digit > 9) {
            alba_fault(ALBA_RANGE, pc);
            return 0;
        }
        v += digit * mul;
        mul = mul > alba_lim_of<T>::highest() / 10 ? alba_lim_of<T>::highest() : mul * 10;
        x >>= 4;
    }
    return v;
}
// Binary to BCD: 0 ..= max, else a range fault (0).
template <typename T> static ALBA_INLINE T alba_tod(T a, T max, uint16_t pc) {
    if (a < 0 || a > max) {
        alba_fault(ALBA_RANGE, pc);
        return 0;
    }
    T v = 0, x = a;
    uint8_t shift = 0;
    while (x > 0) {
        v |= (x % 10) << shift;
        shift += 4;
        x /= 10;
    }
    return v;
}
// LIM with the Logix wrap-around rule.
template <typename T> static ALBA_INLINE bool alba_lim(T lo, T t, T hi) {
    return lo <= hi ? (lo <= t && t <= hi) : (t >= lo || t <= hi);
}

// ---- REAL -----------------------------------------------------------------

// NaN becomes 0 and an infinity ±FLT_MAX, each a fault (division by zero when
// the divisor was zero).
static ALBA_INLINE float alba_fix(float v, bool divisor_zero, uint16_t pc) {
    if (isfinite(v)) return v;
    if (divisor_zero) {
        alba_fault(ALBA_DIVZERO, pc);
        return isnan(v) ? 0.0f : copysignf(3.40282347e+38f, v);
    }
    if (isnan(v)) {
        alba_fault(ALBA_NAN, pc);
        return 0.0f;
    }
    alba_fault(ALBA_OVERFLOW, pc);
    return copysignf(3.40282347e+38f, v);
}
// Round half to even (Rust's round_ties_even).
static ALBA_INLINE float alba_round_even(float x) {
    float t = truncf(x);
    float d = x - t;  // exact
    if (fabsf(d) > 0.5f || (fabsf(d) == 0.5f && fmodf(t, 2.0f) != 0.0f)) t += (x < 0.0f ? -1.0f : 1.0f);
    return t;
}
// REAL to DINT/LINT: round half to even; NaN gives 0 and out-of-range values
// saturate, each a fault. `hi` is the first float above the range (2^31, 2^63).
static ALBA_INLINE int32_t alba_f2i(float v, uint16_t pc) {
    if (isnan(v)) {
        alba_fault(ALBA_NAN, pc);
        return 0;
    }
    float r = alba_round_even(v);
    if (r < -2147483648.0f) {
        alba_fault(ALBA_OVERFLOW, pc);
        return INT32_MIN;
    }
    if (r >= 2147483648.0f) {
        alba_fault(ALBA_OVERFLOW, pc);
        return INT32_MAX;
    }
    return (int32_t)r;
}
static ALBA_INLINE int64_t alba_f2l(float v, uint16_t pc) {
    if (isnan(v)) {
        alba_fault(ALBA_NAN, pc);
        return 0;
    }
    float r = alba_round_even(v);
    if (r < -9223372036854775808.0f) {
        alba_fault(ALBA_OVERFLOW, pc);
        return INT64_MIN;
    }
    if (r >= 9223372036854775808.0f) {
        alba_fault(ALBA_OVERFLOW, pc);
        // The largest double below 2^63, as the engine saturates.
        return INT64_C(9223372036854774784);
    }
    return (int64_t)r;
}

// ---- marker memory (big-endian) -----------------------------------------

static ALBA_INLINE int32_t alba_ld_word(const uint8_t *p) { return (int16_t)((uint16_t)p[0] << 8 | p[1]); }
static ALBA_INLINE int32_t alba_ld_dword(const uint8_t *p) {
    return (int32_t)((uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]);
}
static ALBA_INLINE float alba_ld_real(const uint8_t *p, uint16_t pc) {
    union { uint32_t u; float f; } v;
    v.u = (uint32_t)alba_ld_dword(p);
    return alba_fix(v.f, false, pc);
}
static ALBA_INLINE void alba_st_word(uint8_t *p, int32_t v) {
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}
static ALBA_INLINE void alba_st_dword(uint8_t *p, int32_t v) {
    p[0] = (uint8_t)((uint32_t)v >> 24);
    p[1] = (uint8_t)((uint32_t)v >> 16);
    p[2] = (uint8_t)((uint32_t)v >> 8);
    p[3] = (uint8_t)v;
}
static ALBA_INLINE void alba_st_real(uint8_t *p, float f) {
    union { uint32_t u; float f; } v;
    v.f = f;
    alba_st_dword(p, (int32_t)v.u);
}

// ---- timers (TIMER: i = PRE, ACC, LAST; b = EN, TT, DN) -------------------
// TON, TOF and RTO count ACC in units of their time base `base` (ms: 1, 10, 100,
// 1000 or 60000); TP counts milliseconds.

static ALBA_INLINE int32_t alba_preset(const int32_t *ti, uint16_t pc) {
    if (ti[0] < 0) {
        alba_fault(ALBA_NEGPRESET, pc);
        return 0;
    }
    return ti[0];
}
// Adds the time since the last update to ACC in whole units of `base` ms; the last
// update moves on by the units counted only, so the time short of a unit is kept.
static ALBA_INLINE void alba_elapse(int32_t *ti, uint32_t now, uint32_t base) {
    uint32_t dt = now - (uint32_t)ti[2];
    if (base > 1) {
        dt /= base;
        ti[2] = (int32_t)((uint32_t)ti[2] + dt * base);
    } else {
        ti[2] = (int32_t)now;
    }
    if (dt > (uint32_t)INT32_MAX) dt = INT32_MAX;
    ti[1] = ti[1] > INT32_MAX - (int32_t)dt ? INT32_MAX : ti[1] + (int32_t)dt;
}
static ALBA_INLINE void alba_done_at_preset(int32_t *ti, bool *tb, int32_t pre) {
    if (!tb[2] && ti[1] >= pre) {
        tb[2] = true;
        ti[1] = pre;
    }
}
static ALBA_INLINE void alba_ton(int32_t *ti, bool *tb, bool rc, uint32_t now, uint32_t base, uint16_t pc) {
    if (rc) {
        int32_t pre = alba_preset(ti, pc);
        if (!tb[0]) {
            tb[0] = true;
            ti[1] = 0;
            ti[2] = (int32_t)now;
        } else if (!tb[2]) {
            alba_elapse(ti, now, base);
        }
        alba_done_at_preset(ti, tb, pre);
        tb[1] = !tb[2];
    } else {
        tb[0] = tb[1] = tb[2] = false;
        ti[1] = 0;
    }
}
static ALBA_INLINE void alba_tof(int32_t *ti, bool *tb, bool rc, uint32_t now, uint32_t base, uint16_t pc) {
    if (rc) {
        tb[0] = true;
        tb[2] = true;
        tb[1] = false;
        ti[1] = 0;
        return;
    }
    if (tb[0]) {
        tb[0] = false;
        tb[1] = true;
        ti[1] = 0;
        ti[2] = (int32_t)now;
    } else if (tb[1]) {
        alba_elapse(ti, now, base);
    }
    if (tb[1]) {
        int32_t pre = alba_preset(ti, pc);
        if (ti[1] >= pre) {
            tb[2] = tb[1] = false;
            ti[1] = pre;
        }
    }
}
static ALBA_INLINE void alba_rto(int32_t *ti, bool *tb, bool rc, uint32_t now, uint32_t base, uint16_t pc) {
    if (rc) {
        int32_t pre = alba_preset(ti, pc);
        if (!tb[0]) {
            tb[0] = true;
            ti[2] = (int32_t)now;
        } else if (!tb[2]) {
            alba_elapse(ti, now, base);
        }
        alba_done_at_preset(ti, tb, pre);
        tb[1] = !tb[2];
    } else {
        tb[0] = tb[1] = false;
    }
}
static ALBA_INLINE void alba_tp(int32_t *ti, bool *tb, bool rc, uint32_t now, uint16_t pc) {
    bool rising = rc && !tb[0];
    if (tb[2]) {
        alba_elapse(ti, now, 1);
    } else if (rising) {
        tb[2] = true;
        ti[1] = 0;
        ti[2] = (int32_t)now;
    }
    if (tb[2]) {
        int32_t pre = alba_preset(ti, pc);
        if (ti[1] >= pre) {
            tb[2] = false;
            ti[1] = pre;
        }
    }
    if (!tb[2] && !rc) ti[1] = 0;
    tb[1] = tb[2];
    tb[0] = rc;
}
static ALBA_INLINE void alba_res_t(int32_t *ti, bool *tb) {
    ti[1] = 0;
    tb[0] = tb[1] = tb[2] = false;
}

// ---- counters (COUNTER: i = PRE, ACC; b = CU, CD, DN, OV, UN) -------------

static ALBA_INLINE void alba_count(int32_t *ci, bool *cb, bool rc, bool up) {
    bool *edge = up ? &cb[0] : &cb[1];
    if (rc && !*edge) {
        int32_t v = ci[1];
        bool wrapped = up ? v == INT32_MAX : v == INT32_MIN;
        ci[1] = (int32_t)((uint32_t)v + (up ? 1u : 0xFFFFFFFFu));
        if (wrapped) {
            bool *set = up ? &cb[3] : &cb[4];
            bool *clear = up ? &cb[4] : &cb[3];
            if (*clear) *clear = false;
            else *set = true;
        }
    }
    *edge = rc;
    cb[2] = ci[1] >= ci[0];
}
static ALBA_INLINE void alba_res_c(int32_t *ci, bool *cb) {
    ci[1] = 0;
    cb[0] = cb[1] = cb[2] = cb[3] = cb[4] = false;
}

// ---- S7-200 timers (i = CV, PT, pending ms, LAST; b = bit, enable) -------

static ALBA_INLINE void alba_s7_advance(int32_t *ti, uint32_t now, uint16_t res, int32_t cap) {
    uint32_t dt = now - (uint32_t)ti[3];
    ti[3] = (int32_t)now;
    uint64_t total = (uint64_t)(ti[2] > 0 ? ti[2] : 0) + dt;
    uint64_t units = total / res;
    if (units > (uint64_t)INT32_MAX) units = INT32_MAX;
    ti[2] = (int32_t)(total % res);
    int32_t cv = ti[0] > INT32_MAX - (int32_t)units ? INT32_MAX : ti[0] + (int32_t)units;
    if (cap < 0) cap = 0;
    ti[0] = cv < cap ? cv : cap;
}
// kind: 0 TON, 1 TONR, 2 TOF.
static ALBA_INLINE void alba_s7_timer(int32_t *ti, bool *tb, bool enable, uint32_t now, uint16_t res, uint8_t kind) {
    bool was = tb[1];
    tb[1] = enable;
    if (kind != 2) {
        if (enable) {
            if (!was) {
                if (kind == 0) ti[0] = ti[2] = 0;
                ti[3] = (int32_t)now;
            } else {
                alba_s7_advance(ti, now, res, INT16_MAX);
            }
            tb[0] = ti[0] >= ti[1];
        } else if (kind == 0) {
            ti[0] = ti[2] = 0;
            tb[0] = false;
        }
        return;
    }
    if (enable) {
        tb[0] = true;
        ti[0] = ti[2] = 0;
        return;
    }
    if (was) {
        ti[0] = ti[2] = 0;
        ti[3] = (int32_t)now;
    } else if (tb[0]) {
        alba_s7_advance(ti, now, res, ti[1]);
    }
    if (tb[0] && ti[0] >= ti[1]) tb[0] = false;
}
static ALBA_INLINE void alba_s7_res_t(int32_t *ti, bool *tb) {
    ti[0] = ti[2] = 0;
    tb[0] = false;
}

// ---- S7-200 counters (i = CV, PV; b = bit, CU was, CD was, CU, CD) --------

// kind: 0 CTU, 1 CTD, 2 CTUD. `top` is the reset (CTU, CTUD) or load (CTD).
static ALBA_INLINE void alba_s7_counter(int32_t *ci, bool *cb, bool top, uint8_t kind) {
    bool up = cb[3] && !cb[1];
    bool down = cb[4] && !cb[2];
    cb[1] = cb[3];
    cb[2] = cb[4];
    int32_t v = ci[0];
    if (kind == 0) {
        v = top ? 0 : up ? (v + 1 < INT16_MAX ? v + 1 : INT16_MAX) : v;
        ci[0] = v;
        cb[0] = v >= ci[1];
    } else if (kind == 1) {
        if (top) {
            ci[0] = ci[1];
            cb[0] = false;
        } else {
            if (down && v > 0) v--;
            ci[0] = v;
            cb[0] = v == 0;
        }
    } else {
        if (up) v = v >= INT16_MAX ? INT16_MIN : v + 1;
        if (down) v = v <= INT16_MIN ? INT16_MAX : v - 1;
        if (top) v = 0;
        ci[0] = v;
        cb[0] = v >= ci[1];
    }
}
static ALBA_INLINE void alba_s7_res_c(int32_t *ci, bool *cb) {
    ci[0] = 0;
    cb[0] = false;
}

#endif
