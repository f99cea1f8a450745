//! A recursive-descent parser for Structured Text. A statement that does
//! not parse is reported and skipped up to its `;`, so one run finds every
//! error of a file.

use crate::ast::*;
use crate::lex::{Tok, Token, lex};
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_model::Literal;

/// Parses `text`: the tree of what parsed, and every error.
pub fn parse(text: &str, file: FileId) -> (File, Vec<Diagnostic>) {
    let (toks, mut diags) = lex(text, file);
    let mut p = Parser {
        toks,
        pos: 0,
        file,
        diags: Vec::new(),
    };
    let f = p.file();
    diags.extend(p.diags);
    diags.sort_by_key(|d| d.primary.as_ref().map(|l| l.span.start));
    (f, diags)
}

/// Words that end a statement list.
const ENDERS: [&str; 15] = [
    "END_IF",
    "ELSIF",
    "ELSE",
    "END_CASE",
    "END_FOR",
    "END_WHILE",
    "UNTIL",
    "END_REPEAT",
    "END_PROGRAM",
    "END_FUNCTION",
    "END_FUNCTION_BLOCK",
    "PROGRAM",
    "FUNCTION",
    "FUNCTION_BLOCK",
    "TYPE",
];

/// Reserved words that may not name a variable.
pub const KEYWORDS: [&str; 44] = [
    "PROGRAM",
    "END_PROGRAM",
    "FUNCTION",
    "END_FUNCTION",
    "FUNCTION_BLOCK",
    "END_FUNCTION_BLOCK",
    "VAR",
    "VAR_INPUT",
    "VAR_OUTPUT",
    "VAR_IN_OUT",
    "VAR_TEMP",
    "VAR_GLOBAL",
    "VAR_EXTERNAL",
    "END_VAR",
    "RETAIN",
    "CONSTANT",
    "TYPE",
    "END_TYPE",
    "STRUCT",
    "END_STRUCT",
    "ARRAY",
    "OF",
    "IF",
    "THEN",
    "ELSIF",
    "ELSE",
    "END_IF",
    "CASE",
    "END_CASE",
    "FOR",
    "TO",
    "BY",
    "DO",
    "END_FOR",
    "WHILE",
    "END_WHILE",
    "REPEAT",
    "UNTIL",
    "END_REPEAT",
    "EXIT",
    "RETURN",
    "AND",
    "OR",
    "NOT",
];

type R<T> = Result<T, Diagnostic>;

struct Parser {
    toks: Vec<Token>,
    pos: usize,
    file: FileId,
    diags: Vec<Diagnostic>,
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Ident(s) => format!("`{s}`"),
        Tok::Number(s) => format!("the number `{s}`"),
        Tok::Typed(a, b) => format!("`{a}#{b}`"),
        Tok::Str(..) => "a string".into(),
        Tok::Punct(p) => format!("`{p}`"),
        Tok::Eof => "the end of the file".into(),
    }
}

