//! Explicit reachability graph of a bounded net, stored compactly.
//!
//! Markings are bit-packed (each place gets just enough bits for the largest value seen;
//! a value that does not fit restarts the exploration with a wider field for that place)
//! into one flat arena; an open-addressing table of `u32` state indices (hashing the
//! packed bytes once per generated successor) finds duplicates. States are numbered in
//! breadth-first order, so the parent pointers give shortest firing sequences.
//! Edges are not stored: liveness and reversibility come from one iterative Tarjan pass
//! (Pearce's one-word-per-state variant) that recomputes successors.
//!
//! While exploring, each successor that raises some place above its largest value so far
//! is compared with its ancestors: a successor strictly covering an ancestor proves the
//! net unbounded (Karp–Miller's criterion), and this check alone guarantees termination.
//! With inhibitor arcs the criterion is used only when the places that grew carry no
//! inhibitor arc (enabling stays monotone in the others).

use crate::PtNet;

/// Outcome of [`explore`].
pub enum Explored {
    /// The full reachability graph.
    Graph(Box<Graph>),
    /// A marking strictly covering an ancestor was found: the net is unbounded.
    Unbounded,
    /// `max_states` was reached before the graph was complete.
    Limit,
    /// A place count exceeded `u32`.
    Overflow,
}

/// Bit layout of a packed marking: one field per place, never straddling a 64-bit word.
#[derive(Clone, Debug)]
pub struct Layout {
    bits: Vec<u32>,
    word: Vec<u32>,
    shift: Vec<u32>,
    /// Bytes per packed marking.
    pub bytes: usize,
    /// 64-bit words per marking.
    pub words: usize,
}

/// One arc on the packed form: word, shift, field mask, weight.
#[derive(Clone, Copy, Debug)]
struct Field {
    word: u32,
    shift: u32,
    mask: u64,
    weight: u64,
}

impl Field {
    #[inline]
    fn get(&self, w: &[u64]) -> u64 {
        (w[self.word as usize] >> self.shift) & self.mask
    }
}

/// The transitions compiled onto a layout.
struct Packed {
    pre: Vec<Vec<Field>>,
    post: Vec<Vec<Field>>,
    reads: Vec<Vec<Field>>,
    inhibitors: Vec<Vec<Field>>,
    post_places: Vec<Vec<usize>>,
}

impl Packed {
    fn new(net: &PtNet, layout: &Layout) -> Packed {
        let f = |arcs: &Vec<Vec<(usize, u32)>>| -> Vec<Vec<Field>> {
            arcs.iter()
                .map(|v| {
                    v.iter()
                        .map(|&(p, w)| Field {
                            word: layout.word[p],
                            shift: layout.shift[p],
                            mask: if layout.bits[p] >= 64 {
                                u64::MAX
                            } else {
                                (1u64 << layout.bits[p]) - 1
                            },
                            weight: u64::from(w),
                        })
                        .collect()
                })
                .collect()
        };
        Packed {
            pre: f(&net.pre),
            post: f(&net.post),
            reads: f(&net.reads),
            inhibitors: f(&net.inhibitors),
            post_places: net.post.iter().map(|v| v.iter().map(|&(p, _)| p).collect()).collect(),
        }
    }

    #[inline]
    fn enabled(&self, w: &[u64], t: usize) -> bool {
        self.pre[t].iter().all(|f| f.get(w) >= f.weight)
            && self.reads[t].iter().all(|f| f.get(w) >= f.weight)
            && self.inhibitors[t].iter().all(|f| f.get(w) < f.weight)
    }

    /// Fires enabled `t` from `cur` into `next`; `Err(i)` when the `i`-th output field overflows.
    #[inline]
    fn fire(&self, cur: &[u64], next: &mut [u64], t: usize) -> Result<(), usize> {
        next.copy_from_slice(cur);
        for f in &self.pre[t] {
            next[f.word as usize] -= f.weight << f.shift;
        }
        for (i, f) in self.post[t].iter().enumerate() {
            if f.get(next) + f.weight > f.mask {
                return Err(i);
            }
            next[f.word as usize] += f.weight << f.shift;
        }
        Ok(())
    }
}

impl Layout {
    fn new(bits: Vec<u32>) -> Layout {
        let mut word = Vec::with_capacity(bits.len());
        let mut shift = Vec::with_capacity(bits.len());
        let mut total = 0u32;
        for &b in &bits {
            if total % 64 + b > 64 {
                total = total.div_ceil(64) * 64;
            }
            word.push(total / 64);
            shift.push(total % 64);
            total += b;
        }
        let bytes = (total as usize).div_ceil(8).max(1);
        Layout {
            bits,
            word,
            shift,
            bytes,
            words: bytes.div_ceil(8),
        }
    }

