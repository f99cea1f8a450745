//! Petri-mode nets (SPEC §10.5, docs/nets.md "petri") lowered onto the one IR.
//!
//! Each place's marking is a DINT tag `<net>.<place id>` laid out after the
//! tags of tags.csv ([`marking_tags`]). In its turn, the net:
//!
//! 1. copies the marking of every input place into an *available* temporary
//!    and clears a *produced* temporary of every output place;
//! 2. takes the transitions in order (priority given first, lower first, then
//!    document order), one rung each: `rc = guard AND avail >= w (inputs) AND
//!    m < w (inhibitors) AND m >= w (read arcs)`; if `rc`, `avail -= w` for the
//!    inputs and `produced += w` for the outputs. Markings are not written
//!    during the turn, so guards, inhibitor and read arcs see the starting
//!    marking;
//! 3. writes `marking = avail + produced`, then every `<tag>` BOOL =
//!    `marking > 0`.
//!
//! Only existing ops are used, so every engine mode and the Arduino export
//! run nets unchanged.

use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_ir::values::{Class, V, class_of_lit, class_of_type, float_class, promote};
use alba_ir::{Access, BinOp, Builder, Cmp, I, Op, Place, Target, UnOp};
use alba_ladder::expr::{self, BinE, Expr, Func};
use alba_model::{Address, DataType, Literal, Tag, TagTable, Value};
use alba_net::{ArcKind, ElementKind, Net};
use std::collections::HashMap;
use std::path::Path;

/// The name of a net: its file name without the extension.
pub fn net_name(program: &str) -> String {
    Path::new(program)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or(program)
        .to_string()
}

/// The marking tag of a place.
pub fn marking_tag(net: &str, place: &str) -> String {
    format!("{net}.{place}")
}

/// A tag a net (or chart) adds to the tag table: never retained, no address.
pub(crate) fn net_tag(name: String, ty: DataType, initial: Option<Value>, description: String, span: Span) -> Tag {
    Tag {
        name,
        ty,
        address: None,
        address_text: None,
        initial,
        members: Vec::new(),
        retain: false,
        description,
        span,
    }
}

/// The numbers of the rungs that compute the transitions' "enabled"
/// elements (one per transition, in document order, after the turn).
pub const ENABLED_RUNGS: u32 = 20_000;

/// The span of a transition's "enabled" element: empty, at the start of the
/// transition's tag (its "fired" element has the tag's span). The server
/// finds both by span (`GET /api/programs/{name}`, `transitions`).
pub fn enabled_span(transition: Span) -> Span {
    Span::new(transition.file, transition.start as usize..transition.start as usize)
}

/// A `<tag>` place: the tag it drives and, for a numeric tag, the constant
/// (its `value` prop) the tag holds while the place is marked.
pub(crate) struct Drive {
    place: usize,
    dest: Place,
    value: Option<Literal>,
}

/// Writes each `<tag>` place's tag: a BOOL true while the place is marked;
/// a number its `value` while marked, else 0 (the source's State sets its
/// variable to 1 while it has the token; issue 34 lets it set a constant).
pub(crate) fn emit_drives(b: &mut Builder, net: &Net, drives: Vec<Drive>, marking: &[I], zero: I) {
    for d in drives {
        let span = net.places[d.place].span;
        let elem = b.element(span);
        b.emit(Op::True, elem);
        b.emit(Op::CmpI(Cmp::Gt, marking[d.place], zero), elem);
        let Some(v) = d.value else {
            let (out, post) = b.bool_out(d.dest, elem);
            b.emit(Op::Ote(out), elem);
            b.post(post, elem);
            continue;
        };
        lower_assign(b, d.dest, &Expr::Lit(v, span), elem);
        b.emit(Op::True, elem);
        b.emit(Op::CmpI(Cmp::Le, marking[d.place], zero), elem);
        lower_assign(b, d.dest, &Expr::Lit(Literal::Int(0), span), elem);
    }
}

