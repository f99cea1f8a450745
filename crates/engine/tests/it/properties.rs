//! Properties over random ladder programs: the same stimulus gives the same
//! trace (determinism), and the fused code of unmonitored scans computes
//! exactly what the one-op-per-instruction code of monitored scans does.

use crate::util::{compile_text, observable, simulate};
use alba_engine::Engine;
use alba_ir::{Place, Target};
use alba_model::Value;
use proptest::prelude::*;
use std::sync::Arc;

const TAGS: &str = "name,type,address,initial\n\
I0,BOOL,DI:1/0,\nI1,BOOL,DI:1/1,\nI2,BOOL,DI:1/2,\nI3,BOOL,DI:1/3,\n\
B0,BOOL,,\nB1,BOOL,,1\nB2,BOOL,,\nB3,BOOL,,\nQ0,BOOL,DO:2/0,\nQ1,BOOL,DO:2/1,\n\
T0,TIMER,,\nT1,TIMER,,\nC0,COUNTER,,\nC1,COUNTER,,\n\
D0,DINT,,3\nD1,DINT,,-7\nD2,DINT,,\nS0,INT,,100\nR0,REAL,,1.5\nR1,REAL,,\nW0,INT,MW0,\nM0,BOOL,M2.1,\n\
P0,PID,,\"KP=1;KI=0.5;KD=0.1;UPD=20;MAXO=80\"\n";

fn contact() -> impl Strategy<Value = String> {
    let bit = prop::sample::select(vec![
        "I0", "I1", "I2", "I3", "B0", "B1", "B2", "B3", "Q0", "T0.DN", "T1.TT", "C0.DN", "C1.CU", "M0", "P0.DN",
        "P0.UL",
    ]);
    let cmp = prop::sample::select(vec![
        "GRT(D0,D1)",
        "LES(D2,5)",
        "EQU(C0.ACC,2)",
        "GEQ(R0,D0)",
        "NEQ(S0,W0)",
        "LEQ(T0.ACC,15)",
        "LIM(D1,D0,2)",
        "LIM(10,D2,-10)",
        "MEQ(D0,6,2)",
    ]);
    prop_oneof![
        (prop::bool::ANY, bit).prop_map(|(n, b)| format!("{}({b})", if n { "XIO" } else { "XIC" })),
        cmp.prop_map(str::to_string),
        Just("ONS(B3)".to_string()),
    ]
}

fn output() -> impl Strategy<Value = String> {
    prop::sample::select(vec![
        "OTE(B0)",
        "PID(P0,D0,R1)",
        "PID(P0,R0,D2)",
        "MOV(D1,P0.SP)",
        "MOV(R0,R1)",
        "MOV(R1,P0.SP)",
        "OTE(P0.MAN)",
        "OTE(Q0)",
        "OTL(B2)",
        "OTU(B2)",
        "OTE(Q1)",
        "OTL(M0)",
        "OTU(B3)",
        "OSR(B1,Q1)",
        "OSF(B0,B3)",
        "TON(T0,30,0)",
        "TOF(T1,70,0)",
        "RTO(T0,30,0)",
        "TP(T1,70,0)",
        "RES(T0)",
        "RES(C1)",
        "CTU(C0,3,0)",
        "CTD(C0,3,0)",
        "CTU(C1,2,0)",
        "ADD(D0,1,D0)",
        "SUB(D1,D0,D2)",
        "MUL(D2,D1,D2)",
        "DIV(D0,D2,D1)",
        "MOD(D0,D1,D2)",
        "MOV(R0,D2)",
        "ADD(S0,30000,S0)",
        "MUL(R0,1.5,R1)",
        "DIV(R1,D2,R0)",
        "CPT(D2,(D0+D1)*2-C0.ACC)",
        "CPT(R1,SIN(R0)+D0/4)",
        "SCP(D0,0,10,0.0,100.0,R1)",
        "NEG(D1,D1)",
        "ABS(D1,D2)",
        "AND(D0,D1,D2)",
        "NOT(D0,D2)",
        "XOR(W0,D0,W0)",
        "ADD(W0,1,W0)",
        "CLR(D2)",
        "SQR(D0,R1)",
        "MOV(T0.ACC,D2)",
        "NOP()",
    ])
    .prop_map(str::to_string)
}

