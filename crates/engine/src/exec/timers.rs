//! Timers and counters: Logix (TON, TOF, RTO, TP, CTU, CTD) and S7-200.

use crate::fault::FaultCode;
use crate::mem::{Mem, Sink, rd, wr};
use alba_ir::op::{S7Ctr, S7Tmr};
use alba_ir::{Ctr, Tmr};

// ---- timers and counters (SPEC §3.2) ----------------------------------------
//
// A TIMER is integer slots PRE, ACC, LAST (the clock at its last update,
// wrapping milliseconds) and bool slots EN, TT, DN. Time counted is always
// clock time between scans, never a number of scans.

const PRE: u32 = 0;
const ACC: u32 = 1;
const LAST: u32 = 2;
const EN: u32 = 0;
const TT: u32 = 1;
const DN: u32 = 2;

/// The preset, with a fault (and 0) when negative.
#[inline(always)]
fn preset(m: &Mem, t: Tmr, sink: &mut Sink, pc: usize) -> i32 {
    let pre = rd!(m.i, t.i.0 + PRE);
    if pre < 0 {
        sink.fault(FaultCode::NegativePreset, pc);
        return 0;
    }
    pre
}

/// Adds the clock time elapsed since the timer's last update to ACC, in
/// whole units of `base` ms: the last update moves on by the units counted
/// only, so the time short of a unit is kept for the next scan.
#[inline(always)]
fn elapse(m: &mut Mem, t: Tmr, now: u32, base: u32) {
    let last = rd!(m.i, t.i.0 + LAST) as u32;
    let dt = now.wrapping_sub(last);
    let units = if base <= 1 { dt } else { dt / base };
    wr!(
        m.i,
        t.i.0 + LAST,
        last.wrapping_add(units.wrapping_mul(base.max(1))) as i32
    );
    let acc = rd!(m.i, t.i.0 + ACC);
    wr!(m.i, t.i.0 + ACC, acc.saturating_add(units.min(i32::MAX as u32) as i32));
}

/// Sets DN and stops ACC at PRE once reached (TON, RTO).
#[inline(always)]
fn done_at_preset(m: &mut Mem, t: Tmr, pre: i32) {
    if !rd!(m.b, t.b.0 + DN) && rd!(m.i, t.i.0 + ACC) >= pre {
        wr!(m.b, t.b.0 + DN, true);
        wr!(m.i, t.i.0 + ACC, pre);
    }
}

/// TON: rung true → EN; ACC from 0 on the first true scan, adding clock
/// time (in units of `base` ms) after; DN at PRE (ACC stops there); TT = EN ∧ ¬DN. Rung false →
/// everything 0.
#[inline(always)]
pub(super) fn ton(m: &mut Mem, t: Tmr, base: u32, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    if rc {
        let pre = preset(m, t, sink, pc);
        if !rd!(m.b, t.b.0 + EN) {
            wr!(m.b, t.b.0 + EN, true);
            wr!(m.i, t.i.0 + ACC, 0);
            wr!(m.i, t.i.0 + LAST, now as i32);
        } else if !rd!(m.b, t.b.0 + DN) {
            elapse(m, t, now, base);
        }
        done_at_preset(m, t, pre);
        wr!(m.b, t.b.0 + TT, !rd!(m.b, t.b.0 + DN));
    } else {
        wr!(m.b, t.b.0 + EN, false);
        wr!(m.b, t.b.0 + TT, false);
        wr!(m.b, t.b.0 + DN, false);
        wr!(m.i, t.i.0 + ACC, 0);
    }
}

/// TOF: rung true → EN = DN = 1, TT = 0, ACC = 0. The first false scan
/// after that starts timing from 0; at PRE, DN = TT = 0.
pub(super) fn tof(m: &mut Mem, t: Tmr, base: u32, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    if rc {
        wr!(m.b, t.b.0 + EN, true);
        wr!(m.b, t.b.0 + DN, true);
        wr!(m.b, t.b.0 + TT, false);
        wr!(m.i, t.i.0 + ACC, 0);
        return;
    }
    if rd!(m.b, t.b.0 + EN) {
        wr!(m.b, t.b.0 + EN, false);
        wr!(m.b, t.b.0 + TT, true);
        wr!(m.i, t.i.0 + ACC, 0);
        wr!(m.i, t.i.0 + LAST, now as i32);
    } else if rd!(m.b, t.b.0 + TT) {
        elapse(m, t, now, base);
    }
    if rd!(m.b, t.b.0 + TT) {
        let pre = preset(m, t, sink, pc);
        if rd!(m.i, t.i.0 + ACC) >= pre {
            wr!(m.b, t.b.0 + DN, false);
            wr!(m.b, t.b.0 + TT, false);
            wr!(m.i, t.i.0 + ACC, pre);
        }
    }
}

