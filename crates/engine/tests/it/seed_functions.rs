//! The state-net source's expression language (`003_…` §2.2.3.5, issue 34
//! point 1): its functions and operators in a net's script and guard, run by
//! the engine in every mode and checked against the functions computed here
//! in f64 (the source's parser computes in doubles).

use crate::util::{MODES, compile, simulate_in};
use std::path::PathBuf;

/// A project folder under the system's temporary directory.
fn project(name: &str, tags: &str, script: &str, guard: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-seed-fn-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let w = |f: &str, t: &str| std::fs::write(dir.join(f), t).expect("write");
    w(
        "alba.toml",
        &format!("name = \"{name}\"\nscan_ms = 10\nprograms = [\"n.pnml\"]\n"),
    );
    w(
        "tags.csv",
        &format!("name,type,address,initial,retain,description\n{tags}"),
    );
    let esc = script.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
    let guard = guard.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
    w(
        "n.pnml",
        &format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
  <net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">
    <toolspecific tool="alba" version="1"><mode>normal</mode></toolspecific>
    <page id="page0">
      <place id="S"><initialMarking><text>1</text></initialMarking></place>
      <transition id="go"><toolspecific tool="alba" version="1"><kind>condition</kind><guard>{guard}</guard></toolspecific></transition>
      <place id="e"><toolspecific tool="alba" version="1"><kind>expression</kind><script>{esc}</script></toolspecific></place>
      <transition id="back"/>
      <arc id="a1" source="S" target="go"/>
      <arc id="a2" source="go" target="e"/>
      <arc id="a3" source="e" target="back"/>
      <arc id="a4" source="back" target="S"/>
    </page>
  </net>
</pnml>
"#
        ),
    );
    dir
}

/// The values of `tags` after the script ran once (the third scan), the
/// same in every engine mode.
fn run(dir: &PathBuf, tags: &[&str]) -> Vec<f64> {
    let program = compile(dir);
    let cols = tags.join(",");
    let mut first: Option<String> = None;
    for mode in MODES {
        let trace = simulate_in(mode, program.clone(), "", Some(&cols), (10, 20, 10));
        if let Some(f) = &first {
            assert_eq!(f, &trace, "{mode:?} differs");
        }
        first = Some(trace);
    }
    let trace = first.unwrap_or_default();
    let last = trace.lines().last().unwrap_or_default();
    let _ = std::fs::remove_dir_all(dir);
    last.split(',')
        .skip(1)
        .map(|v| v.parse::<f64>().unwrap_or_else(|_| panic!("`{v}` in {trace}")))
        .collect()
}

fn close(got: f64, want: f64) -> bool {
    (got - want).abs() <= 1e-5 * want.abs().max(0.1)
}

/// IEEE remainder as .NET's Math.IEEERemainder computes it.
fn ieee_rem(a: f64, b: f64) -> f64 {
    let q = (a / b).round_ties_even();
    a - b * q
}

