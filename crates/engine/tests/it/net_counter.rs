//! A state net's Counter element in both directions (issue 34, point 10; the
//! `003_…` seed's counter counts up or down from its load): a token that goes
//! round a loop through the counter changes its count by one a visit, in every
//! engine mode.

use crate::util::{MODES, compile, simulate_in};
use std::path::PathBuf;

/// A normal-mode loop S → go → c (a counter) → back → S: the token visits the
/// counter every fourth scan.
fn project(name: &str, props: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-net-counter-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let w = |f: &str, t: &str| std::fs::write(dir.join(f), t).expect("write");
    w(
        "alba.toml",
        &format!("name = \"{name}\"\nscan_ms = 10\nprograms = [\"n.pnml\"]\n"),
    );
    w("tags.csv", "name,type,address,initial,retain,description\n");
    w(
        "n.pnml",
        &format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
  <net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">
    <toolspecific tool="alba" version="1"><mode>normal</mode></toolspecific>
    <page id="page0">
      <place id="S"><initialMarking><text>1</text></initialMarking></place>
      <transition id="go"/>
      <place id="c"><toolspecific tool="alba" version="1"><kind>counter</kind>{props}</toolspecific></place>
      <transition id="back"/>
      <arc id="a1" source="S" target="go"/>
      <arc id="a2" source="go" target="c"/>
      <arc id="a3" source="c" target="back"/>
      <arc id="a4" source="back" target="S"/>
    </page>
  </net>
</pnml>
"#
        ),
    );
    dir
}

/// The count after each scan up to 150 ms, the same in every engine mode.
fn counts(dir: &PathBuf) -> Vec<i64> {
    let program = compile(dir);
    let mut first: Option<String> = None;
    for mode in MODES {
        let trace = simulate_in(mode, program.clone(), "", Some("n.c.count"), (10, 150, 10));
        if let Some(f) = &first {
            assert_eq!(f, &trace, "{mode:?} differs");
        }
        first = Some(trace);
    }
    let _ = std::fs::remove_dir_all(dir);
    first
        .unwrap_or_default()
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).and_then(|v| v.parse().ok()).expect("a count"))
        .collect()
}

/// The distinct counts in order (each visit changes the count once).
fn steps(c: &[i64]) -> Vec<i64> {
    let mut out: Vec<i64> = Vec::new();
    for &v in c {
        if out.last() != Some(&v) {
            out.push(v);
        }
    }
    out
}

#[test]
fn a_counter_counts_down_from_its_load_one_a_visit() {
    let c = counts(&project(
        "down",
        r#"<prop name="load">10</prop><prop name="direction">down</prop>"#,
    ));
    assert_eq!(c.len(), 16, "{c:?}");
    assert_eq!(c[0], 10, "the load, before the first visit: {c:?}");
    assert_eq!(steps(&c), [10, 9, 8, 7, 6], "{c:?}");
    // the source's own word for it counts down too
    let c2 = counts(&project(
        "counterdown",
        r#"<prop name="load">10</prop><prop name="direction">CounterDown</prop>"#,
    ));
    assert_eq!(c2, c);
}

#[test]
fn a_counter_counts_up_by_default_and_past_zero_down() {
    let up = counts(&project("up", r#"<prop name="load">2</prop>"#));
    assert_eq!(steps(&up), [2, 3, 4, 5, 6], "{up:?}");
    // down from 1: on below zero (the count is a DINT, as the source's)
    let down = counts(&project(
        "below",
        r#"<prop name="load">1</prop><prop name="direction">down</prop>"#,
    ));
    assert_eq!(steps(&down), [1, 0, -1, -2, -3], "{down:?}");
}
