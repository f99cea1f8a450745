//! Structural reductions of a net before the contest's examinations explore it
//! ([`super::answer`]; docs/nets.md, "Structural reductions"). Each rule keeps the
//! answer of every property asked, and the rules are applied to a fixed point, each to
//! the net the previous ones left (which answers like the original):
//!
//! - **Dead transitions**: a transition needing more tokens in a place than it holds
//!   initially, where no transition ever adds to that place (or inhibited by a place
//!   already full that nothing ever empties), never fires: removed.
//! - **Duplicate transitions**: transitions with the same input, output, read and
//!   inhibitor arcs: one is kept.
//! - **Redundant transitions**: a transition `t` (not named by `is-fireable`) such that
//!   wherever it is enabled another transition `t1` is, with the same effect; or `t1`
//!   then `t2` fire in sequence, their effects adding up to `t`'s. Wherever `t` is
//!   enabled, `t1` is when it needs in each place at most what `t` needs (input or read
//!   arc) and each of its inhibitor arcs has one of `t` at most as heavy on the same
//!   place; `t2` is, after `t1`, when it needs at most `t`'s need plus `t1`'s effect,
//!   and each of its inhibitor arcs `(q, w)` has one of `t`, `(q, w')`, with `w' +
//!   effect(t1, q) ≤ w`. Every firing of `t` can then be replaced by `t1` or `t1 t2`,
//!   which reach the same marking: the reachable markings are the same, and so are the
//!   dead ones (where `t` is enabled, `t1` is too), so every property asked is kept,
//!   deadlocks included; the other transitions keep their enabling.
//! - **Implicit places**: a place that never alone disables a transition: whatever it
//!   holds, when a transition's other arcs allow it to fire, the place does too. Proven
//!   exactly (integers) by a lower bound on its marking: weights `Y_q ≥ 0` on other
//!   places and `D > 0` such that every transition `t` changes `D·p` at least as much
//!   as `Σ Y_q·q` (`D·C[p,t] ≥ Σ Y_q·C[q,t]`), so that `D·m(p) ≥ Σ Y_q·m(q) + b` in
//!   every reachable marking, `b = D·m0(p) − Σ Y_q·m0(q)`; and each transition needing
//!   `p` (input or read arc) needs at most `D·need(t,p) ≤ Σ Y_q·need(t,q) + b`. Where
//!   `t`'s other arcs allow it to fire, `m(q) ≥ need(t,q)`, so (`Y ≥ 0`) `D·m(p) ≥
//!   D·need(t,p)`. The weights come from the initial marking alone (`Y = 0`: no
//!   transition takes more than it gives there), from one place `q` (`Y_q = D = 1`: a
//!   copy of `q` with as many tokens or more), or else from a linear program over the
//!   places sharing a transition with `p` (the implicit-place program of Silva, Teruel
//!   and Colom, 1998, as a feasibility test): rows `Σ y_q·C[q,t] ≤ C[p,t]` for every
//!   transition on `p` or those places, `Σ y_q·(m0(q) − need(t,q)) ≤ m0(p) − need(t,p)`
//!   for every `t` needing `p`, solved exactly by the small rational simplex of
//!   [`super::lp`] (Bland's rule, at most 48 places and 400 rows, tried again for a
//!   place only once one of its transitions changed, all of a reduction's programs
//!   within 5 M tableau-cell updates, given up on any overflow). Whatever found them,
//!   the weights are checked again here in integers before the place is removed. The reachable markings are the original
//!   ones without the place, and every transition is enabled exactly where it was.
//! - **Pre-agglomeration** (Berthelot): a place `p`, initially empty, without read or
//!   inhibitor arcs, filled by the transitions `H` (`w` tokens each) and emptied by `F`
//!   (`w` each), with `|H|·|F| ≤ |H| + |F|` (one of them a single transition, or two
//!   and two: the net does not grow), each `f` of `F` needing nothing but its `w`
//!   tokens of `p` (so it can fire as soon as an `h` has): each `h` and `f` become one
//!   transition `h.f`. Matching each firing of an `f` with an earlier one of an `h`
//!   whose tokens are still in `p` (tokens are alike: first in, first out), moving
//!   every `f` to right after the `h` that fed it keeps a firing sequence one (nothing
//!   inhibits the places `f` fills); tokens left in `p` at the end are moved on by
//!   firing `f`. The places read by a formula must then not be `p` nor ones `f` fills.
//!   A dead marking has `p` empty, so deadlocks are kept too.
//! - **Post-agglomeration** (Berthelot): the same, but each `h` of `H` gives only its
//!   `w` tokens to `p` and has no read or inhibitor arc (so it can wait until the `f`
//!   matched with it fires); tokens left in `p` are given back by not firing their `h`.
//!   The places read by a formula must not be `p` nor ones `h` takes from, and nothing
//!   may inhibit those. Off with a deadlock question (the net may be dead once `h` has
//!   fired and `f` cannot, while in the reduced net `h`'s tokens, still there, keep it
//!   alive).
//!
//! Agglomerations are off when a formula nests `deadlock` (other than EF deadlock
//! itself); nothing a formula reads is removed or fused (its places, the transitions
//! `is-fireable` names and, for agglomerations, the places of their arcs). A trace of
//! the reduced net maps back to the original net by expanding every fused transition
//! into the transitions it stands for, in order ([`Reduction::trace`]); implicit places
//! never block it, and a removed redundant transition is simply not in it.

use super::super::formula::{IntExpr, Pred, Property, Query};
use super::lp;
use crate::PtNet;

/// The linear program of an implicit place: at most this many places in it…
const LP_PLACES: usize = 48;
/// …and this many rows (transitions and needs).
const LP_ROWS: usize = 400;
/// Tableau-cell updates all the linear programs of one reduction may spend.
const LP_BUDGET: u64 = 5_000_000;

/// How a place was found implicit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Implicit {
    No,
    /// By its initial marking or one other place.
    Cheaply,
    /// By several places, with weights from the linear program.
    ByLp,
}

/// How many times each rule was applied.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Applied {
    /// Implicit places removed.
    pub implicit_places: usize,
    /// Of which proven over several places (the linear program).
    pub implicit_places_lp: usize,
    /// Transitions removed as never enabled.
    pub dead_transitions: usize,
    /// Transitions removed as duplicates of another.
    pub duplicate_transitions: usize,
    /// Transitions removed as redundant (another one, or two in sequence, do the same
    /// wherever they are enabled).
    pub redundant_transitions: usize,
    /// Pre-agglomerations (one place each).
    pub pre_agglomerations: usize,
    /// Post-agglomerations (one place each).
    pub post_agglomerations: usize,
}

impl std::ops::AddAssign for Applied {
    fn add_assign(&mut self, o: Applied) {
        self.implicit_places += o.implicit_places;
        self.implicit_places_lp += o.implicit_places_lp;
        self.redundant_transitions += o.redundant_transitions;
        self.dead_transitions += o.dead_transitions;
        self.duplicate_transitions += o.duplicate_transitions;
        self.pre_agglomerations += o.pre_agglomerations;
        self.post_agglomerations += o.post_agglomerations;
    }
}

/// A reduced net and how to translate to and from it.
#[derive(Clone, Debug)]
pub struct Reduction {
    /// The reduced net.
    pub net: PtNet,
    /// Per place of the original net: its number in the reduced one (`usize::MAX`:
    /// removed).
    pub place: Vec<usize>,
    /// Per transition of the original net: its number in the reduced one when it is
    /// there unchanged in its firing (`usize::MAX`: removed or fused).
    pub transition: Vec<usize>,
    /// Per transition of the reduced net: the firing sequence of the original net it
    /// stands for.
    pub expand: Vec<Vec<usize>>,
    /// The rules applied.
    pub applied: Applied,
}

