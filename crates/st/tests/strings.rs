//! STRING and WSTRING (docs/st.md "Strings", ADR 0017): goldens of every
//! string function, comparison and conversion, run in every engine mode
//! (fused interpreter, monitored interpreter, native code), which must agree
//! on every scan; the edge cases (empty strings, truncation to the declared
//! length, positions out of range).

#[path = "common/modes.rs"]
mod modes;

use alba_engine::Engine;
use alba_model::Value;
use modes::{W, errors, once, program, run, write};

#[test]
fn literals_assignment_escapes_and_truncation() {
    let (v, faults) = once(
        "name,type\n",
        "PROGRAM Main
         VAR
           a : STRING;                 (* 80 characters *)
           b : STRING[5] := 'init';
           c : STRING[5];
           d : STRING[3];
           e : STRING;
           w : WSTRING[10] := \"Größe\";
           x : WSTRING[4];
         END_VAR
         a := 'it$'s $$5$N$54ab';
         c := 'abcdefgh';              (* cut to 5 *)
         d := c;                       (* cut to 3 *)
         e := '';
         x := \"$00E9t$P\";
         END_PROGRAM",
        &[
            W::S("Main.a"),
            W::S("Main.b"),
            W::S("Main.c"),
            W::S("Main.d"),
            W::S("Main.e"),
            W::S("Main.w"),
            W::S("Main.x"),
        ],
    );
    assert_eq!(v, ["it's $5\nTab", "init", "abcde", "abc", "", "Größe", "ét\u{c}"]);
    assert_eq!(faults, 0);
}

#[test]
fn the_string_functions_compute_what_the_standard_says() {
    let (v, faults) = once(
        "name,type\nN,INT\nF1,INT\nF2,INT\nF3,INT\nF4,INT\n",
        "PROGRAM Main
         VAR
           s : STRING[8] := 'ABCDE';
           l, r, m, c3, ins, del, rep, e1, e2, cut : STRING[16];
           short : STRING[6];
         END_VAR
         N := LEN(s);
         l := LEFT(s, 2);
         r := RIGHT(s, 3);
         m := MID(s, 2, 2);
         c3 := CONCAT(l, '-', r);
         ins := INSERT(s, 'XY', 2);
         del := DELETE(s, 2, 3);
         rep := REPLACE(s, 'X', 2, 3);
         F1 := FIND(s, 'CD');
         F2 := FIND(s, 'CX');
         F3 := FIND(s, '');
         F4 := FIND(CONCAT(s, s), RIGHT(s, 2));
         e1 := LEFT('', 3);
         e2 := MID(s, 0, 2);
         short := CONCAT(s, s);
         cut := CONCAT(LEFT(s, 0), RIGHT(s, 0));
         END_PROGRAM",
        &[
            W::V("N"),
            W::S("Main.l"),
            W::S("Main.r"),
            W::S("Main.m"),
            W::S("Main.c3"),
            W::S("Main.ins"),
            W::S("Main.del"),
            W::S("Main.rep"),
            W::V("F1"),
            W::V("F2"),
            W::V("F3"),
            W::V("F4"),
            W::S("Main.e1"),
            W::S("Main.e2"),
            W::S("Main.short"),
            W::S("Main.cut"),
        ],
    );
    assert_eq!(
        v,
        [
            "5", "AB", "CDE", "BC", "AB-CDE", "ABXYCDE", "ABE", "ABXE", "3", "0", "0", "4", "", "", "ABCDEA", ""
        ]
    );
    // MID with a length of 0 is no fault; none of these is out of range.
    assert_eq!(faults, 0);
}

