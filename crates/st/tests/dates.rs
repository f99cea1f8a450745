//! LTIME, DATE, TIME_OF_DAY and DATE_AND_TIME (docs/st.md, ADR 0017):
//! literals, arithmetic, comparisons and conversions in every engine mode,
//! which must agree on every scan; the overflow of a difference that does
//! not fit a TIME; what is refused.

#[path = "common/modes.rs"]
mod modes;

use modes::{W, errors, once};

/// Milliseconds since 1970-01-01 of a few days (`date -u -d … +%s`).
const FEB_28_2024: i64 = 1_709_078_400_000;
const FEB_29_2024: i64 = 1_709_164_800_000;
const MAR_10_2024: i64 = 1_710_028_800_000;
const HOUR: i64 = 3_600_000;

#[test]
fn dates_times_of_day_and_long_times_compute_what_the_standard_says() {
    let (v, faults) = once(
        "name,type\nMs,TIME\n",
        "PROGRAM Main
         VAR
           d1 : DATE := D#2024-02-28;
           d2, d3 : DATE;
           t1 : TOD := TOD#23:59:59.5;
           t2 : TIME_OF_DAY;
           dt1 : DT := DT#2024-02-28-23:00:00;
           dt2 : DATE_AND_TIME;
           lt : LTIME := LTIME#1ms500us;
           lt2, lt3 : LTIME;
           span1, span2, span3 : TIME;
           b1, b2, b3, b4 : BOOL;
           n, epoch : LINT;
         END_VAR
         d2 := DATE#2024-03-10;
         span1 := d2 - d1;
         dt2 := dt1 + T#2h;
         span2 := dt2 - dt1;
         t2 := DT_TO_TOD(dt2);
         d3 := DT_TO_DATE(dt2);
         span3 := TOD#12:00 - t1;
         lt2 := lt * 3 + TIME_TO_LTIME(T#2s) - LTIME#1us;
         lt3 := -lt2 / 2;
         n := LTIME_TO_LINT(lt2);
         epoch := DATE_TO_LINT(D#1970-01-01);
         Ms := LTIME_TO_TIME(lt2);
         b1 := d1 < d2;
         b2 := dt2 = CONCAT_DATE_TOD(D#2024-02-29, TOD#01:00:00);
         b3 := lt > LTIME#1ms;
         b4 := t1 <= TOD#12:00:00;
         END_PROGRAM",
        &[
            W::V("Main.d1"),
            W::V("Main.d2"),
            W::V("Main.span1"),
            W::V("Main.dt2"),
            W::V("Main.span2"),
            W::V("Main.t2"),
            W::V("Main.d3"),
            W::V("Main.span3"),
            W::V("Main.lt2"),
            W::V("Main.lt3"),
            W::V("Main.n"),
            W::V("Main.epoch"),
            W::V("Ms"),
            W::V("Main.b1"),
            W::V("Main.b2"),
            W::V("Main.b3"),
            W::V("Main.b4"),
        ],
    );
    let int = |s: &String| -> i64 {
        s.trim_start_matches("T#")
            .trim_end_matches("ms")
            .parse()
            .unwrap_or_else(|_| panic!("not a number: {s}"))
    };
    let nums: Vec<i64> = v[..13].iter().map(int).collect();
    assert_eq!(
        nums,
        [
            FEB_28_2024,
            MAR_10_2024,
            11 * 24 * HOUR,
            FEB_29_2024 + HOUR,
            2 * HOUR,
            HOUR,
            FEB_29_2024,
            12 * HOUR - (24 * HOUR - 500),
            2_004_499_000,
            -1_002_249_500,
            2_004_499_000,
            0,
            2004,
        ]
    );
    assert_eq!(v[13..], ["1", "1", "1", "0"]);
    assert_eq!(faults, 0);
}

#[test]
fn a_difference_that_does_not_fit_a_time_is_an_overflow_fault() {
    // 60 days do not fit a TIME (32-bit milliseconds, 24.8 days).
    let (_, faults) = once(
        "name,type\nSpan,TIME\n",
        "PROGRAM Main
         Span := D#2024-03-01 - D#2024-01-01;
         END_PROGRAM",
        &[W::V("Span")],
    );
    assert_eq!(faults, 1);
}

#[test]
fn date_and_time_errors_are_located() {
    let e = errors(
        "name,type\n",
        "PROGRAM Main
         VAR d : DATE; t : TOD; x : DT; l : LTIME; END_VAR
         d := D#2024-02-30;
         t := TOD#25:00:00;
         x := d + d;
         x := x + 5;
         l := TO_LTIME(T#1s);
         d := x;
         l := T#1s;
         END_PROGRAM",
    );
    for want in [
        "`D#2024-02-30` is not a valid DATE literal",
        "`TOD#25:00:00` is not a valid TIME_OF_DAY literal",
        "`+` of DATE and DATE is not defined",
        "`+` of DATE_AND_TIME and DINT is not defined",
        "TO_LTIME of a TIME",
        "cannot assign a DATE_AND_TIME to `d`",
        "cannot assign a TIME to `l`",
    ] {
        assert!(e.contains(want), "missing `{want}` in:\n{e}");
    }
}
