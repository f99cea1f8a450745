//! Checks a ladder program against the tag table and lowers it to the IR.
//!
//! Checking and lowering are one walk: each instruction's operands are
//! resolved and checked against what the instruction expects (count, type,
//! writability), then its ops are emitted. Every problem is reported; the
//! emitted ops are only used when there is none.
//!
//! Numeric instructions compute in one *class* (DINT, LINT, REAL or LREAL)
//! chosen from all their operands, destination included (SPEC §3.2: mixed
//! INT/REAL arithmetic is done in REAL and converted to the destination).

use crate::ast::{Arg, Element, Instr, Mnemonic, Operand, Program, Rung};
use crate::expr::{self, BinE, Expr, Func};
use alba_diag::{Code, Diagnostic, Span};
use alba_ir::values::{Class, Src, V, class_name, class_of, class_of_lit, class_of_type, float_class, promote};
use alba_ir::{Access, B, BinOp, Builder, Cmp, Ctr, I, Layout, Op, Place, ResolveError, Target, TimeBase, Tmr, UnOp};
use alba_model::slc::{self, Slc, SlcStruct};
use alba_model::tags::is_identifier;
use alba_model::{Address, DataType, Literal, Value};
use std::collections::HashMap;

/// Literal presets and accumulators given so far, per slot (key `(0,
/// slot)`), and the time base of each timer (key `(1, its first integer
/// slot)`, the base's code), across all the programs of a project (two
/// instructions on one timer must agree).
#[derive(Debug, Default)]
pub struct Presets(HashMap<(u8, u32), (i64, Span)>);

/// Compiles one ladder program, parsed from `src`, into `b` as a unit named
/// `name`. (`src` gives CPT expressions their exact positions: operands in
/// the tree have their whitespace collapsed.)
pub fn compile(prog: &Program, src: &str, name: &str, b: &mut Builder, presets: &mut Presets) -> Vec<Diagnostic> {
    compile_in(prog, src, name, b, presets, Dialect::Logix)
}

/// Whose semantics the program follows where Logix and AuroraLD disagree
/// (`[ladder] dialect` of alba.toml; docs/ladder.md "Dialects").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dialect {
    /// Rockwell Logix: `LIM` includes both bounds, `SQRT`/`sqrt` of a
    /// negative is the root of its absolute value.
    #[default]
    Logix,
    /// AuroraLD Studio (`000_…` §3.4.3.1, Table 8): `LIM` is low ≤ test <
    /// high, `sqrt` of a negative is 0.
    AuroraLd,
}

/// [`compile`] in a dialect.
pub fn compile_in(
    prog: &Program,
    src: &str,
    name: &str,
    b: &mut Builder,
    presets: &mut Presets,
    dialect: Dialect,
) -> Vec<Diagnostic> {
    let mut c = Compiler {
        b,
        src,
        presets,
        dialect,
        diags: Vec::new(),
        labels: HashMap::new(),
        jumps: Vec::new(),
    };
    c.b.begin_unit(name);
    c.collect_labels(prog);
    let mut rung_ops = Vec::with_capacity(prog.rungs.len());
    for (n, rung) in prog.rungs.iter().enumerate() {
        check_structure(rung, &mut c.diags);
        rung_ops.push(c.b.here());
        c.b.begin_rung(n as u32, rung.span);
        c.elements(&rung.elements);
    }
    for (at, label, span) in std::mem::take(&mut c.jumps) {
        match c.labels.get(&label.to_ascii_uppercase()) {
            Some(&(rung, _)) => c.b.patch_jump(at, rung_ops[rung]),
            None if prog.broken_labels.iter().any(|l| l.eq_ignore_ascii_case(&label)) => {}
            None => {
                let mut d = Diagnostic::new(
                    Code::MissingLabel,
                    format!("no rung has LBL({label})"),
                    span,
                    "unknown label",
                );
                let mut all: Vec<&str> = c.labels.values().map(|(_, (n, _))| n.as_str()).collect();
                if !all.is_empty() {
                    all.sort_unstable();
                    d = d.with_help(format!("the labels of this program are: {}", all.join(", ")));
                }
                c.diags.push(d);
            }
        }
    }
    c.b.end_unit();
    c.diags
}

/// Every name a program's operands and CPT expressions give, as written.
fn each_name(prog: &Program, f: &mut impl FnMut(&str)) {
    fn walk(elems: &[Element], f: &mut impl FnMut(&str)) {
        for e in elems {
            match e {
                Element::Branch(b) => b.legs.iter().for_each(|l| walk(l, f)),
                Element::Instr(i) => {
                    for (k, o) in i.operands.iter().enumerate() {
                        if i.mnemonic.args().get(k) == Some(&Arg::Expr) {
                            if let Ok(e) = expr::parse(&o.text, o.span.file, o.span.start as usize) {
                                names(&e, f);
                            }
                        } else {
                            f(&o.text);
                        }
                    }
                }
            }
        }
    }
    fn names(e: &Expr, f: &mut impl FnMut(&str)) {
        match e {
            Expr::Name(n, _) => f(n),
            Expr::Neg(a) | Expr::Not(a, _) => names(a, f),
            Expr::Bin(_, a, b, _) => {
                names(a, f);
                names(b, f);
            }
            Expr::Call(_, args, _) => args.iter().for_each(|a| names(a, f)),
            Expr::Lit(..) | Expr::Const(_) => {}
        }
    }
    for r in &prog.rungs {
        walk(&r.elements, f);
    }
}

/// Addresses a program names directly (the layout sizes the I/O images to them).
pub fn addresses(prog: &Program) -> Vec<Address> {
    let mut out = Vec::new();
    each_name(prog, &mut |n| {
        if let Ok(Some(a)) = Address::parse(n) {
            out.push(a);
        }
    });
    out
}

