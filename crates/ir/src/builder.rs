//! What front ends use to emit IR: rungs, elements, ops, temporaries,
//! constants and initial values.

use crate::layout::{Layout, Place, TagSlot};
use crate::memory::Memory;
use crate::op::{B, D, F, I, L, Op};
use crate::program::{Element, Loc, NO_ELEM, Program, RungInfo, Unit};
use alba_diag::{Files, Span};
use alba_model::Value;
use std::collections::HashMap;

/// A pool of reusable temporary slots of one class: `used` of `slots` are
/// in use; releasing to a mark frees everything taken after it.
#[derive(Debug, Default, Clone)]
struct Pool {
    slots: Vec<u32>,
    used: usize,
}

/// Temporaries in use at some point; release them with [`Builder::release`].
#[derive(Debug, Clone, Copy)]
pub struct TempMark([usize; 5]);

pub struct Builder {
    layout: Layout,
    init: Memory,
    ops: Vec<Op>,
    locs: Vec<Loc>,
    elements: Vec<Element>,
    rungs: Vec<RungInfo>,
    units: Vec<Unit>,
    rung: u32,
    pools: [Pool; 5],
    const_i: HashMap<i32, I>,
    const_f: HashMap<u32, F>,
    const_l: HashMap<i64, L>,
    const_d: HashMap<u64, D>,
    plants: Vec<crate::program::PlantSpec>,
}

impl Builder {
    /// Starts a program over `layout`, with memory holding every tag's
    /// initial value.
    pub fn new(layout: Layout) -> Builder {
        let mut init = Memory::new(layout.counts, layout.marker_bytes);
        for (idx, tag) in layout.tags.iter().enumerate() {
            if let TagSlot::Pid(p) = layout.slot(idx) {
                let defaults = alba_model::types::PID_DEFAULTS.iter().map(|(n, v)| (*n, *v));
                let given = tag.members.iter().map(|(n, v)| (n.as_str(), v.as_f64()));
                for (name, v) in defaults.chain(given) {
                    let Some(m) = tag.ty.member(name) else { continue };
                    let place = p.member(m);
                    let value = match m.ty {
                        alba_model::DataType::Bool => Value::Bool(v != 0.0),
                        alba_model::DataType::Real => Value::Real(v as f32),
                        _ => Value::Dint(v as i32),
                    };
                    init.write(place, value);
                }
                continue;
            }
            let Some(v) = tag.initial else { continue };
            let place = match layout.slot(idx) {
                TagSlot::Bool(b) => Place::Bool(b),
                TagSlot::Int(i) => Place::Int(i, tag.ty),
                TagSlot::Real(f) => Place::Real(f),
                TagSlot::Lint(l) => Place::Lint(l),
                TagSlot::Lreal(d) => Place::Lreal(d),
                TagSlot::Marker(a) => match Layout::marker_place(a, tag.ty) {
                    Some(p) => p,
                    None => continue,
                },
                TagSlot::Timer(_) | TagSlot::Counter(_) | TagSlot::Pid(_) => continue,
            };
            init.write(place, v);
        }
        Builder {
            layout,
            init,
            ops: Vec::new(),
            locs: Vec::new(),
            elements: Vec::new(),
            rungs: Vec::new(),
            units: Vec::new(),
            rung: 0,
            pools: Default::default(),
            const_i: HashMap::new(),
            const_f: HashMap::new(),
            const_l: HashMap::new(),
            const_d: HashMap::new(),
            plants: Vec::new(),
        }
    }

    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Starts a program unit (a file of the project); returns its index.
    pub fn begin_unit(&mut self, name: &str) -> u16 {
        let here = self.here();
        self.units.push(Unit {
            name: name.to_string(),
            first_op: here,
            end_op: here,
            plant: self.layout.plant,
        });
        (self.units.len() - 1) as u16
    }

    /// From now on, units are plant models: names resolve with plant access
    /// (inputs writable, outputs read-only). Plant units come last.
    pub fn begin_plant(&mut self) {
        self.layout.plant = true;
    }

