//! The PID runs of `004_…` Chapter 5 against the thesis's measured table
//! (docs/pid.md §5), in the engine: each run is simulated from its example
//! (`examples/pid-*`: the plant model, the loop, the case's stimulus), and
//! the overshoot and 98 % settling time of Loop.PV are taken from the trace
//! (20 ms samples) with `analysis::step_info`, as `alba sim --summary` does.
//!
//! Two tolerances per run:
//!
//! * the *band* of the simulated/measured settling-time ratio: ±20 % where
//!   the nominal model lands there, and for the others a band around where
//!   it lands now with a reason tested below; a run that drifts out of its
//!   band, either way, fails, so the table and its reasons stay true;
//! * the *reach* of the components: the RC circuits' electrolytic
//!   capacitors are ±20 % (each of C1 and C2 of the second-order circuit)
//!   and the loop's gain ±10 % (the current-to-voltage converter of Fig. 5-1
//!   is trimmed by hand, "ganancia negativa variable", with 5 % resistors);
//!   the figures were read from data polled over DH-485, good to about one
//!   loop update T. The test states, per run, whether the measured settling
//!   time lies inside [fastest − T, slowest + T] over that box, and fails
//!   when that changes.

use crate::util::compile;
use alba_engine::Engine;
use alba_engine::analysis::step_info;
use alba_engine::sim::{self, SimOptions, Stimulus};
use alba_model::plant::{Dynamics, PlantModel};
use std::path::PathBuf;
use std::sync::Arc;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

/// Simulates one case of an example (its stimulus, then `extra` rows at
/// t = 0 that override it) with the plant edited by `plant`; returns
/// (overshoot %, 98 % settling time s, infinite if never) of Loop.PV
/// against Loop.SP.
fn run(ex: &str, case: &str, extra: &[(&str, f64)], until_ms: u64, plant: &dyn Fn(&mut PlantModel)) -> (f64, f64) {
    let dir = example(ex);
    let mut program = compile(&dir);
    for p in &mut program.plants {
        plant(&mut p.model);
    }
    let mut text = std::fs::read_to_string(dir.join(format!("stimulus-{case}.csv"))).expect("stimulus");
    for (tag, v) in extra {
        text.push_str(&format!("\n0,{tag},{v}"));
    }
    text.push('\n');
    let mut files = alba_diag::Files::new();
    let f = files.add("stimulus.csv", &text);
    let stim = Stimulus::parse(files.text(f), f, &program.layout)
        .unwrap_or_else(|d| panic!("{}", alba_diag::render_all(&d, &files)));
    let cols = sim::columns("Loop.PV,Loop.SP", &program.layout).expect("columns");
    let mut engine = Engine::new(Arc::new(program)).expect("program");
    let mut out = Vec::new();
    let opt = SimOptions {
        scan_ms: 10,
        until_ms,
        every_ms: 20,
    };
    sim::run(&mut engine, &stim, &cols, opt, &mut out).expect("runs");
    let (mut t, mut y, mut r) = (Vec::new(), Vec::new(), Vec::new());
    for line in String::from_utf8(out).expect("utf8").lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().expect("number")).collect();
        t.push(v[0] as u64);
        y.push(v[1]);
        r.push(v[2]);
    }
    let s = step_info(&t, &y, Some(&r)).expect("a step");
    (
        s.overshoot_pct,
        s.settling_ms.map_or(f64::INFINITY, |ms| ms as f64 / 1000.0),
    )
}

fn nominal(_: &mut PlantModel) {}