/// The SLC 500 timers and counters a program names (`T4:0`, `C5:1.DN`,
/// also in CPT expressions): the layout makes their structures.
pub fn slc_structs(prog: &Program) -> std::collections::BTreeSet<SlcStruct> {
    let mut out = std::collections::BTreeSet::new();
    each_name(prog, &mut |n| {
        if let Ok(Some(Slc::Struct(st, _))) = slc::parse(&n.to_ascii_uppercase(), n) {
            out.insert(st);
        }
    });
    out
}

/// A rung needs an output instruction, and must end with one (as in Logix):
/// the last element, or the last element of every leg of a final branch.
fn check_structure(rung: &Rung, diags: &mut Vec<Diagnostic>) {
    fn has_output(elems: &[Element]) -> bool {
        elems.iter().any(|e| match e {
            Element::Instr(i) => i.mnemonic.is_output(),
            Element::Branch(b) => b.legs.iter().any(|l| has_output(l)),
        })
    }
    /// The first trailing input instruction, if the sequence does not end with an output.
    fn trailing_input(elems: &[Element]) -> Option<&Instr> {
        match elems.last()? {
            Element::Instr(i) if i.mnemonic.is_output() => None,
            Element::Instr(i) => Some(i),
            Element::Branch(b) => b.legs.iter().find_map(|l| trailing_input(l)),
        }
    }
    if !has_output(&rung.elements) {
        let span = rung.elements.first().map_or(rung.span, |e| e.span());
        diags.push(
            Diagnostic::new(
                Code::NoOutput,
                "this rung has no output instruction",
                span,
                "rung without output",
            )
            .with_help(
                "end the rung with an output such as OTE(tag), OTL(tag), TON(timer,ms,0), MOV(src,dest) or NOP()",
            ),
        );
    } else if let Some(i) = trailing_input(&rung.elements) {
        diags.push(
            Diagnostic::new(
                Code::NoOutput,
                format!("the rung ends with the input instruction {}", i.mnemonic.name()),
                i.span,
                "input at the end",
            )
            .with_help("a rung (and each leg of a final branch) ends with an output instruction"),
        );
    }
}

/// A resolved operand.
#[derive(Debug, Clone, Copy)]
enum Opnd {
    Lit(Literal),
    Place(Place, Access),
    Timer(Tmr),
    Counter(Ctr),
    Pid(alba_ir::Pidt),
    /// `?`: no initial value given.
    Unset,
}

/// The value of a literal or place operand.
fn src(o: Opnd) -> Src {
    match o {
        Opnd::Lit(l) => Src::Lit(l),
        Opnd::Place(p, _) => Src::Place(p),
        // Not a value; `check` refuses these where a value is needed.
        Opnd::Timer(_) | Opnd::Counter(_) | Opnd::Pid(_) | Opnd::Unset => Src::Lit(Literal::Int(0)),
    }
}

/// The place of a place operand (`check` has made sure it is one).
fn place(o: Opnd) -> Place {
    match o {
        Opnd::Place(p, _) => p,
        _ => Place::Bool(B(0)),
    }
}

struct Compiler<'a> {
    b: &'a mut Builder,
    src: &'a str,
    presets: &'a mut Presets,
    dialect: Dialect,
    diags: Vec<Diagnostic>,
    /// Label (upper case) → (rung index, (name as written, span)).
    labels: HashMap<String, (usize, (String, Span))>,
    /// JMPs to patch: op index, label, span.
    jumps: Vec<(u32, String, Span)>,
}

