//! CPT expressions (SPEC §3.2).
//!
//! Precedence, lowest first: `OR`, `XOR`, `AND`, comparisons
//! (`= <> < > <= >=`), `+ -`, `* / MOD`, unary `-` and `NOT`, then `**`/`^`
//! (right-associative, so `-2**2` is `-(2**2)` and `2**-1` works).
//! Keywords, functions and the constants `PI` and `E` are case-insensitive.
//!
//! Nets' guards and scripts ([`parse_net`]) read the same language with the
//! state-net source's additions (`003_…` §2.2.3.5, its Mathos parser): the
//! operators `%` (MOD), `:` (division), `&` (AND), `|` (OR), `==`, `!=`,
//! its functions (`cos`, `cosh`, `arcos`, … `sign`, see [`Func::parse`]) and
//! its precedence: one level per operator, tightest first `^`/`**` (left to
//! right), `%`/`MOD`, `:`, `/`, `*`, `-`, `+`, then comparisons, `&`/`AND`,
//! `XOR`, `|`/`OR`; unary `-` binds tighter than `^` (`-2^2` is 4).

use alba_diag::{FileId, Span};
use alba_model::Literal;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    Sqrt,
    Abs,
    Sin,
    Cos,
    Tan,
    Asn,
    Acs,
    Atn,
    Atan2,
    Ln,
    Log,
    Deg,
    Rad,
    Trn,
    Frd,
    Tod,
    Round,
    // The state-net source's (`003_…`) and AuroraLD's functions, lowered
    // onto the IR's existing operations (`crate::funcs`).
    Cosh,
    Sinh,
    Tanh,
    Exp,
    Floor,
    Ceil,
    Sign,
    /// `rem(a, b)`: the IEEE remainder, `a - b·n` with `n` the nearest
    /// integer to `a/b`.
    Rem,
    /// `root(a, b)`: `a ** (1/b)`.
    Root,
    /// `pow(a, b)`: `a ** b`.
    Pow,
    /// `log(a, b)`: the logarithm of `a` in base `b`.
    LogB,
    /// The square root of the source (`sqrt` in a net): of a negative it is
    /// not a number (0 and a minor fault), where CPT's takes the absolute value.
    SqrtStrict,
    /// Rounding half away from zero (`round` in a net), where CPT's rounds
    /// half to even.
    RoundAway,
    /// AuroraLD's `rnd(a, b)`: a pseudo-random number from a to b.
    Rnd,
    /// AuroraLD's `sqrt` (`[ladder] dialect = "aurorald"`): 0 for a negative.
    SqrtZero,
}

/// Which expression language a text is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Syntax {
    /// CPT's (SPEC §3.2).
    Cpt,
    /// Nets' guards and scripts: CPT's plus the state-net source's.
    Net,
}

