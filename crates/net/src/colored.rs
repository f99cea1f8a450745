//! Coloured nets: PNML symmetric nets (ISO/IEC 15909-2, `symmetricnet` grammar, the
//! Model Checking Contest's `-COL-` models) unfolded to place/transition nets for the
//! analysis. docs/nets.md, section "Coloured nets".
//!
//! Sorts: `dot`, cyclic and finite enumerations, finite integer ranges and products of
//! them (named by `<namedsort>`, used by `<usersort>`). Terms: variables, constants
//! (`useroperator` naming a constant, `dotconstant`, `finiteintrangeconstant`),
//! `successor`/`predecessor`, `tuple`, `all`, `numberof`, `add`, `subtract`; guards
//! (`<condition>`) with `and`, `or`, `not`, `imply`, `equality`, `inequality`,
//! `lessthan`, `lessthanorequal`, `greaterthan`, `greaterthanorequal`,
//! `booleanconstant`. Each place becomes one place per colour of its sort, each
//! transition one transition per binding of its variables that satisfies its guard.
//! Anything else, or an unfolding over the [`Budget`], is a located error (E602, E605,
//! E606), never a guess.

use crate::model::{Arc, Net, Place, Transition};
use alba_diag::{Code, Diagnostic, FileId, Span};
use alba_xml::{self as xml, Elem};
use std::collections::{BTreeMap, HashMap, HashSet};

/// How large an unfolding may be.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// Most places, transitions and arcs of the unfolded net, together.
    pub elements: u64,
    /// Most variable bindings tried, over all transitions.
    pub bindings: u64,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget {
            elements: 2_000_000,
            bindings: 20_000_000,
        }
    }
}

/// What an unfolding made of a coloured net.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Unfolding {
    pub coloured_places: usize,
    pub coloured_transitions: usize,
    /// Variable bindings tried (those failing the guard included).
    pub bindings: u64,
    /// Per coloured place, in document order: its id and its unfolded places (their
    /// indices in the unfolded net's places, one per colour of its sort).
    pub places: Vec<(String, std::ops::Range<usize>)>,
    /// Per coloured transition, in document order: its id and its unfolded transitions
    /// (their indices in the unfolded net's transitions, one per binding kept).
    pub transitions: Vec<(String, std::ops::Range<usize>)>,
}

/// Whether `text`'s `<net>` is a symmetric (coloured) net: its `type` names the
/// `symmetricnet` grammar. Cheap: reads the first `<net …>` tag only.
pub fn is_symmetric(text: &str) -> bool {
    let mut from = 0;
    while let Some(i) = text[from..].find("<net") {
        let at = from + i + 4;
        if text[at..].starts_with(|c: char| c.is_ascii_whitespace()) {
            let end = text[at..].find('>').map_or(text.len(), |e| at + e);
            return text[at..end].to_ascii_lowercase().contains("symmetricnet");
        }
        from = at;
    }
    false
}

/// Loads a PNML file for the analysis: a symmetric net unfolded within the default
/// [`Budget`] (with what the unfolding made), any other net as [`crate::load`] does.
pub fn load_for_analysis(file: FileId, text: &str) -> (Option<Net>, Vec<Diagnostic>, Option<Unfolding>) {
    if is_symmetric(text) {
        match unfold(file, text, &Budget::default()) {
            Ok((net, u)) => (Some(net), Vec::new(), Some(u)),
            Err(d) => (None, vec![d], None),
        }
    } else {
        let (net, diags) = crate::load(file, text);
        (net, diags, None)
    }
}

/// A colour: one value (index) per component of its sort.
type Colour = Vec<u32>;

#[derive(Clone, Debug, PartialEq)]
enum Kind {
    Dot,
    Enum,
    Range(i64),
}

/// A sort that is not a product.
struct Basic {
    size: u32,
    /// One label per value: a constant's name (else id), an integer, `dot`.
    labels: Vec<String>,
    kind: Kind,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Cmp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

enum T {
    Var(usize),
    Const(Colour),
    /// `successor` (+1) or `predecessor` (-1) of a one-component term, modulo its sort.
    Step(Box<Term>, i64, u32),
    Tuple(Vec<Term>),
    All(Vec<usize>),
    NumberOf(u32, Box<Term>),
    Add(Vec<Term>),
    Sub(Box<Term>, Box<Term>),
    And(Vec<Term>),
    Or(Vec<Term>),
    Not(Box<Term>),
    Imply(Box<Term>, Box<Term>),
    Compare(Cmp, Box<Term>, Box<Term>),
    Bool(bool),
}

struct Term {
    t: T,
    span: Span,
}

struct Var {
    sort: Vec<usize>,
}

struct Unfolder<'a> {
    file: FileId,
    text: &'a str,
    basics: Vec<Basic>,
    /// Named sort id → its components.
    sorts: HashMap<String, Vec<usize>>,
    /// Constant id → (basic sort, value).
    constants: HashMap<String, (usize, u32)>,
    vars: Vec<Var>,
    var_ids: HashMap<String, usize>,
    budget: Budget,
}

type R<T> = Result<T, Diagnostic>;

fn err(code: Code, msg: impl Into<String>, span: Span, label: &str, help: &str) -> Diagnostic {
    Diagnostic::new(code, msg, span, label).with_help(help)
}

