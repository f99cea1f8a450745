//! Test tables (`tests/*.test.csv`, SPEC §10.6): a `time_ms` column, input
//! columns set before the first scan with t ≥ time_ms, and `expect:<Tag>`
//! columns checked at the end of that scan (a blank cell sets or checks
//! nothing). Runs on the engine with power-flow monitoring on, so the
//! tables' rung and instruction coverage comes with the results.

use alba_diag::{Code, Diagnostic, FileId, Files, Span};
use alba_engine::Engine;
use alba_ir::{Access, Layout, Place, Program, Target};
use alba_model::{Value, csv};
use std::sync::Arc;

/// One step of a table: what to set, then what to check, at scan time `time_ms`.
#[derive(Debug, Clone, PartialEq)]
struct Row {
    time_ms: u64,
    /// 1-based line of the row, for messages.
    line: usize,
    sets: Vec<(Place, Value)>,
    /// (column index into `Table::expects`, expected value).
    checks: Vec<(usize, Value)>,
}

/// A parsed test table.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The checked columns: tag name and place.
    expects: Vec<(String, Place)>,
    rows: Vec<Row>,
}

/// The first wrong cell of a failed table.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    pub line: usize,
    pub time_ms: u64,
    pub tag: String,
    pub expected: String,
    pub actual: String,
}

/// The result of one table.
#[derive(Debug, Clone, PartialEq)]
pub enum TestResult {
    Passed {
        checks: usize,
    },
    Failed(Mismatch),
    /// The table could not run (a bad file, a major fault).
    Error(String),
}

#[derive(Debug, Clone, PartialEq)]
pub struct TestCase {
    /// The file name without `.test.csv`.
    pub name: String,
    pub file: String,
    pub result: TestResult,
    pub scans: u64,
    pub millis: u128,
}