/// Adds the marking tags of `net` to `tags` (DINT, initial value = initial
/// marking, not retained); a name already taken is an error.
pub fn marking_tags(net: &Net, name: &str, tags: &mut TagTable, diags: &mut Vec<Diagnostic>) {
    for p in &net.places {
        let tag = marking_tag(name, &p.id);
        if let Some(t) = tags.get(&tag) {
            diags.push(
                Diagnostic::new(
                    Code::NetTagClash,
                    format!(
                        "the marking of place `{}` is the tag `{tag}`, which already exists",
                        p.id
                    ),
                    p.span,
                    "place",
                )
                .with_note(t.span, "declared here")
                .with_help("rename the place or the tag (or the net's file)"),
            );
            continue;
        }
        // `Delay.DN` must keep meaning the member of the TIMER `Delay`.
        if let Some(t) = tags.get(name).filter(|t| t.ty.member(&p.id).is_some()) {
            diags.push(
                Diagnostic::new(
                    Code::NetTagClash,
                    format!(
                        "the marking of place `{}` would be `{tag}`, a member of the {} `{}`",
                        p.id, t.ty, t.name
                    ),
                    p.span,
                    "place",
                )
                .with_note(t.span, "declared here")
                .with_help("rename the place or the net's file"),
            );
            continue;
        }
        let Ok(initial) = i32::try_from(p.initial) else {
            diags.push(Diagnostic::new(
                Code::NetRange,
                format!("the initial marking {} does not fit a DINT", p.initial),
                p.span,
                "place",
            ));
            continue;
        };
        tags.push(net_tag(
            tag,
            DataType::Dint,
            Some(Value::Dint(initial)),
            format!("marking of place {} of net {name}", p.id),
            p.span,
        ));
    }
}

/// The I/O and marker addresses a net names (in guards and `<tag>`s), so
/// that the layout's images hold them.
pub fn addresses(net: &Net, file: FileId) -> Vec<Address> {
    fn names(e: &Expr, out: &mut Vec<Address>) {
        match e {
            Expr::Name(n, _) => {
                if let Ok(Some(a)) = Address::parse(n) {
                    out.push(a);
                }
            }
            Expr::Neg(a) | Expr::Not(a, _) => names(a, out),
            Expr::Bin(_, a, b, _) => {
                names(a, out);
                names(b, out);
            }
            Expr::Call(_, args, _) => args.iter().for_each(|a| names(a, out)),
            Expr::Lit(..) | Expr::Const(_) => {}
        }
    }
    let mut out = Vec::new();
    for g in net.transitions.iter().filter_map(|t| t.guard.as_ref()) {
        if let Ok(e) = expr::parse_net(&g.text, file, g.span.start as usize) {
            names(&e, &mut out);
        }
    }
    for tag in net.places.iter().filter_map(|p| p.tag.as_deref()) {
        if let Ok(Some(a)) = Address::parse(tag) {
            out.push(a);
        }
    }
    out
}

#[derive(Default)]
struct Arcs {
    input: Vec<(usize, i32)>,
    output: Vec<(usize, i32)>,
    inhibitor: Vec<(usize, i32)>,
    read: Vec<(usize, i32)>,
}

/// Adds weight `w` for place `p` (arcs between the same pair add up).
fn add(list: &mut Vec<(usize, i32)>, p: usize, w: i32) -> bool {
    if let Some(e) = list.iter_mut().find(|e| e.0 == p) {
        match e.1.checked_add(w) {
            Some(s) => e.1 = s,
            None => return false,
        }
    } else {
        list.push((p, w));
    }
    true
}

/// Compiles a Petri-mode net as one unit. Its marking tags are in the
/// layout already ([`marking_tags`]).
pub fn compile(net: &Net, file: FileId, text: &str, unit: &str, b: &mut Builder) -> Vec<Diagnostic> {
    compile_with(net, file, text, unit, b, (|_| {}, |_, _| {}))
}

