//! The syntax tree of a Structured Text file, with spans for every name,
//! statement and expression.

use alba_diag::Span;

/// A file: its POUs and `TYPE` declarations, in order.
#[derive(Debug, Clone, Default)]
pub struct File {
    pub pous: Vec<Pou>,
    pub types: Vec<TypeDecl>,
    /// `VAR_GLOBAL` blocks outside any POU (a `CONFIGURATION` is not read).
    pub globals: Vec<VarBlock>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

impl Ident {
    pub fn is(&self, s: &str) -> bool {
        self.name.eq_ignore_ascii_case(s)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PouKind {
    Program,
    Function,
    FunctionBlock,
}

impl PouKind {
    pub fn keyword(self) -> &'static str {
        match self {
            PouKind::Program => "PROGRAM",
            PouKind::Function => "FUNCTION",
            PouKind::FunctionBlock => "FUNCTION_BLOCK",
        }
    }
}

#[derive(Debug, Clone)]
pub struct Pou {
    pub kind: PouKind,
    pub name: Ident,
    /// A FUNCTION's result type.
    pub ret: Option<TypeRef>,
    pub vars: Vec<VarBlock>,
    pub body: Vec<Stmt>,
    pub span: Span,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarKind {
    Var,
    Input,
    Output,
    InOut,
    Temp,
    Global,
    External,
}

impl VarKind {
    pub fn keyword(self) -> &'static str {
        match self {
            VarKind::Var => "VAR",
            VarKind::Input => "VAR_INPUT",
            VarKind::Output => "VAR_OUTPUT",
            VarKind::InOut => "VAR_IN_OUT",
            VarKind::Temp => "VAR_TEMP",
            VarKind::Global => "VAR_GLOBAL",
            VarKind::External => "VAR_EXTERNAL",
        }
    }
}

#[derive(Debug, Clone)]
pub struct VarBlock {
    pub kind: VarKind,
    pub retain: bool,
    pub constant: bool,
    pub vars: Vec<VarDecl>,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct VarDecl {
    pub names: Vec<Ident>,
    /// `AT %IX0.0`, as written.
    pub at: Option<(String, Span)>,
    pub ty: TypeRef,
    pub init: Option<Init>,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub enum TypeRef {
    /// An elementary type, a standard FB, or a user type, by name.
    Named(Ident),
    /// `STRING[n]` / `WSTRING[n]` (or without a length).
    String {
        wide: bool,
        len: Option<Box<Expr>>,
        span: Span,
    },
    Array {
        dims: Vec<(Expr, Expr)>,
        of: Box<TypeRef>,
        span: Span,
    },
    Struct {
        members: Vec<VarDecl>,
        span: Span,
    },
    Enum {
        values: Vec<(Ident, Option<Expr>)>,
        span: Span,
    },
    Subrange {
        base: Ident,
        lo: Box<Expr>,
        hi: Box<Expr>,
        span: Span,
    },
}

impl TypeRef {
    pub fn span(&self) -> Span {
        match self {
            TypeRef::Named(i) => i.span,
            TypeRef::String { span, .. }
            | TypeRef::Array { span, .. }
            | TypeRef::Struct { span, .. }
            | TypeRef::Enum { span, .. }
            | TypeRef::Subrange { span, .. } => *span,
        }
    }
}

#[derive(Debug, Clone)]
pub enum Init {
    Expr(Expr),
    /// `[1, 2, 3(0)]`: elements, with a repeat count.
    Array(Vec<(Option<Expr>, Init)>, Span),
    /// `(a := 1, b := 2)`.
    Struct(Vec<(Ident, Init)>, Span),
}

#[derive(Debug, Clone)]
pub struct TypeDecl {
    pub name: Ident,
    pub ty: TypeRef,
    pub init: Option<Init>,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct Stmt {
    pub kind: StmtKind,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub enum CaseLabel {
    One(Expr),
    Range(Expr, Expr),
}

#[derive(Debug, Clone)]
pub enum StmtKind {
    Assign(Expr, Expr),
    /// An FB or function call as a statement.
    Call(Expr, Vec<Arg>),
    If {
        arms: Vec<(Expr, Vec<Stmt>)>,
        els: Option<Vec<Stmt>>,
    },
    Case {
        sel: Expr,
        arms: Vec<(Vec<CaseLabel>, Vec<Stmt>)>,
        els: Option<Vec<Stmt>>,
    },
    For {
        var: Ident,
        from: Expr,
        to: Expr,
        by: Option<Expr>,
        body: Vec<Stmt>,
    },
    While(Expr, Vec<Stmt>),
    Repeat(Vec<Stmt>, Expr),
    Exit,
    Return,
    Empty,
}

#[derive(Debug, Clone)]
pub struct Arg {
    /// `name :=` or `name =>` (formal), or none (positional).
    pub name: Option<Ident>,
    /// `=>`: an output parameter.
    pub output: bool,
    /// `NOT name =>`.
    pub negated: bool,
    pub value: Expr,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
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

impl BinOp {
    pub fn text(self) -> &'static str {
        match self {
            BinOp::Or => "OR",
            BinOp::Xor => "XOR",
            BinOp::And => "AND",
            BinOp::Eq => "=",
            BinOp::Ne => "<>",
            BinOp::Lt => "<",
            BinOp::Gt => ">",
            BinOp::Le => "<=",
            BinOp::Ge => ">=",
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Mod => "MOD",
            BinOp::Pow => "**",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnOp {
    Neg,
    Not,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Lit {
    Bool(bool),
    /// An integer, with the type a typed literal gave it (`DINT#5`).
    Int(i64, Option<String>),
    Real(f64, Option<String>),
    /// Milliseconds (`T#1h2m`, `TIME#5s`).
    Time(i64),
    /// Other typed literals kept as written (`DATE#2024-01-01`, `Color#Red`).
    Other(String, String),
    Str(String, bool),
}

#[derive(Debug, Clone)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub enum ExprKind {
    Lit(Lit),
    Name(Ident),
    Member(Box<Expr>, Ident),
    Index(Box<Expr>, Vec<Expr>),
    Unary(UnOp, Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    Call(Ident, Vec<Arg>),
}

/// The syntax tree printed back as fully parenthesised ST, one statement a
/// line (for golden tests and for reading what the parser understood).
pub fn dump(f: &File) -> String {
    let mut out = String::new();
    if !f.types.is_empty() {
        out.push_str("TYPE\n");
        for t in &f.types {
            out.push_str(&format!("  {} : {}", t.name.name, ty(&t.ty)));
            if let Some(i) = &t.init {
                out.push_str(&format!(" := {}", init(i)));
            }
            out.push_str(";\n");
        }
        out.push_str("END_TYPE\n");
    }
    for b in &f.globals {
        block(&mut out, b, "");
    }
    for p in &f.pous {
        out.push_str(p.kind.keyword());
        out.push(' ');
        out.push_str(&p.name.name);
        if let Some(r) = &p.ret {
            out.push_str(&format!(" : {}", ty(r)));
        }
        out.push('\n');
        for b in &p.vars {
            block(&mut out, b, "  ");
        }
        stmts(&mut out, &p.body, 1);
        out.push_str(&format!("END_{}\n", p.kind.keyword()));
    }
    out
}

fn block(out: &mut String, b: &VarBlock, pad: &str) {
    out.push_str(pad);
    out.push_str(b.kind.keyword());
    if b.retain {
        out.push_str(" RETAIN");
    }
    if b.constant {
        out.push_str(" CONSTANT");
    }
    out.push('\n');
    for v in &b.vars {
        let names: Vec<_> = v.names.iter().map(|n| n.name.as_str()).collect();
        out.push_str(&format!("{pad}  {}", names.join(", ")));
        if let Some((a, _)) = &v.at {
            out.push_str(&format!(" AT {a}"));
        }
        out.push_str(&format!(" : {}", ty(&v.ty)));
        if let Some(i) = &v.init {
            out.push_str(&format!(" := {}", init(i)));
        }
        out.push_str(";\n");
    }
    out.push_str(&format!("{pad}END_VAR\n"));
}

fn ty(t: &TypeRef) -> String {
    match t {
        TypeRef::Named(i) => i.name.clone(),
        TypeRef::String { wide, len, .. } => {
            let k = if *wide { "WSTRING" } else { "STRING" };
            match len {
                Some(l) => format!("{k}[{}]", expr(l)),
                None => k.to_string(),
            }
        }
        TypeRef::Array { dims, of, .. } => {
            let d: Vec<_> = dims.iter().map(|(a, b)| format!("{}..{}", expr(a), expr(b))).collect();
            format!("ARRAY[{}] OF {}", d.join(", "), ty(of))
        }
        TypeRef::Struct { members, .. } => {
            let m: Vec<_> = members
                .iter()
                .map(|v| {
                    let names: Vec<_> = v.names.iter().map(|n| n.name.as_str()).collect();
                    let i = v.init.as_ref().map(|i| format!(" := {}", init(i))).unwrap_or_default();
                    format!("{} : {}{i};", names.join(", "), ty(&v.ty))
                })
                .collect();
            format!("STRUCT {} END_STRUCT", m.join(" "))
        }
        TypeRef::Enum { values, .. } => {
            let v: Vec<_> = values
                .iter()
                .map(|(n, e)| match e {
                    Some(e) => format!("{} := {}", n.name, expr(e)),
                    None => n.name.clone(),
                })
                .collect();
            format!("({})", v.join(", "))
        }
        TypeRef::Subrange { base, lo, hi, .. } => format!("{}({}..{})", base.name, expr(lo), expr(hi)),
    }
}

fn init(i: &Init) -> String {
    match i {
        Init::Expr(e) => expr(e),
        Init::Array(items, _) => {
            let v: Vec<_> = items
                .iter()
                .map(|(n, i)| match n {
                    Some(n) => format!("{}({})", expr(n), init(i)),
                    None => init(i),
                })
                .collect();
            format!("[{}]", v.join(", "))
        }
        Init::Struct(items, _) => {
            let v: Vec<_> = items
                .iter()
                .map(|(n, i)| format!("{} := {}", n.name, init(i)))
                .collect();
            format!("({})", v.join(", "))
        }
    }
}

fn args(a: &[Arg]) -> String {
    let v: Vec<_> = a
        .iter()
        .map(|a| match &a.name {
            Some(n) if a.output && a.value.span.start == a.value.span.end => format!("{} =>", n.name),
            Some(n) => format!(
                "{}{} {} {}",
                if a.negated { "NOT " } else { "" },
                n.name,
                if a.output { "=>" } else { ":=" },
                expr(&a.value)
            ),
            None => expr(&a.value),
        })
        .collect();
    v.join(", ")
}

pub fn expr(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Lit(l) => match l {
            Lit::Bool(b) => if *b { "TRUE" } else { "FALSE" }.into(),
            Lit::Int(v, t) => t.as_ref().map_or(v.to_string(), |t| format!("{t}#{v}")),
            Lit::Real(v, t) => t.as_ref().map_or(format!("{v:?}"), |t| format!("{t}#{v:?}")),
            Lit::Time(ms) => format!("T#{ms}ms"),
            Lit::Other(t, v) => format!("{t}#{v}"),
            Lit::Str(s, w) => {
                let q = if *w { '"' } else { '\'' };
                format!("{q}{}{q}", s.replace('$', "$$").replace(q, &format!("${q}")))
            }
        },
        ExprKind::Name(i) => i.name.clone(),
        ExprKind::Member(b, m) => format!("{}.{}", expr(b), m.name),
        ExprKind::Index(b, ix) => {
            let v: Vec<_> = ix.iter().map(expr).collect();
            format!("{}[{}]", expr(b), v.join(", "))
        }
        ExprKind::Unary(UnOp::Neg, a) => format!("(-{})", expr(a)),
        ExprKind::Unary(UnOp::Not, a) => format!("(NOT {})", expr(a)),
        ExprKind::Binary(op, a, b) => format!("({} {} {})", expr(a), op.text(), expr(b)),
        ExprKind::Call(n, a) => format!("{}({})", n.name, args(a)),
    }
}

fn stmts(out: &mut String, list: &[Stmt], depth: usize) {
    for s in list {
        stmt(out, s, depth);
    }
}

fn stmt(out: &mut String, s: &Stmt, depth: usize) {
    let pad = "  ".repeat(depth);
    match &s.kind {
        StmtKind::Assign(l, r) => out.push_str(&format!("{pad}{} := {};\n", expr(l), expr(r))),
        StmtKind::Call(c, a) => out.push_str(&format!("{pad}{}({});\n", expr(c), args(a))),
        StmtKind::If { arms, els } => {
            for (k, (c, body)) in arms.iter().enumerate() {
                let kw = if k == 0 { "IF" } else { "ELSIF" };
                out.push_str(&format!("{pad}{kw} {} THEN\n", expr(c)));
                stmts(out, body, depth + 1);
            }
            if let Some(e) = els {
                out.push_str(&format!("{pad}ELSE\n"));
                stmts(out, e, depth + 1);
            }
            out.push_str(&format!("{pad}END_IF;\n"));
        }
        StmtKind::Case { sel, arms, els } => {
            out.push_str(&format!("{pad}CASE {} OF\n", expr(sel)));
            for (labels, body) in arms {
                let l: Vec<_> = labels
                    .iter()
                    .map(|l| match l {
                        CaseLabel::One(e) => expr(e),
                        CaseLabel::Range(a, b) => format!("{}..{}", expr(a), expr(b)),
                    })
                    .collect();
                out.push_str(&format!("{pad}{}:\n", l.join(", ")));
                stmts(out, body, depth + 1);
            }
            if let Some(e) = els {
                out.push_str(&format!("{pad}ELSE\n"));
                stmts(out, e, depth + 1);
            }
            out.push_str(&format!("{pad}END_CASE;\n"));
        }
        StmtKind::For {
            var,
            from,
            to,
            by,
            body,
        } => {
            let by = by.as_ref().map(|b| format!(" BY {}", expr(b))).unwrap_or_default();
            out.push_str(&format!(
                "{pad}FOR {} := {} TO {}{by} DO\n",
                var.name,
                expr(from),
                expr(to)
            ));
            stmts(out, body, depth + 1);
            out.push_str(&format!("{pad}END_FOR;\n"));
        }
        StmtKind::While(c, body) => {
            out.push_str(&format!("{pad}WHILE {} DO\n", expr(c)));
            stmts(out, body, depth + 1);
            out.push_str(&format!("{pad}END_WHILE;\n"));
        }
        StmtKind::Repeat(body, c) => {
            out.push_str(&format!("{pad}REPEAT\n"));
            stmts(out, body, depth + 1);
            out.push_str(&format!("{pad}UNTIL {} END_REPEAT;\n", expr(c)));
        }
        StmtKind::Exit => out.push_str(&format!("{pad}EXIT;\n")),
        StmtKind::Return => out.push_str(&format!("{pad}RETURN;\n")),
        StmtKind::Empty => out.push_str(&format!("{pad};\n")),
    }
}
