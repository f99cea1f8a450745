//! The PID instruction against hand-computed steps, one feature at a time,
//! in every execution mode (fused, monitored, native code).

use crate::util::{MODES, Mode, compile_text};
use alba_engine::Engine;
use alba_ir::Target;
use alba_model::Value;
use std::sync::Arc;

const LAD: &str = "XIC(Run)PID(Loop,PVin,Out);\n";

/// A loop `Loop` with the given `initial` parameters, PV from `PVin` (REAL)
/// to `Out` (REAL), enabled by `Run` (initially on); one engine per mode.
struct Rig {
    engines: Vec<Engine>,
    t: u64,
}

impl Rig {
    fn new(params: &str) -> Rig {
        let tags = format!("name,type,address,initial\nPVin,REAL,,\nOut,REAL,,\nRun,BOOL,,1\nLoop,PID,,\"{params}\"\n");
        let p = Arc::new(compile_text(&tags, LAD).unwrap_or_else(|e| panic!("{e}")));
        let engines = MODES
            .iter()
            .map(|m| {
                let mut e = Engine::new(p.clone()).expect("verifies");
                match m {
                    Mode::Fused => {}
                    Mode::Monitored => e.set_monitor(true),
                    Mode::Native => {
                        if cfg!(feature = "jit") {
                            e.compile_native().expect("native code");
                        }
                    }
                }
                e
            })
            .collect();
        Rig { engines, t: 0 }
    }

    fn set(&mut self, name: &str, v: Value) {
        for e in &mut self.engines {
            let Ok(Target::Value { place, .. }) = e.program().layout.resolve(name) else {
                panic!("{name}")
            };
            e.write(place, v);
        }
    }

    fn real(&mut self, name: &str, v: f32) {
        self.set(name, Value::Real(v));
    }

    fn bit(&mut self, name: &str, v: bool) {
        self.set(name, Value::Bool(v));
    }

    /// One scan at the current time in every engine, then the clock moves on `dt` ms.
    fn scan(&mut self, dt: u64) {
        for e in &mut self.engines {
            e.scan(self.t).expect("scan");
        }
        self.t += dt;
    }

    /// A value, the same in every mode.
    fn get(&self, name: &str) -> Value {
        let vals: Vec<Value> = self
            .engines
            .iter()
            .map(|e| {
                let Ok(Target::Value { place, .. }) = e.program().layout.resolve(name) else {
                    panic!("{name}")
                };
                e.read(place)
            })
            .collect();
        assert!(
            vals.windows(2).all(|w| w[0] == w[1]),
            "{name} differs between modes: {vals:?}"
        );
        vals[0]
    }

    fn f(&self, name: &str) -> f64 {
        self.get(name).as_f64()
    }

    fn b(&self, name: &str) -> bool {
        self.get(name).as_bool()
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-4 * (1.0 + b.abs())
}

macro_rules! assert_close {
    ($a:expr, $b:expr) => {{
        let (a, b) = ($a, $b);
        assert!(close(a, b), "{} = {a}, expected {b}", stringify!($a));
    }};
}

#[test]
fn p_only_output_is_gain_times_error() {
    let mut r = Rig::new("KP=2;UPD=100");
    r.real("Loop.SP", 10.0);
    r.real("PVin", 4.0);
    r.scan(10);
    assert!(r.b("Loop.EN") && r.b("Loop.DN"));
    assert_close!(r.f("Loop.PV"), 4.0);
    assert_close!(r.f("Loop.ERR"), 6.0);
    assert_close!(r.f("Loop.CV"), 12.0);
    assert_close!(r.f("Out"), 12.0);
    // Output limited to MAXO (100 % by default) with UL set.
    r.real("PVin", -60.0);
    for _ in 0..10 {
        r.scan(10);
    }
    assert_close!(r.f("Loop.CV"), 100.0);
    assert!(r.b("Loop.UL") && !r.b("Loop.LL"));
}

#[test]
fn integral_stops_at_the_limit_and_leaves_it_at_once() {
    // KI = 1/s, T = 0.1 s, e = 10: +1 % per update; MAXO = 5.
    let mut r = Rig::new("KI=1;UPD=100;MAXO=5");
    r.real("Loop.SP", 10.0);
    let mut cv = Vec::new();
    for _ in 0..10 {
        r.scan(100);
        cv.push(r.f("Loop.CV"));
    }
    assert_eq!(cv, [1.0, 2.0, 3.0, 4.0, 5.0, 5.0, 5.0, 5.0, 5.0, 5.0]);
    assert!(r.b("Loop.UL"));
    // The error reverses: the output leaves the limit on the next update
    // (no wound-up integral to unwind).
    r.real("PVin", 20.0);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 4.0);
    assert!(!r.b("Loop.UL"));
}

