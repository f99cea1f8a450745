//! `alba bench`'s Structured Text contender: the benchmark rung of
//! `bench.rs` written in ST, run by the interpreter and as native code
//! against the same hand-written Rust (numbers printed, never asserted).
//!
//! Each rung is five statements on its own tags and instances:
//!
//! ```text
//! r := NOT T_i.Q OR A_i;
//! T_i(IN := r, PT := T#5ms);
//! C_i(CU := r, PV := 30000);
//! Q_i := r AND C_i.CV > L_i;
//! IF Q_i THEN V_i := V_i + 1; END_IF;
//! ```
//! with `T_i : TON; C_i : CTU;` declared on one line of the PROGRAM's `VAR`
//! block, so a rung is six lines of text. The counter's preset is an INT in
//! ST (30 000 instead of the Ladder's 1 000 000): no rung reaches it, and
//! `C.DN` is not compared.

use crate::bench::{Race, SCAN_MS, native, native_rungs, place, preset, race};
use alba_diag::Files;
use alba_engine::Engine;
use alba_ir::Program;
use alba_model::{TagTable, Value};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

/// Lines of ST text per rung.
const LINES_PER_RUNG: usize = 6;

/// tags.csv and the ST program of `n` rungs.
pub fn generate(n: usize) -> (String, String) {
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let mut vars = String::from("PROGRAM Main\nVAR\n    r : BOOL;\n");
    let mut body = String::new();
    for i in 0..n {
        let a = u8::from(i % 11 == 0);
        tags.push_str(&format!(
            "A_{i},BOOL,,{a},,\nL_{i},DINT,,{},,\nV_{i},DINT,,,,\nQ_{i},BOOL,,,,\n",
            i % 5
        ));
        vars.push_str(&format!("    T_{i} : TON; C_{i} : CTU;\n"));
        body.push_str(&format!(
            "r := NOT T_{i}.Q OR A_{i};\nT_{i}(IN := r, PT := T#{}ms);\nC_{i}(CU := r, PV := 30000);\nQ_{i} := r AND C_{i}.CV > L_{i};\nIF Q_{i} THEN V_{i} := V_{i} + 1; END_IF;\n",
            preset(i)
        ));
    }
    vars.push_str("END_VAR\n");
    vars.push_str(&body);
    vars.push_str("END_PROGRAM\n");
    (tags, vars)
}

struct Built {
    program: Arc<Program>,
    lines: usize,
    parse_ms: f64,
    compile_ms: f64,
}

/// Parses, checks and compiles the ST program of `n` rungs, timing both.
fn build(n: usize) -> Result<Built, String> {
    let (tags_csv, st) = generate(n);
    let lines = st.lines().count();
    let mut files = Files::new();
    let tf = files.add("tags.csv", tags_csv);
    let sf = files.add("main.st", st);
    let t0 = Instant::now();
    let (mut tags, mut diags): (TagTable, _) = TagTable::parse(files.text(tf), tf);
    let (ast, d) = alba_st::parse(files.text(sf), sf);
    diags.extend(d);
    let parse_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t1 = Instant::now();
    alba_st::declare(&ast, &mut tags, &mut diags);
    let mut b = alba_ir::Builder::new(alba_ir::Layout::new(&tags, &Default::default()));
    diags.extend(alba_st::compile(&ast, "main.st", &mut b));
    if let Some(d) = diags.first() {
        return Err(format!("the generated ST program does not compile: {d}"));
    }
    let program = b.finish(files);
    program.verify().map_err(|e| e.to_string())?;
    let compile_ms = t1.elapsed().as_secs_f64() * 1e3;
    Ok(Built {
        program: Arc::new(program),
        lines,
        parse_ms,
        compile_ms,
    })
}

