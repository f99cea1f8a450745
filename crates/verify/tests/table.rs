//! Test tables: checks, the first wrong cell, coverage figures on a known
//! program, and JUnit XML read back by an XML parser.

mod common;

use alba_diag::Files;
use alba_verify::table::{self, Coverage, TestResult};
use common::*;
use quick_xml::events::Event;

const TAGS: &str = "\
Start,BOOL,DI:1/0,,,
Stop,BOOL,DI:1/1,,,
Motor,BOOL,DO:2/0,,,
Lamp,BOOL,DO:2/1,,,
Delay,TIMER,,,,
";
/// examples/start-stop: 3 rungs, 1 branch, 8 instructions.
const LAD: &str = "\
[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);
XIC(Motor)TON(Delay,5000,0);
XIC(Delay.DN)OTE(Lamp);
";

fn run(text: &str, cov: &mut Coverage) -> TestResult {
    let program = compile(TAGS, LAD);
    let mut files = Files::new();
    let f = files.add("t.test.csv", text.to_string());
    let t = table::parse(files.text(f), f, &program.layout).unwrap_or_else(|d| panic!("{d:?}"));
    table::run(&program, SCAN_MS, &t, cov).0
}

#[test]
fn a_table_passes_and_its_coverage_is_counted() {
    let program = compile(TAGS, LAD);
    let mut cov = Coverage::new(&program);
    let r = run(
        "time_ms,Start,expect:Motor,expect:Lamp\n0,0,0,0\n100,1,1,\n200,0,1,0\n",
        &mut cov,
    );
    assert_eq!(r, TestResult::Passed { checks: 5 });
    let rep = cov.report(&program);
    // The lamp's rung never had power; its two instructions never switched.
    assert_eq!((rep.rungs_powered, rep.rungs), (2, 3), "{rep}");
    assert_eq!((rep.branches_powered, rep.branches), (1, 1), "{rep}");
    assert_eq!((rep.switched, rep.instructions), (6, 8), "{rep}");
    assert_eq!(rep.never_switched.len(), 2, "{rep}");
    assert!(
        rep.never_switched[0].contains("XIC(Delay.DN)") && rep.never_switched[0].contains("always off"),
        "{rep}"
    );
    assert!(rep.rungs_never[0].contains("rung 2"), "{rep}");
    // Per element, for the ladder's overlay: the lamp's coil was never on.
    let last = program.elements.len() - 1;
    assert_eq!(cov.element(last), Some((false, true)));
    assert_eq!(cov.element(last + 1), None);

    // A longer table lights the lamp and presses Stop: everything switches.
    let r = run(
        "time_ms,Start,Stop,expect:Motor,expect:Lamp\n0,0,0,0,0\n100,1,,1,0\n200,0,,1,0\n5090,,,1,0\n5100,,,1,1\n6000,,1,0,0\n6100,,0,0,0\n",
        &mut cov,
    );
    assert!(matches!(r, TestResult::Passed { .. }), "{r:?}");
    let rep = cov.report(&program);
    assert_eq!((rep.rungs_powered, rep.switched, rep.instructions), (3, 8, 8), "{rep}");
}

#[test]
fn a_failure_names_the_first_wrong_cell() {
    let program = compile(TAGS, LAD);
    let mut cov = Coverage::new(&program);
    let r = run(
        "time_ms,Start,expect:Motor,expect:Lamp\n0,0,0,0\n100,1,1,1\n200,0,0,1\n",
        &mut cov,
    );
    let TestResult::Failed(m) = r else { panic!("{r:?}") };
    assert_eq!((m.line, m.time_ms, m.tag.as_str()), (3, 100, "Lamp"));
    assert_eq!((m.expected.as_str(), m.actual.as_str()), ("1", "0"));
    assert_eq!(table::describe(&m), "line 3, t = 100 ms: expect:Lamp is 0, expected 1");
}