/// [`compile`], with `before` adding rungs to the net's unit ahead of its
/// turn (an SFC's conditions in ST) and `after` once the new marking is
/// written (an SFC's step flags and actions), given the marking slot of
/// each place.
pub(crate) fn compile_with(
    net: &Net,
    file: FileId,
    text: &str,
    unit: &str,
    b: &mut Builder,
    (before, after): (impl FnOnce(&mut Builder), impl FnOnce(&mut Builder, &[I])),
) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    let name = net_name(unit);
    let at_start = Span::new(file, 0..text.len().min(1));
    // Element kinds of the source's state nets run only in normal mode.
    let kinds = net
        .places
        .iter()
        .filter(|p| p.kind != ElementKind::State)
        .map(|p| (p.kind, p.span));
    let kinds = kinds.chain(
        net.transitions
            .iter()
            .filter(|t| t.kind != ElementKind::Transition)
            .map(|t| (t.kind, t.span)),
    );
    for (kind, span) in kinds {
        diags.push(
            Diagnostic::new(
                Code::NetMode,
                format!(
                    "{} {} element runs in normal mode, not in a Petri-mode net",
                    if kind.as_str().starts_with(['a', 'e', 'i', 'o', 'u']) { "an" } else { "a" },
                    kind.as_str()
                ),
                span,
                "not a plain place or transition",
            )
            .with_help(
                "a Petri-mode net has plain places and transitions (guards and `<tag>` give it conditions and actions); \
                 the state-net kinds need `<mode>normal</mode>`",
            ),
        );
    }
    // Marking slots.
    let mut marking = Vec::with_capacity(net.places.len());
    let mut place_of = HashMap::new();
    for (k, p) in net.places.iter().enumerate() {
        place_of.insert(p.id.as_str(), k);
        let slot = match b.layout().resolve(&marking_tag(&name, &p.id)) {
            Ok(Target::Value {
                place: Place::Int(i, _),
                ..
            }) => Some(i),
            _ => None,
        };
        marking.push(slot);
    }
    let tr_of: HashMap<&str, usize> = net
        .transitions
        .iter()
        .enumerate()
        .map(|(k, t)| (t.id.as_str(), k))
        .collect();
    let mut arcs: Vec<Arcs> = net.transitions.iter().map(|_| Arcs::default()).collect();
    for a in &net.arcs {
        let Ok(w) = i32::try_from(a.weight) else {
            diags.push(Diagnostic::new(
                Code::NetRange,
                format!("the weight {} does not fit a DINT marking", a.weight),
                a.span,
                "arc",
            ));
            continue;
        };
        let pt = (place_of.get(a.source.as_str()), tr_of.get(a.target.as_str()));
        let tp = (tr_of.get(a.source.as_str()), place_of.get(a.target.as_str()));
        let ok = match (pt, tp, a.kind) {
            ((Some(&p), Some(&t)), _, ArcKind::Normal) => add(&mut arcs[t].input, p, w),
            ((Some(&p), Some(&t)), _, ArcKind::Inhibitor) => add(&mut arcs[t].inhibitor, p, w),
            ((Some(&p), Some(&t)), _, ArcKind::Read) => add(&mut arcs[t].read, p, w),
            (_, (Some(&t), Some(&p)), ArcKind::Normal) => add(&mut arcs[t].output, p, w),
            (_, (Some(_), Some(_)), _) => {
                diags.push(Diagnostic::new(
                    Code::NetArc,
                    "an inhibitor or read arc goes from a place to a transition",
                    a.span,
                    "arc from a transition",
                ));
                true
            }
            // Unknown ends and place-to-place arcs: the loader reports them.
            _ => true,
        };
        if !ok {
            diags.push(Diagnostic::new(
                Code::NetRange,
                "the arcs between these two nodes weigh more than a DINT holds",
                a.span,
                "arc",
            ));
        }
    }
    let drives = drives(net, &name, b, &mut diags);
    let guards = guards(net, file, text, b, &mut diags);
    if !diags.is_empty() || marking.iter().any(Option::is_none) {
        return diags;
    }
    let marking: Vec<I> = marking.into_iter().flatten().collect();

    b.begin_unit(unit);
    let mark = b.mark();
    before(b);
    let zero = b.const_i(0);
    // 1. The available and produced tokens.
    let first = net.transitions.first().map_or(at_start, |t| t.span);
    b.begin_rung(0, first);
    let mut avail: Vec<Option<I>> = vec![None; net.places.len()];
    let mut produced: Vec<Option<I>> = vec![None; net.places.len()];
    for a in &arcs {
        for &(p, _) in &a.input {
            if avail[p].is_none() {
                let t = b.temp_i();
                b.emit(Op::CopyI(marking[p], t), alba_ir::NO_ELEM);
                avail[p] = Some(t);
            }
        }
        for &(p, _) in &a.output {
            if produced[p].is_none() {
                let t = b.temp_i();
                b.emit(Op::CopyI(zero, t), alba_ir::NO_ELEM);
                produced[p] = Some(t);
            }
        }
    }
    // 2. The transitions.
    let mut guard_bits: Vec<Option<alba_ir::B>> = vec![None; net.transitions.len()];
    for (n, &t) in net.firing_order().iter().enumerate() {
        let tr = &net.transitions[t];
        let a = &arcs[t];
        b.begin_rung(n as u32 + 1, tr.span);
        let elem = b.element(tr.span);
        if let Some(g) = &guards[t] {
            lower_guard(b, g, elem);
            // Kept for the transition's "enabled" element (below).
            let gb = b.temp_b();
            b.emit(Op::Ote(gb), elem);
            guard_bits[t] = Some(gb);
        }
        for &(p, w) in &a.input {
            if let Some(av) = avail[p] {
                let w = b.const_i(w);
                b.emit(Op::CmpI(Cmp::Ge, av, w), elem);
            }
        }
        for &(p, w) in &a.inhibitor {
            let w = b.const_i(w);
            b.emit(Op::CmpI(Cmp::Lt, marking[p], w), elem);
        }
        for &(p, w) in &a.read {
            let w = b.const_i(w);
            b.emit(Op::CmpI(Cmp::Ge, marking[p], w), elem);
        }
        for &(p, w) in &a.input {
            if let Some(av) = avail[p] {
                let w = b.const_i(w);
                b.emit(Op::BinI(BinOp::Sub, av, w, av), elem);
            }
        }
        for &(p, w) in &a.output {
            if let Some(pr) = produced[p] {
                let w = b.const_i(w);
                b.emit(Op::BinI(BinOp::Add, pr, w, pr), elem);
            }
        }
    }
    // 3. The new marking, then the driven tags.
    let end = net.places.first().map_or(first, |p| p.span);
    b.begin_rung(net.transitions.len() as u32 + 1, end);
    for (p, &m) in marking.iter().enumerate() {
        let from = avail[p].unwrap_or(m);
        match produced[p] {
            Some(pr) => {
                b.emit(Op::BinI(BinOp::Add, from, pr, m), alba_ir::NO_ELEM);
            }
            None if from != m => {
                b.emit(Op::CopyI(from, m), alba_ir::NO_ELEM);
            }
            None => {}
        }
    }
    emit_drives(b, net, drives, &marking, zero);
    after(b, &marking);
    // 4. Monitoring: each transition's "enabled" element, on the new marking.
    for (t, tr) in net.transitions.iter().enumerate() {
        let a = &arcs[t];
        b.begin_rung(ENABLED_RUNGS + t as u32, tr.span);
        let elem = b.element(enabled_span(tr.span));
        b.emit(Op::True, elem);
        if let Some(gb) = guard_bits[t] {
            b.emit(Op::Xic(gb), elem);
        }
        for &(p, w) in a.input.iter().chain(&a.read) {
            let w = b.const_i(w);
            b.emit(Op::CmpI(Cmp::Ge, marking[p], w), elem);
        }
        for &(p, w) in &a.inhibitor {
            let w = b.const_i(w);
            b.emit(Op::CmpI(Cmp::Lt, marking[p], w), elem);
        }
    }
    b.release(mark);
    b.end_unit();
    diags
}