#[test]
fn every_function_of_the_source_gives_its_result() {
    type F = fn(f64, f64) -> f64;
    type Case<'a> = (&'a str, F, &'a [(f64, f64)]);
    let cases: &[Case] = &[
        ("cos(X)", |x, _| x.cos(), &[(0.0, 0.0), (1.0, 0.0), (-2.5, 0.0)]),
        (
            "cosh(X)",
            |x, _| x.cosh(),
            &[(0.0, 0.0), (1.5, 0.0), (-3.0, 0.0), (40.0, 0.0)],
        ),
        ("arcos(X)", |x, _| x.acos(), &[(0.5, 0.0), (-1.0, 0.0)]),
        ("arccos(X)", |x, _| x.acos(), &[(0.25, 0.0)]),
        ("sin(X)", |x, _| x.sin(), &[(0.5, 0.0), (-4.0, 0.0)]),
        ("sinh(X)", |x, _| x.sinh(), &[(1.0, 0.0), (-2.0, 0.0), (30.0, 0.0)]),
        ("arcsin(X)", |x, _| x.asin(), &[(0.5, 0.0), (-1.0, 0.0)]),
        ("tan(X)", |x, _| x.tan(), &[(0.5, 0.0), (-1.2, 0.0)]),
        (
            "tanh(X)",
            |x, _| x.tanh(),
            &[(0.5, 0.0), (-1.2, 0.0), (25.0, 0.0), (-300.0, 0.0)],
        ),
        ("arctan(X)", |x, _| x.atan(), &[(1.0, 0.0), (-30.0, 0.0)]),
        ("sqrt(X)", |x, _| x.sqrt(), &[(2.0, 0.0), (0.0, 0.0), (1e6, 0.0)]),
        (
            "rem(X, Y)",
            ieee_rem,
            &[
                (5.0, 2.0),
                (3.0, 2.0),
                (7.5, 2.0),
                (-7.0, 3.0),
                (10.0, 4.0),
                (11.0, 4.0),
            ],
        ),
        (
            "root(X, Y)",
            |x, y| x.powf(1.0 / y),
            &[(27.0, 3.0), (16.0, 4.0), (2.0, 2.0)],
        ),
        ("pow(X, Y)", |x, y| x.powf(y), &[(2.0, 10.0), (9.0, 0.5), (-2.0, 3.0)]),
        ("exp(X)", |x, _| x.exp(), &[(0.0, 0.0), (1.0, 0.0), (-3.5, 0.0)]),
        ("abs(X)", |x, _| x.abs(), &[(-3.25, 0.0), (2.0, 0.0)]),
        ("log(X)", |x, _| x.log10(), &[(1000.0, 0.0), (2.0, 0.0)]),
        (
            "log(X, Y)",
            |x, y| x.ln() / y.ln(),
            &[(8.0, 2.0), (100.0, 10.0), (5.0, 3.0)],
        ),
        ("ln(X)", |x, _| x.ln(), &[(10.0, 0.0)]),
        // .NET's Math.Round(x, MidpointRounding.AwayFromZero).
        (
            "round(X)",
            |x, _| x.round(),
            &[(2.5, 0.0), (-2.5, 0.0), (3.5, 0.0), (2.4, 0.0), (-0.5, 0.0), (7.0, 0.0)],
        ),
        ("truncate(X)", |x, _| x.trunc(), &[(2.7, 0.0), (-2.7, 0.0)]),
        ("floor(X)", |x, _| x.floor(), &[(2.7, 0.0), (-2.7, 0.0), (-3.0, 0.0)]),
        ("ceiling(X)", |x, _| x.ceil(), &[(2.2, 0.0), (-2.7, 0.0), (4.0, 0.0)]),
        (
            "sign(X)",
            |x, _| if x == 0.0 { 0.0 } else { x.signum() },
            &[(-0.5, 0.0), (0.0, 0.0), (12.0, 0.0)],
        ),
    ];
    let mut tags = String::new();
    let mut script = String::from("define{}\nfunction\n{\n");
    let mut names = Vec::new();
    let mut want = Vec::new();
    let mut k = 0;
    for (text, f, inputs) in cases {
        for &(x, y) in *inputs {
            // The inputs as REAL tags: the reference uses what the engine reads.
            let (x32, y32) = (x as f32 as f64, y as f32 as f64);
            tags.push_str(&format!("X{k},REAL,,{x},,\nY{k},REAL,,{y},,\nO{k},LREAL,,,,\n"));
            let e = text.replace('X', &format!("X{k}")).replace('Y', &format!("Y{k}"));
            script.push_str(&format!("    O{k} = {e};\n"));
            names.push(format!("O{k}"));
            want.push((format!("{text} of {x}, {y}"), f(x32, y32)));
            k += 1;
        }
    }
    script.push('}');
    let dir = project("functions", &tags, &script, "TRUE");
    let cols: Vec<&str> = names.iter().map(String::as_str).collect();
    let got = run(&dir, &cols);
    let wrong: Vec<String> = want
        .iter()
        .zip(&got)
        .filter(|((_, w), g)| !close(**g, *w))
        .map(|((what, w), g)| format!("{what}: want {w}, got {g}"))
        .collect();
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_sources_operators_and_precedence() {
    // (expression, its value with the source's precedence)
    let cases: &[(&str, f64)] = &[
        // `%` binds tighter than `*`: 2 * (7 % 4), where CPT's MOD gives 14 MOD 4 = 2.
        ("2 * 7 % 4", 6.0),
        ("7 % 4", 3.0),
        ("7.5 % 2", 1.5),
        // `:` divides, before `/`: (8 : 2) / 2, and 8 / (2 : 2).
        ("8 : 2 / 2", 2.0),
        ("8 / 2 : 2", 8.0),
        // As `/`: in the class of its operands (integers truncate).
        ("9 : 4", 2.0),
        ("9.0 : 4", 2.25),
        // `^` left to right, unary minus first.
        ("2 ^ 3 ^ 2", 64.0),
        ("-2 ^ 2", 4.0),
        ("2 ^ -1", 0.5),
        ("2 ** 3", 8.0),
        // `%` before `^`? No: `^` is tightest.
        ("2 ^ 3 % 5", 3.0),
        ("10 - 2 + 3", 11.0),
        ("10 - 4 - 3", 3.0),
        ("2 + 3 * 4", 14.0),
        ("A * 3 : 2", 7.5),
        ("cos(0) + sqrt(16) * 2", 9.0),
    ];
    let mut script = String::from("function\n{\n");
    let mut tags = String::from("A,REAL,,5,,\n");
    let mut names = Vec::new();
    for (k, (e, _)) in cases.iter().enumerate() {
        tags.push_str(&format!("O{k},LREAL,,,,\n"));
        script.push_str(&format!("    O{k} = {e};\n"));
        names.push(format!("O{k}"));
    }
    script.push('}');
    let dir = project("operators", &tags, &script, "TRUE");
    let cols: Vec<&str> = names.iter().map(String::as_str).collect();
    let got = run(&dir, &cols);
    for ((e, want), g) in cases.iter().zip(&got) {
        assert!(close(*g, *want), "{e}: want {want}, got {g}");
    }
}

#[test]
fn the_sources_guards_with_functions_and_logic_operators() {
    // The source's own condition examples (§2.2.3.7, §4.5.4.1): `|`, `&`,
    // `==`, `!=`, and a function in a guard. The token reaches `e` (Runs
    // counts) only while the guard holds.
    for (guard, a, b, passes) in [
        ("(A > 2) | (B < 3)", 1.0, 2.0, true),
        ("(A > 2) | (B < 3)", 1.0, 5.0, false),
        ("((A > 2) & (B > 3))", 3.0, 4.0, true),
        ("((A > 2) & (B > 3))", 3.0, 2.0, false),
        ("cos(A) > 0.5", 0.0, 0.0, true),
        ("cos(A) > 0.5", 3.0, 0.0, false),
        ("A == B", 2.0, 2.0, true),
        ("A != B", 2.0, 2.0, false),
        ("sqrt(A) + abs(B) >= 5 AND NOT (B = 0)", 9.0, -2.0, true),
    ] {
        let tags = format!("A,REAL,,{a},,\nB,REAL,,{b},,\nRuns,DINT,,,,\n");
        let dir = project("guards", &tags, "function{ Runs = Runs + 1 }", guard);
        let got = run(&dir, &["Runs"]);
        assert_eq!(got[0] > 0.0, passes, "{guard} with A={a}, B={b}: Runs = {}", got[0]);
    }
}

#[test]
fn domain_errors_give_alba_defined_results_and_a_minor_fault() {
    // (expression, result, fault code): not a number is 0 (code 3), ±∞ is
    // ±MAX (1), a division by zero saturates or gives 0 (2).
    let max = f32::MAX as f64;
    for (e, want, code) in [
        ("sqrt(X)", 0.0, 3),
        ("log(Z)", -max, 1),
        ("ln(X)", 0.0, 3),
        ("arcos(T)", 0.0, 3),
        ("arcsin(T)", 0.0, 3),
        ("pow(X, 0.5)", 0.0, 3),
        ("root(X, 2)", 0.0, 3),
        ("log(X, 2)", 0.0, 3),
        ("rem(5, Z)", 0.0, 2),
        ("7 % Z", 0.0, 2),
        ("1 : Z", max, 2),
        ("exp(1000)", max, 1),
        ("cosh(200)", max, 1),
    ] {
        let tags = "X,REAL,,-4,,\nZ,REAL,,0,,\nT,REAL,,2,,\nO,REAL,,,,\n";
        let dir = project("domain", tags, &format!("function{{ O = {e} }}"), "TRUE");
        let got = run(&dir, &["O", "S:MINOR", "S:FAULTCODE"]);
        assert!(close(got[0], want), "{e}: want {want}, got {}", got[0]);
        assert_eq!((got[1], got[2]), (1.0, code as f64), "{e}: the minor fault");
    }
}

/// AuroraLD's CPT (`000_…` Table 8, issue 34 point 2): QScript's names,
/// with their results, in every engine mode.
#[test]
fn cpt_takes_auroralds_names_with_their_results() {
    use crate::util::compile_text;
    let (x, n) = (2.5f32 as f64, -2.5f32 as f64);
    let cases: &[(&str, f64)] = &[
        ("log10(X)", x.log10()),
        ("logE(X)", x.ln()),
        ("log(X, 2)", x.ln() / 2f64.ln()),
        ("log(1000, 10)", 3.0),
        ("Int(X)", 2.0),
        ("Int(N)", -2.0),
        ("signum(N)", -1.0),
        ("signum(X)", 1.0),
        ("signum(X - X)", 0.0),
        ("cosh(X)", x.cosh()),
        ("sinh(N)", n.sinh()),
        ("tanh(N)", n.tanh()),
        ("radians(180)", std::f64::consts::PI),
        ("degrees(PI)", 180.0),
        ("sqrt(X * 4) + abs(N)", (x * 4.0).sqrt() + 2.5),
        ("atan2(1, 1) * 4", std::f64::consts::PI),
    ];
    let mut tags = String::from("name,type,address,initial,retain,description\nX,REAL,,2.5,,\nN,REAL,,-2.5,,\n");
    let mut lad = String::new();
    let mut names = Vec::new();
    for (k, (e, _)) in cases.iter().enumerate() {
        tags.push_str(&format!("O{k},REAL,,,,\n"));
        lad.push_str(&format!("CPT(O{k},{e});\n"));
        names.push(format!("O{k}"));
    }
    let program = compile_text(&tags, &lad).unwrap_or_else(|e| panic!("{e}"));
    let cols = names.join(",");
    let mut first: Option<String> = None;
    for mode in MODES {
        let t = simulate_in(mode, program.clone(), "", Some(&cols), (10, 0, 10));
        if let Some(f) = &first {
            assert_eq!(f, &t, "{mode:?} differs");
        }
        first = Some(t);
    }
    let trace = first.unwrap_or_default();
    let got: Vec<f64> = trace
        .lines()
        .last()
        .unwrap_or_default()
        .split(',')
        .skip(1)
        .map(|v| v.parse().unwrap_or(f64::NAN))
        .collect();
    for ((e, want), g) in cases.iter().zip(&got) {
        assert!(close(*g, *want), "CPT {e}: want {want}, got {g}");
    }
}

/// `rnd(a, b)`: a number from a to b, a new one each time the CPT runs, the
/// same sequence in every engine mode (a program's runs are repeatable).
#[test]
fn cpt_rnd_draws_in_its_range_and_repeats_across_modes() {
    use crate::util::compile_text;
    let tags = "name,type,address,initial,retain,description\nR,REAL,,,,\nS,REAL,,,,\nD,DINT,,,,\n";
    let program = compile_text(tags, "CPT(R,rnd(5, 10));\nCPT(S,rnd(-1, 1));\nCPT(D,rnd(0, 6));\n")
        .unwrap_or_else(|e| panic!("{e}"));
    let mut first: Option<String> = None;
    for mode in MODES {
        let t = simulate_in(mode, program.clone(), "", Some("R,S,D"), (10, 1990, 10));
        if let Some(f) = &first {
            assert_eq!(f, &t, "{mode:?} differs");
        }
        first = Some(t);
    }
    let trace = first.unwrap_or_default();
    let rows: Vec<Vec<f64>> = trace
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(1).map(|v| v.parse().unwrap_or(f64::NAN)).collect())
        .collect();
    assert_eq!(rows.len(), 200);
    let col = |k: usize| rows.iter().map(|r| r[k]).collect::<Vec<_>>();
    let (r, s, d) = (col(0), col(1), col(2));
    assert!(r.iter().all(|v| (5.0..=10.0).contains(v)), "{r:?}");
    assert!(s.iter().all(|v| (-1.0..=1.0).contains(v)), "{s:?}");
    assert!(d.iter().all(|v| (0.0..=6.0).contains(v) && v.fract() == 0.0), "{d:?}");
    // Spread over the range: both halves drawn, and few repeats.
    assert!(r.iter().any(|v| *v < 7.5) && r.iter().any(|v| *v > 7.5), "{r:?}");
    let mut distinct = r.clone();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    assert!(distinct.len() > 190, "{} distinct of 200", distinct.len());
    // The two calls have sequences of their own.
    assert_ne!(r.iter().map(|v| (v - 7.5) / 2.5).collect::<Vec<_>>(), s);
}

