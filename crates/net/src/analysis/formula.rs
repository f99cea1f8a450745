//! The Model Checking Contest's examinations `UpperBounds`, `ReachabilityCardinality`,
//! `ReachabilityFireability` and `ReachabilityDeadlock` (docs/nets.md, section "contest
//! examinations"): the contest's XML formula files read into [`Property`]s, checked by
//! [`check`] and answered in the contest's output form ([`Answer`]'s `Display`:
//! `FORMULA <id> TRUE|FALSE|<bound> TECHNIQUES …`).
//!
//! Grammar read (the subset of the contest's `property-set` these examinations use):
//! `<property><id>…</id><formula>Q</formula></property>` with `Q` one of
//! `<exists-path><finally>φ</finally></exists-path>` (EF φ),
//! `<all-paths><globally>φ</globally></all-paths>` (AG φ) and
//! `<place-bound><place>p</place>…</place-bound>` (the most tokens the places hold
//! together in a reachable marking); state formulas `φ` are `<true/>`, `<false/>`,
//! `<negation>`, `<conjunction>`, `<disjunction>`, `<integer-le>` of two integer
//! expressions (`<integer-constant>`, `<tokens-count><place>…</tokens-count>`,
//! `<integer-sum>`), `<is-fireable><transition>…</is-fireable>` and `<deadlock/>`.
//! Places and transitions are named by their PNML ids. `ReachabilityDeadlock` has no
//! file: it is the fixed question EF deadlock, [`deadlock_property`].
//!
//! A coloured model's formulas name its coloured places and transitions
//! ([`parse_for`] with the [`Unfolding`]): a coloured place stands for all its unfolded
//! places (its tokens are theirs together, its bound the bound of their sum) and a
//! coloured transition for all its unfolded ones (fireable when one of them is).

use crate::PtNet;
use crate::colored::Unfolding;
use alba_xml::Elem;
use std::collections::HashMap;

/// An integer expression of a state formula.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IntExpr {
    /// A constant.
    Const(u64),
    /// The tokens of these places together.
    Tokens(Vec<usize>),
    /// A sum of expressions.
    Sum(Vec<IntExpr>),
}

/// A state formula.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pred {
    /// Always true.
    True,
    /// Always false.
    False,
    /// Negation.
    Not(Box<Pred>),
    /// All of them.
    And(Vec<Pred>),
    /// At least one of them.
    Or(Vec<Pred>),
    /// `a <= b`.
    Le(IntExpr, IntExpr),
    /// At least one of these transitions is enabled.
    Fireable(Vec<usize>),
    /// No transition is enabled.
    Deadlock,
}

/// The question of a property.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Query {
    /// EF φ: some reachable marking satisfies φ.
    Ef(Pred),
    /// AG φ: every reachable marking satisfies φ.
    Ag(Pred),
    /// The most tokens these places hold together in a reachable marking.
    Bound(Vec<usize>),
}

/// One property of a formula file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Property {
    /// The contest's id (`Anderson-PT-04-ReachabilityCardinality-00`).
    pub id: String,
    /// The question.
    pub query: Query,
}

/// A formula file that cannot be read: where and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FormulaError {
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1.
    pub column: u32,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for FormulaError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: {}", self.line, self.column, self.message)
    }
}

impl std::error::Error for FormulaError {}

/// The property `ReachabilityDeadlock` (EF deadlock), as the contest's oracle names it.
pub fn deadlock_property() -> Property {
    Property {
        id: "ReachabilityDeadlock".to_string(),
        query: Query::Ef(Pred::Deadlock),
    }
}

/// Formula files are small; the limits of PNML files are ample.
const LIMITS: alba_xml::Limits = alba_xml::Limits {
    max_depth: 256,
    max_elements: 1_000_000,
    refuse_doctype: false,
};

struct Reader<'a> {
    text: &'a str,
    /// Each name and the places (transitions) it stands for.
    places: HashMap<&'a str, Vec<usize>>,
    transitions: HashMap<&'a str, Vec<usize>>,
}