#[test]
fn computed_lengths_and_positions_every_value_in_every_mode() {
    // Every length and position from -1 to 7 on 'hello' (and on an empty
    // string), computed at run time: the results against a model of the
    // standard's functions, and a fault for each negative length or
    // position below 1.
    let p = program(
        "name,type\nL,INT\nP,INT\nN,INT\n",
        "PROGRAM Main
         VAR s : STRING[8] := 'hello'; z : STRING[4]; a, b, c, d, e, f, g : STRING[12]; END_VAR
         a := LEFT(s, L);
         b := RIGHT(s, L);
         c := MID(s, L, P);
         d := DELETE(s, L, P);
         e := INSERT(s, '#', L);
         f := REPLACE(s, '[]', L, P);
         g := MID(z, L, P);
         N := FIND(s, MID(s, L, P));
         END_PROGRAM",
    );
    let cases: Vec<(i64, i64)> = (-1..=7).flat_map(|l| (-1..=7).map(move |p| (l, p))).collect();
    let set = |e: &mut Engine, k: u64| {
        let (l, p) = cases[k as usize];
        write(e, "L", Value::Int(l as i16));
        write(e, "P", Value::Int(p as i16));
    };
    let watch = [
        W::S("Main.a"),
        W::S("Main.b"),
        W::S("Main.c"),
        W::S("Main.d"),
        W::S("Main.e"),
        W::S("Main.f"),
        W::S("Main.g"),
        W::V("N"),
    ];
    let (rows, faults) = run(&p, cases.len() as u64, &set, &watch);
    let s = "hello";
    let n = s.len() as i64;
    // The model: lengths below 0 count as 0, positions below 1 as 1, and
    // both are cut to the string.
    let sub = |from: i64, len: i64| -> String {
        let from = from.clamp(0, n);
        let len = len.clamp(0, n - from);
        s[from as usize..(from + len) as usize].to_string()
    };
    let mut want_faults = 0;
    for ((l, p), row) in cases.iter().zip(&rows) {
        let (l, p) = (*l, *p);
        let lc = l.max(0);
        let p0 = (p - 1).clamp(0, n);
        let mid = sub(p0, lc);
        let del = format!("{}{}", sub(0, p0), sub(p0 + lc.min(n - p0), n));
        let ins_at = l.clamp(0, n);
        let ins = format!("{}#{}", sub(0, ins_at), sub(ins_at, n));
        let rep = format!("{}[]{}", sub(0, p0), sub(p0 + lc.min(n - p0), n));
        let find = if mid.is_empty() {
            0
        } else {
            s.find(&mid).map_or(0, |i| i + 1)
        };
        let want = [
            sub(0, lc),
            sub(n - lc.min(n), n),
            mid,
            del,
            ins,
            rep,
            String::new(),
            find.to_string(),
        ];
        assert_eq!(row.as_slice(), want.as_slice(), "L = {l}, P = {p}");
        // Faults: LEFT, RIGHT, MID×3, DELETE, INSERT (its P is L here),
        // REPLACE each report a negative length; MID×3, DELETE, REPLACE a position below 1.
        if l < 0 {
            want_faults += 8;
        }
        if p < 1 {
            want_faults += 5;
        }
    }
    assert_eq!(faults, want_faults);
}

#[test]
fn comparisons_order_by_the_first_different_character() {
    let p = program(
        "name,type\nEq,BOOL\nNe,BOOL\nLt,BOOL\nGt,BOOL\nLe,BOOL\nGe,BOOL\n",
        "PROGRAM Main
         VAR a, b : STRING[6]; k : INT; END_VAR
         CASE k OF
           0: a := 'abc'; b := 'abc';
           1: a := 'abc'; b := 'abd';
           2: a := 'ab'; b := 'abc';
           3: a := 'b'; b := 'abc';
           4: a := ''; b := '';
           5: a := 'abcdef'; b := 'abcdeg';
         END_CASE;
         Eq := a = b; Ne := a <> b; Lt := a < b; Gt := a > b; Le := a <= b; Ge := a >= b;
         k := k + 1;
         END_PROGRAM",
    );
    let names = ["Eq", "Ne", "Lt", "Gt", "Le", "Ge"];
    let watch: Vec<W> = names.iter().map(|n| W::V(n)).collect();
    let (rows, faults) = run(&p, 6, &|_, _| {}, &watch);
    let pairs = [
        ("abc", "abc"),
        ("abc", "abd"),
        ("ab", "abc"),
        ("b", "abc"),
        ("", ""),
        ("abcdef", "abcdeg"),
    ];
    for ((a, b), row) in pairs.iter().zip(&rows) {
        let want = [a == b, a != b, a < b, a > b, a <= b, a >= b].map(|x| Value::Bool(x).to_string());
        assert_eq!(row.as_slice(), want.as_slice(), "{a:?} vs {b:?}");
    }
    assert_eq!(faults, 0);
}

