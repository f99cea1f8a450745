//! The PID instruction (SPEC §6): the semantics of `Op::Pid`.
//!
//! One execution of the instruction:
//!
//! 1. `EN` follows the rung. While the rung is false nothing else happens:
//!    the output holds its last value and the loop restarts cold (integral
//!    cleared, as on the SLC 500) when the rung is true again.
//! 2. The parameters are checked (`PidParams::check`); a bad one sets
//!    `ERRC` (the SLC's code), records a minor fault when the code changes,
//!    and holds the output.
//! 3. In timed mode (`TM`, the default) the loop updates every `UPD` ms of
//!    engine clock, on a drift-free schedule independent of the scan; `DN`
//!    is true in the scans that updated. In STI mode (`TM` false) it updates
//!    at every execution with its rung true, as the SLC's does inside its
//!    selectable timed interrupt. When a whole update period is missed (scans slower than the
//!    loop), `TF` is set and the schedule restarts from now. The update
//!    always uses `dt = UPD` (as the SLC does, which is why TF warns that
//!    the integral and derivative are then wrong).
//! 4. PV = the raw input scaled from `MINI..MAXI` to `MINS..MAXS` (when
//!    both ranges are set; `PVOR` when the raw value is outside and it is
//!    clamped). SP outside `MINS..MAXS` sets `SPOR` and the last valid SP
//!    is used. The error `ERR = SP − PV` (reverse acting) or `PV − SP`
//!    (`DIRECT`), and with scaling it is taken in % of `MAXS − MINS`, so
//!    gains are %CV per %PV.
//! 5. The deadband `DB` (engineering units) is entered when the error is
//!    within ±DB and crosses zero, and left when it leaves ±DB (`INDB`);
//!    inside, the error is 0.
//! 6. The algorithm `FORM`: 0 positional (ISA with `DEP`: KC, TI s, TD s,
//!    or with `MINUTES` TI in minutes per repeat and TD in minutes, the SLC's;
//!    else KP, KI /s, KD s) with derivative on PV (default) or on the error
//!    (`DOE`), low-pass filtered with time constant Td/DFN; 1 and 2 the
//!    velocity forms of the source's eq. 3-30 (s-plane) and 3-31 (z-plane)
//!    in REAL arithmetic; 3 and 4 the same (eq. 3-32, 3-33) in the SLC's
//!    16-bit integer arithmetic, on the SLC's 0-16383 scale of 0-100 %.
//!    FORM 11 and 12 (3 and 4 plus the listing bit 8) are the source
//!    programs PID_CONT and PID_DISC as they are described (`004_…`
//!    §3.3.1.1 and Annex F; the ladder of Annex E is not legible): the
//!    module's 0-32767 scale of 0-10 V instead of 0-16383, a negative u(k)
//!    set to 0 ("se verifica que el valor de u(k) no sea negativo"), and
//!    u(k−1) that u(k), not the output limited to MINO..MAXO.
//! 7. `BIAS` is added (positional form). With `OL` the output is clamped to
//!    `MINO..MAXO` % and the integral does not move further into a limit
//!    (conditional integration: anti-windup); `UL`/`LL` flag the unclamped
//!    output beyond the limits (alarms only without `OL`).
//! 8. In manual (`MAN`) the operator's `CV` is the output (clamped with
//!    `OL`) and the integral (velocity forms: u(k−1) and the errors) track
//!    it, so the return to auto is bumpless; the switch to manual is too,
//!    as CV keeps its last value until the operator writes it.
//! 9. The raw output is `CV` scaled from 0..100 % to `MINCV..MAXCV` (when
//!    set), left in the hidden output slot for the front end to move to
//!    the CV operand.

use crate::fault::FaultCode;
use crate::mem::{Mem, Sink};
use alba_ir::Pidt;
use alba_ir::op::*;
use alba_model::types::PidParams;