impl Reader<'_> {
    fn error(&self, at: &Elem, message: String) -> FormulaError {
        let (line, column) = alba_xml::line_col(self.text, at.start);
        FormulaError { line, column, message }
    }

    fn elements<'e>(&self, e: &'e Elem) -> impl Iterator<Item = &'e Elem> {
        e.children.iter()
    }

    fn only_child<'e>(&self, e: &'e Elem) -> Result<&'e Elem, FormulaError> {
        let mut it = self.elements(e);
        match (it.next(), it.next()) {
            (Some(c), None) => Ok(c),
            _ => Err(self.error(e, format!("<{}> needs exactly one element inside", e.name))),
        }
    }

    fn place(&self, e: &Elem) -> Result<&[usize], FormulaError> {
        let id = e.text.trim();
        self.places
            .get(id)
            .map(Vec::as_slice)
            .ok_or_else(|| self.error(e, format!("no place `{id}` in the net")))
    }

    fn transition(&self, e: &Elem) -> Result<&[usize], FormulaError> {
        let id = e.text.trim();
        self.transitions
            .get(id)
            .map(Vec::as_slice)
            .ok_or_else(|| self.error(e, format!("no transition `{id}` in the net")))
    }

    fn places_of(&self, e: &Elem) -> Result<Vec<usize>, FormulaError> {
        let mut out = Vec::new();
        for c in self.elements(e) {
            match c.name.as_str() {
                "place" => out.extend(self.place(c)?),
                other => return Err(self.error(c, format!("<{other}> inside <{}>: expected <place>", e.name))),
            }
        }
        Ok(out)
    }

    fn int(&self, e: &Elem) -> Result<IntExpr, FormulaError> {
        match e.name.as_str() {
            "integer-constant" => e
                .text
                .trim()
                .parse()
                .map(IntExpr::Const)
                .map_err(|_| self.error(e, format!("`{}` is not a natural number", e.text.trim()))),
            "tokens-count" => Ok(IntExpr::Tokens(self.places_of(e)?)),
            "integer-sum" => Ok(IntExpr::Sum(
                self.elements(e).map(|c| self.int(c)).collect::<Result<_, _>>()?,
            )),
            other => Err(self.error(e, format!("<{other}> is not an integer expression this reader knows"))),
        }
    }

    fn pred(&self, e: &Elem) -> Result<Pred, FormulaError> {
        let all = |r: &Self| self.elements(e).map(|c| r.pred(c)).collect::<Result<Vec<_>, _>>();
        match e.name.as_str() {
            "true" => Ok(Pred::True),
            "false" => Ok(Pred::False),
            "deadlock" => Ok(Pred::Deadlock),
            "negation" => Ok(Pred::Not(Box::new(self.pred(self.only_child(e)?)?))),
            "conjunction" => Ok(Pred::And(all(self)?)),
            "disjunction" => Ok(Pred::Or(all(self)?)),
            "integer-le" => {
                let v: Vec<&Elem> = self.elements(e).collect();
                match v[..] {
                    [a, b] => Ok(Pred::Le(self.int(a)?, self.int(b)?)),
                    _ => Err(self.error(e, "<integer-le> needs two integer expressions".into())),
                }
            }
            "is-fireable" => {
                let mut ts = Vec::new();
                for c in self.elements(e) {
                    match c.name.as_str() {
                        "transition" => ts.extend(self.transition(c)?),
                        other => {
                            return Err(self.error(c, format!("<{other}> inside <is-fireable>: expected <transition>")));
                        }
                    }
                }
                Ok(Pred::Fireable(ts))
            }
            other => Err(self.error(e, format!("<{other}> is not a state formula this reader knows"))),
        }
    }

    fn query(&self, e: &Elem) -> Result<Query, FormulaError> {
        match e.name.as_str() {
            "exists-path" => {
                let f = self.only_child(e)?;
                if f.name != "finally" {
                    return Err(self.error(f, format!("<exists-path><{}>: only <finally> is read", f.name)));
                }
                Ok(Query::Ef(self.pred(self.only_child(f)?)?))
            }
            "all-paths" => {
                let g = self.only_child(e)?;
                if g.name != "globally" {
                    return Err(self.error(g, format!("<all-paths><{}>: only <globally> is read", g.name)));
                }
                Ok(Query::Ag(self.pred(self.only_child(g)?)?))
            }
            "place-bound" => Ok(Query::Bound(self.places_of(e)?)),
            other => Err(self.error(
                e,
                format!("<{other}>: expected <exists-path>, <all-paths> or <place-bound>"),
            )),
        }
    }
}

