//! The lowering's optimisations (statements sharing rungs, the peephole on
//! boolean temporaries, literal presets in slots of their own; issue 36):
//! what they give the benchmark rung of `alba bench --st`, and a
//! differential test against `compile_unoptimised` on ST programs of the
//! repository, every scan, in every engine mode.

use alba_diag::{Files, render_all};
use alba_engine::Engine;
use alba_ir::{Builder, Layout, Op, Program};
use alba_model::{DataType, TagTable, Value};
use std::path::Path;
use std::sync::Arc;

/// tags.csv and the ST text of `n` rungs of `alba bench --st`
/// (`crates/cli/src/bench_st.rs`).
fn bench(n: usize) -> (String, String) {
    let mut tags = String::from("name,type,address,initial\n");
    let mut vars = String::from("PROGRAM Main\nVAR\n    r : BOOL;\n");
    let mut body = String::new();
    for i in 0..n {
        tags.push_str(&format!(
            "A_{i},BOOL,,{}\nL_{i},DINT,,{}\nV_{i},DINT,,\nQ_{i},BOOL,,\n",
            u8::from(i % 11 == 0),
            i % 5
        ));
        vars.push_str(&format!("    T_{i} : TON; C_{i} : CTU;\n"));
        body.push_str(&format!(
            "r := NOT T_{i}.Q OR A_{i};\nT_{i}(IN := r, PT := T#{}ms);\nC_{i}(CU := r, PV := 30000);\n\
             Q_{i} := r AND C_{i}.CV > L_{i};\nIF Q_{i} THEN V_{i} := V_{i} + 1; END_IF;\n",
            5 + i % 7
        ));
    }
    (tags, format!("{vars}END_VAR\n{body}END_PROGRAM\n"))
}

/// The program of `main` (with the POUs of `library`) over `csv`, lowered
/// with or without the optimisations; and the slots of the tags (the
/// layout before lowering), which both programs share.
fn build(csv: &str, main: &str, library: &[&str], optimise: bool) -> (Program, [usize; 5]) {
    let mut files = Files::new();
    let tf = files.add("tags.csv", csv);
    let (mut tags, mut diags): (TagTable, _) = TagTable::parse(files.text(tf), tf);
    let lib_ids: Vec<_> = library
        .iter()
        .enumerate()
        .map(|(k, t)| files.add(format!("lib{k}.st"), *t))
        .collect();
    let mf = files.add("main.st", main);
    let libs: Vec<alba_st::File> = lib_ids
        .iter()
        .map(|&f| {
            let (ast, d) = alba_st::parse(files.text(f), f);
            diags.extend(d);
            ast
        })
        .collect();
    let (ast, d) = alba_st::parse(files.text(mf), mf);
    diags.extend(d);
    let lib_refs: Vec<&alba_st::File> = libs.iter().collect();
    for l in &libs {
        let mut others = lib_refs.clone();
        others.retain(|o| !std::ptr::eq(*o, l));
        others.push(&ast);
        alba_st::declare_with(l, &others, &mut tags, &mut diags);
    }
    alba_st::declare_with(&ast, &lib_refs, &mut tags, &mut diags);
    let layout = Layout::new(&tags, &Default::default());
    let c = layout.counts;
    let counts = [c.b as usize, c.i as usize, c.f as usize, c.l as usize, c.d as usize];
    let mut b = Builder::new(layout);
    for (k, l) in libs.iter().enumerate() {
        let mut others = lib_refs.clone();
        others.retain(|o| !std::ptr::eq(*o, l));
        others.push(&ast);
        let name = format!("lib{k}.st");
        diags.extend(if optimise {
            alba_st::compile_with(l, &others, &name, &mut b)
        } else {
            alba_st::compile_unoptimised(l, &others, &name, &mut b)
        });
    }
    diags.extend(if optimise {
        alba_st::compile_with(&ast, &lib_refs, "main.st", &mut b)
    } else {
        alba_st::compile_unoptimised(&ast, &lib_refs, "main.st", &mut b)
    });
    assert!(diags.is_empty(), "{}", render_all(&diags, &files));
    let p = b.finish(files);
    p.verify().expect("verifies");
    (p, counts)
}

fn engine(p: &Program, mode: &str) -> Engine {
    let mut e = Engine::new(Arc::new(p.clone())).expect("verifies");
    match mode {
        "monitored" => e.set_monitor(true),
        "native" => e.compile_native().expect("native code"),
        _ => {}
    }
    e
}

