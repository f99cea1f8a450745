//! Helpers shared by the engine's integration tests.

use alba_diag::Files;
use alba_engine::Engine;
use alba_engine::sim::{self, Column, SimOptions, Stimulus};
use alba_ir::Program;
use std::path::Path;
use std::sync::Arc;

/// Compiles a project folder, panicking with rendered diagnostics on errors.
pub fn compile(dir: &Path) -> Program {
    let c = alba_load::compile_dir(dir);
    match c.program {
        Some(p) => p,
        None => panic!(
            "{} does not compile:\n{}",
            dir.display(),
            alba_diag::render_all(&c.diagnostics, &c.project.files)
        ),
    }
}

/// Compiles ladder text and tags given inline (a project without files).
pub fn compile_text(tags_csv: &str, ladder: &str) -> Result<Program, String> {
    let mut files = Files::new();
    let tf = files.add("tags.csv", tags_csv);
    let lf = files.add("main.lad", ladder);
    let (tags, d1) = alba_model::TagTable::parse(files.text(tf), tf);
    let (ast, d2) = alba_ladder::parse(files.text(lf), lf);
    let layout = alba_ladder::layout_for(&tags, &[&ast]);
    let mut b = alba_ir::Builder::new(layout);
    let d3 = alba_ladder::compile(
        &ast,
        files.text(lf),
        "main.lad",
        &mut b,
        &mut alba_ladder::Presets::default(),
    );
    let all: Vec<_> = d1.into_iter().chain(d2).chain(d3).collect();
    if !all.is_empty() {
        return Err(alba_diag::render_all(&all, &files));
    }
    Ok(b.finish(files))
}

/// How the engine runs a program: all must give the same results.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Fused interpreter code (unmonitored scans).
    Fused,
    /// One op per instruction, recording power flow.
    Monitored,
    /// Machine code (the interpreter where the `jit` feature is off).
    Native,
}

pub const MODES: [Mode; 3] = [Mode::Fused, Mode::Monitored, Mode::Native];

/// Runs a simulation (fused code) and returns the trace text.
pub fn simulate(program: Program, stimulus: &str, tags: Option<&str>, scan_ms: u64, until: u64, every: u64) -> String {
    simulate_in(Mode::Fused, program, stimulus, tags, (scan_ms, until, every))
}

/// Runs a simulation in one mode; `times` is (scan_ms, until, every).
pub fn simulate_in(mode: Mode, program: Program, stimulus: &str, tags: Option<&str>, times: (u64, u64, u64)) -> String {
    let (scan_ms, until, every) = times;
    let mut files = Files::new();
    let f = files.add("stimulus.csv", stimulus);
    let stim = if stimulus.trim().is_empty() {
        Stimulus::default()
    } else {
        match Stimulus::parse(files.text(f), f, &program.layout) {
            Ok(s) => s,
            Err(d) => panic!("bad stimulus:\n{}", alba_diag::render_all(&d, &files)),
        }
    };
    let cols: Vec<Column> = match tags {
        Some(t) => sim::columns(t, &program.layout).unwrap_or_else(|d| panic!("bad --tags: {}", d[0])),
        None => sim::all_columns(&program.layout),
    };
    let mut engine = Engine::new(Arc::new(program)).expect("program verifies");
    match mode {
        Mode::Fused => {}
        Mode::Monitored => engine.set_monitor(true),
        Mode::Native => {
            if cfg!(feature = "jit") {
                engine.compile_native().expect("native code");
            }
        }
    }
    let mut out = Vec::new();
    let opt = SimOptions {
        scan_ms,
        until_ms: until,
        every_ms: every,
    };
    sim::run(&mut engine, &stim, &cols, opt, &mut out).expect("simulation runs");
    String::from_utf8(out).expect("utf-8 trace")
}

/// A value compared bit for bit: two engines that both compute a NaN agree
/// (`Value`'s `PartialEq` says NaN != NaN), and -0.0 differs from 0.0.
#[derive(Clone, Copy)]
pub struct Exact(pub alba_model::Value);

impl PartialEq for Exact {
    fn eq(&self, other: &Self) -> bool {
        use alba_model::Value::{Lreal, Real};
        match (self.0, other.0) {
            (Real(a), Real(b)) => a.to_bits() == b.to_bits(),
            (Lreal(a), Lreal(b)) => a.to_bits() == b.to_bits(),
            (a, b) => a == b,
        }
    }
}

impl std::fmt::Debug for Exact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// Every observable value: tags (structures by member), I/O images, marker
/// bytes and system tags; not the compiler's scratch slots.
pub fn observable(e: &Engine) -> Vec<(String, Exact)> {
    let p = e.program();
    let mut out: Vec<_> = sim::all_columns(&p.layout)
        .into_iter()
        .map(|c| (c.name, e.read(c.place)))
        .collect();
    let l = &p.layout;
    let m = e.memory();
    out.extend((0..l.di.len).map(|n| (format!("DI{n}"), alba_model::Value::Bool(m.b[(l.di.base + n) as usize]))));
    out.extend((0..l.dout.len).map(|n| {
        (
            format!("DO{n}"),
            alba_model::Value::Bool(m.b[(l.dout.base + n) as usize]),
        )
    }));
    out.extend(
        m.m.iter()
            .enumerate()
            .map(|(k, b)| (format!("MB{k}"), alba_model::Value::Sint(*b as i8))),
    );
    for s in ["S:FS", "S:MINOR", "S:FAULTCODE"] {
        if let Ok(alba_ir::Target::Value { place, .. }) = l.resolve(s) {
            out.push((s.to_string(), e.read(place)));
        }
    }
    out.into_iter().map(|(n, v)| (n, Exact(v))).collect()
}
