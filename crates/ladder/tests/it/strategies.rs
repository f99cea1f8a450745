//! Generators of random ladder programs (as ASTs), CPT expressions and
//! operands in canonical text, and a "noisy" printer that writes a program in
//! a legal but non-canonical way.

use alba_diag::{FileId, Span};
use alba_ladder::{Arg, Branch, Element, Instr, Mnemonic, Operand, Program, Rung};
use proptest::prelude::*;
use proptest::test_runner::Config;

/// A proptest configuration with `cases` cases unless `PROPTEST_CASES` is set.
pub fn config(cases: u32) -> Config {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(cases);
    Config {
        cases,
        ..Config::default()
    }
}

/// The span generated ASTs carry (spans are ignored when comparing).
pub fn no_span() -> Span {
    Span::new(FileId(0), 0..0)
}

pub fn ident() -> impl Strategy<Value = String> {
    "[A-Za-z_][A-Za-z0-9_]{0,9}"
}

/// An identifier that is not an expression keyword or constant.
pub fn expr_ident() -> impl Strategy<Value = String> {
    ident().prop_filter("keyword", |s| {
        !["MOD", "AND", "OR", "XOR", "NOT", "PI", "E"]
            .iter()
            .any(|k| k.eq_ignore_ascii_case(s))
    })
}

pub fn member() -> impl Strategy<Value = String> {
    let field = prop_oneof![
        prop::sample::select(vec!["DN", "ACC", "PRE", "EN", "TT", "CU", "CD", "OV", "UN", "SP", "PV"])
            .prop_map(str::to_string),
        ident(),
    ];
    (ident(), field, proptest::option::of(ident())).prop_map(|(a, b, c)| match c {
        Some(c) => format!("{a}.{b}.{c}"),
        None => format!("{a}.{b}"),
    })
}

/// Addresses in every notation of SPEC §2.2, plus system bits.
pub fn address() -> impl Strategy<Value = String> {
    prop_oneof![
        "(DI|DO|AI|AO|di|do):[1-4]/[0-9]{1,2}",
        "%(IX|QX|MX)[0-9]{1,2}\\.[0-7]",
        "%(IW|QW|MW|MD|ix|qw)[0-9]{1,3}",
        "[IQM][0-9]{1,2}\\.[0-7]",
        "(MB|MW|MD|AIW|AQW)[0-9]{1,3}",
        "Ain[0-9]",
        Just("S:FS".to_string()),
        Just("SM0.1".to_string()),
    ]
}

pub fn int_lit() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => "-?[0-9]{1,9}",
        1 => "(16#[0-9A-F]{1,4}|2#[01]{1,8}|[0-9]{1,3}_[0-9]{3})",
        1 => "T#[0-9]{1,3}(ms|s|m|h)",
    ]
}

pub fn real_lit() -> impl Strategy<Value = String> {
    "-?[0-9]{1,4}\\.[0-9]{1,4}([eE]-?[0-9]{1,2})?"
}

/// Operand text the parser passes through untouched: no whitespace, no
/// `,` `(` `)` `[` `]` `;` (unicode welcome).
pub fn raw_operand() -> impl Strategy<Value = String> {
    "[^\\s,()\\[\\];]{1,8}"
}

/// Any non-expression operand, canonical.
pub fn operand() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => ident(),
        3 => member(),
        3 => address(),
        3 => int_lit(),
        2 => real_lit(),
        1 => Just("?".to_string()),
        1 => (ident(), 0..20u32).prop_map(|(a, i)| format!("{a}[{i}]")),
        1 => raw_operand(),
    ]
}