#[test]
fn derivative_on_pv_ignores_a_setpoint_step() {
    // KD = 1 s, no filter, outputs not limited.
    let mut r = Rig::new("KD=1;DFN=0;UPD=100;OL=0");
    r.scan(100);
    r.real("Loop.SP", 10.0);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 0.0);
    // PV rises by 1 in 0.1 s: D = -KD * dPV/dt = -10.
    r.real("PVin", 1.0);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), -10.0);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 0.0);
}

#[test]
fn derivative_on_error_kicks_on_a_setpoint_step() {
    let mut r = Rig::new("KD=1;DFN=0;UPD=100;OL=0;DOE=1");
    r.scan(100);
    r.real("Loop.SP", 10.0);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 100.0);
}

#[test]
fn derivative_filter_is_first_order_with_td_over_n() {
    // KP = 1, KD = 1: Td = 1 s; N = 10: Tf = 0.1 s; T = 0.1 s.
    // D(k) = (Tf D(k-1) + KD (x(k) - x(k-1))) / (Tf + T), x = -PV.
    let mut r = Rig::new("KP=1;KD=1;DFN=10;UPD=100;OL=0");
    r.scan(100);
    r.real("PVin", 1.0);
    let mut d = Vec::new();
    for _ in 0..3 {
        r.scan(100);
        d.push(r.f("Loop.CV") + 1.0); // minus the P term (-1)
    }
    assert_close!(d[0], -5.0);
    assert_close!(d[1], -2.5);
    assert_close!(d[2], -1.25);
}

#[test]
fn deadband_is_entered_at_a_zero_crossing() {
    let mut r = Rig::new("KP=1;DB=1;MAXS=100;UPD=100;OL=0");
    // With MAXS-MINS = 100 the error is in % of 100 units: numerically equal.
    r.real("Loop.SP", 10.0);
    let mut seen = Vec::new();
    for pv in [12.0, 10.5, 9.5, 9.2, 8.5] {
        r.real("PVin", pv);
        r.scan(100);
        seen.push((r.f("Loop.CV"), r.b("Loop.INDB")));
    }
    let want = [(-2.0, false), (-0.5, false), (0.0, true), (0.0, true), (1.5, false)];
    for (s, w) in seen.iter().zip(want) {
        assert!(close(s.0, w.0) && s.1 == w.1, "{seen:?}");
    }
}

#[test]
fn manual_to_auto_and_back_is_bumpless() {
    let mut r = Rig::new("KP=1;KI=1;UPD=100");
    r.real("Loop.SP", 10.0);
    r.bit("Loop.MAN", true);
    r.real("Loop.CV", 40.0);
    r.scan(100);
    r.scan(100);
    assert_close!(r.f("Out"), 40.0);
    r.bit("Loop.MAN", false);
    r.scan(100);
    // The integral tracked 40 - P (10) = 30: now 30 + KI·T·e = 31, CV = 10 + 31.
    assert_close!(r.f("Loop.CV"), 41.0);
    // To manual: the output stays until the operator writes it.
    r.bit("Loop.MAN", true);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 41.0);
    r.real("Loop.CV", 20.0);
    r.scan(100);
    assert_close!(r.f("Out"), 20.0);
}