/// A sequence of elements ending in an output (branches nest once).
fn body(depth: u32) -> BoxedStrategy<String> {
    let leg = if depth == 0 {
        prop::collection::vec(contact(), 1..3).prop_map(|v| v.join("")).boxed()
    } else {
        prop_oneof![3 => prop::collection::vec(contact(), 1..3).prop_map(|v| v.join("")), 1 => body(depth - 1)].boxed()
    };
    (
        prop::collection::vec(contact(), 0..3),
        prop::option::of(prop::collection::vec(leg, 2..4)),
        prop::collection::vec(contact(), 0..2),
        prop::collection::vec(output(), 1..3),
    )
        .prop_map(|(pre, branch, mid, outs)| {
            let mut s = pre.join("");
            if let Some(legs) = branch {
                s.push('[');
                s.push_str(&legs.join(","));
                s.push(']');
            }
            s.push_str(&mid.join(""));
            s.push_str(&outs.join(""));
            s
        })
        .boxed()
}

fn program() -> impl Strategy<Value = String> {
    prop::collection::vec(body(1).prop_map(|b| format!("{b};\n")), 1..12).prop_map(|v| v.concat())
}

/// Input toggles: (time, input, value).
fn stimulus() -> impl Strategy<Value = String> {
    prop::collection::vec((0u64..600, 0usize..4, prop::bool::ANY), 0..30).prop_map(|rows| {
        let mut s = String::from("time_ms,tag,value\n");
        for (t, i, v) in rows {
            s.push_str(&format!("{t},I{i},{}\n", u8::from(v)));
        }
        s
    })
}

fn input(p: &alba_ir::Program, i: usize) -> Place {
    match p.layout.resolve(&format!("I{i}")) {
        Ok(Target::Value { place, .. }) => place,
        _ => unreachable!(),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn same_stimulus_same_trace(lad in program(), stim in stimulus()) {
        let p1 = compile_text(TAGS, &lad).map_err(|e| TestCaseError::fail(format!("{lad}\n{e}")))?;
        let p2 = compile_text(TAGS, &lad).map_err(TestCaseError::fail)?;
        let a = simulate(p1, &stim, None, 10, 600, 10);
        let b = simulate(p2, &stim, None, 10, 600, 10);
        prop_assert_eq!(a, b);
    }

    #[test]
    fn fused_code_matches_unfused_code(lad in program(), toggles in prop::collection::vec((0usize..4, prop::bool::ANY), 60)) {
        let p = Arc::new(compile_text(TAGS, &lad).map_err(|e| TestCaseError::fail(format!("{lad}\n{e}")))?);
        let mut fast = Engine::new(p.clone()).unwrap();
        let mut plain = Engine::new(p.clone()).unwrap();
        plain.set_monitor(true);
        for (k, (i, v)) in toggles.into_iter().enumerate() {
            for e in [&mut fast, &mut plain] {
                e.write(input(&p, i), Value::Bool(v));
                e.scan(k as u64 * 10).unwrap();
            }
            prop_assert_eq!(observable(&fast), observable(&plain), "scan {} of\n{}", k, lad);
            prop_assert_eq!(fast.faults(), plain.faults());
        }
    }
}

#[cfg(feature = "jit")]
proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn native_code_matches_the_interpreter(lad in program(), toggles in prop::collection::vec((0usize..4, prop::bool::ANY), 60)) {
        let p = Arc::new(compile_text(TAGS, &lad).map_err(|e| TestCaseError::fail(format!("{lad}\n{e}")))?);
        let mut native = Engine::new(p.clone()).unwrap();
        native.compile_native().map_err(|e| TestCaseError::fail(e.to_string()))?;
        let mut interp = Engine::new(p.clone()).unwrap();
        for (k, (i, v)) in toggles.into_iter().enumerate() {
            for e in [&mut native, &mut interp] {
                e.write(input(&p, i), Value::Bool(v));
                e.scan(k as u64 * 10).unwrap();
            }
            prop_assert_eq!(observable(&native), observable(&interp), "scan {} of\n{}", k, lad);
            prop_assert_eq!(native.faults(), interp.faults());
        }
    }
}

