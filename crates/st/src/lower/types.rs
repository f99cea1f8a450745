//! The types the lowering knows: elementary, ARRAY, STRUCT, enumerations,
//! subranges, bit strings, standard and user function blocks; the user
//! types and POUs a file sees; literal initial values.

use super::*;

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
    pub(super) fn from_name(n: &str) -> Option<Fb> {
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
    pub(super) fn name(self) -> &'static str {
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
    pub(super) fn params(self) -> (Params, Params) {
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
pub(super) type Params = &'static [(&'static str, P)];

/// The type of a standard FB's parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum P {
    Bool,
    Int,
    Time,
}

impl P {
    pub(super) fn ty(self) -> Ty {
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
    /// `STRING[n]` (`WSTRING[n]` when wide): at most n characters.
    Str(bool, u32),
    /// Nanoseconds, in a LINT.
    Ltime,
    /// Milliseconds since 1970-01-01 (a whole day), in a LINT.
    Date,
    /// Milliseconds since midnight, in a LINT.
    Tod,
    /// Milliseconds since 1970-01-01 00:00, in a LINT.
    Dt,
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
            Ty::Str(wide, n) => write!(f, "{}[{n}]", if *wide { "WSTRING" } else { "STRING" }),
            Ty::Ltime => f.write_str("LTIME"),
            Ty::Date => f.write_str("DATE"),
            Ty::Tod => f.write_str("TIME_OF_DAY"),
            Ty::Dt => f.write_str("DATE_AND_TIME"),
        }
    }
}