    pub fn end_unit(&mut self) {
        let here = self.here();
        if let Some(u) = self.units.last_mut() {
            u.end_op = here;
        }
    }

    /// Starts a rung (emits its `Rung` op); returns the rung's index.
    pub fn begin_rung(&mut self, number: u32, span: Span) -> u32 {
        let unit = (self.units.len().max(1) - 1) as u16;
        self.rungs.push(RungInfo {
            unit,
            number,
            span,
            first_op: self.here(),
        });
        self.rung = (self.rungs.len() - 1) as u32;
        self.emit(Op::Rung, NO_ELEM);
        self.rung
    }

    /// Declares an element of the current rung; returns its id.
    pub fn element(&mut self, span: Span) -> u32 {
        self.elements.push(Element { rung: self.rung, span });
        (self.elements.len() - 1) as u32
    }

    /// The ops emitted so far.
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// Index the next op will have.
    pub fn here(&self) -> u32 {
        self.ops.len() as u32
    }

    pub fn emit(&mut self, op: Op, elem: u32) -> u32 {
        self.ops.push(op);
        self.locs.push(Loc { rung: self.rung, elem });
        self.ops.len() as u32 - 1
    }

    /// Takes back the last op emitted, for a front end's peephole: the
    /// caller makes sure nothing refers to its index (no jump target, no
    /// `Jmp` to patch). Never takes back a rung's `Rung`.
    pub fn pop(&mut self) -> Option<Op> {
        match self.ops.last() {
            None | Some(Op::Rung) => None,
            Some(_) => {
                self.locs.pop();
                self.ops.pop()
            }
        }
    }

    /// Sets the target of the `Jmp` at `at`.
    pub fn patch_jump(&mut self, at: u32, target: u32) {
        if let Some(op @ Op::Jmp(_)) = self.ops.get_mut(at as usize) {
            *op = Op::Jmp(target);
        }
    }

    pub fn mark(&self) -> TempMark {
        TempMark(self.pools.each_ref().map(|p| p.used))
    }

    /// The bool temporaries taken after mark `m` (released or not): dead
    /// once the code that took them is done, as every use of a temporary
    /// writes it before reading it.
    pub fn temps_b_since(&self, m: TempMark) -> &[u32] {
        self.pools[0].slots.get(m.0[0]..).unwrap_or(&[])
    }

    /// The integer temporaries taken after mark `m` (as [`Builder::temps_b_since`]).
    pub fn temps_i_since(&self, m: TempMark) -> &[u32] {
        self.pools[1].slots.get(m.0[1]..).unwrap_or(&[])
    }

    /// Rewrites the ops from `start` on, one entry each (`None`: dropped),
    /// for a front end's clean-up of code it just emitted: the caller makes
    /// sure no index from `start` on is referred to (no `Rung`, no `Jmp`,
    /// no jump target among them). An op keeps its location.
    pub fn rewrite_since(&mut self, start: u32, new: Vec<Option<Op>>) {
        let start = start as usize;
        let mut k = start;
        for (pc, op) in (start..).zip(new) {
            if pc >= self.ops.len() {
                break;
            }
            if let Some(op) = op {
                self.ops[k] = op;
                self.locs[k] = self.locs[pc];
                k += 1;
            }
        }
        self.ops.truncate(k);
        self.locs.truncate(k);
    }

    pub fn release(&mut self, m: TempMark) {
        for (p, used) in self.pools.iter_mut().zip(m.0) {
            p.used = used;
        }
    }

    fn pooled(&mut self, class: usize) -> u32 {
        let pool = &mut self.pools[class];
        if pool.used == pool.slots.len() {
            let c = &mut self.layout.counts;
            let counter = match class {
                0 => &mut c.b,
                1 => &mut c.i,
                2 => &mut c.f,
                3 => &mut c.l,
                _ => &mut c.d,
            };
            pool.slots.push(*counter);
            *counter += 1;
            match class {
                0 => self.init.b.push(false),
                1 => self.init.i.push(0),
                2 => self.init.f.push(0.0),
                3 => self.init.l.push(0),
                _ => self.init.d.push(0.0),
            }
        }
        pool.used += 1;
        pool.slots[pool.used - 1]
    }

