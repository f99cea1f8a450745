//! Explicit reachability graph of a bounded net, stored compactly.
//!
//! Markings are bit-packed (each place gets just enough bits for the largest value seen;
//! a value that does not fit widens that place's field and re-packs the states found so
//! far in place, keeping their numbers, so the exploration goes on where it was) into an
//! arena of fixed-size chunks. An open-addressing table of `u32` entries (a state number
//! in the low 27 bits, 5 bits of the hash above, so most mismatches are told without
//! reading the arena; linear probing, load ≤ 0.8, grown by half) finds duplicates.
//! States are numbered in breadth-first order and only the first state of each BFS level
//! is kept: a shortest firing sequence to a state is rebuilt backwards, firing
//! transitions in reverse and looking the predecessor up in the previous level. So a
//! state costs its packed marking and about five bytes of table.
//!
//! The successors of a state are computed together and their table slots and arena
//! entries touched before any is compared, so that the memory accesses of one state's
//! successors overlap instead of waiting one after the other.
//!
//! Edges are not stored: liveness and reversibility come from one iterative Tarjan pass
//! (Pearce's one-word-per-state variant) that recomputes successors.
//!
//! While exploring, each successor that raises some place above its largest value so far
//! is compared with its ancestors: a successor strictly covering an ancestor proves the
//! net unbounded (Karp–Miller's criterion), and this check alone guarantees termination.
//! With inhibitor arcs the criterion is used only when the places that grew carry no
//! inhibitor arc (enabling stays monotone in the others).

use super::{Control, Part, Progress};
use crate::PtNet;

/// Limits of [`explore`].
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Largest number of states.
    pub max_states: usize,
    /// Bytes the arena and the table may use.
    pub memory: usize,
}

/// Why an exploration stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// `max_states` (or the 2^27 states a table entry can number).
    States,
    /// The memory budget.
    Memory,
    /// The cancellation flag.
    Cancelled,
}

/// Outcome of [`explore`].
pub enum Explored {
    /// The full reachability graph.
    Graph(Box<Graph>),
    /// A marking strictly covering an ancestor was found: the net is unbounded.
    Unbounded,
    /// Stopped before the graph was complete.
    Limit {
        /// Why.
        why: Stop,
        /// States found by then.
        states: usize,
        /// Bytes used by then.
        bytes: usize,
    },
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
    /// Enabling tests: `(field, weight, at least)`; `at least` false for inhibitors.
    tests: Vec<Vec<(Field, bool)>>,
    /// Per transition, per word: what firing adds (wrapping: removal as two's complement).
    delta: Vec<Vec<(u32, u64)>>,
    /// Per transition: the places it adds to, with what it adds (`post - pre`, > 0).
    grow: Vec<Vec<(Field, usize)>>,
}

impl Packed {
    fn new(net: &PtNet, layout: &Layout) -> Packed {
        let field = |p: usize, w: u32| Field {
            word: layout.word[p],
            shift: layout.shift[p],
            mask: if layout.bits[p] >= 64 {
                u64::MAX
            } else {
                (1u64 << layout.bits[p]) - 1
            },
            weight: u64::from(w),
        };
        let nt = net.transitions.len();
        let mut tests = Vec::with_capacity(nt);
        let mut delta = Vec::with_capacity(nt);
        for t in 0..nt {
            // Inputs and reads with the same place: the larger weight is the test.
            let mut need: Vec<(usize, u32)> = net.pre[t].clone();
            for &(p, w) in &net.reads[t] {
                match need.iter_mut().find(|(q, _)| *q == p) {
                    Some((_, v)) => *v = (*v).max(w),
                    None => need.push((p, w)),
                }
            }
            let mut v: Vec<(Field, bool)> = need.iter().map(|&(p, w)| (field(p, w), true)).collect();
            v.extend(net.inhibitors[t].iter().map(|&(p, w)| (field(p, w), false)));
            tests.push(v);
            let mut d: Vec<(u32, u64)> = Vec::new();
            let mut add = |word: u32, x: u64| match d.iter_mut().find(|(w, _)| *w == word) {
                Some((_, v)) => *v = v.wrapping_add(x),
                None => d.push((word, x)),
            };
            for &(p, w) in &net.pre[t] {
                add(layout.word[p], (u64::from(w) << layout.shift[p]).wrapping_neg());
            }
            for &(p, w) in &net.post[t] {
                add(layout.word[p], u64::from(w) << layout.shift[p]);
            }
            d.retain(|&(_, x)| x != 0);
            delta.push(d);
        }
        Packed {
            tests,
            delta,
            grow: (0..nt)
                .map(|t| {
                    net.post[t]
                        .iter()
                        .filter_map(|&(p, w)| {
                            let taken = net.pre[t].iter().find(|(q, _)| *q == p).map_or(0, |&(_, v)| v);
                            (w > taken).then(|| (field(p, w - taken), p))
                        })
                        .collect()
                })
                .collect(),
        }
    }

