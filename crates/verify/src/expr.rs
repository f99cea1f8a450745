//! Property expressions: Alba's expression language (the CPT form of
//! `alba_ladder::expr`) with its names resolved to places of a program's
//! memory, evaluated at the end of a scan.

use alba_diag::{FileId, Span};
use alba_ir::{Layout, Memory, Place, Target};
use alba_ladder::expr::{self, BinE, Expr, Func};
use alba_model::{Literal, Value};

/// A value during evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum V {
    Bool(bool),
    Int(i64),
    Real(f64),
}

impl V {
    pub fn truth(self) -> bool {
        match self {
            V::Bool(b) => b,
            V::Int(i) => i != 0,
            V::Real(r) => r != 0.0,
        }
    }
    fn int(self) -> i64 {
        match self {
            V::Bool(b) => b as i64,
            V::Int(i) => i,
            V::Real(r) => r as i64,
        }
    }
    fn real(self) -> f64 {
        match self {
            V::Bool(b) => b as i64 as f64,
            V::Int(i) => i as f64,
            V::Real(r) => r,
        }
    }
}

/// An expression with its names resolved.
#[derive(Debug, Clone, PartialEq)]
pub enum Compiled {
    Const(V),
    Read(Place),
    Neg(Box<Compiled>),
    Not(Box<Compiled>),
    Bin(BinE, Box<Compiled>, Box<Compiled>),
    Call(Func, Vec<Compiled>),
}

/// A problem with an expression: message and where (byte range of the file).
#[derive(Debug, Clone, PartialEq)]
pub struct ExprError {
    pub message: String,
    pub span: Span,
}

/// Parses `text` (at byte `base` of `file`) and resolves its names in `layout`.
pub fn compile(text: &str, file: FileId, base: usize, layout: &Layout) -> Result<Compiled, ExprError> {
    let e = expr::parse(text, file, base).map_err(|(message, span)| ExprError { message, span })?;
    resolve(&e, layout)
}

fn resolve(e: &Expr, layout: &Layout) -> Result<Compiled, ExprError> {
    Ok(match e {
        Expr::Lit(l, _) => Compiled::Const(match *l {
            Literal::Bool(b) => V::Bool(b),
            Literal::Int(i) | Literal::Time(i) => V::Int(i),
            Literal::Real(r) => V::Real(r),
        }),
        Expr::Const(c) => Compiled::Const(V::Real(*c)),
        Expr::Name(n, span) => match layout.resolve(n) {
            Ok(Target::Value { place, .. }) => Compiled::Read(place),
            Ok(_) => {
                return Err(ExprError {
                    message: format!("`{n}` is a structure; name a member such as {n}.DN or {n}.ACC"),
                    span: *span,
                });
            }
            Err(err) => {
                let mut message = err.to_string();
                if let Some(s) = layout.tags.suggest(n) {
                    message.push_str(&format!(" (did you mean `{s}`?)"));
                }
                return Err(ExprError { message, span: *span });
            }
        },
        Expr::Neg(a) => Compiled::Neg(Box::new(resolve(a, layout)?)),
        Expr::Not(a, _) => Compiled::Not(Box::new(resolve(a, layout)?)),
        Expr::Bin(op, a, b, _) => Compiled::Bin(*op, Box::new(resolve(a, layout)?), Box::new(resolve(b, layout)?)),
        Expr::Call(f, args, span) => {
            if f.arity() != args.len() {
                return Err(ExprError {
                    message: format!("{f:?} takes {} argument(s)", f.arity()),
                    span: *span,
                });
            }
            let args = args.iter().map(|a| resolve(a, layout)).collect::<Result<Vec<_>, _>>()?;
            Compiled::Call(*f, args)
        }
    })
}

fn value(v: Value) -> V {
    match v {
        Value::Bool(b) => V::Bool(b),
        Value::Real(_) | Value::Lreal(_) => V::Real(v.as_f64()),
        _ => V::Int(v.as_i64()),
    }
}

impl Compiled {
    /// Evaluates on `m`. Integer arithmetic wraps at 64 bits; a division by
    /// zero gives 0 (a property never faults).
    pub fn eval(&self, m: &Memory) -> V {
        match self {
            Compiled::Const(v) => *v,
            Compiled::Read(p) => value(m.read(*p)),
            Compiled::Neg(a) => match a.eval(m) {
                V::Real(r) => V::Real(-r),
                v => V::Int(v.int().wrapping_neg()),
            },
            Compiled::Not(a) => match a.eval(m) {
                V::Bool(b) => V::Bool(!b),
                V::Int(i) => V::Int(!i),
                V::Real(r) => V::Bool(r == 0.0),
            },
            Compiled::Bin(op, a, b) => bin(*op, a.eval(m), b.eval(m)),
            Compiled::Call(f, args) => {
                let x: Vec<V> = args.iter().map(|a| a.eval(m)).collect();
                call(*f, &x)
            }
        }
    }

    /// Every place the expression reads.
    pub fn places(&self, out: &mut Vec<Place>) {
        match self {
            Compiled::Const(_) => {}
            Compiled::Read(p) => out.push(*p),
            Compiled::Neg(a) | Compiled::Not(a) => a.places(out),
            Compiled::Bin(_, a, b) => {
                a.places(out);
                b.places(out);
            }
            Compiled::Call(_, args) => args.iter().for_each(|a| a.places(out)),
        }
    }
}

