//! The PID runs of `004_…` Chapter 5 against the thesis's measured table
//! (docs/pid.md §5): each case is simulated with `alba sim --summary`, and
//! its 98 % settling time must lie in the band stated here relative to the
//! measured one, and its overshoot within the stated points. Cases inside
//! ±20 % need no reason; every wider band says why, and the test fails when
//! a run drifts outside its band (in either direction: a case that gets
//! *closer* than its band expects fails too, so the table and its reasons
//! stay true). The engine's `crates/engine/tests/it/thesis.rs` holds the same
//! runs on 20 ms traces, with the reach of the component tolerances and an
//! experiment for each run outside ±20 %.

use crate::{alba, repo};

struct Case {
    example: &'static str,
    case: &'static str,
    /// Measured by the source: overshoot (%) and 98 % settling time (s).
    mp: f64,
    ts: f64,
    /// Allowed simulated/measured settling-time ratio.
    band: (f64, f64),
    /// Allowed |simulated − measured| overshoot, percentage points.
    mp_points: f64,
    /// Why the band is wider than ±20 % (empty when it is not).
    why: &'static str,
}

const WITHIN: (f64, f64) = (0.8, 1.2);

const CASES: &[Case] = &[
    Case {
        example: "pid-gp1",
        case: "z-tuned",
        mp: 2.0,
        ts: 10.6,
        band: WITHIN,
        mp_points: 3.0,
        why: "",
    },
    Case {
        example: "pid-gp1",
        case: "s-theory",
        mp: 0.0,
        ts: 31.27,
        band: WITHIN,
        mp_points: 3.0,
        why: "",
    },
    Case {
        example: "pid-gp1",
        case: "instruction",
        mp: 8.69,
        ts: 29.6,
        band: WITHIN,
        mp_points: 4.0,
        why: "",
    },
    Case {
        example: "pid-gp1",
        case: "instruction-kp10",
        mp: 0.0,
        ts: 12.1,
        band: WITHIN,
        mp_points: 3.0,
        why: "",
    },
    Case {
        example: "pid-gp3",
        case: "s-theory",
        mp: 2.0,
        ts: 22.4,
        band: WITHIN,
        mp_points: 3.0,
        why: "",
    },
    Case {
        example: "pid-level",
        case: "s-tuned",
        mp: 0.0,
        ts: 25.35,
        band: WITHIN,
        mp_points: 3.0,
        why: "",
    },
    Case {
        example: "pid-motomatic",
        case: "tuned",
        mp: 1.4,
        ts: 1.87,
        band: WITHIN,
        mp_points: 3.0,
        why: "",
    },
    Case {
        example: "pid-gp1",
        case: "z-theory",
        mp: 0.0,
        ts: 30.4,
        band: (1.2, 1.3),
        mp_points: 3.0,
        why: "not the components: τ 8-12 s and gain 0.8-1.2 keep it at 35-41 s (the sweep below), nor the \
              programs' handling of u(k) (FORM 12, crates/engine/tests/it/thesis.rs); Annex E's ladder is illegible",
    },
    Case {
        example: "pid-gp2",
        case: "s-theory",
        mp: 0.0,
        ts: 10.47,
        band: (1.2, 1.25),
        mp_points: 3.0,
        why: "as gp1 z-theory: the nominal 470 µF capacitor; 21 %, at the edge",
    },
    Case {
        example: "pid-gp1",
        case: "s-tuned",
        mp: 0.0,
        ts: 9.97,
        band: (1.7, 2.0),
        mp_points: 3.0,
        why: "not the components either (17-21 s over the sweep below), nor the programs' handling of u(k): \
              on their 0-32767 scale u stops at 10 V anyway (FORM 11; crates/engine/tests/it/thesis.rs)",
    },
    Case {
        example: "pid-gp2",
        case: "z-theory",
        mp: 0.0,
        ts: 9.96,
        band: (1.4, 1.5),
        mp_points: 3.0,
        why: "Ki 0.03 per sample: the integral is nearly absent, so the simulated loop follows the nominal τ",
    },
    Case {
        example: "pid-gp3",
        case: "instruction",
        mp: 0.0,
        ts: 21.11,
        band: (1.4, 1.5),
        mp_points: 3.0,
        why: "the instruction's gains read as Kc 3, Ti 0.2 min (the source gives only \"kp, ki\")",
    },
    Case {
        example: "pid-level",
        case: "s-theory",
        mp: 5.71,
        ts: 36.41,
        band: (0.03, 0.05),
        mp_points: 6.0,
        why: "the published level model 0.028/(s+0.224) cannot take 36 s in any units: it settles in 1.5 s",
    },
];

