//! A stimulus (a counterexample or a witness) replayed scan by scan as
//! `alba sim` replays it, keeping what the studio shows at each scan: the
//! value of every tag and which program elements carried power.

use crate::ReplayError;
use alba_diag::Files;
use alba_engine::Engine;
use alba_engine::sim::{Action, Stimulus};
use alba_ir::{Place, Program, Target};
use std::sync::Arc;

/// Tags shown at most (the stimulus's own tags always are).
pub const MAX_TAGS: usize = 200;
/// Scans replayed at most (the explorer's deepest search is a million).
pub const MAX_SCANS: u32 = 2_000_000;
/// Scans kept at most: the last ones, where the violation is.
pub const KEEP_SCANS: u32 = 2_000;

/// One scan of a replay.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceScan {
    /// The scan's time (scan `k` runs at `k × scan_ms`).
    pub time_ms: u64,
    /// Parallel to [`Trace::tags`], as `alba sim` prints values.
    pub values: Vec<String>,
    /// Indices into `Program::elements` energised at the end of the scan.
    pub on: Vec<u32>,
}

/// A replay: the tags shown and the scans kept (the last [`KEEP_SCANS`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    pub tags: Vec<String>,
    /// The number (0-based) of the first scan kept.
    pub first: u32,
    pub scans: Vec<TraceScan>,
}

/// The stimulus's rows (`time_ms,tag,value`), as written.
pub fn rows(text: &str) -> Vec<(u64, String, String)> {
    let (records, _) = alba_model::csv::read(text);
    records
        .into_iter()
        .skip(1)
        .filter_map(|r| {
            let f: Vec<String> = r.fields.iter().map(|f| f.text.trim().to_string()).collect();
            Some((f.first()?.parse().ok()?, f.get(1)?.clone(), f.get(2)?.clone()))
        })
        .collect()
}

