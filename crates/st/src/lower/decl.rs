//! The variables of POUs and the tags they are declared as (before the
//! layout is made): PROGRAM variables, instances of function blocks member
//! by member, structures, arrays.

use super::*;

pub(super) fn plain_tag(
    name: String,
    ty: DataType,
    initial: Option<Value>,
    retain: bool,
    description: String,
    span: Span,
) -> Tag {
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
pub(super) struct Var {
    pub(super) ty: Ty,
    /// Its tag's name (its elements' names add `[i]`).
    pub(super) tag: String,
    pub(super) kind: VarKind,
    pub(super) retain: bool,
    pub(super) constant: bool,
    pub(super) init: Option<Init>,
    pub(super) span: Span,
}

/// The variables of `pou` (or of the file's `VAR_GLOBAL`s, prefix `None`),
/// by lower-case name, with the errors of their declarations.
pub(super) fn variables(
    blocks: &[ast::VarBlock],
    prefix: Option<&str>,
    types: &Types,
    diags: &mut Vec<Diagnostic>,
) -> Vec<(String, Var)> {
    let mut out: Vec<(String, Var)> = Vec::new();
    // Where each name was first declared (a map: a PROGRAM may have thousands).
    let mut seen: HashMap<String, Span> = HashMap::new();
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
                if let Some(prev) = seen.get(&key) {
                    diags.push(
                        decl_error(n.span, format!("`{}` is declared twice", n.name))
                            .with_note(*prev, "first declared here"),
                    );
                    continue;
                }
                seen.insert(key.clone(), n.span);
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
pub(super) struct Decl<'t, 'a> {
    pub(super) types: &'t Types<'a>,
    pub(super) tags: &'t mut TagTable,
    pub(super) diags: &'t mut Vec<Diagnostic>,
    /// Tags declared for instances of user FUNCTION_BLOCKs.
    pub(super) instance_tags: usize,
    /// The FUNCTION_BLOCKs whose instance is being declared (lower-case).
    pub(super) open: Vec<String>,
}

impl Decl<'_, '_> {
    /// Adds the tags of a variable of type `ty` named `tag`.
    pub(super) fn var(&mut self, tag: &str, ty: &Ty, init: Option<&Init>, retain: bool, span: Span, depth: u32) {
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
            Ty::Str(wide, n) => {
                let text = match init {
                    None => String::new(),
                    Some(Init::Expr(Expr {
                        kind: ExprKind::Lit(Lit::Str(t, w)),
                        ..
                    })) if w == wide => t.clone(),
                    Some(Init::Expr(e)) => {
                        self.diags
                            .push(type_error(e.span, format!("a {ty} takes a string literal")));
                        String::new()
                    }
                    Some(Init::Array(_, span) | Init::Struct(_, span)) => {
                        self.diags
                            .push(type_error(*span, format!("a {ty} takes one string literal")));
                        String::new()
                    }
                };
                let codes: Vec<i32> = if *wide {
                    text.encode_utf16().map(i32::from).collect()
                } else {
                    text.bytes().map(i32::from).collect()
                };
                // A longer initial value is cut to the length, as `:=` does.
                let len = codes.len().min(*n as usize);
                self.tags.push(plain(
                    format!("{tag}.LEN"),
                    DataType::Dint,
                    Some(Value::Dint(len as i32)),
                ));
                for k in 0..*n as usize {
                    let c = codes.get(k).filter(|_| k < len).copied().unwrap_or(0);
                    self.tags
                        .push(plain(format!("{tag}[{}]", k + 1), DataType::Dint, Some(Value::Dint(c))));
                }
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
            Ty::Array(of, dims) if matches!(**of, Ty::Struct(_) | Ty::Fb(_) | Ty::User(_) | Ty::Str(..)) => {
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
            // Reported once, in the later of the two files.
            && other.name.span.file < p.name.span.file
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
