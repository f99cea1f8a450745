//! A state net's Counter and State elements (issue 34, point 10; the `003_…`
//! seed): a token that goes round a loop through a counter changes its count
//! by one a visit, up or down from its load; a State with a `value` sets its
//! numeric tag to that constant while it has the token (the source's sets 1),
//! and 0 after — in every engine mode.

use crate::util::{MODES, compile, simulate_in};
use std::path::PathBuf;

/// A normal-mode loop S → go → c (a counter) → back → S: the token visits the
/// counter every fourth scan.
fn project(name: &str, props: &str) -> PathBuf {
    project_with(name, props, "", "")
}

/// As [`project`], with `state` inside S's Alba block and `tags` in tags.csv.
fn project_with(name: &str, props: &str, state: &str, tags: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("alba-net-counter-{}-{name}", std::process::id()));
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
    w(
        "n.pnml",
        &format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
  <net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">
    <toolspecific tool="alba" version="1"><mode>normal</mode></toolspecific>
    <page id="page0">
      <place id="S"><initialMarking><text>1</text></initialMarking><toolspecific tool="alba" version="1">{state}</toolspecific></place>
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
    column(dir, "n.c.count")
        .iter()
        .map(|v| v.parse().expect("a count"))
        .collect()
}

/// `tag` after each scan up to 150 ms, the same in every engine mode.
fn column(dir: &PathBuf, tag: &str) -> Vec<String> {
    let program = compile(dir);
    let mut first: Option<String> = None;
    for mode in MODES {
        let trace = simulate_in(mode, program.clone(), "", Some(tag), (10, 150, 10));
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
        .map(|l| l.split(',').nth(1).expect("a value").to_string())
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

#[test]
fn a_state_with_a_value_sets_its_tag_to_that_constant_while_it_has_the_token() {
    // S has the token at 0 ms, then every fourth scan (S → go → c → back → S)
    let dir = project_with(
        "state-dint",
        "",
        r#"<tag>Speed</tag><prop name="value">1500</prop>"#,
        "Speed,DINT,,,,\n",
    );
    let speed = column(&dir, "Speed");
    let marked = column(&project_with("state-marking", "", "", ""), "n.S");
    assert_eq!(speed.len(), 16);
    for (k, (v, m)) in speed.iter().zip(&marked).enumerate() {
        assert_eq!(v, if m == "1" { "1500" } else { "0" }, "scan {k}: {speed:?} {marked:?}");
    }
    assert!(speed.iter().filter(|v| *v == "1500").count() >= 3, "{speed:?}");
    // a REAL tag holds a REAL constant
    let level = column(
        &project_with(
            "state-real",
            "",
            r#"<tag>Level</tag><prop name="value">2.5</prop>"#,
            "Level,REAL,,,,\n",
        ),
        "Level",
    );
    let marked: Vec<bool> = column(&project_with("state-marking-2", "", "", ""), "n.S")
        .iter()
        .map(|m| m == "1")
        .collect();
    let want: Vec<&str> = marked.iter().map(|m| if *m { "2.5" } else { "0" }).collect();
    assert_eq!(level, want);
    assert!(want.contains(&"2.5"));
}

#[test]
fn a_state_value_needs_a_number_and_a_numeric_tag() {
    for (state, tags, says) in [
        (
            r#"<tag>Run</tag><prop name="value">5</prop>"#,
            "Run,BOOL,,,,\n",
            "not a number",
        ),
        (
            r#"<tag>Speed</tag><prop name="value">fast</prop>"#,
            "Speed,DINT,,,,\n",
            "is not a number",
        ),
        (r#"<prop name="value">5</prop>"#, "", "no `<tag>`"),
    ] {
        let dir = project_with("state-bad", "", state, tags);
        let c = alba_load::compile_dir(&dir);
        let _ = std::fs::remove_dir_all(&dir);
        assert!(c.program.is_none(), "{state}");
        assert!(
            c.diagnostics
                .iter()
                .any(|d| d.code == alba_diag::Code::NetPlaceTag && d.message.contains(says)),
            "{state}: {:?}",
            c.diagnostics
        );
    }
}