/// A CPT expression in canonical text: single spaces around binary
/// operators, `, ` between function arguments, none inside parentheses.
pub fn expr() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        4 => expr_ident(),
        2 => member(),
        2 => address(),
        3 => int_lit(),
        2 => real_lit(),
        1 => prop::sample::select(vec!["PI", "E", "pi"]).prop_map(str::to_string),
    ];
    leaf.prop_recursive(4, 12, 2, |inner| {
        let op = prop::sample::select(vec![
            "+", "-", "*", "/", "MOD", "**", "^", "=", "<>", "<", ">", "<=", ">=", "AND", "OR", "XOR", "mod", "and",
        ]);
        let func = prop::sample::select(vec![
            "SQR", "SQRT", "ABS", "SIN", "COS", "TAN", "ASN", "ACS", "ATN", "LN", "LOG", "DEG", "RAD", "TRN", "FRD",
            "TOD", "ROUND", "sqrt",
        ]);
        prop_oneof![
            4 => (inner.clone(), op, inner.clone()).prop_map(|(a, o, b)| format!("{a} {o} {b}")),
            2 => inner.clone().prop_map(|a| format!("({a})")),
            2 => (func, inner.clone()).prop_map(|(f, a)| format!("{f}({a})")),
            1 => (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("ATAN2({a}, {b})")),
            1 => inner.clone().prop_map(|a| format!("NOT {a}")),
            1 => inner.prop_map(|a| format!("-({a})")),
        ]
    })
}

/// Operand text for a position: an expression for CPT's, otherwise any
/// operand (the parser does not look at what a position expects).
pub fn operand_for(arg: Arg) -> BoxedStrategy<String> {
    match arg {
        Arg::Expr => expr().boxed(),
        _ => operand().boxed(),
    }
}

pub fn instr() -> impl Strategy<Value = Instr> {
    prop::sample::select(Mnemonic::ALL).prop_flat_map(|m| {
        let ops: Vec<BoxedStrategy<String>> = m.args().iter().map(|&a| operand_for(a)).collect();
        ops.prop_map(move |texts| Instr {
            mnemonic: m,
            operands: texts
                .into_iter()
                .map(|text| Operand { text, span: no_span() })
                .collect(),
            span: no_span(),
            name_span: no_span(),
        })
    })
}

/// An element: an instruction or a (nested) branch of 2+ non-empty legs.
/// Branches nest up to 4 deep; about a third of the elements are branches.
/// (Hand-rolled rather than `prop_recursive`, which made programs ten
/// times larger and slower to generate for no extra coverage.)
pub fn element() -> BoxedStrategy<Element> {
    element_at(4)
}

fn element_at(depth: u32) -> BoxedStrategy<Element> {
    let leaf = instr().prop_map(Element::Instr);
    if depth == 0 {
        return leaf.boxed();
    }
    let branch = prop::collection::vec(prop::collection::vec(element_at(depth - 1), 1..3), 2..4)
        .prop_map(|legs| Element::Branch(Branch { legs, span: no_span() }));
    prop_oneof![2 => leaf, 1 => branch].boxed()
}

/// One comment line as the parser keeps it: trimmed, no line break.
pub fn comment_line() -> impl Strategy<Value = String> {
    prop_oneof![
        8 => "[ -~]{0,40}",
        2 => "[ -~àéñüß€中文→Ω\\t]{0,20}",
        1 => Just(String::new()),
    ]
    .prop_map(|s| s.trim().to_string())
}

pub fn rung() -> impl Strategy<Value = Rung> {
    (
        prop::collection::vec(comment_line(), 0..3),
        prop_oneof![
            8 => prop::collection::vec(element(), 1..5),
            1 => Just(Vec::new()),
        ],
    )
        .prop_map(|(comment, elements)| Rung {
            comment,
            elements,
            span: no_span(),
        })
}

pub fn program() -> impl Strategy<Value = Program> {
    (
        prop::collection::vec(rung(), 0..6),
        proptest::option::weighted(
            0.2,
            prop::collection::vec(comment_line(), 1..3).prop_map(|l| l.join("\n")),
        ),
    )
        .prop_map(|(rungs, trailing_comment)| Program {
            rungs,
            trailing_comment,
            broken_labels: Vec::new(),
        })
}

/// A small deterministic generator for the noisy printer (SplitMix64).
pub struct Noise(u64);