impl Parser {
    fn peek(&self) -> &Tok {
        &self.toks[self.pos.min(self.toks.len() - 1)].tok
    }
    fn peek_at(&self, k: usize) -> &Tok {
        &self.toks[(self.pos + k).min(self.toks.len() - 1)].tok
    }
    fn tok(&self) -> &Token {
        &self.toks[self.pos.min(self.toks.len() - 1)]
    }
    fn span_here(&self) -> Span {
        let t = self.tok();
        Span::new(self.file, t.start..t.end)
    }
    fn from(&self, start: usize) -> Span {
        let end = if self.pos == 0 {
            start
        } else {
            self.toks[self.pos - 1].end.max(start)
        };
        Span::new(self.file, start..end)
    }
    fn start(&self) -> usize {
        self.tok().start
    }
    fn bump(&mut self) -> Token {
        let t = self.tok().clone();
        if self.pos < self.toks.len() - 1 {
            self.pos += 1;
        }
        t
    }
    fn is_kw(&self, kw: &str) -> bool {
        matches!(self.peek(), Tok::Ident(s) if s.eq_ignore_ascii_case(kw))
    }
    fn is_p(&self, p: &str) -> bool {
        matches!(self.peek(), Tok::Punct(q) if *q == p)
    }
    fn eat_kw(&mut self, kw: &str) -> bool {
        if self.is_kw(kw) {
            self.bump();
            true
        } else {
            false
        }
    }
    fn eat_p(&mut self, p: &str) -> bool {
        if self.is_p(p) {
            self.bump();
            true
        } else {
            false
        }
    }
    fn error(&self, what: &str) -> Diagnostic {
        Diagnostic::new(
            Code::StSyntax,
            format!("expected {what}, found {}", describe(self.peek())),
            self.span_here(),
            format!("expected {what}"),
        )
    }
    fn expect_kw(&mut self, kw: &str) -> R<()> {
        if self.eat_kw(kw) {
            Ok(())
        } else {
            Err(self.error(&format!("`{kw}`")))
        }
    }
    fn expect_p(&mut self, p: &str) -> R<()> {
        if self.eat_p(p) {
            Ok(())
        } else {
            Err(self.error(&format!("`{p}`")))
        }
    }
    fn ident(&mut self) -> R<Ident> {
        match self.peek().clone() {
            Tok::Ident(s) if !KEYWORDS.iter().any(|k| k.eq_ignore_ascii_case(&s)) => {
                let span = self.span_here();
                self.bump();
                Ok(Ident { name: s, span })
            }
            _ => Err(self.error("a name")),
        }
    }
    /// Skips to just after the next `;` at this level, or to a word that
    /// ends a block.
    fn sync(&mut self) {
        loop {
            match self.peek() {
                Tok::Eof => return,
                Tok::Punct(";") => {
                    self.bump();
                    return;
                }
                Tok::Ident(s)
                    if ENDERS.iter().any(|k| k.eq_ignore_ascii_case(s)) || s.eq_ignore_ascii_case("END_VAR") =>
                {
                    return;
                }
                _ => {
                    self.bump();
                }
            }
        }
    }

    fn file(&mut self) -> File {
        let mut f = File::default();
        loop {
            let before = self.pos;
            let r = match self.peek() {
                Tok::Eof => break,
                Tok::Ident(s) => match s.to_ascii_uppercase().as_str() {
                    "PROGRAM" => self.pou(PouKind::Program).map(|p| f.pous.push(p)),
                    "FUNCTION" => self.pou(PouKind::Function).map(|p| f.pous.push(p)),
                    "FUNCTION_BLOCK" => self.pou(PouKind::FunctionBlock).map(|p| f.pous.push(p)),
                    "TYPE" => self.types().map(|t| f.types.extend(t)),
                    "VAR_GLOBAL" => self.var_block().map(|b| f.globals.push(b)),
                    _ => Err(self.error("`PROGRAM`, `FUNCTION`, `FUNCTION_BLOCK`, `TYPE` or `VAR_GLOBAL`")),
                },
                _ => Err(self.error("`PROGRAM`, `FUNCTION`, `FUNCTION_BLOCK`, `TYPE` or `VAR_GLOBAL`")),
            };
            if let Err(d) = r {
                self.diags.push(d);
                // Skip to the next POU.
                if self.pos == before {
                    self.bump();
                }
                while !matches!(self.peek(), Tok::Eof)
                    && !["PROGRAM", "FUNCTION", "FUNCTION_BLOCK", "TYPE"]
                        .iter()
                        .any(|k| self.is_kw(k))
                {
                    self.bump();
                }
            }
        }
        f
    }

    fn pou(&mut self, kind: PouKind) -> R<Pou> {
        let start = self.start();
        self.bump();
        let name = self.ident()?;
        let ret = if kind == PouKind::Function && self.eat_p(":") {
            Some(self.type_ref()?)
        } else {
            None
        };
        let mut vars = Vec::new();
        while [
            "VAR",
            "VAR_INPUT",
            "VAR_OUTPUT",
            "VAR_IN_OUT",
            "VAR_TEMP",
            "VAR_GLOBAL",
            "VAR_EXTERNAL",
        ]
        .iter()
        .any(|k| self.is_kw(k))
        {
            match self.var_block() {
                Ok(b) => vars.push(b),
                Err(d) => {
                    self.diags.push(d);
                    while !matches!(self.peek(), Tok::Eof) && !self.is_kw("END_VAR") {
                        self.bump();
                    }
                    self.eat_kw("END_VAR");
                }
            }
        }
        let end = format!("END_{}", kind.keyword());
        let body = self.stmt_list();
        if !self.eat_kw(&end) {
            return Err(self.error(&format!("`{end}`")));
        }
        Ok(Pou {
            kind,
            name,
            ret,
            vars,
            body,
            span: self.from(start),
        })
    }

