//! ST programs lowered to the IR and run by the engine, in every mode
//! (fused interpreter, monitored interpreter, native code), which must
//! agree value for value on every scan.

use alba_diag::{Diagnostic, Files, render_all};
use alba_engine::Engine;
use alba_ir::{Builder, Layout, Program, Target};
use alba_model::{TagTable, Value};
use std::sync::Arc;

/// Compiles `st` over the tags of `csv`: the program or the rendered errors.
fn build(csv: &str, st: &str) -> Result<Program, (String, Vec<Diagnostic>)> {
    let mut files = Files::new();
    let tf = files.add("tags.csv", csv);
    let sf = files.add("main.st", st);
    let (mut tags, mut diags) = TagTable::parse(files.text(tf), tf);
    let (ast, d) = alba_st::parse(files.text(sf), sf);
    diags.extend(d);
    alba_st::declare(&ast, &mut tags, &mut diags);
    let mut b = Builder::new(Layout::new(&tags, &Default::default()));
    diags.extend(alba_st::compile(&ast, "main.st", &mut b));
    if !diags.is_empty() {
        return Err((render_all(&diags, &files), diags));
    }
    Ok(b.finish(files))
}

fn program(csv: &str, st: &str) -> Program {
    build(csv, st).unwrap_or_else(|(e, _)| panic!("does not compile:\n{e}"))
}

fn errors(csv: &str, st: &str) -> String {
    match build(csv, st) {
        Ok(_) => panic!("compiled, but errors were expected"),
        Err((text, _)) => text,
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Fused,
    Monitored,
    Native,
}
const MODES: [Mode; 3] = [Mode::Fused, Mode::Monitored, Mode::Native];

fn engine(p: &Program, mode: Mode) -> Engine {
    let mut e = Engine::new(Arc::new(p.clone())).expect("verifies");
    match mode {
        Mode::Fused => {}
        Mode::Monitored => e.set_monitor(true),
        Mode::Native => e.compile_native().expect("native code"),
    }
    e
}

fn place(e: &Engine, name: &str) -> alba_ir::layout::Place {
    match e.program().layout.resolve(name) {
        Ok(Target::Value { place, .. }) => place,
        other => panic!("`{name}`: {other:?}"),
    }
}

fn get(e: &Engine, name: &str) -> Value {
    e.read(place(e, name))
}

fn set(e: &mut Engine, name: &str, v: Value) {
    let p = place(e, name);
    e.write(p, v);
}

/// Runs `script` (per scan: the writes before it) in every mode, every
/// `scan_ms`; returns the values of `watch` after each scan, checking that
/// all modes agree on them.
type Script<'a> = &'a [(u64, &'a [(&'a str, Value)])];
fn run_all(p: &Program, scan_ms: u64, scans: u64, script: Script, watch: &[&str]) -> Vec<Vec<Value>> {
    let mut results: Vec<Vec<Vec<Value>>> = Vec::new();
    for mode in MODES {
        let mut e = engine(p, mode);
        let mut rows = Vec::new();
        for k in 0..scans {
            let now = k * scan_ms;
            for (at, writes) in script {
                if *at == now {
                    for (n, v) in *writes {
                        set(&mut e, n, *v);
                    }
                }
            }
            e.scan(now)
                .unwrap_or_else(|f| panic!("{mode:?}: major fault {}", f.message));
            rows.push(watch.iter().map(|w| get(&e, w)).collect());
        }
        results.push(rows);
    }
    for (k, r) in results.iter().enumerate().skip(1) {
        assert_eq!(&results[0], r, "{:?} and {:?} disagree", MODES[0], MODES[k]);
    }
    results.swap_remove(0)
}

fn b(v: bool) -> Value {
    Value::Bool(v)
}

