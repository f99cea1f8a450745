//! Explicit reachability graph of a bounded net, stored compactly.
//!
//! Markings are bit-packed (each place gets just enough bits for the largest value seen;
//! a value that does not fit widens that place's field by one bit and re-lays the states
//! found so far in place, chunk by chunk, keeping their numbers, so the exploration goes
//! on where it was) into an arena of chunks of 2^16 states. The index is a table of
//! `u32` entries (a state number in the low 27 bits, 5 bits of the hash above, so most
//! mismatches are told without reading the arena) split into 256 segments by the hash's
//! top bits, each an open-addressing table with linear probing, load ≤ 0.85, doubled on
//! its own (the segments start at sizes spread over one doubling, so they do not all
//! grow at once): growing holds one segment twice, never the whole table. A marking's
//! hash is `finish(Σ m[p] · weight(p))`: it does not depend on the layout (widening a
//! field leaves the table as it is) and a transition adds a constant to the sum, so a
//! successor's hash costs an addition and a finaliser.
//!
//! States are numbered in breadth-first order and only the first state of each BFS level
//! is kept: a shortest firing sequence to a state is rebuilt backwards, firing
//! transitions in reverse and looking the predecessor up in the previous level (the one
//! of smallest number: the BFS parent). So a state costs its packed marking and about
//! five to seven bytes of table, nothing else.
//!
//! Each level is expanded [`BATCH`] states at a time in two phases. First the batch's
//! successors are computed and looked up, the store only read, on `threads` threads
//! (each a contiguous part of the batch). Most successors of a batch are successors of
//! other states of the batch too (60 % on Kanban), so a small table keeps the first of
//! each marking ([`dedupe`]) and only those are looked up. The look-ups go one after
//! the other, but each asks the processor for its table slot, and for the state that
//! slot names, a few look-ups in advance ([`Store::find_all`]), so that their cache
//! misses overlap. Then the successors not found are numbered and appended to the arena
//! on one thread, in the order of their states and transitions (with several threads, a
//! small table of the batch's candidates tells the first of each marking), and entered in
//! the table together, its segments split between the threads ([`Store::enter_all`]):
//! the states' numbers, hence every
//! result (shortest traces included), are the same whatever the number of threads. The
//! buffers of both phases are kept from batch to batch, and markings of one or two words
//! (up to 16 bytes, most nets) have their own compiled copy of the scan and the look-ups.
//! A marking's hash sum is read byte by byte from tables (it is linear in the marking's
//! bits), not field by field; a transition's tests, effect and growth are one record
//! ([`Packed`]).
//!
//! Edges are not stored. Liveness and reversibility ([`components`]) first search
//! backwards from the initial state (predecessors recomputed and looked up, one bit per
//! state, level by level on `threads` threads): when every state reaches the initial
//! one, the graph is strongly connected. Otherwise one iterative Tarjan pass (Pearce's
//! one-word-per-state variant, [`tarjan`]) recomputes successors.
//!
//! While exploring, each new state that raises some place above its largest value so
//! far is compared with its ancestors (its BFS parents, found as for traces): a state
//! strictly covering an ancestor proves the net unbounded (Karp–Miller's criterion), and
//! this check alone guarantees termination. With inhibitor arcs the criterion is used
//! only when the places that grew carry no inhibitor arc (enabling stays monotone in the
//! others).

use super::{Control, Part, Progress};
use crate::PtNet;
use std::sync::atomic::{AtomicU64, Ordering};

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
    /// Each place's weight in the hash ([`hash_marking`]).
    mix: Vec<u64>,
    /// Per byte of a packed marking, per value of the byte: what it adds to
    /// [`Layout::linear`] (the sum is linear in the bits, with wrapping arithmetic); empty
    /// when the markings are longer than [`TABLE_BYTES`].
    by_byte: Vec<[u64; 256]>,
    /// Per byte, per value: the places (bit `p` for place `p`) it has a token in; empty
    /// with more than 64 places or markings longer than [`TABLE_BYTES`].
    marked_by_byte: Vec<[u64; 256]>,
    /// Per byte, per value: the tokens it holds ([`Layout::tokens`]); empty when the
    /// markings are longer than [`TABLE_BYTES`].
    tokens_by_byte: Vec<[u64; 256]>,
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

/// The transitions compiled onto a layout: a record per transition, its arcs in three
/// arrays shared by all (so that a state's successors are computed from a few cache
/// lines).
struct Packed {
    trans: Vec<Trans>,
    /// Enabling tests: `(field with the weight, at least)`; `at least` false for
    /// inhibitors.
    tests: Vec<(Field, bool)>,
    /// Per word: what firing adds (wrapping: removal as two's complement).
    delta: Vec<(u32, u64)>,
    /// The places a transition adds to, with what it adds (`post - pre`, > 0).
    grow: Vec<(Field, usize)>,
}

/// One transition of [`Packed`]: its parts of the shared arrays, and what its firing
/// adds to the hash's sum.
#[derive(Clone, Copy)]
struct Trans {
    tests: (u32, u32),
    delta: (u32, u32),
    grow: (u32, u32),
    /// `Σ (post - pre)[p] · weight(p)`.
    hash_shift: u64,
    /// The places it needs a token in (bit `p` for place `p`); 0 when the layout has no
    /// tables of marked places ([`Layout::marked`]).
    need: u64,
    /// Whether `need` is all its tests say (weights 1, no inhibitor arc, tables there).
    by_need: bool,
}