    /// Packs `m` into `words`; `Err(p)` for the first place that does not fit.
    fn pack(&self, m: &[u32], words: &mut [u64]) -> Result<(), usize> {
        words.iter_mut().for_each(|w| *w = 0);
        for (p, &v) in m.iter().enumerate() {
            let b = self.bits[p];
            if b < 32 && v >> b != 0 {
                return Err(p);
            }
            words[self.word[p] as usize] |= u64::from(v) << self.shift[p];
        }
        Ok(())
    }

    fn unpack_words(&self, words: &[u64], m: &mut [u32]) {
        for (p, slot) in m.iter_mut().enumerate() {
            let b = self.bits[p];
            let mask = if b >= 64 { u64::MAX } else { (1u64 << b) - 1 };
            *slot = ((words[self.word[p] as usize] >> self.shift[p]) & mask) as u32;
        }
    }

    #[inline]
    fn load(&self, bytes: &[u8], words: &mut [u64]) {
        for (i, chunk) in bytes.chunks(8).enumerate() {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            words[i] = u64::from_le_bytes(b);
        }
    }

    fn unpack(&self, bytes: &[u8], words: &mut [u64], m: &mut [u32]) {
        self.load(bytes, words);
        self.unpack_words(words, m);
    }
}

fn words_to_bytes(words: &[u64], out: &mut [u8]) {
    for (i, chunk) in out.chunks_mut(8).enumerate() {
        let b = words[i].to_le_bytes();
        chunk.copy_from_slice(&b[..chunk.len()]);
    }
}

#[inline]
fn hash_words(words: &[u64]) -> u64 {
    let mut h: u64 = 0x243f_6a88_85a3_08d3;
    for &w in words {
        h = (h.rotate_left(5) ^ w).wrapping_mul(0x517c_c1b7_2722_0a95);
    }
    // Final avalanche (splitmix64) so the low bits used for the slot are well mixed.
    h ^= h >> 30;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^ (h >> 31)
}

const EMPTY: u32 = u32::MAX;

/// The packed states and their index.
pub struct Store {
    /// Layout of the packed markings.
    pub layout: Layout,
    arena: Vec<u8>,
    table: Vec<u32>,
    len: usize,
}

impl Store {
    fn new(layout: Layout) -> Store {
        Store {
            layout,
            arena: Vec::new(),
            table: vec![EMPTY; 1 << 10],
            len: 0,
        }
    }

    /// Number of states.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there is no state.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn state(&self, i: usize) -> &[u8] {
        let n = self.layout.bytes;
        &self.arena[i * n..(i + 1) * n]
    }

    /// The marking of state `i` (unpacked into `m`).
    pub fn marking(&self, i: usize, words: &mut [u64], m: &mut [u32]) {
        self.layout.unpack(self.state(i), words, m);
    }

    fn grow(&mut self) {
        let cap = self.table.len() * 2;
        let mut table = vec![EMPTY; cap];
        let mask = cap - 1;
        let mut words = vec![0u64; self.layout.words];
        for i in 0..self.len {
            self.layout.load(self.state(i), &mut words);
            let mut slot = hash_words(&words) as usize & mask;
            while table[slot] != EMPTY {
                slot = (slot + 1) & mask;
            }
            table[slot] = i as u32;
        }
        self.table = table;
    }

    /// Index of `bytes`, inserting it when new: `(index, inserted)`.
    #[inline]
    fn insert(&mut self, words: &[u64], bytes: &[u8]) -> (u32, bool) {
        if (self.len + 1) * 10 > self.table.len() * 7 {
            self.grow();
        }
        let mask = self.table.len() - 1;
        let mut slot = hash_words(words) as usize & mask;
        loop {
            let i = self.table[slot];
            if i == EMPTY {
                let idx = self.len as u32;
                self.table[slot] = idx;
                self.arena.extend_from_slice(bytes);
                self.len += 1;
                return (idx, true);
            }
            if self.state(i as usize) == bytes {
                return (i, false);
            }
            slot = (slot + 1) & mask;
        }
    }

    /// Index of `bytes` if present.
    #[inline]
    fn find(&self, words: &[u64], bytes: &[u8]) -> Option<u32> {
        let mask = self.table.len() - 1;
        let mut slot = hash_words(words) as usize & mask;
        loop {
            let i = self.table[slot];
            if i == EMPTY {
                return None;
            }
            if self.state(i as usize) == bytes {
                return Some(i);
            }
            slot = (slot + 1) & mask;
        }
    }

    /// Bytes used by the arena and the table (capacity).
    pub fn bytes_used(&self) -> usize {
        self.arena.capacity() + self.table.len() * 4
    }
}