impl Reduction {
    /// Places removed.
    pub fn places_removed(&self) -> usize {
        self.place.len() - self.net.places.len()
    }

    /// Transitions removed (a fusion of two counts one).
    pub fn transitions_removed(&self) -> usize {
        self.transition.len() - self.net.transitions.len()
    }

    /// The properties over the reduced net's numbers (everything they read is kept).
    pub fn properties(&self, props: &[Property]) -> Vec<Property> {
        props
            .iter()
            .map(|p| Property {
                id: p.id.clone(),
                query: match &p.query {
                    Query::Ef(f) => Query::Ef(f.map(&self.place, &self.transition)),
                    Query::Ag(f) => Query::Ag(f.map(&self.place, &self.transition)),
                    Query::Bound(ps) => Query::Bound(ps.iter().map(|&q| self.place[q]).collect()),
                },
            })
            .collect()
    }

    /// A firing sequence of the reduced net as one of the original net.
    pub fn trace(&self, trace: &[usize]) -> Vec<usize> {
        trace.iter().flat_map(|&t| self.expand[t].iter().copied()).collect()
    }
}

/// What the properties forbid touching.
struct Keep {
    /// Places whose marking a formula reads.
    read: Vec<bool>,
    /// `read`, and the places of the arcs of the transitions `is-fireable` names.
    touched: Vec<bool>,
    /// Transitions `is-fireable` names.
    named: Vec<bool>,
    /// Agglomerations allowed (no `deadlock` nested in a formula).
    agglomerate: bool,
    /// Post-agglomerations allowed (no deadlock question at all).
    post: bool,
}

fn int_places(e: &IntExpr, out: &mut Vec<usize>) {
    match e {
        IntExpr::Const(_) => {}
        IntExpr::Tokens(ps) => out.extend(ps),
        IntExpr::Sum(v) => v.iter().for_each(|e| int_places(e, out)),
    }
}

/// The places and transitions `f` reads; whether it says `deadlock`.
fn pred_support(f: &Pred, places: &mut Vec<usize>, transitions: &mut Vec<usize>) -> bool {
    match f {
        Pred::True | Pred::False => false,
        Pred::Deadlock => true,
        Pred::Not(p) => pred_support(p, places, transitions),
        Pred::And(v) | Pred::Or(v) => v.iter().fold(false, |d, p| pred_support(p, places, transitions) | d),
        Pred::Le(a, b) => {
            int_places(a, places);
            int_places(b, places);
            false
        }
        Pred::Fireable(ts) => {
            transitions.extend(ts);
            false
        }
    }
}

fn keep(net: &PtNet, props: &[Property]) -> Keep {
    let mut k = Keep {
        read: vec![false; net.places.len()],
        touched: vec![false; net.places.len()],
        named: vec![false; net.transitions.len()],
        agglomerate: true,
        post: true,
    };
    let (mut places, mut transitions) = (Vec::new(), Vec::new());
    for p in props {
        match &p.query {
            Query::Bound(ps) => places.extend(ps),
            Query::Ef(Pred::Deadlock) => k.post = false,
            Query::Ag(Pred::Not(d)) if **d == Pred::Deadlock => k.post = false,
            Query::Ef(f) | Query::Ag(f) => {
                if pred_support(f, &mut places, &mut transitions) {
                    k.agglomerate = false;
                    k.post = false;
                }
            }
        }
    }
    for p in places {
        k.read[p] = true;
        k.touched[p] = true;
    }
    for t in transitions {
        k.named[t] = true;
        for &(p, _) in net.pre[t]
            .iter()
            .chain(&net.post[t])
            .chain(&net.reads[t])
            .chain(&net.inhibitors[t])
        {
            k.touched[p] = true;
        }
    }
    k
}

fn weight(arcs: &[(usize, u32)], p: usize) -> u32 {
    arcs.iter().find(|a| a.0 == p).map_or(0, |a| a.1)
}

fn has(arcs: &[(usize, u32)], p: usize) -> bool {
    arcs.iter().any(|a| a.0 == p)
}

/// The net being reduced: places and transitions keep their numbers; removed ones are
/// marked dead and lose their arcs.
struct Work {
    net: PtNet,
    place_alive: Vec<bool>,
    alive: Vec<bool>,
    expand: Vec<Vec<usize>>,
    /// Per place: the transitions that have (or once had) an arc on it.
    col: Vec<Vec<usize>>,
    applied: Applied,
    /// What the implicit places' linear programs may still spend.
    lp_budget: u64,
    /// Per place: a linear program was tried and nothing on its transitions has
    /// changed since (a transition removed or fused).
    lp_tried: Vec<bool>,
}

impl Work {
    fn new(net: &PtNet) -> Work {
        let mut col = vec![Vec::new(); net.places.len()];
        for t in 0..net.transitions.len() {
            for &(p, _) in net.pre[t]
                .iter()
                .chain(&net.post[t])
                .chain(&net.reads[t])
                .chain(&net.inhibitors[t])
            {
                col[p].push(t);
            }
        }
        Work {
            net: net.clone(),
            place_alive: vec![true; net.places.len()],
            alive: vec![true; net.transitions.len()],
            expand: (0..net.transitions.len()).map(|t| vec![t]).collect(),
            col,
            applied: Applied::default(),
            lp_budget: LP_BUDGET,
            lp_tried: vec![false; net.places.len()],
        }
    }

    fn has_arc(&self, t: usize, p: usize) -> bool {
        let n = &self.net;
        [&n.pre[t], &n.post[t], &n.reads[t], &n.inhibitors[t]]
            .iter()
            .any(|arcs| arcs.iter().any(|a| a.0 == p))
    }