    fn var_block(&mut self) -> R<VarBlock> {
        let start = self.start();
        let kind = match self.bump().tok {
            Tok::Ident(s) => match s.to_ascii_uppercase().as_str() {
                "VAR_INPUT" => VarKind::Input,
                "VAR_OUTPUT" => VarKind::Output,
                "VAR_IN_OUT" => VarKind::InOut,
                "VAR_TEMP" => VarKind::Temp,
                "VAR_GLOBAL" => VarKind::Global,
                "VAR_EXTERNAL" => VarKind::External,
                _ => VarKind::Var,
            },
            _ => VarKind::Var,
        };
        let (mut retain, mut constant) = (false, false);
        loop {
            if self.eat_kw("RETAIN") {
                retain = true;
            } else if self.eat_kw("NON_RETAIN") {
            } else if self.eat_kw("CONSTANT") {
                constant = true;
            } else {
                break;
            }
        }
        let mut vars = Vec::new();
        while !self.is_kw("END_VAR") {
            if matches!(self.peek(), Tok::Eof) {
                return Err(self.error("`END_VAR`"));
            }
            let before = self.pos;
            match self.var_decl() {
                Ok(v) => vars.push(v),
                Err(d) => {
                    self.diags.push(d);
                    if self.pos == before {
                        self.bump();
                    }
                    self.sync();
                }
            }
        }
        self.bump();
        Ok(VarBlock {
            kind,
            retain,
            constant,
            vars,
            span: self.from(start),
        })
    }

    fn var_decl(&mut self) -> R<VarDecl> {
        let start = self.start();
        let mut names = vec![self.ident()?];
        while self.eat_p(",") {
            names.push(self.ident()?);
        }
        let at = if self.eat_kw("AT") {
            let s = self.start();
            // %IX0.0 lexes as `%`-less pieces; take the text up to `:`.
            let mut text = String::new();
            while !self.is_p(":") && !matches!(self.peek(), Tok::Eof | Tok::Punct(";")) {
                let t = self.bump();
                text.push_str(&match t.tok {
                    Tok::Ident(s) | Tok::Number(s) => s,
                    Tok::Punct(p) => p.to_string(),
                    other => describe(&other),
                });
            }
            Some((text, self.from(s)))
        } else {
            None
        };
        self.expect_p(":")?;
        let ty = self.type_ref()?;
        let init = if self.eat_p(":=") { Some(self.init()?) } else { None };
        self.expect_p(";")?;
        Ok(VarDecl {
            names,
            at,
            ty,
            init,
            span: self.from(start),
        })
    }

    fn init(&mut self) -> R<Init> {
        let start = self.start();
        if self.eat_p("[") {
            let mut items = Vec::new();
            loop {
                // `(a := 1, b := 2)`: an element that is a structure.
                if self.is_p("(")
                    && matches!(self.peek_at(1), Tok::Ident(_))
                    && matches!(self.peek_at(2), Tok::Punct(":="))
                {
                    items.push((None, self.init()?));
                    if !self.eat_p(",") {
                        break;
                    }
                    continue;
                }
                // `n(value)`: a repeated element.
                let e = if matches!(self.peek(), Tok::Number(_)) && matches!(self.peek_at(1), Tok::Punct("(")) {
                    self.primary()?
                } else {
                    self.expr()?
                };
                if self.eat_p("(") {
                    let inner = if self.is_p(")") {
                        Init::Array(Vec::new(), self.span_here())
                    } else {
                        self.init()?
                    };
                    self.expect_p(")")?;
                    items.push((Some(e), inner));
                } else {
                    items.push((None, Init::Expr(e)));
                }
                if !self.eat_p(",") {
                    break;
                }
            }
            self.expect_p("]")?;
            return Ok(Init::Array(items, self.from(start)));
        }
        if self.is_p("(") && matches!(self.peek_at(1), Tok::Ident(_)) && matches!(self.peek_at(2), Tok::Punct(":=")) {
            self.bump();
            let mut items = Vec::new();
            loop {
                let n = self.ident()?;
                self.expect_p(":=")?;
                items.push((n, self.init()?));
                if !self.eat_p(",") {
                    break;
                }
            }
            self.expect_p(")")?;
            return Ok(Init::Struct(items, self.from(start)));
        }
        Ok(Init::Expr(self.expr()?))
    }

