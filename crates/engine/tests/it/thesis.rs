//! The PID runs of `004_…` Chapter 5 against the thesis's measured table
//! (docs/pid.md §5), in the engine: each run is simulated from its example
//! (`examples/pid-*`: the plant model, the loop, the case's stimulus), and
//! the overshoot and 98 % settling time of the process (the analog input,
//! scaled as the loop scales it) are taken from the trace (20 ms samples)
//! with `analysis::step_info`, as `alba sim --summary` does.
//!
//! Tolerances per run:
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
//!   time lies inside [fastest − T, slowest + T] over that box, or within
//!   20 % of its nearest end, or neither, and fails when that changes;
//! * the *overshoot*: within 2 points of the measured one (the figures'
//!   reading), from the nominal model or from the components' range, as
//!   stated per run.
//!
//! The tests after the table are the experiments behind each run outside
//! ±20 % (docs/pid.md §5).

use crate::util::compile;
use alba_engine::Engine;
use alba_engine::analysis::step_info;
use alba_engine::sim::{self, SimOptions, Stimulus};
use alba_model::plant::{Dynamics, PlantModel};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

/// The step response of one simulated run: the overshoot (%) and the 98 %
/// settling time (s, infinite if never) of the process — the plant's
/// measurement as the analog input reads it, scaled as the loop scales it —
/// and the settling time of the loop's own `Loop.PV`, which holds each
/// sample for a loop update T.
#[derive(Debug, Clone, Copy)]
struct Step {
    mp: f64,
    ts: f64,
    ts_pv: f64,
}

/// How one run is simulated: an example's case (its stimulus, then `extra`
/// rows at t = 0 that override it), the plant edited by `plant`, the scan
/// period, the trace's sampling, and optionally another program in place of
/// the example's `main.lad` (with the tags it adds).
struct Sim<'a> {
    example: &'a str,
    case: &'a str,
    until: u64,
    extra: Vec<(&'a str, f64)>,
    scan_ms: u64,
    every_ms: u64,
    plant: &'a dyn Fn(&mut PlantModel),
    program: Option<(String, String)>,
}

impl<'a> Sim<'a> {
    fn new(example: &'a str, case: &'a str, until: u64) -> Self {
        Sim {
            example,
            case,
            until,
            extra: Vec::new(),
            scan_ms: 10,
            every_ms: 20,
            plant: &nominal,
            program: None,
        }
    }