// REAL members.
const SP: usize = 0;
const PV: usize = 1;
const ERR: usize = 2;
const CV: usize = 3;
const KP: usize = 4;
const KI: usize = 5;
const KD: usize = 6;
const KC: usize = 7;
const TI: usize = 8;
const TD: usize = 9;
const BIAS: usize = 10;
const MAXO: usize = 11;
const MINO: usize = 12;
const MAXS: usize = 13;
const MINS: usize = 14;
const MAXI: usize = 15;
const MINI: usize = 16;
const MAXCV: usize = 17;
const MINCV: usize = 18;
const DBAND: usize = 19;
const DFN: usize = 20;
// DINT members.
const UPD: usize = 0;
const ERRC: usize = 1;
const FORM: usize = 2;
// BOOL members.
const EN: usize = 0;
const DN: usize = 1;
const UL: usize = 2;
const LL: usize = 3;
const SPOR: usize = 4;
const PVOR: usize = 5;
const INDB: usize = 6;
const TF: usize = 7;
const MAN: usize = 8;
const DIRECT: usize = 9;
const DOE: usize = 10;
const DEP: usize = 11;
const OL: usize = 12;
const TM: usize = 13;
const MINUTES: usize = 14;

/// Counts of the SLC's 0-16383 scale per percent.
pub const SLC_PER_PCT: f64 = 16383.0 / 100.0;

/// Counts per percent of the scale the `004_…` listings work on (FORM 11
/// and 12): the analog module's 0-10 V as 0-32767 (Annex F).
pub const LISTING_PER_PCT: f64 = 32767.0 / 100.0;

/// Runs one execution of the instruction.
pub(crate) fn pid(m: &mut Mem, p: Pidt, rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    let (f0, i0, b0) = (p.f.0 as usize, p.i.0 as usize, p.b.0 as usize);
    let (Some(f), Some(iv), Some(b)) = (
        m.f.get_mut(f0..f0 + PID_F_SLOTS as usize),
        m.i.get_mut(i0..i0 + PID_I_SLOTS as usize),
        m.b.get_mut(b0..b0 + PID_B_SLOTS as usize),
    ) else {
        return;
    };
    pid_on(f, iv, b, rc, now, sink, pc);
}

/// [`pid`] on the op's REAL, DINT and BOOL slot ranges.
pub(crate) fn pid_on(f: &mut [f32], iv: &mut [i32], b: &mut [bool], rc: bool, now: u32, sink: &mut Sink, pc: usize) {
    b[EN] = rc;
    b[DN] = false;
    if !rc {
        b[PID_B_RUN as usize] = false;
        return;
    }
    let params = PidParams {
        kp: f[KP].into(),
        ki: f[KI].into(),
        kd: f[KD].into(),
        kc: f[KC].into(),
        ti: f[TI].into(),
        td: f[TD].into(),
        maxs: f[MAXS].into(),
        mins: f[MINS].into(),
        db: f[DBAND].into(),
        maxo: f[MAXO].into(),
        mino: f[MINO].into(),
        dfn: f[DFN].into(),
        maxi: f[MAXI].into(),
        mini: f[MINI].into(),
        maxcv: f[MAXCV].into(),
        mincv: f[MINCV].into(),
        bias: f[BIAS].into(),
        upd: iv[UPD].into(),
        form: iv[FORM].into(),
    };
    if let Some((code, _, _)) = params.check() {
        if iv[ERRC] != code {
            iv[ERRC] = code;
            sink.fault(FaultCode::PidParameter, pc);
        }
        return;
    }
    iv[ERRC] = 0;
    let upd = iv[UPD];
    let running = b[PID_B_RUN as usize];
    let due = iv[PID_I_DUE as usize] as u32;
    if !b[TM] {
        // STI mode: the SLC runs the loop in a selectable timed interrupt of
        // period UPD and the instruction updates at every execution; here the
        // program decides when it executes (every scan with scan_ms = UPD, or
        // under a timer's DN), and dt is UPD as on the SLC.
        b[TF] = false;
    } else if running {
        let lag = now.wrapping_sub(due) as i32;
        if lag < 0 {
            return;
        }
        b[TF] = lag >= upd;
        let next = if b[TF] { now } else { due };
        iv[PID_I_DUE as usize] = next.wrapping_add(upd as u32) as i32;
    } else {
        b[TF] = false;
        iv[PID_I_DUE as usize] = now.wrapping_add(upd as u32) as i32;
    }
    b[DN] = true;
    update(f, iv, b, &params, running);
}