    fn type_ref(&mut self) -> R<TypeRef> {
        let start = self.start();
        if self.eat_kw("ARRAY") {
            self.expect_p("[")?;
            let mut dims = Vec::new();
            loop {
                let lo = self.expr()?;
                self.expect_p("..")?;
                let hi = self.expr()?;
                dims.push((lo, hi));
                if !self.eat_p(",") {
                    break;
                }
            }
            self.expect_p("]")?;
            self.expect_kw("OF")?;
            let of = Box::new(self.type_ref()?);
            return Ok(TypeRef::Array {
                dims,
                of,
                span: self.from(start),
            });
        }
        if self.eat_kw("STRUCT") {
            let mut members = Vec::new();
            while !self.eat_kw("END_STRUCT") {
                if matches!(self.peek(), Tok::Eof) {
                    return Err(self.error("`END_STRUCT`"));
                }
                members.push(self.var_decl()?);
            }
            return Ok(TypeRef::Struct {
                members,
                span: self.from(start),
            });
        }
        if self.eat_p("(") {
            let mut values = Vec::new();
            loop {
                let n = self.ident()?;
                let v = if self.eat_p(":=") { Some(self.expr()?) } else { None };
                values.push((n, v));
                if !self.eat_p(",") {
                    break;
                }
            }
            self.expect_p(")")?;
            return Ok(TypeRef::Enum {
                values,
                span: self.from(start),
            });
        }
        if self.is_kw("STRING") || self.is_kw("WSTRING") {
            let wide = self.is_kw("WSTRING");
            self.bump();
            let len = if self.eat_p("[") || self.eat_p("(") {
                let e = self.expr()?;
                if !self.eat_p("]") {
                    self.expect_p(")")?;
                }
                Some(Box::new(e))
            } else {
                None
            };
            return Ok(TypeRef::String {
                wide,
                len,
                span: self.from(start),
            });
        }
        let base = self.ident()?;
        if self.eat_p("(") {
            let lo = Box::new(self.expr()?);
            self.expect_p("..")?;
            let hi = Box::new(self.expr()?);
            self.expect_p(")")?;
            return Ok(TypeRef::Subrange {
                base,
                lo,
                hi,
                span: self.from(start),
            });
        }
        Ok(TypeRef::Named(base))
    }

    fn types(&mut self) -> R<Vec<TypeDecl>> {
        self.bump();
        let mut out = Vec::new();
        while !self.eat_kw("END_TYPE") {
            if matches!(self.peek(), Tok::Eof) {
                return Err(self.error("`END_TYPE`"));
            }
            let start = self.start();
            let name = self.ident()?;
            self.expect_p(":")?;
            let ty = self.type_ref()?;
            let init = if self.eat_p(":=") { Some(self.init()?) } else { None };
            self.expect_p(";")?;
            out.push(TypeDecl {
                name,
                ty,
                init,
                span: self.from(start),
            });
        }
        Ok(out)
    }

    fn stmt_list(&mut self) -> Vec<Stmt> {
        let mut out = Vec::new();
        loop {
            match self.peek() {
                Tok::Eof => return out,
                Tok::Ident(s) if ENDERS.iter().any(|k| k.eq_ignore_ascii_case(s)) => return out,
                _ => {}
            }
            let before = self.pos;
            match self.stmt() {
                Ok(s) => out.push(s),
                Err(d) => {
                    self.diags.push(d);
                    if self.pos == before {
                        self.bump();
                    }
                    self.sync();
                }
            }
        }
    }