const GRAMMAR: &str = "Alba unfolds the symmetric nets of the Model Checking Contest: dot, enumerations, finite integer ranges and their products; variables, constants, successor, predecessor, tuple, all, numberof, add, subtract; guards with and, or, not, imply, equality, inequality and the order comparisons (docs/nets.md, \"Coloured nets\")";

impl Unfolder<'_> {
    fn span(&self, e: &Elem) -> Span {
        let a = e.start.min(self.text.len());
        Span::new(self.file, a..e.start_end.clamp(a, self.text.len()))
    }

    fn unsupported(&self, e: &Elem, what: &str) -> Diagnostic {
        err(
            Code::PnmlStructure,
            format!("<{}> is not a {what} Alba can unfold", e.name),
            self.span(e),
            "not supported",
            GRAMMAR,
        )
    }

    fn attr<'e>(&self, e: &'e Elem, name: &str) -> R<&'e str> {
        e.attr(name).filter(|v| !v.trim().is_empty()).ok_or_else(|| {
            err(
                Code::PnmlStructure,
                format!("<{}> has no `{name}`", e.name),
                self.span(e),
                "attribute missing",
                GRAMMAR,
            )
        })
    }

    /// The one element child of `e` (skipping `<text>` and `<graphics>`), e.g. the
    /// sort of a `<namedsort>`, the term of a `<subterm>` or `<structure>`.
    fn only_child<'e>(&self, e: &'e Elem) -> R<&'e Elem> {
        let mut it = e
            .children
            .iter()
            .filter(|c| !matches!(c.name.as_str(), "text" | "graphics" | "toolspecific"));
        match (it.next(), it.next()) {
            (Some(c), None) => Ok(c),
            _ => Err(err(
                Code::PnmlStructure,
                format!("<{}> holds one sort or term", e.name),
                self.span(e),
                "not one child",
                GRAMMAR,
            )),
        }
    }

    fn number(&self, e: &Elem, name: &str) -> R<i64> {
        let v = self.attr(e, name)?;
        v.trim().parse::<i64>().map_err(|_| {
            err(
                Code::PnmlNumber,
                format!("`{name}` of <{}> is `{v}`, not a whole number", e.name),
                self.span(e),
                "not a number",
                GRAMMAR,
            )
        })
    }

    fn add_basic(&mut self, b: Basic, e: &Elem) -> R<usize> {
        if u64::from(b.size) > self.budget.elements || b.size == 0 {
            return Err(err(
                Code::PnmlLimit,
                format!(
                    "a sort of {} colours: Alba unfolds sorts of 1 to {} colours",
                    b.size, self.budget.elements
                ),
                self.span(e),
                "sort too large",
                "the unfolded net would not fit the budget; analyse a smaller instance",
            ));
        }
        self.basics.push(b);
        Ok(self.basics.len() - 1)
    }

    /// A sort element: its components.
    fn sort(&mut self, e: &Elem) -> R<Vec<usize>> {
        match e.name.as_str() {
            "usersort" => {
                let id = self.attr(e, "declaration")?;
                self.sorts.get(id).cloned().ok_or_else(|| {
                    err(
                        Code::PnmlStructure,
                        format!("the sort `{id}` is not declared"),
                        self.span(e),
                        "unknown sort",
                        "declare it with <namedsort id=\"..\"> in the net's <declaration> before its use",
                    )
                })
            }
            "dot" => Ok(vec![self.dot(e)?]),
            "cyclicenumeration" | "finiteenumeration" => {
                let mut ids = Vec::new();
                let mut labels = Vec::new();
                for c in e.all("feconstant") {
                    let id = self.attr(c, "id")?.to_string();
                    // The constant's name labels the unfolded nodes, as in the contest's
                    // P/T twins (`Think_1`); its id when it has none.
                    labels.push(
                        c.attr("name")
                            .filter(|n| !n.trim().is_empty())
                            .unwrap_or(&id)
                            .to_string(),
                    );
                    ids.push(id);
                }
                let b = self.add_basic(
                    Basic {
                        size: labels.len() as u32,
                        labels,
                        kind: Kind::Enum,
                    },
                    e,
                )?;
                for (i, (l, c)) in ids.iter().zip(e.all("feconstant")).enumerate() {
                    if self.constants.insert(l.clone(), (b, i as u32)).is_some() {
                        return Err(err(
                            Code::PnmlDuplicateId,
                            format!("the constant `{l}` is declared twice"),
                            self.span(c),
                            "second one",
                            "constants' ids are unique in the document",
                        ));
                    }
                }
                Ok(vec![b])
            }
            "finiteintrange" => Ok(vec![self.range(e)?]),
            "productsort" => {
                let mut out = Vec::new();
                for c in &e.children {
                    out.extend(self.sort(c)?);
                }
                if out.is_empty() {
                    return Err(self.unsupported(e, "product of sorts (it is empty)"));
                }
                Ok(out)
            }
            _ => Err(self.unsupported(e, "sort")),
        }
    }

    fn dot(&mut self, e: &Elem) -> R<usize> {
        if let Some(i) = self.basics.iter().position(|b| b.kind == Kind::Dot) {
            return Ok(i);
        }
        self.add_basic(
            Basic {
                size: 1,
                labels: vec!["dot".into()],
                kind: Kind::Dot,
            },
            e,
        )
    }

    /// A `<finiteintrange start end>`: the same range is the same sort.
    fn range(&mut self, e: &Elem) -> R<usize> {
        let (lo, hi) = (self.number(e, "start")?, self.number(e, "end")?);
        if let Some(i) = self
            .basics
            .iter()
            .position(|b| b.kind == Kind::Range(lo) && i64::from(b.size) == hi - lo + 1)
        {
            return Ok(i);
        }
        let size = hi.checked_sub(lo).and_then(|d| d.checked_add(1)).unwrap_or(0);
        if size < 1 || size > i64::from(u32::MAX) {
            return Err(err(
                Code::PnmlNumber,
                format!("the range {lo}..{hi} is empty or too large"),
                self.span(e),
                "bad range",
                "a finite integer range has start ≤ end",
            ));
        }
        self.add_basic(
            Basic {
                size: size as u32,
                labels: (lo..=hi).map(|v| v.to_string()).collect(),
                kind: Kind::Range(lo),
            },
            e,
        )
    }

    fn declarations(&mut self, decls: &[&Elem]) -> R<()> {
        // Sorts may be used before they are declared (products of later sorts): resolve
        // in rounds.
        let mut named: Vec<&Elem> = Vec::new();
        let mut vars: Vec<&Elem> = Vec::new();
        for d in decls {
            for c in &d.children {
                match c.name.as_str() {
                    "namedsort" => named.push(c),
                    "variabledecl" => vars.push(c),
                    "text" | "graphics" | "toolspecific" => {}
                    _ => return Err(self.unsupported(c, "declaration")),
                }
            }
        }
        let mut pending = named;
        while !pending.is_empty() {
            let mut next = Vec::new();
            let mut first_err = None;
            for n in &pending {
                let id = self.attr(n, "id")?.to_string();
                let sort = self.only_child(n)?;
                let needs: Vec<&Elem> = {
                    let mut out = Vec::new();
                    if sort.name == "usersort" {
                        out.push(sort);
                    }
                    sort.descendants("usersort", &mut out);
                    out
                };
                if needs
                    .iter()
                    .any(|u| u.attr("declaration").is_some_and(|d| !self.sorts.contains_key(d)))
                {
                    next.push(*n);
                    continue;
                }
                match self.sort(sort) {
                    Ok(s) => {
                        if self.sorts.insert(id.clone(), s).is_some() {
                            return Err(err(
                                Code::PnmlDuplicateId,
                                format!("the sort `{id}` is declared twice"),
                                self.span(n),
                                "second one",
                                "sort ids are unique in the document",
                            ));
                        }
                    }
                    Err(e) => first_err = first_err.or(Some(e)),
                }
            }
            if let Some(e) = first_err {
                return Err(e);
            }
            if next.len() == pending.len() {
                // No progress: a sort used in a cycle of declarations, or not declared.
                let waiting: HashSet<&str> = next.iter().filter_map(|n| n.attr("id")).collect();
                let mut uses = Vec::new();
                for n in &next {
                    n.descendants("usersort", &mut uses);
                }
                if let Some(u) = uses
                    .iter()
                    .find(|u| u.attr("declaration").is_some_and(|d| waiting.contains(d)))
                {
                    return Err(err(
                        Code::PnmlStructure,
                        "the sorts refer to each other in a cycle",
                        self.span(u),
                        "cyclic sort",
                        "a product names sorts declared without it",
                    ));
                }
                let sort = self.only_child(next[0])?;
                return Err(self.sort(sort).err().unwrap_or_else(|| self.unsupported(sort, "sort")));
            }
            pending = next;
        }
        for v in vars {
            let id = self.attr(v, "id")?.to_string();
            let sort = self.only_child(v)?;
            let sort = self.sort(sort)?;
            if self.var_ids.insert(id.clone(), self.vars.len()).is_some() {
                return Err(err(
                    Code::PnmlDuplicateId,
                    format!("the variable `{id}` is declared twice"),
                    self.span(v),
                    "second one",
                    "variable ids are unique in the document",
                ));
            }
            self.vars.push(Var { sort });
        }
        Ok(())
    }

    /// A term (the child of a `<structure>` or `<subterm>`) and its sort when it is a
    /// colour (`None` for multisets and booleans).
    fn term(&mut self, e: &Elem) -> R<(Term, Option<Vec<usize>>)> {
        let span = self.span(e);
        let subterms = |u: &mut Self| -> R<Vec<(Term, Option<Vec<usize>>)>> {
            let mut out = Vec::new();
            for s in e.all("subterm") {
                let c = u.only_child(s)?;
                out.push(u.term(c)?);
            }
            Ok(out)
        };
        let two = |u: &mut Self| -> R<(Term, Option<Vec<usize>>, Term)> {
            let mut v = subterms(u)?;
            if v.len() != 2 {
                return Err(err(
                    Code::PnmlStructure,
                    format!("<{}> takes two <subterm>s, not {}", e.name, v.len()),
                    span,
                    "wrong arity",
                    GRAMMAR,
                ));
            }
            let (b, _) = v.pop().ok_or_else(|| u.unsupported(e, "term"))?;
            let (a, sa) = v.pop().ok_or_else(|| u.unsupported(e, "term"))?;
            Ok((a, sa, b))
        };
        let t = |t: T| Term { t, span };
        Ok(match e.name.as_str() {
            "variable" => {
                let id = self.attr(e, "refvariable")?;
                let Some(&v) = self.var_ids.get(id) else {
                    return Err(err(
                        Code::PnmlStructure,
                        format!("the variable `{id}` is not declared"),
                        span,
                        "unknown variable",
                        "declare it with <variabledecl id=\"..\"> in the net's <declaration>",
                    ));
                };
                (t(T::Var(v)), Some(self.vars[v].sort.clone()))
            }
            "useroperator" => {
                let id = self.attr(e, "declaration")?;
                let Some(&(b, v)) = self.constants.get(id) else {
                    return Err(err(
                        Code::PnmlStructure,
                        format!("`{id}` is not a declared constant"),
                        span,
                        "unknown constant",
                        "a <useroperator> names a <feconstant> of an enumeration",
                    ));
                };
                (t(T::Const(vec![v])), Some(vec![b]))
            }
            "dotconstant" => {
                let b = self.dot(e)?;
                (t(T::Const(vec![0])), Some(vec![b]))
            }
            "finiteintrangeconstant" => {
                let value = self.number(e, "value")?;
                let r = e
                    .child("finiteintrange")
                    .ok_or_else(|| self.unsupported(e, "constant without its <finiteintrange>"))?;
                let b = self.range(r)?;
                let Kind::Range(lo) = self.basics[b].kind else {
                    return Err(self.unsupported(e, "constant"));
                };
                let at = value - lo;
                if at < 0 || at >= i64::from(self.basics[b].size) {
                    return Err(err(
                        Code::PnmlNumber,
                        format!("{value} is outside its range"),
                        span,
                        "out of range",
                        "a finiteintrangeconstant's value lies in its range",
                    ));
                }
                (t(T::Const(vec![at as u32])), Some(vec![b]))
            }
            "successor" | "predecessor" => {
                let mut v = subterms(self)?;
                let (inner, sort) = match (v.pop(), v.is_empty()) {
                    (Some(x), true) => x,
                    _ => return Err(self.unsupported(e, "term with one <subterm>")),
                };
                let Some([b]) = sort.as_deref() else {
                    return Err(err(
                        Code::PnmlStructure,
                        format!("<{}> of a term that is not one enumeration or range value", e.name),
                        span,
                        "not a single colour",
                        GRAMMAR,
                    ));
                };
                let step = if e.name == "successor" { 1 } else { -1 };
                let size = self.basics[*b].size;
                (t(T::Step(Box::new(inner), step, size)), Some(vec![*b]))
            }
            "tuple" => {
                let v = subterms(self)?;
                let mut sort = Vec::new();
                let mut terms = Vec::new();
                for (x, s) in v {
                    let Some(s) = s else {
                        return Err(err(
                            Code::PnmlStructure,
                            "a tuple's parts are colours",
                            x.span,
                            "not a colour",
                            GRAMMAR,
                        ));
                    };
                    sort.extend(s);
                    terms.push(x);
                }
                (t(T::Tuple(terms)), Some(sort))
            }
            "all" => {
                let s = self.only_child(e)?;
                let sort = self.sort(s)?;
                (t(T::All(sort.clone())), Some(sort))
            }
            "numberof" => {
                let mut v = subterms(self)?;
                if v.len() != 2 {
                    return Err(self.unsupported(e, "numberof (it takes a number and a colour)"));
                }
                let (c, _) = v.pop().ok_or_else(|| self.unsupported(e, "term"))?;
                let (n, _) = v.pop().ok_or_else(|| self.unsupported(e, "term"))?;
                let T::Const(ref k) = n.t else {
                    return Err(err(
                        Code::PnmlStructure,
                        "the first part of a numberof is a <numberconstant>",
                        n.span,
                        "not a number",
                        GRAMMAR,
                    ));
                };
                let k = k.first().copied().unwrap_or(0);
                (t(T::NumberOf(k, Box::new(c))), None)
            }
            "numberconstant" => {
                let value = self.number(e, "value")?;
                let value = u32::try_from(value)
                    .ok()
                    .filter(|v| *v <= crate::MAX_WEIGHT)
                    .ok_or_else(|| {
                        err(
                            Code::PnmlNumber,
                            format!("{value} tokens: a count is from 0 to {}", crate::MAX_WEIGHT),
                            span,
                            "out of range",
                            GRAMMAR,
                        )
                    })?;
                // A number is kept as a one-value constant; only numberof reads it.
                (t(T::Const(vec![value])), None)
            }
            "add" => {
                let v = subterms(self)?;
                (t(T::Add(v.into_iter().map(|(x, _)| x).collect())), None)
            }
            "subtract" => {
                // The first multiset less the others.
                let mut v: Vec<Term> = subterms(self)?.into_iter().map(|(x, _)| x).collect();
                if v.len() < 2 {
                    return Err(self.unsupported(e, "subtract of fewer than two <subterm>s"));
                }
                let rest = v.split_off(1);
                let first = v.pop().ok_or_else(|| self.unsupported(e, "term"))?;
                let rest = Term { t: T::Add(rest), span };
                (t(T::Sub(Box::new(first), Box::new(rest))), None)
            }
            "and" | "or" => {
                let v: Vec<Term> = subterms(self)?.into_iter().map(|(x, _)| x).collect();
                (t(if e.name == "and" { T::And(v) } else { T::Or(v) }), None)
            }
            "not" => {
                let mut v = subterms(self)?;
                match (v.pop(), v.is_empty()) {
                    (Some((x, _)), true) => (t(T::Not(Box::new(x))), None),
                    _ => return Err(self.unsupported(e, "not with one <subterm>")),
                }
            }
            "imply" => {
                let (a, _, b) = two(self)?;
                (t(T::Imply(Box::new(a), Box::new(b))), None)
            }
            "booleanconstant" => {
                let v = self.attr(e, "value")?;
                (t(T::Bool(v.trim() == "true")), None)
            }
            "equality" | "inequality" | "lessthan" | "lessthanorequal" | "greaterthan" | "greaterthanorequal" => {
                let op = match e.name.as_str() {
                    "equality" => Cmp::Eq,
                    "inequality" => Cmp::Ne,
                    "lessthan" => Cmp::Lt,
                    "lessthanorequal" => Cmp::Le,
                    "greaterthan" => Cmp::Gt,
                    _ => Cmp::Ge,
                };
                let (a, sa, b) = two(self)?;
                if sa.is_none() {
                    return Err(err(
                        Code::PnmlStructure,
                        format!("<{}> compares colours", e.name),
                        a.span,
                        "not a colour",
                        GRAMMAR,
                    ));
                }
                (t(T::Compare(op, Box::new(a), Box::new(b))), None)
            }
            _ => return Err(self.unsupported(e, "term")),
        })
    }

    /// Refuses a term denoting more colours than the budget's elements.
    fn within(&self, n: u64, span: Span) -> R<()> {
        if n > self.budget.elements {
            return Err(err(
                Code::PnmlLimit,
                format!(
                    "this term denotes {n} colours; Alba unfolds at most {}",
                    self.budget.elements
                ),
                span,
                "too many colours",
                "the unfolded net would not fit the budget; analyse a smaller instance",
            ));
        }
        Ok(())
    }

    /// The colours of a colour term (several for `all`, or a tuple holding one).
    fn colours(&self, term: &Term, b: &[Colour], out: &mut Vec<Colour>) -> R<()> {
        match &term.t {
            T::Var(v) => out.push(b[*v].clone()),
            T::Const(c) => out.push(c.clone()),
            T::Step(inner, step, size) => {
                let mut v = Vec::new();
                self.colours(inner, b, &mut v)?;
                for c in v {
                    let x = c.first().copied().unwrap_or(0);
                    let n = (i64::from(x) + step).rem_euclid(i64::from(*size));
                    out.push(vec![n as u32]);
                }
            }
            T::Tuple(parts) => {
                let mut acc: Vec<Colour> = vec![Vec::new()];
                for p in parts {
                    let mut v = Vec::new();
                    self.colours(p, b, &mut v)?;
                    self.within((acc.len() as u64).saturating_mul(v.len() as u64), term.span)?;
                    acc = acc
                        .iter()
                        .flat_map(|a| {
                            v.iter().map(move |x| {
                                let mut c = a.clone();
                                c.extend_from_slice(x);
                                c
                            })
                        })
                        .collect();
                    self.within(acc.len() as u64, term.span)?;
                }
                out.extend(acc);
            }
            T::All(sort) => {
                let sizes: Vec<u32> = sort.iter().map(|s| self.basics[*s].size).collect();
                let n = sizes
                    .iter()
                    .try_fold(1u64, |a, s| a.checked_mul(u64::from(*s)))
                    .unwrap_or(u64::MAX);
                self.within(n.saturating_add(out.len() as u64), term.span)?;
                for i in 0..n {
                    out.push(decode(i, &sizes));
                }
            }
            _ => {
                return Err(err(
                    Code::PnmlStructure,
                    "a multiset or condition where a colour is expected",
                    term.span,
                    "not a colour",
                    GRAMMAR,
                ));
            }
        }
        Ok(())
    }

    /// The multiset of a term: colour → count.
    fn multiset(&self, term: &Term, b: &[Colour], out: &mut BTreeMap<Colour, i64>, sign: i64) -> R<()> {
        match &term.t {
            T::NumberOf(k, c) => {
                let mut v = Vec::new();
                self.colours(c, b, &mut v)?;
                for c in v {
                    *out.entry(c).or_default() += sign * i64::from(*k);
                }
            }
            T::Add(parts) => {
                for p in parts {
                    self.multiset(p, b, out, sign)?;
                }
            }
            T::Sub(x, y) => {
                self.multiset(x, b, out, sign)?;
                self.multiset(y, b, out, -sign)?;
            }
            _ => {
                let mut v = Vec::new();
                self.colours(term, b, &mut v)?;
                for c in v {
                    *out.entry(c).or_default() += sign;
                }
            }
        }
        Ok(())
    }

    fn holds(&self, term: &Term, b: &[Colour]) -> R<bool> {
        Ok(match &term.t {
            T::And(v) => {
                for x in v {
                    if !self.holds(x, b)? {
                        return Ok(false);
                    }
                }
                true
            }
            T::Or(v) => {
                for x in v {
                    if self.holds(x, b)? {
                        return Ok(true);
                    }
                }
                false
            }
            T::Not(x) => !self.holds(x, b)?,
            T::Imply(x, y) => !self.holds(x, b)? || self.holds(y, b)?,
            T::Bool(v) => *v,
            T::Compare(op, x, y) => {
                let (mut cx, mut cy) = (Vec::new(), Vec::new());
                self.colours(x, b, &mut cx)?;
                self.colours(y, b, &mut cy)?;
                let (Some(a), Some(c), 1, 1) = (cx.first(), cy.first(), cx.len(), cy.len()) else {
                    return Err(err(
                        Code::PnmlStructure,
                        "a comparison of more than one colour",
                        term.span,
                        "not one colour",
                        GRAMMAR,
                    ));
                };
                match op {
                    Cmp::Eq => a == c,
                    Cmp::Ne => a != c,
                    Cmp::Lt => a < c,
                    Cmp::Le => a <= c,
                    Cmp::Gt => a > c,
                    Cmp::Ge => a >= c,
                }
            }
            _ => {
                return Err(err(
                    Code::PnmlStructure,
                    "a condition is a boolean term",
                    term.span,
                    "not a condition",
                    GRAMMAR,
                ));
            }
        })
    }

    fn label(&self, sort: &[usize], c: &Colour) -> String {
        sort.iter()
            .zip(c)
            .map(|(s, v)| self.basics[*s].labels[*v as usize].as_str())
            .collect::<Vec<_>>()
            .join("_")
    }
}