fn bin(op: BinE, a: V, b: V) -> V {
    let real = matches!(a, V::Real(_)) || matches!(b, V::Real(_));
    let both_bool = matches!((a, b), (V::Bool(_), V::Bool(_)));
    match op {
        BinE::And if both_bool => V::Bool(a.truth() && b.truth()),
        BinE::Or if both_bool => V::Bool(a.truth() || b.truth()),
        BinE::Xor if both_bool => V::Bool(a.truth() ^ b.truth()),
        BinE::And if !real => V::Int(a.int() & b.int()),
        BinE::Or if !real => V::Int(a.int() | b.int()),
        BinE::Xor if !real => V::Int(a.int() ^ b.int()),
        BinE::And => V::Bool(a.truth() && b.truth()),
        BinE::Or => V::Bool(a.truth() || b.truth()),
        BinE::Xor => V::Bool(a.truth() ^ b.truth()),
        BinE::Eq | BinE::Ne | BinE::Lt | BinE::Gt | BinE::Le | BinE::Ge => {
            let ord = if real {
                a.real().partial_cmp(&b.real())
            } else {
                Some(a.int().cmp(&b.int()))
            };
            use std::cmp::Ordering::*;
            V::Bool(match (op, ord) {
                (_, None) => op == BinE::Ne,
                (BinE::Eq, Some(o)) => o == Equal,
                (BinE::Ne, Some(o)) => o != Equal,
                (BinE::Lt, Some(o)) => o == Less,
                (BinE::Gt, Some(o)) => o == Greater,
                (BinE::Le, Some(o)) => o != Greater,
                (_, Some(o)) => o != Less,
            })
        }
        BinE::Pow => V::Real(a.real().powf(b.real())),
        _ if real => {
            let (x, y) = (a.real(), b.real());
            V::Real(match op {
                BinE::Add => x + y,
                BinE::Sub => x - y,
                BinE::Mul => x * y,
                BinE::Div if y == 0.0 => 0.0,
                BinE::Div => x / y,
                BinE::Mod if y == 0.0 => 0.0,
                _ => x % y,
            })
        }
        _ => {
            let (x, y) = (a.int(), b.int());
            V::Int(match op {
                BinE::Add => x.wrapping_add(y),
                BinE::Sub => x.wrapping_sub(y),
                BinE::Mul => x.wrapping_mul(y),
                BinE::Div | BinE::Mod if y == 0 => 0,
                BinE::Div => x.wrapping_div(y),
                _ => x.wrapping_rem(y),
            })
        }
    }
}

fn call(f: Func, x: &[V]) -> V {
    let a = x.first().copied().unwrap_or(V::Int(0));
    let r = a.real();
    match f {
        Func::Abs => match a {
            V::Real(r) => V::Real(r.abs()),
            v => V::Int(v.int().wrapping_abs()),
        },
        Func::Sqrt => V::Real(r.sqrt()),
        Func::Sin => V::Real(r.sin()),
        Func::Cos => V::Real(r.cos()),
        Func::Tan => V::Real(r.tan()),
        Func::Asn => V::Real(r.asin()),
        Func::Acs => V::Real(r.acos()),
        Func::Atn => V::Real(r.atan()),
        Func::Ln => V::Real(r.ln()),
        Func::Log => V::Real(r.log10()),
        Func::Deg => V::Real(r.to_degrees()),
        Func::Rad => V::Real(r.to_radians()),
        Func::Trn => V::Int(r.trunc() as i64),
        Func::Round => V::Int(r.round_ties_even() as i64),
        Func::Floor => V::Int(r.floor() as i64),
        Func::Ceil => V::Int(r.ceil() as i64),
        Func::Sign => V::Int(if r > 0.0 {
            1
        } else if r < 0.0 {
            -1
        } else {
            0
        }),
        _ => {
            let b = x.get(1).copied().unwrap_or(V::Int(0)).real();
            match f {
                Func::Atan2 => V::Real(r.atan2(b)),
                Func::Pow => V::Real(r.powf(b)),
                _ => V::Real(f64::NAN),
            }
        }
    }
}

/// A function a property may not call ([`supported`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{0:?} is not available in properties")]
pub struct Unsupported(pub Func);

/// Functions a property may call (the rest are refused when read).
pub fn supported(e: &Compiled) -> Result<(), Unsupported> {
    match e {
        Compiled::Call(f, args) => {
            let ok = matches!(
                f,
                Func::Abs
                    | Func::Sqrt
                    | Func::Sin
                    | Func::Cos
                    | Func::Tan
                    | Func::Asn
                    | Func::Acs
                    | Func::Atn
                    | Func::Ln
                    | Func::Log
                    | Func::Deg
                    | Func::Rad
                    | Func::Trn
                    | Func::Round
                    | Func::Floor
                    | Func::Ceil
                    | Func::Sign
                    | Func::Atan2
                    | Func::Pow
            );
            if !ok {
                return Err(Unsupported(*f));
            }
            args.iter().try_for_each(supported)
        }
        Compiled::Neg(a) | Compiled::Not(a) => supported(a),
        Compiled::Bin(_, a, b) => supported(a).and_then(|()| supported(b)),
        _ => Ok(()),
    }
}