/// Each name and what it stands for: the coloured nodes' ids (their unfolded nodes),
/// then the net's own ids.
fn names<'a>(ids: &'a [String], coloured: &'a [(String, std::ops::Range<usize>)]) -> HashMap<&'a str, Vec<usize>> {
    let mut m: HashMap<&str, Vec<usize>> = HashMap::new();
    for (id, range) in coloured {
        m.insert(id.as_str(), range.clone().collect());
    }
    for (i, id) in ids.iter().enumerate() {
        m.entry(id.as_str()).or_insert_with(|| vec![i]);
    }
    m
}

/// Reads a contest formula file (`property-set`) against the net whose ids it names.
pub fn parse(text: &str, net: &PtNet) -> Result<Vec<Property>, FormulaError> {
    parse_for(text, net, None)
}

/// [`parse`] for a net that may come from a coloured model: with its [`Unfolding`], a
/// name is first a coloured place or transition (standing for all its unfolded ones),
/// then an unfolded one.
pub fn parse_for(text: &str, net: &PtNet, unfolding: Option<&Unfolding>) -> Result<Vec<Property>, FormulaError> {
    let root = alba_xml::parse(text, &LIMITS).map_err(|e| {
        let (line, column) = alba_xml::line_col(text, e.offset);
        FormulaError {
            line,
            column,
            message: e.message,
        }
    })?;
    let r = Reader {
        text,
        places: names(&net.places, unfolding.map_or(&[], |u| &u.places)),
        transitions: names(&net.transitions, unfolding.map_or(&[], |u| &u.transitions)),
    };
    if root.name != "property-set" {
        return Err(r.error(&root, format!("<{}>: expected <property-set>", root.name)));
    }
    let mut out = Vec::new();
    for p in root.all("property") {
        let id = p
            .child("id")
            .map(|i| i.text.trim().to_string())
            .filter(|i| !i.is_empty())
            .ok_or_else(|| r.error(p, "<property> without <id>".into()))?;
        let f = p
            .child("formula")
            .ok_or_else(|| r.error(p, format!("property `{id}` without <formula>")))?;
        out.push(Property {
            id,
            query: r.query(r.only_child(f)?)?,
        });
    }
    Ok(out)
}

impl IntExpr {
    /// The value at marking `m`.
    pub fn eval(&self, m: &[u32]) -> u64 {
        match self {
            IntExpr::Const(c) => *c,
            IntExpr::Tokens(ps) => ps.iter().map(|&p| u64::from(m[p])).sum(),
            IntExpr::Sum(v) => v.iter().map(|e| e.eval(m)).fold(0, u64::saturating_add),
        }
    }

    /// The places it counts.
    fn places(&self, out: &mut Vec<usize>) {
        match self {
            IntExpr::Const(_) => {}
            IntExpr::Tokens(ps) => out.extend(ps),
            IntExpr::Sum(v) => v.iter().for_each(|e| e.places(out)),
        }
    }
}

impl IntExpr {
    fn map(&self, place: &[usize]) -> IntExpr {
        match self {
            IntExpr::Const(c) => IntExpr::Const(*c),
            IntExpr::Tokens(ps) => IntExpr::Tokens(ps.iter().map(|&p| place[p]).collect()),
            IntExpr::Sum(v) => IntExpr::Sum(v.iter().map(|e| e.map(place)).collect()),
        }
    }
}

impl Pred {
    /// The places whose tokens the formula reads and the transitions whose enabling it
    /// asks (`is-fireable`); `None` when it depends on the whole net (`deadlock`).
    pub fn support(&self, places: &mut Vec<usize>, transitions: &mut Vec<usize>) -> Option<()> {
        match self {
            Pred::True | Pred::False => Some(()),
            Pred::Not(p) => p.support(places, transitions),
            Pred::And(v) | Pred::Or(v) => v.iter().try_for_each(|p| p.support(places, transitions)),
            Pred::Le(a, b) => {
                a.places(places);
                b.places(places);
                Some(())
            }
            Pred::Fireable(ts) => {
                transitions.extend(ts);
                Some(())
            }
            Pred::Deadlock => None,
        }
    }

