//! `alba verify`'s decisions on programs whose answers are known, and a
//! property test against exhaustive simulation of every input sequence.

mod common;

use alba_engine::Engine;
use alba_verify::explore::{self, Budget, Method, Outcome};
use alba_verify::expr::Evaluator;
use alba_verify::props::Kind;
use common::*;
use proptest::prelude::*;

#[test]
fn the_interlock_holds_and_fails_without_its_contact() {
    let toml = "[[property]]\nname = \"never both\"\nmutex = [\"Fwd\", \"Rev\"]\n";
    let good = compile(MOTOR_TAGS, MOTOR);
    let (_, v, _) = decide(&good, toml);
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    assert!(v[0].run.is_none());
    // Proved by 1-induction (each rung's interlock contact reads the other
    // coil as the scan leaves it), and by the explicit search alone.
    assert_eq!(v[0].method, Method::Induction(1));
    assert!(v[0].sat_calls >= 2);
    let explicit = Budget {
        induction_k: 0,
        ..Budget::default()
    };
    let (_, v, _) = decide_with(&good, toml, explicit);
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    assert_eq!(v[0].method, Method::Explicit);
    assert!(v[0].states > 0);

    let bad = compile(MOTOR_TAGS, MOTOR_NO_INTERLOCK);
    let (model, v, p) = decide(&bad, toml);
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    let run = v[0].run.as_ref().expect("a counterexample");
    // The shortest violation: both buttons on the first scan.
    assert_eq!(run.scans.len(), 1, "{run:?}");
    assert_eq!(v[0].depth, 1);
    // It replays through the engine as `alba sim` runs it.
    assert_eq!(explore::replay(&model, &p.properties[0], &p.assumes, run), Ok(()));
    let stim = explore::stimulus(&model, run);
    assert!(stim.starts_with("time_ms,tag,value\n"), "{stim}");
    assert!(stim.contains("0,FwdBtn,1") && stim.contains("0,RevBtn,1"), "{stim}");
}

