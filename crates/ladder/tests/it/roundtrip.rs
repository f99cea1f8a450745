//! Round trips: print a random AST, parse it back, get the same AST
//! (ignoring spans) and no diagnostics; and `print ∘ parse` is the identity
//! on canonical text.

use crate::check::{ast_diff, ast_spans, ladder_input};
use crate::strategies::{config, expr, program};
use alba_diag::FileId;
use alba_ladder::{parse, print};
use proptest::prelude::*;
use std::path::Path;

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn print_then_parse_gives_the_ast_back(p in program()) {
        let text = print(&p);
        let (q, diags) = parse(&text, FileId(0));
        prop_assert!(
            diags.is_empty(),
            "diagnostics on printed text: {:?}\n{text}",
            diags.iter().map(|d| &d.message).collect::<Vec<_>>()
        );
        if let Some(d) = ast_diff(&p, &q) {
            prop_assert!(false, "{d}\ntext:\n{text}");
        }
        if let Err(e) = ast_spans(&text, FileId(0), &q) {
            prop_assert!(false, "{e}\ntext:\n{text}");
        }
    }

    #[test]
    fn printer_after_parser_is_the_identity_on_canonical_text(p in program()) {
        let text = print(&p);
        let (q, _) = parse(&text, FileId(0));
        prop_assert_eq!(print(&q), text);
    }

    /// The generator's CPT expressions are valid expressions (so the round
    /// trip above really carries expressions), and the parser's spans stay
    /// inside the operand.
    #[test]
    fn generated_expressions_parse(e in expr()) {
        let base = 9;
        match alba_ladder::expr::parse(&e, FileId(0), base) {
            Ok(_) => {}
            Err((msg, sp)) => prop_assert!(false, "{e:?}: {msg} at {}..{}", sp.start, sp.end),
        }
    }
}

#[test]
fn hand_written_canonical_programs_are_fixed_points() {
    let texts = [
        "",
        ";\n",
        "XIC(a);\n",
        "// Start/stop with seal-in, then a 5 s delay\n[XIC(Start),XIC(Motor)]XIO(Stop)OTE(Motor);\nXIC(Motor)TON(Delay,5000,0);\nXIC(Delay.DN)OTE(Lamp);\n",
        "//\n// two\nAFI()NOP();\n// trailing\n//\n",
        "[[XIC(a),XIO(b)][XIC(c),[XIC(d),XIC(e)]],XIC(f)]OTE(g);\n",
        "CPT(x,ATAN2(y, z) * (A + B) ** -2)MOV(DI:1/3,%MW4)ADD(I0.2,-1.5e3,MW4);\n",
        "LIM(?,A[3],16#FF)TON(T,T#5s,?);\n",
        "// ünïcödé → 中文\nXIC(Motör)OTE(ß);\n",
    ];
    for t in texts {
        let (p, d) = parse(t, FileId(0));
        assert!(d.is_empty(), "{t:?}: {d:?}");
        assert_eq!(print(&p), t);
        ladder_input(t).unwrap();
    }
}

/// Every example program survives parse → print → parse.
#[test]
fn examples_round_trip() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut n = 0;
    for dir in std::fs::read_dir(&root).unwrap() {
        let path = dir.unwrap().path().join("main.lad");
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        n += 1;
        let (p, d) = parse(&text, FileId(0));
        assert!(d.is_empty(), "{}: {d:?}", path.display());
        let printed = print(&p);
        let (q, d) = parse(&printed, FileId(0));
        assert!(d.is_empty(), "{}: {d:?}", path.display());
        assert_eq!(ast_diff(&p, &q), None, "{}", path.display());
        assert_eq!(print(&q), printed);
    }
    assert!(n > 0, "no examples/*/main.lad found under {}", root.display());
}