/// The `<tag>` places of `net`: each the tag it drives (a BOOL, or a number
/// with the place's `value`), checked (E622).
pub(crate) fn drives(net: &Net, name: &str, b: &Builder, diags: &mut Vec<Diagnostic>) -> Vec<Drive> {
    let mut drives = Vec::new();
    for (k, p) in net.places.iter().enumerate() {
        let bad = |msg: String| Diagnostic::new(Code::NetPlaceTag, msg, p.span, "place");
        // a State's constant (`003_…`); other kinds (a Variable's DefineTarget) read `value` themselves
        let own = if p.kind == ElementKind::State {
            p.props.get("value")
        } else {
            None
        };
        let value = match own.map(|v| v.trim()) {
            None => None,
            Some(v) => match Literal::parse(v) {
                Ok(l @ (Literal::Int(_) | Literal::Real(_))) => Some(l),
                _ => {
                    diags.push(
                        bad(format!("the value `{v}` of place `{}` is not a number", p.id)).with_help(
                            "while marked, the place's numeric `<tag>` holds this constant: `5`, `-2`, `1.5`",
                        ),
                    );
                    continue;
                }
            },
        };
        let Some(tag) = &p.tag else {
            if value.is_some() {
                diags.push(
                    bad(format!("place `{}` has a `value` but no `<tag>` to write it to", p.id))
                        .with_help("give it `<tag>NAME</tag>`, a numeric tag"),
                );
            }
            continue;
        };
        match b.layout().resolve(tag) {
            // a number with the place's `value`, or a BOOL without one: written while marked
            Ok(Target::Value { place, access })
                if match value {
                    Some(_) => place.data_type() != DataType::Bool && place.data_type().is_numeric(),
                    None => place.data_type() == DataType::Bool,
                } =>
            {
                let (verb, what) = if value.is_some() {
                    ("write", "a tag to write")
                } else {
                    ("drive", "a BOOL")
                };
                if access != Access::ReadWrite {
                    diags.push(bad(format!(
                        "place `{}` cannot {verb} `{tag}`: {}",
                        p.id,
                        access.why_not_writable()
                    )));
                } else if net
                    .places
                    .iter()
                    .any(|q| marking_tag(name, &q.id).eq_ignore_ascii_case(tag))
                {
                    diags.push(bad(format!("`{tag}` is a marking, not {what}")));
                } else {
                    drives.push(Drive {
                        place: k,
                        dest: place,
                        value,
                    });
                }
            }
            Ok(Target::Value { place, .. }) if value.is_some() => diags.push(
                bad(format!(
                    "place `{}` writes its value to `{tag}`, which is {}, not a number",
                    p.id,
                    place.data_type().with_article()
                ))
                .with_help("a BOOL tag is true while the place is marked: leave the `value` out"),
            ),
            Ok(Target::Value { place, .. }) => diags.push(
                bad(format!(
                    "place `{}` drives `{tag}`, which is {}, not a BOOL",
                    p.id,
                    place.data_type().with_article()
                ))
                .with_help("or give the place a `value`: the number the tag holds while it is marked"),
            ),
            Ok(_) => diags.push(bad(format!("`{tag}` is a structure, not a BOOL; name a member"))),
            Err(e) => {
                let mut d = bad(format!("place `{}` drives {e}", p.id));
                if let Some(s) = b.layout().tags.suggest(tag) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                diags.push(d);
            }
        }
    }
    drives
}

