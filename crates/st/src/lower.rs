//! The checker and the lowering of ST `PROGRAM`s to the Alba IR.
//!
//! [`declare`] adds a tag for every variable of every PROGRAM (named
//! `<program>.<variable>`, array elements `<program>.<a>[i]`, standard FB
//! instances as TIMER / COUNTER / BOOL tags) and for `VAR_GLOBAL`s, before
//! the layout is made; [`compile`] then lowers each body in file order.
//!
//! Evaluation keeps one invariant: between ops of the lowering the rung
//! condition `rc` is true, so the IR's data operations (which act only while
//! `rc` holds) always act; boolean logic uses `rc` and restores it with
//! `True`. Control flow is `Jmp` to the `Rung` that starts each block.

use crate::ast::{
    self, Arg, BinOp, CaseLabel, Expr, ExprKind, Ident, Init, Lit, Pou, PouKind, Stmt, StmtKind, TypeRef, UnOp as AUn,
    VarKind,
};
use alba_diag::{Code, Diagnostic, Span};
use alba_ir::layout::Place;
use alba_ir::op::{B, BinOp as IBin, Cmp, Ctr, I, Op, UnOp as IUn, Width};
use alba_ir::values::{Class, V};
use alba_ir::{Access, Builder, NO_ELEM, Target};
use alba_model::tags::{Tag, TagTable, edit_distance};
use alba_model::{DataType, Value};
use std::collections::{HashMap, HashSet};
use std::rc::Rc;

type R<T> = Result<T, Diagnostic>;

/// Most elements an ARRAY may have (each is a tag).
pub const MAX_ELEMENTS: i64 = 10_000;

/// The standard function blocks Alba maps onto its engine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fb {
    Ton,
    Tof,
    Tp,
    Ctu,
    Ctd,
    Ctud,
    RTrig,
    FTrig,
    Sr,
    Rs,
}

impl Fb {
    fn from_name(n: &str) -> Option<Fb> {
        Some(match n.to_ascii_uppercase().as_str() {
            "TON" => Fb::Ton,
            "TOF" => Fb::Tof,
            "TP" => Fb::Tp,
            "CTU" => Fb::Ctu,
            "CTD" => Fb::Ctd,
            "CTUD" => Fb::Ctud,
            "R_TRIG" => Fb::RTrig,
            "F_TRIG" => Fb::FTrig,
            "SR" => Fb::Sr,
            "RS" => Fb::Rs,
            _ => return None,
        })
    }
    fn name(self) -> &'static str {
        match self {
            Fb::Ton => "TON",
            Fb::Tof => "TOF",
            Fb::Tp => "TP",
            Fb::Ctu => "CTU",
            Fb::Ctd => "CTD",
            Fb::Ctud => "CTUD",
            Fb::RTrig => "R_TRIG",
            Fb::FTrig => "F_TRIG",
            Fb::Sr => "SR",
            Fb::Rs => "RS",
        }
    }
    /// Inputs and outputs with their types.
    fn params(self) -> (Params, Params) {
        use P::*;
        match self {
            Fb::Ton | Fb::Tof | Fb::Tp => (&[("IN", Bool), ("PT", Time)], &[("Q", Bool), ("ET", Time)]),
            Fb::Ctu => (&[("CU", Bool), ("R", Bool), ("PV", Int)], &[("Q", Bool), ("CV", Int)]),
            Fb::Ctd => (&[("CD", Bool), ("LD", Bool), ("PV", Int)], &[("Q", Bool), ("CV", Int)]),
            Fb::Ctud => (
                &[("CU", Bool), ("CD", Bool), ("R", Bool), ("LD", Bool), ("PV", Int)],
                &[("QU", Bool), ("QD", Bool), ("CV", Int)],
            ),
            Fb::RTrig | Fb::FTrig => (&[("CLK", Bool)], &[("Q", Bool)]),
            Fb::Sr => (&[("S1", Bool), ("R", Bool)], &[("Q1", Bool)]),
            Fb::Rs => (&[("S", Bool), ("R1", Bool)], &[("Q1", Bool)]),
        }
    }
}

/// Parameters of a standard FB: names and types.
type Params = &'static [(&'static str, P)];
/// An array's element type, element places and bounds.
type ArrayParts = (Ty, Vec<Place>, Vec<(i64, i64)>);
/// An indexed element: its type, the places it is chosen from, the bounds
/// and the index expressions.
type Indexed<'e> = (Ty, Vec<Place>, Vec<(i64, i64)>, &'e [Expr]);
/// A call's inputs by parameter, and its `=>` outputs.
type Bound<'e> = (Vec<Option<&'e Expr>>, Vec<(usize, &'e Arg)>);

/// The type of a standard FB's parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum P {
    Bool,
    Int,
    Time,
}

impl P {
    fn ty(self) -> Ty {
        match self {
            P::Bool => Ty::Bool,
            P::Int => Ty::Int,
            P::Time => Ty::Time,
        }
    }
}

/// A STRUCT type: its name (`STRUCT` for one written in a declaration) and
/// its members with their types and default initial values.
#[derive(Debug)]
pub struct StructTy {
    pub name: String,
    pub members: Vec<(String, Ty, Option<Init>)>,
}

impl PartialEq for StructTy {
    fn eq(&self, o: &Self) -> bool {
        self.name.eq_ignore_ascii_case(&o.name)
            && self.members.len() == o.members.len()
            && self
                .members
                .iter()
                .zip(&o.members)
                .all(|(a, b)| a.0 == b.0 && a.1 == b.1)
    }
}

/// An enumerated type: its name and its values.
#[derive(Debug, PartialEq)]
pub struct EnumTy {
    pub name: String,
    pub values: Vec<(String, i64)>,
}

/// A type the lowering knows.
#[derive(Debug, Clone, PartialEq)]
pub enum Ty {
    Bool,
    Sint,
    Int,
    Dint,
    Lint,
    Real,
    Lreal,
    Time,
    Usint,
    Uint,
    Udint,
    Ulint,
    Byte,
    Word,
    Dword,
    Lword,
    Array(Box<Ty>, Vec<(i64, i64)>),
    Fb(Fb),
    /// A user FUNCTION_BLOCK, by its name as declared.
    User(String),
    Struct(Rc<StructTy>),
    Enum(Rc<EnumTy>),
    /// A subrange of an integer type.
    Sub(Box<Ty>, i64, i64),
}

impl std::fmt::Display for Ty {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ty::Bool => f.write_str("BOOL"),
            Ty::Sint => f.write_str("SINT"),
            Ty::Int => f.write_str("INT"),
            Ty::Dint => f.write_str("DINT"),
            Ty::Lint => f.write_str("LINT"),
            Ty::Real => f.write_str("REAL"),
            Ty::Lreal => f.write_str("LREAL"),
            Ty::Time => f.write_str("TIME"),
            Ty::Usint => f.write_str("USINT"),
            Ty::Uint => f.write_str("UINT"),
            Ty::Udint => f.write_str("UDINT"),
            Ty::Ulint => f.write_str("ULINT"),
            Ty::Byte => f.write_str("BYTE"),
            Ty::Word => f.write_str("WORD"),
            Ty::Dword => f.write_str("DWORD"),
            Ty::Lword => f.write_str("LWORD"),
            Ty::Array(of, dims) => {
                let d: Vec<_> = dims.iter().map(|(a, b)| format!("{a}..{b}")).collect();
                write!(f, "ARRAY[{}] OF {of}", d.join(","))
            }
            Ty::Fb(k) => f.write_str(k.name()),
            Ty::User(n) => f.write_str(n),
            Ty::Struct(s) => f.write_str(&s.name),
            Ty::Enum(e) => f.write_str(&e.name),
            Ty::Sub(b, lo, hi) => write!(f, "{b}({lo}..{hi})"),
        }
    }
}

impl Ty {
    /// The type of the tag (or slot) that stores a value of this type.
    fn data_type(&self) -> Option<DataType> {
        Some(match self {
            Ty::Bool => DataType::Bool,
            Ty::Sint => DataType::Sint,
            Ty::Int | Ty::Usint | Ty::Byte => DataType::Int,
            Ty::Dint | Ty::Uint | Ty::Word | Ty::Enum(_) => DataType::Dint,
            Ty::Lint | Ty::Udint | Ty::Ulint | Ty::Dword | Ty::Lword => DataType::Lint,
            Ty::Real => DataType::Real,
            Ty::Lreal => DataType::Lreal,
            Ty::Time => DataType::Time,
            Ty::Sub(b, ..) => return b.data_type(),
            _ => return None,
        })
    }
    fn from_data_type(t: DataType) -> Option<Ty> {
        Some(match t {
            DataType::Bool => Ty::Bool,
            DataType::Sint => Ty::Sint,
            DataType::Int => Ty::Int,
            DataType::Dint => Ty::Dint,
            DataType::Lint => Ty::Lint,
            DataType::Real => Ty::Real,
            DataType::Lreal => Ty::Lreal,
            DataType::Time => Ty::Time,
            _ => return None,
        })
    }
    /// The type a value read from this type has (a subrange reads as its base).
    fn value(&self) -> Ty {
        match self {
            Ty::Sub(b, ..) => (**b).clone(),
            t => t.clone(),
        }
    }
    fn is_int(&self) -> bool {
        matches!(self, Ty::Sint | Ty::Int | Ty::Dint | Ty::Lint) || self.is_unsigned()
    }
    fn is_unsigned(&self) -> bool {
        matches!(self, Ty::Usint | Ty::Uint | Ty::Udint | Ty::Ulint)
    }
    fn is_bits(&self) -> bool {
        matches!(self, Ty::Byte | Ty::Word | Ty::Dword | Ty::Lword)
    }
    /// Bits of an unsigned integer or a bit string.
    fn bits(&self) -> Option<u32> {
        Some(match self {
            Ty::Usint | Ty::Byte => 8,
            Ty::Uint | Ty::Word => 16,
            Ty::Udint | Ty::Dword => 32,
            Ty::Ulint | Ty::Lword => 64,
            _ => return None,
        })
    }
    fn is_real(&self) -> bool {
        matches!(self, Ty::Real | Ty::Lreal)
    }
    fn is_num(&self) -> bool {
        self.is_int() || self.is_real() || *self == Ty::Time
    }
    fn class(&self) -> Class {
        match self.data_type() {
            Some(DataType::Lint) => Class::L,
            Some(DataType::Real) => Class::F,
            Some(DataType::Lreal) => Class::D,
            _ => Class::I,
        }
    }
    fn rank(&self) -> u8 {
        match self {
            Ty::Sint => 1,
            Ty::Int => 2,
            Ty::Dint => 3,
            Ty::Lint => 4,
            Ty::Real => 5,
            Ty::Lreal => 6,
            Ty::Usint | Ty::Byte => 11,
            Ty::Uint | Ty::Word => 12,
            Ty::Udint | Ty::Dword => 13,
            Ty::Ulint | Ty::Lword => 14,
            _ => 0,
        }
    }
    fn elements(&self) -> i64 {
        match self {
            Ty::Array(_, dims) => dims.iter().map(|(a, b)| b - a + 1).product(),
            _ => 1,
        }
    }
}

/// Whether a value of `from` may be used where `to` is wanted without a
/// conversion function (IEC 61131-3 implicit widening).
fn widens(from: &Ty, to: &Ty) -> bool {
    if from == to {
        return true;
    }
    match (from, to) {
        (Ty::Sub(b, ..), to) => widens(b, to),
        (from, Ty::Sub(b, ..)) => widens(from, b),
        (a, b) if a.is_unsigned() && b.is_unsigned() => a.rank() < b.rank(),
        (a, b) if a.is_bits() && b.is_bits() => a.rank() < b.rank(),
        (Ty::Usint, Ty::Int | Ty::Dint | Ty::Lint | Ty::Real | Ty::Lreal) => true,
        (Ty::Uint, Ty::Dint | Ty::Lint | Ty::Real | Ty::Lreal) => true,
        (Ty::Udint, Ty::Lint | Ty::Lreal) => true,
        (a, b) if a.is_int() && b.is_int() && !a.is_unsigned() && !b.is_unsigned() => a.rank() < b.rank(),
        (Ty::Sint | Ty::Int, Ty::Real | Ty::Lreal) => true,
        (Ty::Dint, Ty::Lreal) => true,
        (Ty::Real, Ty::Lreal) => true,
        _ => false,
    }
}

fn elementary(name: &str) -> Option<Ty> {
    Some(match name.to_ascii_uppercase().as_str() {
        "BOOL" => Ty::Bool,
        "SINT" => Ty::Sint,
        "INT" => Ty::Int,
        "DINT" => Ty::Dint,
        "LINT" => Ty::Lint,
        "REAL" => Ty::Real,
        "LREAL" => Ty::Lreal,
        "TIME" => Ty::Time,
        "USINT" => Ty::Usint,
        "UINT" => Ty::Uint,
        "UDINT" => Ty::Udint,
        "ULINT" => Ty::Ulint,
        "BYTE" => Ty::Byte,
        "WORD" => Ty::Word,
        "DWORD" => Ty::Dword,
        "LWORD" => Ty::Lword,
        _ => return None,
    })
}

const UNSUPPORTED_TYPES: [&str; 6] = ["LTIME", "DATE", "TIME_OF_DAY", "TOD", "DATE_AND_TIME", "DT"];

fn not_supported(span: Span, what: String) -> Diagnostic {
    Diagnostic::new(Code::StNotSupported, what, span, "not supported yet")
}

fn type_error(span: Span, msg: String) -> Diagnostic {
    Diagnostic::new(Code::StType, msg, span, "type")
}

fn decl_error(span: Span, msg: String) -> Diagnostic {
    Diagnostic::new(Code::StDeclaration, msg, span, "declaration")
}

fn closest<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let lower = name.to_ascii_lowercase();
    candidates
        .map(|c| (edit_distance(&lower, &c.to_ascii_lowercase()), c))
        .filter(|(d, _)| *d <= 2.max(lower.len() / 4))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// A constant integer from an expression (literals, negation).
fn const_int(e: &Expr) -> Option<i64> {
    match &e.kind {
        ExprKind::Lit(Lit::Int(v, _)) => Some(*v),
        ExprKind::Unary(AUn::Neg, a) => const_int(a).map(|v| -v),
        _ => None,
    }
}

/// The user types and POUs of a file, by lower-case name.
struct Types<'a> {
    aliases: HashMap<String, &'a ast::TypeDecl>,
    /// FUNCTIONs and FUNCTION_BLOCKs.
    pous: HashMap<String, &'a Pou>,
    /// Every enumerated type declared in a `TYPE` block.
    enums: Vec<Rc<EnumTy>>,
}

/// The types and POUs `file` sees: its own, then those of `library` (the
/// other `.st` files of the project) that it does not declare itself.
fn types_of<'a>(file: &'a ast::File, library: &[&'a ast::File]) -> Types<'a> {
    let mut t = Types {
        aliases: HashMap::new(),
        pous: HashMap::new(),
        enums: Vec::new(),
    };
    for f in std::iter::once(file).chain(library.iter().copied()) {
        for d in &f.types {
            t.aliases.entry(d.name.name.to_ascii_lowercase()).or_insert(d);
        }
        for p in f.pous.iter().filter(|p| p.kind != PouKind::Program) {
            t.pous.entry(p.name.name.to_ascii_lowercase()).or_insert(p);
        }
    }
    let mut enums = Vec::new();
    for d in t.aliases.values() {
        if let TypeRef::Enum { .. } = d.ty
            && let Ok(Ty::Enum(e)) = resolve_named(&d.ty, &d.name.name, &t, 0)
        {
            enums.push(((d.span.file.0, d.span.start), e));
        }
    }
    // In declaration order (the first file's first), whatever the map's order.
    enums.sort_by_key(|(at, _)| *at);
    t.enums = enums.into_iter().map(|(_, e)| e).collect();
    t
}

/// The type a declaration names, or why it cannot be used.
fn resolve_type(t: &TypeRef, types: &Types, depth: u32) -> R<Ty> {
    resolve_named(t, "STRUCT", types, depth)
}

/// An enumerated type's values, numbered from 0 or from the value given.
fn enum_values(values: &[(Ident, Option<Expr>)]) -> R<Vec<(String, i64)>> {
    let mut out: Vec<(String, i64)> = Vec::new();
    let mut next = 0i64;
    for (n, e) in values {
        let v = match e {
            None => next,
            Some(e) => {
                const_int(e).ok_or_else(|| decl_error(e.span, "an enumeration value is an integer literal".into()))?
            }
        };
        if out.iter().any(|(m, _)| m.eq_ignore_ascii_case(&n.name)) {
            return Err(decl_error(n.span, format!("`{}` is listed twice", n.name)));
        }
        if i32::try_from(v).is_err() {
            return Err(decl_error(n.span, format!("{v} does not fit a DINT")));
        }
        out.push((n.name.clone(), v));
        next = v + 1;
    }
    Ok(out)
}

/// [`resolve_type`], `name` naming a STRUCT or enumeration declared in `TYPE`.
fn resolve_named(t: &TypeRef, name: &str, types: &Types, depth: u32) -> R<Ty> {
    if depth > 16 {
        return Err(decl_error(
            t.span(),
            format!("the type `{name}` is defined in terms of itself"),
        ));
    }
    match t {
        TypeRef::Named(n) => {
            if let Some(ty) = elementary(&n.name) {
                return Ok(ty);
            }
            if let Some(fb) = Fb::from_name(&n.name) {
                return Ok(Ty::Fb(fb));
            }
            let key = n.name.to_ascii_lowercase();
            if let Some(alias) = types.aliases.get(&key) {
                return resolve_named(&alias.ty, &alias.name.name, types, depth + 1);
            }
            if let Some(p) = types.pous.get(&key) {
                if p.kind == PouKind::FunctionBlock {
                    return Ok(Ty::User(p.name.name.clone()));
                }
                return Err(decl_error(n.span, format!("`{}` is a FUNCTION, not a type", n.name)));
            }
            if UNSUPPORTED_TYPES.iter().any(|u| n.is(u)) {
                return Err(not_supported(
                    n.span,
                    format!(
                        "the type {} is not supported by the engine yet",
                        n.name.to_ascii_uppercase()
                    ),
                ));
            }
            let known = [
                "BOOL", "SINT", "INT", "DINT", "LINT", "REAL", "LREAL", "TIME", "USINT", "UINT", "UDINT", "ULINT",
                "BYTE", "WORD", "DWORD", "LWORD", "TON", "TOF", "TP", "CTU", "CTD", "CTUD", "R_TRIG", "F_TRIG", "SR",
                "RS",
            ];
            let user: Vec<&str> = types
                .aliases
                .values()
                .map(|t| t.name.name.as_str())
                .chain(types.pous.values().map(|p| p.name.name.as_str()))
                .collect();
            let mut d = Diagnostic::new(Code::StName, format!("unknown type `{}`", n.name), n.span, "type");
            if let Some(s) = closest(&n.name, known.into_iter().chain(user)) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            Err(d)
        }
        TypeRef::String { span, .. } => Err(not_supported(
            *span,
            "STRING and WSTRING are not supported by the engine yet".into(),
        )),
        TypeRef::Struct { members, span } => {
            let mut out: Vec<(String, Ty, Option<Init>)> = Vec::new();
            for d in members {
                let ty = resolve_type(&d.ty, types, depth + 1)?;
                if matches!(ty, Ty::Fb(_) | Ty::User(_)) {
                    return Err(not_supported(
                        d.ty.span(),
                        "function block instances inside a STRUCT are not supported yet".into(),
                    ));
                }
                for n in &d.names {
                    if out.iter().any(|(m, ..)| m.eq_ignore_ascii_case(&n.name)) {
                        return Err(decl_error(n.span, format!("the member `{}` is declared twice", n.name)));
                    }
                    out.push((n.name.clone(), ty.clone(), d.init.clone()));
                }
            }
            if out.is_empty() {
                return Err(decl_error(*span, "a STRUCT has at least one member".into()));
            }
            Ok(Ty::Struct(Rc::new(StructTy {
                name: name.to_string(),
                members: out,
            })))
        }
        TypeRef::Enum { values, .. } => Ok(Ty::Enum(Rc::new(EnumTy {
            name: if name == "STRUCT" {
                "ENUM".into()
            } else {
                name.to_string()
            },
            values: enum_values(values)?,
        }))),
        TypeRef::Subrange { base, lo, hi, span } => {
            let b = elementary(&base.name).filter(Ty::is_int).ok_or_else(|| {
                type_error(
                    base.span,
                    format!("a subrange is of an integer type, not {}", base.name),
                )
            })?;
            let (Some(l), Some(h)) = (const_int(lo), const_int(hi)) else {
                return Err(decl_error(*span, "subrange bounds are integer literals".into()));
            };
            if l > h || !fits(l, &b) || !fits(h, &b) {
                return Err(decl_error(
                    *span,
                    format!("the range {l}..{h} is empty or does not fit a {b}"),
                ));
            }
            Ok(Ty::Sub(Box::new(b), l, h))
        }
        TypeRef::Array { dims, of, span } => {
            let of = resolve_type(of, types, depth + 1)?;
            if matches!(of, Ty::Array(..)) {
                return Err(not_supported(*span, format!("arrays of {of} are not supported yet")));
            }
            let mut out = Vec::new();
            for (lo, hi) in dims {
                let (Some(l), Some(h)) = (const_int(lo), const_int(hi)) else {
                    return Err(decl_error(
                        lo.span.to(hi.span),
                        "array bounds are integer literals".into(),
                    ));
                };
                if l > h {
                    return Err(decl_error(
                        lo.span.to(hi.span),
                        format!("the low bound {l} is above the high bound {h}"),
                    ));
                }
                out.push((l, h));
            }
            let ty = Ty::Array(Box::new(of), out);
            let n = ty.elements();
            if !(1..=MAX_ELEMENTS).contains(&n) {
                return Err(decl_error(
                    *span,
                    format!("an array has at most {MAX_ELEMENTS} elements (this one {n})"),
                ));
            }
            Ok(ty)
        }
    }
}

/// The elements of an array in order, as index suffixes (`[1]`, `[1,2]`).
fn element_suffixes(dims: &[(i64, i64)]) -> Vec<String> {
    let mut out = vec![String::new()];
    for (k, (lo, hi)) in dims.iter().enumerate() {
        let mut next = Vec::new();
        for prefix in &out {
            for i in *lo..=*hi {
                next.push(if k == 0 {
                    format!("{i}")
                } else {
                    format!("{prefix},{i}")
                });
            }
        }
        out = next;
    }
    out.into_iter().map(|s| format!("[{s}]")).collect()
}

/// The value of a literal initial value as `ty`.
fn literal_value(e: &Expr, ty: &Ty) -> R<Value> {
    let bad = || {
        type_error(
            e.span,
            format!("the initial value `{}` is not {} literal", ast::expr(e), an(ty)),
        )
    };
    let int = |v: i64| -> R<Value> {
        if !fits(v, ty) {
            return Err(bad());
        }
        Ok(match ty.data_type() {
            Some(DataType::Sint) => Value::Sint(v as i8),
            Some(DataType::Int) => Value::Int(v as i16),
            Some(DataType::Dint) => Value::Dint(v as i32),
            _ => Value::Lint(v),
        })
    };
    let v = match (&e.kind, ty) {
        (ExprKind::Lit(Lit::Bool(b)), Ty::Bool) => Value::Bool(*b),
        (ExprKind::Lit(Lit::Time(ms)), Ty::Time) => Value::Time(i32::try_from(*ms).map_err(|_| bad())?),
        (ExprKind::Lit(Lit::Int(v, _)), Ty::Real) => Value::Real(*v as f32),
        (ExprKind::Lit(Lit::Int(v, _)), Ty::Lreal) => Value::Lreal(*v as f64),
        (ExprKind::Lit(Lit::Int(v, _)), t) if t.is_int() || t.is_bits() || matches!(t, Ty::Sub(..)) => int(*v)?,
        (ExprKind::Unary(AUn::Neg, _), t) if t.is_int() || matches!(t, Ty::Sub(..)) => {
            int(const_int(e).ok_or_else(bad)?)?
        }
        (ExprKind::Lit(Lit::Real(v, _)), Ty::Real) => Value::Real(*v as f32),
        (ExprKind::Lit(Lit::Real(v, _)), Ty::Lreal) => Value::Lreal(*v),
        (ExprKind::Name(n), Ty::Enum(en)) => Value::Dint(enum_value(en, &n.name).ok_or_else(bad)? as i32),
        (ExprKind::Lit(Lit::Other(t, n)), Ty::Enum(en)) if t.eq_ignore_ascii_case(&en.name) => {
            Value::Dint(enum_value(en, n).ok_or_else(bad)? as i32)
        }
        _ => return Err(bad()),
    };
    Ok(v)
}

fn enum_value(en: &EnumTy, name: &str) -> Option<i64> {
    en.values
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, v)| *v)
}

