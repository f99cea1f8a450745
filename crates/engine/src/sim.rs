//! Simulation in virtual time (SPEC §10.2): a stimulus file drives inputs,
//! a trace records chosen values.
//!
//! Scan k runs at t = k·scan_ms while t ≤ until. Each stimulus row is
//! applied before the first scan with t ≥ time_ms. A trace row is written
//! after the scan at t = 0 and after every scan whose t is a multiple of
//! `every`.

use crate::clock::{Clock, VirtualClock};
use crate::engine::{Engine, MajorFault};
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_ir::{Access, Layout, Place, Target};
use alba_model::{Value, csv};
use std::io::{self, Write};

/// One stimulus row, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct StimulusRow {
    pub time_ms: u64,
    pub place: Place,
    pub action: Action,
}

impl Stimulus {
    /// The rows as plain writes, or the first row that forces (the board's
    /// firmware has no forces).
    pub fn writes(&self) -> Result<Vec<(u64, Place, Value)>, &StimulusRow> {
        self.rows
            .iter()
            .map(|r| match r.action {
                Action::Set(v) => Ok((r.time_ms, r.place, v)),
                _ => Err(r),
            })
            .collect()
    }
}

/// What a stimulus row does: the value column holds a value (`1`), `force
/// VALUE` or `unforce`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Action {
    /// Writes the value (ignored while the place is forced).
    Set(Value),
    /// Forces the place: it keeps the value against every writer, plant
    /// models and plant programs included, until `unforce`.
    Force(Value),
    Unforce,
}

/// Rows in the order they apply (stable by time).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stimulus {
    pub rows: Vec<StimulusRow>,
}

impl Stimulus {
    /// Parses a stimulus CSV (`time_ms,tag,value`) against a layout,
    /// reporting every bad row.
    pub fn parse(text: &str, file: FileId, layout: &Layout) -> Result<Stimulus, Vec<Diagnostic>> {
        let sp = |r: &std::ops::Range<usize>| Span::new(file, r.clone());
        let (records, errors) = csv::read(text);
        let mut diags: Vec<Diagnostic> = errors
            .iter()
            .map(|e| Diagnostic::new(Code::CsvSyntax, e.message.clone(), sp(&e.span), "here"))
            .collect();
        let mut records = records.into_iter();
        let header_ok = |r: &csv::Record| {
            let names: Vec<String> = r.fields.iter().map(|f| f.text.trim().to_ascii_lowercase()).collect();
            names == ["time_ms", "tag", "value"]
        };
        match records.next() {
            Some(h) if header_ok(&h) => {}
            Some(h) => {
                diags.push(
                    Diagnostic::new(
                        Code::CsvHeader,
                        "the stimulus header must be `time_ms,tag,value`",
                        sp(&h.span),
                        "header",
                    )
                    .with_help("write the header `time_ms,tag,value` on the first line"),
                );
                return Err(diags);
            }
            None => {
                diags.push(Diagnostic::new(
                    Code::CsvHeader,
                    "the stimulus file is empty",
                    Span::new(file, 0..0),
                    "expected `time_ms,tag,value`",
                ));
                return Err(diags);
            }
        }
        let mut rows = Vec::new();
        for r in records {
            if r.fields.len() != 3 {
                let at = r.fields.get(3).map_or(r.end(), |f| f.span.clone());
                diags.push(Diagnostic::new(
                    Code::StimulusSyntax,
                    format!("a stimulus row has 3 fields, this one has {}", r.fields.len()),
                    sp(&at),
                    "expected time_ms,tag,value",
                ));
                continue;
            }
            let (t, name, val) = (&r.fields[0], &r.fields[1], &r.fields[2]);
            // `force VALUE`, `unforce` or a value.
            let word = val.text.trim();
            let (forcing, value_text) = match word.split_once(char::is_whitespace) {
                Some((w, rest)) if w.eq_ignore_ascii_case("force") => (true, Some(rest.trim())),
                _ if word.eq_ignore_ascii_case("unforce") => (true, None),
                _ => (false, Some(word)),
            };
            let time_ms = match t.text.trim().parse::<u64>() {
                Ok(v) => Some(v),
                Err(_) => {
                    diags.push(Diagnostic::new(
                        Code::StimulusSyntax,
                        format!("`{}` is not a time in milliseconds", t.text.trim()),
                        sp(&t.span),
                        "expected a non-negative integer",
                    ));
                    None
                }
            };
            let place = match layout.resolve(name.text.trim()) {
                Ok(Target::Value { place, .. }) if layout.is_output(place) && !forcing => {
                    diags.push(
                        Diagnostic::new(
                            Code::StimulusTarget,
                            format!("`{}` is an output, driven by the program", name.text.trim()),
                            sp(&name.span),
                            "output",
                        )
                        .with_help(
                            "a stimulus sets inputs (and internal tags); outputs come from the program \
                             (write `force 1` to force one)",
                        ),
                    );
                    None
                }
                Ok(Target::Value { place, access }) if access != Access::ReadOnly => Some(place),
                Ok(Target::Value { .. }) => {
                    diags.push(Diagnostic::new(
                        Code::StimulusTarget,
                        format!("`{}` is read-only and cannot be set by a stimulus", name.text.trim()),
                        sp(&name.span),
                        "read-only",
                    ));
                    None
                }
                Ok(_) => {
                    diags.push(Diagnostic::new(
                        Code::StimulusTarget,
                        format!(
                            "`{}` is a structure; set a member like {}.PRE",
                            name.text.trim(),
                            name.text.trim()
                        ),
                        sp(&name.span),
                        "structure",
                    ));
                    None
                }
                Err(e) => {
                    let mut d = Diagnostic::new(Code::StimulusTarget, e.to_string(), sp(&name.span), "cannot be set");
                    if let Some(s) = layout.tags.suggest(name.text.trim()) {
                        d = d.with_help(format!("did you mean `{s}`?"));
                    }
                    diags.push(d);
                    None
                }
            };
            let (Some(time_ms), Some(place)) = (time_ms, place) else {
                continue;
            };
            let Some(value_text) = value_text else {
                rows.push(StimulusRow {
                    time_ms,
                    place,
                    action: Action::Unforce,
                });
                continue;
            };
            match Value::parse(value_text, place.data_type()) {
                Ok(value) => rows.push(StimulusRow {
                    time_ms,
                    place,
                    action: if forcing {
                        Action::Force(value)
                    } else {
                        Action::Set(value)
                    },
                }),
                Err(m) => diags.push(Diagnostic::new(
                    Code::StimulusSyntax,
                    format!("bad value for `{}`: {m}", name.text.trim()),
                    sp(&val.span),
                    format!("expected {} value", place.data_type().with_article()),
                )),
            }
        }
        if !diags.is_empty() {
            return Err(diags);
        }
        rows.sort_by_key(|r| r.time_ms);
        Ok(Stimulus { rows })
    }
}