fn update(f: &mut [f32], iv: &mut [i32], b: &mut [bool], p: &PidParams, running: bool) {
    let dt = p.upd / 1000.0;
    // Process variable.
    let span = p.maxs - p.mins;
    let scaled = p.maxi != p.mini && span != 0.0;
    let mut raw = f64::from(f[PID_F_IN as usize]);
    if !raw.is_finite() {
        b[PVOR] = true;
        b[DN] = false;
        return;
    }
    b[PVOR] = false;
    let pv = if scaled {
        let (lo, hi) = (p.mini.min(p.maxi), p.mini.max(p.maxi));
        if raw < lo || raw > hi {
            b[PVOR] = true;
            raw = raw.clamp(lo, hi);
        }
        p.mins + (raw - p.mini) * span / (p.maxi - p.mini)
    } else {
        raw
    };
    f[PV] = pv as f32;
    // Setpoint.
    let mut sp = f64::from(f[SP]);
    b[SPOR] = !sp.is_finite() || (span > 0.0 && (sp < p.mins || sp > p.maxs));
    if b[SPOR] {
        sp = f[PID_F_SPLAST as usize].into();
    } else {
        f[PID_F_SPLAST as usize] = sp as f32;
    }
    // Error, in engineering units and in % of the span.
    let sign = if b[DIRECT] { -1.0 } else { 1.0 };
    let e = sign * (sp - pv);
    f[ERR] = e as f32;
    let pct = if span > 0.0 { 100.0 / span } else { 1.0 };
    // Zero-crossing deadband.
    let eprev = f64::from(f[PID_F_EPREV as usize]);
    if p.db > 0.0 && running {
        if b[INDB] {
            b[INDB] = e.abs() <= p.db;
        } else {
            b[INDB] = e.abs() <= p.db && (e == 0.0 || (e > 0.0) != (eprev > 0.0));
        }
    } else {
        b[INDB] = false;
    }
    f[PID_F_EPREV as usize] = e as f32;
    let e_pct = if b[INDB] { 0.0 } else { e * pct };
    // Gains; TI and TD in seconds (the members hold minutes with MINUTES).
    let per = if b[MINUTES] { 60.0 } else { 1.0 };
    let (ti, td) = (p.ti * per, p.td * per);
    let (kp, ki, kd) = if b[DEP] {
        (p.kc, if ti > 0.0 { p.kc / ti } else { 0.0 }, p.kc * td)
    } else {
        (p.kp, p.ki, p.kd)
    };
    let (lo, hi) = (p.mino, p.maxo);
    let man = b[MAN];
    b[PID_B_WASMAN as usize] = man;
    let cv_in = f64::from(f[CV]);
    let form = p.base_form() as i32;
    let listing = p.listing();
    let (cv, unclamped) = match form {
        0 => {
            // Derivative on PV (of the error's sign) or on the error.
            let x = if b[DOE] { e_pct } else { -sign * pv * pct };
            let td = if b[DEP] {
                td
            } else if kp > 0.0 {
                kd / kp
            } else {
                0.0
            };
            let tf = if p.dfn > 0.0 { td / p.dfn } else { 0.0 };
            let mut dterm = f64::from(f[PID_F_DTERM as usize]);
            let mut integ = f64::from(f[PID_F_INT as usize]);
            if !running {
                f[PID_F_DPREV as usize] = x as f32;
                dterm = 0.0;
                integ = 0.0;
            }
            let dprev = f64::from(f[PID_F_DPREV as usize]);
            dterm = (tf * dterm + kd * (x - dprev)) / (tf + dt);
            f[PID_F_DPREV as usize] = x as f32;
            f[PID_F_DTERM as usize] = dterm as f32;
            let pterm = kp * e_pct;
            let out = if man {
                let cv = if b[OL] { cv_in.clamp(lo, hi) } else { cv_in };
                integ = cv - pterm - dterm - p.bias;
                (cv, cv_in)
            } else {
                // The output the controller asks for (UL/LL compare it
                // with the limits); the integral does not move further
                // into a limit.
                let mut next = integ + ki * dt * e_pct;
                let wanted = pterm + next + dterm + p.bias;
                let step = ki * e_pct;
                if b[OL] && ((wanted > hi && step > 0.0) || (wanted < lo && step < 0.0)) {
                    next = integ;
                }
                integ = next;
                let u = pterm + integ + dterm + p.bias;
                (if b[OL] { u.clamp(lo, hi) } else { u }, wanted)
            };
            f[PID_F_INT as usize] = integ as f32;
            out
        }
        1 | 2 => {
            let (mut u1, mut e1, mut e2) = (
                f64::from(f[PID_F_INT as usize]),
                f64::from(f[PID_F_E1 as usize]),
                f64::from(f[PID_F_E2 as usize]),
            );
            if !running {
                (u1, e1, e2) = (cv_in, 0.0, 0.0);
            }
            let out = if man {
                let cv = if b[OL] { cv_in.clamp(lo, hi) } else { cv_in };
                (u1, e1, e2) = (cv, e_pct, e_pct);
                (cv, cv_in)
            } else {
                let u = velocity(form == 1, kp, ki, kd, dt, e_pct, e1, e2, u1);
                let cv = if b[OL] { u.clamp(lo, hi) } else { u };
                (u1, e2, e1) = (cv, e1, e_pct);
                (cv, u)
            };
            f[PID_F_INT as usize] = u1 as f32;
            f[PID_F_E1 as usize] = e1 as f32;
            f[PID_F_E2 as usize] = e2 as f32;
            out
        }
        _ => {
            // The listing's scale is the analog module's: 0-10 V is 0-32767
            // (Annex F: "En PID discretizado, la referencia tiene un rango de
            // [0,32767]"; the control signal N9:1 is shown as u/32767·10 V).
            let per_pct = if listing { LISTING_PER_PCT } else { SLC_PER_PCT };
            let counts = |x: f64| sat16((x * per_pct).round());
            let e = counts(e_pct);
            let (mut u1, mut e1, mut e2) = (
                iv[PID_I_U1 as usize] as i16,
                iv[PID_I_E1 as usize] as i16,
                iv[PID_I_E2 as usize] as i16,
            );
            if !running {
                (u1, e1, e2) = (counts(cv_in), 0, 0);
            }
            let (lo_c, hi_c) = (counts(lo), counts(hi));
            let out = if man {
                let cv = if b[OL] { cv_in.clamp(lo, hi) } else { cv_in };
                (u1, e1, e2) = (counts(cv), e, e);
                (cv, cv_in)
            } else {
                let k = |g: f64| sat16((g * 100.0).round());
                let t_cs = sat16((p.upd / 10.0).round());
                let u = slc_velocity(form == 3, k(kp), k(ki), k(kd), t_cs, e, e1, e2, u1);
                // The listing (FORM 11, 12; §3.3.1.1): "se verifica que el
                // valor de u(k) no sea negativo" — a negative u(k) becomes 0 —
                // and the "actualización … de la señal actuante" stores that
                // u(k) as u(k−1): bounded above only by the ADD's saturation
                // at 32767, which on this scale is 100 %. MINO/MAXO limit
                // the output written, not u(k−1).
                let kept = if listing { u.max(0) } else { u };
                let uc = if b[OL] { kept.clamp(lo_c, hi_c) } else { kept };
                (u1, e2, e1) = (if listing { kept } else { uc }, e1, e);
                (f64::from(uc) / per_pct, f64::from(u) / per_pct)
            };
            iv[PID_I_U1 as usize] = u1.into();
            iv[PID_I_E1 as usize] = e1.into();
            iv[PID_I_E2 as usize] = e2.into();
            out
        }
    };
    b[UL] = unclamped > hi;
    b[LL] = unclamped < lo;
    b[PID_B_RUN as usize] = true;
    f[CV] = cv as f32;
    let out = if p.maxcv != p.mincv {
        p.mincv + cv * (p.maxcv - p.mincv) / 100.0
    } else {
        cv
    };
    f[PID_F_OUT as usize] = out as f32;
}

