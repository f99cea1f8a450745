//! `alba bench`: the engine against plain optimised Rust on generated
//! ladder programs (numbers printed, never asserted).
//!
//! Each rung has two contacts in a branch, a TON, a CTU, a compare, an ADD
//! and an OTE, on its own tags:
//!
//! ```text
//! [XIO(T_i.DN),XIC(A_i)]TON(T_i,P_i,0)CTU(C_i,1000000,0)GRT(C_i.ACC,L_i)ADD(V_i,1,V_i)OTE(Q_i);
//! ```
//! The timer restarts itself when done (a pulse generator), the counter
//! counts its pulses, and the rest of the rung acts once the count passes a
//! limit. The native baseline runs the same logic on an array of structs;
//! before timing, both run from the same start and their results are
//! compared tag by tag.

use alba_diag::Files;
use alba_engine::Engine;
use alba_ir::{Place, Program, Target};
use alba_model::{TagTable, Value};
use std::hint::black_box;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

/// Scan period of the benchmark, in virtual milliseconds.
pub(crate) const SCAN_MS: u64 = 1;

pub fn generate(n: usize) -> (String, String) {
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let mut lad = String::new();
    for i in 0..n {
        let a = u8::from(i % 11 == 0);
        tags.push_str(&format!(
            "A_{i},BOOL,,{a},,\nT_{i},TIMER,,,,\nC_{i},COUNTER,,,,\nL_{i},DINT,,{},,\nV_{i},DINT,,,,\nQ_{i},BOOL,,,,\n",
            i % 5
        ));
        lad.push_str(&format!(
            "[XIO(T_{i}.DN),XIC(A_{i})]TON(T_{i},{},0)CTU(C_{i},1000000,0)GRT(C_{i}.ACC,L_{i})ADD(V_{i},1,V_{i})OTE(Q_{i});\n",
            preset(i)
        ));
    }
    (tags, lad)
}

pub(crate) fn preset(i: usize) -> i32 {
    5 + (i % 7) as i32
}

/// The same logic in plain Rust.
pub(crate) mod native {
    #[derive(Clone, Default)]
    pub struct Rung {
        pub a: bool,
        pub t_pre: i32,
        pub t_acc: i32,
        pub t_last: u32,
        pub t_en: bool,
        pub t_tt: bool,
        pub t_dn: bool,
        pub c_pre: i32,
        pub c_acc: i32,
        pub c_cu: bool,
        pub c_dn: bool,
        pub c_ov: bool,
        pub l: i32,
        pub v: i32,
        pub q: bool,
        pub overflow: bool,
    }

    #[inline(always)]
    fn scan_rung(r: &mut Rung, now: u32) {
        let rc = !r.t_dn || r.a;
        // TON
        if rc {
            if !r.t_en {
                r.t_en = true;
                r.t_acc = 0;
                r.t_last = now;
            } else if !r.t_dn {
                let dt = now.wrapping_sub(r.t_last);
                r.t_last = now;
                r.t_acc = r.t_acc.saturating_add(dt as i32);
            }
            if !r.t_dn && r.t_acc >= r.t_pre {
                r.t_dn = true;
                r.t_acc = r.t_pre;
            }
            r.t_tt = !r.t_dn;
        } else {
            r.t_en = false;
            r.t_tt = false;
            r.t_dn = false;
            r.t_acc = 0;
        }
        // CTU
        if rc && !r.c_cu {
            match r.c_acc.checked_add(1) {
                Some(v) => r.c_acc = v,
                None => {
                    r.c_acc = i32::MIN;
                    r.c_ov = true;
                }
            }
        }
        r.c_cu = rc;
        r.c_dn = r.c_acc >= r.c_pre;
        // GRT, ADD, OTE
        let rc = rc && r.c_acc > r.l;
        if rc {
            match r.v.checked_add(1) {
                Some(v) => r.v = v,
                None => {
                    r.v = r.v.wrapping_add(1);
                    r.overflow = true;
                }
            }
        }
        r.q = rc;
    }

    /// Not inlined, so that a profiler sees it (one call per scan).
    #[inline(never)]
    pub fn scan(rungs: &mut [Rung], now: u32) {
        for r in rungs.iter_mut() {
            scan_rung(r, now);
        }
    }
}