#[test]
fn rows_apply_before_the_first_scan_at_or_after_their_time() {
    let program = compile(TAGS, LAD);
    let mut cov = Coverage::new(&program);
    // 105 ms falls between scans: the row applies to the scan at 110 ms and
    // its check is made at the end of that scan, the timer's first; 125 ms
    // is the scan at 130 ms, 20 ms of timing later.
    let r = run(
        "time_ms,Start,expect:Motor,expect:Delay.ACC\n105,1,1,0\n125,0,1,20\n",
        &mut cov,
    );
    assert!(matches!(r, TestResult::Passed { checks: 4 }), "{r:?}");
}

#[test]
fn a_table_too_long_is_refused_not_run() {
    let program = compile(TAGS, LAD);
    let mut cov = Coverage::new(&program);
    let r = run("time_ms,Start\n0,1\n999999999999,0\n", &mut cov);
    let TestResult::Error(e) = r else { panic!("{r:?}") };
    assert!(e.starts_with("line 3:") && e.contains("10000000 scans"), "{e}");
}

#[test]
fn bad_tables_are_refused_with_their_place() {
    let program = compile(TAGS, LAD);
    let mut files = Files::new();
    for (text, needle) in [
        ("", "empty"),
        ("t,Start\n", "first column"),
        ("time_ms,Motor\n0,1\n", "output"),
        ("time_ms,Nope\n0,1\n", "Nope"),
        ("time_ms,Start\nx,1\n", "not a time"),
        ("time_ms,Start\n0,2\n", "bad value"),
        ("time_ms,Start\n10,1\n0,1\n", "forward in time"),
        ("time_ms,Start\n0,1,1\n", "fields"),
        ("time_ms,expect:Delay\n0,1\n", "structure"),
    ] {
        let f = files.add("t.test.csv", text.to_string());
        let d = table::parse(files.text(f), f, &program.layout).expect_err(text);
        assert!(d.iter().any(|d| d.message.contains(needle)), "{text:?}: {d:?}");
    }
}

#[test]
fn junit_has_one_testcase_per_table_and_parses() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), TAGS, LAD);
    std::fs::create_dir(dir.path().join("tests")).expect("tests");
    std::fs::write(
        dir.path().join("tests/start.test.csv"),
        "time_ms,Start,expect:Motor\n0,1,1\n10,0,1\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("tests/lamp.test.csv"),
        "time_ms,Start,expect:Lamp\n0,1,1\n",
    )
    .expect("write");
    std::fs::write(dir.path().join("tests/broken.test.csv"), "time_ms,Nope\n0,1\n").expect("write");
    std::fs::write(dir.path().join("tests/notes.csv"), "not a table").expect("write");
    let c = alba_load::compile_dir(dir.path());
    let program = std::sync::Arc::new(c.program.expect("compiles"));
    let (cases, _) = table::run_dir(dir.path(), &program, SCAN_MS).expect("runs");
    let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["broken", "lamp", "start"]);
    let xml = table::junit("t & <co>", &cases);
    // Read it back with a real XML parser.
    let mut reader = quick_xml::Reader::from_str(&xml);
    let (mut testcases, mut failures, mut errors) = (Vec::new(), Vec::new(), 0);
    let mut suite = String::new();
    loop {
        match reader.read_event().expect("well-formed XML") {
            Event::Eof => break,
            Event::Start(e) | Event::Empty(e) => {
                let attr = |k: &str| {
                    e.try_get_attribute(k)
                        .expect("attribute")
                        .map(|a| a.unescape_value().expect("value").into_owned())
                };
                match e.name().as_ref() {
                    b"testcase" => testcases.push(attr("name").expect("name")),
                    b"failure" => failures.push(attr("message").expect("message")),
                    b"error" => errors += 1,
                    b"testsuite" => suite = attr("name").expect("suite name"),
                    _ => {}
                }
            }
            _ => {}
        }
    }
    assert_eq!(suite, "t & <co>");
    assert_eq!(testcases, ["broken", "lamp", "start"]);
    assert_eq!(failures, ["line 2, t = 0 ms: expect:Lamp is 0, expected 1"]);
    assert_eq!(errors, 1);
}
