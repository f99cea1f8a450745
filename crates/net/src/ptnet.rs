//! The underlying place/transition net used by the analysis: places, transitions, and
//! per-transition input (pre), output (post), inhibitor and read arcs with weights.
//! Guards, priorities and tags are not part of it: the analysis is of the P/T net.

/// A place/transition net with inhibitor and read (test) arcs.
///
/// Semantics: transition `t` is enabled at marking `m` when `m[p] >= w` for every
/// input arc and read arc `(p, w)`, and `m[p] < w` for every inhibitor arc `(p, w)`.
/// Firing removes the input weights and adds the output weights; read and inhibitor
/// arcs move no tokens.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PtNet {
    /// Place ids (PNML ids), index = place number.
    pub places: Vec<String>,
    /// Transition ids (PNML ids), index = transition number.
    pub transitions: Vec<String>,
    /// Initial marking, one entry per place.
    pub initial: Vec<u32>,
    /// Per transition: input arcs `(place, weight)`.
    pub pre: Vec<Vec<(usize, u32)>>,
    /// Per transition: output arcs `(place, weight)`.
    pub post: Vec<Vec<(usize, u32)>>,
    /// Per transition: inhibitor arcs `(place, weight)`: enabled only while `m[p] < weight`.
    pub inhibitors: Vec<Vec<(usize, u32)>>,
    /// Per transition: read (test) arcs `(place, weight)`: needs `m[p] >= weight`, moves nothing.
    pub reads: Vec<Vec<(usize, u32)>>,
}

impl PtNet {
    /// An empty net.
    pub fn new() -> PtNet {
        PtNet::default()
    }

    /// Adds a place with its initial marking; returns its index.
    pub fn add_place(&mut self, id: &str, initial: u32) -> usize {
        self.places.push(id.to_string());
        self.initial.push(initial);
        self.places.len() - 1
    }

    /// Adds a transition without arcs; returns its index.
    pub fn add_transition(&mut self, id: &str) -> usize {
        self.transitions.push(id.to_string());
        self.pre.push(Vec::new());
        self.post.push(Vec::new());
        self.inhibitors.push(Vec::new());
        self.reads.push(Vec::new());
        self.transitions.len() - 1
    }

    /// Adds `weight` to the input arc place → transition (arcs between the same pair add up).
    pub fn add_pre(&mut self, t: usize, p: usize, weight: u32) {
        add_arc(&mut self.pre[t], p, weight);
    }

    /// Adds `weight` to the output arc transition → place.
    pub fn add_post(&mut self, t: usize, p: usize, weight: u32) {
        add_arc(&mut self.post[t], p, weight);
    }

    /// An inhibitor arc: `t` is enabled only while `m[p] < weight`.
    pub fn add_inhibitor(&mut self, t: usize, p: usize, weight: u32) {
        match self.inhibitors[t].iter_mut().find(|(q, _)| *q == p) {
            Some((_, w)) => *w = (*w).min(weight),
            None => self.inhibitors[t].push((p, weight)),
        }
    }

    /// A read (test) arc: `t` needs `m[p] >= weight` and moves no token.
    pub fn add_read(&mut self, t: usize, p: usize, weight: u32) {
        match self.reads[t].iter_mut().find(|(q, _)| *q == p) {
            Some((_, w)) => *w = (*w).max(weight),
            None => self.reads[t].push((p, weight)),
        }
    }

    /// Index of the place with this id.
    pub fn place(&self, id: &str) -> Option<usize> {
        self.places.iter().position(|p| p == id)
    }

    /// Index of the transition with this id.
    pub fn transition(&self, id: &str) -> Option<usize> {
        self.transitions.iter().position(|t| t == id)
    }

    /// Whether the net has at least one inhibitor arc.
    pub fn has_inhibitors(&self) -> bool {
        self.inhibitors.iter().any(|v| !v.is_empty())
    }

    /// Whether `t` is enabled at `m`.
    pub fn enabled(&self, m: &[u32], t: usize) -> bool {
        self.pre[t].iter().all(|&(p, w)| m[p] >= w)
            && self.reads[t].iter().all(|&(p, w)| m[p] >= w)
            && self.inhibitors[t].iter().all(|&(p, w)| m[p] < w)
    }

    /// Fires `t` at `m` (which must enable it); `None` when a count would overflow `u32`.
    pub fn fire(&self, m: &[u32], t: usize) -> Option<Vec<u32>> {
        let mut next = m.to_vec();
        for &(p, w) in &self.pre[t] {
            next[p] -= w;
        }
        for &(p, w) in &self.post[t] {
            next[p] = next[p].checked_add(w)?;
        }
        Some(next)
    }

    /// The incidence matrix `C[p][t] = post(t, p) - pre(t, p)` (read and inhibitor arcs: 0).
    #[allow(clippy::needless_range_loop)]
    pub fn incidence(&self) -> Vec<Vec<i64>> {
        let mut c = vec![vec![0i64; self.transitions.len()]; self.places.len()];
        for t in 0..self.transitions.len() {
            for &(p, w) in &self.pre[t] {
                c[p][t] -= i64::from(w);
            }
            for &(p, w) in &self.post[t] {
                c[p][t] += i64::from(w);
            }
        }
        c
    }
}

fn add_arc(arcs: &mut Vec<(usize, u32)>, p: usize, weight: u32) {
    match arcs.iter_mut().find(|(q, _)| *q == p) {
        Some((_, w)) => *w = w.saturating_add(weight),
        None => arcs.push((p, weight)),
    }
}

impl PtNet {
    /// The place/transition net underlying a loaded [`crate::Net`]: places and transitions in
    /// document order, arcs by kind (normal place → transition: input; transition → place:
    /// output; inhibitor and read arcs from their place). Guards, priorities, tags and
    /// element kinds are not part of it. Arcs naming unknown elements (which the loader
    /// already reports) are skipped.
    pub fn from_net(net: &crate::Net) -> PtNet {
        use crate::ArcKind;
        use std::collections::HashMap;
        let mut pt = PtNet::new();
        let mut places = HashMap::new();
        let mut transitions = HashMap::new();
        for p in &net.places {
            places.insert(p.id.as_str(), pt.add_place(&p.id, p.initial));
        }
        for t in &net.transitions {
            transitions.insert(t.id.as_str(), pt.add_transition(&t.id));
        }
        for a in &net.arcs {
            let (s, d) = (a.source.as_str(), a.target.as_str());
            let place_to_transition = match (places.get(s), transitions.get(d)) {
                (Some(&p), Some(&t)) => Some((p, t)),
                _ => None,
            };
            let transition_to_place = match (transitions.get(s), places.get(d)) {
                (Some(&t), Some(&p)) => Some((p, t)),
                _ => None,
            };
            match (a.kind, place_to_transition, transition_to_place) {
                (ArcKind::Normal, Some((p, t)), _) => pt.add_pre(t, p, a.weight),
                (ArcKind::Normal, None, Some((p, t))) => pt.add_post(t, p, a.weight),
                (ArcKind::Inhibitor, Some((p, t)), _) | (ArcKind::Inhibitor, None, Some((p, t))) => {
                    pt.add_inhibitor(t, p, a.weight)
                }
                (ArcKind::Read, Some((p, t)), _) | (ArcKind::Read, None, Some((p, t))) => pt.add_read(t, p, a.weight),
                _ => {}
            }
        }
        pt
    }
}