/// A traced column: the name as given and where its value lives.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    pub name: String,
    pub place: Place,
}

/// Resolves `--tags A,B.DN,DO:2/0`. Errors name the bad item.
pub fn columns(list: &str, layout: &Layout) -> Result<Vec<Column>, Vec<Diagnostic>> {
    let mut out = Vec::new();
    let mut diags = Vec::new();
    for name in list.split(',').map(str::trim) {
        if name.is_empty() {
            diags.push(Diagnostic::unplaced(
                Code::TraceName,
                "--tags has an empty name (two commas, or a comma at an end)",
            ));
            continue;
        }
        match layout.resolve(name) {
            Ok(Target::Value { place, .. }) => out.push(Column {
                name: name.to_string(),
                place,
            }),
            Ok(_) => diags.push(Diagnostic::unplaced(
                Code::TraceName,
                format!("--tags: `{name}` is a structure; name a member such as {name}.ACC or {name}.DN"),
            )),
            Err(e) => {
                let mut d = Diagnostic::unplaced(Code::TraceName, format!("--tags: {e}"));
                if let Some(s) = layout.tags.suggest(name) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                diags.push(d);
            }
        }
    }
    if diags.is_empty() { Ok(out) } else { Err(diags) }
}

/// Every tag, structures as their members, in tags.csv order.
pub fn all_columns(layout: &Layout) -> Vec<Column> {
    let mut out = Vec::new();
    for t in layout.tags.iter() {
        let names: Vec<String> = if t.ty.is_struct() {
            t.ty.members()
                .iter()
                .map(|m| format!("{}.{}", t.name, m.name))
                .collect()
        } else {
            vec![t.name.clone()]
        };
        for name in names {
            if let Ok(Target::Value { place, .. }) = layout.resolve(&name) {
                out.push(Column { name, place });
            }
        }
    }
    out
}

/// How long to simulate and how often to record.
#[derive(Debug, Clone, Copy)]
pub struct SimOptions {
    pub scan_ms: u64,
    pub until_ms: u64,
    pub every_ms: u64,
}

#[derive(Debug)]
pub enum SimError {
    Io(io::Error),
    Major(MajorFault),
}

impl From<io::Error> for SimError {
    fn from(e: io::Error) -> Self {
        SimError::Io(e)
    }
}

/// Runs the simulation, writing the trace CSV to `out`.
pub fn run(
    engine: &mut Engine,
    stimulus: &Stimulus,
    cols: &[Column],
    opt: SimOptions,
    out: &mut dyn Write,
) -> Result<(), SimError> {
    run_observed(engine, stimulus, cols, opt, out, &mut |_, _| {})
}

/// [`run`], calling `after_scan(t, engine)` after every scan (at virtual
/// time t): what evaluates alarms in `alba sim --alarms`.
pub fn run_observed(
    engine: &mut Engine,
    stimulus: &Stimulus,
    cols: &[Column],
    opt: SimOptions,
    out: &mut dyn Write,
    after_scan: &mut dyn FnMut(u64, &Engine),
) -> Result<(), SimError> {
    let mut line = String::from("time_ms");
    for c in cols {
        line.push(',');
        line.push_str(&csv_field(&c.name));
    }
    line.push('\n');
    out.write_all(line.as_bytes())?;
    let scan_ms = opt.scan_ms.max(1);
    let every = opt.every_ms.max(1);
    let mut next_row = 0;
    let mut clock = VirtualClock::new();
    while clock.now_ms() <= opt.until_ms {
        let t = clock.now_ms();
        engine.step_plants(t);
        while let Some(r) = stimulus.rows.get(next_row).filter(|r| r.time_ms <= t) {
            match r.action {
                Action::Set(v) => engine.write(r.place, v),
                Action::Force(v) => engine.force(r.place, v),
                Action::Unforce => engine.unforce(r.place),
            }
            next_row += 1;
        }
        engine.scan(t).map_err(SimError::Major)?;
        after_scan(t, engine);
        if t.is_multiple_of(every) {
            line.clear();
            line.push_str(&t.to_string());
            for c in cols {
                line.push(',');
                line.push_str(&engine.read(c.place).to_string());
            }
            line.push('\n');
            out.write_all(line.as_bytes())?;
        }
        clock.advance(scan_ms);
    }
    Ok(())
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
