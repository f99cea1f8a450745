//! Calls of user FUNCTIONs and FUNCTION_BLOCKs, inlined where they are
//! called: arguments bound in the caller's scope, the body lowered in the
//! callee's, outputs assigned back; bodies never called checked alone.

use super::*;

/// The scope of one POU body, saved while another is inlined.
pub(super) struct Scope {
    pub(super) vars: HashMap<String, Var>,
    pub(super) aliases: HashMap<String, Loc>,
    pub(super) loops: Vec<LoopLabels>,
    pub(super) returns: Vec<u32>,
    pub(super) pou: String,
}

/// The errors of the bodies of FUNCTIONs and FUNCTION_BLOCKs that are
/// never called, each lowered on its own (an FB as an instance of its own,
/// with scratch tags) into one scratch program.
pub(super) fn check_alone(
    pous: &[&Pou],
    types: &Types,
    globals: &HashMap<String, Var>,
    layout: &alba_ir::Layout,
) -> Vec<Diagnostic> {
    if pous.is_empty() {
        return Vec::new();
    }
    let mut tags = layout.tags.clone();
    let mut diags = Vec::new();
    let inst = |p: &Pou| format!("{}#check", p.name.name);
    {
        let mut d = Decl {
            types,
            tags: &mut tags,
            diags: &mut diags,
            instance_tags: 0,
            open: Vec::new(),
        };
        for p in pous {
            let prefix = if p.kind == PouKind::FunctionBlock {
                d.var(&inst(p), &Ty::User(p.name.name.clone()), None, false, p.name.span, 0);
                inst(p)
            } else {
                p.name.name.clone()
            };
            // Instances given as VAR_IN_OUT: scratch ones.
            for (_, v) in variables(&p.vars, Some(&prefix), types, &mut Vec::new()) {
                if v.kind == VarKind::InOut && matches!(v.ty, Ty::Fb(_) | Ty::User(_)) {
                    d.var(&format!("{}#io", v.tag), &v.ty, None, false, v.span, 0);
                }
            }
        }
    }
    let mut b = Builder::new(alba_ir::Layout::new(&tags, &Default::default()));
    b.begin_unit("check");
    let mut rungs = 0;
    for p in pous {
        let mut l = Lower::new(&mut b, types, globals.clone(), globals.clone(), rungs, &p.name.name);
        l.rung(p.name.span);
        let r = if p.kind == PouKind::FunctionBlock {
            l.inline_fb(p, &inst(p), &[], p.name.span, true)
        } else {
            l.inline_function(p, &[], p.name.span, true).map(|_| ())
        };
        if let Err(d) = r {
            l.diags.push(d);
        }
        rungs = l.rungs;
        diags.extend(l.diags);
    }
    diags
}

/// The arguments of a call bound: input values, in-out storage, `=>`
/// outputs, and in-outs to copy back (elements with a computed index).
pub(super) type Binding<'e> = (
    Vec<(String, Given)>,
    HashMap<String, Loc>,
    Vec<(String, &'e Arg)>,
    Vec<(&'e Expr, Loc)>,
);

/// An input argument: a value, or a structure to copy.
pub(super) enum Given {
    Val(Val),
    Copy(Loc),
}

/// The type of what a location holds.
pub(super) fn loc_type(l: &Loc) -> Option<Ty> {
    match l {
        Loc::Value { ty, .. } | Loc::Array { ty, .. } | Loc::StructArray { ty, .. } => Some(ty.clone()),
        Loc::Fb { kind, .. } => Some(Ty::Fb(*kind)),
        Loc::User { fb, .. } => Some(Ty::User(fb.clone())),
        Loc::Struct { ty, .. } => Some(Ty::Struct(ty.clone())),
        Loc::Str { ty, .. } => Some(ty.clone()),
        Loc::EnumConst(e, _) => Some(Ty::Enum(e.clone())),
        Loc::CounterQ { .. } | Loc::Bit { .. } => Some(Ty::Bool),
    }
}

/// A location whose values cannot be written from here (an FB's outputs).
pub(super) fn read_only(l: Loc) -> Loc {
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
        Loc::Str { len, chars, ty, .. } => Loc::Str {
            len,
            chars,
            ty,
            writable: false,
        },
        l => l,
    }
}