    fn body_until(&mut self, words: &[&str]) -> R<Vec<Stmt>> {
        let b = self.stmt_list();
        if words.iter().any(|w| self.is_kw(w)) {
            Ok(b)
        } else {
            let list: Vec<_> = words.iter().map(|w| format!("`{w}`")).collect();
            Err(self.error(&list.join(" or ")))
        }
    }

    fn end(&mut self, kw: &str) -> R<()> {
        self.expect_kw(kw)?;
        self.expect_p(";")
    }

    fn stmt(&mut self) -> R<Stmt> {
        let start = self.start();
        let kind = if self.eat_p(";") {
            return Ok(Stmt {
                kind: StmtKind::Empty,
                span: self.from(start),
            });
        } else if self.eat_kw("IF") {
            let mut arms = Vec::new();
            let mut els = None;
            let c = self.expr()?;
            self.expect_kw("THEN")?;
            arms.push((c, self.body_until(&["ELSIF", "ELSE", "END_IF"])?));
            while self.eat_kw("ELSIF") {
                let c = self.expr()?;
                self.expect_kw("THEN")?;
                arms.push((c, self.body_until(&["ELSIF", "ELSE", "END_IF"])?));
            }
            if self.eat_kw("ELSE") {
                els = Some(self.body_until(&["END_IF"])?);
            }
            self.end("END_IF")?;
            StmtKind::If { arms, els }
        } else if self.eat_kw("CASE") {
            let sel = self.expr()?;
            self.expect_kw("OF")?;
            let mut arms = Vec::new();
            let mut els = None;
            loop {
                if self.eat_kw("ELSE") {
                    els = Some(self.body_until(&["END_CASE"])?);
                    break;
                }
                if self.is_kw("END_CASE") {
                    break;
                }
                if matches!(self.peek(), Tok::Eof) || ENDERS.iter().any(|k| self.is_kw(k)) {
                    return Err(self.error("a CASE label, `ELSE` or `END_CASE`"));
                }
                let mut labels = Vec::new();
                loop {
                    let a = self.expr()?;
                    if self.eat_p("..") {
                        labels.push(CaseLabel::Range(a, self.expr()?));
                    } else {
                        labels.push(CaseLabel::One(a));
                    }
                    if !self.eat_p(",") {
                        break;
                    }
                }
                self.expect_p(":")?;
                let body = self.case_body()?;
                arms.push((labels, body));
            }
            self.end("END_CASE")?;
            StmtKind::Case { sel, arms, els }
        } else if self.eat_kw("FOR") {
            let var = self.ident()?;
            self.expect_p(":=")?;
            let from = self.expr()?;
            self.expect_kw("TO")?;
            let to = self.expr()?;
            let by = if self.eat_kw("BY") { Some(self.expr()?) } else { None };
            self.expect_kw("DO")?;
            let body = self.body_until(&["END_FOR"])?;
            self.end("END_FOR")?;
            StmtKind::For {
                var,
                from,
                to,
                by,
                body,
            }
        } else if self.eat_kw("WHILE") {
            let c = self.expr()?;
            self.expect_kw("DO")?;
            let body = self.body_until(&["END_WHILE"])?;
            self.end("END_WHILE")?;
            StmtKind::While(c, body)
        } else if self.eat_kw("REPEAT") {
            let body = self.body_until(&["UNTIL"])?;
            self.expect_kw("UNTIL")?;
            let c = self.expr()?;
            self.end("END_REPEAT")?;
            StmtKind::Repeat(body, c)
        } else if self.eat_kw("EXIT") {
            self.expect_p(";")?;
            StmtKind::Exit
        } else if self.eat_kw("RETURN") {
            self.expect_p(";")?;
            StmtKind::Return
        } else {
            let target = self.postfix()?;
            if self.eat_p(":=") {
                let value = self.expr()?;
                self.expect_p(";")?;
                StmtKind::Assign(target, value)
            } else if let ExprKind::Call(name, args) = target.kind {
                self.expect_p(";")?;
                let span = name.span;
                StmtKind::Call(
                    Expr {
                        kind: ExprKind::Name(name),
                        span,
                    },
                    args,
                )
            } else if matches!(target.kind, ExprKind::Index(..)) && self.eat_p("(") {
                let args = self.args()?;
                self.expect_p(";")?;
                StmtKind::Call(target, args)
            } else if self.is_p("(") {
                // `inst.sub(...)` is not ST; `a.b(...)` would land here.
                return Err(self.error("`:=`"));
            } else {
                return Err(self.error("`:=` or `(` (an assignment or a call)"));
            }
        };
        Ok(Stmt {
            kind,
            span: self.from(start),
        })
    }