/// Parses a table against a layout, reporting every bad header or cell.
pub fn parse(text: &str, file: FileId, layout: &Layout) -> Result<Table, Vec<Diagnostic>> {
    let sp = |r: &std::ops::Range<usize>| Span::new(file, r.clone());
    let (records, errors) = csv::read(text);
    let mut diags: Vec<Diagnostic> = errors
        .iter()
        .map(|e| Diagnostic::new(Code::CsvSyntax, e.message.clone(), sp(&e.span), "here"))
        .collect();
    let mut records = records.into_iter();
    let Some(header) = records.next() else {
        diags.push(Diagnostic::new(
            Code::CsvHeader,
            "the test table is empty",
            Span::new(file, 0..0),
            "expected `time_ms,<input>...,expect:<tag>...`",
        ));
        return Err(diags);
    };
    enum Col {
        Set(Place),
        Expect(usize),
        Bad,
    }
    let mut cols = Vec::new();
    let mut expects = Vec::new();
    for (k, f) in header.fields.iter().enumerate() {
        let name = f.text.trim();
        if k == 0 {
            if !name.eq_ignore_ascii_case("time_ms") {
                diags.push(
                    Diagnostic::new(
                        Code::CsvHeader,
                        "a test table's first column is `time_ms`",
                        sp(&f.span),
                        "here",
                    )
                    .with_help("write `time_ms,Start,Stop,expect:Motor` on the first line"),
                );
                return Err(diags);
            }
            continue;
        }
        let (expect, tag) = match name.split_once(':') {
            Some((e, t)) if e.trim().eq_ignore_ascii_case("expect") => (true, t.trim()),
            _ => (false, name),
        };
        let col = match layout.resolve(tag) {
            Ok(Target::Value { place, .. }) if expect => {
                expects.push((tag.to_string(), place));
                Col::Expect(expects.len() - 1)
            }
            Ok(Target::Value { place, .. }) if layout.is_output(place) => {
                diags.push(
                    Diagnostic::new(
                        Code::StimulusTarget,
                        format!("`{tag}` is an output, driven by the program"),
                        sp(&f.span),
                        "output",
                    )
                    .with_help(format!("to check it, name the column `expect:{tag}`")),
                );
                Col::Bad
            }
            Ok(Target::Value { place, access }) if access != Access::ReadOnly => Col::Set(place),
            Ok(Target::Value { .. }) => {
                diags.push(Diagnostic::new(
                    Code::StimulusTarget,
                    format!("`{tag}` is read-only and cannot be set by a test"),
                    sp(&f.span),
                    "read-only",
                ));
                Col::Bad
            }
            Ok(_) => {
                diags.push(Diagnostic::new(
                    Code::StimulusTarget,
                    format!("`{tag}` is a structure; name a member such as {tag}.DN"),
                    sp(&f.span),
                    "structure",
                ));
                Col::Bad
            }
            Err(e) => {
                let mut d = Diagnostic::new(Code::UnknownTag, e.to_string(), sp(&f.span), "unknown");
                if let Some(s) = layout.tags.suggest(tag) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                diags.push(d);
                Col::Bad
            }
        };
        cols.push(col);
    }
    let mut rows = Vec::new();
    let mut last_time = 0;
    for r in records {
        let line = 1 + text[..r.span.start.min(text.len())].matches('\n').count();
        if r.fields.len() == 1 && r.fields[0].text.trim().is_empty() {
            continue;
        }
        if r.fields.len() != header.fields.len() {
            diags.push(Diagnostic::new(
                Code::StimulusSyntax,
                format!(
                    "this row has {} fields, the header {}",
                    r.fields.len(),
                    header.fields.len()
                ),
                sp(&r.end()),
                "here",
            ));
            continue;
        }
        let t = &r.fields[0];
        let time_ms = match t.text.trim().parse::<u64>() {
            Ok(v) if v >= last_time => v,
            Ok(_) => {
                diags.push(Diagnostic::new(
                    Code::StimulusSyntax,
                    "the rows of a test table go forward in time",
                    sp(&t.span),
                    "earlier than the row above",
                ));
                continue;
            }
            Err(_) => {
                diags.push(Diagnostic::new(
                    Code::StimulusSyntax,
                    format!("`{}` is not a time in milliseconds", t.text.trim()),
                    sp(&t.span),
                    "expected a non-negative integer",
                ));
                continue;
            }
        };
        last_time = time_ms;
        let mut row = Row {
            time_ms,
            line,
            sets: Vec::new(),
            checks: Vec::new(),
        };
        for (f, col) in r.fields[1..].iter().zip(&cols) {
            let cell = f.text.trim();
            if cell.is_empty() {
                continue;
            }
            let place = match col {
                Col::Set(p) => *p,
                Col::Expect(k) => expects[*k].1,
                Col::Bad => continue,
            };
            match Value::parse(cell, place.data_type()) {
                Ok(v) => match col {
                    Col::Set(p) => row.sets.push((*p, v)),
                    Col::Expect(k) => row.checks.push((*k, v)),
                    Col::Bad => {}
                },
                Err(m) => diags.push(Diagnostic::new(
                    Code::StimulusSyntax,
                    format!("bad value `{cell}`: {m}"),
                    sp(&f.span),
                    format!("expected {} value", place.data_type().with_article()),
                )),
            }
        }
        rows.push(row);
    }
    if diags.is_empty() {
        Ok(Table { expects, rows })
    } else {
        Err(diags)
    }
}

fn same(expected: Value, actual: Value) -> bool {
    match (expected, actual) {
        (Value::Real(_) | Value::Lreal(_), _) | (_, Value::Real(_) | Value::Lreal(_)) => {
            let (e, a) = (expected.as_f64(), actual.as_f64());
            (e - a).abs() <= 1e-6 * e.abs().max(1.0) || (e.is_nan() && a.is_nan())
        }
        _ => expected.as_i64() == actual.as_i64(),
    }
}

/// Which elements ever had power after them, and which ever had none.
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    on: Vec<bool>,
    off: Vec<bool>,
}

impl Coverage {
    pub fn new(program: &Program) -> Coverage {
        let n = program.elements.len();
        Coverage {
            on: vec![false; n],
            off: vec![false; n],
        }
    }

    /// Element `e` (an index into `Program::elements`): (ever energised,
    /// ever not) over the scans run so far; for an overlay on the ladder.
    pub fn element(&self, e: usize) -> Option<(bool, bool)> {
        Some((*self.on.get(e)?, *self.off.get(e)?))
    }

    fn record(&mut self, engine: &Engine) {
        if let Some(pf) = engine.power_flow() {
            for e in 0..self.on.len() {
                if pf.get(e as u32) {
                    self.on[e] = true;
                } else {
                    self.off[e] = true;
                }
            }
        }
    }