/// Every tag slot, and the faults so far (where: the line, column and text
/// of the statement; rung numbers differ, as statements share rungs).
fn observe(e: &Engine, counts: [usize; 5]) -> String {
    let m = e.memory();
    let mut out = format!(
        "{:?} {:?} {:?} {:?} {:?} {:?} faults {}",
        &m.b[..counts[0]],
        &m.i[..counts[1]],
        &m.f[..counts[2]],
        &m.l[..counts[3]],
        &m.d[..counts[4]],
        m.m,
        e.faults().count
    );
    for f in [&e.faults().first, &e.faults().last].into_iter().flatten() {
        let at = e.describe_fault(f);
        out.push_str(&format!(
            " [{} {}]",
            f.code,
            at.split_once('(').map_or("", |(_, rest)| rest)
        ));
    }
    out
}

/// Runs both lowerings of the program for `scans` scans in every mode,
/// writing pseudo-random values to the tags of tags.csv before each scan,
/// and requires the same tags and faults after every scan.
fn same_results(what: &str, csv: &str, main: &str, library: &[&str], scans: u64) {
    let (opt, counts) = build(csv, main, library, true);
    let (plain, _) = build(csv, main, library, false);
    assert!(
        opt.ops.len() <= plain.ops.len() && opt.rungs.len() <= plain.rungs.len(),
        "{what}: the optimised lowering is larger ({} ops, {} rungs against {}, {})",
        opt.ops.len(),
        opt.rungs.len(),
        plain.ops.len(),
        plain.rungs.len()
    );
    let (tags, _) = TagTable::parse(csv, alba_diag::FileId(0));
    let inputs: Vec<(String, DataType)> = tags.iter().map(|t| (t.name.clone(), t.ty)).collect();
    for mode in ["fused", "monitored", "native"] {
        let mut a = engine(&opt, mode);
        let mut b = engine(&plain, "fused");
        let mut seed = 0x2545_f491_u64;
        for k in 0..scans {
            for _ in 0..2 {
                seed = seed
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let Some((name, ty)) = inputs.get((seed >> 33) as usize % inputs.len().max(1)) else {
                    break;
                };
                let x = (seed >> 40) as i32 % 200 - 50;
                let v = match ty {
                    DataType::Bool => Value::Bool(x & 1 == 1),
                    DataType::Int => Value::Int(x as i16),
                    DataType::Dint => Value::Dint(x),
                    DataType::Real => Value::Real(x as f32 / 4.0),
                    _ => continue,
                };
                for e in [&mut a, &mut b] {
                    if let Ok(alba_ir::Target::Value { place, .. }) = e.program().layout.resolve(name) {
                        e.write(place, v);
                    }
                }
            }
            for e in [&mut a, &mut b] {
                e.scan(k * 7)
                    .unwrap_or_else(|f| panic!("{what} {mode}: major fault {}", f.message));
            }
            assert_eq!(
                observe(&a, counts),
                observe(&b, counts),
                "{what}: the optimised lowering ({mode}) differs from the unoptimised one after scan {k}"
            );
        }
    }
}