/// The guards of `net`'s transitions, parsed and typed as BOOL (E621);
/// `None` for a transition without one (or with an error, reported).
pub(crate) fn guards(
    net: &Net,
    file: FileId,
    text: &str,
    b: &mut Builder,
    diags: &mut Vec<Diagnostic>,
) -> Vec<Option<Expr>> {
    let mut guards = Vec::with_capacity(net.transitions.len());
    for t in &net.transitions {
        let before = diags.len();
        let g = t
            .guard
            .as_ref()
            .and_then(|g| match expr::parse_net(&g.text, file, g.span.start as usize) {
                Ok(e) => {
                    let mut gc = Guard { b, diags: &mut *diags };
                    match gc.ty(&e) {
                        Some(Ty::Bool) => Some(e),
                        Some(Ty::Num(_)) => {
                            gc.diags.push(
                                Diagnostic::new(
                                    Code::NetGuard,
                                    format!("the guard of transition `{}` is a number, not a BOOL", t.id),
                                    g.span,
                                    "not BOOL",
                                )
                                .with_help("compare it: `count > 0`"),
                            );
                            None
                        }
                        None => None,
                    }
                }
                Err((msg, span)) => {
                    diags.push(Diagnostic::new(Code::NetGuard, msg, span, "in this guard"));
                    None
                }
            });
        // After an entity (`&gt;`) or in CDATA, the text's offsets are not
        // the file's: a problem found there points at the whole guard.
        if let Some(g) = &t.guard {
            let raw = text.get(g.span.start as usize..g.span.end as usize).unwrap_or("");
            let exact = g.span.start + raw.find(['&', '<']).unwrap_or(raw.len()) as u32;
            for d in &mut diags[before..] {
                if let Some(l) = d.primary.as_mut().filter(|l| l.span.end > exact) {
                    l.span = g.span;
                }
            }
        }
        guards.push(g);
    }
    guards
}

/// Checks a numeric expression of a script (E631): its names, types and
/// operators, as a guard's are checked; errors are pushed with `code`.
pub(crate) fn check_number(b: &mut Builder, e: &Expr, diags: &mut Vec<Diagnostic>) -> bool {
    let before = diags.len();
    let t = Guard { b, diags: &mut *diags }.ty(e);
    for d in &mut diags[before..] {
        d.code = Code::NetScript;
    }
    match t {
        Some(Ty::Num(_)) => true,
        Some(Ty::Bool) => false,
        None => false,
    }
}