fn range<T>(v: &[T], (a, b): (u32, u32)) -> &[T] {
    &v[a as usize..b as usize]
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
        let mut packed = Packed {
            trans: Vec::with_capacity(nt),
            tests: Vec::new(),
            delta: Vec::new(),
            grow: Vec::new(),
        };
        let at = |v: usize| v as u32;
        for t in 0..nt {
            // Inputs and reads with the same place: the larger weight is the test.
            let mut need: Vec<(usize, u32)> = net.pre[t].clone();
            for &(p, w) in &net.reads[t] {
                match need.iter_mut().find(|(q, _)| *q == p) {
                    Some((_, v)) => *v = (*v).max(w),
                    None => need.push((p, w)),
                }
            }
            let tables = !layout.marked_by_byte.is_empty();
            let mask = if tables {
                need.iter().fold(0u64, |m, &(p, _)| m | 1 << p)
            } else {
                0
            };
            let by_need = tables && net.inhibitors[t].is_empty() && need.iter().all(|&(_, w)| w == 1);
            let tests = at(packed.tests.len());
            packed.tests.extend(need.iter().map(|&(p, w)| (field(p, w), true)));
            packed
                .tests
                .extend(net.inhibitors[t].iter().map(|&(p, w)| (field(p, w), false)));
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
            let delta = at(packed.delta.len());
            packed.delta.extend(d.into_iter().filter(|&(_, x)| x != 0));
            let grow = at(packed.grow.len());
            packed.grow.extend(net.post[t].iter().filter_map(|&(p, w)| {
                let taken = net.pre[t].iter().find(|(q, _)| *q == p).map_or(0, |&(_, v)| v);
                (w > taken).then(|| (field(p, w - taken), p))
            }));
            let sum = |arcs: &[(usize, u32)]| {
                arcs.iter().fold(0u64, |h, &(p, w)| {
                    h.wrapping_add(u64::from(w).wrapping_mul(place_weight(p)))
                })
            };
            packed.trans.push(Trans {
                tests: (tests, at(packed.tests.len())),
                delta: (delta, at(packed.delta.len())),
                grow: (grow, at(packed.grow.len())),
                hash_shift: sum(&net.post[t]).wrapping_sub(sum(&net.pre[t])),
                need: mask,
                by_need,
            });
        }
        packed
    }

    /// The places `t` adds to, with what it adds.
    #[inline]
    fn grow(&self, t: usize) -> &[(Field, usize)] {
        range(&self.grow, self.trans[t].grow)
    }

    #[inline]
    fn enabled(&self, w: &[u64], t: usize) -> bool {
        range(&self.tests, self.trans[t].tests)
            .iter()
            .all(|&(f, at_least)| (f.get(w) >= f.weight) == at_least)
    }

    /// Whether `t` is enabled in `w`, whose marked places are `marked` ([`Layout::marked`]):
    /// most transitions are told by their needs alone.
    #[inline(always)]
    fn enabled_in(&self, w: &[u64], marked: u64, t: usize) -> bool {
        let tr = &self.trans[t];
        if marked & tr.need != tr.need {
            return false;
        }
        tr.by_need || self.enabled(w, t)
    }

    /// Fires enabled `t` from `cur` into `next`; `Err(p)` when place `p` would overflow
    /// its field.
    #[inline(always)]
    fn fire(&self, cur: &[u64], next: &mut [u64], t: usize) -> Result<(), usize> {
        let tr = &self.trans[t];
        for &(f, p) in range(&self.grow, tr.grow) {
            if f.get(cur) + f.weight > f.mask {
                return Err(p);
            }
        }
        next.copy_from_slice(cur);
        for &(w, x) in range(&self.delta, tr.delta) {
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
        let mix: Vec<u64> = (0..bits.len()).map(place_weight).collect();
        // Bit `b` of field `p` adds `mix[p] << b` (wrapping) to the sum, is a token in
        // place `p`, and `1 << b` tokens.
        let mut by_bit = vec![[0u64; 3]; bytes * 8];
        for p in 0..bits.len() {
            for b in 0..bits[p].min(64) {
                if let Some(x) = by_bit.get_mut((64 * word[p] + shift[p] + b) as usize) {
                    *x = [
                        mix[p].wrapping_shl(b),
                        1u64.wrapping_shl(p as u32),
                        1u64.wrapping_shl(b),
                    ];
                }
            }
        }
        // Per byte, per value: the bits' contributions of kind `i`, summed (`add`) or
        // or-ed.
        let tables = |i: usize, add: bool| -> Vec<[u64; 256]> {
            by_bit
                .chunks(8)
                .map(|bit| {
                    let mut t = [0u64; 256];
                    for (v, x) in t.iter_mut().enumerate() {
                        *x = (0..8)
                            .filter(|b| v >> b & 1 == 1)
                            .fold(0u64, |s, b| if add { s.wrapping_add(bit[b][i]) } else { s | bit[b][i] });
                    }
                    t
                })
                .collect()
        };
        let small = bytes <= TABLE_BYTES;
        Layout {
            by_byte: if small { tables(0, true) } else { Vec::new() },
            marked_by_byte: if small && bits.len() <= 64 {
                tables(1, false)
            } else {
                Vec::new()
            },
            tokens_by_byte: if small { tables(2, true) } else { Vec::new() },
            mix,
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

    /// `Σ m[p] · weight(p)` of a packed marking (the hash before [`finish`]).
    #[inline]
    fn linear(&self, words: &[u64]) -> u64 {
        if !self.by_byte.is_empty() {
            return sum_by_byte(&self.by_byte, words);
        }
        (0..self.bits.len()).fold(0u64, |h, p| {
            let b = self.bits[p];
            let mask = if b >= 64 { u64::MAX } else { (1u64 << b) - 1 };
            let v = (words[self.word[p] as usize] >> self.shift[p]) & mask;
            h.wrapping_add(v.wrapping_mul(self.mix[p]))
        })
    }

    /// The places marked in a packed marking (bit `p` for place `p`), when there are at
    /// most 64 places and the tables are there ([`Packed::enabled_in`]).
    #[inline]
    fn marked(&self, words: &[u64]) -> u64 {
        let mut m = 0u64;
        for (k, t) in self.marked_by_byte.iter().enumerate() {
            m |= t[(words[k / 8] >> (8 * (k % 8))) as usize & 0xff];
        }
        m
    }

    /// The sum of the fields of a packed marking.
    #[inline]
    fn tokens(&self, words: &[u64]) -> u64 {
        if !self.tokens_by_byte.is_empty() {
            return sum_by_byte(&self.tokens_by_byte, words);
        }
        (0..self.bits.len())
            .map(|p| {
                let b = self.bits[p];
                let mask = if b >= 64 { u64::MAX } else { (1u64 << b) - 1 };
                (words[self.word[p] as usize] >> self.shift[p]) & mask
            })
            .sum()
    }
}

/// `Σ tables[k][byte k of words]` (wrapping): a sum linear in the marking's bits, one
/// table look-up per byte.
#[inline]
fn sum_by_byte(tables: &[[u64; 256]], words: &[u64]) -> u64 {
    tables.iter().enumerate().fold(0u64, |h, (k, t)| {
        h.wrapping_add(t[(words[k / 8] >> (8 * (k % 8))) as usize & 0xff])
    })
}

#[inline]
fn words_to_bytes(words: &[u64], out: &mut [u8]) {
    for (i, chunk) in out.chunks_mut(8).enumerate() {
        let b = words[i].to_le_bytes();
        chunk.copy_from_slice(&b[..chunk.len()]);
    }
}

/// The splitmix64 finaliser: every bit of `x` reaches every bit of the result.
#[inline]
fn finish(mut x: u64) -> u64 {
    x ^= x >> 30;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 27;
    x = x.wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// The random odd weight of place `p` in the markings' hash.
fn place_weight(p: usize) -> u64 {
    finish((p as u64).wrapping_add(0x243f_6a88_85a3_08d3)) | 1
}

/// The hash of a marking: `finish(Σ m[p] · weight(p))`. The sum does not depend on the
/// layout (widening a field keeps every state's hash, so the table stays as it is), and
/// a transition adds the same constant to it wherever it fires, so a successor's hash
/// costs an addition.
fn hash_marking(m: &[u32]) -> u64 {
    finish(m.iter().enumerate().fold(0u64, |h, (p, &v)| {
        h.wrapping_add(u64::from(v).wrapping_mul(place_weight(p)))
    }))
}

const EMPTY: u32 = u32::MAX;
/// Markings up to this many bytes have their hash summed byte by byte from tables
/// ([`Layout::linear`]); 2 KiB of tables a byte.
const TABLE_BYTES: usize = 32;
/// Bits of a table entry that number the state.
const INDEX_BITS: u32 = 27;
const INDEX_MASK: u32 = (1 << INDEX_BITS) - 1;
/// The most states a table entry can number (the all-ones index is the empty mark).
pub const MAX_STATES: usize = INDEX_MASK as usize - 1;
/// States per arena chunk.
const CHUNK_STATES: usize = 1 << 16;
/// Zero bytes after the last state of a chunk, so that any state's words are read whole.
const PAD: usize = 8;
/// The table is split into `2^SEGMENT_BITS` segments (by the hash's top bits), each an
/// open-addressing table grown on its own: growing never holds two whole tables.
const SEGMENT_BITS: u32 = 8;
const SEGMENTS: usize = 1 << SEGMENT_BITS;
/// Slots of a new segment.
const MIN_SLOTS: usize = 16;
/// A segment grows past this load (per mille).
const MAX_LOAD: usize = 850;
/// Load after the exploration, when the segments are compacted (per mille).
const FINAL_LOAD: usize = 850;
/// A segment grows by this factor (per mille of its slots), so that a state is placed
/// again about twice; the segments' sizes start spread over one growth step (see
/// [`Store::new`]), so they do not all grow at once and the table's load stays near its
/// mean (about 0.82 of the most).
const GROWTH: usize = 1500;
/// The fewest entries [`Store::enter_all`] splits between threads.
const PARALLEL_ENTRIES: usize = 1024;
/// The fewest states a thread of [`scan_parallel`] takes.
const GROUP: usize = 32;

#[inline]
fn tag(h: u64) -> u32 {
    ((h as u32) & 31) << INDEX_BITS
}

#[inline]
fn segment(h: u64) -> usize {
    (h >> (64 - SEGMENT_BITS)) as usize
}

/// The first slot of hash `h` in a segment of `n` slots (Lemire's multiply-shift on the
/// bits below the segment's).
#[inline]
fn home(h: u64, n: usize) -> usize {
    ((u128::from(h << SEGMENT_BITS) * n as u128) >> 64) as usize
}

#[inline]
fn read_word(chunk: &[u8], at: usize) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&chunk[at..at + 8]);
    u64::from_le_bytes(b)
}

/// The arena's packed states, read only: what a look-up compares with and what a growing
/// segment of the table hashes again.
#[derive(Clone, Copy)]
struct States<'a> {
    chunks: &'a [Vec<u8>],
    layout: &'a Layout,
}