impl Lower<'_> {
    /// Storage in slots of this lowering (no tag) for a variable of a FUNCTION.
    pub(super) fn temp_storage(&mut self, ty: &Ty, span: Span) -> R<Loc> {
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
            Ty::Str(_, n) => Loc::Str {
                len: self.b.temp_i(),
                chars: Rc::new((0..*n).map(|_| self.b.temp_i()).collect()),
                ty: ty.clone(),
                writable: true,
            },
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

    pub(super) fn enter(&mut self, pou: &Pou, vars: HashMap<String, Var>, aliases: HashMap<String, Loc>) -> Scope {
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

    pub(super) fn leave(&mut self, s: Scope) {
        self.stack.pop();
        self.vars = s.vars;
        self.aliases = s.aliases;
        self.loops = s.loops;
        self.returns = s.returns;
        self.pou = s.pou;
    }

    /// Refuses a call that would inline `pou` inside itself.
    pub(super) fn check_recursion(&self, pou: &Pou, at: Span) -> R<()> {
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
    pub(super) fn params_of(vars: &[(String, Var)]) -> Vec<(String, Var)> {
        vars.iter()
            .filter(|(_, v)| matches!(v.kind, VarKind::Input | VarKind::InOut | VarKind::Output))
            .cloned()
            .collect()
    }

    /// Binds the arguments of a call to a user POU: the input values and
    /// in-out storage (evaluated in the caller's scope), and the `=>` outputs.
    pub(super) fn bind_user<'e>(
        &mut self,
        pou: &Pou,
        params: &[(String, Var)],
        args: &'e [Arg],
        span: Span,
        check: bool,
    ) -> R<Binding<'e>> {
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
        let mut back = Vec::new();
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
                    // An element with a computed index: passed by value and
                    // result (copied in here, back after the body).
                    ExprKind::Index(_, ix) if ix.iter().any(|i| const_int(i).is_none()) => {
                        let tmp = if self.struct_elements(e)?.is_some() {
                            self.composite_of(e)?
                        } else {
                            let (val, vty) = self.eval(e, Some(&v.ty.value()))?;
                            let tmp = self.temp_storage(&vty, *espan)?;
                            if let Loc::Value { place, ty, .. } = &tmp {
                                let (place, ty) = (*place, ty.clone());
                                self.store(place, val, &ty);
                            }
                            tmp
                        };
                        back.push((*e, tmp.clone()));
                        tmp
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
                let src = self.composite_of(e)?;
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
        Ok((inputs, inouts, outs, back))
    }

    /// Inlines a call of the user FUNCTION_BLOCK `pou` on the instance whose
    /// tags start with `prefix` (`check`: lowered only to check its body).
    pub(super) fn inline_fb(&mut self, pou: &Pou, prefix: &str, args: &[Arg], span: Span, check: bool) -> R<()> {
        self.check_recursion(pou, span)?;
        let vars = variables(&pou.vars, Some(prefix), self.types, &mut Vec::new());
        let params = Self::params_of(&vars);
        let (inputs, inouts, outs, back) = self.bind_user(pou, &params, args, span, check)?;
        let mut scope = self.globals.clone();
        scope.extend(vars.iter().filter(|(_, v)| v.kind != VarKind::InOut).cloned());
        let saved = self.enter(pou, scope, inouts);
        let r = self.run_body(pou, inputs, span, true);
        self.leave(saved);
        r?;
        self.write_back(back)?;
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
    pub(super) fn inline_function(&mut self, pou: &Pou, args: &[Arg], span: Span, check: bool) -> R<(Val, Ty)> {
        match self.inline_function_loc(pou, args, span, check)? {
            Some(l) => {
                let e = Expr {
                    kind: ExprKind::Name(pou.name.clone()),
                    span,
                };
                self.read_loc(&l, &e)
            }
            None => Ok((self.constant(&Lit::Bool(false), &Ty::Bool), Ty::Bool)),
        }
    }

    /// [`Lower::inline_function`], giving where its result is (a STRUCT or
    /// ARRAY result is copied from there by the caller); `None` for a
    /// FUNCTION without a result type.
    pub(super) fn inline_function_loc(&mut self, pou: &Pou, args: &[Arg], span: Span, check: bool) -> R<Option<Loc>> {
        self.check_recursion(pou, span)?;
        let vars = variables(&pou.vars, Some(&pou.name.name), self.types, &mut Vec::new());
        let params = Self::params_of(&vars);
        let ret = match &pou.ret {
            Some(t) => {
                let t = resolve_type(t, self.types, 0)?;
                if matches!(&t, Ty::Fb(_) | Ty::User(_))
                    || matches!(&t, Ty::Array(of, _) if matches!(**of, Ty::Fb(_) | Ty::User(_)))
                {
                    return Err(not_supported(
                        pou.ret.as_ref().map_or(pou.name.span, TypeRef::span),
                        format!("a FUNCTION returning {} is not supported yet", an(&t)),
                    ));
                }
                Some(t)
            }
            None => None,
        };
        let (inputs, mut aliases, outs, back) = self.bind_user(pou, &params, args, span, check)?;
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
        self.write_back(back)?;
        for (key, a) in outs {
            if let Some(src) = locals.get(&key) {
                self.assign_output(a, src)?;
            }
        }
        Ok(ret.and_then(|_| locals.get(&fkey).cloned()))
    }

    /// Copies VAR_IN_OUT arguments passed by value and result back to the
    /// elements they came from (the index evaluated again).
    fn write_back(&mut self, back: Vec<(&Expr, Loc)>) -> R<()> {
        for (e, tmp) in back {
            if let Some((elems, dims, _, ix)) = self.struct_elements(e)? {
                self.each_element(&elems, &dims, ix, e.span, &mut |l: &mut Self, el: &Loc| {
                    l.copy_loc(el, &tmp);
                    Ok(())
                })?;
            } else {
                self.assign_with(e, e.span, &mut |l: &mut Self, _| l.read_loc(&tmp, e))?;
            }
        }
        Ok(())
    }

    /// The storage an expression names, or the result of a user FUNCTION it
    /// calls (for structures and arrays, copied as a whole).
    pub(super) fn composite_of(&mut self, e: &Expr) -> R<Loc> {
        if let ExprKind::Call(n, args) = &e.kind
            && let Some(p) = self.types.pous.get(&n.name.to_ascii_lowercase()).copied()
            && p.kind == PouKind::Function
        {
            return match self.inline_function_loc(p, args, e.span, false)? {
                Some(l) => Ok(l),
                None => Err(type_error(e.span, format!("`{}` has no result", n.name))),
            };
        }
        // An element of an array of structures with a computed index: copied
        // into slots of its own, one guarded copy per element.
        if let Some((elems, dims, of, ix)) = self.struct_elements(e)? {
            let tmp = self.temp_storage(&of, e.span)?;
            self.each_element(&elems, &dims, ix, e.span, &mut |l: &mut Self, el: &Loc| {
                l.copy_loc(&tmp, el);
                Ok(())
            })?;
            return Ok(tmp);
        }
        self.locate(e)
    }

    /// `a[i]` on an array of structures with a computed index: the elements,
    /// the bounds, the element type and the indexes.
    #[allow(clippy::type_complexity)]
    pub(super) fn struct_elements<'e>(
        &mut self,
        e: &'e Expr,
    ) -> R<Option<(Rc<Vec<Loc>>, Vec<(i64, i64)>, Ty, &'e [Expr])>> {
        let ExprKind::Index(base, ix) = &e.kind else {
            return Ok(None);
        };
        if ix.iter().all(|i| const_int(i).is_some()) {
            return Ok(None);
        }
        match self.locate(base) {
            Ok(Loc::StructArray {
                elems,
                dims,
                ty: Ty::Array(of, _),
            }) if matches!(*of, Ty::Struct(_)) => Ok(Some((elems, dims, *of, ix))),
            _ => Ok(None),
        }
    }

    /// Runs `f` on the element a computed index chooses: one guarded copy of
    /// what `f` lowers per element (an index out of range is the range fault
    /// and chooses none).
    pub(super) fn each_element(
        &mut self,
        elems: &[Loc],
        dims: &[(i64, i64)],
        ix: &[Expr],
        span: Span,
        f: &mut dyn FnMut(&mut Self, &Loc) -> R<()>,
    ) -> R<()> {
        let flat = match self.flat_index(dims, ix, span)? {
            Ok(k) => return f(self, &elems[k]),
            Err(flat) => flat,
        };
        for (k, el) in elems.iter().enumerate() {
            let kc = self.b.const_i(k as i32);
            self.emit(Op::CmpI(Cmp::Ne, flat, kc));
            let skip = self.emit(Op::Jmp(0));
            self.emit(Op::True);
            f(self, el)?;
            let next = self.rung(span);
            self.patch(&[skip], next);
        }
        Ok(())
    }

    /// The inputs stored, then the body of a user POU, in the scope entered.
    pub(super) fn run_body(&mut self, pou: &Pou, inputs: Vec<(String, Given)>, span: Span, temps: bool) -> R<()> {
        for (key, g) in inputs {
            let loc = self.lookup(&Ident { name: key, span })?;
            match (g, &loc) {
                (Given::Val(v), Loc::Value { place, ty, .. }) => {
                    let (place, ty) = (*place, ty.clone());
                    self.store_checked(place, v, &ty);
                }
                (Given::Val(v), Loc::Str { len, chars, .. }) => {
                    if let Some(src) = self.str_of(v) {
                        let (len, chars) = (*len, chars.clone());
                        self.str_store(len, &chars, &src);
                    }
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
    pub(super) fn assign_output(&mut self, a: &Arg, src: &Loc) -> R<()> {
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

    /// An input or output of an instance of a user FUNCTION_BLOCK.
    pub(super) fn user_member(&mut self, fb: &str, prefix: &str, m: &Ident) -> R<Loc> {
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

    /// A call of an element of an array of function block instances
    /// (`t[2](…)`, or `t[i](…)`: one branch per element).
    pub(super) fn call_element(&mut self, base: &Expr, ix: &[Expr], args: &[Arg], callee: &Expr, span: Span) -> R<()> {
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

    pub(super) fn call_loc(&mut self, l: Loc, inst: &Ident, args: &[Arg], span: Span) -> R<()> {
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
}