impl Func {
    /// The function called `name` in `syntax`.
    pub fn parse(name: &str, syntax: Syntax) -> Option<Func> {
        if syntax == Syntax::Net {
            let f = match name.to_ascii_lowercase().as_str() {
                "cos" => Some(Func::Cos),
                "cosh" => Some(Func::Cosh),
                // `arcos` as the source spells it.
                "arcos" | "arccos" | "acos" => Some(Func::Acs),
                "sin" => Some(Func::Sin),
                "sinh" => Some(Func::Sinh),
                "arcsin" | "asin" => Some(Func::Asn),
                "tan" => Some(Func::Tan),
                "tanh" => Some(Func::Tanh),
                "arctan" | "atan" => Some(Func::Atn),
                "sqrt" => Some(Func::SqrtStrict),
                "rem" => Some(Func::Rem),
                "root" => Some(Func::Root),
                "pow" => Some(Func::Pow),
                "exp" => Some(Func::Exp),
                "abs" => Some(Func::Abs),
                "log" => Some(Func::Log),
                "round" => Some(Func::RoundAway),
                "truncate" => Some(Func::Trn),
                "floor" => Some(Func::Floor),
                "ceiling" | "ceil" => Some(Func::Ceil),
                "sign" => Some(Func::Sign),
                _ => None,
            };
            if f.is_some() {
                return f;
            }
        }
        Some(match name.to_ascii_uppercase().as_str() {
            "SQR" | "SQRT" => Func::Sqrt,
            "ABS" => Func::Abs,
            "SIN" => Func::Sin,
            "COS" => Func::Cos,
            "TAN" => Func::Tan,
            "ASN" | "ASIN" => Func::Asn,
            "ACS" | "ACOS" => Func::Acs,
            "ATN" | "ATAN" => Func::Atn,
            "ATAN2" => Func::Atan2,
            "LN" => Func::Ln,
            "LOG" => Func::Log,
            "DEG" => Func::Deg,
            "RAD" => Func::Rad,
            "TRN" => Func::Trn,
            "FRD" => Func::Frd,
            "TOD" => Func::Tod,
            "ROUND" => Func::Round,
            // AuroraLD's (QScript's) names, `000_…` Table 8.
            "LOG10" => Func::Log,
            "LOGE" => Func::Ln,
            "INT" => Func::Trn,
            "SIGNUM" => Func::Sign,
            "COSH" => Func::Cosh,
            "SINH" => Func::Sinh,
            "TANH" => Func::Tanh,
            "RND" => Func::Rnd,
            "RADIANS" => Func::Rad,
            "DEGREES" => Func::Deg,
            _ => return None,
        })
    }

    pub fn arity(self) -> usize {
        match self {
            Func::Atan2 | Func::Rem | Func::Root | Func::Pow | Func::LogB | Func::Rnd => 2,
            _ => 1,
        }
    }