#[test]
fn an_assumption_restricts_the_runs() {
    // Without the interlock, but with the buttons never pressed together
    // and, once running, the other button not pressed: the directions stay apart.
    let toml = "\
[[property]]
name = \"never both\"
mutex = [\"Fwd\", \"Rev\"]

[[assume]]
expr = \"NOT (FwdBtn AND RevBtn) AND NOT (Fwd AND RevBtn)\"
";
    let bad = compile(MOTOR_TAGS, MOTOR_NO_INTERLOCK);
    let (_, v, _) = decide(&bad, toml);
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
}

const LATCH_TAGS: &str = "\
Start,BOOL,DI:1/0,,,
Stop,BOOL,DI:1/1,,,
Motor,BOOL,DO:2/0,,,
";

#[test]
fn swapped_rung_order_is_caught() {
    let toml = "[[property]]\nname = \"stop wins\"\nnever = \"Stop AND Motor\"\n";
    let good = compile(LATCH_TAGS, "XIC(Start)OTL(Motor);\nXIC(Stop)OTU(Motor);\n");
    let (_, v, _) = decide(&good, toml);
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    let swapped = compile(LATCH_TAGS, "XIC(Stop)OTU(Motor);\nXIC(Start)OTL(Motor);\n");
    let (_, v, _) = decide(&swapped, toml);
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    // Both buttons on the first scan.
    assert_eq!(v[0].depth, 1);
}

const LAMP_TAGS: &str = "\
Start,BOOL,DI:1/0,,,
Stop,BOOL,DI:1/1,,,
Motor,BOOL,DO:2/0,,,
Lamp,BOOL,DO:2/1,,,
Delay,TIMER,,,,
";
const LAMP: &str = "\
[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);
XIC(Motor)TON(Delay,500,0);
XIC(Delay.DN)OTE(Lamp);
";

#[test]
fn a_response_time_is_decided_to_the_scan() {
    let prog = compile(LAMP_TAGS, LAMP);
    let toml = |ms: u64| {
        format!(
            "[[property]]\nname = \"lamp follows\"\nresponse = {{ trigger = \"Motor\", then = \"Lamp\", within_ms = {ms} }}\n\
             [[assume]]\nexpr = \"NOT Stop\"\n"
        )
    };
    // The timer starts in the scan the motor starts: DN 500 ms later.
    let (_, v, _) = decide(&prog, &toml(500));
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    let (model, v, p) = decide(&prog, &toml(490));
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    let run = v[0].run.as_ref().expect("counterexample");
    // Start at the first scan, then 50 scans until the deadline passes.
    assert_eq!(run.scans.len(), 51, "{:?}", run.scans.len());
    assert_eq!(explore::replay(&model, &p.properties[0], &p.assumes, run), Ok(()));
    // Without the assumption, Stop makes the lamp never come.
    let (_, v, _) = decide(
        &prog,
        "[[property]]\nname = \"r\"\nresponse = { trigger = \"Motor\", then = \"Lamp\", within_ms = 5000 }\n",
    );
    assert_eq!(outcome(&v[0]), "refuted");
}

#[test]
fn a_timer_counting_tenths_of_a_second_is_decided_to_the_scan() {
    // The same lamp with its delay as 5 units of 100 ms: ACC counts tenths,
    // the time short of a unit carried from scan to scan (issue 34 point 3).
    let prog = compile(LAMP_TAGS, &LAMP.replace("TON(Delay,500,0)", "TON(Delay,5,0,ds)"));
    let toml = |ms: u64| {
        format!(
            "[[property]]\nname = \"lamp follows\"\nresponse = {{ trigger = \"Motor\", then = \"Lamp\", within_ms = {ms} }}\n\
             [[property]]\nname = \"acc in tenths\"\nalways = \"Delay.ACC <= 5\"\n\
             [[assume]]\nexpr = \"NOT Stop\"\n"
        )
    };
    let (_, v, _) = decide(&prog, &toml(500));
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    assert_eq!(outcome(&v[1]), "proved", "{:?}", v[1].outcome);
    let (model, v, p) = decide(&prog, &toml(490));
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    let run = v[0].run.as_ref().expect("counterexample");
    assert_eq!(explore::replay(&model, &p.properties[0], &p.assumes, run), Ok(()));
}

#[test]
fn reachable_gives_a_witness_or_is_refuted() {
    let prog = compile(LAMP_TAGS, LAMP);
    let toml = "\
[[property]]
name = \"lamp\"
reachable = \"Lamp\"

[[property]]
name = \"lamp alone\"
reachable = \"Lamp AND NOT Motor\"

[[property]]
name = \"acc\"
always = \"Delay.ACC <= 500 AND Delay.ACC >= 0\"
";
    let (model, v, p) = decide(&prog, toml);
    assert_eq!(outcome(&v[0]), "proved");
    let run = v[0].run.as_ref().expect("witness");
    assert_eq!(run.scans.len(), 51);
    assert_eq!(explore::replay(&model, &p.properties[0], &p.assumes, run), Ok(()));
    assert_eq!(outcome(&v[1]), "refuted");
    assert!(v[1].run.is_none());
    assert_eq!(outcome(&v[2]), "proved", "{:?}", v[2].outcome);
}

#[test]
fn numeric_inputs_need_a_domain() {
    let tags = "Level,INT,AI:3/0,,,\nHigh,BOOL,DO:2/0,,,\n";
    let lad = "GRT(Level,800)OTE(High);\n";
    let prog = compile(tags, lad);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"h\"\nnever = \"High AND Level < 800\"\n");
    match &v[0].outcome {
        Outcome::Unknown(why) => assert!(why.contains("Level") && why.contains("[domain]"), "{why}"),
        o => panic!("expected unknown, got {o:?}"),
    }
    // A property that does not depend on the level needs no domain.
    let tags2 = format!("{tags}Go,BOOL,DI:1/0,,,\nLamp,BOOL,DO:2/1,,,\n");
    let prog2 = compile(&tags2, &format!("{lad}XIC(Go)OTE(Lamp);\n"));
    let (_, v, _) = decide(&prog2, "[[property]]\nname = \"l\"\nnever = \"Lamp AND NOT Go\"\n");
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    let with = "[[property]]\nname = \"h\"\nnever = \"High AND Level <= 800\"\n[domain]\nLevel = [0, 800, 801, 1023]\n";
    let (_, v, _) = decide(&prog, with);
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    let wrong = "[[property]]\nname = \"h\"\nnever = \"High\"\n[domain]\nLevel = [0, 1023]\n";
    let (_, v, _) = decide(&prog, wrong);
    assert_eq!(outcome(&v[0]), "refuted");
}