    /// The live transitions with an arc on `p`, in order.
    fn touching(&self, p: usize) -> Vec<usize> {
        let mut v: Vec<usize> = self.col[p]
            .iter()
            .copied()
            .filter(|&t| self.alive[t] && self.has_arc(t, p))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Tokens `t` needs in `p` (input or read arc).
    fn need(&self, t: usize, p: usize) -> u32 {
        weight(&self.net.pre[t], p).max(weight(&self.net.reads[t], p))
    }

    /// What firing `t` does to `p`.
    fn effect(&self, t: usize, p: usize) -> i64 {
        i64::from(weight(&self.net.post[t], p)) - i64::from(weight(&self.net.pre[t], p))
    }

    fn inhibited(&self, p: usize) -> bool {
        self.touching(p).iter().any(|&t| has(&self.net.inhibitors[t], p))
    }

    fn remove_place(&mut self, p: usize) {
        for t in self.touching(p) {
            let n = &mut self.net;
            for arcs in [&mut n.pre[t], &mut n.post[t], &mut n.reads[t], &mut n.inhibitors[t]] {
                arcs.retain(|a| a.0 != p);
            }
        }
        self.place_alive[p] = false;
    }

    fn remove_transition(&mut self, t: usize) {
        self.alive[t] = false;
        let n = &mut self.net;
        for arcs in [&mut n.pre[t], &mut n.post[t], &mut n.reads[t], &mut n.inhibitors[t]] {
            for &(q, _) in arcs.iter() {
                self.lp_tried[q] = false;
            }
            arcs.clear();
        }
    }

    /// Transitions never enabled: a place never filled holds too few tokens for them, or
    /// one never emptied holds too many for their inhibitor arc.
    fn dead_transitions(&mut self, keep: &Keep) -> bool {
        let mut changed = false;
        for p in 0..self.net.places.len() {
            if !self.place_alive[p] {
                continue;
            }
            let ts = self.touching(p);
            let m0 = self.net.initial[p];
            let never_up = ts.iter().all(|&t| self.effect(t, p) <= 0);
            let never_down = ts.iter().all(|&t| self.effect(t, p) >= 0);
            for &t in &ts {
                let short = never_up && self.need(t, p) > m0;
                let w = weight(&self.net.inhibitors[t], p);
                let full = never_down && w > 0 && m0 >= w;
                if !keep.named[t] && self.alive[t] && (short || full) {
                    self.remove_transition(t);
                    self.applied.dead_transitions += 1;
                    changed = true;
                }
            }
        }
        changed
    }

    /// Transitions with the same arcs as another: one kept (a named one if any; named
    /// ones are all kept).
    fn duplicate_transitions(&mut self, keep: &Keep) -> bool {
        let mut groups: std::collections::HashMap<[Vec<(usize, u32)>; 4], Vec<usize>> = Default::default();
        for t in (0..self.net.transitions.len()).filter(|&t| self.alive[t]) {
            let n = &self.net;
            let mut key = [
                n.pre[t].clone(),
                n.post[t].clone(),
                n.reads[t].clone(),
                n.inhibitors[t].clone(),
            ];
            key.iter_mut().for_each(|v| v.sort_unstable());
            groups.entry(key).or_default().push(t);
        }
        let mut changed = false;
        let mut groups: Vec<Vec<usize>> = groups.into_values().filter(|g| g.len() > 1).collect();
        groups.sort_unstable();
        for g in groups {
            let kept = g.iter().copied().find(|&t| keep.named[t]).unwrap_or(g[0]);
            for t in g {
                if t != kept && !keep.named[t] {
                    self.remove_transition(t);
                    self.applied.duplicate_transitions += 1;
                    changed = true;
                }
            }
        }
        changed
    }

    /// `t`'s effect, place by place (sorted, no zeros).
    fn effects(&self, t: usize) -> Vec<(usize, i64)> {
        let n = &self.net;
        let mut v: Vec<(usize, i64)> = n.pre[t]
            .iter()
            .chain(&n.post[t])
            .map(|&(q, _)| (q, self.effect(t, q)))
            .filter(|&(_, e)| e != 0)
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Whether `u` is enabled wherever `t` is, once `before` (an effect) has been
    /// added: it needs at most `t`'s needs plus `before`, and each of its inhibitor
    /// arcs is implied by one of `t`'s.
    fn follows(&self, t: usize, u: usize, before: &[(usize, i64)]) -> bool {
        let n = &self.net;
        let shift = |q: usize| before.iter().find(|e| e.0 == q).map_or(0, |e| e.1);
        n.pre[u]
            .iter()
            .chain(&n.reads[u])
            .all(|&(q, w)| i64::from(w) <= i64::from(self.need(t, q)) + shift(q))
            && n.inhibitors[u].iter().all(|&(q, w)| {
                // m(q) < w_t, so m(q) + shift < w_t + shift ≤ w.
                let wt = weight(&n.inhibitors[t], q);
                wt > 0 && i64::from(wt) + shift(q) <= i64::from(w)
            })
    }

    /// Transitions another does the same as wherever they are enabled (`t1`, enabled
    /// wherever `t` is, with `t`'s effect), or two in sequence (`t1` then `t2`, the
    /// second enabled after the first wherever `t` is, with `t`'s effect together):
    /// removed unless a formula names them (see the module's text).
    fn redundant_transitions(&mut self, keep: &Keep) -> bool {
        let nt = self.net.transitions.len();
        let effects: Vec<Vec<(usize, i64)>> = (0..nt)
            .map(|t| if self.alive[t] { self.effects(t) } else { Vec::new() })
            .collect();
        let mut by_effect: std::collections::HashMap<&[(usize, i64)], Vec<usize>> = Default::default();
        for t in (0..nt).filter(|&t| self.alive[t]) {
            by_effect.entry(&effects[t]).or_default().push(t);
        }
        let needless: Vec<usize> = (0..nt)
            .filter(|&t| self.alive[t] && self.net.pre[t].is_empty() && self.net.reads[t].is_empty())
            .collect();
        let mut changed = false;
        for t in 0..nt {
            if !self.alive[t] || keep.named[t] {
                continue;
            }
            let n = &self.net;
            // t1 needs nothing t does not: it has an arc on one of t's needs, or none.
            let mut firsts: Vec<usize> = n.pre[t]
                .iter()
                .chain(&n.reads[t])
                .flat_map(|&(q, _)| self.col[q].iter().copied())
                .chain(needless.iter().copied())
                .filter(|&u| u != t && self.alive[u])
                .collect();
            firsts.sort_unstable();
            firsts.dedup();
            let found = firsts.into_iter().any(|t1| {
                if !self.follows(t, t1, &[]) {
                    return false;
                }
                if effects[t1] == effects[t] {
                    return true;
                }
                let mut rest = effects[t].clone();
                for &(q, e) in &effects[t1] {
                    match rest.iter_mut().find(|r| r.0 == q) {
                        Some(r) => r.1 -= e,
                        None => rest.push((q, -e)),
                    }
                }
                rest.retain(|r| r.1 != 0);
                rest.sort_unstable();
                by_effect.get(rest.as_slice()).is_some_and(|seconds| {
                    seconds
                        .iter()
                        .any(|&t2| t2 != t && self.alive[t2] && self.follows(t, t2, &effects[t1]))
                })
            });
            if found {
                // Removed at once: the next ones are proven without it.
                self.remove_transition(t);
                self.applied.redundant_transitions += 1;
                changed = true;
            }
        }
        changed
    }

    /// Whether `D·m(p) − Σ Y_q·m(q)` never decreases (`D > 0`, every `Y_q ≥ 0`, `q ≠ p`)
    /// and bounds `D·m(p)` enough for every transition needing `p`: when its other
    /// arcs allow it to fire, so does `p` (see the module's text). The proof every
    /// implicit place is removed on, checked exactly whatever found the weights.
    fn implied_by(&self, p: usize, ys: &[(usize, i128)], d: i128) -> bool {
        if d <= 0 || ys.iter().any(|&(q, y)| q == p || y < 0 || !self.place_alive[q]) {
            return false;
        }
        let ts = self.touching(p);
        if ts.iter().any(|&t| has(&self.net.inhibitors[t], p)) {
            return false;
        }
        let mut all = ts.clone();
        for &(q, _) in ys {
            all.extend(self.touching(q));
        }
        all.sort_unstable();
        all.dedup();
        let combo = |f: &dyn Fn(usize) -> i64| -> Option<i128> {
            ys.iter()
                .try_fold(0i128, |s, &(q, y)| s.checked_add(y.checked_mul(i128::from(f(q)))?))
        };
        let grows = all.iter().all(|&t| {
            let rhs = combo(&|q| self.effect(t, q));
            let lhs = d.checked_mul(i128::from(self.effect(t, p)));
            matches!((lhs, rhs), (Some(l), Some(r)) if l >= r)
        });
        // D·m(p) ≥ Σ Y_q·m(q) + b, b = D·m0(p) − Σ Y_q·m0(q).
        let Some(b) = combo(&|q| i64::from(self.net.initial[q]))
            .and_then(|s| d.checked_mul(i128::from(self.net.initial[p]))?.checked_sub(s))
        else {
            return false;
        };
        grows
            && ts.iter().all(|&t| {
                let need = i128::from(self.need(t, p));
                let rhs = combo(&|q| i64::from(self.need(t, q))).and_then(|s| s.checked_add(b));
                need == 0 || matches!((d.checked_mul(need), rhs), (Some(l), Some(r)) if l <= r)
            })
    }

    /// Whether `p` never alone disables a transition (see the module's text): proven by
    /// its initial marking, by one other place, or by weights over several places that
    /// a linear program finds.
    fn implicit(&mut self, p: usize) -> Implicit {
        let ts = self.touching(p);
        if ts.iter().any(|&t| has(&self.net.inhibitors[t], p)) {
            return Implicit::No;
        }
        let Some(&t0) = ts.iter().find(|&&t| self.need(t, p) > 0) else {
            return Implicit::Cheaply;
        };
        if self.implied_by(p, &[], 1) {
            return Implicit::Cheaply;
        }
        let n = &self.net;
        let candidates: Vec<usize> = n.pre[t0].iter().chain(&n.reads[t0]).map(|&(q, _)| q).collect();
        if candidates.iter().any(|&q| q != p && self.implied_by(p, &[(q, 1)], 1)) {
            return Implicit::Cheaply;
        }
        match self.lp_weights(p, &ts) {
            Some((ys, d)) if self.implied_by(p, &ys, d) => Implicit::ByLp,
            _ => Implicit::No,
        }
    }

    /// Weights `Y / D` over the places sharing a transition with `p` proving it
    /// implicit, from the linear program of the module's text; `None` when it has none,
    /// when it is too big or when the budget is spent.
    fn lp_weights(&mut self, p: usize, ts: &[usize]) -> Option<(Vec<(usize, i128)>, i128)> {
        if std::mem::replace(&mut self.lp_tried[p], true) {
            return None;
        }
        let n = &self.net;
        let mut qs: Vec<usize> = ts
            .iter()
            .flat_map(|&t| n.pre[t].iter().chain(&n.post[t]).chain(&n.reads[t]))
            .map(|&(q, _)| q)
            .filter(|&q| q != p && self.place_alive[q])
            .collect();
        qs.sort_unstable();
        qs.dedup();
        if qs.is_empty() || qs.len() > LP_PLACES {
            return None;
        }
        // A row of ts with c < 0 and no negative coefficient has no solution (checked
        // before the places' other transitions are gathered).
        let hopeless = |c: i64, coef: &dyn Fn(usize) -> i64| c < 0 && qs.iter().all(|&q| coef(q) >= 0);
        let m0 = |q: usize| i64::from(self.net.initial[q]);
        if ts.iter().any(|&t| {
            let need = i64::from(self.need(t, p));
            hopeless(self.effect(t, p), &|q| self.effect(t, q))
                || (need > 0 && hopeless(m0(p) - need, &|q| m0(q) - i64::from(self.need(t, q))))
        }) {
            return None;
        }
        let mut rel: Vec<usize> = ts.to_vec();
        for &q in &qs {
            rel.extend(self.touching(q));
        }
        rel.sort_unstable();
        rel.dedup();
        // Rows a·y ≤ c: every transition changes p at least as much as Σ y_q·q; each
        // need of p is at most Σ y_q·need(q) + m0(p) − Σ y_q·m0(q).
        let (mut a, mut c) = (Vec::new(), Vec::new());
        for &t in &rel {
            a.push(qs.iter().map(|&q| self.effect(t, q)).collect::<Vec<i64>>());
            c.push(self.effect(t, p));
        }
        for &t in ts {
            let need = i64::from(self.need(t, p));
            if need > 0 {
                a.push(qs.iter().map(|&q| m0(q) - i64::from(self.need(t, q))).collect());
                c.push(m0(p) - need);
            }
        }
        // Rows 0 ≤ c hold: dropped; 0 ≤ c < 0 cannot.
        let mut rows = Vec::new();
        for (r, ci) in a.into_iter().zip(c) {
            if r.iter().all(|&x| x == 0) {
                if ci < 0 {
                    return None;
                }
            } else {
                rows.push((r, ci));
            }
        }
        if rows.len() > LP_ROWS {
            return None;
        }
        let (a, c): (Vec<Vec<i64>>, Vec<i64>) = rows.into_iter().unzip();
        let (y, d) = lp::feasible(&a, &c, &mut self.lp_budget)?;
        Some((qs.into_iter().zip(y).filter(|&(_, y)| y > 0).collect(), d))
    }

    fn implicit_places(&mut self, keep: &Keep) -> bool {
        let mut changed = false;
        for p in 0..self.net.places.len() {
            if !self.place_alive[p] || keep.read[p] {
                continue;
            }
            let how = self.implicit(p);
            if how != Implicit::No {
                self.remove_place(p);
                self.applied.implicit_places += 1;
                self.applied.implicit_places_lp += usize::from(how == Implicit::ByLp);
                changed = true;
            }
        }
        changed
    }

    /// `h` then `f` as one transition: a net of one transition over the same places,
    /// its name and the original transitions it stands for.
    fn fused(&self, h: usize, f: usize, p: usize) -> (PtNet, String, Vec<usize>) {
        let n = &self.net;
        let mut fused = PtNet::new();
        fused.add_transition("");
        for &(q, w) in n.pre[h].iter().chain(n.pre[f].iter().filter(|a| a.0 != p)) {
            fused.add_pre(0, q, w);
        }
        for &(q, w) in n.post[h].iter().filter(|a| a.0 != p).chain(&n.post[f]) {
            fused.add_post(0, q, w);
        }
        // f's conditions hold after h has taken its inputs (h gives only to p, or f
        // has no read and inhibitor arcs).
        for &(q, w) in &n.reads[h] {
            fused.add_read(0, q, w);
        }
        for &(q, w) in &n.reads[f] {
            fused.add_read(0, q, w.saturating_add(weight(&n.pre[h], q)));
        }
        for &(q, w) in n.inhibitors[h].iter().chain(&n.inhibitors[f]) {
            fused.add_inhibitor(0, q, w);
        }
        let name = format!("{}.{}", n.transitions[h], n.transitions[f]);
        let expand = [self.expand[h].clone(), self.expand[f].clone()].concat();
        (fused, name, expand)
    }

    /// A transition from [`Work::fused`] in slot `into`.
    fn put(&mut self, into: usize, (mut fused, name, expand): (PtNet, String, Vec<usize>)) {
        for arcs in [&fused.pre[0], &fused.post[0], &fused.reads[0], &fused.inhibitors[0]] {
            for &(q, _) in arcs {
                self.col[q].push(into);
                self.lp_tried[q] = false;
            }
        }
        let n = &mut self.net;
        n.transitions[into] = name;
        n.pre[into] = std::mem::take(&mut fused.pre[0]);
        n.post[into] = std::mem::take(&mut fused.post[0]);
        n.reads[into] = std::mem::take(&mut fused.reads[0]);
        n.inhibitors[into] = std::mem::take(&mut fused.inhibitors[0]);
        self.expand[into] = expand;
    }

    /// One agglomeration through `p` when a rule allows it.
    fn agglomerate(&mut self, p: usize, keep: &Keep) -> bool {
        let n = &self.net;
        if keep.touched[p] || n.initial[p] != 0 {
            return false;
        }
        let ts = self.touching(p);
        if ts
            .iter()
            .any(|&t| keep.named[t] || has(&n.reads[t], p) || has(&n.inhibitors[t], p))
        {
            return false;
        }
        let h: Vec<usize> = ts.iter().copied().filter(|&t| weight(&n.post[t], p) > 0).collect();
        let f: Vec<usize> = ts.iter().copied().filter(|&t| weight(&n.pre[t], p) > 0).collect();
        // The net must not grow: |H|·|F| fused transitions replace |H| + |F|.
        let grows = h.len() * f.len() > h.len() + f.len();
        if h.is_empty() || f.is_empty() || grows || h.iter().any(|t| f.contains(t)) {
            return false;
        }
        let w = weight(&n.pre[f[0]], p);
        if f.iter().any(|&t| weight(&n.pre[t], p) != w) || h.iter().any(|&t| weight(&n.post[t], p) != w) {
            return false;
        }
        // Pre: each f needs only p; nothing reads the places it fills, nothing inhibits them.
        let pre = f.iter().all(|&t| {
            n.pre[t].len() == 1
                && n.reads[t].is_empty()
                && n.inhibitors[t].is_empty()
                && n.post[t].iter().all(|&(q, _)| !keep.touched[q] && !self.inhibited(q))
        });
        // Post: each h only gives p, without read or inhibitor arcs; nothing reads the
        // places it takes from, nothing inhibits them.
        let post = !pre
            && keep.post
            && h.iter().all(|&t| {
                n.post[t].len() == 1
                    && n.reads[t].is_empty()
                    && n.inhibitors[t].is_empty()
                    && n.pre[t].iter().all(|&(q, _)| !keep.touched[q] && !self.inhibited(q))
            });
        if !pre && !post {
            return false;
        }
        // Every h.f, computed before any slot is overwritten; in the slots of H (one f),
        // of F (one h), or of both (two and two).
        let pairs: Vec<_> = h
            .iter()
            .flat_map(|&a| f.iter().map(move |&b| (a, b)))
            .map(|(a, b)| self.fused(a, b, p))
            .collect();
        let slots = match (h.len(), f.len()) {
            (_, 1) => [h, f].concat(),
            (1, _) => [f, h].concat(),
            _ => [h, f].concat(),
        };
        for &slot in &slots[pairs.len()..] {
            self.remove_transition(slot);
        }
        for (slot, t) in slots.into_iter().zip(pairs) {
            self.put(slot, t);
        }
        self.remove_place(p);
        if pre {
            self.applied.pre_agglomerations += 1;
        } else {
            self.applied.post_agglomerations += 1;
        }
        true
    }

    fn agglomerations(&mut self, keep: &Keep) -> bool {
        let mut changed = false;
        for p in 0..self.net.places.len() {
            if self.place_alive[p] && self.agglomerate(p, keep) {
                changed = true;
            }
        }
        changed
    }

    fn finish(self, original: &PtNet) -> Reduction {
        let mut r = Reduction {
            net: PtNet::new(),
            place: vec![usize::MAX; original.places.len()],
            transition: vec![usize::MAX; original.transitions.len()],
            expand: Vec::new(),
            applied: self.applied,
        };
        for p in (0..self.net.places.len()).filter(|&p| self.place_alive[p]) {
            r.place[p] = r.net.add_place(&self.net.places[p], self.net.initial[p]);
        }
        for t in (0..self.net.transitions.len()).filter(|&t| self.alive[t]) {
            let u = r.net.add_transition(&self.net.transitions[t]);
            if self.expand[t] == [t] {
                r.transition[t] = u;
            }
            for &(p, w) in &self.net.pre[t] {
                r.net.add_pre(u, r.place[p], w);
            }
            for &(p, w) in &self.net.post[t] {
                r.net.add_post(u, r.place[p], w);
            }
            for &(p, w) in &self.net.reads[t] {
                r.net.add_read(u, r.place[p], w);
            }
            for &(p, w) in &self.net.inhibitors[t] {
                r.net.add_inhibitor(u, r.place[p], w);
            }
            r.expand.push(self.expand[t].clone());
        }
        r
    }
}

/// The net reduced for these properties (the rules of the module's text, to a fixed
/// point); `None` when no rule applies.
pub fn reduce(net: &PtNet, props: &[Property]) -> Option<Reduction> {
    let keep = keep(net, props);
    let mut w = Work::new(net);
    loop {
        let mut changed = w.dead_transitions(&keep);
        changed |= w.duplicate_transitions(&keep);
        changed |= w.redundant_transitions(&keep);
        changed |= w.implicit_places(&keep);
        if keep.agglomerate {
            changed |= w.agglomerations(&keep);
        }
        if !changed {
            break;
        }
    }
    (w.applied != Applied::default()).then(|| w.finish(net))
}

#[cfg(test)]
mod tests {
    use super::super::{CheckOptions, Verdict, answer, check};
    use super::*;
    use crate::analysis::Control;
    use crate::analysis::formula::deadlock_property;

    fn le(places: Vec<usize>, c: u64) -> Pred {
        Pred::Le(IntExpr::Tokens(places), IntExpr::Const(c))
    }

    fn ef(f: Pred) -> Property {
        Property {
            id: "ef".into(),
            query: Query::Ef(f),
        }
    }

    /// The answers with the reductions equal the full exploration's, and every trace
    /// replays in the original net to a marking showing the verdict.
    fn same_answers(net: &PtNet, props: &[Property]) {
        let full = CheckOptions {
            stubborn: false,
            slice: false,
            reduce: false,
            ..CheckOptions::default()
        };
        let want = check(net, props, &full, &Control::none()).answers;
        let only = CheckOptions {
            slice: false,
            ..CheckOptions::default()
        };
        let have = answer(net, props, &only, &Control::none());
        for ((p, a), b) in props.iter().zip(&want).zip(&have) {
            assert_eq!(a.verdict, b.verdict, "{}: {:?}", p.id, p.query);
            if let (Some(trace), Query::Ef(f) | Query::Ag(f)) = (&b.trace, &p.query) {
                let mut m = net.initial.clone();
                for &t in trace {
                    assert!(net.enabled(&m, t), "{} in {trace:?}", net.transitions[t]);
                    m = net.fire(&m, t).expect("fires");
                }
                assert_eq!(f.eval(net, &m), b.verdict == Verdict::True);
            }
        }
    }

    /// `a -h-> p -f-> b`, one token in `a`.
    fn chain() -> PtNet {
        let mut net = PtNet::new();
        let a = net.add_place("a", 1);
        let p = net.add_place("p", 0);
        let b = net.add_place("b", 0);
        let h = net.add_transition("h");
        net.add_pre(h, a, 1);
        net.add_post(h, p, 1);
        let f = net.add_transition("f");
        net.add_pre(f, p, 1);
        net.add_post(f, b, 1);
        net
    }

    #[test]
    fn a_copy_of_a_place_with_more_tokens_is_implicit() {
        // Two processes share a mutex `m`; `m2` is m's copy with one token more.
        let mut net = PtNet::new();
        let m = net.add_place("m", 1);
        let m2 = net.add_place("m2", 2);
        let mut busy = Vec::new();
        for i in 0..2 {
            let idle = net.add_place(&format!("idle{i}"), 1);
            let b = net.add_place(&format!("busy{i}"), 0);
            let enter = net.add_transition(&format!("enter{i}"));
            net.add_pre(enter, idle, 1);
            net.add_pre(enter, m, 1);
            net.add_pre(enter, m2, 1);
            net.add_post(enter, b, 1);
            let leave = net.add_transition(&format!("leave{i}"));
            net.add_pre(leave, b, 1);
            net.add_post(leave, idle, 1);
            net.add_post(leave, m, 1);
            net.add_post(leave, m2, 1);
            busy.push(b);
        }
        let both = ef(Pred::Not(Box::new(le(busy.clone(), 1))));
        let r = reduce(&net, std::slice::from_ref(&both)).expect("reduced");
        assert_eq!(r.place[m2], usize::MAX, "m2 implied by m");
        assert_ne!(r.place[m], usize::MAX);
        assert_eq!(r.applied.implicit_places, 1);
        same_answers(&net, &[both.clone(), deadlock_property()]);
        // Read by a formula: kept. With as many tokens as m, one of the two goes.
        let reads = ef(le(vec![m2], 0));
        assert!(reduce(&net, std::slice::from_ref(&reads)).is_none_or(|r| r.place[m2] != usize::MAX));
        // With fewer tokens than m, m2 is the one that blocks: m goes, m2 stays.
        let mut fewer = net.clone();
        fewer.initial[m2] = 0;
        let r = reduce(&fewer, std::slice::from_ref(&both)).expect("reduced");
        assert_ne!(r.place[m2], usize::MAX);
        assert_eq!(r.place[m], usize::MAX);
        same_answers(&fewer, &[both.clone(), deadlock_property()]);
        // An inhibitor arc on it: kept.
        let mut inhibited = net.clone();
        let t = inhibited.add_transition("watch");
        inhibited.add_inhibitor(t, m2, 1);
        let r = reduce(&inhibited, std::slice::from_ref(&both));
        assert!(r.is_none_or(|r| r.place[m2] != usize::MAX));
        same_answers(&inhibited, &[both, deadlock_property()]);
    }

    /// A token cycling `a -t1-> b -t2-> c -t3-> a`; `p`, filled by t1 and emptied by t3,
    /// holds `b + c`: t3 needs `c` and `p`. No single place implies `p` (it changes as
    /// `b + c`); the two do. A formula reads a, b and c (no agglomeration).
    fn cycle_with_a_sum_place() -> (PtNet, usize, Property) {
        let mut net = PtNet::new();
        let a = net.add_place("a", 1);
        let b = net.add_place("b", 0);
        let c = net.add_place("c", 0);
        let p = net.add_place("p", 0);
        for (name, from, to) in [("t1", a, b), ("t2", b, c), ("t3", c, a)] {
            let t = net.add_transition(name);
            net.add_pre(t, from, 1);
            net.add_post(t, to, 1);
        }
        net.add_post(0, p, 1);
        net.add_pre(2, p, 1);
        (net, p, ef(le(vec![a, b, c], 0)))
    }

    fn removed(net: &PtNet, props: &[Property], p: usize) -> bool {
        reduce(net, props).is_some_and(|r| r.place[p] == usize::MAX)
    }

    #[test]
    fn a_place_implied_by_a_sum_of_places_is_removed_by_the_linear_program() {
        let (net, p, f) = cycle_with_a_sum_place();
        let props = [f.clone(), deadlock_property()];
        let r = reduce(&net, &props).expect("reduced");
        assert_eq!(r.place[p], usize::MAX);
        assert_eq!((r.applied.implicit_places, r.applied.implicit_places_lp), (1, 1));
        same_answers(&net, &props);
        // A formula reads p: kept.
        let reads = [ef(le(vec![p], 0))];
        assert!(!removed(&net, &reads, p));
        // An inhibitor arc on p: kept.
        let mut inhibited = net.clone();
        let t = inhibited.add_transition("watch");
        inhibited.add_inhibitor(t, p, 1);
        assert!(!removed(&inhibited, std::slice::from_ref(&f), p));
        same_answers(&inhibited, &[f.clone(), deadlock_property()]);
        // The budget spent: kept.
        let mut w = Work::new(&net);
        w.lp_budget = 0;
        assert_eq!(w.implicit(p), Implicit::No);
        assert_eq!(Work::new(&net).implicit(p), Implicit::ByLp);
    }

    #[test]
    fn the_proof_refuses_negative_weights_and_a_zero_denominator() {
        // t: p -> q, u: q -> p, q holds the token: p blocks t at first. With y_q = -1,
        // m(p) - (-1)·m(q) = m(p) + m(q) never changes and would "prove" p; so would
        // D = 0.
        let mut net = PtNet::new();
        let (p, q) = (net.add_place("p", 0), net.add_place("q", 1));
        let t = net.add_transition("t");
        net.add_pre(t, p, 1);
        net.add_post(t, q, 1);
        let u = net.add_transition("u");
        net.add_pre(u, q, 1);
        net.add_post(u, p, 1);
        let w = Work::new(&net);
        assert!(!w.implied_by(p, &[(q, -1)], 1));
        assert!(!w.implied_by(p, &[], 0));
        assert!(!w.implied_by(p, &[(q, 1)], 1));
        assert_eq!(Work::new(&net).implicit(p), Implicit::No);
    }

    #[test]
    fn the_linear_program_refuses_each_broken_side_condition() {
        let (net, p, f) = cycle_with_a_sum_place();
        let (a, b, c) = (0, 1, 2);
        // p changes less than b + c: a transition empties it alone (t3 then blocked).
        let mut leaks = net.clone();
        let t = leaks.add_transition("leak");
        leaks.add_pre(t, p, 1);
        // p holds b + c − 1 (the token starts in b): t3 blocked, a never refilled.
        let mut short = net.clone();
        short.initial[a] = 0;
        short.initial[b] = 1;
        // t3 needs 2 of p (one token only).
        let mut heavy = net.clone();
        heavy.pre[2].retain(|&(q, _)| q != p);
        heavy.add_pre(2, p, 2);
        heavy.initial[a] = 2;
        // A transition reads 2 of p but needs only 1 of c.
        let mut reads = net.clone();
        let watch = reads.add_transition("watch");
        reads.add_read(watch, p, 2);
        reads.add_read(watch, c, 1);
        let refilled = ef(Pred::Not(Box::new(le(vec![a], 0))));
        for (what, net, props) in [
            ("leak", leaks, vec![f.clone(), refilled.clone(), deadlock_property()]),
            ("short", short, vec![f.clone(), refilled.clone(), deadlock_property()]),
            ("heavy", heavy, vec![f.clone(), refilled, deadlock_property()]),
            ("reads", reads, vec![f.clone(), ef(Pred::Fireable(vec![watch]))]),
        ] {
            assert!(!removed(&net, &props, p), "{what}");
            same_answers(&net, &props);
        }
    }

    #[test]
    fn a_transition_doing_what_two_others_do_in_sequence_is_redundant() {
        // a -t1-> b -t2-> c, and t: a -> c. A formula reads a, b and c.
        let mut net = PtNet::new();
        let (a, b, c) = (net.add_place("a", 1), net.add_place("b", 0), net.add_place("c", 0));
        for (name, from, to) in [("t1", a, b), ("t2", b, c), ("t", a, c)] {
            let t = net.add_transition(name);
            net.add_pre(t, from, 1);
            net.add_post(t, to, 1);
        }
        let f = ef(Pred::And(vec![le(vec![a, b], 0), le(vec![c], 0)]));
        let props = [f.clone(), deadlock_property()];
        let r = reduce(&net, &props).expect("reduced");
        assert_eq!(r.applied.redundant_transitions, 1);
        assert_eq!(r.transition[2], usize::MAX);
        same_answers(&net, &props);
        // Named by is-fireable: kept.
        let named = [ef(Pred::Fireable(vec![2])), f.clone()];
        assert!(reduce(&net, &named).is_none_or(|r| r.transition[2] != usize::MAX));
        same_answers(&net, &named);
        // t gives one more token to c: not the same effect.
        let mut more = net.clone();
        more.post[2][0].1 = 2;
        let two = [ef(Pred::Not(Box::new(le(vec![c], 1))))];
        assert!(reduce(&more, &two).is_none_or(|r| r.transition[2] != usize::MAX));
        same_answers(&more, &two);
        // t1 also reads d, filled later by g: t can fire where t1 cannot.
        let mut reads = net.clone();
        let (d, e) = (reads.add_place("d", 0), reads.add_place("e", 1));
        reads.add_read(0, d, 1);
        let g = reads.add_transition("g");
        reads.add_pre(g, e, 1);
        reads.add_post(g, d, 1);
        let early = [ef(Pred::And(vec![
            le(vec![a, b, d], 0),
            Pred::Not(Box::new(le(vec![c], 0))),
        ]))];
        assert!(reduce(&reads, &early).is_none_or(|r| r.transition[2] != usize::MAX));
        same_answers(&reads, &early);
        // t2 also reads d (filled later by g): t can fire where t1 t2 cannot.
        let mut second = net.clone();
        let (d, e) = (second.add_place("d", 0), second.add_place("e", 1));
        second.add_read(1, d, 1);
        let g = second.add_transition("g");
        second.add_pre(g, e, 1);
        second.add_post(g, d, 1);
        assert!(reduce(&second, &early).is_none_or(|r| r.transition[2] != usize::MAX));
        same_answers(&second, &early);
        // t1 is inhibited by x (emptied by k, never refilled), t is not.
        let mut first = net.clone();
        let x = first.add_place("x", 1);
        first.add_inhibitor(0, x, 1);
        let k = first.add_transition("k");
        first.add_pre(k, x, 1);
        let with_x = [ef(Pred::And(vec![
            Pred::Not(Box::new(le(vec![c], 0))),
            Pred::Not(Box::new(le(vec![x], 0))),
        ]))];
        assert!(reduce(&first, &with_x).is_none_or(|r| r.transition[2] != usize::MAX));
        same_answers(&first, &with_x);
        // t2 is inhibited by x, t is not.
        let mut inhibited = net.clone();
        let x = inhibited.add_place("x", 1);
        inhibited.add_inhibitor(1, x, 1);
        let k = inhibited.add_transition("k");
        inhibited.add_pre(k, x, 1);
        assert!(reduce(&inhibited, &with_x).is_none_or(|r| r.transition[2] != usize::MAX));
        same_answers(&inhibited, &with_x);
        // ...unless t is inhibited there too.
        inhibited.add_inhibitor(2, x, 1);
        assert!(reduce(&inhibited, &with_x).is_some_and(|r| r.transition[2] == usize::MAX));
        same_answers(&inhibited, &with_x);
    }

    #[test]
    fn a_transition_needing_more_for_the_same_effect_is_redundant() {
        // t: a -> b reading e (k empties it); t1: a -> b. Deadlocks are kept: t1 is
        // enabled wherever t is.
        let mut net = PtNet::new();
        let (a, b, e) = (net.add_place("a", 1), net.add_place("b", 0), net.add_place("e", 1));
        let t = net.add_transition("t");
        net.add_pre(t, a, 1);
        net.add_post(t, b, 1);
        net.add_read(t, e, 1);
        let t1 = net.add_transition("t1");
        net.add_pre(t1, a, 1);
        net.add_post(t1, b, 1);
        let k = net.add_transition("k");
        net.add_pre(k, e, 1);
        let props = [ef(le(vec![a, e], 0)), ef(le(vec![b], 0)), deadlock_property()];
        let r = reduce(&net, &props).expect("reduced");
        assert_eq!(r.transition[t], usize::MAX);
        assert_ne!(r.transition[t1], usize::MAX);
        same_answers(&net, &props);
        // The other way round: t1 needs less, it stays.
        assert!(reduce(&net, &[ef(Pred::Fireable(vec![t]))]).is_none_or(|r| r.transition[t1] != usize::MAX));
    }

    #[test]
    fn a_place_only_gaining_with_enough_tokens_is_implicit_and_one_short_is_not() {
        // `t` reads `s` (2 tokens, never taken): implicit; with 1 token, t never fires.
        let mut net = chain();
        let s = net.add_place("s", 2);
        net.add_read(0, s, 2);
        let r = reduce(&net, &[ef(le(vec![0], 0))]).expect("reduced");
        assert_eq!(r.place[s], usize::MAX);
        net.initial[s] = 1;
        let r = reduce(&net, &[ef(le(vec![0], 0))]).expect("reduced");
        assert!(r.applied.dead_transitions >= 1, "h never fires: {:?}", r.applied);
        assert_eq!(r.transition[0], usize::MAX);
        same_answers(&net, &[ef(le(vec![0], 0)), deadlock_property()]);
    }

    #[test]
    fn duplicate_transitions_leave_one_and_keep_named_ones() {
        let mut net = chain();
        let h2 = net.add_transition("h2");
        net.add_pre(h2, 0, 1);
        net.add_post(h2, 1, 1);
        let props = [ef(le(vec![1], 0)), ef(Pred::Not(Box::new(le(vec![1], 0))))];
        let r = reduce(&net, &props).expect("reduced");
        assert_eq!(r.applied.duplicate_transitions, 1);
        assert_eq!(r.transition[h2], usize::MAX);
        same_answers(&net, &props);
        // Named by is-fireable: both kept.
        let named = [ef(Pred::Fireable(vec![0])), ef(Pred::Fireable(vec![h2]))];
        let r = reduce(&net, &named);
        assert!(r.is_none_or(|r| r.transition[h2] != usize::MAX && r.transition[0] != usize::MAX));
        same_answers(&net, &named);
    }

    #[test]
    fn pre_agglomeration_fuses_the_chain_and_expands_the_trace() {
        let net = chain();
        // a emptied: the fused transition's trace is h f (b is not read: f's output).
        let got = ef(le(vec![0], 0));
        let r = reduce(&net, std::slice::from_ref(&got)).expect("reduced");
        assert_eq!(r.applied.pre_agglomerations, 1);
        assert_eq!(r.place[1], usize::MAX);
        assert_eq!(r.net.transitions, ["h.f"]);
        assert_eq!(r.expand, [vec![0, 1]]);
        let unsliced = CheckOptions {
            slice: false,
            ..CheckOptions::default()
        };
        let a = answer(&net, std::slice::from_ref(&got), &unsliced, &Control::none());
        assert_eq!(a[0].trace, Some(vec![0, 1]));
        assert!(a[0].techniques.contains(&"STRUCTURAL_REDUCTION"));
        same_answers(&net, &[got, deadlock_property()]);
        // The deadlock question alone: the net shrinks to one transition.
        let r = reduce(&net, &[deadlock_property()]).expect("reduced");
        assert_eq!(r.net.transitions.len(), 1);
        // a = b = 0 holds only while the token is in p: a formula reading b (filled by
        // f) forbids the fusion, else the answer would be wrong.
        let between = ef(Pred::And(vec![le(vec![0], 0), le(vec![2], 0)]));
        assert!(reduce(&net, std::slice::from_ref(&between)).is_none_or(|r| r.place[1] != usize::MAX));
        same_answers(&net, &[between]);
    }

    #[test]
    fn pre_agglomeration_needs_f_free_and_its_outputs_uninhibited() {
        // f also needs `c`: not free, no pre-agglomeration (post- applies: h gives only p).
        let mut net = chain();
        let c = net.add_place("c", 0);
        net.add_pre(1, c, 1);
        let props = [ef(le(vec![0], 0))];
        let r = reduce(&net, &props).expect("reduced");
        assert_eq!(r.applied.pre_agglomerations, 0);
        same_answers(&net, &props);
        // With a deadlock question post-agglomeration is off: h can fire and then the
        // net is dead with the token in p.
        let props = [deadlock_property(), ef(le(vec![0], 0))];
        assert!(reduce(&net, &props).is_none_or(|r| r.applied.post_agglomerations == 0));
        same_answers(&net, &props);
        // h also gives x, which g takes while nothing is in b (an inhibitor arc): firing
        // f early, with h, would disable g for ever and lose d.
        let mut net = chain();
        let x = net.add_place("x", 0);
        net.add_post(0, x, 1);
        let d = net.add_place("d", 0);
        let g = net.add_transition("g");
        net.add_pre(g, x, 1);
        net.add_inhibitor(g, 2, 1);
        net.add_post(g, d, 1);
        let props = [ef(Pred::Not(Box::new(le(vec![d], 0))))];
        let r = reduce(&net, &props);
        assert!(r.is_none_or(|r| r.applied.pre_agglomerations == 0));
        same_answers(&net, &props);
        let a = answer(&net, &props, &CheckOptions::default(), &Control::none());
        assert_eq!(a[0].verdict, Verdict::True);
    }

    #[test]
    fn post_agglomeration_postpones_h_unless_a_formula_reads_its_inputs() {
        // h: a -> p, f: p + c -> b; c is filled by g.
        let mut net = chain();
        let c = net.add_place("c", 0);
        net.add_pre(1, c, 1);
        let g = net.add_transition("g");
        net.add_post(g, c, 1);
        let e = net.add_place("e", 1);
        net.add_pre(g, e, 1);
        let props = [ef(Pred::Not(Box::new(le(vec![2], 0))))];
        let r = reduce(&net, &props).expect("reduced");
        assert!(r.applied.post_agglomerations >= 1, "{:?}", r.applied);
        same_answers(&net, &props);
        // a = 0 with b = 0: only while the token waits in p; reading a forbids it.
        let props = [ef(Pred::And(vec![le(vec![0], 0), le(vec![2], 0)]))];
        assert!(reduce(&net, &props).is_none_or(|r| r.place[1] != usize::MAX));
        same_answers(&net, &props);
    }

    #[test]
    fn two_and_two_agglomerate_but_three_and_two_do_not() {
        // h_i: a_i -> p, f_j: p -> b_j; a formula reads the a_i.
        let mut net = PtNet::new();
        let p = net.add_place("p", 0);
        let a: Vec<usize> = (0..3).map(|i| net.add_place(&format!("a{i}"), 1)).collect();
        let b: Vec<usize> = (0..2).map(|j| net.add_place(&format!("b{j}"), 0)).collect();
        for (i, &q) in a.iter().enumerate().take(2) {
            let h = net.add_transition(&format!("h{i}"));
            net.add_pre(h, q, 1);
            net.add_post(h, p, 1);
        }
        for (j, &q) in b.iter().enumerate() {
            let f = net.add_transition(&format!("f{j}"));
            net.add_pre(f, p, 1);
            net.add_post(f, q, 1);
        }
        // g needs both b_j (else they would be implicit and the h_i.f_j duplicates).
        let g = net.add_transition("g");
        net.add_pre(g, b[0], 1);
        net.add_pre(g, b[1], 1);
        let props = [ef(le(vec![a[0], a[1]], 0)), deadlock_property()];
        let r = reduce(&net, &props).expect("reduced");
        assert_eq!(r.place[p], usize::MAX);
        assert_eq!(r.applied.pre_agglomerations, 1);
        let mut names = r.net.transitions.clone();
        names.sort();
        assert_eq!(names, ["g", "h0.f0", "h0.f1", "h1.f0", "h1.f1"]);
        same_answers(&net, &props);
        // A third h: six fused transitions would replace five; p stays.
        let h = net.add_transition("h2");
        net.add_pre(h, a[2], 1);
        net.add_post(h, p, 1);
        let props = [ef(le(a.clone(), 0)), deadlock_property()];
        assert!(!removed(&net, &props, p));
        same_answers(&net, &props);
    }

    #[test]
    fn a_formula_nesting_deadlock_turns_the_agglomerations_off() {
        // Not dead with a empty: only while the token waits in p (f enabled); fused, the
        // net is dead as soon as a is empty.
        let net = chain();
        let props = [ef(Pred::And(vec![Pred::Not(Box::new(Pred::Deadlock)), le(vec![0], 0)]))];
        assert!(reduce(&net, &props).is_none_or(|r| r.place[1] != usize::MAX));
        same_answers(&net, &props);
        let a = answer(&net, &props, &CheckOptions::default(), &Control::none());
        assert_eq!(a[0].verdict, Verdict::True);
    }

    #[test]
    fn post_agglomeration_is_off_for_deadlocks_and_inhibited_inputs() {
        // h: a -> p, f: p + c -> b; g: e -> c, k: c -> d; z loops on a, y on b. The net
        // is dead after g h k (a and c empty, the token stuck in p); with h waiting for
        // f it never is (z or y can always fire).
        let mut net = chain();
        let (c, d, e) = (net.add_place("c", 0), net.add_place("d", 0), net.add_place("e", 1));
        net.add_pre(1, c, 1);
        let g = net.add_transition("g");
        net.add_pre(g, e, 1);
        net.add_post(g, c, 1);
        let k = net.add_transition("k");
        net.add_pre(k, c, 1);
        net.add_post(k, d, 1);
        for (name, p) in [("z", 0), ("y", 2)] {
            let t = net.add_transition(name);
            net.add_pre(t, p, 1);
            net.add_post(t, p, 1);
        }
        let props = [deadlock_property()];
        assert!(reduce(&net, &props).is_none_or(|r| r.applied.post_agglomerations == 0));
        same_answers(&net, &props);
        let a = answer(&net, &props, &CheckOptions::default(), &Control::none());
        assert_eq!(a[0].verdict, Verdict::True);
        // Without the deadlock question it applies.
        let props = [ef(Pred::Not(Box::new(le(vec![d], 0))))];
        assert!(reduce(&net, &props).is_some_and(|r| r.applied.post_agglomerations > 0));
        same_answers(&net, &props);

        // h: a -> p, f: p + c -> b (c from y: e -> c); g needs a and b empty (inhibitor
        // arcs): only while h's token waits in p, so h must not wait for f.
        let mut net = chain();
        let (c, d, e) = (net.add_place("c", 0), net.add_place("d", 0), net.add_place("e", 1));
        net.add_pre(1, c, 1);
        let y = net.add_transition("y");
        net.add_pre(y, e, 1);
        net.add_post(y, c, 1);
        let g = net.add_transition("g");
        net.add_inhibitor(g, 0, 1);
        net.add_inhibitor(g, 2, 1);
        net.add_post(g, d, 1);
        let props = [ef(Pred::Not(Box::new(le(vec![d], 0))))];
        assert!(reduce(&net, &props).is_none_or(|r| r.place[1] != usize::MAX));
        same_answers(&net, &props);
        let a = answer(&net, &props, &CheckOptions::default(), &Control::none());
        assert_eq!(a[0].verdict, Verdict::True);
    }

    #[test]
    fn rules_iterate_to_a_fixed_point_on_independent_processes() {
        // n processes idle -> busy -> done and a final transition needing every done:
        // every chain fuses; the deadlock question then explores a handful of markings.
        let net = crate::analysis::stubborn::tests::processes(6);
        let r = reduce(&net, &[deadlock_property()]).expect("reduced");
        assert_eq!(r.applied.pre_agglomerations, 6);
        assert!(r.net.places.len() <= 12, "{:?}", r.net.places);
        same_answers(&net, &[deadlock_property()]);
        let full = CheckOptions {
            reduce: false,
            stubborn: false,
            ..CheckOptions::default()
        };
        let reduced = check(&r.net, &r.properties(&[deadlock_property()]), &full, &Control::none());
        assert!(reduced.states < 3usize.pow(6), "{}", reduced.states);
    }
}