#[test]
fn direct_action_takes_pv_minus_sp() {
    let mut r = Rig::new("KP=2;DIRECT=1;UPD=100");
    r.real("Loop.SP", 10.0);
    r.real("PVin", 14.0);
    r.scan(100);
    assert_close!(r.f("Loop.ERR"), 4.0);
    assert_close!(r.f("Loop.CV"), 8.0);
}

#[test]
fn dependent_gains_are_kc_ti_td() {
    // KC = 2, TI = 0.5 s (KI = 4/s), T = 0.1 s, e = 1: CV = 2 + 0.4.
    let mut r = Rig::new("DEP=1;KC=2;TI=0.5;UPD=100");
    r.real("Loop.SP", 1.0);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 2.4);
}

#[test]
fn minutes_make_ti_and_td_the_slcs_units() {
    // MINUTES: TI in minutes per repeat, TD in minutes, as the SLC 500
    // holds them; the loop is the one in seconds. KC = 2, TI = 0.5 s =
    // 0.5/60 min, TD = 0.6 s = 0.01 min, DFN 0, e = 1 then PV moves.
    let seconds = "DEP=1;KC=2;TI=0.5;TD=0.6;DFN=0;UPD=100;OL=0";
    let minutes = "DEP=1;MINUTES=1;KC=2;TI=0.5s;TD=0.01min;DFN=0;UPD=100;OL=0";
    let (mut a, mut b) = (Rig::new(seconds), Rig::new(minutes));
    assert_close!(b.f("Loop.TI"), 0.5 / 60.0);
    assert_close!(b.f("Loop.TD"), 0.01);
    for r in [&mut a, &mut b] {
        r.real("Loop.SP", 1.0);
    }
    for pv in [0.0, 0.2, 0.5, 0.7] {
        for r in [&mut a, &mut b] {
            r.real("PVin", pv);
            r.scan(100);
        }
        assert_close!(b.f("Loop.CV"), a.f("Loop.CV"));
    }
    // By hand, the first update: 2·1 + 2/0.5·1·0.1 = 2.4 (no derivative:
    // PV did not move).
    let mut r = Rig::new("DEP=1;MINUTES=1;KC=2;TI=0.1;UPD=100");
    r.real("Loop.SP", 1.0);
    r.scan(100);
    // TI = 0.1 min = 6 s: 2 + 2/6·0.1 = 2.0333…
    assert_close!(r.f("Loop.CV"), 2.0 + 2.0 / 6.0 * 0.1);
    // Written at run time (the API, a stimulus): the same unit.
    r.real("Loop.TI", 0.05);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 2.0 + 2.0 / 6.0 * 0.1 + 2.0 / 3.0 * 0.1);
}

#[test]
fn bias_is_added() {
    let mut r = Rig::new("KP=1;BIAS=30;UPD=100");
    r.real("Loop.SP", 5.0);
    r.scan(100);
    assert_close!(r.f("Loop.CV"), 35.0);
}

#[test]
fn loop_updates_on_its_own_clock() {
    // UPD = 25 ms with 10 ms scans: updates at 0, 30, 50, 80, 100, …
    // (every due time, on the first scan at or after it).
    let mut r = Rig::new("KP=1;UPD=25");
    let mut done = Vec::new();
    for _ in 0..11 {
        let t = r.t;
        r.scan(10);
        if r.b("Loop.DN") {
            done.push(t);
        }
        assert!(!r.b("Loop.TF"));
    }
    assert_eq!(done, [0, 30, 50, 80, 100]);
    // Scans slower than the loop: an update is missed, TF says so.
    let mut r = Rig::new("KP=1;UPD=15");
    r.scan(40);
    r.scan(40);
    assert!(r.b("Loop.DN") && r.b("Loop.TF"));
}