/// The velocity forms in real arithmetic: eq. 3-30 (s-plane design,
/// `splane`) and eq. 3-31 (z-plane design):
///
/// s: u = u1 + Kp(e−e1) + Ki·T/2·(e+e1) + Kd/T·(e−e1) + Kd/T·(e2−e1)
/// z: u = u1 + Kp(e−e1) + Ki·e + Kd·(e−e1) + Kd·(e2−e1)
#[allow(clippy::too_many_arguments)]
pub fn velocity(splane: bool, kp: f64, ki: f64, kd: f64, t: f64, e: f64, e1: f64, e2: f64, u1: f64) -> f64 {
    if splane {
        u1 + kp * (e - e1) + ki * t / 2.0 * (e + e1) + kd / t * (e - e1) + kd / t * (e2 - e1)
    } else {
        u1 + kp * (e - e1) + ki * e + kd * (e - e1) + kd * (e2 - e1)
    }
}

/// Saturates to 16 bits, as SLC math does on overflow.
pub fn sat16(v: f64) -> i16 {
    v.clamp(i16::MIN.into(), i16::MAX.into()) as i16
}

/// SLC ADD/SUB: 16-bit result, saturated on overflow.
pub fn slc_add(a: i16, b: i16) -> i16 {
    a.saturating_add(b)
}