/// RTO: like TON, but a false rung keeps ACC and DN; a true scan after a
/// false one adds nothing (timing resumes then). Only RES clears it.
pub(super) fn rto(m: &mut Mem, t: Tmr, base: u32, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    if rc {
        let pre = preset(m, t, sink, pc);
        if !rd!(m.b, t.b.0 + EN) {
            wr!(m.b, t.b.0 + EN, true);
            wr!(m.i, t.i.0 + LAST, now as i32);
        } else if !rd!(m.b, t.b.0 + DN) {
            elapse(m, t, now, base);
        }
        done_at_preset(m, t, pre);
        wr!(m.b, t.b.0 + TT, !rd!(m.b, t.b.0 + DN));
    } else {
        wr!(m.b, t.b.0 + EN, false);
        wr!(m.b, t.b.0 + TT, false);
    }
}

/// TP: a rising rung starts a pulse DN = 1 of PRE ms (ACC from 0, whatever
/// the rung does next); not retriggerable while DN; ACC = 0 once the pulse
/// has ended and the rung is false. TT follows DN; EN is the rung.
pub(super) fn tp(m: &mut Mem, t: Tmr, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    let rising = rc && !rd!(m.b, t.b.0 + EN);
    if rd!(m.b, t.b.0 + DN) {
        elapse(m, t, now, 1);
    } else if rising {
        wr!(m.b, t.b.0 + DN, true);
        wr!(m.i, t.i.0 + ACC, 0);
        wr!(m.i, t.i.0 + LAST, now as i32);
    }
    if rd!(m.b, t.b.0 + DN) {
        let pre = preset(m, t, sink, pc);
        if rd!(m.i, t.i.0 + ACC) >= pre {
            wr!(m.b, t.b.0 + DN, false);
            wr!(m.i, t.i.0 + ACC, pre);
        }
    }
    if !rd!(m.b, t.b.0 + DN) && !rc {
        wr!(m.i, t.i.0 + ACC, 0);
    }
    wr!(m.b, t.b.0 + TT, rd!(m.b, t.b.0 + DN));
    wr!(m.b, t.b.0 + EN, rc);
}

/// CTU (`up`) / CTD: count on the false→true transition of the rung (CU/CD
/// remember the last rung state); DN = ACC ≥ PRE. Wrapping past the 32-bit
/// range sets OV (up) or UN (down), or clears the opposite flag if set.
#[inline(always)]
pub(super) fn count(m: &mut Mem, c: Ctr, rc: bool, up: bool) {
    let (pre, acc) = (c.i.0, c.i.0 + 1);
    let b = c.b.0;
    let (dn, ov, un) = (b + 2, b + 3, b + 4);
    let edge = if up { b } else { b + 1 };
    if rc && !rd!(m.b, edge) {
        let v = rd!(m.i, acc);
        let (next, wrapped) = if up { v.overflowing_add(1) } else { v.overflowing_sub(1) };
        wr!(m.i, acc, next);
        if wrapped {
            let (set, clear) = if up { (ov, un) } else { (un, ov) };
            if rd!(m.b, clear) {
                wr!(m.b, clear, false);
            } else {
                wr!(m.b, set, true);
            }
        }
    }
    wr!(m.b, edge, rc);
    wr!(m.b, dn, rd!(m.i, acc) >= rd!(m.i, pre));
}

// ---- S7-200 timers and counters (SPEC §4) -----------------------------------
//
// An S7 timer counts in units of its resolution (1, 10 or 100 ms); the
// milliseconds not yet making a unit are kept, so no time is lost between
// scans. Its current value is a 16-bit count: TON and TONR go on counting to
// 32767, TOF stops at PT.

#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum S7Kind {
    Ton,
    Tonr,
    Tof,
}