    pub fn temp_b(&mut self) -> B {
        B(self.pooled(0))
    }

    /// A bool slot of its own, initially false, that keeps its value from
    /// scan to scan (the memory of an edge detector).
    pub fn state_b(&mut self) -> B {
        let s = B(self.layout.counts.b);
        self.layout.counts.b += 1;
        self.init.b.push(false);
        s
    }
    /// An integer slot of its own, initially `v`, that keeps its value from
    /// scan to scan (the state of a pseudo-random sequence).
    pub fn state_i(&mut self, v: i32) -> I {
        let s = I(self.layout.counts.i);
        self.layout.counts.i += 1;
        self.init.i.push(v);
        s
    }
    pub fn temp_i(&mut self) -> I {
        I(self.pooled(1))
    }
    pub fn temp_f(&mut self) -> F {
        F(self.pooled(2))
    }
    pub fn temp_l(&mut self) -> L {
        L(self.pooled(3))
    }
    pub fn temp_d(&mut self) -> D {
        D(self.pooled(4))
    }

    /// A read-only slot holding `v` (shared by every use of the same value).
    pub fn const_i(&mut self, v: i32) -> I {
        if let Some(&s) = self.const_i.get(&v) {
            return s;
        }
        let s = I(self.layout.counts.i);
        self.layout.counts.i += 1;
        self.init.i.push(v);
        self.const_i.insert(v, s);
        s
    }
    /// The constant of slot `s` in a read-only slot that no later use
    /// shares, or `s` itself when it is no shared [`Builder::const_i`]. A
    /// constant just made (the last integer slot) becomes that slot itself,
    /// so each call takes exactly one new slot.
    pub fn own_i(&mut self, s: I) -> I {
        let v = self.init.i.get(s.0 as usize).copied();
        match v {
            Some(v) if self.const_i.get(&v) == Some(&s) => {
                if s.0 + 1 == self.layout.counts.i {
                    self.const_i.remove(&v);
                    s
                } else {
                    self.state_i(v)
                }
            }
            _ => s,
        }
    }
    pub fn const_f(&mut self, v: f32) -> F {
        if let Some(&s) = self.const_f.get(&v.to_bits()) {
            return s;
        }
        let s = F(self.layout.counts.f);
        self.layout.counts.f += 1;
        self.init.f.push(v);
        self.const_f.insert(v.to_bits(), s);
        s
    }
    pub fn const_l(&mut self, v: i64) -> L {
        if let Some(&s) = self.const_l.get(&v) {
            return s;
        }
        let s = L(self.layout.counts.l);
        self.layout.counts.l += 1;
        self.init.l.push(v);
        self.const_l.insert(v, s);
        s
    }
    pub fn const_d(&mut self, v: f64) -> D {
        if let Some(&s) = self.const_d.get(&v.to_bits()) {
            return s;
        }
        let s = D(self.layout.counts.d);
        self.layout.counts.d += 1;
        self.init.d.push(v);
        self.const_d.insert(v.to_bits(), s);
        s
    }

    /// Sets the initial value of a place (a timer's literal preset, say).
    pub fn set_initial(&mut self, place: Place, v: Value) {
        self.init.write(place, v);
    }

    /// Attaches a plant model (see `Program::plants`).
    pub fn add_plant(&mut self, p: crate::program::PlantSpec) {
        self.plants.push(p);
    }

    pub fn finish(mut self, files: Files) -> Program {
        self.end_unit();
        self.layout.plant = false;
        Program {
            ops: self.ops,
            locs: self.locs,
            elements: self.elements,
            rungs: self.rungs,
            units: self.units,
            layout: self.layout,
            init: self.init,
            files,
            plants: self.plants,
        }
    }
}