/// The initial value of a variable of `ty` given none (a subrange's low
/// bound, an enumeration's first value).
fn default_value(ty: &Ty) -> Option<Value> {
    match ty {
        Ty::Sub(_, lo, _) if *lo != 0 => literal_value(
            &Expr {
                kind: ExprKind::Lit(Lit::Int(*lo, None)),
                span: Span::new(alba_diag::FileId(0), 0..0),
            },
            ty,
        )
        .ok(),
        Ty::Enum(e) => e.values.first().map(|(_, v)| Value::Dint(*v as i32)),
        _ => None,
    }
}

fn plain_tag(name: String, ty: DataType, initial: Option<Value>, retain: bool, description: String, span: Span) -> Tag {
    Tag {
        name,
        ty,
        address: None,
        address_text: None,
        initial,
        members: Vec::new(),
        retain,
        description,
        span,
    }
}

/// One declared variable of a POU.
#[derive(Debug, Clone)]
struct Var {
    ty: Ty,
    /// Its tag's name (its elements' names add `[i]`).
    tag: String,
    kind: VarKind,
    retain: bool,
    constant: bool,
    init: Option<Init>,
    span: Span,
}

/// The variables of `pou` (or of the file's `VAR_GLOBAL`s, prefix `None`),
/// by lower-case name, with the errors of their declarations.
fn variables(
    blocks: &[ast::VarBlock],
    prefix: Option<&str>,
    types: &Types,
    diags: &mut Vec<Diagnostic>,
) -> Vec<(String, Var)> {
    let mut out: Vec<(String, Var)> = Vec::new();
    for b in blocks {
        for d in &b.vars {
            let ty = match resolve_type(&d.ty, types, 0) {
                Ok(t) => t,
                Err(e) => {
                    diags.push(e);
                    continue;
                }
            };
            if let Some((_, span)) = &d.at {
                diags.push(not_supported(
                    *span,
                    "`AT` addresses are not supported yet: give the tag its address in tags.csv".into(),
                ));
            }
            for n in &d.names {
                let key = n.name.to_ascii_lowercase();
                if let Some((_, prev)) = out.iter().find(|(k, _)| *k == key) {
                    diags.push(
                        decl_error(n.span, format!("`{}` is declared twice", n.name))
                            .with_note(prev.span, "first declared here"),
                    );
                    continue;
                }
                let global = matches!(b.kind, VarKind::Global | VarKind::External) || prefix.is_none();
                let tag = match prefix {
                    Some(p) if !global => format!("{p}.{}", n.name),
                    _ => n.name.clone(),
                };
                out.push((
                    key,
                    Var {
                        ty: ty.clone(),
                        tag,
                        kind: b.kind,
                        retain: b.retain,
                        constant: b.constant,
                        init: d.init.clone(),
                        span: n.span,
                    },
                ));
            }
        }
    }
    out
}

/// Where tags are declared, and the types they may name.
struct Decl<'t, 'a> {
    types: &'t Types<'a>,
    tags: &'t mut TagTable,
    diags: &'t mut Vec<Diagnostic>,
    /// Tags declared for instances of user FUNCTION_BLOCKs.
    instance_tags: usize,
    /// The FUNCTION_BLOCKs whose instance is being declared (lower-case).
    open: Vec<String>,
}

impl Decl<'_, '_> {
    /// Adds the tags of a variable of type `ty` named `tag`.
    fn var(&mut self, tag: &str, ty: &Ty, init: Option<&Init>, retain: bool, span: Span, depth: u32) {
        if let Some(t) = self.tags.get(tag) {
            self.diags.push(
                decl_error(span, format!("the variable's tag `{tag}` already exists"))
                    .with_note(t.span, "declared here"),
            );
            return;
        }
        let desc = "Structured Text variable".to_string();
        let plain = |name: String, dt, init| plain_tag(name, dt, init, retain, desc.clone(), span);
        match ty {
            Ty::Fb(fb) => match fb {
                Fb::Ton | Fb::Tof | Fb::Tp => self.tags.push(plain(tag.to_string(), DataType::Timer, None)),
                Fb::Ctu | Fb::Ctd | Fb::Ctud => self.tags.push(plain(tag.to_string(), DataType::Counter, None)),
                Fb::RTrig | Fb::FTrig => {
                    for m in ["Q", "M"] {
                        self.tags.push(plain(format!("{tag}.{m}"), DataType::Bool, None));
                    }
                }
                Fb::Sr | Fb::Rs => self.tags.push(plain(format!("{tag}.Q1"), DataType::Bool, None)),
            },
            Ty::User(name) => {
                let key = name.to_ascii_lowercase();
                if self.open.contains(&key) || depth > 32 {
                    self.diags.push(decl_error(
                        span,
                        format!("the FUNCTION_BLOCK `{name}` contains an instance of itself"),
                    ));
                    return;
                }
                let Some(pou) = self.types.pous.get(&name.to_ascii_lowercase()) else {
                    return;
                };
                if self.instance_tags > MAX_INSTANCE_TAGS {
                    self.diags.push(decl_error(
                        span,
                        format!("the instances of function blocks pass {MAX_INSTANCE_TAGS} tags"),
                    ));
                    return;
                }
                // `c : Counter := (step := 2)` sets the initial values of inputs.
                let given = match init {
                    Some(Init::Struct(items, _)) => items.as_slice(),
                    Some(Init::Array(_, span)) => {
                        self.diags
                            .push(type_error(*span, format!("a {name} takes `(input := value, …)`")));
                        &[]
                    }
                    Some(Init::Expr(e)) => {
                        self.diags
                            .push(type_error(e.span, format!("a {name} takes `(input := value, …)`")));
                        &[]
                    }
                    None => &[],
                };
                let vars = variables(&pou.vars, Some(tag), self.types, &mut Vec::new());
                for (n, _) in given {
                    let ok = vars
                        .iter()
                        .any(|(k, v)| n.is(k) && matches!(v.kind, VarKind::Input | VarKind::Output | VarKind::Var));
                    if !ok {
                        self.diags.push(Diagnostic::new(
                            Code::StName,
                            format!("{name} has no variable `{}` to initialise", n.name),
                            n.span,
                            "initial value",
                        ));
                    }
                }
                self.open.push(key);
                for (key, v) in vars {
                    if matches!(v.kind, VarKind::InOut | VarKind::External | VarKind::Global) {
                        continue;
                    }
                    let before = self.tags.len();
                    let i = given
                        .iter()
                        .find(|(n, _)| n.is(&key))
                        .map(|(_, i)| i)
                        .or(v.init.as_ref());
                    self.var(&v.tag, &v.ty, i, retain || v.retain, v.span, depth + 1);
                    self.instance_tags += self.tags.len() - before;
                }
                self.open.pop();
            }
            Ty::Struct(s) => {
                let given = match init {
                    Some(Init::Struct(items, _)) => items.as_slice(),
                    Some(Init::Array(_, span)) => {
                        self.diags
                            .push(type_error(*span, format!("a {} takes `(member := value, …)`", s.name)));
                        &[]
                    }
                    Some(Init::Expr(e)) => {
                        self.diags
                            .push(type_error(e.span, format!("a {} takes `(member := value, …)`", s.name)));
                        &[]
                    }
                    None => &[],
                };
                for (n, _) in given {
                    if !s.members.iter().any(|(m, ..)| n.is(m)) {
                        let mut d = Diagnostic::new(
                            Code::StName,
                            format!("{} has no member `{}`", s.name, n.name),
                            n.span,
                            "member",
                        );
                        if let Some(c) = closest(&n.name, s.members.iter().map(|(m, ..)| m.as_str())) {
                            d = d.with_help(format!("did you mean `{c}`?"));
                        }
                        self.diags.push(d);
                    }
                }
                for (m, mty, minit) in &s.members {
                    let i = given.iter().find(|(n, _)| n.is(m)).map(|(_, i)| i).or(minit.as_ref());
                    self.var(&format!("{tag}.{m}"), mty, i, retain, span, depth + 1);
                }
            }
            Ty::Array(of, dims) if matches!(**of, Ty::Struct(_) | Ty::Fb(_) | Ty::User(_)) => {
                let suffixes = element_suffixes(dims);
                let mut inits: Vec<Option<&Init>> = vec![None; suffixes.len()];
                if let Some(Init::Array(items, _)) = init {
                    let mut k = 0usize;
                    for (count, item) in items {
                        let n = count.as_ref().and_then(const_int).unwrap_or(1).max(0) as usize;
                        for _ in 0..n {
                            if let Some(slot) = inits.get_mut(k) {
                                *slot = Some(item);
                            }
                            k += 1;
                        }
                    }
                    if k > inits.len() {
                        self.diags.push(decl_error(
                            span,
                            format!("more initial values than the {} elements", inits.len()),
                        ));
                    }
                }
                for (s, i) in suffixes.iter().zip(inits) {
                    self.var(&format!("{tag}{s}"), of, i, retain, span, depth + 1);
                }
            }
            Ty::Array(of, dims) => {
                let Some(dt) = of.data_type() else { return };
                let suffixes = element_suffixes(dims);
                let mut inits: Vec<Option<Value>> = vec![default_value(of); suffixes.len()];
                match init {
                    None => {}
                    Some(Init::Array(items, span)) => {
                        let mut k = 0usize;
                        for (count, item) in items {
                            let n = match count {
                                None => 1,
                                Some(c) => match const_int(c) {
                                    Some(n) if n >= 0 => n as usize,
                                    _ => {
                                        self.diags
                                            .push(decl_error(c.span, "a repeat count is a literal integer ≥ 0".into()));
                                        return;
                                    }
                                },
                            };
                            let Init::Expr(e) = item else {
                                self.diags.push(decl_error(
                                    *span,
                                    "an array element's initial value is a literal".into(),
                                ));
                                return;
                            };
                            let val = match literal_value(e, of) {
                                Ok(x) => x,
                                Err(d) => {
                                    self.diags.push(d);
                                    return;
                                }
                            };
                            for _ in 0..n {
                                if k >= inits.len() {
                                    self.diags.push(decl_error(
                                        *span,
                                        format!("more initial values than the {} elements", inits.len()),
                                    ));
                                    return;
                                }
                                inits[k] = Some(val);
                                k += 1;
                            }
                        }
                    }
                    Some(Init::Expr(e)) => {
                        self.diags.push(type_error(
                            e.span,
                            "an array's initial value is a list `[1, 2, 3]`".into(),
                        ));
                    }
                    Some(Init::Struct(_, span)) => self.diags.push(type_error(
                        *span,
                        "an array's initial value is a list `[1, 2, 3]`".into(),
                    )),
                }
                for (s, init) in suffixes.into_iter().zip(inits) {
                    self.tags.push(plain(format!("{tag}{s}"), dt, init));
                }
            }
            ty => {
                let Some(dt) = ty.data_type() else { return };
                let init = match init {
                    None => default_value(ty),
                    Some(Init::Expr(e)) => match literal_value(e, ty) {
                        Ok(x) => Some(x),
                        Err(d) => {
                            self.diags.push(d);
                            None
                        }
                    },
                    Some(Init::Array(_, span) | Init::Struct(_, span)) => {
                        self.diags.push(type_error(*span, format!("a {ty} takes one value")));
                        None
                    }
                };
                self.tags.push(plain(tag.to_string(), dt, init));
            }
        }
    }
}

/// Adds the tags of every PROGRAM's variables (with the instances of user
/// FUNCTION_BLOCKs, member by member) and of the `VAR_GLOBAL`s of `file` to
/// `tags` (before the layout is made).
pub fn declare(file: &ast::File, tags: &mut TagTable, diags: &mut Vec<Diagnostic>) {
    declare_with(file, &[], tags, diags);
}

/// [`declare`], with the FUNCTIONs, FUNCTION_BLOCKs and TYPEs of the other
/// `.st` files of the project (`library`) known as well.
pub fn declare_with(file: &ast::File, library: &[&ast::File], tags: &mut TagTable, diags: &mut Vec<Diagnostic>) {
    let types = types_of(file, library);
    for p in file.pous.iter().filter(|p| p.kind != PouKind::Program) {
        let key = p.name.name.to_ascii_lowercase();
        if let Some(other) = library
            .iter()
            .flat_map(|f| f.pous.iter())
            .find(|o| o.kind != PouKind::Program && o.name.name.to_ascii_lowercase() == key)
        {
            diags.push(
                decl_error(
                    p.name.span,
                    format!("`{}` is declared in another file too", p.name.name),
                )
                .with_note(other.name.span, "also declared here"),
            );
        }
    }
    for t in &file.types {
        if let Err(e) = resolve_named(&t.ty, &t.name.name, &types, 0) {
            diags.push(e);
        }
    }
    let mut vars = Vec::new();
    for g in &file.globals {
        vars.extend(variables(std::slice::from_ref(g), None, &types, diags));
    }
    for p in &file.pous {
        if p.kind != PouKind::Program {
            // Declaration errors of FUNCTIONs and FUNCTION_BLOCKs, once.
            variables(&p.vars, Some(&p.name.name), &types, diags);
            continue;
        }
        for (_, v) in variables(&p.vars, Some(&p.name.name), &types, diags) {
            if v.kind != VarKind::External {
                vars.push((String::new(), v));
            }
        }
    }
    let mut d = Decl {
        types: &types,
        tags,
        diags,
        instance_tags: 0,
        open: Vec::new(),
    };
    for (_, v) in vars {
        d.var(&v.tag, &v.ty, v.init.as_ref(), v.retain, v.span, 0);
    }
}

/// What computes the value of an assignment, given the type wanted.
type ValueOf<'f, L> = dyn FnMut(&mut L, Option<&Ty>) -> R<(Val, Ty)> + 'f;

/// A value read into a slot.
#[derive(Debug, Clone, Copy)]
enum Val {
    B(B),
    N(V),
}

/// Where a name or member lives.
#[derive(Debug, Clone)]
enum Loc {
    Value {
        place: Place,
        access: Access,
        ty: Ty,
        constant: bool,
    },
    /// An array: its element places in order.
    Array {
        elems: Vec<Place>,
        ty: Ty,
        of: Ty,
        dims: Vec<(i64, i64)>,
    },
    Fb {
        kind: Fb,
        name: String,
    },
    /// Q (QU) of a counter: CV >= PV; with `down`, Q (QD): CV <= 0.
    CounterQ {
        c: Ctr,
        down: bool,
    },
    /// An instance of a user FUNCTION_BLOCK: its tags start with `prefix.`.
    User {
        fb: String,
        prefix: String,
    },
    Struct {
        ty: Rc<StructTy>,
        members: Vec<(String, Loc)>,
    },
    /// A value of an enumerated type, by name.
    EnumConst(Rc<EnumTy>, i64),
    /// An array of structures: each element's location, in order.
    StructArray {
        ty: Ty,
        elems: Rc<Vec<Loc>>,
        dims: Vec<(i64, i64)>,
    },
    /// Bit `bit` of an integer or bit string (`x.3`).
    Bit {
        place: Place,
        access: Access,
        ty: Ty,
        bit: u32,
        constant: bool,
    },
}

struct LoopLabels {
    exits: Vec<u32>,
}

/// Most nested calls of user FUNCTIONs and FUNCTION_BLOCKs (each is inlined).
const MAX_CALL_DEPTH: usize = 16;
/// Most operations of a program before one more call is inlined.
const MAX_OPS: u32 = 4_000_000;
/// Most tags the instances of user FUNCTION_BLOCKs of a file may declare.
const MAX_INSTANCE_TAGS: usize = 200_000;

struct Lower<'a> {
    b: &'a mut Builder,
    types: &'a Types<'a>,
    /// `VAR_GLOBAL`s of the file.
    globals: HashMap<String, Var>,
    vars: HashMap<String, Var>,
    /// Names bound to storage that is not a tag of their own: VAR_IN_OUT
    /// parameters and the variables of a FUNCTION being inlined.
    aliases: HashMap<String, Loc>,
    diags: Vec<Diagnostic>,
    elem: u32,
    rungs: u32,
    loops: Vec<LoopLabels>,
    returns: Vec<u32>,
    pou: String,
    /// The user POUs being inlined (lower-case), innermost last.
    stack: Vec<String>,
    /// User POUs inlined at least once (lower-case).
    called: HashSet<String>,
    /// Element places of the arrays met so far, by tag.
    arrays: HashMap<String, Vec<Place>>,
    /// Structures and arrays of structures or instances met so far, by tag.
    composites: HashMap<(String, bool), Loc>,
}