#[test]
fn motor_start_stop_with_an_on_delay() {
    let p = program(
        "name,type,address\nStart,BOOL,DI:1/0\nStop,BOOL,DI:1/1\nMotor,BOOL,DO:2/0\nFan,BOOL,DO:2/1\n",
        "PROGRAM Main
         VAR delay : TON; END_VAR
         Motor := (Start OR Motor) AND NOT Stop;
         delay(IN := Motor, PT := T#50ms, Q => Fan);
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        14,
        &[
            (10, &[("Start", b(true))]),
            (20, &[("Start", b(false))]),
            (110, &[("Stop", b(true))]),
        ],
        &["Motor", "Fan", "Main.delay.ACC"],
    );
    let motor: Vec<bool> = rows.iter().map(|r| r[0] == b(true)).collect();
    let fan: Vec<bool> = rows.iter().map(|r| r[1] == b(true)).collect();
    assert_eq!(
        motor,
        [
            false, true, true, true, true, true, true, true, true, true, true, false, false, false
        ]
    );
    // The fan follows 50 ms after the motor, and stops with it.
    let first_fan = fan.iter().position(|f| *f).expect("the fan starts");
    assert_eq!(first_fan, 6, "{fan:?}");
    assert!(!fan[11], "the fan stops with the motor");
}

#[test]
fn loops_and_selection_compute_what_the_standard_says() {
    let p = program(
        "name,type\nSum,DINT\nFact,DINT\nOdd,DINT\nSel,INT\nWhileN,INT\nRep,INT\nMx,REAL\n",
        "PROGRAM Main
         VAR i : INT; k : DINT := 1; END_VAR
         Sum := 0;
         FOR i := 1 TO 10 DO Sum := Sum + i; END_FOR;
         Fact := 1; k := 1;
         WHILE k <= 6 DO Fact := Fact * k; k := k + 1; END_WHILE;
         Odd := 0;
         FOR i := 9 TO 1 BY -2 DO
           IF i = 3 THEN EXIT; END_IF;
           Odd := Odd * 10 + i;
         END_FOR;
         CASE Odd MOD 7 OF
           0: Sel := 100;
           1..3, 5: Sel := 200;
         ELSE Sel := 300;
         END_CASE;
         WhileN := 0;
         REPEAT WhileN := WhileN + 3; UNTIL WhileN > 10 END_REPEAT;
         Rep := LIMIT(0, WhileN * 20, 100) + MIN(4, 2, 8) + SEL(TRUE, 1, 1000) + MUX(2, 5, 6, 7);
         Mx := MAX(1.5, INT_TO_REAL(i), 2.0) + SQRT(16.0) + EXPT(2.0, 3.0);
         IF Sum = 55 AND NOT (Fact <> 720) THEN ; ELSE Sel := -1; END_IF;
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 2, &[], &["Sum", "Fact", "Odd", "Sel", "WhileN", "Rep", "Mx"]);
    let want = [
        Value::Dint(55),
        Value::Dint(720),
        Value::Dint(975),
        // 975 MOD 7 = 2
        Value::Int(200),
        Value::Int(12),
        // LIMIT(0,240,100)=100, MIN=2, SEL(TRUE)=1000, MUX(2)=7
        Value::Int(1109),
        // i ended at 3 (EXIT): MAX(1.5, 3.0, 2.0) + 4 + 8
        Value::Real(15.0),
    ];
    assert_eq!(rows[1], want);
}

#[test]
fn arrays_with_computed_indexes_and_their_faults() {
    let p = program(
        "name,type\nIx,INT\nOut,DINT\nFlag,BOOL\nQ,DINT\nD,DINT\n",
        "PROGRAM Main
         VAR a : ARRAY[1..5] OF DINT := [10, 20, 3(7)]; m : ARRAY[0..1, 1..2] OF BOOL; END_VAR
         a[Ix] := a[Ix] + 1;
         Out := a[1] * 1000 + a[2] * 10 + a[5];
         m[1, Ix] := TRUE;
         Flag := m[1, 2];
         Q := 100 / D;
         END_PROGRAM",
    );
    for mode in MODES {
        let mut e = engine(&p, mode);
        set(&mut e, "Ix", Value::Int(2));
        set(&mut e, "D", Value::Dint(4));
        e.scan(0).expect("scan");
        assert_eq!(get(&e, "Out"), Value::Dint(10 * 1000 + 21 * 10 + 7), "{mode:?}");
        assert_eq!(get(&e, "Flag"), b(true), "{mode:?}");
        assert_eq!(get(&e, "Q"), Value::Dint(25), "{mode:?}");
        assert_eq!(e.faults().count, 0, "{mode:?}");
        // Out of range: a fault, nothing written, and the scan goes on.
        set(&mut e, "Ix", Value::Int(6));
        e.scan(10).expect("scan");
        assert!(e.faults().count >= 1, "{mode:?}: no fault for a[6]");
        assert_eq!(get(&e, "Out"), Value::Dint(10 * 1000 + 21 * 10 + 7), "{mode:?}");
        assert_eq!(get(&e, "Main.a[5]"), Value::Dint(7), "{mode:?}");
        // Division by zero: a fault as in Ladder.
        let before = e.faults().count;
        set(&mut e, "Ix", Value::Int(1));
        set(&mut e, "D", Value::Dint(0));
        e.scan(20).expect("scan");
        assert!(e.faults().count > before, "{mode:?}: no fault for 100 / 0");
        let f = e.faults().last.expect("a fault");
        let at = e.describe_fault(&f);
        assert!(at.contains("main.st"), "{mode:?}: {at}");
    }
}

#[test]
fn standard_function_blocks() {
    let p = program(
        "name,type\nIn,BOOL\nRst,BOOL\nUp,BOOL\nCv,INT\nCq,BOOL\nDq,BOOL\nRise,BOOL\nFall,BOOL\nLatch,BOOL\nPulse,BOOL\nOff,BOOL\n",
        "PROGRAM Main
         VAR c : CTU; d : CTD; r : R_TRIG; f : F_TRIG; s : SR; p : TP; o : TOF; END_VAR
         c(CU := In, R := Rst, PV := 3, Q => Cq, CV => Cv);
         d(CD := In, LD := Rst, PV := 2);
         Dq := d.Q;
         r(CLK := In);
         Rise := r.Q;
         f(CLK := In, Q => Fall);
         s(S1 := Up, R := Rst, Q1 => Latch);
         p(IN := In, PT := T#30ms, Q => Pulse);
         o(IN := In, PT := T#20ms, Q => Off);
         END_PROGRAM",
    );
    let t = |v| Value::Bool(v);
    let rows = run_all(
        &p,
        10,
        16,
        &[
            (0, &[("In", t(true)), ("Up", t(true))]),
            (10, &[("In", t(false)), ("Up", t(false))]),
            (20, &[("In", t(true))]),
            (30, &[("In", t(false))]),
            (40, &[("In", t(true))]),
            (70, &[("In", t(false)), ("Rst", t(true))]),
            (80, &[("Rst", t(false))]),
        ],
        &["Cv", "Cq", "Rise", "Fall", "Latch", "Dq", "Pulse", "Off"],
    );
    let col = |k: usize| rows.iter().map(|r| r[k]).collect::<Vec<_>>();
    let ints: Vec<i64> = col(0).iter().map(|v| v.as_f64() as i64).collect();
    // Rising edges of CU at 0, 20 and 40 ms (held through 70 ms); R at 70 ms.
    assert_eq!(&ints[..9], &[1, 1, 2, 2, 3, 3, 3, 0, 0], "CV");
    let bools = |k| col(k).iter().map(|v| *v == Value::Bool(true)).collect::<Vec<_>>();
    assert_eq!(
        &bools(1)[..9],
        &[false, false, false, false, true, true, true, false, false],
        "CTU.Q"
    );
    // R_TRIG fires on the first scan when CLK is already true, once while held.
    assert_eq!(
        &bools(2)[..9],
        &[true, false, true, false, true, false, false, false, false],
        "R_TRIG.Q"
    );
    assert_eq!(
        &bools(3)[..9],
        &[false, true, false, true, false, false, false, true, false],
        "F_TRIG.Q"
    );
    assert_eq!(
        &bools(4)[..9],
        &[true, true, true, true, true, true, true, false, false],
        "SR.Q1"
    );
    // CTD from 0 (no load yet): at or below 0 -> Q.
    assert!(bools(5)[0], "CTD.Q");
    // TP: a 30 ms pulse from the first rising edge, not retriggered meanwhile.
    assert_eq!(&bools(6)[..4], &[true, true, true, false], "TP.Q");
    // TOF: true while IN, and 20 ms after it falls.
    assert!(bools(7)[0] && bools(7)[1], "TOF.Q");
    assert!(!bools(7)[12], "TOF.Q after the delay");
}

#[test]
fn the_checker_names_both_types_and_suggests_names() {
    let e = errors(
        "name,type\nLevel,REAL\nCount,DINT\n",
        "PROGRAM Main
         VAR i : INT; ok : BOOL; t : TON; END_VAR
         i := Level;
         Count := Cuont + 1;
         ok := i;
         t(IN := ok, PT := 5);
         ok := t.DN;
         IF i THEN ; END_IF;
         Count := Count / 2.5;
         Level := SQRT(i);
         EXIT;
         END_PROGRAM",
    );
    for want in [
        "error[E221]: cannot assign a REAL to `i`, an INT",
        "error[E222]: unknown name `Cuont`",
        "did you mean `Count`?",
        "cannot assign an INT to `ok`, a BOOL",
        "TON.PT is a TIME, not a DINT",
        "TON has no member `DN`",
        "a condition is BOOL, not INT",
        "`/` of DINT and REAL: the types differ",
        "SQRT takes a REAL or LREAL, not INT",
        "error[E224]: EXIT is only allowed inside FOR, WHILE or REPEAT",
        "main.st:3:",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}

#[test]
fn inputs_constants_and_unsupported_features_are_refused_at_their_place() {
    let e = errors(
        "name,type,address\nStart,BOOL,DI:1/0\n",
        "PROGRAM Main
         VAR CONSTANT k : INT := 3; END_VAR
         VAR s : STRING; w : LTIME; x : INT; a : ARRAY[1..2] OF INT; END_VAR
         Start := TRUE;
         k := 4;
         x := LEN(x);
         a[3] := 1;
         END_PROGRAM",
    );
    for want in [
        "error[E304]: `Start` cannot be written: it is an input",
        "`k` is CONSTANT",
        "LEN takes a STRING, not an INT",
        "the index 3 is outside the bounds 1..2",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}

#[test]
fn narrowing_overflows_fault_and_wrap_like_ladder() {
    let p = program(
        "name,type\nX,INT\nY,SINT\n",
        "PROGRAM Main
         X := X + 16000;
         Y := DINT_TO_SINT(INT_TO_DINT(X) / 1000);
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 3, &[], &["X", "Y"]);
    assert_eq!(rows[0], [Value::Int(16000), Value::Sint(16)]);
    assert_eq!(rows[1], [Value::Int(32000), Value::Sint(32)]);
    // 48000 wraps to 48000 - 65536.
    assert_eq!(rows[2][0], Value::Int(-17536));
    let mut e = engine(&p, Mode::Fused);
    for k in 0..3 {
        e.scan(k * 10).expect("scan");
    }
    assert!(e.faults().count >= 1, "the overflow is a fault");
}

#[test]
fn a_runaway_loop_is_a_major_fault_not_a_hang() {
    let p = program(
        "name,type\nN,DINT\n",
        "PROGRAM Main WHILE TRUE DO N := N + 1; END_WHILE; END_PROGRAM",
    );
    for mode in MODES {
        let mut e = engine(&p, mode);
        let r = e.scan(0);
        assert!(r.is_err(), "{mode:?}: an endless loop must stop the scan");
    }
}

/// 10 000 lines of ST parsed, checked and lowered; prints the time (debug
/// builds are slower than release; tests never assert wall-clock time).
#[test]
fn ten_thousand_lines_compile_and_the_time_is_printed() {
    let mut src = String::from("PROGRAM Big\nVAR i, n : DINT; a : ARRAY[0..99] OF DINT; t : TON; END_VAR\n");
    for k in 0..2_500 {
        src.push_str(&format!("n := n + {k} MOD 7;\n"));
        src.push_str(&format!(
            "IF n > {k} THEN a[n MOD 100] := a[{}] - 1; END_IF;\n",
            k % 100
        ));
        src.push_str("t(IN := n > 3, PT := T#1s);\n");
        src.push_str("CASE n MOD 4 OF 0: i := 1; 1..2: i := 2; ELSE i := 3; END_CASE;\n");
    }
    src.push_str("END_PROGRAM\n");
    let lines = src.lines().count();
    assert!(lines >= 10_000);
    let start = std::time::Instant::now();
    let p = program("name,type\n", &src);
    let took = start.elapsed();
    println!(
        "{lines} lines of ST: parse, check and lower in {took:?} ({} ops)",
        p.ops.len()
    );
    let mut e = engine(&p, Mode::Fused);
    e.scan(0).expect("scan");
    assert!(p.ops.len() > lines);
}

const USER_POUS: &str = "
FUNCTION_BLOCK Counter
VAR_INPUT up : BOOL; step : INT := 1; END_VAR
VAR_OUTPUT n : INT; END_VAR
VAR edge : R_TRIG; calls : DINT; END_VAR
edge(CLK := up);
IF edge.Q THEN n := n + step; END_IF;
calls := calls + 1;
END_FUNCTION_BLOCK

FUNCTION_BLOCK Pair
VAR_INPUT x : BOOL; END_VAR
VAR_OUTPUT total : INT; END_VAR
VAR a, b : Counter; END_VAR
a(up := x);
b(up := NOT x, step := 10);
total := a.n + b.n;
END_FUNCTION_BLOCK

FUNCTION Scale : DINT
VAR_INPUT v : DINT; k : DINT; END_VAR
VAR_OUTPUT twice : DINT; END_VAR
VAR tmp : DINT; END_VAR
tmp := v * k;
twice := tmp * 2;
IF v < 0 THEN Scale := 0; RETURN; END_IF;
Scale := tmp;
END_FUNCTION

FUNCTION Swap : BOOL
VAR_IN_OUT a, b : INT; END_VAR
VAR t : INT; END_VAR
t := a; a := b; b := t;
Swap := TRUE;
END_FUNCTION

FUNCTION Fact : DINT
VAR_INPUT n : INT; END_VAR
VAR i : INT; END_VAR
Fact := 1;
FOR i := 2 TO n DO Fact := Fact * i; END_FOR;
END_FUNCTION

PROGRAM Main
VAR c1 : Counter; c2 : Counter := (step := 7); p : Pair; dbl : DINT; END_VAR
c1(up := In);
c2(In, 5);
p(x := In, total => Total);
N1 := c1.n; N2 := c2.n;
S := Scale(INT_TO_DINT(N2), 3, twice => dbl);
Tw := dbl;
Neg := Scale(v := -4, k := 2);
A := 1; B := 2;
Swap(A, B);
F := Fact(5) + Fact(DINT_TO_INT(Fact(3)) - 3);
END_PROGRAM
";

#[test]
fn user_function_blocks_keep_state_per_instance_and_functions_are_inlined() {
    let p = program(
        "name,type\nIn,BOOL\nN1,INT\nN2,INT\nTotal,INT\nS,DINT\nTw,DINT\nNeg,DINT\nA,INT\nB,INT\nF,DINT\n",
        USER_POUS,
    );
    let rows = run_all(
        &p,
        10,
        3,
        &[
            (0, &[("In", b(true))]),
            (10, &[("In", b(false))]),
            (20, &[("In", b(true))]),
        ],
        &[
            "N1",
            "N2",
            "Total",
            "S",
            "Tw",
            "Neg",
            "A",
            "B",
            "F",
            "Main.c1.calls",
            "Main.p.b.n",
            "Main.c1.edge.Q",
        ],
    );
    let i = Value::Int;
    let d = Value::Dint;
    // c1 counts rising edges (scans 0 and 2), c2 by 5; p.b counts the
    // rising edges of NOT x (scan 1) by 10.
    assert_eq!(
        rows[0],
        [
            i(1),
            i(5),
            i(1),
            d(15),
            d(30),
            d(0),
            i(2),
            i(1),
            d(126),
            d(1),
            i(0),
            b(true)
        ]
    );
    assert_eq!(
        rows[1],
        [
            i(1),
            i(5),
            i(11),
            d(15),
            d(30),
            d(0),
            i(2),
            i(1),
            d(126),
            d(2),
            i(10),
            b(false)
        ]
    );
    assert_eq!(
        rows[2],
        [
            i(2),
            i(10),
            i(12),
            d(30),
            d(60),
            d(0),
            i(2),
            i(1),
            d(126),
            d(3),
            i(10),
            b(true)
        ]
    );
}

#[test]
fn user_function_blocks_nest_standard_timers_with_their_own_state() {
    let p = program(
        "name,type\nGo,BOOL\nQ1,BOOL\nQ2,BOOL\nEt,TIME\n",
        "FUNCTION_BLOCK Delay
         VAR_INPUT in : BOOL; pt : TIME; END_VAR
         VAR_OUTPUT q : BOOL; et : TIME; END_VAR
         VAR t : TON; END_VAR
         t(IN := in, PT := pt, Q => q, ET => et);
         END_FUNCTION_BLOCK
         PROGRAM Main
         VAR d1, d2 : Delay; END_VAR
         d1(in := Go, pt := T#20ms, q => Q1, et => Et);
         d2(in := Go, pt := T#40ms);
         Q2 := d2.q;
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        7,
        &[(0, &[("Go", b(true))])],
        &["Q1", "Q2", "Et", "Main.d2.t.ACC"],
    );
    let q1: Vec<bool> = rows.iter().map(|r| r[0] == b(true)).collect();
    let q2: Vec<bool> = rows.iter().map(|r| r[1] == b(true)).collect();
    assert_eq!(q1, [false, false, true, true, true, true, true]);
    assert_eq!(q2, [false, false, false, false, true, true, true]);
    assert_eq!(rows[2][2], Value::Time(20));
    assert_eq!(rows[3][3], Value::Dint(30));
}

#[test]
fn user_pou_bodies_are_checked_and_recursion_is_refused_at_its_place() {
    let e = errors(
        "name,type\nLevel,REAL\nCount,DINT\n",
        "FUNCTION Again : DINT
         VAR_INPUT n : DINT; END_VAR
         Again := Again(n - 1);
         END_FUNCTION
         FUNCTION Unused : INT
         VAR_INPUT x : INT; END_VAR
         Unused := Levle;
         END_FUNCTION
         FUNCTION_BLOCK Box
         VAR_INPUT x : INT; END_VAR
         VAR_OUTPUT y : BOOL; END_VAR
         VAR inner : INT; END_VAR
         y := x;
         END_FUNCTION_BLOCK
         FUNCTION Sw : BOOL
         VAR_IN_OUT a : INT; END_VAR
         a := 1;
         END_FUNCTION
         PROGRAM Main
         VAR b : Box; k : INT; END_VAR
         Count := Again(3);
         b(xx := 1);
         b(x := 1);
         k := b.inner;
         Box(x := 2);
         Sw();
         Count := Sacle(2);
         END_PROGRAM",
    );
    for want in [
        "error[E223]: `Again` calls itself (again → again): calls are inlined, so recursion is not supported",
        "main.st:3:",
        "unknown name `Levle`",
        "did you mean `Level`?",
        "cannot assign an INT to `y`, a BOOL",
        "Box has no input `xx`",
        "did you mean `x`?",
        "`inner` is a VAR of Box: only its inputs and outputs are seen from outside",
        "`Box` is a FUNCTION_BLOCK type: declare an instance",
        "the VAR_IN_OUT `a` of Sw must be given a variable",
        "unknown function `Sacle`",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
    // A body inlined twice reports its error once.
    assert_eq!(e.matches("cannot assign an INT to `y`").count(), 1, "{e}");
}

const TYPES: &str = "
TYPE
  Point : STRUCT x : INT; y : INT := 7; END_STRUCT;
  Color : (Red, Green := 5, Blue);
  Pct : INT(0..100);
  Seg : STRUCT a, b : Point; c : Color; END_STRUCT;
END_TYPE
";

#[test]
fn structures_enumerations_and_subranges_run_in_every_mode() {
    let src = format!(
        "{TYPES}
         FUNCTION_BLOCK Mover
         VAR_IN_OUT p : Point; END_VAR
         VAR_INPUT d : INT; END_VAR
         p.x := p.x + d;
         END_FUNCTION_BLOCK
         FUNCTION Len2 : DINT
         VAR_INPUT p : Point; END_VAR
         Len2 := INT_TO_DINT(p.x) * p.x + INT_TO_DINT(p.y) * p.y;
         END_FUNCTION
         PROGRAM Main
         VAR p, q : Point := (x := 1); s : Seg; c : Color; pct : Pct; m : Mover; cnt : INT; END_VAR
         m(p := p, d := 2);
         q := p;
         s.a := q; s.b.y := 3;
         c := Color#Blue;
         cnt := 0;
         IF c = Blue THEN cnt := 1; END_IF;
         CASE c OF Red: cnt := cnt + 10; Green, Blue: cnt := cnt + 100; END_CASE;
         pct := Want;
         X := q.x; Y := s.a.y; L := Len2(q);
         Pv := pct;
         N := cnt;
         END_PROGRAM"
    );
    let p = program("name,type\nWant,INT\nX,INT\nY,INT\nL,DINT\nPv,INT\nN,INT\n", &src);
    let rows = run_all(
        &p,
        10,
        3,
        &[
            (0, &[("Want", Value::Int(50))]),
            (10, &[("Want", Value::Int(150))]),
            (20, &[("Want", Value::Int(-1))]),
        ],
        &[
            "X",
            "Y",
            "L",
            "Pv",
            "N",
            "Main.c",
            "Main.s.b.y",
            "Main.s.b.x",
            "Main.p.y",
            "Main.s.c",
        ],
    );
    let i = Value::Int;
    let d = Value::Dint;
    assert_eq!(
        rows[0],
        [i(3), i(7), d(58), i(50), i(101), d(6), i(3), i(0), i(7), d(0)]
    );
    // Out of the subrange: a fault, and the variable keeps its value.
    assert_eq!(rows[1][..5], [i(5), i(7), d(74), i(50), i(101)]);
    assert_eq!(rows[2][..5], [i(7), i(7), d(98), i(50), i(101)]);
    for mode in MODES {
        let mut e = engine(&p, mode);
        set(&mut e, "Want", Value::Int(50));
        e.scan(0).expect("scan");
        assert_eq!(e.faults().count, 0, "{mode:?}");
        set(&mut e, "Want", Value::Int(101));
        e.scan(10).expect("scan");
        assert!(e.faults().count >= 1, "{mode:?}: no fault out of the subrange");
        assert_eq!(get(&e, "Main.pct"), Value::Int(50), "{mode:?}");
    }
}

#[test]
fn structure_enumeration_and_subrange_errors_are_located() {
    let e = errors(
        "name,type\nN,DINT\n",
        &format!(
            "{TYPES}
             PROGRAM Main
             VAR p : Point; s : Seg; c : Color; k : Pct := 200; END_VAR
             c := c + 1;
             c := 1;
             p.z := 1;
             p := s;
             c := Color#Pink;
             N := p;
             END_PROGRAM"
        ),
    );
    for want in [
        "`+` of Color and DINT: the types differ",
        "cannot assign a DINT to `c`, a Color",
        "Point has no member `z`",
        "cannot assign a Seg to `p`, a Point",
        "the enumeration Color has no value `Pink`",
        "the initial value `200` is not an INT(0..100) literal",
        "`p` is a whole Point; read a member",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}

#[test]
fn bit_strings_and_unsigned_integers_shift_rotate_and_wrap() {
    let p = program(
        "name,type\nN,INT\n",
        "PROGRAM Main
         VAR b : BYTE := 16#A5; u : USINT := 250;
             b1, b2, b3, b4, b5 : BYTE; w1 : WORD; d1 : DWORD; l1, l2, l3 : LWORD;
             u1 : USINT; ui : UINT; ud : UDINT; i1 : INT; i2 : DINT; ok : BOOL;
         END_VAR
         b1 := SHL(b, 1);
         b2 := ROL(b, 1);
         b3 := ROR(b, N);
         b4 := NOT b AND 16#0F;
         b5 := b XOR BYTE#16#FF;
         w1 := SHL(WORD#16#00FF, N) OR 1;
         d1 := SHR(DWORD#16#8000_0000, N) OR DWORD#16#F;
         l1 := ROL(SHL(LWORD#1, 63) OR 1, 1);
         l2 := SHR(SHL(LWORD#1, 63), 60);
         l3 := ROR(LWORD#1, N);
         u1 := u + 10;
         ui := INT_TO_UINT(-1) - 1;
         ud := UDINT#4000000000 + UDINT#1000000000;
         i1 := BYTE_TO_INT(b) + USINT_TO_INT(u1);
         i2 := UINT_TO_DINT(ui) + u;
         ok := (b AND 16#80) <> 0 AND w1 > 2000;
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        2,
        &[(0, &[("N", Value::Int(3))])],
        &[
            "Main.b1", "Main.b2", "Main.b3", "Main.b4", "Main.b5", "Main.w1", "Main.d1", "Main.l1", "Main.l2",
            "Main.l3", "Main.u1", "Main.ui", "Main.ud", "Main.i1", "Main.i2", "Main.ok",
        ],
    );
    let (i, d, l) = (Value::Int, Value::Dint, Value::Lint);
    assert_eq!(
        rows[1],
        [
            i(0x4A),
            i(0x4B),
            i(0xB4),
            i(0x0A),
            i(0x5A),
            d(0x07F9),
            l(0x1000_000F),
            l(3),
            l(8),
            l(1 << 61),
            i(4),
            d(65534),
            l(705_032_704),
            i(0xA5 + 4),
            d(65534 + 250),
            b(true),
        ]
    );
}

#[test]
fn bit_string_errors_name_the_types() {
    let e = errors(
        "name,type\nN,INT\n",
        "PROGRAM Main
         VAR b : BYTE; w : WORD; x : INT; u : USINT; END_VAR
         b := b + 1;
         x := SHL(x, 1);
         b := w;
         x := b;
         x := x AND 3;
         u := -u;
         END_PROGRAM",
    );
    for want in [
        "`+` does not take bit strings (BYTE)",
        "SHL shifts a bit string (BYTE … LWORD), not an INT",
        "cannot assign a WORD to `b`, a BYTE",
        "cannot assign a BYTE to `x`, an INT",
        "AND takes BOOL operands or bit strings (BYTE … LWORD) of one type, not INT and INT",
        "`-` takes a number, not a USINT",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}

#[test]
fn arrays_pass_by_value_instances_pass_in_out_and_local_enumerations_run() {
    let p = program(
        "name,type\nS,DINT\nH0,DINT\nH1,DINT\nM,INT\n",
        "FUNCTION Sum3 : DINT
         VAR_INPUT a : ARRAY[1..3] OF DINT; END_VAR
         VAR i : INT; END_VAR
         FOR i := 1 TO 3 DO Sum3 := Sum3 + a[i]; END_FOR;
         a[1] := 100;
         END_FUNCTION
         FUNCTION_BLOCK Acc
         VAR_INPUT x : DINT; END_VAR
         VAR_OUTPUT hist : ARRAY[0..1] OF DINT; END_VAR
         hist[1] := hist[0]; hist[0] := x;
         END_FUNCTION_BLOCK
         FUNCTION_BLOCK Bump
         VAR_IN_OUT c : Acc; END_VAR
         c(x := c.hist[0] + 1);
         END_FUNCTION_BLOCK
         PROGRAM Main
         VAR v : ARRAY[1..3] OF DINT := [1, 2, 3]; h : ARRAY[0..1] OF DINT; acc : Acc; b : Bump;
             mode : (Idle, Run, Halt) := Run; END_VAR
         S := Sum3(v) + v[1];
         b(c := acc);
         acc(hist => h);
         H0 := h[0]; H1 := h[1];
         M := 0;
         IF mode = Run THEN M := 1; END_IF;
         CASE mode OF Idle: M := 10; Run: M := M + 20; END_CASE;
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 2, &[], &["S", "H0", "H1", "M"]);
    let d = Value::Dint;
    // Sum3 works on a copy: v[1] stays 1.
    assert_eq!(rows[0], [d(7), d(1), d(1), Value::Int(21)]);
    assert_eq!(rows[1], [d(7), d(2), d(2), Value::Int(21)]);
}

#[test]
fn bits_of_integers_and_bit_strings_read_and_write() {
    let p = program(
        "name,type\nFlags,DINT\nIn,BOOL\nS,SINT\nB3,BOOL\nTop,BOOL\n",
        "PROGRAM Main
         VAR w : WORD := 16#0100; l : LWORD; i : INT := -1; END_VAR
         Flags.3 := In;
         Flags.31 := In;
         S.7 := TRUE;
         S.0 := NOT S.0;
         w.0 := w.8;
         w.8 := FALSE;
         l.63 := TRUE;
         Top := l.63 AND NOT l.62;
         i.15 := FALSE;
         B3 := Flags.3;
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        2,
        &[(0, &[("In", b(true))]), (10, &[("In", b(false))])],
        &["Flags", "S", "B3", "Top", "Main.w", "Main.l", "Main.i"],
    );
    assert_eq!(
        rows[0],
        [
            Value::Dint(i32::MIN | 8),
            Value::Sint(-127),
            b(true),
            b(true),
            Value::Dint(1),
            Value::Lint(i64::MIN),
            Value::Int(i16::MAX),
        ]
    );
    assert_eq!(rows[1][..3], [Value::Dint(0), Value::Sint(-128), b(false)]);
    let e = errors(
        "name,type\nN,INT\n",
        "PROGRAM Main VAR b : BYTE; r : REAL; END_VAR b.8 := TRUE; N.1 := 1; r.0 := TRUE; END_PROGRAM",
    );
    for want in [
        "`b` is a BYTE: its bits are `.0` to `.7`, not `.8`",
        "a bit is a BOOL, not a DINT",
        "`r` is a REAL; it has no members",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}

#[test]
fn a_fault_inside_an_inlined_body_points_at_the_callee_line() {
    let p = program(
        "name,type\nD,DINT\nQ,DINT\n",
        "FUNCTION Ratio : DINT
         VAR_INPUT a, b : DINT; END_VAR
         Ratio := a / b;
         END_FUNCTION
         PROGRAM Main
         Q := Ratio(100, D);
         END_PROGRAM",
    );
    for mode in MODES {
        let mut e = engine(&p, mode);
        set(&mut e, "D", Value::Dint(4));
        e.scan(0).expect("scan");
        assert_eq!(get(&e, "Q"), Value::Dint(25), "{mode:?}");
        set(&mut e, "D", Value::Dint(0));
        e.scan(10).expect("scan");
        let f = e.faults().last.expect("a fault");
        let at = e.describe_fault(&f);
        assert!(at.contains("(3:10 `Ratio := a / b;`)"), "{mode:?}: {at}");
    }
    let e = errors(
        "name,type\nX,BOOL\n",
        "PROGRAM Main VAR t : TON; END_VAR X := t(IN := TRUE); END_PROGRAM",
    );
    assert!(
        e.contains("`t` is a function block instance: call it as a statement"),
        "{e}"
    );
}

#[test]
fn arrays_of_structures_with_constant_and_computed_indexes() {
    let p = program(
        "name,type\nIx,INT\nSum,DINT\nHot,BOOL\n",
        "TYPE Zone : STRUCT temp : INT; on : BOOL; lim : INT := 50; END_STRUCT; END_TYPE
         FUNCTION Hottest : INT
         VAR_INPUT z : ARRAY[1..3] OF Zone; END_VAR
         VAR i : INT; END_VAR
         FOR i := 1 TO 3 DO Hottest := MAX(Hottest, z[i].temp); END_FOR;
         END_FUNCTION
         PROGRAM Main
         VAR zs : ARRAY[1..3] OF Zone := [(temp := 10), (temp := 20, lim := 15)]; k : INT; first : Zone; h : INT; END_VAR
         zs[Ix].temp := zs[Ix].temp + 5;
         zs[3].on := TRUE;
         first := zs[1];
         Sum := 0;
         FOR k := 1 TO 3 DO
           Sum := Sum + zs[k].temp;
           IF zs[k].temp > zs[k].lim THEN Hot := TRUE; END_IF;
         END_FOR;
         h := Hottest(zs);
         zs[2] := first;
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        2,
        &[(0, &[("Ix", Value::Int(2))])],
        &[
            "Sum",
            "Hot",
            "Main.zs[2].temp",
            "Main.zs[3].on",
            "Main.first.temp",
            "Main.h",
            "Main.zs[2].lim",
        ],
    );
    let i = Value::Int;
    // Scan 0: zs[2].temp 20 → 25 (above its limit 15), then zs[2] := zs[1].
    assert_eq!(rows[0], [Value::Dint(35), b(true), i(10), b(true), i(10), i(25), i(50)]);
    assert_eq!(rows[1], [Value::Dint(25), b(true), i(10), b(true), i(10), i(15), i(50)]);
    for mode in MODES {
        let mut e = engine(&p, mode);
        set(&mut e, "Ix", Value::Int(4));
        e.scan(0).expect("scan");
        assert!(e.faults().count >= 1, "{mode:?}: no fault for zs[4]");
    }
}

#[test]
fn function_block_temps_externals_and_inputs_set_from_outside() {
    let p = program(
        "name,type\nOut,INT\nG,DINT\n",
        "VAR_GLOBAL Limit : INT := 3; END_VAR
         FUNCTION_BLOCK Step
         VAR_INPUT go : BOOL; END_VAR
         VAR_OUTPUT n : INT; END_VAR
         VAR_TEMP t : INT := 10; END_VAR
         VAR_EXTERNAL Limit : INT; G : DINT; END_VAR
         t := t + 1;
         IF go AND n < Limit THEN n := n + t - 10; END_IF;
         G := G + 1;
         END_FUNCTION_BLOCK
         PROGRAM Main
         VAR s : Step; END_VAR
         s.go := TRUE;
         s();
         Out := s.n;
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 5, &[], &["Out", "G", "Main.s.t", "Main.s.go"]);
    let outs: Vec<Value> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(outs, [1, 2, 3, 3, 3].map(Value::Int));
    assert_eq!(rows[4][1], Value::Dint(5));
    assert_eq!(rows[4][2], Value::Int(11));
    assert_eq!(rows[4][3], b(true));
    let e = errors(
        "name,type\n",
        "FUNCTION_BLOCK Step VAR_OUTPUT n : INT; END_VAR n := 1; END_FUNCTION_BLOCK
         PROGRAM Main VAR s : Step; END_VAR s.n := 2; END_PROGRAM",
    );
    assert!(e.contains("error[E304]: `s.n` cannot be written"), "{e}");
}

/// Classic bit-twiddling functions (written here, in the style of the
/// OSCAT library) give their well-known results in every mode.
#[test]
fn bit_functions_written_in_st_give_known_results() {
    let p = program(
        "name,type\nX,DINT\n",
        "FUNCTION BitCount : INT
         VAR_INPUT in : DWORD; END_VAR
         WHILE in <> 0 DO
           IF in.0 THEN BitCount := BitCount + 1; END_IF;
           in := SHR(in, 1);
         END_WHILE;
         END_FUNCTION
         FUNCTION Reverse : BYTE
         VAR_INPUT in : BYTE; END_VAR
         VAR i : INT; END_VAR
         FOR i := 0 TO 7 DO
           Reverse := SHL(Reverse, 1) OR (in AND 1);
           in := SHR(in, 1);
         END_FOR;
         END_FUNCTION
         FUNCTION GrayToBin : WORD
         VAR_INPUT g : WORD; END_VAR
         GrayToBin := g;
         WHILE g <> 0 DO
           g := SHR(g, 1);
           GrayToBin := GrayToBin XOR g;
         END_WHILE;
         END_FUNCTION
         FUNCTION Crc8 : BYTE
         VAR_IN_OUT data : ARRAY[0..3] OF BYTE; END_VAR
         VAR i, k : INT; END_VAR
         FOR i := 0 TO 3 DO
           Crc8 := Crc8 XOR data[i];
           FOR k := 1 TO 8 DO
             IF Crc8.7 THEN Crc8 := SHL(Crc8, 1) XOR 16#07; ELSE Crc8 := SHL(Crc8, 1); END_IF;
           END_FOR;
         END_FOR;
         END_FUNCTION
         PROGRAM Main
         VAR bc : INT; rv : BYTE; gb : WORD; crc : BYTE; d : ARRAY[0..3] OF BYTE := [16#31, 16#32, 16#33, 16#34];
             r1, r2 : DWORD; END_VAR
         bc := BitCount(DINT_TO_DWORD(X));
         rv := Reverse(16#01) OR Reverse(16#30);
         gb := GrayToBin(2#1101);
         crc := Crc8(d);
         r1 := ROL(DWORD#16#8000_0001, 4);
         r2 := ROR(DWORD#16#8000_0001, 4);
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        1,
        &[(0, &[("X", Value::Dint(-1))])],
        &["Main.bc", "Main.rv", "Main.gb", "Main.crc", "Main.r1", "Main.r2"],
    );
    assert_eq!(
        rows[0],
        [
            Value::Int(32),
            // 0x01 reversed is 0x80, 0x30 reversed is 0x0C.
            Value::Int(0x8C),
            // Gray 1101 is binary 1001.
            Value::Dint(0b1001),
            // CRC-8 (polynomial 0x07, initial 0) of "1234".
            Value::Int(0xC2),
            Value::Lint(0x18),
            Value::Lint(0x1800_0000),
        ]
    );
}

/// The parse golden of user POUs also checks, lowers and runs alike in every mode.
#[test]
fn the_user_pous_golden_runs() {
    let src = include_str!("parse/user_pous.st");
    let p = program("name,type\nStart,BOOL\nSmall,INT\nCount,DINT\n", src);
    let rows = run_all(
        &p,
        10,
        4,
        &[
            (0, &[("Start", b(true))]),
            (10, &[("Start", b(false))]),
            (20, &[("Start", b(true))]),
        ],
        &["Small", "Count", "Main.pt.x", "Main.zs[1].x", "Main.w", "Main.pc"],
    );
    // k stays 0: zs[0] is out of range (a fault, nothing written).
    assert_eq!(
        rows[3],
        [
            Value::Int(2),
            Value::Dint(6),
            Value::Int(3),
            Value::Int(0),
            Value::Dint(0x80F1),
            Value::Int(100)
        ]
    );
}

#[test]
fn arrays_of_function_block_instances_called_by_constant_and_computed_index() {
    let p = program(
        "name,type\nRun,BOOL\nDone,INT\nEdges,INT\nFirst,BOOL\n",
        "FUNCTION_BLOCK Edge
         VAR_INPUT x : BOOL; END_VAR
         VAR_OUTPUT n : INT; END_VAR
         VAR r : R_TRIG; END_VAR
         r(CLK := x);
         IF r.Q THEN n := n + 1; END_IF;
         END_FUNCTION_BLOCK
         PROGRAM Main
         VAR t : ARRAY[1..3] OF TON; e : ARRAY[0..1] OF Edge; i : INT; END_VAR
         Done := 0;
         FOR i := 1 TO 3 DO
           t[i](IN := Run, PT := INT_TO_TIME(i * 10));
           IF t[i].Q THEN Done := Done + 1; END_IF;
         END_FOR;
         e[0](x := Run);
         e[1](x := NOT Run);
         Edges := e[0].n * 10 + e[1].n;
         t[1](Q => First);
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        6,
        &[(0, &[("Run", b(true))]), (40, &[("Run", b(false))])],
        &["Done", "Edges", "First", "Main.t[3].ACC", "Main.e[1].n"],
    );
    let done: Vec<Value> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(done, [0, 1, 2, 3, 0, 0].map(Value::Int));
    assert_eq!(rows[3][1], Value::Int(10));
    assert_eq!(rows[4][1], Value::Int(11));
    assert_eq!(rows[1][2], b(true));
    assert_eq!(rows[3][3], Value::Dint(30));
}

#[test]
fn an_instance_declaration_sets_initial_values_of_its_inputs() {
    let p = program(
        "name,type\nN,INT\n",
        "FUNCTION_BLOCK Add
         VAR_INPUT step : INT := 1; END_VAR
         VAR_OUTPUT n : INT; END_VAR
         n := n + step;
         END_FUNCTION_BLOCK
         PROGRAM Main
         VAR a : Add := (step := 7); b : Add; END_VAR
         a(); b();
         N := a.n * 100 + b.n;
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 2, &[], &["N", "Main.a.step"]);
    assert_eq!(rows[1], [Value::Int(1402), Value::Int(7)]);
    let e = errors(
        "name,type\n",
        "FUNCTION_BLOCK Add VAR_INPUT step : INT; END_VAR END_FUNCTION_BLOCK
         PROGRAM Main VAR a : Add := (stp := 7); END_VAR a(); END_PROGRAM",
    );
    assert!(e.contains("Add has no variable `stp` to initialise"), "{e}");
}

#[test]
fn bcd_conversions_and_move() {
    let p = program(
        "name,type\nIn,INT\nBin,INT\n",
        "PROGRAM Main
         VAR w : WORD; d : DWORD; END_VAR
         w := INT_TO_BCD_WORD(In);
         Bin := WORD_BCD_TO_INT(MOVE(w));
         d := DINT_TO_BCD_DWORD(12345678);
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        1,
        &[(0, &[("In", Value::Int(567))])],
        &["Main.w", "Bin", "Main.d"],
    );
    assert_eq!(
        rows[0],
        [Value::Dint(0x0567), Value::Int(567), Value::Lint(0x1234_5678)]
    );
    let q = program(
        "name,type\nBin,INT\n",
        "PROGRAM Main Bin := WORD_BCD_TO_INT(WORD#16#12A4); END_PROGRAM",
    );
    for mode in MODES {
        let mut e = engine(&q, mode);
        e.scan(0).expect("scan");
        assert!(e.faults().count >= 1, "{mode:?}: a nibble above 9 is a fault");
    }
}

#[test]
fn a_function_block_containing_itself_is_refused() {
    let e = errors(
        "name,type\n",
        "FUNCTION_BLOCK Node VAR next : Node; v : INT; END_VAR v := v + 1; END_FUNCTION_BLOCK
         PROGRAM Main VAR n : Node; END_VAR n(); END_PROGRAM",
    );
    assert!(
        e.contains("the FUNCTION_BLOCK `Node` contains an instance of itself"),
        "{e}"
    );
}

/// 1 000 instances of a user FB, each called once a scan: the inlined
/// program's size and the time to compile it are printed.
#[test]
fn a_thousand_inlined_calls_compile_and_the_time_is_printed() {
    let mut src = String::from(
        "FUNCTION_BLOCK Debounce
         VAR_INPUT in : BOOL; pt : TIME; END_VAR
         VAR_OUTPUT q : BOOL; END_VAR
         VAR t : TON; r : R_TRIG; n : DINT; END_VAR
         t(IN := in, PT := pt);
         r(CLK := t.Q);
         IF r.Q THEN n := n + 1; END_IF;
         q := t.Q;
         END_FUNCTION_BLOCK
         FUNCTION Clamp : DINT
         VAR_INPUT x, lo, hi : DINT; END_VAR
         Clamp := LIMIT(lo, x, hi);
         END_FUNCTION
         PROGRAM Big
         VAR d : ARRAY[1..1000] OF Debounce; k : DINT; END_VAR\n",
    );
    for i in 1..=1000 {
        src.push_str(&format!(
            "d[{i}](in := In, pt := T#{}ms); k := Clamp(k + BOOL_TO_DINT(d[{i}].q), 0, 500);\n",
            10 + i % 7
        ));
    }
    src.push_str("Out := k;\nEND_PROGRAM\n");
    let start = std::time::Instant::now();
    let p = program("name,type\nIn,BOOL\nOut,DINT\n", &src);
    let took = start.elapsed();
    println!(
        "1 000 FB calls and 1 000 FUNCTION calls inlined: {} ops, {} tags, compiled in {took:?}",
        p.ops.len(),
        p.layout.tags.len()
    );
    let rows = run_all(&p, 10, 3, &[(0, &[("In", b(true))])], &["Out"]);
    assert_eq!(rows[2][0], Value::Dint(500));
}

#[test]
fn an_uncalled_block_with_an_instance_in_out_is_checked_without_false_errors() {
    let e = errors(
        "name,type\nQ,BOOL\n",
        "FUNCTION_BLOCK Drive
         VAR_IN_OUT t : TON; END_VAR
         VAR_OUTPUT q : BOOL; END_VAR
         t(IN := TRUE, PT := T#1s);
         q := t.Q;
         END_FUNCTION_BLOCK
         FUNCTION Twice : INT
         VAR_IN_OUT t : TON; END_VAR
         t(IN := FALSE);
         Twice := t.Qq;
         END_FUNCTION
         PROGRAM Main Q := TRUE; END_PROGRAM",
    );
    assert!(e.contains("TON has no member `Qq`"), "{e}");
    assert_eq!(e.matches("error[").count(), 1, "{e}");
}

#[test]
fn a_bare_enumeration_value_takes_the_type_wanted() {
    let p = program(
        "name,type\nN,INT\n",
        "TYPE Light : (Off, On); Mode : (Auto, Manual, Off); END_TYPE
         PROGRAM Main
         VAR m : Mode; l : Light := On; END_VAR
         m := Off;
         N := 0;
         IF m = Off THEN N := 1; END_IF;
         CASE m OF Off: N := N + 10; Auto: N := N + 100; END_CASE;
         IF l = On AND m = Mode#Off THEN N := N + 1000; END_IF;
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 1, &[], &["N", "Main.m", "Main.l"]);
    assert_eq!(rows[0], [Value::Int(1011), Value::Dint(2), Value::Dint(1)]);
}

/// A FUNCTION_BLOCK and a TYPE of one `.st` file used by the PROGRAM of
/// another (`declare_with` / `compile_with`, the other files as the library).
#[test]
fn pous_and_types_of_another_file_are_known_through_the_library() {
    let mut files = Files::new();
    let tf = files.add("tags.csv", "name,type\nIn,BOOL\nN,INT\n");
    let lf = files.add(
        "lib.st",
        "TYPE Pair : STRUCT a, b : INT; END_STRUCT; END_TYPE
         FUNCTION_BLOCK Count VAR_INPUT x : BOOL; END_VAR VAR_OUTPUT p : Pair; END_VAR
         VAR r : R_TRIG; END_VAR
         r(CLK := x); IF r.Q THEN p.a := p.a + 1; ELSE p.b := p.b + 1; END_IF;
         END_FUNCTION_BLOCK",
    );
    let mf = files.add(
        "main.st",
        "PROGRAM Main VAR c : Count; q : Pair; END_VAR
         c(x := In, p => q); N := q.a * 10 + q.b; END_PROGRAM",
    );
    let (mut tags, mut diags) = TagTable::parse(files.text(tf), tf);
    let (lib, d1) = alba_st::parse(files.text(lf), lf);
    let (main, d2) = alba_st::parse(files.text(mf), mf);
    diags.extend(d1);
    diags.extend(d2);
    alba_st::declare_with(&lib, &[&main], &mut tags, &mut diags);
    alba_st::declare_with(&main, &[&lib], &mut tags, &mut diags);
    let mut bl = Builder::new(Layout::new(&tags, &Default::default()));
    diags.extend(alba_st::compile_with(&lib, &[&main], "lib.st", &mut bl));
    diags.extend(alba_st::compile_with(&main, &[&lib], "main.st", &mut bl));
    assert!(diags.is_empty(), "{}", render_all(&diags, &files));
    let p = bl.finish(files);
    let rows = run_all(&p, 10, 3, &[(0, &[("In", b(true))])], &["N", "Main.c.p.a"]);
    assert_eq!(rows[2], [Value::Int(12), Value::Int(1)]);
}

/// An online edit (the engine's `replace`) keeps the state of every user FB
/// instance: its variables, and the timers and edges inside, are tags.
#[test]
fn an_online_edit_keeps_the_state_of_user_fb_instances() {
    let fb = "FUNCTION_BLOCK Counter
         VAR_INPUT up : BOOL; END_VAR
         VAR_OUTPUT n : INT; END_VAR
         VAR edge : R_TRIG; t : TON; END_VAR
         edge(CLK := up);
         IF edge.Q THEN n := n + 1; END_IF;
         t(IN := up, PT := T#1s);
         END_FUNCTION_BLOCK";
    let before = program(
        "name,type\nIn,BOOL\nN,INT\n",
        &format!("{fb}\nPROGRAM Main VAR c : Counter; END_VAR c(up := In); N := c.n; END_PROGRAM"),
    );
    let after = program(
        "name,type\nIn,BOOL\nN,INT\n",
        &format!("{fb}\nPROGRAM Main VAR c : Counter; END_VAR c(up := In); N := c.n * 100; END_PROGRAM"),
    );
    for mode in MODES {
        let mut e = engine(&before, mode);
        for (k, v) in [true, false, true].into_iter().enumerate() {
            set(&mut e, "In", b(v));
            e.scan(k as u64 * 10).expect("scan");
        }
        assert_eq!(get(&e, "N"), Value::Int(2), "{mode:?}");
        e.replace(Arc::new(after.clone())).expect("online edit");
        // In held TRUE: no new edge (the R_TRIG's memory was kept), the
        // timer goes on from 0 ms at 20 ms.
        e.scan(30).expect("scan");
        assert_eq!(get(&e, "N"), Value::Int(200), "{mode:?}");
        assert_eq!(get(&e, "Main.c.t.ACC"), Value::Dint(10), "{mode:?}");
    }
}

#[test]
fn generic_to_conversions_take_the_argument_type() {
    let p = program(
        "name,type\nR,REAL\nI,INT\nD,DINT\nB,BOOL\n",
        "TYPE Color : (Red, Green := 5, Blue); END_TYPE
         PROGRAM Main VAR c : Color := Blue; w : WORD; END_VAR
         I := TO_INT(R);
         D := TO_DINT(c) + TO_DINT(TRUE);
         w := TO_WORD(-1);
         B := TO_BOOL(w);
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        1,
        &[(0, &[("R", Value::Real(2.5))])],
        &["I", "D", "Main.w", "B"],
    );
    // 2.5 rounds half to even.
    assert_eq!(rows[0], [Value::Int(2), Value::Dint(7), Value::Dint(0xFFFF), b(true)]);
}

#[test]
fn functions_return_structures_and_arrays_and_arrays_assign_whole() {
    let p = program(
        "name,type\nX,INT\nS,DINT\n",
        "TYPE Point : STRUCT x, y : INT; END_STRUCT; END_TYPE
         FUNCTION Make : Point
         VAR_INPUT x, y : INT; END_VAR
         Make.x := x; Make.y := y;
         END_FUNCTION
         FUNCTION Len2 : DINT
         VAR_INPUT p : Point; END_VAR
         Len2 := INT_TO_DINT(p.x * p.x + p.y * p.y);
         END_FUNCTION
         FUNCTION Ramp : ARRAY[1..3] OF INT
         VAR_INPUT k : INT; END_VAR
         VAR i : INT; END_VAR
         FOR i := 1 TO 3 DO Ramp[i] := i * k; END_FOR;
         END_FUNCTION
         PROGRAM Main VAR p : Point; a, b : ARRAY[1..3] OF INT; END_VAR
         p := Make(3, 4);
         S := Len2(Make(1, 2)) * 100 + Len2(p);
         a := Ramp(10);
         b := a;
         X := b[3];
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 1, &[], &["S", "X", "Main.p.y", "Main.b[1]"]);
    assert_eq!(
        rows[0],
        [Value::Dint(525), Value::Int(30), Value::Int(4), Value::Int(10)]
    );
}

#[test]
fn global_instances_and_structures_are_external_in_programs() {
    let p = program(
        "name,type\nIn,BOOL\nN,INT\n",
        "TYPE Pt : STRUCT x, y : INT; END_STRUCT; END_TYPE
         FUNCTION_BLOCK Count VAR_INPUT x : BOOL; END_VAR VAR_OUTPUT n : INT; END_VAR VAR r : R_TRIG; END_VAR
         r(CLK := x); IF r.Q THEN n := n + 1; END_IF;
         END_FUNCTION_BLOCK
         VAR_GLOBAL g : Count; gp : Pt; edge : R_TRIG; END_VAR
         PROGRAM A VAR_EXTERNAL g : Count; gp : Pt; END_VAR g(x := In); gp.x := g.n; END_PROGRAM
         PROGRAM B VAR_EXTERNAL gp : Pt; edge : R_TRIG; END_VAR edge(CLK := In); N := gp.x * 10 + BOOL_TO_INT(edge.Q); END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        3,
        &[
            (0, &[("In", b(true))]),
            (10, &[("In", b(false))]),
            (20, &[("In", b(true))]),
        ],
        &["N", "g.n"],
    );
    assert_eq!(rows[2], [Value::Int(21), Value::Int(2)]);
    let e = errors(
        "name,type\n",
        "TYPE Pt : STRUCT x, y : INT; END_STRUCT; END_TYPE
         PROGRAM A VAR_EXTERNAL nope : Pt; t : TON; END_VAR END_PROGRAM",
    );
    assert!(
        e.contains("`nope` is VAR_EXTERNAL but no tag or VAR_GLOBAL has that name"),
        "{e}"
    );
    assert!(
        e.contains("`t` is VAR_EXTERNAL but no tag or VAR_GLOBAL has that name"),
        "{e}"
    );
}

#[test]
fn en_runs_a_call_only_when_true_and_eno_says_whether_it_ran() {
    let p = program(
        "name,type\nGo,BOOL\nOk,BOOL\nN,INT\nQ,BOOL\n",
        "FUNCTION_BLOCK Inc VAR_OUTPUT n : INT; END_VAR n := n + 1; END_FUNCTION_BLOCK
         PROGRAM Main VAR i : Inc; t : TON; END_VAR
         i(EN := Go, ENO => Ok);
         N := i.n;
         t(EN := Go, IN := TRUE, PT := T#20ms, Q => Q);
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        5,
        &[
            (0, &[("Go", b(true))]),
            (20, &[("Go", b(false))]),
            (30, &[("Go", b(true))]),
        ],
        &["N", "Ok", "Q", "Main.t.ACC"],
    );
    let n: Vec<Value> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(n, [1, 2, 2, 3, 4].map(Value::Int));
    let ok: Vec<bool> = rows.iter().map(|r| r[1] == b(true)).collect();
    assert_eq!(ok, [true, true, false, true, true]);
    // The timer is not called at 20 ms: its ET stays at 10 ms, then goes on.
    assert_eq!(rows[2][3], Value::Dint(10));
    let e = errors(
        "name,type\nX,DINT\n",
        "FUNCTION F : DINT VAR_INPUT a : DINT; END_VAR F := a; END_FUNCTION
         PROGRAM Main X := F(EN := TRUE, a := 1); END_PROGRAM",
    );
    assert!(
        e.contains("EN and ENO are taken by a call written as a statement"),
        "{e}"
    );
}

#[test]
fn whole_elements_of_arrays_of_structures_with_computed_indexes() {
    let p = program(
        "name,type\nI,INT\nJ,INT\nS,DINT\n",
        "TYPE Pt : STRUCT x, y : INT; END_STRUCT; END_TYPE
         FUNCTION Sum : DINT VAR_INPUT p : Pt; END_VAR Sum := INT_TO_DINT(p.x + p.y); END_FUNCTION
         PROGRAM Main VAR zs : ARRAY[1..3] OF Pt := [(x := 1, y := 2), (x := 10, y := 20), (x := 100, y := 200)]; p : Pt; END_VAR
         p := zs[I];
         zs[J] := p;
         S := Sum(zs[J]) * 1000 + Sum(zs[1]);
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        1,
        &[(0, &[("I", Value::Int(2)), ("J", Value::Int(1))])],
        &["S", "Main.p.x", "Main.zs[1].y", "Main.zs[3].x"],
    );
    assert_eq!(
        rows[0],
        [Value::Dint(30_030), Value::Int(10), Value::Int(20), Value::Int(100)]
    );
    for mode in MODES {
        let mut e = engine(&p, mode);
        set(&mut e, "I", Value::Int(4));
        set(&mut e, "J", Value::Int(1));
        e.scan(0).expect("scan");
        assert!(e.faults().count >= 1, "{mode:?}: zs[4] is a fault");
    }
}

#[test]
fn in_out_elements_with_computed_indexes_pass_by_value_and_result() {
    let p = program(
        "name,type\nI,INT\nJ,INT\nS,DINT\n",
        "TYPE Pt : STRUCT x, y : INT; END_STRUCT; END_TYPE
         FUNCTION Swap : BOOL VAR_IN_OUT a, b : INT; END_VAR VAR t : INT; END_VAR
         t := a; a := b; b := t; Swap := TRUE;
         END_FUNCTION
         FUNCTION_BLOCK Flip VAR_IN_OUT p : Pt; END_VAR VAR t : INT; END_VAR
         t := p.x; p.x := p.y; p.y := t;
         END_FUNCTION_BLOCK
         PROGRAM Main VAR a : ARRAY[1..3] OF INT := [1, 2, 3]; zs : ARRAY[0..1] OF Pt := [(x := 5, y := 6)]; f : Flip; END_VAR
         Swap(a[I], a[J]);
         f(p := zs[I - 1]);
         S := a[1] * 100 + a[2] * 10 + a[3];
         END_PROGRAM",
    );
    let rows = run_all(
        &p,
        10,
        2,
        &[(0, &[("I", Value::Int(1)), ("J", Value::Int(3))])],
        &["S", "Main.zs[0].x", "Main.zs[0].y"],
    );
    assert_eq!(rows[0], [Value::Dint(321), Value::Int(6), Value::Int(5)]);
    assert_eq!(rows[1], [Value::Dint(123), Value::Int(5), Value::Int(6)]);
}

#[test]
fn operator_functions_and_bool_literals_0_and_1_as_openplc_writes_them() {
    // Real OpenPLC programs write `DIV(a, b)`, `mod(a, b)` and `x : BOOL := 1`
    // (IEC 61131-3's boolean literals include 0 and 1).
    let p = program(
        "name,type\nA,DINT\nB,DINT\nC,DINT\nD,DINT\nM,DINT\nF,BOOL\nG,BOOL\n",
        "PROGRAM Main
         VAR on : BOOL := 1; off : BOOL := 0; END_VAR
         A := ADD(1, 2, 3, 4);
         B := MUL(2, 3, 4);
         C := SUB(10, 4);
         D := DIV(17, 5);
         M := mod(17, 5);
         F := on;
         G := off;
         END_PROGRAM",
    );
    let rows = run_all(&p, 10, 1, &[], &["A", "B", "C", "D", "M", "F", "G"]);
    let d = Value::Dint;
    assert_eq!(rows[0], [d(10), d(24), d(6), d(3), d(2), b(true), b(false)]);
    let e = errors(
        "name,type\n",
        "PROGRAM Main VAR x : BOOL := 2; y : DINT; END_VAR y := DIV(1); END_PROGRAM",
    );
    for want in [
        "the initial value `2` is not a BOOL literal",
        "DIV takes 2 argument(s), not 1",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}
