//! Timers with a time base (`TON(T,5,0,s)`, issue 34 point 3) and SLC 500
//! operands (`T4:0.ACC`, `N7:2`, point 4): what the compiler emits and the
//! diagnostics it gives.

use alba_diag::{Code, Diagnostic, Files};
use alba_ir::{Builder, Op, TimeBase};
use alba_ladder::{Presets, compile, layout_for, parse};
use alba_model::TagTable;

const TAGS: &str = "name,type,address,initial,retain,description\nRun,BOOL,,,,\nT,TIMER,,,,\nU,TIMER,,,,\nN,DINT,,,,\n";

/// Compiles `src` (one or more programs separated by `---`) on `TAGS`.
fn build(src: &str) -> (Vec<Op>, Vec<Diagnostic>) {
    let mut files = Files::new();
    let tf = files.add("tags.csv", TAGS);
    let (tags, d) = TagTable::parse(TAGS, tf);
    assert!(d.is_empty(), "{d:?}");
    let parts: Vec<&str> = src.split("---").collect();
    let progs: Vec<_> = parts
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let f = files.add(format!("p{k}.lad"), *p);
            let (prog, d) = parse(p, f);
            assert!(d.is_empty(), "{d:?}");
            prog
        })
        .collect();
    let refs: Vec<_> = progs.iter().collect();
    let mut b = Builder::new(layout_for(&tags, &refs));
    let mut presets = Presets::default();
    let mut diags = Vec::new();
    for (k, (prog, text)) in progs.iter().zip(&parts).enumerate() {
        diags.extend(compile(prog, text, &format!("p{k}"), &mut b, &mut presets));
    }
    (b.finish(files).ops, diags)
}

fn bases(ops: &[Op]) -> Vec<(&'static str, TimeBase)> {
    ops.iter()
        .filter_map(|op| match op {
            Op::Ton(_, b) => Some(("TON", *b)),
            Op::Tof(_, b) => Some(("TOF", *b)),
            Op::Rto(_, b) => Some(("RTO", *b)),
            _ => None,
        })
        .collect()
}

fn codes(d: &[Diagnostic]) -> Vec<(Code, String)> {
    d.iter().map(|d| (d.code, d.message.clone())).collect()
}

#[test]
fn the_fourth_operand_is_the_time_base_and_none_is_ms() {
    let (ops, d) = build("XIC(Run)TON(T,5,0);\nXIC(Run)TOF(U,5,0,min);\n");
    assert!(d.is_empty(), "{:?}", codes(&d));
    assert_eq!(bases(&ops), [("TON", TimeBase::Ms), ("TOF", TimeBase::Min)]);
    for (text, base) in [
        ("ms", TimeBase::Ms),
        ("CS", TimeBase::Cs),
        ("ds", TimeBase::Ds),
        ("s", TimeBase::S),
        ("Min", TimeBase::Min),
        ("0.001", TimeBase::Ms),
        ("0.01", TimeBase::Cs),
        ("0.1", TimeBase::Ds),
        ("1.0", TimeBase::S),
        ("60", TimeBase::Min),
    ] {
        let (ops, d) = build(&format!("XIC(Run)RTO(T,5,0,{text});\n"));
        assert!(d.is_empty(), "{text}: {:?}", codes(&d));
        assert_eq!(bases(&ops), [("RTO", base)], "{text}");
    }
}

#[test]
fn a_bad_time_base_is_e310_at_the_operand() {
    let src = "XIC(Run)TON(T,5,0,h);\n";
    let (_, d) = build(src);
    assert_eq!(d.len(), 1, "{:?}", codes(&d));
    assert_eq!(d[0].code, Code::BadLiteral);
    assert!(d[0].message.contains("`h` is not a time base"), "{}", d[0].message);
    let span = d[0].primary.as_ref().map(|l| l.span).expect("a place");
    assert_eq!(&src[span.range()], "h");
}

#[test]
fn one_timer_has_one_time_base_across_programs() {
    let (_, d) = build("XIC(Run)TON(T,5,0,s);\n---\nXIC(Run)RTO(T,5,0,ds);\n");
    assert_eq!(d.len(), 1, "{:?}", codes(&d));
    assert_eq!(d[0].code, Code::ConflictingPreset);
    assert!(
        d[0].message.contains("the time base s given earlier"),
        "{}",
        d[0].message
    );
    // No base is ms: it conflicts with a base given elsewhere.
    let (_, d) = build("XIC(Run)TON(T,5,0);\nXIC(Run)TOF(T,5,0,cs);\n");
    assert_eq!(
        codes(&d).first().map(|c| c.0),
        Some(Code::ConflictingPreset),
        "{:?}",
        codes(&d)
    );
    // TP counts milliseconds: not on a timer with another base.
    let (_, d) = build("XIC(Run)TON(T,5,0,s);\nXIC(Run)TP(T,5,0);\n");
    assert_eq!(
        codes(&d).first().map(|c| c.0),
        Some(Code::ConflictingPreset),
        "{:?}",
        codes(&d)
    );
    // The same base twice (by name and in seconds) is one base.
    let (_, d) = build("XIC(Run)TON(T,5,0,s);\nXIC(Run)TON(T,5,0,1.0);\n");
    assert!(d.is_empty(), "{:?}", codes(&d));
}