impl States<'_> {
    /// The mask of the last word of a packed marking.
    #[inline(always)]
    fn last_mask(&self) -> u64 {
        match self.layout.bytes % 8 {
            0 => u64::MAX,
            r => (1u64 << (8 * r)) - 1,
        }
    }

    /// The chunk of state `i`, and where in it the state starts.
    #[inline(always)]
    fn locate(&self, i: usize) -> (&[u8], usize) {
        (&self.chunks[i / CHUNK_STATES], (i % CHUNK_STATES) * self.layout.bytes)
    }

    /// The words of state `i`.
    #[inline(always)]
    fn load(&self, i: usize, words: &mut [u64]) {
        let (chunk, at) = self.locate(i);
        let last = words.len() - 1;
        for (k, w) in words.iter_mut().enumerate() {
            *w = read_word(chunk, at + 8 * k);
        }
        words[last] &= self.last_mask();
    }

    /// Whether state `i` is `words`.
    #[inline(always)]
    fn equal(&self, i: usize, words: &[u64]) -> bool {
        let (chunk, at) = self.locate(i);
        let last = words.len() - 1;
        for (k, &w) in words[..last].iter().enumerate() {
            if read_word(chunk, at + 8 * k) != w {
                return false;
            }
        }
        read_word(chunk, at + 8 * last) & self.last_mask() == words[last]
    }

    /// The first byte of state `i`.
    #[inline(always)]
    fn ptr(&self, i: usize) -> &u8 {
        let (chunk, at) = self.locate(i);
        &chunk[at]
    }
}

/// Places entry `e` (state `e & INDEX_MASK`, hash `h`) in `table`.
#[inline]
fn place(table: &mut [u32], h: u64, e: u32) {
    let n = table.len();
    let mut slot = home(h, n);
    while table[slot] != EMPTY {
        slot += 1;
        if slot == n {
            slot = 0;
        }
    }
    table[slot] = e;
}

/// Rebuilds a segment of the table with `slots` slots: its entries placed again, their
/// hashes computed from `states`.
fn rebuild(table: &mut Vec<u32>, slots: usize, states: States<'_>) {
    let entries: Vec<u32> = table.iter().copied().filter(|&e| e != EMPTY).collect();
    *table = vec![EMPTY; slots];
    let mut words = vec![0u64; states.layout.words];
    for (k, &e) in entries.iter().enumerate() {
        if let Some(&ahead) = entries.get(k + AHEAD) {
            prefetch(states.ptr((ahead & INDEX_MASK) as usize));
        }
        states.load((e & INDEX_MASK) as usize, &mut words);
        place(table, finish(states.layout.linear(&words)), e);
    }
}

/// The packed states and their index.
pub struct Store {
    /// Layout of the packed markings.
    pub layout: Layout,
    /// `CHUNK_STATES` states each, `layout.bytes` apiece, then `PAD` zero bytes.
    chunks: Vec<Vec<u8>>,
    /// The segments of the table: `u32` entries, a state number in the low 27 bits and
    /// 5 bits of the hash above.
    segments: Vec<Vec<u32>>,
    /// Entries per segment.
    fill: Vec<u32>,
    len: usize,
    /// Bytes allocated (chunks' capacity and segments).
    bytes: usize,
    /// The most bytes used at once.
    peak: usize,
}