#[test]
fn a_budget_too_small_answers_unknown_never_proved() {
    let prog = compile(LAMP_TAGS, LAMP);
    let budget = Budget {
        max_states: 20,
        ..Budget::default()
    };
    let (_, v, _) = decide_with(
        &prog,
        "[[property]]\nname = \"p\"\nnever = \"Lamp AND NOT Motor\"\n",
        budget,
    );
    match &v[0].outcome {
        Outcome::Unknown(why) => assert!(why.contains("budget"), "{why}"),
        o => panic!("expected unknown, got {o:?}"),
    }
}

#[test]
fn what_cannot_influence_the_property_is_left_out() {
    // A running count of forward presses grows without bound; the
    // interlock property does not read it, so the search still ends.
    let tags = format!("{MOTOR_TAGS}Presses,DINT,,,,\n");
    let lad = format!("{MOTOR}XIC(FwdBtn)ADD(Presses,1,Presses);\n");
    let prog = compile(&tags, &lad);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nmutex = [\"Fwd\", \"Rev\"]\n");
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    // A property on the count keeps it, and is refuted.
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Presses = 3\"\n");
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    assert_eq!(v[0].depth, 3);
}

#[test]
fn a_jump_over_a_rung_is_part_of_its_influence() {
    // Hold skips the lamp's rung, which then keeps its last value: the lamp
    // stays on after Go is released. Hold is read by no rung the lamp's
    // rung depends on, only by the jump.
    let tags = "Go,BOOL,DI:1/0,,,\nHold,BOOL,DI:1/1,,,\nLamp,BOOL,DO:2/0,,,\n";
    let lad = "XIC(Hold)JMP(Over);\nXIC(Go)OTE(Lamp);\nLBL(Over)NOP();\n";
    let prog = compile(tags, lad);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Lamp AND NOT Go\"\n");
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    assert_eq!(v[0].depth, 2);
    // And a skipped timer catches up with the time it missed.
    let tags = "Go,BOOL,DI:1/0,,,\nHold,BOOL,DI:1/1,,,\nLamp,BOOL,DO:2/0,,,\nT,TIMER,,,,\n";
    let lad = "XIC(Hold)JMP(Over);\nXIC(Go)TON(T,50,0);\nLBL(Over)NOP();\nXIC(T.DN)OTE(Lamp);\n";
    let prog = compile(tags, lad);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Lamp\"\n");
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    // Go at 0 ms starts it; held over, it is done at its next execution 50 ms on.
    assert_eq!(v[0].depth, 6);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Lamp AND T.ACC <> 50\"\n");
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
}

#[test]
fn a_reset_before_its_timer_keeps_the_clock_abstract() {
    // RES comes first in the program: the timer's clock is still unread
    // while it is off, so the search ends (and a deadline is exact).
    let tags = "Go,BOOL,DI:1/0,,,\nClear,BOOL,DI:1/1,,,\nLamp,BOOL,DO:2/0,,,\nT,TIMER,,,,\n";
    let lad = "XIC(Clear)RES(T);\nXIC(Go)TON(T,50,0);\nXIC(T.DN)OTE(Lamp);\n";
    let prog = compile(tags, lad);
    let budget = Budget {
        max_states: 50_000,
        ..Budget::default()
    };
    let (_, v, _) = decide_with(
        &prog,
        "[[property]]\nname = \"p\"\nnever = \"Lamp AND NOT Go\"\n",
        budget,
    );
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    assert!(v[0].states < 100, "{} states", v[0].states);
}