/// (overshoot %, settling time s) from `alba sim --summary`.
fn simulate(example: &str, case: &str) -> (f64, f64) {
    simulate_in(&repo().join("examples").join(example), example, case)
}

fn simulate_in(dir: &std::path::Path, example: &str, case: &str) -> (f64, f64) {
    let args = std::fs::read_to_string(dir.join(format!("golden-{case}.args"))).expect("args");
    let stimulus = format!("stimulus-{case}.csv");
    let mut argv: Vec<&str> = vec!["sim", "."];
    argv.extend(args.split_whitespace());
    argv.extend(["--stimulus", &stimulus, "--summary", "Loop.PV:Loop.SP"]);
    let out = alba(dir, &argv);
    let text = String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{example} {case}: {text}");
    let num = |after: &str| -> f64 {
        let at = text
            .find(after)
            .unwrap_or_else(|| panic!("{example} {case}: no `{after}` in {text}"))
            + after.len();
        text[at..]
            .split_whitespace()
            .next()
            .and_then(|w| w.parse().ok())
            .unwrap_or_else(|| panic!("{example} {case}: a number after `{after}`"))
    };
    (num("overshoot "), num("settling time (98 %) "))
}

#[test]
fn pid_runs_stay_within_their_bands_of_the_thesis_table() {
    let mut failures = Vec::new();
    let mut within = 0;
    for c in CASES {
        let (mp, ts) = simulate(c.example, c.case);
        let ratio = ts / c.ts;
        if (0.8..=1.2).contains(&ratio) {
            within += 1;
        }
        let wide = c.band != WITHIN;
        assert_eq!(
            wide,
            !c.why.is_empty(),
            "{} {}: a band wider than ±20 % needs its reason",
            c.example,
            c.case
        );
        if !(c.band.0..=c.band.1).contains(&ratio) {
            failures.push(format!(
                "{} {}: settling {ts:.2} s against {:.2} s measured (ratio {ratio:.3}, band {:?}){}",
                c.example,
                c.case,
                c.ts,
                c.band,
                if wide { format!(" — {}", c.why) } else { String::new() }
            ));
        }
        if (mp - c.mp).abs() > c.mp_points {
            failures.push(format!(
                "{} {}: overshoot {mp:.2} % against {:.2} % measured (±{} points)",
                c.example, c.case, c.mp, c.mp_points
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(
        within, 7,
        "runs within 20 % of the measured settling time (docs/pid.md §5)"
    );
}

/// The explanation docs/pid.md used to give — the RC circuit's component
/// tolerances — tested: over τ = 8-12 s (the capacitor's ±20 %) and the
/// converter's gain 0.8-1.2, gp1's z-theory and s-tuned runs stay far from
/// the measured 30.4 s and 9.97 s. The difference is in the algorithm, not in
/// the plant.
#[test]
fn component_tolerances_do_not_explain_the_gp1_differences() {
    let src = repo().join("examples/pid-gp1");
    let toml = std::fs::read_to_string(src.join("alba.toml")).expect("alba.toml");
    assert!(
        toml.contains("tau = 10.0") && toml.contains("gain = 1.0"),
        "the nominal model changed"
    );
    for (tau, gain) in [(8.0, 0.8), (8.0, 1.2), (12.0, 0.8), (12.0, 1.2)] {
        let dir = crate::scratch(&format!("pid-sweep-{tau}-{gain}"));
        for e in std::fs::read_dir(&src).expect("example") {
            let p = e.expect("entry").path();
            std::fs::copy(&p, dir.join(p.file_name().expect("name"))).expect("copy");
        }
        let t = toml
            .replace("tau = 10.0", &format!("tau = {tau}"))
            .replace("gain = 1.0", &format!("gain = {gain}"));
        std::fs::write(dir.join("alba.toml"), t).expect("write");
        let (_, z) = simulate_in(&dir, "pid-gp1", "z-theory");
        let (_, s) = simulate_in(&dir, "pid-gp1", "s-tuned");
        assert!(
            (34.0..=42.0).contains(&z),
            "τ {tau}, gain {gain}: z-theory settles in {z} s"
        );
        assert!(
            (16.0..=21.0).contains(&s),
            "τ {tau}, gain {gain}: s-tuned settles in {s} s"
        );
    }
}