    /// The figures and the instructions never switched.
    pub fn report(&self, program: &Program) -> CoverageReport {
        let text = |e: usize| {
            let sp = program.elements[e].span;
            let t = program.files.text(sp.file);
            t.get(sp.start as usize..sp.end as usize).unwrap_or("").to_string()
        };
        let is_branch = |e: usize| text(e).trim_start().starts_with('[');
        let mut r = CoverageReport::default();
        // A rung carried power when its last instruction (in the source) did.
        for rung in 0..program.rungs.len() {
            let last = (0..program.elements.len())
                .filter(|&e| program.elements[e].rung as usize == rung && !is_branch(e))
                .max_by_key(|&e| program.elements[e].span.end);
            if let Some(e) = last {
                r.rungs += 1;
                if self.on[e] {
                    r.rungs_powered += 1;
                } else {
                    r.rungs_never.push(self.place(program, e));
                }
            }
        }
        for e in 0..program.elements.len() {
            if is_branch(e) {
                r.branches += 1;
                if self.on[e] {
                    r.branches_powered += 1;
                }
                continue;
            }
            r.instructions += 1;
            if self.on[e] && self.off[e] {
                r.switched += 1;
            } else {
                r.never_switched.push(format!(
                    "{} `{}` (always {})",
                    self.place(program, e),
                    text(e).trim(),
                    if self.on[e] { "energised" } else { "off" }
                ));
            }
        }
        r
    }

    fn place(&self, program: &Program, e: usize) -> String {
        let el = &program.elements[e];
        let (line, _) = program.files.line_col(el.span.file, el.span.start as usize);
        let rung = &program.rungs[el.rung as usize];
        let unit = program.units.get(rung.unit as usize).map_or("?", |u| u.name.as_str());
        format!("{unit} rung {} (line {line})", rung.number)
    }
}

/// Coverage figures (docs/verify.md "Coverage").
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CoverageReport {
    pub rungs: usize,
    pub rungs_powered: usize,
    pub rungs_never: Vec<String>,
    pub branches: usize,
    pub branches_powered: usize,
    pub instructions: usize,
    pub switched: usize,
    pub never_switched: Vec<String>,
}

impl std::fmt::Display for CoverageReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "coverage: {}/{} rungs carried power, {}/{} branches carried power, {}/{} instructions switched",
            self.rungs_powered, self.rungs, self.branches_powered, self.branches, self.switched, self.instructions
        )?;
        for r in &self.rungs_never {
            writeln!(f, "  rung never carried power: {r}")?;
        }
        for i in &self.never_switched {
            writeln!(f, "  never switched: {i}")?;
        }
        Ok(())
    }
}

/// The longest table, in scans (a day at 10 ms is 8 640 000).
pub const MAX_SCANS: u64 = 10_000_000;

/// Runs one table from a fresh start, recording coverage.
pub fn run(program: &Arc<Program>, scan_ms: u64, table: &Table, cov: &mut Coverage) -> (TestResult, u64) {
    let mut engine = match Engine::new(program.clone()) {
        Ok(e) => e,
        Err(e) => return (TestResult::Error(format!("the program does not load: {e}")), 0),
    };
    engine.set_monitor(true);
    let scan_ms = scan_ms.max(1);
    if let Some(last) = table.rows.last()
        && last.time_ms / scan_ms > MAX_SCANS
    {
        return (
            TestResult::Error(format!(
                "line {}: {} ms is more than {MAX_SCANS} scans of {scan_ms} ms; a table runs at most that long",
                last.line, last.time_ms
            )),
            0,
        );
    }
    let mut checks = 0;
    let mut next = 0;
    let mut scans = 0;
    let mut t = 0u64;
    while next < table.rows.len() {
        engine.step_plants(t);
        let first = next;
        while let Some(r) = table.rows.get(next).filter(|r| r.time_ms <= t) {
            for (p, v) in &r.sets {
                engine.write(*p, *v);
            }
            next += 1;
        }
        if let Err(m) = engine.scan(t) {
            return (
                TestResult::Error(format!("major fault at {t} ms: {}", m.message)),
                scans,
            );
        }
        scans += 1;
        cov.record(&engine);
        for r in &table.rows[first..next] {
            for (k, want) in &r.checks {
                let (tag, place) = &table.expects[*k];
                let got = engine.read(*place);
                checks += 1;
                if !same(*want, got) {
                    return (
                        TestResult::Failed(Mismatch {
                            line: r.line,
                            time_ms: r.time_ms,
                            tag: tag.clone(),
                            expected: want.to_string(),
                            actual: got.to_string(),
                        }),
                        scans,
                    );
                }
            }
        }
        t += scan_ms;
    }
    (TestResult::Passed { checks }, scans)
}