/// Tags of copy `k` of a repeated rung, declared together (as generated
/// programs and arrays of structures have them).
fn copy_tags(k: usize) -> String {
    format!(
        "A_{k},BOOL,,{}\nB_{k},BOOL,,\nO_{k},BOOL,,\nQ_{k},BOOL,,\nT_{k},TIMER,,\nC_{k},COUNTER,,\n\
         D_{k},DINT,,{}\nE_{k},DINT,,-{k}\nR_{k},REAL,,{k}.5\n\
         P_{k},PID,,\"KP=1;KI=0.5;UPD=20\"\n",
        k % 2,
        2_147_483_640 - 3 * k as i64
    )
}

/// An element of a repeated rung: `#` is the copy's number; the others are
/// shared by every copy (inputs, `D0`).
fn copy_contact() -> impl Strategy<Value = String> {
    prop::sample::select(vec![
        "XIC(A_#)",
        "XIO(B_#)",
        "XIC(T_#.DN)",
        "XIO(T_#.DN)",
        "XIC(C_#.DN)",
        "XIC(I0)",
        "XIO(I1)",
        "XIC(I2)",
        "GRT(D_#,E_#)",
        "LES(C_#.ACC,3)",
        "EQU(T_#.ACC,D_#)",
        "GEQ(D0,E_#)",
        "ONS(O_#)",
    ])
    .prop_map(str::to_string)
}

fn copy_output() -> impl Strategy<Value = String> {
    prop::sample::select(vec![
        "OTE(Q_#)",
        "OTL(B_#)",
        "OTU(B_#)",
        "OSR(O_#,Q_#)",
        "TON(T_#,20,0)",
        "MOV(E_#,T_#.PRE)",
        "MOV(2147483640,T_#.ACC)",
        "CTU(C_#,3,0)",
        "CTD(C_#,3,0)",
        "ADD(D_#,1,D_#)",
        "SUB(E_#,D_#,E_#)",
        "ADD(D0,1,D0)",
        "MOV(D_#,D2)",
        "MOV(E_#,D_#)",
        "MOV(R_#,R1)",
        "MUL(E_#,3,E_#)",
        "RES(T_#)",
        "TOF(T_#,20,0)",
        "PID(P_#,R_#,R1)",
    ])
    .prop_map(str::to_string)
}

/// A rung to repeat: contacts, maybe a branch, outputs.
fn copy_body() -> impl Strategy<Value = String> {
    (
        prop::collection::vec(copy_contact(), 0..3),
        prop::option::of(prop::collection::vec(
            prop::collection::vec(copy_contact(), 1..3).prop_map(|v| v.join("")),
            2..4,
        )),
        prop::collection::vec(copy_output(), 1..4),
    )
        .prop_map(|(pre, branch, outs)| {
            let mut s = pre.join("");
            if let Some(legs) = branch {
                s.push_str(&format!("[{}]", legs.join(",")));
            }
            s + &outs.join("")
        })
}

#[cfg(feature = "jit")]
proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// `n` copies of a rung, each on tags of its own, run as strided native
    /// code (class bases in registers, constant offsets); a jump to copy
    /// `skip` enters the run in its middle.
    #[test]
    fn strided_native_code_matches_the_interpreter(
        body in copy_body(),
        n in 4usize..10,
        skip in 0usize..4,
        toggles in prop::collection::vec((0usize..4, prop::bool::ANY), 50),
    ) {
        let mut tags = TAGS.to_string();
        // Every copy has a label (a label is an op: the copies keep one shape).
        let mut lad = format!("XIC(I3)JMP(M{skip});\n");
        for k in 0..n {
            tags.push_str(&copy_tags(k));
            lad.push_str(&format!("LBL(M{k}){};\n", body.replace('#', &k.to_string())));
        }
        let p = Arc::new(compile_text(&tags, &lad).map_err(|e| TestCaseError::fail(format!("{lad}\n{e}")))?);
        let mut native = Engine::new(p.clone()).unwrap();
        native.compile_native().map_err(|e| TestCaseError::fail(e.to_string()))?;
        let (_, strided, _) = native.native_layout().unwrap();
        prop_assert!(strided >= 4, "{} rungs strided in\n{}", strided, lad);
        let mut interp = Engine::new(p.clone()).unwrap();
        for (k, (i, v)) in toggles.into_iter().enumerate() {
            for e in [&mut native, &mut interp] {
                e.write(input(&p, i), Value::Bool(v));
                e.scan(k as u64 * 10).unwrap();
            }
            prop_assert_eq!(observable(&native), observable(&interp), "scan {} of\n{}", k, lad);
            prop_assert_eq!(native.faults(), interp.faults(), "scan {} of\n{}", k, lad);
        }
    }
}