impl Store {
    fn new(layout: Layout) -> Store {
        // Segment `i` starts with `MIN_SLOTS · GROWTH^(i / SEGMENTS)` slots.
        let step = GROWTH as f64 / 1000.0;
        let segments: Vec<Vec<u32>> = (0..SEGMENTS)
            .map(|i| vec![EMPTY; (MIN_SLOTS as f64 * step.powf(i as f64 / SEGMENTS as f64)) as usize])
            .collect();
        let bytes = segments.iter().map(|t| t.len() * 4).sum();
        Store {
            layout,
            chunks: Vec::new(),
            segments,
            fill: vec![0; SEGMENTS],
            len: 0,
            bytes,
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

    /// The arena's states.
    #[inline(always)]
    fn states(&self) -> States<'_> {
        States {
            chunks: &self.chunks,
            layout: &self.layout,
        }
    }

    /// The table's segments, to change, and the arena's states, to read.
    fn segments_and_states(&mut self) -> (&mut [Vec<u32>], States<'_>) {
        let states = States {
            chunks: &self.chunks,
            layout: &self.layout,
        };
        (&mut self.segments, states)
    }

    /// The words of state `i`.
    #[inline]
    pub fn load(&self, i: usize, words: &mut [u64]) {
        self.states().load(i, words);
    }

    /// The marking of state `i` (unpacked into `m`).
    pub fn marking(&self, i: usize, words: &mut [u64], m: &mut [u32]) {
        self.load(i, &mut words[..self.layout.words]);
        self.layout.unpack_words(words, m);
    }

    /// Appends a state's words to the arena: its number.
    fn push(&mut self, words: &[u64]) -> u32 {
        let n = self.layout.bytes;
        if self.len == self.chunks.len() * CHUNK_STATES {
            // The first chunk grows by doubling (a small net does not take a whole one).
            let cap = if self.chunks.is_empty() {
                64 * n + PAD
            } else {
                CHUNK_STATES * n + PAD
            };
            let mut c = Vec::with_capacity(cap);
            c.resize(PAD, 0);
            self.bytes += c.capacity();
            self.chunks.push(c);
        }
        let Some(chunk) = self.chunks.last_mut() else {
            return self.len as u32;
        };
        let before = chunk.capacity();
        let at = chunk.len() - PAD;
        chunk.resize(at + n + PAD, 0);
        words_to_bytes(words, &mut chunk[at..at + n]);
        self.bytes = self.bytes + chunk.capacity() - before;
        self.peak = self.peak.max(self.bytes);
        self.len += 1;
        (self.len - 1) as u32
    }

    /// Probes segment `seg` for `words` (hash `h`): `Ok(index)` when present, else
    /// `Err(slot)`, the empty slot where it would go.
    #[inline(always)]
    fn probe(&self, seg: usize, h: u64, words: &[u64]) -> Result<u32, usize> {
        let table = &self.segments[seg];
        let n = table.len();
        let mut slot = home(h, n);
        let t = tag(h);
        loop {
            let e = table[slot];
            if e == EMPTY {
                return Err(slot);
            }
            if e & !INDEX_MASK == t && self.states().equal((e & INDEX_MASK) as usize, words) {
                return Ok(e & INDEX_MASK);
            }
            slot += 1;
            if slot == n {
                slot = 0;
            }
        }
    }

    /// Index of `words` (hash `h`) if present.
    #[inline(always)]
    fn find(&self, h: u64, words: &[u64]) -> Option<u32> {
        self.probe(segment(h), h, words).ok()
    }

    /// The home slot of hash `h`.
    #[inline]
    fn home_slot(&self, h: u64) -> &u32 {
        let table = &self.segments[segment(h)];
        &table[home(h, table.len())]
    }

    /// Looks up the markings `words[k * w..(k + 1) * w]` (hashes `hashes[k]`) one after
    /// the other, into `found`: each one's number or [`EMPTY`]. Each asks for its home
    /// slot [`AHEAD`] look-ups in advance, and for the state that slot names half as far
    /// ([`prefetch`]), so that the cache misses of several look-ups overlap.
    fn find_all(&self, hashes: &[u64], words: &[u64], found: &mut Vec<u32>) {
        match self.layout.words {
            1 => self.find_all_in::<1>(hashes, words, found),
            2 => self.find_all_in::<2>(hashes, words, found),
            _ => self.find_all_in::<0>(hashes, words, found),
        }
    }

    /// [`Store::find_all`] for markings of `W` words (0: any number), so that the
    /// compiler knows the markings' length in the most common cases.
    #[inline]
    fn find_all_in<const W: usize>(&self, hashes: &[u64], words: &[u64], found: &mut Vec<u32>) {
        let w = if W > 0 { W } else { self.layout.words };
        found.clear();
        found.resize(hashes.len(), EMPTY);
        for (k, &h) in hashes.iter().enumerate() {
            if let Some(&ahead) = hashes.get(k + AHEAD) {
                prefetch(self.home_slot(ahead));
            }
            if let Some(&ahead) = hashes.get(k + AHEAD / 2) {
                let e = *self.home_slot(ahead);
                if e != EMPTY {
                    prefetch(self.states().ptr((e & INDEX_MASK) as usize));
                }
            }
            if let Some(i) = self.find(h, &words[k * w..(k + 1) * w]) {
                found[k] = i;
            }
        }
    }

    /// Room in the arena for one more state: `false` when the memory budget does not
    /// allow it.
    #[inline]
    fn room_in_arena(&self, memory: usize) -> bool {
        self.len < self.chunks.len() * CHUNK_STATES || self.bytes + CHUNK_STATES * self.layout.bytes + PAD <= memory
    }

    /// Enters the states numbered from `first` on (hashes `hashes`, in the arena already)
    /// in the table. Each segment first grows to the size its new entries need, then
    /// takes them in order; the segments are split between `threads` threads. `false`,
    /// with nothing entered, when the grown table would take more than `memory` bytes.
    fn enter_all(&mut self, hashes: &[u64], first: u32, memory: usize, threads: usize) -> bool {
        let mut fill = self.fill.clone();
        for &h in hashes {
            fill[segment(h)] += 1;
        }
        let old = |seg: usize| self.segments[seg].len();
        let sizes: Vec<usize> = (0..SEGMENTS)
            .map(|seg| {
                let mut slots = old(seg);
                while fill[seg] as usize * 1000 > slots * MAX_LOAD {
                    slots = (slots * GROWTH / 1000).max(slots + MIN_SLOTS);
                }
                slots
            })
            .collect();
        let grown: usize = (0..SEGMENTS).map(|seg| (sizes[seg] - old(seg)) * 4).sum();
        // Each thread holds one segment twice while it rebuilds it.
        let twice = (0..SEGMENTS)
            .filter(|&seg| sizes[seg] > old(seg))
            .map(old)
            .max()
            .unwrap_or(0)
            * 4
            * threads;
        if self.bytes + grown + twice > memory {
            return false;
        }
        self.peak = self.peak.max(self.bytes + grown + twice);
        self.bytes += grown;
        self.fill = fill;
        let (segments, states) = self.segments_and_states();
        let enter = |segments: &mut [Vec<u32>], base: usize| {
            for (table, &slots) in segments.iter_mut().zip(&sizes[base..]) {
                if slots > table.len() {
                    rebuild(table, slots, states);
                }
            }
            let mine = base..base + segments.len();
            for (k, &h) in hashes.iter().enumerate() {
                if let Some(&ahead) = hashes.get(k + AHEAD) {
                    let seg = segment(ahead);
                    if mine.contains(&seg) {
                        let table = &segments[seg - base];
                        prefetch(&table[home(ahead, table.len())]);
                    }
                }
                let seg = segment(h);
                if mine.contains(&seg) {
                    place(&mut segments[seg - base], h, tag(h) | (first + k as u32));
                }
            }
        };
        if threads > 1 && hashes.len() >= PARALLEL_ENTRIES {
            let (a, b) = segments.split_at_mut(SEGMENTS / 2);
            std::thread::scope(|scope| {
                scope.spawn(|| enter(b, SEGMENTS / 2));
                enter(a, 0);
            });
        } else {
            enter(segments, 0);
        }
        true
    }

    /// Shrinks the segments to load [`FINAL_LOAD`] (after the exploration).
    fn shrink(&mut self) {
        for seg in 0..SEGMENTS {
            let slots = (self.fill[seg] as usize * 1000 / FINAL_LOAD + 1).max(MIN_SLOTS);
            let old = self.segments[seg].len();
            if slots < old {
                let (segments, states) = self.segments_and_states();
                rebuild(&mut segments[seg], slots, states);
                self.bytes -= (old - slots) * 4;
            }
        }
    }

    /// Index of the unpacked marking `m`, if it fits the layout and is present.
    fn find_marking(&self, m: &[u32]) -> Option<u32> {
        let mut words = vec![0u64; self.layout.words];
        self.layout.pack(m, &mut words).ok()?;
        self.find(hash_marking(m), &words)
    }

    /// Bytes used by the arena and the table.
    pub fn bytes_used(&self) -> usize {
        self.bytes
    }

    /// Widens the fields to `layout` (wider or as wide on every place) in place, chunk
    /// by chunk (the chunks split between `threads` threads), keeping the states' numbers
    /// and the table.
    fn widen(&mut self, layout: Layout, threads: usize) {
        let n = layout.bytes;
        let mut counts = Vec::with_capacity(self.chunks.len());
        for (c, chunk) in self.chunks.iter_mut().enumerate() {
            let k = (self.len - c * CHUNK_STATES).min(CHUNK_STATES);
            let before = chunk.capacity();
            let want = if c == 0 && self.len <= CHUNK_STATES {
                k * n + PAD
            } else {
                CHUNK_STATES * n + PAD
            };
            chunk.reserve_exact(want.saturating_sub(chunk.len()));
            chunk.resize((k * n + PAD).max(chunk.len()), 0);
            self.bytes = self.bytes + chunk.capacity() - before;
            self.peak = self.peak.max(self.bytes);
            counts.push(k);
        }
        let old = &self.layout;
        let runs = runs(old, &layout);
        let relay = |chunks: &mut [Vec<u8>], counts: &[usize]| {
            for (chunk, &k) in chunks.iter_mut().zip(counts) {
                relay_chunk(chunk, k, old, &layout, &runs);
            }
        };
        let half = self.chunks.len() / 2;
        if threads > 1 && half > 0 {
            let (a, b) = self.chunks.split_at_mut(half);
            let (ca, cb) = counts.split_at(half);
            std::thread::scope(|scope| {
                scope.spawn(|| relay(b, cb));
                relay(a, ca);
            });
        } else {
            relay(&mut self.chunks, &counts);
        }
        // The states' hashes do not depend on the layout: the table stays as it is.
        self.layout = layout;
    }
}

/// A run of fields that keep their order and spacing from one layout to a wider one:
/// the `mask` bits at `shift` of word `word` go to word `to` at `to_shift`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Run {
    word: u32,
    shift: u32,
    mask: u64,
    to: u32,
    to_shift: u32,
}

/// The runs that re-lay a marking from `old` to `new` (wider or as wide on every
/// place): consecutive places move together while they stay in one word of each and
/// move by the same number of bits, so widening one place splits the fields in a few
/// runs, not one per place.
fn runs(old: &Layout, new: &Layout) -> Vec<Run> {
    let mut out: Vec<Run> = Vec::new();
    for p in 0..old.bits.len() {
        let bits = old.bits[p].min(64);
        let (word, shift, to, to_shift) = (old.word[p], old.shift[p], new.word[p], new.shift[p]);
        let mask = if bits >= 64 {
            u64::MAX
        } else {
            ((1u64 << bits) - 1) << shift
        };
        match out.last_mut() {
            Some(r) if r.word == word && r.to == to && r.to_shift + shift == r.shift + to_shift => r.mask |= mask,
            _ => out.push(Run {
                word,
                shift,
                mask,
                to,
                to_shift,
            }),
        }
    }
    // The masks were gathered at the fields' places in the word: bring them to the run's
    // start.
    for r in &mut out {
        r.mask >>= r.shift;
    }
    out
}

