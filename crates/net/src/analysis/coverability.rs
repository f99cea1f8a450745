//! Karp–Miller coverability graph for unbounded nets.
//!
//! Nodes are ω-markings (`OMEGA` = unbounded). From a node, every enabled transition
//! gives a successor; when the successor strictly covers a node on its discovery path,
//! the places that grew become ω. Equal ω-markings share a node (the coverability graph
//! rather than the tree). With inhibitor arcs, a place read by an inhibitor arc must never
//! become ω (enabling is not monotone there); the construction then stops with
//! [`Coverability::InhibitorOmega`].

use crate::PtNet;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};

/// The ω value.
pub const OMEGA: u32 = u32::MAX;

/// Outcome of [`coverability`].
pub enum Coverability {
    /// The coverability graph.
    Graph {
        /// The ω-markings.
        nodes: Vec<Vec<u32>>,
        /// Number of edges.
        edges: u64,
        /// Whether each transition is enabled in some node.
        enabled: Vec<bool>,
    },
    /// More than the allowed number of nodes.
    Limit,
    /// An inhibitor place would become ω: the result would not be sound.
    InhibitorOmega(usize),
}

fn enabled(net: &PtNet, m: &[u32], t: usize) -> bool {
    net.pre[t].iter().all(|&(p, w)| m[p] == OMEGA || m[p] >= w)
        && net.reads[t].iter().all(|&(p, w)| m[p] == OMEGA || m[p] >= w)
        && net.inhibitors[t].iter().all(|&(p, w)| m[p] != OMEGA && m[p] < w)
}

/// Builds the Karp–Miller coverability graph, up to `max_nodes` nodes.
#[allow(clippy::needless_range_loop)]
pub fn coverability(net: &PtNet, max_nodes: usize, cancel: &AtomicBool) -> Coverability {
    let np = net.places.len();
    let nt = net.transitions.len();
    let mut inhibited = vec![false; np];
    for arcs in &net.inhibitors {
        for &(p, _) in arcs {
            inhibited[p] = true;
        }
    }
    let mut nodes: Vec<Vec<u32>> = vec![net.initial.clone()];
    let mut parent: Vec<usize> = vec![usize::MAX];
    let mut index: HashMap<Vec<u32>, usize> = HashMap::from([(net.initial.clone(), 0)]);
    let mut en = vec![false; nt];
    let mut edges = 0u64;
    let mut work = vec![0usize];
    while let Some(n) = work.pop() {
        if cancel.load(Ordering::Relaxed) {
            return Coverability::Limit;
        }
        let cur = nodes[n].clone();
        for t in 0..nt {
            if !enabled(net, &cur, t) {
                continue;
            }
            en[t] = true;
            let mut next = cur.clone();
            for &(p, w) in &net.pre[t] {
                if next[p] != OMEGA {
                    next[p] -= w;
                }
            }
            for &(p, w) in &net.post[t] {
                if next[p] != OMEGA {
                    // A finite count this large is treated as unbounded.
                    next[p] = next[p].checked_add(w).filter(|&v| v != OMEGA).unwrap_or(OMEGA);
                }
            }
            // Acceleration along the discovery path.
            let mut a = n;
            loop {
                let anc = &nodes[a];
                if next.iter().zip(anc).all(|(x, y)| x >= y) && next != *anc {
                    for p in 0..np {
                        if next[p] > anc[p] && next[p] != OMEGA {
                            if inhibited[p] {
                                return Coverability::InhibitorOmega(p);
                            }
                            next[p] = OMEGA;
                        }
                    }
                }
                if parent[a] == usize::MAX {
                    break;
                }
                a = parent[a];
            }
            edges += 1;
            if !index.contains_key(&next) {
                let id = nodes.len();
                if id >= max_nodes {
                    return Coverability::Limit;
                }
                index.insert(next.clone(), id);
                nodes.push(next);
                parent.push(n);
                work.push(id);
            }
        }
    }
    Coverability::Graph {
        nodes,
        edges,
        enabled: en,
    }
}