/// Runs the ST program (interpreted, or native with `native`) and the plain
/// Rust for `scans` scans from the start and compares every rung.
fn verify(p: &Arc<Program>, n: usize, scans: u64, native: bool) -> Result<(), String> {
    let mut e = Engine::new(p.clone()).map_err(|e| e.to_string())?;
    if native {
        e.compile_native().map_err(|e| e.to_string())?;
    }
    let mut rs = native_rungs(n);
    for k in 0..scans {
        e.scan(k * SCAN_MS).map_err(|m| m.message)?;
        native::scan(&mut rs, (k * SCAN_MS) as u32);
    }
    for (i, r) in rs.iter().enumerate() {
        let checks = [
            (format!("V_{i}"), Value::Dint(r.v)),
            (format!("Main.C_{i}.ACC"), Value::Dint(r.c_acc)),
            (format!("Main.T_{i}.ACC"), Value::Dint(r.t_acc)),
            (format!("Main.T_{i}.DN"), Value::Bool(r.t_dn)),
            (format!("Q_{i}"), Value::Bool(r.q)),
        ];
        for (name, want) in checks {
            let got = e.read(place(p, &name)?);
            if got != want {
                return Err(format!("{name}: ST {got}, plain Rust {want}"));
            }
        }
    }
    Ok(())
}

/// The ST contender at the benchmark's sizes and at the rung counts of a
/// 1 000-line and a 10 000-line program.
pub fn run(sizes: &[usize], quick: bool) -> ExitCode {
    let runs = if quick { 3 } else { 21 };
    println!("\nStructured Text: the same rung in ST (r := NOT T.Q OR A; T(IN := r, PT := T#5ms);");
    println!("C(CU := r, PV := 30000); Q := r AND C.CV > L; IF Q THEN V := V + 1; END_IF;), 6 lines per rung");
    println!(
        "{:>6} {:>6} | {:>7} {:>7} {:>6} | {:>11} {:>5} | {:>11} {:>5} | {:>9}",
        "rungs", "lines", "parse", "check+", "native", "interpreter", "ratio", "native code", "ratio", "plain Rust"
    );
    println!(
        "{:>6} {:>6} | {:>7} {:>7} {:>6} | {:>11} {:>5} | {:>11} {:>5} | {:>9}",
        "", "", "ms", "compile", "ms", "ns/rung", "", "ns/rung", "", "ns/rung"
    );
    let mut all: Vec<usize> = sizes.iter().map(|n| (*n).max(1)).collect();
    all.extend([1_000 / LINES_PER_RUNG, 10_000 / LINES_PER_RUNG]);
    all.sort_unstable();
    all.dedup();
    let mut bests = Vec::new();
    for n in all {
        let built = match build(n) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        let p = built.program.clone();
        if let Err(e) = verify(&p, n, 200, false).and_then(|()| verify(&p, n, 200, true)) {
            eprintln!("error: ST and plain Rust disagree at N = {n}: {e}");
            return ExitCode::FAILURE;
        }
        let Race {
            jit,
            jit_ms,
            per_rung: [engine_ns, jit_ns, native_ns],
            ratios: [engine_ratio, jit_ratio],
            best,
            ..
        } = match race(&p, n, runs, quick) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        bests.push(best);
        println!(
            "{:>6} {:>6} | {:>7.1} {:>7.1} {:>6.1} | {:>11.2} {:>5.2} | {:>11.2} {:>5.2} | {:>9.2}",
            n,
            built.lines,
            built.parse_ms,
            built.compile_ms,
            jit_ms,
            engine_ns,
            engine_ratio,
            jit_ns,
            jit_ratio,
            native_ns
        );
        if let Some((rungs, strided, functions)) = jit.native_layout() {
            println!("         native code: {functions} function(s), {strided} of {rungs} IR rungs in strided runs");
        }
    }
    println!("Best round of each contender:");
    println!(
        "{:>6} | {:>11} {:>5} | {:>11} {:>5} | {:>9}",
        "rungs", "interpreter", "ratio", "native code", "ratio", "plain Rust"
    );
    for b in &bests {
        println!("{b}");
    }
    println!("parse = tags.csv and ST text; check+compile = declare, check, lower to IR, verify.");
    ExitCode::SUCCESS
}