pub(crate) fn native_rungs(n: usize) -> Vec<native::Rung> {
    (0..n)
        .map(|i| native::Rung {
            a: i % 11 == 0,
            t_pre: preset(i),
            c_pre: 1_000_000,
            l: (i % 5) as i32,
            ..Default::default()
        })
        .collect()
}

struct Built {
    program: Program,
    parse_ms: f64,
    compile_ms: f64,
}

fn build(n: usize) -> Result<Built, String> {
    let (tags_csv, lad) = generate(n);
    let mut files = Files::new();
    let tf = files.add("tags.csv", tags_csv);
    let lf = files.add("main.lad", lad);
    let t0 = Instant::now();
    let (tags, d1): (TagTable, _) = TagTable::parse(files.text(tf), tf);
    let (ast, d2) = alba_ladder::parse(files.text(lf), lf);
    let parse_ms = t0.elapsed().as_secs_f64() * 1e3;
    if !d1.is_empty() || !d2.is_empty() {
        return Err("generated program does not parse".into());
    }
    let t1 = Instant::now();
    let layout = alba_ladder::layout_for(&tags, &[&ast]);
    let mut b = alba_ir::Builder::new(layout);
    let d3 = alba_ladder::compile(
        &ast,
        files.text(lf),
        "main.lad",
        &mut b,
        &mut alba_ladder::Presets::default(),
    );
    if !d3.is_empty() {
        return Err(format!("generated program does not compile: {}", d3[0]));
    }
    let program = b.finish(files);
    program.verify().map_err(|e| e.to_string())?;
    let compile_ms = t1.elapsed().as_secs_f64() * 1e3;
    Ok(Built {
        program,
        parse_ms,
        compile_ms,
    })
}

pub(crate) fn place(p: &Program, name: &str) -> Result<Place, String> {
    match p.layout.resolve(name) {
        Ok(Target::Value { place, .. }) => Ok(place),
        _ => Err(format!("cannot resolve {name}")),
    }
}

/// Runs the engine (interpreted, or native with `native`) and the plain Rust
/// version for `scans` scans from the start and compares every rung.
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
            (format!("C_{i}.ACC"), Value::Dint(r.c_acc)),
            (format!("T_{i}.ACC"), Value::Dint(r.t_acc)),
            (format!("T_{i}.DN"), Value::Bool(r.t_dn)),
            (format!("Q_{i}"), Value::Bool(r.q)),
        ];
        for (name, want) in checks {
            let got = e.read(place(p, &name)?);
            if got != want {
                return Err(format!("{name}: engine {got}, native {want}"));
            }
        }
    }
    Ok(())
}

pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median nanoseconds per scan of each contender over `runs` rounds of
/// `scans` scans (see `round_samples`).
fn time_rounds<const N: usize>(runs: usize, scans: u64, fs: &mut [&mut dyn FnMut(u64); N]) -> [f64; N] {
    round_samples(runs, scans, fs).map(median)
}

/// Nanoseconds per scan of each contender in each of `runs` rounds of
/// `scans` scans. The contenders take turns within each round, so they are
/// measured under the same conditions (this machine is a shared VM whose
/// speed drifts); a warm-up of up to 1000 scans comes first.
pub(crate) fn round_samples<const N: usize>(
    runs: usize,
    scans: u64,
    fs: &mut [&mut dyn FnMut(u64); N],
) -> [Vec<f64>; N] {
    let mut k = [0u64; N];
    for (f, k) in fs.iter_mut().zip(k.iter_mut()) {
        for _ in 0..scans.min(1000) {
            f(*k);
            *k += 1;
        }
    }
    let mut samples = [(); N].map(|()| Vec::with_capacity(runs));
    for _ in 0..runs {
        for ((f, k), out) in fs.iter_mut().zip(k.iter_mut()).zip(samples.iter_mut()) {
            let t = Instant::now();
            for _ in 0..scans {
                f(*k);
                *k += 1;
            }
            out.push(t.elapsed().as_nanos() as f64 / scans as f64);
        }
    }
    samples
}

/// The median over rounds of `a / b` measured in the same round.
pub(crate) fn median_ratio(a: &[f64], b: &[f64]) -> f64 {
    median(a.iter().zip(b).map(|(a, b)| a / b).collect())
}