impl Compiler<'_> {
    fn err(&mut self, code: Code, msg: impl Into<String>, span: Span, label: impl Into<String>) {
        self.diags.push(Diagnostic::new(code, msg, span, label));
    }

    fn collect_labels(&mut self, prog: &Program) {
        fn lbls<'p>(elems: &'p [Element], out: &mut Vec<&'p Instr>) {
            for e in elems {
                match e {
                    Element::Instr(i) if i.mnemonic == Mnemonic::LBL => out.push(i),
                    Element::Instr(_) => {}
                    Element::Branch(b) => b.legs.iter().for_each(|l| lbls(l, out)),
                }
            }
        }
        for (n, rung) in prog.rungs.iter().enumerate() {
            let mut found = Vec::new();
            lbls(&rung.elements, &mut found);
            for i in found {
                let first = matches!(rung.elements.first(), Some(Element::Instr(f)) if std::ptr::eq(f, i));
                if !first {
                    self.err(
                        Code::LabelNotFirst,
                        "LBL must be the first instruction of its rung",
                        i.span,
                        "label not at the rung start",
                    );
                }
                let Some(op) = i.operands.first() else {
                    continue;
                };
                if !is_identifier(&op.text) {
                    continue; // reported when the instruction is checked
                }
                let key = op.text.to_ascii_uppercase();
                if let Some((_, (_, prev))) = self.labels.get(&key) {
                    let prev = *prev;
                    self.diags.push(
                        Diagnostic::new(
                            Code::DuplicateLabel,
                            format!("label `{}` is set twice", op.text),
                            op.span,
                            "second LBL",
                        )
                        .with_note(prev, "first set here"),
                    );
                    continue;
                }
                self.labels.insert(key, (n, (op.text.clone(), op.span)));
            }
        }
    }

    fn elements(&mut self, elems: &[Element]) {
        for e in elems {
            match e {
                Element::Instr(i) => {
                    let elem = self.b.element(i.span);
                    let mark = self.b.mark();
                    self.instr(i, elem);
                    self.b.release(mark);
                }
                Element::Branch(br) => {
                    let elem = self.b.element(br.span);
                    let mark = self.b.mark();
                    let save = self.b.temp_b();
                    let acc = self.b.temp_b();
                    self.b.emit(Op::BrOpen { save, acc }, alba_ir::NO_ELEM);
                    for (k, leg) in br.legs.iter().enumerate() {
                        if k > 0 {
                            self.b.emit(Op::BrNext { save, acc }, alba_ir::NO_ELEM);
                        }
                        self.elements(leg);
                    }
                    self.b.emit(Op::BrClose { acc }, elem);
                    self.b.release(mark);
                }
            }
        }
    }

    /// Resolves an operand's text to a literal, `?` or a place.
    fn resolve(&mut self, o: &Operand) -> Option<Opnd> {
        let t = o.text.as_str();
        if t == "?" {
            return Some(Opnd::Unset);
        }
        let upper = t.to_ascii_uppercase();
        let looks_literal = t.starts_with(|c: char| c.is_ascii_digit() || matches!(c, '+' | '-' | '.'))
            || upper == "TRUE"
            || upper == "FALSE"
            || upper.starts_with("T#")
            || upper.starts_with("TIME#");
        if looks_literal {
            return match Literal::parse(t) {
                Ok(l) => Some(Opnd::Lit(l)),
                Err(m) => {
                    self.err(Code::BadLiteral, m, o.span, "bad literal");
                    None
                }
            };
        }
        match self.b.layout().resolve(t) {
            Ok(Target::Value { place, access }) => Some(Opnd::Place(place, access)),
            Ok(Target::Timer(tm)) => Some(Opnd::Timer(tm)),
            Ok(Target::Counter(c)) => Some(Opnd::Counter(c)),
            Ok(Target::Pid(p)) => Some(Opnd::Pid(p)),
            Err(e) => {
                let code = match &e {
                    ResolveError::UnknownTag(_) => Code::UnknownTag,
                    ResolveError::UnknownMember { .. } => Code::UnknownMember,
                    ResolveError::NotAStructure { .. } => Code::OperandType,
                    ResolveError::BadAddress(_) | ResolveError::OutsideImage(_) => Code::BadAddress,
                };
                let mut d = Diagnostic::new(code, e.to_string(), o.span, "here");
                if let ResolveError::UnknownTag(n) = &e {
                    d = match self.b.layout().tags.suggest(n) {
                        Some(s) => d.with_help(format!("did you mean `{s}`?")),
                        None => d.with_help("declare it in tags.csv"),
                    };
                }
                self.diags.push(d);
                None
            }
        }
    }

    fn describe(&self, o: &Opnd) -> String {
        match o {
            Opnd::Lit(Literal::Bool(_)) => "a boolean literal".into(),
            Opnd::Lit(Literal::Real(_)) => "a REAL literal".into(),
            Opnd::Lit(_) => "an integer literal".into(),
            Opnd::Place(p, _) => format!("a {}", p.data_type()),
            Opnd::Timer(_) => "a TIMER".into(),
            Opnd::Counter(_) => "a COUNTER".into(),
            Opnd::Pid(_) => "a PID".into(),
            Opnd::Unset => "`?`".into(),
        }
    }

    fn wrong(&mut self, i: &Instr, o: &Operand, r: &Opnd, expected: &str) {
        let found = self.describe(r);
        self.err(
            Code::OperandType,
            format!(
                "{} expects {expected} here, found {found} `{}`",
                i.mnemonic.name(),
                o.text
            ),
            o.span,
            format!("expected {expected}"),
        );
    }

    fn not_writable(&mut self, o: &Operand, access: Access) {
        self.err(
            Code::NotWritable,
            format!("`{}` cannot be written: {}", o.text, access.why_not_writable()),
            o.span,
            "not writable",
        );
    }

    /// Checks one operand against what its position expects.
    fn check(&mut self, i: &Instr, o: &Operand, arg: Arg) -> Option<Opnd> {
        if arg == Arg::Label {
            if !is_identifier(&o.text) {
                self.err(
                    Code::Syntax,
                    format!("`{}` is not a label name", o.text),
                    o.span,
                    "expected a name",
                );
                return None;
            }
            return Some(Opnd::Unset);
        }
        if arg == Arg::Expr {
            return Some(Opnd::Unset);
        }
        let r = self.resolve(o)?;
        let is_bool = |p: &Place| p.data_type() == DataType::Bool;
        let ok = match (arg, &r) {
            (Arg::BitIn, Opnd::Place(p, _)) => is_bool(p),
            (Arg::BitOut, Opnd::Place(p, a)) if is_bool(p) => {
                if *a != Access::ReadWrite {
                    self.not_writable(o, *a);
                    return None;
                }
                true
            }
            (Arg::Timer, Opnd::Timer(_)) | (Arg::Counter, Opnd::Counter(_)) => true,
            (Arg::TimerOrCounter, Opnd::Timer(_) | Opnd::Counter(_)) => true,
            (Arg::Preset, Opnd::Unset) | (Arg::Accum, Opnd::Unset) => true,
            (Arg::Preset | Arg::Accum, Opnd::Lit(Literal::Int(v) | Literal::Time(v))) => {
                if i32::try_from(*v).is_err() {
                    self.err(
                        Code::BadLiteral,
                        format!("{v} does not fit a DINT"),
                        o.span,
                        "out of range",
                    );
                    return None;
                }
                if *v < 0 && matches!(i.mnemonic.group(), crate::ast::Group::Timer) {
                    self.err(
                        Code::BadLiteral,
                        "a timer preset or accumulator cannot be negative",
                        o.span,
                        "negative time",
                    );
                    return None;
                }
                true
            }
            (Arg::Preset, Opnd::Place(p, _)) => class_of_type(p.data_type()) == Class::I && !is_bool(p),
            (Arg::NumIn, Opnd::Lit(Literal::Bool(_))) => false,
            (Arg::NumIn, Opnd::Lit(_)) => true,
            (Arg::NumIn, Opnd::Place(p, _)) => p.data_type().is_numeric(),
            (Arg::NumOut | Arg::BitOut, Opnd::Lit(_)) => {
                self.err(
                    Code::NotWritable,
                    format!("`{}` is a literal and cannot be written", o.text),
                    o.span,
                    "expected a tag to write",
                );
                return None;
            }
            (Arg::NumOut, Opnd::Place(p, a)) if p.data_type().is_numeric() => {
                if *a != Access::ReadWrite {
                    self.not_writable(o, *a);
                    return None;
                }
                true
            }
            (Arg::Pid, Opnd::Pid(_)) => true,
            _ => false,
        };
        if !ok {
            let expected = match arg {
                Arg::BitIn => "a BOOL",
                Arg::BitOut => "a BOOL tag to write",
                Arg::Timer => "a TIMER tag",
                Arg::Counter => "a COUNTER tag",
                Arg::TimerOrCounter => "a TIMER or COUNTER tag",
                Arg::Preset => "an integer preset (literal, `?` or integer tag)",
                Arg::Accum => "an integer literal or `?`",
                Arg::NumIn => "a number (tag or literal)",
                Arg::NumOut => "a numeric tag to write",
                Arg::Pid => "a PID tag",
                Arg::Label | Arg::Expr => "something else",
            };
            self.wrong(i, o, &r, expected);
            return None;
        }
        Some(r)
    }

    /// The time base of a TON, TOF or RTO: its optional fourth operand
    /// (`TON(T,5,0,s)`; ms when absent), the same for every instruction on
    /// one timer. `None` after a diagnostic.
    fn time_base(&mut self, i: &Instr, t: Tmr) -> Option<TimeBase> {
        let Some(o) = i.operands.get(3) else {
            return self.same_base(t, TimeBase::Ms, i.name_span, "");
        };
        let Some(base) = TimeBase::parse(&o.text) else {
            self.err(
                Code::BadLiteral,
                format!(
                    "`{}` is not a time base; write ms, cs, ds, s or min (or 0.001, 0.01, 0.1, 1.0, 60 seconds)",
                    o.text
                ),
                o.span,
                "not a time base",
            );
            return None;
        };
        self.same_base(t, base, o.span, &o.text)
    }

    /// A timer's literal duration (`T#5s`) in units of its time base: whole
    /// units only (`T#1500ms` in s is `E310`). Other operands as they are.
    fn in_base(&mut self, o: &Operand, r: Opnd, base: TimeBase) -> Option<Opnd> {
        let Opnd::Lit(Literal::Time(ms)) = r else {
            return Some(r);
        };
        let unit = i64::from(base.ms());
        if ms % unit != 0 {
            self.err(
                Code::BadLiteral,
                format!(
                    "`{}` is not a whole number of {} (the timer's time base)",
                    o.text,
                    base.name()
                ),
                o.span,
                format!("{} {} and a part", ms / unit, base.name()),
            );
            return None;
        }
        Some(Opnd::Lit(Literal::Time(ms / unit)))
    }

    /// Records the time base of timer `t`, refusing a second, different one.
    fn same_base(&mut self, t: Tmr, base: TimeBase, span: Span, text: &str) -> Option<TimeBase> {
        match self.presets.0.get(&(1, t.i.0)) {
            Some(&(prev, first)) if prev != i64::from(base.code()) => {
                let prev = TimeBase::from_code(prev as u8).unwrap_or_default();
                let given = if text.is_empty() {
                    "no time base (ms)".to_string()
                } else {
                    format!("the time base `{text}`")
                };
                self.diags.push(
                    Diagnostic::new(
                        Code::ConflictingPreset,
                        format!(
                            "{given} conflicts with the time base {} given earlier for the same timer",
                            prev.name()
                        ),
                        span,
                        "different time base",
                    )
                    .with_note(first, "first given here")
                    .with_help("give every TON, TOF and RTO on one timer the same time base"),
                );
                None
            }
            Some(_) => Some(base),
            None => {
                self.presets.0.insert((1, t.i.0), (i64::from(base.code()), span));
                Some(base)
            }
        }
    }

    fn instr(&mut self, i: &Instr, elem: u32) {
        let m = i.mnemonic;
        let args = m.args();
        let based = m.optional().contains(&crate::ast::Optional::TimeBase);
        let most = args.len() + m.optional().len();
        if !(args.len()..=most).contains(&i.operands.len()) {
            if based {
                self.err(
                    Code::OperandCount,
                    format!(
                        "{} takes 3 operands, or 4 with a time base, found {}",
                        m.name(),
                        i.operands.len()
                    ),
                    i.span,
                    format!(
                        "expected {}(Timer,Preset,Accum) or {0}(Timer,Preset,Accum,TimeBase)",
                        m.name()
                    ),
                );
                return;
            }
            let names: Vec<&str> = args.iter().map(|a| arg_name(*a)).collect();
            self.err(
                Code::OperandCount,
                format!(
                    "{} takes {} operand{}, found {}",
                    m.name(),
                    args.len(),
                    if args.len() == 1 { "" } else { "s" },
                    i.operands.len()
                ),
                i.span,
                format!("expected {}({})", m.name(), names.join(",")),
            );
            return;
        }
        let mut ops = Vec::with_capacity(args.len());
        let mut failed = false;
        for (o, a) in i.operands.iter().zip(args) {
            match self.check(i, o, *a) {
                Some(r) => ops.push(r),
                None => failed = true,
            }
        }
        if failed || !self.literals_fit(i, &ops) {
            return;
        }
        use Mnemonic as M;
        match m {
            M::XIC | M::XIO => {
                let b = self.b.bool_in(place(ops[0]), elem);
                self.b.emit(if m == M::XIC { Op::Xic(b) } else { Op::Xio(b) }, elem);
            }
            M::OTE | M::OTL | M::OTU | M::ONS => {
                let (b, post) = self.b.bool_out(place(ops[0]), elem);
                let op = match m {
                    M::OTE => Op::Ote(b),
                    M::OTL => Op::Otl(b),
                    M::OTU => Op::Otu(b),
                    _ => Op::Ons(b),
                };
                self.b.emit(op, elem);
                self.b.post(post, elem);
            }
            M::OSR | M::OSF => {
                let (s, p1) = self.b.bool_out(place(ops[0]), elem);
                let (o, p2) = self.b.bool_out(place(ops[1]), elem);
                self.b
                    .emit(if m == M::OSR { Op::Osr(s, o) } else { Op::Osf(s, o) }, elem);
                self.b.post(p1, elem);
                self.b.post(p2, elem);
            }
            M::TON | M::TOF | M::RTO | M::TP => {
                let Opnd::Timer(t) = ops[0] else { return };
                // TP counts milliseconds: its timer has no other base.
                let base = if m == M::TP {
                    self.same_base(t, TimeBase::Ms, i.name_span, "")
                } else {
                    self.time_base(i, t)
                };
                let Some(base) = base else { return };
                let (Some(pre), Some(acc)) = (
                    self.in_base(&i.operands[1], ops[1], base),
                    self.in_base(&i.operands[2], ops[2], base),
                ) else {
                    return;
                };
                self.preset(t.i, &i.operands[1], pre, elem);
                self.accum(I(t.i.0 + 1), &i.operands[2], acc);
                let op = match m {
                    M::TON => Op::Ton(t, base),
                    M::TOF => Op::Tof(t, base),
                    M::RTO => Op::Rto(t, base),
                    _ => Op::Tp(t),
                };
                self.b.emit(op, elem);
            }
            M::CTU | M::CTD => {
                let Opnd::Counter(c) = ops[0] else { return };
                self.preset(c.i, &i.operands[1], ops[1], elem);
                self.accum(I(c.i.0 + 1), &i.operands[2], ops[2]);
                self.b.emit(if m == M::CTU { Op::Ctu(c) } else { Op::Ctd(c) }, elem);
            }
            M::RES => match ops[0] {
                Opnd::Timer(t) => {
                    self.b.emit(Op::ResT(t), elem);
                }
                Opnd::Counter(c) => {
                    self.b.emit(Op::ResC(c), elem);
                }
                _ => {}
            },
            M::EQU | M::NEQ | M::LES | M::GRT | M::LEQ | M::GEQ => {
                let cmp = match m {
                    M::EQU => Cmp::Eq,
                    M::NEQ => Cmp::Ne,
                    M::LES => Cmp::Lt,
                    M::GRT => Cmp::Gt,
                    M::LEQ => Cmp::Le,
                    _ => Cmp::Ge,
                };
                let c = self.class(&ops);
                let a = self.b.read(src(ops[0]), c, elem);
                let b = self.b.read(src(ops[1]), c, elem);
                let op = match (a, b) {
                    (V::I(a), V::I(b)) => Op::CmpI(cmp, a, b),
                    (V::F(a), V::F(b)) => Op::CmpF(cmp, a, b),
                    (V::L(a), V::L(b)) => Op::CmpL(cmp, a, b),
                    (V::D(a), V::D(b)) => Op::CmpD(cmp, a, b),
                    _ => return,
                };
                self.b.emit(op, elem);
            }
            M::LIM => {
                let c = self.class(&ops);
                let v: Vec<V> = ops.iter().map(|o| self.b.read(src(*o), c, elem)).collect();
                if self.dialect == Dialect::AuroraLd {
                    // low <= test < high: two compares in series.
                    for (cmp, x, y) in [(Cmp::Ge, v[1], v[0]), (Cmp::Lt, v[1], v[2])] {
                        let op = match (x, y) {
                            (V::I(a), V::I(b)) => Op::CmpI(cmp, a, b),
                            (V::F(a), V::F(b)) => Op::CmpF(cmp, a, b),
                            (V::L(a), V::L(b)) => Op::CmpL(cmp, a, b),
                            (V::D(a), V::D(b)) => Op::CmpD(cmp, a, b),
                            _ => return,
                        };
                        self.b.emit(op, elem);
                    }
                    return;
                }
                let op = match (v[0], v[1], v[2]) {
                    (V::I(a), V::I(b), V::I(d)) => Op::LimI(a, b, d),
                    (V::F(a), V::F(b), V::F(d)) => Op::LimF(a, b, d),
                    (V::L(a), V::L(b), V::L(d)) => Op::LimL(a, b, d),
                    (V::D(a), V::D(b), V::D(d)) => Op::LimD(a, b, d),
                    _ => return,
                };
                self.b.emit(op, elem);
            }
            M::MEQ => {
                let c = self.class(&ops);
                if !self.integer_only(i, &ops, c) {
                    return;
                }
                let v: Vec<V> = ops.iter().map(|o| self.b.read(src(*o), c, elem)).collect();
                let op = match (v[0], v[1], v[2]) {
                    (V::I(a), V::I(b), V::I(d)) => Op::MeqI(a, b, d),
                    (V::L(a), V::L(b), V::L(d)) => Op::MeqL(a, b, d),
                    _ => return,
                };
                self.b.emit(op, elem);
            }
            M::ADD | M::SUB | M::MUL | M::DIV | M::MOD | M::XPY | M::AND | M::OR | M::XOR => {
                let op = match m {
                    M::ADD => BinOp::Add,
                    M::SUB => BinOp::Sub,
                    M::MUL => BinOp::Mul,
                    M::DIV => BinOp::Div,
                    M::MOD => BinOp::Mod,
                    M::XPY => BinOp::Pow,
                    M::AND => BinOp::And,
                    M::OR => BinOp::Or,
                    _ => BinOp::Xor,
                };
                let mut c = self.class(&ops);
                if m == M::XPY {
                    c = float_class(c);
                }
                if matches!(m, M::AND | M::OR | M::XOR) && !self.integer_only(i, &ops, c) {
                    return;
                }
                let a = self.b.read(src(ops[0]), c, elem);
                let b = self.b.read(src(ops[1]), c, elem);
                let Opnd::Place(dest, _) = ops[2] else { return };
                let (d, post) = self.b.dest(dest, c, elem);
                self.b.bin(op, a, b, d, elem);
                self.b.post(post, elem);
            }
            M::SQR | M::LN | M::LOG | M::SIN | M::COS | M::TAN | M::ASN | M::ACS | M::ATN | M::DEG | M::RAD => {
                let op = match m {
                    M::SQR => UnOp::Sqrt,
                    M::LN => UnOp::Ln,
                    M::LOG => UnOp::Log,
                    M::SIN => UnOp::Sin,
                    M::COS => UnOp::Cos,
                    M::TAN => UnOp::Tan,
                    M::ASN => UnOp::Asin,
                    M::ACS => UnOp::Acos,
                    M::ATN => UnOp::Atan,
                    M::DEG => UnOp::Deg,
                    _ => UnOp::Rad,
                };
                let c = float_class(self.class(&ops));
                if m == M::SQR && self.dialect == Dialect::AuroraLd {
                    // AuroraLD's SQR of a negative is 0, as its CPT's sqrt.
                    let Opnd::Place(dest, _) = ops[1] else { return };
                    let a = self.b.read(src(ops[0]), c, elem);
                    let v = crate::funcs::call(self.b, Func::SqrtZero, &[a], c, elem);
                    let (d, post) = self.b.dest(dest, c, elem);
                    self.b.un(UnOp::Mov, v, d, elem);
                    self.b.post(post, elem);
                    return;
                }
                self.unary(op, &ops, c, elem);
            }
            M::NEG | M::ABS | M::MOV | M::NOT => {
                let op = match m {
                    M::NEG => UnOp::Neg,
                    M::ABS => UnOp::Abs,
                    M::MOV => UnOp::Mov,
                    _ => UnOp::Not,
                };
                let c = self.class(&ops);
                if m == M::NOT && !self.integer_only(i, &ops, c) {
                    return;
                }
                self.unary(op, &ops, c, elem);
            }
            M::CLR => {
                let zero = [Opnd::Lit(Literal::Int(0)), ops[0]];
                let c = self.class(&zero);
                self.unary(UnOp::Mov, &zero, c, elem);
            }
            M::SCP => {
                let c = float_class(self.class(&ops));
                let v: Vec<V> = ops[..5].iter().map(|o| self.b.read(src(*o), c, elem)).collect();
                let (input, in_min, in_max, sc_min, sc_max) = (v[0], v[1], v[2], v[3], v[4]);
                let span_out = self.b.temp(c);
                self.b.bin(BinOp::Sub, sc_max, sc_min, span_out, elem);
                let span_in = self.b.temp(c);
                self.b.bin(BinOp::Sub, in_max, in_min, span_in, elem);
                let slope = self.b.temp(c);
                self.b.bin(BinOp::Div, span_out, span_in, slope, elem);
                let offset = self.b.temp(c);
                self.b.bin(BinOp::Sub, input, in_min, offset, elem);
                let scaled = self.b.temp(c);
                self.b.bin(BinOp::Mul, offset, slope, scaled, elem);
                let Opnd::Place(dest, _) = ops[5] else { return };
                let (d, post) = self.b.dest(dest, c, elem);
                self.b.bin(BinOp::Add, scaled, sc_min, d, elem);
                self.b.post(post, elem);
            }
            M::CPT => self.cpt(i, ops[0], elem),
            M::JMP => {
                let at = self.b.emit(Op::Jmp(0), elem);
                self.jumps.push((at, i.operands[0].text.clone(), i.operands[0].span));
            }
            M::LBL | M::NOP => {
                self.b.emit(Op::Nop, elem);
            }
            M::AFI => {
                self.b.emit(Op::Afi, elem);
            }
            M::PID => {
                use alba_ir::op::{PID_F_IN, PID_F_OUT};
                let Opnd::Pid(p) = ops[0] else { return };
                let pv = self.b.read(src(ops[1]), Class::F, elem);
                let input = alba_ir::F(p.f.0 + PID_F_IN);
                if let V::F(pv) = pv {
                    self.b.emit(Op::UnF(UnOp::Mov, pv, input), elem);
                }
                self.b.emit(Op::Pid(p), elem);
                let Opnd::Place(dest, _) = ops[2] else { return };
                let (d, post) = self.b.dest(dest, Class::F, elem);
                let output = alba_ir::F(p.f.0 + PID_F_OUT);
                // `dest` in class F is a REAL slot (converted back by `post`).
                if let V::F(d) = d {
                    self.b.emit(Op::UnF(UnOp::Mov, output, d), elem);
                }
                self.b.post(post, elem);
            }
        }
    }

    /// Literals must fit the instruction: an integer beyond DINT needs a LINT
    /// or LREAL operand beside it, a real beyond REAL an LREAL one, and the
    /// source of a MOV must fit its destination.
    fn literals_fit(&mut self, i: &Instr, ops: &[Opnd]) -> bool {
        let tags = promote(ops.iter().filter_map(|o| match o {
            Opnd::Place(p, _) => Some(class_of_type(p.data_type())),
            _ => None,
        }));
        let mut ok = true;
        for (o, r) in i.operands.iter().zip(ops) {
            let Opnd::Lit(l) = r else { continue };
            let bad = match *l {
                Literal::Int(v) | Literal::Time(v) => i32::try_from(v).is_err() && !matches!(tags, Class::L | Class::D),
                Literal::Real(v) => v.abs() > f32::MAX as f64 && tags != Class::D,
                Literal::Bool(_) => false,
            };
            if bad {
                let msg = match l {
                    Literal::Real(_) => format!(
                        "`{}` is beyond the REAL range; only an LREAL instruction takes it",
                        o.text
                    ),
                    _ => format!(
                        "`{}` is beyond the DINT range; only a LINT or LREAL instruction takes it",
                        o.text
                    ),
                };
                self.err(Code::BadLiteral, msg, o.span, "too large");
                ok = false;
            }
        }
        if ok
            && i.mnemonic == Mnemonic::MOV
            && let (Opnd::Lit(l), Opnd::Place(p, _)) = (ops[0], ops[1])
            && let Some((lo, hi)) = p.data_type().int_range()
        {
            // Reals are rounded half to even on the way into an integer.
            let v = match l {
                Literal::Int(v) | Literal::Time(v) => v as f64,
                Literal::Real(r) => r.round_ties_even(),
                Literal::Bool(_) => 0.0,
            };
            if v < lo as f64 || v > hi as f64 {
                let (src, dest) = (&i.operands[0], &i.operands[1]);
                self.err(
                    Code::BadLiteral,
                    format!(
                        "`{}` does not fit {} `{}` ({lo} to {hi})",
                        src.text,
                        p.data_type(),
                        dest.text
                    ),
                    src.span,
                    "out of range",
                );
                ok = false;
            }
        }
        ok
    }

    /// In a REAL expression, every real literal must fit a REAL.
    fn reals_fit(&mut self, e: &Expr) -> bool {
        match e {
            Expr::Lit(Literal::Real(v), sp) if v.abs() > f32::MAX as f64 => {
                let text = self.src.get(sp.range()).unwrap_or("").to_string();
                self.err(
                    Code::BadLiteral,
                    format!("`{text}` is beyond the REAL range, and this expression is computed in REAL"),
                    *sp,
                    "too large",
                );
                false
            }
            Expr::Neg(a) | Expr::Not(a, _) => self.reals_fit(a),
            Expr::Bin(_, a, b, _) => {
                let x = self.reals_fit(a);
                self.reals_fit(b) && x
            }
            Expr::Call(_, args, _) => {
                // Every argument, to report every bad literal.
                let mut ok = true;
                for a in args {
                    ok &= self.reals_fit(a);
                }
                ok
            }
            Expr::Lit(..) | Expr::Name(..) | Expr::Const(_) => true,
        }
    }

    /// Refuses a real operand to an integer-only instruction, pointing at it.
    fn integer_only(&mut self, i: &Instr, ops: &[Opnd], c: Class) -> bool {
        if !matches!(c, Class::F | Class::D) {
            return true;
        }
        let k = ops
            .iter()
            .position(|o| matches!(self.class(std::slice::from_ref(o)), Class::F | Class::D));
        let (span, text) = match k.and_then(|k| i.operands.get(k)) {
            Some(o) => (o.span, o.text.as_str()),
            None => (i.span, ""),
        };
        let found = k.map(|k| self.describe(&ops[k])).unwrap_or_default();
        self.err(
            Code::OperandType,
            format!("{} works on integers, but `{text}` is {found}", i.mnemonic.name()),
            span,
            "expected an integer",
        );
        false
    }

    /// The class of an instruction from all its numeric operands.
    fn class(&self, ops: &[Opnd]) -> Class {
        promote(ops.iter().filter_map(|o| match o {
            Opnd::Lit(_) | Opnd::Place(..) => Some(class_of(src(*o))),
            _ => None,
        }))
    }

    /// `dest = op src` with `ops = [src, dest]`.
    fn unary(&mut self, op: UnOp, ops: &[Opnd], c: Class, elem: u32) {
        let Opnd::Place(dest, _) = ops[1] else { return };
        self.b.unary_to(op, src(ops[0]), dest, c, elem);
    }

    fn preset(&mut self, pre: I, o: &Operand, r: Opnd, elem: u32) {
        match r {
            Opnd::Lit(l) => self.initial(pre, o, l),
            Opnd::Place(p, _) => {
                if let V::I(src) = self.b.load(p, elem) {
                    self.b.emit(Op::CopyI(src, pre), elem);
                }
            }
            _ => {}
        }
    }

    fn accum(&mut self, acc: I, o: &Operand, r: Opnd) {
        if let Opnd::Lit(l) = r {
            self.initial(acc, o, l);
        }
    }

    /// Records a literal PRE/ACC as the structure's initial value, refusing
    /// a second, different one.
    fn initial(&mut self, slot: I, o: &Operand, l: Literal) {
        let v = match l {
            Literal::Int(v) | Literal::Time(v) => v,
            _ => return,
        };
        match self.presets.0.get(&(0, slot.0)) {
            Some(&(prev, span)) if prev != v => {
                self.diags.push(
                    Diagnostic::new(
                        Code::ConflictingPreset,
                        format!(
                            "`{}` conflicts with the value {prev} given earlier for the same structure",
                            o.text
                        ),
                        o.span,
                        "different initial value",
                    )
                    .with_note(span, "first given here")
                    .with_help("give the same literal in both places, or `?` in one of them"),
                );
            }
            Some(_) => {}
            None => {
                self.presets.0.insert((0, slot.0), (v, o.span));
                self.b
                    .set_initial(Place::Int(slot, DataType::Dint), Value::Dint(v as i32));
            }
        }
    }

    fn cpt(&mut self, i: &Instr, dest: Opnd, elem: u32) {
        let o = &i.operands[1];
        let raw = self.src.get(o.span.range()).unwrap_or(&o.text);
        let e = match expr::parse(raw, o.span.file, o.span.start as usize) {
            Ok(e) => e,
            Err((msg, span)) => {
                self.err(Code::Expression, msg, span, "in this expression");
                return;
            }
        };
        // Resolve the leaves first: types decide the class.
        let mut leaves = Vec::new();
        let mut float_ops = false;
        if !self.leaves(&e, &mut leaves, &mut float_ops) {
            return;
        }
        let Opnd::Place(dest_place, _) = dest else {
            return;
        };
        let mut classes: Vec<Class> = leaves.iter().map(|(p, _)| class_of_type(p.data_type())).collect();
        classes.push(class_of_type(dest_place.data_type()));
        collect_literal_classes(&e, &mut classes);
        let mut c = promote(classes);
        if float_ops {
            c = float_class(c);
        }
        if c == Class::F && !self.reals_fit(&e) {
            return;
        }
        let mut leaves = leaves.into_iter();
        let Some(v) = self.expr(&e, c, &mut leaves, elem) else {
            return;
        };
        let (d, post) = self.b.dest(dest_place, c, elem);
        self.b.un(UnOp::Mov, v, d, elem);
        self.b.post(post, elem);
    }

    /// Resolves every name of the expression in order; notes float-only operations.
    fn leaves(&mut self, e: &Expr, out: &mut Vec<(Place, Span)>, float_ops: &mut bool) -> bool {
        match e {
            Expr::Lit(Literal::Bool(_), sp) => {
                self.err(
                    Code::Expression,
                    "booleans are not values in CPT; use 1 or 0",
                    *sp,
                    "boolean",
                );
                false
            }
            Expr::Lit(..) => true,
            Expr::Const(_) => {
                *float_ops = true;
                true
            }
            Expr::Name(n, sp) => {
                let o = Operand {
                    text: n.clone(),
                    span: *sp,
                };
                match self.resolve(&o) {
                    Some(Opnd::Place(p, _)) if p.data_type().is_numeric() => {
                        out.push((p, *sp));
                        true
                    }
                    Some(r) => {
                        let found = self.describe(&r);
                        self.err(
                            Code::OperandType,
                            format!("CPT needs numbers, found {found} `{n}`"),
                            *sp,
                            "not a number",
                        );
                        false
                    }
                    None => false,
                }
            }
            Expr::Neg(a) | Expr::Not(a, _) => self.leaves(a, out, float_ops),
            Expr::Bin(op, a, b, _) => {
                if *op == BinE::Pow {
                    *float_ops = true;
                }
                // Evaluate both sides even if the first fails, to report all errors.
                let x = self.leaves(a, out, float_ops);
                let y = self.leaves(b, out, float_ops);
                x && y
            }
            Expr::Call(f, args, _) => {
                if f.is_float() {
                    *float_ops = true;
                }
                let mut ok = true;
                for a in args {
                    ok &= self.leaves(a, out, float_ops);
                }
                ok
            }
        }
    }

    fn expr(&mut self, e: &Expr, c: Class, leaves: &mut impl Iterator<Item = (Place, Span)>, elem: u32) -> Option<V> {
        let int_only = |this: &mut Self, what: &str, sp: Span| -> bool {
            if matches!(c, Class::F | Class::D) {
                this.err(
                    Code::Expression,
                    format!(
                        "{what} works on integers, but this expression is computed in {}",
                        class_name(c)
                    ),
                    sp,
                    "integer operation",
                );
                return false;
            }
            true
        };
        Some(match e {
            Expr::Lit(l, _) => self.b.constant(*l, c),
            Expr::Const(k) => self.b.constant(Literal::Real(*k), c),
            Expr::Name(..) => {
                let (p, _) = leaves.next()?;
                let v = self.b.load(p, elem);
                self.b.convert(v, c, elem)
            }
            Expr::Neg(a) => {
                let a = self.expr(a, c, leaves, elem)?;
                let t = self.b.temp(c);
                self.b.un(UnOp::Neg, a, t, elem);
                t
            }
            Expr::Not(a, sp) => {
                if !int_only(self, "NOT", *sp) {
                    return None;
                }
                let a = self.expr(a, c, leaves, elem)?;
                let t = self.b.temp(c);
                self.b.un(UnOp::Not, a, t, elem);
                t
            }
            Expr::Bin(op, a, b, sp) => {
                let op = match op {
                    BinE::Or => BinOp::Or,
                    BinE::Xor => BinOp::Xor,
                    BinE::And => BinOp::And,
                    BinE::Eq => BinOp::Cmp(Cmp::Eq),
                    BinE::Ne => BinOp::Cmp(Cmp::Ne),
                    BinE::Lt => BinOp::Cmp(Cmp::Lt),
                    BinE::Gt => BinOp::Cmp(Cmp::Gt),
                    BinE::Le => BinOp::Cmp(Cmp::Le),
                    BinE::Ge => BinOp::Cmp(Cmp::Ge),
                    BinE::Add => BinOp::Add,
                    BinE::Sub => BinOp::Sub,
                    BinE::Mul => BinOp::Mul,
                    BinE::Div => BinOp::Div,
                    BinE::Mod => BinOp::Mod,
                    BinE::Pow => BinOp::Pow,
                };
                if matches!(op, BinOp::And | BinOp::Or | BinOp::Xor) {
                    let name = format!("{op:?}").to_ascii_uppercase();
                    if !int_only(self, &name, *sp) {
                        return None;
                    }
                }
                let a = self.expr(a, c, leaves, elem)?;
                let b = self.expr(b, c, leaves, elem)?;
                let t = self.b.temp(c);
                self.b.bin(op, a, b, t, elem);
                t
            }
            Expr::Call(f, args, sp) => {
                if matches!(f, Func::Frd | Func::Tod) {
                    let name = if *f == Func::Frd { "FRD" } else { "TOD" };
                    if !int_only(self, name, *sp) {
                        return None;
                    }
                }
                let mut vals = Vec::with_capacity(args.len());
                for a in args {
                    vals.push(self.expr(a, c, leaves, elem)?);
                }
                let f = match f {
                    Func::Sqrt if self.dialect == Dialect::AuroraLd => Func::SqrtZero,
                    f => *f,
                };
                crate::funcs::call(self.b, f, &vals, c, elem)
            }
        })
    }
}