#[test]
fn a_fault_flag_read_by_a_kept_rung_keeps_everything() {
    // The division is outside the property's cone, but its fault sets
    // S:MINOR, which the lamp's rung reads.
    let tags = "Go,BOOL,DI:1/0,,,\nLamp,BOOL,DO:2/0,,,\nNum,INT,,7,,\nZero,INT,,0,,\nRes,INT,,,,\n";
    let lad = "XIC(Go)DIV(Num,Zero,Res);\nXIC(S:MINOR)OTE(Lamp);\n";
    let prog = compile(tags, lad);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Lamp\"\n");
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    // The flag is set at the end of the faulting scan: the lamp lights in the next.
    assert_eq!(v[0].depth, 2);
}

#[test]
fn a_counter_is_bounded_only_when_exact() {
    let tags = "Pulse,BOOL,DI:1/0,,,\nReset,BOOL,DI:1/1,,,\nC,COUNTER,,,,\nFull,BOOL,DO:2/0,,,\n";
    // Counting forever: its ACC only shows through DN, so the search ends.
    let lad = "XIC(Pulse)CTU(C,3,0);\nXIC(Reset)RES(C);\nXIC(C.DN)OTE(Full);\n";
    let prog = compile(tags, lad);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Full AND NOT C.DN\"\n");
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    // A property reading ACC keeps it exact: unbounded, so unknown at the budget.
    let budget = Budget {
        max_states: 5_000,
        ..Budget::default()
    };
    let (_, v, _) = decide_with(&prog, "[[property]]\nname = \"p\"\nnever = \"C.ACC < 0\"\n", budget);
    assert_eq!(outcome(&v[0]), "unknown", "{:?}", v[0].outcome);
    let (_, v, _) = decide_with(&prog, "[[property]]\nname = \"p\"\nnever = \"C.ACC = 4\"\n", budget);
    assert_eq!(outcome(&v[0]), "refuted", "{:?}", v[0].outcome);
    assert_eq!(v[0].depth, 7, "the shortest run: four rising edges");
}

/// k-induction proves what holds in its abstraction at the smallest k, and
/// leaves to the explicit search what depends on a timer's value.
#[test]
fn k_induction_takes_the_smallest_k_and_leaves_timers_to_the_search() {
    // D1 and D2 are last scan's A and NOT A: never both, but only once A and
    // Na have been written by a scan (an arbitrary state may hold both):
    // not 1-inductive, 2-inductive.
    let tags = "In,BOOL,DI:1/0,,,\nA,BOOL,,,,\nNa,BOOL,,,,\nD1,BOOL,DO:2/0,,,\nD2,BOOL,DO:2/1,,,\n";
    let lad = "XIC(A)OTE(D1);\nXIC(Na)OTE(D2);\nXIC(In)OTE(A);\nXIO(In)OTE(Na);\n";
    let prog = compile(tags, lad);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"D1 AND D2\"\n");
    assert_eq!(outcome(&v[0]), "proved", "{:?}", v[0].outcome);
    assert_eq!(v[0].method, Method::Induction(2));
    // With k limited to 1 the explicit search proves it.
    let one = Budget {
        induction_k: 1,
        ..Budget::default()
    };
    let (_, v, _) = decide_with(&prog, "[[property]]\nname = \"p\"\nnever = \"D1 AND D2\"\n", one);
    assert_eq!((outcome(&v[0]), v[0].method), ("proved", Method::Explicit));
    assert!(v[0].sat_calls >= 2, "the base and the step were asked");
    // The lamp follows a timer's DN, havocked in the abstraction: the search decides.
    let prog = compile(LAMP_TAGS, LAMP);
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Lamp AND NOT Motor\"\n");
    assert_eq!((outcome(&v[0]), v[0].method), ("proved", Method::Explicit));
    assert!(v[0].states > 0);
    // A false invariant is never proved by it: refuted by the search, with its counterexample.
    let (_, v, _) = decide(&prog, "[[property]]\nname = \"p\"\nnever = \"Lamp\"\n");
    assert_eq!((outcome(&v[0]), v[0].method), ("refuted", Method::Explicit));
    assert!(v[0].run.is_some());
}