/// Timers at their edges agree in every mode, in strided runs and alone:
/// an accumulator that overflows, a zero and a negative preset, the clock
/// wrapping past 2^32 ms and a jump of more than i32::MAX ms.
#[test]
fn timers_at_the_edges_agree_in_every_mode() {
    let mut tags = String::from("name,type,address,initial\nI0,BOOL,DI:1/0,\nI1,BOOL,DI:1/1,\nI2,BOOL,DI:1/2,\n");
    let mut lad = String::new();
    for k in 0..5 {
        tags.push_str(&format!("T_{k},TIMER,,\nE_{k},DINT,,-{k}\nQ_{k},BOOL,,\n"));
    }
    // Three strided runs of five rungs.
    for k in 0..5 {
        lad.push_str(&format!("XIC(I0)MOV(2147483640,T_{k}.ACC);\n"));
    }
    for k in 0..5 {
        lad.push_str(&format!("XIO(I1)TON(T_{k},{},0)OTE(Q_{k});\n", 3 * k));
    }
    for k in 0..5 {
        lad.push_str(&format!("XIC(I2)MOV(E_{k},T_{k}.PRE);\n"));
    }
    // One more on its own (a table run).
    tags.push_str("T_x,TIMER,,\n");
    lad.push_str("XIC(I0)MOV(2147483640,T_x.ACC);\nXIO(I1)TON(T_x,25,0);\n");
    let p = Arc::new(compile_text(&tags, &lad).unwrap());
    let mut engines: Vec<Engine> = (0..3).map(|_| Engine::new(p.clone()).unwrap()).collect();
    engines[1].set_monitor(true);
    #[cfg(feature = "jit")]
    {
        engines[2].compile_native().unwrap();
        assert_eq!(
            engines[2].native_layout().map(|l| l.1),
            Some(15),
            "the copies run strided"
        );
    }
    let times = (0..30u64)
        .map(|k| k * 7)
        .chain((0..30).map(|k| (1u64 << 32) - 40 + k * 9))
        .chain((0..10).map(|k| (1u64 << 33) + 3_000_000_000 * (k % 2) + k));
    for (k, t) in times.enumerate() {
        for e in engines.iter_mut() {
            for (i, period) in [(0, 7), (1, 5), (2, 11)] {
                e.write(input(&p, i), Value::Bool(k % period == 0));
            }
            e.scan(t).unwrap();
        }
        for e in &engines[1..] {
            assert_eq!(observable(e), observable(&engines[0]), "scan {k} at {t} ms");
            assert_eq!(e.faults(), engines[0].faults(), "scan {k} at {t} ms");
        }
    }
}