/// The plant with its capacitors (time constants) scaled by `c1`, `c2` and
/// its gain by `g`: τ of a first-order model, C1 and C2 of the
/// second-order circuit (47 s² + 19.4 s + 1 = R²C1C2 s² + (RC1 + 2RC2) s + 1
/// with RC1 = 10 s, RC2 = 4.7 s), the area and pump of the tank.
fn toleranced(c1: f64, c2: f64, g: f64) -> impl Fn(&mut PlantModel) {
    move |m: &mut PlantModel| match &mut m.dynamics {
        Dynamics::FirstOrder { gain, tau } => {
            *tau *= c1;
            *gain *= g;
        }
        Dynamics::SecondOrder { gain, a2, a1, .. } => {
            *a2 *= c1 * c2;
            *a1 = 10.0 * c1 + 2.0 * 4.7 * c2;
            *gain *= g;
        }
        Dynamics::Tank { area, inflow, .. } => {
            *area *= c1;
            *inflow *= g;
        }
        Dynamics::Motor { .. } => {}
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Reach {
    /// The measured settling time is inside what the component tolerances reach.
    Inside,
    /// It is not: the components do not explain the difference.
    Outside,
}

struct Case {
    example: &'static str,
    case: &'static str,
    /// Simulated time, ms.
    until: u64,
    /// Loop update T, s (the reading tolerance of the figures).
    t: f64,
    /// The source's measured overshoot (%) and 98 % settling time (s).
    mp: f64,
    ts: f64,
    /// Allowed simulated/measured settling-time ratio.
    band: (f64, f64),
    /// Allowed |simulated − measured| overshoot, percentage points.
    mp_points: f64,
    reach: Reach,
    /// Why the band is wider than ±20 % (empty when it is not).
    why: &'static str,
}

const WITHIN: (f64, f64) = (0.8, 1.2);

#[rustfmt::skip]
const CASES: &[Case] = &[
    // Prueba 1, Fig. 5-8 to 5-11: Gp1 = 1/(10s+1), T = 640 ms, 5 V step.
    Case { example: "pid-gp1", case: "z-theory", until: 80000, t: 0.64, mp: 0.0, ts: 30.4, band: (1.2, 1.3), mp_points: 2.0, reach: Reach::Outside,
        why: "not the components (the sweep) nor the listing's u(k) handling (FORM 12 = FORM 4 here); Annex E's ladder is illegible" },
    Case { example: "pid-gp1", case: "z-tuned", until: 60000, t: 0.64, mp: 2.0, ts: 10.6, band: WITHIN, mp_points: 2.0, reach: Reach::Inside, why: "" },
    Case { example: "pid-gp1", case: "s-theory", until: 80000, t: 0.64, mp: 0.0, ts: 31.27, band: WITHIN, mp_points: 2.0, reach: Reach::Outside, why: "" },
    Case { example: "pid-gp1", case: "s-tuned", until: 60000, t: 0.64, mp: 0.0, ts: 9.97, band: (1.7, 2.0), mp_points: 2.0, reach: Reach::Outside,
        why: "not the components (the sweep) nor the listing's u(k) handling (FORM 11 = FORM 3 here); u(k-1) up to 200 % would fit it but breaks z-tuned and s-theory" },
    // Prueba 6, Fig. 5-21 and 5-22: the SLC PID instruction, Kc 2 and 10, Ti 0.1 min, 20 ms, 4.6 V step.
    Case { example: "pid-gp1", case: "instruction", until: 60000, t: 0.02, mp: 8.69, ts: 29.6, band: WITHIN, mp_points: 4.0, reach: Reach::Inside, why: "" },
    Case { example: "pid-gp1", case: "instruction-kp10", until: 60000, t: 0.02, mp: 0.0, ts: 12.1, band: WITHIN, mp_points: 2.0, reach: Reach::Inside, why: "" },
    // Prueba 2, Fig. 5-12 and 5-14: Gp2 = 1/(4.7s+1), T = 80 ms.
    Case { example: "pid-gp2", case: "z-theory", until: 40000, t: 0.08, mp: 0.0, ts: 9.96, band: (1.4, 1.5), mp_points: 2.0, reach: Reach::Outside,
        why: "Ki 0.03 per sample leaves the loop nearly proportional, so it follows the plant: the box reaches 10.7 s, 8 % from the measured run" },
    Case { example: "pid-gp2", case: "s-theory", until: 40000, t: 0.08, mp: 0.0, ts: 10.47, band: WITHIN, mp_points: 2.0, reach: Reach::Inside, why: "" },
    // Prueba 3, Fig. 5-16, and Prueba 8, Fig. 5-24: Gp3 = 1/(47s²+19.4s+1).
    Case { example: "pid-gp3", case: "s-theory", until: 100000, t: 0.08, mp: 2.0, ts: 22.4, band: WITHIN, mp_points: 2.0, reach: Reach::Inside, why: "" },
    Case { example: "pid-gp3", case: "instruction", until: 100000, t: 0.04, mp: 0.0, ts: 21.11, band: (1.4, 1.5), mp_points: 2.0, reach: Reach::Inside,
        why: "the PI zero 1/Ti does not cancel the slow pole, whose tail sets ts: C2 +20 % and the gain +10 % bring it to the measured 21 s" },
    // Prueba 4, Fig. 5-18 and 5-19: the level prototype as the thesis describes it physically
    // (pump behind a chopper, saturating; the tank drained through a valve), not the published
    // Gp4 = 0.028/(s+0.224), which cannot take 36 s (the_level_model_cannot_take_36_s). The
    // overshoot of s-theory is 7 points above the measured one: the_level_overshoot_trades_against_the_tuned_run.
    Case { example: "pid-level-prototype", case: "s-theory", until: 80000, t: 0.25, mp: 5.71, ts: 36.41, band: WITHIN, mp_points: 7.5, reach: Reach::Inside, why: "" },
    Case { example: "pid-level-prototype", case: "s-tuned", until: 80000, t: 0.5, mp: 0.0, ts: 25.35, band: WITHIN, mp_points: 2.0, reach: Reach::Outside, why: "" },
    // Prueba 5, Fig. 5-20: the Motomatic, Kp 1, Ki 2.5, 20 ms, 7 V step.
    Case { example: "pid-motomatic", case: "tuned", until: 6000, t: 0.02, mp: 1.4, ts: 1.87, band: WITHIN, mp_points: 2.0, reach: Reach::Inside, why: "" },
];

/// Every run of the thesis's table whose gains the thesis gives, in its
/// band and with its reach; 9 of the 13 within ±20 % of the measured
/// settling time.
#[test]
fn pid_runs_against_the_thesis_table() {
    let mut failures = Vec::new();
    let mut within = 0;
    for c in CASES {
        let (mp, ts) = run(c.example, c.case, &[], c.until, &nominal);
        let ratio = ts / c.ts;
        within += usize::from((0.8..=1.2).contains(&ratio));
        assert_eq!(
            c.band != WITHIN,
            !c.why.is_empty(),
            "{} {}: a band wider than ±20 % needs its reason",
            c.example,
            c.case
        );
        // The reach of the component tolerances.
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for c1 in [0.8, 1.0, 1.2] {
            for c2 in [0.8, 1.0, 1.2] {
                for g in [0.9, 1.0, 1.1] {
                    if c2 != 1.0 && c.example != "pid-gp3" {
                        continue;
                    }
                    let (_, s) = run(c.example, c.case, &[], c.until, &toleranced(c1, c2, g));
                    (lo, hi) = (lo.min(s), hi.max(s));
                }
            }
        }
        let reach = if (lo - c.t..=hi + c.t).contains(&c.ts) {
            Reach::Inside
        } else {
            Reach::Outside
        };
        println!(
            "{} {}: Mp {mp:.2} % (measured {}), ts {ts:.2} s (measured {}, ratio {ratio:.3}); components {lo:.2}-{hi:.2} s: {reach:?}",
            c.example, c.case, c.mp, c.ts
        );
        if !(c.band.0..=c.band.1).contains(&ratio) {
            failures.push(format!(
                "{} {}: settling {ts:.2} s against {} s measured (ratio {ratio:.3}, band {:?}) {}",
                c.example, c.case, c.ts, c.band, c.why
            ));
        }
        if (mp - c.mp).abs() > c.mp_points {
            failures.push(format!(
                "{} {}: overshoot {mp:.2} % against {} % measured (±{} points)",
                c.example, c.case, c.mp, c.mp_points
            ));
        }
        if reach != c.reach {
            failures.push(format!(
                "{} {}: the component tolerances reach {lo:.2}-{hi:.2} s ± {} s, measured {} s: {reach:?}, stated {:?}",
                c.example, c.case, c.t, c.ts, c.reach
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(
        within, 9,
        "runs within ±20 % of the measured settling time (docs/pid.md §5)"
    );
}

/// The source's programs as §3.3.1.1 and Annex F describe them (FORM 11,
/// 12: the module's 0-32767 scale, negative u(k) set to 0, u(k−1) not
/// limited to MAXO) settle every run of the RC circuits and the Motomatic
/// within 5 % of FORM 3/4: on that scale the 16-bit ADD saturates at 32767
/// = 10 V, so keeping the "unclamped" u(k) keeps it at 100 % anyway. The
/// programs' handling of u(k) is not what parts the simulation from the
/// measured runs. (The level prototype too; on the published level model
/// it does: the_level_model_cannot_take_36_s.)
#[test]
fn the_listing_forms_change_no_rc_run() {
    for c in CASES
        .iter()
        .filter(|c| c.t >= 0.02 && !c.case.starts_with("instruction"))
    {
        let form = if c.case.starts_with('z') { 4.0 } else { 3.0 };
        let (mp, ts) = run(c.example, c.case, &[("Loop.FORM", form)], c.until, &nominal);
        let (mpl, tsl) = run(c.example, c.case, &[("Loop.FORM", form + 8.0)], c.until, &nominal);
        println!(
            "{} {}: FORM {form} {mp:.2} % {ts:.2} s, FORM {} {mpl:.2} % {tsl:.2} s",
            c.example,
            c.case,
            form + 8.0
        );
        assert!(
            (tsl - ts).abs() <= 0.05 * ts && (mpl - mp).abs() <= 1.0,
            "{} {}: FORM {} {mpl:.2} % {tsl:.2} s, FORM {form} {mp:.2} % {ts:.2} s",
            c.example,
            c.case,
            form + 8.0
        );
    }
}

/// The reading of §3.3.1.1 that the issue tried — the programs on the
/// 0-16383 scale with u(k−1) kept up to the 16-bit limit, 32767 = 200 % —
/// is FORM 11/12 on a doubled scale: the PV span 0-20 V (raw 0-20000, so
/// an error of 1 V is 1638 counts, as on 0-16383) and CV 100 % = 20 V
/// (32767 counts = 200 % of the 10 V drive, which still saturates at
/// 10 V); MAXO above 100 % is refused (51H), as on the SLC. It brings gp1 s-tuned within 20 % of the measured 9.97 s, but gp1
/// z-tuned overshoots by 10 % or more (measured 2 %) and gp1 s-theory and
/// gp2 s-theory settle 30 % too fast. Annex F puts the programs on the
/// 0-32767 scale, where 200 % cannot be stored; the data do not want it
/// either.
#[test]
fn u_kept_up_to_200_percent_fits_one_run_and_breaks_three() {
    let cases = [
        ("pid-gp1", "s-tuned", 3.0, 60000),
        ("pid-gp1", "z-tuned", 4.0, 60000),
        ("pid-gp1", "s-theory", 3.0, 80000),
        ("pid-gp2", "s-theory", 3.0, 40000),
    ];
    let mut got = Vec::new();
    for (ex, case, form, until) in cases {
        let doubled = [
            ("Loop.FORM", form + 8.0),
            ("Loop.MAXI", 20000.0),
            ("Loop.MAXS", 20.0),
            ("Loop.MAXCV", 20000.0),
        ];
        let (mp, ts) = run(ex, case, &doubled, until, &nominal);
        println!("{ex} {case}, u up to 200 %: {mp:.2} % {ts:.2} s");
        got.push((mp, ts));
    }
    assert!((0.8..=1.2).contains(&(got[0].1 / 9.97)), "gp1 s-tuned {:?}", got[0]);
    assert!(got[1].0 > 10.0, "gp1 z-tuned {:?}", got[1]);
    assert!(got[2].1 / 31.27 < 0.7, "gp1 s-theory {:?}", got[2]);
    assert!(got[3].1 / 10.47 < 0.75, "gp2 s-theory {:?}", got[3]);
}

/// The level model 0.028/(s + 0.224) as published, in the only units where
/// the step 15.2 → 26.6 cm is possible (metres, the sensor 10 V per metre)
/// settles in seconds; in centimetres (the same numbers per cm, the sensor
/// 0.1 V per cm) the pump at 10 V holds at most 0.028·10/0.224 = 1.25 cm
/// and the level never gets to 26.6 cm. Neither is the measured 36.4 s.
/// (Its s-tuned run does land within 20 %, 29.5 s against 25.35, but under
/// FORM 11 Kp 9.5 makes the DDV overflow negative — ΔPV of more than 1 V in
/// 500 ms — which the SLC turns into +32767: an overshoot of more than 50 %
/// that the prototype, at 0 %, never showed; the real tank was far slower.)
#[test]
fn the_level_model_cannot_take_36_s() {
    let (_, metres) = run("pid-level", "s-theory", &[], 80000, &nominal);
    assert!(metres < 5.0, "metres: {metres}");
    let (_, tuned) = run("pid-level", "s-tuned", &[], 80000, &nominal);
    assert!((0.8..=1.2).contains(&(tuned / 25.35)), "s-tuned: {tuned}");
    let (listing, _) = run("pid-level", "s-tuned", &[("Loop.FORM", 11.0)], 80000, &nominal);
    assert!(listing > 50.0, "s-tuned under FORM 11: overshoot {listing}");
    let cm = |m: &mut PlantModel| {
        if let Dynamics::Tank { sensor, .. } = &mut m.dynamics {
            *sensor = 0.1;
        }
    };
    let (_, centimetres) = run("pid-level", "s-theory", &[], 80000, &cm);
    println!("level s-theory: {metres:.2} s in metres, {centimetres} in centimetres");
    assert!(centimetres.is_infinite(), "centimetres: {centimetres}");
}

/// The level prototype's model (examples/pid-level-prototype: a pump with a
/// dead zone behind a saturating chopper, a tank drained through an orifice)
/// has three numbers the thesis does not give: the pump's flow per volt, its
/// dead zone and the drain's opening (the tank's area only scales time, and
/// is folded into the other two). Over a grid of them, every model that puts
/// s-theory within 20 % of its measured 36.41 s *and* within 2 points of its
/// measured 5.71 % overshoot settles s-tuned at least 25 % slower than the
/// measured 25.35 s: the two runs pull the model apart, so the example takes
/// a model with both settling times within 20 % and s-theory's overshoot 7
/// points high (12.5 %) rather than one run exact and the other out.
#[test]
fn the_level_overshoot_trades_against_the_tuned_run() {
    let mut matched = 0;
    let mut fastest_tuned = f64::INFINITY;
    for outflow in [15.0, 20.0, 22.5, 25.0, 30.0, 35.0] {
        for inflow in [15.0, 17.5, 20.0, 22.5, 25.0, 30.0, 35.0] {
            for dead_zone in [0.0, 1.0, 2.0, 3.0, 4.0] {
                // at rest at 15.2 cm: inflow·(u − dead_zone) = outflow·√15.2
                let rest = dead_zone + outflow * 15.2f64.sqrt() / inflow;
                if rest > 9.0 {
                    continue;
                }
                let set = move |m: &mut PlantModel| {
                    if let Dynamics::Tank {
                        inflow: i,
                        outflow: o,
                        dead_zone: d,
                        ..
                    } = &mut m.dynamics
                    {
                        (*i, *o, *d) = (inflow, outflow, dead_zone);
                    }
                };
                let at_rest = [("Loop.CV", rest * 10.0)];
                let (mp, ts) = run("pid-level-prototype", "s-theory", &at_rest, 80000, &set);
                if !(0.8..=1.2).contains(&(ts / 36.41)) || (mp - 5.71).abs() > 2.0 {
                    continue;
                }
                matched += 1;
                let (_, tuned) = run("pid-level-prototype", "s-tuned", &at_rest, 80000, &set);
                println!(
                    "inflow {inflow} outflow {outflow} dead zone {dead_zone}: s-theory {mp:.2} % {ts:.2} s, s-tuned {tuned:.2} s"
                );
                fastest_tuned = fastest_tuned.min(tuned);
            }
        }
    }
    assert!(matched >= 3, "models matching s-theory: {matched}");
    assert!(
        fastest_tuned / 25.35 > 1.25,
        "a model matching s-theory settles s-tuned in {fastest_tuned:.2} s"
    );
}