/// Re-lays the `k` states of `chunk` from layout `old` to the wider `new` (the chunk
/// already long enough) by `runs`, from the last state down: state `j`'s new place
/// starts at or after the old end of every state before it.
fn relay_chunk(chunk: &mut [u8], k: usize, old: &Layout, new: &Layout, runs: &[Run]) {
    let (old_n, n) = (old.bytes, new.bytes);
    let mut words = vec![0u64; old.words];
    let mut wide = vec![0u64; new.words];
    let old_mask = match old_n % 8 {
        0 => u64::MAX,
        r => (1u64 << (8 * r)) - 1,
    };
    let last = words.len() - 1;
    for j in (0..k).rev() {
        for (i, w) in words.iter_mut().enumerate() {
            *w = read_word(chunk, j * old_n + 8 * i);
        }
        words[last] &= old_mask;
        wide.iter_mut().for_each(|w| *w = 0);
        for r in runs {
            wide[r.to as usize] |= ((words[r.word as usize] >> r.shift) & r.mask) << r.to_shift;
        }
        words_to_bytes(&wide, &mut chunk[j * n..(j + 1) * n]);
    }
    chunk[k * n..].iter_mut().for_each(|b| *b = 0);
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
    /// The most bytes the exploration used at once.
    pub peak_bytes: usize,
    net: PtNet,
}

/// The BFS level of state `s` given the first state of each level.
fn level_of(levels: &[u32], s: u32) -> usize {
    levels.partition_point(|&l| l <= s) - 1
}