    /// The formula over renumbered places and transitions (a slice's numbers).
    pub fn map(&self, place: &[usize], transition: &[usize]) -> Pred {
        match self {
            Pred::True => Pred::True,
            Pred::False => Pred::False,
            Pred::Deadlock => Pred::Deadlock,
            Pred::Not(p) => Pred::Not(Box::new(p.map(place, transition))),
            Pred::And(v) => Pred::And(v.iter().map(|p| p.map(place, transition)).collect()),
            Pred::Or(v) => Pred::Or(v.iter().map(|p| p.map(place, transition)).collect()),
            Pred::Le(a, b) => Pred::Le(a.map(place), b.map(place)),
            Pred::Fireable(ts) => Pred::Fireable(ts.iter().map(|&t| transition[t]).collect()),
        }
    }
}

/// A slice of a net (Rakow's slicing for safety properties): the places a property reads,
/// every transition that changes one of the slice's places, and the places of those
/// transitions' arcs, to a fixed point. A transition left out changes no place of the
/// slice, so the slice's transitions are enabled and fire there exactly as in the whole
/// net: the markings reachable in the slice are the projections of the net's, and every
/// firing sequence of the slice is one of the net. Reachability and bounds over the
/// slice's places keep their answers, and a trace in the slice replays in the net.
pub struct Slice {
    /// The sliced net.
    pub net: PtNet,
    /// Per place of the net: its number in the slice (`usize::MAX`: left out).
    pub place: Vec<usize>,
    /// Per transition of the net: its number in the slice (`usize::MAX`: left out).
    pub transition: Vec<usize>,
    /// Per transition of the slice: its number in the net.
    pub back: Vec<usize>,
}

/// The slice of `net` for properties reading `places` and asking whether `transitions`
/// are enabled (these are kept, with the places of their arcs); `None` when it is the
/// whole net.
pub fn slice(net: &PtNet, places: &[usize], transitions: &[usize]) -> Option<Slice> {
    let ix = Index::new(net);
    let np = net.places.len();
    let nt = net.transitions.len();
    let mut keep_p = vec![false; np];
    let mut keep_t = vec![false; nt];
    let mut work: Vec<usize> = places.to_vec();
    let keep = |t: usize, keep_t: &mut [bool], work: &mut Vec<usize>| {
        if !std::mem::replace(&mut keep_t[t], true) {
            let arcs = net.pre[t].iter().chain(&net.reads[t]).chain(&net.inhibitors[t]);
            work.extend(arcs.map(|&(q, _)| q));
        }
    };
    for &t in transitions {
        keep(t, &mut keep_t, &mut work);
    }
    while let Some(p) = work.pop() {
        if std::mem::replace(&mut keep_p[p], true) {
            continue;
        }
        for &t in ix.inc[p].iter().chain(&ix.dec[p]) {
            keep(t, &mut keep_t, &mut work);
        }
    }
    if keep_p.iter().all(|&k| k) && keep_t.iter().all(|&k| k) {
        return None;
    }
    let mut s = Slice {
        net: PtNet::new(),
        place: vec![usize::MAX; np],
        transition: vec![usize::MAX; nt],
        back: Vec::new(),
    };
    for p in (0..np).filter(|&p| keep_p[p]) {
        s.place[p] = s.net.add_place(&net.places[p], net.initial[p]);
    }
    for t in (0..nt).filter(|&t| keep_t[t]) {
        let u = s.net.add_transition(&net.transitions[t]);
        s.transition[t] = u;
        s.back.push(t);
        // Every arc of a kept transition is on a kept place, except output arcs, which
        // are on kept places too unless the transition only adds there: dropped.
        for &(p, w) in &net.pre[t] {
            s.net.add_pre(u, s.place[p], w);
        }
        for &(p, w) in net.post[t].iter().filter(|&&(p, _)| keep_p[p]) {
            s.net.add_post(u, s.place[p], w);
        }
        for &(p, w) in &net.reads[t] {
            s.net.add_read(u, s.place[p], w);
        }
        for &(p, w) in &net.inhibitors[t] {
            s.net.add_inhibitor(u, s.place[p], w);
        }
    }
    Some(s)
}