/// The scope of one POU body, saved while another is inlined.
struct Scope {
    vars: HashMap<String, Var>,
    aliases: HashMap<String, Loc>,
    loops: Vec<LoopLabels>,
    returns: Vec<u32>,
    pou: String,
}

/// Lowers the PROGRAMs of `file`, in order, as unit `name`. User FUNCTIONs
/// and FUNCTION_BLOCKs are inlined where they are called; the bodies of
/// those never called are checked on their own.
pub fn compile(file: &ast::File, name: &str, b: &mut Builder) -> Vec<Diagnostic> {
    compile_with(file, &[], name, b)
}

/// [`compile`], with the FUNCTIONs, FUNCTION_BLOCKs and TYPEs of the other
/// `.st` files of the project (`library`) callable and usable as well.
pub fn compile_with(file: &ast::File, library: &[&ast::File], name: &str, b: &mut Builder) -> Vec<Diagnostic> {
    let types = types_of(file, library);
    let mut diags = Vec::new();
    let globals: HashMap<String, Var> = variables(&file.globals, None, &types, &mut Vec::new())
        .into_iter()
        .collect();
    b.begin_unit(name);
    let mut rungs = 0;
    let mut called = HashSet::new();
    for p in &file.pous {
        if p.kind != PouKind::Program {
            continue;
        }
        let mut vars = globals.clone();
        vars.extend(variables(&p.vars, Some(&p.name.name), &types, &mut Vec::new()));
        let mut l = Lower::new(b, &types, globals.clone(), vars, rungs, &p.name.name);
        l.program(p);
        rungs = l.rungs;
        diags.extend(l.diags);
        called.extend(l.called);
    }
    b.end_unit();
    for p in &file.pous {
        if p.kind != PouKind::Program && !called.contains(&p.name.name.to_ascii_lowercase()) {
            diags.extend(check_alone(p, &types, &globals, b.layout()));
        }
    }
    // A body inlined at several places reports its errors once.
    let mut seen = HashSet::new();
    diags.retain(|d| {
        seen.insert(format!(
            "{:?}{}{:?}",
            d.code,
            d.message,
            d.primary.as_ref().map(|l| l.span)
        ))
    });
    diags
}

/// The errors of the body of a FUNCTION or FUNCTION_BLOCK that is never
/// called, lowered on its own (an FB as an instance of its own).
fn check_alone(p: &Pou, types: &Types, globals: &HashMap<String, Var>, layout: &alba_ir::Layout) -> Vec<Diagnostic> {
    let mut tags = layout.tags.clone();
    let mut diags = Vec::new();
    let inst = format!("{}#check", p.name.name);
    {
        let mut d = Decl {
            types,
            tags: &mut tags,
            diags: &mut diags,
            instance_tags: 0,
            open: Vec::new(),
        };
        let prefix = if p.kind == PouKind::FunctionBlock {
            d.var(&inst, &Ty::User(p.name.name.clone()), None, false, p.name.span, 0);
            &inst
        } else {
            &p.name.name
        };
        // Instances given as VAR_IN_OUT: scratch ones.
        for (_, v) in variables(&p.vars, Some(prefix), types, &mut Vec::new()) {
            if v.kind == VarKind::InOut && matches!(v.ty, Ty::Fb(_) | Ty::User(_)) {
                d.var(&format!("{}#io", v.tag), &v.ty, None, false, v.span, 0);
            }
        }
    }
    let mut b = Builder::new(alba_ir::Layout::new(&tags, &Default::default()));
    b.begin_unit("check");
    let mut l = Lower::new(&mut b, types, globals.clone(), globals.clone(), 0, &p.name.name);
    l.rung(p.name.span);
    let r = if p.kind == PouKind::FunctionBlock {
        l.inline_fb(p, &inst, &[], p.name.span, true)
    } else {
        l.inline_function(p, &[], p.name.span, true).map(|_| ())
    };
    if let Err(d) = r {
        l.diags.push(d);
    }
    diags.extend(l.diags);
    diags
}

impl<'a> Lower<'a> {
    fn new(
        b: &'a mut Builder,
        types: &'a Types<'a>,
        globals: HashMap<String, Var>,
        vars: HashMap<String, Var>,
        rungs: u32,
        pou: &str,
    ) -> Lower<'a> {
        Lower {
            b,
            types,
            globals,
            vars,
            aliases: HashMap::new(),
            diags: Vec::new(),
            elem: NO_ELEM,
            rungs,
            loops: Vec::new(),
            returns: Vec::new(),
            pou: pou.to_string(),
            stack: Vec::new(),
            called: HashSet::new(),
            arrays: HashMap::new(),
            composites: HashMap::new(),
        }
    }
}

impl Lower<'_> {
    fn emit(&mut self, op: Op) -> u32 {
        self.b.emit(op, self.elem)
    }

    fn rung(&mut self, span: Span) -> u32 {
        let at = self.b.here();
        self.b.begin_rung(self.rungs, span);
        self.rungs += 1;
        self.elem = self.b.element(span);
        at
    }

    fn patch(&mut self, jumps: &[u32], target: u32) {
        for j in jumps {
            self.b.patch_jump(*j, target);
        }
    }

    /// Checks the VAR_EXTERNALs of the scope against the globals.
    fn check_externals(&mut self) {
        let mut ext: Vec<Var> = self
            .vars
            .values()
            .filter(|v| v.kind == VarKind::External)
            .cloned()
            .collect();
        ext.sort_by_key(|v| v.span.start);
        for v in ext {
            match self.b.layout().resolve(&v.tag) {
                Err(_) => self.diags.push(Diagnostic::new(
                    Code::StName,
                    format!("`{}` is VAR_EXTERNAL but no tag or VAR_GLOBAL has that name", v.tag),
                    v.span,
                    "external",
                )),
                Ok(Target::Value { place, .. }) if Some(place.data_type()) != v.ty.data_type() => {
                    self.diags.push(type_error(
                        v.span,
                        format!(
                            "`{}` is declared {} here but the global is {}",
                            v.tag,
                            v.ty,
                            place.data_type()
                        ),
                    ))
                }
                Ok(_) => {}
            }
        }
    }

    /// VAR_TEMP starts from its initial value on every execution.
    fn init_temps(&mut self) {
        let mut temps: Vec<_> = self
            .vars
            .values()
            .filter(|v| v.kind == VarKind::Temp)
            .cloned()
            .collect();
        temps.sort_by_key(|v| v.span.start);
        for v in temps {
            let id = Ident {
                name: v.tag.rsplit('.').next().unwrap_or(&v.tag).to_string(),
                span: v.span,
            };
            if let Ok(loc) = self.lookup(&id) {
                self.init_loc(&loc, v.init.as_ref());
            }
        }
    }

    fn program(&mut self, p: &Pou) {
        self.check_externals();
        self.rung(p.name.span);
        self.init_temps();
        self.block(&p.body);
        let end = self.rung(Span::new(p.span.file, p.span.end as usize..p.span.end as usize));
        let returns = std::mem::take(&mut self.returns);
        self.patch(&returns, end);
    }

    /// Stores initial values into storage (a value given, else the type's default).
    fn init_loc(&mut self, loc: &Loc, init: Option<&Init>) {
        match loc {
            Loc::Value { place, ty, .. } => {
                let value = match init {
                    Some(Init::Expr(e)) => literal_value(e, ty).ok(),
                    _ => None,
                }
                .or_else(|| default_value(ty))
                .or_else(|| ty.data_type().and_then(Value::zero));
                if let Some(value) = value {
                    let _ = self.store_const(*place, value);
                }
            }
            Loc::Array { elems, of, .. } => {
                let mut vals: Vec<Option<Value>> = vec![None; elems.len()];
                if let Some(Init::Array(items, _)) = init {
                    let mut k = 0;
                    for (count, item) in items {
                        let n = count.as_ref().and_then(const_int).unwrap_or(1).max(0) as usize;
                        let v = match item {
                            Init::Expr(e) => literal_value(e, of).ok(),
                            _ => None,
                        };
                        for _ in 0..n {
                            if k < vals.len() {
                                vals[k] = v;
                            }
                            k += 1;
                        }
                    }
                }
                let elems = elems.clone();
                for (p, v) in elems.into_iter().zip(vals) {
                    let v = v
                        .or_else(|| default_value(of))
                        .or_else(|| of.data_type().and_then(Value::zero));
                    if let Some(v) = v {
                        let _ = self.store_const(p, v);
                    }
                }
            }
            Loc::StructArray { elems, .. } => {
                let mut inits: Vec<Option<&Init>> = vec![None; elems.len()];
                if let Some(Init::Array(items, _)) = init {
                    let mut k = 0usize;
                    for (count, item) in items {
                        let n = count.as_ref().and_then(const_int).unwrap_or(1).max(0) as usize;
                        for _ in 0..n {
                            if let Some(slot) = inits.get_mut(k) {
                                *slot = Some(item);
                            }
                            k += 1;
                        }
                    }
                }
                for (l, i) in elems.clone().iter().zip(inits) {
                    self.init_loc(l, i);
                }
            }
            Loc::Struct { ty, members } => {
                let given = match init {
                    Some(Init::Struct(items, _)) => items.as_slice(),
                    _ => &[],
                };
                for ((m, l), (_, _, minit)) in members.iter().zip(&ty.members) {
                    let i = given.iter().find(|(n, _)| n.is(m)).map(|(_, i)| i).or(minit.as_ref());
                    self.init_loc(l, i);
                }
            }
            _ => {}
        }
    }

    /// Storage in slots of this lowering (no tag) for a variable of a FUNCTION.
    fn temp_storage(&mut self, ty: &Ty, span: Span) -> R<Loc> {
        let slot = |l: &mut Self, t: &Ty| -> Place {
            match t.data_type() {
                Some(DataType::Bool) => Place::Bool(l.b.temp_b()),
                Some(DataType::Real) => Place::Real(l.b.temp_f()),
                Some(DataType::Lreal) => Place::Lreal(l.b.temp_d()),
                Some(DataType::Lint) => Place::Lint(l.b.temp_l()),
                Some(dt) => Place::Int(l.b.temp_i(), dt),
                None => Place::Bool(l.b.temp_b()),
            }
        };
        Ok(match ty {
            Ty::Array(of, dims) if matches!(**of, Ty::Struct(_)) => {
                let mut elems = Vec::new();
                for _ in 0..ty.elements() {
                    elems.push(self.temp_storage(of, span)?);
                }
                Loc::StructArray {
                    ty: ty.clone(),
                    elems: Rc::new(elems),
                    dims: dims.clone(),
                }
            }
            Ty::Array(of, dims) => {
                let elems = (0..ty.elements()).map(|_| slot(self, of)).collect();
                Loc::Array {
                    elems,
                    ty: ty.clone(),
                    of: (**of).clone(),
                    dims: dims.clone(),
                }
            }
            Ty::Struct(s) => {
                let mut members = Vec::new();
                for (m, mty, _) in &s.members {
                    members.push((m.clone(), self.temp_storage(mty, span)?));
                }
                Loc::Struct { ty: s.clone(), members }
            }
            Ty::Fb(_) | Ty::User(_) => {
                return Err(not_supported(
                    span,
                    format!("a FUNCTION has no function block instances ({ty}); use a FUNCTION_BLOCK"),
                ));
            }
            t => Loc::Value {
                place: slot(self, t),
                access: Access::ReadWrite,
                ty: t.clone(),
                constant: false,
            },
        })
    }

    fn enter(&mut self, pou: &Pou, vars: HashMap<String, Var>, aliases: HashMap<String, Loc>) -> Scope {
        self.stack.push(pou.name.name.to_ascii_lowercase());
        self.called.insert(pou.name.name.to_ascii_lowercase());
        Scope {
            vars: std::mem::replace(&mut self.vars, vars),
            aliases: std::mem::replace(&mut self.aliases, aliases),
            loops: std::mem::take(&mut self.loops),
            returns: std::mem::take(&mut self.returns),
            pou: std::mem::replace(&mut self.pou, pou.name.name.clone()),
        }
    }

    fn leave(&mut self, s: Scope) {
        self.stack.pop();
        self.vars = s.vars;
        self.aliases = s.aliases;
        self.loops = s.loops;
        self.returns = s.returns;
        self.pou = s.pou;
    }

    /// Refuses a call that would inline `pou` inside itself.
    fn check_recursion(&self, pou: &Pou, at: Span) -> R<()> {
        let key = pou.name.name.to_ascii_lowercase();
        if self.stack.contains(&key) {
            let mut chain = self.stack.clone();
            chain.push(key);
            return Err(Diagnostic::new(
                Code::StNotSupported,
                format!(
                    "`{}` calls itself ({}): calls are inlined, so recursion is not supported",
                    pou.name.name,
                    chain.join(" → ")
                ),
                at,
                "recursive call",
            ));
        }
        if self.b.here() > MAX_OPS {
            return Err(not_supported(
                at,
                format!("the program passes {MAX_OPS} operations with its calls inlined"),
            ));
        }
        if self.stack.len() >= MAX_CALL_DEPTH {
            return Err(not_supported(
                at,
                format!("calls nested deeper than {MAX_CALL_DEPTH} are not supported"),
            ));
        }
        Ok(())
    }

    /// The parameters of a user POU in declaration order: inputs, in-outs
    /// and outputs (positional arguments bind inputs and in-outs in order).
    fn params_of(vars: &[(String, Var)]) -> Vec<(String, Var)> {
        vars.iter()
            .filter(|(_, v)| matches!(v.kind, VarKind::Input | VarKind::InOut | VarKind::Output))
            .cloned()
            .collect()
    }

    /// Binds the arguments of a call to a user POU: the input values and
    /// in-out storage (evaluated in the caller's scope), and the `=>` outputs.
    #[allow(clippy::type_complexity)]
    fn bind_user<'e>(
        &mut self,
        pou: &Pou,
        params: &[(String, Var)],
        args: &'e [Arg],
        span: Span,
        check: bool,
    ) -> R<(Vec<(String, Given)>, HashMap<String, Loc>, Vec<(String, &'e Arg)>)> {
        let fname = &pou.name.name;
        let positional: Vec<&(String, Var)> = params.iter().filter(|(_, v)| v.kind != VarKind::Output).collect();
        let mut given: Vec<(String, &Expr, Span)> = Vec::new();
        let mut outs = Vec::new();
        for (k, a) in args.iter().enumerate() {
            let key = match &a.name {
                None => match positional.get(k) {
                    Some((key, _)) => key.clone(),
                    None => {
                        return Err(type_error(
                            a.value.span,
                            format!("{fname} takes {} positional argument(s)", positional.len()),
                        ));
                    }
                },
                Some(n) => {
                    let key = n.name.to_ascii_lowercase();
                    let want = if a.output { "output" } else { "input" };
                    let ok = params
                        .iter()
                        .any(|(k, v)| *k == key && ((v.kind == VarKind::Output) == a.output));
                    if !ok {
                        let names: Vec<&str> = params
                            .iter()
                            .filter(|(_, v)| (v.kind == VarKind::Output) == a.output)
                            .map(|(_, v)| v.tag.rsplit('.').next().unwrap_or(&v.tag))
                            .collect();
                        let mut d = Diagnostic::new(
                            Code::StName,
                            format!("{fname} has no {want} `{}`", n.name),
                            n.span,
                            want,
                        );
                        d = d.with_help(match closest(&n.name, names.iter().copied()) {
                            Some(s) => format!("did you mean `{s}`?"),
                            None if names.is_empty() => format!("{fname} has no {want}s"),
                            None => format!("its {want}s: {}", names.join(", ")),
                        });
                        return Err(d);
                    }
                    key
                }
            };
            if a.output {
                outs.push((key, a));
                continue;
            }
            if given.iter().any(|(k, ..)| *k == key) {
                return Err(type_error(a.value.span, format!("`{key}` is given twice")));
            }
            given.push((key, &a.value, a.value.span));
        }
        let mut inputs = Vec::new();
        let mut inouts = HashMap::new();
        for (key, v) in params {
            let Some((_, e, espan)) = given.iter().find(|(k, ..)| k == key) else {
                if v.kind == VarKind::InOut {
                    if check {
                        // Checking a body alone: FB instances have scratch tags
                        // (see `check_alone`), other types scratch slots.
                        let io = format!("{}#io", v.tag);
                        let loc = match &v.ty {
                            Ty::Fb(_) | Ty::User(_) => self.tag_loc(
                                &io,
                                &v.ty,
                                false,
                                &Ident {
                                    name: key.clone(),
                                    span: v.span,
                                },
                            )?,
                            ty => self.temp_storage(ty, v.span)?,
                        };
                        inouts.insert(key.clone(), loc);
                        continue;
                    }
                    return Err(type_error(
                        span,
                        format!("the VAR_IN_OUT `{key}` of {fname} must be given a variable"),
                    ));
                }
                continue;
            };
            let pname = v.tag.rsplit('.').next().unwrap_or(key);
            if v.kind == VarKind::InOut {
                let loc = match &e.kind {
                    ExprKind::Index(base, ix) => {
                        let (of, elems, dims) = self.array(base)?;
                        match self.flat_index(&dims, ix, *espan)? {
                            Ok(k) => Loc::Value {
                                place: elems[k],
                                access: Access::ReadWrite,
                                ty: of,
                                constant: false,
                            },
                            Err(_) => {
                                return Err(not_supported(
                                    *espan,
                                    "an array element with a computed index as a VAR_IN_OUT argument".into(),
                                ));
                            }
                        }
                    }
                    _ => self.locate(e)?,
                };
                let lty = loc_type(&loc);
                if lty.as_ref() != Some(&v.ty) {
                    return Err(type_error(
                        *espan,
                        format!(
                            "{fname}.{pname} is a VAR_IN_OUT {}; `{}` is {}",
                            v.ty,
                            ast::expr(e),
                            lty.map_or("not a variable".to_string(), |t| an(&t))
                        ),
                    ));
                }
                if let Loc::Value { access, constant, .. } = &loc
                    && (*access != Access::ReadWrite || *constant)
                {
                    return Err(Diagnostic::new(
                        Code::NotWritable,
                        format!("`{}` cannot be written, so it is no VAR_IN_OUT argument", ast::expr(e)),
                        *espan,
                        "not writable",
                    ));
                }
                inouts.insert(key.clone(), loc);
                continue;
            }
            if let Ty::Struct(_) | Ty::Array(..) = v.ty {
                let src = self.locate(e)?;
                if loc_type(&src).as_ref() != Some(&v.ty) {
                    return Err(type_error(*espan, format!("{fname}.{pname} is {}", an(&v.ty))));
                }
                inputs.push((key.clone(), Given::Copy(src)));
                continue;
            }
            let want = v.ty.value();
            let (val, vty) = self.eval(e, Some(&want))?;
            if !widens(&vty, &v.ty) {
                return Err(type_error(
                    *espan,
                    format!("{fname}.{pname} is {}, not {}", an(&v.ty), an(&vty)),
                ));
            }
            let val = match val {
                Val::N(x) => Val::N(self.b.convert(x, v.ty.class(), self.elem)),
                b => b,
            };
            inputs.push((key.clone(), Given::Val(val)));
        }
        Ok((inputs, inouts, outs))
    }
}

/// An input argument: a value, or a structure to copy.
enum Given {
    Val(Val),
    Copy(Loc),
}

/// The type of what a location holds.
fn loc_type(l: &Loc) -> Option<Ty> {
    match l {
        Loc::Value { ty, .. } | Loc::Array { ty, .. } | Loc::StructArray { ty, .. } => Some(ty.clone()),
        Loc::Fb { kind, .. } => Some(Ty::Fb(*kind)),
        Loc::User { fb, .. } => Some(Ty::User(fb.clone())),
        Loc::Struct { ty, .. } => Some(Ty::Struct(ty.clone())),
        Loc::EnumConst(e, _) => Some(Ty::Enum(e.clone())),
        Loc::CounterQ { .. } | Loc::Bit { .. } => Some(Ty::Bool),
    }
}