/// A complete reachability graph (edges implicit).
pub struct Graph {
    /// The states.
    pub store: Store,
    /// BFS parent of each state (`u32::MAX` for the initial one).
    pub parent: Vec<u32>,
    /// Transition fired from the parent.
    pub via: Vec<u32>,
    /// Number of edges (firings between states).
    pub edges: u64,
    /// Number of dead markings.
    pub deadlocks: u64,
    /// The first dead marking in BFS order (a closest one to the initial marking).
    pub first_deadlock: Option<u32>,
    /// Whether each transition fired at least once.
    pub fired: Vec<bool>,
    /// Largest value of each place.
    pub max: Vec<u32>,
}

impl Graph {
    /// Transitions fired from the initial marking to state `s` (a shortest sequence).
    pub fn trace(&self, mut s: u32) -> Vec<usize> {
        let mut out = Vec::new();
        while self.parent[s as usize] != u32::MAX {
            out.push(self.via[s as usize] as usize);
            s = self.parent[s as usize];
        }
        out.reverse();
        out
    }

    /// Bytes used by the graph's data structures.
    pub fn bytes_used(&self) -> usize {
        self.store.bytes_used() + self.parent.capacity() * 4 + self.via.capacity() * 4
    }
}

fn bits_for(v: u32) -> u32 {
    (32 - v.leading_zeros()).max(1)
}

/// Explores the reachability graph breadth-first, up to `max_states` states.
#[allow(clippy::needless_range_loop)]
pub fn explore(net: &PtNet, max_states: usize, cancel: &dyn Fn() -> bool) -> Explored {
    let np = net.places.len();
    let nt = net.transitions.len();
    let inhibited: Vec<bool> = {
        let mut v = vec![false; np];
        for arcs in &net.inhibitors {
            for &(p, _) in arcs {
                v[p] = true;
            }
        }
        v
    };
    let mut bits: Vec<u32> = net.initial.iter().map(|&v| bits_for(v)).collect();
    'restart: loop {
        let layout = Layout::new(bits.clone());
        let packed_net = Packed::new(net, &layout);
        let mut store = Store::new(layout.clone());
        let mut cur = vec![0u64; layout.words];
        let mut next = vec![0u64; layout.words];
        let mut words2 = vec![0u64; layout.words];
        let mut bytes = vec![0u8; layout.bytes];
        let mut m = vec![0u32; np];
        let mut anc = vec![0u32; np];
        let mut max = net.initial.clone();
        if layout.pack(&net.initial, &mut cur).is_err() {
            return Explored::Overflow;
        }
        words_to_bytes(&cur, &mut bytes);
        store.insert(&cur, &bytes);
        let mut parent = vec![u32::MAX];
        let mut via = vec![0u32];
        let mut edges = 0u64;
        let mut deadlocks = 0u64;
        let mut first_deadlock = None;
        let mut fired = vec![false; nt];
        let mut s = 0usize;
        while s < store.len() {
            if s & 0xffff == 0 && cancel() {
                return Explored::Limit;
            }
            layout.load(store.state(s), &mut cur);
            let mut dead = true;
            for t in 0..nt {
                if !packed_net.enabled(&cur, t) {
                    continue;
                }
                dead = false;
                fired[t] = true;
                if let Err(i) = packed_net.fire(&cur, &mut next, t) {
                    // Widen the place that does not fit and start again.
                    let p = packed_net.post_places[t][i];
                    if bits[p] >= 32 {
                        return Explored::Overflow;
                    }
                    bits[p] = (bits[p] * 2).min(32);
                    continue 'restart;
                }
                let mut record = false;
                for (i, f) in packed_net.post[t].iter().enumerate() {
                    let p = packed_net.post_places[t][i];
                    let v = f.get(&next) as u32;
                    if v > max[p] {
                        max[p] = v;
                        record = true;
                    }
                }
                if record {
                    // Karp–Miller: does the successor strictly cover an ancestor?
                    layout.unpack_words(&next, &mut m);
                    let mut a = s;
                    loop {
                        store.marking(a, &mut words2, &mut anc);
                        let covers = m.iter().zip(&anc).all(|(x, y)| x >= y)
                            && m != anc
                            && m.iter().zip(&anc).zip(&inhibited).all(|((x, y), &inh)| x == y || !inh);
                        if covers {
                            return Explored::Unbounded;
                        }
                        if parent[a] == u32::MAX {
                            break;
                        }
                        a = parent[a] as usize;
                    }
                }
                words_to_bytes(&next, &mut bytes);
                let (_, inserted) = store.insert(&next, &bytes);
                edges += 1;
                if inserted {
                    parent.push(s as u32);
                    via.push(t as u32);
                    if store.len() > max_states {
                        return Explored::Limit;
                    }
                }
            }
            if dead {
                deadlocks += 1;
                first_deadlock.get_or_insert(s as u32);
            }
            s += 1;
        }
        return Explored::Graph(Box::new(Graph {
            store,
            parent,
            via,
            edges,
            deadlocks,
            first_deadlock,
            fired,
            max,
        }));
    }
}