/// The `i`-th colour of a product of sorts of these sizes (the last component fastest).
fn decode(mut i: u64, sizes: &[u32]) -> Colour {
    let mut c = vec![0; sizes.len()];
    for (k, s) in sizes.iter().enumerate().rev() {
        c[k] = (i % u64::from(*s)) as u32;
        i /= u64::from(*s);
    }
    c
}

fn encode(c: &Colour, sizes: &[u32]) -> Option<u64> {
    if c.len() != sizes.len() {
        return None;
    }
    let mut i = 0u64;
    for (v, s) in c.iter().zip(sizes) {
        if v >= s {
            return None;
        }
        i = i * u64::from(*s) + u64::from(*v);
    }
    Some(i)
}

/// The structure of a label (`<type>`, `<hlinitialMarking>`, `<hlinscription>`,
/// `<condition>`): its one term.
fn structure<'e>(u: &Unfolder, label: &'e Elem) -> R<&'e Elem> {
    let s = label.child("structure").ok_or_else(|| {
        err(
            Code::PnmlStructure,
            format!("<{}> has no <structure>", label.name),
            u.span(label),
            "structure missing",
            "a symmetric net's labels hold their term in <structure>; the <text> is only a comment",
        )
    })?;
    u.only_child(s)
}

struct CPlace {
    id: String,
    sizes: Vec<u32>,
    initial: Option<Term>,
    /// Index of its first unfolded place.
    first: usize,
}