/// A property's expression is evaluated by the engine (lowered onto the IR,
/// expr.rs): DINT arithmetic wraps at 32 bits and a division by zero
/// saturates as in a rung, its typing is the compiler's, and a fault of
/// the expression does not reach the program's memory.
#[test]
fn expressions_have_the_engines_semantics() {
    let tags = "Start,BOOL,DI:1/0,,,\nLamp,BOOL,DO:2/0,,,\nBig,DINT,,2147483647,,\nFive,DINT,,5,,\nZero,DINT,,0,,\n";
    // The lamp lights on a minor fault: a fault of a property's division
    // would light it if it reached the program.
    let prog = compile(tags, "XIC(S:MINOR)OTE(Lamp);\nXIC(Start)NOP();\n");
    let toml = "\
[[property]]
name = \"DINT wraps\"
always = \"Big + 1 < 0\"

[[property]]
name = \"division by zero saturates\"
always = \"Five / Zero = 2147483647 AND (0 - Five) / Zero < -2147483647\"

[[property]]
name = \"no fault reaches the program\"
never = \"Lamp OR S:MINOR\"

[[property]]
name = \"REAL division\"
always = \"Five / 2.0 = 2.5 AND Five / 2 = 2\"
";
    let (_, v, _) = decide(&prog, toml);
    for r in &v {
        assert_eq!(outcome(r), "proved", "{}: {:?}", r.name, r.outcome);
    }
    let mut files = alba_diag::Files::new();
    for (text, needle) in [
        ("never = \"Lamp AND 3\"", "BOOL"),
        ("never = \"Big\"", "a number, not a BOOL"),
        ("never = \"Lamp + 1 > 0\"", "numbers on both sides"),
    ] {
        let f = files.add("properties.toml", format!("[[property]]\nname = \"p\"\n{text}\n"));
        let d = alba_verify::props::parse(files.text(f), f, &prog.layout).expect_err(text);
        assert!(d.iter().any(|d| d.message.contains(needle)), "{text}: {d:?}");
        assert!(d.iter().all(|d| d.code == alba_diag::Code::Expression), "{text}: {d:?}");
    }
}

#[test]
fn bad_properties_are_refused_with_their_place() {
    let prog = compile(LAMP_TAGS, LAMP);
    let mut files = alba_diag::Files::new();
    for (text, needle) in [
        ("[[property]]\nname = \"a\"\nnever = \"Lamp AND Nope\"\n", "Nope"),
        ("[[property]]\nname = \"a\"\n", "0 kinds"),
        (
            "[[property]]\nname = \"a\"\nnever = \"Lamp\"\nalways = \"Lamp\"\n",
            "2 kinds",
        ),
        ("[[property]]\nname = \"a\"\nnever = \"Lamp AND\"\n", ""),
        ("[[property]]\nname = \"a\"\nmutex = [\"Lamp\"]\n", "at least two"),
        ("[[property]]\nname = \"a\"\nnever = \"Delay\"\n", "structure"),
        ("[[propery]]\nname = \"a\"\n", "unknown field"),
        ("[domain]\nNope = [1]\n", "Nope"),
        ("[domain]\nLamp = [1]\n", "is an output"),
        ("[domain]\nStart = []\n", "no value"),
        ("[domain]\nStart = [2]\n", "bad value"),
    ] {
        let f = files.add("properties.toml", text.to_string());
        let d = alba_verify::props::parse(files.text(f), f, &prog.layout).expect_err(text);
        assert!(d.iter().any(|d| d.message.contains(needle)), "{text}: {:?}", d);
        assert!(d.iter().all(|d| d.primary.is_some()), "{text}: placed");
    }
}

