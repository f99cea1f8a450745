//! Non-canonical text normalises: whitespace and line breaks between tokens
//! and inside operands, lowercase mnemonics, several rungs on one line,
//! indented comments, CRLF: parsing gives the same AST as the canonical text.

use crate::check::{ast_diff, ast_spans};
use crate::strategies::{config, noisy, program};
use alba_diag::FileId;
use alba_ladder::{parse, print};
use proptest::prelude::*;

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn noisy_text_parses_to_the_canonical_ast((p, seed) in (program(), any::<u64>())) {
        let text = noisy(&p, seed);
        let (q, diags) = parse(&text, FileId(0));
        prop_assert!(
            diags.is_empty(),
            "diagnostics: {:?}\ntext: {text:?}",
            diags.iter().map(|d| &d.message).collect::<Vec<_>>()
        );
        if let Some(d) = ast_diff(&p, &q) {
            prop_assert!(false, "{d}\ntext: {text:?}");
        }
        if let Err(e) = ast_spans(&text, FileId(0), &q) {
            prop_assert!(false, "{e}\ntext: {text:?}");
        }
        prop_assert_eq!(print(&q), print(&p));
    }
}

#[test]
fn hand_written_non_canonical_texts() {
    let cases = [
        ("xic(a)ote(b);", "XIC(a)OTE(b);\n"),
        ("  Xic ( a )\n\tOtE(\n b\n)\r\n;", "XIC(a)OTE(b);\n"),
        ("XIC(a);XIO(b)OTE(c);  XIC(d) ;\n", "XIC(a);\nXIO(b)OTE(c);\nXIC(d);\n"),
        ("[ xic(a) ,\n  xio( b ) ] ote(c);", "[XIC(a),XIO(b)]OTE(c);\n"),
        ("cpt( x ,  (A  +\n B)\t*  2 );", "CPT(x,(A + B) * 2);\n"),
        (
            "   //   spaced comment   \r\n\r\n  XIC(a);\r\n//tail\t\r\n",
            "// spaced comment\nXIC(a);\n// tail\n",
        ),
        ("afi( )nop(\u{a0});", "AFI()NOP();\n"),
        // Whitespace inside an operand collapses to one space; it is not
        // removed, so `( A + B )` stays a different text from `(A + B)`.
        ("CPT(x,( A\t+ B ));", "CPT(x,( A + B ));\n"),
    ];
    for (input, canonical) in cases {
        let (p, d) = parse(input, FileId(0));
        assert!(d.is_empty(), "{input:?}: {d:?}");
        assert_eq!(print(&p), canonical, "{input:?}");
        let (q, _) = parse(canonical, FileId(0));
        assert_eq!(ast_diff(&p, &q), None, "{input:?}");
        ast_spans(input, FileId(0), &p).unwrap();
    }
}