/// `[ladder] dialect = "aurorald"` (issue 34, point 5) against the Logix
/// default: LIM's upper bound (AuroraLD: low <= test < high), and the
/// square root of a negative (Logix: of its absolute value; AuroraLD: 0).
#[test]
fn the_aurorald_dialect_against_logix() {
    for (aurora, x) in [
        (false, 0),
        (false, 5),
        (false, 10),
        (false, 11),
        (true, 0),
        (true, 5),
        (true, 10),
        (true, 11),
    ] {
        let name = format!("dialect-{aurora}-{x}");
        let dir = std::env::temp_dir().join(format!("alba-seed-fn-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp dir");
        let w = |f: &str, t: &str| std::fs::write(dir.join(f), t).expect("write");
        let table = if aurora {
            "[ladder]\ndialect = \"aurorald\"\n"
        } else {
            ""
        };
        w(
            "alba.toml",
            &format!("name = \"{name}\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n{table}"),
        );
        let y = x as f64 + 0.5;
        w(
            "tags.csv",
            &format!(
                "name,type,address,initial,retain,description\nX,DINT,,{x},,\nY,REAL,,{y},,\nN,REAL,,-4,,\nInBand,BOOL,,,,\nInReal,BOOL,,,,\nR,REAL,,,,\nS,REAL,,,,\nP,REAL,,,,\n"
            ),
        );
        w(
            "main.lad",
            "LIM(0,X,10)OTE(InBand);\nLIM(0.5,Y,10.5)OTE(InReal);\nCPT(R,sqrt(N));\nSQR(N,S);\nCPT(P,SQRT(16)+sqrt(X));\n",
        );
        let got = run(&dir, &["InBand", "InReal", "R", "S", "P", "S:MINOR"]);
        let band = if aurora {
            (0..10).contains(&x)
        } else {
            (0..=10).contains(&x)
        };
        let root = if aurora { 0.0 } else { 2.0 };
        let want = [
            band as u8 as f64,
            band as u8 as f64,
            root,
            root,
            4.0 + (x as f64).sqrt(),
            0.0,
        ];
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            assert!(
                close(*g, w),
                "aurorald {aurora}, X = {x}: column {k} is {g}, want {w} ({got:?})"
            );
        }
    }
}