fn collect_literal_classes(e: &Expr, out: &mut Vec<Class>) {
    match e {
        Expr::Lit(l, _) => out.push(class_of_lit(*l)),
        Expr::Neg(a) | Expr::Not(a, _) => collect_literal_classes(a, out),
        Expr::Bin(_, a, b, _) => {
            collect_literal_classes(a, out);
            collect_literal_classes(b, out);
        }
        Expr::Call(_, args, _) => args.iter().for_each(|a| collect_literal_classes(a, out)),
        Expr::Name(..) | Expr::Const(_) => {}
    }
}

fn arg_name(a: Arg) -> &'static str {
    match a {
        Arg::BitIn | Arg::BitOut => "bit",
        Arg::Timer => "timer",
        Arg::Counter => "counter",
        Arg::TimerOrCounter => "timer_or_counter",
        Arg::Preset => "preset",
        Arg::Accum => "accum",
        Arg::NumIn => "source",
        Arg::NumOut => "dest",
        Arg::Label => "label",
        Arg::Expr => "expression",
        Arg::Pid => "pid",
    }
}

/// The layout used for ladder programs: tags plus the addresses programs name.
pub fn layout_for(tags: &alba_model::TagTable, programs: &[&Program]) -> Layout {
    let used: Vec<Address> = programs.iter().flat_map(|p| addresses(p)).collect();
    Layout::new(
        tags,
        &alba_ir::layout::Uses {
            addresses: used,
            slc: programs.iter().flat_map(|p| slc_structs(p)).collect(),
            ..Default::default()
        },
    )
}
