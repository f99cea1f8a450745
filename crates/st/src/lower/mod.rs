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
//!
//! `types` holds the types and what a file declares, `decl` the tags of
//! variables, `calls` the inlining of user FUNCTIONs and FUNCTION_BLOCKs,
//! `bits` bit strings on the engine's signed slots.

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

mod bits;
mod calls;
mod dates;
mod decl;
mod strconv;
mod strings;
mod types;

use bits::*;
use calls::*;
use dates::*;
use decl::*;
pub use decl::{declare, declare_with};
use strings::*;
use types::*;
pub use types::{EnumTy, Fb, StructTy, Ty};

type R<T> = Result<T, Diagnostic>;

/// Most elements an ARRAY may have (each is a tag).
pub const MAX_ELEMENTS: i64 = 10_000;

/// An indexed element: its type, the places it is chosen from, the bounds
/// and the index expressions.
type Indexed<'e> = (Ty, Vec<Place>, Vec<(i64, i64)>, &'e [Expr]);
/// A call's inputs by parameter, and its `=>` outputs.
type Bound<'e> = (Vec<Option<&'e Expr>>, Vec<(usize, &'e Arg)>);

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

/// What computes the value of an assignment, given the type wanted.
type ValueOf<'f, L> = dyn FnMut(&mut L, Option<&Ty>) -> R<(Val, Ty)> + 'f;

/// A value read into a slot.
#[derive(Debug, Clone, Copy)]
enum Val {
    B(B),
    N(V),
    /// A string: its slots, kept in `Lower::strs`.
    S(u32),
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
    /// A STRING or WSTRING: its length slot and character slots.
    Str {
        len: I,
        chars: Rc<Vec<I>>,
        ty: Ty,
        writable: bool,
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
/// A statement opens a rung of its own once the current one has this many
/// ops: long straight-line code becomes rungs of about this size.
const RUNG_OPS: u32 = 256;
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
    /// String values of the expressions lowered so far (`Val::S`).
    strs: Vec<Str>,
    /// Statements share rungs and the peephole runs (see [`Lower::open`]
    /// and [`Lower::emit`]); off for [`compile_unoptimised`].
    optimise: bool,
    /// The op of the current rung's `Rung`.
    rung_op: u32,
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
    b.begin_unit(name);
    let diags = compile_in(file, library, 0, b);
    b.end_unit();
    diags
}

/// [`compile_with`] into the unit being built, its rungs numbered from
/// `first_rung` (an SFC's ST actions, after its chart).
pub fn compile_in(file: &ast::File, library: &[&ast::File], first_rung: u32, b: &mut Builder) -> Vec<Diagnostic> {
    lower_in(file, library, first_rung, b, true)
}

/// [`compile_with`] as the lowering was before its optimisations: a rung for
/// every statement, booleans through their temporaries. The same programs
/// must compute the same (a differential test), so its only use is there.
pub fn compile_unoptimised(file: &ast::File, library: &[&ast::File], name: &str, b: &mut Builder) -> Vec<Diagnostic> {
    b.begin_unit(name);
    let diags = lower_in(file, library, 0, b, false);
    b.end_unit();
    diags
}

fn lower_in(
    file: &ast::File,
    library: &[&ast::File],
    first_rung: u32,
    b: &mut Builder,
    optimise: bool,
) -> Vec<Diagnostic> {
    let types = types_of(file, library);
    let mut diags = Vec::new();
    let globals: HashMap<String, Var> = variables(&file.globals, None, &types, &mut Vec::new())
        .into_iter()
        .collect();
    let mut rungs = first_rung;
    let mut called = HashSet::new();
    for p in &file.pous {
        if p.kind != PouKind::Program {
            continue;
        }
        let mut vars = globals.clone();
        vars.extend(variables(&p.vars, Some(&p.name.name), &types, &mut Vec::new()));
        let mut l = Lower::new(b, &types, globals.clone(), vars, rungs, &p.name.name);
        l.optimise = optimise;
        l.program(p);
        rungs = l.rungs;
        diags.extend(l.diags);
        called.extend(l.called);
    }
    let uncalled: Vec<&Pou> = file
        .pous
        .iter()
        .filter(|p| p.kind != PouKind::Program && !called.contains(&p.name.name.to_ascii_lowercase()))
        .collect();
    diags.extend(check_alone(&uncalled, &types, &globals, b.layout()));
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
            strs: Vec::new(),
            optimise: true,
            rung_op: 0,
        }
    }
}