/// One size of a contender raced against the hand-written Rust.
pub(crate) struct Race {
    pub engine: Engine,
    /// After `compile_native` (the interpreter when native code is unavailable).
    pub jit: Engine,
    /// Machine-code generation (NaN when unavailable).
    pub jit_ms: f64,
    /// Median ns/rung of the interpreter, native code and plain Rust.
    pub per_rung: [f64; 3],
    /// Median ratios of the interpreter and native code to plain Rust.
    pub ratios: [f64; 2],
    /// The best round's line of the summary table.
    pub best: String,
}

/// Times the interpreter and native code of `p` (`n` rungs of the benchmark)
/// against [`native_rungs`], the three taking turns in each of `runs` rounds
/// of about 20 ms of engine work.
pub(crate) fn race(p: &Arc<Program>, n: usize, runs: usize, quick: bool) -> Result<Race, String> {
    let scans = ((20_000_000 / (n as u64 * 20)).max(10)) / if quick { 4 } else { 1 };
    let refused = |e: alba_engine::EngineError| format!("the engine refuses the program: {e}");
    let mut engine = Engine::new(p.clone()).map_err(refused)?;
    let mut jit = Engine::new(p.clone()).map_err(refused)?;
    let t = Instant::now();
    let jit_ms = match jit.compile_native() {
        Ok(()) => t.elapsed().as_secs_f64() * 1e3,
        Err(e) => {
            eprintln!("native code unavailable: {e}");
            f64::NAN
        }
    };
    let mut rungs = native_rungs(n);
    let [engine_t, jit_t, native_t] = round_samples(
        runs,
        scans.max(3),
        &mut [
            &mut |k| {
                let _ = engine.scan(black_box(k * SCAN_MS));
            },
            &mut |k| {
                let _ = jit.scan(black_box(k * SCAN_MS));
            },
            &mut |k| native::scan(black_box(&mut rungs), black_box((k * SCAN_MS) as u32)),
        ],
    );
    let ratios = [median_ratio(&engine_t, &native_t), median_ratio(&jit_t, &native_t)];
    let best = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min) / n as f64;
    let [engine_best, jit_best, native_best] = [&engine_t, &jit_t, &native_t].map(|v| best(v));
    let best = format!(
        "{n:>6} | {engine_best:>11.2} {:>5.2} | {jit_best:>11.2} {:>5.2} | {native_best:>9.2}",
        engine_best / native_best,
        jit_best / native_best
    );
    let per_rung = [engine_t, jit_t, native_t].map(|v| median(v) / n as f64);
    Ok(Race {
        engine,
        jit,
        jit_ms,
        per_rung,
        ratios,
        best,
    })
}