#[test]
fn sti_mode_updates_at_every_execution_with_dt_upd() {
    // TM false: the SLC's STI mode, the loop in a timed interrupt of period
    // UPD: it updates whenever it executes with its rung true (here every
    // 10 ms scan), never late (TF stays false), and integrates with dt = UPD.
    let mut r = Rig::new("KP=0;KI=2;UPD=100;TM=0;MAXS=0");
    r.real("Loop.SP", 10.0);
    let mut done = 0;
    for _ in 0..5 {
        r.scan(10);
        done += usize::from(r.b("Loop.DN"));
        assert!(!r.b("Loop.TF"));
    }
    assert_eq!(done, 5, "an update at every execution");
    // each update adds Ki·e·dt = 2 · 10 · 0.1 = 2 %
    assert_close!(r.f("Loop.CV"), 10.0);
    // A false rung: no execution, no update.
    r.bit("Run", false);
    r.scan(10);
    assert!(!r.b("Loop.DN"));
    // Timed mode (the default) with the same scans: every 10th scan.
    let mut r = Rig::new("KP=0;KI=2;UPD=100;MAXS=0");
    r.real("Loop.SP", 10.0);
    let mut done = 0;
    for _ in 0..10 {
        r.scan(10);
        done += usize::from(r.b("Loop.DN"));
    }
    assert_eq!(done, 1);
}

#[test]
fn scaling_from_raw_input_to_raw_output() {
    // 0-10000 raw (mV) is 0-10 V; the output 0-100 % is 0-10000 raw.
    let mut r = Rig::new("KP=1;MINI=0;MAXI=10000;MINS=0;MAXS=10;MINCV=0;MAXCV=10000;UPD=100");
    r.real("Loop.SP", 5.0);
    r.real("PVin", 2500.0);
    r.scan(100);
    assert_close!(r.f("Loop.PV"), 2.5);
    assert_close!(r.f("Loop.ERR"), 2.5);
    assert_close!(r.f("Loop.CV"), 25.0);
    assert_close!(r.f("Out"), 2500.0);
    r.real("PVin", 12000.0);
    r.scan(100);
    assert!(r.b("Loop.PVOR"));
    assert_close!(r.f("Loop.PV"), 10.0);
    // A setpoint out of range keeps the last valid one.
    r.real("Loop.SP", 11.0);
    r.real("PVin", 2500.0);
    r.scan(100);
    assert!(r.b("Loop.SPOR"));
    assert_close!(r.f("Loop.ERR"), 2.5);
}

#[test]
fn a_false_rung_holds_the_output() {
    let mut r = Rig::new("KP=1;UPD=100");
    r.real("Loop.SP", 5.0);
    r.scan(100);
    r.bit("Run", false);
    r.real("PVin", 5.0);
    r.scan(100);
    assert!(!r.b("Loop.EN") && !r.b("Loop.DN"));
    assert_close!(r.f("Out"), 5.0);
}

#[test]
fn bad_parameters_at_run_time_are_minor_faults_and_hold_the_output() {
    let mut r = Rig::new("KP=1;UPD=100");
    r.real("Loop.SP", 5.0);
    r.scan(100);
    r.set("Loop.UPD", Value::Dint(0));
    r.real("Loop.SP", 7.0);
    r.scan(100);
    assert_eq!(r.get("Loop.ERRC"), Value::Dint(0x11));
    assert!(r.b("S:MINOR"));
    assert_eq!(r.get("S:FAULTCODE"), Value::Dint(6));
    assert_close!(r.f("Out"), 5.0);
    for (m, v, code) in [
        ("Loop.KP", f32::NAN, 0x70),
        ("Loop.KP", -1.0, 0x12),
        ("Loop.MINS", 5.0, 0x23),
        ("Loop.MAXO", 150.0, 0x51),
        ("Loop.MAXO", -1.0, 0x51),
        ("Loop.MINO", -5.0, 0x52),
        ("Loop.MINO", 101.0, 0x52),
    ] {
        let mut r = Rig::new("KP=1;UPD=100");
        r.real(m, v);
        r.scan(100);
        assert_eq!(r.get("Loop.ERRC"), Value::Dint(code), "{m} = {v}");
    }
    // Fixed, the loop runs again.
    r.set("Loop.UPD", Value::Dint(100));
    r.scan(100);
    assert_eq!(r.get("Loop.ERRC"), Value::Dint(0));
    assert_close!(r.f("Out"), 7.0);
}