impl Lower<'_> {
    fn emit(&mut self, op: Op) -> u32 {
        if self.optimise
            && let Some(at) = self.peephole(op)
        {
            return at;
        }
        self.b.emit(op, self.elem)
    }

    /// After `Ote s; True`, `rc` was `s`: an op reading `s` back into `rc`
    /// right after can use `rc` instead (`Ld s` is then nothing, `Ldn s` a
    /// `Not`, `CopyB s → d` an `Ote d`, and `Ld x; Xic s` / `Ld x; Or s` an
    /// `Xic x` / `Or x`). The ops are contiguous in one rung (jumps land on
    /// `Rung`s only), so nothing runs between them. `None`: emit `op` as it is.
    fn peephole(&mut self, op: Op) -> Option<u32> {
        let ops = self.b.ops();
        let n = ops.len();
        let after = |k: usize, s: B| n >= k + 2 && ops[n - k - 2] == Op::Ote(s) && ops[n - k - 1] == Op::True;
        let last = ops.last().copied();
        let now = match op {
            Op::Ld(s) if after(0, s) => Vec::new(),
            Op::Ldn(s) if after(0, s) => vec![Op::Not],
            Op::CopyB(s, d) if after(0, s) => vec![Op::Ote(d), Op::True],
            Op::Xic(s) | Op::Or(s) if after(1, s) => {
                let Some(Op::Ld(x)) = last else { return None };
                self.b.pop();
                vec![if matches!(op, Op::Xic(_)) {
                    Op::Xic(x)
                } else {
                    Op::Or(x)
                }]
            }
            _ => return None,
        };
        self.b.pop();
        let mut at = self.b.here().saturating_sub(1);
        for o in now {
            at = self.b.emit(o, self.elem);
        }
        Some(at)
    }

    /// Where a statement without jumps into it begins: a new element in the
    /// current rung (each statement keeps its own element, so its span, for
    /// faults and diagnostics), or a rung of its own when the lowering is
    /// not optimised or the current rung is already long.
    fn open(&mut self, span: Span) {
        if self.optimise && self.b.here() - self.rung_op < RUNG_OPS {
            self.elem = self.b.element(span);
        } else {
            self.rung(span);
        }
    }

    fn rung(&mut self, span: Span) -> u32 {
        let at = self.b.here();
        self.rung_op = at;
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
            let missing = || {
                Diagnostic::new(
                    Code::StName,
                    format!("`{}` is VAR_EXTERNAL but no tag or VAR_GLOBAL has that name", v.tag),
                    v.span,
                    "external",
                )
            };
            // Structures, arrays and FB instances are several tags.
            if matches!(v.ty, Ty::Struct(_) | Ty::Array(..) | Ty::User(_) | Ty::Fb(_)) {
                if !self.declared(&v.tag, &v.ty, 0) {
                    self.diags.push(missing());
                }
                continue;
            }
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

    /// Whether the tags of a variable of type `ty` named `tag` exist.
    fn declared(&mut self, tag: &str, ty: &Ty, depth: u32) -> bool {
        let layout = self.b.layout();
        match ty {
            Ty::Fb(Fb::RTrig | Fb::FTrig) => layout.resolve(&format!("{tag}.Q")).is_ok(),
            Ty::Fb(Fb::Sr | Fb::Rs) => layout.resolve(&format!("{tag}.Q1")).is_ok(),
            Ty::Fb(_) => layout.resolve(tag).is_ok(),
            Ty::User(fb) => {
                let Some(p) = self.types.pous.get(&fb.to_ascii_lowercase()).copied() else {
                    return false;
                };
                depth < 32
                    && variables(&p.vars, Some(tag), self.types, &mut Vec::new())
                        .iter()
                        .filter(|(_, w)| !matches!(w.kind, VarKind::InOut | VarKind::External | VarKind::Global))
                        .all(|(_, w)| self.declared(&w.tag, &w.ty, depth + 1))
            }
            _ => {
                let id = Ident {
                    name: tag.to_string(),
                    span: Span::new(alba_diag::FileId(0), 0..0),
                };
                self.tag_loc(tag, ty, false, &id).is_ok()
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
            Loc::Str { len, chars, ty, .. } => {
                let text = match (init, ty) {
                    (Some(Init::Expr(e)), Ty::Str(wide, _)) => match &e.kind {
                        ExprKind::Lit(Lit::Str(t, w)) if w == wide => t.clone(),
                        _ => String::new(),
                    },
                    _ => String::new(),
                };
                let wide = matches!(ty, Ty::Str(true, _));
                let (v, _) = self.str_literal(&text, wide);
                if let Some(src) = self.str_of(v) {
                    let (len, chars) = (*len, chars.clone());
                    self.str_store(len, &chars, &src);
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
}

impl Lower<'_> {
    /// Copies every value of `src` into `dst` (two locations of one type).
    fn copy_loc(&mut self, dst: &Loc, src: &Loc) {
        match (dst, src) {
            (Loc::Str { len, chars, .. }, Loc::Str { len: sl, chars: sc, .. }) => {
                let s = self.str_loc(*sl, sc);
                self.str_store(*len, chars, &s);
            }
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
            Ty::Str(_, cap) => {
                let slot = |name: &str, l: &mut Self| match l.b.layout().resolve(name) {
                    Ok(Target::Value {
                        place: Place::Int(i, _),
                        access,
                    }) => Ok((i, access == Access::ReadWrite)),
                    _ => Err(l.unknown(n, "variable")),
                };
                let (len, writable) = slot(&format!("{tag}.LEN"), self)?;
                let mut chars = Vec::with_capacity(*cap as usize);
                for k in 1..=*cap {
                    chars.push(slot(&format!("{tag}[{k}]"), self)?.0);
                }
                Ok(Loc::Str {
                    len,
                    chars: Rc::new(chars),
                    ty: ty.clone(),
                    writable: writable && !constant,
                })
            }
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
            Ty::Array(of, dims) if matches!(**of, Ty::Struct(_) | Ty::Fb(_) | Ty::User(_) | Ty::Str(..)) => {
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
            let start = self.b.here();
            if let Err(d) = self.stmt(s) {
                self.diags.push(d);
            }
            if self.optimise {
                self.drop_dead_stores(mark, start);
            }
            self.b.release(mark);
        }
    }

    /// Cleans up a straight-line statement (no `Rung`, no `Jmp` from `start`
    /// on) once its temporaries (taken after `mark`) are dead: drops each
    /// `Ote t` to a bool temporary that nothing after it in the statement
    /// mentions (the peephole leaves many: `Ote t; Or b` where `t` was
    /// reloaded), and writes `BinI(Add|Sub, a, b, t); UnI(Mov, t, d)` as
    /// `BinI(.., d)` (a sum always writes its slot, wrapped or not).
    fn drop_dead_stores(&mut self, mark: alba_ir::TempMark, start: u32) {
        use alba_ir::op::AnySlot;
        let ops = &self.b.ops()[start as usize..];
        if ops.iter().any(|o| matches!(o, Op::Rung | Op::Jmp(_))) {
            return;
        }
        let temps_b: HashSet<u32> = self.b.temps_b_since(mark).iter().copied().collect();
        let temps_i: HashSet<u32> = self.b.temps_i_since(mark).iter().copied().collect();
        if temps_b.is_empty() && temps_i.is_empty() {
            return;
        }
        // Backwards: a temporary is read later if an op after mentions it
        // (an op with several slots of a class: any temporary between the
        // least and the greatest, as timers and counters give only their ends).
        let mut later_b: HashSet<u32> = HashSet::new();
        let mut later_i: HashSet<u32> = HashSet::new();
        let mut new: Vec<Option<Op>> = ops.iter().copied().map(Some).collect();
        for k in (0..new.len()).rev() {
            let Some(op) = new[k] else { continue };
            match op {
                Op::Ote(t) if temps_b.contains(&t.0) && !later_b.contains(&t.0) => {
                    new[k] = None;
                    continue;
                }
                Op::UnI(IUn::Mov, t, d) if temps_i.contains(&t.0) && !later_i.contains(&t.0) && k > 0 => {
                    if let Some(Op::BinI(o @ (IBin::Add | IBin::Sub), a, b, t2)) = new[k - 1]
                        && t2 == t
                        && a != t
                        && b != t
                    {
                        new[k - 1] = Some(Op::BinI(o, a, b, d));
                        new[k] = None;
                        continue;
                    }
                }
                _ => {}
            }
            let slots = op.slots();
            let range = |pick: &dyn Fn(&AnySlot) -> Option<u32>| {
                slots
                    .iter()
                    .filter_map(pick)
                    .fold((u32::MAX, 0), |(lo, hi), x| (lo.min(x), hi.max(x)))
            };
            let (lo, hi) = range(&|s| if let AnySlot::B(x) = s { Some(*x) } else { None });
            if lo <= hi {
                later_b.extend(temps_b.iter().filter(|&&t| (lo..=hi).contains(&t)));
            }
            let (lo, hi) = range(&|s| if let AnySlot::I(x) = s { Some(*x) } else { None });
            if lo <= hi {
                later_i.extend(temps_i.iter().filter(|&&t| (lo..=hi).contains(&t)));
            }
        }
        if new.iter().any(Option::is_none) || new.iter().zip(ops).any(|(n, o)| n.as_ref() != Some(o)) {
            self.b.rewrite_since(start, new);
        }
    }

    fn stmt(&mut self, s: &Stmt) -> R<()> {
        match &s.kind {
            StmtKind::Empty => Ok(()),
            StmtKind::Assign(lhs, rhs) => {
                self.open(s.span);
                self.assign(lhs, rhs)
            }
            StmtKind::Call(callee, args) => {
                self.open(s.span);
                let is = |a: &Arg, n: &str| a.name.as_ref().is_some_and(|x| x.is(n));
                let en = args.iter().find(|a| !a.output && is(a, "EN"));
                let eno = args.iter().find(|a| a.output && is(a, "ENO"));
                if en.is_none() && eno.is_none() {
                    return self.call_stmt(callee, args, s.span);
                }
                // EN := c runs the call only when c is TRUE; ENO => x says
                // whether it ran.
                let rest: Vec<Arg> = args.iter().filter(|a| !is(a, "EN") && !is(a, "ENO")).cloned().collect();
                let skip = match en {
                    Some(a) => {
                        let c = self.cond(&a.value)?;
                        self.emit(Op::Ldn(c));
                        let j = self.emit(Op::Jmp(0));
                        self.emit(Op::True);
                        Some(j)
                    }
                    None => None,
                };
                self.call_stmt(callee, &rest, s.span)?;
                let set_eno = |l: &mut Self, v: bool| -> R<()> {
                    if let Some(a) = eno {
                        l.assign_with(&a.value, a.value.span, &mut |l: &mut Self, _| {
                            Ok((l.constant(&Lit::Bool(v), &Ty::Bool), Ty::Bool))
                        })?;
                    }
                    Ok(())
                };
                set_eno(self, true)?;
                if let Some(skip) = skip {
                    let done = self.emit(Op::Jmp(0));
                    let off = self.rung(s.span);
                    self.patch(&[skip], off);
                    set_eno(self, false)?;
                    let end = self.rung(s.span);
                    self.patch(&[done], end);
                }
                Ok(())
            }
            StmtKind::If { arms, els } => {
                let mut ends = Vec::new();
                let mut next = 0;
                for (k, (c, body)) in arms.iter().enumerate() {
                    if k > 0 {
                        // ELSIF: evaluated in the rung the previous arm skips to.
                        self.elem = self.b.element(c.span);
                    } else {
                        self.open(s.span);
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
                self.open(s.span);
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

    /// A call as a statement: of an FB instance (an element of an array of
    /// them), or of a function for nothing (it may fault).
    fn call_stmt(&mut self, callee: &Expr, args: &[Arg], span: Span) -> R<()> {
        if let ExprKind::Index(base, ix) = &callee.kind {
            return self.call_element(base, ix, args, callee, span);
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
            Some(Loc::User { fb, prefix }) => match self.types.pous.get(&fb.to_ascii_lowercase()).copied() {
                Some(p) => self.inline_fb(p, &prefix, args, span, false),
                None => Err(self.unknown(n, "function block")),
            },
            _ => self.call(n, args, None, callee.span).map(|_| ()),
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
                    Some(Loc::Str { ty, .. }) => {
                        return Err(type_error(
                            m.span,
                            format!(
                                "`{}` is {}; it has no members (LEN gives its length)",
                                ast::expr(base),
                                an(&ty)
                            ),
                        ));
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
            Loc::Str { len, chars, ty, .. } => {
                let s = self.str_loc(*len, chars);
                Ok((self.keep(s), ty.clone()))
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
            (Lit::Other(t, v), _) if matches!(date_literal(t, v), Some(Ok(_))) => {
                let x = date_literal(t, v).and_then(Result::ok).map_or(0, |(_, x)| x);
                Val::N(V::L(self.b.const_l(x)))
            }
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
            Lit::Other(t, v) if date_literal(t, v).is_some() => match date_literal(t, v) {
                Some(Ok((ty, _))) => ty,
                Some(Err(m)) => return Err(type_error(span, m)),
                None => Ty::Lint,
            },
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
            ExprKind::Lit(Lit::Str(text, wide)) => Ok(self.str_literal(text, *wide)),
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
                    Val::N(_) | Val::S(_) => Err(type_error(
                        a.span,
                        format!("NOT takes a BOOL or a bit string (BYTE … LWORD), not {}", an(&ty)),
                    )),
                }
            }
            ExprKind::Unary(AUn::Neg, a) => {
                let (v, ty) = self.eval(a, hint)?;
                match v {
                    Val::N(x) if (ty.is_num() && !ty.is_unsigned()) || ty == Ty::Ltime => {
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
        if let (Val::S(_), _) | (_, Val::S(_)) = (va, vb) {
            return self.str_binary(op, (va, &ta), (vb, &tb), span);
        }
        if (is_date(&ta) || is_date(&tb))
            && let (Val::N(x), Val::N(y)) = (va, vb)
        {
            return self.date_binary(op, (x, &ta), (y, &tb), span);
        }
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
            Val::S(_) => Err(type_error(e.span, format!("a string where a {ty} is wanted"))),
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
            // Strings are stored by `str_store` (the type check refuses them here).
            Val::S(_) => {}
        }
    }

    fn assign(&mut self, lhs: &Expr, rhs: &Expr) -> R<()> {
        // A whole structure: copied member by member.
        let maybe_struct = match &lhs.kind {
            ExprKind::Name(n) => {
                let k = n.name.to_ascii_lowercase();
                self.aliases
                    .get(&k)
                    .is_some_and(|l| matches!(l, Loc::Struct { .. } | Loc::Array { .. } | Loc::StructArray { .. }))
                    || self
                        .vars
                        .get(&k)
                        .is_some_and(|v| matches!(v.ty, Ty::Struct(_) | Ty::Array(..)))
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
        if maybe_struct && let Some((elems, dims, of, ix)) = self.struct_elements(lhs)? {
            // `zs[i] := p`: one guarded copy per element.
            let src = self.composite_of(rhs)?;
            if loc_type(&src).as_ref() != Some(&of) {
                return Err(type_error(
                    rhs.span,
                    format!("cannot assign this to `{}`, {}", ast::expr(lhs), an(&of)),
                ));
            }
            return self.each_element(&elems, &dims, ix, lhs.span, &mut |l: &mut Self, el: &Loc| {
                l.copy_loc(el, &src);
                Ok(())
            });
        }
        if maybe_struct
            && let Ok(dst @ (Loc::Struct { .. } | Loc::StructArray { .. } | Loc::Array { .. })) = self.locate(lhs)
        {
            let src = self.composite_of(rhs)?;
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
        if let Loc::Str {
            len,
            chars,
            ty,
            writable,
        } = &loc
        {
            if !*writable {
                return Err(Diagnostic::new(
                    Code::NotWritable,
                    format!("`{}` cannot be written", ast::expr(lhs)),
                    lhs.span,
                    "not writable",
                ));
            }
            let (v, vty) = value(self, Some(ty))?;
            let src = match (self.str_of(v), &vty, ty) {
                (Some(src), Ty::Str(a, _), Ty::Str(b, _)) if a == b => src,
                _ => {
                    return Err(type_error(
                        rspan,
                        format!("cannot assign {} to `{}`, {}", an(&vty), ast::expr(lhs), an(ty)),
                    ));
                }
            };
            self.str_store(*len, chars, &src);
            return Ok(());
        }
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
                    // A literal preset from a slot of the instance's own, so
                    // instances declared together read presets laid out as
                    // regularly as their other slots (native code's strided
                    // runs), whatever the values.
                    let pt = if self.optimise { self.b.own_i(pt) } else { pt };
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
        if let Some(a) = args
            .iter()
            .find(|a| a.name.as_ref().is_some_and(|x| x.is("EN") || x.is("ENO")))
        {
            let at = a.name.as_ref().map_or(a.value.span, |x| x.span);
            return Err(not_supported(
                at,
                "EN and ENO are taken by a call written as a statement (`F(EN := c, ENO => ok);`), not in an expression"
                    .into(),
            ));
        }
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
        // The operators' standard functions: ADD and MUL (n-ary), SUB, DIV,
        // MOD (as OpenPLC programs write `DIV(a, b)`, `mod(a, b)`).
        let op = match up.as_str() {
            "ADD" => Some((BinOp::Add, true)),
            "MUL" => Some((BinOp::Mul, true)),
            "SUB" => Some((BinOp::Sub, false)),
            "DIV" => Some((BinOp::Div, false)),
            "MOD" => Some((BinOp::Mod, false)),
            _ => None,
        };
        if let Some((op, nary)) = op {
            if !nary || positional.len() < 2 {
                arity(2)?;
            }
            let mut e = positional[0].clone();
            for b in &positional[1..] {
                e = Expr {
                    kind: ExprKind::Binary(op, Box::new(e), Box::new((*b).clone())),
                    span,
                };
            }
            return self.eval(&e, hint);
        }
        if let Some(r) = self.string_call(&up, &positional, span) {
            return r;
        }
        if up == "CONCAT_DATE_TOD" {
            return self.concat_date_tod(&positional, span);
        }
        if let Some((from, to)) = up.split_once("_TO_") {
            arity(1)?;
            if let Some(r) = self.string_conversion(from, to, positional[0], span) {
                return r;
            }
            if let (Some(f), Some(t)) = (elementary(from), elementary(to))
                && let Some(r) = self.date_conversion(&f, &t, positional[0], &up)
            {
                return r;
            }
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
        // TO_Y: the 3rd edition's conversion from the argument's own type
        // (an enumeration converts as its number).
        if let Some(to) = up.strip_prefix("TO_")
            && let Some(to_ty) = elementary(to)
        {
            arity(1)?;
            let (v, ty) = self.eval(positional[0], Some(&to_ty))?;
            let from = match ty {
                Ty::Enum(_) => Ty::Dint,
                t => t,
            };
            if is_date(&from) || is_date(&to_ty) || matches!(from, Ty::Str(..)) {
                return Err(not_supported(
                    n.span,
                    format!(
                        "{up} of {}: write the conversion with both types ({from}_TO_{to})",
                        an(&from)
                    ),
                ));
            }
            return Ok((self.convert(v, &from, &to_ty), to_ty));
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

    fn convert(&mut self, v: Val, from: &Ty, to: &Ty) -> Val {
        match (v, to) {
            (Val::S(_), _) => v,
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