fn read(path: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn the_bench_rung_is_one_ir_rung_of_few_ops_run_strided_by_native_code() {
    let n = 12;
    let (csv, st) = bench(n);
    let (p, _) = build(&csv, &st, &[], true);
    let (plain, _) = build(&csv, &st, &[], false);
    // Before: 7 IR rungs and 36 ops per benchmark rung.
    assert_eq!(plain.rungs.len(), 7 * n + 2, "{}", plain.dump());
    // Now one IR rung per benchmark rung (from the end of one IF to the
    // end of the next), plus the program's first and last.
    assert_eq!(p.rungs.len(), n + 2, "{}", p.dump());
    let per_rung = p.ops.len() / n;
    assert!(per_rung <= 20, "{per_rung} ops per benchmark rung:\n{}", p.dump());
    // No bool copy through a temporary, no reload of the bit just written.
    let dump = p.dump();
    assert!(!dump.contains("CopyB"), "{dump}");
    for w in p.ops.windows(3) {
        if let [Op::Ote(s), Op::True, Op::Ld(t) | Op::Ldn(t)] = w {
            assert_ne!(s, t, "a bit read back right after it was written:\n{dump}");
        }
    }
    // Native code: every benchmark rung but the first in one strided run.
    let mut e = engine(&p, "native");
    let (rungs, strided, _) = e.native_layout().expect("native code");
    assert_eq!(rungs, n + 2);
    assert!(strided >= n - 2, "{strided} of {rungs} IR rungs strided");
    e.scan(0).expect("scan");
    same_results("the bench rungs", &csv, &st, &[], 120);
}

#[test]
fn a_fault_in_a_shared_rung_names_its_own_statement() {
    let csv = "name,type\nY,DINT\nB,DINT\nX,BOOL\n";
    let st =
        "PROGRAM Main\nVAR a : ARRAY[1..3] OF DINT; END_VAR\nX := NOT X;\nY := 10 / B;\na[B + 4] := 1;\nEND_PROGRAM\n";
    let (p, _) = build(csv, st, &[], true);
    assert_eq!(
        p.rungs.len(),
        2,
        "the three statements share the first rung:\n{}",
        p.dump()
    );
    for mode in ["fused", "monitored", "native"] {
        let mut e = engine(&p, mode);
        e.scan(0).expect("scan");
        let first = e.faults().first.expect("a fault");
        let last = e.faults().last.expect("a fault");
        assert!(
            e.describe_fault(&first).contains("(4:1 `Y := 10 / B;`)"),
            "{mode}: {}",
            e.describe_fault(&first)
        );
        assert!(
            e.describe_fault(&last).contains("(5:1 `a[B + 4] := 1;`)"),
            "{mode}: {}",
            e.describe_fault(&last)
        );
    }
}

#[test]
fn control_flow_and_boolean_logic_compute_the_same_as_unoptimised() {
    let csv = "name,type\nA,BOOL\nB,BOOL\nG,BOOL\nN,DINT\nM,DINT\nR,REAL\nQ1,BOOL\nQ2,BOOL\nQ3,BOOL\nK,DINT\nS,DINT\n";
    let st = "\
PROGRAM Main
VAR i : DINT; t : TON; cnt : CTUD; e : R_TRIG; arr : ARRAY[0..4] OF DINT; x : BOOL; END_VAR
Q1 := (A AND NOT B) OR (G XOR A) OR NOT (B AND G);
Q2 := Q1 AND N > M OR NOT Q1 AND N <= M;
Q3 := NOT Q2;
x := Q3;
Q1 := x AND A;
IF A AND NOT B THEN K := K + 1; ELSIF B OR G THEN K := K - 1; IF Q2 THEN K := K + 10; END_IF; ELSE K := 0; END_IF;
CASE N OF
  0..3: S := S + 1;
  4, 7: S := S * 2; IF S > 1000 THEN S := 0; END_IF;
ELSE S := N;
END_CASE;
FOR i := 0 TO 4 DO
  arr[i] := i * N;
  IF arr[i] > 50 THEN EXIT; END_IF;
END_FOR;
WHILE M > 100 DO M := M - 7; END_WHILE;
REPEAT M := M + 1; UNTIL M > -20 END_REPEAT;
t(IN := A OR Q3, PT := T#30ms);
cnt(CU := B, CD := G, R := A AND B, PV := 5);
e(CLK := t.Q);
IF e.Q THEN K := K + 100; END_IF;
arr[N] := 3;
M := M / (N - 2);
R := R * 0.5 + DINT_TO_REAL(K);
IF K > 1000 THEN RETURN; END_IF;
K := K + 1;
END_PROGRAM
";
    same_results("control flow", csv, st, &[], 400);
}

#[test]
fn the_repository_st_programs_compute_the_same_as_unoptimised() {
    same_results(
        "examples/st-motor",
        &read("examples/st-motor/tags.csv"),
        &read("examples/st-motor/main.st"),
        &[],
        300,
    );
    same_results(
        "st-library",
        &read("crates/compiler/tests/projects/st-library/tags.csv"),
        &read("crates/compiler/tests/projects/st-library/main.st"),
        &[&read("crates/compiler/tests/projects/st-library/lib.st")],
        300,
    );
    same_results(
        "oscat-basic",
        &read("crates/compiler/tests/projects/oscat-basic/tags.csv"),
        &read("crates/compiler/tests/projects/oscat-basic/main.st"),
        &[&read("crates/compiler/tests/projects/oscat-basic/oscat.st")],
        20,
    );
}