    fn with(mut self, rows: &[(&'a str, f64)]) -> Self {
        self.extra.extend_from_slice(rows);
        self
    }

    fn plant(mut self, plant: &'a dyn Fn(&mut PlantModel)) -> Self {
        self.plant = plant;
        self
    }

    fn scan(mut self, ms: u64) -> Self {
        self.scan_ms = ms;
        self
    }

    fn every(mut self, ms: u64) -> Self {
        self.every_ms = ms;
        self
    }

    /// Runs `ladder` instead of the example's program; `tags` are rows
    /// added to its tags.csv.
    fn program(mut self, tags: &str, ladder: &str) -> Self {
        self.program = Some((tags.to_string(), ladder.to_string()));
        self
    }

    fn run(&self) -> Step {
        let dir = example(self.example);
        let mut program = match &self.program {
            None => compile(&dir),
            Some((tags, ladder)) => {
                static N: AtomicUsize = AtomicUsize::new(0);
                let n = N.fetch_add(1, Ordering::Relaxed);
                let tmp = std::env::temp_dir().join(format!("alba-thesis-{}-{n}", std::process::id()));
                std::fs::create_dir_all(&tmp).expect("temp dir");
                std::fs::copy(dir.join("alba.toml"), tmp.join("alba.toml")).expect("alba.toml");
                let csv = std::fs::read_to_string(dir.join("tags.csv")).expect("tags.csv");
                std::fs::write(tmp.join("tags.csv"), format!("{}\n{tags}\n", csv.trim_end())).expect("tags");
                std::fs::write(tmp.join("main.lad"), ladder).expect("main.lad");
                let p = compile(&tmp);
                std::fs::remove_dir_all(&tmp).ok();
                p
            }
        };
        for p in &mut program.plants {
            (self.plant)(&mut p.model);
        }
        let input = program.plants[0].model.output.0.clone();
        let mut text = std::fs::read_to_string(dir.join(format!("stimulus-{}.csv", self.case))).expect("stimulus");
        for (tag, v) in &self.extra {
            text.push_str(&format!("\n0,{tag},{v}"));
        }
        text.push('\n');
        let mut files = alba_diag::Files::new();
        let f = files.add("stimulus.csv", &text);
        let stim = Stimulus::parse(files.text(f), f, &program.layout)
            .unwrap_or_else(|d| panic!("{}", alba_diag::render_all(&d, &files)));
        let names = format!("Loop.PV,Loop.SP,{input},Loop.MINI,Loop.MAXI,Loop.MINS,Loop.MAXS");
        let cols = sim::columns(&names, &program.layout).expect("columns");
        let mut engine = Engine::new(Arc::new(program)).expect("program");
        let mut out = Vec::new();
        let opt = SimOptions {
            scan_ms: self.scan_ms,
            until_ms: self.until,
            every_ms: self.every_ms,
        };
        sim::run(&mut engine, &stim, &cols, opt, &mut out).expect("runs");
        let (mut t, mut pv, mut sp, mut y) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for line in String::from_utf8(out).expect("utf8").lines().skip(1) {
            let v: Vec<f64> = line.split(',').map(|x| x.parse().expect("number")).collect();
            t.push(v[0] as u64);
            pv.push(v[1]);
            sp.push(v[2]);
            // The loop's scaling: MINS + (raw − MINI)·(MAXS − MINS)/(MAXI − MINI).
            y.push(v[6] + (v[3] - v[4]) * (v[7] - v[6]) / (v[5] - v[4]));
        }
        let secs = |ms: Option<u64>| ms.map_or(f64::INFINITY, |ms| ms as f64 / 1000.0);
        let process = step_info(&t, &y, Some(&sp)).expect("a step");
        let held = step_info(&t, &pv, Some(&sp)).expect("a step");
        Step {
            mp: process.overshoot_pct,
            ts: secs(process.settling_ms),
            ts_pv: secs(held.settling_ms),
        }
    }
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

/// A first-order plant K/(τs + 1) given a second pole: K/((τs + 1)(τ2·s + 1)),
/// its time constant τ scaled by `c` and its gain by `g` (τ2 = 0: none).
fn second_pole(tau2: f64, c: f64, g: f64) -> impl Fn(&mut PlantModel) {
    move |m: &mut PlantModel| {
        if tau2 == 0.0 {
            toleranced(c, 1.0, g)(m);
        } else if let Dynamics::FirstOrder { gain, tau } = m.dynamics {
            let tau = tau * c;
            m.dynamics = Dynamics::SecondOrder {
                gain: gain * g,
                a2: tau * tau2,
                a1: tau + tau2,
                a0: 1.0,
            };
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Reach {
    /// The measured settling time is inside what the component tolerances
    /// reach (one loop update either side).
    Inside,
    /// It is not, but the nearest end of their reach is within 20 % of it.
    Within,
    /// Neither: the components do not explain the difference.
    Outside,
}

/// How the simulated overshoot stands against the measured one.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Overshoot {
    /// The nominal model within 2 points of it.
    Near,
    /// Only some components of the box within 2 points (the nominal farther).
    Components,
    /// Neither: within this many points, for a reason tested elsewhere.
    Traded(f64),
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
    reach: Reach,
    overshoot: Overshoot,
    /// Why the band is wider than ±20 % (empty when it is not): the tests that show it.
    why: &'static str,
}

const WITHIN: (f64, f64) = (0.8, 1.2);

#[rustfmt::skip]
const CASES: &[Case] = &[
    // Prueba 1, Fig. 5-8 to 5-11: Gp1 = 1/(10s+1), T = 640 ms, 5 V step.
    Case { example: "pid-gp1", case: "z-theory", until: 80000, t: 0.64, mp: 0.0, ts: 30.4, band: (1.15, 1.3), reach: Reach::Within, overshoot: Overshoot::Near,
        why: "the bench's components, one set for its ten RC runs, bring it to 1.19 (one_bench_one_set_of_components); not the listing's u(k) nor PID_DISC's clock-bit sampling (pid_disc_sampled_by_a_clock_bit)" },
    Case { example: "pid-gp1", case: "z-tuned", until: 60000, t: 0.64, mp: 2.0, ts: 10.6, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Near, why: "" },
    Case { example: "pid-gp1", case: "s-theory", until: 80000, t: 0.64, mp: 0.0, ts: 31.27, band: WITHIN, reach: Reach::Within, overshoot: Overshoot::Near, why: "" },
    Case { example: "pid-gp1", case: "s-tuned", until: 60000, t: 0.64, mp: 0.0, ts: 9.97, band: (1.7, 2.0), reach: Reach::Outside, overshoot: Overshoot::Near,
        why: "outside everything the model, the bench and the listing reach (gp1_s_tuned_is_beyond_the_model_and_the_listing)" },
    // Prueba 6, Fig. 5-21 and 5-22: the SLC PID instruction, Kc 2 and 10, Ti 0.1 min, 20 ms, 4.6 V step.
    Case { example: "pid-gp1", case: "instruction", until: 60000, t: 0.02, mp: 8.69, ts: 29.6, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Components, why: "" },
    Case { example: "pid-gp1", case: "instruction-kp10", until: 60000, t: 0.02, mp: 0.0, ts: 12.1, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Near, why: "" },
    // Prueba 2, Fig. 5-12 and 5-14: Gp2 = 1/(4.7s+1), T = 80 ms.
    Case { example: "pid-gp2", case: "z-theory", until: 40000, t: 0.08, mp: 0.0, ts: 9.96, band: (1.4, 1.5), reach: Reach::Within, overshoot: Overshoot::Near,
        why: "the bench's components bring it to 1.18-1.20 (one_bench_one_set_of_components); not PID_DISC's clock-bit sampling (pid_disc_sampled_by_a_clock_bit)" },
    Case { example: "pid-gp2", case: "s-theory", until: 40000, t: 0.08, mp: 0.0, ts: 10.47, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Near, why: "" },
    // Prueba 3, Fig. 5-16, and Prueba 8, Fig. 5-24: Gp3 = 1/(47s²+19.4s+1).
    Case { example: "pid-gp3", case: "s-theory", until: 100000, t: 0.08, mp: 2.0, ts: 22.4, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Near, why: "" },
    Case { example: "pid-gp3", case: "instruction", until: 100000, t: 0.04, mp: 0.0, ts: 21.11, band: (1.4, 1.5), reach: Reach::Inside, overshoot: Overshoot::Near,
        why: "the PI zero 1/Ti does not cancel the slow pole, whose tail sets ts: the bench's components bring it to 1.01-1.07 (one_bench_one_set_of_components)" },
    // Prueba 4, Fig. 5-18 and 5-19: the level prototype as the thesis describes it physically
    // (pump behind a chopper, saturating; the tank drained through a valve), not the published
    // Gp4 = 0.028/(s+0.224), which cannot take 36 s (the_level_model_cannot_take_36_s). The
    // overshoot of s-theory is 7 points above the measured one: the_level_overshoot_trades_against_the_tuned_run.
    Case { example: "pid-level-prototype", case: "s-theory", until: 80000, t: 0.25, mp: 5.71, ts: 36.41, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Traded(7.5), why: "" },
    Case { example: "pid-level-prototype", case: "s-tuned", until: 80000, t: 0.5, mp: 0.0, ts: 25.35, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Near, why: "" },
    // Prueba 5, Fig. 5-20: the Motomatic, Kp 1, Ki 2.5, 20 ms, 7 V step.
    Case { example: "pid-motomatic", case: "tuned", until: 6000, t: 0.02, mp: 1.4, ts: 1.87, band: WITHIN, reach: Reach::Inside, overshoot: Overshoot::Near, why: "" },
];

fn case(example: &str, name: &str) -> &'static Case {
    CASES
        .iter()
        .find(|c| c.example == example && c.case == name)
        .expect("a case of the table")
}

impl Case {
    fn sim(&self) -> Sim<'static> {
        Sim::new(self.example, self.case, self.until)
    }
}

/// Every run of the thesis's table whose gains the thesis gives, in its
/// band and with its reach; 9 of the 13 within ±20 % of the measured
/// settling time.
#[test]
fn pid_runs_against_the_thesis_table() {
    let mut failures = Vec::new();
    let mut within = 0;
    for c in CASES {
        let Step { mp, ts, ts_pv } = c.sim().run();
        let ratio = ts / c.ts;
        within += usize::from((0.8..=1.2).contains(&ratio));
        assert_eq!(
            c.band != WITHIN,
            !c.why.is_empty(),
            "{} {}: a band wider than ±20 % needs its reason",
            c.example,
            c.case
        );
        // The reach of the component tolerances, settling time and overshoot.
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        let (mut mp_lo, mut mp_hi) = (f64::INFINITY, 0.0f64);
        for c1 in [0.8, 1.0, 1.2] {
            for c2 in [0.8, 1.0, 1.2] {
                for g in [0.9, 1.0, 1.1] {
                    if c2 != 1.0 && c.example != "pid-gp3" {
                        continue;
                    }
                    let s = c.sim().plant(&toleranced(c1, c2, g)).run();
                    (lo, hi) = (lo.min(s.ts), hi.max(s.ts));
                    (mp_lo, mp_hi) = (mp_lo.min(s.mp), mp_hi.max(s.mp));
                }
            }
        }
        let reach = if (lo - c.t..=hi + c.t).contains(&c.ts) {
            Reach::Inside
        } else if [lo, hi].iter().any(|x| (0.8..=1.2).contains(&(x / c.ts))) {
            Reach::Within
        } else {
            Reach::Outside
        };
        let overshoot = if (mp - c.mp).abs() <= 2.0 {
            Overshoot::Near
        } else if (mp_lo - 2.0..=mp_hi + 2.0).contains(&c.mp) {
            Overshoot::Components
        } else {
            Overshoot::Traded((mp - c.mp).abs())
        };
        println!(
            "{} {}: Mp {mp:.2} % (measured {}; components {mp_lo:.2}-{mp_hi:.2}: {overshoot:?}), ts {ts:.2} s (Loop.PV {ts_pv:.2} s; measured {}, ratio {ratio:.4}); components {lo:.2}-{hi:.2} s: {reach:?}",
            c.example, c.case, c.mp, c.ts
        );
        if !(c.band.0..=c.band.1).contains(&ratio) {
            failures.push(format!(
                "{} {}: settling {ts:.2} s against {} s measured (ratio {ratio:.3}, band {:?}) {}",
                c.example, c.case, c.ts, c.band, c.why
            ));
        }
        let mp_ok = match (overshoot, c.overshoot) {
            (Overshoot::Traded(got), Overshoot::Traded(most)) => got <= most,
            (got, stated) => got == stated,
        };
        if !mp_ok {
            failures.push(format!(
                "{} {}: overshoot {mp:.2} % against {} % measured, components {mp_lo:.2}-{mp_hi:.2} %: {overshoot:?}, stated {:?}",
                c.example, c.case, c.mp, c.overshoot
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
        let s = c.sim().with(&[("Loop.FORM", form)]).run();
        let l = c.sim().with(&[("Loop.FORM", form + 8.0)]).run();
        println!(
            "{} {}: FORM {form} {:.2} % {:.2} s, FORM {} {:.2} % {:.2} s",
            c.example,
            c.case,
            s.mp,
            s.ts,
            form + 8.0,
            l.mp,
            l.ts
        );
        assert!(
            (l.ts - s.ts).abs() <= 0.05 * s.ts && (l.mp - s.mp).abs() <= 1.0,
            "{} {}: FORM {} {l:?}, FORM {form} {s:?}",
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
/// 10 V); MAXO above 100 % is refused (51H), as on the SLC. It brings gp1
/// s-tuned within 20 % of the measured 9.97 s, but gp1 z-tuned overshoots
/// by 10 % or more (measured 2 %) and gp1 s-theory and gp2 s-theory settle
/// 30 % too fast. Annex F puts the programs on the 0-32767 scale, where
/// 200 % cannot be stored; the data do not want it either.
#[test]
fn u_kept_up_to_200_percent_fits_one_run_and_breaks_three() {
    let runs = [
        ("pid-gp1", "s-tuned", 3.0),
        ("pid-gp1", "z-tuned", 4.0),
        ("pid-gp1", "s-theory", 3.0),
        ("pid-gp2", "s-theory", 3.0),
    ];
    let mut got = Vec::new();
    for (ex, name, form) in runs {
        let doubled = [
            ("Loop.FORM", form + 8.0),
            ("Loop.MAXI", 20000.0),
            ("Loop.MAXS", 20.0),
            ("Loop.MAXCV", 20000.0),
        ];
        let s = case(ex, name).sim().with(&doubled).run();
        println!("{ex} {name}, u up to 200 %: {:.2} % {:.2} s", s.mp, s.ts);
        got.push(s);
    }
    assert!((0.8..=1.2).contains(&(got[0].ts / 9.97)), "gp1 s-tuned {:?}", got[0]);
    assert!(got[1].mp > 10.0, "gp1 z-tuned {:?}", got[1]);
    assert!(got[2].ts / 31.27 < 0.7, "gp1 s-theory {:?}", got[2]);
    assert!(got[3].ts / 10.47 < 0.75, "gp2 s-theory {:?}", got[3]);
}

/// The program PID_DISC as Annex A.2.2 and E give it: the algorithm is in
/// the main program (rungs 2:0-2:37, not an interrupt) and "el periodo de
/// muestreo … debe ser cambiado alterando la línea 1 del programa
/// (instrucción XIO S:4/0). Los valores permitidos constan en la tabla 3-6".
/// S:4 is the SLC's free-running clock, +1 every 10 ms (§3.3.3); its bit n
/// toggles every 2^n × 10 ms, so its period is 2^(n+1) × 10 ms — Table 3-6's
/// "PERIODO" (S:4/5 = 640 ms, S:4/2 = 80 ms: the sampling periods of
/// Prueba 1 and 2). The rungs themselves are illegible in our copy, so
/// both readings of line 1 are run, in ladder, on the examples' plants:
///
/// * with a one-shot after the XIO, the algorithm runs once per period, at
///   the bit's falling edge: the timed loop of the table (within one
///   period of it);
/// * a bare XIO runs it in every scan while the bit is 0 — half of each
///   period, at the scan rate (§2.1: "aproximadamente alrededor de los
///   20 ms"; a 5/02 runs these 38 rungs in a few ms). The velocity form's
///   proportional steps add up to the same, but Ki·e is added in every
///   scan, an integral tens of times stronger: gp1 z-theory settles in a
///   third of the measured 30.4 s (or never: a limit cycle at 1 ms) and
///   both z-theory runs overshoot (4 % or more where 0 % was measured).
///
/// Neither brings the z-theory runs to their measured settling times; the
/// one-shot reading is the one that matches the table's sampling periods
/// and the measured 0 % overshoots, and it is the model's.
#[test]
fn pid_disc_sampled_by_a_clock_bit() {
    const TAGS: &str = "Free,TIMER,,,,S:4 as a timer's milliseconds\nS4,DINT,,,,the SLC's free-running clock S:4 (10 ms counts)\nQ,DINT,,,,\nBit,DINT,,,,S:4/n\nOpen,BOOL,,,,XIO S:4/n passes\nEdge,BOOL,,,,one-shot storage";
    let ladder = |half: u32, one_shot: bool| {
        format!(
            "// S:4: +1 every 10 ms from the start; S:4/n its bit n, n = log2({half})\n\
             TON(Free,2147483647,0);\n\
             DIV(Free.ACC,10,S4);\n\
             DIV(S4,{half},Q);\n\
             AND(Q,1,Bit);\n\
             // line 1 of PID_DISC: XIO S:4/n{}\n\
             EQU(Bit,0){}OTE(Open);\n\
             XIO(Open)JMP(Skip);\n\
             PID(Loop,Meas,Drive);\n\
             LBL(Skip)NOP();\n",
            if one_shot { ", then a one-shot" } else { "" },
            if one_shot { "ONS(Edge)" } else { "" },
        )
    };
    // The program, not the instruction, decides when the loop updates: TM off.
    let sti = [("Loop.TM", 0.0), ("Loop.FORM", 12.0)];
    for (ex, name) in [("pid-gp1", "z-theory"), ("pid-gp1", "z-tuned"), ("pid-gp2", "z-theory")] {
        let c = case(ex, name);
        let half = (c.t * 1000.0 / 20.0) as u32;
        let timed = c.sim().with(&[("Loop.FORM", 12.0)]).run();
        let once = c.sim().with(&sti).program(TAGS, &ladder(half, true)).run();
        println!(
            "{ex} {name}: timed {:.2} % {:.2} s; S:4/n and a one-shot {:.2} % {:.2} s (measured {} % {} s)",
            timed.mp, timed.ts, once.mp, once.ts, c.mp, c.ts
        );
        assert!(
            (once.ts - timed.ts).abs() <= c.t && (once.mp - timed.mp).abs() < 0.5,
            "{ex} {name}: one-shot {once:?}, timed {timed:?}"
        );
        for scan in [2, 5, 10, 20] {
            let every = c.sim().scan(scan).with(&sti).program(TAGS, &ladder(half, false)).run();
            println!(
                "{ex} {name}: S:4/n without a one-shot, {scan} ms scans: {:.2} % {:.2} s (ratio {:.2})",
                every.mp,
                every.ts,
                every.ts / c.ts
            );
            match name {
                "z-theory" if ex == "pid-gp1" => {
                    assert!(
                        every.ts / c.ts < 0.5 && every.mp > 2.0,
                        "{ex} {name} at {scan} ms: {every:?}"
                    )
                }
                "z-theory" => assert!(every.mp > 4.0, "{ex} {name} at {scan} ms: {every:?}"),
                _ => {}
            }
        }
    }
}

/// Annex F, the PC program that drew the source's figures: it polls N9:0
/// and N9:1 over DH-485 and puts sample n at x = n·a pixels with
/// "a=450.0*0.085/tiempo_x" ("Variable 'a' sirve para calibrar el tiempo
/// de barrido de una pantalla. Escala del eje de tiempo. Difiere con cada
/// PC."), while the axis (escala_x) is labelled tiempo_x/15 s per
/// division: the figure's time is n × 85 ms whatever a poll really took
/// (the real time of a screen, clock() before and after, is only printed
/// beside it, "Tiempo(s)="). A poll of p ms puts every settling time read
/// off a figure at 85/p of the real one.
///
/// For each run (nominal model), the poll periods that would bring the
/// simulated settling time within 20 % of the real one: at 85 ms (the
/// calibration) the 9 of the table; from 103 to 108 ms, 11, all but gp1
/// s-tuned and gp1 instruction; no poll period brings gp1 s-tuned within
/// 20 % together with gp1 s-theory, the same program on the same circuit.
/// The figures are not in our copy, so the real poll period stays a
/// reading uncertainty: the bench's components explain the same runs
/// without it (one_bench_one_set_of_components), and it cannot explain
/// gp1 s-tuned.
#[test]
fn the_figures_time_axis_is_assumed() {
    let sims: Vec<(&Case, f64)> = CASES.iter().map(|c| (c, c.sim().run().ts)).collect();
    // Poll period p (ms) for which a run is within 20 %: 0.8 ≤ ts·85/(p·measured) ≤ 1.2.
    let range = |c: &Case, ts: f64| (85.0 * ts / (1.2 * c.ts), 85.0 * ts / (0.8 * c.ts));
    let within_at = |p: f64| {
        sims.iter()
            .filter(|(c, ts)| {
                let (lo, hi) = range(c, *ts);
                (lo..=hi).contains(&p)
            })
            .map(|(c, _)| format!("{} {}", c.example, c.case))
            .collect::<Vec<_>>()
    };
    for (c, ts) in &sims {
        let (lo, hi) = range(c, *ts);
        println!("{} {}: within 20 % for a poll of {lo:.1}-{hi:.1} ms", c.example, c.case);
    }
    assert_eq!(within_at(85.0).len(), 9, "{:?}", within_at(85.0));
    let best = (800..1600)
        .map(|p| f64::from(p) / 10.0)
        .max_by_key(|p| within_at(*p).len())
        .expect("a poll period");
    let most = within_at(best);
    println!("poll {best} ms: {} within 20 %: {most:?}", most.len());
    assert_eq!(most.len(), 11, "{most:?}");
    assert!(most.iter().any(|r| r == "pid-gp1 z-theory") && most.iter().any(|r| r == "pid-gp2 z-theory"));
    let tuned = sims
        .iter()
        .find(|(c, _)| c.example == "pid-gp1" && c.case == "s-tuned")
        .expect("s-tuned");
    let theory = sims
        .iter()
        .find(|(c, _)| c.example == "pid-gp1" && c.case == "s-theory")
        .expect("s-theory");
    let (a, b) = (range(tuned.0, tuned.1), range(theory.0, theory.1));
    assert!(a.1 < b.0 || b.1 < a.0, "gp1 s-tuned {a:?} and s-theory {b:?} overlap");
}

/// gp1 s-tuned (Kp 8, Ki 1.5 /s, PID_CONT at 640 ms) measured 9.97 s; the
/// model settles in 18 s. Everything the source and the hardware let vary
/// was tried, and none reaches it without breaking another run:
///
/// * the components and what a real circuit adds — C ±20 %, the loop gain
///   ±10 %, a second pole (the input module's filter, 95 % in 60 ms, so
///   τ ≈ 20 ms, §2.2.16; up to 0.2 s), with the SLC's arithmetic (FORM 3)
///   or the listing's (FORM 11): 17 s at the fastest;
/// * the sampling: PID_CONT runs in an STI interrupt of period S:30 but
///   its T is a constant in the rungs (no N7 word holds it, Annex A.2.1),
///   so a mismatch scales the integral; an m-fold one that brings s-tuned
///   within 20 % takes s-theory, the same program on the same circuit, out
///   of it (and the other way round);
/// * the gains: the table's, entered ×100 as integers, are exact; within
///   ±0.5 of Kp and ±0.1 of Ki the run still takes 1.5 times the measured
///   time; Kp = 6 (or Ki = 2.5) would give it — a misprint that nothing
///   in the source confirms;
/// * the output handling of §3.3.1.1 up to 200 %
///   (u_kept_up_to_200_percent_fits_one_run_and_breaks_three) and the
///   figures' time axis (the_figures_time_axis_is_assumed): each fits this
///   run only by taking another run of Prueba 1 out.
///
/// The measured run is outside what the published plant and the programs
/// as described can produce.
#[test]
fn gp1_s_tuned_is_beyond_the_model_and_the_listing() {
    let tuned = case("pid-gp1", "s-tuned");
    let theory = case("pid-gp1", "s-theory");
    let mut fastest = f64::INFINITY;
    for tau2 in [0.0, 0.02, 0.2] {
        for c in [0.8, 1.0, 1.2] {
            for g in [0.9, 1.0, 1.1] {
                for form in [3.0, 11.0] {
                    let plant = second_pole(tau2, c, g);
                    let s = tuned.sim().with(&[("Loop.FORM", form)]).plant(&plant).run();
                    fastest = fastest.min(s.ts);
                }
            }
        }
    }
    println!("gp1 s-tuned over components, second pole and FORM 3/11: {fastest:.2} s at the fastest");
    assert!(
        fastest > 1.6 * tuned.ts,
        "gp1 s-tuned reaches {fastest:.2} s (measured {})",
        tuned.ts
    );
    // T in the rungs against the STI period: the integral m times as strong.
    for m in [1.25, 1.5, 2.0, 3.0] {
        let a = tuned.sim().with(&[("Loop.KI", 1.5 * m)]).run();
        let b = theory.sim().with(&[("Loop.KI", 0.5 * m)]).run();
        let (ra, rb) = (a.ts / tuned.ts, b.ts / theory.ts);
        println!(
            "integral ×{m}: s-tuned {:.2} % {:.2} s ({ra:.2}), s-theory {:.2} % {:.2} s ({rb:.2})",
            a.mp, a.ts, b.mp, b.ts
        );
        assert!(
            !((0.8..=1.2).contains(&ra) && (0.8..=1.2).contains(&rb)),
            "integral ×{m} fits both"
        );
    }
    // The gains near the table's, and the nearest that would fit.
    for (kp, ki) in [(7.5, 1.5), (8.5, 1.5), (8.0, 1.4), (8.0, 1.6)] {
        let s = tuned.sim().with(&[("Loop.KP", kp), ("Loop.KI", ki)]).run();
        println!("Kp {kp} Ki {ki}: {:.2} % {:.2} s", s.mp, s.ts);
        assert!(s.ts > 1.5 * tuned.ts, "Kp {kp} Ki {ki}: {s:?}");
    }
    for (kp, ki) in [(6.0, 1.5), (8.0, 2.5)] {
        let s = tuned.sim().with(&[("Loop.KP", kp), ("Loop.KI", ki)]).run();
        println!("Kp {kp} Ki {ki}: {:.2} % {:.2} s", s.mp, s.ts);
        assert!(
            (0.8..=1.2).contains(&(s.ts / tuned.ts)) && s.mp < 2.0,
            "Kp {kp} Ki {ki}: {s:?}"
        );
    }
}

/// The Motomatic measured 1.4 % overshoot; the first-order model has none,
/// and cannot have any: under a PI the closed loop τs² + (1 + K·Kp)s +
/// K·Ki has real poles for every gain (its discriminant is negative only
/// if 4τ·K·Ki > (1 + K·Kp)², never true here), the slower one slower than
/// the zero Ki/Kp. A second pole (the armature's L/R, the input module's
/// 20 ms filter, up to 0.1 s) with τ ±20 % and the gain ±10 % gives less
/// than 0.5 %: it is not what the model lacks. It takes a second pole of
/// about 0.2 s (as slow as the mechanical one) to reach 1.4 %, and then the
/// loop settles in under half the measured 1.87 s. What does read as 1.4 %
/// is ripple on the tachometer (a DC tachometer's commutation ripple, which
/// the PC's polled samples catch at random): 50 mV rms, 0.5 % of the range
/// and inside the 2 % band, sampled every 85 ms as Annex F's program did,
/// reads (median of eight draws) as the measured overshoot and leaves the
/// settling time within 20 %. This is consistent with the measured run,
/// not proven by it: the figure that would show the ripple (Fig. 5-20) is
/// not in our copy, and the example keeps the model noiseless.
#[test]
fn the_motomatic_overshoot_is_ripple_not_a_second_pole() {
    let c = case("pid-motomatic", "tuned");
    let design = Sim::new("pid-motomatic", "s-theory", 6000).run();
    println!(
        "Motomatic s-theory (the design, not measured): {:.2} % {:.2} s",
        design.mp, design.ts
    );
    let mut most: f64 = 0.0;
    for tau2 in [0.005, 0.02, 0.05, 0.1] {
        for k in [0.8, 1.0, 1.2] {
            for g in [0.9, 1.0, 1.1] {
                most = most.max(c.sim().plant(&second_pole(tau2, k, g)).run().mp);
            }
        }
    }
    println!("Motomatic with a second pole up to 0.1 s: overshoot {most:.2} % at most");
    assert!(most < 0.5, "{most}");
    let slow = (15..=30)
        .map(|n| f64::from(n) / 100.0)
        .map(|tau2| (tau2, c.sim().plant(&second_pole(tau2, 1.0, 1.0)).run()))
        .find(|(_, s)| s.mp >= c.mp)
        .expect("a second pole that overshoots 1.4 %");
    println!("second pole {} s: {:.2} % {:.2} s", slow.0, slow.1.mp, slow.1.ts);
    assert!(slow.0 >= 0.2 && slow.1.ts < 0.5 * c.ts, "{slow:?}");
    // Ripple: the overshoot and settling time read off samples polled every
    // 85 ms, over eight draws of it.
    let mut draws: Vec<Step> = (1..=8)
        .map(|seed| {
            let ripple = move |m: &mut PlantModel| {
                m.noise = 0.05;
                m.seed = seed;
            };
            c.sim().plant(&ripple).scan(5).every(85).run()
        })
        .collect();
    draws.sort_by(|a, b| a.mp.total_cmp(&b.mp));
    for d in &draws {
        println!("ripple 50 mV rms, polled every 85 ms: {:.2} % {:.2} s", d.mp, d.ts);
    }
    let median = (draws[3].mp + draws[4].mp) / 2.0;
    assert!((median - c.mp).abs() < 0.5, "median overshoot {median:.2} %");
    let mut ts: Vec<f64> = draws.iter().map(|d| d.ts).collect();
    ts.sort_by(f64::total_cmp);
    let median_ts = (ts[3] + ts[4]) / 2.0;
    println!("ripple: median overshoot {median:.2} %, median settling time {median_ts:.2} s");
    assert!(
        (0.8..=1.2).contains(&(median_ts / c.ts)),
        "median settling time {median_ts:.2} s"
    );
}

/// gp2 s-theory lands 19.8 % above the measured 10.47 s, 0.02 s inside
/// the ±20 % band, and the count of runs within 20 % (9) depends on it. It
/// is not an artefact of the measurement: the process enters its ±2 %
/// band at 12.54 s whether the trace is sampled every 20, 10 or 1 ms and
/// whether the scan is 10, 5 or 1 ms (the loop updates on its own 80 ms
/// schedule), and under the listing's arithmetic (FORM 11) too. The loop's
/// held PV, what Annex F's PC would have plotted if N9:0 is written once
/// per sample, shows it at the next update, 12.56 s. Before this run was
/// measured on the process, the table used that held PV, which rounds every
/// settling time up to a loop update (640 ms in Prueba 1). Either way the
/// margin, 0.02-0.03 s, is well under the figures' reading tolerance (a
/// loop update, 80 ms, and a DH-485 poll, 85 ms): this run is at the edge,
/// and the table says so.
#[test]
fn gp2_s_theory_is_at_the_edge_by_any_measure() {
    let c = case("pid-gp2", "s-theory");
    let edge = 1.2 * c.ts;
    let mut measures = vec![("process, 20 ms trace, 10 ms scans", c.sim().run().ts)];
    let table = measures[0].1;
    for (what, scan, every) in [
        ("10 ms trace", 10, 10),
        ("5 ms scans", 5, 5),
        ("1 ms scans and trace", 1, 1),
    ] {
        measures.push((what, c.sim().scan(scan).every(every).run().ts));
    }
    measures.push(("FORM 11", c.sim().with(&[("Loop.FORM", 11.0)]).run().ts));
    let held = c.sim().run().ts_pv;
    for (what, ts) in &measures {
        println!(
            "gp2 s-theory, {what}: {ts:.3} s (ratio {:.4}; the edge {edge:.3} s)",
            ts / c.ts
        );
        assert!((ts - table).abs() <= 0.02 && *ts < edge, "{what}: {ts}");
    }
    println!("gp2 s-theory, Loop.PV: {held:.3} s (ratio {:.4})", held / c.ts);
    assert!(held < edge && held - table <= c.t, "Loop.PV: {held}");
    assert!(
        edge - table < 0.1 && edge - held < 0.1,
        "no longer at the edge: {table}, {held}"
    );
}

/// The three RC circuits were built on one bench from two electrolytic
/// capacitors (§5.1.1-5.1.2: Gp1 with C = 1000 µF, Gp2 with 470 µF, Gp3
/// with C1 = 1000 µF and C2 = 470 µF) behind one current-to-voltage
/// converter, so one set of component values must serve all ten of their
/// runs. With both capacitors 20 % above nominal (the edge of an
/// electrolytic's ±20 %: 1200 and 564 µF) and the converter's gain 2.5 %
/// low, nine of the ten settle within 20 % of the measured times — all but
/// gp1 s-tuned, which stays 70 % slow — and every overshoot comes within 2
/// points of the measured one: gp1 instruction 7.9 % (8.69 measured, 5.2 %
/// nominal: the larger capacitor lowers the loop's damping, 10·c·s² +
/// (1 + 2g)s + 2g/6 with Kc 2, Ti 6 s), gp3 s-theory 2.0 % (2 % measured,
/// 0 % nominal). A neighbouring set (C470 +15 %, gain +2.5 %) does the
/// same: it is a region, not a fitted point. The examples keep the nominal
/// values the source publishes; this is the tested explanation of the RC
/// runs outside ±20 % (gp1 and gp2 z-theory, gp3 instruction), and it
/// leaves gp1 s-tuned unexplained
/// (gp1_s_tuned_is_beyond_the_model_and_the_listing).
#[test]
fn one_bench_one_set_of_components() {
    for (c1000, c470, g) in [(1.2, 1.2, 0.975), (1.2, 1.15, 1.025)] {
        for c in CASES
            .iter()
            .filter(|c| ["pid-gp1", "pid-gp2", "pid-gp3"].contains(&c.example))
        {
            let bench = match c.example {
                "pid-gp1" => toleranced(c1000, 1.0, g),
                "pid-gp2" => toleranced(c470, 1.0, g),
                _ => toleranced(c1000, c470, g),
            };
            let s = c.sim().plant(&bench).run();
            let ratio = s.ts / c.ts;
            println!(
                "C1000 ×{c1000}, C470 ×{c470}, gain ×{g}: {} {}: {:.2} % (measured {}), {:.2} s (measured {}, ratio {ratio:.3})",
                c.example, c.case, s.mp, c.mp, s.ts, c.ts
            );
            if c.case == "s-tuned" {
                assert!(ratio > 1.6, "gp1 s-tuned {s:?}");
            } else {
                assert!((0.8..=1.2).contains(&ratio), "{} {}: {s:?}", c.example, c.case);
            }
            assert!((s.mp - c.mp).abs() <= 2.0, "{} {}: {s:?}", c.example, c.case);
        }
    }
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
    let level = |name: &'static str| Sim::new("pid-level", name, 80000);
    let metres = level("s-theory").run().ts;
    assert!(metres < 5.0, "metres: {metres}");
    let tuned = level("s-tuned").run();
    println!("published level model, s-tuned: {:.2} % {:.2} s", tuned.mp, tuned.ts);
    let tuned = tuned.ts;
    assert!((0.8..=1.2).contains(&(tuned / 25.35)), "s-tuned: {tuned}");
    let listing = level("s-tuned").with(&[("Loop.FORM", 11.0)]).run().mp;
    assert!(listing > 50.0, "s-tuned under FORM 11: overshoot {listing}");
    let cm = |m: &mut PlantModel| {
        if let Dynamics::Tank { sensor, .. } = &mut m.dynamics {
            *sensor = 0.1;
        }
    };
    let centimetres = level("s-theory").plant(&cm).run().ts;
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
                let theory = case("pid-level-prototype", "s-theory")
                    .sim()
                    .with(&at_rest)
                    .plant(&set)
                    .run();
                if !(0.8..=1.2).contains(&(theory.ts / 36.41)) || (theory.mp - 5.71).abs() > 2.0 {
                    continue;
                }
                matched += 1;
                let tuned = case("pid-level-prototype", "s-tuned")
                    .sim()
                    .with(&at_rest)
                    .plant(&set)
                    .run()
                    .ts;
                println!(
                    "inflow {inflow} outflow {outflow} dead zone {dead_zone}: s-theory {:.2} % {:.2} s, s-tuned {tuned:.2} s",
                    theory.mp, theory.ts
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