    /// The statements of one CASE arm: up to the next label, `ELSE` or `END_CASE`.
    fn case_body(&mut self) -> R<Vec<Stmt>> {
        let mut out = Vec::new();
        loop {
            if matches!(self.peek(), Tok::Eof) || ENDERS.iter().any(|k| self.is_kw(k)) || self.is_kw("END_CASE") {
                return Ok(out);
            }
            // A new label: a literal or a name followed by `:`, `,` or `..`.
            if self.starts_label() {
                return Ok(out);
            }
            let before = self.pos;
            match self.stmt() {
                Ok(s) => out.push(s),
                Err(d) => {
                    self.diags.push(d);
                    if self.pos == before {
                        self.bump();
                    }
                    self.sync();
                }
            }
        }
    }

    fn starts_label(&self) -> bool {
        let mut k = 0;
        if matches!(self.peek(), Tok::Punct("-")) {
            k = 1;
        }
        let first = matches!(self.peek_at(k), Tok::Number(_) | Tok::Typed(..) | Tok::Ident(_));
        first && matches!(self.peek_at(k + 1), Tok::Punct(":" | "," | ".."))
    }

    pub fn expr(&mut self) -> R<Expr> {
        self.binary(0)
    }

    fn binop(&self) -> Option<(BinOp, u8)> {
        Some(match self.peek() {
            Tok::Ident(s) => match s.to_ascii_uppercase().as_str() {
                "OR" => (BinOp::Or, 1),
                "XOR" => (BinOp::Xor, 2),
                "AND" => (BinOp::And, 3),
                "MOD" => (BinOp::Mod, 7),
                _ => return None,
            },
            Tok::Punct(p) => match *p {
                "&" => (BinOp::And, 3),
                "=" => (BinOp::Eq, 4),
                "<>" => (BinOp::Ne, 4),
                "<" => (BinOp::Lt, 5),
                ">" => (BinOp::Gt, 5),
                "<=" => (BinOp::Le, 5),
                ">=" => (BinOp::Ge, 5),
                "+" => (BinOp::Add, 6),
                "-" => (BinOp::Sub, 6),
                "*" => (BinOp::Mul, 7),
                "/" => (BinOp::Div, 7),
                "**" => (BinOp::Pow, 8),
                _ => return None,
            },
            _ => return None,
        })
    }

    fn binary(&mut self, min: u8) -> R<Expr> {
        let start = self.start();
        let mut lhs = self.unary()?;
        while let Some((op, prec)) = self.binop() {
            if prec < min {
                break;
            }
            self.bump();
            // `**` is left-associative in IEC 61131-3 like the others.
            let rhs = self.binary(prec + 1)?;
            lhs = Expr {
                kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                span: self.from(start),
            };
        }
        Ok(lhs)
    }

    fn unary(&mut self) -> R<Expr> {
        let start = self.start();
        let op = if self.eat_p("-") {
            Some(UnOp::Neg)
        } else if self.eat_kw("NOT") {
            Some(UnOp::Not)
        } else {
            self.eat_p("+");
            None
        };
        match op {
            Some(op) => {
                let a = self.unary()?;
                // `-5` is a literal, not a negation (so INT#-32768 and -32768 fit).
                if op == UnOp::Neg
                    && let ExprKind::Lit(Lit::Int(v, t)) = &a.kind
                {
                    return Ok(Expr {
                        kind: ExprKind::Lit(Lit::Int(-v, t.clone())),
                        span: self.from(start),
                    });
                }
                if op == UnOp::Neg
                    && let ExprKind::Lit(Lit::Real(v, t)) = &a.kind
                {
                    return Ok(Expr {
                        kind: ExprKind::Lit(Lit::Real(-v, t.clone())),
                        span: self.from(start),
                    });
                }
                Ok(Expr {
                    kind: ExprKind::Unary(op, Box::new(a)),
                    span: self.from(start),
                })
            }
            None => self.postfix(),
        }
    }