pub fn run(sizes: &[usize], quick: bool) -> ExitCode {
    let runs = if quick { 3 } else { 21 };
    println!("alba bench: rung = [XIO(T.DN),XIC(A)]TON(T,P,0)CTU(C,1000000,0)GRT(C.ACC,L)ADD(V,1,V)OTE(Q)");
    println!(
        "median of {runs} rounds, the three contenders taking turns in each; virtual clock 1 ms per scan; ns/rung = time per scan / rungs\n"
    );
    println!(
        "{:>6} | {:>7} {:>7} {:>6} | {:>11} {:>5} | {:>11} {:>5} | {:>9} | {:>6} {:>13}",
        "rungs",
        "parse",
        "compile",
        "native",
        "interpreter",
        "ratio",
        "native code",
        "ratio",
        "plain Rust",
        "data",
        "state"
    );
    println!(
        "{:>6} | {:>7} {:>7} {:>6} | {:>11} {:>5} | {:>11} {:>5} | {:>9} | {:>6} {:>13}",
        "", "ms", "ms", "ms", "ns/rung", "", "ns/rung", "", "ns/rung", "B/rung", "interp/native"
    );
    let (mut layouts, mut bests) = (Vec::new(), Vec::new());
    for &n in sizes {
        let n = n.max(1);
        let built = match build(n) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        let p = Arc::new(built.program);
        if let Err(e) = verify(&p, n, 200, false).and_then(|()| verify(&p, n, 200, true)) {
            eprintln!("error: engine and native disagree at N = {n}: {e}");
            return ExitCode::FAILURE;
        }
        let Race {
            engine,
            jit,
            jit_ms,
            per_rung: [engine_ns, jit_ns, native_ns],
            ratios: [engine_ratio, jit_ratio],
            best,
        } = match race(&p, n, runs, quick) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        bests.push(best);
        let data = p.init.size_bytes() as f64 / n as f64;
        let state = |e: &Engine| e.footprint() as f64 / n as f64 - data;
        let state = format!("{:.0} / {:.0}", state(&engine), state(&jit));
        if let Some((rungs, strided, functions)) = jit.native_layout() {
            layouts.push(format!(
                "  N = {n}: {functions} function(s), {strided} of {rungs} rungs in strided runs"
            ));
        }
        println!(
            "{:>6} | {:>7.1} {:>7.1} {:>6.1} | {:>11.2} {:>5.2} | {:>11.2} {:>5.2} | {:>9.2} | {:>6.1} {:>13}",
            n,
            built.parse_ms,
            built.compile_ms,
            jit_ms,
            engine_ns,
            engine_ratio,
            jit_ns,
            jit_ratio,
            native_ns,
            data,
            state
        );
    }
    println!("\nBest round of each contender (the least disturbed by the machine's other work):");
    println!(
        "{:>6} | {:>11} {:>5} | {:>11} {:>5} | {:>9}",
        "rungs", "interpreter", "ratio", "native code", "ratio", "plain Rust"
    );
    for b in &bests {
        println!("{b}");
    }
    println!(
        "\nparse = tags.csv and ladder text; compile = check, lower to IR, verify; native = machine-code generation."
    );
    println!("interpreter = unmonitored scans without native code; native code = after `compile_native`;");
    println!("plain Rust = the same logic hand-written over an array of structs; ratio = engine / plain Rust");
    println!("in the same round (median over the rounds);");
    println!("data = program memory per rung; state = everything else the engine holds per rung: the IR with");
    println!("its source locations, and the interpreter's fused code or native code's operand table and runs.");
    println!("Native code (machine code per rung shape; strided runs keep a few base addresses in registers):");
    for l in &layouts {
        println!("{l}");
    }
    println!("Reference (OpenPLC v3 / MatIEC C, g++ -O2, same rung): 11 ns/rung at 100, 29 at 1000, 47 at 10000.");
    if il_vs_ladder(sizes, runs, quick) != ExitCode::SUCCESS {
        return ExitCode::FAILURE;
    }
    pid_loops(sizes, runs, quick)
}

/// A contender of the scan benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Contender {
    Interpreter,
    Native,
    Rust,
}