impl Lower<'_> {
    /// Inlines a call of the user FUNCTION_BLOCK `pou` on the instance whose
    /// tags start with `prefix` (`check`: lowered only to check its body).
    fn inline_fb(&mut self, pou: &Pou, prefix: &str, args: &[Arg], span: Span, check: bool) -> R<()> {
        self.check_recursion(pou, span)?;
        let vars = variables(&pou.vars, Some(prefix), self.types, &mut Vec::new());
        let params = Self::params_of(&vars);
        let (inputs, inouts, outs) = self.bind_user(pou, &params, args, span, check)?;
        let mut scope = self.globals.clone();
        scope.extend(vars.iter().filter(|(_, v)| v.kind != VarKind::InOut).cloned());
        let saved = self.enter(pou, scope, inouts);
        let r = self.run_body(pou, inputs, span, true);
        self.leave(saved);
        r?;
        for (key, a) in outs {
            let Some((_, v)) = vars.iter().find(|(k, _)| *k == key) else {
                continue;
            };
            let id = Ident {
                name: key.clone(),
                span: a.value.span,
            };
            let src = self.tag_loc(&v.tag, &v.ty, false, &id)?;
            self.assign_output(a, &src)?;
        }
        Ok(())
    }

    /// Inlines a call of the user FUNCTION `pou`: its variables live in
    /// slots of this call; gives its result.
    fn inline_function(&mut self, pou: &Pou, args: &[Arg], span: Span, check: bool) -> R<(Val, Ty)> {
        self.check_recursion(pou, span)?;
        let vars = variables(&pou.vars, Some(&pou.name.name), self.types, &mut Vec::new());
        let params = Self::params_of(&vars);
        let ret = match &pou.ret {
            Some(t) => {
                let t = resolve_type(t, self.types, 0)?;
                if t.data_type().is_none() {
                    return Err(not_supported(
                        pou.ret.as_ref().map_or(pou.name.span, TypeRef::span),
                        format!("a FUNCTION returning {} is not supported yet", an(&t)),
                    ));
                }
                Some(t)
            }
            None => None,
        };
        let (inputs, mut aliases, outs) = self.bind_user(pou, &params, args, span, check)?;
        let mut scope = self.globals.clone();
        for (key, v) in &vars {
            match v.kind {
                VarKind::InOut => {}
                VarKind::External | VarKind::Global => {
                    scope.insert(key.clone(), v.clone());
                }
                _ => {
                    let mut loc = self.temp_storage(&v.ty, v.span)?;
                    self.init_loc(&loc, v.init.as_ref());
                    if let Loc::Value { constant, .. } = &mut loc {
                        *constant = v.constant;
                    }
                    aliases.insert(key.clone(), loc);
                }
            }
        }
        let fkey = pou.name.name.to_ascii_lowercase();
        if let Some(rt) = &ret {
            let loc = self.temp_storage(rt, pou.name.span)?;
            self.init_loc(&loc, None);
            aliases.insert(fkey.clone(), loc);
        }
        let locals = aliases.clone();
        let saved = self.enter(pou, scope, aliases);
        let r = self.run_body(pou, inputs, span, false);
        self.leave(saved);
        r?;
        for (key, a) in outs {
            if let Some(src) = locals.get(&key) {
                self.assign_output(a, src)?;
            }
        }
        match (ret, locals.get(&fkey)) {
            (Some(_), Some(l)) => {
                let e = Expr {
                    kind: ExprKind::Name(pou.name.clone()),
                    span,
                };
                self.read_loc(l, &e)
            }
            _ => Ok((self.constant(&Lit::Bool(false), &Ty::Bool), Ty::Bool)),
        }
    }

    /// The inputs stored, then the body of a user POU, in the scope entered.
    fn run_body(&mut self, pou: &Pou, inputs: Vec<(String, Given)>, span: Span, temps: bool) -> R<()> {
        for (key, g) in inputs {
            let loc = self.lookup(&Ident { name: key, span })?;
            match (g, &loc) {
                (Given::Val(v), Loc::Value { place, ty, .. }) => {
                    let (place, ty) = (*place, ty.clone());
                    self.store_checked(place, v, &ty);
                }
                (Given::Copy(src), _) => self.copy_loc(&loc, &src),
                _ => {}
            }
        }
        self.check_externals();
        if temps {
            self.init_temps();
        }
        self.block(&pou.body);
        let end = self.rung(span);
        let returns = std::mem::take(&mut self.returns);
        self.patch(&returns, end);
        Ok(())
    }

    /// `lhs => output` of a call: the output's value assigned to `lhs`.
    fn assign_output(&mut self, a: &Arg, src: &Loc) -> R<()> {
        if matches!(a.value.kind, ExprKind::Lit(Lit::Bool(false))) && a.value.span.start == a.value.span.end {
            return Ok(());
        }
        if let Loc::Struct { .. } | Loc::Array { .. } | Loc::StructArray { .. } = src {
            let dst = self.locate(&a.value)?;
            if loc_type(&dst) != loc_type(src) {
                return Err(type_error(
                    a.value.span,
                    "the output and the variable differ in type".into(),
                ));
            }
            self.copy_loc(&dst, src);
            return Ok(());
        }
        let negated = a.negated;
        let e = a.value.clone();
        self.assign_with(&a.value, a.value.span, &mut |l: &mut Self, _| {
            let (v, t) = l.read_loc(src, &e)?;
            if negated {
                let Val::B(b) = v else {
                    return Err(type_error(e.span, format!("NOT of an output that is {}", an(&t))));
                };
                let n = l.b.temp_b();
                l.emit(Op::Ldn(b));
                l.emit(Op::Ote(n));
                l.emit(Op::True);
                return Ok((Val::B(n), t));
            }
            Ok((v, t))
        })
    }

    /// Copies every value of `src` into `dst` (two locations of one type).
    fn copy_loc(&mut self, dst: &Loc, src: &Loc) {
        match (dst, src) {
            (Loc::StructArray { elems: d, .. }, Loc::StructArray { elems: s, .. }) => {
                for (a, b) in d.iter().zip(s.iter()) {
                    self.copy_loc(a, b);
                }
            }
            (Loc::Struct { members: d, .. }, Loc::Struct { members: s, .. }) => {
                for ((_, a), (_, b)) in d.iter().zip(s) {
                    self.copy_loc(a, b);
                }
            }
            (Loc::Array { elems: d, of, .. }, Loc::Array { elems: s, .. }) => {
                for (a, b) in d.iter().zip(s) {
                    let v = if *of == Ty::Bool {
                        Val::B(self.b.bool_in(*b, self.elem))
                    } else {
                        Val::N(self.b.load(*b, self.elem))
                    };
                    self.store(*a, v, of);
                }
            }
            (Loc::Value { place, ty, .. }, src) => {
                let e = Expr {
                    kind: ExprKind::Lit(Lit::Bool(false)),
                    span: Span::new(alba_diag::FileId(0), 0..0),
                };
                if let Ok((v, _)) = self.read_loc(src, &e) {
                    let (place, ty) = (*place, ty.clone());
                    self.store_checked(place, v, &ty);
                }
            }
            _ => {}
        }
    }

    /// Storage of a variable whose tag (or first tag) is `tag`.
    fn tag_loc(&mut self, tag: &str, ty: &Ty, constant: bool, n: &Ident) -> R<Loc> {
        let composite = matches!(ty, Ty::Struct(_))
            || matches!(ty, Ty::Array(of, _) if !matches!(**of, Ty::Bool) && of.data_type().is_none());
        if composite {
            if let Some(l) = self.composites.get(&(tag.to_string(), constant)) {
                return Ok(l.clone());
            }
            let l = self.tag_loc_uncached(tag, ty, constant, n)?;
            self.composites.insert((tag.to_string(), constant), l.clone());
            return Ok(l);
        }
        self.tag_loc_uncached(tag, ty, constant, n)
    }

    fn tag_loc_uncached(&mut self, tag: &str, ty: &Ty, constant: bool, n: &Ident) -> R<Loc> {
        match ty {
            Ty::Fb(kind) => Ok(Loc::Fb {
                kind: *kind,
                name: tag.to_string(),
            }),
            Ty::User(fb) => Ok(Loc::User {
                fb: fb.clone(),
                prefix: tag.to_string(),
            }),
            Ty::Struct(s) => {
                let mut members = Vec::new();
                for (m, mty, _) in &s.members {
                    members.push((m.clone(), self.tag_loc(&format!("{tag}.{m}"), mty, constant, n)?));
                }
                Ok(Loc::Struct { ty: s.clone(), members })
            }
            Ty::Array(of, dims) if matches!(**of, Ty::Struct(_) | Ty::Fb(_) | Ty::User(_)) => {
                let mut elems = Vec::new();
                for s in element_suffixes(dims) {
                    elems.push(self.tag_loc(&format!("{tag}{s}"), of, constant, n)?);
                }
                Ok(Loc::StructArray {
                    ty: ty.clone(),
                    elems: Rc::new(elems),
                    dims: dims.clone(),
                })
            }
            Ty::Array(of, dims) => {
                let elems = match self.arrays.get(tag) {
                    Some(e) => e.clone(),
                    None => {
                        let mut elems = Vec::new();
                        for s in element_suffixes(dims) {
                            match self.b.layout().resolve(&format!("{tag}{s}")) {
                                Ok(Target::Value { place, .. }) => elems.push(place),
                                _ => return Err(self.unknown(n, "variable")),
                            }
                        }
                        self.arrays.insert(tag.to_string(), elems.clone());
                        elems
                    }
                };
                Ok(Loc::Array {
                    elems,
                    ty: ty.clone(),
                    of: (**of).clone(),
                    dims: dims.clone(),
                })
            }
            _ => match self.b.layout().resolve(tag) {
                Ok(Target::Value { place, access }) => Ok(Loc::Value {
                    place,
                    access,
                    ty: ty.clone(),
                    constant,
                }),
                Ok(_) => Err(type_error(
                    n.span,
                    format!("`{tag}` is a TIMER, COUNTER or PID tag, not {}", an(ty)),
                )),
                Err(_) => Err(self.unknown(n, "variable")),
            },
        }
    }

    /// An input or output of an instance of a user FUNCTION_BLOCK.
    fn user_member(&mut self, fb: &str, prefix: &str, m: &Ident) -> R<Loc> {
        let Some(pou) = self.types.pous.get(&fb.to_ascii_lowercase()).copied() else {
            return Err(self.unknown(m, "member"));
        };
        let vars = variables(&pou.vars, Some(prefix), self.types, &mut Vec::new());
        let key = m.name.to_ascii_lowercase();
        match vars.iter().find(|(k, _)| *k == key) {
            Some((_, v)) if matches!(v.kind, VarKind::Input | VarKind::Output) => {
                let loc = self.tag_loc(&v.tag, &v.ty, false, m)?;
                Ok(if v.kind == VarKind::Output { read_only(loc) } else { loc })
            }
            Some((_, v)) => Err(type_error(
                m.span,
                format!(
                    "`{}` is a {} of {fb}: only its inputs and outputs are seen from outside",
                    m.name,
                    v.kind.keyword()
                ),
            )),
            None => {
                let names: Vec<&str> = vars
                    .iter()
                    .filter(|(_, v)| matches!(v.kind, VarKind::Input | VarKind::Output))
                    .map(|(_, v)| v.tag.rsplit('.').next().unwrap_or(&v.tag))
                    .collect();
                let mut d = Diagnostic::new(
                    Code::StName,
                    format!("{fb} has no input or output `{}`", m.name),
                    m.span,
                    "member",
                );
                d = d.with_help(match closest(&m.name, names.iter().copied()) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => format!("{fb} has {}", names.join(", ")),
                });
                Err(d)
            }
        }
    }

    /// Stores `v` into `place` of type `ty`; a value outside a subrange is a
    /// range fault and is not stored.
    fn store_checked(&mut self, place: Place, v: Val, ty: &Ty) {
        let (Ty::Sub(base, lo, hi), Val::N(x)) = (ty, v) else {
            self.store(place, v, ty);
            return;
        };
        let class = base.class();
        let x = self.b.convert(x, class, self.elem);
        let (clo, chi) = (
            self.b.constant(alba_model::Literal::Int(*lo), class),
            self.b.constant(alba_model::Literal::Int(*hi), class),
        );
        let bad = self.b.temp_b();
        self.cmp(Cmp::Lt, x, clo);
        self.emit(Op::Ote(bad));
        self.emit(Op::True);
        self.cmp(Cmp::Gt, x, chi);
        self.emit(Op::Or(bad));
        self.emit(Op::Ote(bad));
        self.emit(Op::True);
        self.range_fault(bad);
        self.emit(Op::Ldn(bad));
        self.store(place, Val::N(x), base);
        self.emit(Op::True);
    }

    /// A range fault when `bad` is set (rc true after).
    fn range_fault(&mut self, bad: B) {
        let junk = self.b.temp_i();
        let not_bcd = self.b.const_i(0xA);
        self.emit(Op::Ld(bad));
        self.emit(Op::UnI(IUn::Frd, not_bcd, junk));
        self.emit(Op::True);
    }

    /// An integer constant of a CASE label: a literal or an enumeration value.
    fn case_const(&self, e: &Expr, sel: &Ty) -> Option<i64> {
        if let Some(v) = const_int(e) {
            return Some(v);
        }
        match &e.kind {
            // The selector's own enumeration first.
            ExprKind::Name(n) if matches!(sel, Ty::Enum(en) if enum_value(en, &n.name).is_some()) => match sel {
                Ty::Enum(en) => enum_value(en, &n.name),
                _ => None,
            },
            ExprKind::Name(n) => {
                let declared = self.vars.values().filter_map(|v| match &v.ty {
                    Ty::Enum(e) => Some(e),
                    _ => None,
                });
                self.types
                    .enums
                    .iter()
                    .chain(declared)
                    .find_map(|en| enum_value(en, &n.name))
            }
            ExprKind::Lit(Lit::Other(t, v)) => self
                .types
                .enums
                .iter()
                .filter(|en| en.name.eq_ignore_ascii_case(t))
                .find_map(|en| enum_value(en, v)),
            _ => None,
        }
    }
}

/// A location whose values cannot be written from here (an FB's outputs).
fn read_only(l: Loc) -> Loc {
    match l {
        Loc::Value {
            place, ty, constant, ..
        } => Loc::Value {
            place,
            access: Access::ReadOnly,
            ty,
            constant,
        },
        Loc::Struct { ty, members } => Loc::Struct {
            ty,
            members: members.into_iter().map(|(m, l)| (m, read_only(l))).collect(),
        },
        l => l,
    }
}