#[test]
fn conversions_between_strings_and_integers() {
    let (v, faults) = once(
        "name,type\nA,DINT\nB,INT\nC,LINT\nD,DINT\nEn,DINT\nBig,LINT\n",
        "PROGRAM Main
         VAR s1, s2, s3, s4, s5, s6 : STRING; w : WSTRING[8]; n : STRING[4]; END_VAR
         Big := -9223372036854775807;
         s1 := DINT_TO_STRING(-123);
         s2 := INT_TO_STRING(0);
         s3 := LINT_TO_STRING(Big);
         s4 := BYTE_TO_STRING(BYTE#255);
         s5 := WSTRING_TO_STRING(\"aé\");
         w := STRING_TO_WSTRING('xyz');
         n := DINT_TO_STRING(1234567);            (* cut to 4 *)
         A := STRING_TO_DINT('  -42x7');
         B := STRING_TO_INT('+17');
         C := STRING_TO_LINT(s3);
         D := STRING_TO_DINT('abc');
         En := STRING_TO_DINT(CONCAT('1', '2', '3'));
         s6 := DINT_TO_STRING(En + 1);
         END_PROGRAM",
        &[
            W::S("Main.s1"),
            W::S("Main.s2"),
            W::S("Main.s3"),
            W::S("Main.s4"),
            W::S("Main.s5"),
            W::S("Main.w"),
            W::S("Main.n"),
            W::V("A"),
            W::V("B"),
            W::V("C"),
            W::V("D"),
            W::V("En"),
            W::S("Main.s6"),
        ],
    );
    assert_eq!(
        v,
        [
            "-123",
            "0",
            "-9223372036854775807",
            "255",
            "a?",
            "xyz",
            "1234",
            "-42",
            "17",
            "-9223372036854775807",
            "0",
            "123",
            "124"
        ]
    );
    assert_eq!(faults, 0);
}

#[test]
fn strings_pass_through_functions_function_blocks_and_structures() {
    let (v, faults) = once(
        "name,type\n",
        "TYPE Rec : STRUCT name : STRING[8]; n : INT; END_STRUCT; END_TYPE
         FUNCTION Greet : STRING[16]
         VAR_INPUT who : STRING[8]; END_VAR
         Greet := CONCAT('hi ', who);
         END_FUNCTION
         FUNCTION_BLOCK Keep
         VAR_INPUT x : STRING[4]; END_VAR
         VAR_OUTPUT last : STRING[4]; END_VAR
         IF LEN(x) > 0 THEN last := x; END_IF;
         END_FUNCTION_BLOCK
         PROGRAM Main
         VAR g : STRING; k : Keep; out : STRING; r : Rec; names : ARRAY[1..2] OF STRING[3]; END_VAR
         g := Greet('bob');
         k(x := 'abcdef');
         out := k.last;
         r.name := 'rec';
         names[2] := r.name;
         END_PROGRAM",
        &[
            W::S("Main.g"),
            W::S("Main.out"),
            W::S("Main.r.name"),
            W::S("Main.names[2]"),
        ],
    );
    assert_eq!(v, ["hi bob", "abcd", "rec", "rec"]);
    assert_eq!(faults, 0);
}

#[test]
fn strings_are_checked() {
    let e = errors(
        "name,type\nN,INT\n",
        "PROGRAM Main
         VAR s : STRING[4]; w : WSTRING; t : STRING[0]; END_VAR
         s := 5;
         N := s;
         s := w;
         s := s + s;
         N := LEFT(s);
         N := FIND(s, 3);
         s := 'caf$E9';
         w := \"$00E9t$D800\";
         s := FOO_TO_STRING(1);
         END_PROGRAM",
    );
    for want in [
        "a string's length is a literal from 1 to 1024",
        "cannot assign a DINT to `s`, a STRING[4]",
        "cannot assign a STRING[4] to `N`",
        "cannot assign a WSTRING[80] to `s`",
        "`+` does not take strings",
        "LEFT takes 2 argument(s), not 1",
        "FIND takes a STRING",
        "`$E9`: a STRING escape is an ASCII code ($00 to $7F); use a WSTRING for others",
        "`$D800` is not a character (a UTF-16 surrogate)",
        "FOO_TO_STRING: `FOO` is not an elementary type",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}

#[test]
fn the_cost_of_each_string_function_is_printed() {
    // Ops of one call on STRING[80] operands (straight-line code, the same on
    // every scan); printed for docs/st.md, bounded so a change that makes
    // them grow is seen.
    let base = modes::program(
        "name,type\nN,INT\n",
        "PROGRAM Main VAR a, b, r : STRING; x : REAL; y : LREAL; t : TIME; dt : DT; END_VAR N := 1; END_PROGRAM",
    )
    .ops
    .len();
    let mut costs = Vec::new();
    for (call, bound) in [
        ("r := a;", 100),
        ("N := LEN(a);", 10),
        ("r := LEFT(a, N);", 500),
        ("r := RIGHT(a, N);", 950),
        ("r := MID(a, N, N);", 1_250),
        ("r := CONCAT(a, b);", 2_300),
        ("r := CONCAT('x = ', b);", 320),
        ("r := INSERT(a, b, N);", 5_600),
        ("r := DELETE(a, N, N);", 2_400),
        ("r := REPLACE(a, b, N, N);", 5_600),
        ("N := FIND(a, 'abc');", 700),
        ("N := FIND(a, b);", 20_000),
        ("N := BOOL_TO_INT(a < b);", 400),
        ("r := INT_TO_STRING(N);", 560),
        ("N := STRING_TO_INT(a);", 2_800),
        ("r := REAL_TO_STRING(x);", 4_000),
        ("r := LREAL_TO_STRING(y);", 6_000),
        ("r := TIME_TO_STRING(t);", 4_000),
        ("x := STRING_TO_REAL(a);", 8_000),
        ("t := STRING_TO_TIME(a);", 17_000),
        ("r := DT_TO_STRING(dt);", 5_000),
        ("dt := STRING_TO_DT(a);", 16_000),
    ] {
        let p = modes::program(
            "name,type\nN,INT\n",
            &format!(
                "PROGRAM Main VAR a, b, r : STRING; x : REAL; y : LREAL; t : TIME; dt : DT; END_VAR N := 1; {call} END_PROGRAM"
            ),
        );
        let ops = p.ops.len() - base;
        costs.push(format!("{call} {ops}"));
        assert!(ops <= bound, "`{call}`: {ops} ops");
    }
    println!("ops per call on STRING[80]: {}", costs.join(", "));
}

#[test]
fn conversions_between_strings_and_reals_times_and_bools() {
    let (v, faults) = once(
        "name,type\nR1,REAL\nR2,REAL\nR3,REAL\nL1,LREAL\nL2,LREAL\nL3,LREAL\nB1,BOOL\nB2,BOOL\nB3,BOOL\nB4,BOOL\n",
        "PROGRAM Main
         VAR a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u : STRING; w : WSTRING[12]; x : REAL := 0.1; END_VAR
         a := REAL_TO_STRING(12.5);
         b := REAL_TO_STRING(-100.0);
         c := REAL_TO_STRING(x);
         d := REAL_TO_STRING(1.0E10);
         e := REAL_TO_STRING(0.0);
         f := REAL_TO_STRING(1234567.0);
         g := REAL_TO_STRING(-2.5E-7);
         h := LREAL_TO_STRING(LREAL#0.1 + LREAL#0.2);
         i := LREAL_TO_STRING(LREAL#1.5E300);
         j := LREAL_TO_STRING(LREAL#-0.00001);
         k := LREAL_TO_STRING(LREAL#123456789012345.0);
         l := TIME_TO_STRING(T#1h2m3s4ms);
         m := TIME_TO_STRING(T#0s);
         n := TIME_TO_STRING(T#-1.5s);
         o := TIME_TO_STRING(T#24d20h31m23s647ms);
         p := LTIME_TO_STRING(LTIME#1d1ms2us3ns);
         q := BOOL_TO_STRING(x > 0.0);
         r := BOOL_TO_STRING(FALSE);
         w := REAL_TO_WSTRING(9.99);
         R1 := STRING_TO_REAL('  -1.5E3x');
         R2 := STRING_TO_REAL('0.1');
         R3 := STRING_TO_REAL('abc');
         L1 := STRING_TO_LREAL('3.14159265358979');
         L2 := STRING_TO_LREAL(LREAL_TO_STRING(LREAL#2.5E-8));
         L3 := STRING_TO_LREAL('+42.');
         s := REAL_TO_STRING(STRING_TO_REAL('7e-2'));
         t := REAL_TO_STRING(9.9999999);
         u := LREAL_TO_STRING(LREAL#1.0E15);
         B1 := STRING_TO_BOOL('true');
         B2 := STRING_TO_BOOL(' 1');
         B3 := STRING_TO_BOOL('FALSE');
         B4 := STRING_TO_BOOL(BOOL_TO_STRING(TRUE));
         END_PROGRAM",
        &[
            W::S("Main.a"),
            W::S("Main.b"),
            W::S("Main.c"),
            W::S("Main.d"),
            W::S("Main.e"),
            W::S("Main.f"),
            W::S("Main.g"),
            W::S("Main.h"),
            W::S("Main.i"),
            W::S("Main.j"),
            W::S("Main.k"),
            W::S("Main.l"),
            W::S("Main.m"),
            W::S("Main.n"),
            W::S("Main.o"),
            W::S("Main.p"),
            W::S("Main.q"),
            W::S("Main.r"),
            W::S("Main.w"),
            W::V("R1"),
            W::V("R2"),
            W::V("R3"),
            W::V("L1"),
            W::V("L2"),
            W::V("L3"),
            W::S("Main.s"),
            W::S("Main.t"),
            W::S("Main.u"),
            W::V("B1"),
            W::V("B2"),
            W::V("B3"),
            W::V("B4"),
        ],
    );
    assert_eq!(
        v,
        [
            "12.5",
            "-100.0",
            "0.1",
            "1.0E10",
            "0.0",
            "1234567.0",
            "-2.5E-7",
            "0.3",
            "1.5E300",
            "-0.00001",
            "123456789012345.0",
            "T#1h2m3s4ms",
            "T#0ms",
            "T#-1s500ms",
            "T#24d20h31m23s647ms",
            "LTIME#1d1ms2us3ns",
            "TRUE",
            "FALSE",
            "9.99",
            "-1500",
            "0.1",
            "0",
            "3.14159265358979",
            "2.5e-8",
            "42",
            "0.07",
            "10.0",
            "1.0E15",
            "1",
            "1",
            "0",
            "1",
        ]
    );
    assert_eq!(faults, 0);
}

/// `s<k> := exprs[k];` into STRINGs `s<k>`, run in every mode: their values and the
/// faults.
fn strings_of(exprs: &[String]) -> (Vec<String>, u64) {
    let body: String = exprs
        .iter()
        .enumerate()
        .map(|(k, e)| format!("s{k} := {e};\n"))
        .collect();
    let vars: Vec<String> = (0..exprs.len()).map(|k| format!("s{k}")).collect();
    let program = format!(
        "PROGRAM Main VAR {} : STRING; END_VAR\n{body}END_PROGRAM",
        vars.join(", ")
    );
    let read: Vec<String> = vars.iter().map(|v| format!("Main.{v}")).collect();
    let watch: Vec<W> = read.iter().map(|r| W::S(r.as_str())).collect();
    once("name,type\nN,INT\n", &program, &watch)
}

#[test]
fn durations_read_from_strings() {
    let texts = [
        "T#1h2m3s4ms",
        "t#1H30M",
        "  TIME#-1.5s",
        "-1.5s",
        "1d_2h",
        "2m",
        "2ms",
        "T#24d20h31m23s647ms",
        "5s!",
        "T#1.2345s",
        "abc",
        "T5s",
        "T# 5s",
        "12",
        "1us",
        "1x5s",
        "",
    ];
    let want = [
        "T#1h2m3s4ms",
        "T#1h30m",
        "T#-1s500ms",
        "T#-1s500ms",
        "T#1d2h",
        "T#2m",
        "T#2ms",
        "T#24d20h31m23s647ms",
        "T#5s",
        "T#1s234ms",
        "T#0ms",
        "T#0ms",
        "T#0ms",
        "T#0ms",
        "T#0ms",
        "T#0ms",
        "T#0ms",
    ];
    let long = [
        ("LTIME#1d1ms2us3ns", "LTIME#1d1ms2us3ns"),
        ("lt#2us3NS", "LTIME#2us3ns"),
        ("LTIME#1.5us", "LTIME#1us500ns"),
        ("1m1s", "LTIME#1m1s"),
        ("3u", "LTIME#0ns"),
    ];
    let mut texts_of: Vec<String> = texts
        .iter()
        .map(|t| format!("TIME_TO_STRING(STRING_TO_TIME('{t}'))"))
        .collect();
    texts_of.extend(
        long.iter()
            .map(|(t, _)| format!("LTIME_TO_STRING(STRING_TO_LTIME('{t}'))")),
    );
    // TIME_TO_STRING's text reads back as the same duration.
    texts_of.push("TIME_TO_STRING(STRING_TO_TIME(TIME_TO_STRING(T#-3d4h5m6s7ms)))".into());
    let (v, faults) = strings_of(&texts_of);
    let mut expected: Vec<&str> = want.to_vec();
    expected.extend(long.iter().map(|(_, w)| *w));
    expected.push("T#-3d4h5m6s7ms");
    assert_eq!(v, expected);
    assert_eq!(faults, 0);
    // Too long for a TIME (a DINT of milliseconds): the overflow fault, as STRING_TO_DINT.
    let (_, faults) = once(
        "name,type\nN,INT\n",
        "PROGRAM Main VAR t : TIME; END_VAR t := STRING_TO_TIME('T#30d'); END_PROGRAM",
        &[],
    );
    assert_eq!(faults, 1);
}

#[test]
fn dates_read_from_strings() {
    // (function, text, what its *_TO_STRING writes)
    let cases = [
        ("DATE", "D#2024-01-31", "D#2024-01-31"),
        ("DATE", "  date#2000-02-29", "D#2000-02-29"),
        ("DATE", "1999-12-31", "D#1999-12-31"),
        ("DATE", "D#2024-1-5x", "D#2024-01-05"),
        ("DATE", "D#1970-01-01", "D#1970-01-01"),
        ("DATE", "D#1969-12-31", "D#1969-12-31"),
        ("DATE", "D#2_024-03-01", "D#2024-03-01"),
        ("DATE", "D#2023-02-29", "D#1970-01-01"),
        ("DATE", "D#1900-02-29", "D#1970-01-01"),
        ("DATE", "D#2024-13-01", "D#1970-01-01"),
        ("DATE", "D#2024-04-31", "D#1970-01-01"),
        ("DATE", "D#2024-01", "D#1970-01-01"),
        ("DATE", "D2024-01-01", "D#1970-01-01"),
        ("DATE", "", "D#1970-01-01"),
        ("TOD", "TOD#08:05:03.04", "TOD#08:05:03.04"),
        ("TOD", "time_of_day#23:59:59.9999", "TOD#23:59:59.999"),
        ("TOD", "12:30", "TOD#12:30:00"),
        ("TOD", "TOD#7:5:3!", "TOD#07:05:03"),
        ("TOD", "TOD#24:00:00", "TOD#00:00:00"),
        ("TOD", "TOD#12:60", "TOD#00:00:00"),
        ("TOD", "TOD#12", "TOD#00:00:00"),
        ("DT", "DT#2024-01-31-12:30:15.5", "DT#2024-01-31-12:30:15.5"),
        ("DT", "date_and_time#1970-01-01-00:00:01", "DT#1970-01-01-00:00:01"),
        ("DT", "DT#2024-02-29-23:59", "DT#2024-02-29-23:59:00"),
        ("DT", "DT#2024-02-29", "DT#1970-01-01-00:00:00"),
        ("DT", "DT#2024-02-30-01:00", "DT#1970-01-01-00:00:00"),
    ];
    let mut texts_of: Vec<String> = cases
        .iter()
        .map(|(f, t, _)| format!("{f}_TO_STRING(STRING_TO_{f}('{t}'))"))
        .collect();
    // What *_TO_STRING writes reads back as the same value.
    texts_of.push("DT_TO_STRING(STRING_TO_DT(DT_TO_STRING(DT#1987-06-05-04:03:02.1)))".into());
    texts_of.push("DATE_TO_STRING(STRING_TO_DATE(DATE_TO_STRING(D#1600-03-01)))".into());
    let (v, faults) = strings_of(&texts_of);
    let mut expected: Vec<&str> = cases.iter().map(|(_, _, w)| *w).collect();
    expected.extend(["DT#1987-06-05-04:03:02.1", "D#1600-03-01"]);
    assert_eq!(v, expected);
    assert_eq!(faults, 0);
}

#[test]
fn dates_and_times_of_day_as_their_literals() {
    let (v, faults) = once(
        "name,type\n",
        "PROGRAM Main
         VAR a, b, c, d, e, f, g : STRING; t : TOD := TOD#08:05:03.04; END_VAR
         a := DATE_TO_STRING(D#2024-01-31);
         b := DATE_TO_STRING(D#2000-02-29);
         c := TOD_TO_STRING(TOD#12:30:15.5);
         d := TOD_TO_STRING(t);
         e := DT_TO_STRING(DT#2024-01-31-12:30:00);
         f := DT_TO_STRING(DT#1969-12-31-23:59:59.25);
         g := TIME_OF_DAY_TO_STRING(TOD#00:00:00);
         END_PROGRAM",
        &[
            W::S("Main.a"),
            W::S("Main.b"),
            W::S("Main.c"),
            W::S("Main.d"),
            W::S("Main.e"),
            W::S("Main.f"),
            W::S("Main.g"),
        ],
    );
    assert_eq!(
        v,
        [
            "D#2024-01-31",
            "D#2000-02-29",
            "TOD#12:30:15.5",
            "TOD#08:05:03.04",
            "DT#2024-01-31-12:30:00",
            "DT#1969-12-31-23:59:59.25",
            "TOD#00:00:00",
        ]
    );
    assert_eq!(faults, 0);
}