// ---- a property test: the search against exhaustive simulation ------------

const RANDOM_TAGS: &str = "\
In0,BOOL,DI:1/0,,,
In1,BOOL,DI:1/1,,,
M0,BOOL,,,,
M1,BOOL,,,,
M2,BOOL,,,,
Tm,TIMER,,,,
Ct,COUNTER,,,,
N,DINT,,,,
";
const CONTACTS: [&str; 7] = ["In0", "In1", "M0", "M1", "M2", "Tm.DN", "Ct.DN"];
const OUTPUTS: [&str; 13] = [
    "OTE(M0)",
    "OTE(M1)",
    "OTE(M2)",
    "OTL(M0)",
    "OTL(M1)",
    "OTL(M2)",
    "OTU(M0)",
    "OTU(M1)",
    "OTU(M2)",
    "TON(Tm,20,0)",
    "CTU(Ct,2,0)",
    "RES(Ct)",
    // Unbounded, and read by no property: the cone of influence drops it.
    "ADD(N,1,N)",
];
const PROPERTIES: [&str; 6] = [
    "never = \"M0 AND M1\"",
    "never = \"M2\"",
    "always = \"NOT (M1 AND Tm.DN)\"",
    "mutex = [\"M0\", \"M2\", \"In1\"]",
    "reachable = \"M1 AND Ct.DN\"",
    "never = \"M0 AND NOT In0\"",
];
/// Scans simulated for every input sequence.
const DEPTH: usize = 5;

fn contact() -> impl Strategy<Value = String> {
    (any::<bool>(), 0..CONTACTS.len()).prop_map(|(n, k)| format!("{}({})", if n { "XIO" } else { "XIC" }, CONTACTS[k]))
}

fn rung() -> impl Strategy<Value = String> {
    (
        prop::collection::vec(contact(), 1..3),
        prop::option::of((contact(), contact())),
        0..OUTPUTS.len(),
    )
        .prop_map(|(series, branch, out)| {
            let mut s = series.concat();
            if let Some((a, b)) = branch {
                s.push_str(&format!("[{a},{b}]"));
            }
            format!("{s}{};\n", OUTPUTS[out])
        })
}