/// Replays `text` (a stimulus CSV) for `scans` scans of `scan_ms`, keeping
/// the last [`KEEP_SCANS`] of them.
pub fn trace(program: &Arc<Program>, scan_ms: u64, text: &str, scans: u32) -> Result<Trace, ReplayError> {
    if scans > MAX_SCANS {
        return Err(ReplayError::TooLong { scans, max: MAX_SCANS });
    }
    let layout = &program.layout;
    let mut files = Files::new();
    let f = files.add("stimulus.csv".to_string(), text.to_string());
    let stim = Stimulus::parse(files.text(f), f, layout).map_err(|d| {
        let d = &d[0];
        ReplayError::Stimulus(match &d.primary {
            Some(l) => {
                let (line, col) = files.line_col(l.span.file, l.span.start as usize);
                format!("the stimulus, line {line}, column {col}: {}", d.message)
            }
            None => format!("the stimulus: {}", d.message),
        })
    })?;
    // The stimulus's tags first, then the program's other plain tags.
    let mut shown: Vec<(String, Place)> = Vec::new();
    let mut add = |name: &str| {
        if shown.len() < MAX_TAGS
            && !shown.iter().any(|(n, _)| n.eq_ignore_ascii_case(name))
            && let Ok(Target::Value { place, .. }) = layout.resolve(name)
        {
            shown.push((name.to_string(), place));
        }
    };
    for (_, tag, _) in rows(text) {
        add(&tag);
    }
    for t in layout.tags.iter() {
        add(&t.name);
    }
    let mut engine = Engine::new(program.clone()).map_err(ReplayError::Program)?;
    engine.set_monitor(true);
    let scan_ms = scan_ms.max(1);
    let mut next = 0;
    let first = scans.saturating_sub(KEEP_SCANS);
    let mut out = Vec::with_capacity((scans - first) as usize);
    for k in 0..u64::from(scans) {
        let t = k * scan_ms;
        engine.step_plants(t);
        while let Some(r) = stim.rows.get(next).filter(|r| r.time_ms <= t) {
            match r.action {
                Action::Set(v) => engine.write(r.place, v),
                Action::Force(_) | Action::Unforce => {
                    return Err(ReplayError::Forces);
                }
            }
            next += 1;
        }
        engine.scan(t).map_err(|m| ReplayError::FaultAt {
            t_ms: t,
            message: m.message,
        })?;
        if k < u64::from(first) {
            continue;
        }
        let on = match engine.power_flow() {
            Some(pf) => (0..program.elements.len() as u32).filter(|e| pf.get(*e)).collect(),
            None => Vec::new(),
        };
        out.push(TraceScan {
            time_ms: t,
            values: shown.iter().map(|(_, p)| engine.read(*p).to_string()).collect(),
            on,
        });
    }
    Ok(Trace {
        tags: shown.into_iter().map(|(n, _)| n).collect(),
        first,
        scans: out,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compile(ladder: &str, tags: &str) -> Arc<Program> {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path();
        std::fs::write(
            d.join("alba.toml"),
            "name = \"t\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
        )
        .unwrap();
        std::fs::write(
            d.join("tags.csv"),
            format!("name,type,address,initial,retain,description\n{tags}"),
        )
        .unwrap();
        std::fs::write(d.join("main.lad"), ladder).unwrap();
        let c = alba_load::compile_dir(d);
        let msgs: Vec<String> = c.diagnostics.iter().map(|d| d.message.clone()).collect();
        Arc::new(c.program.unwrap_or_else(|| panic!("{msgs:?}")))
    }

    #[test]
    fn a_replay_shows_values_and_power_scan_by_scan() {
        let p = compile(
            "XIC(Start)OTE(Motor);\n",
            "Start,BOOL,DI:1/0,,,\nMotor,BOOL,DO:2/0,,,\n",
        );
        let t = trace(&p, 10, "time_ms,tag,value\n20,Start,1\n", 4).unwrap();
        assert_eq!(t.tags, ["Start", "Motor"]);
        let motor: Vec<&str> = t.scans.iter().map(|s| s.values[1].as_str()).collect();
        assert_eq!(motor, ["0", "0", "1", "1"]);
        assert_eq!(t.scans[2].time_ms, 20);
        assert!(t.scans[1].on.is_empty());
        assert_eq!(t.scans[3].on.len(), p.elements.len());
    }

    #[test]
    fn a_bad_stimulus_is_an_error_naming_the_line() {
        let p = compile("XIC(A)OTE(B);\n", "A,BOOL,DI:1/0,,,\nB,BOOL,DO:2/0,,,\n");
        let e = trace(&p, 10, "time_ms,tag,value\n0,Nope,1\n", 2).unwrap_err();
        assert!(matches!(&e, ReplayError::Stimulus(m) if m.contains("line 2")), "{e}");
        assert_eq!(
            trace(&p, 10, "time_ms,tag,value\n", MAX_SCANS + 1).unwrap_err(),
            ReplayError::TooLong {
                scans: MAX_SCANS + 1,
                max: MAX_SCANS
            }
        );
    }

    #[test]
    fn a_long_replay_keeps_its_last_scans() {
        let p = compile("XIC(A)OTE(B);\n", "A,BOOL,DI:1/0,,,\nB,BOOL,DO:2/0,,,\n");
        let n = KEEP_SCANS + 500;
        let t = trace(
            &p,
            10,
            &format!("time_ms,tag,value\n{},A,1\n", u64::from(n - 1) * 10),
            n,
        )
        .unwrap();
        assert_eq!(t.first, 500);
        assert_eq!(t.scans.len(), KEEP_SCANS as usize);
        assert_eq!(t.scans[0].time_ms, 5000);
        let last = t.scans.last().unwrap();
        assert_eq!((last.time_ms, last.values[1].as_str()), (u64::from(n - 1) * 10, "1"));
        assert_eq!(t.scans[KEEP_SCANS as usize - 2].values[1], "0");
    }
}