impl Noise {
    pub fn new(seed: u64) -> Noise {
        Noise(seed)
    }

    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// True one time in `n`.
    pub fn one_in(&mut self, n: u64) -> bool {
        self.next().is_multiple_of(n)
    }

    pub fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[(self.next() % from.len() as u64) as usize]
    }

    /// Whitespace between tokens (ASCII only: that is what the parser skips),
    /// often none.
    pub fn gap(&mut self) -> &'static str {
        if self.one_in(2) {
            ""
        } else {
            self.pick(&[" ", "  ", "\t", "\n", "\r\n", " \n\t ", "\n\n", "\x0c"])
        }
    }

    /// Whitespace inside an operand: anything `char::is_whitespace` accepts.
    pub fn op_gap(&mut self) -> &'static str {
        self.pick(&[
            " ",
            "   ",
            "\t",
            "\n",
            "\r\n",
            " \t\n ",
            "\u{a0}",
            "\u{3000}",
            "\u{2003} ",
        ])
    }
}

/// Writes `p` in legal but non-canonical text: whitespace and line breaks
/// between all tokens and around and inside operands, mnemonics in random
/// case, several rungs on one line, indented comments with extra spaces,
/// CRLF line ends, blank lines.
pub fn noisy(p: &Program, seed: u64) -> String {
    let mut n = Noise::new(seed);
    let mut out = String::new();
    out.push_str(n.gap());
    let mut at_line_start = true;
    for r in &p.rungs {
        if !r.comment.is_empty() && !at_line_start {
            out.push_str(n.pick(&["\n", "\r\n", " \n", "\n\n"]));
        }
        for c in &r.comment {
            noisy_comment(&mut out, &mut n, c);
        }
        noisy_elements(&mut out, &mut n, &r.elements);
        out.push_str(n.gap());
        out.push(';');
        let end = n.pick(&["\n", "\r\n", "", " ", "\t", "\n\n"]);
        out.push_str(end);
        at_line_start = end.ends_with('\n');
    }
    if let Some(c) = &p.trailing_comment {
        if !at_line_start {
            out.push('\n');
        }
        for line in c.split('\n') {
            noisy_comment(&mut out, &mut n, line);
        }
    }
    out.push_str(n.gap());
    out
}

fn noisy_comment(out: &mut String, n: &mut Noise, c: &str) {
    out.push_str(n.pick(&["", "", "  ", "\t"]));
    out.push_str("//");
    out.push_str(n.pick(&["", " ", " ", "   ", "\t"]));
    if c.is_empty() {
        // "//" then spaces: still an empty comment.
    } else {
        out.push_str(c);
    }
    out.push_str(n.pick(&["", "", "  ", "\t", "\r"]));
    out.push_str(n.pick(&["\n", "\r\n", "\n\n", "\n \t\n"]));
}

/// `XIC`, `xic`, `xIc`...
fn random_case(n: &mut Noise, name: &str) -> String {
    match n.next() % 3 {
        0 => name.to_string(),
        1 => name.to_ascii_lowercase(),
        _ => name
            .chars()
            .map(|c| if n.one_in(2) { c.to_ascii_lowercase() } else { c })
            .collect(),
    }
}

fn noisy_elements(out: &mut String, n: &mut Noise, elems: &[Element]) {
    for e in elems {
        out.push_str(n.gap());
        match e {
            Element::Instr(i) => {
                out.push_str(&random_case(n, i.mnemonic.name()));
                out.push_str(n.gap());
                out.push('(');
                if i.operands.is_empty() && n.one_in(2) {
                    out.push_str(n.op_gap());
                }
                for (k, o) in i.operands.iter().enumerate() {
                    if k > 0 {
                        out.push(',');
                    }
                    if n.one_in(2) {
                        out.push_str(n.op_gap());
                    }
                    for (w, word) in o.text.split(' ').enumerate() {
                        if w > 0 {
                            out.push_str(n.op_gap());
                        }
                        out.push_str(word);
                    }
                    if n.one_in(2) {
                        out.push_str(n.op_gap());
                    }
                }
                out.push(')');
            }
            Element::Branch(b) => {
                out.push('[');
                for (k, leg) in b.legs.iter().enumerate() {
                    if k > 0 {
                        out.push_str(n.gap());
                        out.push(',');
                    }
                    noisy_elements(out, n, leg);
                    out.push_str(n.gap());
                }
                out.push(']');
            }
        }
    }
}

