//! The PID runs of `004_…` Chapter 5 against the thesis's measured table
//! (docs/pid.md §5): each case is simulated with `alba sim --summary`, and
//! its 98 % settling time must lie in the band stated here relative to the
//! measured one, and its overshoot within the stated points. Cases inside
//! ±20 % need no reason; every wider band says why, and the test fails when
//! a run drifts outside its band (in either direction: a case that gets
//! *closer* than its band expects fails too, so the table and its reasons
//! stay true).

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
        why: "the nominal RC (τ = 10 s) against a 1000 µF electrolytic of ±20 %: a slow design follows τ",
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
        why: "after 2 s of saturation the s-plane integral unwinds slowly; the source's listing (which keeps the \
              unclamped u(k) as u(k-1)) is not legible in our copy, so Alba stores the limited output",
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
    let dir = repo().join("examples").join(example);
    let args = std::fs::read_to_string(dir.join(format!("golden-{case}.args"))).expect("args");
    let stimulus = format!("stimulus-{case}.csv");
    let mut argv: Vec<&str> = vec!["sim", "."];
    argv.extend(args.split_whitespace());
    argv.extend(["--stimulus", &stimulus, "--summary", "Loop.PV:Loop.SP"]);
    let out = alba(&dir, &argv);
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