#[test]
fn constant_bad_parameters_are_located_errors() {
    for (init, want) in [
        ("UPD=0", "UPD = 0"),
        ("MINS=10;MAXS=5", "MINS = 10 is more than MAXS = 5"),
        ("TI=-1", "TI = -1"),
        (
            "MAXO=200",
            "MAXO = 200: the output's upper limit must be from 0 to 100 % (SLC error 51H)",
        ),
        (
            "MINO=-1",
            "MINO = -1: the output's lower limit must be from 0 to 100 % (SLC error 52H)",
        ),
        ("KP=x", "bad value for KP"),
        ("EN=1", "status"),
        ("ZZ=1", "no member `ZZ`"),
    ] {
        let tags = format!("name,type,address,initial\nPVin,REAL,,\nOut,REAL,,\nRun,BOOL,,1\nLoop,PID,,\"{init}\"\n");
        let err = compile_text(&tags, LAD)
            .err()
            .unwrap_or_else(|| panic!("{init} accepted"));
        assert!(err.contains("E121") && err.contains(want), "{init}: {err}");
        assert!(err.contains("tags.csv:5:"), "{init}: {err}");
    }
}

#[test]
fn velocity_forms_run_the_source_equations_sample_by_sample() {
    use alba_engine::pid::{SLC_PER_PCT, slc_velocity, velocity};
    let pvs = [0.0f32, 1.0, 2.5, 4.0, 4.5, 5.2, 5.1, 5.0];
    for form in 1..=4 {
        let mut r = Rig::new(&format!("KP=5;KI=0.8;KD=0.33;UPD=640;OL=0;FORM={form}"));
        r.real("Loop.SP", 5.0);
        let (mut e1, mut e2, mut u) = (0.0f64, 0.0f64, 0.0f64);
        let (mut i1, mut i2, mut iu) = (0i16, 0i16, 0i16);
        for pv in pvs {
            r.real("PVin", pv);
            r.scan(640);
            let e = 5.0 - f64::from(pv);
            let want = match form {
                1 | 2 => {
                    let ef = f64::from(e as f32);
                    u = velocity(form == 1, 5.0, 0.8, f64::from(0.33f32), 0.64, ef, e1, e2, u);
                    (e2, e1) = (e1, ef);
                    u
                }
                _ => {
                    let ec = (e * SLC_PER_PCT).round() as i16;
                    iu = slc_velocity(form == 3, 500, 80, 33, 64, ec, i1, i2, iu);
                    (i2, i1) = (i1, ec);
                    f64::from(iu) / SLC_PER_PCT
                }
            };
            let cv = r.f("Loop.CV");
            assert!(
                (cv - want).abs() < 1e-3 * (1.0 + want.abs()),
                "FORM {form}, PV {pv}: {cv} vs {want}"
            );
        }
    }
}