/// Pieces that random inputs are made of: the punctuation of the grammar,
/// instruction names, operand fragments, whitespace and non-ASCII text.
pub const PIECES: &[&str] = &[
    "[",
    "]",
    "(",
    ")",
    ",",
    ";",
    "/",
    "//",
    " ",
    "\n",
    "\r\n",
    "\t",
    "XIC",
    "xio",
    "OTE",
    "TON",
    "CPT",
    "LBL",
    "JMP",
    "AFI",
    "ATAN2",
    "A",
    "b",
    "_x",
    "1",
    "0",
    "-",
    ".",
    ".DN",
    ":",
    "%",
    "#",
    "T#",
    "16#",
    "?",
    "\"",
    "'",
    "*",
    "**",
    "+",
    "e",
    "é",
    "中",
    "€",
    "\u{1F600}",
    "\u{a0}",
    "\u{200B}",
    "\u{FEFF}",
    "\0",
    "\\",
    "{",
    "}",
    "=",
    "<>",
];

/// A random mix of [`PIECES`].
pub fn soup() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(PIECES), 0..80).prop_map(|v| v.concat())
}

/// A mutation of a text: delete, insert or duplicate at a place chosen by
/// an index (moved back to a character boundary).
#[derive(Debug, Clone)]
pub enum Mutation {
    Delete(prop::sample::Index, usize),
    Insert(prop::sample::Index, &'static str),
    Duplicate(prop::sample::Index, usize),
    Swap(prop::sample::Index, prop::sample::Index),
}

pub fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<prop::sample::Index>(), 1..6usize).prop_map(|(i, n)| Mutation::Delete(i, n)),
        (any::<prop::sample::Index>(), prop::sample::select(PIECES)).prop_map(|(i, s)| Mutation::Insert(i, s)),
        (any::<prop::sample::Index>(), 1..20usize).prop_map(|(i, n)| Mutation::Duplicate(i, n)),
        (any::<prop::sample::Index>(), any::<prop::sample::Index>()).prop_map(|(i, j)| Mutation::Swap(i, j)),
    ]
}

fn boundary(s: &str, i: &prop::sample::Index) -> usize {
    if s.is_empty() {
        return 0;
    }
    let mut at = i.index(s.len() + 1);
    while !s.is_char_boundary(at) {
        at -= 1;
    }
    at
}

fn forward(s: &str, from: usize, chars: usize) -> usize {
    s[from..].char_indices().nth(chars).map_or(s.len(), |(k, _)| from + k)
}

pub fn mutate(text: &str, muts: &[Mutation]) -> String {
    let mut s = text.to_string();
    for m in muts {
        match m {
            Mutation::Delete(i, n) => {
                let a = boundary(&s, i);
                let b = forward(&s, a, *n);
                s.replace_range(a..b, "");
            }
            Mutation::Insert(i, piece) => {
                let a = boundary(&s, i);
                s.insert_str(a, piece);
            }
            Mutation::Duplicate(i, n) => {
                let a = boundary(&s, i);
                let b = forward(&s, a, *n);
                let copy = s[a..b].to_string();
                s.insert_str(b, &copy);
            }
            Mutation::Swap(i, j) => {
                let (a, b) = (boundary(&s, i), boundary(&s, j));
                let (a, b) = (a.min(b), a.max(b));
                if let (Some(x), Some(y)) = (s[a..].chars().next(), s[b..].chars().next())
                    && a != b
                {
                    let (xl, yl) = (x.len_utf8(), y.len_utf8());
                    if a + xl <= b {
                        s.replace_range(b..b + yl, &x.to_string());
                        s.replace_range(a..a + xl, &y.to_string());
                    }
                }
            }
        }
    }
    s
}