    fn postfix(&mut self) -> R<Expr> {
        let start = self.start();
        let mut e = self.primary()?;
        loop {
            if self.eat_p(".") {
                let m = match self.peek().clone() {
                    // `x.0`: a bit of an integer.
                    Tok::Number(n) => {
                        let span = self.span_here();
                        self.bump();
                        Ident { name: n, span }
                    }
                    _ => self.ident()?,
                };
                e = Expr {
                    kind: ExprKind::Member(Box::new(e), m),
                    span: self.from(start),
                };
            } else if self.eat_p("[") {
                let mut ix = vec![self.expr()?];
                while self.eat_p(",") {
                    ix.push(self.expr()?);
                }
                self.expect_p("]")?;
                e = Expr {
                    kind: ExprKind::Index(Box::new(e), ix),
                    span: self.from(start),
                };
            } else if self.is_p("(") {
                let ExprKind::Name(name) = &e.kind else {
                    if let ExprKind::Index(..) = e.kind {
                        // `t[i](…)`: an element of an array of FB instances,
                        // called as a statement.
                        return Ok(e);
                    }
                    return Err(self.error("an operator, `;` or `)`"));
                };
                let name = name.clone();
                self.bump();
                let args = self.args()?;
                e = Expr {
                    kind: ExprKind::Call(name, args),
                    span: self.from(start),
                };
            } else {
                return Ok(e);
            }
        }
    }

    fn args(&mut self) -> R<Vec<Arg>> {
        let mut out = Vec::new();
        if self.eat_p(")") {
            return Ok(out);
        }
        loop {
            let negated = self.is_kw("NOT") && matches!(self.peek_at(2), Tok::Punct("=>"));
            if negated {
                self.bump();
            }
            let formal = matches!(self.peek(), Tok::Ident(_)) && matches!(self.peek_at(1), Tok::Punct(":=" | "=>"));
            if formal {
                let name = self.ident()?;
                let output = matches!(self.bump().tok, Tok::Punct("=>"));
                let value = if output && (self.is_p(",") || self.is_p(")")) {
                    // `Q =>` with nothing: the output is not connected (an empty span says so).
                    let at = self.start();
                    let span = Span::new(self.file, at..at);
                    Expr {
                        kind: ExprKind::Lit(Lit::Bool(false)),
                        span,
                    }
                } else {
                    self.expr()?
                };
                out.push(Arg {
                    name: Some(name),
                    output,
                    negated,
                    value,
                });
            } else {
                out.push(Arg {
                    name: None,
                    output: false,
                    negated: false,
                    value: self.expr()?,
                });
            }
            if !self.eat_p(",") {
                break;
            }
        }
        self.expect_p(")")?;
        Ok(out)
    }

    fn primary(&mut self) -> R<Expr> {
        let span = self.span_here();
        let lit = |l| {
            Ok(Expr {
                kind: ExprKind::Lit(l),
                span,
            })
        };
        match self.peek().clone() {
            Tok::Punct("(") => {
                self.bump();
                let e = self.expr()?;
                self.expect_p(")")?;
                Ok(e)
            }
            Tok::Number(n) => {
                self.bump();
                let l = number(&n, None).map_err(|m| self.bad_literal(span, m))?;
                lit(l)
            }
            Tok::Str(s, w) => {
                self.bump();
                lit(Lit::Str(s, w))
            }
            Tok::Typed(t, v) => {
                self.bump();
                let l = typed(&t, &v).map_err(|m| self.bad_literal(span, m))?;
                lit(l)
            }
            Tok::Ident(s) if s.eq_ignore_ascii_case("TRUE") => {
                self.bump();
                lit(Lit::Bool(true))
            }
            Tok::Ident(s) if s.eq_ignore_ascii_case("FALSE") => {
                self.bump();
                lit(Lit::Bool(false))
            }
            Tok::Ident(_) => {
                let i = self.ident()?;
                Ok(Expr {
                    span: i.span,
                    kind: ExprKind::Name(i),
                })
            }
            _ => Err(self.error("an expression")),
        }
    }