/// `dest = e` while the rung condition holds: computed in the widest class
/// of its operands (as CPT, SPEC §3.2), then converted and narrowed into
/// `dest`, with the faults of Ladder's math.
pub(crate) fn lower_assign(b: &mut Builder, dest: Place, e: &Expr, elem: u32) {
    let mut diags = Vec::new();
    let inner = b.mark();
    let mut g = Guard { b, diags: &mut diags };
    let c = g.class(e);
    let v = g.num(e, c, elem);
    if let Some(v) = v {
        let (d, post) = b.dest(dest, c, elem);
        b.un(UnOp::Mov, v, d, elem);
        b.post(post, elem);
    }
    b.release(inner);
}

/// Lowers a typed guard into the rung condition (`guards` checked it).
pub(crate) fn lower_guard(b: &mut Builder, e: &Expr, elem: u32) {
    let mut diags = Vec::new();
    let inner = b.mark();
    Guard { b, diags: &mut diags }.cond(e, elem);
    b.release(inner);
}

/// Lowers `e`, a BOOL expression of Alba's expression language (a property
/// of `alba verify`, docs/verify.md), into ops that write its value to
/// `dest`: typed and lowered as a guard is, so that its comparisons,
/// arithmetic, conversions and faults are the engine's (one semantics,
/// SPEC §11). Problems are returned with `code` (a number is refused at
/// `span`, the whole expression); nothing is emitted then.
pub fn lower_condition(
    b: &mut Builder,
    e: &Expr,
    span: Span,
    dest: alba_ir::B,
    elem: u32,
    code: Code,
) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    let ty = Guard { b, diags: &mut diags }.ty(e);
    for d in &mut diags {
        d.code = code;
    }
    match ty {
        Some(Ty::Bool) => {
            lower_guard(b, e, elem);
            b.emit(Op::Ote(dest), elem);
        }
        Some(Ty::Num(_)) => {
            diags.push(
                Diagnostic::new(code, "this expression is a number, not a BOOL", span, "not BOOL")
                    .with_help("compare it: `C.ACC > 0`"),
            );
        }
        None => {}
    }
    diags
}