/// FORM 11 and 12: the source programs' own handling (`004_…` §3.3.1.1,
/// Annex F): errors and u on the module's 0-32767 scale, a negative u(k)
/// set to 0 (with or without OL), and u(k−1) the u(k) computed, not the
/// output limited to MAXO. FORM 4 on the same samples keeps the limited
/// output, so the two part at the first sample after the limit.
#[test]
fn listing_forms_keep_u_beyond_the_output_limit_and_reject_negatives() {
    use alba_engine::pid::{LISTING_PER_PCT, SLC_PER_PCT, slc_velocity};
    // e = 5, 5, 5, -1, 0, 0, -9: u climbs past MAXO = 30, falls, and goes negative.
    let pvs = [0.0f32, 0.0, 0.0, 6.0, 5.0, 5.0, 14.0];
    for (form, ol) in [(11, true), (12, true), (12, false), (4, true)] {
        let mut r = Rig::new(&format!("KP=5;KI=0.8;UPD=640;MAXO=30;OL={};FORM={form}", u8::from(ol)));
        r.real("Loop.SP", 5.0);
        let listing = form > 8;
        let per = if listing { LISTING_PER_PCT } else { SLC_PER_PCT };
        let hi = (30.0 * per).round() as i16;
        let (mut i1, mut i2, mut u1) = (0i16, 0i16, 0i16);
        let mut parted = false;
        for pv in pvs {
            r.real("PVin", pv);
            r.scan(640);
            let ec = ((5.0 - f64::from(pv)) * per).round() as i16;
            let u = slc_velocity(form == 11, 500, 80, 0, 64, ec, i1, i2, u1);
            let kept = if listing { u.max(0) } else { u };
            let out = if ol { kept.clamp(0, hi) } else { kept };
            u1 = if listing { kept } else { out };
            (i2, i1) = (i1, ec);
            parted |= u1 != out;
            let cv = r.f("Loop.CV");
            let want = f64::from(out) / per;
            assert!(
                (cv - want).abs() < 1e-3,
                "FORM {form} OL {ol}, PV {pv}: CV {cv} vs {want}"
            );
            assert!(cv >= 0.0 || !listing, "FORM {form}: CV {cv} negative");
        }
        // The case exercises what it is about: u(k−1) above the limit
        // (listing with OL), or a negative u(k) set to 0 (listing without OL).
        assert_eq!(parted, listing && ol, "FORM {form} OL {ol}");
    }
    // By hand, FORM 12 with OL (counts of 327.67 per %): k0 29 % (9502),
    // k1 33 %, k2 37 % (12124, CV 30 %), k3 37 − 30 − 0.8 = 6.2 % (6.19 in counts), where
    // FORM 4 has gone from its limit 30 % to 30 − 30.8 < 0, so 0.
    let mut a = Rig::new("KP=5;KI=0.8;UPD=640;MAXO=30;FORM=12");
    let mut b = Rig::new("KP=5;KI=0.8;UPD=640;MAXO=30;FORM=4");
    for r in [&mut a, &mut b] {
        r.real("Loop.SP", 5.0);
        for pv in &pvs[..4] {
            r.real("PVin", *pv);
            r.scan(640);
        }
    }
    assert!((a.f("Loop.CV") - 6.2).abs() < 0.02, "FORM 12: {}", a.f("Loop.CV"));
    assert!(b.f("Loop.CV").abs() < 0.01, "FORM 4: {}", b.f("Loop.CV"));
}

#[test]
fn listing_bit_is_only_for_the_16_bit_forms() {
    for (init, want) in [
        ("FORM=9", "FORM = 9"),
        ("FORM=13", "FORM = 13"),
        ("FORM=11;UPD=5", "UPD = 5"),
    ] {
        let tags = format!("name,type,address,initial\nPVin,REAL,,\nOut,REAL,,\nRun,BOOL,,1\nLoop,PID,,\"{init}\"\n");
        let err = compile_text(&tags, LAD)
            .err()
            .unwrap_or_else(|| panic!("{init} accepted"));
        assert!(err.contains("E121") && err.contains(want), "{init}: {err}");
    }
    assert!(
        compile_text(
            "name,type,address,initial\nPVin,REAL,,\nOut,REAL,,\nRun,BOOL,,1\nLoop,PID,,\"FORM=12\"\n",
            LAD
        )
        .is_ok()
    );
}