/// The first scan (1-based) at which some input sequence of `DEPTH` scans
/// makes `bad` true, by simulating all of them.
fn first_by_simulation(
    program: &std::sync::Arc<alba_ir::Program>,
    bad: &mut dyn FnMut(&alba_ir::Memory) -> bool,
) -> Option<usize> {
    let inputs: Vec<alba_ir::Place> = ["In0", "In1"]
        .iter()
        .map(|n| match program.layout.resolve(n) {
            Ok(alba_ir::Target::Value { place, .. }) => place,
            _ => panic!("input {n}"),
        })
        .collect();
    let mut best: Option<usize> = None;
    for seq in 0..4usize.pow(DEPTH as u32) {
        let mut e = Engine::new(program.clone()).expect("engine");
        for k in 0..DEPTH {
            if best.is_some_and(|b| k + 1 >= b) {
                break;
            }
            let combo = seq >> (2 * k) & 3;
            e.write(inputs[0], alba_model::Value::Bool(combo & 1 == 1));
            e.write(inputs[1], alba_model::Value::Bool(combo & 2 == 2));
            e.scan(k as u64 * SCAN_MS).expect("scan");
            if bad(e.memory()) {
                best = Some(k + 1);
                break;
            }
        }
    }
    best
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The search's answer agrees with simulating every input sequence: a
    /// violation (or witness) found by simulation within `DEPTH` scans is
    /// found by the search at the same, shortest, depth; `proved` never
    /// meets a violation in simulation.
    #[test]
    fn the_search_agrees_with_exhaustive_simulation(
        rungs in prop::collection::vec(rung(), 1..6),
        which in 0..PROPERTIES.len(),
        // A forward jump over some rungs (a skipped timer catches up later).
        jump in prop::option::of((contact(), 0usize..6)),
    ) {
        let mut rungs = rungs;
        if let Some((cond, at)) = jump {
            let at = 1 + at % rungs.len();
            rungs.insert(at, "LBL(Skip)NOP();\n".to_string());
            rungs.insert(0, format!("{cond}JMP(Skip);\n"));
        }
        let lad = rungs.concat();
        let program = compile(RANDOM_TAGS, &lad);
        let toml = format!("[[property]]\nname = \"p\"\n{}\n", PROPERTIES[which]);
        let (_, v, p) = decide(&program, &toml);
        let prop = &p.properties[0];
        let mut probes = Evaluator::new(&p.probes).expect("probes");
        let mut bad = |m: &alba_ir::Memory| {
            let m = probes.run(m).expect("probes run");
            match &prop.kind {
                Kind::Never(e) => e.holds(m),
                Kind::Always(e) => !e.holds(m),
                Kind::Mutex(es) => es.iter().filter(|e| e.holds(m)).count() > 1,
                Kind::Reachable(e) => e.holds(m),
                Kind::Response { .. } => unreachable!(),
            }
        };
        let sim = first_by_simulation(&program, &mut bad);
        let reachable = matches!(prop.kind, Kind::Reachable(_));
        let found = match (&v[0].outcome, reachable) {
            (Outcome::Refuted, false) | (Outcome::Proved, true) => Some(v[0].depth as usize),
            (Outcome::Proved, false) | (Outcome::Refuted, true) => None,
            (Outcome::Unknown(why), _) => panic!("unknown on a small program: {why}\n{lad}"),
        };
        match sim {
            Some(d) => prop_assert_eq!(found, Some(d), "{}\n{}", lad, toml),
            None => prop_assert!(found.is_none_or(|d| d > DEPTH), "{}\n{}\nsearch {:?}", lad, toml, found),
        }
    }
}

#[test]
fn a_project_folder_is_verified_with_its_files_written() {
    use alba_verify::project::{self, Options};
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), MOTOR_TAGS, MOTOR_NO_INTERLOCK);
    std::fs::write(
        dir.path().join("properties.toml"),
        "[[property]]\nname = \"a b\"\nmutex = [\"Fwd\", \"Rev\"]\n\n[[property]]\nname = \"a_b\"\nreachable = \"Rev\"\n\n\
         [[property]]\nname = \"stop\"\nnever = \"Stop AND Fwd\"\n",
    )
    .expect("write");
    let mut seen = Vec::new();
    let reports = project::verify(dir.path(), &Options::default(), &mut |r, scan| {
        seen.push((r.name.clone(), scan))
    })
    .unwrap_or_else(|f| panic!("{:?}", f.diagnostics));
    assert_eq!(seen.len(), 3);
    assert_eq!(seen[0].1, SCAN_MS);
    let results: Vec<&str> = reports.iter().map(|r| r.result).collect();
    assert_eq!(results, ["refuted", "proved", "proved"]);
    assert_eq!(project::exit_status(&reports), 1);
    let cex = reports[0].counterexample.as_deref().expect("counterexample");
    let witness = reports[1].witness.as_deref().expect("witness");
    // Names that slug alike get files of their own.
    assert_ne!(cex, witness);
    assert!(std::path::Path::new(cex).exists() && std::path::Path::new(witness).exists());
    assert!(reports[1].counterexample.is_none() && reports[2].counterexample.is_none());
    // Only one property, and a name that is not there.
    let only = Options {
        only: Some("stop".into()),
        ..Options::default()
    };
    let r = project::verify(dir.path(), &only, &mut |_, _| {}).unwrap_or_else(|f| panic!("{:?}", f.diagnostics));
    assert_eq!((r.len(), project::exit_status(&r)), (1, 0));
    let none = Options {
        only: Some("nope".into()),
        ..Options::default()
    };
    let Err(f) = project::verify(dir.path(), &none, &mut |_, _| {}) else {
        panic!("refused")
    };
    assert!(f.diagnostics[0].message.contains("nope"));
}