/// Jumps forward and backward, and a runaway loop, agree in every mode.
/// A jump to the next rung (an ST `IF` without `ELSE` in a rung of
/// statements) inside a strided run: native code skips the rest of that
/// rung and goes on with the next one of the run, as the interpreter does.
#[cfg(feature = "jit")]
#[test]
fn a_jump_to_the_next_rung_in_a_strided_run_skips_only_the_rest_of_its_rung() {
    let n = 8;
    let mut tags = String::from("name,type\n");
    let mut lad = String::new();
    for k in 0..n {
        tags.push_str(&format!("S_{k},BOOL\nV_{k},DINT\n"));
        let label = if k > 0 {
            format!("LBL(L_{})", k - 1)
        } else {
            String::new()
        };
        lad.push_str(&format!(
            "{label}[XIC(S_{k})JMP(L_{k}),XIO(S_{k})]ADD(V_{k},1,V_{k});\n"
        ));
    }
    lad.push_str(&format!("LBL(L_{})NOP();\n", n - 1));
    let p = Arc::new(compile_text(&tags, &lad).unwrap());
    let mut engines: Vec<Engine> = (0..2).map(|_| Engine::new(p.clone()).unwrap()).collect();
    engines[1].compile_native().unwrap();
    let (_, strided, _) = engines[1].native_layout().unwrap();
    assert!(strided >= n - 2, "{strided} rungs strided");
    let place = |name: String| match p.layout.resolve(&name) {
        Ok(Target::Value { place, .. }) => place,
        other => panic!("{name}: {other:?}"),
    };
    for scan in 0..12u64 {
        for e in engines.iter_mut() {
            for k in 0..n {
                e.write(
                    place(format!("S_{k}")),
                    Value::Bool((scan + k as u64).is_multiple_of(3)),
                );
            }
            e.scan(scan * 10).unwrap();
        }
        assert_eq!(observable(&engines[1]), observable(&engines[0]), "scan {scan}");
    }
    // V_k counts the scans in which S_k was false (the jump not taken).
    for k in 0..n {
        let want = (0..12u64).filter(|s| !(s + k as u64).is_multiple_of(3)).count() as i32;
        assert_eq!(engines[1].read(place(format!("V_{k}"))), Value::Dint(want), "V_{k}");
    }
}

#[test]
fn jumps_agree_in_every_mode() {
    let tags = "name,type,address,initial\nA,BOOL,DI:1/0,\nN,DINT,,\nK,DINT,,\nQ,BOOL,DO:2/0,\nLoop,BOOL,,\n";
    let lad = "XIC(A)JMP(Skip);\nADD(N,1,N);\nLBL(Skip)XIO(A)OTE(Q);\n\
               LBL(Back)XIC(Loop)LES(K,3)ADD(K,1,K)JMP(Back);\nXIC(A)MOV(0,K);\n";
    let p = Arc::new(compile_text(tags, lad).unwrap());
    let mut engines: Vec<Engine> = (0..3).map(|_| Engine::new(p.clone()).unwrap()).collect();
    engines[1].set_monitor(true);
    #[cfg(feature = "jit")]
    engines[2].compile_native().unwrap();
    let a = match p.layout.resolve("A") {
        Ok(Target::Value { place, .. }) => place,
        _ => unreachable!(),
    };
    let lp = match p.layout.resolve("Loop") {
        Ok(Target::Value { place, .. }) => place,
        _ => unreachable!(),
    };
    for k in 0..20u64 {
        for e in engines.iter_mut() {
            e.write(a, Value::Bool(k % 5 == 0));
            e.write(lp, Value::Bool(k % 3 == 0));
            e.scan(k * 10).unwrap();
        }
        let first = observable(&engines[0]);
        for e in &engines[1..] {
            assert_eq!(observable(e), first, "scan {k}");
        }
    }
    // A loop that never ends is a major fault in every mode, at the same place.
    let lad = "LBL(Again)XIC(Loop)JMP(Again);\n";
    let p = Arc::new(compile_text(tags, lad).unwrap());
    let mut engines: Vec<Engine> = (0..3).map(|_| Engine::new(p.clone()).unwrap()).collect();
    engines[1].set_monitor(true);
    #[cfg(feature = "jit")]
    engines[2].compile_native().unwrap();
    let lp = match p.layout.resolve("Loop") {
        Ok(Target::Value { place, .. }) => place,
        _ => unreachable!(),
    };
    let faults: Vec<_> = engines
        .iter_mut()
        .map(|e| {
            e.write(lp, Value::Bool(true));
            e.scan(0).unwrap_err()
        })
        .collect();
    assert!(faults[0].message.contains("backward jumps"), "{}", faults[0].message);
    assert!(faults.iter().all(|f| f == &faults[0]), "{faults:?}");
}