#[test]
fn a_duration_counts_in_the_timers_base() {
    // T#5s in a base of s is 5; T#1500ms in ds is 15; in s it is no whole number.
    let (_, d) = build(
        "XIC(Run)TON(T,T#5s,0,s);\nXIC(Run)TON(T,5,0,s);\nXIC(Run)TOF(U,T#1500ms,0,ds);\nXIC(Run)TOF(U,15,0,ds);\n",
    );
    assert!(d.is_empty(), "{:?}", codes(&d));
    let src = "XIC(Run)TON(T,T#1500ms,0,s);\n";
    let (_, d) = build(src);
    assert_eq!(d.len(), 1, "{:?}", codes(&d));
    assert_eq!(d[0].code, Code::BadLiteral);
    assert!(d[0].message.contains("not a whole number of s"), "{}", d[0].message);
    let span = d[0].primary.as_ref().map(|l| l.span).expect("a place");
    assert_eq!(&src[span.range()], "T#1500ms");
}

#[test]
fn tp_and_five_operands_are_refused_with_the_count() {
    let (_, d) = build("XIC(Run)TP(T,5,0,s);\n");
    assert_eq!(
        codes(&d).first().map(|c| c.0),
        Some(Code::OperandCount),
        "{:?}",
        codes(&d)
    );
    let (_, d) = build("XIC(Run)TON(T,5,0,s,s);\n");
    assert_eq!(d.len(), 1, "{:?}", codes(&d));
    assert_eq!(d[0].code, Code::OperandCount);
    assert!(
        d[0].message.contains("3 operands, or 4 with a time base"),
        "{}",
        d[0].message
    );
}

#[test]
fn slc_operands_compile_wherever_a_tag_does() {
    let (ops, d) = build(
        "XIC(I:1/0)TON(T4:0,3,0,s);\nXIC(T4:0.DN)OTE(O:0/3);\nXIC(B3:0/1)CTU(C5:1,2,0);\nXIC(C5:1.DN)MOV(T4:0.ACC,N7:2);\nMOV(N7:2,F8:0);\n",
    );
    assert!(d.is_empty(), "{:?}", codes(&d));
    assert_eq!(bases(&ops), [("TON", TimeBase::S)]);
    assert!(ops.iter().any(|o| matches!(o, Op::Ctu(_))));
    // A REAL is written into F8:0 (its marker double word).
    assert!(
        ops.iter().any(|o| matches!(
            o,
            Op::StM {
                slot: alba_ir::MarkerSlot::Real(_),
                byte: 1024
            }
        )),
        "{ops:?}"
    );
}

#[test]
fn slc_names_in_cpt_expressions_resolve_and_make_their_timers() {
    // T4:5 is named only inside the expression: the layout still makes it.
    let (ops, d) = build("CPT(N7:0,T4:5.ACC*2+N7:2);\nCPT(F8:1,F8:0*2.5);\nCPT(N7:1,B3:1+1);\n");
    assert!(d.is_empty(), "{:?}", codes(&d));
    assert!(
        ops.iter().any(|o| matches!(
            o,
            Op::StM {
                slot: alba_ir::MarkerSlot::Real(_),
                byte: 1028
            }
        )),
        "F8:1 written as a REAL: {ops:?}"
    );
}

#[test]
fn bad_slc_operands_are_precise() {
    for (src, needle, code) in [
        ("XIC(N12:0)OTE(Run);\n", "N12 is not one of them", Code::BadAddress),
        ("XIC(B3:0/16)OTE(Run);\n", "0 to 15", Code::BadAddress),
        ("XIC(T4:0.XX)OTE(Run);\n", "has no member `XX`", Code::UnknownMember),
        ("XIC(Run)OTE(I:0/1);\n", "input", Code::NotWritable),
    ] {
        let (_, d) = build(src);
        assert!(!d.is_empty(), "{src}");
        assert_eq!(d[0].code, code, "{src}: {:?}", codes(&d));
        let label = d[0].primary.as_ref().map(|l| l.message.as_str()).unwrap_or("");
        assert!(
            d[0].message.contains(needle) || label.contains(needle),
            "{src}: {:?}",
            codes(&d)
        );
    }
}