/// `alba bench --profile C`: `scans` scans of contender `C` on `n` rungs,
/// untimed, for a profiler: `valgrind --tool=callgrind
/// --toggle-collect='*Engine*scan*' --toggle-collect='*native*scan*'` counts
/// only the scans.
pub fn profile(contender: Contender, n: usize, scans: u64) -> ExitCode {
    let n = n.max(1);
    let p = match build(n) {
        Ok(b) => Arc::new(b.program),
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    if contender == Contender::Rust {
        let mut rungs = native_rungs(n);
        for k in 0..scans {
            native::scan(black_box(&mut rungs), black_box((k * SCAN_MS) as u32));
        }
    } else {
        let Ok(mut e) = Engine::new(p) else {
            return ExitCode::FAILURE;
        };
        if contender == Contender::Native
            && let Err(err) = e.compile_native()
        {
            eprintln!("error: {err}");
            return ExitCode::FAILURE;
        }
        for k in 0..scans {
            let _ = e.scan(black_box(k * SCAN_MS));
        }
    }
    println!("{contender:?}: {scans} scans of {n} rungs");
    ExitCode::SUCCESS
}

/// `alba bench --listing`: the Cranelift IR and machine code (after
/// register allocation; jumps to the next block are dropped when the code is
/// emitted) of the benchmark rung, as a strided run of 8 rungs.
pub fn listing() -> ExitCode {
    let listing = build(8).and_then(|b| {
        Engine::new(Arc::new(b.program))
            .and_then(|e| e.native_listing())
            .map_err(|e| e.to_string())
    });
    match listing {
        Ok(l) => {
            print!("{l}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The cost of the PID instruction: N rungs `PID(L_i,PV_i,CV_i);` (a REAL
/// PV moved in, the output moved out), updating on every scan (UPD = the
/// scan period) or every 100 scans.
fn pid_loops(sizes: &[usize], runs: usize, quick: bool) -> ExitCode {
    println!(
        "\nPID loops: rung = PID(L,PV,CV); (PV REAL in, CV REAL out; PID with KP KI KD, derivative filter, limits)"
    );
    println!(
        "{:>6} | {:>5} | {:>11} | {:>11}",
        "loops", "UPD", "interpreter", "native code"
    );
    println!("{:>6} | {:>5} | {:>11} | {:>11}", "", "ms", "ns/loop", "ns/loop");
    for &n in sizes {
        let n = n.max(1);
        for upd in [1, 100] {
            let mut tags = String::from("name,type,address,initial,retain,description\n");
            let mut lad = String::new();
            for i in 0..n {
                tags.push_str(&format!(
                    "L_{i},PID,,\"KP=1.5;KI=0.4;KD=0.1;UPD={upd};SP=50\",,\nPV_{i},REAL,,{},,\nCV_{i},REAL,,,,\n",
                    (i % 97) as f32
                ));
                lad.push_str(&format!("PID(L_{i},PV_{i},CV_{i});\n"));
            }
            let p = match compile_text(&tags, "main.lad", &lad) {
                Ok(p) => p,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::FAILURE;
                }
            };
            let (Ok(mut engine), Ok(mut jit)) = (Engine::new(p.clone()), Engine::new(p.clone())) else {
                return ExitCode::FAILURE;
            };
            let _ = jit.compile_native();
            let scans = ((5_000_000 / (n as u64 * 50)).max(10)) / if quick { 4 } else { 1 };
            let [engine_ns, jit_ns] = time_rounds(
                runs,
                scans.max(3),
                &mut [
                    &mut |k| {
                        let _ = engine.scan(black_box(k * SCAN_MS));
                    },
                    &mut |k| {
                        let _ = jit.scan(black_box(k * SCAN_MS));
                    },
                ],
            );
            if engine.memory() != jit.memory() {
                eprintln!("error: interpreter and native code disagree on the PID loops");
                return ExitCode::FAILURE;
            }
            println!(
                "{:>6} | {:>5} | {:>11.2} | {:>11.2}",
                n,
                upd,
                engine_ns / n as f64,
                jit_ns / n as f64
            );
        }
    }
    println!("UPD 1 = every scan computes (worst case); UPD 100 = the loop waits 99 scans of 100 (gating only).");
    ExitCode::SUCCESS
}

/// The same logic as ladder rungs and as AWL networks (stack operations
/// included): one network `LD A; O B; LPS; AN C; = Q; LPP; A D; = R`.
fn il_vs_ladder(sizes: &[usize], runs: usize, quick: bool) -> ExitCode {
    println!("\nInstruction List against Ladder, the same logic:");
    println!("  ladder: [XIC(A),XIC(B)][XIO(C)OTE(Q),XIC(D)OTE(R)];");
    println!("  AWL:    LD A / O B / LPS / AN C / = Q / LPP / A D / = R");
    println!(
        "{:>6} | {:>18} | {:>18}\n{:>6} | {:>8} {:>9} | {:>8} {:>9}",
        "rungs", "interpreter ns/rung", "native ns/rung", "", "ladder", "AWL", "ladder", "AWL"
    );
    for &n in sizes {
        let n = n.max(1);
        let (tags, lad, awl) = generate_logic(n);
        let (Ok(ladder), Ok(il)) = (
            compile_text(&tags, "main.lad", &lad),
            compile_text(&tags, "main.awl", &awl),
        ) else {
            eprintln!("error: the generated logic programs do not compile");
            return ExitCode::FAILURE;
        };
        let scans = ((20_000_000 / (n as u64 * 10)).max(10)) / if quick { 4 } else { 1 };
        let mut engines = Vec::new();
        for p in [&ladder, &il] {
            for native in [false, true] {
                let Ok(mut e) = Engine::new(p.clone()) else {
                    return ExitCode::FAILURE;
                };
                if native && e.compile_native().is_err() {
                    eprintln!("native code unavailable");
                    return ExitCode::FAILURE;
                }
                engines.push(e);
            }
        }
        // Both languages must compute the same outputs.
        for e in &mut engines {
            let _ = e.scan(0);
        }
        for i in (0..n).step_by((n / 10).max(1)) {
            for name in [format!("Q_{i}"), format!("R_{i}")] {
                let values: Vec<Value> = [(&ladder, 0), (&ladder, 1), (&il, 2), (&il, 3)]
                    .iter()
                    .map(|(p, k)| place(p, &name).map(|pl| engines[*k].read(pl)))
                    .collect::<Result<_, _>>()
                    .unwrap_or_default();
                if values.windows(2).any(|w| w[0] != w[1]) {
                    eprintln!("error: ladder and AWL disagree on {name}: {values:?}");
                    return ExitCode::FAILURE;
                }
            }
        }
        let [e0, e1, e2, e3] = &mut engines[..] else {
            return ExitCode::FAILURE;
        };
        let ns = time_rounds(
            runs,
            scans.max(3),
            &mut [
                &mut |k| {
                    let _ = e0.scan(black_box(k));
                },
                &mut |k| {
                    let _ = e2.scan(black_box(k));
                },
                &mut |k| {
                    let _ = e1.scan(black_box(k));
                },
                &mut |k| {
                    let _ = e3.scan(black_box(k));
                },
            ],
        )
        .map(|t| t / n as f64);
        println!("{n:>6} | {:>8.2} {:>9.2} | {:>8.2} {:>9.2}", ns[0], ns[1], ns[2], ns[3]);
    }
    ExitCode::SUCCESS
}

/// Tags, ladder and AWL text of `n` copies of the logic network.
fn generate_logic(n: usize) -> (String, String, String) {
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let (mut lad, mut awl) = (String::new(), String::new());
    for i in 0..n {
        let bit = |k: usize| u8::from((i >> k) & 1 == 1);
        tags.push_str(&format!(
            "A_{i},BOOL,,{},,\nB_{i},BOOL,,{},,\nC_{i},BOOL,,{},,\nD_{i},BOOL,,{},,\nQ_{i},BOOL,,,,\nR_{i},BOOL,,,,\n",
            bit(0),
            bit(1),
            bit(2),
            bit(3)
        ));
        lad.push_str(&format!(
            "[XIC(A_{i}),XIC(B_{i})][XIO(C_{i})OTE(Q_{i}),XIC(D_{i})OTE(R_{i})];\n"
        ));
        awl.push_str(&format!(
            "NETWORK\nLD A_{i}\nO B_{i}\nLPS\nAN C_{i}\n= Q_{i}\nLPP\nA D_{i}\n= R_{i}\n"
        ));
    }
    (tags, lad, awl)
}

/// Compiles one generated program (ladder or AWL by `name`).
pub fn compile_text(tags_csv: &str, name: &str, text: &str) -> Result<Arc<Program>, String> {
    let mut files = Files::new();
    let tf = files.add("tags.csv", tags_csv);
    let f = files.add(name, text);
    let (tags, mut diags) = TagTable::parse(files.text(tf), tf);
    let program = if name.ends_with(".awl") {
        let (ast, d) = alba_il::parse(files.text(f), f);
        diags.extend(d);
        let mut b = alba_ir::Builder::new(alba_ir::Layout::new(&tags, &alba_il::uses(&ast)));
        diags.extend(alba_il::compile(&ast, name, &mut b, &mut alba_il::Shared::default()));
        b.finish(files)
    } else {
        let (ast, d) = alba_ladder::parse(files.text(f), f);
        diags.extend(d);
        let mut b = alba_ir::Builder::new(alba_ladder::layout_for(&tags, &[&ast]));
        let src = files.text(f).to_string();
        diags.extend(alba_ladder::compile(
            &ast,
            &src,
            name,
            &mut b,
            &mut alba_ladder::Presets::default(),
        ));
        b.finish(files)
    };
    match diags.first() {
        Some(d) => Err(d.message.clone()),
        None => Ok(Arc::new(program)),
    }
}

/// `alba bench --nets`: (a) the scan cost of a Petri-mode net against the
/// same logic in Ladder (fused interpreter, ns per transition per scan);
/// (b) the analysis benchmark of `alba_net::analysis::bench` (states/s,
/// bytes/state, Kanban 5, invariants on 100 places). Prints, never asserts.
/// `alba bench --historian`: `alba_historian::bench`.
pub fn historian(quick: bool) -> ExitCode {
    match alba_historian::bench::run(quick) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

pub fn nets(quick: bool) -> ExitCode {
    let runs = if quick { 3 } else { 9 };
    println!("alba bench --nets: (a) a Petri-mode net of N two-place cycles (2N transitions) against the");
    println!("same moves in Ladder, `GEQ(a,1)[SUB(a,1,a),ADD(b,1,b)];` per transition; fused interpreter.\n");
    println!(
        "{:>12} | {:>14} {:>14} {:>6}",
        "transitions", "net ns/trans.", "ladder ns/tr.", "ratio"
    );
    for n in [50usize, 500] {
        let (tags, lad, pnml) = net_and_ladder(n);
        let dir = std::env::temp_dir().join(format!("alba-bench-nets-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let files = [
            (
                "alba.toml",
                "name = \"bench\"\nscan_ms = 1\nprograms = [\"cyc.pnml\"]\n".to_string(),
            ),
            ("tags.csv", "name,type,address,initial,retain,description\n".to_string()),
            ("cyc.pnml", pnml),
        ];
        if std::fs::create_dir_all(&dir).is_err() || files.iter().any(|(f, t)| std::fs::write(dir.join(f), t).is_err())
        {
            eprintln!("error: cannot write {}", dir.display());
            return ExitCode::FAILURE;
        }
        let c = alba_load::compile_dir(&dir);
        let _ = std::fs::remove_dir_all(&dir);
        let Some(net_prog) = c.program else {
            eprintln!(
                "error: the generated net does not compile: {}",
                alba_diag::render_all(&c.diagnostics, c.files())
            );
            return ExitCode::FAILURE;
        };
        let lad_prog = match compile_text(&tags, "main.lad", &lad) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        let (Ok(mut net_engine), Ok(mut lad_engine)) = (Engine::new(Arc::new(net_prog)), Engine::new(lad_prog)) else {
            return ExitCode::FAILURE;
        };
        let scans = (2_000_000 / n as u64).max(10) / if quick { 4 } else { 1 };
        let [net_ns, lad_ns] = time_rounds(
            runs,
            scans,
            &mut [
                &mut |k| {
                    let _ = net_engine.scan(black_box(k));
                },
                &mut |k| {
                    let _ = lad_engine.scan(black_box(k));
                },
            ],
        );
        let per = |ns: f64| ns / (2 * n) as f64;
        println!(
            "{:>12} | {:>14.2} {:>14.2} {:>6.2}",
            2 * n,
            per(net_ns),
            per(lad_ns),
            net_ns / lad_ns
        );
    }
    println!("\n(b) analysis (complete: state space, deadlocks, liveness, reversibility, invariants):\n");
    print!("{}", alba_net::analysis::bench::run(quick));
    ExitCode::SUCCESS
}

/// N two-place cycles `a_i ⇄ b_i` (one token each) as a Petri-mode net, and
/// the same moves in Ladder with DINT tags.
fn net_and_ladder(n: usize) -> (String, String, String) {
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let mut lad = String::new();
    let mut pnml = String::from(
        "<pnml xmlns=\"http://www.pnml.org/version-2009/grammar/pnml\"><net id=\"cyc\" type=\"http://www.pnml.org/version-2009/grammar/ptnet\"><page id=\"pg\">\n",
    );
    for i in 0..n {
        tags.push_str(&format!("a{i},DINT,,1,,\nb{i},DINT,,0,,\n"));
        lad.push_str(&format!(
            "GEQ(a{i},1)[SUB(a{i},1,a{i}),ADD(b{i},1,b{i})];\nGEQ(b{i},1)[SUB(b{i},1,b{i}),ADD(a{i},1,a{i})];\n"
        ));
        pnml.push_str(&format!(
            "<place id=\"a{i}\"><initialMarking><text>1</text></initialMarking></place><place id=\"b{i}\"/>\
             <transition id=\"f{i}\"/><transition id=\"g{i}\"/>\
             <arc id=\"x{i}\" source=\"a{i}\" target=\"f{i}\"/><arc id=\"y{i}\" source=\"f{i}\" target=\"b{i}\"/>\
             <arc id=\"z{i}\" source=\"b{i}\" target=\"g{i}\"/><arc id=\"w{i}\" source=\"g{i}\" target=\"a{i}\"/>\n"
        ));
    }
    pnml.push_str("</page></net></pnml>\n");
    (tags, lad, pnml)
}

/// `alba bench --swap`: the gap an online edit leaves between two scans
/// (issue 31). Before, the engine thread verified, compiled (native code
/// or the interpreter's forms) and migrated memory between two scans; now
/// `Engine::prepare` does that on another thread and the engine only
/// `swap`s. Prints both on N-rung programs (the edit recompiles the same
/// program: the work is the same as for a changed rung), then the scan
/// lateness `alba run`'s runtime shows through an edit.
pub fn swap(sizes: &[usize]) -> ExitCode {
    println!("alba bench --swap: an online edit of N rungs (engine thread's gap between two scans)\n");
    println!(
        "{:>7} {:>12} | {:>16} | {:>13} {:>12} {:>13}",
        "rungs", "engine", "before: on the", "after: prepare", "swap (gap)", "free old"
    );
    println!(
        "{:>7} {:>12} | {:>16} | {:>13} {:>12} {:>13}",
        "", "", "engine thread ms", "elsewhere ms", "ms", "elsewhere ms"
    );
    for &n in sizes {
        let (Ok(a), Ok(b)) = (build(n), build(n)) else {
            eprintln!("error: the benchmark program does not build");
            return ExitCode::FAILURE;
        };
        let (a, b) = (Arc::new(a.program), Arc::new(b.program));
        for native in [false, true] {
            let start = || -> Option<Engine> {
                let mut e = Engine::new(a.clone()).ok()?;
                if native && e.compile_native().is_err() {
                    return None;
                }
                for k in 0..3 {
                    let _ = e.scan(k);
                }
                Some(e)
            };
            let (Some(mut old), Some(mut new)) = (start(), start()) else {
                eprintln!("native code unavailable");
                continue;
            };
            let t = Instant::now();
            if let Err(e) = old.replace(b.clone()) {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
            let before = t.elapsed();
            let t = Instant::now();
            let prepared = match Engine::prepare(b.clone(), &a, native) {
                Ok(p) => p,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::FAILURE;
                }
            };
            let prepare = t.elapsed();
            let t = Instant::now();
            let retired = new.swap(prepared);
            let gap = t.elapsed();
            let t = Instant::now();
            drop(retired);
            let free = t.elapsed();
            let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
            println!(
                "{n:>7} {:>12} | {:>16.2} | {:>13.2} {:>12.3} {:>13.2}",
                if native { "native" } else { "interpreter" },
                ms(before),
                ms(prepare),
                ms(gap),
                ms(free)
            );
        }
    }
    // Through the runtime: the largest scan lateness while an edit is applied.
    let n = sizes.last().copied().unwrap_or(50_000);
    let (Ok(a), Ok(b)) = (build(n), build(n)) else {
        return ExitCode::FAILURE;
    };
    println!("\nalba run's runtime, {n} rungs, native code, 100 ms scans: scan lateness around one online edit");
    let log = alba_runtime::ScanLog::new(100_000);
    let mut opts = alba_runtime::Options::new(100);
    opts.native = true;
    opts.scan_log = Some(log.clone());
    let Ok(rt) = alba_runtime::Runtime::start(Arc::new(a.program), opts, Box::new(alba_runtime::SimIo)) else {
        eprintln!("error: the runtime does not start");
        return ExitCode::FAILURE;
    };
    let h = rt.handle();
    let tokio = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    std::thread::sleep(std::time::Duration::from_millis(500));
    log.record(true);
    let t = Instant::now();
    let edited = tokio.block_on(h.replace(Arc::new(b.program)));
    let edit = t.elapsed();
    std::thread::sleep(std::time::Duration::from_millis(500));
    log.record(false);
    rt.shutdown();
    if let Err(e) = edited {
        eprintln!("error: the edit was refused: {e}");
        return ExitCode::FAILURE;
    }
    let late = log.late_ns();
    let worst = late.iter().copied().max().unwrap_or(0);
    println!(
        "  the edit took {:.1} ms to answer; {} scans recorded, worst lateness {:.3} ms, {} overruns",
        edit.as_secs_f64() * 1e3,
        late.len(),
        worst as f64 / 1e6,
        log.overruns()
    );
    ExitCode::SUCCESS
}