/// Adds the clock time since the last update to the count, up to `cap`.
#[inline]
fn s7_advance(m: &mut Mem, t: S7Tmr, now: u32, cap: i32) {
    let (cv, rem, last) = (t.i.0, t.i.0 + 2, t.i.0 + 3);
    let dt = now.wrapping_sub(rd!(m.i, last) as u32);
    wr!(m.i, last, now as i32);
    let res = u64::from(t.res.max(1));
    let total = rd!(m.i, rem).max(0) as u64 + u64::from(dt);
    let units = (total / res).min(i32::MAX as u64) as i32;
    wr!(m.i, rem, (total % res) as i32);
    wr!(m.i, cv, rd!(m.i, cv).saturating_add(units).min(cap.max(0)));
}

pub(super) fn s7_timer(m: &mut Mem, t: S7Tmr, enable: bool, now: u32, kind: S7Kind) {
    let (cv, pt, rem, last) = (t.i.0, t.i.0 + 1, t.i.0 + 2, t.i.0 + 3);
    let (bit, en) = (t.b.0, t.b.0 + 1);
    let was = rd!(m.b, en);
    wr!(m.b, en, enable);
    match kind {
        S7Kind::Ton | S7Kind::Tonr => {
            if enable {
                if !was {
                    // The first enabled execution starts timing (TON from 0,
                    // TONR from where it stopped) and counts nothing yet.
                    if kind == S7Kind::Ton {
                        wr!(m.i, cv, 0);
                        wr!(m.i, rem, 0);
                    }
                    wr!(m.i, last, now as i32);
                } else {
                    s7_advance(m, t, now, i16::MAX as i32);
                }
                wr!(m.b, bit, rd!(m.i, cv) >= rd!(m.i, pt));
            } else if kind == S7Kind::Ton {
                wr!(m.i, cv, 0);
                wr!(m.i, rem, 0);
                wr!(m.b, bit, false);
            }
        }
        S7Kind::Tof => {
            if enable {
                wr!(m.b, bit, true);
                wr!(m.i, cv, 0);
                wr!(m.i, rem, 0);
                return;
            }
            if was {
                // The enable has just dropped: timing starts from 0.
                wr!(m.i, cv, 0);
                wr!(m.i, rem, 0);
                wr!(m.i, last, now as i32);
            } else if rd!(m.b, bit) {
                let p = rd!(m.i, pt);
                s7_advance(m, t, now, p);
            }
            if rd!(m.b, bit) && rd!(m.i, cv) >= rd!(m.i, pt) {
                wr!(m.b, bit, false);
            }
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum S7Count {
    Up,
    Down,
    UpDown,
}

/// CTU/CTD/CTUD. `top` is the reset input (CTU, CTUD) or the load input
/// (CTD); the count inputs were copied to `b+3` (up) and `b+4` (down).
pub(super) fn s7_counter(m: &mut Mem, c: S7Ctr, top: bool, kind: S7Count) {
    let (cv, pv) = (c.i.0, c.i.0 + 1);
    let (bit, cu_was, cd_was, cu, cd) = (c.b.0, c.b.0 + 1, c.b.0 + 2, c.b.0 + 3, c.b.0 + 4);
    let up = rd!(m.b, cu) && !rd!(m.b, cu_was);
    let down = rd!(m.b, cd) && !rd!(m.b, cd_was);
    wr!(m.b, cu_was, rd!(m.b, cu));
    wr!(m.b, cd_was, rd!(m.b, cd));
    let v = rd!(m.i, cv);
    match kind {
        S7Count::Up => {
            // Stops at 32767; the reset wins.
            let v = if top {
                0
            } else if up {
                (v + 1).min(i16::MAX as i32)
            } else {
                v
            };
            wr!(m.i, cv, v);
            wr!(m.b, bit, v >= rd!(m.i, pv));
        }
        S7Count::Down => {
            if top {
                // Load: the preset, and the bit off.
                wr!(m.i, cv, rd!(m.i, pv));
                wr!(m.b, bit, false);
            } else {
                let v = if down && v > 0 { v - 1 } else { v };
                wr!(m.i, cv, v);
                wr!(m.b, bit, v == 0);
            }
        }
        S7Count::UpDown => {
            // Wraps at the ends of the 16-bit range; the reset wins.
            let mut v = v;
            if up {
                v = if v >= i16::MAX as i32 { i16::MIN as i32 } else { v + 1 };
            }
            if down {
                v = if v <= i16::MIN as i32 { i16::MAX as i32 } else { v - 1 };
            }
            if top {
                v = 0;
            }
            wr!(m.i, cv, v);
            wr!(m.b, bit, v >= rd!(m.i, pv));
        }
    }
}