/// The BFS parent of state `s` (marking `m`) of level `k > 0` and the transition from
/// it: the first state of the previous level with an edge to `s` (the one whose
/// successors first found it), and the first transition, in net order, taking it there.
fn bfs_parent(net: &PtNet, store: &Store, levels: &[u32], k: usize, m: &[u32]) -> Option<(usize, u32)> {
    let (lo, hi) = (levels[k - 1], levels[k]);
    (0..net.transitions.len())
        .filter_map(|t| {
            let mut prev = m.to_vec();
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
        .min_by_key(|&(t, i)| (i, t))
}

/// A shortest firing sequence from the initial state to `s` (BFS parents, rebuilt
/// backwards).
fn trace_back(net: &PtNet, store: &Store, levels: &[u32], mut s: u32) -> Vec<usize> {
    let np = net.places.len();
    let mut words = vec![0u64; store.layout.words];
    let mut m = vec![0u32; np];
    let mut out = Vec::new();
    let mut k = level_of(levels, s);
    while k > 0 {
        store.marking(s as usize, &mut words, &mut m);
        // Unreachable `None`: every state of level k has a predecessor in level k - 1.
        let Some((t, i)) = bfs_parent(net, store, levels, k, &m) else {
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

/// States of a level whose successors are computed (in parallel) before the new ones
/// are inserted (in order).
const BATCH: usize = 1 << 14;

/// States a batch takes from a net of `nt` transitions and markings of `w` words: at most
/// [`BATCH`], fewer when their successors could take more than 2^20 words (8 MiB; a
/// successor takes its words, its hash and its origin), so that nets of many transitions
/// and wide markings keep the buffers small. The batches do not change the states'
/// numbers.
fn batch_states(nt: usize, w: usize) -> usize {
    ((1 << 20) / (nt.max(1) * (w + 2))).clamp(GROUP, BATCH)
}

/// How many look-ups ahead [`Store::find_all`] asks for memory.
const AHEAD: usize = 32;

/// Asks the processor to bring the cache line of `x` in, without waiting for it.
#[inline(always)]
#[allow(unsafe_code)]
fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint: it changes no state the program can observe and
    // never faults (here the address is even a valid reference); SSE, which it needs,
    // is part of the x86_64 baseline.
    unsafe {
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>((x as *const T).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// A thread's part of a batch ([`Scan::scan`]): its buffers, kept from batch to batch,
/// and what it found: the successors not in the store yet (in the order of their states
/// and transitions) and the part's counts.
#[derive(Default)]
struct Scan {
    cur: Vec<u64>,
    succ: Vec<u64>,
    succ_hashes: Vec<u64>,
    from_to: Vec<(u32, u32)>,
    found: Vec<u32>,
    /// The table of [`dedupe`].
    local: Vec<u32>,
    /// `(state, transition)` of each successor not found.
    new: Vec<(u32, u32)>,
    /// Their packed words.
    words: Vec<u64>,
    /// Their hashes.
    hashes: Vec<u64>,
    edges: u64,
    deadlocks: u64,
    first_deadlock: Option<u32>,
    fired: Vec<bool>,
    max_tokens: u64,
    /// The first state (and place) whose successor did not fit its field: the part is
    /// done up to it.
    overflow: Option<(usize, usize)>,
}

impl Scan {
    /// The successors of states `from..to`, looked up in `store` (read only) together
    /// ([`Store::find_all`]).
    fn scan(&mut self, store: &Store, packed: &Packed, count_tokens: bool, from: usize, to: usize) {
        match store.layout.words {
            1 => self.scan_in::<1>(store, packed, count_tokens, from, to),
            2 => self.scan_in::<2>(store, packed, count_tokens, from, to),
            _ => self.scan_in::<0>(store, packed, count_tokens, from, to),
        }
    }

    /// [`Scan::scan`] for markings of `W` words (0: any number).
    fn scan_in<const W: usize>(&mut self, store: &Store, packed: &Packed, count_tokens: bool, from: usize, to: usize) {
        let layout = &store.layout;
        let w = if W > 0 { W } else { layout.words };
        let nt = packed.trans.len();
        self.new.clear();
        self.words.clear();
        self.hashes.clear();
        (self.edges, self.deadlocks, self.first_deadlock) = (0, 0, None);
        self.fired.clear();
        self.fired.resize(nt, false);
        (self.max_tokens, self.overflow) = (0, None);
        self.cur.resize(w, 0);
        self.succ.clear();
        self.succ_hashes.clear();
        self.from_to.clear();
        let (cur, succ, hashes) = (&mut self.cur, &mut self.succ, &mut self.succ_hashes);
        let cur = &mut cur[..w];
        'states: for x in from..to {
            store.load(x, cur);
            let lin = layout.linear(cur);
            let marked = layout.marked(cur);
            if count_tokens {
                self.max_tokens = self.max_tokens.max(layout.tokens(cur));
            }
            let before = hashes.len();
            for t in 0..nt {
                if !packed.enabled_in(cur, marked, t) {
                    continue;
                }
                self.fired[t] = true;
                let k = succ.len();
                succ.resize(k + w, 0);
                if let Err(p) = packed.fire(cur, &mut succ[k..k + w], t) {
                    succ.truncate(before * w);
                    hashes.truncate(before);
                    self.from_to.truncate(before);
                    self.overflow = Some((x, p));
                    break 'states;
                }
                hashes.push(finish(lin.wrapping_add(packed.trans[t].hash_shift)));
                self.from_to.push((x as u32, t as u32));
            }
            let n = (hashes.len() - before) as u64;
            self.edges += n;
            if n == 0 {
                self.deadlocks += 1;
                self.first_deadlock.get_or_insert(x as u32);
            }
        }
        // Most successors of a batch are successors of other states of the batch too
        // (60 % on Kanban): only the first of each marking is looked up.
        let n = dedupe::<W>(hashes, succ, &mut self.from_to, w, &mut self.local);
        store.find_all_in::<W>(&hashes[..n], &succ[..n * w], &mut self.found);
        for (k, &h) in hashes[..n].iter().enumerate().filter(|&(k, _)| self.found[k] == EMPTY) {
            self.new.push(self.from_to[k]);
            self.words.extend_from_slice(&succ[k * w..(k + 1) * w]);
            self.hashes.push(h);
        }
    }
}

/// Keeps the first of each marking among the successors `succ` (`w` words each, hashes
/// `hashes`, origins `from_to` unless empty), moved to the front in their order: their
/// number. `local` is the table of the ones kept (their positions), an open-addressing
/// table by the hashes' low bits.
fn dedupe<const W: usize>(
    hashes: &mut [u64],
    succ: &mut [u64],
    from_to: &mut [(u32, u32)],
    w: usize,
    local: &mut Vec<u32>,
) -> usize {
    let w = if W > 0 { W } else { w };
    let size = (2 * hashes.len()).next_power_of_two().max(16);
    local.clear();
    local.resize(size, EMPTY);
    let mut kept = 0;
    for k in 0..hashes.len() {
        let h = hashes[k];
        let mut slot = h as usize & (size - 1);
        let first = loop {
            let j = local[slot] as usize;
            if j == EMPTY as usize {
                local[slot] = kept as u32;
                break true;
            }
            // One or two words are compared at once; longer markings are compared
            // after their hashes.
            if (W > 0 || hashes[j] == h) && succ[j * w..(j + 1) * w] == succ[k * w..(k + 1) * w] {
                break false;
            }
            slot = (slot + 1) & (size - 1);
        };
        if first {
            hashes[kept] = h;
            if let Some(&o) = from_to.get(k) {
                from_to[kept] = o;
            }
            succ.copy_within(k * w..(k + 1) * w, kept * w);
            kept += 1;
        }
    }
    kept
}

/// Scans `from..to` on up to `parts.len()` threads, each a contiguous part (in order in
/// `parts`; the ones left over find nothing).
fn scan_parallel(store: &Store, packed: &Packed, count_tokens: bool, from: usize, to: usize, parts: &mut [Scan]) {
    let threads = parts.len().clamp(1, (to - from).div_ceil(GROUP).max(1));
    let step = (to - from).div_ceil(threads);
    let range = |k: usize| ((from + k * step).min(to), (from + (k + 1) * step).min(to));
    let Some((first, rest)) = parts.split_first_mut() else {
        return;
    };
    std::thread::scope(|scope| {
        let handles: Vec<_> = rest
            .iter_mut()
            .enumerate()
            .map(|(k, part)| {
                let (a, b) = range(k + 1);
                scope.spawn(move || part.scan(store, packed, count_tokens, a, b))
            })
            .collect();
        let (a, b) = range(0);
        first.scan(store, packed, count_tokens, a, b);
        // A scan does not panic on a consistent store; if one did, its part is scanned
        // again below.
        handles.into_iter().map(|h| h.join().is_ok()).collect::<Vec<_>>()
    })
    .into_iter()
    .enumerate()
    .filter(|&(_, ok)| !ok)
    .for_each(|(k, _)| {
        let (a, b) = range(k + 1);
        rest[k].scan(store, packed, count_tokens, a, b);
    });
}

/// Explores the reachability graph breadth-first within `limits`, on one thread.
pub fn explore(net: &PtNet, limits: &Limits, control: &Control<'_>) -> Explored {
    explore_threads(net, limits, 1, control)
}

/// Explores the reachability graph breadth-first within `limits`. Each level is taken
/// [`BATCH`] states at a time: `threads` threads compute the batch's successors and
/// look them up (the store is only read), then the new ones are inserted in the order
/// of their states and transitions, so the states' numbers, and every result, do not
/// depend on the number of threads.
pub fn explore_threads(net: &PtNet, limits: &Limits, threads: usize, control: &Control<'_>) -> Explored {
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
    let layout = Layout::new(bits.clone());
    let mut packed = Packed::new(net, &layout);
    let mut store = Store::new(layout.clone());
    let mut max = net.initial.clone();
    let mut max_tokens = net.initial.iter().map(|&v| u64::from(v)).sum::<u64>();
    let mut cur = vec![0u64; layout.words];
    if layout.pack(&net.initial, &mut cur).is_err() {
        return Explored::Overflow;
    }
    let h0 = hash_marking(&net.initial);
    let fits = store.room_in_arena(limits.memory) && {
        let i0 = store.push(&cur);
        store.enter_all(&[h0], i0, limits.memory, 1)
    };
    if !fits {
        return Explored::Limit {
            why: Stop::Memory,
            states: 0,
            bytes: store.bytes_used(),
        };
    }
    let mut levels: Vec<u32> = vec![0];
    let mut level_end = 1usize;
    let mut edges = 0u64;
    let mut deadlocks = 0u64;
    let mut first_deadlock = None;
    let mut fired = vec![false; nt];
    let mut m = vec![0u32; np];
    let mut anc = vec![0u32; np];
    let mut anc_words = vec![0u64; layout.words];
    let stop = |why, store: &Store, levels: &Vec<u32>| Explored::Limit {
        why,
        states: store.len(),
        bytes: store.bytes_used() + levels.capacity() * 4,
    };
    let mut parts: Vec<Scan> = (0..threads.max(1)).map(|_| Scan::default()).collect();
    let (mut new, mut words, mut hashes, mut seen) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    // The hashes of a batch's new states, entered in the table together.
    let mut entered = Vec::new();
    let mut s = 0usize;
    let mut reported = 0usize;
    while s < store.len() {
        if s == level_end {
            levels.push(s as u32);
            level_end = store.len();
        }
        // Every 16 384 states expanded or found (a net of many transitions finds its
        // million states from a few thousand).
        if s + store.len() >= reported {
            reported = s + store.len() + (1 << 14);
            if control.cancelled() {
                return stop(Stop::Cancelled, &store, &levels);
            }
            (control.progress)(&Progress {
                part: Part::StateSpace,
                states: store.len() as u64,
                bytes: store.bytes_used() + levels.capacity() * 4,
            });
        }
        let end = (s + batch_states(nt, store.layout.words)).min(level_end);
        scan_parallel(&store, &packed, !constant_tokens, s, end, &mut parts);
        let w = store.layout.words;
        // The candidates: the successors not found, part after part up to the first
        // overflow, in the order of their states and transitions.
        let mut overflow = None;
        let mut contributing = 0;
        new.clear();
        words.clear();
        hashes.clear();
        for part in &parts {
            edges += part.edges;
            deadlocks += part.deadlocks;
            if first_deadlock.is_none() {
                first_deadlock = part.first_deadlock;
            }
            fired.iter_mut().zip(&part.fired).for_each(|(f, &g)| *f |= g);
            max_tokens = max_tokens.max(part.max_tokens);
            contributing += usize::from(!part.new.is_empty());
            new.extend_from_slice(&part.new);
            words.extend_from_slice(&part.words);
            hashes.extend_from_slice(&part.hashes);
            if part.overflow.is_some() {
                overflow = part.overflow;
                break;
            }
        }
        // The first candidate of each marking is a new state; the others are found in
        // `seen`, a small table of the batch's candidates. A part's candidates are all
        // different ([`dedupe`]): with one part, each is the first.
        let size = (2 * new.len()).next_power_of_two().max(16);
        seen.clear();
        if contributing > 1 {
            seen.resize(size, EMPTY);
        }
        let budget = limits.memory.saturating_sub(levels.capacity() * 4);
        let first_new = store.len() as u32;
        entered.clear();
        for (k, &(x, t)) in new.iter().enumerate() {
            let (h, next) = (hashes[k], &words[k * w..(k + 1) * w]);
            // Karp–Miller at records: does the successor strictly cover an ancestor?
            // A record on a place read by an inhibitor arc rules every ancestor out
            // (the criterion needs equality there). Only the places the transition
            // adds to can set one, and only a new state can.
            let mut record = false;
            let mut inhibited_record = false;
            for &(f, p) in packed.grow(t as usize) {
                let v = f.get(next) as u32;
                if v > max[p] {
                    max[p] = v;
                    record = true;
                    inhibited_record |= inhibited[p];
                }
            }
            if record && !inhibited_record {
                store.layout.unpack_words(next, &mut m);
                // The ancestors: `x` and its BFS parents.
                let mut at = x;
                loop {
                    store.marking(at as usize, &mut anc_words, &mut anc);
                    let covers = m.iter().zip(&anc).all(|(x, y)| x >= y)
                        && m != anc
                        && m.iter().zip(&anc).zip(&inhibited).all(|((x, y), &inh)| x == y || !inh);
                    if covers {
                        return Explored::Unbounded;
                    }
                    let k = level_of(&levels, at);
                    if k == 0 {
                        break;
                    }
                    match bfs_parent(net, &store, &levels, k, &anc) {
                        Some((_, i)) => at = i,
                        None => break,
                    }
                }
            }
            let mut slot = h as usize & (size - 1);
            let first = contributing <= 1
                || loop {
                    let j = seen[slot] as usize;
                    if j == EMPTY as usize {
                        seen[slot] = k as u32;
                        break true;
                    }
                    if hashes[j] == h && words[j * w..(j + 1) * w] == *next {
                        break false;
                    }
                    slot = (slot + 1) & (size - 1);
                };
            if first {
                if !store.room_in_arena(budget) {
                    return stop(Stop::Memory, &store, &levels);
                }
                store.push(next);
                if store.len() > max_states {
                    return stop(Stop::States, &store, &levels);
                }
                entered.push(h);
            }
        }
        if !store.enter_all(&entered, first_new, budget, threads) {
            return stop(Stop::Memory, &store, &levels);
        }
        match overflow {
            Some((x, p)) => {
                // Widen the place that does not fit (in place), and go on from the state
                // whose successor did not fit.
                if bits[p] >= 32 {
                    return Explored::Overflow;
                }
                bits[p] += 1;
                let layout = Layout::new(bits.clone());
                packed = Packed::new(net, &layout);
                store.widen(layout, threads);
                anc_words = vec![0u64; store.layout.words];
                s = x;
            }
            None => s = end,
        }
    }
    let deadlock_trace = first_deadlock.map(|d| trace_back(net, &store, &levels, d));
    let peak_bytes = store.peak.max(store.bytes_used()) + levels.capacity() * 4;
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

/// Why the SCC pass did not complete.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SccStop {
    /// The cancellation flag.
    Cancelled,
    /// Tarjan's pass needs more than the memory left.
    Budget,
}

/// Bytes of the SCC pass when the graph is not strongly connected (Tarjan's word and
/// two bits per state).
pub fn tarjan_bytes(states: usize) -> usize {
    states * 4 + states.div_ceil(64) * 16
}

/// The strongly connected components, liveness and reversibility on `threads` threads,
/// with `memory` bytes left: `(components, bytes used)`.
///
/// First a backward breadth-first search from the initial state over predecessors
/// (transitions fired in reverse, looked up in the store; one bit per state): when it
/// reaches every state, the graph is one strongly connected component, reversible, and
/// live iff every transition fired. Otherwise Tarjan's pass ([`tarjan`]) counts the
/// components.
pub fn components(
    net: &PtNet,
    g: &Graph,
    threads: usize,
    memory: usize,
    control: &Control<'_>,
) -> Result<(Components, usize), SccStop> {
    let n = g.store.len();
    let (all, bytes) = reaches_initial(net, g, threads, control).ok_or(SccStop::Cancelled)?;
    if all {
        let live = g.fired.iter().all(|&f| f);
        return Ok((
            Components {
                count: 1,
                terminal: 1,
                live,
                reversible: true,
            },
            bytes,
        ));
    }
    if tarjan_bytes(n) > memory {
        return Err(SccStop::Budget);
    }
    let c = tarjan(net, g, control).ok_or(SccStop::Cancelled)?;
    Ok((c, bytes.max(tarjan_bytes(n))))
}

/// The predecessors of states `frontier`, each state seen for the first time (its bit
/// set in `seen`) once. States are taken [`batch_states`] at a time, their predecessors looked
/// up together ([`Store::find_all`]).
fn predecessors(g: &Graph, back: &Packed, fwd: &Packed, seen: &[AtomicU64], frontier: &[u32]) -> Vec<u32> {
    match g.store.layout.words {
        1 => predecessors_in::<1>(g, back, fwd, seen, frontier),
        2 => predecessors_in::<2>(g, back, fwd, seen, frontier),
        _ => predecessors_in::<0>(g, back, fwd, seen, frontier),
    }
}

/// [`predecessors`] for markings of `W` words (0: any number).
fn predecessors_in<const W: usize>(
    g: &Graph,
    back: &Packed,
    fwd: &Packed,
    seen: &[AtomicU64],
    frontier: &[u32],
) -> Vec<u32> {
    let store = &g.store;
    let w = if W > 0 { W } else { store.layout.words };
    let nt = back.trans.len();
    let mut cur = vec![0u64; w];
    let cur = &mut cur[..w];
    let mut prev: Vec<u64> = Vec::new();
    let mut hashes: Vec<u64> = Vec::new();
    let mut found: Vec<u32> = Vec::new();
    let mut local: Vec<u32> = Vec::new();
    let mut out = Vec::new();
    for chunk in frontier.chunks(batch_states(nt, w)) {
        prev.clear();
        hashes.clear();
        for &v in chunk {
            store.load(v as usize, cur);
            let lin = store.layout.linear(cur);
            let marked = store.layout.marked(cur);
            for t in 0..nt {
                if !back.enabled_in(cur, marked, t) {
                    continue;
                }
                let k = prev.len();
                prev.resize(k + w, 0);
                // A predecessor that does not fit the layout is not a state; one that
                // does must enable `t` (read and inhibitor arcs included).
                if back.fire(cur, &mut prev[k..k + w], t).is_err() || !fwd.enabled(&prev[k..k + w], t) {
                    prev.truncate(k);
                    continue;
                }
                hashes.push(finish(lin.wrapping_add(back.trans[t].hash_shift)));
            }
        }
        // As in the exploration, many predecessors of a chunk repeat one another.
        let n = dedupe::<W>(&mut hashes, &mut prev, &mut [], w, &mut local);
        store.find_all_in::<W>(&hashes[..n], &prev[..n * w], &mut found);
        for &i in found.iter().filter(|&&i| i != EMPTY) {
            let (word, bit) = (&seen[i as usize / 64], 1u64 << (i % 64));
            if word.load(Ordering::Relaxed) & bit == 0 && word.fetch_or(bit, Ordering::Relaxed) & bit == 0 {
                out.push(i);
            }
        }
    }
    out
}

/// Whether every state reaches the initial one (backward breadth-first search, level by
/// level, each level's states split between `threads` threads), and the bytes it used;
/// `None` when cancelled.
fn reaches_initial(net: &PtNet, g: &Graph, threads: usize, control: &Control<'_>) -> Option<(bool, usize)> {
    let n = g.store.len();
    let layout = &g.store.layout;
    let reversed = PtNet {
        pre: net.post.clone(),
        post: net.pre.clone(),
        reads: vec![Vec::new(); net.transitions.len()],
        inhibitors: vec![Vec::new(); net.transitions.len()],
        ..net.clone()
    };
    let back = Packed::new(&reversed, layout);
    let fwd = Packed::new(net, layout);
    let seen: Vec<AtomicU64> = (0..n.div_ceil(64)).map(|_| AtomicU64::new(0)).collect();
    seen[0].fetch_or(1, Ordering::Relaxed);
    let mut frontier = vec![0u32];
    let mut reached = 1usize;
    let mut bytes = seen.len() * 8;
    while !frontier.is_empty() {
        if control.cancelled() {
            return None;
        }
        (control.progress)(&Progress {
            part: Part::Components,
            states: reached as u64,
            bytes: g.bytes_used() + bytes,
        });
        let parts = threads.clamp(1, frontier.len().div_ceil(1 << 12));
        let next: Vec<u32> = if parts == 1 {
            predecessors(g, &back, &fwd, &seen, &frontier)
        } else {
            let step = frontier.len().div_ceil(parts);
            let (back, fwd, seen) = (&back, &fwd, &seen[..]);
            std::thread::scope(|scope| {
                let handles: Vec<_> = frontier[step..]
                    .chunks(step)
                    .map(|part| scope.spawn(move || predecessors(g, back, fwd, seen, part)))
                    .collect();
                let mut next = predecessors(g, back, fwd, seen, &frontier[..step]);
                for h in handles {
                    // Were a part to panic, the search would stop short: not every
                    // state reached, Tarjan's pass decides.
                    match h.join() {
                        Ok(v) => next.extend(v),
                        Err(_) => return Vec::new(),
                    }
                }
                next
            })
        };
        reached += next.len();
        bytes = bytes.max(seen.len() * 8 + (frontier.capacity() + next.capacity()) * 4);
        frontier = next;
    }
    Some((reached == n, bytes))
}

/// Tarjan's algorithm (Pearce's variant, iterative) on the implicit graph; `None` when
/// cancelled. Each state's successors are looked up together when it is entered and
/// kept on an edge stack while it is on the DFS path.
pub fn tarjan(net: &PtNet, g: &Graph, control: &Control<'_>) -> Option<Components> {
    let n = g.store.len();
    let nt = net.transitions.len();
    let layout = &g.store.layout;
    let packed_net = Packed::new(net, layout);
    let w = layout.words;
    let mut cur = vec![0u64; w];
    let mut next = vec![0u64; w];
    let mut succ_hashes: Vec<u64> = Vec::new();
    let mut succ_words: Vec<u64> = Vec::new();
    let mut found: Vec<u32> = Vec::new();
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
        g.store.load(v as usize, &mut cur);
        let lin = layout.linear(&cur);
        succ_hashes.clear();
        succ_words.clear();
        for t in 0..nt {
            if !packed_net.enabled(&cur, t) || packed_net.fire(&cur, &mut next, t).is_err() {
                continue;
            }
            succ_hashes.push(finish(lin.wrapping_add(packed_net.trans[t].hash_shift)));
            succ_words.extend_from_slice(&next);
        }
        g.store.find_all(&succ_hashes, &succ_words, &mut found);
        edges.extend(found.iter().filter(|&&i| i != EMPTY));
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
                            g.store.load(m, &mut words);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `dedupe` keeps the first of each marking, in order, with its origin; markings of
    /// equal hashes but different words are both kept.
    #[test]
    fn dedupe_keeps_the_first_of_each_marking() {
        fn run<const W: usize>(w: usize) {
            // Markings 0..4 by their first word; marking 3 shares marking 1's hash.
            let marking = |i: u64| -> Vec<u64> { (0..w as u64).map(|k| i * 10 + k).collect() };
            let order = [2u64, 1, 2, 3, 0, 1, 3, 3, 4, 0];
            let mut succ: Vec<u64> = order.iter().flat_map(|&i| marking(i)).collect();
            let mut hashes: Vec<u64> = order.iter().map(|&i| if i == 3 { 1 } else { i }).collect();
            let mut from_to: Vec<(u32, u32)> = (0..order.len() as u32).map(|k| (k, 7)).collect();
            let mut local = Vec::new();
            let n = dedupe::<W>(&mut hashes, &mut succ, &mut from_to, w, &mut local);
            assert_eq!(n, 5);
            let kept: Vec<u64> = (0..n).map(|k| succ[k * w] / 10).collect();
            assert_eq!(kept, [2, 1, 3, 0, 4]);
            assert_eq!(&hashes[..n], [2, 1, 1, 0, 4]);
            assert_eq!(&from_to[..n], [(0, 7), (1, 7), (3, 7), (4, 7), (8, 7)]);
            for k in 0..n {
                assert_eq!(succ[k * w..(k + 1) * w], marking(kept[k])[..]);
            }
        }
        run::<1>(1);
        run::<2>(2);
        run::<0>(3);
    }

    /// Re-laying by runs gives what unpacking and packing again give, whichever place
    /// widens (fields moving to the next word included), and the token tables count
    /// what the fields hold.
    #[test]
    fn relaying_by_runs_is_unpacking_and_packing() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed = finish(seed.wrapping_add(1));
            seed
        };
        for bits in [
            vec![3u32; 16],
            vec![5, 7, 20, 31, 1, 1, 2, 9, 13],
            vec![1; 70],
            vec![32, 32, 3],
        ] {
            let old = Layout::new(bits.clone());
            for p in 0..bits.len() {
                let mut wider = bits.clone();
                wider[p] += 1;
                let new = Layout::new(wider);
                let runs = runs(&old, &new);
                assert!(
                    runs.len() <= 4 + new.words,
                    "{} runs for {} words",
                    runs.len(),
                    new.words
                );
                let k = 5;
                let mut chunk = vec![0u8; k * new.bytes + PAD];
                let mut markings = Vec::new();
                for j in 0..k {
                    let m: Vec<u32> = bits.iter().map(|&b| (next() & ((1u64 << b) - 1)) as u32).collect();
                    let mut w = vec![0u64; old.words];
                    old.pack(&m, &mut w).unwrap();
                    words_to_bytes(&w, &mut chunk[j * old.bytes..(j + 1) * old.bytes]);
                    markings.push(m);
                }
                relay_chunk(&mut chunk, k, &old, &new, &runs);
                for (j, m) in markings.iter().enumerate() {
                    let mut want = vec![0u64; new.words];
                    new.pack(m, &mut want).unwrap();
                    let mut bytes = vec![0u8; new.bytes];
                    words_to_bytes(&want, &mut bytes);
                    let got = &chunk[j * new.bytes..(j + 1) * new.bytes];
                    assert_eq!(got, bytes, "bits {bits:?}, place {p} widened, state {j}");
                    let tokens: u64 = m.iter().map(|&v| u64::from(v)).sum();
                    assert_eq!(new.tokens(&want), tokens);
                }
            }
        }
    }

    /// A batch entered on two threads is entered as on one: every state is found under
    /// its number; a budget the grown table would pass enters nothing.
    #[test]
    fn entering_on_two_threads_is_entering_on_one() {
        let layout = Layout::new(vec![8, 8, 8, 3, 1]);
        let marking = |i: u32| vec![i & 255, (i >> 8) & 255, (i >> 16) & 255, i % 7, i % 2];
        let mut words = vec![0u64; layout.words];
        // `room`: the bytes the table may take beyond the store's once the states are in
        // the arena (`None`: no budget).
        let mut enter = |store: &mut Store, from: u32, to: u32, room: Option<usize>, threads: usize| {
            let first = store.len() as u32;
            let mut hashes = Vec::new();
            for i in from..to {
                let m = marking(i);
                assert!(layout.pack(&m, &mut words).is_ok());
                store.push(&words);
                hashes.push(hash_marking(&m));
            }
            let memory = room.map_or(usize::MAX, |r| store.bytes_used() + r);
            store.enter_all(&hashes, first, memory, threads)
        };
        for threads in [1, 2] {
            let mut store = Store::new(layout.clone());
            for from in (0..60_000).step_by(5_000) {
                assert!(enter(&mut store, from, from + 5_000, None, threads));
            }
            for i in (0..60_000).step_by(7) {
                assert_eq!(store.find_marking(&marking(i)), Some(i), "{threads} threads");
            }
            assert_eq!(store.find_marking(&marking(60_000)), None);
            assert!(!enter(&mut store, 60_000, 65_000, Some(0), threads));
            assert_eq!(store.find_marking(&marking(60_000)), None);
            assert_eq!(store.find_marking(&marking(59_999)), Some(59_999));
        }
    }
}