    /// Whether the function computes in floating point (the others keep
    /// their argument's class: an integer stays an integer).
    pub fn is_float(self) -> bool {
        !matches!(
            self,
            Func::Abs
                | Func::Trn
                | Func::Round
                | Func::Frd
                | Func::Tod
                | Func::Floor
                | Func::Ceil
                | Func::Sign
                | Func::RoundAway
        )
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinE {
    Or,
    Xor,
    And,
    Eq,
    Ne,
    Lt,
    Gt,
    Le,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
    Mod,
    Pow,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    Lit(Literal, Span),
    /// A tag, member, address or system tag.
    Name(String, Span),
    /// PI or E.
    Const(f64),
    Neg(Box<Expr>),
    Not(Box<Expr>, Span),
    Bin(BinE, Box<Expr>, Box<Expr>, Span),
    Call(Func, Vec<Expr>, Span),
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(String),
    Ident(String),
    Op(&'static str),
    LParen,
    RParen,
    Comma,
}

/// A parse error: message and span.
pub type ExprError = (String, Span);

/// Parses the CPT expression `text`, which starts at byte `base` of `file`.
pub fn parse(text: &str, file: FileId, base: usize) -> Result<Expr, ExprError> {
    parse_in(text, file, base, Syntax::Cpt)
}

/// Parses a net's guard or script expression (the module's doc: the
/// state-net source's operators, functions and precedence).
pub fn parse_net(text: &str, file: FileId, base: usize) -> Result<Expr, ExprError> {
    parse_in(text, file, base, Syntax::Net)
}

pub fn parse_in(text: &str, file: FileId, base: usize, syntax: Syntax) -> Result<Expr, ExprError> {
    let toks = lex(text, file, base, syntax)?;
    let mut p = P {
        toks,
        pos: 0,
        file,
        end: base + text.len(),
        depth: 0,
        operators: 0,
        syntax,
    };
    let e = p.or()?;
    if let Some((t, sp)) = p.toks.get(p.pos) {
        return Err((format!("unexpected {} after the expression", describe(t)), *sp));
    }
    Ok(e)
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Num(s) | Tok::Ident(s) => format!("`{s}`"),
        Tok::Op(s) => format!("`{s}`"),
        Tok::LParen => "`(`".into(),
        Tok::RParen => "`)`".into(),
        Tok::Comma => "`,`".into(),
    }
}

fn lex(text: &str, file: FileId, base: usize, syntax: Syntax) -> Result<Vec<(Tok, Span)>, ExprError> {
    let net = syntax == Syntax::Net;
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let sp = |s: usize, e: usize| Span::new(file, base + s..base + e);
    while i < b.len() {
        let c = b[i];
        let start = i;
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        // In a net, `%` and `:` after a value are operators.
        let after_value = match out.last() {
            Some((Tok::Num(_) | Tok::RParen, _)) => true,
            Some((Tok::Ident(w), _)) => !["AND", "OR", "XOR", "NOT", "MOD"]
                .iter()
                .any(|k| w.eq_ignore_ascii_case(k)),
            _ => false,
        };
        let tok = if net && after_value && (c == b'%' || c == b':') {
            i += 1;
            Tok::Op(if c == b'%' { "%" } else { ":" })
        } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            // Digits, '.', '_', based '#', exponent with sign.
            while i < b.len() {
                let d = b[i];
                let exp_sign =
                    (d == b'+' || d == b'-') && matches!(b[i - 1], b'e' | b'E') && !text[start..i].contains('#');
                if d.is_ascii_alphanumeric() || d == b'.' || d == b'_' || d == b'#' || exp_sign {
                    i += 1;
                } else {
                    break;
                }
            }
            Tok::Num(text[start..i].to_string())
        } else if c.is_ascii_alphabetic() || c == b'_' || c == b'%' {
            // Names, members, addresses (DI:1/0, %IX0.1, S:FS) and T#5s.
            // Where a `:` was seen; a `/` then belongs to the name only in an
            // AuroraLD address (`DI:1/0`: digits between `:` and `/`, once).
            let mut colon: Option<usize> = None;
            let mut slash = false;
            while i < b.len() {
                let d = b[i];
                let time_prefix = || matches!(text[start..i].to_ascii_uppercase().as_str(), "T" | "TIME");
                let aurora_slash = || {
                    colon.is_some_and(|c| i > c + 1 && b[c + 1..i].iter().all(u8::is_ascii_digit))
                        && b.get(i + 1).is_some_and(u8::is_ascii_digit)
                };
                let part = d.is_ascii_alphanumeric()
                    || matches!(d, b'_' | b'.' | b':')
                    || (d == b'%' && (!net || i == start))
                    || (d == b'/' && !slash && aurora_slash())
                    || (d == b'#' && time_prefix());
                if !part {
                    break;
                }
                if d == b':' {
                    colon = Some(i);
                }
                slash |= d == b'/';
                i += 1;
            }
            let word = &text[start..i];
            if word.contains('#') {
                Tok::Num(word.to_string())
            } else {
                Tok::Ident(word.to_string())
            }
        } else {
            let two = text.get(i..i + 2).unwrap_or("");
            let op: &'static str = match two {
                "**" => "**",
                "<>" => "<>",
                "<=" => "<=",
                ">=" => ">=",
                "==" if net => "=",
                "!=" if net => "<>",
                _ => match c {
                    b'+' => "+",
                    b'-' => "-",
                    b'*' => "*",
                    b'/' => "/",
                    b'^' => "^",
                    b'=' => "=",
                    b'<' => "<",
                    b'>' => ">",
                    b'&' if net => "&",
                    b'|' if net => "|",
                    b'(' | b')' | b',' => "",
                    _ => {
                        let end = i + text[i..].chars().next().map_or(1, char::len_utf8);
                        return Err((format!("unexpected `{}` in the expression", &text[i..end]), sp(i, end)));
                    }
                },
            };
            if op.is_empty() {
                i += 1;
                match c {
                    b'(' => Tok::LParen,
                    b')' => Tok::RParen,
                    _ => Tok::Comma,
                }
            } else {
                i += if two == "==" || two == "!=" { 2 } else { op.len() };
                Tok::Op(op)
            }
        };
        out.push((tok, sp(start, i)));
    }
    Ok(out)
}

struct P {
    toks: Vec<(Tok, Span)>,
    pos: usize,
    file: FileId,
    end: usize,
    /// Nesting of parentheses, calls and unary operators.
    depth: usize,
    /// Operators so far (a chain `a+b+c…` is a tree as deep as it is long).
    operators: usize,
    syntax: Syntax,
}