/// Who touches each place, for the stubborn sets ([`super::stubborn`]).
pub(crate) struct Index {
    /// Per place: transitions with a positive net effect on it.
    pub inc: Vec<Vec<usize>>,
    /// Per place: transitions with a negative net effect on it.
    pub dec: Vec<Vec<usize>>,
    /// Per place: transitions with an input or read arc from it.
    pub needs: Vec<Vec<usize>>,
    /// Per place: transitions with an inhibitor arc from it.
    pub inhibited: Vec<Vec<usize>>,
    /// Per transition: the transitions its firing can disable (input or read arcs on a
    /// place it empties, inhibitor arcs on a place it fills).
    pub disables: Vec<Vec<usize>>,
}

impl Index {
    pub fn new(net: &PtNet) -> Index {
        let np = net.places.len();
        let mut ix = Index {
            inc: vec![Vec::new(); np],
            dec: vec![Vec::new(); np],
            needs: vec![Vec::new(); np],
            inhibited: vec![Vec::new(); np],
            disables: Vec::new(),
        };
        for t in 0..net.transitions.len() {
            let mut eff: std::collections::BTreeMap<usize, i64> = Default::default();
            for &(p, w) in &net.pre[t] {
                *eff.entry(p).or_default() -= i64::from(w);
                ix.needs[p].push(t);
            }
            for &(p, w) in &net.post[t] {
                *eff.entry(p).or_default() += i64::from(w);
            }
            for &(p, _) in &net.reads[t] {
                if !ix.needs[p].contains(&t) {
                    ix.needs[p].push(t);
                }
            }
            for &(p, _) in &net.inhibitors[t] {
                ix.inhibited[p].push(t);
            }
            for (p, e) in eff {
                if e > 0 {
                    ix.inc[p].push(t);
                } else if e < 0 {
                    ix.dec[p].push(t);
                }
            }
        }
        for t in 0..net.transitions.len() {
            let mut d: Vec<usize> = Vec::new();
            for &(p, _) in &net.pre[t] {
                if ix.dec[p].contains(&t) {
                    d.extend(&ix.needs[p]);
                }
            }
            for &(p, _) in &net.post[t] {
                if ix.inc[p].contains(&t) {
                    d.extend(&ix.inhibited[p]);
                }
            }
            d.sort_unstable();
            d.dedup();
            ix.disables.push(d);
        }
        ix
    }

    /// For `t` disabled at `m`: the transitions that can remove one reason it is disabled
    /// (of the places short of tokens, the one with the fewest producers: those; of the
    /// inhibitor places too full, the one with the fewest consumers: those). Nothing
    /// when `t` is enabled.
    pub fn scapegoat(&self, net: &PtNet, m: &[u32], t: usize, out: &mut Vec<usize>) {
        let short = net.pre[t]
            .iter()
            .chain(&net.reads[t])
            .filter(|&&(p, w)| m[p] < w)
            .map(|&(p, _)| &self.inc[p]);
        let full = net.inhibitors[t]
            .iter()
            .filter(|&&(p, w)| m[p] >= w)
            .map(|&(p, _)| &self.dec[p]);
        if let Some(v) = short.chain(full).min_by_key(|v| v.len()) {
            out.extend(v);
        }
    }

    /// Transitions whose firing can disable `t`: those taking tokens from its input and
    /// read places, and those adding to its inhibitor places.
    pub fn disablers(&self, net: &PtNet, t: usize, out: &mut Vec<usize>) {
        for &(p, _) in net.pre[t].iter().chain(&net.reads[t]) {
            out.extend(&self.dec[p]);
        }
        for &(p, _) in &net.inhibitors[t] {
            out.extend(&self.inc[p]);
        }
    }
}

impl Pred {
    /// Whether marking `m` satisfies the formula.
    pub fn eval(&self, net: &PtNet, m: &[u32]) -> bool {
        match self {
            Pred::True => true,
            Pred::False => false,
            Pred::Not(p) => !p.eval(net, m),
            Pred::And(v) => v.iter().all(|p| p.eval(net, m)),
            Pred::Or(v) => v.iter().any(|p| p.eval(net, m)),
            Pred::Le(a, b) => a.eval(m) <= b.eval(m),
            Pred::Fireable(ts) => ts.iter().any(|&t| net.enabled(m, t)),
            Pred::Deadlock => (0..net.transitions.len()).all(|t| !net.enabled(m, t)),
        }
    }