/// Runs every `tests/*.test.csv` of a compiled project, in name order.
pub fn run_dir(
    dir: &std::path::Path,
    program: &Arc<Program>,
    scan_ms: u64,
) -> Result<(Vec<TestCase>, Coverage), crate::TestsError> {
    let tests = dir.join("tests");
    let mut paths: Vec<_> = std::fs::read_dir(&tests)
        .map_err(|source| crate::TestsError::Unreadable {
            path: tests.clone(),
            source,
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.ends_with(".test.csv"))
        })
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(crate::TestsError::NoTables(tests));
    }
    let mut cov = Coverage::new(program);
    let mut out = Vec::new();
    for p in paths {
        let started = std::time::Instant::now();
        let file_name = p.file_name().and_then(|n| n.to_str()).unwrap_or("").to_string();
        let name = file_name.trim_end_matches(".test.csv").to_string();
        let shown = format!("tests/{file_name}");
        let (result, scans) = match std::fs::read(&p) {
            Err(e) => (TestResult::Error(format!("cannot read {shown}: {e}")), 0),
            Ok(bytes) => match String::from_utf8(bytes) {
                Err(_) => (TestResult::Error(format!("{shown} is not UTF-8 text")), 0),
                Ok(text) => {
                    let mut files = Files::new();
                    let f = files.add(shown.clone(), text);
                    match parse(files.text(f), f, &program.layout) {
                        Ok(table) => run(program, scan_ms, &table, &mut cov),
                        Err(d) => {
                            let msgs: Vec<String> = d
                                .iter()
                                .map(|d| match &d.primary {
                                    Some(l) => {
                                        let (line, col) = files.line_col(l.span.file, l.span.start as usize);
                                        format!("{shown}:{line}:{col}: {}", d.message)
                                    }
                                    None => d.message.clone(),
                                })
                                .collect();
                            (TestResult::Error(msgs.join("\n")), 0)
                        }
                    }
                }
            },
        };
        out.push(TestCase {
            name,
            file: shown,
            result,
            scans,
            millis: started.elapsed().as_millis(),
        });
    }
    Ok((out, cov))
}

fn xml_escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            c if (c as u32) < 0x20 && !matches!(c, '\n' | '\t' | '\r') => o.push(' '),
            c => o.push(c),
        }
    }
    o
}

/// The message naming a table's first wrong cell.
pub fn describe(m: &Mismatch) -> String {
    format!(
        "line {}, t = {} ms: expect:{} is {}, expected {}",
        m.line, m.time_ms, m.tag, m.actual, m.expected
    )
}

/// JUnit XML: one testsuite (the project), one testcase per table.
pub fn junit(project: &str, cases: &[TestCase]) -> String {
    let failures = cases
        .iter()
        .filter(|c| matches!(c.result, TestResult::Failed(_)))
        .count();
    let errors = cases
        .iter()
        .filter(|c| matches!(c.result, TestResult::Error(_)))
        .count();
    let total: u128 = cases.iter().map(|c| c.millis).sum();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str(&format!(
        "<testsuites name=\"alba test\" tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\">\n",
        cases.len()
    ));
    x.push_str(&format!(
        "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" time=\"{:.3}\">\n",
        xml_escape(project),
        cases.len(),
        total as f64 / 1000.0
    ));
    for c in cases {
        x.push_str(&format!(
            "    <testcase name=\"{}\" classname=\"{}\" file=\"{}\" time=\"{:.3}\"",
            xml_escape(&c.name),
            xml_escape(project),
            xml_escape(&c.file),
            c.millis as f64 / 1000.0
        ));
        match &c.result {
            TestResult::Passed { .. } => x.push_str("/>\n"),
            TestResult::Failed(m) => {
                let msg = describe(m);
                x.push_str(&format!(
                    ">\n      <failure message=\"{}\" type=\"mismatch\">{}</failure>\n    </testcase>\n",
                    xml_escape(&msg),
                    xml_escape(&msg)
                ));
            }
            TestResult::Error(e) => {
                let first = e.lines().next().unwrap_or("");
                x.push_str(&format!(
                    ">\n      <error message=\"{}\" type=\"error\">{}</error>\n    </testcase>\n",
                    xml_escape(first),
                    xml_escape(e)
                ));
            }
        }
    }
    x.push_str("  </testsuite>\n</testsuites>\n");
    x
}