impl Lower<'_> {
    fn store_const(&mut self, place: Place, value: Value) -> R<()> {
        let ty = Ty::from_data_type(value.data_type()).unwrap_or(Ty::Dint);
        let val = self.constant(&value_lit(value), &ty);
        self.store(place, val, &ty);
        Ok(())
    }

    fn block(&mut self, list: &[Stmt]) {
        for s in list {
            let mark = self.b.mark();
            if let Err(d) = self.stmt(s) {
                self.diags.push(d);
            }
            self.b.release(mark);
        }
    }

    fn stmt(&mut self, s: &Stmt) -> R<()> {
        match &s.kind {
            StmtKind::Empty => Ok(()),
            StmtKind::Assign(lhs, rhs) => {
                self.rung(s.span);
                self.assign(lhs, rhs)
            }
            StmtKind::Call(callee, args) => {
                self.rung(s.span);
                if let ExprKind::Index(base, ix) = &callee.kind {
                    return self.call_element(base, ix, args, callee, s.span);
                }
                let ExprKind::Name(n) = &callee.kind else {
                    return Err(not_supported(callee.span, "this call is not supported".into()));
                };
                let loc = match self.lookup(n) {
                    Ok(l) => Some(l),
                    Err(_) if self.types.pous.contains_key(&n.name.to_ascii_lowercase()) => None,
                    Err(d) => return Err(d),
                };
                match loc {
                    Some(Loc::Fb { kind, name }) => self.fb_call(kind, &name, n, args),
                    Some(Loc::User { fb, prefix }) => {
                        let pou = self.types.pous.get(&fb.to_ascii_lowercase()).copied();
                        match pou {
                            Some(p) => self.inline_fb(p, &prefix, args, s.span, false),
                            None => Err(self.unknown(n, "function block")),
                        }
                    }
                    _ => {
                        // A function called for nothing: evaluate it (it may fault).
                        self.call(n, args, None, callee.span).map(|_| ())
                    }
                }
            }
            StmtKind::If { arms, els } => {
                let mut ends = Vec::new();
                let mut next = 0;
                for (k, (c, body)) in arms.iter().enumerate() {
                    if k > 0 {
                        // ELSIF: evaluated in the rung the previous arm skips to.
                        self.elem = self.b.element(c.span);
                    } else {
                        self.rung(s.span);
                    }
                    let c = self.cond(c)?;
                    self.emit(Op::Ldn(c));
                    let skip = self.emit(Op::Jmp(0));
                    self.emit(Op::True);
                    self.block(body);
                    if k + 1 < arms.len() || els.is_some() {
                        ends.push(self.emit(Op::Jmp(0)));
                    }
                    next = self.rung(s.span);
                    self.patch(&[skip], next);
                }
                if let Some(e) = els {
                    self.block(e);
                    next = self.rung(s.span);
                }
                self.patch(&ends, next);
                Ok(())
            }
            StmtKind::Case { sel, arms, els } => {
                self.rung(s.span);
                let (v, ty) = self.eval(sel, None)?;
                let (Val::N(v), true) = (v, ty.is_int() || ty.is_bits() || matches!(ty, Ty::Enum(_))) else {
                    return Err(type_error(sel.span, format!("CASE selects on an integer, not a {ty}")));
                };
                let V::I(selector) = self.b.convert(v, Class::I, self.elem) else {
                    return Err(not_supported(sel.span, "a LINT selector is not supported yet".into()));
                };
                let mut ends = Vec::new();
                for (labels, body) in arms {
                    let hit = self.b.temp_b();
                    for (k, label) in labels.iter().enumerate() {
                        let (lo, hi, span) = match label {
                            CaseLabel::One(e) => (self.case_const(e, &ty), self.case_const(e, &ty), e.span),
                            CaseLabel::Range(a, b) => {
                                (self.case_const(a, &ty), self.case_const(b, &ty), a.span.to(b.span))
                            }
                        };
                        let (Some(lo), Some(hi)) = (lo, hi) else {
                            return Err(type_error(
                                span,
                                "a CASE label is an integer literal or a range of them".into(),
                            ));
                        };
                        if lo > hi {
                            return Err(type_error(span, format!("the range {lo}..{hi} is empty")));
                        }
                        let (Ok(lo), Ok(hi)) = (i32::try_from(lo), i32::try_from(hi)) else {
                            return Err(type_error(span, "a CASE label does not fit a DINT".into()));
                        };
                        let (clo, chi) = (self.b.const_i(lo), self.b.const_i(hi));
                        if lo == hi {
                            self.emit(Op::CmpI(Cmp::Eq, selector, clo));
                        } else {
                            self.emit(Op::CmpI(Cmp::Ge, selector, clo));
                            self.emit(Op::CmpI(Cmp::Le, selector, chi));
                        }
                        if k > 0 {
                            self.emit(Op::Or(hit));
                        }
                        self.emit(Op::Ote(hit));
                        self.emit(Op::True);
                    }
                    self.emit(Op::Ldn(hit));
                    let skip = self.emit(Op::Jmp(0));
                    self.emit(Op::True);
                    self.block(body);
                    ends.push(self.emit(Op::Jmp(0)));
                    let next = self.rung(s.span);
                    self.patch(&[skip], next);
                }
                if let Some(e) = els {
                    self.block(e);
                }
                let end = self.rung(s.span);
                self.patch(&ends, end);
                Ok(())
            }
            StmtKind::For {
                var,
                from,
                to,
                by,
                body,
            } => {
                self.rung(s.span);
                let (place, ty) = match self.lookup(var)? {
                    Loc::Value {
                        place,
                        access,
                        ty,
                        constant,
                    } if ty.is_int() && access == Access::ReadWrite && !constant => (place, ty),
                    _ => {
                        return Err(decl_error(
                            var.span,
                            format!("the loop variable `{}` is a writable integer variable", var.name),
                        ));
                    }
                };
                let step = match by {
                    None => 1,
                    Some(e) => match const_int(e) {
                        Some(0) | None => {
                            return Err(not_supported(e.span, "BY takes a non-zero integer literal".into()));
                        }
                        Some(v) => v,
                    },
                };
                let (start, sty) = self.eval(from, Some(&ty))?;
                if !widens(&sty, &ty) {
                    return Err(type_error(
                        from.span,
                        format!("the loop variable is a {ty}; the start value is a {sty}"),
                    ));
                }
                let start = self.fit(start, from, &ty)?;
                self.store(place, Val::N(start), &ty);
                let (end, ety) = self.eval(to, Some(&ty))?;
                if !widens(&ety, &ty) {
                    return Err(type_error(
                        to.span,
                        format!("the loop variable is a {ty}; the end value is a {ety}"),
                    ));
                }
                let end_v = self.fit(end, to, &ty)?;
                // Keep the end value in a slot of its own for the whole loop.
                let end_slot = self.b.temp(ty.class());
                self.b.un(IUn::Mov, end_v, end_slot, self.elem);
                let top = self.rung(s.span);
                let i = self.b.load(place, self.elem);
                let cmp = if step > 0 { Cmp::Gt } else { Cmp::Lt };
                self.cmp(cmp, i, end_slot);
                let exit = self.emit(Op::Jmp(0));
                self.emit(Op::True);
                self.loops.push(LoopLabels { exits: vec![exit] });
                self.block(body);
                self.rung(s.span);
                let i = self.b.load(place, self.elem);
                let stepc = self.constant(&Lit::Int(step, None), &ty);
                let Val::N(stepc) = stepc else { return Ok(()) };
                let next = self.b.temp(ty.class());
                self.b.bin(IBin::Add, i, stepc, next, self.elem);
                self.store(place, Val::N(next), &ty);
                self.emit(Op::Jmp(top));
                let out = self.rung(s.span);
                let l = self.loops.pop().map(|l| l.exits).unwrap_or_default();
                self.patch(&l, out);
                Ok(())
            }
            StmtKind::While(c, body) => {
                let top = self.rung(s.span);
                let c = self.cond(c)?;
                self.emit(Op::Ldn(c));
                let exit = self.emit(Op::Jmp(0));
                self.emit(Op::True);
                self.loops.push(LoopLabels { exits: vec![exit] });
                self.block(body);
                self.emit(Op::Jmp(top));
                let out = self.rung(s.span);
                let l = self.loops.pop().map(|l| l.exits).unwrap_or_default();
                self.patch(&l, out);
                Ok(())
            }
            StmtKind::Repeat(body, c) => {
                let top = self.rung(s.span);
                self.loops.push(LoopLabels { exits: Vec::new() });
                self.block(body);
                self.rung(c.span);
                let cv = self.cond(c);
                let cv = match cv {
                    Ok(v) => v,
                    Err(d) => {
                        self.loops.pop();
                        return Err(d);
                    }
                };
                self.emit(Op::Ldn(cv));
                self.emit(Op::Jmp(top));
                self.emit(Op::True);
                let out = self.rung(s.span);
                let l = self.loops.pop().map(|l| l.exits).unwrap_or_default();
                self.patch(&l, out);
                Ok(())
            }
            StmtKind::Exit => {
                self.rung(s.span);
                let j = self.emit(Op::Jmp(0));
                match self.loops.last_mut() {
                    Some(l) => {
                        l.exits.push(j);
                        Ok(())
                    }
                    None => Err(decl_error(
                        s.span,
                        "EXIT is only allowed inside FOR, WHILE or REPEAT".into(),
                    )),
                }
            }
            StmtKind::Return => {
                self.rung(s.span);
                let j = self.emit(Op::Jmp(0));
                self.returns.push(j);
                Ok(())
            }
        }
    }

    /// `rc = a <cmp> b` (rc true before).
    fn cmp(&mut self, c: Cmp, a: V, b: V) {
        let op = match (a, b) {
            (V::I(a), V::I(b)) => Op::CmpI(c, a, b),
            (V::F(a), V::F(b)) => Op::CmpF(c, a, b),
            (V::L(a), V::L(b)) => Op::CmpL(c, a, b),
            (V::D(a), V::D(b)) => Op::CmpD(c, a, b),
            _ => return,
        };
        self.emit(op);
    }

    fn cond(&mut self, e: &Expr) -> R<B> {
        let (v, ty) = self.eval(e, Some(&Ty::Bool))?;
        match (v, ty) {
            (Val::B(b), Ty::Bool) => Ok(b),
            (_, ty) => Err(type_error(e.span, format!("a condition is BOOL, not {ty}"))),
        }
    }

    /// Names known in this POU, for "did you mean".
    fn known_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .vars
            .values()
            .map(|v| v.tag.rsplit('.').next().unwrap_or(&v.tag).to_string())
            .collect();
        v.extend(self.aliases.keys().cloned());
        v.extend(
            self.b
                .layout()
                .tags
                .iter()
                .filter(|t| !t.name.contains('.'))
                .map(|t| t.name.clone()),
        );
        v
    }

    fn unknown(&self, n: &Ident, what: &str) -> Diagnostic {
        let names = self.known_names();
        let mut d = Diagnostic::new(
            Code::StName,
            format!("unknown {what} `{}`", n.name),
            n.span,
            "not declared",
        );
        if let Some(s) = closest(&n.name, names.iter().map(String::as_str)) {
            d = d.with_help(format!("did you mean `{s}`?"));
        } else {
            d = d.with_help(format!(
                "declare it in a VAR block of {} or as a tag in tags.csv",
                self.pou
            ));
        }
        d
    }

    fn lookup(&mut self, n: &Ident) -> R<Loc> {
        let key = n.name.to_ascii_lowercase();
        if let Some(l) = self.aliases.get(&key) {
            return Ok(l.clone());
        }
        if let Some((tag, ty, constant)) = self.vars.get(&key).map(|v| (v.tag.clone(), v.ty.clone(), v.constant)) {
            return self.tag_loc(&tag, &ty, constant, n);
        }
        match self.b.layout().resolve(&n.name) {
            Ok(Target::Value { place, access }) => {
                let Some(ty) = Ty::from_data_type(place.data_type()) else {
                    return Err(not_supported(
                        n.span,
                        format!("`{}` has a type ST cannot use yet", n.name),
                    ));
                };
                Ok(Loc::Value {
                    place,
                    access,
                    ty,
                    constant: false,
                })
            }
            Ok(_) => Err(not_supported(
                n.span,
                format!(
                    "`{}` is a TIMER, COUNTER or PID tag of tags.csv; in ST use its members (`{}.DN`) or declare a TON/CTU instance",
                    n.name, n.name
                ),
            )),
            Err(e) if n.name.starts_with('%') => Err(Diagnostic::new(Code::StName, e.to_string(), n.span, "address")),
            Err(_) => {
                let declared = self.vars.values().filter_map(|v| match &v.ty {
                    Ty::Enum(e) => Some(e),
                    _ => None,
                });
                for en in self.types.enums.iter().chain(declared) {
                    if let Some(v) = enum_value(en, &n.name) {
                        return Ok(Loc::EnumConst(en.clone(), v));
                    }
                }
                Err(self.unknown(n, "name"))
            }
        }
    }

    /// The place of an lvalue or rvalue expression that names storage.
    fn locate(&mut self, e: &Expr) -> R<Loc> {
        match &e.kind {
            ExprKind::Name(n) => self.lookup(n),
            ExprKind::Member(base, m) => {
                let found = match &base.kind {
                    ExprKind::Name(n) => self.lookup(n).ok(),
                    _ => Some(self.locate(base)?),
                };
                match found {
                    Some(Loc::Fb { kind, name }) => return self.fb_member(kind, &name, m),
                    Some(Loc::User { fb, prefix }) => return self.user_member(&fb, &prefix, m),
                    Some(Loc::Struct { ty, members }) => {
                        return match members.into_iter().find(|(k, _)| m.is(k)) {
                            Some((_, l)) => Ok(l),
                            None => {
                                let names: Vec<&str> = ty.members.iter().map(|(k, ..)| k.as_str()).collect();
                                let mut d = Diagnostic::new(
                                    Code::StName,
                                    format!("{} has no member `{}`", ty.name, m.name),
                                    m.span,
                                    "member",
                                );
                                d = d.with_help(match closest(&m.name, names.iter().copied()) {
                                    Some(c) => format!("did you mean `{c}`?"),
                                    None => format!("{} has {}", ty.name, names.join(", ")),
                                });
                                Err(d)
                            }
                        };
                    }
                    Some(Loc::Value {
                        place,
                        access,
                        ty,
                        constant,
                    }) => {
                        let width = match &ty {
                            Ty::Sint => Some(8),
                            Ty::Int => Some(16),
                            Ty::Dint => Some(32),
                            Ty::Lint => Some(64),
                            t => t.bits(),
                        };
                        let Some(width) = width else {
                            return Err(type_error(
                                m.span,
                                format!("`{}` is {}; it has no members", ast::expr(base), an(&ty)),
                            ));
                        };
                        return match m.name.parse::<u32>() {
                            Ok(bit) if bit < width => Ok(Loc::Bit {
                                place,
                                access,
                                ty,
                                bit,
                                constant,
                            }),
                            _ => Err(type_error(
                                m.span,
                                format!(
                                    "`{}` is {}: its bits are `.0` to `.{}`, not `.{}`",
                                    ast::expr(base),
                                    an(&ty),
                                    width - 1,
                                    m.name
                                ),
                            )),
                        };
                    }
                    Some(Loc::Bit { .. }) => {
                        return Err(type_error(
                            m.span,
                            format!("`{}` is a BOOL; it has no members", ast::expr(base)),
                        ));
                    }
                    Some(Loc::Array { .. } | Loc::StructArray { .. }) => {
                        return Err(type_error(
                            m.span,
                            format!("`{}` is an array; it has no members", ast::expr(base)),
                        ));
                    }
                    Some(Loc::CounterQ { .. } | Loc::EnumConst(..)) => {
                        return Err(type_error(m.span, format!("`{}` has no members", ast::expr(base))));
                    }
                    None => {}
                }
                let ExprKind::Name(n) = &base.kind else {
                    return Err(not_supported(
                        e.span,
                        "members of this expression are not supported".into(),
                    ));
                };
                // A tag member of tags.csv (`Timer1.DN`, `Loop.PV`).
                let full = format!("{}.{}", n.name, m.name);
                match self.b.layout().resolve(&full) {
                    Ok(Target::Value { place, access }) => {
                        let ty = Ty::from_data_type(place.data_type()).unwrap_or(Ty::Dint);
                        Ok(Loc::Value {
                            place,
                            access,
                            ty,
                            constant: false,
                        })
                    }
                    Ok(_) => Err(not_supported(m.span, format!("`{full}` cannot be used in ST yet"))),
                    Err(err) => {
                        // The base is unknown: say so, with "did you mean".
                        if self.lookup(n).is_err() && self.b.layout().resolve(&n.name).is_err() {
                            return Err(self.unknown(n, "name"));
                        }
                        Err(Diagnostic::new(Code::StName, err.to_string(), e.span, "unknown"))
                    }
                }
            }
            ExprKind::Index(base, ix) => {
                if ix.iter().any(|i| const_int(i).is_none()) {
                    return Err(not_supported(
                        e.span,
                        "an element with a computed index cannot be used here yet (only its value, or a member of it)"
                            .into(),
                    ));
                }
                match self.locate(base)? {
                    Loc::Array { elems, of, dims, .. } => {
                        let Ok(k) = self.flat_index(&dims, ix, e.span)? else {
                            return Err(type_error(e.span, "index".into()));
                        };
                        Ok(Loc::Value {
                            place: elems[k],
                            access: Access::ReadWrite,
                            ty: of,
                            constant: false,
                        })
                    }
                    Loc::StructArray { elems, dims, .. } => {
                        let Ok(k) = self.flat_index(&dims, ix, e.span)? else {
                            return Err(type_error(e.span, "index".into()));
                        };
                        Ok(elems[k].clone())
                    }
                    _ => Err(type_error(base.span, format!("`{}` is not an array", ast::expr(base)))),
                }
            }
            _ => Err(type_error(e.span, format!("`{}` is not a variable", ast::expr(e)))),
        }
    }

    fn fb_member(&mut self, kind: Fb, name: &str, m: &Ident) -> R<Loc> {
        let layout = self.b.layout();
        let ro = |place, ty| Loc::Value {
            place,
            access: Access::ReadOnly,
            ty,
            constant: false,
        };
        let up = m.name.to_ascii_uppercase();
        let found = match kind {
            Fb::Ton | Fb::Tof | Fb::Tp => {
                let Ok(Target::Timer(t)) = layout.resolve(name) else {
                    return Err(self.unknown(m, "member"));
                };
                match up.as_str() {
                    "Q" => Some(ro(Place::Bool(B(t.b.0 + 2)), Ty::Bool)),
                    "ET" => Some(ro(Place::Int(I(t.i.0 + 1), DataType::Time), Ty::Time)),
                    "IN" => Some(ro(Place::Bool(t.b), Ty::Bool)),
                    "PT" => Some(ro(Place::Int(t.i, DataType::Time), Ty::Time)),
                    _ => None,
                }
            }
            Fb::Ctu | Fb::Ctd | Fb::Ctud => {
                let Ok(Target::Counter(c)) = layout.resolve(name) else {
                    return Err(self.unknown(m, "member"));
                };
                match up.as_str() {
                    "CV" => Some(ro(Place::Int(I(c.i.0 + 1), DataType::Int), Ty::Int)),
                    "PV" => Some(ro(Place::Int(c.i, DataType::Int), Ty::Int)),
                    "Q" if kind != Fb::Ctud => Some(Loc::CounterQ {
                        c,
                        down: kind == Fb::Ctd,
                    }),
                    "QU" | "QD" if kind == Fb::Ctud => Some(Loc::CounterQ { c, down: up == "QD" }),
                    _ => None,
                }
            }
            Fb::RTrig | Fb::FTrig if up == "Q" => match layout.resolve(&format!("{name}.Q")) {
                Ok(Target::Value { place, .. }) => Some(ro(place, Ty::Bool)),
                _ => None,
            },
            Fb::Sr | Fb::Rs if up == "Q1" => match layout.resolve(&format!("{name}.Q1")) {
                Ok(Target::Value { place, .. }) => Some(ro(place, Ty::Bool)),
                _ => None,
            },
            _ => None,
        };
        found.ok_or_else(|| {
            let (ins, outs) = kind.params();
            let all: Vec<&str> = ins.iter().chain(outs).map(|(n, _)| *n).collect();
            let mut d = Diagnostic::new(
                Code::StName,
                format!("{} has no member `{}`", kind.name(), m.name),
                m.span,
                "member",
            );
            if let Some(s) = closest(&m.name, all.iter().copied()) {
                d = d.with_help(format!("did you mean `{s}`? ({} has {})", kind.name(), all.join(", ")));
            } else {
                d = d.with_help(format!("{} has {}", kind.name(), all.join(", ")));
            }
            d
        })
    }

    /// Reads a located value (counter Q members are computed).
    fn read_loc(&mut self, loc: &Loc, e: &Expr) -> R<(Val, Ty)> {
        match loc {
            Loc::CounterQ { c, down } => Ok((Val::B(self.counter_q(*c, *down)), Ty::Bool)),
            Loc::Value { place, ty, .. } => {
                if *ty == Ty::Bool {
                    Ok((Val::B(self.b.bool_in(*place, self.elem)), Ty::Bool))
                } else {
                    Ok((Val::N(self.b.load(*place, self.elem)), ty.value()))
                }
            }
            Loc::EnumConst(en, v) => {
                let c = self.b.const_i(*v as i32);
                Ok((Val::N(V::I(c)), Ty::Enum(en.clone())))
            }
            Loc::Bit { place, ty, bit, .. } => {
                let x = self.b.load(*place, self.elem);
                let c = vclass(x);
                let mask = self.bit_mask(ty, *bit, c);
                let (t, zero) = (self.b.temp(c), self.int_const(0, c));
                self.b.bin(IBin::And, x, mask, t, self.elem);
                let r = self.b.temp_b();
                self.cmp(Cmp::Ne, t, zero);
                self.emit(Op::Ote(r));
                self.emit(Op::True);
                Ok((Val::B(r), Ty::Bool))
            }
            Loc::User { fb, .. } => Err(type_error(
                e.span,
                format!("`{}` is a {fb} instance; call it or read an output", ast::expr(e)),
            )),
            Loc::Struct { ty, .. } => Err(type_error(
                e.span,
                format!("`{}` is a whole {}; read a member", ast::expr(e), ty.name),
            )),
            Loc::StructArray { ty, .. } => Err(type_error(
                e.span,
                format!("`{}` is a whole {ty}; index it", ast::expr(e)),
            )),
            Loc::Array { ty, .. } => Err(type_error(
                e.span,
                format!("`{}` is a whole {ty}; index it", ast::expr(e)),
            )),
            Loc::Fb { kind, .. } => Err(type_error(
                e.span,
                format!(
                    "`{}` is a {} instance; call it or read a member",
                    ast::expr(e),
                    kind.name()
                ),
            )),
        }
    }

    fn counter_q(&mut self, c: Ctr, down: bool) -> B {
        let t = self.b.temp_b();
        let acc = I(c.i.0 + 1);
        if down {
            let zero = self.b.const_i(0);
            self.emit(Op::CmpI(Cmp::Le, acc, zero));
        } else {
            self.emit(Op::CmpI(Cmp::Ge, acc, c.i));
        }
        self.emit(Op::Ote(t));
        self.emit(Op::True);
        t
    }

    /// A constant of type `ty`.
    fn constant(&mut self, l: &Lit, ty: &Ty) -> Val {
        match (l, ty) {
            (Lit::Bool(b), _) => {
                let t = self.b.temp_b();
                if !b {
                    self.emit(Op::Afi);
                }
                self.emit(Op::Ote(t));
                self.emit(Op::True);
                Val::B(t)
            }
            (Lit::Int(v, _) | Lit::Time(v), ty) => Val::N(self.b.constant(alba_model::Literal::Int(*v), ty.class())),
            (Lit::Real(v, _), ty) => Val::N(self.b.constant(alba_model::Literal::Real(*v), ty.class())),
            _ => Val::N(self.b.constant(alba_model::Literal::Int(0), Class::I)),
        }
    }

    /// The type of a literal: its own, or `hint` for an untyped number that fits it.
    fn lit_type(&self, l: &Lit, hint: Option<&Ty>, span: Span) -> R<Ty> {
        Ok(match l {
            Lit::Bool(_) => Ty::Bool,
            Lit::Time(ms) => {
                if i32::try_from(*ms).is_err() {
                    return Err(type_error(
                        span,
                        format!("T#{ms}ms does not fit a TIME (32-bit milliseconds)"),
                    ));
                }
                Ty::Time
            }
            Lit::Int(v, Some(t)) => {
                let ty =
                    elementary(t).ok_or_else(|| not_supported(span, format!("{t} literals are not supported yet")))?;
                if !fits(*v, &ty) {
                    return Err(type_error(span, format!("{v} does not fit a {ty}")));
                }
                ty
            }
            Lit::Int(v, None) => match hint {
                Some(h) if ((h.is_int() || h.is_bits()) && fits(*v, h)) || h.is_real() => h.clone(),
                _ if fits(*v, &Ty::Dint) => Ty::Dint,
                _ => Ty::Lint,
            },
            Lit::Real(_, Some(t)) => elementary(t).unwrap_or(Ty::Lreal),
            Lit::Real(_, None) => match hint {
                Some(Ty::Lreal) => Ty::Lreal,
                _ => Ty::Real,
            },
            Lit::Str(..) => {
                return Err(not_supported(
                    span,
                    "strings are not supported by the engine yet".into(),
                ));
            }
            Lit::Other(t, v) => {
                return Err(not_supported(
                    span,
                    format!("`{t}#{v}`: this kind of literal is not supported yet"),
                ));
            }
        })
    }

    /// Evaluates `e` (a number in a slot of its class, or a BOOL slot).
    /// `hint`: the type wanted, for untyped literals.
    fn eval(&mut self, e: &Expr, hint: Option<&Ty>) -> R<(Val, Ty)> {
        match &e.kind {
            ExprKind::Lit(Lit::Other(t, v)) if self.types.enums.iter().any(|en| en.name.eq_ignore_ascii_case(t)) => {
                let found = self
                    .types
                    .enums
                    .iter()
                    .filter(|en| en.name.eq_ignore_ascii_case(t))
                    .find_map(|en| enum_value(en, v).map(|x| (en.clone(), x)));
                match found {
                    Some((en, x)) => {
                        let c = self.b.const_i(x as i32);
                        Ok((Val::N(V::I(c)), Ty::Enum(en)))
                    }
                    None => Err(Diagnostic::new(
                        Code::StName,
                        format!("the enumeration {t} has no value `{v}`"),
                        e.span,
                        "value",
                    )),
                }
            }
            ExprKind::Lit(l) => {
                let ty = self.lit_type(l, hint, e.span)?;
                Ok((self.constant(l, &ty), ty))
            }
            // A value of the enumeration wanted, named bare (`c := Red`).
            ExprKind::Name(n)
                if matches!(hint, Some(Ty::Enum(en)) if enum_value(en, &n.name).is_some())
                    && !self.aliases.contains_key(&n.name.to_ascii_lowercase())
                    && !self.vars.contains_key(&n.name.to_ascii_lowercase())
                    && self.b.layout().resolve(&n.name).is_err() =>
            {
                let Some(Ty::Enum(en)) = hint else {
                    return Err(type_error(e.span, "enumeration".into()));
                };
                let v = enum_value(en, &n.name).unwrap_or(0);
                let c = self.b.const_i(v as i32);
                Ok((Val::N(V::I(c)), Ty::Enum(en.clone())))
            }
            ExprKind::Name(_) | ExprKind::Member(..) | ExprKind::Index(..) => {
                if let Some((of, elems, dims, ix)) = self.elements_of(e)? {
                    let v = self.index_read(&elems, &dims, ix, &of, e.span)?;
                    return Ok((v, of.value()));
                }
                let loc = self.locate(e)?;
                self.read_loc(&loc, e)
            }
            ExprKind::Unary(AUn::Not, a) => {
                let (v, ty) = self.eval(a, Some(hint.filter(|h| h.is_bits()).unwrap_or(&Ty::Bool)))?;
                match v {
                    Val::B(b) => {
                        let t = self.b.temp_b();
                        self.emit(Op::Ldn(b));
                        self.emit(Op::Ote(t));
                        self.emit(Op::True);
                        Ok((Val::B(t), Ty::Bool))
                    }
                    Val::N(x) if ty.is_bits() => {
                        let t = self.b.temp(vclass(x));
                        self.b.un(IUn::Not, x, t, self.elem);
                        let w = ty.bits().unwrap_or(64);
                        Ok((Val::N(self.wrap_bits(t, w)), ty))
                    }
                    Val::N(_) => Err(type_error(
                        a.span,
                        format!("NOT takes a BOOL or a bit string (BYTE … LWORD), not {}", an(&ty)),
                    )),
                }
            }
            ExprKind::Unary(AUn::Neg, a) => {
                let (v, ty) = self.eval(a, hint)?;
                match v {
                    Val::N(x) if ty.is_num() && !ty.is_unsigned() => {
                        let t = self.b.temp(ty.class());
                        self.b.un(IUn::Neg, x, t, self.elem);
                        self.narrow(t, &ty);
                        Ok((Val::N(t), ty))
                    }
                    _ => Err(type_error(a.span, format!("`-` takes a number, not a {ty}"))),
                }
            }
            ExprKind::Binary(op, a, b) => self.binary(*op, a, b, e.span, hint),
            ExprKind::Call(n, args) => {
                let (v, ty) = self.call(n, args, hint, e.span)?;
                Ok((v, ty))
            }
        }
    }

    /// Wraps a SINT or INT result to its width (an overflow fault when it changes).
    fn narrow(&mut self, v: V, ty: &Ty) {
        if let V::I(i) = v {
            match ty {
                Ty::Sint => {
                    self.emit(Op::Narrow(i, Width::W8));
                }
                Ty::Int => {
                    self.emit(Op::Narrow(i, Width::W16));
                }
                _ => {}
            }
        }
    }

    /// Both operands of a binary operator, untyped literals taking the other side's type.
    fn operands(&mut self, a: &Expr, b: &Expr, hint: Option<&Ty>) -> R<((Val, Ty), (Val, Ty))> {
        let untyped = |e: &Expr| matches!(e.kind, ExprKind::Lit(Lit::Int(_, None) | Lit::Real(_, None)));
        if untyped(a) && !untyped(b) {
            let rb = self.eval(b, hint)?;
            let ra = self.eval(a, Some(&rb.1))?;
            Ok((ra, rb))
        } else {
            let ra = self.eval(a, hint)?;
            let rb = self.eval(b, Some(&ra.1))?;
            Ok((ra, rb))
        }
    }

    fn binary(&mut self, op: BinOp, a: &Expr, b: &Expr, span: Span, hint: Option<&Ty>) -> R<(Val, Ty)> {
        let logic = matches!(op, BinOp::And | BinOp::Or | BinOp::Xor);
        let compare = matches!(
            op,
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Gt | BinOp::Le | BinOp::Ge
        );
        let h = if logic {
            Some(&Ty::Bool)
        } else if compare {
            None
        } else {
            hint
        };
        let ((va, ta), (vb, tb)) = self.operands(a, b, h)?;
        if let (true, Val::N(x), Val::N(y)) = (logic, va, vb) {
            return self.bitwise(op, (x, &ta), (y, &tb), span);
        }
        if logic || (compare && ta == Ty::Bool && tb == Ty::Bool && matches!(op, BinOp::Eq | BinOp::Ne)) {
            let (Val::B(x), Val::B(y)) = (va, vb) else {
                return Err(type_error(
                    span,
                    format!(
                        "{} takes BOOL operands, not {ta} and {tb} (bit strings are not supported yet)",
                        op.text()
                    ),
                ));
            };
            let t = self.b.temp_b();
            match op {
                BinOp::And => {
                    self.emit(Op::Ld(x));
                    self.emit(Op::Xic(y));
                    self.emit(Op::Ote(t));
                }
                BinOp::Or => {
                    self.emit(Op::Ld(x));
                    self.emit(Op::Or(y));
                    self.emit(Op::Ote(t));
                }
                _ => {
                    // XOR, and `<>` / `=` on BOOL (its negation).
                    let t1 = self.b.temp_b();
                    self.emit(Op::Ld(x));
                    self.emit(Op::Xio(y));
                    self.emit(Op::Ote(t1));
                    self.emit(Op::Ld(y));
                    self.emit(Op::Xio(x));
                    self.emit(Op::Or(t1));
                    if op == BinOp::Eq {
                        self.emit(Op::Not);
                    }
                    self.emit(Op::Ote(t));
                }
            }
            self.emit(Op::True);
            return Ok((Val::B(t), Ty::Bool));
        }
        // Numbers: one type, after implicit widening of either side.
        let (Val::N(x), Val::N(y)) = (va, vb) else {
            return Err(type_error(
                span,
                format!("`{}` takes numbers, not {ta} and {tb}", op.text()),
            ));
        };
        let time_scale = matches!(op, BinOp::Mul | BinOp::Div) && ta == Ty::Time && tb.is_int();
        let ty = if time_scale {
            Ty::Time
        } else if widens(&ta, &tb) {
            tb.clone()
        } else if widens(&tb, &ta) {
            ta.clone()
        } else {
            return Err(type_error(
                span,
                format!(
                    "`{}` of {ta} and {tb}: the types differ; convert one (for example {ta}_TO_{tb})",
                    op.text()
                ),
            ));
        };
        if matches!(ty, Ty::Enum(_)) && !compare {
            return Err(type_error(
                span,
                format!("`{}` does not take enumeration values ({ty})", op.text()),
            ));
        }
        let class = ty.class();
        let x = self.b.convert(x, class, self.elem);
        let y = self.b.convert(y, class, self.elem);
        if compare {
            let c = match op {
                BinOp::Eq => Cmp::Eq,
                BinOp::Ne => Cmp::Ne,
                BinOp::Lt => Cmp::Lt,
                BinOp::Gt => Cmp::Gt,
                BinOp::Le => Cmp::Le,
                _ => Cmp::Ge,
            };
            let t = self.b.temp_b();
            self.cmp(c, x, y);
            self.emit(Op::Ote(t));
            self.emit(Op::True);
            return Ok((Val::B(t), Ty::Bool));
        }
        let iop = match op {
            BinOp::Add => IBin::Add,
            BinOp::Sub => IBin::Sub,
            BinOp::Mul => IBin::Mul,
            BinOp::Div => IBin::Div,
            BinOp::Mod if ty.is_int() => IBin::Mod,
            BinOp::Pow if ty.is_real() => IBin::Pow,
            BinOp::Mod => return Err(type_error(span, format!("MOD takes integers, not {ty}"))),
            _ => {
                return Err(type_error(
                    span,
                    format!("`**` takes REAL or LREAL, not {ty}; convert with {ty}_TO_REAL"),
                ));
            }
        };
        if ty == Ty::Time && matches!(op, BinOp::Mod) {
            return Err(type_error(span, "MOD does not take TIME".into()));
        }
        if ty == Ty::Time && matches!(op, BinOp::Mul | BinOp::Div) && !time_scale {
            return Err(type_error(
                span,
                format!("TIME {} TIME is not defined; scale a TIME by an integer", op.text()),
            ));
        }
        if let Some(w) = ty.bits() {
            if ty.is_bits() {
                return Err(type_error(
                    span,
                    format!(
                        "`{}` does not take bit strings ({ty}); convert to an unsigned integer first",
                        op.text()
                    ),
                ));
            }
            // Unsigned: computed in 64 bits, then wrapped to the width.
            let xl = self.b.convert(x, Class::L, self.elem);
            let yl = self.b.convert(y, Class::L, self.elem);
            let t = self.b.temp(Class::L);
            self.b.bin(iop, xl, yl, t, self.elem);
            let t = self.wrap_bits(t, w);
            return Ok((Val::N(self.b.convert(t, class, self.elem)), ty));
        }
        let t = self.b.temp(class);
        self.b.bin(iop, x, y, t, self.elem);
        self.narrow(t, &ty);
        Ok((Val::N(t), ty))
    }

    /// The element places an indexed expression chooses from: `a[i]`, or a
    /// member of an element of an array of structures (`pts[i].x`,
    /// `pts[i].p.y`) as the list of that member's places, one per element.
    fn elements_of<'e>(&mut self, e: &'e Expr) -> R<Option<Indexed<'e>>> {
        match &e.kind {
            ExprKind::Index(base, ix) => match self.locate(base)? {
                Loc::Array { elems, of, dims, .. } => Ok(Some((of, elems, dims, ix))),
                Loc::StructArray { .. } => Ok(None),
                _ => Err(type_error(base.span, format!("`{}` is not an array", ast::expr(base)))),
            },
            ExprKind::Member(inner, m) => {
                let mut path = vec![m];
                let mut cur: &Expr = inner;
                while let ExprKind::Member(b, mm) = &cur.kind {
                    path.push(mm);
                    cur = b;
                }
                let ExprKind::Index(base, ix) = &cur.kind else {
                    return Ok(None);
                };
                if ix.iter().all(|i| const_int(i).is_some()) {
                    return Ok(None);
                }
                let Loc::StructArray { elems, dims, .. } = self.locate(base)? else {
                    return Ok(None);
                };
                path.reverse();
                let mut places = Vec::new();
                let mut ty = Ty::Bool;
                for el in elems.iter() {
                    let mut l = el.clone();
                    for m in &path {
                        l = self.member_of(l, m)?;
                    }
                    match l {
                        Loc::Value { place, ty: t, .. } => {
                            places.push(place);
                            ty = t;
                        }
                        _ => {
                            return Err(not_supported(
                                e.span,
                                "with a computed index, a member of an element is read or written as one value".into(),
                            ));
                        }
                    }
                }
                Ok(Some((ty, places, dims, ix)))
            }
            _ => Ok(None),
        }
    }

    /// A member of a structure or of a function block instance.
    fn member_of(&mut self, l: Loc, m: &Ident) -> R<Loc> {
        match l {
            Loc::Struct { ty, members } => match members.into_iter().find(|(k, _)| m.is(k)) {
                Some((_, l)) => Ok(l),
                None => {
                    let names: Vec<&str> = ty.members.iter().map(|(k, ..)| k.as_str()).collect();
                    let mut d = Diagnostic::new(
                        Code::StName,
                        format!("{} has no member `{}`", ty.name, m.name),
                        m.span,
                        "member",
                    );
                    d = d.with_help(match closest(&m.name, names.iter().copied()) {
                        Some(c) => format!("did you mean `{c}`?"),
                        None => format!("{} has {}", ty.name, names.join(", ")),
                    });
                    Err(d)
                }
            },
            Loc::Fb { kind, name } => self.fb_member(kind, &name, m),
            Loc::User { fb, prefix } => self.user_member(&fb, &prefix, m),
            _ => Err(type_error(m.span, format!("`.{}`: this has no members", m.name))),
        }
    }

    /// A call of an element of an array of function block instances
    /// (`t[2](…)`, or `t[i](…)`: one branch per element).
    fn call_element(&mut self, base: &Expr, ix: &[Expr], args: &[Arg], callee: &Expr, span: Span) -> R<()> {
        let Loc::StructArray { elems, dims, .. } = self.locate(base)? else {
            return Err(type_error(
                base.span,
                format!("`{}` is not an array of function block instances", ast::expr(base)),
            ));
        };
        let inst = Ident {
            name: ast::expr(callee),
            span: callee.span,
        };
        match self.flat_index(&dims, ix, callee.span)? {
            Ok(k) => self.call_loc(elems[k].clone(), &inst, args, span),
            Err(flat) => {
                for (k, el) in elems.iter().cloned().enumerate() {
                    let kc = self.b.const_i(k as i32);
                    self.emit(Op::CmpI(Cmp::Ne, flat, kc));
                    let skip = self.emit(Op::Jmp(0));
                    self.emit(Op::True);
                    self.call_loc(el, &inst, args, span)?;
                    let next = self.rung(span);
                    self.patch(&[skip], next);
                }
                Ok(())
            }
        }
    }

    fn call_loc(&mut self, l: Loc, inst: &Ident, args: &[Arg], span: Span) -> R<()> {
        match l {
            Loc::Fb { kind, name } => self.fb_call(kind, &name, inst, args),
            Loc::User { fb, prefix } => match self.types.pous.get(&fb.to_ascii_lowercase()).copied() {
                Some(p) => self.inline_fb(p, &prefix, args, span, false),
                None => Err(self.unknown(inst, "function block")),
            },
            _ => Err(type_error(
                inst.span,
                format!("`{}` is not a function block instance", inst.name),
            )),
        }
    }

    fn array(&mut self, base: &Expr) -> R<ArrayParts> {
        match self.locate(base)? {
            Loc::Array { elems, of, dims, .. } => Ok((of, elems, dims)),
            _ => Err(type_error(base.span, format!("`{}` is not an array", ast::expr(base)))),
        }
    }

    /// The flat element number of constant indexes, or the slot holding it
    /// for computed ones (with range faults).
    fn flat_index(&mut self, dims: &[(i64, i64)], ix: &[Expr], span: Span) -> R<Result<usize, I>> {
        if ix.len() != dims.len() {
            return Err(type_error(
                span,
                format!("the array has {} dimension(s), not {}", dims.len(), ix.len()),
            ));
        }
        if let Some(consts) = ix.iter().map(const_int).collect::<Option<Vec<_>>>() {
            let mut flat = 0i64;
            for ((lo, hi), (v, e)) in dims.iter().zip(consts.iter().zip(ix)) {
                if v < lo || v > hi {
                    return Err(type_error(
                        e.span,
                        format!("the index {v} is outside the bounds {lo}..{hi}"),
                    ));
                }
                flat = flat * (hi - lo + 1) + (v - lo);
            }
            return Ok(Ok(flat as usize));
        }
        let flat = self.b.temp_i();
        let zero = self.b.const_i(0);
        self.emit(Op::CopyI(zero, flat));
        let bad = self.b.temp_b();
        self.emit(Op::Afi);
        self.emit(Op::Ote(bad));
        self.emit(Op::True);
        for ((lo, hi), e) in dims.iter().zip(ix) {
            let (v, ty) = self.eval(e, Some(&Ty::Dint))?;
            let Val::N(v) = v else {
                return Err(type_error(e.span, format!("an index is an integer, not {ty}")));
            };
            if !ty.is_int() || ty == Ty::Lint {
                return Err(type_error(e.span, format!("an index is SINT, INT or DINT, not {ty}")));
            }
            let V::I(v) = v else {
                return Err(type_error(e.span, "index".into()));
            };
            let (clo, chi) = (self.b.const_i(*lo as i32), self.b.const_i(*hi as i32));
            // Out of range: remember it, and count from the low bound.
            self.emit(Op::CmpI(Cmp::Lt, v, clo));
            self.emit(Op::Or(bad));
            self.emit(Op::Ote(bad));
            self.emit(Op::True);
            self.emit(Op::CmpI(Cmp::Gt, v, chi));
            self.emit(Op::Or(bad));
            self.emit(Op::Ote(bad));
            self.emit(Op::True);
            let size = self.b.const_i((hi - lo + 1) as i32);
            let off = self.b.temp_i();
            self.emit(Op::BinI(IBin::Sub, v, clo, off));
            self.emit(Op::BinI(IBin::Mul, flat, size, flat));
            self.emit(Op::BinI(IBin::Add, flat, off, flat));
        }
        // An index out of range is a range fault; the flat number then
        // matches no element, so nothing is read (0) or written.
        let junk = self.b.temp_i();
        let not_bcd = self.b.const_i(0xA);
        let minus = self.b.const_i(-1);
        self.emit(Op::Ld(bad));
        self.emit(Op::UnI(IUn::Frd, not_bcd, junk));
        self.emit(Op::UnI(IUn::Mov, minus, flat));
        self.emit(Op::True);
        Ok(Err(flat))
    }

    fn index_read(&mut self, elems: &[Place], dims: &[(i64, i64)], ix: &[Expr], of: &Ty, span: Span) -> R<Val> {
        match self.flat_index(dims, ix, span)? {
            Ok(k) => {
                let p = elems[k];
                Ok(if *of == Ty::Bool {
                    Val::B(self.b.bool_in(p, self.elem))
                } else {
                    Val::N(self.b.load(p, self.elem))
                })
            }
            Err(flat) => {
                if *of == Ty::Bool {
                    let t = self.b.temp_b();
                    self.emit(Op::Afi);
                    self.emit(Op::Ote(t));
                    self.emit(Op::True);
                    for (k, p) in elems.iter().enumerate() {
                        let kc = self.b.const_i(k as i32);
                        let src = self.b.bool_in(*p, self.elem);
                        self.emit(Op::CmpI(Cmp::Eq, flat, kc));
                        self.emit(Op::Xic(src));
                        self.emit(Op::Or(t));
                        self.emit(Op::Ote(t));
                        self.emit(Op::True);
                    }
                    Ok(Val::B(t))
                } else {
                    let t = self.b.temp(of.class());
                    let zero = self.b.constant(alba_model::Literal::Int(0), of.class());
                    self.b.un(IUn::Mov, zero, t, self.elem);
                    for (k, p) in elems.iter().enumerate() {
                        let kc = self.b.const_i(k as i32);
                        let src = self.b.load(*p, self.elem);
                        self.emit(Op::CmpI(Cmp::Eq, flat, kc));
                        self.b.un(IUn::Mov, src, t, self.elem);
                        self.emit(Op::True);
                    }
                    Ok(Val::N(t))
                }
            }
        }
    }

    /// Converts a value of a type that widens to `ty` into `ty`'s class.
    fn fit(&mut self, v: Val, e: &Expr, ty: &Ty) -> R<V> {
        match v {
            Val::N(x) => Ok(self.b.convert(x, ty.class(), self.elem)),
            Val::B(_) => Err(type_error(e.span, format!("a BOOL where a {ty} is wanted"))),
        }
    }

    /// Stores a value of type `ty` into `place`.
    fn store(&mut self, place: Place, v: Val, ty: &Ty) {
        match v {
            Val::B(src) => {
                let (d, post) = self.b.bool_out(place, self.elem);
                self.emit(Op::CopyB(src, d));
                self.b.post(post, self.elem);
            }
            Val::N(x) => {
                let class = ty.class();
                let x = self.b.convert(x, class, self.elem);
                let (d, post) = self.b.dest(place, class, self.elem);
                self.b.un(IUn::Mov, x, d, self.elem);
                self.b.post(post, self.elem);
            }
        }
    }

    fn assign(&mut self, lhs: &Expr, rhs: &Expr) -> R<()> {
        // A whole structure: copied member by member.
        let maybe_struct = match &lhs.kind {
            ExprKind::Name(n) => {
                let k = n.name.to_ascii_lowercase();
                self.aliases.get(&k).is_some_and(|l| matches!(l, Loc::Struct { .. }))
                    || self.vars.get(&k).is_some_and(|v| matches!(v.ty, Ty::Struct(_)))
            }
            ExprKind::Member(..) => true,
            ExprKind::Index(base, _) => match &base.kind {
                ExprKind::Name(n) => {
                    let k = n.name.to_ascii_lowercase();
                    self.aliases
                        .get(&k)
                        .is_some_and(|l| matches!(l, Loc::StructArray { .. }))
                        || self
                            .vars
                            .get(&k)
                            .is_some_and(|v| matches!(&v.ty, Ty::Array(of, _) if matches!(**of, Ty::Struct(_))))
                }
                _ => false,
            },
            _ => false,
        };
        if maybe_struct && let Ok(dst @ (Loc::Struct { .. } | Loc::StructArray { .. })) = self.locate(lhs) {
            let src = self.locate(rhs)?;
            let (dt, st) = (loc_type(&dst), loc_type(&src));
            if dt != st {
                return Err(type_error(
                    rhs.span,
                    format!(
                        "cannot assign {} to `{}`, {}",
                        st.map_or("this".into(), |t| an(&t)),
                        ast::expr(lhs),
                        dt.map_or("a structure".into(), |t| an(&t))
                    ),
                ));
            }
            if let Loc::Struct { members, .. } = &dst
                && members.iter().any(|(_, l)| matches!(l, Loc::Value { access, constant, .. } if *access != Access::ReadWrite || *constant))
            {
                return Err(Diagnostic::new(
                    Code::NotWritable,
                    format!("`{}` cannot be written", ast::expr(lhs)),
                    lhs.span,
                    "not writable",
                ));
            }
            self.copy_loc(&dst, &src);
            return Ok(());
        }
        self.assign_with(lhs, rhs.span, &mut |l: &mut Self, hint| l.eval(rhs, hint))
    }

    /// Assigns to `lhs` the value `value` computes (given the type wanted).
    fn assign_with(&mut self, lhs: &Expr, rspan: Span, value: &mut ValueOf<'_, Self>) -> R<()> {
        if let Some((of, elems, dims, ix)) = self.elements_of(lhs)? {
            let (v, ty) = value(self, Some(&of.value()))?;
            if !widens(&ty, &of) {
                return Err(type_error(
                    rspan,
                    format!("cannot assign {} to {} element; convert it", an(&ty), an(&of)),
                ));
            }
            let v = match v {
                Val::N(x) => Val::N(self.b.convert(x, of.class(), self.elem)),
                b => b,
            };
            return match self.flat_index(&dims, ix, lhs.span)? {
                Ok(k) => {
                    self.store_checked(elems[k], v, &of);
                    Ok(())
                }
                Err(flat) => {
                    if let (Ty::Sub(_, lo, hi), Val::N(x)) = (&of, v) {
                        // Out of the subrange: a fault, and no element written.
                        let (clo, chi) = (
                            self.b.constant(alba_model::Literal::Int(*lo), of.class()),
                            self.b.constant(alba_model::Literal::Int(*hi), of.class()),
                        );
                        let bad = self.b.temp_b();
                        self.cmp(Cmp::Lt, x, clo);
                        self.emit(Op::Ote(bad));
                        self.emit(Op::True);
                        self.cmp(Cmp::Gt, x, chi);
                        self.emit(Op::Or(bad));
                        self.emit(Op::Ote(bad));
                        self.emit(Op::True);
                        self.range_fault(bad);
                        let minus = self.b.const_i(-1);
                        self.emit(Op::Ld(bad));
                        self.emit(Op::UnI(IUn::Mov, minus, flat));
                        self.emit(Op::True);
                    }
                    for (k, p) in elems.iter().enumerate() {
                        let kc = self.b.const_i(k as i32);
                        match (v, *p) {
                            (Val::B(src), Place::Bool(d)) => {
                                self.emit(Op::CmpI(Cmp::Eq, flat, kc));
                                self.emit(Op::Xic(src));
                                self.emit(Op::Otl(d));
                                self.emit(Op::True);
                                self.emit(Op::CmpI(Cmp::Eq, flat, kc));
                                self.emit(Op::Xio(src));
                                self.emit(Op::Otu(d));
                                self.emit(Op::True);
                            }
                            (Val::N(x), p) => {
                                let (d, post) = self.b.dest(p, of.class(), self.elem);
                                self.emit(Op::CmpI(Cmp::Eq, flat, kc));
                                self.b.un(IUn::Mov, x, d, self.elem);
                                self.b.post(post, self.elem);
                                self.emit(Op::True);
                            }
                            _ => {}
                        }
                    }
                    Ok(())
                }
            };
        }
        let loc = self.locate(lhs)?;
        if let Loc::Bit {
            place,
            access,
            ty,
            bit,
            constant,
        } = &loc
        {
            if *constant || *access != Access::ReadWrite {
                return Err(Diagnostic::new(
                    Code::NotWritable,
                    format!("`{}` cannot be written", ast::expr(lhs)),
                    lhs.span,
                    "not writable",
                ));
            }
            let (v, vty) = value(self, Some(&Ty::Bool))?;
            let Val::B(v) = v else {
                return Err(type_error(rspan, format!("a bit is a BOOL, not {}", an(&vty))));
            };
            let x = self.b.load(*place, self.elem);
            let c = vclass(x);
            let mask = self.bit_mask(ty, *bit, c);
            let t = self.b.temp(c);
            self.b.un(IUn::Mov, x, t, self.elem);
            let notmask = self.b.temp(c);
            self.b.un(IUn::Not, mask, notmask, self.elem);
            self.emit(Op::Ld(v));
            self.b.bin(IBin::Or, t, mask, t, self.elem);
            self.emit(Op::Ldn(v));
            self.b.bin(IBin::And, t, notmask, t, self.elem);
            self.emit(Op::True);
            let (place, ty) = (*place, ty.clone());
            self.store(place, Val::N(t), &ty);
            return Ok(());
        }
        let (place, access, ty, constant) = match loc {
            Loc::Value {
                place,
                access,
                ty,
                constant,
            } => (place, access, ty, constant),
            Loc::CounterQ { .. } => (Place::Bool(B(0)), Access::ReadOnly, Ty::Bool, false),
            _ => {
                return Err(type_error(
                    lhs.span,
                    format!("`{}` cannot be assigned as a whole", ast::expr(lhs)),
                ));
            }
        };
        if constant {
            return Err(decl_error(lhs.span, format!("`{}` is CONSTANT", ast::expr(lhs))));
        }
        if access != Access::ReadWrite {
            let why = if access == Access::ReadOnly && matches!(lhs.kind, ExprKind::Member(..)) {
                "it is an output of a function block or a status member".to_string()
            } else {
                access.why_not_writable().to_string()
            };
            return Err(Diagnostic::new(
                Code::NotWritable,
                format!("`{}` cannot be written: {why}", ast::expr(lhs)),
                lhs.span,
                "not writable",
            ));
        }
        let (v, vty) = value(self, Some(&ty.value()))?;
        if !widens(&vty, &ty) {
            return Err(type_error(
                rspan,
                format!(
                    "cannot assign {} to `{}`, {}; convert it (for example {vty}_TO_{ty})",
                    an(&vty),
                    ast::expr(lhs),
                    an(&ty)
                ),
            ));
        }
        self.store_checked(place, v, &ty);
        Ok(())
    }

    /// Inputs of a call by formal name (or position), checked against `params`.
    fn bind<'e>(
        &self,
        fname: &str,
        params: &[(&'static str, P)],
        outs: &[(&'static str, P)],
        args: &'e [Arg],
    ) -> R<Bound<'e>> {
        let mut ins = vec![None; params.len()];
        let mut outputs = Vec::new();
        for (k, a) in args.iter().enumerate() {
            match &a.name {
                None => {
                    if k >= params.len() {
                        return Err(type_error(
                            a.value.span,
                            format!("{fname} takes {} input(s)", params.len()),
                        ));
                    }
                    ins[k] = Some(&a.value);
                }
                Some(n) if a.output => {
                    let Some(i) = outs.iter().position(|(p, _)| n.is(p)) else {
                        let names: Vec<_> = outs.iter().map(|(p, _)| *p).collect();
                        let mut d = Diagnostic::new(
                            Code::StName,
                            format!("{fname} has no output `{}`", n.name),
                            n.span,
                            "output",
                        );
                        d = d.with_help(match closest(&n.name, names.iter().copied()) {
                            Some(s) => format!("did you mean `{s}`?"),
                            None => format!("its outputs: {}", names.join(", ")),
                        });
                        return Err(d);
                    };
                    outputs.push((i, a));
                }
                Some(n) => {
                    let Some(i) = params.iter().position(|(p, _)| n.is(p)) else {
                        let names: Vec<_> = params.iter().map(|(p, _)| *p).collect();
                        let mut d = Diagnostic::new(
                            Code::StName,
                            format!("{fname} has no input `{}`", n.name),
                            n.span,
                            "input",
                        );
                        d = d.with_help(match closest(&n.name, names.iter().copied()) {
                            Some(s) => format!("did you mean `{s}`?"),
                            None => format!("its inputs: {}", names.join(", ")),
                        });
                        return Err(d);
                    };
                    if ins[i].is_some() {
                        return Err(type_error(n.span, format!("`{}` is given twice", n.name)));
                    }
                    ins[i] = Some(&a.value);
                }
            }
        }
        Ok((ins, outputs))
    }

    /// An input value of type `ty`.
    fn input(&mut self, e: &Expr, ty: &Ty, fname: &str, pname: &str) -> R<Val> {
        let (v, vty) = self.eval(e, Some(ty))?;
        if !widens(&vty, ty) {
            return Err(type_error(e.span, format!("{fname}.{pname} is a {ty}, not a {vty}")));
        }
        Ok(match v {
            Val::N(x) => Val::N(self.b.convert(x, ty.class(), self.elem)),
            b => b,
        })
    }

    fn fb_call(&mut self, kind: Fb, name: &str, inst: &Ident, args: &[Arg]) -> R<()> {
        let (params, outs) = kind.params();
        let fname = format!("{} `{}`", kind.name(), inst.name);
        let (ins, outputs) = self.bind(&fname, params, outs, args)?;
        let mut vals = Vec::new();
        for (k, e) in ins.iter().enumerate() {
            vals.push(match e {
                Some(e) => Some(self.input(e, &params[k].1.ty(), kind.name(), params[k].0)?),
                None => None,
            });
        }
        let bool_of = |v: &Option<Val>| match v {
            Some(Val::B(b)) => Some(*b),
            _ => None,
        };
        let int_of = |v: &Option<Val>| match v {
            Some(Val::N(V::I(i))) => Some(*i),
            _ => None,
        };
        let layout = self.b.layout();
        match kind {
            Fb::Ton | Fb::Tof | Fb::Tp => {
                let Ok(Target::Timer(t)) = layout.resolve(name) else {
                    return Err(self.unknown(inst, "timer"));
                };
                if let Some(pt) = int_of(&vals[1]) {
                    self.emit(Op::CopyI(pt, t.i));
                }
                // IN not given: the input of the last call (EN).
                let input = bool_of(&vals[0]).unwrap_or(t.b);
                self.emit(Op::Ld(input));
                self.emit(match kind {
                    Fb::Ton => Op::Ton(t, alba_ir::TimeBase::Ms),
                    Fb::Tof => Op::Tof(t, alba_ir::TimeBase::Ms),
                    _ => Op::Tp(t),
                });
                self.emit(Op::True);
            }
            Fb::Ctu | Fb::Ctd | Fb::Ctud => {
                let Ok(Target::Counter(c)) = layout.resolve(name) else {
                    return Err(self.unknown(inst, "counter"));
                };
                if let Some(pv) = int_of(&vals[params.len() - 1]) {
                    self.emit(Op::CopyI(pv, c.i));
                }
                let acc = I(c.i.0 + 1);
                let (cu, cd, r, ld) = match kind {
                    Fb::Ctu => (bool_of(&vals[0]), None, bool_of(&vals[1]), None),
                    Fb::Ctd => (None, bool_of(&vals[0]), None, bool_of(&vals[1])),
                    _ => (
                        bool_of(&vals[0]),
                        bool_of(&vals[1]),
                        bool_of(&vals[2]),
                        bool_of(&vals[3]),
                    ),
                };
                let (cu_mem, cd_mem) = (c.b, B(c.b.0 + 1));
                if kind != Fb::Ctd {
                    self.emit(Op::Ld(cu.unwrap_or(cu_mem)));
                    self.emit(Op::Ctu(c));
                    self.emit(Op::True);
                }
                if kind != Fb::Ctu {
                    self.emit(Op::Ld(cd.unwrap_or(cd_mem)));
                    self.emit(Op::Ctd(c));
                    self.emit(Op::True);
                }
                if let Some(ld) = ld {
                    self.emit(Op::Ld(ld));
                    self.emit(Op::UnI(IUn::Mov, c.i, acc));
                    self.emit(Op::True);
                }
                if let Some(r) = r {
                    // RES clears the edge memories too: keep them as the inputs are.
                    let (su, sd) = (self.b.temp_b(), self.b.temp_b());
                    self.emit(Op::CopyB(cu_mem, su));
                    self.emit(Op::CopyB(cd_mem, sd));
                    self.emit(Op::Ld(r));
                    self.emit(Op::ResC(c));
                    self.emit(Op::True);
                    self.emit(Op::CopyB(su, cu_mem));
                    self.emit(Op::CopyB(sd, cd_mem));
                }
            }
            Fb::RTrig | Fb::FTrig => {
                let q = self.bool_tag(&format!("{name}.Q"), inst)?;
                let m = self.bool_tag(&format!("{name}.M"), inst)?;
                let clk = bool_of(&vals[0]).unwrap_or(m);
                self.emit(Op::Ld(clk));
                // The one-shots take (storage, output).
                self.emit(if kind == Fb::RTrig {
                    Op::Osr(m, q)
                } else {
                    Op::Osf(m, q)
                });
                self.emit(Op::True);
            }
            Fb::Sr | Fb::Rs => {
                let q = self.bool_tag(&format!("{name}.Q1"), inst)?;
                let f = self.b.temp_b();
                self.emit(Op::Afi);
                self.emit(Op::Ote(f));
                self.emit(Op::True);
                let (set, reset) = (bool_of(&vals[0]).unwrap_or(f), bool_of(&vals[1]).unwrap_or(f));
                if kind == Fb::Sr {
                    // Q1 := S1 OR (NOT R AND Q1)
                    self.emit(Op::Ld(q));
                    self.emit(Op::Xio(reset));
                    self.emit(Op::Or(set));
                } else {
                    // Q1 := NOT R1 AND (S OR Q1)
                    self.emit(Op::Ld(set));
                    self.emit(Op::Or(q));
                    self.emit(Op::Xio(reset));
                }
                self.emit(Op::Ote(q));
                self.emit(Op::True);
            }
        }
        // Outputs `Q => x`.
        for (k, a) in outputs {
            let (oname, _) = outs[k];
            let member = Ident {
                name: oname.to_string(),
                span: a.name.as_ref().map_or(a.value.span, |n| n.span),
            };
            let src = self.fb_member(kind, name, &member)?;
            self.assign_output(a, &src)?;
        }
        Ok(())
    }

    fn bool_tag(&self, name: &str, inst: &Ident) -> R<B> {
        match self.b.layout().resolve(name) {
            Ok(Target::Value {
                place: Place::Bool(b), ..
            }) => Ok(b),
            _ => Err(self.unknown(inst, "instance")),
        }
    }

    /// A standard function (or a conversion) called in an expression.
    fn call(&mut self, n: &Ident, args: &[Arg], hint: Option<&Ty>, span: Span) -> R<(Val, Ty)> {
        let up = n.name.to_ascii_uppercase();
        let positional: Vec<&Expr> = args.iter().filter(|a| !a.output).map(|a| &a.value).collect();
        let arity = |k: usize| -> R<()> {
            if positional.len() == k {
                Ok(())
            } else {
                Err(type_error(
                    span,
                    format!("{up} takes {k} argument(s), not {}", positional.len()),
                ))
            }
        };
        if up == "MOVE" {
            arity(1)?;
            return self.eval(positional[0], hint);
        }
        // BCD: `WORD_BCD_TO_INT`, `INT_TO_BCD_WORD` (the engine's FRD and TOD:
        // a nibble above 9, or a value out of the BCD range, is a range fault).
        let bcd = match up.split_once("_TO_") {
            Some((from, to)) if from.ends_with("_BCD") => Some((from.trim_end_matches("_BCD"), to, IUn::Frd)),
            Some((from, to)) if to.starts_with("BCD_") => Some((from, to.trim_start_matches("BCD_"), IUn::Tod)),
            _ => None,
        };
        if let Some((from, to, op)) = bcd {
            arity(1)?;
            let (Some(from_ty), Some(to_ty)) = (elementary(from), elementary(to)) else {
                return Err(not_supported(n.span, format!("{up}: unknown types")));
            };
            let ok = if op == IUn::Frd {
                from_ty.is_bits() && to_ty.is_int()
            } else {
                from_ty.is_int() && to_ty.is_bits()
            };
            if !ok {
                return Err(type_error(
                    n.span,
                    format!("{up}: BCD conversions are between a bit string and an integer"),
                ));
            }
            let (v, ty) = self.eval(positional[0], Some(&from_ty))?;
            let Val::N(x) = v else {
                return Err(type_error(
                    positional[0].span,
                    format!("{up} takes a {from_ty}, not BOOL"),
                ));
            };
            if ty != from_ty {
                return Err(type_error(
                    positional[0].span,
                    format!("{up} takes a {from_ty}, not a {ty}"),
                ));
            }
            let x = self.b.convert(x, Class::L, self.elem);
            let t = self.b.temp(Class::L);
            self.b.un(op, x, t, self.elem);
            let r = self.convert(Val::N(t), &Ty::Lint, &to_ty);
            return Ok((r, to_ty));
        }
        // X_TO_Y conversions (and TRUNC).
        if let Some((from, to)) = up.split_once("_TO_") {
            arity(1)?;
            let to_ty =
                elementary(to).ok_or_else(|| not_supported(n.span, format!("{up}: {to} is not supported yet")))?;
            let from_ty =
                elementary(from).ok_or_else(|| not_supported(n.span, format!("{up}: {from} is not supported yet")))?;
            let (v, ty) = self.eval(positional[0], Some(&from_ty))?;
            if ty != from_ty {
                return Err(type_error(
                    positional[0].span,
                    format!("{up} takes a {from_ty}, not a {ty}"),
                ));
            }
            return Ok((self.convert(v, &from_ty, &to_ty), to_ty));
        }
        if up == "TRUNC" {
            arity(1)?;
            let (v, ty) = self.eval(positional[0], Some(&Ty::Real))?;
            let Val::N(x) = v else {
                return Err(type_error(span, "TRUNC takes a REAL".into()));
            };
            if !ty.is_real() {
                return Err(type_error(
                    positional[0].span,
                    format!("TRUNC takes a REAL or LREAL, not {ty}"),
                ));
            }
            let t = self.b.temp(ty.class());
            self.b.un(IUn::Trunc, x, t, self.elem);
            let r = self.b.convert(t, Class::I, self.elem);
            return Ok((Val::N(r), Ty::Dint));
        }
        let real_fn = match up.as_str() {
            "SQRT" => Some(IUn::Sqrt),
            "LN" => Some(IUn::Ln),
            "LOG" => Some(IUn::Log),
            "SIN" => Some(IUn::Sin),
            "COS" => Some(IUn::Cos),
            "TAN" => Some(IUn::Tan),
            "ASIN" => Some(IUn::Asin),
            "ACOS" => Some(IUn::Acos),
            "ATAN" => Some(IUn::Atan),
            _ => None,
        };
        if let Some(f) = real_fn.or((up == "ABS").then_some(IUn::Abs)) {
            arity(1)?;
            let h = hint
                .filter(|h| h.is_real() || (up == "ABS" && h.is_num()))
                .cloned()
                .unwrap_or(Ty::Real);
            let (v, ty) = self.eval(positional[0], Some(&h))?;
            let ok = if up == "ABS" { ty.is_num() } else { ty.is_real() };
            let Val::N(x) = v else {
                return Err(type_error(positional[0].span, format!("{up} takes a number, not BOOL")));
            };
            if !ok {
                return Err(type_error(
                    positional[0].span,
                    format!("{up} takes a REAL or LREAL, not {ty}; convert it ({ty}_TO_REAL)"),
                ));
            }
            let t = self.b.temp(ty.class());
            self.b.un(f, x, t, self.elem);
            self.narrow(t, &ty);
            return Ok((Val::N(t), ty));
        }
        if up == "EXP" || up == "EXPT" {
            arity(if up == "EXP" { 1 } else { 2 })?;
            let h = hint.filter(|h| h.is_real()).cloned().unwrap_or(Ty::Real);
            let (base, exp) = if up == "EXP" {
                let e = self.constant(&Lit::Real(std::f64::consts::E, None), &h);
                let (x, tx) = self.eval(positional[0], Some(&h))?;
                ((e, h.clone()), (x, tx))
            } else {
                let a = self.eval(positional[0], Some(&h))?;
                let b = self.eval(positional[1], Some(&a.1))?;
                (a, b)
            };
            let ty = if widens(&exp.1, &base.1) {
                base.1.clone()
            } else {
                exp.1.clone()
            };
            if !ty.is_real() || !widens(&base.1, &ty) || !widens(&exp.1, &ty) {
                return Err(type_error(
                    span,
                    format!("{up} takes REAL or LREAL operands, not {} and {}", base.1, exp.1),
                ));
            }
            let x = self.fit(base.0, positional[0], &ty)?;
            let y = self.fit(exp.0, positional[positional.len() - 1], &ty)?;
            let t = self.b.temp(ty.class());
            self.b.bin(IBin::Pow, x, y, t, self.elem);
            return Ok((Val::N(t), ty));
        }
        match up.as_str() {
            "MIN" | "MAX" | "LIMIT" | "SEL" | "MUX" => return self.selection(&up, &positional, hint, span),
            _ => {}
        }
        if let Some(p) = self.types.pous.get(&n.name.to_ascii_lowercase()).copied() {
            if p.kind == PouKind::Function {
                return self.inline_function(p, args, span, false);
            }
            return Err(type_error(
                n.span,
                format!(
                    "`{}` is a FUNCTION_BLOCK type: declare an instance (`x : {};`) and call the instance",
                    n.name, p.name.name
                ),
            ));
        }
        if ["SHL", "SHR", "ROL", "ROR"].contains(&up.as_str()) {
            arity(2)?;
            let h = hint.filter(|h| h.is_bits()).cloned();
            let (v, ty) = self.eval(positional[0], h.as_ref())?;
            let (Val::N(x), Some(w), true) = (v, ty.bits(), ty.is_bits()) else {
                return Err(type_error(
                    positional[0].span,
                    format!("{up} shifts a bit string (BYTE … LWORD), not {}", an(&ty)),
                ));
            };
            let (nv, nty) = self.eval(positional[1], Some(&Ty::Int))?;
            let Val::N(n) = nv else {
                return Err(type_error(
                    positional[1].span,
                    format!("{up}'s N is an integer, not BOOL"),
                ));
            };
            if !nty.is_int() {
                return Err(type_error(
                    positional[1].span,
                    format!("{up}'s N is an integer, not {nty}"),
                ));
            }
            let r = match const_int(positional[1]) {
                Some(k) if k >= 0 => self.shift_const(&up, x, k.min(1024) as u32, w),
                _ => {
                    let V::I(n) = self.b.convert(n, Class::I, self.elem) else {
                        return Err(type_error(positional[1].span, "N".into()));
                    };
                    self.shift_var(&up, x, n, w)
                }
            };
            return Ok((Val::N(r), ty));
        }
        if [
            "LEN", "LEFT", "RIGHT", "MID", "CONCAT", "INSERT", "DELETE", "REPLACE", "FIND",
        ]
        .contains(&up.as_str())
        {
            return Err(not_supported(
                n.span,
                format!("{up} is not supported yet (strings have no form in the engine)"),
            ));
        }
        let known = [
            "ABS",
            "SQRT",
            "LN",
            "LOG",
            "EXP",
            "EXPT",
            "SIN",
            "COS",
            "TAN",
            "ASIN",
            "ACOS",
            "ATAN",
            "TRUNC",
            "MIN",
            "MAX",
            "LIMIT",
            "SEL",
            "MUX",
            "INT_TO_REAL",
            "REAL_TO_INT",
            "DINT_TO_REAL",
            "REAL_TO_DINT",
            "BOOL_TO_INT",
            "INT_TO_BOOL",
            "TIME_TO_DINT",
            "DINT_TO_TIME",
        ];
        if let Ok(Loc::Fb { .. } | Loc::User { .. }) = self.lookup(n) {
            return Err(type_error(
                n.span,
                format!(
                    "`{}` is a function block instance: call it as a statement (`{}(…);`) and read its outputs",
                    n.name, n.name
                ),
            ));
        }
        let mut names = self.known_names();
        names.extend(self.types.pous.values().map(|p| p.name.name.clone()));
        let mut d = Diagnostic::new(
            Code::StName,
            format!("unknown function `{}`", n.name),
            n.span,
            "function",
        );
        if let Some(s) = closest(&n.name, known.iter().copied().chain(names.iter().map(String::as_str))) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        Err(d)
    }

    /// `x` (of class I or L) with only its low `w` bits, in a new slot.
    fn wrap_bits(&mut self, x: V, w: u32) -> V {
        let c = vclass(x);
        let t = self.b.temp(c);
        if w >= 64 {
            self.b.un(IUn::Mov, x, t, self.elem);
        } else {
            let m = self.b.constant(alba_model::Literal::Int((1i64 << w) - 1), c);
            self.b.bin(IBin::And, x, m, t, self.elem);
        }
        t
    }

    fn int_const(&mut self, v: i64, c: Class) -> V {
        self.b.constant(alba_model::Literal::Int(v), c)
    }

    /// The mask of bit `bit` of a value of `ty` in class `c` (a signed
    /// type's sign bit sign-extended, so setting it stays in range).
    fn bit_mask(&mut self, ty: &Ty, bit: u32, c: Class) -> V {
        let w = match ty {
            Ty::Sint => 8,
            Ty::Int => 16,
            Ty::Dint => 32,
            _ => 64,
        };
        let m = if bit + 1 == w && w < 64 {
            -(1i64 << bit)
        } else {
            1i64 << bit
        };
        self.int_const(m, c)
    }

    /// `AND`, `OR`, `XOR` of two bit strings.
    fn bitwise(&mut self, op: BinOp, (x, ta): (V, &Ty), (y, tb): (V, &Ty), span: Span) -> R<(Val, Ty)> {
        let ty = if widens(ta, tb) { tb.clone() } else { ta.clone() };
        if !(ta.is_bits() && tb.is_bits() && widens(ta, &ty) && widens(tb, &ty)) {
            return Err(type_error(
                span,
                format!(
                    "{} takes BOOL operands or bit strings (BYTE … LWORD) of one type, not {ta} and {tb}",
                    op.text()
                ),
            ));
        }
        let c = ty.class();
        let x = self.b.convert(x, c, self.elem);
        let y = self.b.convert(y, c, self.elem);
        let t = self.b.temp(c);
        let iop = match op {
            BinOp::And => IBin::And,
            BinOp::Or => IBin::Or,
            _ => IBin::Xor,
        };
        self.b.bin(iop, x, y, t, self.elem);
        Ok((Val::N(t), ty))
    }

    /// `SHL`/`SHR`/`ROL`/`ROR` of a `w`-bit string by a constant.
    fn shift_const(&mut self, f: &str, x: V, s: u32, w: u32) -> V {
        match f {
            "SHL" => self.shl(x, s, w),
            "SHR" => self.shr(x, s, w),
            "ROL" => self.rol(x, s % w, w),
            _ => self.rol(x, (w - s % w) % w, w),
        }
    }

    /// `x` shifted left by `s` within `w` bits (values of fewer than 64 bits
    /// are never negative; LWORD's top bit is the sign of its slot).
    fn shl(&mut self, x: V, s: u32, w: u32) -> V {
        let c = vclass(x);
        let t = self.b.temp(c);
        if s >= w {
            let z = self.int_const(0, c);
            self.b.un(IUn::Mov, z, t, self.elem);
            return t;
        }
        if s == 0 {
            self.b.un(IUn::Mov, x, t, self.elem);
            return t;
        }
        let keep = w - s;
        let p = self.int_const(1i64 << s, c);
        if w < 64 {
            let m = self.int_const((1i64 << keep) - 1, c);
            self.b.bin(IBin::And, x, m, t, self.elem);
            self.b.bin(IBin::Mul, t, p, t, self.elem);
            return t;
        }
        // 64 bits: the bits below the one reaching bit 63 move by a product;
        // that one becomes the sign.
        let m = self.int_const((1i64 << (keep - 1)) - 1, c);
        self.b.bin(IBin::And, x, m, t, self.elem);
        self.b.bin(IBin::Mul, t, p, t, self.elem);
        let top = self.int_const(1i64 << (keep - 1), c);
        let (zero, min) = (self.int_const(0, c), self.int_const(i64::MIN, c));
        let tb = self.b.temp(c);
        self.b.bin(IBin::And, x, top, tb, self.elem);
        self.cmp(Cmp::Ne, tb, zero);
        self.b.bin(IBin::Or, t, min, t, self.elem);
        self.emit(Op::True);
        t
    }

    /// `x` shifted right by `s` within `w` bits, zeros coming in.
    fn shr(&mut self, x: V, s: u32, w: u32) -> V {
        let c = vclass(x);
        let t = self.b.temp(c);
        if s >= w {
            let z = self.int_const(0, c);
            self.b.un(IUn::Mov, z, t, self.elem);
            return t;
        }
        if s == 0 {
            self.b.un(IUn::Mov, x, t, self.elem);
            return t;
        }
        let p = self.int_const(1i64 << s, c);
        if w < 64 {
            self.b.bin(IBin::Div, x, p, t, self.elem);
            return t;
        }
        // 64 bits: without the sign, divided; the sign bit comes back at 63 - s.
        let max = self.int_const(i64::MAX, c);
        self.b.bin(IBin::And, x, max, t, self.elem);
        self.b.bin(IBin::Div, t, p, t, self.elem);
        let (zero, bit) = (self.int_const(0, c), self.int_const(1i64 << (63 - s), c));
        self.cmp(Cmp::Lt, x, zero);
        self.b.bin(IBin::Or, t, bit, t, self.elem);
        self.emit(Op::True);
        t
    }

    /// `x` rotated left by `s` (0 ≤ s < w) within `w` bits.
    fn rol(&mut self, x: V, s: u32, w: u32) -> V {
        if s == 0 {
            return self.shl(x, 0, w);
        }
        let a = self.shl(x, s, w);
        let b = self.shr(x, w - s, w);
        let t = self.b.temp(vclass(x));
        self.b.bin(IBin::Or, a, b, t, self.elem);
        t
    }

    /// A shift or rotation by a computed amount `n`: by each power of two
    /// of its bits in turn. SHL/SHR by `n ≥ w` give 0, by `n < 0` the value
    /// unchanged; rotations take `n` modulo `w`.
    fn shift_var(&mut self, f: &str, x: V, n: I, w: u32) -> V {
        let c = vclass(x);
        let r = self.b.temp(c);
        self.b.un(IUn::Mov, x, r, self.elem);
        let rotate = f == "ROL" || f == "ROR";
        let zero = self.b.const_i(0);
        let amount = if rotate {
            let wc = self.b.const_i(w as i32);
            let m = self.b.temp_i();
            self.emit(Op::BinI(IBin::Mod, n, wc, m));
            self.emit(Op::BinI(IBin::Add, m, wc, m));
            self.emit(Op::BinI(IBin::Mod, m, wc, m));
            m
        } else {
            n
        };
        let mut k = 1u32;
        while k < w {
            let shifted = self.shift_const(f, r, k, w);
            let bit = self.b.const_i(k as i32);
            let tb = self.b.temp_i();
            self.emit(Op::BinI(IBin::And, amount, bit, tb));
            self.emit(Op::CmpI(Cmp::Ne, tb, zero));
            self.b.un(IUn::Mov, shifted, r, self.elem);
            self.emit(Op::True);
            k *= 2;
        }
        if !rotate {
            let wc = self.b.const_i(w as i32);
            let z = self.int_const(0, c);
            self.emit(Op::CmpI(Cmp::Ge, n, wc));
            self.b.un(IUn::Mov, z, r, self.elem);
            self.emit(Op::True);
            self.emit(Op::CmpI(Cmp::Lt, n, zero));
            self.b.un(IUn::Mov, x, r, self.elem);
            self.emit(Op::True);
        }
        r
    }

    fn convert(&mut self, v: Val, from: &Ty, to: &Ty) -> Val {
        match (v, to) {
            (Val::B(b), Ty::Bool) => Val::B(b),
            (Val::B(b), to) => {
                let t = self.b.temp(to.class());
                let zero = self.b.constant(alba_model::Literal::Int(0), to.class());
                let one = self.b.constant(alba_model::Literal::Int(1), to.class());
                self.b.un(IUn::Mov, zero, t, self.elem);
                self.emit(Op::Ld(b));
                self.b.un(IUn::Mov, one, t, self.elem);
                self.emit(Op::True);
                Val::N(t)
            }
            (Val::N(x), Ty::Bool) => {
                let zero = self.b.constant(alba_model::Literal::Int(0), from.class());
                let t = self.b.temp_b();
                self.cmp(Cmp::Ne, x, zero);
                self.emit(Op::Ote(t));
                self.emit(Op::True);
                Val::B(t)
            }
            (Val::N(x), to) if to.bits().is_some_and(|w| w < 64) => {
                // Into an unsigned integer or a bit string: the low bits
                // (negative values wrap as two's complement).
                let l = self.b.convert(x, Class::L, self.elem);
                let l = self.wrap_bits(l, to.bits().unwrap_or(64));
                Val::N(self.b.convert(l, to.class(), self.elem))
            }
            (Val::N(x), to) => {
                let y = self.b.convert(x, to.class(), self.elem);
                // Into a new slot when narrowing, so the source is not changed.
                let y = if y == x && from.rank() > to.rank() && matches!(to, Ty::Sint | Ty::Int) {
                    let t = self.b.temp(to.class());
                    self.b.un(IUn::Mov, x, t, self.elem);
                    t
                } else {
                    y
                };
                self.narrow(y, to);
                Val::N(y)
            }
        }
    }

    fn selection(&mut self, f: &str, args: &[&Expr], hint: Option<&Ty>, span: Span) -> R<(Val, Ty)> {
        let (choices, pre): (&[&Expr], Option<&Expr>) = match f {
            "SEL" | "MUX" => match args.split_first() {
                Some((g, rest)) => (rest, Some(*g)),
                None => (&[], None),
            },
            _ => (args, None),
        };
        let need = match f {
            "SEL" => 2,
            "LIMIT" => 3,
            _ => 2,
        };
        if choices.len() < need || (f == "SEL" && choices.len() != 2) || (f == "LIMIT" && choices.len() != 3) {
            let count = match f {
                "SEL" | "LIMIT" => "3".to_string(),
                _ => format!("at least {}", need + usize::from(pre.is_some())),
            };
            return Err(type_error(span, format!("{f} takes {count} arguments")));
        }
        let guard = match pre {
            Some(g) => {
                let want = if f == "SEL" { Ty::Bool } else { Ty::Dint };
                let (v, ty) = self.eval(g, Some(&want))?;
                if (f == "SEL" && ty != Ty::Bool) || (f == "MUX" && !ty.is_int()) {
                    let what = if f == "SEL" { "BOOL" } else { "an integer" };
                    return Err(type_error(g.span, format!("{f}'s first argument is {what}, not {ty}")));
                }
                Some(v)
            }
            None => None,
        };
        let mut vals = Vec::new();
        for e in choices {
            let h = vals.first().map(|(_, t): &(Val, Ty)| t.clone()).or(hint.cloned());
            vals.push(self.eval(e, h.as_ref())?);
        }
        let mut ty = vals[0].1.clone();
        for (_, t) in &vals[1..] {
            if widens(&ty, t) {
                ty = t.clone();
            } else if !widens(t, &ty) {
                return Err(type_error(span, format!("{f} of {ty} and {t}: the types differ")));
            }
        }
        if ty == Ty::Bool && f != "SEL" && f != "MUX" {
            return Err(type_error(span, format!("{f} takes numbers, not BOOL")));
        }
        if ty == Ty::Bool {
            let t = self.b.temp_b();
            let (Some(g), [(Val::B(a), _), (Val::B(b), _)]) = (guard, vals.as_slice()) else {
                return Err(not_supported(
                    span,
                    format!("{f} of BOOL values with more than 2 inputs is not supported yet"),
                ));
            };
            let Val::B(g) = g else {
                return Err(type_error(span, "selector".into()));
            };
            if f == "MUX" {
                return Err(not_supported(span, "MUX of BOOL values is not supported yet".into()));
            }
            // t := (g AND b) OR (NOT g AND a)
            let t1 = self.b.temp_b();
            self.emit(Op::Ld(g));
            self.emit(Op::Xic(*b));
            self.emit(Op::Ote(t1));
            self.emit(Op::Ldn(g));
            self.emit(Op::Xic(*a));
            self.emit(Op::Or(t1));
            self.emit(Op::Ote(t));
            self.emit(Op::True);
            return Ok((Val::B(t), Ty::Bool));
        }
        let class = ty.class();
        let mut slots = Vec::new();
        for (k, (v, _)) in vals.into_iter().enumerate() {
            slots.push(self.fit(v, choices[k], &ty)?);
        }
        let t = self.b.temp(class);
        match f {
            "MIN" | "MAX" => {
                self.b.un(IUn::Mov, slots[0], t, self.elem);
                for s in &slots[1..] {
                    self.cmp(if f == "MIN" { Cmp::Lt } else { Cmp::Gt }, *s, t);
                    self.b.un(IUn::Mov, *s, t, self.elem);
                    self.emit(Op::True);
                }
            }
            "LIMIT" => {
                let (mn, x, mx) = (slots[0], slots[1], slots[2]);
                self.b.un(IUn::Mov, x, t, self.elem);
                self.cmp(Cmp::Lt, t, mn);
                self.b.un(IUn::Mov, mn, t, self.elem);
                self.emit(Op::True);
                self.cmp(Cmp::Gt, t, mx);
                self.b.un(IUn::Mov, mx, t, self.elem);
                self.emit(Op::True);
            }
            "SEL" => {
                let Some(Val::B(g)) = guard else {
                    return Err(type_error(span, "SEL's selector is BOOL".into()));
                };
                self.b.un(IUn::Mov, slots[0], t, self.elem);
                self.emit(Op::Ld(g));
                self.b.un(IUn::Mov, slots[1], t, self.elem);
                self.emit(Op::True);
            }
            _ => {
                let Some(Val::N(k)) = guard else {
                    return Err(type_error(span, "MUX's selector is an integer".into()));
                };
                let V::I(k) = self.b.convert(k, Class::I, self.elem) else {
                    return Err(type_error(span, "MUX".into()));
                };
                self.b.un(IUn::Mov, slots[0], t, self.elem);
                for (i, s) in slots.iter().enumerate().skip(1) {
                    let c = self.b.const_i(i as i32);
                    self.emit(Op::CmpI(Cmp::Eq, k, c));
                    self.b.un(IUn::Mov, *s, t, self.elem);
                    self.emit(Op::True);
                }
            }
        }
        self.narrow(t, &ty);
        Ok((Val::N(t), ty))
    }
}

/// `a BOOL`, `an INT`.
fn an(ty: &Ty) -> String {
    let s = ty.to_string();
    let first = s.as_bytes().first().map(u8::to_ascii_uppercase);
    let vowel = if ty.data_type().is_some() && !matches!(ty, Ty::Enum(_)) {
        // Type names read letter by letter: an SINT, an LREAL, a UDINT.
        matches!(first, Some(b'A' | b'E' | b'I' | b'L' | b'S'))
    } else {
        matches!(first, Some(b'A' | b'E' | b'I' | b'O' | b'U'))
    };
    format!("{} {s}", if vowel { "an" } else { "a" })
}

fn fits(v: i64, ty: &Ty) -> bool {
    match ty {
        Ty::Sint => i8::try_from(v).is_ok(),
        Ty::Int => i16::try_from(v).is_ok(),
        Ty::Dint | Ty::Time => i32::try_from(v).is_ok(),
        Ty::Lint | Ty::Real | Ty::Lreal => true,
        Ty::Usint | Ty::Byte => (0..=0xFF).contains(&v),
        Ty::Uint | Ty::Word => (0..=0xFFFF).contains(&v),
        Ty::Udint | Ty::Dword => (0..=0xFFFF_FFFF).contains(&v),
        Ty::Ulint | Ty::Lword => v >= 0,
        Ty::Sub(b, lo, hi) => (*lo..=*hi).contains(&v) && fits(v, b),
        _ => false,
    }
}

fn vclass(v: V) -> Class {
    match v {
        V::I(_) => Class::I,
        V::F(_) => Class::F,
        V::L(_) => Class::L,
        V::D(_) => Class::D,
    }
}

fn value_lit(v: Value) -> Lit {
    match v {
        Value::Bool(b) => Lit::Bool(b),
        Value::Sint(x) => Lit::Int(x.into(), None),
        Value::Int(x) => Lit::Int(x.into(), None),
        Value::Dint(x) => Lit::Int(x.into(), None),
        Value::Lint(x) => Lit::Int(x, None),
        Value::Real(x) => Lit::Real(x.into(), None),
        Value::Lreal(x) => Lit::Real(x, None),
        Value::Time(x) => Lit::Int(x.into(), None),
    }
}