    /// Adds to `out` transitions of which every firing sequence from `m` that changes the
    /// formula's value to `want` fires at least one (an "up set" when `want` is true):
    /// the formula must have the other value at `m`. Used by the stubborn sets of
    /// [`super::stubborn`].
    pub(crate) fn changers(&self, net: &PtNet, ix: &Index, m: &[u32], want: bool, out: &mut Vec<usize>) {
        let nt = net.transitions.len();
        match self {
            Pred::True | Pred::False => {}
            Pred::Not(p) => p.changers(net, ix, m, !want, out),
            // A conjunction becomes true only when each false conjunct does: one of them.
            // It becomes false when any conjunct does: all of them.
            Pred::And(v) | Pred::Or(v) => {
                let and = matches!(self, Pred::And(_));
                if and == want {
                    // All of these must change: the changers of one that has the other value.
                    if let Some(p) = v.iter().find(|p| p.eval(net, m) != want) {
                        p.changers(net, ix, m, want, out);
                    }
                } else {
                    for p in v.iter().filter(|p| p.eval(net, m) != want) {
                        p.changers(net, ix, m, want, out);
                    }
                }
            }
            Pred::Le(a, b) => {
                // To become true, a must decrease or b increase; to become false, the
                // reverse (every transition changing a place of theirs that way: a
                // superset of those changing a - b that way).
                let (mut pa, mut pb) = (Vec::new(), Vec::new());
                a.places(&mut pa);
                b.places(&mut pb);
                let (down, up) = if want { (&pa, &pb) } else { (&pb, &pa) };
                for &p in down {
                    out.extend(&ix.dec[p]);
                }
                for &p in up {
                    out.extend(&ix.inc[p]);
                }
            }
            Pred::Fireable(ts) => {
                if want {
                    // One of them must become enabled: a reason each is disabled.
                    for &t in ts {
                        ix.scapegoat(net, m, t, out);
                    }
                } else if let Some(&t) = ts.iter().find(|&&t| net.enabled(m, t)) {
                    // All must become disabled, this one too.
                    ix.disablers(net, t, out);
                }
            }
            Pred::Deadlock => {
                if want {
                    if let Some(t) = (0..nt).find(|&t| net.enabled(m, t)) {
                        ix.disablers(net, t, out);
                    }
                } else {
                    for t in 0..nt {
                        ix.scapegoat(net, m, t, out);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn net() -> PtNet {
        let mut n = PtNet::new();
        let a = n.add_place("a", 1);
        let b = n.add_place("b", 0);
        let t = n.add_transition("t");
        n.add_pre(t, a, 1);
        n.add_post(t, b, 1);
        n
    }

    #[test]
    fn reads_the_contest_grammar() {
        let text = r#"<?xml version="1.0"?>
<property-set xmlns="http://mcc.lip6.fr/">
  <property><id>X-00</id><description>d</description><formula>
    <exists-path><finally><conjunction>
      <integer-le><tokens-count><place>a</place><place>b</place></tokens-count><integer-constant>1</integer-constant></integer-le>
      <negation><is-fireable><transition>t</transition></is-fireable></negation>
    </conjunction></finally></exists-path></formula></property>
  <property><id>X-01</id><formula><place-bound><place>b</place></place-bound></formula></property>
</property-set>"#;
        let p = parse(text, &net()).expect("parses");
        assert_eq!(p.len(), 2);
        assert_eq!(p[1].query, Query::Bound(vec![1]));
        let Query::Ef(f) = &p[0].query else {
            panic!("EF expected: {:?}", p[0].query)
        };
        assert!(!f.eval(&net(), &[1, 0]));
        assert!(f.eval(&net(), &[0, 1]));
    }

    #[test]
    fn names_unknown_places_with_their_position() {
        let text = "<property-set>\n<property><id>X</id><formula><place-bound>\n  <place>zz</place></place-bound></formula></property></property-set>";
        let e = parse(text, &net()).expect_err("unknown place");
        assert_eq!((e.line, e.column), (3, 3));
        assert!(e.message.contains("`zz`"), "{e}");
        let e = parse(
            "<property-set><property><id>X</id><formula><eventually/></formula></property></property-set>",
            &net(),
        )
        .expect_err("unknown operator");
        assert!(e.message.contains("<eventually>"), "{e}");
        assert!(parse("<property-set><property>", &net()).is_err());
    }
}
