//! CPT expressions (SPEC §3.2).
//!
//! Precedence, lowest first: `OR`, `XOR`, `AND`, comparisons
//! (`= <> < > <= >=`), `+ -`, `* / MOD`, unary `-` and `NOT`, then `**`/`^`
//! (right-associative, so `-2**2` is `-(2**2)` and `2**-1` works).
//! Keywords, functions and the constants `PI` and `E` are case-insensitive.

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
}

impl Func {
    fn parse(name: &str) -> Option<Func> {
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
            _ => return None,
        })
    }

    pub fn arity(self) -> usize {
        if self == Func::Atan2 { 2 } else { 1 }
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

/// Parses `text`, which starts at byte `base` of `file`.
pub fn parse(text: &str, file: FileId, base: usize) -> Result<Expr, ExprError> {
    let toks = lex(text, file, base)?;
    let mut p = P {
        toks,
        pos: 0,
        file,
        end: base + text.len(),
        depth: 0,
        operators: 0,
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

fn lex(text: &str, file: FileId, base: usize) -> Result<Vec<(Tok, Span)>, ExprError> {
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
        let tok = if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
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
                    || matches!(d, b'_' | b'.' | b'%' | b':')
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
                _ => match c {
                    b'+' => "+",
                    b'-' => "-",
                    b'*' => "*",
                    b'/' => "/",
                    b'^' => "^",
                    b'=' => "=",
                    b'<' => "<",
                    b'>' => ">",
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
                i += op.len();
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
        self.binary(&[("OR", BinE::Or)], P::xor)
    }
    fn xor(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("XOR", BinE::Xor)], P::and)
    }
    fn and(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("AND", BinE::And)], P::cmp)
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
        self.binary(&[("+", BinE::Add), ("-", BinE::Sub)], P::product)
    }
    fn product(&mut self) -> Result<Expr, ExprError> {
        self.binary(&[("*", BinE::Mul), ("/", BinE::Div), ("MOD", BinE::Mod)], P::unary)
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
            Tok::Num(s) => Literal::parse(&s).map(|l| Expr::Lit(l, sp)).map_err(|m| (m, sp)),
            Tok::LParen => {
                let e = self.or()?;
                self.expect(Tok::RParen, "`)`")?;
                Ok(e)
            }
            Tok::Ident(name) => {
                if self.peek() == Some(&Tok::LParen) {
                    let func = Func::parse(&name).ok_or_else(|| (format!("unknown function `{name}`"), sp))?;
                    self.pos += 1;
                    let mut args = vec![self.or()?];
                    while self.peek() == Some(&Tok::Comma) {
                        self.pos += 1;
                        args.push(self.or()?);
                    }
                    self.expect(Tok::RParen, "`)` after the function's arguments")?;
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