    fn bad_literal(&self, span: Span, msg: String) -> Diagnostic {
        Diagnostic::new(Code::StSyntax, msg, span, "literal")
    }
}

/// A number as written, of the type `ty` if typed.
fn number(text: &str, ty: Option<&str>) -> Result<Lit, String> {
    let t = ty.map(str::to_ascii_uppercase);
    match Literal::parse(text)? {
        Literal::Int(v) => match t.as_deref() {
            Some("REAL" | "LREAL") => Ok(Lit::Real(v as f64, t)),
            _ => Ok(Lit::Int(v, t)),
        },
        Literal::Real(v) => match t.as_deref() {
            None | Some("REAL" | "LREAL") => Ok(Lit::Real(v, t)),
            Some(k) => Err(format!("`{k}#{text}`: a {k} literal takes an integer")),
        },
        Literal::Bool(b) => Ok(Lit::Bool(b)),
        Literal::Time(ms) => Ok(Lit::Time(ms)),
    }
}

const INT_TYPES: [&str; 16] = [
    "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "BYTE", "WORD", "DWORD", "LWORD", "REAL",
    "LREAL", "BOOL", "ANY",
];

/// An IEC duration (`1d2h3m4s5ms`, `1.5s`, `2h_30m`) in milliseconds.
fn duration(v: &str) -> Option<i64> {
    duration_in(v, 1.0)
}

/// An IEC duration in nanoseconds (LTIME).
pub(crate) fn duration_ns(v: &str) -> Option<i64> {
    duration_in(v, 1e6)
}

/// A duration in units of `1 / per_ms` milliseconds.
fn duration_in(v: &str, per_ms: f64) -> Option<i64> {
    let v = v.replace('_', "").to_ascii_lowercase();
    let mut rest = v.as_str();
    let mut total = 0f64;
    if rest.is_empty() {
        return None;
    }
    while !rest.is_empty() {
        let n = rest
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(rest.len());
        let num: f64 = rest[..n].parse().ok()?;
        rest = &rest[n..];
        let (unit, len) = if rest.starts_with("ms") {
            (1.0, 2)
        } else if rest.starts_with("us") {
            (0.001, 2)
        } else if rest.starts_with("ns") {
            (0.000_001, 2)
        } else if rest.starts_with('d') {
            (86_400_000.0, 1)
        } else if rest.starts_with('h') {
            (3_600_000.0, 1)
        } else if rest.starts_with('m') {
            (60_000.0, 1)
        } else if rest.starts_with('s') {
            (1000.0, 1)
        } else {
            return None;
        };
        rest = &rest[len..];
        total += num * unit * per_ms;
    }
    (total.is_finite() && total.abs() < 9.2e18).then(|| total.round() as i64)
}

/// A typed literal `t#v`.
fn typed(t: &str, v: &str) -> Result<Lit, String> {
    let upper = t.to_ascii_uppercase();
    match upper.as_str() {
        // An LTIME keeps its text: the lowering reads it in nanoseconds.
        "LT" | "LTIME" => match duration_ns(v.trim_start_matches('-')) {
            Some(_) => Ok(Lit::Other(t.to_string(), v.to_string())),
            None => Err(format!(
                "`{t}#{v}` is not a duration; write it like LTIME#1h2m3s, LTIME#1.5s or LTIME#250us"
            )),
        },
        "T" | "TIME" => match duration(v.trim_start_matches('-')) {
            Some(ms) => Ok(Lit::Time(if v.starts_with('-') { -ms } else { ms })),
            None => Err(format!(
                "`{t}#{v}` is not a duration; write it like T#1h2m3s, T#1.5s or T#250ms"
            )),
        },
        "2" | "8" | "10" | "16" => number(&format!("{t}#{v}"), None),
        "BOOL" => match v.to_ascii_uppercase().as_str() {
            "TRUE" | "1" => Ok(Lit::Bool(true)),
            "FALSE" | "0" => Ok(Lit::Bool(false)),
            _ => Err(format!("`{t}#{v}`: a BOOL literal is TRUE, FALSE, 1 or 0")),
        },
        k if INT_TYPES.contains(&k) => number(v, Some(k)),
        _ => Ok(Lit::Other(t.to_string(), v.to_string())),
    }
}