    #[inline]
    fn enabled(&self, w: &[u64], t: usize) -> bool {
        self.tests[t]
            .iter()
            .all(|&(f, at_least)| (f.get(w) >= f.weight) == at_least)
    }

    /// Fires enabled `t` from `cur` into `next`; `Err(p)` when place `p` would overflow
    /// its field.
    #[inline]
    fn fire(&self, cur: &[u64], next: &mut [u64], t: usize) -> Result<(), usize> {
        for &(f, p) in &self.grow[t] {
            if f.get(cur) + f.weight > f.mask {
                return Err(p);
            }
        }
        next.copy_from_slice(cur);
        for &(w, x) in &self.delta[t] {
            next[w as usize] = next[w as usize].wrapping_add(x);
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

    /// The sum of the fields of a packed marking.
    fn tokens(&self, words: &[u64]) -> u64 {
        (0..self.bits.len())
            .map(|p| {
                let b = self.bits[p];
                let mask = if b >= 64 { u64::MAX } else { (1u64 << b) - 1 };
                (words[self.word[p] as usize] >> self.shift[p]) & mask
            })
            .sum()
    }

    #[inline]
    fn load(&self, bytes: &[u8], words: &mut [u64]) {
        let full = bytes.len() / 8;
        for (i, w) in words.iter_mut().enumerate().take(full) {
            let mut b = [0u8; 8];
            b.copy_from_slice(&bytes[i * 8..i * 8 + 8]);
            *w = u64::from_le_bytes(b);
        }
        if full < words.len() {
            let rest = &bytes[full * 8..];
            let mut b = [0u8; 8];
            b[..rest.len()].copy_from_slice(rest);
            words[full] = u64::from_le_bytes(b);
        }
    }
}

#[inline]
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
    // Final avalanche (splitmix64): every bit of the marking reaches the slot and the tag.
    h ^= h >> 30;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^ (h >> 31)
}

const EMPTY: u32 = u32::MAX;
/// Bits of a table entry that number the state.
const INDEX_BITS: u32 = 27;
const INDEX_MASK: u32 = (1 << INDEX_BITS) - 1;
/// The most states a table entry can number (the all-ones index is the empty mark).
pub const MAX_STATES: usize = INDEX_MASK as usize - 1;
/// Bytes per arena chunk.
const CHUNK_BYTES: usize = 1 << 22;

#[inline]
fn tag(h: u64) -> u32 {
    ((h >> 59) as u32) << INDEX_BITS
}

/// The packed states and their index.
pub struct Store {
    /// Layout of the packed markings.
    pub layout: Layout,
    chunks: Vec<Vec<u8>>,
    per_chunk: usize,
    table: Vec<u32>,
    len: usize,
    /// The most bytes used at once.
    peak: usize,
}

/// The first slot of hash `h` in a table of `n` slots (Lemire's multiply-shift).
#[inline]
fn home(h: u64, n: usize) -> usize {
    ((u128::from(h) * n as u128) >> 64) as usize
}

impl Store {
    fn new(layout: Layout) -> Store {
        let per_chunk = (CHUNK_BYTES / layout.bytes).max(1);
        Store {
            layout,
            chunks: Vec::new(),
            per_chunk,
            table: vec![EMPTY; 1 << 10],
            len: 0,
            peak: 0,
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

    #[inline]
    fn state(&self, i: usize) -> &[u8] {
        let n = self.layout.bytes;
        let (c, k) = (i / self.per_chunk, i % self.per_chunk);
        &self.chunks[c][k * n..(k + 1) * n]
    }

    /// The marking of state `i` (unpacked into `m`).
    pub fn marking(&self, i: usize, words: &mut [u64], m: &mut [u32]) {
        self.layout.load(self.state(i), words);
        self.layout.unpack_words(words, m);
    }

    /// Bytes of a table of `slots` slots.
    fn table_bytes(slots: usize) -> usize {
        slots * 4
    }

    /// Rebuilds the table with `slots` slots.
    fn rehash(&mut self, slots: usize) {
        self.table = Vec::new();
        let mut table = vec![EMPTY; slots];
        let mut words = vec![0u64; self.layout.words];
        for i in 0..self.len {
            self.layout.load(self.state(i), &mut words);
            let h = hash_words(&words);
            let mut slot = home(h, slots);
            while table[slot] != EMPTY {
                slot += 1;
                if slot == slots {
                    slot = 0;
                }
            }
            table[slot] = tag(h) | i as u32;
        }
        self.table = table;
    }

    /// Room for one more state: `false` when the memory budget does not allow it.
    #[inline]
    fn reserve(&mut self, memory: usize) -> bool {
        if (self.len + 1) * 5 > self.table.len() * 4 {
            let slots = self.table.len() + self.table.len() / 2;
            // The old table lives while the new one fills.
            let during = self.bytes_used() + Store::table_bytes(slots);
            if during > memory {
                return false;
            }
            self.peak = self.peak.max(during);
            self.rehash(slots);
        }
        if self.len == self.chunks.len() * self.per_chunk {
            if self.bytes_used() + self.per_chunk * self.layout.bytes > memory {
                return false;
            }
            // Grown by doubling up to its size: a small net does not take a whole chunk.
            self.chunks.push(Vec::new());
        }
        true
    }

    /// Shrinks the table to load 0.8 (after the exploration).
    fn shrink(&mut self) {
        let slots = (self.len * 5 / 4 + 1).max(16);
        if slots < self.table.len() {
            self.peak = self.peak.max(self.bytes_used() + Store::table_bytes(slots));
            self.rehash(slots);
        }
    }

    /// Touches the slot of `h` and the state it names (a hint for the batch to come).
    #[inline]
    fn touch(&self, h: u64) -> u32 {
        let e = self.table[home(h, self.table.len())];
        if e == EMPTY {
            return 0;
        }
        u32::from(self.state((e & INDEX_MASK) as usize)[0])
    }

    /// Index of `bytes` (hash `h`), inserting it when new (room reserved): `(index, inserted)`.
    #[inline]
    fn insert(&mut self, h: u64, bytes: &[u8]) -> (u32, bool) {
        let n = self.table.len();
        let mut slot = home(h, n);
        let t = tag(h);
        loop {
            let e = self.table[slot];
            if e == EMPTY {
                let idx = self.len as u32;
                self.table[slot] = t | idx;
                let c = self.len / self.per_chunk;
                self.chunks[c].extend_from_slice(bytes);
                self.len += 1;
                return (idx, true);
            }
            if e & !INDEX_MASK == t && self.state((e & INDEX_MASK) as usize) == bytes {
                return (e & INDEX_MASK, false);
            }
            slot += 1;
            if slot == n {
                slot = 0;
            }
        }
    }

    /// Index of `bytes` (hash `h`) if present.
    #[inline]
    fn find(&self, h: u64, bytes: &[u8]) -> Option<u32> {
        let n = self.table.len();
        let mut slot = home(h, n);
        let t = tag(h);
        loop {
            let e = self.table[slot];
            if e == EMPTY {
                return None;
            }
            if e & !INDEX_MASK == t && self.state((e & INDEX_MASK) as usize) == bytes {
                return Some(e & INDEX_MASK);
            }
            slot += 1;
            if slot == n {
                slot = 0;
            }
        }
    }

    /// Index of the unpacked marking `m`, if it fits the layout and is present.
    fn find_marking(&self, m: &[u32]) -> Option<u32> {
        let mut words = vec![0u64; self.layout.words];
        self.layout.pack(m, &mut words).ok()?;
        let mut bytes = vec![0u8; self.layout.bytes];
        words_to_bytes(&words, &mut bytes);
        self.find(hash_words(&words), &bytes)
    }

    /// Bytes used by the arena and the table (capacity).
    pub fn bytes_used(&self) -> usize {
        self.chunks.iter().map(Vec::capacity).sum::<usize>() + Store::table_bytes(self.table.len())
    }

    /// The same states in a wider layout, numbered as before.
    fn repack(&self, layout: Layout) -> Store {
        let mut s = Store::new(layout);
        let np = self.layout.bits.len();
        let mut m = vec![0u32; np];
        let mut words = vec![0u64; self.layout.words];
        let mut wide = vec![0u64; s.layout.words];
        let mut bytes = vec![0u8; s.layout.bytes];
        s.table = Vec::new();
        for i in 0..self.len {
            self.marking(i, &mut words, &mut m);
            // Fits: the new layout is wider on every place.
            let _ = s.layout.pack(&m, &mut wide);
            words_to_bytes(&wide, &mut bytes);
            if s.len == s.chunks.len() * s.per_chunk {
                s.chunks.push(Vec::new());
            }
            let c = s.len / s.per_chunk;
            s.chunks[c].extend_from_slice(&bytes);
            s.len += 1;
        }
        s.rehash(self.table.len());
        s
    }
}

/// Entries per chunk of [`Parents`].
const PARENT_CHUNK: usize = 1 << 20;

/// The BFS parent of each state, in chunks (no doubling of one large vector).
#[derive(Default)]
struct Parents {
    chunks: Vec<Vec<u32>>,
    len: usize,
}

impl Parents {
    fn push(&mut self, p: u32) {
        if self.len.is_multiple_of(PARENT_CHUNK) {
            self.chunks
                .push(Vec::with_capacity(PARENT_CHUNK.min(self.len.max(1024))));
        }
        if let Some(c) = self.chunks.last_mut() {
            c.push(p);
        }
        self.len += 1;
    }

    #[inline]
    fn get(&self, i: u32) -> u32 {
        let i = i as usize;
        self.chunks[i / PARENT_CHUNK][i % PARENT_CHUNK]
    }

    fn bytes(&self) -> usize {
        self.chunks.iter().map(|c| c.capacity() * 4).sum()
    }
}

/// A complete reachability graph (edges implicit).
pub struct Graph {
    /// The states.
    pub store: Store,
    /// The first state of each BFS level.
    pub levels: Vec<u32>,
    /// Number of edges (firings between states).
    pub edges: u64,
    /// Number of dead markings.
    pub deadlocks: u64,
    /// The first dead marking in BFS order (a closest one to the initial marking).
    pub first_deadlock: Option<u32>,
    /// A shortest firing sequence to it (BFS parents).
    pub deadlock_trace: Option<Vec<usize>>,
    /// Whether each transition fired at least once.
    pub fired: Vec<bool>,
    /// Largest value of each place.
    pub max: Vec<u32>,
    /// Largest number of tokens in one marking.
    pub max_tokens: u64,
    /// The most bytes the exploration used at once (the old and new table while it grew).
    pub peak_bytes: usize,
    net: PtNet,
}

/// The BFS level of state `s` given the first state of each level.
fn level_of(levels: &[u32], s: u32) -> usize {
    levels.partition_point(|&l| l <= s) - 1
}

/// A shortest firing sequence from the initial state to `s` (BFS levels, rebuilt
/// backwards): at each step the first transition, in net order, whose reverse firing
/// leads to a state of the previous level.
fn trace_back(net: &PtNet, store: &Store, levels: &[u32], mut s: u32) -> Vec<usize> {
    let np = net.places.len();
    let mut words = vec![0u64; store.layout.words];
    let mut m = vec![0u32; np];
    let mut out = Vec::new();
    let mut k = level_of(levels, s);
    while k > 0 {
        store.marking(s as usize, &mut words, &mut m);
        let (lo, hi) = (levels[k - 1], levels[k]);
        // The BFS parent: the first state of the previous level with an edge to `s`,
        // and the first transition taking it there.
        let step = (0..net.transitions.len())
            .filter_map(|t| {
                let mut prev = m.clone();
                for &(p, w) in &net.post[t] {
                    prev[p] = prev[p].checked_sub(w)?;
                }
                for &(p, w) in &net.pre[t] {
                    prev[p] = prev[p].checked_add(w)?;
                }
                if !net.enabled(&prev, t) {
                    return None;
                }
                let i = store.find_marking(&prev)?;
                (lo..hi).contains(&i).then_some((t, i))
            })
            .min_by_key(|&(t, i)| (i, t));
        let Some((t, i)) = step else {
            // Unreachable: every state of level k has a predecessor in level k - 1.
            break;
        };
        out.push(t);
        s = i;
        k -= 1;
    }
    out.reverse();
    out
}

impl Graph {
    /// Transitions fired from the initial marking to state `s` (a shortest sequence).
    pub fn trace(&self, s: u32) -> Vec<usize> {
        trace_back(&self.net, &self.store, &self.levels, s)
    }

    /// Bytes used by the graph's data structures.
    pub fn bytes_used(&self) -> usize {
        self.store.bytes_used() + self.levels.capacity() * 4
    }
}

fn bits_for(v: u32) -> u32 {
    (32 - v.leading_zeros()).max(1)
}

/// Explores the reachability graph breadth-first within `limits`.
#[allow(clippy::needless_range_loop)]
pub fn explore(net: &PtNet, limits: &Limits, control: &Control<'_>) -> Explored {
    let np = net.places.len();
    let nt = net.transitions.len();
    let max_states = limits.max_states.min(MAX_STATES);
    let inhibited: Vec<bool> = {
        let mut v = vec![false; np];
        for arcs in &net.inhibitors {
            for &(p, _) in arcs {
                v[p] = true;
            }
        }
        v
    };
    let constant_tokens = (0..nt).all(|t| {
        let sum = |v: &[(usize, u32)]| v.iter().map(|&(_, w)| u64::from(w)).sum::<u64>();
        sum(&net.pre[t]) == sum(&net.post[t])
    });
    let mut bits: Vec<u32> = net.initial.iter().map(|&v| bits_for(v)).collect();
    let mut layout = Layout::new(bits.clone());
    let mut packed = Packed::new(net, &layout);
    let mut store = Store::new(layout.clone());
    let mut max = net.initial.clone();
    let mut max_tokens = net.initial.iter().map(|&v| u64::from(v)).sum::<u64>();
    let mut cur = vec![0u64; layout.words];
    if layout.pack(&net.initial, &mut cur).is_err() {
        return Explored::Overflow;
    }
    let mut bytes = vec![0u8; layout.bytes];
    words_to_bytes(&cur, &mut bytes);
    if !store.reserve(limits.memory) {
        return Explored::Limit {
            why: Stop::Memory,
            states: 0,
            bytes: store.bytes_used(),
        };
    }
    store.insert(hash_words(&cur), &bytes);
    let mut levels: Vec<u32> = vec![0];
    let mut level_end = 1usize;
    let mut edges = 0u64;
    let mut deadlocks = 0u64;
    let mut first_deadlock = None;
    let mut fired = vec![false; nt];
    // One state's successors: packed words, hashes, transitions.
    let mut succ: Vec<u64> = Vec::new();
    let mut hashes: Vec<u64> = Vec::new();
    let mut via: Vec<usize> = Vec::new();
    let mut m = vec![0u32; np];
    let mut s = 0usize;
    let stop = |why, store: &Store, parents: &Parents| Explored::Limit {
        why,
        states: store.len(),
        bytes: store.bytes_used() + parents.bytes(),
    };
    let mut parents = Parents::default();
    parents.push(u32::MAX);
    let mut anc = vec![0u32; np];
    let mut anc_words = vec![0u64; layout.words];
    'states: while s < store.len() {
        if s == level_end && levels.last() != Some(&(s as u32)) {
            levels.push(s as u32);
            level_end = store.len();
        }
        if s & 0x3fff == 0 {
            if control.cancelled() {
                return stop(Stop::Cancelled, &store, &parents);
            }
            (control.progress)(&Progress {
                part: Part::StateSpace,
                states: store.len() as u64,
                bytes: store.bytes_used() + parents.bytes(),
            });
        }
        let w = layout.words;
        anc_words.resize(w, 0);
        cur.resize(w, 0);
        layout.load(store.state(s), &mut cur);
        if !constant_tokens {
            max_tokens = max_tokens.max(layout.tokens(&cur));
        }
        succ.clear();
        hashes.clear();
        via.clear();
        let mut dead = true;
        for t in 0..nt {
            if !packed.enabled(&cur, t) {
                continue;
            }
            dead = false;
            fired[t] = true;
            let k = succ.len();
            succ.resize(k + w, 0);
            if let Err(p) = packed.fire(&cur, &mut succ[k..], t) {
                // Widen the place that does not fit, re-pack, and do this state again.
                if bits[p] >= 32 {
                    return Explored::Overflow;
                }
                bits[p] = (bits[p] * 2).min(32);
                layout = Layout::new(bits.clone());
                packed = Packed::new(net, &layout);
                let old = store.bytes_used();
                store = store.repack(layout.clone());
                store.peak = store.peak.max(old + store.bytes_used());
                bytes = vec![0u8; layout.bytes];
                continue 'states;
            }
            hashes.push(hash_words(&succ[k..k + w]));
            via.push(t);
        }
        // Overlap the memory accesses of the successors' look-ups.
        let mut touched = 0u32;
        for &h in &hashes {
            touched = touched.wrapping_add(store.touch(h));
        }
        std::hint::black_box(touched);
        for (n, &h) in hashes.iter().enumerate() {
            let next = &succ[n * w..(n + 1) * w];
            // Karp–Miller at records: does the successor strictly cover an ancestor?
            // A record on a place read by an inhibitor arc rules every ancestor out (the
            // criterion needs equality there). Only the places the transition adds to
            // can set one.
            let mut record = false;
            let mut inhibited_record = false;
            for &(f, p) in &packed.grow[via[n]] {
                let v = f.get(next) as u32;
                if v > max[p] {
                    max[p] = v;
                    record = true;
                    inhibited_record |= inhibited[p];
                }
            }
            if record {
                layout.unpack_words(next, &mut m);
            }
            let record = record && !inhibited_record;
            if record {
                // Karp–Miller: does the successor strictly cover an ancestor (the BFS
                // parents of `s`, `s` included)?
                let mut at = s as u32;
                loop {
                    store.marking(at as usize, &mut anc_words, &mut anc);
                    let covers = m.iter().zip(&anc).all(|(x, y)| x >= y)
                        && m != anc
                        && m.iter().zip(&anc).zip(&inhibited).all(|((x, y), &inh)| x == y || !inh);
                    if covers {
                        return Explored::Unbounded;
                    }
                    at = parents.get(at);
                    if at == u32::MAX {
                        break;
                    }
                }
            }
            if !store.reserve(limits.memory.saturating_sub(parents.bytes() + PARENT_CHUNK * 4)) {
                return stop(Stop::Memory, &store, &parents);
            }
            words_to_bytes(next, &mut bytes);
            let (_, inserted) = store.insert(h, &bytes);
            edges += 1;
            if inserted {
                parents.push(s as u32);
                if store.len() > max_states {
                    return stop(Stop::States, &store, &parents);
                }
            }
        }
        if dead {
            deadlocks += 1;
            first_deadlock.get_or_insert(s as u32);
        }
        s += 1;
    }
    let deadlock_trace = first_deadlock.map(|d| {
        let mut path = vec![d];
        while let Some(&last) = path.last() {
            match parents.get(last) {
                u32::MAX => break,
                p => path.push(p),
            }
        }
        path.reverse();
        let mut a = vec![0u32; np];
        let mut b = vec![0u32; np];
        path.windows(2)
            .map(|w2| {
                store.marking(w2[0] as usize, &mut anc_words, &mut a);
                store.marking(w2[1] as usize, &mut anc_words, &mut b);
                (0..nt)
                    .find(|&t| net.enabled(&a, t) && net.fire(&a, t).as_deref() == Some(&b[..]))
                    .unwrap_or(0)
            })
            .collect()
    });
    let peak_bytes = store.peak.max(store.bytes_used()) + parents.bytes();
    drop(parents);
    store.shrink();
    Explored::Graph(Box::new(Graph {
        store,
        levels,
        edges,
        deadlocks,
        first_deadlock,
        deadlock_trace,
        fired,
        max,
        max_tokens,
        peak_bytes,
        net: net.clone(),
    }))
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

/// Tarjan's algorithm (Pearce's variant, iterative) on the implicit graph; `None` when
/// cancelled. Each state's successors are looked up together when it is entered and
/// kept on an edge stack while it is on the DFS path.
pub fn components(net: &PtNet, g: &Graph, control: &Control<'_>) -> Option<Components> {
    let n = g.store.len();
    let nt = net.transitions.len();
    let layout = &g.store.layout;
    let packed_net = Packed::new(net, layout);
    let w = layout.words;
    let mut bytes = vec![0u8; layout.bytes];
    let mut cur = vec![0u64; w];
    let mut next = vec![0u64; w];
    let mut succ_hashes: Vec<u64> = Vec::new();
    let mut succ_words: Vec<u64> = Vec::new();
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
    // The successors of the states on the DFS path.
    let mut edges: Vec<u32> = Vec::new();
    // Frames: (state, start of its successors in `edges`, next one to try, root).
    let mut frames: Vec<(u32, u32, u32, bool)> = Vec::new();
    let mut terminal = 0usize;
    let mut live = true;
    let mut initial_terminal = false;
    let mut enabled_union = vec![false; nt];
    let mut visited = 0usize;
    let mut enter = |v: u32, edges: &mut Vec<u32>| {
        layout.load(g.store.state(v as usize), &mut cur);
        succ_hashes.clear();
        succ_words.clear();
        for t in 0..nt {
            if !packed_net.enabled(&cur, t) || packed_net.fire(&cur, &mut next, t).is_err() {
                continue;
            }
            succ_hashes.push(hash_words(&next));
            succ_words.extend_from_slice(&next);
        }
        let mut touched = 0u32;
        for &h in &succ_hashes {
            touched = touched.wrapping_add(g.store.touch(h));
        }
        std::hint::black_box(touched);
        for (k, &h) in succ_hashes.iter().enumerate() {
            words_to_bytes(&succ_words[k * w..(k + 1) * w], &mut bytes);
            if let Some(i) = g.store.find(h, &bytes) {
                edges.push(i);
            }
        }
    };
    for start in 0..n {
        if rindex[start] != 0 || is(&done, start) {
            continue;
        }
        rindex[start] = index;
        index += 1;
        let e0 = edges.len() as u32;
        enter(start as u32, &mut edges);
        frames.push((start as u32, e0, e0, true));
        while let Some(&mut (v, e_start, ref mut e_next, ref mut root)) = frames.last_mut() {
            let vi = v as usize;
            let mut descend = None;
            while (*e_next as usize) < edges.len() {
                let wi = edges[*e_next as usize] as usize;
                *e_next += 1;
                if is(&done, wi) {
                    set(&mut leaves, vi);
                    continue;
                }
                if rindex[wi] == 0 {
                    descend = Some(wi as u32);
                    break;
                }
                if rindex[wi] < rindex[vi] {
                    rindex[vi] = rindex[wi];
                    *root = false;
                }
            }
            if let Some(wv) = descend {
                visited += 1;
                if visited & 0x3fff == 0 {
                    if control.cancelled() {
                        return None;
                    }
                    (control.progress)(&Progress {
                        part: Part::Components,
                        states: visited as u64,
                        bytes: g.bytes_used() + n * 4,
                    });
                }
                rindex[wv as usize] = index;
                index += 1;
                let e0 = edges.len() as u32;
                enter(wv, &mut edges);
                frames.push((wv, e0, e0, true));
                continue;
            }
            // v is finished.
            let root = *root;
            edges.truncate(e_start as usize);
            frames.pop();
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
                        let mut words = vec![0u64; w];
                        for m in members() {
                            layout.load(g.store.state(m), &mut words);
                            for (t, e) in enabled_union.iter_mut().enumerate() {
                                if !*e && packed_net.enabled(&words, t) {
                                    *e = true;
                                }
                            }
                        }
                        if enabled_union.iter().any(|e| !e) {
                            live = false;
                        }
                    }
                }
                for m in members().collect::<Vec<_>>() {
                    rindex[m] = comp;
                    set(&mut done, m);
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
                        parent.3 = false;
                    }
                } else {
                    set(&mut leaves, ui);
                }
            }
        }
    }
    Some(Components {
        count: comp as usize,
        terminal,
        live,
        reversible: terminal == 1 && initial_terminal,
    })
}