/// Most operators accepted in one expression.
pub const MAX_OPERATORS: usize = 256;

/// Deepest nesting accepted in an expression (a bound on recursion).
pub const MAX_DEPTH: usize = 64;

impl P {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos).map(|(t, _)| t)
    }

    fn span_here(&self) -> Span {
        self.toks
            .get(self.pos)
            .map_or(Span::new(self.file, self.end..self.end), |(_, s)| *s)
    }

    fn keyword(&self, kw: &str) -> bool {
        matches!(self.peek(), Some(Tok::Ident(s)) if s.eq_ignore_ascii_case(kw))
    }

    fn binary(&mut self, ops: &[(&str, BinE)], next: fn(&mut P) -> Result<Expr, ExprError>) -> Result<Expr, ExprError> {
        let mut lhs = next(self)?;
        loop {
            let found = ops.iter().find(|(s, _)| match self.peek() {
                Some(Tok::Op(o)) => o == s,
                Some(Tok::Ident(w)) => w.eq_ignore_ascii_case(s),
                _ => false,
            });
            let Some(&(_, op)) = found else {
                return Ok(lhs);
            };
            let sp = self.span_here();
            self.operators += 1;
            if self.operators > MAX_OPERATORS {
                return Err((
                    format!("the expression has more than {MAX_OPERATORS} operators; split it over several CPTs"),
                    sp,
                ));
            }
            self.pos += 1;
            let rhs = next(self)?;
            lhs = Expr::Bin(op, Box::new(lhs), Box::new(rhs), sp);
        }
    }

    fn or(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("OR", BinE::Or), ("|", BinE::Or)], P::xor)
    }
    fn xor(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("XOR", BinE::Xor)], P::and)
    }
    fn and(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("AND", BinE::And), ("&", BinE::And)], P::cmp)
    }
    fn cmp(&mut self) -> Result<Expr, ExprError> {
        self.binary(
            &[
                ("=", BinE::Eq),
                ("<>", BinE::Ne),
                ("<", BinE::Lt),
                (">", BinE::Gt),
                ("<=", BinE::Le),
                (">=", BinE::Ge),
            ],
            P::sum,
        )
    }
    fn sum(&mut self) -> Result<Expr, ExprError> {
        if self.syntax == Syntax::Net {
            return self.binary(&[("+", BinE::Add)], P::net_sub);
        }
        self.binary(&[("+", BinE::Add), ("-", BinE::Sub)], P::product)
    }
    fn product(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("*", BinE::Mul), ("/", BinE::Div), ("MOD", BinE::Mod)], P::unary)
    }
    // A net's levels, one per operator as the source's parser has them.
    fn net_sub(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("-", BinE::Sub)], P::net_mul)
    }
    fn net_mul(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("*", BinE::Mul)], P::net_div)
    }
    fn net_div(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("/", BinE::Div)], P::net_colon)
    }
    fn net_colon(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[(":", BinE::Div)], P::net_mod)
    }
    fn net_mod(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("%", BinE::Mod), ("MOD", BinE::Mod)], P::net_pow)
    }
    fn net_pow(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("^", BinE::Pow), ("**", BinE::Pow)], P::unary)
    }

    fn unary(&mut self) -> Result<Expr, ExprError> {
        if self.depth >= MAX_DEPTH {
            return Err((
                format!("the expression is nested more than {MAX_DEPTH} deep"),
                self.span_here(),
            ));
        }
        self.depth += 1;
        let e = self.unary_inner();
        self.depth -= 1;
        e
    }

    fn unary_inner(&mut self) -> Result<Expr, ExprError> {
        if matches!(self.peek(), Some(Tok::Op("-"))) {
            self.pos += 1;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        if matches!(self.peek(), Some(Tok::Op("+"))) {
            self.pos += 1;
            return self.unary();
        }
        if self.keyword("NOT") {
            let sp = self.span_here();
            self.pos += 1;
            return Ok(Expr::Not(Box::new(self.unary()?), sp));
        }
        if self.syntax == Syntax::Net {
            return self.primary();
        }
        self.power()
    }

    fn power(&mut self) -> Result<Expr, ExprError> {
        let base = self.primary()?;
        if matches!(self.peek(), Some(Tok::Op("**" | "^"))) {
            let sp = self.span_here();
            self.pos += 1;
            let exp = self.unary()?;
            return Ok(Expr::Bin(BinE::Pow, Box::new(base), Box::new(exp), sp));
        }
        Ok(base)
    }

    fn expect(&mut self, want: Tok, what: &str) -> Result<(), ExprError> {
        if self.peek() == Some(&want) {
            self.pos += 1;
            Ok(())
        } else {
            let found = self.peek().map_or("the end".to_string(), describe);
            Err((format!("expected {what}, found {found}"), self.span_here()))
        }
    }

    fn primary(&mut self) -> Result<Expr, ExprError> {
        let sp = self.span_here();
        let Some(tok) = self.peek().cloned() else {
            return Err(("the expression ends too early: expected a value".into(), sp));
        };
        self.pos += 1;
        match tok {
            Tok::Num(s) => Literal::parse(&s).map(|l| Expr::Lit(l, sp)).map_err(|m| (m.into(), sp)),
            Tok::LParen => {
                let e = self.or()?;
                self.expect(Tok::RParen, "`)`")?;
                Ok(e)
            }
            Tok::Ident(name) => {
                if self.peek() == Some(&Tok::LParen) {
                    let mut func =
                        Func::parse(&name, self.syntax).ok_or_else(|| (format!("unknown function `{name}`"), sp))?;
                    self.pos += 1;
                    let mut args = vec![self.or()?];
                    while self.peek() == Some(&Tok::Comma) {
                        self.pos += 1;
                        args.push(self.or()?);
                    }
                    self.expect(Tok::RParen, "`)` after the function's arguments")?;
                    // `log(a, b)` (the state-net source's and AuroraLD's): the
                    // logarithm in base b.
                    if func == Func::Log && args.len() == 2 {
                        func = Func::LogB;
                    }
                    if args.len() != func.arity() {
                        return Err((
                            format!(
                                "`{}` takes {} argument(s), found {}",
                                name.to_ascii_uppercase(),
                                func.arity(),
                                args.len()
                            ),
                            sp,
                        ));
                    }
                    return Ok(Expr::Call(func, args, sp));
                }
                match name.to_ascii_uppercase().as_str() {
                    "PI" => Ok(Expr::Const(std::f64::consts::PI)),
                    "E" => Ok(Expr::Const(std::f64::consts::E)),
                    "MOD" | "AND" | "OR" | "XOR" | "NOT" => Err((format!("expected a value, found `{name}`"), sp)),
                    _ => Ok(Expr::Name(name, sp)),
                }
            }
            t => Err((format!("expected a value, found {}", describe(&t)), sp)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Result<Expr, String> {
        parse(s, FileId(0), 0).map_err(|(m, sp)| format!("{}..{}: {m}", sp.start, sp.end))
    }

    fn show(e: &Expr) -> String {
        match e {
            Expr::Lit(l, _) => format!("{l:?}"),
            Expr::Name(n, _) => n.clone(),
            Expr::Const(c) => format!("{c:.3}"),
            Expr::Neg(a) => format!("(-{})", show(a)),
            Expr::Not(a, _) => format!("(NOT {})", show(a)),
            Expr::Bin(op, a, b, _) => format!("({} {op:?} {})", show(a), show(b)),
            Expr::Call(f, args, _) => format!("{f:?}({})", args.iter().map(show).collect::<Vec<_>>().join(",")),
        }
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(show(&p("a + b * 2").unwrap()), "(a Add (b Mul Int(2)))");
        assert_eq!(show(&p("-2**2").unwrap()), "(-(Int(2) Pow Int(2)))");
        assert_eq!(show(&p("2**3**2").unwrap()), "(Int(2) Pow (Int(3) Pow Int(2)))");
        assert_eq!(show(&p("a - b - c").unwrap()), "((a Sub b) Sub c)");
        assert_eq!(
            show(&p("x mod 3 = 0 and y or z").unwrap()),
            "((((x Mod Int(3)) Eq Int(0)) And y) Or z)"
        );
        assert_eq!(show(&p("ATAN2(y, x) * 2").unwrap()), "(Atan2(y,x) Mul Int(2))");
        assert_eq!(show(&p("pi*T.ACC/DI:1/0").unwrap()), "((3.142 Mul T.ACC) Div DI:1/0)");
        assert_eq!(show(&p("S:FAULTCODE/2").unwrap()), "(S:FAULTCODE Div Int(2))");
        assert_eq!(show(&p("AI:3/0/4").unwrap()), "(AI:3/0 Div Int(4))");
        assert_eq!(
            show(&p("1.5e-3 + T#2s + 16#FF").unwrap()),
            "((Real(0.0015) Add Time(2000)) Add Int(255))"
        );
        assert_eq!(show(&p("not a <> b").unwrap()), "((NOT a) Ne b)");
    }

    fn n(s: &str) -> Result<String, String> {
        parse_net(s, FileId(0), 0)
            .map(|e| show(&e))
            .map_err(|(m, sp)| format!("{}..{}: {m}", sp.start, sp.end))
    }

    #[test]
    fn a_nets_operators_and_the_sources_precedence() {
        // `%` binds tighter than `*`, `:` tighter than `/`, `-` than `+`.
        assert_eq!(n("a * b % c").unwrap(), "(a Mul (b Mod c))");
        assert_eq!(n("a % b MOD c").unwrap(), "((a Mod b) Mod c)");
        assert_eq!(n("8 / 2 : 2").unwrap(), "(Int(8) Div (Int(2) Div Int(2)))");
        assert_eq!(n("8:2").unwrap(), "(Int(8) Div Int(2))");
        assert_eq!(n("a + b - c").unwrap(), "(a Add (b Sub c))");
        assert_eq!(n("a - b + c").unwrap(), "((a Sub b) Add c)");
        assert_eq!(n("a * b / c").unwrap(), "(a Mul (b Div c))");
        // `^` is tightest and left to right; a unary minus binds tighter still.
        assert_eq!(n("2^3^2").unwrap(), "((Int(2) Pow Int(3)) Pow Int(2))");
        assert_eq!(n("-2^2").unwrap(), "((-Int(2)) Pow Int(2))");
        assert_eq!(n("a ^ b % c").unwrap(), "((a Pow b) Mod c)");
        // Logic: `&` and `|`, `==` and `!=`.
        assert_eq!(
            n("(v2 > 2) | (v3 < 3) & x == 1").unwrap(),
            "((v2 Gt Int(2)) Or ((v3 Lt Int(3)) And (x Eq Int(1))))"
        );
        assert_eq!(n("a != b").unwrap(), "(a Ne b)");
        // `%` at the start of a word is an address, after a value an operator.
        assert_eq!(n("%IX0.1 AND %MX1.0").unwrap(), "(%IX0.1 And %MX1.0)");
        assert_eq!(n("a%b").unwrap(), "(a Mod b)");
        assert_eq!(n("N7:2 + DI:1/0").unwrap(), "(N7:2 Add DI:1/0)");
        assert_eq!(n("(a):b").unwrap(), "(a Div b)");
        // CPT keeps its own: `&` refused, `%` a name, `-2**2` is -(2**2).
        assert_eq!(p("a & b").unwrap_err(), "2..3: unexpected `&` in the expression");
        assert_eq!(show(&p("-2^2").unwrap()), "(-(Int(2) Pow Int(2)))");
        assert_eq!(show(&p("a * b MOD c").unwrap()), "((a Mul b) Mod c)");
    }

    #[test]
    fn a_nets_functions_as_the_source_spells_them() {
        for (text, want) in [
            ("cos(v10)", "Cos(v10)"),
            ("arcos(x)", "Acs(x)"),
            ("ARCCOS(x)", "Acs(x)"),
            ("cosh(x) + sinh(x) + tanh(x)", "((Cosh(x) Add Sinh(x)) Add Tanh(x))"),
            ("sqrt(x)", "SqrtStrict(x)"),
            ("rem(a, b)", "Rem(a,b)"),
            ("root(a, 3)", "Root(a,Int(3))"),
            ("pow(a, 2)", "Pow(a,Int(2))"),
            ("exp(1) * abs(x)", "(Exp(Int(1)) Mul Abs(x))"),
            ("log(x)", "Log(x)"),
            ("log(x, 2)", "LogB(x,Int(2))"),
            ("round(x)", "RoundAway(x)"),
            (
                "truncate(x) + floor(x) + ceiling(x) + sign(x)",
                "(((Trn(x) Add Floor(x)) Add Ceil(x)) Add Sign(x))",
            ),
            // CPT's names stay available, with CPT's meaning.
            ("SQR(x) + ATAN2(y, x)", "(Sqrt(x) Add Atan2(y,x))"),
        ] {
            assert_eq!(n(text).unwrap(), want, "{text}");
        }
        assert_eq!(n("rem(a)").unwrap_err(), "0..3: `REM` takes 2 argument(s), found 1");
        assert_eq!(
            n("log(a, b, c)").unwrap_err(),
            "0..3: `LOG` takes 1 argument(s), found 3"
        );
        assert_eq!(n("cosine(a)").unwrap_err(), "0..6: unknown function `cosine`");
        // CPT's `sqrt` is Logix's (of the absolute value).
        assert_eq!(p("sqrt(a)").map(|e| show(&e)).unwrap(), "Sqrt(a)");
    }

    #[test]
    fn cpt_takes_auroralds_names() {
        for (text, want) in [
            ("log10(a)", "Log(a)"),
            ("logE(a)", "Ln(a)"),
            ("log(a, 2)", "LogB(a,Int(2))"),
            ("Int(a)", "Trn(a)"),
            ("signum(a)", "Sign(a)"),
            ("cosh(a) + sinh(a) + tanh(a)", "((Cosh(a) Add Sinh(a)) Add Tanh(a))"),
            ("rnd(0, 10)", "Rnd(Int(0),Int(10))"),
            ("radians(a)", "Rad(a)"),
            ("degrees(a)", "Deg(a)"),
        ] {
            assert_eq!(show(&p(text).unwrap()), want, "{text}");
        }
        assert_eq!(p("rnd(1)").unwrap_err(), "0..3: `RND` takes 2 argument(s), found 1");
        assert_eq!(
            p("log(1, 2, 3)").unwrap_err(),
            "0..3: `LOG` takes 1 argument(s), found 3"
        );
    }

    #[test]
    fn long_expressions_are_refused_before_they_get_deep() {
        let ok = vec!["a"; MAX_OPERATORS + 1].join("+");
        assert!(p(&ok).is_ok());
        let long = vec!["a"; 20_000].join("+");
        assert!(p(&long).unwrap_err().contains("more than 256 operators"));
    }

    #[test]
    fn errors_point_at_the_problem() {
        assert_eq!(
            p("a +").unwrap_err(),
            "3..3: the expression ends too early: expected a value"
        );
        assert_eq!(p("(a + b").unwrap_err(), "6..6: expected `)`, found the end");
        assert_eq!(p("a $ b").unwrap_err(), "2..3: unexpected `$` in the expression");
        assert_eq!(p("FOO(1)").unwrap_err(), "0..3: unknown function `FOO`");
        assert_eq!(p("ATAN2(1)").unwrap_err(), "0..5: `ATAN2` takes 2 argument(s), found 1");
        assert_eq!(p("a b").unwrap_err(), "2..3: unexpected `b` after the expression");
        assert_eq!(p("1..2").unwrap_err(), "0..4: `1..2` is not a number");
        assert_eq!(p("a * and").unwrap_err(), "4..7: expected a value, found `and`");
    }
}