impl Ty {
    /// The type of the tag (or slot) that stores a value of this type.
    pub(super) fn data_type(&self) -> Option<DataType> {
        Some(match self {
            Ty::Bool => DataType::Bool,
            Ty::Sint => DataType::Sint,
            Ty::Int | Ty::Usint | Ty::Byte => DataType::Int,
            Ty::Dint | Ty::Uint | Ty::Word | Ty::Enum(_) => DataType::Dint,
            Ty::Lint | Ty::Udint | Ty::Ulint | Ty::Dword | Ty::Lword => DataType::Lint,
            Ty::Ltime | Ty::Date | Ty::Tod | Ty::Dt => DataType::Lint,
            Ty::Real => DataType::Real,
            Ty::Lreal => DataType::Lreal,
            Ty::Time => DataType::Time,
            Ty::Sub(b, ..) => return b.data_type(),
            _ => return None,
        })
    }
    pub(super) fn from_data_type(t: DataType) -> Option<Ty> {
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
    pub(super) fn value(&self) -> Ty {
        match self {
            Ty::Sub(b, ..) => (**b).clone(),
            t => t.clone(),
        }
    }
    pub(super) fn is_int(&self) -> bool {
        matches!(self, Ty::Sint | Ty::Int | Ty::Dint | Ty::Lint) || self.is_unsigned()
    }
    pub(super) fn is_unsigned(&self) -> bool {
        matches!(self, Ty::Usint | Ty::Uint | Ty::Udint | Ty::Ulint)
    }
    pub(super) fn is_bits(&self) -> bool {
        matches!(self, Ty::Byte | Ty::Word | Ty::Dword | Ty::Lword)
    }
    /// Bits of an unsigned integer or a bit string.
    pub(super) fn bits(&self) -> Option<u32> {
        Some(match self {
            Ty::Usint | Ty::Byte => 8,
            Ty::Uint | Ty::Word => 16,
            Ty::Udint | Ty::Dword => 32,
            Ty::Ulint | Ty::Lword => 64,
            _ => return None,
        })
    }
    pub(super) fn is_real(&self) -> bool {
        matches!(self, Ty::Real | Ty::Lreal)
    }
    pub(super) fn is_num(&self) -> bool {
        self.is_int() || self.is_real() || *self == Ty::Time
    }
    pub(super) fn class(&self) -> Class {
        match self.data_type() {
            Some(DataType::Lint) => Class::L,
            Some(DataType::Real) => Class::F,
            Some(DataType::Lreal) => Class::D,
            _ => Class::I,
        }
    }
    pub(super) fn rank(&self) -> u8 {
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
    pub(super) fn elements(&self) -> i64 {
        match self {
            Ty::Array(_, dims) => dims.iter().map(|(a, b)| b - a + 1).product(),
            _ => 1,
        }
    }
}

/// Whether a value of `from` may be used where `to` is wanted without a
/// conversion function (IEC 61131-3 implicit widening).
pub(super) fn widens(from: &Ty, to: &Ty) -> bool {
    if from == to {
        return true;
    }
    match (from, to) {
        // A string of any length into one of the same kind (cut to its length).
        (Ty::Str(a, _), Ty::Str(b, _)) => a == b,
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

pub(super) fn elementary(name: &str) -> Option<Ty> {
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
        "LTIME" => Ty::Ltime,
        "DATE" => Ty::Date,
        "TIME_OF_DAY" | "TOD" => Ty::Tod,
        "DATE_AND_TIME" | "DT" => Ty::Dt,
        _ => return None,
    })
}

/// A constant integer from an expression (literals, negation).
pub(super) fn const_int(e: &Expr) -> Option<i64> {
    match &e.kind {
        ExprKind::Lit(Lit::Int(v, _)) => Some(*v),
        ExprKind::Unary(AUn::Neg, a) => const_int(a).map(|v| -v),
        _ => None,
    }
}

/// The user types and POUs of a file, by lower-case name.
pub(super) struct Types<'a> {
    pub(super) aliases: HashMap<String, &'a ast::TypeDecl>,
    /// FUNCTIONs and FUNCTION_BLOCKs.
    pub(super) pous: HashMap<String, &'a Pou>,
    /// Every enumerated type declared in a `TYPE` block.
    pub(super) enums: Vec<Rc<EnumTy>>,
}

/// The types and POUs `file` sees: its own, then those of `library` (the
/// other `.st` files of the project) that it does not declare itself.
pub(super) fn types_of<'a>(file: &'a ast::File, library: &[&'a ast::File]) -> Types<'a> {
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
pub(super) fn resolve_type(t: &TypeRef, types: &Types, depth: u32) -> R<Ty> {
    resolve_named(t, "STRUCT", types, depth)
}

/// An enumerated type's values, numbered from 0 or from the value given.
pub(super) fn enum_values(values: &[(Ident, Option<Expr>)]) -> R<Vec<(String, i64)>> {
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
pub(super) fn resolve_named(t: &TypeRef, name: &str, types: &Types, depth: u32) -> R<Ty> {
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
            let known = [
                "BOOL", "SINT", "INT", "DINT", "LINT", "REAL", "LREAL", "TIME", "USINT", "UINT", "UDINT", "ULINT",
                "BYTE", "WORD", "DWORD", "LWORD", "LTIME", "DATE", "TOD", "DT", "STRING", "WSTRING", "TON", "TOF",
                "TP", "CTU", "CTD", "CTUD", "R_TRIG", "F_TRIG", "SR", "RS",
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
        TypeRef::String { wide, len, span } => {
            let n = match len {
                None => DEFAULT_STRING,
                Some(e) => const_int(e).filter(|n| (1..=MAX_STRING).contains(n)).ok_or_else(|| {
                    decl_error(*span, format!("a string's length is a literal from 1 to {MAX_STRING}"))
                })?,
            };
            Ok(Ty::Str(*wide, n as u32))
        }
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
pub(super) fn element_suffixes(dims: &[(i64, i64)]) -> Vec<String> {
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
pub(super) fn literal_value(e: &Expr, ty: &Ty) -> R<Value> {
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
        // IEC 61131-3's boolean literals include 0 and 1 (matiec's `BOOL := 1`).
        (ExprKind::Lit(Lit::Int(v @ (0 | 1), None)), Ty::Bool) => Value::Bool(*v == 1),
        (ExprKind::Lit(Lit::Time(ms)), Ty::Time) => Value::Time(i32::try_from(*ms).map_err(|_| bad())?),
        (ExprKind::Lit(Lit::Other(t, v)), ty) if is_date(ty) => match date_literal(t, v) {
            Some(Ok((lt, x))) if lt == *ty => Value::Lint(x),
            _ => return Err(bad()),
        },
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

pub(super) fn enum_value(en: &EnumTy, name: &str) -> Option<i64> {
    en.values
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, v)| *v)
}

/// The initial value of a variable of `ty` given none (a subrange's low
/// bound, an enumeration's first value).
pub(super) fn default_value(ty: &Ty) -> Option<Value> {
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

/// `a BOOL`, `an INT`.
pub(super) fn an(ty: &Ty) -> String {
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

pub(super) fn fits(v: i64, ty: &Ty) -> bool {
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

pub(super) fn value_lit(v: Value) -> Lit {
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