/// `TRUE` and `FALSE` (reserved words, never tag names).
fn bool_word(name: &str) -> Option<bool> {
    if name.eq_ignore_ascii_case("TRUE") {
        Some(true)
    } else if name.eq_ignore_ascii_case("FALSE") {
        Some(false)
    } else {
        None
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ty {
    Bool,
    Num(Class),
}

/// Types and lowers a guard: a BOOL expression of Alba's expression
/// language, left in the rung condition.
struct Guard<'a> {
    b: &'a mut Builder,
    diags: &'a mut Vec<Diagnostic>,
}

impl Guard<'_> {
    fn err(&mut self, msg: impl Into<String>, span: Span, label: &str) {
        self.diags.push(Diagnostic::new(Code::NetGuard, msg, span, label));
    }

    fn place(&mut self, name: &str, span: Span) -> Option<Place> {
        match self.b.layout().resolve(name) {
            Ok(Target::Value { place, .. }) => Some(place),
            Ok(_) => {
                self.err(
                    format!("`{name}` is a structure; name a member (`{name}.DN`)"),
                    span,
                    "structure",
                );
                None
            }
            Err(e) => {
                let mut d = Diagnostic::new(Code::NetGuard, e.to_string(), span, "in this guard");
                if let Some(s) = self.b.layout().tags.suggest(name) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                self.diags.push(d);
                None
            }
        }
    }

    fn span_of(e: &Expr) -> Option<Span> {
        match e {
            Expr::Lit(_, s) | Expr::Name(_, s) | Expr::Not(_, s) | Expr::Bin(_, _, _, s) | Expr::Call(_, _, s) => {
                Some(*s)
            }
            Expr::Neg(a) => Self::span_of(a),
            Expr::Const(_) => None,
        }
    }

    /// The type of `e`, with every error reported.
    fn ty(&mut self, e: &Expr) -> Option<Ty> {
        match e {
            Expr::Lit(Literal::Bool(_), _) => Some(Ty::Bool),
            Expr::Name(n, _) if bool_word(n).is_some() => Some(Ty::Bool),
            Expr::Lit(l, _) => Some(Ty::Num(class_of_lit(*l))),
            Expr::Const(_) => Some(Ty::Num(Class::F)),
            Expr::Name(n, sp) => {
                let p = self.place(n, *sp)?;
                Some(match p.data_type() {
                    DataType::Bool => Ty::Bool,
                    t => Ty::Num(class_of_type(t)),
                })
            }
            Expr::Neg(a) => match self.ty(a)? {
                Ty::Num(c) => Some(Ty::Num(c)),
                Ty::Bool => {
                    if let Some(sp) = Self::span_of(a) {
                        self.err("`-` needs a number, found a BOOL", sp, "BOOL");
                    }
                    None
                }
            },
            Expr::Not(a, sp) => match self.ty(a)? {
                Ty::Bool => Some(Ty::Bool),
                Ty::Num(_) => {
                    self.err("NOT needs a BOOL in a guard, found a number", *sp, "NOT of a number");
                    None
                }
            },
            Expr::Bin(op, a, c, sp) => {
                let (x, y) = (self.ty(a), self.ty(c));
                let (x, y) = (x?, y?);
                match op {
                    BinE::And | BinE::Or | BinE::Xor => {
                        if x == Ty::Bool && y == Ty::Bool {
                            Some(Ty::Bool)
                        } else {
                            self.err(
                                format!("{op:?} joins BOOLs in a guard; compare numbers first").to_uppercase(),
                                *sp,
                                "not BOOL",
                            );
                            None
                        }
                    }
                    BinE::Eq | BinE::Ne if x == Ty::Bool && y == Ty::Bool => Some(Ty::Bool),
                    _ => match (x, y) {
                        (Ty::Num(p), Ty::Num(q)) => {
                            let c = promote([p, q]);
                            Some(match op {
                                BinE::Eq | BinE::Ne | BinE::Lt | BinE::Gt | BinE::Le | BinE::Ge => Ty::Bool,
                                BinE::Pow => Ty::Num(float_class(c)),
                                _ => Ty::Num(c),
                            })
                        }
                        _ => {
                            self.err("this operation needs numbers on both sides, found a BOOL", *sp, "BOOL");
                            None
                        }
                    },
                }
            }
            Expr::Call(f, args, sp) => {
                let mut classes = Vec::new();
                let mut ok = true;
                for a in args {
                    match self.ty(a) {
                        Some(Ty::Num(c)) => classes.push(c),
                        Some(Ty::Bool) => {
                            self.err("a function needs numbers, found a BOOL", *sp, "BOOL argument");
                            ok = false;
                        }
                        None => ok = false,
                    }
                }
                if !ok {
                    return None;
                }
                if matches!(f, Func::Frd | Func::Tod) {
                    self.err("FRD and TOD are CPT's (BCD) functions, not a net's", *sp, "function");
                    return None;
                }
                let c = promote(classes);
                Some(Ty::Num(if f.is_float() { float_class(c) } else { c }))
            }
        }
    }

    /// Emits ops that leave `rc` = the value of the BOOL expression `e`
    /// (whatever `rc` was before).
    fn cond(&mut self, e: &Expr, elem: u32) -> Option<()> {
        match e {
            Expr::Lit(Literal::Bool(v), _) => {
                self.b.emit(Op::True, elem);
                if !v {
                    self.b.emit(Op::Not, elem);
                }
            }
            Expr::Name(n, _) if let Some(v) = bool_word(n) => {
                self.b.emit(Op::True, elem);
                if !v {
                    self.b.emit(Op::Not, elem);
                }
            }
            Expr::Name(n, sp) => {
                let p = self.place(n, *sp)?;
                let s = self.b.bool_in(p, elem);
                self.b.emit(Op::Ld(s), elem);
            }
            Expr::Not(a, _) => {
                self.cond(a, elem)?;
                self.b.emit(Op::Not, elem);
            }
            Expr::Bin(op, a, c, _) if self.is_bool(a) => {
                self.cond(a, elem)?;
                let t = self.b.temp_b();
                self.b.emit(Op::Ote(t), elem);
                self.cond(c, elem)?;
                match op {
                    BinE::And => {
                        self.b.emit(Op::Xic(t), elem);
                    }
                    BinE::Or => {
                        self.b.emit(Op::Or(t), elem);
                    }
                    _ => {
                        // XOR, `<>` and `=` of two BOOLs.
                        let u = self.b.temp_b();
                        let v = self.b.temp_b();
                        self.b.emit(Op::Ote(u), elem);
                        self.b.emit(Op::Ld(t), elem);
                        self.b.emit(Op::Xio(u), elem);
                        self.b.emit(Op::Ote(v), elem);
                        self.b.emit(Op::Ld(u), elem);
                        self.b.emit(Op::Xio(t), elem);
                        self.b.emit(Op::Or(v), elem);
                        if *op == BinE::Eq {
                            self.b.emit(Op::Not, elem);
                        }
                    }
                }
            }
            Expr::Bin(op, a, c, _) => {
                let cmp = match op {
                    BinE::Eq => Cmp::Eq,
                    BinE::Ne => Cmp::Ne,
                    BinE::Lt => Cmp::Lt,
                    BinE::Gt => Cmp::Gt,
                    BinE::Le => Cmp::Le,
                    BinE::Ge => Cmp::Ge,
                    _ => return None,
                };
                let class = promote([self.class(a), self.class(c)]);
                // Data operations act only while `rc` is true.
                self.b.emit(Op::True, elem);
                let x = self.num(a, class, elem)?;
                let y = self.num(c, class, elem)?;
                self.b.emit(Op::True, elem);
                let op = match (x, y) {
                    (V::I(x), V::I(y)) => Op::CmpI(cmp, x, y),
                    (V::F(x), V::F(y)) => Op::CmpF(cmp, x, y),
                    (V::L(x), V::L(y)) => Op::CmpL(cmp, x, y),
                    (V::D(x), V::D(y)) => Op::CmpD(cmp, x, y),
                    _ => return None,
                };
                self.b.emit(op, elem);
            }
            _ => return None,
        }
        Some(())
    }

    fn is_bool(&self, e: &Expr) -> bool {
        match e {
            Expr::Lit(Literal::Bool(_), _) | Expr::Not(..) => true,
            Expr::Name(n, _) if bool_word(n).is_some() => true,
            Expr::Name(n, _) => {
                matches!(self.b.layout().resolve(n), Ok(Target::Value { place, .. }) if place.data_type() == DataType::Bool)
            }
            Expr::Bin(op, a, _, _) => match op {
                BinE::And | BinE::Or | BinE::Xor => true,
                BinE::Eq | BinE::Ne => self.is_bool(a),
                BinE::Lt | BinE::Gt | BinE::Le | BinE::Ge => true,
                _ => false,
            },
            _ => false,
        }
    }

    /// The class a numeric expression computes in.
    fn class(&self, e: &Expr) -> Class {
        match e {
            Expr::Lit(l, _) => class_of_lit(*l),
            Expr::Const(_) => Class::F,
            Expr::Name(n, _) => match self.b.layout().resolve(n) {
                Ok(Target::Value { place, .. }) => class_of_type(place.data_type()),
                _ => Class::I,
            },
            Expr::Neg(a) => self.class(a),
            Expr::Bin(BinE::Pow, a, c, _) => float_class(promote([self.class(a), self.class(c)])),
            Expr::Bin(_, a, c, _) => promote([self.class(a), self.class(c)]),
            Expr::Call(f, args, _) => {
                let c = promote(args.iter().map(|a| self.class(a)));
                if f.is_float() { float_class(c) } else { c }
            }
            _ => Class::I,
        }
    }

    /// Emits the numeric expression `e` in class `c` (with `rc` true).
    fn num(&mut self, e: &Expr, c: Class, elem: u32) -> Option<V> {
        Some(match e {
            Expr::Lit(l, _) => self.b.constant(*l, c),
            Expr::Const(k) => self.b.constant(Literal::Real(*k), c),
            Expr::Name(n, sp) => {
                let p = self.place(n, *sp)?;
                let v = self.b.load(p, elem);
                self.b.convert(v, c, elem)
            }
            Expr::Neg(a) => {
                let a = self.num(a, c, elem)?;
                let t = self.b.temp(c);
                self.b.un(UnOp::Neg, a, t, elem);
                t
            }
            Expr::Bin(op, a, d, _) => {
                let op = match op {
                    BinE::Add => BinOp::Add,
                    BinE::Sub => BinOp::Sub,
                    BinE::Mul => BinOp::Mul,
                    BinE::Div => BinOp::Div,
                    BinE::Mod => BinOp::Mod,
                    BinE::Pow => BinOp::Pow,
                    _ => return None,
                };
                let x = self.num(a, c, elem)?;
                let y = self.num(d, c, elem)?;
                let t = self.b.temp(c);
                self.b.bin(op, x, y, t, elem);
                t
            }
            Expr::Call(f, args, _) => {
                // In the function's own class (a float function of integers
                // computes in REAL), then in the expression's.
                let inner = promote([self.class(e), c]);
                let mut vals = Vec::with_capacity(args.len());
                for a in args {
                    vals.push(self.num(a, inner, elem)?);
                }
                let v = alba_ladder::funcs::call(self.b, *f, &vals, inner, elem);
                self.b.convert(v, c, elem)
            }
            _ => return None,
        })
    }
}