pub fn slc_sub(a: i16, b: i16) -> i16 {
    a.saturating_sub(b)
}

/// SLC MUL: the 32-bit product in the math register (what DDV divides),
/// and the 16-bit result saturated.
pub fn slc_mul(a: i16, b: i16) -> (i32, i16) {
    let p = i32::from(a) * i32::from(b);
    (p, sat16(p.into()))
}

/// SLC DDV: the 32-bit math register divided by a 16-bit value, rounded
/// (a remainder of half the divisor or more rounds the quotient away from
/// zero). Division by zero or a quotient beyond 16 bits gives 32767 (and
/// the overflow bit, which the source's program clears).
pub fn slc_ddv(reg: i32, d: i16) -> i16 {
    if d == 0 {
        return i16::MAX;
    }
    let (n, d) = (i64::from(reg), i64::from(d));
    let mut q = n / d;
    let r = n % d;
    if 2 * r.abs() >= d.abs() {
        q += if (n < 0) == (d < 0) { 1 } else { -1 };
    }
    i16::try_from(q).unwrap_or(i16::MAX)
}

/// The velocity forms in SLC 16-bit arithmetic: eq. 3-32 (`splane`) and
/// 3-33, with the gains as integers ×100 (N7:3..5 of the source's
/// program) and T in hundredths of a second:
///
/// s: u = Kp/100·(e−e1) + Ki·T/20000·(e+e1) + Kd/T·(e−e1) + Kd/T·(e2−e1) + u1
/// z: u = Kp/100·(e−e1) + Ki/100·e + Kd/100·(e−e1) + Kd/100·(e2−e1) + u1
///
/// Each term is a SUB/ADD (saturating), a MUL into the math register and a
/// DDV (rounding); the terms are summed left to right with ADD.
#[allow(clippy::too_many_arguments)]
pub fn slc_velocity(splane: bool, kp: i16, ki: i16, kd: i16, t: i16, e: i16, e1: i16, e2: i16, u1: i16) -> i16 {
    let de = slc_sub(e, e1);
    let d2 = slc_sub(e2, e1);
    let t1 = slc_ddv(slc_mul(kp, de).0, 100);
    let (t2, t3, t4) = if splane {
        let (_, kit) = slc_mul(ki, t);
        (
            slc_ddv(slc_mul(kit, slc_add(e, e1)).0, 20000),
            slc_ddv(slc_mul(kd, de).0, t),
            slc_ddv(slc_mul(kd, d2).0, t),
        )
    } else {
        (
            slc_ddv(slc_mul(ki, e).0, 100),
            slc_ddv(slc_mul(kd, de).0, 100),
            slc_ddv(slc_mul(kd, d2).0, 100),
        )
    };
    slc_add(slc_add(slc_add(slc_add(t1, t2), t3), t4), u1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ddv_rounds_half_away_from_zero_and_overflows_to_32767() {
        assert_eq!(slc_ddv(7, 2), 4);
        assert_eq!(slc_ddv(-7, 2), -4);
        assert_eq!(slc_ddv(5, 3), 2);
        assert_eq!(slc_ddv(4, 3), 1);
        assert_eq!(slc_ddv(-350, 100), -4);
        assert_eq!(slc_ddv(105, 100), 1);
        assert_eq!(slc_ddv(100_000, 2), 32767);
        assert_eq!(slc_ddv(-100_000, 2), 32767);
        assert_eq!(slc_ddv(5, 0), 32767);
        assert_eq!(slc_add(32000, 5000), 32767);
        assert_eq!(slc_sub(-32000, 5000), -32768);
        assert_eq!(slc_mul(300, 300), (90_000, 32767));
    }

    /// Eq. 3-33 (z-plane, integer) by hand: Kp = 5.00, Ki = 0.80, Kd = 0.33.
    #[test]
    fn z_plane_integer_form_matches_eq_3_33_by_hand() {
        let (kp, ki, kd) = (500, 80, 33);
        let es = [1000i16, 800, 500, 15, -50];
        // k=0: 500·1000/100 + 80·1000/100 + 33·1000/100 + 33·0/100 = 5000+800+330+0
        // k=1: 500·(-200)/100 + 80·800/100 + 33·(-200)/100 + 33·(0-1000)/100
        //      = -1000 + 640 - 66 - 330 = -756 → 6130 - 756 = 5374
        // k=2: -1500 + 400 + 33·(-300)/100 (-99) + 33·(1000-800)/100 (66) = -1133 → 4241
        // k=3: 500·(-485)/100 = -2425; 80·15/100 = 12 (1.2); 33·(-485)/100 = -160.05 → -160;
        //      33·(800-500)/100 = 99 → -2474 → 1767
        // k=4: 500·(-65)/100 = -325; 80·(-50)/100 = -40; 33·(-65)/100 = -21.45 → -21;
        //      33·(500-15)/100 = 160.05 → 160 → -226 → 1541
        let want = [6130i16, 5374, 4241, 1767, 1541];
        let (mut e1, mut e2, mut u) = (0i16, 0i16, 0i16);
        for (k, &e) in es.iter().enumerate() {
            u = slc_velocity(false, kp, ki, kd, 64, e, e1, e2, u);
            assert_eq!(u, want[k], "sample {k}");
            (e2, e1) = (e1, e);
        }
    }

    /// Eq. 3-32 (s-plane, integer) by hand: Kp = 5.00, Ki = 0.50, Kd = 0.10, T = 640 ms.
    #[test]
    fn s_plane_integer_form_matches_eq_3_32_by_hand() {
        // k=0: 5000 + 3200·1000/20000 (160) + 10·1000/64 (156.25 → 156) + 0 = 5316
        // k=1: -500 + 3200·1900/20000 (304) + 10·(-100)/64 (-15.6 → -16)
        //      + 10·(0-1000)/64 (-156.25 → -156) = -368 → 4948
        let (e1, e2) = (0, 0);
        let u = slc_velocity(true, 500, 50, 10, 64, 1000, e1, e2, 0);
        assert_eq!(u, 5316);
        let u = slc_velocity(true, 500, 50, 10, 64, 900, 1000, 0, u);
        assert_eq!(u, 4948);
    }

    /// The real velocity forms agree with the source's coefficient forms,
    /// eq. 3-16 (s-plane: b0 b1 b2) and eq. 3-29 (z-plane), sample by sample.
    #[test]
    fn real_velocity_forms_match_eq_3_16_and_3_29() {
        let (kp, ki, kd, t) = (4.84, 0.31, 0.7, 0.64);
        let es = [5.0, 4.2, 3.1, 2.0, 1.1, 0.4, -0.2, -0.3, -0.1, 0.0];
        let b0 = kp + kd / t + ki * t / 2.0;
        let b1 = -kp - 2.0 * kd / t + ki * t / 2.0;
        let b2 = kd / t;
        let (z0, z1, z2) = (kp + ki + kd, -kp - 2.0 * kd, kd);
        let (mut e1, mut e2, mut us, mut uz) = (0.0, 0.0, 0.0, 0.0);
        for &e in &es {
            let s_ref = b0 * e + b1 * e1 + b2 * e2 + us;
            let z_ref = z0 * e + z1 * e1 + z2 * e2 + uz;
            us = velocity(true, kp, ki, kd, t, e, e1, e2, us);
            uz = velocity(false, kp, ki, kd, t, e, e1, e2, uz);
            assert!((us - s_ref).abs() < 1e-9, "{us} {s_ref}");
            assert!((uz - z_ref).abs() < 1e-9, "{uz} {z_ref}");
            (e2, e1) = (e1, e);
        }
    }
}