/// Result of the SCC pass.
pub struct Components {
    /// Number of strongly connected components.
    pub count: usize,
    /// Number of terminal components (no edge leaves them).
    pub terminal: usize,
    /// Whether every terminal component enables every transition (liveness L4).
    pub live: bool,
    /// Whether the initial state is in the only terminal component (reversibility).
    pub reversible: bool,
}

/// Tarjan's algorithm (Pearce's variant, iterative) on the implicit graph.
pub fn components(net: &PtNet, g: &Graph) -> Components {
    let n = g.store.len();
    let np = net.places.len();
    let nt = net.transitions.len();
    let layout = &g.store.layout;
    let packed_net = Packed::new(net, layout);
    let mut packed = vec![0u8; layout.bytes];
    let mut cur = vec![0u64; layout.words];
    let mut next = vec![0u64; layout.words];
    let _ = np;
    // rindex: 0 = unvisited; while on the stack the DFS index; when done the component id.
    let mut rindex = vec![0u32; n];
    let mut done = vec![0u64; n.div_ceil(64)];
    // Per state: an edge leaves its (unfinished) component to a finished one.
    let mut leaves = vec![0u64; n.div_ceil(64)];
    let is = |v: &[u64], i: usize| v[i / 64] >> (i % 64) & 1 == 1;
    let set = |v: &mut [u64], i: usize| v[i / 64] |= 1 << (i % 64);
    let mut index = 1u32;
    let mut comp = 0u32;
    let mut stack: Vec<u32> = Vec::new();
    // Frames: (state, next transition to try, root).
    let mut frames: Vec<(u32, u32, bool)> = Vec::new();
    let mut terminal = 0usize;
    let mut live = true;
    let mut initial_terminal = false;
    let mut enabled_union = vec![false; nt];
    for start in 0..n {
        if rindex[start] != 0 || is(&done, start) {
            continue;
        }
        rindex[start] = index;
        index += 1;
        frames.push((start as u32, 0, true));
        while let Some(frame) = frames.last_mut() {
            let v = frame.0;
            let vi = v as usize;
            layout.load(g.store.state(vi), &mut cur);
            let mut descended = false;
            while (frame.1 as usize) < nt {
                let t = frame.1 as usize;
                frame.1 += 1;
                if !packed_net.enabled(&cur, t) {
                    continue;
                }
                if packed_net.fire(&cur, &mut next, t).is_err() {
                    continue;
                }
                words_to_bytes(&next, &mut packed);
                let Some(w) = g.store.find(&next, &packed) else {
                    continue;
                };
                let wi = w as usize;
                if is(&done, wi) {
                    set(&mut leaves, vi);
                    continue;
                }
                if rindex[wi] == 0 {
                    rindex[wi] = index;
                    index += 1;
                    frames.push((w, 0, true));
                    descended = true;
                    break;
                }
                if rindex[wi] < rindex[vi] {
                    rindex[vi] = rindex[wi];
                    frame.2 = false;
                }
            }
            if descended {
                continue;
            }
            // v is finished.
            let (_, _, root) = frames.pop().unwrap_or((v, 0, true));
            if root {
                // Members: stack entries with rindex >= rindex[v], plus v.
                let mut k = stack.len();
                while k > 0 && rindex[vi] <= rindex[stack[k - 1] as usize] {
                    k -= 1;
                }
                let members = || stack[k..].iter().map(|&w| w as usize).chain(std::iter::once(vi));
                let is_terminal = members().all(|w| !is(&leaves, w));
                if is_terminal {
                    terminal += 1;
                    if members().any(|w| w == 0) {
                        initial_terminal = true;
                    }
                    if live {
                        enabled_union.iter_mut().for_each(|e| *e = false);
                        for w in members() {
                            layout.load(g.store.state(w), &mut cur);
                            for (t, e) in enabled_union.iter_mut().enumerate() {
                                if !*e && packed_net.enabled(&cur, t) {
                                    *e = true;
                                }
                            }
                        }
                        if enabled_union.iter().any(|e| !e) {
                            live = false;
                        }
                    }
                }
                for w in members().collect::<Vec<_>>() {
                    rindex[w] = comp;
                    set(&mut done, w);
                }
                stack.truncate(k);
                comp += 1;
            } else {
                stack.push(v);
            }
            // Propagate to the parent frame: low-link and "leaves".
            if let Some(parent) = frames.last_mut() {
                let ui = parent.0 as usize;
                if !is(&done, vi) {
                    if rindex[vi] < rindex[ui] {
                        rindex[ui] = rindex[vi];
                        parent.2 = false;
                    }
                } else {
                    set(&mut leaves, ui);
                }
            }
        }
    }
    Components {
        count: comp as usize,
        terminal,
        live,
        reversible: terminal == 1 && initial_terminal,
    }
}