struct CArc {
    place: usize,
    transition: usize,
    input: bool,
    term: Option<Term>,
    span: Span,
}

fn collect<'e>(e: &'e Elem, out: &mut Vec<&'e Elem>, decls: &mut Vec<&'e Elem>) {
    for c in &e.children {
        match c.name.as_str() {
            "place" | "transition" | "arc" => out.push(c),
            "page" => collect(c, out, decls),
            "declaration" => {
                if let Some(s) = c.child("structure") {
                    decls.extend(s.all("declarations"));
                }
            }
            _ => {}
        }
    }
}

fn vars_of(t: &Term, out: &mut Vec<usize>) {
    match &t.t {
        T::Var(v) => {
            if !out.contains(v) {
                out.push(*v)
            }
        }
        T::Step(x, _, _) | T::NumberOf(_, x) | T::Not(x) => vars_of(x, out),
        T::Tuple(v) | T::Add(v) | T::And(v) | T::Or(v) => v.iter().for_each(|x| vars_of(x, out)),
        T::Sub(x, y) | T::Imply(x, y) | T::Compare(_, x, y) => {
            vars_of(x, out);
            vars_of(y, out);
        }
        T::Const(_) | T::All(_) | T::Bool(_) => {}
    }
}

/// Unfolds the symmetric net of a PNML document into a place/transition [`Net`]: a
/// place `P_c` per place `P` and colour `c` of its sort (`P` itself for a `dot` place),
/// a transition `T_v` per transition `T` and binding `v` of its variables that
/// satisfies its condition, arcs weighted by the inscriptions' multisets. The first
/// error ends it.
pub fn unfold(file: FileId, text: &str, budget: &Budget) -> Result<(Net, Unfolding), Diagnostic> {
    let whole = Span::new(file, 0..0);
    if text.len() > crate::MAX_FILE_BYTES {
        return Err(err(
            Code::PnmlLimit,
            format!("the file has {} bytes; Alba reads PNML files up to 16 MiB", text.len()),
            whole,
            "too large",
            "analyse a smaller instance",
        ));
    }
    let root = match xml::parse(text, &crate::XML_LIMITS) {
        Ok(r) => r,
        Err(_) => {
            // The P/T loader reports XML errors with their place.
            let (_, d) = crate::load(file, text);
            return Err(d
                .into_iter()
                .next()
                .unwrap_or_else(|| err(Code::PnmlSyntax, "not well-formed XML", whole, "here", "fix the XML")));
        }
    };
    let mut u = Unfolder {
        file,
        text,
        basics: Vec::new(),
        sorts: HashMap::new(),
        constants: HashMap::new(),
        vars: Vec::new(),
        var_ids: HashMap::new(),
        budget: *budget,
    };
    let Some(net_elem) = root.child("net") else {
        return Err(err(
            Code::PnmlStructure,
            "the document has no <net>",
            u.span(&root),
            "no net",
            "a PNML file is <pnml><net id=\"..\" type=\"..\">...</net></pnml>",
        ));
    };
    let mut nodes = Vec::new();
    let mut decls = Vec::new();
    collect(net_elem, &mut nodes, &mut decls);
    u.declarations(&decls)?;

    let mut net = Net::new(net_elem.attr("id").unwrap_or("net"));
    net.name = net_elem
        .child("name")
        .and_then(|n| n.child("text"))
        .map(|t| t.text.clone());
    let mut used: HashSet<String> = HashSet::new();
    let mut fresh = |id: String| -> String {
        let mut name = id.clone();
        let mut k = 2;
        while !used.insert(name.clone()) {
            name = format!("{id}#{k}");
            k += 1;
        }
        name
    };
    let elements = std::cell::Cell::new(0u64);
    let count = |n: u64, e: &Elem, u: &Unfolder| -> R<()> {
        elements.set(elements.get().saturating_add(n));
        if elements.get() > u.budget.elements {
            return Err(err(
                Code::PnmlLimit,
                format!(
                    "unfolding the coloured net makes more than {} places, transitions and arcs",
                    u.budget.elements
                ),
                u.span(e),
                "unfolding too large",
                "the unfolded net would not fit the budget; analyse a smaller instance",
            ));
        }
        Ok(())
    };

    // Places.
    let mut places: Vec<CPlace> = Vec::new();
    let mut place_map = Vec::new();
    let mut place_ix: HashMap<String, usize> = HashMap::new();
    let mut ids: HashMap<String, Span> = HashMap::new();
    let mut check_id = |u: &Unfolder, e: &Elem| -> R<String> {
        let id = u.attr(e, "id")?.to_string();
        if let Some(first) = ids.insert(id.clone(), u.span(e)) {
            return Err(err(
                Code::PnmlDuplicateId,
                format!("the id `{id}` is used twice"),
                u.span(e),
                "second use",
                "ids are unique in the whole PNML document",
            )
            .with_note(first, "first use"));
        }
        Ok(id)
    };
    for e in nodes.iter().filter(|e| e.name == "place") {
        let id = check_id(&u, e)?;
        let sort = match e.child("type") {
            Some(t) => {
                let s = structure(&u, t)?;
                u.sort(s)?
            }
            None => vec![u.dot(e)?],
        };
        let sizes: Vec<u32> = sort.iter().map(|s| u.basics[*s].size).collect();
        let n: u64 = sizes
            .iter()
            .try_fold(1u64, |a, s| a.checked_mul(u64::from(*s)))
            .unwrap_or(u64::MAX);
        count(n, e, &u)?;
        let initial = match e.child("hlinitialMarking") {
            Some(m) => {
                let s = structure(&u, m)?;
                Some(u.term(s)?.0)
            }
            None => None,
        };
        let first = net.places.len();
        for i in 0..n {
            let c = decode(i, &sizes);
            let name = if n == 1 && sort.iter().all(|s| u.basics[*s].kind == Kind::Dot) {
                id.clone()
            } else {
                format!("{id}_{}", u.label(&sort, &c))
            };
            let mut p = Place::new(fresh(name), 0);
            p.span = u.span(e);
            net.places.push(p);
        }
        place_ix.insert(id.clone(), places.len());
        place_map.push((id.clone(), first..net.places.len()));
        places.push(CPlace {
            id,
            sizes,
            initial,
            first,
        });
    }
    for p in &places {
        let Some(m) = &p.initial else { continue };
        let mut ms = BTreeMap::new();
        u.multiset(m, &[], &mut ms, 1)?;
        for (c, k) in ms {
            let at = encode(&c, &p.sizes).ok_or_else(|| {
                err(
                    Code::PnmlStructure,
                    format!("the initial marking of `{}` has a colour not of its sort", p.id),
                    m.span,
                    "wrong sort",
                    "a place's tokens are colours of its <type>",
                )
            })?;
            if !(0..=i64::from(crate::MAX_MARKING)).contains(&k) {
                return Err(err(
                    Code::PnmlNumber,
                    format!("the initial marking of `{}` has {k} tokens of a colour", p.id),
                    m.span,
                    "out of range",
                    "a colour has 0 to 1000000 tokens",
                ));
            }
            net.places[p.first + at as usize].initial = k as u32;
        }
    }

    // Transitions, their guards and arcs.
    let mut trans: Vec<(&Elem, String, Option<Term>)> = Vec::new();
    let mut trans_ix: HashMap<String, usize> = HashMap::new();
    for e in nodes.iter().filter(|e| e.name == "transition") {
        let id = check_id(&u, e)?;
        let guard = match e.child("condition") {
            Some(c) => {
                let s = structure(&u, c)?;
                Some(u.term(s)?.0)
            }
            None => None,
        };
        trans_ix.insert(id.clone(), trans.len());
        trans.push((e, id, guard));
    }
    let mut arcs: Vec<CArc> = Vec::new();
    for e in nodes.iter().filter(|e| e.name == "arc") {
        check_id(&u, e)?;
        let (s, t) = (u.attr(e, "source")?, u.attr(e, "target")?);
        let (place, transition, input) = match (place_ix.get(s), trans_ix.get(t), trans_ix.get(s), place_ix.get(t)) {
            (Some(p), Some(t), _, _) => (*p, *t, true),
            (_, _, Some(t), Some(p)) => (*p, *t, false),
            _ => {
                return Err(err(
                    Code::PnmlArc,
                    format!("arc from `{s}` to `{t}` does not join a place and a transition of the net"),
                    u.span(e),
                    "not a place and a transition",
                    "an arc goes from a place to a transition or from a transition to a place",
                ));
            }
        };
        let term = match e.child("hlinscription") {
            Some(i) => {
                let s = structure(&u, i)?;
                Some(u.term(s)?.0)
            }
            None => None,
        };
        arcs.push(CArc {
            place,
            transition,
            input,
            term,
            span: u.span(e),
        });
    }
    let mut by_transition: Vec<Vec<&CArc>> = vec![Vec::new(); trans.len()];
    for a in &arcs {
        by_transition[a.transition].push(a);
    }

    let mut bindings = 0u64;
    let mut transition_map = Vec::new();
    for (ti, (e, id, guard)) in trans.iter().enumerate() {
        let first_transition = net.transitions.len();
        let mut vs = Vec::new();
        if let Some(g) = guard {
            vars_of(g, &mut vs);
        }
        for a in &by_transition[ti] {
            if let Some(t) = &a.term {
                vars_of(t, &mut vs);
            }
        }
        let sizes: Vec<u64> = vs
            .iter()
            .map(|v| u.vars[*v].sort.iter().map(|s| u64::from(u.basics[*s].size)).product())
            .collect();
        let n = sizes
            .iter()
            .try_fold(1u64, |a, s| a.checked_mul(*s))
            .unwrap_or(u64::MAX);
        bindings = bindings.saturating_add(n);
        if bindings > budget.bindings {
            return Err(err(
                Code::PnmlLimit,
                format!(
                    "unfolding `{id}` needs {n} bindings of its variables; Alba tries at most {} in a net",
                    budget.bindings
                ),
                u.span(e),
                "unfolding too large",
                "the unfolded net would not fit the budget; analyse a smaller instance",
            ));
        }
        let var_sizes: Vec<Vec<u32>> = vs
            .iter()
            .map(|v| u.vars[*v].sort.iter().map(|s| u.basics[*s].size).collect())
            .collect();
        let mut b: Vec<Colour> = vec![Vec::new(); u.vars.len()];
        for i in 0..n {
            let mut rest = i;
            for (k, v) in vs.iter().enumerate().rev() {
                b[*v] = decode(rest % sizes[k], &var_sizes[k]);
                rest /= sizes[k];
            }
            if let Some(g) = guard
                && !u.holds(g, &b)?
            {
                continue;
            }
            let mut pre: BTreeMap<usize, i64> = BTreeMap::new();
            let mut post: BTreeMap<usize, i64> = BTreeMap::new();
            for a in &by_transition[ti] {
                let p = &places[a.place];
                let mut ms = BTreeMap::new();
                match &a.term {
                    Some(t) => u.multiset(t, &b, &mut ms, 1)?,
                    None if p.sizes.iter().all(|s| *s == 1) => {
                        ms.insert(vec![0; p.sizes.len()], 1);
                    }
                    None => {
                        return Err(err(
                            Code::PnmlStructure,
                            format!("an arc of the coloured place `{}` has no <hlinscription>", p.id),
                            a.span,
                            "inscription missing",
                            "only arcs of dot places may leave their inscription out",
                        ));
                    }
                }
                for (c, k) in ms {
                    let at = encode(&c, &p.sizes).ok_or_else(|| {
                        err(
                            Code::PnmlStructure,
                            format!("the inscription's colour is not of the sort of `{}`", p.id),
                            a.span,
                            "wrong sort",
                            "an arc carries colours of its place's <type>",
                        )
                    })?;
                    let side = if a.input { &mut pre } else { &mut post };
                    *side.entry(p.first + at as usize).or_default() += k;
                }
            }
            let name = if vs.is_empty() {
                id.clone()
            } else {
                let parts: Vec<String> = vs.iter().map(|v| u.label(&u.vars[*v].sort, &b[*v])).collect();
                format!("{id}_{}", parts.join("_"))
            };
            let tid = fresh(name);
            let mut t = Transition::new(tid.clone());
            t.span = u.span(e);
            net.transitions.push(t);
            count(1, e, &u)?;
            for (input, side) in [(true, pre), (false, post)] {
                for (p, k) in side {
                    if k == 0 {
                        continue;
                    }
                    if !(1..=i64::from(crate::MAX_WEIGHT)).contains(&k) {
                        return Err(err(
                            Code::PnmlNumber,
                            format!("binding `{tid}`: an arc of weight {k}"),
                            u.span(e),
                            "bad weight",
                            "a subtract that leaves a negative count, or a weight over 1000000",
                        ));
                    }
                    count(1, e, &u)?;
                    let pid = net.places[p].id.clone();
                    let (s, d) = if input { (pid, tid.clone()) } else { (tid.clone(), pid) };
                    let aid = format!("{s}>{d}");
                    net.arcs.push(Arc::new(aid, s, d, k as u32));
                }
            }
        }
        transition_map.push((id.clone(), first_transition..net.transitions.len()));
    }
    Ok((
        net,
        Unfolding {
            coloured_places: places.len(),
            coloured_transitions: trans.len(),
            bindings,
            places: place_map,
            transitions: transition_map,
        },
    ))
}
